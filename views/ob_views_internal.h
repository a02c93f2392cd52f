/* ob_views_internal.h — shared between the files of the views layer. */
#ifndef OB_VIEWS_INTERNAL_H
#define OB_VIEWS_INTERNAL_H

#include "ob_math.h"
#include "ob_views.h"

typedef struct ob_shadow_view ob_shadow_view;
typedef struct ob_paraboloid_view ob_paraboloid_view;

typedef struct ob_views_entry {
    uint32_t node_id;
    ob_view *view;
    void *owner_object;          /* the concrete view (shadow/paraboloid) or particle system */
} ob_views_entry;

struct ob_views {
    ob_renderer *r;
    ob_device *dev;
    ob_material_library *materials;
    ob_effect_context *effects;
    uint32_t env_map_size, shadow_map_size;
    float ambient[4];
    double time, dt;
    ob_effect_counters counted;  /* effect counters already reported to the stats */

    ob_views_entry *shadows;     /* one per shadow-casting light */
    uint32_t shadow_count, shadow_cap;
    ob_views_entry *envs;        /* one per reflective entity */
    uint32_t env_count, env_cap;
    ob_views_entry *systems;     /* particle systems by emitter node */
    uint32_t system_count, system_cap;

    ob_effect *text_effect, *composite_effect, *particle_sim_effect;
};

/* Parameters every camera-like view sets: projection, lights relative to the
 * view's origin, ambient, screen size. */
void ob_views_set_common_params(ob_views *ctx, const ob_view *v, ob_params *params,
                                const float view[16], const float proj[16]);

/* Shadow views of the lights that cast shadows on what `consumer` sees. */
void ob_views_queue_shadows(ob_views *ctx, ob_renderer *r, ob_view *consumer);

ob_shadow_view *ob_shadow_view_create(ob_views *ctx, ob_node *light, ob_result *out_result);
void ob_shadow_view_destroy(ob_views *ctx, ob_shadow_view *v);
ob_view *ob_shadow_view_base(ob_shadow_view *v);
/* Set the consumer whose visible casters the next pre_render fits. */
void ob_shadow_view_set_consumer(ob_shadow_view *v, ob_view *consumer);

ob_paraboloid_view *ob_paraboloid_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result);
void ob_paraboloid_view_destroy(ob_views *ctx, ob_paraboloid_view *v);
ob_view *ob_paraboloid_view_base(ob_paraboloid_view *v);

/* Particle systems by emitter node: the perspective view queues the
 * simulation of every emitter it sees. */
ob_result ob_views_add_system(ob_views *ctx, ob_node *emitter, ob_view *sim, ob_particle_system *ps);
void ob_views_remove_system(ob_views *ctx, ob_particle_system *ps);
void ob_views_queue_simulations(ob_views *ctx, ob_renderer *r, ob_view *consumer);

/* Simulation view of a particle system (ob_view_simulation.c). */
ob_view *ob_particle_system_sim_view(ob_particle_system *ps);

/* Images for a view's targets (colour, depth; with v->samples > 1 and one
 * layer also the multisampled colour and depth, the depth then only
 * multisampled). On failure nothing is made and v is unchanged. */
ob_result ob_views_make_target(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height,
                               uint32_t layers, VkFormat color, VkFormat depth);
void ob_views_release_target(ob_views *ctx, ob_view *v);
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

/* Formats of a view's targets (VK_FORMAT_UNDEFINED when absent). */
void ob_views_target_formats(ob_views *ctx, const ob_view *v, VkFormat *color, VkFormat *depth);
/* Bind an effect's pipeline for v's targets on pm; false if unavailable. */
bool ob_views_bind_effect(ob_views *ctx, ob_effect *e, const ob_view *v, ob_pipeline_manager *pm);

#define OB_VIEWS_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
/* Environment maps: they only feed shading (sampled by reflective
 * materials), so 8-bit linear is kept there; lit values above 1 clip. */
#define OB_VIEWS_COLOR_FORMAT VK_FORMAT_R8G8B8A8_UNORM
/* Camera views render linear HDR colour; the composite tone maps it into an
 * sRGB target (what is read back, written as PNG and presented). */
#define OB_VIEWS_HDR_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define OB_VIEWS_OUTPUT_FORMAT VK_FORMAT_R8G8B8A8_SRGB

#endif /* OB_VIEWS_INTERNAL_H */
