/* Issue 5: the worker pool. It starts and stops with the renderer (threads
 * joined, nothing leaked — the ASan build checks the memory, the thread
 * count here checks the joins), also when creation fails half-way; the
 * threading mode and worker count change at the next frame start, never in
 * the middle of a frame. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ob_renderer_layer.h"
#include "ob_test_adopt.h"
#include "ob_test_world.h"

/* Threads of this process. */
static uint32_t thread_count(void)
{
    DIR *d = opendir("/proc/self/task");
    assert_non_null(d);
    uint32_t n = 0;
    for (struct dirent *e; (e = readdir(d));) n += e->d_name[0] != '.';
    closedir(d);
    return n;
}

/* Threads the driver and layers start once per process stay; take the
 * baseline after one full renderer has come and gone. */
static uint32_t baseline_threads(void)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 2});
    ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    ob_test_world_destroy(&w);
    return thread_count();
}

static void lit_cube(ob_test_world *w)
{
    ob_material *m = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.8f, 0.4f, 0.2f, true);
    ob_world_entity(w, NULL, "cube", w->box, m, 0, 0, 0);
    ob_material *g = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
    ob_world_entity(w, NULL, "ground", w->plane, g, 0, -0.5, 0);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
}

/* Five renderers with 1 to 8 workers: each starts its threads, records a
 * frame with all of them active, and takes every thread with it. */
static void worker_pool_starts_and_stops_with_the_renderer(void **state)
{
    (void)state;
    uint32_t base = baseline_threads();
    static const uint32_t counts[] = {1, 2, 3, 5, 8};
    uint8_t *first = NULL;
    for (size_t k = 0; k < OB_ARRAY_COUNT(counts); k++) {
        uint32_t n = counts[k];
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.workers = n});
        assert_int_equal(ob_renderer_worker_count(w.r), n);
        assert_true(thread_count() >= base + n);
        lit_cube(&w);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
        assert_int_equal(st->mode, OB_THREADING_MULTI);
        assert_int_equal(st->workers, n);
        for (uint32_t i = 0; i < st->view_count; i++) {
            if (st->views[i].chunks == 0) continue;
            assert_true(st->views[i].worker >= 1 && (uint32_t)st->views[i].worker <= n);
        }
        uint8_t *img = ob_world_snapshot(&w);
        if (!first) first = img;
        else {
            assert_int_equal(ob_test_image_max_diff(first, img, w.width, w.height), 0);
            free(img);
        }
        ob_test_world_destroy(&w);
        if (thread_count() != base)
            fail_msg("%u workers: %u threads after destroy, %u before create", n, thread_count(),
                     base);
    }
    free(first);
}

/* One frame driven by hand so the mode can be changed in its middle. */
static const ob_frame_stats *frame_changing_mode(ob_test_world *w, ob_threading mode,
                                                 uint32_t workers)
{
    assert_int_equal(ob_scene_update(w->scene, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_begin_frame(w->r, w->scene), OB_OK);
    ob_views_render(w->views, ob_composite_view_base(w->composite));
    ob_renderer_set_threading(w->r, mode, workers); /* mid-frame: for the next one */
    assert_int_equal(ob_renderer_end_frame(w->r), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(w->r), OB_OK);
    return ob_renderer_last_stats(w->r);
}

/* A change asked for during a frame applies from the next frame start. */
static void threading_change_takes_effect_at_next_frame(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 8, .chunk_draws = 1});
    lit_cube(&w);
    ob_renderer_set_threading(w.r, OB_THREADING_SINGLE, 0);
    static const struct {
        ob_threading mode;
        uint32_t asked, active;
    } steps[] = {
        {OB_THREADING_MULTI, 3, 3},  {OB_THREADING_MULTI, 5, 5},  {OB_THREADING_SINGLE, 0, 0},
        {OB_THREADING_MULTI, 0, 8},  /* 0: all workers */
        {OB_THREADING_MULTI, 99, 8}, /* more than the pool: all of it */
        {OB_THREADING_MULTI, 1, 1},  {OB_THREADING_SINGLE, 4, 0},
    };
    ob_threading mode = OB_THREADING_SINGLE;
    uint32_t active = 0;
    for (size_t i = 0; i < OB_ARRAY_COUNT(steps); i++) {
        const ob_frame_stats *st = frame_changing_mode(&w, steps[i].mode, steps[i].asked);
        /* This frame still ran as set before it began. */
        assert_int_equal(st->mode, mode);
        assert_int_equal(st->workers, active);
        assert_int_equal(ob_renderer_get_threading(w.r), mode);
        mode = steps[i].mode;
        active = steps[i].active;
    }
    const ob_frame_stats *st = frame_changing_mode(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(st->mode, mode);
    assert_int_equal(st->workers, active);
    ob_test_world_destroy(&w);
}

