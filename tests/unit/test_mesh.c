/* CPU meshes: the generators' shapes (counts, closed surfaces, outward
 * faces and normals, uv, bounds), parameter checks, validation messages and
 * normal generation. No device. */
#include "ob_test.h"
#include "ob_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------- helpers */

static void sub3(const float *a, const float *b, double *out)
{
    for (int k = 0; k < 3; k++) out[k] = (double)a[k] - (double)b[k];
}

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Counter-clockwise geometric normal (unnormalized) and centroid of triangle t. */
static void triangle_frame(const ob_mesh *m, uint32_t t, double *out_normal, double *out_centroid)
{
    const float *a = m->vertices[m->indices[3 * t]].position;
    const float *b = m->vertices[m->indices[3 * t + 1]].position;
    const float *c = m->vertices[m->indices[3 * t + 2]].position;
    double e1[3], e2[3];
    sub3(b, a, e1);
    sub3(c, a, e2);
    cross3(e1, e2, out_normal);
    for (int k = 0; k < 3; k++) out_centroid[k] = ((double)a[k] + b[k] + c[k]) / 3.0;
}

/* Counts, index range and the validator agree with what the header promises. */
static void check_counts(const ob_mesh *m, uint32_t vertices, uint32_t indices)
{
    assert_int_equal(m->vertex_count, vertices);
    assert_int_equal(m->index_count, indices);
    assert_int_equal(m->index_count % 3, 0);
    for (uint32_t i = 0; i < m->index_count; i++) assert_true(m->indices[i] < m->vertex_count);
    assert_int_equal(ob_mesh_validate(m, "generated"), OB_OK);
}

static void check_unit_normals_and_uv(const ob_mesh *m, float uv_max)
{
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        const float *n = m->vertices[v].normal;
        double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (fabs(len - 1.0) > 1e-5) fail_msg("vertex %u normal length %.9f", v, len);
        for (int k = 0; k < 2; k++) {
            float t = m->vertices[v].uv[k];
            if (!(t >= 0.0f && t <= uv_max)) fail_msg("vertex %u uv[%d] = %g outside [0,%g]", v, k, (double)t, (double)uv_max);
        }
    }
}

/* Weld positions (tolerance, O(n²): test meshes are small) into ids. */
static uint32_t *weld(const ob_mesh *m, uint32_t *out_unique)
{
    uint32_t *id = malloc(m->vertex_count * sizeof *id);
    uint32_t *rep = malloc(m->vertex_count * sizeof *rep);
    uint32_t n = 0;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        id[v] = UINT32_MAX;
        for (uint32_t u = 0; u < n && id[v] == UINT32_MAX; u++) {
            double d[3];
            sub3(m->vertices[v].position, m->vertices[rep[u]].position, d);
            if (dot3(d, d) < 1e-12) id[v] = u;
        }
        if (id[v] == UINT32_MAX) {
            rep[n] = v;
            id[v] = n++;
        }
    }
    free(rep);
    *out_unique = n;
    return id;
}

typedef struct edge { uint32_t a, b; } edge;

static int edge_cmp(const void *x, const void *y)
{
    const edge *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return 0;
}

/* Closed and consistently oriented: after welding, every directed edge
 * appears exactly once and its reverse exactly once, so every undirected
 * edge is shared by exactly two triangles that wind the same way. */
