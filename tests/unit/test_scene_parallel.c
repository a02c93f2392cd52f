/* ob_scene_update_parallel against ob_scene_update: two scenes built alike
 * (a few thousand nodes, or 24k whose loops the engine cuts by itself;
 * hierarchy up to eight deep, hidden subtrees, a node
 * whose controller turns its transform to NaN and back, zero scale, lights,
 * parallel-safe and serial controllers) are updated frame by frame, one on
 * the caller and one through a loop that runs its indices on four real
 * threads, with the same edits between frames: the snapshots (renderables,
 * lights, proxies, bounds, SoA arrays) and every node's world transform are
 * the same bytes. Run it under -DOB_SANITIZE=thread as well. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_scene.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define THREADS 4u
#define NODES 3000u
/* Enough for levels that the engine cuts by itself (ob_parallel.grain 0)
 * to go to the threads: 2 x UPDATE_GRAIN nodes a thread. */
#define LARGE_NODES 24000u
#define MAX_NODES (LARGE_NODES + 64u)
#define MAX_DEPTH 8u
#define FRAMES 10u

/* ---------------------------------------------- a loop on real threads */

static atomic_uint loops_on_threads;

typedef struct loop_run {
    ob_task_fn fn;
    void *user;
    uint32_t count;
    atomic_uint next;
} loop_run;

typedef struct loop_thread {
    loop_run *run;
    uint32_t index;
    pthread_t thread;
} loop_thread;

static void *loop_main(void *arg)
{
    loop_thread *t = arg;
    for (;;) {
        uint32_t i = atomic_fetch_add(&t->run->next, 1u);
        if (i >= t->run->count) return NULL;
        t->run->fn(t->run->user, i, t->index);
    }
}

static void threads_run(void *ctx, uint32_t count, ob_task_fn fn, void *user)
{
    (void)ctx;
    atomic_fetch_add(&loops_on_threads, 1u);
    loop_run run = {.fn = fn, .user = user, .count = count};
    atomic_init(&run.next, 0u);
    loop_thread threads[THREADS];
    for (uint32_t t = 0; t < THREADS; t++) {
        threads[t] = (loop_thread){.run = &run, .index = t};
        assert_int_equal(pthread_create(&threads[t].thread, NULL, loop_main, &threads[t]), 0);
    }
    for (uint32_t t = 0; t < THREADS; t++) pthread_join(threads[t].thread, NULL);
}

/* ------------------------------------------------------------ the scene */

static char materials[5], geometries[3]; /* stand-ins: only their addresses matter */

typedef struct pulse_state {
    double time, rate;
} pulse_state;

/* Parallel-safe: its own node's scale and its own state. */
static void pulse_step(ob_node *n, double dt, void *user)
{
    pulse_state *st = user;
    st->time += dt;
    float k = (float)(1.0 + 0.5 * sin(st->time * st->rate));
    ob_node_set_scale(n, (float[3]){k, 1.0f / k, 1.0f});
}

typedef struct glitch_state {
    uint32_t calls, first; /* NaN in updates first and first + 1 (from 1) */
} glitch_state;

/* Parallel-safe: NaN in two updates, then a finite position again. */
static void glitch_step(ob_node *n, double dt, void *user)
{
    (void)dt;
    glitch_state *g = user;
    uint32_t c = ++g->calls;
    ob_node_set_position(n, (double[3]){c == g->first || c == g->first + 1 ? NAN : 1.0 * c, 2, 3});
}

typedef struct world world;

typedef struct follow_state {
    const world *w;
    uint32_t leader;
} follow_state;

struct world {
    ob_scene *s;
    ob_node *nodes[MAX_NODES];   /* NULL once destroyed */
    uint32_t depth[MAX_NODES];
    uint32_t count;
    uint32_t built;              /* nodes world_create made */
    uint32_t glitch;             /* the node glitch_step drives */
    glitch_state glitch_at;
    uint64_t seed;
};

/* Serial: reads another node's local position. */
static void follow_step(ob_node *n, double dt, void *user)
{
    (void)dt;
    const follow_state *f = user;
    ob_node *leader = f->w->nodes[f->leader];
    if (!leader) return;
    double p[3];
    ob_node_get_position(leader, p);
    ob_node_set_position(n, (double[3]){p[0] + 1.0, p[1], p[2] - 1.0});
}

static uint32_t next_random(world *w)
{
    w->seed = w->seed * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(w->seed >> 33);
}

