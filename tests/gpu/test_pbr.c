/* test_pbr.c — the glTF metallic-roughness material as a user sees it: the
 * lit side of a sphere is brighter than the unlit side, a smooth metal shows
 * its highlight at the mirror direction, an alpha-MASK quad cuts out (also
 * from the shadow), BLEND quads are composited back to front whatever their
 * creation order, a double-sided quad shows its back face, shadows and
 * environment maps feed the PBR shading, ST and MT recording give the same
 * bytes, and variants compile only the features a material uses.
 *
 * Assertions are on relations a viewer would see (brighter, redder, the
 * background showing through), not on exact values, so they hold whether
 * the final image is the linear target or the tone-mapped sRGB one.
 */
#define _XOPEN_SOURCE 700
#include "ob_test_world.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image_write.h>
unsigned char *stbi_write_png_to_mem(const unsigned char *pixels, int stride_bytes, int x, int y, int n,
                                     int *out_len);

#include "ob_test_adopt.h"
#include "ob_test_stack.h"
#include "ob_texture.h"

/* Geometry in the extended layout: a mesh with vertex colours is uploaded
 * extended (white here unless `tint` is given). */
static ob_geometry *extended(ob_test_world *w, ob_mesh *m, const char *name, const uint8_t *tint)
{
    m->colors = ob_calloc(m->vertex_count, sizeof *m->colors);
    assert_non_null(m->colors);
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        static const uint8_t white[4] = {255, 255, 255, 255};
        memcpy(m->colors[i], tint ? tint : white, 4);
    }
    ob_geometry *g = ob_world_geometry(w, m, name);
    ob_mesh_release(m);
    return g;
}

static ob_geometry *ext_sphere(ob_test_world *w)
{
    ob_mesh m;
    assert_int_equal(ob_mesh_sphere(0.5f, 48, 32, &m), OB_OK);
    return extended(w, &m, "pbr sphere", NULL);
}

static ob_geometry *ext_quad(ob_test_world *w, float size, const char *name)
{
    ob_mesh m;
    assert_int_equal(ob_mesh_plane(size, size, 1, &m), OB_OK);
    return extended(w, &m, name, NULL);
}

static ob_material *pbr(ob_test_world *w, const char *name, const ob_material_pbr *p, bool shadows,
                        float reflectivity)
{
    ob_result r;
    ob_material *m = ob_material_create(w->lib, &(ob_material_desc){
        .name = name, .kind = OB_MATERIAL_PBR, .pbr = *p, .casts_shadows = shadows,
        .reflectivity = reflectivity}, &r);
    if (!m) fail_msg("material '%s': %s", name, ob_result_name(r));
    return m;
}

/* A quad (the XZ plane turned to face +Z, toward a camera on +Z). */
static ob_node *facing_quad(ob_test_world *w, const char *name, ob_geometry *g, ob_material *m, double x, double y,
                            double z, bool away)
{
    ob_node *n = ob_world_entity(w, NULL, name, g, m, x, y, z);
    const float s = sqrtf(0.5f);
    /* +90 degrees about X takes +Y to +Z; -90 turns it away. */
    ob_node_set_rotation(n, (const float[4]){away ? -s : s, 0, 0, s});
    return n;
}

/* OB_PBR_DUMP=dir writes each checked image as <dir>/<name>.png. */
static void dump(const ob_test_world *w, const char *name)
{
    const char *dir = getenv("OB_PBR_DUMP");
    if (!dir) return;
    char path[512];
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    stbi_write_png(path, (int)w->width, (int)w->height, 4, w->pixels, (int)w->width * 4);
}

static float luminance(const uint8_t *p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

static bool same_rgb(const uint8_t *a, const uint8_t *b, int tol)
{
    for (int c = 0; c < 3; c++)
        if (abs((int)a[c] - (int)b[c]) > tol) return false;
    return true;
}

/* ---------------------------------------------------------------- tests */

/* A 160x120 world with one PBR ball at the origin, a sun at (lx, ly, lz)
 * and the camera 2.5 units away on +Z; one frame, read back. */
static void ball_under_sun(ob_test_world *w, const char *name, const ob_material_pbr *p, float intensity, double lx,
                           double ly, double lz, const char *dump_name)
{
    ob_test_world_create(w, &(ob_test_world_desc){.width = 160, .height = 120});
    ob_world_entity(w, NULL, "ball", ext_sphere(w), pbr(w, name, p, false, 0), 0, 0, 0);
    ob_world_light(w, OB_LIGHT_DIRECTIONAL, false, intensity, lx, ly, lz);
    ob_world_look(w, 0, 0, 2.5, 0, 0, 0);
    ob_test_world_frame(w, OB_THREADING_SINGLE, 0);
    ob_world_read(w);
    dump(w, dump_name);
}

/* Light from +X: the right half of the sphere is brighter than the left. */
static void lit_side_is_brighter(void **state)
{
    (void)state;
    ob_material_pbr p = ob_material_pbr_defaults();
    p.base_color[0] = p.base_color[1] = p.base_color[2] = 0.8f;
    p.metallic = 0.0f;
    p.roughness = 0.6f;
    ob_test_world w;
    ball_under_sun(&w, "clay", &p, 2.0f, 5, 0, 0, __func__);
    float right = luminance(ob_world_pixel(&w, 80 + 14, 60));
    float left = luminance(ob_world_pixel(&w, 80 - 14, 60));
    if (!(right > left + 40.0f)) fail_msg("lit side %.0f, unlit side %.0f", right, left);
    ob_test_world_destroy(&w);
}

/* The brightest pixel of the ball of ball_under_sun (its luminance; where
 * it is into *out_x, *out_y). */
static float brightest(const ob_test_world *w, uint32_t *out_x, uint32_t *out_y)
{
    float best = -1.0f;
    *out_x = *out_y = 0;
    for (uint32_t y = 30; y < 90; y++)
        for (uint32_t x = 50; x < 110; x++) {
            float l = luminance(ob_world_pixel(w, x, y));
            if (l > best) best = l, *out_x = x, *out_y = y;
        }
    return best;
}

/* Where a mirror-like lobe of ball_under_sun's ball peaks for a sun at
 * (5, 5, 5): the half vector of l = (1,1,1)/sqrt3 and v = +Z, seen on a
 * sphere of radius ~23 pixels at (80, 60): about 9 pixels right and up. */
static void mirror_point(float *out_x, float *out_y)
{
    float h[3] = {0.57735f, 0.57735f, 1.57735f};
    float hl = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    float radius_px = 0.5f / tanf(0.5f) / 2.5f * 60.0f;
    *out_x = 80.0f + radius_px * h[0] / hl;
    *out_y = 60.0f - radius_px * h[1] / hl;
}

/* A smooth white metal lit from the upper right: the brightest pixel of the
 * sphere sits where the normal is the half vector between the light and the
 * eye (up and to the right of the centre), and it is much brighter than the
 * rest of the (dark: no diffuse) metal. */
static void smooth_metal_highlight_at_mirror_direction(void **state)
{
    (void)state;
    ob_material_pbr p = ob_material_pbr_defaults();
    p.metallic = 1.0f;
    p.roughness = 0.05f;
    ob_test_world w;
    ball_under_sun(&w, "chrome", &p, 3.0f, 5, 5, 5, __func__);
    uint32_t bx, by;
    float best = brightest(&w, &bx, &by), ex, ey;
    mirror_point(&ex, &ey);
    if (fabsf((float)bx - ex) > 4.0f || fabsf((float)by - ey) > 4.0f)
        fail_msg("highlight at (%u, %u), expected near (%.1f, %.1f)", bx, by, ex, ey);
    float opposite = luminance(ob_world_pixel(&w, (uint32_t)(160.0f - ex), (uint32_t)(120.0f - ey)));
    if (!(best > 200.0f && opposite < best - 80.0f))
        fail_msg("highlight %.0f, the opposite side %.0f", best, opposite);
    ob_test_world_destroy(&w);
}

/* A w x h RGBA8 image as a PNG texture, sampled NEAREST and CLAMP. */
static const ob_texture *nearest_texture(ob_texture_cache *cache, const uint8_t *px, int w, int h, const char *what)
{
    int size;
    uint8_t *png = stbi_write_png_to_mem(px, w * 4, w, h, 4, &size);
    assert_non_null(png);
    ob_result r;
    const ob_texture *t = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .srgb = true, .context = what,
        .sampling = {.mag = OB_TEXTURE_FILTER_NEAREST, .min = OB_TEXTURE_FILTER_NEAREST,
                     .mip = OB_TEXTURE_FILTER_NEAREST, .wrap_u = OB_TEXTURE_WRAP_CLAMP,
                     .wrap_v = OB_TEXTURE_WRAP_CLAMP}}, &r);
    ob_free(png);
    assert_non_null(t);
    return t;
}