static void check_closed(const ob_mesh *m)
{
    uint32_t unique;
    uint32_t *id = weld(m, &unique);
    uint32_t tris = m->index_count / 3;
    edge *e = malloc(3 * tris * sizeof *e);
    for (uint32_t t = 0; t < tris; t++) {
        for (int k = 0; k < 3; k++) {
            e[3 * t + k].a = id[m->indices[3 * t + k]];
            e[3 * t + k].b = id[m->indices[3 * t + (k + 1) % 3]];
            if (e[3 * t + k].a == e[3 * t + k].b) fail_msg("triangle %u is degenerate after welding", t);
        }
    }
    qsort(e, 3 * tris, sizeof *e, edge_cmp);
    for (uint32_t i = 0; i < 3 * tris; i++) {
        if (i + 1 < 3 * tris && edge_cmp(&e[i], &e[i + 1]) == 0)
            fail_msg("directed edge %u->%u used twice (inconsistent winding)", e[i].a, e[i].b);
        edge rev = {e[i].b, e[i].a};
        if (!bsearch(&rev, e, 3 * tris, sizeof *e, edge_cmp))
            fail_msg("edge %u->%u has no neighbour (open surface)", e[i].a, e[i].b);
    }
    free(e);
    free(id);
}

/* Every triangle faces away from `centre` and agrees with its vertex normals. */
static void check_outward(const ob_mesh *m, const double *centre)
{
    for (uint32_t t = 0; t < m->index_count / 3; t++) {
        double n[3], c[3], out[3];
        triangle_frame(m, t, n, c);
        for (int k = 0; k < 3; k++) out[k] = c[k] - centre[k];
        if (sqrt(dot3(n, n)) <= 0.0) fail_msg("triangle %u has zero area", t);
        if (dot3(n, out) <= 0.0) fail_msg("triangle %u faces inwards", t);
        for (int k = 0; k < 3; k++) {
            const float *vn = m->vertices[m->indices[3 * t + k]].normal;
            double vd[3] = {vn[0], vn[1], vn[2]};
            if (dot3(vd, n) <= 0.0) fail_msg("triangle %u vertex %d normal disagrees with the face", t, k);
        }
    }
}

static void check_bounds(const ob_bounds *b, const float *min, const float *max, float radius, float eps)
{
    for (int k = 0; k < 3; k++) {
        assert_float_equal(b->min[k], min[k], eps);
        assert_float_equal(b->max[k], max[k], eps);
        assert_float_equal(b->center[k], 0.5f * (min[k] + max[k]), eps);
    }
    assert_float_equal(b->radius, radius, eps);
}

static const double origin[3] = {0, 0, 0};

/* ----------------------------------------------------------- generators */

static void box_is_closed_flat_and_exactly_bounded(void **state)
{
    (void)state;
    const float h[3] = {1.5f, 0.25f, 2.0f};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    check_counts(&m, 24, 36);
    check_unit_normals_and_uv(&m, 1.0f);
    check_closed(&m);
    check_outward(&m, origin);
    /* Flat faces: the four vertices of a face share its normal exactly. */
    for (uint32_t f = 0; f < 6; f++)
        for (uint32_t c = 1; c < 4; c++)
            assert_memory_equal(m.vertices[4 * f].normal, m.vertices[4 * f + c].normal, sizeof(float[3]));
    const float lo[3] = {-h[0], -h[1], -h[2]};
    check_bounds(&m.bounds, lo, h, sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]), 1e-6f);
    ob_mesh_release(&m);
}

static void sphere_is_closed_round_and_faces_out(void **state)
{
    (void)state;
    const uint32_t slices = 16, stacks = 8;
    const float r = 2.5f;
    ob_mesh m;
    assert_int_equal(ob_mesh_sphere(r, slices, stacks, &m), OB_OK);
    check_counts(&m, 2 * slices + (stacks - 1) * (slices + 1), 6 * slices * (stacks - 1));
    check_unit_normals_and_uv(&m, 1.0f);
    check_closed(&m);
    check_outward(&m, origin);
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        const float *p = m.vertices[v].position, *n = m.vertices[v].normal;
        assert_float_equal(sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), r, 1e-5f);
        for (int k = 0; k < 3; k++) assert_float_equal(n[k], p[k] / r, 1e-5f);
    }
    const float lo[3] = {-r, -r, -r}, hi[3] = {r, r, r};
    check_bounds(&m.bounds, lo, hi, r, 1e-5f);
    ob_mesh_release(&m);

    /* The fewest segments still make a closed solid. */
    assert_int_equal(ob_mesh_sphere(1.0f, 3, 2, &m), OB_OK);
    check_counts(&m, 10, 18);
    check_closed(&m);
    check_outward(&m, origin);
    ob_mesh_release(&m);
}

