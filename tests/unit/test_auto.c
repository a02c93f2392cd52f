/* OB_THREADING_AUTO's choice (engine/ob_auto.c), driven the way the renderer
 * drives it, with made-up costs: which way it takes, how often it pays for
 * re-measuring the other, and how fast it follows a change. */
#include "ob_test.h"

#include "ob_auto_internal.h"

#include <stdint.h>

typedef struct sim {
    ob_auto_state s;
    ob_record_cost way[2];      /* [0] inline, [1] workers */
    uint32_t probes;
} sim;

/* One AUTO frame of `draws` draws, each way costing its ps per draw: the
 * choice, then the frame's cost noted as the renderer notes it. Returns the
 * way the frame recorded (true = the workers). */
static bool frame(sim *m, uint64_t inline_ps, uint64_t workers_ps, uint32_t draws)
{
    bool workers = ob_auto_choose(&m->s, &m->way[0], &m->way[1]);
    if (m->s.probing) m->probes++;
    uint64_t ps = workers ? workers_ps : inline_ps;
    ob_record_cost_note(&m->way[workers], ps * draws / 1000u, draws);
    m->way[!workers].age++;
    return workers;
}

/* Each way is measured once first; then the cheaper one is kept. */
static void measures_both_ways_then_keeps_the_cheaper(void **state)
{
    (void)state;
    sim m = {0};
    assert_false(frame(&m, 180000, 100000, 1000));
    assert_true(frame(&m, 180000, 100000, 1000));
    for (int f = 0; f < 20; f++) assert_true(frame(&m, 180000, 100000, 1000));
    m = (sim){0};
    frame(&m, 100000, 180000, 1000);
    frame(&m, 100000, 180000, 1000);
    for (int f = 0; f < 20; f++) assert_false(frame(&m, 100000, 180000, 1000));
}

/* Two slow frames of the chosen way in a row (a late wake-up, a preempted
 * worker) do not turn the choice; three in a row do, and the way comes back
 * once its frames are fast again. */
static void slow_frames_decide_nothing_unless_they_last(void **state)
{
    (void)state;
    sim m = {0};
    for (int f = 0; f < 100; f++) frame(&m, 180000, 100000, 1000);
    for (int f = 0; f < 2; f++) assert_true(frame(&m, 180000, 400000, 1000));
    assert_true(frame(&m, 180000, 100000, 1000));
    for (int f = 0; f < 3; f++) assert_true(frame(&m, 180000, 400000, 1000));
    assert_false(frame(&m, 180000, 400000, 1000));
    /* On inline now: the workers are re-measured after 32 frames. */
    int back = -1;
    for (int f = 0; f < 40 && back < 0; f++)
        if (frame(&m, 180000, 100000, 1000) && !m.s.probing) back = f;
    assert_true(back >= 0);
}

/* A choice every probe confirms by a wide margin is re-measured less and
 * less often (32, 64, ... 512 frames): over 4000 frames some ten probes,
 * where a fixed 32-frame interval takes some 120, each at the dearer way's
 * cost. It never stops re-measuring. */
static void a_clear_choice_is_re_measured_less_often(void **state)
{
    (void)state;
    sim m = {0};
    uint32_t inline_frames = 0;
    for (int f = 0; f < 4000; f++) inline_frames += !frame(&m, 180000, 100000, 1000);
    assert_true(m.probes >= 5);
    assert_true(m.probes <= 12);
    assert_int_equal(inline_frames, m.probes + 1);   /* the first frame measured inline */
    assert_int_equal(ob_auto_remeasure_interval(&m.s), 512);
}

/* Ways within the clear margin (10% apart) keep the short interval: a
 * change there could turn the choice any frame. */
static void close_ways_keep_the_short_interval(void **state)
{
    (void)state;
    sim m = {0};
    for (int f = 0; f < 4000; f++) {
        bool workers = frame(&m, 110000, 100000, 1000);
        assert_true(workers || m.s.probing || f == 0);
    }
    assert_int_equal(ob_auto_remeasure_interval(&m.s), 32);
    assert_true(m.probes >= 100);
}

/* After backing off, a way that became cheaper is still found by the next
 * probe (its figure is the fastest of its last three frames). */
static void a_change_is_followed_after_backing_off(void **state)
{
    (void)state;
    sim m = {0};
    for (int f = 0; f < 2000; f++) frame(&m, 180000, 100000, 1000);
    assert_int_equal(ob_auto_remeasure_interval(&m.s), 512);
    int switched = -1;
    for (int f = 0; f < 1200 && switched < 0; f++) {
        frame(&m, 60000, 100000, 1000);
        if (!m.s.way) switched = f;
    }
    assert_true(switched >= 0);
    assert_true(switched <= 512 + 2);
    /* It stays there. */
    for (int f = 0; f < 100; f++) {
        bool workers = frame(&m, 60000, 100000, 1000);
        assert_true(!workers || m.s.probing);
    }
}

