/* test_effect.c — render effects: standard shaders compile and build their
 * programs, pipelines are created once per target-format pair, broken shaders
 * are reported and survived, the pipeline cache round-trips through disk. */
#define _XOPEN_SOURCE 700
#include "ob_test.h"

#include <ftw.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_effect.h"
#include "ob_material.h"
#include "ob_params.h"

typedef struct fixture {
    ob_device *dev;
    ob_param_registry *reg;
    char dir[64];               /* private cache folder */
} fixture;

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

static int setup(void **state)
{
    static fixture f;
    f.dev = ob_test_device_create();
    ob_result r;
    f.reg = ob_param_registry_create(&(ob_param_registry_desc){.slot_count = 2}, &r);
    assert_non_null(f.reg);
    snprintf(f.dir, sizeof f.dir, "/tmp/ob-effect-test-XXXXXX");
    assert_non_null(mkdtemp(f.dir));
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    ob_test_assert_no_validation(f->dev);
    ob_param_registry_destroy(f->reg);
    ob_device_destroy(f->dev);
    nftw(f->dir, remove_entry, 8, FTW_DEPTH | FTW_PHYS);
    return 0;
}

static ob_effect_context *make_context(fixture *f, const char *sub)
{
    char dir[128];
    snprintf(dir, sizeof dir, "%s/%s", f->dir, sub);
    ob_result r;
    ob_effect_context *ctx = ob_effect_context_create(f->dev, f->reg, dir, &r);
    assert_non_null(ctx);
    assert_int_equal(r, OB_OK);
    return ctx;
}

/* Every standard effect and every lit variant compiles, builds its binding
 * plan and gets a pipeline for the targets it is used with. */
static void test_standard_effects_build(void **state)
{
    fixture *f = *state;
    ob_effect_context *ctx = make_context(f, "std");
    ob_result r;
    ob_material_library *lib = ob_material_library_create(ctx, NULL, &r);
    assert_non_null(lib);
    assert_int_equal(ob_effect_context_counters(ctx).variants_compiled, 0);

    const VkFormat rgba = VK_FORMAT_R8G8B8A8_UNORM, d32 = VK_FORMAT_D32_SFLOAT;
    static const struct {
        ob_std_effect kind;
        uint32_t variant;
        VkFormat color, depth;
        uint32_t resources;      /* set-1 bindings the program must have */
        bool push;               /* uses the PerDraw push constants */
    } cases[] = {
        {OB_STD_LIT, 0, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 0, true},
        {OB_STD_LIT, OB_VARIANT_SHADOWS, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 1, true},
        {OB_STD_LIT, OB_VARIANT_ENVMAP, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 1, true},
        {OB_STD_LIT, OB_VARIANT_SHADOWS | OB_VARIANT_ENVMAP, VK_FORMAT_R8G8B8A8_UNORM,
         VK_FORMAT_D32_SFLOAT, 2, true},
        {OB_STD_LIT, OB_VARIANT_BLENDED, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 0, true},
        {OB_STD_DEPTH, 0, VK_FORMAT_UNDEFINED, VK_FORMAT_D32_SFLOAT, 0, true},
        {OB_STD_PARABOLOID, 0, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 0, true},
        {OB_STD_UNLIT, 0, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 0, true},
        {OB_STD_OVERLAY, 0, VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_UNDEFINED, 0, true},
        {OB_STD_FULLSCREEN, 0, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_UNDEFINED, 1, false},
        {OB_STD_PARTICLES_SIM, 0, VK_FORMAT_UNDEFINED, VK_FORMAT_UNDEFINED, 1, false},
        {OB_STD_PARTICLES_DRAW, 0, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, 1, true},
    };
    (void)rgba, (void)d32;
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        ob_effect *e = ob_material_library_effect(lib, cases[i].kind, cases[i].variant, &r);
        if (!e) fail_msg("standard effect %u/%u failed: %s", cases[i].kind, cases[i].variant,
                         ob_result_name(r));
        const ob_program *prog = ob_effect_program(e);
        assert_non_null(prog);
        assert_int_equal(prog->resource_count, cases[i].resources);
        if (cases[i].push) assert_int_equal(prog->push_size, 128);
        else assert_int_equal(prog->push_size, 0);
        uint32_t id = 0;
        VkPipeline p = ob_effect_pipeline(e, cases[i].color, cases[i].depth, &id);
        if (!p) fail_msg("no pipeline for effect '%s'", ob_effect_name(e));
        assert_int_not_equal(id, 0);
        /* Asking again compiles nothing new. */
        assert_ptr_equal(ob_material_library_effect(lib, cases[i].kind, cases[i].variant, &r), e);
    }
    ob_effect *sim = ob_material_library_find_effect(lib, OB_STD_PARTICLES_SIM, 0);
    assert_true(ob_effect_is_compute(sim));
    uint32_t ls[3];
    ob_effect_local_size(sim, ls);
    assert_int_equal(ls[0], 64);
    assert_int_equal(ob_effect_program(sim)->bind_point, VK_PIPELINE_BIND_POINT_COMPUTE);
    /* The lit program's uniform blocks: PerView, PerMaterial, PbrMaterial
     * (the metallic-roughness factors LIT is mapped to) and PerViewLights
     * (the point and spot lights) in set 0. */
    assert_int_equal(ob_effect_program(ob_material_library_find_effect(lib, OB_STD_LIT, 0))->ubo_count, 4);

    ob_effect_counters c = ob_effect_context_counters(ctx);
    assert_int_equal(c.variants_compiled, OB_ARRAY_COUNT(cases));
    assert_int_equal(c.pipelines_created, OB_ARRAY_COUNT(cases));
    assert_int_equal(c.pipelines_failed, 0);
    ob_material_library_destroy(lib);
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(f->dev);
}

