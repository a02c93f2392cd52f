/* Levels of detail (ob_geometry_desc.lods, ob_views_set_lod): culling draws
 * an entity at the coarsest level whose error projects to within the
 * tolerance, so a near entity keeps level 0 and a far one takes a coarse
 * level; the level never goes down with distance; the picture moves by
 * about a pixel at most; a larger tolerance takes coarser levels; off,
 * every item is level 0; shadow cascades choose by texels; and the levels,
 * pixels and command hashes are the same in every threading mode. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

#define ROW 12   /* entities receding from the camera */

/* A ball of three levels (24 x 16, 8 x 5, 4 x 3 segments), with the
 * errors ob_mesh_deviation measures. */
static ob_geometry *ball(ob_test_world *w)
{
    ob_mesh m[3];
    assert_int_equal(ob_mesh_sphere(0.5f, 24, 16, &m[0]), OB_OK);
    assert_int_equal(ob_mesh_sphere(0.5f, 8, 5, &m[1]), OB_OK);
    assert_int_equal(ob_mesh_sphere(0.5f, 4, 3, &m[2]), OB_OK);
    ob_geometry_lod lods[2] = {{&m[1], 0}, {&m[2], 0}};
    assert_int_equal(ob_mesh_deviation(&m[0], &m[1], &lods[0].error), OB_OK);
    assert_int_equal(ob_mesh_deviation(&m[0], &m[2], &lods[1].error), OB_OK);
    ob_result r;
    ob_geometry *g = ob_stack_add_geometry_desc(
        w->stack, &(ob_geometry_desc){.mesh = &m[0], .name = "ball", .lods = lods, .lod_count = 2},
        &r);
    assert_int_equal(r, OB_OK);
    for (int k = 0; k < 3; k++) ob_mesh_release(&m[k]);
    return g;
}

/* A row of balls at 3, 4.5, 6.75, ... units in front of the camera (each
 * 1.5 times farther), a little to the side so none hides the next, a
 * floor of one level and the sun, casting shadows or not. */
static void build_row(ob_test_world *w, bool shadows, ob_node *out[ROW])
{
    ob_geometry *g = ball(w);
    ob_material *m = ob_world_material(w, "ball", OB_MATERIAL_LIT, 0.8f, 0.5f, 0.3f, true);
    double d = 3.0;
    for (int k = 0; k < ROW; k++, d *= 1.5) {
        char name[16];
        snprintf(name, sizeof name, "ball%d", k);
        double side = (k % 2 ? 0.12 : -0.12) * d;
        out[k] = ob_world_entity(w, NULL, name, g, m, side, 0.0, -d);
    }
    ob_world_entity(w, NULL, "floor", w->plane, m, 0, -0.6, -5);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, shadows, 1.0f, 2, 4, 3);
    ob_world_look(w, 0, 0.3, 0, 0, 0, -10);
}

/* The level the main view drew node n at; -1 when it is not in the list. */
static int level_of(const ob_view *v, const ob_node *n)
{
    for (uint32_t i = 0; i < v->item_count; i++)
        if (v->items[i].node == n) return v->items[i].lod;
    return -1;
}

static void near_keeps_level_0_far_takes_the_coarsest(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_node *row[ROW];
    build_row(&w, false, row);
    const ob_view *main = ob_perspective_view_base(w.main);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    int before = 0, coarse = 0;
    for (int k = 0; k < ROW; k++) {
        int l = level_of(main, row[k]);
        if (l < 0) fail_msg("ball%d not drawn", k);
        if (l < before) fail_msg("ball%d at level %d, nearer ball at %d", k, l, before);
        before = l;
        coarse += l > 0;
    }
    /* The statistics count them. */
    assert_int_equal(st->lod_items, coarse);
    assert_int_equal(ob_world_view_stats(st, main->name)->lod_items, coarse);
    assert_int_equal(level_of(main, row[0]), 0);
    assert_int_equal(level_of(main, row[ROW - 1]), 2);

    /* Ten pixels of tolerance: no ball at a finer level than with one, and
     * some coarser. */
    int levels_1px[ROW], levels_10px[ROW], coarser = 0;
    for (int k = 0; k < ROW; k++) levels_1px[k] = level_of(main, row[k]);
    assert_int_equal(ob_views_set_lod_error(w.views, 10.0f), OB_OK);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    for (int k = 0; k < ROW; k++) {
        levels_10px[k] = level_of(main, row[k]);
        assert_true(levels_10px[k] >= levels_1px[k]);
        coarser += levels_10px[k] > levels_1px[k];
    }
    assert_true(coarser > 0);
    /* Refused tolerances leave it as it was. */
    assert_int_equal(ob_views_set_lod_error(w.views, -1.0f), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_views_set_lod_error(w.views, NAN), OB_ERR_INVALID_ARGUMENT);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    for (int k = 0; k < ROW; k++) assert_int_equal(level_of(main, row[k]), levels_10px[k]);

    /* Off: level 0 everywhere. */
    ob_views_set_lod(w.views, false);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    for (int k = 0; k < ROW; k++) assert_int_equal(level_of(main, row[k]), 0);
    assert_int_equal(st->lod_items, 0);
    ob_test_world_destroy(&w);
}

