/* Geometry on the device: a generated box uploads into valid buffers whose
 * contents read back exactly; a broken mesh uploads nothing; failures leave
 * no resources behind; no validation messages. */
#include "ob_test.h"
#include "ob_geometry.h"
#include "ob_renderer_layer.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static ob_device *dev;

static int create_device(void **state)
{
    (void)state;
    dev = ob_test_device_create();
    return dev ? 0 : -1;
}

static int destroy_device(void **state)
{
    (void)state;
    ob_device_destroy(dev);
    dev = NULL;
    return 0;
}

/* Copies a device-local buffer into a host-visible one and returns a copy of its bytes. */
static void *read_back(ob_buffer src, uint64_t size)
{
    ob_result r;
    ob_buffer_desc desc = {.size = size, .usage = OB_BUFFER_TRANSFER_DST, .host_visible = true, .name = "read-back"};
    ob_buffer dst = ob_buffer_create(dev, &desc, &r);
    assert_int_equal(r, OB_OK);
    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
    VkBufferCopy region = {.size = size};
    vkCmdCopyBuffer(cmd, ob_buffer_vk(dev, src), ob_buffer_vk(dev, dst), 1, &region);
    assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);
    void *copy = malloc(size);
    memcpy(copy, ob_buffer_mapped(dev, dst), size);
    ob_buffer_destroy(dev, dst);
    return copy;
}

