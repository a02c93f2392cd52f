#define _POSIX_C_SOURCE 200809L
/* test_stack_content.c — content into an ob_stack in a few calls
 * (ob_stack_content.h): a textured model added with ob_stack_add_model
 * shows its texture (not one flat colour, and not what the same box looks
 * like without it); ob_stack_fit_camera puts a model that sits far from
 * the origin in the middle of the image at a reasonable size; a missing or
 * broken model file and a missing scene file return an error naming the
 * file and the stack keeps rendering what it had; a scene file's missing
 * models are reported in the record the stack keeps; a model added with
 * levels of detail has them and the same file without is drawn at level 0
 * alone; ob_stack_destroy
 * frees all of it; and a failure at any allocation or Vulkan creation
 * while a model is added leaves the stack rendering and nothing leaked. */
#include "ob_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_stack_content.h"
#include "ob_test_adopt.h"
#include "ob_test_world.h"

#define W 160u
#define H 120u
#define BOX_GLB "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb"
#define SCENES OB_SOURCE_DIR "/tests/data/scenes/"

static ob_stack *make_stack_on(const ob_vulkan_handles *adopt)
{
    ob_stack_desc d = {.renderer = {.device = {.app_name = "obelisk-test-stack-content", .validation = 1,
                                               .adopt = adopt},
                                    .worker_count = 2},
                       .width = W, .height = H, .shadow_map_size = 256,
                       .clear_color = {0.0f, 0.0f, 1.0f, 1.0f}};
    ob_result r;
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    return s;
}

static ob_stack *make_stack(void) { return make_stack_on(NULL); }

/* One frame, waited for, the final image into px (W * H * 4). */
static void render(ob_stack *s, uint8_t *px)
{
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    assert_int_equal(ob_image_read_rgba8(s->device, ob_stack_final_image(s), px), OB_OK);
}

/* The clear colour as the composite writes it (tone mapped, sRGB). */
static bool is_clear(const uint8_t *p, const uint8_t *clear)
{
    for (int k = 0; k < 3; k++)
        if (abs((int)p[k] - (int)clear[k]) > 6) return false;
    return true;
}

/* What the model covers: pixels other than the clear colour (the top-left
 * corner's, which a framed model leaves free), their share of the image
 * and their centre (in image fractions). */
typedef struct coverage {
    double share, cx, cy;
    uint32_t colours;   /* distinct colours among them, 3 bits per channel */
} coverage;

static coverage measure(const uint8_t *px)
{
    coverage c = {0};
    bool seen[512] = {false};
    uint32_t n = 0;
    for (uint32_t y = 0; y < H; y++)
        for (uint32_t x = 0; x < W; x++) {
            const uint8_t *p = px + ((size_t)y * W + x) * 4;
            if (is_clear(p, px)) continue;
            n++;
            c.cx += x + 0.5, c.cy += y + 0.5;
            uint32_t key = (uint32_t)(p[0] >> 5) << 6 | (uint32_t)(p[1] >> 5) << 3 | (uint32_t)(p[2] >> 5);
            if (!seen[key]) seen[key] = true, c.colours++;
        }
    c.share = (double)n / (W * H);
    if (n) c.cx /= (double)n * W, c.cy /= (double)n * H;
    return c;
}

static void test_textured_model_shows_its_texture(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    uint8_t *textured = malloc((size_t)W * H * 4), *plain = malloc((size_t)W * H * 4);   /* test-side */
    assert_non_null(textured);
    assert_non_null(plain);

    ob_stack *s = make_stack();
    ob_result r;
    ob_node *box = ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB}, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(box);
    assert_string_equal(ob_node_name(box), "BoxTextured.glb");
    ob_node *sun = ob_stack_add_sun(s, NULL, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(sun);
    assert_int_equal(ob_node_get_light(sun)->type, OB_LIGHT_DIRECTIONAL);
    assert_true(ob_node_get_light(sun)->casts_shadows);
    assert_int_equal(ob_stack_fit_camera(s, box), OB_OK);
    render(s, textured);
    coverage c = measure(textured);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);

    /* The same box drawn with one plain material instead of its own. */
    s = make_stack();
    ob_material_desc md = {.name = "plain", .kind = OB_MATERIAL_LIT, .diffuse = {0.8f, 0.8f, 0.8f, 1.0f}};
    ob_material *grey = ob_material_create(s->materials, &md, &r);
    assert_non_null(grey);
    box = ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB, .material = grey}, &r);
    assert_non_null(box);
    assert_non_null(ob_stack_add_sun(s, NULL, &r));
    assert_int_equal(ob_stack_fit_camera(s, box), OB_OK);
    render(s, plain);
    coverage p = measure(plain);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);

    uint32_t differ = ob_rgba_diff_count(textured, plain, W * H, 24);
    printf("textured: %.1f%% covered, %u colours; plain: %u colours; %u pixels differ\n",
           c.share * 100.0, c.colours, p.colours, differ);
    assert_true(c.share > 0.1 && c.share < 0.9);
    assert_true(c.colours >= 8);                  /* not a flat colour */
    assert_true(c.colours > p.colours);           /* more than shading alone gives */
    assert_true(differ > (W * H) / 20);           /* the texture is drawn, not the factor */
    free(textured);
    free(plain);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
}

