/* ob_geometry.c — uploading meshes into vertex + index buffers. */
#include "ob_geometry.h"

#include "ob_renderer_layer.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define OB_GEOMETRY_LOG "geometry"

/* One level of detail: its range of the shared buffers. */
typedef struct geometry_lod {
    uint32_t first_index, index_count;
    int32_t vertex_offset;
    float error;
} geometry_lod;

struct ob_geometry {
    ob_buffer vertex_buffer;
    ob_buffer index_buffer;
    uint32_t vertex_count;
    uint32_t index_count;
    uint32_t instance_count;
    VkPrimitiveTopology topology;
    ob_bounds bounds;
    uint32_t id;
    bool extended;
    bool uv1;                 /* extended with TEXCOORD1 */
    char *name;
    uint32_t lod_count;       /* 1 for a mesh without coarser levels */
    geometry_lod lods[OB_GEOMETRY_MAX_LODS];
};

_Static_assert(OB_GEOMETRY_MAX_LODS == OB_LOD_MAX, "the geometry's levels fit the engine's");

/* Immutable, so sharing one instance across threads is safe. */
static const ob_vertex_layout standard_layout = {
    .stride = sizeof(ob_vertex),
    .attribute_count = 3,
    .attributes = {
        {0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(ob_vertex, position), "POSITION"},
        {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(ob_vertex, normal), "NORMAL"},
        {2, VK_FORMAT_R32G32_SFLOAT, offsetof(ob_vertex, uv), "TEXCOORD0"},
    },
};

const ob_vertex_layout *ob_vertex_layout_standard(void) { return &standard_layout; }

_Static_assert(sizeof(ob_vertex_extended) == 52, "the extended vertex is 52 bytes, unpadded");

/* The extended vertex's attributes, shared by both extended layouts. */
#define EXTENDED_ATTRIBUTES                                                                    \
    {0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(ob_vertex_extended, position), "POSITION"},       \
    {1, VK_FORMAT_R32G32B32_SFLOAT, offsetof(ob_vertex_extended, normal), "NORMAL"},           \
    {2, VK_FORMAT_R32G32_SFLOAT, offsetof(ob_vertex_extended, uv), "TEXCOORD0"},               \
    {3, VK_FORMAT_R8G8B8A8_UNORM, offsetof(ob_vertex_extended, color), "COLOR0"},              \
    {4, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(ob_vertex_extended, tangent), "TANGENT"}

static const ob_vertex_layout extended_layout = {
    .stride = sizeof(ob_vertex_extended),
    .attribute_count = 5,
    .attributes = {EXTENDED_ATTRIBUTES},
};

const ob_vertex_layout *ob_vertex_layout_extended(void) { return &extended_layout; }

_Static_assert(sizeof(ob_vertex_extended_uv1) == 60, "the extended vertex with TEXCOORD1 is 60 bytes");

static const ob_vertex_layout extended_uv1_layout = {
    .stride = sizeof(ob_vertex_extended_uv1),
    .attribute_count = 6,
    .attributes = {EXTENDED_ATTRIBUTES,
                   {5, VK_FORMAT_R32G32_SFLOAT, offsetof(ob_vertex_extended_uv1, uv1), "TEXCOORD1"}},
};

const ob_vertex_layout *ob_vertex_layout_extended_uv1(void) { return &extended_uv1_layout; }

/* The mesh interleaved in the extended layout (with uv1: the TEXCOORD1 one,
 * stride 60) into out, defaults where an optional array is missing (uv1:
 * the first set). */
