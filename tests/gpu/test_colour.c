/* The colour pipeline as a user sees it in the output image: linear values
 * reach the sRGB final image correctly encoded, the tone map follows its
 * documented formula and keeps HDR values above 1, MSAA gives the coverage
 * levels of a known edge, resizing renders the new size, and ST and MT stay
 * byte-identical with MSAA. Expected values are computed here from the
 * formulas (docs/architecture.md, materials/shaders/composite.frag), not
 * taken from the engine. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

/* ------------------------------------------------------------ formulas */

static double srgb_encode(double l)
{
    l = l < 0.0 ? 0.0 : l > 1.0 ? 1.0 : l;
    return l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
}

static double srgb_decode(double e)
{
    return e <= 0.04045 ? e / 12.92 : pow((e + 0.055) / 1.055, 2.4);
}

/* Narkowicz's ACES fit. */
static double aces(double x)
{
    double y = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    return y < 0.0 ? 0.0 : y > 1.0 ? 1.0 : y;
}

static double level(double encoded) { return encoded * 255.0; }

/* ------------------------------------------------------------ scene helpers */

static ob_material *unlit(ob_test_world *w, const char *name, float r, float g, float b)
{
    ob_result res;
    ob_material_desc d = {.name = name, .kind = OB_MATERIAL_UNLIT, .diffuse = {r, g, b, 1.0f},
                          .casts_shadows = false};
    ob_material *m = ob_material_create(w->lib, &d, &res);
    if (!m) fail_msg("material '%s': %s", name, ob_result_name(res));
    return m;
}

/* The 20 x 20 plane facing the camera (which looks down -Z from z = 5),
 * turned by `angle` about the view axis, placed so that its left edge runs
 * through the origin: left of the edge the clear colour, right the plane. */
static ob_node *half_plane(ob_test_world *w, ob_material *m, double angle)
{
    ob_node *n = ob_world_entity(w, NULL, "half-plane", w->plane, m, 10.0 * cos(angle),
                                      10.0 * sin(angle), 0.0);
    double s = sin(OB_PI / 4), c = cos(OB_PI / 4);
    double sz = sin(angle / 2), cz = cos(angle / 2);
    /* q = q_z(angle) * q_x(90 deg): face the camera, then turn in the image. */
    const double q[4] = {cz * s, sz * s, c * sz, cz * c};
    ob_node_set_rotation_d(n, q);
    return n;
}

static void set_clear(ob_test_world *w, float v)
{
    float *c = ob_perspective_view_base(w->main)->clear_color;
    c[0] = c[1] = c[2] = v;
    c[3] = 1.0f;
}

static void assert_all_near(const ob_test_world *w, double want, double tol, const char *what)
{
    for (uint32_t y = 0; y < w->height; y++)
        for (uint32_t x = 0; x < w->width; x++) {
            const uint8_t *p = ob_world_pixel(w, x, y);
            for (int i = 0; i < 3; i++)
                if (fabs(p[i] - want) > tol)
                    fail_msg("%s: pixel (%u,%u) channel %d is %u, expected %.2f +- %.0f", what, x,
                             y, i, p[i], want, tol);
        }
}

/* ------------------------------------------------------------ (a) encode and tone map */

/* Tone map off, exposure 1: a linear 0.5 (cleared and drawn) reads back as
 * its sRGB encoding, 188 / 255. */
