/* A lost device, or a queue that runs out of memory, in the middle of work.
 *
 * OB_FAULT_DEVICE_LOST makes a queue submission or a wait (frame fence,
 * device idle, one-shot upload) report VK_ERROR_DEVICE_LOST; a submission
 * it hits is not made, a wait it hits has really waited. OB_FAULT_SUBMIT_OOM
 * makes a submission report VK_ERROR_OUT_OF_DEVICE_MEMORY without making it.
 *
 * What a user must see: the call that met the loss returns
 * OB_ERR_DEVICE_LOST and the log says so; every later frame, upload and
 * read-back is refused with OB_ERR_DEVICE_LOST (and a log line); the
 * renderer and everything on it can still be destroyed, with the validation
 * layer silent and nothing leaked. A submission that ran out of memory is a
 * failed frame, not a lost device: the next frame draws exactly what an
 * undisturbed run draws.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_stack.h"


#define REFERENCE_FRAMES 5u

typedef struct fixture {
    uint8_t *reference[REFERENCE_FRAMES];   /* image after frame k, undisturbed */
    uint32_t width, height;
} fixture;

static void start(ob_test_stack *s)
{
    ob_result r = ob_test_stack_start(s, NULL);
    if (r == OB_OK) r = ob_test_stack_build_scene(s);
    if (r != OB_OK) fail_msg("set-up: %s", ob_result_name(r));
}

/* Destroys the stack and fails the test if the validation layer spoke at
 * any time since the log was last cleared (destruction included). */
static void stop_clean(ob_test_stack *s)
{
    ob_test_stack_stop(s);
    if (ob_test_log_has("[vk-validation]", NULL)) {
        ob_test_log_dump(OB_LOG_WARN, 40);
        fail_msg("the validation layer reported a problem");
    }
}

static uint8_t *read_image(ob_test_stack *s)
{
    uint8_t *img = malloc((size_t)s->width * s->height * 4);
    assert_non_null(img);
    ob_result r = ob_test_stack_read(s, img);
    if (r != OB_OK) fail_msg("read-back: %s", ob_result_name(r));
    return img;
}

static void assert_same_as_reference(const fixture *fx, ob_test_stack *s)
{
    assert_true(s->frames >= 1 && s->frames <= REFERENCE_FRAMES);
    uint8_t *img = read_image(s);
    uint32_t diff = ob_test_image_max_diff(img, fx->reference[s->frames - 1], s->width, s->height);
    free(img);
    if (diff) fail_msg("frame %llu differs from an undisturbed run by %u", (unsigned long long)s->frames - 1, diff);
}

/* The device is lost: everything that would use it says so. */
static void assert_refused(ob_test_stack *s)
{
    assert_true(ob_device_is_lost(s->world.dev));
    ob_test_log_clear();
    assert_int_equal(ob_test_stack_frame(s, OB_THREADING_SINGLE, 0), OB_ERR_DEVICE_LOST);
    assert_true(ob_test_log_has("[renderer]", "device is lost", NULL));
    assert_int_equal(ob_test_stack_frame(s, OB_THREADING_MULTI, 0), OB_ERR_DEVICE_LOST);
    assert_int_equal(ob_renderer_wait_idle(s->world.r), OB_ERR_DEVICE_LOST);

    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){1, 1, 1}, &m), OB_OK);
    ob_result r;
    ob_geometry *g = ob_geometry_create(s->world.dev, &(ob_geometry_desc){.mesh = &m, .name = "late"}, &r);
    ob_mesh_release(&m);
    assert_null(g);
    assert_int_equal(r, OB_ERR_DEVICE_LOST);

    uint8_t *img = malloc((size_t)s->width * s->height * 4);
    assert_non_null(img);
    assert_int_equal(ob_test_stack_read(s, img), OB_ERR_DEVICE_LOST);
    free(img);
}

/* Arms kind to fire at its first point after `frames` good frames, inside
 * the next frame's recording and submission (after its PreRender). */
