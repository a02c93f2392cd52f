#include "ob_mirror_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t next_random(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float random01(uint32_t *s) { return (float)next_random(s) / (float)(1u << 24); }

/* ------------------------------------------------------------ the definition
 * Every number of the scene is here once; ob_mirror_scene_build makes the
 * scene from it and ob_mirror_scene_write_json writes it as a scene file
 * (demos/scenes/mirror.json). */

static const char *const shape_names[OB_MIRROR_SCENE_SHAPES] = {"box", "sphere", "torus", "cone"};
static const float box_half = 0.35f;
static const struct { float radius; uint32_t slices, stacks; } shape_sphere = {0.4f, 16, 10};
static const struct { float major, minor; uint32_t major_segments, minor_segments; } shape_torus = {
    0.35f, 0.12f, 20, 10};
static const struct { float radius, height; uint32_t slices; } shape_cone = {0.35f, 0.8f, 16};
static const struct { float radius; uint32_t slices, stacks; } ball = {1.5f, 48, 32};
static const struct { float width, depth; uint32_t subdivisions; } ground = {60.0f, 60.0f, 8};

/* Colours are authored sRGB-encoded, as a scene file writes them (the
 * generated mirror.json holds these numbers), and decoded to linear light
 * where materials and lights are made. */
static void linear3(const float srgb[3], float out[3])
{
    for (int i = 0; i < 3; i++) out[i] = ob_srgb_to_linear(srgb[i]);
}

static ob_material_desc linear_material(const ob_material_desc *authored)
{
    ob_material_desc d = *authored;
    linear3(authored->diffuse, d.diffuse);
    linear3(authored->specular, d.specular);
    return d;
}

static const float palette_colors[OB_MIRROR_SCENE_COLOURS][3] = {
    {0.9f, 0.3f, 0.25f}, {0.25f, 0.7f, 0.35f}, {0.3f, 0.45f, 0.9f}, {0.95f, 0.8f, 0.3f},
    {0.8f, 0.4f, 0.85f}, {0.3f, 0.85f, 0.85f}, {0.95f, 0.55f, 0.2f}, {0.85f, 0.85f, 0.85f},
};
static const ob_material_desc ground_material = {
    .name = "ground", .kind = OB_MATERIAL_LIT, .diffuse = {0.55f, 0.55f, 0.5f, 1.0f},
    .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
static const ob_material_desc mirror_material = {
    .name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .casts_shadows = true,
    .diffuse = {0.9f, 0.9f, 0.95f, 1.0f}, .reflectivity = 0.85f};

#define MIRRORS 3
static void mirror_position(int i, double out[3])
{
    double a = 2.0 * 3.14159265358979 * i / 3.0;
    out[0] = 3.2 * cos(a);
    out[1] = 1.6;
    out[2] = 3.2 * sin(a);
}

/* One orbiting object, drawn from the seed (the draws in this order). */
typedef struct mirror_object {
    uint32_t kind, colour;
    double center[3], radius;
    float speed, phase;          /* radians per second, radians */
    float spin[3], spin_speed;   /* spin axis (not normalised), radians per second */
} mirror_object;

static mirror_object object_params(uint32_t *seed, double spread_to)
{
    mirror_object o = {0};
    o.kind = next_random(seed) % OB_MIRROR_SCENE_SHAPES;
    o.colour = next_random(seed) % OB_MIRROR_SCENE_COLOURS;
    double u = random01(seed);
    o.radius = spread_to > 0.0 ? sqrt(36.0 + u * (spread_to * spread_to - 36.0)) : 6.0 + 14.0 * u;
    o.center[1] = 0.4 + 3.0 * random01(seed);
    float speed = (0.1f + 0.3f * random01(seed)) * (random01(seed) < 0.5f ? -1.0f : 1.0f);
    if (spread_to > 0.0) speed *= (float)(20.0 / o.radius);
    o.speed = speed;
    o.phase = 6.2831853f * random01(seed);
    float spin[3] = {random01(seed) - 0.5f, 1.0f, random01(seed) - 0.5f};
    memcpy(o.spin, spin, sizeof spin);
    o.spin_speed = 0.5f + 2.0f * random01(seed);
    return o;
}
static const float orbit_axis[3] = {0.0f, 1.0f, 0.0f};

static const struct { const char *name; ob_light_desc desc; double position[3]; } sun = {
    "sun", {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.96f, 0.9f}, .intensity = 1.0f},
    {12.0, 20.0, 8.0}};   /* aimed at the origin */