/* A 2x1 PNG: left texel transparent, right opaque white. */
static const ob_texture *half_transparent(ob_texture_cache *cache)
{
    static const uint8_t px[8] = {255, 255, 255, 0, 255, 255, 255, 255};
    return nearest_texture(cache, px, 2, 1, "test: half transparent");
}

/* A 160x120 world with a texture cache and a shadow-casting "leaf":
 * MASK with the half-transparent texture, lit green (emissive) or, double-
 * sided, plain white. */
static ob_material *leaf_world(ob_test_world *w, ob_texture_cache **out_cache, bool double_sided)
{
    ob_test_world_create(w, &(ob_test_world_desc){.width = 160, .height = 120});
    ob_result r;
    *out_cache = ob_texture_cache_create(w->dev, &r);
    assert_non_null(*out_cache);
    ob_material_pbr p = ob_material_pbr_defaults();
    p.base_color_texture.texture = half_transparent(*out_cache);
    p.alpha_mode = OB_ALPHA_MASK;
    p.metallic = 0.0f;
    p.double_sided = double_sided;
    if (!double_sided) p.emissive[1] = 1.0f;
    return pbr(w, "leaf", &p, true, 0);
}

/* MASK: the transparent half of the texture shows the background, the
 * opaque half the (green, emissive) quad; the light's shadow of the quad is
 * cut out the same way. */
static void alpha_mask_cuts_out(void **state)
{
    (void)state;
    ob_test_world w;
    ob_texture_cache *cache;
    ob_material *leaf = leaf_world(&w, &cache, false);
    ob_result r;
    facing_quad(&w, "leaf", ext_quad(&w, 1.0f, "leaf quad"), leaf, 0, 0, 0, false);
    ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    dump(&w, __func__);
    uint8_t bg[4];
    memcpy(bg, ob_world_pixel(&w, 2, 2), 4);
    const uint8_t *cut = ob_world_pixel(&w, 80 - 8, 60);
    const uint8_t *kept = ob_world_pixel(&w, 80 + 8, 60);
    if (!same_rgb(cut, bg, 0)) fail_msg("cut-out half (%u, %u, %u) is not the background", cut[0], cut[1], cut[2]);
    if (!(kept[1] > bg[1] + 60)) fail_msg("kept half (%u, %u, %u) is not the green quad", kept[0], kept[1], kept[2]);
    char effect[96];
    snprintf(effect, sizeof effect, "%s",
             ob_effect_name(ob_material_get_view_effect(leaf, w.r, NULL, ob_perspective_view_base(w.main), false, &r)));
    assert_non_null(strstr(effect, "mask"));
    assert_non_null(strstr(effect, "base"));
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
}

/* The same quad held over a ground, under a sun that casts shadows or not:
 * the pixels the shadow darkens all lie under the opaque half (right of the
 * middle: the scene and camera are symmetric in x), none under the cut-out
 * half. */
static uint8_t *mask_shadow_scene(bool shadows)
{
    ob_test_world w;
    ob_texture_cache *cache;
    ob_material *leaf = leaf_world(&w, &cache, true);
    /* Horizontal (the plane faces +Y), one unit above the ground. */
    ob_world_entity(&w, NULL, "leaf", ext_quad(&w, 2.0f, "leaf quad"), leaf, 0, 1, 0);
    ob_material_pbr g = ob_material_pbr_defaults();
    g.metallic = 0.0f;
    g.base_color[0] = g.base_color[1] = g.base_color[2] = 0.4f;
    ob_world_entity(&w, NULL, "ground", ext_quad(&w, 12.0f, "ground quad"), pbr(&w, "ground", &g, true, 0), 0,
                         0, 0);
    /* From behind and above: the shadow falls toward the camera. */
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, shadows, 1.5f, 0, 10, -8);
    ob_world_look(&w, 0, 5, 5, 0, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint8_t *img = ob_world_snapshot(&w);
    dump(&w, shadows ? "mask_shadow_on" : "mask_shadow_off");
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
    return img;
}

static void alpha_mask_cuts_the_shadow_too(void **state)
{
    (void)state;
    uint8_t *lit = mask_shadow_scene(false), *shadowed = mask_shadow_scene(true);
    uint32_t left = 0, right = 0;
    for (uint32_t y = 0; y < 120; y++)
        for (uint32_t x = 0; x < 160; x++) {
            size_t i = 4 * ((size_t)y * 160 + x);
            /* (A band around x = 0 is left out: the shadow's filtered edge.) */
            if (luminance(shadowed + i) < luminance(lit + i) - 20.0f && (x < 74 || x >= 80))
                *(x < 74 ? &left : &right) += 1;
        }
    if (right < 100 || left > 0) fail_msg("shadowed pixels: %u under the cut-out half, %u under the opaque half", left, right);
    free(lit);
    free(shadowed);
}

/* Two half-transparent emissive quads overlapping: green in front, red
 * behind, created front first. Back to front, the overlap is greener than
 * it is red (red first then green over it). */
