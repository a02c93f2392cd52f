/* Cascaded shadow maps (issue 28): what a user sees of them.
 *
 * - Along a 200-unit floor with a post every 10 units, seen from a low
 *   camera, four cascades keep the near shadows sharp and the far ones
 *   there, where one map over the same distance blurs the near ones.
 * - The cascades hold still: a second camera that samples the maps fitted
 *   for the first (the two-camera rule) sees the same shadow on its static
 *   floor while the first camera moves by less than a texel; with one
 *   cascade also while it moves by many texels or turns in place (with
 *   more, the splits move with the camera: measured, not asserted).
 */
#include "ob_test_world.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 320
#define H 200

/* ------------------------------------------------------------ long floor */

typedef struct long_floor {
    uint8_t *pixels;            /* W x H RGBA of the final image */
    uint32_t cascades_ran;
} long_floor;

/* The golden "cascades" in code: floor 24 x 200, a post (0.5 x 3 x 0.5)
 * every 10 units, a sun low from the side; `posts_cast` off gives the same
 * picture without their shadows. */
static long_floor render_long_floor(uint32_t cascades, bool posts_cast)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = W, .height = H,
                                                   .shadow_map_size = 512});
    assert_int_equal(ob_views_set_shadow_cascades(w.views, cascades), OB_OK);
    assert_int_equal(ob_views_set_shadow_distance(w.views, 200.0f), OB_OK);
    ob_material *floor_m = ob_world_material(&w, "floor", OB_MATERIAL_LIT, 0.7f, 0.7f, 0.7f, false);
    ob_material *post_m = ob_world_material(&w, "post", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, posts_cast);
    ob_node *floor_n = ob_world_entity(&w, NULL, "floor", w.plane, floor_m, 0, 0, -95);
    ob_node_set_scale(floor_n, (const float[3]){1.2f, 1.0f, 10.0f});
    for (int i = 0; i < 20; i++) {
        char name[16];
        snprintf(name, sizeof name, "post%d", i);
        ob_node *p = ob_world_entity(&w, NULL, name, w.box, post_m, 2.5, 1.5, -10.0 * i);
        ob_node_set_scale(p, (const float[3]){0.5f, 3.0f, 0.5f});
    }
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 80, 55, 25);
    ob_world_look(&w, 0, 1.6, 6, 0, 0.8, -60);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    long_floor out = {.cascades_ran = ob_world_shadow_cascades(st, "sun", NULL)};
    ob_world_read(&w);
    out.pixels = ob_world_copy(&w);
    assert_non_null(out.pixels);
    ob_test_world_destroy(&w);
    return out;
}

/* Shadow pixels of rows [y0, y1): darker than the unshadowed picture by
 * more than 12 levels (green), split into those darkened by at least 80%
 * of the full shadow (umbra) and the rest (penumbra: blur). */
typedef struct shadow_count {
    uint32_t umbra, penumbra;
} shadow_count;

static shadow_count count_shadow(const long_floor *lit, const long_floor *img, uint32_t y0,
                                 uint32_t y1, int full)
{
    shadow_count c = {0, 0};
    for (uint32_t y = y0; y < y1; y++) {
        for (uint32_t x = 0; x < W; x++) {
            size_t i = ((size_t)y * W + x) * 4 + 1;
            int d = (int)lit->pixels[i] - (int)img->pixels[i];
            if (d <= 12) continue;
            if (d * 5 >= full * 4) c.umbra++;
            else c.penumbra++;
        }
    }
    return c;
}

/* The darkening of the floor in full shadow: the largest seen near the
 * camera, in the cascaded image. */
static int full_shadow(const long_floor *lit, const long_floor *img)
{
    int full = 0;
    for (size_t i = (size_t)(H / 2) * W * 4 + 1; i < (size_t)W * H * 4; i += 4)
        full = OB_MAX(full, (int)lit->pixels[i] - (int)img->pixels[i]);
    return full;
}