typedef struct race_arg {
    ob_effect *e;
    VkPipeline got;
    uint32_t id;
} race_arg;

static void *race_pipeline(void *p)
{
    race_arg *a = p;
    a->got = ob_effect_pipeline(a->e, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, &a->id);
    return NULL;
}

static const ob_effect_vertex_input standard_input = {
    .stride = 32,
    .attribute_count = 3,
    .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, VK_FORMAT_R32G32_SFLOAT, 24}},
};

/* A pipeline is created once per format pair, even when several recording
 * threads ask for it at the same moment, and reused afterwards. */
static void test_pipeline_once_per_format_pair(void **state)
{
    fixture *f = *state;
    ob_effect_context *ctx = make_context(f, "pairs");
    ob_result r;
    ob_effect *e = ob_effect_create(ctx, &(ob_effect_desc){
        .name = "pairs", .vertex = "pbr.vert", .fragment = "pbr.frag", .layout = &standard_input,
        .depth_test = true, .depth_write = true, .cull = VK_CULL_MODE_BACK_BIT}, &r);
    assert_non_null(e);
    assert_int_equal(ob_effect_pipeline_count(e), 0);   /* nothing until first use */

    race_arg args[4];
    pthread_t threads[4];
    for (int i = 0; i < 4; i++) {
        args[i] = (race_arg){.e = e};
        assert_int_equal(pthread_create(&threads[i], NULL, race_pipeline, &args[i]), 0);
    }
    for (int i = 0; i < 4; i++) pthread_join(threads[i], NULL);
    for (int i = 0; i < 4; i++) {
        assert_non_null(args[i].got);
        assert_ptr_equal(args[i].got, args[0].got);
        assert_int_equal(args[i].id, args[0].id);
    }
    assert_int_equal(ob_effect_context_counters(ctx).pipelines_created, 1);
    for (int i = 0; i < 100; i++)
        assert_ptr_equal(ob_effect_pipeline(e, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, NULL),
                         args[0].got);
    assert_int_equal(ob_effect_context_counters(ctx).pipelines_created, 1);

    uint32_t other_id;
    VkPipeline other = ob_effect_pipeline(e, VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_D32_SFLOAT,
                                          &other_id);
    assert_non_null(other);
    assert_ptr_not_equal(other, args[0].got);
    assert_int_not_equal(other_id, args[0].id);
    assert_int_equal(ob_effect_pipeline_count(e), 2);
    assert_int_equal(ob_effect_context_counters(ctx).pipelines_created, 2);
    ob_effect_destroy(e);
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(f->dev);
}

