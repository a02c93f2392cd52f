/* fuzz_model — libFuzzer target for the model loaders (geometry/ob_model*.c):
 * assimp's parsers followed by our checks of the raw scene, post-processing
 * and the merge into one ob_mesh (ob_model_load_mesh); then the same file through
 * ob_model_open (the glTF extension scan, nodes, primitives, materials,
 * images, tangents).
 *
 * Input: byte 0 picks the file extension (assimp chooses a parser by it and
 * by the content), the rest is the file. A range of byte 0 makes
 * the input structure-aware (byte 0 from 0x70): the rest of the bytes are decisions, and
 * gen_gltf writes a well-formed glTF 2 file from them, with what random
 * bytes almost never reach: skins (with and without inverseBindMatrices,
 * too few matrices, joint indices past the joint count, weights that are
 * 0, negative, Inf or NaN), sparse accessors, morph targets, byte strides
 * shorter than their element, accessor offsets and counts past their
 * buffer view. ob_model_load_mesh takes a path, so the
 * bytes are written to a file in a per-process temporary folder first.
 * A successful load must give a mesh that passes ob_mesh_validate and has
 * finite bounds, and simplified (ob_mesh_simplify) a valid mesh no larger;
 * a failed one must leave the mesh empty. A successful open
 * must give a model keeping every promise of ob_model.h (parents first,
 * indices in range, finite transforms, unit tangents where normal maps
 * are); a failed one must hand out NULL. Anything else, and any sanitizer
 * report (leaks included), is a finding.
 *
 * Build and run: see fuzz/model.cmake (clang, OB_FUZZ=ON) and docs/soak.md
 * ("Fuzzing the model loader").
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_mesh.h"
#include "ob_model.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
const char *__asan_default_options(void);
const char *__lsan_default_suppressions(void);

/* A file that declares billions of vertices makes assimp ask for hundreds
 * of gigabytes at once. On a real system that request fails, operator new
 * throws and assimp rejects the file; here too: allocations over 2 GiB
 * return NULL (bad_alloc) instead of being reported as a finding. Memory
 * that really grows past -rss_limit_mb is still reported. $ASAN_OPTIONS
 * overrides these. */
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1:max_allocation_size_mb=2048";
}

/* assimp leaks on some of its own error paths (inside aiImportFile, e.g. an
 * ASCII STL whose facet breaks off: see docs/soak.md). Those allocations
 * come from C++ operator new, where the fast unwinder stops; the only C++
 * here is assimp (and libFuzzer). Our loader is C and allocates through
 * ob_malloc: its leaks are still reported. */
const char *__lsan_default_suppressions(void) { return "leak:libstdc++.so\n"; }

/* The formats the engine documents (OBJ, PLY, glTF 2) and the small ones
 * assimp sniffs by content anyway. */
static const char *const extensions[] = {"obj", "ply", "gltf", "glb", "off", "stl"};
/* Byte 0 (its low 7 bits; bit 7 is flip_uv) from 0x70 up: gen_gltf. Below,
 * the extension by byte 0 % 6, as the saved seeds were written. */
#define GENERATED_GLTF 0x70u

/* Per-process state of the harness itself, not of the engine. */
static char temp_dir[64];
static char paths[sizeof extensions / sizeof extensions[0]][96];

static void quiet_sink(void *user, ob_log_level level, const char *module, const char *file,
                       int line, const char *message)
{
    (void)user, (void)level, (void)module, (void)file, (void)line, (void)message;
}

