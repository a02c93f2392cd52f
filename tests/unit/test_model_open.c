/* ob_model_open: a model keeps its structure and material data. No device.
 *
 * Where the expected values come from (not from the loader under test):
 * - the files in tests/data/models: written by tests/data/models/make_models.py, whose
 *   source states every value checked here (factors, samplers, tangents,
 *   colours, hierarchy);
 * - assimp-testmodels glTF files: their JSON is read here with cJSON (the
 *   JSON chunk of a .glb), and materials are matched by name (assimp numbers
 *   glTF materials in the order meshes first use them, not the file's);
 * - OBJ/PLY package files: the .mtl and PLY text, quoted in the tests.
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_model.h"

#include <cjson/cJSON.h>
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#include <stb_image.h>   /* compiled once in the library (engine/ob_stb_impl.c) */
#pragma GCC diagnostic pop
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MODELS "/usr/share/assimp/models/"
#define DATA OB_SOURCE_DIR "/tests/data/models/"

static bool have_model(const char *path)
{
    if (access(path, R_OK) == 0) return true;
    print_message("SKIP: %s is missing (install Debian's assimp-testmodels)\n", path);
    return false;
}

static ob_model *open_ok(const char *path, bool flip_uv)
{
    ob_model *m = NULL;
    ob_result r = ob_model_open(&(ob_model_desc){.path = path, .flip_uv = flip_uv}, &m);
    if (r != OB_OK) {
        ob_test_log_dump(OB_LOG_WARN, 20);
        fail_msg("%s: %s", path, ob_result_name(r));
    }
    assert_non_null(m);
    return m;
}

static void expect_refused(const char *path, ob_result expected, const char *a, const char *b)
{
    ob_model *m = (ob_model *)1;
    ob_test_log_clear();
    ob_result r = ob_model_open(&(ob_model_desc){.path = path}, &m);
    if (r != expected)
        fail_msg("%s: got %s, expected %s", path, ob_result_name(r), ob_result_name(expected));
    assert_null(m);
    if (!ob_test_log_has(path, a, b, NULL)) {
        ob_test_log_dump(OB_LOG_DEBUG, 20);
        fail_msg("%s: no log line naming the file, '%s' and '%s'", path, a, b ? b : "");
    }
}

static const ob_model_material *material_named(const ob_model *m, const char *name)
{
    for (uint32_t i = 0; i < m->material_count; i++)
        if (strcmp(m->materials[i].name, name) == 0) return &m->materials[i];
    fail_msg("no material '%s'", name);
    return NULL;
}

static const ob_model_primitive *primitive_named(const ob_model *m, const char *name)
{
    for (uint32_t i = 0; i < m->primitive_count; i++)
        if (strcmp(m->primitives[i].name, name) == 0) return &m->primitives[i];
    fail_msg("no primitive '%s'", name);
    return NULL;
}

static bool ends_with(const char *s, const char *tail)
{
    size_t a = strlen(s), b = strlen(tail);
    return a >= b && strcmp(s + a - b, tail) == 0;
}

/* Every structural promise of ob_model.h. */
static void expect_well_formed(const ob_model *m)
{
    assert_true(m->node_count > 0 && m->primitive_count > 0 && m->material_count > 0);
    assert_int_equal(m->nodes[0].parent, -1);
    for (uint32_t i = 0; i < m->node_count; i++) {
        const ob_model_node *n = &m->nodes[i];
        assert_non_null(n->name);
        assert_true(n->parent < (int32_t)i);   /* parents first */
        for (int k = 0; k < 16; k++) assert_true(isfinite(n->local[k]));
        for (uint32_t p = 0; p < n->primitive_count; p++)
            assert_true(n->primitives[p] < m->primitive_count);
    }
    for (uint32_t i = 0; i < m->primitive_count; i++) {
        const ob_model_primitive *p = &m->primitives[i];
        assert_true(p->material < m->material_count);
        assert_int_equal(ob_mesh_validate(&p->mesh, p->name), OB_OK);
        const ob_model_material *mat = &m->materials[p->material];
        /* Tangents exactly where a normal map needs them; unit, w = ±1, ⟂ normal. */
        assert_int_equal(p->mesh.tangents != NULL,
                         mat->normal_texture.image >= 0 || mat->clearcoat_normal_texture.image >= 0);
        for (uint32_t v = 0; p->mesh.tangents && v < p->mesh.vertex_count; v++) {
            const float *t = p->mesh.tangents[v], *n = p->mesh.vertices[v].normal;
            float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            if (fabsf(len - 1.0f) > 1e-4f) fail_msg("%s: vertex %u tangent length %g", p->name, v, (double)len);
            assert_true(t[3] == 1.0f || t[3] == -1.0f);
            assert_true(fabsf(t[0] * n[0] + t[1] * n[1] + t[2] * n[2]) < 1e-4f);
        }
    }
    for (uint32_t i = 0; i < m->material_count; i++) {
        const ob_model_texture *t = &m->materials[i].base_color_texture;
        for (int s = 0; s < 5; s++, t++) assert_true(t->image >= -1 && t->image < (int32_t)m->image_count);
    }
    for (uint32_t i = 0; i < m->image_count; i++) {
        const ob_model_image *img = &m->images[i];
        assert_non_null(img->name);
        assert_true((img->path != NULL) != (img->data != NULL));
        if (img->path) assert_int_equal(access(img->path, R_OK), 0);
        else assert_true(img->size > 0);
    }
}

/* --------------------------------------------------------- small files */

