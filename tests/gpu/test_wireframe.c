/* Wireframe views (ob_view_set_wireframe, obelisk-view's W key): the
 * polygon mode is part of the pipeline key, a wireframe view draws edges
 * (another image, other command hashes), and turning it off again gives
 * back the filled frame exactly — images and command hashes — so nothing
 * changes for anyone who never turns it on. */
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

/* A filled pipeline keeps its id; a wireframe one is another pipeline with
 * another id; line topologies are edges already and keep theirs. */
static void polygon_mode_is_part_of_the_pipeline_key(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_result r;
    ob_effect *e = ob_effect_create(
        w.fx, &(ob_effect_desc){.name = "keyed", .vertex = "unlit.vert", .fragment = "unlit.frag",
                                .layout = ob_views_standard_input(), .depth_test = true},
        &r);
    assert_non_null(e);
    uint32_t id_fill = 0, id_fill_b = 0, id_wire = 0, id_wire_b = 0;
    VkPipeline fill = ob_effect_pipeline(e, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, &id_fill);
    VkPipeline fill_b = ob_effect_pipeline_for(
        e, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 1, false}, &id_fill_b);
    VkPipeline wire = ob_effect_pipeline_for(
        e, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 1, true}, &id_wire);
    VkPipeline wire_b = ob_effect_pipeline_for(
        e, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 1, true}, &id_wire_b);
    assert_true(fill != VK_NULL_HANDLE && wire != VK_NULL_HANDLE);
    assert_true(fill == fill_b && id_fill == id_fill_b);
    assert_true(wire != fill && id_wire != id_fill);
    assert_true(wire == wire_b && id_wire == id_wire_b);
    assert_int_equal(ob_effect_pipeline_count(e), 2);
    ob_effect *points = ob_effect_create(
        w.fx, &(ob_effect_desc){.name = "lines", .vertex = "unlit.vert", .fragment = "unlit.frag",
                                .layout = ob_views_standard_input(),
                                .topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST},
        &r);
    assert_non_null(points);
    uint32_t id_p = 0, id_pw = 0;
    VkPipeline p = ob_effect_pipeline(points, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, &id_p);
    VkPipeline pw = ob_effect_pipeline_for(
        points, &(ob_effect_targets){VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT, 1, true}, &id_pw);
    assert_true(p == pw && id_p == id_pw);
    ob_effect_destroy(points);
    ob_effect_destroy(e);
    ob_test_world_destroy(&w);
}

/* A lit box and sphere on a plane: wireframe shows the background through
 * the faces and changes the hash; off again, the frame is the filled one
 * byte for byte with the same hash, in single- and multi-threaded mode. */
static void wireframe_view_draws_edges_and_off_restores_the_frame(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, NULL);
    ob_material *m = ob_world_material(&w, "test", OB_MATERIAL_LIT, 0.8f, 0.6f, 0.3f, true);
    ob_world_entity(&w, NULL, "box", w.box, m, -0.8, 0.5, 0);
    ob_world_entity(&w, NULL, "sphere", w.sphere, m, 0.8, 0.5, 0);
    ob_world_entity(&w, NULL, "floor", w.plane, m, 0, 0, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 1.0f, 2, 4, 3);
    ob_world_look(&w, 0, 2.5, 4.5, 0, 0.3, 0);
    ob_view *main = ob_perspective_view_base(w.main);

    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t filled_hash = st->frame_hash;
    uint8_t *filled = ob_world_snapshot(&w);

    assert_int_equal(ob_view_set_wireframe(main, w.dev, true), OB_OK);
    st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t wire_hash = st->frame_hash;
    uint8_t *wire = ob_world_snapshot(&w);
    assert_true(wire_hash != filled_hash);
    /* Most of the faces' pixels now show the clear colour. */
    uint32_t changed = ob_rgba_diff_count(filled, wire, w.width * w.height, 8);
    if (changed < w.width * w.height / 10) fail_msg("wireframe changed only %u pixels", changed);
    /* Multi-threaded recording draws the same wireframe. */
    st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    assert_true(st->frame_hash == wire_hash);
    uint8_t *wire_mt = ob_world_snapshot(&w);
    assert_memory_equal(wire, wire_mt, (size_t)w.width * w.height * 4);

    assert_int_equal(ob_view_set_wireframe(main, w.dev, false), OB_OK);
    for (int mode = 0; mode < 2; mode++) {
        st = ob_test_world_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, 0);
        assert_true(st->frame_hash == filled_hash);
        uint8_t *again = ob_world_snapshot(&w);
        assert_memory_equal(filled, again, (size_t)w.width * w.height * 4);
        free(again);
    }
    free(filled);
    free(wire);
    free(wire_mt);
    ob_test_world_destroy(&w);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(polygon_mode_is_part_of_the_pipeline_key),
        cmocka_unit_test(wireframe_view_draws_edges_and_off_restores_the_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
