/* ob_mesh_simplify.c — coarser levels of detail from any triangle mesh:
 * half-edge collapses, cheapest first by the quadric error of the
 * original planes around them (Garland & Heckbert, "Surface
 * Simplification Using Quadric Error Metrics", 1997). */
#include "ob_mesh.h"

#include <math.h>
#include <stdlib.h>   /* qsort */
#include <string.h>

#define SIMPLIFY_LOG "geometry"

/* A symmetric 4x4 quadric: sum over planes (n, d) of (n.p + d)^2, kept as
 * its 10 distinct entries (a2 ab ac ad b2 bc bd c2 cd d2). */
typedef struct quadric {
    double q[10];
} quadric;

static void quadric_add_plane(quadric *Q, const double n[3], double d)
{
    double p[4] = {n[0], n[1], n[2], d};
    int k = 0;
    for (int i = 0; i < 4; i++)
        for (int j = i; j < 4; j++) Q->q[k++] += p[i] * p[j];
}

static void quadric_add(quadric *into, const quadric *a)
{
    for (int k = 0; k < 10; k++) into->q[k] += a->q[k];
}

/* (p, 1)^T Q (p, 1): the sum of the squared distances of p to the planes,
 * so its square root bounds p's distance from each of them. */
static double quadric_eval(const quadric *Q, const float p[3])
{
    const double *q = Q->q;
    double x = p[0], y = p[1], z = p[2];
    double e = q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y +
               2 * q[5] * y * z + 2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
    return e > 0.0 ? e : 0.0;
}

static void tri_normal(const float *a, const float *b, const float *c, double out[3])
{
    double u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = (double)b[k] - a[k];
        v[k] = (double)c[k] - a[k];
    }
    out[0] = u[1] * v[2] - u[2] * v[1];
    out[1] = u[2] * v[0] - u[0] * v[2];
    out[2] = u[0] * v[1] - u[1] * v[0];
}

