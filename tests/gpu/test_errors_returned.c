/* test_errors_returned.c (gpu) — issue 27, "errors reach the caller": every
 * create path that needs a device fails through what it returns (a NULL
 * object or a zero handle and the ob_result), not only through the log, and
 * the log line names the file or the entity. Work deferred to the first
 * frame (effect variants, pipelines) fails through the frame: ob_stack_frame
 * and ob_views_render return the error, ob_frame_stats counts it and names
 * what failed. docs/errors.md lists each path with the test that checks it;
 * tests/unit/test_errors_returned_core.c has the paths without a device.
 *
 * Broken shaders come from a copy of the shader folder with one file
 * replaced by GLSL that does not compile, given to the stack through
 * ob_device_desc.shader_dir. */
#define _GNU_SOURCE
#include "ob_test.h"

#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ob_model_instance.h"
#include "ob_scene_load.h"
#include "ob_stack.h"
#include "ob_texture.h"

#define W 32u
#define H 24u
#define MISSING "/nonexistent/obelisk-errors/missing"

static char tmp_root[256];

/* ---------------------------------------------------------------- helpers */

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fputs(text, f) >= 0, 1);
    assert_int_equal(fclose(f), 0);
}

/* GLSL that reads and does not compile (line 3). */
#define BROKEN_GLSL "#version 450\nvoid main() {\n    not_a_type x = 1;\n}\n"

/* A copy of the shader folder in tmp_root/<name>, `broken` (may be NULL)
 * replaced by GLSL that does not compile; the folder's path into out. */
static void shader_folder(const char *name, const char *broken, char *out, size_t size)
{
    snprintf(out, size, "%s/%s", tmp_root, name);
    assert_int_equal(mkdir(out, 0755), 0);
    assert_true(ob_test_copy_shader_folder(out) >= 10);
    if (broken) {
        char b[1024];
        snprintf(b, sizeof b, "%s/%s", out, broken);
        write_file(b, BROKEN_GLSL);
    }
}

static ob_stack_desc stack_desc(const char *shader_dir)
{
    return (ob_stack_desc){.renderer = {.device = {.app_name = "test_errors_returned",
                                                   .validation = 1, .shader_dir = shader_dir},
                                        .worker_count = 1},
                           .width = W, .height = H, .shadow_map_size = 64, .env_map_size = 16};
}

static ob_stack *good_stack(void)
{
    ob_result r;
    ob_stack_desc d = stack_desc(NULL);
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    return s;
}

static void stop(ob_stack *s)
{
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
}

/* ----------------------------------------------------------------- device */

static void device_with_a_missing_extension_fails(void **state)
{
    (void)state;
    static const char *const exts[] = {"VK_OBELISK_no_such_extension"};
    ob_device_desc d = {.app_name = "test_errors_returned", .validation = 1,
                        .instance_extensions = exts, .instance_extension_count = 1};
    ob_result r = OB_OK;
    assert_null(ob_device_create(&d, &r));
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    assert_logged("VK_OBELISK_no_such_extension");
}

static void renderer_with_a_missing_extension_fails(void **state)
{
    (void)state;
    static const char *const exts[] = {"VK_OBELISK_no_such_extension"};
    ob_renderer_desc d = {.device = {.validation = 1, .instance_extensions = exts,
                                     .instance_extension_count = 1},
                          .worker_count = 1};
    ob_result r = OB_OK;
    assert_null(ob_renderer_create(&d, &r));
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    assert_logged("VK_OBELISK_no_such_extension");
}

/* -------------------------------------------------------------- resources */

