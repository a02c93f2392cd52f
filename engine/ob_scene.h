/* ob_scene.h — the scene graph: entities (nodes) with transforms, controllers,
 * renderables, cameras and lights (Hieroglyph 3's Entity3D/Node3D).
 *
 * Lifecycle: ob_scene_create → ob_node_create ... → once per frame
 * ob_scene_update(dt) (controllers, then local and world transforms, bounds,
 * and the frame's snapshot of renderables and lights) → render → ...
 * → ob_scene_destroy (frees every node). Node pointers stay valid until the
 * node (or an ancestor) is destroyed.
 *
 * Numerics: positions and world transforms are double. The GPU gets float
 * matrices relative to a camera origin (ob_node_world_relative), so a scene
 * far from the world origin renders exactly like one at the origin. A node
 * whose transform is not finite (NaN/Inf given by the user or produced by a
 * controller) is not rendered, nor is its subtree; one error line names it
 * ("entity 'name' (id 42): non-finite transform; not rendered") and an info
 * line says when it is fine again. Zero scale is allowed.
 *
 * Traversal never recurses: 100,000-level chains update with no stack growth.
 *
 * Cost: an update evaluates only the nodes whose local transform,
 * visibility or renderable changed since the last one (a setter was
 * called, a controller ran) and their descendants; a static node costs two
 * bytes read. What the update touches per node lives in dense arrays of
 * the scene, not in the node.
 *
 * Thread rule: every mutating function (create/destroy/set_* /add_* /update)
 * is [render thread] and must not run while workers read the scene. Queries
 * (world_*, renderable, camera, light, snapshots, find) are [any thread]
 * while no mutation runs: the snapshot from ob_scene_update is immutable until
 * the next update, so workers may read it while recording.
 *
 * Controllers run inside ob_scene_update; a script controller may change
 * transforms, visibility, renderables, cameras and lights of any node, but not
 * the structure (create/destroy/set_parent/update return OB_ERR_WRONG_STATE
 * there).
 */
#ifndef OB_SCENE_H
#define OB_SCENE_H

#include "ob_core.h"
#include "ob_math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ob_scene ob_scene;
typedef struct ob_node ob_node;
struct ob_material;   /* opaque to the engine (materials layer) */
struct ob_geometry;   /* opaque to the engine (geometry layer) */

/* What to draw for a node. The bounding sphere is in the node's local space,
 * set by the caller from the geometry's bounds. */
typedef struct ob_renderable {
    struct ob_material *material;
    struct ob_geometry *geometry;
    float local_center[3];
    float local_radius;   /* >= 0 */
} ob_renderable;

/* ------------------------------------------------------------------ scene */

/* New scene holding only its root node (named "root"). NULL with
 * *out_result set on failure (out_result may be NULL). */
ob_scene *ob_scene_create(ob_result *out_result);
/* Frees every node. NULL is a no-op. */
void ob_scene_destroy(ob_scene *s);
ob_node *ob_scene_root(ob_scene *s);
/* Live nodes, the root included. */
uint32_t ob_scene_node_count(const ob_scene *s);
/* First node (lowest id) with that name, or NULL. Linear in the node count. */
ob_node *ob_scene_find(const ob_scene *s, const char *name);

/* Runs controllers, then recomputes local and world transforms and world
 * bounds, then rebuilds the snapshot. Controllers run per node in the order
 * added, parents before children, in two passes: first each node's leading
 * parallel-safe controllers (ob_controller_desc.parallel: those added
 * before its first other one), then every other controller. dt in seconds,
 * finite and >= 0. Errors: OB_ERR_INVALID_ARGUMENT
 * (bad dt), OB_ERR_WRONG_STATE (called from a controller),
 * OB_ERR_OUT_OF_HOST_MEMORY (nothing changed). Bad transforms are not errors
 * of the update: they are logged and those nodes skipped. */
ob_result ob_scene_update(ob_scene *s, double dt);
/* ob_scene_update with its per-node work in parallel loops run through par,
 * par->grain nodes per index (0: 1024), each loop handed out only when every
 * thread gets two indices' worth: one loop per level of the hierarchy (its
 * nodes' parallel-safe controllers, then their transforms and their part of
 * the snapshot) when no node has another kind of controller; otherwise a
 * loop of the parallel-safe controllers, the others on the caller, then the
 * levels. Only when a node entered or left the snapshot is it rebuilt (one
 * more loop, in chunks of the id order). Everything else runs on the
 * caller. Gives exactly ob_scene_update's result whatever the thread count
 * or grain. par NULL: ob_scene_update. */
