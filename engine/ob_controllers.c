/* ob_controllers.c — the built-in controllers (rotation, orbit, script),
 * written on the public node API (ob_node_add_controller) like any user
 * controller would be. State is kept in double so long runs do not drift. */
#include "ob_scene.h"

#define CONTROLLER_LOG "scene"

typedef struct rotation_state {
    double axis[3];   /* unit */
    double rate;      /* radians per second */
} rotation_state;

typedef struct orbit_state {
    double center[3];
    double u[3], v[3];   /* orthonormal basis of the orbit plane, v = axis x u */
    double radius;
    double rate;
    double angle;        /* kept in (-2pi, 2pi) so it never loses precision */
} orbit_state;

static void rotation_step(ob_node *n, double dt, void *user)
{
    const rotation_state *st = user;
    double q[4], dq[4];
    ob_node_get_rotation(n, q);
    ob_dquat_from_axis_angle(st->axis, st->rate * dt, dq);
    ob_dquat_mul(q, dq, q);
    /* Renormalizing every step keeps |q| = 1 to rounding for any number of
     * updates. A non-finite q is stored as is, so the update names the node. */
    ob_dquat_normalize(q, q);
    ob_node_set_rotation_d(n, q);
}

static void orbit_place(ob_node *n, const orbit_state *st)
{
    double c = cos(st->angle) * st->radius, s = sin(st->angle) * st->radius, p[3];
    for (int i = 0; i < 3; i++) p[i] = st->center[i] + c * st->u[i] + s * st->v[i];
    ob_node_set_position(n, p);
}

static void orbit_step(ob_node *n, double dt, void *user)
{
    orbit_state *st = user;
    st->angle = fmod(st->angle + st->rate * dt, 2.0 * OB_PI);
    orbit_place(n, st);
}

static bool axis_from_floats(const float axis[3], double dest[3])
{
    double a[3] = {axis[0], axis[1], axis[2]};
    return ob_dvec3_normalize(a, dest);
}

ob_result ob_node_add_rotation_controller(ob_node *n, const float axis[3], float radians_per_second)
{
    double a[3];
    if (!axis_from_floats(axis, a) || !isfinite(radians_per_second)) {
        OB_LOG_E(CONTROLLER_LOG, "entity '%s' (id %u): rotation controller needs a non-zero "
                 "finite axis and a finite rate; refused", ob_node_name(n), ob_node_id(n));
        return OB_ERR_INVALID_ARGUMENT;
    }
    rotation_state *st = ob_malloc(sizeof *st);
    if (!st) {
        OB_LOG_E(CONTROLLER_LOG, "entity '%s' (id %u): cannot add a rotation controller: out "
                 "of host memory", ob_node_name(n), ob_node_id(n));
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    ob_dvec3_copy(a, st->axis);
    st->rate = radians_per_second;
    return ob_node_add_controller(n, &(ob_controller_desc){.fn = rotation_step, .user = st,
                                                           .parallel = true,
                                                           .release = ob_free});
}

ob_result ob_node_add_orbit_controller(ob_node *n, const double center[3], const float axis[3],
                                       double radius, float radians_per_second, float phase)
{
    double a[3];
    if (!axis_from_floats(axis, a) || !ob_dvec3_is_finite(center) || !isfinite(radius) ||
        radius < 0.0 || !isfinite(radians_per_second) || !isfinite(phase)) {
        OB_LOG_E(CONTROLLER_LOG, "entity '%s' (id %u): orbit controller needs a non-zero finite "
                 "axis, a finite center, rate and phase and a radius >= 0; refused",
                 ob_node_name(n), ob_node_id(n));
        return OB_ERR_INVALID_ARGUMENT;
    }
    orbit_state *st = ob_malloc(sizeof *st);
    if (!st) {
        OB_LOG_E(CONTROLLER_LOG, "entity '%s' (id %u): cannot add an orbit controller: out of "
                 "host memory", ob_node_name(n), ob_node_id(n));
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    /* Angle 0 lies along the world axis least aligned with the orbit axis
     * (ties: X, then Y, then Z), projected into the plane: X for a Y axis. */
    int k = 0;
    if (fabs(a[1]) < fabs(a[k])) k = 1;
    if (fabs(a[2]) < fabs(a[k])) k = 2;
    double e[3] = {0.0, 0.0, 0.0}, proj[3];
    e[k] = 1.0;
    ob_dvec3_scale(a, ob_dvec3_dot(e, a), proj);
    ob_dvec3_sub(e, proj, st->u);
    ob_dvec3_normalize(st->u, st->u); /* |e - proj| >= sqrt(2/3): cannot fail */
    ob_dvec3_cross(a, st->u, st->v);
    ob_dvec3_copy(center, st->center);
    st->radius = radius;
    st->rate = radians_per_second;
    st->angle = phase;
    return ob_node_add_controller(n, &(ob_controller_desc){.fn = orbit_step, .user = st,
                                                           .parallel = true,
                                                           .release = ob_free});
}

ob_result ob_node_add_script_controller(ob_node *n, ob_controller_fn fn, void *user)
{
    return ob_node_add_controller(n, &(ob_controller_desc){.fn = fn, .user = user});
}
