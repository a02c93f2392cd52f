/* ob_test_world.h — a whole engine stack for gpu tests, built on ob_stack
 * (views/scene/ob_stack.h): renderer (validation on), effects, materials, views, a
 * scene with a camera, the main perspective view and the composite final
 * target; a box, a sphere and a plane; helpers to add entities and lights,
 * run frames in a given threading mode and read the image back.
 *
 * Every helper fails the running cmocka test on error, so tests read as the
 * scenario they check. ob_test_world_destroy asserts the validation layer
 * stayed silent and Obelisk's heap is back where it was.
 *
 * Lifecycle: ob_test_world_create → helpers and frames →
 * ob_test_world_destroy. Thread rule: the test's thread only.
 */
#ifndef OB_TEST_WORLD_H
#define OB_TEST_WORLD_H

#include "ob_stack.h"
#include "ob_test.h"

typedef struct ob_test_world_desc {
    uint32_t workers;          /* 0 → 4 */
    uint32_t width, height;    /* 0 → 160 x 120 */
    uint32_t env_map_size;     /* 0 → 64 */
    uint32_t shadow_map_size;  /* 0 → 256 */
    float clear_color[4];      /* zero → opaque dark blue (0.1, 0.2, 0.3, 1) */
    uint32_t chunk_draws;      /* renderer's draws per job; 0 → the renderer's default */
    uint32_t parallel_grain;   /* renderer's entities per parallel-loop index; 0 → default */
    uint32_t msaa;             /* main view's samples per pixel; 0 → 1 */
} ob_test_world_desc;

typedef struct ob_test_world {
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
    ob_geometry *box, *sphere, *plane;
    uint32_t width, height;
    uint8_t *pixels;           /* width * height * 4, filled by ob_test_world_read */
    ob_heap_stats heap_at_create;   /* destroy checks Obelisk's heap is back to it */
} ob_test_world;

void ob_test_world_create(ob_test_world *w, const ob_test_world_desc *desc);
void ob_test_world_destroy(ob_test_world *w);

/* Geometry from a mesh (the world owns it; the caller releases the mesh). */
ob_geometry *ob_test_world_geometry(ob_test_world *w, const ob_mesh *mesh, const char *name);
ob_material *ob_test_world_material(ob_test_world *w, ob_material_kind kind, float r, float g,
                                    float b, bool casts_shadows);
ob_node *ob_test_world_entity(ob_test_world *w, ob_node *parent, const char *name, ob_geometry *g,
                              ob_material *m, double x, double y, double z);
ob_node *ob_test_world_light(ob_test_world *w, ob_light_type type, bool shadows, float intensity,
                             double x, double y, double z);
void ob_test_world_look(ob_test_world *w, double ex, double ey, double ez, double tx, double ty,
                        double tz);

/* One frame (dt = 1/60 after the first) in `mode` with `workers` active
 * (0 = all), waited for; returns its final stats (GPU times included). */
const ob_frame_stats *ob_test_world_frame(ob_test_world *w, ob_threading mode, uint32_t workers);
/* Like ob_test_world_frame, and pre-draws `extra` views in the same frame
 * after the final one (so they execute before it). */
const ob_frame_stats *ob_test_world_frame_with(ob_test_world *w, ob_threading mode,
                                               uint32_t workers, ob_view *const *extra,
                                               uint32_t extra_count);
/* Read the final image into w->pixels; returns it. When the final image
 * was resized, w->width, w->height and w->pixels follow it first. */
const uint8_t *ob_test_world_read(ob_test_world *w);
/* Pixel (x, y) of the last read, RGBA. */
const uint8_t *ob_test_world_pixel(const ob_test_world *w, uint32_t x, uint32_t y);
/* A heap copy (free()) of the last read image. */
uint8_t *ob_test_world_copy(const ob_test_world *w);
/* Pixels of two RGBA8 images with some channel differing by more than tol. */
uint32_t ob_test_image_diff_count(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h,
                                  uint32_t tol);
/* The stats of the view called name in st (NULL if it did not run). */
const ob_view_stats *ob_test_view_stats(const ob_frame_stats *st, const char *name);
/* The skip reason recorded for name, OB_SKIP_NONE if none. */
ob_skip_reason ob_test_skip_reason(const ob_frame_stats *st, const char *name);

/* Read the final image and return a copy (free() it). */
uint8_t *ob_test_world_snapshot(ob_test_world *w);
/* Position of the view called name in st->views (execution order), -1 if absent. */
int ob_test_view_index(const ob_frame_stats *st, const char *name);
/* Views of a type that ran in st. */
uint32_t ob_test_count_views(const ob_frame_stats *st, ob_view_type type);
/* Skip entries of st with that reason. */
uint32_t ob_test_count_skipped(const ob_frame_stats *st, ob_skip_reason reason);

#endif
