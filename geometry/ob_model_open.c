/* ob_model_open.c — a model file with its structure (ob_model.h): nodes and
 * primitives here, materials and images in ob_model_material.c.
 *
 * The order is ob_model_load_mesh's (ob_model.c explains why): PLY and glTF
 * prechecks, parse with no post-processing, check the raw scene, and only
 * then triangulate, generate missing normals and join identical vertices —
 * but without aiProcess_PreTransformVertices or our own merge: each aiMesh
 * stays a primitive and each aiNode a node.
 *
 * Every allocation hangs off the model as soon as it is made (with its
 * count), so every failure path is one ob_model_close.
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_model.h"
#include "ob_model_internal.h"
#include "ob_math.h"

#include <assimp/cimport.h>
#include <assimp/scene.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct open_ctx {
    ob_model_check chk;
    const struct aiScene *scene;
    ob_model *model;
    bool flip_uv;
    uint32_t *mesh_primitive;   /* per aiMesh: its primitive, UINT32_MAX when dropped */
    uint32_t dropped_meshes;    /* points / lines only */
    struct light_name *light_names;   /* the file's lights sorted by name, for the nodes to find */
    uint32_t light_name_count;
    uint32_t fixed_normals;
} open_ctx;

static const char *ai_name(const struct aiString *s) { return s->length ? s->data : NULL; }

static char *name_or(const struct aiString *s, const char *what, uint32_t index)
{
    if (ai_name(s)) return ob_strdup(s->data);
    char fallback[40];
    snprintf(fallback, sizeof fallback, "%s %u", what, index);
    return ob_strdup(fallback);
}

static ob_result out_of_memory(open_ctx *c, const char *what)
{
    OB_LOG_E(OB_MODEL_LOG, "%s: out of memory for %s", c->chk.path, what);
    return OB_ERR_OUT_OF_HOST_MEMORY;
}

/* ------------------------------------------------------------ primitives */

static uint8_t unorm8(float v)
{
    v = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
    return (uint8_t)lrintf(v * 255.0f);
}

/* The file's tangents (glTF TANGENT), orthogonalized against the final
 * normals; w from assimp's bitangent, which its glTF importer made as
 * cross(N, T) · w. */
static ob_result file_tangents(open_ctx *c, uint32_t mi, const struct aiMesh *m, ob_mesh *mesh)
{
    mesh->tangents = ob_malloc((size_t)mesh->vertex_count * sizeof *mesh->tangents);
    if (!mesh->tangents) return out_of_memory(c, "tangents");
    for (uint32_t v = 0; v < mesh->vertex_count; v++) {
        const struct aiVector3D *t = &m->mTangents[v];
        if (!ob_model_v3_finite(t) || (m->mBitangents && !ob_model_v3_finite(&m->mBitangents[v]))) {
            ob_model_bad(&c->chk, "mesh %u '%s': vertex %u tangent is not finite (%g, %g, %g)", mi,
                         m->mName.data, v, (double)t->x, (double)t->y, (double)t->z);
            return OB_ERR_BAD_MODEL;
        }
        const float *n = mesh->vertices[v].normal;
        double tan[3] = {t->x, t->y, t->z};
        double d = n[0] * tan[0] + n[1] * tan[1] + n[2] * tan[2];
        for (int k = 0; k < 3; k++) tan[k] -= n[k] * d;
        double len = sqrt(tan[0] * tan[0] + tan[1] * tan[1] + tan[2] * tan[2]);
        double w = 1.0;
        if (m->mBitangents) {
            const struct aiVector3D *b = &m->mBitangents[v];
            double nxt[3] = {n[1] * tan[2] - n[2] * tan[1], n[2] * tan[0] - n[0] * tan[2],
                             n[0] * tan[1] - n[1] * tan[0]};
            w = nxt[0] * b->x + nxt[1] * b->y + nxt[2] * b->z < 0.0 ? -1.0 : 1.0;
        }
        if (!(len > 1e-12) || !isfinite(len)) {
            /* Parallel to the normal or zero in the file: any perpendicular. */
            double ax = fabs(n[0]) < 0.9 ? 1.0 : 0.0, ay = 1.0 - ax;
            tan[0] = ay * n[2];
            tan[1] = -ax * n[2];
            tan[2] = ax * n[1] - ay * n[0];
            len = sqrt(tan[0] * tan[0] + tan[1] * tan[1] + tan[2] * tan[2]);
            if (!(len > 1e-12)) {
                tan[0] = 1.0;
                tan[1] = tan[2] = 0.0;
                len = 1.0;
            }
        }
        for (int k = 0; k < 3; k++) mesh->tangents[v][k] = (float)(tan[k] / len);
        mesh->tangents[v][3] = (float)w;
    }
    return OB_OK;
}

