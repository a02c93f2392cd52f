/* ob_math.h — the numerically careful math of Obelisk.
 *
 * What it is: double-precision vectors, quaternions and affine transforms for
 * the scene graph, plus the float matrices the GPU sees (reversed-Z
 * projections, camera-relative world and view matrices) and frustum culling.
 *
 * Why doubles: the scene composes world transforms in double on the CPU and
 * hands the GPU float matrices *relative to a camera origin* (translation =
 * world - origin, subtracted in double, then cast). A scene 1e7 units from the
 * origin therefore renders exactly like the same scene at the origin.
 *
 * Conventions: right-handed; a camera looks down its local -Z with +Y up.
 * Float 4x4 matrices are column-major float[16] (element (row r, col c) at
 * [c*4 + r]), the same memory layout as cglm's mat4. Linear 3x3 parts are
 * column-major double[9]. Quaternions are (x, y, z, w). Clip space is
 * Vulkan's: depth in [0, 1], y pointing down in the framebuffer.
 * Depth is reversed everywhere (near → 1, far → 0): clear depth to 0 and use
 * VK_COMPARE_OP_GREATER_OR_EQUAL.
 *
 * Lifecycle: none (pure functions, no allocation). The small functions the
 * scene update runs per node are inline definitions here (C99 inline: the
 * library still exports each, from ob_math.c).
 * Thread rule: every function is [any thread]; outputs may alias inputs only
 * where a function says so.
 */
#ifndef OB_MATH_H
#define OB_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define OB_PI 3.14159265358979323846

/* ------------------------------------------------------------ double vec3 */

typedef double ob_dvec3[3];

static inline void ob_dvec3_set(double x, double y, double z, double dest[3])
{
    dest[0] = x;
    dest[1] = y;
    dest[2] = z;
}
static inline void ob_dvec3_copy(const double a[3], double dest[3])
{
    dest[0] = a[0];
    dest[1] = a[1];
    dest[2] = a[2];
}
static inline void ob_dvec3_add(const double a[3], const double b[3], double dest[3])
{
    dest[0] = a[0] + b[0];
    dest[1] = a[1] + b[1];
    dest[2] = a[2] + b[2];
}
static inline void ob_dvec3_sub(const double a[3], const double b[3], double dest[3])
{
    dest[0] = a[0] - b[0];
    dest[1] = a[1] - b[1];
    dest[2] = a[2] - b[2];
}
static inline void ob_dvec3_scale(const double a[3], double s, double dest[3])
{
    dest[0] = a[0] * s;
    dest[1] = a[1] * s;
    dest[2] = a[2] * s;
}
static inline double ob_dvec3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
/* dest may alias a or b. */
static inline void ob_dvec3_cross(const double a[3], const double b[3], double dest[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    dest[0] = x;
    dest[1] = y;
    dest[2] = z;
}
static inline double ob_dvec3_length(const double a[3]) { return sqrt(ob_dvec3_dot(a, a)); }
static inline bool ob_dvec3_is_finite(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}
/* Unit vector along a. Returns false (dest untouched) when a is zero or not
 * finite. dest may alias a. */
bool ob_dvec3_normalize(const double a[3], double dest[3]);

/* ------------------------------------------------------ double quaternion */

void ob_dquat_identity(double dest[4]);
/* Rotation of `angle` radians about `axis` (need not be unit; a zero axis
 * gives the identity). */
void ob_dquat_from_axis_angle(const double axis[3], double angle, double dest[4]);
/* Components x, y, z, w of the quaternion product a * b (a[0..4), b[0..4)
 * in x, y, z, w order), in any arithmetic type (as OB_QUAT_TO_MAT3_SCALED
 * below). */
#define OB_QUAT_MUL_X(a, b) ((a)[3] * (b)[0] + (a)[0] * (b)[3] + (a)[1] * (b)[2] - (a)[2] * (b)[1])
#define OB_QUAT_MUL_Y(a, b) ((a)[3] * (b)[1] - (a)[0] * (b)[2] + (a)[1] * (b)[3] + (a)[2] * (b)[0])
#define OB_QUAT_MUL_Z(a, b) ((a)[3] * (b)[2] + (a)[0] * (b)[1] - (a)[1] * (b)[0] + (a)[2] * (b)[3])
#define OB_QUAT_MUL_W(a, b) ((a)[3] * (b)[3] - (a)[0] * (b)[0] - (a)[1] * (b)[1] - (a)[2] * (b)[2])
/* dest = a * b (b applied first). dest may alias a or b. */
inline void ob_dquat_mul(const double a[4], const double b[4], double dest[4])
{
    double x = OB_QUAT_MUL_X(a, b), y = OB_QUAT_MUL_Y(a, b);
    double z = OB_QUAT_MUL_Z(a, b), w = OB_QUAT_MUL_W(a, b);
    dest[0] = x;
    dest[1] = y;
    dest[2] = z;
    dest[3] = w;
}
/* Whether ob_dquat_normalize takes its usual case for a squared length n2
 * (then each component times 1 / sqrt(n2)). */
#define OB_DQUAT_NORM2_USUAL(n2) ((n2) > 0x1p-900 && (n2) < 0x1p900)
/* Unit quaternion along q. Returns false (dest untouched) when q is zero or
 * not finite. dest may alias q. */
inline bool ob_dquat_normalize(const double q[4], double dest[4])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double n2 = x * x + y * y + z * z + w * w;
    /* The usual case (a near-unit rotation, every update of every node):
     * the squares neither overflow nor underflow, so no rescaling (four
     * divisions) is needed. A NaN or infinite component fails the test. */
    if (OB_DQUAT_NORM2_USUAL(n2)) {
        double inv = 1.0 / sqrt(n2);
        dest[0] = x * inv;
        dest[1] = y * inv;
        dest[2] = z * inv;
        dest[3] = w * inv;
        return true;
    }
    if (!isfinite(x) || !isfinite(y) || !isfinite(z) || !isfinite(w)) return false;
    double big = fmax(fmax(fabs(x), fabs(y)), fmax(fabs(z), fabs(w)));
    if (big == 0.0) return false;
    x /= big;
    y /= big;
    z /= big;
    w /= big;
    double inv = 1.0 / sqrt(x * x + y * y + z * z + w * w);
    dest[0] = x * inv;
    dest[1] = y * inv;
    dest[2] = z * inv;
    dest[3] = w * inv;
    return true;
}
/* q must be unit. dest may alias v. */
void ob_dquat_rotate(const double q[4], const double v[3], double dest[3]);
/* The column-major rotation matrix of unit quaternion (x, y, z, w), each
 * column times its scale (s0, s1, s2), into dest[0..9), in arithmetic type
 * T: double, or a vector of doubles (the scene update's lanes), so that
 * every form does the same operations in the same order. */
