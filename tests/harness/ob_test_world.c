#include "ob_test_world.h"

#include <string.h>

/* The world's error policy here: a failure fails the test, naming the step. */
static void fail_test(ob_world *w, ob_result r, const char *what, void *user)
{
    (void)w;
    (void)user;
    fail_msg("%s: %s", what, ob_result_name(r));
}

void ob_test_world_create(ob_test_world *w, const ob_test_world_desc *desc)
{
    ob_test_setup_log();
    ob_test_world_desc d = desc ? *desc : (ob_test_world_desc){0};
    ob_world_desc wd = ob_world_desc_small("obelisk-test");
    wd.on_error = fail_test;
    ob_stack_desc *sd = &wd.stack;
    sd->renderer.device.validation = 1;
    sd->renderer.worker_count = d.workers ? d.workers : 4;
    sd->renderer.chunk_draws = d.chunk_draws;
    sd->renderer.parallel_grain = d.parallel_grain;
    if (d.width) sd->width = d.width;
    if (d.height) sd->height = d.height;
    if (d.env_map_size) sd->env_map_size = d.env_map_size;
    if (d.shadow_map_size) sd->shadow_map_size = d.shadow_map_size;
    if (d.clear_color[3] > 0.0f) memcpy(sd->clear_color, d.clear_color, sizeof sd->clear_color);
    sd->msaa = d.msaa;
    sd->cache_dir = d.cache_dir;
    sd->renderer.device.adopt = d.adopt;
    sd->env_map_kind = d.env_map_kind;
    sd->renderer.ring_staging = d.ring_staging;
    sd->renderer.instance_runs = d.instance_runs;
    ob_world_create(w, &wd);
}

void ob_test_world_destroy(ob_test_world *w)
{
    if (!w->stack) return;
    ob_world_leftovers left = ob_world_destroy(w);
    if (left.validation_errors || left.validation_warnings)
        fail_msg("validation layer reported %u errors and %u warnings", left.validation_errors,
                 left.validation_warnings);
    /* Everything the world made is gone: a leak the sanitizer build would
     * also catch, but this also catches memory kept in a list until exit. */
    if (left.heap_blocks || left.heap_bytes)
        fail_msg("Obelisk's heap holds %lld blocks (%lld bytes) more after the world was destroyed",
                 (long long)left.heap_blocks, (long long)left.heap_bytes);
}

const ob_frame_stats *ob_test_world_frame(ob_test_world *w, ob_threading mode, uint32_t workers)
{
    return ob_test_world_frame_with(w, mode, workers, NULL, 0);
}

const ob_frame_stats *ob_test_world_frame_with(ob_test_world *w, ob_threading mode,
                                               uint32_t workers, ob_view *const *extra,
                                               uint32_t extra_count)
{
    ob_world_frame(w, mode, workers, extra, extra_count);
    return ob_world_stats(w);
}

ob_node *ob_test_world_light(ob_test_world *w, const char *name, const ob_light_desc *d, double x,
                             double y, double z)
{
    ob_result r;
    ob_node *n = ob_node_create(w->scene, NULL, name, &r);
    assert_non_null(n);
    assert_int_equal(ob_node_set_light(n, d), OB_OK);
    ob_node_set_position(n, (const double[3]){x, y, z});
    return n;
}

ob_geometry *ob_test_world_pbr_plane(ob_test_world *w, uint32_t subdivisions)
{
    ob_mesh mesh;
    assert_int_equal(ob_mesh_plane(20.0f, 20.0f, subdivisions, &mesh), OB_OK);
    mesh.colors = ob_calloc(mesh.vertex_count, sizeof *mesh.colors);
    assert_non_null(mesh.colors);
    memset(mesh.colors, 255, mesh.vertex_count * sizeof *mesh.colors);
    ob_geometry *plane = ob_world_geometry(w, &mesh, "pbr plane");
    ob_mesh_release(&mesh);
    return plane;
}
