#include "ob_renderer.h"
#include "ob_renderer_layer.h"

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

static VkFormat image_format(const ob_device *dev, ob_image img)
{
    ob_image_info info;
    if (!img.id || ob_image_get_info(dev, img, &info) != OB_OK) return VK_FORMAT_UNDEFINED;
    return info.format;
}

void ob_view_attachment_formats(const ob_view *v, const ob_device *dev, VkFormat *out_color,
                                VkFormat *out_depth, uint32_t *out_samples)
{
    bool ms = v->samples > 1;
    *out_color = image_format(dev, ms && v->msaa_color.id ? v->msaa_color : v->color);
    *out_depth = image_format(dev, ms ? v->msaa_depth : v->depth);
    *out_samples = ms ? v->samples : 1;
}

bool ob_view_resize(ob_view *v, uint32_t width, uint32_t height)
{
    if (!v || width == 0 || height == 0) {
        OB_LOG_E("view", "view '%s': resize to %ux%u refused (a side is zero)", v ? v->name : "?",
                 width, height);
        return false;
    }
    v->resize_width = width;
    v->resize_height = height;
    return true;
}

bool ob_view_take_resize(ob_view *v, uint32_t *out_width, uint32_t *out_height)
{
    if (!v->resize_width || !v->resize_height) return false;
    *out_width = v->resize_width;
    *out_height = v->resize_height;
    v->resize_width = v->resize_height = 0;
    return true;
}

void ob_view_release(ob_view *v)
{
    if (!v) return;
    ob_free(v->items);
    ob_free(v->sort_scratch);
    v->items = NULL;
    v->sort_scratch = NULL;
    v->sort_scratch_cap = 0;
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

/* The draw-list key (bgfx-style): sort_hi holds the class (opaque first)
 * and the priority; sort_key, for opaque items, a coarse depth band (the
 * distance's exponent in steps of 4x), the material's state group, the mesh
 * and the fine depth, so that draws binding the same state follow each
 * other while the front-to-back order survives between bands; for blended
 * items the full depth, back to front, then state group and mesh. dist2 is
 * >= 0, and positive floats order like their bits. */
static void item_key(ob_draw_item *it, uint32_t cls, uint32_t priority, uint32_t state,
                     uint32_t mesh, float dist2)
{
    uint32_t bits;
    memcpy(&bits, &dist2, sizeof bits);
    it->sort_hi = ((cls & 1u) << 31) | (priority & 0x7fffffffu);
    if (cls & 1u) {
        it->sort_key = ((uint64_t)~bits << 32) | ((uint64_t)(state & 0xffffu) << 16) | (mesh & 0xffffu);
    } else {
        uint64_t band = bits >> 25;            /* sign 0, top 6 bits of the exponent */
        uint64_t fine = (bits >> 5) & 0xfffffu; /* the rest of the depth, 20 bits */
        it->sort_key = (band << 58) | ((uint64_t)(state & 0xfffu) << 46) |
                       ((uint64_t)(mesh & 0x3ffffu) << 28) | (fine << 8);
    }
}

static uint32_t item_digit(const ob_draw_item *it, uint32_t pass)
{
    if (pass < 4) return (it->node_id >> (8 * pass)) & 0xffu;
    if (pass < 12) return (uint32_t)(it->sort_key >> (8 * (pass - 4))) & 0xffu;
    return (it->sort_hi >> (8 * (pass - 12))) & 0xffu;
}

/* Stable LSD radix sort on (sort_hi, sort_key, node_id), a byte per pass:
 * linear in the item count, no comparator calls. A pass in which every item
 * has the same byte is skipped (most of the high bytes in practice). */
static void sort_items(ob_draw_item *items, ob_draw_item *scratch, uint32_t n)
{
    ob_draw_item *src = items, *dst = scratch;
    for (uint32_t pass = 0; pass < 16; pass++) {
        uint32_t count[256] = {0};
        for (uint32_t i = 0; i < n; i++) count[item_digit(&src[i], pass)]++;
        if (count[item_digit(&src[0], pass)] == n) continue;
        uint32_t sum = 0;
        for (uint32_t b = 0; b < 256; b++) {
            uint32_t c = count[b];
            count[b] = sum;
            sum += c;
        }
        for (uint32_t i = 0; i < n; i++) dst[count[item_digit(&src[i], pass)]++] = src[i];
        ob_draw_item *t = src;
        src = dst;
        dst = t;
    }
    if (src != items) memcpy(items, src, sizeof *items * n);
}

ob_result ob_view_cull(ob_view *v, ob_renderer *r, const ob_scene *scene, const ob_node *exclude)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    const ob_geometry_iface *gi = ob_renderer_get_geometry_iface(r);
    uint64_t t0 = ob_time_ns();
    uint32_t count = 0;
    const ob_render_proxy *proxies = ob_scene_render_proxies(scene, &count);
    const ob_render_bound *bounds = ob_scene_render_bounds(scene, &count);
    v->proxies = proxies;
    v->item_count = 0;
    v->culled = 0;
    if (!mi) return OB_ERR_WRONG_STATE;
    ob_result res = ob_array_reserve((void **)&v->items, &v->item_cap, count, sizeof *v->items);
    if (res == OB_OK)
        res = ob_array_reserve((void **)&v->sort_scratch, &v->sort_scratch_cap, count,
                               sizeof *v->sort_scratch);
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
        const ob_render_proxy *p = &proxies[i];
        if (p->node == exclude || !p->material || !mi->renders(p->material, v->type)) {
            v->culled++;
            continue;
        }
        const double *c = bounds[i].center;
        float radius = bounds[i].radius;
        /* A bound that is not empty locally but zero in the world: the world
         * transform has zero scale, every triangle has zero area. Drawing it
         * yields nothing, but keeping it would still queue its env map and
         * stretch a shadow map's fit to its position. */
        if (radius == 0.0f && bounds[i].local_radius > 0.0f) {
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
                         v->name, ob_node_name(p->node), p->node_id, c[0] - v->origin[0],
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
        uint32_t cls = 0, priority = 0, state = 0;
        mi->sort_info(p->material, v->type, &cls, &priority, &state);
        float d2 = rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2];
        ob_draw_item *it = &v->items[v->item_count++];
        *it = (ob_draw_item){.node_id = p->node_id, .node = p->node, .proxy = i};
        item_key(it, cls, priority, state, gi && p->geometry ? gi->id(p->geometry) : 0, d2);
    }
    if (!out_of_range) v->range_reported = false;
    if (v->item_count > 1) sort_items(v->items, v->sort_scratch, v->item_count);
    v->cull_ns = ob_time_ns() - t0;
    return OB_OK;
}

