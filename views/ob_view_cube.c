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
    ob_env_params env;
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

void ob_views_cube_face_view(uint32_t face, float dest[16])
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
 * right, forward ± up, of length sqrt 2: the radius is scaled by it). */
uint8_t ob_views_cube_faces(const double rel[3], double radius)
{
    uint8_t mask = 0;
    double reach = radius * 1.4142135623730951;
    for (uint32_t face = 0; face < 6; face++) {
        const float *f = face_forward[face], *u = face_up[face];
        float rt[3];
        cross3(f, u, rt);
        double df = 0, dr = 0, du = 0;
        for (int k = 0; k < 3; k++) {
            df += rel[k] * f[k];
            dr += rel[k] * rt[k];
            du += rel[k] * u[k];
        }
        if (df - dr >= -reach && df + dr >= -reach && df - du >= -reach && df + du >= -reach)
            mask |= (uint8_t)(1u << face);
    }
    return mask;
}

static bool cube_pre_cull(ob_view *v, ob_renderer *r)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    /* A 90-degree face has half its side in pixels per world unit at
     * distance 1 at its centre, and twice that at its edges: the edges'. */
    v->lod_scale = ob_views_lod_scale(cv->ctx, (float)v->width);
    return ob_views_env_pre_cull(v, r, cv->owner);
}

static void cube_post_cull(ob_view *v, ob_renderer *r)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    ob_views_env_post_cull(cv->ctx, v, r, ob_views_cube_faces, &cv->reach, &cv->reach_cap, &cv->reach_valid);
}

static void cube_render_params(ob_view *v, ob_renderer *r, ob_params *params)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    (void)r;
    float view[16];
    ob_views_cube_face_view(0, view);
    ob_views_set_common_params(cv->ctx, v, params, view, cv->proj);
}

static void cube_usage_params(ob_view *v, ob_renderer *r, ob_params *params, const ob_view *consumer)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    (void)r;
    (void)consumer;
    /* A face spans 90 degrees over its side: 2 / pi of it per radian at
     * the centre. */
    ob_views_env_usage(&cv->env, v, params, 1.0f, (float)(2.0 / CUBE_PI) * (float)v->width);
}

static void cube_record(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t layer,
                        uint32_t first, uint32_t count)
{
    ob_cube_view *cv = (ob_cube_view *)v;
    float view[16];
    ob_views_cube_face_view(layer, view);
    const ob_param_builtins *b = ob_param_registry_builtins(ob_renderer_registry(r));
    ob_params_set_mat4(ob_pipeline_manager_params(pm), b->view, view);
    ob_views_record_masked(v, r, pm, first, count, cv->reach_valid ? cv->reach : NULL,
                           (uint8_t)(1u << layer));
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
    cv->ctx = ctx;
    cv->owner = owner;
    ob_math_perspective_reverse_z((float)(CUBE_PI / 2.0), 1.0f, CUBE_NEAR, cv->proj);
    r = ob_views_env_view_init(ctx, &cv->base, &cube_vtbl, OB_VIEW_CUBE, "cubemap", owner, 6, &cv->env);
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
