/* Issue 28 (first slice): many point lights and spot lights.
 *
 * - 256 point lights light a wall, and each adds its contribution: the
 *   image with all of them equals, in linear light, the sum of four images
 *   with 64 of them each (minus three times the unlit image, which carries
 *   the ambient term every render adds once).
 * - A spot light lights inside its cone like a point light, nothing outside
 *   it, and something in between on the soft edge.
 * - glTF KHR_lights_punctual lights of a model, loaded through a scene
 *   file, are light nodes placed by the model entity's transform.
 * - Lights over OB_MAX_LIGHTS are logged once by name and counted in the
 *   frame stats every frame.
 * - The same many-light scene renders byte-identically single- and
 *   multi-threaded, and with the light tiles off (every light evaluated in
 *   every fragment).
 *
 * The wall faces the camera (+Z) at z = 0, the camera at (0, 0, 8) looks
 * at it; the composite's tone map is off and its exposure low so no pixel
 * clips (the sum of linear colours is then the colour of the sum). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_scene_load.h"
#include "ob_test_world.h"

#define DATA OB_SOURCE_DIR "/tests/data/scenes/"

#define GRID 16                  /* 16 x 16 = 256 point lights */
#define LIGHTS (GRID * GRID)
#define EXPOSURE 0.25f

