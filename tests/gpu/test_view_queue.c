/* Issue 5: the view queue. Views queued during another view's PreRender run
 * before it; recursion stops at its bound; what a scene does not need is
 * left out with the reason in the stats; bad cameras and entities do not
 * break the frame. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"
#include "ob_renderer_layer.h"

/* ------------------------------------------------------------ helpers */

static ob_material *mirror_material(ob_test_world *w)
{
    ob_result r;
    ob_material_desc d = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .casts_shadows = true};
    ob_material *m = ob_material_create(w->lib, &d, &r);
    if (!m) fail_msg("mirror material: %s", ob_result_name(r));
    return m;
}

/* No view name appears twice in a frame. */
static void assert_each_view_once(const ob_frame_stats *st)
{
    for (uint32_t i = 0; i < st->view_count; i++)
        for (uint32_t j = i + 1; j < st->view_count; j++)
            if (strcmp(st->views[i].name, st->views[j].name) == 0)
                fail_msg("view '%s' ran twice in frame %llu", st->views[i].name,
                         (unsigned long long)st->frame);
}

/* Every dependency of v ran before v in st. */
static void assert_deps_first(const ob_frame_stats *st, const ob_view *v)
{
    int at = ob_world_view_index(st, v->name);
    if (at < 0) fail_msg("view '%s' did not run", v->name);
    for (uint32_t i = 0; i < v->dep_count; i++) {
        int d = ob_world_view_index(st, v->deps[i]->name);
        if (d < 0 || d >= at)
            fail_msg("view '%s' (position %d) depends on '%s' (position %d)", v->name, at,
                     v->deps[i]->name, d);
    }
}

/* One frame whose PreRender starts from the given root views, in order. */
static const ob_frame_stats *frame_from_roots(ob_test_world *w, ob_view **roots, uint32_t count,
                                              ob_threading mode)
{
    ob_renderer_set_threading(w->r, mode, 0);
    assert_int_equal(ob_scene_update(w->scene, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_begin_frame(w->r, w->scene), OB_OK);
    for (uint32_t i = 0; i < count; i++) ob_views_render(w->views, roots[i]);
    assert_int_equal(ob_renderer_end_frame(w->r), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(w->r), OB_OK);
    return ob_renderer_last_stats(w->r);
}

static bool all_pixels(const ob_test_world *w, const uint8_t rgba[4])
{
    for (uint32_t y = 0; y < w->height; y++)
        for (uint32_t x = 0; x < w->width; x++)
            if (memcmp(ob_world_pixel(w, x, y), rgba, 4) != 0) return false;
    return true;
}

/* ------------------------------------------------------------ synthetic views */

/* A compute-only view that queues itself and then pre-draws the views it
 * needs: the renderer's queue seen without any scene logic. */
typedef struct graph_view {
    ob_view base;
    struct graph_view *needs[4];
    uint32_t need_count;
    uint32_t pre_renders;
} graph_view;

static void graph_pre_render(ob_view *v, ob_renderer *r)
{
    graph_view *g = (graph_view *)v;
    g->pre_renders++;
    if (!ob_renderer_queue_view(r, v)) return;
    for (uint32_t i = 0; i < g->need_count; i++) ob_renderer_pre_render(r, &g->needs[i]->base);
}

static void graph_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                         uint32_t first, uint32_t count)
{
    (void)v, (void)r, (void)pm, (void)layer, (void)first, (void)count;
}

static const ob_view_vtbl graph_vtbl = {.type_name = "graph", .pre_render = graph_pre_render,
                                        .record = graph_record};

static void graph_init(graph_view *g, const char *name)
{
    memset(g, 0, sizeof *g);
    ob_view_init(&g->base, &graph_vtbl, OB_VIEW_SIMULATION, name);
    g->base.layer_count = 0;
}

static void graph_release(graph_view *g, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++) ob_view_release(&g[i].base);
}

/* ------------------------------------------------------------ ordering */

/* Shadow map, environment map and particle simulation are queued by the
 * main view's PreRender and run before it; the main view runs before the
 * composite that reads it. */
