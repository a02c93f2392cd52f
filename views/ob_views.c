#include "ob_views_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ------------------------------------------------------------ parameters */

typedef struct view_params {
    ob_param screen, ambient, light_dir, light_color;
    ob_param shadow_matrices, shadow_splits, shadow_cascades, shadow_axis, paraboloid;
} view_params;

static view_params params_of(ob_param_registry *reg)
{
    view_params p;
    p.screen = ob_param_find(reg, "ScreenSize");
    p.ambient = ob_param_find(reg, "AmbientColor");
    p.light_dir = ob_param_find(reg, "LightDirection");
    p.light_color = ob_param_find(reg, "LightColor");
    p.shadow_matrices = ob_param_find(reg, "ShadowMatrices");
    p.shadow_splits = ob_param_find(reg, "ShadowSplits");
    p.shadow_cascades = ob_param_find(reg, "ShadowCascades");
    p.shadow_axis = ob_param_find(reg, "ShadowAxis");
    p.paraboloid = ob_param_find(reg, "ParaboloidDirection");
    return p;
}

static ob_result register_params(ob_param_registry *reg)
{
    static const char *const vec4s[] = {
        "ScreenSize", "AmbientColor", "LightDirection", "LightColor", "LightGrid",
        "ParaboloidDirection", "SimStep", "SimEmitter", "SimForce", "DiffuseColor", "ToneMap",
        "EnvMapInfo", "ShadowSplits", "ShadowCascades", "ShadowAxis",
    };
    ob_result r = OB_OK;
    for (size_t i = 0; i < OB_ARRAY_COUNT(vec4s) && r == OB_OK; i++)
        ob_param_register(reg, vec4s[i], OB_PARAM_VEC4, 1, &r);
    if (r == OB_OK) ob_param_register(reg, "LightTable", OB_PARAM_BYTES, OB_LIGHT_TABLE_BYTES, &r);
    if (r == OB_OK) ob_param_register(reg, "LightTiles", OB_PARAM_BYTES, OB_LIGHT_TILES_BYTES, &r);
    if (r == OB_OK)
        ob_param_register(reg, "ShadowMatrices", OB_PARAM_MAT4_ARRAY, OB_SHADOW_MAX_CASCADES, &r);
    if (r == OB_OK) ob_param_register(reg, "ShadowMap", OB_PARAM_TEXTURE, 1, &r);
    if (r == OB_OK) ob_param_register(reg, "EnvMap", OB_PARAM_TEXTURE, 1, &r);
    if (r == OB_OK) ob_param_register(reg, "SourceImage", OB_PARAM_TEXTURE, 1, &r);
    if (r == OB_OK) ob_param_register(reg, "Particles", OB_PARAM_STORAGE_BUFFER, 1, &r);
    return r;
}

void ob_views_set_common_params(ob_views *ctx, const ob_view *v, ob_params *params,
                                const float view[16], const float proj[16])
{
    const ob_param_builtins *b = ob_param_registry_builtins(params->reg);
    view_params p = params_of(params->reg);
    ob_params_set_mat4(params, b->view, view);
    ob_params_set_mat4(params, b->proj, proj);
    float screen[4] = {(float)v->width, (float)v->height, v->width ? 1.0f / (float)v->width : 0.0f,
                       v->height ? 1.0f / (float)v->height : 0.0f};
    ob_params_set_vec4(params, p.screen, screen);
    ob_params_set_vec4(params, p.ambient, ctx->ambient);
    /* Members of the shared PerView block that only some views use get a
     * defined value here (dependencies and the paraboloid view override
     * them afterwards), so a slot never carries another view's leftovers:
     * the packed bytes, and so the command hashes, do not depend on which
     * views a worker happened to record before. */
    float identity[OB_SHADOW_MAX_CASCADES][16];
    for (uint32_t i = 0; i < OB_SHADOW_MAX_CASCADES; i++) ob_mat4_identity(identity[i]);
    ob_params_set_mat4_array(params, p.shadow_matrices, &identity[0][0], OB_SHADOW_MAX_CASCADES);
    static const float zero4[4] = {0, 0, 0, 0};
    ob_params_set_vec4(params, p.shadow_splits, zero4);
    ob_params_set_vec4(params, p.shadow_cascades, zero4);
    ob_params_set_vec4(params, p.shadow_axis, zero4);
    ob_params_set_vec4(params, p.paraboloid, zero4);

    /* Lights, relative to the view's origin like everything else. */
    float zero[4] = {0, 0, 0, 0};
    float dir[4] = {0, 1, 0, 0}, dcolor[4] = {0, 0, 0, 0};
    bool have_dir = false;
    uint32_t count = 0;
    ob_scene *scene = ob_renderer_scene(ctx->r);
    ob_node *const *lights = scene ? ob_scene_lights(scene, &count) : NULL;
    for (uint32_t i = 0; i < count; i++) {
        const ob_light_desc *l = ob_node_get_light(lights[i]);
        if (l->type == OB_LIGHT_DIRECTIONAL && !have_dir) {
            float right[3], up[3], fwd[3];
            ob_node_world_axes(lights[i], right, up, fwd);
            dir[0] = -fwd[0];
            dir[1] = -fwd[1];
            dir[2] = -fwd[2];
            dcolor[0] = l->color[0];
            dcolor[1] = l->color[1];
            dcolor[2] = l->color[2];
            dcolor[3] = l->intensity;
            have_dir = true;
        }
    }
    ob_params_set_vec4(params, p.light_dir, dir);
    ob_params_set_vec4(params, p.light_color, have_dir ? dcolor : zero);
    ob_views_set_light_params(ctx, v, params, view, proj);
}

