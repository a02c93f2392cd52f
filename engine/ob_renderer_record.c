#define _GNU_SOURCE
#include "ob_renderer_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ worker pool */

static ob_result worker_init(ob_renderer *r, ob_worker *w, uint32_t index)
{
    ob_result res;
    w->renderer = r;
    w->index = index;
    w->cpu = -1;
    atomic_init(&w->ticket, 0u);
    atomic_init(&w->gen, 0u);
    atomic_init(&w->sleeping, 0);
    w->seen = 0;
    w->gen_taken = 0;
    for (uint32_t f = 0; f < OB_MAX_FRAMES_IN_FLIGHT; f++) ob_arena_allocator_init(&w->alloc[f]);
    if (sem_init(&w->go, 0, 0) != 0) {
        OB_LOG_E("renderer", "worker %u: its wake-up semaphore cannot be created", index);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    w->go_ready = true;
    char name[32];
    snprintf(name, sizeof name, "worker%u", index);
    ob_pipeline_manager_desc pmd = {
        .device = r->dev,
        .registry = r->reg,
        .slot = index,
        .frames_in_flight = r->frames_in_flight,
        .name = name,
        .staged = r->ring_staged,
        .runs = r->instance_runs,
    };
    w->pm = ob_pipeline_manager_create(&pmd, &res);
    if (!w->pm) return res;
    for (uint32_t f = 0; f < r->frames_in_flight; f++) {
        VkCommandPoolCreateInfo pci = {
            .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
            .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
            .queueFamilyIndex = ob_device_queue_family(r->dev),
        };
        VkResult vr = OB_VK_CHECK_CREATE(vkCreateCommandPool(ob_device_vk(r->dev), &pci,
                                                             &w->alloc[f].callbacks, &w->pools[f]));
        if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    }
    return OB_OK;
}

static void worker_release(ob_renderer *r, ob_worker *w)
{
    for (uint32_t f = 0; f < OB_MAX_FRAMES_IN_FLIGHT; f++) {
        if (w->pools[f])
            vkDestroyCommandPool(ob_device_vk(r->dev), w->pools[f], &w->alloc[f].callbacks);
        ob_arena_allocator_release(&w->alloc[f]);
        ob_free(w->cmds[f]);
    }
    ob_pipeline_manager_destroy(w->pm);
    if (w->go_ready) sem_destroy(&w->go);
    memset(w, 0, sizeof *w);
}

/* Next secondary command buffer of this worker for the current frame slot
 * (allocated once, reused every time the slot comes round). The frame's
 * first buffer resets the slot's pool, on the thread that records into it:
 * lavapipe walks every command the pool holds to free it (some 40 us a
 * worker at 8 views x 10k objects), so each recording thread pays for its
 * own. (Reset ahead by the pool threads in begin_frame, the resets made
 * them join PreRender's culling wave 50-250 us late on the 2-core VM.)
 * The slot's fence was waited for in begin_frame, so nothing in it is pending. On failure
 * returns VK_NULL_HANDLE with *out_result set and logged. */
static VkCommandBuffer worker_next_cmd(ob_renderer *r, ob_worker *w, ob_result *out_result)
{
    uint32_t f = r->slot;
    *out_result = OB_OK;
    if (w->cmd_used == 0 && w->pool_recorded[f]) {
        VkResult vr = OB_VK_CHECK(vkResetCommandPool(ob_device_vk(r->dev), w->pools[f], 0));
        if (vr != VK_SUCCESS) {
            ob_device_note_result(r->dev, vr);
            *out_result = ob_result_from_vk(vr);
            return VK_NULL_HANDLE;
        }
        w->pool_recorded[f] = false;
    }
    if (w->cmd_used >= w->cmd_count[f]) {
        *out_result = ob_array_reserve((void **)&w->cmds[f], &w->cmd_cap[f], w->cmd_count[f] + 1,
                                       sizeof(VkCommandBuffer));
        if (*out_result != OB_OK) {
            OB_LOG_E("renderer", "worker %u: its list of secondary command buffers cannot grow "
                     "past %u: %s", w->index, w->cmd_count[f], ob_result_name(*out_result));
            return VK_NULL_HANDLE;
        }
        VkCommandBufferAllocateInfo ai = {
            .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
            .commandPool = w->pools[f],
            .level = VK_COMMAND_BUFFER_LEVEL_SECONDARY,
            .commandBufferCount = 1,
        };
        VkCommandBuffer cmd;
        VkResult vr = OB_VK_CHECK_CREATE(vkAllocateCommandBuffers(ob_device_vk(r->dev), &ai, &cmd));
        if (vr != VK_SUCCESS) {
            ob_device_note_result(r->dev, vr);
            *out_result = ob_result_from_vk(vr);
            return VK_NULL_HANDLE;
        }
        w->cmds[f][w->cmd_count[f]++] = cmd;
    }
    w->pool_recorded[f] = true;
    return w->cmds[f][w->cmd_used++];
}

/* The per-view parameters a recording of v needs in a manager's slot. */
static void set_view_params(ob_renderer *r, ob_view *v, ob_pipeline_manager *pm)
{
    ob_params *params = ob_pipeline_manager_params(pm);
    if (v->vtbl->set_render_params) v->vtbl->set_render_params(v, r, params);
    for (uint32_t i = 0; i < v->dep_count; i++) {
        ob_view *d = v->deps[i];
        if (d->vtbl->set_usage_params) d->vtbl->set_usage_params(d, r, params, v);
    }
    if (v->layer_count > 0) {
        ob_pipeline_manager_set_viewport(pm, 0.0f, 0.0f, (float)v->width, (float)v->height);
        ob_pipeline_manager_set_scissor(pm, 0, 0, v->width, v->height);
    }
}

static void record_job(ob_renderer *r, ob_worker *w, ob_job *job)
{
    ob_view *v = job->view;
    uint64_t t0 = ob_time_ns();
    job->worker = (int32_t)w->index;
    ob_result res;
    job->cmd = worker_next_cmd(r, w, &res);
    if (!job->cmd) {
        OB_LOG_E("renderer", "view '%s' (layer %u, items %u..%u) not recorded by worker %u: %s",
                 v->name, job->layer, job->first, job->first + job->count, w->index,
                 ob_result_name(res));
        w->error = res;
        return;
    }
    VkFormat color, depth;
    uint32_t samples;
    ob_view_attachment_formats(v, r->dev, &color, &depth, &samples);
    VkCommandBufferInheritanceRenderingInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO,
        .colorAttachmentCount = color != VK_FORMAT_UNDEFINED ? 1u : 0u,
        .pColorAttachmentFormats = &color,
        .depthAttachmentFormat = depth,
        .rasterizationSamples = (VkSampleCountFlagBits)samples,
    };
    bool graphics = v->layer_count > 0;
    VkCommandBufferInheritanceInfo inherit = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO,
        .pNext = graphics ? &rendering : NULL,
    };
    VkCommandBufferBeginInfo bi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT |
                 (graphics ? VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT : 0u),
        .pInheritanceInfo = &inherit,
    };
    if (OB_VK_CHECK(vkBeginCommandBuffer(job->cmd, &bi)) != VK_SUCCESS) {
        w->error = OB_ERR_VULKAN;
        job->cmd = VK_NULL_HANDLE;
        return;
    }
    ob_pipeline_manager_begin(w->pm, job->cmd);
    set_view_params(r, v, w->pm);
    v->vtbl->record(v, r, w->pm, job->layer, job->first, job->count);
    job->hash = ob_pipeline_manager_end(w->pm);
    job->stats = ob_pipeline_manager_stats_take(w->pm);
    if (OB_VK_CHECK(vkEndCommandBuffer(job->cmd)) != VK_SUCCESS) {
        w->error = OB_ERR_VULKAN;
        job->cmd = VK_NULL_HANDLE;
    }
    job->record_ns = ob_time_ns() - t0;
}