static void near_shadows_sharp_far_shadows_kept(void **state)
{
    (void)state;
    long_floor lit = render_long_floor(4, false);
    long_floor four = render_long_floor(4, true);
    long_floor one = render_long_floor(1, true);
    assert_int_equal(four.cascades_ran, 4);
    assert_int_equal(one.cascades_ran, 1);
    int full = full_shadow(&lit, &four);
    assert_true(full > 40);
    /* Rows 92..106, just under the horizon, hold the far floor; the bottom
     * third the first few units. */
    shadow_count far4 = count_shadow(&lit, &four, 92, 106, full);
    shadow_count far1 = count_shadow(&lit, &one, 92, 106, full);
    shadow_count near4 = count_shadow(&lit, &four, 2 * H / 3, H, full);
    shadow_count near1 = count_shadow(&lit, &one, 2 * H / 3, H, full);
    print_message("far: 4 cascades %u umbra + %u penumbra, 1 cascade %u + %u; near: 4 cascades "
                  "%u + %u, 1 cascade %u + %u (full shadow %d levels)\n", far4.umbra,
                  far4.penumbra, far1.umbra, far1.penumbra, near4.umbra, near4.penumbra,
                  near1.umbra, near1.penumbra, full);
    /* Far posts still throw shadows (thin lines: a post there is under a
     * pixel wide; 30 pixels here), more than one map keeps (8). */
    assert_true(far4.umbra + far4.penumbra >= 15);
    assert_true(far4.umbra + far4.penumbra > 2 * (far1.umbra + far1.penumbra));
    /* Near the camera, four cascades draw the posts' shadows dark with
     * sharp edges; one map over 200 units has texels wider than a post
     * (0.8 units at 512 texels) and loses most of them. */
    assert_true(near4.umbra > 200);
    assert_true(near4.penumbra * 2 < near4.umbra);
    assert_true((near1.umbra + near1.penumbra) * 4 < near4.umbra + near4.penumbra);
    free(lit.pixels);
    free(four.pixels);
    free(one.pixels);
}

/* ------------------------------------------------------------ stability */

/* The scene the moving camera ("driver", the first consumer: the cascades
 * are fitted to it) and the still one ("observer", drawn after it in the
 * same frame, sampling the same maps) both see: a floor and three posts. */
typedef struct stability_world {
    ob_test_world w;
    ob_node *driver;
    ob_perspective_view *driver_view;
} stability_world;

static void stability_create(stability_world *s, uint32_t cascades)
{
    ob_test_world_create(&s->w, &(ob_test_world_desc){.width = 160, .height = 120,
                                                      .shadow_map_size = 512});
    ob_test_world *w = &s->w;
    assert_int_equal(ob_views_set_shadow_cascades(w->views, cascades), OB_OK);
    assert_int_equal(ob_views_set_shadow_distance(w->views, 60.0f), OB_OK);
    ob_material *floor_m = ob_world_material(w, "floor", OB_MATERIAL_LIT, 0.7f, 0.7f, 0.7f, false);
    ob_material *post_m = ob_world_material(w, "post", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, true);
    ob_world_entity(w, NULL, "floor", w->plane, floor_m, 0, 0, 0);
    for (int i = 0; i < 3; i++) {
        ob_node *p = ob_world_entity(w, NULL, i == 0 ? "p0" : i == 1 ? "p1" : "p2", w->box, post_m,
                                     -2.0 + 2.0 * i, 1.0, -1.0 * i);
        ob_node_set_scale(p, (const float[3]){0.3f, 2.0f, 0.3f});
    }
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 6, 9, 3);
    /* The observer is the stack's main camera; the driver another view. */
    ob_world_look(w, 1, 6, 7, 0, 0, -1);
    ob_result r;
    s->driver = ob_node_create(w->scene, NULL, "driver", &r);
    assert_non_null(s->driver);
    assert_int_equal(ob_node_set_camera(s->driver, &(ob_camera_desc){.fovy = 1.0f}), OB_OK);
    s->driver_view = ob_perspective_view_create(w->views,
        &(ob_perspective_desc){.name = "driver", .camera = s->driver, .width = 160,
                               .height = 120, .clear_color = {0.3f, 0.3f, 0.3f, 1}}, &r);
    assert_non_null(s->driver_view);
}

