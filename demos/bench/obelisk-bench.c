/* obelisk-bench — what multithreaded recording buys, what the engine costs
 * per draw, and what quality costs.
 *
 *   sweep      views × objects × threading modes (ST, 1, 2, 4 workers,
 *              auto) on the sweep scene (demos/bench/ob_bench_scene.h: a
 *              "view" is one more camera's perspective view of the whole
 *              scene): CPU time per phase and recording time with the device
 *              idle, frame time with frames in flight, GPU time, draws per
 *              second, binds requested / issued, command hashes (equal in
 *              every mode, else the run fails)
 *   raw        the same draws recorded with bare Vulkan (ob_bench_raw.h):
 *              engine ns per draw / raw ns per draw
 *   scene200   obelisk-mirror's 200-object scene in ST, MT and auto
 *   quality    env-map and shadow-map sizes: image error against the
 *              highest-quality single-threaded image next to frame time; the
 *              threading modes must give that image byte for byte; MSAA
 *              sample counts against a supersampled antialiasing reference
 *   lights     frame cost against point-light count at fixed coverage, with
 *              the tile grid and with every light everywhere
 *              (ob_bench_lights.h)
 *   teardown   destroying a scene graph of 100k entities, in one call and
 *              one entity at a time (no device)
 *   stability  numerical precision and extreme cases (ob_stability.h):
 *              each case's error against the bound its test asserts, and its
 *              run time
 *
 * Medians of repeated frames after warm-up; every ratio comes from one run.
 * Fixed seeds. A program, not a test: it never judges a time; it fails
 * when a threading mode's image or command hashes differ (exit 4) or a
 * stability case exceeds its bound (exit 5). It stops before measuring
 * anything when the standard effects do not compile (exit 6: the shader
 * folder is wrong, say), since every frame would then draw nothing.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_bench_machine.h"
#include "ob_bench_progress.h"
#include "ob_bench_report.h"

#define MAX_LIST 8

typedef struct bench_options {
    bool quick, progress;
    bool perf, stability;      /* which sections run */
    bool sweep_only;           /* --sweep-only: of the performance sections, the sweep */
    bool no_instancing;        /* --no-instancing: one draw per entity */
    bool no_lod;               /* --no-lod: the sweep's shapes at level 0 everywhere */
    bool cpu_device;           /* the device is a CPU (lavapipe): big frames get fewer frames */
    ob_gpu_timing gpu_timing;  /* --gpu-timing */
    const char *json, *csv, *charts;
    uint32_t seed;
    uint32_t views[MAX_LIST], view_count;
    uint32_t objects[MAX_LIST], object_count;
    ob_bench_mode modes[OB_BENCH_MAX_MODES];
    char mode_names[OB_BENCH_MAX_MODES][8];
    uint32_t mode_count;
    uint32_t warmup, rounds, flight;
    uint32_t passes;           /* --passes N */
    uint32_t settle;           /* --settle N */
    uint32_t view_width, view_height, image_width, image_height;
    uint32_t raw_objects;
} bench_options;

static const char usage_text[] =
    "usage: obelisk-bench [options]\n"
    "  --quick            a reduced run (two to three minutes on 2 cores; views 1,8, modes\n"
    "                     ST,2,auto, and 50000 objects in 1 view only)\n"
    "  --stability-only   only the numerical stability and extreme cases section\n"
    "  --no-stability     leave that section out\n"
    "  --sweep-only       only the sweep (the per-configuration table): no per-draw rerun,\n"
    "                     mirror scene, quality, lights or stability (profiling)\n"
    "  --no-instancing    one draw per entity (the per-draw push block), for comparison\n"
    "  --no-lod           the sweep's shapes at full detail however small (levels of detail\n"
    "                     off), for comparison\n"
    "  --gpu-timing sampled|views|off   GPU timestamps: the frame's every frame and each\n"
    "                     view's every 16th (default), every view every frame, or none\n"
    "  --json FILE        write every result and the summary as JSON\n"
    "  --csv FILE         write every result as CSV (one row per configuration); the\n"
    "                     stability rows go to FILE-stability.csv (FILE less .csv)\n"
    "  --charts DIR       write speedup.png and error.png (gnuplot; performance only)\n"
    "  --views LIST       perspective views per frame (default 1,4,8,16)\n"
    "  --objects LIST     objects (default 1000,10000,50000; at most 100000)\n"
    "  --modes LIST       ST, worker counts, auto (default ST,1,2,4,auto)\n"
    "  --warmup N --rounds N --flight N   idle rounds (warm-up 3, measured 15 quick / 7),\n"
    "                     in-flight frames per mode (2 quick / 5)\n"
    "  --passes N         frames per mode in each idle round, the fastest kept (3)\n"
    "  --settle N         unmeasured frames of a mode before each measured idle one (2:\n"
    "                     the frames in flight, so each reuses a slot of its own mode),\n"
    "                     and updates before its measured update\n"
    "  --view-size WxH    size of each sweep view (default 256x192)\n"
    "  --size WxH         size of the quality images (default 640x480)\n"
    "  --seed S           scene seed (default 1)\n"
    "  --no-progress      no progress bar even on a terminal\n";

static bool parse_list(const char *s, uint32_t *out, uint32_t *count, uint32_t max_value)
{
    *count = 0;
    char *end;
    while (*s) {
        unsigned long v = strtoul(s, &end, 10);
        if (end == s || v == 0 || v > max_value || *count >= MAX_LIST) return false;
        out[(*count)++] = (uint32_t)v;
        s = *end == ',' ? end + 1 : end;
        if (*end && *end != ',') return false;
    }
    return *count > 0;
}

