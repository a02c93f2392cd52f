#define _POSIX_C_SOURCE 200809L
#include "ob_bench_report.h"

#include <errno.h>
#include <math.h>
#include <spawn.h>
#include <string.h>
#include <sys/wait.h>

extern char **environ;

/* ------------------------------------------------------------ helpers */

/* A finite number as the files carry it: whole numbers (pixel sums, counts)
 * exactly, others to 9 significant digits (%.6g wrote 4100181 as 4.10018e+06). */
static void num_text(double v, char buf[40])
{
    if (v == floor(v) && fabs(v) < 1e15) snprintf(buf, 40, "%.0f", v);
    else snprintf(buf, 40, "%.9g", v);
}

/* JSON has no NaN or infinity: those become null. */
static void json_num(FILE *f, double v)
{
    if (!isfinite(v)) {
        fputs("null", f);
        return;
    }
    char buf[40];
    num_text(v, buf);
    fputs(buf, f);
}

static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

static void csv_num(FILE *f, double v)
{
    if (isnan(v)) fputs(",", f);
    else if (isinf(v)) fputs(",inf", f);
    else {
        char buf[40];
        num_text(v, buf);
        fprintf(f, ",%s", buf);
    }
}

static FILE *open_out(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) OB_LOG_E("bench", "cannot write '%s': %s", path, strerror(errno));
    return f;
}

static ob_result close_out(FILE *f, const char *path)
{
    bool bad = ferror(f) != 0;
    if (fclose(f) != 0) bad = true;
    if (bad) {
        OB_LOG_E("bench", "writing '%s' failed: %s", path, strerror(errno));
        return OB_ERR_IO;
    }
    return OB_OK;
}

/* ------------------------------------------------------------ text */

static void print_entry(FILE *f, const ob_bench_sweep_entry *e)
{
    for (uint32_t m = 0; m < e->mode_count; m++) {
        const ob_bench_result *r = &e->results[m];
        char spread[32];
        snprintf(spread, sizeof spread, "%.2f [%.2f,%.2f]", r->speedup_record,
                 r->speedup_record_p25, r->speedup_record_p75);
        fprintf(f,
                "  %5u %6u %-5s %4.1f %7u %8.2f %8.2f %8.2f %8.2f %7.2f %8.2f %7.2f %7.2f %7.2f "
                "%8.2f %8.2f %-18s %9.0f %6u/%-6u %s\n",
                e->views, e->objects, r->mode.name, r->workers_used, r->draws, r->update_ms,
                r->pre_render_ms, r->record_ms, r->assemble_ms, r->submit_ms, r->record_total_ms,
                r->record_cpu_render_ms, r->record_cpu_workers_ms, r->record_cpu_max_worker_ms,
                r->gpu_ms, r->frame_ms, spread, r->draws_per_s,
                r->pm.descriptor_binds_issued, r->pm.descriptor_binds_requested,
                r->hash_mismatches ? "HASH MISMATCH" : "");
        /* Frames that stamped every view (all of them with --gpu-timing
         * views): their views' time and the rest, the staged ring's copy and
         * the barriers, each frame's own difference (a difference of two
         * medians over different frames came out negative). */
        if (!isnan(r->gpu_views_ms))
            fprintf(f, "  %5s %6s %-5s gpu %.2f ms: views %.2f, the rest %.2f (upload %.1f MiB)\n", "", "",
                    r->mode.name, r->gpu_ms, r->gpu_views_ms, r->gpu_rest_ms, r->upload_mb);
    }
}

static void print_header(FILE *f)
{
    fprintf(f, "  %5s %6s %-5s %4s %7s %8s %8s %8s %8s %7s %8s %7s %7s %7s %8s %8s %-18s %9s %13s\n",
            "views", "objs", "mode", "wrk", "draws", "update", "pre-rend", "record", "assemble",
            "submit", "rec+asm", "cpu-rt", "cpu-wk", "cpu-wmx", "gpu", "frame", "spdup [p25,p75]",
            "draws/s", "desc binds");
}

static void print_spread(FILE *f, const char *name, ob_bench_spread v)
{
    fprintf(f, "  %-30s %.3f [%.3f, %.3f]", name, v.median, v.p25, v.p75);
}

/* The MSAA rows: error against the supersampled reference next to frame time. */
static void print_msaa(FILE *f, const ob_bench_report *rep)
{
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        const ob_bench_quality_row *q = &rep->quality[i];
        if (q->kind == OB_BENCH_QUALITY_MSAA_REFERENCE)
            fprintf(f, "\nMSAA: image error against the antialiasing reference (%ux the size per "
                       "axis, %ux MSAA, box-downsampled in linear light; env %u, shadow %u, %s):\n"
                       "  %7s %8s %9s %9s %9s %9s\n",
                    q->supersample, q->msaa_samples, q->env_size, q->shadow_size, q->mode.name,
                    "samples", "max_abs", "psnr_dB", "frame_ms", "gpu_ms", "rec+asm");
        else if (q->kind == OB_BENCH_QUALITY_MSAA)
            fprintf(f, "  %6ux %8u %9.2f %9.2f %9.2f %9.2f\n", q->msaa_samples, q->max_abs_diff,
                    q->psnr_db, q->frame_ms, q->gpu_ms, q->record_total_ms);
    }
}

static void print_lights(FILE *f, const ob_bench_report *rep)
{
    if (!rep->lights_count) return;
    fprintf(f, "\nlights at fixed coverage (a wall and 120 boxes, %ux%u, ST; each light's range "
               "1.25 grid spacings), %s per frame over %u rounds of %u frames:\n"
               "  %6s %7s %-6s %9s %9s %9s\n",
            rep->lights_width, rep->lights_height,
            rep->lights[0].cpu_measure ? "process CPU ms (CPU device)" : "GPU ms", rep->lights_rounds,
            rep->lights_frames, "lights", "range", "tiles", "median", "p25", "p75");
    for (uint32_t i = 0; i < rep->lights_count; i++) {
        const ob_bench_lights_row *l = &rep->lights[i];
        fprintf(f, "  %6u %7.3f %-6s %9.2f %9.2f %9.2f\n", l->lights, l->range,
                l->tiles ? "grid" : "all", l->cost_ms.median, l->cost_ms.p25, l->cost_ms.p75);
    }
}

/* How the renderer drew instance runs. */
static const char *runs_name(ob_instance_runs runs)
{
    switch (runs) {
    case OB_INSTANCE_RUNS_MULTI_DRAW: return "multi-draw indirect";
    case OB_INSTANCE_RUNS_DIRECT: return "a direct draw per instance";
    default: return "instanced draws";
    }
}

