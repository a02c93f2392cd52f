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
 * engine's push block) + vkCmdDrawIndexed. Only recording is timed (begin to
 * end); nothing is submitted. Repeated `reps` times, median reported.
 *
 * Lifecycle: one call. Thread rule: render thread, outside a frame, with the
 * device idle (it makes and destroys Vulkan objects of its own).
 */
#ifndef OB_BENCH_RAW_H
#define OB_BENCH_RAW_H

#include "ob_demo.h"

typedef struct ob_bench_raw_result {
    uint32_t draws;
    uint32_t reps;
    uint32_t buffer_binds;     /* vertex + index binds per recording */
    double record_ms;          /* median recording time */
    double ns_per_draw;        /* record_ms / draws */
} ob_bench_raw_result;

/* Failure: an ob_result (shader compile, Vulkan creation; logged); nothing
 * stays allocated. A view with no draws is OB_ERR_INVALID_ARGUMENT. */
ob_result ob_bench_raw_measure(ob_demo *d, const ob_view *v, uint32_t reps,
                               ob_bench_raw_result *out);

#endif /* OB_BENCH_RAW_H */
