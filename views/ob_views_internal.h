/* ob_views_internal.h — shared between the files of the views layer; not
 * installed. What custom views may use is in ob_views_layer.h. */
#ifndef OB_VIEWS_INTERNAL_H
#define OB_VIEWS_INTERNAL_H

#include "ob_math.h"
#include "ob_views_layer.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

typedef struct ob_shadow_view ob_shadow_view;
typedef struct ob_paraboloid_view ob_paraboloid_view;
typedef struct ob_cube_view ob_cube_view;
typedef struct ob_local_shadows ob_local_shadows;

typedef struct ob_views_entry {
    uint32_t node_id;
    ob_view *view;
    void *owner_object;          /* the concrete view (shadow/paraboloid/cube) or particle system */
} ob_views_entry;

struct ob_views {
    ob_renderer *r;
    ob_device *dev;
    ob_material_library *materials;
    ob_effect_context *effects;
    uint32_t env_map_size, shadow_map_size;
    uint32_t shadow_cascades;    /* 1..OB_SHADOW_MAX_CASCADES */
    float shadow_distance;       /* 0: from what the camera sees */
    float shadow_split_lambda;   /* (0, 1] */
    ob_env_map_kind env_map_kind;
    float sky_color[4];          /* alpha 0: none, use the asking camera's clear colour */
    float ambient[4];
    double time, dt;
    ob_effect_counters counted;  /* effect counters already reported to the stats */

    ob_views_entry *shadows;     /* one per shadow-casting light */
    uint32_t shadow_count, shadow_cap;
    ob_views_entry *envs;        /* one per reflective entity */
    uint32_t env_count, env_cap;
    ob_views_entry *systems;     /* particle systems by emitter node */
    uint32_t system_count, system_cap;
    uint32_t *over_limit;        /* ids of lights logged as over OB_MAX_LIGHTS, ascending */
    uint32_t over_limit_count, over_limit_cap;
    bool light_tiles_off;        /* ob_views_set_light_tiles(false): every light in tile 0 */
    bool lod_off;                /* ob_views_set_lod(false): level 0 everywhere */
    float lod_error;             /* pixels, > 0 */
    ob_local_shadows *local_shadows; /* point and spot lights' shadow views, made on first need */

    ob_effect *text_effect, *composite_effect, *particle_sim_effect;
};

/* The cascades of one directional light (ob_view_shadow.c): views named
 * "shadow:<light>:c<i>", one layer each of one array depth image of the
 * context's cascade count at its shadow map size. Failure: the image's
 * error, NULL. [render thread] */
ob_shadow_view *ob_shadow_view_create(ob_views *ctx, ob_node *light, ob_result *out_result);
void ob_shadow_view_destroy(ob_views *ctx, ob_shadow_view *v);
/* "shadow:<light>": the name the set is left out under as a whole. */
const char *ob_shadow_view_name(const ob_shadow_view *v);
/* Fits the cascades to `consumer` (unless an earlier consumer of this frame
 * did) and pre-renders each, so the consumer depends on them; left out
 * (OB_SKIP_NO_CASTERS) when the consumer sees no caster. [render thread,
 * PreRender] */
void ob_shadow_view_pre_render(ob_shadow_view *v, ob_renderer *r, ob_view *consumer);

ob_paraboloid_view *ob_paraboloid_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result);
void ob_paraboloid_view_destroy(ob_views *ctx, ob_paraboloid_view *v);
ob_view *ob_paraboloid_view_base(ob_paraboloid_view *v);

/* Fill the lit shaders' PerViewLights block (LightGrid, LightTable,
 * LightTiles) for v: the scene's first OB_MAX_LIGHTS point and spot lights
 * relative to v->origin and, for a perspective view, the screen tiles each
 * may reach. Cannot fail. [recording thread: writes only params] */
void ob_views_set_light_params(ob_views *ctx, const ob_view *v, ob_params *params,
                               const float view[16], const float proj[16]);
/* Log each point or spot light over OB_MAX_LIGHTS once by name and note how
 * many are over in the frame's stats. [render thread, PreRender] */
void ob_views_report_light_limit(ob_views *ctx, ob_renderer *r);
/* What an environment map (paraboloid or cube) hands its consumers. */
typedef struct ob_env_params {
    ob_param env_map, env_matrix, env_info;
} ob_env_params;
/* The common set-up of an environment map view v of `owner`, named
 * "<prefix>:<owner>": no frustum (everything around counts), reversed-Z
 * clear, a full mip chain, HDR colour and depth of `layers` layers at the
 * context's env_map_size, and its params in *env. The clear colour is set
 * per frame (queue_hook). Failure: the registry's or the image's error, v's
 * targets empty. [render thread] */
ob_result ob_views_env_view_init(ob_views *ctx, ob_view *v, const ob_view_vtbl *vtbl,
                                 ob_view_type type, const char *prefix, const ob_node *owner,
                                 uint32_t layers, ob_env_params *env);
/* EnvMap = v's colour, EnvMapMatrix = identity (maps are in the world's
 * frame), EnvMapInfo = (kind, top mip level, texels_per_radian, 0): what
 * materials/shaders/envmap.glsl reads. [recording thread: writes params] */
