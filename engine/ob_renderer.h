/* ob_renderer.h — the frame: view queue, worker pool, submission, stats.
 *
 * Hieroglyph 3's RendererDX11 with its multithreaded task processing, on
 * Vulkan. During PreRender views queue themselves (ob_renderer_queue_view,
 * in the extension header ob_renderer_layer.h); ob_renderer_process_views records them — dependencies first — either
 * inline into the primary command buffer through the immediate pipeline
 * manager (single-threaded), or as jobs handed all at once to a pool of
 * workers, worker i recording with pipeline manager i into secondaries from
 * its own command pool (multi-threaded). The primary then executes every
 * view in order, with the barriers each needs, in one submission.
 *
 * Lifecycle: create → [attach_surface] → { begin_frame → PreRender (the
 * views layer's ob_views_render per root view) → [process_views] →
 * end_frame } * → [detach_surface] → destroy.
 * Thread rule: every function is [render thread]; workers are internal.
 * The threading mode and the active worker count change only at begin_frame.
 *
 * Vulkan objects: by default the renderer creates its instance and device;
 * with desc.device.adopt it runs on the application's (ob_vulkan_handles in
 * ob_device.h) and destroys none of them.
 *
 * Presenting: without a surface the renderer is headless (a program reads
 * the final image back itself, e.g. ob_image_write_png). With one (ob_renderer_attach_surface) it owns a swapchain on
 * it: begin_frame acquires an image, the frame's primary ends by copying the
 * present image (a presenting composite view's target) into it, the frame's
 * one submission waits for the acquire and signals the present, and
 * end_frame presents. A swapchain out of date, suboptimal or of another
 * size than the surface is rebuilt at the next begin_frame; a surface of
 * size 0x0 (a minimised window) skips presenting, not the frame, and is no
 * error.
 */
#ifndef OB_RENDERER_H
#define OB_RENDERER_H

#include "ob_device.h"
#include "ob_params.h"
#include "ob_pipeline_manager.h"
#include "ob_resources.h"
#include "ob_scene.h"
#include "ob_view.h"

#define OB_MAX_WORKERS 16
#define OB_MAX_FRAME_VIEWS 128

/* The interfaces through which the engine calls up into materials and
 * geometry, and the hooks views and materials call during a frame, are the
 * extension API: engine/ob_renderer_layer.h (<obelisk/ob_renderer_layer.h>),
 * which this header does not include. Here they are opaque. */
typedef struct ob_material_iface ob_material_iface;
typedef struct ob_geometry_iface ob_geometry_iface;

typedef enum ob_threading {
    OB_THREADING_SINGLE = 0,   /* immediate: record everything into the primary */
    OB_THREADING_MULTI = 1,    /* workers record secondaries */
    OB_THREADING_AUTO = 2,     /* decide per frame from last frames' measured cost */
} ob_threading;
/* Stable short name of a mode: "single", "multi" or "auto" (the words
 * --threads and the benchmark's files use); "unknown" for other values.
 * Never NULL. [any thread] */
const char *ob_threading_name(ob_threading mode);

/* GPU timestamps. A stamp written after a view's work waits for that work:
 * on lavapipe each one flushes the rasteriser, so stamping every view of
 * every frame costs 5-15% of the frame period at 1-8 views and up to ~40%
 * at 16 views x 10k objects (docs/benchmark.md, "GPU timestamps"). */
typedef enum ob_gpu_timing {
    OB_GPU_TIMING_SAMPLED = 0,   /* the frame's GPU time every frame, each view's every
                                    OB_VIEW_TIMESTAMP_INTERVAL-th frame (the default) */
    OB_GPU_TIMING_EVERY_VIEW,    /* the frame's and each view's, every frame */
    OB_GPU_TIMING_OFF,           /* none: gpu_ms is -1 everywhere */
} ob_gpu_timing;
#define OB_VIEW_TIMESTAMP_INTERVAL 16u

/* Where the draws read the blocks the pipeline managers write each frame
 * (uniform blocks, per-instance blocks). */
