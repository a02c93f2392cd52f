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

/* A node's built-in controllers while NODE_MOTION says it has no others:
 * 168 bytes beside each other in a dense array by slot, instead of two
 * 128-byte controller slots and their 24-byte list in two more places. */
struct node_motion {
    ob_orbit_state orbit;      /* while NODE_ORBIT */
    ob_rotation_state spin;    /* while NODE_SPIN */
};

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

/* sin and cos of an orbit's angle (|x| < 2pi, where its state keeps it;
 * NaN for a non-finite x), within an ulp of libm's: fdlibm's reduction by
 * pi/2 in three parts and its kernels on [-pi/4, pi/4], inline and without
 * libm's range checks and calls, which cost the update more than anything
 * else of the orbit (about a fifth of a warm update at 50k objects). */
static inline void orbit_sincos(double x, double *out_s, double *out_c)
{
    static const double two_over_pi = 6.36619772367581382433e-01;
    static const double pio2_1 = 1.57079632673412561417e+00;  /* first 33 bits of pi/2 */
    static const double pio2_2 = 6.07710050630396597660e-11;  /* the next 33 bits */
    static const double pio2_2t = 2.02226624879595063154e-21; /* pi/2 - pio2_1 - pio2_2 */
    static const double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                        S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                        S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
    static const double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                        C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                        C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
    if (!(fabs(x) < 8.0)) { /* NaN or infinite (never in the range) */
        *out_s = *out_c = x - x;
        return;
    }
    /* Rounded to the nearest integer by the addition (round to nearest). */
    double k = (x * two_over_pi + 0x1.8p52) - 0x1.8p52;
    double t = x - k * pio2_1, w = k * pio2_2, r = t - w;
    r -= k * pio2_2t - ((t - r) - w);
    double z = r * r;
    double sr = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    double cp = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    double hz = 0.5 * z, one_hz = 1.0 - hz;
    double cr = one_hz + (((1.0 - one_hz) - hz) + z * cp);
    int q = (int)k & 3;
    double s = (q & 1) ? cr : sr, c = (q & 1) ? sr : cr;
    *out_s = (q & 2) ? -s : s;
    *out_c = ((q + 1) & 2) ? -c : c;
}

/* position = center + radius (cos a u + sin a v), a += rate * dt. The
 * caller marks the node dirty. */
static inline void ob_orbit_kernel(node_xf *x, ob_orbit_state *st, double dt)
{
    double angle = st->angle + st->rate * dt;
    /* fmod is exact, and the identity below 2pi: call it only above. */
    st->angle = fabs(angle) < 2.0 * OB_PI ? angle : fmod(angle, 2.0 * OB_PI);
    double sin_a, cos_a;
    orbit_sincos(st->angle, &sin_a, &cos_a);
    double c = cos_a * st->radius, s = sin_a * st->radius;
    for (int i = 0; i < 3; i++) x->position[i] = st->center[i] + c * st->u[i] + s * st->v[i];
}

/* Runs the node's controllers in scene->motion (state: its NODE_* byte,
 * NODE_MOTION set). keep_world: other controllers run before the node's
 * evaluation and may read its world rotation, which must stay the last
 * update's (when they do not, it is left to follow the rotation: the
 * evaluation comes right after). [the slot's own thread] */
static inline void ob_motion_run(ob_scene *s, uint32_t slot, uint8_t state, double dt,
                                 bool keep_world)
{
    node_motion *m = &s->motion[slot];
    if (state & NODE_ORBIT) ob_orbit_kernel(&s->xf[slot], &m->orbit, dt);
    if (state & NODE_SPIN) {
        if (keep_world) node_world_rotation_keep(s, slot);
        ob_rotation_kernel(&s->xf[slot], &m->spin, dt);
    }
    s->state[slot] = (uint8_t)(state | NODE_DIRTY);
}

/* Runs controller c of the node in slot: a built-in one's kernel in place,
 * any other through its function. keep_world: as for ob_motion_run.
 * [the slot's own thread] */
static inline void ob_controller_run(ob_scene *s, uint32_t slot, ob_controller_slot *c, double dt,
                                     bool keep_world)
{
    if (c->fn == ob_rotation_controller_step) {
        if (keep_world) node_world_rotation_keep(s, slot);
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