/* ------------------------------------------------------------ env maps */

ob_result ob_views_env_view_init(ob_views *ctx, ob_view *v, const ob_view_vtbl *vtbl,
                                 ob_view_type type, const char *prefix, const ob_node *owner,
                                 uint32_t layers, ob_env_params *env)
{
    char name[48];
    snprintf(name, sizeof name, "%s:%s", prefix, ob_node_name(owner));
    ob_view_init(v, vtbl, type, name);
    v->no_frustum = true;
    v->clear_depth = 0.0f;
    v->clear_color[3] = 1.0f;
    v->color_mips = ob_image_mip_levels_max(ctx->env_map_size, ctx->env_map_size);
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    ob_result r = OB_OK;
    env->env_map = ob_param_find(reg, "EnvMap");
    env->env_info = ob_param_find(reg, "EnvMapInfo");
    env->env_matrix = ob_param_find(reg, "EnvMapMatrix");
    if (!env->env_matrix.id) env->env_matrix = ob_param_register(reg, "EnvMapMatrix", OB_PARAM_MAT4, 1, &r);
    if (r != OB_OK) return r;
    return ob_views_make_target(ctx, v, ctx->env_map_size, ctx->env_map_size, layers,
                                OB_VIEWS_ENV_FORMAT, OB_VIEWS_DEPTH_FORMAT);
}

void ob_views_env_usage(const ob_env_params *p, const ob_view *v, ob_params *params, float kind,
                        float texels_per_radian)
{
    float identity[16];
    ob_mat4_identity(identity);
    ob_params_set_texture(params, p->env_map, v->color);
    ob_params_set_mat4(params, p->env_matrix, identity);
    float info[4] = {kind, (float)(v->color_mips ? v->color_mips - 1 : 0), texels_per_radian, 0.0f};
    ob_params_set_vec4(params, p->env_info, info);
}

bool ob_views_env_pre_cull(ob_view *v, ob_renderer *r, const ob_node *owner)
{
    if (!ob_renderer_queue_view(r, v)) return false;
    float radius;
    ob_node_world_sphere(owner, v->origin, &radius);
    ob_mat4_identity(v->view_proj);
    v->cull_exclude = owner;
    return true;
}

void ob_views_env_post_cull(ob_views *ctx, ob_view *v, ob_renderer *r, ob_env_layer_mask_fn mask_of,
                            uint8_t **masks, uint32_t *cap, bool *valid)
{
    *valid = ob_array_reserve((void **)masks, cap, v->item_count, sizeof **masks) == OB_OK;
    if (!*valid)
        OB_LOG_W("view", "view '%s': no memory for the per-layer item masks; every item is drawn "
                 "in every layer this frame", v->name);
    for (uint32_t i = 0; *valid && i < v->item_count; i++) {
        double c[3];
        float radius;
        ob_view_item_sphere(v, i, c, &radius);
        double rel[3] = {c[0] - v->origin[0], c[1] - v->origin[1], c[2] - v->origin[2]};
        double dist = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
        (*masks)[i] = mask_of(rel, (double)radius + ((double)radius + dist) * 1e-5 + 1e-6);
    }
    ob_view_pre_render_items(v, r);
    /* A particle system the map sees must step before the map draws it and
     * hand it its parameters (it becomes a dependency), as for a camera. */
    ob_views_queue_simulations(ctx, r, v);
    ob_material_library_prepare_view(ctx->materials, r, v);
}

