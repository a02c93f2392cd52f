/* ob_scene.c — the scene graph (see ob_scene.h).
 *
 * Storage: one ob_malloc per node (name inline), so node pointers are stable.
 * Three flat arrays make a frame linear and recursion-free:
 *   by_id  nodes in creation (= id) order, with holes left by destroy and
 *          compacted lazily; the snapshot is built from it, so it comes out
 *          sorted by id without a sort;
 *   order  parents before children (pre-order), rebuilt only when the
 *          structure changed, walked with no stack at all;
 *   renderables / lights  the frame's snapshot.
 */
#include "ob_scene.h"

#include <string.h>

#define SCENE_LOG "scene"

typedef struct ob_controller_slot {
    ob_controller_fn fn;
    void *user;
    void (*release)(void *user);
} ob_controller_slot;

struct ob_node {
    ob_scene *scene;
    uint32_t id;
    uint32_t by_id_index;
    ob_node *parent, *first_child, *last_child, *prev_sibling, *next_sibling;

    double position[3];
    double rotation[4];
    double scale[3];

    ob_daffine world;           /* last valid world transform */
    double world_rotation[4];   /* rotations alone: axes survive zero scale */
    double world_center[3];
    float world_radius;

    ob_renderable renderable;
    ob_camera_desc camera;
    ob_light_desc light;
    ob_controller_slot *controllers;
    uint32_t controller_count, controller_cap;
    uint32_t parallel_controllers; /* the leading parallel-safe ones */
    uint32_t depth;                /* in the hierarchy: the root is 0 */
    void *user;

    bool hidden, has_renderable, has_camera, has_light;
    bool world_valid;        /* this node and every ancestor finite at the last update */
    bool effective_hidden;   /* hidden itself or through an ancestor */
    bool renderable_now;     /* in the current snapshot's sense */
    bool fault_reported;     /* an error line about this node's own transform is out */
    bool dying;              /* marked while its subtree is being destroyed */
    uint32_t proxy_index;    /* in the snapshot's proxies while renderable_now */
    uint32_t material_index, geometry_index; /* interned (scene->materials, ->geometries);
                                                0 without a renderable */
    char name[];
};

/* ------------------------------------------------------------- interning */

/* Distinct pointers (materials, geometries) numbered densely, so that the
 * snapshot can carry a small index per renderable and culling can keep a
 * table per index instead of asking an interface per entity. Index 0 is
 * "none". An index is counted by the renderables that use it; at zero it
 * stays mapped (the same pointer set again revives it) until enough are
 * unused, then they are freed for reuse and the map is rebuilt. Render
 * thread only (set_renderable, destroy, update's start). */
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

static uint32_t intern_hash(const void *p, uint32_t mask)
{
    return (uint32_t)(ob_hash_u64(OB_HASH_SEED, (uint64_t)(uintptr_t)p) & mask);
}

static void intern_map_put(intern_table *t, uint32_t index)
{
    uint32_t mask = t->map_cap - 1;
    for (uint32_t h = intern_hash(t->ptr[index], mask);; h = (h + 1) & mask) {
        if (!t->map[h]) {
            t->map[h] = index;
            return;
        }
    }
}

static ob_result intern_map_rebuild(intern_table *t, uint32_t cap)
{
    uint32_t *map = ob_calloc(cap, sizeof *map);
    if (!map) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_free(t->map);
    t->map = map;
    t->map_cap = cap;
    for (uint32_t i = 1; i < t->count; i++)
        if (t->ptr[i]) intern_map_put(t, i);
    return OB_OK;
}

/* p's index, counted once more (0 for NULL). 0 with *out set on failure. */
static uint32_t intern_acquire(intern_table *t, void *p, ob_result *out)
{
    *out = OB_OK;
    if (!p) return 0;
    if (t->map_cap) {
        uint32_t mask = t->map_cap - 1;
        for (uint32_t h = intern_hash(p, mask); t->map[h]; h = (h + 1) & mask) {
            uint32_t i = t->map[h];
            if (t->ptr[i] != p) continue;
            if (t->refs[i]++ == 0) t->unused--;
            return i;
        }
    }
    if (t->count == 0) t->count = 1; /* index 0: none */
    uint32_t mapped = t->count - 1 - t->free_count;
    if (2 * (mapped + 1) > t->map_cap) {
        *out = intern_map_rebuild(t, t->map_cap ? 2 * t->map_cap : 64);
        if (*out != OB_OK) return 0;
    }
    uint32_t i;
    if (t->free_count) {
        i = t->free_list[--t->free_count];
    } else {
        *out = ob_array_reserve((void **)&t->ptr, &t->cap, t->count + 1, sizeof *t->ptr);
        if (*out == OB_OK)
            *out = ob_array_reserve((void **)&t->refs, &t->refs_cap, t->count + 1, sizeof *t->refs);
        if (*out != OB_OK) return 0;
        i = t->count++;
    }
    t->ptr[i] = p;
    t->refs[i] = 1;
    intern_map_put(t, i);
    return i;
}

static void intern_release(intern_table *t, uint32_t i)
{
    if (i && --t->refs[i] == 0) t->unused++;
}

/* Frees the unused indices for reuse once they outnumber the used ones. */
static void intern_trim(intern_table *t)
{
    uint32_t used = t->count ? t->count - 1 - t->free_count - t->unused : 0;
    if (t->unused < 32 || t->unused < used) return;
    if (ob_array_reserve((void **)&t->free_list, &t->free_cap, t->free_count + t->unused,
                         sizeof *t->free_list) != OB_OK)
        return; /* tried again at the next update */
    for (uint32_t i = 1; i < t->count; i++) {
        if (t->ptr[i] && t->refs[i] == 0) {
            t->ptr[i] = NULL;
            t->free_list[t->free_count++] = i;
        }
    }
    t->unused = 0;
    /* Without memory for a new map the old one stays: probing skips the
     * freed indices (their pointer no longer matches). */
    (void)intern_map_rebuild(t, t->map_cap);
}