static void dependencies_run_before_consumers(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 3, 7, 0, 0.5, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    ob_material *ground = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *box = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, true);
    ob_world_entity(&w, NULL, "ground", w.plane, ground, 0, -0.5, 0);
    ob_world_entity(&w, NULL, "box", w.box, box, -1.5, 0, 0);
    ob_node *mirror = ob_world_entity(&w, NULL, "mirror", w.sphere, mirror_material(&w), 1, 0.2, 0);
    ob_result r;
    ob_particle_system *ps = ob_particle_system_create(w.views, w.scene, NULL,
        &(ob_particle_desc){.name = "sparks", .count = 256, .seed = 7}, &r);
    assert_non_null(ps);
    ob_view *main = ob_perspective_view_base(w.main);
    ob_view *composite = ob_composite_view_base(w.composite);
    for (int f = 0; f < 4; f++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, f % 2 ? OB_THREADING_MULTI
                                                                 : OB_THREADING_SINGLE, 0);
        /* The sun's shadow is OB_SHADOW_DEFAULT_CASCADES views. */
        const int c = OB_SHADOW_DEFAULT_CASCADES;
        assert_int_equal(st->view_count, 4 + c);
        assert_each_view_once(st);
        int shadow = ob_world_view_index(st, "shadow:sun:c3");
        int env = ob_world_view_index(st, "envmap:mirror");
        int sim = ob_world_view_index(st, "sparks");
        int at_main = ob_world_view_index(st, "main");
        int at_composite = ob_world_view_index(st, "composite");
        assert_true(shadow >= 0 && env >= 0 && sim >= 0);
        assert_true(shadow < at_main && env < at_main && sim < at_main);
        assert_int_equal(at_main, 2 + c);
        assert_int_equal(at_composite, 3 + c);
        assert_int_equal(main->dep_count, 2 + (uint32_t)c);
        assert_deps_first(st, main);
        assert_deps_first(st, composite);
        ob_view *env_view = ob_renderer_attached_view(w.r, mirror, OB_VIEW_PARABOLOID);
        assert_non_null(env_view);
        assert_deps_first(st, env_view);
        assert_int_equal(ob_world_count_skipped(st, OB_SKIP_RECURSION), 0);
    }
    assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
    ob_particle_system_destroy(w.views, ps);
    ob_test_world_destroy(&w);
}

/* A dependency queued by one consumer and needed by a later one (the same
 * shared view) still runs before both. */
static void shared_dependency_runs_before_every_consumer(void **state)
{
    (void)state;
    graph_view g[4];
    graph_init(&g[0], "root");
    graph_init(&g[1], "left");
    graph_init(&g[2], "right");
    graph_init(&g[3], "shared");
    g[0].needs[0] = &g[1];
    g[0].needs[1] = &g[2];
    g[0].need_count = 2;
    g[1].needs[0] = &g[3];
    g[1].need_count = 1;
    g[2].needs[0] = &g[3];
    g[2].need_count = 1;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_view *root = &g[0].base;
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st = frame_from_roots(&w, &root, 1, mode ? OB_THREADING_MULTI
                                                                       : OB_THREADING_SINGLE);
        assert_int_equal(st->view_count, 4);
        assert_each_view_once(st);
        assert_int_equal(g[2].base.dep_count, 1);
        for (int i = 0; i < 4; i++) assert_deps_first(st, &g[i].base);
        assert_int_equal(ob_world_view_index(st, "root"), 3);
    }
    ob_test_world_destroy(&w);
    graph_release(g, 4);
}

/* A second camera at `eye` looking at `target`, and its perspective view
 * "side" of the world's size (the caller destroys the view). */
static ob_perspective_view *side_view(ob_test_world *w, const double eye[3], const double target[3])
{
    ob_result r;
    ob_node *cam = ob_node_create(w->scene, NULL, "side-camera", &r);
    assert_non_null(cam);
    assert_int_equal(ob_node_set_camera(cam, &(ob_camera_desc){.fovy = 0.6f}), OB_OK);
    ob_node_set_position(cam, eye);
    assert_int_equal(ob_node_look_at(cam, target, (const double[3]){0, 1, 0}), OB_OK);
    ob_perspective_view *side = ob_perspective_view_create(w->views,
        &(ob_perspective_desc){.name = "side", .camera = cam, .width = w->width,
                               .height = w->height, .clear_color = {0.3f, 0.3f, 0.3f, 1}}, &r);
    assert_non_null(side);
    return side;
}