static void print_perf(const ob_bench_report *rep, FILE *f)
{
    char runs[64] = "";
    if (rep->instancing) snprintf(runs, sizeof runs, " (runs as %s)", runs_name(rep->instance_runs));
    fprintf(f, "sweep: medians (ms) over %u idle rounds of each mode's fastest of %u frames, "
               "each after %u unmeasured frame(s) of its mode (%u warm-up rounds first); "
               "frame = in-flight period over %u frames; frames over ~%u draws: %u rounds of %u "
               "frame(s), %u warm-up, %u in flight; spdup = median over rounds of ST rec+asm / this, "
               "[p25,p75]; cpu-rt, cpu-wk, cpu-wmx = recording CPU time of the render thread, "
               "all workers, busiest worker (nan: not reported by the engine); levels of detail "
               "%s, instancing %s%s\n",
            rep->rounds, rep->passes, rep->settle, rep->warmup, rep->flight, rep->big_draws,
            rep->big_rounds, rep->big_passes, rep->big_warmup, rep->big_flight,
            rep->lod ? "on" : "off", rep->instancing ? "on" : "off", runs);
    print_header(f);
    for (uint32_t i = 0; i < rep->sweep_count; i++) print_entry(f, &rep->sweep[i]);
    fprintf(f, "\nmirror scene, 200 objects (auto vs best):\n");
    print_header(f);
    print_entry(f, &rep->scene200);
    fprintf(f, "\nraw Vulkan baseline (%u views, %u objects), one recording after each pass of "
               "%u idle rounds, the fastest of a round kept: %u draws, raw %.1f ns/draw, engine "
               "(ST) %.1f ns/draw, ratio %.2f (median of per-round ratios); vkCmd calls/object "
               "raw %.2f, engine ~%.2f; host allocations/object raw %.2f, engine %.2f\n",
            rep->raw_views, rep->raw_objects, rep->raw.reps, rep->raw.draws, rep->raw.ns_per_draw,
            rep->engine_ns_per_draw, rep->summary.engine_vs_raw_per_draw,
            rep->summary.commands_per_object_raw, rep->summary.commands_per_object_engine,
            rep->summary.host_allocs_per_object_raw, rep->summary.host_allocs_per_object_engine);
    fprintf(f, "raw instanced (a run of one mesh one draw): %.1f ns/draw, engine/raw instanced "
               "%.2f; vkCmd calls/object %.3f\n",
            rep->raw_instanced.ns_per_draw, rep->summary.engine_vs_raw_instanced_per_object.median,
            rep->summary.commands_per_object_raw_instanced);
    fprintf(f, "raw loops executed (same view, draws and triangles): GPU %.2f ms per draw, "
               "%.2f ms instanced\n", rep->raw_gpu_ms, rep->raw_gpu_instanced_ms);
    fprintf(f, "\nimage error against the reference (ST, highest quality), mirror scene %ux%u, "
               "frame %u:\n  %-18s %5s %6s %-5s %8s %9s %9s %9s %9s %s\n",
            rep->image_width, rep->image_height, rep->image_frames, "kind", "env", "shadow",
            "mode", "max_abs", "psnr_dB", "frame_ms", "gpu_ms", "rec+asm", "hashes");
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        const ob_bench_quality_row *q = &rep->quality[i];
        if (q->kind == OB_BENCH_QUALITY_MSAA_REFERENCE || q->kind == OB_BENCH_QUALITY_MSAA) continue;
        fprintf(f, "  %-18s %5u %6u %-5s %8u %9.2f %9.2f %9.2f %9.2f %s\n",
                ob_bench_quality_kind_name(q->kind), q->env_size, q->shadow_size, q->mode.name,
                q->max_abs_diff, q->psnr_db, q->frame_ms, q->gpu_ms, q->record_total_ms,
                q->kind != OB_BENCH_QUALITY_THREADING ? "-"
                : q->hash_mismatches                  ? "MISMATCH"
                                                      : "equal");
    }
    print_msaa(f, rep);
    print_lights(f, rep);
    const ob_bench_summary *s = &rep->summary;
    fprintf(f, "\nsummary (ratios: median of per-round ratios [p25, p75]):\n");
    print_spread(f, "mt_speedup_record_10k_8views", s->mt_speedup_record_10k_8views);
    fprintf(f, " (best MT mode %s)\n", s->mt_speedup_best_mode ? s->mt_speedup_best_mode : "-");
    print_spread(f, "engine_vs_raw_per_object", s->engine_vs_raw_per_object);
    fputs(" (= engine_vs_raw_per_draw)\n", f);
    print_spread(f, "engine_vs_raw_instanced", s->engine_vs_raw_instanced_per_object);
    fputs(" (against the raw loop instanced)\n", f);
    print_spread(f, "auto_vs_best_200", s->auto_vs_best_200);
    fprintf(f, " (recording; in-flight frames %.3f)\n", s->auto_vs_best_200_frame);
    print_spread(f, "auto_vs_best_10k_8views", s->auto_vs_best_10k_8views);
    fprintf(f, "\n  %-30s %.3f (200), %.3f (10k x 8): against each round's lower of ST and MT\n",
            "auto_vs_round_min", s->auto_vs_round_min_200, s->auto_vs_round_min_10k_8views);
    const char *split = s->frame_cpu_mode ? s->frame_cpu_mode : "-";
    print_spread(f, "frame_cpu_speedup_10k_8views", s->frame_cpu_speedup_10k_8views);
    fprintf(f, " (ST / %s: update + pre-render + record + assemble + submit)\n", split);
    print_spread(f, "serial_fraction_10k_8views", s->serial_fraction_10k_8views);
    fprintf(f, " (%s: serial / total CPU of a frame with its update; Amdahl on 16 cores %.2fx)\n",
            split, s->amdahl_speedup_16_cores);
    print_spread(f, "prerender_ns_per_object_view", s->prerender_ns_per_object_view);
    fputs(" (ST, 10k x 8)\n", f);
    print_spread(f, "update_ns_per_object", s->update_ns_per_object);
    fputs(" (ST, 50k objects, 1 view)", f);
    fprintf(f, "\n  %-30s %.0f (ob_nodes_destroy of all), %.0f (one at a time, newest first); "
               "100k entities", "teardown_ns_per_entity", s->teardown_ns_per_entity_batch,
            s->teardown_ns_per_entity_single);
    fprintf(f, "\n  %-30s %.3f (GPU ms, ST, 10k x 8 views: instanced %.1f, one draw per entity "
               "%.1f)", "gpu_time_instanced_vs_per_draw", s->gpu_time_instanced_vs_per_draw_10k_8views,
            s->gpu_ms_10k_8views, s->gpu_ms_10k_8views_per_draw);
    fputc('\n', f);
    print_spread(f, "raw_gpu_instanced_vs_per_draw", s->raw_gpu_instanced_vs_per_draw);
    fprintf(f, " (the raw loops' GPU time, %u views x %u objects: bare Vulkan's on this device)",
            rep->raw_views, rep->raw_objects);
    fprintf(f, "\n  %-30s %.1f (ST, 10k x 8: vertices submitted per entity drawn; %.1f%% of "
               "them at a coarser level of detail)", "vertices_per_draw",
            s->vertices_per_draw_10k_8views, 100.0 * s->lod_share_10k_8views);
    fprintf(f, "\n  %-30s %.3f with the tile grid, %.3f with every light everywhere "
               "(frame cost from 4 to 256 lights at fixed coverage; below 1: sub-linear)",
            "lights_cost_exponent_4_to_256", s->lights_cost_exponent_4_to_256,
            s->lights_cost_exponent_4_to_256_all);
    fprintf(f, "\n  %-30s %.3f (ST record per draw, 1 view; ratio of medians)\n"
               "  %-30s %.2f engine (estimate), %.2f raw\n  %-30s %.2f engine, %.2f raw\n",
            "per_object_growth_50k_vs_1k", s->per_object_growth_50k_vs_1k, "commands_per_object",
            s->commands_per_object_engine, s->commands_per_object_raw, "host_allocs_per_object",
            s->host_allocs_per_object_engine, s->host_allocs_per_object_raw);
    fprintf(f, "  %-30s %s (max abs diff %u, hash mismatches %u)\n"
               "  %-30s %.0f s (load average %.1f at start, %.1f at end)\n"
               "  %-30s %.0f ns at start, %.0f ns at end (a cache line between two CPUs "
               "and back: every MT figure follows it)\n",
            "threading modes identical", s->threading_identical ? "yes" : "NO",
            s->threading_max_abs_diff, s->hash_mismatches, "run time", rep->seconds,
            rep->load_start, rep->load_end, "core_to_core_round_trip", rep->core_ns_start,
            rep->core_ns_end);
}

