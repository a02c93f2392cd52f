#include "ob_mirror_scene.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static uint32_t next_random(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float random01(uint32_t *s) { return (float)next_random(s) / (float)(1u << 24); }

static ob_result add_mirrors(ob_demo *d, ob_geometry *ball, ob_material *mirror_mat)
{
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "mirror%d", i);
        ob_node *n = ob_demo_entity(d, NULL, name, ball, mirror_mat);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        double a = 2.0 * 3.14159265358979 * i / 3.0;
        double p[3] = {3.2 * cos(a), 1.6, 3.2 * sin(a)};
        ob_node_set_position(n, p);
    }
    return OB_OK;
}

ob_result ob_mirror_scene_shapes(ob_demo *d, ob_geometry *out[OB_MIRROR_SCENE_SHAPES])
{
    static const char *const names[OB_MIRROR_SCENE_SHAPES] = {"box", "sphere", "torus", "cone"};
    ob_mesh meshes[OB_MIRROR_SCENE_SHAPES] = {{0}};
    float half[3] = {0.35f, 0.35f, 0.35f};
    ob_result r;
    if ((r = ob_mesh_box(half, &meshes[0])) == OB_OK &&
        (r = ob_mesh_sphere(0.4f, 16, 10, &meshes[1])) == OB_OK &&
        (r = ob_mesh_torus(0.35f, 0.12f, 20, 10, &meshes[2])) == OB_OK &&
        (r = ob_mesh_cone(0.35f, 0.8f, 16, &meshes[3])) == OB_OK) {
        for (int k = 0; k < OB_MIRROR_SCENE_SHAPES && r == OB_OK; k++)
            if (!(out[k] = ob_demo_geometry(d, &meshes[k], names[k]))) r = OB_ERR_BAD_MODEL;
    }
    for (int k = 0; k < OB_MIRROR_SCENE_SHAPES; k++) ob_mesh_release(&meshes[k]);
    return r;
}

ob_result ob_mirror_scene_palette(ob_demo *d, bool casts_shadows,
                                  ob_material *out[OB_MIRROR_SCENE_COLOURS])
{
    static const float colors[OB_MIRROR_SCENE_COLOURS][3] = {
        {0.9f, 0.3f, 0.25f}, {0.25f, 0.7f, 0.35f}, {0.3f, 0.45f, 0.9f}, {0.95f, 0.8f, 0.3f},
        {0.8f, 0.4f, 0.85f}, {0.3f, 0.85f, 0.85f}, {0.95f, 0.55f, 0.2f}, {0.85f, 0.85f, 0.85f},
    };
    ob_result r = OB_OK;
    for (int i = 0; i < OB_MIRROR_SCENE_COLOURS; i++) {
        ob_material_desc md = {.name = "diffuse", .kind = OB_MATERIAL_LIT,
                               .casts_shadows = casts_shadows,
                               .diffuse = {colors[i][0], colors[i][1], colors[i][2], 1.0f}};
        if (!(out[i] = ob_material_create(d->lib, &md, &r))) return r;
    }
    return OB_OK;
}