static void plane_faces_up_on_a_grid(void **state)
{
    (void)state;
    const uint32_t n = 4;
    ob_mesh m;
    assert_int_equal(ob_mesh_plane(3.0f, 2.0f, n, &m), OB_OK);
    check_counts(&m, (n + 1) * (n + 1), 6 * n * n);
    check_unit_normals_and_uv(&m, 1.0f);
    for (uint32_t t = 0; t < m.index_count / 3; t++) {
        double nrm[3], c[3];
        triangle_frame(&m, t, nrm, c);
        assert_true(nrm[1] > 0.0);
        assert_true(fabs(nrm[0]) < 1e-9 && fabs(nrm[2]) < 1e-9);
    }
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        assert_float_equal(m.vertices[v].position[1], 0.0f, 0.0f);
        assert_float_equal(m.vertices[v].normal[1], 1.0f, 0.0f);
    }
    /* Total area: the triangles tile the rectangle exactly once. */
    double area = 0.0;
    for (uint32_t t = 0; t < m.index_count / 3; t++) {
        double nrm[3], c[3];
        triangle_frame(&m, t, nrm, c);
        area += 0.5 * sqrt(dot3(nrm, nrm));
    }
    assert_float_equal((float)area, 6.0f, 1e-5f);
    const float lo[3] = {-1.5f, 0, -1.0f}, hi[3] = {1.5f, 0, 1.0f};
    check_bounds(&m.bounds, lo, hi, sqrtf(1.5f * 1.5f + 1.0f), 1e-6f);
    ob_mesh_release(&m);
}

static void cone_is_closed_with_a_cap_below(void **state)
{
    (void)state;
    const uint32_t slices = 12;
    const float r = 1.0f, h = 3.0f;
    ob_mesh m;
    assert_int_equal(ob_mesh_cone(r, h, slices, &m), OB_OK);
    check_counts(&m, 3 * slices + 3, 6 * slices);
    check_unit_normals_and_uv(&m, 1.0f);
    check_closed(&m);
    const double inside[3] = {0, h / 4.0, 0};   /* the centroid of a cone: convex, any interior point works */
    check_outward(&m, inside);
    const float lo[3] = {-r, 0, -r}, hi[3] = {r, h, r};
    check_bounds(&m.bounds, lo, hi, sqrtf(r * r + h * h / 4), 1e-6f);
    ob_mesh_release(&m);
}

static void torus_is_closed_and_faces_out_of_the_tube(void **state)
{
    (void)state;
    const uint32_t major = 24, minor = 12;
    const float R = 2.0f, r = 0.5f;
    ob_mesh m;
    assert_int_equal(ob_mesh_torus(R, r, major, minor, &m), OB_OK);
    check_counts(&m, (major + 1) * (minor + 1), 6 * major * minor);
    check_unit_normals_and_uv(&m, 1.0f);
    check_closed(&m);
    /* Not convex: "outward" means away from the nearest point of the tube's core circle. */
    for (uint32_t t = 0; t < m.index_count / 3; t++) {
        double n[3], c[3];
        triangle_frame(&m, t, n, c);
        double rad = sqrt(c[0] * c[0] + c[2] * c[2]);
        double core[3] = {c[0] / rad * R, 0.0, c[2] / rad * R};
        double out[3] = {c[0] - core[0], c[1] - core[1], c[2] - core[2]};
        if (dot3(n, out) <= 0.0) fail_msg("torus triangle %u faces into the tube", t);
        for (int k = 0; k < 3; k++) {
            const float *vn = m.vertices[m.indices[3 * t + k]].normal;
            double vd[3] = {vn[0], vn[1], vn[2]};
            if (dot3(vd, n) <= 0.0) fail_msg("torus triangle %u vertex normal disagrees", t);
        }
    }
    const float lo[3] = {-(R + r), -r, -(R + r)}, hi[3] = {R + r, r, R + r};
    check_bounds(&m.bounds, lo, hi, R + r, 1e-6f);
    ob_mesh_release(&m);
}

