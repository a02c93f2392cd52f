#include "ob_bench_run.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* SAMPLE_SETTLE frames are rendered and not kept; SAMPLE_SLOWER_PASS ones
 * are idle frames slower than their mode's fastest of the round, kept only
 * for the hash check. */
typedef enum sample_kind {
    SAMPLE_WARMUP, SAMPLE_IDLE, SAMPLE_FLIGHT, SAMPLE_SETTLE, SAMPLE_SLOWER_PASS
} sample_kind;

typedef struct sample {
    uint64_t serial;
    uint32_t mode, round, pass;
    sample_kind kind;
    double update_ms, update_cpu_ms, pre_render_ms, record_ms, assemble_ms, submit_ms;
    double cpu_frame_ms, cpu_no_update_ms, record_total_ms, gpu_ms, gpu_views_ms, wall_ms;
    double gpu_rest_ms;        /* gpu_ms - gpu_views_ms of this frame */
    double upload_mb;
    double serial_fraction;
    double draws, views, vertices, lod_items;
    double cpu_render_ms, cpu_workers_ms, cpu_max_worker_ms, host_allocs_per_object;
    uint32_t workers;
    ob_pipeline_manager_stats pm;
    uint64_t hash;
} sample;

/* A mode's update of an idle round, timed around the call. */
typedef struct round_update {
    double wall_ms, cpu_ms;
    ob_update_stats st;        /* the renderer's figures of the call */
} round_update;

typedef struct collector {
    sample *samples;
    uint32_t count, cap;
    round_update *updates;     /* [round * mode_count + mode], warm-up rounds first */
} collector;

/* Final stats arrive in frame order once a frame is known complete: attach
 * the GPU time to the sample of that frame. */
static void on_stats(void *user, const ob_frame_stats *st)
{
    collector *c = user;
    for (uint32_t i = c->count; i-- > 0;) {
        if (c->samples[i].serial == st->frame) {
            c->samples[i].gpu_ms = st->gpu_ms >= 0.0 ? st->gpu_ms : NAN;
            /* The views' own stamps, summed: what the frame's GPU time
             * holds besides them is the uploads and the barriers between
             * views (NAN unless every view was stamped). */
            double views = st->view_count ? 0.0 : NAN;
            for (uint32_t v = 0; v < st->view_count; v++)
                views += st->views[v].gpu_ms >= 0.0 ? st->views[v].gpu_ms : NAN;
            c->samples[i].gpu_views_ms = views;
            c->samples[i].gpu_rest_ms = c->samples[i].gpu_ms - views;
            return;
        }
    }
}

uint32_t ob_bench_split_mode(const ob_bench_mode *modes, uint32_t count)
{
    uint32_t best = UINT32_MAX;
    for (uint32_t m = 0; m < count; m++)
        if (modes[m].threading == OB_THREADING_MULTI &&
            (best == UINT32_MAX || modes[m].workers > modes[best].workers))
            best = m;
    return best;
}

void ob_bench_set_mode(ob_renderer *r, const ob_bench_mode *m)
{
    ob_renderer_set_threading(r, m->threading, m->threading == OB_THREADING_SINGLE ? 0 : m->workers);
}

/* The recording CPU times of st into p. The render thread always records
 * or assembles something, so its 0 means the engine does not measure: NAN
 * then, so that medians say "unknown" rather than "free". */
static void cpu_figures(const ob_frame_stats *st, sample *p)
{
    if (st->record_cpu_ns[0] == 0) {
        p->cpu_render_ms = p->cpu_workers_ms = p->cpu_max_worker_ms = NAN;
        p->host_allocs_per_object = NAN;
        return;
    }
    uint64_t sum = 0, max = 0;
    for (uint32_t i = 1; i <= OB_MAX_WORKERS; i++) {
        sum += st->record_cpu_ns[i];
        max = OB_MAX(max, st->record_cpu_ns[i]);
    }
    p->cpu_render_ms = st->record_cpu_ns[0] * 1e-6;
    p->cpu_workers_ms = sum * 1e-6;
    p->cpu_max_worker_ms = max * 1e-6;
    p->host_allocs_per_object = st->draws ? (double)st->cmd_host_allocs / st->draws : NAN;
}

/* The serial share of the CPU time of a frame with its mode's update of
 * the round: the frame's own figures (less an update the renderer gave it,
 * which may be another mode's) and the update's; NAN when the engine does
 * not measure them. */