/* Job j for the calling thread, unless another took it. */
static bool job_claim(ob_renderer *r, uint32_t j)
{
    return !atomic_load_explicit(&r->jobs[j].taken, memory_order_relaxed) &&
           !atomic_exchange_explicit(&r->jobs[j].taken, true, memory_order_relaxed);
}

/* Worker w's share of the frame's jobs, recorded by the loop thread
 * `thread` (0: the render thread, i: pool thread i): first the jobs whose
 * home it is (the views whose culling it finished, so whose draw items its
 * caches hold) and those with none, biggest first (build_jobs sorted
 * them); then, from the smallest up, the ones left of the other threads'.
 * Taken from one shared list in cost order instead, each thread read half
 * its items from the other core. Runs on w's pool thread or on the render
 * thread. */
static void record_batch(ob_renderer *r, ob_worker *w, uint32_t thread)
{
    uint64_t c0 = ob_thread_cpu_ns();
    w->cmd_used = 0;
    uint32_t n = r->job_count;
    for (uint32_t j = 0; j < n; j++) {
        uint32_t home = r->jobs[j].home;
        if ((home == thread || home == OB_VIEW_NO_THREAD) && job_claim(r, j))
            record_job(r, w, &r->jobs[j]);
    }
    for (uint32_t j = n; j-- > 0;)
        if (job_claim(r, j)) record_job(r, w, &r->jobs[j]);
    w->cpu_ns = ob_thread_cpu_ns() - c0;
}

#define TASK_NONE UINT32_MAX

/* The next index of block b from its front (the owner's end), or
 * TASK_NONE once it is empty. */
static uint32_t task_take_front(ob_task_block *b)
{
    unsigned long long v = atomic_load_explicit(&b->range, memory_order_relaxed);
    for (;;) {
        uint32_t next = (uint32_t)v, end = (uint32_t)(v >> 32);
        if (next >= end) return TASK_NONE;
        if (atomic_compare_exchange_weak_explicit(&b->range, &v, v + 1, memory_order_relaxed,
                                                  memory_order_relaxed))
            return next;
    }
}

/* The last index of block b (a thread stealing from another's block). */
static uint32_t task_take_back(ob_task_block *b)
{
    unsigned long long v = atomic_load_explicit(&b->range, memory_order_relaxed);
    for (;;) {
        uint32_t next = (uint32_t)v, end = (uint32_t)(v >> 32);
        if (next >= end) return TASK_NONE;
        unsigned long long w = (unsigned long long)(end - 1) << 32 | next;
        if (atomic_compare_exchange_weak_explicit(&b->range, &v, w, memory_order_relaxed,
                                                  memory_order_relaxed))
            return end - 1;
    }
}

static inline void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield" ::: "memory");
#endif
}

/* Indices of the running parallel loop. `thread` is the caller's loop
 * thread number (0 = the render thread, pool thread i is i), which is also
 * its home block: the same share of every loop's indices, frame after
 * frame. The update's loops cut the entities in id order, so a thread
 * updates, next frame, the entities whose data its own caches hold; the
 * culling wave numbers its chunks view by view, so a thread culls and
 * sorts whole views (ob_view.c's cull_wave). Taken first
 * come, first served, an index went to either thread, and each entity's
 * lines moved between the cores: on the 2-core VM while its cores were far
 * apart (a cache line's round trip 450-500 ns), the update at 8 views x
 * 10k took 0.30 ms on two threads against 0.39 on one; with home blocks
 * 0.24 (medians of interleaved runs, docs/benchmark.md session 23). A
 * thread done with its block takes from the back of the others', so a
 * late or slow thread's share still spreads as before. */
static void run_tasks(ob_renderer *r, uint32_t thread)
{
    uint32_t blocks = r->task_block_count;
    uint32_t home = thread % blocks;
    for (uint32_t i; (i = task_take_front(&r->task_blocks[home])) != TASK_NONE;)
        r->task_fn(r->task_user, i, thread);
    for (uint32_t k = 1; k < blocks; k++) {
        ob_task_block *b = &r->task_blocks[(home + k) % blocks];
        for (uint32_t i; (i = task_take_back(b)) != TASK_NONE;) r->task_fn(r->task_user, i, thread);
    }
    if (r->task_idle)
        while (r->task_idle(r->task_user, thread)) cpu_relax();
}

/* How long a pool thread polls for its next batch, and the render thread
 * for the end of one, before sleeping on a semaphore. A frame's hand-outs
 * (the update's levels, the culling waves, recording) come tens of
 * microseconds apart, and waking a thread that sleeps costs some 30-50 us
 * on a 2-core VM, as much as a hand-out's whole work at 10k objects: a
 * thread that polls takes the next batch at once. A batch that does not
 * come costs at most this much CPU before the thread sleeps. */
#define POOL_SPIN_NS 100000u

/* How long at most a pool thread polls while the render thread holds the
 * pool awake (ob_renderer.hold_awake), in case it never lets go. */
#define POOL_HOLD_MAX_NS 2000000u

/* Polls until *v != old, for at most POOL_SPIN_NS, longer while *hold is
 * set (up to POOL_HOLD_MAX_NS; hold may be NULL); true when it changed. */
static bool spin_while_equal(atomic_uint *v, unsigned old, const atomic_bool *hold)
{
    uint64_t t0 = 0;
    for (uint32_t k = 0;; k++) {
        if (atomic_load_explicit(v, memory_order_acquire) != old) return true;
        if ((k & 63u) == 0) {
            uint64_t t = ob_time_ns();
            if (k == 0) t0 = t;
            else if (t - t0 > POOL_SPIN_NS &&
                     (!hold || !atomic_load_explicit(hold, memory_order_relaxed) ||
                      t - t0 > POOL_HOLD_MAX_NS))
                return false;
        }
        cpu_relax();
    }
}

/* Sleeping on a semaphore without missing a post or leaving one behind:
 * the sleeper says so in *flag (1) and looks at the condition again; the
 * waker changes the condition (or, nudging, leaves it), then posts only
 * when it is the one to take the flag back (1 -> 0). Both sides are
 * sequentially consistent, so at least one of them sees the other's write;
 * when both do, exactly one takes the flag, and a sleeper that loses it
 * takes the post. One sleep: true when *v changed, false when a nudge woke
 * it with *v as it was. */
static bool sleep_once(atomic_uint *v, unsigned old, atomic_int *flag, sem_t *sem)
{
    atomic_store(flag, 1);
    if (atomic_load(v) != old) {
        int one = 1;
        if (!atomic_compare_exchange_strong(flag, &one, 0))
            while (sem_wait(sem) != 0) {} /* EINTR */
        return true;
    }
    while (sem_wait(sem) != 0) {} /* EINTR; the waker took the flag */
    return atomic_load(v) != old;
}