static void box_uploads_with_counts_bounds_and_contents(void **state)
{
    (void)state;
    const float h[3] = {1.0f, 2.0f, 3.0f};
    ob_mesh box;
    assert_int_equal(ob_mesh_box(h, &box), OB_OK);
    ob_resource_counts before = ob_resource_counts_get(dev);

    ob_result r;
    ob_geometry_desc desc = {.mesh = &box, .name = "crate"};
    ob_geometry *g = ob_geometry_create(dev, &desc, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(g);
    assert_int_equal(ob_geometry_vertex_count(g), 24);
    assert_int_equal(ob_geometry_index_count(g), 36);
    assert_int_equal(ob_geometry_topology(g), VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    assert_ptr_equal(ob_geometry_layout(g), ob_vertex_layout_standard());
    assert_int_equal(ob_geometry_layout(g)->stride, sizeof(ob_vertex));
    assert_string_equal(ob_geometry_name(g), "crate");
    assert_memory_equal(ob_geometry_bounds(g), &box.bounds, sizeof box.bounds);
    assert_true(ob_buffer_is_valid(dev, ob_geometry_vertex_buffer(g)));
    assert_true(ob_buffer_is_valid(dev, ob_geometry_index_buffer(g)));
    assert_int_equal(ob_buffer_size(dev, ob_geometry_vertex_buffer(g)), 24 * sizeof(ob_vertex));
    assert_int_equal(ob_buffer_size(dev, ob_geometry_index_buffer(g)), 36 * sizeof(uint32_t));
    ob_resource_counts during = ob_resource_counts_get(dev);
    assert_int_equal(during.buffers, before.buffers + 2);

    void *vertices = read_back(ob_geometry_vertex_buffer(g), 24 * sizeof(ob_vertex));
    void *indices = read_back(ob_geometry_index_buffer(g), 36 * sizeof(uint32_t));
    assert_memory_equal(vertices, box.vertices, 24 * sizeof(ob_vertex));
    assert_memory_equal(indices, box.indices, 36 * sizeof(uint32_t));
    free(vertices);
    free(indices);

    /* Ids: stable for equal geometry, explicit when given, never 0. */
    ob_geometry *twin = ob_geometry_create(dev, &desc, &r);
    assert_non_null(twin);
    assert_int_not_equal(ob_geometry_id(g), 0);
    assert_int_equal(ob_geometry_id(twin), ob_geometry_id(g));
    ob_geometry_desc named = {.mesh = &box, .name = "crate", .id = 77};
    ob_geometry *explicit_id = ob_geometry_create(dev, &named, &r);
    assert_int_equal(ob_geometry_id(explicit_id), 77);

    ob_geometry_destroy(dev, explicit_id);
    ob_geometry_destroy(dev, twin);
    ob_geometry_destroy(dev, g);
    ob_geometry_destroy(dev, NULL);
    assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
    ob_mesh_release(&box);
    ob_test_assert_no_validation(dev);
}

/* TEXCOORD_1: the extended layout plus location 5 at 52 (stride 60); a
 * mesh with uv1 uploads so without a flag, one without it repeats its uv
 * there when asked (a material reading set 1 on a mesh lacking it). */
static void extended_uv1_layout_carries_the_second_set(void **state)
{
    (void)state;
    const ob_vertex_layout *l = ob_vertex_layout_extended_uv1();
    assert_int_equal(l->stride, 60);
    assert_int_equal(l->attribute_count, 6);
    for (uint32_t i = 0; i < 5; i++)
        assert_memory_equal(&l->attributes[i], &ob_vertex_layout_extended()->attributes[i], sizeof l->attributes[i]);
    assert_int_equal(l->attributes[5].location, 5);
    assert_int_equal(l->attributes[5].offset, 52);
    assert_int_equal(l->attributes[5].format, VK_FORMAT_R32G32_SFLOAT);
    assert_string_equal(l->attributes[5].semantic, "TEXCOORD1");

    const float h[3] = {1, 1, 1};
    ob_mesh box;
    assert_int_equal(ob_mesh_box(h, &box), OB_OK);
    ob_result r;
    ob_geometry *g = ob_geometry_create(dev, &(ob_geometry_desc){.mesh = &box, .name = "uv0 twice", .texcoord1 = true}, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_equal(ob_geometry_layout(g), l);
    assert_int_equal(ob_buffer_size(dev, ob_geometry_vertex_buffer(g)), 24 * 60);
    ob_vertex_extended_uv1 *x = read_back(ob_geometry_vertex_buffer(g), 24 * 60);
    for (uint32_t i = 0; i < 24; i++) {
        assert_memory_equal(x[i].base.uv, box.vertices[i].uv, sizeof x[i].base.uv);
        assert_memory_equal(x[i].uv1, box.vertices[i].uv, sizeof x[i].uv1);
    }
    free(x);
    ob_geometry_destroy(dev, g);

    box.uv1 = ob_calloc(24, sizeof *box.uv1);
    assert_non_null(box.uv1);
    for (uint32_t i = 0; i < 24; i++) box.uv1[i][0] = 0.5f, box.uv1[i][1] = (float)i;
    g = ob_geometry_create(dev, &(ob_geometry_desc){.mesh = &box, .name = "lightmapped"}, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_equal(ob_geometry_layout(g), l);
    x = read_back(ob_geometry_vertex_buffer(g), 24 * 60);
    for (uint32_t i = 0; i < 24; i++) {
        assert_memory_equal(x[i].base.position, box.vertices[i].position, sizeof x[i].base.position);
        assert_memory_equal(x[i].uv1, box.uv1[i], sizeof x[i].uv1);
    }
    free(x);
    ob_geometry_destroy(dev, g);

    /* A non-finite second uv is refused like any other attribute. */
    box.uv1[5][1] = INFINITY;
    ob_test_log_clear();
    assert_null(ob_geometry_create(dev, &(ob_geometry_desc){.mesh = &box, .name = "lightmapped"}, &r));
    assert_int_equal(r, OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("lightmapped: vertex 5 uv1", NULL));
    ob_mesh_release(&box);
    ob_test_assert_no_validation(dev);
}

/* The extended layout: colours and tangents interleave after the standard
 * attributes; what a mesh lacks gets the documented defaults. */
static void extended_layout_interleaves_colours_and_tangents(void **state)
{
    (void)state;
    const ob_vertex_layout *l = ob_vertex_layout_extended();
    assert_int_equal(l->stride, 52);
    assert_int_equal(l->attribute_count, 5);
    const uint32_t offsets[5] = {0, 12, 24, 32, 36};
    const VkFormat formats[5] = {VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT,
                                 VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM,
                                 VK_FORMAT_R32G32B32A32_SFLOAT};
    for (uint32_t i = 0; i < 5; i++) {
        assert_int_equal(l->attributes[i].location, i);
        assert_int_equal(l->attributes[i].offset, offsets[i]);
        assert_int_equal(l->attributes[i].format, formats[i]);
    }
    assert_string_equal(l->attributes[3].semantic, "COLOR0");
    assert_string_equal(l->attributes[4].semantic, "TANGENT");

    const float h[3] = {1, 1, 1};
    ob_mesh box;
    assert_int_equal(ob_mesh_box(h, &box), OB_OK);
    assert_null(box.tangents);
    assert_null(box.colors);
    ob_resource_counts before = ob_resource_counts_get(dev);

    /* A plain mesh uploaded with the flag: defaults everywhere. */
    ob_result r;
    ob_geometry_desc plain = {.mesh = &box, .name = "crate", .extended = true};
    ob_geometry *g = ob_geometry_create(dev, &plain, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_equal(ob_geometry_layout(g), ob_vertex_layout_extended());
    assert_int_equal(ob_buffer_size(dev, ob_geometry_vertex_buffer(g)), 24 * 52);
    ob_vertex_extended *x = read_back(ob_geometry_vertex_buffer(g), 24 * 52);
    for (uint32_t i = 0; i < 24; i++) {
        assert_memory_equal(x[i].position, box.vertices[i].position, sizeof x[i].position);
        assert_memory_equal(x[i].normal, box.vertices[i].normal, sizeof x[i].normal);
        assert_memory_equal(x[i].uv, box.vertices[i].uv, sizeof x[i].uv);
        const uint8_t white[4] = {255, 255, 255, 255};
        const float tangent[4] = {1, 0, 0, 1};
        assert_memory_equal(x[i].color, white, 4);
        assert_memory_equal(x[i].tangent, tangent, sizeof tangent);
    }
    free(x);
    ob_geometry_desc standard = {.mesh = &box, .name = "crate"};
    ob_geometry *s = ob_geometry_create(dev, &standard, &r);
    assert_ptr_equal(ob_geometry_layout(s), ob_vertex_layout_standard());
    assert_int_not_equal(ob_geometry_id(s), ob_geometry_id(g));   /* different bytes on the device */
    ob_geometry_destroy(dev, s);
    ob_geometry_destroy(dev, g);

    /* A mesh with colours and tangents is extended without the flag. */
    box.colors = ob_calloc(24, sizeof *box.colors);
    box.tangents = ob_calloc(24, sizeof *box.tangents);
    assert_non_null(box.colors);
    assert_non_null(box.tangents);
    for (uint32_t i = 0; i < 24; i++) {
        box.colors[i][0] = (uint8_t)i;
        box.colors[i][1] = (uint8_t)(2 * i);
        box.colors[i][2] = 7;
        box.colors[i][3] = 200;
        box.tangents[i][0] = 0;
        box.tangents[i][1] = 0;
        box.tangents[i][2] = 1;
        box.tangents[i][3] = (i & 1) ? -1.0f : 1.0f;
    }
    ob_geometry_desc full = {.mesh = &box, .name = "painted"};
    g = ob_geometry_create(dev, &full, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_equal(ob_geometry_layout(g), ob_vertex_layout_extended());
    x = read_back(ob_geometry_vertex_buffer(g), 24 * 52);
    for (uint32_t i = 0; i < 24; i++) {
        assert_memory_equal(x[i].position, box.vertices[i].position, sizeof x[i].position);
        assert_memory_equal(x[i].color, box.colors[i], 4);
        assert_memory_equal(x[i].tangent, box.tangents[i], 16);
    }
    free(x);
    ob_geometry_destroy(dev, g);

    /* A non-finite tangent is refused like any other attribute. */
    box.tangents[3][1] = NAN;
    ob_test_log_clear();
    assert_null(ob_geometry_create(dev, &full, &r));
    assert_int_equal(r, OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("painted: vertex 3 tangent is not finite", NULL));

    /* The extended path's interleaving buffer fails cleanly too. */
    box.tangents[3][1] = 0;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    g = ob_geometry_create(dev, &full, NULL);
    uint64_t points = ob_fault_count(OB_FAULT_HOST_ALLOC);
    ob_geometry_destroy(dev, g);
    for (uint64_t n = 1; n <= points; n++) {
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        g = ob_geometry_create(dev, &full, &r);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        if (g) ob_geometry_destroy(dev, g);
        else assert_int_equal(r, OB_ERR_OUT_OF_HOST_MEMORY);
        assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
    }

    /* ob_mesh_release frees the optional arrays (ob_calloc'd above): the
     * heap's live block count returns to where it was. */
    ob_heap_stats heap = ob_heap_stats_now();
    ob_mesh_release(&box);
    assert_null(box.colors);
    assert_null(box.tangents);
    assert_int_equal(ob_heap_stats_now().live_blocks, heap.live_blocks - 4);
    assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
    ob_test_assert_no_validation(dev);
}

static void broken_mesh_uploads_nothing(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    ob_mesh box;
    assert_int_equal(ob_mesh_box(h, &box), OB_OK);
    box.indices[5] = 4000;
    ob_resource_counts before = ob_resource_counts_get(dev);
    ob_test_log_clear();
    ob_result r;
    ob_geometry_desc desc = {.mesh = &box, .name = "crate"};
    assert_null(ob_geometry_create(dev, &desc, &r));
    assert_int_equal(r, OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("crate: index 5 = 4000 out of range (24 vertices)", NULL));
    assert_true(ob_test_log_has("crate: mesh rejected, nothing uploaded", NULL));
    ob_resource_counts after = ob_resource_counts_get(dev);
    assert_int_equal(after.buffers, before.buffers);
    assert_int_equal(after.device_bytes, before.device_bytes);

    box.indices[5] = 5;
    ob_geometry_desc patches = {.mesh = &box, .name = "crate", .topology = VK_PRIMITIVE_TOPOLOGY_PATCH_LIST};
    assert_null(ob_geometry_create(dev, &patches, &r));
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    assert_null(ob_geometry_create(dev, NULL, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
    ob_mesh_release(&box);
    ob_test_assert_no_validation(dev);
}

static void line_list_topology_is_kept(void **state)
{
    (void)state;
    ob_vertex v[2] = {{{0, 0, 0}, {0, 1, 0}, {0, 0}}, {{1, 0, 0}, {0, 1, 0}, {1, 0}}};
    uint32_t idx[2] = {0, 1};
    ob_mesh line = {.vertices = v, .vertex_count = 2, .indices = idx, .index_count = 2};
    ob_result r;
    ob_geometry_desc desc = {.mesh = &line, .name = "axis", .topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST};
    ob_geometry *g = ob_geometry_create(dev, &desc, &r);
    assert_int_equal(r, OB_OK);
    assert_int_equal(ob_geometry_topology(g), VK_PRIMITIVE_TOPOLOGY_LINE_LIST);
    assert_float_equal(ob_geometry_bounds(g)->max[0], 1.0f, 0.0f);
    ob_geometry_destroy(dev, g);
    ob_test_assert_no_validation(dev);
}

static void failures_leave_no_resources(void **state)
{
    (void)state;
    const float h[3] = {1, 1, 1};
    ob_mesh box;
    assert_int_equal(ob_mesh_box(h, &box), OB_OK);
    ob_geometry_desc desc = {.mesh = &box, .name = "crate"};
    ob_resource_counts before = ob_resource_counts_get(dev);
    const ob_fault_kind kinds[2] = {OB_FAULT_HOST_ALLOC, OB_FAULT_VK_OBJECT};
    for (int k = 0; k < 2; k++) {
        ob_fault_arm(kinds[k], 0);
        ob_geometry *g = ob_geometry_create(dev, &desc, NULL);
        uint64_t points = ob_fault_count(kinds[k]);
        ob_geometry_destroy(dev, g);
        for (uint64_t n = 1; n <= points; n++) {
            ob_result r;
            ob_fault_arm(kinds[k], n);
            g = ob_geometry_create(dev, &desc, &r);
            ob_fault_arm(kinds[k], 0);
            if (g) {   /* the fault hit something that is allowed to fail softly */
                ob_geometry_destroy(dev, g);
                continue;
            }
            assert_int_not_equal(r, OB_OK);
            assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
        }
    }
    assert_int_equal(ob_resource_counts_get(dev).buffers, before.buffers);
    ob_mesh_release(&box);
    ob_test_assert_no_validation(dev);
}

/* Levels of detail share the buffers: each level's indices read back at its
 * first index, its vertices at its vertex offset, through the geometry
 * interface's draw data; the errors come back as given. */
static void levels_of_detail_share_the_buffers(void **state)
{
    (void)state;
    ob_mesh fine, mid, coarse;
    assert_int_equal(ob_mesh_sphere(1.0f, 16, 10, &fine), OB_OK);
    assert_int_equal(ob_mesh_sphere(1.0f, 8, 5, &mid), OB_OK);
    assert_int_equal(ob_mesh_sphere(1.0f, 4, 3, &coarse), OB_OK);
    float e_mid, e_coarse, e_self;
    assert_int_equal(ob_mesh_deviation(&fine, &mid, &e_mid), OB_OK);
    assert_int_equal(ob_mesh_deviation(&fine, &coarse, &e_coarse), OB_OK);
    assert_int_equal(ob_mesh_deviation(&fine, &fine, &e_self), OB_OK);
    /* A chord of a unit circle 2*pi/8 long sags 1 - cos(pi/8) = 0.076 at
     * its middle; the coarse sphere is much further off; a mesh is 0 from
     * itself. */
    assert_true(e_mid > 0.07f && e_mid < 0.3f);
    assert_true(e_coarse > e_mid && e_coarse < 1.0f);
    assert_true(e_self < 1e-6f);

    ob_geometry_lod lods[2] = {{&mid, e_mid}, {&coarse, e_coarse}};
    ob_result r;
    ob_geometry *g = ob_geometry_create(dev, &(ob_geometry_desc){.mesh = &fine, .name = "ball",
                                                                 .lods = lods, .lod_count = 2}, &r);
    assert_int_equal(r, OB_OK);
    assert_int_equal(ob_geometry_lod_count(g), 3);
    assert_int_equal(ob_geometry_index_count(g), fine.index_count);
    assert_int_equal(ob_geometry_vertex_count(g), fine.vertex_count);
    assert_true(ob_geometry_lod_error(g, 0) == 0.0f);
    assert_true(ob_geometry_lod_error(g, 2) == e_coarse);
    assert_int_equal(ob_geometry_lod_index_count(g, 1), mid.index_count);
    assert_int_equal(ob_geometry_lod_index_count(g, 3), 0);
    const ob_bounds *b = ob_geometry_bounds(g);
    assert_true(fabsf(b->radius - 1.0f) < 1e-4f);   /* level 0's */

    const ob_geometry_iface *gi = ob_geometry_iface_get();
    float rel[OB_LOD_MAX];
    assert_int_equal(gi->lods(g, rel), 3);
    assert_true(rel[0] == 0.0f && fabsf(rel[1] - e_mid / b->radius) < 1e-6f);
    uint32_t total_vertices = fine.vertex_count + mid.vertex_count + coarse.vertex_count;
    uint32_t total_indices = fine.index_count + mid.index_count + coarse.index_count;
    uint32_t *indices = read_back(ob_geometry_index_buffer(g), total_indices * 4ull);
    ob_vertex *vertices = read_back(ob_geometry_vertex_buffer(g), total_vertices * sizeof(ob_vertex));
    const ob_mesh *level[3] = {&fine, &mid, &coarse};
    for (uint32_t l = 0; l < 3; l++) {
        ob_draw_data dd;
        gi->draw_data(g, l, &dd);
        assert_int_equal(dd.count, level[l]->index_count);
        assert_memory_equal(indices + dd.first, level[l]->indices, dd.count * 4u);
        assert_memory_equal(vertices + dd.vertex_offset, level[l]->vertices,
                            level[l]->vertex_count * sizeof(ob_vertex));
    }
    free(indices);
    free(vertices);
    ob_geometry_destroy(dev, g);
    ob_mesh_release(&fine);
    ob_mesh_release(&mid);
    ob_mesh_release(&coarse);
}

/* Levels that cannot be drawn right are refused, naming the level, and
 * nothing is uploaded. */
static void bad_levels_are_refused(void **state)
{
    (void)state;
    ob_mesh fine, coarse, broken;
    assert_int_equal(ob_mesh_sphere(1.0f, 12, 8, &fine), OB_OK);
    assert_int_equal(ob_mesh_sphere(1.0f, 4, 3, &coarse), OB_OK);
    assert_int_equal(ob_mesh_sphere(1.0f, 4, 3, &broken), OB_OK);
    broken.indices[2] = broken.vertex_count + 5;
    ob_resource_counts before = ob_resource_counts_get(dev);
    struct {
        ob_geometry_lod lods[2];
        uint32_t count;
        ob_result want;
    } cases[] = {
        {{{&coarse, NAN}}, 1, OB_ERR_INVALID_ARGUMENT},
        {{{&coarse, 0.0f}}, 1, OB_ERR_INVALID_ARGUMENT},
        {{{&coarse, -1.0f}}, 1, OB_ERR_INVALID_ARGUMENT},
        {{{NULL, 0.1f}}, 1, OB_ERR_INVALID_ARGUMENT},
        {{{&coarse, 0.2f}, {&coarse, 0.1f}}, 2, OB_ERR_INVALID_ARGUMENT},   /* errors go down */
        {{{&broken, 0.2f}}, 1, OB_ERR_OUT_OF_RANGE},
        {{{&coarse, 0.2f}}, OB_GEOMETRY_MAX_LODS, OB_ERR_LIMIT},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        ob_result r = OB_OK;
        ob_geometry_desc gd = {.mesh = &fine, .name = "ball", .lods = cases[k].lods,
                               .lod_count = cases[k].count};
        assert_null(ob_geometry_create(dev, &gd, &r));
        assert_int_equal(r, cases[k].want);
    }
    /* Procedural geometry has no levels to choose between. */
    ob_result r = OB_OK;
    ob_geometry_lod one = {&coarse, 0.2f};
    assert_null(ob_geometry_create(dev, &(ob_geometry_desc){.vertex_count = 6, .lods = &one,
                                                            .lod_count = 1}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    ob_resource_counts after = ob_resource_counts_get(dev);
    assert_int_equal(after.buffers, before.buffers);
    ob_mesh_release(&fine);
    ob_mesh_release(&coarse);
    ob_mesh_release(&broken);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(box_uploads_with_counts_bounds_and_contents),
        cmocka_unit_test(extended_layout_interleaves_colours_and_tangents),
        cmocka_unit_test(extended_uv1_layout_carries_the_second_set),
        cmocka_unit_test(broken_mesh_uploads_nothing),
        cmocka_unit_test(line_list_topology_is_kept),
        cmocka_unit_test(failures_leave_no_resources),
        cmocka_unit_test(levels_of_detail_share_the_buffers),
        cmocka_unit_test(bad_levels_are_refused),
    };
    return cmocka_run_group_tests(tests, create_device, destroy_device);
}
