/* ob_model_instance.h — a model (geometry/ob_model.h) put into a scene: its
 * device resources made once (ob_model_assets: one geometry per primitive,
 * one engine material per model material), then any number of instances,
 * each a tree of entities under a root the caller gives: one entity per
 * model node (its local transform), under it one entity per primitive the
 * node places, drawing that primitive's geometry with its material. The
 * scene graph, culling and sort keys then see every primitive on its own.
 *
 * Lifecycle: ob_model_open → ob_model_assets_create (takes the model) →
 * ob_model_assets_instantiate (as often as wanted) → frames → destroy the
 * instances' root nodes (or the scene) → ob_renderer_wait_idle →
 * ob_model_assets_destroy. The entities reference the assets' geometry and
 * materials: destroy them first.
 *
 * Materials. ob_model_material_to_material is the one place where an
 * ob_model_material becomes an engine material: a PBR material
 * (materials/ob_material.h, docs/materials.md) with the file's factors, its
 * five texture slots loaded through a texture cache (base colour and
 * emissive as sRGB, the data maps as UNORM, samplers from the file) with
 * their uv sets and KHR_texture_transform, clearcoat (its three textures
 * loaded only when the material has a coat), alpha mode and cutoff, sidedness, and vertex colours when a primitive of the
 * material has them; casting shadows unless blended. A texture that does
 * not load is warned about (model, material, slot, file) and its slot left
 * empty: the material falls back to its factor and the rest renders. The
 * function also says whether the material's effects read the extended
 * vertex layout (PBR does); a primitive is uploaded in the layout its
 * material reads (the standard layout for an override of a standard kind,
 * its tangents and colours left out; TEXCOORD_1 only for a material that
 * reads it, ob_material_reads_texcoord1, the first set standing in, with a
 * warning, where a primitive of it has none).
 *
 * Mirroring: any world transform with a negative determinant, within the
 * model or above its root, is drawn with clockwise front faces and outward
 * normals by the engine itself (the pipeline manager and the normal matrix),
 * so primitives need no mirrored copy.
 *
 * Thread rule: everything here is [render thread], between frames (it makes
 * device resources, materials and nodes).
 */
#ifndef OB_MODEL_INSTANCE_H
#define OB_MODEL_INSTANCE_H

#include "ob_geometry.h"
#include "ob_material.h"
#include "ob_model.h"
#include "ob_renderer.h"
#include "ob_scene.h"
#include "ob_texture.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What converting one model material needs. */
typedef struct ob_model_material_context {
    ob_material_library *library;
    ob_texture_cache *textures;   /* where its textures load; NULL: drawn without them (warned) */
    const ob_model *model;     /* the material's model: images, path */
    const char *model_name;    /* for names and messages: "BoxTextured.glb" */
} ob_model_material_context;

/* An engine material for model->materials[index], named
 * "<model_name>/<material name>"; *out_extended_layout (may be NULL) says
 * whether its effects read the extended vertex layout. NULL with
 * *out_result set (may be NULL) when the library refuses it. The caller
 * owns the material (ob_material_destroy). [render thread] */
ob_material *ob_model_material_to_material(const ob_model_material_context *ctx, uint32_t index,
                                           bool *out_extended_layout, ob_result *out_result);

/* True when a primitive drawing with model->materials[index] has vertex
 * colours (COLOR_0, PLY colours). Primitives of that material without them
 * are uploaded white in the extended layout, so a material multiplying its
 * base colour by COLOR0 (ob_material_pbr.vertex_colors) draws them right
 * too. [any thread] */
bool ob_model_material_has_vertex_colors(const ob_model *model, uint32_t index);

typedef struct ob_model_assets ob_model_assets;

#define OB_MODEL_ASSETS_IDS_PER_PRIMITIVE 4u

typedef struct ob_model_assets_desc {
    ob_renderer *renderer;           /* geometry goes to its device */
    ob_material_library *materials;  /* the one the views draw with */
    /* Where the model's textures load, shared with other models (identical
     * images load once); it must outlive the assets. NULL → the assets make
     * their own cache, destroyed with them. */
    ob_texture_cache *textures;
    const char *name;                /* for geometry, materials and logs; NULL → the model's file name */
    /* Geometry ids for command hashes: primitive p's variant v (0..3: 0 the
     * standard layout, 1 the extended one, 3 the extended one with
     * TEXCOORD1 for a material reading the second uv set) gets
     * first_geometry_id + 4·p + v, so the model reserves
     * OB_MODEL_ASSETS_IDS_PER_PRIMITIVE × primitive_count ids whatever is
     * uploaded; 0 → each derived from its contents. */
    uint32_t first_geometry_id;
    /* Coarser levels of detail made for each primitive (0..7,
     * ob_geometry_make_lods: each half the triangles of the one before);
     * a primitive that cannot have them is drawn at level 0, with a
     * warning naming the file and the primitive. */
    uint32_t lods;
} ob_model_assets_desc;

/* Takes `model` (closed by ob_model_assets_destroy, or here on failure) and
 * makes one engine material per model material that a primitive uses.
 * Geometry is uploaded by instantiation, once per primitive and variant
 * (its material's layout or the standard one for an override; mirrored or
 * not), and shared by every later instance. NULL with *out_result set (may be
 * NULL) on failure: the geometry's or the material's error, logged with the
 * model's file and the primitive or material; nothing stays allocated.
 * [render thread] */
ob_model_assets *ob_model_assets_create(const ob_model_assets_desc *desc, ob_model *model,
                                        ob_result *out_result);

/* Destroys the geometry (deferred) and the materials and closes the model.
 * NULL is a no-op. [render thread, after the entities drawing them are gone
 * and ob_renderer_wait_idle] */
void ob_model_assets_destroy(ob_model_assets *a);

const ob_model *ob_model_assets_model(const ob_model_assets *a);
uint32_t ob_model_assets_geometry_count(const ob_model_assets *a);   /* uploads so far */
ob_material *ob_model_assets_material(const ob_model_assets *a, uint32_t model_material);   /* NULL if unused */

/* Creates the model's entities under `root` (an existing node: the model's
 * root, whose transform places the model): one per model node, named as
 * the node (carrying the node's glTF light, if any: ob_model_light), and
 * under each one per primitive it places, named as the
 * primitive, renderable with the primitive's geometry and material (or
 * `override`, when not NULL, for every primitive: it must read the standard
 * layout, like every material of the library's standard kinds).
 * *out_entities (may be NULL) gets the number of entities made.
 * Failure (node creation, an upload): the error, and the entities made so
 * far are destroyed again (root itself stays). [render thread] */
ob_result ob_model_assets_instantiate(ob_model_assets *a, ob_scene *scene, ob_node *root,
                                      ob_material *override, uint32_t *out_entities);

#ifdef __cplusplus
}
#endif
#endif /* OB_MODEL_INSTANCE_H */