static double srgb_to_linear(double c)
{
    c /= 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* Half the linear width of 8-bit code c: how far the stored code can be
 * from the value it rounds. */
static double half_step(int c)
{
    double lo = srgb_to_linear(c > 0 ? c - 0.5 : 0), hi = srgb_to_linear(c < 255 ? c + 0.5 : 255);
    return (hi - lo) / 2.0;
}

static ob_node *wall_of(ob_test_world *w, ob_geometry *g, ob_material *m)
{
    ob_node *n = ob_world_entity(w, NULL, "wall", g, m, 0, 0, 0);
    /* The XZ plane turned about X by 90 degrees: it faces +Z. */
    double s = sqrt(0.5);
    ob_node_set_rotation_d(n, (const double[4]){s, 0, 0, s});
    return n;
}

static ob_node *wall(ob_test_world *w, float r, float g, float b)
{
    return wall_of(w, w->plane, ob_world_material(w, "wall", OB_MATERIAL_LIT, r, g, b, false));
}

/* A rough dielectric glTF material of the same colour, on the plane in the
 * extended vertex layout the PBR shaders read (a mesh with vertex colours,
 * white here). */
static ob_node *pbr_wall(ob_test_world *w, float r, float g, float b)
{
    ob_geometry *plane = ob_test_world_pbr_plane(w, 1);
    ob_material_desc md = {.name = "pbr wall", .kind = OB_MATERIAL_PBR, .pbr = ob_material_pbr_defaults()};
    md.pbr.base_color[0] = r, md.pbr.base_color[1] = g, md.pbr.base_color[2] = b;
    md.pbr.metallic = 0.0f;
    md.pbr.roughness = 0.8f;
    return wall_of(w, plane, ob_world_material_desc(w, &md));
}

static void setup(ob_test_world *w, uint32_t workers)
{
    ob_test_world_create(w, &(ob_test_world_desc){.workers = workers});
    ob_world_look(w, 0, 0, 8, 0, 0, 0);
    ob_composite_view_set_tonemap(w->composite, false);
    ob_composite_view_set_exposure(w->composite, EXPOSURE);
}


/* 256 coloured point lights of range 2.5 on a 16 x 16 grid 0.6 in front of
 * the wall, covering the camera's view. */
static void add_point_grid(ob_test_world *w, ob_node *out[LIGHTS], float intensity)
{
    for (int i = 0; i < LIGHTS; i++) {
        int gx = i % GRID, gy = i / GRID;
        ob_light_desc d = {.type = OB_LIGHT_POINT,
                           .color = {0.3f + 0.7f * (float)gx / GRID, 0.5f,
                                     0.3f + 0.7f * (float)gy / GRID},
                           .intensity = intensity, .range = 2.5f};
        char name[32];
        snprintf(name, sizeof name, "lamp %d", i);
        out[i] = ob_test_world_light(w, name, &d, -6.0 + 0.8 * gx, -4.5 + 0.6 * gy, 0.6);
    }
}

/* The grey lit wall under the 256 point lights. */
static void wall_under_point_grid(ob_test_world *w, uint32_t workers, float grey, ob_node *out[LIGHTS])
{
    setup(w, workers);
    wall(w, grey, grey, grey);
    add_point_grid(w, out, 0.6f);
}

static void set_intensity(ob_node *n, float intensity)
{
    ob_light_desc d = *ob_node_get_light(n);
    d.intensity = intensity;
    assert_int_equal(ob_node_set_light(n, &d), OB_OK);
}

static void point_lights_add_up(bool pbr)
{
    ob_test_world w;
    setup(&w, 0);
    if (pbr) pbr_wall(&w, 0.8f, 0.8f, 0.8f);
    else wall(&w, 0.8f, 0.8f, 0.8f);
    ob_node *lights[LIGHTS];
    add_point_grid(&w, lights, 0.6f);
    const uint32_t n = w.width * w.height * 4;

    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_test_world_frame(&w, OB_THREADING_SINGLE, 0)->lights_over_limit, 0);
    uint8_t *all = ob_world_snapshot(&w);
    uint8_t *part[4];
    for (int k = 0; k < 4; k++) {
        for (int i = 0; i < LIGHTS; i++) set_intensity(lights[i], i / 64 == k ? 0.6f : 0.0f);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        part[k] = ob_world_snapshot(&w);
    }
    for (int i = 0; i < LIGHTS; i++) set_intensity(lights[i], 0.0f);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *none = ob_world_snapshot(&w);

    /* all - none == sum_k (part_k - none) in linear light, within the
     * rounding of the six 8-bit images (half a code each, in linear) plus
     * 1e-3 for the half-float target and summation order. */
    uint32_t bad = 0, lit = 0;
    double worst = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        if (i % 4 == 3) continue;
        double want = srgb_to_linear(all[i]) - srgb_to_linear(none[i]);
        double got = 0.0, tol = half_step(all[i]) + 3.0 * half_step(none[i]) + 1e-3;
        for (int k = 0; k < 4; k++) {
            got += srgb_to_linear(part[k][i]) - srgb_to_linear(none[i]);
            tol += half_step(part[k][i]);
        }
        double err = fabs(got - want);
        if (err > tol) bad++;
        if (err - tol > worst) worst = err - tol;
        lit += want > 0.05;
        /* No clipping: the sum is only linear below 1 (exposure 0.25). */
        assert_true(all[i] < 255);
    }
    if (bad) fail_msg("%u channels: 256 lights differ from the sum of 4 x 64 (worst %.4f beyond tolerance)",
                      bad, worst);
    assert_true(lit > n / 2);   /* the lights do light most of the wall */
    /* Each quarter of the lights lights something the others do not. */
    for (int k = 0; k < 4; k++) assert_true(ob_rgba_diff_count(part[k], none, n / 4, 8) > 200);
    free(all);
    free(none);
    for (int k = 0; k < 4; k++) free(part[k]);
    ob_test_world_destroy(&w);
}

static void every_point_light_adds_its_contribution(void **state)
{
    (void)state;
    point_lights_add_up(false);
}

/* The same through the PBR shader. */
static void every_point_light_adds_its_contribution_pbr(void **state)
{
    (void)state;
    point_lights_add_up(true);
}

/* Pixel of the wall point (x, y, 0) for the camera at (0, 0, 8), fovy 1. */
static const uint8_t *wall_pixel(ob_test_world *w, double x, double y)
{
    double scale = (w->height / 2.0) / (8.0 * tan(0.5));
    return ob_world_pixel(w, (uint32_t)lround(w->width / 2.0 + x * scale - 0.5),
                          (uint32_t)lround(w->height / 2.0 - y * scale - 0.5));
}