static void sleep_until_changed(atomic_uint *v, unsigned old, atomic_int *flag, sem_t *sem)
{
    while (!sleep_once(v, old, flag, sem)) {}
}

static void wake_sleeper(atomic_int *flag, sem_t *sem)
{
    int one = 1;
    if (atomic_load(flag) == 1 && atomic_compare_exchange_strong(flag, &one, 0)) sem_post(sem);
}

/* Gives worker w its next batch (or the quit), set up in r beforehand: a
 * ticket, which releases what was stored before it (gen, the quit). */
static void worker_wake(ob_worker *w, uint32_t gen)
{
    atomic_store_explicit(&w->gen, gen, memory_order_relaxed);
    atomic_fetch_add(&w->ticket, 1u);
    wake_sleeper(&w->sleeping, &w->go);
}

#define BATCH_CLOSED (1ull << 31)

/* Pool thread w joins the batch its ticket was for, unless it is closed
 * (the render thread finished it alone while w was waking up) or w already
 * took it (w read a later gen early: the render thread stores gen before
 * bumping the ticket, so w may see the next batch's gen on an earlier
 * ticket, and then that batch's own ticket finds it taken). */
static bool worker_join(ob_renderer *r, ob_worker *w)
{
    uint32_t gen = atomic_load_explicit(&w->gen, memory_order_relaxed);
    if (gen == w->gen_taken) return false;
    w->gen_taken = gen;
    unsigned long long s = atomic_load(&r->batch_state);
    while ((uint32_t)(s >> 32) == gen && !(s & BATCH_CLOSED))
        if (atomic_compare_exchange_weak(&r->batch_state, &s, s + 1)) return true;
    return false;
}

/* Worker w's wait for its next ticket: polls, then sleeps; a nudge
 * (ob_renderer_workers_nudge) sends it back to polling. */
static void worker_wait(ob_worker *w)
{
    while (!spin_while_equal(&w->ticket, w->seen, &w->renderer->hold_awake))
        if (sleep_once(&w->ticket, w->seen, &w->sleeping, &w->go)) break;
    w->seen++;
}

void ob_renderer_workers_nudge(ob_renderer *r, uint32_t threads)
{
    for (uint32_t i = 0; i + 1 < threads && i < r->worker_count; i++)
        if (r->workers[i].started) wake_sleeper(&r->workers[i].sleeping, &r->workers[i].go);
}

/* A pool thread's batch is done (its results written before). */
static void worker_finished(ob_renderer *r)
{
    atomic_fetch_add(&r->finished, 1u);
    wake_sleeper(&r->waiting, &r->done);
}

/* The render thread's wait until `count` pool threads finished the batch
 * handed out after finished was reset. */
static void wait_finished(ob_renderer *r, unsigned count)
{
    for (;;) {
        unsigned now = atomic_load_explicit(&r->finished, memory_order_acquire);
        if (now == count) return;
        if (!spin_while_equal(&r->finished, now, NULL))
            sleep_until_changed(&r->finished, now, &r->waiting, &r->done);
    }
}

static void *worker_main(void *arg)
{
    ob_worker *w = arg;
    ob_renderer *r = w->renderer;
    for (;;) {
        worker_wait(w);
        if (atomic_load_explicit(&r->quit, memory_order_relaxed)) break;
        if (!worker_join(r, w)) continue;
        if (r->task_fn) {
            uint64_t c0 = ob_thread_cpu_ns();
            run_tasks(r, w->index);
            w->cpu_ns = ob_thread_cpu_ns() - c0;
        } else {
            record_batch(r, w, w->index);
        }
        worker_finished(r);
    }
    return NULL;
}

uint32_t ob_renderer_parallel_threads(const ob_renderer *r)
{
    ob_threading mode = r->in_frame ? r->mode : r->pending_mode;
    uint32_t active = r->in_frame ? r->active : r->pending_active;
    if (mode == OB_THREADING_SINGLE || r->worker_count == 0) return 1;
    return OB_MAX(1u, OB_MIN(active, r->worker_count));
}

static void place_workers(ob_renderer *r, uint32_t helpers);

/* The hand-out both kinds of batch share (the frame's jobs, a parallel
 * loop's indices), set up in r beforehand: pool threads 1..helpers are
 * woken, the render thread runs own(r, arg) meanwhile, and the call returns
 * when all are done. The pool threads' CPU (their cpu_ns) and the render
 * thread's count as parallel in the frame's (or the update's) figures. */
static void hand_out(ob_renderer *r, uint32_t helpers, void (*own)(ob_renderer *r, void *arg),
                     void *arg)
{
    uint64_t c0 = ob_thread_cpu_ns();
    r->handed_out = true;
    place_workers(r, helpers);
    atomic_store_explicit(&r->finished, 0u, memory_order_relaxed); /* no batch runs now */
    uint32_t gen = ++r->batch_gen;
    if (gen == 0) gen = ++r->batch_gen; /* 0: no batch taken yet (gen_taken's start) */
    atomic_store(&r->batch_state, (unsigned long long)gen << 32);
    for (uint32_t i = 0; i < helpers; i++) worker_wake(&r->workers[i], gen);
    own(r, arg);
    /* The pool threads that did not join by now never will: the batch is
     * done without them, and their cpu_ns stays 0. */
    unsigned long long s = atomic_fetch_or(&r->batch_state, BATCH_CLOSED);
    wait_finished(r, (unsigned)(s & (BATCH_CLOSED - 1)));
    uint64_t pool = 0;
    for (uint32_t i = 0; i < helpers; i++) pool += r->workers[i].cpu_ns;
    if (r->acc_pool) *r->acc_pool += pool;
    if (r->acc_render_parallel) *r->acc_render_parallel += ob_thread_cpu_ns() - c0;
}

static void own_tasks(ob_renderer *r, void *arg)
{
    (void)arg;
    run_tasks(r, 0);
}

/* ob_parallel's run for the pool: pool threads 1..threads-1 (only as many as
 * there are indices) are woken, the render thread takes indices too, each
 * thread then helps through idle (when given) until it says there is
 * nothing more, and the call returns when every index is done. A loop
 * started from inside a loop, or from a pool thread, runs on the caller. */
static void pool_run_helped(void *ctx, uint32_t count, ob_task_fn fn, ob_idle_fn idle, void *user)
{
    ob_renderer *r = ctx;
    uint32_t threads = ob_renderer_parallel_threads(r);
    if (r->in_parallel || threads < 2 || count < 2) {
        for (uint32_t i = 0; i < count; i++) fn(user, i, 0);
        while (idle && idle(user, 0)) {}
        return;
    }
    uint32_t helpers = OB_MIN(threads - 1, count - 1);
    r->in_parallel = true;
    r->task_fn = fn;
    r->task_idle = idle;
    r->task_user = user;
    /* One block per thread that may join, in thread order; published by
     * hand_out's batch_state store. */
    uint32_t blocks = helpers + 1;
    r->task_block_count = blocks;
    for (uint32_t b = 0; b < blocks; b++) {
        unsigned long long first = (unsigned long long)count * b / blocks;
        unsigned long long end = (unsigned long long)count * (b + 1) / blocks;
        atomic_store_explicit(&r->task_blocks[b].range, end << 32 | first, memory_order_relaxed);
    }
    hand_out(r, helpers, own_tasks, NULL);
    r->task_fn = NULL;
    r->task_idle = NULL;
    r->in_parallel = false;
    /* Recording reads the workers' cpu_ns as its own: none left from here. */
    for (uint32_t i = 0; i < helpers; i++) r->workers[i].cpu_ns = 0;
}

