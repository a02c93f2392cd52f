/* Degenerate and invalid input, rendered: zero scale (singular normal
 * matrix), an up vector parallel to the view direction, zero-size views, an
 * empty scene, switched-off lights, NaN/Inf in transforms, materials and
 * parameters. Each case checks the image against the scene without the bad
 * part (measured as a max abs pixel difference, promised 0) and the message
 * a user would read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

#define W 128
#define H 96

/* A clear colour exact in UNORM8: 51, 102, 153. */
static const ob_test_world_desc desc = {.width = W, .height = H,
                                        .clear_color = {0.2f, 0.4f, 0.6f, 1.0f}};

static bool is_clear(const uint8_t *p) { return p[0] == 51 && p[1] == 102 && p[2] == 153; }

/* A lit ground, two shadow-casting boxes and a shadowed sun. */
typedef struct base_scene {
    ob_material *ground, *red, *mirror;
    ob_node *sun;
} base_scene;

static base_scene build_base(ob_test_world *w)
{
    base_scene b;
    b.ground = ob_test_world_material(w, OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    b.red = ob_test_world_material(w, OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    b.mirror = ob_test_world_material(w, OB_MATERIAL_REFLECTIVE, 0.9f, 0.9f, 0.9f, true);
    ob_test_world_entity(w, NULL, "ground", w->plane, b.ground, 0, 0, 0);
    ob_test_world_entity(w, NULL, "left", w->box, b.red, -0.8, 0.5, 0);
    ob_test_world_entity(w, NULL, "right", w->box, b.red, 0.8, 0.5, -0.5);
    b.sun = ob_test_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_test_world_look(w, 0, 2.5, 4.5, 0, 0.4, 0);
    return b;
}

/* Renders a frame and returns a copy of the image. */
static uint8_t *render(ob_test_world *w, const ob_frame_stats **out_stats)
{
    const ob_frame_stats *st = ob_test_world_frame(w, OB_THREADING_SINGLE, 0);
    if (out_stats) *out_stats = st;
    ob_test_world_read(w);
    return ob_test_world_copy(w);
}

static uint32_t report_diff(const char *what, const uint8_t *a, const uint8_t *b)
{
    uint32_t max_diff = ob_test_image_max_diff(a, b, W, H);
    print_message("%s: max abs pixel difference %u (tolerance 0), %u of %u pixels differ\n", what,
                  max_diff, ob_test_image_diff_count(a, b, W, H, 0), W * H);
    return max_diff;
}

/* -------------------------------------------------------------- zero scale */

/* A zero-scale entity has a singular normal matrix (all zero) and collapses
 * to a point: it must add nothing to the image, no NaN-black pixels, and not
 * bend the shadow map's fit (it sits outside the other casters' bounds). */
static void zero_scale_entity_adds_nothing(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    base_scene b = build_base(&w);
    ob_node *box = ob_test_world_entity(&w, NULL, "collapsed-box", w.box, b.red, 2.0, 1.5, -2.5);
    ob_node *ball = ob_test_world_entity(&w, NULL, "collapsed-mirror", w.sphere, b.mirror, -1.5,
                                         0.5, 1.0);
    ob_node_set_hidden(box, true);
    ob_node_set_hidden(ball, true);
    uint8_t *without = render(&w, NULL);
    ob_node_set_hidden(box, false);
    ob_node_set_hidden(ball, false);
    ob_node_set_scale(box, (const float[3]){0, 0, 0});
    ob_node_set_scale(ball, (const float[3]){0, 0, 0});
    const ob_frame_stats *st;
    uint8_t *with = render(&w, &st);
    const ob_view_stats *main = ob_test_view_stats(st, "main");
    print_message("zero scale: main view drew %u items, shadow view %s\n", main->draws,
                  ob_test_view_stats(st, "shadow:sun") ? "ran" : "did not run");
    assert_int_equal(report_diff("zero scale (box + reflective sphere)", without, with), 0);
    free(without);
    free(with);
    ob_test_world_destroy(&w);
}

/* Scale zero on one axis only: the box is a flat square whose cofactor
 * normal matrix keeps the top face's normal. It must shade like a plane of
 * the same size (no black, no NaN). */
static void flattened_box_shades_like_a_plane(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    ob_material *m = ob_test_world_material(&w, OB_MATERIAL_LIT, 0.3f, 0.7f, 0.4f, false);
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 3);
    ob_test_world_look(&w, 0, 3, 2, 0, 0, 0);
    ob_node *flat = ob_test_world_entity(&w, NULL, "flat", w.box, m, 0, 0, 0);
    ob_node_set_scale(flat, (const float[3]){2.0f, 0.0f, 2.0f});
    uint8_t *box_img = render(&w, NULL);
    ob_node_set_hidden(flat, true);
    ob_node *plane = ob_test_world_entity(&w, NULL, "plane", w.plane, m, 0, 0, 0);
    ob_node_set_scale(plane, (const float[3]){0.1f, 0.1f, 0.1f}); /* 20 units -> 2 */
    uint8_t *plane_img = render(&w, NULL);
    const uint8_t *c = box_img + ((size_t)(H / 2) * W + W / 2) * 4;
    print_message("flattened box centre pixel %u,%u,%u\n", c[0], c[1], c[2]);
    assert_true(c[1] > 100); /* lit green, not NaN-black */
    uint32_t max_diff = ob_test_image_max_diff(box_img, plane_img, W, H);
    uint32_t count = ob_test_image_diff_count(box_img, plane_img, W, H, 1);
    print_message("flattened box vs plane: max abs pixel difference %u, %u pixels differ by more "
                  "than 1 level (tolerance: 8 edge pixels)\n", max_diff, count);
    /* Both are the same square; different triangulations may round an edge
     * pixel's coverage differently, never the shade of the inside. */
    assert_true(count <= 8);
    free(box_img);
    free(plane_img);
    ob_test_world_destroy(&w);
}

/* -------------------------------------------------------------- camera */

/* look_at with up parallel to the direction: the up axis is replaced (the
 * world axis least aligned with the direction, preferring Z: +Z for a camera
 * looking straight down), the log names the camera, and the frame is the one
 * an explicit up = +Z gives. */
static void camera_up_parallel_to_direction_renders(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    build_base(&w);
    ob_node_set_position(w.camera, (const double[3]){0, 6, 0});
    ob_test_log_clear();
    assert_int_equal(ob_node_look_at(w.camera, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0}),
                     OB_OK);
    assert_true(ob_test_log_has("'camera'", "parallel", NULL));
    uint8_t *fallback = render(&w, NULL);
    assert_int_equal(ob_node_look_at(w.camera, (const double[3]){0, 0, 0}, (const double[3]){0, 0, 1}),
                     OB_OK);
    uint8_t *explicit_up = render(&w, NULL);
    /* The boxes are in view: not just the clear colour. */
    uint32_t clear_like = 0;
    for (uint32_t i = 0; i < W * H; i++)
        clear_like += is_clear(fallback + 4 * i);
    assert_true(clear_like < W * H / 2);
    uint32_t d = ob_test_image_max_diff(fallback, explicit_up, W, H);
    print_message("up parallel to direction vs explicit up (0,0,1): max abs pixel difference "
                  "%u (tolerance 0)\n", d);
    assert_int_equal(d, 0);
    free(fallback);
    free(explicit_up);
    ob_test_world_destroy(&w);
}