static void linear_half_reads_back_as_188(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.clear_color = {0.5f, 0.5f, 0.5f, 1.0f}});
    ob_world_look(&w, 0, 0, 5, 0, 0, 0);
    half_plane(&w, unlit(&w, "grey", 0.5f, 0.5f, 0.5f), 0.0);
    ob_composite_view_set_tonemap(w.composite, false);
    assert_true(ob_composite_view_set_exposure(w.composite, 1.0f));
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_view_stats(st, "main")->draws, 1);
        ob_world_read(&w);
        assert_near(level(srgb_encode(0.5)), 187.5, 0.1);
        assert_all_near(&w, 188.0, 1.0, "linear 0.5, tone map off");
    }
    ob_image_info info;
    assert_int_equal(ob_image_get_info(w.dev, ob_composite_view_target(w.composite), &info), OB_OK);
    assert_int_equal(info.format, VK_FORMAT_R8G8B8A8_SRGB);
    assert_int_equal(ob_image_get_info(w.dev, ob_perspective_view_color(w.main), &info), OB_OK);
    assert_int_equal(info.format, VK_FORMAT_R16G16B16A16_SFLOAT);
    /* Lean: without MSAA no multisampled target exists. */
    assert_int_equal(ob_perspective_view_samples(w.main), 1);
    assert_int_equal(ob_perspective_view_base(w.main)->msaa_color.id, 0);
    assert_int_equal(ob_perspective_view_base(w.main)->msaa_depth.id, 0);
    ob_test_world_destroy(&w);
}

/* Tone map on: the output is sRGB(ACES(exposure * value)) for values below
 * and above 1; a value above 1 survives the HDR target (an 8-bit target
 * would clamp 4 to 1 before the tone map). */
static void tone_map_follows_the_documented_formula(void **state)
{
    (void)state;
    static const float values[] = {0.0f, 0.02f, 0.18f, 0.5f, 1.0f, 4.0f, 16.0f};
    static const float exposures[] = {1.0f, 2.0f, 0.25f};
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 32, .height = 24});
    ob_composite_view_set_tonemap(w.composite, true);
    double got_at[2] = {0, 0};
    for (size_t e = 0; e < OB_ARRAY_COUNT(exposures); e++) {
        assert_true(ob_composite_view_set_exposure(w.composite, exposures[e]));
        for (size_t i = 0; i < OB_ARRAY_COUNT(values); i++) {
            set_clear(&w, values[i]);
            ob_test_world_frame(&w, (i + e) % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            ob_world_read(&w);
            double want = level(srgb_encode(aces((double)exposures[e] * values[i])));
            char what[64];
            snprintf(what, sizeof what, "value %g at exposure %g", (double)values[i],
                     (double)exposures[e]);
            assert_all_near(&w, want, 1.0, what);
            /* The engine's CPU mirror of the curve agrees too. */
            assert_near(ob_composite_view_output_level(w.composite, values[i]), want, 1.0);
            if (e == 0 && values[i] == 1.0f) got_at[0] = ob_world_pixel(&w, 0, 0)[0];
            if (e == 0 && values[i] == 4.0f) got_at[1] = ob_world_pixel(&w, 0, 0)[0];
        }
    }
    assert_true(got_at[1] > got_at[0] + 10.0);
    /* Refused exposures leave the old one. */
    ob_test_log_clear();
    assert_false(ob_composite_view_set_exposure(w.composite, -1.0f));
    assert_false(ob_composite_view_set_exposure(w.composite, NAN));
    assert_true(ob_test_log_has("exposure", "refused", NULL));
    assert_near(ob_composite_view_exposure(w.composite), 0.25, 0);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------------ (b) MSAA coverage */

typedef struct coverage {
    uint32_t levels[5];      /* pixels at 0, 1/4, 2/4, 3/4, 1 (linear) */
    uint32_t off_level;      /* pixels at none of them */
} coverage;

static coverage edge_coverage(uint32_t msaa)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.clear_color = {0, 0, 0, 1}, .msaa = msaa});
    ob_world_look(&w, 0, 0, 5, 0, 0, 0);
    half_plane(&w, unlit(&w, "white", 1.0f, 1.0f, 1.0f), 0.15);
    ob_composite_view_set_tonemap(w.composite, false);
    assert_int_equal(ob_perspective_view_samples(w.main), msaa);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    coverage c = {{0}, 0};
    for (uint32_t y = 0; y < w.height; y++)
        for (uint32_t x = 0; x < w.width; x++) {
            double l = srgb_decode(ob_world_pixel(&w, x, y)[1] / 255.0);
            double k = round(l * 4.0);
            if (fabs(l - k / 4.0) < 0.01) c.levels[(int)k]++;
            else c.off_level++;
        }
    ob_test_world_destroy(&w);
    return c;
}

