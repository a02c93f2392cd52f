/* test_scene_load.c — ob_scene_load, the library's scene-file loader: a
 * small file arrives as it says (entities, materials, lights, camera,
 * particles, settings) and renders; a missing model is reported with the
 * file and the entity and the rest renders; a malformed file gives the file
 * and the JSON path and leaves the scene untouched; a generator's "lods"
 * gives its geometry that many coarser levels; and a failure at any
 * allocation or Vulkan creation during a load leaves nothing in the scene
 * and nothing leaked. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"

#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "ob_scene_load.h"

#define DATA OB_SOURCE_DIR "/tests/data/scenes/"
#define W 64u
#define H 48u
#define DEG (3.14159265358979323846 / 180.0)

static ob_stack *make_stack(const ob_scene_file_settings *settings)
{
    ob_stack_desc d = {.renderer = {.device = {.app_name = "obelisk-test-scene-load", .validation = 1},
                                    .worker_count = 2},
                       .width = W, .height = H, .env_map_size = 16, .shadow_map_size = 64,
                       .clear_color = {0.0f, 0.0f, 1.0f, 1.0f}};
    if (settings) ob_scene_load_stack_desc(settings, &d);
    ob_result r;
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    return s;
}

/* Two frames, then the final image (malloc'd, RGBA8). */
static uint8_t *render_rgba(ob_stack *s)
{
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    uint8_t *px = malloc((size_t)W * H * 4);   /* test-side image */
    assert_non_null(px);
    assert_int_equal(ob_image_read_rgba8(s->device, ob_stack_final_image(s), px), OB_OK);
    return px;
}

/* Two frames, then the share of the final image's pixels that are not the
 * clear colour (opaque blue). */
static double rendered_share(ob_stack *s)
{
    uint8_t *px = render_rgba(s);
    uint32_t drawn = 0;
    for (uint32_t i = 0; i < W * H; i++) {
        const uint8_t *p = px + (size_t)i * 4;
        if (!(p[0] < 8 && p[1] < 8 && p[2] > 247)) drawn++;
    }
    free(px);
    return (double)drawn / (W * H);
}

static ob_material *material_of(ob_node *n)
{
    const ob_renderable *rd = ob_node_get_renderable(n);
    assert_non_null(rd);
    return rd->material;
}

/* The renderable entities in n's subtree (n included), and the first. */
static uint32_t renderables_below(ob_node *n, ob_node **out_first)
{
    uint32_t count = 0;
    if (ob_node_is_renderable(n)) {
        if (out_first && !*out_first) *out_first = n;
        count++;
    }
    for (ob_node *c = ob_node_first_child(n); c; c = ob_node_next_sibling(c))
        count += renderables_below(c, out_first);
    return count;
}

static uint32_t nodes_below(ob_node *n)
{
    uint32_t count = 0;
    for (ob_node *c = ob_node_first_child(n); c; c = ob_node_next_sibling(c)) count += 1 + nodes_below(c);
    return count;
}