static ob_result build_primitive(open_ctx *c, uint32_t mi, const struct aiMesh *m,
                                 ob_model_primitive *p)
{
    ob_model *model = c->model;
    uint64_t tris = 0;
    for (uint32_t f = 0; f < m->mNumFaces; f++) tris += m->mFaces[f].mNumIndices == 3;
    if (3 * tris > UINT32_MAX) {
        OB_LOG_E(OB_MODEL_LOG, "%s: mesh %u '%s': %llu triangles exceed the 32-bit index range",
                 c->chk.path, mi, m->mName.data, (unsigned long long)tris);
        return OB_ERR_LIMIT;
    }
    if (m->mMaterialIndex >= model->material_count) {
        ob_model_bad(&c->chk, "mesh %u '%s' uses material %u; the file has %u", mi, m->mName.data,
                     m->mMaterialIndex, model->material_count);
        return OB_ERR_BAD_MODEL;
    }
    p->material = m->mMaterialIndex;
    p->name = name_or(&m->mName, "mesh", mi);
    ob_mesh *mesh = &p->mesh;
    mesh->vertices = ob_calloc(m->mNumVertices, sizeof *mesh->vertices);
    mesh->indices = ob_malloc((size_t)(3 * tris) * sizeof *mesh->indices);
    if (!p->name || !mesh->vertices || !mesh->indices) return out_of_memory(c, "a primitive");
    mesh->vertex_count = m->mNumVertices;
    mesh->index_count = (uint32_t)(3 * tris);

    for (uint32_t v = 0; v < m->mNumVertices; v++) {
        ob_vertex *dst = &mesh->vertices[v];
        dst->position[0] = m->mVertices[v].x;
        dst->position[1] = m->mVertices[v].y;
        dst->position[2] = m->mVertices[v].z;
        double n[3] = {0, 0, 0}, len = 0.0;
        if (m->mNormals) {
            n[0] = m->mNormals[v].x;
            n[1] = m->mNormals[v].y;
            n[2] = m->mNormals[v].z;
            len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        }
        if (len > 1e-30 && isfinite(len)) {
            for (int k = 0; k < 3; k++) dst->normal[k] = (float)(n[k] / len);
        } else {   /* as ob_model_load_mesh and ob_mesh_generate_normals */
            dst->normal[1] = 1.0f;
            c->fixed_normals++;
        }
        if (m->mTextureCoords[0]) {
            dst->uv[0] = m->mTextureCoords[0][v].x;
            dst->uv[1] = m->mTextureCoords[0][v].y;
        }
    }
    uint32_t *idx = mesh->indices;
    for (uint32_t f = 0; f < m->mNumFaces; f++) {
        const struct aiFace *face = &m->mFaces[f];
        if (face->mNumIndices != 3) continue;
        for (uint32_t k = 0; k < 3; k++) *idx++ = face->mIndices[k];
    }
    if (m->mColors[0]) {
        mesh->colors = ob_malloc((size_t)mesh->vertex_count * sizeof *mesh->colors);
        if (!mesh->colors) return out_of_memory(c, "vertex colours");
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            const struct aiColor4D *col = &m->mColors[0][v];
            if (!isfinite(col->r) || !isfinite(col->g) || !isfinite(col->b) || !isfinite(col->a)) {
                ob_model_bad(&c->chk, "mesh %u '%s': vertex %u colour is not finite", mi,
                             m->mName.data, v);
                return OB_ERR_BAD_MODEL;
            }
            mesh->colors[v][0] = unorm8(col->r);
            mesh->colors[v][1] = unorm8(col->g);
            mesh->colors[v][2] = unorm8(col->b);
            mesh->colors[v][3] = unorm8(col->a);
        }
    }
    if (m->mTextureCoords[1]) {
        mesh->uv1 = ob_malloc((size_t)mesh->vertex_count * sizeof *mesh->uv1);
        if (!mesh->uv1) return out_of_memory(c, "the second uv set");
        for (uint32_t v = 0; v < mesh->vertex_count; v++) {
            mesh->uv1[v][0] = m->mTextureCoords[1][v].x;
            mesh->uv1[v][1] = m->mTextureCoords[1][v].y;
        }
    }
    /* Validation covers indices after post-processing and every attribute
     * (positions were checked raw; assimp's steps must not have broken
     * them either). */
    char label[320];
    snprintf(label, sizeof label, "%s: mesh %u '%s'", c->chk.path, mi, p->name);
    if (ob_mesh_validate(mesh, label) != OB_OK || ob_mesh_compute_bounds(mesh) != OB_OK) {
        c->chk.problems++;
        return OB_ERR_BAD_MODEL;
    }
    const ob_model_material *mat = &model->materials[p->material];
    if (mat->normal_texture.image < 0 && mat->clearcoat_normal_texture.image < 0) return OB_OK;
    /* Tangents only where a normal map needs them. */
    if (m->mTangents && m->mNormals) return file_tangents(c, mi, m, mesh);
    ob_result r = ob_mesh_generate_tangents(mesh, !c->flip_uv);
    if (r == OB_ERR_OUT_OF_HOST_MEMORY) return out_of_memory(c, "tangents");
    return r;
}

