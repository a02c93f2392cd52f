#include "ob_views_internal.h"

#include <math.h>
#include <string.h>

struct ob_perspective_view {
    ob_view base;
    ob_views *ctx;
    ob_node *camera;
    float view[16], proj[16];
    bool warned_degenerate;
};

/* Clip coordinates are homogeneous: the projection times any k draws the
 * same picture. With k a power of two near 1 / znear (frexp: w on the near
 * plane in [0.5, 1)), clip coordinates are of the order of 1 at any scene
 * scale, and the scaling is exact in float, so the pixels are the same as
 * with k = 1 wherever that worked. Without it a 1e-30 scene has clip
 * coordinates of 1e-30, and a GPU that rasterizes homogeneously (products
 * of two clip coordinates: 1e-60) and flushes denormals to zero loses its
 * triangles (issue 25.2: 194 levels on NVIDIA, none on lavapipe, which
 * divides by w first). */
static void scale_clip_to_near(float proj[16], float znear)
{
    int e = 0;
    (void)frexpf(znear, &e);
    for (int i = 0; i < 16; i++) proj[i] = ldexpf(proj[i], -e);
}

static bool perspective_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_perspective_view *pv = (ob_perspective_view *)v;
    if (!ob_renderer_queue_view(r, v)) return false;
    ob_views_apply_resize(pv->ctx, v);
    ob_scene *scene = ob_renderer_scene(r);
    const ob_camera_desc *cam = pv->camera ? ob_node_get_camera(pv->camera) : NULL;
    if (!scene || !cam || !ob_node_transform_is_valid(pv->camera)) {
        /* Nothing sensible to render: the view still clears its target. */
        if (!pv->warned_degenerate)
            OB_LOG_E("views", "view '%s': camera %s%s%s is missing or has an invalid transform; "
                     "rendering the clear colour only", v->name, pv->camera ? "'" : "",
                     pv->camera ? ob_node_name(pv->camera) : "(none)", pv->camera ? "'" : "");
        pv->warned_degenerate = true;
        v->item_count = 0;
        return false;
    }
    ob_node_world_position(pv->camera, v->origin);
    ob_node_view_relative(pv->camera, v->origin, pv->view);
    float aspect = cam->aspect > 0.0f ? cam->aspect
                                      : (v->height ? (float)v->width / (float)v->height : 1.0f);
    float fovy = cam->fovy > 0.0f && cam->fovy < 3.1f ? cam->fovy : 1.0471976f;
    float znear = cam->znear > 0.0f ? cam->znear : 0.1f;
    ob_math_perspective_reverse_z(fovy, aspect, znear, pv->proj);
    scale_clip_to_near(pv->proj, znear);
    ob_mat4_mul(pv->proj, pv->view, v->view_proj);
    v->cull_exclude = NULL;
    /* Rows of pixels per world unit at distance 1, for levels of detail. */
    v->lod_scale = ob_views_lod_scale(pv->ctx, 0.5f * (float)v->height / tanf(0.5f * fovy));
    return true;
}

/* After culling: shadow maps for the lights, the views the visible items'
 * materials need, simulations, pipelines. */
static void perspective_post_cull(ob_view *v, ob_renderer *r)
{
    ob_perspective_view *pv = (ob_perspective_view *)v;
    ob_views_queue_shadows(pv->ctx, r, v);
    ob_view_pre_render_items(v, r);
    /* After the items' PreRender: an environment map queued there that sees
     * a particle system has queued the simulation after itself, so the step
     * runs before the map and this view (queue order is run in reverse). */
    ob_views_queue_simulations(pv->ctx, r, v);
    ob_material_library_prepare_view(pv->ctx->materials, r, v);
}

static void perspective_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_perspective_view *pv = (ob_perspective_view *)v;
    (void)r;
    ob_views_set_common_params(pv->ctx, v, params, pv->view, pv->proj);
}

static const ob_view_vtbl perspective_vtbl = {
    .type_name = "perspective",
    .pre_cull = perspective_pre_cull,
    .post_cull = perspective_post_cull,
    .set_render_params = perspective_render_params,
    .record = ob_view_record_draw_list,
};

ob_perspective_view *ob_perspective_view_create(ob_views *ctx, const ob_perspective_desc *desc,
                                                ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_perspective_view *pv = NULL;
    if (!ctx || !desc || desc->width == 0 || desc->height == 0) {
        OB_LOG_E("views", "perspective view '%s': needs a width and height (got %ux%u)",
                 desc && desc->name ? desc->name : "?", desc ? desc->width : 0,
                 desc ? desc->height : 0);
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    /* The view cannot be given a camera later: without one it could only
     * ever render its clear colour. */
    if (!desc->camera) {
        OB_LOG_E("views", "perspective view '%s': needs a camera node (desc.camera is NULL)",
                 desc->name ? desc->name : "camera");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    pv = ob_calloc(1, sizeof *pv);
    if (!pv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    ob_view_init(&pv->base, &perspective_vtbl, OB_VIEW_PERSPECTIVE,
                 desc->name ? desc->name : "camera");
    pv->ctx = ctx;
    pv->camera = desc->camera;
    memcpy(pv->base.clear_color, desc->clear_color, sizeof pv->base.clear_color);
    pv->base.clear_depth = 0.0f;
    VkFormat color = desc->color_format ? desc->color_format : OB_VIEWS_HDR_FORMAT;
    pv->base.samples = ob_views_supported_samples(ctx, pv->base.name, desc->samples, color,
                                                  OB_VIEWS_DEPTH_FORMAT);
    r = ob_views_make_target(ctx, &pv->base, desc->width, desc->height, 1, color,
                             OB_VIEWS_DEPTH_FORMAT);
    if (r != OB_OK) {
        ob_free(pv);
        pv = NULL;
    }
done:
    if (r != OB_OK && r != OB_ERR_INVALID_ARGUMENT)
        OB_LOG_E("views", "perspective view '%s' not created: %s",
                 desc->name ? desc->name : "camera", ob_result_name(r));
    if (out_result) *out_result = r;
    return pv;
}

void ob_perspective_view_destroy(ob_views *ctx, ob_perspective_view *v)
{
    if (v) ob_views_free_view(ctx, &v->base);
}

ob_view *ob_perspective_view_base(ob_perspective_view *v) { return &v->base; }
ob_image ob_perspective_view_color(const ob_perspective_view *v) { return v->base.color; }
uint32_t ob_perspective_view_samples(const ob_perspective_view *v) { return v->base.samples > 1 ? v->base.samples : 1; }
