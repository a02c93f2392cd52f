/* ob_views_lights.c — the point and spot lights of a view: the light table
 * and the screen-tile grid of the lit shaders' PerViewLights block
 * (materials/shaders/lighting.glsl), and the report of lights over the
 * limit.
 *
 * Design (docs/architecture.md, "Many lights"): a 16 x 16 grid of screen
 * tiles per view, each a 256-bit mask of the lights whose range sphere may
 * reach it, built on the CPU from the sphere's projected bounds. It needs no
 * per-object data, so the 128-byte per-draw block and instancing stay as
 * they are, and it needs no descriptor indexing: the block is one more
 * uniform block in set 0. Lights are indexed in node-id order; the shader
 * walks the mask bits in ascending order, so the sum is the same whatever
 * the tiling or the thread that records. A spot light's tiles are those of
 * the smallest sphere around its cone (bounded by its range), not of its
 * range sphere.
 *
 * Shadowed lights: row 3's .y is the light's first layer in the local
 * shadow array when the view samples its map this frame, else -1
 * (ob_view_local_shadow.c); the block's matrices come with the table.
 */
#include "ob_views_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct light_block {
    float grid[4];
    float table[OB_MAX_LIGHTS * 4][4];
    uint32_t tiles[OB_LIGHT_TILES_X * OB_LIGHT_TILES_Y][OB_MAX_LIGHTS / 32];
} light_block;

_Static_assert(sizeof(((light_block *)0)->table) == OB_LIGHT_TABLE_BYTES, "table layout");
_Static_assert(sizeof(((light_block *)0)->tiles) == OB_LIGHT_TILES_BYTES, "tile layout");

/* Point and spot lights that light: the same test where the table is built
 * and where the limit is reported, so both count the same lights. */
static bool is_local_light(const ob_light_desc *l)
{
    return l->type != OB_LIGHT_DIRECTIONAL && l->intensity > 0.0f;
}

/* clip = m * (x, y, z, 1), m column-major. */
static void transform_point(const float m[16], const float x[3], float dest[4])
{
    for (int r = 0; r < 4; r++)
        dest[r] = m[r] * x[0] + m[4 + r] * x[1] + m[8 + r] * x[2] + m[12 + r];
}

/* The tiles [x0, x1] x [y0, y1] (inclusive) that the sphere (c, radius)
 * given camera-relative may cover in a width x height view: the screen
 * bounds of the corners of its box in view space, widened by a pixel. False
 * when it covers none (behind the eye or off screen). A box that reaches
 * the eye's plane covers the whole grid. */
static bool sphere_tiles(const float view[16], const float proj[16], const float c[3],
                         float radius, uint32_t width, uint32_t height, uint32_t out[4])
{
    float vc[4];
    transform_point(view, c, vc);
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    uint32_t behind = 0;
    for (int k = 0; k < 8; k++) {
        float corner[3] = {vc[0] + (k & 1 ? radius : -radius), vc[1] + (k & 2 ? radius : -radius),
                           vc[2] + (k & 4 ? radius : -radius)};
        float clip[4];
        transform_point(proj, corner, clip);
        if (!(clip[3] > 1e-6f)) {
            behind++;
            continue;
        }
        for (int a = 0; a < 2; a++) {
            float ndc = clip[a] / clip[3];
            lo[a] = fminf(lo[a], ndc);
            hi[a] = fmaxf(hi[a], ndc);
        }
    }
    if (behind == 8) return false;
    if (behind > 0) {
        out[0] = out[2] = 0;
        out[1] = OB_LIGHT_TILES_X - 1;
        out[3] = OB_LIGHT_TILES_Y - 1;
        return true;
    }
    if (hi[0] < -1.0f || lo[0] > 1.0f || hi[1] < -1.0f || lo[1] > 1.0f) return false;
    float size[2] = {(float)width, (float)height};
    uint32_t tile[2] = {(width + OB_LIGHT_TILES_X - 1) / OB_LIGHT_TILES_X,
                        (height + OB_LIGHT_TILES_Y - 1) / OB_LIGHT_TILES_Y};
    uint32_t count[2] = {OB_LIGHT_TILES_X, OB_LIGHT_TILES_Y};
    for (int a = 0; a < 2; a++) {
        float p0 = (fmaxf(lo[a], -1.0f) * 0.5f + 0.5f) * size[a] - 1.0f;
        float p1 = (fminf(hi[a], 1.0f) * 0.5f + 0.5f) * size[a] + 1.0f;
        float t0 = floorf(p0 / (float)tile[a]), t1 = floorf(p1 / (float)tile[a]);
        out[2 * a] = t0 < 0.0f ? 0 : (uint32_t)t0;
        out[2 * a + 1] = t1 >= (float)(count[a] - 1) ? count[a] - 1 : (uint32_t)t1;
    }
    return true;
}

