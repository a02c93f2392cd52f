/* ob_update_lanes.h — the scene update's common node (see simple_node in
 * ob_scene_update.c) over OB_LANES nodes at once, included by
 * ob_scene_update.c once per lane width, OB_LANES defined to it (no
 * include guard; the parameters of the width: ob_lanes_begin.h).
 *
 * Each lane does exactly the operations of ob_scene_xf_local,
 * node_world_bound, proxy_write_world and proxy_write_finite in their
 * order (the same bits whatever the width), without the stages' flags and
 * stores in between. Lanes past n repeat lane 0. */

#include "ob_lanes_begin.h"

#if OB_LANES == 2
#define OB_INDEX_PTRS(a) ((double *const[2]){&(a)[i[0]], &(a)[i[1]]})
#else
#define OB_INDEX_PTRS(a) ((double *const[4]){&(a)[i[0]], &(a)[i[1]], &(a)[i[2]], &(a)[i[3]]})
#endif

/* proxy_write_world's float 3x3 of each lane's world m into p[l], and
 * whether each mirrors (bit l): ob_det3_negative of the floats stored,
 * evaluated in the lanes on the same values, so the same answer. */
static inline __attribute__((always_inline)) OB_LANE_TARGET int
OB_LANE(proxy_linear)(ob_render_proxy *const p[OB_LANES], const OB_VD m[9])
{
#if OB_LANES == 4
    OB_VD lf[9];
    __m128 f[9];
    for (int k = 0; k < 9; k++) {
        f[k] = _mm256_cvtpd_ps((__m256d)m[k]);
        lf[k] = (OB_VD)_mm256_cvtps_pd(f[k]);
    }
    for (int k = 0; k < 8; k += 4) {
        /* Entries k..k + 3 of every lane: a 4x4 transpose. */
        __m128 r0 = f[k], r1 = f[k + 1], r2 = f[k + 2], r3 = f[k + 3];
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        _mm_storeu_ps(&p[0]->linear[k], r0);
        _mm_storeu_ps(&p[1]->linear[k], r1);
        _mm_storeu_ps(&p[2]->linear[k], r2);
        _mm_storeu_ps(&p[3]->linear[k], r3);
    }
    _mm_store_ss(&p[0]->linear[8], f[8]);
    _mm_store_ss(&p[1]->linear[8], _mm_shuffle_ps(f[8], f[8], 1));
    _mm_store_ss(&p[2]->linear[8], _mm_shuffle_ps(f[8], f[8], 2));
    _mm_store_ss(&p[3]->linear[8], _mm_shuffle_ps(f[8], f[8], 3));
#elif defined(__SSE2__)
    OB_VD lf[9];
    __m128 f[9];
    for (int k = 0; k < 9; k++) {
        f[k] = _mm_cvtpd_ps(m[k]);
        lf[k] = _mm_cvtps_pd(f[k]);
    }
    for (int k = 0; k < 8; k += 2) {
        __m128 pair = _mm_unpacklo_ps(f[k], f[k + 1]); /* k and k + 1 of lane 0, then lane 1 */
        _mm_storel_pi((__m64 *)&p[0]->linear[k], pair);
        _mm_storeh_pi((__m64 *)&p[1]->linear[k], pair);
    }
    _mm_store_ss(&p[0]->linear[8], f[8]);
    _mm_store_ss(&p[1]->linear[8], _mm_shuffle_ps(f[8], f[8], 1));
#else
    OB_VD lf[9];
    for (uint32_t l = 0; l < OB_LANES; l++)
        for (int k = 0; k < 9; k++) lf[k][l] = p[l]->linear[k] = (float)m[k][l];
#endif
    OB_VU negative = (OB_VU)(OB_DET3_COLUMNS(lf, lf + 3, lf + 6) < 0.0);
    int mirrors = 0;
    for (uint32_t l = 0; l < OB_LANES; l++) mirrors |= (int)(negative[l] & 1u) << l;
    return mirrors;
}

/* Evaluates the simple nodes of items[0..n) (1 <= n <= OB_LANES). False,
 * with nothing written, when a position or scale is not finite: those
 * nodes take node_eval's way, which names them. */
