/* ob_pipeline_manager.h — records one thread's commands with redundant-state filtering.
 *
 * Hieroglyph 3's PipelineManagerDX11: a pipeline manager wraps one command
 * buffer — the primary (immediate) or a secondary (deferred) — and is the only
 * code that calls vkCmd* for draws. Views and entities set desired state
 * (pipeline + program, vertex/index buffers, viewport, scissor) and issue draws;
 * the manager binds only what differs from the current state and counts
 * requested vs issued binds.
 *
 * Uniform data: at each draw the manager packs the program's uniform blocks
 * from its parameter slot into its uniform ring (one per frame slot) — only
 * when a mapped parameter changed since the block was last packed — and binds
 * them with dynamic offsets. Images, samplers and storage buffers go through
 * push descriptors; push-constant blocks are packed from parameters too.
 *
 * Command hash: every draw folds the state it draws with (stable ids and
 * uniform contents, never pointers or ring offsets) into a polynomial rolling
 * hash. Hashes of consecutive chunks combine (ob_cmd_hash_concat) into the hash
 * of the whole sequence, so a view recorded inline, or split into chunks
 * recorded by different threads, hashes the same.
 *
 * Lifecycle: create (render thread) → per frame: begin_frame(slot) → any number
 * of begin(cmd)/.../end() → destroy (after the device is idle).
 * Thread rule: a manager belongs to one thread at a time [worker: own slot only];
 * it only reads shared immutable data (programs, geometry, parameter registry).
 */
#ifndef OB_PIPELINE_MANAGER_H
#define OB_PIPELINE_MANAGER_H

#include "ob_params.h"
#include "ob_program.h"
#include "ob_resources.h"

typedef struct ob_pipeline_manager ob_pipeline_manager;

/* How a run of instances (entities of one material and mesh, in draw
 * order) becomes commands, with an instanced program (ob_program.instanced;
 * with a per-draw program each entity is its own draw either way). The
 * pixels and command hashes are the same on every path. */
typedef enum ob_instance_runs {
    /* Multi-draw indirect on a GPU that has it (multiDrawIndirect and
     * drawIndirectFirstInstance), one instanced draw on a CPU device
     * (lavapipe) or where it lacks them. $OB_INSTANCE_RUNS=instanced|multi|
     * direct overrides it. */
    OB_INSTANCE_RUNS_AUTO = 0,
    /* One vkCmdDrawIndexed of the run's count instances. On lavapipe the
     * run's draw setup is paid once: 0.6x the GPU time of one draw each at
     * 8 views x 10k. On an H100 small meshes drawn this way take 2x the
     * GPU time of one draw each (16.7 ms against 8.4 at 16 views x 100k):
     * the device walks a draw's instances far slower than separate draws. */
    OB_INSTANCE_RUNS_INSTANCED,
    /* One vkCmdDrawIndexedIndirect of count draws of one instance each,
     * their arguments written beside the per-instance blocks (firstInstance
     * picks the block): one command on the host, one draw an instance on
     * the device. On that H100: 14.8 ms of GPU time for an idle frame, and
     * a frame every 8.4-9.8 ms in flight with 16 workers (instanced 16.7).
     * Asked for where the device lacks either feature, runs are instanced
     * (logged when the renderer is created). */
    OB_INSTANCE_RUNS_MULTI_DRAW,
    /* One vkCmdDrawIndexed per instance, firstInstance picking its block:
     * a command per entity on the host, as without instancing, but no
     * push block written. On that H100, capping runs at one instance a
     * draw gave 9.37 ms of GPU time at 16 views x 100k (instanced 16.7,
     * multi-draw 14.8, push-block draws 8.44) for 67 ms of ST recording
     * against 44 instanced. Not chosen by AUTO: what it does in flight
     * was not measured. */
    OB_INSTANCE_RUNS_DIRECT,
} ob_instance_runs;

typedef struct ob_pipeline_manager_desc {
    ob_device *device;
    ob_param_registry *registry;
    uint32_t slot;              /* parameter slot: 0 immediate, i = worker i */
    uint32_t frames_in_flight;  /* 0 → 2 */
    uint64_t ring_chunk_size;   /* 0 → 4 MiB; the ring grows by chunks when full */
    /* The ring is written in host memory and read from a device-local copy
     * that ob_pipeline_manager_record_uploads makes, before the frame's
     * draws (ob_renderer_desc.ring_staging). */
    bool staged;
    /* How instance runs are drawn (ob_renderer_desc.instance_runs, which
     * the renderer resolves for the device; AUTO here is INSTANCED). */
    ob_instance_runs runs;
    const char *name;
} ob_pipeline_manager_desc;

typedef struct ob_cmd_hash {
    uint64_t hash;              /* polynomial rolling hash of the draw states */
    uint64_t scale;             /* OB_CMD_HASH_BASE ^ draw count (mod 2^64) */
    uint32_t draws;
} ob_cmd_hash;

