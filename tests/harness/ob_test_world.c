#include "ob_test_world.h"

#include <stdlib.h>
#include <string.h>

#define CHECK(expr, what)                                                                  \
    do {                                                                                   \
        ob_result check_r_ = (expr);                                                       \
        if (check_r_ != OB_OK) fail_msg("%s: %s", what, ob_result_name(check_r_));        \
    } while (0)

void ob_test_world_create(ob_test_world *w, const ob_test_world_desc *desc)
{
    ob_test_setup_log();
    ob_test_world_desc d = desc ? *desc : (ob_test_world_desc){0};
    memset(w, 0, sizeof *w);
    w->heap_at_create = ob_heap_stats_now();
    w->width = d.width ? d.width : 160;
    w->height = d.height ? d.height : 120;
    ob_stack_desc sd = {
        .renderer = {.device = {.app_name = "obelisk-test", .validation = 1},
                     .worker_count = d.workers ? d.workers : 4, .chunk_draws = d.chunk_draws,
                     .parallel_grain = d.parallel_grain},
        .width = w->width, .height = w->height,
        .clear_color = {0.1f, 0.2f, 0.3f, 1.0f},
        .camera = {.fovy = 1.0f, .znear = 0.1f},
        .env_map_size = d.env_map_size ? d.env_map_size : 64,
        .shadow_map_size = d.shadow_map_size ? d.shadow_map_size : 256,
        .msaa = d.msaa,
    };
    if (d.clear_color[3] > 0.0f) memcpy(sd.clear_color, d.clear_color, sizeof sd.clear_color);
    ob_result r;
    w->stack = ob_stack_create(&sd, &r);
    if (!w->stack) fail_msg("stack: %s", ob_result_name(r));
    w->r = w->stack->renderer;
    w->dev = w->stack->device;
    w->fx = w->stack->effects;
    w->lib = w->stack->materials;
    w->views = w->stack->views;
    w->scene = w->stack->scene;
    w->camera = w->stack->camera;
    w->main = w->stack->main;
    w->composite = w->stack->composite;
    w->pixels = malloc((size_t)w->width * w->height * 4);
    assert_non_null(w->pixels);

    ob_mesh m = {0};
    CHECK(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m), "box");
    w->box = ob_test_world_geometry(w, &m, "box");
    ob_mesh_release(&m);
    CHECK(ob_mesh_sphere(0.5f, 24, 16, &m), "sphere");
    w->sphere = ob_test_world_geometry(w, &m, "sphere");
    ob_mesh_release(&m);
    CHECK(ob_mesh_plane(20.0f, 20.0f, 2, &m), "plane");
    w->plane = ob_test_world_geometry(w, &m, "plane");
    ob_mesh_release(&m);
    ob_test_world_look(w, 0.0, 2.0, 5.0, 0.0, 0.0, 0.0);
}

void ob_test_world_destroy(ob_test_world *w)
{
    if (!w->stack) return;
    ob_renderer_wait_idle(w->r);
    ob_validation_counts vc = ob_device_validation_counts(w->dev);
    ob_stack_destroy(w->stack);
    free(w->pixels);
    ob_heap_stats before = w->heap_at_create, after = ob_heap_stats_now();
    memset(w, 0, sizeof *w);
    if (vc.errors || vc.warnings)
        fail_msg("validation layer reported %u errors and %u warnings", vc.errors, vc.warnings);
    /* Everything the world made is gone: a leak the sanitizer build would
     * also catch, but this also catches memory kept in a list until exit. */
    if (after.live_blocks != before.live_blocks || after.live_bytes != before.live_bytes)
        fail_msg("Obelisk's heap holds %lld blocks (%lld bytes) more after the world was destroyed",
                 (long long)(after.live_blocks - before.live_blocks),
                 (long long)(after.live_bytes - before.live_bytes));
}

ob_geometry *ob_test_world_geometry(ob_test_world *w, const ob_mesh *mesh, const char *name)
{
    ob_result r;
    ob_geometry *g = ob_stack_add_geometry(w->stack, mesh, name, &r);
    if (!g) fail_msg("geometry '%s': %s", name, ob_result_name(r));
    return g;
}

ob_material *ob_test_world_material(ob_test_world *w, ob_material_kind kind, float r, float g,
                                    float b, bool casts_shadows)
{
    ob_result res;
    ob_material_desc md = {.name = "test", .kind = kind, .diffuse = {r, g, b, 1.0f},
                           .specular = {0.0f, 0.0f, 0.0f, 1.0f}, .casts_shadows = casts_shadows};
    ob_material *m = ob_material_create(w->lib, &md, &res);
    if (!m) fail_msg("material: %s", ob_result_name(res));
    return m;
}

ob_node *ob_test_world_entity(ob_test_world *w, ob_node *parent, const char *name, ob_geometry *g,
                              ob_material *m, double x, double y, double z)
{
    ob_result r;
    ob_node *n = ob_stack_add_entity(w->stack, parent, name, g, m, &r);
    if (!n) fail_msg("entity '%s': %s", name, ob_result_name(r));
    ob_node_set_position(n, (const double[3]){x, y, z});
    return n;
}

