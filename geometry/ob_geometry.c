/* ob_geometry.c — uploading meshes into vertex + index buffers. */
#include "ob_geometry.h"

#include "ob_renderer_layer.h"

#include <stdio.h>
#include <string.h>

#define OB_GEOMETRY_LOG "geometry"

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
};

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
 * stride 60), defaults where an optional array is missing (uv1: the first
 * set). NULL when out of memory. */
static void *interleave_extended(const ob_mesh *mesh, bool uv1)
{
    const size_t stride = uv1 ? sizeof(ob_vertex_extended_uv1) : sizeof(ob_vertex_extended);
    uint8_t *out = ob_malloc((size_t)mesh->vertex_count * stride);
    if (!out) return NULL;
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
    return out;
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
 * and extended gets two ids. */
static uint32_t derive_id(const char *name, const ob_mesh *mesh, const void *vertex_bytes,
                          size_t vertex_size)
{
    uint64_t h = ob_hash_str(OB_HASH_SEED, name);
    h = ob_hash_u64(h, mesh->vertex_count);
    h = ob_hash_u64(h, mesh->index_count);
    h = ob_hash_u64(h, vertex_size);
    h = ob_hash_bytes(h, vertex_bytes, vertex_size);
    h = ob_hash_bytes(h, mesh->indices, (size_t)mesh->index_count * sizeof(uint32_t));
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
    g->topology = desc->topology ? desc->topology : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    g->extended = desc->extended;
    g->id = desc->id ? desc->id
                     : (uint32_t)ob_hash_u64(ob_hash_str(OB_HASH_SEED, name),
                                             ((uint64_t)g->vertex_count << 32) | g->instance_count);
    return g;
}

ob_geometry *ob_geometry_create(ob_device *dev, const ob_geometry_desc *desc, ob_result *out_result)
{
    set_result(out_result, OB_OK);
    if (desc && !desc->mesh && desc->vertex_count > 0) return create_procedural(desc, out_result);
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
    g->vertex_count = mesh->vertex_count;
    g->index_count = mesh->index_count;
    g->instance_count = 1;
    g->topology = topology;
    g->uv1 = desc->texcoord1 || mesh->uv1;
    g->extended = desc->extended || mesh->tangents || mesh->colors || g->uv1;

    void *interleaved = NULL;
    const void *vertex_bytes = mesh->vertices;
    size_t vertex_size = (size_t)mesh->vertex_count * sizeof(ob_vertex);
    if (g->extended) {
        interleaved = interleave_extended(mesh, g->uv1);
        if (!interleaved) {
            OB_LOG_E(OB_GEOMETRY_LOG, "%s: out of host memory interleaving %u extended vertices",
                     name, mesh->vertex_count);
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            goto fail_free_geometry;
        }
        vertex_bytes = interleaved;
        vertex_size = (size_t)mesh->vertex_count *
                      (g->uv1 ? sizeof(ob_vertex_extended_uv1) : sizeof(ob_vertex_extended));
    }
    g->id = desc->id ? desc->id : derive_id(name, mesh, vertex_bytes, vertex_size);

    g->vertex_buffer = upload(dev, name, "vertices", OB_BUFFER_VERTEX, vertex_bytes, vertex_size, &r);
    if (!g->vertex_buffer.id) goto fail_free_interleaved;
    g->index_buffer = upload(dev, name, "indices", OB_BUFFER_INDEX, mesh->indices,
                             (uint64_t)mesh->index_count * sizeof(uint32_t), &r);
    if (!g->index_buffer.id) goto fail_destroy_vertex_buffer;
    ob_free(interleaved);
    return g;

fail_destroy_vertex_buffer:
    ob_buffer_destroy(dev, g->vertex_buffer);
fail_free_interleaved:
    ob_free(interleaved);
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

/* ------------------------------------------------------------ engine interface */

static void iface_draw_data(const struct ob_geometry *g, ob_draw_data *out)
{
    *out = (ob_draw_data){.vertex_buffer = g->vertex_buffer, .instance_count = 1};
    if (g->index_count > 0) {
        out->index_buffer = g->index_buffer;
        out->index_type = VK_INDEX_TYPE_UINT32;
        out->count = g->index_count;
    } else {
        /* Procedural geometry (no index buffer): vertex pulling, instanced. */
        out->count = g->vertex_count;
        out->instance_count = g->instance_count;
    }
}

static uint32_t iface_id(const struct ob_geometry *g) { return g->id; }

static const ob_geometry_iface geometry_iface = {
    .draw_data = iface_draw_data,
    .id = iface_id,
};

const ob_geometry_iface *ob_geometry_iface_get(void) { return &geometry_iface; }
