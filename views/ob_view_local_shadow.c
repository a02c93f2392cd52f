/* ob_view_local_shadow.c — shadow maps of point and spot lights.
 *
 * Design (docs/architecture.md, "Shadows of point and spot lights"):
 *   - one view per shadow-casting local light, type OB_VIEW_SHADOW (the
 *     materials' depth-only pass), marked local_shadow so its consumers
 *     take the LOCAL_SHADOWS variants, not the directional SHADOWS one;
 *   - a spot light: one perspective map over its outer cone (reversed-Z,
 *     infinite far plane like every camera; the range bounds what is drawn
 *     through the per-item reach, not a far plane);
 *   - a point light: a cube, six 90-degree faces into six layers, with the
 *     cube environment map's per-item face reach (an item is recorded only
 *     into the faces its bound reaches). A cube rather than a dual
 *     paraboloid: straight edges stay straight at any tessellation (a
 *     paraboloid bends them, and a coarse floor's shadow with them), the
 *     lookup is an ordinary projective compare with PCF, and the face
 *     reach keeps the extra work to the faces that have casters;
 *   - every map is a range of layers of one depth 2D array that the views
 *     share (first_layer), so a lit shader samples any number of shadowed
 *     lights through one binding (LocalShadowMaps, set 1 binding 10) and
 *     one matrix block (LocalShadowMatrices, set 0 binding 5). Layers are
 *     handed out per frame, in PreRender order, to the lights a camera
 *     needs: the same in every threading mode;
 *   - a light's view is left out (OB_SKIP_NOT_NEEDED) when its range and
 *     cone reach no item the consumer sees; a view whose draw list is empty
 *     (no casters) is reported empty by the renderer.
 * The views are pre-rendered like any other (queued from the camera's
 * post_cull, culled in the next wave on the worker pool, recorded as jobs).
 */
#include "ob_views_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct ob_local_shadow_view {
    ob_view base;
    ob_views *ctx;
    ob_node *light;           /* this frame's node of light_id */
    uint32_t light_id;        /* nodes are matched by id: a pointer may be reused */
    bool point;
    bool warned_over_limit;   /* logged once by name, not every frame */
    float view[16], proj[16]; /* spot: the light's view; point: face 0's (others per layer) */
    /* Per item of this frame's draw list: bit L set when its bound reaches
     * layer L (a spot's cone and range, a point's face and range). */
    uint8_t *reach;
    uint32_t reach_cap;
    bool reach_valid;         /* false: no memory for it this frame, draw all */
} ob_local_shadow_view;

struct ob_local_shadows {
    ob_image maps;            /* OB_MAX_LOCAL_SHADOW_LAYERS layers of depth */
    uint32_t size;            /* its side: half the shadow-map size when made, at least 64 */
    ob_sampler sampler;       /* compare, as the directional map's */
    ob_param maps_param, matrices_param;
    ob_local_shadow_view **views;
    uint32_t count, cap;
    uint64_t frame;           /* the frame next_layer counts in */
    uint32_t next_layer;
};

#define LOCAL_SHADOW_PI 3.14159265358979323846

/* ------------------------------------------------------------ the view */

static bool local_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_local_shadow_view *sv = (ob_local_shadow_view *)v;
    if (v->queued_frame == ob_renderer_frame_serial(r)) {
        /* Already queued this frame by another camera: the light's map does
         * not depend on its consumer, so it only gains a dependant. */
        ob_renderer_queue_view(r, v);
        return false;
    }
    if (!ob_renderer_queue_view(r, v)) return false;
    const ob_light_desc *l = ob_node_get_light(sv->light);
    ob_node_world_position(sv->light, v->origin);
    /* Reversed-Z keeps depth precision over any near/far ratio: the near
     * plane only has to stay clear of casters, a thousandth of the range. */
    float znear = l->range > 0.0f ? fminf(l->range * 1e-3f, 0.05f) : 0.05f;
    if (sv->point) {
        ob_math_perspective_reverse_z((float)(LOCAL_SHADOW_PI / 2.0), 1.0f, znear, sv->proj);
        ob_views_cube_face_view(0, sv->view);
        ob_mat4_identity(v->view_proj);
        v->no_frustum = true;   /* every direction: the face reach sorts items */
        /* Cube faces: their edges' pixels per unit, as for cube maps. */
        v->lod_scale = ob_views_lod_scale(sv->ctx, (float)v->width);
    } else {
        /* The cone plus a little for the PCF taps at its rim. */
        float fov = fminf(2.0f * l->outer_angle + 0.05f, (float)LOCAL_SHADOW_PI * 0.98f);
        ob_math_perspective_reverse_z(fov, 1.0f, znear, sv->proj);
        ob_node_view_relative(sv->light, v->origin, sv->view);
        ob_mat4_mul(sv->proj, sv->view, v->view_proj);
        v->no_frustum = false;
        v->lod_scale = ob_views_lod_scale(sv->ctx, 0.5f * (float)v->height / tanf(0.5f * fov));
    }
    v->cull_exclude = NULL;
    return true;
}

