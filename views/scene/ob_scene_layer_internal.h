/* ob_scene_layer_internal.h — shared between the files of the scene layer
 * (views/scene); not installed. */
#ifndef OB_SCENE_LAYER_INTERNAL_H
#define OB_SCENE_LAYER_INTERNAL_H

#include "ob_stack.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

/* The sun a scene file without "lights" gets and ob_stack_add_sun makes. */
extern const ob_light_desc ob_sun_light;
extern const double ob_sun_direction[3];

/* Turns a light node to shine along direction (its forward, −Z), aimed
 * from the origin: position + direction could round back to a far-away
 * position, and a directional light's position is unused. Up is +Y unless
 * |direction.y| > 0.99 (then −Z): give a unit direction. The node's
 * look-at result. [render thread, between frames] */
ob_result ob_light_aim(ob_node *n, const double direction[3]);

/* ob_stack_destroy's two steps for what ob_stack_content.h loaded: the
 * scene files (before the scene, the views and the library go), then the
 * models' assets and textures (after the scene's entities are gone, before
 * the views and the library). Each is a no-op when nothing was loaded.
 * [render thread, after ob_renderer_wait_idle] */
void ob_stack_content_unload_scenes(ob_stack *s);
void ob_stack_content_destroy(ob_stack *s);

#pragma GCC visibility pop

#endif /* OB_SCENE_LAYER_INTERNAL_H */