static ob_result build_primitives(open_ctx *c)
{
    const struct aiScene *s = c->scene;
    ob_model *model = c->model;
    c->mesh_primitive = ob_malloc((size_t)s->mNumMeshes * sizeof *c->mesh_primitive);
    model->primitives = ob_calloc(s->mNumMeshes, sizeof *model->primitives);
    if (!c->mesh_primitive || !model->primitives) return out_of_memory(c, "the primitives");
    bool area = false;
    for (uint32_t mi = 0; mi < s->mNumMeshes; mi++) {
        c->mesh_primitive[mi] = UINT32_MAX;
        const struct aiMesh *m = s->mMeshes[mi];
        if (!m) {
            ob_model_bad(&c->chk, "mesh %u is missing after post-processing", mi);
            return OB_ERR_BAD_MODEL;
        }
        bool triangles = false;
        for (uint32_t f = 0; f < m->mNumFaces && !triangles; f++)
            triangles = m->mFaces[f].mNumIndices == 3;
        if (!triangles) {
            c->dropped_meshes++;
            continue;
        }
        ob_model_primitive *p = &model->primitives[model->primitive_count++];
        ob_result r = build_primitive(c, mi, m, p);
        if (r != OB_OK) return r;
        c->mesh_primitive[mi] = model->primitive_count - 1;
        area = area || ob_model_mesh_has_area(&p->mesh);
    }
    if (model->primitive_count == 0) {
        ob_model_bad(&c->chk, "contains no triangles (%u meshes: only points, lines or empty "
                     "meshes)", s->mNumMeshes);
        return OB_ERR_BAD_MODEL;
    }
    if (!area) {
        ob_model_bad(&c->chk, "all triangles of its %u primitives have zero area",
                     model->primitive_count);
        return OB_ERR_BAD_MODEL;
    }
    return OB_OK;
}

/* ----------------------------------------------------------------- nodes */

