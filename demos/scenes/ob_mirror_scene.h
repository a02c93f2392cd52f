/* ob_mirror_scene.h — obelisk-mirror's scene (Hieroglyph 3's MirrorMirror),
 * defined once: obelisk-mirror renders it and obelisk-bench measures it
 * (its "scene200" and quality runs), so both see the same scene.
 *
 * Three reflective spheres whose dual-paraboloid environment maps see each
 * other, `objects` shapes (box, sphere, torus, cone; eight shadow-casting
 * colours) orbiting them at radius 6..20 and spinning, a 60 x 60 ground, a
 * shadow-casting sun, two point lights and a particle fountain (4096
 * sparks). The seed fixes every object's shape, colour, orbit and spin and
 * the particles' emission. The camera circles the mirrors slowly
 * (ob_mirror_scene_camera).
 *
 * Lifecycle: ob_demo_init → ob_mirror_scene_build → frames, moving the
 * camera with ob_mirror_scene_camera → ob_demo_shutdown (the demo owns
 * everything the scene made). Thread rule: [render thread].
 */
#ifndef OB_MIRROR_SCENE_H
#define OB_MIRROR_SCENE_H

#include <stdio.h>

#include "ob_demo.h"

typedef struct ob_mirror_scene_desc {
    uint32_t objects;        /* orbiting objects (obelisk-mirror's default: 200) */
    uint32_t seed;           /* objects and particles */
} ob_mirror_scene_desc;

/* Builds the scene into d (geometry, materials, nodes and the particle
 * system owned by d and its stack). Failure: the first failing step's
 * result, logged; what was made is freed by ob_demo_shutdown. */
ob_result ob_mirror_scene_build(ob_demo *d, const ob_mirror_scene_desc *desc);

/* The pieces obelisk-bench's sweep scene shares with this one (its objects
 * are spread at this scene's density over a ring that grows with their
 * number). Each fails with the first failing step's result, logged by the
 * engine; what they made belongs to d. */
#define OB_MIRROR_SCENE_SHAPES 4      /* box, sphere, torus, cone */
#define OB_MIRROR_SCENE_COLOURS 8
/* The four shapes' geometry, uploaded in that order (ids follow). With
 * lods, the sphere, torus and cone get coarser levels of detail (fewer
 * segments; each level's error measured with ob_mesh_deviation), which
 * views draw where an entity is small on screen; the box has none. */
#define OB_MIRROR_SCENE_SHAPE_LODS 4  /* levels of the curved shapes, level 0 included */
ob_result ob_mirror_scene_shapes(ob_demo *d, bool lods, ob_geometry *out[OB_MIRROR_SCENE_SHAPES]);
/* The eight lit colours, named "diffuse". */
ob_result ob_mirror_scene_palette(ob_demo *d, bool casts_shadows,
                                  ob_material *out[OB_MIRROR_SCENE_COLOURS]);
/* The ground's lit grey; NULL on failure, *out_result set. */
ob_material *ob_mirror_scene_ground_material(ob_demo *d, ob_result *out_result);
/* `objects` nodes "object<i>" orbiting the y axis and spinning, shape and
 * colour drawn from seed. spread_to 0: radius uniform in 6..20 (this
 * scene); else uniform over the area of the ring 6..spread_to, speed scaled
 * by 20 / radius. */
ob_result ob_mirror_scene_objects(ob_demo *d, uint32_t objects, uint32_t seed, double spread_to,
                                  ob_geometry *const shapes[OB_MIRROR_SCENE_SHAPES],
                                  ob_material *const palette[OB_MIRROR_SCENE_COLOURS]);
/* The sun (shadows as asked) and the red and blue point lights. */
ob_result ob_mirror_scene_lights(ob_demo *d, bool sun_shadows);

/* Writes the scene as a scene file (docs/scene-format.md) that loads
 * (ob_scene_load, seed desc->seed) into the same entities, transforms,
 * controllers, materials, lights, particles and camera (its pose at time 0)
 * as ob_mirror_scene_build — demos/scenes/mirror.json is this output for
 * obelisk-mirror's defaults (200 objects, seed 1). The palette's materials,
 * all named "diffuse" here, are "diffuse0".."diffuse7" there. Needs no
 * device. Failure: OB_ERR_IO when writing fails. [any thread] */
ob_result ob_mirror_scene_write_json(const ob_mirror_scene_desc *desc, FILE *out);

/* Places camera on its circle around the mirrors at scene time `time`
 * (seconds), looking at their centre. */
void ob_mirror_scene_camera(ob_node *camera, double time);

#endif /* OB_MIRROR_SCENE_H */
