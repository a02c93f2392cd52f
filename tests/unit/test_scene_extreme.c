/* Extreme scenes: very deep hierarchies, far-away coordinates, very long
 * runs of incremental rotation, zero scale and very many nodes. Bounds are
 * stated next to each check. */
#include "ob_test.h"
#include "ob_scene.h"

#include <string.h>

#define assert_near(a, b, tol) assert_near_at((a), (b), (tol), #a, __FILE__, __LINE__)
static void assert_near_at(double a, double b, double tol, const char *expr, const char *file,
                           int line)
{
    if (fabs(a - b) <= tol) return;
    print_error("%s = %.17g, expected %.17g within %g\n", expr, a, b, tol);
    _fail(file, line);
}

static ob_scene *new_scene(void)
{
    ob_result r;
    ob_scene *s = ob_scene_create(&r);
    assert_non_null(s);
    return s;
}

static ob_node *new_node(ob_scene *s, ob_node *parent, const char *name)
{
    ob_result r;
    ob_node *n = ob_node_create(s, parent, name, &r);
    assert_non_null(n);
    return n;
}

/* Deterministic pseudo-random numbers in [-1, 1). */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*s >> 11) / (double)(1ull << 52) - 1.0;
}

static void assert_orthonormal_cols(const double m[9], double tol)
{
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            assert_near(ob_dvec3_dot(&m[a * 3], &m[b * 3]), a == b ? 1.0 : 0.0, tol);
}

/* ------------------------------------------------------------ deep chains */

/* Level k is translated by (1,0,0) and rotated by angle th about unit axis u
 * relative to level k-1, so p_k = sum_{j<k} R^j x with x = (1,0,0). With
 * x = x_par + x_perp about u: p_k = k x_par + C_k x_perp + S_k (u x x), where
 * C_k and S_k are the closed-form sums of cos(j th) and sin(j th). This does
 * not share a line of code with the engine's matrix products. */
static void chain_reference(const double u[3], double th, uint32_t k, double dest[3])
{
    const double x[3] = {1, 0, 0};
    double par[3], perp[3], ux[3];
    ob_dvec3_scale(u, ob_dvec3_dot(u, x), par);
    ob_dvec3_sub(x, par, perp);
    ob_dvec3_cross(u, x, ux);
    double h = sin(th / 2);
    double ck = sin(k * th / 2) * cos((k - 1.0) * th / 2) / h;
    double sk = sin(k * th / 2) * sin((k - 1.0) * th / 2) / h;
    for (int i = 0; i < 3; i++) dest[i] = k * par[i] + ck * perp[i] + sk * ux[i];
}