static void intern_release_all(intern_table *t)
{
    ob_free(t->ptr);
    ob_free(t->refs);
    ob_free(t->free_list);
    ob_free(t->map);
    memset(t, 0, sizeof *t);
}

struct ob_scene {
    ob_node *root;
    uint32_t next_id;
    uint32_t node_count;
    bool in_update;
    bool order_dirty;

    ob_node **by_id;
    uint32_t by_id_count, by_id_cap, by_id_holes;
    ob_node **order;
    uint32_t order_count, order_cap;
    /* The nodes by hierarchy level (depth), pre-order within a level:
     * level d is by_level[level_start[d] .. level_start[d + 1]). Rebuilt
     * with order; a level's transforms only read the level above. */
    ob_node **by_level;
    uint32_t by_level_cap;
    uint32_t *level_start;
    uint32_t level_count, level_start_cap;
    ob_node **renderables;
    uint32_t renderable_count, renderable_cap;
    ob_render_proxy *proxies;   /* parallel to renderables */
    ob_render_bound *bounds;    /* parallel to renderables */
    uint32_t proxy_cap, bound_cap;
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

/* Returned for empty snapshots so callers never get NULL. */
static ob_node *const empty_snapshot[1] = {NULL};

static void set_result(ob_result *out, ob_result r)
{
    if (out) *out = r;
}

/* ------------------------------------------------------------ bookkeeping */

static ob_node *node_alloc(ob_scene *s, const char *name, ob_result *out_result)
{
    if (!name) name = "";
    size_t len = strlen(name);
    if (s->next_id == UINT32_MAX) {
        OB_LOG_E(SCENE_LOG, "cannot create entity '%s': node ids exhausted", name);
        set_result(out_result, OB_ERR_LIMIT);
        return NULL;
    }
    ob_node *n = ob_calloc(1, sizeof *n + len + 1);
    if (!n) {
        OB_LOG_E(SCENE_LOG, "cannot create entity '%s': out of host memory", name);
        set_result(out_result, OB_ERR_OUT_OF_HOST_MEMORY);
        return NULL;
    }
    memcpy(n->name, name, len + 1);
    n->scene = s;
    ob_dquat_identity(n->rotation);
    n->scale[0] = n->scale[1] = n->scale[2] = 1.0;
    ob_daffine_identity(&n->world);
    ob_dquat_identity(n->world_rotation);
    set_result(out_result, OB_OK);
    return n;
}

static void node_free(ob_node *n)
{
    intern_release(&n->scene->materials, n->material_index);
    intern_release(&n->scene->geometries, n->geometry_index);
    for (uint32_t i = 0; i < n->controller_count; i++) {
        if (n->controllers[i].release) n->controllers[i].release(n->controllers[i].user);
    }
    ob_free(n->controllers);
    ob_free(n);
}

static void by_id_compact(ob_scene *s)
{
    if (!s->by_id_holes) return;
    uint32_t w = 0;
    for (uint32_t r = 0; r < s->by_id_count; r++) {
        ob_node *n = s->by_id[r];
        if (!n) continue;
        n->by_id_index = w;
        s->by_id[w++] = n;
    }
    s->by_id_count = w;
    s->by_id_holes = 0;
}

/* Registers a fresh node in by_id (ids ascend, so appending keeps it sorted). */
static ob_result by_id_append(ob_scene *s, ob_node *n)
{
    /* Destroy leaves holes; reclaim them before they dominate the array. */
    if (s->by_id_holes > 64 && s->by_id_holes >= s->by_id_count / 2) by_id_compact(s);
    ob_result r = ob_array_reserve((void **)&s->by_id, &s->by_id_cap, s->by_id_count + 1,
                                   sizeof *s->by_id);
    if (r != OB_OK) {
        OB_LOG_E(SCENE_LOG, "cannot create entity '%s': %s", n->name, ob_result_text(r));
        return r;
    }
    n->id = s->next_id++;
    n->by_id_index = s->by_id_count;
    s->by_id[s->by_id_count++] = n;
    s->node_count++;
    return OB_OK;
}

static void link_child(ob_node *parent, ob_node *n)
{
    n->parent = parent;
    n->next_sibling = NULL;
    n->prev_sibling = parent->last_child;
    if (parent->last_child) parent->last_child->next_sibling = n;
    else parent->first_child = n;
    parent->last_child = n;
}

static void unlink_child(ob_node *n)
{
    ob_node *p = n->parent;
    if (!p) return;
    if (n->prev_sibling) n->prev_sibling->next_sibling = n->next_sibling;
    else p->first_child = n->next_sibling;
    if (n->next_sibling) n->next_sibling->prev_sibling = n->prev_sibling;
    else p->last_child = n->prev_sibling;
    n->parent = n->prev_sibling = n->next_sibling = NULL;
}

/* Next node in pre-order after n, staying inside the subtree of top. */
static ob_node *preorder_next(const ob_node *n, const ob_node *top)
{
    if (n->first_child) return n->first_child;
    while (n != top && !n->next_sibling) n = n->parent;
    return n == top ? NULL : n->next_sibling;
}

/* ------------------------------------------------------------------ scene */

ob_scene *ob_scene_create(ob_result *out_result)
{
    ob_scene *s = ob_calloc(1, sizeof *s);
    if (!s) {
        OB_LOG_E(SCENE_LOG, "cannot create scene: out of host memory");
        set_result(out_result, OB_ERR_OUT_OF_HOST_MEMORY);
        return NULL;
    }
    s->next_id = 1;
    s->order_dirty = true;
    ob_result r;
    ob_node *root = node_alloc(s, "root", &r);
    if (!root) goto fail_free_scene;
    r = by_id_append(s, root);
    if (r != OB_OK) goto fail_free_root;
    s->root = root;
    set_result(out_result, OB_OK);
    return s;

fail_free_root:
    node_free(root);
fail_free_scene:
    ob_free(s->by_id);
    ob_free(s);
    set_result(out_result, r);
    return NULL;
}

void ob_scene_destroy(ob_scene *s)
{
    if (!s) return;
    for (uint32_t i = 0; i < s->by_id_count; i++) {
        if (s->by_id[i]) node_free(s->by_id[i]);
    }
    ob_free(s->by_id);
    ob_free(s->order);
    ob_free(s->by_level);
    ob_free(s->level_start);
    ob_free(s->renderables);
    ob_aligned_free(s->proxies);
    ob_free(s->bounds);
    ob_free(s->lights);
    ob_free(s->soa_x);
    ob_free(s->soa_y);
    ob_free(s->soa_z);
    ob_free(s->soa_radius);
    ob_free(s->soa_flags);
    ob_free(s->soa_material);
    ob_free(s->soa_geometry);
    ob_free(s->soa_node_id);
    ob_free(s->soa_node);
    intern_release_all(&s->materials);
    intern_release_all(&s->geometries);
    ob_free(s);
}

ob_node *ob_scene_root(ob_scene *s) { return s->root; }

uint32_t ob_scene_node_count(const ob_scene *s) { return s->node_count; }

ob_node *ob_scene_find(const ob_scene *s, const char *name)
{
    if (!name) return NULL;
    for (uint32_t i = 0; i < s->by_id_count; i++) {
        ob_node *n = s->by_id[i];
        if (n && strcmp(n->name, name) == 0) return n;
    }
    return NULL;
}

ob_node *const *ob_scene_renderables(const ob_scene *s, uint32_t *out_count)
{
    *out_count = s->renderable_count;
    return s->renderables ? s->renderables : empty_snapshot;
}

const ob_render_proxy *ob_scene_render_proxies(const ob_scene *s, uint32_t *out_count)
{
    static const ob_render_proxy none[1];
    *out_count = s->renderable_count;
    return s->proxies ? s->proxies : none;
}

void ob_scene_render_soa(const ob_scene *s, ob_render_soa *out)
{
    static const double none_d[1];
    static const float none_f[1];
    static const uint8_t none_b[1];
    static const uint32_t none_u[1];
    static ob_node *const none_n[1];
    bool any = s->soa_x != NULL;
    *out = (ob_render_soa){
        .count = s->renderable_count,
        .x = any ? s->soa_x : none_d, .y = any ? s->soa_y : none_d, .z = any ? s->soa_z : none_d,
        .radius = any ? s->soa_radius : none_f, .flags = any ? s->soa_flags : none_b,
        .material = any ? s->soa_material : none_u, .geometry = any ? s->soa_geometry : none_u,
        .node_id = any ? s->soa_node_id : none_u, .node = any ? s->soa_node : none_n,
    };
}

struct ob_material *ob_scene_material(const ob_scene *s, uint32_t index)
{
    return index && index < s->materials.count && s->materials.refs[index] ? s->materials.ptr[index]
                                                                       : NULL;
}
struct ob_geometry *ob_scene_geometry(const ob_scene *s, uint32_t index)
{
    return index && index < s->geometries.count && s->geometries.refs[index]
               ? s->geometries.ptr[index] : NULL;
}
uint32_t ob_scene_material_count(const ob_scene *s) { return OB_MAX(s->materials.count, 1u); }
uint32_t ob_scene_geometry_count(const ob_scene *s) { return OB_MAX(s->geometries.count, 1u); }

const ob_render_bound *ob_scene_render_bounds(const ob_scene *s, uint32_t *out_count)
{
    static const ob_render_bound none[1];
    *out_count = s->renderable_count;
    return s->bounds ? s->bounds : none;
}

ob_node *const *ob_scene_lights(const ob_scene *s, uint32_t *out_count)
{
    *out_count = s->light_count;
    return s->lights ? s->lights : empty_snapshot;
}

/* ------------------------------------------------------------------ nodes */

static bool refuse_in_update(const ob_scene *s, const char *what, const ob_node *n)
{
    if (!s->in_update) return false;
    OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): %s is not allowed inside a controller "
             "(during ob_scene_update)", n ? n->name : "", n ? n->id : 0u, what);
    return true;
}