/* A slanted white-on-black edge: with 4 samples the edge pixels take the
 * linear values k/4 (the resolve averages covered samples) and every
 * intermediate level occurs; with 1 sample only 0 and 1 occur. */
static void msaa_4x_gives_quarter_coverage_levels(void **state)
{
    (void)state;
    coverage one = edge_coverage(1);
    assert_int_equal(one.off_level, 0);
    assert_int_equal(one.levels[1] + one.levels[2] + one.levels[3], 0);
    assert_true(one.levels[0] > 1000 && one.levels[4] > 1000);
    coverage four = edge_coverage(4);
    print_message("pixels at coverage 0, 1/4, 2/4, 3/4, 1: 1x %u %u %u %u %u, 4x %u %u %u %u %u\n",
                  one.levels[0], one.levels[1], one.levels[2], one.levels[3], one.levels[4],
                  four.levels[0], four.levels[1], four.levels[2], four.levels[3], four.levels[4]);
    assert_int_equal(four.off_level, 0);
    for (int k = 1; k <= 3; k++)
        if (four.levels[k] == 0) fail_msg("no edge pixel at coverage %d/4", k);
    assert_true(four.levels[0] > 1000 && four.levels[4] > 1000);
}

/* The sample count is part of the pipeline's key: a 4x pipeline is another
 * pipeline with another id, and a single-sampled one keeps the id (and so
 * the command hashes) it had before counts were part of the key. */
static void sample_count_is_part_of_the_pipeline_key(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_result r;
    ob_effect *e = ob_effect_create(
        w.fx, &(ob_effect_desc){.name = "keyed", .vertex = "unlit.vert", .fragment = "unlit.frag",
                                .layout = ob_views_standard_input(), .depth_test = true},
        &r);
    assert_non_null(e);
    uint32_t id1 = 0, id1b = 0, id4 = 0;
    VkPipeline one = ob_effect_pipeline(e, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, &id1);
    VkPipeline one_b = ob_effect_pipeline_for(
        e, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 1}, &id1b);
    VkPipeline four = ob_effect_pipeline_for(
        e, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 4}, &id4);
    assert_true(one != VK_NULL_HANDLE && four != VK_NULL_HANDLE);
    assert_true(one == one_b && id1 == id1b);
    assert_true(four != one && id4 != id1);
    assert_int_equal(ob_effect_pipeline_count(e), 2);
    ob_effect_destroy(e);
    ob_test_world_destroy(&w);
}

/* A count the device cannot do is lowered, and the log says so. */
static void msaa_is_clamped_with_a_message(void **state)
{
    (void)state;
    ob_test_log_clear();
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.msaa = 64});
    uint32_t got = ob_perspective_view_samples(w.main);
    assert_true(got >= 1 && got < 64);
    assert_true(ob_test_log_has("MSAA 64x asked for", "using", NULL));
    ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------------ (c) resize */

static void lit_scene(ob_test_world *w)
{
    ob_world_look(w, 0, 2, 5, 0, 0, 0);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    ob_material *red = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.9f, 0.1f, 0.1f, true);
    ob_material *grey = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, true);
    ob_world_entity(w, NULL, "box", w->box, red, 0, 0.5, 0);
    ob_world_entity(w, NULL, "ground", w->plane, grey, 0, 0, 0);
}

/* The image a fresh world of that size renders of lit_scene. */
static uint8_t *fresh_image(uint32_t width, uint32_t height, uint32_t msaa)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = width, .height = height, .msaa = msaa});
    lit_scene(&w);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *img = ob_world_snapshot(&w);
    ob_test_world_destroy(&w);
    return img;
}