static void features_keep_hierarchy_and_instancing(void **state)
{
    (void)state;
    ob_test_log_clear();
    ob_model *m = open_ok(DATA "features.gltf", true);
    expect_well_formed(m);
    /* Two scene roots: assimp puts its ROOT above them. */
    assert_int_equal(m->node_count, 5);
    const char *names[5] = {"ROOT", "parent", "child", "grandchild", "sibling"};
    const int32_t parents[5] = {-1, 0, 1, 2, 0};
    const uint32_t placed[5] = {0, 0, 2, 2, 1};
    for (uint32_t i = 0; i < 5; i++) {
        assert_string_equal(m->nodes[i].name, names[i]);
        assert_int_equal(m->nodes[i].parent, parents[i]);
        assert_int_equal(m->nodes[i].primitive_count, placed[i]);
    }
    /* Local transforms, column-major: parent's translation, child's scale,
     * sibling's matrix; grandchild's rotation of 90° about Y. */
    const float *p = m->nodes[1].local, *c = m->nodes[2].local, *g = m->nodes[3].local;
    assert_float_equal(p[12], 1.0f, 1e-6f);
    assert_float_equal(p[13], 2.0f, 1e-6f);
    assert_float_equal(p[14], 3.0f, 1e-6f);
    assert_float_equal(c[0], 2.0f, 1e-6f);
    assert_float_equal(c[5], 2.0f, 1e-6f);
    assert_float_equal(c[10], 2.0f, 1e-6f);
    assert_float_equal(g[0], 0.0f, 1e-6f);    /* x axis → -z: column 0 = (0, 0, -1) */
    assert_float_equal(g[2], -1.0f, 1e-6f);
    assert_float_equal(m->nodes[4].local[12], 5.0f, 1e-6f);
    /* One mesh placed twice: both nodes list the same two primitives. */
    assert_memory_equal(m->nodes[2].primitives, m->nodes[3].primitives, 2 * sizeof(uint32_t));
    assert_int_equal(m->primitive_count, 3);
    assert_true(ob_test_log_has("features.gltf", "optional glTF extension ignored",
                                "KHR_materials_emissive_strength", NULL));
    ob_model_close(m);
}

static void features_keep_every_material_field(void **state)
{
    (void)state;
    ob_model *m = open_ok(DATA "features.gltf", true);
    const ob_model_material *mk = material_named(m, "masked");
    const float base[4] = {0.5f, 0.25f, 1.0f, 0.8f}, em[3] = {0.1f, 0.2f, 0.3f};
    for (int k = 0; k < 4; k++) assert_float_equal(mk->base_color[k], base[k], 1e-6f);
    for (int k = 0; k < 3; k++) assert_float_equal(mk->emissive[k], em[k], 1e-6f);
    assert_float_equal(mk->metallic, 0.2f, 1e-6f);
    assert_float_equal(mk->roughness, 0.7f, 1e-6f);
    assert_int_equal(mk->alpha_mode, OB_MODEL_ALPHA_MASK);
    assert_float_equal(mk->alpha_cutoff, 0.3f, 1e-6f);
    assert_true(mk->double_sided);
    assert_float_equal(mk->normal_scale, 0.5f, 1e-6f);
    assert_float_equal(mk->occlusion_strength, 0.25f, 1e-6f);
    /* texture 0 = embedded "dot" with sampler 0, texture 1 = checker.png, no sampler */
    const ob_model_texture *t0[3] = {&mk->base_color_texture, &mk->normal_texture, &mk->emissive_texture};
    const ob_model_texture *t1[2] = {&mk->metallic_roughness_texture, &mk->occlusion_texture};
    for (int i = 0; i < 3; i++) {
        assert_true(t0[i]->image >= 0);
        assert_int_equal(t0[i]->image, mk->base_color_texture.image);
        assert_int_equal(t0[i]->uv_set, 0);
        assert_int_equal(t0[i]->sampler.mag_filter, 9728);
        assert_int_equal(t0[i]->sampler.min_filter, 9987);
        assert_int_equal(t0[i]->sampler.wrap_s, 33071);
        assert_int_equal(t0[i]->sampler.wrap_t, 33648);
    }
    for (int i = 0; i < 2; i++) {
        assert_int_equal(t1[i]->image, mk->metallic_roughness_texture.image);
        assert_int_equal(t1[i]->sampler.mag_filter, 0);
        assert_int_equal(t1[i]->sampler.wrap_s, 10497);
        assert_int_equal(t1[i]->sampler.wrap_t, 10497);
    }
    /* Embedded (a data URI) vs external, each listed once. */
    assert_int_equal(m->image_count, 2);
    const ob_model_image *dot = &m->images[mk->base_color_texture.image];
    const ob_model_image *checker = &m->images[mk->metallic_roughness_texture.image];
    assert_string_equal(dot->name, "dot");
    assert_null(dot->path);
    assert_true(dot->size > 8);
    assert_memory_equal(dot->data, "\x89PNG", 4);
    assert_null(checker->data);
    assert_true(ends_with(checker->path, "tests/data/models/checker.png"));

    const ob_model_material *bl = material_named(m, "blended");
    assert_int_equal(bl->alpha_mode, OB_MODEL_ALPHA_BLEND);
    assert_float_equal(bl->base_color[3], 0.5f, 1e-6f);
    assert_float_equal(bl->metallic, 1.0f, 0.0f);    /* glTF defaults */
    assert_float_equal(bl->roughness, 1.0f, 0.0f);
    assert_float_equal(bl->alpha_cutoff, 0.5f, 0.0f);
    assert_false(bl->double_sided);
    assert_int_equal(bl->normal_texture.image, mk->metallic_roughness_texture.image);
    assert_int_equal(bl->base_color_texture.image, -1);
    const ob_model_material *pl = material_named(m, "plain");
    assert_int_equal(pl->alpha_mode, OB_MODEL_ALPHA_OPAQUE);
    assert_int_equal(pl->normal_texture.image, -1);
    ob_model_close(m);
}