static double uniform(world *w, double lo, double hi)
{
    return lo + (hi - lo) * (next_random(w) / 2147483648.0);
}

static void add_node(world *w, bool serial)
{
    uint32_t i = w->count;
    ob_node *parent = NULL;
    uint32_t depth = 1;
    if (i >= 8 && next_random(w) % 4 != 0) {
        /* A recent node, so that chains form. */
        uint32_t p = i - 1 - next_random(w) % OB_MIN(i, 40u);
        if (w->nodes[p] && w->depth[p] < MAX_DEPTH) {
            parent = w->nodes[p];
            depth = w->depth[p] + 1;
        }
    }
    ob_result r;
    ob_node *n = ob_node_create(w->s, parent, "n", &r);
    assert_non_null(n);
    w->nodes[i] = n;
    w->depth[i] = depth;
    w->count++;

    ob_node_set_position(n, (double[3]){uniform(w, -50, 50), uniform(w, -5, 5), uniform(w, -50, 50)});
    ob_node_set_rotation(n, (float[4]){(float)uniform(w, -1, 1), (float)uniform(w, -1, 1),
                                       (float)uniform(w, -1, 1), (float)uniform(w, 0.1, 2)});
    float sc = i % 997 == 5 ? 0.0f : (float)uniform(w, 0.5, 2);
    /* Every seventh mirrors (the proxies' face flips). */
    ob_node_set_scale(n, (float[3]){i % 7 == 3 ? -sc : sc, sc * (float)uniform(w, 0.5, 1.5), sc});
    uint32_t kind = next_random(w) % 100;
    if (kind < 80) {
        ob_renderable rd = {.material = (struct ob_material *)&materials[next_random(w) % 5],
                            .geometry = (struct ob_geometry *)&geometries[next_random(w) % 3],
                            .local_center = {(float)uniform(w, -1, 1), 0, 0},
                            .local_radius = (float)uniform(w, 0.5, 3)};
        assert_int_equal(ob_node_set_renderable(n, &rd), OB_OK);
    } else if (kind < 83) {
        assert_int_equal(ob_node_set_light(n, &(ob_light_desc){.type = OB_LIGHT_POINT,
                                                               .intensity = 1}), OB_OK);
    }
    if (next_random(w) % 50 == 0) ob_node_set_hidden(n, true);

    uint32_t ctl = next_random(w) % 100;
    float axis[3] = {(float)uniform(w, -1, 1), 1, (float)uniform(w, -1, 1)};
    if (ctl < 40)
        assert_int_equal(ob_node_add_rotation_controller(n, axis, (float)uniform(w, -3, 3)), OB_OK);
    if (ctl >= 30 && ctl < 60)
        assert_int_equal(ob_node_add_orbit_controller(n, (double[3]){0, 0, 0}, axis,
                                                      uniform(w, 1, 20), (float)uniform(w, -2, 2),
                                                      (float)uniform(w, 0, 6)), OB_OK);
    if (ctl >= 60 && ctl < 70) {
        pulse_state *st = malloc(sizeof *st);
        assert_non_null(st);
        *st = (pulse_state){.rate = uniform(w, 1, 4)};
        assert_int_equal(ob_node_add_controller(n, &(ob_controller_desc){
                             .fn = pulse_step, .user = st, .release = free, .parallel = true}),
                         OB_OK);
    }
    if (serial && ctl >= 70 && ctl < 76 && i > 0) {
        follow_state *f = malloc(sizeof *f);
        assert_non_null(f);
        *f = (follow_state){.w = w, .leader = i / 2};
        assert_int_equal(ob_node_add_controller(n, &(ob_controller_desc){
                             .fn = follow_step, .user = f, .release = free}),
                         OB_OK);
    }
}

static bool has_child(const world *w, uint32_t i)
{
    for (uint32_t k = i + 1; k < w->count; k++)
        if (ob_node_get_parent(w->nodes[k]) == w->nodes[i]) return true;
    return false;
}

