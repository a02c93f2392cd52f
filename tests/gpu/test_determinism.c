/* Issue 5: determinism. One animated scene — a shadow-casting sun, a
 * shadowed point light (a cube map) and spot light (issue 28), three
 * mirror spheres with environment maps, a particle simulation and 500
 * moving entities — rendered for five frames single-threaded, with 1, 2, 3,
 * 4 and 8 workers, switching mode every frame, and in AUTO mode: every frame
 * has the same pixels (byte for byte) and the same command hash per view.
 *
 * The sun's shadow is cascaded (issue 28): its four cascade views are
 * compared like every other view. The same holds with cube environment
 * maps (six faces each) in place of the paraboloids.
 *
 * Each run builds the scene afresh (controllers and the particle buffer
 * carry state from frame to frame). The renderer always has 8 workers;
 * ob_renderer_set_threading picks how many record. Views are cut into
 * chunks of 64 draws so that the main, shadow and env-map views are spread
 * over several workers, and the parallel loops of the update and of
 * PreRender's culling take 16 entities an index, so that with workers
 * every wave of views and the update run on the pool, several chunks a
 * view.
 *
 * The same frames again with the pipeline managers' ring staged (written in
 * host memory, copied to device-local memory before the draws, as on a
 * discrete GPU) and direct, in each threading mode: the copy changes no
 * pixel and no command hash (without the copies, frame 0 differs by 242),
 * and the validation layer is silent. Debian 12's layer (1.3.239) does not
 * report a missing barrier between the upload buffer and the primary
 * (checked: no message without it), and lavapipe runs them in order, so
 * the barrier itself is checked by reading record_uploads only.
 *
 * Culling's frustum test runs eight entities at a time where the CPU has
 * AVX2, four with SSE2, one at a time otherwise: on 2,003 spheres of all
 * sizes in and around the main view's frustum (some far away, one beyond
 * float range, one of zero size), every width keeps the same items in the
 * same order with the same keys. */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

#define FRAMES 5
#define ENTITIES 500
#define WIDTH 160
#define HEIGHT 120

typedef struct run_result {
    uint8_t *images[FRAMES];
    ob_frame_stats stats[FRAMES];
} run_result;

/* How a run picks the mode of frame f. */
typedef struct run_plan {
    const char *name;
    ob_env_map_kind env;       /* 0: paraboloid */
    ob_threading modes[FRAMES];
    uint32_t workers[FRAMES];
    ob_ring_staging staging;   /* 0: the device's */
    ob_instance_runs runs;     /* 0: the device's */
    bool sized_jobs;           /* the renderer sizes its jobs (chunk_draws 0), not 64 draws */
} run_plan;

