/* ob_views.h — the concrete render views and the glue that installs them.
 *
 * View types (engine/ob_view.h is the interface):
 *   perspective  a camera's colour + depth; queues the shadow views of the
 *                lights that cast shadows onto what it sees
 *   shadow       a directional light's depth, fitted to the casters the
 *                consumer sees; left out with no caster or zero intensity
 *   paraboloid   dual-paraboloid environment map of one reflective entity
 *                (two layers; the owner is excluded); queued by the material
 *                of a reflective entity visible to the queuing view
 *   simulation   compute only: a particle system in a storage buffer that the
 *                perspective view then draws
 *   overlay      text (stb_easy_font) drawn last over the final target
 *   composite    full-screen copy of a view's colour into the final target
 *
 * ob_views is the context that owns per-entity and per-light views (created
 * on first need, reused every frame), fills the renderer's material and
 * geometry interfaces, and answers the materials' "queue the view I need".
 *
 * Lifecycle: ob_views_create (after the renderer and material library) →
 * views → ob_views_destroy (after ob_renderer_wait_idle).
 * Thread rule: [render thread] for everything here; the views' record and
 * set_*_params callbacks run on workers and only read view state.
 *
 * Writing a view of one's own: ob_views_layer.h (not included here) has what
 * the standard views use — queueing shadows and simulations, targets, the
 * PerView parameters — and docs/extending.md §5 says how.
 */
#ifndef OB_VIEWS_H
#define OB_VIEWS_H

#include "ob_effect.h"
#include "ob_geometry.h"
#include "ob_material.h"
#include "ob_renderer.h"

typedef struct ob_views ob_views;

typedef struct ob_views_desc {
    ob_renderer *renderer;
    ob_material_library *materials;
    ob_effect_context *effects;
    uint32_t env_map_size;       /* 0 → 256 (per paraboloid half) */
    uint32_t shadow_map_size;    /* 0 → 1024 */
    float ambient[4];            /* rgb, w = intensity; zero → (1,1,1,0.15) */
} ob_views_desc;

ob_views *ob_views_create(const ob_views_desc *desc, ob_result *out_result);
void ob_views_destroy(ob_views *ctx);
ob_renderer *ob_views_renderer(ob_views *ctx);
/* Simulation time: every view reads it, so ST and MT agree. */
void ob_views_set_time(ob_views *ctx, double time, double dt);
/* Quality settings (take effect for views created afterwards). */
void ob_views_set_env_map_size(ob_views *ctx, uint32_t size);
void ob_views_set_shadow_map_size(ob_views *ctx, uint32_t size);

/* ---------------------------------------------------------- perspective */

typedef struct ob_perspective_view ob_perspective_view;
typedef struct ob_perspective_desc {
    const char *name;
    ob_node *camera;             /* a node with a camera component */
    uint32_t width, height;
    VkFormat color_format;       /* 0 → R8G8B8A8_UNORM */
    float clear_color[4];
} ob_perspective_desc;

ob_perspective_view *ob_perspective_view_create(ob_views *ctx, const ob_perspective_desc *desc,
                                                ob_result *out_result);
void ob_perspective_view_destroy(ob_views *ctx, ob_perspective_view *v);
ob_view *ob_perspective_view_base(ob_perspective_view *v);
ob_image ob_perspective_view_color(const ob_perspective_view *v);

/* --------------------------------------------------------------- overlay */

typedef struct ob_overlay_view ob_overlay_view;
/* Draws text over `target` (loaded, not cleared) after `source` has run. */
ob_overlay_view *ob_overlay_view_create(ob_views *ctx, ob_view *source, ob_result *out_result);
void ob_overlay_view_destroy(ob_views *ctx, ob_overlay_view *v);
/* Replaces the text (newlines allowed); at most 4 KiB is kept. */
void ob_overlay_view_set_text(ob_overlay_view *v, const char *text);
ob_view *ob_overlay_view_base(ob_overlay_view *v);

/* ------------------------------------------------------------- composite */

typedef struct ob_composite_view ob_composite_view;
/* Copies `source`'s colour into a final target of the same size. */
ob_composite_view *ob_composite_view_create(ob_views *ctx, ob_view *source, ob_result *out_result);
void ob_composite_view_destroy(ob_views *ctx, ob_composite_view *v);
ob_view *ob_composite_view_base(ob_composite_view *v);
/* The final target. Its handle changes when a presenting composite follows
 * a resized window: ask again after each frame. */
ob_image ob_composite_view_target(const ob_composite_view *v);
/* Presenting (off by default): every frame the view runs in, its target is
 * what the renderer presents (ob_renderer_present_image), and when the
 * frame's swapchain image has another size, the target — and the source's,
 * when the source had the same size — are made again at the window's size
 * before the source's PreRender. A failed resize is logged and the old size
 * is scaled to the window. Without an attached surface this changes
 * nothing. [render thread, between frames] */
void ob_composite_view_set_presenting(ob_composite_view *v, bool presenting);

/* -------------------------------------------------------- particle system */

typedef struct ob_particle_system ob_particle_system;
typedef struct ob_particle_desc {
    const char *name;
    uint32_t count;              /* particles; 0 → 4096 */
    uint32_t seed;
    float lifetime;              /* 0 → 3 s */
    float speed;                 /* 0 → 2 */
    float size;                  /* 0 → 0.05 */
    float gravity[3];
    float color[4];              /* zero → warm white */
} ob_particle_desc;
/* Makes the simulation view and a renderable emitter entity as a child of
 * `parent` (the perspective view draws it; its material queues the simulation). */
ob_particle_system *ob_particle_system_create(ob_views *ctx, ob_scene *scene, ob_node *parent,
                                              const ob_particle_desc *desc, ob_result *out_result);
void ob_particle_system_destroy(ob_views *ctx, ob_particle_system *ps);
ob_node *ob_particle_system_node(ob_particle_system *ps);

/* Start a frame's PreRender of a root view (the final view, or another
 * camera view the program renders: each root view queued first is executed
 * last), which pre-renders what it needs, and report the pipelines and
 * shader variants this created to the frame's stats. [render thread, between
 * begin_frame and end_frame] */
void ob_views_render(ob_views *ctx, ob_view *final_view);

/* Standard vertex layout of geometry, as an effect's vertex input: a
 * constant the library owns, made on first use. [any thread] */
const ob_effect_vertex_input *ob_views_standard_input(void);

#endif /* OB_VIEWS_H */
