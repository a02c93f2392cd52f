/* Fault-injection walk: every host allocation (ob_malloc & co.) and every
 * Vulkan creation or allocation (OB_VK_CREATE) of start-up, scene building,
 * a first frame and a steady-state frame is failed in turn.
 *
 * Each phase is run once unarmed to count its points, then once per point
 * with that point failing. What a user must see every time: the failing
 * call returns an error result and says why in the log, or the frame goes on
 * without what failed (a view or draw skipped, logged); nothing crashes,
 * hangs or leaks (the address-sanitizer build is the leak proof, the
 * validation layer's object tracking the proof for Vulkan objects); the
 * validation layer stays silent; everything can be destroyed; and the next,
 * unarmed frame shows exactly the picture of a run that never failed — a
 * failed allocation is a transient condition, never a sticky one.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_adopt.h"
#include "ob_test_stack.h"


typedef enum phase {
    PHASE_START,        /* renderer, effects, materials, views: create then destroy */
    PHASE_SCENE,        /* scene, views, geometry uploads, materials, particle system */
    PHASE_FIRST_FRAME,  /* lazy variants, pipelines, targets, rings */
    PHASE_STEADY_FRAME, /* the third frame: nothing left to create */
    PHASE_COUNT
} phase;

static const char *const phase_names[PHASE_COUNT] = {"start-up", "scene", "first frame",
                                                     "steady frame"};
static const char *const kind_names[OB_FAULT_KIND_COUNT] = {"host allocation", "Vulkan object",
                                                           "device lost", "submit OOM"};

/* The frame compared after a fault: the one right after the armed step. */
#define CHECK_FRAME_FIRST 1u
#define CHECK_FRAME_STEADY 3u
#define STEADY_FRAME 2u

typedef struct outcome {
    ob_result result;       /* of the armed step */
    bool hit;               /* the armed point fired */
    uint64_t count;         /* fault points seen while armed */
    uint64_t before_record; /* of which before the frame's recording began */
    bool logged;            /* an error or warning line was written */
    bool validation;        /* the validation layer said something */
    bool after_ok;          /* the frame after the fault rendered */
    bool after_checked;     /* ... and its image was compared */
    uint32_t after_diff;    /* largest channel difference against the reference */
    ob_result after_result;
} outcome;

typedef struct reference {
    uint8_t *first, *steady;   /* images of frames CHECK_FRAME_FIRST and CHECK_FRAME_STEADY */
    uint32_t width, height;
    /* Every stack of the walks on one instance (ob_test_adopt.h: a real
     * driver does not survive an instance per point; test_device walks the
     * points of instance and device creation). */
    ob_test_vulkan tv;
    ob_env_map_kind env_map_kind;  /* of the stacks walked against this reference */
} reference;

static ob_threading mode_of(bool multi) { return multi ? OB_THREADING_MULTI : OB_THREADING_SINGLE; }

/* Frames 0..upto-1 in `mode`. */
static ob_result frames(ob_test_stack *s, ob_threading mode, uint32_t upto)
{
    ob_result r = OB_OK;
    while (r == OB_OK && s->frames < upto) r = ob_test_stack_frame(s, mode, 0);
    return r;
}

static void dump_ppm(const char *prefix, const char *what, const uint8_t *rgba, uint32_t w, uint32_t h)
{
    char path[512];
    snprintf(path, sizeof path, "%s-%s.ppm", prefix, what);
    FILE *f = fopen(path, "wb");
    if (!f) return;
    fprintf(f, "P6 %u %u 255\n", w, h);
    for (size_t i = 0; i < (size_t)w * h; i++) fwrite(rgba + 4 * i, 1, 3, f);
    fclose(f);
}

