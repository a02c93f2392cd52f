/* ob_mesh.h — CPU triangle meshes: the standard vertex, bounds, validation,
 * normal generation and the shape generators (box, sphere, plane, cone,
 * torus, full-screen triangle). Model files load into the same struct
 * (ob_model_load_mesh in this header, implemented in ob_model.c).
 *
 * Conventions: right-handed, +Y up; a mesh is an indexed triangle list whose
 * front faces wind counter-clockwise seen from outside; uv (0,0) is the
 * top-left of an image (Vulkan sampling convention).
 *
 * Lifecycle: a mesh is plain data. Generators and ob_model_load_mesh fill a
 * caller-provided ob_mesh whose arrays come from ob_malloc; the caller owns
 * them and frees them with ob_mesh_release. A zeroed ob_mesh is empty.
 *
 * Thread rule: every function is [any thread]; a mesh is not synchronized,
 * so one thread writes it at a time. ob_model_load_mesh may run on several
 * threads at once (see there).
 */
#ifndef OB_MESH_H
#define OB_MESH_H

#include "ob_core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The standard interleaved vertex (32 bytes): location 0 position,
 * 1 normal, 2 uv — see ob_vertex_layout_standard() in ob_geometry.h. */
typedef struct ob_vertex {
    float position[3];
    float normal[3];
    float uv[2];
} ob_vertex;

/* Axis-aligned box plus a bounding sphere centred at the box centre whose
 * radius is the largest distance of any vertex from that centre. */
typedef struct ob_bounds {
    float min[3], max[3];
    float center[3];
    float radius;
} ob_bounds;

typedef struct ob_mesh {
    ob_vertex *vertices;
    uint32_t vertex_count;
    /* Optional arrays parallel to `vertices` (NULL when absent; generators
     * leave them NULL; ob_mesh_release frees them). A mesh with either is
     * uploaded in the extended layout (ob_vertex_layout_extended). */
    float (*tangents)[4];   /* xyz unit tangent, w = ±1 bitangent sign (glTF convention) */
    uint8_t (*colors)[4];   /* vertex colour COLOR_0, linear, RGBA8 */
    /* The second uv set (TEXCOORD_1), same convention as uv. A mesh with it
     * is uploaded in the extended layout with TEXCOORD1
     * (ob_vertex_layout_extended_uv1). */
    float (*uv1)[2];
    uint32_t *indices;      /* triangle list: index_count / 3 triangles */
    uint32_t index_count;
    ob_bounds bounds;       /* valid after a generator, ob_model_load_mesh or ob_mesh_compute_bounds */
} ob_mesh;

/* Frees the arrays (tangents and colours too) and zeroes the mesh. NULL or a zeroed mesh is a no-op. */
void ob_mesh_release(ob_mesh *mesh);

/* Bounds of `count` vertices into *out_bounds (zeroed when count is 0).
 * OB_ERR_NON_FINITE (logged with the vertex index) if a position is NaN/Inf,
 * OB_ERR_INVALID_ARGUMENT for NULL arguments; *out_bounds is zeroed on error. */
ob_result ob_bounds_compute(const ob_vertex *vertices, uint32_t count, ob_bounds *out_bounds);

/* mesh->bounds = bounds of its vertices (ob_bounds_compute). */
ob_result ob_mesh_compute_bounds(ob_mesh *mesh);

/* Checks a mesh before it is used or uploaded: non-empty, index_count a
 * multiple of 3, every index < vertex_count, every position, normal and uv
 * finite, and every tangent and second uv (when present) finite. Logs each problem (the first few, then a count) prefixed with
 * `name` (NULL → "mesh"), e.g. "crate: index 1234 = 99999 out of range
 * (8 vertices)". Returns the first problem found: OB_ERR_INVALID_ARGUMENT
 * (NULL, empty, missing arrays, count not a multiple of 3),
 * OB_ERR_OUT_OF_RANGE (index), OB_ERR_NON_FINITE (attribute). */
ob_result ob_mesh_validate(const ob_mesh *mesh, const char *name);

/* The same checks for other primitive layouts: index_count must be a
 * multiple of indices_per_primitive (1 for strips, 2 for line lists, 3 for
 * triangle lists) and at least min_indices. ob_mesh_validate is (3, 3). */
ob_result ob_mesh_validate_primitives(const ob_mesh *mesh, const char *name,
                                      uint32_t indices_per_primitive, uint32_t min_indices);

/* Replaces every vertex normal by the area-weighted sum of the normals of
 * the triangles using it, normalized; a vertex whose sum vanishes (only
 * degenerate triangles, or none) gets (0,1,0). Vertices are not split:
 * share vertices between faces only where the surface should look smooth.
 * OB_ERR_INVALID_ARGUMENT / OB_ERR_OUT_OF_RANGE (logged) on a bad mesh, which
 * is then left unchanged; OB_ERR_OUT_OF_HOST_MEMORY likewise. */