/* Two cameras see one mirror: its environment map is rendered once, before
 * both, so the second camera's image is what it would be on its own. */
static void second_camera_sees_this_frames_env_map(void **state)
{
    (void)state;
    uint8_t *side_images[2];
    for (int run = 0; run < 2; run++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_world_look(&w, 0, 1, 5, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
        ob_material *red = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.9f, 0.1f, 0.1f, false);
        ob_material *green = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.1f, 0.9f, 0.1f, false);
        ob_world_entity(&w, NULL, "mirror", w.sphere, mirror_material(&w), 0, 0, 0);
        ob_world_entity(&w, NULL, "red", w.box, red, -1.5, 0, 0);
        ob_world_entity(&w, NULL, "green", w.box, green, 1.5, 0, 0);
        ob_perspective_view *side = side_view(&w, (const double[3]){0.5, 0.5, -3.0}, (const double[3]){0, 0, 0});
        /* Run 0: the side view alone. Run 1: the main camera first, which
         * queues the mirror's map before the side view asks for it. */
        ob_view *roots[2] = {ob_composite_view_base(w.composite), ob_perspective_view_base(side)};
        const ob_frame_stats *st = run == 0 ? frame_from_roots(&w, &roots[1], 1, OB_THREADING_SINGLE)
                                            : frame_from_roots(&w, roots, 2, OB_THREADING_SINGLE);
        assert_each_view_once(st);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 1);
        assert_deps_first(st, ob_perspective_view_base(side));
        side_images[run] = malloc((size_t)w.width * w.height * 4);
        assert_int_equal(ob_image_read_rgba8(w.dev, ob_perspective_view_color(side),
                                             side_images[run]), OB_OK);
        ob_perspective_view_destroy(w.views, side);
        ob_test_world_destroy(&w);
    }
    assert_int_equal(ob_test_image_max_diff(side_images[0], side_images[1], 160, 120), 0);
    free(side_images[0]);
    free(side_images[1]);
}

/* Issue 25.5: a sun's shadow map is fitted and culled for the first camera
 * that asks for it. A second camera in the same frame (one looking at
 * casters far away) once refitted it after the first had culled it, and
 * the main camera's box lost its shadow. Its image is now the same as with
 * one camera, whether the two PreRenders run one after the other or as one
 * (ob_views_render_many). */
static void second_camera_leaves_the_main_cameras_shadow(void **state)
{
    (void)state;
    uint8_t *main_images[4] = {NULL, NULL, NULL, NULL};
    for (int run = 0; run < 4; run++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_world_look(&w, 0, 3, 5, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, run != 3, 1.0f, 2, 6, 1);
        ob_material *grey = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, false);
        ob_material *red = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.9f, 0.1f, 0.1f, true);
        ob_world_entity(&w, NULL, "ground", w.plane, grey, 0, -0.5, 0);
        ob_world_entity(&w, NULL, "box", w.box, red, 0, 0, 0);
        /* What only the side camera sees: casters 40 units away. */
        ob_world_entity(&w, NULL, "far ground", w.plane, grey, 40, -0.5, 0);
        ob_world_entity(&w, NULL, "far box", w.box, red, 40, 0, 0);
        ob_perspective_view *side = side_view(&w, (const double[3]){40, 3, 5}, (const double[3]){40, 0, 0});
        /* Run 0: the main camera alone; 1: then the side camera, one
         * PreRender each; 2: both in one PreRender; 3: the main camera
         * alone, the sun casting no shadow. */
        ob_view *roots[2] = {ob_composite_view_base(w.composite), ob_perspective_view_base(side)};
        if (run != 2) {
            frame_from_roots(&w, roots, run == 1 ? 2 : 1, OB_THREADING_SINGLE);
        } else {
            assert_int_equal(ob_scene_update(w.scene, 1.0 / 60.0), OB_OK);
            assert_int_equal(ob_renderer_begin_frame(w.r, w.scene), OB_OK);
            ob_views_render_many(w.views, roots, 2);
            assert_int_equal(ob_renderer_end_frame(w.r), OB_OK);
            assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
        }
        assert_int_equal(ob_world_count_views(ob_renderer_last_stats(w.r), OB_VIEW_SHADOW),
                         run != 3 ? OB_SHADOW_DEFAULT_CASCADES : 0);
        ob_world_read(&w);
        main_images[run] = ob_world_copy(&w);
        ob_perspective_view_destroy(w.views, side);
        ob_test_world_destroy(&w);
    }
    /* The shadow is there to lose. */
    uint32_t shadow_px = ob_rgba_diff_count(main_images[0], main_images[3], 160 * 120, 2);
    assert_true(shadow_px > 40);
    for (int run = 1; run < 3; run++) {
        uint32_t n = ob_rgba_diff_count(main_images[0], main_images[run], 160 * 120, 0);
        if (n) fail_msg("run %d: %u pixels of the main camera differ from the one-camera frame", run, n);
    }
    for (int run = 0; run < 4; run++) free(main_images[run]);
}

