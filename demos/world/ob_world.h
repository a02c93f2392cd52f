/* ob_world.h — the one set-up of a world to render in, for the programs and
 * tests that render scenes they build in code: an ob_stack
 * (views/scene/ob_stack.h) under short names, optionally the box, sphere and
 * plane most test scenes are made of, helpers to add materials, entities
 * and lights and to aim the camera, frames in a given threading mode, the
 * final image read back, and lookups in a frame's stats.
 *
 * The demo runner (demos/app/ob_demo.h), the tests' worlds
 * (tests/harness/ob_test_world.h: every step must succeed;
 * ob_test_stack.h: steps may fail under fault injection) and the stability
 * cases (demos/stability/ob_stab_world.h: rows and timings) are thin layers
 * over it that add only their error policy and their bookkeeping.
 *
 * Errors are sticky: the first failing helper stores its ob_result in
 * w->err and what failed in w->err_what ("entity 'ball'"); every later
 * helper does nothing and returns NULL (a frame returns w->err). Frames
 * are the exception to stickiness: a failed frame returns its result
 * without storing it, so a fault-injection walk can go on rendering. The
 * world logs nothing itself beyond what the engine logs; a layer's error
 * policy is desc.on_error (fail the test, log the case's failure).
 *
 * Lifecycle: ob_world_create → helpers and frames → ob_world_destroy (also
 * after a failed create). Thread rule: [render thread] (the renderer's).
 */
#ifndef OB_WORLD_H
#define OB_WORLD_H

#include "ob_stack.h"

typedef struct ob_world ob_world;

/* Called at a helper's failure (the first only: later helpers do nothing)
 * and at every failed frame or read, with the result and what failed. It
 * may not return (a test's fail_msg). */
typedef void (*ob_world_error_fn)(ob_world *w, ob_result r, const char *what, void *user);

typedef struct ob_world_desc {
    ob_stack_desc stack;       /* as given: ob_world_desc_small() fills the small scene's */
    bool primitives;           /* box (half-size 0.5), sphere (radius 0.5, 24 x 16), plane
                                  (20 x 20), and the camera at (0, 2, 5) aimed at the origin */
    ob_world_error_fn on_error;   /* NULL: failures are only returned and stored */
    void *on_error_user;
} ob_world_desc;

/* The small scene the tests and the stability cases render: 160 x 120,
 * environment maps 64, shadow maps 256, cleared to (0.1, 0.2, 0.3, 1), a
 * camera of fovy 1 and near plane 0.1, with the primitives. */
ob_world_desc ob_world_desc_small(const char *app_name);

struct ob_world {
    ob_stack *stack;           /* owns everything below but the pixels */
    /* The stack's objects under their short names (borrowed, read-only). */
    ob_renderer *r;
    ob_device *dev;
    ob_effect_context *fx;
    ob_material_library *lib;
    ob_views *views;
    ob_scene *scene;
    ob_node *camera;
    ob_perspective_view *main;
    ob_composite_view *composite;
    ob_overlay_view *overlay;  /* NULL unless desc.stack.overlay */
    ob_geometry *box, *sphere, *plane;   /* desc.primitives */
    uint32_t width, height;    /* the final image's size: as created, then at the last read */
    uint8_t *pixels;           /* the last read (malloc'ed; not Obelisk's heap); NULL before */
    uint64_t frames;           /* frames begun */
    ob_result err;             /* the first failure, sticky */
    char err_what[96];
    ob_heap_stats heap_at_create;
    ob_world_error_fn on_error;
    void *on_error_user;
};

/* Failure: the failing step's result, also in w->err (w->err_what names
 * the step); ob_world_destroy is still due. */
ob_result ob_world_create(ob_world *w, const ob_world_desc *desc);

/* What a world left behind: validation messages over its life, and
 * Obelisk's heap blocks and bytes still held after it was destroyed
 * (nonzero: a leak, or memory kept in a list until exit). */
typedef struct ob_world_leftovers {
    uint32_t validation_errors, validation_warnings;
    int64_t heap_blocks, heap_bytes;
} ob_world_leftovers;

/* Waits idle (a lost device is fine) and destroys all. Safe on a world
 * whose create failed, on a zeroed one and twice. */
ob_world_leftovers ob_world_destroy(ob_world *w);

