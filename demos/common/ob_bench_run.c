#include "ob_bench_run.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

typedef enum sample_kind { SAMPLE_WARMUP, SAMPLE_IDLE, SAMPLE_FLIGHT } sample_kind;

typedef struct sample {
    uint64_t serial;
    uint32_t mode, round;
    sample_kind kind;
    double update_ms, pre_render_ms, record_ms, assemble_ms, submit_ms, cpu_frame_ms;
    double cpu_no_update_ms, record_total_ms, gpu_ms, wall_ms;
    double draws, views;
    uint32_t workers;
    ob_pm_stats pm;
    uint64_t hash;
} sample;

typedef struct collector {
    sample *samples;
    uint32_t count, cap;
} collector;

/* Final stats arrive in frame order once a frame is known complete: attach
 * the GPU time to the sample of that frame. */
static void on_stats(void *user, const ob_frame_stats *st)
{
    collector *c = user;
    for (uint32_t i = c->count; i-- > 0;) {
        if (c->samples[i].serial == st->frame) {
            c->samples[i].gpu_ms = st->gpu_ms >= 0.0 ? st->gpu_ms : NAN;
            return;
        }
    }
}

void ob_bench_set_mode(ob_renderer *r, const ob_bench_mode *m)
{
    ob_renderer_set_threading(r, m->threading, m->threading == OB_THREADING_SINGLE ? 0 : m->workers);
}

/* One frame in mode m, its CPU stats kept as a sample. */
static ob_result frame(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c,
                       uint32_t mode, uint32_t round, sample_kind kind, bool advance)
{
    ob_renderer *r = s->demo->r;
    ob_bench_set_mode(r, &desc->modes[mode]);
    ob_result res = ob_bench_scene_frame(s, advance, desc->dt);
    if (res != OB_OK) return res;
    const ob_frame_stats *st = ob_renderer_current_stats(r);
    sample *p = &c->samples[c->count++];
    *p = (sample){
        .serial = st->frame, .mode = mode, .round = round, .kind = kind,
        .update_ms = advance ? st->update_ns * 1e-6 : NAN,
        .cpu_no_update_ms = (st->frame_ns - st->update_ns) * 1e-6, .pre_render_ms = st->pre_render_ns * 1e-6,
        .record_ms = st->record_ns * 1e-6, .assemble_ms = st->assemble_ns * 1e-6,
        .submit_ms = st->submit_ns * 1e-6, .cpu_frame_ms = st->frame_ns * 1e-6,
        .record_total_ms = (st->record_ns + st->assemble_ns) * 1e-6,
        .gpu_ms = NAN, .wall_ms = NAN, .draws = st->draws, .views = st->view_count,
        .workers = st->workers, .pm = st->pm, .hash = st->frame_hash,
    };
    if (desc->tick) desc->tick(desc->tick_user);
    return OB_OK;
}

static ob_result idle_loop(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c)
{
    ob_renderer *r = s->demo->r;
    for (uint32_t round = 0; round < desc->warmup + desc->rounds; round++) {
        sample_kind kind = round < desc->warmup ? SAMPLE_WARMUP : SAMPLE_IDLE;
        for (uint32_t m = 0; m < desc->mode_count; m++) {
            ob_result res = ob_renderer_wait_idle(r);
            if (res == OB_OK) res = frame(s, desc, c, m, round, kind, m == 0);
            if (res != OB_OK) return res;
        }
    }
    return ob_renderer_wait_idle(r);
}

static ob_result flight_loop(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c)
{
    ob_renderer *r = s->demo->r;
    for (uint32_t m = 0; m < desc->mode_count && desc->flight > 0; m++) {
        ob_result res = ob_renderer_wait_idle(r);
        /* One unmeasured frame fills the pipeline and applies the mode. */
        if (res == OB_OK) res = frame(s, desc, c, m, 0, SAMPLE_WARMUP, true);
        uint64_t prev = ob_time_ns();
        for (uint32_t i = 0; i < desc->flight && res == OB_OK; i++) {
            res = frame(s, desc, c, m, i, SAMPLE_FLIGHT, true);
            uint64_t now = ob_time_ns();
            c->samples[c->count - 1].wall_ms = (double)(now - prev) * 1e-6;
            prev = now;
        }
        if (res != OB_OK) return res;
    }
    return ob_renderer_wait_idle(r);
}

