/* Issue 4: the pipeline manager binds only what changes, packs uniforms only
 * after a parameter changed, records the same commands into the primary and
 * into secondaries, survives a stale texture handle and leaves out materials
 * that have no effect for a view type.
 *
 * The frame always ends with the composite view (one full-screen draw), so
 * the main view's share of the summed manager stats is the frame's stats
 * minus those of a frame in which the main view is empty. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ob_test_world.h"

#define GRID_COLUMNS 10

/* Boxes on a grid in front of the camera, all visible from (0, 12, 8). */
static void add_grid(ob_test_world *w, uint32_t count, ob_material **materials,
                     uint32_t material_count)
{
    for (uint32_t i = 0; i < count; i++) {
        char name[32];
        snprintf(name, sizeof name, "box%u", i);
        double x = ((double)(i % GRID_COLUMNS) - 4.5) * 1.2, z = -(double)(i / GRID_COLUMNS) * 1.2;
        ob_world_entity(w, NULL, name, w->box, materials[i % material_count], x, 0.0, z);
    }
}

static void frame_camera(ob_test_world *w) { ob_world_look(w, 0, 12, 8, 0, 0, -5); }

/* a - b, field by field (every field of ob_pipeline_manager_stats is a counter). */
static ob_pipeline_manager_stats pm_minus(ob_pipeline_manager_stats a, const ob_pipeline_manager_stats *b)
{
    a.draws -= b->draws;
    a.dispatches -= b->dispatches;
    a.pipeline_binds_requested -= b->pipeline_binds_requested;
    a.pipeline_binds_issued -= b->pipeline_binds_issued;
    a.descriptor_binds_requested -= b->descriptor_binds_requested;
    a.descriptor_binds_issued -= b->descriptor_binds_issued;
    a.push_descriptor_requested -= b->push_descriptor_requested;
    a.push_descriptor_issued -= b->push_descriptor_issued;
    a.push_constant_requested -= b->push_constant_requested;
    a.push_constant_issued -= b->push_constant_issued;
    a.vertex_binds_requested -= b->vertex_binds_requested;
    a.vertex_binds_issued -= b->vertex_binds_issued;
    a.index_binds_requested -= b->index_binds_requested;
    a.index_binds_issued -= b->index_binds_issued;
    a.blocks_packed -= b->blocks_packed;
    a.blocks_reused -= b->blocks_reused;
    a.uniform_bytes -= b->uniform_bytes;
    a.skipped_draws -= b->skipped_draws;
    return a;
}

/* The manager stats of the composite alone (main view empty). */
static ob_pipeline_manager_stats composite_only(ob_test_world *w, ob_threading mode, uint32_t workers)
{
    const ob_frame_stats *st = ob_test_world_frame(w, mode, workers);
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    assert_non_null(main);
    assert_int_equal(main->draws, 0);
    assert_int_equal(st->pm.draws, 1);
    return st->pm;
}

/* Sizes of the lit effect's per-view blocks (PerView and PerViewLights,
 * packed once per view and slot) and its material blocks: PerMaterial
 * (binding 1: only Reflectivity differs between LIT materials) and
 * PbrMaterial (binding 3: the mapped factors); per_material is both. */
static void lit_block_sizes(ob_test_world *w, uint32_t *per_view, uint32_t *per_material,
                            uint32_t *pbr_material)
{
    ob_effect *e = ob_material_library_find_effect(w->lib, OB_STD_LIT, 0);
    assert_non_null(e);
    const ob_program *p = ob_effect_program(e);
    assert_int_equal(p->ubo_count, 4);
    *per_view = *per_material = *pbr_material = 0;
    for (uint32_t i = 0; i < p->ubo_count; i++) {
        if (p->ubos[i].binding == 0 || p->ubos[i].binding == 4) *per_view += p->ubos[i].size;
        if (p->ubos[i].binding == 1 || p->ubos[i].binding == 3) *per_material += p->ubos[i].size;
        if (p->ubos[i].binding == 3) *pbr_material = p->ubos[i].size;
    }
    assert_true(*per_view > 0 && *pbr_material > 0 && *per_material > *pbr_material);
}

/* 100 entities sharing a material and a geometry: one pipeline, vertex,
 * index and descriptor-set bind, and each uniform block packed once. */
