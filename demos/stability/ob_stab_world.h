/* ob_stab_world.h — what the stability cases share (internal to
 * demos/stability): the run context (rows, expected log lines, frame
 * times) and the cases' world: the small world of demos/world/ob_world.h
 * (what the tests render in too) with the run's worker count, frames timed
 * for the report, the validation layer's counts added to the run, and the
 * first failure logged.
 *
 * The cases build with the world's helpers (ob_world_entity(&w.world, ...),
 * ob_world_material, ob_world_light, ob_world_look) and use its stats
 * lookups and image comparisons (ob_world_view_stats, ob_rgba_*). Errors
 * are sticky (the world's rule): the first failing call stores its
 * ob_result in w->world.err (logged by the engine and here, naming what
 * failed) and every later helper does nothing and returns NULL / 0; a
 * failed frame is sticky here too. The node setters accept NULL. A case
 * builds its scene, renders, then checks w->world.err once.
 *
 * Thread rule: [render thread]. The log sink the context installs may be called
 * from any thread (workers, the validation callback); it locks.
 */
#ifndef OB_STAB_WORLD_H
#define OB_STAB_WORLD_H

#include <pthread.h>

#include "ob_stability.h"
#include "ob_world.h"

#define OB_STAB_MAX_NEEDLES 8
#define OB_STAB_LOG_LINES 48
#define OB_STAB_MAX_TIMES 256

/* Expected log lines: those containing one of the needles while a case
 * expects them. Everything else goes to the previous sink. */
typedef struct ob_stab_log {
    pthread_mutex_t lock;
    ob_log_fn prev;
    void *prev_user;
    const char *needles[OB_STAB_MAX_NEEDLES];
    uint32_t needle_count;
    char lines[OB_STAB_LOG_LINES][192];
    uint32_t line_count;
    uint64_t expected[4];          /* by level */
} ob_stab_log;

typedef struct ob_stab_ctx {
    ob_stability *out;
    bool quick;
    uint32_t workers;
    ob_stab_log log;
    double first_ms[OB_STAB_MAX_TIMES], steady_ms[OB_STAB_MAX_TIMES];
    uint32_t first_count, steady_count;
} ob_stab_ctx;

/* Adds a row; ok: the case's other checks held. Verdict: fail when !ok or
 * the error is NAN, else measured only when the bound is NAN, else pass when
 * error <= bound. ms NAN: none. Failure: out of memory (logged). */
ob_result ob_stab_add(ob_stab_ctx *c, const char *name, const char *measure, double error,
                      const char *unit, double bound, bool ok, double ms, const char *detail_fmt,
                      ...) __attribute__((format(printf, 9, 10)));
/* Median wall time of the frames rendered since the last call (those after
 * each world's first frame when there are any, else all); NAN if none. */
double ob_stab_take_ms(ob_stab_ctx *c);
/* Lines containing one of needles (NULL-terminated, static strings) are
 * expected from now on, captured and not printed; NULL stops expecting.
 * Clears the captured lines either way. */
void ob_stab_expect(ob_stab_ctx *c, const char *const *needles);
/* A captured line contains every string of the NULL-terminated list. */
bool ob_stab_log_has(ob_stab_ctx *c, const char *needle, ...);
/* Expected lines logged at ERROR so far in the run. */
uint64_t ob_stab_expected_errors(ob_stab_ctx *c);

typedef struct ob_stab_world_desc {
    uint32_t width, height;        /* 0 → 160 x 120 */
    uint32_t env_map_size;         /* 0 → 64 */
    uint32_t shadow_map_size;      /* 0 → 256 */
    float clear_color[4];          /* alpha 0 → (0.1, 0.2, 0.3, 1) */
    float znear;                   /* 0 → 0.1 (camera fovy 1) */
} ob_stab_world_desc;

typedef struct ob_stab_world {
    ob_world world;                /* world.stack is NULL once destroyed */
    ob_stab_ctx *ctx;
    uint32_t frames;               /* frames rendered (the first is timed apart) */
} ob_stab_world;

/* Failure is stored in w->world.err (and returned); destroy is then still due. */
ob_result ob_stab_world_create(ob_stab_world *w, ob_stab_ctx *c, const ob_stab_world_desc *desc);
/* Waits idle, adds the validation layer's counts to the run, frees all. */
void ob_stab_world_destroy(ob_stab_world *w);

/* NULL-tolerant setters. */
void ob_stab_position(ob_node *n, double x, double y, double z);
void ob_stab_scale(ob_node *n, float x, float y, float z);
void ob_stab_hide(ob_node *n, bool hidden);

/* One frame in mode, waited for; `extra` views are pre-drawn after the
 * final one. Returns its stats, NULL after a failure. */
const ob_frame_stats *ob_stab_frame(ob_stab_world *w, ob_threading mode);
const ob_frame_stats *ob_stab_frame_with(ob_stab_world *w, ob_threading mode,
                                         ob_view *const *extra, uint32_t extra_count);
/* Reads the final image into w->world.pixels and returns an ob_malloc'ed
 * copy (ob_free it); NULL after a failure. */
uint8_t *ob_stab_snapshot(ob_stab_world *w);
/* Renders one frame single-threaded and returns its snapshot. */
uint8_t *ob_stab_render(ob_stab_world *w, const ob_frame_stats **out_stats);

/* The cases, in report order. Each adds its rows; a returned failure ends
 * the run. */
ob_result ob_stab_depth_precision(ob_stab_ctx *c);
ob_result ob_stab_large_coordinates(ob_stab_ctx *c);
ob_result ob_stab_scene_matrices(ob_stab_ctx *c);
ob_result ob_stab_scale_invariance(ob_stab_ctx *c);
ob_result ob_stab_deep_hierarchy(ob_stab_ctx *c, uint32_t levels);
ob_result ob_stab_long_run_rotation(ob_stab_ctx *c);
ob_result ob_stab_zero_scale(ob_stab_ctx *c);
ob_result ob_stab_flattened_box(ob_stab_ctx *c);
ob_result ob_stab_up_parallel(ob_stab_ctx *c);
ob_result ob_stab_refused_views(ob_stab_ctx *c);
ob_result ob_stab_empty_scene(ob_stab_ctx *c);
ob_result ob_stab_light_off(ob_stab_ctx *c);
ob_result ob_stab_non_finite_transform(ob_stab_ctx *c);
ob_result ob_stab_non_finite_light_camera(ob_stab_ctx *c);
ob_result ob_stab_non_finite_material(ob_stab_ctx *c);
ob_result ob_stab_non_finite_parameter(ob_stab_ctx *c);
ob_result ob_stab_beyond_float(ob_stab_ctx *c);
ob_result ob_stab_views_64(ob_stab_ctx *c);
ob_result ob_stab_view_cap(ob_stab_ctx *c);
ob_result ob_stab_env_recursion(ob_stab_ctx *c);
ob_result ob_stab_many_objects(ob_stab_ctx *c);
ob_result ob_stab_no_casters(ob_stab_ctx *c);

#endif /* OB_STAB_WORLD_H */