/* Issue 25.6: the lit shader shades the first directional light with the
 * one ShadowMap. With a second shadow-casting sun, its map was bound last
 * and shaded the first sun's light. Now only the shaded light gets a shadow
 * view (the other is reported not needed), and the image is the one where
 * the second sun casts no shadow. */
static void second_shadow_casting_sun_leaves_the_first_ones_shadow(void **state)
{
    (void)state;
    uint8_t *images[2];
    for (int run = 0; run < 2; run++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_world_look(&w, 0, 3, 5, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 6, 1);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, run == 0, 1.0f, -6, 2, -1);
        ob_material *grey = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, false);
        ob_material *red = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.9f, 0.1f, 0.1f, true);
        ob_world_entity(&w, NULL, "ground", w.plane, grey, 0, -0.5, 0);
        ob_world_entity(&w, NULL, "box", w.box, red, 0, 0, 0);
        ob_view *root = ob_composite_view_base(w.composite);
        const ob_frame_stats *st = frame_from_roots(&w, &root, 1, OB_THREADING_SINGLE);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), OB_SHADOW_DEFAULT_CASCADES);
        if (run == 0) assert_int_equal(ob_world_count_skipped(st, OB_SKIP_NOT_NEEDED), 1);
        ob_world_read(&w);
        images[run] = ob_world_copy(&w);
        ob_test_world_destroy(&w);
    }
    uint32_t n = ob_rgba_diff_count(images[0], images[1], 160 * 120, 0);
    if (n) fail_msg("%u pixels differ from the frame where only the first sun casts a shadow", n);
    free(images[0]);
    free(images[1]);
}

/* ------------------------------------------------------------ recursion */

/* A chain of views each needing the next: the bound cuts it, the cut view is
 * reported, and what runs runs deepest first. */
static void view_chain_stops_at_recursion_bound(void **state)
{
    (void)state;
    enum { N = 8 };
    graph_view g[N];
    for (int i = 0; i < N; i++) {
        char name[16];
        snprintf(name, sizeof name, "chain%d", i);
        graph_init(&g[i], name);
        if (i > 0) {
            g[i - 1].needs[0] = &g[i];
            g[i - 1].need_count = 1;
        }
    }
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_view *root = &g[0].base;
    for (uint32_t bound = 0; bound <= 6; bound++) {
        ob_renderer_set_max_recursion(w.r, bound);
        const ob_frame_stats *st = frame_from_roots(&w, &root, 1, bound % 2 ? OB_THREADING_MULTI
                                                                            : OB_THREADING_SINGLE);
        assert_int_equal(st->view_count, bound + 1);
        for (uint32_t i = 0; i <= bound; i++) {
            char name[16];
            snprintf(name, sizeof name, "chain%u", bound - i);
            assert_string_equal(st->views[i].name, name);
            assert_int_equal(g[bound - i].base.recursion_depth, bound - i);
        }
        assert_int_equal(ob_world_count_skipped(st, OB_SKIP_RECURSION), 1);
        char cut[16];
        snprintf(cut, sizeof cut, "chain%u", bound + 1);
        assert_int_equal(ob_world_skip_reason(st, cut), OB_SKIP_RECURSION);
    }
    ob_test_world_destroy(&w);
    graph_release(g, N);
}