void ob_views_env_usage(const ob_env_params *p, const ob_view *v, ob_params *params, float kind,
                        float texels_per_radian);
/* pre_cull of an environment map: queue v, centre it on its owner, which
 * culling leaves out. [render thread] */
bool ob_views_env_pre_cull(ob_view *v, ob_renderer *r, const ob_node *owner);
/* ob_view.lod_scale for a view of pixels_per_unit pixels per world unit at
 * distance 1: 0 with levels of detail off. */
float ob_views_lod_scale(const ob_views *ctx, float pixels_per_unit);
/* Which layers an item reaches: a bit per layer, from the item's centre
 * relative to the map's and its radius, already widened by far more than
 * the float rounding of a vertex relative to the owner. */
typedef uint8_t (*ob_env_layer_mask_fn)(const double rel[3], double radius);
/* post_cull of an environment map: the per-item layer masks into *masks
 * (grown as needed; *valid false when that fails: logged, every item drawn
 * in every layer), then what a camera does after culling (the items' views,
 * simulations, pipelines). [render thread] */
void ob_views_env_post_cull(ob_views *ctx, ob_view *v, ob_renderer *r, ob_env_layer_mask_fn mask_of,
                            uint8_t **masks, uint32_t *cap, bool *valid);
/* Records items [first, first + count) of v whose mask[i] has `bit`, in
 * runs (all of them when mask is NULL): the per-layer culling of the
 * environment maps. [recording thread] */
void ob_views_record_masked(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm, uint32_t first,
                            uint32_t count, const uint8_t *mask, uint8_t bit);

/* The cube map faces (+X, -X, +Y, -Y, +Z, -Z; envmap.glsl's ob_cube_face
 * and shadow_local.glsl agree): face's world → face view rotation, and the
 * faces an item reaches (an ob_env_layer_mask_fn). [any thread] */
void ob_views_cube_face_view(uint32_t face, float dest[16]);
uint8_t ob_views_cube_faces(const double rel[3], double radius);

ob_cube_view *ob_cube_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result);
void ob_cube_view_destroy(ob_views *ctx, ob_cube_view *v);
ob_view *ob_cube_view_base(ob_cube_view *v);

/* Point and spot lights' shadows (ob_view_local_shadow.c). queue: for each
 * shadow-casting local light that reaches an item `consumer` sees, its
 * shadow view (made on first need) gets layers of the shared array and
 * pre-renders; others are noted skipped. [render thread, PreRender] */
void ob_views_queue_local_shadows(ob_views *ctx, ob_renderer *r, ob_view *consumer);
/* The first shadow layer of `light` as v samples it (-1: v has no map of
 * it this frame) and that light's layer matrices into mats (camera-relative
 * world of v → the layer's clip space). [recording thread: reads views] */
float ob_views_local_shadow_layer(const ob_views *ctx, const ob_view *v, const ob_node *light,
                                  float mats[OB_MAX_LOCAL_SHADOW_LAYERS][16]);
/* LocalShadowMatrices = mats, when a shader uses them. [recording thread] */
void ob_views_set_local_shadow_matrices(const ob_views *ctx, ob_params *params,
                                        const float mats[OB_MAX_LOCAL_SHADOW_LAYERS][16]);
void ob_views_local_shadows_destroy(ob_views *ctx);
/* Whether a spot light at the origin shining along unit `axis`, with
 * cos(outer angle) and range (0: none), may reach the sphere (rel, radius):
 * exact for the cone bounded by its range sphere, conservative never
 * false for a sphere it lights. [any thread] */
bool ob_views_spot_reaches(const float axis[3], float cos_outer, float range, const double rel[3],
                           double radius);

/* Particle systems by emitter node: the perspective view queues the
 * simulation of every emitter it sees (ob_views_queue_simulations). */
ob_result ob_views_add_system(ob_views *ctx, ob_node *emitter, ob_view *sim, ob_particle_system *ps);
void ob_views_remove_system(ob_views *ctx, ob_particle_system *ps);

/* Simulation view of a particle system (ob_view_simulation.c). */
ob_view *ob_particle_system_sim_view(ob_particle_system *ps);

/* v's targets again at width x height (same formats, layers, samples); the
 * old images are destroyed deferred. On failure v keeps its targets, logged. */
ob_result ob_views_resize_target(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height);
/* Applies v's pending ob_view_resize, if any; true when the size changed.
 * Views call it at the start of their PreRender. */
bool ob_views_apply_resize(ob_views *ctx, ob_view *v);
/* The sample count to use for `wanted` (1, 2, 4, 8...): the largest the
 * device offers for both formats up to wanted; a lower count is logged as
 * a warning naming the view. */
uint32_t ob_views_supported_samples(ob_views *ctx, const char *view_name, uint32_t wanted,
                                    VkFormat color, VkFormat depth);

/* Frees a view made by this layer: its targets, its draw list and the
 * object itself (whose first member is the base). NULL ok. */
void ob_views_free_view(ob_views *ctx, ob_view *base);

#pragma GCC visibility pop

#endif /* OB_VIEWS_INTERNAL_H */