static bool parse_modes(const char *s, bench_options *o)
{
    char buf[128];
    snprintf(buf, sizeof buf, "%s", s);
    o->mode_count = 0;
    /* auto hands work to as many workers as there are cores, like a
     * renderer created with the default pool. */
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    uint32_t cores = ncpu > 0 ? (uint32_t)OB_MIN(ncpu, (long)OB_MAX_WORKERS) : 1;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (o->mode_count >= OB_BENCH_MAX_MODES) return false;
        ob_bench_mode *m = &o->modes[o->mode_count];
        snprintf(o->mode_names[o->mode_count], sizeof o->mode_names[0], "%s", tok);
        m->name = o->mode_names[o->mode_count];
        if (!strcmp(tok, "ST")) {
            *m = (ob_bench_mode){m->name, OB_THREADING_SINGLE, 0};
        } else if (!strcmp(tok, "auto")) {
            *m = (ob_bench_mode){m->name, OB_THREADING_AUTO, cores};
        } else {
            char *end;
            unsigned long w = strtoul(tok, &end, 10);
            if (*end || w == 0 || w > OB_MAX_WORKERS) return false;
            *m = (ob_bench_mode){m->name, OB_THREADING_MULTI, (uint32_t)w};
        }
        o->mode_count++;
    }
    return o->mode_count > 0 && o->modes[0].threading == OB_THREADING_SINGLE;
}

static bool parse_size(const char *s, uint32_t *w, uint32_t *h)
{
    return sscanf(s, "%ux%u", w, h) == 2 && *w >= 16 && *h >= 16 && *w <= 4096 && *h <= 4096;
}

static bool parse_options(int argc, char **argv, bench_options *o, int *out_exit)
{
    bool quick = false;
    for (int i = 1; i < argc; i++) quick |= !strcmp(argv[i], "--quick");
    *o = (bench_options){.quick = quick, .progress = true, .perf = true, .stability = true,
                         .seed = 1, .view_width = 256,
                         .view_height = 192, .image_width = 640, .image_height = 480,
                         .raw_objects = 10000};
    const char *views = quick ? "1,8" : "1,4,8,16";
    const char *objects = "1000,10000,50000";
    const char *modes = quick ? "ST,2,auto" : "ST,1,2,4,auto";
    /* Warm-up rounds until the workers' own state (uniform rings, set
     * caches, command pool arenas: per worker and frame slot) is made: in
     * the first rounds a frame on the workers records slower than it will,
     * and AUTO, measuring it, rightly records inline there. */
    o->warmup = 3;
    /* Medians of per-round ratios need rounds to hold still from run to
     * run: each round's figure of a mode is the fastest of 3 frames, the
     * modes in a new order each pass (docs/benchmark.md has how still the
     * figures hold). The in-flight loop feeds no summary ratio, so --quick
     * keeps it short. */
    o->rounds = quick ? 15 : 7;
    o->passes = 3;
    o->flight = quick ? 2 : 5;
    /* Two unmeasured frames of a mode before each measured one: with the
     * renderer's two frames in flight, the measured frame then reuses a frame
     * slot its own mode recorded last, as in a program that stays in one
     * mode. With none, a slot's command pools held another mode's frame,
     * and each mode paid for freeing the other's commands (inline, all of a
     * frame's in the primary; on the workers, theirs in each pool). */
    o->settle = 2;
    *out_exit = 2;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = true, takes = true;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage_text, stdout);
            *out_exit = 0;
            return false;
        } else if (!strcmp(a, "--quick")) {
            takes = false;
        } else if (!strcmp(a, "--no-progress")) {
            o->progress = takes = false;
        } else if (!strcmp(a, "--stability-only")) {
            o->perf = takes = false;
        } else if (!strcmp(a, "--no-instancing")) {
            o->no_instancing = true;
            takes = false;
        } else if (!strcmp(a, "--no-lod")) {
            o->no_lod = true;
            takes = false;
        } else if (!strcmp(a, "--no-stability")) {
            o->stability = takes = false;
        } else if (!strcmp(a, "--sweep-only")) {
            o->sweep_only = true;
            o->stability = takes = false;
        } else if (!v) {
            fprintf(stderr, "obelisk-bench: %s needs a value (or is unknown)\n%s", a, usage_text);
            return false;
        } else if (!strcmp(a, "--json")) {
            o->json = v;
        } else if (!strcmp(a, "--csv")) {
            o->csv = v;
        } else if (!strcmp(a, "--charts")) {
            o->charts = v;
        } else if (!strcmp(a, "--views")) {
            views = v;
        } else if (!strcmp(a, "--objects")) {
            objects = v;
        } else if (!strcmp(a, "--modes")) {
            modes = v;
        } else if (!strcmp(a, "--warmup") || !strcmp(a, "--rounds") || !strcmp(a, "--flight") ||
                   !strcmp(a, "--settle") || !strcmp(a, "--seed") || !strcmp(a, "--passes")) {
            char *end;
            unsigned long n = strtoul(v, &end, 10);
            ok = *v && !*end && n <= 1000;
            uint32_t *dst = !strcmp(a, "--warmup") ? &o->warmup : !strcmp(a, "--rounds") ? &o->rounds
                            : !strcmp(a, "--flight") ? &o->flight
                            : !strcmp(a, "--settle") ? &o->settle
                            : !strcmp(a, "--passes") ? &o->passes : &o->seed;
            *dst = (uint32_t)n;
            if (dst == &o->rounds || dst == &o->passes) ok = ok && n > 0;
        } else if (!strcmp(a, "--gpu-timing")) {
            ok = true;
            if (!strcmp(v, "sampled"))
                o->gpu_timing = OB_GPU_TIMING_SAMPLED;
            else if (!strcmp(v, "views"))
                o->gpu_timing = OB_GPU_TIMING_EVERY_VIEW;
            else if (!strcmp(v, "off"))
                o->gpu_timing = OB_GPU_TIMING_OFF;
            else
                ok = false;
        } else if (!strcmp(a, "--view-size")) {
            ok = parse_size(v, &o->view_width, &o->view_height);
        } else if (!strcmp(a, "--size")) {
            ok = parse_size(v, &o->image_width, &o->image_height);
        } else {
            fprintf(stderr, "obelisk-bench: unknown option '%s'\n%s", a, usage_text);
            return false;
        }
        if (!ok) {
            fprintf(stderr, "obelisk-bench: bad value '%s' for %s\n", v, a);
            return false;
        }
        if (takes) i++;
    }
    if (!parse_list(views, o->views, &o->view_count, OB_BENCH_MAX_VIEWS) ||
        !parse_list(objects, o->objects, &o->object_count, 100000) || !parse_modes(modes, o)) {
        fprintf(stderr, "obelisk-bench: bad --views, --objects or --modes list (modes must start "
                        "with ST; views 1..%u)\n", OB_BENCH_MAX_VIEWS);
        return false;
    }
    if (!o->perf && !o->stability) {
        fprintf(stderr, "obelisk-bench: --stability-only and --no-stability leave nothing to run\n");
        return false;
    }
    if (!o->perf && o->charts) {
        fprintf(stderr, "obelisk-bench: --charts draws the performance sections, which "
                        "--stability-only leaves out\n");
        return false;
    }
    *out_exit = 0;
    return true;
}

