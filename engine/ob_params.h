/* ob_params.h — named render parameters with one value copy per recording slot.
 *
 * Hieroglyph 3's parameter manager in C. A registry maps a name ("ColorMap",
 * "WorldMatrix") to a typed parameter. Every parameter stores slot_count
 * copies of its value (slot 0 = the immediate manager, slot i = worker i),
 * each copy on its own cache lines, so each recording thread writes and reads
 * its own copy without locks and without false sharing. A manager
 * (ob_params) is the registry seen through one slot.
 *
 * Each (parameter, slot) keeps a value id that grows only when a write really
 * changes the stored bytes, so uniform data (ob_param_mapping) is repacked
 * only when something it maps changed in that slot.
 *
 * Built-in matrices: setting WorldMatrix, ViewMatrix or ProjMatrix recomputes
 * WorldViewMatrix, ViewProjMatrix, WorldViewProjMatrix and (for World)
 * NormalMatrix in the same slot (cglm conventions, column-major:
 * WorldViewProj = Proj * View * World). All seven start as identity. A
 * derived matrix may also be set directly; it then holds until one of its
 * sources changes in that slot. NormalMatrix's upper 3x3 is the cofactor
 * matrix of World's (det · inverse-transpose): finite even for a zero scale;
 * the shader normalizes. (When World's largest element is outside 2^±60 the
 * cofactors are taken of World scaled by a power of two, so they neither
 * overflow nor vanish: same direction, different length.)
 *
 * Lifecycle: ob_param_registry_create → register parameters → per frame
 * begin_recording / (set, get, pack on workers) / end_recording → destroy.
 * Mappings are created after the parameters they map and destroyed before
 * the registry.
 *
 * Thread rule:
 *   [render thread, not while recording]: registry create/destroy,
 *     ob_param_register, ob_params_init_*, begin/end_recording.
 *   [worker: own slot only]: ob_params_set_*, ob_params_get_*,
 *     ob_params_value_ptr/value_id, ob_params_pack_needed, ob_params_pack,
 *     ob_param_mapping_slot_user. No locks: a slot is written and read by one
 *     thread at a time, and the registry's tables do not change while
 *     recording (registration is refused then), so handle lookups are plain
 *     reads.
 *   [any thread, never concurrently with registration]: ob_param_find,
 *     ob_param_name/get_type/count/value_size, ob_param_mapping_create/destroy
 *     (a mapping may be built lazily while recording: it only reads the registry).
 *
 * Failure: every error returns an ob_result (or a zero handle / NULL / false),
 * logs one line with module "params" naming the parameter and slot, and
 * leaves stored values unchanged. Non-finite floats are refused: a NaN never
 * reaches a shader.
 */
#ifndef OB_PARAMS_H
#define OB_PARAMS_H

#include <stdbool.h>
#include <stdint.h>

#include "ob_core.h"
#include "ob_reflect.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ob_param_registry ob_param_registry;

/* Handle: pool index + generation like ob_pool ids; 0 is invalid. */
typedef struct ob_param { uint32_t id; } ob_param;

typedef enum ob_param_type {
    OB_PARAM_VEC4,
    OB_PARAM_MAT4,
    OB_PARAM_MAT4_ARRAY,
    OB_PARAM_TEXTURE,          /* ob_image */
    OB_PARAM_SAMPLER,          /* ob_sampler */
    OB_PARAM_UNIFORM_BUFFER,   /* ob_buffer */
    OB_PARAM_STORAGE_BUFFER,   /* ob_buffer */
    OB_PARAM_BYTES,            /* raw bytes of a registered size */
    OB_PARAM_TYPE_COUNT        /* not a type: returned by queries on a bad handle */
} ob_param_type;

/* Largest value one slot of one parameter may hold (bytes). */
#define OB_PARAM_MAX_VALUE_SIZE (1u << 20)
/* Most slots a registry may have (1 immediate + workers). */
#define OB_PARAM_MAX_SLOTS 256u

typedef struct ob_param_registry_desc {
    uint32_t slot_count;   /* 1 + worker count; 0 → 1; > OB_PARAM_MAX_SLOTS is an error */
} ob_param_registry_desc;

typedef struct ob_param_builtins {
    ob_param world, view, proj, world_view, view_proj, world_view_proj, normal;
} ob_param_builtins;

/* Stable name of a type ("mat4 array"); never NULL. [any thread] */
const char *ob_param_type_name(ob_param_type type);

/* Creates a registry with the built-in matrices registered. desc may be NULL
 * (defaults). Returns NULL and sets *out_result (OB_ERR_OUT_OF_RANGE for too
 * many slots, OB_ERR_OUT_OF_HOST_MEMORY) on failure. [render thread] */
ob_param_registry *ob_param_registry_create(const ob_param_registry_desc *desc,
                                            ob_result *out_result);
/* Frees the registry and every parameter's storage; NULL is a no-op.
 * Mappings made from it must be destroyed first. [render thread] */
