/* Extreme workloads: 64 views in one frame (62 environment maps) and the
 * 128-view cap, environment-map recursion bounds 0..4, 100,000 objects in
 * single- and multi-threaded recording, and a shadow-casting light with no
 * caster. Times are printed, never asserted. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

/* Position of view `name` in the frame's execution order, -1 if absent. */
static int view_index(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return (int)i;
    return -1;
}

/* Every dependency of every queued view executed before it. */
static uint32_t check_order(const ob_frame_stats *st, ob_view *const *views, uint32_t count)
{
    uint32_t edges = 0;
    for (uint32_t i = 0; i < count; i++) {
        int at = view_index(st, views[i]->name);
        assert_true(at >= 0);
        for (uint32_t d = 0; d < views[i]->dep_count; d++) {
            int dep_at = view_index(st, views[i]->deps[d]->name);
            if (dep_at < 0 || dep_at >= at)
                fail_msg("view '%s' (#%d) ran before its dependency '%s' (#%d)", views[i]->name,
                         at, views[i]->deps[d]->name, dep_at);
            edges++;
        }
    }
    return edges;
}

/* ------------------------------------------------------- 64 views */

/* 62 reflective spheres in view: each queues its dual-paraboloid map, so
 * the frame has 62 env maps + main + composite = 64 views. Every map must
 * run before main (which samples all 62), with no validation message. */
static void sixty_two_env_maps_in_one_frame(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120, .env_map_size = 16});
    ob_material *ground = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.5f, 0.6f, 0.5f, false);
    ob_test_world_entity(&w, NULL, "ground", w.plane, ground, 0, 0, 0);
    ob_material *mirror = ob_test_world_material(&w, OB_MATERIAL_REFLECTIVE, 0.9f, 0.8f, 0.7f, false);
    ob_node *spheres[62];
    for (uint32_t i = 0; i < 62; i++) {
        char name[32];
        snprintf(name, sizeof name, "ball%02u", i);
        spheres[i] = ob_test_world_entity(&w, NULL, name, w.sphere, mirror, -3.5 + (i % 8),
                                          0.5, -(double)(i / 8));
    }
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    ob_test_world_look(&w, 0, 5, 6, 0, 0, -3);
    uint8_t *img[2];
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        ob_view *views[64];
        uint32_t n = 0;
        for (uint32_t i = 0; i < 62; i++) {
            views[n] = ob_renderer_attached_view(w.r, spheres[i], OB_VIEW_PARABOLOID);
            assert_non_null(views[n]);
            const ob_view_stats *vs = ob_test_view_stats(st, views[n]->name);
            assert_non_null(vs);
            assert_int_equal(vs->skipped, OB_SKIP_NONE);
            assert_true(vs->draws > 0);
            n++;
        }
        views[n++] = ob_perspective_view_base(w.main);
        views[n++] = ob_composite_view_base(w.composite);
        uint32_t edges = check_order(st, views, n);
        int main_at = view_index(st, "main");
        for (uint32_t i = 0; i < 62; i++) assert_true(view_index(st, views[i]->name) < main_at);
        print_message("64 views (%s): %u views ran, %u skipped, %u dependency edges checked, "
                      "%u draws, frame %.1f ms (record %.1f ms)\n", mode ? "MT" : "ST",
                      st->view_count, st->skipped_count, edges, st->draws,
                      (double)st->frame_ns * 1e-6, (double)st->record_ns * 1e-6);
        assert_int_equal(st->view_count, 64);
        ob_test_world_read(&w);
        img[mode] = ob_test_world_copy(&w);
    }
    uint32_t d = ob_test_image_max_diff(img[0], img[1], 160, 120);
    print_message("64 views: ST vs MT max abs pixel difference %u\n", d);
    assert_int_equal(d, 0);
    free(img[0]);
    free(img[1]);
    ob_test_world_destroy(&w); /* asserts the validation layer stayed silent */
}