static void spot_light_lights_its_cone_with_a_soft_edge(void **state)
{
    (void)state;
    const double h = 4.0;   /* the light 4 in front of the wall, shining at it (-Z) */
    const float inner = (float)(20.0 * OB_PI / 180.0), outer = (float)(30.0 * OB_PI / 180.0);
    /* Wall points at 10, 25 and 40 degrees off the axis (along +X). */
    const double at[3] = {h * tan(10.0 * OB_PI / 180.0), h * tan(25.0 * OB_PI / 180.0),
                          h * tan(40.0 * OB_PI / 180.0)};
    uint8_t spot[3], point[3];
    for (int pass = 0; pass < 2; pass++) {
        ob_test_world w;
        setup(&w, 0);
        wall(&w, 0.9f, 0.9f, 0.9f);
        ob_light_desc d = {.type = pass ? OB_LIGHT_POINT : OB_LIGHT_SPOT, .intensity = 12.0f,
                           .inner_angle = pass ? 0.0f : inner, .outer_angle = pass ? 0.0f : outer};
        ob_test_world_light(&w, "torch", &d, 0, 0, h);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        for (int k = 0; k < 3; k++) (pass ? point : spot)[k] = wall_pixel(&w, at[k], 0)[1];
        ob_test_world_destroy(&w);
    }
    /* Inside the inner cone: exactly the point light. */
    assert_true(point[0] > 60);
    assert_int_equal(spot[0], point[0]);
    /* Outside the outer cone: dark (the ambient term only), where the point
     * light still lights. */
    assert_true(point[2] > spot[2] + 20);
    /* On the edge, between the two. */
    assert_true(spot[1] > spot[2] + 5);
    assert_true(spot[1] + 5 < point[1]);
}

static void lights_over_the_limit_are_reported_once_by_name(void **state)
{
    (void)state;
    ob_test_world w;
    ob_node *lights[LIGHTS];
    wall_under_point_grid(&w, 0, 0.8f, lights);
    ob_light_desc d = {.type = OB_LIGHT_SPOT, .intensity = 1.0f};
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "extra %d", i);
        ob_test_world_light(&w, name, &d, i, 0, 2);
    }
    ob_test_log_clear();
    assert_int_equal(ob_test_world_frame(&w, OB_THREADING_SINGLE, 0)->lights_over_limit, 3);
    for (int i = 0; i < 3; i++) {
        char name[40];
        snprintf(name, sizeof name, "light 'extra %d'", i);
        assert_true(ob_test_log_has(name, "over the limit of 256", NULL));
    }
    assert_false(ob_test_log_has("lamp 255", "over the limit", NULL));
    ob_test_log_clear();
    assert_int_equal(ob_test_world_frame(&w, OB_THREADING_SINGLE, 0)->lights_over_limit, 3);
    assert_false(ob_test_log_has("over the limit", NULL));   /* once, not every frame */
    /* One light fewer under the limit: an extra one takes its place. */
    set_intensity(lights[0], 0.0f);
    assert_int_equal(ob_test_world_frame(&w, OB_THREADING_SINGLE, 0)->lights_over_limit, 2);
    ob_test_world_destroy(&w);
}

/* Many lights, many objects (instanced runs with different lights on each
 * member), spot and point: single- and multi-threaded frames agree byte for
 * byte and command hash for command hash. */
