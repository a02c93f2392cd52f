/* Issue 28: shadows of spot and point lights.
 *
 * - A shadowed spot light over a floor with a box in its cone: the floor
 *   behind the box (from the light) is darker than the floor beside it at
 *   the same distance and angle, which the same light without shadows
 *   lights alike; the same through the PBR shader.
 * - A shadowed point light among four boxes: behind each box (four cube
 *   faces) the floor is darker than beside it.
 * - A shadowed light whose range (or spot cone) reaches nothing the camera
 *   sees queues no shadow view (noted as not needed) and its scene draws as
 *   without it.
 * - A shadow view with no caster in its cone records nothing (reported
 *   empty) and changes no pixel.
 * - Shadowed lights past OB_MAX_LOCAL_SHADOW_LAYERS light unshadowed,
 *   logged once by name and noted over the limit every frame.
 *
 * The floor is the XZ plane; the camera looks down at it from (0, 9, 6);
 * materials have no specular highlight, so a floor point's colour depends
 * only on its distance and angle to the light. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_math.h"
#include "ob_test_world.h"

static void setup(ob_test_world *w)
{
    ob_test_world_create(w, &(ob_test_world_desc){.width = 320, .height = 240});
    ob_world_look(w, 0, 9, 6, 0, 0, 0);
}

/* The floor: lit, or a rough dielectric glTF material on the plane in the
 * extended vertex layout the PBR shaders read (white vertex colours). */
static void add_floor(ob_test_world *w, bool pbr)
{
    if (!pbr) {
        ob_world_entity(w, NULL, "floor", w->plane,
                        ob_world_material(w, "floor", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, false), 0, 0, 0);
        return;
    }
    ob_geometry *plane = ob_test_world_pbr_plane(w, 2);
    ob_material_desc md = {.name = "pbr floor", .kind = OB_MATERIAL_PBR, .pbr = ob_material_pbr_defaults()};
    md.pbr.metallic = 0.0f;
    md.pbr.roughness = 1.0f;
    ob_world_entity(w, NULL, "floor", plane, ob_world_material_desc(w, &md), 0, 0, 0);
}


static ob_node *box(ob_test_world *w, const char *name, double x, double y, double z, float size)
{
    ob_material *m = ob_world_material(w, "box", OB_MATERIAL_LIT, 0.7f, 0.4f, 0.2f, true);
    ob_node *n = ob_world_entity(w, NULL, name, w->box, m, x, y, z);
    ob_node_set_scale(n, (const float[3]){size, size, size});
    return n;
}

/* Green channel of the final image at world point p, projected through the
 * main camera (fovy 1, reversed-Z, as the perspective view makes it). */
static int pixel_at(ob_test_world *w, double x, double y, double z)
{
    double eye[3];
    ob_node_world_position(w->camera, eye);
    float view[16], proj[16], vp[16];
    ob_node_view_relative(w->camera, eye, view);
    const ob_camera_desc *cam = ob_node_get_camera(w->camera);
    ob_math_perspective_reverse_z(cam->fovy > 0.0f ? cam->fovy : 1.0471976f,
                                  (float)w->width / (float)w->height, 0.1f, proj);
    ob_mat4_mul(proj, view, vp);
    float rel[3] = {(float)(x - eye[0]), (float)(y - eye[1]), (float)(z - eye[2])};
    float clip[4];
    for (int r = 0; r < 4; r++)
        clip[r] = vp[r] * rel[0] + vp[4 + r] * rel[1] + vp[8 + r] * rel[2] + vp[12 + r];
    assert_true(clip[3] > 0.0f);
    double px = (clip[0] / clip[3] * 0.5 + 0.5) * w->width, py = (clip[1] / clip[3] * 0.5 + 0.5) * w->height;
    assert_true(px >= 0 && px < w->width && py >= 0 && py < w->height);
    return ob_world_pixel(w, (uint32_t)px, (uint32_t)py)[1];
}

static void set_shadows(ob_node *light, bool on)
{
    ob_light_desc d = *ob_node_get_light(light);
    d.casts_shadows = on;
    assert_int_equal(ob_node_set_light(light, &d), OB_OK);
}

/* The spot 4 above the floor shining down; a box at (1, 1.5, 0) throws
 * its shadow about (1.6, 0, 0); (-1.6, 0, 0) is the same distance and
 * angle from the light on the other side, with nothing in between. */
