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
    ob_param direction;
    ob_env_params env;
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
 * of a map whose owner stands among them). */
static uint8_t paraboloid_layers(const double rel[3], double radius)
{
    return (uint8_t)((rel[2] + radius >= 0.0 ? 1u : 0u) | (-rel[2] + radius >= 0.0 ? 2u : 0u));
}

static bool paraboloid_pre_cull(ob_view *v, ob_renderer *r)
{
    return ob_views_env_pre_cull(v, r, ((ob_paraboloid_view *)v)->owner);
}

static void paraboloid_post_cull(ob_view *v, ob_renderer *r)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    ob_views_env_post_cull(pv->ctx, v, r, paraboloid_layers, &pv->reach, &pv->reach_cap, &pv->reach_valid);
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
    /* Texcoords span [-1, 1] over the side: a direction turning by dθ near
     * a half's centre moves dθ / 2 in the paraboloid, a quarter of the side. */
    ob_views_env_usage(&pv->env, v, params, 0.0f, 0.25f * (float)v->width);
}

static void paraboloid_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count)
{
    ob_paraboloid_view *pv = (ob_paraboloid_view *)v;
    float side = layer == 0 ? 1.0f : -1.0f;
    float dir[4] = {side, PARABOLOID_NEAR, 0.0f, 0.0f};
    ob_params_set_vec4(ob_pipeline_manager_params(pm), pv->direction, dir);
    ob_views_record_masked(v, r, pm, first, count, pv->reach_valid ? pv->reach : NULL,
                           (uint8_t)(1u << layer));
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
    pv->ctx = ctx;
    pv->owner = owner;
    pv->direction = ob_param_find(ob_renderer_registry(ctx->r), "ParaboloidDirection");
    r = ob_views_env_view_init(ctx, &pv->base, &paraboloid_vtbl, OB_VIEW_PARABOLOID, "envmap", owner,
                               2, &pv->env);
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