static void remove_temp(void)
{
    for (size_t i = 0; i < sizeof extensions / sizeof extensions[0]; i++) unlink(paths[i]);
    if (temp_dir[0]) rmdir(temp_dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    /* Every rejected input logs why; at thousands of inputs a second that is
     * only noise. OB_FUZZ_LOG=1 keeps the engine's default sink. */
    if (!getenv("OB_FUZZ_LOG")) ob_log_set_sink(quiet_sink, NULL, NULL);
    snprintf(temp_dir, sizeof temp_dir, "/tmp/ob-fuzz-model-XXXXXX");
    if (!mkdtemp(temp_dir)) {
        perror("fuzz_model: mkdtemp");
        abort();
    }
    for (size_t i = 0; i < sizeof extensions / sizeof extensions[0]; i++)
        snprintf(paths[i], sizeof paths[i], "%s/model.%s", temp_dir, extensions[i]);
    atexit(remove_temp);
    return 0;
}

static void check_mesh(const ob_mesh *m, const ob_model_info *info)
{
    /* A loaded mesh is what the rest of the engine trusts without checking. */
    if (m->vertex_count == 0 || m->index_count == 0 || m->index_count % 3 != 0 || !m->vertices ||
        !m->indices)
        abort();
    for (uint32_t i = 0; i < m->index_count; i++)
        if (m->indices[i] >= m->vertex_count) abort();
    for (uint32_t v = 0; v < m->vertex_count; v++)
        for (int k = 0; k < 3; k++)
            if (!isfinite(m->vertices[v].position[k]) || !isfinite(m->vertices[v].normal[k])) abort();
    if (!isfinite(m->bounds.radius) || m->bounds.radius < 0.0f) abort();
    if (info->vertex_count != m->vertex_count || info->triangle_count != m->index_count / 3) abort();
}

static void check_texture(const ob_model *m, const ob_model_texture *t)
{
    if (t->image < -1 || t->image >= (int32_t)m->image_count) abort();
}

static void check_model(const ob_model *m)
{
    if (!m->path || !m->node_count || !m->primitive_count || !m->material_count) abort();
    if (m->nodes[0].parent != -1) abort();
    for (uint32_t i = 0; i < m->node_count; i++) {
        const ob_model_node *n = &m->nodes[i];
        if (!n->name || n->parent >= (int32_t)i || n->parent < -1) abort();
        for (int k = 0; k < 16; k++)
            if (!isfinite(n->local[k])) abort();
        for (uint32_t p = 0; p < n->primitive_count; p++)
            if (n->primitives[p] >= m->primitive_count) abort();
    }
    for (uint32_t i = 0; i < m->primitive_count; i++) {
        const ob_model_primitive *p = &m->primitives[i];
        if (!p->name || p->material >= m->material_count) abort();
        if (ob_mesh_validate(&p->mesh, "fuzz") != OB_OK || !isfinite(p->mesh.bounds.radius)) abort();
        bool normal_map = m->materials[p->material].normal_texture.image >= 0;
        if ((p->mesh.tangents != NULL) != normal_map) abort();
        for (uint32_t v = 0; p->mesh.tangents && v < p->mesh.vertex_count; v++) {
            const float *t = p->mesh.tangents[v];
            float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            if (!(fabsf(len - 1.0f) < 1e-3f) || (t[3] != 1.0f && t[3] != -1.0f)) abort();
        }
    }
    for (uint32_t i = 0; i < m->material_count; i++) {
        const ob_model_material *mat = &m->materials[i];
        if (!mat->name || mat->alpha_mode > OB_MODEL_ALPHA_BLEND) abort();
        check_texture(m, &mat->base_color_texture);
        check_texture(m, &mat->metallic_roughness_texture);
        check_texture(m, &mat->normal_texture);
        check_texture(m, &mat->occlusion_texture);
        check_texture(m, &mat->emissive_texture);
    }
    for (uint32_t i = 0; i < m->image_count; i++) {
        const ob_model_image *img = &m->images[i];
        if (!img->name || (img->path == NULL) == (img->data == NULL) || (img->data && !img->size)) abort();
    }
}


/* ------------------------------------------------- structure-aware glTF */

typedef struct choices {
    const uint8_t *p, *end;
} choices;

/* The next decision byte; 0 once the input is used up. */
static uint8_t pick(choices *c) { return c->p < c->end ? *c->p++ : 0; }

static float pick_float(choices *c)
{
    static const float special[] = {0.0f, 1.0f, -1.0f, 0.5f, 2.0f, 1e38f, -1e-30f, INFINITY,
                                    -INFINITY, NAN, 3.0f, 0.25f};
    uint8_t b = pick(c);
    return b < 192 ? (float)(b % 16) * 0.25f - 1.0f : special[b % (sizeof special / sizeof special[0])];
}

typedef struct text {
    char *s;
    size_t len, cap;
} text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void put(text *t, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap);
        va_end(ap);
        if (n < 0) abort();
        if ((size_t)n < t->cap - t->len) {
            t->len += (size_t)n;
            return;
        }
        t->cap = t->cap * 2 + (size_t)n + 64;
        t->s = realloc(t->s, t->cap);
        if (!t->s) abort();
    }
}

static void put_base64(text *t, const uint8_t *data, size_t size)
{
    static const char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < size; i += 3) {
        uint32_t v = (uint32_t)data[i] << 16 | (i + 1 < size ? (uint32_t)data[i + 1] << 8 : 0) |
                     (i + 2 < size ? data[i + 2] : 0);
        put(t, "%c%c%c%c", abc[v >> 18 & 63], abc[v >> 12 & 63],
            i + 1 < size ? abc[v >> 6 & 63] : '=', i + 2 < size ? abc[v & 63] : '=');
    }
}

