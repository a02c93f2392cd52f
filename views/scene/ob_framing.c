#include "ob_framing.h"

#include <math.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)
#define LOG_MODULE "framing"

/* n is root or under it. */
static bool in_subtree(const ob_node *n, const ob_node *root)
{
    for (; n; n = ob_node_get_parent(n))
        if (n == root) return true;
    return false;
}

ob_result ob_framing_measure(ob_scene *scene, const ob_node *root, double lo[3], double hi[3],
                             double center[3], double *radius)
{
    for (int k = 0; k < 3; k++) lo[k] = INFINITY, hi[k] = -INFINITY, center[k] = 0.0;
    *radius = 1.0;
    ob_result r = ob_scene_update(scene, 0.0);
    if (r != OB_OK) return r;
    uint32_t n = 0, measured = 0;
    ob_node *const *nodes = ob_scene_renderables(scene, &n);
    for (uint32_t i = 0; i < n; i++) {
        if (root && !in_subtree(nodes[i], root)) continue;
        double c[3];
        float rad;
        ob_node_world_sphere(nodes[i], c, &rad);
        for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], c[k] - rad), hi[k] = fmax(hi[k], c[k] + rad);
        measured++;
    }
    if (!measured) return OB_OK;
    for (int k = 0; k < 3; k++) center[k] = 0.5 * (lo[k] + hi[k]);
    *radius = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        if (root && !in_subtree(nodes[i], root)) continue;
        double c[3];
        float rad;
        ob_node_world_sphere(nodes[i], c, &rad);
        double dx = c[0] - center[0], dy = c[1] - center[1], dz = c[2] - center[2];
        *radius = fmax(*radius, sqrt(dx * dx + dy * dy + dz * dz) + rad);
    }
    return OB_OK;
}

ob_result ob_framing_aim_camera(ob_node *camera, const double sphere_center[3], double radius,
                                double aspect)
{
    if (!camera || !sphere_center || !(aspect > 0.0) || !isfinite(aspect)) {
        OB_LOG_E(LOG_MODULE, "ob_framing_aim_camera: %s", !camera ? "no camera node"
                 : !sphere_center ? "no centre" : "the aspect must be finite and > 0");
        return OB_ERR_INVALID_ARGUMENT;
    }
    double center[3] = {0, 0, 0};
    if (isfinite(sphere_center[0] + sphere_center[1] + sphere_center[2]))
        memcpy(center, sphere_center, sizeof center);
    if (!(radius > 0.0) || !isfinite(radius)) radius = 1.0;
    const double fovy = 45.0 * DEG;
    double half = fmin(fovy * 0.5, atan(tan(fovy * 0.5) * aspect));
    double dist = radius / sin(half) * 1.08;
    double dir[3] = {sin(35.0 * DEG) * cos(25.0 * DEG), sin(25.0 * DEG), cos(35.0 * DEG) * cos(25.0 * DEG)};
    double eye[3], up[3] = {0, 1, 0};
    for (int k = 0; k < 3; k++) eye[k] = center[k] + dir[k] * dist;
    ob_camera_desc cam = {.fovy = (float)fovy, .znear = (float)fmax(dist * 0.01, 1e-4)};
    ob_result r = ob_node_set_camera(camera, &cam);
    if (r != OB_OK) return r;
    ob_node_set_position(camera, eye);
    return ob_node_look_at(camera, center, up);
}
