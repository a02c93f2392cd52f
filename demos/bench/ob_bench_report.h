/* ob_bench_report.h — what obelisk-bench measured, and its outputs: a
 * table on stdout, JSON, CSV, gnuplot charts. Either section may be left
 * out: the performance one (sweep, raw, scene200, quality: perf = false)
 * or the stability one (ob_stability.h: stability = NULL).
 *
 * Lifecycle: the program fills an ob_bench_report, then calls the writers.
 * Thread rule: any one thread. Writers report I/O failures as OB_ERR_IO
 * (logged with the path); the charts need gnuplot on PATH
 * (OB_ERR_UNSUPPORTED, logged, when it is missing or fails).
 */
#ifndef OB_BENCH_REPORT_H
#define OB_BENCH_REPORT_H

#include <stdio.h>

#include "ob_bench_lights.h"
#include "ob_bench_quality.h"
#include "ob_bench_raw.h"
#include "ob_bench_run.h"
#include "ob_stability.h"


/* One scene (views × objects) measured in every mode of the list. */
typedef struct ob_bench_sweep_entry {
    uint32_t views, objects;
    uint32_t mode_count;
    ob_bench_result results[OB_BENCH_MAX_MODES];
} ob_bench_sweep_entry;

/* Ratios between modes are medians of per-round ratios from the idle
 * rounds, with p25 and p75 beside them (ob_bench_run.h). */
typedef struct ob_bench_summary {
    ob_bench_spread mt_speedup_record_10k_8views;  /* ST record / MT record, 10k objects,
                                                      8 views, the MT mode with the best median */
    const char *mt_speedup_best_mode;      /* the MT mode that was best there */
    /* engine ST record_total per visible object / raw ns per object, 1 view,
     * raw_objects; both recorded in every idle round */
    ob_bench_spread engine_vs_raw_per_object;
    /* The same against the raw loop instanced (a run of one mesh one draw) */
    ob_bench_spread engine_vs_raw_instanced_per_object;
    double commands_per_object_raw_instanced;
    double engine_vs_raw_per_draw;         /* the same median, under its older name */
    /* auto record_total / the better fixed mode's (ST or MT, by median over
     * the run) in the same round: 200-object mirror scene, and 10k objects
     * in 8 views (ob_bench_result.vs_best_fixed_record) */
    ob_bench_spread auto_vs_best_200, auto_vs_best_10k_8views;
    /* The same against each round's lower of ST and MT, biased above 1 when
     * the two are close (ob_bench_result.vs_round_min_record); medians. */
    double auto_vs_round_min_200, auto_vs_round_min_10k_8views;
    double auto_vs_best_200_frame;         /* auto frame_ms / min(ST, MT) frame_ms (in flight) */
    /* ST record per draw, 1 view: 50k objects / 1k objects (ratio of medians:
     * different scenes share no round) */
    double per_object_growth_50k_vs_1k;
    /* 10k objects, 8 views, the split mode (ob_bench_split_mode: the
     * multi-threaded mode of most workers; frame_cpu_mode names it): median
     * over rounds of ST's (update + pre-render + record + assemble + submit)
     * / that mode's (ob_bench_result.frame_cpu_speedup), and its frames'
     * serial CPU share, update included (ob_bench_result.serial_fraction),
     * with the speedup Amdahl's law gives that share on 16 cores,
     * 1 / (s + (1 - s) / 16), from the median. */
    ob_bench_spread frame_cpu_speedup_10k_8views;
    const char *frame_cpu_mode;
    ob_bench_spread serial_fraction_10k_8views;
    double amdahl_speedup_16_cores;
    /* ST, per round: pre-render ns / (objects x views) at 10k objects x 8
     * views; update ns / objects at 50k objects, 1 view. */
    ob_bench_spread prerender_ns_per_object_view;
    ob_bench_spread update_ns_per_object;
    /* Destroying a scene graph of 100k renderable entities (no device), ns
     * per entity, median of 3: all in one ob_nodes_destroy, and one
     * ob_node_destroy each, newest first (ob_scene_unload's order). */
    double teardown_ns_per_entity_batch, teardown_ns_per_entity_single;
    /* GPU time of the 10k x 8 views frame, ST, instanced (the default) and
     * with one draw per entity (--no-instancing, a run of its own), medians;
     * their ratio. */
    double gpu_ms_10k_8views, gpu_ms_10k_8views_per_draw;
    double gpu_time_instanced_vs_per_draw_10k_8views;
    /* The same ratio for the raw loops (ob_bench_raw_gpu_ms: the raw
     * baseline's view, same draws and triangles, no engine), per round
     * [p25, p75]: what bare Vulkan gets on this device, to read the
     * engine's against. */
    ob_bench_spread raw_gpu_instanced_vs_per_draw;
    /* ST, 10k x 8 views: vertices submitted per entity drawn, and the share
     * of entities drawn at a coarser level of detail. */
    double vertices_per_draw_10k_8views, lod_share_10k_8views;
    /* The lights section (ob_bench_lights.h): the exponent of the frame
     * cost's growth from 4 to 256 point lights at fixed coverage, with the
     * tile grid and with every light in every fragment (below 1:
     * sub-linear). */
    double lights_cost_exponent_4_to_256, lights_cost_exponent_4_to_256_all;
    /* vkCmd calls per visible object: the engine's estimated from the
     * pipeline manager's issued counters, the raw loop's counted; in the raw
     * configuration, ST */
    double commands_per_object_engine, commands_per_object_raw;
    /* driver host allocations through the command pools per visible object
     * (engine: NAN until the engine reports them) */
    double host_allocs_per_object_engine, host_allocs_per_object_raw;
    uint32_t threading_max_abs_diff;       /* largest image difference of any mode vs ST */
    uint32_t hash_mismatches;              /* frames of any mode whose hash differed from ST's */
    bool threading_identical;              /* both of the above are 0 */
} ob_bench_summary;

