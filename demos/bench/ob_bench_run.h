/* ob_bench_run.h — measuring one scene in several threading modes.
 *
 * Two loops, both over every mode of the list, in the same process on the
 * same scene (so ratios between modes come from one run):
 *   idle     rounds of `passes` passes of one frame per mode; before each
 *            frame the device is waited idle (ob_renderer_wait_idle), so
 *            recording never competes with lavapipe executing the previous
 *            frame on the same cores.
 *            Each round starts with the updates: device idle, every mode in
 *            turn (the round's order) is set and moves the scene on once
 *            through ob_renderer_update_scene, under its own threading; the
 *            bench times each call itself (ob_time_ns, ob_thread_cpu_ns on
 *            the render thread) and takes the renderer's CPU split of it
 *            (ob_renderer_last_update_stats: render thread, its part in
 *            parallel loops, pool threads), and keeps them as that mode's
 *            update of the round. The scene thus advances once per mode per
 *            round, and every pass of the round renders the same state
 *            untouched, so every mode records exactly the same commands and
 *            their hashes must be equal. A mode's frames of the round are
 *            reported with its own update of the round (update_ms,
 *            serial_fraction), not with the one the renderer's stats of
 *            the frame carry (the last update's, whichever mode made it).
 *            The mode order steps through all orders of the modes, a new one
 *            each pass, so no mode always follows the same other mode. A
 *            mode's figure for the round is its fastest
 *            pass: interference on this VM (a preempted thread, a late
 *            wake-up) only ever adds time, so the fastest of a few frames of
 *            the same commands is the steadiest estimate of their cost; the
 *            slower passes are checked for hashes and otherwise dropped.
 *            Gives the CPU phases, GPU time (timestamps), binds.
 *   flight   per mode, consecutive frames without waiting (frames in
 *            flight, the normal way to run; each advances the scene): gives
 *            the frame period.
 * Warm-up frames (idle, round-robin) come first. Reported values are medians;
 * ratios between modes are medians of per-round ratios (both frames of a
 * ratio from the same round, so a slow spell of the machine divides out),
 * with their quartiles. The in-flight loop runs the modes one after another,
 * so its ratio (speedup_frame) stays a ratio of medians.
 * An optional hook runs after every pass of every idle round with the device
 * idle, given that pass's recording times: a baseline measured there (the
 * raw Vulkan loop) shares the rounds' conditions.
 *
 * Lifecycle: fill ob_bench_run_desc → ob_bench_run_modes → read results.
 * Thread rule: render thread; the renderer's stats callback is taken over
 * for the duration of the call and restored to none afterwards.
 */
#ifndef OB_BENCH_RUN_H
#define OB_BENCH_RUN_H

#include "ob_bench_scene.h"

/* Modes one run (and one report entry) holds. */
#define OB_BENCH_MAX_MODES 8

typedef struct ob_bench_mode {
    const char *name;          /* "ST", "1", "2", "4", "auto" */
    ob_threading threading;
    uint32_t workers;          /* active workers for MULTI/AUTO (0 for ST) */
} ob_bench_mode;

/* Called once per rendered frame (progress display). */
typedef void (*ob_bench_tick_fn)(void *user);

/* One mode's frame of an idle round, as the round hook sees it. */
typedef struct ob_bench_round_sample {
    double record_total_ms;    /* record + assemble */
    uint32_t draws;
} ob_bench_round_sample;

/* After pass `pass` of idle round `round` (warm-up rounds first, measured
 * false), device idle; modes[m] is mode m's frame of that pass. [render
 * thread]. A result other than OB_OK stops the run with that result. */
typedef ob_result (*ob_bench_round_fn)(void *user, uint32_t round, uint32_t pass, bool measured,
                                       const ob_bench_round_sample *modes);

/* Median and quartiles of values taken one per round. */
typedef struct ob_bench_spread {
    double median, p25, p75;   /* NAN when there was no value */
} ob_bench_spread;

typedef struct ob_bench_run_desc {
    const ob_bench_mode *modes;
    uint32_t mode_count;       /* the first mode is the reference for hashes and speedups */
    uint32_t warmup;           /* idle frames per mode before measuring */
    uint32_t rounds;           /* measured idle rounds */
    uint32_t passes;           /* frames per mode and round, the fastest kept (0 = 1) */
    /* Unmeasured idle frames of a mode right before each of its measured
     * ones (0: the measured frame is the first after switching modes). */
    uint32_t settle;
    uint32_t flight;           /* measured in-flight frames per mode (0 = skip the loop) */
    double dt;                 /* scene time step, e.g. 1/60 */
    ob_bench_tick_fn tick;
    void *tick_user;
    ob_bench_round_fn round_hook;  /* optional */
    void *round_user;
} ob_bench_run_desc;