/* Views that need each other in a cycle: each is queued once, PreRender
 * ends, and the view closing the cycle reads the other's previous frame. */
static void view_cycle_is_queued_once(void **state)
{
    (void)state;
    graph_view g[3];
    graph_init(&g[0], "a");
    graph_init(&g[1], "b");
    graph_init(&g[2], "c");
    g[0].needs[0] = &g[1];
    g[1].needs[0] = &g[2];
    g[2].needs[0] = &g[0];
    g[2].needs[1] = &g[1];
    g[0].need_count = g[1].need_count = 1;
    g[2].need_count = 2;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_view *root = &g[0].base;
    for (int f = 0; f < 2; f++) {
        for (int i = 0; i < 3; i++) g[i].pre_renders = 0;
        const ob_frame_stats *st = frame_from_roots(&w, &root, 1, f ? OB_THREADING_MULTI
                                                                    : OB_THREADING_SINGLE);
        assert_int_equal(st->view_count, 3);
        assert_each_view_once(st);
        assert_int_equal(g[0].pre_renders, 2);
        assert_int_equal(g[1].pre_renders, 2);
        assert_int_equal(g[2].pre_renders, 1);
        /* Deepest first; a, the cycle's start, last. */
        assert_string_equal(st->views[0].name, "c");
        assert_string_equal(st->views[1].name, "b");
        assert_string_equal(st->views[2].name, "a");
        assert_int_equal(ob_world_count_skipped(st, OB_SKIP_RECURSION), 0);
    }
    ob_test_world_destroy(&w);
    graph_release(g, 3);
}

/* Three mirror spheres that see each other. The composite is the root
 * (depth 0), the main view depth 1, its shadow and environment maps depth 2;
 * an environment map draws the other mirrors without their own reflection,
 * so it queues nothing deeper. Each map runs at most once per frame. */
static void mirror_spheres_stop_at_recursion_bound(void **state)
{
    (void)state;
    for (uint32_t bound = 0; bound <= 4; bound++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_world_look(&w, 0, 3, 6, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
        ob_material *mirror = mirror_material(&w);
        ob_material *g = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
        ob_world_entity(&w, NULL, "ground", w.plane, g, 0, -0.5, 0);
        ob_world_entity(&w, NULL, "m0", w.sphere, mirror, -1, 0, 0);
        ob_world_entity(&w, NULL, "m1", w.sphere, mirror, 1, 0, 0);
        ob_world_entity(&w, NULL, "m2", w.sphere, mirror, 0, 0, -1.5);
        ob_renderer_set_max_recursion(w.r, bound);
        for (int f = 0; f < 2; f++) {
            const ob_frame_stats *st =
                ob_test_world_frame(&w, f ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            assert_each_view_once(st);
            uint32_t envs = ob_world_count_views(st, OB_VIEW_PARABOLOID);
            uint32_t cut = ob_world_count_skipped(st, OB_SKIP_RECURSION);
            if (bound == 0) {
                assert_int_equal(st->view_count, 1); /* the composite */
                assert_int_equal(ob_world_skip_reason(st, "main"), OB_SKIP_RECURSION);
                assert_int_equal(cut, 1);
            } else if (bound == 1) {
                assert_int_equal(envs, 0);
                assert_int_equal(ob_world_skip_reason(st, "envmap:m0"), OB_SKIP_RECURSION);
                assert_int_equal(ob_world_skip_reason(st, "envmap:m1"), OB_SKIP_RECURSION);
                assert_int_equal(ob_world_skip_reason(st, "envmap:m2"), OB_SKIP_RECURSION);
                assert_int_equal(ob_world_skip_reason(st, "shadow:sun:c0"), OB_SKIP_RECURSION);
                assert_int_equal(cut, 3 + OB_SHADOW_DEFAULT_CASCADES);
                /* Without their maps the mirrors are drawn plainly lit. */
                assert_int_equal(ob_world_view_stats(st, "main")->draws, 4);
            } else {
                assert_int_equal(envs, 3);
                assert_int_equal(cut, 0);
                /* Each map draws the ground and the two other mirrors, in
                 * the halves their bounds reach: m0 and m1 (z = 0) see the
                 * ground and each other in both, m2 (z = -1.5) only in -Z;
                 * m2 sees the ground in both and m0, m1 only in +Z. */
                static const uint32_t expected_draws[3] = {2 + 2 + 1, 2 + 2 + 1, 2 + 1 + 1};
                for (int i = 0; i < 3; i++) {
                    char name[16];
                    snprintf(name, sizeof name, "envmap:m%d", i);
                    const ob_view_stats *vs = ob_world_view_stats(st, name);
                    assert_non_null(vs);
                    assert_int_equal(vs->items, 3);
                    assert_int_equal(vs->draws, expected_draws[i]);
                    assert_true(ob_world_view_index(st, name) < ob_world_view_index(st, "main"));
                }
            }
        }
        ob_test_world_destroy(&w);
    }
}

/* ------------------------------------------------------------ left out */

static void no_reflective_entity_no_env_map(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.6f, 0.7f, false);
    ob_world_entity(&w, NULL, "ball", w.sphere, m, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 0);
    assert_int_equal(st->view_count, 2);
    assert_int_equal(st->skipped_count, 0);
    ob_test_world_destroy(&w);
}

static void light_without_shadows_no_shadow_view(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
    ob_world_light(&w, OB_LIGHT_POINT, false, 1.0f, 0, 2, 2);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.6f, 0.7f, true);
    ob_world_entity(&w, NULL, "box", w.box, m, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), 0);
    assert_int_equal(st->skipped_count, 0);
    ob_test_world_destroy(&w);
}