ob_node *ob_node_create(ob_scene *s, ob_node *parent, const char *name, ob_result *out_result)
{
    if (!parent) parent = s->root;
    if (parent->scene != s) {
        OB_LOG_E(SCENE_LOG, "cannot create entity '%s': parent '%s' (id %u) belongs to "
                 "another scene", name ? name : "", parent->name, parent->id);
        set_result(out_result, OB_ERR_INVALID_ARGUMENT);
        return NULL;
    }
    if (refuse_in_update(s, "creating a child", parent)) {
        set_result(out_result, OB_ERR_WRONG_STATE);
        return NULL;
    }
    ob_node *n = node_alloc(s, name, out_result);
    if (!n) return NULL;
    ob_result r = by_id_append(s, n);
    if (r != OB_OK) {
        node_free(n);
        set_result(out_result, r);
        return NULL;
    }
    link_child(parent, n);
    s->order_dirty = true;
    return n;
}

/* Drops the marked (dying) nodes from a snapshot array. */
static uint32_t filter_dying(ob_node **items, uint32_t count)
{
    uint32_t w = 0;
    for (uint32_t r = 0; r < count; r++)
        if (!items[r]->dying) items[w++] = items[r];
    return w;
}

/* filter_dying for the renderables and their proxies together. */
static void filter_dying_renderables(ob_scene *s)
{
    uint32_t w = 0;
    for (uint32_t r = 0; r < s->renderable_count; r++) {
        ob_node *n = s->renderables[r];
        if (n->dying) continue;
        s->renderables[w] = n;
        s->proxies[w] = s->proxies[r];
        s->bounds[w] = s->bounds[r];
        s->soa_x[w] = s->soa_x[r];
        s->soa_y[w] = s->soa_y[r];
        s->soa_z[w] = s->soa_z[r];
        s->soa_radius[w] = s->soa_radius[r];
        s->soa_flags[w] = s->soa_flags[r];
        s->soa_material[w] = s->soa_material[r];
        s->soa_geometry[w] = s->soa_geometry[r];
        s->soa_node_id[w] = s->soa_node_id[r];
        s->soa_node[w] = s->soa_node[r];
        n->proxy_index = w++;
    }
    s->renderable_count = w;
}