/* Extra perspective views up to the renderer's cap of OB_MAX_FRAME_VIEWS
 * (128) all run; one more is refused with a message and a skip reason, and
 * the rest of the frame is unaffected. */
static void views_up_to_the_frame_cap(void **state)
{
    (void)state;
    enum { EXTRA = OB_MAX_FRAME_VIEWS - 2 + 1 };   /* main + composite + extras = cap + 1 */
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_material *m = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.7f, 0.4f, 0.2f, false);
    ob_test_world_entity(&w, NULL, "cube", w.box, m, 0, 0.5, 0);
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_test_world_read(&w);
    uint8_t *alone = ob_test_world_copy(&w);

    ob_perspective_view *extra[EXTRA];
    ob_view *bases[EXTRA];
    for (uint32_t i = 0; i < EXTRA; i++) {
        char name[32];
        snprintf(name, sizeof name, "extra%03u", i);
        ob_result r;
        ob_perspective_desc pd = {.name = name, .camera = w.camera, .width = 16, .height = 16,
                                  .clear_color = {0, 0, 0, 1}};
        extra[i] = ob_perspective_view_create(w.views, &pd, &r);
        assert_non_null(extra[i]);
        bases[i] = ob_perspective_view_base(extra[i]);
    }
    for (int mode = 0; mode < 2; mode++) {
        ob_test_log_clear();
        const ob_frame_stats *st = ob_test_world_frame_with(
            &w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0, bases, EXTRA);
        assert_int_equal(st->view_count, OB_MAX_FRAME_VIEWS);
        for (uint32_t i = 0; i + 1 < EXTRA; i++) {
            const ob_view_stats *vs = ob_test_view_stats(st, bases[i]->name);
            assert_non_null(vs);
            assert_int_equal(vs->draws, 1);
        }
        const char *last = bases[EXTRA - 1]->name;
        assert_null(ob_test_view_stats(st, last));
        assert_int_equal(ob_test_skip_reason(st, last), OB_SKIP_ERROR);
        assert_true(ob_test_log_has(last, "more than 128 views", NULL));
        ob_view *order[2] = {ob_perspective_view_base(w.main), ob_composite_view_base(w.composite)};
        check_order(st, order, 2);
        print_message("view cap (%s): %u views ran, '%s' refused (%s), frame %.1f ms\n",
                      mode ? "MT" : "ST", st->view_count, last,
                      ob_skip_reason_name(ob_test_skip_reason(st, last)),
                      (double)st->frame_ns * 1e-6);
        ob_test_world_read(&w);
        assert_int_equal(ob_test_image_max_diff(alone, w.pixels, 64, 48), 0);
    }
    /* A refused view is just late, not broken: next frame without the crowd
     * it runs. */
    const ob_frame_stats *st = ob_test_world_frame_with(&w, OB_THREADING_SINGLE, 0,
                                                        &bases[EXTRA - 1], 1);
    assert_non_null(ob_test_view_stats(st, bases[EXTRA - 1]->name));
    for (uint32_t i = 0; i < EXTRA; i++) ob_perspective_view_destroy(w.views, extra[i]);
    free(alone);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------- recursion bound */

/* Env-map recursion bound 0..4. Queue depths: composite 0, main 1, its env
 * maps and shadow map 2 (env maps draw reflective neighbours without their
 * own reflections, so nothing is queued deeper). The image must render
 * without error at every bound and change less and less as it grows. */