/* ------------------------------------------------------------ steps */

static uint32_t pool_size(const bench_options *o, uint32_t cores)
{
    uint32_t pool = cores;
    for (uint32_t m = 0; m < o->mode_count; m++) pool = OB_MAX(pool, o->modes[m].workers);
    return OB_MIN(pool, (uint32_t)OB_MAX_WORKERS);
}

static ob_demo_options demo_options(const bench_options *o, uint32_t pool, uint32_t w, uint32_t h,
                                    uint32_t objects)
{
    return (ob_demo_options){.frames = 1, .threads = (int)pool, .width = w, .height = h,
                             .seed = o->seed, .objects = objects, .quiet = true,
                             .gpu_timing = o->gpu_timing};
}

/* Lavapipe executes every frame on the same two cores, at some 10-25 us
 * a draw: big frames get fewer repetitions so the full sweep stays near ten
 * minutes. A view draws about a third of the objects (ob_bench_scene.h).
 * A GPU draws them in milliseconds, so there they get the asked-for
 * warm-up and rounds: with one warm-up frame per mode, 16 views x 100k on
 * the H100 still grew the workers' rings in measured frames (16 workers
 * recorded in 19 ms, their busiest in 7 ms of CPU). */
#define BIG_FRAME_DRAWS 50000u

static bool big_frame(uint32_t views, uint32_t objects)
{
    return (uint64_t)views * objects / 3 > BIG_FRAME_DRAWS;
}

typedef struct frame_counts {
    uint32_t warmup, rounds, passes, settle, flight;
} frame_counts;

/* Big frames take seconds each in lavapipe: one pass, no settle frame. */
static frame_counts counts_for(const bench_options *o, uint32_t views, uint32_t objects)
{
    bool big = o->cpu_device && big_frame(views, objects);
    return (frame_counts){
        .warmup = big ? OB_MIN(o->warmup, 1u) : o->warmup,
        .rounds = big ? OB_MIN(o->rounds, 3u) : o->rounds,
        .passes = big ? 1u : o->passes,
        .settle = big ? 0u : o->settle,
        .flight = big ? OB_MIN(o->flight, 2u) : o->flight,
    };
}

/* --quick measures 50k objects in one view only (the per-object growth
 * from 1k to 50k), not in several: that keeps it to a few minutes. */
static bool config_runs(const bench_options *o, uint32_t views, uint32_t objects)
{
    return !(o->quick && views > 1 && objects > 10000);
}

/* Progress units of one sweep frame: its draws, so the bar follows time
 * (a mirror-scene frame, about 1500 draws at 640x480, counts as one). */
static uint64_t frame_weight(uint32_t views, uint32_t objects)
{
    return OB_MAX((uint64_t)views * objects / 3 / 1500, (uint64_t)1);
}

/* The raw baseline inside the sweep's idle rounds: after the engine's
 * frames of every pass, one raw recording of the same draw list, so the
 * engine and the raw loop are priced under the same state of the machine
 * and their ratio is taken per round, each side's fastest pass, as the
 * engine's modes are compared. */
typedef struct raw_rounds {
    ob_demo *demo;
    const ob_view *view;
    ob_bench_raw *raw;         /* made at the first round, once the view has a draw list */
    ob_bench_raw_sample last, last_instanced;
    uint32_t passes;
    double round_raw_ns, round_raw_instanced_ns, round_engine_ms;  /* this round's fastest so far */
    uint32_t round_engine_draws;
    double *raw_ms, *allocs_per_draw, *engine_vs_raw;  /* one per measured round */
    double *raw_instanced_ms, *engine_vs_raw_instanced;
    /* Each measured round's GPU time of the two loops, executed after its
     * last pass (ob_bench_raw_gpu_ms), and their ratio. */
    double *raw_gpu_ms, *raw_gpu_instanced_ms, *raw_gpu_ratio;
    uint32_t n, cap;
} raw_rounds;

static ob_result raw_round(void *user, uint32_t round, uint32_t pass, bool measured,
                           const ob_bench_round_sample *modes)
{
    (void)round;
    raw_rounds *rr = user;
    ob_result r = OB_OK;
    if (!rr->raw) {
        rr->raw = ob_bench_raw_create(rr->demo, rr->view, &r);
        /* One unmeasured pass warms the driver's allocator and the caches. */
        if (rr->raw) r = ob_bench_raw_record(rr->raw, &rr->last);
        if (r != OB_OK) return r;
    }
    r = ob_bench_raw_record(rr->raw, &rr->last);
    if (r == OB_OK) r = ob_bench_raw_record_instanced(rr->raw, &rr->last_instanced);
    if (r != OB_OK || !measured || rr->n >= rr->cap || rr->last.draws == 0) return r;
    if (pass == 0 || (double)rr->last.ns < rr->round_raw_ns) rr->round_raw_ns = (double)rr->last.ns;
    if (pass == 0 || (double)rr->last_instanced.ns < rr->round_raw_instanced_ns)
        rr->round_raw_instanced_ns = (double)rr->last_instanced.ns;
    if (pass == 0 || modes[0].record_total_ms < rr->round_engine_ms) {
        rr->round_engine_ms = modes[0].record_total_ms;
        rr->round_engine_draws = modes[0].draws;
    }
    if (pass + 1 < rr->passes) return OB_OK;
    double raw_ns = rr->round_raw_ns / rr->last.draws;
    double engine_ns = rr->round_engine_draws ? rr->round_engine_ms * 1e6 / rr->round_engine_draws
                                              : NAN;
    rr->raw_ms[rr->n] = rr->round_raw_ns * 1e-6;
    rr->allocs_per_draw[rr->n] = (double)rr->last.host_allocs / rr->last.draws;
    rr->engine_vs_raw[rr->n] = engine_ns / raw_ns;
    rr->raw_instanced_ms[rr->n] = rr->round_raw_instanced_ns * 1e-6;
    rr->engine_vs_raw_instanced[rr->n] = engine_ns / (rr->round_raw_instanced_ns / rr->last.draws);
    /* Executed after the round's timed recordings, so none of them follows
     * an execution in its pass. */
    r = ob_bench_raw_gpu_ms(rr->raw, false, &rr->raw_gpu_ms[rr->n]);
    if (r == OB_OK) r = ob_bench_raw_gpu_ms(rr->raw, true, &rr->raw_gpu_instanced_ms[rr->n]);
    rr->raw_gpu_ratio[rr->n] = r == OB_OK ? rr->raw_gpu_instanced_ms[rr->n] / rr->raw_gpu_ms[rr->n]
                                          : NAN;
    rr->n++;
    return r;
}

