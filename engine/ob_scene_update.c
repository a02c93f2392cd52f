/* ob_scene_update.c — ob_scene_update: controllers, world transforms, bounds
 * and the frame's snapshot (see ob_scene.h; the storage is described in
 * ob_scene_internal.h).
 *
 * One loop per hierarchy level, parents first, over the level's nodes by
 * slot. A node is evaluated (world transform, world rotation, bound, and
 * its proxy when it stays in the snapshot) when its local transform,
 * visibility or renderable changed (NODE_DIRTY) or its parent was evaluated
 * in this update (NODE_CHANGED); any other node costs two bytes read. When
 * no node has a controller that is not parallel-safe, the same loop first
 * runs each node's controllers; otherwise the parallel-safe ones run in a
 * loop of their own, then the others on the caller, before the levels.
 * Only when a node entered or left the snapshot is the whole snapshot
 * rebuilt: a count over one byte per node on the caller, then one loop that
 * fills it in id (= slot) order.
 *
 * Every loop writes per node (or per chunk) and the caller combines chunks
 * in index order, so the result is the same for any thread count.
 */
#include "ob_controllers_internal.h"

#include <float.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* The level loop takes its nodes a few at a time (their controllers, then
 * the simple ones' evaluation, in pairs), so that a node's data is still
 * in the core's first cache when its evaluation reads what its controllers
 * wrote: at 50k moving objects 16 at a time cost 10-15% more. The others
 * gather into an eval_batch, run once it could fill up. */
#define LEVEL_STEP 4u

typedef struct update_ctx {
    ob_scene *s;
    double dt;
    const ob_parallel *par;
    uint32_t grain;             /* nodes per loop index */
    const level_item *items;    /* the current loop's nodes */
    uint32_t count;
    bool controllers;           /* the level loop runs the parallel-safe controllers */
    bool lanes4;                /* steps of four usual nodes in AVX2's four lanes: their
                                   built-in controllers, then their evaluation */
    uint32_t *counts;           /* per chunk: membership changed; the snapshot's offsets */
} update_ctx;

static uint32_t chunks_of(uint32_t count, uint32_t grain)
{
    return (uint32_t)(((uint64_t)count + grain - 1) / grain);
}

/* Where chunk k of count items ends, grain per chunk. */
static uint32_t chunk_end(uint32_t count, uint32_t k, uint32_t grain)
{
    return (uint32_t)OB_MIN((uint64_t)count, ((uint64_t)k + 1) * grain);
}

/* A loop over `items` nodes, c->grain per index. It goes through par only
 * when each thread gets two UPDATE_GRAINs' worth (a hand-out costs more
 * than a few nodes' work), else it runs on the caller; the result is the
 * same either way. Handed out, the nodes are cut into eight or more
 * indices a thread (whole steps, UPDATE_GRAIN_MIN or more each): indices
 * are taken first come, first served, so a thread that wakes late or a
 * slow index then holds the others up by an eighth of a share, not by
 * half. A caller's ob_parallel.grain is kept as it is. loop_plan sets
 * c->grain and says where the loop runs. */
static const ob_parallel *loop_plan(update_ctx *c, uint32_t items)
{
    uint32_t fixed = c->par && c->par->grain ? c->par->grain : 0;
    const ob_parallel *par =
        ob_parallel_worth(c->par, items, fixed ? fixed : UPDATE_GRAIN) ? c->par : NULL;
    c->grain = fixed ? fixed : UPDATE_GRAIN;
    if (par && !fixed) {
        uint32_t share = items / (8u * par->threads);
        share = (share + LEVEL_STEP - 1) / LEVEL_STEP * LEVEL_STEP;
        c->grain = OB_MIN(UPDATE_GRAIN, OB_MAX(UPDATE_GRAIN_MIN, share));
    }
    return par;
}

static void update_loop(update_ctx *c, uint32_t items, ob_task_fn fn)
{
    const ob_parallel *par = loop_plan(c, items);
    ob_parallel_run(par, chunks_of(items, c->grain), fn, c);
}

/* ------------------------------------------------------------- transforms */

local_status ob_scene_xf_local(const node_xf *x, ob_daffine *dest, double unit_q[4])
{
    /* x - x is 0 for a finite x and NaN otherwise; the rotation is tested
     * by its normalization, the usual case of which needs it finite. */
    const double *t = x->position;
    const float *sc = x->scale;
    double bad_t = (t[0] - t[0]) + (t[1] - t[1]) + (t[2] - t[2]);
    float bad_s = (sc[0] - sc[0]) + (sc[1] - sc[1]) + (sc[2] - sc[2]);
    if (bad_t != 0.0 || bad_s != 0.0f) return LOCAL_NON_FINITE;
    if (x->flags & XF_ROTATION_UNIT) {
        memcpy(unit_q, x->rotation, sizeof x->rotation);
    } else if (!ob_dquat_normalize(x->rotation, unit_q)) {
        const double *r = x->rotation;
        bool finite = isfinite(r[0]) && isfinite(r[1]) && isfinite(r[2]) && isfinite(r[3]);
        return finite ? LOCAL_ZERO_ROTATION : LOCAL_NON_FINITE;
    }
    const double scale[3] = {sc[0], sc[1], sc[2]};
    /* Finite: a unit rotation's entries are at most 1 in magnitude and a
     * scale at most FLT_MAX, so no product overflows. */
    ob_daffine_from_trs(t, unit_q, scale, dest);
    return LOCAL_OK;
}