static void env_map_recursion_bounds(void **state)
{
    (void)state;
    uint8_t *img[5];
    uint32_t views[5];
    for (uint32_t depth = 0; depth <= 4; depth++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.width = 128, .height = 96});
        ob_renderer_set_max_recursion(w.r, depth);
        ob_material *ground = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.5f, 0.5f, 0.6f, false);
        ob_material *red = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.9f, 0.2f, 0.1f, true);
        ob_material *mirror = ob_test_world_material(&w, OB_MATERIAL_REFLECTIVE, 0.9f, 0.9f, 0.9f, true);
        ob_test_world_entity(&w, NULL, "ground", w.plane, ground, 0, 0, 0);
        ob_test_world_entity(&w, NULL, "cube", w.box, red, 0, 0.5, -1.2);
        ob_test_world_entity(&w, NULL, "left-mirror", w.sphere, mirror, -0.7, 0.5, 0);
        ob_test_world_entity(&w, NULL, "right-mirror", w.sphere, mirror, 0.7, 0.5, 0);
        ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
        ob_test_world_look(&w, 0, 1.5, 3, 0, 0.4, 0);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
        views[depth] = st->view_count;
        uint32_t bounded = 0;
        for (uint32_t i = 0; i < st->skipped_count; i++)
            bounded += st->skipped[i].reason == OB_SKIP_RECURSION;
        print_message("recursion bound %u: %u views ran, %u left out at the bound\n", depth,
                      st->view_count, bounded);
        ob_test_world_read(&w);
        img[depth] = ob_test_world_copy(&w);
        ob_test_world_destroy(&w);
    }
    uint64_t prev = UINT64_MAX;
    for (uint32_t d = 0; d < 4; d++) {
        uint64_t sum = 0;
        for (size_t i = 0; i < 128 * 96 * 4; i++)
            sum += (uint64_t)abs((int)img[d][i] - (int)img[d + 1][i]);
        print_message("recursion bound %u -> %u: max abs pixel difference %u, %u pixels differ, "
                      "summed abs difference %llu\n", d, d + 1,
                      ob_test_image_max_diff(img[d], img[d + 1], 128, 96),
                      ob_test_image_diff_count(img[d], img[d + 1], 128, 96, 0),
                      (unsigned long long)sum);
        assert_true(sum <= prev);
        prev = sum;
    }
    assert_true(views[0] < views[1] && views[1] < views[2]);
    for (uint32_t d = 0; d <= 4; d++) free(img[d]);
}

/* ------------------------------------------------------- 100,000 objects */

#define GRID_X 400
#define GRID_Z 250

/* 100,000 small cubes (four materials) over the view; frames recorded
 * single- and multi-threaded give the same image and the same command
 * hashes. Times are reported, not asserted. */