static ob_result frame_failing_at_submit(ob_test_stack *s, ob_threading mode, ob_fault_kind kind)
{
    ob_result r = ob_test_stack_frame_begin(s, mode, 0);
    if (r != OB_OK) fail_msg("frame %llu did not begin: %s", (unsigned long long)s->frames - 1, ob_result_name(r));
    ob_test_log_clear();
    ob_fault_arm(kind, 1);
    r = ob_renderer_end_frame(s->world.r);
    bool hit = ob_fault_hit(kind);
    ob_fault_arm(kind, 0);
    assert_true(hit);
    return r;
}

static void lost_at_submit(ob_threading mode)
{
    ob_test_stack s;
    start(&s);
    assert_int_equal(ob_test_stack_frame(&s, mode, 0), OB_OK);
    assert_int_equal(frame_failing_at_submit(&s, mode, OB_FAULT_DEVICE_LOST), OB_ERR_DEVICE_LOST);
    assert_true(ob_test_log_has("[device]", "lost", NULL));
    assert_true(ob_test_log_has("[renderer]", "not submitted", NULL));
    assert_refused(&s);
    stop_clean(&s);
}

static void lost_at_submit_st(void **state) { (void)state; lost_at_submit(OB_THREADING_SINGLE); }
static void lost_at_submit_mt(void **state) { (void)state; lost_at_submit(OB_THREADING_MULTI); }

/* The frame fence wait at begin_frame reports the loss. */
static void lost_at_frame_wait(void **state)
{
    (void)state;
    ob_test_stack s;
    start(&s);
    assert_int_equal(ob_test_stack_frame(&s, OB_THREADING_SINGLE, 0), OB_OK);
    assert_int_equal(ob_test_stack_frame(&s, OB_THREADING_SINGLE, 0), OB_OK);
    ob_test_log_clear();
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 1);
    ob_result r = ob_test_stack_frame_begin(&s, OB_THREADING_SINGLE, 0);
    assert_true(ob_fault_hit(OB_FAULT_DEVICE_LOST));
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 0);
    assert_int_equal(r, OB_ERR_DEVICE_LOST);
    assert_true(ob_test_log_has("[device]", "lost", NULL));
    assert_true(ob_test_log_has("[renderer]", "waiting for frame slot", NULL));
    assert_refused(&s);
    stop_clean(&s);
}

/* ob_renderer_wait_idle after a submitted frame reports the loss. */
static void lost_at_wait_idle(void **state)
{
    (void)state;
    ob_test_stack s;
    start(&s);
    assert_int_equal(ob_test_stack_frame_begin(&s, OB_THREADING_MULTI, 0), OB_OK);
    assert_int_equal(ob_renderer_end_frame(s.world.r), OB_OK);
    ob_test_log_clear();
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 1);
    ob_result r = ob_renderer_wait_idle(s.world.r);
    assert_true(ob_fault_hit(OB_FAULT_DEVICE_LOST));
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 0);
    assert_int_equal(r, OB_ERR_DEVICE_LOST);
    assert_true(ob_test_log_has("[device]", "lost", NULL));
    assert_refused(&s);
    stop_clean(&s);
}

/* A geometry upload's one-shot submission meets the loss. */
static void lost_during_upload(void **state)
{
    (void)state;
    ob_test_stack s;
    start(&s);
    assert_int_equal(ob_test_stack_frame(&s, OB_THREADING_SINGLE, 0), OB_OK);
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_sphere(1.0f, 8, 6, &m), OB_OK);
    ob_test_log_clear();
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 1);
    ob_result r;
    ob_geometry *g = ob_geometry_create(s.world.dev, &(ob_geometry_desc){.mesh = &m, .name = "ball"}, &r);
    assert_true(ob_fault_hit(OB_FAULT_DEVICE_LOST));
    ob_fault_arm(OB_FAULT_DEVICE_LOST, 0);
    ob_mesh_release(&m);
    assert_null(g);
    assert_int_equal(r, OB_ERR_DEVICE_LOST);
    assert_true(ob_test_log_has("[device]", "lost", NULL));
    assert_refused(&s);
    stop_clean(&s);
}