/* Within the tolerance of one pixel, the picture with levels is the one
 * without them but for a few silhouette pixels of the far balls. */
static void levels_keep_the_picture(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_node *row[ROW];
    build_row(&w, false, row);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t hash_on = st->frame_hash;
    uint8_t *on = ob_world_snapshot(&w);
    ob_views_set_lod(w.views, false);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *off = ob_world_snapshot(&w);
    /* Other index ranges are drawn, so the commands differ. */
    assert_true(st->frame_hash != hash_on);
    uint32_t pixels = w.width * w.height;
    uint32_t moved = ob_rgba_diff_count(on, off, pixels, 24);
    if (moved > pixels / 200)
        fail_msg("%u of %u pixels differ by more than 24 levels with levels of detail", moved,
                 pixels);
    free(on);
    free(off);
    ob_test_world_destroy(&w);
}

/* The levels are chosen in culling, on the pool in chunks: every mode and
 * worker count gives the same frame, pixels and command hash. */
static void every_mode_draws_the_same_levels(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.parallel_grain = 4});
    ob_node *row[ROW];
    build_row(&w, false, row);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t hash = st->frame_hash;
    uint8_t *ref = ob_world_snapshot(&w);
    static const struct { ob_threading mode; uint32_t workers; } modes[] = {
        {OB_THREADING_MULTI, 1}, {OB_THREADING_MULTI, 2}, {OB_THREADING_MULTI, 0},
        {OB_THREADING_AUTO, 0}, {OB_THREADING_SINGLE, 0},
    };
    for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++) {
        st = ob_test_world_frame(&w, modes[k].mode, modes[k].workers);
        assert_true(st->frame_hash == hash);
        uint8_t *again = ob_world_snapshot(&w);
        assert_memory_equal(ref, again, (size_t)w.width * w.height * 4);
        free(again);
    }
    free(ref);
    ob_test_world_destroy(&w);
}

/* Shadow cascades choose by texels, the same at any distance; point and
 * spot lights' maps as perspective views: with a shadowed sun, some
 * shadow-map items are drawn coarser, none with levels off, and the frame
 * is the same in every mode. */
static void shadow_maps_choose_levels_by_texels(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_node *row[ROW];
    build_row(&w, true, row);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t hash = st->frame_hash;
    uint32_t shadow_coarse = 0, shadow_views = 0;
    for (uint32_t k = 0; k < st->view_count; k++)
        if (st->views[k].type == OB_VIEW_SHADOW) {
            shadow_views++;
            shadow_coarse += st->views[k].lod_items;
        }
    assert_true(shadow_views > 0);
    assert_true(shadow_coarse > 0);
    uint8_t *ref = ob_world_snapshot(&w);
    st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    assert_true(st->frame_hash == hash);
    uint8_t *mt = ob_world_snapshot(&w);
    assert_memory_equal(ref, mt, (size_t)w.width * w.height * 4);
    ob_views_set_lod(w.views, false);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    for (uint32_t k = 0; k < st->view_count; k++) assert_int_equal(st->views[k].lod_items, 0);
    free(ref);
    free(mt);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(near_keeps_level_0_far_takes_the_coarsest),
        cmocka_unit_test(levels_keep_the_picture),
        cmocka_unit_test(every_mode_draws_the_same_levels),
        cmocka_unit_test(shadow_maps_choose_levels_by_texels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
