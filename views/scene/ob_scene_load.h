/* ob_scene_load.h — loading a scene file (docs/scene-format.md) into a scene:
 * the file's materials, entities with generated meshes or models (OBJ, PLY,
 * glTF and whatever else assimp reads), lights, camera and particle systems,
 * made with the program's renderer, material library, views and scene.
 *
 *   ob_scene_file_error err;
 *   ob_scene_loaded loaded;
 *   if (ob_scene_load_stack(stack, &(ob_scene_load_desc){.path = "scene.json"},
 *                           &loaded, &err) != OB_OK)
 *       fprintf(stderr, "%s\n", err.message);   // "scene.json: entities[3].transform.scale: ..."
 *   ... frames ...
 *   ob_renderer_wait_idle(stack->renderer);
 *   ob_scene_unload(&loaded);
 *   ob_stack_destroy(stack);
 *
 * Errors. Every error names the file and the JSON path of what it concerns,
 * in out_error (ob_scene_file.h): a malformed file is the parser's error
 * ("scene.json: lights[0].type: expected ..."); a step of building that
 * fails names the value it was building ("scene.json: entities[2].geometry:
 * sphere geometry failed: ..."). Either is a hard failure: the load returns
 * the error and leaves nothing it made in the scene, the material library or
 * the views (a camera node given in the desc is restored as it was).
 * Models keep their structure (ob_model_instance.h): the entity is the
 * model's root, with one child entity per node of the file and one per
 * primitive, each drawing with the model's own material, or, when the
 * entity names a "material", with that one for every primitive. Each model
 * file is opened once and its geometry and materials shared by the
 * entities naming it.
 * A model that does not load is not a hard failure: its entity stays as a
 * transform-only node (its children still render), the loss is logged as a
 * warning naming the file and the entity ("scene.json: entities[2] 'ghost':
 * model 'x.obj' did not load (...); the entity is left out"), the model
 * loader's own error line says why, and out->left_out lists it.
 *
 * Ownership. The scene owns the nodes and the material library the
 * materials, as always, but they are the load's to take back:
 * ob_scene_unload destroys the particle systems, the nodes the load made
 * (entities with their subtrees, lights, a camera node it created), the
 * materials and the geometry, which only the loaded scene owns. Unload
 * before destroying the scene, the views or the library (ob_stack_destroy
 * destroys those), and after ob_renderer_wait_idle. An ob_scene_loaded that
 * is never unloaded leaks its geometry and particle systems.
 *
 * Settings. The file's "settings" shape the set-up: ob_scene_load_stack_desc
 * puts them into an ob_stack_desc before ob_stack_create (size, clear colour
 * and ambient can only be given there); ob_scene_load_apply_settings applies
 * what a live set-up can still take (threading, env-map and shadow-map sizes).
 * ob_scene_load_stack applies those; ob_scene_load never touches settings,
 * so a program can let its command line override the file.
 *
 * Thread rule: [render thread], between frames (never while recording), as
 * every mutation of the scene, the materials and the views. ob_scene_file_*
 * (parsing alone) is [any thread].
 */
#ifndef OB_SCENE_LOAD_H
#define OB_SCENE_LOAD_H

#include "ob_framing.h"
#include "ob_model_instance.h"
#include "ob_scene_file.h"
#include "ob_stack.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What a load builds with. The material library must be the one the views
 * draw with; geometry is uploaded to the renderer's device. */
typedef struct ob_scene_load_target {
    ob_renderer *renderer;
    ob_material_library *materials;
    ob_views *views;
    ob_scene *scene;
} ob_scene_load_target;

typedef struct ob_scene_load_desc {
    const char *path;             /* the scene file, parsed by the load (ignored when file is set) */
    const ob_scene_file *file;    /* a description parsed already (ob_scene_file_load); stays the caller's */
    /* Gets the file's camera. NULL: a new node "camera" is made when the file
     * has one (ob_scene_load_stack: the stack's camera). */
    ob_node *camera;
    /* > 0 and the file has no camera: `camera` (required then) is pointed at
     * the scene's bounds for this width/height (ob_framing_aim_camera).
     * 0: left as it is (ob_scene_load_stack: the final image's aspect). */
    double frame_aspect;
    uint32_t seed;                /* particle system i is seeded seed + i */
    /* Geometry ids for command hashes: first_geometry_id, +1, ... in upload
     * order; 0 → each derived from its contents (ob_geometry_desc.id). */
    uint32_t first_geometry_id;
    /* A model path the file gives relative to itself must resolve, after
     * symbolic links, inside the scene file's folder, and each model's own
     * references inside the model's folder (ob_model_desc.allow_any_folder);
     * otherwise the entity is left out, naming the path. true allows any
     * folder: trusted content only. Absolute model paths are the file's
     * explicit choice and are not confined. */
    bool allow_any_folder;
} ob_scene_load_desc;

