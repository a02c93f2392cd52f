/* ob_bench_raw.h — the raw Vulkan baseline: the same draws recorded the
 * minimal way, to price the engine's per-draw recording cost.
 *
 * From a view's draw list of the last frame (same objects, same order) it
 * takes each object's world matrix (camera-relative, as the engine computes
 * it) and normal matrix, and its geometry's buffers and index count. It
 * then records, on the render thread, into a secondary command buffer of
 * its own pool on the renderer's device (inheriting a dynamic-rendering
 * scope of the view's formats): one minimal pipeline (push constants only,
 * no descriptor sets) bound once, viewport and scissor once, vertex and
 * index buffers only when the geometry changes from the previous draw, and
 * per object vkCmdPushConstants (128 bytes: world + normal matrix, the
 * engine's push block; its world matrix with the view's view-projection
 * applied, so the triangles land where the engine's do) + vkCmdDrawIndexed.
 * A recording is timed begin to end and not submitted; ob_bench_raw_gpu_ms
 * records again and executes, for bare Vulkan's GPU time. The pool
 * allocates through counting callbacks, so a recording also says how many
 * host allocations the driver made for it, and how many vkCmd calls it
 * made.
 *
 * Lifecycle: create (from the view's draw list of the last frame) → record
 * once per measuring round, interleaved with the engine's frames → destroy.
 * Thread rule: render thread, outside a frame, with the device idle (it
 * makes, resets and destroys Vulkan objects of its own); no global state.
 */
#ifndef OB_BENCH_RAW_H
#define OB_BENCH_RAW_H

#include "ob_demo.h"

typedef struct ob_bench_raw ob_bench_raw;

/* One recording. */
typedef struct ob_bench_raw_sample {
    uint64_t ns;               /* vkBeginCommandBuffer to vkEndCommandBuffer */
    uint32_t draws;
    uint32_t buffer_binds;     /* vertex + index binds */
    uint32_t commands;         /* vkCmd* calls */
    uint64_t host_allocs;      /* driver allocations and reallocations through the pool */
} ob_bench_raw_sample;

/* What a run of recordings gave (filled by the caller from the samples). */
typedef struct ob_bench_raw_result {
    uint32_t draws;
    uint32_t reps;             /* measured rounds (each its fastest pass) */
    uint32_t buffer_binds;     /* vertex + index binds per recording */
    double record_ms;          /* median recording time */
    double ns_per_draw;        /* median over recordings of ns / draws */
    double commands_per_object;    /* vkCmd calls / draws */
    double host_allocs_per_object; /* median of host allocations / draws */
} ob_bench_raw_result;

/* Gathers v's draws and makes the pipeline and pool. Failure: NULL, the
 * reason in *out_result (shader compile, Vulkan creation; logged; a view
 * with no draws is OB_ERR_INVALID_ARGUMENT) and nothing stays allocated. */
ob_bench_raw *ob_bench_raw_create(ob_demo *d, const ob_view *v, ob_result *out_result);
/* Resets the pool and records every draw once, timed. Failure: OB_ERR_VULKAN
 * (logged); *out is then zero. */
ob_result ob_bench_raw_record(ob_bench_raw *raw, ob_bench_raw_sample *out);
/* The same draws instanced: the world matrices' rows (the engine's 48-byte
 * per-instance block) copied as instance data into a mapped buffer
 * (binding 1) at each recording, as a scene that moves must, the
 * view-projection pushed once, and a run of one mesh as one
 * vkCmdDrawIndexed. */
ob_result ob_bench_raw_record_instanced(ob_bench_raw *raw, ob_bench_raw_sample *out);
/* Records the per-draw or instanced loop again (untimed) and executes it
 * on the device into view-sized targets of its own, cleared first: *out_ms
 * is the GPU time between timestamps around the draws (NAN where the queue
 * has no timestamps). It prices what the driver does with the same draws
 * and triangles without an engine around them: instanced over per-draw is
 * what instancing gives on this device with the cheapest shaders, the
 * measure to read the engine's ratio against. Failure: the one-shot
 * submission's or the query's result (logged), *out_ms NAN. Submits and
 * waits: the recordings it makes are not timed. */
ob_result ob_bench_raw_gpu_ms(ob_bench_raw *raw, bool instanced, double *out_ms);
/* Destroys what create made. NULL ok. */
void ob_bench_raw_destroy(ob_bench_raw *raw);

#endif /* OB_BENCH_RAW_H */