static void many_lights_same_in_every_threading_mode(void **state)
{
    (void)state;
    ob_test_world w;
    ob_node *lights[LIGHTS];
    wall_under_point_grid(&w, 4, 0.7f, lights);
    set_intensity(lights[LIGHTS - 1], 0.0f);   /* room for the spot under the limit */
    ob_light_desc spot = {.type = OB_LIGHT_SPOT, .intensity = 6.0f, .range = 9.0f,
                          .inner_angle = 0.3f, .outer_angle = 0.5f};
    ob_test_world_light(&w, "torch", &spot, 1, 1, 5);
    ob_material *m = ob_world_material(&w, "ball", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    for (int i = 0; i < 120; i++)
        ob_world_entity(&w, NULL, "ball", w.box, m, -5.5 + 1.0 * (i % 12), -4 + 0.8 * (i / 12), 0.4);
    const uint32_t n = w.width * w.height * 4;
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t st_hash = st->frame_hash;
    uint8_t *single = ob_world_snapshot(&w);
    for (uint32_t workers = 1; workers <= 4; workers += 3) {
        st = ob_test_world_frame(&w, OB_THREADING_MULTI, workers);
        assert_true(st->frame_hash == st_hash);
        uint8_t *multi = ob_world_snapshot(&w);
        assert_int_equal(ob_rgba_diff_count(single, multi, n / 4, 0), 0);
        free(multi);
    }
    /* The tile grid only leaves out what adds exactly zero: without it
     * (every light in every fragment) the pixels are the same. */
    assert_int_equal(st->lights_over_limit, 0);
    ob_views_set_light_tiles(w.views, false);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *untiled = ob_world_snapshot(&w);
    assert_int_equal(ob_rgba_diff_count(single, untiled, n / 4, 0), 0);
    free(untiled);
    free(single);
    ob_test_world_destroy(&w);
}

static ob_node *find_light(ob_scene *scene, const char *name)
{
    uint32_t count = 0;
    ob_node *const *lights = ob_scene_lights(scene, &count);
    for (uint32_t i = 0; i < count; i++)
        if (strcmp(ob_node_name(lights[i]), name) == 0) return lights[i];
    fail_msg("no light node '%s'", name);
    return NULL;
}

static void gltf_lights_are_light_nodes_of_the_model(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_scene_loaded l;
    ob_scene_file_error err;
    /* "../models/" is outside the scene's folder: trusted test content. */
    ob_result r = ob_scene_load_stack(w.stack, &(ob_scene_load_desc){.path = DATA "load_lights.json",
                                                                     .allow_any_folder = true},
                                      &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);   /* updates the snapshot */

    const ob_light_desc *spot = ob_node_get_light(find_light(w.scene, "scene-spot"));
    assert_int_equal(spot->type, OB_LIGHT_SPOT);
    assert_float_equal(spot->outer_angle, 20.0 * OB_PI / 180.0, 1e-6);

    /* lights.gltf under the entity at (10, 0, 0): the lamp at (0, 0, 2) of
     * the model, the torch at (1, 0, 3) aimed down (-Y). */
    ob_node *lamp = find_light(w.scene, "lamp_node");
    assert_int_equal(ob_node_get_light(lamp)->type, OB_LIGHT_POINT);
    assert_float_equal(ob_node_get_light(lamp)->range, 5.0, 1e-6);
    double p[3];
    ob_node_world_position(lamp, p);
    assert_float_equal(p[0], 10.0, 1e-9);
    assert_float_equal(p[2], 2.0, 1e-9);
    ob_node *torch = find_light(w.scene, "torch_node");
    assert_int_equal(ob_node_get_light(torch)->type, OB_LIGHT_SPOT);
    float right[3], up[3], fwd[3];
    ob_node_world_axes(torch, right, up, fwd);
    assert_float_equal(fwd[1], -1.0, 1e-5);
    ob_node_world_position(torch, p);
    assert_float_equal(p[0], 11.0, 1e-9);
    assert_int_equal(ob_node_get_light(find_light(w.scene, "sky_node"))->type, OB_LIGHT_DIRECTIONAL);
    ob_scene_unload(&l);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_point_light_adds_its_contribution),
        cmocka_unit_test(every_point_light_adds_its_contribution_pbr),
        cmocka_unit_test(spot_light_lights_its_cone_with_a_soft_edge),
        cmocka_unit_test(gltf_lights_are_light_nodes_of_the_model),
        cmocka_unit_test(lights_over_the_limit_are_reported_once_by_name),
        cmocka_unit_test(many_lights_same_in_every_threading_mode),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