/* The raw result and the per-round engine/raw ratio from the rounds. */
static void raw_results(raw_rounds *rr, ob_bench_report *rep)
{
    ob_bench_raw_result *o = &rep->raw;
    ob_bench_spread ms, allocs;
    ob_bench_spread_of(rr->raw_ms, rr->n, &ms);
    ob_bench_spread_of(rr->allocs_per_draw, rr->n, &allocs);
    ob_bench_spread_of(rr->engine_vs_raw, rr->n, &rep->engine_vs_raw);
    ob_bench_spread_of(rr->engine_vs_raw_instanced, rr->n, &rep->engine_vs_raw_instanced);
    ob_bench_spread ims, gpu, gpu_instanced;
    ob_bench_spread_of(rr->raw_instanced_ms, rr->n, &ims);
    ob_bench_spread_of(rr->raw_gpu_ms, rr->n, &gpu);
    ob_bench_spread_of(rr->raw_gpu_instanced_ms, rr->n, &gpu_instanced);
    ob_bench_spread_of(rr->raw_gpu_ratio, rr->n, &rep->raw_gpu_instanced_vs_per_draw);
    rep->raw_gpu_ms = gpu.median;
    rep->raw_gpu_instanced_ms = gpu_instanced.median;
    rep->raw_instanced = (ob_bench_raw_result){
        .draws = rr->last_instanced.draws, .reps = rr->n,
        .buffer_binds = rr->last_instanced.buffer_binds, .record_ms = ims.median,
        .ns_per_draw = rr->last_instanced.draws ? ims.median * 1e6 / rr->last_instanced.draws : NAN,
        .commands_per_object = rr->last_instanced.draws
                                   ? (double)rr->last_instanced.commands / rr->last_instanced.draws
                                   : NAN,
        .host_allocs_per_object = NAN,
    };
    *o = (ob_bench_raw_result){
        .draws = rr->last.draws, .reps = rr->n, .buffer_binds = rr->last.buffer_binds,
        .record_ms = ms.median,
        .ns_per_draw = rr->last.draws ? ms.median * 1e6 / rr->last.draws : NAN,
        .commands_per_object = rr->last.draws ? (double)rr->last.commands / rr->last.draws : NAN,
        .host_allocs_per_object = allocs.median,
    };
}

/* One sweep configuration, with the raw baseline in its rounds when it is
 * the raw one. */
static ob_result sweep_config(const bench_options *o, ob_bench_report *rep, uint32_t views,
                              uint32_t objects, ob_bench_progress *prog, ob_bench_sweep_entry *out)
{
    ob_demo_options dopt = demo_options(o, rep->pool_workers, o->view_width, o->view_height, objects);
    ob_demo d;
    ob_bench_scene s = {0};
    ob_result r = ob_demo_init(&d, &dopt);
    if (r == OB_OK && o->no_instancing) ob_material_library_set_instancing(d.world.stack->materials, false);
    if (r == OB_OK && o->no_lod) ob_views_set_lod(d.world.views, false);
    ob_bench_scene_desc sd = {.kind = OB_BENCH_SCENE_SWEEP, .objects = objects, .views = views,
                              .seed = o->seed};
    if (r == OB_OK && !rep->device_name[0]) {
        ob_device *dev = ob_renderer_device(d.world.r);
        snprintf(rep->device_name, sizeof rep->device_name, "%s", ob_device_name(dev));
        snprintf(rep->driver_info, sizeof rep->driver_info, "%s", ob_device_driver_info(dev));
        rep->validation = ob_device_validation_enabled(dev);
        rep->instance_runs = ob_renderer_instance_runs(d.world.r);
        rep->driver_heap_kept = ob_device_keeps_driver_heap(dev);
    }
    if (r == OB_OK) r = ob_bench_scene_build(&s, &d, &sd);
    ob_bench_run_desc rd = {.modes = o->modes, .mode_count = o->mode_count, .dt = 1.0 / 60.0,
                            .tick = ob_bench_progress_tick, .tick_user = prog};
    frame_counts fc = counts_for(o, views, objects);
    rd.warmup = fc.warmup;
    rd.rounds = fc.rounds;
    rd.passes = fc.passes;
    rd.settle = fc.settle;
    rd.flight = fc.flight;
    *out = (ob_bench_sweep_entry){.views = views, .objects = objects, .mode_count = o->mode_count};
    raw_rounds rr = {.demo = &d, .passes = rd.passes};
    bool raw = views == 1 && objects == o->raw_objects;
    if (r == OB_OK && raw) {
        rr.view = s.views[0];
        rr.cap = rd.rounds;
        rr.raw_ms = ob_calloc(8 * (size_t)rr.cap, sizeof *rr.raw_ms);
        if (rr.raw_ms) {
            rr.allocs_per_draw = rr.raw_ms + rr.cap;
            rr.engine_vs_raw = rr.raw_ms + 2 * rr.cap;
            rr.raw_instanced_ms = rr.raw_ms + 3 * rr.cap;
            rr.engine_vs_raw_instanced = rr.raw_ms + 4 * rr.cap;
            rr.raw_gpu_ms = rr.raw_ms + 5 * rr.cap;
            rr.raw_gpu_instanced_ms = rr.raw_ms + 6 * rr.cap;
            rr.raw_gpu_ratio = rr.raw_ms + 7 * rr.cap;
            rd.round_hook = raw_round;
            rd.round_user = &rr;
        } else {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
        }
    }
    if (r == OB_OK) r = ob_bench_run_modes(&s, &rd, out->results);
    if (r == OB_OK && raw) {
        raw_results(&rr, rep);
        rep->raw_views = views;
        rep->raw_objects = objects;
        const ob_bench_result *st = &out->results[0];
        rep->engine_ns_per_draw = st->record_total_ms * 1e6 / st->draws;
    }
    if (d.world.r) ob_renderer_wait_idle(d.world.r);
    ob_bench_raw_destroy(rr.raw);
    ob_free(rr.raw_ms);
    ob_bench_scene_release(&s);
    ob_demo_shutdown(&d);
    return r;
}

