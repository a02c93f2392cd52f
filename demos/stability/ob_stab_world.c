#define _POSIX_C_SOURCE 200809L
#include "ob_stab_world.h"


#include <math.h>
#include <stdio.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ rows */

ob_result ob_stab_add(ob_stab_ctx *c, const char *name, const char *measure, double error,
                      const char *unit, double bound, bool ok, double ms, const char *detail_fmt,
                      ...)
{
    ob_stability *s = c->out;
    if (ob_array_reserve((void **)&s->rows, &s->cap, s->count + 1, sizeof *s->rows) != OB_OK) {
        OB_LOG_E("bench", "stability: no memory for the row '%s'", name);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    ob_stability_row *row = &s->rows[s->count++];
    memset(row, 0, sizeof *row);
    snprintf(row->name, sizeof row->name, "%s", name);
    snprintf(row->measure, sizeof row->measure, "%s", measure);
    snprintf(row->unit, sizeof row->unit, "%s", unit);
    row->error = error;
    row->bound = bound;
    row->ms = ms;
    row->checks_ok = ok;
    if (!ok || isnan(error)) row->verdict = OB_STABILITY_FAIL;
    else if (isnan(bound)) row->verdict = OB_STABILITY_MEASURED;
    else row->verdict = error <= bound ? OB_STABILITY_PASS : OB_STABILITY_FAIL;
    va_list ap;
    va_start(ap, detail_fmt);
    vsnprintf(row->detail, sizeof row->detail, detail_fmt, ap);
    va_end(ap);
    if (row->verdict == OB_STABILITY_FAIL) s->failed++;
    if (row->verdict == OB_STABILITY_MEASURED) s->measured++;
    return OB_OK;
}

double ob_stab_take_ms(ob_stab_ctx *c)
{
    double ms = c->steady_count ? ob_median(c->steady_ms, c->steady_count)
                                : ob_median(c->first_ms, c->first_count);
    c->steady_count = c->first_count = 0;
    return ms;
}

/* ------------------------------------------------------------ log capture */

void ob_stab_expect(ob_stab_ctx *c, const char *const *needles)
{
    ob_stab_log *l = &c->log;
    pthread_mutex_lock(&l->lock);
    l->needle_count = 0;
    for (; needles && *needles && l->needle_count < OB_STAB_MAX_NEEDLES; needles++)
        l->needles[l->needle_count++] = *needles;
    l->line_count = 0;
    pthread_mutex_unlock(&l->lock);
}

bool ob_stab_log_has(ob_stab_ctx *c, const char *needle, ...)
{
    const char *list[8];
    uint32_t n = 0;
    va_list ap;
    va_start(ap, needle);
    for (const char *s = needle; s && n < 8; s = va_arg(ap, const char *)) list[n++] = s;
    va_end(ap);
    ob_stab_log *l = &c->log;
    bool found = false;
    pthread_mutex_lock(&l->lock);
    for (uint32_t i = 0; i < l->line_count && !found; i++) {
        bool all = true;
        for (uint32_t k = 0; k < n && all; k++) all = strstr(l->lines[i], list[k]) != NULL;
        found = all;
    }
    pthread_mutex_unlock(&l->lock);
    return found;
}

uint64_t ob_stab_expected_errors(ob_stab_ctx *c)
{
    pthread_mutex_lock(&c->log.lock);
    uint64_t n = c->log.expected[OB_LOG_ERROR];
    pthread_mutex_unlock(&c->log.lock);
    return n;
}

/* ------------------------------------------------------------ world */

static void fail(ob_stab_world *w, ob_result r, const char *what, const char *name)
{
    if (w->err != OB_OK) return;
    w->err = r;
    OB_LOG_E("bench", "stability: %s '%s' failed: %s", what, name ? name : "", ob_result_name(r));
}

ob_result ob_stab_world_create(ob_stab_world *w, ob_stab_ctx *c, const ob_stab_world_desc *desc)
{
    memset(w, 0, sizeof *w);
    w->ctx = c;
    w->width = desc->width ? desc->width : 160;
    w->height = desc->height ? desc->height : 120;
    ob_stack_desc sd = {
        .renderer = {.device = {.app_name = "obelisk-stability"}, .worker_count = c->workers,
                     .threading = c->workers ? OB_THREADING_MULTI : OB_THREADING_SINGLE},
        .width = w->width, .height = w->height,
        .clear_color = {0.1f, 0.2f, 0.3f, 1.0f},
        .camera = {.fovy = 1.0f, .znear = desc->znear > 0 ? desc->znear : 0.1f},
        .env_map_size = desc->env_map_size ? desc->env_map_size : 64,
        .shadow_map_size = desc->shadow_map_size ? desc->shadow_map_size : 256,
    };
    if (desc->clear_color[3] > 0.0f) memcpy(sd.clear_color, desc->clear_color, sizeof sd.clear_color);
    ob_result r;
    if (!(w->s = ob_stack_create(&sd, &r))) {
        fail(w, r, "renderer set-up", "");
        return r;
    }
    ob_device *dev = w->s->device;
    if (!c->out->device_name[0]) {
        snprintf(c->out->device_name, sizeof c->out->device_name, "%s", ob_device_name(dev));
        snprintf(c->out->driver_info, sizeof c->out->driver_info, "%s", ob_device_driver_info(dev));
    }
    c->out->validation |= ob_device_validation_enabled(dev);
    w->pixels = ob_malloc((size_t)w->width * w->height * 4);
    if (!w->pixels) fail(w, OB_ERR_OUT_OF_HOST_MEMORY, "image", "pixels");
    ob_mesh m = {0};
    struct { const char *name; ob_geometry **dst; } shapes[3] = {
        {"box", &w->box}, {"sphere", &w->sphere}, {"plane", &w->plane}};
    for (int i = 0; i < 3 && w->err == OB_OK; i++) {
        r = i == 0 ? ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m)
            : i == 1 ? ob_mesh_sphere(0.5f, 24, 16, &m)
                     : ob_mesh_plane(20.0f, 20.0f, 2, &m);
        if (r == OB_OK) *shapes[i].dst = ob_stack_add_geometry(w->s, &m, shapes[i].name, &r);
        ob_mesh_release(&m);
        if (r != OB_OK) fail(w, r, "geometry", shapes[i].name);
    }
    ob_stab_look(w, 0.0, 2.0, 5.0, 0.0, 0.0, 0.0);
    return w->err;
}