static ob_result count_nodes(open_ctx *c, const struct aiNode *n, uint32_t depth, uint64_t *count)
{
    if (depth > OB_MODEL_MAX_NODE_DEPTH) {
        ob_model_bad(&c->chk, "node hierarchy deeper than %u levels", OB_MODEL_MAX_NODE_DEPTH);
        return OB_ERR_BAD_MODEL;
    }
    if (++*count > UINT32_MAX / 2) {
        OB_LOG_E(OB_MODEL_LOG, "%s: too many nodes", c->chk.path);
        return OB_ERR_LIMIT;
    }
    for (uint32_t k = 0; k < n->mNumChildren; k++) {
        if (!n->mChildren || !n->mChildren[k]) {
            ob_model_bad(&c->chk, "node '%s' has a missing child %u", n->mName.data, k);
            return OB_ERR_BAD_MODEL;
        }
        ob_result r = count_nodes(c, n->mChildren[k], depth + 1, count);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

/* ------------------------------------------------------------ lights */

typedef struct light_name {
    const char *name;
    uint32_t light;             /* index into scene->mLights */
    bool placed;
} light_name;

static int compare_light_names(const void *a, const void *b)
{
    const light_name *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->light > y->light) - (x->light < y->light);
}

/* The file's lights by name, so each node finds its own in log time. */
static ob_result index_lights(open_ctx *c)
{
    const struct aiScene *s = c->scene;
    if (!s->mNumLights || !s->mLights) return OB_OK;
    uint32_t n = s->mNumLights < OB_MODEL_MAX_LIGHTS ? s->mNumLights : OB_MODEL_MAX_LIGHTS;
    if (s->mNumLights > n)
        OB_LOG_W(OB_MODEL_LOG, "%s: %u lights; only the first %u are kept (OB_MODEL_MAX_LIGHTS)",
                 c->chk.path, s->mNumLights, n);
    c->light_names = ob_calloc(n, sizeof *c->light_names);
    c->model->lights = ob_calloc(n, sizeof *c->model->lights);
    if (!c->light_names || !c->model->lights) return out_of_memory(c, "the lights");
    for (uint32_t i = 0; i < n; i++) {
        if (!s->mLights[i]) continue;
        c->light_names[c->light_name_count++] = (light_name){s->mLights[i]->mName.data, i, false};
    }
    qsort(c->light_names, c->light_name_count, sizeof *c->light_names, compare_light_names);
    return OB_OK;
}

/* glTF's range, which assimp keeps in the node's metadata; 0 (none) when absent. */
static float light_range(const struct aiNode *n)
{
    const struct aiMetadata *m = n->mMetaData;
    for (uint32_t i = 0; m && m->mKeys && m->mValues && i < m->mNumProperties; i++) {
        if (strcmp(m->mKeys[i].data, "PBR_LightRange") != 0 || !m->mValues[i].mData) continue;
        if (m->mValues[i].mType == AI_FLOAT) return *(const float *)m->mValues[i].mData;
        if (m->mValues[i].mType == AI_DOUBLE) return (float)*(const double *)m->mValues[i].mData;
    }
    return 0.0f;
}

/* The light named like node `index`, if any, onto it. A bad light is
 * warned about and dropped; the model still loads. */
static void place_light(open_ctx *c, const struct aiNode *n, uint32_t index)
{
    if (!c->light_name_count) return;
    light_name key = {n->mName.data, 0, false};
    light_name *hit = NULL;
    /* The first unplaced light of that name (two nodes may share a name). */
    for (uint32_t lo = 0, hi = c->light_name_count; lo < hi;) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (strcmp(c->light_names[mid].name, key.name) < 0) lo = mid + 1;
        else hi = mid, hit = &c->light_names[mid];
    }
    while (hit && hit < c->light_names + c->light_name_count && strcmp(hit->name, key.name) == 0 &&
           hit->placed)
        hit++;
    if (!hit || hit >= c->light_names + c->light_name_count || strcmp(hit->name, key.name) != 0) return;
    hit->placed = true;
    const struct aiLight *al = c->scene->mLights[hit->light];
    const char *name = c->model->nodes[index].name;
    ob_light_desc d = {0};   /* casts_shadows false: glTF says nothing of shadows */
    switch (al->mType) {
    case aiLightSource_DIRECTIONAL: d.type = OB_LIGHT_DIRECTIONAL; break;
    case aiLightSource_POINT: d.type = OB_LIGHT_POINT; break;
    case aiLightSource_SPOT: d.type = OB_LIGHT_SPOT; break;
    default:
        OB_LOG_W(OB_MODEL_LOG, "%s: light '%s' is of a type Obelisk does not draw (%d); dropped",
                 c->chk.path, name, (int)al->mType);
        return;
    }
    float rgb[3] = {al->mColorDiffuse.r, al->mColorDiffuse.g, al->mColorDiffuse.b};
    float range = light_range(n), inner = al->mAngleInnerCone, outer = al->mAngleOuterCone;
    float peak = fmaxf(rgb[0], fmaxf(rgb[1], rgb[2]));
    if (!isfinite(rgb[0] + rgb[1] + rgb[2] + range) || rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0 ||
        range < 0 || (d.type == OB_LIGHT_SPOT && !isfinite(inner + outer))) {
        OB_LOG_W(OB_MODEL_LOG, "%s: light '%s' has a negative or non-finite colour, range or "
                 "cone angle; dropped", c->chk.path, name);
        return;
    }
    d.intensity = peak;
    for (int k = 0; k < 3; k++) d.color[k] = peak > 0.0f ? rgb[k] / peak : 1.0f;
    if (d.type != OB_LIGHT_DIRECTIONAL) d.range = range;
    if (d.type == OB_LIGHT_SPOT) {
        const float max_outer = 89.9f * (float)(OB_PI / 180.0);
        d.outer_angle = outer > max_outer ? max_outer : outer > 0.0f ? outer : 1e-6f;
        d.inner_angle = inner < 0.0f ? 0.0f : inner > d.outer_angle ? d.outer_angle : inner;
    }
    c->model->lights[c->model->light_count++] = (ob_model_light){index, d};
}

