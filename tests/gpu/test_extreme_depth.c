/* Numerical precision of rendering: reversed-Z depth ordering of nearly
 * coplanar surfaces far from the camera, and a whole lit, shadowed,
 * reflective scene moved 1e7 units from the origin.
 *
 * Every case prints what it measured (print_message) so the numbers can be
 * quoted; the assertions hold the bounds the engine promises. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

/* ------------------------------------------------------------ helpers */

static ob_material *make_material(ob_test_world *w, ob_material_kind kind, float r, float g,
                                  float b, uint32_t priority, bool casts_shadows)
{
    ob_result res;
    ob_material_desc md = {.name = "extreme", .kind = kind, .diffuse = {r, g, b, 1.0f},
                           .specular = {0.0f, 0.0f, 0.0f, 1.0f}, .priority = priority,
                           .casts_shadows = casts_shadows};
    ob_material *m = ob_material_create(w->lib, &md, &res);
    if (!m) fail_msg("material: %s", ob_result_name(res));
    return m;
}

static void set_material(ob_node *n, ob_material *m)
{
    ob_renderable rd = *ob_node_renderable(n);
    rd.material = m;
    assert_int_equal(ob_node_set_renderable(n, &rd), OB_OK);
}

static void set_uniform_scale(ob_node *n, float s)
{
    ob_node_set_scale(n, (const float[3]){s, s, s});
}

/* Number of float steps between two positive floats. */
static uint32_t float_steps(float a, float b)
{
    uint32_t x, y;
    memcpy(&x, &a, sizeof x);
    memcpy(&y, &b, sizeof y);
    return x > y ? x - y : y - x;
}

/* ------------------------------------------------------- depth ordering */

/* Two camera-facing quads: "far" fills the view at distance d, "near" sits a
 * relative gap g in front of it (at d * (1 - g)) and covers the right half of
 * the image. With reversed-Z (depth = znear / distance, compare >=) the near
 * quad must cover the overlap whichever is drawn first: material priorities
 * force both draw orders (opaque items sort by priority before distance). */
typedef struct depth_rig {
    ob_test_world w;
    ob_node *far, *near;
    ob_material *far_first, *far_second, *near_first, *near_second;
} depth_rig;

static const float far_rgb[3] = {1.0f, 0.0f, 0.0f};
static const float near_rgb[3] = {0.0f, 1.0f, 0.0f};

static void depth_rig_create(depth_rig *rig, float znear)
{
    ob_test_world_create(&rig->w, &(ob_test_world_desc){.width = 96, .height = 64});
    ob_test_world *w = &rig->w;
    assert_int_equal(ob_node_set_camera(w->camera, &(ob_camera_desc){.fovy = 1.0f, .znear = znear}),
                     OB_OK);
    ob_test_world_look(w, 0, 0, 0, 0, 0, -1);
    rig->far_first = make_material(w, OB_MATERIAL_UNLIT, far_rgb[0], far_rgb[1], far_rgb[2], 0, false);
    rig->far_second = make_material(w, OB_MATERIAL_UNLIT, far_rgb[0], far_rgb[1], far_rgb[2], 1, false);
    rig->near_first = make_material(w, OB_MATERIAL_UNLIT, near_rgb[0], near_rgb[1], near_rgb[2], 0, false);
    rig->near_second = make_material(w, OB_MATERIAL_UNLIT, near_rgb[0], near_rgb[1], near_rgb[2], 1, false);
    rig->far = ob_test_world_entity(w, NULL, "far", w->plane, rig->far_first, 0, 0, 0);
    rig->near = ob_test_world_entity(w, NULL, "near", w->plane, rig->near_second, 0, 0, 0);
    /* The plane faces +Y; a quarter turn about X makes it face the camera (+Z). */
    const double q[4] = {sin(OB_PI / 4), 0, 0, cos(OB_PI / 4)};
    ob_node_set_rotation_d(rig->far, q);
    ob_node_set_rotation_d(rig->near, q);
}

