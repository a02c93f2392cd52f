/* What a user sees first: the clear colour, a lit cube, the same pixels in
 * single- and multi-threaded recording. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

static const ob_test_world_desc small = {.width = 160, .height = 120,
                                         .clear_color = {0.2f, 0.4f, 0.6f, 1.0f}};

static void empty_scene_is_the_clear_colour(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &small);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    /* The clear colour is linear: what shows is its tone-mapped sRGB level. */
    uint8_t want[3];
    for (int i = 0; i < 3; i++)
        want[i] = ob_composite_view_output_level(w.composite, small.clear_color[i]);
    for (uint32_t y = 0; y < w.height; y++) {
        for (uint32_t x = 0; x < w.width; x++) {
            const uint8_t *p = ob_world_pixel(&w, x, y);
            if (abs(p[0] - want[0]) > 1 || abs(p[1] - want[1]) > 1 || abs(p[2] - want[2]) > 1 ||
                p[3] != 255)
                fail_msg("pixel (%u,%u) = %u,%u,%u,%u, expected the clear colour %u,%u,%u,255", x,
                         y, p[0], p[1], p[2], p[3], want[0], want[1], want[2]);
        }
    }
    /* The empty main view records nothing and says so. */
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    assert_non_null(main);
    assert_int_equal(main->draws, 0);
    assert_int_equal(main->skipped, OB_SKIP_EMPTY);
    ob_test_world_destroy(&w);
}

/* The metallic-roughness model (docs/materials.md) where the normal, the
 * light and the view are one direction (n.l = n.v = n.h = v.h = 1), for a
 * dielectric (metallic 0, F0 0.04) of GGX alpha a under a unit light and
 * an ambient light of that intensity:
 *   light    pi (f_diffuse + f_specular) = (1 - F0) base + F0 / (4 a^2)
 *            (F = F0 at v.h = 1; D = 1 / (pi a^2); Vis = 1/4)
 *   ambient  ambient ((1 - F_a) base + F_a), F_a = F0 at n.v = 1. */
static float dielectric_face_on(float base, float a, float ambient)
{
    const float f0 = 0.04f;
    return (1.0f - f0) * base + f0 / (4.0f * a * a) + ambient * ((1.0f - f0) * base + f0);
}

/* A cube face-on to the camera and to a white directional light: the centre
 * is the model's face-on value in linear light, then tone mapped and
 * sRGB-encoded by the composite. ob_world_material's specular {0, 0, 0, 1}
 * is the faintest highlight: the dielectric floor F0 = 0.04 and roughness
 * (2 / (1 + 2))^(1/4), so a = sqrt(2/3), base colour = diffuse. */
static void lit_cube_centre_has_the_expected_shade(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &small);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.4f, 0.2f, false);
    ob_world_entity(&w, NULL, "cube", w.box, m, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 0, 0, 10);
    ob_world_look(&w, 0, 0, 5, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(st->draws, 2); /* the cube and the composite's full-screen triangle */
    ob_world_read(&w);
    const uint8_t *c = ob_world_pixel(&w, w.width / 2, w.height / 2);
    const float a = sqrtf(2.0f / 3.0f), diffuse[3] = {0.8f, 0.4f, 0.2f};
    float expected[3];
    for (int i = 0; i < 3; i++) expected[i] = dielectric_face_on(diffuse[i], a, 0.15f);
    for (int i = 0; i < 3; i++)
        assert_near(c[i], ob_composite_view_output_level(w.composite, expected[i]), 2.0);
    assert_int_equal(c[3], 255);
    /* Depth test and framing: a corner still shows the clear colour. */
    const uint8_t *corner = ob_world_pixel(&w, 2, 2);
    assert_near(corner[0], ob_composite_view_output_level(w.composite, small.clear_color[0]), 1);
    assert_near(corner[2], ob_composite_view_output_level(w.composite, small.clear_color[2]), 1);
    ob_test_world_destroy(&w);
}

/* Rotation changes the image over frames (the cube is animated), and every
 * frame is the same whichever mode recorded it. */
static void rotating_cube_same_in_every_mode(void **state)
{
    (void)state;
    uint8_t *frames[2][3];
    for (int run = 0; run < 2; run++) {
        ob_test_world w;
        ob_test_world_create(&w, &small);
        ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.3f, 0.7f, 0.9f, true);
        ob_node *cube = ob_world_entity(&w, NULL, "cube", w.box, m, 0, 0.6, 0);
        ob_node_add_rotation_controller(cube, (const float[3]){0.3f, 1.0f, 0.1f}, 2.0f);
        ob_material *g = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
        ob_world_entity(&w, NULL, "ground", w.plane, g, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
        ob_world_look(&w, 0, 2.5, 4, 0, 0.3, 0);
        for (int f = 0; f < 3; f++) {
            ob_threading mode = run == 0 ? OB_THREADING_SINGLE : OB_THREADING_MULTI;
            ob_test_world_frame(&w, mode, run == 0 ? 0 : 3);
            ob_world_read(&w);
            frames[run][f] = malloc((size_t)w.width * w.height * 4);
            memcpy(frames[run][f], w.pixels, (size_t)w.width * w.height * 4);
        }
        ob_test_world_destroy(&w);
    }
    assert_true(memcmp(frames[0][0], frames[0][2], 160 * 120 * 4) != 0);
    for (int f = 0; f < 3; f++) {
        assert_int_equal(ob_test_image_max_diff(frames[0][f], frames[1][f], 160, 120), 0);
        free(frames[0][f]);
        free(frames[1][f]);
    }
}

