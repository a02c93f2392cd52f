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

    ob_effect *text_effect, *composite_effect, *particle_sim_effect;
};

ob_shadow_view *ob_shadow_view_create(ob_views *ctx, ob_node *light, ob_result *out_result);
void ob_shadow_view_destroy(ob_views *ctx, ob_shadow_view *v);
ob_view *ob_shadow_view_base(ob_shadow_view *v);
/* Set the consumer whose visible casters the next pre_render fits. */
void ob_shadow_view_set_consumer(ob_shadow_view *v, ob_view *consumer);

ob_paraboloid_view *ob_paraboloid_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result);
void ob_paraboloid_view_destroy(ob_views *ctx, ob_paraboloid_view *v);
ob_view *ob_paraboloid_view_base(ob_paraboloid_view *v);

ob_cube_view *ob_cube_view_create(ob_views *ctx, ob_node *owner, ob_result *out_result);
void ob_cube_view_destroy(ob_views *ctx, ob_cube_view *v);
ob_view *ob_cube_view_base(ob_cube_view *v);

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