/* AUTO decides from measured cost: it measures each way of recording the
 * scene first (inline, then on the workers), and keeps re-measuring the way
 * it did not choose, so a scene whose cost changes is followed. (Which way
 * wins depends on the machine; that both are measured does not.) */
static void auto_measures_both_ways(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 2, .chunk_draws = 1});
    lit_cube(&w);
    uint32_t inline_frames = 0, worker_frames = 0;
    for (int f = 0; f < 40; f++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_AUTO, 0);
        assert_int_equal(st->mode, OB_THREADING_AUTO);
        if (f == 0) assert_int_equal(st->workers, 0);
        if (f == 1) assert_int_equal(st->workers, 2);
        if (st->workers) worker_frames++;
        else inline_frames++;
    }
    /* 40 frames: each way at least once past the first two. */
    assert_true(inline_frames >= 2);
    assert_true(worker_frames >= 2);
    ob_test_world_destroy(&w);
}

/* Views are recorded by workers of the active set only. */
static void only_active_workers_record(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 6, .chunk_draws = 2});
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.4f, 0.2f, false);
    for (int i = 0; i < 60; i++)
        ob_world_entity(&w, NULL, "box", w.box, m, (i % 10) - 4.5, 0, -(i / 10));
    ob_world_look(&w, 0, 8, 8, 0, 0, -3);
    for (uint32_t n = 1; n <= 6; n++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, n);
        assert_int_equal(st->workers, n);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        assert_int_equal(main->draws, 60);
        assert_true(main->chunks >= 30);
        for (uint32_t i = 0; i < st->view_count; i++)
            if (st->views[i].chunks)
                assert_true(st->views[i].worker >= 1 && (uint32_t)st->views[i].worker <= n);
    }
    ob_test_world_destroy(&w);
}

/* A parallel loop's indices on the pool (ob_renderer_parallel): each runs
 * exactly once, whatever the count and the active workers. Each thread
 * starts on its own block of the indices (the render thread, loop thread
 * 0, on the first) and takes it from the front; a thread held up in its
 * block has the rest of it taken by the others, from the back. */
#define PROBE_MAX 1000u

typedef struct loop_probe {
    atomic_uint runs[PROBE_MAX];
    atomic_uint thread_of[PROBE_MAX];
    atomic_bool stolen;         /* an index of block 0 ran on a pool thread */
    atomic_bool held;           /* the render thread began its first index */
    uint32_t block0_end;
    bool hold_first;            /* the render thread's first index waits until stolen */
} loop_probe;

static void probe_task(void *user, uint32_t i, uint32_t thread)
{
    loop_probe *p = user;
    atomic_fetch_add(&p->runs[i], 1u);
    atomic_store(&p->thread_of[i], thread);
    if (i < p->block0_end && thread != 0) atomic_store(&p->stolen, true);
    /* Whichever index the render thread runs first: index 0 unless the
     * pool threads, running while it was not, took all of its block. */
    if (!p->hold_first || thread != 0 || atomic_exchange(&p->held, true)) return;
    /* At most 10 s: a pool thread must wake, finish its own block and steal. */
    for (int k = 0; k < 200000 && !atomic_load(&p->stolen); k++)
        nanosleep(&(struct timespec){.tv_nsec = 50000}, NULL);
}

static void probe_reset(loop_probe *p, uint32_t count, uint32_t threads, bool hold)
{
    for (uint32_t i = 0; i < PROBE_MAX; i++) {
        atomic_init(&p->runs[i], 0u);
        atomic_init(&p->thread_of[i], UINT32_MAX);
    }
    atomic_init(&p->stolen, false);
    atomic_init(&p->held, false);
    p->block0_end = count / threads;
    p->hold_first = hold;
}

/* Block b of a loop of `count` indices on n threads (one block for each
 * thread that may take part) was taken by its owner, thread b, from the
 * front and by the others from the back: the indices its owner ran come
 * first. */
