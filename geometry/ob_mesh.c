/* ob_mesh.c — CPU meshes: bounds, validation, normals and shape generators. */
#include "ob_mesh.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define OB_MESH_LOG "geometry"
#define OB_PI_F 3.14159265358979323846f
/* Validation names the first few problems and then only counts the rest, so
 * a broken million-index mesh does not flood the log. */
#define OB_VALIDATE_LOG_MAX 4u

static bool vec_finite(const float *v, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

void ob_mesh_release(ob_mesh *mesh)
{
    if (!mesh) return;
    ob_free(mesh->vertices);
    ob_free(mesh->indices);
    ob_free(mesh->tangents);
    ob_free(mesh->colors);
    ob_free(mesh->uv1);
    memset(mesh, 0, sizeof *mesh);
}

/* ------------------------------------------------------------------ bounds */

ob_result ob_bounds_compute(const ob_vertex *vertices, uint32_t count, ob_bounds *out_bounds)
{
    if (!out_bounds || (count && !vertices)) {
        OB_LOG_E(OB_MESH_LOG, "ob_bounds_compute: NULL %s", out_bounds ? "vertices" : "out_bounds");
        if (out_bounds) memset(out_bounds, 0, sizeof *out_bounds);
        return OB_ERR_INVALID_ARGUMENT;
    }
    memset(out_bounds, 0, sizeof *out_bounds);
    if (count == 0) return OB_OK;

    float lo[3], hi[3];
    for (uint32_t k = 0; k < 3; k++) lo[k] = hi[k] = vertices[0].position[k];
    for (uint32_t i = 0; i < count; i++) {
        const float *p = vertices[i].position;
        if (!vec_finite(p, 3)) {
            OB_LOG_E(OB_MESH_LOG, "bounds: vertex %u position is not finite (%g, %g, %g)", i,
                     (double)p[0], (double)p[1], (double)p[2]);
            return OB_ERR_NON_FINITE;
        }
        for (uint32_t k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], p[k]);
            hi[k] = fmaxf(hi[k], p[k]);
        }
    }
    double c[3], r2 = 0.0;
    for (uint32_t k = 0; k < 3; k++) c[k] = 0.5 * ((double)lo[k] + (double)hi[k]);
    for (uint32_t i = 0; i < count; i++) {
        const float *p = vertices[i].position;
        double d2 = 0.0;
        for (uint32_t k = 0; k < 3; k++) d2 += ((double)p[k] - c[k]) * ((double)p[k] - c[k]);
        if (d2 > r2) r2 = d2;
    }
    for (uint32_t k = 0; k < 3; k++) {
        out_bounds->min[k] = lo[k];
        out_bounds->max[k] = hi[k];
        out_bounds->center[k] = (float)c[k];
    }
    out_bounds->radius = (float)sqrt(r2);
    return OB_OK;
}

ob_result ob_mesh_compute_bounds(ob_mesh *mesh)
{
    if (!mesh) {
        OB_LOG_E(OB_MESH_LOG, "ob_mesh_compute_bounds: NULL mesh");
        return OB_ERR_INVALID_ARGUMENT;
    }
    return ob_bounds_compute(mesh->vertices, mesh->vertex_count, &mesh->bounds);
}

/* -------------------------------------------------------------- validation */

typedef struct validate_state {
    const char *name;
    ob_result first;
    uint32_t problems;
} validate_state;