/* A shader with a syntax error: the effect fails with the file and line in
 * the log, and the engine goes on creating and using other effects. */
static void test_broken_shader_reported(void **state)
{
    fixture *f = *state;
    ob_effect_context *ctx = make_context(f, "broken");
    char path[128];
    snprintf(path, sizeof path, "%s/broken_effect.frag", f->dir);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs("#version 450\n"
          "layout(location = 0) out vec4 outColor;\n"
          "void main()\n"
          "{\n"
          "    outColor = vec4(1.0) +* ;\n"
          "}\n", fp);
    fclose(fp);

    ob_test_log_clear();
    ob_result r = OB_OK;
    ob_effect *bad = ob_effect_create(ctx, &(ob_effect_desc){
        .name = "broken", .vertex = "fullscreen.vert", .fragment = path}, &r);
    assert_null(bad);
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("broken_effect.frag:5", NULL));
    assert_true(ob_test_log_has("effect 'broken'", NULL));

    /* A missing file is an I/O error naming it. */
    bad = ob_effect_create(ctx, &(ob_effect_desc){.vertex = "no_such_shader.vert"}, &r);
    assert_null(bad);
    assert_int_equal(r, OB_ERR_IO);
    assert_true(ob_test_log_has("no_such_shader.vert", NULL));

    /* The engine keeps going. */
    ob_effect *good = ob_effect_create(ctx, &(ob_effect_desc){
        .name = "good", .vertex = "fullscreen.vert", .fragment = "fullscreen.frag"}, &r);
    assert_non_null(good);
    assert_non_null(ob_effect_pipeline(good, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_UNDEFINED, NULL));
    assert_int_equal(ob_effect_context_counters(ctx).variants_compiled, 1);
    ob_effect_destroy(good);
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(f->dev);
}

