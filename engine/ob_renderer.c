#define _POSIX_C_SOURCE 200809L
#include "ob_renderer_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A consumer never has more dependencies than there are other views. */
_Static_assert(OB_VIEW_MAX_DEPS >= OB_MAX_FRAME_VIEWS - 1, "dependency lists can overflow");

const char *ob_skip_reason_name(ob_skip_reason r)
{
    switch (r) {
    case OB_SKIP_NONE: return "none";
    case OB_SKIP_EMPTY: return "empty";
    case OB_SKIP_RECURSION: return "recursion bound";
    case OB_SKIP_NO_CASTERS: return "no shadow casters";
    case OB_SKIP_NOT_NEEDED: return "not needed";
    case OB_SKIP_DUPLICATE: return "already queued";
    case OB_SKIP_ERROR: return "error";
    case OB_SKIP_OVER_LIMIT: return "over the limit";
    }
    return "unknown";
}

const char *ob_threading_name(ob_threading mode)
{
    switch (mode) {
    case OB_THREADING_SINGLE: return "single";
    case OB_THREADING_MULTI: return "multi";
    case OB_THREADING_AUTO: return "auto";
    }
    return "unknown";
}

uint64_t ob_frame_stats_cpu_work_ns(const ob_frame_stats *st)
{
    return st->update_ns + st->pre_render_ns + st->record_ns + st->assemble_ns + st->submit_ns;
}

uint64_t ob_frame_stats_wait_ns(const ob_frame_stats *st)
{
    return st->gpu_wait_ns + st->acquire_ns + st->present_ns;
}

/* ------------------------------------------------------------ lifecycle */

static ob_result create_frame_slot(ob_renderer *r, ob_frame_slot *fs, uint32_t index)
{
    VkDevice vk = ob_device_vk(r->dev);
    VkCommandPoolCreateInfo pci = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
        .queueFamilyIndex = ob_device_queue_family(r->dev),
    };
    ob_arena_allocator_init(&fs->alloc);
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateCommandPool(vk, &pci, &fs->alloc.callbacks,
                                                         &fs->pool));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    VkCommandBufferAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = fs->pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    vr = OB_VK_CHECK_CREATE(vkAllocateCommandBuffers(vk, &ai, &fs->primary));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    char name[32];
    snprintf(name, sizeof name, "primary[%u]", index);
    ob_device_set_name(r->dev, VK_OBJECT_TYPE_COMMAND_BUFFER, (uint64_t)(uintptr_t)fs->primary, name);
    if (r->ring_staged) {
        vr = OB_VK_CHECK_CREATE(vkAllocateCommandBuffers(vk, &ai, &fs->upload));
        if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
        snprintf(name, sizeof name, "ring upload[%u]", index);
        ob_device_set_name(r->dev, VK_OBJECT_TYPE_COMMAND_BUFFER, (uint64_t)(uintptr_t)fs->upload, name);
    }
    VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO,
                             .flags = VK_FENCE_CREATE_SIGNALED_BIT};
    vr = OB_VK_CHECK_CREATE(vkCreateFence(vk, &fci, NULL, &fs->fence));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    if (r->gpu_timing != OB_GPU_TIMING_OFF && ob_device_timestamp_period_ns(r->dev) > 0) {
        fs->query_capacity = 2 * OB_MAX_FRAME_VIEWS + 2;
        VkQueryPoolCreateInfo qci = {
            .sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
            .queryType = VK_QUERY_TYPE_TIMESTAMP,
            .queryCount = fs->query_capacity,
        };
        vr = OB_VK_CHECK_CREATE(vkCreateQueryPool(vk, &qci, NULL, &fs->queries));
        if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    }
    return OB_OK;
}

static void destroy_frame_slot(ob_renderer *r, ob_frame_slot *fs)
{
    VkDevice vk = ob_device_vk(r->dev);
    if (fs->queries) vkDestroyQueryPool(vk, fs->queries, NULL);
    if (fs->fence) vkDestroyFence(vk, fs->fence, NULL);
    if (fs->pool) vkDestroyCommandPool(vk, fs->pool, &fs->alloc.callbacks);
    ob_arena_allocator_release(&fs->alloc);
    memset(fs, 0, sizeof *fs);
}