static void test_load_small_scene(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(ob_scene_file_load(DATA "load_small.json", &sf, &err), OB_OK);

    /* Settings: what shapes the set-up goes into the stack's desc. */
    ob_stack_desc sd = {0};
    ob_scene_load_stack_desc(&sf.settings, &sd);
    assert_int_equal(sd.renderer.threading, OB_THREADING_MULTI);
    assert_int_equal(sd.renderer.worker_count, 1);
    assert_int_equal(sd.env_map_size, 16);
    assert_int_equal(sd.shadow_map_size, 64);
    assert_true(sd.clear_color[0] == 0.0f && sd.clear_color[2] == 1.0f && sd.clear_color[3] == 1.0f);
    assert_int_equal(sd.width, 0);   /* the file gives no size: left as it was */

    ob_stack *s = make_stack(&sf.settings);
    uint32_t nodes_before = ob_scene_node_count(s->scene);
    ob_scene_loaded l;
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.file = &sf, .seed = 7}, &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    assert_string_equal(err.message, "");
    assert_int_equal(ob_renderer_get_threading(s->renderer), OB_THREADING_MULTI);

    /* Entities in the file's order, with their parents. */
    static const char *const names[] = {"floor", "crate", "ball", "pyramid", "crate-twin"};
    assert_int_equal(l.entity_count, 5);
    for (uint32_t i = 0; i < 5; i++) {
        assert_string_equal(ob_node_name(l.entities[i]), names[i]);
        assert_true(ob_node_is_renderable(l.entities[i]) == (i != 3));   /* 3: a model's root */
    }
    /* The pyramid OBJ keeps its structure: assimp's root node and the
     * "defaultobject" group, which places the one primitive. */
    ob_node *model_root = ob_node_first_child(l.entities[3]);
    assert_string_equal(ob_node_name(model_root), "load_pyramid.obj");
    assert_string_equal(ob_node_name(ob_node_first_child(model_root)), "defaultobject");
    ob_node *pyramid_draw = NULL;
    assert_int_equal(renderables_below(l.entities[3], &pyramid_draw), 1);
    assert_int_equal(l.model_entity_count, 3);
    assert_ptr_equal(ob_node_get_parent(l.entities[3]), l.entities[1]);
    assert_ptr_equal(ob_node_get_parent(l.entities[1]), ob_scene_root(s->scene));
    double p[3];
    ob_node_get_position(l.entities[2], p);
    assert_near(p[0], 1.5, 1e-12);
    assert_near(p[1], 0.5, 1e-12);
    assert_int_equal(l.left_out_count, 0);

    /* Materials: the file's two, the pyramid's inline one, then "default". */
    assert_int_equal(l.material_count, 4);
    assert_string_equal(ob_material_name(l.materials[0]), "red");
    assert_string_equal(ob_material_name(l.materials[1]), "mirror");
    assert_string_equal(ob_material_name(l.materials[2]), "entities[3].material");
    assert_string_equal(ob_material_name(l.materials[3]), "default");
    assert_int_equal(ob_material_get_kind(l.materials[1]), OB_MATERIAL_REFLECTIVE);
    assert_ptr_equal(material_of(l.entities[0]), l.materials[3]);
    assert_ptr_equal(material_of(l.entities[1]), l.materials[0]);
    assert_ptr_equal(material_of(l.entities[2]), l.materials[1]);
    assert_ptr_equal(material_of(pyramid_draw), l.materials[2]);   /* the entity's material overrides */
    assert_ptr_equal(material_of(l.entities[4]), l.materials[0]);

    /* Geometry: plane, box (shared by the two crates), sphere; the model's own. */
    assert_int_equal(l.geometry_count, 3);
    assert_int_equal(l.model_count, 1);
    assert_int_equal(ob_model_assets_geometry_count(l.models[0]), 1);
    assert_ptr_equal(ob_node_get_renderable(l.entities[1])->geometry, ob_node_get_renderable(l.entities[4])->geometry);
    const ob_bounds *pyramid = ob_geometry_bounds(ob_node_get_renderable(pyramid_draw)->geometry);
    assert_near(pyramid->max[1] - pyramid->min[1], 1.0, 1e-6);

    /* Lights as the file says. */
    assert_int_equal(l.light_count, 2);
    assert_string_equal(ob_node_name(l.lights[0]), "sun");
    const ob_light_desc *sun = ob_node_get_light(l.lights[0]);
    assert_non_null(sun);
    assert_int_equal(sun->type, OB_LIGHT_DIRECTIONAL);
    assert_true(sun->casts_shadows);
    const ob_light_desc *lamp = ob_node_get_light(l.lights[1]);
    assert_non_null(lamp);
    assert_int_equal(lamp->type, OB_LIGHT_POINT);
    assert_near(lamp->intensity, 2.0, 1e-6);
    assert_near(lamp->range, 8.0, 1e-6);
    assert_near(lamp->color[2], 1.0, 1e-6);
    ob_node_get_position(l.lights[1], p);
    assert_near(p[1], 2.0, 1e-12);

    /* The camera: the stack's own node, placed as the file says. */
    assert_ptr_equal(l.camera, s->camera);
    assert_false(l.camera_created);
    assert_false(l.framed);
    const ob_camera_desc *cam = ob_node_get_camera(s->camera);
    assert_non_null(cam);
    assert_near(cam->fovy, 50.0 * DEG, 1e-6);
    assert_near(cam->znear, 0.05, 1e-6);
    ob_node_get_position(s->camera, p);
    assert_near(p[2], 6.0, 1e-12);

    /* Particles under their entity; bounds around the floor. */
    assert_int_equal(l.particle_count, 1);
    assert_ptr_equal(ob_node_get_parent(ob_particle_system_node(l.particles[0])), l.entities[2]);
    assert_true(l.has_bounds);
    assert_true(l.min[0] <= -4.0 && l.max[0] >= 4.0 && l.radius >= 4.0);

    double share = rendered_share(s);
    assert_true(share > 0.3);
    assert_true(ob_renderer_last_stats(s->renderer)->draws >= 5);
    ob_test_assert_no_validation(s->device);

    ob_scene_unload(&l);
    assert_int_equal(ob_scene_node_count(s->scene), nodes_before);
    assert_null(l.entities);
    ob_scene_unload(&l);   /* zeroed: a no-op */
    ob_scene_unload(NULL);
    ob_stack_destroy(s);
    ob_scene_file_release(&sf);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
}