static void interleave_extended(const ob_mesh *mesh, bool uv1, uint8_t *out)
{
    const size_t stride = uv1 ? sizeof(ob_vertex_extended_uv1) : sizeof(ob_vertex_extended);
    for (uint32_t i = 0; i < mesh->vertex_count; i++) {
        ob_vertex_extended *e = (ob_vertex_extended *)(void *)(out + i * stride);
        const ob_vertex *v = &mesh->vertices[i];
        if (uv1) {
            ob_vertex_extended_uv1 *x = (ob_vertex_extended_uv1 *)(void *)e;
            memcpy(x->uv1, mesh->uv1 ? mesh->uv1[i] : v->uv, sizeof x->uv1);
        }
        memcpy(e->position, v->position, sizeof e->position);
        memcpy(e->normal, v->normal, sizeof e->normal);
        memcpy(e->uv, v->uv, sizeof e->uv);
        if (mesh->colors) memcpy(e->color, mesh->colors[i], sizeof e->color);
        else memset(e->color, 255, sizeof e->color);
        if (mesh->tangents) {
            memcpy(e->tangent, mesh->tangents[i], sizeof e->tangent);
        } else {
            e->tangent[0] = 1.0f;
            e->tangent[1] = e->tangent[2] = 0.0f;
            e->tangent[3] = 1.0f;
        }
    }
}

/* How many indices make one primitive, and the fewest a draw needs. */
static bool topology_shape(VkPrimitiveTopology t, uint32_t *out_per_primitive, uint32_t *out_min)
{
    switch (t) {
    case VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST: *out_per_primitive = 3; *out_min = 3; return true;
    case VK_PRIMITIVE_TOPOLOGY_LINE_LIST: *out_per_primitive = 2; *out_min = 2; return true;
    case VK_PRIMITIVE_TOPOLOGY_LINE_STRIP: *out_per_primitive = 1; *out_min = 2; return true;
    case VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP:
    case VK_PRIMITIVE_TOPOLOGY_TRIANGLE_FAN: *out_per_primitive = 1; *out_min = 3; return true;
    default: return false;
    }
}

/* Hashes the bytes that are uploaded, so the same mesh uploaded standard
 * and extended gets two ids; every level's indices and errors too. */
static uint32_t derive_id(const char *name, const ob_geometry *g, const void *vertex_bytes,
                          size_t vertex_size, const uint32_t *indices)
{
    uint64_t h = ob_hash_str(OB_HASH_SEED, name);
    h = ob_hash_u64(h, g->vertex_count);
    h = ob_hash_u64(h, g->index_count);
    h = ob_hash_u64(h, vertex_size);
    h = ob_hash_bytes(h, vertex_bytes, vertex_size);
    uint32_t total = g->lods[g->lod_count - 1].first_index + g->lods[g->lod_count - 1].index_count;
    h = ob_hash_bytes(h, indices, (size_t)total * sizeof(uint32_t));
    for (uint32_t l = 1; l < g->lod_count; l++) {
        h = ob_hash_u64(h, ((uint64_t)g->lods[l].first_index << 32) | (uint32_t)g->lods[l].vertex_offset);
        h = ob_hash_bytes(h, &g->lods[l].error, sizeof g->lods[l].error);
    }
    uint32_t id = (uint32_t)(h ^ (h >> 32));
    return id ? id : 1u;   /* 0 means "none" everywhere else */
}

static void set_result(ob_result *out_result, ob_result r)
{
    if (out_result) *out_result = r;
}

/* A device-local buffer holding `size` bytes of data, named "<name>/<what>".
 * TRANSFER_SRC lets tools and tests read it back. */
static ob_buffer upload(ob_device *dev, const char *name, const char *what, uint32_t usage,
                        const void *data, uint64_t size, ob_result *out_result)
{
    char debug_name[160];
    snprintf(debug_name, sizeof debug_name, "%s/%s", name, what);
    ob_buffer_desc desc = {
        .size = size,
        .usage = usage | OB_BUFFER_TRANSFER_DST | OB_BUFFER_TRANSFER_SRC,
        .data = data,
        .name = debug_name,
    };
    ob_buffer buf = ob_buffer_create(dev, &desc, out_result);
    if (!buf.id) {
        if (*out_result == OB_OK) *out_result = OB_ERR_VULKAN;
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: %s buffer (%llu bytes) not created: %s", name, what,
                 (unsigned long long)size, ob_result_name(*out_result));
    }
    return buf;
}