/* A zero-size perspective view and bad camera settings are refused at
 * creation with a message naming them; the frame goes on unchanged. */
static void zero_size_view_is_refused(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    build_base(&w);
    uint8_t *before = render(&w, NULL);
    static const uint32_t sizes[][2] = {{0, 64}, {64, 0}, {0, 0}};
    for (size_t i = 0; i < OB_ARRAY_COUNT(sizes); i++) {
        ob_test_log_clear();
        ob_result r = OB_OK;
        ob_perspective_desc pd = {.name = "degenerate", .camera = w.camera, .width = sizes[i][0],
                                  .height = sizes[i][1]};
        assert_null(ob_perspective_view_create(w.views, &pd, &r));
        assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
        assert_true(ob_test_log_has("'degenerate'", "width and height", NULL));
    }
    ob_result r;
    ob_node *bad = ob_node_create(w.scene, NULL, "bad-camera", &r);
    static const ob_camera_desc bad_cams[] = {
        {.fovy = 3.5f}, {.fovy = -1.0f}, {.znear = -0.1f}, {.aspect = -1.0f}, {.fovy = NAN},
        {.znear = INFINITY},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(bad_cams); i++) {
        ob_test_log_clear();
        assert_int_equal(ob_node_set_camera(bad, &bad_cams[i]), OB_ERR_INVALID_ARGUMENT);
        assert_true(ob_test_log_has("'bad-camera'", NULL));
    }
    assert_null(ob_node_camera(bad));
    uint8_t *after = render(&w, NULL);
    assert_int_equal(report_diff("frame after refused views and cameras", before, after), 0);
    free(before);
    free(after);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------- empty and lights */

/* Nothing renderable, but a shadow-casting sun and a point light: the clear
 * colour everywhere, the main view says it was empty and the shadow view
 * that it had no caster. */
static void empty_scene_with_lights_is_the_clear_colour(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    ob_test_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_test_world_light(&w, OB_LIGHT_POINT, false, 2.0f, 0, 2, 0);
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        ob_test_world_read(&w);
        uint32_t wrong = 0;
        for (uint32_t i = 0; i < W * H; i++) {
            const uint8_t *p = w.pixels + 4 * i;
            wrong += !is_clear(p) || p[3] != 255;
        }
        print_message("empty scene (%s): %u pixels differ from the clear colour; main: %s, "
                      "shadow:sun: %s\n", mode ? "MT" : "ST", wrong,
                      ob_skip_reason_name(ob_test_view_stats(st, "main")->skipped),
                      ob_skip_reason_name(ob_test_skip_reason(st, "shadow:sun")));
        assert_int_equal(wrong, 0);
        assert_int_equal(ob_test_view_stats(st, "main")->skipped, OB_SKIP_EMPTY);
        assert_int_equal(ob_test_skip_reason(st, "shadow:sun"), OB_SKIP_NO_CASTERS);
        assert_null(ob_test_view_stats(st, "shadow:sun"));
    }
    ob_test_world_destroy(&w);
}