static bool floats_finite(const float *v, int count)
{
    for (int i = 0; i < count; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

static void proxy_set_renderable(ob_scene *s, const ob_node *n)
{
    uint32_t i = n->proxy_index;
    ob_render_proxy *p = &s->proxies[i];
    p->material = n->has_renderable ? n->renderable.material : NULL;
    p->geometry = n->has_renderable ? n->renderable.geometry : NULL;
    s->bounds[i].local_radius = n->has_renderable ? n->renderable.local_radius : 0.0f;
    s->soa_material[i] = n->material_index;
    s->soa_geometry[i] = n->geometry_index;
    s->soa_flags[i] = s->bounds[i].radius == 0.0f && s->bounds[i].local_radius > 0.0f
                          ? OB_RENDER_ZERO_SCALE : 0u;
}

_Static_assert(sizeof(ob_render_proxy) == 2 * OB_CACHE_LINE, "a proxy is two cache lines");

static void proxy_fill(ob_scene *s, ob_node *n)
{
    ob_render_proxy *p = &s->proxies[n->proxy_index];
    ob_render_bound *b = &s->bounds[n->proxy_index];
    float w[16] = {0}, nm[16];
    for (int c = 0; c < 3; c++) {
        for (int r = 0; r < 3; r++) w[c * 4 + r] = (float)n->world.m[c * 3 + r];
        p->world_t[c] = n->world.t[c];
        b->center[c] = n->world_center[c];
    }
    w[15] = 1.0f;
    ob_mat4_normal_cofactor(w, nm);
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) {
            p->linear[c * 3 + r] = w[c * 4 + r];
            p->normal[c * 3 + r] = nm[c * 4 + r];
        }
    p->finite = floats_finite(p->linear, 9) && floats_finite(p->normal, 9);
    b->radius = n->world_radius;
    p->node = n;
    p->node_id = n->id;
    uint32_t i = n->proxy_index;
    s->soa_x[i] = b->center[0];
    s->soa_y[i] = b->center[1];
    s->soa_z[i] = b->center[2];
    s->soa_radius[i] = b->radius;
    s->soa_node_id[i] = n->id;
    s->soa_node[i] = n;
    proxy_set_renderable(s, n);
}

void ob_node_destroy(ob_scene *s, ob_node *n)
{
    if (!n) return;
    if (n->scene != s) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): destroy through another scene; ignored",
                 n->name, n->id);
        return;
    }
    if (n == s->root) {
        OB_LOG_E(SCENE_LOG, "the root of a scene cannot be destroyed (destroy the scene); ignored");
        return;
    }
    if (refuse_in_update(s, "destroy", n)) return;

    /* Mark first so the snapshot can be filtered while the nodes still exist. */
    bool in_snapshot = false;
    for (ob_node *m = n; m; m = preorder_next(m, n)) {
        m->dying = true;
        in_snapshot |= m->renderable_now || (m->has_light && m->world_valid);
    }
    if (in_snapshot) {
        filter_dying_renderables(s);
        s->light_count = filter_dying(s->lights, s->light_count);
    }

    unlink_child(n);
    /* Free leaves first, climbing back up: no stack, each edge walked twice. */
    ob_node *cur = n;
    for (;;) {
        while (cur->first_child) cur = cur->first_child;
        ob_node *up = cur->parent;
        bool last = cur == n;
        if (!last) unlink_child(cur);
        s->by_id[cur->by_id_index] = NULL;
        s->by_id_holes++;
        s->node_count--;
        node_free(cur);
        if (last) break;
        cur = up;
    }
    s->order_dirty = true;
}

ob_result ob_node_set_parent(ob_scene *s, ob_node *n, ob_node *parent)
{
    if (!parent) parent = s->root;
    if (n->scene != s || parent->scene != s) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): cannot be parented to '%s' (id %u) of "
                 "another scene", n->name, n->id, parent->name, parent->id);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (n == s->root) {
        OB_LOG_E(SCENE_LOG, "the root of a scene cannot be given a parent");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (refuse_in_update(s, "set_parent", n)) return OB_ERR_WRONG_STATE;
    for (const ob_node *p = parent; p; p = p->parent) {
        if (p == n) {
            OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): parenting it to '%s' (id %u) would make "
                     "a cycle; refused", n->name, n->id, parent->name, parent->id);
            return OB_ERR_INVALID_ARGUMENT;
        }
    }
    if (n->parent == parent) return OB_OK;
    unlink_child(n);
    link_child(parent, n);
    s->order_dirty = true;
    return OB_OK;
}

