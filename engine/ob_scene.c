/* ob_scene.c — the scene graph (see ob_scene.h): nodes, their API, the
 * interning of materials and geometries. The per-frame update and its
 * snapshot are in ob_scene_update.c; the storage both share (a node's
 * update data in dense slot arrays of the scene) is described in
 * ob_scene_internal.h.
 */
#include "ob_controllers_internal.h"

#include <string.h>

/* ------------------------------------------------------------- interning */

/* Distinct pointers (materials, geometries) numbered densely, so that the
 * snapshot can carry a small index per renderable and culling can keep a
 * table per index instead of asking an interface per entity. Index 0 is
 * "none". An index is counted by the renderables that use it; at zero it
 * stays mapped (the same pointer set again revives it) until enough are
 * unused, then they are freed for reuse and the map is rebuilt. Render
 * thread only (set_renderable, destroy, update's start). The table itself is
 * in ob_scene_internal.h. */

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
        t->ptr[0] = NULL; /* read through ob_render_soa's tables */
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

void ob_scene_intern_trim(ob_scene *s)
{
    intern_trim(&s->materials);
    intern_trim(&s->geometries);
}

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
    n->by_id_index = NO_SLOT;
    set_result(out_result, OB_OK);
    return n;
}

/* Frees n and what its slot owns (its controllers); the slot itself is
 * left to the caller. */
static void node_free(ob_node *n)
{
    if (n->by_id_index != NO_SLOT) {
        ob_scene *s = n->scene;
        node_controllers *ctl = &s->ctl[n->by_id_index];
        for (uint32_t i = 0; i < ctl->count; i++) {
            ob_controller_slot *c = &ctl->slots[i];
            if (c->release) c->release(controller_user(c));
        }
        if (ctl->pooled) {
            s->ctl_loose += ctl->count; /* unused until the next repack */
        } else {
            s->ctl_loose -= ctl->count;
            ob_free(ctl->slots);
        }
        *ctl = (node_controllers){0};
    }
    ob_free(n);
}

void ob_scene_compact(ob_scene *s)
{
    if (!s->by_id_holes) return;
    uint32_t w = 0;
    for (uint32_t r = 0; r < s->by_id_count; r++) {
        ob_node *n = s->by_id[r];
        if (!n) continue;
        if (w != r) {
            n->by_id_index = w;
            s->by_id[w] = n;
            s->xf[w] = s->xf[r];
            s->state[w] = s->state[r];
            s->slot_id[w] = s->slot_id[r];
            s->draw[w] = s->draw[r];
            s->ctl[w] = s->ctl[r];
            if (s->state[w] & NODE_MOTION) s->motion[w] = s->motion[r];
            if (!(s->xf[w].flags & XF_WORLD_ROT_LOCAL)) s->world_rot[w] = s->world_rot[r];
        }
        w++;
    }
    s->by_id_count = w;
    s->by_id_holes = 0;
    s->order_dirty = true; /* the orders name slots */
}

/* Registers a fresh node in by_id and gives it its slot (ids ascend, so
 * appending keeps by_id sorted). */
static ob_result by_id_append(ob_scene *s, ob_node *n)
{
    /* Destroy leaves holes; reclaim them before they dominate the array. */
    if (s->by_id_holes > 64 && s->by_id_holes >= s->by_id_count / 2) ob_scene_compact(s);
    uint32_t need = s->by_id_count + 1;
    ob_result r = ob_array_reserve((void **)&s->by_id, &s->by_id_cap, need, sizeof *s->by_id);
    if (r == OB_OK)
        r = ob_array_reserve_aligned((void **)&s->xf, &s->xf_cap, need, sizeof *s->xf,
                                     OB_CACHE_LINE);
    if (r == OB_OK) r = ob_array_reserve((void **)&s->state, &s->state_cap, need, sizeof *s->state);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->slot_id, &s->slot_id_cap, need, sizeof *s->slot_id);
    if (r == OB_OK) r = ob_array_reserve((void **)&s->draw, &s->draw_cap, need, sizeof *s->draw);
    if (r == OB_OK) r = ob_array_reserve((void **)&s->ctl, &s->ctl_cap, need, sizeof *s->ctl);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->motion, &s->motion_cap, need, sizeof *s->motion);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->world_rot, &s->world_rot_cap, need,
                             sizeof *s->world_rot);
    if (r != OB_OK) {
        OB_LOG_E(SCENE_LOG, "cannot create entity '%s': %s", n->name, ob_result_text(r));
        return r;
    }
    uint32_t slot = s->by_id_count++;
    n->id = s->next_id++;
    n->by_id_index = slot;
    s->by_id[slot] = n;
    node_xf *x = &s->xf[slot];
    memset(x, 0, sizeof *x);
    ob_dquat_identity(x->rotation);
    x->scale[0] = x->scale[1] = x->scale[2] = 1.0f;
    ob_daffine_identity(&x->world);
    x->flags = XF_WORLD_ROT_LOCAL;
    s->state[slot] = NODE_DIRTY;
    s->slot_id[slot] = n->id;
    s->draw[slot] = (node_draw){0};
    s->ctl[slot] = (node_controllers){0};
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