#define OB_CMD_HASH_BASE 0x100000001b3ull
static inline ob_cmd_hash ob_cmd_hash_empty(void) { return (ob_cmd_hash){0, 1, 0}; }
/* Hash of sequence a followed by sequence b. */
static inline ob_cmd_hash ob_cmd_hash_concat(ob_cmd_hash a, ob_cmd_hash b)
{
    return (ob_cmd_hash){a.hash * b.scale + b.hash, a.scale * b.scale, a.draws + b.draws};
}

typedef struct ob_pipeline_manager_stats {
    uint32_t draws, dispatches;     /* draws: entities (an instanced draw counts each instance) */
    uint32_t draw_calls;            /* draw commands recorded */
    uint32_t instances;             /* instances drawn by instanced draws (of draws) */
    uint32_t multi_draw_runs;       /* of draw_calls: runs drawn as one multi-draw indirect */
    uint32_t pipeline_binds_requested, pipeline_binds_issued;
    uint32_t descriptor_binds_requested, descriptor_binds_issued;  /* set 0 (dynamic UBOs) */
    uint32_t push_descriptor_requested, push_descriptor_issued;     /* set 1 */
    uint32_t push_constant_requested, push_constant_issued;
    uint32_t vertex_binds_requested, vertex_binds_issued;
    uint32_t index_binds_requested, index_binds_issued;
    uint32_t blocks_packed, blocks_reused;
    uint32_t descriptor_sets_allocated;     /* set-0 sets written for the cache */
    uint32_t descriptor_set_cache_resets;   /* frame slots whose cache was emptied (past its bound) */
    uint64_t uniform_bytes;
    uint32_t skipped_draws;     /* draws refused: invalid handles, no pipeline */
    /* Set-0 sets the manager's frame slot keeps cached after the frame (the
     * largest of any manager in ob_frame_stats); at most 1024 carried into
     * the next frame of that slot, whatever programs came and went. */
    uint32_t descriptor_sets_held;
    /* The most instances one draw drew (a level: the largest of any
     * manager, or of a view's recording jobs). */
    uint32_t longest_run;
    /* Vertices the draws submitted: each draw's index (or vertex) count
     * times its instances; indirect draws are not counted (their counts
     * are on the device). With levels of detail, what they saved. */
    uint64_t vertices;
} ob_pipeline_manager_stats;

ob_pipeline_manager *ob_pipeline_manager_create(const ob_pipeline_manager_desc *desc,
                                                ob_result *out_result);
void ob_pipeline_manager_destroy(ob_pipeline_manager *pm);

/* Start of a frame in frame slot `slot` (its previous use has completed):
 * rewinds the slot's uniform ring. frame_serial increases every frame. */
void ob_pipeline_manager_begin_frame(ob_pipeline_manager *pm, uint32_t slot, uint64_t frame_serial);
/* A staged ring (desc.staged): records into cmd the copies of what this
 * frame wrote into the ring to the device-local buffers the draws read, and
 * returns the bytes copied (0, and nothing recorded, when unstaged or
 * unused). Called once the frame's recording is over, for a command buffer
 * that runs before the draws; the caller adds the barrier to the reads.
 * [render thread, the manager idle] */
uint64_t ob_pipeline_manager_record_uploads(ob_pipeline_manager *pm, VkCommandBuffer cmd);

/* Wrap cmd (already begun by the caller) and forget all current state. */
void ob_pipeline_manager_begin(ob_pipeline_manager *pm, VkCommandBuffer cmd);
/* Stop wrapping; returns the hash of what was drawn since begin. */
ob_cmd_hash ob_pipeline_manager_end(ob_pipeline_manager *pm);
VkCommandBuffer ob_pipeline_manager_command_buffer(const ob_pipeline_manager *pm);
ob_params *ob_pipeline_manager_params(ob_pipeline_manager *pm);

/* Desired state. The pipeline id is stable (for hashes). */
void ob_pipeline_manager_set_pipeline(ob_pipeline_manager *pm, VkPipeline pipeline, uint32_t pipeline_id,
                        const ob_program *program);
/* The per-draw transforms of the next draw only: world_normal[0..15] the
 * world matrix (column-major, camera-relative), [16..31] its normal matrix
 * (ob_mat4_normal_cofactor), all finite (the caller checks; the view loop
 * has them from ob_render_proxy_per_draw). The array is read by the next
 * draw, not copied: it must stay valid until then. A program whose push block is the
 * standard per-draw block (ob_program.push_world_normal) gets them straight
 * in its push constants and the parameters are left alone, so the bound sets
 * stay valid from one draw to the next; any other program gets the world
 * matrix as the WorldMatrix parameter (which derives the rest) before the
 * draw. */