static ob_result scene200(const bench_options *o, ob_bench_report *rep, ob_bench_progress *prog)
{
    ob_demo_options dopt = demo_options(o, rep->pool_workers, o->image_width, o->image_height, 200);
    ob_demo d;
    ob_bench_scene s = {0};
    ob_result r = ob_demo_init(&d, &dopt);
    if (r == OB_OK && o->no_instancing) ob_material_library_set_instancing(d.world.stack->materials, false);
    ob_bench_scene_desc sd = {.kind = OB_BENCH_SCENE_MIRROR, .objects = 200, .seed = o->seed};
    if (r == OB_OK) r = ob_bench_scene_build(&s, &d, &sd);
    ob_bench_mode modes[3] = {{"ST", OB_THREADING_SINGLE, 0},
                              {"MT", OB_THREADING_MULTI, rep->cores},
                              {"auto", OB_THREADING_AUTO, rep->cores}};
    ob_bench_run_desc rd = {.modes = modes, .mode_count = 3, .warmup = o->warmup,
                            .rounds = o->rounds, .passes = o->passes, .settle = o->settle,
                            .flight = 2 * o->flight,
                            .dt = 1.0 / 60.0,
                            .tick = ob_bench_progress_tick, .tick_user = prog};
    rep->scene200 = (ob_bench_sweep_entry){.views = 1, .objects = 200, .mode_count = 3};
    if (r == OB_OK) r = ob_bench_run_modes(&s, &rd, rep->scene200.results);
    if (d.world.r) ob_renderer_wait_idle(d.world.r);
    ob_bench_scene_release(&s);
    ob_demo_shutdown(&d);
    return r;
}

static const ob_bench_sweep_entry *find_entry(const ob_bench_report *rep, uint32_t views,
                                              uint32_t objects)
{
    for (uint32_t i = 0; i < rep->sweep_count; i++)
        if (rep->sweep[i].views == views && rep->sweep[i].objects == objects) return &rep->sweep[i];
    return NULL;
}

/* The first auto mode's result; NULL without one. */
static const ob_bench_result *auto_result(const ob_bench_sweep_entry *e)
{
    for (uint32_t m = 0; e && m < e->mode_count; m++)
        if (e->results[m].mode.threading == OB_THREADING_AUTO) return &e->results[m];
    return NULL;
}

/* v with every value times k. */
static ob_bench_spread spread_scaled(ob_bench_spread v, double k)
{
    return (ob_bench_spread){v.median * k, v.p25 * k, v.p75 * k};
}

/* ST recording time per draw (ratio of the medians). */
static double st_ns_per_draw(const ob_bench_sweep_entry *e)
{
    if (!e || e->mode_count == 0 || e->results[0].draws == 0) return NAN;
    return e->results[0].record_total_ms * 1e6 / e->results[0].draws;
}

/* Teardown of a scene graph of `count` renderable entities, ns per entity:
 * batch in one ob_nodes_destroy, else one ob_node_destroy each, newest
 * first. The renderables' material and geometry pointers are never dereferenced: the scene
 * only interns the pointers. NAN when the scene cannot be built. */
#define TEARDOWN_ENTITIES 100000u

static double teardown_once(uint32_t count, bool batch)
{
    static const int material, geometry;
    ob_scene *s = ob_scene_create(NULL);
    ob_node **nodes = ob_calloc(count, sizeof *nodes);
    double ns = NAN;
    uint32_t made = 0;
    for (; s && nodes && made < count; made++) {
        nodes[made] = ob_node_create(s, NULL, "entity", NULL);
        if (!nodes[made]) break;
        ob_renderable rd = {.material = (struct ob_material *)(uintptr_t)&material,
                            .geometry = (struct ob_geometry *)(uintptr_t)&geometry,
                            .local_radius = 1.0f};
        if (ob_node_set_renderable(nodes[made], &rd) != OB_OK) break;
        ob_node_set_position(nodes[made], (double[3]){made % 300, 0.0, made / 300});
    }
    if (made == count && ob_scene_update(s, 0.0) == OB_OK) {
        uint64_t t0 = ob_time_ns();
        if (batch) ob_nodes_destroy(s, nodes, count);
        else
            for (uint32_t i = count; i-- > 0;) ob_node_destroy(nodes[i]);
        ns = (double)(ob_time_ns() - t0) / count;
    }
    ob_free(nodes);
    ob_scene_destroy(s);
    return ns;
}

static double teardown_ns(bool batch)
{
    double v[3];
    for (int i = 0; i < 3; i++) v[i] = teardown_once(TEARDOWN_ENTITIES, batch);
    return ob_median(v, 3);
}