uint32_t ob_node_id(const ob_node *n) { return n->id; }
const char *ob_node_name(const ob_node *n) { return n->name; }
ob_node *ob_node_get_parent(const ob_node *n) { return n->parent; }
ob_node *ob_node_first_child(const ob_node *n) { return n->first_child; }
ob_node *ob_node_next_sibling(const ob_node *n) { return n->next_sibling; }

void ob_node_set_position(ob_node *n, const double p[3]) { ob_dvec3_copy(p, n->position); }

void ob_node_set_rotation(ob_node *n, const float q[4])
{
    for (int i = 0; i < 4; i++) n->rotation[i] = q[i];
}

void ob_node_set_rotation_d(ob_node *n, const double q[4])
{
    for (int i = 0; i < 4; i++) n->rotation[i] = q[i];
}

void ob_node_set_scale(ob_node *n, const float s[3])
{
    for (int i = 0; i < 3; i++) n->scale[i] = s[i];
}

void ob_node_set_euler(ob_node *n, float pitch, float yaw, float roll)
{
    static const double x_axis[3] = {1, 0, 0}, y_axis[3] = {0, 1, 0}, z_axis[3] = {0, 0, 1};
    double qy[4], qx[4], qz[4];
    ob_dquat_from_axis_angle(y_axis, yaw, qy);
    ob_dquat_from_axis_angle(x_axis, pitch, qx);
    ob_dquat_from_axis_angle(z_axis, roll, qz);
    ob_dquat_mul(qy, qx, n->rotation);
    ob_dquat_mul(n->rotation, qz, n->rotation);
}

void ob_node_get_position(const ob_node *n, double dest[3]) { ob_dvec3_copy(n->position, dest); }

void ob_node_get_rotation(const ob_node *n, double dest[4])
{
    for (int i = 0; i < 4; i++) dest[i] = n->rotation[i];
}

void ob_node_get_scale(const ob_node *n, float dest[3])
{
    for (int i = 0; i < 3; i++) dest[i] = (float)n->scale[i];
}

void ob_node_set_hidden(ob_node *n, bool hidden) { n->hidden = hidden; }
bool ob_node_is_hidden(const ob_node *n) { return n->hidden; }

ob_result ob_node_set_renderable(ob_node *n, const ob_renderable *r)
{
    ob_scene *s = n->scene;
    if (!r) {
        n->has_renderable = false;
        memset(&n->renderable, 0, sizeof n->renderable);
        intern_release(&s->materials, n->material_index);
        intern_release(&s->geometries, n->geometry_index);
        n->material_index = n->geometry_index = 0;
        if (n->renderable_now) proxy_set_renderable(n->scene, n);
        return OB_OK;
    }
    if (!floats_finite(r->local_center, 3) || !isfinite(r->local_radius) || r->local_radius < 0.0f) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): renderable bounds must be finite with a "
                 "radius >= 0 (got radius %g); refused", n->name, n->id, (double)r->local_radius);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_result res;
    uint32_t mi = intern_acquire(&s->materials, r->material, &res), gi = 0;
    if (res == OB_OK) {
        gi = intern_acquire(&s->geometries, r->geometry, &res);
        if (res != OB_OK) intern_release(&s->materials, mi);
    }
    if (res != OB_OK) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): renderable not set: %s", n->name, n->id,
                 ob_result_text(res));
        return res;
    }
    intern_release(&s->materials, n->material_index);
    intern_release(&s->geometries, n->geometry_index);
    n->material_index = mi;
    n->geometry_index = gi;
    n->renderable = *r;
    n->has_renderable = true;
    if (n->renderable_now) proxy_set_renderable(n->scene, n);
    return OB_OK;
}

const ob_renderable *ob_node_get_renderable(const ob_node *n)
{
    return n->has_renderable ? &n->renderable : NULL;
}

void ob_node_set_user(ob_node *n, void *user) { n->user = user; }
void *ob_node_get_user(const ob_node *n) { return n->user; }

/* --------------------------------------------------------------- transform */

typedef enum local_status { LOCAL_OK, LOCAL_NON_FINITE, LOCAL_ZERO_ROTATION } local_status;

/* Local transform of n, with its unit rotation. */
static local_status node_local(const ob_node *n, ob_daffine *dest, double unit_q[4])
{
    if (!ob_dvec3_is_finite(n->position) || !ob_dvec3_is_finite(n->scale) ||
        !isfinite(n->rotation[0]) || !isfinite(n->rotation[1]) || !isfinite(n->rotation[2]) ||
        !isfinite(n->rotation[3]))
        return LOCAL_NON_FINITE;
    if (!ob_dquat_normalize(n->rotation, unit_q)) return LOCAL_ZERO_ROTATION;
    ob_daffine_from_trs(n->position, unit_q, n->scale, dest);
    return ob_daffine_is_finite(dest) ? LOCAL_OK : LOCAL_NON_FINITE;
}

static void report_fault(ob_node *n, local_status st)
{
    if (n->fault_reported) return;
    n->fault_reported = true;
    if (st == LOCAL_ZERO_ROTATION)
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): zero-length rotation quaternion; not rendered",
                 n->name, n->id);
    else
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): non-finite transform; not rendered",
                 n->name, n->id);
}