#define OB_QUAT_TO_MAT3_SCALED(T, x, y, z, w, s0, s1, s2, dest)                                \
    do {                                                                                      \
        T xx_ = (x) * (x), yy_ = (y) * (y), zz_ = (z) * (z);                                  \
        T xy_ = (x) * (y), xz_ = (x) * (z), yz_ = (y) * (z);                                  \
        T wx_ = (w) * (x), wy_ = (w) * (y), wz_ = (w) * (z);                                  \
        (dest)[0] = (1.0 - 2.0 * (yy_ + zz_)) * (s0);                                         \
        (dest)[1] = 2.0 * (xy_ + wz_) * (s0);                                                 \
        (dest)[2] = 2.0 * (xz_ - wy_) * (s0);                                                 \
        (dest)[3] = 2.0 * (xy_ - wz_) * (s1);                                                 \
        (dest)[4] = (1.0 - 2.0 * (xx_ + zz_)) * (s1);                                         \
        (dest)[5] = 2.0 * (yz_ + wx_) * (s1);                                                 \
        (dest)[6] = 2.0 * (xz_ + wy_) * (s2);                                                 \
        (dest)[7] = 2.0 * (yz_ - wx_) * (s2);                                                 \
        (dest)[8] = (1.0 - 2.0 * (xx_ + yy_)) * (s2);                                         \
    } while (0)
/* Column-major rotation matrix of unit q. */
inline void ob_dquat_to_mat3(const double q[4], double dest[9])
{
    /* Times 1.0: exact, so the unscaled matrix. */
    OB_QUAT_TO_MAT3_SCALED(double, q[0], q[1], q[2], q[3], 1.0, 1.0, 1.0, dest);
}
/* Unit quaternion of an orthonormal, right-handed column-major matrix. */
void ob_dmat3_to_dquat(const double m[9], double dest[4]);

/* --------------------------------------------------- double affine (3x4) */

/* x' = m * x + t, m column-major. The world transform of a scene node. */
typedef struct ob_daffine {
    double m[9];
    double t[3];
} ob_daffine;