static void check_blocks(const loop_probe *p, uint32_t count, uint32_t n)
{
    uint32_t blocks = n < count ? n : count;
    for (uint32_t b = 0; b < blocks; b++) {
        uint32_t first = (uint32_t)((uint64_t)count * b / blocks);
        uint32_t end = (uint32_t)((uint64_t)count * (b + 1) / blocks);
        bool others = false;
        for (uint32_t i = first; i < end; i++) {
            bool own = atomic_load(&p->thread_of[i]) == b;
            if (own && others)
                fail_msg("%u threads, %u indices: block %u's index %u ran on its owner after "
                         "an earlier one ran elsewhere", n, count, b, i);
            others |= !own;
        }
    }
}

static void parallel_loops_run_each_index_once(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4});
    static loop_probe p;
    static const uint32_t counts[] = {1, 2, 3, 5, 17, 64, PROBE_MAX};
    for (uint32_t n = 1; n <= 4; n++) {
        assert_int_equal(ob_renderer_set_threading(w.r, OB_THREADING_MULTI, n), OB_OK);
        for (size_t k = 0; k < OB_ARRAY_COUNT(counts); k++) {
            ob_parallel par = ob_renderer_parallel(w.r);
            assert_int_equal(par.threads, n);
            probe_reset(&p, counts[k], n, false);
            ob_parallel_run(&par, counts[k], probe_task, &p);
            for (uint32_t i = 0; i < counts[k]; i++)
                if (atomic_load(&p.runs[i]) != 1)
                    fail_msg("%u threads, %u indices: index %u ran %u times", n, counts[k], i,
                             atomic_load(&p.runs[i]));
            for (uint32_t i = counts[k]; i < PROBE_MAX; i++) assert_int_equal(atomic_load(&p.runs[i]), 0);
            for (uint32_t i = 0; i < counts[k]; i++) assert_true(atomic_load(&p.thread_of[i]) < n);
            if (n > 1) check_blocks(&p, counts[k], n);
        }
    }
    /* Four threads, 64 indices: the render thread begins its block (16)
     * and holds on its first index until a pool thread has taken one of
     * the others, which only stealing does. (On a loaded machine the pool
     * threads may run before the render thread takes any index, and then
     * take its whole block: stolen all the same, and still from the back,
     * which check_blocks sees. Asserting that index 0 ran on the render
     * thread failed that way once in the address sanitizer's suite.) */
    probe_reset(&p, 64, 4, true);
    ob_parallel par = ob_renderer_parallel(w.r);
    ob_parallel_run(&par, 64, probe_task, &p);
    assert_true(atomic_load(&p.stolen));
    for (uint32_t i = 0; i < 64; i++) assert_int_equal(atomic_load(&p.runs[i]), 1);
    check_blocks(&p, 64, 4);
    ob_test_world_destroy(&w);
}

/* A helped loop (ob_parallel_run_helped), as PreRender's culling wave
 * shares a big view's gather: each index leaves PIECES pieces of work that
 * any thread may take in idle; the index's own thread takes what is left.
 * The loop returns with every piece done exactly once, whoever helped. */
#define HELP_INDICES 24u
#define PIECES 8u

typedef struct help_probe {
    atomic_uint ready[HELP_INDICES];     /* pieces published by index i (0 or PIECES) */
    atomic_uint next[HELP_INDICES];      /* the next piece of index i to take */
    atomic_uint done[HELP_INDICES][PIECES];
    atomic_uint left;                    /* pieces not done, over the loop */
    atomic_uint helped;                  /* pieces taken in idle */
    atomic_uint idle_calls[OB_MAX_WORKERS + 1];
} help_probe;

static bool help_take(help_probe *p, uint32_t i)
{
    uint32_t ready = atomic_load_explicit(&p->ready[i], memory_order_acquire);
    uint32_t k = atomic_load(&p->next[i]);
    while (k < ready)
        if (atomic_compare_exchange_weak(&p->next[i], &k, k + 1)) {
            atomic_fetch_add(&p->done[i][k], 1);
            atomic_fetch_sub_explicit(&p->left, 1, memory_order_release);
            return true;
        }
    return false;
}

static void help_task(void *user, uint32_t i, uint32_t thread)
{
    (void)thread;
    help_probe *p = user;
    atomic_store_explicit(&p->ready[i], PIECES, memory_order_release);
    while (help_take(p, i)) {}
}

