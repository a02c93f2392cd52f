/* ob_math.c — see ob_math.h. Everything is computed in double and cast to
 * float only at the end, where the GPU needs it. */
#include "ob_math.h"

#include <string.h>

/* The external definitions of the inline functions of ob_math.h. */
extern inline void ob_dquat_mul(const double a[4], const double b[4], double dest[4]);
extern inline bool ob_dquat_normalize(const double q[4], double dest[4]);
extern inline void ob_dquat_to_mat3(const double q[4], double dest[9]);
extern inline void ob_daffine_from_trs(const double t[3], const double q[4], const double s[3],
                                       ob_daffine *dest);
extern inline void ob_daffine_mul(const ob_daffine *a, const ob_daffine *b, ob_daffine *dest);
extern inline void ob_daffine_transform_point(const ob_daffine *a, const double p[3],
                                              double dest[3]);
extern inline bool ob_daffine_is_finite(const ob_daffine *a);
extern inline double ob_daffine_max_scale(const ob_daffine *a);
extern inline void ob_mat3_normal_cofactor_in_range(const float m[9], float dest[9]);
extern inline bool ob_mat3_normal_cofactor(const float m[9], float dest[9]);

bool ob_dvec3_normalize(const double a[3], double dest[3])
{
    if (!ob_dvec3_is_finite(a)) return false;
    /* Scale first so tiny or huge (but finite) vectors do not under/overflow
     * in the squared length. */
    double big = fmax(fabs(a[0]), fmax(fabs(a[1]), fabs(a[2])));
    if (big == 0.0) return false;
    double s[3] = {a[0] / big, a[1] / big, a[2] / big};
    double len = ob_dvec3_length(s);
    ob_dvec3_scale(s, 1.0 / len, dest);
    return true;
}

/* ------------------------------------------------------------- quaternion */

void ob_dquat_identity(double dest[4])
{
    dest[0] = dest[1] = dest[2] = 0.0;
    dest[3] = 1.0;
}

void ob_dquat_from_axis_angle(const double axis[3], double angle, double dest[4])
{
    double n[3];
    if (!ob_dvec3_normalize(axis, n)) {
        ob_dquat_identity(dest);
        return;
    }
    double s = sin(angle * 0.5);
    dest[0] = n[0] * s;
    dest[1] = n[1] * s;
    dest[2] = n[2] * s;
    dest[3] = cos(angle * 0.5);
}

void ob_dquat_rotate(const double q[4], const double v[3], double dest[3])
{
    /* v' = v + w t + q.xyz x t, with t = 2 q.xyz x v: fewer roundings than
     * building the matrix. */
    double t[3], c[3];
    ob_dvec3_cross(q, v, t);
    ob_dvec3_scale(t, 2.0, t);
    ob_dvec3_cross(q, t, c);
    double x = v[0] + q[3] * t[0] + c[0];
    double y = v[1] + q[3] * t[1] + c[1];
    double z = v[2] + q[3] * t[2] + c[2];
    dest[0] = x;
    dest[1] = y;
    dest[2] = z;
}

void ob_dmat3_to_dquat(const double m[9], double dest[4])
{
    /* Shepperd's method: pick the largest of w, x, y, z to divide by, so the
     * result stays accurate for every rotation angle. */
#define M(r, c) m[(c) * 3 + (r)]
    double q[4];
    double trace = M(0, 0) + M(1, 1) + M(2, 2);
    if (trace > 0.0) {
        double s = sqrt(trace + 1.0) * 2.0;
        q[3] = 0.25 * s;
        q[0] = (M(2, 1) - M(1, 2)) / s;
        q[1] = (M(0, 2) - M(2, 0)) / s;
        q[2] = (M(1, 0) - M(0, 1)) / s;
    } else if (M(0, 0) > M(1, 1) && M(0, 0) > M(2, 2)) {
        double s = sqrt(1.0 + M(0, 0) - M(1, 1) - M(2, 2)) * 2.0;
        q[3] = (M(2, 1) - M(1, 2)) / s;
        q[0] = 0.25 * s;
        q[1] = (M(0, 1) + M(1, 0)) / s;
        q[2] = (M(0, 2) + M(2, 0)) / s;
    } else if (M(1, 1) > M(2, 2)) {
        double s = sqrt(1.0 + M(1, 1) - M(0, 0) - M(2, 2)) * 2.0;
        q[3] = (M(0, 2) - M(2, 0)) / s;
        q[0] = (M(0, 1) + M(1, 0)) / s;
        q[1] = 0.25 * s;
        q[2] = (M(1, 2) + M(2, 1)) / s;
    } else {
        double s = sqrt(1.0 + M(2, 2) - M(0, 0) - M(1, 1)) * 2.0;
        q[3] = (M(1, 0) - M(0, 1)) / s;
        q[0] = (M(0, 2) + M(2, 0)) / s;
        q[1] = (M(1, 2) + M(2, 1)) / s;
        q[2] = 0.25 * s;
    }
#undef M
    if (!ob_dquat_normalize(q, dest)) ob_dquat_identity(dest);
}