static bool is_rgb(const uint8_t *p, const float rgb[3])
{
    return p[0] == (uint8_t)(rgb[0] * 255) && p[1] == (uint8_t)(rgb[1] * 255) &&
           p[2] == (uint8_t)(rgb[2] * 255);
}

typedef struct depth_result {
    uint32_t wrong_overlap;   /* overlap pixels not showing the near quad */
    uint32_t wrong_far;       /* far-only pixels not showing the far quad */
    uint32_t overlap_pixels;
} depth_result;

/* One frame with the quads at d and d * (1 - gap); near_drawn_first picks
 * the draw order. */
static depth_result depth_rig_render(depth_rig *rig, double d, double gap, bool near_drawn_first)
{
    ob_test_world *w = &rig->w;
    /* The plane mesh is 20 units: scale 0.2 d makes it 4 d wide, more than
     * the 1.46 d the view spans at distance d. The near one's left edge sits
     * on the view axis. */
    float s = (float)(0.2 * d);
    set_uniform_scale(rig->far, s);
    set_uniform_scale(rig->near, s);
    ob_node_set_position(rig->far, (const double[3]){0, 0, -d});
    ob_node_set_position(rig->near, (const double[3]){2.0 * d, 0, -d * (1.0 - gap)});
    set_material(rig->far, near_drawn_first ? rig->far_second : rig->far_first);
    set_material(rig->near, near_drawn_first ? rig->near_first : rig->near_second);
    const ob_frame_stats *st = ob_test_world_frame(w, OB_THREADING_SINGLE, 0);
    const ob_view_stats *main = ob_test_view_stats(st, "main");
    assert_non_null(main);
    assert_int_equal(main->draws, 2);
    ob_test_world_read(w);
    depth_result res = {0};
    for (uint32_t y = 0; y < w->height; y++) {
        for (uint32_t x = 0; x < w->width; x++) {
            const uint8_t *p = ob_test_world_pixel(w, x, y);
            if (x + 2 < w->width / 2) {
                res.wrong_far += !is_rgb(p, far_rgb);
            } else if (x > w->width / 2 + 1) {
                res.overlap_pixels++;
                res.wrong_overlap += !is_rgb(p, near_rgb);
            }
        }
    }
    return res;
}