static ob_geometry *create_procedural(const ob_geometry_desc *desc, ob_result *out_result)
{
    const char *name = desc->name && desc->name[0] ? desc->name : "geometry";
    ob_geometry *g = ob_calloc(1, sizeof *g);
    if (g) g->name = ob_strdup(name);
    if (!g || !g->name) {
        ob_free(g);
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: out of host memory for the geometry object", name);
        set_result(out_result, OB_ERR_OUT_OF_HOST_MEMORY);
        return NULL;
    }
    g->vertex_count = desc->vertex_count;
    g->instance_count = desc->instance_count ? desc->instance_count : 1;
    g->lod_count = 1;
    g->topology = desc->topology ? desc->topology : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    g->extended = desc->extended;
    g->id = desc->id ? desc->id
                     : (uint32_t)ob_hash_u64(ob_hash_str(OB_HASH_SEED, name),
                                             ((uint64_t)g->vertex_count << 32) | g->instance_count);
    return g;
}

ob_result ob_geometry_measure_lods(const ob_mesh *level0, ob_geometry_lod *levels, uint32_t count)
{
    if (!level0 || (count && !levels)) return OB_ERR_INVALID_ARGUMENT;
    for (uint32_t l = 0; l < count; l++) {
        ob_result r = ob_mesh_deviation(level0, levels[l].mesh, &levels[l].error);
        if (r != OB_OK) return r;
        /* A coarser level is never claimed better than the one before. */
        if (l > 0) levels[l].error = fmaxf(levels[l].error, levels[l - 1].error);
    }
    return OB_OK;
}

ob_result ob_geometry_make_lods(const ob_mesh *level0, uint32_t count, ob_mesh *meshes,
                                ob_geometry_lod *levels, uint32_t *out_count)
{
    if (out_count) *out_count = 0;
    if (!level0 || !out_count || (count && (!meshes || !levels))) return OB_ERR_INVALID_ARGUMENT;
    if (count > OB_GEOMETRY_MAX_LODS - 1) {
        OB_LOG_E(OB_GEOMETRY_LOG, "make_lods: %u levels asked for; at most %u besides level 0",
                 count, OB_GEOMETRY_MAX_LODS - 1);
        return OB_ERR_LIMIT;
    }
    uint32_t n = 0;
    ob_result r = OB_OK;
    const ob_mesh *before = level0;
    while (n < count) {
        ob_mesh *m = &meshes[n];
        r = ob_mesh_simplify(before, before->index_count / 2, INFINITY, m, NULL);
        if (r != OB_OK) break;
        /* Seams and borders left too little to collapse: no level. */
        if ((uint64_t)m->index_count * 10 > (uint64_t)before->index_count * 9) {
            ob_mesh_release(m);
            break;
        }
        float error = 0.0f;
        if ((r = ob_mesh_deviation(level0, m, &error)) != OB_OK) {
            ob_mesh_release(m);
            break;
        }
        /* Never claimed better than the level before, and > 0 as a level's
         * error must be (a flat region collapses at no cost). */
        if (n > 0) error = fmaxf(error, levels[n - 1].error);
        levels[n] = (ob_geometry_lod){.mesh = m, .error = fmaxf(error, FLT_MIN)};
        before = m;
        n++;
    }
    if (r != OB_OK) {
        for (uint32_t l = 0; l < n; l++) ob_mesh_release(&meshes[l]);
        return r;
    }
    *out_count = n;
    return OB_OK;
}

/* Checks desc's coarser levels (their errors and counts; each mesh as
 * level 0 is checked) and gathers every level's mesh into meshes. */