/* A light at intensity 0 is off: its shadow view is left out with the
 * reason "not needed"; hiding a light leaves it out too. */
static void switched_off_light_no_shadow_view(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_node *sun = ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.6f, 0.7f, true);
    ob_world_entity(&w, NULL, "box", w.box, m, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_shadow_cascades(st, "sun", NULL), OB_SHADOW_DEFAULT_CASCADES);
    ob_light_desc dark = *ob_node_get_light(sun);
    dark.intensity = 0.0f;
    assert_int_equal(ob_node_set_light(sun, &dark), OB_OK);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), 0);
    assert_int_equal(ob_world_skip_reason(st, "shadow:sun"), OB_SKIP_NOT_NEEDED);
    dark.intensity = 1.0f;
    assert_int_equal(ob_node_set_light(sun, &dark), OB_OK);
    ob_node_set_hidden(sun, true);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), 0);
    ob_test_world_destroy(&w);
}

static void no_caster_in_view_skips_shadow(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 2, 5, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    ob_material *caster = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.2f, true);
    ob_material *plain = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
    ob_world_entity(&w, NULL, "ground", w.plane, plain, 0, -0.5, 0);
    ob_world_entity(&w, NULL, "caster-behind", w.box, caster, 0, 0, 12); /* behind the camera */
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_SHADOW), 0);
        assert_int_equal(ob_world_skip_reason(st, "shadow:sun"), OB_SKIP_NO_CASTERS);
        assert_int_equal(ob_world_view_stats(st, "main")->draws, 1);
    }
    ob_test_world_destroy(&w);
}

static void reflective_outside_frustum_no_env_map(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 2, 5, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
    ob_world_entity(&w, NULL, "box", w.box, m, 0, 0, 0);
    ob_node *mirror = ob_world_entity(&w, NULL, "mirror", w.sphere, mirror_material(&w), 0, 0, 12);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 0);
    assert_int_equal(ob_world_view_stats(st, "main")->culled, 1);
    assert_null(ob_renderer_attached_view(w.r, mirror, OB_VIEW_PARABOLOID));
    /* Turn the camera round: now it is needed. */
    ob_world_look(&w, 0, 2, 5, 0, 0, 12);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 1);
    ob_test_world_destroy(&w);
}

