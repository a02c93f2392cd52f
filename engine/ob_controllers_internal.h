/* ob_controllers_internal.h — the built-in rotation and orbit controllers
 * as kernels on a node's slot data. ob_controllers.c adds them to nodes
 * (their state inline, ob_node_add_controller_state) with the functions
 * below as their ob_controller_fn; the scene update recognises those and
 * runs the kernel in its own loop instead, with no call through a pointer
 * and no visit to the node. Not installed.
 */
#ifndef OB_CONTROLLERS_INTERNAL_H
#define OB_CONTROLLERS_INTERNAL_H

#include "ob_scene_internal.h"

#include <string.h>

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

typedef struct ob_rotation_state {
    double axis[3];   /* unit */
    double rate;      /* radians per second */
    double step_dt;   /* the dt step is for (NaN: none yet) */
    double step[4];   /* rotation of one update: most updates have the last one's dt */
} ob_rotation_state;

typedef struct ob_orbit_state {
    double center[3];
    double u[3], v[3];   /* orthonormal basis of the orbit plane, v = axis x u */
    double radius;
    double rate;
    double angle;        /* kept in (-2pi, 2pi) so it never loses precision */
} ob_orbit_state;

/* The ob_controller_fn of each (the kernel on the node's slot data). */
void ob_rotation_controller_step(ob_node *n, double dt, void *user);
void ob_orbit_controller_step(ob_node *n, double dt, void *user);

/* q = q * step(axis, rate * dt). The caller marks the node dirty. */
static inline void ob_rotation_kernel(node_xf *x, ob_rotation_state *st, double dt)
{
    double q[4];
    if (dt != st->step_dt) {
        ob_dquat_from_axis_angle(st->axis, st->rate * dt, st->step);
        st->step_dt = dt;
    }
    ob_dquat_mul(x->rotation, st->step, q);
    /* Renormalizing every step keeps |q| = 1 to rounding for any number of
     * updates, and the update takes q as it is instead of normalizing it
     * again. A non-finite q is stored as is, so the update names the node. */
    if (ob_dquat_normalize(q, q)) x->flags |= XF_ROTATION_UNIT;
    else x->flags &= ~(uint32_t)XF_ROTATION_UNIT;
    memcpy(x->rotation, q, sizeof q);
}

/* position = center + radius (cos a u + sin a v), a += rate * dt. The
 * caller marks the node dirty. */
static inline void ob_orbit_kernel(node_xf *x, ob_orbit_state *st, double dt)
{
    double angle = st->angle + st->rate * dt;
    /* fmod is exact, and the identity below 2pi: call it only above. */
    st->angle = fabs(angle) < 2.0 * OB_PI ? angle : fmod(angle, 2.0 * OB_PI);
    double c = cos(st->angle) * st->radius, s = sin(st->angle) * st->radius;
    for (int i = 0; i < 3; i++) x->position[i] = st->center[i] + c * st->u[i] + s * st->v[i];
}

/* Runs controller c of the node in slot: a built-in one's kernel in place,
 * any other through its function. [the slot's own thread] */
static inline void ob_controller_run(ob_scene *s, uint32_t slot, ob_controller_slot *c, double dt)
{
    if (c->fn == ob_rotation_controller_step) {
        ob_rotation_kernel(&s->xf[slot], (ob_rotation_state *)(void *)c->state, dt);
        s->state[slot] |= NODE_DIRTY;
    } else if (c->fn == ob_orbit_controller_step) {
        ob_orbit_kernel(&s->xf[slot], (ob_orbit_state *)(void *)c->state, dt);
        s->state[slot] |= NODE_DIRTY;
    } else {
        c->fn(s->by_id[slot], dt, controller_user(c));
    }
}

#pragma GCC visibility pop

#endif /* OB_CONTROLLERS_INTERNAL_H */