static void shared_state_bound_once_single_threaded(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_material_library_set_instancing(w.lib, false); /* one draw per entity */
    frame_camera(&w);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 10, 6);
    ob_pipeline_manager_stats base = composite_only(&w, OB_THREADING_SINGLE, 0);

    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.7f, 0.5f, 0.3f, false);
    add_grid(&w, 100, &m, 1);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint32_t per_view, per_material, pbr_material;
    lit_block_sizes(&w, &per_view, &per_material, &pbr_material);
    ob_pipeline_manager_stats s = pm_minus(st->pm, &base);
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    assert_int_equal(main->draws, 100);
    assert_int_equal(main->chunks, 1);
    assert_int_equal(main->worker, -1);
    assert_int_equal(s.draws, 100);
    assert_int_equal(s.pipeline_binds_requested, 100);
    assert_int_equal(s.pipeline_binds_issued, 1);
    assert_int_equal(s.vertex_binds_requested, 100);
    assert_int_equal(s.vertex_binds_issued, 1);
    assert_int_equal(s.index_binds_requested, 100);
    assert_int_equal(s.index_binds_issued, 1);
    assert_int_equal(s.descriptor_binds_requested, 100);
    assert_int_equal(s.descriptor_binds_issued, 1);
    /* PerView, PerViewLights, PerMaterial and PbrMaterial packed once,
     * reused by the other 99 draws. */
    assert_int_equal(s.blocks_packed, 4);
    assert_int_equal(s.blocks_reused, 4 * 99);
    assert_int_equal(s.uniform_bytes, per_view + per_material);
    /* Every box has its own world matrix: push constants change per draw. */
    assert_int_equal(s.push_constant_requested, 100);
    assert_int_equal(s.push_constant_issued, 100);
    assert_int_equal(s.skipped_draws, 0);
    ob_test_world_destroy(&w);
}

/* Multi-threaded, the main view is split into chunks, each recorded into its
 * own secondary: state is bound once per secondary. */
static void shared_state_bound_once_per_secondary(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4, .chunk_draws = 25});
    ob_material_library_set_instancing(w.lib, false); /* one draw per entity */
    frame_camera(&w);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 10, 6);
    ob_pipeline_manager_stats base = composite_only(&w, OB_THREADING_MULTI, 4);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.7f, 0.5f, 0.3f, false);
    add_grid(&w, 100, &m, 1);
    uint32_t per_view, per_material, pbr_material;
    for (int frame = 0; frame < 3; frame++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 4);
        if (frame == 0) lit_block_sizes(&w, &per_view, &per_material, &pbr_material);
        ob_pipeline_manager_stats s = pm_minus(st->pm, &base);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        assert_int_equal(st->workers, 4);
        assert_int_equal(main->draws, 100);
        assert_true(main->worker >= 1 && main->worker <= 4);
        uint32_t chunks = main->chunks;
        assert_true(chunks >= 4); /* 100 draws, 25 per job */
        assert_true(chunks <= 100);
        assert_int_equal(s.pipeline_binds_requested, 100);
        assert_int_equal(s.pipeline_binds_issued, chunks);
        assert_int_equal(s.vertex_binds_requested, 100);
        assert_int_equal(s.vertex_binds_issued, chunks);
        assert_int_equal(s.index_binds_requested, 100);
        assert_int_equal(s.index_binds_issued, chunks);
        assert_int_equal(s.descriptor_binds_requested, 100);
        assert_int_equal(s.descriptor_binds_issued, chunks);
        /* A worker keeps its packed blocks across the chunks it records. */
        assert_true(s.blocks_packed >= 4 && s.blocks_packed <= 4 * chunks);
        assert_int_equal(s.blocks_packed + s.blocks_reused, 400);
        assert_true(s.uniform_bytes <= (uint64_t)chunks * (per_view + per_material));
        assert_int_equal(s.skipped_draws, 0);
    }
    ob_test_world_destroy(&w);
}

/* Uniform data follows parameter changes, not draws: more draws with the
 * same parameters pack nothing more; distinct material objects with equal
 * values pack like one material; a colour per draw packs per draw. */
static void uniforms_packed_only_after_a_change(void **state)
{
    (void)state;
    enum { SHARED_50, SHARED_100, SAME_VALUES, DISTINCT, CASES };
    ob_pipeline_manager_stats got[CASES];
    uint32_t per_view = 0, per_material = 0, pbr_material = 0;
    for (int c = 0; c < CASES; c++) {
        ob_test_world w;
        ob_test_world_create(&w, NULL);
        ob_material_library_set_instancing(w.lib, false); /* one draw per entity */
        frame_camera(&w);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 10, 6);
        ob_pipeline_manager_stats base = composite_only(&w, OB_THREADING_SINGLE, 0);
        ob_material *mats[100];
        uint32_t nm = c == SHARED_50 || c == SHARED_100 ? 1 : 100;
        for (uint32_t i = 0; i < nm; i++) {
            float red = c == DISTINCT ? (float)i / 100.0f : 0.5f;
            mats[i] = ob_world_material(&w, "test", OB_MATERIAL_LIT, red, 0.5f, 0.5f, false);
        }
        uint32_t count = c == SHARED_50 ? 50 : 100;
        add_grid(&w, count, mats, nm);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_view_stats(st, "main")->draws, count);
        got[c] = pm_minus(st->pm, &base);
        if (c == 0) lit_block_sizes(&w, &per_view, &per_material, &pbr_material);
        /* The next frame packs again (new ring space) but no more than this one. */
        const ob_frame_stats *again = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        assert_int_equal(pm_minus(again->pm, &base).blocks_packed, got[c].blocks_packed);
        ob_test_world_destroy(&w);
    }
    assert_int_equal(got[SHARED_50].blocks_packed, 4);
    assert_int_equal(got[SHARED_100].blocks_packed, 4);
    assert_int_equal(got[SHARED_50].uniform_bytes, got[SHARED_100].uniform_bytes);
    assert_int_equal(got[SAME_VALUES].blocks_packed, 4);
    assert_int_equal(got[SAME_VALUES].uniform_bytes, per_view + per_material);
    assert_int_equal(got[SAME_VALUES].descriptor_binds_issued, 1);
    /* A colour per material changes its PbrMaterial block only. */
    assert_int_equal(got[DISTINCT].blocks_packed, 3 + 100);
    assert_int_equal(got[DISTINCT].blocks_reused, 3 * 99);
    assert_int_equal(got[DISTINCT].uniform_bytes, per_view + per_material + 99 * pbr_material);
    /* One effect for all of them: still one pipeline bind. */
    assert_int_equal(got[DISTINCT].pipeline_binds_issued, 1);
}

