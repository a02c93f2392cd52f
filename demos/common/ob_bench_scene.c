#include "ob_bench_scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define KINDS 4
#define PALETTE 8
#define TWO_PI 6.283185307179586

static uint32_t next_random(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float random01(uint32_t *s) { return (float)next_random(s) / (float)(1u << 24); }

/* The outer radius of the ring that holds n objects at obelisk-mirror's
 * density (200 objects between radius 6 and 20). */
static double ring_outer(uint32_t n)
{
    double n_eff = n < 200 ? 200.0 : (double)n;
    return sqrt(36.0 + (400.0 - 36.0) * n_eff / 200.0);
}

static ob_result make_palette(ob_demo *d, bool casts_shadows, ob_material *out[PALETTE])
{
    static const float colors[PALETTE][3] = {
        {0.9f, 0.3f, 0.25f}, {0.25f, 0.7f, 0.35f}, {0.3f, 0.45f, 0.9f}, {0.95f, 0.8f, 0.3f},
        {0.8f, 0.4f, 0.85f}, {0.3f, 0.85f, 0.85f}, {0.95f, 0.55f, 0.2f}, {0.85f, 0.85f, 0.85f},
    };
    ob_result r = OB_OK;
    for (int i = 0; i < PALETTE; i++) {
        ob_material_desc md = {.name = "diffuse", .kind = OB_MATERIAL_LIT,
                               .casts_shadows = casts_shadows,
                               .diffuse = {colors[i][0], colors[i][1], colors[i][2], 1.0f}};
        out[i] = ob_material_create(d->lib, &md, &r);
        if (!out[i]) return r;
    }
    return OB_OK;
}

/* Orbiting, spinning objects. The mirror scene keeps obelisk-mirror's
 * radius distribution (uniform in radius); the sweep spreads them uniformly
 * over the ring's area so a larger N makes a larger, equally dense ring. */
static ob_result add_objects(ob_demo *d, const ob_bench_scene_desc *desc, double outer,
                             ob_geometry *const kinds[KINDS], ob_material *const palette[PALETTE])
{
    uint32_t seed = desc->seed;
    for (uint32_t i = 0; i < desc->objects; i++) {
        char name[32];
        snprintf(name, sizeof name, "object%u", i);
        uint32_t kind = next_random(&seed) % KINDS;
        ob_material *m = palette[next_random(&seed) % PALETTE];
        ob_node *n = ob_demo_entity(d, NULL, name, kinds[kind], m);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        double u = random01(&seed);
        double radius = desc->kind == OB_BENCH_SCENE_MIRROR
                            ? 6.0 + 14.0 * u
                            : sqrt(36.0 + u * (outer * outer - 36.0));
        double center[3] = {0.0, 0.4 + 3.0 * random01(&seed), 0.0};
        float axis[3] = {0.0f, 1.0f, 0.0f};
        float speed = (0.1f + 0.3f * random01(&seed)) * (random01(&seed) < 0.5f ? -1.0f : 1.0f);
        if (desc->kind == OB_BENCH_SCENE_SWEEP) speed *= (float)(20.0 / radius);
        ob_result r = ob_node_add_orbit_controller(n, center, axis, radius, speed,
                                                   (float)TWO_PI * random01(&seed));
        if (r != OB_OK) return r;
        float spin[3] = {random01(&seed) - 0.5f, 1.0f, random01(&seed) - 0.5f};
        r = ob_node_add_rotation_controller(n, spin, 0.5f + 2.0f * random01(&seed));
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

static ob_result add_lights(ob_demo *d, bool sun_shadows)
{
    ob_result r;
    ob_node *sun = ob_node_create(d->scene, NULL, "sun", &r);
    if (!sun) return r;
    ob_light_desc ld = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.96f, 0.9f},
                        .intensity = 1.0f, .casts_shadows = sun_shadows};
    if ((r = ob_node_set_light(sun, &ld)) != OB_OK) return r;
    double sun_pos[3] = {12.0, 20.0, 8.0}, origin[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    ob_node_set_position(sun, sun_pos);
    if ((r = ob_node_look_at(sun, origin, up)) != OB_OK) return r;
    static const float point_colors[2][3] = {{1.0f, 0.4f, 0.2f}, {0.2f, 0.5f, 1.0f}};
    for (int i = 0; i < 2; i++) {
        ob_node *pl = ob_node_create(d->scene, NULL, i ? "blue-light" : "red-light", &r);
        if (!pl) return r;
        ob_light_desc pd = {.type = OB_LIGHT_POINT, .intensity = 2.0f, .range = 14.0f};
        memcpy(pd.color, point_colors[i], sizeof pd.color);
        if ((r = ob_node_set_light(pl, &pd)) != OB_OK) return r;
        double p[3] = {i ? -7.0 : 7.0, 2.5, i ? 5.0 : -5.0};
        ob_node_set_position(pl, p);
    }
    return OB_OK;
}

static ob_result add_mirrors(ob_demo *d, ob_geometry *ball)
{
    ob_result r;
    ob_material_desc mm = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .casts_shadows = true,
                           .diffuse = {0.9f, 0.9f, 0.95f, 1.0f}, .reflectivity = 0.85f};
    ob_material *mirror_mat = ob_material_create(d->lib, &mm, &r);
    if (!mirror_mat) return r;
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "mirror%d", i);
        ob_node *n = ob_demo_entity(d, NULL, name, ball, mirror_mat);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        double a = TWO_PI * i / 3.0;
        double p[3] = {3.2 * cos(a), 1.6, 3.2 * sin(a)};
        ob_node_set_position(n, p);
    }
    ob_node *fountain = ob_node_create(d->scene, NULL, "fountain", &r);
    if (!fountain) return r;
    double fp[3] = {0.0, 0.2, 0.0};
    ob_node_set_position(fountain, fp);
    ob_particle_desc pdesc = {.name = "sparks", .count = 4096, .seed = d->opt.seed,
                              .lifetime = 2.5f, .speed = 3.0f, .size = 0.06f,
                              .gravity = {0.0f, -2.5f, 0.0f}};
    return ob_demo_particles(d, fountain, &pdesc) ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
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
    place_sweep_camera(d->camera, s->ring_radius, 0, s->view_count);
    for (uint32_t k = 1; k < s->view_count; k++) {
        char name[32];
        snprintf(name, sizeof name, "camera%u", k);
        s->cameras[k] = ob_node_create(d->scene, NULL, name, &r);
        if (!s->cameras[k]) return r;
        if ((r = ob_node_set_camera(s->cameras[k], &cam)) != OB_OK) return r;
        place_sweep_camera(s->cameras[k], s->ring_radius, k, s->view_count);
        snprintf(name, sizeof name, "view%u", k);
        ob_perspective_desc pd = {.name = name, .camera = s->cameras[k], .width = d->opt.width,
                                  .height = d->opt.height,
                                  .clear_color = {0.08f, 0.09f, 0.12f, 1.0f}};
        s->extra[k] = ob_perspective_view_create(d->views, &pd, &r);
        if (!s->extra[k]) return r;
        s->views[k] = ob_perspective_view_base(s->extra[k]);
    }
    return OB_OK;
}