/* One frame with the driver at eye, looking along yaw (radians about +Y
 * from -Z) and slightly down; the observer's image in *out (W*H*4). */
static void stability_frame(stability_world *s, const double eye[3], float yaw, uint8_t *out)
{
    ob_test_world *w = &s->w;
    ob_node_set_position(s->driver, eye);
    ob_node_set_euler(s->driver, -0.25f, yaw, 0.0f);
    ob_view *roots[2] = {ob_perspective_view_base(s->driver_view),
                         ob_composite_view_base(w->composite)};
    for (int f = 0; f < 2; f++) {
        assert_int_equal(ob_scene_update(w->scene, 1.0 / 60.0), OB_OK);
        assert_int_equal(ob_renderer_begin_frame(w->r, w->scene), OB_OK);
        ob_views_render_many(w->views, roots, 2);
        assert_int_equal(ob_renderer_end_frame(w->r), OB_OK);
        assert_int_equal(ob_renderer_wait_idle(w->r), OB_OK);
    }
    /* The observer did not refit the cascades: they name the driver's. */
    const ob_frame_stats *st = ob_renderer_last_stats(w->r);
    assert_true(ob_world_shadow_cascades(st, "sun", NULL) > 0);
    ob_world_read(w);
    memcpy(out, w->pixels, (size_t)160 * 120 * 4);
}

static void stability_destroy(stability_world *s)
{
    ob_perspective_view_destroy(s->w.views, s->driver_view);
    ob_test_world_destroy(&s->w);
}

/* The observer's static floor does not change while the driver, which the
 * cascades follow, moves or turns. Float rounding of the matrices may move
 * a PCF weight by a level; a cascade that crawled with the camera would
 * move whole shadow edges (tens of pixels by tens of levels). */
static void shadow_holds_still_when_the_camera_moves(void **state)
{
    (void)state;
    enum { N = 160 * 120 };
    /* all: checked with four cascades too. A move along the view or a
     * turn moves the split distances with the camera, so a floor point
     * near a split changes cascade (as in any cascaded shadow map); with
     * one cascade nothing may change. */
    static const struct {
        const char *what;
        double eye[3];
        float yaw;
        bool all;
    } moves[] = {
        {"a thousandth of a unit sideways", {0.001, 2.0, 6.0}, 0.0f, true},
        {"a quarter of a cascade-0 texel", {0.0, 2.0, 6.004}, 0.0f, true},
        {"0.3 units forward and sideways", {0.2, 2.0, 5.7}, 0.0f, false},
        {"turned 3 degrees in place", {0.0, 2.0, 6.0}, 0.052f, false},
        {"turned 10 degrees in place", {0.0, 2.0, 6.0}, -0.175f, false},
    };
    for (uint32_t cascades = 1; cascades <= 4; cascades += 3) {
        stability_world s;
        stability_create(&s, cascades);
        uint8_t *ref = malloc(N * 4), *img = malloc(N * 4);
        assert_non_null(ref);
        assert_non_null(img);
        stability_frame(&s, (const double[3]){0.0, 2.0, 6.0}, 0.0f, ref);
        for (size_t m = 0; m < OB_ARRAY_COUNT(moves); m++) {
            stability_frame(&s, moves[m].eye, moves[m].yaw, img);
            uint32_t max = ob_rgba_max_diff(ref, img, N);
            uint32_t count = ob_rgba_diff_count(ref, img, N, 1);
            bool checked = cascades == 1 || moves[m].all;
            print_message("%u cascade(s), driver %s: %u observer pixels differ by more than 1, "
                          "at most %u levels%s\n", cascades, moves[m].what, count, max,
                          checked ? "" : " (measured only)");
            if (checked && (max > 1 || count > 0))
                fail_msg("%u cascade(s), driver %s: the observer's shadow changed (%u pixels "
                         "beyond 1 level, at most %u)", cascades, moves[m].what, count, max);
        }
        free(ref);
        free(img);
        stability_destroy(&s);
    }
}

