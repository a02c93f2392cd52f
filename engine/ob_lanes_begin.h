/* ob_lanes_begin.h — the parameters of a lane template (ob_motion_lanes.h,
 * ob_update_lanes.h) for the width OB_LANES the includer defined, 2 or 4
 * (4: only where ob_controllers_internal.h defines OB_MOTION_LANES4):
 *   OB_VD, OB_VU      vectors of that many doubles and uint64_t
 *   OB_LANE(name)     the name with the width appended
 *   OB_LANE_TARGET    the function attribute the width's instructions need
 *   OB_LANE_SQRT(v)   every lane's correctly rounded square root
 *   OB_LANES_OF(p, e) the vector of p[l]->e, p an array of OB_LANES pointers
 *   OB_LANE_PTRS(p, e) the array of the OB_LANES pointers &p[l]->e (the
 *                     destinations of OB_LANE(ob_lanes_store))
 *   OB_LANES_PICK(dst, src, n) dst[l] = src[l] for the n lanes in use,
 *                     src[0] for the others (an unused lane repeats lane 0)
 * No include guard: the template includes ob_lanes_end.h, which undefines
 * them and OB_LANES. */
#define OB_LANES_PICK(dst, src, n)                                                                 \
    for (uint32_t l_ = 0; l_ < OB_LANES; l_++) (dst)[l_] = (src)[l_ < (n) ? l_ : 0]
#if OB_LANES == 2
#define OB_VD ob_v2d
#define OB_VU ob_v2u
#define OB_LANE(name) name##2
#define OB_LANE_TARGET
#define OB_LANE_SQRT OB_V2D_SQRT
#define OB_LANES_OF(p, e) ((OB_VD){(p)[0]->e, (p)[1]->e})
#define OB_LANE_PTRS(p, e) ((double *const[2]){&(p)[0]->e, &(p)[1]->e})
#elif OB_LANES == 4
#define OB_VD ob_v4d
#define OB_VU ob_v4u
#define OB_LANE(name) name##4
#define OB_LANE_TARGET __attribute__((target("avx2")))
#define OB_LANE_SQRT(v) ((ob_v4d)_mm256_sqrt_pd((__m256d)(v)))
#define OB_LANES_OF(p, e) ((OB_VD){(p)[0]->e, (p)[1]->e, (p)[2]->e, (p)[3]->e})
#define OB_LANE_PTRS(p, e) ((double *const[4]){&(p)[0]->e, &(p)[1]->e, &(p)[2]->e, &(p)[3]->e})
#else
#error "OB_LANES is 2 or 4"
#endif
