/* ob_params_values.c — per-slot value access: checked set/get/init, value
 * ids, and the derived built-in matrices. */
#include "ob_params_internal.h"

#include "ob_math.h"

#include <cglm/cglm.h>
#include <stdio.h>
#include <string.h>

#define ALL_SLOTS UINT32_MAX
#define ANY_TYPE OB_PARAM_TYPE_COUNT

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
                 slot_text(slot, sb), ob_param_type_name(info->type),
                 want == OB_PARAM_UNIFORM_BUFFER ? "buffer" : ob_param_type_name(want));
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
static bool cell_store(const ob_param_registry *reg, const ob_param_info *info, uint32_t slot,
                       const void *src, uint32_t offset, uint32_t size)
{
    unsigned char *cell = ob_param_cell(info, slot);
    uint64_t *id = (uint64_t *)(void *)cell;
    unsigned char *val = cell + OB_PARAM_VALUE_OFFSET + offset;
    if (size == 0 || (*id != 0 && memcmp(val, src, size) == 0)) return false;
    memcpy(val, src, size);
    ++*id;
    ob_param_slot_changed(reg, slot);
    return true;
}

static void store(const ob_param_registry *reg, const ob_param_info *info, uint32_t slot,
                  const void *src, uint32_t offset, uint32_t size)
{
    if (slot != ALL_SLOTS) {
        cell_store(reg, info, slot, src, offset, size);
        return;
    }
    for (uint32_t s = 0; s < reg->slot_count; s++) cell_store(reg, info, s, src, offset, size);
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

/* Derived matrices of slot with source `role` replaced by src; returns false
 * if any is non-finite (products of huge finite values can overflow). */
static bool derive(const ob_param_registry *reg, uint32_t slot, uint32_t role,
                   const float *src, derived *d)
{
    mat4 m[3];
    for (uint32_t r = OB_PARAM_ROLE_WORLD; r <= OB_PARAM_ROLE_PROJ; r++) {
        const void *stored = ob_param_cell_value(reg->role_info[r], slot);
        memcpy(m[r - OB_PARAM_ROLE_WORLD], r == role ? (const void *)src : stored, sizeof(mat4));
    }
    glm_mat4_mul(m[1], m[0], d->world_view);
    glm_mat4_mul(m[2], m[1], d->view_proj);
    glm_mat4_mul(d->view_proj, m[0], d->world_view_proj);
    bool ok = all_finite(&d->world_view[0][0], 16) && all_finite(&d->view_proj[0][0], 16) &&
              all_finite(&d->world_view_proj[0][0], 16);
    if (role == OB_PARAM_ROLE_WORLD) {
        ob_mat4_normal_cofactor((const float *)(const void *)m[0], (float *)(void *)d->normal);
        ok = ok && all_finite(&d->normal[0][0], 16);
    }
    return ok;
}

static void store_derived(const ob_param_registry *reg, uint32_t slot, uint32_t role,
                          const derived *d)
{
    ob_param_info *const *out = reg->role_info;
    if (role != OB_PARAM_ROLE_PROJ)
        cell_store(reg, out[OB_PARAM_ROLE_WORLD_VIEW], slot, d->world_view, 0, 64);
    if (role != OB_PARAM_ROLE_WORLD)
        cell_store(reg, out[OB_PARAM_ROLE_VIEW_PROJ], slot, d->view_proj, 0, 64);
    cell_store(reg, out[OB_PARAM_ROLE_WORLD_VIEW_PROJ], slot, d->world_view_proj, 0, 64);
    if (role == OB_PARAM_ROLE_WORLD)
        cell_store(reg, out[OB_PARAM_ROLE_NORMAL], slot, d->normal, 0, 64);
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
        if (!cell_store(reg, info, s, src, 0, 64)) continue;
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
    if (info->derive_role >= OB_PARAM_ROLE_WORLD && info->derive_role <= OB_PARAM_ROLE_PROJ)
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

uint64_t ob_params_serial(const ob_params *pm)
{
    if (!pm || !pm->reg || pm->slot >= pm->reg->slot_count) return 0;
    return pm->reg->slot_serials[(size_t)pm->slot * OB_SERIAL_STRIDE];
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