static uint32_t next_random(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float random01(uint32_t *s) { return (float)next_random(s) / (float)(1u << 24); }

static void build_scene(ob_test_world *w, ob_particle_system **out_ps)
{
    ob_world_look(w, 0, 7, 14, 0, 0.5, 0);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 6, 12, 4);
    ob_world_light(w, OB_LIGHT_POINT, true, 2.0f, -3, 2, 2);
    ob_result r;
    ob_node *spot = ob_node_create(w->scene, NULL, "torch", &r);
    assert_non_null(spot);
    ob_light_desc sd = {.type = OB_LIGHT_SPOT, .intensity = 6.0f, .range = 14.0f,
                        .outer_angle = 0.6f, .inner_angle = 0.4f, .casts_shadows = true};
    assert_int_equal(ob_node_set_light(spot, &sd), OB_OK);
    ob_node_set_position(spot, (const double[3]){2, 5, 3});
    assert_int_equal(ob_node_look_at(spot, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0}),
                     OB_OK);
    ob_material *palette[8];
    for (int i = 0; i < 6; i++)
        palette[i] = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.2f + 0.13f * (float)i,
                                            0.9f - 0.12f * (float)i, 0.3f + 0.1f * (float)(i % 3),
                                            i != 5);
    palette[6] = ob_world_material(w, "test", OB_MATERIAL_UNLIT, 0.95f, 0.85f, 0.2f, true);
    palette[7] = ob_material_create(w->lib, &(ob_material_desc){.name = "glass",
        .kind = OB_MATERIAL_LIT, .diffuse = {0.4f, 0.6f, 0.9f, 0.5f}, .blended = true}, &r);
    assert_non_null(palette[7]);
    ob_material *ground = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.55f, 0.55f, 0.5f, false);
    ob_world_entity(w, NULL, "ground", w->plane, ground, 0, -0.6, 0);
    ob_material *mirror = ob_material_create(w->lib, &(ob_material_desc){.name = "mirror",
        .kind = OB_MATERIAL_REFLECTIVE, .reflectivity = 0.8f, .casts_shadows = true}, &r);
    assert_non_null(mirror);
    static const double mirrors[3][3] = {{-1.6, 0.4, 0}, {1.6, 0.4, 0}, {0, 0.4, -2.2}};
    for (int i = 0; i < 3; i++) {
        char name[16];
        snprintf(name, sizeof name, "mirror%d", i);
        ob_node *m = ob_world_entity(w, NULL, name, w->sphere, mirror, mirrors[i][0],
                                          mirrors[i][1], mirrors[i][2]);
        ob_node_set_scale(m, (const float[3]){1.6f, 1.6f, 1.6f});
    }
    uint32_t seed = 12345;
    for (uint32_t i = 0; i < ENTITIES; i++) {
        char name[24];
        snprintf(name, sizeof name, "object%u", i);
        ob_geometry *g = i % 3 == 0 ? w->sphere : w->box;
        ob_material *m = palette[next_random(&seed) % 8];
        ob_node *n = ob_world_entity(w, NULL, name, g, m, 0, 0, 0);
        ob_node_set_scale(n, (const float[3]){0.3f, 0.3f, 0.3f});
        double radius = 3.0 + 5.0 * random01(&seed);
        double center[3] = {0.0, 0.2 + 2.0 * random01(&seed), 0.0};
        float speed = (0.2f + 0.6f * random01(&seed)) * (i % 2 ? -1.0f : 1.0f);
        assert_int_equal(ob_node_add_orbit_controller(n, center, (const float[3]){0, 1, 0}, radius,
                                                      speed, 6.2831853f * random01(&seed)), OB_OK);
        float spin[3] = {random01(&seed) - 0.5f, 1.0f, random01(&seed) - 0.5f};
        assert_int_equal(ob_node_add_rotation_controller(n, spin, 1.0f + 2.0f * random01(&seed)),
                         OB_OK);
    }
    ob_node *fountain = ob_node_create(w->scene, NULL, "fountain", &r);
    assert_non_null(fountain);
    ob_node_set_position(fountain, (const double[3]){0.0, 0.0, 1.5});
    ob_particle_desc pd = {.name = "sparks", .count = 1024, .seed = 3, .lifetime = 1.5f,
                           .speed = 2.0f, .size = 0.05f, .gravity = {0.0f, -2.0f, 0.0f}};
    *out_ps = ob_particle_system_create(w->views, w->scene, fountain, &pd, &r);
    if (!*out_ps) fail_msg("particles: %s", ob_result_name(r));
}

static void run(const run_plan *plan, run_result *out)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 8, .width = WIDTH,
                                                   .height = HEIGHT, .env_map_size = 32,
                                                   .shadow_map_size = 128,
                                                   .chunk_draws = plan->sized_jobs ? 0 : 64,
                                                   .parallel_grain = 16,
                                                   .env_map_kind = plan->env,
                                                   .ring_staging = plan->staging,
                                                   .instance_runs = plan->runs});
    assert_int_equal(ob_renderer_worker_count(w.r), 8);
    ob_particle_system *ps = NULL;
    build_scene(&w, &ps);
    for (int f = 0; f < FRAMES; f++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, plan->modes[f], plan->workers[f]);
        out->stats[f] = *st;
        out->images[f] = ob_world_snapshot(&w);
        /* A staged frame copies what its managers wrote; a direct one
         * nothing; AUTO stages where mapped memory is not device-local (a
         * discrete GPU), unless $OB_RING_STAGING says otherwise. */
        const char *env = getenv("OB_RING_STAGING");
        bool staged = plan->staging == OB_RING_STAGING_ON ||
                      (plan->staging == OB_RING_STAGING_AUTO &&
                       (env ? !strcmp(env, "on")
                            : !ob_device_host_memory_is_device_local(ob_renderer_device(w.r))));
        if (staged) assert_true(st->ring_upload_bytes > 0);
        else assert_int_equal(st->ring_upload_bytes, 0);
        /* Runs are the multi-draws asked for (the features are there on
         * lavapipe and the GPUs tested), or instanced draws. */
        if (ob_renderer_instance_runs(w.r) == OB_INSTANCE_RUNS_MULTI_DRAW)
            assert_true(st->pm.multi_draw_runs > 0);
        else assert_int_equal(st->pm.multi_draw_runs, 0);
        if (plan->runs) assert_int_equal(ob_renderer_instance_runs(w.r), plan->runs);
        /* The mode asked for is the mode used (AUTO decides for itself). */
        if (plan->modes[f] == OB_THREADING_SINGLE) assert_int_equal(st->workers, 0);
        if (plan->modes[f] == OB_THREADING_MULTI)
            assert_int_equal(st->workers, plan->workers[f] ? plan->workers[f] : 8);
    }
    assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
    ob_particle_system_destroy(w.views, ps);
    ob_test_world_destroy(&w);
}