static void features_carry_colours_and_tangents(void **state)
{
    (void)state;
    for (int flip = 0; flip < 2; flip++) {
        ob_model *m = open_ok(DATA "features.gltf", flip);
        /* quad-0: the file's TANGENT (0,1,0,-1) and COLOR_0 per corner. */
        const ob_model_primitive *a = primitive_named(m, "quad-0");
        assert_non_null(a->mesh.tangents);
        assert_non_null(a->mesh.colors);
        for (uint32_t v = 0; v < a->mesh.vertex_count; v++) {
            const float want[4] = {0, 1, 0, -1};
            assert_memory_equal(a->mesh.tangents[v], want, sizeof want);
            const float *pos = a->mesh.vertices[v].position;
            /* corners (-1,-1) red, (1,-1) green, (1,1) blue at alpha 0.5, (-1,1) white */
            uint8_t expect[4] = {255, 255, 255, 255};
            if (pos[0] < 0 && pos[1] < 0) memcpy(expect, (uint8_t[4]){255, 0, 0, 255}, 4);
            if (pos[0] > 0 && pos[1] < 0) memcpy(expect, (uint8_t[4]){0, 255, 0, 255}, 4);
            if (pos[0] > 0 && pos[1] > 0) memcpy(expect, (uint8_t[4]){0, 0, 255, 128}, 4);
            assert_memory_equal(a->mesh.colors[v], expect, 4);
            /* uv: the file's glTF uv with flip_uv, mirrored without it */
            float v_file = pos[1] > 0 ? 0.0f : 1.0f;
            assert_float_equal(a->mesh.vertices[v].uv[1], flip ? v_file : 1.0f - v_file, 1e-6f);
        }
        /* quad-1: generated. The image stands upright seen from +Z, so the
         * tangent is +X and the bitangent (top of the image) +Y =
         * cross(+Z, +X): w = +1, whichever way the uv run. */
        const ob_model_primitive *b = primitive_named(m, "quad-1");
        assert_non_null(b->mesh.tangents);
        assert_null(b->mesh.colors);
        for (uint32_t v = 0; v < b->mesh.vertex_count; v++) {
            const float *t = b->mesh.tangents[v];
            assert_float_equal(t[0], 1.0f, 1e-5f);
            assert_float_equal(t[1], 0.0f, 1e-5f);
            assert_float_equal(t[2], 0.0f, 1e-5f);
            assert_float_equal(t[3], 1.0f, 0.0f);
        }
        const ob_model_primitive *tri = primitive_named(m, "tri");
        assert_null(tri->mesh.tangents);   /* no normal map */
        assert_null(tri->mesh.colors);
        ob_model_close(m);
    }
}

static void obj_mtl_maps_to_metallic_roughness(void **state)
{
    (void)state;
    ob_test_log_clear();
    ob_model *m = open_ok(DATA "mtl_quad.obj", true);
    expect_well_formed(m);
    /* newmtl bumpy: Kd 0.2 0.4 0.6, Ke 0.5 0.25 0, Ns 98, d 0.5, map_Kd
     * checker.png, map_Bump -bm 0.75 normal.png (an RGB normal map). */
    const ob_model_material *b = material_named(m, "bumpy");
    const float base[4] = {0.2f, 0.4f, 0.6f, 0.5f}, em[3] = {0.5f, 0.25f, 0.0f};
    for (int k = 0; k < 4; k++) assert_float_equal(b->base_color[k], base[k], 1e-6f);
    for (int k = 0; k < 3; k++) assert_float_equal(b->emissive[k], em[k], 1e-6f);
    assert_int_equal(b->alpha_mode, OB_MODEL_ALPHA_BLEND);
    assert_float_equal(b->metallic, 0.0f, 0.0f);
    assert_float_equal(b->roughness, (float)pow(2.0 / 100.0, 0.25), 1e-5f);
    assert_float_equal(b->normal_scale, 0.75f, 1e-6f);
    assert_true(ends_with(m->images[b->base_color_texture.image].path, "/checker.png"));
    assert_true(ends_with(m->images[b->normal_texture.image].path, "/normal.png"));
    assert_non_null(primitive_named(m, "bumpy")->mesh.tangents);
    /* newmtl heighty: Ns 0, bump height.png (grey, one channel): a height
     * map, not used as a normal map. */
    const ob_model_material *h = material_named(m, "heighty");
    assert_float_equal(h->roughness, 1.0f, 1e-6f);
    assert_int_equal(h->alpha_mode, OB_MODEL_ALPHA_OPAQUE);
    assert_int_equal(h->normal_texture.image, -1);
    assert_null(primitive_named(m, "heighty")->mesh.tangents);
    assert_true(ob_test_log_has("mtl_quad.obj", "heighty", "height.png", "height map", NULL));
    ob_model_close(m);
}

/* --------------------------------------------------------- bad files */

static void refuses_required_unknown_extension(void **state)
{
    (void)state;
    expect_refused(DATA "requires_unknown.gltf", OB_ERR_UNSUPPORTED, "refused", "KHR_imaginary_feature");
    assert_false(ob_test_log_has("KHR_materials_unlit", "Obelisk does not support", NULL));
    expect_refused(DATA "requires_unknown.glb", OB_ERR_UNSUPPORTED, "refused", "KHR_imaginary_feature");
    if (have_model(MODELS "glTF2/draco/2CylinderEngine.gltf"))
        expect_refused(MODELS "glTF2/draco/2CylinderEngine.gltf", OB_ERR_UNSUPPORTED, "refused",
                       "KHR_draco_mesh_compression");
}

static void missing_texture_file_keeps_factors(void **state)
{
    (void)state;
    ob_test_log_clear();
    ob_model *m = open_ok(DATA "missing_texture.gltf", true);
    const ob_model_material *lost = material_named(m, "lost");
    assert_int_equal(lost->base_color_texture.image, -1);
    assert_int_equal(m->image_count, 0);
    assert_true(ob_test_log_has("missing_texture.gltf", "material 0 'lost'", "baseColorTexture",
                                "does_not_exist.png", "not found", NULL));
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 1);   /* once, not per assimp slot */
    ob_model_close(m);
}

static void refuses_out_of_range_indices(void **state)
{
    (void)state;
    /* assimp's glTF reader refuses the index itself, naming the mesh. */
    expect_refused(DATA "index_out_of_range.gltf", OB_ERR_PARSE, "assimp could not read", "\"tri\"");
    /* A PLY passes indices through: our raw check names the mesh and face. */
    char dir[] = "/tmp/ob_test_model_open_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[96];
    snprintf(path, sizeof path, "%s/oob.ply", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
          "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
          "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", f);
    fclose(f);
    expect_refused(path, OB_ERR_BAD_MODEL, "mesh 0", "index 2 = 9 out of range (3 vertices)");
    remove(path);
    rmdir(dir);
}

