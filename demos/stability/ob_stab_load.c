/* Stability cases about extreme workloads: 64 views in one frame, the
 * 128-view cap, env-map recursion bounds 0..4, 100,000 objects single- and
 * multi-threaded, a shadow map without casters. tests/gpu/test_extreme_load.c
 * runs these cases and asserts on their rows; times are reported, never
 * judged. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_stab_world.h"
#include "ob_renderer_layer.h"

static int view_index(const ob_frame_stats *st, const char *name)
{
    for (uint32_t i = 0; st && i < st->view_count; i++)
        if (strcmp(st->views[i].name, name) == 0) return (int)i;
    return -1;
}

/* Dependency edges of views that did not execute after their dependency. */
static uint32_t order_violations(const ob_frame_stats *st, ob_view *const *views, uint32_t count,
                                 uint32_t *out_edges)
{
    uint32_t bad = 0;
    for (uint32_t i = 0; i < count; i++) {
        int at = view_index(st, views[i]->name);
        bad += at < 0;
        for (uint32_t d = 0; d < views[i]->dep_count; d++) {
            int dep_at = view_index(st, views[i]->deps[d]->name);
            bad += dep_at < 0 || dep_at >= at;
            (*out_edges)++;
        }
    }
    return bad;
}

/* ------------------------------------------------------- 64 views */

#define BALLS 62

/* 62 reflective spheres in view: 62 env maps + main + composite = 64 views,
 * every map before main; ST and MT images identical. */
ob_result ob_stab_views_64(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = 160, .height = 120,
                                                      .env_map_size = 16});
    ob_material *ground = ob_world_material(&w.world, "ground", OB_MATERIAL_LIT, 0.5f, 0.6f, 0.5f, false);
    ob_material *mirror = ob_world_material(&w.world, "mirror", OB_MATERIAL_REFLECTIVE, 0.9f, 0.8f, 0.7f, false);
    ob_world_entity(&w.world, NULL, "ground", w.world.plane, ground, 0, 0, 0);
    ob_node *spheres[BALLS];
    for (uint32_t i = 0; i < BALLS; i++) {
        char name[32];
        snprintf(name, sizeof name, "ball%02u", i);
        spheres[i] = ob_world_entity(&w.world, NULL, name, w.world.sphere, mirror, -3.5 + (i % 8), 0.5,
                                    -(double)(i / 8));
    }
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    ob_world_look(&w.world, 0, 5, 6, 0, 0, -3);
    uint8_t *img[2] = {NULL, NULL};
    uint32_t bad = 0, edges = 0, ran = 0, draws = 0, worst = 0;
    double wall[2] = {0, 0};
    for (int round = 0; round < 2 && w.world.err == OB_OK; round++) {
        for (int mode = 0; mode < 2 && w.world.err == OB_OK; mode++) {
            uint64_t t0 = ob_time_ns();
            const ob_frame_stats *st =
                ob_stab_frame(&w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE);
            wall[mode] = (double)(ob_time_ns() - t0) * 1e-6;
            if (!st) break;
            ob_view *views[BALLS + 2];
            uint32_t n = 0;
            for (uint32_t i = 0; i < BALLS; i++) {
                ob_view *v = ob_renderer_attached_view(w.world.stack->renderer, spheres[i], OB_VIEW_PARABOLOID);
                const ob_view_stats *vs = v ? ob_world_view_stats(st, v->name) : NULL;
                if (!vs || vs->skipped != OB_SKIP_NONE || vs->draws == 0) bad++;
                if (v) views[n++] = v;
            }
            int main_at = view_index(st, "main");
            for (uint32_t i = 0; i < n; i++) bad += view_index(st, views[i]->name) >= main_at;
            views[n++] = ob_perspective_view_base(w.world.stack->main);
            views[n++] = ob_composite_view_base(w.world.stack->composite);
            edges = 0;
            bad += order_violations(st, views, n, &edges);
            ran = st->view_count;
            bad += ran != 64;
            draws = st->draws;
            uint8_t *shot = ob_stab_snapshot(&w);
            if (round == 0) img[mode] = shot;
            else {
                worst = OB_MAX(worst, ob_rgba_max_diff(img[0], shot, 160 * 120));
                ob_free(shot);
            }
        }
    }
    worst = OB_MAX(worst, ob_rgba_max_diff(img[0], img[1], 160 * 120));
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "views_64", "max abs pixel difference, ST vs MT (and between frames): "
                                       "62 env maps + main + composite in one frame",
                        worst, "levels/255", 0, bad == 0, ob_stab_take_ms(c),
                        "%u views ran, %u draws; %u dependency edges, %u env maps or edges out of "
                        "order or empty; frame ST %.0f ms, MT %.0f ms", ran, draws, edges, bad,
                        wall[0], wall[1]);
    ob_free(img[0]);
    ob_free(img[1]);
    if (r == OB_OK) r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}