typedef enum ob_ring_staging {
    /* Staged where the device's host-visible memory is not device-local (a
     * discrete GPU), direct where it is (lavapipe, integrated GPUs).
     * $OB_RING_STAGING=on|off overrides it. */
    OB_RING_STAGING_AUTO = 0,
    /* Written in host memory, copied to device-local memory at the start of
     * the frame's command buffers: the GPU reads its own memory (on an
     * H100, instanced draws read host memory across PCIe at 2.6x the GPU
     * time of one draw each), and the host never writes across PCIe (the
     * H100 machine mapped its device-local host-visible memory uncached). */
    OB_RING_STAGING_ON,
    /* Written where the draws read them, host-visible memory. */
    OB_RING_STAGING_OFF,
} ob_ring_staging;

typedef struct ob_renderer_desc {
    ob_device_desc device;
    uint32_t worker_count;       /* pool size; 0 → number of cores (max OB_MAX_WORKERS) */
    ob_threading threading;      /* initial mode */
    /* Target draws per job when splitting a view. 0 → sized per frame:
     * the frame's draws over 4 jobs per active thread, at least 2048. */
    uint32_t chunk_draws;
    /* Entities (nodes) per index of the parallel loops of PreRender and of
     * ob_renderer_update_scene; a loop goes to the pool only when each
     * thread gets two indices' worth. 0 → 4096 for culling, 1024 for the
     * update. Small values (tests) put the parallel paths to work on small
     * scenes. */
    uint32_t parallel_grain;
    /* The pool's threads are pinned, each to a CPU other than the one the
     * render thread is recording on (re-pinned only when that changes):
     * without it the scheduler often wakes a worker onto the render
     * thread's CPU. The calling thread is never pinned. true = leave all
     * placement to the scheduler. */
    bool no_thread_affinity;
    /* Which GPU timestamps frames write (ob_frame_stats.gpu_ms and the
     * views' gpu_ms; -1 where none was written). */
    ob_gpu_timing gpu_timing;
    ob_ring_staging ring_staging;
    ob_instance_runs instance_runs;  /* ob_pipeline_manager.h */
} ob_renderer_desc;

typedef enum ob_skip_reason {
    OB_SKIP_NONE = 0,
    OB_SKIP_EMPTY,               /* no draws: nothing recorded */
    OB_SKIP_RECURSION,           /* queued deeper than the recursion bound */
    OB_SKIP_NO_CASTERS,          /* shadow view with no caster in range */
    OB_SKIP_NOT_NEEDED,          /* nobody visible asked for it */
    OB_SKIP_DUPLICATE,           /* already queued this frame (not reported by the renderer
                                    today: a second queueing only adds a dependency) */
    OB_SKIP_ERROR,               /* failed (see log) */
    OB_SKIP_OVER_LIMIT,          /* over a documented limit (docs/limits.md), logged once
                                    by name: a shadowed light past the shadow layers */
} ob_skip_reason;
const char *ob_skip_reason_name(ob_skip_reason r);

typedef struct ob_view_stats {
    char name[48];
    ob_view_type type;
    uint32_t draws, culled, items;
    /* Draw commands recorded, the draws among `draws` that were instances
     * of instanced draws, and the most instances of one draw (one recording
     * job's: a run cut between two jobs counts as two). */
    uint32_t draw_calls, instances, longest_run;
    /* Items drawn at a coarser level of detail than level 0 (ob_view.lod_scale). */
    uint32_t lod_items;
    uint32_t chunks;
    int32_t worker;              /* worker of the first chunk; -1 = immediate */
    uint64_t cull_ns, record_ns; /* CPU */
    double gpu_ms;               /* from timestamps, -1 if unavailable */
    ob_cmd_hash hash;
    ob_skip_reason skipped;
} ob_view_stats;