/* A model placed far from the origin, scaled, under a parent, is framed:
 * it covers a good part of the image, around its centre. Adding the file a
 * second time places it again (the same assets). */
static void test_fit_camera_frames_the_model(void **state)
{
    (void)state;
    uint8_t *px = malloc((size_t)W * H * 4);   /* test-side */
    assert_non_null(px);
    ob_stack *s = make_stack();
    ob_result r;
    ob_node *parent = ob_node_create(s->scene, NULL, "far away", &r);
    assert_non_null(parent);
    ob_node_set_position(parent, (const double[3]){400.0, -120.0, 900.0});
    ob_stack_model_desc md = {.path = BOX_GLB, .parent = parent, .name = "big box",
                              .position = {10.0, 0.0, 0.0}, .rotation = {0.0, 0.3826834, 0.0, 0.9238795},
                              .scale = {25.0f, 25.0f, 25.0f}};
    ob_node *box = ob_stack_add_model(s, &md, &r);
    assert_non_null(box);
    assert_ptr_equal(ob_node_get_parent(box), parent);
    assert_string_equal(ob_node_name(box), "big box");
    assert_non_null(ob_stack_add_sun(s, (const double[3]){0.3, -1.0, -0.2}, &r));

    /* Before framing the camera looks at the origin: nothing there. */
    render(s, px);
    assert_true(measure(px).share < 0.01);
    assert_int_equal(ob_stack_fit_camera(s, box), OB_OK);
    render(s, px);
    coverage c = measure(px);
    printf("framed: %.1f%% covered, centre %.2f %.2f\n", c.share * 100.0, c.cx, c.cy);
    assert_true(c.share > 0.1 && c.share < 0.9);
    assert_true(fabs(c.cx - 0.5) < 0.15 && fabs(c.cy - 0.5) < 0.15);

    /* A second instance beside it; framing the whole scene shows both. */
    md.position[0] = 60.0;
    md.name = NULL;
    ob_node *twin = ob_stack_add_model(s, &md, &r);
    assert_non_null(twin);
    assert_string_equal(ob_node_name(twin), "BoxTextured.glb");
    assert_int_equal(ob_stack_fit_camera(s, NULL), OB_OK);
    render(s, px);
    coverage both = measure(px);
    assert_true(both.share > 0.05 && both.share < 0.9);
    assert_true(fabs(both.cx - 0.5) < 0.15);

    /* Nothing renderable under a node: refused, the camera left alone. */
    ob_node *empty = ob_node_create(s->scene, NULL, "empty", &r);
    assert_non_null(empty);
    ob_test_log_clear();
    ob_test_log_set_echo(false);
    assert_int_equal(ob_stack_fit_camera(s, empty), OB_ERR_NOT_FOUND);
    ob_test_log_set_echo(true);
    assert_true(ob_test_log_has("empty", "nothing renderable", NULL));
    render(s, px);
    assert_true(fabs(measure(px).share - both.share) < 1e-9);

    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
    free(px);
}

/* Bad files: each call fails with the loader's result, a log line names
 * the file, nothing is added, and the stack keeps rendering what it had. */
