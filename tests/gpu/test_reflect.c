/* Reflections (issue 28): environment maps keep HDR values, clear to the
 * scene's sky (the main view's clear colour unless set), blur with
 * roughness through their mip chain, and come as dual paraboloids or cube
 * maps that show the same surroundings; cube maps record the same in ST and
 * MT and are left out when their owner is not seen. (The fault walks of
 * the cube view are in test_faults.c.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_test_world.h"

/* The camera at (0, 0, cam_z) looks at the origin: fovy 1, 160 x 120. */
#define W 160
#define H 120

static const ob_env_map_kind kinds[2] = {OB_ENV_MAP_PARABOLOID, OB_ENV_MAP_CUBE};
static const char *const kind_names[2] = {"paraboloid", "cube"};

static ob_material *mirror(ob_test_world *w)
{
    ob_result r;
    ob_material_desc d = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .reflectivity = 1.0f,
                          .diffuse = {0, 0, 0, 1}, .specular = {0, 0, 0, 1}};
    ob_material *m = ob_material_create(w->lib, &d, &r);
    if (!m) fail_msg("mirror material: %s", ob_result_name(r));
    return m;
}

static ob_material *metal(ob_test_world *w, const char *name, float roughness)
{
    ob_result r;
    ob_material_desc d = {.name = name, .kind = OB_MATERIAL_PBR, .reflectivity = 1.0f};
    d.pbr = ob_material_pbr_defaults();
    d.pbr.metallic = 1.0f;
    d.pbr.roughness = roughness;
    ob_material *m = ob_material_create(w->lib, &d, &r);
    if (!m) fail_msg("metal material: %s", ob_result_name(r));
    return m;
}

/* A sphere of radius 0.5 in the extended vertex layout (vertex colours,
 * white), which the PBR material's shaders read. */
static ob_geometry *pbr_sphere(ob_test_world *w)
{
    ob_mesh m;
    assert_int_equal(ob_mesh_sphere(0.5f, 48, 32, &m), OB_OK);
    m.colors = ob_calloc(m.vertex_count, sizeof *m.colors);
    assert_non_null(m.colors);
    memset(m.colors, 255, (size_t)m.vertex_count * sizeof *m.colors);
    ob_geometry *g = ob_world_geometry(w, &m, "pbr sphere");
    ob_mesh_release(&m);
    return g;
}

/* OB_REFLECT_DUMP=prefix writes the final images as PNG (debugging). */
static void dump(ob_test_world *w, const char *what, int k)
{
    const char *prefix = getenv("OB_REFLECT_DUMP");
    if (!prefix) return;
    char path[512];
    snprintf(path, sizeof path, "%s-%s-%s.png", prefix, what, kind_names[k]);
    ob_image_write_png(w->dev, ob_composite_view_target(w->composite), path);
}

/* Pixel of world point (x, y, 0) seen from (0, 0, cam_z). */
static void project(double x, double y, double cam_z, int *px, int *py)
{
    double t = tan(0.5);
    *px = (int)lround(W / 2.0 + x / cam_z / (t * W / H) * (W / 2.0));
    *py = (int)lround(H / 2.0 - y / cam_z / t * (H / 2.0));
}

/* A wall of boxes behind the camera in a red / blue checker, lit by a sun
 * from beyond the spheres (so its own highlight stays off the spheres'
 * centres): what the spheres reflect. */
static void checker_wall(ob_test_world *w)
{
    ob_material *red = ob_world_material(w, "red", OB_MATERIAL_LIT, 0.9f, 0.1f, 0.1f, false);
    ob_material *blue = ob_world_material(w, "blue", OB_MATERIAL_LIT, 0.1f, 0.2f, 0.9f, false);
    for (int i = -5; i <= 5; i++)
        for (int j = -5; j <= 5; j++)
            ob_world_entity(w, NULL, "tile", w->box, ((i + j) & 1) ? red : blue, i, j, 6.0);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 1, 2, -8);
}

/* Sum of absolute differences of neighbouring pixels (RGB) within radius r
 * of (cx, cy), per pixel: how much detail a reflection shows. */
static double local_contrast(const uint8_t *img, int cx, int cy, int r)
{
    double sum = 0;
    int n = 0;
    for (int y = cy - r; y < cy + r; y++)
        for (int x = cx - r; x < cx + r; x++) {
            if ((x - cx) * (x - cx) + (y - cy) * (y - cy) > r * r) continue;
            const uint8_t *p = img + 4 * ((size_t)y * W + x);
            for (int c = 0; c < 3; c++) sum += abs((int)p[c] - (int)p[4 + c]) + abs((int)p[c] - (int)p[4 * W + c]);
            n++;
        }
    return n ? sum / n : 0;
}