/* ------------------------------------------------------- view cap */

#define EXTRA (OB_MAX_FRAME_VIEWS - 2 + 1)   /* main + composite + extras = cap + 1 */

/* Perspective views up to the renderer's cap all run; one more is refused
 * (named, skip reason "error") and the rest of the frame is unaffected. */
ob_result ob_stab_view_cap(ob_stab_ctx *c)
{
    static const char *const expect[] = {"more than 128 views", NULL};
    ob_stab_world w;
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = 64, .height = 48});
    ob_material *m = ob_world_material(&w.world, "orange", OB_MATERIAL_LIT, 0.7f, 0.4f, 0.2f, false);
    ob_world_entity(&w.world, NULL, "cube", w.world.box, m, 0, 0.5, 0);
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    uint8_t *alone = ob_stab_render(&w, NULL);
    ob_perspective_view *extra[EXTRA];
    ob_view *bases[EXTRA];
    uint32_t made = 0;
    for (; made < EXTRA && w.world.err == OB_OK; made++) {
        char name[32];
        snprintf(name, sizeof name, "extra%03u", made);
        ob_perspective_desc pd = {.name = name, .camera = w.world.stack->camera, .width = 16, .height = 16,
                                  .clear_color = {0, 0, 0, 1}};
        ob_result res;
        extra[made] = ob_perspective_view_create(w.world.stack->views, &pd, &res);
        if (!extra[made]) {
            w.world.err = res;
            break;
        }
        bases[made] = ob_perspective_view_base(extra[made]);
    }
    uint32_t bad = 0, worst = 0, ran = 0;
    bool refused = true, named = true, later = false;
    const char *last = made == EXTRA ? bases[EXTRA - 1]->name : "";
    for (int mode = 0; mode < 2 && w.world.err == OB_OK; mode++) {
        ob_stab_expect(c, expect);
        const ob_frame_stats *st = ob_stab_frame_with(
            &w, mode ? OB_THREADING_MULTI : OB_THREADING_SINGLE, bases, EXTRA);
        named &= ob_stab_log_has(c, last, "more than 128 views", NULL);
        ob_stab_expect(c, NULL);
        if (!st) break;
        ran = st->view_count;
        bad += ran != OB_MAX_FRAME_VIEWS;
        for (uint32_t i = 0; i + 1 < EXTRA; i++) {
            const ob_view_stats *vs = ob_world_view_stats(st, bases[i]->name);
            bad += !vs || vs->draws != 1;
        }
        refused &= !ob_world_view_stats(st, last) &&
                   ob_world_skip_reason(st, last) == OB_SKIP_ERROR;
        ob_view *order[2] = {ob_perspective_view_base(w.world.stack->main),
                             ob_composite_view_base(w.world.stack->composite)};
        uint32_t edges = 0;
        bad += order_violations(st, order, 2, &edges);
        uint8_t *img = ob_stab_snapshot(&w);
        worst = OB_MAX(worst, ob_rgba_max_diff(alone, img, 64 * 48));
        ob_free(img);
    }
    double ms = ob_stab_take_ms(c);
    /* Refused is just late: next frame, without the crowd, it runs. */
    if (made == EXTRA) {
        const ob_frame_stats *st = ob_stab_frame_with(&w, OB_THREADING_SINGLE, &bases[EXTRA - 1], 1);
        later = ob_world_view_stats(st, last) != NULL;
    }
    ob_stab_take_ms(c);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "view_cap_128", "max abs pixel difference of the final image with 127 "
                                           "extra views queued vs alone (cap 128)",
                        worst, "levels/255", 0, bad == 0 && refused && named && later, ms,
                        "%u views ran; the 129th refused with reason error: %s, named: %s; ran "
                        "the next frame: %s; %u views missing, empty or out of order", ran,
                        refused ? "yes" : "NO", named ? "yes" : "NO", later ? "yes" : "NO", bad);
    if (w.world.stack->renderer) ob_renderer_wait_idle(w.world.stack->renderer);
    for (uint32_t i = 0; i < made; i++) ob_perspective_view_destroy(w.world.stack->views, extra[i]);
    ob_free(alone);
    if (r == OB_OK) r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}

/* ------------------------------------------------------- recursion bound */

#define REC_W 128
#define REC_H 96

/* Env-map recursion bound 0..4 (composite 0, main 1, env and shadow maps 2;
 * env maps draw their neighbours without reflections, so nothing deeper):
 * every bound renders, and the image changes less and less as it grows. */