void ob_views_record_masked(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t first,
                            uint32_t count, const uint8_t *mask, uint8_t bit)
{
    uint32_t end = first + count < v->item_count ? first + count : v->item_count;
    uint32_t run = first;
    for (uint32_t i = first; i < end && mask; i++) {
        if (mask[i] & bit) continue;
        if (i > run) ob_view_record_items(v, r, pm, run, i - run);
        run = i + 1;
    }
    if (end > run) ob_view_record_items(v, r, pm, run, end - run);
}

/* ------------------------------------------------------------ targets */

/* One image of a view's targets, named "<view>.<what>". */
static ob_image make_image(ob_views *ctx, const ob_view *v, const char *what, uint32_t width,
                           uint32_t height, uint32_t layers, VkFormat format, uint32_t usage,
                           uint32_t samples, uint32_t mips, ob_result *out_result)
{
    char name[64];
    snprintf(name, sizeof name, "%s.%s", v->name, what);
    ob_image_desc d = {.width = width, .height = height, .layers = layers, .format = format,
                       .usage = usage, .samples = samples, .name = name, .mip_levels = mips};
    return ob_image_create(ctx->dev, &d, out_result);
}

ob_result ob_views_make_target(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height,
                               uint32_t layers, VkFormat color, VkFormat depth)
{
    ob_result r = OB_OK;
    /* Multisampled: colour and depth are drawn at v->samples, colour is
     * resolved into the single-sampled `color` consumers read. */
    uint32_t samples = layers == 1 && v->samples > 1 ? v->samples : 1;
    ob_image img[4] = {{0}};   /* color, depth, msaa_color, msaa_depth */
    /* Mips (v->color_mips) only where the device blits the format linearly;
     * otherwise one level, said once per target. */
    uint32_t mips = OB_MIN(v->color_mips ? v->color_mips : 1, ob_image_mip_levels_max(width, height));
    if (mips > 1 && color != VK_FORMAT_UNDEFINED && !ob_image_format_blits_linear(ctx->dev, color)) {
        OB_LOG_W("views", "view '%s': format %d cannot be blitted linearly on '%s'; its colour "
                 "target has no mips (rough reflections come out sharp)", v->name, (int)color,
                 ob_device_name(ctx->dev));
        mips = 1;
    }
    if (color != VK_FORMAT_UNDEFINED) {
        img[0] = make_image(ctx, v, "color", width, height, layers, color,
                            OB_IMAGE_COLOR_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC |
                                OB_IMAGE_TRANSFER_DST, 1, mips, &r);
        if (r == OB_OK && samples > 1)
            img[2] = make_image(ctx, v, "color.msaa", width, height, 1, color,
                                OB_IMAGE_COLOR_TARGET, samples, 1, &r);
    }
    if (r == OB_OK && depth != VK_FORMAT_UNDEFINED) {
        if (samples > 1)
            img[3] = make_image(ctx, v, "depth.msaa", width, height, 1, depth,
                                OB_IMAGE_DEPTH_TARGET, samples, 1, &r);
        else
            img[1] = make_image(ctx, v, "depth", width, height, layers, depth,
                                OB_IMAGE_DEPTH_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_DST,
                                1, 1, &r);
    }
    if (r != OB_OK) {
        for (int i = 0; i < 4; i++) ob_image_destroy(ctx->dev, img[i]);
        return r;
    }
    v->color = img[0];
    v->depth = img[1];
    v->msaa_color = img[2];
    v->msaa_depth = img[3];
    v->samples = samples;
    v->color_mips = color != VK_FORMAT_UNDEFINED ? mips : v->color_mips;
    v->width = width;
    v->height = height;
    v->layer_count = layers;
    return OB_OK;
}

void ob_views_release_target(ob_views *ctx, ob_view *v)
{
    ob_image_destroy(ctx->dev, v->color);
    ob_image_destroy(ctx->dev, v->depth);
    ob_image_destroy(ctx->dev, v->msaa_color);
    ob_image_destroy(ctx->dev, v->msaa_depth);
    v->color = v->depth = v->msaa_color = v->msaa_depth = (ob_image){0};
}

