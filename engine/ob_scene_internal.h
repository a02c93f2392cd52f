/* ob_scene_internal.h — the scene's structs, shared by ob_scene.c (nodes,
 * their API and the interning of materials and geometries) and
 * ob_scene_update.c (the per-frame update and its snapshot). Not installed.
 *
 * Storage: one ob_malloc per node (name inline), so node pointers are stable;
 * what the update reads and writes per node lives in the scene instead, in
 * dense arrays indexed by the node's slot (its index in by_id), so that the
 * update streams through memory and never follows a node pointer for a node
 * that has no controller. by_id is in creation (= id) order, with holes left
 * by destroy and compacted at the next update (all slot arrays move
 * together), so the snapshot comes out sorted by id without a sort.
 */
#ifndef OB_SCENE_INTERNAL_H
#define OB_SCENE_INTERNAL_H

#include "ob_scene.h"

#include <stddef.h>
#include <string.h>

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

#define SCENE_LOG "scene"
#define NO_SLOT UINT32_MAX

/* Nodes per index of the update's loops unless ob_parallel.grain says
 * otherwise: at most UPDATE_GRAIN (tens of microseconds of work, so a
 * hand-out costs little beside it), and no fewer than UPDATE_GRAIN_MIN
 * when a parallel loop cuts its nodes finer to give each thread several
 * indices. A loop is handed out only when each thread gets two
 * UPDATE_GRAINs' worth. */
#define UPDATE_GRAIN 1024u
#define UPDATE_GRAIN_MIN 256u

typedef struct ob_controller_slot {
    ob_controller_fn fn;
    void *user;                 /* unless the state is inline */
    void (*release)(void *user);
    bool inline_state;          /* user is state (ob_node_add_controller_state) */
    _Alignas(max_align_t) unsigned char state[OB_CONTROLLER_STATE_SIZE];
} ob_controller_slot;

static inline void *controller_user(ob_controller_slot *c)
{
    return c->inline_state ? c->state : c->user;
}

/* A node's controllers, kept by slot so that the update reaches them (and,
 * for the built-in ones, the state they move) without the node. They lie
 * in the scene's pool, every node's one after another in level order
 * (repacked at an update once enough lie elsewhere), or, once the node got
 * one more since, in a block of their own. */
typedef struct node_controllers {
    ob_controller_slot *slots;
    uint32_t count, cap;        /* pooled: cap == count */
    uint32_t parallel;          /* the leading parallel-safe ones */
    bool pooled;
} node_controllers;

/* node_xf.flags */
enum {
    XF_HIDDEN = 1u << 0,            /* the node's own flag */
    XF_EFFECTIVE_HIDDEN = 1u << 1,  /* hidden itself or through an ancestor */
    XF_WORLD_VALID = 1u << 2,       /* it and every ancestor finite at the last evaluation */
    XF_HAS_RENDERABLE = 1u << 3,
    XF_HAS_LIGHT = 1u << 4,
    XF_FAULT_REPORTED = 1u << 5,    /* an error line about its own transform is out */
    XF_HAS_CHILDREN = 1u << 6,      /* as of the last order rebuild */
    XF_IDENTITY = 1u << 7,          /* world and world rotation exactly the identity
                                       (tracked for nodes with children only) */
    XF_ROTATION_UNIT = 1u << 8,     /* rotation is unit as ob_dquat_normalize made it
                                       (the rotation controller's): used as is */
    XF_WORLD_ROT_LOCAL = 1u << 9,   /* the world rotation is the unit rotation (as the
                                       last evaluation made it from this very rotation):
                                       not stored; else it is scene->world_rot[slot].
                                       A rotation change stores it first
                                       (node_world_rotation_keep), except a rotation
                                       controller's in the fused loop, whose node is
                                       evaluated right after: should that evaluation
                                       fail (a non-finite position or scale in the same
                                       update), the world rotation follows the new
                                       rotation while the world stays the last valid
                                       one, which shows only in the axes of a node
                                       whose last valid world had a zero scale */
};

/* A node's transform data: three cache lines, everything its evaluation
 * reads or writes except the parent's. What follows from them is not kept
 * here: the world bound (world and local bound give it, and the snapshot's
 * arrays hold it for the renderables), and the world rotation of a node
 * whose parent is the identity (its own unit rotation; see
 * XF_WORLD_ROT_LOCAL). A moving node costs the update a quarter fewer
 * bytes than with them. */
typedef struct node_xf {
    _Alignas(OB_CACHE_LINE) double position[3];
    double rotation[4];         /* as set: need not be unit */
    ob_daffine world;           /* last valid world transform */
    float scale[3];             /* set from floats only, so float holds it exactly */
    float local_center[3], local_radius; /* the renderable's bound; zero without one */
    uint32_t flags;             /* XF_* */
    uint32_t proxy_index;       /* in the snapshot's proxies while NODE_IN_RENDERABLES */
} node_xf;