/* Many programs, each with its own PerView and PerMaterial mappings, drawn
 * once each: every draw must read its own material block (the per-manager
 * cache of packed blocks must never hand one entry to two blocks of a
 * draw). Unlit colours land in the image exactly. */
static void many_programs_each_read_their_own_uniforms(void **state)
{
    (void)state;
    enum { N = 100, SIDE = 10 };
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 0, 20, 0, 0, 0);
    ob_node_set_camera(w.camera, &(ob_camera_desc){.fovy = 0.6f, .znear = 0.1f});
    ob_effect *effects[N];
    float colors[N][3];
    for (uint32_t i = 0; i < N; i++) {
        char name[32], value[16];
        snprintf(name, sizeof name, "unlit-%u", i);
        snprintf(value, sizeof value, "%u", i);
        ob_shader_define def = {"TEST_VARIANT", value};
        ob_effect_desc ed = {.name = name, .vertex = "unlit.vert", .fragment = "unlit.frag",
                             .define_count = 1, .defines = &def,
                             .layout = ob_views_standard_input(), .depth_test = true,
                             .depth_write = true, .cull = VK_CULL_MODE_BACK_BIT};
        ob_result r;
        effects[i] = ob_effect_create(w.fx, &ed, &r);
        if (!effects[i]) fail_msg("effect %u: %s", i, ob_result_name(r));
        colors[i][0] = (float)(i % 5) / 5.0f + 0.1f;
        colors[i][1] = (float)((i / 5) % 5) / 5.0f + 0.1f;
        colors[i][2] = (float)(i / 25) / 5.0f + 0.1f;
        ob_material_desc md = {.name = name, .kind = OB_MATERIAL_CUSTOM,
                               .diffuse = {colors[i][0], colors[i][1], colors[i][2], 1.0f}};
        ob_material *m = ob_material_create(w.lib, &md, &r);
        assert_non_null(m);
        assert_int_equal(ob_material_set_view_effect(m, OB_VIEW_PERSPECTIVE, effects[i]), OB_OK);
        double x = (double)(i % SIDE) - 4.5, y = (double)(i / SIDE) - 4.5;
        ob_world_entity(&w, NULL, name, w.box, m, x, y, 0);
    }
    const double half_h = 19.5 * tan(0.3), half_w = half_h * 160.0 / 120.0;
    for (int f = 0; f < 4; f++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, f % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_view_stats(st, "main")->draws, N);
        ob_world_read(&w);
        for (uint32_t i = 0; i < N; i++) {
            double x = (double)(i % SIDE) - 4.5, y = (double)(i / SIDE) - 4.5;
            uint32_t px = (uint32_t)((x / half_w + 1.0) * 0.5 * w.width);
            uint32_t py = (uint32_t)((1.0 - y / half_h) * 0.5 * w.height);
            const uint8_t *p = ob_world_pixel(&w, px, py);
            uint8_t want[3];
            for (int c = 0; c < 3; c++)
                want[c] = ob_composite_view_output_level(w.composite, colors[i][c]);
            for (int c = 0; c < 3; c++)
                if (abs(p[c] - want[c]) > 1)
                    fail_msg("frame %d, box %u at (%u,%u): %u,%u,%u, expected %u,%u,%u", f,
                             i, px, py, p[0], p[1], p[2], want[0], want[1], want[2]);
        }
    }
    assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
    for (uint32_t i = 0; i < N; i++) ob_effect_destroy(effects[i]);
    ob_test_world_destroy(&w);
}

/* Issue 25.9: a frame slot's set-0 cache kept a set for every program it
 * ever drew, so a program that changes its scenes held more every time.
 * With the bound lowered to 8 ($OB_SET_CACHE_LIMIT), rounds of 12 new
 * programs each (made, drawn in both modes, destroyed) leave every manager
 * holding at most the bound plus one frame's programs, the resets are
 * counted, and every box keeps its colour. Before: 12 more sets a round. */