/* Issue 25.2: scaled by 1e-30 the scene's clip coordinates were 1e-30.
 * lavapipe divides by w before rasterizing and drew it exactly; a GPU that
 * rasterizes in homogeneous coordinates forms products of two of them
 * (1e-60), which a float flushes to zero, and lost the picture (NVIDIA: 194
 * levels). The view's projection now keeps clip coordinates of the order
 * of 1 at every scale: the near plane's w lies in [0.5, 1), so every
 * product of two clip coordinates of what is drawn is a normal float, on
 * any device. The picture, specular highlight included, is the unit
 * scene's, bit for bit. */
static void tiny_and_huge_scenes_keep_clip_coordinates_normal(void **state)
{
    (void)state;
    static const double scales[] = {1.0, 1e-30, 0x1p-100, 1e-12, 1e-3, 1e12, 1e30};
    uint8_t *unit = NULL;
    for (size_t i = 0; i < sizeof scales / sizeof scales[0]; i++) {
        const double sc = scales[i];
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        assert_int_equal(ob_node_set_camera(w.camera, &(ob_camera_desc){.fovy = 1.0f, .znear = (float)(0.1 * sc)}),
                         OB_OK);
        ob_world_look(&w, 0.0, 2.0 * sc, 5.0 * sc, 0.0, 0.0, 0.0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2 * sc, 6 * sc, 1 * sc);
        /* Specular: the view vector, camera-relative and as small as the scene. */
        ob_result mr;
        ob_material *red = ob_material_create(w.lib, &(ob_material_desc){
            .name = "shiny", .kind = OB_MATERIAL_LIT, .diffuse = {0.9f, 0.1f, 0.1f, 1.0f},
            .specular = {0.8f, 0.8f, 0.8f, 16.0f}}, &mr);
        assert_non_null(red);
        ob_node *box = ob_world_entity(&w, NULL, "box", w.box, red, 0, 0, 0);
        ob_node_set_scale(box, (const float[3]){(float)sc, (float)sc, (float)sc});
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);

        /* The box's corners (half-size 0.5) through the view's matrix. */
        const ob_view *v = ob_perspective_view_base(w.main);
        float smallest = INFINITY;
        for (int c = 0; c < 8; c++) {
            float p[3] = {(float)((c & 1 ? 0.5 : -0.5) * sc - v->origin[0]),
                          (float)((c & 2 ? 0.5 : -0.5) * sc - v->origin[1]),
                          (float)((c & 4 ? 0.5 : -0.5) * sc - v->origin[2])};
            for (int row = 0; row < 4; row++) {
                float clip = v->view_proj[row] * p[0] + v->view_proj[4 + row] * p[1] +
                             v->view_proj[8 + row] * p[2] + v->view_proj[12 + row];
                if (row == 3 || clip != 0.0f) smallest = fminf(smallest, fabsf(clip));
            }
        }
        /* Products of two coordinates this size are normal floats. */
        if (!(smallest * smallest >= 0x1p-126f))
            fail_msg("scale %g: a clip coordinate of %g; products of two flush to zero", sc, (double)smallest);
        if (i == 0) {
            unit = ob_world_copy(&w);
        } else {
            uint32_t d = ob_test_image_max_diff(unit, w.pixels, w.width, w.height);
            if (d) fail_msg("scale %g: %u levels from the unit scene", sc, d);
        }
        ob_test_world_destroy(&w);
    }
    free(unit);
}

/* Issue 25.7: a scene transform that mirrors (negative determinant) kept
 * counter-clockwise front faces and turned the normal matrix's normals
 * inward: the mirrored box showed its inside, dark. A box mirrored in x, in
 * y and z, and in all three is now the same picture as the box itself (the
 * box is symmetric, and the sun lights it from a general direction). */
static void mirrored_entity_looks_like_the_original(void **state)
{
    (void)state;
    static const float scales[4][3] = {{1, 1, 1}, {-1, 1, 1}, {1, -1, -1}, {-1, -1, -1}};
    uint8_t *images[4];
    for (int i = 0; i < 4; i++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_world_look(&w, 1.5, 2.0, 4.0, 0.0, 0.0, 0.0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 3, 1);
        ob_material *red = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.9f, 0.3f, 0.1f, false);
        ob_node *box = ob_world_entity(&w, NULL, "box", w.box, red, 0, 0, 0);
        ob_node_set_scale(box, scales[i]);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        images[i] = ob_world_copy(&w);
        ob_test_world_destroy(&w);
    }
    for (int i = 1; i < 4; i++) {
        uint32_t n = ob_rgba_diff_count(images[0], images[i], 160 * 120, 2);
        if (n) fail_msg("scale (%g, %g, %g): %u pixels differ from the unmirrored box", (double)scales[i][0],
                        (double)scales[i][1], (double)scales[i][2], n);
    }
    for (int i = 0; i < 4; i++) free(images[i]);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(empty_scene_is_the_clear_colour),
        cmocka_unit_test(mirrored_entity_looks_like_the_original),
        cmocka_unit_test(tiny_and_huge_scenes_keep_clip_coordinates_normal),
        cmocka_unit_test(lit_cube_centre_has_the_expected_shade),
        cmocka_unit_test(rotating_cube_same_in_every_mode),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
