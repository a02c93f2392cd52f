/* ob_view.h — the render view interface (Hieroglyph 3's SceneRenderTask).
 *
 * A view is one pass of the frame: a camera's colour + depth, a light's shadow
 * map, an environment map, a simulation, an overlay. Concrete views live in
 * views/ and embed ob_view as their first member.
 *
 * Frame life of a view:
 *   pre_render   [render thread]  queue itself (ob_renderer_queue_view), cull the
 *                               scene into its draw list (ob_view_cull), and let
 *                               visible entities' materials queue the views they
 *                               need (ob_view_pre_render_items)
 *   set_render_params [the recording thread] at the start of each job (chunk)
 *                               of the view: fill the per-view parameters of
 *                               the slot that records it
 *   record     [any one thread] record draw-list items [first, first+count) through
 *                               a pipeline manager; may run as several chunks on
 *                               several workers, each into its own secondary
 *   set_usage_params            what consumers need (its output texture), applied
 *                               by the renderer before a consumer records
 *
 * Ownership: the application (or the views layer) owns views; the renderer only
 * holds them in its queue for one frame.
 */
#ifndef OB_VIEW_H
#define OB_VIEW_H

#include "ob_pipeline_manager.h"
#include "ob_scene.h"

typedef struct ob_renderer ob_renderer;

typedef enum ob_view_type {
    OB_VIEW_PERSPECTIVE = 0,
    OB_VIEW_SHADOW,
    OB_VIEW_PARABOLOID,
    OB_VIEW_SIMULATION,
    OB_VIEW_OVERLAY,
    OB_VIEW_COMPOSITE,
    OB_VIEW_CUBE,              /* cube environment map: six 90° faces (layers) */
    OB_VIEW_TYPE_COUNT
} ob_view_type;

const char *ob_view_type_name(ob_view_type t);

/* A view may depend on every other view of its frame (a camera seeing 100
 * reflective entities samples 100 env maps), so this matches the renderer's
 * OB_MAX_FRAME_VIEWS (checked there) and an edge is never dropped. */
#define OB_VIEW_MAX_DEPS 128
#define OB_VIEW_MAX_INPUTS 8
#define OB_VIEW_MAX_LAYERS 6
#define OB_VIEW_NO_THREAD UINT32_MAX  /* ob_view.cull_thread: none */

typedef struct ob_view ob_view;

/* One entry of a view's draw list, ordered by (sort_hi, sort_key, node_id):
 * class and priority, then for opaque items a coarse depth band, material
 * state, mesh and fine depth (front to back), for blended items depth (back
 * to front), material state and mesh. The entity id makes the order total. */
typedef struct ob_draw_item {
    uint64_t sort_key;
    uint32_t sort_hi;       /* class (top bit) and priority */
    uint32_t node_id;
    ob_node *node;
    uint32_t proxy;         /* index in the view's proxies (the scene snapshot's) */
    /* The renderable's material and geometry as the snapshot's indices
     * (ob_render_soa: soa.materials[material] is the pointer; 0 none), so
     * that recording finds a run's end in the list itself. */
    uint32_t material, geometry;
    uint8_t lod;            /* the geometry's level of detail drawn (ob_view.lod_scale) */
} ob_draw_item;

/* What culling knows of one material (by its scene index, ob_render_soa)
 * in one view: asked of the material interface once per view and frame,
 * never per entity. */
typedef struct ob_view_material {
    uint32_t sort_hi, state;  /* class and priority, state group, for this view's type */
    uint8_t mask;             /* bit t: the material renders in views of type t */
    uint8_t per_entity;       /* its pre_render depends on the entity here */
    uint8_t seen;             /* culling's scratch (the material's first item found) */
} ob_view_material;

/* An item of a view's draw list that its post-cull work visits, with what
 * that work reads of it: culling fills these on the pool, so the render
 * thread does not follow item -> node -> renderable through lines culling
 * has long evicted or another core wrote (about 0.5 us an item on the
 * 2-core machine). */
