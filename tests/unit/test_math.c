/* Math that decides what ends up on screen: reversed-Z depth ordering,
 * projections, frustum culling, look rotations, camera-relative matrices. */
#include "ob_test.h"
#include "ob_math.h"

#include <string.h>


/* clip = M * v computed in float, as the GPU does. */
static void clip_of(const float m[16], const float v[3], float clip[4])
{
    for (int r = 0; r < 4; r++)
        clip[r] = m[r] * v[0] + m[4 + r] * v[1] + m[8 + r] * v[2] + m[12 + r];
}

static float depth_of(const float m[16], const float v[3])
{
    float c[4];
    clip_of(m, v, c);
    return c[2] / c[3];
}

static void perspective_maps_near_to_one_and_far_toward_zero(void **state)
{
    (void)state;
    float p[16];
    ob_math_perspective_reverse_z(1.0f, 1.5f, 0.1f, p);
    assert_true(depth_of(p, (float[3]){0, 0, -0.1f}) == 1.0f);
    float prev = 1.0f;
    const float dist[] = {0.2f, 1.0f, 10.0f, 1000.0f, 1e6f, 1e12f};
    for (size_t i = 0; i < OB_ARRAY_COUNT(dist); i++) {
        float d = depth_of(p, (float[3]){0.5f, -0.25f, -dist[i]});
        assert_true(d < prev);
        assert_true(d > 0.0f);
        prev = d;
    }
    assert_true(prev < 1e-12f);
    /* Behind the near plane: depth > 1 (clipped). */
    assert_true(depth_of(p, (float[3]){0, 0, -0.05f}) > 1.0f);
    /* World +Y up is up in the image: Vulkan's y = -1 is the top row. */
    float c[4];
    clip_of(p, (float[3]){0, 1, -2}, c);
    assert_true(c[1] / c[3] < 0.0f);
    clip_of(p, (float[3]){1, 0, -2}, c);
    assert_true(c[0] / c[3] > 0.0f);
    /* The frustum edge: y = tan(fovy/2) * distance lands at ndc -1. */
    clip_of(p, (float[3]){0, tanf(0.5f) * 3.0f, -3.0f}, c);
    assert_near(c[1] / c[3], -1.0f, 1e-6f);
}

static void reversed_z_keeps_far_points_ordered(void **state)
{
    (void)state;
    /* near 1e-3 and points out to 1e5 (a 1e8 range) 0.1% apart: every step
     * must give a strictly smaller float depth, so no z-fighting. */
    float p[16];
    ob_math_perspective_reverse_z(0.9f, 16.0f / 9.0f, 1e-3f, p);
    float prev = 2.0f;
    uint32_t steps = 0;
    for (double d = 1e-2; d <= 1.001e5; d *= 1.001, steps++) {
        float v[3] = {(float)(0.3 * d), (float)(-0.2 * d), (float)-d};
        float depth = depth_of(p, v);
        if (!(depth < prev)) fail_msg("depth not decreasing at distance %.9g (%.9g >= %.9g)", d,
                                      (double)depth, (double)prev);
        prev = depth;
    }
    assert_true(steps > 16000);
    /* The specified pair: 1e5 and 1e5 * 1.001. */
    float a = depth_of(p, (float[3]){0, 0, -1e5f});
    float b = depth_of(p, (float[3]){0, 0, -1.001e5f});
    assert_true(b < a);
    assert_true(b > 0.0f);
}

static void ortho_reverse_z_maps_box(void **state)
{
    (void)state;
    float o[16];
    ob_math_ortho_reverse_z(-10, 10, -5, 5, 1, 101, o);
    float c[4];
    assert_near(depth_of(o, (float[3]){3, 2, -1}), 1.0f, 1e-7f);
    assert_near(depth_of(o, (float[3]){3, 2, -101}), 0.0f, 1e-7f);
    assert_near(depth_of(o, (float[3]){0, 0, -51}), 0.5f, 1e-7f);
    clip_of(o, (float[3]){10, 5, -20}, c);
    assert_near(c[0], 1.0f, 1e-6f);
    assert_near(c[1], -1.0f, 1e-6f); /* +Y up → top row */
    assert_near(c[3], 1.0f, 0.0f);
    clip_of(o, (float[3]){-10, -5, -20}, c);
    assert_near(c[0], -1.0f, 1e-6f);
    assert_near(c[1], 1.0f, 1e-6f);
    /* Off-centre box */
    ob_math_ortho_reverse_z(0, 4, 2, 6, -3, 3, o);
    clip_of(o, (float[3]){2, 4, 0}, c);
    assert_near(c[0], 0.0f, 1e-6f);
    assert_near(c[1], 0.0f, 1e-6f);
    assert_near(c[2], 0.5f, 1e-6f);
}