static double serial_fraction(const ob_frame_stats *st, const ob_update_stats *u)
{
    double render = (double)(st->cpu_render_ns - st->update_cpu_render_ns) + (double)u->cpu_render_ns;
    double parallel = (double)(st->cpu_render_parallel_ns - st->update_cpu_render_parallel_ns) +
                      (double)u->cpu_render_parallel_ns;
    double total = render + (double)(st->cpu_pool_ns - st->update_cpu_pool_ns) + (double)u->cpu_pool_ns;
    if (st->cpu_render_ns == 0 || total <= 0.0) return NAN;
    return (render - parallel) / total;
}

/* One frame in mode m, its CPU stats kept as a sample unless kind is
 * SAMPLE_SETTLE. An advancing frame (in flight) carries its own update in
 * its stats; an idle one gets its mode's update of the round. */
static ob_result frame(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c,
                       uint32_t mode, uint32_t round, uint32_t pass, sample_kind kind, bool advance)
{
    ob_renderer *r = s->demo->world.r;
    ob_bench_set_mode(r, &desc->modes[mode]);
    ob_result res = ob_bench_scene_frame(s, advance, desc->dt);
    if (res == OB_OK && desc->tick) desc->tick(desc->tick_user);
    if (res != OB_OK || kind == SAMPLE_SETTLE) return res;
    const ob_frame_stats *st = ob_renderer_current_stats(r);
    sample *p = &c->samples[c->count++];
    *p = (sample){
        .serial = st->frame, .mode = mode, .round = round, .pass = pass, .kind = kind,
        .update_ms = advance ? st->update_ns * 1e-6 : NAN, .update_cpu_ms = NAN,
        .cpu_no_update_ms = (st->frame_ns - st->update_ns) * 1e-6, .pre_render_ms = st->pre_render_ns * 1e-6,
        .record_ms = st->record_ns * 1e-6, .assemble_ms = st->assemble_ns * 1e-6,
        .submit_ms = st->submit_ns * 1e-6, .cpu_frame_ms = st->frame_ns * 1e-6,
        .record_total_ms = (st->record_ns + st->assemble_ns) * 1e-6,
        .gpu_ms = NAN, .gpu_views_ms = NAN, .gpu_rest_ms = NAN, .wall_ms = NAN,
        .draws = st->draws, .views = st->view_count,
        .upload_mb = (double)st->ring_upload_bytes / (1024.0 * 1024.0),
        .vertices = (double)st->pm.vertices, .lod_items = st->lod_items,
        .workers = st->workers, .pm = st->pm, .hash = st->frame_hash,
        .serial_fraction = NAN,
    };
    if (!advance) {
        const round_update *u = &c->updates[round * desc->mode_count + mode];
        p->update_ms = u->wall_ms;
        p->update_cpu_ms = u->cpu_ms;
        p->serial_fraction = serial_fraction(st, &u->st);
    }
    cpu_figures(st, p);
    return OB_OK;
}

/* The pass's frames (the last mode_count samples) to the hook, device idle. */
static ob_result round_hook(const ob_bench_run_desc *desc, const collector *c, uint32_t round,
                            uint32_t pass, ob_bench_round_sample *buf)
{
    const sample *first = &c->samples[c->count - desc->mode_count];
    for (uint32_t i = 0; i < desc->mode_count; i++) {
        const sample *p = &first[i];
        buf[p->mode] = (ob_bench_round_sample){p->record_total_ms, (uint32_t)p->draws};
    }
    return desc->round_hook(desc->round_user, round, pass, round >= desc->warmup, buf);
}

/* The k-th order of n modes, cycling through all n! orders (k read in the
 * factorial number system): over the passes every mode is preceded by every
 * other one equally often, and lands equally often on each frame slot after
 * each of them. A fixed cyclic order (only rotated) kept each mode after
 * the same one: AUTO always followed MT, on the frame slot MT had just
 * used, and measured 2-4% slower than MT for it on the 10k x 8 sweep. */