void ob_daffine_identity(ob_daffine *dest);
/* T * R * S; q must be unit. */
inline void ob_daffine_from_trs(const double t[3], const double q[4], const double s[3],
                                ob_daffine *dest)
{
    OB_QUAT_TO_MAT3_SCALED(double, q[0], q[1], q[2], q[3], s[0], s[1], s[2], dest->m);
    dest->t[0] = t[0];
    dest->t[1] = t[1];
    dest->t[2] = t[2];
}
/* dest = a * b (b applied first). dest may alias a or b. */
inline void ob_daffine_mul(const ob_daffine *a, const ob_daffine *b, ob_daffine *dest)
{
    ob_daffine r;
    for (int c = 0; c < 3; c++) {
        for (int k = 0; k < 3; k++) {
            r.m[c * 3 + k] = a->m[k] * b->m[c * 3] + a->m[3 + k] * b->m[c * 3 + 1] +
                             a->m[6 + k] * b->m[c * 3 + 2];
        }
    }
    for (int k = 0; k < 3; k++)
        r.t[k] = a->m[k] * b->t[0] + a->m[3 + k] * b->t[1] + a->m[6 + k] * b->t[2] + a->t[k];
    *dest = r;
}
/* Row r of m * (x, y, z) + t for a column-major m, in any arithmetic type
 * (as OB_QUAT_TO_MAT3_SCALED). */
#define OB_AFFINE_ROW(m, t, r, x, y, z)                                                       \
    ((m)[r] * (x) + (m)[3 + (r)] * (y) + (m)[6 + (r)] * (z) + (t)[r])
/* dest may alias p. */
inline void ob_daffine_transform_point(const ob_daffine *a, const double p[3], double dest[3])
{
    double x = p[0], y = p[1], z = p[2];
    double r0 = OB_AFFINE_ROW(a->m, a->t, 0, x, y, z);
    double r1 = OB_AFFINE_ROW(a->m, a->t, 1, x, y, z);
    double r2 = OB_AFFINE_ROW(a->m, a->t, 2, x, y, z);
    dest[0] = r0;
    dest[1] = r1;
    dest[2] = r2;
}
inline bool ob_daffine_is_finite(const ob_daffine *a)
{
    /* Branch-free: x - x is 0 for a finite x and NaN for Inf or NaN, and a
     * sum with a NaN in it is NaN. */
    const double *m = a->m, *t = a->t;
    double z = ((m[0] - m[0]) + (m[1] - m[1])) + ((m[2] - m[2]) + (m[3] - m[3])) +
               ((m[4] - m[4]) + (m[5] - m[5])) + ((m[6] - m[6]) + (m[7] - m[7])) +
               ((m[8] - m[8]) + (t[0] - t[0])) + ((t[1] - t[1]) + (t[2] - t[2]));
    return z == z;
}
/* The squared length of column c of a column-major 3x3 m, in any
 * arithmetic type (as OB_QUAT_TO_MAT3_SCALED). */
#define OB_COLUMN_LENGTH2(m, c)                                                               \
    ((m)[(c) * 3] * (m)[(c) * 3] + (m)[(c) * 3 + 1] * (m)[(c) * 3 + 1] +                      \
     (m)[(c) * 3 + 2] * (m)[(c) * 3 + 2])
/* Largest column length of the linear part: the factor a bounding sphere's
 * radius grows by. */
inline double ob_daffine_max_scale(const ob_daffine *a)
{
    /* sqrt is correctly rounded, so monotonic: the root of the largest
     * squared length is the largest of the roots. A NaN length is passed
     * over (as fmax would). */
    double best = 0.0;
    for (int c = 0; c < 3; c++) {
        double d = OB_COLUMN_LENGTH2(a->m, c);
        best = d > best ? d : best;
    }
    return sqrt(best);
}
/* The float matrix the GPU sees for a world transform rendered relative to
 * `origin` (usually the camera's world position): the translation is
 * (a->t - origin) in double, then cast, so large coordinates lose nothing. */
void ob_daffine_to_relative(const ob_daffine *a, const double origin[3], float dest[16]);

/* --------------------------------------------------------- float matrices */

void ob_mat4_identity(float dest[16]);
/* dest = a * b. dest may alias a or b. */
void ob_mat4_mul(const float a[16], const float b[16], float dest[16]);
/* The normal matrix of world w (column-major): the cofactor matrix of its
 * upper 3x3 (columns c1×c2, c2×c0, c0×c1), i.e. det · inverse-transpose,
 * times the sign of det so that a mirroring w keeps normals outward:
 * correct for non-uniform scale, finite for zero scale, and the shader
 * normalizes anyway. It grows as scale²; outside 2^±60 the columns are first
 * scaled by a power of two (exact; only the direction matters), so it neither
 * overflows nor turns denormal for any finite w. Row and column 3 are those
 * of the identity. */