void ob_stab_world_destroy(ob_stab_world *w)
{
    if (w->s) {
        ob_renderer_wait_idle(w->s->renderer);
        ob_validation_counts vc = ob_device_validation_counts(w->s->device);
        w->ctx->out->validation_messages += vc.errors + vc.warnings;
    }
    ob_stack_destroy(w->s);
    w->s = NULL;
    ob_free(w->pixels);
    w->pixels = NULL;
}

ob_material *ob_stab_material_desc(ob_stab_world *w, const ob_material_desc *md)
{
    if (w->err != OB_OK) return NULL;
    ob_result r;
    ob_material *m = ob_material_create(w->s->materials, md, &r);
    if (!m) fail(w, r, "material", md->name);
    return m;
}

ob_material *ob_stab_material(ob_stab_world *w, const char *name, ob_material_kind kind, float r,
                              float g, float b, bool casts_shadows)
{
    ob_material_desc md = {.name = name, .kind = kind, .diffuse = {r, g, b, 1.0f},
                           .specular = {0.0f, 0.0f, 0.0f, 1.0f}, .casts_shadows = casts_shadows};
    return ob_stab_material_desc(w, &md);
}

ob_node *ob_stab_entity(ob_stab_world *w, ob_node *parent, const char *name, ob_geometry *g,
                        ob_material *m, double x, double y, double z)
{
    if (w->err != OB_OK) return NULL;
    ob_result r;
    ob_node *n = ob_stack_add_entity(w->s, parent, name, g, m, &r);
    if (!n) {
        fail(w, r, "entity", name);
        return NULL;
    }
    ob_stab_position(n, x, y, z);
    return n;
}

ob_node *ob_stab_light(ob_stab_world *w, ob_light_type type, bool shadows, float intensity,
                       double x, double y, double z)
{
    if (w->err != OB_OK) return NULL;
    const char *name = type == OB_LIGHT_DIRECTIONAL ? "sun" : "lamp";
    ob_result r;
    ob_node *n = ob_node_create(w->s->scene, NULL, name, &r);
    if (!n) {
        fail(w, r, "light", name);
        return NULL;
    }
    ob_light_desc ld = {.type = type, .color = {1.0f, 1.0f, 1.0f}, .intensity = intensity,
                        .casts_shadows = shadows};
    r = ob_node_set_light(n, &ld);
    ob_stab_position(n, x, y, z);
    if (r == OB_OK && type == OB_LIGHT_DIRECTIONAL)
        r = ob_node_look_at(n, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0});
    if (r != OB_OK) fail(w, r, "light", name);
    return n;
}

void ob_stab_look(ob_stab_world *w, double ex, double ey, double ez, double tx, double ty,
                  double tz)
{
    if (w->err != OB_OK) return;
    ob_stab_position(w->s->camera, ex, ey, ez);
    ob_result r = ob_node_look_at(w->s->camera, (const double[3]){tx, ty, tz},
                                  (const double[3]){0, 1, 0});
    if (r != OB_OK) fail(w, r, "camera aim", "camera");
}

