/* ob_bench_scene.h — the scenes obelisk-bench renders, and one frame of them.
 *
 * Two kinds, both built on an initialised ob_demo (renderer, materials,
 * views, camera, main view, composite):
 *   sweep   N lit objects (four shapes, eight materials) orbiting and
 *           spinning over a ground plane, one directional light (no
 *           shadows) and two point lights. The ring of objects grows with
 *           sqrt(N) so the density stays that of obelisk-mirror. V "views"
 *           = V perspective views of the same scene from V cameras that
 *           stand a little behind the centre and look outward in V evenly
 *           spaced directions, each framing a wedge of the ring (a view
 *           draws about a third of the objects and culls the rest): the
 *           demo's main view (shown by the composite) plus V-1 extra
 *           perspective views queued in the frame before it.
 *   mirror  obelisk-mirror's scene itself (demos/scenes/ob_mirror_scene.h:
 *           three reflective spheres whose dual-paraboloid environment maps
 *           see each other, N orbiting objects, a shadow-casting sun, two
 *           point lights, a particle fountain); the camera circles slowly.
 *
 * Lifecycle: ob_demo_init → ob_bench_scene_build → frames → (ob_renderer_wait_idle)
 * ob_bench_scene_release → ob_demo_shutdown.
 * Thread rule: render thread only. Fixed seeds: the same desc gives the same
 * scene, and the same sequence of frame() calls the same images.
 */
#ifndef OB_BENCH_SCENE_H
#define OB_BENCH_SCENE_H

#include "ob_demo.h"

#define OB_BENCH_MAX_VIEWS 32

typedef enum ob_bench_scene_kind {
    OB_BENCH_SCENE_SWEEP = 0,
    OB_BENCH_SCENE_MIRROR,
} ob_bench_scene_kind;

typedef struct ob_bench_scene_desc {
    ob_bench_scene_kind kind;
    uint32_t objects;
    uint32_t views;          /* sweep: perspective views (0 → 1), at most OB_BENCH_MAX_VIEWS */
    uint32_t seed;
} ob_bench_scene_desc;

typedef struct ob_bench_scene {
    ob_demo *demo;
    ob_bench_scene_kind kind;
    uint32_t view_count;
    ob_view *views[OB_BENCH_MAX_VIEWS];                 /* [0] = the demo's main view */
    ob_perspective_view *extra[OB_BENCH_MAX_VIEWS];     /* [0] unused */
    ob_node *cameras[OB_BENCH_MAX_VIEWS];               /* [0] = the demo's camera */
    double ring_radius;      /* outer radius of the object ring */
    double time;             /* scene time of the last frame */
} ob_bench_scene;

/* Builds the scene into d (geometry and materials owned by d and its
 * library; extra views owned by s). Failure: an ob_result, logged; what was
 * made is released by ob_bench_scene_release + ob_demo_shutdown. */
ob_result ob_bench_scene_build(ob_bench_scene *s, ob_demo *d, const ob_bench_scene_desc *desc);
/* Destroys the extra views (the device must be idle). Zeroed s ok. */
void ob_bench_scene_release(ob_bench_scene *s);

/* Moves the scene on by dt (controllers, transforms, the mirror scene's
 * camera) through ob_renderer_update_scene: on the renderer's worker pool
 * as the threading mode set for the next frame says. Its figures go to the
 * next frame's stats (update_ns, cpu_*). Outside a frame. Returns the
 * update's result. */
ob_result ob_bench_scene_advance(ob_bench_scene *s, double dt);

/* One frame. advance: ob_bench_scene_advance(s, dt) first, so the frame's
 * stats carry the update; otherwise render the last state again without
 * touching the scene (an update with dt 0 would still renormalize
 * rotations and change low bits of the matrices). The views get (time, dt)
 * either way. Then begin, pre-render every view, end (submit). The caller
 * picks the threading mode before. Returns the first failing result
 * (logged by the engine). */
ob_result ob_bench_scene_frame(ob_bench_scene *s, bool advance, double dt);

#endif /* OB_BENCH_SCENE_H */