typedef struct ob_view_material_item {
    ob_node *node;                /* the item's entity */
    struct ob_material *material; /* its material in the snapshot culled */
    uint32_t item;                /* its index in the draw list */
} ob_view_material_item;

typedef struct ob_view_vtbl {
    const char *type_name;
    void (*pre_render)(ob_view *v, ob_renderer *r);
    /* Per-view parameters (matrices, lights) into a manager's slot. */
    void (*set_render_params)(ob_view *v, ob_renderer *r, ob_params *params);
    /* What a consumer samples (e.g. the env map texture, the shadow map and
     * the matrix into it from the consumer's camera-relative space), into a
     * manager's slot. Called by the renderer for each dependency before a
     * consumer records, and by materials per draw for views attached to an
     * entity (ob_renderer_attached_view). [any thread: only reads v] */
    void (*set_usage_params)(ob_view *v, ob_renderer *r, ob_params *params,
                             const ob_view *consumer);
    /* Record items [first, first+count) of layer `layer`. Compute views get
     * count = 0 and record their dispatches with layer 0. */
    void (*record)(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                   uint32_t layer, uint32_t first, uint32_t count);
    /* Optional: PreRender in two halves, so that the renderer can cull the
     * views of a frame together, on the worker pool (in waves: the views
     * queued by one wave's post_cull are culled as the next wave). pre_cull
     * queues the view and sets what culling reads (origin, view_proj,
     * no_frustum, cull_exclude); it returns true when the view wants its
     * draw list culled. The renderer then culls it (ob_view_cull_many) and
     * calls post_cull with the view current again at the same depth: the
     * rest of PreRender (views its items need, pipelines). A view with
     * them leaves pre_render NULL. [render thread] */
    bool (*pre_cull)(ob_view *v, ob_renderer *r);
    void (*post_cull)(ob_view *v, ob_renderer *r);
} ob_view_vtbl;

struct ob_view {
    const ob_view_vtbl *vtbl;
    ob_view_type type;
    char name[48];
    uint32_t id;                      /* stable id: order ties, hashes */

    /* Targets. A graphics view renders layer_count passes (2 for the dual
     * paraboloid, 6 for a cube map), each into layer i of color/depth
     * (either may be zero). */
    ob_image color, depth;
    uint32_t layer_count;             /* 0 → compute view (no rendering scope) */
    /* Layer i of the view is layer first_layer + i of color/depth: views
     * that share one array target (a light's shadow cascades, the local
     * lights' shadow maps) each own their layers. The images are created
     * and destroyed by their owner (the first cascade, the local shadow
     * set), not by every view. 0 otherwise. */
    uint32_t first_layer;
    /* A point or spot light's shadow view (type OB_VIEW_SHADOW): consumers
     * sample it as the local lights' shadow array (materials' LOCAL_SHADOWS
     * variants), not as the directional light's map (SHADOWS). */
    bool local_shadow;
    /* Mip levels wanted for `color` (0 or 1: none). With more, the target
     * is made with them and, once the view has rendered, the renderer fills
     * levels 1.. from level 0 (a box-filtered blit chain,
     * ob_image_record_mips): environment maps sampled by roughness. */
    uint32_t color_mips;
    uint32_t width, height;
    /* Multisampling. With samples > 1 (one layer only) the view draws into
     * msaa_color / msaa_depth and each rendering scope ends by resolving
     * msaa_color into `color` (the average of the samples), which is what
     * consumers sample; `depth` is then absent (the multisampled depth is
     * not resolved: no consumer reads a camera's depth). */
    uint32_t samples;                 /* 0 or 1 → single-sampled */
    ob_image msaa_color, msaa_depth;
    /* A size asked for by ob_view_resize, 0 when none: the owner of the view
     * makes its targets again at its next PreRender. */
    uint32_t resize_width, resize_height;
    float clear_color[4];
    float clear_depth;                /* 0 with reversed-Z */
    bool load_color;                  /* keep previous contents (overlay on final target) */
    bool custom_record;               /* records its own draws (overlay, composite):
                                         record() runs once per layer with count 0 */
    bool no_frustum;                  /* cull by render flag only (environment maps) */
    /* Levels of detail: culling draws an item at the coarsest level of its
     * geometry whose error e (world units) satisfies
     * e * lod_scale <= d - r, d the distance from the origin to the item's
     * bound centre and r its radius: lod_scale is the view's pixels per
     * world unit at distance 1 over the tolerated error in pixels. 0 (the
     * default): level 0 always. With lod_ortho (an orthographic view, a
     * shadow cascade), lod_scale is its pixels per world unit over the
     * tolerance at any distance: the condition is e * lod_scale <= 1. Set
     * by the view's pre_cull. */
    float lod_scale;
    bool lod_ortho;
    const ob_node *cull_exclude;      /* an entity culling leaves out (an env map's owner) */

