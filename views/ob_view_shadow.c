#include "ob_views_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Cascaded shadow maps of one directional light (docs/architecture.md,
 * "Shadows").
 *
 * The consumer camera's frustum, from its near plane to the shadow
 * distance, is cut into `count` slices (a blend of logarithmic and uniform
 * splits). Each slice gets a cascade: an ordinary render view with an
 * orthographic projection along the light, fitted to the slice's bounding
 * sphere (its size does not change when the camera turns) and moved only in
 * whole shadow-map texels of the light's frame (its texels do not crawl
 * when the camera moves). Its box reaches toward the light past the casters
 * the consumer sees, so casters outside the camera's view still throw their
 * shadows into it; the renderer culls each cascade like any view. All
 * cascades render into the layers of one 2D-array depth image (the first
 * cascade owns it, the others borrow it through first_layer), which
 * materials/shaders/shadow.glsl samples by the consumer's distance along the
 * fitted camera's axis, blending into the next cascade over the last
 * OB_SHADOW_BLEND_BAND of each slice. */

/* The part of each slice over which the shadow blends into the next
 * cascade (and the last one fades out), as a fraction of the slice's depth. */
#define OB_SHADOW_BLEND_BAND 0.1f

typedef struct ob_shadow_cascade {
    ob_view base;
    ob_shadow_view *set;
    float view[16], proj[16];
} ob_shadow_cascade;

struct ob_shadow_view {
    ob_views *ctx;
    ob_node *light;
    char name[48];                 /* "shadow:<light>": skips of the whole set */
    uint32_t count;                /* cascades (layers of `map`) */
    ob_image map;                  /* count layers; owned here */
    uint64_t queued_frame;         /* frame serial of the last fit that queued them */
    double fit_origin[3];          /* origin of the camera they were fitted for */
    float axis[3];                 /* its forward, world axes */
    float splits[OB_SHADOW_MAX_CASCADES];  /* far distance of each slice along axis */
    ob_shadow_cascade cascades[OB_SHADOW_MAX_CASCADES];
    ob_param shadow_map, matrices, split_param, info, axis_param;
};

/* What the consumer's culled list says for the fit: the light-space top
 * (toward the light) and depth extent of the casters it sees, and the
 * distance of its farthest visible point (for the default shadow distance).
 * Its culling already asked every material where it renders (a list not
 * made by ob_view_cull asks the interface per item): no scan of the scene. */
typedef struct caster_range {
    uint32_t casters;
    float top, bottom;             /* light-space z relative to the consumer's origin */
    float farthest;
} caster_range;

static caster_range consumer_casters(const ob_view *c, ob_renderer *r, const double light_z[3])
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    caster_range cr = {0, -FLT_MAX, FLT_MAX, 0.0f};
    bool culled = c->material_count > 0;
    for (uint32_t i = 0; i < c->item_count; i++) {
        double wc[3];
        float radius;
        if (culled) ob_view_item_sphere(c, i, wc, &radius);
        else ob_node_world_sphere(c->items[i].node, wc, &radius);
        double rel[3] = {wc[0] - c->origin[0], wc[1] - c->origin[1], wc[2] - c->origin[2]};
        cr.farthest = fmaxf(cr.farthest, (float)ob_dvec3_length(rel) + radius);
        bool casts = culled ? c->materials[ob_view_item_material(c, i)].mask & (1u << OB_VIEW_SHADOW)
                            : mi->renders(ob_node_get_renderable(c->items[i].node)->material,
                                          OB_VIEW_SHADOW);
        if (!casts) continue;
        float z = (float)ob_dvec3_dot(rel, light_z);
        cr.top = fmaxf(cr.top, z + radius);
        cr.bottom = fminf(cr.bottom, z - radius);
        cr.casters++;
    }
    return cr;
}

/* The consumer's camera from its view-projection (relative to its origin,
 * rotation only; engine perspective: reversed-Z, infinite far plane, so
 * clip w = k * distance along the forward axis and clip z = k * near). */
typedef struct camera_shape {
    float forward[3];
    float znear;
    float k2;                      /* tan^2 of the half-angles, summed: a corner at
                                      distance d is sqrt(k2) * d off the axis */
} camera_shape;