/* An entity left out because its model did not load. */
typedef struct ob_scene_load_left_out {
    uint32_t entity;              /* index into the file's "entities" (and out->entities) */
    ob_result result;             /* why: OB_ERR_IO, OB_ERR_BAD_MODEL, ... */
} ob_scene_load_left_out;

/* What a load made; indices follow the file. Read-only to the program. */
typedef struct ob_scene_loaded {
    ob_node **entities;           /* entities[i] is "entities"[i]'s node (transform-only if left out) */
    uint32_t entity_count;
    ob_geometry **geometry;       /* generated shapes: one per distinct description (shared by
                                     entities alike); models' geometry is in their assets */
    uint32_t geometry_count;
    ob_model_assets **models;     /* one per distinct model file (NULL where it did not open) */
    uint32_t model_count;
    ob_texture_cache *textures;   /* the models' textures, shared across them (identical
                                     images load once); NULL when no model has any */
    uint32_t model_entity_count;  /* entities made under model entities: per model node and
                                     per placed primitive (ob_model_instance.h) */
    ob_material **materials;      /* the file's materials (ob_scene_file order), then "default",
                                     which generated shapes without a material draw with
                                     (models without one draw with their own: see models) */
    uint32_t material_count;
    ob_node **lights;             /* the file's lights; without "lights", the default sun */
    uint32_t light_count;
    ob_particle_system **particles;
    uint32_t particle_count;
    ob_node *camera;              /* the node that got the file's camera; NULL if the file has none */
    bool camera_created;          /* camera is a node the load made (unload destroys it) */
    bool framed;                  /* no camera in the file: desc.camera was framed on the bounds */
    ob_scene_load_left_out *left_out;
    uint32_t left_out_count;
    /* Bounds of every renderable of the scene after the load (world space,
     * after an ob_scene_update with dt 0): a box and the sphere around it
     * that frames it. No renderable: has_bounds false, the unit sphere at
     * the origin. */
    bool has_bounds;
    double min[3], max[3];
    double center[3], radius;
    /* Where it lives, for ob_scene_unload. */
    ob_scene *scene;
    ob_views *views;
    ob_device *device;
} ob_scene_loaded;

/* Loads desc->file (or parses desc->path) into t->scene. On success *out
 * holds what was made (unload it) and out_error is cleared. On failure *out
 * is zeroed, nothing made stays behind, and *out_error (may be NULL) names
 * the file and the JSON path: OB_ERR_PARSE, OB_ERR_IO (the parse),
 * OB_ERR_INVALID_ARGUMENT (a missing target, or frame_aspect without a
 * camera), or the failing step's result (OB_ERR_OUT_OF_HOST_MEMORY,
 * OB_ERR_OUT_OF_DEVICE_MEMORY, ...). A model that does not load is not a
 * failure (see the top). [render thread, between frames] */
ob_result ob_scene_load(const ob_scene_load_target *t, const ob_scene_load_desc *desc,
                        ob_scene_loaded *out, ob_scene_file_error *out_error);

/* ob_scene_load into the stack's renderer, materials, views and scene, with
 * the defaults of the desc taken from the stack (camera: s->camera, framed
 * with the final image's aspect when the file has none); then the file's
 * live settings (ob_scene_load_apply_settings). desc NULL is not allowed: it
 * names the file. Failure as ob_scene_load; the settings are applied only on
 * success. [render thread, between frames] */
ob_result ob_scene_load_stack(ob_stack *s, const ob_scene_load_desc *desc, ob_scene_loaded *out,
                              ob_scene_file_error *out_error);

/* Destroys what the load made (see Ownership at the top) and zeroes *l.
 * A zeroed ob_scene_loaded, or NULL, is a no-op. [render thread, after
 * ob_renderer_wait_idle, before the scene, views and library go] */
void ob_scene_unload(ob_scene_loaded *l);

/* The file's settings that shape a set-up, into *desc before ob_stack_create:
 * size, threads (renderer.threading and worker_count), env-map and
 * shadow-map sizes, env-map kind, clear colour, sky colour and ambient. What the file does not give
 * is left as it was. [any thread] */
void ob_scene_load_stack_desc(const ob_scene_file_settings *settings, ob_stack_desc *desc);

/* The file's settings a live set-up can take: threading (from the next
 * frame), env-map and shadow-map sizes and the env-map kind (for views made
 * afterwards, as entities' maps are, on first need) and the sky colour
 * (from the next frame). Failure: the first setting refused
 * (OB_ERR_OUT_OF_RANGE for a map size the device cannot make, logged); the
 * others are still applied. [render thread, between frames] */
ob_result ob_scene_load_apply_settings(ob_renderer *r, ob_views *views,
                                       const ob_scene_file_settings *settings);

#ifdef __cplusplus
}
#endif
#endif /* OB_SCENE_LOAD_H */