/* The extension scan sees garbage first: whatever it is, no crash, and
 * either assimp's verdict or a refusal with a message. */
static void scan_survives_garbage(void **state)
{
    (void)state;
    char dir[] = "/tmp/ob_test_model_open_XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const struct { const char *name, *text; size_t size; } cases[] = {
        {"cut.gltf", "{\"extensionsRequired\": [\"KHR_x\"", 0},
        {"deep.gltf", NULL, 0},   /* 5000 nested arrays, filled below */
        {"nonstring.gltf", "{\"extensionsRequired\": [1, {}], \"asset\": {}}", 0},
        {"escapes.gltf", "{\"a\\\"b\": \"\\u00e9\\n\", \"extensionsRequired\": [\"K\\u0041\"]}", 0},
        {"notjson.gltf", "\x01\x02garbage", 0},
        {"lying.glb", "glTF\x02\0\0\0\xff\xff\0\0\xff\xff\xff\x7fJSON{}", 22},
        {"short.glb", "glTF\x02\0\0\0", 8},
    };
    char deep[10002];
    for (int i = 0; i < 5000; i++) deep[i] = '[';
    for (int i = 0; i < 5000; i++) deep[5000 + i] = ']';
    deep[10000] = '\0';
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[96];
        snprintf(path, sizeof path, "%s/%s", dir, cases[i].name);
        const char *text = cases[i].text ? cases[i].text : deep;
        size_t size = cases[i].size ? cases[i].size : strlen(text);
        FILE *f = fopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(text, 1, size, f), size);
        fclose(f);
        ob_model *m = NULL;
        ob_test_log_clear();
        ob_result r = ob_model_open(&(ob_model_desc){.path = path}, &m);
        assert_int_not_equal(r, OB_OK);
        assert_null(m);
        assert_true(ob_test_log_has(path, NULL));
        /* "K\u0041" is decoded as assimp's JSON reader decodes it: "KA" (so
         * "sk\u0069ns" is a skin to the scan as it is to assimp). */
        if (strcmp(cases[i].name, "escapes.gltf") == 0)
            assert_true(ob_test_log_has("refused", "KA", NULL));
        remove(path);
    }
    rmdir(dir);
}

static void bad_arguments_and_missing_file(void **state)
{
    (void)state;
    ob_model *m = (ob_model *)1;
    assert_int_equal(ob_model_open(NULL, &m), OB_ERR_INVALID_ARGUMENT);
    assert_null(m);
    assert_int_equal(ob_model_open(&(ob_model_desc){.path = DATA "features.gltf"}, NULL),
                     OB_ERR_INVALID_ARGUMENT);
    m = (ob_model *)1;
    assert_int_equal(ob_model_open(&(ob_model_desc){0}, &m), OB_ERR_INVALID_ARGUMENT);
    assert_null(m);
    expect_refused(DATA "no_such_model.gltf", OB_ERR_IO, "cannot open model file", NULL);
    ob_model_close(NULL);
}

/* Every allocation of an open fails in turn: an error, nothing leaked. */
static void survives_every_allocation_failure(void **state)
{
    (void)state;
    const char *files[] = {DATA "features.gltf", DATA "mtl_quad.obj"};
    ob_test_log_set_echo(false);
    for (int f = 0; f < 2; f++) {
        ob_model *m;
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        assert_int_equal(ob_model_open(&(ob_model_desc){.path = files[f]}, &m), OB_OK);
        uint64_t points = ob_fault_count(OB_FAULT_HOST_ALLOC);
        ob_model_close(m);
        assert_true(points >= 10);
        uint64_t failed = 0;
        for (uint64_t n = 1; n <= points; n++) {
            ob_heap_stats before = ob_heap_stats_now();
            ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
            ob_result r = ob_model_open(&(ob_model_desc){.path = files[f]}, &m);
            ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
            if (r == OB_OK) {   /* a soft path: the height-map probe could not decode */
                ob_model_close(m);
            } else {
                assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
                assert_null(m);
                failed++;
            }
            if (ob_heap_stats_now().live_blocks != before.live_blocks)
                fail_msg("%s: allocation %llu failing leaks %lld blocks", files[f],
                         (unsigned long long)n,
                         (long long)(ob_heap_stats_now().live_blocks - before.live_blocks));
        }
        assert_true(failed * 2 > points);
    }
    ob_test_log_set_echo(true);
}

/* ------------------------------------------------------ package models */

static char *read_text(const char *path, size_t *out_size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *s = malloc((size_t)n + 1);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    if (out_size) *out_size = (size_t)n;
    return s;
}

/* The glTF JSON of a .gltf or .glb (its JSON chunk). */
static cJSON *read_gltf_json(const char *path)
{
    size_t size;
    char *s = read_text(path, &size);
    cJSON *j;
    if (size > 20 && memcmp(s, "glTF", 4) == 0) {
        uint32_t len;
        memcpy(&len, s + 12, 4);
        j = cJSON_ParseWithLength(s + 20, len);
    } else {
        j = cJSON_Parse(s);
    }
    free(s);
    assert_non_null(j);
    return j;
}

static double json_num(const cJSON *obj, const char *key, double fallback)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    return cJSON_IsNumber(v) ? v->valuedouble : fallback;
}

/* Every named material of the JSON against ours: factors, alpha mode,
 * double-sidedness and which textures exist. */
