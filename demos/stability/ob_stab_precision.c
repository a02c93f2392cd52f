/* Stability cases about precision: reversed-Z depth, large coordinates,
 * extreme scales (rendered), deep hierarchies and long incremental runs
 * (scene graph only). tests/gpu/test_extreme_depth.c, test_extreme_scale.c
 * and tests/unit/test_scene_extreme.c run these cases and assert on their
 * rows. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_stab_world.h"

/* ------------------------------------------------------- depth ordering */

/* Two camera-facing quads: "far" fills the view at distance d, "near" sits
 * a relative gap g in front (at d (1 - g)) over the right half. Material
 * priorities force both draw orders (opaque items sort by priority first). */
typedef struct depth_rig {
    ob_stab_world w;
    ob_node *far, *near;
    ob_material *far_first, *far_second, *near_first, *near_second;
} depth_rig;

typedef struct depth_result {
    uint32_t wrong_overlap, wrong_far, overlap_pixels;
    bool two_draws;
} depth_result;

static const float far_rgb[3] = {1.0f, 0.0f, 0.0f};
static const float near_rgb[3] = {0.0f, 1.0f, 0.0f};

static ob_material *unlit(ob_stab_world *w, const char *name, const float rgb[3], uint32_t priority)
{
    ob_material_desc md = {.name = name, .kind = OB_MATERIAL_UNLIT,
                           .diffuse = {rgb[0], rgb[1], rgb[2], 1.0f},
                           .specular = {0.0f, 0.0f, 0.0f, 1.0f}, .priority = priority};
    return ob_world_material_desc(&w->world, &md);
}

static void set_material(ob_stab_world *w, ob_node *n, ob_material *m)
{
    if (w->world.err != OB_OK || !n) return;
    ob_renderable rd = *ob_node_get_renderable(n);
    rd.material = m;
    ob_result r = ob_node_set_renderable(n, &rd);
    if (r != OB_OK) {
        w->world.err = r;
        OB_LOG_E("bench", "stability: material of '%s': %s", ob_node_name(n), ob_result_name(r));
    }
}

/* The composite's output for a linear colour, within one level. */
static bool is_rgb(const ob_stab_world *w, const uint8_t *p, const float rgb[3])
{
    for (int i = 0; i < 3; i++)
        if (abs(p[i] - ob_composite_view_output_level(w->world.stack->composite, rgb[i])) > 1) return false;
    return true;
}

static depth_result depth_render(depth_rig *rig, double d, double gap, bool near_drawn_first)
{
    ob_stab_world *w = &rig->w;
    float s = (float)(0.2 * d);   /* the 20-unit plane, 4 d wide: wider than the view */
    ob_stab_scale(rig->far, s, s, s);
    ob_stab_scale(rig->near, s, s, s);
    ob_stab_position(rig->far, 0, 0, -d);
    ob_stab_position(rig->near, 2.0 * d, 0, -d * (1.0 - gap));
    set_material(w, rig->far, near_drawn_first ? rig->far_second : rig->far_first);
    set_material(w, rig->near, near_drawn_first ? rig->near_first : rig->near_second);
    const ob_frame_stats *st = ob_stab_frame(w, OB_THREADING_SINGLE);
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    uint8_t *img = ob_stab_snapshot(w);
    depth_result res = {.two_draws = main && main->draws == 2};
    for (uint32_t y = 0; img && y < w->world.height; y++) {
        for (uint32_t x = 0; x < w->world.width; x++) {
            const uint8_t *p = img + ((size_t)y * w->world.width + x) * 4;
            if (x + 2 < w->world.width / 2) {
                res.wrong_far += !is_rgb(w, p, far_rgb);
            } else if (x > w->world.width / 2 + 1) {
                res.overlap_pixels++;
                res.wrong_overlap += !is_rgb(w, p, near_rgb);
            }
        }
    }
    ob_free(img);
    return res;
}

static uint32_t float_steps(float a, float b)
{
    uint32_t x, y;
    memcpy(&x, &a, sizeof x);
    memcpy(&y, &b, sizeof y);
    return x > y ? x - y : y - x;
}