/* Wrong descriptions are refused with a message naming the problem. */
static void test_bad_desc_refused(void **state)
{
    fixture *f = *state;
    ob_effect_context *ctx = make_context(f, "bad");
    ob_result r;
    /* pbr.vert reads the normal (location 1): a position-only layout lacks it. */
    ob_effect_vertex_input position_only = {
        .stride = 12, .attribute_count = 1, .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}}};
    ob_test_log_clear();
    assert_null(ob_effect_create(ctx, &(ob_effect_desc){
        .name = "no-normal", .vertex = "pbr.vert", .fragment = "pbr.frag",
        .layout = &position_only}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("no-normal", "inNormal", "location 1", NULL));

    assert_null(ob_effect_create(ctx, &(ob_effect_desc){.name = "empty"}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_null(ob_effect_create(ctx, &(ob_effect_desc){
        .name = "mixed", .vertex = "pbr.vert", .compute = "particles.comp"}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    /* depth.vert only reads the position, so the same layout is enough there. */
    ob_effect *depth = ob_effect_create(ctx, &(ob_effect_desc){
        .vertex = "depth.vert", .layout = &position_only, .depth_test = true,
        .depth_write = true, .depth_bias_constant = -1.0f, .depth_bias_slope = -1.5f}, &r);
    assert_non_null(depth);
    assert_string_equal(ob_effect_name(depth), "depth.vert");
    assert_non_null(ob_effect_pipeline(depth, VK_FORMAT_UNDEFINED, VK_FORMAT_D32_SFLOAT, NULL));
    assert_int_equal(ob_effect_context_counters(ctx).variants_compiled, 1);
    ob_effect_destroy(depth);
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(f->dev);
}

static long file_size(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return -1;
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fclose(fp);
    return n;
}

static uint32_t build_lit_pipeline(ob_effect_context *ctx)
{
    ob_result r;
    ob_effect *e = ob_effect_create(ctx, &(ob_effect_desc){
        .name = "cached", .vertex = "pbr.vert", .fragment = "pbr.frag", .layout = &standard_input,
        .depth_test = true, .depth_write = true}, &r);
    assert_non_null(e);
    assert_non_null(ob_effect_pipeline(e, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, NULL));
    ob_effect_destroy(e);
    return ob_effect_context_counters(ctx).pipelines_created;
}

/* pipelines.bin is written when a context is destroyed and accepted by the
 * next one on the same device; a corrupt file is ignored with a log line. */
static void test_pipeline_cache_roundtrip(void **state)
{
    fixture *f = *state;
    ob_effect_context *first = make_context(f, "cache");
    char path[256];
    snprintf(path, sizeof path, "%s", ob_effect_context_cache_path(first));
    assert_true(strstr(path, "/cache/pipelines.bin") != NULL);
    assert_int_equal(ob_effect_context_counters(first).cache_loaded_bytes, 0);
    assert_int_equal(build_lit_pipeline(first), 1);
    ob_effect_context_destroy(first);
    long saved = file_size(path);
    assert_true(saved >= (long)sizeof(VkPipelineCacheHeaderVersionOne));

    ob_effect_context *second = make_context(f, "cache");
    ob_effect_counters c = ob_effect_context_counters(second);
    assert_int_equal(c.cache_loaded_bytes, (uint32_t)saved);
    assert_int_equal(build_lit_pipeline(second), 1);
    c = ob_effect_context_counters(second);
    /* lavapipe's VkPipelineCache is a stub: report what it says, assert nothing. */
    print_message("pipeline cache: %ld bytes saved and reloaded; creation feedback reports "
                  "%u of %u pipelines as cache hits\n", saved, c.pipelines_from_cache_hint,
                  c.pipelines_created);
    ob_effect_context_destroy(second);

    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs("definitely not a pipeline cache, but long enough to hold a header", fp);
    fclose(fp);
    ob_test_log_clear();
    ob_effect_context *third = make_context(f, "cache");
    assert_int_equal(ob_effect_context_counters(third).cache_loaded_bytes, 0);
    assert_true(ob_test_log_has("pipelines.bin", "ignored", NULL));
    assert_int_equal(build_lit_pipeline(third), 1);
    ob_effect_context_destroy(third);
    /* ...and replaced by a valid one. */
    ob_effect_context *fourth = make_context(f, "cache");
    assert_int_equal(ob_effect_context_counters(fourth).cache_loaded_bytes, (uint32_t)saved);
    ob_effect_context_destroy(fourth);
    ob_test_assert_no_validation(f->dev);
}

/* Every allocation and Vulkan object creation of effect creation can fail
 * without leaking or crashing, and the failure is reported. */
static void test_effect_creation_faults(void **state)
{
    fixture *f = *state;
    ob_effect_context *ctx = make_context(f, "faults");
    ob_effect_desc desc = {.name = "faulty", .vertex = "pbr.vert", .fragment = "pbr.frag",
                           .layout = &standard_input, .depth_test = true};
    ob_result r;
    /* Warm the compiler's cache, so the walk covers the effect's own work. */
    ob_effect *e = ob_effect_create(ctx, &desc, &r);
    assert_non_null(e);
    ob_effect_destroy(e);
    for (int kind = 0; kind < OB_FAULT_KIND_COUNT; kind++) {
        ob_fault_arm((ob_fault_kind)kind, 0);   /* unarmed: counts the calls */
        e = ob_effect_create(ctx, &desc, &r);
        assert_non_null(e);
        ob_effect_pipeline(e, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, NULL);
        uint64_t calls = ob_fault_count((ob_fault_kind)kind);
        ob_effect_destroy(e);
        for (uint64_t n = 1; n <= calls; n++) {
            ob_fault_arm((ob_fault_kind)kind, n);
            e = ob_effect_create(ctx, &desc, &r);
            if (e) {
                /* The fault may land in pipeline creation: then no pipeline. */
                ob_effect_pipeline(e, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_D32_SFLOAT, NULL);
                ob_effect_destroy(e);
            } else {
                assert_true(ob_fault_hit((ob_fault_kind)kind));
                assert_int_not_equal(r, OB_OK);
            }
        }
        ob_fault_arm((ob_fault_kind)kind, 0);
    }
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(f->dev);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_standard_effects_build),
        cmocka_unit_test(test_pipeline_once_per_format_pair),
        cmocka_unit_test(test_broken_shader_reported),
        cmocka_unit_test(test_bad_desc_refused),
        cmocka_unit_test(test_pipeline_cache_roundtrip),
        cmocka_unit_test(test_effect_creation_faults),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