static void pool_run(void *ctx, uint32_t count, ob_task_fn fn, void *user)
{
    pool_run_helped(ctx, count, fn, NULL, user);
}

ob_parallel ob_renderer_parallel(ob_renderer *r)
{
    return (ob_parallel){.run = pool_run, .ctx = r, .threads = ob_renderer_parallel_threads(r),
                         .grain = r->parallel_grain, .run_helped = pool_run_helped};
}

ob_result ob_renderer_workers_start(ob_renderer *r)
{
    /* The CPUs this process may run on (taskset, cgroups), for place_workers. */
    cpu_set_t allowed;
    r->cpu_count = 0;
    if (sched_getaffinity(0, sizeof allowed, &allowed) == 0)
        for (int c = 0; c < CPU_SETSIZE && r->cpu_count < OB_ARRAY_COUNT(r->cpus); c++)
            if (CPU_ISSET(c, &allowed)) r->cpus[r->cpu_count++] = c;
    atomic_init(&r->finished, 0u);
    atomic_init(&r->batch_state, 0ull);
    atomic_init(&r->quit, false);
    atomic_init(&r->hold_awake, false);
    atomic_init(&r->waiting, 0);
    if (sem_init(&r->done, 0, 0) != 0) {
        OB_LOG_E("renderer", "the workers' completion semaphore cannot be created");
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    r->done_ready = true;
    for (uint32_t i = 0; i < r->worker_count; i++) {
        ob_result res = worker_init(r, &r->workers[i], i + 1);
        if (res != OB_OK) return res;
    }
    for (uint32_t i = 0; i < r->worker_count; i++) {
        if (pthread_create(&r->workers[i].thread, NULL, worker_main, &r->workers[i]) != 0) {
            OB_LOG_E("renderer", "cannot start worker thread %u", i + 1);
            return OB_ERR_OUT_OF_HOST_MEMORY;
        }
        r->workers[i].started = true;
    }
    return OB_OK;
}

void ob_renderer_workers_stop(ob_renderer *r)
{
    atomic_store_explicit(&r->quit, true, memory_order_relaxed); /* the tickets below release it */
    for (uint32_t i = 0; i < r->worker_count; i++)
        if (r->workers[i].started) worker_wake(&r->workers[i], 0);
    for (uint32_t i = 0; i < r->worker_count; i++) {
        if (r->workers[i].started) pthread_join(r->workers[i].thread, NULL);
        worker_release(r, &r->workers[i]);
    }
    if (r->done_ready) sem_destroy(&r->done);
    r->done_ready = false;
}

/* Keep the pool threads about to be woken off the CPU the render thread is
 * recording on, each on its own CPU of the process's set where there are
 * enough. Left to itself the scheduler often wakes a worker onto the
 * waker's CPU and leaves the two sharing it for milliseconds while the other
 * CPU idles (seen here on 2 cores: one frame in two recorded at the speed of
 * one thread). Only the pool's own threads are pinned, never the caller's;
 * an affinity call is made only when a worker's CPU has to change. */
static void place_workers(ob_renderer *r, uint32_t helpers)
{
    if (r->no_affinity || r->cpu_count < 2) return;
    int here = sched_getcpu();
    uint32_t next = 0;
    for (uint32_t i = 0; i < helpers; i++) {
        ob_worker *w = &r->workers[i];
        int cpu = r->cpus[next++ % r->cpu_count];
        if (cpu == here) cpu = r->cpus[next++ % r->cpu_count];
        if (w->cpu == cpu) continue;
        cpu_set_t set;
        CPU_ZERO(&set);
        CPU_SET(cpu, &set);
        if (pthread_setaffinity_np(w->thread, sizeof set, &set) == 0) w->cpu = cpu;
    }
}

/* Hand the frame's jobs to the active workers and wait for all. Only the
 * pool threads that have a job to take are woken; the render thread records
 * the last active worker's share instead of sleeping. */
static void own_jobs(ob_renderer *r, void *worker) { record_batch(r, worker, 0); }

static void run_jobs(ob_renderer *r, uint32_t active)
{
    /* Held until the frame is submitted (ob_renderer_record_frame): a pool
     * thread that finished its share keeps polling through the rest of
     * the render thread's share, assembly and the submit. With that CPU
     * asleep, lavapipe's vkQueueSubmit2, waking its queue thread onto it,
     * took 42 us instead of 7 on the 2-core VM (medians at 8 views x 10k). */
    atomic_store_explicit(&r->hold_awake, true, memory_order_relaxed);
    for (uint32_t j = 0; j < r->job_count; j++) atomic_init(&r->jobs[j].taken, false);
    hand_out(r, OB_MIN(active - 1, r->job_count - 1), own_jobs, &r->workers[active - 1]);
}

/* ------------------------------------------------------------ jobs */

static int compare_jobs_by_cost(const void *a, const void *b)
{
    const ob_job *x = a, *y = b;
    if (x->predicted_ns != y->predicted_ns) return x->predicted_ns > y->predicted_ns ? -1 : 1;
    if (x->view_index != y->view_index) return x->view_index < y->view_index ? -1 : 1;
    if (x->layer != y->layer) return x->layer < y->layer ? -1 : 1;
    return (x->first > y->first) - (x->first < y->first);
}

/* Assembly order: view, layer, then position in the draw list. */
static int compare_jobs_in_view_order(const void *a, const void *b)
{
    const ob_job *x = *(const ob_job *const *)a, *y = *(const ob_job *const *)b;
    if (x->view_index != y->view_index) return x->view_index < y->view_index ? -1 : 1;
    if (x->layer != y->layer) return x->layer < y->layer ? -1 : 1;
    return (x->first > y->first) - (x->first < y->first);
}

/* A job is split in the tail only when each half keeps this many draws
 * (some 25-50 us of recording): below that a secondary's own cost eats
 * what the split saves. */
#define TAIL_SPLIT_MIN_DRAWS 256u

/* The frame's recording ends when the last job does, and jobs are handed
 * out biggest first, so the threads finish apart by up to the length of
 * the jobs taken last. Halving the 2 × active smallest jobs halves that
 * gap for a few more secondaries (seen on 10k objects x 8 views: 16 jobs of
 * ~0.18 ms, the two threads finishing ~0.1 ms apart). Order stays total:
 * the halves are ordered like any job, by cost, then view, layer, first. */
static ob_result split_tail(ob_renderer *r, uint32_t active)
{
    uint32_t tail = OB_MIN(2 * active, r->job_count), n = r->job_count;
    ob_result res = ob_array_reserve((void **)&r->jobs, &r->job_cap, n + tail, sizeof *r->jobs);
    if (res != OB_OK) return res;
    for (uint32_t i = n - tail; i < n; i++) {
        ob_job *j = &r->jobs[i];
        if (j->view->custom_record || j->view->layer_count == 0 || j->count < 2 * TAIL_SPLIT_MIN_DRAWS)
            continue;
        uint32_t half = j->count / 2;
        ob_job *k = &r->jobs[r->job_count++];
        *k = *j;
        k->first = j->first + half;
        k->count = j->count - half;
        k->predicted_ns = j->predicted_ns * k->count / j->count;
        j->predicted_ns -= k->predicted_ns;
        j->count = half;
    }
    if (r->job_count > n) qsort(r->jobs, r->job_count, sizeof *r->jobs, compare_jobs_by_cost);
    return OB_OK;
}

/* The smallest chunk a view is cut into when the renderer sizes jobs
 * itself, and the jobs per active thread it aims for. Each job costs some
 * 12 us on a 2-core VM before its draws: a secondary, the view's parameters
 * set again (3 us), and up to its first draw 8 us (pipeline, descriptors,
 * the 24 KiB PerView block with the light table packed and hashed). Fixed
 * 2048-draw chunks cut 10k objects x 8 views into 20 jobs for 2 threads, and
 * their jobs' work came to 14% over the single-threaded recording's (12
 * jobs: 7%). Four jobs a thread, handed out biggest first with the tail
 * halved (split_tail), keep the threads within a small job of each other. */
#define CHUNK_MIN_DRAWS 2048u
#define JOBS_PER_THREAD 4u

/* Draws per chunk for this frame: the renderer's chunk_draws when one was
 * given, otherwise the frame's draws (items times layers) over
 * JOBS_PER_THREAD per active thread, at least CHUNK_MIN_DRAWS. */
static uint32_t chunk_size(const ob_renderer *r, ob_view **order, uint32_t count, uint32_t active)
{
    if (r->chunk_draws) return r->chunk_draws;
    uint64_t draws = 0;
    for (uint32_t i = 0; i < count; i++)
        if (order[i]->layer_count && !order[i]->custom_record)
            draws += (uint64_t)order[i]->item_count * order[i]->layer_count;
    uint64_t per_job = draws / ((uint64_t)OB_MAX(active, 1u) * JOBS_PER_THREAD);
    return (uint32_t)OB_MIN(OB_MAX(per_job, (uint64_t)CHUNK_MIN_DRAWS), (uint64_t)UINT32_MAX);
}

/* Split views into jobs. A view is cut into chunks when it has many draws or
 * took long to record last time, so one big view does not serialise a frame. */
static ob_result build_jobs(ob_renderer *r, ob_view **order, uint32_t count, uint32_t active)
{
    r->job_count = 0;
    uint32_t chunk_draws = chunk_size(r, order, count, active);
    for (uint32_t i = 0; i < count; i++) {
        ob_view *v = order[i];
        uint32_t layers = v->layer_count ? v->layer_count : 1;
        bool compute = v->layer_count == 0;
        if (!compute && !v->custom_record && v->item_count == 0) continue;
        uint32_t chunks = 1;
        if (!compute && !v->custom_record) {
            /* A given size is a bound (ceil); a sized one a target
             * (nearest), so a view a little over it is not cut in two. */
            uint64_t bias = r->chunk_draws ? chunk_draws - 1u : chunk_draws / 2u;
            chunks = (uint32_t)OB_MAX(((uint64_t)v->item_count + bias) / chunk_draws, 1u);
            /* Slow views get up to two chunks per worker, never fewer than
             * the draw count asks for. */
            uint64_t by_cost = OB_MIN(v->cost_ns / (250u * 1000u * layers), (uint64_t)active * 2);
            if (by_cost > chunks) chunks = (uint32_t)by_cost;
            if (chunks > v->item_count) chunks = v->item_count;
            if (chunks == 0) chunks = 1;
        }
        uint64_t per_item = v->item_count ? v->cost_ns / ((uint64_t)v->item_count * layers) : 0;
        if (per_item == 0) per_item = 300;
        for (uint32_t l = 0; l < layers; l++) {
            for (uint32_t c = 0; c < chunks; c++) {
                uint32_t first = (uint32_t)((uint64_t)v->item_count * c / chunks);
                uint32_t end = (uint32_t)((uint64_t)v->item_count * (c + 1) / chunks);
                ob_result res = ob_array_reserve((void **)&r->jobs, &r->job_cap, r->job_count + 1,
                                                 sizeof *r->jobs);
                if (res != OB_OK) return res;
                r->jobs[r->job_count++] = (ob_job){
                    .view = v,
                    .view_index = i,
                    .layer = l,
                    .first = first,
                    .count = end - first,
                    .predicted_ns = (compute || v->custom_record) ? 20000 : per_item * (end - first),
                    .worker = -1,
                    .home = v->cull_thread < active ? v->cull_thread : OB_VIEW_NO_THREAD,
                };
            }
        }
    }
    /* Largest predicted cost first; assembly later walks views in order. */
    if (r->job_count > 1) qsort(r->jobs, r->job_count, sizeof *r->jobs, compare_jobs_by_cost);
    return active > 1 ? split_tail(r, active) : OB_OK;
}

/* ------------------------------------------------------------ primary */

/* Colour and depth of each dependency, the inputs, the view's own targets
 * (colour, depth, and with MSAA the two multisampled ones). */
#define VIEW_MAX_BARRIERS (2 * OB_VIEW_MAX_DEPS + OB_VIEW_MAX_INPUTS + 4)

/* Keep img's tracked state from before this frame's first barrier on it. */
void ob_renderer_note_image_state(ob_renderer *r, ob_image img)
{
    for (uint32_t i = 0; i < r->undo_count; i++)
        if (r->undo[i].img.id == img.id) return;
    if (r->undo_count >= OB_MAX_FRAME_IMAGES) {
        r->undo_overflow = true;
        return;
    }
    ob_image_undo *u = &r->undo[r->undo_count];
    if (ob_image_get_state(r->dev, img, &u->before) == OB_OK) {
        u->img = img;
        r->undo_count++;
    }
}

/* The primary will not run: put the layout tracking back to what the GPU
 * last saw, or the next frame's barriers would start from layouts the
 * images never reached (and say so to the validation layer). */
static void undo_states(ob_renderer *r)
{
    for (uint32_t i = 0; i < r->undo_count; i++)
        ob_image_set_state(r->dev, r->undo[i].img, &r->undo[i].before);
    if (r->undo_overflow)
        OB_LOG_E("renderer", "frame %llu touched more than %u images: the layout tracking of the "
                 "others may not match the device after this failed frame",
                 (unsigned long long)r->serial, OB_MAX_FRAME_IMAGES);
    r->undo_count = 0;
    r->undo_overflow = false;
}

static void add_image_barrier(ob_renderer *r, ob_image img, VkImageLayout layout,
                              VkPipelineStageFlags2 stages, VkAccessFlags2 access,
                              VkImageMemoryBarrier2 *barriers, uint32_t *n)
{
    if (!img.id || *n >= VIEW_MAX_BARRIERS) return;
    ob_image_state next = {layout, stages, access};
    ob_renderer_note_image_state(r, img);
    if (ob_image_transition(r->dev, img, &next, &barriers[*n])) (*n)++;
}

/* An input that was never written (an env map at the recursion bound on the
 * first frame) is cleared so that sampling it is defined. */
static void clear_if_undefined(ob_renderer *r, VkCommandBuffer cmd, ob_image img)
{
    ob_image_state st;
    ob_image_info info;
    if (!img.id || ob_image_get_state(r->dev, img, &st) != OB_OK ||
        st.layout != VK_IMAGE_LAYOUT_UNDEFINED || ob_image_get_info(r->dev, img, &info) != OB_OK)
        return;
    VkImageMemoryBarrier2 b;
    ob_image_state dst = {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                          VK_ACCESS_2_TRANSFER_WRITE_BIT};
    ob_renderer_note_image_state(r, img);
    if (!ob_image_transition(r->dev, img, &dst, &b)) return;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                            .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
    vkCmdPipelineBarrier2(cmd, &dep);
    VkImageSubresourceRange range = {info.aspect, 0, VK_REMAINING_MIP_LEVELS, 0, info.layers};
    if (info.aspect & VK_IMAGE_ASPECT_DEPTH_BIT) {
        VkClearDepthStencilValue z = {0.0f, 0};
        vkCmdClearDepthStencilImage(cmd, ob_image_vk(r->dev, img),
                                    VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &z, 1, &range);
    } else {
        VkClearColorValue c = {{0.0f, 0.0f, 0.0f, 1.0f}};
        vkCmdClearColorImage(cmd, ob_image_vk(r->dev, img), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             &c, 1, &range);
    }
}

static void view_barriers(ob_renderer *r, VkCommandBuffer cmd, ob_view *v)
{
    VkImageMemoryBarrier2 barriers[VIEW_MAX_BARRIERS];
    uint32_t n = 0;
    const VkPipelineStageFlags2 sample_stages =
        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT;
    for (uint32_t i = 0; i < v->dep_count; i++) {
        ob_view *d = v->deps[i];
        if (d->layer_count == 0) continue;
        clear_if_undefined(r, cmd, d->color);
        clear_if_undefined(r, cmd, d->depth);
        add_image_barrier(r, d->color, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sample_stages,
                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, barriers, &n);
        add_image_barrier(r, d->depth, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sample_stages,
                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, barriers, &n);
    }
    for (uint32_t i = 0; i < v->input_count; i++) {
        clear_if_undefined(r, cmd, v->inputs[i]);
        add_image_barrier(r, v->inputs[i], VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, sample_stages,
                          VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, barriers, &n);
    }
    if (v->layer_count > 0) {
        /* With MSAA `color` is the resolve target: the resolve writes it in
         * the colour-attachment-output stage, like a colour attachment. */
        bool ms = v->samples > 1;
        add_image_barrier(r, v->color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                          VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                          VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                          barriers, &n);
        if (ms)
            add_image_barrier(r, v->msaa_color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                              VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                              VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                                  VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                              barriers, &n);
        add_image_barrier(r, ms ? v->msaa_depth : v->depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                          VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                              VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                          barriers, &n);
    }
    /* Storage buffers: a simulation writes what a consumer's vertex shader
     * reads. Before a write, wait for earlier reads and writes; before a
     * consumer of a simulation, wait for its write. */
    VkMemoryBarrier2 mem = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    bool need_mem = false;
    if (v->storage_written.id) {
        mem.srcStageMask = VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        mem.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        mem.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        mem.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        need_mem = true;
    }
    for (uint32_t i = 0; i < v->dep_count && !need_mem; i++) {
        if (!v->deps[i]->storage_written.id) continue;
        mem.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        mem.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        mem.dstStageMask = VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT;
        mem.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
        need_mem = true;
    }
    if (n == 0 && !need_mem) return;
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .memoryBarrierCount = need_mem ? 1u : 0u,
        .pMemoryBarriers = &mem,
        .imageMemoryBarrierCount = n,
        .pImageMemoryBarriers = barriers,
    };
    vkCmdPipelineBarrier2(cmd, &dep);
}