/* Depth first, the node before its children: parents come first. */
static ob_result add_node(open_ctx *c, const struct aiNode *n, int32_t parent, uint32_t depth)
{
    ob_model *model = c->model;
    const uint32_t index = model->node_count++;
    ob_model_node *node = &model->nodes[index];
    node->parent = parent;
    node->name = name_or(&n->mName, "node", index);
    if (!node->name) return out_of_memory(c, "a node name");
    const struct aiMatrix4x4 *t = &n->mTransformation;
    const float rows[4][4] = {{t->a1, t->a2, t->a3, t->a4}, {t->b1, t->b2, t->b3, t->b4},
                              {t->c1, t->c2, t->c3, t->c4}, {t->d1, t->d2, t->d3, t->d4}};
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            float v = rows[row][col];
            if (!isfinite(v)) {
                ob_model_bad(&c->chk, "node %u '%s': transform is not finite", index, node->name);
                return OB_ERR_BAD_MODEL;
            }
            node->local[col * 4 + row] = v;
        }
    uint32_t placed = 0;
    for (uint32_t k = 0; k < n->mNumMeshes; k++) {
        uint32_t mi = n->mMeshes[k];
        if (mi >= c->scene->mNumMeshes) {
            ob_model_bad(&c->chk, "node %u '%s' refers to mesh %u of %u after post-processing",
                         index, node->name, mi, c->scene->mNumMeshes);
            return OB_ERR_BAD_MODEL;
        }
        placed += c->mesh_primitive[mi] != UINT32_MAX;
    }
    if (placed) {
        node->primitives = ob_malloc((size_t)placed * sizeof *node->primitives);
        if (!node->primitives) return out_of_memory(c, "a node's primitive list");
        for (uint32_t k = 0; k < n->mNumMeshes; k++) {
            uint32_t p = c->mesh_primitive[n->mMeshes[k]];
            if (p != UINT32_MAX) node->primitives[node->primitive_count++] = p;
        }
    }
    place_light(c, n, index);
    for (uint32_t k = 0; k < n->mNumChildren; k++) {
        ob_result r = add_node(c, n->mChildren[k], (int32_t)index, depth + 1);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

static ob_result build_nodes(open_ctx *c)
{
    const struct aiNode *root = c->scene->mRootNode;
    if (!root) {
        ob_model_bad(&c->chk, "has no root node after post-processing");
        return OB_ERR_BAD_MODEL;
    }
    uint64_t count = 0;
    ob_result r = count_nodes(c, root, 0, &count);
    if (r != OB_OK) return r;
    c->model->nodes = ob_calloc((size_t)count, sizeof *c->model->nodes);
    if (!c->model->nodes) return out_of_memory(c, "the nodes");
    r = index_lights(c);
    if (r == OB_OK) r = add_node(c, root, -1, 0);
    if (r != OB_OK) return r;
    for (uint32_t i = 0; i < c->light_name_count; i++)
        if (!c->light_names[i].placed)
            OB_LOG_W(OB_MODEL_LOG, "%s: light '%s' is on no node; dropped", c->chk.path,
                     c->light_names[i].name);
    uint32_t placements = 0;
    for (uint32_t i = 0; i < c->model->node_count; i++) placements += c->model->nodes[i].primitive_count;
    if (placements == 0) {
        ob_model_bad(&c->chk, "no node places any of its %u primitives", c->model->primitive_count);
        return OB_ERR_BAD_MODEL;
    }
    return OB_OK;
}

/* ------------------------------------------------------------------ open */

ob_result ob_model_open(const ob_model_desc *desc, ob_model **out_model)
{
    if (out_model) *out_model = NULL;
    if (!desc || !desc->path || !desc->path[0] || !out_model) {
        OB_LOG_E(OB_MODEL_LOG, "ob_model_open: %s", !desc ? "NULL desc"
                 : !out_model ? "NULL out_model" : "no path given");
        return OB_ERR_INVALID_ARGUMENT;
    }
    const char *path = desc->path;
    ob_model_io io;
    open_ctx c = {.chk = {.path = path, .io = &io}, .flip_uv = desc->flip_uv};
    /* The file's own hierarchy is kept: no PreTransformVertices (the
     * import never asks for it). */
    const struct aiScene *scene;
    ob_result r = ob_model_import(&c.chk, desc, true, &scene);
    if (r != OB_OK) {
        ob_model_io_release(&io);
        return r;
    }
    c.scene = scene;
    ob_model *model = ob_calloc(1, sizeof *model);
    c.model = model;
    if (!model || !(model->path = ob_strdup(path))) {
        r = out_of_memory(&c, "the model");
        goto fail_close_model;
    }
    r = ob_model_read_materials(&c.chk, scene, desc->flip_uv, model);
    if (r == OB_OK) r = build_primitives(&c);
    if (r == OB_OK) r = build_nodes(&c);
    if (r != OB_OK) goto fail_close_model;

    if (c.fixed_normals)
        OB_LOG_W(OB_MODEL_LOG, "%s: %u vertices have a zero-length normal (in the file, or "
                 "only degenerate triangles use them); set to (0,1,0)", path, c.fixed_normals);
    if (c.dropped_meshes)
        OB_LOG_I(OB_MODEL_LOG, "%s: %u meshes of points or lines dropped", path, c.dropped_meshes);
    uint64_t vertices = 0, triangles = 0;
    for (uint32_t i = 0; i < model->primitive_count; i++) {
        vertices += model->primitives[i].mesh.vertex_count;
        triangles += model->primitives[i].mesh.index_count / 3;
    }
    OB_LOG_I(OB_MODEL_LOG, "%s: %u nodes, %u primitives (%llu vertices, %llu triangles), "
             "%u materials, %u images", path, model->node_count, model->primitive_count,
             (unsigned long long)vertices, (unsigned long long)triangles, model->material_count,
             model->image_count);
    if (model->light_count)
        OB_LOG_I(OB_MODEL_LOG, "%s: %u lights", path, model->light_count);
    ob_free(c.mesh_primitive);
    ob_free(c.light_names);
    aiReleaseImport(scene);
    ob_model_io_release(&io);
    *out_model = model;
    return OB_OK;

fail_close_model:
    ob_model_report_more(&c.chk);
    ob_free(c.mesh_primitive);
    ob_free(c.light_names);
    ob_model_close(model);
    aiReleaseImport(scene);
    ob_model_io_release(&io);
    return r;
}

void ob_model_close(ob_model *model)
{
    if (!model) return;
    for (uint32_t i = 0; i < model->node_count; i++) {
        ob_free(model->nodes[i].name);
        ob_free(model->nodes[i].primitives);
    }
    for (uint32_t i = 0; i < model->primitive_count; i++) {
        ob_mesh_release(&model->primitives[i].mesh);
        ob_free(model->primitives[i].name);
    }
    for (uint32_t i = 0; i < model->material_count; i++) ob_free(model->materials[i].name);
    for (uint32_t i = 0; i < model->image_count; i++) {
        ob_free(model->images[i].name);
        ob_free(model->images[i].path);
        ob_free(model->images[i].data);
    }
    ob_free(model->nodes);
    ob_free(model->primitives);
    ob_free(model->materials);
    ob_free(model->images);
    ob_free(model->lights);
    ob_free(model->path);
    ob_free(model);
}