/* A light switched off — intensity 0, or hidden — lights nothing and costs
 * no shadow view (left out with the reason "not needed" at intensity 0), and
 * the image is that of a scene without it. */
static void switched_off_light_has_no_shadow_view(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    base_scene b = build_base(&w);
    ob_node *lamp = ob_test_world_light(&w, OB_LIGHT_POINT, false, 1.0f, 1, 2, 1);
    ob_node_set_hidden(b.sun, true);
    ob_node_set_hidden(lamp, true);
    const ob_frame_stats *st;
    uint8_t *off = render(&w, &st);
    assert_null(ob_test_view_stats(st, "shadow:sun"));
    ob_node_destroy(w.scene, lamp);
    /* The same sun at intensity 0 instead of hidden. */
    ob_node_set_hidden(b.sun, false);
    ob_light_desc dark = *ob_node_light(b.sun);
    dark.intensity = 0.0f;
    assert_int_equal(ob_node_set_light(b.sun, &dark), OB_OK);
    uint8_t *zero = render(&w, &st);
    assert_null(ob_test_view_stats(st, "shadow:sun"));
    assert_int_equal(ob_test_skip_reason(st, "shadow:sun"), OB_SKIP_NOT_NEEDED);
    print_message("intensity-0 sun: shadow view left out (%s)\n",
                  ob_skip_reason_name(ob_test_skip_reason(st, "shadow:sun")));
    ob_node_destroy(w.scene, b.sun);
    uint8_t *none = render(&w, NULL);
    assert_int_equal(report_diff("hidden lights vs no lights", off, none), 0);
    assert_int_equal(report_diff("intensity-0 sun vs no sun", zero, none), 0);
    free(off);
    free(zero);
    free(none);
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------ non-finite input */

typedef struct bad_transform {
    const char *what;
    void (*apply)(ob_node *n);
} bad_transform;

static void nan_position(ob_node *n) { ob_node_set_position(n, (const double[3]){NAN, 0, 0}); }
static void inf_position(ob_node *n) { ob_node_set_position(n, (const double[3]){0, -INFINITY, 0}); }
static void inf_scale(ob_node *n) { ob_node_set_scale(n, (const float[3]){1, INFINITY, 1}); }
static void nan_rotation(ob_node *n) { ob_node_set_rotation(n, (const float[4]){0, NAN, 0, 1}); }
static void zero_rotation(ob_node *n) { ob_node_set_rotation(n, (const float[4]){0, 0, 0, 0}); }

/* An entity (and a child under it) with a NaN or Inf in its transform is
 * rejected with its name in the log; the rest renders exactly as without
 * it, and once the transform is fixed it is back. */
static void non_finite_transform_rejects_only_that_entity(void **state)
{
    (void)state;
    static const bad_transform cases[] = {
        {"NaN position", nan_position}, {"-Inf position", inf_position},
        {"Inf scale", inf_scale},       {"NaN rotation", nan_rotation},
        {"zero rotation", zero_rotation},
    };
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    base_scene b = build_base(&w);
    ob_node *bad = ob_test_world_entity(&w, NULL, "bad-entity", w.box, b.red, 0, 0.5, 1.2);
    ob_node *child = ob_test_world_entity(&w, bad, "bad-child", w.sphere, b.mirror, 0, 1.0, 0);
    uint8_t *good = render(&w, NULL);
    ob_node_set_hidden(bad, true);
    uint8_t *without = render(&w, NULL);
    ob_node_set_hidden(bad, false);
    assert_true(ob_test_image_max_diff(good, without, W, H) > 0);
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        ob_test_log_clear();
        double pos[3];
        double rot[4];
        float scale[3];
        ob_node_get_position(bad, pos);
        ob_node_get_rotation(bad, rot);
        ob_node_get_scale(bad, scale);
        cases[i].apply(bad);
        const ob_frame_stats *st;
        uint8_t *img = render(&w, &st);
        char what[96];
        snprintf(what, sizeof what, "%s on an entity with a child", cases[i].what);
        assert_int_equal(report_diff(what, without, img), 0);
        assert_true(ob_test_log_has("'bad-entity'", "not rendered", NULL));
        assert_false(ob_test_log_has("'bad-child'", NULL)); /* the ancestor is named once */
        assert_int_equal(ob_test_view_stats(st, "main")->draws, 3); /* ground and two boxes */
        free(img);
        ob_node_set_position(bad, pos);
        ob_node_set_rotation_d(bad, rot);
        ob_node_set_scale(bad, scale);
        img = render(&w, NULL);
        assert_int_equal(ob_test_image_max_diff(good, img, W, H), 0);
        assert_true(ob_test_log_has("'bad-entity'", "finite again", NULL));
        free(img);
    }
    (void)child;
    free(good);
    free(without);
    ob_test_world_destroy(&w);
}