/* One frame's figures. Times are wall time (CLOCK_MONOTONIC) on the render
 * thread unless said otherwise. They fall in two kinds, and only the first
 * is the engine's CPU work:
 *   work:    update_ns + pre_render_ns + record_ns + assemble_ns + submit_ns
 *            (ob_frame_stats_cpu_work_ns)
 *   waiting: gpu_wait_ns + acquire_ns + present_ns (ob_frame_stats_wait_ns):
 *            in begin_frame for the GPU to finish the frame that last used
 *            this slot (frame - frames_in_flight: its fence and its
 *            timestamps) and for a swapchain image, and vkQueuePresentKHR
 *            in end_frame
 * wait_ns is all of begin_frame: those two waits, resetting the slot's
 * pools and the stats callback of the completed frame. frame_ns spans
 * begin_frame to the end of end_frame plus the update, so it holds work,
 * waiting and whatever the application did in between. A slow GPU shows
 * in gpu_wait_ns and gpu_ms, never in the work. */
typedef struct ob_frame_stats {
    uint64_t frame;              /* the frame's serial: ob_renderer_frame_serial() after its
                                    begin_frame; the first frame is 1 */
    ob_threading mode;
    uint32_t workers;            /* active workers (0 = single-threaded) */
    uint64_t update_ns, pre_render_ns, record_ns, assemble_ns, submit_ns, wait_ns, frame_ns;
    /* Parts of wait_ns (gpu_wait_ns: this slot's fence and the timestamps
     * of the frame it held; acquire_ns: the swapchain image, 0 headless)
     * and the present in end_frame (0 headless). */
    uint64_t gpu_wait_ns, acquire_ns, present_ns;
    double gpu_ms;
    uint32_t view_count;
    ob_view_stats views[OB_MAX_FRAME_VIEWS];
    uint32_t skipped_count;
    struct { char name[48]; ob_skip_reason reason; } skipped[OB_MAX_FRAME_VIEWS];
    uint32_t draws, culled;
    uint32_t lod_items;                        /* the views' lod_items, summed */
    ob_pipeline_manager_stats pm;              /* summed over every manager */
    /* CPU time (CLOCK_THREAD_CPUTIME_ID) each thread spent recording this
     * frame: [0] the render thread (inline recording or its share of the
     * jobs, plus assembling the primary), [i] pool worker i. Shows the work
     * apart from scheduling: on a loaded machine wall time grows, this not. */
    uint64_t record_cpu_ns[OB_MAX_WORKERS + 1];
    /* Host allocations the driver made through the command pools'
     * allocation callbacks while this frame was recorded, all threads. */
    uint64_t cmd_host_allocs;
    /* Bytes of uniform and per-instance blocks copied to device-local
     * memory this frame (a staged ring, ob_renderer_desc.ring_staging); 0
     * unstaged. */
    uint64_t ring_upload_bytes;
    /* CPU time (CLOCK_THREAD_CPUTIME_ID) of the frame's CPU phases, from the
     * update (when made through ob_renderer_update_scene) to the submission:
     * cpu_render_ns on the render thread in all, cpu_render_parallel_ns the
     * part of it inside parallel sections (parallel update, culling, the
     * jobs it records itself), cpu_pool_ns the pool threads' (all of it in
     * parallel sections). The serial part is cpu_render_ns -
     * cpu_render_parallel_ns; the frame's total cpu_render_ns + cpu_pool_ns. */
    uint64_t cpu_render_ns, cpu_render_parallel_ns, cpu_pool_ns;
    /* The update's part of each of the three (0 without an update through
     * ob_renderer_update_scene before this frame's begin_frame). */
    uint64_t update_cpu_render_ns, update_cpu_render_parallel_ns, update_cpu_pool_ns;
    uint32_t pipelines_created, variants_created;
    /* Point and spot lights that lit nothing this frame because the scene
     * has more than OB_MAX_LIGHTS (each is also logged once by name). */
    uint32_t lights_over_limit;
    uint64_t frame_hash;         /* all view hashes in order */
    /* Failures this frame met and went on without (the frame still ran,
     * without what failed): a view not made, resized or culled, a material
     * whose effect variant or pipeline could not be made. Each is logged
     * naming the view, entity or material, listed in skipped[] with
     * OB_SKIP_ERROR, and counted here; first_error is the result of the
     * first that came with one (ob_renderer_note_error; OB_OK when none
     * did). A program that must not show a degraded picture checks these
     * after end_frame (ob_views_render and ob_stack_frame return
     * first_error). */
    uint32_t errors;
    ob_result first_error;
} ob_frame_stats;