ob_result ob_views_resize_target(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height)
{
    if (width == v->width && height == v->height) return OB_OK;
    VkFormat color, depth;
    ob_views_target_formats(ctx, v, &color, &depth);
    ob_view old = *v;
    ob_result r = ob_views_make_target(ctx, v, width, height, v->layer_count, color, depth);
    if (r != OB_OK) {
        OB_LOG_E("views", "view '%s': cannot resize from %ux%u to %ux%u (%s); it keeps its size",
                 v->name, old.width, old.height, width, height, ob_result_name(r));
        /* In a frame (a resize asked for with ob_view_resize applies in
         * PreRender), the frame reports it: no-op between frames. */
        ob_renderer_note_error(ctx->r, v->name, r);
        return r;
    }
    /* Deferred: frames in flight still use the old images. */
    ob_views_release_target(ctx, &old);
    OB_LOG_I("views", "view '%s': targets now %ux%u (were %ux%u)", v->name, width, height,
             old.width, old.height);
    return OB_OK;
}

bool ob_views_apply_resize(ob_views *ctx, ob_view *v)
{
    uint32_t w, h;
    return ob_view_take_resize(v, &w, &h) && ob_views_resize_target(ctx, v, w, h) == OB_OK;
}

uint32_t ob_views_supported_samples(ob_views *ctx, const char *view_name, uint32_t wanted,
                                    VkFormat color, VkFormat depth)
{
    if (wanted <= 1) return 1;
    const VkPhysicalDeviceLimits *lim = &ob_device_properties(ctx->dev)->limits;
    VkSampleCountFlags counts = lim->framebufferColorSampleCounts & lim->framebufferDepthSampleCounts;
    VkPhysicalDevice pd = ob_device_vk_physical(ctx->dev);
    VkImageFormatProperties ip;
    if (vkGetPhysicalDeviceImageFormatProperties(pd, color, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL,
                                                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, 0, &ip) == VK_SUCCESS)
        counts &= ip.sampleCounts;
    if (depth != VK_FORMAT_UNDEFINED &&
        vkGetPhysicalDeviceImageFormatProperties(pd, depth, VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL,
                                                 VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, 0,
                                                 &ip) == VK_SUCCESS)
        counts &= ip.sampleCounts;
    uint32_t got = 1;
    for (uint32_t s = 2; s <= 64 && s <= wanted; s <<= 1)
        if (counts & s) got = s;
    if (got != wanted)
        OB_LOG_W("views", "view '%s': MSAA %ux asked for; '%s' offers at most %ux for colour format "
                 "%d with depth format %d (sample counts 0x%x): using %ux", view_name, wanted,
                 ob_device_name(ctx->dev), got, (int)color, (int)depth, (unsigned)counts, got);
    return got;
}

void ob_views_free_view(ob_views *ctx, ob_view *base)
{
    if (!base) return;
    ob_views_release_target(ctx, base);
    ob_view_release(base);
    ob_free(base);
}

void ob_views_target_formats(ob_views *ctx, const ob_view *v, VkFormat *out_color, VkFormat *out_depth)
{
    ob_image_info info;
    *out_color = *out_depth = VK_FORMAT_UNDEFINED;
    if (v->color.id && ob_image_get_info(ctx->dev, v->color, &info) == OB_OK) *out_color = info.format;
    ob_image d = v->depth.id ? v->depth : v->msaa_depth;
    if (d.id && ob_image_get_info(ctx->dev, d, &info) == OB_OK) *out_depth = info.format;
}

bool ob_views_prepare_effect(ob_views *ctx, ob_renderer *r, ob_effect *e, ob_view *v)
{
    if (!e) {
        ob_renderer_note_error(r, v->name, OB_ERR_NOT_FOUND);
        return false;
    }
    ob_effect_targets t = {.wireframe = false};   /* as ob_views_bind_effect binds it */
    ob_view_attachment_formats(v, ctx->dev, &t.color, &t.depth, &t.samples);
    if (ob_effect_pipeline_for(e, &t, NULL)) return true;
    ob_renderer_note_error(r, v->name, OB_ERR_VULKAN);
    return false;
}

bool ob_views_bind_effect(ob_views *ctx, ob_effect *e, const ob_view *v, ob_pipeline_manager *pm)
{
    if (!e) return false;
    ob_effect_targets t = {.wireframe = false};   /* the views' own passes stay filled */
    ob_view_attachment_formats(v, ctx->dev, &t.color, &t.depth, &t.samples);
    uint32_t id = 0;
    VkPipeline p = ob_effect_pipeline_for(e, &t, &id);
    if (!p) return false;
    ob_pipeline_manager_set_pipeline(pm, p, id, ob_effect_program(e));
    return true;
}