typedef struct ob_bench_result {
    ob_bench_mode mode;
    uint32_t frames;           /* measured idle frames */
    uint32_t draws;            /* per frame (median) */
    uint32_t views;            /* views recorded per frame (median) */
    double vertices;           /* vertices the draws submitted per frame (median) */
    uint32_t lod_items;        /* items drawn at a coarser level of detail (median) */
    double workers_used;       /* mean active workers of the measured frames (auto varies) */
    /* medians, milliseconds, idle loop */
    double update_ms;          /* the mode's own update of each round (wall) */
    double update_cpu_ms;      /* its render thread CPU time */
    double pre_render_ms, record_ms, assemble_ms, submit_ms;
    double record_total_ms;    /* record + assemble: start of recording to primary complete */
    double cpu_frame_ms;       /* the renderer's frame_ns with the device idle (its update
                                  replaced by update_ms) */
    double gpu_ms;             /* timestamps (NAN if unavailable) */
    double gpu_views_ms;       /* the views' stamps summed (NAN unless every view was
                                  stamped: --gpu-timing views; with the default
                                  sampling, the median of the frames that were) */
    double gpu_rest_ms;        /* median over those frames of their GPU time less
                                  their views' (uploads, barriers, clears) */
    double upload_mb;          /* the staged ring's copy to device memory (0 unstaged) */
    double gpu_flight_ms;      /* timestamps of the frames in flight (a real GPU idle
                                  between frames may run them at lower clocks) */
    double draws_per_s;        /* draws / record_total */
    double frame_ms;           /* in-flight frame period (median), NAN without the loop */
    double speedup_record;     /* median over idle rounds of (reference mode's record_total /
                                  this one's) in the same round */
    double speedup_record_p25, speedup_record_p75;
    double speedup_frame;      /* reference mode's frame_ms / this one's (ratio of medians) */
    /* Median over idle rounds of this mode's record_total / the best fixed
     * mode's (ST or MULTI: the one of lowest median record_total over the
     * run) in the same round: what auto is judged by, since recording is
     * what it decides on. */
    ob_bench_spread vs_best_fixed_record;
    /* The same against the lowest fixed-mode time of each round (the
     * figure before 2026-11-24). When two modes are within the noise of
     * each other the minimum of their two times is below both modes' usual
     * time, so even a mode that always ran the better one scores above 1:
     * kept to compare with older runs, not to judge auto by. */
    ob_bench_spread vs_round_min_record;
    /* Over idle rounds: the mode's update of each round, and each round's
     * fastest pre-render of its passes (it may be another pass than the
     * kept one, which is the fastest by recording time). */
    ob_bench_spread update_round_ms, pre_render_round_ms;
    /* Median over idle rounds of the reference mode's CPU phases of the
     * frame / this mode's, both of the same round. A mode's phases of a
     * round: its update of the round + the fastest of its passes' pre-render
     * + record + assemble + submit (wall time). */
    ob_bench_spread frame_cpu_speedup;
    /* Median over idle rounds of the serial CPU share of the mode's frame
     * with its update of the round: (cpu_render - cpu_render_parallel) /
     * (cpu_render + cpu_pool), from thread CPU clocks (ob_frame_stats,
     * ob_update_stats). split: the mode the summary reports it for (the
     * multi-threaded mode of most workers, ob_bench_split_mode). */
    bool split;
    ob_bench_spread serial_fraction;
    /* Recording CPU time (ob_frame_stats.record_cpu_ns), medians over idle
     * frames: render thread, sum over workers, busiest worker. NAN when the
     * engine does not report it (every frame read 0). Next to the wall times
     * they tell a loaded machine (wall grows, CPU not) from a slow design. */
    double record_cpu_render_ms, record_cpu_workers_ms, record_cpu_max_worker_ms;
    /* Median of cmd_host_allocs / draws (NAN when the engine reports no
     * per-frame CPU or allocation figures). */
    double cmd_host_allocs_per_object;
    /* Estimate of vkCmd calls the pipeline manager made per draw: (every
     * *_issued counter + draws + dispatches) / draws, last measured frame. */
    double commands_per_object;
    ob_pipeline_manager_stats pm;            /* bind counters of the last measured frame */
    uint64_t frame_hash;       /* of the last measured frame */
    uint32_t hash_mismatches;  /* measured frames whose hash differed from the reference mode's */
} ob_bench_result;

/* Runs the loops; out has desc->mode_count entries (1..OB_BENCH_MAX_MODES,
 * else OB_ERR_INVALID_ARGUMENT). Failure: the first frame or hook error
 * (logged); out is then incomplete. */
ob_result ob_bench_run_modes(ob_bench_scene *s, const ob_bench_run_desc *desc,
                             ob_bench_result *out);

/* Median and quartiles (linear interpolation) of the non-NAN values; sorts
 * them in place. [any thread]. No value: every field NAN. */
void ob_bench_spread_of(double *values, uint32_t n, ob_bench_spread *out);

/* The mode the summary reports the frame figures for: the multi-threaded mode of
 * most workers (the first of them on a tie); UINT32_MAX when there is none.
 * [any thread] */
uint32_t ob_bench_split_mode(const ob_bench_mode *modes, uint32_t count);

/* Sets the renderer's threading mode for the next frame. */
void ob_bench_set_mode(ob_renderer *r, const ob_bench_mode *m);

#endif /* OB_BENCH_RUN_H */