static void test_load_missing_model(void **state)
{
    (void)state;
    ob_stack *s = make_stack(NULL);
    ob_scene_loaded l;
    ob_scene_file_error err;
    ob_test_log_clear();
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = DATA "missing_model.json"}, &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);

    /* Reported with the file and the entity, and listed. */
    assert_true(ob_test_log_has(DATA "missing_model.json: entities[2] 'ghost': model '", "no-such-model.obj",
                                "did not load", NULL));
    assert_true(ob_test_log_has("missing_model.json: entities[4] 'ghost-twin': model", NULL));
    assert_true(ob_test_log_has("missing_model.json: entities[5] 'infinite-box': model", NULL));
    assert_int_equal(l.left_out_count, 3);
    assert_int_equal(l.left_out[0].entity, 2);
    assert_int_equal(l.left_out[0].result, OB_ERR_IO);
    assert_int_equal(l.left_out[1].entity, 4);
    assert_int_equal(l.left_out[2].entity, 5);

    /* The rest is there: the missing model's node stays for its child. */
    assert_int_equal(l.entity_count, 6);
    assert_false(ob_node_is_renderable(l.entities[2]));
    assert_true(ob_node_is_renderable(l.entities[3]));
    assert_ptr_equal(ob_node_get_parent(l.entities[3]), l.entities[2]);
    assert_int_equal(l.geometry_count, 3);   /* plane, box, sphere */
    assert_int_equal(l.model_count, 2);      /* the two files, both failed */
    assert_null(l.models[0]);
    assert_null(l.models[1]);
    assert_int_equal(l.model_entity_count, 0);
    assert_int_equal(l.light_count, 1);      /* no "lights": the default sun */
    assert_string_equal(ob_node_name(l.lights[0]), "sun");

    /* And it renders: the floor, the box and the sphere cover much of it. */
    assert_true(rendered_share(s) > 0.2);
    ob_test_assert_no_validation(s->device);
    ob_scene_unload(&l);
    ob_stack_destroy(s);
}

/* A glTF model in a scene keeps its hierarchy: the entity is the model's
 * root, with one entity per glTF node (assimp's ROOT above the file's two
 * scene roots) and one per placed primitive, each with the model's own
 * material, shared where primitives share one; the mirrored node's quad
 * faces the camera like its twin; and it renders, identically whether one
 * thread or several record. */
