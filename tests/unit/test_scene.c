/* The scene graph as a user sees it: world transforms, hierarchy edits,
 * visibility, the frame snapshot, controllers, bad transforms and allocation
 * failures. */
#include "ob_test.h"
#include "ob_scene.h"
#include "ob_scene_internal.h"

#include <float.h>
#include <stdio.h>
#include <string.h>


static ob_scene *new_scene(void)
{
    ob_result r = OB_ERR_IO;
    ob_scene *s = ob_scene_create(&r);
    assert_non_null(s);
    assert_int_equal(r, OB_OK);
    return s;
}

static ob_node *new_node(ob_scene *s, ob_node *parent, const char *name)
{
    ob_result r = OB_ERR_IO;
    ob_node *n = ob_node_create(s, parent, name, &r);
    assert_non_null(n);
    assert_int_equal(r, OB_OK);
    return n;
}

static void make_renderable(ob_node *n)
{
    ob_renderable rd = {.local_radius = 1.0f};
    assert_int_equal(ob_node_set_renderable(n, &rd), OB_OK);
}

/* ---- an independent reference: row-major 4x4 doubles, Rodrigues rotation */

typedef struct ref4 {
    double m[4][4];
} ref4;

static ref4 ref_trs(const double t[3], const float q[4], const float s[3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    double vn = sqrt(x * x + y * y + z * z), th = 2.0 * atan2(vn, w);
    double k[3] = {vn > 0 ? x / vn : 1, vn > 0 ? y / vn : 0, vn > 0 ? z / vn : 0};
    double c = cos(th), sn = sin(th);
    double kx[3][3] = {{0, -k[2], k[1]}, {k[2], 0, -k[0]}, {-k[1], k[0], 0}};
    ref4 out = {{{0}}};
    for (int r = 0; r < 3; r++) {
        for (int col = 0; col < 3; col++) {
            double rot = (r == col ? c : 0.0) + sn * kx[r][col] + (1 - c) * k[r] * k[col];
            out.m[r][col] = rot * s[col];
        }
        out.m[r][3] = t[r];
    }
    out.m[3][3] = 1;
    return out;
}

static ref4 ref_mul(const ref4 *a, const ref4 *b)
{
    ref4 out = {{{0}}};
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 4; k++) out.m[r][c] += a->m[r][k] * b->m[k][c];
    return out;
}

static void assert_world_equals(const ob_node *n, const ref4 *ref, double tol)
{
    ob_daffine w;
    ob_node_world_affine(n, &w);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) assert_near(w.m[c * 3 + r], ref->m[r][c], tol);
        assert_near(w.t[r], ref->m[r][3], tol);
    }
}

static void hierarchy_matches_double_reference(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    const double t[3][3] = {{10, -2, 3.5}, {0.25, 4, -1}, {-3, 0.5, 7}};
    const float q[3][4] = {{0.2f, 0.3f, 0.1f, 0.9f}, {0, 0.7071068f, 0, 0.7071068f},
                           {-0.4f, 0.1f, 0.5f, 0.6f}};
    const float sc[3][3] = {{2, 2, 2}, {1, 3, 0.5f}, {0.7f, 0.7f, 1.2f}};
    ob_node *n[3];
    ref4 ref[3];
    for (int i = 0; i < 3; i++) {
        n[i] = new_node(s, i ? n[i - 1] : NULL, "level");
        ob_node_set_position(n[i], t[i]);
        ob_node_set_rotation(n[i], q[i]);
        ob_node_set_scale(n[i], sc[i]);
        ref4 local = ref_trs(t[i], q[i], sc[i]);
        ref[i] = i ? ref_mul(&ref[i - 1], &local) : local;
    }
    assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
    for (int i = 0; i < 3; i++) assert_world_equals(n[i], &ref[i], 1e-12);
    double p[3];
    ob_node_world_position(n[2], p);
    for (int k = 0; k < 3; k++) assert_near(p[k], ref[2].m[k][3], 1e-12);
    /* Relative to an origin: translation minus origin, the rest unchanged. */
    float rel[16];
    ob_node_world_relative(n[2], (double[3]){1, 2, 3}, rel);
    assert_near(rel[12], ref[2].m[0][3] - 1, 1e-5);
    assert_near(rel[14], ref[2].m[2][3] - 3, 1e-5);
    assert_near(rel[4], ref[2].m[0][1], 1e-6);
    assert_near(rel[15], 1.0, 0.0);
    ob_scene_destroy(s);
}

static void reparenting_moves_subtree(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *a = new_node(s, NULL, "a"), *b = new_node(s, NULL, "b");
    ob_node *c = new_node(s, a, "c"), *d = new_node(s, c, "d");
    ob_node_set_position(a, (double[3]){100, 0, 0});
    ob_node_set_position(b, (double[3]){0, 200, 0});
    ob_node_set_rotation(b, (float[4]){0, 0, 0.70710678f, 0.70710678f}); /* 90° about Z */
    ob_node_set_position(c, (double[3]){1, 0, 0});
    ob_node_set_position(d, (double[3]){0, 0, 5});
    ob_scene_update(s, 0.0);
    double p[3];
    ob_node_world_position(d, p);
    assert_near(p[0], 101, 1e-12);
    assert_near(p[2], 5, 1e-12);

    assert_int_equal(ob_node_set_parent(s, c, b), OB_OK);
    assert_ptr_equal(ob_node_get_parent(c), b);
    assert_null(ob_node_first_child(a));
    ob_scene_update(s, 0.0);
    ob_node_world_position(d, p); /* local kept: b * (1,0,0) + (0,0,5) rotated */
    assert_near(p[0], 0, 1e-6);
    assert_near(p[1], 201, 1e-6);
    assert_near(p[2], 5, 1e-6);

    assert_int_equal(ob_node_set_parent(s, d, NULL), OB_OK); /* to the root */
    ob_scene_update(s, 0.0);
    ob_node_world_position(d, p);
    assert_near(p[0], 0, 1e-12);
    assert_near(p[1], 0, 1e-12);
    assert_near(p[2], 5, 1e-12);
    /* Children order is attachment order. */
    ob_node *root = ob_scene_root(s);
    assert_ptr_equal(ob_node_first_child(root), a);
    assert_ptr_equal(ob_node_next_sibling(a), b);
    assert_ptr_equal(ob_node_next_sibling(b), d);
    assert_null(ob_node_next_sibling(d));
    ob_scene_destroy(s);
}