static void blend_sorts_back_to_front(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
    ob_material_pbr p = ob_material_pbr_defaults();
    p.alpha_mode = OB_ALPHA_BLEND;
    p.metallic = 0.0f;
    p.base_color[0] = p.base_color[1] = p.base_color[2] = 0.0f;
    p.base_color[3] = 0.5f;
    ob_material_pbr green = p, red = p;
    green.emissive[1] = 1.0f;
    red.emissive[0] = 1.0f;
    ob_geometry *q = ext_quad(&w, 1.0f, "glass quad");
    facing_quad(&w, "front", q, pbr(&w, "green glass", &green, false, 0), 0.25, 0, 0.5, false);
    facing_quad(&w, "back", q, pbr(&w, "red glass", &red, false, 0), -0.25, 0, 0, false);
    ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    dump(&w, __func__);
    const uint8_t *overlap = ob_world_pixel(&w, 80, 60);
    if (!(overlap[1] > overlap[0] + 20))
        fail_msg("overlap (%u, %u, %u): the front (green) layer should dominate", overlap[0], overlap[1], overlap[2]);
    /* Each quad alone where they do not overlap: half of its colour over the background. */
    const uint8_t *only_red = ob_world_pixel(&w, 80 - 30, 60);
    assert_true(only_red[0] > only_red[1] + 20);
    ob_test_world_destroy(&w);
}

/* A quad facing away from the camera: culled when single-sided, drawn (and
 * lit on its back, the normal flipped) when double-sided. */
static void double_sided_shows_the_back(void **state)
{
    (void)state;
    for (int ds = 0; ds < 2; ds++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
        ob_material_pbr p = ob_material_pbr_defaults();
        p.metallic = 0.0f;
        p.double_sided = ds;
        facing_quad(&w, "card", ext_quad(&w, 1.0f, "card quad"), pbr(&w, "card", &p, false, 0), 0, 0, 0, true);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 2.0f, 0, 0, 5);
        ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        ob_world_read(&w);
    dump(&w, __func__);
        const uint8_t *bg = ob_world_pixel(&w, 2, 2), *mid = ob_world_pixel(&w, 80, 60);
        if (ds && !(luminance(mid) > luminance(bg) + 80))
            fail_msg("double-sided back face (%u, %u, %u) is not lit", mid[0], mid[1], mid[2]);
        if (!ds && !same_rgb(mid, bg, 0)) fail_msg("single-sided back face was drawn");
        ob_test_world_destroy(&w);
    }
}

/* A PBR box on a PBR ground under a shadow-casting sun: the ground has a
 * shadow (darker pixels than with the same sun casting none), and the
 * ground's variant is the shadowed one. */
static void shadow_map_feeds_pbr(void **state)
{
    (void)state;
    uint8_t *img[2];
    for (int shadows = 0; shadows < 2; shadows++) {
        ob_test_world w;
        ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
        ob_material_pbr p = ob_material_pbr_defaults();
        p.metallic = 0.0f;
        p.base_color[0] = p.base_color[1] = p.base_color[2] = 0.7f;
        ob_material *m = pbr(&w, "stone", &p, true, 0);
        ob_mesh box;
        assert_int_equal(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &box), OB_OK);
        ob_world_entity(&w, NULL, "box", extended(&w, &box, "pbr box", NULL), m, 0, 0.5, 0);
        ob_node *ground = ob_world_entity(&w, NULL, "ground", ext_quad(&w, 10.0f, "ground quad"), m, 0, 0, 0);
        ob_world_light(&w, OB_LIGHT_DIRECTIONAL, shadows, 2.0f, 3, 6, 2);
        ob_world_look(&w, 0, 4, 5, 0, 0, 0);
        ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
        img[shadows] = ob_world_snapshot(&w);
        dump(&w, shadows ? "shadow_on" : "shadow_off");
        ob_result r;
        const char *name = ob_effect_name(
            ob_material_get_view_effect(m, w.r, ground, ob_perspective_view_base(w.main), false, &r));
        if (shadows != (strstr(name, "sh") != NULL)) fail_msg("variant '%s' with shadows %d", name, shadows);
        ob_test_world_destroy(&w);
    }
    uint32_t darker = 0, brighter = 0;
    for (size_t i = 0; i < 160 * 120; i++) {
        float a = luminance(img[0] + 4 * i), b = luminance(img[1] + 4 * i);
        darker += b < a - 30.0f;
        brighter += b > a + 2.0f;
    }
    if (darker < 40 || brighter > 0) fail_msg("%u pixels in shadow, %u brighter", darker, brighter);
    free(img[0]);
    free(img[1]);
}

/* A smooth metal sphere with reflectivity 1 next to a red emissive box:
 * its environment map (drawn with PBR shading in the paraboloid views)
 * makes the side facing the box redder than the other side. */
static void environment_map_feeds_pbr(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
    ob_material_pbr chrome = ob_material_pbr_defaults();
    chrome.roughness = 0.05f;
    ob_material *mirror = pbr(&w, "chrome", &chrome, false, 1.0f);
    ob_node *ball = ob_world_entity(&w, NULL, "ball", ext_sphere(&w), mirror, 0, 0, 0);
    ob_material_pbr glow = ob_material_pbr_defaults();
    glow.base_color[0] = glow.base_color[1] = glow.base_color[2] = 0.0f;
    glow.metallic = 0.0f;
    glow.emissive[0] = 1.0f;
    ob_mesh box;
    assert_int_equal(ob_mesh_box((const float[3]){0.5f, 1.0f, 1.0f}, &box), OB_OK);
    ob_world_entity(&w, NULL, "red wall", extended(&w, &box, "wall", NULL), pbr(&w, "glow", &glow, false, 0),
                         1.5, 0, 0);
    ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_true(ob_world_count_views(st, OB_VIEW_PARABOLOID) >= 1);
    ob_world_read(&w);
    dump(&w, __func__);
    const uint8_t *toward = ob_world_pixel(&w, 80 + 16, 60), *away = ob_world_pixel(&w, 80 - 16, 60);
    /* Redness (red over green), so the check holds through tone mapping too. */
    if (!((int)toward[0] - (int)toward[1] > (int)away[0] - (int)away[1] + 30))
        fail_msg("side facing the red wall (%u, %u, %u), other side (%u, %u, %u)", toward[0], toward[1], toward[2],
                 away[0], away[1], away[2]);
    ob_result r;
    const char *name = ob_effect_name(
        ob_material_get_view_effect(mirror, w.r, ball, ob_perspective_view_base(w.main), false, &r));
    assert_non_null(strstr(name, "env"));
    ob_test_world_destroy(&w);
}

/* Textured, masked, blended, double-sided and plain PBR materials with
 * shadows: ST and MT recording give the same bytes and the same hash. */