ob_result ob_stab_depth_precision(ob_stab_ctx *c)
{
    const float znear = 1e-3f;
    static const double distances[] = {1e3, 1e4, 1e5};
    static const double gaps[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
    depth_rig rig = {0};
    ob_stab_world *w = &rig.w;
    ob_stab_world_create(w, c, &(ob_stab_world_desc){.width = 96, .height = 64, .znear = znear});
    ob_world_look(&w->world, 0, 0, 0, 0, 0, -1);
    rig.far_first = unlit(w, "far-first", far_rgb, 0);
    rig.far_second = unlit(w, "far-second", far_rgb, 1);
    rig.near_first = unlit(w, "near-first", near_rgb, 0);
    rig.near_second = unlit(w, "near-second", near_rgb, 1);
    rig.far = ob_world_entity(&w->world, NULL, "far", w->world.plane, rig.far_first, 0, 0, 0);
    rig.near = ob_world_entity(&w->world, NULL, "near", w->world.plane, rig.near_second, 0, 0, 0);
    /* The plane faces +Y; a quarter turn about X makes it face the camera. */
    const double q[4] = {sin(OB_PI / 4), 0, 0, cos(OB_PI / 4)};
    if (rig.far && rig.near) {
        ob_node_set_rotation_d(rig.far, q);
        ob_node_set_rotation_d(rig.near, q);
    }
    ob_result r = OB_OK;
    struct { depth_result a, b; double ms, smallest, first_bad; uint32_t bad_pixels; bool ok; } res[3];
    memset(res, 0, sizeof res);
    for (size_t di = 0; di < OB_ARRAY_COUNT(distances) && w->world.err == OB_OK; di++) {
        double d = distances[di];
        res[di].smallest = 0.0;
        res[di].first_bad = NAN;
        res[di].bad_pixels = 0;
        res[di].ok = true;
        bool resolved_so_far = true;
        for (size_t gi = 0; gi < OB_ARRAY_COUNT(gaps); gi++) {
            depth_result a = depth_render(&rig, d, gaps[gi], false);
            depth_result b = depth_render(&rig, d, gaps[gi], true);
            res[di].ok &= a.two_draws && b.two_draws && a.wrong_far == 0 && b.wrong_far == 0;
            if (gi == 0) {
                res[di].a = a;
                res[di].b = b;
                res[di].ms = ob_stab_take_ms(c);
            }
            if (resolved_so_far && a.wrong_overlap == 0 && b.wrong_overlap == 0) {
                res[di].smallest = gaps[gi];
            } else if (resolved_so_far) {
                resolved_so_far = false;
                res[di].first_bad = gaps[gi];
                res[di].bad_pixels = a.wrong_overlap + b.wrong_overlap;
            }
        }
    }
    if (w->world.err == OB_OK) {
        for (size_t di = 0; di < OB_ARRAY_COUNT(distances) && r == OB_OK; di++) {
            double d = distances[di];
            const depth_result *a = &res[di].a, *b = &res[di].b;
            float z_far = (float)(znear / d), z_near = (float)(znear / (d * (1.0 - 1e-3)));
            char name[48];
            snprintf(name, sizeof name, "depth_precision d=%.0e", d);
            r = ob_stab_add(c, name, "wrong pixels, quads 0.1% of d apart, znear 1e-3, reversed-Z "
                                     "infinite far, both draw orders",
                            (double)(a->wrong_overlap + b->wrong_overlap + a->wrong_far + b->wrong_far),
                            "pixels", 0, res[di].ok, res[di].ms,
                            "overlap wrong %u / %u of %u (far / near drawn first), far-only wrong "
                            "%u / %u; depths %u float steps apart",
                            a->wrong_overlap, b->wrong_overlap, a->overlap_pixels, a->wrong_far,
                            b->wrong_far, float_steps(z_near, z_far));
        }
        double ms = ob_stab_take_ms(c);
        for (size_t di = 0; di < OB_ARRAY_COUNT(distances) && r == OB_OK; di++) {
            char name[48];
            snprintf(name, sizeof name, "depth_resolution d=%.0e", distances[di]);
            r = ob_stab_add(c, name, "smallest relative gap resolved in both draw orders (gaps "
                                     "1e-3..1e-8; measured only)",
                            res[di].smallest, "rel. gap", NAN, res[di].ok, ms,
                            "= %.3g units; the next gap (%.0e) had %u wrong pixels", res[di].smallest *
                            distances[di], res[di].first_bad, res[di].bad_pixels);
        }
    }
    if (r == OB_OK) r = w->world.err;
    ob_stab_world_destroy(w);
    return r;
}

/* ------------------------------------------------- large coordinates */

typedef struct offset_image {
    uint8_t *pixels;
    uint32_t shadow_draws, env_draws, env_items;   /* 0 when the view did not run */
} offset_image;

static ob_node *aimed_light(ob_stab_world *w, const char *name, const ob_light_desc *ld,
                            const double pos[3], const double *target)
{
    if (w->world.err != OB_OK) return NULL;
    ob_result r;
    ob_node *n = ob_node_create(w->world.stack->scene, NULL, name, &r);
    if (n) {
        r = ob_node_set_light(n, ld);
        ob_node_set_position(n, pos);
        if (r == OB_OK && target) r = ob_node_look_at(n, target, (const double[3]){0, 1, 0});
    }
    if (r != OB_OK) {
        w->world.err = r;
        OB_LOG_E("bench", "stability: light '%s': %s", name, ob_result_name(r));
    }
    return n;
}

/* Every position (entities, lights, camera) is o + p with p not dyadic (0.3
 * is not a double), so o + p rounds to the double grid at o as a real far
 * scene does. */
static void build_offset_scene(ob_stab_world *w, const double o[3])
{
    ob_material *ground = ob_world_material(&w->world, "ground", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.55f, false);
    ob_material *red = ob_world_material(&w->world, "red", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    ob_material *blue = ob_world_material(&w->world, "blue", OB_MATERIAL_LIT, 0.2f, 0.3f, 0.9f, true);
    ob_material *mirror = ob_world_material_desc(
        &w->world, &(ob_material_desc){.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE,
                               .diffuse = {0.9f, 0.9f, 0.9f, 1.0f}, .reflectivity = 0.7f,
                               .casts_shadows = true});
    ob_world_entity(&w->world, NULL, "ground", w->world.plane, ground, o[0], o[1], o[2]);
    ob_node *cube = ob_world_entity(&w->world, NULL, "cube", w->world.box, red, o[0] - 0.7, o[1] + 0.5, o[2] - 0.3);
    if (cube) ob_node_set_euler(cube, 0.0f, 0.6f, 0.0f);
    ob_node *tall = ob_world_entity(&w->world, NULL, "tall", w->world.box, blue, o[0] + 0.45, o[1] + 0.75,
                                   o[2] - 1.55);
    ob_stab_scale(tall, 0.5f, 1.5f, 0.5f);
    ob_world_entity(&w->world, NULL, "mirror", w->world.sphere, mirror, o[0] + 1.05, o[1] + 0.5, o[2] + 0.45);
    aimed_light(w, "sun", &(ob_light_desc){.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.95f, 0.9f},
                                           .intensity = 0.9f, .casts_shadows = true},
                (const double[3]){o[0] + 3.1, o[1] + 8, o[2] + 4.3}, o);
    aimed_light(w, "lamp", &(ob_light_desc){.type = OB_LIGHT_POINT, .color = {0.4f, 0.6f, 1.0f},
                                            .intensity = 3.0f, .range = 8.0f},
                (const double[3]){o[0] - 2.1, o[1] + 1.5, o[2] + 1.3}, NULL);
    ob_world_look(&w->world, o[0] + 0.55, o[1] + 2.5, o[2] + 4.6, o[0] + 0.05, o[1] + 0.5, o[2] - 0.1);
}

/* Two frames (ST, then MT: the steady state) and the image. */
static ob_result render_offset(ob_stab_ctx *c, const double o[3], offset_image *out)
{
    ob_stab_world w;
    *out = (offset_image){0};
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = 160, .height = 120});
    build_offset_scene(&w, o);
    ob_stab_frame(&w, OB_THREADING_SINGLE);
    const ob_frame_stats *st = ob_stab_frame(&w, OB_THREADING_MULTI);
    ob_world_shadow_cascades(st, "sun", &out->shadow_draws);
    const ob_view_stats *env = ob_world_view_stats(st, "envmap:mirror");
    out->env_draws = env ? env->draws : 0;
    out->env_items = env ? env->items : 0;
    out->pixels = ob_stab_snapshot(&w);
    ob_result r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}