/* Pixel counts and levels as integers, small errors in %g. */
static void format_value(double v, char *buf, size_t n)
{
    if (isnan(v)) snprintf(buf, n, "-");
    else if (v == floor(v) && fabs(v) < 1e9) snprintf(buf, n, "%.0f", v);
    else snprintf(buf, n, "%.3g", v);
}

static const char *row_verdict(const ob_stability_row *row)
{
    switch (row->verdict) {
    case OB_STABILITY_PASS: return "ok";
    case OB_STABILITY_MEASURED: return "-";
    case OB_STABILITY_FAIL: break;
    }
    return "FAIL";
}

static void print_stability(const ob_stability *s, FILE *f)
{
    fprintf(f, "\nnumerical stability and extreme cases%s: %u rows from %u cases, %u failed (over "
               "the bound the test asserts, or a check of the case), %u measured only (bound "
               "'-', pass '-': neither passed nor failed); ms = median frame (after a renderer's "
               "first) or update time; renderers with %u workers\n",
            s->quick ? " (--quick: two cases shrunk, see their rows)" : "", s->count, s->cases,
            s->failed, s->measured, s->workers);
    fprintf(f, "  %-38s %10s %-11s %8s %-4s %9s  %s\n", "case", "error", "unit", "bound", "pass",
            "ms", "measure / detail");
    for (uint32_t i = 0; i < s->count; i++) {
        const ob_stability_row *row = &s->rows[i];
        char err[32], bound[32], ms[32];
        format_value(row->error, err, sizeof err);
        format_value(row->bound, bound, sizeof bound);
        if (isnan(row->ms)) snprintf(ms, sizeof ms, "-");
        else snprintf(ms, sizeof ms, "%.1f", row->ms);
        fprintf(f, "  %-38s %10s %-11s %8s %-4s %9s  %s\n", row->name, err, row->unit, bound,
                row_verdict(row), ms, row->measure);
        if (row->detail[0]) fprintf(f, "  %-38s %48s%s\n", "", "", row->detail);
    }
    fprintf(f, "  section: %.1f s; log lines the cases provoked (caught and checked, not printed): "
               "%llu error(s), %llu warning(s); validation layer %s (%u messages)\n",
            s->seconds, (unsigned long long)s->expected_errors,
            (unsigned long long)s->expected_warnings, s->validation ? "on" : "off",
            s->validation_messages);
}

void ob_bench_report_print(const ob_bench_report *rep, FILE *f)
{
    fprintf(f, "\nobelisk-bench%s on %s (%s), %u cores, worker pool %u%s%s%s\n",
            rep->quick ? " --quick" : "", rep->device_name, rep->driver_info, rep->cores,
            rep->pool_workers, rep->driver_heap_kept ? ", driver heap kept" : "",
            rep->validation ? ", VALIDATION ON (times not meaningful)" : "",
            rep->gpu_timing == OB_GPU_TIMING_SAMPLED ? ""
            : rep->gpu_timing == OB_GPU_TIMING_OFF ? ", no GPU timestamps"
                                                   : ", GPU timestamps on every view");
    if (rep->perf) print_perf(rep, f);
    if (rep->stability) print_stability(rep->stability, f);
}

/* ------------------------------------------------------------ JSON */

static void json_pair(FILE *f, const char *name, uint32_t req, uint32_t iss, bool last)
{
    fprintf(f, "\"%s\":[%u,%u]%s", name, req, iss, last ? "" : ",");
}