static void test_load_gltf_hierarchy(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    ob_stack *s = make_stack(NULL);
    uint32_t nodes_before = ob_scene_node_count(s->scene);
    ob_scene_loaded l;
    ob_scene_file_error err;
    /* The scene reaches its models through "../models/": outside its own
     * folder, so allowed explicitly (trusted test content; issue 26 point 6). */
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = DATA "load_gltf.json",
                                                               .allow_any_folder = true},
                                      &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    assert_int_equal(l.left_out_count, 0);
    assert_int_equal(l.entity_count, 4);
    assert_int_equal(l.model_count, 2);   /* each file opened once for its two entities */
    ob_node *features = l.entities[0];
    /* features.gltf: 5 nodes (ROOT, parent, child, grandchild, sibling);
     * child and grandchild place the 2-primitive quad mesh, sibling the
     * triangle: 5 primitive entities. */
    assert_int_equal(nodes_below(features), 10);
    assert_int_equal(renderables_below(features, NULL), 5);
    ob_node *root = ob_node_first_child(features);
    assert_string_equal(ob_node_name(root), "ROOT");
    ob_node *parent = ob_node_first_child(root);
    assert_string_equal(ob_node_name(parent), "parent");
    double p[3];
    ob_node_get_position(parent, p);
    assert_near(p[0], 1.0, 1e-6);
    assert_near(p[2], 3.0, 1e-6);
    ob_node *child = ob_node_first_child(parent);
    assert_string_equal(ob_node_name(child), "child");
    ob_node *quad0 = ob_node_first_child(child);   /* the child's primitives come first */
    assert_string_equal(ob_node_name(quad0), "quad-0");
    ob_node *quad1 = ob_node_next_sibling(quad0);
    assert_string_equal(ob_node_name(quad1), "quad-1");
    /* Materials: one per model material that a primitive uses, shared by
     * both placements of the quad; the blended one is blended. */
    ob_material *masked = material_of(quad0);
    assert_string_equal(ob_material_name(masked), "features.gltf/masked");
    assert_string_equal(ob_material_name(material_of(quad1)), "features.gltf/blended");
    const ob_model *fm = ob_model_assets_model(l.models[0]);
    for (uint32_t i = 0; i < fm->material_count; i++)   /* only "masked" (quad-0) has COLOR_0 */
        assert_int_equal(ob_model_material_has_vertex_colors(fm, i),
                         strcmp(fm->materials[i].name, "masked") == 0);
    ob_node *grand = ob_node_next_sibling(quad1);
    assert_string_equal(ob_node_name(grand), "grandchild");
    assert_ptr_equal(material_of(ob_node_first_child(grand)), masked);
    assert_ptr_equal(ob_node_get_renderable(ob_node_first_child(grand))->geometry,
                     ob_node_get_renderable(quad0)->geometry);
    /* The second entity naming the file draws the same geometry. */
    ob_node *again = ob_node_first_child(ob_node_first_child(ob_node_first_child(ob_node_first_child(l.entities[2]))));
    assert_string_equal(ob_node_name(again), "quad-0");
    assert_ptr_equal(ob_node_get_renderable(again)->geometry, ob_node_get_renderable(quad0)->geometry);
    /* mirror.gltf: ROOT, left, right and a quad under each: 5; twice each file. */
    assert_int_equal(nodes_below(l.entities[1]), 5);
    assert_int_equal(l.model_entity_count, 2 * (10 + 5));

    /* It renders, and one thread records what several do, byte for byte. */
    ob_renderer_set_threading(s->renderer, OB_THREADING_SINGLE, 0);
    uint8_t *st = render_rgba(s);
    ob_renderer_set_threading(s->renderer, OB_THREADING_MULTI, 0);
    uint8_t *mt = render_rgba(s);
    assert_memory_equal(st, mt, (size_t)W * H * 4);
    uint32_t drawn = 0;
    for (uint32_t i = 0; i < W * H; i++) drawn += !(st[4 * i] < 8 && st[4 * i + 1] < 8 && st[4 * i + 2] > 247);
    assert_true(drawn > W * H / 20);
    /* The red quads at (±1.5, -1, 0), seen from (0, 0, 8) with 50° fov:
     * pixels (22, 30) and (41, 30) of 64x48. The mirrored one (left) is not
     * culled as a back face. */
    const uint32_t at[2] = {30 * W + 22, 30 * W + 41};
    for (int k = 0; k < 2; k++) {
        const uint8_t *px = &st[4 * at[k]];
        if (!(px[0] > 64 && px[2] < 64))
            fail_msg("%s quad: pixel (%u, 30) is %u %u %u, not red", k ? "right" : "mirrored left",
                     at[k] % W, px[0], px[1], px[2]);
    }
    free(st);
    free(mt);
    ob_test_assert_no_validation(s->device);
    ob_scene_unload(&l);
    assert_int_equal(ob_scene_node_count(s->scene), nodes_before);
    ob_stack_destroy(s);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
}