    /* Images read by this view's draws besides its dependencies' targets. */
    uint32_t input_count;
    ob_image inputs[OB_VIEW_MAX_INPUTS];
    ob_buffer storage_written;        /* compute views: buffer written (consumers
                                         read it in their vertex stage) */

    /* Per frame, filled during pre_render; owned by the view. */
    ob_draw_item *items;
    uint32_t item_count, item_cap;
    const ob_render_proxy *proxies; /* the snapshot culled from (items index it) */
    ob_render_soa soa;                /* its culling data (items' proxy indexes it too) */
    ob_view_material *materials;      /* per material index of the snapshot */
    uint32_t material_count, material_cap;
    /* The items ob_view_for_each_material_item visits, found by culling:
     * the first of each material and every one of a per-entity material,
     * in draw order, with their entity and material. Not valid (all items
     * visited) while material_items is NULL after a failed allocation. */
    ob_view_material_item *material_items;
    uint32_t material_item_count, material_item_cap;
    bool material_items_valid;
    void *cull_mem;                   /* culling's working memory */
    size_t cull_mem_size;
    uint32_t culled;                  /* entities rejected by frustum or render flag */
    uint32_t lod_items;               /* items at a level of detail above 0 */
    uint32_t recursion_depth;         /* how deep in the PreRender chain it was queued */
    ob_view *deps[OB_VIEW_MAX_DEPS];  /* views that must execute before this one */
    uint32_t dep_count;
    double origin[3];                 /* camera-relative rendering origin */
    float view_proj[16];              /* culling matrix (relative to origin) */
    uint64_t queued_frame;            /* renderer frame serial when last queued */
    uint64_t cost_ns;                 /* measured recording cost last time (chunking) */
    uint64_t cull_ns;                 /* this frame's ob_view_cull time */
    /* The parallel loop's thread (0: the render thread, i: pool thread i)
     * that finished this frame's culling, so holds the draw items in its
     * caches; recording prefers it (build_jobs). OB_VIEW_NO_THREAD: culled
     * inline, or not this frame. */
    uint32_t cull_thread;
    /* Tests' switch: culling's frustum test as wide as the CPU allows (0),
     * at most four entities at a time (4), or one at a time (1). The same
     * entities are kept whichever. */
    uint8_t cull_lanes;
    bool range_reported;              /* an entity beyond float range was logged
                                         and has not gone away since */
    /* Materials' triangles in this view are drawn as their edges
     * (VK_POLYGON_MODE_LINE): part of the pipeline key, so a wireframe view
     * has pipelines (and pipeline ids, hence command hashes) of its own and
     * a filled one keeps its usual ones. Set with ob_view_set_wireframe. */
    bool wireframe;
};

/* The colour and depth formats (VK_FORMAT_UNDEFINED when absent) and the
 * sample count of what v's rendering scopes draw into: what a pipeline
 * drawing in v must be made for. [any thread: only reads v] */
void ob_view_attachment_formats(const ob_view *v, const ob_device *dev, VkFormat *out_color,
                                VkFormat *out_depth, uint32_t *out_samples);