ob_result ob_stab_env_recursion(ob_stab_ctx *c)
{
    uint8_t *img[5] = {NULL};
    uint32_t views[5] = {0}, bounded[5] = {0};
    double ms[5] = {0};
    ob_result r = OB_OK;
    for (uint32_t depth = 0; depth <= 4 && r == OB_OK; depth++) {
        ob_stab_world w;
        ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = REC_W, .height = REC_H});
        if (w.world.stack->renderer) ob_renderer_set_max_recursion(w.world.stack->renderer, depth);
        ob_material *ground = ob_world_material(&w.world, "ground", OB_MATERIAL_LIT, 0.5f, 0.5f, 0.6f, false);
        ob_material *red = ob_world_material(&w.world, "red", OB_MATERIAL_LIT, 0.9f, 0.2f, 0.1f, true);
        ob_material *mirror = ob_world_material(&w.world, "mirror", OB_MATERIAL_REFLECTIVE, 0.9f, 0.9f,
                                               0.9f, true);
        ob_world_entity(&w.world, NULL, "ground", w.world.plane, ground, 0, 0, 0);
        ob_world_entity(&w.world, NULL, "cube", w.world.box, red, 0, 0.5, -1.2);
        ob_world_entity(&w.world, NULL, "left-mirror", w.world.sphere, mirror, -0.7, 0.5, 0);
        ob_world_entity(&w.world, NULL, "right-mirror", w.world.sphere, mirror, 0.7, 0.5, 0);
        ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
        ob_world_look(&w.world, 0, 1.5, 3, 0, 0.4, 0);
        ob_stab_frame(&w, OB_THREADING_SINGLE);
        const ob_frame_stats *st = ob_stab_frame(&w, OB_THREADING_MULTI);
        for (uint32_t i = 0; st && i < st->skipped_count; i++)
            bounded[depth] += st->skipped[i].reason == OB_SKIP_RECURSION;
        views[depth] = st ? st->view_count : 0;
        img[depth] = ob_stab_snapshot(&w);
        ms[depth] = ob_stab_take_ms(c);
        r = w.world.err;
        ob_stab_world_destroy(&w);
    }
    bool grows = views[0] < views[1] && views[1] < views[2];
    uint64_t prev = UINT64_MAX;
    for (uint32_t d = 0; d < 4 && r == OB_OK; d++) {
        uint64_t sum = 0;
        for (size_t i = 0; i < (size_t)REC_W * REC_H * 4; i++)
            sum += (uint64_t)abs((int)img[d][i] - (int)img[d + 1][i]);
        char name[48];
        snprintf(name, sizeof name, "env_recursion %u->%u", d, d + 1);
        r = ob_stab_add(c, name, "summed abs pixel difference between the images at recursion "
                                 "bounds d and d+1 (must not grow with d)",
                        (double)sum, "levels", d == 0 ? NAN : (double)prev, grows, ms[d + 1],
                        "bound %u: %u views ran, %u left out at the bound (bound %u: %u, %u); max "
                        "abs %u, %u px differ", d + 1, views[d + 1], bounded[d + 1], d, views[d],
                        bounded[d], ob_rgba_max_diff(img[d], img[d + 1], REC_W * REC_H),
                        ob_rgba_diff_count(img[d], img[d + 1], REC_W * REC_H, 0));
        prev = sum;
    }
    for (uint32_t d = 0; d <= 4; d++) ob_free(img[d]);
    return r;
}

/* ------------------------------------------------------- many objects */

/* 100,000 small cubes (four materials), all in view: ST and MT frames give
 * the same image and the same command hash. With quick: 10,000. */