bool ob_views_spot_reaches(const float axis[3], float cos_outer, float range, const double rel[3],
                           double radius)
{
    /* Signed distance from the centre to the cone's side (Wronski's test),
     * then the range sphere and the plane through the apex (the cone is
     * narrower than a half-space: outer angle < 90 degrees). */
    double len2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2];
    double along = rel[0] * axis[0] + rel[1] * axis[1] + rel[2] * axis[2];
    if (range > 0.0f && sqrt(len2) - radius > (double)range) return false;
    if (along < -radius) return false;
    double c = cos_outer, s = sqrt(fmax(1.0 - c * c, 0.0));
    double across = sqrt(fmax(len2 - along * along, 0.0));
    return c * across - along * s <= radius;
}

/* The smallest sphere around a spot light's cone bounded by its range
 * (apex, rim and cap): centred on the axis; the range sphere for a point
 * light or an unbounded spot. */
static void light_bound(const ob_light_desc *l, const float axis[3], const float pos[3],
                        float out_center[3], float *out_radius)
{
    memcpy(out_center, pos, 3 * sizeof(float));
    *out_radius = l->range;
    if (l->type != OB_LIGHT_SPOT || !(l->range > 0.0f)) return;
    float c = cosf(l->outer_angle), s = sinf(l->outer_angle);
    /* Under 45 degrees the sphere through apex and rim holds the cap; wider,
     * the one around the rim does. */
    float along = c >= s ? l->range / (2.0f * c) : l->range * c;
    *out_radius = c >= s ? along : l->range * s;
    for (int k = 0; k < 3; k++) out_center[k] = pos[k] + axis[k] * along;
}