static void fullscreen_triangle_covers_clip_space(void **state)
{
    (void)state;
    ob_mesh m;
    assert_int_equal(ob_mesh_fullscreen_triangle(&m), OB_OK);
    check_counts(&m, 3, 3);
    check_unit_normals_and_uv(&m, 2.0f);
    /* Interpolating uv at each clip-space corner gives that corner's screen uv. */
    const float *p0 = m.vertices[m.indices[0]].position, *p1 = m.vertices[m.indices[1]].position,
                *p2 = m.vertices[m.indices[2]].position;
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    double det = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
    assert_true(det > 0.0);   /* counter-clockwise in x-right, y-up */
    for (int c = 0; c < 4; c++) {
        double x = corners[c][0], y = corners[c][1];
        double b1 = ((x - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (y - p0[1])) / det;
        double b2 = ((p1[0] - p0[0]) * (y - p0[1]) - (x - p0[0]) * (p1[1] - p0[1])) / det;
        double b0 = 1.0 - b1 - b2;
        assert_true(b0 >= -1e-9 && b1 >= -1e-9 && b2 >= -1e-9);   /* inside */
        for (int k = 0; k < 2; k++) {
            double uv = b0 * m.vertices[m.indices[0]].uv[k] + b1 * m.vertices[m.indices[1]].uv[k] +
                        b2 * m.vertices[m.indices[2]].uv[k];
            assert_float_equal((float)uv, (float)((corners[c][k] + 1.0) / 2.0), 1e-6f);
        }
    }
    ob_mesh_release(&m);
}

static void expect_rejected(ob_result r, const ob_mesh *m, const char *shape, const char *what)
{
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_null(m->vertices);
    assert_null(m->indices);
    assert_int_equal(m->vertex_count, 0);
    if (!ob_test_log_has(shape, what, NULL)) fail_msg("no log line naming '%s' and '%s'", shape, what);
}

static void generators_reject_bad_parameters(void **state)
{
    (void)state;
    ob_mesh m;
    ob_test_log_clear();
    const float zero_x[3] = {0.0f, 1.0f, 1.0f}, nan_z[3] = {1.0f, 1.0f, NAN};
    expect_rejected(ob_mesh_box(zero_x, &m), &m, "box", "half extent x");
    expect_rejected(ob_mesh_box(nan_z, &m), &m, "box", "half extent z");
    expect_rejected(ob_mesh_box(NULL, &m), &m, "box", "NULL");
    expect_rejected(ob_mesh_sphere(-1.0f, 8, 8, &m), &m, "sphere", "radius");
    expect_rejected(ob_mesh_sphere(1.0f, 2, 8, &m), &m, "sphere", "slices");
    expect_rejected(ob_mesh_sphere(1.0f, 8, 1, &m), &m, "sphere", "stacks");
    expect_rejected(ob_mesh_sphere(1.0f, OB_MESH_MAX_SEGMENTS + 1, 8, &m), &m, "sphere", "slices");
    expect_rejected(ob_mesh_plane(1.0f, INFINITY, 1, &m), &m, "plane", "depth");
    expect_rejected(ob_mesh_plane(1.0f, 1.0f, 0, &m), &m, "plane", "subdivisions");
    expect_rejected(ob_mesh_cone(1.0f, 0.0f, 8, &m), &m, "cone", "height");
    expect_rejected(ob_mesh_cone(1.0f, 1.0f, 2, &m), &m, "cone", "slices");
    expect_rejected(ob_mesh_torus(1.0f, 1.0f, 8, 8, &m), &m, "torus", "minor radius");
    expect_rejected(ob_mesh_torus(1.0f, 0.5f, 8, 2, &m), &m, "torus", "minor segments");
    expect_rejected(ob_mesh_torus(0.0f, 0.5f, 8, 8, &m), &m, "torus", "major radius");
}

static void generators_fail_cleanly_without_memory(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    for (uint64_t nth = 1; nth <= 2; nth++) {
        ob_mesh m;
        ob_fault_arm(OB_FAULT_HOST_ALLOC, nth);
        ob_result r = ob_mesh_box(h, &m);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
        assert_null(m.vertices);
        assert_null(m.indices);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, nth);
        r = ob_mesh_torus(2, 1, 8, 8, &m);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
        assert_null(m.vertices);
    }
}

