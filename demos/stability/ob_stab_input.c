/* Stability cases about degenerate and invalid input, rendered: each image is
 * compared with the scene without the bad part (promised: no pixel differs,
 * none turned NaN-black) and the message a user would read is checked.
 * tests/gpu/test_extreme_input.c and (the far entity) test_extreme_scale.c
 * run these cases and assert on their rows. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_stab_world.h"

#define W 128
#define H 96
#define N (W * H)

/* A linear clear colour: the image shows its tone-mapped sRGB levels. */
static const ob_stab_world_desc desc = {.width = W, .height = H,
                                        .clear_color = {0.2f, 0.4f, 0.6f, 1.0f}};

/* Within one level of the composite's output for the clear colour (the
 * GPU's arithmetic may round the other way). */
static bool is_clear(const ob_composite_view *cv, const uint8_t *p)
{
    for (int i = 0; i < 3; i++)
        if (abs(p[i] - ob_composite_view_output_level(cv, desc.clear_color[i])) > 1) return false;
    return true;
}

static uint32_t not_clear(const ob_stab_world *w, const uint8_t *img)
{
    if (!w->world.stack) return N;
    uint32_t n = 0;
    for (uint32_t i = 0; img && i < N; i++)
        n += !is_clear(w->world.stack->composite, img + 4 * i) || img[4 * i + 3] != 255;
    return n;
}

/* A lit ground, two shadow-casting boxes and a shadowed sun. */
typedef struct base_scene {
    ob_material *ground, *red, *mirror;
    ob_node *sun;
} base_scene;

static base_scene build_base(ob_stab_world *w)
{
    base_scene b;
    b.ground = ob_world_material(&w->world, "stab-ground", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    b.red = ob_world_material(&w->world, "stab-red", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    b.mirror = ob_world_material(&w->world, "stab-mirror", OB_MATERIAL_REFLECTIVE, 0.9f, 0.9f, 0.9f, true);
    ob_world_entity(&w->world, NULL, "ground", w->world.plane, b.ground, 0, 0, 0);
    ob_world_entity(&w->world, NULL, "left", w->world.box, b.red, -0.8, 0.5, 0);
    ob_world_entity(&w->world, NULL, "right", w->world.box, b.red, 0.8, 0.5, -0.5);
    b.sun = ob_world_light(&w->world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_world_look(&w->world, 0, 2.5, 4.5, 0, 0.4, 0);
    return b;
}

static const char *yes(bool b) { return b ? "yes" : "NO"; }

/* Ends a case: the world's failure wins over the row's. */
static ob_result finish(ob_stab_ctx *c, ob_stab_world *w, ob_result row)
{
    ob_stab_expect(c, NULL);
    ob_result r = w->world.err != OB_OK ? w->world.err : row;
    ob_stab_world_destroy(w);
    return r;
}

/* ------------------------------------------------------------ zero scale */

ob_result ob_stab_zero_scale(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    base_scene b = build_base(&w);
    ob_node *box = ob_world_entity(&w.world, NULL, "collapsed-box", w.world.box, b.red, 2.0, 1.5, -2.5);
    ob_node *ball = ob_world_entity(&w.world, NULL, "collapsed-mirror", w.world.sphere, b.mirror, -1.5, 0.5, 1.0);
    ob_stab_hide(box, true);
    ob_stab_hide(ball, true);
    uint8_t *without = ob_stab_render(&w, NULL);
    ob_stab_hide(box, false);
    ob_stab_hide(ball, false);
    ob_stab_scale(box, 0, 0, 0);
    ob_stab_scale(ball, 0, 0, 0);
    const ob_frame_stats *st;
    uint8_t *with = ob_stab_render(&w, &st);
    const ob_view_stats *main = ob_world_view_stats(st, "main");
    uint32_t black = ob_rgba_nan_black(without, with, N);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "zero_scale", "pixels differing from the scene without the two "
                                         "zero-scale entities (box, reflective sphere)",
                        ob_rgba_diff_count(without, with, N, 0), "pixels", 0, black == 0,
                        ob_stab_take_ms(c), "max abs diff %u; NaN-black pixels %u; main drew %u "
                        "items, shadow view %s", ob_rgba_max_diff(without, with, N), black,
                        main ? main->draws : 0, ob_world_shadow_cascades(st, "sun", NULL) ? "ran" : "did not run");
    ob_free(without);
    ob_free(with);
    return finish(c, &w, r);
}

/* Scale zero on one axis: a flat square whose cofactor normal matrix keeps
 * the top face's normal; it must shade like a plane of that size. */
ob_result ob_stab_flattened_box(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    ob_material *m = ob_world_material(&w.world, "green", OB_MATERIAL_LIT, 0.3f, 0.7f, 0.4f, false);
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 3);
    ob_world_look(&w.world, 0, 3, 2, 0, 0, 0);
    ob_node *flat = ob_world_entity(&w.world, NULL, "flat", w.world.box, m, 0, 0, 0);
    ob_stab_scale(flat, 2.0f, 0.0f, 2.0f);
    uint8_t *box_img = ob_stab_render(&w, NULL);
    ob_stab_hide(flat, true);
    ob_stab_scale(ob_world_entity(&w.world, NULL, "plane", w.world.plane, m, 0, 0, 0), 0.1f, 0.1f, 0.1f);
    uint8_t *plane_img = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        const uint8_t *p = box_img + ((size_t)(H / 2) * W + W / 2) * 4;
        r = ob_stab_add(c, "flattened_box", "pixels differing by more than 1 level: box scaled "
                                            "(2, 0, 2) vs a plane of that size (edge pixels only)",
                        ob_rgba_diff_count(box_img, plane_img, N, 1), "pixels", 8, p[1] > 100,
                        ob_stab_take_ms(c), "max abs diff %u; centre pixel %u,%u,%u (lit green "
                        "> 100, not NaN-black)", ob_rgba_max_diff(box_img, plane_img, N), p[0],
                        p[1], p[2]);
    }
    ob_free(box_img);
    ob_free(plane_img);
    return finish(c, &w, r);
}