static world *world_create(bool serial, uint32_t nodes)
{
    world *w = calloc(1, sizeof *w);
    assert_non_null(w);
    w->seed = 12345;
    ob_result r;
    w->s = ob_scene_create(&r);
    assert_non_null(w->s);
    for (uint32_t i = 0; i < nodes; i++) add_node(w, serial);
    w->built = nodes;
    w->glitch = 17;
    w->glitch_at.first = 4;
    if (nodes > NODES) {
        /* A top-level leaf late in its level, drawn and shown, in frames
         * without edits: only one of its level's last chunks can see it
         * leave the snapshot and come back. (Frame 5's new nodes take
         * parents among the last 40.) */
        w->glitch_at.first = 8;
        w->glitch = nodes - 41;
        while (w->depth[w->glitch] != 1 || has_child(w, w->glitch)) w->glitch--;
        assert_int_equal(ob_node_set_renderable(w->nodes[w->glitch], &(ob_renderable){
                             .material = (struct ob_material *)&materials[0],
                             .local_radius = 1}), OB_OK);
        ob_node_set_hidden(w->nodes[w->glitch], false);
    }
    assert_int_equal(ob_node_add_controller(w->nodes[w->glitch], &(ob_controller_desc){
                         .fn = glitch_step, .user = &w->glitch_at, .parallel = true}),
                     OB_OK);
    return w;
}

static void world_destroy(world *w)
{
    ob_scene_destroy(w->s);
    free(w);
}

static void destroy_subtree(world *w, uint32_t top)
{
    ob_node *t = w->nodes[top];
    if (!t) return;
    for (uint32_t i = 0; i < w->count; i++) {
        for (ob_node *p = w->nodes[i]; p; p = ob_node_get_parent(p)) {
            if (p != t) continue;
            if (i != top) w->nodes[i] = NULL;
            break;
        }
    }
    w->nodes[top] = NULL;
    ob_node_destroy(t);
}

/* The same edits on both worlds between frames. */
static void world_edit(world *w, uint32_t frame, bool serial)
{
    switch (frame) {
    case 2: /* a subtree hidden, another shown */
        ob_node_set_hidden(w->nodes[9], true);
        for (uint32_t i = 10; i < w->count; i++) {
            if (w->nodes[i] && ob_node_is_hidden(w->nodes[i])) {
                ob_node_set_hidden(w->nodes[i], false);
                break;
            }
        }
        break;
    case 3: /* renderables cleared and changed, a light added */
        ob_node_set_renderable(w->nodes[40], NULL);
        ob_node_set_renderable(w->nodes[41], &(ob_renderable){
                                   .material = (struct ob_material *)&materials[4],
                                   .local_radius = 7});
        ob_node_set_light(w->nodes[42], &(ob_light_desc){.type = OB_LIGHT_DIRECTIONAL});
        break;
    case 4: /* a subtree destroyed */
        destroy_subtree(w, 100);
        break;
    case 5: /* new nodes, the root moved */
        for (uint32_t k = 0; k < 40; k++) add_node(w, serial);
        ob_node_set_position(ob_scene_root(w->s), (double[3]){3, 0, -2});
        break;
    case 6: /* a node moved under another, the root back home */
        if (w->nodes[300] && w->nodes[2]) ob_node_set_parent(w->s, w->nodes[300], w->nodes[2]);
        ob_node_set_position(ob_scene_root(w->s), (double[3]){0, 0, 0});
        break;
    default:
        break;
    }
}

/* ------------------------------------------------------------ comparison */

static uint32_t id_or_zero(const ob_node *n) { return n ? ob_node_id(n) : 0u; }