static bool help_idle(void *user, uint32_t thread)
{
    help_probe *p = user;
    atomic_fetch_add(&p->idle_calls[OB_MIN(thread, (uint32_t)OB_MAX_WORKERS)], 1);
    for (uint32_t i = 0; i < HELP_INDICES; i++)
        if (help_take(p, i)) {
            atomic_fetch_add(&p->helped, 1);
            return true;
        }
    return false;
}

static void helped_loops_do_every_piece_once(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4});
    static help_probe p;
    for (uint32_t n = 1; n <= 4; n++) {
        assert_int_equal(ob_renderer_set_threading(w.r, OB_THREADING_MULTI, n), OB_OK);
        for (uint32_t round = 0; round < 20; round++) {
            memset(&p, 0, sizeof p);
            atomic_store(&p.left, HELP_INDICES * PIECES);
            ob_parallel par = ob_renderer_parallel(w.r);
            ob_parallel_run_helped(&par, HELP_INDICES, help_task, help_idle, &p);
            assert_int_equal(atomic_load_explicit(&p.left, memory_order_acquire), 0);
            for (uint32_t i = 0; i < HELP_INDICES; i++)
                for (uint32_t k = 0; k < PIECES; k++)
                    if (atomic_load(&p.done[i][k]) != 1)
                        fail_msg("%u threads: piece %u of index %u done %u times", n, k, i,
                                 atomic_load(&p.done[i][k]));
            /* Every thread of the loop asked for help before it left; the
             * caller at least once, whatever the thread count. */
            assert_true(atomic_load(&p.idle_calls[0]) >= 1);
            for (uint32_t t = n; t <= OB_MAX_WORKERS; t++) assert_int_equal(atomic_load(&p.idle_calls[t]), 0);
        }
    }
    ob_test_world_destroy(&w);
}

/* Renderer creation failing at each host allocation and each Vulkan object
 * creation in turn: a NULL renderer and an error, no thread left running, no
 * memory left (ASan), no validation message from the half-built device. */
static void failed_creation_leaves_no_worker_behind(void **state)
{
    (void)state;
    static const ob_fault_kind kinds[] = {OB_FAULT_HOST_ALLOC, OB_FAULT_VK_OBJECT};
    /* One instance for the whole walk (ob_test_adopt.h says why); the
     * instance's own creation points are test_device's. Its driver threads
     * (lavapipe's rasterizers) are part of the baseline. */
    ob_test_vulkan tv;
    ob_test_vulkan_create(&tv);
    uint32_t base = baseline_threads();
    for (size_t k = 0; k < OB_ARRAY_COUNT(kinds); k++) {
        ob_renderer_desc rd = {.device = {.app_name = "obelisk-test", .validation = 1, .adopt = &tv.handles},
                               .worker_count = 4};
        ob_result r;
        ob_fault_arm(kinds[k], 0);
        ob_renderer *ren = ob_renderer_create(&rd, &r);
        assert_non_null(ren);
        uint64_t points = ob_fault_count(kinds[k]);
        ob_renderer_destroy(ren);
        assert_true(points > 0);
        uint32_t failed = 0;
        for (uint64_t nth = 1; nth <= points; nth++) {
            ob_fault_arm(kinds[k], nth);
            ren = ob_renderer_create(&rd, &r);
            bool hit = ob_fault_hit(kinds[k]);
            ob_fault_arm(kinds[k], 0);
            if (ren) {
                /* A failure the renderer could live with (a debug name, say). */
                ob_validation_counts vc = ob_device_validation_counts(ob_renderer_device(ren));
                assert_int_equal(vc.errors + vc.warnings, 0);
                ob_renderer_destroy(ren);
            } else {
                assert_true(hit);
                assert_int_not_equal(r, OB_OK);
                failed++;
            }
            if (thread_count() != base)
                fail_msg("fault %zu at point %llu: %u threads, %u before", k,
                         (unsigned long long)nth, thread_count(), base);
        }
        assert_true(failed > 0);
    }
    ob_test_vulkan_destroy(&tv);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(worker_pool_starts_and_stops_with_the_renderer),
        cmocka_unit_test(threading_change_takes_effect_at_next_frame),
        cmocka_unit_test(only_active_workers_record),
        cmocka_unit_test(auto_measures_both_ways),
        cmocka_unit_test(parallel_loops_run_each_index_once),
        cmocka_unit_test(helped_loops_do_every_piece_once),
        cmocka_unit_test(failed_creation_leaves_no_worker_behind),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