/* ------------------------------------------------------------ camera */

ob_result ob_stab_up_parallel(ob_stab_ctx *c)
{
    static const char *const expect[] = {"parallel to the view direction", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    build_base(&w);
    ob_stab_position(w.world.stack->camera, 0, 6, 0);
    ob_stab_expect(c, expect);
    ob_result look = w.world.err == OB_OK ? ob_node_look_at(w.world.stack->camera, (const double[3]){0, 0, 0},
                                                      (const double[3]){0, 1, 0})
                                    : w.world.err;
    bool named = ob_stab_log_has(c, "'camera'", "parallel", NULL);
    ob_stab_expect(c, NULL);
    uint8_t *fallback = ob_stab_render(&w, NULL);
    if (w.world.err == OB_OK && look == OB_OK)
        look = ob_node_look_at(w.world.stack->camera, (const double[3]){0, 0, 0}, (const double[3]){0, 0, 1});
    uint8_t *explicit_up = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        uint32_t clear_like = N - not_clear(&w, fallback);
        r = ob_stab_add(c, "up_parallel_to_direction", "max abs pixel difference: look_at straight "
                                                       "down with up (0,1,0) vs explicit up (0,0,1)",
                        ob_rgba_max_diff(fallback, explicit_up, N), "levels/255", 0,
                        look == OB_OK && named && clear_like < N / 2, ob_stab_take_ms(c),
                        "%u pixels differ; look_at accepted: %s; log names the camera: %s; "
                        "clear-colour pixels %u (< half: the boxes are in view)",
                        ob_rgba_diff_count(fallback, explicit_up, N, 0), yes(look == OB_OK),
                        yes(named), clear_like);
    }
    ob_free(fallback);
    ob_free(explicit_up);
    return finish(c, &w, r);
}

/* Zero-size views and invalid cameras are refused with their name logged;
 * the frame goes on unchanged. */
