#include "ob_bench_scene.h"

#include "ob_mirror_scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TWO_PI 6.283185307179586

/* The outer radius of the ring that holds n objects at obelisk-mirror's
 * density (200 objects between radius 6 and 20). */
static double ring_outer(uint32_t n)
{
    double n_eff = n < 200 ? 200.0 : (double)n;
    return sqrt(36.0 + (400.0 - 36.0) * n_eff / 200.0);
}

/* Sweep cameras: camera k stands a little behind the centre, low, and looks
 * outward along direction a_k (evenly spaced), so it frames a wedge of the
 * ring: each view culls most of the scene and draws about a third of the
 * objects (the stats say how many). Lavapipe then executes about V * N / 3
 * draws a frame rather than V * N, which keeps the 16-view, 50k-object
 * frame affordable on two cores. */
static void place_sweep_camera(ob_node *cam, double outer, uint32_t k, uint32_t count)
{
    double a = 0.6 + TWO_PI * k / count;
    double c = cos(a), s = sin(a);
    double eye[3] = {-0.35 * outer * c, 0.15 * outer, -0.35 * outer * s};
    double target[3] = {outer * c, 0.0, outer * s}, up[3] = {0.0, 1.0, 0.0};
    ob_node_set_position(cam, eye);
    ob_node_look_at(cam, target, up);
}

static ob_result add_views(ob_bench_scene *s, ob_demo *d)
{
    ob_result r = OB_OK;
    ob_camera_desc cam = {.fovy = 1.0f, .znear = 0.05f};
    place_sweep_camera(d->world.camera, s->ring_radius, 0, s->view_count);
    for (uint32_t k = 1; k < s->view_count; k++) {
        char name[32];
        snprintf(name, sizeof name, "camera%u", k);
        s->cameras[k] = ob_node_create(d->world.scene, NULL, name, &r);
        if (!s->cameras[k]) return r;
        if ((r = ob_node_set_camera(s->cameras[k], &cam)) != OB_OK) return r;
        place_sweep_camera(s->cameras[k], s->ring_radius, k, s->view_count);
        snprintf(name, sizeof name, "view%u", k);
        ob_perspective_desc pd = {.name = name, .camera = s->cameras[k], .width = d->opt.width,
                                  .height = d->opt.height,
                                  .clear_color = {0.08f, 0.09f, 0.12f, 1.0f}};
        s->extra[k] = ob_perspective_view_create(d->world.views, &pd, &r);
        if (!s->extra[k]) return r;
        s->views[k] = ob_perspective_view_base(s->extra[k]);
    }
    return OB_OK;
}

/* The sweep scene: geometry (four shapes, ground), palette, ground,
 * objects, lights, then the extra views. */
static ob_result build_sweep(ob_bench_scene *s, ob_demo *d, const ob_bench_scene_desc *desc)
{
    s->ring_radius = ring_outer(desc->objects);
    float ground_size = (float)(2.4 * s->ring_radius);
    ob_mesh ground_mesh = {0};
    ob_geometry *shapes[OB_MIRROR_SCENE_SHAPES], *ground = NULL;
    ob_material *palette[OB_MIRROR_SCENE_COLOURS], *ground_mat = NULL;
    ob_result r = ob_mirror_scene_shapes(d, true, shapes);
    if (r == OB_OK && (r = ob_mesh_plane(ground_size, ground_size, 8, &ground_mesh)) == OB_OK &&
        !(ground = ob_demo_geometry(d, &ground_mesh, "ground")))
        r = OB_ERR_BAD_MODEL;
    ob_mesh_release(&ground_mesh);
    if (r == OB_OK) r = ob_mirror_scene_palette(d, false, palette);
    if (r == OB_OK) ground_mat = ob_mirror_scene_ground_material(d, &r);
    if (r == OB_OK && !ob_demo_entity(d, NULL, "ground", ground, ground_mat))
        r = OB_ERR_OUT_OF_HOST_MEMORY;
    if (r == OB_OK)
        r = ob_mirror_scene_objects(d, desc->objects, desc->seed, s->ring_radius, shapes, palette);
    if (r == OB_OK) r = ob_mirror_scene_lights(d, false);
    if (r == OB_OK) r = add_views(s, d);
    return r;
}

ob_result ob_bench_scene_build(ob_bench_scene *s, ob_demo *d, const ob_bench_scene_desc *desc)
{
    memset(s, 0, sizeof *s);
    s->demo = d;
    s->kind = desc->kind;
    bool mirror = desc->kind == OB_BENCH_SCENE_MIRROR;
    s->view_count = mirror ? 1 : (desc->views ? desc->views : 1);
    if (s->view_count > OB_BENCH_MAX_VIEWS) {
        OB_LOG_E("bench", "%u views asked for; at most %u", s->view_count, OB_BENCH_MAX_VIEWS);
        return OB_ERR_LIMIT;
    }
    s->views[0] = ob_perspective_view_base(d->world.main);
    s->cameras[0] = d->world.camera;
    ob_result r;
    if (mirror) {
        s->ring_radius = 20.0;
        r = ob_mirror_scene_build(d, &(ob_mirror_scene_desc){.objects = desc->objects,
                                                             .seed = desc->seed});
    } else {
        r = build_sweep(s, d, desc);
    }
    if (r != OB_OK) OB_LOG_E("bench", "building the %s scene (%u objects, %u views) failed: %s",
                             mirror ? "mirror" : "sweep", desc->objects, s->view_count,
                             ob_result_name(r));
    return r;
}

void ob_bench_scene_release(ob_bench_scene *s)
{
    if (!s->demo) return;
    for (uint32_t k = 1; k < OB_BENCH_MAX_VIEWS; k++)
        ob_perspective_view_destroy(s->demo->world.views, s->extra[k]);
    memset(s, 0, sizeof *s);
}

ob_result ob_bench_scene_advance(ob_bench_scene *s, double dt)
{
    ob_demo *d = s->demo;
    s->time += dt;
    if (s->kind == OB_BENCH_SCENE_MIRROR) ob_mirror_scene_camera(d->world.camera, s->time);
    return ob_renderer_update_scene(d->world.r, d->world.scene, dt);
}

ob_result ob_bench_scene_frame(ob_bench_scene *s, bool advance, double dt)
{
    ob_demo *d = s->demo;
    if (advance) {
        ob_result r = ob_bench_scene_advance(s, dt);
        if (r != OB_OK) return r;
    }
    ob_views_set_time(d->world.views, s->time, dt);
    ob_result r = ob_renderer_begin_frame(d->world.r, d->world.scene);
    if (r != OB_OK) return r;
    /* Every root of the frame in one PreRender, so that their culling
     * shares the worker pool: the extra cameras, then the final image. */
    ob_view *roots[OB_BENCH_MAX_VIEWS + 1];
    uint32_t n = 0;
    for (uint32_t k = 1; k < s->view_count; k++) roots[n++] = s->views[k];
    roots[n++] = ob_composite_view_base(d->world.composite);
    ob_views_render_many(d->world.views, roots, n);
    return ob_renderer_end_frame(d->world.r);
}
