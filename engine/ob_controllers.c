/* ob_controllers.c — the built-in controllers (rotation, orbit, script).
 * The rotation and orbit controllers keep their state in the scene
 * (scene->motion, or as ob_node_add_controller_state's copy once the node
 * has other controllers), in double so long runs do not drift;
 * their steps are kernels on the node's slot data
 * (ob_controllers_internal.h), which the update runs in its own loop. */
#include "ob_controllers_internal.h"

#define CONTROLLER_LOG "scene"

void ob_rotation_controller_step(ob_node *n, double dt, void *user)
{
    node_world_rotation_keep(n->scene, n->by_id_index);
    ob_rotation_kernel(node_xf_of(n), user, dt);
    node_touch(n);
}

void ob_orbit_controller_step(ob_node *n, double dt, void *user)
{
    ob_orbit_kernel(node_xf_of(n), user, dt);
    node_touch(n);
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
    ob_rotation_state st = {.axis = {a[0], a[1], a[2]}, .rate = radians_per_second,
                            .step_dt = NAN};
    return ob_scene_motion_add(n, NODE_SPIN, &st, sizeof st);
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
    ob_orbit_state state, *st = &state;
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
    return ob_scene_motion_add(n, NODE_ORBIT, st, sizeof *st);
}

ob_result ob_node_add_script_controller(ob_node *n, ob_controller_fn fn, void *user)
{
    return ob_node_add_controller(n, &(ob_controller_desc){.fn = fn, .user = user});
}