static void release(run_result *r)
{
    for (int f = 0; f < FRAMES; f++) free(r->images[f]);
}

/* The scene really is what it claims: every kind of view runs and the
 * frames differ from each other (it moves). */
static void check_reference(const run_result *ref, ob_env_map_kind env)
{
    for (int f = 0; f < FRAMES; f++) {
        const ob_frame_stats *st = &ref->stats[f];
        assert_int_equal(ob_world_count_views(st, env == OB_ENV_MAP_CUBE ? OB_VIEW_CUBE
                                                                         : OB_VIEW_PARABOLOID), 3);
        /* The sun's shadow is four cascade views, several of them drawing
         * (their hashes and the pixels they shade are compared below), plus
         * the point light's cube and the spot's. */
        assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), OB_SHADOW_DEFAULT_CASCADES + 2);
        assert_non_null(ob_world_view_stats(st, "shadow:lamp"));
        assert_true(ob_world_view_stats(st, "shadow:torch")->draws > 0);
        uint32_t drawing = 0;
        for (uint32_t c = 0; c < OB_SHADOW_DEFAULT_CASCADES; c++) {
            char name[32];
            snprintf(name, sizeof name, "shadow:sun:c%u", c);
            const ob_view_stats *vs = ob_world_view_stats(st, name);
            assert_non_null(vs);
            drawing += vs->draws > 0;
        }
        assert_true(drawing >= 2);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_SIMULATION), 1);
        assert_true(ob_world_view_stats(st, "main")->draws > 200);
        assert_int_equal(st->pm.skipped_draws, 0);
        if (f > 0)
            assert_true(ob_test_image_max_diff(ref->images[f - 1], ref->images[f], WIDTH, HEIGHT) > 0);
    }
}

static void assert_same(const run_result *ref, const run_result *got, const char *name)
{
    for (int f = 0; f < FRAMES; f++) {
        const ob_frame_stats *a = &ref->stats[f], *b = &got->stats[f];
        if (a->view_count != b->view_count)
            fail_msg("%s, frame %d: %u views, single-threaded %u", name, f, b->view_count,
                     a->view_count);
        for (uint32_t i = 0; i < a->view_count; i++) {
            if (strcmp(a->views[i].name, b->views[i].name) != 0)
                fail_msg("%s, frame %d: view %u is '%s', single-threaded '%s'", name, f, i,
                         b->views[i].name, a->views[i].name);
            if (a->views[i].hash.hash != b->views[i].hash.hash ||
                a->views[i].hash.draws != b->views[i].hash.draws)
                fail_msg("%s, frame %d, view '%s': hash %016llx (%u draws), single-threaded "
                         "%016llx (%u draws)", name, f, a->views[i].name,
                         (unsigned long long)b->views[i].hash.hash, b->views[i].hash.draws,
                         (unsigned long long)a->views[i].hash.hash, a->views[i].hash.draws);
        }
        assert_true(a->frame_hash == b->frame_hash);
        uint32_t diff = ob_test_image_max_diff(ref->images[f], got->images[f], WIDTH, HEIGHT);
        if (diff) fail_msg("%s, frame %d: pixels differ by up to %u", name, f, diff);
    }
}

static run_plan constant_plan(const char *name, ob_threading mode, uint32_t workers)
{
    run_plan p = {.name = name};
    for (int f = 0; f < FRAMES; f++) {
        p.modes[f] = mode;
        p.workers[f] = workers;
    }
    return p;
}

/* Multi-threaded with 8, then ST, 2 workers, ST and AUTO: a plan that
 * switches mode every frame, ending in AUTO. */
static run_plan switching_plan(const char *name)
{
    return (run_plan){.name = name,
                      .modes = {OB_THREADING_MULTI, OB_THREADING_SINGLE, OB_THREADING_MULTI,
                                OB_THREADING_SINGLE, OB_THREADING_AUTO},
                      .workers = {8, 0, 2, 0, 0}};
}