static void nearly_coplanar_quads_keep_their_order(void **state)
{
    (void)state;
    const float znear = 1e-3f;
    const double distances[] = {1e3, 1e4, 1e5};
    /* 1e-3 is the promise; the smaller gaps measure where ordering breaks. */
    const double gaps[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
    depth_rig rig;
    depth_rig_create(&rig, znear);
    for (size_t di = 0; di < OB_ARRAY_COUNT(distances); di++) {
        double d = distances[di];
        double smallest_resolved = 0.0;
        bool all_resolved_so_far = true;
        for (size_t gi = 0; gi < OB_ARRAY_COUNT(gaps); gi++) {
            double gap = gaps[gi];
            depth_result a = depth_rig_render(&rig, d, gap, false);
            depth_result b = depth_rig_render(&rig, d, gap, true);
            float z_far = (float)(znear / d), z_near = (float)(znear / (d * (1.0 - gap)));
            print_message("depth: d=%.0e gap=%.0e (%.3g units): depth %.6e vs %.6e = %u float "
                          "steps; wrong overlap pixels %u (far drawn first) / %u (near first) of "
                          "%u\n",
                          d, gap, d * gap, (double)z_near, (double)z_far,
                          float_steps(z_near, z_far), a.wrong_overlap, b.wrong_overlap,
                          a.overlap_pixels);
            /* The far quad is never hidden where the near one is absent. */
            assert_int_equal(a.wrong_far, 0);
            assert_int_equal(b.wrong_far, 0);
            if (gap >= 1e-3) {
                assert_int_equal(a.wrong_overlap, 0);
                assert_int_equal(b.wrong_overlap, 0);
            }
            if (all_resolved_so_far && a.wrong_overlap == 0 && b.wrong_overlap == 0)
                smallest_resolved = gap;
            else
                all_resolved_so_far = false;
        }
        print_message("depth: d=%.0e, znear=%.0e: smallest relative gap resolved in both draw "
                      "orders = %.0e (asserted: 1e-3)\n", d, (double)znear, smallest_resolved);
    }
    ob_test_world_destroy(&rig.w);
}

/* ------------------------------------------------- large coordinates */

/* A lit scene with shadows, a point light and a reflective sphere, every
 * position given as offset + p (entities, lights and camera alike). The
 * local positions are deliberately not dyadic (0.3 is not a double): offset
 * + p then rounds to the double grid at the offset, as a real scene far from
 * the origin does. */
static void build_offset_scene(ob_test_world *w, const double o[3])
{
    ob_material *ground = make_material(w, OB_MATERIAL_LIT, 0.6f, 0.6f, 0.55f, 0, false);
    ob_material *red = make_material(w, OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, 0, true);
    ob_material *blue = make_material(w, OB_MATERIAL_LIT, 0.2f, 0.3f, 0.9f, 0, true);
    ob_result res;
    ob_material *mirror = ob_material_create(
        w->lib, &(ob_material_desc){.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE,
                                    .diffuse = {0.9f, 0.9f, 0.9f, 1.0f}, .reflectivity = 0.7f,
                                    .casts_shadows = true},
        &res);
    assert_non_null(mirror);
    ob_test_world_entity(w, NULL, "ground", w->plane, ground, o[0], o[1], o[2]);
    ob_node *cube = ob_test_world_entity(w, NULL, "cube", w->box, red, o[0] - 0.7, o[1] + 0.5,
                                         o[2] - 0.3);
    ob_node_set_euler(cube, 0.0f, 0.6f, 0.0f);
    ob_node *tall = ob_test_world_entity(w, NULL, "tall", w->box, blue, o[0] + 0.45, o[1] + 0.75,
                                         o[2] - 1.55);
    ob_node_set_scale(tall, (const float[3]){0.5f, 1.5f, 0.5f});
    ob_test_world_entity(w, NULL, "mirror", w->sphere, mirror, o[0] + 1.05, o[1] + 0.5, o[2] + 0.45);

    ob_node *sun = ob_node_create(w->scene, NULL, "sun", &res);
    assert_non_null(sun);
    assert_int_equal(ob_node_set_light(sun, &(ob_light_desc){.type = OB_LIGHT_DIRECTIONAL,
                                                             .color = {1.0f, 0.95f, 0.9f},
                                                             .intensity = 0.9f,
                                                             .casts_shadows = true}),
                     OB_OK);
    ob_node_set_position(sun, (const double[3]){o[0] + 3.1, o[1] + 8, o[2] + 4.3});
    assert_int_equal(ob_node_look_at(sun, o, (const double[3]){0, 1, 0}), OB_OK);
    ob_node *lamp = ob_node_create(w->scene, NULL, "lamp", &res);
    assert_non_null(lamp);
    assert_int_equal(ob_node_set_light(lamp, &(ob_light_desc){.type = OB_LIGHT_POINT,
                                                              .color = {0.4f, 0.6f, 1.0f},
                                                              .intensity = 3.0f, .range = 8.0f}),
                     OB_OK);
    ob_node_set_position(lamp, (const double[3]){o[0] - 2.1, o[1] + 1.5, o[2] + 1.3});
    ob_test_world_look(w, o[0] + 0.55, o[1] + 2.5, o[2] + 4.6, o[0] + 0.05, o[1] + 0.5, o[2] - 0.1);
}

/* Renders the scene at offset o (two frames: the env map reads itself one
 * frame late nowhere, but the second frame is the steady state) and returns
 * a copy of the image. */
static uint8_t *render_offset_scene(const double o[3], ob_frame_stats *out_stats)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
    build_offset_scene(&w, o);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    *out_stats = *st;
    ob_test_world_read(&w);
    uint8_t *img = ob_test_world_copy(&w);
    ob_test_world_destroy(&w);
    return img;
}

