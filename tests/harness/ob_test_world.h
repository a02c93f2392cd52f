/* ob_test_world.h — the world of gpu tests: an ob_world
 * (demos/world/ob_world.h: the stack, the box, sphere and plane, helpers,
 * frames, read-back and stats lookups) with the validation layer on, where
 * every step must succeed.
 *
 * The tests call the world's helpers (ob_world_entity, ob_world_light,
 * ob_world_read, ob_world_view_stats, ob_rgba_diff_count, ...); any failure
 * fails the running cmocka test, so tests read as the scenario they check.
 * ob_test_world_destroy asserts the validation layer stayed silent and
 * Obelisk's heap is back where it was.
 *
 * Lifecycle: ob_test_world_create → helpers and frames →
 * ob_test_world_destroy. Thread rule: the test's thread only.
 */
#ifndef OB_TEST_WORLD_H
#define OB_TEST_WORLD_H

#include "ob_test.h"
#include "ob_world.h"

typedef struct ob_test_world_desc {
    uint32_t workers;          /* 0 → 4 */
    uint32_t width, height;    /* 0 → 160 x 120 */
    uint32_t env_map_size;     /* 0 → 64 */
    uint32_t shadow_map_size;  /* 0 → 256 */
    float clear_color[4];      /* zero → opaque dark blue (0.1, 0.2, 0.3, 1) */
    uint32_t chunk_draws;      /* renderer's draws per job; 0 → the renderer's default */
    uint32_t parallel_grain;   /* renderer's entities per parallel-loop index; 0 → default */
    uint32_t msaa;             /* main view's samples per pixel; 0 → 1 */
    ob_env_map_kind env_map_kind;  /* 0 → paraboloid */
    ob_ring_staging ring_staging;  /* 0 → the device's (AUTO) */
    ob_instance_runs instance_runs;  /* 0 → the device's (AUTO) */
    const char *cache_dir;     /* pipeline cache folder; NULL → the effect context's default */
    /* The application's instance and device (ob_test_adopt.h) for walks
     * that start many stacks; NULL → the engine's own. */
    const ob_vulkan_handles *adopt;
} ob_test_world_desc;

/* The world itself: its fields (w.r, w.lib, w.box, w.pixels, ...) are the
 * tests' short names. */
typedef ob_world ob_test_world;

/* The small world (ob_world_desc_small) with the validation layer on and
 * the desc's changes; any failure of a world helper (ob_world_entity,
 * ob_world_material, ob_world_read, ...) or frame fails the test, naming
 * what failed. */
void ob_test_world_create(ob_test_world *w, const ob_test_world_desc *desc);
/* Fails the test when the validation layer spoke or Obelisk's heap is not
 * back where it was at create. */
void ob_test_world_destroy(ob_test_world *w);

/* One frame (dt = 1/60 after the first) in `mode` with `workers` active
 * (0 = all), waited for; returns its final stats (GPU times included). */
const ob_frame_stats *ob_test_world_frame(ob_test_world *w, ob_threading mode, uint32_t workers);
/* Like ob_test_world_frame, and pre-draws `extra` views in the same frame
 * after the final one (so they execute before it). */
const ob_frame_stats *ob_test_world_frame_with(ob_test_world *w, ob_threading mode,
                                               uint32_t workers, ob_view *const *extra,
                                               uint32_t extra_count);

/* A light node `name` of d at (x, y, z) (fails the test when refused). */
ob_node *ob_test_world_light(ob_test_world *w, const char *name, const ob_light_desc *d, double x,
                             double y, double z);
/* The 20 x 20 XZ plane in the extended vertex layout the PBR shaders read
 * (white vertex colours), owned by the world. */
ob_geometry *ob_test_world_pbr_plane(ob_test_world *w, uint32_t subdivisions);

#endif
