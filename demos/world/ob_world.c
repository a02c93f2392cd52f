#define _POSIX_C_SOURCE 200809L
#include "ob_world.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Stores the first failure; later ones are consequences. */
static void fail(ob_world *w, ob_result r, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void fail(ob_world *w, ob_result r, const char *fmt, ...)
{
    if (w->err != OB_OK) return;
    w->err = r;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->err_what, sizeof w->err_what, fmt, ap);
    va_end(ap);
    if (w->on_error) w->on_error(w, r, w->err_what, w->on_error_user);
}

/* A failed frame is not stored (see the header), only reported. */
static ob_result frame_failed(ob_world *w, ob_result r)
{
    if (r != OB_OK && w->on_error) w->on_error(w, r, "frame", w->on_error_user);
    return r;
}

ob_world_desc ob_world_desc_small(const char *app_name)
{
    return (ob_world_desc){
        .stack = {.renderer = {.device = {.app_name = app_name}},
                  .width = 160, .height = 120,
                  .clear_color = {0.1f, 0.2f, 0.3f, 1.0f},
                  .camera = {.fovy = 1.0f, .znear = 0.1f},
                  .env_map_size = 64, .shadow_map_size = 256},
        .primitives = true,
    };
}

static void add_primitives(ob_world *w)
{
    ob_mesh m = {0};
    struct { const char *name; ob_geometry **dst; } shapes[3] = {
        {"box", &w->box}, {"sphere", &w->sphere}, {"plane", &w->plane}};
    for (int i = 0; i < 3 && w->err == OB_OK; i++) {
        ob_result r = i == 0 ? ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m)
                      : i == 1 ? ob_mesh_sphere(0.5f, 24, 16, &m)
                               : ob_mesh_plane(20.0f, 20.0f, 2, &m);
        if (r == OB_OK) *shapes[i].dst = ob_world_geometry(w, &m, shapes[i].name);
        else fail(w, r, "geometry '%s'", shapes[i].name);
        ob_mesh_release(&m);
    }
    ob_world_look(w, 0.0, 2.0, 5.0, 0.0, 0.0, 0.0);
}

ob_result ob_world_create(ob_world *w, const ob_world_desc *desc)
{
    memset(w, 0, sizeof *w);
    w->heap_at_create = ob_heap_stats_now();
    w->on_error = desc->on_error;
    w->on_error_user = desc->on_error_user;
    w->width = desc->stack.width ? desc->stack.width : 640;    /* ob_stack's defaults */
    w->height = desc->stack.height ? desc->stack.height : 480;
    ob_result r;
    if (!(w->stack = ob_stack_create(&desc->stack, &r))) {
        fail(w, r, "stack");
        return r;
    }
    ob_stack *s = w->stack;
    w->r = s->renderer;
    w->dev = s->device;
    w->fx = s->effects;
    w->lib = s->materials;
    w->views = s->views;
    w->scene = s->scene;
    w->camera = s->camera;
    w->main = s->main;
    w->composite = s->composite;
    w->overlay = s->overlay;
    if (desc->primitives) add_primitives(w);
    return w->err;
}

ob_world_leftovers ob_world_destroy(ob_world *w)
{
    ob_world_leftovers left = {0};
    if (w->stack) {
        ob_renderer_wait_idle(w->r);
        ob_validation_counts vc = ob_device_validation_counts(w->dev);
        left.validation_errors = vc.errors;
        left.validation_warnings = vc.warnings;
        ob_stack_destroy(w->stack);
        ob_heap_stats after = ob_heap_stats_now();
        left.heap_blocks = (int64_t)(after.live_blocks - w->heap_at_create.live_blocks);
        left.heap_bytes = (int64_t)(after.live_bytes - w->heap_at_create.live_bytes);
    }
    free(w->pixels);
    memset(w, 0, sizeof *w);
    return left;
}

ob_geometry *ob_world_geometry(ob_world *w, const ob_mesh *mesh, const char *name)
{
    if (w->err != OB_OK) return NULL;
    ob_result r;
    ob_geometry *g = ob_stack_add_geometry(w->stack, mesh, name, &r);
    if (!g) fail(w, r, "geometry '%s'", name ? name : "");
    return g;
}