/* World rotations (rotations alone: axes survive zero scale) of the nodes
 * without XF_WORLD_ROT_LOCAL. */
typedef struct node_rot {
    double q[4];
} node_rot;

_Static_assert(sizeof(node_xf) == 3 * OB_CACHE_LINE, "node_xf is three cache lines");

/* scene->state: one byte per slot, what the update's loops test before they
 * touch anything else of a node. */
enum {
    NODE_DIRTY = 1u << 0,           /* its local transform, hidden flag, renderable or
                                       light changed since its last evaluation */
    NODE_CHANGED = 1u << 1,         /* evaluated in this update: its children must be */
    NODE_IN_RENDERABLES = 1u << 2,  /* in the snapshot's renderables (ob_node_is_renderable) */
    NODE_IN_LIGHTS = 1u << 3,       /* in the snapshot's lights */
    NODE_PARALLEL = 1u << 4,        /* has leading parallel-safe controllers */
    NODE_SERIAL = 1u << 5,          /* has other controllers */
    /* A built-in orbit or rotation controller kept in scene->motion: only
     * while the node has no controller in scene->ctl (and so at most one
     * of each); the two commute, so they need no order. */
    NODE_ORBIT = 1u << 6,
    NODE_SPIN = 1u << 7,
    NODE_MOTION = NODE_ORBIT | NODE_SPIN,
};

/* The state of NODE_ORBIT and NODE_SPIN (ob_controllers_internal.h). */
typedef struct node_motion node_motion;

/* The renderable's pointers and their interned indices (0 without one). */
typedef struct node_draw {
    struct ob_material *material;
    struct ob_geometry *geometry;
    uint32_t material_index, geometry_index;
} node_draw;

/* An entry of the update's level order: a node and its parent, by slot. */
typedef struct level_item {
    uint32_t slot, parent;      /* parent NO_SLOT for the root */
} level_item;

/* Distinct pointers (materials, geometries) numbered densely; see ob_scene.c. */
typedef struct intern_table {
    void **ptr;                 /* index -> pointer; NULL = free */
    uint32_t *refs;
    uint32_t count, cap, refs_cap; /* indices [0, count) exist */
    uint32_t *free_list;
    uint32_t free_count, free_cap;
    uint32_t unused;            /* mapped indices with refs == 0 */
    uint32_t *map;              /* open addressing: index, 0 = empty */
    uint32_t map_cap;           /* power of two, or 0 */
} intern_table;

struct ob_node {
    /* What the node API reads to find the node's slot data. */
    ob_scene *scene;
    uint32_t by_id_index;          /* its slot */
    uint32_t id;
    uint32_t depth;                /* in the hierarchy: the root is 0 */
    ob_node *parent, *first_child, *last_child, *prev_sibling, *next_sibling;
    ob_renderable renderable;      /* as set (ob_node_get_renderable) */
    ob_camera_desc camera;
    ob_light_desc light;
    void *user;
    bool has_camera;
    bool dying;                    /* marked while its subtree is being destroyed */
    char name[];
};

struct ob_scene {
    ob_node *root;
    uint32_t next_id;
    uint32_t node_count;
    bool in_update;
    bool order_dirty;
    bool snapshot_dirty;           /* the next update rebuilds the whole snapshot */
    bool motion_lanes2;            /* the built-in controllers two nodes at a time even
                                      where the CPU has four-wide lanes (tests) */
    uint32_t serial_nodes;         /* nodes with a controller that is not parallel-safe */

    /* Slot arrays, by_id_count long (holes: by_id NULL). */
    ob_node **by_id;
    node_xf *xf;
    uint8_t *state;                /* NODE_* */
    uint32_t *slot_id;             /* the node's id */
    node_draw *draw;
    node_controllers *ctl;
    node_motion *motion;           /* read only for nodes with NODE_MOTION */
    node_rot *world_rot;           /* read only for nodes without XF_WORLD_ROT_LOCAL */
    uint32_t by_id_count, by_id_holes;
    uint32_t by_id_cap, xf_cap, state_cap, slot_id_cap, draw_cap, ctl_cap, motion_cap,
             world_rot_cap;

    /* order: slots in pre-order (parents first), for serial controllers;
     * by_level: the same nodes by hierarchy level (depth), pre-order within
     * a level: level d is by_level[level_start[d] .. level_start[d + 1]).
     * Rebuilt when the structure changed; a level's transforms only read
     * the level above. */
    uint32_t *order;
    uint32_t order_count, order_cap;
    level_item *by_level;
    uint32_t by_level_cap;
    uint32_t *level_start;
    uint32_t level_count, level_start_cap;
    uint32_t *chunk_counts;        /* the update's per-chunk figures */
    uint32_t chunk_counts_cap;