static void expect_materials_match_json(const ob_model *m, const cJSON *doc)
{
    const cJSON *mat;
    uint32_t checked = 0;
    cJSON_ArrayForEach(mat, cJSON_GetObjectItemCaseSensitive(doc, "materials")) {
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(mat, "name");
        if (!cJSON_IsString(name)) continue;
        const ob_model_material *ours = material_named(m, name->valuestring);
        const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(mat, "pbrMetallicRoughness");
        const cJSON *base = cJSON_GetObjectItemCaseSensitive(pbr, "baseColorFactor");
        for (int k = 0; k < 4; k++) {
            double want = base ? cJSON_GetArrayItem(base, k)->valuedouble : 1.0;
            assert_float_equal(ours->base_color[k], want, 1e-6);
        }
        assert_float_equal(ours->metallic, json_num(pbr, "metallicFactor", 1.0), 1e-6);
        assert_float_equal(ours->roughness, json_num(pbr, "roughnessFactor", 1.0), 1e-6);
        const cJSON *mode = cJSON_GetObjectItemCaseSensitive(mat, "alphaMode");
        uint32_t want_mode = !cJSON_IsString(mode) ? 0 : strcmp(mode->valuestring, "MASK") == 0 ? 1
                             : strcmp(mode->valuestring, "BLEND") == 0 ? 2 : 0;
        assert_int_equal(ours->alpha_mode, want_mode);
        assert_int_equal(ours->double_sided, cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(mat, "doubleSided")));
        assert_int_equal(ours->normal_texture.image >= 0,
                         cJSON_HasObjectItem(mat, "normalTexture"));
        assert_int_equal(ours->base_color_texture.image >= 0,
                         cJSON_HasObjectItem(pbr, "baseColorTexture"));
        assert_int_equal(ours->metallic_roughness_texture.image >= 0,
                         cJSON_HasObjectItem(pbr, "metallicRoughnessTexture"));
        assert_int_equal(ours->emissive_texture.image >= 0, cJSON_HasObjectItem(mat, "emissiveTexture"));
        checked++;
    }
    assert_true(checked > 0);
}

static void box_textured_embedded_and_external(void **state)
{
    (void)state;
    const char *glb = MODELS "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
    const char *gltf = MODELS "glTF2/BoxTextured-glTF/BoxTextured.gltf";
    if (!have_model(glb) || !have_model(gltf)) return;
    for (int i = 0; i < 2; i++) {
        const char *path = i ? gltf : glb;
        ob_model *m = open_ok(path, true);
        expect_well_formed(m);
        cJSON *doc = read_gltf_json(path);
        expect_materials_match_json(m, doc);
        /* nodes[0] (a matrix) holds nodes[1] (the mesh): under nodes[0]. */
        assert_int_equal(m->node_count, (uint32_t)cJSON_GetArraySize(cJSON_GetObjectItem(doc, "nodes")));
        assert_int_equal(m->nodes[1].parent, 0);
        assert_int_equal(m->nodes[1].primitive_count, 1);
        const float *root = m->nodes[0].local;   /* matrix [1,0,0,0, 0,0,-1,0, 0,1,0,0, 0,0,0,1] */
        const cJSON *matrix = cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "nodes"), 0), "matrix");
        for (int k = 0; k < 16; k++) assert_float_equal(root[k], cJSON_GetArrayItem(matrix, k)->valuedouble, 1e-6);
        const ob_model_material *tex = material_named(m, "Texture");
        const cJSON *sampler = cJSON_GetArrayItem(cJSON_GetObjectItem(doc, "samplers"), 0);
        assert_int_equal(tex->base_color_texture.sampler.mag_filter, (uint32_t)json_num(sampler, "magFilter", 0));
        assert_int_equal(tex->base_color_texture.sampler.min_filter, (uint32_t)json_num(sampler, "minFilter", 0));
        assert_int_equal(tex->base_color_texture.sampler.wrap_s, (uint32_t)json_num(sampler, "wrapS", 10497));
        assert_int_equal(tex->base_color_texture.sampler.wrap_t, (uint32_t)json_num(sampler, "wrapT", 10497));
        assert_int_equal(m->image_count, 1);
        const ob_model_image *img = &m->images[tex->base_color_texture.image];
        if (i == 0) {   /* .glb: the PNG in a buffer view, as bytes */
            assert_null(img->path);
            assert_memory_equal(img->data, "\x89PNG", 4);
        } else {        /* .gltf: "CesiumLogoFlat.png" next to it */
            assert_null(img->data);
            assert_string_equal(img->path, MODELS "glTF2/BoxTextured-glTF/CesiumLogoFlat.png");
        }
        cJSON_Delete(doc);
        ob_model_close(m);
    }
}

static void engine_keeps_its_hierarchy(void **state)
{
    (void)state;
    const char *path = MODELS "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb";
    if (!have_model(path)) return;
    ob_model *m = open_ok(path, true);
    expect_well_formed(m);
    cJSON *doc = read_gltf_json(path);
    /* Two scene roots (nodes 81 and 0): assimp's ROOT above every glTF node. */
    uint32_t nodes = (uint32_t)cJSON_GetArraySize(cJSON_GetObjectItem(doc, "nodes"));
    assert_int_equal(m->node_count, nodes + 1);
    assert_string_equal(m->nodes[0].name, "ROOT");
    uint32_t primitives = 0, placements = 0, deepest = 0;
    const cJSON *mesh;
    cJSON_ArrayForEach(mesh, cJSON_GetObjectItem(doc, "meshes"))
        primitives += (uint32_t)cJSON_GetArraySize(cJSON_GetObjectItem(mesh, "primitives"));
    assert_int_equal(m->primitive_count, primitives);
    for (uint32_t i = 0; i < m->node_count; i++) {
        placements += m->nodes[i].primitive_count;
        uint32_t depth = 0;
        for (int32_t p = m->nodes[i].parent; p >= 0; p = m->nodes[p].parent) depth++;
        if (depth > deepest) deepest = depth;
    }
    assert_int_equal(placements, 115);   /* as ob_model_load_mesh's merged instances */
    assert_true(deepest >= 3);
    expect_materials_match_json(m, doc);
    cJSON_Delete(doc);
    ob_model_close(m);
}

static void clear_coat_normal_maps_get_tangents(void **state)
{
    (void)state;
    const char *path = MODELS "glTF2/ClearCoat-glTF/ClearCoatTest.gltf";
    if (!have_model(path)) return;
    ob_model *m = open_ok(path, true);
    expect_well_formed(m);   /* tangents unit, w ±1, ⟂ normal, exactly where normal maps are */
    cJSON *doc = read_gltf_json(path);
    expect_materials_match_json(m, doc);
    cJSON_Delete(doc);
    uint32_t with_tangents = 0;
    for (uint32_t i = 0; i < m->primitive_count; i++) with_tangents += m->primitives[i].mesh.tangents != NULL;
    assert_true(with_tangents > 0);
    const ob_model_material *coating = material_named(m, "Partial_Coating");
    assert_int_equal(coating->alpha_mode, OB_MODEL_ALPHA_BLEND);
    ob_model_close(m);
}