static void assert_orthonormal(const double m[9], double tol)
{
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            double d = ob_dvec3_dot(&m[a * 3], &m[b * 3]);
            if (fabs(d - (a == b ? 1.0 : 0.0)) > tol)
                fail_msg("columns %d,%d dot %.17g", a, b, d);
        }
    }
    double c[3];
    ob_dvec3_cross(&m[0], &m[3], c);
    if (ob_dvec3_dot(c, &m[6]) < 1.0 - tol) fail_msg("not right-handed");
}

/* Deterministic pseudo-random numbers in [-1, 1). */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / (double)(1ull << 52) - 1.0;
}

static void look_rotation_is_orthonormal_and_aims(void **state)
{
    (void)state;
    uint64_t seed = 7;
    for (int i = 0; i < 2000; i++) {
        double dir[3] = {rnd(&seed), rnd(&seed), rnd(&seed)};
        double up[3] = {rnd(&seed), rnd(&seed), rnd(&seed)};
        double m[9], n[3], c[3];
        if (!ob_dvec3_normalize(dir, n)) continue;
        ob_dvec3_cross(n, up, c);
        if (ob_dvec3_length(c) < 1e-3) continue;
        assert_int_equal(ob_math_look_rotation(dir, up, m), OB_LOOK_OK);
        assert_orthonormal(m, 1e-12);
        for (int k = 0; k < 3; k++) assert_near(-m[6 + k], n[k], 1e-12); /* -Z = dir */
        assert_true(ob_dvec3_dot(&m[3], up) > 0.0);                          /* up side kept */
        assert_near(ob_dvec3_dot(&m[0], up), 0.0, 1e-12);           /* no roll */
    }
    /* The identity case. */
    double m[9];
    ob_math_look_rotation((double[3]){0, 0, -1}, (double[3]){0, 1, 0}, m);
    const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    for (int k = 0; k < 9; k++) assert_near(m[k], id[k], 1e-15);
}

static void degenerate_look_rotation_is_flagged_and_finite(void **state)
{
    (void)state;
    struct {
        double dir[3], up[3];
        unsigned expect;
    } cases[] = {
        {{0, -1, 0}, {0, 1, 0}, OB_LOOK_UP_REPLACED},          /* straight down */
        {{0, 5, 0}, {0, 2, 0}, OB_LOOK_UP_REPLACED},           /* straight up */
        {{1e-9, 1, 0}, {0, 1, 0}, OB_LOOK_UP_REPLACED},        /* nearly parallel */
        {{1, 2, 3}, {0, 0, 0}, OB_LOOK_UP_REPLACED},           /* zero up */
        {{1, 2, 3}, {NAN, 0, 1}, OB_LOOK_UP_REPLACED},         /* NaN up */
        {{0, 0, 0}, {0, 1, 0}, OB_LOOK_DIR_REPLACED},          /* zero dir */
        {{INFINITY, 0, 0}, {0, 0, 1}, OB_LOOK_DIR_REPLACED | OB_LOOK_UP_REPLACED},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        double m[9];
        unsigned st = ob_math_look_rotation(cases[i].dir, cases[i].up, m);
        assert_int_equal(st, cases[i].expect);
        for (int k = 0; k < 9; k++) assert_true(isfinite(m[k]));
        assert_orthonormal(m, 1e-12);
        double n[3];
        if (ob_dvec3_normalize(cases[i].dir, n))
            for (int k = 0; k < 3; k++) assert_near(-m[6 + k], n[k], 1e-12);
        else
            assert_near(m[8], 1.0, 1e-15); /* fell back to looking down -Z */
    }
}

