#include "ob_views_internal.h"

#include <math.h>

/* Full-screen pass: tone maps a view's linear HDR colour into the final
 * target (R8G8B8A8_SRGB: what is read back, written as PNG and presented).
 * The curve and its formula are in materials/shaders/composite.frag
 * (Narkowicz's ACES fit after a linear exposure scale); the target's sRGB
 * format does the encode, so the overlay drawn over it afterwards blends in
 * linear space and is not touched by the exposure.
 *
 * Size: the composite's target has its source's size, checked every
 * frame after the source's PreRender (which applies the source's pending
 * ob_view_resize), so resizing the camera view resizes the picture in the
 * same frame; ob_view_resize on the composite is passed to the source.
 * Presenting, it hands its target to the renderer each frame (copied into
 * the swapchain image at the end of the frame, after the overlay drew on
 * it) and follows the window: when the frame's swapchain image has another
 * size, the source (when it had the composite's size) is asked for that
 * size before its PreRender, so the camera's aspect and the copy match the
 * window, and the target takes the window's size. Old images go through
 * the device's deferred deletion (frames in flight still read them). */
struct ob_composite_view {
    ob_view base;
    ob_views *ctx;
    ob_view *source;
    ob_param source_image, tone_map;
    float exposure;
    bool tonemap;
    bool presenting;
};

/* The context's one composite effect, made by the first composite view's
 * creation so that a shader that cannot be read or compiled fails there
 * (the caller gets the result) instead of giving a black frame and OB_OK. */
static ob_result composite_effect(ob_views *ctx)
{
    if (ctx->composite_effect) return OB_OK;
    ob_effect_desc d = {
        .name = "composite",
        .vertex = "fullscreen.vert",
        .fragment = "composite.frag",
    };
    ob_result r = OB_OK;
    ctx->composite_effect = ob_effect_create(ctx->effects, &d, &r);
    return r;
}

static void composite_pre_render(ob_view *v, ob_renderer *r)
{
    ob_composite_view *cv = (ob_composite_view *)v;
    ob_view *src = cv->source;
    if (!ob_renderer_queue_view(r, v)) return;
    /* The composite's size follows its source's (or the window's): a resize
     * asked of it is the source's. */
    uint32_t w, h;
    if (ob_view_take_resize(v, &w, &h)) ob_view_resize(src, w, h);
    bool window = cv->presenting && ob_renderer_present_extent(r, &w, &h);
    /* A source that had the picture's size follows the window. */
    if (window && (w != v->width || h != v->height) && src->width == v->width &&
        src->height == v->height)
        ob_view_resize(src, w, h);
    ob_renderer_pre_render(r, src);   /* applies the source's resize */
    if (!window) {
        w = src->width;
        h = src->height;
    }
    if ((w != v->width || h != v->height) && ob_views_resize_target(cv->ctx, v, w, h) != OB_OK) {
        /* The copy to the window scales whatever size is left. */
        OB_LOG_E("views", "composite of '%s': stays %ux%u instead of %ux%u%s", src->name, v->width,
                 v->height, w, h, window ? "; the image is scaled to the window" : "");
    }
    v->inputs[0] = src->color;
    if (cv->presenting) ob_renderer_present_image(r, v->color);
    ob_views_prepare_effect(cv->ctx, r, cv->ctx->composite_effect, v);
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
    ob_params *params = ob_pipeline_manager_params(pm);
    ob_params_set_texture(params, cv->source_image, cv->source->color);
    ob_params_set_vec4(params, cv->tone_map,
                       (const float[4]){cv->exposure, cv->tonemap ? 1.0f : 0.0f, 0.0f, 0.0f});
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
    r = composite_effect(ctx);
    if (r != OB_OK) goto done;
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
    cv->tone_map = ob_param_find(ob_renderer_registry(ctx->r), "ToneMap");
    cv->exposure = OB_COMPOSITE_DEFAULT_EXPOSURE;
    cv->tonemap = true;
    r = ob_views_make_target(ctx, &cv->base, source->width, source->height, 1,
                             OB_VIEWS_OUTPUT_FORMAT, VK_FORMAT_UNDEFINED);
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

bool ob_composite_view_set_exposure(ob_composite_view *v, float exposure)
{
    if (!v || !isfinite(exposure) || exposure < 0.0f) {
        OB_LOG_E("views", "composite%s%s: exposure %g refused (a finite value >= 0 is needed); "
                 "it stays %g", v ? " of " : "", v ? v->source->name : "", (double)exposure,
                 v ? (double)v->exposure : 0.0);
        return false;
    }
    v->exposure = exposure;
    return true;
}

float ob_composite_view_exposure(const ob_composite_view *v) { return v->exposure; }
void ob_composite_view_set_tonemap(ob_composite_view *v, bool tonemap) { v->tonemap = tonemap; }
ob_image ob_composite_view_target(const ob_composite_view *v) { return v->base.color; }

uint8_t ob_composite_view_output_level(const ob_composite_view *v, float linear)
{
    float x = linear * v->exposure;
    x = x > 0.0f ? x : 0.0f;   /* NaN too */
    if (v->tonemap) x = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
    x = x < 1.0f ? x : 1.0f;
    float e = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)(e * 255.0f + 0.5f);
}