static ob_result check_levels(const ob_geometry_desc *desc, const char *name, uint32_t per_primitive,
                              uint32_t min_indices, const ob_mesh *meshes[OB_GEOMETRY_MAX_LODS])
{
    if (desc->lod_count >= OB_GEOMETRY_MAX_LODS) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: %u levels of detail; at most %u besides level 0", name,
                 desc->lod_count, OB_GEOMETRY_MAX_LODS - 1);
        return OB_ERR_LIMIT;
    }
    if (desc->lod_count && !desc->lods) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: lod_count %u without lods", name, desc->lod_count);
        return OB_ERR_INVALID_ARGUMENT;
    }
    meshes[0] = desc->mesh;
    float before = 0.0f;
    for (uint32_t l = 0; l < desc->lod_count; l++) {
        const ob_geometry_lod *lod = &desc->lods[l];
        char level_name[160];
        snprintf(level_name, sizeof level_name, "%s (level %u)", name, l + 1);
        if (!lod->mesh || !isfinite(lod->error) || !(lod->error > 0.0f) || lod->error < before) {
            OB_LOG_E(OB_GEOMETRY_LOG, "%s: %s; a level needs a mesh and an error that is finite, "
                     "positive and at least the level before's (%g)", level_name,
                     !lod->mesh ? "no mesh" : "error out of range", (double)before);
            return OB_ERR_INVALID_ARGUMENT;
        }
        ob_result r = ob_mesh_validate_primitives(lod->mesh, level_name, per_primitive, min_indices);
        if (r != OB_OK) return r;
        before = lod->error;
        meshes[l + 1] = lod->mesh;
    }
    return OB_OK;
}

/* Every level's vertices side by side in the uploaded layout, or level 0's
 * own array when that is what is uploaded (*out_owned false). */
static const void *gather_vertices(const ob_geometry *g, const ob_mesh *const *meshes,
                                   uint32_t total, size_t stride, bool *out_owned)
{
    *out_owned = false;
    if (g->lod_count == 1 && !g->extended) return meshes[0]->vertices;
    uint8_t *out = ob_malloc((size_t)total * stride);
    if (!out) return NULL;
    *out_owned = true;
    for (uint32_t l = 0; l < g->lod_count; l++) {
        uint8_t *at = out + (size_t)g->lods[l].vertex_offset * stride;
        if (g->extended) interleave_extended(meshes[l], g->uv1, at);
        else memcpy(at, meshes[l]->vertices, (size_t)meshes[l]->vertex_count * stride);
    }
    return out;
}

/* Every level's indices side by side (each relative to its own vertices:
 * the draw's vertex offset places them), or level 0's own array. */
static const uint32_t *gather_indices(const ob_geometry *g, const ob_mesh *const *meshes,
                                      uint32_t total, bool *out_owned)
{
    *out_owned = false;
    if (g->lod_count == 1) return meshes[0]->indices;
    uint32_t *out = ob_malloc((size_t)total * sizeof *out);
    if (!out) return NULL;
    *out_owned = true;
    for (uint32_t l = 0; l < g->lod_count; l++)
        memcpy(out + g->lods[l].first_index, meshes[l]->indices,
               (size_t)meshes[l]->index_count * sizeof *out);
    return out;
}