static void same_frames_in_every_threading_mode(void **state)
{
    (void)state;
    run_result ref;
    run_plan st_plan = constant_plan("single-threaded", OB_THREADING_SINGLE, 0);
    run(&st_plan, &ref);
    check_reference(&ref, OB_ENV_MAP_PARABOLOID);

    static const uint32_t counts[] = {1, 2, 3, 4, 8};
    for (size_t k = 0; k < OB_ARRAY_COUNT(counts); k++) {
        char name[32];
        snprintf(name, sizeof name, "%u workers", counts[k]);
        run_plan plan = constant_plan(name, OB_THREADING_MULTI, counts[k]);
        run_result got;
        run(&plan, &got);
        /* Chunked: the main view was recorded as several secondaries. */
        for (int f = 0; f < FRAMES; f++)
            assert_true(ob_world_view_stats(&got.stats[f], "main")->chunks > 1);
        assert_same(&ref, &got, name);
        release(&got);
    }
    release(&ref);
}

static void switching_mode_every_frame_changes_nothing(void **state)
{
    (void)state;
    run_result ref, got;
    run_plan st_plan = constant_plan("single-threaded", OB_THREADING_SINGLE, 0);
    run(&st_plan, &ref);
    run_plan mixed = {.name = "switching every frame",
                      .modes = {OB_THREADING_MULTI, OB_THREADING_SINGLE, OB_THREADING_MULTI,
                                OB_THREADING_SINGLE, OB_THREADING_MULTI},
                      .workers = {3, 0, 8, 0, 1}};
    run(&mixed, &got);
    assert_same(&ref, &got, mixed.name);
    release(&got);
    run_plan automatic = constant_plan("auto", OB_THREADING_AUTO, 0);
    run(&automatic, &got);
    for (int f = 0; f < FRAMES; f++) assert_int_equal(got.stats[f].mode, OB_THREADING_AUTO);
    assert_same(&ref, &got, automatic.name);
    release(&got);
    release(&ref);
}

/* The reference plan's frames, checked to be what the scene claims, and
 * each plan's against them. */
static void same_as_reference(const run_plan *reference, const run_plan *plans, size_t count)
{
    run_result ref, got;
    run(reference, &ref);
    check_reference(&ref, reference->env);
    for (size_t k = 0; k < count; k++) {
        run(&plans[k], &got);
        assert_same(&ref, &got, plans[k].name);
        release(&got);
    }
    release(&ref);
}

/* Cube environment maps (issue 28): six faces a map, each face's items
 * chosen per item, recorded in chunks over the workers like the rest. */
static void cube_env_maps_same_in_every_threading_mode(void **state)
{
    (void)state;
    run_plan st_plan = constant_plan("cube, single-threaded", OB_THREADING_SINGLE, 0);
    run_plan plans[] = {constant_plan("cube, 2 workers", OB_THREADING_MULTI, 2),
                        constant_plan("cube, 8 workers", OB_THREADING_MULTI, 8)};
    st_plan.env = OB_ENV_MAP_CUBE;
    for (size_t k = 0; k < OB_ARRAY_COUNT(plans); k++) plans[k].env = OB_ENV_MAP_CUBE;
    same_as_reference(&st_plan, plans, OB_ARRAY_COUNT(plans));
}

static void staged_ring_same_frames_as_direct(void **state)
{
    (void)state;
    run_plan direct = constant_plan("direct, single-threaded", OB_THREADING_SINGLE, 0);
    direct.staging = OB_RING_STAGING_OFF;
    run_plan plans[] = {constant_plan("staged, single-threaded", OB_THREADING_SINGLE, 0),
                        constant_plan("staged, 3 workers", OB_THREADING_MULTI, 3),
                        switching_plan("staged, switching every frame")};
    for (size_t k = 0; k < OB_ARRAY_COUNT(plans); k++) plans[k].staging = OB_RING_STAGING_ON;
    same_as_reference(&direct, plans, OB_ARRAY_COUNT(plans));
}

/* Instance runs drawn as multi-draw indirect (a GPU's default), staged or
 * direct, in every threading mode, or as a direct draw per instance: the
 * frames of instanced runs. */
static void multi_draw_and_direct_runs_same_frames(void **state)
{
    (void)state;
    run_plan ref = constant_plan("instanced, single-threaded", OB_THREADING_SINGLE, 0);
    ref.runs = OB_INSTANCE_RUNS_INSTANCED;
    run_plan plans[] = {constant_plan("multi-draw, single-threaded", OB_THREADING_SINGLE, 0),
                        constant_plan("multi-draw, 3 workers", OB_THREADING_MULTI, 3),
                        switching_plan("multi-draw staged, switching every frame")};
    for (size_t k = 0; k < OB_ARRAY_COUNT(plans); k++) plans[k].runs = OB_INSTANCE_RUNS_MULTI_DRAW;
    plans[1].runs = OB_INSTANCE_RUNS_DIRECT;
    plans[1].name = "direct draws, 3 workers";
    plans[2].staging = OB_RING_STAGING_ON;
    same_as_reference(&ref, plans, OB_ARRAY_COUNT(plans));
}