ob_result ob_stab_large_coordinates(ob_stab_ctx *c)
{
    enum { N = 160 * 120 };
    static const struct { const char *name; double o[3]; } cases[] = {
        {"large_coordinates 1e7", {1e7, 1e7, 1e7}},
        {"large_coordinates -1e7,1e7,-1e7", {-1e7, 1e7, -1e7}},
        {"large_coordinates 1e7+fraction", {1e7 + 0.1, -3e7 + 0.3, 12345678.9}},
        {"large_coordinates 1e9", {1e9 + 0.1, 1e9 + 0.1, -(1e9 + 0.1)}},
        {"large_coordinates 1e11", {1e11 + 0.1, 1e11 + 0.1, -(1e11 + 0.1)}},
        {"large_coordinates 1e13", {1e13 + 0.1, 1e13 + 0.1, -(1e13 + 0.1)}},
    };
    offset_image ref;
    ob_result r = render_offset(c, (const double[3]){0, 0, 0}, &ref);
    /* The reference really exercises shadows (three casters) and the env
     * map (three neighbours, at least one reaching both halves). */
    bool ref_full = ref.shadow_draws >= 3 && ref.env_items >= 3 && ref.env_draws > ref.env_items;
    ob_stab_take_ms(c);
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases) && r == OB_OK; i++) {
        offset_image img;
        r = render_offset(c, cases[i].o, &img);
        bool promised = i < 3;
        if (r == OB_OK) {
            uint32_t max_diff = ob_rgba_max_diff(ref.pixels, img.pixels, N);
            uint32_t count = ob_rgba_diff_count(ref.pixels, img.pixels, N, 0);
            double spacing = nextafter(fabs(cases[i].o[0]), INFINITY) - fabs(cases[i].o[0]);
            r = ob_stab_add(c, cases[i].name,
                            promised ? "max abs pixel difference against the scene at the origin "
                                       "(shadows, point light, env map)"
                                     : "the same, beyond the promise (measured only)",
                            max_diff, "levels/255", promised ? 0 : NAN,
                            img.shadow_draws > 0 && img.env_draws > 0 && ref_full,
                            ob_stab_take_ms(c),
                            "%u of %u pixels differ; offset (%.10g, %.10g, %.10g), double spacing "
                            "%.2g; shadow:sun %u draws, envmap:mirror %u (origin: %u, %u)",
                            count, N, cases[i].o[0], cases[i].o[1], cases[i].o[2], spacing,
                            img.shadow_draws, img.env_draws, ref.shadow_draws, ref.env_draws);
        }
        ob_free(img.pixels);
    }
    ob_free(ref.pixels);
    return r;
}