ob_node *ob_scene_preorder_next(const ob_node *n, const ob_node *top)
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
    s->snapshot_dirty = true;
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
    ob_aligned_free(s->xf);
    ob_free(s->state);
    ob_free(s->slot_id);
    ob_free(s->draw);
    ob_free(s->ctl);
    ob_free(s->motion);
    ob_free(s->world_rot);
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
    ob_aligned_free(s->xf);
    ob_free(s->state);
    ob_free(s->slot_id);
    ob_free(s->draw);
    ob_free(s->ctl);
    ob_free(s->motion);
    ob_free(s->world_rot);
    ob_free(s->ctl_pool);
    ob_free(s->retired);
    ob_free(s->order);
    ob_free(s->by_level);
    ob_free(s->level_start);
    ob_free(s->chunk_counts);
    ob_free(s->renderables);
    ob_aligned_free(s->proxies);
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
    static void *const none_p[1];
    bool any = s->soa_x != NULL;
    /* Every index the snapshot uses exists, so its table does (index 0's
     * entry is NULL). */
    void *const *mats = s->materials.ptr ? s->materials.ptr : none_p;
    void *const *geos = s->geometries.ptr ? s->geometries.ptr : none_p;
    *out = (ob_render_soa){
        .count = s->renderable_count,
        .x = any ? s->soa_x : none_d, .y = any ? s->soa_y : none_d, .z = any ? s->soa_z : none_d,
        .radius = any ? s->soa_radius : none_f, .flags = any ? s->soa_flags : none_b,
        .material = any ? s->soa_material : none_u, .geometry = any ? s->soa_geometry : none_u,
        .node_id = any ? s->soa_node_id : none_u, .node = any ? s->soa_node : none_n,
        .materials = (struct ob_material *const *)mats,
        .geometries = (struct ob_geometry *const *)geos,
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

/* Whether n may be destroyed through s (logged when not). */
static bool destroy_allowed(ob_scene *s, const ob_node *n)
{
    if (n->scene != s || n->by_id_index >= s->by_id_count || s->by_id[n->by_id_index] != n) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): destroy through another scene; ignored",
                 n->name, n->id);
        return false;
    }
    if (n == s->root) {
        OB_LOG_E(SCENE_LOG, "the root of a scene cannot be destroyed (destroy the scene); ignored");
        return false;
    }
    return true;
}

/* Frees the subtree of top, already unlinked from its parent: leaves first,
 * climbing back up, so no stack and each edge walked twice. */
static void free_subtree(ob_scene *s, ob_node *top)
{
    ob_node *cur = top;
    for (;;) {
        while (cur->first_child) cur = cur->first_child;
        ob_node *up = cur->parent;
        bool last = cur == top;
        if (!last) unlink_child(cur);
        uint32_t slot = cur->by_id_index;
        intern_release(&s->materials, s->draw[slot].material_index);
        intern_release(&s->geometries, s->draw[slot].geometry_index);
        if (s->state[slot] & NODE_SERIAL) s->serial_nodes--;
        s->by_id[slot] = NULL;
        s->by_id_holes++;
        s->node_count--;
        node_free(cur);
        if (last) break;
        cur = up;
    }
}

ob_result ob_node_destroy(ob_node *n)
{
    return n ? ob_nodes_destroy(n->scene, &n, 1) : OB_OK;
}