/* A sky above 1 reaches the mirror unclipped: exposed by 1/8 without the
 * tone map, a sky of 4 reflects as 0.5, where an 8-bit map would give at
 * most 1/8. */
static void hdr_sky_survives_in_the_reflection(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = kinds[k]});
        ob_world_look(&w, 0, 0, 1.6, 0, 0, 0);
        ob_world_entity(&w, NULL, "mirror", w.sphere, mirror(&w), 0, 0, 0);
        ob_views_set_sky_color(w.views, (const float[4]){4.0f, 4.0f, 4.0f, 1.0f});
        assert_true(ob_composite_view_set_exposure(w.composite, 0.125f));
        ob_composite_view_set_tonemap(w.composite, false);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
        const uint8_t *centre = ob_world_pixel(&w, W / 2, H / 2);
        uint8_t want = ob_composite_view_output_level(w.composite, 4.0f);
        uint8_t clipped = ob_composite_view_output_level(w.composite, 1.0f);
        print_message("%s: mirror centre %u %u %u, HDR sky gives %u, a clipped map %u\n",
                      kind_names[k], centre[0], centre[1], centre[2], want, clipped);
        for (int c = 0; c < 3; c++) assert_in_range(centre[c], want - 3, want + 3);
        ob_test_world_destroy(&w);
    }
}

/* With no sky colour set, a mirror shows the scene's clear colour (the main
 * view's), not a colour of its own. */
static void reflection_clears_to_the_scene_clear_colour(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = kinds[k],
                                                       .clear_color = {0.05f, 0.3f, 0.1f, 1.0f}});
        ob_world_look(&w, 0, 0, 1.6, 0, 0, 0);
        ob_world_entity(&w, NULL, "mirror", w.sphere, mirror(&w), 0, 0, 0);
        const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        assert_int_equal(ob_world_count_views(st, kinds[k] == OB_ENV_MAP_CUBE ? OB_VIEW_CUBE
                                                                              : OB_VIEW_PARABOLOID), 1);
        ob_world_read(&w);
        const uint8_t *centre = ob_world_pixel(&w, W / 2, H / 2);
        const uint8_t *corner = ob_world_pixel(&w, 2, 2);
        print_message("%s: mirror centre %u %u %u, background %u %u %u\n", kind_names[k], centre[0],
                      centre[1], centre[2], corner[0], corner[1], corner[2]);
        for (int c = 0; c < 3; c++) assert_in_range(centre[c], corner[c] - 2, corner[c] + 2);
        ob_test_world_destroy(&w);
    }
}

/* A rough metal reflects its surroundings blurred (a coarser mip level),
 * a smooth one sharp: the rough sphere's image has far less local contrast. */
static void rough_metal_reflects_blurred(void **state)
{
    (void)state;
    for (int k = 0; k < 2; k++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = kinds[k], .width = W, .height = H});
        ob_world_look(&w, 0, 0, 3, 0, 0, 0);
        checker_wall(&w);
        ob_geometry *ball = pbr_sphere(&w);
        ob_world_entity(&w, NULL, "smooth", ball, metal(&w, "smooth", 0.05f), -0.7, 0, 0);
        ob_world_entity(&w, NULL, "rough", ball, metal(&w, "rough", 0.7f), 0.7, 0, 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        const uint8_t *img = ob_world_read(&w);
        dump(&w, "rough", k);
        int sx, sy, rx, ry;
        project(-0.7, 0, 3, &sx, &sy);
        project(0.7, 0, 3, &rx, &ry);
        double smooth = local_contrast(img, sx, sy, 9), rough = local_contrast(img, rx, ry, 9);
        print_message("%s: local contrast smooth %.1f, rough %.1f\n", kind_names[k], smooth, rough);
        assert_true(smooth > 20.0);
        assert_true(rough < 0.4 * smooth);
        ob_test_world_destroy(&w);
    }
}

/* The cube map and the paraboloid show the same surroundings: the mirror's
 * pixels agree on average within a few levels (they differ in sampling:
 * the paraboloid's resolution varies over the sphere), and nothing else in
 * the image depends on the kind. */