ob_result ob_stab_refused_views(ob_stab_ctx *c)
{
    static const char *const expect[] = {"'degenerate'", "'bad-camera'", NULL};
    static const uint32_t sizes[][2] = {{0, 64}, {64, 0}, {0, 0}};
    static const ob_camera_desc bad_cams[] = {
        {.fovy = 3.5f}, {.fovy = -1.0f}, {.znear = -0.1f}, {.aspect = -1.0f}, {.fovy = NAN},
        {.znear = INFINITY},
    };
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    build_base(&w);
    uint8_t *before = ob_stab_render(&w, NULL);
    uint32_t accepted = 0, wrong_result = 0, unnamed = 0;
    for (size_t i = 0; i < OB_ARRAY_COUNT(sizes) && w.world.err == OB_OK; i++) {
        ob_stab_expect(c, expect);
        ob_result res = OB_OK;
        ob_perspective_desc pd = {.name = "degenerate", .camera = w.world.stack->camera,
                                  .width = sizes[i][0], .height = sizes[i][1]};
        ob_perspective_view *v = ob_perspective_view_create(w.world.stack->views, &pd, &res);
        if (v) {
            accepted++;
            ob_perspective_view_destroy(w.world.stack->views, v);
        }
        wrong_result += !v && res != OB_ERR_INVALID_ARGUMENT;
        unnamed += !ob_stab_log_has(c, "'degenerate'", "width and height", NULL);
    }
    ob_result res = OB_OK;
    ob_node *bad = w.world.err == OB_OK ? ob_node_create(w.world.stack->scene, NULL, "bad-camera", &res) : NULL;
    if (!bad && w.world.err == OB_OK) w.world.err = res;
    for (size_t i = 0; i < OB_ARRAY_COUNT(bad_cams) && bad; i++) {
        ob_stab_expect(c, expect);
        res = ob_node_set_camera(bad, &bad_cams[i]);
        accepted += res == OB_OK;
        wrong_result += res != OB_OK && res != OB_ERR_INVALID_ARGUMENT;
        unnamed += !ob_stab_log_has(c, "'bad-camera'", NULL);
    }
    ob_stab_expect(c, NULL);
    bool no_camera = bad && !ob_node_get_camera(bad);
    uint8_t *after = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        uint32_t diff = ob_rgba_diff_count(before, after, N, 0);
        r = ob_stab_add(c, "refused_views_and_cameras",
                        "bad descs accepted: zero-size views (3) and cameras with fovy 3.5/-1/NaN, "
                        "znear -0.1/Inf, aspect -1 (6)",
                        accepted, "accepted", 0, wrong_result == 0 && unnamed == 0 && no_camera &&
                        diff == 0, ob_stab_take_ms(c),
                        "frame after: %u pixels differ (must be 0); refusals without "
                        "OB_ERR_INVALID_ARGUMENT %u, without the name in the log %u",
                        diff, wrong_result, unnamed);
    }
    ob_free(before);
    ob_free(after);
    return finish(c, &w, r);
}

/* ------------------------------------------------------- empty and lights */

ob_result ob_stab_empty_scene(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_world_light(&w.world, OB_LIGHT_POINT, false, 2.0f, 0, 2, 0);
    uint32_t worst = 0;
    bool ok = true;
    ob_skip_reason main_skip = OB_SKIP_NONE, shadow_skip = OB_SKIP_NONE;
    for (int mode = 0; mode < 4 && w.world.err == OB_OK; mode++) {
        const ob_frame_stats *st = ob_stab_frame(&w, mode % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE);
        uint8_t *img = ob_stab_snapshot(&w);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        main_skip = main ? main->skipped : OB_SKIP_ERROR;
        shadow_skip = ob_world_skip_reason(st, "shadow:sun");
        ok &= main_skip == OB_SKIP_EMPTY && shadow_skip == OB_SKIP_NO_CASTERS &&
              ob_world_shadow_cascades(st, "sun", NULL) == 0;
        if (img) worst = OB_MAX(worst, not_clear(&w, img));
        ob_free(img);
    }
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "empty_scene", "pixels other than the clear colour: lights (one "
                                          "shadowed) but nothing to draw, ST and MT",
                        worst, "pixels", 0, ok, ob_stab_take_ms(c), "main: %s, shadow:sun: %s",
                        ob_skip_reason_name(main_skip), ob_skip_reason_name(shadow_skip));
    return finish(c, &w, r);
}

/* A light switched off (intensity 0, or hidden) lights nothing and costs no
 * shadow view. */
