#include "ob_views_internal.h"

/* Full-screen pass: copies a view's colour into the final target (what is
 * read back or presented). It is the natural place for post-processing.
 *
 * Presenting, it hands its target to the renderer each frame (copied into
 * the swapchain image at the end of the frame, after the overlay drew on
 * it) and follows the window: when the frame's swapchain image has another
 * size, its target and its source's (when the source had the composite's
 * size) are made again at that size before the source's PreRender, so the
 * camera's aspect and the copy match the window. The old images go through
 * the device's deferred deletion (frames in flight still read them). */
struct ob_composite_view {
    ob_view base;
    ob_views *ctx;
    ob_view *source;
    ob_param source_image;
    bool presenting;
};

/* v's targets again at width x height, same formats and layers. On failure
 * v keeps its old targets and the error is returned. */
static ob_result remake_targets(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height)
{
    VkFormat color, depth;
    ob_views_target_formats(ctx, v, &color, &depth);
    ob_image old_color = v->color, old_depth = v->depth;
    v->color = v->depth = (ob_image){0};
    ob_result r = ob_views_make_target(ctx, v, width, height, v->layer_count, color, depth);
    if (r != OB_OK) {
        v->color = old_color;
        v->depth = old_depth;
        return r;
    }
    ob_image_destroy(ctx->dev, old_color);
    ob_image_destroy(ctx->dev, old_depth);
    return OB_OK;
}

static void follow_window(ob_composite_view *cv, ob_renderer *r)
{
    ob_view *v = &cv->base, *src = cv->source;
    uint32_t w, h;
    if (!ob_renderer_present_extent(r, &w, &h) || (w == v->width && h == v->height)) return;
    bool source_follows = src->width == v->width && src->height == v->height;
    ob_result res = source_follows ? remake_targets(cv->ctx, src, w, h) : OB_OK;
    if (res == OB_OK) res = remake_targets(cv->ctx, v, w, h);
    if (res != OB_OK) {
        /* The copy to the window scales whatever size is left. */
        OB_LOG_E("views", "composite of '%s': cannot resize to the window's %ux%u (%s); the "
                 "image is scaled to the window instead", src->name, w, h, ob_result_name(res));
    }
    v->inputs[0] = src->color;
}

static ob_effect *composite_effect(ob_views *ctx)
{
    if (!ctx->composite_effect) {
        ob_effect_desc d = {
            .name = "composite",
            .vertex = "fullscreen.vert",
            .fragment = "fullscreen.frag",
        };
        ob_result r;
        ctx->composite_effect = ob_effect_create(ctx->effects, &d, &r);
    }
    return ctx->composite_effect;
}

static void composite_pre_render(ob_view *v, ob_renderer *r)
{
    ob_composite_view *cv = (ob_composite_view *)v;
    if (!ob_renderer_queue_view(r, v)) return;
    if (cv->presenting) {
        follow_window(cv, r);
        ob_renderer_present_image(r, v->color);
    }
    ob_renderer_pre_render(r, cv->source);
    composite_effect(cv->ctx);
}

static void composite_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                             uint32_t layer, uint32_t first, uint32_t count)
{
    ob_composite_view *cv = (ob_composite_view *)v;
    (void)r;
    (void)layer;
    (void)first;
    (void)count;
    if (!ob_views_bind_effect(cv->ctx, cv->ctx->composite_effect, v, pm)) return;
    ob_params_set_texture(ob_pipeline_manager_params(pm), cv->source_image, cv->source->color);
    ob_pipeline_manager_set_vertex_buffer(pm, (ob_buffer){0}, 0);
    ob_pipeline_manager_draw(pm, 3, 1, 0, 0);
}

static const ob_view_vtbl composite_vtbl = {
    .type_name = "composite",
    .pre_render = composite_pre_render,
    .record = composite_record,
};

ob_composite_view *ob_composite_view_create(ob_views *ctx, ob_view *source, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_composite_view *cv = NULL;
    if (!ctx || !source || !source->color.id) {
        OB_LOG_E("views", "composite view: needs a source view with a colour target");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    cv = ob_calloc(1, sizeof *cv);
    if (!cv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    ob_view_init(&cv->base, &composite_vtbl, OB_VIEW_COMPOSITE, "composite");
    cv->ctx = ctx;
    cv->source = source;
    cv->base.custom_record = true;
    /* The source's colour is sampled whether or not the source ran this
     * frame (it may be left out, e.g. past the recursion bound): as an input
     * it gets its barrier, and is cleared if it was never written. */
    cv->base.inputs[0] = source->color;
    cv->base.input_count = 1;
    cv->source_image = ob_param_find(ob_renderer_registry(ctx->r), "SourceImage");
    ob_image_info info;
    r = ob_image_get_info(ctx->dev, source->color, &info);
    if (r == OB_OK)
        r = ob_views_make_target(ctx, &cv->base, source->width, source->height, 1, info.format,
                                 VK_FORMAT_UNDEFINED);
    if (r != OB_OK) {
        ob_free(cv);
        cv = NULL;
    }
done:
    if (r != OB_OK && r != OB_ERR_INVALID_ARGUMENT)
        OB_LOG_E("views", "composite view of '%s' not created: %s", source->name, ob_result_name(r));
    if (out_result) *out_result = r;
    return cv;
}

void ob_composite_view_destroy(ob_views *ctx, ob_composite_view *v)
{
    if (v) ob_views_free_view(ctx, &v->base);
}

ob_view *ob_composite_view_base(ob_composite_view *v) { return &v->base; }
void ob_composite_view_set_presenting(ob_composite_view *v, bool presenting) { v->presenting = presenting; }
ob_image ob_composite_view_target(const ob_composite_view *v) { return v->base.color; }