static void report_fault(const ob_node *n, local_status st)
{
    if (st == LOCAL_ZERO_ROTATION)
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): zero-length rotation quaternion; not rendered",
                 n->name, n->id);
    else
        OB_LOG_E(SCENE_LOG, "entity '%s' (id %u): non-finite transform; not rendered",
                 n->name, n->id);
}

/* Whether world and world rotation q are exactly the identity. */
static bool is_identity(const node_xf *x, const double q[4])
{
    const double *m = x->world.m, *t = x->world.t;
    return m[0] == 1.0 && m[1] == 0.0 && m[2] == 0.0 && m[3] == 0.0 && m[4] == 1.0 &&
           m[5] == 0.0 && m[6] == 0.0 && m[7] == 0.0 && m[8] == 1.0 && t[0] == 0.0 &&
           t[1] == 0.0 && t[2] == 0.0 && q[0] == 0.0 && q[1] == 0.0 && q[2] == 0.0 &&
           q[3] == 1.0;
}

/* ---------------------------------------------------------------- snapshot */

_Static_assert(sizeof(ob_render_proxy) == OB_CACHE_LINE, "a proxy is one cache line");

static uint8_t zero_scale_flag(const node_xf *x, float world_radius)
{
    return world_radius == 0.0f && x->local_radius > 0.0f ? OB_RENDER_ZERO_SCALE : 0u;
}

/* What of proxy i follows the node's world, in two steps so that a batch's
 * values are stored well before they are read back (a load that spans
 * several recent smaller stores waits for them to retire). */
static void proxy_write_world(ob_scene *s, const node_xf *x, uint32_t i, const double center[3],
                              float radius)
{
    ob_render_proxy *p = &s->proxies[i];
    for (int k = 0; k < 9; k++) p->linear[k] = (float)x->world.m[k];
    for (int k = 0; k < 3; k++) p->world_t[k] = x->world.t[k];
    s->soa_x[i] = center[0];
    s->soa_y[i] = center[1];
    s->soa_z[i] = center[2];
    s->soa_radius[i] = radius;
    s->soa_flags[i] = zero_scale_flag(x, radius);
}

/* Whether the float form of a finite double 3x3, linear, is finite; scale
 * its largest column length (as ob_daffine_max_scale gives it). No entry
 * exceeds that in magnitude, so only a scale beyond FLT_MAX (almost never)
 * needs the entries looked at. */
static uint8_t linear_finite(const float linear[9], double scale)
{
    if (scale <= FLT_MAX) return 1;
    uint8_t ok = 1;
    for (int k = 0; k < 9; k++) ok &= fabsf(linear[k]) <= FLT_MAX;
    return ok;
}

/* What proxy i's matrix is, once its values are stored: finite in float,
 * and mirroring (found once per update here, not per instance and view
 * when it is drawn). */
static void proxy_write_finite(ob_scene *s, uint32_t i, double scale)
{
    ob_render_proxy *p = &s->proxies[i];
    p->finite = linear_finite(p->linear, scale);
    p->mirrors = ob_det3_negative(p->linear, 3, 1);
}

void ob_scene_proxy_set_renderable(ob_scene *s, uint32_t slot)
{
    const node_draw *d = &s->draw[slot];
    const node_xf *x = &s->xf[slot];
    uint32_t i = x->proxy_index;
    s->soa_material[i] = d->material_index;
    s->soa_geometry[i] = d->geometry_index;
    double center[3];
    float radius;
    node_world_bound(x, center, &radius);
    s->soa_flags[i] = zero_scale_flag(x, radius);
}

/* The whole of proxy i for the node in slot. */
static void proxy_fill(ob_scene *s, uint32_t slot, uint32_t i)
{
    node_xf *x = &s->xf[slot];
    x->proxy_index = i;
    s->soa_node[i] = s->by_id[slot];
    s->soa_node_id[i] = s->slot_id[slot];
    ob_scene_proxy_set_renderable(s, slot);
    double center[3];
    float radius;
    double scale = node_world_bound(x, center, &radius);
    proxy_write_world(s, x, i, center, radius);
    proxy_write_finite(s, i, scale);
}