static void update_node(ob_node *n)
{
    const ob_node *p = n->parent;
    bool parent_valid = !p || p->world_valid;
    n->effective_hidden = n->hidden || (p && p->effective_hidden);

    ob_daffine local, world;
    double q[4];
    local_status st = node_local(n, &local, q);
    if (st == LOCAL_OK && parent_valid) {
        if (p) ob_daffine_mul(&p->world, &local, &world);
        else world = local;
        if (!ob_daffine_is_finite(&world)) st = LOCAL_NON_FINITE; /* overflow through the chain */
    }
    if (st != LOCAL_OK) {
        n->world_valid = false;
        report_fault(n, st);
        return;
    }
    if (!parent_valid) {
        /* Its own transform is fine; the ancestor at fault has been named. */
        n->world_valid = false;
        return;
    }
    n->world = world;
    n->world_valid = true;
    if (p) {
        ob_dquat_mul(p->world_rotation, q, n->world_rotation);
        ob_dquat_normalize(n->world_rotation, n->world_rotation);
    } else {
        memcpy(n->world_rotation, q, sizeof q);
    }
    if (n->has_renderable) {
        double c[3] = {n->renderable.local_center[0], n->renderable.local_center[1],
                       n->renderable.local_center[2]};
        ob_daffine_transform_point(&n->world, c, n->world_center);
        n->world_radius = (float)(n->renderable.local_radius * ob_daffine_max_scale(&n->world));
    }
    if (n->fault_reported) {
        n->fault_reported = false;
        OB_LOG_I(SCENE_LOG, "entity '%s' (id %u): transform finite again; rendered", n->name, n->id);
    }
}

/* order in pre-order, and by_level: a counting sort of it by depth. */
static void order_rebuild(ob_scene *s)
{
    uint32_t count = 0, levels = 0;
    for (ob_node *n = s->root; n; n = preorder_next(n, s->root)) {
        n->depth = n->parent ? n->parent->depth + 1 : 0;
        if (n->depth + 1 > levels) levels = n->depth + 1;
        s->order[count++] = n;
    }
    s->order_count = count;
    s->level_count = levels;
    uint32_t *start = s->level_start;
    memset(start, 0, sizeof *start * (levels + 1));
    for (uint32_t i = 0; i < count; i++) start[s->order[i]->depth + 1]++;
    for (uint32_t d = 0; d < levels; d++) start[d + 1] += start[d];
    /* start[d] is now where level d begins; fill, then shift back. */
    for (uint32_t i = 0; i < count; i++) s->by_level[start[s->order[i]->depth]++] = s->order[i];
    for (uint32_t d = levels; d > 0; d--) start[d] = start[d - 1];
    start[0] = 0;
    s->order_dirty = false;
}

static ob_result update_reserve(ob_scene *s)
{
    uint32_t need = s->node_count;
    ob_result r = ob_array_reserve((void **)&s->order, &s->order_cap, need, sizeof *s->order);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->by_level, &s->by_level_cap, need, sizeof *s->by_level);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->level_start, &s->level_start_cap, need + 1,
                             sizeof *s->level_start);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->renderables, &s->renderable_cap, need,
                             sizeof *s->renderables);
    if (r == OB_OK)
        r = ob_array_reserve_aligned((void **)&s->proxies, &s->proxy_cap, need,
                                     sizeof *s->proxies, OB_CACHE_LINE);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->bounds, &s->bound_cap, need, sizeof *s->bounds);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->lights, &s->light_cap, need, sizeof *s->lights);
    if (r == OB_OK && s->soa_cap < need) {
        /* All the arrays grow together to the same capacity. */
        uint32_t cap = OB_MAX(need, 2 * s->soa_cap);
        void *x = ob_realloc(s->soa_x, sizeof(double) * cap);
        if (x) s->soa_x = x;
        void *y = x ? ob_realloc(s->soa_y, sizeof(double) * cap) : NULL;
        if (y) s->soa_y = y;
        void *z = y ? ob_realloc(s->soa_z, sizeof(double) * cap) : NULL;
        if (z) s->soa_z = z;
        void *rad = z ? ob_realloc(s->soa_radius, sizeof(float) * cap) : NULL;
        if (rad) s->soa_radius = rad;
        void *fl = rad ? ob_realloc(s->soa_flags, cap) : NULL;
        if (fl) s->soa_flags = fl;
        void *m = fl ? ob_realloc(s->soa_material, sizeof(uint32_t) * cap) : NULL;
        if (m) s->soa_material = m;
        void *g = m ? ob_realloc(s->soa_geometry, sizeof(uint32_t) * cap) : NULL;
        if (g) s->soa_geometry = g;
        void *id = g ? ob_realloc(s->soa_node_id, sizeof(uint32_t) * cap) : NULL;
        if (id) s->soa_node_id = id;
        void *nodes = id ? ob_realloc(s->soa_node, sizeof(ob_node *) * cap) : NULL;
        if (nodes) {
            s->soa_node = nodes;
            s->soa_cap = cap;
        } else {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
        }
    }
    if (r != OB_OK)
        OB_LOG_E(SCENE_LOG, "scene update of %u nodes: %s; scene left as it was", need,
                 ob_result_text(r));
    return r;
}

/* Nodes per index of the update's parallel loops: a few microseconds of
 * work each, so a loop's hand-out costs little beside it. */
#define UPDATE_GRAIN 1024u

typedef struct update_ctx {
    ob_scene *s;
    double dt;
    ob_node **nodes;            /* the current loop's nodes */
    uint32_t count;
    uint32_t *counts;           /* snapshot: per chunk, renderables then lights */
} update_ctx;

static uint32_t chunks_of(uint32_t count) { return (count + UPDATE_GRAIN - 1) / UPDATE_GRAIN; }

static void run_parallel_controllers(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    uint32_t end = OB_MIN(c->count, (chunk + 1) * UPDATE_GRAIN);
    for (uint32_t i = chunk * UPDATE_GRAIN; i < end; i++) {
        ob_node *n = c->nodes[i];
        for (uint32_t k = 0; k < n->parallel_controllers; k++)
            n->controllers[k].fn(n, c->dt, n->controllers[k].user);
    }
}

static void run_update_nodes(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    uint32_t end = OB_MIN(c->count, (chunk + 1) * UPDATE_GRAIN);
    for (uint32_t i = chunk * UPDATE_GRAIN; i < end; i++) update_node(c->nodes[i]);
}

