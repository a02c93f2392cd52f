/* ob_motion_lanes.h — the built-in rotation and orbit kernels over
 * OB_LANES nodes at once, included by ob_controllers_internal.h once per
 * lane width, OB_LANES defined to it (no include guard; the parameters of
 * the width: ob_lanes_begin.h). The includer also provides
 * OB_LANE(ob_lanes_store)(double *const d[OB_LANES], OB_VD v), which
 * stores lane l of v at d[l].
 *
 * Each lane does exactly the one-node form's operations in the same order,
 * without fused multiply-adds (ISO C mode: no contraction; and the wider
 * form's target adds no FMA), so a node moves by the same bits whatever
 * the width and whichever nodes share its group. Lanes past n repeat lane
 * 0 (its node takes their stores again, with the same values). */

#include "ob_lanes_begin.h"

/* sin and cos of the orbit angles x (|x| < 2pi, where the state keeps them;
 * NaN for a non-finite x), within an ulp of libm's: fdlibm's reduction by
 * pi/2 in three parts and its kernels on [-pi/4, pi/4], inline and without
 * libm's range checks and calls, which cost the update more than anything
 * else of the orbit (about a fifth of a warm update at 50k objects).
 * Inlined always: with two callers GCC made it a function whose arguments
 * went through memory. */
static inline __attribute__((always_inline)) OB_LANE_TARGET void
OB_LANE(orbit_sincos)(const OB_VD *in_x, OB_VD *out_s, OB_VD *out_c)
{
    OB_VD x = *in_x;
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
    OB_VD kb = x * two_over_pi + 0x1.8p52;
    OB_VD k = kb - 0x1.8p52;
    OB_VD t = x - k * pio2_1, w = k * pio2_2, r = t - w;
    r -= k * pio2_2t - ((t - r) - w);
    OB_VD z = r * r;
    OB_VD sr = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    OB_VD cp = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    OB_VD hz = 0.5 * z, one_hz = 1.0 - hz;
    OB_VD cr = one_hz + (((1.0 - one_hz) - hz) + z * cp);
    /* The quadrant picks and signs them without a branch: it differs from
     * one object to the next, and a mispredicted branch on it cost the
     * update a twentieth of its time. */
    OB_VU q = (OB_VU)kb & 3u, swap = -(q & 1u), sb = (OB_VU)sr, cb = (OB_VU)cr;
    OB_VU s_bits = ((sb & ~swap) | (cb & swap)) ^ ((q >> 1) << 63);
    OB_VU c_bits = ((cb & ~swap) | (sb & swap)) ^ ((((q + 1u) >> 1) & 1u) << 63);
    OB_VU abs_x = (OB_VU)x & ~(((OB_VU){0} + 1u) << 63);
    OB_VU bad = (OB_VU)((OB_VU)((OB_VD)abs_x < 8.0) == 0), nan = (OB_VU)(x - x);
    *out_s = (OB_VD)((s_bits & ~bad) | (nan & bad));
    *out_c = (OB_VD)((c_bits & ~bad) | (nan & bad));
}

/* position = center + radius (cos a u + sin a v), a += rate * dt, for
 * nodes x[0..n) (1 <= n <= OB_LANES). The caller marks the nodes dirty. */
