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
 * Lifecycle: none (pure functions, no allocation).
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
/* dest = a * b (b applied first). dest may alias a or b. */
void ob_dquat_mul(const double a[4], const double b[4], double dest[4]);
/* Unit quaternion along q. Returns false (dest untouched) when q is zero or
 * not finite. dest may alias q. */
bool ob_dquat_normalize(const double q[4], double dest[4]);
/* q must be unit. dest may alias v. */
void ob_dquat_rotate(const double q[4], const double v[3], double dest[3]);
/* Column-major rotation matrix of unit q. */
void ob_dquat_to_mat3(const double q[4], double dest[9]);
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
void ob_daffine_from_trs(const double t[3], const double q[4], const double s[3], ob_daffine *dest);
/* dest = a * b (b applied first). dest may alias a or b. */
void ob_daffine_mul(const ob_daffine *a, const ob_daffine *b, ob_daffine *dest);
/* dest may alias p. */
void ob_daffine_transform_point(const ob_daffine *a, const double p[3], double dest[3]);
bool ob_daffine_is_finite(const ob_daffine *a);
/* Largest column length of the linear part: the factor a bounding sphere's
 * radius grows by. */
double ob_daffine_max_scale(const ob_daffine *a);
/* The float matrix the GPU sees for a world transform rendered relative to
 * `origin` (usually the camera's world position): the translation is
 * (a->t - origin) in double, then cast, so large coordinates lose nothing. */
void ob_daffine_to_relative(const ob_daffine *a, const double origin[3], float dest[16]);

/* --------------------------------------------------------- float matrices */

void ob_mat4_identity(float dest[16]);
/* dest = a * b. dest may alias a or b. */
void ob_mat4_mul(const float a[16], const float b[16], float dest[16]);
/* The normal matrix of world w (column-major): the cofactor matrix of its
 * upper 3x3 (columns c1×c2, c2×c0, c0×c1), i.e. det · inverse-transpose:
 * correct for non-uniform scale, finite for zero scale, and the shader
 * normalizes anyway. It grows as scale²; outside 2^±60 the columns are first
 * scaled by a power of two (exact; only the direction matters), so it neither
 * overflows nor turns denormal for any finite w. Row and column 3 are those
 * of the identity. */
void ob_mat4_normal_cofactor(const float w[16], float dest[16]);
/* The same for a column-major 3x3 m (the upper 3x3 of w): dest is the
 * upper 3x3 of ob_mat4_normal_cofactor's result, bit for bit. dest must not
 * alias m. */
void ob_mat3_normal_cofactor(const float m[9], float dest[9]);

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
