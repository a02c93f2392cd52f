/* ob_params.c — parameter registry, per-slot value storage, derived matrices.
 * Packing into uniform blocks lives in ob_params_pack.c. */
#include "ob_params_internal.h"

#include <cglm/cglm.h>
#include <stdio.h>
#include <string.h>

#define ALL_SLOTS UINT32_MAX
#define ANY_TYPE OB_PARAM_TYPE_COUNT

/* Built-in transform roles: the three sources and what is derived from them. */
enum {
    ROLE_NONE = 0,
    ROLE_WORLD,
    ROLE_VIEW,
    ROLE_PROJ,
    ROLE_WORLD_VIEW,
    ROLE_VIEW_PROJ,
    ROLE_WORLD_VIEW_PROJ,
    ROLE_NORMAL,
    ROLE_COUNT
};

static const char *const builtin_names[ROLE_COUNT] = {
    [ROLE_WORLD] = "WorldMatrix",
    [ROLE_VIEW] = "ViewMatrix",
    [ROLE_PROJ] = "ProjMatrix",
    [ROLE_WORLD_VIEW] = "WorldViewMatrix",
    [ROLE_VIEW_PROJ] = "ViewProjMatrix",
    [ROLE_WORLD_VIEW_PROJ] = "WorldViewProjMatrix",
    [ROLE_NORMAL] = "NormalMatrix",
};

/* Open-addressing name table entry; id 0 marks an empty bucket. */
typedef struct name_entry {
    uint32_t id;
    uint32_t hash;
} name_entry;

struct ob_param_registry {
    uint32_t slot_count;
    bool recording;
    ob_pool pool;                       /* handle id → ob_param_info* */
    name_entry *names;                  /* power-of-two capacity, load ≤ 1/2 */
    uint32_t names_cap;
    ob_param_builtins builtins;
    ob_param_info *role_info[ROLE_COUNT];
};

static const char *const type_names[OB_PARAM_TYPE_COUNT] = {
    [OB_PARAM_VEC4] = "vec4",
    [OB_PARAM_MAT4] = "mat4",
    [OB_PARAM_MAT4_ARRAY] = "mat4 array",
    [OB_PARAM_TEXTURE] = "texture",
    [OB_PARAM_SAMPLER] = "sampler",
    [OB_PARAM_UNIFORM_BUFFER] = "uniform buffer",
    [OB_PARAM_STORAGE_BUFFER] = "storage buffer",
    [OB_PARAM_BYTES] = "bytes",
};

const char *ob_param_type_name(ob_param_type type)
{
    return (unsigned)type < OB_PARAM_TYPE_COUNT ? type_names[type] : "invalid type";
}

static uint64_t value_size_of(ob_param_type type, uint32_t count)
{
    switch (type) {
    case OB_PARAM_VEC4: return 16;
    case OB_PARAM_MAT4: return 64;
    case OB_PARAM_MAT4_ARRAY: return 64ull * count;
    case OB_PARAM_TEXTURE: return sizeof(ob_image);
    case OB_PARAM_SAMPLER: return sizeof(ob_sampler);
    case OB_PARAM_UNIFORM_BUFFER:
    case OB_PARAM_STORAGE_BUFFER: return sizeof(ob_buffer);
    case OB_PARAM_BYTES: return count;
    case OB_PARAM_TYPE_COUNT: break;
    }
    return 0;
}

static uint32_t name_hash(const char *name)
{
    uint64_t h = ob_hash_str(OB_HASH_SEED, name);
    return (uint32_t)(h ^ (h >> 32));
}

ob_param_info *ob_param_info_get(const ob_param_registry *reg, ob_param p)
{
    return ob_pool_get(&reg->pool, p.id);
}

/* ------------------------------------------------------------- name table */

static ob_param_info *names_lookup(const ob_param_registry *reg, const char *name, uint32_t hash)
{
    if (!reg->names_cap) return NULL;
    uint32_t mask = reg->names_cap - 1;
    for (uint32_t i = hash & mask;; i = (i + 1) & mask) {
        const name_entry *e = &reg->names[i];
        if (!e->id) return NULL;
        if (e->hash == hash) {
            ob_param_info *info = ob_pool_get(&reg->pool, e->id);
            if (strcmp(info->name, name) == 0) return info;
        }
    }
}