ob_result ob_stab_light_off(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    base_scene b = build_base(&w);
    ob_node *lamp = ob_world_light(&w.world, OB_LIGHT_POINT, false, 1.0f, 1, 2, 1);
    ob_stab_hide(b.sun, true);
    ob_stab_hide(lamp, true);
    const ob_frame_stats *st;
    uint8_t *off = ob_stab_render(&w, &st);
    bool absent = ob_world_shadow_cascades(st, "sun", NULL) == 0;
    if (lamp) ob_node_destroy(lamp);
    ob_stab_hide(b.sun, false);
    ob_result set = OB_OK;
    if (b.sun) {
        ob_light_desc dark = *ob_node_get_light(b.sun);
        dark.intensity = 0.0f;
        set = ob_node_set_light(b.sun, &dark);
    }
    uint8_t *zero = ob_stab_render(&w, &st);
    absent &= ob_world_shadow_cascades(st, "sun", NULL) == 0;
    ob_skip_reason skip = ob_world_skip_reason(st, "shadow:sun");
    if (b.sun) ob_node_destroy(b.sun);
    uint8_t *none = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        uint32_t d_zero = ob_rgba_diff_count(zero, none, N, 0);
        uint32_t d_off = ob_rgba_diff_count(off, none, N, 0);
        r = ob_stab_add(c, "light_intensity_0", "pixels differing from the scene without the "
                                                "light: sun at intensity 0 (and hidden lights)",
                        OB_MAX(d_zero, d_off), "pixels", 0,
                        set == OB_OK && absent && skip == OB_SKIP_NOT_NEEDED, ob_stab_take_ms(c),
                        "intensity 0: %u px, hidden: %u px; shadow view left out: %s (%s)",
                        d_zero, d_off, yes(absent), ob_skip_reason_name(skip));
    }
    ob_free(off);
    ob_free(zero);
    ob_free(none);
    return finish(c, &w, r);
}

/* ------------------------------------------------------ non-finite input */

static void apply_bad(ob_node *n, int which)
{
    switch (which) {
    case 0: ob_node_set_position(n, (const double[3]){NAN, 0, 0}); break;
    case 1: ob_node_set_position(n, (const double[3]){0, -INFINITY, 0}); break;
    case 2: ob_node_set_scale(n, (const float[3]){1, INFINITY, 1}); break;
    case 3: ob_node_set_rotation(n, (const float[4]){0, NAN, 0, 1}); break;
    default: ob_node_set_rotation(n, (const float[4]){0, 0, 0, 0}); break;
    }
}

/* An entity (with a child) with NaN or Inf in its transform is left out
 * and named; the rest renders as without it; fixed, it is back. */