static void json_result(FILE *f, const ob_bench_result *r)
{
    fputs("{\"mode\":", f);
    json_str(f, r->mode.name);
    fprintf(f, ",\"threading\":\"%s\",\"workers\":%u,\"workers_used\":",
            ob_threading_name(r->mode.threading), r->mode.workers);
    json_num(f, r->workers_used);
    fprintf(f, ",\"frames\":%u,\"views\":%u,\"draws\":%u,\"vertices\":%.0f,\"lod_items\":%u",
            r->frames, r->views, r->draws, r->vertices, r->lod_items);
    static const char *const names[] = {"update_ms", "pre_render_ms", "record_ms", "assemble_ms",
                                        "submit_ms", "record_total_ms", "cpu_frame_ms", "gpu_ms",
                                        "frame_ms", "draws_per_s", "speedup_record",
                                        "speedup_frame", "speedup_record_p25",
                                        "speedup_record_p75", "vs_best_fixed_record",
                                        "vs_best_fixed_record_p25", "vs_best_fixed_record_p75",
                                        "record_cpu_render_ms", "record_cpu_workers_ms",
                                        "record_cpu_max_worker_ms", "cmd_host_allocs_per_object",
                                        "commands_per_object", "vs_round_min_record",
                                        "update_cpu_ms", "frame_cpu_speedup",
                                        "frame_cpu_speedup_p25", "frame_cpu_speedup_p75",
                                        "serial_fraction", "serial_fraction_p25",
                                        "serial_fraction_p75", "gpu_views_ms", "upload_mb",
                                        "gpu_flight_ms", "gpu_rest_ms"};
    const double values[] = {r->update_ms, r->pre_render_ms, r->record_ms, r->assemble_ms,
                             r->submit_ms, r->record_total_ms, r->cpu_frame_ms, r->gpu_ms,
                             r->frame_ms, r->draws_per_s, r->speedup_record, r->speedup_frame,
                             r->speedup_record_p25, r->speedup_record_p75,
                             r->vs_best_fixed_record.median, r->vs_best_fixed_record.p25,
                             r->vs_best_fixed_record.p75, r->record_cpu_render_ms,
                             r->record_cpu_workers_ms, r->record_cpu_max_worker_ms,
                             r->cmd_host_allocs_per_object, r->commands_per_object,
                             r->vs_round_min_record.median, r->update_cpu_ms,
                             r->frame_cpu_speedup.median, r->frame_cpu_speedup.p25,
                             r->frame_cpu_speedup.p75, r->serial_fraction.median,
                             r->serial_fraction.p25, r->serial_fraction.p75, r->gpu_views_ms,
                             r->upload_mb, r->gpu_flight_ms, r->gpu_rest_ms};
    _Static_assert(OB_ARRAY_COUNT(names) == OB_ARRAY_COUNT(values), "a name per value");
    for (size_t i = 0; i < OB_ARRAY_COUNT(names); i++) {
        fprintf(f, ",\"%s\":", names[i]);
        json_num(f, values[i]);
    }
    const ob_pipeline_manager_stats *p = &r->pm;
    fputs(",\"binds\":{", f);
    json_pair(f, "pipeline", p->pipeline_binds_requested, p->pipeline_binds_issued, false);
    json_pair(f, "descriptor", p->descriptor_binds_requested, p->descriptor_binds_issued, false);
    json_pair(f, "push_descriptor", p->push_descriptor_requested, p->push_descriptor_issued, false);
    json_pair(f, "push_constant", p->push_constant_requested, p->push_constant_issued, false);
    json_pair(f, "vertex", p->vertex_binds_requested, p->vertex_binds_issued, false);
    json_pair(f, "index", p->index_binds_requested, p->index_binds_issued, true);
    fprintf(f, "},\"uniform_bytes\":%llu,\"frame_hash\":\"%016llx\",\"hash_mismatches\":%u}",
            (unsigned long long)p->uniform_bytes, (unsigned long long)r->frame_hash,
            r->hash_mismatches);
}

static void json_entry(FILE *f, const ob_bench_sweep_entry *e)
{
    fprintf(f, "{\"views\":%u,\"objects\":%u,\"modes\":[", e->views, e->objects);
    for (uint32_t m = 0; m < e->mode_count; m++) {
        fputs(m ? ",\n    " : "\n    ", f);
        json_result(f, &e->results[m]);
    }
    fputs("]}", f);
}

static void json_quality(FILE *f, const ob_bench_quality_row *q)
{
    fprintf(f, "{\"kind\":\"%s\",\"env_size\":%u,\"shadow_size\":%u,\"mode\":",
            ob_bench_quality_kind_name(q->kind), q->env_size, q->shadow_size);
    json_str(f, q->mode.name);
    fprintf(f, ",\"workers\":%u,\"max_abs_diff\":%u,\"psnr_db\":", q->mode.workers, q->max_abs_diff);
    json_num(f, q->psnr_db);
    fputs(",\"frame_ms\":", f);
    json_num(f, q->frame_ms);
    fputs(",\"gpu_ms\":", f);
    json_num(f, q->gpu_ms);
    fputs(",\"record_total_ms\":", f);
    json_num(f, q->record_total_ms);
    fprintf(f, ",\"draws\":%u,\"hash_mismatches\":%u,\"msaa_samples\":%u,\"supersample\":%u",
            q->draws, q->hash_mismatches, q->msaa_samples, q->supersample);
    if (q->kind == OB_BENCH_QUALITY_MSAA || q->kind == OB_BENCH_QUALITY_MSAA_REFERENCE)
        fprintf(f, ",\"against\":\"msaa-reference\"");
    if (q->kind == OB_BENCH_QUALITY_ENV_CUBE)
        fprintf(f, ",\"against\":\"env-cube-reference\"");
    if (q->kind == OB_BENCH_QUALITY_ENV_CUBE_REFERENCE)
        fprintf(f, ",\"env_map\":\"cube\",\"against\":\"reference\"");
    if (q->kind == OB_BENCH_QUALITY_MSAA_REFERENCE)
        fprintf(f, ",\"reference\":\"drawn at %ux the size per axis with %ux MSAA (the most the "
                   "device offers, up to 8x), box-downsampled %ux%u in linear light\"",
                q->supersample, q->msaa_samples, q->supersample, q->supersample);
    fputc('}', f);
}

/* "name":median,"name_p25":p25,"name_p75":p75, */
static void json_spread(FILE *f, const char *name, ob_bench_spread v)
{
    const double values[3] = {v.median, v.p25, v.p75};
    static const char *const suffix[3] = {"", "_p25", "_p75"};
    for (int i = 0; i < 3; i++) {
        fprintf(f, "\"%s%s\":", name, suffix[i]);
        json_num(f, values[i]);
        fputc(',', f);
    }
}

static void json_field(FILE *f, const char *name, double v)
{
    fprintf(f, "\"%s\":", name);
    json_num(f, v);
    fputc(',', f);
}

/* "name":"text", (an empty string for NULL) */
static void json_text_field(FILE *f, const char *name, const char *text)
{
    fprintf(f, "\"%s\":", name);
    json_str(f, text ? text : "");
    fputc(',', f);
}