static void spot_shadow_darkens_the_floor_behind_a_caster(bool pbr)
{
    ob_test_world w;
    setup(&w);
    add_floor(&w, pbr);
    box(&w, "caster", 1.0, 1.5, 0.0, 0.6f);
    ob_light_desc d = {.type = OB_LIGHT_SPOT, .intensity = 10.0f, .range = 12.0f,
                       .inner_angle = 0.6f, .outer_angle = 0.8f, .casts_shadows = true};
    ob_node *spot = ob_test_world_light(&w, "torch", &d, 0, 4, 0);
    assert_int_equal(ob_node_look_at(spot, (const double[3]){0, 0, 0}, (const double[3]){0, 0, -1}),
                     OB_OK);
    for (int pass = 0; pass < 2; pass++) {
        set_shadows(spot, pass == 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
        ob_world_read(&w);
        int behind = pixel_at(&w, 1.6, 0, 0), beside = pixel_at(&w, -1.6, 0, 0);
        if (pass == 0) {
            const ob_view_stats *vs = ob_world_view_stats(st, "shadow:torch");
            assert_non_null(vs);
            assert_true(vs->draws > 0);
            if (!(behind + 30 < beside)) fail_msg("behind the box %d, beside it %d", behind, beside);
        } else {
            /* Without shadows: lit alike, and no shadow view. */
            assert_null(ob_world_view_stats(st, "shadow:torch"));
            assert_true(abs(behind - beside) <= 2);
            assert_true(beside > 40);
        }
    }
    ob_test_world_destroy(&w);
}

static void spot_light_shadows_lit(void **state)
{
    (void)state;
    spot_shadow_darkens_the_floor_behind_a_caster(false);
}

static void spot_light_shadows_pbr(void **state)
{
    (void)state;
    spot_shadow_darkens_the_floor_behind_a_caster(true);
}

/* The bulb 1.2 above the floor, a box (top 0.8) 1.5 away on each axis: its
 * shadow covers the floor from 1.9 to 5.7 out; (3, 0, 0) is behind it,
 * (2.12, 0, 2.12) the same distance from the bulb between two shadows. */
static void point_light_shadows_every_side(void **state)
{
    (void)state;
    ob_test_world w;
    setup(&w);
    add_floor(&w, false);
    static const double dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int k = 0; k < 4; k++) {
        char name[16];
        snprintf(name, sizeof name, "box%d", k);
        box(&w, name, 1.5 * dirs[k][0], 0.4, 1.5 * dirs[k][1], 0.8f);
    }
    ob_light_desc d = {.type = OB_LIGHT_POINT, .intensity = 8.0f, .range = 12.0f,
                       .casts_shadows = true};
    ob_test_world_light(&w, "bulb", &d, 0, 1.2, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_non_null(ob_world_view_stats(st, "shadow:bulb"));
    ob_world_read(&w);
    const double s = 3.0 * sqrt(0.5);
    for (int k = 0; k < 4; k++) {
        int behind = pixel_at(&w, 3.0 * dirs[k][0], 0, 3.0 * dirs[k][1]);
        /* Beside: turned 45 degrees from this box towards the next. */
        int beside = pixel_at(&w, s * (dirs[k][0] + dirs[k][1]), 0, s * (dirs[k][1] - dirs[k][0]));
        if (!(behind + 30 < beside))
            fail_msg("side %d: behind the box %d, beside it %d", k, behind, beside);
    }
    ob_test_world_destroy(&w);
}

/* Far off to the side with a short range: it lights nothing the camera
 * sees, so its map is not drawn, and the image is as without it. */
static void light_out_of_view_queues_no_shadow_view(void **state)
{
    (void)state;
    ob_test_world w;
    setup(&w);
    add_floor(&w, false);
    box(&w, "caster", 0.0, 0.5, 0.0, 1.0f);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 3, 8, 2);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *without = ob_world_snapshot(&w);
    ob_light_desc spot = {.type = OB_LIGHT_SPOT, .intensity = 5.0f, .range = 3.0f,
                          .outer_angle = 0.5f, .casts_shadows = true};
    ob_light_desc point = {.type = OB_LIGHT_POINT, .intensity = 5.0f, .range = 3.0f,
                           .casts_shadows = true};
    ob_test_world_light(&w, "far-spot", &spot, 60, 1, 0);
    /* A point light beside a caster, but its range ends before the floor
     * the camera sees: the plane is 20 wide, the light 40 off. */
    ob_test_world_light(&w, "far-bulb", &point, 0, 1, 40);
    box(&w, "far-caster", 0.0, 0.5, 39.0, 1.0f);
    /* Above the floor's bound (a sphere of radius 14), in range of it, but
     * its cone points up: the cone, not the range sphere, decides. */
    ob_light_desc upward = spot;
    upward.range = 20.0f;
    ob_node *up = ob_test_world_light(&w, "up-spot", &upward, 0, 16, 0);
    assert_int_equal(ob_node_look_at(up, (const double[3]){0, 30, 0}, (const double[3]){0, 0, -1}),
                     OB_OK);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    assert_null(ob_world_view_stats(st, "shadow:far-spot"));
    assert_null(ob_world_view_stats(st, "shadow:far-bulb"));
    assert_int_equal(ob_world_skip_reason(st, "shadow:far-spot"), OB_SKIP_NOT_NEEDED);
    assert_int_equal(ob_world_skip_reason(st, "shadow:far-bulb"), OB_SKIP_NOT_NEEDED);
    assert_int_equal(ob_world_skip_reason(st, "shadow:up-spot"), OB_SKIP_NOT_NEEDED);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), 0);
    uint8_t *with = ob_world_snapshot(&w);
    assert_int_equal(ob_rgba_diff_count(without, with, w.width * w.height, 0), 0);
    free(without);
    free(with);
    ob_test_world_destroy(&w);
}