static void summarize(ob_bench_report *rep)
{
    ob_bench_summary *s = &rep->summary;
    s->mt_speedup_record_10k_8views = (ob_bench_spread){NAN, NAN, NAN};
    for (uint32_t i = 0; i < rep->sweep_count; i++) {
        const ob_bench_sweep_entry *e = &rep->sweep[i];
        for (uint32_t m = 0; m < e->mode_count; m++) s->hash_mismatches += e->results[m].hash_mismatches;
    }
    const ob_bench_sweep_entry *e8 = find_entry(rep, 8, 10000);
    for (uint32_t m = 1; e8 && m < e8->mode_count; m++) {
        const ob_bench_result *r = &e8->results[m];
        double best = s->mt_speedup_record_10k_8views.median;
        if (r->mode.threading != OB_THREADING_MULTI || !(isnan(best) || r->speedup_record > best))
            continue;
        s->mt_speedup_record_10k_8views = (ob_bench_spread){r->speedup_record,
                                                            r->speedup_record_p25,
                                                            r->speedup_record_p75};
        s->mt_speedup_best_mode = r->mode.name;
    }
    /* The whole frame's CPU phases and their serial share, for the
     * multi-threaded mode of most workers (ob_bench_split_mode). */
    const ob_bench_spread none = {NAN, NAN, NAN};
    s->frame_cpu_speedup_10k_8views = s->serial_fraction_10k_8views = none;
    for (uint32_t m = 0; e8 && m < e8->mode_count; m++) {
        const ob_bench_result *r = &e8->results[m];
        if (!r->split) continue;
        s->frame_cpu_speedup_10k_8views = r->frame_cpu_speedup;
        s->serial_fraction_10k_8views = r->serial_fraction;
        s->frame_cpu_mode = r->mode.name;
    }
    double serial = s->serial_fraction_10k_8views.median;
    s->amdahl_speedup_16_cores = 1.0 / (serial + (1.0 - serial) / 16.0);
    double object_views = e8 ? (double)e8->objects * e8->views : NAN;
    s->prerender_ns_per_object_view =
        e8 ? spread_scaled(e8->results[0].pre_render_round_ms, 1e6 / object_views) : none;
    s->gpu_ms_10k_8views = e8 ? e8->results[0].gpu_ms : NAN;
    s->gpu_ms_10k_8views_per_draw = rep->per_draw_10k_8views.mode_count
                                        ? rep->per_draw_10k_8views.results[0].gpu_ms : NAN;
    s->gpu_time_instanced_vs_per_draw_10k_8views =
        s->gpu_ms_10k_8views / s->gpu_ms_10k_8views_per_draw;
    double draws8 = e8 && e8->results[0].draws ? (double)e8->results[0].draws : NAN;
    s->vertices_per_draw_10k_8views = e8 ? e8->results[0].vertices / draws8 : NAN;
    s->lod_share_10k_8views = e8 ? e8->results[0].lod_items / draws8 : NAN;
    const ob_bench_sweep_entry *e50 = find_entry(rep, 1, 50000);
    s->update_ns_per_object =
        e50 ? spread_scaled(e50->results[0].update_round_ms, 1e6 / e50->objects) : none;
    const ob_bench_result *a8 = auto_result(e8);
    s->auto_vs_best_10k_8views = a8 ? a8->vs_best_fixed_record : (ob_bench_spread){NAN, NAN, NAN};
    s->auto_vs_round_min_10k_8views = a8 ? a8->vs_round_min_record.median : NAN;
    for (uint32_t m = 0; m < rep->scene200.mode_count; m++)
        s->hash_mismatches += rep->scene200.results[m].hash_mismatches;
    s->engine_vs_raw_per_object = rep->engine_vs_raw;
    s->engine_vs_raw_instanced_per_object = rep->engine_vs_raw_instanced;
    s->commands_per_object_raw_instanced = rep->raw_instanced.commands_per_object;
    s->raw_gpu_instanced_vs_per_draw = rep->raw_gpu_instanced_vs_per_draw;
    /* Per visible object is per draw in ST: the old name keeps its meaning. */
    s->engine_vs_raw_per_draw = rep->engine_vs_raw.median;
    const ob_bench_result *r200 = rep->scene200.results;
    s->auto_vs_best_200 = rep->scene200.mode_count == 3 ? r200[2].vs_best_fixed_record
                                                        : (ob_bench_spread){NAN, NAN, NAN};
    s->auto_vs_round_min_200 = rep->scene200.mode_count == 3 ? r200[2].vs_round_min_record.median : NAN;
    s->auto_vs_best_200_frame = rep->scene200.mode_count == 3
                                    ? r200[2].frame_ms / fmin(r200[0].frame_ms, r200[1].frame_ms)
                                    : NAN;
    /* Different scenes cannot share a round, so this one is a ratio of
     * medians: it reads how the per-object cost grows with the scene
     * (caches, culling, sorting), not a speedup. */
    s->per_object_growth_50k_vs_1k = st_ns_per_draw(find_entry(rep, 1, 50000)) /
                                     st_ns_per_draw(find_entry(rep, 1, 1000));
    const ob_bench_sweep_entry *raw = find_entry(rep, rep->raw_views, rep->raw_objects);
    s->commands_per_object_engine = raw ? raw->results[0].commands_per_object : NAN;
    s->host_allocs_per_object_engine = raw ? raw->results[0].cmd_host_allocs_per_object : NAN;
    s->commands_per_object_raw = rep->raw.commands_per_object;
    s->host_allocs_per_object_raw = rep->raw.host_allocs_per_object;
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        const ob_bench_quality_row *q = &rep->quality[i];
        if (q->kind != OB_BENCH_QUALITY_THREADING) continue;
        s->threading_max_abs_diff = OB_MAX(s->threading_max_abs_diff, q->max_abs_diff);
        s->hash_mismatches += q->hash_mismatches;
    }
    s->threading_identical = s->threading_max_abs_diff == 0 && s->hash_mismatches == 0;
}

/* The progress bar through a stability run: labelled per case, a tick after. */
static void stability_progress(void *user, const char *label, bool done)
{
    ob_bench_progress *prog = user;
    if (done) ob_bench_progress_tick(prog);
    else ob_bench_progress_label(prog, "stability: %s", label);
}

/* The 1-minute load average: other work on the machine skews every time. */
static double load_average(void)
{
    double load = NAN;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &load) != 1) load = NAN;
        fclose(f);
    }
    return load;
}

/* Every standard effect compiles, on a throwaway stack: without them the
 * frames draw nothing and every figure would be noise. The measured stacks
 * are made afterwards, as before. */