static void problem(validate_state *s, ob_result r, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void problem(validate_state *s, ob_result r, const char *fmt, ...)
{
    if (s->first == OB_OK) s->first = r;
    if (s->problems++ >= OB_VALIDATE_LOG_MAX) return;
    char text[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    OB_LOG_E(OB_MESH_LOG, "%s: %s", s->name, text);
}

static void check_attribute(validate_state *s, uint32_t vertex, const char *what,
                            const float *v, uint32_t n)
{
    if (vec_finite(v, n)) return;
    if (n == 3)
        problem(s, OB_ERR_NON_FINITE, "vertex %u %s is not finite (%g, %g, %g)", vertex, what,
                (double)v[0], (double)v[1], (double)v[2]);
    else
        problem(s, OB_ERR_NON_FINITE, "vertex %u %s is not finite (%g, %g)", vertex, what,
                (double)v[0], (double)v[1]);
}

ob_result ob_mesh_validate_primitives(const ob_mesh *mesh, const char *name,
                                      uint32_t indices_per_primitive, uint32_t min_indices)
{
    validate_state s = {.name = name ? name : "mesh"};
    if (!mesh) {
        problem(&s, OB_ERR_INVALID_ARGUMENT, "NULL mesh");
        return s.first;
    }
    if (indices_per_primitive == 0) indices_per_primitive = 1;
    if (mesh->vertex_count == 0 || mesh->index_count == 0)
        problem(&s, OB_ERR_INVALID_ARGUMENT, "empty mesh (%u vertices, %u indices)",
                mesh->vertex_count, mesh->index_count);
    if ((mesh->vertex_count && !mesh->vertices) || (mesh->index_count && !mesh->indices))
        problem(&s, OB_ERR_INVALID_ARGUMENT, "%s array is NULL but its count is %u",
                mesh->index_count && !mesh->indices ? "index" : "vertex",
                mesh->index_count && !mesh->indices ? mesh->index_count : mesh->vertex_count);
    if (s.first != OB_OK) goto done;
    if (mesh->index_count % indices_per_primitive != 0)
        problem(&s, OB_ERR_INVALID_ARGUMENT, "index count %u is not a multiple of %u",
                mesh->index_count, indices_per_primitive);
    if (mesh->index_count < min_indices)
        problem(&s, OB_ERR_INVALID_ARGUMENT, "%u indices, a primitive needs at least %u",
                mesh->index_count, min_indices);

    for (uint32_t i = 0; i < mesh->index_count; i++) {
        if (mesh->indices[i] >= mesh->vertex_count)
            problem(&s, OB_ERR_OUT_OF_RANGE, "index %u = %u out of range (%u vertices)", i,
                    mesh->indices[i], mesh->vertex_count);
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const ob_vertex *vx = &mesh->vertices[v];
        check_attribute(&s, v, "position", vx->position, 3);
        check_attribute(&s, v, "normal", vx->normal, 3);
        check_attribute(&s, v, "uv", vx->uv, 2);
        if (mesh->uv1) check_attribute(&s, v, "uv1", mesh->uv1[v], 2);
        if (mesh->tangents && !vec_finite(mesh->tangents[v], 4))
            problem(&s, OB_ERR_NON_FINITE, "vertex %u tangent is not finite (%g, %g, %g, %g)", v,
                    (double)mesh->tangents[v][0], (double)mesh->tangents[v][1],
                    (double)mesh->tangents[v][2], (double)mesh->tangents[v][3]);
    }
done:
    if (s.problems > OB_VALIDATE_LOG_MAX)
        OB_LOG_E(OB_MESH_LOG, "%s: %u more problems not shown (%u in all)", s.name,
                 s.problems - OB_VALIDATE_LOG_MAX, s.problems);
    return s.first;
}

ob_result ob_mesh_validate(const ob_mesh *mesh, const char *name)
{
    return ob_mesh_validate_primitives(mesh, name, 3, 3);
}

/* ----------------------------------------------------------------- normals */

ob_result ob_mesh_generate_normals(ob_mesh *mesh)
{
    if (!mesh || !mesh->vertices || !mesh->indices || mesh->index_count % 3 != 0) {
        OB_LOG_E(OB_MESH_LOG, "generate normals: %s", !mesh ? "NULL mesh"
                 : mesh->index_count % 3 ? "index count is not a multiple of 3"
                                         : "mesh has no vertices or indices");
        return OB_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t i = 0; i < mesh->index_count; i++) {
        if (mesh->indices[i] >= mesh->vertex_count) {
            OB_LOG_E(OB_MESH_LOG, "generate normals: index %u = %u out of range (%u vertices)", i,
                     mesh->indices[i], mesh->vertex_count);
            return OB_ERR_OUT_OF_RANGE;
        }
    }
    /* Accumulate in double: a vertex shared by thousands of triangles would
     * otherwise lose the small ones. */
    double *acc = ob_calloc(mesh->vertex_count, 3 * sizeof(double));
    if (!acc) {
        OB_LOG_E(OB_MESH_LOG, "generate normals: out of memory for %u vertices", mesh->vertex_count);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
        const uint32_t *tri = &mesh->indices[t];
        const float *a = mesh->vertices[tri[0]].position;
        const float *b = mesh->vertices[tri[1]].position;
        const float *c = mesh->vertices[tri[2]].position;
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)b[k] - a[k];
            e2[k] = (double)c[k] - a[k];
        }
        /* The unnormalized cross product is twice the area: area weighting for free. */
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        if (!isfinite(n[0]) || !isfinite(n[1]) || !isfinite(n[2])) continue;
        for (int j = 0; j < 3; j++)
            for (int k = 0; k < 3; k++) acc[3 * (size_t)tri[j] + k] += n[k];
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const double *s = &acc[3 * (size_t)v];
        double len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
        float *n = mesh->vertices[v].normal;
        if (len > 1e-30 && isfinite(len)) {
            for (int k = 0; k < 3; k++) n[k] = (float)(s[k] / len);
        } else {
            n[0] = 0.0f;
            n[1] = 1.0f;
            n[2] = 0.0f;
        }
    }
    ob_free(acc);
    return OB_OK;
}

/* ---------------------------------------------------------------- tangents */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static bool normalize3(double *v)
{
    double len = sqrt(dot3(v, v));
    if (!(len > 1e-20) || !isfinite(len)) return false;
    for (int k = 0; k < 3; k++) v[k] /= len;
    return true;
}

