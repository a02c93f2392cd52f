/* ob_geometry.h — geometry on the GPU: one vertex buffer, one 32-bit index
 * buffer, the vertex layout, the primitive topology and the bounds
 * (Hieroglyph's GeometryDX11). The pipeline manager binds it; effects match
 * their vertex inputs against its layout.
 *
 * Lifecycle: ob_geometry_create uploads an ob_mesh (the mesh stays the
 * caller's; the geometry keeps no pointer to it) → draw in frames →
 * ob_geometry_destroy, which may follow a draw recorded in the current frame
 * (the buffers are destroyed deferred, after the frame slot completes).
 *
 * Thread rule: create and destroy are [render thread] (they create and
 * destroy device resources). A geometry is immutable after creation: every
 * accessor is [any thread], so recording workers read it freely.
 */
#ifndef OB_GEOMETRY_H
#define OB_GEOMETRY_H

#include "ob_mesh.h"
#include "ob_resources.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ob_vertex_attribute {
    uint32_t location;
    VkFormat format;
    uint32_t offset;        /* bytes from the start of the vertex */
    const char *semantic;   /* "POSITION", "NORMAL", "TEXCOORD0", "COLOR0", "TANGENT" */
} ob_vertex_attribute;

typedef struct ob_vertex_layout {
    uint32_t stride;
    uint32_t attribute_count;
    ob_vertex_attribute attributes[8];
} ob_vertex_layout;

/* The layout of ob_vertex: location 0 POSITION (R32G32B32_SFLOAT, offset 0),
 * 1 NORMAL (R32G32B32_SFLOAT, 12), 2 TEXCOORD0 (R32G32_SFLOAT, 24);
 * stride 32. A static constant, never NULL. [any thread] */
const ob_vertex_layout *ob_vertex_layout_standard(void);

/* One vertex of the extended layout (52 bytes, no padding): the standard
 * vertex followed by COLOR_0 and the tangent. */
typedef struct ob_vertex_extended {
    float position[3];
    float normal[3];
    float uv[2];
    uint8_t color[4];       /* linear RGBA8; 255,255,255,255 when the mesh has none */
    float tangent[4];       /* xyz unit, w = ±1 bitangent sign; (1,0,0,1) when the mesh has none */
} ob_vertex_extended;

/* The layout of ob_vertex_extended, for meshes with vertex colours or
 * tangents (glTF models): location 0 POSITION (R32G32B32_SFLOAT, 0),
 * 1 NORMAL (R32G32B32_SFLOAT, 12), 2 TEXCOORD0 (R32G32_SFLOAT, 24),
 * 3 COLOR0 (R8G8B8A8_UNORM, 32), 4 TANGENT (R32G32B32A32_SFLOAT, 36);
 * stride 52. A static constant, never NULL. [any thread] */
const ob_vertex_layout *ob_vertex_layout_extended(void);

/* The extended vertex followed by a second uv set (60 bytes): meshes with
 * TEXCOORD_1 (ob_mesh.uv1) drawn by materials that read it. */
typedef struct ob_vertex_extended_uv1 {
    ob_vertex_extended base;
    float uv1[2];
} ob_vertex_extended_uv1;

/* ob_vertex_layout_extended() plus location 5 TEXCOORD1 (R32G32_SFLOAT,
 * 52); stride 60. A static constant, never NULL. [any thread] */
const ob_vertex_layout *ob_vertex_layout_extended_uv1(void);

typedef struct ob_geometry ob_geometry;

/* Levels of detail: level 0 (desc.mesh) and at most this many levels in
 * all. */
#define OB_GEOMETRY_MAX_LODS 8u

/* A coarser level of a geometry: drawn instead of the finer ones where its
 * error projects to less than the views' pixel tolerance
 * (ob_views_set_lod_error). */
typedef struct ob_geometry_lod {
    const ob_mesh *mesh;   /* its vertices are uploaded like level 0's (same layout) */
    /* > 0 and finite, in the mesh's units: the farthest the level's surface
     * lies from level 0's (ob_mesh_deviation measures it). Levels come
     * finest first: each error at least the one before. */
    float error;
} ob_geometry_lod;

/* Measures each level's error against level 0 (ob_mesh_deviation), kept
 * at least the level before's so the chain is valid for
 * ob_geometry_desc.lods. Fails as ob_mesh_deviation does (levels[].error
 * then unset). */
ob_result ob_geometry_measure_lods(const ob_mesh *level0, ob_geometry_lod *levels, uint32_t count);

/* Up to `count` coarser levels of level0 made by ob_mesh_simplify, each
 * with half the indices of the one before, into meshes[0..] (release each)
 * and levels[0..] (their meshes and errors, ready for ob_geometry_desc);
 * *out_count how many. Stops early, with fewer, where a level would keep
 * more than nine tenths of the one before (seams and borders stay, so a
 * mesh of split vertices makes none). Each level's error is measured
 * against level0 with ob_mesh_deviation, kept non-decreasing and > 0.
 * Errors: OB_ERR_LIMIT over OB_GEOMETRY_MAX_LODS - 1 levels,
 * OB_ERR_INVALID_ARGUMENT, ob_mesh_simplify's and ob_mesh_deviation's (no
 * level then left allocated). [any thread] */
ob_result ob_geometry_make_lods(const ob_mesh *level0, uint32_t count, ob_mesh *meshes,
                                ob_geometry_lod *levels, uint32_t *out_count);