static void check_chain(uint32_t levels)
{
    ob_scene *s = new_scene();
    double axis[3] = {0.3, 0.5, 0.8};
    ob_dvec3_normalize(axis, axis);
    const double half = 0.0005; /* 0.001 rad per level */
    const float qf[4] = {(float)(axis[0] * sin(half)), (float)(axis[1] * sin(half)),
                         (float)(axis[2] * sin(half)), (float)cos(half)};
    ob_node **chain = ob_malloc(levels * sizeof *chain);
    assert_non_null(chain);
    ob_node *parent = NULL;
    for (uint32_t k = 0; k < levels; k++) {
        chain[k] = parent = new_node(s, parent, "link");
        ob_node_set_position(parent, (double[3]){1, 0, 0});
        ob_node_set_rotation(parent, qf);
    }
    /* The engine uses the float quaternion as given: take its exact axis and
     * angle for the reference. (Read back rather than widen qf here: GCC 12.2
     * at -O2 vectorizes the widening and skips the float rounding.) */
    double stored[4], u[3];
    ob_node_get_rotation(chain[0], stored);
    double th = 2.0 * atan2(ob_dvec3_length(stored), stored[3]);
    ob_dvec3_normalize(stored, u);
    ob_node_set_renderable(chain[levels - 1], &(ob_renderable){.local_radius = 1});
    assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);

    /* Bound: |p_k - ref_k| <= 1e-9 * k, i.e. relative to the length of the
     * chain walked so far (the error of k composed double products grows
     * like k^2 * 1e-16, far below this for k <= 1e5). */
    double worst = 0.0;
    for (uint32_t k = 1; k <= levels; k++) {
        if (k % 97 && k != levels && k > 50) continue;
        double p[3], ref[3], d[3];
        ob_node_world_position(chain[k - 1], p);
        chain_reference(u, th, k, ref);
        ob_dvec3_sub(p, ref, d);
        double err = ob_dvec3_length(d) / k;
        if (err > worst) worst = err;
        if (err > 1e-9) fail_msg("level %u: error %.3g per level", k, err);
    }
    print_message("%u levels: worst error %.3g per level\n", levels, worst);
    /* The last world rotation is a rotation by levels * th about u. */
    ob_daffine w;
    ob_node_world_affine(chain[levels - 1], &w);
    double q[4], r[9];
    ob_dquat_from_axis_angle(u, levels * th, q);
    ob_dquat_to_mat3(q, r);
    for (int i = 0; i < 9; i++) assert_near(w.m[i], r[i], 1e-9);
    uint32_t count;
    ob_scene_renderables(s, &count);
    assert_int_equal(count, 1);

    /* Edits on the deep chain stay iterative too: a cycle check walks all
     * the ancestors, destroy frees the whole chain. */
    assert_int_equal(ob_node_set_parent(s, chain[0], chain[levels - 1]), OB_ERR_INVALID_ARGUMENT);
    ob_node_destroy(s, chain[0]);
    assert_int_equal(ob_scene_node_count(s), 1);
    ob_scene_renderables(s, &count);
    assert_int_equal(count, 0);
    assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
    ob_free(chain);
    ob_scene_destroy(s);
}

static void chain_of_ten_thousand_levels(void **state)
{
    (void)state;
    check_chain(10000);
}

static void chain_of_hundred_thousand_levels(void **state)
{
    (void)state;
    check_chain(100000);
}

/* ------------------------------------------------------ large coordinates */

typedef struct small_scene {
    ob_scene *s;
    ob_node *cam;
    ob_node *items[4];
} small_scene;

static void build_small_scene(small_scene *sc, const double offset[3])
{
    sc->s = new_scene();
    ob_node *base = new_node(sc->s, NULL, "base");
    ob_node *arm = new_node(sc->s, base, "arm");
    ob_node *hand = new_node(sc->s, arm, "hand");
    ob_node *moon = new_node(sc->s, NULL, "moon");
    sc->cam = new_node(sc->s, NULL, "camera");
    double p[3];
    ob_dvec3_add(offset, (double[3]){1.37, -0.29, 2.11}, p);
    ob_node_set_position(base, p);
    ob_node_set_rotation(base, (float[4]){0.1f, 0.2f, 0.3f, 0.9f});
    ob_node_set_position(arm, (double[3]){0.31, 1.13, -0.77});
    ob_node_set_scale(arm, (float[3]){0.5f, 1.5f, 1.0f});
    ob_node_set_position(hand, (double[3]){0.05, 0.6, 0.1});
    ob_node_add_rotation_controller(hand, (float[3]){1, 1, 0}, 2.0f);
    double c[3];
    ob_dvec3_add(offset, (double[3]){-0.5, 0.25, 0.4}, c);
    ob_node_add_orbit_controller(moon, c, (float[3]){0, 1, 0.2f}, 3.3, 0.7f, 0.1f);
    ob_dvec3_add(offset, (double[3]){0.23, 1.71, 6.07}, p);
    ob_node_set_position(sc->cam, p);
    ob_node_set_camera(sc->cam, &(ob_camera_desc){0});
    ob_node *items[4] = {base, arm, hand, moon};
    for (int i = 0; i < 4; i++) {
        sc->items[i] = items[i];
        ob_node_set_renderable(items[i], &(ob_renderable){.local_center = {0.1f, 0, 0},
                                                           .local_radius = 0.5f});
    }
    ob_scene_update(sc->s, 0.0);
    double target[3];
    ob_node_world_position(base, target);
    assert_int_equal(ob_node_look_at(sc->cam, target, (double[3]){0, 1, 0}), OB_OK);
    for (int i = 0; i < 30; i++) ob_scene_update(sc->s, 1.0 / 60.0);
}