/* Creates the device (or adopts the application's: desc.device.adopt), the
 * parameter registry, the frame slots and the workers. Failure: NULL,
 * *out_result set, the cause logged, everything created so far destroyed. */
ob_renderer *ob_renderer_create(const ob_renderer_desc *desc, ob_result *out_result);
/* Waits idle, detaches the surface, stops and joins the workers, destroys
 * everything it created (never adopted Vulkan objects). NULL ok. */
void ob_renderer_destroy(ob_renderer *r);

ob_device *ob_renderer_device(ob_renderer *r);
/* How instance runs are drawn: desc.instance_runs resolved for the device
 * (never AUTO). */
ob_instance_runs ob_renderer_instance_runs(const ob_renderer *r);
ob_param_registry *ob_renderer_registry(ob_renderer *r);
/* The immediate parameter manager (slot 0). */
ob_params *ob_renderer_params(ob_renderer *r);
uint32_t ob_renderer_worker_count(const ob_renderer *r);

/* Takes effect at the next begin_frame. active_workers 0 (or more than the
 * pool has) → all. A mode outside ob_threading is refused
 * (OB_ERR_INVALID_ARGUMENT, logged; the pending mode is unchanged). */
ob_result ob_renderer_set_threading(ob_renderer *r, ob_threading mode, uint32_t active_workers);
ob_threading ob_renderer_get_threading(const ob_renderer *r);

/* Waits for this frame slot's fence, collects its GPU timings, resets its
 * pools and rings, applies a pending mode change. */
ob_result ob_renderer_begin_frame(ob_renderer *r, ob_scene *scene);
ob_scene *ob_renderer_scene(ob_renderer *r);
uint64_t ob_renderer_frame_serial(const ob_renderer *r);

/* Record every queued view (dependencies first) and submit. */
ob_result ob_renderer_process_views(ob_renderer *r);

/* Deepest PreRender nesting queued (a view pre-rendered by a view ...
 * `depth` levels down); deeper views are left out with OB_SKIP_RECURSION in
 * the stats. Default 4; at most OB_MAX_VIEW_STACK - 2 (30, engine/
 * ob_renderer_internal.h), larger values are clamped. [render thread] */
void ob_renderer_set_max_recursion(ob_renderer *r, uint32_t depth);

/* Time the application spent updating the scene, for the stats (a program
 * that calls ob_scene_update itself; ob_renderer_update_scene notes its own). */
void ob_renderer_note_update_ns(ob_renderer *r, uint64_t ns);

/* ob_scene_update(s, dt) on the renderer's worker pool: controllers that
 * declared themselves parallel-safe, world transforms and bounds, and the
 * snapshot run in chunks on the pool threads and the render thread; other
 * controllers on the render thread, in the order ob_scene_update runs them.
 * The result is exactly ob_scene_update's. It follows the threading mode the
 * next begin_frame applies (single-threaded: all on the calling thread).
 * Call it before begin_frame: its wall time and CPU time are that frame's
 * update figures (ob_frame_stats.update_ns, cpu_*). [render thread] */
ob_result ob_renderer_update_scene(ob_renderer *r, ob_scene *s, double dt);

/* The figures of the last ob_renderer_update_scene: wall time, and CPU
 * time as in ob_frame_stats (render thread, its part in parallel loops,
 * pool threads). */
typedef struct ob_update_stats {
    uint64_t ns, cpu_render_ns, cpu_render_parallel_ns, cpu_pool_ns;
} ob_update_stats;
void ob_renderer_last_update_stats(const ob_renderer *r, ob_update_stats *out);

/* Called with each frame's final stats (GPU times included) once the frame
 * is known complete, in frame order, exactly once per submitted frame.
 * Completion is learnt from the frame slot's fence, so the call comes late:
 * the stats of frame N (stats->frame == N) arrive from inside the
 * begin_frame of frame N + frames_in_flight (2 frames late by default,
 * ob_device_frames_in_flight), when that frame reuses N's slot, or from
 * ob_renderer_wait_idle (and so ob_renderer_destroy) for the last frames.
 * During a call from begin_frame, ob_renderer_frame_serial() is still the
 * newest frame submitted, N + frames_in_flight - 1. The same lag holds for
 * ob_renderer_last_stats. [render thread] */