static void assert_same_snapshot(const world *a, const world *b)
{
    uint32_t na, nb;
    ob_node *const *ra = ob_scene_renderables(a->s, &na);
    ob_node *const *rb = ob_scene_renderables(b->s, &nb);
    assert_int_equal(na, nb);
    assert_true(na > a->built / 2);
    for (uint32_t i = 0; i < na; i++) assert_int_equal(ob_node_id(ra[i]), ob_node_id(rb[i]));
    ob_node *const *la = ob_scene_lights(a->s, &na);
    ob_node *const *lb = ob_scene_lights(b->s, &nb);
    assert_int_equal(na, nb);
    for (uint32_t i = 0; i < na; i++) assert_int_equal(ob_node_id(la[i]), ob_node_id(lb[i]));

    const ob_render_proxy *pa = ob_scene_render_proxies(a->s, &na);
    const ob_render_proxy *pb = ob_scene_render_proxies(b->s, &nb);
    for (uint32_t i = 0; i < na; i++) {
        assert_memory_equal(pa[i].linear, pb[i].linear, sizeof pa[i].linear);
        assert_memory_equal(pa[i].world_t, pb[i].world_t, sizeof pa[i].world_t);
        assert_int_equal(pa[i].finite, pb[i].finite);
        assert_int_equal(pa[i].mirrors, pb[i].mirrors);
    }

    ob_render_soa sa, sb;
    ob_scene_render_soa(a->s, &sa);
    ob_scene_render_soa(b->s, &sb);
    assert_int_equal(sa.count, sb.count);
    for (uint32_t i = 0; i < sa.count; i++) {
        assert_ptr_equal(sa.materials[sa.material[i]], sb.materials[sb.material[i]]);
        assert_ptr_equal(sa.geometries[sa.geometry[i]], sb.geometries[sb.geometry[i]]);
    }
    assert_memory_equal(sa.x, sb.x, sizeof *sa.x * sa.count);
    assert_memory_equal(sa.y, sb.y, sizeof *sa.y * sa.count);
    assert_memory_equal(sa.z, sb.z, sizeof *sa.z * sa.count);
    assert_memory_equal(sa.radius, sb.radius, sizeof *sa.radius * sa.count);
    assert_memory_equal(sa.flags, sb.flags, sa.count);
    assert_memory_equal(sa.material, sb.material, sizeof *sa.material * sa.count);
    assert_memory_equal(sa.geometry, sb.geometry, sizeof *sa.geometry * sa.count);
    assert_memory_equal(sa.node_id, sb.node_id, sizeof *sa.node_id * sa.count);
    for (uint32_t i = 0; i < sa.count; i++) assert_int_equal(id_or_zero(sa.node[i]), sa.node_id[i]);

    assert_int_equal(a->count, b->count);
    for (uint32_t i = 0; i < a->count; i++) {
        assert_true(!a->nodes[i] == !b->nodes[i]);
        if (!a->nodes[i]) continue;
        ob_daffine wa, wb;
        ob_node_world_affine(a->nodes[i], &wa);
        ob_node_world_affine(b->nodes[i], &wb);
        assert_memory_equal(&wa, &wb, sizeof wa);
        assert_int_equal(ob_node_is_renderable(a->nodes[i]), ob_node_is_renderable(b->nodes[i]));
        assert_int_equal(ob_node_transform_is_valid(a->nodes[i]),
                         ob_node_transform_is_valid(b->nodes[i]));
    }
}

/* The snapshot agrees with the nodes it names and with the formulas the
 * proxies are documented by (ob_mat4_normal_cofactor of the float world). */
static void assert_snapshot_consistent(const world *w)
{
    uint32_t count;
    ob_node *const *items = ob_scene_renderables(w->s, &count);
    const ob_render_proxy *p = ob_scene_render_proxies(w->s, &count);
    ob_render_soa soa;
    ob_scene_render_soa(w->s, &soa);
    for (uint32_t i = 0; i < count; i++) {
        const ob_node *n = items[i];
        assert_true(ob_node_is_renderable(n));
        const ob_renderable *rd = ob_node_get_renderable(n);
        assert_non_null(rd);
        assert_ptr_equal(soa.node[i], n);
        assert_int_equal(soa.node_id[i], ob_node_id(n));
        assert_ptr_equal(ob_scene_material(w->s, soa.material[i]), rd->material);
        assert_ptr_equal(ob_scene_geometry(w->s, soa.geometry[i]), rd->geometry);
        assert_ptr_equal(soa.materials[soa.material[i]], rd->material);
        assert_ptr_equal(soa.geometries[soa.geometry[i]], rd->geometry);
        ob_daffine wm;
        ob_node_world_affine(n, &wm);
        float m4[16], nm[16], block[32];
        ob_daffine_to_relative(&wm, (double[3]){0, 0, 0}, m4);
        ob_mat4_normal_cofactor(m4, nm);
        assert_true(ob_render_proxy_per_draw(&p[i], (double[3]){0, 0, 0}, block));
        assert_int_equal(p[i].finite, 1);
        assert_int_equal(p[i].mirrors, ob_det3_negative(m4, 4, 1));
        for (int c = 0; c < 3; c++) {
            for (int r = 0; r < 3; r++) {
                assert_memory_equal(&p[i].linear[c * 3 + r], &m4[c * 4 + r], sizeof(float));
                assert_memory_equal(&block[16 + c * 4 + r], &nm[c * 4 + r], sizeof(float));
            }
        }
        assert_memory_equal(p[i].world_t, wm.t, sizeof wm.t);
        double center[3];
        float radius;
        ob_node_world_sphere(n, center, &radius);
        assert_memory_equal(&soa.x[i], &center[0], sizeof(double));
        assert_memory_equal(&soa.y[i], &center[1], sizeof(double));
        assert_memory_equal(&soa.z[i], &center[2], sizeof(double));
        assert_memory_equal(&soa.radius[i], &radius, sizeof radius);
        assert_int_equal(soa.flags[i], radius == 0.0f && rd->local_radius > 0.0f
                                           ? OB_RENDER_ZERO_SCALE : 0u);
    }
}