static void names_put(name_entry *table, uint32_t cap, name_entry entry)
{
    uint32_t mask = cap - 1;
    uint32_t i = entry.hash & mask;
    while (table[i].id) i = (i + 1) & mask;
    table[i] = entry;
}

/* Makes room for one more name; the table is unchanged on failure. */
static ob_result names_reserve_one(ob_param_registry *reg)
{
    uint32_t need = reg->pool.count + 1;
    if (reg->names_cap && need <= reg->names_cap / 2) return OB_OK;
    uint32_t cap = reg->names_cap ? reg->names_cap * 2 : 32;
    name_entry *table = ob_calloc(cap, sizeof *table);
    if (!table) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < reg->names_cap; i++) {
        if (reg->names[i].id) names_put(table, cap, reg->names[i]);
    }
    ob_free(reg->names);
    reg->names = table;
    reg->names_cap = cap;
    return OB_OK;
}

/* ------------------------------------------------------------ registration */

static void info_free(ob_param_info *info)
{
    if (!info) return;
    ob_aligned_free(info->cells);
    ob_free(info);
}

ob_param ob_param_register(ob_param_registry *reg, const char *name, ob_param_type type,
                           uint32_t count, ob_result *out_result)
{
    ob_param handle = {0};
    ob_result r = OB_OK;
    ob_param_info *info = NULL;
    if (!reg || !name || !name[0]) {
        OB_LOG_E("params", "register: %s", !reg ? "NULL registry" : "empty parameter name");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    if (reg->recording) {
        OB_LOG_E("params", "register '%s': not allowed while recording (register at start-up "
                 "or between frames)", name);
        r = OB_ERR_WRONG_STATE;
        goto done;
    }
    if ((unsigned)type >= OB_PARAM_TYPE_COUNT) {
        OB_LOG_E("params", "register '%s': invalid type %d", name, (int)type);
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    if (type != OB_PARAM_MAT4_ARRAY && type != OB_PARAM_BYTES) {
        count = 1;
    } else if (count == 0) {
        OB_LOG_E("params", "register '%s': a %s parameter needs a count of at least 1", name,
                 type_names[type]);
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    uint64_t size = value_size_of(type, count);
    if (size > OB_PARAM_MAX_VALUE_SIZE) {
        OB_LOG_E("params", "register '%s': %s of %llu bytes exceeds the %u-byte limit", name,
                 type_names[type], (unsigned long long)size, OB_PARAM_MAX_VALUE_SIZE);
        r = OB_ERR_LIMIT;
        goto done;
    }
    uint32_t hash = name_hash(name);
    ob_param_info *existing = names_lookup(reg, name, hash);
    if (existing) {
        if (existing->type == type && existing->count == count) {
            handle = existing->handle;
            goto done;
        }
        OB_LOG_E("params", "register '%s': already registered as %s[%u], not %s[%u]", name,
                 type_names[existing->type], existing->count, type_names[type], count);
        r = OB_ERR_DUPLICATE;
        goto done;
    }

    r = names_reserve_one(reg);
    if (r != OB_OK) goto fail_log;
    size_t name_len = strlen(name);
    info = ob_malloc(sizeof *info + name_len + 1);
    if (!info) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    memset(info, 0, sizeof *info);
    memcpy(info->name, name, name_len + 1);
    info->type = type;
    info->count = count;
    info->value_size = (uint32_t)size;
    uint32_t cell = OB_PARAM_VALUE_OFFSET + info->value_size;
    info->cell_stride = (cell + OB_CACHE_LINE - 1) / OB_CACHE_LINE * OB_CACHE_LINE;
    size_t bytes = (size_t)info->cell_stride * reg->slot_count;
    info->cells = ob_aligned_alloc(OB_CACHE_LINE, bytes);
    if (!info->cells) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_info;
    }
    memset(info->cells, 0, bytes);
    info->handle.id = ob_pool_insert(&reg->pool, info, &r);
    if (!info->handle.id) goto fail_free_info;
    names_put(reg->names, reg->names_cap, (name_entry){info->handle.id, hash});
    handle = info->handle;
    goto done;

fail_free_info:
    info_free(info);
fail_log:
    OB_LOG_E("params", "register '%s': %s", name, ob_result_text(r));
done:
    if (out_result) *out_result = r;
    return handle;
}

ob_param ob_param_find(const ob_param_registry *reg, const char *name)
{
    if (!reg || !name) return (ob_param){0};
    ob_param_info *info = names_lookup(reg, name, name_hash(name));
    return info ? info->handle : (ob_param){0};
}

/* ---------------------------------------------------------------- registry */

ob_param_registry *ob_param_registry_create(const ob_param_registry_desc *desc,
                                            ob_result *out_result)
{
    ob_result r = OB_OK;
    uint32_t slots = desc && desc->slot_count ? desc->slot_count : 1;
    ob_param_registry *reg = NULL;
    if (slots > OB_PARAM_MAX_SLOTS) {
        OB_LOG_E("params", "registry: %u slots requested, at most %u", slots, OB_PARAM_MAX_SLOTS);
        r = OB_ERR_OUT_OF_RANGE;
        goto done;
    }
    reg = ob_calloc(1, sizeof *reg);
    if (!reg) {
        OB_LOG_E("params", "registry: out of host memory");
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    reg->slot_count = slots;
    ob_pool_init(&reg->pool);

    ob_param *role_handle[ROLE_COUNT] = {
        [ROLE_WORLD] = &reg->builtins.world,
        [ROLE_VIEW] = &reg->builtins.view,
        [ROLE_PROJ] = &reg->builtins.proj,
        [ROLE_WORLD_VIEW] = &reg->builtins.world_view,
        [ROLE_VIEW_PROJ] = &reg->builtins.view_proj,
        [ROLE_WORLD_VIEW_PROJ] = &reg->builtins.world_view_proj,
        [ROLE_NORMAL] = &reg->builtins.normal,
    };
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (uint32_t role = ROLE_WORLD; role < ROLE_COUNT; role++) {
        *role_handle[role] = ob_param_register(reg, builtin_names[role], OB_PARAM_MAT4, 1, &r);
        if (r != OB_OK) goto fail_destroy;
        ob_param_info *info = ob_param_info_get(reg, *role_handle[role]);
        info->derive_role = role;
        reg->role_info[role] = info;
        /* Identity until written (value id stays 0): a forgotten matrix shows
         * the object untransformed instead of collapsing it to a point. */
        for (uint32_t s = 0; s < slots; s++) memcpy(ob_param_cell_value(info, s), identity, 64);
    }
    goto done;

fail_destroy:
    OB_LOG_E("params", "registry: cannot register built-in parameters: %s", ob_result_text(r));
    ob_param_registry_destroy(reg);
    reg = NULL;
done:
    if (out_result) *out_result = r;
    return reg;
}

void ob_param_registry_destroy(ob_param_registry *reg)
{
    if (!reg) return;
    uint32_t cursor = 0;
    ob_param_info *info;
    while ((info = ob_pool_next(&reg->pool, &cursor, NULL))) info_free(info);
    ob_pool_release(&reg->pool);
    ob_free(reg->names);
    ob_free(reg);
}

uint32_t ob_param_registry_slot_count(const ob_param_registry *reg)
{
    return reg ? reg->slot_count : 0;
}

uint32_t ob_param_registry_param_count(const ob_param_registry *reg)
{
    return reg ? reg->pool.count : 0;
}

const ob_param_builtins *ob_param_registry_builtins(const ob_param_registry *reg)
{
    return reg ? &reg->builtins : NULL;
}

void ob_param_registry_begin_recording(ob_param_registry *reg)
{
    if (reg) reg->recording = true;
}

void ob_param_registry_end_recording(ob_param_registry *reg)
{
    if (reg) reg->recording = false;
}

bool ob_param_registry_is_recording(const ob_param_registry *reg)
{
    return reg && reg->recording;
}

/* ------------------------------------------------------------------ queries */

static ob_param_info *query(const ob_param_registry *reg, ob_param p, const char *op)
{
    ob_param_info *info = reg ? ob_param_info_get(reg, p) : NULL;
    if (!info) {
        OB_LOG_E("params", "%s: %s parameter handle 0x%08x", op,
                 reg ? "invalid or stale" : "NULL registry for", p.id);
    }
    return info;
}

const char *ob_param_name(const ob_param_registry *reg, ob_param p)
{
    ob_param_info *info = query(reg, p, "name");
    return info ? info->name : NULL;
}

ob_param_type ob_param_get_type(const ob_param_registry *reg, ob_param p)
{
    ob_param_info *info = query(reg, p, "get_type");
    return info ? info->type : OB_PARAM_TYPE_COUNT;
}

uint32_t ob_param_count(const ob_param_registry *reg, ob_param p)
{
    ob_param_info *info = query(reg, p, "count");
    return info ? info->count : 0;
}

uint32_t ob_param_value_size(const ob_param_registry *reg, ob_param p)
{
    ob_param_info *info = query(reg, p, "value_size");
    return info ? info->value_size : 0;
}

/* ----------------------------------------------------------- checked access */

ob_result ob_params_manager(ob_param_registry *reg, uint32_t slot, ob_params *out)
{
    if (!reg || !out) {
        OB_LOG_E("params", "manager: NULL %s", !reg ? "registry" : "output");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (slot >= reg->slot_count) {
        OB_LOG_E("params", "manager: slot %u out of range (registry has %u slots)", slot,
                 reg->slot_count);
        return OB_ERR_OUT_OF_RANGE;
    }
    *out = (ob_params){reg, slot};
    return OB_OK;
}

static const char *slot_text(uint32_t slot, char buf[32])
{
    if (slot == ALL_SLOTS) return "all slots";
    snprintf(buf, 32, "slot %u", slot);
    return buf;
}

static bool type_accepts(ob_param_type have, ob_param_type want)
{
    if (want == ANY_TYPE || have == want) return true;
    return want == OB_PARAM_UNIFORM_BUFFER && have == OB_PARAM_STORAGE_BUFFER;
}

/* Resolves p for an access to slot (ALL_SLOTS for init_*) expecting type
 * want (ANY_TYPE: no check). On failure logs, sets *out_r, returns NULL. */
static ob_param_info *checked(const ob_param_registry *reg, ob_param p, uint32_t slot,
                              ob_param_type want, const char *op, ob_result *out_r)
{
    char sb[32];
    if (!reg) {
        OB_LOG_E("params", "%s: NULL registry or manager (handle 0x%08x)", op, p.id);
        *out_r = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    ob_param_info *info = ob_param_info_get(reg, p);
    if (!info) {
        OB_LOG_E("params", "%s: invalid or stale parameter handle 0x%08x (%s)", op, p.id,
                 slot_text(slot, sb));
        *out_r = OB_ERR_INVALID_HANDLE;
        return NULL;
    }
    if (slot == ALL_SLOTS && reg->recording) {
        OB_LOG_E("params", "%s '%s': not allowed while recording (workers own their slots)", op,
                 info->name);
        *out_r = OB_ERR_WRONG_STATE;
        return NULL;
    }
    if (slot != ALL_SLOTS && slot >= reg->slot_count) {
        OB_LOG_E("params", "%s '%s': slot %u out of range (registry has %u slots)", op,
                 info->name, slot, reg->slot_count);
        *out_r = OB_ERR_OUT_OF_RANGE;
        return NULL;
    }
    if (!type_accepts(info->type, want)) {
        OB_LOG_E("params", "%s '%s' (%s): parameter is a %s, not a %s", op, info->name,
                 slot_text(slot, sb), type_names[info->type],
                 want == OB_PARAM_UNIFORM_BUFFER ? "buffer" : type_names[want]);
        *out_r = OB_ERR_TYPE_MISMATCH;
        return NULL;
    }
    *out_r = OB_OK;
    return info;
}

static ob_param_info *checked_pm(const ob_params *pm, ob_param p, ob_param_type want,
                                 const char *op, ob_result *out_r)
{
    return checked(pm ? pm->reg : NULL, p, pm ? pm->slot : 0, want, op, out_r);
}

static ob_result fail_null(const ob_param_info *info, uint32_t slot, const char *op)
{
    char sb[32];
    OB_LOG_E("params", "%s '%s' (%s): NULL data", op, info->name, slot_text(slot, sb));
    return OB_ERR_INVALID_ARGUMENT;
}

/* ------------------------------------------------------------------ storage */

/* Compare, then copy: the value id moves only on a real change (or the
 * first write, so "never written" stays distinguishable from zeros). */
static bool cell_store(const ob_param_info *info, uint32_t slot, const void *src,
                       uint32_t offset, uint32_t size)
{
    unsigned char *cell = ob_param_cell(info, slot);
    uint64_t *id = (uint64_t *)(void *)cell;
    unsigned char *val = cell + OB_PARAM_VALUE_OFFSET + offset;
    if (size == 0 || (*id != 0 && memcmp(val, src, size) == 0)) return false;
    memcpy(val, src, size);
    ++*id;
    return true;
}

static void store(const ob_param_registry *reg, const ob_param_info *info, uint32_t slot,
                  const void *src, uint32_t offset, uint32_t size)
{
    if (slot != ALL_SLOTS) {
        cell_store(info, slot, src, offset, size);
        return;
    }
    for (uint32_t s = 0; s < reg->slot_count; s++) cell_store(info, s, src, offset, size);
}

static bool all_finite(const float *f, size_t n)
{
    /* Exponent all ones = Inf or NaN; a bit test is cheaper than isfinite
     * and cannot be folded away by fast-math. */
    uint32_t bad = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &f[i], sizeof bits);
        bad |= (bits & 0x7f800000u) == 0x7f800000u;
    }
    return !bad;
}

/* ------------------------------------------------------- derived matrices */

typedef struct derived {
    mat4 world_view, view_proj, world_view_proj, normal;
} derived;

/* Cofactor matrix of the upper 3x3 (columns c1×c2, c2×c0, c0×c1) = det ·
 * inverse-transpose: correct for non-uniform scale, finite for zero scale,
 * and the shader normalizes anyway. */
static void normal_from_world(mat4 w, mat4 dest)
{
    glm_mat4_zero(dest);
    glm_vec3_cross(w[1], w[2], dest[0]);
    glm_vec3_cross(w[2], w[0], dest[1]);
    glm_vec3_cross(w[0], w[1], dest[2]);
    dest[3][3] = 1.0f;
}

/* Derived matrices of slot with source `role` replaced by src; returns false
 * if any is non-finite (products of huge finite values can overflow). */
static bool derive(const ob_param_registry *reg, uint32_t slot, uint32_t role,
                   const float *src, derived *d)
{
    mat4 m[3];
    for (uint32_t r = ROLE_WORLD; r <= ROLE_PROJ; r++) {
        const void *from = r == role ? (const void *)src : ob_param_cell_value(reg->role_info[r], slot);
        memcpy(m[r - ROLE_WORLD], from, sizeof(mat4));
    }
    glm_mat4_mul(m[1], m[0], d->world_view);
    glm_mat4_mul(m[2], m[1], d->view_proj);
    glm_mat4_mul(d->view_proj, m[0], d->world_view_proj);
    bool ok = all_finite(&d->world_view[0][0], 16) && all_finite(&d->view_proj[0][0], 16) &&
              all_finite(&d->world_view_proj[0][0], 16);
    if (role == ROLE_WORLD) {
        normal_from_world(m[0], d->normal);
        ok = ok && all_finite(&d->normal[0][0], 16);
    }
    return ok;
}

static void store_derived(const ob_param_registry *reg, uint32_t slot, uint32_t role,
                          const derived *d)
{
    if (role != ROLE_PROJ) cell_store(reg->role_info[ROLE_WORLD_VIEW], slot, d->world_view, 0, 64);
    if (role != ROLE_WORLD) cell_store(reg->role_info[ROLE_VIEW_PROJ], slot, d->view_proj, 0, 64);
    cell_store(reg->role_info[ROLE_WORLD_VIEW_PROJ], slot, d->world_view_proj, 0, 64);
    if (role == ROLE_WORLD) cell_store(reg->role_info[ROLE_NORMAL], slot, d->normal, 0, 64);
}

/* A world/view/proj write: every affected slot is checked before any is
 * written, so a refused write leaves all of them as they were. */
static ob_result store_transform(const ob_param_registry *reg, const ob_param_info *info,
                                 uint32_t slot, const float *src, const char *op)
{
    uint32_t first = slot == ALL_SLOTS ? 0 : slot;
    uint32_t end = slot == ALL_SLOTS ? reg->slot_count : slot + 1;
    uint32_t role = info->derive_role;
    derived d;
    /* The common case on a worker: the same matrix again costs one compare. */
    if (end - first == 1 && *ob_param_cell_id(info, first) != 0 &&
        memcmp(ob_param_cell_value(info, first), src, 64) == 0)
        return OB_OK;
    for (uint32_t s = first; s < end; s++) {
        if (!derive(reg, s, role, src, &d)) {
            OB_LOG_E("params", "%s '%s' (slot %u): the derived matrices would be non-finite "
                     "(values too large); refused", op, info->name, s);
            return OB_ERR_NON_FINITE;
        }
    }
    for (uint32_t s = first; s < end; s++) {
        if (!cell_store(info, s, src, 0, 64)) continue;
        if (end - first > 1) derive(reg, s, role, src, &d);
        store_derived(reg, s, role, &d);
    }
    return OB_OK;
}

/* --------------------------------------------------------------- writes */

static ob_result write_floats(const ob_param_registry *reg, const ob_param_info *info,
                              uint32_t slot, const float *src, uint32_t offset, uint32_t size,
                              const char *op)
{
    char sb[32];
    if (!src) return fail_null(info, slot, op);
    if (!all_finite(src, size / sizeof(float))) {
        OB_LOG_E("params", "%s '%s' (%s): NaN or Inf in the value; refused", op, info->name,
                 slot_text(slot, sb));
        return OB_ERR_NON_FINITE;
    }
    if (info->derive_role >= ROLE_WORLD && info->derive_role <= ROLE_PROJ)
        return store_transform(reg, info, slot, src, op);
    store(reg, info, slot, src, offset, size);
    return OB_OK;
}

static ob_result write_vec4(ob_param_registry *reg, uint32_t slot, ob_param p, const float v[4],
                            const char *op)
{
    ob_result r;
    ob_param_info *info = checked(reg, p, slot, OB_PARAM_VEC4, op, &r);
    return info ? write_floats(reg, info, slot, v, 0, 16, op) : r;
}

static ob_result write_mat4(ob_param_registry *reg, uint32_t slot, ob_param p, const float *m,
                            const char *op)
{
    ob_result r;
    ob_param_info *info = checked(reg, p, slot, OB_PARAM_MAT4, op, &r);
    return info ? write_floats(reg, info, slot, m, 0, 64, op) : r;
}

static ob_result range_check(const ob_param_info *info, uint32_t slot, uint32_t first,
                             uint32_t count, const char *op)
{
    char sb[32];
    if (first <= info->count && count <= info->count - first) return OB_OK;
    OB_LOG_E("params", "%s '%s' (%s): elements [%u, %llu) exceed the %u registered", op,
             info->name, slot_text(slot, sb), first, (unsigned long long)first + count,
             info->count);
    return OB_ERR_OUT_OF_RANGE;
}

static ob_result write_mat4_array(ob_param_registry *reg, uint32_t slot, ob_param p,
                                  uint32_t first, const float *m, uint32_t count, const char *op)
{
    ob_result r;
    ob_param_info *info = checked(reg, p, slot, OB_PARAM_MAT4_ARRAY, op, &r);
    if (!info) return r;
    r = range_check(info, slot, first, count, op);
    if (r != OB_OK) return r;
    return write_floats(reg, info, slot, m, first * 64u, count * 64u, op);
}

static ob_result write_handle(ob_param_registry *reg, uint32_t slot, ob_param p,
                              ob_param_type want, uint32_t id, const char *op)
{
    ob_result r;
    ob_param_info *info = checked(reg, p, slot, want, op, &r);
    if (info) store(reg, info, slot, &id, 0, sizeof id);
    return r;
}

static ob_result write_bytes(ob_param_registry *reg, uint32_t slot, ob_param p,
                             const void *data, uint32_t size, const char *op)
{
    char sb[32];
    ob_result r;
    ob_param_info *info = checked(reg, p, slot, OB_PARAM_BYTES, op, &r);
    if (!info) return r;
    if (!data) return fail_null(info, slot, op);
    if (size != info->value_size) {
        OB_LOG_E("params", "%s '%s' (%s): %u bytes given, %u registered", op, info->name,
                 slot_text(slot, sb), size, info->value_size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    store(reg, info, slot, data, 0, size);
    return OB_OK;
}

#define PM_REG(pm) ((pm) ? (pm)->reg : NULL)
#define PM_SLOT(pm) ((pm) ? (pm)->slot : 0)

ob_result ob_params_set_vec4(ob_params *pm, ob_param p, const float v[4])
{
    return write_vec4(PM_REG(pm), PM_SLOT(pm), p, v, "set_vec4");
}

ob_result ob_params_set_mat4(ob_params *pm, ob_param p, const float *m)
{
    return write_mat4(PM_REG(pm), PM_SLOT(pm), p, m, "set_mat4");
}

ob_result ob_params_set_mat4_array(ob_params *pm, ob_param p, const float *m, uint32_t count)
{
    return write_mat4_array(PM_REG(pm), PM_SLOT(pm), p, 0, m, count, "set_mat4_array");
}

ob_result ob_params_set_mat4_array_at(ob_params *pm, ob_param p, uint32_t first,
                                      const float *m, uint32_t count)
{
    return write_mat4_array(PM_REG(pm), PM_SLOT(pm), p, first, m, count, "set_mat4_array_at");
}

ob_result ob_params_set_texture(ob_params *pm, ob_param p, ob_image img)
{
    return write_handle(PM_REG(pm), PM_SLOT(pm), p, OB_PARAM_TEXTURE, img.id, "set_texture");
}

ob_result ob_params_set_sampler(ob_params *pm, ob_param p, ob_sampler s)
{
    return write_handle(PM_REG(pm), PM_SLOT(pm), p, OB_PARAM_SAMPLER, s.id, "set_sampler");
}

ob_result ob_params_set_buffer(ob_params *pm, ob_param p, ob_buffer b)
{
    return write_handle(PM_REG(pm), PM_SLOT(pm), p, OB_PARAM_UNIFORM_BUFFER, b.id, "set_buffer");
}

ob_result ob_params_set_bytes(ob_params *pm, ob_param p, const void *data, uint32_t size)
{
    return write_bytes(PM_REG(pm), PM_SLOT(pm), p, data, size, "set_bytes");
}

ob_result ob_params_init_vec4(ob_param_registry *reg, ob_param p, const float v[4])
{
    return write_vec4(reg, ALL_SLOTS, p, v, "init_vec4");
}

ob_result ob_params_init_mat4(ob_param_registry *reg, ob_param p, const float *m)
{
    return write_mat4(reg, ALL_SLOTS, p, m, "init_mat4");
}

ob_result ob_params_init_mat4_array(ob_param_registry *reg, ob_param p, const float *m,
                                    uint32_t count)
{
    return write_mat4_array(reg, ALL_SLOTS, p, 0, m, count, "init_mat4_array");
}

ob_result ob_params_init_texture(ob_param_registry *reg, ob_param p, ob_image img)
{
    return write_handle(reg, ALL_SLOTS, p, OB_PARAM_TEXTURE, img.id, "init_texture");
}

ob_result ob_params_init_sampler(ob_param_registry *reg, ob_param p, ob_sampler s)
{
    return write_handle(reg, ALL_SLOTS, p, OB_PARAM_SAMPLER, s.id, "init_sampler");
}

ob_result ob_params_init_buffer(ob_param_registry *reg, ob_param p, ob_buffer b)
{
    return write_handle(reg, ALL_SLOTS, p, OB_PARAM_UNIFORM_BUFFER, b.id, "init_buffer");
}

ob_result ob_params_init_bytes(ob_param_registry *reg, ob_param p, const void *data,
                               uint32_t size)
{
    return write_bytes(reg, ALL_SLOTS, p, data, size, "init_bytes");
}

/* ---------------------------------------------------------------- reads */

/* Copies size bytes at offset of pm's slot into out after the checks. */
static ob_result read_value(const ob_params *pm, ob_param p, ob_param_type want, uint32_t offset,
                            uint32_t size, void *out, const char *op)
{
    ob_result r;
    const ob_param_info *info = checked_pm(pm, p, want, op, &r);
    if (!info) return r;
    if (!out) {
        OB_LOG_E("params", "%s '%s' (slot %u): NULL output", op, info->name, pm->slot);
        return OB_ERR_INVALID_ARGUMENT;
    }
    memcpy(out, ob_param_cell_value(info, pm->slot) + offset, size);
    return OB_OK;
}

ob_result ob_params_get_vec4(const ob_params *pm, ob_param p, float out_v[4])
{
    return read_value(pm, p, OB_PARAM_VEC4, 0, 16, out_v, "get_vec4");
}

ob_result ob_params_get_mat4(const ob_params *pm, ob_param p, float *out_m)
{
    return read_value(pm, p, OB_PARAM_MAT4, 0, 64, out_m, "get_mat4");
}

ob_result ob_params_get_mat4_array_at(const ob_params *pm, ob_param p, uint32_t first,
                                      uint32_t count, float *out_m)
{
    ob_result r;
    const char *op = "get_mat4_array";
    const ob_param_info *info = checked_pm(pm, p, OB_PARAM_MAT4_ARRAY, op, &r);
    if (!info) return r;
    r = range_check(info, pm->slot, first, count, op);
    if (r != OB_OK) return r;
    return read_value(pm, p, OB_PARAM_MAT4_ARRAY, first * 64u, count * 64u, out_m, op);
}

ob_result ob_params_get_mat4_array(const ob_params *pm, ob_param p, uint32_t count, float *out_m)
{
    return ob_params_get_mat4_array_at(pm, p, 0, count, out_m);
}

ob_result ob_params_get_texture(const ob_params *pm, ob_param p, ob_image *out_img)
{
    return read_value(pm, p, OB_PARAM_TEXTURE, 0, sizeof *out_img, out_img, "get_texture");
}

ob_result ob_params_get_sampler(const ob_params *pm, ob_param p, ob_sampler *out_s)
{
    return read_value(pm, p, OB_PARAM_SAMPLER, 0, sizeof *out_s, out_s, "get_sampler");
}

ob_result ob_params_get_buffer(const ob_params *pm, ob_param p, ob_buffer *out_b)
{
    return read_value(pm, p, OB_PARAM_UNIFORM_BUFFER, 0, sizeof *out_b, out_b, "get_buffer");
}

ob_result ob_params_get_bytes(const ob_params *pm, ob_param p, uint32_t size, void *out_data)
{
    ob_result r;
    const ob_param_info *info = checked_pm(pm, p, OB_PARAM_BYTES, "get_bytes", &r);
    if (!info) return r;
    if (size != info->value_size) {
        OB_LOG_E("params", "get_bytes '%s' (slot %u): %u bytes asked, %u registered", info->name,
                 pm->slot, size, info->value_size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    return read_value(pm, p, OB_PARAM_BYTES, 0, size, out_data, "get_bytes");
}

const void *ob_params_value_ptr(const ob_params *pm, ob_param p)
{
    ob_result r;
    const ob_param_info *info = checked_pm(pm, p, ANY_TYPE, "value_ptr", &r);
    return info ? ob_param_cell_value(info, pm->slot) : NULL;
}

uint64_t ob_params_value_id(const ob_params *pm, ob_param p)
{
    ob_result r;
    const ob_param_info *info = checked_pm(pm, p, ANY_TYPE, "value_id", &r);
    return info ? *ob_param_cell_id(info, pm->slot) : 0;
}