static void json_summary(FILE *f, const ob_bench_report *rep)
{
    const ob_bench_summary *s = &rep->summary;
    fputs("\"summary\":{", f);
    json_spread(f, "mt_speedup_record_10k_8views", s->mt_speedup_record_10k_8views);
    json_text_field(f, "mt_speedup_best_mode", s->mt_speedup_best_mode);
    json_field(f, "engine_vs_raw_per_draw", s->engine_vs_raw_per_draw);
    json_spread(f, "engine_vs_raw_per_object", s->engine_vs_raw_per_object);
    json_spread(f, "auto_vs_best_200", s->auto_vs_best_200);
    json_field(f, "auto_vs_best_200_frame", s->auto_vs_best_200_frame);
    json_spread(f, "auto_vs_best_10k_8views", s->auto_vs_best_10k_8views);
    json_field(f, "auto_vs_round_min_200", s->auto_vs_round_min_200);
    json_field(f, "auto_vs_round_min_10k_8views", s->auto_vs_round_min_10k_8views);
    json_field(f, "per_object_growth_50k_vs_1k", s->per_object_growth_50k_vs_1k);
    json_spread(f, "frame_cpu_speedup_10k_8views", s->frame_cpu_speedup_10k_8views);
    json_text_field(f, "frame_cpu_mode", s->frame_cpu_mode);
    json_spread(f, "serial_fraction_10k_8views", s->serial_fraction_10k_8views);
    json_field(f, "amdahl_speedup_16_cores", s->amdahl_speedup_16_cores);
    json_spread(f, "prerender_ns_per_object_view", s->prerender_ns_per_object_view);
    json_spread(f, "update_ns_per_object", s->update_ns_per_object);
    json_field(f, "gpu_ms_10k_8views", s->gpu_ms_10k_8views);
    json_field(f, "gpu_ms_10k_8views_per_draw", s->gpu_ms_10k_8views_per_draw);
    json_field(f, "gpu_time_instanced_vs_per_draw_10k_8views",
               s->gpu_time_instanced_vs_per_draw_10k_8views);
    json_spread(f, "raw_gpu_instanced_vs_per_draw", s->raw_gpu_instanced_vs_per_draw);
    json_field(f, "raw_gpu_ms", rep->raw_gpu_ms);
    json_field(f, "raw_gpu_instanced_ms", rep->raw_gpu_instanced_ms);
    json_field(f, "vertices_per_draw_10k_8views", s->vertices_per_draw_10k_8views);
    json_field(f, "lod_share_10k_8views", s->lod_share_10k_8views);
    json_field(f, "lights_cost_exponent_4_to_256", s->lights_cost_exponent_4_to_256);
    json_field(f, "lights_cost_exponent_4_to_256_all", s->lights_cost_exponent_4_to_256_all);
    json_field(f, "teardown_ns_per_entity_batch", s->teardown_ns_per_entity_batch);
    json_field(f, "teardown_ns_per_entity_single", s->teardown_ns_per_entity_single);
    json_field(f, "commands_per_object_engine", s->commands_per_object_engine);
    json_field(f, "commands_per_object_raw", s->commands_per_object_raw);
    json_field(f, "commands_per_object_raw_instanced", s->commands_per_object_raw_instanced);
    json_spread(f, "engine_vs_raw_instanced_per_object", s->engine_vs_raw_instanced_per_object);
    json_field(f, "host_allocs_per_object_engine", s->host_allocs_per_object_engine);
    json_field(f, "host_allocs_per_object_raw", s->host_allocs_per_object_raw);
    fprintf(f, "\"threading_max_abs_diff\":%u,\"hash_mismatches\":%u,\"threading_identical\":%s,",
            s->threading_max_abs_diff, s->hash_mismatches, s->threading_identical ? "true" : "false");
    if (rep->stability) fprintf(f, "\"stability_failed\":%u,", rep->stability->failed);
    /* $OB_INSTANCE_RUNS's words */
    fprintf(f, "\"instance_runs\":\"%s\",",
            rep->instance_runs == OB_INSTANCE_RUNS_MULTI_DRAW ? "multi"
            : rep->instance_runs == OB_INSTANCE_RUNS_DIRECT   ? "direct"
                                                              : "instanced");
    fprintf(f, "\"driver_heap_kept\":%s,", rep->driver_heap_kept ? "true" : "false");
    fputs("\"device\":{\"name\":", f);
    json_str(f, rep->device_name);
    fputs(",\"driver\":", f);
    json_str(f, rep->driver_info);
    fputs("}}", f);
}

static void json_stability(FILE *f, const ob_stability *s)
{
    fputs("\"stability\":[\n  ", f);
    for (uint32_t i = 0; i < s->count; i++) {
        const ob_stability_row *row = &s->rows[i];
        if (i) fputs(",\n  ", f);
        fputs("{\"name\":", f);
        json_str(f, row->name);
        fputs(",\"measure\":", f);
        json_str(f, row->measure);
        fputs(",\"error\":", f);
        json_num(f, row->error);
        fputs(",\"unit\":", f);
        json_str(f, row->unit);
        fputs(",\"bound\":", f);
        json_num(f, row->bound);
        /* pass: null for a measured-only row, which neither passed nor failed. */
        fprintf(f, ",\"pass\":%s,\"verdict\":\"%s\",\"ms\":",
                row->verdict == OB_STABILITY_MEASURED ? "null"
                : row->verdict == OB_STABILITY_PASS   ? "true"
                                                      : "false",
                ob_stability_verdict_name(row->verdict));
        json_num(f, row->ms);
        fputs(",\"detail\":", f);
        json_str(f, row->detail);
        fputs("}", f);
    }
    fprintf(f, "],\n\"stability_info\":{\"quick\":%s,\"rows\":%u,\"cases\":%u,\"failed\":%u,"
               "\"measured_only\":%u,\"workers\":%u,\"validation\":%s,\"validation_messages\":%u,"
               "\"expected_log_errors\":%llu,\"expected_log_warnings\":%llu,\"seconds\":%.1f,"
               "\"device\":{\"name\":",
            s->quick ? "true" : "false", s->count, s->cases, s->failed, s->measured, s->workers,
            s->validation ? "true" : "false",
            s->validation_messages, (unsigned long long)s->expected_errors,
            (unsigned long long)s->expected_warnings, s->seconds);
    json_str(f, s->device_name);
    fputs(",\"driver\":", f);
    json_str(f, s->driver_info);
    fputs("}}\n", f);
}

static void json_perf(FILE *f, const ob_bench_report *rep);