void ob_scene_snapshot_drop_dying(ob_scene *s, uint32_t from, bool lights)
{
    uint32_t w = from;
    for (uint32_t r = from; r < s->renderable_count; r++) {
        ob_node *n = s->renderables[r];
        if (n->dying) continue;
        s->renderables[w] = n;
        s->proxies[w] = s->proxies[r];
        s->soa_x[w] = s->soa_x[r];
        s->soa_y[w] = s->soa_y[r];
        s->soa_z[w] = s->soa_z[r];
        s->soa_radius[w] = s->soa_radius[r];
        s->soa_flags[w] = s->soa_flags[r];
        s->soa_material[w] = s->soa_material[r];
        s->soa_geometry[w] = s->soa_geometry[r];
        s->soa_node_id[w] = s->soa_node_id[r];
        s->soa_node[w] = s->soa_node[r];
        s->xf[n->by_id_index].proxy_index = w++;
    }
    s->renderable_count = w;
    if (!lights) return;
    w = 0;
    for (uint32_t r = 0; r < s->light_count; r++)
        if (!s->lights[r]->dying) s->lights[w++] = s->lights[r];
    s->light_count = w;
}

/* Each chunk of slots fills its part, from the offsets in counts. */
static void run_snapshot_fill(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    ob_scene *s = c->s;
    uint32_t end = chunk_end(s->by_id_count, chunk, c->grain);
    uint32_t rc = c->counts[2 * chunk], lc = c->counts[2 * chunk + 1];
    for (uint32_t slot = chunk * c->grain; slot < end; slot++) {
        uint8_t st = s->state[slot];
        if (st & NODE_IN_RENDERABLES) {
            proxy_fill(s, slot, rc);
            s->renderables[rc++] = s->by_id[slot];
        }
        if (st & NODE_IN_LIGHTS) s->lights[lc++] = s->by_id[slot];
    }
}

static void snapshot_rebuild(ob_scene *s, update_ctx *c)
{
    const ob_parallel *par = loop_plan(c, s->by_id_count);
    uint32_t chunks = chunks_of(s->by_id_count, c->grain), rc = 0, lc = 0;
    for (uint32_t k = 0; k < chunks; k++) {
        uint32_t end = chunk_end(s->by_id_count, k, c->grain), nr = 0, nl = 0;
        for (uint32_t slot = k * c->grain; slot < end; slot++) {
            nr += s->state[slot] & NODE_IN_RENDERABLES;
            nl += s->state[slot] & NODE_IN_LIGHTS;
        }
        c->counts[2 * k] = rc;
        c->counts[2 * k + 1] = lc;
        rc += nr / NODE_IN_RENDERABLES;
        lc += nl / NODE_IN_LIGHTS;
    }
    ob_parallel_run(par, chunks, run_snapshot_fill, c);
    s->renderable_count = rc;
    s->light_count = lc;
    s->snapshot_dirty = false;
}

/* ------------------------------------------------------------- evaluation */

/* Nodes are evaluated in batches, stage by stage (local transforms, then
 * worlds, then proxies): a stage's work for one node is independent of the
 * next node's, so the long latencies (square roots, divisions, cache
 * misses) of several nodes overlap instead of queueing one behind another. */
#define EVAL_BATCH 16u

typedef struct eval_batch {
    uint32_t count;
    level_item item[EVAL_BATCH];
    local_status st[EVAL_BATCH];
    bool in_place[EVAL_BATCH];  /* its world and world rotation are its local ones,
                                   the world computed straight into its node_xf */
    bool proxy[EVAL_BATCH];     /* stays in the snapshot: its proxy follows */
    uint32_t proxy_index[EVAL_BATCH];
    double center[EVAL_BATCH][3]; /* world bound of those with proxy[k] */
    float radius[EVAL_BATCH];
    double scale[EVAL_BATCH];   /* the world's largest column length, with the bound */
    double q[EVAL_BATCH][4];    /* unit local rotation, then world rotation */
    ob_daffine world[EVAL_BATCH];
} eval_batch;

/* Evaluates node k of the batch, whose parent (if any) is evaluated
 * already, from its local transform (stage one): validity, visibility,
 * world transform and rotation, bound. Sets b->proxy[k] when it stays in
 * the snapshot. True when it entered or left it. */