static void test_load_frames_without_camera(void **state)
{
    (void)state;
    ob_stack *s = make_stack(NULL);
    ob_scene_loaded l;
    ob_scene_file_error err;
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = DATA "load_framed.json"}, &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    assert_null(l.camera);
    assert_true(l.framed);
    assert_true(l.has_bounds);
    assert_near(l.center[0], 10.0, 1e-6);
    /* Framed: the camera looks at the box from outside its sphere. */
    double eye[3];
    ob_node_get_position(s->camera, eye);
    double dx = eye[0] - l.center[0], dy = eye[1] - l.center[1], dz = eye[2] - l.center[2];
    assert_true(sqrt(dx * dx + dy * dy + dz * dz) > l.radius);
    assert_true(rendered_share(s) > 0.05);
    ob_test_assert_no_validation(s->device);
    ob_scene_unload(&l);
    ob_stack_destroy(s);
}

static void test_load_malformed_leaves_scene(void **state)
{
    (void)state;
    ob_stack *s = make_stack(NULL);
    uint32_t nodes_before = ob_scene_node_count(s->scene);
    ob_scene_loaded l;
    ob_scene_file_error err;
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = DATA "bad_light_type.json"}, &l, &err);
    assert_int_equal(r, OB_ERR_PARSE);
    assert_string_equal(err.json_path, "lights[1].type");
    assert_string_equal(err.message, DATA "bad_light_type.json: lights[1].type: missing "
                                     "(expected \"directional\", \"point\" or \"spot\")");
    assert_int_equal(ob_scene_node_count(s->scene), nodes_before);
    assert_int_equal(l.entity_count, 0);
    assert_null(l.materials);

    r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = DATA "no-such-scene.json"}, &l, &err);
    assert_int_equal(r, OB_ERR_IO);
    assert_non_null(strstr(err.message, "no-such-scene.json: cannot open"));
    assert_int_equal(ob_scene_node_count(s->scene), nodes_before);

    /* A missing argument is named, and nothing happens. */
    ob_scene_load_target t = {.renderer = s->renderer, .materials = s->materials, .scene = s->scene};
    r = ob_scene_load(&t, &(ob_scene_load_desc){.path = DATA "load_small.json"}, &l, &err);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err.message, "load_small.json: ob_scene_load: no target.views"));
    assert_int_equal(ob_scene_node_count(s->scene), nodes_before);
    ob_stack_destroy(s);
}

/* "lods" on a generator: the geometry carries that many coarser levels,
 * fewer where the segments reach their minimum (a cone of 8 slices: 5,
 * then 3); the same generator with other lods is another geometry; the
 * frame renders. */
/* A loaded scene renders a frame; then it, the stack and the scene file
 * written for the test (path, in its own folder dir) go. */
static void render_and_clean_up(ob_stack *s, ob_scene_loaded *l, const char *path, const char *dir)
{
    uint8_t *rgba = render_rgba(s);
    assert_non_null(rgba);
    free(rgba);
    ob_renderer_wait_idle(s->renderer);
    ob_scene_unload(l);
    ob_stack_destroy(s);
    remove(path);
    rmdir(dir);
}

