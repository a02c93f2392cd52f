/* ob_framing.h — showing what is in a scene: the bounds of the renderables
 * under a node (or of the whole scene), and a camera placed so that a
 * bounding sphere fills its view. The one implementation behind the scene
 * loader's automatic camera (ob_scene_load.h: a file without a camera),
 * ob_stack_fit_camera (ob_stack_content.h) and obelisk-view's model framing.
 *
 * Lifecycle: plain functions on an existing scene and camera node; nothing
 * is kept. Thread rule: [render thread, between frames] (measuring updates
 * the scene; aiming changes a node), as every mutation of a scene.
 */
#ifndef OB_FRAMING_H
#define OB_FRAMING_H

#include "ob_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Updates the scene (dt 0) and measures the renderables (world bounding
 * spheres) of root's subtree, root included; root NULL: every renderable
 * of the scene (what ob_scene_renderables lists: hidden ones are left
 * out). The box around them goes to lo/hi, its centre to center, and the
 * radius of the sphere about that centre holding them all to *radius. No
 * renderable: lo = +inf, hi = −inf, centre 0, radius 1, OB_OK (hi[0] <
 * lo[0] tells). Failure: the update's result, outputs as for no
 * renderable. [render thread, between frames] */
ob_result ob_framing_measure(ob_scene *scene, const ob_node *root, double lo[3], double hi[3],
                             double center[3], double *radius);

/* Points camera at a bounding sphere from a 3/4 view above it, at the
 * distance where the sphere fills the narrower field of view (45 degrees
 * vertical) of an image of this aspect (width / height), and sets its
 * camera (fov 45 degrees, near plane 1% of the distance). A non-finite centre is taken as the origin, a radius that is
 * not > 0 and finite as 1. Failure: OB_ERR_INVALID_ARGUMENT (no camera or
 * centre, an aspect that is not finite and > 0; logged) or the node's
 * result; the camera is then changed only in part. [render thread, between
 * frames] */
ob_result ob_framing_aim_camera(ob_node *camera, const double center[3], double radius,
                                double aspect);

#ifdef __cplusplus
}
#endif
#endif /* OB_FRAMING_H */