/* Draws v's materials as wireframe (on) or filled (off, the default), from
 * its next PreRender. Needs the device feature fillModeNonSolid: without it
 * turning on is refused with OB_ERR_UNSUPPORTED and a log line saying so,
 * and v stays filled. [render thread, between frames] */
ob_result ob_view_set_wireframe(ob_view *v, const ob_device *dev, bool on);

/* Asks for v's targets at width x height. Nothing changes now: the view's
 * owner makes the targets again at the
 * view's next PreRender, before anything of that frame is recorded, and the
 * old images go through the device's deferred deletion, so work already
 * recorded keeps its images. The views layer does it for perspective and
 * composite views (shadow and environment maps take their sizes from the
 * views' settings). A zero side is refused (logged, false).
 * [render thread] */
bool ob_view_resize(ob_view *v, uint32_t width, uint32_t height);
/* The pending resize of v, if any, and clears it (for the view's owner).
 * [render thread] */
bool ob_view_take_resize(ob_view *v, uint32_t *out_width, uint32_t *out_height);

/* Initialise the base part (name copied, id = hash of name). */
void ob_view_init(ob_view *v, const ob_view_vtbl *vtbl, ob_view_type type, const char *name);
/* Free the draw list. */
void ob_view_release(ob_view *v);

/* Frustum-cull the scene's renderables into v->items for view type v->type,
 * using v->origin and v->view_proj, skipping `exclude` (the owner of an env map),
 * entities whose material does not render in this view type, entities of
 * zero world scale, and entities whose bound relative to v->origin does not
 * fit in a float (logged once, naming the entity, until none is left); then sort
 * the list (opaque front to back, blended back to front, priority, id).
 * [render thread] */
ob_result ob_view_cull(ob_view *v, ob_renderer *r, const ob_scene *scene, const ob_node *exclude);
/* ob_view_cull of several views at once, each with its own cull_exclude:
 * the chunks of every view's entities in one parallel loop on the
 * renderer's pool, then each view's sort in another (on the caller when
 * the views hold few entities or the frame is single-threaded). The draw
 * lists are the same as culling each view alone. Returns the first error;
 * a view that fails goes on empty (logged). [render thread] */
ob_result ob_view_cull_many(ob_renderer *r, const ob_scene *scene, ob_view *const *views,
                            uint32_t count);

/* Record v->items[first..first+count) with the renderer's material and geometry
 * interfaces: per item, set WorldMatrix (camera-relative), apply the material
 * for v->type, draw the geometry. [any thread, own manager] */
void ob_view_record_items(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                          uint32_t first, uint32_t count);

/* ob_view_record_items as a view's `record` callback, for views whose
 * layers all draw the same list (perspective, shadow). */
void ob_view_record_draw_list(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count);

/* Let the material of every item queue the views it needs: once per
 * material, or per item for a material whose pre_render depends on the
 * entity (ob_material_iface.pre_render_per_entity). [render thread] */
void ob_view_pre_render_items(ob_view *v, ob_renderer *r);

/* Calls fn(user, v, e) for each item e of v's draw list that is the first
 * item of its material, or whose material's PreRender depends on the
 * entity; in draw order. For per-material work over a draw list (preparing
 * pipelines) without a call per item. [render thread, after ob_view_cull] */
void ob_view_for_each_material_item(ob_view *v,
                                    void (*fn)(void *user, ob_view *v,
                                               const ob_view_material_item *e),
                                    void *user);

/* Item i's world bounding sphere (from the snapshot it was culled from).
 * [any thread, after ob_view_cull] */
void ob_view_item_sphere(const ob_view *v, uint32_t item, double center[3], float *radius);
/* The material index (ob_render_soa) of item i: v->materials[index] holds
 * what culling knew of it. [any thread, after ob_view_cull] */
uint32_t ob_view_item_material(const ob_view *v, uint32_t item);

/* v cannot run before dep has: add the dependency edge (deduplicated). */
void ob_view_add_dependency(ob_view *v, ob_view *dep);

#endif /* OB_VIEW_H */
