/* Shader compiler: variants, includes, error messages, the disk cache,
 * reflection, threads and allocation failures. No GPU needed. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_shader.h"

#include <dirent.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define DATA_DIR OB_SOURCE_DIR "/tests/data/shaders"
#define PATH_LEN 1024

/* ---------------------------------------------------------------- helpers */

static void make_temp_dir(char out[256])
{
    const char *tmp = getenv("TMPDIR");
    snprintf(out, 256, "%s/ob_shader_test_XXXXXX", tmp && tmp[0] ? tmp : "/tmp");
    assert_non_null(mkdtemp(out));
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (d) {
        struct dirent *e;
        while ((e = readdir(d))) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
            char child[PATH_LEN];
            snprintf(child, sizeof child, "%s/%s", path, e->d_name);
            remove_tree(child);
        }
        closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

static void write_text(const char *dir, const char *name, const char *text)
{
    char path[PATH_LEN];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* Every file in <cache>/spirv; returns how many (names in out). */
static int cache_files(const char *cache_dir, char out[][PATH_LEN], int max)
{
    char dir[300];
    snprintf(dir, sizeof dir, "%s/spirv", cache_dir);
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        if (n < max) snprintf(out[n], PATH_LEN, "%s/%s", dir, e->d_name);
        n++;
    }
    closedir(d);
    return n;
}

static ob_shader_compiler *compiler_at(const char *shader_dir, const char *cache_dir)
{
    ob_shader_compiler_desc desc = {.shader_dir = shader_dir ? shader_dir : DATA_DIR,
                                    .cache_dir = cache_dir, .no_disk_cache = cache_dir == NULL};
    ob_result r;
    ob_shader_compiler *c = ob_shader_compiler_create(&desc, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(c);
    return c;
}

static const ob_shader *get_ok(ob_shader_compiler *c, const char *path, ob_shader_stage stage,
                               uint32_t define_count, const ob_shader_define *defines)
{
    ob_shader_desc desc = {.path = path, .stage = stage, .define_count = define_count,
                           .defines = defines};
    ob_result r;
    const ob_shader *s = ob_shader_get(c, &desc, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(s);
    return s;
}

static ob_result get_fails(ob_shader_compiler *c, const char *path, ob_shader_stage stage)
{
    ob_shader_desc desc = {.path = path, .stage = stage};
    ob_result r = OB_OK;
    assert_null(ob_shader_get(c, &desc, &r));
    return r;
}

static void assert_member(const ob_block_layout *b, const char *name, ob_member_type type,
                          uint32_t offset, uint32_t size, uint32_t array_len, uint32_t stride)
{
    const ob_block_member *m = ob_block_find_member(b, name);
    assert_non_null(m);
    assert_int_equal(m->type, type);
    assert_int_equal(m->offset, offset);
    assert_int_equal(m->size, size);
    assert_int_equal(m->array_len, array_len);
    assert_int_equal(m->array_stride, stride);
}

/* ------------------------------------------------------------- compiling */

static void vertex_and_fragment_with_includes_compile(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *vs = get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    const ob_shader *fs = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    assert_true(vs->spirv_words > 5);
    assert_int_equal(vs->spirv[0], 0x07230203u);
    assert_int_equal(fs->spirv[0], 0x07230203u);
    assert_int_equal(vs->stage, OB_SHADER_VERTEX);
    assert_string_equal(vs->name, "basic.vert");
    assert_int_not_equal(vs->hash, fs->hash);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.compiled, 2);
    assert_int_equal(st.failed, 0);
    ob_shader_compiler_destroy(c);
}

static void in_memory_source_compiles(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    /* The include resolves next to the given path, in the shader folder. */
    ob_shader_desc desc = {.path = "generated/inline.frag", .stage = OB_SHADER_FRAGMENT,
                           .source = "#version 450\n#include \"common.glsl\"\n"
                                     "layout(location = 0) out vec4 o;\n"
                                     "void main() { o = draw.Tint; }\n"};
    ob_result r;
    const ob_shader *s = ob_shader_get(c, &desc, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(ob_reflection_find_block(&s->reflection, "PerDraw"));
    /* A different source under the same name is a different variant. */
    desc.source = "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(1.0); }\n";
    const ob_shader *s2 = ob_shader_get(c, &desc, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_not_equal(s, s2);
    assert_int_equal(s2->reflection.push_block, -1);
    ob_shader_compiler_destroy(c);
}

/* ------------------------------------------------------------ reflection */

static void reflection_gives_std140_layout_and_interface(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *vs = get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    const ob_reflection *rv = &vs->reflection;

    const ob_block_layout *frame = ob_reflection_find_block(rv, "PerFrame");
    assert_non_null(frame);
    assert_int_equal(frame->set, 0);
    assert_int_equal(frame->binding, 0);
    assert_int_equal(frame->size, 340);
    assert_int_equal(frame->member_count, 4);
    assert_member(frame, "ViewProj", OB_MEMBER_MAT4, 0, 64, 0, 0);
    assert_member(frame, "CameraPos", OB_MEMBER_VEC4, 64, 16, 0, 0);
    assert_member(frame, "Bones", OB_MEMBER_MAT4, 80, 256, 4, 64);
    assert_member(frame, "Time", OB_MEMBER_FLOAT, 336, 4, 0, 0);

    const ob_binding *fb = ob_reflection_find_binding(rv, "PerFrame");
    assert_non_null(fb);
    assert_int_equal(fb->kind, OB_BINDING_UNIFORM_BUFFER);
    assert_int_equal(fb->stages, VK_SHADER_STAGE_VERTEX_BIT);
    assert_int_equal(fb->count, 1);
    assert_ptr_equal(&rv->blocks[fb->block], frame);

    assert_true(rv->push_block >= 0);
    const ob_block_layout *push = &rv->blocks[rv->push_block];
    assert_string_equal(push->name, "PerDraw");
    assert_int_equal(push->size, 80);
    assert_member(push, "World", OB_MEMBER_MAT4, 0, 64, 0, 0);
    assert_member(push, "Tint", OB_MEMBER_VEC4, 64, 16, 0, 0);
    assert_int_equal(rv->push_stages, VK_SHADER_STAGE_VERTEX_BIT);

    static const struct { const char *name; uint32_t location; VkFormat format; } inputs[] = {
        {"Position", 0, VK_FORMAT_R32G32B32_SFLOAT},
        {"Normal", 1, VK_FORMAT_R32G32B32_SFLOAT},
        {"TexCoord", 2, VK_FORMAT_R32G32_SFLOAT},
        {"Joints", 3, VK_FORMAT_R32G32B32A32_UINT},
    };
    assert_int_equal(rv->vertex_input_count, 4);
    for (uint32_t i = 0; i < 4; i++) {
        assert_string_equal(rv->vertex_inputs[i].name, inputs[i].name);
        assert_int_equal(rv->vertex_inputs[i].location, inputs[i].location);
        assert_int_equal(rv->vertex_inputs[i].format, inputs[i].format);
    }

    const ob_shader *fs = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    const ob_binding *diffuse = ob_reflection_find_binding(&fs->reflection, "DiffuseMap");
    assert_non_null(diffuse);
    assert_int_equal(diffuse->kind, OB_BINDING_COMBINED_IMAGE_SAMPLER);
    assert_int_equal(diffuse->set, 1);
    assert_int_equal(diffuse->binding, 0);
    assert_int_equal(diffuse->count, 1);
    assert_int_equal(diffuse->block, -1);
    assert_int_equal(diffuse->stages, VK_SHADER_STAGE_FRAGMENT_BIT);
    assert_int_equal(fs->reflection.vertex_input_count, 0);
    /* Sorted by (set, binding): PerFrame (0,0) before DiffuseMap (1,0). */
    assert_string_equal(fs->reflection.bindings[0].name, "PerFrame");
    assert_string_equal(fs->reflection.bindings[1].name, "DiffuseMap");

    const ob_shader *cs = get_ok(c, "particles.comp", OB_SHADER_COMPUTE, 0, NULL);
    const ob_reflection *rc = &cs->reflection;
    assert_int_equal(rc->local_size[0], 8);
    assert_int_equal(rc->local_size[1], 4);
    assert_int_equal(rc->local_size[2], 1);
    const ob_binding *particles = ob_reflection_find_binding(rc, "Particles");
    assert_non_null(particles);
    assert_int_equal(particles->kind, OB_BINDING_STORAGE_BUFFER);
    assert_int_equal(particles->set, 1);
    assert_int_equal(particles->binding, 0);
    /* A runtime array: no length, a stride, no fixed size. */
    assert_member(&rc->blocks[particles->block], "positions", OB_MEMBER_VEC4, 0, 0, 0, 16);
    const ob_binding *target = ob_reflection_find_binding(rc, "Target");
    assert_non_null(target);
    assert_int_equal(target->kind, OB_BINDING_STORAGE_IMAGE);
    assert_int_equal(target->binding, 1);
    assert_int_equal(target->stages, VK_SHADER_STAGE_COMPUTE_BIT);
    ob_shader_compiler_destroy(c);
}

static void merge_joins_stages_and_rejects_conflicts(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *vs = get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    const ob_shader *fs = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    const ob_reflection *stages[] = {&vs->reflection, &fs->reflection};
    ob_reflection merged;
    assert_int_equal(ob_reflection_merge(stages, 2, &merged), OB_OK);
    assert_int_equal(merged.binding_count, 2);
    const ob_binding *frame = ob_reflection_find_binding(&merged, "PerFrame");
    assert_non_null(frame);
    assert_int_equal(frame->stages, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT);
    /* One block for PerFrame plus the push-constant block. */
    assert_int_equal(merged.block_count, 2);
    assert_int_equal(ob_reflection_find_block(&merged, "PerFrame")->size, 340);
    assert_true(merged.push_block >= 0);
    assert_int_equal(merged.push_stages, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT);
    assert_int_equal(merged.vertex_input_count, 4);
    assert_int_equal(ob_reflection_find_binding(&merged, "DiffuseMap")->stages,
                     VK_SHADER_STAGE_FRAGMENT_BIT);
    ob_reflection_release(&merged);
    assert_int_equal(merged.block_count, 0);

    ob_test_log_clear();
    const ob_shader *bad = get_ok(c, "conflict.frag", OB_SHADER_FRAGMENT, 0, NULL);
    const ob_reflection *conflicting[] = {&vs->reflection, &bad->reflection};
    assert_int_equal(ob_reflection_merge(conflicting, 2, &merged), OB_ERR_TYPE_MISMATCH);
    assert_true(ob_test_log_has("set 0 binding 0", "PerFrame", "Material", NULL));
    assert_int_equal(merged.binding_count, 0);
    ob_reflection_release(&merged);
    ob_shader_compiler_destroy(c);
}

/* A stage that includes the push-constant block without reading it (as
 * the standard fragment shaders include common.glsl's PerDraw) is not one
 * of its stages: the layout's range and every vkCmdPushConstants then
 * reach only the stages that read it. On lavapipe a push that reaches the
 * fragment stage makes llvmpipe store its whole fragment state again, a
 * 33 KB copy a draw (docs/benchmark.md, session 11). */
static void push_block_reaches_only_the_stages_that_read_it(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *vs = get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    const ob_shader *fs = get_ok(c, "unread_push.frag", OB_SHADER_FRAGMENT, 0, NULL);
    assert_int_equal(fs->reflection.push_block, -1);
    assert_int_equal(fs->reflection.push_stages, 0);
    assert_non_null(ob_reflection_find_binding(&fs->reflection, "PerFrame"));
    const ob_reflection *stages[] = {&vs->reflection, &fs->reflection};
    ob_reflection merged;
    assert_int_equal(ob_reflection_merge(stages, 2, &merged), OB_OK);
    assert_true(merged.push_block >= 0);
    assert_int_equal(merged.blocks[merged.push_block].size, 80);
    assert_int_equal(merged.push_stages, VK_SHADER_STAGE_VERTEX_BIT);
    ob_reflection_release(&merged);
    ob_shader_compiler_destroy(c);
}

/* -------------------------------------------------------------- variants */

static void define_selects_a_variant(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *plain = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    const ob_shader_define fog[] = {{"USE_FOG", NULL}, {"FOG_AMOUNT", "0.25"}};
    const ob_shader *foggy = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 2, fog);
    assert_ptr_not_equal(plain, foggy);
    assert_int_not_equal(plain->hash, foggy->hash);
    assert_string_equal(foggy->name, "basic.frag [FOG_AMOUNT=0.25, USE_FOG=1]");
    assert_true(plain->spirv_words != foggy->spirv_words ||
                memcmp(plain->spirv, foggy->spirv, plain->spirv_words * 4) != 0);
    /* The #ifdef USE_FOG branch declares and samples FogMap. */
    assert_null(ob_reflection_find_binding(&plain->reflection, "FogMap"));
    const ob_binding *fogmap = ob_reflection_find_binding(&foggy->reflection, "FogMap");
    assert_non_null(fogmap);
    assert_int_equal(fogmap->set, 1);
    assert_int_equal(fogmap->binding, 1);
    /* Define order does not make another variant. */
    const ob_shader_define fog_swapped[] = {{"FOG_AMOUNT", "0.25"}, {"USE_FOG", "1"}};
    assert_ptr_equal(get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 2, fog_swapped), foggy);

    ob_test_log_clear();
    const ob_shader_define bad[] = {{"2BAD", NULL}};
    ob_shader_desc desc = {.path = "basic.frag", .stage = OB_SHADER_FRAGMENT, .define_count = 1,
                           .defines = bad};
    ob_result r;
    assert_null(ob_shader_get(c, &desc, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("2BAD", NULL));
    const ob_shader_define twice[] = {{"A", "1"}, {"A", "2"}};
    desc.defines = twice;
    desc.define_count = 2;
    assert_null(ob_shader_get(c, &desc, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    ob_shader_compiler_destroy(c);
}

/* ---------------------------------------------------------------- errors */

static void syntax_error_names_file_and_line(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    ob_test_log_clear();
    assert_int_equal(get_fails(c, "syntax_error.frag", OB_SHADER_FRAGMENT), OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("syntax_error.frag:7: ", "syntax error", NULL));
    assert_int_equal(ob_shader_compiler_get_stats(c).failed, 1);
    /* Failures are not cached: asking again compiles (and fails) again. */
    assert_int_equal(get_fails(c, "syntax_error.frag", OB_SHADER_FRAGMENT), OB_ERR_SHADER_COMPILE);
    assert_int_equal(ob_shader_compiler_get_stats(c).failed, 2);
    ob_shader_compiler_destroy(c);
}

static void error_in_include_names_the_included_file(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    ob_test_log_clear();
    assert_int_equal(get_fails(c, "include_error.frag", OB_SHADER_FRAGMENT), OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("broken.glsl:3: ", "undefined_thing", NULL));
    assert_false(ob_test_log_has("include_error.frag:3:", NULL));
    /* Lines of the including file stay right after inlined (nested) includes. */
    ob_test_log_clear();
    assert_int_equal(get_fails(c, "after_include.frag", OB_SHADER_FRAGMENT), OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("after_include.frag:5: ", "not_declared", NULL));
    ob_shader_compiler_destroy(c);
}

static void missing_file_names_the_path(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    ob_test_log_clear();
    assert_int_equal(get_fails(c, "does_not_exist.frag", OB_SHADER_FRAGMENT), OB_ERR_IO);
    assert_true(ob_test_log_has("does_not_exist.frag", NULL));
    ob_shader_compiler_destroy(c);
}

static void missing_include_names_the_include(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    ob_test_log_clear();
    assert_int_equal(get_fails(c, "missing_include.frag", OB_SHADER_FRAGMENT), OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("missing_include.frag:6: ", "no_such_file.glsl", NULL));
    /* The include in the inactive #ifdef is not reported. */
    assert_false(ob_test_log_has("also_missing.glsl", NULL));
    /* With the branch active it is. */
    const ob_shader_define on[] = {{"NEVER_DEFINED", NULL}};
    ob_shader_desc desc = {.path = "missing_include.frag", .stage = OB_SHADER_FRAGMENT,
                           .define_count = 1, .defines = on};
    ob_result r;
    ob_test_log_clear();
    assert_null(ob_shader_get(c, &desc, &r));
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_true(ob_test_log_has("missing_include.frag:4: ", "lib/also_missing.glsl", NULL));
    assert_false(ob_test_log_has("missing #endif", NULL));
    ob_shader_compiler_destroy(c);
}

/* ----------------------------------------------------------------- cache */

static void memory_cache_returns_the_same_variant(void **state)
{
    (void)state;
    ob_shader_compiler *c = compiler_at(NULL, NULL);
    const ob_shader *a = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    const ob_shader *b = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    assert_ptr_equal(a, b);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.compiled, 1);
    assert_int_equal(st.memory_hits, 1);
    assert_int_equal(st.disk_hits, 0);
    ob_shader_compiler_destroy(c);
}

static void disk_cache_serves_a_second_compiler(void **state)
{
    (void)state;
    char cache[256];
    make_temp_dir(cache);
    ob_shader_compiler *c1 = compiler_at(NULL, cache);
    const ob_shader *s1 = get_ok(c1, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    size_t words = s1->spirv_words;
    uint32_t *copy = malloc(words * 4);
    memcpy(copy, s1->spirv, words * 4);
    uint64_t hash = s1->hash;
    ob_shader_compiler_destroy(c1);

    ob_shader_compiler *c2 = compiler_at(NULL, cache);
    const ob_shader *s2 = get_ok(c2, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c2);
    assert_int_equal(st.disk_hits, 1);
    assert_int_equal(st.compiled, 0);
    assert_int_equal(s2->hash, hash);
    assert_int_equal(s2->spirv_words, words);
    assert_memory_equal(s2->spirv, copy, words * 4);
    /* Reflection is rebuilt from the cached SPIR-V. */
    assert_int_equal(s2->reflection.vertex_input_count, 4);
    assert_int_equal(ob_reflection_find_block(&s2->reflection, "PerFrame")->size, 340);
    ob_shader_compiler_destroy(c2);
    free(copy);
    remove_tree(cache);
}

/* Damages the only cache file, then checks a new compiler rejects and rebuilds it. */
static void check_rejected_and_rebuilt(const char *cache, const uint32_t *good, size_t words)
{
    ob_test_log_clear();
    ob_shader_compiler *c = compiler_at(NULL, cache);
    const ob_shader *s = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.disk_rejected, 1);
    assert_int_equal(st.compiled, 1);
    assert_int_equal(st.disk_hits, 0);
    assert_int_equal(s->spirv_words, words);
    assert_memory_equal(s->spirv, good, words * 4);
    assert_true(ob_test_log_has("corrupt", NULL));
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 1);
    ob_shader_compiler_destroy(c);
    /* The rebuilt file serves the next compiler. */
    c = compiler_at(NULL, cache);
    get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    assert_int_equal(ob_shader_compiler_get_stats(c).disk_hits, 1);
    ob_shader_compiler_destroy(c);
}

static void corrupt_cache_file_is_detected_and_rebuilt(void **state)
{
    (void)state;
    char cache[256], files[4][PATH_LEN];
    make_temp_dir(cache);
    ob_shader_compiler *c = compiler_at(NULL, cache);
    const ob_shader *s = get_ok(c, "basic.frag", OB_SHADER_FRAGMENT, 0, NULL);
    size_t words = s->spirv_words;
    uint32_t *good = malloc(words * 4);
    memcpy(good, s->spirv, words * 4);
    ob_shader_compiler_destroy(c);
    assert_int_equal(cache_files(cache, files, 4), 1);

    /* Truncated: half the file is gone. */
    struct stat st;
    assert_int_equal(stat(files[0], &st), 0);
    assert_int_equal(truncate(files[0], st.st_size / 2), 0);
    check_rejected_and_rebuilt(cache, good, words);

    /* One bit flipped in the SPIR-V words. */
    FILE *f = fopen(files[0], "r+b");
    assert_non_null(f);
    fseek(f, st.st_size - 9, SEEK_SET);
    int byte = fgetc(f);
    fseek(f, st.st_size - 9, SEEK_SET);
    fputc(byte ^ 0x10, f);
    fclose(f);
    check_rejected_and_rebuilt(cache, good, words);
    free(good);
    remove_tree(cache);
}

static void editing_an_include_invalidates_the_cache(void **state)
{
    (void)state;
    char shaders[256], cache[256];
    make_temp_dir(shaders);
    make_temp_dir(cache);
    write_text(shaders, "main.frag",
               "#version 450\n#include \"color.glsl\"\n"
               "layout(location = 0) out vec4 o;\nvoid main() { o = COLOR; }\n");
    write_text(shaders, "color.glsl", "const vec4 COLOR = vec4(1.0, 0.0, 0.0, 1.0);\n");
    ob_shader_compiler *c = compiler_at(shaders, cache);
    uint64_t first = get_ok(c, "main.frag", OB_SHADER_FRAGMENT, 0, NULL)->hash;
    ob_shader_compiler_destroy(c);

    /* A comment (on the same line: lines are part of the preprocessed
     * source) does not change the preprocessed source: still a disk hit. */
    write_text(shaders, "color.glsl", "const vec4 COLOR = vec4(1.0, 0.0, 0.0, 1.0); // red\n");
    c = compiler_at(shaders, cache);
    assert_int_equal(get_ok(c, "main.frag", OB_SHADER_FRAGMENT, 0, NULL)->hash, first);
    assert_int_equal(ob_shader_compiler_get_stats(c).disk_hits, 1);
    ob_shader_compiler_destroy(c);

    write_text(shaders, "color.glsl", "const vec4 COLOR = vec4(0.0, 1.0, 0.0, 1.0);\n");
    c = compiler_at(shaders, cache);
    const ob_shader *s = get_ok(c, "main.frag", OB_SHADER_FRAGMENT, 0, NULL);
    assert_int_not_equal(s->hash, first);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.compiled, 1);
    assert_int_equal(st.disk_hits, 0);
    ob_shader_compiler_destroy(c);
    remove_tree(shaders);
    remove_tree(cache);
}

/* --------------------------------------------------------------- threads */

#define THREADS 8

typedef struct thread_job {
    ob_shader_compiler *c;
    pthread_barrier_t *start;
    int index;
    const ob_shader *shared, *variant;
    ob_result r1, r2;
} thread_job;

static void *thread_main(void *arg)
{
    thread_job *j = arg;
    char value[8];
    snprintf(value, sizeof value, "%d", j->index % 4);
    ob_shader_define def = {"VARIANT", value};
    ob_shader_desc shared = {.path = "basic.frag", .stage = OB_SHADER_FRAGMENT};
    ob_shader_desc variant = {.path = "basic.frag", .stage = OB_SHADER_FRAGMENT,
                              .define_count = 1, .defines = &def};
    pthread_barrier_wait(j->start);
    if (j->index & 1) {
        j->shared = ob_shader_get(j->c, &shared, &j->r1);
        j->variant = ob_shader_get(j->c, &variant, &j->r2);
    } else {
        j->variant = ob_shader_get(j->c, &variant, &j->r2);
        j->shared = ob_shader_get(j->c, &shared, &j->r1);
    }
    return NULL;
}

static void concurrent_gets_compile_each_variant_once(void **state)
{
    (void)state;
    char cache[256];
    make_temp_dir(cache);
    ob_shader_compiler *c = compiler_at(NULL, cache);
    pthread_barrier_t start;
    pthread_barrier_init(&start, NULL, THREADS);
    pthread_t threads[THREADS];
    thread_job jobs[THREADS];
    for (int i = 0; i < THREADS; i++) {
        jobs[i] = (thread_job){.c = c, .start = &start, .index = i};
        assert_int_equal(pthread_create(&threads[i], NULL, thread_main, &jobs[i]), 0);
    }
    for (int i = 0; i < THREADS; i++) pthread_join(threads[i], NULL);
    pthread_barrier_destroy(&start);

    for (int i = 0; i < THREADS; i++) {
        assert_int_equal(jobs[i].r1, OB_OK);
        assert_int_equal(jobs[i].r2, OB_OK);
        assert_ptr_equal(jobs[i].shared, jobs[0].shared);
        assert_ptr_equal(jobs[i].variant, jobs[i % 4].variant);
        if (i < 4 && i > 0) assert_ptr_not_equal(jobs[i].variant, jobs[0].variant);
    }
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.compiled, 5);   /* the shared variant + VARIANT=0..3 */
    assert_int_equal(st.memory_hits, 2 * THREADS - 5);
    assert_int_equal(st.failed, 0);
    char files[8][PATH_LEN];
    assert_int_equal(cache_files(cache, files, 8), 5);
    ob_shader_compiler_destroy(c);
    remove_tree(cache);
}

/* ------------------------------------------------------ allocation faults */

static void clear_cache(const char *cache)
{
    char dir[300];
    struct stat st;
    snprintf(dir, sizeof dir, "%s/spirv", cache);
    if (stat(dir, &st) != 0) return;
    char files[16][PATH_LEN];
    int n = cache_files(cache, files, 16);
    for (int i = 0; i < n && i < 16; i++) unlink(files[i]);
}

/* Walks every host allocation of one get on a fresh compiler. An essential
 * allocation that fails makes the get fail cleanly with
 * OB_ERR_OUT_OF_HOST_MEMORY; only the cache write may fail without failing
 * the get (it logs a warning). fresh: empty the cache before each run, so
 * every run compiles and writes; otherwise every run is a disk hit. */
static void walk_faults(const char *cache, bool fresh)
{
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    if (cache && fresh) clear_cache(cache);
    ob_shader_compiler *c = compiler_at(NULL, cache);
    get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    ob_shader_compiler_destroy(c);
    uint64_t count = ob_fault_count(OB_FAULT_HOST_ALLOC);
    assert_true(count > 5);

    ob_shader_compiler_desc desc = {.shader_dir = DATA_DIR, .cache_dir = cache,
                                    .no_disk_cache = cache == NULL};
    ob_shader_desc sd = {.path = "basic.vert", .stage = OB_SHADER_VERTEX};
    uint32_t survived = 0;
    for (uint64_t n = 1; n <= count; n++) {
        ob_test_log_clear();
        if (cache && fresh) clear_cache(cache);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        ob_result r = OB_OK;
        c = ob_shader_compiler_create(&desc, &r);
        if (!c) {
            assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
            continue;
        }
        const ob_shader *s = ob_shader_get(c, &sd, &r);
        assert_true(ob_fault_hit(OB_FAULT_HOST_ALLOC));
        if (!s) {
            assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
            assert_true(ob_test_log_has("out of host memory", NULL));
        } else {
            assert_int_equal(r, OB_OK);
            assert_true(ob_test_log_has("cache file", NULL));
            survived++;
        }
        ob_shader_compiler_destroy(c);
    }
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    /* Only the cache write (its buffer) may fail without failing the get. */
    assert_true(survived <= (cache && fresh ? 1u : 0u));
}

static void host_allocation_failures_are_clean(void **state)
{
    (void)state;
    walk_faults(NULL, true);   /* compile, no disk cache */
    char cache[256];
    make_temp_dir(cache);
    walk_faults(cache, true);  /* compile and write the cache file */
    walk_faults(cache, false); /* load from the cache file */
    /* No failed run left a broken cache file behind. */
    ob_test_log_clear();
    ob_shader_compiler *c = compiler_at(NULL, cache);
    get_ok(c, "basic.vert", OB_SHADER_VERTEX, 0, NULL);
    ob_shader_compiler_stats st = ob_shader_compiler_get_stats(c);
    assert_int_equal(st.disk_hits, 1);
    assert_int_equal(st.disk_rejected, 0);
    ob_shader_compiler_destroy(c);
    remove_tree(cache);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(vertex_and_fragment_with_includes_compile),
        cmocka_unit_test(in_memory_source_compiles),
        cmocka_unit_test(reflection_gives_std140_layout_and_interface),
        cmocka_unit_test(merge_joins_stages_and_rejects_conflicts),
        cmocka_unit_test(push_block_reaches_only_the_stages_that_read_it),
        cmocka_unit_test(define_selects_a_variant),
        cmocka_unit_test(syntax_error_names_file_and_line),
        cmocka_unit_test(error_in_include_names_the_included_file),
        cmocka_unit_test(missing_file_names_the_path),
        cmocka_unit_test(missing_include_names_the_include),
        cmocka_unit_test(memory_cache_returns_the_same_variant),
        cmocka_unit_test(disk_cache_serves_a_second_compiler),
        cmocka_unit_test(corrupt_cache_file_is_detected_and_rebuilt),
        cmocka_unit_test(editing_an_include_invalidates_the_cache),
        cmocka_unit_test(concurrent_gets_compile_each_variant_once),
        cmocka_unit_test(host_allocation_failures_are_clean),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
