/* ob_params_pack.c — mapping reflected uniform-block members to parameters
 * and packing a slot's values into a block when they changed. */
#include "ob_params_internal.h"

#include <string.h>

/* One mapped member: where its bytes come from and where they go. */
typedef struct map_entry {
    const ob_param_info *info;
    uint32_t offset;       /* in the block */
    uint32_t elem_size;    /* bytes per element (the whole value if not an array) */
    uint32_t elem_count;   /* 1, or array_len for a mat4 array */
    uint32_t stride;       /* block bytes between elements */
} map_entry;

/* Per-slot state, on its own cache lines: [user][packed][ids...]. */
enum { STATE_USER = 0, STATE_PACKED = 1, STATE_IDS = 2 };

struct ob_param_mapping {
    ob_param_registry *reg;
    uint32_t block_size;
    uint32_t slot_count;
    uint32_t member_count;
    uint32_t entry_count;
    uint32_t state_stride;   /* bytes, multiple of OB_CACHE_LINE */
    map_entry *entries;
    unsigned char *states;
};

static uint64_t *slot_state(const ob_param_mapping *map, uint32_t slot)
{
    return (uint64_t *)(void *)(map->states + (size_t)slot * map->state_stride);
}

static const char *member_type_name(ob_member_type type)
{
    switch (type) {
    case OB_MEMBER_FLOAT: return "float";
    case OB_MEMBER_VEC2: return "vec2";
    case OB_MEMBER_VEC3: return "vec3";
    case OB_MEMBER_VEC4: return "vec4";
    case OB_MEMBER_MAT4: return "mat4";
    case OB_MEMBER_INT: return "int";
    case OB_MEMBER_UINT: return "uint";
    case OB_MEMBER_IVEC4: return "ivec4";
    case OB_MEMBER_UVEC4: return "uvec4";
    case OB_MEMBER_OTHER: break;
    }
    return "struct/other";
}

/* Fills *e if member m can take parameter info's value; false if not. */
static bool member_matches(const ob_block_member *m, const ob_param_info *info, map_entry *e)
{
    *e = (map_entry){info, m->offset, info->value_size, 1, 0};
    switch (info->type) {
    case OB_PARAM_VEC4:
        return m->type == OB_MEMBER_VEC4 && m->array_len == 0 && m->size == 16;
    case OB_PARAM_MAT4:
        return m->type == OB_MEMBER_MAT4 && m->array_len == 0 && m->size == 64;
    case OB_PARAM_MAT4_ARRAY:
        if (m->type != OB_MEMBER_MAT4 || m->array_len == 0 || m->array_len > info->count ||
            m->array_stride < 64 ||
            m->size < (uint64_t)(m->array_len - 1) * m->array_stride + 64)
            return false;
        e->elem_size = 64;
        e->elem_count = m->array_len;
        e->stride = m->array_stride;
        return true;
    case OB_PARAM_BYTES:
        return m->size == info->value_size;
    default:
        return false;   /* resources are bound through descriptors, not packed */
    }
}

static uint64_t entry_end(const map_entry *e)
{
    return (uint64_t)e->offset + (uint64_t)(e->elem_count - 1) * e->stride + e->elem_size;
}

ob_param_mapping *ob_param_mapping_create(ob_param_registry *reg, const ob_block_layout *layout,
                                          const char *shader_name, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_param_mapping *map = NULL;
    const char *shader = shader_name ? shader_name : "(unnamed shader)";
    if (!reg || !layout || layout->size == 0 || (layout->member_count && !layout->members)) {
        OB_LOG_E("params", "mapping for shader '%s': %s", shader,
                 !reg ? "NULL registry" : !layout ? "NULL layout" : "empty block layout");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    char block[OB_REFLECT_NAME_MAX + 1];
    memcpy(block, layout->name, OB_REFLECT_NAME_MAX);
    block[OB_REFLECT_NAME_MAX] = '\0';

    map = ob_calloc(1, sizeof *map);
    if (!map) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    map->reg = reg;
    map->block_size = layout->size;
    map->slot_count = ob_param_registry_slot_count(reg);
    map->member_count = layout->member_count;
    map->entries = ob_calloc(layout->member_count, sizeof *map->entries);
    if (!map->entries) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_map;
    }
    for (uint32_t i = 0; i < layout->member_count; i++) {
        const ob_block_member *m = &layout->members[i];
        char name[OB_REFLECT_NAME_MAX + 1];
        memcpy(name, m->name, OB_REFLECT_NAME_MAX);
        name[OB_REFLECT_NAME_MAX] = '\0';
        ob_param p = ob_param_find(reg, name);
        const ob_param_info *info = p.id ? ob_param_info_get(reg, p) : NULL;
        if (!info) {
            OB_LOG_W("params", "shader '%s' block '%s': member '%s' (%s at offset %u) has no "
                     "parameter of that name; its bytes stay zero", shader, block, name,
                     member_type_name(m->type), m->offset);
            continue;
        }
        map_entry e;
        if (!member_matches(m, info, &e)) {
            OB_LOG_W("params", "shader '%s' block '%s': member '%s' (%s, %u bytes, array %u, "
                     "stride %u) does not fit parameter '%s' (%s, count %u, %u bytes); its "
                     "bytes stay zero", shader, block, name, member_type_name(m->type),
                     m->size, m->array_len, m->array_stride, info->name,
                     ob_param_type_name(info->type), info->count, info->value_size);
            continue;
        }
        if (entry_end(&e) > layout->size) {
            OB_LOG_W("params", "shader '%s' block '%s': member '%s' at offset %u reaches byte "
                     "%llu, past the %u-byte block; its bytes stay zero", shader, block, name,
                     m->offset, (unsigned long long)entry_end(&e), layout->size);
            continue;
        }
        map->entries[map->entry_count++] = e;
    }
    size_t state = (STATE_IDS + (size_t)map->entry_count) * sizeof(uint64_t);
    map->state_stride = (uint32_t)((state + OB_CACHE_LINE - 1) / OB_CACHE_LINE * OB_CACHE_LINE);
    size_t bytes = (size_t)map->state_stride * map->slot_count;
    map->states = ob_aligned_alloc(OB_CACHE_LINE, bytes);
    if (!map->states) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_map;
    }
    memset(map->states, 0, bytes);
    goto done;