static void st_and_mt_are_byte_identical(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120, .workers = 4});
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(w.dev, &r);
    const ob_texture *tex = half_transparent(cache);
    ob_material_pbr kinds[4];
    for (int i = 0; i < 4; i++) {
        kinds[i] = ob_material_pbr_defaults();
        kinds[i].metallic = i * 0.3f;
        kinds[i].roughness = 0.3f + i * 0.2f;
        kinds[i].base_color_texture.texture = tex;
    }
    kinds[1].alpha_mode = OB_ALPHA_MASK;
    kinds[2].alpha_mode = OB_ALPHA_BLEND;
    kinds[3].double_sided = true;
    ob_material *mats[4];
    for (int i = 0; i < 4; i++) {
        char name[16];
        snprintf(name, sizeof name, "pbr %d", i);
        mats[i] = pbr(&w, name, &kinds[i], true, 0);
    }
    ob_geometry *ball = ext_sphere(&w);
    for (int i = 0; i < 40; i++) {
        char name[16];
        snprintf(name, sizeof name, "ball %d", i);
        ob_world_entity(&w, NULL, name, ball, mats[i % 4], (i % 8) - 3.5, 0.5 * (i / 8) - 1.0, -(i % 3));
    }
    ob_world_entity(&w, NULL, "ground", ext_quad(&w, 20.0f, "ground quad"), mats[0], 0, -1.6, 0);
    ob_world_light(&w, OB_LIGHT_DIRECTIONAL, true, 2.0f, 2, 6, 3);
    ob_world_look(&w, 0, 1, 7, 0, 0, 0);
    const ob_frame_stats *st = ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    uint64_t st_hash = st->frame_hash;
    uint8_t *single = ob_world_snapshot(&w);
    st = ob_test_world_frame(&w, OB_THREADING_MULTI, 0);
    uint64_t mt_hash = st->frame_hash;
    uint8_t *multi = ob_world_snapshot(&w);
    assert_int_equal(st_hash, mt_hash);
    assert_int_equal(ob_rgba_diff_count(single, multi, 160 * 120, 0), 0);
    free(single);
    free(multi);
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
}

/* A material without textures compiles the variant without any texture
 * define (and says what it left out); one with a base colour texture only
 * that one. */
static void variants_only_use_what_the_material_uses(void **state)
{
    (void)state;
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(w.dev, &r);
    ob_material_pbr plain = ob_material_pbr_defaults(), textured = ob_material_pbr_defaults();
    textured.base_color_texture.texture = half_transparent(cache);
    ob_material *mp = pbr(&w, "plain", &plain, false, 0), *mt = pbr(&w, "textured", &textured, false, 0);
    ob_geometry *ball = ext_sphere(&w);
    ob_node *a = ob_world_entity(&w, NULL, "a", ball, mp, -0.6, 0, 0);
    ob_node *b = ob_world_entity(&w, NULL, "b", ball, mt, 0.6, 0, 0);
    ob_node_set_hidden(a, true);
    ob_node_set_hidden(b, true);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);   /* the composite's own effect, first */
    ob_node_set_hidden(a, false);
    ob_node_set_hidden(b, false);
    uint32_t before = ob_effect_context_counters(w.fx).variants_compiled;
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    /* Two variants: one per feature set (no shadow, env or depth pass here). */
    assert_int_equal(ob_effect_context_counters(w.fx).variants_compiled - before, 2);
    ob_view *main_view = ob_perspective_view_base(w.main);
    assert_string_equal(ob_effect_name(ob_material_get_view_effect(mp, w.r, a, main_view, false, &r)), "pbr:inst");
    assert_string_equal(ob_effect_name(ob_material_get_view_effect(mt, w.r, b, main_view, false, &r)), "pbr:base+inst");
    char left[256];
    /* 9 texture/alpha/sidedness features plus texture transforms, the second
     * uv set and clearcoat (its textures are implied without a coat). */
    assert_int_equal(ob_material_pbr_left_out(mp, left, sizeof left), 12);
    assert_non_null(strstr(left, "normal texture"));
    assert_non_null(strstr(left, "clearcoat"));
    assert_null(strstr(left, "clearcoat texture"));
    assert_int_equal(ob_material_pbr_left_out(mt, left, sizeof left), 11);
    assert_null(strstr(left, "base colour texture"));
    /* The same feature set in another material shares the variant. */
    ob_material *mp2 = pbr(&w, "plain too", &plain, false, 0);
    ob_world_entity(&w, NULL, "c", ball, mp2, 0, 0.8, 0);
    before = ob_effect_context_counters(w.fx).variants_compiled;
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    assert_int_equal(ob_effect_context_counters(w.fx).variants_compiled - before, 0);
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
}

/* A 1x1 texture of one texel. */
static const ob_texture *texel(ob_texture_cache *cache, uint8_t r, uint8_t g, uint8_t b, bool srgb)
{
    const uint8_t px[4] = {r, g, b, 255};
    int size;
    uint8_t *png = stbi_write_png_to_mem(px, 4, 1, 1, 4, &size);
    assert_non_null(png);
    ob_result res;
    const ob_texture *t = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .srgb = srgb, .context = "test: one texel"}, &res);
    ob_free(png);
    assert_non_null(t);
    return t;
}

enum { MAP_NONE, MAP_NORMAL, MAP_OCCLUSION, MAP_EMISSIVE, MAP_METALLIC_ROUGHNESS };

/* Luminance in the middle of a grey quad facing the camera, lit by a sun
 * from +X at a grazing angle (or by the ambient light alone), with one map. */
static float quad_with_map(int map, bool sun)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(w.dev, &r);
    ob_material_pbr p = ob_material_pbr_defaults();
    p.metallic = 0.0f;
    p.base_color[0] = p.base_color[1] = p.base_color[2] = 0.6f;
    switch (map) {
    case MAP_NORMAL:   /* tangent-space (0.6, 0, 0.8): tilted toward the tangent, +X */
        p.normal_texture.texture = texel(cache, 204, 128, 230, false);
        break;
    case MAP_OCCLUSION:
        p.occlusion_texture.texture = texel(cache, 0, 0, 0, false);
        break;
    case MAP_EMISSIVE:
        p.emissive[0] = p.emissive[1] = p.emissive[2] = 1.0f;
        p.emissive_texture.texture = texel(cache, 255, 0, 0, true);
        break;
    case MAP_METALLIC_ROUGHNESS:   /* metallic factor 1 times B = 255, roughness 1 times G = 0 */
        p.metallic = 1.0f;
        p.metallic_roughness_texture.texture = texel(cache, 0, 0, 255, false);
        break;
    default:
        break;
    }
    facing_quad(&w, "card", ext_quad(&w, 2.0f, "card quad"), pbr(&w, "card", &p, false, 0), 0, 0, 0, false);
    if (sun) ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 2.0f, 5, 0, 0.5);
    ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    const uint8_t *mid = ob_world_pixel(&w, 32, 24);
    float l = map == MAP_EMISSIVE ? (float)mid[0] - (float)mid[1] : luminance(mid);
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
    return l;
}

