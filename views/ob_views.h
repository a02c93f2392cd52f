/* ob_views.h — the concrete render views and the glue that installs them.
 *
 * View types (engine/ob_view.h is the interface):
 *   perspective  a camera's linear HDR colour + depth (optionally
 *                multisampled and resolved); queues the shadow views of the
 *                lights that cast shadows onto what it sees
 *   shadow       a directional light's cascaded shadow maps: one view per
 *                cascade ("shadow:<light>:c<i>"), each fitted to a slice of
 *                the consumer camera's frustum, all in the layers of one
 *                array depth image; left out with no caster in view or
 *                zero intensity
 *   paraboloid   dual-paraboloid environment map of one reflective entity
 *                (two layers; the owner is excluded); queued by the material
 *                of a reflective entity visible to the queuing view
 *   cube         the same as a cube map (six 90-degree faces in six layers),
 *                when the context's env map kind is OB_ENV_MAP_CUBE
 *                Both are linear HDR with a mip chain sampled by roughness,
 *                cleared to the clear colour of the first camera view that
 *                queues them in the frame.
 *   simulation   compute only: a particle system in a storage buffer that the
 *                perspective view then draws
 *   overlay      text (stb_easy_font) drawn last over the final target
 *   composite    full-screen pass tone mapping a view's colour into the
 *                final target (sRGB); its size follows its source's
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

/* How a reflective entity's environment map is made (docs/materials.md has
 * the trade-off; obelisk-bench's quality section measures it). */
typedef enum ob_env_map_kind {
    OB_ENV_MAP_PARABOLOID = 0,   /* default: two renders per map, but a polygon's
                                    straight edges are bent (subdivide large ones) */
    OB_ENV_MAP_CUBE,             /* six renders per map, straight edges exact */
    OB_ENV_MAP_KIND_COUNT
} ob_env_map_kind;

typedef struct ob_views_desc {
    ob_renderer *renderer;
    ob_material_library *materials;
    ob_effect_context *effects;
    uint32_t env_map_size;       /* 0 → 256 (side of a paraboloid half or cube face) */
    ob_env_map_kind env_map_kind;  /* 0 → OB_ENV_MAP_PARABOLOID */
    float sky_color[4];          /* linear rgb what env maps clear to, alpha > 0 to
                                    use it; alpha 0 → the clear colour of the first
                                    camera view that asks for the map in the frame
                                    (ob_stack passes its main view's clear colour) */
    uint32_t shadow_map_size;    /* 0 → 1024 (side of each cascade) */
    uint32_t shadow_cascades;    /* 0 → OB_SHADOW_DEFAULT_CASCADES; 1..OB_SHADOW_MAX_CASCADES */
    float shadow_distance;       /* how far from the camera shadows reach; 0 → the farthest
                                    point the camera sees, rounded up to a power of two */
    float shadow_split_lambda;   /* 0 → OB_SHADOW_DEFAULT_SPLIT_LAMBDA; (0, 1]: the share of
                                    logarithmic splits against uniform ones */
    float ambient[4];            /* rgb, w = intensity; zero → (1,1,1,0.15) */
    float lod_error;             /* pixels a level of detail may be off by; 0 → 1 */
} ob_views_desc;

/* Cascaded shadow maps of the shaded directional light (docs/architecture.md,
 * "Shadows"): at most this many cascades per light and camera. */
#define OB_SHADOW_MAX_CASCADES 4
#define OB_SHADOW_DEFAULT_CASCADES 4
#define OB_SHADOW_DEFAULT_SPLIT_LAMBDA 0.75f

ob_views *ob_views_create(const ob_views_desc *desc, ob_result *out_result);
void ob_views_destroy(ob_views *ctx);
ob_renderer *ob_views_renderer(ob_views *ctx);
/* Simulation time: every view reads it, so ST and MT agree. */
void ob_views_set_time(ob_views *ctx, double time, double dt);
/* Quality settings (take effect for views created afterwards; 0 → the
 * default). A size over the device's maxImageDimension2D is refused
 * (OB_ERR_OUT_OF_RANGE, logged; the size stays): the maps could never be
 * made. ob_views_create refuses such a desc size the same way. */
ob_result ob_views_set_env_map_size(ob_views *ctx, uint32_t size);
ob_result ob_views_set_shadow_map_size(ob_views *ctx, uint32_t size);
/* Cascades of a directional light's shadow from the next frame (0 → the
 * default, 4); over OB_SHADOW_MAX_CASCADES is refused (OB_ERR_OUT_OF_RANGE,
 * logged; the count stays). The shadow distance (0 → from the scene;
 * negative or not finite refused) and the split lambda (0 → the default;
 * outside [0, 1] refused) the same way. [render thread, between frames] */
ob_result ob_views_set_shadow_cascades(ob_views *ctx, uint32_t count);
ob_result ob_views_set_shadow_distance(ob_views *ctx, float distance);
ob_result ob_views_set_shadow_split_lambda(ob_views *ctx, float lambda);
/* Screen-tile culling of point and spot lights (docs/architecture.md,
 * "Many lights"), on by default. Off, every fragment of a camera view loops
 * over all the scene's lights: the same pixels (a light adds exactly zero
 * beyond its range), only slower; for measuring and checking the grid.
 * [render thread, between frames] */