fail_free_map:
    ob_param_mapping_destroy(map);
    map = NULL;
fail_log:
    OB_LOG_E("params", "mapping for shader '%s': %s", shader, ob_result_text(r));
done:
    if (out_result) *out_result = r;
    return map;
}

void ob_param_mapping_destroy(ob_param_mapping *map)
{
    if (!map) return;
    ob_aligned_free(map->states);
    ob_free(map->entries);
    ob_free(map);
}

uint32_t ob_param_mapping_block_size(const ob_param_mapping *map)
{
    return map ? map->block_size : 0;
}

uint32_t ob_param_mapping_mapped_count(const ob_param_mapping *map)
{
    return map ? map->entry_count : 0;
}

uint32_t ob_param_mapping_unmapped_count(const ob_param_mapping *map)
{
    return map ? map->member_count - map->entry_count : 0;
}

/* pm may pack map: same registry, slot in range. Logs otherwise. */
static bool pack_args_ok(const ob_params *pm, const ob_param_mapping *map, const char *op)
{
    if (!pm || !map || pm->reg != map->reg) {
        OB_LOG_E("params", "%s: %s", op,
                 !pm || !map ? "NULL manager or mapping"
                             : "mapping was made for another registry");
        return false;
    }
    if (pm->slot >= map->slot_count) {
        OB_LOG_E("params", "%s: slot %u out of range (registry has %u slots)", op, pm->slot,
                 map->slot_count);
        return false;
    }
    return true;
}

static bool needed(const ob_param_mapping *map, uint32_t slot)
{
    const uint64_t *st = slot_state(map, slot);
    if (!st[STATE_PACKED]) return true;
    for (uint32_t i = 0; i < map->entry_count; i++) {
        if (st[STATE_IDS + i] != *ob_param_cell_id(map->entries[i].info, slot)) return true;
    }
    return false;
}

bool ob_params_pack_needed(const ob_params *pm, const ob_param_mapping *map)
{
    return pack_args_ok(pm, map, "pack_needed") && needed(map, pm->slot);
}

bool ob_params_pack(const ob_params *pm, ob_param_mapping *map, void *dst, bool force)
{
    if (!pack_args_ok(pm, map, "pack")) return false;
    if (!dst) {
        OB_LOG_E("params", "pack (slot %u): NULL destination", pm->slot);
        return false;
    }
    uint32_t slot = pm->slot;
    if (!force && !needed(map, slot)) return false;
    uint64_t *st = slot_state(map, slot);
    unsigned char *out = dst;
    memset(out, 0, map->block_size);
    for (uint32_t i = 0; i < map->entry_count; i++) {
        const map_entry *e = &map->entries[i];
        const unsigned char *src = ob_param_cell_value(e->info, slot);
        /* The id is read before the bytes; only this slot's thread writes
         * either, so they agree. */
        st[STATE_IDS + i] = *ob_param_cell_id(e->info, slot);
        if (e->elem_count == 1) {
            memcpy(out + e->offset, src, e->elem_size);
            continue;
        }
        for (uint32_t k = 0; k < e->elem_count; k++)
            memcpy(out + e->offset + (size_t)k * e->stride, src + (size_t)k * e->elem_size,
                   e->elem_size);
    }
    st[STATE_PACKED] = 1;
    return true;
}

static bool reads_world(const ob_param_info *info)
{
    switch (info->derive_role) {
    case OB_PARAM_ROLE_WORLD:
    case OB_PARAM_ROLE_WORLD_VIEW:
    case OB_PARAM_ROLE_WORLD_VIEW_PROJ:
    case OB_PARAM_ROLE_NORMAL:
        return true;
    default:
        return false;
    }
}

bool ob_param_mapping_reads_world(const ob_param_mapping *map)
{
    if (!map) return false;
    for (uint32_t i = 0; i < map->entry_count; i++)
        if (reads_world(map->entries[i].info)) return true;
    return false;
}

bool ob_param_mapping_is_world_normal(const ob_param_mapping *map)
{
    if (!map || map->block_size != 128 || map->entry_count != 2) return false;
    const map_entry *w = &map->entries[0], *n = &map->entries[1];
    if (w->offset > n->offset) {
        const map_entry *t = w;
        w = n;
        n = t;
    }
    return w->info->derive_role == OB_PARAM_ROLE_WORLD && w->offset == 0 &&
           w->elem_count == 1 && n->info->derive_role == OB_PARAM_ROLE_NORMAL &&
           n->offset == 64 && n->elem_count == 1;
}

uint64_t *ob_param_mapping_slot_user(ob_param_mapping *map, uint32_t slot)
{
    if (!map || slot >= map->slot_count) {
        OB_LOG_E("params", "mapping slot_user: %s slot %u", map ? "out of range" : "NULL mapping",
                 slot);
        return NULL;
    }
    return &slot_state(map, slot)[STATE_USER];
}