static void scene_far_from_origin_renders_the_same(void **state)
{
    (void)state;
    const double origin[3] = {0, 0, 0};
    ob_frame_stats ref_stats;
    uint8_t *ref = render_offset_scene(origin, &ref_stats);
    /* The reference really exercises shadows and the environment map. */
    const ob_view_stats *shadow = ob_test_view_stats(&ref_stats, "shadow:sun");
    const ob_view_stats *env = ob_test_view_stats(&ref_stats, "envmap:mirror");
    assert_non_null(shadow);
    assert_non_null(env);
    assert_true(shadow->draws >= 3);
    /* Three neighbours in the map, at least one reaching both halves. */
    assert_true(env->items >= 3);
    assert_true(env->draws > env->items);

    static const struct {
        const char *what;
        double o[3];
        uint32_t tolerance;   /* max abs channel difference allowed */
    } cases[] = {
        /* offset + p rounds to the double grid there (spacing 1.9e-9 at 1e7,
         * 3.7e-9 at 3e7), so a camera-relative position can differ from the
         * origin scene's by that much before its cast to float, whose steps
         * near these values are 30 to 100 times coarser: the floats the GPU
         * sees, and so the images, come out identical. */
        {"1e7 on every axis", {1e7, 1e7, 1e7}, 0},
        {"-1e7, 1e7, -1e7", {-1e7, 1e7, -1e7}, 0},
        {"1e7 + fractions", {1e7 + 0.1, -3e7 + 0.3, 12345678.9}, 0},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        ob_frame_stats st;
        uint8_t *img = render_offset_scene(cases[i].o, &st);
        uint32_t max_diff = ob_test_image_max_diff(ref, img, 160, 120);
        uint32_t count = ob_test_image_diff_count(ref, img, 160, 120, 0);
        print_message("large coordinates: offset %s (%.10g, %.10g, %.10g): max abs pixel "
                      "difference %u (tolerance %u), %u of %u pixels differ\n",
                      cases[i].what, cases[i].o[0], cases[i].o[1], cases[i].o[2], max_diff,
                      cases[i].tolerance, count, 160 * 120);
        assert_non_null(ob_test_view_stats(&st, "shadow:sun"));
        assert_non_null(ob_test_view_stats(&st, "envmap:mirror"));
        assert_true(max_diff <= cases[i].tolerance);
        free(img);
    }
    free(ref);
}

/* Not a promise, a measurement: how far the same scene can go before the
 * double grid (ulp 2^-52 * |offset|) shows in the image. */
static void measure_offsets_beyond_1e7(void **state)
{
    (void)state;
    const double origin[3] = {0, 0, 0};
    ob_frame_stats st;
    uint8_t *ref = render_offset_scene(origin, &st);
    const double offsets[] = {1e9 + 0.1, 1e11 + 0.1, 1e13 + 0.1};
    for (size_t i = 0; i < OB_ARRAY_COUNT(offsets); i++) {
        double o[3] = {offsets[i], offsets[i], -offsets[i]};
        uint8_t *img = render_offset_scene(o, &st);
        print_message("large coordinates (measured only): offset %.3g: max abs pixel difference "
                      "%u, %u pixels differ (double spacing there %.2g)\n",
                      offsets[i], ob_test_image_max_diff(ref, img, 160, 120),
                      ob_test_image_diff_count(ref, img, 160, 120, 0),
                      nextafter(offsets[i], INFINITY) - offsets[i]);
        free(img);
    }
    free(ref);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(nearly_coplanar_quads_keep_their_order),
        cmocka_unit_test(scene_far_from_origin_renders_the_same),
        cmocka_unit_test(measure_offsets_beyond_1e7),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