    ob_controller_slot *ctl_pool;  /* see node_controllers */
    uint32_t ctl_pool_size;
    uint32_t ctl_loose;            /* controllers outside the pool, and pool slots unused */
    void **retired;                /* controller blocks replaced during the update, freed after it */
    uint32_t retired_count, retired_cap;

    /* The snapshot. */
    ob_node **renderables;
    uint32_t renderable_count, renderable_cap;
    ob_render_proxy *proxies;   /* parallel to renderables */
    uint32_t proxy_cap;
    /* The snapshot's culling data in structure-of-arrays form, parallel
     * to renderables (ob_render_soa). */
    double *soa_x, *soa_y, *soa_z;
    float *soa_radius;
    uint8_t *soa_flags;
    uint32_t *soa_material, *soa_geometry, *soa_node_id;
    ob_node **soa_node;
    uint32_t soa_cap;
    intern_table materials, geometries;
    ob_node **lights;
    uint32_t light_count, light_cap;
};

static inline node_xf *node_xf_of(const ob_node *n) { return &n->scene->xf[n->by_id_index]; }

/* Marks n for the next update: its evaluation reads what changed. */
static inline void node_touch(const ob_node *n) { n->scene->state[n->by_id_index] |= NODE_DIRTY; }

/* The node's world rotation, as of its last valid evaluation. */
static inline void node_world_rotation(const ob_scene *s, uint32_t slot, double dest[4])
{
    const node_xf *x = &s->xf[slot];
    if (!(x->flags & XF_WORLD_ROT_LOCAL)) memcpy(dest, s->world_rot[slot].q, sizeof s->world_rot[slot].q);
    else if (x->flags & XF_ROTATION_UNIT) memcpy(dest, x->rotation, sizeof x->rotation);
    /* The normalization succeeded at the evaluation; the identity only
     * keeps dest defined for the compiler. */
    else if (!ob_dquat_normalize(x->rotation, dest)) ob_dquat_identity(dest);
}

/* Before the node's rotation changes: its world rotation is stored. */
static inline void node_world_rotation_keep(ob_scene *s, uint32_t slot)
{
    node_xf *x = &s->xf[slot];
    if (!(x->flags & XF_WORLD_ROT_LOCAL)) return;
    node_world_rotation(s, slot, s->world_rot[slot].q);
    x->flags &= ~(uint32_t)XF_WORLD_ROT_LOCAL;
}

/* The node's world bound from its world transform and local bound (zero
 * without a renderable), as the update computes it; the world's largest
 * column length, which scales it, is returned. */
static inline double node_world_bound(const node_xf *x, double center[3], float *radius)
{
    double c[3] = {x->local_center[0], x->local_center[1], x->local_center[2]};
    ob_daffine_transform_point(&x->world, c, center);
    double scale = ob_daffine_max_scale(&x->world);
    *radius = (float)(x->local_radius * scale);
    return scale;
}

typedef enum local_status { LOCAL_OK, LOCAL_NON_FINITE, LOCAL_ZERO_ROTATION } local_status;

/* ob_scene.c */
/* Closes the holes of by_id (and every slot array) left by destroy. */
void ob_scene_compact(ob_scene *s);
/* Frees unused material and geometry indices for reuse (see interning). */
void ob_scene_intern_trim(ob_scene *s);
/* Next node in pre-order after n, staying inside the subtree of top. */
ob_node *ob_scene_preorder_next(const ob_node *n, const ob_node *top);

/* Adds a built-in controller (kind NODE_ORBIT or NODE_SPIN, its state at
 * state) to n: into scene->motion when the node has no other controller
 * and none of that kind, else as any controller (after moving those in
 * scene->motion into its list). Errors: ob_node_add_controller's. */
ob_result ob_scene_motion_add(ob_node *n, uint8_t kind, const void *state, size_t size);

/* ob_scene_update.c */
/* Local transform of a node, with its unit rotation. [any thread] */
local_status ob_scene_xf_local(const node_xf *x, ob_daffine *dest, double unit_q[4]);
/* The proxy of a node in the snapshot follows its renderable (material,
 * geometry, local radius). */
void ob_scene_proxy_set_renderable(ob_scene *s, uint32_t slot);
/* Drops the marked (dying) nodes from the snapshot: the renderables from
 * index `from` on (none lies before it), and the lights when `lights`. */
void ob_scene_snapshot_drop_dying(ob_scene *s, uint32_t from, bool lights);

#pragma GCC visibility pop

#endif /* OB_SCENE_INTERNAL_H */