static void compare_after(ob_test_stack *s, ob_threading mode, uint32_t frame, const uint8_t *ref,
                          outcome *o)
{
    /* Frames between the fault and the compared one still run (time moves on). */
    o->after_result = OB_OK;
    while (o->after_result == OB_OK && s->frames <= frame)
        o->after_result = ob_test_stack_frame(s, mode, 0);
    o->after_ok = o->after_result == OB_OK;
    if (!o->after_ok || !ref) return;
    uint8_t *img = malloc((size_t)s->width * s->height * 4);
    assert_non_null(img);
    o->after_result = ob_test_stack_read(s, img);
    o->after_ok = o->after_result == OB_OK;
    if (o->after_ok) {
        o->after_checked = true;
        o->after_diff = ob_test_image_max_diff(img, ref, s->width, s->height);
        if (o->after_diff && getenv("OB_FAULT_DUMP")) {
            /* OB_FAULT_DUMP=prefix: the differing frame and its reference as PPM. */
            dump_ppm(getenv("OB_FAULT_DUMP"), "after", img, s->width, s->height);
            dump_ppm(getenv("OB_FAULT_DUMP"), "reference", ref, s->width, s->height);
        }
    }
    free(img);
}

/* Runs `ph` with the nth point of `kind` failing (0: none, to count). */
static void run_phase(phase ph, bool multi, ob_fault_kind kind, uint64_t nth, const reference *ref,
                      outcome *o)
{
    memset(o, 0, sizeof *o);
    ob_test_log_clear();
    ob_threading mode = mode_of(multi);
    ob_test_stack s;
    ob_result r = OB_OK;
    if (ph == PHASE_START) {
        ob_fault_arm(kind, nth);
        r = ob_test_stack_start(&s, &(ob_test_stack_desc){.adopt = &ref->tv.handles, .env_map_kind = ref->env_map_kind});
        ob_test_stack_stop(&s);
        o->hit = ob_fault_hit(kind);
        o->count = ob_fault_count(kind);
        ob_fault_arm(kind, 0);
        o->result = r;
        o->after_ok = true;
    } else {
        r = ob_test_stack_start(&s, &(ob_test_stack_desc){.adopt = &ref->tv.handles, .env_map_kind = ref->env_map_kind});
        if (r != OB_OK) fail_msg("%s: unarmed start-up failed: %s", phase_names[ph], ob_result_name(r));
        if (ph != PHASE_SCENE) {
            r = ob_test_stack_build_scene(&s);
            if (r != OB_OK) fail_msg("%s: unarmed scene failed: %s", phase_names[ph], ob_result_name(r));
        }
        if (ph == PHASE_STEADY_FRAME) {
            r = frames(&s, mode, STEADY_FRAME);
            if (r != OB_OK) fail_msg("%s: unarmed frames failed: %s", phase_names[ph], ob_result_name(r));
        }
        ob_test_log_clear();
        ob_fault_arm(kind, nth);
        if (ph == PHASE_SCENE) r = ob_test_stack_build_scene(&s);
        else r = ob_test_stack_frame(&s, mode, 0);
        o->hit = ob_fault_hit(kind);
        o->count = ob_fault_count(kind);
        o->before_record = ph == PHASE_SCENE ? 0 : s.fault_points_before_record[kind];
        ob_fault_arm(kind, 0);
        o->result = r;
        /* What follows must not depend on the failure: a clean scene error
         * leaves nothing to render; otherwise the frame after renders. */
        if (ph == PHASE_SCENE && r == OB_OK)
            compare_after(&s, mode, CHECK_FRAME_FIRST, ref ? ref->first : NULL, o);
        else if (ph == PHASE_FIRST_FRAME)
            compare_after(&s, mode, CHECK_FRAME_FIRST, ref ? ref->first : NULL, o);
        else if (ph == PHASE_STEADY_FRAME)
            compare_after(&s, mode, CHECK_FRAME_STEADY, ref ? ref->steady : NULL, o);
        else
            o->after_ok = true;
        ob_test_stack_stop(&s);
    }
    o->logged = ob_test_log_count(OB_LOG_WARN) > 0;
    o->validation = ob_test_log_has("[vk-validation]", NULL);
}