static const struct { const char *name; ob_light_desc desc; double position[3]; } points[2] = {
    {"red-light", {.type = OB_LIGHT_POINT, .color = {1.0f, 0.4f, 0.2f}, .intensity = 2.0f,
                   .range = 14.0f}, {7.0, 2.5, -5.0}},
    {"blue-light", {.type = OB_LIGHT_POINT, .color = {0.2f, 0.5f, 1.0f}, .intensity = 2.0f,
                    .range = 14.0f}, {-7.0, 2.5, 5.0}},
};

static const double fountain_position[3] = {0.0, 0.2, 0.0};
static ob_particle_desc fountain_particles(uint32_t seed)
{
    return (ob_particle_desc){.name = "sparks", .count = 4096, .seed = seed, .lifetime = 2.5f,
                              .speed = 3.0f, .size = 0.06f, .gravity = {0.0f, -2.5f, 0.0f}};
}

/* The camera's circle (ob_mirror_scene_camera) and obelisk-mirror's lens. */
static void camera_at(double time, double eye[3])
{
    double a = 0.15 * time + 0.6;
    eye[0] = 17.0 * cos(a);
    eye[1] = 7.0;
    eye[2] = 17.0 * sin(a);
}
static const double camera_target[3] = {0.0, 1.2, 0.0};

/* ------------------------------------------------------------ building */

static ob_result add_mirrors(ob_demo *d, ob_geometry *ball_geometry, ob_material *mirror_mat)
{
    for (int i = 0; i < MIRRORS; i++) {
        char name[32];
        snprintf(name, sizeof name, "mirror%d", i);
        ob_node *n = ob_demo_entity(d, NULL, name, ball_geometry, mirror_mat);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        double p[3];
        mirror_position(i, p);
        ob_node_set_position(n, p);
    }
    return OB_OK;
}

/* Shape k at level of detail `level`: level 0 is the scene's shape, each
 * level after it has about 0.6 times the segments (at least 3; the box has
 * level 0 only). */
static ob_result shape_mesh(int k, uint32_t level, ob_mesh *out)
{
    static const float keep[OB_MIRROR_SCENE_SHAPE_LODS] = {1.0f, 0.6f, 0.4f, 0.25f};
    float f = keep[level];
#define SEG(n) ((uint32_t)fmaxf(3.0f, floorf((float)(n) * f + 0.5f)))
    switch (k) {
    case 0: return ob_mesh_box((const float[3]){box_half, box_half, box_half}, out);
    case 1: return ob_mesh_sphere(shape_sphere.radius, SEG(shape_sphere.slices),
                                  OB_MAX(2u, SEG(shape_sphere.stacks)), out);
    case 2: return ob_mesh_torus(shape_torus.major, shape_torus.minor,
                                 SEG(shape_torus.major_segments), SEG(shape_torus.minor_segments),
                                 out);
    default: return ob_mesh_cone(shape_cone.radius, shape_cone.height, SEG(shape_cone.slices), out);
    }
#undef SEG
}

/* Shape k with its levels of detail (none for the box or without lods). */
static ob_geometry *shape_geometry(ob_demo *d, int k, bool lods, ob_result *out_result)
{
    ob_mesh meshes[OB_MIRROR_SCENE_SHAPE_LODS] = {{0}};
    ob_geometry_lod levels[OB_MIRROR_SCENE_SHAPE_LODS - 1] = {{0}};
    uint32_t count = lods && k != 0 ? OB_MIRROR_SCENE_SHAPE_LODS : 1;
    ob_geometry *g = NULL;
    ob_result r = OB_OK;
    for (uint32_t l = 0; l < count && r == OB_OK; l++)
        if ((r = shape_mesh(k, l, &meshes[l])) == OB_OK && l > 0) levels[l - 1].mesh = &meshes[l];
    if (r == OB_OK) r = ob_geometry_measure_lods(&meshes[0], levels, count - 1);
    if (r == OB_OK) {
        ob_geometry_desc gd = {.mesh = &meshes[0], .name = shape_names[k], .lods = levels,
                               .lod_count = count - 1};
        g = ob_stack_add_geometry_desc(d->world.stack, &gd, &r);
    }
    for (uint32_t l = 0; l < count; l++) ob_mesh_release(&meshes[l]);
    *out_result = r;
    return g;
}