/* ------------------------------------------------------------ validation */

static void validate_names_out_of_range_index(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    m.indices[4] = 99999;
    ob_test_log_clear();
    assert_int_equal(ob_mesh_validate(&m, "crate"), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("crate: index 4 = 99999 out of range (24 vertices)", NULL));
    ob_mesh_release(&m);
}

static void validate_names_non_finite_attributes(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    m.vertices[3].position[1] = NAN;
    m.vertices[7].uv[0] = INFINITY;
    ob_test_log_clear();
    assert_int_equal(ob_mesh_validate(&m, "crate"), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("crate: vertex 3 position is not finite", NULL));
    assert_true(ob_test_log_has("crate: vertex 7 uv is not finite", NULL));
    ob_test_log_clear();
    assert_int_equal(ob_mesh_compute_bounds(&m), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("vertex 3 position is not finite", NULL));
    ob_mesh_release(&m);
}

static void validate_rejects_empty_and_partial_triangles(void **state)
{
    (void)state;
    ob_mesh empty = {0};
    ob_test_log_clear();
    assert_int_equal(ob_mesh_validate(&empty, "nothing"), OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("nothing: empty mesh", NULL));
    assert_int_equal(ob_mesh_validate(NULL, NULL), OB_ERR_INVALID_ARGUMENT);

    const float h[3] = {1, 1, 1};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    m.index_count = 35;
    assert_int_equal(ob_mesh_validate(&m, "crate"), OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("crate: index count 35 is not a multiple of 3", NULL));
    /* The same indices read as a line strip are fine. */
    assert_int_equal(ob_mesh_validate_primitives(&m, "crate", 1, 2), OB_OK);
    m.index_count = 36;
    ob_mesh_release(&m);
}

static void validate_does_not_flood_the_log(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    for (uint32_t i = 0; i < m.index_count; i++) m.indices[i] = 1000 + i;
    ob_test_log_clear();
    assert_int_equal(ob_mesh_validate(&m, "crate"), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_count(OB_LOG_ERROR) <= 5);
    assert_true(ob_test_log_has("crate: 32 more problems not shown (36 in all)", NULL));
    ob_mesh_release(&m);
}

/* --------------------------------------------------------------- normals */

static void generate_normals_restores_flat_box_normals(void **state)
{
    (void)state;
    const float h[3] = {0.5f, 2.0f, 1.0f};
    ob_mesh m;
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    float expected[24][3];
    for (uint32_t v = 0; v < 24; v++) {
        memcpy(expected[v], m.vertices[v].normal, sizeof expected[v]);
        memset(m.vertices[v].normal, 0, sizeof expected[v]);
    }
    assert_int_equal(ob_mesh_generate_normals(&m), OB_OK);
    for (uint32_t v = 0; v < 24; v++)
        for (int k = 0; k < 3; k++) assert_float_equal(m.vertices[v].normal[k], expected[v][k], 1e-6f);
    ob_mesh_release(&m);
}