/* A caster the camera does not see (above it, toward the sun) still throws
 * its shadow onto the floor the camera sees: the cascades reach toward the
 * light past what the camera sees, and are culled on their own. */
static void caster_out_of_view_still_casts(void **state)
{
    (void)state;
    uint8_t *images[2];
    uint32_t main_draws[2];
    for (int run = 0; run < 2; run++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_material *m = ob_world_material(&w, "m", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, true);
        ob_material *floor_m = ob_world_material(&w, "floor", OB_MATERIAL_LIT, 0.7f, 0.7f, 0.7f, false);
        ob_world_entity(&w, NULL, "floor", w.plane, floor_m, 0, 0, 0);
        ob_world_entity(&w, NULL, "seen", w.box, m, -1.5, 0.5, 0);
        /* On the line from the origin toward the sun, 6 units up it: far
         * above the camera's view (it looks down from (0, 2, 5)). */
        ob_node *above = ob_world_entity(&w, NULL, "above", w.box, m, 1.36, 5.4, 2.0);
        ob_node_set_hidden(above, run == 1);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        main_draws[run] = ob_world_view_stats(st, "main")->draws;
        ob_world_read(&w);
        images[run] = ob_world_copy(&w);
        assert_non_null(images[run]);
        ob_test_world_destroy(&w);
    }
    /* The camera draws the same entities either way... */
    assert_int_equal(main_draws[0], main_draws[1]);
    /* ...but the unseen box's shadow darkens the floor around the origin. */
    uint32_t shadowed = ob_rgba_diff_count(images[1], images[0], 160 * 120, 12);
    print_message("the unseen caster's shadow: %u pixels\n", shadowed);
    assert_true(shadowed > 100);
    free(images[0]);
    free(images[1]);
}

/* Out-of-range settings are refused and keep the old value; a new count
 * applies from the next frame (the array map is made again). */
static void cascade_settings_checked_and_applied(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_material *m = ob_world_material(&w, "m", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, true);
    ob_material *floor_m = ob_world_material(&w, "floor", OB_MATERIAL_LIT, 0.7f, 0.7f, 0.7f, false);
    ob_world_entity(&w, NULL, "floor", w.plane, floor_m, 0, -0.5, 0);
    ob_world_entity(&w, NULL, "box", w.box, m, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    assert_int_equal(ob_views_set_shadow_cascades(w.views, OB_SHADOW_MAX_CASCADES + 1),
                     OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_views_set_shadow_distance(w.views, -1.0f), OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_views_set_shadow_distance(w.views, INFINITY), OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_views_set_shadow_split_lambda(w.views, 1.5f), OB_ERR_OUT_OF_RANGE);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_shadow_cascades(st, "sun", NULL), OB_SHADOW_DEFAULT_CASCADES);
    static const uint32_t counts[] = {2, 1, 4, 3};
    for (size_t i = 0; i < OB_ARRAY_COUNT(counts); i++) {
        assert_int_equal(ob_views_set_shadow_cascades(w.views, counts[i]), OB_OK);
        st = ob_test_world_frame(&w, i % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_shadow_cascades(st, "sun", NULL), counts[i]);
        char last[32];
        snprintf(last, sizeof last, "shadow:sun:c%u", counts[i] - 1);
        assert_non_null(ob_world_view_stats(st, last));
    }
    ob_test_world_destroy(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(near_shadows_sharp_far_shadows_kept),
        cmocka_unit_test(shadow_holds_still_when_the_camera_moves),
        cmocka_unit_test(caster_out_of_view_still_casts),
        cmocka_unit_test(cascade_settings_checked_and_applied),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