ob_result ob_mirror_scene_shapes(ob_demo *d, bool lods, ob_geometry *out[OB_MIRROR_SCENE_SHAPES])
{
    ob_result r = OB_OK;
    for (int k = 0; k < OB_MIRROR_SCENE_SHAPES && r == OB_OK; k++)
        out[k] = shape_geometry(d, k, lods, &r);
    return r;
}

ob_result ob_mirror_scene_palette(ob_demo *d, bool casts_shadows,
                                  ob_material *out[OB_MIRROR_SCENE_COLOURS])
{
    ob_result r = OB_OK;
    for (int i = 0; i < OB_MIRROR_SCENE_COLOURS; i++) {
        const float *c = palette_colors[i];
        ob_material_desc md = {.name = "diffuse", .kind = OB_MATERIAL_LIT,
                               .casts_shadows = casts_shadows, .diffuse = {0, 0, 0, 1.0f}};
        linear3(c, md.diffuse);
        if (!(out[i] = ob_material_create(d->world.lib, &md, &r))) return r;
    }
    return OB_OK;
}

ob_material *ob_mirror_scene_ground_material(ob_demo *d, ob_result *out_result)
{
    ob_material_desc md = linear_material(&ground_material);
    return ob_material_create(d->world.lib, &md, out_result);
}