typedef struct ob_bench_report {
    bool quick;
    bool perf;                                     /* the performance sections ran */
    const ob_stability *stability;           /* NULL: that section did not run */
    uint32_t seed, cores, pool_workers;
    char device_name[256], driver_info[256];   /* ob_device_name / ob_device_driver_info */
    bool validation;
    ob_gpu_timing gpu_timing;                      /* --gpu-timing */
    uint32_t warmup, rounds, flight;               /* sweep frame counts per mode */
    uint32_t passes;                               /* frames per mode and idle round */
    uint32_t settle;                               /* ob_bench_run_desc.settle */
    uint32_t big_draws;                            /* frames of more draws (estimated) use */
    uint32_t big_warmup, big_rounds, big_flight;   /* these counts instead */
    uint32_t big_passes, big_settle;               /* (a GPU keeps the asked-for ones) */
    uint32_t view_width, view_height;              /* sweep view size */
    bool lod, instancing;                          /* the sweep's levels of detail, instancing */
    ob_instance_runs instance_runs;                /* how the renderer draws instance runs */
    bool driver_heap_kept;                         /* ob_device_keeps_driver_heap */
    uint32_t image_width, image_height, image_frames;
    double seconds;                                /* whole run, wall clock */
    double load_start, load_end;                   /* 1-minute load average (NAN if unknown) */
    double core_ns_start, core_ns_end;             /* ob_bench_core_to_core_ns (NAN if unknown) */

    ob_bench_sweep_entry *sweep;
    uint32_t sweep_count;
    ob_bench_raw_result raw;                       /* raw Vulkan baseline */
    uint32_t raw_views, raw_objects;               /* the sweep entry it is compared with */
    double engine_ns_per_draw;                     /* that entry's ST record / draws */
    ob_bench_spread engine_vs_raw;                 /* per-round ratio of the two per draw */
    ob_bench_raw_result raw_instanced;             /* the raw loop instanced, same rounds */
    ob_bench_spread engine_vs_raw_instanced;
    /* The raw loops executed, GPU ms (medians), and their per-round ratio. */
    double raw_gpu_ms, raw_gpu_instanced_ms;
    ob_bench_spread raw_gpu_instanced_vs_per_draw;
    ob_bench_quality_row *quality;
    uint32_t quality_count;
    ob_bench_sweep_entry scene200;                 /* mirror scene: ST, MT, auto */
    ob_bench_sweep_entry per_draw_10k_8views;      /* ST, --no-instancing (mode_count 0: not run) */
    ob_bench_lights_row *lights;                   /* the lights section's rows */
    uint32_t lights_count;
    uint32_t lights_width, lights_height, lights_frames, lights_rounds;
    ob_bench_summary summary;
} ob_bench_report;

void ob_bench_report_print(const ob_bench_report *rep, FILE *f);
ob_result ob_bench_report_json(const ob_bench_report *rep, const char *path);
/* The performance sections, one row per configuration and mode. */
ob_result ob_bench_report_csv(const ob_bench_report *rep, const char *path);
/* The stability section: header name,measure,error,unit,bound,pass,ms,detail,
 * one row a case (empty fields for NAN). */
ob_result ob_bench_report_stability_csv(const ob_stability *s, const char *path);
/* Where the stability CSV of --csv FILE goes: FILE without a trailing
 * ".csv", then "-stability.csv". */
void ob_bench_report_stability_csv_path(const char *csv, char *dest, size_t dest_size);
/* Writes DIR/speedup.png (record-time speedup against workers, one line
 * per object count, one panel per view count) and DIR/error.png (PSNR
 * against frame time for the quality settings), with their .dat and .gp
 * files beside them. Creates DIR. */
ob_result ob_bench_report_charts(const ob_bench_report *rep, const char *dir);

#endif /* OB_BENCH_REPORT_H */