static bool node_eval(ob_scene *s, eval_batch *b, uint32_t k)
{
    level_item it = b->item[k];
    local_status st = b->st[k];
    node_xf *x = &s->xf[it.slot];
    const node_xf *p = it.parent == NO_SLOT ? NULL : &s->xf[it.parent];
    uint32_t flags = x->flags & ~(uint32_t)(XF_EFFECTIVE_HIDDEN | XF_IDENTITY);
    if ((flags & XF_HIDDEN) || (p && (p->flags & XF_EFFECTIVE_HIDDEN))) flags |= XF_EFFECTIVE_HIDDEN;
    bool parent_valid = !p || (p->flags & XF_WORLD_VALID);
    /* Under an identity parent (the root, usually) the world is the local
     * transform and the world rotation the local one. */
    bool through = p && !(p->flags & XF_IDENTITY);
    ob_daffine *world = b->in_place[k] ? &x->world : &b->world[k];

    if (st == LOCAL_OK && parent_valid && through) {
        ob_daffine_mul(&p->world, world, world);
        if (!ob_daffine_is_finite(world)) st = LOCAL_NON_FINITE; /* overflow through the chain */
    }
    if (st != LOCAL_OK) {
        flags &= ~(uint32_t)XF_WORLD_VALID;
        if (!(flags & XF_FAULT_REPORTED)) {
            flags |= XF_FAULT_REPORTED;
            report_fault(s->by_id[it.slot], st);
        }
    } else if (!parent_valid) {
        /* Its own transform is fine; the ancestor at fault has been named. */
        flags &= ~(uint32_t)XF_WORLD_VALID;
    } else {
        flags |= XF_WORLD_VALID;
        if (!b->in_place[k]) x->world = *world;
        const double *world_q = b->q[k]; /* from x->rotation as it is */
        if (through) {
            double pq[4], *dest = s->world_rot[it.slot].q;
            node_world_rotation(s, it.parent, pq);
            ob_dquat_mul(pq, b->q[k], dest);
            ob_dquat_normalize(dest, dest);
            world_q = dest;
            flags &= ~(uint32_t)XF_WORLD_ROT_LOCAL;
        } else {
            flags |= XF_WORLD_ROT_LOCAL;
        }
        if ((flags & XF_HAS_CHILDREN) && is_identity(x, world_q)) flags |= XF_IDENTITY;
        if (flags & XF_FAULT_REPORTED) {
            flags &= ~(uint32_t)XF_FAULT_REPORTED;
            const ob_node *n = s->by_id[it.slot];
            OB_LOG_I(SCENE_LOG, "entity '%s' (id %u): transform finite again; rendered", n->name,
                     n->id);
        }
    }
    x->flags = flags;

    bool shown = (flags & XF_WORLD_VALID) && !(flags & XF_EFFECTIVE_HIDDEN);
    uint8_t member = (shown && (flags & XF_HAS_RENDERABLE) ? NODE_IN_RENDERABLES : 0u) |
                     (shown && (flags & XF_HAS_LIGHT) ? NODE_IN_LIGHTS : 0u);
    uint8_t old = s->state[it.slot];
    s->state[it.slot] = (uint8_t)((old & ~(NODE_DIRTY | NODE_IN_RENDERABLES | NODE_IN_LIGHTS)) |
                                  NODE_CHANGED | member);
    b->proxy[k] = (old & member & NODE_IN_RENDERABLES) != 0;
    if (b->proxy[k]) b->scale[k] = node_world_bound(x, b->center[k], &b->radius[k]);
    return ((old ^ member) & (NODE_IN_RENDERABLES | NODE_IN_LIGHTS)) != 0;
}

/* True when some node of the batch entered or left the snapshot. */
static bool eval_batch_run(ob_scene *s, eval_batch *b)
{
    for (uint32_t k = 0; k < b->count; k++) {
        level_item it = b->item[k];
        node_xf *x = &s->xf[it.slot];
        /* Under a valid identity parent (or none) a node that passes the
         * local checks is valid, and nothing is written before they pass. */
        const node_xf *p = it.parent == NO_SLOT ? NULL : &s->xf[it.parent];
        b->in_place[k] = !p || (p->flags & (XF_IDENTITY | XF_WORLD_VALID)) ==
                                   (XF_IDENTITY | XF_WORLD_VALID);
        b->st[k] = ob_scene_xf_local(x, b->in_place[k] ? &x->world : &b->world[k], b->q[k]);
        /* The proxy's line is only written, a stage later: asked for now,
         * it is there by then (3-4 ns an object at 50k). */
        if (s->state[it.slot] & NODE_IN_RENDERABLES)
            __builtin_prefetch(&s->proxies[x->proxy_index], 1);
    }
    bool changed = false;
    for (uint32_t k = 0; k < b->count; k++)
        changed |= node_eval(s, b, k);
    uint32_t proxies = 0;
    for (uint32_t k = 0; k < b->count; k++) {
        if (!b->proxy[k]) continue;
        const node_xf *x = &s->xf[b->item[k].slot];
        proxy_write_world(s, x, x->proxy_index, b->center[k], b->radius[k]);
        b->proxy_index[proxies] = x->proxy_index;
        b->scale[proxies++] = b->scale[k];
    }
    for (uint32_t k = 0; k < proxies; k++) proxy_write_finite(s, b->proxy_index[k], b->scale[k]);
    b->count = 0;
    return changed;
}