/* Every world is its chain of local transforms, composed here from the
 * nodes' getters: no evaluation was skipped that should have run. */
static void assert_worlds_follow_locals(const world *w)
{
    for (uint32_t i = 0; i < w->count; i++) {
        const ob_node *n = w->nodes[i];
        if (!n || !ob_node_transform_is_valid(n)) continue;
        ob_daffine ref, local;
        ob_daffine_identity(&ref);
        for (const ob_node *a = n; a; a = ob_node_get_parent(a)) {
            double t[3], q[4], s[3];
            float sf[3];
            ob_node_get_position(a, t);
            ob_node_get_rotation(a, q);
            ob_node_get_scale(a, sf);
            for (int k = 0; k < 3; k++) s[k] = sf[k];
            assert_true(ob_dquat_normalize(q, q));
            ob_daffine_from_trs(t, q, s, &local);
            ob_daffine_mul(&local, &ref, &ref);
        }
        ob_daffine got;
        ob_node_world_affine(n, &got);
        for (int k = 0; k < 9; k++) assert_near(got.m[k], ref.m[k], 1e-9 * (1 + fabs(ref.m[k])));
        for (int k = 0; k < 3; k++) assert_near(got.t[k], ref.t[k], 1e-9 * (1 + fabs(ref.t[k])));
    }
}

static void run_frames(bool serial, uint32_t grain, uint32_t nodes, uint32_t threads)
{
    ob_test_log_set_echo(false);
    world *a = world_create(serial, nodes), *b = world_create(serial, nodes);
    const ob_parallel par = {.run = threads_run, .threads = threads, .grain = grain};
    atomic_store(&loops_on_threads, 0u);
    for (uint32_t frame = 0; frame < FRAMES; frame++) {
        world_edit(a, frame, serial);
        world_edit(b, frame, serial);
        /* A longer step now and then: the rotation controller's cached step changes. */
        double dt = frame == 7 ? 1.0 / 30.0 : 1.0 / 60.0;
        ob_test_log_clear();
        assert_int_equal(ob_scene_update(a->s, dt), OB_OK);
        uint32_t errors = ob_test_log_count(OB_LOG_ERROR);
        ob_test_log_clear();
        assert_int_equal(ob_scene_update_parallel(b->s, dt, &par), OB_OK);
        assert_int_equal(ob_test_log_count(OB_LOG_ERROR), errors);
        if (frame + 1 == b->glitch_at.first) {
            /* The glitching node went NaN: named once, out of the snapshot. */
            assert_int_equal(errors, 1);
            assert_false(ob_node_transform_is_valid(b->nodes[b->glitch]));
        }
        if (frame == b->glitch_at.first + 1) assert_true(ob_test_log_has("'n'", "finite again", NULL));
        assert_same_snapshot(a, b);
        assert_snapshot_consistent(b);
        assert_worlds_follow_locals(b);
    }
    /* Every frame's levels of many nodes went to the threads. */
    assert_true(atomic_load(&loops_on_threads) >= 2 * FRAMES);
    ob_test_log_set_echo(true);
    world_destroy(a);
    world_destroy(b);
}

/* Controllers run in each level's loop, right before the transforms. */
static void parallel_safe_controllers_only(void **state)
{
    (void)state;
    run_frames(false, 16, NODES, THREADS);
}

/* A loop for the parallel-safe controllers, the serial ones on the caller,
 * then the levels; an odd grain, so chunks end mid-batch. */
static void with_serial_controllers(void **state)
{
    (void)state;
    run_frames(true, 37, NODES, THREADS);
}

/* No grain from the caller: each loop cuts its nodes by the thread count
 * (levels of a few thousand nodes into a few hundred a chunk, the
 * snapshot's slots into larger chunks), so chunks differ from loop to
 * loop. */
static void levels_cut_by_the_engine(void **state)
{
    (void)state;
    run_frames(true, 0, LARGE_NODES, 2);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(parallel_safe_controllers_only),
        cmocka_unit_test(with_serial_controllers),
        cmocka_unit_test(levels_cut_by_the_engine),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