/* Largest |a - b| / max(1, |b|) over a matrix. */
static double matrix_rel_diff(const float a[16], const float b[16])
{
    double worst = 0;
    for (int i = 0; i < 16; i++)
        worst = fmax(worst, fabs((double)a[i] - b[i]) / fmax(1.0, fabs((double)b[i])));
    return worst;
}

static void far_scene_renders_like_origin(void **state)
{
    (void)state;
    const double offsets[][3] = {{1e7, 1e7, 1e7}, {-1e7, 3e6, -1e7}, {1e7, 0, 0}};
    small_scene ref;
    build_small_scene(&ref, (double[3]){0, 0, 0});
    double ref_eye[3];
    ob_node_world_position(ref.cam, ref_eye);
    for (size_t o = 0; o < OB_ARRAY_COUNT(offsets); o++) {
        small_scene far;
        build_small_scene(&far, offsets[o]);
        double eye[3];
        ob_node_world_position(far.cam, eye);
        /* Bound: every element within 1e-6 relative (max(1, |x|)), i.e. at
         * most a float ulp or so from the origin case: the double work at
         * 1e7 carries ~2e-9 absolute error before the cast. */
        float a[16], b[16], vp[16], proj[16];
        ob_node_view_relative(ref.cam, ref_eye, a);
        ob_node_view_relative(far.cam, eye, b);
        assert_true(matrix_rel_diff(b, a) <= 1e-6);
        ob_math_perspective_reverse_z(1.0f, 1.5f, 0.1f, proj);
        ob_mat4_mul(proj, b, vp);
        ob_frustum f;
        ob_frustum_from_matrix(vp, &f);
        double naive_worst = 0;
        for (int i = 0; i < 4; i++) {
            ob_node_world_relative(ref.items[i], ref_eye, a);
            ob_node_world_relative(far.items[i], eye, b);
            double d = matrix_rel_diff(b, a);
            if (d > 1e-6) fail_msg("offset %zu item %d: relative difference %.3g", o, i, d);
            /* Same culling answer, same bounds relative to the camera. */
            double c[3];
            float radius, rel[3];
            ob_node_world_sphere(far.items[i], c, &radius);
            for (int k = 0; k < 3; k++) rel[k] = (float)(c[k] - eye[k]);
            assert_true(ob_frustum_test_sphere(&f, rel, radius));
            /* What a float world matrix would have done: an error of a good
             * fraction of a unit — proof that the offset is large enough. */
            ob_daffine w;
            ob_node_world_affine(far.items[i], &w);
            for (int k = 0; k < 3; k++) {
                float naive = (float)w.t[k] - (float)eye[k];
                naive_worst = fmax(naive_worst, fabs(naive - (double)a[12 + k]));
            }
        }
        assert_true(naive_worst > 0.01);
        ob_scene_destroy(far.s);
    }
    ob_scene_destroy(ref.s);
}

/* ------------------------------------------------- long incremental runs */

