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
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/* The built-in controllers run on two nodes at once, as lanes of GCC and
 * Clang vector types: two doubles fill an SSE2 register, which every
 * x86-64 CPU has (four-wide ones were built through the stack there and
 * cost more than they saved). Each lane does exactly the operations of the
 * one-node form, in the same order and without fused multiply-adds (ISO C
 * mode: no contraction), so a node moves by the same bits whichever node
 * shares its pair: the update stays deterministic for any thread count and
 * chunking. */
typedef double ob_v2d __attribute__((vector_size(16)));
typedef uint64_t ob_v2u __attribute__((vector_size(16)));
/* Both lanes' square roots: the correctly rounded root either way, one
 * instruction with SSE2 (libm's sqrt carries a branch for errno). */
#if defined(__SSE2__)
#define OB_V2D_SQRT(v) ((ob_v2d)_mm_sqrt_pd(v))
#else
#define OB_V2D_SQRT(v) ((ob_v2d){sqrt((v)[0]), sqrt((v)[1])})
#endif

/* Stores lane 0 of v at d0 and lane 1 at d1, straight from the register
 * with SSE2. A group of one node passes its node twice (its lanes are
 * equal), so that no store waits on a branch. */
static inline void ob_v2d_store2(double *d0, double *d1, ob_v2d v)
{
#if defined(__SSE2__)
    _mm_storel_pd(d0, v);
    _mm_storeh_pd(d1, v);
#else
    *d0 = v[0];
    *d1 = v[1];
#endif
}

/* ob_rotation_kernel2's stores when a lane's squared norm n2 lies outside
 * the usual range: lane by lane, as the one-node form. inv: 1 / |q|. */
static void __attribute__((cold, noinline, unused))
ob_rotation_store_unusual(node_xf *const x[2], const ob_v2d q[4], ob_v2d n2, ob_v2d inv, uint32_t n)
{
    for (uint32_t l = 0; l < n; l++) {
        double r[4] = {q[0][l], q[1][l], q[2][l], q[3][l]};
        /* Renormalizing every step keeps |q| = 1 to rounding for any
         * number of updates, and the update takes q as it is instead of
         * normalizing it again. Outside the usual range the one-node form
         * rescales; a non-finite q is stored as is, so the update names
         * the node. */
        bool unit = true;
        if (OB_DQUAT_NORM2_USUAL(n2[l]))
            for (int c = 0; c < 4; c++) r[c] *= inv[l];
        else
            unit = ob_dquat_normalize(r, r);
        if (unit) x[l]->flags |= XF_ROTATION_UNIT;
        else x[l]->flags &= ~(uint32_t)XF_ROTATION_UNIT;
        memcpy(x[l]->rotation, r, sizeof r);
    }
}

/* q = q * step(axis, rate * dt) for nodes x[0..n) (n 1 or 2; an unused
 * lane repeats lane 0, and node 0 takes its stores again). The caller
 * marks the nodes dirty. Inlined always, as the orbit's: the caller's
 * loop keeps the lanes in registers. */
static inline __attribute__((always_inline)) void
ob_rotation_kernel2(node_xf *const x[2], ob_rotation_state *const st[2], uint32_t n, double dt)
{
    for (uint32_t l = 0; l < n; l++) {
        if (dt == st[l]->step_dt) continue;
        ob_dquat_from_axis_angle(st[l]->axis, st[l]->rate * dt, st[l]->step);
        st[l]->step_dt = dt;
    }
    uint32_t i1 = n > 1 ? 1 : 0;
#define A(c) (ob_v2d){x[0]->rotation[c], x[i1]->rotation[c]}
#define B(c) (ob_v2d){st[0]->step[c], st[i1]->step[c]}
    ob_v2d a[4] = {A(0), A(1), A(2), A(3)}, b[4] = {B(0), B(1), B(2), B(3)};
#undef A
#undef B
    /* ob_dquat_mul(rotation, step), then ob_dquat_normalize's usual case. */
    ob_v2d q[4] = {OB_QUAT_MUL_X(a, b), OB_QUAT_MUL_Y(a, b), OB_QUAT_MUL_Z(a, b),
                   OB_QUAT_MUL_W(a, b)};
    ob_v2d n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    ob_v2d inv = 1.0 / OB_V2D_SQRT(n2);
    if (__builtin_expect(!(OB_DQUAT_NORM2_USUAL(n2[0]) && OB_DQUAT_NORM2_USUAL(n2[1])), 0)) {
        ob_rotation_store_unusual(x, q, n2, inv, n);
        return;
    }
    /* The usual case in both lanes (an unused lane repeats lane 0): the
     * one-node form's multiplications, in the lanes. */
    for (int c = 0; c < 4; c++) {
        q[c] *= inv;
        ob_v2d_store2(&x[0]->rotation[c], &x[i1]->rotation[c], q[c]);
    }
    x[0]->flags |= XF_ROTATION_UNIT;
    x[i1]->flags |= XF_ROTATION_UNIT;
}