/* ----------------------------------------------------------------- affine */

void ob_daffine_identity(ob_daffine *dest)
{
    memset(dest, 0, sizeof *dest);
    dest->m[0] = dest->m[4] = dest->m[8] = 1.0;
}

void ob_daffine_to_relative(const ob_daffine *a, const double origin[3], float dest[16])
{
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) dest[c * 4 + r] = (float)a->m[c * 3 + r];
        dest[c * 4 + 3] = 0.0f;
    }
    for (int r = 0; r < 3; r++) dest[12 + r] = (float)(a->t[r] - origin[r]);
    dest[15] = 1.0f;
}

/* --------------------------------------------------------- float matrices */

void ob_mat4_identity(float dest[16])
{
    memset(dest, 0, 16 * sizeof(float));
    dest[0] = dest[5] = dest[10] = dest[15] = 1.0f;
}

void ob_mat4_mul(const float a[16], const float b[16], float dest[16])
{
    float r[16];
    for (int c = 0; c < 4; c++)
        for (int k = 0; k < 4; k++)
            r[c * 4 + k] = a[k] * b[c * 4] + a[4 + k] * b[c * 4 + 1] + a[8 + k] * b[c * 4 + 2] +
                           a[12 + k] * b[c * 4 + 3];
    memcpy(dest, r, sizeof r);
}

void ob_mat4_normal_cofactor(const float w[16], float dest[16])
{
    float m[9], n[9];
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) m[c * 3 + r] = w[c * 4 + r];
    ob_mat3_normal_cofactor(m, n);
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) dest[c * 4 + r] = n[c * 3 + r];
        dest[c * 4 + 3] = 0.0f;
    }
    dest[12] = dest[13] = dest[14] = 0.0f;
    dest[15] = 1.0f;
}

void ob_math_perspective_reverse_z(float fovy, float aspect, float znear, float dest[16])
{
    /* clip.z = znear and clip.w = -z, so depth = znear / -z: exactly 1 on the
     * near plane and tending to 0 at infinity. Float keeps its relative
     * precision near 0, which is where distant geometry lands — the reason
     * reversed Z keeps far depths ordered. */
    double f = 1.0 / tan((double)fovy * 0.5);
    memset(dest, 0, 16 * sizeof(float));
    dest[0] = (float)(f / (double)aspect);
    dest[5] = (float)-f; /* Vulkan's framebuffer y points down */
    dest[11] = -1.0f;
    dest[14] = znear;
}

void ob_math_ortho_reverse_z(float left, float right, float bottom, float top,
                             float znear, float zfar, float dest[16])
{
    double l = left, r = right, b = bottom, t = top, n = znear, f = zfar;
    memset(dest, 0, 16 * sizeof(float));
    dest[0] = (float)(2.0 / (r - l));
    dest[5] = (float)(-2.0 / (t - b));
    dest[10] = (float)(1.0 / (f - n));
    dest[12] = (float)(-(r + l) / (r - l));
    dest[13] = (float)((t + b) / (t - b));
    dest[14] = (float)(f / (f - n));
    dest[15] = 1.0f;
}

/* ---------------------------------------------------------- look and view */

/* Below this sine of the angle between dir and up the basis is too ill
 * conditioned to trust (the camera would spin with rounding noise). */
#define OB_LOOK_MIN_SINE 1e-6