static void rotation_stays_unit_after_ten_million_updates(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n = new_node(s, NULL, "turntable");
    ob_node *child = new_node(s, n, "on-top");
    ob_node_set_position(child, (double[3]){0, 1, 0});
    const float axis[3] = {0.2f, -0.7f, 0.4f};
    const float rate = 1.3f;
    assert_int_equal(ob_node_add_rotation_controller(n, axis, rate), OB_OK);
    const uint32_t updates = 10000000;
    const double dt = 1.0 / 60.0;
    for (uint32_t i = 0; i < updates; i++) {
        if (ob_scene_update(s, dt) != OB_OK) fail_msg("update %u failed", i);
    }
    /* Bounds: unit within 1e-6, world matrix orthonormal within 1e-6. */
    double q[4];
    ob_node_get_rotation(n, q);
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    print_message("after %u updates: |q| - 1 = %.3g\n", updates, len - 1.0);
    assert_near(len, 1.0, 1e-6);
    ob_daffine w;
    ob_node_world_affine(n, &w);
    assert_orthonormal_cols(w.m, 1e-6);
    float m[16];
    ob_node_world_relative(n, (double[3]){0, 0, 0}, m);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double d = 0;
            for (int k = 0; k < 3; k++) d += (double)m[a * 4 + k] * m[b * 4 + k];
            assert_near(d, a == b ? 1.0 : 0.0, 1e-6);
        }
    /* No angular drift either: the integrated rotation equals the analytic
     * one (same per-step angle) within 1e-6 per component. */
    double ax[3] = {axis[0], axis[1], axis[2]}, expect[4];
    ob_dquat_from_axis_angle(ax, (double)updates * (rate * dt), expect);
    double dot = 0;
    for (int k = 0; k < 4; k++) dot += q[k] * expect[k];
    double sign = dot < 0 ? -1.0 : 1.0;
    for (int k = 0; k < 4; k++) assert_near(q[k], sign * expect[k], 1e-6);
    /* The child rides along at distance 1. */
    double p[3];
    ob_node_world_position(child, p);
    assert_near(ob_dvec3_length(p), 1.0, 1e-9);
    ob_scene_destroy(s);
}

/* ------------------------------------------------------------- zero scale */

static void zero_scale_stays_finite(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *flat = new_node(s, NULL, "flat"), *squashed = new_node(s, NULL, "squashed");
    ob_node *rider = new_node(s, flat, "rider");
    ob_node_set_scale(flat, (float[3]){0, 0, 0});
    ob_node_set_rotation(flat, (float[4]){0, 0.70710678f, 0, 0.70710678f}); /* 90° about Y */
    ob_node_set_scale(squashed, (float[3]){0, 1, 1});
    ob_node_set_position(rider, (double[3]){3, 4, 5});
    ob_node *nodes[3] = {flat, squashed, rider};
    for (int i = 0; i < 3; i++)
        ob_node_set_renderable(nodes[i], &(ob_renderable){.local_radius = 2});
    ob_test_log_clear();
    assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 0);
    for (int i = 0; i < 3; i++) {
        assert_true(ob_node_is_renderable(nodes[i]));
        float m[16], v[16], r[3], u[3], f[3];
        ob_node_world_relative(nodes[i], (double[3]){1, 1, 1}, m);
        ob_node_view_relative(nodes[i], (double[3]){1, 1, 1}, v);
        ob_node_world_axes(nodes[i], r, u, f);
        for (int k = 0; k < 16; k++) assert_true(isfinite(m[k]) && isfinite(v[k]));
        double axes[9];
        for (int k = 0; k < 3; k++) {
            axes[k] = r[k];
            axes[3 + k] = u[k];
            axes[6 + k] = -f[k];
        }
        assert_orthonormal_cols(axes, 1e-6);
    }
    /* Under a zero-scaled parent everything collapses to the parent's origin,
     * but the directions still follow the rotations: forward is -X here. */
    double c[3];
    float radius, f[3];
    ob_node_world_sphere(rider, c, &radius);
    assert_near(radius, 0, 0);
    assert_near(ob_dvec3_length(c), 0, 0);
    ob_node_world_axes(rider, NULL, NULL, f);
    assert_near(f[0], -1, 1e-6);
    ob_node_world_sphere(squashed, c, &radius);
    assert_near(radius, 2, 1e-6);
    ob_scene_destroy(s);
}

/* -------------------------------------------------------- many nodes */

#define MANY 100000

typedef struct many_node {
    ob_node *node;
    int32_t parent;   /* index, -1 = root; always < own index */
    double t[3];
    float q[4];
} many_node;

/* World position by walking the ancestors with the quaternion rotate
 * (scale 1 everywhere): p = t_0 + R_0 (t_1 + R_1 (... t_k)). */
