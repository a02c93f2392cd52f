/* The viewer's camera control (demos/app/ob_orbit.h): what a user dragging
 * and scrolling would see go wrong — the eye leaving the target's distance,
 * the view flipping over the pole, a pan that does not follow the cursor,
 * a zoom through the target, framing that differs from the first view. */
#include <math.h>

#include "ob_orbit.h"
#include "ob_test.h"

static const double PI = 3.14159265358979323846;

static double dist3(const double a[3], const double b[3])
{
    double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

static void from_eye_round_trips(void **state)
{
    (void)state;
    ob_orbit o = {0};
    const double eye[3] = {3, 4, 12}, target[3] = {1, 2, -1};
    assert_true(ob_orbit_from_eye(&o, eye, target));
    double back[3];
    ob_orbit_eye(&o, back);
    for (int k = 0; k < 3; k++) assert_near(back[k], eye[k], 1e-9);
    assert_near(o.distance, dist3(eye, target), 1e-12);
    /* Degenerate and non-finite input changes nothing. */
    ob_orbit before = o;
    assert_false(ob_orbit_from_eye(&o, target, target));
    assert_false(ob_orbit_from_eye(&o, (double[3]){NAN, 0, 0}, target));
    assert_memory_equal(&o, &before, sizeof o);
}

/* Dragging turns about the target: the distance stays, a drag of the whole
 * height turns by pi, the scene turns with the cursor (drag right: the eye
 * goes left), and the pitch stops short of the pole. */
static void rotate_orbits_the_target(void **state)
{
    (void)state;
    ob_orbit o = {0};
    assert_true(ob_orbit_from_eye(&o, (double[3]){0, 0, 5}, (double[3]){0, 0, 0}));
    assert_true(ob_orbit_rotate(&o, 100, 0, 400));   /* a quarter height right */
    double eye[3];
    ob_orbit_eye(&o, eye);
    assert_near(dist3(eye, o.target), 5.0, 1e-12);
    assert_true(eye[0] < -1.0);                         /* the eye went left */
    assert_near(atan2(-eye[0], eye[2]), PI / 4, 1e-12);
    assert_true(ob_orbit_rotate(&o, -100, 0, 400));
    ob_orbit_eye(&o, eye);
    assert_near(eye[0], 0.0, 1e-12);
    assert_near(eye[2], 5.0, 1e-12);
    /* Down raises the eye; far past the pole it stops at OB_ORBIT_MAX_PITCH. */
    assert_true(ob_orbit_rotate(&o, 0, 40, 400));
    ob_orbit_eye(&o, eye);
    assert_true(eye[1] > 0.0);
    assert_true(ob_orbit_rotate(&o, 0, 100000, 400));
    assert_near(o.pitch, OB_ORBIT_MAX_PITCH, 1e-12);
    double right[3], up[3];
    ob_orbit_axes(&o, right, up);
    assert_true(up[1] > 0.0);                           /* not flipped */
    assert_false(ob_orbit_rotate(&o, NAN, 0, 400));
    assert_false(ob_orbit_rotate(&o, 1, 0, 0));
}

/* The axes are orthonormal and right-handed with the view direction. */
static void axes_are_orthonormal(void **state)
{
    (void)state;
    ob_orbit o = {.distance = 2, .yaw = 0.7, .pitch = -0.4};
    double right[3], up[3], eye[3];
    ob_orbit_axes(&o, right, up);
    ob_orbit_eye(&o, eye);
    double fwd[3] = {-eye[0] / 2, -eye[1] / 2, -eye[2] / 2};
    assert_near(right[0] * up[0] + right[1] * up[1] + right[2] * up[2], 0, 1e-12);
    assert_near(right[0] * fwd[0] + right[1] * fwd[1] + right[2] * fwd[2], 0, 1e-12);
    assert_near(up[0] * fwd[0] + up[1] * fwd[1] + up[2] * fwd[2], 0, 1e-12);
    assert_near(right[0] * right[0] + right[1] * right[1] + right[2] * right[2], 1, 1e-12);
    assert_near(up[0] * up[0] + up[1] * up[1] + up[2] * up[2], 1, 1e-12);
    /* right x up = -forward (the camera looks down -Z). */
    double c[3] = {right[1] * up[2] - right[2] * up[1], right[2] * up[0] - right[0] * up[2],
                   right[0] * up[1] - right[1] * up[0]};
    for (int k = 0; k < 3; k++) assert_near(c[k], -fwd[k], 1e-12);
}

/* A pan of the whole viewport height moves the target by the height the
 * view spans at the target's depth; the eye moves with it. */
static void pan_follows_the_cursor(void **state)
{
    (void)state;
    ob_orbit o = {0};
    assert_true(ob_orbit_from_eye(&o, (double[3]){0, 0, 10}, (double[3]){0, 0, 0}));
    const double fovy = PI / 2;   /* the view spans 2 * 10 * tan(45°) = 20 units */
    assert_true(ob_orbit_pan(&o, 0, 400, 400, fovy));   /* cursor dragged down */
    assert_near(o.target[1], 20.0, 1e-9);               /* the scene went down: the target up */
    assert_true(ob_orbit_pan(&o, 200, -400, 400, fovy));
    assert_near(o.target[0], -10.0, 1e-9);
    assert_near(o.target[1], 0.0, 1e-9);
    assert_near(o.distance, 10.0, 1e-12);
    assert_false(ob_orbit_pan(&o, 1, 1, 400, 0));
}

/* A wheel step in is 10% closer; out is back; never through the target or
 * off to infinity. */
static void zoom_scales_the_distance_within_bounds(void **state)
{
    (void)state;
    ob_orbit o = {0};
    assert_true(ob_orbit_from_eye(&o, (double[3]){0, 0, 10}, (double[3]){0, 0, 0}));
    assert_true(ob_orbit_zoom(&o, 1));
    assert_near(o.distance, 9.0, 1e-12);
    assert_true(ob_orbit_zoom(&o, -1));
    assert_near(o.distance, 10.0, 1e-12);
    assert_true(ob_orbit_zoom(&o, 1e6));
    assert_near(o.distance, o.min_distance, 1e-15);
    assert_true(o.distance > 0.0);
    assert_true(ob_orbit_zoom(&o, -1e6));
    assert_near(o.distance, o.max_distance, 1e-6);
    assert_false(ob_orbit_zoom(&o, INFINITY));
    assert_true(ob_orbit_znear(&o) > 0.0);
}

/* Framing keeps the direction and puts the sphere in the narrower field of
 * view the way ob_framing_aim_camera does (radius / sin(half) * 1.08). */
static void frame_fits_the_sphere(void **state)
{
    (void)state;
    ob_orbit o = {0};
    assert_true(ob_orbit_from_eye(&o, (double[3]){5, 5, 5}, (double[3]){0, 0, 0}));
    double yaw = o.yaw, pitch = o.pitch;
    const double fovy = 45.0 * PI / 180.0;
    assert_true(ob_orbit_frame(&o, (double[3]){1, 2, 3}, 2.0, fovy, 4.0 / 3.0));
    assert_near(o.distance, 2.0 / sin(fovy / 2) * 1.08, 1e-12);
    assert_near(o.yaw, yaw, 0);
    assert_near(o.pitch, pitch, 0);
    assert_near(o.target[2], 3.0, 0);
    /* A tall image: the horizontal field is the narrower one. */
    assert_true(ob_orbit_frame(&o, (double[3]){0, 0, 0}, 1.0, fovy, 0.5));
    assert_near(o.distance, 1.0 / sin(atan(tan(fovy / 2) * 0.5)) * 1.08, 1e-12);
    ob_orbit before = o;
    assert_false(ob_orbit_frame(&o, (double[3]){0, 0, 0}, 0.0, fovy, 1.0));
    assert_false(ob_orbit_frame(&o, (double[3]){0, 0, 0}, 1.0, fovy, NAN));
    assert_memory_equal(&o, &before, sizeof o);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(from_eye_round_trips),
        cmocka_unit_test(rotate_orbits_the_target),
        cmocka_unit_test(axes_are_orthonormal),
        cmocka_unit_test(pan_follows_the_cursor),
        cmocka_unit_test(zoom_scales_the_distance_within_bounds),
        cmocka_unit_test(frame_fits_the_sphere),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