/* desc.ring_staging for this device; $OB_RING_STAGING=on|off overrides
 * AUTO (to run a suite staged on lavapipe, or direct on a GPU). */
static bool ring_staged(ob_ring_staging asked, const ob_device *dev)
{
    static const char *const words[] = {"on", "off"};
    static const ob_ring_staging values[] = {OB_RING_STAGING_ON, OB_RING_STAGING_OFF};
    if (asked == OB_RING_STAGING_AUTO) {
        int k = ob_env_choice("OB_RING_STAGING", words, 2, "renderer", "ignored");
        if (k >= 0) asked = values[k];
    }
    if (asked == OB_RING_STAGING_AUTO) return !ob_device_host_memory_is_device_local(dev);
    return asked == OB_RING_STAGING_ON;
}

/* desc.instance_runs for this device (never AUTO); $OB_INSTANCE_RUNS=
 * instanced|multi|direct overrides AUTO. */
static ob_instance_runs instance_runs(ob_instance_runs asked, const ob_device *dev)
{
    static const char *const words[] = {"instanced", "multi", "direct"};
    static const ob_instance_runs values[] = {OB_INSTANCE_RUNS_INSTANCED, OB_INSTANCE_RUNS_MULTI_DRAW,
                                              OB_INSTANCE_RUNS_DIRECT};
    if (asked == OB_INSTANCE_RUNS_AUTO) {
        int k = ob_env_choice("OB_INSTANCE_RUNS", words, 3, "renderer", "ignored");
        if (k >= 0) asked = values[k];
    }
    const ob_device_caps *caps = ob_device_get_caps(dev);
    bool can = caps->multi_draw_indirect && caps->draw_indirect_first_instance;
    if (asked == OB_INSTANCE_RUNS_AUTO)
        return can && !ob_device_is_cpu(dev) ? OB_INSTANCE_RUNS_MULTI_DRAW : OB_INSTANCE_RUNS_INSTANCED;
    if (asked == OB_INSTANCE_RUNS_MULTI_DRAW && !can) {
        OB_LOG_W("renderer", "instance runs as multi-draw indirect: the device lacks %s; runs are "
                 "instanced draws", caps->multi_draw_indirect ? "drawIndirectFirstInstance" : "multiDrawIndirect");
        return OB_INSTANCE_RUNS_INSTANCED;
    }
    return asked == OB_INSTANCE_RUNS_MULTI_DRAW || asked == OB_INSTANCE_RUNS_DIRECT
               ? asked
               : OB_INSTANCE_RUNS_INSTANCED;
}