static double dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A candidate collapse: vertex u onto vertex v (u's triangles take v). */
typedef struct collapse {
    double cost;
    uint32_t u, v;
} collapse;

static int compare_collapses(const void *pa, const void *pb)
{
    const collapse *a = pa, *b = pb;
    if (a->cost != b->cost) return a->cost < b->cost ? -1 : 1;
    if (a->u != b->u) return a->u < b->u ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

typedef struct position_key {
    float p[3];
    uint32_t vertex;
} position_key;

static int compare_positions(const void *pa, const void *pb)
{
    const position_key *a = pa, *b = pb;
    int c = memcmp(a->p, b->p, sizeof a->p);
    if (c) return c;
    return (a->vertex > b->vertex) - (a->vertex < b->vertex);
}

typedef struct simplifier {
    const ob_mesh *in;
    uint32_t *tris;       /* live triangles, 3 indices each */
    uint32_t tri_count;
    uint32_t *cls;        /* vertex -> position class (its first vertex at that position) */
    uint8_t *locked;      /* never moved: seams, borders, non-manifold edges */
    quadric *Q;           /* per class */
    /* Per pass: the triangles around each vertex (CSR). */
    uint32_t *adj_start, *adj;
    uint32_t *stamp;      /* per class, for neighbour counting */
    uint32_t stamp_serial;
    uint8_t *touched;     /* per vertex, this pass */
} simplifier;

/* Classes by exact position (a vertex seam: several vertices, one point). */
static ob_result classify(simplifier *s)
{
    uint32_t n = s->in->vertex_count;
    position_key *keys = ob_malloc(sizeof *keys * n);
    if (!keys) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < n; i++) {
        memcpy(keys[i].p, s->in->vertices[i].position, sizeof keys[i].p);
        for (int k = 0; k < 3; k++)
            if (keys[i].p[k] == 0.0f) keys[i].p[k] = 0.0f;   /* -0 and +0 one point */
        keys[i].vertex = i;
    }
    qsort(keys, n, sizeof *keys, compare_positions);
    for (uint32_t i = 0; i < n;) {
        uint32_t j = i + 1;
        while (j < n && !memcmp(keys[j].p, keys[i].p, sizeof keys[i].p)) j++;
        uint32_t first = keys[i].vertex;   /* lowest index: keys sort by vertex last */
        for (uint32_t k = i; k < j; k++) {
            s->cls[keys[k].vertex] = first;
            if (j - i > 1) s->locked[keys[k].vertex] = 1;
        }
        i = j;
    }
    ob_free(keys);
    return OB_OK;
}

typedef struct edge_key {
    uint32_t a, b;   /* classes, a < b */
} edge_key;

static int compare_edges(const void *pa, const void *pb)
{
    const edge_key *a = pa, *b = pb;
    if (a->a != b->a) return a->a < b->a ? -1 : 1;
    return (a->b > b->b) - (a->b < b->b);
}

/* Locks both ends of every edge that does not have exactly two triangles
 * (a border or a non-manifold edge): moving them would open or tear the
 * surface. Edges are compared by class, so a seam's two sides count as
 * one edge. */
static ob_result lock_borders(simplifier *s)
{
    uint32_t n = s->tri_count * 3;
    edge_key *e = ob_malloc(sizeof *e * (n ? n : 1));
    if (!e) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t t = 0; t < s->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = s->cls[s->tris[3 * t + k]], b = s->cls[s->tris[3 * t + (k + 1) % 3]];
            e[3 * t + k] = a < b ? (edge_key){a, b} : (edge_key){b, a};
        }
    qsort(e, n, sizeof *e, compare_edges);
    /* By class (a class is its first vertex's index), then each vertex. */
    uint8_t *by_class = ob_calloc(s->in->vertex_count, 1);
    if (!by_class) {
        ob_free(e);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    for (uint32_t i = 0; i < n;) {
        uint32_t j = i + 1;
        while (j < n && e[j].a == e[i].a && e[j].b == e[i].b) j++;
        if (j - i != 2) by_class[e[i].a] = by_class[e[i].b] = 1;
        i = j;
    }
    for (uint32_t v = 0; v < s->in->vertex_count; v++) s->locked[v] |= by_class[s->cls[v]];
    ob_free(by_class);
    ob_free(e);
    return OB_OK;
}

static ob_result build_adjacency(simplifier *s)
{
    uint32_t n = s->in->vertex_count;
    memset(s->adj_start, 0, sizeof *s->adj_start * (n + 1));
    for (uint32_t i = 0; i < 3 * s->tri_count; i++) s->adj_start[s->tris[i] + 1]++;
    for (uint32_t v = 0; v < n; v++) s->adj_start[v + 1] += s->adj_start[v];
    uint32_t *fill = ob_malloc(sizeof *fill * (n ? n : 1));
    if (!fill) return OB_ERR_OUT_OF_HOST_MEMORY;
    memcpy(fill, s->adj_start, sizeof *fill * n);
    for (uint32_t t = 0; t < s->tri_count; t++)
        for (int k = 0; k < 3; k++) s->adj[fill[s->tris[3 * t + k]]++] = t;
    ob_free(fill);
    return OB_OK;
}

static const float *pos(const simplifier *s, uint32_t v) { return s->in->vertices[v].position; }

/* The link condition, by class: u and v share exactly two neighbours (the
 * third corners of the edge's two triangles), else the collapse would fold
 * the surface onto itself. u is in no seam, so its triangles are all of
 * vertex u; v's are found through its neighbours' triangles too. */
static bool link_ok(simplifier *s, uint32_t u, uint32_t v)
{
    uint32_t cu = s->cls[u], cv = s->cls[v];
    uint32_t mark = ++s->stamp_serial;
    /* Classes around u. */
    for (uint32_t k = s->adj_start[u]; k < s->adj_start[u + 1]; k++) {
        const uint32_t *t = &s->tris[3 * s->adj[k]];
        for (int c = 0; c < 3; c++) s->stamp[s->cls[t[c]]] = mark;
    }
    /* Classes around v that are also around u: counted once each. */
    uint32_t shared = 0, count_mark = ++s->stamp_serial;
    for (uint32_t k = s->adj_start[v]; k < s->adj_start[v + 1]; k++) {
        const uint32_t *t = &s->tris[3 * s->adj[k]];
        for (int c = 0; c < 3; c++) {
            uint32_t w = s->cls[t[c]];
            if (w == cu || w == cv || s->stamp[w] != mark) continue;
            s->stamp[w] = count_mark;
            shared++;
        }
    }
    return shared == 2;
}

/* No triangle of u that survives may turn over or collapse to a sliver. */
static bool flips(const simplifier *s, uint32_t u, uint32_t v)
{
    uint32_t cv = s->cls[v];
    for (uint32_t k = s->adj_start[u]; k < s->adj_start[u + 1]; k++) {
        const uint32_t *t = &s->tris[3 * s->adj[k]];
        bool has_v = false;
        for (int c = 0; c < 3; c++) has_v |= s->cls[t[c]] == cv;
        if (has_v) continue;   /* removed by the collapse */
        const float *p[3], *q[3];
        for (int c = 0; c < 3; c++) {
            p[c] = pos(s, t[c]);
            q[c] = t[c] == u ? pos(s, v) : p[c];
        }
        double n0[3], n1[3];
        tri_normal(p[0], p[1], p[2], n0);
        tri_normal(q[0], q[1], q[2], n1);
        double d = dot3d(n0, n1), l0 = dot3d(n0, n0), l1 = dot3d(n1, n1);
        /* Turned by more than about 80 degrees, or nearly no area left. */
        if (d <= 0.17 * sqrt(l0 * l1) || l1 <= 1e-12 * l0) return true;
        /* Nor may it face across its corners' shading normals (by more
         * than about 75 degrees): turns that each pass this test one
         * collapse at a time add up, and fold the surface along a seam. */
        for (int c = 0; c < 3; c++) {
            const float *nv = s->in->vertices[t[c] == u ? v : t[c]].normal;
            double N[3] = {nv[0], nv[1], nv[2]}, lN = dot3d(N, N);
            if (lN > 0.0 && dot3d(n1, N) < 0.26 * sqrt(l1 * lN)) return true;
        }
    }
    return false;
}

/* One pass: candidate collapses cheapest first, each vertex moved or
 * moved onto at most once. Returns the collapses made. */
static uint32_t pass(simplifier *s, uint32_t target_tris, double max_cost, double *worst,
                     collapse *cand, ob_result *res)
{
    *res = build_adjacency(s);
    if (*res != OB_OK) return 0;
    uint32_t n = 0;
    for (uint32_t t = 0; t < s->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = s->tris[3 * t + k], b = s->tris[3 * t + (k + 1) % 3];
            for (int dir = 0; dir < 2; dir++) {
                uint32_t u = dir ? b : a, v = dir ? a : b;
                if (s->locked[u]) continue;
                quadric q = s->Q[s->cls[u]];
                quadric_add(&q, &s->Q[s->cls[v]]);
                cand[n++] = (collapse){quadric_eval(&q, pos(s, v)), u, v};
            }
        }
    qsort(cand, n, sizeof *cand, compare_collapses);
    memset(s->touched, 0, s->in->vertex_count);
    uint32_t made = 0, live = s->tri_count;
    for (uint32_t i = 0; i < n && live > target_tris; i++) {
        const collapse *c = &cand[i];
        if (c->cost > max_cost) break;
        if (s->touched[c->u] || s->touched[c->v]) continue;
        if (!link_ok(s, c->u, c->v) || flips(s, c->u, c->v)) continue;
        uint32_t cu = s->cls[c->u], cv = s->cls[c->v];
        for (uint32_t k = s->adj_start[c->u]; k < s->adj_start[c->u + 1]; k++) {
            uint32_t *t = &s->tris[3 * s->adj[k]];
            bool has_v = false;
            for (int j = 0; j < 3; j++) {
                has_v |= s->cls[t[j]] == cv;
                s->touched[t[j]] = 1;
            }
            if (has_v) {
                t[0] = t[1] = t[2] = UINT32_MAX;   /* removed */
                live--;
            } else {
                for (int j = 0; j < 3; j++)
                    if (t[j] == c->u) t[j] = c->v;
            }
        }
        quadric_add(&s->Q[cv], &s->Q[cu]);
        s->touched[c->u] = s->touched[c->v] = 1;
        if (c->cost > *worst) *worst = c->cost;
        made++;
    }
    /* Drop the removed triangles, keeping the others' order. */
    uint32_t w = 0;
    for (uint32_t t = 0; t < s->tri_count; t++) {
        if (s->tris[3 * t] == UINT32_MAX) continue;
        memmove(&s->tris[3 * w], &s->tris[3 * t], 3 * sizeof *s->tris);
        w++;
    }
    s->tri_count = w;
    return made;
}

/* The output: the vertices the triangles still use, in their input order,
 * with every attribute array the input has. */
static ob_result emit(const simplifier *s, ob_mesh *out)
{
    const ob_mesh *in = s->in;
    uint32_t *remap = ob_malloc(sizeof *remap * in->vertex_count);
    if (!remap) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t v = 0; v < in->vertex_count; v++) remap[v] = UINT32_MAX;
    for (uint32_t i = 0; i < 3 * s->tri_count; i++) remap[s->tris[i]] = 0;
    uint32_t used = 0;
    for (uint32_t v = 0; v < in->vertex_count; v++)
        if (remap[v] == 0) remap[v] = used++;
    ob_result r = OB_OK;
    out->vertices = ob_malloc(sizeof *out->vertices * (used ? used : 1));
    out->indices = ob_malloc(sizeof *out->indices * (s->tri_count ? 3 * s->tri_count : 1));
    if (in->tangents) out->tangents = ob_malloc(sizeof *out->tangents * (used ? used : 1));
    if (in->colors) out->colors = ob_malloc(sizeof *out->colors * (used ? used : 1));
    if (in->uv1) out->uv1 = ob_malloc(sizeof *out->uv1 * (used ? used : 1));
    if (!out->vertices || !out->indices || (in->tangents && !out->tangents) ||
        (in->colors && !out->colors) || (in->uv1 && !out->uv1)) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    for (uint32_t v = 0; v < in->vertex_count; v++) {
        if (remap[v] == UINT32_MAX) continue;
        uint32_t o = remap[v];
        out->vertices[o] = in->vertices[v];
        if (in->tangents) memcpy(out->tangents[o], in->tangents[v], sizeof out->tangents[o]);
        if (in->colors) memcpy(out->colors[o], in->colors[v], sizeof out->colors[o]);
        if (in->uv1) memcpy(out->uv1[o], in->uv1[v], sizeof out->uv1[o]);
    }
    for (uint32_t i = 0; i < 3 * s->tri_count; i++) out->indices[i] = remap[s->tris[i]];
    out->vertex_count = used;
    out->index_count = 3 * s->tri_count;
    r = ob_mesh_compute_bounds(out);
done:
    ob_free(remap);
    if (r != OB_OK) ob_mesh_release(out);
    return r;
}