/* ------------------------------------------- large coordinates, scene */

/* A small scene (hierarchy, controllers, camera) at an offset: the
 * camera-relative matrices the GPU gets must match the origin's, and so must
 * the culling answer. */
typedef struct small_scene {
    ob_scene *s;
    ob_node *cam, *items[4];
} small_scene;

static ob_result build_small_scene(small_scene *sc, const double offset[3])
{
    ob_result r;
    *sc = (small_scene){0};
    sc->s = ob_scene_create(&r);
    if (!sc->s) return r;
    static const char *const names[] = {"base", "arm", "hand", "moon", "camera"};
    ob_node *n[5];
    for (int i = 0; i < 5; i++) {
        ob_node *parent = i == 1 ? n[0] : i == 2 ? n[1] : NULL;
        n[i] = ob_node_create(sc->s, parent, names[i], &r);
        if (!n[i]) return r;
    }
    double p[3];
    ob_dvec3_add(offset, (const double[3]){1.37, -0.29, 2.11}, p);
    ob_node_set_position(n[0], p);
    ob_node_set_rotation(n[0], (const float[4]){0.1f, 0.2f, 0.3f, 0.9f});
    ob_node_set_position(n[1], (const double[3]){0.31, 1.13, -0.77});
    ob_node_set_scale(n[1], (const float[3]){0.5f, 1.5f, 1.0f});
    ob_node_set_position(n[2], (const double[3]){0.05, 0.6, 0.1});
    if ((r = ob_node_add_rotation_controller(n[2], (const float[3]){1, 1, 0}, 2.0f)) != OB_OK) return r;
    double center[3];
    ob_dvec3_add(offset, (const double[3]){-0.5, 0.25, 0.4}, center);
    r = ob_node_add_orbit_controller(n[3], center, (const float[3]){0, 1, 0.2f}, 3.3, 0.7f, 0.1f);
    if (r != OB_OK) return r;
    sc->cam = n[4];
    ob_dvec3_add(offset, (const double[3]){0.23, 1.71, 6.07}, p);
    ob_node_set_position(sc->cam, p);
    if ((r = ob_node_set_camera(sc->cam, &(ob_camera_desc){0})) != OB_OK) return r;
    for (int i = 0; i < 4; i++) {
        sc->items[i] = n[i];
        r = ob_node_set_renderable(n[i], &(ob_renderable){.local_center = {0.1f, 0, 0},
                                                           .local_radius = 0.5f});
        if (r != OB_OK) return r;
    }
    if ((r = ob_scene_update(sc->s, 0.0)) != OB_OK) return r;
    double target[3];
    ob_node_world_position(n[0], target);
    if ((r = ob_node_look_at(sc->cam, target, (const double[3]){0, 1, 0})) != OB_OK) return r;
    for (int i = 0; i < 30 && r == OB_OK; i++) r = ob_scene_update(sc->s, 1.0 / 60.0);
    return r;
}