typedef struct ob_geometry_desc {
    const ob_mesh *mesh;
    const char *name;       /* copied; NULL → "geometry". Used in logs and debug names */
    /* 0 = TRIANGLE_LIST (so POINT_LIST, whose value is 0, cannot be chosen).
     * Also LINE_LIST, LINE_STRIP, TRIANGLE_STRIP, TRIANGLE_FAN; the mesh's
     * indices are then read as that topology. */
    VkPrimitiveTopology topology;
    /* Stable id for command hashes (never a pointer, so hashes repeat across
     * runs). 0 → derived from a hash of the name, the counts and the vertex
     * and index data: equal geometry gets an equal id, which is what a
     * command hash needs. Give explicit ids if you need them unique. */
    uint32_t id;
    /* Procedural geometry (mesh NULL): no buffers; a draw is vertex_count
     * vertices × instance_count instances whose shader pulls its own data
     * (particles). Bounds are then unknown: the entity supplies its own. */
    uint32_t vertex_count;
    uint32_t instance_count;   /* 0 → 1 */
    /* Upload in the extended layout (ob_vertex_extended): missing colours
     * become 255,255,255,255, missing tangents (1,0,0,1). A mesh with
     * tangents or colours is uploaded extended even without this flag; to
     * draw such a mesh with a standard-layout effect, pass a copy of the
     * ob_mesh with those two pointers set to NULL. */
    bool extended;
    /* Upload in the extended layout with TEXCOORD1 (ob_vertex_extended_uv1):
     * a mesh without uv1 repeats its uv there. A mesh with uv1 is uploaded
     * so even without this flag; to draw it with a layout without TEXCOORD1,
     * pass a copy of the ob_mesh with uv1 set to NULL. */
    bool texcoord1;
    /* Coarser levels after desc->mesh (level 0), finest first; at most
     * OB_GEOMETRY_MAX_LODS - 1; none for procedural geometry. They share
     * level 0's buffers, topology and bounds (a level pokes out of the bound
     * by at most its error, which is less than the tolerance where it is
     * drawn), and each is validated like level 0. */
    const ob_geometry_lod *lods;
    uint32_t lod_count;
} ob_geometry_desc;

/* Validates the mesh (and each level's) for the topology first (ob_mesh_validate_primitives:
 * indices in range, finite attributes; logged under the name) and uploads
 * nothing if it fails. Then uploads the vertices and indices into
 * device-local buffers (staged, waits for the copy; TRANSFER_SRC too, so
 * tools and tests can read them back) and computes the bounds
 * from the vertices (mesh->bounds is not trusted).
 * Returns NULL and sets *out_result (may be NULL) on failure:
 * OB_ERR_INVALID_ARGUMENT (no device, desc or mesh; bad mesh; a level
 * without a mesh, with an error not finite, not positive or less than the
 * level before's, or on procedural geometry), OB_ERR_LIMIT (more levels
 * than OB_GEOMETRY_MAX_LODS),
 * OB_ERR_OUT_OF_RANGE / OB_ERR_NON_FINITE (mesh contents),
 * OB_ERR_UNSUPPORTED (topology), or the buffer creation's error. Nothing
 * stays allocated on failure. [render thread] */
ob_geometry *ob_geometry_create(ob_device *dev, const ob_geometry_desc *desc, ob_result *out_result);

/* Destroys the buffers deferred and frees the object at once. NULL is a
 * no-op. [render thread] */
void ob_geometry_destroy(ob_device *dev, ob_geometry *geo);

/* Accessors [any thread]. On NULL they return a zero handle, 0 or NULL
 * (the topology accessor: TRIANGLE_LIST). */
ob_buffer ob_geometry_vertex_buffer(const ob_geometry *g);
ob_buffer ob_geometry_index_buffer(const ob_geometry *g);   /* VK_INDEX_TYPE_UINT32 */
uint32_t ob_geometry_index_count(const ob_geometry *g);      /* level 0's */
uint32_t ob_geometry_vertex_count(const ob_geometry *g);
uint32_t ob_geometry_instance_count(const ob_geometry *g);  /* 1 for meshes */
const ob_vertex_layout *ob_geometry_layout(const ob_geometry *g);  /* standard, extended or extended_uv1 */
VkPrimitiveTopology ob_geometry_topology(const ob_geometry *g);
const ob_bounds *ob_geometry_bounds(const ob_geometry *g);
uint32_t ob_geometry_id(const ob_geometry *g);              /* never 0 for a live geometry */
const char *ob_geometry_name(const ob_geometry *g);
/* Levels of detail: how many (1 without coarser ones; 0 on NULL), and level
 * `level`'s error (0 for level 0 and out of range) and index count (0 out
 * of range). */
uint32_t ob_geometry_lod_count(const ob_geometry *g);
float ob_geometry_lod_error(const ob_geometry *g, uint32_t level);
uint32_t ob_geometry_lod_index_count(const ob_geometry *g, uint32_t level);

/* The engine's interface to geometry (engine/ob_renderer_layer.h): a
 * geometry's draw data and stable id. ob_views_create installs it. Static
 * data. [any thread] */
const struct ob_geometry_iface *ob_geometry_iface_get(void);

#ifdef __cplusplus
}
#endif
#endif /* OB_GEOMETRY_H */