/* Angle at corner a of triangle (a, b, c). */
static double corner_angle(const float *a, const float *b, const float *c)
{
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
    }
    if (!normalize3(u) || !normalize3(v)) return 0.0;
    double d = dot3(u, v);
    return acos(d < -1.0 ? -1.0 : d > 1.0 ? 1.0 : d);
}

ob_result ob_mesh_generate_tangents(ob_mesh *mesh, bool uv_origin_bottom_left)
{
    if (!mesh || !mesh->vertices || !mesh->indices || mesh->index_count % 3 != 0) {
        OB_LOG_E(OB_MESH_LOG, "generate tangents: %s", !mesh ? "NULL mesh"
                 : mesh->index_count % 3 ? "index count is not a multiple of 3"
                                         : "mesh has no vertices or indices");
        return OB_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t i = 0; i < mesh->index_count; i++) {
        if (mesh->indices[i] >= mesh->vertex_count) {
            OB_LOG_E(OB_MESH_LOG, "generate tangents: index %u = %u out of range (%u vertices)", i,
                     mesh->indices[i], mesh->vertex_count);
            return OB_ERR_OUT_OF_RANGE;
        }
    }
    /* tangent sum (3) and bitangent sum (3) per vertex */
    double *acc = ob_calloc(mesh->vertex_count, 6 * sizeof(double));
    float(*out)[4] = mesh->tangents ? mesh->tangents : ob_malloc((size_t)mesh->vertex_count * sizeof *out);
    if (!acc || !out) {
        ob_free(acc);
        if (out != mesh->tangents) ob_free(out);
        OB_LOG_E(OB_MESH_LOG, "generate tangents: out of memory for %u vertices", mesh->vertex_count);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    /* v measured up the image whichever way the mesh stores it. */
    const double v_up = uv_origin_bottom_left ? 1.0 : -1.0;
    for (uint32_t t = 0; t + 2 < mesh->index_count; t += 3) {
        const uint32_t *tri = &mesh->indices[t];
        const ob_vertex *a = &mesh->vertices[tri[0]], *b = &mesh->vertices[tri[1]],
                        *c = &mesh->vertices[tri[2]];
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)b->position[k] - a->position[k];
            e2[k] = (double)c->position[k] - a->position[k];
        }
        double du1 = (double)b->uv[0] - a->uv[0], dv1 = v_up * ((double)b->uv[1] - a->uv[1]);
        double du2 = (double)c->uv[0] - a->uv[0], dv2 = v_up * ((double)c->uv[1] - a->uv[1]);
        double det = du1 * dv2 - du2 * dv1;
        if (!(fabs(det) > 1e-20) || !isfinite(det)) continue;   /* no uv area: no direction */
        double tan[3], bit[3];
        for (int k = 0; k < 3; k++) {
            tan[k] = (e1[k] * dv2 - e2[k] * dv1) / det;
            bit[k] = (e2[k] * du1 - e1[k] * du2) / det;
        }
        if (!normalize3(tan) || !normalize3(bit)) continue;
        const float *p[3] = {a->position, b->position, c->position};
        for (int j = 0; j < 3; j++) {
            double w = corner_angle(p[j], p[(j + 1) % 3], p[(j + 2) % 3]);
            double *s = &acc[6 * (size_t)tri[j]];
            for (int k = 0; k < 3; k++) {
                s[k] += w * tan[k];
                s[3 + k] += w * bit[k];
            }
        }
    }
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const double *s = &acc[6 * (size_t)v];
        const float *nf = mesh->vertices[v].normal;
        double n[3] = {nf[0], nf[1], nf[2]};
        if (!normalize3(n)) {
            n[0] = 0.0;
            n[1] = 1.0;
            n[2] = 0.0;
        }
        double tan[3] = {s[0], s[1], s[2]};
        double d = dot3(n, tan);
        for (int k = 0; k < 3; k++) tan[k] -= n[k] * d;
        double w = 1.0;
        if (normalize3(tan)) {
            double nxt[3];
            cross3(n, tan, nxt);
            w = dot3(nxt, s + 3) < 0.0 ? -1.0 : 1.0;
        } else {
            /* Any unit vector perpendicular to n: cross with the axis least
             * aligned with it. */
            double axis[3] = {0, 0, 0};
            int m = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0
                    : fabs(n[1]) <= fabs(n[2])                           ? 1 : 2;
            axis[m] = 1.0;
            cross3(axis, n, tan);
            normalize3(tan);
        }
        for (int k = 0; k < 3; k++) out[v][k] = (float)tan[k];
        out[v][3] = (float)w;
    }
    ob_free(acc);
    mesh->tangents = out;
    return OB_OK;
}

/* -------------------------------------------------------------- generators */

static bool size_ok(const char *shape, const char *what, float v)
{
    if (isfinite(v) && v > 0.0f) return true;
    OB_LOG_E(OB_MESH_LOG, "%s: %s must be a positive finite number (got %g)", shape, what, (double)v);
    return false;
}