static void make_reference(reference *ref)
{
    ob_test_stack s;
    ob_result r = ob_test_stack_start(&s, &(ob_test_stack_desc){.adopt = &ref->tv.handles, .env_map_kind = ref->env_map_kind});
    if (r == OB_OK) r = ob_test_stack_build_scene(&s);
    if (r != OB_OK) fail_msg("reference run: %s", ob_result_name(r));
    ref->width = s.width;
    ref->height = s.height;
    size_t size = (size_t)s.width * s.height * 4;
    ref->first = malloc(size);
    ref->steady = malloc(size);
    assert_true(ref->first && ref->steady);
    r = frames(&s, OB_THREADING_SINGLE, CHECK_FRAME_FIRST + 1);
    if (r == OB_OK) r = ob_test_stack_read(&s, ref->first);
    if (r == OB_OK) r = frames(&s, OB_THREADING_SINGLE, CHECK_FRAME_STEADY + 1);
    if (r == OB_OK) r = ob_test_stack_read(&s, ref->steady);
    if (r != OB_OK) fail_msg("reference frames: %s", ob_result_name(r));
    /* The walks cover the sun's shadow cascades (the creation of their
     * array map and each cascade view's PreRender and recording). */
    uint32_t shadow_draws = 0;
    assert_int_equal(ob_world_shadow_cascades(ob_renderer_last_stats(s.world.r), "sun",
                                              &shadow_draws), OB_SHADOW_DEFAULT_CASCADES);
    assert_true(shadow_draws > 0);
    ob_test_stack_stop(&s);
    assert_false(ob_test_log_has("[vk-validation]", NULL));
    /* The scene really draws something besides the clear colour. */
    uint32_t lit = 0;
    for (size_t i = 0; i < size; i += 4) lit += ref->steady[i] > 60;
    assert_true(lit > 50);
}

static void free_reference(reference *ref)
{
    free(ref->first);
    free(ref->steady);
}

typedef struct tally {
    uint64_t points, errors, degraded, broken;
    uint64_t by_result[OB_RESULT_COUNT];
} tally;

/* Every broken rule is listed, so one run shows all the points to fix. */
static void broken(tally *t, const char *where, ob_fault_kind kind, uint64_t n, const char *what)
{
    t->broken++;
    print_error("%s, %s point %llu: %s; its log:\n", where, kind_names[kind], (unsigned long long)n, what);
    ob_test_log_dump(OB_LOG_WARN, 24);
}