static double matrix_rel_diff(const float a[16], const float b[16])
{
    double worst = 0;
    for (int i = 0; i < 16; i++)
        worst = fmax(worst, fabs((double)a[i] - b[i]) / fmax(1.0, fabs((double)b[i])));
    return worst;
}

ob_result ob_stab_scene_matrices(ob_stab_ctx *c)
{
    static const double offsets[][3] = {{1e7, 1e7, 1e7}, {-1e7, 3e6, -1e7}, {1e7, 0, 0}};
    small_scene ref, far = {0};
    ob_result r = build_small_scene(&ref, (const double[3]){0, 0, 0});
    double worst = 0, naive_worst = 0, ms[3];
    uint32_t culled = 0;
    for (size_t o = 0; o < OB_ARRAY_COUNT(offsets) && r == OB_OK; o++) {
        uint64_t t0 = ob_time_ns();
        r = build_small_scene(&far, offsets[o]);
        ms[o] = (double)(ob_time_ns() - t0) * 1e-6;
        if (r != OB_OK) break;
        double ref_eye[3], eye[3];
        ob_node_world_position(ref.cam, ref_eye);
        ob_node_world_position(far.cam, eye);
        float a[16], b[16];
        ob_node_view_relative(ref.cam, ref_eye, a);
        ob_node_view_relative(far.cam, eye, b);
        worst = fmax(worst, matrix_rel_diff(b, a));
        float proj[16], vp[16];
        ob_math_perspective_reverse_z(1.0f, 1.5f, 0.1f, proj);
        ob_mat4_mul(proj, b, vp);
        ob_frustum f;
        ob_frustum_from_matrix(vp, &f);
        for (int i = 0; i < 4; i++) {
            ob_node_world_relative(ref.items[i], ref_eye, a);
            ob_node_world_relative(far.items[i], eye, b);
            worst = fmax(worst, matrix_rel_diff(b, a));
            double center[3];
            float radius, rel[3];
            ob_node_world_sphere(far.items[i], center, &radius);
            for (int k = 0; k < 3; k++) rel[k] = (float)(center[k] - eye[k]);
            culled += !ob_frustum_test_sphere(&f, rel, radius);
            /* What a float world matrix would give: proof the offset matters. */
            ob_daffine wa;
            ob_node_world_affine(far.items[i], &wa);
            for (int k = 0; k < 3; k++)
                naive_worst = fmax(naive_worst, fabs(((float)wa.t[k] - (float)eye[k]) - (double)a[12 + k]));
        }
        ob_scene_destroy(far.s);
        far.s = NULL;
    }
    if (far.s) ob_scene_destroy(far.s);
    if (ref.s) ob_scene_destroy(ref.s);
    if (r != OB_OK) {
        OB_LOG_E("bench", "stability: scene at 1e7 could not be built: %s", ob_result_name(r));
        return r;
    }
    return ob_stab_add(c, "large_coordinates matrices",
                       "max relative element difference of the camera-relative view and world "
                       "matrices at 1e7 vs the origin",
                       worst, "relative", 1e-6, naive_worst > 0.01 && culled == 0,
                       ob_median(ms, 3),
                       "3 offsets; hierarchy with scale, controllers, camera; float world "
                       "matrices would be off by %.3g units (must be > 0.01); items culled %u "
                       "(must be 0); ms = build + 31 updates", naive_worst, culled);
}

/* ------------------------------------------------------- scales */

#define SCALE_W 128
#define SCALE_H 96

/* Ground, two boxes and a shadowed sun, all lengths (near plane too) times s. */
static ob_result render_scaled(ob_stab_ctx *c, double s, uint8_t **out_img, bool *out_shadow)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = SCALE_W, .height = SCALE_H,
                                                      .clear_color = {0.2f, 0.4f, 0.6f, 1.0f},
                                                      .znear = (float)(0.05 * s)});
    ob_material *ground = ob_world_material(&w.world, "ground", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *red = ob_world_material(&w.world, "red", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    ob_material *blue = ob_world_material(&w.world, "blue", OB_MATERIAL_LIT, 0.1f, 0.3f, 0.9f, true);
    float fs = (float)s;
    ob_stab_scale(ob_world_entity(&w.world, NULL, "ground", w.world.plane, ground, 0, 0, 0), fs, fs, fs);
    ob_node *n = ob_world_entity(&w.world, NULL, "cube", w.world.box, red, -0.7 * s, 0.5 * s, 0.3 * s);
    ob_stab_scale(n, fs, fs, fs);
    if (n) ob_node_set_euler(n, 0.0f, 0.5f, 0.0f);
    n = ob_world_entity(&w.world, NULL, "tall", w.world.box, blue, 0.6 * s, 0.75 * s, -0.8 * s);
    ob_stab_scale(n, 0.5f * fs, 1.5f * fs, 0.5f * fs);
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3 * s, 8 * s, 4 * s);
    ob_world_look(&w.world, 0.3 * s, 2.2 * s, 4.1 * s, 0, 0.4 * s, 0);
    const ob_frame_stats *st;
    *out_img = ob_stab_render(&w, &st);
    *out_shadow = ob_world_shadow_cascades(st, "sun", NULL) > 0;
    ob_stab_frame(&w, OB_THREADING_SINGLE);   /* timed: the first frame makes pipelines */
    ob_result r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}