static void set_cache_holds_its_bound_across_changing_scenes(void **state)
{
    (void)state;
    enum { ROUNDS = 5, N = 12, LIMIT = 8 };
    setenv("OB_SET_CACHE_LIMIT", "8", 1);
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    unsetenv("OB_SET_CACHE_LIMIT");
    ob_world_look(&w, 0, 0, 20, 0, 0, 0);
    ob_node_set_camera(w.camera, &(ob_camera_desc){.fovy = 0.6f, .znear = 0.1f});
    uint32_t resets = 0, most_held = 0;
    for (uint32_t round = 0; round < ROUNDS; round++) {
        ob_effect *effects[N];
        ob_material *materials[N];
        ob_node *nodes[N];
        for (uint32_t i = 0; i < N; i++) {
            char name[32], value[16];
            snprintf(name, sizeof name, "round-%u-%u", round, i);
            snprintf(value, sizeof value, "%u", round * N + i);
            ob_shader_define def = {"TEST_VARIANT", value};
            ob_effect_desc ed = {.name = name, .vertex = "unlit.vert", .fragment = "unlit.frag",
                                 .define_count = 1, .defines = &def,
                                 .layout = ob_views_standard_input(), .depth_test = true,
                                 .depth_write = true, .cull = VK_CULL_MODE_BACK_BIT};
            ob_result r;
            effects[i] = ob_effect_create(w.fx, &ed, &r);
            if (!effects[i]) fail_msg("effect %u: %s", i, ob_result_name(r));
            ob_material_desc md = {.name = name, .kind = OB_MATERIAL_CUSTOM,
                                   .diffuse = {0.2f + 0.05f * (float)i, 0.5f, 0.9f - 0.05f * (float)i, 1.0f}};
            materials[i] = ob_material_create(w.lib, &md, &r);
            assert_non_null(materials[i]);
            assert_int_equal(ob_material_set_view_effect(materials[i], OB_VIEW_PERSPECTIVE, effects[i]), OB_OK);
            nodes[i] = ob_world_entity(&w, NULL, name, w.box, materials[i], (double)i * 1.5 - 8.25, 0, 0);
        }
        for (int f = 0; f < 4; f++) {
            const ob_frame_stats *st =
                ob_test_world_frame(&w, f % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
            assert_int_equal(ob_world_view_stats(st, "main")->draws, N);
            resets += st->pm.descriptor_set_cache_resets;
            if (st->pm.descriptor_sets_held > most_held) most_held = st->pm.descriptor_sets_held;
            if (st->pm.descriptor_sets_held > LIMIT + N + 4)
                fail_msg("round %u frame %d: a manager holds %u sets (bound %u)", round, f,
                         st->pm.descriptor_sets_held, LIMIT);
            ob_world_read(&w);
            const uint8_t *p = ob_world_pixel(&w, w.width / 2, w.height / 2);
            if (p[2] < 64) fail_msg("round %u frame %d: the middle box is %u,%u,%u", round, f, p[0], p[1], p[2]);
        }
        assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
        for (uint32_t i = 0; i < N; i++) {
            ob_node_destroy(nodes[i]);
            ob_material_destroy(materials[i]);
            ob_effect_destroy(effects[i]);
        }
    }
    printf("[ set cache ] %u resets, at most %u sets held (bound %u)\n", resets, most_held, LIMIT);
    assert_true(resets > 0);
    ob_test_world_destroy(&w);
}

/* Build the scene used for the ST/MT comparison: shared and distinct
 * materials, two geometries, a shadow-casting light. */
static void mixed_scene(ob_test_world *w)
{
    frame_camera(w);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 10, 5);
    ob_material *mats[4] = {
        ob_world_material(w, "test", OB_MATERIAL_LIT, 0.8f, 0.3f, 0.2f, true),
        ob_world_material(w, "test", OB_MATERIAL_LIT, 0.2f, 0.7f, 0.3f, true),
        ob_world_material(w, "test", OB_MATERIAL_UNLIT, 0.9f, 0.9f, 0.2f, false),
        ob_world_material(w, "test", OB_MATERIAL_LIT, 0.3f, 0.3f, 0.9f, false),
    };
    add_grid(w, 120, mats, 4);
    ob_material *ground = ob_world_material(w, "test", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_world_entity(w, NULL, "ground", w->plane, ground, 0, -0.5, -5);
    for (int i = 0; i < 10; i++) {
        char name[16];
        snprintf(name, sizeof name, "ball%d", i);
        ob_world_entity(w, NULL, name, w->sphere, mats[i % 2], -5.0 + i, 1.0, -4.0);
    }
}

/* The same draws recorded inline into the primary and as chunks into
 * secondaries on several workers: same pixels, same command hashes. */
static void primary_and_secondaries_record_the_same(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4, .chunk_draws = 16});
    mixed_scene(&w);
    ob_frame_stats ref = *ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *ref_pixels = ob_world_snapshot(&w);
    assert_int_equal(ref.workers, 0);
    const ob_view_stats *ref_main = ob_world_view_stats(&ref, "main");
    assert_true(ref_main->draws >= 120);
    assert_true(ob_world_shadow_cascades(&ref, "sun", NULL) > 0);
    static const uint32_t workers[] = {1, 2, 4};
    for (size_t k = 0; k < OB_ARRAY_COUNT(workers); k++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, workers[k]);
        assert_int_equal(st->workers, workers[k]);
        assert_int_equal(st->view_count, ref.view_count);
        assert_true(ob_world_view_stats(st, "main")->chunks > 1);
        for (uint32_t i = 0; i < ref.view_count; i++) {
            assert_string_equal(st->views[i].name, ref.views[i].name);
            assert_int_equal(st->views[i].draws, ref.views[i].draws);
            if (st->views[i].hash.hash != ref.views[i].hash.hash)
                fail_msg("view '%s': hash %016llx with %u workers, %016llx single-threaded",
                         ref.views[i].name, (unsigned long long)st->views[i].hash.hash, workers[k],
                         (unsigned long long)ref.views[i].hash.hash);
            assert_int_equal(st->views[i].hash.draws, ref.views[i].hash.draws);
        }
        assert_true(st->frame_hash == ref.frame_hash);
        ob_world_read(&w);
        assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
    }
    free(ref_pixels);
    ob_test_world_destroy(&w);
}

