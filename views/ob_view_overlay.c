#include "ob_views_internal.h"

#include <string.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-braces"
#endif
#include <stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* Text drawn last over the final target. Glyph quads come from stb_easy_font
 * (16-byte vertices: position + RGBA8) into a host-visible buffer per frame
 * slot, built on the render thread in pre_render and drawn by one indexed draw. */

#define OVERLAY_TEXT_MAX 4096
#define OVERLAY_MAX_QUADS 8192
#define OVERLAY_SLOTS 4
#define OVERLAY_SCALE 2.0f

typedef struct overlay_vertex {
    float x, y, z;
    uint8_t rgba[4];
} overlay_vertex;

struct ob_overlay_view {
    ob_view base;
    ob_views *ctx;
    ob_view *source;
    char text[OVERLAY_TEXT_MAX];
    ob_buffer vertices[OVERLAY_SLOTS];
    ob_buffer indices;
    uint32_t slot, quad_count;
    ob_param diffuse;
};

/* The context's one text effect, made by the first overlay's creation so
 * that a shader that cannot be read or compiled fails there, where the
 * caller sees the result, instead of in every frame, logged only. */
static ob_result text_effect(ob_views *ctx)
{
    if (ctx->text_effect) return OB_OK;
    static const ob_shader_define defines[] = {{"SCREEN_SPACE", "1"}, {"VERTEX_COLOR", "1"}};
    ob_effect_vertex_input input = {
        .stride = sizeof(overlay_vertex),
        .attribute_count = 2,
        .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {3, VK_FORMAT_R8G8B8A8_UNORM, 12}},
    };
    ob_effect_desc d = {
        .name = "overlay-text",
        .vertex = "unlit.vert",
        .fragment = "unlit.frag",
        .define_count = 2,
        .defines = defines,
        .layout = &input,
        .blend = true,
    };
    ob_result r = OB_OK;
    ctx->text_effect = ob_effect_create(ctx->effects, &d, &r);
    return r;
}

static void overlay_pre_render(ob_view *v, ob_renderer *r)
{
    ob_overlay_view *ov = (ob_overlay_view *)v;
    if (!ob_renderer_queue_view(r, v)) return;
    ob_renderer_pre_render(r, ov->source);
    v->color = ov->source->color;
    v->width = ov->source->width;
    v->height = ov->source->height;
    ob_views_prepare_effect(ov->ctx, r, ov->ctx->text_effect, v);

    /* Build this frame's quads into the slot the GPU is no longer reading. */
    ov->slot = (uint32_t)(ob_renderer_frame_serial(r) % OVERLAY_SLOTS);
    ob_device *dev = ov->ctx->dev;
    overlay_vertex *dst = ob_buffer_mapped(dev, ov->vertices[ov->slot]);
    ov->quad_count = 0;
    if (!dst) return;
    float y = 8.0f;
    const char *line = ov->text;
    while (*line && ov->quad_count < OVERLAY_MAX_QUADS) {
        char buf[512];
        size_t n = strcspn(line, "\n");
        size_t copy = n < sizeof buf - 1 ? n : sizeof buf - 1;
        memcpy(buf, line, copy);
        buf[copy] = '\0';
        unsigned char white[4] = {255, 255, 255, 255};
        uint32_t room = OVERLAY_MAX_QUADS - ov->quad_count;
        int quads = stb_easy_font_print(8.0f / OVERLAY_SCALE, y / OVERLAY_SCALE, buf, white,
                                        dst + 4 * ov->quad_count,
                                        (int)(room * 4 * sizeof(overlay_vertex)));
        ov->quad_count += (uint32_t)quads;
        y += 12.0f * OVERLAY_SCALE;
        line += n;
        if (*line == '\n') line++;
    }
}