/* Snapshot, first pass: which nodes are in it, counted per chunk of by_id. */
static void run_snapshot_count(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    uint32_t end = OB_MIN(c->s->by_id_count, (chunk + 1) * UPDATE_GRAIN), rc = 0, lc = 0;
    for (uint32_t i = chunk * UPDATE_GRAIN; i < end; i++) {
        ob_node *n = c->s->by_id[i];
        bool visible = n->world_valid && !n->effective_hidden;
        n->renderable_now = visible && n->has_renderable;
        rc += n->renderable_now;
        lc += visible && n->has_light;
    }
    c->counts[2 * chunk] = rc;
    c->counts[2 * chunk + 1] = lc;
}

/* Second pass: each chunk fills its part, from the prefix sums in counts. */
static void run_snapshot_fill(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    ob_scene *s = c->s;
    uint32_t end = OB_MIN(s->by_id_count, (chunk + 1) * UPDATE_GRAIN);
    uint32_t rc = c->counts[2 * chunk], lc = c->counts[2 * chunk + 1];
    for (uint32_t i = chunk * UPDATE_GRAIN; i < end; i++) {
        ob_node *n = s->by_id[i];
        if (n->renderable_now) {
            n->proxy_index = rc;
            proxy_fill(s, n);
            s->renderables[rc++] = n;
        }
        if (n->world_valid && !n->effective_hidden && n->has_light) s->lights[lc++] = n;
    }
}

ob_result ob_scene_update(ob_scene *s, double dt) { return ob_scene_update_parallel(s, dt, NULL); }

ob_result ob_scene_update_parallel(ob_scene *s, double dt, const ob_parallel *par)
{
    if (!isfinite(dt) || dt < 0.0) {
        OB_LOG_E(SCENE_LOG, "scene update: dt must be finite and >= 0 (got %g)", dt);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (s->in_update) {
        OB_LOG_E(SCENE_LOG, "ob_scene_update called from a controller; refused");
        return OB_ERR_WRONG_STATE;
    }
    ob_result r = update_reserve(s);
    if (r != OB_OK) return r;
    intern_trim(&s->materials);
    intern_trim(&s->geometries);
    by_id_compact(s);
    if (s->order_dirty) order_rebuild(s);
    uint32_t chunks = chunks_of(s->by_id_count);
    uint32_t *counts = ob_malloc(sizeof *counts * 2 * (chunks + 1));
    if (!counts) {
        OB_LOG_E(SCENE_LOG, "scene update of %u nodes: out of host memory; scene left as it was",
                 s->node_count);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }

    s->in_update = true;
    update_ctx c = {.s = s, .dt = dt, .nodes = s->order, .count = s->order_count};
    ob_parallel_run(par, chunks_of(c.count), run_parallel_controllers, &c);
    for (uint32_t i = 0; i < s->order_count; i++) {
        ob_node *n = s->order[i];
        /* Re-read the array each time: a controller may add controllers. */
        uint32_t count = n->controller_count;
        for (uint32_t k = n->parallel_controllers; k < count; k++)
            n->controllers[k].fn(n, dt, n->controllers[k].user);
    }
    for (uint32_t d = 0; d < s->level_count; d++) {
        c.nodes = s->by_level + s->level_start[d];
        c.count = s->level_start[d + 1] - s->level_start[d];
        ob_parallel_run(par, chunks_of(c.count), run_update_nodes, &c);
    }
    s->in_update = false;

    c.counts = counts;
    ob_parallel_run(par, chunks, run_snapshot_count, &c);
    uint32_t rc = 0, lc = 0;
    for (uint32_t k = 0; k < chunks; k++) {
        uint32_t nr = counts[2 * k], nl = counts[2 * k + 1];
        counts[2 * k] = rc;
        counts[2 * k + 1] = lc;
        rc += nr;
        lc += nl;
    }
    ob_parallel_run(par, chunks, run_snapshot_fill, &c);
    s->renderable_count = rc;
    s->light_count = lc;
    ob_free(counts);
    return OB_OK;
}

/* ----------------------------------------------------------- world queries */

void ob_node_world_position(const ob_node *n, double dest[3]) { ob_dvec3_copy(n->world.t, dest); }

void ob_node_world_affine(const ob_node *n, ob_daffine *dest) { *dest = n->world; }

void ob_node_world_relative(const ob_node *n, const double origin[3], float dest[16])
{
    ob_daffine_to_relative(&n->world, origin, dest);
}

/* Orthonormal world axes (columns X, Y, Z) in double. */
static void node_axes(const ob_node *n, double axes[9])
{
    const double *m = n->world.m;
    double *right = &axes[0], *up = &axes[3], *back = &axes[6];
    if (ob_dvec3_normalize(&m[6], back)) {
        double proj[3];
        ob_dvec3_scale(back, ob_dvec3_dot(&m[3], back), proj);
        ob_dvec3_sub(&m[3], proj, up);
        if (ob_dvec3_normalize(up, up)) {
            ob_dvec3_cross(up, back, right);
            return;
        }
    }
    /* Zero (or collapsed) scale: the directions live on in the rotations. */
    ob_dquat_to_mat3(n->world_rotation, axes);
}

void ob_node_world_axes(const ob_node *n, float right[3], float up[3], float forward[3])
{
    double axes[9];
    node_axes(n, axes);
    for (int i = 0; i < 3; i++) {
        if (right) right[i] = (float)axes[i];
        if (up) up[i] = (float)axes[3 + i];
        if (forward) forward[i] = (float)-axes[6 + i];
    }
}

void ob_node_view_relative(const ob_node *n, const double origin[3], float dest[16])
{
    double axes[9];
    node_axes(n, axes);
    ob_math_view_relative(axes, n->world.t, origin, dest);
}

void ob_node_world_sphere(const ob_node *n, double center[3], float *radius)
{
    if (!n->has_renderable) {
        ob_dvec3_set(0.0, 0.0, 0.0, center);
        *radius = 0.0f;
        return;
    }
    ob_dvec3_copy(n->world_center, center);
    *radius = n->world_radius;
}

bool ob_node_is_renderable(const ob_node *n) { return n->renderable_now; }
bool ob_node_transform_is_valid(const ob_node *n) { return n->world_valid; }

ob_result ob_node_look_at(ob_node *n, const double target[3], const double up[3])
{
    /* Walk the ancestors now rather than trust the last update: look_at is
     * often called right after moving or creating the node. */
    ob_daffine world, local;
    double parent_q[4], q[4];
    ob_dquat_identity(parent_q);
    if (node_local(n, &world, q) != LOCAL_OK) goto fail_log_non_finite;
    for (const ob_node *p = n->parent; p; p = p->parent) {
        if (node_local(p, &local, q) != LOCAL_OK) goto fail_log_non_finite;
        ob_daffine_mul(&local, &world, &world);
        ob_dquat_mul(q, parent_q, parent_q);
    }
    double dir[3];
    ob_dvec3_sub(target, world.t, dir);
    if (!ob_dvec3_is_finite(up) || !ob_dvec3_is_finite(dir) || ob_dvec3_length(dir) == 0.0) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): look_at target is at the entity's position "
                 "or not finite; rotation unchanged", n->name, n->id);
        return OB_ERR_INVALID_ARGUMENT;
    }
    double basis[9], world_q[4], inv_parent[4];
    ob_look_status st = ob_math_look_rotation(dir, up, basis);
    if (st & OB_LOOK_UP_REPLACED)
        OB_LOG_W(SCENE_LOG, "entity '%s' (id %u): look_at up vector (%g, %g, %g) is parallel to "
                 "the view direction or zero; using another up axis", n->name, n->id,
                 up[0], up[1], up[2]);
    ob_dmat3_to_dquat(basis, world_q);
    /* local = parent_world^-1 * world (conjugate of a unit quaternion). */
    inv_parent[0] = -parent_q[0];
    inv_parent[1] = -parent_q[1];
    inv_parent[2] = -parent_q[2];
    inv_parent[3] = parent_q[3];
    ob_dquat_mul(inv_parent, world_q, n->rotation);
    ob_dquat_normalize(n->rotation, n->rotation);
    return OB_OK;