static bool segments_ok(const char *shape, const char *what, uint32_t n, uint32_t min)
{
    if (n >= min && n <= OB_MESH_MAX_SEGMENTS) return true;
    OB_LOG_E(OB_MESH_LOG, "%s: %s must be between %u and %u (got %u)", shape, what, min,
             OB_MESH_MAX_SEGMENTS, n);
    return false;
}

/* The product of a generator's two segment counts bounds its vertices
 * (about one per cell): OB_MESH_MAX_GENERATED_CELLS keeps a 4096 x 4096
 * request from committing gigabytes. */
static bool cells_ok(const char *shape, const char *a_name, uint32_t a, const char *b_name, uint32_t b)
{
    if ((uint64_t)a * b <= OB_MESH_MAX_GENERATED_CELLS) return true;
    OB_LOG_E(OB_MESH_LOG, "%s: %s x %s = %u x %u = %llu cells, more than the limit of %u", shape,
             a_name, b_name, a, b, (unsigned long long)a * b, OB_MESH_MAX_GENERATED_CELLS);
    return false;
}

static ob_result mesh_alloc(const char *shape, uint32_t vertex_count, uint32_t index_count,
                            ob_mesh *out)
{
    out->vertices = ob_calloc(vertex_count, sizeof(ob_vertex));
    out->indices = ob_calloc(index_count, sizeof(uint32_t));
    if (!out->vertices || !out->indices) {
        OB_LOG_E(OB_MESH_LOG, "%s: out of memory for %u vertices and %u indices", shape,
                 vertex_count, index_count);
        ob_mesh_release(out);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    out->vertex_count = vertex_count;
    out->index_count = index_count;
    return OB_OK;
}

static void set_vertex(ob_vertex *v, float px, float py, float pz, float nx, float ny, float nz,
                       float u, float t)
{
    v->position[0] = px;
    v->position[1] = py;
    v->position[2] = pz;
    v->normal[0] = nx;
    v->normal[1] = ny;
    v->normal[2] = nz;
    v->uv[0] = u;
    v->uv[1] = t;
}

static uint32_t *emit_tri(uint32_t *dst, uint32_t a, uint32_t b, uint32_t c)
{
    dst[0] = a;
    dst[1] = b;
    dst[2] = c;
    return dst + 3;
}

/* Quad a-b-c-d in counter-clockwise order seen from the front. */
static uint32_t *emit_quad(uint32_t *dst, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    return emit_tri(emit_tri(dst, a, b, c), a, c, d);
}

/* Exact cos/sin on the quarter turns, so seams and poles built from the same
 * angle index weld bit-exactly and axis-aligned extents equal the radius. */
static void ring_dir(uint32_t step, uint32_t steps, float *out_cos, float *out_sin)
{
    step %= steps;
    if ((uint64_t)step * 4u % steps == 0) {
        static const float c4[4] = {1.0f, 0.0f, -1.0f, 0.0f};
        static const float s4[4] = {0.0f, 1.0f, 0.0f, -1.0f};
        uint32_t q = (uint32_t)((uint64_t)step * 4u / steps);
        *out_cos = c4[q];
        *out_sin = s4[q];
        return;
    }
    float a = 2.0f * OB_PI_F * (float)step / (float)steps;
    *out_cos = cosf(a);
    *out_sin = sinf(a);
}

static ob_result finish(ob_mesh *out)
{
    ob_result r = ob_mesh_compute_bounds(out);
    if (r != OB_OK) ob_mesh_release(out);
    return r;
}

ob_result ob_mesh_box(const float half_extents[3], ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!half_extents) {
        OB_LOG_E(OB_MESH_LOG, "box: NULL half_extents");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (!size_ok("box", "half extent x", half_extents[0]) ||
        !size_ok("box", "half extent y", half_extents[1]) ||
        !size_ok("box", "half extent z", half_extents[2]))
        return OB_ERR_INVALID_ARGUMENT;
    ob_result r = mesh_alloc("box", 24, 36, out);
    if (r != OB_OK) return r;

    /* Per face: outward normal n and in-plane axes u, v with u × v = n, so
     * corners (-u-v, +u-v, +u+v, -u+v) run counter-clockwise seen from outside. */
    static const float faces[6][3][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},   {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    static const float corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    uint32_t *idx = out->indices;
    for (uint32_t f = 0; f < 6; f++) {
        const float *n = faces[f][0], *u = faces[f][1], *v = faces[f][2];
        for (uint32_t c = 0; c < 4; c++) {
            float p[3];
            for (int k = 0; k < 3; k++)
                p[k] = (n[k] + corner[c][0] * u[k] + corner[c][1] * v[k]) * half_extents[k];
            /* Image top (v = 0) on the face's +v side. */
            set_vertex(&out->vertices[4 * f + c], p[0], p[1], p[2], n[0], n[1], n[2],
                       0.5f * (corner[c][0] + 1.0f), 0.5f * (1.0f - corner[c][1]));
        }
        idx = emit_quad(idx, 4 * f, 4 * f + 1, 4 * f + 2, 4 * f + 3);
    }
    return finish(out);
}

ob_result ob_mesh_sphere(float radius, uint32_t slices, uint32_t stacks, ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!size_ok("sphere", "radius", radius) || !segments_ok("sphere", "slices", slices, 3) ||
        !segments_ok("sphere", "stacks", stacks, 2) ||
        !cells_ok("sphere", "slices", slices, "stacks", stacks))
        return OB_ERR_INVALID_ARGUMENT;
    /* Rows: the north pole (slices vertices, one per triangle so each gets
     * its own u), stacks-1 rings of slices+1 (the seam column is duplicated
     * for uv), the south pole (slices vertices). */
    const uint32_t ring = slices + 1;
    const uint32_t first_ring = slices;
    const uint32_t south = first_ring + (stacks - 1) * ring;
    ob_result r = mesh_alloc("sphere", south + slices, 6 * slices * (stacks - 1), out);
    if (r != OB_OK) return r;

    for (uint32_t j = 0; j < slices; j++) {
        float u = ((float)j + 0.5f) / (float)slices;
        set_vertex(&out->vertices[j], 0, radius, 0, 0, 1, 0, u, 0.0f);
        set_vertex(&out->vertices[south + j], 0, -radius, 0, 0, -1, 0, u, 1.0f);
    }
    for (uint32_t i = 1; i < stacks; i++) {
        /* Polar angle from +Y; stacks/2 is the exact equator when even. */
        float cphi, sphi;
        ring_dir(i, 2 * stacks, &cphi, &sphi);
        for (uint32_t j = 0; j <= slices; j++) {
            float cth, sth;
            ring_dir(j, slices, &cth, &sth);
            float n[3] = {sphi * cth, cphi, -sphi * sth};
            set_vertex(&out->vertices[first_ring + (i - 1) * ring + j], radius * n[0],
                       radius * n[1], radius * n[2], n[0], n[1], n[2],
                       (float)j / (float)slices, (float)i / (float)stacks);
        }
    }
    /* Quad (a = row i col j, b = row i+1 col j, c = row i+1 col j+1,
     * d = row i col j+1) winds counter-clockwise outward because
     * dP/dphi × dP/dtheta points away from the centre. */
    uint32_t *idx = out->indices;
    for (uint32_t j = 0; j < slices; j++)
        idx = emit_tri(idx, j, first_ring + j, first_ring + j + 1);
    for (uint32_t i = 1; i + 1 < stacks; i++) {
        uint32_t row = first_ring + (i - 1) * ring, next = row + ring;
        for (uint32_t j = 0; j < slices; j++)
            idx = emit_quad(idx, row + j, next + j, next + j + 1, row + j + 1);
    }
    uint32_t last = first_ring + (stacks - 2) * ring;
    for (uint32_t j = 0; j < slices; j++)
        idx = emit_tri(idx, last + j, south + j, last + j + 1);
    return finish(out);
}

ob_result ob_mesh_plane(float width, float depth, uint32_t subdivisions, ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!size_ok("plane", "width", width) || !size_ok("plane", "depth", depth) ||
        !segments_ok("plane", "subdivisions", subdivisions, 1) ||
        !cells_ok("plane", "subdivisions", subdivisions, "subdivisions", subdivisions))
        return OB_ERR_INVALID_ARGUMENT;
    const uint32_t n = subdivisions, row = n + 1;
    ob_result r = mesh_alloc("plane", row * row, 6 * n * n, out);
    if (r != OB_OK) return r;
    for (uint32_t i = 0; i <= n; i++) {      /* along X */
        for (uint32_t j = 0; j <= n; j++) {  /* along Z */
            float s = (float)i / (float)n, t = (float)j / (float)n;
            set_vertex(&out->vertices[i * row + j], (s - 0.5f) * width, 0.0f, (t - 0.5f) * depth,
                       0, 1, 0, s, t);
        }
    }
    /* Seen from +Y, going +Z then +X is counter-clockwise. */
    uint32_t *idx = out->indices;
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < n; j++)
            idx = emit_quad(idx, i * row + j, i * row + j + 1, (i + 1) * row + j + 1,
                            (i + 1) * row + j);
    return finish(out);
}