ob_material *ob_world_material_desc(ob_world *w, const ob_material_desc *md)
{
    if (w->err != OB_OK) return NULL;
    ob_result r;
    ob_material *m = ob_material_create(w->lib, md, &r);
    if (!m) fail(w, r, "material '%s'", md->name ? md->name : "");
    return m;
}

ob_material *ob_world_material(ob_world *w, const char *name, ob_material_kind kind, float r,
                               float g, float b, bool casts_shadows)
{
    ob_material_desc md = {.name = name, .kind = kind, .diffuse = {r, g, b, 1.0f},
                           .specular = {0.0f, 0.0f, 0.0f, 1.0f}, .casts_shadows = casts_shadows};
    return ob_world_material_desc(w, &md);
}

ob_node *ob_world_entity(ob_world *w, ob_node *parent, const char *name, ob_geometry *g,
                         ob_material *m, double x, double y, double z)
{
    if (w->err != OB_OK) return NULL;
    ob_result r;
    ob_node *n = ob_stack_add_entity(w->stack, parent, name, g, m, &r);
    if (!n) {
        fail(w, r, "entity '%s'", name ? name : "");
        return NULL;
    }
    ob_node_set_position(n, (const double[3]){x, y, z});
    return n;
}

ob_node *ob_world_light(ob_world *w, ob_light_type type, bool shadows, float intensity, double x,
                        double y, double z)
{
    if (w->err != OB_OK) return NULL;
    const char *name = type == OB_LIGHT_DIRECTIONAL ? "sun" : "lamp";
    ob_result r;
    ob_node *n = ob_node_create(w->scene, NULL, name, &r);
    if (!n) {
        fail(w, r, "light '%s'", name);
        return NULL;
    }
    ob_light_desc ld = {.type = type, .color = {1.0f, 1.0f, 1.0f}, .intensity = intensity,
                        .casts_shadows = shadows};
    r = ob_node_set_light(n, &ld);
    ob_node_set_position(n, (const double[3]){x, y, z});
    if (r == OB_OK && type != OB_LIGHT_POINT)
        r = ob_node_look_at(n, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0});
    if (r != OB_OK) fail(w, r, "light '%s'", name);
    return n;
}

void ob_world_look(ob_world *w, double ex, double ey, double ez, double tx, double ty, double tz)
{
    if (w->err != OB_OK) return;
    ob_node_set_position(w->camera, (const double[3]){ex, ey, ez});
    ob_result r = ob_node_look_at(w->camera, (const double[3]){tx, ty, tz}, (const double[3]){0, 1, 0});
    if (r != OB_OK) fail(w, r, "camera aim");
}

/* ------------------------------------------------------------ frames */

ob_result ob_world_frame_begin(ob_world *w, ob_threading mode, uint32_t workers,
                               ob_view *const *extra, uint32_t extra_count)
{
    if (w->err != OB_OK) return w->err;
    w->frames++;
    ob_renderer_set_threading(w->r, mode, workers);
    ob_result r = ob_stack_frame_begin(w->stack, 1.0 / 60.0);
    if (r != OB_OK) return frame_failed(w, r);
    ob_views_render(w->views, w->stack->final_view);
    for (uint32_t i = 0; i < extra_count; i++) ob_views_render(w->views, extra[i]);
    return OB_OK;
}

ob_result ob_world_frame_end(ob_world *w)
{
    ob_result r = ob_renderer_end_frame(w->r);
    ob_result idle = ob_renderer_wait_idle(w->r);
    return frame_failed(w, r != OB_OK ? r : idle);
}

ob_result ob_world_frame(ob_world *w, ob_threading mode, uint32_t workers, ob_view *const *extra,
                         uint32_t extra_count)
{
    ob_result r = ob_world_frame_begin(w, mode, workers, extra, extra_count);
    return r == OB_OK ? ob_world_frame_end(w) : r;
}

const ob_frame_stats *ob_world_stats(const ob_world *w)
{
    return w->r ? ob_renderer_last_stats(w->r) : NULL;
}