ob_result ob_stab_non_finite_transform(ob_stab_ctx *c)
{
    static const char *const names[] = {"NaN position", "-Inf position", "Inf scale",
                                        "NaN rotation", "zero rotation"};
    static const char *const expect[] = {"'bad-entity'", "'bad-child'", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    base_scene b = build_base(&w);
    ob_node *bad = ob_world_entity(&w.world, NULL, "bad-entity", w.world.box, b.red, 0, 0.5, 1.2);
    ob_world_entity(&w.world, bad, "bad-child", w.world.sphere, b.mirror, 0, 1.0, 0);
    uint8_t *good = ob_stab_render(&w, NULL);
    ob_stab_hide(bad, true);
    uint8_t *without = ob_stab_render(&w, NULL);
    ob_stab_hide(bad, false);
    bool visible = ob_rgba_max_diff(good, without, N) > 0;
    ob_stab_take_ms(c);
    ob_result r = OB_OK;
    for (int i = 0; i < 5 && w.world.err == OB_OK && r == OB_OK; i++) {
        double pos[3], rot[4];
        float scale[3];
        ob_node_get_position(bad, pos);
        ob_node_get_rotation(bad, rot);
        ob_node_get_scale(bad, scale);
        ob_stab_expect(c, expect);
        apply_bad(bad, i);
        const ob_frame_stats *st;
        uint8_t *img = ob_stab_render(&w, &st);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        uint32_t draws = main ? main->draws : 0;
        bool named = ob_stab_log_has(c, "'bad-entity'", "not rendered", NULL);
        bool child_named = ob_stab_log_has(c, "'bad-child'", NULL);
        ob_node_set_position(bad, pos);
        ob_node_set_rotation_d(bad, rot);
        ob_node_set_scale(bad, scale);
        uint8_t *fixed = ob_stab_render(&w, NULL);
        bool back = w.world.err == OB_OK && ob_rgba_max_diff(good, fixed, N) == 0 &&
                    ob_stab_log_has(c, "'bad-entity'", "finite again", NULL);
        ob_stab_expect(c, NULL);
        if (w.world.err == OB_OK) {
            char name[48];
            snprintf(name, sizeof name, "non_finite_transform %s", names[i]);
            uint32_t black = ob_rgba_nan_black(without, img, N);
            r = ob_stab_add(c, name, "pixels differing from the scene without the entity (it has "
                                     "a reflective child)",
                            ob_rgba_diff_count(without, img, N, 0), "pixels", 0,
                            black == 0 && named && !child_named && draws == 3 && back && visible,
                            ob_stab_take_ms(c), "NaN-black %u; main drew %u (3 expected); log "
                            "names it: %s, not its child: %s; back once fixed: %s", black, draws,
                            yes(named), yes(!child_named), yes(back));
        }
        ob_free(img);
        ob_free(fixed);
    }
    ob_free(good);
    ob_free(without);
    return finish(c, &w, r);
}

/* A light with NaN/Inf is left out; a camera with NaN renders the clear
 * colour (view and camera named); both recover. */
ob_result ob_stab_non_finite_light_camera(ob_stab_ctx *c)
{
    static const char *const expect[] = {"'lamp'", "'sun'", "'camera'", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    base_scene b = build_base(&w);
    uint8_t *good = ob_stab_render(&w, NULL);
    ob_stab_expect(c, expect);
    ob_node *lamp = ob_world_light(&w.world, OB_LIGHT_POINT, false, 3.0f, 0, 1, 1);
    ob_stab_position(lamp, NAN, 1, 1);
    uint8_t *img_lamp = ob_stab_render(&w, NULL);
    ob_stab_position(b.sun, 3, INFINITY, 4);
    const ob_frame_stats *st;
    uint8_t *img_sun = ob_stab_render(&w, &st);
    bool shadow_absent = ob_world_shadow_cascades(st, "sun", NULL) == 0;
    ob_stab_hide(b.sun, true);
    uint8_t *no_sun = ob_stab_render(&w, NULL);
    ob_stab_hide(b.sun, false);
    ob_stab_position(b.sun, 3, 8, 4);
    if (lamp) ob_node_destroy(lamp);
    double light_ms = ob_stab_take_ms(c);

    ob_stab_expect(c, expect);
    double eye[3] = {0, 2.5, 4.5};
    if (w.world.stack->camera) ob_node_get_position(w.world.stack->camera, eye);
    ob_stab_position(w.world.stack->camera, eye[0], NAN, eye[2]);
    uint8_t *img_cam = ob_stab_render(&w, NULL);
    bool named = ob_stab_log_has(c, "'main'", "'camera'", NULL);
    ob_stab_position(w.world.stack->camera, eye[0], eye[1], eye[2]);
    uint8_t *fixed = ob_stab_render(&w, NULL);
    ob_stab_expect(c, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        uint32_t d_lamp = ob_rgba_diff_count(good, img_lamp, N, 0);
        uint32_t d_sun = ob_rgba_diff_count(no_sun, img_sun, N, 0);
        uint32_t black = ob_rgba_nan_black(good, img_lamp, N) + ob_rgba_nan_black(no_sun, img_sun, N);
        r = ob_stab_add(c, "non_finite_light", "pixels differing from the scene without the "
                                               "light: NaN point light; Inf sun vs hidden sun",
                        OB_MAX(d_lamp, d_sun), "pixels", 0, shadow_absent && black == 0, light_ms,
                        "NaN lamp %u px, Inf sun %u px; NaN-black %u; Inf sun's shadow view left "
                        "out: %s", d_lamp, d_sun, black, yes(shadow_absent));
        bool back = ob_rgba_max_diff(good, fixed, N) == 0;
        if (r == OB_OK)
            r = ob_stab_add(c, "non_finite_camera", "pixels other than the clear colour with a NaN "
                                                    "camera position",
                            not_clear(&w, img_cam), "pixels", 0, named && back, ob_stab_take_ms(c),
                            "log names view and camera: %s; image as before once fixed: %s",
                            yes(named), yes(back));
    }
    ob_free(good);
    ob_free(img_lamp);
    ob_free(img_sun);
    ob_free(no_sun);
    ob_free(img_cam);
    ob_free(fixed);
    return finish(c, &w, r);
}

/* NaN/Inf given to material setters and to a new material: refused, named,
 * the image unchanged. */
ob_result ob_stab_non_finite_material(ob_stab_ctx *c)
{
    static const char *const expect[] = {"'stab-red'", "'stab-ground'", "'stab-mirror'",
                                         "'nan-material'", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    base_scene b = build_base(&w);
    uint8_t *before = ob_stab_render(&w, NULL);
    uint32_t refused = 0;
    uint64_t errors = 0;
    bool named = false;
    if (w.world.err == OB_OK) {
        ob_stab_expect(c, expect);
        errors = ob_stab_expected_errors(c);
        refused += ob_material_set_diffuse(b.red, (const float[4]){NAN, 0, 0, 1}) == OB_ERR_NON_FINITE;
        refused += ob_material_set_specular(b.red, (const float[4]){1, 1, 1, INFINITY}) ==
                   OB_ERR_NON_FINITE;
        refused += ob_material_set_emissive(b.ground, (const float[4]){0, -INFINITY, 0, 0}) ==
                   OB_ERR_NON_FINITE;
        refused += ob_material_set_reflectivity(b.mirror, NAN) == OB_ERR_NON_FINITE;
        errors = ob_stab_expected_errors(c) - errors;
        ob_result res = OB_OK;
        ob_material *m = ob_material_create(
            w.world.stack->materials, &(ob_material_desc){.name = "nan-material", .diffuse = {1, NAN, 1, 1}}, &res);
        refused += !m && res == OB_ERR_NON_FINITE;
        named = ob_stab_log_has(c, "'stab-red'", "non-finite", NULL) &&
                ob_stab_log_has(c, "'nan-material'", NULL);
        ob_stab_expect(c, NULL);
    }
    uint8_t *after = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "non_finite_material", "pixels differing after NaN/Inf given to 4 "
                                                  "material setters and a create (all refused)",
                        ob_rgba_diff_count(before, after, N, 0), "pixels", 0,
                        refused == 5 && named && errors >= 4, ob_stab_take_ms(c),
                        "%u of 5 refused with OB_ERR_NON_FINITE; named in the log: %s; errors "
                        "logged by the 4 setters %llu", refused, yes(named),
                        (unsigned long long)errors);
    ob_free(before);
    ob_free(after);
    return finish(c, &w, r);
}

/* NaN written to a parameter directly: refused, the slot keeps its value. */
ob_result ob_stab_non_finite_parameter(ob_stab_ctx *c)
{
    static const char *const expect[] = {"'AmbientColor'", "'WorldMatrix'", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    build_base(&w);
    uint8_t *before = ob_stab_render(&w, NULL);
    uint32_t refused = 0;
    bool kept = false, named = false, found = false;
    if (w.world.err == OB_OK) {
        ob_param_registry *reg = ob_renderer_registry(w.world.stack->renderer);
        ob_params *params = ob_renderer_params(w.world.stack->renderer);
        ob_param ambient = ob_param_find(reg, "AmbientColor");
        ob_param world = ob_param_registry_builtins(reg)->world;
        const float good[4] = {0.5f, 0.25f, 0.125f, 1.0f};
        found = ambient.id != 0 && ob_params_set_vec4(params, ambient, good) == OB_OK;
        ob_stab_expect(c, expect);
        refused += ob_params_set_vec4(params, ambient, (const float[4]){NAN, 0, 0, 1}) ==
                   OB_ERR_NON_FINITE;
        float now[4] = {0, 0, 0, 0};
        kept = ob_params_get_vec4(params, ambient, now) == OB_OK && !memcmp(now, good, sizeof good);
        refused += ob_params_init_vec4(reg, ambient, (const float[4]){0, INFINITY, 0, 1}) ==
                   OB_ERR_NON_FINITE;
        float m[16];
        ob_mat4_identity(m);
        m[13] = NAN;
        refused += ob_params_set_mat4(params, world, m) == OB_ERR_NON_FINITE;
        named = ob_stab_log_has(c, "'AmbientColor'", "NaN or Inf", NULL) &&
                ob_stab_log_has(c, "'WorldMatrix'", NULL);
        ob_stab_expect(c, NULL);
    }
    uint8_t *after = ob_stab_render(&w, NULL);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "non_finite_parameter", "pixels differing after NaN/Inf written to "
                                                   "AmbientColor (set, init) and WorldMatrix",
                        ob_rgba_diff_count(before, after, N, 0), "pixels", 0,
                        found && refused == 3 && kept && named, ob_stab_take_ms(c),
                        "%u of 3 refused with OB_ERR_NON_FINITE; value kept: %s; named: %s",
                        refused, yes(kept), yes(named));
    ob_free(before);
    ob_free(after);
    return finish(c, &w, r);
}

/* ------------------------------------------------- beyond float range */

/* An entity whose camera-relative bound is not a float (1e39 ahead, or
 * world scale 1e40 through a parent) is left out, named once, and the rest
 * of the image (shadow fit included) is the one without it. */
ob_result ob_stab_beyond_float(ob_stab_ctx *c)
{
    static const char *const expect[] = {"'beyond-float'", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &desc);
    ob_material *ground = ob_world_material(&w.world, "ground", OB_MATERIAL_LIT, 0.6f, 0.6f, 0.6f, false);
    ob_material *red = ob_world_material(&w.world, "red", OB_MATERIAL_LIT, 0.8f, 0.2f, 0.1f, true);
    ob_world_entity(&w.world, NULL, "ground", w.world.plane, ground, 0, 0, 0);
    ob_world_entity(&w.world, NULL, "cube", w.world.box, red, 0, 0.5, 0);
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    ob_world_look(&w.world, 0, 2.5, 4.5, 0, 0.4, 0);
    ob_result res = OB_OK;
    ob_node *parent = w.world.err == OB_OK ? ob_node_create(w.world.stack->scene, NULL, "giant-parent", &res) : NULL;
    if (!parent && w.world.err == OB_OK) w.world.err = res;
    ob_node *far = ob_world_entity(&w.world, parent, "beyond-float", w.world.box, red, 0, 0, 0);
    ob_stab_hide(far, true);
    uint8_t *without = ob_stab_render(&w, NULL);
    ob_stab_hide(far, false);
    ob_stab_take_ms(c);
    ob_result r = OB_OK;
    for (int k = 0; k < 2 && w.world.err == OB_OK && r == OB_OK; k++) {
        if (k == 0) {
            ob_stab_position(far, 0, -0.4e39, -1e39);
        } else {
            ob_stab_position(far, 0, 0, -1e-19);
            ob_stab_scale(parent, 1e20f, 1e20f, 1e20f);
            ob_stab_scale(far, 1e20f, 1e20f, 1e20f);
        }
        uint32_t worst = 0, draws[2] = {0, 0};
        bool named = false, renamed = true;
        for (int mode = 0; mode < 2; mode++) {
            ob_stab_expect(c, expect);
            const ob_frame_stats *st =
                ob_stab_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE);
            const ob_view_stats *main = ob_world_view_stats(st, "main");
            draws[mode] = main ? main->draws : 0;
            uint8_t *img = ob_stab_snapshot(&w);
            worst = OB_MAX(worst, ob_rgba_max_diff(without, img, N));
            ob_free(img);
            /* Named the first frame, not again while it stays out of range. */
            if (mode == 0) named = ob_stab_log_has(c, "'main'", "'beyond-float'", "float range", NULL);
            else renamed = ob_stab_log_has(c, "'beyond-float'", NULL);
        }
        ob_stab_expect(c, NULL);
        double ms = ob_stab_take_ms(c);
        /* Back in range, in front of the cube: drawn again. */
        ob_stab_scale(parent, 1, 1, 1);
        ob_stab_scale(far, 0.5f, 0.5f, 0.5f);
        ob_stab_position(far, 0.8, 0.25, 1.0);
        const ob_frame_stats *st = ob_stab_frame(&w, OB_THREADING_SINGLE);
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        uint8_t *img = ob_stab_snapshot(&w);
        bool back = main && main->draws == 3 && ob_rgba_max_diff(without, img, N) > 0;
        ob_free(img);
        ob_stab_take_ms(c);
        if (w.world.err == OB_OK)
            r = ob_stab_add(c, k == 0 ? "beyond_float_range 1e39 ahead"
                                      : "beyond_float_range world scale 1e40",
                            "max abs pixel difference against the scene without the entity, ST "
                            "and MT", worst, "levels/255", 0,
                            named && !renamed && draws[0] == 2 && draws[1] == 2 && back, ms,
                            "main drew %u / %u (ST / MT, 2 expected); named once: %s; drawn again "
                            "back in range: %s", draws[0], draws[1], yes(named && !renamed),
                            yes(back));
    }
    ob_free(without);
    return finish(c, &w, r);
}