static OB_LANE_TARGET bool OB_LANE(eval_simple)(ob_scene *s, const level_item *items, uint32_t n)
{
    uint32_t slot[OB_LANES], i[OB_LANES];
    node_xf *x[OB_LANES];
    ob_render_proxy *p[OB_LANES];
    level_item it[OB_LANES];
    OB_LANES_PICK(it, items, n);
    for (uint32_t l = 0; l < OB_LANES; l++) {
        slot[l] = it[l].slot;
        x[l] = &s->xf[slot[l]];
    }
    OB_VD t[3] = {OB_LANES_OF(x, position[0]), OB_LANES_OF(x, position[1]),
                  OB_LANES_OF(x, position[2])};
    OB_VD sc[3] = {OB_LANES_OF(x, scale[0]), OB_LANES_OF(x, scale[1]), OB_LANES_OF(x, scale[2])};
    /* ob_scene_xf_local's test, in the lanes: v - v is 0 for a finite v
     * and NaN otherwise (a float's double is finite when it is). */
    OB_VD bad = ((t[0] - t[0]) + (t[1] - t[1])) + ((t[2] - t[2]) + (sc[0] - sc[0])) +
                ((sc[1] - sc[1]) + (sc[2] - sc[2]));
    bool finite = true;
    for (uint32_t l = 0; l < OB_LANES; l++) finite &= bad[l] == 0.0;
    if (__builtin_expect(!finite, 0)) return false;
    /* ob_daffine_from_trs(position, rotation, scale): the rotation is unit */
    OB_VD m[9];
    OB_QUAT_TO_MAT3_SCALED(OB_VD, OB_LANES_OF(x, rotation[0]), OB_LANES_OF(x, rotation[1]),
                           OB_LANES_OF(x, rotation[2]), OB_LANES_OF(x, rotation[3]), sc[0], sc[1],
                           sc[2], m);
    /* node_world_bound */
    OB_VD cx = OB_LANES_OF(x, local_center[0]), cy = OB_LANES_OF(x, local_center[1]),
          cz = OB_LANES_OF(x, local_center[2]);
    OB_VD center[3];
    for (int r = 0; r < 3; r++) center[r] = OB_AFFINE_ROW(m, t, r, cx, cy, cz);
    OB_VD best = {0.0};
    for (int c = 0; c < 3; c++) {
        /* ob_daffine_max_scale's choice: d where d > best, else best */
        OB_VD d = OB_COLUMN_LENGTH2(m, c);
        OB_VU more = (OB_VU)(d > best);
        best = (OB_VD)(((OB_VU)d & more) | ((OB_VU)best & ~more));
    }
    OB_VD scale = OB_LANE_SQRT(best);
    OB_VD radius = OB_LANES_OF(x, local_radius) * scale;
    /* Every lane stored, from the registers: a repeated lane repeats lane
     * 0's stores with the same values. */
    for (uint32_t l = 0; l < OB_LANES; l++) {
        i[l] = x[l]->proxy_index;
        p[l] = &s->proxies[i[l]];
    }
    int mirrors = OB_LANE(proxy_linear)(p, m);
    for (int k = 0; k < 9; k++) OB_LANE(ob_lanes_store)(OB_LANE_PTRS(x, world.m[k]), m[k]);
    for (int k = 0; k < 3; k++) {
        OB_LANE(ob_lanes_store)(OB_LANE_PTRS(x, world.t[k]), t[k]);
        OB_LANE(ob_lanes_store)(OB_LANE_PTRS(p, world_t[k]), t[k]);
    }
    OB_LANE(ob_lanes_store)(OB_INDEX_PTRS(s->soa_x), center[0]);
    OB_LANE(ob_lanes_store)(OB_INDEX_PTRS(s->soa_y), center[1]);
    OB_LANE(ob_lanes_store)(OB_INDEX_PTRS(s->soa_z), center[2]);
    for (uint32_t l = 0; l < OB_LANES; l++) {
        node_xf *xl = x[l];
        float r = (float)radius[l];
        xl->flags = (xl->flags & ~(uint32_t)(XF_EFFECTIVE_HIDDEN | XF_IDENTITY)) | XF_WORLD_VALID |
                    XF_WORLD_ROT_LOCAL;
        s->state[slot[l]] =
            (uint8_t)((s->state[slot[l]] & ~(NODE_DIRTY | NODE_IN_LIGHTS)) | NODE_CHANGED);
        s->soa_radius[i[l]] = r;
        s->soa_flags[i[l]] = zero_scale_flag(xl, r);
        p[l]->finite = linear_finite(p[l]->linear, scale[l]);
        p[l]->mirrors = (uint8_t)((mirrors >> l) & 1);
    }
    return true;
}

#undef OB_INDEX_PTRS
#include "ob_lanes_end.h"