/* A spot over a floor that casts nothing, with a small box inside its
 * square frustum but outside its round cone (a corner): the box reaches
 * no layer, so the view records nothing and says so, and the lit floor is
 * as without shadows. */
static void no_caster_in_reach_records_nothing(void **state)
{
    (void)state;
    ob_test_world w;
    setup(&w);
    add_floor(&w, false);
    box(&w, "corner", 2.1, 0.1, 2.1, 0.2f);
    ob_light_desc d = {.type = OB_LIGHT_SPOT, .intensity = 10.0f, .range = 12.0f,
                       .outer_angle = 0.5f, .casts_shadows = true};
    ob_node *spot = ob_test_world_light(&w, "torch", &d, 0, 4, 0);
    assert_int_equal(ob_node_look_at(spot, (const double[3]){0, 0, 0}, (const double[3]){0, 0, -1}),
                     OB_OK);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    const ob_view_stats *vs = ob_world_view_stats(st, "shadow:torch");
    assert_non_null(vs);
    assert_int_equal(vs->draws, 0);
    assert_int_equal(vs->skipped, OB_SKIP_EMPTY);
    uint8_t *with = ob_world_snapshot(&w);
    set_shadows(spot, false);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *without = ob_world_snapshot(&w);
    assert_int_equal(ob_rgba_diff_count(without, with, w.width * w.height, 0), 0);
    free(without);
    free(with);
    ob_test_world_destroy(&w);
}

/* Three point lights need 18 layers: the third lights unshadowed, named
 * once in the log and noted over the limit every frame. */
static void lights_past_the_shadow_layers_are_reported_once(void **state)
{
    (void)state;
    ob_test_world w;
    setup(&w);
    add_floor(&w, false);
    box(&w, "caster", 0.0, 0.5, 0.0, 1.0f);
    ob_light_desc d = {.type = OB_LIGHT_POINT, .intensity = 3.0f, .range = 10.0f,
                       .casts_shadows = true};
    for (int i = 0; i < 3; i++) {
        char name[16];
        snprintf(name, sizeof name, "bulb%d", i);
        ob_test_world_light(&w, name, &d, -2.0 + 2.0 * i, 2.5, 1.0);
    }
    ob_test_log_clear();
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_non_null(ob_world_view_stats(st, "shadow:bulb0"));
    assert_non_null(ob_world_view_stats(st, "shadow:bulb1"));
    assert_null(ob_world_view_stats(st, "shadow:bulb2"));
    assert_int_equal(ob_world_skip_reason(st, "shadow:bulb2"), OB_SKIP_OVER_LIMIT);
    assert_true(ob_test_log_has("light 'bulb2'", "shadow layers", NULL));
    ob_test_log_clear();
    st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    assert_int_equal(ob_world_skip_reason(st, "shadow:bulb2"), OB_SKIP_OVER_LIMIT);
    assert_false(ob_test_log_has("shadow layers", NULL));   /* once, not every frame */
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(spot_light_shadows_lit),
        cmocka_unit_test(spot_light_shadows_pbr),
        cmocka_unit_test(point_light_shadows_every_side),
        cmocka_unit_test(light_out_of_view_queues_no_shadow_view),
        cmocka_unit_test(no_caster_in_reach_records_nothing),
        cmocka_unit_test(lights_past_the_shadow_layers_are_reported_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