ob_geometry *ob_geometry_create(ob_device *dev, const ob_geometry_desc *desc, ob_result *out_result)
{
    set_result(out_result, OB_OK);
    if (desc && !desc->mesh && desc->vertex_count > 0) {
        if (desc->lod_count) {
            OB_LOG_E(OB_GEOMETRY_LOG, "%s: procedural geometry has no levels of detail",
                     desc->name && desc->name[0] ? desc->name : "geometry");
            set_result(out_result, OB_ERR_INVALID_ARGUMENT);
            return NULL;
        }
        return create_procedural(desc, out_result);
    }
    if (!dev || !desc || !desc->mesh) {
        OB_LOG_E(OB_GEOMETRY_LOG, "ob_geometry_create: NULL %s", !dev ? "device"
                 : !desc ? "desc" : "mesh");
        set_result(out_result, OB_ERR_INVALID_ARGUMENT);
        return NULL;
    }
    const char *name = desc->name && desc->name[0] ? desc->name : "geometry";
    const ob_mesh *mesh = desc->mesh;
    VkPrimitiveTopology topology = desc->topology ? desc->topology : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    uint32_t per_primitive, min_indices;
    if (!topology_shape(topology, &per_primitive, &min_indices)) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: primitive topology %d is not supported", name, (int)topology);
        set_result(out_result, OB_ERR_UNSUPPORTED);
        return NULL;
    }
    ob_result r = ob_mesh_validate_primitives(mesh, name, per_primitive, min_indices);
    const ob_mesh *meshes[OB_GEOMETRY_MAX_LODS] = {0};
    if (r == OB_OK) r = check_levels(desc, name, per_primitive, min_indices, meshes);
    if (r != OB_OK) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: mesh rejected, nothing uploaded", name);
        set_result(out_result, r);
        return NULL;
    }

    ob_geometry *g = ob_calloc(1, sizeof *g);
    if (!g) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: out of host memory for the geometry object", name);
        set_result(out_result, OB_ERR_OUT_OF_HOST_MEMORY);
        return NULL;
    }
    g->name = ob_strdup(name);
    if (!g->name) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: out of host memory for the name", name);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_geometry;
    }
    r = ob_bounds_compute(mesh->vertices, mesh->vertex_count, &g->bounds);
    if (r != OB_OK) goto fail_free_geometry;   /* unreachable after validation, kept honest */
    g->lod_count = desc->lod_count + 1;
    g->instance_count = 1;
    g->topology = topology;
    uint64_t vertices = 0, indices = 0;
    for (uint32_t l = 0; l < g->lod_count; l++) {
        const ob_mesh *m = meshes[l];
        g->uv1 |= m->uv1 != NULL;
        g->extended |= m->tangents || m->colors;
        g->lods[l] = (geometry_lod){.first_index = (uint32_t)indices, .index_count = m->index_count,
                                    .vertex_offset = (int32_t)vertices,
                                    .error = l ? desc->lods[l - 1].error : 0.0f};
        vertices += m->vertex_count;
        indices += m->index_count;
        if (vertices > INT32_MAX || indices > UINT32_MAX / sizeof(uint32_t)) {
            OB_LOG_E(OB_GEOMETRY_LOG, "%s: %llu vertices and %llu indices in its levels; more "
                     "than one buffer addresses", name, (unsigned long long)vertices,
                     (unsigned long long)indices);
            r = OB_ERR_LIMIT;
            goto fail_free_geometry;
        }
    }
    g->uv1 |= desc->texcoord1;
    g->extended |= desc->extended || g->uv1;
    g->vertex_count = mesh->vertex_count;
    g->index_count = mesh->index_count;

    size_t stride = g->uv1 ? sizeof(ob_vertex_extended_uv1)
                    : g->extended ? sizeof(ob_vertex_extended) : sizeof(ob_vertex);
    size_t vertex_size = (size_t)vertices * stride;
    bool own_vertices = false, own_indices = false;
    const void *vertex_bytes = gather_vertices(g, meshes, (uint32_t)vertices, stride,
                                               &own_vertices);
    const uint32_t *index_data = vertex_bytes ? gather_indices(g, meshes, (uint32_t)indices,
                                                               &own_indices) : NULL;
    if (!vertex_bytes || !index_data) {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: out of host memory gathering %llu vertices and %llu "
                 "indices for upload", name, (unsigned long long)vertices,
                 (unsigned long long)indices);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_staging;
    }
    g->id = desc->id ? desc->id : derive_id(name, g, vertex_bytes, vertex_size, index_data);

    g->vertex_buffer = upload(dev, name, "vertices", OB_BUFFER_VERTEX, vertex_bytes, vertex_size, &r);
    if (!g->vertex_buffer.id) goto fail_free_staging;
    g->index_buffer = upload(dev, name, "indices", OB_BUFFER_INDEX, index_data,
                             indices * sizeof(uint32_t), &r);
    if (!g->index_buffer.id) goto fail_destroy_vertex_buffer;
    if (own_vertices) ob_free((void *)vertex_bytes);
    if (own_indices) ob_free((void *)index_data);
    return g;

fail_destroy_vertex_buffer:
    ob_buffer_destroy(dev, g->vertex_buffer);
fail_free_staging:
    if (own_vertices) ob_free((void *)vertex_bytes);
    if (own_indices) ob_free((void *)index_data);
