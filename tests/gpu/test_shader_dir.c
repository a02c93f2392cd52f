/* test_shader_dir.c — ob_device_desc.shader_dir points a whole stack
 * (renderer, effect context, material library, standard views) at a shader
 * folder: with $OB_SHADER_DIR naming an empty folder, a stack given a copy of
 * the shaders renders the same pixels and commands as one using the default
 * folder; a stack given an empty folder fails to compile its effects, and the
 * message names that folder. */
#define _GNU_SOURCE
#include "ob_test.h"

#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_stack.h"

#define W 64u
#define H 48u

static char tmp_root[256];

/* A fresh folder under tmp_root. */
static void make_dir(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", tmp_root, name);
    assert_int_equal(mkdir(out, 0755), 0);
}

/* A red box lit by a shadow-casting light, two frames: the image and the
 * last frame's command hash. */
static void render_box(const char *shader_dir, uint8_t *out_px, uint64_t *out_hash)
{
    ob_result r;
    ob_stack_desc d = {.renderer = {.device = {.app_name = "test_shader_dir", .validation = 1,
                                               .shader_dir = shader_dir},
                                    .worker_count = 2},
                       .width = W, .height = H, .shadow_map_size = 64,
                       .clear_color = {0.0f, 0.0f, 1.0f, 1.0f}};
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    if (shader_dir) assert_string_equal(ob_device_shader_dir(s->device), shader_dir);
    else assert_null(ob_device_shader_dir(s->device));
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m), OB_OK);
    ob_geometry *box = ob_stack_add_geometry(s, &m, "box", &r);
    ob_mesh_release(&m);
    assert_non_null(box);
    ob_material_desc md = {.name = "red", .kind = OB_MATERIAL_LIT, .casts_shadows = true,
                           .diffuse = {1, 0, 0, 1}};
    ob_material *red = ob_material_create(s->materials, &md, &r);
    assert_non_null(red);
    assert_non_null(ob_stack_add_entity(s, NULL, "box", box, red, &r));
    ob_node *sun = ob_node_create(s->scene, NULL, "sun", &r);
    assert_non_null(sun);
    ob_light_desc light = {.type = OB_LIGHT_DIRECTIONAL, .color = {1, 1, 1}, .intensity = 1.0f,
                           .casts_shadows = true};
    assert_int_equal(ob_node_set_light(sun, &light), OB_OK);
    ob_node_set_position(s->camera, (const double[3]){0.0, 0.0, 3.0});
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    const ob_frame_stats *st = ob_renderer_last_stats(s->renderer);
    assert_true(st->draws >= 2);   /* the box in the main view and in the shadow map */
    *out_hash = st->frame_hash;
    assert_int_equal(ob_image_read_rgba8(s->device, ob_stack_final_image(s), out_px), OB_OK);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
}

static void test_desc_folder_reaches_every_effect(void **state)
{
    (void)state;
    char copy[300], empty[300];
    make_dir(copy, sizeof copy, "copy");
    make_dir(empty, sizeof empty, "empty");
    assert_true(ob_test_copy_shader_folder(copy) >= 10);

    uint8_t *a = malloc((size_t)W * H * 4), *b = malloc((size_t)W * H * 4);
    assert_non_null(a);
    assert_non_null(b);
    uint64_t ha = 0, hb = 0;
    unsetenv("OB_SHADER_DIR");
    render_box(NULL, a, &ha);

    /* The environment's folder has nothing: only the desc can make it work. */
    setenv("OB_SHADER_DIR", empty, 1);
    ob_test_log_clear();
    render_box(copy, b, &hb);
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 0);
    assert_true(ha == hb);
    assert_memory_equal(a, b, (size_t)W * H * 4);
    const uint8_t *centre = b + ((size_t)(H / 2) * W + W / 2) * 4;
    /* The lit red box, not the blue clear colour: red dominates (the
     * highlight and the tone map's shoulder lift green and blue too). */
    assert_true(centre[0] > 100 && centre[0] > centre[1] + 40 && centre[0] > centre[2] + 40);
    unsetenv("OB_SHADER_DIR");
    free(a);
    free(b);
}

static void test_empty_desc_folder_is_named(void **state)
{
    (void)state;
    char empty[300];
    make_dir(empty, sizeof empty, "empty-desc");
    unsetenv("OB_SHADER_DIR");   /* the default folder would work: the desc wins */
    ob_test_log_set_echo(false);
    ob_test_log_clear();
    ob_result r;
    ob_stack_desc d = {.renderer = {.device = {.validation = 1, .shader_dir = empty},
                                    .worker_count = 1},
                       .width = W, .height = H};
    ob_stack *s = ob_stack_create(&d, &r);
    if (s) {
        assert_null(ob_material_library_effect(s->materials, OB_STD_LIT, 0, &r));
        assert_int_equal(r, OB_ERR_IO);
        ob_stack_destroy(s);
    } else {
        assert_int_not_equal(r, OB_OK);
    }
    ob_test_log_set_echo(true);
    assert_true(ob_test_log_has(empty, "cannot read shader", NULL));
}

int main(void)
{
    ob_test_setup_log();
    snprintf(tmp_root, sizeof tmp_root, "/tmp/ob-test-shader-dir-XXXXXX");
    if (!mkdtemp(tmp_root)) return 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_desc_folder_reaches_every_effect),
        cmocka_unit_test(test_empty_desc_folder_is_named),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_root);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmp_root);
    return failed;
}
