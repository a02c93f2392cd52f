/* ob_renderer_internal.h — renderer state shared by its implementation files
 * (ob_renderer.c: frame and queue; ob_renderer_record.c: jobs, workers and the
 * primary). Not part of the API. */
#ifndef OB_RENDERER_INTERNAL_H
#define OB_RENDERER_INTERNAL_H

#include <pthread.h>
#include <semaphore.h>
#include <stdatomic.h>

#include "ob_auto_internal.h"
#include "ob_renderer_layer.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

#define OB_MAX_VIEW_STACK 32

/* A thread's block of a parallel loop's indices, [next, end) packed as
 * next | end << 32: its owner takes from the front, a thread whose own
 * block is empty from the back. One cache line each: the owner's takes
 * stay in its own cache. */
typedef struct ob_task_block {
    _Alignas(64) atomic_ullong range;
} ob_task_block;

/* One unit of recording: a chunk of one layer of one view. */
typedef struct ob_job {
    ob_view *view;
    uint32_t view_index;        /* position in processing order */
    uint32_t layer, first, count;
    uint64_t predicted_ns;
    VkCommandBuffer cmd;        /* secondary, filled by the worker */
    ob_cmd_hash hash;
    ob_pipeline_manager_stats stats;
    uint64_t record_ns;
    int32_t worker;
    uint32_t home;              /* the recording thread it goes to first (record_batch) */
    atomic_bool taken;          /* claimed by a recording thread this frame */
} ob_job;

/* Worker i's recording state: pipeline manager i (parameter slot i), a
 * command pool per frame slot and its secondaries. A batch of worker i is
 * recorded by pool thread i, or, for the last active worker, by the render
 * thread itself (it would otherwise sleep while the others record). Only the
 * thread recording a batch touches this state; batches are handed over
 * by hand_out (a ticket the thread polls for, a semaphore once it sleeps),
 * so one thread at a time. */
typedef struct ob_worker {
    ob_renderer *renderer;
    pthread_t thread;
    bool started;
    /* Handing it a batch (see hand_out): the render thread bumps ticket;
     * the thread spins on it a while after each batch, then sleeps on go,
     * which is posted only when it says it sleeps. */
    atomic_uint ticket;         /* batches handed to it, and the quit */
    atomic_int sleeping;        /* 1: about to wait, or waiting, on go */
    uint32_t seen;              /* tickets it took (its own thread only) */
    atomic_uint gen;            /* the batch its last ticket was for (batch_state's) */
    uint32_t gen_taken;         /* the last batch it looked at (its own thread only) */
    sem_t go;
    bool go_ready;
    uint32_t index;             /* 1-based: parameter slot and pair index */
    ob_pipeline_manager *pm;
    VkCommandPool pools[OB_MAX_FRAMES_IN_FLIGHT];
    bool pool_recorded[OB_MAX_FRAMES_IN_FLIGHT]; /* holds commands: reset before its next use */
    VkCommandBuffer *cmds[OB_MAX_FRAMES_IN_FLIGHT];
    uint32_t cmd_count[OB_MAX_FRAMES_IN_FLIGHT], cmd_cap[OB_MAX_FRAMES_IN_FLIGHT];
    uint32_t cmd_used;
    uint64_t cpu_ns;            /* thread CPU time of its last batch (jobs or loop indices) */
    ob_arena_allocator alloc[OB_MAX_FRAMES_IN_FLIGHT];  /* one per pool */
    int cpu;                    /* the CPU it is pinned to; -1 = none yet */
    ob_result error;
} ob_worker;

typedef struct ob_frame_slot {
    VkCommandPool pool;
    ob_arena_allocator alloc;   /* the pool's */
    VkCommandBuffer primary;
    /* A staged ring's: the copies of the pipeline managers' rings to the
     * device-local buffers the draws read, submitted before primary (it
     * also holds the frame's first timestamp, so that the GPU time counts
     * the copies). NULL when the ring is not staged. */
    VkCommandBuffer upload;
    VkFence fence;
    VkQueryPool queries;
    uint32_t query_capacity;
    bool pending;               /* submitted, stats not yet collected */
    bool unsubmitted;           /* the fence was reset but the submission failed */
    uint32_t view_queries;      /* views with timestamps in the pending frame */
    ob_frame_stats stats;
} ob_frame_slot;