static void order_of(uint64_t k, uint32_t n, uint32_t *out)
{
    uint32_t left[OB_BENCH_MAX_MODES];
    uint64_t count = 1;
    for (uint32_t i = 0; i < n; i++) {
        left[i] = i;
        count *= i + 1;
    }
    k %= count;
    for (uint32_t i = 0; i < n; i++) {
        count /= n - i;
        uint32_t pick = (uint32_t)(k / count);
        k %= count;
        out[i] = left[pick];
        for (uint32_t j = pick; j + 1 < n - i; j++) left[j] = left[j + 1];
    }
}

/* The round's updates, device idle: each mode in the round's order moves
 * the scene on once under its own threading, timed here; the renderer's
 * figures of the call (ob_renderer_last_update_stats) give its CPU split.
 * Like a measured frame, a measured update comes after the mode's settle
 * updates (unmeasured), so that it finds the mode as a program updating in
 * it would: pool threads awake from its last hand-out, each core's caches
 * holding the nodes it wrote, not the last mode's. Without them, the
 * update of a mode on the workers always came after the wait for the
 * device or a single-threaded update (the order only rotates): its pool
 * thread asleep, 15-40 us to join, and the nodes written from the other
 * core. */
static ob_result round_updates(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c,
                               uint32_t round, const uint32_t *order)
{
    ob_renderer *r = s->demo->world.r;
    ob_result res = ob_renderer_wait_idle(r);
    for (uint32_t i = 0; i < desc->mode_count && res == OB_OK; i++) {
        uint32_t m = order[i];
        ob_bench_set_mode(r, &desc->modes[m]);
        for (uint32_t k = 0; k < desc->settle && res == OB_OK; k++)
            res = ob_bench_scene_advance(s, desc->dt);
        if (res != OB_OK) break;
        uint64_t t0 = ob_time_ns(), c0 = ob_thread_cpu_ns();
        res = ob_bench_scene_advance(s, desc->dt);
        uint64_t c1 = ob_thread_cpu_ns(), t1 = ob_time_ns();
        round_update *u = &c->updates[round * desc->mode_count + m];
        *u = (round_update){(t1 - t0) * 1e-6, (c1 - c0) * 1e-6, {0}};
        ob_renderer_last_update_stats(r, &u->st);
    }
    return res;
}

static ob_result idle_loop(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c)
{
    ob_renderer *r = s->demo->world.r;
    ob_bench_round_sample round_modes[OB_BENCH_MAX_MODES];
    uint32_t passes = OB_MAX(desc->passes, 1u);
    for (uint32_t round = 0; round < desc->warmup + desc->rounds; round++) {
        sample_kind kind = round < desc->warmup ? SAMPLE_WARMUP : SAMPLE_IDLE;
        for (uint32_t pass = 0; pass < passes; pass++) {
            /* A new order each pass, so every mode takes every place and
               follows every other mode equally often: a mode is not always
               right after the workers ran (their caches warm from
               recording). */
            uint32_t order[OB_BENCH_MAX_MODES];
            order_of((uint64_t)round * passes + pass, desc->mode_count, order);
            if (pass == 0) {
                /* The updates rotate by round, so that every mode updates
                 * first (on caches the frames left cold) equally often
                 * within mode_count rounds: the passes' orders repeat with
                 * the pass count, and the first (modes - 1)! orders all
                 * start with the same mode. */
                uint32_t update_order[OB_BENCH_MAX_MODES];
                for (uint32_t i = 0; i < desc->mode_count; i++)
                    update_order[i] = (i + round) % desc->mode_count;
                ob_result res = round_updates(s, desc, c, round, update_order);
                if (res != OB_OK) return res;
            }
            for (uint32_t i = 0; i < desc->mode_count; i++) {
                uint32_t m = order[i];
                /* Settle frames first: the measured one then finds the mode
                 * as a program running in it would (worker threads awake,
                 * their caches holding this scene), not just switched. */
                for (uint32_t k = 0; k <= desc->settle; k++) {
                    ob_result res = ob_renderer_wait_idle(r);
                    if (res == OB_OK)
                        res = frame(s, desc, c, m, round, pass,
                                    k < desc->settle ? SAMPLE_SETTLE : kind, false);
                    if (res != OB_OK) return res;
                }
            }
            if (!desc->round_hook) continue;
            ob_result res = ob_renderer_wait_idle(r);
            if (res == OB_OK) res = round_hook(desc, c, round, pass, round_modes);
            if (res != OB_OK) return res;
        }
    }
    return ob_renderer_wait_idle(r);
}