/* The attachment view of img for one layer of v: level 0 of that layer
 * (the whole view of a single-layer image without mips), offset by the
 * view's first_layer where views share an array target. */
static VkImageView attachment_view(ob_renderer *r, const ob_view *v, ob_image img, uint32_t layer)
{
    if (!img.id) return VK_NULL_HANDLE;
    return ob_image_layer_view(r->dev, img, v->first_layer + layer);
}

/* A multisampled view (one layer) draws into msaa_color / msaa_depth, which
 * nothing reads afterwards (not stored unless the colour is loaded next
 * time), and resolves the colour into v->color with the samples' average
 * at the end of the scope. */
static void begin_rendering(ob_renderer *r, VkCommandBuffer cmd, ob_view *v, uint32_t layer,
                            bool secondaries)
{
    bool ms = v->samples > 1;
    ob_image color_img = ms ? v->msaa_color : v->color, depth_img = ms ? v->msaa_depth : v->depth;
    VkRenderingAttachmentInfo color = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = attachment_view(r, v, color_img, layer),
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = v->load_color ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = ms && !v->load_color ? VK_ATTACHMENT_STORE_OP_DONT_CARE
                                        : VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.color = {{v->clear_color[0], v->clear_color[1], v->clear_color[2],
                              v->clear_color[3]}},
    };
    if (ms) {
        color.resolveMode = VK_RESOLVE_MODE_AVERAGE_BIT;
        color.resolveImageView = ob_image_view(r->dev, v->color);
        color.resolveImageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    }
    VkRenderingAttachmentInfo depth = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = attachment_view(r, v, depth_img, layer),
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = ms ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.depthStencil = {v->clear_depth, 0},
    };
    VkRenderingInfo ri = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .flags = secondaries ? VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT : 0u,
        .renderArea = {{0, 0}, {v->width, v->height}},
        .layerCount = 1,
        .colorAttachmentCount = color_img.id ? 1u : 0u,
        .pColorAttachments = &color,
        .pDepthAttachment = depth_img.id ? &depth : NULL,
    };
    vkCmdBeginRendering(cmd, &ri);
}