ob_material *ob_mirror_scene_ground_material(ob_demo *d, ob_result *out_result)
{
    ob_material_desc gm = {.name = "ground", .kind = OB_MATERIAL_LIT,
                           .diffuse = {0.55f, 0.55f, 0.5f, 1.0f},
                           .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
    return ob_material_create(d->lib, &gm, out_result);
}

ob_result ob_mirror_scene_objects(ob_demo *d, uint32_t objects, uint32_t seed, double spread_to,
                                  ob_geometry *const shapes[OB_MIRROR_SCENE_SHAPES],
                                  ob_material *const palette[OB_MIRROR_SCENE_COLOURS])
{
    for (uint32_t i = 0; i < objects; i++) {
        char name[32];
        snprintf(name, sizeof name, "object%u", i);
        uint32_t kind = next_random(&seed) % OB_MIRROR_SCENE_SHAPES;
        ob_material *m = palette[next_random(&seed) % OB_MIRROR_SCENE_COLOURS];
        ob_node *n = ob_demo_entity(d, NULL, name, shapes[kind], m);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        double u = random01(&seed);
        double radius = spread_to > 0.0 ? sqrt(36.0 + u * (spread_to * spread_to - 36.0))
                                        : 6.0 + 14.0 * u;
        double center[3] = {0.0, 0.4 + 3.0 * random01(&seed), 0.0};
        float axis[3] = {0.0f, 1.0f, 0.0f};
        float speed = (0.1f + 0.3f * random01(&seed)) * (random01(&seed) < 0.5f ? -1.0f : 1.0f);
        if (spread_to > 0.0) speed *= (float)(20.0 / radius);
        ob_result r = ob_node_add_orbit_controller(n, center, axis, radius, speed,
                                                   6.2831853f * random01(&seed));
        if (r != OB_OK) return r;
        float spin[3] = {random01(&seed) - 0.5f, 1.0f, random01(&seed) - 0.5f};
        r = ob_node_add_rotation_controller(n, spin, 0.5f + 2.0f * random01(&seed));
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

ob_result ob_mirror_scene_lights(ob_demo *d, bool sun_shadows)
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

static ob_result add_fountain(ob_demo *d, uint32_t seed)
{
    ob_result r;
    ob_node *fountain = ob_node_create(d->scene, NULL, "fountain", &r);
    if (!fountain) return r;
    double fp[3] = {0.0, 0.2, 0.0};
    ob_node_set_position(fountain, fp);
    ob_particle_desc pdesc = {.name = "sparks", .count = 4096, .seed = seed,
                              .lifetime = 2.5f, .speed = 3.0f, .size = 0.06f,
                              .gravity = {0.0f, -2.5f, 0.0f}};
    return ob_demo_particles(d, fountain, &pdesc) ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
}

/* Geometry ids follow upload order (the command hashes fold them in): the
 * four shapes, the mirror ball, the ground. */
ob_result ob_mirror_scene_build(ob_demo *d, const ob_mirror_scene_desc *desc)
{
    ob_mesh ball_mesh = {0}, ground_mesh = {0};
    ob_geometry *shapes[OB_MIRROR_SCENE_SHAPES];
    ob_result r = ob_mirror_scene_shapes(d, shapes);
    if (r != OB_OK || (r = ob_mesh_sphere(1.5f, 48, 32, &ball_mesh)) != OB_OK ||
        (r = ob_mesh_plane(60.0f, 60.0f, 8, &ground_mesh)) != OB_OK)
        goto done;
    ob_geometry *ball = ob_demo_geometry(d, &ball_mesh, "mirror-ball");
    ob_geometry *ground = ob_demo_geometry(d, &ground_mesh, "ground");
    if (!ball || !ground) { r = OB_ERR_BAD_MODEL; goto done; }

    ob_material *palette[OB_MIRROR_SCENE_COLOURS];
    if ((r = ob_mirror_scene_palette(d, true, palette)) != OB_OK) goto done;
    ob_material *ground_mat = ob_mirror_scene_ground_material(d, &r);
    if (!ground_mat) goto done;
    ob_material_desc mm = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .casts_shadows = true,
                           .diffuse = {0.9f, 0.9f, 0.95f, 1.0f}, .reflectivity = 0.85f};
    ob_material *mirror_mat = ob_material_create(d->lib, &mm, &r);
    if (!mirror_mat) goto done;

    if (!ob_demo_entity(d, NULL, "ground", ground, ground_mat)) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    if ((r = add_mirrors(d, ball, mirror_mat)) != OB_OK) goto done;
    if ((r = ob_mirror_scene_objects(d, desc->objects, desc->seed, 0.0, shapes, palette)) != OB_OK)
        goto done;
    if ((r = ob_mirror_scene_lights(d, true)) != OB_OK) goto done;
    r = add_fountain(d, desc->seed);
done:
    ob_mesh_release(&ball_mesh);
    ob_mesh_release(&ground_mesh);
    if (r != OB_OK)
        OB_LOG_E("demo", "building the mirror scene (%u objects) failed: %s", desc->objects,
                 ob_result_name(r));
    return r;
}

void ob_mirror_scene_camera(ob_node *camera, double time)
{
    double a = 0.15 * time + 0.6;
    double eye[3] = {17.0 * cos(a), 7.0, 17.0 * sin(a)}, target[3] = {0.0, 1.2, 0.0};
    double up[3] = {0.0, 1.0, 0.0};
    ob_node_set_position(camera, eye);
    ob_node_look_at(camera, target, up);
}