fail_free_geometry:
    ob_free(g->name);
    ob_free(g);
    set_result(out_result, r);
    return NULL;
}

void ob_geometry_destroy(ob_device *dev, ob_geometry *geo)
{
    if (!geo) return;
    if (dev) {
        ob_buffer_destroy(dev, geo->index_buffer);
        ob_buffer_destroy(dev, geo->vertex_buffer);
    } else {
        OB_LOG_E(OB_GEOMETRY_LOG, "%s: destroyed without a device; its buffers leak",
                 geo->name ? geo->name : "geometry");
    }
    ob_free(geo->name);
    ob_free(geo);
}

ob_buffer ob_geometry_vertex_buffer(const ob_geometry *g)
{
    return g ? g->vertex_buffer : (ob_buffer){0};
}

ob_buffer ob_geometry_index_buffer(const ob_geometry *g)
{
    return g ? g->index_buffer : (ob_buffer){0};
}

uint32_t ob_geometry_index_count(const ob_geometry *g) { return g ? g->index_count : 0; }
uint32_t ob_geometry_vertex_count(const ob_geometry *g) { return g ? g->vertex_count : 0; }
uint32_t ob_geometry_instance_count(const ob_geometry *g) { return g ? g->instance_count : 0; }

const ob_vertex_layout *ob_geometry_layout(const ob_geometry *g)
{
    if (!g) return NULL;
    return g->uv1 ? &extended_uv1_layout : g->extended ? &extended_layout : &standard_layout;
}

VkPrimitiveTopology ob_geometry_topology(const ob_geometry *g)
{
    return g ? g->topology : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
}

const ob_bounds *ob_geometry_bounds(const ob_geometry *g) { return g ? &g->bounds : NULL; }
uint32_t ob_geometry_id(const ob_geometry *g) { return g ? g->id : 0; }
const char *ob_geometry_name(const ob_geometry *g) { return g ? g->name : NULL; }

uint32_t ob_geometry_lod_count(const ob_geometry *g) { return g ? OB_MAX(g->lod_count, 1u) : 0; }

float ob_geometry_lod_error(const ob_geometry *g, uint32_t level)
{
    return g && level < g->lod_count ? g->lods[level].error : 0.0f;
}

uint32_t ob_geometry_lod_index_count(const ob_geometry *g, uint32_t level)
{
    if (!g) return 0;
    if (level == 0) return g->index_count;
    return level < g->lod_count ? g->lods[level].index_count : 0;
}

/* ------------------------------------------------------------ engine interface */

static void iface_draw_data(const struct ob_geometry *g, uint32_t lod, ob_draw_data *out)
{
    *out = (ob_draw_data){.vertex_buffer = g->vertex_buffer, .instance_count = 1};
    if (g->index_count > 0) {
        const geometry_lod *l = &g->lods[lod < g->lod_count ? lod : 0];
        out->index_buffer = g->index_buffer;
        out->index_type = VK_INDEX_TYPE_UINT32;
        out->count = l->index_count;
        out->first = l->first_index;
        out->vertex_offset = l->vertex_offset;
    } else {
        /* Procedural geometry (no index buffer): vertex pulling, instanced. */
        out->count = g->vertex_count;
        out->instance_count = g->instance_count;
    }
}

static uint32_t iface_lods(const struct ob_geometry *g, float rel_error[OB_LOD_MAX])
{
    rel_error[0] = 0.0f;
    uint32_t n = OB_MAX(g->lod_count, 1u);
    /* A bound of no size has no level to save: everything is level 0. */
    if (!(g->bounds.radius > 0.0f)) return 1;
    for (uint32_t l = 1; l < n; l++) rel_error[l] = g->lods[l].error / g->bounds.radius;
    return n;
}

static uint32_t iface_id(const struct ob_geometry *g) { return g->id; }

static const ob_geometry_iface geometry_iface = {
    .draw_data = iface_draw_data,
    .id = iface_id,
    .lods = iface_lods,
};

const ob_geometry_iface *ob_geometry_iface_get(void) { return &geometry_iface; }