static void stat_view(ob_frame_stats *st, uint32_t i, const ob_view *v)
{
    ob_view_stats *vs = &st->views[i];
    snprintf(vs->name, sizeof vs->name, "%s", v->name);
    vs->type = v->type;
    vs->items = v->item_count;
    vs->culled = v->culled;
    vs->lod_items = v->lod_items;
    vs->cull_ns = v->cull_ns;
    vs->worker = -1;
    vs->hash = ob_cmd_hash_empty();
    vs->gpu_ms = -1.0;
    vs->skipped = (v->layer_count > 0 && !v->custom_record && v->item_count == 0) ? OB_SKIP_EMPTY
                                                                                 : OB_SKIP_NONE;
    st->culled += v->culled;
    st->lod_items += v->lod_items;
}

/* Driver host allocations through every command pool so far. */
static uint64_t cmd_allocations(ob_renderer *r)
{
    uint64_t n = 0;
    for (uint32_t f = 0; f < r->frames_in_flight; f++)
        n += ob_arena_allocator_count(&r->frames[f].alloc);
    for (uint32_t i = 0; i < r->worker_count; i++)
        for (uint32_t f = 0; f < OB_MAX_FRAMES_IN_FLIGHT; f++)
            n += ob_arena_allocator_count(&r->workers[i].alloc[f]);
    return n;
}