ob_result ob_nodes_destroy(ob_scene *s, ob_node *const *nodes, uint32_t count)
{
    if (count == 0) return OB_OK;
    if (!s || !nodes) {
        OB_LOG_E(SCENE_LOG, "ob_nodes_destroy: no scene or no node list");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (s->in_update) {
        const ob_node *n = nodes[0];
        refuse_in_update(s, "destroy", n);
        return OB_ERR_WRONG_STATE;
    }
    ob_result result = OB_OK;
    /* Mark every subtree first, so that the snapshot loses them all in one
     * pass while the nodes still exist, from the first of them in it on:
     * the work is the subtrees' size plus the snapshot's tail past them,
     * whatever the count (unloading a scene, newest entities first, pays
     * for the entities only). */
    uint32_t first_proxy = UINT32_MAX;
    bool lights = false;
    for (uint32_t i = 0; i < count; i++) {
        ob_node *n = nodes[i];
        if (!n || n->dying) continue;
        if (!destroy_allowed(s, n)) {
            result = OB_ERR_INVALID_ARGUMENT;
            continue;
        }
        for (ob_node *m = n; m; m = ob_scene_preorder_next(m, n)) {
            m->dying = true;
            uint8_t st = s->state[m->by_id_index];
            if ((st & NODE_IN_RENDERABLES) && s->xf[m->by_id_index].proxy_index < first_proxy)
                first_proxy = s->xf[m->by_id_index].proxy_index;
            lights |= (st & NODE_IN_LIGHTS) != 0;
        }
    }
    if (first_proxy != UINT32_MAX || lights)
        ob_scene_snapshot_drop_dying(s, first_proxy == UINT32_MAX ? s->renderable_count
                                                                  : first_proxy, lights);
    /* The tops (listed nodes under no other dying node) leave the tree,
     * chained through their now unused sibling links; a node listed twice
     * is out of the tree (no parent) the second time. */
    ob_node *tops = NULL;
    for (uint32_t i = 0; i < count; i++) {
        ob_node *n = nodes[i];
        if (!n || !n->dying || !n->parent || n->parent->dying) continue;
        unlink_child(n);
        n->next_sibling = tops;
        tops = n;
    }
    while (tops) {
        ob_node *next = tops->next_sibling;
        tops->next_sibling = NULL;
        free_subtree(s, tops);
        tops = next;
    }
    s->order_dirty = true;
    return result;
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
    node_touch(n);
    s->order_dirty = true;
    return OB_OK;
}

uint32_t ob_node_id(const ob_node *n) { return n->id; }
const char *ob_node_name(const ob_node *n) { return n->name; }
ob_node *ob_node_get_parent(const ob_node *n) { return n->parent; }
ob_node *ob_node_first_child(const ob_node *n) { return n->first_child; }
ob_node *ob_node_next_sibling(const ob_node *n) { return n->next_sibling; }

void ob_node_set_position(ob_node *n, const double p[3])
{
    ob_dvec3_copy(p, node_xf_of(n)->position);
    node_touch(n);
}

/* A rotation set from outside is normalized by the update. */
static double *rotation_for_set(ob_node *n)
{
    node_xf *x = node_xf_of(n);
    node_world_rotation_keep(n->scene, n->by_id_index);
    x->flags &= ~(uint32_t)XF_ROTATION_UNIT;
    node_touch(n);
    return x->rotation;
}

void ob_node_set_rotation(ob_node *n, const float q[4])
{
    double *rotation = rotation_for_set(n);
    for (int i = 0; i < 4; i++) rotation[i] = q[i];
}

void ob_node_set_rotation_d(ob_node *n, const double q[4])
{
    memcpy(rotation_for_set(n), q, sizeof node_xf_of(n)->rotation);
}

void ob_node_set_scale(ob_node *n, const float s[3])
{
    float *scale = node_xf_of(n)->scale;
    for (int i = 0; i < 3; i++) scale[i] = s[i];
    node_touch(n);
}

void ob_node_set_euler(ob_node *n, float pitch, float yaw, float roll)
{
    static const double x_axis[3] = {1, 0, 0}, y_axis[3] = {0, 1, 0}, z_axis[3] = {0, 0, 1};
    double qy[4], qx[4], qz[4], *rotation = rotation_for_set(n);
    ob_dquat_from_axis_angle(y_axis, yaw, qy);
    ob_dquat_from_axis_angle(x_axis, pitch, qx);
    ob_dquat_from_axis_angle(z_axis, roll, qz);
    ob_dquat_mul(qy, qx, rotation);
    ob_dquat_mul(rotation, qz, rotation);
}

void ob_node_get_position(const ob_node *n, double dest[3])
{
    ob_dvec3_copy(node_xf_of(n)->position, dest);
}

/* Copied whole (not element by element), so that a caller reading the
 * copy as pairs finds them in whole stores. */
void ob_node_get_rotation(const ob_node *n, double dest[4])
{
    memcpy(dest, node_xf_of(n)->rotation, sizeof node_xf_of(n)->rotation);
}

void ob_node_get_scale(const ob_node *n, float dest[3])
{
    const float *scale = node_xf_of(n)->scale;
    for (int i = 0; i < 3; i++) dest[i] = scale[i];
}

void ob_node_set_hidden(ob_node *n, bool hidden)
{
    node_xf *x = node_xf_of(n);
    x->flags = hidden ? x->flags | XF_HIDDEN : x->flags & ~(uint32_t)XF_HIDDEN;
    node_touch(n);
}

bool ob_node_is_hidden(const ob_node *n) { return (node_xf_of(n)->flags & XF_HIDDEN) != 0; }

static bool floats_finite(const float *v, int count)
{
    for (int i = 0; i < count; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

ob_result ob_node_set_renderable(ob_node *n, const ob_renderable *r)
{
    ob_scene *s = n->scene;
    uint32_t slot = n->by_id_index;
    node_xf *x = &s->xf[slot];
    node_draw *d = &s->draw[slot];
    if (!r) {
        x->flags &= ~(uint32_t)XF_HAS_RENDERABLE;
        memset(&n->renderable, 0, sizeof n->renderable);
        memset(x->local_center, 0, sizeof x->local_center);
        x->local_radius = 0.0f;
        intern_release(&s->materials, d->material_index);
        intern_release(&s->geometries, d->geometry_index);
        *d = (node_draw){0};
        if (s->state[slot] & NODE_IN_RENDERABLES) ob_scene_proxy_set_renderable(s, slot);
        node_touch(n);
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
    intern_release(&s->materials, d->material_index);
    intern_release(&s->geometries, d->geometry_index);
    *d = (node_draw){.material = r->material, .geometry = r->geometry,
                     .material_index = mi, .geometry_index = gi};
    n->renderable = *r;
    memcpy(x->local_center, r->local_center, sizeof x->local_center);
    x->local_radius = r->local_radius;
    x->flags |= XF_HAS_RENDERABLE;
    if (s->state[slot] & NODE_IN_RENDERABLES) ob_scene_proxy_set_renderable(s, slot);
    node_touch(n);
    return OB_OK;
}

const ob_renderable *ob_node_get_renderable(const ob_node *n)
{
    return node_xf_of(n)->flags & XF_HAS_RENDERABLE ? &n->renderable : NULL;
}

void ob_node_set_user(ob_node *n, void *user) { n->user = user; }
void *ob_node_get_user(const ob_node *n) { return n->user; }

/* ----------------------------------------------------------- world queries */

void ob_node_world_position(const ob_node *n, double dest[3])
{
    ob_dvec3_copy(node_xf_of(n)->world.t, dest);
}

void ob_node_world_affine(const ob_node *n, ob_daffine *dest) { *dest = node_xf_of(n)->world; }

void ob_node_world_relative(const ob_node *n, const double origin[3], float dest[16])
{
    ob_daffine_to_relative(&node_xf_of(n)->world, origin, dest);
}

/* Orthonormal world axes (columns X, Y, Z) in double. */
static void node_axes(const ob_node *n, double axes[9])
{
    const node_xf *x = node_xf_of(n);
    const double *m = x->world.m;
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
    double q[4];
    node_world_rotation(n->scene, n->by_id_index, q);
    ob_dquat_to_mat3(q, axes);
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
    ob_math_view_relative(axes, node_xf_of(n)->world.t, origin, dest);
}

void ob_node_world_sphere(const ob_node *n, double center[3], float *radius)
{
    const node_xf *x = node_xf_of(n);
    if (!(x->flags & XF_HAS_RENDERABLE)) {
        ob_dvec3_set(0.0, 0.0, 0.0, center);
        *radius = 0.0f;
        return;
    }
    node_world_bound(x, center, radius);
}

bool ob_node_is_renderable(const ob_node *n)
{
    return (n->scene->state[n->by_id_index] & NODE_IN_RENDERABLES) != 0;
}

bool ob_node_transform_is_valid(const ob_node *n)
{
    return (node_xf_of(n)->flags & XF_WORLD_VALID) != 0;
}

ob_result ob_node_look_at(ob_node *n, const double target[3], const double up[3])
{
    /* Walk the ancestors now rather than trust the last update: look_at is
     * often called right after moving or creating the node. */
    ob_daffine world, local;
    double parent_q[4], q[4];
    ob_dquat_identity(parent_q);
    if (ob_scene_xf_local(node_xf_of(n), &world, q) != LOCAL_OK) goto fail_log_non_finite;
    for (const ob_node *p = n->parent; p; p = p->parent) {
        if (ob_scene_xf_local(node_xf_of(p), &local, q) != LOCAL_OK) goto fail_log_non_finite;
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
    double *rotation = rotation_for_set(n);
    ob_dquat_mul(inv_parent, world_q, rotation);
    ob_dquat_normalize(rotation, rotation);
    return OB_OK;

fail_log_non_finite:
    OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): look_at on a non-finite transform (its own or an "
             "ancestor's); rotation unchanged", n->name, n->id);
    return OB_ERR_NON_FINITE;
}

/* ------------------------------------------------------------ controllers */

/* Appends a controller to the node's list (see controller_add). */
static ob_result controller_append(ob_node *n, const ob_controller_desc *d, const void *state,
                                   size_t size)
{
    void *release_arg = state ? (void *)state : d->user;
    ob_scene *s = n->scene;
    node_controllers *ctl = &s->ctl[n->by_id_index];
    if (ctl->count == ctl->cap) {
        /* Slots are large (their inline state): grow one at a time from one.
         * During an update the running controller may be one of this node's
         * (a serial one): its old block is freed only after the update. */
        uint32_t cap = ctl->cap ? 2 * ctl->cap : 1;
        bool retire = s->in_update && !ctl->pooled && ctl->slots;
        ob_result r = retire ? ob_array_reserve((void **)&s->retired, &s->retired_cap,
                                                s->retired_count + 1, sizeof *s->retired)
                             : OB_OK;
        ob_controller_slot *grown = r == OB_OK ? ob_malloc(sizeof *grown * cap) : NULL;
        if (!grown) {
            OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): cannot add a controller: %s", n->name,
                     n->id, ob_result_text(OB_ERR_OUT_OF_HOST_MEMORY));
            if (d->release) d->release(release_arg);
            return OB_ERR_OUT_OF_HOST_MEMORY;
        }
        if (ctl->count) memcpy(grown, ctl->slots, sizeof *grown * ctl->count);
        if (ctl->pooled) s->ctl_loose += 2 * ctl->count; /* unused in the pool, copied out */
        else if (retire) s->retired[s->retired_count++] = ctl->slots;
        else ob_free(ctl->slots);
        ctl->slots = grown;
        ctl->cap = cap;
        ctl->pooled = false;
    }
    s->ctl_loose++;
    if (d->parallel && ctl->parallel == ctl->count) ctl->parallel++;
    ob_controller_slot *c = &ctl->slots[ctl->count++];
    c->fn = d->fn;
    c->user = state ? NULL : d->user;
    c->release = d->release;
    c->inline_state = state != NULL;
    if (state) memcpy(c->state, state, size);
    uint8_t *st = &s->state[n->by_id_index];
    if (ctl->parallel) *st |= NODE_PARALLEL;
    if (ctl->count > ctl->parallel && !(*st & NODE_SERIAL)) {
        *st |= NODE_SERIAL;
        s->serial_nodes++;
    }
    return OB_OK;
}

/* A built-in kind kept in scene->motion (NODE_ORBIT or NODE_SPIN): its
 * function, and where its state lies in m (size in *out_size). */
static ob_controller_fn motion_fn(uint8_t kind)
{
    return kind == NODE_ORBIT ? ob_orbit_controller_step : ob_rotation_controller_step;
}

static void *motion_state(node_motion *m, uint8_t kind, size_t *out_size)
{
    *out_size = kind == NODE_ORBIT ? sizeof m->orbit : sizeof m->spin;
    return kind == NODE_ORBIT ? (void *)&m->orbit : (void *)&m->spin;
}

/* The node's built-in controllers in scene->motion into its list, as
 * ob_node_add_controller_state's: the list must keep the order added. */
static ob_result motion_unpack(ob_node *n)
{
    static const uint8_t kinds[] = {NODE_ORBIT, NODE_SPIN};
    ob_scene *s = n->scene;
    uint32_t slot = n->by_id_index;
    for (size_t k = 0; k < OB_ARRAY_COUNT(kinds); k++) {
        if (!(s->state[slot] & kinds[k])) continue;
        size_t size;
        const void *state = motion_state(&s->motion[slot], kinds[k], &size);
        ob_result r = controller_append(
            n, &(ob_controller_desc){.fn = motion_fn(kinds[k]), .parallel = true}, state, size);
        if (r != OB_OK) return r;
        s->state[slot] &= (uint8_t)~kinds[k];
    }
    return OB_OK;
}

static ob_result controller_add(ob_node *n, const ob_controller_desc *d, const void *state,
                                size_t size)
{
    ob_result r = motion_unpack(n);
    if (r != OB_OK) {
        if (d->release) d->release(state ? (void *)state : d->user);
        return r;
    }
    return controller_append(n, d, state, size);
}

ob_result ob_scene_motion_add(ob_node *n, uint8_t kind, const void *state, size_t size)
{
    ob_scene *s = n->scene;
    uint32_t slot = n->by_id_index;
    if (!s->ctl[slot].count && !(s->state[slot] & kind)) {
        size_t kept;
        memcpy(motion_state(&s->motion[slot], kind, &kept), state, size);
        s->state[slot] |= kind;
        return OB_OK;
    }
    return controller_add(n, &(ob_controller_desc){.fn = motion_fn(kind), .parallel = true},
                          state, size);
}

ob_result ob_node_add_controller(ob_node *n, const ob_controller_desc *d)
{
    if (!d || !d->fn) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): controller without a function; refused",
                 n->name, n->id);
        if (d && d->release) d->release(d->user);
        return OB_ERR_INVALID_ARGUMENT;
    }
    return controller_add(n, d, NULL, 0);
}