static void overlay_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                           uint32_t first, uint32_t count)
{
    ob_overlay_view *ov = (ob_overlay_view *)v;
    (void)r;
    (void)layer;
    (void)first;
    (void)count;
    if (ov->quad_count == 0 || !ob_views_bind_effect(ov->ctx, ov->ctx->text_effect, v, pm)) return;
    ob_params *params = ob_pipeline_manager_params(pm);
    float scale[16];
    ob_mat4_identity(scale);
    scale[0] = scale[5] = OVERLAY_SCALE;
    ob_params_set_mat4(params, ob_param_registry_builtins(params->reg)->world, scale);
    static const float white[4] = {1, 1, 1, 1};
    ob_params_set_vec4(params, ov->diffuse, white);
    ob_pipeline_manager_set_vertex_buffer(pm, ov->vertices[ov->slot], 0);
    ob_pipeline_manager_set_index_buffer(pm, ov->indices, 0, VK_INDEX_TYPE_UINT32);
    ob_pipeline_manager_draw_indexed(pm, ov->quad_count * 6, 1, 0, 0, 0);
}

static void overlay_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_overlay_view *ov = (ob_overlay_view *)v;
    (void)r;
    float identity[16];
    ob_mat4_identity(identity);
    ob_views_set_common_params(ov->ctx, v, params, identity, identity);
}

static const ob_view_vtbl overlay_vtbl = {
    .type_name = "overlay",
    .pre_render = overlay_pre_render,
    .set_render_params = overlay_render_params,
    .record = overlay_record,
};

ob_overlay_view *ob_overlay_view_create(ob_views *ctx, ob_view *source, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_overlay_view *ov = NULL;
    uint32_t *idx = NULL;
    if (!ctx || !source || !source->color.id) {
        OB_LOG_E("views", "overlay view: needs a source view with a colour target");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    r = text_effect(ctx);
    if (r != OB_OK) goto done;
    ov = ob_calloc(1, sizeof *ov);
    idx = ob_malloc(sizeof *idx * 6 * OVERLAY_MAX_QUADS);
    if (!ov || !idx) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_destroy_overlay;
    }
    ob_view_init(&ov->base, &overlay_vtbl, OB_VIEW_OVERLAY, "overlay");
    ov->ctx = ctx;
    ov->source = source;
    ov->base.load_color = true;
    ov->base.custom_record = true;
    ov->base.color = source->color;
    ov->base.width = source->width;
    ov->base.height = source->height;
    ov->diffuse = ob_param_find(ob_renderer_registry(ctx->r), "DiffuseColor");
    for (uint32_t q = 0; q < OVERLAY_MAX_QUADS; q++) {
        static const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; k++) idx[6 * q + k] = 4 * q + quad[k];
    }
    ob_buffer_desc ib = {.size = sizeof *idx * 6 * OVERLAY_MAX_QUADS, .usage = OB_BUFFER_INDEX,
                         .data = idx, .name = "overlay.indices"};
    ov->indices = ob_buffer_create(ctx->dev, &ib, &r);
    if (!ov->indices.id) goto fail_destroy_overlay;
    for (uint32_t s = 0; s < OVERLAY_SLOTS; s++) {
        ob_buffer_desc vb = {.size = sizeof(overlay_vertex) * 4 * OVERLAY_MAX_QUADS,
                             .usage = OB_BUFFER_VERTEX, .host_visible = true,
                             .name = "overlay.vertices"};
        ov->vertices[s] = ob_buffer_create(ctx->dev, &vb, &r);
        if (!ov->vertices[s].id) goto fail_destroy_overlay;
    }
    ob_free(idx);
    goto done;
fail_destroy_overlay:
    ob_free(idx);
    ob_overlay_view_destroy(ctx, ov);
    ov = NULL;
done:
    if (r != OB_OK && r != OB_ERR_INVALID_ARGUMENT)
        OB_LOG_E("views", "overlay view of '%s' not created: %s", source->name, ob_result_name(r));
    if (out_result) *out_result = r;
    return ov;
}

void ob_overlay_view_destroy(ob_views *ctx, ob_overlay_view *v)
{
    if (!v) return;
    for (uint32_t s = 0; s < OVERLAY_SLOTS; s++) ob_buffer_destroy(ctx->dev, v->vertices[s]);
    ob_buffer_destroy(ctx->dev, v->indices);
    ob_view_release(&v->base);
    ob_free(v);
}

void ob_overlay_view_set_text(ob_overlay_view *v, const char *text)
{
    size_t n = strlen(text);
    if (n >= sizeof v->text) n = sizeof v->text - 1;
    memcpy(v->text, text, n);
    v->text[n] = '\0';
}

ob_view *ob_overlay_view_base(ob_overlay_view *v) { return &v->base; }