/* Instanced runs draw what one draw per entity draws: the same pixels,
 * byte for byte, in far fewer draw calls, and the same command hashes in
 * every threading mode however the runs are cut into recording jobs. */
static void instanced_runs_draw_what_single_draws_draw(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4, .chunk_draws = 16});
    mixed_scene(&w);
    ob_material_library_set_instancing(w.lib, false);
    ob_frame_stats single = *ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *ref_pixels = ob_world_snapshot(&w);
    assert_int_equal(single.pm.instances, 0);
    assert_int_equal(single.pm.draw_calls, single.pm.draws);

    ob_material_library_set_instancing(w.lib, true);
    ob_frame_stats inst = *ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
    assert_int_equal(inst.pm.draws, single.pm.draws);
    for (uint32_t i = 0; i < inst.view_count; i++)
        assert_int_equal(inst.views[i].draws, single.views[i].draws);
    /* 120 boxes of 4 materials, 10 balls of 2, a ground; a shadow view of
     * the casters: every entity an instance, in a handful of runs. */
    assert_true(inst.pm.instances >= 131);
    assert_true(inst.pm.draw_calls * 4 < inst.pm.draws);
    const ob_view_stats *main = ob_world_view_stats(&inst, "main");
    assert_int_equal(main->instances, main->draws);
    assert_true(main->draw_calls * 4 < main->draws);
    assert_true(main->longest_run >= 10 && main->longest_run <= main->draws);
    const ob_view_stats *off = ob_world_view_stats(&single, "main");
    assert_int_equal(off->instances, 0);
    assert_int_equal(off->draw_calls, off->draws);
    assert_int_equal(off->longest_run, 0);

    static const uint32_t workers[] = {1, 2, 4};
    for (size_t k = 0; k < OB_ARRAY_COUNT(workers); k++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, workers[k]);
        assert_true(ob_world_view_stats(st, "main")->chunks > 1);
        for (uint32_t i = 0; i < inst.view_count; i++) {
            assert_string_equal(st->views[i].name, inst.views[i].name);
            assert_int_equal(st->views[i].hash.draws, inst.views[i].hash.draws);
            if (st->views[i].hash.hash != inst.views[i].hash.hash)
                fail_msg("view '%s': hash %016llx with %u workers, %016llx single-threaded",
                         inst.views[i].name, (unsigned long long)st->views[i].hash.hash,
                         workers[k], (unsigned long long)inst.views[i].hash.hash);
        }
        assert_true(st->frame_hash == inst.frame_hash);
        ob_world_read(&w);
        assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
    }
    free(ref_pixels);
    ob_test_world_destroy(&w);
}

/* Runs drawn as multi-draw indirect (a GPU's way, asked for here on any
 * device, staged and direct) or as a direct draw per instance draw what
 * instanced draws draw: the same pixels and command hashes; one command a
 * run for the multi-draws, one an instance for the direct draws. */