/* Jobs sized by the renderer (the default) rather than 64 draws each: a
 * view is cut by the frame's draws per thread, or by its last recording
 * time (the main view here, slow on lavapipe), and the frames are the same
 * as ever. */
static void renderer_sized_jobs_same_frames(void **state)
{
    (void)state;
    run_plan st_plan = constant_plan("single-threaded", OB_THREADING_SINGLE, 0);
    run_plan plans[] = {constant_plan("sized jobs, 2 workers", OB_THREADING_MULTI, 2),
                        constant_plan("sized jobs, 8 workers", OB_THREADING_MULTI, 8)};
    run_result ref, got;
    run(&st_plan, &ref);
    for (size_t k = 0; k < OB_ARRAY_COUNT(plans); k++) {
        plans[k].sized_jobs = true;
        run(&plans[k], &got);
        assert_same(&ref, &got, plans[k].name);
        release(&got);
    }
    release(&ref);
}

/* The main view's draw list of one frame: node id, key and level. */
typedef struct cull_result {
    uint32_t count, culled;
    uint32_t node_id[2100];
    uint64_t key[2100];
    uint8_t lod[2100];
} cull_result;

static void cull_frame(ob_test_world *w, uint8_t lanes, cull_result *out)
{
    ob_view *v = ob_perspective_view_base(w->main);
    v->cull_lanes = lanes;
    const ob_frame_stats *st = ob_test_world_frame(w, OB_THREADING_SINGLE, 0);
    assert_true(v->item_count <= OB_ARRAY_COUNT(out->node_id));
    out->count = v->item_count;
    out->culled = ob_world_view_stats(st, "main")->culled;
    for (uint32_t i = 0; i < v->item_count; i++) {
        out->node_id[i] = v->items[i].node_id;
        out->key[i] = v->items[i].sort_key;
        out->lod[i] = v->items[i].lod;
    }
}

static void frustum_test_same_at_every_width(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_material *m = ob_world_material(&w, "grey", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
    uint32_t seed = 7;
    /* An odd count: the eight- and four-wide loops leave a remainder. */
    for (uint32_t i = 0; i < 2003; i++) {
        double x = (random01(&seed) - 0.5) * 80.0, y = (random01(&seed) - 0.5) * 50.0;
        double z = 15.0 - random01(&seed) * 100.0; /* some behind the camera (z 5) */
        if (i % 97 == 3) z -= 1e6;  /* far away */
        if (i == 1000) x = 1e39;    /* beyond float range: named, not drawn */
        ob_node *n = ob_world_entity(&w, NULL, "s", w.sphere, m, x, y, z);
        float k = i == 500 ? 0.0f : 0.05f + 6.0f * random01(&seed) * random01(&seed);
        ob_node_set_scale(n, (float[3]){k, k, k});
    }
    cull_result *ref = calloc(3, sizeof *ref);
    assert_non_null(ref);
    static const uint8_t lanes[3] = {1, 4, 0};
    ob_test_log_set_echo(false);
    ob_test_log_clear();
    for (int k = 0; k < 3; k++) cull_frame(&w, lanes[k], &ref[k]);
    assert_true(ob_test_log_has("beyond float range", NULL));
    ob_test_log_set_echo(true);
    /* Plenty on either side of the planes. */
    assert_true(ref[0].count > 300 && ref[0].culled > 300);
    for (int k = 1; k < 3; k++) {
        assert_int_equal(ref[k].count, ref[0].count);
        assert_int_equal(ref[k].culled, ref[0].culled);
        assert_memory_equal(ref[k].node_id, ref[0].node_id, sizeof(uint32_t) * ref[0].count);
        assert_memory_equal(ref[k].key, ref[0].key, sizeof(uint64_t) * ref[0].count);
        assert_memory_equal(ref[k].lod, ref[0].lod, ref[0].count);
    }
    free(ref);
    ob_perspective_view_base(w.main)->cull_lanes = 0;
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(same_frames_in_every_threading_mode),
        cmocka_unit_test(switching_mode_every_frame_changes_nothing),
        cmocka_unit_test(cube_env_maps_same_in_every_threading_mode),
        cmocka_unit_test(staged_ring_same_frames_as_direct),
        cmocka_unit_test(multi_draw_and_direct_runs_same_frames),
        cmocka_unit_test(renderer_sized_jobs_same_frames),
        cmocka_unit_test(frustum_test_same_at_every_width),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
