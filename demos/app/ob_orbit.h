/* ob_orbit.h — the viewer's camera control as pure math: an eye orbiting a
 * target at a distance, moved by input deltas (pixels dragged, wheel steps)
 * and turned into an eye, a target and a near plane the demo gives its
 * camera node. No window, no engine: the same calls serve GLFW's callbacks,
 * a scripted run (--input, ob_input.h) and the unit test
 * (tests/unit/test_orbit.c).
 *
 * Conventions: +Y is up; yaw turns about +Y (0 puts the eye on the target's
 * +Z side), pitch raises the eye (clamped to ±OB_ORBIT_MAX_PITCH so that
 * the view never flips over the pole). Dragging a full viewport height
 * turns by pi; a pan moves the target so that the point under the cursor at
 * the target's depth stays under it; a wheel step moves the eye 10% of the
 * way towards (or away from) the target.
 *
 * Lifecycle: a plain struct; ob_orbit_from_eye or ob_orbit_frame sets it up.
 * Thread rule: none (no shared state); one orbit per caller.
 * Failure: non-finite or degenerate input leaves the orbit unchanged and
 * returns false; the orbit is then still valid.
 */
#ifndef OB_ORBIT_H
#define OB_ORBIT_H

#include <stdbool.h>

#define OB_ORBIT_MAX_PITCH 1.5533430342749532   /* 89 degrees */
#define OB_ORBIT_ZOOM_STEP 0.9                   /* distance factor per wheel step in */

typedef struct ob_orbit {
    double target[3];
    double distance;     /* > 0 */
    double yaw, pitch;   /* radians */
    /* The closest the eye may come and the farthest it may go (set by
     * ob_orbit_frame from the scene's size: zooming into the target or out
     * to infinity is no use). */
    double min_distance, max_distance;
} ob_orbit;

/* An orbit with the eye at eye looking at target. False (o unchanged) when
 * they coincide or are not finite. */
bool ob_orbit_from_eye(ob_orbit *o, const double eye[3], const double target[3]);
/* Keeps the direction and sets target and distance so that a sphere fills
 * the narrower field of view (fovy vertical, radians; aspect width/height),
 * with 8% to spare — the framing obelisk-view starts with. Also sets
 * min/max_distance from the radius. False (o unchanged) for a radius not
 * > 0, a bad fovy or aspect, or non-finite input. */
bool ob_orbit_frame(ob_orbit *o, const double center[3], double radius, double fovy, double aspect);

/* Drag to turn: dx, dy in pixels (right, down), over a viewport
 * viewport_height pixels high. Dragging right turns the eye left round the
 * target (the scene turns with the cursor); dragging down raises it. */
bool ob_orbit_rotate(ob_orbit *o, double dx, double dy, double viewport_height);
/* Drag to pan: the target moves in the view plane so that what is under the
 * cursor at the target's depth follows it (fovy: the vertical field of
 * view in radians). */
bool ob_orbit_pan(ob_orbit *o, double dx, double dy, double viewport_height, double fovy);
/* Wheel: steps > 0 zoom in (towards the target), < 0 out; fractions are
 * fine (touchpads). The distance stays within min/max_distance. */
bool ob_orbit_zoom(ob_orbit *o, double steps);

/* Where the eye is, and the camera's up and right axes (unit vectors). */
void ob_orbit_eye(const ob_orbit *o, double dest[3]);
void ob_orbit_axes(const ob_orbit *o, double right[3], double up[3]);
/* A near plane for this distance: 1% of it, as ob_framing_aim_camera
 * picks, so that zooming keeps depth precision where the target is. */
double ob_orbit_znear(const ob_orbit *o);

#endif /* OB_ORBIT_H */