/* The measured cost of recording this frame's way (engine/ob_auto.c). */

/* The stage of the frame's end stamp. On a real GPU a stamp at top of pipe
 * is written when the command is read, before the work: it must wait for
 * all commands. lavapipe flushes llvmpipe's scene for any stamp not at top
 * of pipe (lvp_execute.c, handle_write_timestamp2), which with the default
 * sampled timing cost up to twice the frame period (issue 25.11); its
 * timestamp queries are binned into the scene (lp_setup_end_query), so at
 * top of pipe the end stamp still follows the frame's rasterisation, and
 * costs no flush. Frames stamping every view keep ALL_COMMANDS, as the views'
 * own end stamps flush anyway. */
static VkPipelineStageFlags2 frame_end_stage(const ob_renderer *r, bool view_stamps)
{
    return ob_device_is_cpu(r->dev) && !view_stamps ? VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT
                                                    : VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
}

static void note_cost(ob_renderer *r, bool multi, uint32_t workers, uint64_t ns, uint32_t draws)
{
    uint32_t way = multi ? workers : 0;
    ob_record_cost_note(&r->measured[way], ns, draws);
    /* Every other way AUTO weighs against this one ages. */
    for (uint32_t i = 0; i <= r->worker_count; i++)
        if (i != way) r->measured[i].age++;
}

/* A staged ring's upload buffer, recorded once the frame's recording is
 * over (the rings hold all it wrote): the frame's first timestamp (after
 * resetting `queries` of them, 0 for none), every pipeline manager's copy
 * to the buffers the draws read, and the barrier from the copies to those
 * reads. Submitted before the primary, so its barrier orders them. */
static VkResult record_uploads(ob_renderer *r, ob_frame_slot *fs, uint32_t queries)
{
    VkCommandBuffer cmd = fs->upload;
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    VkResult vr = OB_VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    if (vr != VK_SUCCESS) return vr;
    if (queries) {
        vkCmdResetQueryPool(cmd, fs->queries, 0, queries);
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, fs->queries, 0);
    }
    uint64_t bytes = ob_pipeline_manager_record_uploads(r->immediate, cmd);
    for (uint32_t i = 0; i < r->worker_count; i++)
        bytes += ob_pipeline_manager_record_uploads(r->workers[i].pm, cmd);
    if (bytes) {
        VkMemoryBarrier2 mb = {.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
                               .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
                               .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                               .dstStageMask = VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                                               VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT |
                                               VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                                               VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                               .dstAccessMask = VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT |
                                                VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT |
                                                VK_ACCESS_2_UNIFORM_READ_BIT};
        VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                                .memoryBarrierCount = 1,
                                .pMemoryBarriers = &mb};
        vkCmdPipelineBarrier2(cmd, &dep);
    }
    r->cur.ring_upload_bytes = bytes;
    return OB_VK_CHECK(vkEndCommandBuffer(cmd));
}

static ob_result record_frame(ob_renderer *r, ob_view **order, uint32_t count);

ob_result ob_renderer_record_frame(ob_renderer *r, ob_view **order, uint32_t count)
{
    ob_result res = record_frame(r, order, count);
    atomic_store_explicit(&r->hold_awake, false, memory_order_relaxed);
    return res;
}