static void multi_draw_and_direct_runs_draw_what_instanced_runs_draw(void **state)
{
    (void)state;
    ob_test_world ref;
    ob_test_world_create(&ref, &(ob_test_world_desc){.workers = 4, .chunk_draws = 16,
                                                     .instance_runs = OB_INSTANCE_RUNS_INSTANCED});
    mixed_scene(&ref);
    assert_int_equal(ob_renderer_instance_runs(ref.r), OB_INSTANCE_RUNS_INSTANCED);
    ob_frame_stats inst = *ob_test_world_frame(&ref, OB_THREADING_SINGLE, 0);
    uint8_t *ref_pixels = ob_world_snapshot(&ref);
    assert_int_equal(inst.pm.multi_draw_runs, 0);
    assert_true(inst.pm.instances >= 131);
    ob_test_world_destroy(&ref);

    /* A direct draw per instance: one command each, the same pixels and
     * hash (it needs no feature). */
    ob_test_world dw;
    ob_test_world_create(&dw, &(ob_test_world_desc){.workers = 4, .chunk_draws = 16,
                                                    .ring_staging = OB_RING_STAGING_ON,
                                                    .instance_runs = OB_INSTANCE_RUNS_DIRECT});
    mixed_scene(&dw);
    assert_int_equal(ob_renderer_instance_runs(dw.r), OB_INSTANCE_RUNS_DIRECT);
    for (uint32_t workers = 0; workers <= 4; workers += 4) {
        const ob_frame_stats *st =
            ob_test_world_frame(&dw, workers ? OB_THREADING_MULTI : OB_THREADING_SINGLE, workers);
        assert_int_equal(st->pm.instances, inst.pm.instances);
        assert_int_equal(st->pm.draw_calls, st->pm.draws);
        assert_int_equal(st->pm.multi_draw_runs, 0);
        assert_true(st->frame_hash == inst.frame_hash);
        ob_world_read(&dw);
        assert_int_equal(ob_test_image_max_diff(ref_pixels, dw.pixels, dw.width, dw.height), 0);
    }
    ob_test_world_destroy(&dw);

    static const ob_ring_staging staging[] = {OB_RING_STAGING_OFF, OB_RING_STAGING_ON};
    for (size_t s = 0; s < OB_ARRAY_COUNT(staging); s++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.workers = 4, .chunk_draws = 16,
                                                       .ring_staging = staging[s],
                                                       .instance_runs = OB_INSTANCE_RUNS_MULTI_DRAW});
        mixed_scene(&w);
        const ob_device_caps *caps = ob_device_get_caps(ob_renderer_device(w.r));
        if (!caps->multi_draw_indirect || !caps->draw_indirect_first_instance) {
            /* Asked for without the features: instanced, as documented. */
            assert_int_equal(ob_renderer_instance_runs(w.r), OB_INSTANCE_RUNS_INSTANCED);
            ob_test_world_destroy(&w);
            free(ref_pixels);
            skip();
        }
        assert_int_equal(ob_renderer_instance_runs(w.r), OB_INSTANCE_RUNS_MULTI_DRAW);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        /* One command a run, as instanced: the runs of more than one
         * instance are the multi-draws. */
        assert_int_equal(st->pm.draw_calls, inst.pm.draw_calls);
        assert_int_equal(st->pm.instances, inst.pm.instances);
        assert_true(st->pm.multi_draw_runs > 0 && st->pm.multi_draw_runs <= st->pm.draw_calls);
        assert_true(st->frame_hash == inst.frame_hash);
        ob_world_read(&w);
        assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
        static const uint32_t workers[] = {1, 4};
        for (size_t k = 0; k < OB_ARRAY_COUNT(workers); k++) {
            st = ob_test_world_frame(&w, OB_THREADING_MULTI, workers[k]);
            assert_true(ob_world_view_stats(st, "main")->chunks > 1);
            assert_true(st->frame_hash == inst.frame_hash);
            ob_world_read(&w);
            assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
        }
        ob_test_world_destroy(&w);
    }
    free(ref_pixels);
}

/* A view cut into more chunks than one vkCmdExecuteCommands batch holds
 * (one draw per chunk, 300 boxes): every chunk is executed, the image and
 * the hashes are those of the single-threaded frame. */
static void a_view_of_many_chunks_draws_everything(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 2, .chunk_draws = 1});
    frame_camera(&w);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 10, 6);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.7f, 0.5f, 0.3f, false);
    add_grid(&w, 300, &m, 1);
    ob_frame_stats ref = *ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *ref_pixels = ob_world_snapshot(&w);
    const ob_view_stats *ref_main = ob_world_view_stats(&ref, "main");
    assert_true(ref_main->draws > 256);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 2);
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    assert_int_equal(main->chunks, ref_main->draws);
    assert_int_equal(main->draws, ref_main->draws);
    assert_true(main->hash.hash == ref_main->hash.hash);
    assert_true(st->frame_hash == ref.frame_hash);
    ob_world_read(&w);
    assert_int_equal(ob_test_image_max_diff(ref_pixels, w.pixels, w.width, w.height), 0);
    free(ref_pixels);
    ob_test_world_destroy(&w);
}

/* A fragment shader sampling "TestTexture" (and "TestTextureSampler"). */
static const char textured_frag[] =
    "#version 450\n"
    "layout(set = 1, binding = 0) uniform sampler2D TestTexture;\n"
    "layout(location = 0) in vec4 vColor;\n"
    "layout(location = 0) out vec4 outColor;\n"
    "void main() { outColor = texture(TestTexture, vec2(0.5)); }\n";

/* A texture parameter whose image was destroyed: the draws that sample it
 * are skipped and counted, one line is logged, nothing crashes and every
 * other draw still lands. */