ob_result ob_stab_scale_invariance(ob_stab_ctx *c)
{
    enum { N = SCALE_W * SCALE_H };
    static const double small[] = {1e-30, 1e-20, 1e-12, 1e-9, 1e-6, 1e-3, 0x1p-40, 0x1p-20};
    static const double large[] = {1e3, 1e6, 1e12, 1e15, 1e18, 1e24, 1e30, 0x1p20, 0x1p60};
    static const struct { const char *name; const double *s; uint32_t n; } groups[] = {
        {"scale_invariance 1e-30..1e-3", small, OB_ARRAY_COUNT(small)},
        {"scale_invariance 1e3..1e30", large, OB_ARRAY_COUNT(large)},
    };
    uint8_t *unit = NULL;
    bool shadow = false;
    ob_result r = render_scaled(c, 1.0, &unit, &shadow);
    bool unit_shadow = shadow;
    ob_stab_take_ms(c);
    for (size_t g = 0; g < OB_ARRAY_COUNT(groups) && r == OB_OK; g++) {
        uint32_t worst = 0, worst_count = 0;
        double worst_s = groups[g].s[0];
        bool all_shadowed = unit_shadow;
        for (uint32_t i = 0; i < groups[g].n && r == OB_OK; i++) {
            uint8_t *img = NULL;
            r = render_scaled(c, groups[g].s[i], &img, &shadow);
            uint32_t d = ob_rgba_max_diff(unit, img, N);
            all_shadowed &= shadow;
            if (d > worst || i == 0) {
                worst = d;
                worst_s = groups[g].s[i];
                worst_count = ob_rgba_diff_count(unit, img, N, 0);
            }
            ob_free(img);
        }
        char worst_at[64] = "identical at every one";
        if (worst > 0)
            snprintf(worst_at, sizeof worst_at, "worst at %.3g: %u of %u pixels differ", worst_s,
                     worst_count, N);
        /* 1 level, not 0: the metallic-roughness model's Fresnel reads the
         * view vector at every pixel (Blinn-Phong did only inside a
         * highlight), and the camera-relative positions round differently
         * at scales that are not powers of 2 (those stay identical), so a
         * pixel sitting on a level's edge may step by one. */
        if (r == OB_OK)
            r = ob_stab_add(c, groups[g].name, "max abs pixel difference against scale 1 (camera, "
                                               "near plane, shadow fit scaled too)",
                            worst, "levels/255", 1, all_shadowed, ob_stab_take_ms(c),
                            "%u scales incl. powers of 2, %s; shadow view ran at every scale: %s",
                            groups[g].n, worst_at, all_shadowed ? "yes" : "NO");
    }
    if (r == OB_OK) {
        uint8_t *img = NULL;
        r = render_scaled(c, 1e36, &img, &shadow);
        if (r == OB_OK)
            r = ob_stab_add(c, "scale_invariance 1e36", "the same at 1e36, where clip coordinates "
                                                        "near FLT_MAX overflow (measured only)",
                            ob_rgba_max_diff(unit, img, N), "levels/255", NAN, true,
                            ob_stab_take_ms(c), "%u of %u pixels differ",
                            ob_rgba_diff_count(unit, img, N, 0), N);
        ob_free(img);
    }
    ob_free(unit);
    return r;
}

/* ------------------------------------------------------------ chains */

/* Level k is translated by (1,0,0) and rotated by th about u relative to
 * level k-1: p_k = k x_par + C_k x_perp + S_k (u x x) with the closed-form
 * sums C_k, S_k of cos(j th), sin(j th) — no code shared with the engine. */
