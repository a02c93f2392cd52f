#include "ob_orbit.h"

#include <math.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

static bool finite3(const double v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static double clamp(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

bool ob_orbit_from_eye(ob_orbit *o, const double eye[3], const double target[3])
{
    if (!finite3(eye) || !finite3(target)) return false;
    double d[3] = {eye[0] - target[0], eye[1] - target[1], eye[2] - target[2]};
    double dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(dist > 0.0) || !isfinite(dist)) return false;
    memcpy(o->target, target, sizeof o->target);
    o->distance = dist;
    o->pitch = clamp(asin(clamp(d[1] / dist, -1.0, 1.0)), -OB_ORBIT_MAX_PITCH, OB_ORBIT_MAX_PITCH);
    /* Straight above or below, the yaw is any: keep the one we had. */
    if (fabs(d[0]) + fabs(d[2]) > 0.0) o->yaw = atan2(d[0], d[2]);
    else if (!isfinite(o->yaw)) o->yaw = 0.0;
    o->min_distance = dist * 1e-3;
    o->max_distance = dist * 1e3;
    return true;
}

bool ob_orbit_frame(ob_orbit *o, const double center[3], double radius, double fovy, double aspect)
{
    if (!finite3(center) || !(radius > 0.0) || !isfinite(radius) || !(fovy > 0.0) || !(fovy < PI) ||
        !(aspect > 0.0) || !isfinite(aspect))
        return false;
    /* The sphere fills the narrower half-angle, as ob_framing_aim_camera frames it. */
    double half = fmin(fovy * 0.5, atan(tan(fovy * 0.5) * aspect));
    memcpy(o->target, center, sizeof o->target);
    o->distance = radius / sin(half) * 1.08;
    o->min_distance = radius * 1e-2;
    o->max_distance = radius * 1e3;
    return true;
}

bool ob_orbit_rotate(ob_orbit *o, double dx, double dy, double viewport_height)
{
    if (!isfinite(dx) || !isfinite(dy) || !(viewport_height > 0.0)) return false;
    o->yaw = remainder(o->yaw - dx / viewport_height * PI, 2.0 * PI);
    o->pitch = clamp(o->pitch + dy / viewport_height * PI, -OB_ORBIT_MAX_PITCH, OB_ORBIT_MAX_PITCH);
    return true;
}

bool ob_orbit_pan(ob_orbit *o, double dx, double dy, double viewport_height, double fovy)
{
    if (!isfinite(dx) || !isfinite(dy) || !(viewport_height > 0.0) || !(fovy > 0.0) || !(fovy < PI))
        return false;
    /* World units per pixel at the target's depth. */
    double per_pixel = 2.0 * o->distance * tan(fovy * 0.5) / viewport_height;
    double right[3], up[3];
    ob_orbit_axes(o, right, up);
    double moved[3];
    for (int k = 0; k < 3; k++) moved[k] = o->target[k] + (-right[k] * dx + up[k] * dy) * per_pixel;
    if (!finite3(moved)) return false;
    memcpy(o->target, moved, sizeof moved);
    return true;
}

bool ob_orbit_zoom(ob_orbit *o, double steps)
{
    if (!isfinite(steps)) return false;
    double d = o->distance * pow(OB_ORBIT_ZOOM_STEP, steps);
    if (o->max_distance > o->min_distance && o->min_distance > 0.0)
        d = clamp(d, o->min_distance, o->max_distance);
    if (!(d > 0.0) || !isfinite(d)) return false;
    o->distance = d;
    return true;
}

void ob_orbit_eye(const ob_orbit *o, double dest[3])
{
    double cp = cos(o->pitch);
    dest[0] = o->target[0] + o->distance * cp * sin(o->yaw);
    dest[1] = o->target[1] + o->distance * sin(o->pitch);
    dest[2] = o->target[2] + o->distance * cp * cos(o->yaw);
}

void ob_orbit_axes(const ob_orbit *o, double right[3], double up[3])
{
    double cp = cos(o->pitch), sp = sin(o->pitch), cy = cos(o->yaw), sy = sin(o->yaw);
    /* forward = -(cp sy, sp, cp cy); right = forward x +Y, normalised;
     * up = right x forward. */
    right[0] = cy, right[1] = 0.0, right[2] = -sy;
    up[0] = -sp * sy, up[1] = cp, up[2] = -sp * cy;
}

double ob_orbit_znear(const ob_orbit *o) { return fmax(o->distance * 0.01, 1e-4); }