static bool camera_shape_of(const float vp[16], camera_shape *out)
{
    /* In double: the rows hold 1 / znear (scale_clip_to_near), whose
     * square leaves float's range in a scene of 1e-30 or 1e30. */
    double row[3][3], len[3];
    for (int j = 0; j < 3; j++) {
        int rj = j == 2 ? 3 : j;   /* rows x, y and w */
        for (int k = 0; k < 3; k++) row[j][k] = vp[k * 4 + rj];
        len[j] = ob_dvec3_length(row[j]);
    }
    if (!(len[0] > 0.0 && len[1] > 0.0 && len[2] > 0.0)) return false;
    for (int k = 0; k < 3; k++) out->forward[k] = (float)(row[2][k] / len[2]);
    out->znear = (float)(vp[14] / len[2]);
    double tx = len[2] / len[0], ty = len[2] / len[1];
    out->k2 = (float)(tx * tx + ty * ty);
    return out->znear > 0.0f && isfinite(out->znear) && isfinite(out->k2);
}

/* The practical split scheme: lambda of the logarithmic split plus
 * (1 - lambda) of the uniform one, between near and far. */
static float split_distance(float znear, float zfar, float lambda, uint32_t i, uint32_t count)
{
    float t = (float)i / (float)count;
    float log_split = znear * powf(zfar / znear, t);
    float uniform_split = znear + (zfar - znear) * t;
    return lambda * log_split + (1.0f - lambda) * uniform_split;
}

/* The smallest sphere around the frustum slice [d0, d1] of a camera of
 * shape k2: its centre on the axis, at *out_z. In double: the squares of a
 * 1e24-unit slice overflow float, those of a 1e-30 one underflow. */
static float slice_sphere(float d0, float d1, float k2, float *out_z)
{
    double a = d0, b = d1, k = k2;
    double z = 0.5 * (a + b) * (1.0 + k);
    if (z >= b) {
        *out_z = d1;
        return (float)(sqrt(k) * b);
    }
    *out_z = (float)z;
    return (float)sqrt((b - z) * (b - z) + k * b * b);
}

static void fit_cascade(ob_shadow_cascade *sc, const double axes[9], const double anchor[3],
                        const double centre[3], float radius, double caster_top,
                        float caster_depth, uint32_t size)
{
    ob_view *v = &sc->base;
    /* One texel more than the sphere on every side: snapping moves the box
     * by less than a texel. */
    double half = (double)radius * size / (size - 2.0);
    double texel = 2.0 * half / size;
    /* The texel grid is anchored at the light's node, not at the world's
     * origin: it holds still while the camera moves, and moves with a
     * scene moved as a whole (the same shadow at any coordinates). */
    double light[3], base[3];
    for (int k = 0; k < 3; k++) {
        base[k] = ob_dvec3_dot(&axes[3 * k], anchor);
        light[k] = floor((ob_dvec3_dot(&axes[3 * k], centre) - base[k]) / texel) * texel;
    }
    for (int k = 0; k < 3; k++)
        v->origin[k] = anchor[k] + axes[k] * light[0] + axes[3 + k] * light[1] + axes[6 + k] * light[2];
    ob_math_view_relative(axes, v->origin, v->origin, sc->view);
    /* Toward the light: past the highest caster the consumer sees by its
     * casters' depth (a caster out of view above them still fits), in
     * whole box sizes so the depth mapping holds still as well. */
    double reach = fmax(half, caster_top - base[2] - light[2] + caster_depth);
    reach = ceil(reach / (2.0 * half)) * 2.0 * half;
    ob_math_ortho_reverse_z((float)-half, (float)half, (float)-half, (float)half, (float)-reach,
                            (float)(half + texel), sc->proj);
    ob_mat4_mul(sc->proj, sc->view, v->view_proj);
    /* Levels of detail by texels: the same size at any distance. */
    v->lod_scale = ob_views_lod_scale(sc->set->ctx, (float)(1.0 / texel));
    v->lod_ortho = true;
}

/* Splits and fits every cascade for consumer c; false when c sees no
 * caster or is no perspective camera. */