/* A scene that changes size re-measures the other way within a few
 * frames (the draw count is smoothed), whatever the interval had grown to. */
static void a_resized_scene_is_re_measured_at_once(void **state)
{
    (void)state;
    sim m = {0};
    for (int f = 0; f < 2000; f++) frame(&m, 180000, 100000, 1000);
    assert_int_equal(ob_auto_remeasure_interval(&m.s), 512);
    uint32_t before = m.probes;
    for (int f = 0; f < 4; f++) frame(&m, 180000, 100000, 3000);
    assert_true(m.probes > before);
}

/* A 16-core machine as the renderer drives AUTO with 16 workers: recording
 * on n workers costs work/n plus a hand-out cost that grows with n, so the
 * cheapest count lies inside the range, and inline costs the work alone. */
typedef struct count_sim {
    ob_auto_state s;
    ob_record_cost measured[17];   /* [0] inline, [n] n workers */
    uint32_t frames_at[17];
} count_sim;

static uint64_t cost_on(uint32_t workers, uint64_t work_ps, uint64_t per_worker_ps)
{
    return workers ? work_ps / workers + per_worker_ps * workers : work_ps;
}

/* One AUTO frame as begin_frame and the recording take it (ob_renderer.c,
 * ob_renderer_record.c); returns the worker count it recorded with (0:
 * inline). */
static uint32_t count_frame(count_sim *m, uint64_t work_ps, uint64_t per_worker_ps,
                            uint32_t draws)
{
    uint32_t best = ob_auto_best_workers(&m->s, m->measured, 16);
    bool multi = ob_auto_choose(&m->s, &m->measured[0], &m->measured[best]);
    uint32_t n = multi && !m->s.probing ? ob_auto_probe_workers(&m->s, m->measured, 16)
                                        : best;
    uint32_t way = multi ? n : 0;
    ob_record_cost_note(&m->measured[way], cost_on(way, work_ps, per_worker_ps) * draws / 1000u,
                        draws);
    for (uint32_t i = 0; i <= 16; i++)
        if (i != way) m->measured[i].age++;
    m->frames_at[way]++;
    return way;
}

/* With 16 workers allowed and 8 the cheapest, AUTO measures its way down
 * from 16 to the cheapest count and records almost every frame there;
 * inline is measured first and then only re-measured with the usual
 * backing off (32, 64, ... 512 frames). */
static void auto_finds_the_cheapest_worker_count(void **state)
{
    (void)state;
    count_sim m = {0};
    /* work 1 600 000 ps, 20 000 ps per worker: 2 -> 840k, 4 -> 480k,
     * 8 -> 360k, 16 -> 420k (per 1000 draws' ps, as cost_on gives). */
    for (int f = 0; f < 2000; f++) count_frame(&m, 1600000, 20000, 1000);
    assert_int_equal(m.s.workers, 8);
    assert_true(m.frames_at[8] > 1900);
    assert_true(m.frames_at[0] >= 1 && m.frames_at[0] <= 10);
    /* The neighbours are re-measured now and then, never the far counts. */
    assert_true(m.frames_at[4] >= 2 && m.frames_at[4] <= 12);
    assert_true(m.frames_at[16] >= 2 && m.frames_at[16] <= 12);
    assert_true(m.frames_at[2] <= 3);
}

/* When the scene grows so that more workers pay, the count follows. */
static void the_worker_count_follows_a_growing_scene(void **state)
{
    (void)state;
    count_sim m = {0};
    for (int f = 0; f < 600; f++) count_frame(&m, 1600000, 20000, 1000);
    assert_int_equal(m.s.workers, 8);
    /* Four times the draws, each four times the work: 16 workers win. */
    for (int f = 0; f < 600; f++) count_frame(&m, 6400000, 20000, 4000);
    assert_int_equal(m.s.workers, 16);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(measures_both_ways_then_keeps_the_cheaper),
        cmocka_unit_test(slow_frames_decide_nothing_unless_they_last),
        cmocka_unit_test(a_clear_choice_is_re_measured_less_often),
        cmocka_unit_test(close_ways_keep_the_short_interval),
        cmocka_unit_test(a_change_is_followed_after_backing_off),
        cmocka_unit_test(a_resized_scene_is_re_measured_at_once),
        cmocka_unit_test(auto_finds_the_cheapest_worker_count),
        cmocka_unit_test(the_worker_count_follows_a_growing_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