ob_result ob_mesh_simplify(const ob_mesh *in, uint32_t target_index_count, float max_error,
                           ob_mesh *out, float *out_error)
{
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    if (out_error) *out_error = 0.0f;
    if (!(max_error >= 0.0f)) {
        OB_LOG_E(SIMPLIFY_LOG, "simplify: max_error %g must be >= 0 (INFINITY: no bound)",
                 (double)max_error);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_result r = ob_mesh_validate(in, "simplify");
    if (r != OB_OK) return r;
    uint32_t n = in->vertex_count, tris = in->index_count / 3;
    simplifier s = {.in = in, .tri_count = tris};
    s.tris = ob_malloc(sizeof *s.tris * 3 * tris);
    s.cls = ob_malloc(sizeof *s.cls * n);
    s.locked = ob_calloc(n, 1);
    s.Q = ob_calloc(n, sizeof *s.Q);
    s.adj_start = ob_malloc(sizeof *s.adj_start * (n + 1));
    s.adj = ob_malloc(sizeof *s.adj * 3 * tris);
    s.stamp = ob_calloc(n, sizeof *s.stamp);
    s.touched = ob_malloc(n);
    collapse *cand = ob_malloc(sizeof *cand * 6 * tris);
    if (!s.tris || !s.cls || !s.locked || !s.Q || !s.adj_start || !s.adj || !s.stamp ||
        !s.touched || !cand) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    memcpy(s.tris, in->indices, sizeof *s.tris * 3 * tris);
    if ((r = classify(&s)) != OB_OK) goto done;
    /* Triangles with two corners at one point draw nothing: dropped, so no
     * edge of zero length is ever a candidate (it would collapse a vertex
     * onto itself and take all its triangles). */
    uint32_t kept = 0;
    for (uint32_t t = 0; t < tris; t++) {
        const uint32_t *v = &s.tris[3 * t];
        uint32_t a = s.cls[v[0]], b = s.cls[v[1]], c = s.cls[v[2]];
        if (a == b || b == c || a == c) continue;
        memmove(&s.tris[3 * kept++], v, 3 * sizeof *v);
    }
    s.tri_count = kept;
    if (kept == 0) {
        OB_LOG_E(SIMPLIFY_LOG, "simplify: every one of the %u triangles has two corners at one "
                 "point; nothing to simplify", tris);
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    if ((r = lock_borders(&s)) != OB_OK) goto done;
    /* Each class's quadric: the planes of the triangles around it, each
     * once (unweighted, so the error bounds a distance); degenerate
     * triangles have no plane. */
    for (uint32_t t = 0; t < s.tri_count; t++) {
        const uint32_t *v = &s.tris[3 * t];
        double nrm[3];
        tri_normal(pos(&s, v[0]), pos(&s, v[1]), pos(&s, v[2]), nrm);
        double len = sqrt(dot3d(nrm, nrm));
        if (!(len > 0.0)) continue;
        for (int k = 0; k < 3; k++) nrm[k] /= len;
        const float *p = pos(&s, v[0]);
        double d = -(nrm[0] * p[0] + nrm[1] * p[1] + nrm[2] * p[2]);
        for (int k = 0; k < 3; k++) quadric_add_plane(&s.Q[s.cls[v[k]]], nrm, d);
    }
    uint32_t target_tris = target_index_count / 3;
    double max_cost = isinf(max_error) ? INFINITY : (double)max_error * max_error, worst = 0.0;
    while (s.tri_count > target_tris) {
        uint32_t made = pass(&s, target_tris, max_cost, &worst, cand, &r);
        if (r != OB_OK) goto done;
        if (made == 0) break;
    }
    r = emit(&s, out);
    if (r == OB_OK && out_error) *out_error = (float)sqrt(worst);
done:
    if (r == OB_ERR_OUT_OF_HOST_MEMORY)
        OB_LOG_E(SIMPLIFY_LOG, "simplify: no memory for a mesh of %u vertices, %u triangles", n,
                 tris);
    ob_free(s.tris);
    ob_free(s.cls);
    ob_free(s.locked);
    ob_free(s.Q);
    ob_free(s.adj_start);
    ob_free(s.adj);
    ob_free(s.stamp);
    ob_free(s.touched);
    ob_free(cand);
    return r;
}
