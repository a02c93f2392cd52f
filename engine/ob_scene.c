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
    void *user;

    bool hidden, has_renderable, has_camera, has_light;
    bool world_valid;        /* this node and every ancestor finite at the last update */
    bool effective_hidden;   /* hidden itself or through an ancestor */
    bool renderable_now;     /* in the current snapshot's sense */
    bool fault_reported;     /* an error line about this node's own transform is out */
    bool dying;              /* marked while its subtree is being destroyed */
    uint32_t proxy_index;    /* in the snapshot's proxies while renderable_now */
    char name[];
};

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
    ob_node **renderables;
    uint32_t renderable_count, renderable_cap;
    ob_render_proxy *proxies;   /* parallel to renderables */
    ob_render_bound *bounds;    /* parallel to renderables */
    uint32_t proxy_cap, bound_cap;
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
    ob_free(s->renderables);
    ob_aligned_free(s->proxies);
    ob_free(s->bounds);
    ob_free(s->lights);
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
    ob_render_proxy *p = &s->proxies[n->proxy_index];
    p->material = n->has_renderable ? n->renderable.material : NULL;
    p->geometry = n->has_renderable ? n->renderable.geometry : NULL;
    s->bounds[n->proxy_index].local_radius = n->has_renderable ? n->renderable.local_radius : 0.0f;
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
    if (!r) {
        n->has_renderable = false;
        memset(&n->renderable, 0, sizeof n->renderable);
        if (n->renderable_now) proxy_set_renderable(n->scene, n);
        return OB_OK;
    }
    if (!floats_finite(r->local_center, 3) || !isfinite(r->local_radius) || r->local_radius < 0.0f) {
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): renderable bounds must be finite with a "
                 "radius >= 0 (got radius %g); refused", n->name, n->id, (double)r->local_radius);
        return OB_ERR_INVALID_ARGUMENT;
    }
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

static void order_rebuild(ob_scene *s)
{
    uint32_t count = 0;
    for (ob_node *n = s->root; n; n = preorder_next(n, s->root)) s->order[count++] = n;
    s->order_count = count;
    s->order_dirty = false;
}

static ob_result update_reserve(ob_scene *s)
{
    uint32_t need = s->node_count;
    ob_result r = ob_array_reserve((void **)&s->order, &s->order_cap, need, sizeof *s->order);
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
    if (r != OB_OK)
        OB_LOG_E(SCENE_LOG, "scene update of %u nodes: %s; scene left as it was", need,
                 ob_result_text(r));
    return r;
}

ob_result ob_scene_update(ob_scene *s, double dt)
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
    by_id_compact(s);
    if (s->order_dirty) order_rebuild(s);

    s->in_update = true;
    for (uint32_t i = 0; i < s->order_count; i++) {
        ob_node *n = s->order[i];
        /* Re-read the array each time: a controller may add controllers. */
        uint32_t count = n->controller_count;
        for (uint32_t c = 0; c < count; c++) n->controllers[c].fn(n, dt, n->controllers[c].user);
    }
    for (uint32_t i = 0; i < s->order_count; i++) update_node(s->order[i]);
    s->in_update = false;

    uint32_t rc = 0, lc = 0;
    for (uint32_t i = 0; i < s->by_id_count; i++) {
        ob_node *n = s->by_id[i];
        bool visible = n->world_valid && !n->effective_hidden;
        n->renderable_now = visible && n->has_renderable;
        if (n->renderable_now) {
            n->proxy_index = rc;
            proxy_fill(s, n);
            s->renderables[rc++] = n;
        }
        if (visible && n->has_light) s->lights[lc++] = n;
    }
    s->renderable_count = rc;
    s->light_count = lc;
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