static void hundred_thousand_cubes(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
    ob_material *mats[4] = {
        ob_test_world_material(&w, OB_MATERIAL_LIT, 0.9f, 0.3f, 0.2f, false),
        ob_test_world_material(&w, OB_MATERIAL_LIT, 0.2f, 0.8f, 0.3f, false),
        ob_test_world_material(&w, OB_MATERIAL_LIT, 0.2f, 0.4f, 0.9f, false),
        ob_test_world_material(&w, OB_MATERIAL_LIT, 0.8f, 0.8f, 0.2f, false),
    };
    uint64_t t0 = ob_time_ns();
    for (uint32_t z = 0; z < GRID_Z; z++) {
        for (uint32_t x = 0; x < GRID_X; x++) {
            ob_node *n = ob_test_world_entity(&w, NULL, "cube", w.box, mats[(x + z) & 3],
                                              (x - GRID_X / 2.0) * 0.1, 0.0, -(double)z * 0.1);
            ob_node_set_scale(n, (const float[3]){0.08f, 0.08f, 0.08f});
        }
    }
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    /* Straight above the grid's centre, +Y of the image toward -Z: the
     * whole 40 x 25 grid is in view, nothing is culled. */
    ob_node_set_position(w.camera, (const double[3]){-0.05, 34, -12.45});
    assert_int_equal(ob_node_look_at(w.camera, (const double[3]){-0.05, 0, -12.45},
                                     (const double[3]){0, 0, -1}), OB_OK);
    print_message("100k cubes: scene built in %.0f ms (%u nodes)\n",
                  (double)(ob_time_ns() - t0) * 1e-6, ob_scene_node_count(w.scene));
    static const struct { ob_threading mode; const char *name; } runs[] = {
        {OB_THREADING_SINGLE, "ST"}, {OB_THREADING_MULTI, "MT"}, {OB_THREADING_SINGLE, "ST"},
        {OB_THREADING_MULTI, "MT"},
    };
    uint8_t *first = NULL;
    uint64_t hash = 0;
    for (size_t i = 0; i < OB_ARRAY_COUNT(runs); i++) {
        uint64_t f0 = ob_time_ns();
        const ob_frame_stats *st = ob_test_world_frame(&w, runs[i].mode, 0);
        uint64_t wall = ob_time_ns() - f0;
        const ob_view_stats *main = ob_test_view_stats(st, "main");
        print_message("100k cubes frame %zu (%s, %u workers): %u draws, %u culled; pre-render "
                      "(cull) %.1f ms, record %.1f ms, submit %.1f ms, frame %.1f ms, GPU %.1f ms, "
                      "wall incl. wait %.1f ms, main in %u chunks\n",
                      i, runs[i].name, st->workers, st->draws, st->culled,
                      (double)st->pre_render_ns * 1e-6, (double)st->record_ns * 1e-6,
                      (double)st->submit_ns * 1e-6, (double)st->frame_ns * 1e-6, st->gpu_ms,
                      (double)wall * 1e-6, main->chunks);
        assert_int_equal(main->draws, GRID_X * GRID_Z);
        ob_test_world_read(&w);
        if (!first) {
            first = ob_test_world_copy(&w);
            hash = main->hash.hash;
        } else {
            uint32_t d = ob_test_image_max_diff(first, w.pixels, 160, 120);
            print_message("100k cubes frame %zu vs frame 0: max abs pixel difference %u, command "
                          "hash %s\n", i, d, main->hash.hash == hash ? "equal" : "DIFFERENT");
            assert_int_equal(d, 0);
            assert_true(main->hash.hash == hash);
        }
    }
    free(first);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------- no casters */

/* A shadow-casting sun over receivers only: the shadow view is left out
 * with "no shadow casters", and the image is the unshadowed one. */
static void shadow_map_without_casters_is_skipped(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 128, .height = 96});
    ob_material *m = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.6f, 0.5f, 0.4f, false);
    ob_test_world_entity(&w, NULL, "ground", w.plane, m, 0, 0, 0);
    ob_test_world_entity(&w, NULL, "cube", w.box, m, 0, 0.5, 0);
    ob_node *sun = ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_null(ob_test_view_stats(st, "shadow:sun"));
    assert_int_equal(ob_test_skip_reason(st, "shadow:sun"), OB_SKIP_NO_CASTERS);
    print_message("no casters: shadow:sun %s (%s)\n",
                  ob_test_view_stats(st, "shadow:sun") ? "ran" : "left out",
                  ob_skip_reason_name(ob_test_skip_reason(st, "shadow:sun")));
    ob_test_world_read(&w);
    uint8_t *skipped = ob_test_world_copy(&w);
    ob_light_desc ld = *ob_node_light(sun);
    ld.casts_shadows = false;
    assert_int_equal(ob_node_set_light(sun, &ld), OB_OK);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_test_skip_reason(st, "shadow:sun"), OB_SKIP_NONE);
    ob_test_world_read(&w);
    uint32_t d = ob_test_image_max_diff(skipped, w.pixels, 128, 96);
    print_message("no casters vs light without shadows: max abs pixel difference %u (tolerance "
                  "0)\n", d);
    assert_int_equal(d, 0);
    free(skipped);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sixty_two_env_maps_in_one_frame),
        cmocka_unit_test(views_up_to_the_frame_cap),
        cmocka_unit_test(env_map_recursion_bounds),
        cmocka_unit_test(shadow_map_without_casters_is_skipped),
        cmocka_unit_test(hundred_thousand_cubes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