ob_result ob_node_add_controller_state(ob_node *n, const ob_controller_desc *d, const void *state,
                                       size_t size)
{
    if (!d || !d->fn || !state || size > OB_CONTROLLER_STATE_SIZE) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): controller without a function or a state, "
                 "or with a state over %u bytes (%zu); refused", n->name, n->id,
                 OB_CONTROLLER_STATE_SIZE, size);
        if (d && d->release && state) d->release((void *)state);
        return OB_ERR_INVALID_ARGUMENT;
    }
    return controller_add(n, d, state, size);
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
    node_xf *x = node_xf_of(n);
    if (!d) {
        x->flags &= ~(uint32_t)XF_HAS_LIGHT;
        node_touch(n);
        return OB_OK;
    }
    ob_light_desc l = *d;
    bool ok = (l.type == OB_LIGHT_DIRECTIONAL || l.type == OB_LIGHT_POINT ||
               l.type == OB_LIGHT_SPOT) &&
              floats_finite(l.color, 3) && isfinite(l.intensity) && isfinite(l.range) &&
              l.color[0] >= 0.0f && l.color[1] >= 0.0f && l.color[2] >= 0.0f &&
              l.intensity >= 0.0f && l.range >= 0.0f;
    if (!ok) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): light needs a known type and finite, "
                 "non-negative colour, intensity and range; refused", n->name, n->id);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (l.type == OB_LIGHT_SPOT) {
        if (l.outer_angle == 0.0f) l.outer_angle = (float)(OB_PI / 4.0);
        /* The comparisons are false for NaN, so non-finite angles fail too. */
        if (!(l.inner_angle >= 0.0f && l.inner_angle <= l.outer_angle &&
              l.outer_angle < (float)(OB_PI / 2.0))) {
            OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): spot light needs finite angles with "
                     "0 <= inner_angle <= outer_angle < pi/2 (got %g, %g radians); refused",
                     n->name, n->id, (double)d->inner_angle, (double)d->outer_angle);
            return OB_ERR_INVALID_ARGUMENT;
        }
    } else {
        l.inner_angle = l.outer_angle = 0.0f;
    }
    if (l.color[0] == 0.0f && l.color[1] == 0.0f && l.color[2] == 0.0f)
        l.color[0] = l.color[1] = l.color[2] = 1.0f;
    n->light = l;
    x->flags |= XF_HAS_LIGHT;
    node_touch(n);
    return OB_OK;
}

const ob_light_desc *ob_node_get_light(const ob_node *n)
{
    return node_xf_of(n)->flags & XF_HAS_LIGHT ? &n->light : NULL;
}