void ob_stab_position(ob_node *n, double x, double y, double z)
{
    if (n) ob_node_set_position(n, (const double[3]){x, y, z});
}

void ob_stab_scale(ob_node *n, float x, float y, float z)
{
    if (n) ob_node_set_scale(n, (const float[3]){x, y, z});
}

void ob_stab_hide(ob_node *n, bool hidden)
{
    if (n) ob_node_set_hidden(n, hidden);
}

/* ------------------------------------------------------------ frames */

const ob_frame_stats *ob_stab_frame(ob_stab_world *w, ob_threading mode)
{
    return ob_stab_frame_with(w, mode, NULL, 0);
}

const ob_frame_stats *ob_stab_frame_with(ob_stab_world *w, ob_threading mode,
                                         ob_view *const *extra, uint32_t extra_count)
{
    if (w->err != OB_OK) return NULL;
    ob_renderer *r = w->s->renderer;
    uint64_t t0 = ob_time_ns();
    ob_renderer_set_threading(r, mode, 0);
    ob_result res = ob_stack_frame_begin(w->s, 1.0 / 60.0);
    if (res == OB_OK) {
        ob_views_render(w->s->views, w->s->final_view);
        for (uint32_t i = 0; i < extra_count; i++) ob_views_render(w->s->views, extra[i]);
        res = ob_renderer_end_frame(r);
    }
    if (res == OB_OK) res = ob_renderer_wait_idle(r);
    if (res != OB_OK) {
        fail(w, res, "frame", "main");
        return NULL;
    }
    double ms = (double)(ob_time_ns() - t0) * 1e-6;
    ob_stab_ctx *c = w->ctx;
    /* A renderer's first frame creates its pipelines: not what a case costs. */
    if (w->frames == 0 && c->first_count < OB_STAB_MAX_TIMES) c->first_ms[c->first_count++] = ms;
    else if (w->frames > 0 && c->steady_count < OB_STAB_MAX_TIMES) c->steady_ms[c->steady_count++] = ms;
    w->frames++;
    return ob_renderer_last_stats(r);
}

uint8_t *ob_stab_snapshot(ob_stab_world *w)
{
    if (w->err != OB_OK) return NULL;
    ob_result r = ob_image_read_rgba8(ob_renderer_device(w->s->renderer),
                                      ob_composite_view_target(w->s->composite), w->pixels);
    if (r != OB_OK) {
        fail(w, r, "read back", "composite");
        return NULL;
    }
    size_t n = (size_t)w->width * w->height * 4;
    uint8_t *copy = ob_malloc(n);
    if (!copy) {
        fail(w, OB_ERR_OUT_OF_HOST_MEMORY, "image copy", "composite");
        return NULL;
    }
    memcpy(copy, w->pixels, n);
    return copy;
}

uint8_t *ob_stab_render(ob_stab_world *w, const ob_frame_stats **out_stats)
{
    const ob_frame_stats *st = ob_stab_frame(w, OB_THREADING_SINGLE);
    if (out_stats) *out_stats = st;
    return ob_stab_snapshot(w);
}

const ob_view_stats *ob_stab_view_stats(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; st && i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return &st->views[i];
    return NULL;
}

ob_skip_reason ob_stab_skip_reason(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; st && i < st->skipped_count; i++)
        if (strcmp(st->skipped[i].name, name) == 0) return st->skipped[i].reason;
    return OB_SKIP_NONE;
}

/* ------------------------------------------------------------ images */

static uint32_t channel_diff(uint8_t a, uint8_t b) { return a > b ? a - b : b - a; }

uint32_t ob_stab_max_diff(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint32_t worst = 0;
    for (size_t i = 0; a && b && i < (size_t)n * 4; i++) worst = OB_MAX(worst, channel_diff(a[i], b[i]));
    return worst;
}

uint32_t ob_stab_diff_count(const uint8_t *a, const uint8_t *b, uint32_t n, uint32_t tol)
{
    uint32_t count = 0;
    for (size_t i = 0; a && b && i < n; i++) {
        bool differs = false;
        for (int k = 0; k < 4; k++) differs |= channel_diff(a[4 * i + k], b[4 * i + k]) > tol;
        count += differs;
    }
    return count;
}

uint32_t ob_stab_nan_black(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint32_t count = 0;
    for (size_t i = 0; a && b && i < n; i++) {
        const uint8_t *p = a + 4 * i, *q = b + 4 * i;
        count += (q[0] | q[1] | q[2]) == 0 && (p[0] | p[1] | p[2]) != 0;
    }
    return count;
}