static void test_bad_files_name_the_file_and_the_stack_renders_on(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    uint8_t *good = malloc((size_t)W * H * 4), *px = malloc((size_t)W * H * 4);   /* test-side */
    assert_non_null(good);
    assert_non_null(px);
    ob_stack *s = make_stack();
    ob_result r;
    ob_node *box = ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB}, &r);
    assert_non_null(box);
    assert_non_null(ob_stack_add_sun(s, NULL, &r));
    assert_int_equal(ob_stack_fit_camera(s, box), OB_OK);
    render(s, good);
    uint32_t nodes = ob_scene_node_count(s->scene);

    char dir[] = "/tmp/obelisk-broken-XXXXXX", broken[64];
    assert_non_null(mkdtemp(dir));
    snprintf(broken, sizeof broken, "%s/broken.gltf", dir);
    FILE *f = fopen(broken, "w");
    assert_non_null(f);
    fputs("{ \"asset\": { \"version\": \"2.0\" }, \"meshes\": [ { \"primitives\": 7 } ", f);
    fclose(f);

    ob_test_log_set_echo(false);
    const char *missing = "/tmp/obelisk-no-such-dir/no-such-model.glb";
    ob_test_log_clear();
    assert_null(ob_stack_add_model(s, &(ob_stack_model_desc){.path = missing}, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_true(ob_test_log_has(missing, "not added", NULL));

    ob_test_log_clear();
    assert_null(ob_stack_add_model(s, &(ob_stack_model_desc){.path = broken}, &r));
    assert_true(r == OB_ERR_PARSE || r == OB_ERR_BAD_MODEL);
    assert_true(ob_test_log_has(broken, "not added", NULL));

    ob_test_log_clear();
    assert_null(ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB,
                                                              .position = {NAN, 0.0, 0.0}}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has(BOX_GLB, "not finite", NULL));

    assert_null(ob_stack_add_model(s, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_null(ob_stack_add_sun(s, (const double[3]){0.0, 0.0, 0.0}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);

    ob_scene_file_error err;
    const ob_scene_loaded *loaded = (const ob_scene_loaded *)1;
    const char *no_scene = "/tmp/obelisk-no-such-dir/scene.json";
    ob_test_log_clear();
    assert_int_equal(ob_stack_load_scene(s, no_scene, &loaded, &err), OB_ERR_IO);
    assert_null(loaded);
    assert_non_null(strstr(err.message, no_scene));
    assert_true(ob_test_log_has(no_scene, NULL));
    ob_test_log_clear();
    assert_int_equal(ob_stack_load_scene(s, SCENES "bad_syntax.json", &loaded, &err), OB_ERR_PARSE);
    assert_non_null(strstr(err.message, "bad_syntax.json"));
    assert_true(ob_test_log_has("bad_syntax.json", NULL));
    ob_test_log_set_echo(true);
    unlink(broken);
    rmdir(dir);

    /* Nothing was added, and the frame is the one before. */
    assert_int_equal(ob_scene_node_count(s->scene), nodes);
    render(s, px);
    assert_int_equal(ob_rgba_diff_count(good, px, W * H, 0), 0);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
    free(good);
    free(px);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
}

/* A scene file into the stack: its models that do not load are listed in
 * the record the stack keeps (and logged), the rest renders, and a model
 * added from code sits beside it; ob_stack_destroy unloads it all. */
static void test_scene_file_reports_what_was_left_out(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    uint8_t *px = malloc((size_t)W * H * 4);   /* test-side */
    assert_non_null(px);
    ob_stack *s = make_stack();
    const ob_scene_loaded *loaded = NULL;
    ob_scene_file_error err;
    ob_test_log_set_echo(false);
    ob_test_log_clear();
    assert_int_equal(ob_stack_load_scene(s, SCENES "missing_model.json", &loaded, &err), OB_OK);
    ob_test_log_set_echo(true);
    assert_non_null(loaded);
    assert_int_equal(loaded->left_out_count, 3);
    assert_int_equal(loaded->left_out[0].entity, 2);
    assert_int_equal(loaded->left_out[0].result, OB_ERR_IO);
    assert_true(ob_test_log_has("missing_model.json", "ghost", "no-such-model.obj", NULL));

    ob_result r;
    ob_node *box = ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB,
                                                                .position = {0.0, 2.0, 0.0}}, &r);
    assert_non_null(box);
    const ob_scene_loaded *second = NULL;
    assert_int_equal(ob_stack_load_scene(s, SCENES "load_small.json", &second, NULL), OB_OK);
    assert_non_null(second);
    assert_int_equal(second->left_out_count, 0);
    assert_int_equal(ob_stack_fit_camera(s, NULL), OB_OK);
    render(s, px);
    coverage c = measure(px);
    assert_true(c.share > 0.08 && c.share < 0.9);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
    free(px);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
}

/* Every point of one fault kind while BoxTextured is added to a fresh
 * stack, in turn: the add fails with an error and adds no node, or (a
 * texture that could not be made) succeeds with the texture dropped and a
 * warning; either way the next frame renders, adding the model again
 * works, and ob_stack_destroy leaves Obelisk's heap as it was. All on one
 * adopted instance (ob_test_adopt.h), as test_stack's walks. */
static void walk_add_model_faults(ob_fault_kind kind)
{
    ob_test_vulkan tv;
    ob_test_vulkan_create(&tv);
    ob_result r;
    ob_stack *s = make_stack_on(&tv.handles);
    ob_fault_arm(kind, 0);   /* unarmed: counts the points */
    assert_non_null(ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB}, &r));
    uint64_t points = ob_fault_count(kind);
    ob_stack_destroy(s);
    assert_true(points > 0);
    ob_test_log_set_echo(false);
    uint64_t failed = 0;
    for (uint64_t n = 1; n <= points; n++) {
        ob_heap_stats before = ob_heap_stats_now();
        s = make_stack_on(&tv.handles);
        uint32_t nodes = ob_scene_node_count(s->scene);
        ob_fault_arm(kind, n);
        ob_node *box = ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB}, &r);
        bool hit = ob_fault_hit(kind);
        ob_fault_arm(kind, 0);
        if (!box) {
            if (!hit) fail_msg("fault %llu of %llu did not fire but the add failed", (unsigned long long)n,
                               (unsigned long long)points);
            assert_int_not_equal(r, OB_OK);
            assert_int_equal(ob_scene_node_count(s->scene), nodes);
            failed++;
        }
        assert_int_equal(ob_stack_frame(s, 0.0), OB_OK);
        if (!box) assert_non_null(ob_stack_add_model(s, &(ob_stack_model_desc){.path = BOX_GLB}, &r));
        assert_int_equal(ob_stack_fit_camera(s, NULL), OB_OK);
        assert_int_equal(ob_stack_frame(s, 0.0), OB_OK);
        assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
        ob_test_assert_no_validation(s->device);
        ob_stack_destroy(s);
        ob_heap_stats after = ob_heap_stats_now();
        if (after.live_blocks != before.live_blocks)
            fail_msg("fault %llu: %lld blocks left", (unsigned long long)n,
                     (long long)(after.live_blocks - before.live_blocks));
    }
    ob_test_log_set_echo(true);
    printf("%llu fault points, %llu failed the add\n", (unsigned long long)points,
           (unsigned long long)failed);
    assert_true(failed > 0);
    ob_test_vulkan_destroy(&tv);
}

