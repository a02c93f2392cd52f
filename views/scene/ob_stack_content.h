/* ob_stack_content.h — content into an ob_stack (ob_stack.h) in a few calls:
 * a model file with its materials and textures, a sun, a scene file, and
 * the camera framed on what is there. What these calls load, the stack owns
 * and ob_stack_destroy frees, in the right order.
 *
 *   ob_stack *s = ob_stack_create(&(ob_stack_desc){.width = 640, .height = 480}, &r);
 *   ob_node *model = ob_stack_add_model(s, &(ob_stack_model_desc){.path = "box.glb"}, &r);
 *   ob_stack_add_sun(s, NULL, &r);            // the default sun, casting shadows
 *   ob_stack_fit_camera(s, model);            // or NULL: the whole scene
 *   ob_stack_frame(s, 0.0);
 *   ob_image_write_png(s->device, ob_stack_final_image(s), "box.png");
 *   ob_stack_destroy(s);                      // the model, its textures, the sun, ...
 *
 * Models. ob_stack_add_model opens the file (ob_model_open: glTF 2, OBJ,
 * PLY and what else assimp reads), makes its materials with their textures
 * (ob_model_assets_create) and places it under a root node of its own
 * (ob_model_assets_instantiate): one entity per node of the file, one per
 * primitive. Each file is opened once per stack: adding it again places
 * another instance of the same geometry, materials and textures. Textures
 * load into one cache per stack, so identical images load once.
 * ob_model_instance.h is the same path step by step, for a scene of your
 * own; ob_model_load_mesh (ob_mesh.h) is the shape alone, without materials.
 *
 * Failure. Every call returns (or sets) an ob_result, logs an error line
 * naming the file (the model or scene file) and the result, and leaves the
 * stack as it was: it keeps rendering what it had.
 *
 * Ownership. The nodes these calls make belong to s->scene like any other;
 * the program may move them, hide them or destroy them (a model's root
 * node with its subtree). The models' geometry, materials and textures and
 * the loaded scene files stay the stack's until ob_stack_destroy: it
 * unloads the scene files first, destroys the scene, then the models'
 * assets and textures, before the views and the material library.
 *
 * Thread rule: [render thread, between frames] for every function (they
 * make device resources, materials and nodes).
 */
#ifndef OB_STACK_CONTENT_H
#define OB_STACK_CONTENT_H

#include "ob_framing.h"
#include "ob_scene_load.h"
#include "ob_stack.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ob_stack_model_desc {
    const char *path;            /* the model file; required */
    ob_node *parent;             /* NULL → the scene's root */
    const char *name;            /* the root node's name; NULL → the file's name ("box.glb") */
    /* The root node's transform, relative to parent (later: ob_node_set_*
     * on the returned node). */
    double position[3];
    double rotation[4];          /* quaternion x, y, z, w; all zero → identity */
    float scale[3];              /* all zero → 1, 1, 1 */
    /* Draws every primitive with this material instead of the model's own
     * (one of the library's standard kinds). NULL → the file's materials. */
    ob_material *material;
    /* Files the model refers to must resolve inside its folder unless this
     * is true (ob_model_desc.allow_any_folder): trusted content only. */
    bool allow_any_folder;
    /* Coarser levels of detail for each primitive (0..7; more are taken as
     * 7): ob_geometry_make_lods, each with half the triangles of the one
     * before, drawn where their error stays within the views' tolerance
     * (ob_views_set_lod_error). The same file with another count is
     * another set of geometry. */
    uint32_t lods;
} ob_stack_model_desc;

/* Loads desc->path with its materials and textures (or finds it loaded)
 * and places an instance under a new root node, which it returns (the
 * model's nodes and primitives are entities under it). Failure: NULL,
 * *out_result set (may be NULL): OB_ERR_INVALID_ARGUMENT (no desc or path,
 * a non-finite transform), the model loader's result (OB_ERR_IO,
 * OB_ERR_PARSE, OB_ERR_BAD_MODEL, OB_ERR_UNSUPPORTED, OB_ERR_LIMIT, ...),
 * or the device's; logged naming the file; nothing is added to the scene.
 * A texture that does not load is a warning, not a failure: its material
 * keeps its factors (ob_model_instance.h). [render thread, between frames] */
ob_node *ob_stack_add_model(ob_stack *s, const ob_stack_model_desc *desc, ob_result *out_result);

/* A directional light under the scene's root, white-ish (1, 0.97, 0.92),
 * intensity 1, casting shadows: the sun a scene file without "lights"
 * gets. It shines along direction (need not be unit length); NULL → that
 * file sun's (−0.11, −0.77, −0.63), from above and in front. Returns its
 * node (ob_node_set_light changes colour, intensity or shadows). Failure:
 * NULL, *out_result set (may be NULL): OB_ERR_INVALID_ARGUMENT for a zero
 * or non-finite direction (logged), or the node's result; nothing added.
 * [render thread, between frames] */
ob_node *ob_stack_add_sun(ob_stack *s, const double direction[3], ob_result *out_result);

/* Points s->camera at the renderables under node (node included; NULL →
 * every renderable of the scene), so that their bounding sphere fills the
 * view from a 3/4 view above (ob_framing_aim_camera), for the final
 * image's aspect. Updates the scene (dt 0) to measure. Failure, logged:
 * OB_ERR_NOT_FOUND (nothing renderable there; names the node) or
 * OB_ERR_NON_FINITE (bounds that overflowed), the camera unchanged; or the
 * scene's or the camera's result (the camera then changed only in part).
 * [render thread, between frames] */
ob_result ob_stack_fit_camera(ob_stack *s, const ob_node *node);

/* Loads a scene file (docs/scene-format.md) into the stack with
 * ob_scene_load_stack: its materials, entities, models, lights and
 * particles, its camera on s->camera (or s->camera framed on the scene
 * when the file has none), its live settings. *out_loaded (may be NULL)
 * gets the load's record, owned by the stack until ob_stack_destroy, whose
 * left_out lists the entities whose model did not load (each also logged:
 * not a failure, the rest renders). Failure: the load's result (OB_ERR_IO,
 * OB_ERR_PARSE, ...), *out_loaded NULL, out_error (may be NULL) filled
 * with the message naming the file and the JSON path, the message logged,
 * and nothing of the file left in the stack. [render thread, between frames] */
ob_result ob_stack_load_scene(ob_stack *s, const char *path, const ob_scene_loaded **out_loaded,
                              ob_scene_file_error *out_error);

#ifdef __cplusplus
}
#endif
#endif /* OB_STACK_CONTENT_H */