static void cycles_and_foreign_nodes_refused(void **state)
{
    (void)state;
    ob_scene *s = new_scene(), *other = new_scene();
    ob_node *a = new_node(s, NULL, "anc"), *b = new_node(s, a, "mid"), *c = new_node(s, b, "leaf");
    ob_node *x = new_node(other, NULL, "stranger");
    ob_test_log_clear();
    assert_int_equal(ob_node_set_parent(s, a, c), OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'anc'", "cycle", NULL));
    assert_int_equal(ob_node_set_parent(s, a, a), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_parent(s, ob_scene_root(s), c), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_parent(s, c, x), OB_ERR_INVALID_ARGUMENT);
    ob_result r = OB_OK;
    assert_null(ob_node_create(s, x, "bad", &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_destroy(ob_scene_root(s)), OB_ERR_INVALID_ARGUMENT); /* logged */
    assert_true(ob_test_log_has("root", "cannot be destroyed", NULL));
    /* Structure unchanged. */
    assert_ptr_equal(ob_node_get_parent(c), b);
    assert_ptr_equal(ob_node_get_parent(b), a);
    assert_ptr_equal(ob_node_get_parent(a), ob_scene_root(s));
    assert_int_equal(ob_scene_node_count(s), 4);
    assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
    ob_scene_destroy(s);
    ob_scene_destroy(other);
}

static bool snapshot_has(const ob_scene *s, const ob_node *n)
{
    uint32_t count;
    ob_node *const *items = ob_scene_renderables(s, &count);
    for (uint32_t i = 0; i < count; i++)
        if (items[i] == n) return true;
    return false;
}

static void hidden_subtree_leaves_snapshot(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *group = new_node(s, NULL, "group"), *inner = new_node(s, group, "inner");
    ob_node *leaf = new_node(s, inner, "leaf"), *other = new_node(s, NULL, "other");
    make_renderable(inner);
    make_renderable(leaf);
    make_renderable(other);
    ob_scene_update(s, 0.0);
    uint32_t count;
    ob_scene_renderables(s, &count);
    assert_int_equal(count, 3);

    ob_node_set_hidden(group, true); /* group itself draws nothing */
    ob_scene_update(s, 0.0);
    ob_scene_renderables(s, &count);
    assert_int_equal(count, 1);
    assert_true(snapshot_has(s, other));
    assert_false(ob_node_is_renderable(leaf));
    assert_false(ob_node_is_renderable(inner));
    assert_true(ob_node_is_hidden(group));
    assert_false(ob_node_is_hidden(leaf));

    ob_node_set_hidden(group, false);
    ob_node_set_renderable(inner, NULL); /* cleared */
    ob_scene_update(s, 0.0);
    assert_true(snapshot_has(s, leaf));
    assert_false(snapshot_has(s, inner));
    assert_null(ob_node_get_renderable(inner));
    assert_non_null(ob_node_get_renderable(leaf));
    ob_scene_destroy(s);
}

static void renderables_sorted_by_id(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n[12];
    for (int i = 0; i < 12; i++) {
        n[i] = new_node(s, i % 3 && i ? n[i - 1] : NULL, "n");
        if (i % 4 != 1) make_renderable(n[i]);
    }
    /* Shuffle the tree so that parent-before-child order differs from ids. */
    assert_int_equal(ob_node_set_parent(s, n[0], n[11]), OB_OK);
    assert_int_equal(ob_node_set_parent(s, n[5], n[9]), OB_OK);
    ob_scene_update(s, 0.0);
    uint32_t count;
    ob_node *const *items = ob_scene_renderables(s, &count);
    assert_int_equal(count, 9);
    for (uint32_t i = 1; i < count; i++) assert_true(ob_node_id(items[i - 1]) < ob_node_id(items[i]));
    for (int i = 1; i < 12; i++) assert_true(ob_node_id(n[i - 1]) < ob_node_id(n[i]));
    ob_scene_destroy(s);
}

static void rotation_controller_matches_axis_angle(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n = new_node(s, NULL, "spinner");
    const float q0f[4] = {0, 0.38268343f, 0, 0.92387953f}; /* 45° about Y first */
    ob_node_set_rotation(n, q0f);
    assert_int_equal(ob_node_add_rotation_controller(n, (float[3]){1, 2, 3}, 0.7f), OB_OK);
    for (int i = 0; i < 120; i++) assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
    /* q = q0 * rot(axis, rate * t): a spin about the node's own axis. */
    double q0[4] = {q0f[0], q0f[1], q0f[2], q0f[3]}, dq[4], expect[4], got[4];
    ob_dquat_normalize(q0, q0);
    ob_dquat_from_axis_angle((double[3]){1, 2, 3}, 0.7f * 2.0, dq);
    ob_dquat_mul(q0, dq, expect);
    ob_node_get_rotation(n, got);
    for (int k = 0; k < 4; k++) assert_near(got[k], expect[k], 1e-12);
    /* And the world matrix is that rotation. */
    float qf[4] = {(float)expect[0], (float)expect[1], (float)expect[2], (float)expect[3]};
    ref4 ref = ref_trs((double[3]){0, 0, 0}, qf, (float[3]){1, 1, 1});
    assert_world_equals(n, &ref, 1e-6);
    /* Invalid controllers are refused with the node's name. */
    ob_test_log_clear();
    assert_int_equal(ob_node_add_rotation_controller(n, (float[3]){0, 0, 0}, 1.0f),
                     OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'spinner'", NULL));
    assert_int_equal(ob_node_add_rotation_controller(n, (float[3]){0, 1, 0}, NAN),
                     OB_ERR_INVALID_ARGUMENT);
    ob_scene_destroy(s);
}

static void orbit_controller_stays_on_circle(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *flat = new_node(s, NULL, "flat"), *tilted = new_node(s, NULL, "tilted");
    const double c[3] = {1, 2, 3};
    assert_int_equal(ob_node_add_orbit_controller(flat, c, (float[3]){0, 1, 0}, 5, 0.5f, 0.25f), OB_OK);
    assert_int_equal(ob_node_add_orbit_controller(tilted, c, (float[3]){1, 1, 0}, 2, -1.5f, 0), OB_OK);
    for (int i = 0; i < 90; i++) ob_scene_update(s, 1.0 / 30.0);
    double p[3], d[3];
    /* Axis Y: angle 0 along +X, turning right-handedly (toward -Z). */
    double th = 0.25 + 0.5 * 3.0;
    ob_node_world_position(flat, p);
    assert_near(p[0], 1 + 5 * cos(th), 1e-9);
    assert_near(p[1], 2, 1e-12);
    assert_near(p[2], 3 - 5 * sin(th), 1e-9);
    /* Tilted axis: on the circle, in the plane. */
    ob_node_world_position(tilted, p);
    ob_dvec3_sub(p, c, d);
    assert_near(ob_dvec3_length(d), 2, 1e-12);
    assert_near(d[0] + d[1], 0, 1e-12);
    /* angle 0 is +Z here (least aligned axis); v = axis x u = (1,-1,0)/sqrt2 */
    th = -1.5 * 3.0;
    assert_near(d[2], 2 * cos(th), 1e-9);
    assert_near(d[0], 2 * sin(th) / sqrt(2.0), 1e-9);
    assert_int_equal(ob_node_add_orbit_controller(flat, c, (float[3]){0, 1, 0}, -1, 1, 0),
                     OB_ERR_INVALID_ARGUMENT);
    ob_scene_destroy(s);
}

typedef struct script_log {
    int calls[8];
    int count;
} script_log;

static void script_first(ob_node *n, double dt, void *user)
{
    (void)dt;
    script_log *log = user;
    log->calls[log->count++ % 8] = 1;
    ob_node_set_position(n, (double[3]){5, 0, 0});
}

static void script_second(ob_node *n, double dt, void *user)
{
    (void)n;
    (void)dt;
    script_log *log = user;
    log->calls[log->count++ % 8] = 2;
}

static void script_controllers_run_in_order_before_world(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n = new_node(s, NULL, "scripted"), *child = new_node(s, n, "child");
    ob_node_set_position(child, (double[3]){0, 1, 0});
    script_log log = {{0}, 0};
    assert_int_equal(ob_node_add_script_controller(n, script_first, &log), OB_OK);
    assert_int_equal(ob_node_add_script_controller(n, script_second, &log), OB_OK);
    assert_int_equal(ob_node_add_script_controller(n, NULL, &log), OB_ERR_INVALID_ARGUMENT);
    ob_scene_update(s, 0.5);
    assert_int_equal(log.count, 2);
    assert_int_equal(log.calls[0], 1);
    assert_int_equal(log.calls[1], 2);
    double p[3];
    ob_node_world_position(child, p); /* the script's move shows in this update */
    assert_near(p[0], 5, 0);
    assert_near(p[1], 1, 0);
    ob_scene_destroy(s);
}

typedef struct meddler {
    ob_scene *scene;
    ob_node *victim;
    ob_result create_r, parent_r, destroy_r, update_r;
    bool created;
} meddler;

static void script_meddles(ob_node *n, double dt, void *user)
{
    (void)n;
    (void)dt;
    meddler *m = user;
    m->create_r = OB_OK;
    m->created = ob_node_create(m->scene, NULL, "late", &m->create_r) != NULL;
    m->parent_r = ob_node_set_parent(m->scene, m->victim, NULL);
    m->destroy_r = ob_node_destroy(m->victim);
    m->update_r = ob_scene_update(m->scene, 0.0);
}

static void structure_changes_refused_inside_controllers(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n = new_node(s, NULL, "meddler"), *g = new_node(s, NULL, "g");
    meddler m = {.scene = s, .victim = new_node(s, g, "victim")};
    ob_node_add_script_controller(n, script_meddles, &m);
    assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
    assert_false(m.created);
    assert_int_equal(m.create_r, OB_ERR_WRONG_STATE);
    assert_int_equal(m.parent_r, OB_ERR_WRONG_STATE);
    assert_int_equal(m.destroy_r, OB_ERR_WRONG_STATE);
    assert_int_equal(m.update_r, OB_ERR_WRONG_STATE);
    assert_int_equal(ob_scene_node_count(s), 4);
    assert_ptr_equal(ob_node_get_parent(m.victim), g);
    assert_true(ob_test_log_has("'victim'", "not allowed inside a controller", NULL));
    ob_scene_destroy(s);
}

static void count_release(void *user) { (*(int *)user)++; }
static void noop_step(ob_node *n, double dt, void *user)
{
    (void)n;
    (void)dt;
    (void)user;
}

static void destroy_subtree_frees_everything(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *keep = new_node(s, NULL, "keep"), *doomed = new_node(s, NULL, "doomed");
    make_renderable(keep);
    int released = 0;
    ob_node *prev = doomed;
    for (int i = 0; i < 50; i++) {
        ob_node *n = new_node(s, i % 2 ? prev : doomed, "part");
        make_renderable(n);
        ob_node_set_light(n, &(ob_light_desc){.type = OB_LIGHT_POINT});
        ob_node_add_rotation_controller(n, (float[3]){0, 1, 0}, 1);
        ob_node_add_orbit_controller(n, (double[3]){0, 0, 0}, (float[3]){0, 1, 0}, 1, 1, 0);
        ob_node_add_controller(n, &(ob_controller_desc){.fn = noop_step, .user = &released,
                                                          .release = count_release});
        prev = n;
    }
    ob_scene_update(s, 0.1);
    uint32_t count, lights;
    ob_scene_renderables(s, &count);
    assert_int_equal(count, 51);
    uint32_t keep_id = ob_node_id(keep);
    ob_node_destroy(doomed);
    /* Gone from the snapshot at once, before the next update. */
    ob_node *const *items = ob_scene_renderables(s, &count);
    assert_int_equal(count, 1);
    assert_int_equal(ob_node_id(items[0]), keep_id);
    ob_scene_lights(s, &lights);
    assert_int_equal(lights, 0);
    assert_int_equal(released, 50);
    assert_int_equal(ob_scene_node_count(s), 2);
    assert_null(ob_scene_find(s, "part"));
    assert_null(ob_scene_find(s, "doomed"));
    assert_int_equal(ob_scene_update(s, 0.1), OB_OK);
    /* Ids are never reused. */
    ob_node *fresh = new_node(s, NULL, "fresh");
    assert_true(ob_node_id(fresh) > keep_id + 51);
    ob_node_destroy(NULL);
    ob_scene_destroy(s); /* ASan: no leak of nodes, names or controller state */
}

/* Destroying many nodes in one call: a node listed under another listed
 * one, twice, or NULL; what is left (snapshot, lights, tree) is what one
 * call per node would leave, in id order. */
static void destroy_many_matches_one_at_a_time(void **state)
{
    (void)state;
    ob_scene *batch = new_scene(), *single = new_scene();
    ob_scene *scenes[2] = {batch, single};
    ob_node *nodes[2][40];
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < 40; i++) {
            /* Every fifth node a root-level one; the rest hang under the
             * previous node, so subtrees nest. */
            nodes[k][i] = new_node(scenes[k], i % 5 ? nodes[k][i - 1] : NULL, "n");
            make_renderable(nodes[k][i]);
            if (i % 3 == 0) ob_node_set_light(nodes[k][i], &(ob_light_desc){.type = OB_LIGHT_POINT});
        }
        assert_int_equal(ob_scene_update(scenes[k], 0.1), OB_OK);
    }
    /* 7 lies under 6 (both listed, the child first), 6 twice, 20 with its
     * subtree, 33 alone at the end of its chain, 0's chain from its root. */
    ob_node *list[] = {nodes[0][7], nodes[0][6], NULL, nodes[0][20], nodes[0][6], nodes[0][34],
                       nodes[0][0]};
    ob_nodes_destroy(batch, list, OB_ARRAY_COUNT(list));
    int order[] = {34, 20, 6, 0};
    for (size_t i = 0; i < OB_ARRAY_COUNT(order); i++) ob_node_destroy(nodes[1][order[i]]);
    for (int pass = 0; pass < 2; pass++) {
        uint32_t nb, ns, lb, ls;
        ob_node *const *rb = ob_scene_renderables(batch, &nb);
        ob_node *const *rs = ob_scene_renderables(single, &ns);
        assert_int_equal(nb, ns);
        /* 40 less 0-4, 6-9, 20-24, 34 */
        assert_int_equal(nb, 40 - 5 - 4 - 5 - 1);
        for (uint32_t i = 0; i < nb; i++) {
            assert_int_equal(ob_node_id(rb[i]), ob_node_id(rs[i]));
            if (i) assert_true(ob_node_id(rb[i]) > ob_node_id(rb[i - 1]));
        }
        ob_render_soa sb, ss;
        ob_scene_render_soa(batch, &sb);
        ob_scene_render_soa(single, &ss);
        assert_int_equal(sb.count, nb);
        for (uint32_t i = 0; i < nb; i++) {
            assert_ptr_equal(sb.node[i], rb[i]);
            assert_int_equal(sb.node_id[i], ob_node_id(rb[i]));
            assert_memory_equal(&sb.x[i], &ss.x[i], sizeof(double));
        }
        ob_node *const *la = ob_scene_lights(batch, &lb);
        ob_node *const *lsn = ob_scene_lights(single, &ls);
        assert_int_equal(lb, ls);
        for (uint32_t i = 0; i < lb; i++) assert_int_equal(ob_node_id(la[i]), ob_node_id(lsn[i]));
        assert_int_equal(ob_scene_node_count(batch), ob_scene_node_count(single));
        assert_int_equal(ob_scene_node_count(batch), 1 + 25);
        /* And the same after an update. */
        assert_int_equal(ob_scene_update(batch, 0.1), OB_OK);
        assert_int_equal(ob_scene_update(single, 0.1), OB_OK);
    }
    ob_nodes_destroy(batch, NULL, 0);
    ob_scene_destroy(batch); /* ASan: nothing leaked, nothing freed twice */
    ob_scene_destroy(single);
}

typedef struct counter_state {
    uint32_t calls;
    double sum;
    int *released;
} counter_state;

static void counter_step(ob_node *n, double dt, void *user)
{
    (void)n;
    counter_state *st = user;
    st->calls++;
    st->sum += dt;
}

static void counter_release(void *user)
{
    counter_state *st = user;
    *st->released += (int)st->calls;
}

typedef struct adder {
    ob_node *target;
    counter_state added;
    bool done;
} adder;

/* Serial: adds a counter to another node once, from inside the update. */
static void add_once(ob_node *n, double dt, void *user)
{
    (void)n;
    (void)dt;
    adder *a = user;
    if (a->done) return;
    a->done = true;
    assert_int_equal(ob_node_add_controller_state(a->target, &(ob_controller_desc){
                         .fn = counter_step, .release = counter_release, .parallel = true},
                         &a->added, sizeof a->added), OB_OK);
}

static void controller_state_kept_by_the_node(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *a = new_node(s, NULL, "a"), *b = new_node(s, NULL, "b");
    int released = 0;
    counter_state init = {.released = &released};
    const ob_controller_desc d = {.fn = counter_step, .release = counter_release, .parallel = true};
    assert_int_equal(ob_node_add_controller_state(a, &d, &init, sizeof init), OB_OK);
    /* Many nodes' controllers, so that they are repacked into one pool. */
    for (int i = 0; i < 200; i++) {
        ob_node *m = new_node(s, b, "m");
        assert_int_equal(ob_node_add_controller_state(m, &d, &init, sizeof init), OB_OK);
        ob_node_add_rotation_controller(m, (float[3]){0, 1, 0}, 1);
    }
    adder add = {.target = b, .added = {.released = &released}};
    assert_int_equal(ob_node_add_script_controller(a, add_once, &add), OB_OK);
    for (int i = 0; i < 3; i++) assert_int_equal(ob_scene_update(s, 0.5), OB_OK);
    assert_int_equal(init.calls, 0); /* the node's copy counted, not the caller's */
    assert_true(add.done);
    /* A state over the limit is refused, its release run at once. */
    char big[OB_CONTROLLER_STATE_SIZE + 8] = {0};
    ob_test_log_clear();
    assert_int_equal(ob_node_add_controller_state(a, &(ob_controller_desc){.fn = counter_step},
                                                  big, sizeof big), OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'a'", "state", NULL));
    ob_node_destroy(b);
    /* b's counter was added by a's script in the first update and ran in the
     * two after it (parallel ones run before serial ones); each of the 200
     * children's ran three times. */
    assert_int_equal(released, 2 + 200 * 3);
    ob_scene_destroy(s);
    assert_int_equal(released, 2 + 200 * 3 + 3);
}

/* ------------------------------------------------ non-finite transforms */

typedef enum fault_kind {
    BAD_POSITION,
    BAD_ROTATION,
    BAD_SCALE,
    BAD_SCRIPT,
    BAD_ZERO_QUAT,
    BAD_OVERFLOW,
    BAD_KIND_COUNT
} fault_kind;

typedef struct bad_script {
    bool produce_inf;
} bad_script;

static void script_maybe_inf(ob_node *n, double dt, void *user)
{
    (void)dt;
    const bad_script *b = user;
    ob_node_set_position(n, (double[3]){b->produce_inf ? INFINITY : 1.0, 0, 0});
}

static void break_node(ob_node *mover, ob_node *passenger, fault_kind kind, bad_script *script, bool broken)
{
    switch (kind) {
    case BAD_POSITION:
        ob_node_set_position(mover, (double[3]){1, broken ? NAN : 0, 0});
        break;
    case BAD_ROTATION:
        ob_node_set_rotation(mover, (float[4]){0, 0, broken ? NAN : 0, 1});
        break;
    case BAD_SCALE:
        ob_node_set_scale(mover, (float[3]){1, broken ? INFINITY : 1, 1});
        break;
    case BAD_SCRIPT:
        script->produce_inf = broken;
        break;
    case BAD_ZERO_QUAT:
        ob_node_set_rotation(mover, (float[4]){0, 0, 0, broken ? 0.0f : 2.0f});
        break;
    case BAD_OVERFLOW: /* each finite, the product overflows */
        ob_node_set_scale(mover, (float[3]){1e30f, 1, 1});
        ob_node_set_scale(passenger, (float[3]){broken ? 1e30f : 1.0f, 1, 1});
        ob_node_set_position(passenger, (double[3]){broken ? 1e300 : 0.0, 0, 0});
        break;
    case BAD_KIND_COUNT:
        break;
    }
}

static void bad_transform_rejected_once_and_recovers(void **state)
{
    (void)state;
    for (int kind = 0; kind < BAD_KIND_COUNT; kind++) {
        ob_scene *s = new_scene();
        ob_node *mover = new_node(s, NULL, "mover"), *passenger = new_node(s, mover, "passenger");
        ob_node *grandchild = new_node(s, passenger, "grandchild");
        ob_node *bystander = new_node(s, NULL, "bystander");
        make_renderable(mover);
        make_renderable(passenger);
        make_renderable(grandchild);
        make_renderable(bystander);
        bad_script script = {false};
        if (kind == BAD_SCRIPT) ob_node_add_script_controller(mover, script_maybe_inf, &script);
        ob_scene_update(s, 0.0);
        uint32_t count;
        ob_scene_renderables(s, &count);
        assert_int_equal(count, 4);

        /* Overflow is caught at the first non-finite world: the passenger. */
        ob_node *culprit = kind == BAD_OVERFLOW ? passenger : mover;
        char expect[160];
        snprintf(expect, sizeof expect, "entity '%s' (id %u): %s; not rendered",
                 ob_node_name(culprit), ob_node_id(culprit),
                 kind == BAD_ZERO_QUAT ? "zero-length rotation quaternion" : "non-finite transform");
        ob_test_log_clear();
        break_node(mover, passenger, (fault_kind)kind, &script, true);
        for (int frame = 0; frame < 5; frame++) {
            ob_node_set_position(bystander, (double[3]){frame, 0, 0});
            assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
        }
        if (!ob_test_log_has(expect, NULL)) fail_msg("kind %d: missing '%s'", kind, expect);
        assert_int_equal(ob_test_log_count(OB_LOG_ERROR), 1);
        assert_false(ob_node_is_renderable(passenger));
        assert_false(ob_node_is_renderable(grandchild));
        assert_false(ob_node_transform_is_valid(grandchild));
        assert_int_equal(ob_node_is_renderable(mover), kind == BAD_OVERFLOW);
        assert_true(ob_node_is_renderable(bystander));
        double p[3];
        ob_node_world_position(bystander, p); /* the rest still updates */
        assert_near(p[0], 4, 0);
        ob_node *const *items = ob_scene_renderables(s, &count);
        assert_int_equal(count, kind == BAD_OVERFLOW ? 2 : 1);
        assert_ptr_equal(items[count - 1], bystander);
        /* Queries on the rejected node stay finite (last valid world). */
        float rel[16];
        ob_node_world_relative(grandchild, (double[3]){0, 0, 0}, rel);
        for (int k = 0; k < 16; k++) assert_true(isfinite(rel[k]));

        break_node(mover, passenger, (fault_kind)kind, &script, false);
        assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
        assert_true(ob_node_is_renderable(passenger));
        assert_true(ob_node_is_renderable(grandchild));
        ob_scene_renderables(s, &count);
        assert_int_equal(count, 4);
        assert_true(ob_test_log_has(ob_node_name(culprit), "finite again", NULL));
        assert_int_equal(ob_test_log_count(OB_LOG_ERROR), 1);
        ob_scene_destroy(s);
    }
}

/* Spinning renderable leaves under the root take the update's common
 * path, two at a time: one with a bad position, scale or orbit is named and dropped on
 * its own, the leaf sharing its pair is placed as usual, and both come
 * back once their transform is finite again. */
static void bad_leaf_rejected_beside_a_good_one(void **state)
{
    (void)state;
    enum { LEAVES = 8 };
    for (int kind = 0; kind < 3; kind++) {
        ob_scene *s = new_scene();
        ob_node *leaf[LEAVES];
        for (int k = 0; k < LEAVES; k++) {
            char name[16];
            snprintf(name, sizeof name, "leaf%d", k);
            leaf[k] = new_node(s, NULL, name);
            make_renderable(leaf[k]);
            ob_node_set_position(leaf[k], (double[3]){k, 0, 0});
            /* The common path takes a rotation its spin keeps unit. */
            assert_int_equal(ob_node_add_rotation_controller(leaf[k], (float[3]){0, 1, 0}, 0.5f),
                             OB_OK);
        }
        ob_node *bad = leaf[5];
        if (kind == 2) /* each input finite, the orbit's position overflows */
            assert_int_equal(ob_node_add_orbit_controller(bad, (double[3]){DBL_MAX, 0, 0},
                                                          (float[3]){0, 1, 0}, 0.75 * DBL_MAX,
                                                          0.0f, 0.0f),
                             OB_OK);
        char expect[96];
        snprintf(expect, sizeof expect, "entity 'leaf5' (id %u): non-finite transform; not rendered",
                 ob_node_id(bad));
        ob_test_log_clear();
        assert_int_equal(ob_scene_update(s, 0.0), OB_OK);
        uint32_t count;
        ob_scene_renderables(s, &count);
        assert_int_equal(count, kind == 2 ? LEAVES - 1 : LEAVES);
        assert_int_equal(ob_test_log_count(OB_LOG_ERROR), kind == 2);
        if (kind == 2) assert_true(ob_test_log_has(expect, NULL));
        ob_test_log_clear();
        if (kind == 0) ob_node_set_position(bad, (double[3]){NAN, 0, 0});
        if (kind == 1) ob_node_set_scale(bad, (float[3]){1, INFINITY, 1});
        for (int k = 0; k < LEAVES; k++)
            if (leaf[k] != bad) ob_node_set_position(leaf[k], (double[3]){k, 2, 0});
        assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
        /* Named once: at its first bad update. */
        assert_int_equal(ob_test_log_count(OB_LOG_ERROR), kind != 2);
        if (kind != 2 && !ob_test_log_has(expect, NULL))
            fail_msg("kind %d: missing '%s'", kind, expect);
        assert_false(ob_node_is_renderable(bad));
        ob_scene_renderables(s, &count);
        assert_int_equal(count, LEAVES - 1);
        for (int k = 0; k < LEAVES; k++) {
            if (leaf[k] == bad) continue;
            double p[3];
            ob_node_world_position(leaf[k], p);
            assert_true(p[0] == k && p[1] == 2 && p[2] == 0);
            assert_true(ob_node_is_renderable(leaf[k]));
        }
        if (kind == 0) ob_node_set_position(bad, (double[3]){5, 2, 0});
        if (kind == 1) ob_node_set_scale(bad, (float[3]){1, 1, 1});
        if (kind != 2) {
            assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
            assert_true(ob_node_is_renderable(bad));
            ob_scene_renderables(s, &count);
            assert_int_equal(count, LEAVES);
            assert_true(ob_test_log_has("leaf5", "finite again", NULL));
        }
        ob_scene_destroy(s);
    }
}

static void bad_update_arguments_refused(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    assert_int_equal(ob_scene_update(s, NAN), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_scene_update(s, -1.0), OB_ERR_INVALID_ARGUMENT);
    ob_node *n = new_node(s, NULL, "boxy");
    ob_test_log_clear();
    assert_int_equal(ob_node_set_renderable(n, &(ob_renderable){.local_radius = -1}),
                     OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_renderable(n, &(ob_renderable){.local_center = {NAN, 0, 0}}),
                     OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'boxy'", "renderable", NULL));
    assert_null(ob_node_get_renderable(n));
    ob_scene_destroy(s);
}

static void cameras_and_lights(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *cam = new_node(s, NULL, "cam");
    assert_null(ob_node_get_camera(cam));
    assert_int_equal(ob_node_set_camera(cam, &(ob_camera_desc){0}), OB_OK);
    const ob_camera_desc *cd = ob_node_get_camera(cam);
    assert_non_null(cd);
    assert_near(cd->fovy, OB_PI / 3, 1e-6);
    assert_near(cd->znear, 0.1, 1e-7);
    assert_near(cd->aspect, 0, 0);
    assert_int_equal(ob_node_set_camera(cam, &(ob_camera_desc){.fovy = 4}), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_camera(cam, &(ob_camera_desc){.znear = -1}), OB_ERR_INVALID_ARGUMENT);
    assert_near(ob_node_get_camera(cam)->fovy, OB_PI / 3, 1e-6); /* unchanged */
    ob_node_set_camera(cam, NULL);
    assert_null(ob_node_get_camera(cam));

    ob_node *sun = new_node(s, NULL, "sun"), *lamp = new_node(s, NULL, "lamp");
    ob_node *off = new_node(s, NULL, "off"), *broken = new_node(s, NULL, "broken");
    assert_int_equal(ob_node_set_light(sun, &(ob_light_desc){.type = OB_LIGHT_DIRECTIONAL,
                                                             .casts_shadows = true}), OB_OK);
    const ob_light_desc *ld = ob_node_get_light(sun);
    assert_near(ld->color[1], 1, 0);
    assert_near(ld->intensity, 0, 0); /* literal: a light faded to 0 stays off */
    assert_true(ld->casts_shadows);
    assert_int_equal(ob_node_set_light(lamp, &(ob_light_desc){.type = OB_LIGHT_POINT,
                                                              .color = {1, 0.5f, 0},
                                                              .intensity = 3, .range = 10}), OB_OK);
    assert_near(ob_node_get_light(lamp)->color[1], 0.5, 0);
    assert_int_equal(ob_node_set_light(off, &(ob_light_desc){.intensity = -1}), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_light(off, &(ob_light_desc){.type = (ob_light_type)7}),
                     OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_node_set_light(off, &(ob_light_desc){.type = OB_LIGHT_POINT}), OB_OK);
    assert_int_equal(ob_node_set_light(broken, &(ob_light_desc){.type = OB_LIGHT_POINT}), OB_OK);
    ob_node_set_hidden(off, true);
    ob_node_set_position(broken, (double[3]){NAN, 0, 0});
    ob_scene_update(s, 0.0);
    uint32_t count;
    ob_node *const *lights = ob_scene_lights(s, &count);
    assert_int_equal(count, 2);
    assert_ptr_equal(lights[0], sun);
    assert_ptr_equal(lights[1], lamp);
    /* A directional light shines along its node's forward. */
    ob_node_set_euler(sun, -(float)OB_PI / 2, 0, 0); /* pitch down */
    ob_scene_update(s, 0.0);
    float fwd[3];
    ob_node_world_axes(sun, NULL, NULL, fwd);
    assert_near(fwd[1], -1, 1e-6);
    ob_node_set_light(lamp, NULL);
    assert_null(ob_node_get_light(lamp));
    ob_scene_destroy(s);
}

static void look_at_aims_forward(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *arm = new_node(s, NULL, "arm"), *eye = new_node(s, arm, "eye");
    ob_node_set_position(arm, (double[3]){10, 0, 0});
    ob_node_set_rotation(arm, (float[4]){0, 0.70710678f, 0, 0.70710678f});
    ob_node_set_position(eye, (double[3]){0, 3, 5});
    /* No update yet: look_at walks the ancestors itself. */
    const double target[3] = {-1, 2, 7};
    assert_int_equal(ob_node_look_at(eye, target, (double[3]){0, 1, 0}), OB_OK);
    ob_scene_update(s, 0.0);
    double p[3], dir[3];
    ob_node_world_position(eye, p);
    assert_near(p[0], 15, 1e-6); /* +Z rotated 90° about Y is +X */
    ob_dvec3_sub(target, p, dir);
    ob_dvec3_normalize(dir, dir);
    float r[3], u[3], f[3];
    ob_node_world_axes(eye, r, u, f);
    for (int k = 0; k < 3; k++) assert_near(f[k], dir[k], 1e-6);
    assert_true(u[1] > 0);
    assert_near(r[1], 0, 1e-6); /* no roll */

    ob_test_log_clear();
    assert_int_equal(ob_node_look_at(eye, (double[3]){15, 100, 0}, (double[3]){0, 1, 0}), OB_OK);
    assert_true(ob_test_log_has("entity 'eye'", "another up axis", NULL));
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 1);
    ob_scene_update(s, 0.0);
    ob_node_world_axes(eye, r, u, f);
    assert_near(f[1], 1, 1e-6);
    for (int k = 0; k < 3; k++) assert_true(isfinite(r[k]) && isfinite(u[k]));

    double before[4], after[4];
    ob_node_get_rotation(eye, before);
    assert_int_equal(ob_node_look_at(eye, p, (double[3]){0, 1, 0}), OB_ERR_INVALID_ARGUMENT);
    ob_node_get_rotation(eye, after);
    assert_memory_equal(before, after, sizeof before);
    ob_scene_destroy(s);
}

static void world_sphere_and_axes(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *n = new_node(s, NULL, "blob");
    ob_node_set_position(n, (double[3]){1e7, 0, -2});
    ob_node_set_rotation(n, (float[4]){0, 0, 0.70710678f, 0.70710678f}); /* 90° about Z */
    ob_node_set_scale(n, (float[3]){2, 3, 1});
    ob_renderable rd = {.local_center = {1, 0, 0}, .local_radius = 2};
    ob_node_set_renderable(n, &rd);
    ob_scene_update(s, 0.0);
    double c[3];
    float radius;
    ob_node_world_sphere(n, c, &radius);
    assert_near(c[0], 1e7, 1e-6);
    assert_near(c[1], 2, 1e-6);
    assert_near(radius, 6, 1e-5);
    float r[3], u[3], f[3];
    ob_node_world_axes(n, r, u, f);
    assert_near(r[1], 1, 1e-6);
    assert_near(u[0], -1, 1e-6);
    assert_near(f[2], -1, 1e-6);
    ob_node *plain = new_node(s, NULL, "plain");
    ob_scene_update(s, 0.0);
    ob_node_world_sphere(plain, c, &radius);
    assert_near(radius, 0, 0);
    ob_scene_destroy(s);
}

static void find_names_and_user_data(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *a = new_node(s, NULL, "twin"), *b = new_node(s, NULL, "twin");
    ob_node *anon = new_node(s, NULL, NULL);
    assert_ptr_equal(ob_scene_find(s, "twin"), a);
    assert_ptr_equal(ob_scene_find(s, "root"), ob_scene_root(s));
    assert_null(ob_scene_find(s, "nobody"));
    assert_string_equal(ob_node_name(anon), "");
    int tag;
    ob_node_set_user(b, &tag);
    assert_ptr_equal(ob_node_get_user(b), &tag);
    assert_null(ob_node_get_user(a));
    assert_int_equal(ob_scene_node_count(s), 4);
    uint32_t count = 99;
    ob_node *const *items = ob_scene_renderables(s, &count);
    assert_non_null(items);
    assert_int_equal(count, 0);
    ob_scene_destroy(s);
    ob_scene_destroy(NULL);
}

/* --------------------------------------------------------- fault injection */

static ob_result fault_scenario(void)
{
    ob_result r = OB_OK;
    ob_scene *s = ob_scene_create(&r);
    if (!s) return r;
    ob_node *prev = NULL, *mid = NULL;
    for (int i = 0; i < 40 && r == OB_OK; i++) {
        ob_node *n = ob_node_create(s, i % 3 ? prev : NULL, "node", &r);
        if (!n) break;
        make_renderable(n);
        if (i % 5 == 0) r = ob_node_add_rotation_controller(n, (float[3]){0, 1, 0}, 1);
        if (r == OB_OK && i % 7 == 0)
            r = ob_node_add_orbit_controller(n, (double[3]){0, 0, 0}, (float[3]){0, 1, 0}, 2, 1, 0);
        if (r == OB_OK && i % 4 == 0) r = ob_node_add_script_controller(n, noop_step, NULL);
        if (i == 20) mid = n;
        prev = n;
    }
    if (r == OB_OK) r = ob_scene_update(s, 0.1);
    if (r == OB_OK) {
        ob_node_destroy(mid);
        r = ob_scene_update(s, 0.1);
    }
    if (r == OB_OK) {
        uint32_t count;
        ob_scene_renderables(s, &count);
        if (count == 0) r = OB_ERR_WRONG_STATE; /* must never happen */
    }
    ob_scene_destroy(s);
    return r;
}

/* The built-in controllers of a node without others live apart from the
 * controller list (scene->motion) until another controller comes: a node
 * must move the same whichever way its controllers are kept, with a
 * second rotation, with serial controllers, and after destroyed nodes'
 * slots are compacted away. */
static void builtin_controllers_kept_apart_move_the_same(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *doomed[80];
    for (int i = 0; i < 80; i++) {
        doomed[i] = new_node(s, NULL, "doomed");
        ob_node_add_rotation_controller(doomed[i], (float[3]){1, 0, 0}, 2);
    }
    /* kinds: 0 apart; 1 listed (a no-op first); 2 apart, then a second
     * rotation; 3 listed with a second rotation; 4 apart, then a serial
     * controller; 5 listed with one */
    ob_node *n[6];
    int released = 0;
    for (int k = 0; k < 6; k++) {
        n[k] = new_node(s, NULL, "moving");
        make_renderable(n[k]);
        if (k % 2)
            assert_int_equal(ob_node_add_controller(n[k], &(ob_controller_desc){
                                 .fn = noop_step, .user = &released, .parallel = true}), OB_OK);
        assert_int_equal(ob_node_add_orbit_controller(n[k], (double[3]){1e6, 2, 3},
                                                      (float[3]){0, 1, 0.5f}, 4, 0.9f, 0.3f),
                         OB_OK);
        assert_int_equal(ob_node_add_rotation_controller(n[k], (float[3]){1, 2, 3}, 0.7f), OB_OK);
    }
    assert_int_equal(ob_scene_update(s, 1.0 / 60.0), OB_OK);
    for (int k = 2; k < 4; k++)
        assert_int_equal(ob_node_add_rotation_controller(n[k], (float[3]){0, 0, 1}, -1.1f), OB_OK);
    for (int k = 4; k < 6; k++)
        assert_int_equal(ob_node_add_controller(n[k], &(ob_controller_desc){
                             .fn = noop_step, .user = &released}), OB_OK);
    for (int i = 0; i < 80; i++) ob_node_destroy(doomed[i]);
    for (int i = 0; i < 100; i++) assert_int_equal(ob_scene_update(s, i % 3 ? 1.0 / 60.0 : 0.05), OB_OK);
    for (int k = 0; k < 6; k += 2) {
        double pa[3], pb[3], qa[4], qb[4];
        ob_daffine wa, wb;
        ob_node_get_position(n[k], pa);
        ob_node_get_position(n[k + 1], pb);
        ob_node_get_rotation(n[k], qa);
        ob_node_get_rotation(n[k + 1], qb);
        ob_node_world_affine(n[k], &wa);
        ob_node_world_affine(n[k + 1], &wb);
        assert_memory_equal(pa, pb, sizeof pa);
        assert_memory_equal(qa, qb, sizeof qa);
        assert_memory_equal(&wa, &wb, sizeof wa);
        assert_true(fabs(pa[0] - 1e6) > 0.1); /* it moved */
    }
    /* The second rotation turned kinds 2 and 3 on from where 0 and 1 are. */
    double q0[4], q2[4];
    ob_node_get_rotation(n[0], q0);
    ob_node_get_rotation(n[2], q2);
    assert_true(fabs(q0[0] - q2[0]) + fabs(q0[3] - q2[3]) > 1e-3);
    ob_scene_destroy(s);
}

/* The update runs the built-in controllers on two nodes at once: a node
 * moves by the same bits whichever node shares its pair, and alone (the
 * one-node form, which the listed controllers use): an orbit whose angle
 * wraps (its fmod), one far from the origin, a rotation so small or so
 * large that its normalization rescales, each beside ordinary ones. */
static ob_node *grouped_node(ob_scene *s, uint32_t kind)
{
    ob_node *n = new_node(s, NULL, "grouped");
    make_renderable(n);
    const double centre[3] = {kind == 3 ? 1e9 : 0.5, -2, 3};
    const float axis[3] = {0.2f * (float)kind, 1, 0.5f};
    static const float rates[7] = {0.9f, 80.0f, 0, -1.3f, 2.1f, 0.4f, -60.0f};
    if (kind != 2)
        assert_int_equal(ob_node_add_orbit_controller(n, centre, axis, 1.5 + kind, rates[kind],
                                                      0.1f * (float)kind), OB_OK);
    if (kind == 4) ob_node_set_rotation_d(n, (double[4]){1e-200, 0, 3e-201, 1e-200});
    if (kind == 5) ob_node_set_rotation_d(n, (double[4]){0, 2e200, 0, 1e200});
    if (kind != 3)
        assert_int_equal(ob_node_add_rotation_controller(n, (float[3]){1, 2.0f - (float)kind, 3},
                                                         0.3f + 0.5f * (float)kind), OB_OK);
    return n;
}

/* Nodes of the given grouped_node kinds added to scenes x and y (each
 * may hold other nodes already, and be set to update differently) and
 * each alone in a scene of its own; after `steps` updates each node is at
 * the same position, rotation and world, bit for bit, in all three. The
 * nodes of x in out. */
static void same_motion_three_ways(ob_scene *x, ob_scene *y, const uint32_t *kinds,
                                   uint32_t count, int steps, ob_node **out)
{
    ob_node *ny[16], *na[16];
    ob_scene *alone[16];
    assert_true(count <= 16);
    for (uint32_t k = 0; k < count; k++) {
        out[k] = grouped_node(x, kinds[k]);
        ny[k] = grouped_node(y, kinds[k]);
        alone[k] = new_scene();
        na[k] = grouped_node(alone[k], kinds[k]);
    }
    for (int i = 0; i < steps; i++) {
        double dt = i % 4 ? 1.0 / 60.0 : 0.05;
        assert_int_equal(ob_scene_update(x, dt), OB_OK);
        assert_int_equal(ob_scene_update(y, dt), OB_OK);
        for (uint32_t k = 0; k < count; k++) assert_int_equal(ob_scene_update(alone[k], dt), OB_OK);
    }
    for (uint32_t k = 0; k < count; k++) {
        const ob_node *n[3] = {out[k], ny[k], na[k]};
        double p[3][3], q[3][4];
        ob_daffine w[3];
        for (int v = 0; v < 3; v++) {
            ob_node_get_position(n[v], p[v]);
            ob_node_get_rotation(n[v], q[v]);
            ob_node_world_affine(n[v], &w[v]);
        }
        for (int v = 1; v < 3; v++) {
            assert_memory_equal(p[0], p[v], sizeof p[0]);
            assert_memory_equal(q[0], q[v], sizeof q[0]);
            assert_memory_equal(&w[0], &w[v], sizeof w[0]);
        }
        ob_scene_destroy(alone[k]);
    }
}

static void builtin_controllers_same_bits_in_any_pair(void **state)
{
    (void)state;
    static const uint32_t kinds[] = {0, 1, 2, 3, 4, 5, 6};
    enum { KINDS = sizeof kinds / sizeof kinds[0] };
    ob_scene *grouped = new_scene(), *shifted = new_scene();
    ob_node *g[KINDS];
    /* shifted starts with one more node, so every pair holds other nodes */
    grouped_node(shifted, 0);
    same_motion_three_ways(grouped, shifted, kinds, KINDS, 120, g);
    for (uint32_t k = 0; k < KINDS; k++) {
        /* an orbit took it off the origin; its rotation stays unit */
        double p[3], q[4];
        ob_node_get_position(g[k], p);
        ob_node_get_rotation(g[k], q);
        if (k != 2) assert_true(ob_dvec3_length(p) > 0.1);
        double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        assert_near(len, 1.0, 1e-12);
    }
    ob_scene_destroy(grouped);
    ob_scene_destroy(shifted);
}

/* Where the CPU has AVX2, a step of four nodes that each have both
 * built-in controllers runs in four lanes: the same bits as two at a time
 * (motion_lanes2) and as alone, with orbits that wrap and rotations whose
 * normalization rescales (the four-lane step then falls back to pairs). */
static void builtin_controllers_same_bits_in_four_lanes(void **state)
{
    (void)state;
    static const uint32_t kinds[] = {0, 1, 4, 5, 6, 0, 1, 6, 4, 0, 5, 1, 6, 0, 1, 4};
    enum { NODES = sizeof kinds / sizeof kinds[0] };
    ob_scene *four = new_scene(), *two = new_scene();
    two->motion_lanes2 = true;
    ob_node *f[NODES];
    same_motion_three_ways(four, two, kinds, NODES, 90, f);
    for (uint32_t k = 0; k < NODES; k++) {
        double p[3];
        ob_node_get_position(f[k], p);
        assert_true(ob_dvec3_length(p) > 0.1);
    }
    ob_scene_destroy(four);
    ob_scene_destroy(two);
}

/* The update evaluates the common node (a renderable leaf under the root,
 * shown, valid, its rotation unit) in a pass of its own, two at a time; a
 * light on the same node sends it through the general evaluation. Both
 * give the same world, proxy and bound bits, at any scale: mirrored, zero,
 * in one axis, so large or so small that the normal matrix rescales. */
static void common_nodes_check(bool spin_all)
{
    enum { NODES = 9, STEPS = 40 };
    static const float scales[NODES][3] = {
        {1, 1, 1},  {-1, 2, 0.5f},           {0, 0, 0},          {3e30f, 1e30f, 2e30f},
        {1e-25f, 2e-25f, 1e-25f}, {1, 1, 1}, {0.5f, 0.5f, 0.5f}, {2, -3, 4},
        {0, 1, 1}};
    ob_scene *sc[2] = {new_scene(), new_scene()};
    ob_node *n[2][NODES];
    ob_light_desc light = {.type = OB_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 1, .range = 5};
    for (int v = 0; v < 2; v++) {
        for (int k = 0; k < NODES; k++) {
            n[v][k] = new_node(sc[v], NULL, "common");
            ob_renderable rd = {.local_center = {0.25f * (float)k, -1, 0.5f}, .local_radius = 1.5f};
            assert_int_equal(ob_node_set_renderable(n[v][k], &rd), OB_OK);
            ob_node_set_scale(n[v][k], scales[k]);
            assert_int_equal(ob_node_add_orbit_controller(n[v][k], (double[3]){1e5 * k, 2, 3},
                                                          (float[3]){0, 1, 0}, 2 + k, 0.7f,
                                                          0.2f * (float)k),
                             OB_OK);
            if (k % 3 || spin_all)
                assert_int_equal(ob_node_add_rotation_controller(n[v][k],
                                                                 (float[3]){1, 2, (float)k}, 1.1f),
                                 OB_OK);
            if (v == 1) assert_int_equal(ob_node_set_light(n[v][k], &light), OB_OK);
        }
    }
    for (int i = 0; i < STEPS; i++) {
        for (int v = 0; v < 2; v++) assert_int_equal(ob_scene_update(sc[v], 1.0 / 30.0), OB_OK);
        uint32_t count[2];
        const ob_render_proxy *p[2] = {ob_scene_render_proxies(sc[0], &count[0]),
                                       ob_scene_render_proxies(sc[1], &count[1])};
        ob_render_soa soa[2];
        ob_scene_render_soa(sc[0], &soa[0]);
        ob_scene_render_soa(sc[1], &soa[1]);
        assert_int_equal(count[0], NODES);
        assert_int_equal(count[1], NODES);
        for (uint32_t k = 0; k < NODES; k++) {
            assert_memory_equal(p[0][k].linear, p[1][k].linear, sizeof p[0][k].linear);
            float block[2][32];
            ob_render_proxy_per_draw(&p[0][k], (double[3]){0, 0, 0}, block[0]);
            ob_render_proxy_per_draw(&p[1][k], (double[3]){0, 0, 0}, block[1]);
            assert_memory_equal(block[0], block[1], sizeof block[0]);
            assert_memory_equal(p[0][k].world_t, p[1][k].world_t, sizeof p[0][k].world_t);
            assert_int_equal(p[0][k].finite, p[1][k].finite);
            assert_int_equal(p[0][k].mirrors, p[1][k].mirrors);
            assert_memory_equal(&soa[0].x[k], &soa[1].x[k], sizeof soa[0].x[k]);
            assert_memory_equal(&soa[0].y[k], &soa[1].y[k], sizeof soa[0].y[k]);
            assert_memory_equal(&soa[0].z[k], &soa[1].z[k], sizeof soa[0].z[k]);
            assert_memory_equal(&soa[0].radius[k], &soa[1].radius[k], sizeof soa[0].radius[k]);
            assert_int_equal(soa[0].flags[k], soa[1].flags[k]);
            ob_daffine w[2];
            ob_node_world_affine(n[0][k], &w[0]);
            ob_node_world_affine(n[1][k], &w[1]);
            assert_memory_equal(&w[0], &w[1], sizeof w[0]);
        }
        /* a zero scale is flagged; the huge and tiny ones stay finite; the
         * mirrored ones mirror */
        assert_int_equal(soa[0].flags[2], OB_RENDER_ZERO_SCALE);
        assert_true(p[0][1].mirrors && p[0][7].mirrors && !p[0][0].mirrors);
        assert_true(p[0][3].finite && p[0][4].finite);
    }
    ob_scene_destroy(sc[0]);
    ob_scene_destroy(sc[1]);
}

static void common_nodes_evaluate_as_any_other(void **state)
{
    (void)state;
    common_nodes_check(false);
}

/* All of them spinning: where the CPU has AVX2, steps of four common
 * nodes evaluate in four lanes, with the same bits. */
static void common_nodes_in_four_lanes_evaluate_as_any_other(void **state)
{
    (void)state;
    common_nodes_check(true);
}

typedef struct axes_probe {
    ob_node *watched;
    float forward[3];
} axes_probe;

static void probe_axes(ob_node *n, double dt, void *user)
{
    (void)n;
    (void)dt;
    axes_probe *p = user;
    ob_node_world_axes(p->watched, NULL, NULL, p->forward);
}

/* A zero-scale node's axes come from its world rotation, which is kept as
 * of the last update however the rotation changes after it: by a setter,
 * or by a rotation controller seen from a serial one during the update;
 * under a rotated parent too. */
static void world_rotation_as_of_last_update(void **state)
{
    (void)state;
    ob_scene *s = new_scene();
    ob_node *flat = new_node(s, NULL, "flat"), *parent = new_node(s, NULL, "parent");
    ob_node *child = new_node(s, parent, "child"), *spin = new_node(s, NULL, "spin");
    ob_node *watcher = new_node(s, NULL, "watcher");
    const float zero[3] = {0, 0, 0};
    const float about_y[4] = {0, 0.70710678f, 0, 0.70710678f}; /* 90° about Y */
    ob_node_set_scale(flat, zero);
    ob_node_set_rotation(flat, about_y);
    ob_node_set_rotation(parent, about_y);
    ob_node_set_scale(child, zero);
    ob_node_set_rotation(child, about_y);
    ob_node_set_scale(spin, zero);
    assert_int_equal(ob_node_add_rotation_controller(spin, (float[3]){0, 1, 0}, 1.0f), OB_OK);
    axes_probe probe = {.watched = spin};
    assert_int_equal(ob_node_add_script_controller(watcher, probe_axes, &probe), OB_OK);
    assert_int_equal(ob_scene_update(s, 0.5), OB_OK);
    float f[3], before[3];
    ob_node_world_axes(flat, NULL, NULL, f);
    assert_near(f[0], -1, 1e-6); /* -Z turned 90° about Y */
    ob_node_set_rotation(flat, (float[4]){0, 0, 0, 1});
    ob_node_world_axes(flat, NULL, NULL, f);
    assert_near(f[0], -1, 1e-6); /* still the last update's */
    assert_int_equal(ob_scene_update(s, 0.5), OB_OK);
    ob_node_world_axes(flat, NULL, NULL, f);
    assert_near(f[2], -1, 1e-6);
    ob_node_world_axes(child, NULL, NULL, f);
    assert_near(f[2], 1, 1e-6); /* 180° about Y in all */
    /* The serial controller saw spin as the previous update left it. */
    ob_node_world_axes(spin, NULL, NULL, before);
    assert_int_equal(ob_scene_update(s, 0.5), OB_OK);
    for (int k = 0; k < 3; k++) assert_float_equal(probe.forward[k], before[k], 0);
    ob_node_world_axes(spin, NULL, NULL, f);
    assert_true(fabsf(f[0] - before[0]) + fabsf(f[2] - before[2]) > 0.1f);
    ob_scene_destroy(s);
}

static void allocation_failures_are_clean(void **state)
{
    (void)state;
    uint64_t n;
    for (n = 1;; n++) {
        ob_test_log_clear();
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        ob_result r = fault_scenario();
        bool hit = ob_fault_hit(OB_FAULT_HOST_ALLOC);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        if (!hit) {
            assert_int_equal(r, OB_OK);
            break;
        }
        if (r != OB_ERR_OUT_OF_HOST_MEMORY)
            fail_msg("allocation %llu: got %s", (unsigned long long)n, ob_result_name(r));
        assert_true(ob_test_log_has("out of host memory", NULL));
    }
    assert_true(n > 20); /* the walk really covered many allocation points */
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hierarchy_matches_double_reference),
        cmocka_unit_test(reparenting_moves_subtree),
        cmocka_unit_test(cycles_and_foreign_nodes_refused),
        cmocka_unit_test(hidden_subtree_leaves_snapshot),
        cmocka_unit_test(renderables_sorted_by_id),
        cmocka_unit_test(rotation_controller_matches_axis_angle),
        cmocka_unit_test(orbit_controller_stays_on_circle),
        cmocka_unit_test(builtin_controllers_same_bits_in_any_pair),
        cmocka_unit_test(builtin_controllers_same_bits_in_four_lanes),
        cmocka_unit_test(common_nodes_evaluate_as_any_other),
        cmocka_unit_test(common_nodes_in_four_lanes_evaluate_as_any_other),
        cmocka_unit_test(script_controllers_run_in_order_before_world),
        cmocka_unit_test(structure_changes_refused_inside_controllers),
        cmocka_unit_test(destroy_subtree_frees_everything),
        cmocka_unit_test(destroy_many_matches_one_at_a_time),
        cmocka_unit_test(controller_state_kept_by_the_node),
        cmocka_unit_test(builtin_controllers_kept_apart_move_the_same),
        cmocka_unit_test(bad_transform_rejected_once_and_recovers),
        cmocka_unit_test(bad_leaf_rejected_beside_a_good_one),
        cmocka_unit_test(bad_update_arguments_refused),
        cmocka_unit_test(cameras_and_lights),
        cmocka_unit_test(look_at_aims_forward),
        cmocka_unit_test(world_sphere_and_axes),
        cmocka_unit_test(world_rotation_as_of_last_update),
        cmocka_unit_test(find_names_and_user_data),
        cmocka_unit_test(allocation_failures_are_clean),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
