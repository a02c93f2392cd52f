/* ob_renderer_layer.h — the renderer's extension API: what the layers above
 * the engine (views, materials, geometry) and people writing a custom view or
 * material call. A program that only uses the standard views, materials and
 * ob_stack never needs it, and neither ob_renderer.h nor obelisk/obelisk.h
 * includes it: #include <obelisk/ob_renderer_layer.h> explicitly
 * (docs/extending.md says when).
 *
 * Contents:
 *   - the interfaces the engine calls up through (ob_material_iface,
 *     ob_geometry_iface), installed by ob_views_create;
 *   - PreRender: queueing a view, starting another view's PreRender, the
 *     current view and nesting depth, views attached to an entity;
 *   - what a view or the views layer reports into the frame's stats;
 *   - the present image of a frame (a presenting composite view).
 *
 * Thread rule: [render thread] unless a function says otherwise; the PreRender
 * functions only between ob_renderer_begin_frame and the frame's
 * process_views/end_frame (outside a frame they do nothing or return
 * false/NULL, as each says).
 */
#ifndef OB_RENDERER_LAYER_H
#define OB_RENDERER_LAYER_H

#include "ob_renderer.h"

/* ---- interfaces into materials and geometry ----------------------------- */

/* What a material's apply did. */
typedef enum ob_apply_result {
    OB_APPLY_SKIP = 0,      /* not drawn in this view */
    OB_APPLY_ENTITY = 1,    /* applied, for this entity only: apply again for the next */
    OB_APPLY_MATERIAL = 2,  /* applied, and the same for every entity with this
                             * material in this view: the next one of those may
                             * be drawn without applying again */
} ob_apply_result;

struct ob_material_iface {
    /* Render flag for the view type (Hieroglyph's Params[type].bRender). [any thread] */
    bool (*renders)(const struct ob_material *m, ob_view_type type);
    /* Sort class: 0 opaque, 1 blended; priority orders within a class;
     * state groups draws that bind the same pipeline and parameters (a
     * dense id: its low 16 bits go into the sort key). [any thread] */
    void (*sort_info)(const struct ob_material *m, ob_view_type type,
                      uint32_t *out_class, uint32_t *out_priority, uint32_t *out_state);
    /* An entity with this material is visible to view v: queue what it needs
     * (env maps, ...), and make the pipeline for v's targets exist.
     * [render thread, PreRender] */
    void (*pre_render)(struct ob_material *m, ob_node *entity, ob_renderer *r, ob_view *v);
    /* Optional. Whether pre_render of m in a view of this type depends on
     * the entity (it queues something per entity, like an env map). When
     * false, a view calls pre_render once per material, for the first of
     * its items with it in draw order, instead of once per item. NULL: per
     * item. [any thread] */
    bool (*pre_render_per_entity)(const struct ob_material *m, ob_view_type type);
    /* Set the pipeline and the material's parameters for v. Views draw the
     * entities of a state group one after another and apply once per run of
     * the same material when it answers OB_APPLY_MATERIAL. [recording thread:
     * writes only pm's slot] */
    ob_apply_result (*apply)(struct ob_material *m, ob_node *entity, ob_renderer *r,
                             ob_pipeline_manager *pm, const ob_view *v);
};

/* Levels of detail a geometry may have, level 0 included. */
#define OB_LOD_MAX 8u

struct ob_geometry_iface {
    /* What drawing level `lod` of g takes (buffers, counts, ranges), by
     * value: the view's loop asks once per run of items of one geometry and
     * level and draws from it itself (ob_pipeline_manager_draw_data). lod is
     * below what `lods` gives (0 without it). [any thread] */
    void (*draw_data)(const struct ob_geometry *g, uint32_t lod, ob_draw_data *out);
    /* Stable id for sorting and hashing. [any thread] */
    uint32_t (*id)(const struct ob_geometry *g);
    /* Optional (NULL: every geometry has level 0 only). g's levels of
     * detail, 1..OB_LOD_MAX, and in rel_error[l] level l's error over the
     * radius of g's bound (rel_error[0] = 0; non-decreasing). Culling asks
     * once per geometry and wave, and draws an item at the coarsest level
     * whose error projects to within the view's tolerance
     * (ob_view.lod_scale). [any thread] */
    uint32_t (*lods)(const struct ob_geometry *g, float rel_error[OB_LOD_MAX]);
};

/* Install the interface the renderer calls for every renderable's material
 * (geometry). The renderer keeps a copy; NULL uninstalls (nothing is drawn
 * then: ob_view_cull fails with OB_ERR_WRONG_STATE). ob_views_create installs
 * the library's; a program that wraps it (docs/extending.md §4.2) installs
 * its copy afterwards. Cannot fail.
 * [render thread, between frames] */
void ob_renderer_set_material_iface(ob_renderer *r, const ob_material_iface *iface);
void ob_renderer_set_geometry_iface(ob_renderer *r, const ob_geometry_iface *iface);
/* The installed copy, NULL when none. Valid until the next set_*_iface.
 * [any thread, while no set_*_iface runs] */
const ob_material_iface *ob_renderer_get_material_iface(const ob_renderer *r);
const ob_geometry_iface *ob_renderer_get_geometry_iface(const ob_renderer *r);

/* ---- PreRender ----------------------------------------------------------- */

