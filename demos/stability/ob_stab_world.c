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

/* The cases' error policy: every failure is logged, naming what failed,
 * and a failed frame ends the case like a failed helper (sticky). */
static void log_failure(ob_world *world, ob_result r, const char *what, void *user)
{
    (void)user;
    OB_LOG_E("bench", "stability: %s failed: %s", what, ob_result_name(r));
    if (world->err == OB_OK) {
        world->err = r;
        snprintf(world->err_what, sizeof world->err_what, "%s", what);
    }
}

ob_result ob_stab_world_create(ob_stab_world *w, ob_stab_ctx *c, const ob_stab_world_desc *desc)
{
    memset(w, 0, sizeof *w);
    w->ctx = c;
    ob_world_desc wd = ob_world_desc_small("obelisk-stability");
    wd.on_error = log_failure;
    ob_stack_desc *sd = &wd.stack;
    sd->renderer.worker_count = c->workers;
    sd->renderer.threading = c->workers ? OB_THREADING_MULTI : OB_THREADING_SINGLE;
    if (desc->width) sd->width = desc->width;
    if (desc->height) sd->height = desc->height;
    if (desc->znear > 0) sd->camera.znear = desc->znear;
    if (desc->env_map_size) sd->env_map_size = desc->env_map_size;
    if (desc->shadow_map_size) sd->shadow_map_size = desc->shadow_map_size;
    if (desc->clear_color[3] > 0.0f) memcpy(sd->clear_color, desc->clear_color, sizeof sd->clear_color);
    ob_world_create(&w->world, &wd);
    if (w->world.dev) {
        ob_device *dev = w->world.dev;
        if (!c->out->device_name[0]) {
            snprintf(c->out->device_name, sizeof c->out->device_name, "%s", ob_device_name(dev));
            snprintf(c->out->driver_info, sizeof c->out->driver_info, "%s", ob_device_driver_info(dev));
        }
        c->out->validation |= ob_device_validation_enabled(dev);
    }
    return w->world.err;
}

void ob_stab_world_destroy(ob_stab_world *w)
{
    if (w->world.stack) {
        ob_world_leftovers left = ob_world_destroy(&w->world);
        w->ctx->out->validation_messages += left.validation_errors + left.validation_warnings;
    }
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
    if (w->world.err != OB_OK) return NULL;
    uint64_t t0 = ob_time_ns();
    if (ob_world_frame(&w->world, mode, 0, extra, extra_count) != OB_OK) return NULL;
    double ms = (double)(ob_time_ns() - t0) * 1e-6;
    ob_stab_ctx *c = w->ctx;
    /* A renderer's first frame creates its pipelines: not what a case costs. */
    if (w->frames == 0 && c->first_count < OB_STAB_MAX_TIMES) c->first_ms[c->first_count++] = ms;
    else if (w->frames > 0 && c->steady_count < OB_STAB_MAX_TIMES) c->steady_ms[c->steady_count++] = ms;
    w->frames++;
    return ob_world_stats(&w->world);
}

uint8_t *ob_stab_snapshot(ob_stab_world *w)
{
    const uint8_t *pixels = ob_world_read(&w->world);
    if (!pixels) return NULL;
    size_t n = (size_t)w->world.width * w->world.height * 4;
    uint8_t *copy = ob_malloc(n);
    if (!copy) {
        log_failure(&w->world, OB_ERR_OUT_OF_HOST_MEMORY, "image copy", NULL);
        return NULL;
    }
    memcpy(copy, pixels, n);
    return copy;
}

uint8_t *ob_stab_render(ob_stab_world *w, const ob_frame_stats **out_stats)
{
    const ob_frame_stats *st = ob_stab_frame(w, OB_THREADING_SINGLE);
    if (out_stats) *out_stats = st;
    return ob_stab_snapshot(w);
}
