/* ob_model.c — model files through assimp's C API, checked before use.
 *
 * Order matters: the file is parsed with no post-processing, the raw meshes
 * are checked (face indices against the vertex count, finite attributes,
 * at least one polygon), and only then are triangulation, normal generation
 * and vertex joining applied. Those steps index vertices through the faces
 * and would read out of bounds on a broken file before we could reject it.
 *
 * Two facts about Debian's libassimp 5.2 shape the checks (both seen with
 * the assimp-testmodels files):
 * - it is built with ai_assert enabled: a face with no indices, or a mesh
 *   whose mPrimitiveTypes claims polygons it does not have, aborts the
 *   process inside aiProcess_Triangulate;
 * - if a post-processing step throws (SortByPType on a mesh without faces,
 *   or removing every mesh when AI_CONFIG_PP_SBP_REMOVE is set),
 *   aiApplyPostProcessing releases a scene that the step already deleted: a
 *   use-after-free. So we never ask assimp to remove meshes (points and
 *   lines are split off by SortByPType and skipped here), a file without
 *   polygons is rejected beforehand, and faceless meshes get a type. Only an
 *   allocation failure inside a step can still take that path.
 * A third, found by fuzz/fuzz_model.c: its PLY reader hangs on a truncated
 * header and reads out of bounds when the header or the data lie, all
 * inside aiImportFile. PLY files are checked against their own header
 * first (ob_model_ply.c).
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_mesh.h"
#include "ob_model_internal.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>


/* assimp's C API stores the text of the last failed import in one
 * process-wide std::string (written at the end of every failed
 * aiImportFile* call, read by aiGetErrorString). Concurrent failed imports
 * would race on it, so the parse step and the copy of its error text hold
 * this lock. Post-processing, checks and merging run unlocked: they use only
 * the per-import aiScene. assimp keeps no other process state as long as no
 * log stream is attached (we attach none, so it stays quiet). Listed with
 * the rest of Obelisk's process-wide state in ob_core.h. */
static pthread_mutex_t ob_assimp_parse_lock = PTHREAD_MUTEX_INITIALIZER;

typedef struct model_ctx {
    ob_model_check chk;     /* path, BAD_MODEL problems seen (first few are logged) */
    uint64_t vertex_total;  /* sizing pass */
    uint64_t index_total;
    uint32_t instances;
    uint32_t fixed_normals;
    ob_mesh *out;           /* filling pass (NULL while sizing) */
    uint32_t vertex_at, index_at;
} model_ctx;

void ob_model_vbad(ob_model_check *c, const char *fmt, va_list ap)
{
    if (c->problems++ >= OB_MODEL_LOG_MAX) return;
    char text[384];
    vsnprintf(text, sizeof text, fmt, ap);
    OB_LOG_E(OB_MODEL_LOG, "%s: %s", c->path, text);
}

void ob_model_bad(ob_model_check *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    ob_model_vbad(c, fmt, ap);
    va_end(ap);
}

