/* ob_params_internal.h — the registry and storage layout shared by
 * ob_params.c (registry), ob_params_values.c (value access) and
 * ob_params_pack.c (packing). Not API: nothing else includes it.
 *
 * A parameter's storage is one 64-byte aligned allocation of slot_count
 * cells. A cell is [value id (8 bytes) | pad to 32 | value], its size rounded
 * up to whole cache lines, so two slots never share a line. The value sits at
 * a 32-byte boundary so a stored mat4 is a valid cglm operand.
 */
#ifndef OB_PARAMS_INTERNAL_H
#define OB_PARAMS_INTERNAL_H

#include "ob_params.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

#define OB_PARAM_VALUE_OFFSET 32u

typedef struct ob_param_info {
    ob_param handle;
    ob_param_type type;
    uint32_t count;        /* elements (mat4 array), bytes (bytes), else 1 */
    uint32_t value_size;   /* bytes of one slot's value */
    uint32_t cell_stride;  /* bytes between slots' cells, multiple of OB_CACHE_LINE */
    uint32_t derive_role;  /* ob_param_role of a built-in matrix, 0 otherwise */
    unsigned char *cells;  /* slot_count * cell_stride bytes */
    char name[];           /* NUL-terminated, owned */
} ob_param_info;

static inline unsigned char *ob_param_cell(const ob_param_info *info, uint32_t slot)
{
    return info->cells + (size_t)slot * info->cell_stride;
}

static inline uint64_t *ob_param_cell_id(const ob_param_info *info, uint32_t slot)
{
    return (uint64_t *)(void *)ob_param_cell(info, slot);
}

static inline unsigned char *ob_param_cell_value(const ob_param_info *info, uint32_t slot)
{
    return ob_param_cell(info, slot) + OB_PARAM_VALUE_OFFSET;
}

/* Built-in transform roles: the three sources and what is derived from them. */
typedef enum ob_param_role {
    OB_PARAM_ROLE_NONE = 0,
    OB_PARAM_ROLE_WORLD,
    OB_PARAM_ROLE_VIEW,
    OB_PARAM_ROLE_PROJ,
    OB_PARAM_ROLE_WORLD_VIEW,
    OB_PARAM_ROLE_VIEW_PROJ,
    OB_PARAM_ROLE_WORLD_VIEW_PROJ,
    OB_PARAM_ROLE_NORMAL,
    OB_PARAM_ROLE_COUNT
} ob_param_role;

/* Open-addressing name table entry; id 0 marks an empty bucket. */
typedef struct ob_param_name_entry {
    uint32_t id;
    uint32_t hash;
} ob_param_name_entry;

struct ob_param_registry {
    uint32_t slot_count;
    bool recording;
    ob_pool pool;                       /* handle id → ob_param_info* */
    ob_param_name_entry *names;                  /* power-of-two capacity, load ≤ 1/2 */
    uint32_t names_cap;
    ob_param_builtins builtins;
    ob_param_info *role_info[OB_PARAM_ROLE_COUNT];
    /* Per slot, on its own cache line (OB_SERIAL_STRIDE words apart): grows
     * by one per real change of any value in that slot. */
    uint64_t *slot_serials;
};

#define OB_SERIAL_STRIDE (OB_CACHE_LINE / sizeof(uint64_t))

static inline void ob_param_slot_changed(const ob_param_registry *reg, uint32_t slot)
{
    reg->slot_serials[(size_t)slot * OB_SERIAL_STRIDE]++;
}

/* The parameter for p, or NULL (no log) if p is zero or stale. Lock-free:
 * the tables only change outside recording. */
ob_param_info *ob_param_info_get(const ob_param_registry *reg, ob_param p);

#pragma GCC visibility pop

#endif /* OB_PARAMS_INTERNAL_H */