static void chain_reference(const double u[3], double th, uint32_t k, double dest[3])
{
    const double x[3] = {1, 0, 0};
    double par[3], perp[3], ux[3];
    ob_dvec3_scale(u, ob_dvec3_dot(u, x), par);
    ob_dvec3_sub(x, par, perp);
    ob_dvec3_cross(u, x, ux);
    double h = sin(th / 2);
    double ck = sin(k * th / 2) * cos((k - 1.0) * th / 2) / h;
    double sk = sin(k * th / 2) * sin((k - 1.0) * th / 2) / h;
    for (int i = 0; i < 3; i++) dest[i] = k * par[i] + ck * perp[i] + sk * ux[i];
}

ob_result ob_stab_deep_hierarchy(ob_stab_ctx *c, uint32_t levels)
{
    ob_result r;
    ob_scene *s = ob_scene_create(&r);
    ob_node **chain = ob_malloc(levels * sizeof *chain);
    if (!s || !chain) {
        if (!chain) r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free;
    }
    double axis[3] = {0.3, 0.5, 0.8};
    ob_dvec3_normalize(axis, axis);
    const double half = 0.0005;   /* 0.001 rad per level */
    const float qf[4] = {(float)(axis[0] * sin(half)), (float)(axis[1] * sin(half)),
                         (float)(axis[2] * sin(half)), (float)cos(half)};
    ob_node *parent = NULL;
    for (uint32_t k = 0; k < levels; k++) {
        chain[k] = parent = ob_node_create(s, parent, "link", &r);
        if (!parent) goto fail_free;
        ob_node_set_position(parent, (const double[3]){1, 0, 0});
        ob_node_set_rotation(parent, qf);
    }
    /* The engine uses the float quaternion as given: its exact axis and angle
     * are the reference's (read back: GCC may skip the float rounding of qf). */
    double stored[4], u[3];
    ob_node_get_rotation(chain[0], stored);
    double th = 2.0 * atan2(ob_dvec3_length(stored), stored[3]);
    ob_dvec3_normalize(stored, u);
    r = ob_node_set_renderable(chain[levels - 1], &(ob_renderable){.local_radius = 1});
    if (r != OB_OK) goto fail_free;
    double ms[3];
    for (int i = 0; i < 3; i++) {
        uint64_t t0 = ob_time_ns();
        r = ob_scene_update(s, 1.0 / 60.0);
        ms[i] = (double)(ob_time_ns() - t0) * 1e-6;
        if (r != OB_OK) goto fail_free;
    }
    /* Bound (the test's): |p_k - ref_k| <= 1e-9 k, the error relative to the
     * length of chain walked so far. */
    double worst = 0.0;
    uint32_t worst_level = 0, sampled = 0;
    for (uint32_t k = 1; k <= levels; k++) {
        if (k % 97 && k != levels && k > 50) continue;
        double p[3], ref[3], d[3];
        ob_node_world_position(chain[k - 1], p);
        chain_reference(u, th, k, ref);
        ob_dvec3_sub(p, ref, d);
        double err = ob_dvec3_length(d) / k;
        sampled++;
        if (err > worst) {
            worst = err;
            worst_level = k;
        }
    }
    ob_daffine wa;
    ob_node_world_affine(chain[levels - 1], &wa);
    double q[4], rot[9], rot_err = 0;
    ob_dquat_from_axis_angle(u, levels * th, q);
    ob_dquat_to_mat3(q, rot);
    for (int i = 0; i < 9; i++) rot_err = fmax(rot_err, fabs(wa.m[i] - rot[i]));
    double update_ms = ob_median(ms, 3);
    /* Edits on the deep chain stay iterative too: the cycle check walks every
     * ancestor, destroy frees the whole chain. */
    static const char *const expect[] = {"would make a cycle", NULL};
    uint32_t before, after;
    ob_scene_renderables(s, &before);
    ob_stab_expect(c, expect);
    ob_result cycle = ob_node_set_parent(s, chain[0], chain[levels - 1]);
    bool named = ob_stab_log_has(c, "'link'", "would make a cycle", NULL);
    ob_stab_expect(c, NULL);
    ob_node_destroy(chain[0]);
    ob_scene_renderables(s, &after);
    bool edits = before == 1 && cycle == OB_ERR_INVALID_ARGUMENT && named &&
                 ob_scene_node_count(s) == 1 && after == 0 && ob_scene_update(s, 0.0) == OB_OK;
    char name[48];
    snprintf(name, sizeof name, "deep_hierarchy %u position", levels);
    r = ob_stab_add(c, name, "world position vs double closed form: max |p_k - ref_k| / k over "
                             "sampled levels k", worst, "rel./level", 1e-9, edits, update_ms,
                    "%u levels sampled, worst at level %u; cycle refused and named, chain "
                    "destroyed: %s; ms = one ob_scene_update of the chain (median of 3)",
                    sampled, worst_level, edits ? "yes" : "NO");
    if (r == OB_OK) {
        snprintf(name, sizeof name, "deep_hierarchy %u rotation", levels);
        r = ob_stab_add(c, name, "last level's world rotation vs rotation by levels*th: max "
                                 "element difference", rot_err, "abs", 1e-9, true, update_ms,
                        "total angle %.4g rad about (%.3f, %.3f, %.3f)", levels * th, u[0], u[1],
                        u[2]);
    }
    ob_free(chain);
    ob_scene_destroy(s);
    return r;

fail_free:
    OB_LOG_E("bench", "stability: %u-level chain could not be built: %s", levels, ob_result_name(r));
    ob_free(chain);
    if (s) ob_scene_destroy(s);
    return r;
}