static void empty_view_records_nothing(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.clear_color = {0.2f, 0.4f, 0.6f, 1.0f}});
    ob_world_look(&w, 0, 2, 5, 0, 0, 0);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.5f, false);
    for (int i = 0; i < 5; i++) ob_world_entity(&w, NULL, "behind", w.box, m, i, 0, 20);
    uint8_t clear[4] = {ob_composite_view_output_level(w.composite, 0.2f),
                        ob_composite_view_output_level(w.composite, 0.4f),
                        ob_composite_view_output_level(w.composite, 0.6f), 255};
    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        assert_non_null(main);
        assert_int_equal(main->skipped, OB_SKIP_EMPTY);
        assert_int_equal(main->draws, 0);
        assert_int_equal(main->items, 0);
        assert_int_equal(main->culled, 5);
        assert_int_equal(main->chunks, 0);
        assert_int_equal(main->hash.draws, 0);
        assert_true(main->hash.hash == ob_cmd_hash_empty().hash);
        assert_int_equal(st->draws, 1); /* the composite */
        ob_world_read(&w);
        assert_true(all_pixels(&w, clear));
    }
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------------ bad input */

static void basic_scene(ob_test_world *w)
{
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
    ob_material *ground = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *ball = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, false);
    ob_world_entity(w, NULL, "ground", w->plane, ground, 0, -0.5, 0);
    ob_world_entity(w, NULL, "ball", w->sphere, ball, 0, 0, 0);
    ob_world_entity(w, NULL, "box", w->box, ball, 1.2, 0, 0.4);
}

/* A camera looking straight down with up = +Y: the basis is degenerate.
 * The engine picks another up axis, says so naming the camera, and renders
 * what a slightly tilted up gives. A zero-scaled camera keeps its axes too. */
static void degenerate_camera_still_renders(void **state)
{
    (void)state;
    uint8_t *images[3];
    for (int c = 0; c < 3; c++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        basic_scene(&w);
        ob_node_set_position(w.camera, (const double[3]){0, 6, 0});
        const double target[3] = {0, 0, 0};
        const double up_parallel[3] = {0, 1, 0}, up_tilted[3] = {0, 1, 0.01};
        ob_test_log_clear();
        assert_int_equal(ob_node_look_at(w.camera, target, c == 1 ? up_tilted : up_parallel), OB_OK);
        if (c == 0) assert_true(ob_test_log_has("'camera'", "parallel", NULL));
        if (c == 2) ob_node_set_scale(w.camera, (const float[3]){0, 0, 0});
        ob_test_world_frame(&w, c == 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        images[c] = ob_world_snapshot(&w);
        /* NaN would turn pixels black (or into garbage); the scene has none. */
        for (uint32_t i = 0; i < w.width * w.height; i++) {
            const uint8_t *p = images[c] + 4 * i;
            if (p[0] == 0 && p[1] == 0 && p[2] == 0) fail_msg("case %d: black pixel %u", c, i);
            assert_int_equal(p[3], 255);
        }
        ob_test_world_destroy(&w);
    }
    assert_int_equal(ob_test_image_max_diff(images[0], images[1], 160, 120), 0);
    assert_int_equal(ob_test_image_max_diff(images[0], images[2], 160, 120), 0);
    for (int c = 0; c < 3; c++) free(images[c]);
}

/* An entity (and its child) with a NaN position is left out with its name
 * in the log; everything else renders as if it were not there. */
static void non_finite_entity_left_out(void **state)
{
    (void)state;
    uint8_t *images[2][2];
    for (int c = 0; c < 2; c++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        basic_scene(&w);
        ob_test_log_clear();
        if (c == 1) {
            ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.1f, 0.9f, 0.1f, true);
            ob_node *bad = ob_world_entity(&w, NULL, "broken-entity", w.box, m, NAN, 0, 0);
            ob_world_entity(&w, bad, "child-of-broken", w.box, m, 0, 1, 0);
        }
        for (int mode = 0; mode < 2; mode++) {
            const ob_frame_stats *st =
                ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            assert_int_equal(ob_world_view_stats(st, "main")->draws, 3);
            images[c][mode] = ob_world_snapshot(&w);
        }
        if (c == 1) assert_true(ob_test_log_has("'broken-entity'", "non-finite", NULL));
        ob_test_world_destroy(&w);
    }
    for (int mode = 0; mode < 2; mode++) {
        assert_int_equal(ob_test_image_max_diff(images[0][mode], images[1][mode], 160, 120), 0);
        free(images[0][mode]);
        free(images[1][mode]);
    }
}