/* Walks every point of `kind` in `ph`; fails the test on the first broken rule. */
static void walk(phase ph, bool multi, ob_fault_kind kind, const reference *ref)
{
    /* Start-up creates and joins the worker threads (and unwinds a pool
     * half made): the thread sanitizer walks it. The rest of a
     * single-threaded walk runs on the render thread alone. */
    if (!multi && ph != PHASE_START) ob_test_skip_under_tsan("a single-threaded walk");
    outcome o;
    run_phase(ph, multi, kind, 0, ref, &o);
    if (o.result != OB_OK) fail_msg("%s: unarmed run failed: %s", phase_names[ph], ob_result_name(o.result));
    if (o.validation) fail_msg("%s: unarmed run: the validation layer spoke", phase_names[ph]);
    if (ph != PHASE_START && ph != PHASE_SCENE && o.after_checked && o.after_diff != 0)
        fail_msg("%s: unarmed run differs from the reference by %u", phase_names[ph], o.after_diff);
    const uint64_t count = o.count;
    /* Multi-threaded, the PreRender is the same render-thread code as
     * single-threaded (walked there): walk what differs, the recording. */
    const uint64_t first = multi ? o.before_record + 1 : 1;
    tally t = {.points = count - first + 1};
    /* OB_FAULT_POINT=n walks only point n (debugging a failure). */
    uint64_t only = getenv("OB_FAULT_POINT") ? strtoull(getenv("OB_FAULT_POINT"), NULL, 10) : 0;
    for (uint64_t n = only ? only : first; n <= (only ? only : count); n++) {
        run_phase(ph, multi, kind, n, ref, &o);
        const char *where = phase_names[ph];
        /* Multi-threaded recording interleaves the workers' points, so the
         * nth call of a run is not always the nth of the counting run. */
        if (!o.hit && !multi)
            broken(&t, where, kind, n, "never reached (the phase is not deterministic)");
        if (o.validation) broken(&t, where, kind, n, "the validation layer reported a problem");
        if (o.result != OB_OK) {
            t.errors++;
            t.by_result[o.result]++;
            if (!o.logged) broken(&t, where, kind, n, "returned an error without a log line");
        } else if (o.hit) {
            t.degraded++;
            if (!o.logged) broken(&t, where, kind, n, "failure absorbed silently (no log line)");
        }
        if (!o.after_ok) broken(&t, where, kind, n, "the next frame failed too");
        if (o.after_checked && o.after_diff != 0)
            broken(&t, where, kind, n, "the next frame differs from an undisturbed run");
    }
    printf("[ faults   ] %-12s %-2s %-15s: %4llu points walked (%llu..%llu of %llu), %4llu returned "
           "an error, %4llu degraded the frame (logged)",
           phase_names[ph], multi ? "MT" : "ST", kind_names[kind], (unsigned long long)t.points,
           (unsigned long long)first, (unsigned long long)count, (unsigned long long)count,
           (unsigned long long)t.errors, (unsigned long long)t.degraded);
    for (int r = 0; r < OB_RESULT_COUNT; r++)
        if (t.by_result[r]) printf(" %s x%llu", ob_result_name((ob_result)r), (unsigned long long)t.by_result[r]);
    printf("\n");
    fflush(stdout);
    if (t.broken) fail_msg("%s: %llu fault points broke a rule (listed above)", phase_names[ph],
                           (unsigned long long)t.broken);
}

/* The walks of a first and a steady frame with cube environment maps (six
 * layers, mips, a view of its own) against a reference made with them; the
 * scene and start-up phases do not depend on the kind. */
static void cube_walk(void **state, phase ph, bool multi, ob_fault_kind kind)
{
    if (!multi) ob_test_skip_under_tsan("a single-threaded walk");
    reference cube = *(reference *)*state;
    cube.env_map_kind = OB_ENV_MAP_CUBE;
    make_reference(&cube);
    walk(ph, multi, kind, &cube);
    free_reference(&cube);
}

static void first_frame_cube_host(void **state) { cube_walk(state, PHASE_FIRST_FRAME, false, OB_FAULT_HOST_ALLOC); }
static void first_frame_cube_vulkan(void **state) { cube_walk(state, PHASE_FIRST_FRAME, false, OB_FAULT_VK_OBJECT); }
static void steady_frame_cube_mt_host(void **state) { cube_walk(state, PHASE_STEADY_FRAME, true, OB_FAULT_HOST_ALLOC); }

static int setup(void **state)
{
    reference *ref = calloc(1, sizeof *ref);
    if (!ref) return -1;
    ob_test_vulkan_create(&ref->tv);
    make_reference(ref);
    *state = ref;
    return 0;
}

static int teardown(void **state)
{
    if (!*state) return 0; /* setup failed */
    free_reference(*state);
    ob_test_vulkan_destroy(&((reference *)*state)->tv);
    free(*state);
    return 0;
}