static void cube_matches_paraboloid(void **state)
{
    (void)state;
    uint8_t *img[2];
    for (int k = 0; k < 2; k++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = kinds[k], .env_map_size = 128});
        ob_world_look(&w, 0, 0, 1.6, 0, 0, 0);
        checker_wall(&w);
        ob_material *green = ob_world_material(&w, "green", OB_MATERIAL_LIT, 0.1f, 0.8f, 0.2f, false);
        ob_world_entity(&w, NULL, "left", w.sphere, green, -2.5, 0, 0.5);
        ob_world_entity(&w, NULL, "above", w.box, green, 0, 2.5, -1);
        ob_world_entity(&w, NULL, "mirror", w.sphere, mirror(&w), 0, 0, 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        dump(&w, "cube-vs-paraboloid", k);
        img[k] = ob_world_snapshot(&w);
        assert_non_null(img[k]);
        ob_test_world_destroy(&w);
    }
    int cx, cy, ex, ey;
    project(0, 0, 1.6, &cx, &cy);
    project(0.5, 0, 1.6, &ex, &ey);
    int radius = ex - cx;   /* a little over the sphere's silhouette */
    double inside = 0;
    uint32_t n_inside = 0, outside_diff = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *a = img[0] + 4 * ((size_t)y * W + x), *b = img[1] + 4 * ((size_t)y * W + x);
            bool in = (x - cx) * (x - cx) + (y - cy) * (y - cy) <= (radius + 2) * (radius + 2);
            for (int c = 0; c < 3; c++) {
                if (in) inside += abs((int)a[c] - (int)b[c]);
                else if (a[c] != b[c]) outside_diff++;
            }
            n_inside += in;
        }
    double mean = inside / (3.0 * n_inside);
    print_message("cube vs paraboloid: mean difference %.2f levels over %u mirror pixels, %u channels "
                  "differ elsewhere\n", mean, n_inside, outside_diff);
    assert_int_equal(outside_diff, 0);
    assert_true(mean < 12.0);
    free(img[0]);
    free(img[1]);
}

/* Cube maps record the same commands and pixels single- and
 * multi-threaded, one map per visible mirror and none of the other kind:
 * the same two frames of the same scene in two worlds, compared frame by
 * frame and view by view (as test_determinism does). */
typedef struct cube_run {
    ob_frame_stats stats[2];
    uint8_t *images[2];
} cube_run;

static void cube_scene_frames(ob_threading mode, cube_run *out)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = OB_ENV_MAP_CUBE});
    ob_world_look(&w, 0, 1, 4, 0, 0, 0);
    checker_wall(&w);
    ob_material *m = mirror(&w);
    ob_world_entity(&w, NULL, "m0", w.sphere, m, -1.2, 0, 0);
    ob_world_entity(&w, NULL, "m1", w.sphere, m, 0, 0.3, 0);
    ob_world_entity(&w, NULL, "m2", pbr_sphere(&w), metal(&w, "metal", 0.4f), 1.2, 0, 0);
    for (int f = 0; f < 2; f++) {
        const ob_frame_stats *st = ob_test_world_frame(&w, mode, 0);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_CUBE), 3);
        assert_int_equal(ob_world_count_views(st, OB_VIEW_PARABOLOID), 0);
        out->stats[f] = *st;
        out->images[f] = ob_world_snapshot(&w);
        assert_non_null(out->images[f]);
    }
    ob_test_world_destroy(&w);
}

static void cube_maps_st_equals_mt(void **state)
{
    (void)state;
    cube_run single, multi;
    cube_scene_frames(OB_THREADING_SINGLE, &single);
    cube_scene_frames(OB_THREADING_MULTI, &multi);
    for (int f = 0; f < 2; f++) {
        const ob_frame_stats *a = &single.stats[f], *b = &multi.stats[f];
        assert_int_equal(a->view_count, b->view_count);
        for (uint32_t i = 0; i < a->view_count; i++)
            if (a->views[i].hash.hash != b->views[i].hash.hash)
                fail_msg("frame %d, view '%s': MT hash %016llx (%u draws), ST %016llx (%u draws)", f,
                         a->views[i].name, (unsigned long long)b->views[i].hash.hash,
                         b->views[i].hash.draws, (unsigned long long)a->views[i].hash.hash,
                         a->views[i].hash.draws);
        assert_true(a->frame_hash == b->frame_hash);
        assert_int_equal(ob_rgba_diff_count(single.images[f], multi.images[f], W * H, 0), 0);
        free(single.images[f]);
        free(multi.images[f]);
    }
}

/* A mirror the camera does not see gets no cube map. */
static void cube_left_out_when_owner_unseen(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.env_map_kind = OB_ENV_MAP_CUBE});
    ob_world_look(&w, 0, 0, 4, 0, 0, 0);
    ob_world_entity(&w, NULL, "behind", w.sphere, mirror(&w), 0, 0, 8);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_world_count_views(st, OB_VIEW_CUBE), 0);
    ob_test_world_destroy(&w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hdr_sky_survives_in_the_reflection),
        cmocka_unit_test(reflection_clears_to_the_scene_clear_colour),
        cmocka_unit_test(rough_metal_reflects_blurred),
        cmocka_unit_test(cube_matches_paraboloid),
        cmocka_unit_test(cube_maps_st_equals_mt),
        cmocka_unit_test(cube_left_out_when_owner_unseen),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
