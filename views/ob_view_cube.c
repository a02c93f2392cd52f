#include "ob_views_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Cube environment map of one entity: six 90-degree perspective views from
 * the owner's centre into the six layers of one 2D array (faces +X, -X, +Y,
 * -Y, +Z, -Z, with the bases of materials/shaders/envmap.glsl's
 * ob_cube_face: the two must agree). The map's frame is the world's, like
 * the paraboloid's. Each face is an ordinary perspective projection, so
 * straight edges stay straight (no subdivision needed, unlike the
 * paraboloid), at three times the paraboloid's rendering work for the same
 * side. Linear HDR with a full mip chain, as the paraboloid.
 *
 * Lifecycle and thread rule as the paraboloid view: made by the views
 * context on the first need of a reflective entity, pre-rendered on the
 * render thread; record and the params callbacks only read the view. */
struct ob_cube_view {
    ob_view base;
    ob_views *ctx;
    ob_node *owner;
    ob_param env_map, env_matrix, env_info;
    float proj[16];
    /* Per item of this frame's draw list: bit F set when its bound reaches
     * face F's frustum (filled in post_cull, read by the recording). */
    uint8_t *reach;
    uint32_t reach_cap;
    bool reach_valid;      /* false: no memory for it this frame, draw all */
};

#define CUBE_NEAR 0.05f
#define CUBE_PI 3.14159265358979323846

static const float face_forward[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                         {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
static const float face_up[6][3] = {{0, 1, 0}, {0, 1, 0}, {0, 0, -1},
                                    {0, 0, 1}, {0, 1, 0}, {0, 1, 0}};

static void cross3(const float a[3], const float b[3], float dest[3])
{
    dest[0] = a[1] * b[2] - a[2] * b[1];
    dest[1] = a[2] * b[0] - a[0] * b[2];
    dest[2] = a[0] * b[1] - a[1] * b[0];
}

/* World → face view (rows right, up, -forward; camera looks down -Z). */
static void face_view(uint32_t face, float dest[16])
{
    const float *f = face_forward[face], *u = face_up[face];
    float r[3];
    cross3(f, u, r);
    memset(dest, 0, 16 * sizeof(float));
    for (int i = 0; i < 3; i++) {
        dest[i * 4 + 0] = r[i];
        dest[i * 4 + 1] = u[i];
        dest[i * 4 + 2] = -f[i];
    }
    dest[15] = 1.0f;
}

/* An item reaches face F when its bound is not wholly outside one of the
 * four planes through the centre that bound the face (normals forward ±
 * right, forward ± up, unnormalised: the test scales the radius). Widened
 * as the paraboloid's, so no vertex can round across a plane. */
static void cube_reach(ob_cube_view *cv)
{
    ob_view *v = &cv->base;
    cv->reach_valid = ob_array_reserve((void **)&cv->reach, &cv->reach_cap, v->item_count,
                                       sizeof *cv->reach) == OB_OK;
    if (!cv->reach_valid) {
        OB_LOG_W("view", "view '%s': no memory for the per-face item masks; every item is drawn "
                 "in every face this frame", v->name);
        return;
    }
    for (uint32_t i = 0; i < v->item_count; i++) {
        double c[3];
        float radius;
        ob_view_item_sphere(v, i, c, &radius);
        double rel[3] = {c[0] - v->origin[0], c[1] - v->origin[1], c[2] - v->origin[2]};
        double dist = sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
        double reach = ((double)radius + ((double)radius + dist) * 1e-5 + 1e-6) * sqrt(2.0);
        uint8_t mask = 0;
        for (uint32_t face = 0; face < 6; face++) {
            const float *f = face_forward[face], *u = face_up[face];
            float r[3];
            cross3(f, u, r);
            double df = 0, dr = 0, du = 0;
            for (int k = 0; k < 3; k++) {
                df += rel[k] * f[k];
                dr += rel[k] * r[k];
                du += rel[k] * u[k];
            }
            bool in = df - dr >= -reach && df + dr >= -reach && df - du >= -reach && df + du >= -reach;
            if (in) mask |= (uint8_t)(1u << face);
        }
        cv->reach[i] = mask;
    }
}

static bool cube_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    if (!ob_renderer_queue_view(r, v)) return false;
    float radius;
    ob_node_world_sphere(cv->owner, v->origin, &radius);
    ob_mat4_identity(v->view_proj);
    v->cull_exclude = cv->owner;
    return true;
}

static void cube_post_cull(ob_view *v, ob_renderer *r)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    cube_reach(cv);
    ob_view_pre_render_items(v, r);
    ob_views_queue_simulations(cv->ctx, r, v);
    ob_material_library_prepare_view(cv->ctx->materials, r, v);
}