/* sin and cos of two orbit angles (|x| < 2pi, where the state keeps them;
 * NaN for a non-finite x), within an ulp of libm's: fdlibm's reduction by
 * pi/2 in three parts and its kernels on [-pi/4, pi/4], inline and without
 * libm's range checks and calls, which cost the update more than anything
 * else of the orbit (about a fifth of a warm update at 50k objects).
 * Inlined always: called from two places, GCC made it a function whose
 * arguments go through memory. */
static inline __attribute__((always_inline)) void
orbit_sincos2(const ob_v2d *in_x, ob_v2d *out_s, ob_v2d *out_c)
{
    ob_v2d x = *in_x;
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
    /* Rounded to the nearest integer k by the addition (round to nearest),
     * which leaves k mod 4 in the two low bits of kb's mantissa. Outside
     * |x| < 8 (NaN, infinite: never in the range) the lane's result is
     * replaced by x - x below. */
    ob_v2d kb = x * two_over_pi + 0x1.8p52;
    ob_v2d k = kb - 0x1.8p52;
    ob_v2d t = x - k * pio2_1, w = k * pio2_2, r = t - w;
    r -= k * pio2_2t - ((t - r) - w);
    ob_v2d z = r * r;
    ob_v2d sr = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    ob_v2d cp = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    ob_v2d hz = 0.5 * z, one_hz = 1.0 - hz;
    ob_v2d cr = one_hz + (((1.0 - one_hz) - hz) + z * cp);
    /* The quadrant picks and signs them without a branch: it differs from
     * one object to the next, and a mispredicted branch on it cost the
     * update a twentieth of its time. */
    ob_v2u q = (ob_v2u)kb & 3u, swap = -(q & 1u), sb = (ob_v2u)sr, cb = (ob_v2u)cr;
    ob_v2u s_bits = ((sb & ~swap) | (cb & swap)) ^ ((q >> 1) << 63);
    ob_v2u c_bits = ((cb & ~swap) | (sb & swap)) ^ ((((q + 1u) >> 1) & 1u) << 63);
    ob_v2u abs_x = (ob_v2u)x & ~((ob_v2u){1, 1} << 63);
    ob_v2u bad = (ob_v2u)((ob_v2u)((ob_v2d)abs_x < 8.0) == 0), nan = (ob_v2u)(x - x);
    *out_s = (ob_v2d)((s_bits & ~bad) | (nan & bad));
    *out_c = (ob_v2d)((c_bits & ~bad) | (nan & bad));
}

/* position = center + radius (cos a u + sin a v), a += rate * dt, for
 * nodes x[0..n) (n 1 or 2, as for ob_rotation_kernel2). The caller marks
 * the nodes dirty. */
static inline __attribute__((always_inline)) void
ob_orbit_kernel2(node_xf *const x[2], ob_orbit_state *const st[2], uint32_t n, double dt)
{
    uint32_t i1 = n > 1 ? 1 : 0;
#define F(field) (ob_v2d){st[0]->field, st[i1]->field}
    ob_v2d angle = F(angle) + F(rate) * dt, radius = F(radius);
    ob_v2d center[3] = {F(center[0]), F(center[1]), F(center[2])};
    ob_v2d u[3] = {F(u[0]), F(u[1]), F(u[2])}, v[3] = {F(v[0]), F(v[1]), F(v[2])};
#undef F
    /* fmod is exact, and the identity below 2pi: called only above. */
    /* Both lanes: an unused one must stay equal to lane 0. */
    if (!(fabs(angle[0]) < 2.0 * OB_PI && fabs(angle[1]) < 2.0 * OB_PI))
        for (uint32_t l = 0; l < 2; l++)
            if (!(fabs(angle[l]) < 2.0 * OB_PI)) angle[l] = fmod(angle[l], 2.0 * OB_PI);
    ob_v2d_store2(&st[0]->angle, &st[i1]->angle, angle);
    ob_v2d sin_a, cos_a;
    orbit_sincos2(&angle, &sin_a, &cos_a);
    ob_v2d c = cos_a * radius, s = sin_a * radius;
    ob_v2d p[3];
    for (int k = 0; k < 3; k++) p[k] = center[k] + c * u[k] + s * v[k];
    for (int k = 0; k < 3; k++) ob_v2d_store2(&x[0]->position[k], &x[i1]->position[k], p[k]);
}

/* The one-node forms (a group of one). */
static inline void ob_rotation_kernel(node_xf *x, ob_rotation_state *st, double dt)
{
    node_xf *xs[2] = {x};
    ob_rotation_state *sts[2] = {st};
    ob_rotation_kernel2(xs, sts, 1, dt);
}

static inline void ob_orbit_kernel(node_xf *x, ob_orbit_state *st, double dt)
{
    node_xf *xs[2] = {x};
    ob_orbit_state *sts[2] = {st};
    ob_orbit_kernel2(xs, sts, 1, dt);
}

/* Runs controller c of the node in slot: a built-in one's kernel in place,
 * any other through its function. keep_world: other controllers run
 * before the node's evaluation and may read its world rotation, which must
 * stay the last update's (when they do not, it is left to follow the
 * rotation: the evaluation comes right after). [the slot's own thread] */
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