/* Queue v for this frame. Returns false when v is already queued (the
 * consumer then depends on the earlier queueing; nothing is recorded in the
 * stats), when the PreRender chain is deeper than max_recursion
 * (OB_SKIP_RECURSION in the stats), or when v has more inputs than
 * OB_VIEW_MAX_INPUTS or the frame more views than OB_MAX_FRAME_VIEWS
 * (OB_SKIP_ERROR, logged). A view's pre_render calls it first and returns
 * when it is false. The view running its pre_render (if any) becomes a
 * consumer of v: v is recorded before it. [render thread, PreRender] */
bool ob_renderer_queue_view(ob_renderer *r, ob_view *v);
/* Run v's pre_render with v as the current view (so views it queues become
 * its dependencies and the recursion depth is known). Everyone starts a
 * view's PreRender through this, never by calling pre_render directly; a
 * program's root views start through ob_views_render. No-op outside a frame
 * or for NULL; nested deeper than OB_MAX_VIEW_STACK it records
 * OB_SKIP_RECURSION and does not run v. [render thread, PreRender] */
void ob_renderer_pre_render(ob_renderer *r, ob_view *v);
/* ob_renderer_pre_render of several root views as one PreRender: the
 * views that split theirs (ob_view_vtbl.pre_cull) are culled together, in
 * waves on the worker pool, and finished in the order they were queued.
 * Views queued during a view's post_cull are culled in the next wave. A
 * frame's result (queue, order, draw lists, hashes) is the same in every
 * threading mode. Inside a running PreRender the views simply join it.
 * [render thread, PreRender] */
void ob_renderer_pre_render_many(ob_renderer *r, ob_view *const *roots, uint32_t count);
/* The renderer's worker pool as a parallel loop (ob_parallel, ob_core.h),
 * for PreRender work split over chunks: as many threads as the frame's
 * threading mode gives (1 single-threaded: the loop runs on the caller).
 * The loop's functions must not call the renderer; a loop started inside
 * one runs on its caller. The CPU time spent in it counts as parallel in
 * the frame's stats. [render thread] */
ob_parallel ob_renderer_parallel(ob_renderer *r);
/* Nesting of the running pre_render: 0 for a root view, 1 for a view it
 * started, ... (0 outside PreRender). [render thread] */
uint32_t ob_renderer_recursion_depth(const ob_renderer *r);
/* The view whose pre_render is running (NULL outside PreRender). [render thread] */
ob_view *ob_renderer_current_view(const ob_renderer *r);

/* Views attached to an entity for this frame (its environment map): set by
 * the views layer during PreRender, read by materials while recording.
 * Attachments are cleared at begin_frame. attach replaces an attachment of
 * the same view type; it fails only with OB_ERR_OUT_OF_MEMORY (nothing
 * attached). [attach: render thread, PreRender; get: any thread, while no
 * attach runs] */
ob_result ob_renderer_attach_view(ob_renderer *r, const ob_node *entity, ob_view *v);
/* NULL when none of that type is attached. */
ob_view *ob_renderer_attached_view(const ob_renderer *r, const ob_node *entity, ob_view_type type);

/* ---- reporting into the frame's stats ------------------------------------ */

/* A view left out this frame, and why (once per name and reason; beyond
 * OB_MAX_FRAME_VIEWS entries the rest are dropped). OB_SKIP_ERROR counts in
 * the frame's errors; prefer ob_renderer_note_error, which keeps the result
 * too. [render thread] */
void ob_renderer_note_skipped(ob_renderer *r, const char *name, ob_skip_reason reason);
/* Something named `name` (a view, an entity, a material) failed with
 * `error` and the frame goes on without it: listed in the frame's skipped[]
 * with OB_SKIP_ERROR (once per name), counted in ob_frame_stats.errors, and
 * the frame's first_error when it is the first. The caller logs the cause.
 * No-op for OB_OK or outside a frame. [render thread] */
void ob_renderer_note_error(ob_renderer *r, const char *name, ob_result error);
/* Pipelines and shader variants the higher layers created this frame
 * (added to the frame's stats). [render thread] */
void ob_renderer_note_created(ob_renderer *r, uint32_t pipelines, uint32_t variants);
/* Point and spot lights left out this frame for being over OB_MAX_LIGHTS
 * (ob_frame_stats.lights_over_limit is set to the largest count noted in the
 * frame, so every camera view may note the same scene). [render thread] */
void ob_renderer_note_lights_over_limit(ob_renderer *r, uint32_t count);

/* ---- the present image --------------------------------------------------- */

/* This frame presents `image` (a colour image with OB_IMAGE_TRANSFER_SRC
 * usage): at the end of the primary it is blitted, scaled to the window if
 * sizes differ, into the acquired swapchain image. A presenting composite
 * view calls it from its pre_render. No-op when headless or outside a frame;
 * a frame with a swapchain image and nothing to present shows black (and
 * logs a warning once). An image that is stale or lacks
 * OB_IMAGE_TRANSFER_SRC is refused here, where the frame can report it:
 * logged, the frame's error (OB_ERR_INVALID_ARGUMENT, named "present"),
 * and the window shows black. [render thread, PreRender] */
void ob_renderer_present_image(ob_renderer *r, ob_image image);
/* The size of this frame's swapchain image; false (and 0x0) when headless,
 * outside a frame, or when this frame is not presented (minimised). Views
 * that follow the window size read it during PreRender. [render thread] */
bool ob_renderer_present_extent(const ob_renderer *r, uint32_t *out_width, uint32_t *out_height);

#endif /* OB_RENDERER_LAYER_H */
