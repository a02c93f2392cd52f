#define _POSIX_C_SOURCE 200809L
/* test_stack.c — ob_stack, the usual set-up in one call: it renders what a
 * program adds to it, frees everything it made, refuses bad entities, and a
 * failure at any allocation or Vulkan creation of ob_stack_create returns
 * NULL with the error and leaves nothing behind. */
#include "ob_test.h"

#include <stdlib.h>
#include <unistd.h>
#include <string.h>

#include "ob_stack.h"
#include "ob_test_adopt.h"

#define W 64u
#define H 48u

static ob_stack *make_stack_on(const ob_vulkan_handles *adopt, ob_result *out_result)
{
    ob_stack_desc d = {.renderer = {.device = {.app_name = "obelisk-test-stack", .validation = 1,
                                               .adopt = adopt},
                                    .worker_count = 2},
                       .width = W, .height = H, .shadow_map_size = 64,
                       .clear_color = {0.0f, 0.0f, 1.0f, 1.0f}};
    return ob_stack_create(&d, out_result);
}

static ob_stack *make_stack(ob_result *out_result) { return make_stack_on(NULL, out_result); }

static void test_stack_renders_and_frees(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    ob_result r;
    ob_stack *s = make_stack(&r);
    assert_non_null(s);
    assert_int_equal(r, OB_OK);
    assert_non_null(s->renderer);
    assert_ptr_equal(s->device, ob_renderer_device(s->renderer));
    assert_null(s->overlay);
    assert_ptr_equal(s->final_view, ob_composite_view_base(s->composite));

    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m), OB_OK);
    ob_geometry *box = ob_stack_add_geometry(s, &m, "box", &r);
    ob_mesh_release(&m);
    assert_non_null(box);
    assert_int_equal(s->geometry_count, 1);
    ob_material_desc md = {.name = "red", .kind = OB_MATERIAL_LIT, .diffuse = {1, 0, 0, 1},
                           .emissive = {1, 0, 0, 1}};
    ob_material *red = ob_material_create(s->materials, &md, &r);
    assert_non_null(red);
    assert_non_null(ob_stack_add_entity(s, NULL, "box", box, red, &r));
    assert_int_equal(r, OB_OK);
    ob_node_set_position(s->camera, (const double[3]){0.0, 0.0, 3.0});

    /* No geometry: refused, logged, nothing added to the scene. */
    ob_test_log_clear();
    assert_null(ob_stack_add_entity(s, NULL, "nothing", NULL, red, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("nothing", NULL));

    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(s->frames, 2);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    assert_true(ob_renderer_last_stats(s->renderer)->draws >= 1);

    uint8_t *px = malloc((size_t)W * H * 4);   /* test-side image */
    assert_non_null(px);
    assert_int_equal(ob_image_read_rgba8(s->device, ob_stack_final_image(s), px), OB_OK);
    const uint8_t *centre = px + ((size_t)(H / 2) * W + W / 2) * 4;
    const uint8_t *corner = px;
    assert_true(centre[0] > 200 && centre[2] < 50);   /* the red box */
    assert_true(corner[2] > 200 && corner[0] < 50);   /* the clear colour */
    free(px);

    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
    ob_stack_destroy(NULL);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
}

/* Issue 25.8: with its shader folder empty, the stack rendered black and
 * every call returned OB_OK. Creation fails now, naming the file. */
static void test_stack_without_shaders_fails_naming_one(void **state)
{
    (void)state;
    char dir[] = "/tmp/obelisk-no-shaders-XXXXXX";
    assert_non_null(mkdtemp(dir));
    ob_test_log_clear();
    ob_test_log_set_echo(false);
    ob_result r = OB_OK;
    ob_stack_desc d = {.renderer = {.device = {.validation = 1, .shader_dir = dir}, .worker_count = 1},
                       .width = W, .height = H};
    ob_stack *s = ob_stack_create(&d, &r);
    ob_test_log_set_echo(true);
    rmdir(dir);
    assert_null(s);
    assert_int_equal(r, OB_ERR_IO);
    if (!ob_test_log_has("pbr.vert", "cannot be read", dir, NULL)) {
        ob_test_log_dump(OB_LOG_WARN, 20);
        fail_msg("no log line names the missing shader and its folder");
    }
}

static void test_stack_overlay_is_final(void **state)
{
    (void)state;
    ob_result r;
    ob_stack_desc d = {.renderer = {.device = {.validation = 1}, .worker_count = 1},
                       .width = W, .height = H, .overlay = true};
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    assert_non_null(s->overlay);
    assert_ptr_equal(s->final_view, ob_overlay_view_base(s->overlay));
    ob_overlay_view_set_text(s->overlay, "stack");
    assert_int_equal(ob_stack_frame(s, 0.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
}

/* Every point of one fault kind during create in turn (about 170 in all,
 * a few seconds): NULL and an error whenever the point fired, nothing left
 * behind on Obelisk's heap (the address-sanitizer build checks the rest).
 * All on one adopted instance (ob_test_adopt.h): test_device walks the
 * points of instance and device creation. */
static void walk_create_faults(ob_fault_kind kind)
{
    ob_test_vulkan tv;
    ob_test_vulkan_create(&tv);
    ob_result r;
    ob_fault_arm(kind, 0);   /* unarmed: counts the points */
    ob_stack *s = make_stack_on(&tv.handles, &r);
    uint64_t points = ob_fault_count(kind);
    assert_non_null(s);
    ob_stack_destroy(s);
    assert_true(points > 0);
    ob_test_log_set_echo(false);
    for (uint64_t n = 1; n <= points; n++) {
        ob_heap_stats before = ob_heap_stats_now();
        ob_fault_arm(kind, n);
        s = make_stack_on(&tv.handles, &r);
        bool hit = ob_fault_hit(kind);
        ob_fault_arm(kind, 0);
        if (hit) {
            if (s) fail_msg("fault %llu of %llu fired but create succeeded",
                            (unsigned long long)n, (unsigned long long)points);
            assert_int_not_equal(r, OB_OK);
        }
        ob_stack_destroy(s);
        ob_heap_stats after = ob_heap_stats_now();
        if (after.live_blocks != before.live_blocks)
            fail_msg("fault %llu: %lld blocks left", (unsigned long long)n,
                     (long long)(after.live_blocks - before.live_blocks));
    }
    ob_test_log_set_echo(true);
    ob_test_vulkan_destroy(&tv);
}

static void test_stack_create_host_faults(void **state)
{
    (void)state;
    walk_create_faults(OB_FAULT_HOST_ALLOC);
}

static void test_stack_create_vk_faults(void **state)
{
    (void)state;
    walk_create_faults(OB_FAULT_VK_OBJECT);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stack_renders_and_frees),
        cmocka_unit_test(test_stack_overlay_is_final),
        cmocka_unit_test(test_stack_without_shaders_fails_naming_one),
        cmocka_unit_test(test_stack_create_host_faults),
        cmocka_unit_test(test_stack_create_vk_faults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