/* One buffer, laid out as: positions (vertex_count vec3), indices (u16),
 * joints (u8 vec4), weights (vec4), inverse bind matrices (mat4), morph
 * positions (vec3), sparse indices (u16) and values (vec3). Accessors
 * point into it with counts, offsets and strides chosen by the input (most
 * right, some wrong). Written to path. */
static void gen_gltf(const char *path, const uint8_t *data, size_t size)
{
    choices c = {data, data + size};
    const uint32_t verts = 3 + pick(&c) % 6, joints = 1 + pick(&c) % 4;
    uint8_t blob[4096];
    size_t at = 0;
    const size_t pos_off = at;
    for (uint32_t v = 0; v < verts * 3; v++, at += 4) {
        float f = pick(&c) < 240 ? (float)((v * 7 + v / 3) % 5) - 2.0f : pick_float(&c);
        memcpy(blob + at, &f, 4);
    }
    const size_t idx_off = at;
    const uint32_t index_count = 3 * (1 + pick(&c) % 3);
    for (uint32_t i = 0; i < index_count; i++, at += 2) {
        uint16_t ix = pick(&c) < 230 ? (uint16_t)(i % verts) : (uint16_t)(verts + pick(&c));
        memcpy(blob + at, &ix, 2);
    }
    at = (at + 3) & ~(size_t)3;
    const size_t joint_off = at;
    for (uint32_t v = 0; v < verts * 4; v++) blob[at++] = pick(&c) < 220 ? (uint8_t)(v % joints) : pick(&c);
    const size_t weight_off = at;
    for (uint32_t v = 0; v < verts * 4; v++, at += 4) {
        float w = pick(&c) < 200 ? (v % 4 == 0 ? 1.0f : 0.0f) : pick_float(&c);
        memcpy(blob + at, &w, 4);
    }
    const size_t ibm_off = at;
    for (uint32_t j = 0; j < joints * 16; j++, at += 4) {
        float m = j % 5 == 0 ? 1.0f : 0.0f;
        if (pick(&c) > 240) m = pick_float(&c);
        memcpy(blob + at, &m, 4);
    }
    const size_t morph_off = at;
    for (uint32_t v = 0; v < verts * 3; v++, at += 4) {
        float f = pick_float(&c);
        memcpy(blob + at, &f, 4);
    }
    const size_t sparse_idx_off = at;
    for (uint32_t i = 0; i < 2; i++, at += 2) {
        uint16_t ix = (uint16_t)(pick(&c) % (verts + 2));
        memcpy(blob + at, &ix, 2);
    }
    const size_t sparse_val_off = at;
    for (uint32_t v = 0; v < 6; v++, at += 4) {
        float f = pick_float(&c);
        memcpy(blob + at, &f, 4);
    }
    const size_t blob_size = at;

    const uint8_t flags = pick(&c);
    const bool skin = flags & 1, ibm = flags & 2, morph = flags & 4, sparse = flags & 8,
               indexed = !(flags & 16), bad_stride = (flags & 0xE0) == 0xE0;
    /* Counts: usually right, sometimes past the data. */
    uint32_t pos_count = pick(&c) < 230 ? verts : verts + pick(&c);
    uint32_t ibm_count = pick(&c) < 200 ? joints : pick(&c) % (joints + 2);

    text t = {.s = malloc(4096), .cap = 4096};
    if (!t.s) abort();
    put(&t, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[");
    put(&t, "{\"mesh\":0%s%s", skin ? ",\"skin\":0" : "", joints > 0 ? ",\"children\":[" : "");
    for (uint32_t j = 0; j < joints; j++) put(&t, "%s%u", j ? "," : "", 1 + j);
    put(&t, "%s}", joints > 0 ? "]" : "");
    for (uint32_t j = 0; j < joints; j++)
        put(&t, ",{\"translation\":[%g,0,0]}", (double)j);
    put(&t, "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0");
    if (skin || (flags & 64)) put(&t, ",\"JOINTS_0\":2,\"WEIGHTS_0\":3");
    put(&t, "}%s,\"mode\":%u", indexed ? ",\"indices\":1" : "", pick(&c) < 240 ? 4u : pick(&c) % 8u);
    if (morph) put(&t, ",\"targets\":[{\"POSITION\":5}]");
    put(&t, "}]%s}]", morph ? ",\"weights\":[0.5]" : "");
    if (skin) {
        put(&t, ",\"skins\":[{\"joints\":[");
        for (uint32_t j = 0; j < joints; j++)
            put(&t, "%s%u", j ? "," : "", pick(&c) < 230 ? 1 + j : (uint32_t)pick(&c));
        put(&t, "]%s}]", ibm ? ",\"inverseBindMatrices\":4" : "");
    }
    put(&t, ",\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,", blob_size);
    put_base64(&t, blob, blob_size);
    put(&t, "\"}],\"bufferViews\":[");
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu%s},", pos_off, idx_off - pos_off,
        bad_stride ? ",\"byteStride\":4" : "");
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u},", idx_off, index_count * 2);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u},", joint_off, verts * 4);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u},", weight_off, verts * 16);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u},", ibm_off, joints * 64);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u},", morph_off, verts * 12);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":4},", sparse_idx_off);
    put(&t, "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":24}],", sparse_val_off);
    put(&t, "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\","
            "\"min\":[-2,-2,-2],\"max\":[2,2,2]", pos_count);
    if (sparse)
        put(&t, ",\"sparse\":{\"count\":%u,\"indices\":{\"bufferView\":6,\"componentType\":5123},"
                "\"values\":{\"bufferView\":7}}", 1u + pick(&c) % 3u);
    put(&t, "},{\"bufferView\":1,\"componentType\":5123,\"count\":%u,\"type\":\"SCALAR\"},", index_count);
    put(&t, "{\"bufferView\":2,\"componentType\":5121,\"count\":%u,\"type\":\"VEC4\"},", verts);
    put(&t, "{\"bufferView\":3,\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"},", verts);
    put(&t, "{\"bufferView\":4,\"componentType\":5126,\"count\":%u,\"type\":\"MAT4\"},", ibm_count);
    put(&t, "{\"bufferView\":5,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}]}", verts);

    FILE *f = fopen(path, "wb");
    if (!f || fwrite(t.s, 1, t.len, f) != t.len || fclose(f) != 0) abort();
    free(t.s);
}

