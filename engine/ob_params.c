/* ob_params.c — the parameter registry: registration, the name table, queries.
 * Value access lives in ob_params_values.c, packing in ob_params_pack.c. */
#include "ob_params_internal.h"

#include <stdio.h>
#include <string.h>

static const char *const builtin_names[OB_PARAM_ROLE_COUNT] = {
    [OB_PARAM_ROLE_WORLD] = "WorldMatrix",
    [OB_PARAM_ROLE_VIEW] = "ViewMatrix",
    [OB_PARAM_ROLE_PROJ] = "ProjMatrix",
    [OB_PARAM_ROLE_WORLD_VIEW] = "WorldViewMatrix",
    [OB_PARAM_ROLE_VIEW_PROJ] = "ViewProjMatrix",
    [OB_PARAM_ROLE_WORLD_VIEW_PROJ] = "WorldViewProjMatrix",
    [OB_PARAM_ROLE_NORMAL] = "NormalMatrix",
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
        const ob_param_name_entry *e = &reg->names[i];
        if (!e->id) return NULL;
        if (e->hash == hash) {
            ob_param_info *info = ob_pool_get(&reg->pool, e->id);
            if (strcmp(info->name, name) == 0) return info;
        }
    }
}

static void names_put(ob_param_name_entry *table, uint32_t cap, ob_param_name_entry entry)
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
    ob_param_name_entry *table = ob_calloc(cap, sizeof *table);
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
    names_put(reg->names, reg->names_cap, (ob_param_name_entry){info->handle.id, hash});
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
    reg->slot_serials = ob_aligned_alloc(OB_CACHE_LINE, (size_t)slots * OB_CACHE_LINE);
    if (!reg->slot_serials) {
        OB_LOG_E("params", "registry: out of host memory");
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        ob_param_registry_destroy(reg);
        reg = NULL;
        goto done;
    }
    memset(reg->slot_serials, 0, (size_t)slots * OB_CACHE_LINE);

    ob_param *role_handle[OB_PARAM_ROLE_COUNT] = {
        [OB_PARAM_ROLE_WORLD] = &reg->builtins.world,
        [OB_PARAM_ROLE_VIEW] = &reg->builtins.view,
        [OB_PARAM_ROLE_PROJ] = &reg->builtins.proj,
        [OB_PARAM_ROLE_WORLD_VIEW] = &reg->builtins.world_view,
        [OB_PARAM_ROLE_VIEW_PROJ] = &reg->builtins.view_proj,
        [OB_PARAM_ROLE_WORLD_VIEW_PROJ] = &reg->builtins.world_view_proj,
        [OB_PARAM_ROLE_NORMAL] = &reg->builtins.normal,
    };
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (uint32_t role = OB_PARAM_ROLE_WORLD; role < OB_PARAM_ROLE_COUNT; role++) {
        *role_handle[role] = ob_param_register(reg, builtin_names[role], OB_PARAM_MAT4, 1, &r);
        if (r != OB_OK) goto fail_destroy_registry;
        ob_param_info *info = ob_param_info_get(reg, *role_handle[role]);
        info->derive_role = role;
        reg->role_info[role] = info;
        /* Identity until written (value id stays 0): a forgotten matrix shows
         * the object untransformed instead of collapsing it to a point. */
        for (uint32_t s = 0; s < slots; s++) memcpy(ob_param_cell_value(info, s), identity, 64);
    }
    goto done;

fail_destroy_registry:
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
    ob_aligned_free(reg->slot_serials);
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