static ob_result flight_loop(ob_bench_scene *s, const ob_bench_run_desc *desc, collector *c)
{
    ob_renderer *r = s->demo->world.r;
    for (uint32_t m = 0; m < desc->mode_count && desc->flight > 0; m++) {
        ob_result res = ob_renderer_wait_idle(r);
        /* One unmeasured frame fills the pipeline and applies the mode. */
        if (res == OB_OK) res = frame(s, desc, c, m, 0, 0, SAMPLE_WARMUP, true);
        uint64_t prev = ob_time_ns();
        for (uint32_t i = 0; i < desc->flight && res == OB_OK; i++) {
            res = frame(s, desc, c, m, i, 0, SAMPLE_FLIGHT, true);
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
    return ob_median(buf, n);
}

void ob_bench_spread_of(double *values, uint32_t n, ob_bench_spread *out)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++)
        if (!isnan(values[i])) values[k++] = values[i];
    if (!k) {
        *out = (ob_bench_spread){NAN, NAN, NAN};
        return;
    }
    /* ob_median sorts; its median is the 0.5 quantile below. */
    out->median = ob_median(values, k);
    double at[2] = {0.25 * (k - 1), 0.75 * (k - 1)};
    double q[2];
    for (int i = 0; i < 2; i++) {
        uint32_t lo = (uint32_t)at[i], hi = OB_MIN(lo + 1, k - 1);
        q[i] = values[lo] + (values[hi] - values[lo]) * (at[i] - lo);
    }
    out->p25 = q[0];
    out->p75 = q[1];
}

/* The frame of a kind of a mode in a round; NULL if it is missing. */
static const sample *round_sample(const collector *c, sample_kind kind, uint32_t mode,
                                  uint32_t round)
{
    for (uint32_t i = 0; i < c->count; i++) {
        const sample *p = &c->samples[i];
        if (p->kind == kind && p->mode == mode && p->round == round) return p;
    }
    return NULL;
}

/* The idle frame of a mode in a round (its kept pass); NULL if it is missing. */
static const sample *idle_sample(const collector *c, uint32_t mode, uint32_t round)
{
    return round_sample(c, SAMPLE_IDLE, mode, round);
}

/* The frame's CPU phases after the update, wall time. */
static double frame_phases_ms(const sample *p)
{
    return p->pre_render_ms + p->record_ms + p->assemble_ms + p->submit_ms;
}

static double pre_render_ms(const sample *p) { return p->pre_render_ms; }

/* The lowest figure of a mode's passes of a measured round (kept or
 * slower by recording time): interference only ever adds time, so each
 * figure takes its own fastest pass (keep_fastest_passes). NAN if none. */
static double fastest_pass(const collector *c, uint32_t mode, uint32_t round,
                           double (*figure)(const sample *))
{
    double best = NAN;
    for (uint32_t i = 0; i < c->count; i++) {
        const sample *p = &c->samples[i];
        if ((p->kind != SAMPLE_IDLE && p->kind != SAMPLE_SLOWER_PASS) || p->mode != mode ||
            p->round != round)
            continue;
        double v = figure(p);
        if (isnan(best) || v < best) best = v;
    }
    return best;
}

/* A mode's CPU phases of a round's frame: its update of the round + the
 * fastest pass of the rest. */
static double round_frame_ms(const ob_bench_run_desc *desc, const collector *c, uint32_t mode,
                             uint32_t round)
{
    return c->updates[round * desc->mode_count + mode].wall_ms +
           fastest_pass(c, mode, round, frame_phases_ms);
}

/* Ratios within each idle round, then their median: both frames of a ratio
 * saw the same state of the machine, which a ratio of two medians taken
 * from different frames does not promise. */
