#include "ob_views_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Dual-paraboloid environment map of one entity: layer 0 holds the +Z
 * hemisphere around the owner's centre, layer 1 the -Z one. The map's frame
 * is the world's (ViewMatrix and EnvMapMatrix are identity), so reflective
 * lookups only need the reflection vector. Linear HDR (OB_VIEWS_ENV_FORMAT)
 * with a full mip chain the renderer blits after the map renders.
 *
 * The projection is per vertex: a triangle's straight edges stay straight in
 * the map while the true image of a long edge is curved, so a large
 * polygon (a floor of one quad) is bent — a thin band, broken at the
 * equator where the halves meet. Subdivided geometry (a plane of 64
 * subdivisions), or the cube map (ob_view_cube.c), avoids it: see
 * docs/limits.md. */
struct ob_paraboloid_view {
    ob_view base;
    ob_views *ctx;
    ob_node *owner;
    ob_param direction, env_map, env_matrix, env_info;
    /* Per item of this frame's draw list: bit L set when its bound reaches
     * layer L's hemisphere (filled in pre_render, read by the recording). */
    uint8_t *reach;
    uint32_t reach_cap;
    bool reach_valid;      /* false: no memory for it this frame, draw all */
};

#define PARABOLOID_NEAR 0.05f

/* A layer holds one hemisphere (z * side >= 0 around the owner); the
 * shaders discard every fragment of the other one. An item whose bound lies
 * wholly in the other hemisphere therefore leaves no pixel in that layer:
 * not drawing it there changes nothing but the cost (about half the items
 * of a map whose owner stands among them). The bound is widened by far more
 * than the float rounding of a vertex relative to the owner (about 1e-7 of
 * its distance), so that no vertex can round across the plane. */
static void paraboloid_reach(ob_paraboloid_view *pv)
{
    ob_view *v = &pv->base;
    pv->reach_valid = ob_array_reserve((void **)&pv->reach, &pv->reach_cap, v->item_count,
                                       sizeof *pv->reach) == OB_OK;
    if (!pv->reach_valid) {
        OB_LOG_W("view", "view '%s': no memory for the per-layer item masks; every item is drawn "
                 "in both layers this frame", v->name);
        return;
    }
    for (uint32_t i = 0; i < v->item_count; i++) {
        double c[3];
        float radius;
        ob_view_item_sphere(v, i, c, &radius);
        double rel[3] = {c[0] - v->origin[0], c[1] - v->origin[1], c[2] - v->origin[2]};
        double dist = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
        double reach = (double)radius + ((double)radius + dist) * 1e-5 + 1e-6;
        pv->reach[i] = (uint8_t)((rel[2] + reach >= 0.0 ? 1u : 0u) | (-rel[2] + reach >= 0.0 ? 2u : 0u));
    }
}

static bool paraboloid_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    if (!ob_renderer_queue_view(r, v)) return false;
    float radius;
    ob_node_world_sphere(pv->owner, v->origin, &radius);
    ob_mat4_identity(v->view_proj);
    v->cull_exclude = pv->owner;
    return true;
}

static void paraboloid_post_cull(ob_view *v, ob_renderer *r)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    paraboloid_reach(pv);
    ob_view_pre_render_items(v, r);
    /* A particle system the map sees must step before the map draws it and
     * hand it its parameters (it becomes a dependency), as for a camera. */
    ob_views_queue_simulations(pv->ctx, r, v);
    ob_material_library_prepare_view(pv->ctx->materials, r, v);
}

static void paraboloid_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    (void)r;
    float identity[16];
    ob_mat4_identity(identity);
    ob_views_set_common_params(pv->ctx, v, params, identity, identity);
}

static void paraboloid_usage_params(ob_view *v, ob_renderer *r, ob_params *params,
                                    const ob_view *consumer)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    (void)r;
    (void)consumer;
    float identity[16];
    ob_mat4_identity(identity);
    ob_params_set_texture(params, pv->env_map, v->color);
    ob_params_set_mat4(params, pv->env_matrix, identity);
    /* Texcoords span [-1, 1] over the side: a direction turning by dθ near
     * a half's centre moves dθ / 2 in the paraboloid, a quarter of the side. */
    float info[4] = {0.0f, (float)(v->color_mips ? v->color_mips - 1 : 0), 0.25f * (float)v->width, 0.0f};
    ob_params_set_vec4(params, pv->env_info, info);
}

static void paraboloid_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    float side = layer == 0 ? 1.0f : -1.0f;
    float dir[4] = {side, PARABOLOID_NEAR, 0.0f, 0.0f};
    ob_params_set_vec4(ob_pipeline_manager_params(pm), pv->direction, dir);
    /* Runs of items this layer draws are recorded together. */
    uint32_t end = first + count < v->item_count ? first + count : v->item_count;
    uint32_t run = first;
    uint8_t bit = (uint8_t)(1u << layer);
    for (uint32_t i = first; i < end && pv->reach_valid; i++) {
        if (pv->reach[i] & bit) continue;
        if (i > run) ob_view_record_items(v, r, pm, run, i - run);
        run = i + 1;
    }
    if (end > run) ob_view_record_items(v, r, pm, run, end - run);
}

static const ob_view_vtbl paraboloid_vtbl = {
    .type_name = "paraboloid",
    .pre_cull = paraboloid_pre_cull,
    .post_cull = paraboloid_post_cull,
    .set_render_params = paraboloid_render_params,
    .set_usage_params = paraboloid_usage_params,
    .record = paraboloid_record,
};

ob_paraboloid_view *ob_paraboloid_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_paraboloid_view *pv = ob_calloc(1, sizeof *pv);
    if (!pv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    char name[48];
    snprintf(name, sizeof name, "envmap:%s", ob_node_name(owner));
    ob_view_init(&pv->base, &paraboloid_vtbl, OB_VIEW_PARABOLOID, name);
    pv->ctx = ctx;
    pv->owner = owner;
    pv->base.no_frustum = true;
    pv->base.clear_depth = 0.0f;
    /* The clear colour is the first camera's of each frame (queue_hook):
     * the sky a reflection shows is the one around the object. */
    pv->base.clear_color[3] = 1.0f;
    pv->base.color_mips = ob_image_mip_levels_max(ctx->env_map_size, ctx->env_map_size);
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    pv->direction = ob_param_find(reg, "ParaboloidDirection");
    pv->env_map = ob_param_find(reg, "EnvMap");
    pv->env_matrix = ob_param_find(reg, "EnvMapMatrix");
    pv->env_info = ob_param_find(reg, "EnvMapInfo");
    if (!pv->env_matrix.id) pv->env_matrix = ob_param_register(reg, "EnvMapMatrix", OB_PARAM_MAT4, 1, &r);
    if (r == OB_OK)
        r = ob_views_make_target(ctx, &pv->base, ctx->env_map_size, ctx->env_map_size, 2,
                                 OB_VIEWS_ENV_FORMAT, OB_VIEWS_DEPTH_FORMAT);
    if (r != OB_OK) {
        ob_free(pv);
        pv = NULL;
    }
done:
    if (out_result) *out_result = r;
    return pv;
}

void ob_paraboloid_view_destroy(ob_views *ctx, ob_paraboloid_view *v)
{
    if (!v) return;
    ob_free(v->reach);
    ob_views_free_view(ctx, &v->base);
}

ob_view *ob_paraboloid_view_base(ob_paraboloid_view *v) { return &v->base; }