void ob_views_set_light_params(ob_views *ctx, const ob_view *v, ob_params *params,
                               const float view[16], const float proj[16])
{
    ob_param_registry *reg = params->reg;
    ob_param grid = ob_param_find(reg, "LightGrid");
    ob_param table = ob_param_find(reg, "LightTable");
    ob_param tiles = ob_param_find(reg, "LightTiles");
    if (!grid.id || !table.id || !tiles.id) return;   /* no lit shaders in this registry */

    /* 24 KiB: on the recording thread's stack, written whole so no slot
     * keeps another view's lights. */
    light_block b;
    memset(&b, 0, sizeof b);
    bool tiled = v->type == OB_VIEW_PERSPECTIVE && v->width > 0 && v->height > 0 &&
                 !ctx->light_tiles_off;
    if (tiled) {
        b.grid[0] = (float)((v->width + OB_LIGHT_TILES_X - 1) / OB_LIGHT_TILES_X);
        b.grid[1] = (float)((v->height + OB_LIGHT_TILES_Y - 1) / OB_LIGHT_TILES_Y);
        b.grid[3] = 1.0f;
    }

    float shadow_mats[OB_MAX_LOCAL_SHADOW_LAYERS][16];
    for (uint32_t k = 0; k < OB_MAX_LOCAL_SHADOW_LAYERS; k++) ob_mat4_identity(shadow_mats[k]);
    uint32_t count = 0, used = 0;
    ob_scene *scene = ob_renderer_scene(ctx->r);
    ob_node *const *lights = scene ? ob_scene_lights(scene, &count) : NULL;
    for (uint32_t i = 0; i < count && used < OB_MAX_LIGHTS; i++) {
        const ob_light_desc *l = ob_node_get_light(lights[i]);
        if (!is_local_light(l)) continue;
        double pos[3];
        ob_node_world_position(lights[i], pos);
        float c[3] = {(float)(pos[0] - v->origin[0]), (float)(pos[1] - v->origin[1]),
                      (float)(pos[2] - v->origin[2])};
        memcpy(b.table[4 * used], c, sizeof c);
        b.table[4 * used][3] = l->range;
        memcpy(b.table[4 * used + 1], l->color, sizeof l->color);
        b.table[4 * used + 1][3] = l->intensity;
        float right[3], up[3], fwd[3] = {0, 0, 0};
        if (l->type == OB_LIGHT_SPOT) {
            ob_node_world_axes(lights[i], right, up, fwd);
            memcpy(b.table[4 * used + 2], fwd, sizeof fwd);
            b.table[4 * used + 2][3] = cosf(l->outer_angle);
            b.table[4 * used + 3][0] = cosf(l->inner_angle);
        } else {
            b.table[4 * used + 2][3] = -2.0f;   /* a point light: no cone */
        }
        b.table[4 * used + 3][1] =
            l->casts_shadows ? ob_views_local_shadow_layer(ctx, v, lights[i], shadow_mats) : -1.0f;

        uint32_t word = used / 32, bit = 1u << (used % 32);
        uint32_t r[4] = {0, 0, 0, 0};
        bool reaches = true;
        float bc[3], bradius;
        light_bound(l, fwd, c, bc, &bradius);
        if (tiled && l->range > 0.0f)
            reaches = sphere_tiles(view, proj, bc, bradius, v->width, v->height, r);
        else if (tiled)
            r[1] = OB_LIGHT_TILES_X - 1, r[3] = OB_LIGHT_TILES_Y - 1;
        if (reaches)
            for (uint32_t y = r[2]; y <= r[3]; y++)
                for (uint32_t x = r[0]; x <= r[1]; x++) b.tiles[y * OB_LIGHT_TILES_X + x][word] |= bit;
        used++;
    }
    b.grid[2] = (float)((used + 31) / 32);   /* mask words the shaders walk */
    ob_params_set_vec4(params, grid, b.grid);
    ob_params_set_bytes(params, table, b.table, sizeof b.table);
    ob_params_set_bytes(params, tiles, b.tiles, sizeof b.tiles);
    ob_views_set_local_shadow_matrices(ctx, params, (const float(*)[16])shadow_mats);
}

static int compare_ids(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

void ob_views_report_light_limit(ob_views *ctx, ob_renderer *r)
{
    uint32_t count = 0, used = 0, over = 0;
    ob_scene *scene = ob_renderer_scene(r);
    ob_node *const *lights = scene ? ob_scene_lights(scene, &count) : NULL;
    for (uint32_t i = 0; i < count; i++) {
        if (!is_local_light(ob_node_get_light(lights[i]))) continue;
        if (used < OB_MAX_LIGHTS) {
            used++;
            continue;
        }
        over++;
        uint32_t id = ob_node_id(lights[i]);
        if (ctx->over_limit_count &&
            bsearch(&id, ctx->over_limit, ctx->over_limit_count, sizeof id, compare_ids))
            continue;   /* (bsearch takes no NULL array, even an empty one) */
        OB_LOG_W("views", "light '%s' (id %u): over the limit of %u point and spot lights a "
                 "scene (docs/limits.md); it lights nothing", ob_node_name(lights[i]), id,
                 OB_MAX_LIGHTS);
        if (ctx->over_limit_count == ctx->over_limit_cap) {
            uint32_t cap = ctx->over_limit_cap ? 2 * ctx->over_limit_cap : 16;
            uint32_t *grown = ob_realloc(ctx->over_limit, sizeof *grown * cap);
            if (!grown) continue;   /* logged again next frame: better than never */
            ctx->over_limit = grown;
            ctx->over_limit_cap = cap;
        }
        /* Insert in order (ids come in ascending order, so this is an append
         * except when lights were added since the last report). */
        uint32_t at = ctx->over_limit_count;
        while (at > 0 && ctx->over_limit[at - 1] > id) {
            ctx->over_limit[at] = ctx->over_limit[at - 1];
            at--;
        }
        ctx->over_limit[at] = id;
        ctx->over_limit_count++;
    }
    if (over) ob_renderer_note_lights_over_limit(r, over);
}