/* Each map changes what it should: a normal map tilted toward a grazing
 * light brightens the quad, a black occlusion map removes the ambient
 * light, a red emissive texture makes it glow red, and a metallic-
 * roughness map making it metal removes the diffuse light. */
static void texture_maps_change_the_shading(void **state)
{
    (void)state;
    float flat = quad_with_map(MAP_NONE, true), bumped = quad_with_map(MAP_NORMAL, true);
    if (!(bumped > flat + 40.0f)) fail_msg("normal map toward the light %.0f, without %.0f", bumped, flat);
    float ambient = quad_with_map(MAP_NONE, false), occluded = quad_with_map(MAP_OCCLUSION, false);
    if (!(ambient > occluded + 15.0f)) fail_msg("ambient alone %.0f, occluded %.0f", ambient, occluded);
    float redness = quad_with_map(MAP_EMISSIVE, false);
    if (!(redness > 100.0f)) fail_msg("red emissive texture: red - green = %.0f", redness);
    float metal = quad_with_map(MAP_METALLIC_ROUGHNESS, true);
    if (!(metal < flat - 10.0f)) fail_msg("metal (no diffuse) %.0f, dielectric %.0f", metal, flat);
}

/* ------------------------------------------- glTF extensions (issue 28) */

/* A 2x2 PNG, NEAREST and CLAMP: texel (0,0) red, (1,0) green, (0,1) blue,
 * (1,1) white (uv (0,0) is the top-left texel). */
static const ob_texture *quadrants(ob_texture_cache *cache)
{
    static const uint8_t px[16] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    return nearest_texture(cache, px, 2, 2, "test: quadrants");
}

enum { Q_RED, Q_GREEN, Q_BLUE, Q_WHITE };

/* Which quadrant colour a pixel shows. */
static int quadrant_of(const uint8_t *p)
{
    if (p[0] > 100 && p[1] > 100 && p[2] > 100) return Q_WHITE;
    return p[0] >= p[1] && p[0] >= p[2] ? Q_RED : p[1] >= p[2] ? Q_GREEN : Q_BLUE;
}

/* Four points around the middle of a card facing the camera, one in each
 * quarter of its uv square. */
static const uint32_t probe[4][2] = {{24, 18}, {40, 18}, {24, 30}, {40, 30}};

/* The quadrant each probe shows on a card whose emissive texture (black
 * base, so the emissive is what shows) is the quadrants image with
 * `slot`'s uv set and transform; with second_set the card's uv are all
 * (0,0) and, when the slot reads set 1, its uv1 are the plane's uv. */
static void card_quadrants(const ob_material_texture *slot, bool second_set, int out[4], char *variant,
                           size_t variant_size)
{
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(w.dev, &r);
    ob_material_pbr p = ob_material_pbr_defaults();
    p.base_color[0] = p.base_color[1] = p.base_color[2] = 0.0f;
    p.metallic = 0.0f;
    p.emissive[0] = p.emissive[1] = p.emissive[2] = 1.0f;
    p.emissive_texture = *slot;
    p.emissive_texture.texture = quadrants(cache);
    ob_mesh m;
    assert_int_equal(ob_mesh_plane(2.0f, 2.0f, 1, &m), OB_OK);
    if (second_set) {
        /* Set 0 (0,0) everywhere: one texel. A material reading only set 0
         * must draw a mesh without uv1 (the 52-byte layout), as
         * ob_model_instance uploads it. */
        if (slot->uv_set == 1) {
            m.uv1 = ob_malloc((size_t)m.vertex_count * sizeof *m.uv1);
            assert_non_null(m.uv1);
        }
        for (uint32_t i = 0; i < m.vertex_count; i++) {
            if (m.uv1) memcpy(m.uv1[i], m.vertices[i].uv, sizeof m.uv1[i]);
            m.vertices[i].uv[0] = m.vertices[i].uv[1] = 0.0f;
        }
    }
    ob_material *mat = pbr(&w, "card", &p, false, 0);
    ob_node *card = facing_quad(&w, "card", extended(&w, &m, "card quad", NULL), mat, 0, 0, 0, false);
    ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_world_read(&w);
    for (int k = 0; k < 4; k++) out[k] = quadrant_of(ob_world_pixel(&w, probe[k][0], probe[k][1]));
    if (variant)
        snprintf(variant, variant_size, "%s",
                 ob_effect_name(ob_material_get_view_effect(mat, w.r, card, ob_perspective_view_base(w.main), false,
                                                            &r)));
    ob_texture_cache_destroy(cache);   /* before the device goes */
    ob_test_world_destroy(&w);
}

/* KHR_texture_transform lands the texture where the spec says: an offset
 * of half the image in u shows the right column everywhere (the rest is
 * clamped), and a quarter turn (rotation pi/2, offset (0, 1): u' = v,
 * v' = 1 - u) turns the image a quarter, each point showing the colour
 * the spec's map names, wherever the plane's uv put each quadrant. */
static void texture_transform_lands_where_expected(void **state)
{
    (void)state;
    int plain[4], shifted[4], turned[4];
    char variant[64];
    card_quadrants(&(ob_material_texture){0}, false, plain, variant, sizeof variant);
    assert_string_equal(variant, "pbr:emi+inst");
    bool seen[4] = {false};
    for (int k = 0; k < 4; k++) seen[plain[k]] = true;
    assert_true(seen[Q_RED] && seen[Q_GREEN] && seen[Q_BLUE] && seen[Q_WHITE]);   /* one quadrant each */

    card_quadrants(&(ob_material_texture){.has_transform = true, .transform = {1, 0, 0.5f, 0, 1, 0}}, false,
                   shifted, variant, sizeof variant);
    assert_string_equal(variant, "pbr:emi+uvx+inst");
    /* u + 0.5: every point shows its row's right texel. */
    static const int shift[4] = {[Q_RED] = Q_GREEN, [Q_GREEN] = Q_GREEN, [Q_BLUE] = Q_WHITE, [Q_WHITE] = Q_WHITE};
    for (int k = 0; k < 4; k++)
        if (shifted[k] != shift[plain[k]]) fail_msg("offset: probe %d shows %d, expected %d", k, shifted[k], shift[plain[k]]);

    /* glTF: u' = cos r u + sin r v + ox, v' = -sin r u + cos r v + oy. */
    card_quadrants(&(ob_material_texture){.has_transform = true, .transform = {0, 1, 0, -1, 0, 1}}, false, turned,
                   NULL, 0);
    /* A point in quadrant (cu, cv) samples texel (cv, 1 - cu). */
    static const int turn[4] = {[Q_RED] = Q_BLUE, [Q_GREEN] = Q_RED, [Q_BLUE] = Q_WHITE, [Q_WHITE] = Q_GREEN};
    for (int k = 0; k < 4; k++)
        if (turned[k] != turn[plain[k]]) fail_msg("rotation: probe %d shows %d, expected %d", k, turned[k], turn[plain[k]]);
}