ob_result ob_bench_report_json(const ob_bench_report *rep, const char *path)
{
    FILE *f = open_out(path);
    if (!f) return OB_ERR_IO;
    fprintf(f, "{\"program\":\"obelisk-bench\",\"quick\":%s,\"seed\":%u,\"seconds\":%.1f,\n",
            rep->quick ? "true" : "false", rep->seed, rep->seconds);
    fprintf(f, "\"machine\":{\"cores\":%u,\"pool_workers\":%u,\"validation\":%s,"
               "\"gpu_timing\":\"%s\",",
            rep->cores, rep->pool_workers, rep->validation ? "true" : "false",
            rep->gpu_timing == OB_GPU_TIMING_SAMPLED ? "sampled"
            : rep->gpu_timing == OB_GPU_TIMING_OFF   ? "off"
                                                     : "views");
    fputs("\"load_average\":[", f);
    json_num(f, rep->load_start);
    fputs(",", f);
    json_num(f, rep->load_end);
    fputs("],\"core_to_core_round_trip_ns\":[", f);
    json_num(f, rep->core_ns_start);
    fputs(",", f);
    json_num(f, rep->core_ns_end);
    fputs("]},\n", f);
    if (rep->perf) json_perf(f, rep);
    if (rep->perf && rep->stability) fputs(",\n", f);
    if (rep->stability) json_stability(f, rep->stability);
    fputs("}\n", f);
    return close_out(f, path);
}

static void json_perf(FILE *f, const ob_bench_report *rep)
{
    fprintf(f, "\"settings\":{\"warmup\":%u,\"rounds\":%u,\"passes\":%u,\"settle\":%u,"
               "\"flight\":%u,\"big_frames\":{\"over_draws\":%u,\"warmup\":%u,\"rounds\":%u,"
               "\"passes\":%u,\"settle\":%u,\"flight\":%u},"
               "\"view_size\":[%u,%u],\"image_size\":[%u,%u],\"image_frames\":%u,"
               "\"lod\":%s,\"instancing\":%s},\n",
            rep->warmup, rep->rounds, rep->passes, rep->settle, rep->flight, rep->big_draws,
            rep->big_warmup, rep->big_rounds, rep->big_passes, rep->big_settle, rep->big_flight,
            rep->view_width, rep->view_height,
            rep->image_width, rep->image_height, rep->image_frames, rep->lod ? "true" : "false",
            rep->instancing ? "true" : "false");
    fputs("\"sweep\":[\n  ", f);
    for (uint32_t i = 0; i < rep->sweep_count; i++) {
        if (i) fputs(",\n  ", f);
        json_entry(f, &rep->sweep[i]);
    }
    fputs("],\n\"scene200\":", f);
    json_entry(f, &rep->scene200);
    fprintf(f, ",\n\"raw_baseline\":{\"views\":%u,\"objects\":%u,\"draws\":%u,\"reps\":%u,"
               "\"buffer_binds\":%u,\"raw_record_ms\":",
            rep->raw_views, rep->raw_objects, rep->raw.draws, rep->raw.reps, rep->raw.buffer_binds);
    json_num(f, rep->raw.record_ms);
    fputs(",\"raw_ns_per_draw\":", f);
    json_num(f, rep->raw.ns_per_draw);
    fputs(",\"engine_ns_per_draw\":", f);
    json_num(f, rep->engine_ns_per_draw);
    fputs(",\"commands_per_object\":", f);
    json_num(f, rep->raw.commands_per_object);
    fputs(",\"host_allocs_per_object\":", f);
    json_num(f, rep->raw.host_allocs_per_object);
    fputs("},\n\"quality\":[\n  ", f);
    uint32_t written = 0;
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        if (rep->quality[i].kind == OB_BENCH_QUALITY_THREADING) continue;
        if (written++) fputs(",\n  ", f);
        json_quality(f, &rep->quality[i]);
    }
    /* The threading check: the mirror scene's images, plus every sweep
     * configuration's command hashes (no image there). */
    fputs("],\n\"threading_check\":[\n  ", f);
    written = 0;
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        const ob_bench_quality_row *q = &rep->quality[i];
        if (q->kind != OB_BENCH_QUALITY_THREADING) continue;
        if (written++) fputs(",\n  ", f);
        fputs("{\"scene\":\"mirror\",\"mode\":", f);
        json_str(f, q->mode.name);
        fprintf(f, ",\"max_abs_diff\":%u,\"hash_mismatches\":%u,\"identical\":%s}",
                q->max_abs_diff, q->hash_mismatches,
                q->max_abs_diff == 0 && q->hash_mismatches == 0 ? "true" : "false");
    }
    fprintf(f, "],\n\"lights\":{\"size\":[%u,%u],\"rounds\":%u,\"frames\":%u,\"rows\":[",
            rep->lights_width, rep->lights_height, rep->lights_rounds, rep->lights_frames);
    for (uint32_t i = 0; i < rep->lights_count; i++) {
        const ob_bench_lights_row *l = &rep->lights[i];
        fprintf(f, "%s\n  {\"lights\":%u,\"range\":%.4f,\"tiles\":%s,\"measure\":\"%s\",",
                i ? "," : "", l->lights, l->range, l->tiles ? "true" : "false",
                l->cpu_measure ? "process_cpu" : "gpu");
        json_spread(f, "cost_ms", l->cost_ms);
        fputs("\"unit\":\"ms\"}", f);
    }
    fputs("]},\n", f);
    json_summary(f, rep);
}

/* ------------------------------------------------------------ CSV */

static void csv_result(FILE *f, const char *section, uint32_t views, uint32_t objects,
                       const ob_bench_result *r)
{
    const ob_pipeline_manager_stats *p = &r->pm;
    fprintf(f, "%s,%u,%u,,,%s,%u", section, views, objects, r->mode.name, r->mode.workers);
    const double v[] = {r->workers_used, r->draws, r->update_ms, r->pre_render_ms, r->record_ms,
                        r->assemble_ms, r->submit_ms, r->record_total_ms, r->cpu_frame_ms,
                        r->gpu_ms, r->frame_ms, r->draws_per_s, r->speedup_record, r->speedup_frame};
    for (size_t i = 0; i < OB_ARRAY_COUNT(v); i++) csv_num(f, v[i]);
    fprintf(f, ",%u,%u,%u,%u,%u,%u,%u,%u,%u,%u,%u,%u,,,%u", p->pipeline_binds_requested,
            p->pipeline_binds_issued, p->descriptor_binds_requested, p->descriptor_binds_issued,
            p->push_descriptor_requested, p->push_descriptor_issued, p->push_constant_requested,
            p->push_constant_issued, p->vertex_binds_requested, p->vertex_binds_issued,
            p->index_binds_requested, p->index_binds_issued, r->hash_mismatches);
    /* Columns added later go last, so older readers keep their indices. */
    const double added[] = {r->speedup_record_p25, r->speedup_record_p75,
                            r->vs_best_fixed_record.median, r->record_cpu_render_ms,
                            r->record_cpu_workers_ms, r->record_cpu_max_worker_ms,
                            r->cmd_host_allocs_per_object, r->commands_per_object,
                            r->vs_round_min_record.median};
    for (size_t i = 0; i < OB_ARRAY_COUNT(added); i++) csv_num(f, added[i]);
    fputs(",1,1", f);   /* msaa_samples, supersample: the sweep draws single-sampled */
    const double frame[] = {r->frame_cpu_speedup.median, r->frame_cpu_speedup.p25,
                            r->frame_cpu_speedup.p75, r->serial_fraction.median,
                            r->pre_render_round_ms.median * 1e6 / ((double)objects * views),
                            r->update_round_ms.median * 1e6 / objects, r->update_cpu_ms};
    for (size_t i = 0; i < OB_ARRAY_COUNT(frame); i++) csv_num(f, frame[i]);
    fputc('\n', f);
}