/* Geometry from a mesh (the world owns it; the caller releases the mesh). */
ob_geometry *ob_world_geometry(ob_world *w, const ob_mesh *mesh, const char *name);
ob_material *ob_world_material_desc(ob_world *w, const ob_material_desc *md);
/* A material without specular highlight. */
ob_material *ob_world_material(ob_world *w, const char *name, ob_material_kind kind, float r,
                               float g, float b, bool casts_shadows);
/* An entity drawing g with m at (x, y, z) under parent (NULL → root). */
ob_node *ob_world_entity(ob_world *w, ob_node *parent, const char *name, ob_geometry *g,
                         ob_material *m, double x, double y, double z);
/* A white light at (x, y, z) named "sun" (directional) or "lamp" (point or
 * spot); directional and spot lights aimed at the origin. */
ob_node *ob_world_light(ob_world *w, ob_light_type type, bool shadows, float intensity, double x,
                        double y, double z);
/* The camera at the eye, aimed at the target, up +Y. */
void ob_world_look(ob_world *w, double ex, double ey, double ez, double tx, double ty, double tz);

/* One frame in `mode` with `workers` active (0 = all), dt = 1/60 after the
 * first; `extra` views are pre-drawn in the same frame after the final one
 * (so they execute before it). _begin updates, begins the frame and runs
 * the PreRender; _end (only after a successful _begin) records, submits
 * and waits idle. Each returns the first failure of its steps. */
ob_result ob_world_frame(ob_world *w, ob_threading mode, uint32_t workers, ob_view *const *extra,
                         uint32_t extra_count);
ob_result ob_world_frame_begin(ob_world *w, ob_threading mode, uint32_t workers,
                               ob_view *const *extra, uint32_t extra_count);
ob_result ob_world_frame_end(ob_world *w);
/* The last frame's stats (GPU times included once waited for). */
const ob_frame_stats *ob_world_stats(const ob_world *w);

/* Reads the final image into w->pixels and returns it; when the final
 * image was resized, w->width, w->height and w->pixels follow it first.
 * NULL after a failure (stored). */
const uint8_t *ob_world_read(ob_world *w);
/* Pixel (x, y) of the last read, RGBA. */
const uint8_t *ob_world_pixel(const ob_world *w, uint32_t x, uint32_t y);
/* A malloc'ed copy (free() it) of the last read image; NULL when there is
 * none or no memory. _snapshot reads first. */
uint8_t *ob_world_copy(const ob_world *w);
uint8_t *ob_world_snapshot(ob_world *w);

/* ---- a frame's stats by view name (NULL-tolerant: st may be NULL) ---- */

/* The stats of the view called name (NULL if it did not run). */
const ob_view_stats *ob_world_view_stats(const ob_frame_stats *st, const char *name);
/* Its position in st->views (execution order), -1 if absent. */
int ob_world_view_index(const ob_frame_stats *st, const char *name);
/* The skip reason recorded for name, OB_SKIP_NONE if none. */
ob_skip_reason ob_world_skip_reason(const ob_frame_stats *st, const char *name);
/* The cascades of a directional light's shadow ("shadow:<light>:c<i>")
 * that ran: how many, and their draws summed into *out_draws (may be NULL). */
uint32_t ob_world_shadow_cascades(const ob_frame_stats *st, const char *light, uint32_t *out_draws);
/* Views of a type that ran; skip entries with a reason. */
uint32_t ob_world_count_views(const ob_frame_stats *st, ob_view_type type);
uint32_t ob_world_count_skipped(const ob_frame_stats *st, ob_skip_reason reason);

/* ---- RGBA8 images of n pixels (NULL-tolerant: 0 when either is NULL) ---- */

/* The largest channel difference, alpha included. */
uint32_t ob_rgba_max_diff(const uint8_t *a, const uint8_t *b, uint32_t n);
/* Pixels with some channel differing by more than tol. */
uint32_t ob_rgba_diff_count(const uint8_t *a, const uint8_t *b, uint32_t n, uint32_t tol);
/* Pixels black in b where a is not (how a NaN colour shows in UNORM8). */
uint32_t ob_rgba_nan_black(const uint8_t *a, const uint8_t *b, uint32_t n);

#endif /* OB_WORLD_H */