/* An image's tracked state before the frame's first barrier on it: restored
 * when the frame is not submitted, so the tracking matches the GPU again. */
typedef struct ob_image_undo {
    ob_image img;
    ob_image_state before;
} ob_image_undo;
#define OB_MAX_FRAME_IMAGES (4 * OB_MAX_FRAME_VIEWS)

typedef struct ob_present ob_present;

/* A view whose pre_cull has run and whose culling and post_cull wait for
 * its wave: the PreRender chain that queued it, itself included, to be
 * current again for post_cull. */
typedef struct ob_pending_cull {
    ob_view *view;
    uint32_t depth;
    ob_view *stack[OB_MAX_VIEW_STACK];
} ob_pending_cull;

typedef struct ob_attachment {
    uint32_t node_id;
    ob_view *view;
} ob_attachment;

struct ob_renderer {
    ob_device *dev;
    ob_param_registry *reg;
    ob_params params0;
    ob_pipeline_manager *immediate;
    ob_worker workers[OB_MAX_WORKERS];
    uint32_t worker_count;
    int cpus[64];               /* the CPUs the process may run on (at start) */
    uint32_t cpu_count;
    bool no_affinity;           /* desc.no_thread_affinity */
    ob_gpu_timing gpu_timing;   /* desc.gpu_timing */
    bool ring_staged;           /* desc.ring_staging resolved for the device */
    ob_instance_runs instance_runs;  /* desc.instance_runs resolved (never AUTO) */
    uint32_t chunk_draws;
    uint32_t parallel_grain;    /* desc.parallel_grain (0: each loop's own) */

    ob_frame_slot frames[OB_MAX_FRAMES_IN_FLIGHT];
    uint32_t frames_in_flight, slot;
    uint64_t serial;
    bool in_frame, submitted;

    ob_threading mode, pending_mode;
    uint32_t active, pending_active;
    bool auto_multi;            /* AUTO's way for this frame (a probe or its choice) */
    uint32_t auto_workers;      /* and its worker count when that is the workers */
    ob_auto_state auto_state;
    /* Measured recording cost (wall time from the start of recording to the
     * primary's end) of each way of recording this scene, [0] inline and [1]
     * with the active workers: a moving average over the frames recorded
     * that way (in any mode), with the draw count it was measured at and the
     * frames since. AUTO records the cheaper way and re-measures the other
     * when it is stale or the scene has changed size. */
    ob_record_cost measured[OB_MAX_WORKERS + 1]; /* [0] inline, [n] on n workers */

    ob_material_iface material_iface;
    ob_geometry_iface geometry_iface;
    bool has_material_iface, has_geometry_iface;
    ob_scene *scene;

    ob_view *queue[OB_MAX_FRAME_VIEWS];
    int32_t queued_by[OB_MAX_FRAME_VIEWS]; /* queue index of the view whose PreRender
                                              queued each one; -1 for a root */
    uint32_t queue_count;
    ob_view *stack[OB_MAX_VIEW_STACK];
    uint32_t stack_depth, max_recursion;
    /* PreRender in waves (ob_view_vtbl.pre_cull): the views waiting for the
     * next wave's culling, and the one being finished. */
    ob_pending_cull wave[OB_MAX_FRAME_VIEWS];
    uint32_t wave_count;
    ob_pending_cull current_wave[OB_MAX_FRAME_VIEWS];
    bool flushing;
    ob_attachment *attachments;
    uint32_t attachment_count, attachment_cap;

    ob_job *jobs;
    uint32_t job_count, job_cap;

    ob_image_undo undo[OB_MAX_FRAME_IMAGES];
    uint32_t undo_count;
    bool undo_overflow;