/* The first frame (every target still UNDEFINED) and a later one fail to
 * submit; the frame after each is the undisturbed picture. */
static void submit_oom(fixture *fx, ob_threading mode)
{
    for (uint32_t fail_at = 0; fail_at < 3; fail_at += 2) {
        ob_test_stack s;
        start(&s);
        while (s.frames < fail_at) assert_int_equal(ob_test_stack_frame(&s, mode, 0), OB_OK);
        ob_result r = frame_failing_at_submit(&s, mode, OB_FAULT_SUBMIT_OOM);
        assert_int_equal(r, OB_ERR_OUT_OF_DEVICE_MEMORY);
        assert_true(ob_test_log_has("[renderer]", "not submitted", NULL));
        assert_false(ob_device_is_lost(s.world.dev));
        assert_int_equal(ob_renderer_wait_idle(s.world.r), OB_OK);
        assert_int_equal(ob_test_stack_frame(&s, mode, 0), OB_OK);
        assert_same_as_reference(fx, &s);
        assert_int_equal(ob_test_stack_frame(&s, mode, 0), OB_OK);
        assert_same_as_reference(fx, &s);
        stop_clean(&s);
    }
}

static void submit_oom_st(void **state) { submit_oom(*state, OB_THREADING_SINGLE); }
static void submit_oom_mt(void **state) { submit_oom(*state, OB_THREADING_MULTI); }

/* Every submission and wait of a scene build, three frames and a read-back
 * in turn: wherever the loss is met, what follows is refused and the
 * teardown is clean. */