/* ------------------------------------------------------------ entity views */

static ob_views_entry *find_entry(ob_views_entry *list, uint32_t count, uint32_t node_id)
{
    for (uint32_t i = 0; i < count; i++)
        if (list[i].node_id == node_id) return &list[i];
    return NULL;
}

static ob_result add_entry(ob_views_entry **list, uint32_t *count, uint32_t *cap,
                           ob_views_entry e)
{
    ob_result r = ob_array_reserve((void **)list, cap, *count + 1, sizeof **list);
    if (r == OB_OK) (*list)[(*count)++] = e;
    return r;
}

/* The material library asks for the views an entity needs (its env map, its
 * simulation). Each is created on first need and pre-drawn with the current
 * view as its consumer. */
static void env_destroy(ob_views *ctx, ob_view *view, void *object)
{
    if (view->type == OB_VIEW_CUBE)
        ob_cube_view_destroy(ctx, object);
    else
        ob_paraboloid_view_destroy(ctx, object);
}

/* The env map of an entity: made on first need, of the context's kind. */
static ob_views_entry *env_entry(ob_views *ctx, ob_renderer *r, ob_node *entity)
{
    uint32_t id = ob_node_id(entity);
    ob_views_entry *e = find_entry(ctx->envs, ctx->env_count, id);
    if (e) return e;
    ob_result res;
    ob_view *view = NULL;
    void *object = NULL;
    if (ctx->env_map_kind == OB_ENV_MAP_CUBE) {
        ob_cube_view *cv = ob_cube_view_create(ctx, entity, &res);
        if (cv) view = ob_cube_view_base(cv);
        object = cv;
    } else {
        ob_paraboloid_view *pv = ob_paraboloid_view_create(ctx, entity, &res);
        if (pv) view = ob_paraboloid_view_base(pv);
        object = pv;
    }
    if (!view) {
        OB_LOG_E("views", "entity '%s' (id %u): cannot create its environment map: %s",
                 ob_node_name(entity), id, ob_result_name(res));
        ob_renderer_note_error(r, ob_node_name(entity), res);
        return NULL;
    }
    if (add_entry(&ctx->envs, &ctx->env_count, &ctx->env_cap, (ob_views_entry){id, view, object}) != OB_OK) {
        OB_LOG_E("views", "entity '%s' (id %u): no memory to keep its environment map; "
                 "skipped this frame", ob_node_name(entity), id);
        ob_renderer_note_error(r, ob_node_name(entity), OB_ERR_OUT_OF_HOST_MEMORY);
        env_destroy(ctx, view, object);
        return NULL;
    }
    return &ctx->envs[ctx->env_count - 1];
}

/* The material library asks for the views an entity needs (its env map, its
 * simulation). Each is created on first need and pre-drawn with the current
 * view as its consumer. */
static void queue_hook(void *user, ob_node *entity, ob_renderer *r, ob_view *requesting,
                       ob_view_type needed)
{
    ob_views *ctx = user;
    uint32_t id = ob_node_id(entity);
    if (needed == OB_VIEW_PARABOLOID || needed == OB_VIEW_CUBE) {
        ob_views_entry *e = env_entry(ctx, r, entity);
        if (!e) return;
        /* The map shows the sky around its owner: the context's sky colour,
         * else the clear colour of the first view that asks for it this
         * frame (PreRender's order is fixed, so ST and MT agree). */
        if (ctx->sky_color[3] > 0.0f) {
            memcpy(e->view->clear_color, ctx->sky_color, 3 * sizeof(float));
        } else if (requesting && e->view->queued_frame != ob_renderer_frame_serial(r)) {
            memcpy(e->view->clear_color, requesting->clear_color, 3 * sizeof(float));
        }
        e->view->clear_color[3] = 1.0f;
        ob_renderer_pre_render(r, e->view);
        /* Only a map that renders this frame is sampled: one left out (past
         * the recursion bound, say) was never written, so the entity is
         * drawn without its reflection instead. */
        if (e->view->queued_frame == ob_renderer_frame_serial(r)) {
            ob_result res = ob_renderer_attach_view(r, entity, e->view);
            if (res != OB_OK) {
                /* Unattached, the material cannot find the map: the entity
                 * draws without its reflection this frame. */
                OB_LOG_E("views", "entity '%s' (id %u): environment map not attached (%s); "
                         "drawn without reflections this frame", ob_node_name(entity), id,
                         ob_result_name(res));
                ob_renderer_note_error(r, e->view->name, res);
            }
        }
    }
}