ob_result ob_mesh_generate_normals(ob_mesh *mesh);

/* Fills mesh->tangents (allocating the array if it is NULL) with unit
 * tangents orthogonal to each vertex normal, w = ±1, in the glTF / MikkTSpace
 * convention: tangent along increasing u, bitangent = cross(normal,
 * tangent.xyz) · w along increasing v measured towards the TOP of the image
 * (the normal map's +Y). uv_origin_bottom_left says which way the mesh's v
 * runs: false for the ob_mesh convention (v = 0 at the top of the image,
 * model files loaded with flip_uv), true for assimp's raw uv.
 * Per triangle, the tangent and bitangent come from the uv derivatives
 * (solving the edge equations), are normalized and added to its three
 * vertices weighted by the corner angle (as MikkTSpace does); per vertex the
 * sum is Gram-Schmidt orthogonalized against the normal and w is the sign of
 * the accumulated bitangent against cross(normal, tangent). What differs
 * from the full MikkTSpace algorithm: vertices are not split where
 * triangles sharing one disagree on handedness (mirrored uv islands joined
 * at a vertex) — the sum decides; and a vertex whose triangles all have
 * degenerate uv gets an arbitrary unit tangent perpendicular to its normal
 * (w = 1) rather than one borrowed from its neighbours. Normals must be
 * unit length (as validated meshes and loaded models have them).
 * OB_ERR_INVALID_ARGUMENT / OB_ERR_OUT_OF_RANGE (logged) on a bad mesh,
 * OB_ERR_OUT_OF_HOST_MEMORY; the mesh is then unchanged. [any thread] */
ob_result ob_mesh_generate_tangents(ob_mesh *mesh, bool uv_origin_bottom_left);

/* ------------------------------------------------------------ generators
 * Each fills *out (which it first zeroes; the caller releases it) with unit
 * normals, uv in [0,1] and bounds, and returns OB_OK. Bad parameters
 * (non-finite or non-positive sizes, too few segments, more than
 * OB_MESH_MAX_SEGMENTS, or two segment counts whose product is more than
 * OB_MESH_MAX_GENERATED_CELLS: sphere slices x stacks, plane
 * subdivisions², torus major x minor segments) give OB_ERR_INVALID_ARGUMENT with a log line;
 * allocation failure OB_ERR_OUT_OF_HOST_MEMORY. *out stays zeroed on error. */

#define OB_MESH_MAX_SEGMENTS 4096u
#define OB_MESH_MAX_GENERATED_CELLS (1u << 20)   /* about 50 MB of vertices and indices */

/* Box centred at the origin: 24 vertices (4 per face, flat normals), 36 indices. */
ob_result ob_mesh_box(const float half_extents[3], ob_mesh *out);

/* UV sphere centred at the origin, poles on ±Y. slices ≥ 3 around Y,
 * stacks ≥ 2 from pole to pole. Pole rows have one vertex per slice:
 * 2·slices + (stacks−1)·(slices+1) vertices, 6·slices·(stacks−1) indices. */
ob_result ob_mesh_sphere(float radius, uint32_t slices, uint32_t stacks, ob_mesh *out);

/* Plane in XZ centred at the origin, facing +Y; width along X, depth along
 * Z; subdivisions ≥ 1 cells per side: (n+1)² vertices, 6n² indices. */
ob_result ob_mesh_plane(float width, float depth, uint32_t subdivisions, ob_mesh *out);

/* Cone around +Y: base disc (capped) at y=0, apex at y=height, slices ≥ 3.
 * Smooth side normals; the apex has one vertex per slice.
 * 3·slices + 3 vertices, 6·slices indices. */
ob_result ob_mesh_cone(float radius, float height, uint32_t slices, ob_mesh *out);

/* Torus around the Y axis in the XZ plane; 0 < minor_radius < major_radius,
 * both segment counts ≥ 3: (major+1)(minor+1) vertices,
 * 6·major·minor indices. */
ob_result ob_mesh_torus(float major_radius, float minor_radius, uint32_t major_segments,
                        uint32_t minor_segments, ob_mesh *out);

/* How far apart two triangle-list meshes' surfaces are, both ways: the
 * largest distance from a point of one (its vertices, edge midpoints and
 * triangle centroids) to the nearest triangle of the other, in *out. The
 * error of a level of detail (ob_geometry_lod.error) against level 0. The
 * nearest triangle is searched in a uniform grid over the other mesh (up to
 * 128 cells an axis), exactly: the same figure as testing every triangle,
 * in time near the points' count for meshes whose levels lie close.
 * Errors: either mesh failing ob_mesh_validate (its error),
 * OB_ERR_OUT_OF_HOST_MEMORY for the grid (logged). */
ob_result ob_mesh_deviation(const ob_mesh *a, const ob_mesh *b, float *out);