const uint8_t *ob_world_read(ob_world *w)
{
    if (w->err != OB_OK) return NULL;
    ob_image final = ob_stack_final_image(w->stack);
    ob_image_info info;
    ob_result r = ob_image_get_info(w->dev, final, &info);
    if (r == OB_OK && (info.width != w->width || info.height != w->height || !w->pixels)) {
        free(w->pixels);
        w->width = info.width;
        w->height = info.height;
        w->pixels = malloc((size_t)w->width * w->height * 4);
        if (!w->pixels) r = OB_ERR_OUT_OF_HOST_MEMORY;
    }
    if (r == OB_OK) r = ob_image_read_rgba8(w->dev, final, w->pixels);
    if (r != OB_OK) {
        fail(w, r, "read back");
        return NULL;
    }
    return w->pixels;
}

const uint8_t *ob_world_pixel(const ob_world *w, uint32_t x, uint32_t y)
{
    return w->pixels + ((size_t)y * w->width + x) * 4;
}

uint8_t *ob_world_copy(const ob_world *w)
{
    if (!w->pixels) return NULL;
    size_t n = (size_t)w->width * w->height * 4;
    uint8_t *copy = malloc(n);   /* the caller's image: not Obelisk's heap */
    if (copy) memcpy(copy, w->pixels, n);
    return copy;
}

uint8_t *ob_world_snapshot(ob_world *w)
{
    return ob_world_read(w) ? ob_world_copy(w) : NULL;
}

/* ------------------------------------------------------------ stats */

const ob_view_stats *ob_world_view_stats(const ob_frame_stats *st, const char *name)
{
    int i = ob_world_view_index(st, name);
    return i < 0 ? NULL : &st->views[i];
}

uint32_t ob_world_shadow_cascades(const ob_frame_stats *st, const char *light, uint32_t *out_draws)
{
    char prefix[64];
    int n = snprintf(prefix, sizeof prefix, "shadow:%s:c", light);
    uint32_t count = 0, draws = 0;
    for (uint32_t i = 0; st && n > 0 && i < st->view_count; i++) {
        if (strncmp(st->views[i].name, prefix, (size_t)n) != 0) continue;
        count++;
        draws += st->views[i].draws;
    }
    if (out_draws) *out_draws = draws;
    return count;
}

int ob_world_view_index(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; st && i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return (int)i;
    return -1;
}

ob_skip_reason ob_world_skip_reason(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; st && i < st->skipped_count; i++)
        if (strcmp(st->skipped[i].name, name) == 0) return st->skipped[i].reason;
    return OB_SKIP_NONE;
}

uint32_t ob_world_count_views(const ob_frame_stats *st, ob_view_type type)
{
    uint32_t n = 0;
    for (uint32_t i = 0; st && i < st->view_count; i++) n += st->views[i].type == type;
    return n;
}

uint32_t ob_world_count_skipped(const ob_frame_stats *st, ob_skip_reason reason)
{
    uint32_t n = 0;
    for (uint32_t i = 0; st && i < st->skipped_count; i++) n += st->skipped[i].reason == reason;
    return n;
}

/* ------------------------------------------------------------ images */

static uint32_t channel_diff(uint8_t a, uint8_t b) { return a > b ? a - b : b - a; }

uint32_t ob_rgba_max_diff(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint32_t worst = 0;
    for (size_t i = 0; a && b && i < (size_t)n * 4; i++) worst = OB_MAX(worst, channel_diff(a[i], b[i]));
    return worst;
}

uint32_t ob_rgba_diff_count(const uint8_t *a, const uint8_t *b, uint32_t n, uint32_t tol)
{
    uint32_t count = 0;
    for (size_t i = 0; a && b && i < n; i++) {
        bool differs = false;
        for (int k = 0; k < 4; k++) differs |= channel_diff(a[4 * i + k], b[4 * i + k]) > tol;
        count += differs;
    }
    return count;
}

uint32_t ob_rgba_nan_black(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint32_t count = 0;
    for (size_t i = 0; a && b && i < n; i++) {
        const uint8_t *p = a + 4 * i, *q = b + 4 * i;
        count += (q[0] | q[1] | q[2]) == 0 && (p[0] | p[1] | p[2]) != 0;
    }
    return count;
}
