/* Extreme sizes: the same shadowed scene scaled by 1e-6 ... 1e18 (camera,
 * near plane and light fit scaled with it) renders like the unit one, and
 * an entity whose camera-relative transform does not fit in a float is left
 * out with its name in the log instead of being drawn with another entity's
 * matrix. Measured differences are printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

#define W 128
#define H 96

static const ob_test_world_desc desc = {.width = W, .height = H,
                                        .clear_color = {0.2f, 0.4f, 0.6f, 1.0f}};

/* Ground, two boxes and a shadowed sun, all lengths multiplied by s. The
 * near plane scales too, so every depth value is the unit scene's. */
static uint8_t *render_scaled(double s, ob_frame_stats *out_stats)
{
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    assert_int_equal(ob_node_set_camera(w.camera, &(ob_camera_desc){.fovy = 1.0f,
                                                                   .znear = (float)(0.05 * s)}),
                     OB_OK);
    ob_material *ground = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *red = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    ob_material *blue = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.1f, 0.3f, 0.9f, true);
    float fs = (float)s;
    ob_node *n = ob_test_world_entity(&w, NULL, "ground", w.plane, ground, 0, 0, 0);
    ob_node_set_scale(n, (const float[3]){fs, fs, fs});
    n = ob_test_world_entity(&w, NULL, "cube", w.box, red, -0.7 * s, 0.5 * s, 0.3 * s);
    ob_node_set_scale(n, (const float[3]){fs, fs, fs});
    ob_node_set_euler(n, 0.0f, 0.5f, 0.0f);
    n = ob_test_world_entity(&w, NULL, "tall", w.box, blue, 0.6 * s, 0.75 * s, -0.8 * s);
    ob_node_set_scale(n, (const float[3]){0.5f * fs, 1.5f * fs, 0.5f * fs});
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3 * s, 8 * s, 4 * s);
    ob_test_world_look(&w, 0.3 * s, 2.2 * s, 4.1 * s, 0, 0.4 * s, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    if (out_stats) *out_stats = *st;
    ob_test_world_read(&w);
    uint8_t *img = ob_test_world_copy(&w);
    ob_test_world_destroy(&w);
    return img;
}

static void same_scene_at_any_scale(void **state)
{
    (void)state;
    ob_frame_stats st;
    uint8_t *unit = render_scaled(1.0, &st);
    assert_non_null(ob_test_view_stats(&st, "shadow:sun"));
    /* Promised: the image of the unit scene, exactly. */
    static const double promised[] = {
        1e-30, 1e-20, 1e-12, 1e-9, 1e-6, 1e-3, 0x1p-40, 0x1p-20,
        1e3,   1e6,   1e12,  1e15, 1e18, 1e24, 1e30,   0x1p20, 0x1p60,
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(promised); i++) {
        uint8_t *img = render_scaled(promised[i], &st);
        uint32_t max_diff = ob_test_image_max_diff(unit, img, W, H);
        print_message("scale %.3g: max abs pixel difference %u (tolerance 0), %u of %u pixels "
                      "differ\n", promised[i], max_diff,
                      ob_test_image_diff_count(unit, img, W, H, 0), W * H);
        assert_non_null(ob_test_view_stats(&st, "shadow:sun"));
        assert_int_equal(max_diff, 0);
        free(img);
    }
    /* Measured only: at 1e36 the clip coordinates of the ground (1e37) are a
     * factor 30 from FLT_MAX and products of them overflow. */
    uint8_t *img = render_scaled(1e36, &st);
    print_message("scale 1e+36 (measured only): max abs pixel difference %u, %u pixels differ\n",
                  ob_test_image_max_diff(unit, img, W, H),
                  ob_test_image_diff_count(unit, img, W, H, 0));
    free(img);
    free(unit);
}

/* An entity whose bound relative to the camera is not a float, placed
 * straight ahead (1e39 units away, or world scale 1e40 through a parent
 * chain): no matrix could place it on the GPU. It is left out and named in
 * the log, and the rest of the image (shadows included: it must not stretch
 * the light's fit) is the one without it. Back in range it renders again,
 * and going out again is reported again. */
static void entity_beyond_float_range_is_left_out(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    ob_material *ground = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *red = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    ob_test_world_entity(&w, NULL, "ground", w.plane, ground, 0, 0, 0);
    ob_test_world_entity(&w, NULL, "cube", w.box, red, 0, 0.5, 0);
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_test_world_look(&w, 0, 2.5, 4.5, 0, 0.4, 0);
    ob_result r;
    ob_node *parent = ob_node_create(w.scene, NULL, "giant-parent", &r);
    assert_non_null(parent);
    ob_node *far = ob_test_world_entity(&w, parent, "beyond-float", w.box, red, 0, 0, 0);
    ob_node_set_hidden(far, true);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_test_world_read(&w);
    uint8_t *without = ob_test_world_copy(&w);
    ob_node_set_hidden(far, false);

    for (int c = 0; c < 2; c++) {
        if (c == 0) {
            ob_node_set_position(far, (const double[3]){0, -0.4e39, -1e39});
        } else {
            ob_node_set_position(far, (const double[3]){0, 0, -1e-19});
            ob_node_set_scale(parent, (const float[3]){1e20f, 1e20f, 1e20f});
            ob_node_set_scale(far, (const float[3]){1e20f, 1e20f, 1e20f});
        }
        const char *what = c == 0 ? "1e39 units ahead" : "world scale 1e40 (parent 1e20 x child 1e20)";
        for (int mode = 0; mode < 2; mode++) {
            ob_test_log_clear();
            const ob_frame_stats *st =
                ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            ob_test_world_read(&w);
            uint32_t max_diff = ob_test_image_max_diff(without, w.pixels, W, H);
            print_message("%s (%s): max abs pixel difference %u (tolerance 0), main drew %u\n",
                          what, mode ? "MT" : "ST", max_diff, ob_test_view_stats(st, "main")->draws);
            assert_int_equal(max_diff, 0);
            assert_int_equal(ob_test_view_stats(st, "main")->draws, 2);
            /* Named the first frame, not again while it stays out of range. */
            if (mode == 0) assert_true(ob_test_log_has("'main'", "'beyond-float'", "float range", NULL));
            else assert_false(ob_test_log_has("'beyond-float'", NULL));
        }
        /* Back in range (in front of the cube): drawn again. */
        ob_node_set_scale(parent, (const float[3]){1, 1, 1});
        ob_node_set_scale(far, (const float[3]){0.5f, 0.5f, 0.5f});
        ob_node_set_position(far, (const double[3]){0.8, 0.25, 1.0});
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_test_world_read(&w);
        assert_int_equal(ob_test_view_stats(st, "main")->draws, 3);
        assert_true(ob_test_image_max_diff(without, w.pixels, W, H) > 0);
    }
    free(without);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(same_scene_at_any_scale),
        cmocka_unit_test(entity_beyond_float_range_is_left_out),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