static void resources_refuse_bad_descs(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_result r = OB_OK;
    ob_buffer b = ob_buffer_create(dev, &(ob_buffer_desc){.size = 0, .usage = OB_BUFFER_VERTEX,
                                                          .name = "empty-buffer"}, &r);
    assert_int_equal(b.id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("'empty-buffer'");

    r = OB_OK;
    ob_image i = ob_image_create(dev, &(ob_image_desc){.width = 0, .height = 4,
                                                       .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                       .usage = OB_IMAGE_SAMPLED, .name = "flat-image"}, &r);
    assert_int_equal(i.id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("flat-image");

    /* A sampler the driver refuses (fault injection): a zero handle and the
     * result, not a handle that fails later. */
    r = OB_OK;
    ob_fault_arm(OB_FAULT_VK_OBJECT, 1);
    ob_sampler s = ob_sampler_create(dev, &(ob_sampler_desc){.name = "refused-sampler"}, &r);
    bool hit = ob_fault_hit(OB_FAULT_VK_OBJECT);
    ob_fault_arm(OB_FAULT_VK_OBJECT, 0);
    assert_true(hit);
    assert_int_equal(s.id, 0);
    assert_int_not_equal(r, OB_OK);
    assert_logged("refused-sampler");
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

static void pipeline_manager_failure_is_returned(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_result r;
    ob_param_registry *reg = ob_param_registry_create(NULL, &r);
    assert_non_null(reg);
    r = OB_OK;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    ob_pipeline_manager_desc d = {.device = dev, .registry = reg, .name = "refused-pm"};
    ob_pipeline_manager *pm = ob_pipeline_manager_create(&d, &r);
    bool hit = ob_fault_hit(OB_FAULT_HOST_ALLOC);
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_true(hit);
    assert_null(pm);
    assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
    assert_logged("refused-pm");
    ob_param_registry_destroy(reg);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

static void texture_missing_file_is_io(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(dev, &r);
    assert_non_null(cache);
    ob_texture_desc d = {.path = MISSING ".png", .srgb = true, .context = "test material"};
    r = OB_OK;
    assert_null(ob_texture_cache_load(cache, &d, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_logged(MISSING ".png", "test material");
    ob_texture_cache_destroy(cache);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

static void geometry_with_a_bad_index_is_refused(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){1, 1, 1}, &m), OB_OK);
    m.indices[4] = m.vertex_count + 7;
    ob_result r = OB_OK;
    assert_null(ob_geometry_create(dev, &(ob_geometry_desc){.mesh = &m, .name = "broken-box"}, &r));
    assert_int_equal(r, OB_ERR_OUT_OF_RANGE);
    assert_logged("broken-box");
    ob_mesh_release(&m);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

/* ---------------------------------------------------------------- effects */

static void effect_with_a_missing_shader_is_io(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_test_log_clear();
    ob_result r = OB_OK;
    ob_effect_desc d = {.name = "ghost", .vertex = MISSING ".vert"};
    assert_null(ob_effect_create(s->effects, &d, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_logged(MISSING ".vert");
    stop(s);
}

static void effect_that_does_not_compile_is_returned(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/broken.vert", tmp_root);
    write_file(path, BROKEN_GLSL);
    ob_stack *s = good_stack();
    ob_test_log_clear();
    ob_result r = OB_OK;
    ob_effect_desc d = {.name = "broken", .vertex = path};
    assert_null(ob_effect_create(s->effects, &d, &r));
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_logged("broken.vert:3");
    stop(s);
}

/* Every host allocation of an effect's creation (its program and
 * parameter registration included, from a fresh registry) fails in turn:
 * each failure returns NULL and an error, never an effect with a part
 * missing. */
static void effect_allocation_failures_are_returned(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_effect_desc d = {.name = "walked", .vertex = "pbr.vert", .fragment = "pbr.frag",
                        .layout = ob_views_standard_input(), .depth_test = true,
                        .depth_write = true};
    uint64_t points = 0;
    for (uint64_t n = 0;; n++) {
        ob_result r;
        ob_param_registry *reg = ob_param_registry_create(&(ob_param_registry_desc){.slot_count = 2}, &r);
        assert_non_null(reg);
        ob_effect_context *ctx = ob_effect_context_create(dev, reg, NULL, &r);
        assert_non_null(ctx);
        r = OB_OK;
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);   /* n = 0: unarmed, counts the points */
        ob_effect *e = ob_effect_create(ctx, &d, &r);
        bool hit = n && ob_fault_hit(OB_FAULT_HOST_ALLOC);
        uint64_t count = ob_fault_count(OB_FAULT_HOST_ALLOC);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        if (n == 0) points = count;
        if (hit) {
            if (e) fail_msg("allocation %llu of %llu failed, yet the effect was created",
                            (unsigned long long)n, (unsigned long long)points);
            assert_int_not_equal(r, OB_OK);
        } else {
            assert_non_null(e);
            assert_int_equal(r, OB_OK);
        }
        ob_effect_destroy(e);
        ob_effect_context_destroy(ctx);
        ob_param_registry_destroy(reg);
        if (n >= points) break;
    }
    assert_true(points > 0);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

static void effect_context_failures_are_returned(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    assert_null(ob_effect_context_create(NULL, NULL, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("effect context", "device");
    ob_device *dev = ob_test_device_create();
    ob_param_registry *reg = ob_param_registry_create(NULL, &r);
    assert_non_null(reg);
    ob_test_log_clear();
    r = OB_OK;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    assert_null(ob_effect_context_create(dev, reg, NULL, &r));
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
    assert_logged("effect context");
    ob_param_registry_destroy(reg);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

/* -------------------------------------------------------------- materials */

static void material_library_without_shaders_is_io(void **state)
{
    (void)state;
    char empty[300];
    snprintf(empty, sizeof empty, "%s/empty", tmp_root);
    assert_int_equal(mkdir(empty, 0755), 0);
    ob_result r;
    ob_renderer *rd = ob_renderer_create(&(ob_renderer_desc){.device = {.validation = 1,
                                                                         .shader_dir = empty},
                                                              .worker_count = 1}, &r);
    assert_non_null(rd);
    ob_effect_context *ctx = ob_effect_context_create(ob_renderer_device(rd),
                                                      ob_renderer_registry(rd), NULL, &r);
    assert_non_null(ctx);
    ob_test_log_clear();
    r = OB_OK;
    assert_null(ob_material_library_create(ctx, NULL, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_logged("pbr.vert", empty);
    ob_effect_context_destroy(ctx);
    ob_test_assert_no_validation(ob_renderer_device(rd));
    ob_renderer_destroy(rd);
}

static void material_bad_descs_are_refused(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_test_log_clear();
    ob_result r = OB_OK;
    assert_null(ob_material_create(s->materials, &(ob_material_desc){.name = "odd-kind",
                                                                     .kind = OB_MATERIAL_KIND_COUNT}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("'odd-kind'");
    r = OB_OK;
    ob_material_desc nan_desc = {.name = "nan-red", .kind = OB_MATERIAL_LIT,
                                 .diffuse = {NAN, 0, 0, 1}};
    assert_null(ob_material_create(s->materials, &nan_desc, &r));
    assert_int_equal(r, OB_ERR_NON_FINITE);
    assert_logged("'nan-red'");
    stop(s);
}

/* ------------------------------------------------------------------ views */

static void views_bad_descs_are_refused(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_test_log_clear();
    ob_result r = OB_OK;
    assert_null(ob_views_create(&(ob_views_desc){.renderer = s->renderer}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("material library");

    /* A map size the device cannot make: refused when asked, not in a frame. */
    uint32_t too_big = ob_device_properties(s->device)->limits.maxImageDimension2D + 1;
    r = OB_OK;
    assert_null(ob_views_create(&(ob_views_desc){.renderer = s->renderer, .materials = s->materials,
                                                 .effects = s->effects, .shadow_map_size = too_big},
                                &r));
    assert_int_equal(r, OB_ERR_OUT_OF_RANGE);
    assert_logged("shadow map", "refused");
    ob_test_log_clear();
    assert_int_equal(ob_views_set_env_map_size(s->views, too_big), OB_ERR_OUT_OF_RANGE);
    assert_logged("environment map", "refused");
    assert_int_equal(ob_views_set_env_map_size(s->views, 0), OB_OK);

    /* A scene file's settings go through the same setters. */
    ob_test_log_clear();
    ob_scene_file_settings fs = {.shadow_map_size = too_big};
    assert_int_equal(ob_scene_load_apply_settings(s->renderer, s->views, &fs), OB_ERR_OUT_OF_RANGE);
    assert_logged("shadow map", "refused");

    /* A perspective view cannot be given a camera later. */
    ob_test_log_clear();
    r = OB_OK;
    ob_perspective_desc pd = {.name = "blind", .width = W, .height = H};
    assert_null(ob_perspective_view_create(s->views, &pd, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("'blind'", "camera");

    /* Overlay and composite need a source with a colour target. */
    ob_test_log_clear();
    r = OB_OK;
    assert_null(ob_overlay_view_create(s->views, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("overlay view", "source");
    r = OB_OK;
    assert_null(ob_composite_view_create(s->views, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("composite view", "source");
    stop(s);
}

static void renderer_bad_threading_mode_is_refused(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_test_log_clear();
    assert_int_equal(ob_renderer_set_threading(s->renderer, (ob_threading)7, 0),
                     OB_ERR_INVALID_ARGUMENT);
    assert_logged("threading mode 7");
    assert_int_equal(ob_renderer_set_threading(s->renderer, OB_THREADING_MULTI, 0), OB_OK);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    stop(s);
}

/* A view's effect is made with the view: a shader that does not compile
 * fails ob_stack_create (composite, overlay) or the particle system's
 * creation, naming the file, instead of a frame without it and OB_OK. */
static void stack_with_a_broken_view_shader_fails(const char *broken, bool overlay)
{
    char dir[300];
    char name[64];
    snprintf(name, sizeof name, "broken-%s", broken);
    shader_folder(name, broken, dir, sizeof dir);
    ob_stack_desc d = stack_desc(dir);
    d.overlay = overlay;
    ob_result r = OB_OK;
    ob_test_log_clear();
    ob_stack *s = ob_stack_create(&d, &r);
    if (s) {
        stop(s);
        fail_msg("a stack with a broken %s was created", broken);
    }
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_logged(broken);
}

static void composite_shader_that_does_not_compile_fails_the_stack(void **state)
{
    (void)state;
    stack_with_a_broken_view_shader_fails("composite.frag", false);
}

static void overlay_shader_that_does_not_compile_fails_the_stack(void **state)
{
    (void)state;
    /* unlit.frag is the overlay's text effect's: without an overlay the
     * stack does not compile it (and the library only reads it). */
    char dir[300];
    shader_folder("unlit-no-overlay", "unlit.frag", dir, sizeof dir);
    ob_stack_desc d = stack_desc(dir);
    ob_result r;
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    stop(s);
    stack_with_a_broken_view_shader_fails("unlit.frag", true);
}

static void particle_shader_that_does_not_compile_fails_the_system(void **state)
{
    (void)state;
    char dir[300];
    shader_folder("broken-particles", "particles.comp", dir, sizeof dir);
    ob_stack_desc d = stack_desc(dir);
    ob_result r;
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    ob_test_log_clear();
    r = OB_OK;
    ob_particle_desc pd = {.name = "frozen-sparks", .count = 16};
    assert_null(ob_particle_system_create(s->views, s->scene, NULL, &pd, &r));
    assert_int_equal(r, OB_ERR_SHADER_COMPILE);
    assert_logged("particles.comp");
    assert_logged("'frozen-sparks'", "not created");
    assert_int_equal(ob_scene_node_count(s->scene), 2);   /* root and camera: nothing left */
    stop(s);
}

/* ------------------------------------------------------------------ frame */

/* A material's effect is made in its first frame: a pbr.frag that reads
 * but does not compile gives that frame an error — returned by
 * ob_views_render and ob_stack_frame, counted in the stats, the material
 * named — and the frame still renders the rest. */
static void frame_with_a_material_that_does_not_compile_returns_it(void **state)
{
    (void)state;
    char dir[300];
    shader_folder("broken-lit", "pbr.frag", dir, sizeof dir);
    ob_stack_desc d = stack_desc(dir);
    ob_result r;
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);   /* the library reads pbr.frag; it is compiled on first use */
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m), OB_OK);
    ob_geometry *box = ob_stack_add_geometry(s, &m, "box", &r);
    ob_mesh_release(&m);
    assert_non_null(box);
    ob_material *red = ob_material_create(s->materials, &(ob_material_desc){.name = "red",
                                          .kind = OB_MATERIAL_LIT, .diffuse = {1, 0, 0, 1}}, &r);
    assert_non_null(red);
    assert_non_null(ob_stack_add_entity(s, NULL, "box", box, red, &r));
    ob_node_set_position(s->camera, (const double[3]){0.0, 0.0, 3.0});
    ob_test_log_clear();

    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_ERR_SHADER_COMPILE);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    const ob_frame_stats *st = ob_renderer_last_stats(s->renderer);
    assert_true(st->errors >= 1);
    assert_int_equal(st->first_error, OB_ERR_SHADER_COMPILE);
    bool named = false;
    for (uint32_t i = 0; i < st->skipped_count; i++)
        named |= strcmp(st->skipped[i].name, "material:red") == 0 &&
                 st->skipped[i].reason == OB_SKIP_ERROR;
    assert_true(named);
    assert_logged("pbr.frag:3");

    /* Every later frame says so too (the failure is kept, not retried),
     * through the split frame as well. */
    assert_int_equal(ob_stack_frame_begin(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_views_render(s->views, s->final_view), OB_ERR_SHADER_COMPILE);
    assert_int_equal(ob_renderer_end_frame(s->renderer), OB_OK);
    stop(s);
}

/* A resize applies in the next PreRender: one the device cannot make is
 * that frame's error, naming the view, and the view keeps its size. */
static void resize_the_device_cannot_make_is_returned(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    uint32_t too_big = ob_device_properties(s->device)->limits.maxImageDimension2D + 1;
    assert_true(ob_stack_resize(s, too_big, H));
    ob_test_log_clear();
    ob_result r = ob_stack_frame(s, 1.0 / 60.0);
    assert_int_not_equal(r, OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    const ob_frame_stats *st = ob_renderer_last_stats(s->renderer);
    assert_int_equal(st->first_error, r);
    assert_logged("'main'", "cannot resize");
    assert_int_equal(ob_perspective_view_base(s->main)->width, W);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);   /* asked once, reported once */
    stop(s);
}

/* A correct frame reports no error. */
static void correct_frame_reports_none(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    const ob_frame_stats *st = ob_renderer_last_stats(s->renderer);
    assert_int_equal(st->errors, 0);
    assert_int_equal(st->first_error, OB_OK);
    stop(s);
}

static void stack_entity_without_geometry_is_refused(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_test_log_clear();
    ob_result r = OB_OK;
    assert_null(ob_stack_add_entity(s, NULL, "orphan", NULL, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("'orphan'", "no geometry");
    assert_int_equal(ob_scene_node_count(s->scene), 2);
    r = OB_OK;
    assert_null(ob_stack_add_geometry(s, &(ob_mesh){0}, "hollow", &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("hollow");
    stop(s);
}

/* ---------------------------------------------------------- scene loading */

static void scene_load_missing_file_is_io(void **state)
{
    (void)state;
    ob_stack *s = good_stack();
    ob_scene_loaded loaded;
    ob_scene_file_error err;
    assert_int_equal(ob_scene_load_stack(s, &(ob_scene_load_desc){.path = MISSING ".json"}, &loaded,
                                         &err),
                     OB_ERR_IO);
    assert_non_null(strstr(err.message, MISSING ".json"));
    assert_int_equal(ob_scene_node_count(s->scene), 2);
    stop(s);
}

static void model_assets_without_a_desc_are_refused(void **state)
{
    (void)state;
    ob_result r = OB_OK;
    assert_null(ob_model_assets_create(NULL, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_logged("ob_model_assets_create", "desc");
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st, (void)flag, (void)ftw;
    return remove(path);
}

int main(void)
{
    ob_test_setup_log();
    snprintf(tmp_root, sizeof tmp_root, "/tmp/ob-test-errors-XXXXXX");
    if (!mkdtemp(tmp_root)) return 1;
    unsetenv("OB_SHADER_DIR");
    const struct CMUnitTest tests[] = {
        ob_test_expecting_errors(device_with_a_missing_extension_fails),
        ob_test_expecting_errors(renderer_with_a_missing_extension_fails),
        ob_test_expecting_errors(resources_refuse_bad_descs),
        ob_test_expecting_errors(pipeline_manager_failure_is_returned),
        ob_test_expecting_errors(texture_missing_file_is_io),
        ob_test_expecting_errors(geometry_with_a_bad_index_is_refused),
        ob_test_expecting_errors(effect_with_a_missing_shader_is_io),
        ob_test_expecting_errors(effect_that_does_not_compile_is_returned),
        ob_test_expecting_errors(effect_allocation_failures_are_returned),
        ob_test_expecting_errors(effect_context_failures_are_returned),
        ob_test_expecting_errors(material_library_without_shaders_is_io),
        ob_test_expecting_errors(material_bad_descs_are_refused),
        ob_test_expecting_errors(views_bad_descs_are_refused),
        ob_test_expecting_errors(renderer_bad_threading_mode_is_refused),
        ob_test_expecting_errors(composite_shader_that_does_not_compile_fails_the_stack),
        ob_test_expecting_errors(overlay_shader_that_does_not_compile_fails_the_stack),
        ob_test_expecting_errors(particle_shader_that_does_not_compile_fails_the_system),
        ob_test_expecting_errors(frame_with_a_material_that_does_not_compile_returns_it),
        ob_test_expecting_errors(resize_the_device_cannot_make_is_returned),
        ob_test_expecting_errors(correct_frame_reports_none),
        ob_test_expecting_errors(stack_entity_without_geometry_is_refused),
        ob_test_expecting_errors(scene_load_missing_file_is_io),
        ob_test_expecting_errors(model_assets_without_a_desc_are_refused),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    nftw(tmp_root, remove_entry, 8, FTW_DEPTH | FTW_PHYS);
    return failed;
}