    /* The parallel loop being run (ob_renderer_parallel): a pool thread
     * woken while task_fn is set runs loop indices instead of jobs. The
     * indices are cut into one contiguous block per thread of the loop
     * (task_blocks), its home: see run_tasks. */
    ob_task_fn task_fn;
    ob_idle_fn task_idle;       /* the loop's help after its indices, or NULL */
    void *task_user;
    uint32_t task_block_count;
    ob_task_block task_blocks[OB_MAX_WORKERS + 1];
    bool in_parallel;           /* a loop is running: a nested one runs inline */
    /* Whether a batch went to the pool threads since begin_frame, and
     * whether the last frame sent any (then the next wakes them early:
     * ob_renderer_workers_nudge). */
    bool handed_out, frame_used_pool;
    /* Where the CPU time of parallel sections is added: the frame's stats,
     * or the pending update's before begin_frame. */
    uint64_t *acc_render_parallel, *acc_pool;
    uint64_t frame_cpu0;        /* render thread CPU at begin_frame */
    /* ob_renderer_update_scene's figures, for the next begin_frame. */
    struct {
        bool valid;
        uint64_t ns, cpu_render, cpu_render_parallel, cpu_pool;
    } update;

    /* A batch's end: each pool thread adds one to finished; the render
     * thread spins on it a while, then sleeps on done, posted only when
     * it says it waits. */
    atomic_uint finished;
    atomic_int waiting;
    /* The batch being handed out: its number (high 32 bits), whether it is
     * closed (BATCH_CLOSED) and how many pool threads joined it (the low
     * bits). A pool thread joins only an open batch; the render thread
     * closes it once its own share is done and waits for the joined
     * ones alone, so a thread still waking up costs the render thread
     * nothing when the work is already done. */
    atomic_ullong batch_state;
    uint32_t batch_gen;
    sem_t done;
    bool done_ready;
    atomic_bool quit;           /* read by a pool thread on any ticket, joined or not */
    atomic_bool hold_awake;     /* pool threads poll on past POOL_SPIN_NS (see run_jobs) */

    ob_present *present;        /* the attached surface's swapchain; NULL = headless */

    ob_frame_stats_fn stats_fn;
    void *stats_user;
    ob_frame_stats cur;         /* being built */
    ob_frame_stats last;        /* complete, with GPU times */
    uint64_t frame_start_ns;
};

/* ob_renderer_record.c */
/* The threads a parallel loop gets now: 1 single-threaded, else the active
 * workers (the pending mode's outside a frame). */
uint32_t ob_renderer_parallel_threads(const ob_renderer *r);
ob_result ob_renderer_workers_start(ob_renderer *r);
/* Wakes pool threads 1..threads-1 that sleep, without a batch: they poll
 * for one as after a batch, so that the next hand-out finds them awake. */
void ob_renderer_workers_nudge(ob_renderer *r, uint32_t threads);
void ob_renderer_workers_stop(ob_renderer *r);
ob_result ob_renderer_record_frame(ob_renderer *r, ob_view **order, uint32_t count);
/* Keep img's tracked state from before this frame's first barrier on it, so
 * a frame that is not submitted can put it back. */
void ob_renderer_note_image_state(ob_renderer *r, ob_image img);

/* ob_renderer_present.c — each a no-op without an attached surface.
 * begin_frame: acquire this frame's image (none when minimised). */
ob_result ob_renderer_present_acquire(ob_renderer *r);
/* End of the primary: the present image into the acquired image, to PRESENT_SRC. */
void ob_renderer_present_record(ob_renderer *r, VkCommandBuffer cmd);
/* The frame's submission: the wait on the acquire and the signal for the
 * present (returns 1, or 0 with nothing to add); then whether it was
 * submitted. */
uint32_t ob_renderer_present_sync(ob_renderer *r, VkSemaphoreSubmitInfo *out_wait,
                                  VkSemaphoreSubmitInfo *out_signal);
void ob_renderer_present_submitted(ob_renderer *r, bool submitted);
/* end_frame: queue the present of a submitted frame. */
ob_result ob_renderer_present_queue(ob_renderer *r);

#pragma GCC visibility pop

#endif /* OB_RENDERER_INTERNAL_H */
