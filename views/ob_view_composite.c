#include "ob_views_internal.h"

/* Full-screen pass: copies a view's colour into the final target (what is
 * read back or presented). It is the natural place for post-processing. */
struct ob_composite_view {
    ob_view base;
    ob_views *ctx;
    ob_view *source;
    ob_param source_image;
};

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

static void composite_pre_draw(ob_view *v, ob_renderer *r)
{
    ob_composite_view *cv = (ob_composite_view *)v;
    if (!ob_renderer_queue_view(r, v)) return;
    ob_renderer_pre_draw(r, cv->source);
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
    ob_params_set_texture(ob_pm_params(pm), cv->source_image, cv->source->color);
    ob_pm_set_vertex_buffer(pm, (ob_buffer){0}, 0);
    ob_pm_draw(pm, 3, 1, 0, 0);
}

static const ob_view_vtbl composite_vtbl = {
    .type_name = "composite",
    .pre_draw = composite_pre_draw,
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
ob_image ob_composite_view_target(const ob_composite_view *v) { return v->base.color; }