static void generate_normals_smooths_shared_corners(void **state)
{
    (void)state;
    /* A cube with 8 shared corners and no normals: each corner's normal
     * must be unit length and point out of the cube, and by the cube's
     * symmetry under this triangulation lie in the corner's octant. */
    ob_vertex v[8] = {0};
    for (uint32_t i = 0; i < 8; i++) {
        v[i].position[0] = (i & 1) ? 1.0f : -1.0f;
        v[i].position[1] = (i & 2) ? 1.0f : -1.0f;
        v[i].position[2] = (i & 4) ? 1.0f : -1.0f;
    }
    uint32_t idx[36] = {
        0, 4, 6, 0, 6, 2,   /* -X */  1, 3, 7, 1, 7, 5,   /* +X */
        0, 1, 5, 0, 5, 4,   /* -Y */  2, 6, 7, 2, 7, 3,   /* +Y */
        0, 2, 3, 0, 3, 1,   /* -Z */  4, 5, 7, 4, 7, 6,   /* +Z */
    };
    ob_mesh m = {.vertices = v, .vertex_count = 8, .indices = idx, .index_count = 36};
    check_closed(&m);
    assert_int_equal(ob_mesh_generate_normals(&m), OB_OK);
    check_outward(&m, origin);   /* faces wind outward and the new normals agree with them */
    for (uint32_t i = 0; i < 8; i++) {
        const float *n = v[i].normal, *p = v[i].position;
        assert_float_equal(sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0f, 1e-6f);
        for (int k = 0; k < 3; k++) assert_true(n[k] * p[k] > 0.0f);
    }
}

static void generate_normals_handles_degenerate_and_bad_input(void **state)
{
    (void)state;
    ob_vertex v[4] = {{{0, 0, 0}}, {{1, 0, 0}}, {{2, 0, 0}}, {{5, 5, 5}}};   /* collinear + unused */
    uint32_t idx[3] = {0, 1, 2};
    ob_mesh m = {.vertices = v, .vertex_count = 4, .indices = idx, .index_count = 3};
    assert_int_equal(ob_mesh_generate_normals(&m), OB_OK);
    for (uint32_t i = 0; i < 4; i++) {
        assert_float_equal(v[i].normal[0], 0.0f, 0.0f);
        assert_float_equal(v[i].normal[1], 1.0f, 0.0f);
        assert_float_equal(v[i].normal[2], 0.0f, 0.0f);
    }
    idx[2] = 4;
    ob_test_log_clear();
    assert_int_equal(ob_mesh_generate_normals(&m), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("index 2 = 4 out of range (4 vertices)", NULL));
    assert_int_equal(ob_mesh_generate_normals(NULL), OB_ERR_INVALID_ARGUMENT);
}

static void release_accepts_null_and_zeroed(void **state)
{
    (void)state;
    ob_mesh_release(NULL);
    ob_mesh m = {0};
    ob_mesh_release(&m);
    const float h[3] = {1, 1, 1};
    assert_int_equal(ob_mesh_box(h, &m), OB_OK);
    ob_mesh_release(&m);
    assert_null(m.vertices);
    assert_int_equal(m.index_count, 0);
    ob_mesh_release(&m);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(box_is_closed_flat_and_exactly_bounded),
        cmocka_unit_test(sphere_is_closed_round_and_faces_out),
        cmocka_unit_test(plane_faces_up_on_a_grid),
        cmocka_unit_test(cone_is_closed_with_a_cap_below),
        cmocka_unit_test(torus_is_closed_and_faces_out_of_the_tube),
        cmocka_unit_test(fullscreen_triangle_covers_clip_space),
        cmocka_unit_test(generators_reject_bad_parameters),
        cmocka_unit_test(generators_fail_cleanly_without_memory),
        cmocka_unit_test(validate_names_out_of_range_index),
        cmocka_unit_test(validate_names_non_finite_attributes),
        cmocka_unit_test(validate_rejects_empty_and_partial_triangles),
        cmocka_unit_test(validate_does_not_flood_the_log),
        cmocka_unit_test(generate_normals_restores_flat_box_normals),
        cmocka_unit_test(generate_normals_smooths_shared_corners),
        cmocka_unit_test(generate_normals_handles_degenerate_and_bad_input),
        cmocka_unit_test(release_accepts_null_and_zeroed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