ob_result ob_mesh_cone(float radius, float height, uint32_t slices, ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!size_ok("cone", "radius", radius) || !size_ok("cone", "height", height) ||
        !segments_ok("cone", "slices", slices, 3))
        return OB_ERR_INVALID_ARGUMENT;
    /* apex[slices] | side ring[slices+1] | cap centre | cap ring[slices+1] */
    const uint32_t side = slices, centre = side + slices + 1, cap = centre + 1;
    ob_result r = mesh_alloc("cone", cap + slices + 1, 6 * slices, out);
    if (r != OB_OK) return r;

    /* The side normal tilts up by the half-angle: (h·radial + r·up) / slant. */
    const float slant = sqrtf(radius * radius + height * height);
    const float nr = height / slant, ny = radius / slant;
    for (uint32_t j = 0; j < slices; j++) {
        /* The apex normal of slice j is taken at its middle angle. */
        float mid = 2.0f * OB_PI_F * ((float)j + 0.5f) / (float)slices;
        float c = cosf(mid), s = sinf(mid);
        set_vertex(&out->vertices[j], 0, height, 0, nr * c, ny, -nr * s,
                   ((float)j + 0.5f) / (float)slices, 0.0f);
    }
    for (uint32_t j = 0; j <= slices; j++) {
        float c, s;
        ring_dir(j, slices, &c, &s);
        set_vertex(&out->vertices[side + j], radius * c, 0, -radius * s, nr * c, ny, -nr * s,
                   (float)j / (float)slices, 1.0f);
        set_vertex(&out->vertices[cap + j], radius * c, 0, -radius * s, 0, -1, 0,
                   0.5f + 0.5f * c, 0.5f + 0.5f * s);
    }
    set_vertex(&out->vertices[centre], 0, 0, 0, 0, -1, 0, 0.5f, 0.5f);

    uint32_t *idx = out->indices;
    for (uint32_t j = 0; j < slices; j++) idx = emit_tri(idx, j, side + j, side + j + 1);
    /* The cap faces -Y: the same ring walked the other way. */
    for (uint32_t j = 0; j < slices; j++) idx = emit_tri(idx, centre, cap + j + 1, cap + j);
    return finish(out);
}