/* The columns after supersample that only sweep and scene200 rows fill. */
#define CSV_FRAME_COLUMNS ",,,,,,,"

ob_result ob_bench_report_csv(const ob_bench_report *rep, const char *path)
{
    FILE *f = open_out(path);
    if (!f) return OB_ERR_IO;
    fputs("section,views,objects,env_size,shadow_size,mode,workers,workers_used,draws,update_ms,"
          "pre_render_ms,record_ms,assemble_ms,submit_ms,record_total_ms,cpu_frame_ms,gpu_ms,"
          "frame_ms,draws_per_s,speedup_record,speedup_frame,pipeline_req,pipeline_iss,"
          "descriptor_req,descriptor_iss,push_descriptor_req,push_descriptor_iss,push_constant_req,"
          "push_constant_iss,vertex_req,vertex_iss,index_req,index_iss,max_abs_diff,psnr_db,"
          "hash_mismatches,speedup_record_p25,speedup_record_p75,vs_best_fixed_record,"
          "record_cpu_render_ms,record_cpu_workers_ms,record_cpu_max_worker_ms,"
          "cmd_host_allocs_per_object,commands_per_object,vs_round_min_record,msaa_samples,"
          "supersample,frame_cpu_speedup,frame_cpu_speedup_p25,frame_cpu_speedup_p75,"
          "serial_fraction,prerender_ns_per_object_view,update_ns_per_object,update_cpu_ms\n",
          f);
    for (uint32_t i = 0; i < rep->sweep_count; i++)
        for (uint32_t m = 0; m < rep->sweep[i].mode_count; m++)
            csv_result(f, "sweep", rep->sweep[i].views, rep->sweep[i].objects,
                       &rep->sweep[i].results[m]);
    for (uint32_t m = 0; m < rep->scene200.mode_count; m++)
        csv_result(f, "scene200", 1, rep->scene200.objects, &rep->scene200.results[m]);
    for (uint32_t i = 0; i < rep->quality_count; i++) {
        const ob_bench_quality_row *q = &rep->quality[i];
        fprintf(f, "%s,1,%u,%u,%u,%s,%u,,%u,,,,,", ob_bench_quality_kind_name(q->kind),
                rep->scene200.objects, q->env_size, q->shadow_size, q->mode.name, q->mode.workers,
                q->draws);
        csv_num(f, q->record_total_ms);
        fputs(",", f);
        csv_num(f, q->gpu_ms);
        csv_num(f, q->frame_ms);
        fputs(",,,,,,,,,,,,,,,", f);
        fprintf(f, ",%u", q->max_abs_diff);
        csv_num(f, q->psnr_db);
        /* The nine columns added for the sweep rows, then msaa_samples, supersample,
         * then the frame columns (sweep rows only). */
        fprintf(f, ",%u,,,,,,,,,,%u,%u" CSV_FRAME_COLUMNS "\n", q->hash_mismatches, q->msaa_samples,
                q->supersample);
    }
    /* Raw: record time in record_ms and record_total_ms, and draws/s. */
    fprintf(f, "raw,%u,%u,,,raw,0,,%u,,", rep->raw_views, rep->raw_objects, rep->raw.draws);
    csv_num(f, rep->raw.record_ms);
    fputs(",,", f);
    csv_num(f, rep->raw.record_ms);
    fputs(",,,", f);
    csv_num(f, rep->raw.record_ms > 0 ? rep->raw.draws / (rep->raw.record_ms * 1e-3) : NAN);
    fputs(",,,,,,,,,,,,,,,,,,,,,,,", f);
    csv_num(f, rep->raw.host_allocs_per_object);
    csv_num(f, rep->raw.commands_per_object);
    /* vs_round_min_record (none), msaa_samples, supersample, then none of the frame columns */
    fputs(",,1,1" CSV_FRAME_COLUMNS "\n", f);
    return close_out(f, path);
}