ob_node *ob_test_world_light(ob_test_world *w, ob_light_type type, bool shadows, float intensity,
                             double x, double y, double z)
{
    ob_result r;
    ob_node *n = ob_node_create(w->scene, NULL, type == OB_LIGHT_DIRECTIONAL ? "sun" : "lamp", &r);
    if (!n) fail_msg("light: %s", ob_result_name(r));
    ob_light_desc ld = {.type = type, .color = {1.0f, 1.0f, 1.0f}, .intensity = intensity,
                        .range = 0.0f, .casts_shadows = shadows};
    CHECK(ob_node_set_light(n, &ld), "light");
    ob_node_set_position(n, (const double[3]){x, y, z});
    if (type == OB_LIGHT_DIRECTIONAL)
        CHECK(ob_node_look_at(n, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0}), "light aim");
    return n;
}

void ob_test_world_look(ob_test_world *w, double ex, double ey, double ez, double tx, double ty,
                        double tz)
{
    ob_node_set_position(w->camera, (const double[3]){ex, ey, ez});
    CHECK(ob_node_look_at(w->camera, (const double[3]){tx, ty, tz}, (const double[3]){0, 1, 0}),
          "camera aim");
}

const ob_frame_stats *ob_test_world_frame(ob_test_world *w, ob_threading mode, uint32_t workers)
{
    return ob_test_world_frame_with(w, mode, workers, NULL, 0);
}

const ob_frame_stats *ob_test_world_frame_with(ob_test_world *w, ob_threading mode,
                                               uint32_t workers, ob_view *const *extra,
                                               uint32_t extra_count)
{
    ob_renderer_set_threading(w->r, mode, workers);
    CHECK(ob_stack_frame_begin(w->stack, 1.0 / 60.0), "frame begin");
    ob_views_render(w->views, w->stack->final_view);
    for (uint32_t i = 0; i < extra_count; i++) ob_views_render(w->views, extra[i]);
    CHECK(ob_renderer_end_frame(w->r), "end frame");
    CHECK(ob_renderer_wait_idle(w->r), "wait idle");
    return ob_renderer_last_stats(w->r);
}

const uint8_t *ob_test_world_read(ob_test_world *w)
{
    /* The final image may have been resized since the last read. */
    ob_image_info info;
    CHECK(ob_image_get_info(w->dev, ob_composite_view_target(w->composite), &info), "final image");
    if (info.width != w->width || info.height != w->height) {
        free(w->pixels);
        w->width = info.width;
        w->height = info.height;
        w->pixels = malloc((size_t)w->width * w->height * 4);
        assert_non_null(w->pixels);
    }
    CHECK(ob_image_read_rgba8(w->dev, ob_composite_view_target(w->composite), w->pixels), "read back");
    return w->pixels;
}

const uint8_t *ob_test_world_pixel(const ob_test_world *w, uint32_t x, uint32_t y)
{
    return w->pixels + ((size_t)y * w->width + x) * 4;
}

uint8_t *ob_test_world_copy(const ob_test_world *w)
{
    size_t n = (size_t)w->width * w->height * 4;
    uint8_t *copy = malloc(n); /* test-side image: not an engine allocation */
    assert_non_null(copy);
    memcpy(copy, w->pixels, n);
    return copy;
}

uint32_t ob_test_image_diff_count(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h,
                                  uint32_t tol)
{
    uint32_t count = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        bool differs = false;
        for (int c = 0; c < 4; c++) {
            uint32_t d = a[4 * i + c] > b[4 * i + c] ? a[4 * i + c] - b[4 * i + c]
                                                     : b[4 * i + c] - a[4 * i + c];
            differs = differs || d > tol;
        }
        count += differs;
    }
    return count;
}

const ob_view_stats *ob_test_view_stats(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return &st->views[i];
    return NULL;
}

ob_skip_reason ob_test_skip_reason(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; i < st->skipped_count; i++)
        if (strcmp(st->skipped[i].name, name) == 0) return st->skipped[i].reason;
    return OB_SKIP_NONE;
}

uint8_t *ob_test_world_snapshot(ob_test_world *w)
{
    ob_test_world_read(w);
    size_t n = (size_t)w->width * w->height * 4;
    uint8_t *copy = malloc(n); /* test-side bookkeeping: not an engine allocation */
    assert_non_null(copy);
    memcpy(copy, w->pixels, n);
    return copy;
}

int ob_test_view_index(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return (int)i;
    return -1;
}

uint32_t ob_test_count_views(const ob_frame_stats *st, ob_view_type type)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < st->view_count; i++) n += st->views[i].type == type;
    return n;
}

uint32_t ob_test_count_skipped(const ob_frame_stats *st, ob_skip_reason reason)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < st->skipped_count; i++) n += st->skipped[i].reason == reason;
    return n;
}