/* A texture reading TEXCOORD_1 samples the mesh's second uv set (here the
 * plane's own uv, while set 0 is (0,0) everywhere), through the 60-byte
 * layout, and shows all four quadrants where the plain card does; read
 * with set 0 the card shows one texel. */
static void texcoord1_is_used(void **state)
{
    (void)state;
    int plain[4], set0[4], set1[4];
    char variant[64];
    card_quadrants(&(ob_material_texture){0}, false, plain, NULL, 0);
    card_quadrants(&(ob_material_texture){.uv_set = 1}, true, set1, variant, sizeof variant);
    assert_string_equal(variant, "pbr:emi+uv1+inst");
    for (int k = 0; k < 4; k++) assert_int_equal(set1[k], plain[k]);
    card_quadrants(&(ob_material_texture){0}, true, set0, variant, sizeof variant);
    assert_string_equal(variant, "pbr:emi+inst");
    for (int k = 1; k < 4; k++) assert_int_equal(set0[k], set0[0]);
}

/* KHR_materials_clearcoat adds a sharp highlight over a rough base: the
 * coated ball's brightest pixel sits at the mirror direction and is much
 * brighter than anything on the uncoated ball, whose rough lobe is broad;
 * only the coated material compiles the clearcoat variant. */
static void clearcoat_adds_a_highlight_layer(void **state)
{
    (void)state;
    ob_material_pbr p = ob_material_pbr_defaults();
    p.base_color[0] = 0.5f, p.base_color[1] = 0.02f, p.base_color[2] = 0.01f;
    p.metallic = 0.0f;
    p.roughness = 0.8f;
    float best[2];
    uint32_t bx = 0, by = 0;
    for (int coated = 0; coated < 2; coated++) {
        p.clearcoat = coated ? 1.0f : 0.0f;
        p.clearcoat_roughness = 0.05f;
        ob_test_world w;
        ball_under_sun(&w, coated ? "coated" : "base", &p, 3.0f, 5, 5, 5, coated ? "clearcoat" : "clearcoat_base");
        best[coated] = brightest(&w, &bx, &by);
        ob_test_world_destroy(&w);
    }
    if (!(best[1] > best[0] + 60.0f)) fail_msg("coated highlight %.0f, uncoated %.0f", best[1], best[0]);
    float ex, ey;   /* the coat's lobe peaks where a mirror's would */
    mirror_point(&ex, &ey);
    if (fabsf((float)bx - ex) > 4.0f || fabsf((float)by - ey) > 4.0f)
        fail_msg("coat highlight at (%u, %u), expected near (%.1f, %.1f)", bx, by, ex, ey);

    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_result r;
    p.clearcoat = 1.0f;
    ob_material *coated = pbr(&w, "coated", &p, false, 0);
    p.clearcoat = 0.0f;
    ob_material *bare = pbr(&w, "bare", &p, false, 0);
    ob_geometry *ball = ext_sphere(&w);
    ob_node *a = ob_world_entity(&w, NULL, "a", ball, coated, -0.6, 0, 0);
    ob_node *b = ob_world_entity(&w, NULL, "b", ball, bare, 0.6, 0, 0);
    ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
    ob_view *main_view = ob_perspective_view_base(w.main);
    assert_string_equal(ob_effect_name(ob_material_get_view_effect(coated, w.r, a, main_view, false, &r)), "pbr:cc+inst");
    assert_string_equal(ob_effect_name(ob_material_get_view_effect(bare, w.r, b, main_view, false, &r)), "pbr:inst");
    char left[512];
    ob_material_pbr_left_out(coated, left, sizeof left);
    assert_non_null(strstr(left, "clearcoat normal texture"));
    ob_test_world_destroy(&w);
}

/* ------------------------------------------------------------ faults */

/* A PBR scene on the fault-tolerant test stack: a masked, normal-mapped,
 * textured ball and a ground casting and taking shadows, a reflective PBR
 * ball with its environment map. Every step returns its result. */
typedef struct pbr_stack {
    ob_test_stack t;
    ob_texture_cache *cache;
    /* Encoded before any fault is armed: stb_image_write does not survive a
     * failed realloc. */
    const uint8_t *png[2];
    int png_size[2];
} pbr_stack;

static void walk_pngs(uint8_t *png[2], int size[2])
{
    static const uint8_t px[16] = {255, 200, 120, 255, 255, 200, 120, 0, 90, 160, 255, 255, 255, 255, 255, 255};
    static const uint8_t bump[16] = {160, 128, 240, 255, 96, 128, 240, 255, 128, 160, 240, 255, 128, 96, 240, 255};
    png[0] = stbi_write_png_to_mem(px, 8, 2, 2, 4, &size[0]);
    png[1] = stbi_write_png_to_mem(bump, 8, 2, 2, 4, &size[1]);
    assert_true(png[0] && png[1]);
}

/* The mesh `made` filled, with (white) vertex colours so it is uploaded
 * extended; released either way. NULL with *out_result on failure. */
static ob_geometry *extended_or_error(ob_stack *s, ob_result made, ob_mesh *m, const char *name, ob_result *out_result)
{
    ob_geometry *g = NULL;
    *out_result = made;
    if (made == OB_OK) {
        m->colors = ob_calloc(m->vertex_count, sizeof *m->colors);
        if (m->colors) {
            g = ob_stack_add_geometry(s, m, name, out_result);
        } else {
            OB_LOG_W("test", "fault walk: no memory for the test's vertex colours");
            *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
        }
    }
    ob_mesh_release(m);
    return g;
}