/* A coarser copy of a triangle-list mesh, for a level of detail
 * (ob_geometry_lod): edges are collapsed cheapest first, one end onto the
 * other, costed by the summed squared distances to the original planes
 * around them (quadric error metrics, Garland & Heckbert 1997), until at
 * most target_index_count indices are left or the next collapse would cost
 * more than max_error (INFINITY: no bound). Every output vertex is an input
 * vertex, with its normal, uv, tangent, colour and second uv, so textures
 * and shading carry over. Kept in place: vertices on a seam (several
 * vertices at one position), on a border or on a non-manifold edge, so the
 * outline and the uv charts stay; a collapse that would fold the surface
 * (the link condition) or turn a triangle over is skipped. Triangles with
 * two corners at one point draw nothing and are dropped. Deterministic.
 * *out_error (may be NULL): the square root of the costliest collapse made,
 * in the mesh's units, which bounds how far a moved vertex lies from the
 * planes it left; ob_mesh_deviation measures the real distance. *out is a new mesh (ob_mesh_release it), a copy of
 * the input when nothing could be collapsed. Errors: ob_mesh_validate's,
 * OB_ERR_INVALID_ARGUMENT for a NULL out, a negative or NaN max_error or
 * a mesh of degenerate triangles only, OB_ERR_OUT_OF_HOST_MEMORY; *out is
 * then zeroed. [any thread] */
ob_result ob_mesh_simplify(const ob_mesh *in, uint32_t target_index_count, float max_error,
                           ob_mesh *out, float *out_error);

/* One triangle covering clip space [-1,1]² at z=0 — positions (-1,-1),
 * (3,-1), (-1,3) with uv (0,0), (2,0), (0,2) so uv spans 0..1 on screen
 * (uv 0,0 at the top-left in Vulkan). Normal +Z. Its winding flips with
 * Vulkan's y-down viewport: draw it with culling off. */
ob_result ob_mesh_fullscreen_triangle(ob_mesh *out);

/* ------------------------------------------------------------ model files */

typedef struct ob_model_desc {
    const char *path;   /* OBJ, PLY, glTF 2 (.gltf/.glb) or any format assimp reads */
    bool flip_uv;       /* v → 1 − v: assimp hands out uv with (0,0) at the bottom-left
                           of the image; set this to sample with Vulkan's top-left origin */
    /* Files the model refers to (glTF buffers and images, an OBJ's mtllib
     * and textures) must resolve, after symbolic links, inside the model
     * file's folder; one that does not is refused, naming it, and the model
     * with it (OB_ERR_IO). true allows any folder: for trusted content only. */
    bool allow_any_folder;
} ob_model_desc;

typedef struct ob_model_info {
    uint32_t mesh_count;      /* mesh instances merged (a mesh placed by two nodes counts twice) */
    uint32_t vertex_count;
    uint32_t triangle_count;
} ob_model_info;

/* SHAPE ONLY: MATERIALS AND TEXTURES ARE DROPPED. A textured model loaded
 * this way renders with whatever one material the caller gives it (a white
 * cube for BoxTextured.glb). To show a model as its file describes it (its
 * materials, textures and node structure), use ob_stack_add_model
 * (ob_stack_content.h) in one call, or ob_model_open (ob_model.h) →
 * ob_model_assets_create → ob_model_assets_instantiate
 * (ob_model_instance.h) on a scene of your own. This function is for
 * callers that want only the geometry: collision, bounds, one flat mesh.
 *
 * Loads every mesh of a model file into one ob_mesh: each mesh instance is
 * transformed by its node's accumulated transform (normals by the
 * inverse-transpose; a mirroring transform keeps faces counter-clockwise),
 * polygons are triangulated, missing normals generated (smooth), identical
 * vertices joined per mesh, points and lines dropped.
 * Before anything is used, the raw data from the file is checked (every face
 * index < the mesh's vertex count, finite positions, normals and uv), and the
 * merged result again (at least one triangle).
 * Errors (logged with the path; *out and *out_info stay zeroed):
 * OB_ERR_INVALID_ARGUMENT (no desc/path), OB_ERR_IO (the file is missing or
 * unreadable), OB_ERR_PARSE (assimp rejected it; its message is quoted),
 * OB_ERR_BAD_MODEL (no triangles, an index out of range, a non-finite value,
 * a singular node transform: names the mesh index/name and the problem),
 * OB_ERR_LIMIT (more than 2^32−1 vertices or indices),
 * OB_ERR_OUT_OF_HOST_MEMORY.
 * [any thread]: loads may run concurrently; only assimp's parse step is
 * serialized (its C API keeps the last error text in one process-wide string). */
/* out_info may be NULL. */
ob_result ob_model_load_mesh(const ob_model_desc *desc, ob_mesh *out, ob_model_info *out_info);

#ifdef __cplusplus
}
#endif
#endif /* OB_MESH_H */