static void round_ratios(const ob_bench_run_desc *desc, const collector *c, double *buf,
                         ob_bench_result *out)
{
    /* The best fixed mode: lowest median recording time over the rounds. */
    uint32_t best_mode = UINT32_MAX;
    double best_median = INFINITY;
    for (uint32_t m = 0; m < desc->mode_count; m++) {
        if (desc->modes[m].threading == OB_THREADING_AUTO) continue;
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            buf[k] = p ? p->record_total_ms : NAN;
        }
        double med = ob_median(buf, desc->rounds);
        if (med < best_median) best_median = med, best_mode = m;
    }
    double *round_min = buf + desc->rounds;
    for (uint32_t k = 0; k < desc->rounds; k++) {
        round_min[k] = INFINITY;
        for (uint32_t m = 0; m < desc->mode_count; m++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            if (p && desc->modes[m].threading != OB_THREADING_AUTO)
                round_min[k] = fmin(round_min[k], p->record_total_ms);
        }
    }
    for (uint32_t m = 0; m < desc->mode_count; m++) {
        ob_bench_spread sp;
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *ref = idle_sample(c, 0, desc->warmup + k);
            const sample *p = idle_sample(c, m, desc->warmup + k);
            buf[k] = ref && p ? ref->record_total_ms / p->record_total_ms : NAN;
        }
        ob_bench_spread_of(buf, desc->rounds, &sp);
        out[m].speedup_record = sp.median;
        out[m].speedup_record_p25 = sp.p25;
        out[m].speedup_record_p75 = sp.p75;
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            const sample *b = best_mode < desc->mode_count ? idle_sample(c, best_mode, desc->warmup + k)
                                                           : NULL;
            buf[k] = p && b ? p->record_total_ms / b->record_total_ms : NAN;
        }
        ob_bench_spread_of(buf, desc->rounds, &out[m].vs_best_fixed_record);
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            buf[k] = p && isfinite(round_min[k]) ? p->record_total_ms / round_min[k] : NAN;
        }
        ob_bench_spread_of(buf, desc->rounds, &out[m].vs_round_min_record);
        for (uint32_t k = 0; k < desc->rounds; k++)
            buf[k] = round_frame_ms(desc, c, 0, desc->warmup + k) /
                     round_frame_ms(desc, c, m, desc->warmup + k);
        ob_bench_spread_of(buf, desc->rounds, &out[m].frame_cpu_speedup);
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            buf[k] = p ? p->update_ms : NAN;
        }
        ob_bench_spread_of(buf, desc->rounds, &out[m].update_round_ms);
        for (uint32_t k = 0; k < desc->rounds; k++)
            buf[k] = fastest_pass(c, m, desc->warmup + k, pre_render_ms);
        ob_bench_spread_of(buf, desc->rounds, &out[m].pre_render_round_ms);
        for (uint32_t k = 0; k < desc->rounds; k++) {
            const sample *p = idle_sample(c, m, desc->warmup + k);
            buf[k] = p ? p->serial_fraction : NAN;
        }
        ob_bench_spread_of(buf, desc->rounds, &out[m].serial_fraction);
    }
}

/* Keeps each mode's fastest pass of every measured round as its idle
 * sample of the round; the slower passes become SAMPLE_SLOWER_PASS. */
static void keep_fastest_passes(collector *c)
{
    for (uint32_t i = 0; i < c->count; i++) {
        sample *p = &c->samples[i];
        if (p->kind != SAMPLE_IDLE) continue;
        for (uint32_t j = i + 1; j < c->count; j++) {
            sample *q = &c->samples[j];
            if (q->kind != SAMPLE_IDLE || q->mode != p->mode || q->round != p->round) continue;
            /* Ties keep the earlier pass. */
            if (q->record_total_ms < p->record_total_ms) {
                p->kind = SAMPLE_SLOWER_PASS;
                break;
            }
            q->kind = SAMPLE_SLOWER_PASS;
        }
    }
}

#define MEDIAN(m, kind, field) field_median(c, m, kind, offsetof(sample, field), buf)

