/* fuzz_model — libFuzzer target for the model loaders (geometry/ob_model*.c):
 * assimp's parsers followed by our checks of the raw scene, post-processing
 * and the merge into one ob_mesh (ob_model_load); then the same file through
 * ob_model_open (the glTF extension scan, nodes, primitives, materials,
 * images, tangents).
 *
 * Input: byte 0 picks the file extension (assimp chooses a parser by it and
 * by the content), the rest is the file. ob_model_load takes a path, so the
 * bytes are written to a file in a per-process temporary folder first.
 * A successful load must give a mesh that passes ob_mesh_validate and has
 * finite bounds; a failed one must leave the mesh empty. A successful open
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    size_t which = data[0] % (sizeof extensions / sizeof extensions[0]);
    const char *path = paths[which];
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (size > 1 && fwrite(data + 1, 1, size - 1, f) != size - 1) abort();
    if (fclose(f) != 0) abort();

    ob_mesh mesh;
    ob_model_info info;
    ob_result r = ob_model_load(&(ob_model_desc){.path = path}, &mesh, &info);
    if (r == OB_OK) {
        check_mesh(&mesh, &info);
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