void ob_mat4_normal_cofactor(const float w[16], float dest[16]);
/* The determinant of the 3x3 of columns a, b, c (three entries each, of
 * any arithmetic type: the update evaluates it on two matrices in vector
 * lanes), in the one order ob_det3_negative uses. */
#define OB_DET3_COLUMNS(a, b, c)                                                                  \
    ((a)[0] * ((b)[1] * (c)[2] - (b)[2] * (c)[1]) + (a)[1] * ((b)[2] * (c)[0] - (b)[0] * (c)[2]) + \
     (a)[2] * ((b)[0] * (c)[1] - (b)[1] * (c)[0]))
/* Whether the 3x3 in w has a negative determinant, evaluated in double
 * from the floats (a product of three float columns neither underflows
 * nor overflows there): element (r, c) at w[c * col + r * row]. The
 * engine's one test of a mirroring world (the front face flips): a
 * column-major 3x3 is (w, 3, 1), the rows of a per-instance block
 * (w, 1, 4); the same matrix gives the same answer either way. */
static inline bool ob_det3_negative(const float *w, int col, int row)
{
    double a[3], b[3], c[3];
    for (int r = 0; r < 3; r++) {
        a[r] = w[r * row];
        b[r] = w[col + r * row];
        c[r] = w[2 * col + r * row];
    }
    return OB_DET3_COLUMNS(a, b, c) < 0.0;
}
/* The cofactor part of ob_mat3_normal_cofactor, without its checks and
 * rescaling: for an m the caller knows to be finite with its largest
 * magnitude in [2^-60, 2^60] (then the same result, bit for bit, and
 * finite). */
inline void ob_mat3_normal_cofactor_in_range(const float m[9], float dest[9])
{
    float c0 = m[0], c1 = m[1], c2 = m[2], c3 = m[3], c4 = m[4], c5 = m[5], c6 = m[6],
          c7 = m[7], c8 = m[8];
    /* Column i is column i+1 x column i+2. */
    dest[0] = c4 * c8 - c5 * c7;
    dest[1] = c5 * c6 - c3 * c8;
    dest[2] = c3 * c7 - c4 * c6;
    dest[3] = c7 * c2 - c8 * c1;
    dest[4] = c8 * c0 - c6 * c2;
    dest[5] = c6 * c1 - c7 * c0;
    dest[6] = c1 * c5 - c2 * c4;
    dest[7] = c2 * c3 - c0 * c5;
    dest[8] = c0 * c4 - c1 * c3;
    /* The cofactor is det * inverse-transpose: a mirroring matrix (negative
     * determinant) would turn normals inward. The sign of det (column 0
     * dotted with column 0 of the cofactor, in double so that it cannot
     * underflow) turns them back: the inverse-transpose's direction at any
     * scale. */
    if ((double)c0 * dest[0] + (double)c1 * dest[1] + (double)c2 * dest[2] < 0.0)
        for (int i = 0; i < 9; i++) dest[i] = -dest[i];
}
/* The same for a column-major 3x3 m (the upper 3x3 of w): dest is the
 * upper 3x3 of ob_mat4_normal_cofactor's result, bit for bit. dest must not
 * alias m. Returns whether every value of m is finite; then so is every
 * value of dest (the rescaling keeps the products in range). */