/* A light or the camera with a non-finite transform: the light is left out
 * (the image is the one without it); the camera's view renders the clear
 * colour and the log names view and camera; both recover. */
static void non_finite_light_and_camera(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    base_scene b = build_base(&w);
    uint8_t *good = render(&w, NULL);
    ob_node *lamp = ob_test_world_light(&w, OB_LIGHT_POINT, false, 3.0f, 0, 1, 1);
    ob_node_set_position(lamp, (const double[3]){NAN, 1, 1});
    uint8_t *img = render(&w, NULL);
    assert_int_equal(report_diff("NaN point light vs none", good, img), 0);
    free(img);
    ob_node_set_position(b.sun, (const double[3]){3, INFINITY, 4});
    const ob_frame_stats *st;
    img = render(&w, &st);
    assert_null(ob_test_view_stats(st, "shadow:sun"));
    ob_node_set_hidden(b.sun, true);
    uint8_t *no_sun = render(&w, NULL);
    ob_node_set_hidden(b.sun, false);
    assert_int_equal(report_diff("Inf sun vs hidden sun", no_sun, img), 0);
    free(img);
    free(no_sun);
    ob_node_set_position(b.sun, (const double[3]){3, 8, 4});
    ob_node_destroy(w.scene, lamp);

    ob_test_log_clear();
    double eye[3];
    ob_node_get_position(w.camera, eye);
    ob_node_set_position(w.camera, (const double[3]){eye[0], NAN, eye[2]});
    img = render(&w, &st);
    assert_true(ob_test_log_has("'main'", "'camera'", NULL));
    uint32_t not_clear = 0;
    for (uint32_t i = 0; i < W * H; i++)
        not_clear += !is_clear(img + 4 * i);
    print_message("NaN camera: %u pixels differ from the clear colour\n", not_clear);
    assert_int_equal(not_clear, 0);
    free(img);
    ob_node_set_position(w.camera, eye);
    img = render(&w, NULL);
    assert_int_equal(report_diff("camera fixed again vs before", good, img), 0);
    free(img);
    free(good);
    ob_test_world_destroy(&w);
}