/* The common node, two or four at a time: a renderable leaf whose local
 * transform changed, under the root or another valid, shown identity,
 * itself shown, valid and without a fault to take back, its rotation unit
 * (simple_node) and its position and scale finite (eval_simple tests those
 * in its lanes). For it node_eval's outcome is known before it runs:
 * valid, its world its local transform, its world rotation its own, in the
 * snapshot still. So the world, the bound and the proxy are computed in
 * one pass in vector lanes (ob_update_lanes.h), with exactly the
 * operations of ob_scene_xf_local, node_world_bound, proxy_write_world and
 * proxy_write_finite in their order (the same bits), without the stages'
 * flags and stores in between. */
static bool simple_node(const ob_scene *s, level_item it, uint8_t st)
{
    enum { PARENT = XF_IDENTITY | XF_WORLD_VALID | XF_EFFECTIVE_HIDDEN,
           NODE = XF_HIDDEN | XF_FAULT_REPORTED | XF_HAS_CHILDREN | XF_HAS_LIGHT |
                  XF_WORLD_VALID | XF_HAS_RENDERABLE | XF_ROTATION_UNIT };
    if (it.parent != NO_SLOT && (s->xf[it.parent].flags & PARENT) != (XF_IDENTITY | XF_WORLD_VALID))
        return false;
    return (s->xf[it.slot].flags & NODE) == (XF_WORLD_VALID | XF_HAS_RENDERABLE | XF_ROTATION_UNIT) &&
           (st & (NODE_IN_RENDERABLES | NODE_IN_LIGHTS)) == NODE_IN_RENDERABLES;
}

/* The common node's evaluation, two nodes at once and, where the CPU has
 * AVX2, four (ob_update_lanes.h): eval_simple2 and eval_simple4. */
#define OB_LANES 2
#include "ob_update_lanes.h"
#if defined(OB_MOTION_LANES4)
#define OB_LANES 4
#include "ob_update_lanes.h"
#endif

/* ------------------------------------------------------------------ loops */

#if defined(OB_MOTION_LANES4)
_Static_assert(LEVEL_STEP == 4, "the usual step fills AVX2's four lanes");
/* Both built-in controllers of four nodes in AVX2's four lanes (the same
 * bits as two at a time); a rotation outside the usual norm range, two at
 * a time. */
static __attribute__((target("avx2"), noinline)) void
motion_step4(node_xf *const x[4], ob_orbit_state *const orbit[4], ob_rotation_state *const spin[4],
             double dt)
{
    ob_orbit_kernel4(x, orbit, 4, dt);
    if (!ob_rotation_kernel4(x, spin, 4, dt)) {
        ob_rotation_kernel2(x, spin, 2, dt);
        ob_rotation_kernel2(x + 2, spin + 2, 2, dt);
    }
}
#endif

/* Whether this update runs the usual step four nodes at once. */
static bool motion_lanes4(const ob_scene *s)
{
#if defined(OB_MOTION_LANES4)
    return !s->motion_lanes2 && __builtin_cpu_supports("avx2");
#else
    (void)s;
    return false;
#endif
}

/* The parallel-safe controllers of up to LEVEL_STEP nodes: those in
 * scene->motion (NODE_MOTION) two nodes at a time (a step of four that
 * each have both, four at a time with lanes4), the others in each node's
 * list in order; keep_world as for ob_controller_run. */
static void run_batch_controllers(ob_scene *s, const level_item *items, uint32_t count, double dt,
                                  bool keep_world, bool lanes4)
{
    node_xf *orbit_x[LEVEL_STEP], *spin_x[LEVEL_STEP];
    ob_orbit_state *orbit[LEVEL_STEP];
    ob_rotation_state *spin[LEVEL_STEP];
    /* The usual step (a whole one of nodes that each have both built-in
     * controllers and no others) in a straight line, the pairs known. */
    bool usual = count == LEVEL_STEP && !keep_world;
    for (uint32_t j = 0; j < count; j++)
        usual &= (s->state[items[j].slot] & NODE_MOTION) == NODE_MOTION;
    if (usual) {
        for (uint32_t j = 0; j < LEVEL_STEP; j++) {
            uint32_t slot = items[j].slot;
            node_motion *m = &s->motion[slot];
            orbit_x[j] = &s->xf[slot];
            orbit[j] = &m->orbit;
            spin[j] = &m->spin;
            s->state[slot] |= NODE_DIRTY;
        }
#if defined(OB_MOTION_LANES4)
        if (lanes4) {
            motion_step4(orbit_x, orbit, spin, dt);
            return;
        }
#else
        (void)lanes4;
#endif
        for (uint32_t k = 0; k < LEVEL_STEP; k += 2) {
            ob_orbit_kernel2(orbit_x + k, orbit + k, 2, dt);
            ob_rotation_kernel2(orbit_x + k, spin + k, 2, dt);
        }
        return;
    }
    uint32_t orbits = 0, spins = 0;
    for (uint32_t j = 0; j < count; j++) {
        uint32_t slot = items[j].slot;
        uint8_t st = s->state[slot];
        if (st & NODE_MOTION) {
            node_motion *m = &s->motion[slot];
            if (st & NODE_ORBIT) {
                orbit_x[orbits] = &s->xf[slot];
                orbit[orbits++] = &m->orbit;
            }
            if (st & NODE_SPIN) {
                if (keep_world) node_world_rotation_keep(s, slot);
                spin_x[spins] = &s->xf[slot];
                spin[spins++] = &m->spin;
            }
            s->state[slot] = (uint8_t)(st | NODE_DIRTY);
        } else if (st & NODE_PARALLEL) {
            node_controllers *ctl = &s->ctl[slot];
            for (uint32_t k = 0; k < ctl->parallel; k++)
                ob_controller_run(s, slot, &ctl->slots[k], dt, keep_world);
        }
    }
    for (uint32_t k = 0; k < orbits; k += 2)
        ob_orbit_kernel2(orbit_x + k, orbit + k, OB_MIN(2u, orbits - k), dt);
    for (uint32_t k = 0; k < spins; k += 2)
        ob_rotation_kernel2(spin_x + k, spin + k, OB_MIN(2u, spins - k), dt);
}