static void cube_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    (void)r;
    float view[16];
    face_view(0, view);
    ob_views_set_common_params(cv->ctx, v, params, view, cv->proj);
}

static void cube_usage_params(ob_view *v, ob_renderer *r, ob_params *params, const ob_view *consumer)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    (void)r;
    (void)consumer;
    float identity[16];
    ob_mat4_identity(identity);
    ob_params_set_texture(params, cv->env_map, v->color);
    ob_params_set_mat4(params, cv->env_matrix, identity);
    /* A face spans 90 degrees over its side: 2 / pi of it per radian at
     * the centre. */
    float info[4] = {1.0f, (float)(v->color_mips ? v->color_mips - 1 : 0),
                     (float)(2.0 / CUBE_PI) * (float)v->width, 0.0f};
    ob_params_set_vec4(params, cv->env_info, info);
}

static void cube_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                        uint32_t first, uint32_t count)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    float view[16];
    face_view(layer, view);
    const ob_param_builtins *b = ob_param_registry_builtins(ob_renderer_registry(r));
    ob_params_set_mat4(ob_pipeline_manager_params(pm), b->view, view);
    /* Runs of items this face draws are recorded together. */
    uint32_t end = first + count < v->item_count ? first + count : v->item_count;
    uint32_t run = first;
    uint8_t bit = (uint8_t)(1u << layer);
    for (uint32_t i = first; i < end && cv->reach_valid; i++) {
        if (cv->reach[i] & bit) continue;
        if (i > run) ob_view_record_items(v, r, pm, run, i - run);
        run = i + 1;
    }
    if (end > run) ob_view_record_items(v, r, pm, run, end - run);
}

static const ob_view_vtbl cube_vtbl = {
    .type_name = "cube",
    .pre_cull = cube_pre_cull,
    .post_cull = cube_post_cull,
    .set_render_params = cube_render_params,
    .set_usage_params = cube_usage_params,
    .record = cube_record,
};

ob_cube_view *ob_cube_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_cube_view *cv = ob_calloc(1, sizeof *cv);
    if (!cv) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    char name[48];
    snprintf(name, sizeof name, "cubemap:%s", ob_node_name(owner));
    ob_view_init(&cv->base, &cube_vtbl, OB_VIEW_CUBE, name);
    cv->ctx = ctx;
    cv->owner = owner;
    cv->base.no_frustum = true;
    cv->base.clear_depth = 0.0f;
    cv->base.clear_color[3] = 1.0f;   /* the first camera's each frame (queue_hook) */
    cv->base.color_mips = ob_image_mip_levels_max(ctx->env_map_size, ctx->env_map_size);
    ob_math_perspective_reverse_z((float)(CUBE_PI / 2.0), 1.0f, CUBE_NEAR, cv->proj);
    ob_param_registry *reg = ob_renderer_registry(ctx->r);
    cv->env_map = ob_param_find(reg, "EnvMap");
    cv->env_matrix = ob_param_find(reg, "EnvMapMatrix");
    cv->env_info = ob_param_find(reg, "EnvMapInfo");
    if (!cv->env_matrix.id) cv->env_matrix = ob_param_register(reg, "EnvMapMatrix", OB_PARAM_MAT4, 1, &r);
    if (r == OB_OK)
        r = ob_views_make_target(ctx, &cv->base, ctx->env_map_size, ctx->env_map_size, 6,
                                 OB_VIEWS_ENV_FORMAT, OB_VIEWS_DEPTH_FORMAT);
    if (r != OB_OK) {
        ob_free(cv);
        cv = NULL;
    }
done:
    if (out_result) *out_result = r;
    return cv;
}

void ob_cube_view_destroy(ob_views *ctx, ob_cube_view *v)
{
    if (!v) return;
    ob_free(v->reach);
    ob_views_free_view(ctx, &v->base);
}

ob_view *ob_cube_view_base(ob_cube_view *v) { return &v->base; }
