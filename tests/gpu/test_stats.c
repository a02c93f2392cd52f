/* What ob_renderer.h says about the stats a program reads: which frame a
 * callback reports and when it comes (frames in flight late, from
 * begin_frame; the last ones from wait_idle), that the engine's CPU work and
 * the waiting are separate parts of the frame, and the threading mode's
 * name. A user reading the demos' per-frame lines relies on all three. */
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

typedef struct arrival {
    uint64_t frame;       /* stats->frame */
    uint64_t serial;      /* ob_renderer_frame_serial during the call */
    ob_frame_stats st;
} arrival;

typedef struct recorder {
    ob_renderer *r;
    arrival got[16];
    uint32_t count;
} recorder;

static void on_stats(void *user, const ob_frame_stats *st)
{
    recorder *rec = user;
    if (rec->count < 16)
        rec->got[rec->count++] = (arrival){st->frame, ob_renderer_frame_serial(rec->r), *st};
}

static void stats_arrive_frames_in_flight_late(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.7f, 0.7f, 0.7f, false);
    ob_world_entity(&w, NULL, "box", w.box, m, 0, 0, 0);
    ob_world_look(&w, 2, 2, 3, 0, 0, 0);
    recorder *rec = calloc(1, sizeof *rec);   /* 16 whole ob_frame_stats: 370 KB */
    assert_non_null(rec);
    rec->r = w.r;
    ob_renderer_set_stats_callback(w.r, on_stats, rec);
    const uint32_t in_flight = ob_device_frames_in_flight(w.dev);
    assert_true(in_flight >= 1);
    const uint32_t frames = 6;
    uint64_t first = ob_renderer_frame_serial(w.r) + 1;
    for (uint32_t f = 0; f < frames; f++) {
        ob_renderer_set_threading(w.r, f % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_stack_frame_begin(w.stack, 1.0 / 60.0), OB_OK);
        /* Frame first + f is being recorded: only frames in_flight back are reported. */
        uint32_t expect = f + 1 > in_flight ? f + 1 - in_flight : 0;
        assert_int_equal(rec->count, expect);
        ob_views_render(w.views, w.stack->final_view);
        assert_int_equal(ob_renderer_end_frame(w.r), OB_OK);
    }
    for (uint32_t i = 0; i < rec->count; i++) {
        assert_int_equal(rec->got[i].frame, first + i);
        /* Called from the begin_frame of frame + in_flight, before its serial moves. */
        assert_int_equal(rec->got[i].serial, rec->got[i].frame + in_flight - 1);
    }
    uint32_t before_idle = rec->count;
    assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
    assert_int_equal(rec->count, frames);   /* the rest from wait_idle, in order */
    for (uint32_t i = before_idle; i < rec->count; i++) assert_int_equal(rec->got[i].frame, first + i);
    assert_int_equal(ob_renderer_last_stats(w.r)->frame, first + frames - 1);

    /* Work and waiting: the sums are what the header says, the waits are
     * parts of begin_frame, and neither overlaps the other within the frame. */
    for (uint32_t i = 0; i < rec->count; i++) {
        const ob_frame_stats *st = &rec->got[i].st;
        assert_int_equal(ob_frame_stats_cpu_work_ns(st),
                         st->update_ns + st->pre_render_ns + st->record_ns + st->assemble_ns + st->submit_ns);
        assert_int_equal(ob_frame_stats_wait_ns(st), st->gpu_wait_ns + st->acquire_ns + st->present_ns);
        assert_int_equal(st->acquire_ns, 0);   /* headless */
        assert_int_equal(st->present_ns, 0);
        assert_true(st->gpu_wait_ns <= st->wait_ns);
        assert_true(ob_frame_stats_cpu_work_ns(st) + ob_frame_stats_wait_ns(st) <= st->frame_ns);
        assert_true(st->record_ns + st->assemble_ns > 0);
    }
    ob_renderer_set_stats_callback(w.r, NULL, NULL);
    free(rec);
    ob_test_world_destroy(&w);
}

static void threading_modes_have_names(void **state)
{
    (void)state;
    assert_string_equal(ob_threading_name(OB_THREADING_SINGLE), "single");
    assert_string_equal(ob_threading_name(OB_THREADING_MULTI), "multi");
    assert_string_equal(ob_threading_name(OB_THREADING_AUTO), "auto");
    assert_string_equal(ob_threading_name((ob_threading)42), "unknown");
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stats_arrive_frames_in_flight_late),
        cmocka_unit_test(threading_modes_have_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