static ob_result pbr_stack_build(pbr_stack *ps)
{
    ob_stack *s = ps->t.world.stack;
    ob_result r;
    ps->cache = ob_texture_cache_create(ps->t.world.dev, &r);
    if (!ps->cache) return r;
    const ob_texture *tex[2] = {NULL, NULL};
    for (int i = 0; i < 2; i++) {
        tex[i] = ob_texture_cache_load(ps->cache, &(ob_texture_desc){
            .data = ps->png[i], .size = (size_t)ps->png_size[i], .srgb = i == 0,
            .context = i ? "fault walk normal" : "fault walk base"}, &r);
        if (!tex[i]) return r;
    }
    ob_material_pbr leaf = ob_material_pbr_defaults(), chrome = ob_material_pbr_defaults();
    leaf.metallic = 0.2f;
    leaf.base_color_texture.texture = tex[0];
    leaf.normal_texture.texture = tex[1];
    leaf.alpha_mode = OB_ALPHA_MASK;
    leaf.double_sided = true;
    chrome.roughness = 0.1f;
    ob_material *ml = ob_material_create(s->materials, &(ob_material_desc){
        .name = "leaf", .kind = OB_MATERIAL_PBR, .pbr = leaf, .casts_shadows = true}, &r);
    if (!ml) return r;
    ob_material *mc = ob_material_create(s->materials, &(ob_material_desc){
        .name = "chrome", .kind = OB_MATERIAL_PBR, .pbr = chrome, .reflectivity = 1.0f}, &r);
    if (!mc) return r;
    ob_mesh m;
    ob_geometry *ball = extended_or_error(s, ob_mesh_sphere(0.5f, 16, 8, &m), &m, "fault ball", &r);
    if (!ball) return r;
    ob_geometry *ground = extended_or_error(s, ob_mesh_plane(6.0f, 6.0f, 1, &m), &m, "fault ground", &r);
    if (!ground) return r;
    ob_node *n;
    if (!(n = ob_stack_add_entity(s, NULL, "leaf ball", ball, ml, &r))) return r;
    ob_node_set_position(n, (const double[3]){-0.6, 0.5, 0});
    if (!(n = ob_stack_add_entity(s, NULL, "chrome ball", ball, mc, &r))) return r;
    ob_node_set_position(n, (const double[3]){0.6, 0.5, 0});
    if (!(n = ob_stack_add_entity(s, NULL, "ground", ground, ml, &r))) return r;
    ob_node *sun = ob_node_create(s->scene, NULL, "sun", &r);
    if (!sun) return r;
    r = ob_node_set_light(sun, &(ob_light_desc){.type = OB_LIGHT_DIRECTIONAL, .color = {1, 1, 1},
                                                .intensity = 2.0f, .casts_shadows = true});
    if (r != OB_OK) return r;
    ob_node_set_position(sun, (const double[3]){2, 6, 3});
    r = ob_node_look_at(sun, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0});
    if (r != OB_OK) return r;
    ob_node_set_position(s->camera, (const double[3]){0, 1.5, 3});
    return ob_node_look_at(s->camera, (const double[3]){0, 0.3, 0}, (const double[3]){0, 1, 0});
}

static void pbr_stack_stop(pbr_stack *ps)
{
    if (ps->t.world.r) ob_renderer_wait_idle(ps->t.world.r);
    ob_texture_cache_destroy(ps->cache);
    ps->cache = NULL;
    ob_test_stack_stop(&ps->t);
}

typedef struct pbr_outcome {
    ob_result result;
    bool hit, logged, validation, next_ok;
    uint64_t count;
    uint32_t diff;
} pbr_outcome;

/* Builds (armed when `scene`), runs the first frame (armed otherwise), then
 * an unarmed frame compared with ref. */
static pbr_outcome pbr_fault_run(const ob_test_vulkan *tv, bool scene, ob_fault_kind kind, uint64_t nth,
                                 const uint8_t *ref, uint8_t *const png[2], const int png_size[2])
{
    pbr_outcome o = {0};
    pbr_stack ps = {.png = {png[0], png[1]}, .png_size = {png_size[0], png_size[1]}};
    ob_result r = ob_test_stack_start(&ps.t, &(ob_test_stack_desc){.adopt = &tv->handles});
    if (r != OB_OK) fail_msg("fault walk: unarmed start failed: %s", ob_result_name(r));
    ob_test_log_clear();
    if (scene) ob_fault_arm(kind, nth);
    r = pbr_stack_build(&ps);
    if (scene) {
        o.hit = ob_fault_hit(kind);
        o.count = ob_fault_count(kind);
        ob_fault_arm(kind, 0);
        o.result = r;
    } else if (r != OB_OK) {
        fail_msg("fault walk: unarmed scene failed: %s", ob_result_name(r));
    }
    if (r == OB_OK) {
        if (!scene) ob_fault_arm(kind, nth);
        r = ob_test_stack_frame(&ps.t, OB_THREADING_SINGLE, 0);
        if (!scene) {
            o.hit = ob_fault_hit(kind);
            o.count = ob_fault_count(kind);
            ob_fault_arm(kind, 0);
            o.result = r;
        }
        r = ob_test_stack_frame(&ps.t, OB_THREADING_SINGLE, 0);
        o.next_ok = r == OB_OK;
        if (o.next_ok && ref) {
            uint8_t *img = malloc((size_t)ps.t.width * ps.t.height * 4);
            assert_non_null(img);
            o.next_ok = ob_test_stack_read(&ps.t, img) == OB_OK;
            o.diff = ob_test_image_max_diff(img, ref, ps.t.width, ps.t.height);
            free(img);
        }
    } else {
        o.next_ok = true;   /* a scene that failed cleanly has nothing to render */
    }
    pbr_stack_stop(&ps);
    o.logged = ob_test_log_count(OB_LOG_WARN) > 0;
    o.validation = ob_test_log_has("[vk-validation]", NULL);
    return o;
}

/* Host-allocation and Vulkan-object failures while building a PBR
 * scene (textures, materials) and while running its first frame (variants,
 * pipelines, env and shadow maps): an error with a message or a degraded,
 * logged frame; the validation layer silent; the next frame the picture of
 * an undisturbed run. */