void ob_views_queue_shadows(ob_views *ctx, ob_renderer *r, ob_view *consumer)
{
    ob_views_report_light_limit(ctx, r);
    uint32_t count = 0;
    ob_node *const *lights = ob_scene_lights(ob_renderer_scene(r), &count);
    bool shaded_found = false;
    for (uint32_t i = 0; i < count; i++) {
        const ob_light_desc *l = ob_node_get_light(lights[i]);
        if (l->type != OB_LIGHT_DIRECTIONAL) continue;
        /* Only the first directional light is shaded (ob_views_set_common_params,
         * the one ShadowMap of lit.frag): a map of another would be sampled
         * as the first one's shadow (issue 25.6). */
        bool shaded = !shaded_found;
        shaded_found = true;
        if (!l->casts_shadows) continue;
        char name[64];
        snprintf(name, sizeof name, "shadow:%s", ob_node_name(lights[i]));
        if (!shaded || !(l->intensity > 0.0f)) {
            ob_renderer_note_skipped(r, name, OB_SKIP_NOT_NEEDED);
            continue;
        }
        uint32_t id = ob_node_id(lights[i]);
        ob_views_entry *e = find_entry(ctx->shadows, ctx->shadow_count, id);
        if (!e) {
            ob_result res;
            ob_shadow_view *sv = ob_shadow_view_create(ctx, lights[i], &res);
            if (!sv) {
                OB_LOG_E("views", "light '%s': cannot create its shadow map: %s",
                         ob_node_name(lights[i]), ob_result_name(res));
                ob_renderer_note_error(r, name, res);
                continue;
            }
            if (add_entry(&ctx->shadows, &ctx->shadow_count, &ctx->shadow_cap,
                          (ob_views_entry){id, NULL, sv}) != OB_OK) {
                OB_LOG_E("views", "light '%s': no memory to keep its shadow map; skipped this frame",
                         ob_node_name(lights[i]));
                ob_renderer_note_error(r, name, OB_ERR_OUT_OF_HOST_MEMORY);
                ob_shadow_view_destroy(ctx, sv);
                continue;
            }
            e = &ctx->shadows[ctx->shadow_count - 1];
        }
        ob_shadow_view_pre_render(e->owner_object, r, consumer);
    }
    ob_views_queue_local_shadows(ctx, r, consumer);
}

ob_result ob_views_add_system(ob_views *ctx, ob_node *emitter, ob_view *sim, ob_particle_system *ps)
{
    return add_entry(&ctx->systems, &ctx->system_count, &ctx->system_cap,
                     (ob_views_entry){ob_node_id(emitter), sim, ps});
}

void ob_views_remove_system(ob_views *ctx, ob_particle_system *ps)
{
    for (uint32_t i = 0; i < ctx->system_count; i++) {
        if (ctx->systems[i].owner_object == ps) {
            ctx->systems[i] = ctx->systems[--ctx->system_count];
            return;
        }
    }
}

void ob_views_queue_simulations(ob_views *ctx, ob_renderer *r, ob_view *consumer)
{
    if (ctx->system_count == 0) return;
    for (uint32_t i = 0; i < consumer->item_count; i++) {
        ob_views_entry *e = find_entry(ctx->systems, ctx->system_count,
                                       ob_node_id(consumer->items[i].node));
        if (e) ob_renderer_pre_render(r, e->view);
    }
}

/* ------------------------------------------------------------ vertex input */

/* The standard layout as an effect's vertex input, made once: constant
 * after that, so any thread may read it (ob_once_run orders the write
 * before every reader; listed in ob_core.h). */
static ob_effect_vertex_input standard_input;

static ob_result make_standard_input(void)
{
    const ob_vertex_layout *l = ob_vertex_layout_standard();
    standard_input.stride = l->stride;
    standard_input.attribute_count = l->attribute_count;
    for (uint32_t i = 0; i < l->attribute_count; i++) {
        standard_input.attributes[i].location = l->attributes[i].location;
        standard_input.attributes[i].format = l->attributes[i].format;
        standard_input.attributes[i].offset = l->attributes[i].offset;
    }
    return OB_OK;
}
static ob_once standard_input_once = OB_ONCE_INIT("standard input", make_standard_input);

const ob_effect_vertex_input *ob_views_standard_input(void)
{
    ob_once_run(&standard_input_once);
    return &standard_input;
}