static ob_result record_frame(ob_renderer *r, ob_view **order, uint32_t count)
{
    ob_frame_slot *fs = &r->frames[r->slot];
    ob_frame_stats *st = &r->cur;
    VkDevice vk = ob_device_vk(r->dev);
    VkResult vr;
    uint64_t cpu0 = ob_thread_cpu_ns();
    uint64_t allocs0 = cmd_allocations(r);
    bool is_auto = r->mode == OB_THREADING_AUTO;
    bool multi = r->mode == OB_THREADING_MULTI || (is_auto && r->auto_multi);
    uint32_t active = !multi ? 0 : is_auto && r->auto_workers ? r->auto_workers : r->active;
    st->workers = active;
    st->view_count = count;
    for (uint32_t i = 0; i < count; i++) stat_view(st, i, order[i]);

    ob_param_registry_begin_recording(r->reg);
    r->undo_count = 0;
    r->undo_overflow = false;
    uint64_t t_record = ob_time_ns();
    ob_result res = OB_OK;
    if (multi) {
        res = build_jobs(r, order, count, active);
        if (res != OB_OK) {
            OB_LOG_E("renderer", "frame %llu: the job list for %u views cannot grow (%s); the "
                     "frame is submitted without their draws", (unsigned long long)r->serial,
                     count, ob_result_name(res));
            r->job_count = 0;
        }
        if (res == OB_OK && r->job_count > 0) run_jobs(r, active);
        for (uint32_t i = 0; i < r->worker_count; i++) {
            ob_worker *w = &r->workers[i];
            if (w->error != OB_OK && res == OB_OK) res = w->error;
            w->error = OB_OK;
            /* The render thread's share is in its own CPU time. */
            if (i + 1 < active) st->record_cpu_ns[i + 1] = w->cpu_ns;
            w->cpu_ns = 0;
        }
    }
    st->record_ns = multi ? ob_time_ns() - t_record : 0;

    uint64_t t_assemble = ob_time_ns();
    VkCommandBuffer cmd = fs->primary;
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    /* The slot's own pool (primary, upload) is reset here, where the frame
     * starts recording into it, like the workers' (worker_next_cmd): the
     * driver freeing the slot's last recording counts as recording in both
     * modes (inline it is the whole frame's, some 70 us at 8 views x 10k
     * objects on lavapipe). */
    vr = OB_VK_CHECK(vkResetCommandPool(vk, fs->pool, 0));
    if (vr == VK_SUCCESS) vr = OB_VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    if (vr != VK_SUCCESS) {
        ob_param_registry_end_recording(r->reg);
        ob_device_note_result(r->dev, vr);
        OB_LOG_E("renderer", "frame %llu not recorded: its primary command buffer could not be "
                 "reset or begun", (unsigned long long)r->serial);
        return ob_result_from_vk(vr);
    }
    bool timestamps = fs->queries && 2 * count + 2 <= fs->query_capacity;
    bool view_stamps = timestamps && (r->gpu_timing == OB_GPU_TIMING_EVERY_VIEW ||
                                      r->serial % OB_VIEW_TIMESTAMP_INTERVAL == 0);
    /* Staged, the frame's first stamp is in the upload buffer, which runs
     * first (record_uploads). */
    if (timestamps && !fs->upload) {
        vkCmdResetQueryPool(cmd, fs->queries, 0, view_stamps ? 2 * count + 2 : 2);
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, fs->queries, 0);
    }
    if (!multi) ob_pipeline_manager_begin(r->immediate, cmd);

    /* Jobs are sorted by cost; walk them per view in (layer, first) order. */
    ob_job **by_view = NULL;
    uint32_t job_total = multi ? r->job_count : 0;
    if (job_total) {
        by_view = ob_malloc(sizeof *by_view * job_total);
        if (!by_view) {
            res = OB_ERR_OUT_OF_HOST_MEMORY;
            OB_LOG_E("renderer", "frame %llu: no memory to order %u recorded jobs; the frame is "
                     "submitted without their draws", (unsigned long long)r->serial, job_total);
        }
        for (uint32_t j = 0; by_view && j < job_total; j++) by_view[j] = &r->jobs[j];
        if (by_view) qsort(by_view, job_total, sizeof *by_view, compare_jobs_in_view_order);
    }
    uint32_t next = 0;
    for (uint32_t i = 0; i < count; i++) {
        ob_view *v = order[i];
        ob_view_stats *vs = &st->views[i];
        view_barriers(r, cmd, v);
        if (view_stamps)
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, fs->queries, 2 + 2 * i);
        uint64_t tv = ob_time_ns();
        uint32_t layers = v->layer_count ? v->layer_count : 1;
        for (uint32_t l = 0; l < layers; l++) {
            if (v->layer_count > 0) begin_rendering(r, cmd, v, l, multi);
            if (multi) {
                /* Executed in batches: a view may have any number of chunks. */
                VkCommandBuffer secs[64];
                uint32_t ns = 0;
                while (by_view && next < job_total && by_view[next]->view_index == i &&
                       by_view[next]->layer == l) {
                    ob_job *job = by_view[next++];
                    if (job->cmd) secs[ns++] = job->cmd;
                    if (ns == OB_ARRAY_COUNT(secs)) {
                        vkCmdExecuteCommands(cmd, ns, secs);
                        ns = 0;
                    }
                    vs->hash = ob_cmd_hash_concat(vs->hash, job->hash);
                    ob_pipeline_manager_stats_add(&st->pm, &job->stats);
                    vs->draws += job->stats.draws;
                    vs->draw_calls += job->stats.draw_calls;
                    vs->instances += job->stats.instances;
                    vs->longest_run = OB_MAX(vs->longest_run, job->stats.longest_run);
                    vs->record_ns += job->record_ns;
                    if (vs->chunks++ == 0) vs->worker = job->worker;
                }
                if (ns) vkCmdExecuteCommands(cmd, ns, secs);
            } else if (v->layer_count == 0 || v->custom_record || v->item_count > 0) {
                ob_pipeline_manager_begin(r->immediate, cmd);
                set_view_params(r, v, r->immediate);
                v->vtbl->record(v, r, r->immediate, l, 0, v->item_count);
                ob_cmd_hash h = ob_pipeline_manager_end(r->immediate);
                vs->hash = ob_cmd_hash_concat(vs->hash, h);
                vs->chunks++;
            }
            if (v->layer_count > 0) vkCmdEndRendering(cmd);
        }
        /* Levels 1.. of a target with mips (env maps sampled by roughness),
         * made before any consumer's barrier moves it to sampling. */
        if (v->layer_count > 0 && v->color_mips > 1 && v->color.id) {
            ob_renderer_note_image_state(r, v->color);
            ob_image_record_mips(r->dev, cmd, v->color);
        }
        if (!multi) {
            ob_pipeline_manager_stats s = ob_pipeline_manager_stats_take(r->immediate);
            vs->draws = s.draws;
            vs->draw_calls = s.draw_calls;
            vs->instances = s.instances;
            vs->longest_run = s.longest_run;
            ob_pipeline_manager_stats_add(&st->pm, &s);
            vs->record_ns = ob_time_ns() - tv;
        }
        v->cost_ns = vs->record_ns;
        /* The end stamp waits for the view's work (at top of pipe it would
         * be written as soon as the commands are read, on a real GPU). */
        if (view_stamps)
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, fs->queries, 3 + 2 * i);
        st->draws += vs->draws;
        st->frame_hash = ob_hash_u64(ob_hash_u64(st->frame_hash, v->id), vs->hash.hash);
    }
    ob_free(by_view);
    ob_renderer_present_record(r, cmd);
    if (timestamps) vkCmdWriteTimestamp2(cmd, frame_end_stage(r, view_stamps), fs->queries, 1);
    ob_param_registry_end_recording(r->reg);
    if (!multi) st->record_ns = ob_time_ns() - t_assemble;
    st->assemble_ns = ob_time_ns() - t_assemble - (multi ? 0 : st->record_ns);
    note_cost(r, multi, active, st->record_ns + st->assemble_ns, st->draws);
    st->record_cpu_ns[0] = ob_thread_cpu_ns() - cpu0;
    st->cmd_host_allocs = cmd_allocations(r) - allocs0;

    vr = OB_VK_CHECK(vkEndCommandBuffer(cmd));
    if (vr == VK_SUCCESS && fs->upload)
        vr = record_uploads(r, fs, timestamps ? (view_stamps ? 2 * count + 2 : 2) : 0);
    if (vr != VK_SUCCESS) {
        undo_states(r);
        ob_device_note_result(r->dev, vr);
        OB_LOG_E("renderer", "frame %llu not submitted: its command buffer%s could not be %s",
                 (unsigned long long)r->serial, fs->upload ? "s" : "",
                 fs->upload ? "recorded (the primary, or the ring's upload)" : "ended");
        return ob_result_from_vk(vr);
    }
    uint64_t t_submit = ob_time_ns();
    vr = OB_VK_CHECK(vkResetFences(vk, 1, &fs->fence));
    if (vr != VK_SUCCESS) {
        undo_states(r);
        ob_device_note_result(r->dev, vr);
        OB_LOG_E("renderer", "frame %llu not submitted: its fence could not be reset",
                 (unsigned long long)r->serial);
        return ob_result_from_vk(vr);
    }
    VkCommandBufferSubmitInfo cbi[2] = {
        {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = fs->upload},
        {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = cmd}};
    VkSemaphoreSubmitInfo acquired = {0}, ready = {0};
    uint32_t present_sync = ob_renderer_present_sync(r, &acquired, &ready);
    VkSubmitInfo2 si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
                        .waitSemaphoreInfoCount = present_sync,
                        .pWaitSemaphoreInfos = &acquired,
                        .commandBufferInfoCount = fs->upload ? 2 : 1,
                        .pCommandBufferInfos = fs->upload ? cbi : cbi + 1,
                        .signalSemaphoreInfoCount = present_sync,
                        .pSignalSemaphoreInfos = &ready};
    vr = OB_VK_CHECK(OB_VK_SUBMIT(vkQueueSubmit2(ob_device_vk_queue(r->dev), 1, &si, fs->fence)));
    ob_renderer_present_submitted(r, vr == VK_SUCCESS);
    if (vr != VK_SUCCESS) {
        ob_device_note_result(r->dev, vr);
        /* Nothing was submitted: the reset fence will not signal, so the
         * slot's next begin_frame must not wait for it (creating a signalled
         * replacement could fail too and leave that wait hanging). */
        fs->unsubmitted = true;
        undo_states(r);
        OB_LOG_E("renderer", "frame %llu not submitted (%s): nothing of it was drawn%s",
                 (unsigned long long)r->serial, ob_vk_result_name(vr),
                 vr == VK_ERROR_DEVICE_LOST ? "" : "; the next frame starts afresh");
        return ob_result_from_vk(vr);
    }
    st->submit_ns = ob_time_ns() - t_submit;
    st->cpu_render_ns += ob_thread_cpu_ns() - r->frame_cpu0;
    fs->pending = true;
    fs->view_queries = view_stamps ? count : 0;
    return res;
}