/* Median of one double field of the samples of a mode and kind. */
static double field_median(const collector *c, uint32_t mode, sample_kind kind, size_t offset,
                           double *buf)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < c->count; i++) {
        const sample *p = &c->samples[i];
        if (p->mode == mode && p->kind == kind) memcpy(&buf[n++], (const char *)p + offset, sizeof *buf);
    }
    return ob_demo_median(buf, n);
}

#define MEDIAN(m, kind, field) field_median(c, m, kind, offsetof(sample, field), buf)

static void summarize(const ob_bench_run_desc *desc, const collector *c, double *buf,
                      ob_bench_result *out)
{
    for (uint32_t m = 0; m < desc->mode_count; m++) {
        ob_bench_result *o = &out[m];
        memset(o, 0, sizeof *o);
        o->mode = desc->modes[m];
        uint32_t n = 0;
        double workers = 0.0;
        for (uint32_t i = 0; i < c->count; i++) {
            const sample *p = &c->samples[i];
            if (p->mode != m || p->kind != SAMPLE_IDLE) continue;
            n++;
            workers += p->workers;
            o->pm = p->pm;
            o->frame_hash = p->hash;
            /* The reference mode's frame of the same round. */
            for (uint32_t j = 0; j < c->count; j++) {
                const sample *q = &c->samples[j];
                if (q->mode == 0 && q->kind == SAMPLE_IDLE && q->round == p->round) {
                    if (q->hash != p->hash) o->hash_mismatches++;
                    break;
                }
            }
        }
        o->frames = n;
        o->workers_used = n ? workers / n : 0.0;
        o->draws = (uint32_t)MEDIAN(m, SAMPLE_IDLE, draws);
        o->views = (uint32_t)MEDIAN(m, SAMPLE_IDLE, views);
        /* Only the first mode of an idle round moves the scene on; every
         * in-flight frame does, so the update is measured there. */
        o->update_ms = MEDIAN(m, SAMPLE_FLIGHT, update_ms);
        if (isnan(o->update_ms)) o->update_ms = MEDIAN(m, SAMPLE_IDLE, update_ms);
        o->pre_render_ms = MEDIAN(m, SAMPLE_IDLE, pre_render_ms);
        o->record_ms = MEDIAN(m, SAMPLE_IDLE, record_ms);
        o->assemble_ms = MEDIAN(m, SAMPLE_IDLE, assemble_ms);
        o->submit_ms = MEDIAN(m, SAMPLE_IDLE, submit_ms);
        o->record_total_ms = MEDIAN(m, SAMPLE_IDLE, record_total_ms);
        o->cpu_frame_ms = MEDIAN(m, SAMPLE_IDLE, cpu_no_update_ms) + o->update_ms;
        o->gpu_ms = MEDIAN(m, SAMPLE_IDLE, gpu_ms);
        o->frame_ms = MEDIAN(m, SAMPLE_FLIGHT, wall_ms);
        o->draws_per_s = o->record_total_ms > 0.0 ? o->draws / (o->record_total_ms * 1e-3) : NAN;
    }
    for (uint32_t m = 0; m < desc->mode_count; m++) {
        out[m].speedup_record = out[0].record_total_ms / out[m].record_total_ms;
        out[m].speedup_frame = out[0].frame_ms / out[m].frame_ms;
    }
}

ob_result ob_bench_run_modes(ob_bench_scene *s, const ob_bench_run_desc *desc,
                             ob_bench_result *out)
{
    ob_renderer *r = s->demo->r;
    collector c = {0};
    c.cap = desc->mode_count * (desc->warmup + desc->rounds + desc->flight + 1);
    c.samples = ob_calloc(c.cap, sizeof *c.samples);
    double *buf = ob_calloc(c.cap, sizeof *buf);
    if (!c.samples || !buf) {
        ob_free(c.samples);
        ob_free(buf);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    ob_result res = ob_renderer_wait_idle(r);
    ob_renderer_set_stats_callback(r, on_stats, &c);
    if (res == OB_OK) res = idle_loop(s, desc, &c);
    if (res == OB_OK) res = flight_loop(s, desc, &c);
    ob_renderer_set_stats_callback(r, NULL, NULL);
    if (res == OB_OK) summarize(desc, &c, buf, out);
    ob_free(c.samples);
    ob_free(buf);
    return res;
}