ob_result ob_mesh_torus(float major_radius, float minor_radius, uint32_t major_segments,
                        uint32_t minor_segments, ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (!size_ok("torus", "major radius", major_radius) ||
        !size_ok("torus", "minor radius", minor_radius) ||
        !segments_ok("torus", "major segments", major_segments, 3) ||
        !segments_ok("torus", "minor segments", minor_segments, 3) ||
        !cells_ok("torus", "major segments", major_segments, "minor segments", minor_segments))
        return OB_ERR_INVALID_ARGUMENT;
    if (minor_radius >= major_radius) {
        OB_LOG_E(OB_MESH_LOG, "torus: minor radius %g must be below the major radius %g "
                 "(the surface would intersect itself)", (double)minor_radius, (double)major_radius);
        return OB_ERR_INVALID_ARGUMENT;
    }
    const uint32_t row = minor_segments + 1;
    ob_result r = mesh_alloc("torus", (major_segments + 1) * row,
                             6 * major_segments * minor_segments, out);
    if (r != OB_OK) return r;
    for (uint32_t i = 0; i <= major_segments; i++) {
        float ct, st;
        ring_dir(i, major_segments, &ct, &st);
        for (uint32_t j = 0; j <= minor_segments; j++) {
            float cp, sp;
            ring_dir(j, minor_segments, &cp, &sp);
            /* Tube normal: cos(phi)·radial + sin(phi)·up. */
            float n[3] = {cp * ct, sp, -cp * st};
            float d = major_radius + minor_radius * cp;
            set_vertex(&out->vertices[i * row + j], d * ct, minor_radius * sp, -d * st, n[0],
                       n[1], n[2], (float)i / (float)major_segments,
                       (float)j / (float)minor_segments);
        }
    }
    /* dP/dtheta × dP/dphi points out of the tube. */
    uint32_t *idx = out->indices;
    for (uint32_t i = 0; i < major_segments; i++)
        for (uint32_t j = 0; j < minor_segments; j++)
            idx = emit_quad(idx, i * row + j, (i + 1) * row + j, (i + 1) * row + j + 1,
                            i * row + j + 1);
    return finish(out);
}

ob_result ob_mesh_fullscreen_triangle(ob_mesh *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    ob_result r = mesh_alloc("fullscreen triangle", 3, 3, out);
    if (r != OB_OK) return r;
    set_vertex(&out->vertices[0], -1, -1, 0, 0, 0, 1, 0, 0);
    set_vertex(&out->vertices[1], 3, -1, 0, 0, 0, 1, 2, 0);
    set_vertex(&out->vertices[2], -1, 3, 0, 0, 0, 1, 0, 2);
    emit_tri(out->indices, 0, 1, 2);
    return finish(out);
}

/* ------------------------------------------------------------ deviation */

static void v3_sub(const float a[3], const float b[3], float out[3])
{
    for (int k = 0; k < 3; k++) out[k] = a[k] - b[k];
}