static inline __attribute__((always_inline)) OB_LANE_TARGET void
OB_LANE(ob_orbit_kernel)(node_xf *const xn[OB_LANES], ob_orbit_state *const stn[OB_LANES],
                         uint32_t n, double dt)
{
    node_xf *x[OB_LANES];
    ob_orbit_state *st[OB_LANES];
    OB_LANES_PICK(x, xn, n);
    OB_LANES_PICK(st, stn, n);
    OB_VD angle = OB_LANES_OF(st, angle) + OB_LANES_OF(st, rate) * dt;
    OB_VD radius = OB_LANES_OF(st, radius);
    OB_VD center[3] = {OB_LANES_OF(st, center[0]), OB_LANES_OF(st, center[1]),
                       OB_LANES_OF(st, center[2])};
    OB_VD u[3] = {OB_LANES_OF(st, u[0]), OB_LANES_OF(st, u[1]), OB_LANES_OF(st, u[2])};
    OB_VD v[3] = {OB_LANES_OF(st, v[0]), OB_LANES_OF(st, v[1]), OB_LANES_OF(st, v[2])};
    /* fmod is exact, and the identity below 2pi: called only above. Every
     * lane: an unused one must stay equal to lane 0. */
    bool in_range = true;
    for (uint32_t l = 0; l < OB_LANES; l++) in_range &= fabs(angle[l]) < 2.0 * OB_PI;
    if (!in_range)
        for (uint32_t l = 0; l < OB_LANES; l++)
            if (!(fabs(angle[l]) < 2.0 * OB_PI)) angle[l] = fmod(angle[l], 2.0 * OB_PI);
    OB_LANE(ob_lanes_store)(OB_LANE_PTRS(st, angle), angle);
    OB_VD sin_a, cos_a;
    OB_LANE(orbit_sincos)(&angle, &sin_a, &cos_a);
    OB_VD c = cos_a * radius, s = sin_a * radius;
    for (int k = 0; k < 3; k++)
        OB_LANE(ob_lanes_store)(OB_LANE_PTRS(x, position[k]), center[k] + c * u[k] + s * v[k]);
}

/* q = q * step(axis, rate * dt) for nodes x[0..n) (1 <= n <= OB_LANES).
 * The caller marks the nodes dirty. In the usual case (every lane's
 * squared norm in the range where the one-node form rescales by 1 / |q|)
 * stores them and returns true; otherwise the two-lane form stores them
 * lane by lane, and the wider form stores nothing and returns false, for
 * its caller to run the nodes two at a time. */
static inline __attribute__((always_inline)) OB_LANE_TARGET bool
OB_LANE(ob_rotation_kernel)(node_xf *const xn[OB_LANES], ob_rotation_state *const stn[OB_LANES],
                            uint32_t n, double dt)
{
    node_xf *x[OB_LANES];
    ob_rotation_state *st[OB_LANES];
    OB_LANES_PICK(x, xn, n);
    OB_LANES_PICK(st, stn, n);
    for (uint32_t l = 0; l < n; l++) {
        if (dt == st[l]->step_dt) continue;
        ob_dquat_from_axis_angle(st[l]->axis, st[l]->rate * dt, st[l]->step);
        st[l]->step_dt = dt;
    }
    OB_VD a[4], b[4];
    for (int c = 0; c < 4; c++) {
        a[c] = OB_LANES_OF(x, rotation[c]);
        b[c] = OB_LANES_OF(st, step[c]);
    }
    /* ob_dquat_mul(rotation, step), then ob_dquat_normalize's usual case. */
    OB_VD q[4] = {OB_QUAT_MUL_X(a, b), OB_QUAT_MUL_Y(a, b), OB_QUAT_MUL_Z(a, b),
                  OB_QUAT_MUL_W(a, b)};
    OB_VD n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    OB_VD inv = 1.0 / OB_LANE_SQRT(n2);
    bool usual = true;
    for (uint32_t l = 0; l < OB_LANES; l++) usual &= OB_DQUAT_NORM2_USUAL(n2[l]);
    if (__builtin_expect(!usual, 0)) {
#if OB_LANES == 2
        ob_rotation_store_unusual(xn, q, n2, inv, n);
        return true;
#else
        return false;
#endif
    }
    /* The one-node form's multiplications, in the lanes. */
    for (int c = 0; c < 4; c++) OB_LANE(ob_lanes_store)(OB_LANE_PTRS(x, rotation[c]), q[c] * inv);
    for (uint32_t l = 0; l < OB_LANES; l++) x[l]->flags |= XF_ROTATION_UNIT;
    return true;
}

#include "ob_lanes_end.h"