static void pbr_scene_survives_every_fault(void **state)
{
    (void)state;
    ob_test_skip_under_tsan("every point runs single-threaded");
    /* Each point costs a whole stack (~0.5 s here): every `stride`th point
     * and the last are walked; OB_PBR_FAULT_STRIDE=1 walks them all (it
     * passed when this test was written: 622 points). */
    const char *env = getenv("OB_PBR_FAULT_STRIDE");
    const uint64_t stride = env && atoi(env) > 0 ? (uint64_t)atoi(env) : 6u;
    ob_test_log_set_echo(false);
    uint8_t *png[2];
    int png_size[2];
    walk_pngs(png, png_size);
    /* Every stack of the walk on one instance (ob_test_adopt.h says why). */
    ob_test_vulkan tv;
    ob_test_vulkan_create(&tv);
    pbr_outcome ref_run = pbr_fault_run(&tv, false, OB_FAULT_HOST_ALLOC, 0, NULL, png, png_size);
    assert_true(ref_run.next_ok);
    /* The reference image: an unarmed run, frame 2. */
    pbr_stack ps = {.png = {png[0], png[1]}, .png_size = {png_size[0], png_size[1]}};
    assert_int_equal(ob_test_stack_start(&ps.t, &(ob_test_stack_desc){.adopt = &tv.handles}), OB_OK);
    assert_int_equal(pbr_stack_build(&ps), OB_OK);
    assert_int_equal(ob_test_stack_frame(&ps.t, OB_THREADING_SINGLE, 0), OB_OK);
    assert_int_equal(ob_test_stack_frame(&ps.t, OB_THREADING_SINGLE, 0), OB_OK);
    uint8_t *ref = malloc((size_t)ps.t.width * ps.t.height * 4);
    assert_non_null(ref);
    assert_int_equal(ob_test_stack_read(&ps.t, ref), OB_OK);
    pbr_stack_stop(&ps);
    for (int phase = 0; phase < 2; phase++) {
        for (int kind = OB_FAULT_HOST_ALLOC; kind <= OB_FAULT_VK_OBJECT; kind++) {
            uint64_t count = pbr_fault_run(&tv, phase == 0, (ob_fault_kind)kind, 0, ref, png, png_size).count;
            uint64_t errors = 0, degraded = 0, walked = 0;
            for (uint64_t n = 1; n <= count; n = n + stride > count && n != count ? count : n + stride) {
                walked++;
                pbr_outcome o = pbr_fault_run(&tv, phase == 0, (ob_fault_kind)kind, n, ref, png, png_size);
                const char *where = phase == 0 ? "PBR scene" : "PBR first frame";
                if (!o.hit) fail_msg("%s, kind %d point %llu: never reached", where, kind, (unsigned long long)n);
                if (o.validation)
                    fail_msg("%s, kind %d point %llu: the validation layer spoke", where, kind, (unsigned long long)n);
                if (!o.logged)
                    fail_msg("%s, kind %d point %llu: failed without a message", where, kind, (unsigned long long)n);
                if (!o.next_ok || o.diff)
                    fail_msg("%s, kind %d point %llu: the next frame %s (differs by %u)", where, kind,
                             (unsigned long long)n, o.next_ok ? "differs" : "failed", o.diff);
                if (o.result != OB_OK) errors++;
                else degraded++;
            }
            printf("[ pbr faults ] %-15s kind %d: %llu of %llu points, %llu errors, %llu degraded frames (logged)\n",
                   phase == 0 ? "scene" : "first frame", kind, (unsigned long long)walked, (unsigned long long)count,
                   (unsigned long long)errors, (unsigned long long)degraded);
            fflush(stdout);
        }
    }
    free(ref);
    ob_free(png[0]);
    ob_free(png[1]);
    ob_test_vulkan_destroy(&tv);
    ob_test_log_set_echo(true);
}

/* Bad factors are refused by name; defaults are glTF's. */
static void defaults_and_bad_input(void **state)
{
    (void)state;
    ob_material_pbr d = ob_material_pbr_defaults();
    assert_true(d.base_color[3] == 1.0f && d.metallic == 1.0f && d.roughness == 1.0f && d.alpha_cutoff == 0.5f &&
                d.normal_scale == 1.0f && d.occlusion_strength == 1.0f && d.alpha_mode == OB_ALPHA_OPAQUE);
    ob_test_world w;
    ob_test_world_create(&w, &(ob_test_world_desc){.width = 64, .height = 48});
    ob_result r;
    d.roughness = NAN;
    ob_test_log_clear();
    assert_null(ob_material_create(w.lib, &(ob_material_desc){.name = "broken", .kind = OB_MATERIAL_PBR, .pbr = d},
                                   &r));
    assert_int_equal(r, OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("broken", NULL));
    d = ob_material_pbr_defaults();
    d.alpha_mode = (ob_alpha_mode)7;
    assert_null(ob_material_create(w.lib, &(ob_material_desc){.name = "odd", .kind = OB_MATERIAL_PBR, .pbr = d}, &r));
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    ob_test_world_destroy(&w);
}

/* One lighting model: a LIT or REFLECTIVE material draws as the PBR
 * material ob_material_desc_to_pbr makes of it, byte for byte (the same
 * shader and factors; only the vertex layout differs), under a sun and a
 * point light: the highlight, the diffuse and the ambient of each. */
static void lit_draws_as_its_pbr_twin(void **state)
{
    (void)state;
    static const ob_material_desc descs[] = {
        {.name = "plain", .kind = OB_MATERIAL_LIT, .diffuse = {0.8f, 0.3f, 0.2f, 1}},
        {.name = "gold", .kind = OB_MATERIAL_LIT, .diffuse = {0.2f, 0.15f, 0.05f, 1},
         .specular = {1.0f, 0.8f, 0.35f, 6}},
        {.name = "given", .kind = OB_MATERIAL_LIT, .diffuse = {0.3f, 0.5f, 0.9f, 1}, .metallic = 0.4f,
         .roughness = 0.35f, .metallic_roughness = true},
        {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .diffuse = {0.9f, 0.9f, 0.95f, 1}, .roughness = 0.2f},
    };
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(descs); i++) {
        uint8_t *img[2];
        for (int twin = 0; twin < 2; twin++) {
            ob_test_world w;
            ob_test_world_create(&w, &(ob_test_world_desc){.width = 160, .height = 120});
            ob_mesh m;
            assert_int_equal(ob_mesh_sphere(0.5f, 48, 32, &m), OB_OK);
            ob_geometry *g = twin ? extended(&w, &m, "twin sphere", NULL) : ob_world_geometry(&w, &m, "sphere");
            if (!twin) ob_mesh_release(&m);
            ob_material_desc d = twin ? ob_material_desc_to_pbr(&descs[i]) : descs[i];
            ob_world_entity(&w, NULL, "ball", g, ob_world_material_desc(&w, &d), 0, 0, 0);
            ob_world_light(&w, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 3, 4);
            ob_world_light(&w, OB_LIGHT_POINT, false, 2.0f, -1.5, 0.5, 1.5);
            ob_world_look(&w, 0, 0, 2.5, 0, 0, 0);
            ob_test_world_frame(&w, OB_THREADING_SINGLE, 0);
            ob_world_read(&w);
            img[twin] = ob_world_copy(&w);
            assert_int_equal(w.err, OB_OK);
            ob_test_world_destroy(&w);
        }
        uint32_t d = ob_test_image_max_diff(img[0], img[1], 160, 120);
        if (d) fail_msg("material '%s': %u levels from its PBR twin", descs[i].name, d);
        free(img[0]);
        free(img[1]);
    }
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lit_side_is_brighter),
        cmocka_unit_test(lit_draws_as_its_pbr_twin),
        cmocka_unit_test(smooth_metal_highlight_at_mirror_direction),
        cmocka_unit_test(alpha_mask_cuts_out),
        cmocka_unit_test(alpha_mask_cuts_the_shadow_too),
        cmocka_unit_test(blend_sorts_back_to_front),
        cmocka_unit_test(double_sided_shows_the_back),
        cmocka_unit_test(shadow_map_feeds_pbr),
        cmocka_unit_test(environment_map_feeds_pbr),
        cmocka_unit_test(texture_maps_change_the_shading),
        cmocka_unit_test(texture_transform_lands_where_expected),
        cmocka_unit_test(texcoord1_is_used),
        cmocka_unit_test(clearcoat_adds_a_highlight_layer),
        cmocka_unit_test(st_and_mt_are_byte_identical),
        cmocka_unit_test(variants_only_use_what_the_material_uses),
        cmocka_unit_test(defaults_and_bad_input),
        cmocka_unit_test(pbr_scene_survives_every_fault),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