inline bool ob_mat3_normal_cofactor(const float m[9], float dest[9])
{
    float c0 = m[0], c1 = m[1], c2 = m[2], c3 = m[3], c4 = m[4], c5 = m[5], c6 = m[6],
          c7 = m[7], c8 = m[8];
    /* The largest magnitude (a NaN passed over), as a tree, not a chain. */
    bool nan = c0 != c0 || c1 != c1 || c2 != c2 || c3 != c3 || c4 != c4 || c5 != c5 ||
               c6 != c6 || c7 != c7 || c8 != c8;
    float largest = 0.0f;
    if (!nan) {
        float a0 = fabsf(c0), a1 = fabsf(c1), a2 = fabsf(c2), a3 = fabsf(c3), a4 = fabsf(c4);
        float a5 = fabsf(c5), a6 = fabsf(c6), a7 = fabsf(c7), a8 = fabsf(c8);
        float m01 = a0 > a1 ? a0 : a1, m23 = a2 > a3 ? a2 : a3, m45 = a4 > a5 ? a4 : a5;
        float m67 = a6 > a7 ? a6 : a7, m03 = m01 > m23 ? m01 : m23, m47 = m45 > m67 ? m45 : m67;
        float m07 = m03 > m47 ? m03 : m47;
        largest = m07 > a8 ? m07 : a8;
    } else {
        for (int i = 0; i < 9; i++) {
            float a = fabsf(m[i]);
            largest = a > largest ? a : largest;
        }
    }
    if (largest > 0x1p60f || (largest > 0.0f && largest < 0x1p-60f)) {
        int e;
        frexpf(largest, &e);
        c0 = ldexpf(c0, -e);
        c1 = ldexpf(c1, -e);
        c2 = ldexpf(c2, -e);
        c3 = ldexpf(c3, -e);
        c4 = ldexpf(c4, -e);
        c5 = ldexpf(c5, -e);
        c6 = ldexpf(c6, -e);
        c7 = ldexpf(c7, -e);
        c8 = ldexpf(c8, -e);
    }
    float scaled[9] = {c0, c1, c2, c3, c4, c5, c6, c7, c8};
    ob_mat3_normal_cofactor_in_range(scaled, dest);
    return !nan && largest <= 0x1.fffffep127f;
}

/* Infinite reversed-Z perspective for Vulkan clip space: a view-space point
 * at z = -znear gets depth 1, depth → 0 as -z → infinity, and +Y up in view
 * space is up in the image (y is flipped for Vulkan). fovy in radians.
 * Inputs are assumed valid (fovy in (0, pi), aspect > 0, znear > 0). */
void ob_math_perspective_reverse_z(float fovy, float aspect, float znear, float dest[16]);

/* Reversed-Z orthographic projection (shadow maps): view z = -znear → depth
 * 1, z = -zfar → depth 0, y flipped like the perspective one, so the same
 * depth compare works in every view. Requires left != right, bottom != top,
 * znear != zfar. */
void ob_math_ortho_reverse_z(float left, float right, float bottom, float top,
                             float znear, float zfar, float dest[16]);

/* ------------------------------------------------------- look and view */

typedef enum ob_look_status {
    OB_LOOK_OK = 0,
    OB_LOOK_UP_REPLACED = 1,   /* up was parallel to dir, zero or not finite */
    OB_LOOK_DIR_REPLACED = 2,  /* dir was zero or not finite: -Z was used */
} ob_look_status;

/* Orthonormal right-handed rotation (column-major, columns = local X, Y, Z in
 * the world) whose -Z looks along dir and whose +Y is as close to up as
 * possible. A degenerate basis falls back (dir → -Z; up → the world axis least
 * aligned with dir, preferring Z, then Y, then X) and says so, so the caller
 * can name the entity in a message: the result is OB_LOOK_OK or a bitwise OR
 * of the two flags. The rotation is always finite and orthonormal. */
ob_look_status ob_math_look_rotation(const double dir[3], const double up[3], double dest[9]);

/* View matrix of a camera with orthonormal world axes `axes` (columns X, Y, Z)
 * at world position eye, for rendering relative to `origin`. With origin ==
 * eye (camera-relative rendering) it is a pure rotation. */
void ob_math_view_relative(const double axes[9], const double eye[3], const double origin[3],
                           float dest[16]);

/* ---------------------------------------------------------------- frustum */

/* Planes (a, b, c, d) with unit inward normals: a point p is inside a plane
 * when a*p.x + b*p.y + c*p.z + d >= 0. Order: left, right, bottom, top,
 * near, then far when it is finite. */
typedef struct ob_frustum {
    float planes[6][4];
    uint32_t plane_count;
} ob_frustum;

/* Frustum of a (camera-relative) view-projection matrix in Vulkan clip space
 * with reversed depth (0 <= z <= w). The far plane of an infinite projection
 * has no normal and is left out (5 planes); an orthographic one has 6. */
void ob_frustum_from_matrix(const float view_proj[16], ob_frustum *dest);
/* False only when the sphere is entirely outside; straddling spheres count as
 * visible. Points are in the same (camera-relative) space as the matrix. */
bool ob_frustum_test_sphere(const ob_frustum *f, const float center[3], float radius);

/* The sRGB transfer function (IEC 61966-2-1) for one colour channel:
 * encoded (what a colour picker or an 8-bit sRGB image holds) to linear
 * light, and back. Scene files and authored palettes are sRGB; the engine
 * shades in linear light. [any thread] */
float ob_srgb_to_linear(float encoded);
float ob_linear_to_srgb(float linear);

#ifdef __cplusplus
}
#endif
#endif /* OB_MATH_H */