void ob_views_set_light_tiles(ob_views *ctx, bool on);
/* Levels of detail (ob_geometry_desc.lods), on by default: camera views,
 * cube environment maps and the point and spot lights' shadow maps draw
 * each entity at the coarsest level of its geometry whose error, projected
 * from the point of its bound nearest the camera, is at most `pixels` (0 →
 * the default, 1; negative or not finite refused, OB_ERR_INVALID_ARGUMENT,
 * logged); shadow cascades measure it in texels, the same at any distance.
 * Paraboloid maps draw level 0. Off, every view draws level 0: the pixels
 * of a scene without levels. [render thread, between frames] */
ob_result ob_views_set_lod_error(ob_views *ctx, float pixels);
void ob_views_set_lod(ob_views *ctx, bool on);
/* Env map kind for maps created afterwards (an entity keeps the map it has);
 * an unknown kind is refused: logged, false, the old kind kept. [render
 * thread, between frames] */
bool ob_views_set_env_map_kind(ob_views *ctx, ob_env_map_kind kind);
ob_env_map_kind ob_views_env_map_kind(const ob_views *ctx);
/* What env maps clear to from the next frame on (ob_views_desc.sky_color:
 * alpha 0 → the first asking camera's clear colour). Linear, unclamped: a
 * value above 1 is an HDR sky. [render thread, between frames] */
void ob_views_set_sky_color(ob_views *ctx, const float rgba[4]);

/* ---------------------------------------------------------- perspective */

typedef struct ob_perspective_view ob_perspective_view;
typedef struct ob_perspective_desc {
    const char *name;
    ob_node *camera;             /* a node with a camera component */
    uint32_t width, height;
    VkFormat color_format;       /* 0 → R16G16B16A16_SFLOAT (linear HDR) */
    float clear_color[4];        /* linear, like everything the view draws */
    uint32_t samples;            /* MSAA: 0 or 1 → none; 2, 4, 8: drawn multisampled and
                                    resolved (average) into the colour target consumers
                                    read. Lowered to what the device offers for the
                                    formats, with a warning in the log. */
} ob_perspective_desc;

ob_perspective_view *ob_perspective_view_create(ob_views *ctx, const ob_perspective_desc *desc,
                                                ob_result *out_result);
void ob_perspective_view_destroy(ob_views *ctx, ob_perspective_view *v);
ob_view *ob_perspective_view_base(ob_perspective_view *v);
/* The (single-sampled, resolved) colour target. Its handle changes when
 * the view is resized: ask again after each frame. */
ob_image ob_perspective_view_color(const ob_perspective_view *v);
/* Samples per pixel the view renders with (1 without MSAA). */
uint32_t ob_perspective_view_samples(const ob_perspective_view *v);

/* Resizing: ob_view_resize(base, w, h) (engine/ob_view.h) on a perspective
 * or composite view takes effect at the view's next PreRender: its targets are
 * made again (same formats and samples) before anything of that frame is
 * recorded, the old ones destroyed deferred. A composite follows its
 * source's size in the same frame. */

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
/* The exposure a composite starts with: scales the linear scene colour
 * before the tone map. */
#define OB_COMPOSITE_DEFAULT_EXPOSURE 1.0f
/* Tone maps `source`'s linear (HDR) colour into a final target of the same
 * size, format R8G8B8A8_SRGB: the colour pipeline is scene (linear, 16-bit
 * float) → exposure → ACES fit (Narkowicz; formula in
 * materials/shaders/composite.frag) → sRGB encode by the target's format. */
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
/* Exposure: a linear scale of the scene colour before the tone map
 * (default OB_COMPOSITE_DEFAULT_EXPOSURE; 2 is one stop brighter). Takes
 * effect in the next frame recorded. A negative or non-finite value is
 * refused: logged, false, the old value kept. [render thread, between
 * frames] */
bool ob_composite_view_set_exposure(ob_composite_view *v, float exposure);
float ob_composite_view_exposure(const ob_composite_view *v);
/* Tone mapping on (default) or off: off, the exposed colour is only clamped
 * to [0, 1] before the sRGB encode (a linear 0.5 reads back as 188).
 * [render thread, between frames] */
void ob_composite_view_set_tonemap(ob_composite_view *v, bool tonemap);
/* The 8-bit sRGB level the composite writes for a linear colour channel
 * value with its current exposure and tone map, computed on the CPU the way
 * composite.frag does (then encoded and rounded to nearest): for tools and
 * tests that look for a known colour in the output. The GPU's arithmetic
 * may land one level away. [any thread: only reads v] */
uint8_t ob_composite_view_output_level(const ob_composite_view *v, float linear);

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
 * shader variants this created to the frame's stats. Returns the frame's
 * first error so far (ob_frame_stats.first_error of the current stats):
 * OB_OK, or what a view, entity or material met and the frame went on
 * without (an effect variant that does not compile, a pipeline or an env
 * map that could not be made) — the frame still renders the rest, and the
 * log names each. [render thread, between begin_frame and end_frame] */
ob_result ob_views_render(ob_views *ctx, ob_view *final_view);
/* ob_views_render of several root views as one PreRender: the standard
 * views among them and all they need are culled together, in waves on the
 * renderer's worker pool (ob_renderer_pre_render_many). Prefer it to
 * calling ob_views_render per root when a frame has several. Same result.
 * [render thread, between begin_frame and end_frame] */
ob_result ob_views_render_many(ob_views *ctx, ob_view *const *roots, uint32_t count);

/* Standard vertex layout of geometry, as an effect's vertex input: a
 * constant the library owns, made on first use. [any thread] */
const ob_effect_vertex_input *ob_views_standard_input(void);

#endif /* OB_VIEWS_H */