void ob_param_registry_destroy(ob_param_registry *reg);
uint32_t ob_param_registry_slot_count(const ob_param_registry *reg);
/* Number of registered parameters (built-ins included). */
uint32_t ob_param_registry_param_count(const ob_param_registry *reg);
const ob_param_builtins *ob_param_registry_builtins(const ob_param_registry *reg);

/* Recording brackets (the renderer calls them around a frame's recording).
 * While recording, registration and init_* are refused (OB_ERR_WRONG_STATE),
 * which is what lets workers look up handles without a lock. [render thread] */
void ob_param_registry_begin_recording(ob_param_registry *reg);
void ob_param_registry_end_recording(ob_param_registry *reg);
bool ob_param_registry_is_recording(const ob_param_registry *reg);

/* Registers name (copied). count = element count for OB_PARAM_MAT4_ARRAY,
 * byte size for OB_PARAM_BYTES (both ≥ 1), ignored otherwise. Every slot
 * starts zeroed with value id 0. Re-registering a name with the same type and
 * count returns the existing handle; a different type or count is
 * OB_ERR_DUPLICATE. Other errors: OB_ERR_WRONG_STATE (recording),
 * OB_ERR_INVALID_ARGUMENT (empty name, bad type, zero count), OB_ERR_LIMIT
 * (value larger than OB_PARAM_MAX_VALUE_SIZE), OB_ERR_OUT_OF_HOST_MEMORY.
 * Returns the zero handle on failure. [render thread, not while recording] */
ob_param ob_param_register(ob_param_registry *reg, const char *name, ob_param_type type,
                           uint32_t count, ob_result *out_result);
/* The handle for name, or the zero handle if absent (no log). */
ob_param ob_param_find(const ob_param_registry *reg, const char *name);
/* Queries; on a zero/stale handle they log and return NULL / OB_PARAM_TYPE_COUNT / 0. */
const char *ob_param_name(const ob_param_registry *reg, ob_param p);
ob_param_type ob_param_get_type(const ob_param_registry *reg, ob_param p);
uint32_t ob_param_count(const ob_param_registry *reg, ob_param p);
uint32_t ob_param_value_size(const ob_param_registry *reg, ob_param p);   /* bytes per slot */

/* ------------------------------------------------------------------ managers */

/* The registry seen through one slot: a value type, cheap to copy. */
typedef struct ob_params {
    ob_param_registry *reg;
    uint32_t slot;
} ob_params;

/* Fills *out for slot; OB_ERR_OUT_OF_RANGE (logged) if slot ≥ slot_count,
 * OB_ERR_INVALID_ARGUMENT for NULL arguments. [any thread] */
ob_result ob_params_manager(ob_param_registry *reg, uint32_t slot, ob_params *out);

/* set_*: write the manager's own slot. [worker: own slot only]
 * Errors (value untouched, one log line): OB_ERR_INVALID_HANDLE,
 * OB_ERR_TYPE_MISMATCH, OB_ERR_OUT_OF_RANGE (slot, array length),
 * OB_ERR_NON_FINITE (any NaN/Inf in the floats, or in a derived matrix it
 * would produce), OB_ERR_INVALID_ARGUMENT (NULL data, bytes of the wrong size). */
ob_result ob_params_set_vec4(ob_params *pm, ob_param p, const float v[4]);
/* Matrices are 16 floats, column-major like cglm's mat4 (pass &m[0][0]). */
ob_result ob_params_set_mat4(ob_params *pm, ob_param p, const float *m);
/* Writes elements [0, count); count > registered is OB_ERR_OUT_OF_RANGE. */
ob_result ob_params_set_mat4_array(ob_params *pm, ob_param p, const float *m, uint32_t count);
/* Writes elements [first, first + count), e.g. one bone of a palette. */
ob_result ob_params_set_mat4_array_at(ob_params *pm, ob_param p, uint32_t first,
                                      const float *m, uint32_t count);
ob_result ob_params_set_texture(ob_params *pm, ob_param p, ob_image img);
ob_result ob_params_set_sampler(ob_params *pm, ob_param p, ob_sampler s);
/* For OB_PARAM_UNIFORM_BUFFER and OB_PARAM_STORAGE_BUFFER parameters. */
ob_result ob_params_set_buffer(ob_params *pm, ob_param p, ob_buffer b);
/* size must equal the registered size. */
ob_result ob_params_set_bytes(ob_params *pm, ob_param p, const void *data, uint32_t size);

/* init_*: the same write into every slot (a default every manager sees).
 * All slots are checked before any is written. Also OB_ERR_WRONG_STATE while
 * recording. [render thread, not while recording] */
ob_result ob_params_init_vec4(ob_param_registry *reg, ob_param p, const float v[4]);
ob_result ob_params_init_mat4(ob_param_registry *reg, ob_param p, const float *m);
ob_result ob_params_init_mat4_array(ob_param_registry *reg, ob_param p, const float *m,
                                    uint32_t count);