void ob_pipeline_manager_set_world(ob_pipeline_manager *pm, const float world_normal[32]);
void ob_pipeline_manager_set_vertex_buffer(ob_pipeline_manager *pm, ob_buffer buf, uint64_t offset);
void ob_pipeline_manager_set_index_buffer(ob_pipeline_manager *pm, ob_buffer buf, uint64_t offset,
                            VkIndexType type);
void ob_pipeline_manager_set_viewport(ob_pipeline_manager *pm, float x, float y, float w, float h);
void ob_pipeline_manager_set_scissor(ob_pipeline_manager *pm, int32_t x, int32_t y, uint32_t w, uint32_t h);

/* What one draw of a geometry needs, by value: the geometry interface
 * fills it (ob_geometry_iface.draw_data) and the recorder draws from it.
 * Indexed when index_buffer.id != 0: count indices from first, each plus
 * vertex_offset; else count vertices from first. */
typedef struct ob_draw_data {
    ob_buffer vertex_buffer;
    uint64_t vertex_buffer_offset;
    ob_buffer index_buffer;
    uint64_t index_buffer_offset;
    VkIndexType index_type;
    uint32_t count;
    uint32_t instance_count;    /* 1 for a mesh; procedural geometry draws several */
    uint32_t first;
    int32_t vertex_offset;
} ob_draw_data;

/* Draws apply the desired state, then record. Uniform blocks and resources
 * are applied again only when the program or some parameter of the slot
 * changed since the last draw. They return OB_ERR_WRONG_STATE (no pipeline),
 * OB_ERR_INVALID_HANDLE (a stale buffer/image parameter),
 * OB_ERR_OUT_OF_DEVICE_MEMORY (ring growth failed) or OB_ERR_NON_FINITE (a
 * matrix derived from the world matrix given with ob_pipeline_manager_set_world is not
 * finite; logged by the parameters, the caller names the entity) and skip
 * the draw. */
ob_result ob_pipeline_manager_draw(ob_pipeline_manager *pm, uint32_t vertex_count, uint32_t instance_count,
                     uint32_t first_vertex, uint32_t first_instance);
ob_result ob_pipeline_manager_draw_indexed(ob_pipeline_manager *pm, uint32_t index_count,
                             uint32_t instance_count, uint32_t first_index,
                             int32_t vertex_offset, uint32_t first_instance);
/* d's buffers set, then d's draw; world_normal (may be NULL: the world of
 * an earlier set_world, or none) is what set_world takes, read during the
 * call only. The whole per-draw step of a view's draw list in one call. */
ob_result ob_pipeline_manager_draw_data(ob_pipeline_manager *pm, const ob_draw_data *d,
                                        const float world_normal[32]);
/* draw_count draws of VkDrawIndirectCommand (VkDrawIndexedIndirectCommand
 * for the indexed one, which needs an index buffer set) read from args at
 * offset, tightly packed. */
/* Whether the program set reads the per-draw block per instance
 * (ob_program.instanced): then draws go through draw_instances. */
bool ob_pipeline_manager_instanced(const ob_pipeline_manager *pm);
/* count instances of d, drawn as desc.runs says: one instanced draw, one
 * multi-draw indirect of one instance each (its arguments in the ring), or
 * a direct draw per instance. blocks holds count per-instance blocks
 * (OB_INSTANCE_FLOATS each, the world matrix's rows, as
 * ob_render_proxy_instance gives them, all finite), copied into this
 * frame's ring. The command hash folds one value per instance, the same
 * whatever the count, so a run cut into several draws hashes alike.
 * OB_ERR_WRONG_STATE when the program is not instanced. */
ob_result ob_pipeline_manager_draw_instances(ob_pipeline_manager *pm, const ob_draw_data *d,
                                             const float *blocks, uint32_t count);
/* The same for blocks of which all mirror or none does (mirrors says
 * which, as ob_det3_negative gives it for their rows, and as
 * ob_render_proxy.mirrors records it for an entity): the caller knows, so
 * no determinant is taken per instance. The same commands and hash. */
ob_result ob_pipeline_manager_draw_instances_facing(ob_pipeline_manager *pm,
                                                    const ob_draw_data *d, const float *blocks,
                                                    uint32_t count, bool mirrors);
ob_result ob_pipeline_manager_draw_indirect(ob_pipeline_manager *pm, ob_buffer args, uint64_t offset,
                              uint32_t draw_count);
ob_result ob_pipeline_manager_draw_indexed_indirect(ob_pipeline_manager *pm, ob_buffer args,
                                                    uint64_t offset, uint32_t draw_count);
ob_result ob_pipeline_manager_dispatch(ob_pipeline_manager *pm, uint32_t x, uint32_t y, uint32_t z);

/* Stats since the last ob_pipeline_manager_stats_take (which resets them). */
ob_pipeline_manager_stats ob_pipeline_manager_stats_take(ob_pipeline_manager *pm);
void ob_pipeline_manager_stats_add(ob_pipeline_manager_stats *into, const ob_pipeline_manager_stats *s);

#endif /* OB_PIPELINE_MANAGER_H */