static void summarize(const ob_bench_run_desc *desc, collector *c, double *buf,
                      ob_bench_result *out)
{
    keep_fastest_passes(c);
    for (uint32_t m = 0; m < desc->mode_count; m++) {
        ob_bench_result *o = &out[m];
        memset(o, 0, sizeof *o);
        o->mode = desc->modes[m];
        uint32_t n = 0;
        double workers = 0.0;
        for (uint32_t i = 0; i < c->count; i++) {
            const sample *p = &c->samples[i];
            bool idle = p->kind == SAMPLE_IDLE;
            if (p->mode != m || (!idle && p->kind != SAMPLE_SLOWER_PASS)) continue;
            if (idle) {
                n++;
                workers += p->workers;
                o->pm = p->pm;
                o->frame_hash = p->hash;
            }
            /* The reference mode's kept frame of the same round: every pass
             * of every mode must have recorded its commands. */
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
        o->vertices = MEDIAN(m, SAMPLE_IDLE, vertices);
        o->lod_items = (uint32_t)MEDIAN(m, SAMPLE_IDLE, lod_items);
        /* Each kept idle frame carries its mode's update of the round. */
        o->update_ms = MEDIAN(m, SAMPLE_IDLE, update_ms);
        o->update_cpu_ms = MEDIAN(m, SAMPLE_IDLE, update_cpu_ms);
        o->pre_render_ms = MEDIAN(m, SAMPLE_IDLE, pre_render_ms);
        o->record_ms = MEDIAN(m, SAMPLE_IDLE, record_ms);
        o->assemble_ms = MEDIAN(m, SAMPLE_IDLE, assemble_ms);
        o->submit_ms = MEDIAN(m, SAMPLE_IDLE, submit_ms);
        o->record_total_ms = MEDIAN(m, SAMPLE_IDLE, record_total_ms);
        o->cpu_frame_ms = MEDIAN(m, SAMPLE_IDLE, cpu_no_update_ms) + o->update_ms;
        o->gpu_ms = MEDIAN(m, SAMPLE_IDLE, gpu_ms);
        o->gpu_views_ms = MEDIAN(m, SAMPLE_IDLE, gpu_views_ms);
        o->gpu_rest_ms = MEDIAN(m, SAMPLE_IDLE, gpu_rest_ms);
        o->gpu_flight_ms = MEDIAN(m, SAMPLE_FLIGHT, gpu_ms);
        o->upload_mb = MEDIAN(m, SAMPLE_IDLE, upload_mb);
        o->frame_ms = MEDIAN(m, SAMPLE_FLIGHT, wall_ms);
        o->draws_per_s = o->record_total_ms > 0.0 ? o->draws / (o->record_total_ms * 1e-3) : NAN;
        o->record_cpu_render_ms = MEDIAN(m, SAMPLE_IDLE, cpu_render_ms);
        o->record_cpu_workers_ms = MEDIAN(m, SAMPLE_IDLE, cpu_workers_ms);
        o->record_cpu_max_worker_ms = MEDIAN(m, SAMPLE_IDLE, cpu_max_worker_ms);
        o->cmd_host_allocs_per_object = MEDIAN(m, SAMPLE_IDLE, host_allocs_per_object);
        const ob_pipeline_manager_stats *p = &o->pm;
        uint64_t commands = (uint64_t)p->draw_calls + p->dispatches + p->pipeline_binds_issued +
                            p->descriptor_binds_issued + p->push_descriptor_issued +
                            p->push_constant_issued + p->vertex_binds_issued + p->index_binds_issued;
        o->commands_per_object = p->draws ? (double)commands / p->draws : NAN;
    }
    uint32_t split = ob_bench_split_mode(desc->modes, desc->mode_count);
    if (split != UINT32_MAX) out[split].split = true;
    /* The flight loop runs the modes one after another: no rounds to pair. */
    for (uint32_t m = 0; m < desc->mode_count; m++)
        out[m].speedup_frame = out[0].frame_ms / out[m].frame_ms;
    round_ratios(desc, c, buf, out);
}

ob_result ob_bench_run_modes(ob_bench_scene *s, const ob_bench_run_desc *desc,
                             ob_bench_result *out)
{
    ob_renderer *r = s->demo->world.r;
    if (desc->mode_count == 0 || desc->mode_count > OB_BENCH_MAX_MODES)
        return OB_ERR_INVALID_ARGUMENT;
    collector c = {0};
    uint32_t rounds = desc->warmup + desc->rounds;
    /* Per mode its idle and in-flight frames. */
    c.cap = desc->mode_count * (rounds * OB_MAX(desc->passes, 1u) + desc->flight + 1);
    c.samples = ob_calloc(c.cap, sizeof *c.samples);
    c.updates = ob_calloc((size_t)OB_MAX(rounds, 1u) * desc->mode_count, sizeof *c.updates);
    /* Medians take up to cap values; round ratios two arrays of rounds. */
    double *buf = ob_calloc(OB_MAX(c.cap, 2 * desc->rounds), sizeof *buf);
    if (!c.samples || !c.updates || !buf) {
        ob_free(c.samples);
        ob_free(c.updates);
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
    ob_free(c.updates);
    ob_free(buf);
    return res;
}