static bool fit_cascades(ob_shadow_view *sv, ob_renderer *r, const ob_view *c)
{
    const ob_views *ctx = sv->ctx;
    camera_shape cam;
    if (!camera_shape_of(c->view_proj, &cam)) return false;
    float right[3], up[3], fwd[3];
    ob_node_world_axes(sv->light, right, up, fwd);
    double dir[3] = {fwd[0], fwd[1], fwd[2]}, upd[3] = {0.0, 1.0, 0.0}, axes[9];
    ob_math_look_rotation(dir, upd, axes);
    caster_range cr = consumer_casters(c, r, &axes[6]);
    if (cr.casters == 0) return false;

    /* Default distance: the farthest point the camera sees, rounded up to a
     * power of two times the near distance, so that turning the camera
     * rarely changes it (a change resizes every cascade) and a scene scaled
     * as a whole, near plane included, gets the same cascades. */
    float zfar = ctx->shadow_distance;
    if (!(zfar > 0.0f))
        zfar = cam.znear * exp2f(ceilf(log2f(fmaxf(cr.farthest / cam.znear, 2.0f))));
    zfar = fmaxf(zfar, 2.0f * cam.znear);
    double anchor[3];
    ob_node_world_position(sv->light, anchor);
    memcpy(sv->fit_origin, c->origin, sizeof sv->fit_origin);
    memcpy(sv->axis, cam.forward, sizeof sv->axis);
    double caster_top = cr.top + ob_dvec3_dot(&axes[6], c->origin);
    float caster_depth = cr.top - cr.bottom;
    float start = cam.znear, prev = cam.znear;
    for (uint32_t i = 0; i < sv->count; i++) {
        float end = split_distance(cam.znear, zfar, ctx->shadow_split_lambda, i + 1, sv->count);
        if (i + 1 == sv->count) end = zfar;
        sv->splits[i] = end;
        /* The slice reaches back over the previous one's blend band. */
        float from = start - OB_SHADOW_BLEND_BAND * (start - prev), z;
        float radius = slice_sphere(from, end, cam.k2, &z);
        double centre[3];
        for (int k = 0; k < 3; k++) centre[k] = c->origin[k] + (double)cam.forward[k] * z;
        fit_cascade(&sv->cascades[i], axes, anchor, centre, radius, caster_top, caster_depth,
                    sv->cascades[i].base.width);
        prev = start;
        start = end;
    }
    return true;
}

static bool cascade_pre_cull(ob_view *v, ob_renderer *r)
{
    if (v->queued_frame == ob_renderer_frame_serial(r)) {
        /* Queued by an earlier consumer this frame: fitted and culled for
         * it. Refitting now would record its culled list through another
         * frustum (issue 25.5); the queue call makes this consumer depend
         * on it. */
        ob_renderer_queue_view(r, v);
        return false;
    }
    if (!ob_renderer_queue_view(r, v)) return false;
    v->cull_exclude = NULL;
    return true;
}

static void cascade_post_cull(ob_view *v, ob_renderer *r)
{
    ob_shadow_cascade *sc = (ob_shadow_cascade *)v;
    ob_material_library_prepare_view(sc->set->ctx->materials, r, v);
}

static void cascade_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_shadow_cascade *sc = (ob_shadow_cascade *)v;
    (void)r;
    ob_views_set_common_params(sc->set->ctx, v, params, sc->view, sc->proj);
}

/* Every cascade hands the consumer the whole set (the same values from
 * each): the array map, a matrix per cascade from the consumer's
 * camera-relative space, the split distances and the axis they are
 * measured along. */
static void cascade_usage_params(ob_view *v, ob_renderer *r, ob_params *params,
                                 const ob_view *consumer)
{
    const ob_shadow_view *sv = ((ob_shadow_cascade *)v)->set;
    (void)r;
    const double *at = consumer ? consumer->origin : sv->fit_origin;
    float m[OB_SHADOW_MAX_CASCADES][16];
    float splits[4] = {0, 0, 0, 0};
    for (uint32_t i = 0; i < OB_SHADOW_MAX_CASCADES; i++) {
        if (i >= sv->count) {
            ob_mat4_identity(m[i]);
            continue;
        }
        /* The consumer's positions are relative to its own origin. */
        const ob_view *cv = &sv->cascades[i].base;
        float t[16];
        ob_mat4_identity(t);
        for (int k = 0; k < 3; k++) t[12 + k] = (float)(at[k] - cv->origin[k]);
        ob_mat4_mul(cv->view_proj, t, m[i]);
        splits[i] = sv->splits[i];
    }
    double offset = 0.0;
    for (int k = 0; k < 3; k++) offset += (double)sv->axis[k] * (at[k] - sv->fit_origin[k]);
    float axis[4] = {sv->axis[0], sv->axis[1], sv->axis[2], (float)offset};
    float info[4] = {(float)sv->count, OB_SHADOW_BLEND_BAND, 0.0f, 0.0f};
    ob_params_set_texture(params, sv->shadow_map, sv->map);
    ob_params_set_mat4_array(params, sv->matrices, &m[0][0], OB_SHADOW_MAX_CASCADES);
    ob_params_set_vec4(params, sv->split_param, splits);
    ob_params_set_vec4(params, sv->info, info);
    ob_params_set_vec4(params, sv->axis_param, axis);
}