static void run_parallel_controller_loop(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    ob_scene *s = c->s;
    uint32_t end = chunk_end(c->count, chunk, c->grain);
    for (uint32_t i = chunk * c->grain; i < end; i += LEVEL_STEP)
        run_batch_controllers(s, c->items + i, OB_MIN(end, i + LEVEL_STEP) - i, c->dt, true,
                              c->lanes4);
}

/* Levels of at least this many nodes have their data asked for ahead:
 * they outgrow the core's own cache, and the update follows its arrays
 * faster than the hardware's prefetchers ramp up on each new page of each
 * of them. Transform records and controller state are asked for
 * PREFETCH_AHEAD nodes ahead, proxies (whose index the record holds) one
 * step ahead. At 50k moving objects, written out of cache between
 * updates: 84-90 ns an object without, 73-75 with the records, 57-58 with
 * the proxies too, 52-53 with the bounds. Smaller levels are in cache, where the requests only
 * cost (about 5 ns an object). */
#define PREFETCH_MIN_NODES 4096u
#define PREFETCH_AHEAD 16u

/* Asks for the transform records of nodes items[0..count), and their
 * built-in controllers' state when the level loop runs them. Inlined
 * always: GCC finds a function of prefetches alone free of side effects
 * and drops its calls. */
static inline __attribute__((always_inline)) void prefetch_nodes(const ob_scene *s,
                                                                 const level_item *items,
                                                                 uint32_t count, bool controllers)
{
    for (uint32_t j = 0; j < count; j++) {
        uint32_t slot = items[j].slot;
        const char *x = (const char *)&s->xf[slot];
        for (uint32_t line = 0; line < sizeof(node_xf); line += OB_CACHE_LINE)
            __builtin_prefetch(x + line, 1);
        if (!controllers) continue;
        const char *m = (const char *)&s->motion[slot];
        for (uint32_t at = 0; at < sizeof(node_motion); at += OB_CACHE_LINE)
            __builtin_prefetch(m + at, 1);
        __builtin_prefetch(m + sizeof(node_motion) - 1, 1);
    }
}

/* Asks for the proxies of nodes items[0..count) in the snapshot, whose
 * transform records (their proxy index) were asked for earlier, and at
 * each eighth proxy the next line of the bounds' arrays (the proxies of a
 * level's nodes mostly follow one another). */
static inline __attribute__((always_inline)) void prefetch_proxies(const ob_scene *s,
                                                                   const level_item *items,
                                                                   uint32_t count)
{
    for (uint32_t j = 0; j < count; j++) {
        uint32_t slot = items[j].slot;
        if (!(s->state[slot] & NODE_IN_RENDERABLES)) continue;
        uint32_t i = s->xf[slot].proxy_index;
        __builtin_prefetch(&s->proxies[i], 1);
        if (i % 8u == 0 && i + 8 < s->soa_cap) {
            __builtin_prefetch(&s->soa_x[i + 8], 1);
            __builtin_prefetch(&s->soa_y[i + 8], 1);
            __builtin_prefetch(&s->soa_z[i + 8], 1);
            __builtin_prefetch(&s->soa_radius[i + 8], 1);
        }
    }
}

/* One level's nodes, LEVEL_STEP at a time: controllers (when fused), then
 * the evaluation of those that need it. */