static void many_reference(const many_node *m, int32_t i, double dest[3])
{
    double p[3] = {0, 0, 0};
    for (int32_t k = i; k >= 0; k = m[k].parent) {
        double q[4] = {m[k].q[0], m[k].q[1], m[k].q[2], m[k].q[3]};
        ob_dquat_normalize(q, q);
        ob_dquat_rotate(q, p, p);
        ob_dvec3_add(p, m[k].t, p);
    }
    ob_dvec3_copy(p, dest);
}

static bool many_hidden(const many_node *m, const bool *hidden, int32_t i)
{
    for (int32_t k = i; k >= 0; k = m[k].parent)
        if (hidden[k]) return true;
    return false;
}

static void check_many(const many_node *m, uint64_t *seed)
{
    for (int i = 0; i < 300; i++) {
        int32_t k = (int32_t)((rnd(seed) + 1.0) * 0.5 * MANY) % MANY;
        double p[3], ref[3];
        ob_node_world_position(m[k].node, p);
        many_reference(m, k, ref);
        for (int c = 0; c < 3; c++) assert_near(p[c], ref[c], 1e-9 * fmax(1.0, fabs(ref[c])));
    }
}

static void hundred_thousand_nodes_update(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    many_node *m = ob_calloc(MANY, sizeof *m);
    bool *hidden = ob_calloc(MANY, sizeof *hidden);
    assert_non_null(m);
    assert_non_null(hidden);
    uint64_t seed = 42;
    for (int32_t i = 0; i < MANY; i++) {
        /* Mostly near the previous node, sometimes anywhere: deep and wide. */
        double r = rnd(&seed);
        m[i].parent = i == 0 ? -1 : r < -0.9 ? -1 : r < 0.2 ? i - 1 : (int32_t)((r + 1) * 0.5 * i) % i;
        for (int c = 0; c < 3; c++) m[i].t[c] = rnd(&seed) * 10;
        for (int c = 0; c < 4; c++) m[i].q[c] = (float)rnd(&seed);
        m[i].q[3] += 2.0f; /* keep it away from zero */
        m[i].node = new_node(s, m[i].parent < 0 ? NULL : m[m[i].parent].node, "many");
        ob_node_set_position(m[i].node, m[i].t);
        ob_node_set_rotation(m[i].node, m[i].q);
        ob_node_set_renderable(m[i].node, &(ob_renderable){.local_radius = 1});
    }
    assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_scene_node_count(s), MANY + 1);
    uint32_t count;
    ob_scene_renderables(s, &count);
    assert_int_equal(count, MANY);
    check_many(m, &seed);

    /* Reparent (parents stay at lower indices, so no cycles) and hide some. */
    for (int i = 0; i < 2000; i++) {
        int32_t k = 1 + (int32_t)((rnd(&seed) + 1.0) * 0.5 * (MANY - 1)) % (MANY - 1);
        int32_t p = (int32_t)((rnd(&seed) + 1.0) * 0.5 * k) % k;
        m[k].parent = p;
        assert_int_equal(ob_node_set_parent(s, m[k].node, m[p].node), OB_OK);
    }
    for (int i = 0; i < 50; i++) {
        int32_t k = (int32_t)((rnd(&seed) + 1.0) * 0.5 * MANY) % MANY;
        hidden[k] = true;
        ob_node_set_hidden(m[k].node, true);
    }
    assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
    check_many(m, &seed);
    uint32_t expect = 0;
    for (int32_t i = 0; i < MANY; i++) expect += !many_hidden(m, hidden, i);
    ob_node *const *items = ob_scene_renderables(s, &count);
    assert_int_equal(count, expect);
    for (uint32_t i = 1; i < count; i++) assert_true(ob_node_id(items[i - 1]) < ob_node_id(items[i]));
    ob_free(hidden);
    ob_free(m);
    ob_scene_destroy(s);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(chain_of_ten_thousand_levels),
        cmocka_unit_test(chain_of_hundred_thousand_levels),
        cmocka_unit_test(far_scene_renders_like_origin),
        cmocka_unit_test(rotation_stays_unit_after_ten_million_updates),
        cmocka_unit_test(zero_scale_stays_finite),
        cmocka_unit_test(hundred_thousand_nodes_update),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
