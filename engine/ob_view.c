#include "ob_renderer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_math.h"

const char *ob_view_type_name(ob_view_type t)
{
    static const char *const names[OB_VIEW_TYPE_COUNT] = {
        "perspective", "shadow", "paraboloid", "simulation", "overlay", "composite",
    };
    return (unsigned)t < OB_VIEW_TYPE_COUNT ? names[t] : "unknown";
}

void ob_view_init(ob_view *v, const ob_view_vtbl *vtbl, ob_view_type type, const char *name)
{
    memset(v, 0, sizeof *v);
    v->vtbl = vtbl;
    v->type = type;
    snprintf(v->name, sizeof v->name, "%s", name ? name : ob_view_type_name(type));
    v->id = (uint32_t)ob_hash_str(OB_HASH_SEED, v->name);
    v->layer_count = 1;
}

void ob_view_release(ob_view *v)
{
    if (!v) return;
    ob_free(v->items);
    v->items = NULL;
    v->item_count = v->item_cap = 0;
}

void ob_view_add_dependency(ob_view *v, ob_view *dep)
{
    if (!v || !dep || v == dep) return;
    for (uint32_t i = 0; i < v->dep_count; i++)
        if (v->deps[i] == dep) return;
    if (v->dep_count < OB_VIEW_MAX_DEPS) {
        v->deps[v->dep_count++] = dep;
    } else {
        OB_LOG_E("view", "view '%s': more than %u dependencies; '%s' is not ordered before it",
                 v->name, OB_VIEW_MAX_DEPS, dep->name);
    }
}

/* Sort key: class (opaque first), priority, then distance — ascending for
 * opaque (front to back), descending for blended (back to front). Node ids
 * break ties, so the order is total and independent of threads. */
static uint64_t sort_key(uint32_t cls, uint32_t priority, float dist2)
{
    uint32_t bits;
    memcpy(&bits, &dist2, sizeof bits); /* positive floats order like their bits */
    if (cls) bits = ~bits;
    return ((uint64_t)(cls & 1u) << 63) | ((uint64_t)(priority & 0x7fffffffu) << 32) | bits;
}

static int compare_items(const void *a, const void *b)
{
    const ob_draw_item *x = a, *y = b;
    if (x->sort_key != y->sort_key) return x->sort_key < y->sort_key ? -1 : 1;
    uint32_t ix = ob_node_id(x->node), iy = ob_node_id(y->node);
    return (ix > iy) - (ix < iy);
}

ob_result ob_view_cull(ob_view *v, ob_renderer *r, const ob_scene *scene, const ob_node *exclude)
{
    const ob_material_iface *mi = ob_renderer_material_iface(r);
    uint64_t t0 = ob_time_ns();
    uint32_t count = 0;
    ob_node *const *nodes = ob_scene_renderables(scene, &count);
    v->item_count = 0;
    v->culled = 0;
    if (!mi) return OB_ERR_WRONG_STATE;
    ob_result res = ob_array_reserve((void **)&v->items, &v->item_cap, count, sizeof *v->items);
    if (res != OB_OK) {
        /* The view goes on empty this frame; the next frame tries again. */
        OB_LOG_E("view", "view '%s': no draw list for %u renderables (%s); it draws nothing this frame",
                 v->name, count, ob_result_name(res));
        ob_renderer_note_skipped(r, v->name, OB_SKIP_ERROR);
        return res;
    }
    ob_frustum frustum;
    ob_frustum_from_matrix(v->view_proj, &frustum);
    bool out_of_range = false;
    for (uint32_t i = 0; i < count; i++) {
        ob_node *n = nodes[i];
        const ob_renderable *rd = ob_node_renderable(n);
        if (n == exclude || !rd || !rd->material || !mi->renders(rd->material, v->type)) {
            v->culled++;
            continue;
        }
        double c[3];
        float radius;
        ob_node_world_sphere(n, c, &radius);
        /* A bound that is not empty locally but zero in the world: the world
         * transform has zero scale, every triangle has zero area. Drawing it
         * yields nothing, but keeping it would still queue its env map and
         * stretch a shadow map's fit to its position. */
        if (radius == 0.0f && rd->local_radius > 0.0f) {
            v->culled++;
            continue;
        }
        float rel[3] = {(float)(c[0] - v->origin[0]), (float)(c[1] - v->origin[1]),
                        (float)(c[2] - v->origin[2])};
        if (!isfinite(rel[0]) || !isfinite(rel[1]) || !isfinite(rel[2]) || !isfinite(radius)) {
            /* Finite in double, not in float: no matrix the GPU could take
             * places it, and as a "visible" shadow caster it would blow up
             * the light's fit. */
            if (!v->range_reported)
                OB_LOG_E("view", "view '%s': entity '%s' (id %u) lies beyond float range from "
                         "the view's origin (bound at %.3g, %.3g, %.3g, radius %.3g); not drawn",
                         v->name, ob_node_name(n), ob_node_id(n), c[0] - v->origin[0],
                         c[1] - v->origin[1], c[2] - v->origin[2], (double)radius);
            out_of_range = true;
            v->range_reported = true;
            v->culled++;
            continue;
        }
        if (!v->no_frustum && !ob_frustum_test_sphere(&frustum, rel, radius)) {
            v->culled++;
            continue;
        }
        uint32_t cls = 0, priority = 0;
        mi->sort_info(rd->material, v->type, &cls, &priority);
        float d2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2];
        v->items[v->item_count++] = (ob_draw_item){sort_key(cls, priority, d2), n};
    }
    if (!out_of_range) v->range_reported = false;
    /* items is NULL for an empty scene, and qsort's pointer must not be. */
    if (v->item_count > 1) qsort(v->items, v->item_count, sizeof *v->items, compare_items);
    v->cull_ns = ob_time_ns() - t0;
    return OB_OK;
}

void ob_view_pre_render_items(ob_view *v, ob_renderer *r)
{
    const ob_material_iface *mi = ob_renderer_material_iface(r);
    if (!mi || !mi->pre_render) return;
    /* Items can be appended to other views during this loop, never to v. */
    for (uint32_t i = 0; i < v->item_count; i++) {
        ob_node *n = v->items[i].node;
        mi->pre_render(ob_node_renderable(n)->material, n, r, v);
    }
}

void ob_view_record_items(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                          uint32_t first, uint32_t count)
{
    const ob_material_iface *mi = ob_renderer_material_iface(r);
    const ob_geometry_iface *gi = ob_renderer_geometry_iface(r);
    ob_params *params = ob_pm_params(pm);
    ob_param world = ob_param_registry_builtins(params->reg)->world;
    float m[16];
    for (uint32_t i = first; i < first + count && i < v->item_count; i++) {
        ob_node *n = v->items[i].node;
        const ob_renderable *rd = ob_node_renderable(n);
        ob_node_world_relative(n, v->origin, m);
        /* A refused matrix (logged by the parameter) would leave the previous
         * entity's in the slot: drawing then puts this one in its place. */
        if (ob_params_set_mat4(params, world, m) != OB_OK) {
            OB_LOG_E("view", "view '%s': entity '%s' (id %u): world matrix refused; not drawn",
                     v->name, ob_node_name(n), ob_node_id(n));
            continue;
        }
        if (!mi->apply(rd->material, n, r, pm, v)) continue;
        gi->draw(rd->geometry, pm);
    }
}

void ob_view_record_draw_list(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count)
{
    (void)layer;
    ob_view_record_items(v, r, pm, first, count);
}