static void stale_texture_skips_the_draw(void **state)
{
    (void)state;
    char dir[] = "/tmp/ob-test-pm-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[128];
    snprintf(path, sizeof path, "%s/textured.frag", dir);
    assert_int_equal(ob_file_write(path, textured_frag, sizeof textured_frag - 1), OB_OK);

    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 0, 6, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 0, 0, 10);
    ob_result r;
    ob_effect_desc ed = {.name = "textured", .vertex = "unlit.vert", .fragment = path,
                         .layout = ob_views_standard_input(), .depth_test = true,
                         .depth_write = true, .cull = VK_CULL_MODE_BACK_BIT};
    ob_effect *fx = ob_effect_create(w.fx, &ed, &r);
    if (!fx) fail_msg("textured effect: %s", ob_result_name(r));
    ob_param_registry *reg = ob_renderer_registry(w.r);
    ob_param tex = ob_param_find(reg, "TestTexture");
    ob_param smp = ob_param_find(reg, "TestTextureSampler");
    assert_true(tex.id && smp.id);
    const uint8_t green[4 * 4] = {0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255, 0, 255};
    ob_image img = ob_image_create(w.dev, &(ob_image_desc){.width = 2, .height = 2,
        .format = VK_FORMAT_R8G8B8A8_UNORM, .usage = OB_IMAGE_SAMPLED, .data = green,
        .name = "green"}, &r);
    assert_true(img.id != 0);
    ob_sampler sampler = ob_sampler_create(w.dev, &(ob_sampler_desc){.name = "test"}, &r);
    assert_true(sampler.id != 0);
    assert_int_equal(ob_params_init_texture(reg, tex, img), OB_OK);
    assert_int_equal(ob_params_init_sampler(reg, smp, sampler), OB_OK);

    ob_material_desc md = {.name = "textured", .kind = OB_MATERIAL_CUSTOM};
    ob_material *textured = ob_material_create(w.lib, &md, &r);
    assert_non_null(textured);
    assert_int_equal(ob_material_set_view_effect(textured, OB_VIEW_PERSPECTIVE, fx), OB_OK);
    ob_material *red = ob_world_material(&w, "test", OB_MATERIAL_UNLIT, 1.0f, 0.0f, 0.0f, false);
    ob_node *bad[3];
    for (int i = 0; i < 3; i++) {
        char name[16];
        snprintf(name, sizeof name, "textured%d", i);
        bad[i] = ob_world_entity(&w, NULL, name, w.box, textured, -1.5 + 1.5 * i, 1.2, 0);
    }
    ob_world_entity(&w, NULL, "red", w.box, red, 0, -1.2, 0);

    /* Valid texture: the textured boxes are green. */
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(st->pm.skipped_draws, 0);
    assert_int_equal(ob_world_view_stats(st, "main")->draws, 4);
    ob_world_read(&w);
    uint32_t top = (uint32_t)(w.height * 0.3f), bottom = (uint32_t)(w.height * 0.7f);
    const uint8_t *p = ob_world_pixel(&w, w.width / 2, top);
    uint8_t full = ob_composite_view_output_level(w.composite, 1.0f);
    assert_true(p[0] == 0 && abs(p[1] - full) <= 1 && p[2] == 0);

    /* Reference: the frame without the textured boxes. */
    for (int i = 0; i < 3; i++) ob_node_set_hidden(bad[i], true);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *without = ob_world_snapshot(&w);
    for (int i = 0; i < 3; i++) ob_node_set_hidden(bad[i], false);

    ob_image_destroy(w.dev, img); /* TestTexture now holds a stale handle */
    for (int mode = 0; mode < 2; mode++) {
        ob_test_log_clear();
        st = ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 1);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        assert_int_equal(st->pm.skipped_draws, 3);
        assert_int_equal(main->draws, 1); /* the red box */
        assert_int_equal(ob_test_log_count(OB_LOG_WARN), 1);
        assert_true(ob_test_log_has("TestTexture", "stale handle", NULL));
        ob_world_read(&w);
        assert_int_equal(ob_test_image_max_diff(without, w.pixels, w.width, w.height), 0);
        p = ob_world_pixel(&w, w.width / 2, bottom);
        assert_true(abs(p[0] - full) <= 1 && p[1] == 0 && p[2] == 0);
    }
    free(without);
    /* The effect goes before the effect context, once no frame uses it. */
    assert_int_equal(ob_renderer_wait_idle(w.r), OB_OK);
    ob_material_set_view_effect(textured, OB_VIEW_PERSPECTIVE, NULL);
    ob_effect_destroy(fx);
    ob_sampler_destroy(w.dev, sampler);
    ob_test_world_destroy(&w);
    unlink(path);
    rmdir(dir);
}

/* A material with no effect for a view type is not drawn there and counts
 * as culled: a custom material with only a perspective effect, a lit
 * material that casts no shadow, an unlit one in an environment map. */