ob_look_status ob_math_look_rotation(const double dir[3], const double up[3], double dest[9])
{
    unsigned status = OB_LOOK_OK;
    double d[3], u[3], c[3];
    if (!ob_dvec3_normalize(dir, d)) {
        ob_dvec3_set(0.0, 0.0, -1.0, d);
        status |= OB_LOOK_DIR_REPLACED;
    }
    bool up_ok = ob_dvec3_normalize(up, u);
    if (up_ok) {
        ob_dvec3_cross(d, u, c);
        up_ok = ob_dvec3_length(c) >= OB_LOOK_MIN_SINE;
    }
    if (!up_ok) {
        int axis = 2;
        if (fabs(d[1]) < fabs(d[axis])) axis = 1;
        if (fabs(d[0]) < fabs(d[axis])) axis = 0;
        ob_dvec3_set(0.0, 0.0, 0.0, u);
        u[axis] = 1.0;
        status |= OB_LOOK_UP_REPLACED;
    }
    double back[3] = {-d[0], -d[1], -d[2]}, right[3], true_up[3];
    ob_dvec3_cross(u, back, right);
    /* The fallback guarantees a sine of at least ~0.8, so this cannot fail. */
    ob_dvec3_normalize(right, right);
    ob_dvec3_cross(back, right, true_up);
    ob_dvec3_copy(right, &dest[0]);
    ob_dvec3_copy(true_up, &dest[3]);
    ob_dvec3_copy(back, &dest[6]);
    return (ob_look_status)status;
}

void ob_math_view_relative(const double axes[9], const double eye[3], const double origin[3],
                           float dest[16])
{
    double rel[3];
    ob_dvec3_sub(eye, origin, rel);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) dest[c * 4 + r] = (float)axes[r * 3 + c];
        dest[12 + r] = (float)-ob_dvec3_dot(&axes[r * 3], rel);
        dest[r * 4 + 3] = 0.0f;
    }
    dest[15] = 1.0f;
}

/* ---------------------------------------------------------------- frustum */

static void frustum_add_plane(ob_frustum *f, const double p[4])
{
    double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    /* A plane with no normal is the far plane of an infinite projection
     * (clip z is constant there): it bounds nothing, so it is left out. */
    if (!(len > 1e-12 * fabs(p[3])) || !isfinite(len)) return;
    float *dst = f->planes[f->plane_count++];
    for (int i = 0; i < 4; i++) dst[i] = (float)(p[i] / len);
}

void ob_frustum_from_matrix(const float view_proj[16], ob_frustum *dest)
{
    /* Gribb & Hartmann: each clip-space inequality is a plane made of matrix
     * rows. Vulkan with reversed depth: -w <= x, y <= w and 0 <= z <= w. */
    double row[4][4];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) row[r][c] = view_proj[c * 4 + r];
    memset(dest, 0, sizeof *dest);
    double p[4];
    for (int axis = 0; axis < 2; axis++) {
        for (int sign = 1; sign >= -1; sign -= 2) {
            for (int c = 0; c < 4; c++) p[c] = row[3][c] + sign * row[axis][c];
            frustum_add_plane(dest, p);
        }
    }
    for (int c = 0; c < 4; c++) p[c] = row[3][c] - row[2][c]; /* z <= w: near */
    frustum_add_plane(dest, p);
    for (int c = 0; c < 4; c++) p[c] = row[2][c]; /* z >= 0: far */
    frustum_add_plane(dest, p);
}

bool ob_frustum_test_sphere(const ob_frustum *f, const float center[3], float radius)
{
    for (uint32_t i = 0; i < f->plane_count; i++) {
        const float *p = f->planes[i];
        float dist = p[0] * center[0] + p[1] * center[1] + p[2] * center[2] + p[3];
        if (dist < -radius) return false;
    }
    return true;
}

float ob_srgb_to_linear(float encoded)
{
    return encoded <= 0.04045f ? encoded / 12.92f : powf((encoded + 0.055f) / 1.055f, 2.4f);
}

float ob_linear_to_srgb(float linear)
{
    return linear <= 0.0031308f ? linear * 12.92f : 1.055f * powf(linear, 1.0f / 2.4f) - 0.055f;
}