static void test_load_generator_lods(void **state)
{
    (void)state;
    static const char text[] =
        "{\"camera\": {\"position\": [0, 1, 6], \"target\": [0, 0, 0]},\n"
        " \"entities\": [\n"
        "  {\"name\": \"ball\", \"geometry\": {\"generator\": \"sphere\", \"lods\": 3}},\n"
        "  {\"name\": \"plain\", \"geometry\": {\"generator\": \"sphere\"},\n"
        "   \"transform\": {\"position\": [1.5, 0, 0]}},\n"
        "  {\"name\": \"cone\", \"geometry\": {\"generator\": \"cone\", \"slices\": 8, \"lods\": 7},\n"
        "   \"transform\": {\"position\": [-1.5, 0, 0]}},\n"
        "  {\"name\": \"ring\", \"geometry\": {\"generator\": \"torus\", \"lods\": 2},\n"
        "   \"transform\": {\"position\": [0, 1.5, 0]}}]}\n";
    char dir[] = "/tmp/ob-test-lods-XXXXXX", path[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/lods.json", dir);
    assert_int_equal(ob_file_write(path, text, sizeof text - 1), OB_OK);
    ob_stack *s = make_stack(NULL);
    ob_scene_loaded l;
    ob_scene_file_error err;
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = path}, &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    assert_int_equal(l.geometry_count, 4);
    static const uint32_t levels[] = {4, 1, 3, 3};
    for (uint32_t i = 0; i < 4; i++) {
        const ob_renderable *rd = ob_node_get_renderable(l.entities[i]);
        const ob_geometry *g = rd->geometry;
        if (ob_geometry_lod_count(g) != levels[i])
            fail_msg("%s: %u levels, expected %u", ob_node_name(l.entities[i]),
                     ob_geometry_lod_count(g), levels[i]);
        for (uint32_t k = 1; k < levels[i]; k++) {
            assert_true(ob_geometry_lod_error(g, k) > 0.0f);
            assert_true(ob_geometry_lod_error(g, k) >= ob_geometry_lod_error(g, k - 1));
            assert_true(ob_geometry_lod_index_count(g, k) < ob_geometry_lod_index_count(g, k - 1));
        }
    }
    render_and_clean_up(s, &l, path, dir);
}

/* "lods" on a model: each primitive gets coarser levels made by
 * ob_mesh_simplify (Debian's Wuson OBJ, skipped saying so without
 * assimp-testmodels); the same model without them is another geometry,
 * drawn at level 0; both render. */
static void test_load_model_lods(void **state)
{
    (void)state;
    const char *model = "/usr/share/assimp/models/OBJ/WusonOBJ.obj";
    if (access(model, R_OK) != 0) {
        print_message("SKIP: %s is missing (install Debian's assimp-testmodels)\n", model);
        return;
    }
    char text[512];
    snprintf(text, sizeof text,
             "{\"camera\": {\"position\": [0, 1, 6], \"target\": [0, 0, 0]},\n"
             " \"entities\": [\n"
             "  {\"name\": \"far\", \"geometry\": {\"model\": \"%s\", \"lods\": 3}},\n"
             "  {\"name\": \"near\", \"geometry\": {\"model\": \"%s\"},\n"
             "   \"transform\": {\"position\": [2, 0, 0]}}]}\n", model, model);
    char dir[] = "/tmp/ob-test-model-lods-XXXXXX", path[64];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/lods.json", dir);
    assert_int_equal(ob_file_write(path, text, strlen(text)), OB_OK);
    ob_stack *s = make_stack(NULL);
    ob_scene_loaded l;
    ob_scene_file_error err;
    ob_result r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = path}, &l, &err);
    if (r != OB_OK) fail_msg("load failed: %s", err.message);
    assert_int_equal(l.model_count, 2);   /* one file, asked for with and without levels */
    ob_node *far = NULL, *near = NULL;
    assert_int_equal(renderables_below(l.entities[0], &far), 1);
    assert_int_equal(renderables_below(l.entities[1], &near), 1);
    const ob_geometry *g = ob_node_get_renderable(far)->geometry;
    assert_int_equal(ob_geometry_lod_count(g), 4);
    for (uint32_t k = 1; k < 4; k++) {
        assert_true(ob_geometry_lod_error(g, k) > 0.0f);
        assert_true(ob_geometry_lod_error(g, k) >= ob_geometry_lod_error(g, k - 1));
        print_message("level %u: %u indices, error %g\n", k, ob_geometry_lod_index_count(g, k),
                      (double)ob_geometry_lod_error(g, k));
        assert_true(ob_geometry_lod_index_count(g, k) * 10 <= ob_geometry_lod_index_count(g, k - 1) * 9);
    }
    assert_int_equal(ob_geometry_lod_count(ob_node_get_renderable(near)->geometry), 1);
    render_and_clean_up(s, &l, path, dir);
}