typedef void (*ob_frame_stats_fn)(void *user, const ob_frame_stats *stats);
void ob_renderer_set_stats_callback(ob_renderer *r, ob_frame_stats_fn fn, void *user);
/* The two sums of ob_frame_stats' times (see there): the engine's CPU work
 * and the waiting for the GPU, a swapchain image and the present. [any thread] */
uint64_t ob_frame_stats_cpu_work_ns(const ob_frame_stats *stats);
uint64_t ob_frame_stats_wait_ns(const ob_frame_stats *stats);

/* Completes the frame: records and submits it if process_views did not,
 * then presents it when a surface is attached. A failure to record or
 * submit is returned first; a present that fails for good (surface or
 * device lost) returns its error; out of date is no error. */
ob_result ob_renderer_end_frame(ob_renderer *r);
/* Waits for all submitted frames; their stats (with GPU times) become final. */
ob_result ob_renderer_wait_idle(ob_renderer *r);
/* Stats of the most recent frame whose GPU work is known complete: frames_in_flight
 * frames behind the one being recorded (see the stats callback). */
const ob_frame_stats *ob_renderer_last_stats(const ob_renderer *r);
/* Stats of the frame just submitted (CPU parts final, GPU times pending). */
const ob_frame_stats *ob_renderer_current_stats(const ob_renderer *r);

/* ---- presenting ------------------------------------------------------
 * The application creates the window and its VkSurfaceKHR on the renderer's
 * instance (ob_device_vk_instance; the instance needs the surface
 * extensions: ob_device_desc.instance_extensions) and keeps owning it: it
 * calls ob_renderer_detach_surface (or ob_renderer_destroy) before
 * destroying the surface. The device needs VK_KHR_swapchain
 * (ob_device_desc.swapchain). */
typedef struct ob_surface_desc {
    VkSurfaceKHR surface;
    /* The window's size in pixels, used where the surface takes its size
     * from the swapchain (Wayland); X11 and Win32 surfaces say their own.
     * Keep it current with ob_renderer_surface_resized. */
    uint32_t width, height;
    /* false: FIFO (waits for vertical blank); true: MAILBOX, else
     * IMMEDIATE, where the surface offers them. */
    bool no_vsync;
} ob_surface_desc;
/* Checks that the device's queue can present to the surface and picks a
 * format (B8G8R8A8 or R8G8B8A8 UNORM where offered) and mode; the
 * swapchain comes with the next begin_frame. Failure: an error result
 * (OB_ERR_UNSUPPORTED naming what is missing, OB_ERR_WRONG_STATE inside a
 * frame or with a surface already attached), logged, nothing attached.
 * [render thread, between frames] */
ob_result ob_renderer_attach_surface(ob_renderer *r, const ob_surface_desc *desc);
/* Waits idle and destroys the swapchain and its semaphores; the surface
 * stays the application's. No-op without one. [render thread, between frames] */
void ob_renderer_detach_surface(ob_renderer *r);
/* The window was resized (to width x height pixels; 0x0 when minimised):
 * the swapchain is rebuilt at the next begin_frame. Optional where the
 * surface reports its size (it is queried every frame). [render thread] */
void ob_renderer_surface_resized(ob_renderer *r, uint32_t width, uint32_t height);
typedef struct ob_present_stats {
    uint32_t presented;          /* frames shown */
    uint32_t skipped;            /* frames not shown: minimised, out of date, not submitted */
    uint32_t swapchains;         /* swapchains created (1 + rebuilds) */
    uint32_t width, height;      /* of the current swapchain (0x0: none) */
} ob_present_stats;
/* Counts since the surface was attached; all zero when headless. */
ob_present_stats ob_renderer_present_stats(const ob_renderer *r);

#endif /* OB_RENDERER_H */