ob_result ob_stab_many_objects(ob_stab_ctx *c)
{
    const uint32_t gx = c->quick ? 100 : 400, gz = c->quick ? 100 : 250;
    ob_stab_world w;
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = 160, .height = 120});
    ob_material *mats[4] = {
        ob_world_material(&w.world, "red", OB_MATERIAL_LIT, 0.9f, 0.3f, 0.2f, false),
        ob_world_material(&w.world, "green", OB_MATERIAL_LIT, 0.2f, 0.8f, 0.3f, false),
        ob_world_material(&w.world, "blue", OB_MATERIAL_LIT, 0.2f, 0.4f, 0.9f, false),
        ob_world_material(&w.world, "yellow", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.2f, false),
    };
    uint64_t t0 = ob_time_ns();
    for (uint32_t z = 0; z < gz && w.world.err == OB_OK; z++) {
        for (uint32_t x = 0; x < gx; x++) {
            ob_node *n = ob_world_entity(&w.world, NULL, "cube", w.world.box, mats[(x + z) & 3],
                                        (x - gx / 2.0) * 0.1, 0.0, -(double)z * 0.1);
            ob_stab_scale(n, 0.08f, 0.08f, 0.08f);
        }
    }
    double build_ms = (double)(ob_time_ns() - t0) * 1e-6;
    ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, false, 1.0f, 2, 6, 4);
    /* Straight above, +Y of the image toward -Z: every cube in view. */
    ob_stab_position(w.world.stack->camera, -0.05, 34, -12.45);
    if (w.world.err == OB_OK) {
        ob_result res = ob_node_look_at(w.world.stack->camera, (const double[3]){-0.05, 0, -12.45},
                                        (const double[3]){0, 0, -1});
        if (res != OB_OK) w.world.err = res;
    }
    uint8_t *first = NULL;
    uint64_t hash = 0;
    uint32_t worst = 0, hash_mismatches = 0, wrong_draws = 0;
    double wall[4] = {0}, rec[4] = {0};
    for (int i = 0; i < 4 && w.world.err == OB_OK; i++) {
        uint64_t f0 = ob_time_ns();
        const ob_frame_stats *st = ob_stab_frame(&w, i % 2 ? OB_THREADING_MULTI : OB_THREADING_SINGLE);
        wall[i] = (double)(ob_time_ns() - f0) * 1e-6;
        const ob_view_stats *main = ob_world_view_stats(st, "main");
        if (!main) break;
        rec[i] = (double)(st->record_ns + st->assemble_ns) * 1e-6;
        wrong_draws += main->draws != gx * gz;
        uint8_t *img = ob_stab_snapshot(&w);
        if (!first) {
            first = img;
            hash = main->hash.hash;
        } else {
            worst = OB_MAX(worst, ob_rgba_max_diff(first, img, 160 * 120));
            hash_mismatches += main->hash.hash != hash;
            ob_free(img);
        }
    }
    ob_result r = OB_OK;
    if (w.world.err == OB_OK) {
        char name[48], note[64] = "";
        snprintf(name, sizeof name, "objects_%u", gx * gz);
        if (c->quick) snprintf(note, sizeof note, "--quick: %u of 100,000 objects; ", gx * gz);
        r = ob_stab_add(c, name, "max abs pixel difference of ST and MT frames against the first "
                                 "(ST), command hashes equal",
                        worst, "levels/255", 0, hash_mismatches == 0 && wrong_draws == 0,
                        ob_stab_take_ms(c),
                        "%sframe ST %.0f / MT %.0f ms (wall), rec+asm ST %.0f / MT %.0f ms; built "
                        "in %.0f ms; hash mismatches %u, frames with missing draws %u",
                        note, wall[2], wall[3], rec[2], rec[3], build_ms, hash_mismatches,
                        wrong_draws);
    }
    ob_free(first);
    if (r == OB_OK) r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}

/* ------------------------------------------------------- no casters */

/* A shadow-casting sun over receivers only: the shadow view is left out
 * ("no shadow casters") and the image is the unshadowed one. */
ob_result ob_stab_no_casters(ob_stab_ctx *c)
{
    ob_stab_world w;
    ob_stab_world_create(&w, c, &(ob_stab_world_desc){.width = 128, .height = 96});
    ob_material *m = ob_world_material(&w.world, "sand", OB_MATERIAL_LIT, 0.6f, 0.5f, 0.4f, false);
    ob_world_entity(&w.world, NULL, "ground", w.world.plane, m, 0, 0, 0);
    ob_world_entity(&w.world, NULL, "cube", w.world.box, m, 0, 0.5, 0);
    ob_node *sun = ob_world_light(&w.world, OB_LIGHT_DIRECTIONAL, true, 1.0f, 3, 8, 4);
    const ob_frame_stats *st = ob_stab_frame(&w, OB_THREADING_SINGLE);
    ob_skip_reason skipped = ob_world_skip_reason(st, "shadow:sun");
    bool absent = ob_world_shadow_cascades(st, "sun", NULL) == 0;
    uint8_t *without = ob_stab_snapshot(&w);
    ob_result set = OB_OK;
    if (sun) {
        ob_light_desc ld = *ob_node_get_light(sun);
        ld.casts_shadows = false;
        set = ob_node_set_light(sun, &ld);
    }
    st = ob_stab_frame(&w, OB_THREADING_SINGLE);
    ob_skip_reason after = ob_world_skip_reason(st, "shadow:sun");
    uint8_t *plain = ob_stab_snapshot(&w);
    ob_result r = OB_OK;
    if (w.world.err == OB_OK)
        r = ob_stab_add(c, "shadow_map_no_casters", "max abs pixel difference: shadowed sun with "
                                                    "no caster vs the same sun without shadows",
                        ob_rgba_max_diff(without, plain, 128 * 96), "levels/255", 0,
                        set == OB_OK && absent && skipped == OB_SKIP_NO_CASTERS &&
                            after == OB_SKIP_NONE,
                        ob_stab_take_ms(c), "shadow:sun left out: %s (%s)", absent ? "yes" : "NO",
                        ob_skip_reason_name(skipped));
    ob_free(without);
    ob_free(plain);
    if (r == OB_OK) r = w.world.err;
    ob_stab_world_destroy(&w);
    return r;
}