static void local_post_cull(ob_view *v, ob_renderer *r)
{
    ob_local_shadow_view *sv = (ob_local_shadow_view *)v;
    const ob_light_desc *l = ob_node_get_light(sv->light);
    sv->reach_valid = ob_array_reserve((void **)&sv->reach, &sv->reach_cap, v->item_count,
                                       sizeof *sv->reach) == OB_OK;
    if (!sv->reach_valid)
        OB_LOG_W("view", "view '%s': no memory for the per-layer item masks; every item is drawn "
                 "in every layer this frame", v->name);
    float right[3], up[3], fwd[3];
    ob_node_world_axes(sv->light, right, up, fwd);
    float cos_outer = cosf(l->outer_angle);
    bool any = !sv->reach_valid;
    for (uint32_t i = 0; sv->reach_valid && i < v->item_count; i++) {
        double c[3];
        float radius;
        ob_view_item_sphere(v, i, c, &radius);
        double rel[3] = {c[0] - v->origin[0], c[1] - v->origin[1], c[2] - v->origin[2]};
        double dist = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
        /* Widened by far more than the float rounding of a vertex. */
        double reach = (double)radius + ((double)radius + dist) * 1e-5 + 1e-6;
        if (l->range > 0.0f && dist - reach > (double)l->range)
            sv->reach[i] = 0;
        else if (sv->point)
            sv->reach[i] = ob_views_cube_faces(rel, reach);
        else
            sv->reach[i] = ob_views_spot_reaches(fwd, cos_outer, l->range, rel, reach) ? 1u : 0u;
        any = any || sv->reach[i];
    }
    /* No caster within the cone and range: nothing to record, which the
     * renderer reports (OB_SKIP_EMPTY) and the layers are only cleared. */
    if (!any) v->item_count = 0;
    ob_material_library_prepare_view(sv->ctx->materials, r, v);
}

static void local_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_local_shadow_view *sv = (ob_local_shadow_view *)v;
    (void)r;
    ob_views_set_common_params(sv->ctx, v, params, sv->view, sv->proj);
}

static void local_usage_params(ob_view *v, ob_renderer *r, ob_params *params, const ob_view *consumer)
{
    ob_local_shadow_view *sv = (ob_local_shadow_view *)v;
    (void)r;
    (void)consumer;   /* the matrices come with the consumer's light table */
    ob_params_set_texture(params, sv->ctx->local_shadows->maps_param, v->depth);
}

static void local_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                         uint32_t first, uint32_t count)
{
    ob_local_shadow_view *sv = (ob_local_shadow_view *)v;
    if (sv->point) {
        float view[16];
        ob_views_cube_face_view(layer, view);
        const ob_param_builtins *b = ob_param_registry_builtins(ob_renderer_registry(r));
        ob_params_set_mat4(ob_pipeline_manager_params(pm), b->view, view);
    }
    ob_views_record_masked(v, r, pm, first, count, sv->reach_valid ? sv->reach : NULL,
                           (uint8_t)(1u << layer));
}

static const ob_view_vtbl local_shadow_vtbl = {
    .type_name = "shadow",
    .pre_cull = local_pre_cull,
    .post_cull = local_post_cull,
    .set_render_params = local_render_params,
    .set_usage_params = local_usage_params,
    .record = local_record,
};

static void view_destroy(ob_views *ctx, ob_local_shadow_view *sv)
{
    if (!sv) return;
    ob_free(sv->reach);
    sv->base.depth = (ob_image){0};   /* the shared array is not the view's */
    ob_views_free_view(ctx, &sv->base);
}

/* ------------------------------------------------------------ shared state */