/* Levels of detail from what the loader gave (ob_mesh_simplify), for
 * meshes small enough to keep an input fast: a valid mesh of at most as
 * many indices, every vertex one of the input's; or a refusal (a mesh of
 * degenerate triangles only) that hands out nothing. */
static void check_simplified(const ob_mesh *mesh)
{
    if (mesh->index_count > 30000) return;
    ob_mesh lod;
    float error = -1.0f;
    ob_result r = ob_mesh_simplify(mesh, mesh->index_count / 4, INFINITY, &lod, &error);
    if (r != OB_OK) {
        if (lod.vertices || lod.indices || lod.vertex_count || lod.index_count) abort();
        if (r != OB_ERR_INVALID_ARGUMENT) abort();
        return;
    }
    if (ob_mesh_validate(&lod, "fuzz lod") != OB_OK || lod.index_count > mesh->index_count ||
        lod.vertex_count > mesh->vertex_count || !(error >= 0.0f) || !isfinite(lod.bounds.radius))
        abort();
    ob_mesh_release(&lod);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    const bool generated = (data[0] & 0x7Fu) >= GENERATED_GLTF;
    const char *path = paths[generated ? 2 : data[0] % (sizeof extensions / sizeof extensions[0])];
    if (generated) {   /* written as model.gltf */
        gen_gltf(path, data + 1, size - 1);
    } else {
        FILE *f = fopen(path, "wb");
        if (!f) abort();
        if (size > 1 && fwrite(data + 1, 1, size - 1, f) != size - 1) abort();
        if (fclose(f) != 0) abort();
    }

    ob_mesh mesh;
    ob_model_info info;
    ob_result r = ob_model_load_mesh(&(ob_model_desc){.path = path}, &mesh, &info);
    if (r == OB_OK) {
        check_mesh(&mesh, &info);
        check_simplified(&mesh);
        ob_mesh_release(&mesh);
    } else if (mesh.vertices || mesh.indices || mesh.vertex_count || mesh.index_count) {
        abort(); /* a failed load hands out nothing */
    }

    ob_model *model = (ob_model *)&model;   /* must become NULL on failure */
    r = ob_model_open(&(ob_model_desc){.path = path, .flip_uv = (data[0] & 0x80) != 0}, &model);
    if (r == OB_OK) {
        check_model(model);
        ob_model_close(model);
    } else if (model) {
        abort(); /* a failed open hands out nothing */
    }
    return 0;
}