static void quaternion_matrix_round_trip(void **state)
{
    (void)state;
    uint64_t seed = 11;
    for (int i = 0; i < 5000; i++) {
        double axis[3] = {rnd(&seed), rnd(&seed), rnd(&seed)};
        /* Include angles near pi, where naive matrix→quaternion loses precision. */
        double angle = i % 5 == 0 ? OB_PI - 1e-9 * (i % 7) : rnd(&seed) * 4.0;
        double q[4], m[9], back[4], v[3] = {rnd(&seed), rnd(&seed), rnd(&seed)}, a[3], b[3];
        ob_dquat_from_axis_angle(axis, angle, q);
        ob_dquat_to_mat3(q, m);
        assert_orthonormal(m, 1e-12);
        ob_dquat_rotate(q, v, a);
        for (int r = 0; r < 3; r++) b[r] = m[r] * v[0] + m[3 + r] * v[1] + m[6 + r] * v[2];
        for (int r = 0; r < 3; r++) assert_near(a[r], b[r], 1e-12);
        ob_dmat3_to_dquat(m, back);
        double dot = 0;
        for (int k = 0; k < 4; k++) dot += q[k] * back[k];
        assert_near(fabs(dot), 1.0, 1e-12); /* same rotation (q or -q) */
    }
}

static void relative_matrix_cancels_large_offsets(void **state)
{
    (void)state;
    double q[4];
    ob_dquat_from_axis_angle((double[3]){1, 1, 0}, 0.6, q);
    ob_daffine near_o, far_o;
    ob_daffine_from_trs((double[3]){1.25, -2.5, 3.125}, q, (double[3]){1, 2, 3}, &near_o);
    ob_daffine_from_trs((double[3]){1e7 + 1.25, -1e7 - 2.5, 1e7 + 3.125}, q, (double[3]){1, 2, 3},
                        &far_o);
    float a[16], b[16];
    ob_daffine_to_relative(&near_o, (double[3]){0.5, 0.25, 0}, a);
    ob_daffine_to_relative(&far_o, (double[3]){1e7 + 0.5, -1e7 + 0.25, 1e7}, b);
    /* Binary fractions: the double subtraction is exact, so the floats match bit for bit. */
    assert_memory_equal(a, b, sizeof a);
    assert_near(a[12], 0.75f, 0.0f);
    assert_near(a[13], -2.75f, 0.0f);
}

static void view_relative_puts_target_down_negative_z(void **state)
{
    (void)state;
    double eye[3] = {1e7 + 3, 2, -4}, target[3] = {1e7 - 2, 7, 5}, dir[3], axes[9];
    ob_dvec3_sub(target, eye, dir);
    assert_int_equal(ob_math_look_rotation(dir, (double[3]){0, 1, 0}, axes), OB_LOOK_OK);
    float v[16], c[4];
    ob_math_view_relative(axes, eye, eye, v);
    assert_near(v[12], 0.0f, 0.0f); /* camera-relative: a pure rotation */
    float rel[3] = {(float)(target[0] - eye[0]), (float)(target[1] - eye[1]),
                    (float)(target[2] - eye[2])};
    clip_of(v, rel, c);
    assert_near(c[0], 0.0f, 1e-5f);
    assert_near(c[1], 0.0f, 1e-5f);
    assert_near(c[2], -(float)ob_dvec3_length(dir), 1e-5f);
    /* Relative to another origin, the translation moves the eye there. */
    ob_math_view_relative(axes, eye, (double[3]){1e7, 0, 0}, v);
    float e[3] = {3, 2, -4};
    clip_of(v, e, c);
    for (int k = 0; k < 3; k++) assert_near(c[k], 0.0f, 1e-6f);
}