static const ob_view_vtbl cascade_vtbl = {
    .type_name = "shadow",
    .pre_cull = cascade_pre_cull,
    .post_cull = cascade_post_cull,
    .set_render_params = cascade_render_params,
    .set_usage_params = cascade_usage_params,
    .record = ob_view_record_draw_list,
};

/* The array depth image of `count` layers, lent to every cascade. */
static ob_result make_map(ob_shadow_view *sv, uint32_t count)
{
    ob_views *ctx = sv->ctx;
    char name[64];
    snprintf(name, sizeof name, "%s.depth", sv->name);
    uint32_t size = ctx->shadow_map_size;
    ob_image_desc d = {.width = size, .height = size, .layers = count, .array = true,
                       .format = OB_VIEWS_DEPTH_FORMAT, .name = name,
                       .usage = OB_IMAGE_DEPTH_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_DST};
    ob_result r = OB_OK;
    ob_image map = ob_image_create(ctx->dev, &d, &r);
    if (!map.id) return r;
    ob_image_destroy(ctx->dev, sv->map);   /* deferred: frames in flight keep theirs */
    sv->map = map;
    sv->count = count;
    for (uint32_t i = 0; i < OB_SHADOW_MAX_CASCADES; i++) {
        ob_view *v = &sv->cascades[i].base;
        v->depth = i < count ? map : (ob_image){0};
        v->first_layer = i;
        v->width = v->height = size;
        v->layer_count = 1;
    }
    return OB_OK;
}

ob_shadow_view *ob_shadow_view_create(ob_views *ctx, ob_node *light, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_shadow_view *sv = ob_calloc(1, sizeof *sv);
    if (!sv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    sv->ctx = ctx;
    sv->light = light;
    snprintf(sv->name, sizeof sv->name, "shadow:%s", ob_node_name(light));
    for (uint32_t i = 0; i < OB_SHADOW_MAX_CASCADES; i++) {
        ob_shadow_cascade *sc = &sv->cascades[i];
        char name[64];
        snprintf(name, sizeof name, "%s:c%u", sv->name, i);
        ob_view_init(&sc->base, &cascade_vtbl, OB_VIEW_SHADOW, name);
        sc->set = sv;
        sc->base.clear_depth = 0.0f;
    }
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    sv->shadow_map = ob_param_find(reg, "ShadowMap");
    sv->matrices = ob_param_find(reg, "ShadowMatrices");
    sv->split_param = ob_param_find(reg, "ShadowSplits");
    sv->info = ob_param_find(reg, "ShadowCascades");
    sv->axis_param = ob_param_find(reg, "ShadowAxis");
    r = make_map(sv, ctx->shadow_cascades);
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
    if (!v) return;
    for (uint32_t i = 0; i < OB_SHADOW_MAX_CASCADES; i++) ob_view_release(&v->cascades[i].base);
    ob_image_destroy(ctx->dev, v->map);
    ob_free(v);
}

const char *ob_shadow_view_name(const ob_shadow_view *v) { return v->name; }

void ob_shadow_view_pre_render(ob_shadow_view *sv, ob_renderer *r, ob_view *consumer)
{
    uint64_t frame = ob_renderer_frame_serial(r);
    if (sv->queued_frame != frame) {
        /* A new count applies from the next frame that fits the set. */
        if (sv->count != sv->ctx->shadow_cascades) {
            ob_result res = make_map(sv, sv->ctx->shadow_cascades);
            if (res != OB_OK) {
                OB_LOG_E("views", "light '%s': cannot remake its shadow map for %u cascades (%s); "
                         "it keeps %u", ob_node_name(sv->light), sv->ctx->shadow_cascades,
                         ob_result_name(res), sv->count);
                ob_renderer_note_error(r, sv->name, res);
            }
        }
        if (!consumer || !fit_cascades(sv, r, consumer)) {
            ob_renderer_note_skipped(r, sv->name, OB_SKIP_NO_CASTERS);
            return;
        }
        sv->queued_frame = frame;
    }
    for (uint32_t i = 0; i < sv->count; i++) ob_renderer_pre_render(r, &sv->cascades[i].base);
}