ob_result ob_scene_update_parallel(ob_scene *s, double dt, const ob_parallel *par);

/* The frame's snapshot: renderable nodes (ob_node_is_renderable) in ascending
 * id order, and visible light nodes (has a light, not hidden, transform valid)
 * in ascending id order. Rebuilt by ob_scene_update; destroying a node removes
 * it (and its subtree) at once. Never NULL; *out_count may be 0. */
ob_node *const *ob_scene_renderables(const ob_scene *s, uint32_t *out_count);
ob_node *const *ob_scene_lights(const ob_scene *s, uint32_t *out_count);

/* A renderable's world transform for the frame, in an array parallel to the
 * renderables snapshot (same order, same count), so that the views' loops
 * read contiguous memory instead of chasing nodes: the proxy is what
 * recording reads of an entity, one cache line (the array is 64-byte
 * aligned), and the one line the update writes for each moving entity.
 * Who the entity is and what it draws (node, id, material, geometry) lie
 * in ob_render_soa with the bounds; the normal matrix is derived where a
 * draw needs it (ob_render_proxy_per_draw). World data is as of the last
 * ob_scene_update (as the node's queries). */
typedef struct ob_render_proxy {
    float linear[9];             /* world upper 3x3 in float, column-major */
    uint8_t finite;              /* 1: linear is finite in float (and so its normal matrix) */
    uint8_t mirrors;             /* 1: linear's determinant is negative (ob_det3_negative):
                                    drawn with the other front face */
    double world_t[3];           /* world translation */
} ob_render_proxy;

/* The proxies of the snapshot, *out_count of them (= the renderables').
 * Never NULL. Valid until the next update or node destruction. [any
 * thread, while no mutation runs] */
const ob_render_proxy *ob_scene_render_proxies(const ob_scene *s, uint32_t *out_count);

/* The snapshot's culling and identity data as a structure of arrays,
 * parallel to the proxies (index i is proxy i, ascending node id), for
 * loops that touch every renderable in every view: the world bound, a flag
 * byte, the renderable's material and geometry as small dense indices
 * (interned when the renderable is set, following ob_node_set_renderable at
 * once: the materials / geometries tables give the pointer back; 0 is
 * none), and the node and its id. Valid like the proxies. */
#define OB_RENDER_ZERO_SCALE 1u  /* a bound with a local radius but none in the world */
typedef struct ob_render_soa {
    uint32_t count;
    const double *x, *y, *z;      /* world bound centre */
    const float *radius;          /* world bound radius */
    const uint8_t *flags;
    const uint32_t *material, *geometry;
    const uint32_t *node_id;
    ob_node *const *node;
    /* Index -> pointer for material and geometry ([0] NULL), as
     * ob_scene_material / ob_scene_geometry give them for the indices
     * the snapshot uses. */
    struct ob_material *const *materials;
    struct ob_geometry *const *geometries;
} ob_render_soa;
void ob_scene_render_soa(const ob_scene *s, ob_render_soa *out);
/* The pointer behind an index of ob_render_soa (NULL for 0 or an index no
 * renderable of the snapshot uses), and how many indices there are. */
struct ob_material *ob_scene_material(const ob_scene *s, uint32_t index);
struct ob_geometry *ob_scene_geometry(const ob_scene *s, uint32_t index);
uint32_t ob_scene_material_count(const ob_scene *s);
uint32_t ob_scene_geometry_count(const ob_scene *s);

/* The standard per-draw block of a proxy: its world matrix relative to
 * origin (as ob_node_world_relative gives it for the node) in dest[0..15] and
 * the normal matrix (ob_mat4_normal_cofactor's, bit for bit) in
 * dest[16..31]. False when some value is not finite in float (dest is
 * written anyway). */
static inline bool ob_render_proxy_per_draw(const ob_render_proxy *p, const double origin[3],
                                            float dest[32])
{
    float t[3], normal[9];
    ob_mat3_normal_cofactor(p->linear, normal);
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) {
            dest[c * 4 + r] = p->linear[c * 3 + r];
            dest[16 + c * 4 + r] = normal[c * 3 + r];
        }
        dest[c * 4 + 3] = dest[16 + c * 4 + 3] = 0.0f;
        t[c] = (float)(p->world_t[c] - origin[c]);
        dest[12 + c] = t[c];
        dest[28 + c] = 0.0f;
    }
    dest[15] = dest[31] = 1.0f;
    return p->finite && isfinite(t[0]) && isfinite(t[1]) && isfinite(t[2]);
}