static void frustum_perspective_culls_spheres(void **state)
{
    (void)state;
    float p[16], v[16], vp[16];
    double axes[9];
    /* Camera looking along +X (rotated), vertical fov 90 degrees, aspect 1. */
    ob_math_look_rotation((double[3]){1, 0, 0}, (double[3]){0, 1, 0}, axes);
    ob_math_view_relative(axes, (double[3]){0, 0, 0}, (double[3]){0, 0, 0}, v);
    ob_math_perspective_reverse_z((float)(OB_PI / 2), 1.0f, 0.5f, p);
    ob_mat4_mul(p, v, vp);
    ob_frustum f;
    ob_frustum_from_matrix(vp, &f);
    assert_int_equal(f.plane_count, 5); /* the infinite far plane is left out */

    assert_true(ob_frustum_test_sphere(&f, (float[3]){10, 0, 0}, 1));          /* ahead */
    assert_true(ob_frustum_test_sphere(&f, (float[3]){1e9f, 1e8f, 0}, 1));     /* very far */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){-10, 0, 0}, 1));        /* behind */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){10, 0, 12}, 1));        /* right of 45° */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){10, 12, 0}, 1));        /* above */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){10, -12, 0}, 1));       /* below */
    assert_true(ob_frustum_test_sphere(&f, (float[3]){10, 0, 10.5f}, 1));      /* straddles */
    assert_true(ob_frustum_test_sphere(&f, (float[3]){0.2f, 0, 0}, 0.5f));     /* straddles near */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){0.2f, 0, 0}, 0.1f));    /* before near */
    /* Plane distances are true distances (unit normals): 1.01 units off the
     * side plane is out with r = 1, in with r = 1.02. */
    float c[3] = {10, 0, 10 + 1.01f * (float)sqrt(2.0)};
    assert_false(ob_frustum_test_sphere(&f, c, 1.0f));
    assert_true(ob_frustum_test_sphere(&f, c, 1.02f));
}

static void frustum_ortho_has_six_planes(void **state)
{
    (void)state;
    float o[16];
    ob_math_ortho_reverse_z(-10, 10, -5, 5, 1, 100, o);
    ob_frustum f;
    ob_frustum_from_matrix(o, &f);
    assert_int_equal(f.plane_count, 6);
    assert_true(ob_frustum_test_sphere(&f, (float[3]){0, 0, -50}, 1));
    assert_true(ob_frustum_test_sphere(&f, (float[3]){9.5f, 4.5f, -99.5f}, 0.1f));
    assert_false(ob_frustum_test_sphere(&f, (float[3]){0, 0, -102}, 1));   /* beyond far */
    assert_true(ob_frustum_test_sphere(&f, (float[3]){0, 0, -100.5f}, 1)); /* straddles far */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){0, 0, 0.5f}, 0.4f)); /* before near */
    assert_false(ob_frustum_test_sphere(&f, (float[3]){12, 0, -50}, 1.5f));
    assert_true(ob_frustum_test_sphere(&f, (float[3]){12, 0, -50}, 2.5f));
    assert_false(ob_frustum_test_sphere(&f, (float[3]){0, -7, -50}, 1));
}

static void normalize_refuses_zero_and_non_finite(void **state)
{
    (void)state;
    double d[3] = {9, 9, 9};
    assert_false(ob_dvec3_normalize((double[3]){0, 0, 0}, d));
    assert_false(ob_dvec3_normalize((double[3]){NAN, 0, 0}, d));
    assert_near(d[0], 9.0, 0.0); /* untouched */
    assert_true(ob_dvec3_normalize((double[3]){1e-300, 0, 1e-300}, d));
    assert_near(d[0], sqrt(0.5), 1e-15);
    assert_true(ob_dvec3_normalize((double[3]){1e300, 1e300, 0}, d));
    assert_near(d[1], sqrt(0.5), 1e-15);
    double q[4];
    assert_false(ob_dquat_normalize((double[4]){0, 0, 0, 0}, q));
    assert_true(ob_dquat_normalize((double[4]){0, 0, 0, -3}, q));
    assert_near(q[3], -1.0, 0.0);
}

/* The normal matrix as first written (columns c1 x c2, c2 x c0, c0 x c1 of
 * the float world, rescaled by a power of two outside 2^+-60, negated when
 * the determinant is negative): the inline
 * one the scene update uses must give the same bits for every input. */
