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
 * cost more than they saved); where the CPU has AVX2 (asked at run time),
 * the update's usual step runs four at once in a function built for it.
 * Each lane does exactly the operations of the one-node form, in the same
 * order and without fused multiply-adds (ISO C mode: no contraction; the
 * AVX2 target adds no FMA), so a node moves by the same bits whichever
 * nodes share its group and whatever the width: the update stays
 * deterministic for any thread count, chunking and CPU. */
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

/* The kernels two nodes at once (every x86-64 CPU has SSE2) and, where
 * the CPU has AVX2, four (the update's usual step): ob_motion_lanes.h. */
#define OB_LANES 2
static inline __attribute__((always_inline)) void ob_lanes_store2(double *const d[2], ob_v2d v)
{
    ob_v2d_store2(d[0], d[1], v);
}
#include "ob_motion_lanes.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define OB_MOTION_LANES4 1
typedef double ob_v4d __attribute__((vector_size(32)));
typedef uint64_t ob_v4u __attribute__((vector_size(32)));
static inline __attribute__((always_inline, target("avx2"))) void
ob_lanes_store4(double *const d[4], ob_v4d v)
{
    __m128d lo = _mm256_castpd256_pd128((__m256d)v), hi = _mm256_extractf128_pd((__m256d)v, 1);
    _mm_storel_pd(d[0], lo);
    _mm_storeh_pd(d[1], lo);
    _mm_storel_pd(d[2], hi);
    _mm_storeh_pd(d[3], hi);
}
#define OB_LANES 4
#include "ob_motion_lanes.h"
#endif

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
