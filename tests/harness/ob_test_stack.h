/* ob_test_stack.h — the whole engine stack (an ob_world,
 * demos/world/ob_world.h, without primitives) for tests that expect things
 * to fail: every step returns its ob_result instead of failing the test,
 * and ob_test_stack_stop destroys whatever exists after any failure.
 *
 * ob_test_world (ob_test_world.h) is the harness for tests where every step
 * must succeed; this one is for fault injection and device loss, where a
 * step failing cleanly is the behaviour under test.
 *
 * The scene (ob_test_stack_build_scene) is tiny but exercises every lazy
 * path of a first frame: a shadow-casting directional light and caster, a
 * shadowed spot light and point light (views into the shared local shadow
 * array, the LOCAL_SHADOWS variants), a reflective sphere (a paraboloid or cube environment map), a particle system (a
 * compute simulation and a blended draw) and the composite to the final
 * target. Its image depends only on the frame index, never on earlier
 * frames: the particles live shorter than a frame, so every step respawns
 * all of them from the simulation time. A frame that failed therefore
 * leaves nothing behind in the pixels, and the frame after it can be
 * compared with an undisturbed run.
 *
 * Lifecycle: ob_test_stack_start → [ob_test_stack_build_scene →
 * ob_test_stack_frame*] → ob_test_stack_stop. Thread rule: one thread.
 */
#ifndef OB_TEST_STACK_H
#define OB_TEST_STACK_H

#include "ob_test_world.h"

/* The test world's settings, with smaller defaults: workers 0 → 2, size
 * 0 → 48 x 32, env_map_size 0 → 16, shadow_map_size 0 → 32; cache_dir
 * NULL → $OB_CACHE_DIR/stack, else /tmp/obelisk-test-stack. clear_color,
 * chunk_draws, parallel_grain, msaa and env_map_kind (the reflective
 * sphere's map) are the world's defaults. */
typedef ob_test_world_desc ob_test_stack_desc;

typedef struct ob_test_stack {
    ob_world world;            /* owns everything but the particle system */
    ob_particle_system *particles;
    uint32_t width, height, env_map_size, shadow_map_size, workers;
    uint64_t frames;           /* frames attempted (time = frames / 60 s) */
    /* ob_fault_count of each kind when the last frame's PreRender ended:
     * the points after it are the recording and submission. */
    uint64_t fault_points_before_record[OB_FAULT_KIND_COUNT];
    char cache_dir[512];
} ob_test_stack;

/* The world: renderer (validation on), effect context, material library,
 * views, scene, camera (fovy 1, near 0.1), main perspective view and
 * composite. On failure everything created so far is destroyed and the
 * error returned. */
ob_result ob_test_stack_start(ob_test_stack *s, const ob_test_stack_desc *desc);
/* The camera's place, geometry, materials, entities, lights and the
 * particle system. On failure the stack keeps what it made
 * (ob_test_stack_stop frees it) and returns the error. */
ob_result ob_test_stack_build_scene(ob_test_stack *s);
/* One frame in `mode` (workers active, 0 = all), waited for. The frame's
 * time advances even when a step fails, so frame k always shows time k/60.
 * Returns the first failure of update, begin_frame, end_frame or wait_idle. */
ob_result ob_test_stack_frame(ob_test_stack *s, ob_threading mode, uint32_t workers);
/* The same frame in two halves, to act between them: _begin updates, begins
 * the frame and runs the PreRender; _end (only after a successful _begin)
 * records, submits and waits. */
ob_result ob_test_stack_frame_begin(ob_test_stack *s, ob_threading mode, uint32_t workers);
ob_result ob_test_stack_frame_end(ob_test_stack *s);
/* The final image (width * height * 4 bytes). */
ob_result ob_test_stack_read(ob_test_stack *s, uint8_t *out);
/* Waits idle (a lost device is fine) and destroys everything. Safe on a
 * stack whose start failed, and twice. */
void ob_test_stack_stop(ob_test_stack *s);

#endif