/* The array, its sampler and parameters: made with the first view. */
static ob_result state_create(ob_views *ctx)
{
    ob_local_shadows *s = ob_calloc(1, sizeof *s);
    if (!s) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_result r = OB_OK;
    s->size = ctx->shadow_map_size / 2 >= 64 ? ctx->shadow_map_size / 2 : 64;
    ob_image_desc d = {.width = s->size, .height = s->size, .layers = OB_MAX_LOCAL_SHADOW_LAYERS,
                       .format = OB_VIEWS_DEPTH_FORMAT,
                       .usage = OB_IMAGE_DEPTH_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_DST,
                       .name = "shadow:local.depth"};
    s->maps = ob_image_create(ctx->dev, &d, &r);
    ob_sampler_desc sd = {.filter = VK_FILTER_LINEAR, .address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                          .compare = true, .compare_op = VK_COMPARE_OP_GREATER_OR_EQUAL,
                          .name = "LocalShadowMapsSampler"};
    if (r == OB_OK) s->sampler = ob_sampler_create(ctx->dev, &sd, &r);
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    const struct {
        const char *name;
        ob_param_type type;
        uint32_t count;
        ob_param *out;
    } params[] = {
        {"LocalShadowMaps", OB_PARAM_TEXTURE, 1, &s->maps_param},
        {"LocalShadowMatrices", OB_PARAM_MAT4_ARRAY, OB_MAX_LOCAL_SHADOW_LAYERS, &s->matrices_param},
        {"LocalShadowMapsSampler", OB_PARAM_SAMPLER, 1, NULL},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(params) && r == OB_OK; i++) {
        ob_param p = ob_param_find(reg, params[i].name);
        if (!p.id) p = ob_param_register(reg, params[i].name, params[i].type, params[i].count, &r);
        if (params[i].out) *params[i].out = p;
        else if (r == OB_OK) r = ob_params_init_sampler(reg, p, s->sampler);
    }
    if (r != OB_OK) {
        ob_sampler_destroy(ctx->dev, s->sampler);
        ob_image_destroy(ctx->dev, s->maps);
        ob_free(s);
        return r;
    }
    ctx->local_shadows = s;
    return OB_OK;
}

void ob_views_local_shadows_destroy(ob_views *ctx)
{
    ob_local_shadows *s = ctx->local_shadows;
    if (!s) return;
    for (uint32_t i = 0; i < s->count; i++) view_destroy(ctx, s->views[i]);
    ob_free(s->views);
    ob_sampler_destroy(ctx->dev, s->sampler);
    ob_image_destroy(ctx->dev, s->maps);
    ob_free(s);
    ctx->local_shadows = NULL;
}

static ob_local_shadow_view *find_view(const ob_local_shadows *s, const ob_node *light)
{
    uint32_t id = ob_node_id(light);
    for (uint32_t i = 0; s && i < s->count; i++)
        if (s->views[i]->light_id == id) return s->views[i];
    return NULL;
}

/* The light as it is now (a spot may have become a point light). */
static void view_follow(ob_local_shadow_view *sv, ob_node *light)
{
    sv->light = light;
    sv->point = ob_node_get_light(light)->type == OB_LIGHT_POINT;
    sv->base.layer_count = sv->point ? 6 : 1;
}

/* The light's view, made on first need (logged and noted on failure). */
static ob_local_shadow_view *view_for(ob_views *ctx, ob_renderer *r, ob_node *light, const char *name)
{
    ob_result res = OB_OK;
    if (!ctx->local_shadows) res = state_create(ctx);
    ob_local_shadows *s = ctx->local_shadows;
    ob_local_shadow_view *sv = find_view(s, light);
    if (sv) {
        view_follow(sv, light);
        return sv;
    }
    if (res == OB_OK) res = ob_array_reserve((void **)&s->views, &s->cap, s->count + 1, sizeof *s->views);
    if (res == OB_OK && !(sv = ob_calloc(1, sizeof *sv))) res = OB_ERR_OUT_OF_HOST_MEMORY;
    if (res != OB_OK) {
        OB_LOG_E("views", "light '%s': cannot create its shadow map: %s", ob_node_name(light),
                 ob_result_name(res));
        ob_renderer_note_error(r, name, res);
        return NULL;
    }
    ob_view_init(&sv->base, &local_shadow_vtbl, OB_VIEW_SHADOW, name);
    sv->ctx = ctx;
    sv->light_id = ob_node_id(light);
    view_follow(sv, light);
    sv->base.local_shadow = true;
    sv->base.clear_depth = 0.0f;
    sv->base.depth = s->maps;
    sv->base.width = sv->base.height = s->size;
    s->views[s->count++] = sv;
    return sv;
}

/* ------------------------------------------------------------ queueing */

/* Whether the light reaches an item the consumer sees: a shadow no visible
 * surface can receive is not worth drawing. */