static void test_add_model_host_faults(void **state)
{
    (void)state;
    walk_add_model_faults(OB_FAULT_HOST_ALLOC);
}

static void test_add_model_vk_faults(void **state)
{
    (void)state;
    walk_add_model_faults(OB_FAULT_VK_OBJECT);
}

/* The level count of the first renderable's geometry under n; 0 if none. */
static uint32_t geometry_levels(ob_node *n)
{
    const ob_renderable *rd = ob_node_get_renderable(n);
    if (rd && rd->geometry) return ob_geometry_lod_count(rd->geometry);
    for (ob_node *c = ob_node_first_child(n); c; c = ob_node_next_sibling(c)) {
        uint32_t l = geometry_levels(c);
        if (l) return l;
    }
    return 0;
}

/* A model added with levels of detail: its primitive's geometry has them;
 * the same file without is other geometry, at level 0 only; both render. */
static void test_model_with_levels_of_detail(void **state)
{
    (void)state;
    const char *path = "/usr/share/assimp/models/OBJ/WusonOBJ.obj";
    if (access(path, R_OK) != 0) {
        print_message("SKIP: %s is missing (install Debian's assimp-testmodels)\n", path);
        return;
    }
    ob_stack *s = make_stack();
    ob_result r;
    ob_node *with = ob_stack_add_model(s, &(ob_stack_model_desc){.path = path, .lods = 2}, &r);
    assert_non_null(with);
    ob_node *without = ob_stack_add_model(s, &(ob_stack_model_desc){.path = path,
                                                                    .position = {2, 0, 0}}, &r);
    assert_non_null(without);
    assert_int_equal(geometry_levels(with), 3);
    assert_int_equal(geometry_levels(without), 1);
    assert_int_equal(ob_stack_fit_camera(s, NULL), OB_OK);
    uint8_t *px = malloc((size_t)W * H * 4);   /* test-side image */
    assert_non_null(px);
    render(s, px);
    uint8_t clear[4];
    memcpy(clear, px, 4);
    uint32_t covered = 0;
    for (uint32_t i = 0; i < W * H; i++) covered += !is_clear(px + 4 * i, clear);
    assert_true(covered > W * H / 50);   /* both bulls are there */
    free(px);
    ob_stack_destroy(s);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_textured_model_shows_its_texture),
        cmocka_unit_test(test_fit_camera_frames_the_model),
        cmocka_unit_test(test_bad_files_name_the_file_and_the_stack_renders_on),
        cmocka_unit_test(test_scene_file_reports_what_was_left_out),
        cmocka_unit_test(test_add_model_host_faults),
        cmocka_unit_test(test_add_model_vk_faults),
        cmocka_unit_test(test_model_with_levels_of_detail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
