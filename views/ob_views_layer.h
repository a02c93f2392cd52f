/* ob_views_layer.h — the views layer's extension API: what a custom view
 * (docs/extending.md §5) uses to behave like the standard ones. Not included
 * by ob_views.h nor by obelisk/obelisk.h: #include <obelisk/ob_views_layer.h>
 * explicitly. It brings the renderer's extension API (ob_renderer_layer.h).
 *
 * Thread rule: [render thread] unless a function says otherwise. The
 * PreRender functions run inside a view's pre_render (started through
 * ob_renderer_pre_render); set_common_params runs on a recording thread from
 * a view's set_render_params.
 */
#ifndef OB_VIEWS_LAYER_H
#define OB_VIEWS_LAYER_H

#include "ob_renderer_layer.h"
#include "ob_views.h"

/* The standard views' target formats. */
#define OB_VIEWS_DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
/* 8-bit linear colour targets of views that need no range above 1. */
#define OB_VIEWS_COLOR_FORMAT VK_FORMAT_R8G8B8A8_UNORM
/* Environment maps (paraboloid and cube): linear HDR like the camera views,
 * so a lit value or a bright emitter above 1 is reflected as such (a
 * reflection of the sun is not clipped to white before the tone map). */
#define OB_VIEWS_ENV_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
/* Camera views render linear HDR colour; the composite tone maps it into an
 * sRGB target (what is read back, written as PNG and presented). */
#define OB_VIEWS_HDR_FORMAT VK_FORMAT_R16G16B16A16_SFLOAT
#define OB_VIEWS_OUTPUT_FORMAT VK_FORMAT_R8G8B8A8_SRGB

/* ---- PreRender ----------------------------------------------------------- */

/* Pre-render the shadow cascades of the shaded directional light when it
 * casts shadows (made on first need, owned by ctx), fitted to `consumer`'s
 * camera and the casters it sees: call it after ob_view_cull of the
 * consumer. The consumer then depends on them and samples the maps through
 * their set_usage_params (ShadowMap, ShadowMatrices, ShadowSplits,
 * ShadowCascades, ShadowAxis). A light of zero intensity is left out
 * (OB_SKIP_NOT_NEEDED); a shadow view that cannot be made is logged and left
 * out (OB_SKIP_ERROR) and the rest goes on. [render thread, PreRender] */
void ob_views_queue_shadows(ob_views *ctx, ob_renderer *r, ob_view *consumer);
/* Pre-render the simulation of every particle system whose emitter is among
 * `consumer`'s culled items (after ob_view_cull), so it runs before the
 * consumer draws the particles. [render thread, PreRender] */
void ob_views_queue_simulations(ob_views *ctx, ob_renderer *r, ob_view *consumer);

/* ---- targets ------------------------------------------------------------- */

/* Make v's targets: a colour image of format `color` (colour target, sampled,
 * transfer source and destination; with v->color_mips > 1 that many levels,
 * at most a full chain, one where the format does not blit linearly (logged),
 * v->color_mips then set to what was made) and a depth image of format `depth`
 * (depth target, sampled, transfer destination), width x height with
 * `layers` layers, named "<view>.color" / "<view>.depth"; either format may
 * be VK_FORMAT_UNDEFINED (none). With v->samples > 1 and one layer, also
 * the multisampled colour and depth (v->msaa_color, msaa_depth; the depth is
 * then only multisampled). Sets v->color, depth, width, height and
 * layer_count. Failure: the image's error, v's targets left empty (the colour
 * image made first is destroyed again), logged by the resources. [render
 * thread] */
ob_result ob_views_make_target(ob_views *ctx, ob_view *v, uint32_t width, uint32_t height,
                               uint32_t layers, VkFormat color, VkFormat depth);
/* Destroy v's targets (deferred until the frames using them are done) and
 * zero v->color and v->depth. Empty targets are fine. [render thread] */
void ob_views_release_target(ob_views *ctx, ob_view *v);
/* Formats of v's targets (VK_FORMAT_UNDEFINED where absent). [any thread,
 * while no resource is created or destroyed] */
void ob_views_target_formats(ob_views *ctx, const ob_view *v, VkFormat *out_color,
                             VkFormat *out_depth);

/* Make e's pipeline for v's target formats now, in PreRender, where a
 * failure can reach the frame: when e is NULL or the pipeline cannot be
 * made, v's name goes into the frame's errors (ob_renderer_note_error:
 * OB_ERR_NOT_FOUND for no effect, OB_ERR_VULKAN for the pipeline, whose
 * cause the effect logs) and false is returned; v's draws are then skipped
 * while recording. [render thread, PreRender] */
bool ob_views_prepare_effect(ob_views *ctx, ob_renderer *r, ob_effect *e, ob_view *v);

/* ---- recording ----------------------------------------------------------- */

/* Bind e's pipeline for v's target formats on pm. false (nothing bound) when
 * e is NULL or its pipeline for those formats cannot be made. [recording
 * thread] */
bool ob_views_bind_effect(ob_views *ctx, ob_effect *e, const ob_view *v, ob_pipeline_manager *pm);
/* Write the PerView block every camera-like view sets into `params`: View and
 * Projection, ScreenSize from v's size, the ambient colour given to
 * ob_views_create, the scene's first directional light relative to
 * v->origin, the PerViewLights block (up to OB_MAX_LIGHTS point and spot
 * lights and, for a perspective view, the screen tiles each may reach:
 * docs/architecture.md, "Many lights"), and defaults for the shadow
 * cascades' parameters (identity matrices, no cascade) and
 * ParaboloidDirection (zero) that dependencies override. Call it from
 * set_render_params with the slot given. Cannot fail. [recording thread:
 * writes only `params`] */
void ob_views_set_common_params(ob_views *ctx, const ob_view *v, ob_params *params,
                                const float view[16], const float proj[16]);

#endif /* OB_VIEWS_LAYER_H */
