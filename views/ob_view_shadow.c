#include "ob_views_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

struct ob_shadow_view {
    ob_view base;
    ob_views *ctx;
    ob_node *light;
    ob_view *consumer;
    float view[16], proj[16];
    ob_param shadow_map, shadow_matrix;
};

/* Fit an orthographic light frustum around the casters the consumer sees,
 * extended toward the light so casters outside the consumer's view that can
 * still throw a shadow into it are drawn. Returns false with no caster. */
static bool fit_to_casters(ob_shadow_view *sv, ob_renderer *r)
{
    ob_view *v = &sv->base;
    ob_view *c = sv->consumer;
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    float right[3], up[3], fwd[3];
    ob_node_world_axes(sv->light, right, up, fwd);
    double dir[3] = {fwd[0], fwd[1], fwd[2]}, upd[3] = {0.0, 1.0, 0.0}, axes[9];
    ob_math_look_rotation(dir, upd, axes);
    memcpy(v->origin, c->origin, sizeof v->origin);
    ob_math_view_relative(axes, v->origin, v->origin, sv->view);

    float lo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, hi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    uint32_t casters = 0;
    /* The consumer's culling already asked every material where it renders
     * (a list not made by ob_view_cull asks the interface per item). */
    bool culled = c->material_count > 0;
    for (uint32_t i = 0; i < c->item_count; i++) {
        bool casts = culled ? c->materials[ob_view_item_material(c, i)].mask & (1u << OB_VIEW_SHADOW)
                            : mi->renders(ob_node_get_renderable(c->items[i].node)->material,
                                          OB_VIEW_SHADOW);
        if (!casts) continue;
        double wc[3];
        float radius;
        if (culled) ob_view_item_sphere(c, i, wc, &radius);
        else ob_node_world_sphere(c->items[i].node, wc, &radius);
        float rel[3] = {(float)(wc[0] - v->origin[0]), (float)(wc[1] - v->origin[1]),
                        (float)(wc[2] - v->origin[2])};
        for (int k = 0; k < 3; k++) {
            const float *m = sv->view;
            float p = m[k] * rel[0] + m[4 + k] * rel[1] + m[8 + k] * rel[2] + m[12 + k];
            lo[k] = fminf(lo[k], p - radius);
            hi[k] = fmaxf(hi[k], p + radius);
        }
        casters++;
    }
    if (casters == 0) return false;
    /* View space looks down -Z: distance along the light is -z. */
    float znear = -hi[2], zfar = -lo[2];
    float extent = fmaxf(zfar - znear, fmaxf(hi[0] - lo[0], hi[1] - lo[1]));
    /* Margins relative to the casters' size only: an absolute one (a unit,
     * 1e-4) would dwarf a millimetre-sized scene and spread its shadow map
     * over empty space. A single caster without bounds has no size: 1. */
    float size = extent > 0.0f ? extent : 1.0f;
    znear -= 2.0f * size;
    float pad = 1e-3f * size;
    ob_math_ortho_reverse_z(lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad, znear, zfar + pad,
                            sv->proj);
    ob_mat4_mul(sv->proj, sv->view, v->view_proj);
    return true;
}

static bool shadow_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_shadow_view *sv = (ob_shadow_view *)v;
    if (v->queued_frame == ob_renderer_frame_serial(r)) {
        /* Queued by an earlier consumer this frame: fitted and culled for
         * it. Refitting now would record its culled list through another
         * frustum (issue 25.5); the queue call makes this consumer depend
         * on it. */
        ob_renderer_queue_view(r, v);
        return false;
    }
    if (!sv->consumer || !fit_to_casters(sv, r)) {
        ob_renderer_note_skipped(r, v->name, OB_SKIP_NO_CASTERS);
        return false;
    }
    if (!ob_renderer_queue_view(r, v)) return false;
    v->cull_exclude = NULL;
    return true;
}

static void shadow_post_cull(ob_view *v, ob_renderer *r)
{
    ob_shadow_view *sv = (ob_shadow_view *)v;
    ob_material_library_prepare_view(sv->ctx->materials, r, v);
}

static void shadow_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_shadow_view *sv = (ob_shadow_view *)v;
    (void)r;
    ob_views_set_common_params(sv->ctx, v, params, sv->view, sv->proj);
}

static void shadow_usage_params(ob_view *v, ob_renderer *r, ob_params *params,
                                const ob_view *consumer)
{
    ob_shadow_view *sv = (ob_shadow_view *)v;
    (void)r;
    float m[16];
    memcpy(m, v->view_proj, sizeof m);
    if (consumer) {
        /* The consumer's positions are relative to its own origin. */
        float t[16];
        ob_mat4_identity(t);
        t[12] = (float)(consumer->origin[0] - v->origin[0]);
        t[13] = (float)(consumer->origin[1] - v->origin[1]);
        t[14] = (float)(consumer->origin[2] - v->origin[2]);
        ob_mat4_mul(v->view_proj, t, m);
    }
    ob_params_set_texture(params, sv->shadow_map, v->depth);
    ob_params_set_mat4(params, sv->shadow_matrix, m);
}

static const ob_view_vtbl shadow_vtbl = {
    .type_name = "shadow",
    .pre_cull = shadow_pre_cull,
    .post_cull = shadow_post_cull,
    .set_render_params = shadow_render_params,
    .set_usage_params = shadow_usage_params,
    .record = ob_view_record_draw_list,
};

ob_shadow_view *ob_shadow_view_create(ob_views *ctx, ob_node *light, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_shadow_view *sv = ob_calloc(1, sizeof *sv);
    if (!sv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    char name[48];
    snprintf(name, sizeof name, "shadow:%s", ob_node_name(light));
    ob_view_init(&sv->base, &shadow_vtbl, OB_VIEW_SHADOW, name);
    sv->ctx = ctx;
    sv->light = light;
    sv->base.clear_depth = 0.0f;
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    sv->shadow_map = ob_param_find(reg, "ShadowMap");
    sv->shadow_matrix = ob_param_find(reg, "ShadowMatrix");
    r = ob_views_make_target(ctx, &sv->base, ctx->shadow_map_size, ctx->shadow_map_size, 1,
                             VK_FORMAT_UNDEFINED, OB_VIEWS_DEPTH_FORMAT);
    if (r != OB_OK) {
        ob_free(sv);
        sv = NULL;
    }
done:
    if (out_result) *out_result = r;
    return sv;
}

void ob_shadow_view_destroy(ob_views *ctx, ob_shadow_view *v)
{
    if (v) ob_views_free_view(ctx, &v->base);
}

ob_view *ob_shadow_view_base(ob_shadow_view *v) { return &v->base; }
void ob_shadow_view_set_consumer(ob_shadow_view *v, ob_view *consumer) { v->consumer = consumer; }