/* ------------------------------------------------------------ context */

ob_views *ob_views_create(const ob_views_desc *desc, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_views *ctx = NULL;
    if (!desc || !desc->renderer || !desc->materials || !desc->effects) {
        OB_LOG_E("views", "ob_views_create: no %s", !desc ? "desc" : !desc->renderer ? "renderer"
                 : !desc->materials ? "material library" : "effect context");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    ctx = ob_calloc(1, sizeof *ctx);
    if (!ctx) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    ctx->r = desc->renderer;
    ctx->dev = ob_renderer_device(desc->renderer);
    ctx->materials = desc->materials;
    ctx->effects = desc->effects;
    r = ob_views_set_env_map_size(ctx, desc->env_map_size);
    if (r == OB_OK) r = ob_views_set_shadow_map_size(ctx, desc->shadow_map_size);
    if (r == OB_OK) r = ob_views_set_shadow_cascades(ctx, desc->shadow_cascades);
    if (r == OB_OK) r = ob_views_set_shadow_distance(ctx, desc->shadow_distance);
    if (r == OB_OK) r = ob_views_set_shadow_split_lambda(ctx, desc->shadow_split_lambda);
    if (r == OB_OK) r = ob_views_set_lod_error(ctx, desc->lod_error);
    if (r != OB_OK) goto fail_destroy_views;
    if ((unsigned)desc->env_map_kind >= OB_ENV_MAP_KIND_COUNT) {
        OB_LOG_E("views", "env_map_kind %d is not a kind of environment map", (int)desc->env_map_kind);
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_destroy_views;
    }
    ctx->env_map_kind = desc->env_map_kind;
    memcpy(ctx->sky_color, desc->sky_color, sizeof ctx->sky_color);
    static const float default_ambient[4] = {1.0f, 1.0f, 1.0f, 0.15f};
    memcpy(ctx->ambient, desc->ambient[3] > 0.0f ? desc->ambient : default_ambient, sizeof ctx->ambient);
    ctx->dt = 1.0 / 60.0;
    r = register_params(ob_renderer_registry(ctx->r));
    if (r != OB_OK) goto fail_destroy_views;
    /* Samplers (ShadowMapSampler, EnvMapSampler, SourceImageSampler) are
     * the material library's defaults. */
    ob_renderer_set_material_iface(ctx->r, ob_material_iface_get());
    ob_renderer_set_geometry_iface(ctx->r, ob_geometry_iface_get());
    ob_material_library_set_queue_hook(ctx->materials, queue_hook, ctx);
    goto done;

fail_destroy_views:
    ob_views_destroy(ctx);
    ctx = NULL;
done:
    if (r != OB_OK) OB_LOG_E("views", "views context not created: %s", ob_result_name(r));
    if (out_result) *out_result = r;
    return ctx;
}

void ob_views_destroy(ob_views *ctx)
{
    if (!ctx) return;
    for (uint32_t i = 0; i < ctx->shadow_count; i++)
        ob_shadow_view_destroy(ctx, ctx->shadows[i].owner_object);
    for (uint32_t i = 0; i < ctx->env_count; i++)
        env_destroy(ctx, ctx->envs[i].view, ctx->envs[i].owner_object);
    ob_views_local_shadows_destroy(ctx);
    ob_free(ctx->shadows);
    ob_free(ctx->envs);
    ob_free(ctx->systems);
    ob_free(ctx->over_limit);
    ob_effect_destroy(ctx->text_effect);
    ob_effect_destroy(ctx->composite_effect);
    ob_effect_destroy(ctx->particle_sim_effect);
    if (ctx->materials) ob_material_library_set_queue_hook(ctx->materials, NULL, NULL);
    ob_free(ctx);
}

ob_renderer *ob_views_renderer(ob_views *ctx) { return ctx->r; }

void ob_views_set_time(ob_views *ctx, double time, double dt)
{
    ctx->time = time;
    ctx->dt = dt;
}

bool ob_views_set_env_map_kind(ob_views *ctx, ob_env_map_kind kind)
{
    if ((unsigned)kind >= OB_ENV_MAP_KIND_COUNT) {
        OB_LOG_E("views", "env map kind %d is not a kind of environment map; kept %s", (int)kind,
                 ctx->env_map_kind == OB_ENV_MAP_CUBE ? "cube" : "paraboloid");
        return false;
    }
    ctx->env_map_kind = kind;
    return true;
}

ob_env_map_kind ob_views_env_map_kind(const ob_views *ctx) { return ctx->env_map_kind; }

void ob_views_set_sky_color(ob_views *ctx, const float rgba[4])
{
    memcpy(ctx->sky_color, rgba, sizeof ctx->sky_color);
}

/* Whether a map of size x size can be made on this device (logged when not). */
static ob_result check_map_size(const ob_views *ctx, const char *what, uint32_t size)
{
    uint32_t max = ob_device_properties(ctx->dev)->limits.maxImageDimension2D;
    if (size <= max) return OB_OK;
    OB_LOG_E("views", "%s size %u refused: the device's images are at most %u", what, size, max);
    return OB_ERR_OUT_OF_RANGE;
}

void ob_views_set_light_tiles(ob_views *ctx, bool on) { ctx->light_tiles_off = !on; }

void ob_views_set_lod(ob_views *ctx, bool on) { ctx->lod_off = !on; }

ob_result ob_views_set_lod_error(ob_views *ctx, float pixels)
{
    if (!(pixels >= 0.0f) || !isfinite(pixels)) {
        OB_LOG_E("views", "level-of-detail error %g pixels refused: >= 0 and finite (0: the "
                 "default, 1)", (double)pixels);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ctx->lod_error = pixels > 0.0f ? pixels : 1.0f;
    return OB_OK;
}

float ob_views_lod_scale(const ob_views *ctx, float pixels_per_unit)
{
    return ctx->lod_off || !(pixels_per_unit > 0.0f) ? 0.0f : pixels_per_unit / ctx->lod_error;
}

ob_result ob_views_set_env_map_size(ob_views *ctx, uint32_t size)
{
    ob_result r = check_map_size(ctx, "environment map", size);
    if (r == OB_OK) ctx->env_map_size = size ? size : 256;
    return r;
}

ob_result ob_views_set_shadow_map_size(ob_views *ctx, uint32_t size)
{
    ob_result r = check_map_size(ctx, "shadow map", size);
    if (r == OB_OK) ctx->shadow_map_size = size ? size : 1024;
    return r;
}

ob_result ob_views_set_shadow_cascades(ob_views *ctx, uint32_t count)
{
    if (count > OB_SHADOW_MAX_CASCADES) {
        OB_LOG_E("views", "%u shadow cascades refused: 1..%u (0: the default, %u)", count,
                 OB_SHADOW_MAX_CASCADES, OB_SHADOW_DEFAULT_CASCADES);
        return OB_ERR_OUT_OF_RANGE;
    }
    ctx->shadow_cascades = count ? count : OB_SHADOW_DEFAULT_CASCADES;
    return OB_OK;
}

ob_result ob_views_set_shadow_distance(ob_views *ctx, float distance)
{
    if (!(distance >= 0.0f) || !isfinite(distance)) {
        OB_LOG_E("views", "shadow distance %g refused: a finite distance > 0 (0: from the scene)",
                 (double)distance);
        return OB_ERR_OUT_OF_RANGE;
    }
    ctx->shadow_distance = distance;
    return OB_OK;
}

ob_result ob_views_set_shadow_split_lambda(ob_views *ctx, float lambda)
{
    if (!(lambda >= 0.0f && lambda <= 1.0f)) {
        OB_LOG_E("views", "shadow split lambda %g refused: (0, 1] (0: the default, %g)",
                 (double)lambda, (double)OB_SHADOW_DEFAULT_SPLIT_LAMBDA);
        return OB_ERR_OUT_OF_RANGE;
    }
    ctx->shadow_split_lambda = lambda > 0.0f ? lambda : OB_SHADOW_DEFAULT_SPLIT_LAMBDA;
    return OB_OK;
}

ob_result ob_views_render(ob_views *ctx, ob_view *final_view)
{
    return ob_views_render_many(ctx, &final_view, 1);
}

ob_result ob_views_render_many(ob_views *ctx, ob_view *const *roots, uint32_t count)
{
    ob_renderer_pre_render_many(ctx->r, roots, count);
    /* Variants and pipelines are created on first need during PreRender
     * (and rarely while recording): report what this frame added. */
    ob_effect_counters now = ob_effect_context_counters(ctx->effects);
    ob_renderer_note_created(ctx->r, now.pipelines_created - ctx->counted.pipelines_created,
                             now.variants_compiled - ctx->counted.variants_compiled);
    ctx->counted = now;
    return ob_renderer_current_stats(ctx->r)->first_error;
}