/* The per-instance block of a proxy (OB_INSTANCE_STRIDE, ob_program.h):
 * its world matrix relative to origin as three rows, dest[4 r + c] the
 * upper 3x3's row r, column c, and dest[4 r + 3] the translation's r
 * (subtracted in double). False when some value is not finite in float, as
 * ob_render_proxy_per_draw says (dest is written anyway). */
static inline bool ob_render_proxy_instance(const ob_render_proxy *p, const double origin[3],
                                            float dest[12])
{
    float t[3];
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) dest[r * 4 + c] = p->linear[c * 3 + r];
        t[r] = (float)(p->world_t[r] - origin[r]);
        dest[r * 4 + 3] = t[r];
    }
    return p->finite && isfinite(t[0]) && isfinite(t[1]) && isfinite(t[2]);
}

/* ------------------------------------------------------------------- nodes */

/* New node under parent (NULL → root) with identity transform, named `name`
 * (copied; NULL → ""). Its id is unique, increasing in creation order and
 * never reused, so it breaks draw-order ties deterministically. NULL with
 * *out_result set on failure. */
ob_node *ob_node_create(ob_scene *s, ob_node *parent, const char *name, ob_result *out_result);
/* Destroys n and its whole subtree (iteratively). The node knows its
 * scene, so there is no scene argument to get wrong (an earlier two-argument
 * form, called with its arguments guessed, compiled with a warning and
 * crashed). NULL is a no-op (OB_OK). Refused, logged with the node's name
 * and id, nothing destroyed: the root (OB_ERR_INVALID_ARGUMENT: destroy the
 * scene instead) and any call from a controller during ob_scene_update
 * (OB_ERR_WRONG_STATE). [render thread] */
ob_result ob_node_destroy(ob_node *n);
/* Destroys each of nodes[0..count) with its subtree, as many calls of
 * ob_node_destroy would, in time linear in the nodes destroyed (plus the
 * snapshot's entries of newer nodes), where one call per node costs the
 * whole snapshot each. A node may lie in another's subtree, be listed
 * twice, or be NULL. A node that is not a live node of s (another scene's,
 * or the root) is refused, logged with its name, and the others are still
 * destroyed: the result is then OB_ERR_INVALID_ARGUMENT; during
 * ob_scene_update nothing is destroyed (OB_ERR_WRONG_STATE). [render thread] */
ob_result ob_nodes_destroy(ob_scene *s, ob_node *const *nodes, uint32_t count);
/* Moves n (with its subtree) under parent (NULL → root), keeping its local
 * transform. Refuses cycles, the root and nodes of another scene
 * (OB_ERR_INVALID_ARGUMENT, logged). */
ob_result ob_node_set_parent(ob_scene *s, ob_node *n, ob_node *parent);

uint32_t ob_node_id(const ob_node *n);
const char *ob_node_name(const ob_node *n);
ob_node *ob_node_get_parent(const ob_node *n);          /* NULL for the root */
ob_node *ob_node_first_child(const ob_node *n);     /* children in the order attached */
ob_node *ob_node_next_sibling(const ob_node *n);

/* Local transform (relative to the parent): T * R * S. Values are taken as
 * given; non-finite ones are caught by the next update. The rotation need not
 * be unit (it is normalized); a zero quaternion is rejected like a NaN. */
void ob_node_set_position(ob_node *n, const double p[3]);
void ob_node_set_rotation(ob_node *n, const float q[4]);   /* x, y, z, w */
void ob_node_set_rotation_d(ob_node *n, const double q[4]);  /* full precision */
void ob_node_set_scale(ob_node *n, const float s[3]);
/* Rotation from Euler angles in radians: yaw about Y, then pitch about X,
 * then roll about Z, all in the node's local frame (q = yaw * pitch * roll). */
void ob_node_set_euler(ob_node *n, float pitch, float yaw, float roll);
void ob_node_get_position(const ob_node *n, double dest[3]);
/* The stored rotation is double (controllers integrate in double). */
void ob_node_get_rotation(const ob_node *n, double dest[4]);
void ob_node_get_scale(const ob_node *n, float dest[3]);
/* Turns n so its forward (-Z) points from its current world position (walked
 * from its ancestors now, no update needed) to target, +Y as close to up as
 * possible. A degenerate up (parallel to the direction, zero) is replaced by
 * another axis and logged as a warning naming the node (OB_OK). A target at
 * the node's own position or non-finite input leaves the rotation unchanged
 * and returns OB_ERR_INVALID_ARGUMENT (logged). */