static void run_level(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const update_ctx *c = user;
    ob_scene *s = c->s;
    uint8_t *state = s->state;
    uint32_t end = chunk_end(c->count, chunk, c->grain);
    bool changed = false;
    bool prefetch = c->count >= PREFETCH_MIN_NODES;
    eval_batch b;
    b.count = 0;
    for (uint32_t i = chunk * c->grain; i < end; i += LEVEL_STEP) {
        uint32_t step_end = OB_MIN(end, i + LEVEL_STEP);
        if (prefetch) {
            uint32_t from = OB_MIN(end, i + PREFETCH_AHEAD);
            uint32_t to = OB_MIN(end, step_end + PREFETCH_AHEAD);
            prefetch_nodes(s, c->items + from, to - from, c->controllers);
            from = OB_MIN(end, i + LEVEL_STEP);
            to = OB_MIN(end, step_end + LEVEL_STEP);
            prefetch_proxies(s, c->items + from, to - from);
        }
        if (c->controllers)
            run_batch_controllers(s, c->items + i, step_end - i, c->dt, false, c->lanes4);
        level_item simple[LEVEL_STEP];
        uint32_t simples = 0;
        for (uint32_t j = i; j < step_end; j++) {
            level_item it = c->items[j];
            uint8_t st = state[it.slot];
            if ((st & NODE_DIRTY) || (it.parent != NO_SLOT && (state[it.parent] & NODE_CHANGED))) {
                if (simple_node(s, it, st)) simple[simples++] = it;
                else b.item[b.count++] = it;
            } else if (st & NODE_CHANGED) {
                state[it.slot] = (uint8_t)(st & ~NODE_CHANGED);
            }
        }
        uint32_t k = 0;
#if defined(OB_MOTION_LANES4)
        /* A whole step of them in four lanes; one not finite, in pairs. */
        if (simples == LEVEL_STEP && c->lanes4 && eval_simple4(s, simple, LEVEL_STEP)) k = simples;
#endif
        for (; k < simples; k += 2) {
            uint32_t pair = OB_MIN(2u, simples - k);
            if (eval_simple2(s, simple + k, pair)) continue;
            for (uint32_t l = 0; l < pair; l++) b.item[b.count++] = simple[k + l];
        }
        if (b.count > EVAL_BATCH - LEVEL_STEP || (b.count && step_end == end))
            changed |= eval_batch_run(s, &b);
    }
    c->counts[chunk] = changed;
}

/* ------------------------------------------------------------------ update */

/* order in pre-order, and by_level: a counting sort of it by depth. */
static void order_rebuild(ob_scene *s)
{
    uint32_t count = 0, levels = 0;
    for (ob_node *n = s->root; n; n = ob_scene_preorder_next(n, s->root)) {
        n->depth = n->parent ? n->parent->depth + 1 : 0;
        if (n->depth + 1 > levels) levels = n->depth + 1;
        s->order[count++] = n->by_id_index;
        node_xf *x = &s->xf[n->by_id_index];
        if (!n->first_child) {
            x->flags &= ~(uint32_t)(XF_HAS_CHILDREN | XF_IDENTITY);
        } else if (!(x->flags & XF_HAS_CHILDREN)) {
            /* Evaluated again to learn whether it is the identity. */
            x->flags |= XF_HAS_CHILDREN;
            s->state[n->by_id_index] |= NODE_DIRTY;
        }
    }
    s->order_count = count;
    s->level_count = levels;
    uint32_t *start = s->level_start;
    memset(start, 0, sizeof *start * (levels + 1));
    for (uint32_t i = 0; i < count; i++) start[s->by_id[s->order[i]]->depth + 1]++;
    for (uint32_t d = 0; d < levels; d++) start[d + 1] += start[d];
    /* start[d] is now where level d begins; fill, then shift back. */
    for (uint32_t i = 0; i < count; i++) {
        const ob_node *n = s->by_id[s->order[i]];
        s->by_level[start[n->depth]++] = (level_item){
            .slot = n->by_id_index, .parent = n->parent ? n->parent->by_id_index : NO_SLOT};
    }
    for (uint32_t d = levels; d > 0; d--) start[d] = start[d - 1];
    start[0] = 0;
    s->order_dirty = false;
}