static void device_loss_walk(void **state)
{
    (void)state;
    uint64_t count = 0, lost_in_build = 0, lost_in_frames = 0;
    for (uint64_t n = 0; n == 0 || n <= count; n++) {
        ob_test_stack s;
        ob_result r = ob_test_stack_start(&s, NULL);
        if (r != OB_OK) fail_msg("start-up: %s", ob_result_name(r));
        ob_test_log_clear();
        ob_fault_arm(OB_FAULT_DEVICE_LOST, n);
        r = ob_test_stack_build_scene(&s);
        bool lost_building = r != OB_OK;
        if (lost_building) assert_int_equal(r, OB_ERR_DEVICE_LOST);
        bool lost = lost_building;
        for (int f = 0; f < 3 && !lost_building; f++) {
            r = ob_test_stack_frame(&s, f == 1 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            if (lost) assert_int_equal(r, OB_ERR_DEVICE_LOST);   /* refused */
            else if (r != OB_OK) {
                assert_int_equal(r, OB_ERR_DEVICE_LOST);
                lost = true;
            }
        }
        if (!lost_building) {
            uint8_t *img = malloc((size_t)s.width * s.height * 4);
            assert_non_null(img);
            r = ob_test_stack_read(&s, img);
            free(img);
            if (lost || r != OB_OK) assert_int_equal(r, OB_ERR_DEVICE_LOST);
            lost = lost || r != OB_OK;
        }
        bool hit = ob_fault_hit(OB_FAULT_DEVICE_LOST);
        if (n == 0) count = ob_fault_count(OB_FAULT_DEVICE_LOST);
        ob_fault_arm(OB_FAULT_DEVICE_LOST, 0);
        if (n > 0) {
            if (!hit) fail_msg("point %llu of %llu never reached", (unsigned long long)n, (unsigned long long)count);
            if (!lost) fail_msg("point %llu: the loss was not reported", (unsigned long long)n);
            assert_true(ob_device_is_lost(s.world.dev));
            assert_true(ob_test_log_has("[device]", "lost", NULL));
            lost_in_build += lost_building;
            lost_in_frames += !lost_building;
        } else {
            assert_false(lost);
        }
        stop_clean(&s);
    }
    assert_true(count > 0);
    printf("[ loss     ] %llu submission/wait points walked: %llu during the scene's uploads, %llu in "
           "frames or the read-back\n", (unsigned long long)count, (unsigned long long)lost_in_build,
           (unsigned long long)lost_in_frames);
}

/* Every submission of the same run failing for memory: an upload fails
 * cleanly; a frame is lost, and the frame after it is the undisturbed one. */
static void submit_oom_walk(void **state)
{
    fixture *fx = *state;
    uint64_t count = 0, failed_uploads = 0, failed_frames = 0;
    for (uint64_t n = 0; n == 0 || n <= count; n++) {
        ob_test_stack s;
        ob_result r = ob_test_stack_start(&s, NULL);
        if (r != OB_OK) fail_msg("start-up: %s", ob_result_name(r));
        ob_test_log_clear();
        ob_fault_arm(OB_FAULT_SUBMIT_OOM, n);
        r = ob_test_stack_build_scene(&s);
        bool upload_failed = r != OB_OK;
        uint32_t frame_failures = 0;
        for (int f = 0; f < 3 && !upload_failed; f++) {
            r = ob_test_stack_frame(&s, f == 1 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            if (r != OB_OK) {
                assert_int_equal(r, OB_ERR_OUT_OF_DEVICE_MEMORY);
                frame_failures++;
            }
        }
        bool hit = ob_fault_hit(OB_FAULT_SUBMIT_OOM);
        if (n == 0) count = ob_fault_count(OB_FAULT_SUBMIT_OOM);
        ob_fault_arm(OB_FAULT_SUBMIT_OOM, 0);
        if (upload_failed) {
            assert_int_equal(r, OB_ERR_OUT_OF_DEVICE_MEMORY);
            failed_uploads++;
        } else {
            failed_frames += frame_failures;
            /* The frame after: the picture an undisturbed run shows. */
            assert_int_equal(ob_test_stack_frame(&s, OB_THREADING_SINGLE, 0), OB_OK);
            assert_same_as_reference(fx, &s);
        }
        if (n > 0 && !hit) fail_msg("point %llu of %llu never reached", (unsigned long long)n, (unsigned long long)count);
        if (n > 0 && !ob_test_log_has("out of device memory", NULL) &&
            !ob_test_log_has("VK_ERROR_OUT_OF_DEVICE_MEMORY", NULL))
            fail_msg("point %llu: the failure was not logged", (unsigned long long)n);
        assert_false(ob_device_is_lost(s.world.dev));
        stop_clean(&s);
    }
    assert_true(count > 0);
    printf("[ loss     ] %llu submission points failed for memory: %llu uploads failed cleanly, %llu "
           "frames failed and the next one matched\n", (unsigned long long)count,
           (unsigned long long)failed_uploads, (unsigned long long)failed_frames);
}

static int setup(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    if (!fx) return -1;
    ob_test_stack s;
    start(&s);
    fx->width = s.width;
    fx->height = s.height;
    for (uint32_t f = 0; f < REFERENCE_FRAMES; f++) {
        ob_result r = ob_test_stack_frame(&s, OB_THREADING_SINGLE, 0);
        if (r != OB_OK) fail_msg("reference frame %u: %s", f, ob_result_name(r));
        fx->reference[f] = read_image(&s);
    }
    stop_clean(&s);
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture *fx = *state;
    if (!fx) return 0; /* setup failed */
    for (uint32_t f = 0; f < REFERENCE_FRAMES; f++) free(fx->reference[f]);
    free(fx);
    return 0;
}

int main(void)
{
    ob_test_setup_log();
    /* The walks log an expected error per point; keep them for the asserts. */
    ob_test_log_set_echo(getenv("OB_FAULT_ECHO") != NULL);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lost_at_submit_st),
        cmocka_unit_test(lost_at_submit_mt),
        cmocka_unit_test(lost_at_frame_wait),
        cmocka_unit_test(lost_at_wait_idle),
        cmocka_unit_test(lost_during_upload),
        cmocka_unit_test(submit_oom_st),
        cmocka_unit_test(submit_oom_mt),
        cmocka_unit_test(device_loss_walk),
        cmocka_unit_test(submit_oom_walk),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