/* The JSON's KHR_texture_transform of a texture info (identity without). */
static void json_transform(const cJSON *info, double offset[2], double *rotation, double scale[2])
{
    const cJSON *ext = cJSON_GetObjectItem(cJSON_GetObjectItem(info, "extensions"), "KHR_texture_transform");
    const cJSON *o = cJSON_GetObjectItem(ext, "offset"), *sc = cJSON_GetObjectItem(ext, "scale");
    offset[0] = o ? cJSON_GetArrayItem(o, 0)->valuedouble : 0.0;
    offset[1] = o ? cJSON_GetArrayItem(o, 1)->valuedouble : 0.0;
    scale[0] = sc ? cJSON_GetArrayItem(sc, 0)->valuedouble : 1.0;
    scale[1] = sc ? cJSON_GetArrayItem(sc, 1)->valuedouble : 1.0;
    *rotation = json_num(ext, "rotation", 0.0);
}

/* KHR_texture_transform comes through assimp's aiUVTransform as the file
 * wrote it (offset, rotation, scale), and as the matrix that maps the
 * meshes' uv: with flip_uv the glTF uv themselves, without it assimp's
 * mirrored v. Every material of TextureTransformTest against its JSON. */
static void texture_transform_as_authored(void **state)
{
    (void)state;
    const char *path = MODELS "glTF2/textureTransform/TextureTransformTest.gltf";
    if (!have_model(path)) return;
    cJSON *doc = read_gltf_json(path);
    for (int flip = 1; flip >= 0; flip--) {
        ob_model *m = open_ok(path, flip != 0);
        expect_well_formed(m);
        uint32_t transformed = 0;
        const cJSON *mat;
        cJSON_ArrayForEach(mat, cJSON_GetObjectItem(doc, "materials")) {
            const ob_model_material *ours = material_named(m, cJSON_GetObjectItem(mat, "name")->valuestring);
            const cJSON *info = cJSON_GetObjectItem(cJSON_GetObjectItem(mat, "pbrMetallicRoughness"), "baseColorTexture");
            double off[2], rot, sc[2];
            json_transform(info, off, &rot, sc);
            const ob_model_uv_transform *t = &ours->base_color_texture.transform;
            bool identity = off[0] == 0 && off[1] == 0 && rot == 0 && sc[0] == 1 && sc[1] == 1;
            assert_int_equal(t->present, !identity);
            transformed += t->present;
            assert_float_equal(t->offset[0], off[0], 1e-5);
            assert_float_equal(t->offset[1], off[1], 1e-5);
            assert_float_equal(t->rotation, rot, 1e-5);
            assert_float_equal(t->scale[0], sc[0], 1e-5);
            assert_float_equal(t->scale[1], sc[1], 1e-5);
            /* The matrix at a few points against the spec's T·R·S in glTF uv. */
            const double pts[3][2] = {{0, 0}, {1, 0}, {0.25, 0.75}};
            for (int k = 0; k < 3; k++) {
                double u = pts[k][0], v = pts[k][1];
                double gv = flip ? v : 1.0 - v;   /* the file's v of this mesh uv */
                double c = cos(rot), s = sin(rot);
                double gu2 = c * sc[0] * u + s * sc[1] * gv + off[0];
                double gv2 = -s * sc[0] * u + c * sc[1] * gv + off[1];
                double want_v = flip ? gv2 : 1.0 - gv2;
                assert_float_equal(t->uv[0] * u + t->uv[1] * v + t->uv[2], gu2, 1e-5);
                assert_float_equal(t->uv[3] * u + t->uv[4] * v + t->uv[5], want_v, 1e-5);
            }
            assert_int_equal(ours->base_color_texture.uv_set, 0);
        }
        assert_int_equal(transformed, 6);
        ob_model_close(m);
    }
    cJSON_Delete(doc);
}

/* KHR_texture_transform's texCoord override is what assimp 5.2 drops: the
 * glTF scan names the material, the texture and the set it asked for, once
 * per material, and the model still opens. */
static void texcoord_override_is_named(void **state)
{
    (void)state;
    char dir[] = "/tmp/ob_test_model_open_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[96];
    snprintf(path, sizeof path, "%s/override.gltf", dir);
    static const char text[] =
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
        " \"nodes\": [{\"name\": \"tri\", \"mesh\": 0}],"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 1}]}],"
        " \"materials\": [{\"name\": \"plain\"}, {\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0,"
        " \"extensions\": {\"KHR_texture_transform\": {\"offset\": [0.5, 0], \"texCoord\": 1}}}},"
        " \"occlusionTexture\": {\"index\": 0, \"extensions\": {\"KHR_texture_transform\": {\"texCoord\": 1}}},"
        " \"name\": \"shifted\"}],"
        " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"absent.png\"}],"
        " \"buffers\": [{\"byteLength\": 42, \"uri\": \"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA\"}],"
        " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36},"
        " {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6}],"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\","
        " \"min\": [0, 0, 0], \"max\": [1, 1, 0]}, {\"bufferView\": 1, \"componentType\": 5123, \"count\": 3,"
        " \"type\": \"SCALAR\"}], \"extensionsUsed\": [\"KHR_texture_transform\"],"
        " \"extensionsRequired\": [\"KHR_texture_transform\"]}";
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, sizeof text - 1, f), sizeof text - 1);
    fclose(f);
    ob_test_log_clear();
    ob_model *m = open_ok(path, true);   /* required, and honoured */
    assert_true(ob_test_log_has("material 1 'shifted' baseColorTexture", "texCoord override",
                                "TEXCOORD_1", NULL));
    assert_false(ob_test_log_has("occlusionTexture", "texCoord override", NULL));   /* once per material */
    assert_false(ob_test_log_has("'plain'", NULL));
    assert_false(ob_test_log_has("optional glTF extension", NULL));
    ob_model_close(m);
    remove(path);
    rmdir(dir);
}