static void start_up_host(void **state) { walk(PHASE_START, false, OB_FAULT_HOST_ALLOC, *state); }
static void start_up_vulkan(void **state) { walk(PHASE_START, false, OB_FAULT_VK_OBJECT, *state); }
static void scene_host(void **state) { walk(PHASE_SCENE, false, OB_FAULT_HOST_ALLOC, *state); }
static void scene_vulkan(void **state) { walk(PHASE_SCENE, false, OB_FAULT_VK_OBJECT, *state); }
static void first_frame_host(void **state) { walk(PHASE_FIRST_FRAME, false, OB_FAULT_HOST_ALLOC, *state); }
static void first_frame_vulkan(void **state) { walk(PHASE_FIRST_FRAME, false, OB_FAULT_VK_OBJECT, *state); }
static void first_frame_mt_host(void **state) { walk(PHASE_FIRST_FRAME, true, OB_FAULT_HOST_ALLOC, *state); }
static void first_frame_mt_vulkan(void **state) { walk(PHASE_FIRST_FRAME, true, OB_FAULT_VK_OBJECT, *state); }
static void steady_frame_host(void **state) { walk(PHASE_STEADY_FRAME, false, OB_FAULT_HOST_ALLOC, *state); }
static void steady_frame_vulkan(void **state) { walk(PHASE_STEADY_FRAME, false, OB_FAULT_VK_OBJECT, *state); }
static void steady_frame_mt_host(void **state) { walk(PHASE_STEADY_FRAME, true, OB_FAULT_HOST_ALLOC, *state); }
static void steady_frame_mt_vulkan(void **state) { walk(PHASE_STEADY_FRAME, true, OB_FAULT_VK_OBJECT, *state); }

/* The walks in groups, each its own ctest entry (tests/CMakeLists.txt) so
 * that the sanitizer builds run them side by side, each within its time
 * limit: `test_faults GROUP` runs one group, no argument runs them all. */
typedef struct group_test {
    const char *group;
    struct CMUnitTest test;
} group_test;

#define GROUP_TEST(g, f) {g, cmocka_unit_test(f)}

int main(int argc, char **argv)
{
    ob_test_setup_log();
    /* Thousands of expected error lines: keep them for the assertions only. */
    ob_test_log_set_echo(getenv("OB_FAULT_ECHO") != NULL);
    /* OB_FAULT_FILTER=first_frame* runs a subset while debugging. */
    if (getenv("OB_FAULT_FILTER")) cmocka_set_test_filter(getenv("OB_FAULT_FILTER"));
    static const group_test all[] = {
        GROUP_TEST("start", start_up_host),
        GROUP_TEST("start", start_up_vulkan),
        GROUP_TEST("start", scene_host),
        GROUP_TEST("start", scene_vulkan),
        GROUP_TEST("first_host", first_frame_host),
        GROUP_TEST("first", first_frame_vulkan),
        GROUP_TEST("first", first_frame_mt_host),
        GROUP_TEST("first", first_frame_mt_vulkan),
        GROUP_TEST("steady", steady_frame_host),
        GROUP_TEST("steady", steady_frame_vulkan),
        GROUP_TEST("steady", steady_frame_mt_host),
        GROUP_TEST("steady", steady_frame_mt_vulkan),
        GROUP_TEST("cube_host", first_frame_cube_host),
        GROUP_TEST("cube", first_frame_cube_vulkan),
        GROUP_TEST("cube", steady_frame_cube_mt_host),
    };
    const size_t total = sizeof all / sizeof all[0];
    const char *group = argc > 1 ? argv[1] : NULL;
    struct CMUnitTest tests[sizeof all / sizeof all[0]];
    size_t n = 0;
    for (size_t i = 0; i < total; i++)
        if (!group || strcmp(all[i].group, group) == 0) tests[n++] = all[i].test;
    if (n == 0) {
        fprintf(stderr, "test_faults: no group '%s'; the groups:", group);
        for (size_t i = 0; i < total; i++)
            if (i == 0 || strcmp(all[i].group, all[i - 1].group) != 0) fprintf(stderr, " %s", all[i].group);
        fprintf(stderr, "\n");
        return 2;
    }
    return _cmocka_run_group_tests(group ? group : "test_faults", tests, n, setup, teardown);
}