/* Resizing the main view between frames (and the composite, which passes
 * it to its source) renders the new size at the next frame, the same image
 * a world made at that size renders, with the validation layer silent (the
 * old targets are destroyed deferred while the previous frame used them). */
static void resize_mid_run_renders_the_new_size(void **state)
{
    (void)state;
    for (uint32_t msaa = 1; msaa <= 4; msaa *= 4) {
        uint8_t *want_small = fresh_image(96, 64, msaa);
        uint8_t *want_big = fresh_image(200, 150, msaa);
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.msaa = msaa});
        lit_scene(&w);
        ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
        assert_true(ob_stack_resize(w.stack, 96, 64));
        /* Nothing changes until the next frame. */
        assert_int_equal(ob_perspective_view_base(w.main)->width, 160);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        assert_int_equal(w.width, 96);
        assert_int_equal(w.height, 64);
        assert_int_equal(ob_perspective_view_base(w.main)->width, 96);
        assert_int_equal(ob_test_image_max_diff(w.pixels, want_small, 96, 64), 0);
        /* Through the composite, and twice in a row before one frame. */
        assert_true(ob_view_resize(ob_composite_view_base(w.composite), 120, 90));
        assert_true(ob_view_resize(ob_composite_view_base(w.composite), 200, 150));
        ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        assert_int_equal(w.width, 200);
        assert_int_equal(w.height, 150);
        assert_int_equal(ob_test_image_max_diff(w.pixels, want_big, 200, 150), 0);
        /* A zero side is refused and changes nothing. */
        ob_test_log_clear();
        assert_false(ob_stack_resize(w.stack, 0, 10));
        assert_true(ob_test_log_has("resize", "refused", NULL));
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        assert_int_equal(w.width, 200);
        ob_test_world_destroy(&w);
        free(want_small);
        free(want_big);
    }
}

/* ------------------------------------------------------------ (d) ST == MT with MSAA */

/* Shadows, an environment map (their views single-sampled) and a
 * multisampled main view: single- and multi-threaded recording give the
 * same bytes and the same command hashes. */
static void msaa_4x_same_in_st_and_mt(void **state)
{
    (void)state;
    uint8_t *img[2];
    uint64_t hash[2];
    for (int mode = 0; mode < 2; mode++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.msaa = 4, .workers = 3});
        lit_scene(&w);
        ob_result r;
        ob_material *mirror = ob_material_create(
            w.lib, &(ob_material_desc){.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE}, &r);
        assert_non_null(mirror);
        ob_world_entity(&w, NULL, "mirror", w.sphere, mirror, 1.2, 0.6, 0.3);
        ob_world_entity(&w, NULL, "box2", w.box, mirror, -1.3, 0.5, -0.5);
        const ob_frame_stats *st = NULL;
        for (int f = 0; f < 3; f++)
            st = ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 2);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), OB_SHADOW_DEFAULT_CASCADES);
        assert_int_equal(ob_perspective_view_samples(w.main), 4);
        hash[mode] = st->frame_hash;
        img[mode] = ob_world_snapshot(&w);
        ob_test_world_destroy(&w);
    }
    assert_int_equal(ob_test_image_max_diff(img[0], img[1], 160, 120), 0);
    assert_true(hash[0] == hash[1]);
    free(img[0]);
    free(img[1]);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_half_reads_back_as_188),
        cmocka_unit_test(tone_map_follows_the_documented_formula),
        cmocka_unit_test(msaa_4x_gives_quarter_coverage_levels),
        cmocka_unit_test(sample_count_is_part_of_the_pipeline_key),
        cmocka_unit_test(msaa_is_clamped_with_a_message),
        cmocka_unit_test(resize_mid_run_renders_the_new_size),
        cmocka_unit_test(msaa_4x_same_in_st_and_mt),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