/* KHR_materials_clearcoat: factors and the three textures, per material of
 * ClearCoatTest, against the JSON. */
static void clearcoat_as_authored(void **state)
{
    (void)state;
    const char *path = MODELS "glTF2/ClearCoat-glTF/ClearCoatTest.gltf";
    if (!have_model(path)) return;
    ob_model *m = open_ok(path, true);
    cJSON *doc = read_gltf_json(path);
    uint32_t coated = 0;
    const cJSON *mat;
    cJSON_ArrayForEach(mat, cJSON_GetObjectItem(doc, "materials")) {
        const ob_model_material *ours = material_named(m, cJSON_GetObjectItem(mat, "name")->valuestring);
        const cJSON *cc = cJSON_GetObjectItem(cJSON_GetObjectItem(mat, "extensions"), "KHR_materials_clearcoat");
        assert_float_equal(ours->clearcoat, json_num(cc, "clearcoatFactor", 0.0), 1e-6);
        assert_float_equal(ours->clearcoat_roughness, json_num(cc, "clearcoatRoughnessFactor", 0.0), 1e-6);
        assert_int_equal(ours->clearcoat_texture.image >= 0, cJSON_HasObjectItem(cc, "clearcoatTexture"));
        assert_int_equal(ours->clearcoat_roughness_texture.image >= 0,
                         cJSON_HasObjectItem(cc, "clearcoatRoughnessTexture"));
        assert_int_equal(ours->clearcoat_normal_texture.image >= 0, cJSON_HasObjectItem(cc, "clearcoatNormalTexture"));
        assert_float_equal(ours->clearcoat_normal_scale,
                           json_num(cJSON_GetObjectItem(cc, "clearcoatNormalTexture"), "scale", 1.0), 1e-6);
        coated += cc != NULL;
    }
    assert_int_equal(coated, 6);
    /* The coat's textures name the files the JSON's images do. */
    const ob_model_material *partial = material_named(m, "Partial_Coated");
    assert_non_null(strstr(m->images[partial->clearcoat_texture.image].path, "PartialCoating.png"));
    const ob_model_material *rough = material_named(m, "RoughVariations_Coated");
    assert_non_null(strstr(m->images[rough->clearcoat_roughness_texture.image].path, "RoughnessStripes.png"));
    const ob_model_material *wrap = material_named(m, "CoatNorm_Coated");
    assert_non_null(strstr(m->images[wrap->clearcoat_normal_texture.image].path, "PlasticWrap_normals.jpg"));
    cJSON_Delete(doc);
    ob_model_close(m);
}

/* TEXCOORD_1: BoxTexcoords' second uv set reaches the mesh (flipped with
 * the first), and a texture reading it keeps uv_set 1. */
static void second_uv_set_is_read(void **state)
{
    (void)state;
    const char *path = MODELS "glTF2/BoxTexcoords-glTF/boxTexcoords.gltf";
    if (!have_model(path)) return;
    ob_model *a = open_ok(path, true), *b = open_ok(path, false);
    expect_well_formed(a);
    uint32_t with_uv1 = 0;
    for (uint32_t i = 0; i < a->primitive_count; i++) {
        const ob_mesh *ma = &a->primitives[i].mesh, *mb = &b->primitives[i].mesh;
        if (!ma->uv1) continue;
        with_uv1++;
        assert_non_null(mb->uv1);
        for (uint32_t v = 0; v < ma->vertex_count; v++) {
            assert_float_equal(ma->uv1[v][0], mb->uv1[v][0], 1e-6);
            assert_float_equal(ma->uv1[v][1], 1.0f - mb->uv1[v][1], 1e-6);
        }
    }
    assert_true(with_uv1 > 0);
    uint32_t set1 = 0;
    for (uint32_t i = 0; i < a->material_count; i++) {
        const ob_model_texture *t = &a->materials[i].base_color_texture;
        for (int s = 0; s < 5; s++, t++) set1 += t->image >= 0 && t->uv_set == 1;
    }
    assert_true(set1 > 0);
    ob_model_close(a);
    ob_model_close(b);
}

static void obj_and_ply_from_the_package(void **state)
{
    (void)state;
    const char *spider = MODELS "OBJ/spider.obj", *ply = MODELS "PLY/float-color.ply";
    if (!have_model(spider) || !have_model(ply)) return;
    ob_model *m = open_ok(spider, true);
    expect_well_formed(m);
    /* spider.mtl: newmtl HLeibTex, Kd 0.690196 0.639216 0.615686, Ns 0,
     * map_Kd .\SpiderTex.jpg (a Windows path, next to the model). */
    const ob_model_material *h = material_named(m, "HLeibTex");
    assert_float_equal(h->base_color[0], 0.690196f, 1e-6f);
    assert_float_equal(h->base_color[2], 0.615686f, 1e-6f);
    assert_float_equal(h->roughness, 1.0f, 1e-6f);
    assert_true(ends_with(m->images[h->base_color_texture.image].path, "/SpiderTex.jpg"));
    assert_int_equal(m->image_count, 5);
    ob_model_close(m);

    /* float-color.ply: three vertices, colour 0 0 1 1 each. */
    m = open_ok(ply, true);
    expect_well_formed(m);
    assert_int_equal(m->primitive_count, 1);
    const ob_mesh *mesh = &m->primitives[0].mesh;
    assert_non_null(mesh->colors);
    for (uint32_t v = 0; v < mesh->vertex_count; v++)
        assert_memory_equal(mesh->colors[v], ((uint8_t[4]){0, 0, 255, 255}), 4);
    ob_model_close(m);
}

/* A format whose embedded skins are raw texels (assimp's aiTexel arrays,
 * mHeight != 0): the image arrives as a PNG that decodes, and HL1's
 * embedded BMP-named textures as bytes too. */