static void bad(model_ctx *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void bad(model_ctx *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    ob_model_vbad(&c->chk, fmt, ap);
    va_end(ap);
}

void ob_model_report_more(const ob_model_check *c)
{
    if (c->problems > OB_MODEL_LOG_MAX)
        OB_LOG_E(OB_MODEL_LOG, "%s: %u more problems not shown (%u in all)", c->path,
                 c->problems - OB_MODEL_LOG_MAX, c->problems);
}

void ob_model_sanitize_text(char *s, size_t length)
{
    for (size_t i = 0; i < length && s[i];) {
        unsigned char c = (unsigned char)s[i];
        size_t n = c < 0x80 ? 1 : (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
        uint32_t cp = n == 1 ? c : n == 2 ? c & 0x1Fu : n == 3 ? c & 0x0Fu : c & 0x07u;
        bool ok = n > 0 && i + n <= length;
        for (size_t k = 1; ok && k < n; k++) {
            ok = ((unsigned char)s[i + k] & 0xC0) == 0x80;
            cp = cp << 6 | ((unsigned char)s[i + k] & 0x3Fu);
        }
        static const uint32_t min_cp[5] = {0, 0, 0x80, 0x800, 0x10000};
        ok = ok && cp >= min_cp[n] && cp <= 0x10FFFF && !(cp >= 0xD800 && cp <= 0xDFFF) && cp >= 0x20 &&
             !(cp >= 0x7F && cp <= 0x9F);
        if (!ok) {
            s[i++] = '?';
            continue;
        }
        i += n;
    }
}

static const char *mesh_name(const struct aiMesh *m)
{
    return m->mName.length ? m->mName.data : "(unnamed)";
}

ob_result ob_model_check_readable(const char *path)
{
    char why[256];
    ob_result r;
    int fd = ob_file_open_regular(path, "model file", OB_MODEL_MAX_FILE_BYTES, NULL, why, sizeof why, &r);
    if (fd < 0) {
        OB_LOG_E(OB_MODEL_LOG, "%s: cannot open model file: %s", path, why);
        return r;
    }
    close(fd);
    return OB_OK;
}

bool ob_model_v3_finite(const struct aiVector3D *v)
{
    return isfinite(v->x) && isfinite(v->y) && isfinite(v->z);
}

/* The raw file data, before any assimp step touches it. */
static ob_result check_raw_mesh(ob_model_check *c, uint32_t mi, const struct aiMesh *m,
                                uint32_t *out_polygons)
{
    uint32_t before = c->problems;
    /* Names are printed (logs, the lean report): terminal escapes and
     * invalid UTF-8 in them become '?'. */
    ob_model_sanitize_text(((struct aiMesh *)m)->mName.data, m->mName.length);
    if (m->mNumVertices && !m->mVertices)
        ob_model_bad(c, "mesh %u '%s': %u vertices but no positions", mi, mesh_name(m), m->mNumVertices);
    if (m->mNumFaces && !m->mFaces)
        ob_model_bad(c, "mesh %u '%s': %u faces but no face array", mi, mesh_name(m), m->mNumFaces);
    if (c->problems != before) return OB_ERR_BAD_MODEL;

    unsigned types = 0;
    for (uint32_t f = 0; f < m->mNumFaces; f++) {
        const struct aiFace *face = &m->mFaces[f];
        if (!face->mNumIndices || !face->mIndices) {
            ob_model_bad(c, "mesh %u '%s': face %u has no indices", mi, mesh_name(m), f);
            continue;
        }
        types |= face->mNumIndices == 1   ? aiPrimitiveType_POINT
                 : face->mNumIndices == 2 ? aiPrimitiveType_LINE
                 : face->mNumIndices == 3 ? aiPrimitiveType_TRIANGLE
                                          : aiPrimitiveType_POLYGON;
        *out_polygons += face->mNumIndices >= 3;
        for (uint32_t k = 0; k < face->mNumIndices; k++) {
            if (face->mIndices[k] >= m->mNumVertices)
                ob_model_bad(c, "mesh %u '%s': face %u index %u = %u out of range (%u vertices)", mi,
                    mesh_name(m), f, k, face->mIndices[k], m->mNumVertices);
        }
    }
    /* Faces first: a file claiming a billion vertices with broken faces is
     * rejected without walking the vertex array. */
    if (c->problems != before) return OB_ERR_BAD_MODEL;

    for (uint32_t v = 0; v < m->mNumVertices; v++) {
        const struct aiVector3D *p = &m->mVertices[v];
        if (!ob_model_v3_finite(p))
            ob_model_bad(c, "mesh %u '%s': vertex %u position is not finite (%g, %g, %g)", mi,
                mesh_name(m), v, (double)p->x, (double)p->y, (double)p->z);
        if (m->mNormals && !ob_model_v3_finite(&m->mNormals[v])) {
            const struct aiVector3D *n = &m->mNormals[v];
            ob_model_bad(c, "mesh %u '%s': vertex %u normal is not finite (%g, %g, %g)", mi, mesh_name(m),
                v, (double)n->x, (double)n->y, (double)n->z);
        }
        if (m->mTextureCoords[0]) {
            const struct aiVector3D *t = &m->mTextureCoords[0][v];
            if (!isfinite(t->x) || !isfinite(t->y))
                ob_model_bad(c, "mesh %u '%s': vertex %u uv is not finite (%g, %g)", mi, mesh_name(m), v,
                    (double)t->x, (double)t->y);
        }
    }
    if (c->problems != before) return OB_ERR_BAD_MODEL;
    /* Triangulate trusts mPrimitiveTypes (and asserts on a wrong one); make
     * it describe the faces that are really there. This is assimp's own
     * bookkeeping, the file's data is unchanged. A mesh without faces (an
     * empty STL solid) would have no type, which SortByPType throws on
     * (see the top of the file); call it points, the type no later step
     * touches, and it contributes nothing. */
    ((struct aiMesh *)m)->mPrimitiveTypes = types ? types : aiPrimitiveType_POINT;
    return OB_OK;
}

static ob_result check_raw_nodes(ob_model_check *c, const struct aiScene *s, const struct aiNode *n,
                                 uint32_t depth)
{
    if (depth > OB_MODEL_MAX_NODE_DEPTH) {
        ob_model_bad(c, "node hierarchy deeper than %u levels", OB_MODEL_MAX_NODE_DEPTH);
        return OB_ERR_BAD_MODEL;
    }
    ob_model_sanitize_text(((struct aiNode *)n)->mName.data, n->mName.length);
    for (uint32_t k = 0; k < n->mNumMeshes; k++) {
        if (!n->mMeshes || n->mMeshes[k] >= s->mNumMeshes) {
            ob_model_bad(c, "node '%s' refers to mesh %u of %u", n->mName.data,
                n->mMeshes ? n->mMeshes[k] : 0u, s->mNumMeshes);
            return OB_ERR_BAD_MODEL;
        }
    }
    for (uint32_t k = 0; k < n->mNumChildren; k++) {
        if (!n->mChildren || !n->mChildren[k]) {
            ob_model_bad(c, "node '%s' has a missing child %u", n->mName.data, k);
            return OB_ERR_BAD_MODEL;
        }
        ob_result r = check_raw_nodes(c, s, n->mChildren[k], depth + 1);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

ob_result ob_model_check_raw_scene(ob_model_check *c, const struct aiScene *s)
{
    if (!s->mNumMeshes || !s->mMeshes) {
        ob_model_bad(c, "contains no meshes");
        return OB_ERR_BAD_MODEL;
    }
    if (!s->mRootNode) {
        ob_model_bad(c, "has no root node");
        return OB_ERR_BAD_MODEL;
    }
    ob_result first = OB_OK;
    uint32_t polygons = 0;
    for (uint32_t mi = 0; mi < s->mNumMeshes; mi++) {
        ob_result r = OB_ERR_BAD_MODEL;
        if (s->mMeshes[mi])
            r = check_raw_mesh(c, mi, s->mMeshes[mi], &polygons);
        else
            ob_model_bad(c, "mesh %u is missing", mi);
        if (first == OB_OK) first = r;
    }
    if (first != OB_OK) return first;
    if (polygons == 0) {
        ob_model_bad(c, "contains no triangles (%u meshes of points, lines or nothing)", s->mNumMeshes);
        return OB_ERR_BAD_MODEL;
    }
    return check_raw_nodes(c, s, s->mRootNode, 0);
}

/* ------------------------------------------------------------- merging */

/* Column-vector convention as in assimp: p' = M p, translation in m[.][3]. */
typedef struct xform { double m[4][4]; } xform;

static xform xform_from_ai(const struct aiMatrix4x4 *a)
{
    xform x = {{{a->a1, a->a2, a->a3, a->a4},
                {a->b1, a->b2, a->b3, a->b4},
                {a->c1, a->c2, a->c3, a->c4},
                {a->d1, a->d2, a->d3, a->d4}}};
    return x;
}

static xform xform_mul(const xform *a, const xform *b)
{
    xform r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++) s += a->m[i][k] * b->m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

/* Cofactors of the upper 3x3: (M^-1)^T = cof / det, and normals are
 * renormalized anyway, so cof · sign(det) transforms them. */
static void cofactor3(const xform *x, double cof[3][3], double *out_det)
{
    const double(*m)[4] = x->m;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            cof[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
        }
    *out_det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
}

static uint32_t triangle_faces(const struct aiMesh *m)
{
    uint32_t n = 0;
    for (uint32_t f = 0; f < m->mNumFaces; f++) n += m->mFaces[f].mNumIndices == 3;
    return n;
}

static ob_result place_mesh(model_ctx *c, uint32_t mi, const struct aiMesh *m, const xform *x,
                            const char *node)
{
    uint32_t tris = triangle_faces(m);
    if (tris == 0) return OB_OK;
    if (!c->out) {
        c->vertex_total += m->mNumVertices;
        c->index_total += 3ull * tris;
        return OB_OK;
    }
    double cof[3][3], det;
    cofactor3(x, cof, &det);
    if (!isfinite(det) || fabs(det) < 1e-30) {
        bad(c, "node '%s' places mesh %u '%s' with a singular transform (determinant %g)", node,
            mi, mesh_name(m), det);
        return OB_ERR_BAD_MODEL;
    }
    const double sign = det < 0.0 ? -1.0 : 1.0;
    const uint32_t base = c->vertex_at;
    for (uint32_t v = 0; v < m->mNumVertices; v++) {
        ob_vertex *dst = &c->out->vertices[base + v];
        const struct aiVector3D *p = &m->mVertices[v];
        const double pin[3] = {p->x, p->y, p->z};
        for (int i = 0; i < 3; i++)
            dst->position[i] = (float)(x->m[i][0] * pin[0] + x->m[i][1] * pin[1] +
                                       x->m[i][2] * pin[2] + x->m[i][3]);
        double n[3] = {0, 0, 0}, len = 0.0;
        if (m->mNormals) {
            const struct aiVector3D *an = &m->mNormals[v];
            const double nin[3] = {an->x, an->y, an->z};
            for (int i = 0; i < 3; i++) {
                n[i] = sign * (cof[i][0] * nin[0] + cof[i][1] * nin[1] + cof[i][2] * nin[2]);
                len += n[i] * n[i];
            }
            len = sqrt(len);
        }
        if (len > 1e-30 && isfinite(len)) {
            for (int i = 0; i < 3; i++) dst->normal[i] = (float)(n[i] / len);
        } else {
            /* A zero normal in the file, or one generated from degenerate
             * triangles only: the same fallback as ob_mesh_generate_normals. */
            dst->normal[0] = 0.0f;
            dst->normal[1] = 1.0f;
            dst->normal[2] = 0.0f;
            c->fixed_normals++;
        }
        if (m->mTextureCoords[0]) {
            dst->uv[0] = m->mTextureCoords[0][v].x;
            dst->uv[1] = m->mTextureCoords[0][v].y;
        }
        if (!isfinite(dst->position[0]) || !isfinite(dst->position[1]) ||
            !isfinite(dst->position[2])) {
            bad(c, "node '%s' moves vertex %u of mesh %u '%s' out of float range", node, v, mi,
                mesh_name(m));
            return OB_ERR_BAD_MODEL;
        }
    }
    uint32_t *idx = &c->out->indices[c->index_at];
    for (uint32_t f = 0; f < m->mNumFaces; f++) {
        const struct aiFace *face = &m->mFaces[f];
        if (face->mNumIndices != 3) continue;
        for (uint32_t k = 0; k < 3; k++) {
            if (face->mIndices[k] >= m->mNumVertices) {
                bad(c, "mesh %u '%s': face %u index %u = %u out of range (%u vertices) after "
                    "post-processing", mi, mesh_name(m), f, k, face->mIndices[k], m->mNumVertices);
                return OB_ERR_BAD_MODEL;
            }
        }
        /* A mirroring transform turns counter-clockwise faces clockwise. */
        idx[0] = base + face->mIndices[0];
        idx[1] = base + face->mIndices[det < 0.0 ? 2 : 1];
        idx[2] = base + face->mIndices[det < 0.0 ? 1 : 2];
        idx += 3;
    }
    c->vertex_at += m->mNumVertices;
    c->index_at += 3 * tris;
    c->instances++;
    return OB_OK;
}

static ob_result walk(model_ctx *c, const struct aiScene *s, const struct aiNode *n,
                      const xform *parent, uint32_t depth)
{
    if (depth > OB_MODEL_MAX_NODE_DEPTH) {
        bad(c, "node hierarchy deeper than %u levels", OB_MODEL_MAX_NODE_DEPTH);
        return OB_ERR_BAD_MODEL;
    }
    xform local = xform_from_ai(&n->mTransformation);
    xform world = xform_mul(parent, &local);
    const char *name = n->mName.length ? n->mName.data : "(unnamed)";
    for (uint32_t k = 0; k < n->mNumMeshes; k++) {
        uint32_t mi = n->mMeshes[k];
        if (mi >= s->mNumMeshes || !s->mMeshes[mi]) {
            bad(c, "node '%s' refers to mesh %u of %u after post-processing", name, mi,
                s->mNumMeshes);
            return OB_ERR_BAD_MODEL;
        }
        ob_result r = place_mesh(c, mi, s->mMeshes[mi], &world, name);
        if (r != OB_OK) return r;
    }
    for (uint32_t k = 0; k < n->mNumChildren; k++) {
        ob_result r = walk(c, s, n->mChildren[k], &world, depth + 1);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

static ob_result merge_scene(model_ctx *c, const struct aiScene *s, ob_mesh *out)
{
    static const xform identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    if (!s->mRootNode) {
        bad(c, "has no root node after post-processing");
        return OB_ERR_BAD_MODEL;
    }
    ob_result r = walk(c, s, s->mRootNode, &identity, 0);   /* sizing pass */
    if (r != OB_OK) return r;
    if (c->index_total == 0) {
        bad(c, "contains no triangles (%u meshes: only points, lines or empty meshes)",
            s->mNumMeshes);
        return OB_ERR_BAD_MODEL;
    }
    if (c->vertex_total > UINT32_MAX || c->index_total > UINT32_MAX) {
        OB_LOG_E(OB_MODEL_LOG, "%s: %llu vertices and %llu indices exceed the 32-bit index range",
                 c->chk.path, (unsigned long long)c->vertex_total, (unsigned long long)c->index_total);
        return OB_ERR_LIMIT;
    }
    out->vertices = ob_calloc((size_t)c->vertex_total, sizeof(ob_vertex));
    out->indices = ob_calloc((size_t)c->index_total, sizeof(uint32_t));
    if (!out->vertices || !out->indices) {
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory for %llu vertices and %llu indices", c->chk.path,
                 (unsigned long long)c->vertex_total, (unsigned long long)c->index_total);
        ob_mesh_release(out);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    out->vertex_count = (uint32_t)c->vertex_total;
    out->index_count = (uint32_t)c->index_total;
    c->out = out;
    c->instances = 0;
    return walk(c, s, s->mRootNode, &identity, 0);          /* filling pass */
}

/* ---------------------------------------------------------------- load */

const struct aiScene *ob_model_parse(const char *path, ob_model_io *io, char *err, size_t err_size)
{
    struct aiFileIO fio = ob_model_io_assimp(io);
    pthread_mutex_lock(&ob_assimp_parse_lock);
    const struct aiScene *s = aiImportFileEx(path, 0, &fio);
    if (!s) {
        const char *text = aiGetErrorString();
        snprintf(err, err_size, "%s", text && *text ? text : "unknown error");
    }
    pthread_mutex_unlock(&ob_assimp_parse_lock);
    return s;
}

bool ob_model_mesh_has_area(const ob_mesh *m)
{
    for (uint32_t t = 0; t < m->index_count; t += 3) {
        const float *a = m->vertices[m->indices[t]].position;
        const float *b = m->vertices[m->indices[t + 1]].position;
        const float *c = m->vertices[m->indices[t + 2]].position;
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)b[k] - a[k];
            e2[k] = (double)c[k] - a[k];
        }
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
               z = e1[0] * e2[1] - e1[1] * e2[0];
        if (x * x + y * y + z * z > 0.0) return true;
    }
    return false;
}

ob_result ob_model_import(ob_model_check *c, const ob_model_desc *desc, bool refuse_required,
                          const struct aiScene **out_scene)
{
    *out_scene = NULL;
    memset(c->io, 0, sizeof *c->io);
    const char *path = c->path;
    ob_result r = ob_model_check_readable(path);
    if (r == OB_OK) r = ob_model_io_init(c->io, path, desc->allow_any_folder);
    if (r == OB_OK) r = ob_model_ply_precheck(path);
    if (r == OB_OK) r = ob_model_gltf_precheck(path, c->io, refuse_required);
    if (r != OB_OK) return r;
    char err[512];
    const struct aiScene *scene = ob_model_parse(path, c->io, err, sizeof err);
    if (scene && c->io->refused != OB_OK) {
        /* assimp went on without a file we refused (an OBJ's .mtl): the
         * refusal, logged already, is the model's. */
        aiReleaseImport(scene);
        return c->io->refused;
    }
    if (!scene) {
        if (c->io->refused != OB_OK) return c->io->refused;   /* logged, naming the file */
        /* assimp's words for two common glTF faults say nothing of the cause. */
        const char *hint = "";
        if (c->io->gltf && strstr(err, "No suitable reader found"))
            hint = " (its glTF JSON does not parse: a NaN or Infinity literal, a file cut short?)";
        else if (c->io->gltf && strstr(err, "has no faces"))
            hint = " (assimp drops triangles whose indices are past the vertex count: check the "
                   "index accessor's values against POSITION's count)";
        OB_LOG_E(OB_MODEL_LOG, "%s: assimp could not read the model: %s%s", path, err, hint);
        return OB_ERR_PARSE;
    }
    r = ob_model_check_raw_scene(c, scene);
    if (r != OB_OK) {
        ob_model_report_more(c);
        aiReleaseImport(scene);
        return r;
    }
    unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_GenSmoothNormals |
                     aiProcess_JoinIdenticalVertices | (desc->flip_uv ? aiProcess_FlipUVs : 0u);
    scene = aiApplyPostProcessing(scene, flags);
    if (!scene) {   /* assimp has released the scene already */
        OB_LOG_E(OB_MODEL_LOG, "%s: assimp post-processing failed", path);
        return OB_ERR_PARSE;
    }
    *out_scene = scene;
    return OB_OK;
}

ob_result ob_model_load_mesh(const ob_model_desc *desc, ob_mesh *out, ob_model_info *out_info)
{
    if (out) memset(out, 0, sizeof *out);
    if (out_info) memset(out_info, 0, sizeof *out_info);
    if (!desc || !desc->path || !desc->path[0] || !out) {
        OB_LOG_E(OB_MODEL_LOG, "ob_model_load_mesh: %s", !desc ? "NULL desc"
                 : !out ? "NULL out mesh" : "no path given");
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_model_io io;
    model_ctx c = {.chk = {.path = desc->path, .io = &io}};
    const char *path = desc->path;
    const struct aiScene *scene;
    ob_result r = ob_model_import(&c.chk, desc, false, &scene);
    if (r != OB_OK) {
        ob_model_io_release(&io);
        return r;
    }
    r = merge_scene(&c, scene, out);
    if (r != OB_OK) goto fail_release_out;
    if (ob_mesh_validate(out, path) != OB_OK || ob_mesh_compute_bounds(out) != OB_OK) {
        r = OB_ERR_BAD_MODEL;
        goto fail_release_out;
    }
    if (!ob_model_mesh_has_area(out)) {
        bad(&c, "all %u triangles have zero area", out->index_count / 3);
        r = OB_ERR_BAD_MODEL;
        goto fail_release_out;
    }
    if (c.fixed_normals)
        OB_LOG_W(OB_MODEL_LOG, "%s: %u vertices have a zero-length normal (in the file, or "
                 "only degenerate triangles use them); set to (0,1,0)", path, c.fixed_normals);
    if (out_info) {
        out_info->mesh_count = c.instances;
        out_info->vertex_count = out->vertex_count;
        out_info->triangle_count = out->index_count / 3;
    }
    OB_LOG_I(OB_MODEL_LOG, "%s: %u mesh instances, %u vertices, %u triangles", path,
             c.instances, out->vertex_count, out->index_count / 3);
    aiReleaseImport(scene);
    ob_model_io_release(&io);
    return OB_OK;

fail_release_out:
    ob_mesh_release(out);
    ob_model_report_more(&c.chk);
    aiReleaseImport(scene);
    ob_model_io_release(&io);
    return r;
}