static ob_result check_effects(bench_options *o, uint32_t pool)
{
    /* In ob_std_effect's order (materials/ob_material.h). */
    static const char *const names[] = {"lit", "depth", "paraboloid", "unlit", "overlay",
                                        "fullscreen", "particles-sim", "particles-draw"};
    _Static_assert(OB_ARRAY_COUNT(names) == OB_STD_EFFECT_COUNT, "one name per standard effect");
    ob_demo_options dopt = demo_options(o, pool, 64, 64, 0);
    ob_demo d;
    ob_result r = ob_demo_init(&d, &dopt);
    o->cpu_device = r == OB_OK && ob_device_is_cpu(ob_renderer_device(d.world.r));
    /* A shader that cannot be read fails the material library's creation
     * (the log names the file); the hint says where shaders are looked for. */
    if (r != OB_OK)
        fprintf(stderr, "obelisk-bench: cannot set up the renderer: %s (%s)%s\n", ob_result_name(r),
                ob_result_text(r), r == OB_ERR_IO ? "; nothing measured. Are the shaders where the library "
                "looks ($OB_SHADER_DIR, else share/obelisk/shaders beside the library)?" : "");
    for (uint32_t k = 0; r == OB_OK && k < OB_STD_EFFECT_COUNT; k++) {
        if (ob_material_library_effect(d.world.lib, (ob_std_effect)k, 0, &r)) continue;
        fprintf(stderr, "obelisk-bench: the standard effect '%s' does not compile: %s (%s); "
                        "nothing measured. Are the shaders where the library looks "
                        "($OB_SHADER_DIR, else share/obelisk/shaders beside the library)?\n",
                names[k], ob_result_name(r), ob_result_text(r));
    }
    ob_demo_shutdown(&d);
    return r;
}