static void raw_embedded_texture_becomes_png(void **state)
{
    (void)state;
    const char *mdl = MODELS "MDL/MDL3 (3DGS A4)/minigun.MDL";
    const char *hl1 = MODELS "MDL/MDL (HL1)/chrome_sphere.mdl";
    if (!have_model(mdl) || !have_model(hl1)) return;
    for (int f = 0; f < 2; f++) {
        ob_model *m = open_ok(f ? hl1 : mdl, true);
        expect_well_formed(m);
        const ob_model_material *mat = &m->materials[m->primitives[0].material];
        assert_true(mat->base_color_texture.image >= 0);
        const ob_model_image *img = &m->images[mat->base_color_texture.image];
        assert_null(img->path);
        int w = 0, h = 0, n = 0;
        stbi_uc *px = stbi_load_from_memory(img->data, (int)img->size, &w, &h, &n, 4);
        if (!px) fail_msg("%s: embedded image '%s' (%zu bytes) does not decode", m->path, img->name, img->size);
        assert_true(w > 0 && h > 0);
        stbi_image_free(px);
        if (f == 0) assert_memory_equal(img->data, "\x89PNG", 4);   /* encoded here */
        ob_model_close(m);
    }
}

/* Opens may run on several threads at once ([any thread]): each thread's
 * models come out as a serial open makes them. */
typedef struct open_job { uint32_t nodes[2], primitives[2], images[2]; bool ok; } open_job;

static void *open_thread(void *arg)
{
    open_job *j = arg;
    const char *files[2] = {DATA "features.gltf", DATA "mtl_quad.obj"};
    j->ok = true;
    for (int round = 0; round < 4; round++) {
        for (int f = 0; f < 2; f++) {
            ob_model *m = NULL;
            if (ob_model_open(&(ob_model_desc){.path = files[f], .flip_uv = true}, &m) != OB_OK) {
                j->ok = false;
                continue;
            }
            j->ok = j->ok && m->node_count == j->nodes[f] && m->primitive_count == j->primitives[f] &&
                    m->image_count == j->images[f];
            ob_model_close(m);
        }
    }
    return NULL;
}

static void concurrent_opens_agree_with_serial_ones(void **state)
{
    (void)state;
    open_job serial = {0};
    const char *files[2] = {DATA "features.gltf", DATA "mtl_quad.obj"};
    for (int f = 0; f < 2; f++) {
        ob_model *m = open_ok(files[f], true);
        serial.nodes[f] = m->node_count;
        serial.primitives[f] = m->primitive_count;
        serial.images[f] = m->image_count;
        ob_model_close(m);
    }
    enum { THREADS = 4 };
    open_job jobs[THREADS];
    pthread_t threads[THREADS];
    for (int t = 0; t < THREADS; t++) {
        jobs[t] = serial;
        assert_int_equal(pthread_create(&threads[t], NULL, open_thread, &jobs[t]), 0);
    }
    for (int t = 0; t < THREADS; t++) {
        assert_int_equal(pthread_join(threads[t], NULL), 0);
        assert_true(jobs[t].ok);
    }
}

/* KHR_lights_punctual (tests/data/models/make_models.py, lights.gltf): each
 * light lands on the node that names it, intensity split back out of
 * assimp's colour, glTF's range and half-angles kept; a directional light
 * too. */
static void gltf_lights_land_on_their_nodes(void **state)
{
    (void)state;
    ob_model *m = open_ok(DATA "lights.gltf", true);
    assert_int_equal(m->light_count, 3);
    const char *nodes[3] = {"lamp_node", "torch_node", "sky_node"};
    const ob_light_type types[3] = {OB_LIGHT_POINT, OB_LIGHT_SPOT, OB_LIGHT_DIRECTIONAL};
    for (uint32_t i = 0; i < 3; i++) {
        assert_string_equal(m->nodes[m->lights[i].node].name, nodes[i]);
        assert_int_equal(m->lights[i].desc.type, types[i]);
    }
    const ob_light_desc *lamp = &m->lights[0].desc;
    assert_float_equal(lamp->intensity, 4.0, 1e-6);
    assert_float_equal(lamp->color[0], 1.0, 1e-6);
    assert_float_equal(lamp->color[1], 0.5, 1e-6);
    assert_float_equal(lamp->color[2], 0.25, 1e-6);
    assert_float_equal(lamp->range, 5.0, 1e-6);
    const ob_light_desc *torch = &m->lights[1].desc;
    assert_float_equal(torch->intensity, 2.0, 1e-6);
    assert_float_equal(torch->inner_angle, 0.25, 1e-6);
    assert_float_equal(torch->outer_angle, 0.5, 1e-6);
    assert_float_equal(torch->range, 0.0, 0.0);   /* none given: no cut-off */
    assert_float_equal(m->lights[2].desc.color[2], 1.0, 1e-6);
    assert_float_equal(m->lights[2].desc.intensity, 1.0, 1e-6);
    /* Read, so not reported as an ignored extension. */
    assert_false(ob_test_log_has("lights.gltf", "ignored", NULL));
    ob_model_close(m);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(features_keep_hierarchy_and_instancing),
        cmocka_unit_test(features_keep_every_material_field),
        cmocka_unit_test(features_carry_colours_and_tangents),
        cmocka_unit_test(obj_mtl_maps_to_metallic_roughness),
        cmocka_unit_test(refuses_required_unknown_extension),
        cmocka_unit_test(missing_texture_file_keeps_factors),
        cmocka_unit_test(refuses_out_of_range_indices),
        cmocka_unit_test(scan_survives_garbage),
        cmocka_unit_test(bad_arguments_and_missing_file),
        cmocka_unit_test(survives_every_allocation_failure),
        cmocka_unit_test(box_textured_embedded_and_external),
        cmocka_unit_test(engine_keeps_its_hierarchy),
        cmocka_unit_test(clear_coat_normal_maps_get_tangents),
        cmocka_unit_test(texture_transform_as_authored),
        cmocka_unit_test(clearcoat_as_authored),
        cmocka_unit_test(texcoord_override_is_named),
        cmocka_unit_test(second_uv_set_is_read),
        cmocka_unit_test(obj_and_ply_from_the_package),
        cmocka_unit_test(raw_embedded_texture_becomes_png),
        cmocka_unit_test(concurrent_opens_agree_with_serial_ones),
        cmocka_unit_test(gltf_lights_land_on_their_nodes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