static void material_without_effect_is_culled(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_world_look(&w, 0, 3, 6, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 8, 3);
    ob_material *caster = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, true);
    ob_material *no_shadow = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.8f, false);
    ob_material *unlit = ob_world_material(&w, "test", OB_MATERIAL_UNLIT, 0.9f, 0.9f, 0.1f, false);
    ob_result r;
    ob_material *custom = ob_material_create(w.lib, &(ob_material_desc){.name = "custom-unlit",
                                             .kind = OB_MATERIAL_CUSTOM}, &r);
    assert_non_null(custom);
    ob_effect *unlit_fx = ob_material_library_effect(w.lib, OB_STD_UNLIT, 0, &r);
    assert_non_null(unlit_fx);
    assert_int_equal(ob_material_set_view_effect(custom, OB_VIEW_PERSPECTIVE, unlit_fx), OB_OK);
    ob_material_desc mirror_desc = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE,
                                    .casts_shadows = true};
    ob_material *mirror = ob_material_create(w.lib, &mirror_desc, &r);
    assert_non_null(mirror);

    ob_world_entity(&w, NULL, "caster", w.box, caster, -1.5, 0, 0);
    ob_world_entity(&w, NULL, "no-shadow", w.box, no_shadow, 0, 0, -1.5);
    ob_world_entity(&w, NULL, "unlit", w.box, unlit, 1.5, 0, 0);
    ob_world_entity(&w, NULL, "custom", w.box, custom, 0, 0, 1.5);
    ob_world_entity(&w, NULL, "mirror", w.sphere, mirror, 0, 0, 0);
    /* One cascade: the culling of one shadow view is counted below. */
    assert_int_equal(ob_views_set_shadow_cascades(w.views, 1), OB_OK);

    for (int mode = 0; mode < 2; mode++) {
        const ob_frame_stats *st =
            ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        const ob_view_stats *shadow = ob_world_view_stats(st, "shadow:sun:c0");
        const ob_view_stats *env = ob_world_view_stats(st, "envmap:mirror");
        assert_non_null(main);
        assert_non_null(shadow);
        assert_non_null(env);
        assert_int_equal(main->draws, 5);
        assert_int_equal(main->culled, 0);
        /* Shadow: the caster and the mirror; three without a depth effect. */
        assert_int_equal(shadow->draws, 2);
        assert_int_equal(shadow->culled, 3);
        /* Env map (two layers): caster (on the seam at z = 0: both layers)
         * and no-shadow (at z = -1.5, wholly in the -Z layer); the owner is
         * excluded, unlit and custom have no paraboloid effect. */
        assert_int_equal(env->draws, 2 + 1);
        assert_int_equal(env->culled, 3);
        assert_int_equal(st->pm.skipped_draws, 0);
        assert_int_equal(st->culled, main->culled + shadow->culled + env->culled);
    }
    ob_test_world_destroy(&w);
}

/* A mistyped $OB_RING_STAGING or $OB_INSTANCE_RUNS is named in a warning
 * and the device's defaults are kept (where the blocks live, how runs are
 * drawn), as for no setting at all. */
static void unknown_ring_and_run_settings_are_reported(void **state)
{
    (void)state;
    ob_test_log_clear();
    setenv("OB_RING_STAGING", "sometimes", 1);
    setenv("OB_INSTANCE_RUNS", "batched", 1);
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.workers = 2});
    unsetenv("OB_RING_STAGING");
    unsetenv("OB_INSTANCE_RUNS");
    assert_logged("OB_RING_STAGING='sometimes'", "ignored");
    assert_logged("OB_INSTANCE_RUNS='batched'", "ignored");
    mixed_scene(&w);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_MULTI, 2);
    ob_device *dev = ob_renderer_device(w.r);
    /* staged exactly where mapped memory is not device-local */
    assert_int_equal(st->ring_upload_bytes > 0, !ob_device_host_memory_is_device_local(dev));
    const ob_device_caps *caps = ob_device_get_caps(dev);
    bool multi = caps->multi_draw_indirect && caps->draw_indirect_first_instance && !ob_device_is_cpu(dev);
    assert_int_equal(ob_renderer_instance_runs(w.r),
                     multi ? OB_INSTANCE_RUNS_MULTI_DRAW : OB_INSTANCE_RUNS_INSTANCED);
    assert_true(st->draws > 0);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(shared_state_bound_once_single_threaded),
        cmocka_unit_test(shared_state_bound_once_per_secondary),
        cmocka_unit_test(uniforms_packed_only_after_a_change),
        cmocka_unit_test(many_programs_each_read_their_own_uniforms),
        cmocka_unit_test(set_cache_holds_its_bound_across_changing_scenes),
        cmocka_unit_test(primary_and_secondaries_record_the_same),
        cmocka_unit_test(instanced_runs_draw_what_single_draws_draw),
        cmocka_unit_test(multi_draw_and_direct_runs_draw_what_instanced_runs_draw),
        cmocka_unit_test(a_view_of_many_chunks_draws_everything),
        cmocka_unit_test(stale_texture_skips_the_draw),
        cmocka_unit_test(material_without_effect_is_culled),
        cmocka_unit_test(unknown_ring_and_run_settings_are_reported),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