static float v3_dot(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Squared distance from p to the point o + t * e (a point on an edge). */
static float edge_point_d2(const float p[3], const float o[3], const float e[3], float t)
{
    float d[3];
    for (int k = 0; k < 3; k++) d[k] = p[k] - (o[k] + t * e[k]);
    return v3_dot(d, d);
}

/* Squared distance from p to triangle abc: the closest point by its Voronoi
 * region (Ericson, Real-Time Collision Detection, 5.1.5). */
static float point_triangle_d2(const float p[3], const float a[3], const float b[3],
                               const float c[3])
{
    float ab[3], ac[3], ap[3], q[3], d[3];
    v3_sub(b, a, ab);
    v3_sub(c, a, ac);
    v3_sub(p, a, ap);
    float d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return v3_dot(ap, ap);
    float bp[3];
    v3_sub(p, b, bp);
    float d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return v3_dot(bp, bp);
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return edge_point_d2(p, a, ab, d1 / (d1 - d3));
    float cp[3];
    v3_sub(p, c, cp);
    float d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return v3_dot(cp, cp);
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return edge_point_d2(p, a, ac, d2 / (d2 - d6));
    float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f) {
        float bc[3];
        v3_sub(c, b, bc);
        return edge_point_d2(p, b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    float den = 1.0f / (va + vb + vc), v = vb * den, w = vc * den;
    for (int k = 0; k < 3; k++) q[k] = a[k] + ab[k] * v + ac[k] * w;
    v3_sub(p, q, d);
    return v3_dot(d, d);
}

/* A uniform grid of cube cells over a mesh's triangles: cell c lists (CSR)
 * every triangle whose bounding box touches it, so the nearest triangle to
 * a point is found by searching rings of cells outward from the point's
 * instead of testing every triangle. */
typedef struct tri_grid {
    const ob_mesh *m;
    float lo[3], cell;
    uint32_t dim[3];
    uint32_t *start, *tris;   /* cell c's triangles: tris[start[c] .. start[c + 1]) */
    uint32_t *stamp;          /* per triangle: the last query that tested it */
    uint32_t serial;
} tri_grid;

/* Cells per axis at most: 128^3 cells (8 MiB of offsets) for the largest
 * meshes; about one triangle a cell on a surface for smaller ones. */
#define GRID_MAX_DIM 128u

static uint32_t grid_axis(const tri_grid *g, float v, int k)
{
    float f = (v - g->lo[k]) / g->cell;
    if (!(f > 0.0f)) return 0;
    uint32_t i = f >= (float)g->dim[k] ? g->dim[k] - 1 : (uint32_t)f;
    return i;
}

static size_t grid_cell(const tri_grid *g, uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * g->dim[1] + y) * g->dim[0] + x;
}

static void grid_release(tri_grid *g)
{
    ob_free(g->start);
    ob_free(g->tris);
    ob_free(g->stamp);
    memset(g, 0, sizeof *g);
}

static void tri_box(const ob_mesh *m, uint32_t t, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; k++) lo[k] = hi[k] = m->vertices[m->indices[3 * t]].position[k];
    for (int c = 1; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            float v = m->vertices[m->indices[3 * t + c]].position[k];
            lo[k] = fminf(lo[k], v);
            hi[k] = fmaxf(hi[k], v);
        }
}

static ob_result grid_build(tri_grid *g, const ob_mesh *m)
{
    memset(g, 0, sizeof *g);
    g->m = m;
    uint32_t tris = m->index_count / 3;
    float hi[3];
    for (int k = 0; k < 3; k++) g->lo[k] = hi[k] = m->vertices[m->indices[0]].position[k];
    for (uint32_t t = 0; t < tris; t++) {
        float a[3], b[3];
        tri_box(m, t, a, b);
        for (int k = 0; k < 3; k++) {
            g->lo[k] = fminf(g->lo[k], a[k]);
            hi[k] = fmaxf(hi[k], b[k]);
        }
    }
    float extent = fmaxf(fmaxf(hi[0] - g->lo[0], hi[1] - g->lo[1]), hi[2] - g->lo[2]);
    uint32_t per_axis = (uint32_t)ceil(sqrt((double)tris));
    per_axis = per_axis < 1 ? 1 : per_axis > GRID_MAX_DIM ? GRID_MAX_DIM : per_axis;
    g->cell = extent > 0.0f ? extent / (float)per_axis : 1.0f;
    size_t cells = 1;
    for (int k = 0; k < 3; k++) {
        double n = ceil((double)(hi[k] - g->lo[k]) / g->cell);
        g->dim[k] = n < 1.0 ? 1u : n > GRID_MAX_DIM ? GRID_MAX_DIM : (uint32_t)n;
        cells *= g->dim[k];
    }
    g->start = ob_calloc(cells + 1, sizeof *g->start);
    g->stamp = ob_calloc(tris, sizeof *g->stamp);
    if (!g->start || !g->stamp) goto no_memory;
    /* Count, then fill, each triangle into the cells its box touches. */
    uint64_t total = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (uint32_t t = 0; t < tris; t++) {
            float a[3], b[3];
            tri_box(m, t, a, b);
            uint32_t c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = grid_axis(g, a[k], k);
                c1[k] = grid_axis(g, b[k], k);
            }
            for (uint32_t z = c0[2]; z <= c1[2]; z++)
                for (uint32_t y = c0[1]; y <= c1[1]; y++)
                    for (uint32_t x = c0[0]; x <= c1[0]; x++) {
                        size_t c = grid_cell(g, x, y, z);
                        if (pass == 0) g->start[c + 1]++, total++;
                        else g->tris[g->start[c]++] = t;
                    }
        }
        if (pass == 0) {
            if (total > UINT32_MAX) goto no_memory;
            for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
            if (!(g->tris = ob_malloc(sizeof *g->tris * (total ? total : 1)))) goto no_memory;
        }
    }
    /* The fill moved each start to the next cell's: shift back. */
    for (size_t c = cells; c > 0; c--) g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    return OB_OK;