ob_renderer *ob_renderer_create(const ob_renderer_desc *desc, ob_result *out_result)
{
    ob_renderer_desc d = desc ? *desc : (ob_renderer_desc){0};
    ob_result res = OB_OK;
    /* Aligned for its cache-line-aligned members (the loop's task blocks). */
    ob_renderer *r = ob_aligned_alloc(_Alignof(ob_renderer), sizeof *r);
    if (r) memset(r, 0, sizeof *r);
    if (!r) {
        res = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    if (d.worker_count == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        d.worker_count = n > 0 ? (uint32_t)n : 1;
    }
    if (d.worker_count > OB_MAX_WORKERS) d.worker_count = OB_MAX_WORKERS;
    r->worker_count = d.worker_count;
    r->chunk_draws = d.chunk_draws;   /* 0: build_jobs sizes jobs per frame */
    r->parallel_grain = d.parallel_grain;
    r->no_affinity = d.no_thread_affinity;
    r->gpu_timing = d.gpu_timing;
    r->mode = r->pending_mode = d.threading;
    r->active = r->pending_active = r->worker_count;
    r->max_recursion = 4;
    if (d.device.frames_in_flight == 0) d.device.frames_in_flight = 2;
    if (d.device.frames_in_flight > OB_MAX_FRAMES_IN_FLIGHT)
        d.device.frames_in_flight = OB_MAX_FRAMES_IN_FLIGHT;
    r->frames_in_flight = d.device.frames_in_flight;

    r->dev = ob_device_create(&d.device, &res);
    if (!r->dev) goto fail_free_renderer;
    r->ring_staged = ring_staged(d.ring_staging, r->dev);
    r->instance_runs = instance_runs(d.instance_runs, r->dev);
    r->reg = ob_param_registry_create(&(ob_param_registry_desc){.slot_count = 1 + r->worker_count}, &res);
    if (!r->reg) goto fail_destroy_renderer;
    res = ob_params_manager(r->reg, 0, &r->params0);
    if (res != OB_OK) goto fail_destroy_renderer;
    for (uint32_t i = 0; i < r->frames_in_flight; i++) {
        res = create_frame_slot(r, &r->frames[i], i);
        if (res != OB_OK) goto fail_destroy_renderer;
    }
    ob_pipeline_manager_desc pmd = {
        .device = r->dev,
        .registry = r->reg,
        .slot = 0,
        .frames_in_flight = r->frames_in_flight,
        .name = "immediate",
        .staged = r->ring_staged,
        .runs = r->instance_runs,
    };
    r->immediate = ob_pipeline_manager_create(&pmd, &res);
    if (!r->immediate) goto fail_destroy_renderer;
    res = ob_renderer_workers_start(r);
    if (res != OB_OK) goto fail_destroy_renderer;
    if (out_result) *out_result = OB_OK;
    return r;

fail_destroy_renderer:
    ob_renderer_destroy(r);
    r = NULL;
    goto fail_log;
fail_free_renderer:
    ob_aligned_free(r);
    r = NULL;
fail_log:
    OB_LOG_E("renderer", "renderer not created: %s", ob_result_name(res));
    if (out_result) *out_result = res;
    return NULL;
}

void ob_renderer_destroy(ob_renderer *r)
{
    if (!r) return;
    if (r->dev) {
        /* A failure (a lost device) is logged; destroying goes on, since
         * nothing the device still runs can complete any more. */
        OB_VK_CHECK(vkDeviceWaitIdle(ob_device_vk(r->dev)));
        ob_renderer_detach_surface(r);
    }
    ob_renderer_workers_stop(r);
    ob_pipeline_manager_destroy(r->immediate);
    for (uint32_t i = 0; i < OB_MAX_FRAMES_IN_FLIGHT; i++)
        if (r->dev) destroy_frame_slot(r, &r->frames[i]);
    ob_param_registry_destroy(r->reg);
    ob_device_destroy(r->dev);
    ob_free(r->jobs);
    ob_free(r->attachments);
    ob_aligned_free(r);
}

ob_device *ob_renderer_device(ob_renderer *r) { return r->dev; }
ob_instance_runs ob_renderer_instance_runs(const ob_renderer *r) { return r->instance_runs; }
ob_param_registry *ob_renderer_registry(ob_renderer *r) { return r->reg; }
ob_params *ob_renderer_params(ob_renderer *r) { return &r->params0; }
uint32_t ob_renderer_worker_count(const ob_renderer *r) { return r->worker_count; }
ob_scene *ob_renderer_scene(ob_renderer *r) { return r->scene; }
uint64_t ob_renderer_frame_serial(const ob_renderer *r) { return r->serial; }

void ob_renderer_set_material_iface(ob_renderer *r, const ob_material_iface *iface)
{
    r->has_material_iface = iface != NULL;
    if (iface) r->material_iface = *iface;
}

void ob_renderer_set_geometry_iface(ob_renderer *r, const ob_geometry_iface *iface)
{
    r->has_geometry_iface = iface != NULL;
    if (iface) r->geometry_iface = *iface;
}

const ob_material_iface *ob_renderer_get_material_iface(const ob_renderer *r)
{
    return r->has_material_iface ? &r->material_iface : NULL;
}

const ob_geometry_iface *ob_renderer_get_geometry_iface(const ob_renderer *r)
{
    return r->has_geometry_iface ? &r->geometry_iface : NULL;
}

ob_result ob_renderer_set_threading(ob_renderer *r, ob_threading mode, uint32_t active_workers)
{
    if ((unsigned)mode > OB_THREADING_AUTO) {
        OB_LOG_E("renderer", "threading mode %d refused (single, multi or auto); it stays as it was",
                 (int)mode);
        return OB_ERR_INVALID_ARGUMENT;
    }
    r->pending_mode = mode;
    if (active_workers == 0 || active_workers > r->worker_count) active_workers = r->worker_count;
    r->pending_active = active_workers;
    return OB_OK;
}

ob_threading ob_renderer_get_threading(const ob_renderer *r) { return r->mode; }

void ob_renderer_set_max_recursion(ob_renderer *r, uint32_t depth)
{
    r->max_recursion = depth < OB_MAX_VIEW_STACK - 1 ? depth : OB_MAX_VIEW_STACK - 2;
}

/* ------------------------------------------------------------ stats */

/* The frame in `fs` has completed: read its timestamps into its stats and
 * make them the last complete stats. The read may wait for the GPU
 * (lavapipe's does, for the work the fence did not cover): its time is
 * added to *wait_ns when that is not NULL. */
static void collect_frame(ob_renderer *r, ob_frame_slot *fs, uint64_t *wait_ns)
{
    if (!fs->pending) return;
    fs->pending = false;
    ob_frame_stats *st = &fs->stats;
    double period = ob_device_timestamp_period_ns(r->dev);
    uint32_t n = 2 * fs->view_queries + 2;
    uint64_t ts[2 * OB_MAX_FRAME_VIEWS + 2];
    st->gpu_ms = -1.0;
    for (uint32_t i = 0; i < st->view_count; i++) st->views[i].gpu_ms = -1.0;
    uint64_t t_read = ob_time_ns();
    bool read = fs->queries && n <= fs->query_capacity &&
                vkGetQueryPoolResults(ob_device_vk(r->dev), fs->queries, 0, n, sizeof ts, ts,
                                      sizeof ts[0], VK_QUERY_RESULT_64_BIT) == VK_SUCCESS;
    if (wait_ns) *wait_ns += ob_time_ns() - t_read;
    if (read) {
        st->gpu_ms = (double)(ts[1] - ts[0]) * period * 1e-6;
        for (uint32_t i = 0; i < fs->view_queries && i < st->view_count; i++) {
            uint64_t a = ts[2 + 2 * i], b = ts[3 + 2 * i];
            st->views[i].gpu_ms = (double)(b - a) * period * 1e-6;
        }
    }
    r->last = *st;
    if (r->stats_fn) r->stats_fn(r->stats_user, st);
}

void ob_renderer_set_stats_callback(ob_renderer *r, ob_frame_stats_fn fn, void *user)
{
    r->stats_fn = fn;
    r->stats_user = user;
}

void ob_renderer_note_created(ob_renderer *r, uint32_t pipelines, uint32_t variants)
{
    r->cur.pipelines_created += pipelines;
    r->cur.variants_created += variants;
}

const ob_frame_stats *ob_renderer_last_stats(const ob_renderer *r) { return &r->last; }
const ob_frame_stats *ob_renderer_current_stats(const ob_renderer *r) { return &r->cur; }

void ob_renderer_note_update_ns(ob_renderer *r, uint64_t ns) { r->cur.update_ns = ns; }

void ob_renderer_last_update_stats(const ob_renderer *r, ob_update_stats *out)
{
    *out = (ob_update_stats){r->update.ns, r->update.cpu_render, r->update.cpu_render_parallel,
                             r->update.cpu_pool};
}

ob_result ob_renderer_update_scene(ob_renderer *r, ob_scene *s, double dt)
{
    if (r->in_frame) {
        OB_LOG_E("renderer", "ob_renderer_update_scene inside a frame (between begin_frame and "
                 "end_frame); refused");
        return OB_ERR_WRONG_STATE;
    }
    uint64_t t0 = ob_time_ns(), c0 = ob_thread_cpu_ns();
    r->update.cpu_render_parallel = r->update.cpu_pool = 0;
    r->acc_render_parallel = &r->update.cpu_render_parallel;
    r->acc_pool = &r->update.cpu_pool;
    ob_parallel par = ob_renderer_parallel(r);
    ob_result res = ob_scene_update_parallel(s, dt, &par);
    r->acc_render_parallel = r->acc_pool = NULL;
    r->update.cpu_render = ob_thread_cpu_ns() - c0;
    r->update.ns = ob_time_ns() - t0;
    r->update.valid = true;
    return res;
}

/* Adds (name, reason) to the frame's skipped list; false when it was there
 * already. */
static bool add_skipped(ob_frame_stats *st, const char *name, ob_skip_reason reason)
{
    for (uint32_t i = 0; i < st->skipped_count; i++)
        if (strcmp(st->skipped[i].name, name) == 0 && st->skipped[i].reason == reason) return false;
    if (st->skipped_count < OB_MAX_FRAME_VIEWS) {
        snprintf(st->skipped[st->skipped_count].name, sizeof st->skipped[0].name, "%s", name);
        st->skipped[st->skipped_count].reason = reason;
        st->skipped_count++;
    }
    return true;
}

void ob_renderer_note_skipped(ob_renderer *r, const char *name, ob_skip_reason reason)
{
    if (add_skipped(&r->cur, name, reason) && reason == OB_SKIP_ERROR) r->cur.errors++;
}

void ob_renderer_note_error(ob_renderer *r, const char *name, ob_result error)
{
    if (!r || error == OB_OK || !r->in_frame) return;
    if (add_skipped(&r->cur, name ? name : "", OB_SKIP_ERROR)) r->cur.errors++;
    if (r->cur.first_error == OB_OK) r->cur.first_error = error;
}

void ob_renderer_note_lights_over_limit(ob_renderer *r, uint32_t count)
{
    if (count > r->cur.lights_over_limit) r->cur.lights_over_limit = count;
}

/* ------------------------------------------------------------ frame */

ob_result ob_renderer_begin_frame(ob_renderer *r, ob_scene *scene)
{
    if (r->in_frame) {
        OB_LOG_E("renderer", "begin_frame called twice without end_frame");
        return OB_ERR_WRONG_STATE;
    }
    if (ob_device_is_lost(r->dev)) {
        OB_LOG_E("renderer", "frame refused: the device is lost (destroy the renderer and "
                 "create a new one)");
        return OB_ERR_DEVICE_LOST;
    }
    uint64_t t0 = ob_time_ns();
    r->slot = (uint32_t)(r->serial % r->frames_in_flight);
    ob_frame_slot *fs = &r->frames[r->slot];
    VkDevice vk = ob_device_vk(r->dev);
    /* A slot whose last submission failed has nothing pending: its fence was
     * reset for that submission and never signals. */
    VkResult vr = VK_SUCCESS;
    if (!fs->unsubmitted)
        vr = OB_VK_CHECK(OB_VK_WAIT(vkWaitForFences(vk, 1, &fs->fence, VK_TRUE, UINT64_MAX)));
    uint64_t gpu_wait_ns = ob_time_ns() - t0;
    if (vr != VK_SUCCESS) {
        ob_device_note_result(r->dev, vr);
        OB_LOG_E("renderer", "frame %llu: waiting for frame slot %u failed: %s",
                 (unsigned long long)r->serial + 1, r->slot, ob_vk_result_name(vr));
        return ob_result_from_vk(vr);
    }
    fs->unsubmitted = false;
    /* The pool threads the frame's loops will use slept since the last
     * frame: woken now, they poll by the time PreRender hands out its first
     * loop (waking one costs some 30-50 us on a 2-core VM, which the rest of
     * begin_frame and the views' PreRender set-up cover). Only when the last
     * frame handed work out: a small scene's frame runs on the caller. */
    if (r->pending_mode != OB_THREADING_SINGLE && r->frame_used_pool)
        ob_renderer_workers_nudge(r, ob_renderer_parallel_threads(r));
    r->handed_out = false;
    collect_frame(r, fs, &gpu_wait_ns);
    r->serial++;
    ob_device_begin_frame_slot(r->dev, r->slot);
    /* The slot's other command pools are reset where the frame first
     * records into each (the primary's in ob_renderer_record_frame, a
     * worker's not reset above in worker_next_cmd): the slot's fence,
     * waited for above, covers them all. */
    for (uint32_t i = 0; i < r->worker_count; i++)
        ob_pipeline_manager_begin_frame(r->workers[i].pm, r->slot, r->serial);
    ob_pipeline_manager_begin_frame(r->immediate, r->slot, r->serial);
    /* The slot's fence also covers the submission that waited on its
     * acquire semaphore, so the acquire may signal it again. */
    uint64_t t_acquire = ob_time_ns();
    ob_result pres = ob_renderer_present_acquire(r);
    uint64_t acquire_ns = ob_time_ns() - t_acquire;
    if (pres != OB_OK) {
        OB_LOG_E("renderer", "frame %llu: no swapchain image: %s", (unsigned long long)r->serial,
                 ob_result_name(pres));
        return pres;
    }

    r->mode = r->pending_mode;
    r->active = r->pending_active;
    if (r->mode == OB_THREADING_AUTO) {
        /* The workers' way at its cheapest count, against inline; then,
         * recording on the workers, now and then a count next to it. */
        uint32_t best = ob_auto_best_workers(&r->auto_state, r->measured, r->active);
        r->auto_multi = ob_auto_choose(&r->auto_state, &r->measured[0], &r->measured[best]);
        r->auto_workers = r->auto_multi && !r->auto_state.probing
                              ? ob_auto_probe_workers(&r->auto_state, r->measured, r->active)
                              : best;
    }
    r->scene = scene;
    r->queue_count = 0;
    r->stack_depth = 0;
    r->wave_count = 0;
    r->attachment_count = 0;
    memset(&r->cur, 0, sizeof r->cur);
    r->cur.frame = r->serial;
    r->cur.mode = r->mode;
    if (r->update.valid) {
        r->cur.update_ns = r->update.ns;
        r->cur.cpu_render_ns = r->cur.update_cpu_render_ns = r->update.cpu_render;
        r->cur.cpu_render_parallel_ns = r->cur.update_cpu_render_parallel_ns =
            r->update.cpu_render_parallel;
        r->cur.cpu_pool_ns = r->cur.update_cpu_pool_ns = r->update.cpu_pool;
        r->update.valid = false;
    }
    r->acc_render_parallel = &r->cur.cpu_render_parallel_ns;
    r->acc_pool = &r->cur.cpu_pool_ns;
    r->frame_cpu0 = ob_thread_cpu_ns();
    r->frame_start_ns = t0;
    r->in_frame = true;
    r->submitted = false;
    r->cur.gpu_wait_ns = gpu_wait_ns;
    r->cur.acquire_ns = r->present ? acquire_ns : 0;
    r->cur.wait_ns = ob_time_ns() - t0;
    return OB_OK;
}

/* ------------------------------------------------------------ view queue */

static int32_t queue_index(const ob_renderer *r, const ob_view *v)
{
    for (uint32_t i = 0; i < r->queue_count; i++)
        if (r->queue[i] == v) return (int32_t)i;
    return -1;
}

bool ob_renderer_queue_view(ob_renderer *r, ob_view *v)
{
    if (!r->in_frame || !v) return false;
    /* The stack top is v itself (ob_renderer_pre_render pushed it); the view
     * below it is the consumer that asked for v. */
    ob_view *consumer = NULL;
    uint32_t depth = 0;
    if (r->stack_depth > 0 && r->stack[r->stack_depth - 1] == v) {
        depth = r->stack_depth - 1;
        consumer = depth > 0 ? r->stack[depth - 1] : NULL;
    } else if (r->stack_depth > 0) {
        depth = r->stack_depth;
        consumer = r->stack[r->stack_depth - 1];
    }
    if (v->queued_frame == r->serial) {
        /* A view queued earlier in this frame: the consumer still depends on it
         * (if it comes later in the order it reads last frame's contents). */
        if (consumer) ob_view_add_dependency(consumer, v);
        return false;
    }
    if (depth > r->max_recursion) {
        ob_renderer_note_skipped(r, v->name, OB_SKIP_RECURSION);
        return false;
    }
    if (v->input_count > OB_VIEW_MAX_INPUTS) {
        OB_LOG_E("renderer", "view '%s' not queued: %u inputs, at most %u", v->name, v->input_count,
                 OB_VIEW_MAX_INPUTS);
        ob_renderer_note_error(r, v->name, OB_ERR_LIMIT);
        return false;
    }
    if (r->queue_count >= OB_MAX_FRAME_VIEWS) {
        OB_LOG_E("renderer", "view '%s' not queued: more than %u views this frame", v->name,
                 OB_MAX_FRAME_VIEWS);
        ob_renderer_note_error(r, v->name, OB_ERR_LIMIT);
        return false;
    }
    v->queued_frame = r->serial;
    v->recursion_depth = depth;
    v->dep_count = 0;
    v->item_count = 0;
    v->culled = 0;
    v->lod_items = 0;
    v->material_count = 0;    /* what culling knew is last frame's until it runs */
    v->material_items_valid = false;
    v->cull_thread = OB_VIEW_NO_THREAD;
    r->queued_by[r->queue_count] = consumer ? queue_index(r, consumer) : -1;
    r->queue[r->queue_count++] = v;
    if (consumer) ob_view_add_dependency(consumer, v);
    return true;
}

/* Starts v's PreRender with v current. A view with pre_cull/post_cull runs
 * its first half now and waits in r->wave for its culling. */
static void pre_render_start(ob_renderer *r, ob_view *v)
{
    if (!v || !v->vtbl || (!v->vtbl->pre_render && !v->vtbl->pre_cull)) return;
    if (r->stack_depth >= OB_MAX_VIEW_STACK) {
        ob_renderer_note_skipped(r, v->name, OB_SKIP_RECURSION);
        return;
    }
    r->stack[r->stack_depth++] = v;
    if (!v->vtbl->pre_cull) {
        v->vtbl->pre_render(v, r);
    } else if (v->vtbl->pre_cull(v, r) && v->queued_frame == r->serial) {
        /* Queued views only: each at most once a frame, so the wave holds
         * at most OB_MAX_FRAME_VIEWS. */
        ob_pending_cull *p = &r->wave[r->wave_count++];
        p->view = v;
        p->depth = r->stack_depth;
        memcpy(p->stack, r->stack, sizeof *p->stack * r->stack_depth);
    }
    r->stack_depth--;
}

/* Culls the waiting views together (ob_view_cull_many: on the pool), then
 * runs their post_cull in the order they were queued, each with its chain
 * current again; the views those queue make the next wave. */
static void pre_render_waves(ob_renderer *r)
{
    r->flushing = true;
    while (r->wave_count > 0) {
        uint32_t n = r->wave_count;
        memcpy(r->current_wave, r->wave, sizeof *r->wave * n);
        r->wave_count = 0;
        ob_view *views[OB_MAX_FRAME_VIEWS];
        for (uint32_t i = 0; i < n; i++) views[i] = r->current_wave[i].view;
        ob_view_cull_many(r, r->scene, views, n);
        for (uint32_t i = 0; i < n; i++) {
            const ob_pending_cull *p = &r->current_wave[i];
            memcpy(r->stack, p->stack, sizeof *p->stack * p->depth);
            r->stack_depth = p->depth;
            if (p->view->vtbl->post_cull) p->view->vtbl->post_cull(p->view, r);
        }
        r->stack_depth = 0;
    }
    r->flushing = false;
}

void ob_renderer_pre_render_many(ob_renderer *r, ob_view *const *roots, uint32_t count)
{
    if (!r->in_frame || r->flushing || r->stack_depth > 0) {
        /* Inside a PreRender: each view joins the running one. */
        for (uint32_t i = 0; r->in_frame && i < count; i++) pre_render_start(r, roots[i]);
        return;
    }
    uint64_t t0 = ob_time_ns();
    for (uint32_t i = 0; i < count; i++) pre_render_start(r, roots[i]);
    pre_render_waves(r);
    r->cur.pre_render_ns += ob_time_ns() - t0;
}

void ob_renderer_pre_render(ob_renderer *r, ob_view *v) { ob_renderer_pre_render_many(r, &v, 1); }

uint32_t ob_renderer_recursion_depth(const ob_renderer *r)
{
    return r->stack_depth > 0 ? r->stack_depth - 1 : 0;
}

ob_view *ob_renderer_current_view(const ob_renderer *r)
{
    return r->stack_depth > 0 ? r->stack[r->stack_depth - 1] : NULL;
}

ob_result ob_renderer_attach_view(ob_renderer *r, const ob_node *entity, ob_view *v)
{
    uint32_t id = ob_node_id(entity);
    for (uint32_t i = 0; i < r->attachment_count; i++) {
        ob_attachment *a = &r->attachments[i];
        if (a->node_id == id && a->view->type == v->type) {
            a->view = v;
            return OB_OK;
        }
    }
    ob_result res = ob_array_reserve((void **)&r->attachments, &r->attachment_cap,
                                     r->attachment_count + 1, sizeof *r->attachments);
    if (res != OB_OK) return res;
    r->attachments[r->attachment_count++] = (ob_attachment){id, v};
    return OB_OK;
}

ob_view *ob_renderer_attached_view(const ob_renderer *r, const ob_node *entity, ob_view_type type)
{
    uint32_t id = ob_node_id(entity);
    for (uint32_t i = 0; i < r->attachment_count; i++)
        if (r->attachments[i].node_id == id && r->attachments[i].view->type == type)
            return r->attachments[i].view;
    return NULL;
}

/* ------------------------------------------------------------ processing */

/* Was queue entry `ancestor` on the PreRender chain that queued entry i? */
static bool queued_under(const ob_renderer *r, uint32_t i, uint32_t ancestor)
{
    for (int32_t p = r->queued_by[i]; p >= 0; p = r->queued_by[p])
        if ((uint32_t)p == ancestor) return true;
    return false;
}

/* Post-order walk: a view's dependencies are placed before it. Dependencies
 * are visited in reverse order of addition, so a PreRender tree comes out in
 * exactly the reverse of queue order. An edge to a view on the chain that
 * queued this one closes a cycle and is not followed: that consumer reads
 * the previous frame's contents. */
static void order_visit(const ob_renderer *r, uint32_t i, uint8_t *mark, ob_view **order,
                        uint32_t *n)
{
    mark[i] = 1;
    const ob_view *v = r->queue[i];
    for (uint32_t k = v->dep_count; k-- > 0;) {
        int32_t d = queue_index(r, v->deps[k]);
        if (d < 0 || mark[d] || queued_under(r, i, (uint32_t)d)) continue;
        order_visit(r, (uint32_t)d, mark, order, n);
    }
    mark[i] = 2;
    order[(*n)++] = r->queue[i];
}

ob_result ob_renderer_process_views(ob_renderer *r)
{
    if (!r->in_frame || r->submitted) {
        OB_LOG_E("renderer", "process_views outside a frame or called twice");
        return OB_ERR_WRONG_STATE;
    }
    /* Dependencies were queued after their consumers, so reverse queue order
     * runs them first (Hieroglyph's LIFO rule) — as long as every dependency
     * was queued by its consumer. A view another consumer queued earlier (an
     * env map two cameras see) would come after the later consumer, so the
     * order is the dependency order, walked from the last queued view back:
     * identical to LIFO for a tree, correct for shared dependencies. */
    ob_view *order[OB_MAX_FRAME_VIEWS];
    uint8_t mark[OB_MAX_FRAME_VIEWS] = {0};
    uint32_t n = 0;
    for (uint32_t i = r->queue_count; i-- > 0;)
        if (!mark[i]) order_visit(r, i, mark, order, &n);
    ob_result res = ob_renderer_record_frame(r, order, n);
    r->submitted = true;
    return res;
}

ob_result ob_renderer_end_frame(ob_renderer *r)
{
    if (!r->in_frame) return OB_ERR_WRONG_STATE;
    ob_result res = r->submitted ? OB_OK : ob_renderer_process_views(r);
    /* A frame submitted with errors (a view not recorded) still releases
     * its swapchain image: the present waits on what was submitted. */
    uint64_t t_present = ob_time_ns();
    ob_result pres = ob_renderer_present_queue(r);
    r->cur.present_ns = r->present ? ob_time_ns() - t_present : 0;
    r->in_frame = false;
    r->acc_render_parallel = r->acc_pool = NULL;
    r->frame_used_pool = r->handed_out;
    if (res != OB_OK) return res;
    r->cur.frame_ns = ob_time_ns() - r->frame_start_ns + r->cur.update_ns;
    r->frames[r->slot].stats = r->cur;
    return pres;
}

ob_result ob_renderer_wait_idle(ob_renderer *r)
{
    VkResult vr = OB_VK_CHECK(OB_VK_WAIT(vkDeviceWaitIdle(ob_device_vk(r->dev))));
    if (vr != VK_SUCCESS) {
        ob_device_note_result(r->dev, vr);
        return ob_result_from_vk(vr);
    }
    /* Idle, but a lost device's frames never completed: no stats to collect. */
    if (ob_device_is_lost(r->dev)) return OB_ERR_DEVICE_LOST;
    /* Collect in submission order so `last` ends as the newest frame. */
    for (uint64_t k = r->frames_in_flight; k > 0; k--) {
        uint32_t slot = (uint32_t)((r->serial + r->frames_in_flight - k) % r->frames_in_flight);
        if (r->serial >= k - 1) collect_frame(r, &r->frames[slot], NULL);
    }
    return OB_OK;
}