static void reference_normal_cofactor(const float w[16], float dest[16])
{
    float c[3][3], largest = 0.0f;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            c[i][k] = w[i * 4 + k];
            float a = c[i][k] < 0.0f ? -c[i][k] : c[i][k];
            largest = a > largest ? a : largest;
        }
    if (largest > 0x1p60f || (largest > 0.0f && largest < 0x1p-60f)) {
        int exponent;
        frexpf(largest, &exponent);
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++) c[i][k] = ldexpf(c[i][k], -exponent);
    }
    for (int i = 0; i < 3; i++) {
        const float *a = c[(i + 1) % 3], *b = c[(i + 2) % 3];
        dest[i * 4 + 0] = a[1] * b[2] - a[2] * b[1];
        dest[i * 4 + 1] = a[2] * b[0] - a[0] * b[2];
        dest[i * 4 + 2] = a[0] * b[1] - a[1] * b[0];
        dest[i * 4 + 3] = 0.0f;
    }
    /* Times the sign of the determinant: a mirroring world keeps its
     * normals outward (issue 25.7). */
    double det = (double)c[0][0] * dest[0] + (double)c[0][1] * dest[1] + (double)c[0][2] * dest[2];
    if (det < 0.0)
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++) dest[i * 4 + k] = -dest[i * 4 + k];
    dest[12] = dest[13] = dest[14] = 0.0f;
    dest[15] = 1.0f;
}

/* The same bits, or both NaN (a NaN's sign and payload depend on which
 * operand the compiler put first, which C leaves open). */
static void assert_same_floats(const float *a, const float *b, int count)
{
    for (int i = 0; i < count; i++) {
        if (isnan(a[i]) && isnan(b[i])) continue;
        assert_memory_equal(&a[i], &b[i], sizeof(float));
    }
}

static void fast_affine_math_matches_plain_formulas(void **state)
{
    (void)state;
    static const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, 0x1p61f, -0x1p-61f, 0x1p-140f,
                                     3e38f, INFINITY, -INFINITY, NAN};
    uint64_t seed = 99;
    for (int trial = 0; trial < 20000; trial++) {
        float w[16] = {0}, m[9], want[16], got4[16], got3[9];
        bool finite = true;
        /* A magnitude per matrix (so the rescaled ranges are hit), a special
         * value now and then. */
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        int exponent = (int)(seed >> 58) * 5 - 80;
        for (int i = 0; i < 9; i++) {
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            float v = ldexpf((float)((int64_t)(seed >> 40) - (1 << 23)) / (1 << 23), exponent);
            if ((seed & 63) == 0) v = specials[(seed >> 6) % (sizeof specials / sizeof *specials)];
            w[(i / 3) * 4 + i % 3] = m[i] = v;
            finite &= isfinite(v) != 0;
        }
        w[15] = 1.0f;
        reference_normal_cofactor(w, want);
        ob_mat4_normal_cofactor(w, got4);
        assert_same_floats(got4, want, 16);
        assert_int_equal(ob_mat3_normal_cofactor(m, got3), finite);
        for (int i = 0; i < 9; i++) assert_same_floats(&got3[i], &want[(i / 3) * 4 + i % 3], 1);

        ob_daffine a;
        for (int i = 0; i < 9; i++) a.m[i] = (double)m[i] * 1e10;
        for (int i = 0; i < 3; i++) a.t[i] = (double)m[i * 3] * -3.0;
        bool all = true;
        double best = 0.0;
        for (int i = 0; i < 9; i++) all &= isfinite(a.m[i]) != 0;
        for (int i = 0; i < 3; i++) all &= isfinite(a.t[i]) != 0;
        for (int c = 0; c < 3; c++) best = fmax(best, ob_dvec3_length(&a.m[c * 3]));
        assert_int_equal(ob_daffine_is_finite(&a), all);
        double got_scale = ob_daffine_max_scale(&a);
        assert_memory_equal(&got_scale, &best, sizeof best);
    }
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(perspective_maps_near_to_one_and_far_toward_zero),
        cmocka_unit_test(reversed_z_keeps_far_points_ordered),
        cmocka_unit_test(ortho_reverse_z_maps_box),
        cmocka_unit_test(look_rotation_is_orthonormal_and_aims),
        cmocka_unit_test(degenerate_look_rotation_is_flagged_and_finite),
        cmocka_unit_test(quaternion_matrix_round_trip),
        cmocka_unit_test(relative_matrix_cancels_large_offsets),
        cmocka_unit_test(view_relative_puts_target_down_negative_z),
        cmocka_unit_test(frustum_perspective_culls_spheres),
        cmocka_unit_test(frustum_ortho_has_six_planes),
        cmocka_unit_test(normalize_refuses_zero_and_non_finite),
        cmocka_unit_test(fast_affine_math_matches_plain_formulas),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