no_memory:
    grid_release(g);
    return OB_ERR_OUT_OF_HOST_MEMORY;
}

static float tri_d2(const tri_grid *g, const float p[3], uint32_t t)
{
    const ob_mesh *m = g->m;
    return point_triangle_d2(p, m->vertices[m->indices[3 * t]].position,
                             m->vertices[m->indices[3 * t + 1]].position,
                             m->vertices[m->indices[3 * t + 2]].position);
}

/* The squared distance from p to the nearest triangle: rings of cells
 * around p's (clamped into the grid), until no unvisited cell can hold a
 * nearer one. A cell r rings out lies at least (r - 1) cells from p on one
 * axis; one ring more is searched for the rounding of cell indices. */
static float nearest_d2(tri_grid *g, const float p[3])
{
    uint32_t c[3], reach = 0;
    for (int k = 0; k < 3; k++) {
        c[k] = grid_axis(g, p[k], k);
        uint32_t far = c[k] > g->dim[k] - 1 - c[k] ? c[k] : g->dim[k] - 1 - c[k];
        if (far > reach) reach = far;
    }
    uint32_t query = ++g->serial;
    float best = INFINITY;
    for (uint32_t r = 0; r <= reach; r++) {
        if (r >= 2) {
            float lb = (float)(r - 2) * g->cell;
            if (lb * lb > best) break;
        }
        uint32_t lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = c[k] >= r ? c[k] - r : 0;
            hi[k] = c[k] + r < g->dim[k] ? c[k] + r : g->dim[k] - 1;
        }
        for (uint32_t z = lo[2]; z <= hi[2]; z++)
            for (uint32_t y = lo[1]; y <= hi[1]; y++)
                for (uint32_t x = lo[0]; x <= hi[0]; x++) {
                    /* Only the ring's shell: the inside was searched. */
                    uint32_t dx = x > c[0] ? x - c[0] : c[0] - x, dy = y > c[1] ? y - c[1] : c[1] - y,
                             dz = z > c[2] ? z - c[2] : c[2] - z;
                    uint32_t cheb = dx > dy ? dx : dy;
                    if (dz > cheb) cheb = dz;
                    if (cheb != r) continue;
                    size_t cell = grid_cell(g, x, y, z);
                    for (uint32_t i = g->start[cell]; i < g->start[cell + 1]; i++) {
                        uint32_t t = g->tris[i];
                        if (g->stamp[t] == query) continue;
                        g->stamp[t] = query;
                        float d2 = tri_d2(g, p, t);
                        if (d2 < best) best = d2;
                    }
                }
    }
    return best;
}

/* The largest distance from a's sample points to b's surface, squared. */
static ob_result one_way_d2(const ob_mesh *a, const ob_mesh *b, float *out)
{
    tri_grid g;
    ob_result r = grid_build(&g, b);
    if (r != OB_OK) return r;
    float worst = 0.0f;
    for (uint32_t i = 0; i < a->vertex_count; i++)
        worst = fmaxf(worst, nearest_d2(&g, a->vertices[i].position));
    for (uint32_t t = 0; t + 2 < a->index_count; t += 3) {
        const float *p[3] = {a->vertices[a->indices[t]].position,
                             a->vertices[a->indices[t + 1]].position,
                             a->vertices[a->indices[t + 2]].position};
        float q[3];
        for (int e = 0; e < 3; e++) {
            for (int k = 0; k < 3; k++) q[k] = 0.5f * (p[e][k] + p[(e + 1) % 3][k]);
            worst = fmaxf(worst, nearest_d2(&g, q));
        }
        for (int k = 0; k < 3; k++) q[k] = (p[0][k] + p[1][k] + p[2][k]) / 3.0f;
        worst = fmaxf(worst, nearest_d2(&g, q));
    }
    grid_release(&g);
    *out = worst;
    return OB_OK;
}

ob_result ob_mesh_deviation(const ob_mesh *a, const ob_mesh *b, float *out)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    *out = 0.0f;
    ob_result r = ob_mesh_validate(a, "deviation: first mesh");
    if (r == OB_OK) r = ob_mesh_validate(b, "deviation: second mesh");
    if (r != OB_OK) return r;
    float ab = 0.0f, ba = 0.0f;
    if ((r = one_way_d2(a, b, &ab)) != OB_OK || (r = one_way_d2(b, a, &ba)) != OB_OK) {
        OB_LOG_E(OB_MESH_LOG, "deviation of meshes of %u and %u triangles: no memory for the "
                 "search grid", a->index_count / 3, b->index_count / 3);
        return r;
    }
    *out = sqrtf(fmaxf(ab, ba));
    return OB_OK;
}