/* NaN or Inf given to a material setter is refused with its name; the
 * material keeps its value, so the image does not change. */
static void non_finite_material_parameter_is_refused(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    base_scene b = build_base(&w);
    uint8_t *before = render(&w, NULL);
    ob_test_log_clear();
    assert_int_equal(ob_material_set_diffuse(b.red, (const float[4]){NAN, 0, 0, 1}), OB_ERR_NON_FINITE);
    assert_int_equal(ob_material_set_specular(b.red, (const float[4]){1, 1, 1, INFINITY}),
                     OB_ERR_NON_FINITE);
    assert_int_equal(ob_material_set_emissive(b.ground, (const float[4]){0, -INFINITY, 0, 0}),
                     OB_ERR_NON_FINITE);
    assert_int_equal(ob_material_set_reflectivity(b.mirror, NAN), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("non-finite", NULL));
    assert_true(ob_test_log_count(OB_LOG_ERROR) >= 4);
    ob_result r;
    assert_null(ob_material_create(w.lib, &(ob_material_desc){.name = "nan-material",
                                                              .diffuse = {1, NAN, 1, 1}}, &r));
    assert_int_equal(r, OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("'nan-material'", NULL));
    uint8_t *after = render(&w, NULL);
    assert_int_equal(report_diff("material after refused NaN/Inf setters", before, after), 0);
    free(before);
    free(after);
    ob_test_world_destroy(&w);
}

/* NaN in a parameter written directly: refused, the slot keeps its value,
 * the next frame is unchanged. */
static void non_finite_parameter_is_refused(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &desc);
    build_base(&w);
    uint8_t *before = render(&w, NULL);
    ob_param_registry *reg = ob_renderer_registry(w.r);
    ob_params *params = ob_renderer_params(w.r);
    ob_param ambient = ob_param_find(reg, "AmbientColor");
    ob_param world = ob_param_registry_builtins(reg)->world;
    assert_true(ambient.id != 0);
    const float good[4] = {0.5f, 0.25f, 0.125f, 1.0f};
    assert_int_equal(ob_params_set_vec4(params, ambient, good), OB_OK);
    ob_test_log_clear();
    assert_int_equal(ob_params_set_vec4(params, ambient, (const float[4]){NAN, 0, 0, 1}),
                     OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("'AmbientColor'", "NaN or Inf", NULL));
    float now[4];
    assert_int_equal(ob_params_get_vec4(params, ambient, now), OB_OK);
    assert_memory_equal(now, good, sizeof good);
    assert_int_equal(ob_params_init_vec4(reg, ambient, (const float[4]){0, INFINITY, 0, 1}),
                     OB_ERR_NON_FINITE);
    float m[16];
    ob_mat4_identity(m);
    m[13] = NAN;
    assert_int_equal(ob_params_set_mat4(params, world, m), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("'WorldMatrix'", NULL));
    uint8_t *after = render(&w, NULL);
    assert_int_equal(report_diff("frame after refused NaN parameters", before, after), 0);
    free(before);
    free(after);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(zero_scale_entity_adds_nothing),
        cmocka_unit_test(flattened_box_shades_like_a_plane),
        cmocka_unit_test(camera_up_parallel_to_direction_renders),
        cmocka_unit_test(zero_size_view_is_refused),
        cmocka_unit_test(empty_scene_with_lights_is_the_clear_colour),
        cmocka_unit_test(switched_off_light_has_no_shadow_view),
        cmocka_unit_test(non_finite_transform_rejects_only_that_entity),
        cmocka_unit_test(non_finite_light_and_camera),
        cmocka_unit_test(non_finite_material_parameter_is_refused),
        cmocka_unit_test(non_finite_parameter_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