static int run(bench_options *o)
{
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    ob_bench_report rep = {.quick = o->quick, .gpu_timing = o->gpu_timing,
                           .seed = o->seed, .cores = ncpu > 0 ? (uint32_t)ncpu : 1,
                           .warmup = o->warmup, .rounds = o->rounds, .passes = o->passes,
                           .settle = o->settle, .flight = o->flight,
                           .view_width = o->view_width, .view_height = o->view_height,
                           .lod = !o->no_lod, .instancing = !o->no_instancing,
                           .image_width = o->image_width, .image_height = o->image_height,
                           .image_frames = o->quick ? 3 : 4};
    rep.pool_workers = pool_size(o, rep.cores);
    if (check_effects(o, rep.pool_workers) != OB_OK) return 6;
    /* Unknown until the raw configuration has run (it may not be in the lists). */
    rep.engine_vs_raw = rep.raw_gpu_instanced_vs_per_draw = (ob_bench_spread){NAN, NAN, NAN};
    rep.raw_gpu_ms = rep.raw_gpu_instanced_ms = NAN;
    rep.raw = (ob_bench_raw_result){.record_ms = NAN, .ns_per_draw = NAN,
                                    .commands_per_object = NAN, .host_allocs_per_object = NAN};
    rep.engine_ns_per_draw = NAN;
    rep.big_draws = BIG_FRAME_DRAWS;
    frame_counts big = counts_for(o, 1000, 1000000);
    rep.big_warmup = big.warmup;
    rep.big_rounds = big.rounds;
    rep.big_passes = big.passes;
    rep.big_settle = big.settle;
    rep.big_flight = big.flight;
    uint64_t t0 = ob_time_ns();
    rep.load_start = load_average();
    rep.core_ns_start = ob_bench_core_to_core_ns();
    static const uint32_t env_full[] = {64, 128, 256, 512}, shadow_full[] = {256, 512, 1024, 2048};
    static const uint32_t env_quick[] = {128, 512}, shadow_quick[] = {512, 2048};
    ob_bench_quality_desc qd = {
        .base = demo_options(o, rep.pool_workers, o->image_width, o->image_height, 200),
        .pool_workers = rep.pool_workers, .image_frames = rep.image_frames,
        .rounds = o->quick ? 2 : 3, .flight = o->flight,
        .env_sizes = o->quick ? env_quick : env_full, .env_count = o->quick ? 2 : 4,
        .shadow_sizes = o->quick ? shadow_quick : shadow_full, .shadow_count = o->quick ? 2 : 4,
        .modes = o->modes, .mode_count = o->mode_count, .msaa = true, .env_cube = true,
    };
    /* The MSAA series adds up to three sample counts (2x, 4x, 8x: what the
     * device offers; 1x is the reference's image) and its own reference,
     * which draws its image frames only. */
    uint64_t quality_configs = qd.env_count + qd.shadow_count - 1 + o->mode_count - 1 + 3 +
                               (qd.env_cube ? qd.env_count : 0);
    uint64_t total = 0;
    bool rest = o->perf && !o->sweep_only;
    if (o->perf) {
        /* scene200: three modes. */
        if (rest)
            total += 3 * ((o->warmup + o->rounds) * o->passes * (o->settle + 1) + 2 * o->flight + 1) +
                     quality_configs * (qd.image_frames + qd.rounds + qd.flight + 1) +
                     qd.image_frames;
        for (uint32_t n = 0; n < o->object_count; n++) {
            for (uint32_t v = 0; v < o->view_count; v++) {
                if (!config_runs(o, o->views[v], o->objects[n])) continue;
                frame_counts fc = counts_for(o, o->views[v], o->objects[n]);
                /* Per mode its frames. */
                uint64_t rounds = fc.warmup + fc.rounds;
                uint64_t frames = (uint64_t)o->mode_count *
                                  (rounds * fc.passes * (fc.settle + 1) + fc.flight + 1);
                total += frames * frame_weight(o->views[v], o->objects[n]);
                /* The per-draw rerun of 10k x 8 views: ST only. */
                if (o->views[v] == 8 && o->objects[n] == 10000 && !o->no_instancing && rest)
                    total += frames / o->mode_count * frame_weight(8, 10000);
            }
        }
    }
    /* A stability case takes about as long as a dozen mirror-scene frames. */
    const uint64_t stability_unit = 12;
    if (o->stability) total += ob_stability_case_count() * stability_unit;
    ob_bench_lights_desc ld = {.width = o->quick ? 320 : 640, .height = o->quick ? 240 : 480,
                               .frames = o->quick ? 4 : 8, .rounds = 3,
                               .tick = ob_bench_progress_tick};
    rep.lights_width = ld.width;
    rep.lights_height = ld.height;
    rep.lights_frames = ld.frames;
    rep.lights_rounds = ld.rounds;
    if (rest) total += ob_bench_lights_frames(&ld);
    ob_bench_progress prog;
    ob_bench_progress_init(&prog, total, o->progress);
    qd.tick = ob_bench_progress_tick;
    qd.tick_user = &prog;

    int code = 0;
    ob_result r = OB_OK;
    rep.perf = o->perf;
    if (o->perf) {
        rep.sweep = ob_calloc(o->view_count * o->object_count, sizeof *rep.sweep);
        if (!rep.sweep) r = OB_ERR_OUT_OF_HOST_MEMORY;
    }
    for (uint32_t n = 0; n < o->object_count && r == OB_OK && o->perf; n++) {
        for (uint32_t v = 0; v < o->view_count && r == OB_OK; v++) {
            if (!config_runs(o, o->views[v], o->objects[n])) continue;
            ob_bench_progress_label(&prog, "sweep: %u views, %u objects", o->views[v], o->objects[n]);
            prog.unit = frame_weight(o->views[v], o->objects[n]);
            r = sweep_config(o, &rep, o->views[v], o->objects[n], &prog, &rep.sweep[rep.sweep_count]);
            if (r == OB_OK) rep.sweep_count++;
        }
    }
    /* The GPU time one draw per entity costs, next to instancing's: the
     * 10k x 8 views frame again, ST only, per-draw. */
    if (r == OB_OK && rest && !o->no_instancing && find_entry(&rep, 8, 10000)) {
        bench_options po = *o;
        po.no_instancing = true;
        po.mode_count = 1;
        po.modes[0] = (ob_bench_mode){"ST", OB_THREADING_SINGLE, 0};
        ob_bench_progress_label(&prog, "sweep: 8 views, 10000 objects, one draw per entity");
        prog.unit = frame_weight(8, 10000);
        r = sweep_config(&po, &rep, 8, 10000, &prog, &rep.per_draw_10k_8views);
    }
    prog.unit = 1;
    if (r == OB_OK && rest) {
        ob_bench_progress_label(&prog, "mirror scene, 200 objects: ST / MT / auto");
        r = scene200(o, &rep, &prog);
    }
    if (r == OB_OK && rest) {
        ob_bench_progress_label(&prog, "quality and threading check (mirror scene)");
        r = ob_bench_quality_run(&qd, &rep.quality, &rep.quality_count);
    }
    if (r == OB_OK && rest) {
        ob_bench_progress_label(&prog, "lights: 0 to 256 point lights, grid and every light");
        ld.tick_user = &prog;
        r = ob_bench_lights_run(&ld, &rep.lights, &rep.lights_count);
    }
    ob_stability stab = {0};
    if (r == OB_OK && o->stability) {
        prog.unit = stability_unit;
        ob_stability_desc sd = {.quick = o->quick, .on_case = stability_progress,
                                .on_case_user = &prog};
        r = ob_stability_run(&sd, &stab);
        rep.stability = &stab;
        if (!rep.device_name[0]) {
            snprintf(rep.device_name, sizeof rep.device_name, "%s", stab.device_name);
            snprintf(rep.driver_info, sizeof rep.driver_info, "%s", stab.driver_info);
        }
        rep.validation |= stab.validation;
        if (!o->perf) rep.pool_workers = stab.workers;
    }
    ob_bench_progress_finish(&prog);
    rep.seconds = (double)(ob_time_ns() - t0) * 1e-9;
    rep.load_end = load_average();
    rep.core_ns_end = ob_bench_core_to_core_ns();

    if (r != OB_OK) {
        fprintf(stderr, "obelisk-bench: failed: %s (%s)\n", ob_result_name(r), ob_result_text(r));
        code = 1;
    } else {
        if (o->perf) {
            summarize(&rep);
            rep.summary.lights_cost_exponent_4_to_256 =
                ob_bench_lights_exponent(rep.lights, rep.lights_count, true);
            rep.summary.lights_cost_exponent_4_to_256_all =
                ob_bench_lights_exponent(rep.lights, rep.lights_count, false);
            rep.summary.teardown_ns_per_entity_batch = teardown_ns(true);
            rep.summary.teardown_ns_per_entity_single = teardown_ns(false);
        }
        ob_bench_report_print(&rep, stdout);
        if (o->json && ob_bench_report_json(&rep, o->json) != OB_OK) code = 1;
        if (o->csv && o->perf && ob_bench_report_csv(&rep, o->csv) != OB_OK) code = 1;
        if (o->csv && rep.stability) {
            char path[1024];
            ob_bench_report_stability_csv_path(o->csv, path, sizeof path);
            if (ob_bench_report_stability_csv(rep.stability, path) != OB_OK) code = 1;
        }
        if (o->charts && ob_bench_report_charts(&rep, o->charts) != OB_OK) code = 1;
        if (o->perf && !rep.summary.threading_identical) {
            fprintf(stderr, "obelisk-bench: threading modes differ from single-threaded "
                            "(max abs diff %u, %u hash mismatches)\n",
                    rep.summary.threading_max_abs_diff, rep.summary.hash_mismatches);
            code = 4;
        }
        for (uint32_t i = 0; rep.stability && i < stab.count; i++) {
            const ob_stability_row *row = &stab.rows[i];
            if (row->verdict != OB_STABILITY_FAIL) continue;
            fprintf(stderr, "obelisk-bench: stability case '%s' failed: error %.6g %s, bound %.6g "
                            "(%s)\n", row->name, row->error, row->unit, row->bound, row->detail);
            if (!code) code = 5;
        }
        /* The stability cases log refused NaNs and the like on purpose. */
        uint64_t errors = ob_log_count(OB_LOG_ERROR) - stab.expected_errors;
        if (errors > 0) {
            fprintf(stderr, "obelisk-bench: %llu errors were logged\n", (unsigned long long)errors);
            if (!code) code = 3;
        }
    }
    ob_stability_release(&stab);
    ob_free(rep.sweep);
    ob_free(rep.quality);
    ob_free(rep.lights);
    return code;
}

int main(int argc, char **argv)
{
    bench_options o;
    int code;
    if (!parse_options(argc, argv, &o, &code)) return code;
    return run(&o);
}