fail_log_non_finite:
    OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): look_at on a non-finite transform (its own or an "
             "ancestor's); rotation unchanged", n->name, n->id);
    return OB_ERR_NON_FINITE;
}

/* ------------------------------------------------------------ controllers */

ob_result ob_node_add_controller(ob_node *n, const ob_controller_desc *d)
{
    if (!d || !d->fn) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): controller without a function; refused",
                 n->name, n->id);
        if (d && d->release) d->release(d->user);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_result r = ob_array_reserve((void **)&n->controllers, &n->controller_cap,
                                   n->controller_count + 1, sizeof *n->controllers);
    if (r != OB_OK) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): cannot add a controller: %s", n->name, n->id,
                 ob_result_text(r));
        if (d->release) d->release(d->user);
        return r;
    }
    if (d->parallel && n->parallel_controllers == n->controller_count)
        n->parallel_controllers++;
    n->controllers[n->controller_count++] =
        (ob_controller_slot){.fn = d->fn, .user = d->user, .release = d->release};
    return OB_OK;
}

/* ------------------------------------------------------ cameras and lights */

ob_result ob_node_set_camera(ob_node *n, const ob_camera_desc *d)
{
    if (!d) {
        n->has_camera = false;
        return OB_OK;
    }
    ob_camera_desc c = *d;
    if (c.fovy == 0.0f) c.fovy = (float)(OB_PI / 3.0);
    if (c.znear == 0.0f) c.znear = 0.1f;
    if (!(c.fovy > 0.0f && c.fovy < (float)OB_PI) || !(c.znear > 0.0f) || !isfinite(c.znear) ||
        !(c.aspect >= 0.0f) || !isfinite(c.aspect)) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): camera needs fovy in (0, pi), znear > 0 and "
                 "aspect >= 0, all finite (got %g, %g, %g); refused", n->name, n->id,
                 (double)d->fovy, (double)d->znear, (double)d->aspect);
        return OB_ERR_INVALID_ARGUMENT;
    }
    n->camera = c;
    n->has_camera = true;
    return OB_OK;
}

const ob_camera_desc *ob_node_get_camera(const ob_node *n) { return n->has_camera ? &n->camera : NULL; }

ob_result ob_node_set_light(ob_node *n, const ob_light_desc *d)
{
    if (!d) {
        n->has_light = false;
        return OB_OK;
    }
    ob_light_desc l = *d;
    bool ok = (l.type == OB_LIGHT_DIRECTIONAL || l.type == OB_LIGHT_POINT) &&
              floats_finite(l.color, 3) && isfinite(l.intensity) && isfinite(l.range) &&
              l.color[0] >= 0.0f && l.color[1] >= 0.0f && l.color[2] >= 0.0f &&
              l.intensity >= 0.0f && l.range >= 0.0f;
    if (!ok) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): light needs a known type and finite, "
                 "non-negative colour, intensity and range; refused", n->name, n->id);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (l.color[0] == 0.0f && l.color[1] == 0.0f && l.color[2] == 0.0f)
        l.color[0] = l.color[1] = l.color[2] = 1.0f;
    n->light = l;
    n->has_light = true;
    return OB_OK;
}

const ob_light_desc *ob_node_get_light(const ob_node *n) { return n->has_light ? &n->light : NULL; }