ob_result ob_node_look_at(ob_node *n, const double target[3], const double up[3]);

/* Hides n and its subtree from the snapshot (transforms are still updated). */
void ob_node_set_hidden(ob_node *n, bool hidden);
bool ob_node_is_hidden(const ob_node *n);   /* n's own flag */
/* Copies r (NULL clears). A negative or non-finite bound is refused
 * (OB_ERR_INVALID_ARGUMENT, logged, nothing changed). */
ob_result ob_node_set_renderable(ob_node *n, const ob_renderable *r);
const ob_renderable *ob_node_get_renderable(const ob_node *n);   /* NULL if none */

void ob_node_set_user(ob_node *n, void *user);
void *ob_node_get_user(const ob_node *n);

/* ------------------------------------------- world queries (after update) */

/* As of the last ob_scene_update; a node that was never updated, or whose
 * transform is invalid, reports its last valid world (identity at first). */
void ob_node_world_position(const ob_node *n, double dest[3]);
/* Full double world transform. */
void ob_node_world_affine(const ob_node *n, ob_daffine *dest);
/* World matrix for the GPU, relative to origin (usually the camera position). */
void ob_node_world_relative(const ob_node *n, const double origin[3], float dest[16]);
/* Orthonormal right-handed world axes; forward = the node's -Z. Scale and
 * shear are removed; under zero scale the axes come from the rotations alone. */
void ob_node_world_axes(const ob_node *n, float right[3], float up[3], float forward[3]);
/* View matrix of n used as a camera, relative to origin (pass the camera's
 * own world position for camera-relative rendering: then it is a rotation). */
void ob_node_view_relative(const ob_node *n, const double origin[3], float dest[16]);
/* World bounding sphere of the renderable (center (0,0,0), radius 0 without one). */
void ob_node_world_sphere(const ob_node *n, double center[3], float *radius);
/* Has a renderable, neither it nor an ancestor is hidden, transform valid. */
bool ob_node_is_renderable(const ob_node *n);
/* Its world transform (and its ancestors') was finite at the last update. */
bool ob_node_transform_is_valid(const ob_node *n);

/* ----------------------------------------------------------- controllers */

/* Runs during ob_scene_update, before world transforms are computed. */
typedef void (*ob_controller_fn)(ob_node *n, double dt, void *user);

typedef struct ob_controller_desc {
    ob_controller_fn fn;            /* required */
    void *user;
    /* Optional. The node owns user from the call on: release(user) runs once
     * when the node is destroyed, and at once if adding fails. */
    void (*release)(void *user);
    /* Safe to run in parallel with other nodes' controllers: it reads and
     * writes only its own node's transform (ob_node_get/set_position,
     * _rotation, _scale, _euler, look_at) and its own user data, and
     * creates, destroys or re-parents nothing. Those of every node run
     * first, on the worker pool when the update is given one
     * (ob_renderer_update_scene); the rest run after them on the calling
     * thread. When no node has any of the rest, each node's run right
     * before its own transform is computed, level by level of the
     * hierarchy (a node's own world is still the last update's then).
     * The built-in rotation and orbit controllers are. */
    bool parallel;
} ob_controller_desc;

/* General form of the three below. Controllers of a node run in the order
 * added. Errors: OB_ERR_INVALID_ARGUMENT (NULL fn), OB_ERR_OUT_OF_HOST_MEMORY. */
ob_result ob_node_add_controller(ob_node *n, const ob_controller_desc *d);

/* The largest state ob_node_add_controller_state takes, in bytes. */
#define OB_CONTROLLER_STATE_SIZE 96u

/* ob_node_add_controller for a controller whose state is small plain data:
 * the scene keeps a copy of the size bytes at state (size at most
 * OB_CONTROLLER_STATE_SIZE) with the node's controllers, aligned for any
 * type, and passes that copy to fn as user (d->user is ignored). No
 * allocation of its own, and the update reads the states of all nodes'
 * controllers as one stream instead of wherever the heap put them. The
 * copy may move between calls (keep no pointer to it): adding a controller
 * to a node during an update copies that node's states, so a controller
 * that adds one to its own node must not touch its state afterwards in
 * that call. d->release, if set, gets the copy when the node is destroyed
 * (the caller's state at once if adding fails). Errors: those of
 * ob_node_add_controller, and OB_ERR_INVALID_ARGUMENT for a size over the
 * limit or a NULL state. */
ob_result ob_node_add_controller_state(ob_node *n, const ob_controller_desc *d, const void *state,
                                       size_t size);