static bool reaches_visible(const ob_view *consumer, const ob_node *light, const ob_light_desc *l)
{
    double pos[3];
    ob_node_world_position(light, pos);
    float right[3], up[3], fwd[3];
    ob_node_world_axes(light, right, up, fwd);
    float cos_outer = cosf(l->outer_angle);
    for (uint32_t i = 0; i < consumer->item_count; i++) {
        double c[3];
        float radius;
        ob_view_item_sphere(consumer, i, c, &radius);
        double rel[3] = {c[0] - pos[0], c[1] - pos[1], c[2] - pos[2]};
        if (l->type == OB_LIGHT_SPOT) {
            if (ob_views_spot_reaches(fwd, cos_outer, l->range, rel, radius)) return true;
        } else if (!(l->range > 0.0f) ||
                   sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]) - radius <= l->range) {
            return true;
        }
    }
    return false;
}

void ob_views_queue_local_shadows(ob_views *ctx, ob_renderer *r, ob_view *consumer)
{
    uint32_t count = 0, used = 0;
    ob_scene *scene = ob_renderer_scene(r);
    ob_node *const *lights = scene ? ob_scene_lights(scene, &count) : NULL;
    uint64_t frame = ob_renderer_frame_serial(r);
    for (uint32_t i = 0; i < count && used < OB_MAX_LIGHTS; i++) {
        const ob_light_desc *l = ob_node_get_light(lights[i]);
        if (l->type == OB_LIGHT_DIRECTIONAL || !(l->intensity > 0.0f)) continue;
        used++;   /* the same lights, in the same order, as the light table */
        if (!l->casts_shadows) continue;
        char name[48];
        snprintf(name, sizeof name, "shadow:%s", ob_node_name(lights[i]));
        if (!reaches_visible(consumer, lights[i], l)) {
            ob_renderer_note_skipped(r, name, OB_SKIP_NOT_NEEDED);
            continue;
        }
        ob_local_shadow_view *sv = view_for(ctx, r, lights[i], name);
        if (!sv) continue;
        ob_local_shadows *s = ctx->local_shadows;
        if (s->frame != frame) {
            s->frame = frame;
            s->next_layer = 0;
        }
        bool fresh = sv->base.queued_frame != frame;
        if (fresh) {
            if (s->next_layer + sv->base.layer_count > OB_MAX_LOCAL_SHADOW_LAYERS) {
                if (!sv->warned_over_limit)
                    OB_LOG_W("views", "light '%s': its shadow needs %u layers, over the %u shadow "
                             "layers of point and spot lights a frame (docs/limits.md); it lights "
                             "unshadowed", ob_node_name(lights[i]), sv->base.layer_count,
                             OB_MAX_LOCAL_SHADOW_LAYERS);
                sv->warned_over_limit = true;
                ob_renderer_note_skipped(r, name, OB_SKIP_OVER_LIMIT);
                continue;
            }
            sv->base.first_layer = s->next_layer;
        }
        ob_renderer_pre_render(r, &sv->base);
        if (fresh && sv->base.queued_frame == frame) s->next_layer += sv->base.layer_count;
    }
}

/* ------------------------------------------------------------ consumers */

float ob_views_local_shadow_layer(const ob_views *ctx, const ob_view *v, const ob_node *light,
                                  float mats[OB_MAX_LOCAL_SHADOW_LAYERS][16])
{
    const ob_local_shadow_view *sv = find_view(ctx->local_shadows, light);
    if (!sv) return -1.0f;
    bool sampled = false;
    for (uint32_t i = 0; i < v->dep_count && !sampled; i++) sampled = v->deps[i] == &sv->base;
    if (!sampled) return -1.0f;
    const ob_view *b = &sv->base;
    /* The consumer's positions are relative to its own origin. */
    float t[16], face[16], vp[16];
    ob_mat4_identity(t);
    t[12] = (float)(v->origin[0] - b->origin[0]);
    t[13] = (float)(v->origin[1] - b->origin[1]);
    t[14] = (float)(v->origin[2] - b->origin[2]);
    for (uint32_t f = 0; f < b->layer_count; f++) {
        if (sv->point) ob_views_cube_face_view(f, face);
        ob_mat4_mul(sv->proj, sv->point ? face : sv->view, vp);
        ob_mat4_mul(vp, t, mats[b->first_layer + f]);
    }
    return (float)b->first_layer;
}

void ob_views_set_local_shadow_matrices(const ob_views *ctx, ob_params *params,
                                        const float mats[OB_MAX_LOCAL_SHADOW_LAYERS][16])
{
    if (ctx->local_shadows)
        ob_params_set_mat4_array(params, ctx->local_shadows->matrices_param, &mats[0][0],
                                 OB_MAX_LOCAL_SHADOW_LAYERS);
}