/* Every fault point of one kind during a load in turn: a load that fails
 * says so with the file, leaves the scene's node count and its camera as
 * they were, and the next load (unarmed) still renders. A fault inside the
 * model loader is a model that did not load: the load then succeeds with
 * the pyramid left out. */
static void walk_load_faults(ob_fault_kind kind)
{
    ob_test_skip_under_tsan("a load runs on the calling thread alone");
    ob_heap_stats before = ob_heap_stats_now();
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(ob_scene_file_load(DATA "load_small.json", &sf, &err), OB_OK);
    ob_stack *s = make_stack(&sf.settings);
    uint32_t nodes_before = ob_scene_node_count(s->scene);
    ob_node_set_position(s->camera, (const double[3]){1.0, 2.0, 3.0});
    ob_scene_load_desc desc = {.file = &sf};
    ob_scene_loaded l;

    ob_fault_arm(kind, 0);   /* unarmed: counts the points */
    assert_int_equal(ob_scene_load_stack(s, &desc, &l, &err), OB_OK);
    uint64_t points = ob_fault_count(kind);
    ob_scene_unload(&l);
    ob_node_set_position(s->camera, (const double[3]){1.0, 2.0, 3.0});
    assert_true(points > 0);
    ob_test_log_set_echo(false);
    uint32_t failed = 0;
    for (uint64_t n = 1; n <= points; n++) {
        ob_fault_arm(kind, n);
        ob_result r = ob_scene_load_stack(s, &desc, &l, &err);
        bool hit = ob_fault_hit(kind);
        ob_fault_arm(kind, 0);
        if (r == OB_OK) {
            ob_scene_unload(&l);
            ob_node_set_position(s->camera, (const double[3]){1.0, 2.0, 3.0});
            continue;
        }
        failed++;
        if (!hit) fail_msg("fault %llu: the load failed with no fault: %s", (unsigned long long)n, err.message);
        if (!strstr(err.message, "load_small.json: "))
            fail_msg("fault %llu: the error does not name the file: %s", (unsigned long long)n, err.message);
        if (ob_scene_node_count(s->scene) != nodes_before)
            fail_msg("fault %llu (%s): %u nodes left behind", (unsigned long long)n, err.message,
                     ob_scene_node_count(s->scene) - nodes_before);
        double p[3];
        ob_node_get_position(s->camera, p);
        if (p[0] != 1.0 || p[1] != 2.0 || p[2] != 3.0)
            fail_msg("fault %llu (%s): the camera moved", (unsigned long long)n, err.message);
        if (l.entities || l.geometry || l.materials)
            fail_msg("fault %llu: *out is not empty after a failure", (unsigned long long)n);
    }
    ob_test_log_set_echo(true);
    print_message("%llu fault points, %u loads failed cleanly\n", (unsigned long long)points, failed);
    assert_true(failed > 0);

    assert_int_equal(ob_scene_load_stack(s, &desc, &l, &err), OB_OK);
    assert_int_equal(l.left_out_count, 0);
    assert_true(rendered_share(s) > 0.3);
    ob_test_assert_no_validation(s->device);
    ob_scene_unload(&l);
    ob_stack_destroy(s);
    ob_scene_file_release(&sf);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
}

static void test_load_host_faults(void **state)
{
    (void)state;
    walk_load_faults(OB_FAULT_HOST_ALLOC);
}

static void test_load_vk_faults(void **state)
{
    (void)state;
    walk_load_faults(OB_FAULT_VK_OBJECT);
}

int main(void)
{
    ob_test_setup_log();
    /* The fault walks reach cJSON's allocations too (the program's choice:
     * cJSON's hooks are process-wide). */
    ob_scene_file_hook_cjson();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_small_scene),
        cmocka_unit_test(test_load_missing_model),
        cmocka_unit_test(test_load_gltf_hierarchy),
        cmocka_unit_test(test_load_frames_without_camera),
        cmocka_unit_test(test_load_malformed_leaves_scene),
        cmocka_unit_test(test_load_generator_lods),
        cmocka_unit_test(test_load_model_lods),
        cmocka_unit_test(test_load_host_faults),
        cmocka_unit_test(test_load_vk_faults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