static void csv_text(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

ob_result ob_bench_report_stability_csv(const ob_stability *s, const char *path)
{
    FILE *f = open_out(path);
    if (!f) return OB_ERR_IO;
    fputs("name,measure,error,unit,bound,pass,ms,detail,verdict\n", f);
    for (uint32_t i = 0; i < s->count; i++) {
        const ob_stability_row *row = &s->rows[i];
        csv_text(f, row->name);
        fputc(',', f);
        csv_text(f, row->measure);
        csv_num(f, row->error);
        fputc(',', f);
        csv_text(f, row->unit);
        csv_num(f, row->bound);
        /* pass: empty for a measured-only row, which neither passed nor failed. */
        fprintf(f, ",%s", row->verdict == OB_STABILITY_MEASURED ? ""
                          : row->verdict == OB_STABILITY_PASS   ? "true"
                                                                : "false");
        csv_num(f, row->ms);
        fputc(',', f);
        csv_text(f, row->detail);
        fprintf(f, ",%s\n", ob_stability_verdict_name(row->verdict));
    }
    return close_out(f, path);
}

void ob_bench_report_stability_csv_path(const char *csv, char *dest, size_t dest_size)
{
    size_t len = strlen(csv);
    if (len >= 4 && strcmp(csv + len - 4, ".csv") == 0) len -= 4;
    snprintf(dest, dest_size, "%.*s-stability.csv", (int)len, csv);
}

/* ------------------------------------------------------------ charts */

static ob_result run_gnuplot(const char *script)
{
    char *argv[] = {"gnuplot", (char *)script, NULL};
    pid_t pid;
    int err = posix_spawnp(&pid, "gnuplot", NULL, NULL, argv, environ);
    if (err != 0) {
        OB_LOG_E("bench", "cannot run gnuplot for '%s': %s", script, strerror(err));
        return OB_ERR_UNSUPPORTED;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return OB_ERR_UNSUPPORTED;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        OB_LOG_E("bench", "gnuplot failed on '%s' (status %d)", script, status);
        return OB_ERR_UNSUPPORTED;
    }
    return OB_OK;
}

/* Paths of a chart's data and script (1024 bytes each); opens the data. */
static FILE *open_chart_data(const char *dir, const char *name, char *dat, char *gp)
{
    snprintf(dat, 1024, "%s/%s.dat", dir, name);
    snprintf(gp, 1024, "%s/%s.gp", dir, name);
    return open_out(dat);
}

static ob_result speedup_chart(const ob_bench_report *rep, const char *dir)
{
    char dat[1024], gp[1024];
    FILE *f = open_chart_data(dir, "speedup", dat, gp);
    if (!f) return OB_ERR_IO;
    fputs("# views objects workers speedup_record (ST rec+asm / MT rec+asm, device idle)\n", f);
    uint32_t panels[16], panel_count = 0, sizes[16], size_count = 0;
    for (uint32_t i = 0; i < rep->sweep_count; i++) {
        const ob_bench_sweep_entry *e = &rep->sweep[i];
        bool seen = false;
        for (uint32_t k = 0; k < panel_count; k++) seen |= panels[k] == e->views;
        if (!seen && panel_count < 16) panels[panel_count++] = e->views;
        seen = false;
        for (uint32_t k = 0; k < size_count; k++) seen |= sizes[k] == e->objects;
        if (!seen && size_count < 16) sizes[size_count++] = e->objects;
        fprintf(f, "%u %u 0 1\n", e->views, e->objects);
        for (uint32_t m = 0; m < e->mode_count; m++) {
            const ob_bench_result *r = &e->results[m];
            if (r->mode.threading != OB_THREADING_MULTI) continue;
            fprintf(f, "%u %u %u %.4f\n", e->views, e->objects, r->mode.workers, r->speedup_record);
        }
        fputs("\n", f);
    }
    ob_result res = close_out(f, dat);
    if (res != OB_OK) return res;
    f = open_out(gp);
    if (!f) return OB_ERR_IO;
    uint32_t cols = panel_count > 1 ? 2 : 1, rows = (panel_count + cols - 1) / cols;
    fprintf(f, "set terminal pngcairo size %u,%u font ',10'\nset output '%s/speedup.png'\n",
            560 * cols, 400 * (rows ? rows : 1), dir);
    fprintf(f, "set multiplot layout %u,%u title 'Recording speedup vs workers (device idle; "
               "%u cores; 0 = single-threaded)'\n", rows ? rows : 1, cols, rep->cores);
    fputs("set xlabel 'workers'\nset ylabel 'ST / MT record time'\nset key top left\n"
          "set grid\nset xtics 1\nset yrange [0:*]\nset xrange [-0.2:*]\n", f);
    for (uint32_t p = 0; p < panel_count; p++) {
        fprintf(f, "set title '%u view%s'\nplot ", panels[p], panels[p] == 1 ? "" : "s");
        for (uint32_t s = 0; s < size_count; s++)
            fprintf(f, "'%s' using 3:(($1==%u && $2==%u) ? $4 : 1/0) with linespoints lw 2 "
                       "title '%u objects', ", dat, panels[p], sizes[s], sizes[s]);
        fprintf(f, "%u < x ? %u : x dashtype 2 lc rgb 'gray' title 'cores bound'\n", rep->cores,
                rep->cores);
    }
    fputs("unset multiplot\n", f);
    res = close_out(f, gp);
    return res == OB_OK ? run_gnuplot(gp) : res;
}

static ob_result error_chart(const ob_bench_report *rep, const char *dir)
{
    char dat[1024], gp[1024];
    FILE *f = open_chart_data(dir, "error", dat, gp);
    if (!f) return OB_ERR_IO;
    fputs("# series(0 env, 1 shadow, 2 env as cube maps against the cube reference) size frame_ms psnr_db "
          "max_abs_diff\n", f);
    double ref_ms = NAN;
    static const ob_bench_quality_kind series_kind[3] = {OB_BENCH_QUALITY_ENV, OB_BENCH_QUALITY_SHADOW,
                                                         OB_BENCH_QUALITY_ENV_CUBE};
    for (int series = 0; series < 3; series++) {
        for (uint32_t i = 0; i < rep->quality_count; i++) {
            const ob_bench_quality_row *q = &rep->quality[i];
            if (q->kind == OB_BENCH_QUALITY_REFERENCE) ref_ms = q->frame_ms;
            if (q->kind != series_kind[series] || !isfinite(q->psnr_db)) continue;
            fprintf(f, "%d %u %.4f %.4f %u\n", series, series == 1 ? q->shadow_size : q->env_size,
                    q->frame_ms, q->psnr_db, q->max_abs_diff);
        }
        fputs("\n\n", f);
    }
    ob_result res = close_out(f, dat);
    if (res != OB_OK) return res;
    f = open_out(gp);
    if (!f) return OB_ERR_IO;
    fprintf(f, "set terminal pngcairo size 800,560 font ',10'\nset output '%s/error.png'\n", dir);
    fprintf(f, "set title 'Image error vs frame time (mirror scene; reference: ST, highest "
               "quality, %.1f ms)'\n", isfinite(ref_ms) ? ref_ms : 0.0);
    fputs("set xlabel 'frame time in flight (ms)'\nset ylabel 'PSNR over RGB (dB)'\nset grid\n"
          "set key bottom right\n", f);
    fprintf(f, "plot '%s' index 0 using 3:4 with linespoints pt 7 lw 2 title 'env-map size', "
               "'' index 0 using 3:4:(sprintf('%%d', $2)) with labels offset 1,1 notitle, "
               "'' index 1 using 3:4 with linespoints pt 5 lw 2 title 'shadow-map size', "
               "'' index 1 using 3:4:(sprintf('%%d', $2)) with labels offset 1,-1 notitle, "
               "'' index 2 using 3:4 with linespoints pt 9 lw 2 title 'env-map size, cube maps (against the cube reference)', "
               "'' index 2 using 3:4:(sprintf('%%d', $2)) with labels offset 1,1 notitle\n", dat);
    res = close_out(f, gp);
    return res == OB_OK ? run_gnuplot(gp) : res;
}

ob_result ob_bench_report_charts(const ob_bench_report *rep, const char *dir)
{
    if (strpbrk(dir, "'\"\n")) {
        OB_LOG_E("bench", "chart folder '%s': quotes and newlines are not supported", dir);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_result res = ob_dir_make(dir);
    if (res != OB_OK) return res;
    res = speedup_chart(rep, dir);
    ob_result res2 = error_chart(rep, dir);
    return res != OB_OK ? res : res2;
}