/* Spins the node about its local axis: q = q * dq(axis, rate * dt) each update,
 * renormalized every time (double), so it stays unit indefinitely. */
ob_result ob_node_add_rotation_controller(ob_node *n, const float axis[3], float radians_per_second);
/* Sets the node's position on the circle of `radius` about center (parent
 * space) in the plane normal to axis, at angle phase + rate * t, rotating
 * right-handedly about axis. Angle 0 is the world axis least aligned with
 * axis (preferring X, then Y, then Z) projected onto the plane. */
ob_result ob_node_add_orbit_controller(ob_node *n, const double center[3], const float axis[3],
                                       double radius, float radians_per_second, float phase);
ob_result ob_node_add_script_controller(ob_node *n, ob_controller_fn fn, void *user);
/* Errors of the three: OB_ERR_INVALID_ARGUMENT (zero/non-finite axis, rate,
 * radius, NULL fn; logged with the node's name), OB_ERR_OUT_OF_HOST_MEMORY. */

/* ----------------------------------------------------- cameras and lights */

typedef struct ob_camera_desc {
    float fovy;     /* vertical field of view in radians, 0 → 60 degrees */
    float znear;    /* 0 → 0.1 */
    float aspect;   /* 0 → from the view's target */
} ob_camera_desc;

/* Copies d with defaults filled in (NULL removes the camera). Refuses fovy
 * outside (0, pi), negative or non-finite values (OB_ERR_INVALID_ARGUMENT). */
ob_result ob_node_set_camera(ob_node *n, const ob_camera_desc *d);
const ob_camera_desc *ob_node_get_camera(const ob_node *n);   /* NULL if none */

typedef enum ob_light_type { OB_LIGHT_DIRECTIONAL, OB_LIGHT_POINT, OB_LIGHT_SPOT } ob_light_type;

/* The direction of a directional or spot light is its node's forward (-Z);
 * point and spot lights sit at the node's world position. Any number of
 * point and spot lights may light a scene up to OB_MAX_LIGHTS (docs/
 * limits.md); only the first directional light (node-id order) is shaded. */
typedef struct ob_light_desc {
    ob_light_type type;
    float color[3];       /* linear RGB, (0,0,0) → white */
    float intensity;      /* literal: 0 switches the light off (it lights nothing and
                             its shadow view is left out); set 1 for a plain light */
    float range;          /* point and spot lights; 0 → no cut-off */
    /* Default false. Directional: an orthographic map fitted to the casters
     * the camera sees (only the first directional light is shaded). Spot:
     * one perspective map over the outer cone. Point: a cube map (six
     * 90-degree faces). A spot or point light's map is drawn only in frames
     * where the light reaches an entity a camera sees, and then takes layers
     * of the one local shadow array (a spot 1, a point 6; handed out each
     * frame in the cameras' order, node-id order within a camera) up to
     * OB_MAX_LOCAL_SHADOW_LAYERS; a light past that lights unshadowed,
     * logged once by name and listed each frame in ob_frame_stats.skipped
     * (OB_SKIP_OVER_LIMIT). */
    bool casts_shadows;
    /* Spot lights: half-angles of the cone from its axis, in radians. Full
     * intensity inside inner_angle, smoothly down to none at outer_angle;
     * 0 ≤ inner_angle ≤ outer_angle < pi/2. outer_angle 0 → pi/4 (glTF's
     * default); inner_angle 0 is a cone with no fully lit core. */
    float inner_angle, outer_angle;
} ob_light_desc;

/* Most point and spot lights that light one scene: the first OB_MAX_LIGHTS
 * visible ones of non-zero intensity in node-id order. Each light over the
 * limit is logged once by name and counted in ob_frame_stats.lights_over_limit
 * every frame it is left out. */
#define OB_MAX_LIGHTS 256u
/* Layers of the local lights' shadow array (docs/limits.md): e.g. 16 spot
 * lights, or 2 point lights and 4 spot lights, shadowed at once. */
#define OB_MAX_LOCAL_SHADOW_LAYERS 16u

/* Copies d with defaults filled in (NULL removes the light). Refuses unknown
 * types, negative or non-finite values, and spot angles outside
 * 0 ≤ inner ≤ outer < pi/2 (OB_ERR_INVALID_ARGUMENT, logged naming the node). */
ob_result ob_node_set_light(ob_node *n, const ob_light_desc *d);
const ob_light_desc *ob_node_get_light(const ob_node *n);     /* NULL if none */

#ifdef __cplusplus
}
#endif
#endif /* OB_SCENE_H */