/* ------------------------------------------------- long incremental runs */

ob_result ob_stab_long_run_rotation(ob_stab_ctx *c)
{
    const uint32_t full = 10000000, updates = c->quick ? 1000000 : full;
    ob_result r;
    ob_scene *s = ob_scene_create(&r);
    ob_node *n = s ? ob_node_create(s, NULL, "turntable", &r) : NULL;
    ob_node *child = n ? ob_node_create(s, n, "on-top", &r) : NULL;
    const float axis[3] = {0.2f, -0.7f, 0.4f};
    const float rate = 1.3f;
    const double dt = 1.0 / 60.0;
    if (child) r = ob_node_add_rotation_controller(n, axis, rate);
    if (!child || r != OB_OK) goto fail_destroy_scene;
    ob_node_set_position(child, (const double[3]){0, 1, 0});
    uint64_t t0 = ob_time_ns();
    for (uint32_t i = 0; i < updates && r == OB_OK; i++) r = ob_scene_update(s, dt);
    double ms = (double)(ob_time_ns() - t0) * 1e-6;
    if (r != OB_OK) goto fail_destroy_scene;

    double q[4];
    ob_node_get_rotation(n, q);
    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    /* Orthonormality of the double world matrix and of the float one the GPU gets. */
    ob_daffine wa;
    ob_node_world_affine(n, &wa);
    float m[16];
    ob_node_world_relative(n, (const double[3]){0, 0, 0}, m);
    double ortho = 0;
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            double dd = ob_dvec3_dot(&wa.m[a * 3], &wa.m[b * 3]), df = 0;
            for (int k = 0; k < 3; k++) df += (double)m[a * 4 + k] * m[b * 4 + k];
            ortho = fmax(ortho, fmax(fabs(dd - (a == b)), fabs(df - (a == b))));
        }
    }
    double ax[3] = {axis[0], axis[1], axis[2]}, expect[4];
    ob_dquat_from_axis_angle(ax, (double)updates * (rate * dt), expect);
    double dot = 0, drift = 0;
    for (int k = 0; k < 4; k++) dot += q[k] * expect[k];
    for (int k = 0; k < 4; k++) drift = fmax(drift, fabs(q[k] - (dot < 0 ? -1.0 : 1.0) * expect[k]));
    double p[3];
    ob_node_world_position(child, p);
    ob_scene_destroy(s);

    char what[80];
    if (updates == full) snprintf(what, sizeof what, "%u updates at 60 Hz", updates);
    else snprintf(what, sizeof what, "--quick: %u of the full run's %u updates", updates, full);
    double ns = ms * 1e6 / updates;
    r = ob_stab_add(c, "long_run_rotation |q|-1", "| |q| - 1 | of the rotation controller's node",
                    fabs(len - 1.0), "abs", 1e-6, true, ms, "%s, %.0f ns per update", what, ns);
    if (r == OB_OK)
        r = ob_stab_add(c, "long_run_rotation orthonormality",
                        "max |R^T R - I| of the world matrix (double, and the float one for the GPU)",
                        ortho, "abs", 1e-6, true, ms, "%s", what);
    if (r == OB_OK)
        r = ob_stab_add(c, "long_run_rotation drift",
                        "max quaternion component difference against the analytic rotation",
                        drift, "abs", 1e-6, true, ms, "%s; total angle %.4g rad", what,
                        (double)updates * (rate * dt));
    if (r == OB_OK)
        r = ob_stab_add(c, "long_run_rotation child", "| distance of a child at (0,1,0) - 1 |",
                        fabs(ob_dvec3_length(p) - 1.0), "units", 1e-9, true, ms, "%s", what);
    return r;

fail_destroy_scene:
    OB_LOG_E("bench", "stability: rotation run failed: %s", ob_result_name(r));
    if (s) ob_scene_destroy(s);
    return r;
}