/* ------------------------------------------------------------ draw order */

/* The main view's draw list is in (class and priority, key) order, ties in
 * entity id order, with thousands of items of several materials and meshes,
 * opaque and blended (the sort's long-list path), and the same list in
 * every threading mode. */
static void draw_list_in_key_then_id_order(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 4, 30, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 8, 3);
    ob_material *mats[4] = {
        ob_world_material(&w, "red", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.2f, false),
        ob_world_material(&w, "green", OB_MATERIAL_LIT, 0.2f, 0.8f, 0.2f, false),
        ob_world_material(&w, "grey", OB_MATERIAL_UNLIT, 0.5f, 0.5f, 0.5f, false),
        ob_world_material_desc(&w, &(ob_material_desc){
            .name = "glass", .kind = OB_MATERIAL_LIT, .diffuse = {0.3f, 0.3f, 0.9f, 0.5f},
            .blended = true, .priority = 3}),
    };
    ob_geometry *shapes[3] = {w.box, w.sphere, w.plane};
    const int side = 60; /* 3600 entities, most in view */
    for (int i = 0; i < side * side; i++)
        ob_world_entity(&w, NULL, "e", shapes[(i / 7) % 3], mats[(i * 5) % 4],
                        -15.0 + 30.0 * (i % side) / side, 0, -15.0 + 30.0 * (i / side) / side);
    ob_view *v = ob_perspective_view_base(w.main);
    ob_draw_item *first = NULL;
    uint32_t first_count = 0;
    for (int mode = 0; mode < 2; mode++) {
        ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_true(v->item_count > 2048);
        uint32_t blended = 0;
        for (uint32_t i = 0; i < v->item_count; i++) {
            const ob_draw_item *it = &v->items[i];
            blended += it->sort_hi >> 31;
            if (i == 0) continue;
            const ob_draw_item *prev = &v->items[i - 1];
            bool before = prev->sort_hi < it->sort_hi ||
                          (prev->sort_hi == it->sort_hi &&
                           (prev->sort_key < it->sort_key ||
                            (prev->sort_key == it->sort_key && prev->node_id < it->node_id)));
            if (!before)
                fail_msg("draw list items %u and %u out of order: (%08x, %016llx, id %u) then "
                         "(%08x, %016llx, id %u)", i - 1, i, prev->sort_hi,
                         (unsigned long long)prev->sort_key, prev->node_id, it->sort_hi,
                         (unsigned long long)it->sort_key, it->node_id);
        }
        assert_true(blended > 0 && blended < v->item_count);
        if (mode == 0) {
            first_count = v->item_count;
            first = malloc(sizeof *first * first_count);
            assert_non_null(first);
            memcpy(first, v->items, sizeof *first * first_count);
        } else {
            assert_int_equal(v->item_count, first_count);
            for (uint32_t i = 0; i < first_count; i++) {
                assert_int_equal(v->items[i].node_id, first[i].node_id);
                assert_true(v->items[i].sort_key == first[i].sort_key);
            }
        }
    }
    free(first);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(dependencies_run_before_consumers),
        cmocka_unit_test(shared_dependency_runs_before_every_consumer),
        cmocka_unit_test(second_camera_sees_this_frames_env_map),
        cmocka_unit_test(second_camera_leaves_the_main_cameras_shadow),
        cmocka_unit_test(second_shadow_casting_sun_leaves_the_first_ones_shadow),
        cmocka_unit_test(view_chain_stops_at_recursion_bound),
        cmocka_unit_test(view_cycle_is_queued_once),
        cmocka_unit_test(mirror_spheres_stop_at_recursion_bound),
        cmocka_unit_test(no_reflective_entity_no_env_map),
        cmocka_unit_test(light_without_shadows_no_shadow_view),
        cmocka_unit_test(switched_off_light_no_shadow_view),
        cmocka_unit_test(no_caster_in_view_skips_shadow),
        cmocka_unit_test(reflective_outside_frustum_no_env_map),
        cmocka_unit_test(empty_view_records_nothing),
        cmocka_unit_test(degenerate_camera_still_renders),
        cmocka_unit_test(non_finite_entity_left_out),
        cmocka_unit_test(draw_list_in_key_then_id_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