ob_result ob_mirror_scene_objects(ob_demo *d, uint32_t objects, uint32_t seed, double spread_to,
                                  ob_geometry *const shapes[OB_MIRROR_SCENE_SHAPES],
                                  ob_material *const palette[OB_MIRROR_SCENE_COLOURS])
{
    for (uint32_t i = 0; i < objects; i++) {
        char name[32];
        snprintf(name, sizeof name, "object%u", i);
        mirror_object o = object_params(&seed, spread_to);
        ob_node *n = ob_demo_entity(d, NULL, name, shapes[o.kind], palette[o.colour]);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
        ob_result r = ob_node_add_orbit_controller(n, o.center, orbit_axis, o.radius, o.speed,
                                                   o.phase);
        if (r != OB_OK) return r;
        r = ob_node_add_rotation_controller(n, o.spin, o.spin_speed);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

ob_result ob_mirror_scene_lights(ob_demo *d, bool sun_shadows)
{
    ob_result r;
    ob_node *sun_node = ob_node_create(d->world.scene, NULL, sun.name, &r);
    if (!sun_node) return r;
    ob_light_desc ld = sun.desc;
    ld.casts_shadows = sun_shadows;
    linear3(sun.desc.color, ld.color);
    if ((r = ob_node_set_light(sun_node, &ld)) != OB_OK) return r;
    double origin[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    ob_node_set_position(sun_node, sun.position);
    if ((r = ob_node_look_at(sun_node, origin, up)) != OB_OK) return r;

    for (int i = 0; i < 2; i++) {
        ob_node *pl = ob_node_create(d->world.scene, NULL, points[i].name, &r);
        if (!pl) return r;
        ob_light_desc pd = points[i].desc;
        linear3(points[i].desc.color, pd.color);
        if ((r = ob_node_set_light(pl, &pd)) != OB_OK) return r;
        ob_node_set_position(pl, points[i].position);
    }
    return OB_OK;
}

static ob_result add_fountain(ob_demo *d, uint32_t seed)
{
    ob_result r;
    ob_node *fountain = ob_node_create(d->world.scene, NULL, "fountain", &r);
    if (!fountain) return r;
    ob_node_set_position(fountain, fountain_position);
    ob_particle_desc pdesc = fountain_particles(seed);
    ob_demo_particles(d, fountain, &pdesc, &r);   /* r: why it failed, as the views said */
    return r;
}

/* Geometry ids follow upload order (the command hashes fold them in): the
 * four shapes, the mirror ball, the ground. */
ob_result ob_mirror_scene_build(ob_demo *d, const ob_mirror_scene_desc *desc)
{
    ob_mesh ball_mesh = {0}, ground_mesh = {0};
    ob_geometry *shapes[OB_MIRROR_SCENE_SHAPES];
    ob_result r = ob_mirror_scene_shapes(d, false, shapes);
    if (r != OB_OK || (r = ob_mesh_sphere(ball.radius, ball.slices, ball.stacks, &ball_mesh)) != OB_OK ||
        (r = ob_mesh_plane(ground.width, ground.depth, ground.subdivisions, &ground_mesh)) != OB_OK)
        goto done;
    ob_geometry *ball_geometry = ob_demo_geometry(d, &ball_mesh, "mirror-ball");
    ob_geometry *ground_geometry = ob_demo_geometry(d, &ground_mesh, "ground");
    if (!ball_geometry || !ground_geometry) { r = OB_ERR_BAD_MODEL; goto done; }

    ob_material *palette[OB_MIRROR_SCENE_COLOURS];
    if ((r = ob_mirror_scene_palette(d, true, palette)) != OB_OK) goto done;
    ob_material *ground_mat = ob_mirror_scene_ground_material(d, &r);
    if (!ground_mat) goto done;
    ob_material_desc mirror_desc = linear_material(&mirror_material);
    ob_material *mirror_mat = ob_material_create(d->world.lib, &mirror_desc, &r);
    if (!mirror_mat) goto done;

    if (!ob_demo_entity(d, NULL, "ground", ground_geometry, ground_mat)) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    if ((r = add_mirrors(d, ball_geometry, mirror_mat)) != OB_OK) goto done;
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
    double eye[3], up[3] = {0.0, 1.0, 0.0};
    camera_at(time, eye);
    ob_node_set_position(camera, eye);
    ob_node_look_at(camera, camera_target, up);
}

/* ------------------------------------------------------------ as a scene file */

/* The shortest text that reads back as the same float / double. */
static void put_f(FILE *f, float v)
{
    char buf[32];
    for (int p = 6; p <= 9; p++) {
        snprintf(buf, sizeof buf, "%.*g", p, (double)v);
        if (strtof(buf, NULL) == v) break;
    }
    fputs(buf, f);
}

static void put_d(FILE *f, double v)
{
    char buf[40];
    for (int p = 6; p <= 17; p++) {
        snprintf(buf, sizeof buf, "%.*g", p, v);
        if (strtod(buf, NULL) == v) break;
    }
    fputs(buf, f);
}

static void put_fv(FILE *f, const float *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) {
        if (i) fputs(", ", f);
        put_f(f, v[i]);
    }
    fputc(']', f);
}

static void put_dv(FILE *f, const double *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) {
        if (i) fputs(", ", f);
        put_d(f, v[i]);
    }
    fputc(']', f);
}

/* Radians as the file's degrees. The loader reads degrees as a float and
 * makes (float)(degrees * pi/180): of the floats next to the plain
 * conversion, take one that gives back exactly these radians. */
static float degrees(float radians)
{
    const double to_rad = 3.14159265358979323846 / 180.0;
    float g = (float)((double)radians * (180.0 / 3.14159265358979323846));
    float lo = g, hi = g;
    for (int k = 0; k < 8; k++) {
        if ((float)((double)lo * to_rad) == radians) return lo;
        if ((float)((double)hi * to_rad) == radians) return hi;
        lo = nextafterf(lo, -INFINITY);
        hi = nextafterf(hi, INFINITY);
    }
    return g;   /* none: the --check of the file reports the difference */
}

static void put_material(FILE *f, const char *key, const ob_material_desc *m, bool casts_shadows,
                         bool last)
{
    fprintf(f, "    \"%s\": { \"kind\": \"%s\", \"diffuse\": ", key,
            m->kind == OB_MATERIAL_REFLECTIVE ? "reflective" : "lit");
    put_fv(f, m->diffuse, 3);
    if (m->specular[3] > 0.0f) {   /* zero is the library's default, as the file's */
        fputs(", \"specular\": ", f);
        put_fv(f, m->specular, 4);
    }
    if (m->kind == OB_MATERIAL_REFLECTIVE) {
        fputs(", \"reflectivity\": ", f);
        put_f(f, m->reflectivity);
    }
    fprintf(f, ", \"casts_shadows\": %s }%s\n", casts_shadows ? "true" : "false", last ? "" : ",");
}

static void put_shape(FILE *f, uint32_t kind)
{
    switch (kind) {
    case 0:
        fputs("{ \"generator\": \"box\", \"size\": ", f);
        put_f(f, 2.0f * box_half);
        break;
    case 1:
        fputs("{ \"generator\": \"sphere\", \"radius\": ", f);
        put_f(f, shape_sphere.radius);
        fprintf(f, ", \"slices\": %u, \"stacks\": %u", shape_sphere.slices, shape_sphere.stacks);
        break;
    case 2:
        fputs("{ \"generator\": \"torus\", \"major_radius\": ", f);
        put_f(f, shape_torus.major);
        fputs(", \"minor_radius\": ", f);
        put_f(f, shape_torus.minor);
        fprintf(f, ", \"major_segments\": %u, \"minor_segments\": %u", shape_torus.major_segments,
                shape_torus.minor_segments);
        break;
    default:
        fputs("{ \"generator\": \"cone\", \"radius\": ", f);
        put_f(f, shape_cone.radius);
        fputs(", \"height\": ", f);
        put_f(f, shape_cone.height);
        fprintf(f, ", \"slices\": %u", shape_cone.slices);
        break;
    }
    fputs(" }", f);
}

static void put_light(FILE *f, const char *name, const ob_light_desc *l, const double position[3],
                      bool last)
{
    fprintf(f, "    { \"name\": \"%s\", \"type\": \"%s\", \"position\": ", name,
            l->type == OB_LIGHT_DIRECTIONAL ? "directional" : "point");
    put_dv(f, position, 3);
    if (l->type == OB_LIGHT_DIRECTIONAL) fputs(", \"target\": [0, 0, 0]", f);
    fputs(", \"color\": ", f);
    put_fv(f, l->color, 3);
    fputs(", \"intensity\": ", f);
    put_f(f, l->intensity);
    if (l->type == OB_LIGHT_POINT) {
        fputs(", \"range\": ", f);
        put_f(f, l->range);
    } else {
        fprintf(f, ", \"shadows\": %s", l->casts_shadows ? "true" : "false");
    }
    fprintf(f, " }%s\n", last ? "" : ",");
}

ob_result ob_mirror_scene_write_json(const ob_mirror_scene_desc *desc, FILE *f)
{
    uint32_t seed = desc->seed;
    fprintf(f, "{\n  \"description\": \"obelisk-mirror's scene (Hieroglyph 3's MirrorMirror): "
               "three reflective spheres see each other through dual-paraboloid environment maps "
               "while %u shapes orbit them; a sun casts shadows, two point lights tint the ground "
               "and sparks rise from a fountain. Written by obelisk-mirror-scene (objects %u, "
               "seed %u) from demos/scenes/ob_mirror_scene.c, the definition obelisk-mirror and "
               "obelisk-bench use: do not edit, regenerate.\",\n",
            desc->objects, desc->objects, desc->seed);
    /* obelisk-mirror's defaults (ob_demo): 640x480, the stack's map sizes and colours. */
    fputs("  \"settings\": { \"size\": [640, 480], \"env_map_size\": 256, "
          "\"shadow_map_size\": 1024 },\n", f);
    double eye[3];
    camera_at(0.0, eye);
    fputs("  \"camera\": { \"position\": ", f);
    put_dv(f, eye, 3);
    fputs(", \"target\": ", f);
    put_dv(f, camera_target, 3);
    fputs(", \"fov_degrees\": ", f);
    put_d(f, 1.0 * (180.0 / 3.14159265358979323846));
    fputs(", \"near\": 0.05 },\n", f);

    fputs("  \"lights\": [\n", f);
    ob_light_desc sun_desc = sun.desc;
    sun_desc.casts_shadows = true;
    put_light(f, sun.name, &sun_desc, sun.position, false);
    for (int i = 0; i < 2; i++) put_light(f, points[i].name, &points[i].desc, points[i].position, i == 1);
    fputs("  ],\n", f);

    fputs("  \"materials\": {\n", f);
    for (int i = 0; i < OB_MIRROR_SCENE_COLOURS; i++) {
        char key[16];
        snprintf(key, sizeof key, "diffuse%d", i);
        ob_material_desc m = {.kind = OB_MATERIAL_LIT};
        memcpy(m.diffuse, palette_colors[i], sizeof palette_colors[i]);
        put_material(f, key, &m, true, false);
    }
    put_material(f, "ground", &ground_material, ground_material.casts_shadows, false);
    put_material(f, "mirror", &mirror_material, mirror_material.casts_shadows, true);
    fputs("  },\n", f);

    fputs("  \"entities\": [\n", f);
    fputs("    { \"name\": \"ground\", \"material\": \"ground\", \"geometry\": "
          "{ \"generator\": \"plane\", \"width\": ", f);
    put_f(f, ground.width);
    fputs(", \"depth\": ", f);
    put_f(f, ground.depth);
    fprintf(f, ", \"subdivisions\": %u } },\n", ground.subdivisions);
    for (int i = 0; i < MIRRORS; i++) {
        double p[3];
        mirror_position(i, p);
        fprintf(f, "    { \"name\": \"mirror%d\", \"material\": \"mirror\", \"geometry\": "
                   "{ \"generator\": \"sphere\", \"radius\": ", i);
        put_f(f, ball.radius);
        fprintf(f, ", \"slices\": %u, \"stacks\": %u }, \"transform\": { \"position\": ",
                ball.slices, ball.stacks);
        put_dv(f, p, 3);
        fputs(" } },\n", f);
    }
    for (uint32_t i = 0; i < desc->objects; i++) {
        mirror_object o = object_params(&seed, 0.0);
        fprintf(f, "    { \"name\": \"object%u\", \"material\": \"diffuse%u\", \"geometry\": ", i,
                o.colour);
        put_shape(f, o.kind);
        fputs(",\n      \"controllers\": [ { \"orbit\": { \"center\": ", f);
        put_dv(f, o.center, 3);
        fputs(", \"axis\": ", f);
        put_fv(f, orbit_axis, 3);
        fputs(", \"radius\": ", f);
        put_d(f, o.radius);
        fputs(", \"speed_degrees\": ", f);
        put_f(f, degrees(o.speed));
        fputs(", \"phase_degrees\": ", f);
        put_f(f, degrees(o.phase));
        fputs(" } },\n                       { \"rotate\": { \"axis\": ", f);
        put_fv(f, o.spin, 3);
        fputs(", \"speed_degrees\": ", f);
        put_f(f, degrees(o.spin_speed));
        fputs(" } } ] },\n", f);
    }
    fputs("    { \"name\": \"fountain\", \"transform\": { \"position\": ", f);
    put_dv(f, fountain_position, 3);
    fputs(" } }\n  ],\n", f);

    /* The particle system's seed is the loader's: its seed (obelisk-view's
     * --seed, 1 by default) plus the system's index 0, as desc->seed here. */
    ob_particle_desc p = fountain_particles(desc->seed);
    fprintf(f, "  \"particles\": [\n    { \"name\": \"%s\", \"parent\": \"fountain\", \"count\": %u, "
               "\"lifetime\": ", p.name, p.count);
    put_f(f, p.lifetime);
    fputs(", \"speed\": ", f);
    put_f(f, p.speed);
    fputs(", \"size\": ", f);
    put_f(f, p.size);
    fputs(", \"gravity\": ", f);
    put_fv(f, p.gravity, 3);
    fputs(" }\n  ]\n}\n", f);
    return ferror(f) ? OB_ERR_IO : OB_OK;
}