ob_result ob_bench_scene_build(ob_bench_scene *s, ob_demo *d, const ob_bench_scene_desc *desc)
{
    memset(s, 0, sizeof *s);
    s->demo = d;
    s->kind = desc->kind;
    s->view_count = desc->kind == OB_BENCH_SCENE_MIRROR ? 1 : (desc->views ? desc->views : 1);
    if (s->view_count > OB_BENCH_MAX_VIEWS) {
        OB_LOG_E("bench", "%u views asked for; at most %u", s->view_count, OB_BENCH_MAX_VIEWS);
        return OB_ERR_LIMIT;
    }
    s->views[0] = ob_perspective_view_base(d->main);
    s->cameras[0] = d->camera;
    bool mirror = desc->kind == OB_BENCH_SCENE_MIRROR;
    s->ring_radius = mirror ? 20.0 : ring_outer(desc->objects);
    float ground_size = mirror ? 60.0f : (float)(2.4 * s->ring_radius);

    ob_result r = OB_OK;
    ob_mesh meshes[KINDS + 2] = {{0}};
    float half[3] = {0.35f, 0.35f, 0.35f};
    if ((r = ob_mesh_box(half, &meshes[0])) != OB_OK ||
        (r = ob_mesh_sphere(0.4f, 16, 10, &meshes[1])) != OB_OK ||
        (r = ob_mesh_torus(0.35f, 0.12f, 20, 10, &meshes[2])) != OB_OK ||
        (r = ob_mesh_cone(0.35f, 0.8f, 16, &meshes[3])) != OB_OK ||
        (r = ob_mesh_sphere(1.5f, 48, 32, &meshes[4])) != OB_OK ||
        (r = ob_mesh_plane(ground_size, ground_size, 8, &meshes[5])) != OB_OK)
        goto done;
    static const char *const kind_names[KINDS] = {"box", "sphere", "torus", "cone"};
    ob_geometry *kinds[KINDS];
    for (int k = 0; k < KINDS; k++) {
        kinds[k] = ob_demo_geometry(d, &meshes[k], kind_names[k]);
        if (!kinds[k]) { r = OB_ERR_BAD_MODEL; goto done; }
    }
    ob_geometry *ground = ob_demo_geometry(d, &meshes[5], "ground");
    if (!ground) { r = OB_ERR_BAD_MODEL; goto done; }
    ob_material *palette[PALETTE];
    if ((r = make_palette(d, mirror, palette)) != OB_OK) goto done;
    ob_material_desc gm = {.name = "ground", .kind = OB_MATERIAL_LIT,
                           .diffuse = {0.55f, 0.55f, 0.5f, 1.0f},
                           .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
    ob_material *ground_mat = ob_material_create(d->lib, &gm, &r);
    if (!ground_mat) goto done;
    if (!ob_demo_entity(d, NULL, "ground", ground, ground_mat)) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    if (mirror) {
        ob_geometry *ball = ob_demo_geometry(d, &meshes[4], "mirror-ball");
        if (!ball) { r = OB_ERR_BAD_MODEL; goto done; }
        if ((r = add_mirrors(d, ball)) != OB_OK) goto done;
    }
    if ((r = add_objects(d, desc, s->ring_radius, kinds, palette)) != OB_OK) goto done;
    if ((r = add_lights(d, mirror)) != OB_OK) goto done;
    if (!mirror) r = add_views(s, d);
done:
    for (int i = 0; i < KINDS + 2; i++) ob_mesh_release(&meshes[i]);
    if (r != OB_OK) OB_LOG_E("bench", "building the %s scene (%u objects, %u views) failed: %s",
                             mirror ? "mirror" : "sweep", desc->objects, s->view_count,
                             ob_result_name(r));
    return r;
}

void ob_bench_scene_release(ob_bench_scene *s)
{
    if (!s->demo) return;
    for (uint32_t k = 1; k < OB_BENCH_MAX_VIEWS; k++)
        ob_perspective_view_destroy(s->demo->views, s->extra[k]);
    memset(s, 0, sizeof *s);
}

ob_result ob_bench_scene_frame(ob_bench_scene *s, bool advance, double dt)
{
    ob_demo *d = s->demo;
    uint64_t update_ns = 0;
    if (advance) {
        uint64_t t0 = ob_time_ns();
        s->time += dt;
        if (s->kind == OB_BENCH_SCENE_MIRROR) {
            /* obelisk-mirror's camera: circles the mirrors slowly. */
            double a = 0.15 * s->time + 0.6;
            double eye[3] = {17.0 * cos(a), 7.0, 17.0 * sin(a)}, target[3] = {0.0, 1.2, 0.0};
            double up[3] = {0.0, 1.0, 0.0};
            ob_node_set_position(d->camera, eye);
            ob_node_look_at(d->camera, target, up);
        }
        ob_result r = ob_scene_update(d->scene, dt);
        if (r != OB_OK) return r;
        update_ns = ob_time_ns() - t0;
    }
    ob_views_set_time(d->views, s->time, dt);
    ob_result r = ob_renderer_begin_frame(d->r, d->scene);
    if (r != OB_OK) return r;
    ob_renderer_note_update_ns(d->r, update_ns);
    for (uint32_t k = 1; k < s->view_count; k++) ob_renderer_pre_draw(d->r, s->views[k]);
    ob_views_render(d->views, ob_composite_view_base(d->composite));
    return ob_renderer_end_frame(d->r);
}