void ob_view_pre_render_items(ob_view *v, ob_renderer *r)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    if (!mi || !mi->pre_render) return;
    /* Items can be appended to other views during this loop, never to v. */
    for (uint32_t i = 0; i < v->item_count; i++) {
        ob_node *n = v->items[i].node;
        mi->pre_render(ob_node_get_renderable(n)->material, n, r, v);
    }
}

/* Items ahead of the one being drawn whose proxy is prefetched. */
#define PROXY_PREFETCH 16u

void ob_view_record_items(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                          uint32_t first, uint32_t count)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    const ob_geometry_iface *gi = ob_renderer_get_geometry_iface(r);
    /* Items are sorted by state: a run of one material is applied once. */
    const struct ob_material *applied = NULL;
    _Alignas(16) float m[32];
    uint32_t end = first + count < v->item_count ? first + count : v->item_count;
    for (uint32_t i = first; i < end; i++) {
        /* Items are in draw order, proxies in id order: fetch a few ahead so
         * the loop does not wait on memory. */
        if (i + PROXY_PREFETCH < end) {
            const ob_render_proxy *ahead = &v->proxies[v->items[i + PROXY_PREFETCH].proxy];
            __builtin_prefetch(ahead);
            __builtin_prefetch((const char *)ahead + 64);
        }
        const ob_render_proxy *p = &v->proxies[v->items[i].proxy];
        if (!p->material) continue;
        if (p->material != applied) {
            ob_apply_result a = mi->apply(p->material, p->node, r, pm, v);
            applied = a == OB_APPLY_MATERIAL ? p->material : NULL;
            if (a == OB_APPLY_SKIP) continue;
        }
        /* A refused matrix is not drawn (a stale one would put this entity
         * where the previous one was). */
        bool finite = ob_render_proxy_per_draw(p, v->origin, m);
        if (finite) ob_pipeline_manager_set_world(pm, m);
        if (!finite || gi->draw(p->geometry, pm) == OB_ERR_NON_FINITE)
            OB_LOG_E("view", "view '%s': entity '%s' (id %u): world matrix not finite in float "
                     "(or its derived matrices); not drawn", v->name, ob_node_name(p->node),
                     p->node_id);
    }
}

void ob_view_record_draw_list(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count)
{
    (void)layer;
    ob_view_record_items(v, r, pm, first, count);
}