ob_result ob_params_init_texture(ob_param_registry *reg, ob_param p, ob_image img);
ob_result ob_params_init_sampler(ob_param_registry *reg, ob_param p, ob_sampler s);
ob_result ob_params_init_buffer(ob_param_registry *reg, ob_param p, ob_buffer b);
ob_result ob_params_init_bytes(ob_param_registry *reg, ob_param p, const void *data,
                               uint32_t size);

/* get_*: read the manager's own slot into the last argument. On failure (same
 * errors as set_*) the output is not written. [worker: own slot only] */
ob_result ob_params_get_vec4(const ob_params *pm, ob_param p, float out_v[4]);
ob_result ob_params_get_mat4(const ob_params *pm, ob_param p, float *out_m);
/* Reads elements [0, count); count > registered is OB_ERR_OUT_OF_RANGE. */
ob_result ob_params_get_mat4_array(const ob_params *pm, ob_param p, uint32_t count,
                                   float *out_m);
ob_result ob_params_get_mat4_array_at(const ob_params *pm, ob_param p, uint32_t first,
                                      uint32_t count, float *out_m);
ob_result ob_params_get_texture(const ob_params *pm, ob_param p, ob_image *out_img);
ob_result ob_params_get_sampler(const ob_params *pm, ob_param p, ob_sampler *out_s);
ob_result ob_params_get_buffer(const ob_params *pm, ob_param p, ob_buffer *out_b);
/* size must equal the registered size. */
ob_result ob_params_get_bytes(const ob_params *pm, ob_param p, uint32_t size, void *out_data);

/* The slot's stored value (value_size bytes, 32-byte aligned), for packing
 * without a copy; NULL (logged) on a bad handle or slot. Valid until the
 * registry is destroyed. */
const void *ob_params_value_ptr(const ob_params *pm, ob_param p);
/* The slot's value id: 0 = never written; grows by one per real change. */
uint64_t ob_params_value_id(const ob_params *pm, ob_param p);
/* Grows by one per real change of any value in the slot (a write of an equal
 * value changes nothing): equal serials mean every value is as it was. 0 for
 * a NULL manager or bad slot. [worker: own slot only] */
uint64_t ob_params_serial(const ob_params *pm);

/* ------------------------------------------------------------------ packing */

typedef struct ob_param_mapping ob_param_mapping;

/* Maps a reflected block's members to parameters by name: vec4 ↔
 * OB_MEMBER_VEC4, mat4 ↔ OB_MEMBER_MAT4, mat4 array ↔ OB_MEMBER_MAT4 array
 * with 1 ≤ array_len ≤ registered count and array_stride ≥ 64, bytes ↔ any
 * member whose size equals the registered size. A member with no parameter
 * of its name, of another type or size, or reaching past the block, is
 * reported once here (OB_LOG_W naming shader_name and the member) and left
 * unmapped (packing leaves its bytes zero); that is not a failure. Returns
 * NULL and sets *out_result on bad arguments (NULL/empty layout) or
 * OB_ERR_OUT_OF_HOST_MEMORY. [any thread, never concurrently with registration] */
ob_param_mapping *ob_param_mapping_create(ob_param_registry *reg, const ob_block_layout *layout,
                                          const char *shader_name, ob_result *out_result);
/* NULL is a no-op. No slot may be packing it. */
void ob_param_mapping_destroy(ob_param_mapping *map);
uint32_t ob_param_mapping_block_size(const ob_param_mapping *map);
uint32_t ob_param_mapping_unmapped_count(const ob_param_mapping *map);
uint32_t ob_param_mapping_mapped_count(const ob_param_mapping *map);

/* True when a mapped member is the world matrix or one derived from it
 * (world-view, world-view-projection, normal): the block changes per draw. */
bool ob_param_mapping_reads_world(const ob_param_mapping *map);
/* True when the block is exactly the standard per-draw block: 128 bytes,
 * WorldMatrix at 0 and NormalMatrix at 64 and nothing else (materials/
 * shaders/common.glsl's PerDraw). The pipeline manager fills such a block
 * from ob_pipeline_manager_set_world directly. */
bool ob_param_mapping_is_world_normal(const ob_param_mapping *map);

/* True when some mapped parameter's value id in pm's slot differs from the
 * one last packed for that slot, or the slot never packed. False (logged) for
 * a bad slot or mapping of another registry. [worker: own slot only] */
bool ob_params_pack_needed(const ob_params *pm, const ob_param_mapping *map);
/* When pack is needed or force is set: writes block_size bytes at dst (each
 * mapped member at its reflected offset, mat4 arrays at array_stride, every
 * other byte zero), records the packed value ids for the slot and returns
 * true. Returns false when nothing was written (no change, or an error,
 * which is logged). [worker: own slot only] */
bool ob_params_pack(const ob_params *pm, ob_param_mapping *map, void *dst, bool force);
/* A per-slot user word kept with the mapping (the pipeline manager keeps the
 * last ring offset there); starts at 0. NULL (logged) if slot is out of range.
 * [worker: own slot only] */
uint64_t *ob_param_mapping_slot_user(ob_param_mapping *map, uint32_t slot);

#ifdef __cplusplus
}
#endif
#endif /* OB_PARAMS_H */