static ob_result update_reserve(ob_scene *s, uint32_t grain)
{
    uint32_t need = s->node_count;
    ob_result r = ob_array_reserve((void **)&s->order, &s->order_cap, need, sizeof *s->order);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->by_level, &s->by_level_cap, need, sizeof *s->by_level);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->level_start, &s->level_start_cap, need + 1,
                             sizeof *s->level_start);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->chunk_counts, &s->chunk_counts_cap,
                             2 * (chunks_of(s->by_id_count, grain) + 1), sizeof *s->chunk_counts);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->renderables, &s->renderable_cap, need,
                             sizeof *s->renderables);
    if (r == OB_OK)
        r = ob_array_reserve_aligned((void **)&s->proxies, &s->proxy_cap, need,
                                     sizeof *s->proxies, OB_CACHE_LINE);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&s->lights, &s->light_cap, need, sizeof *s->lights);
    if (r == OB_OK && s->soa_cap < need) {
        /* All the arrays grow together to the same capacity; one that
         * cannot keeps the others' growth, harmless, and the old cap. */
        uint32_t cap = OB_MAX(need, 2 * s->soa_cap);
        struct { void **array; size_t size; } soa[] = {
            {(void **)&s->soa_x, sizeof *s->soa_x},
            {(void **)&s->soa_y, sizeof *s->soa_y},
            {(void **)&s->soa_z, sizeof *s->soa_z},
            {(void **)&s->soa_radius, sizeof *s->soa_radius},
            {(void **)&s->soa_flags, sizeof *s->soa_flags},
            {(void **)&s->soa_material, sizeof *s->soa_material},
            {(void **)&s->soa_geometry, sizeof *s->soa_geometry},
            {(void **)&s->soa_node_id, sizeof *s->soa_node_id},
            {(void **)&s->soa_node, sizeof *s->soa_node},
        };
        for (size_t k = 0; k < OB_ARRAY_COUNT(soa) && r == OB_OK; k++) {
            void *grown = ob_realloc(*soa[k].array, soa[k].size * cap);
            if (grown) *soa[k].array = grown;
            else r = OB_ERR_OUT_OF_HOST_MEMORY;
        }
        if (r == OB_OK) s->soa_cap = cap;
    }
    if (r != OB_OK)
        OB_LOG_E(SCENE_LOG, "scene update of %u nodes: %s; scene left as it was", need,
                 ob_result_text(r));
    return r;
}

/* Every node's controllers into one new pool, in level order, so that the
 * update reads them as one stream: once as many lie elsewhere (added since,
 * or left unused by destroyed nodes) as an eighth of the pool. */
static ob_result controllers_repack(ob_scene *s)
{
    if (s->ctl_loose <= s->ctl_pool_size / 8 + 64) return OB_OK;
    uint32_t total = 0;
    for (uint32_t i = 0; i < s->order_count; i++) total += s->ctl[s->by_level[i].slot].count;
    ob_controller_slot *pool = total ? ob_malloc(sizeof *pool * total) : NULL;
    if (total && !pool) {
        OB_LOG_E(SCENE_LOG, "scene update of %u nodes: %s; scene left as it was", s->node_count,
                 ob_result_text(OB_ERR_OUT_OF_HOST_MEMORY));
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    uint32_t w = 0;
    for (uint32_t i = 0; i < s->order_count; i++) {
        node_controllers *ctl = &s->ctl[s->by_level[i].slot];
        if (!ctl->count) continue;
        memcpy(pool + w, ctl->slots, sizeof *pool * ctl->count);
        if (!ctl->pooled) ob_free(ctl->slots);
        ctl->slots = pool + w;
        ctl->cap = ctl->count;
        ctl->pooled = true;
        w += ctl->count;
    }
    ob_free(s->ctl_pool);
    s->ctl_pool = pool;
    s->ctl_pool_size = total;
    s->ctl_loose = 0;
    return OB_OK;
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
    /* The finest cut any loop can take (update_loop). */
    uint32_t grain = par && par->grain ? par->grain : UPDATE_GRAIN_MIN;
    ob_result r = update_reserve(s, grain);
    if (r != OB_OK) return r;
    ob_scene_intern_trim(s);
    ob_scene_compact(s);
    if (s->order_dirty) order_rebuild(s);
    r = controllers_repack(s);
    if (r != OB_OK) return r;

    s->in_update = true;
    update_ctx c = {.s = s, .dt = dt, .par = par, .counts = s->chunk_counts,
                    .lanes4 = motion_lanes4(s)};
    /* Serial controllers may read any node's local transform, so every
     * parallel-safe one must have run before them, and every transform
     * after them. Without any, a node's controllers run right before its
     * evaluation, in the same loop. */
    c.controllers = s->serial_nodes == 0;
    if (!c.controllers) {
        c.items = s->by_level;
        c.count = s->order_count;
        update_loop(&c, c.count, run_parallel_controller_loop);
        for (uint32_t i = 0; i < s->order_count; i++) {
            uint32_t slot = s->order[i];
            if (!(s->state[slot] & NODE_SERIAL)) continue;
            /* Re-read the array each time: a controller may add controllers. */
            uint32_t count = s->ctl[slot].count;
            for (uint32_t k = s->ctl[slot].parallel; k < count; k++)
                ob_controller_run(s, slot, &s->ctl[slot].slots[k], dt, true);
        }
    }
    bool membership_changed = s->snapshot_dirty;
    for (uint32_t d = 0; d < s->level_count; d++) {
        c.items = s->by_level + s->level_start[d];
        c.count = s->level_start[d + 1] - s->level_start[d];
        update_loop(&c, c.count, run_level);
        uint32_t chunks = chunks_of(c.count, c.grain);
        for (uint32_t k = 0; k < chunks; k++) membership_changed |= c.counts[k] != 0;
    }
    s->in_update = false;
    for (uint32_t i = 0; i < s->retired_count; i++) ob_free(s->retired[i]);
    s->retired_count = 0;
    if (membership_changed) snapshot_rebuild(s, &c);
    return OB_OK;
}
