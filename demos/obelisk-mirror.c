/* obelisk-mirror — Hieroglyph 3's MirrorMirror on Obelisk.
 *
 * Three reflective spheres whose dual-paraboloid environment maps see each
 * other (a hall of mirrors, bounded by the renderer's recursion limit), N
 * diffuse objects orbiting and spinning around them, a shadow-casting
 * directional light, a particle fountain and a text overlay. Headless by
 * default: it renders --frames frames, prints a line per frame and a
 * summary, and writes --out. --threads / --toggle choose single- or
 * multi-threaded recording per frame; the pixels are the same either way. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ob_demo.h"

#define KINDS 4
#define PALETTE 8

typedef struct mirror_scene {
    ob_node *center;
} mirror_scene;

static uint32_t next_random(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float random01(uint32_t *s) { return (float)next_random(s) / (float)(1u << 24); }

static ob_result build_scene(ob_demo *d)
{
    ob_result r = OB_OK;
    ob_mesh meshes[KINDS + 2] = {{0}};
    float half[3] = {0.35f, 0.35f, 0.35f};
    if ((r = ob_mesh_box(half, &meshes[0])) != OB_OK ||
        (r = ob_mesh_sphere(0.4f, 16, 10, &meshes[1])) != OB_OK ||
        (r = ob_mesh_torus(0.35f, 0.12f, 20, 10, &meshes[2])) != OB_OK ||
        (r = ob_mesh_cone(0.35f, 0.8f, 16, &meshes[3])) != OB_OK ||
        (r = ob_mesh_sphere(1.5f, 48, 32, &meshes[4])) != OB_OK ||
        (r = ob_mesh_plane(60.0f, 60.0f, 8, &meshes[5])) != OB_OK)
        goto done;
    static const char *const kind_names[KINDS] = {"box", "sphere", "torus", "cone"};
    ob_geometry *kinds[KINDS];
    for (int k = 0; k < KINDS; k++) {
        kinds[k] = ob_demo_geometry(d, &meshes[k], kind_names[k]);
        if (!kinds[k]) { r = OB_ERR_BAD_MODEL; goto done; }
    }
    ob_geometry *ball = ob_demo_geometry(d, &meshes[4], "mirror-ball");
    ob_geometry *ground = ob_demo_geometry(d, &meshes[5], "ground");
    if (!ball || !ground) { r = OB_ERR_BAD_MODEL; goto done; }

    ob_material *palette[PALETTE];
    static const float colors[PALETTE][3] = {
        {0.9f, 0.3f, 0.25f}, {0.25f, 0.7f, 0.35f}, {0.3f, 0.45f, 0.9f}, {0.95f, 0.8f, 0.3f},
        {0.8f, 0.4f, 0.85f}, {0.3f, 0.85f, 0.85f}, {0.95f, 0.55f, 0.2f}, {0.85f, 0.85f, 0.85f},
    };
    for (int i = 0; i < PALETTE; i++) {
        ob_material_desc md = {.name = "diffuse", .kind = OB_MATERIAL_LIT, .casts_shadows = true,
                               .diffuse = {colors[i][0], colors[i][1], colors[i][2], 1.0f}};
        palette[i] = ob_material_create(d->lib, &md, &r);
        if (!palette[i]) goto done;
    }
    ob_material_desc gm = {.name = "ground", .kind = OB_MATERIAL_LIT,
                           .diffuse = {0.55f, 0.55f, 0.5f, 1.0f}, .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
    ob_material *ground_mat = ob_material_create(d->lib, &gm, &r);
    ob_material_desc mm = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE, .casts_shadows = true,
                           .diffuse = {0.9f, 0.9f, 0.95f, 1.0f}, .reflectivity = 0.85f};
    ob_material *mirror_mat = ob_material_create(d->lib, &mm, &r);
    if (!ground_mat || !mirror_mat) goto done;

    if (!ob_demo_entity(d, NULL, "ground", ground, ground_mat)) { r = OB_ERR_OUT_OF_HOST_MEMORY; goto done; }
    for (int i = 0; i < 3; i++) {
        char name[32];
        snprintf(name, sizeof name, "mirror%d", i);
        ob_node *n = ob_demo_entity(d, NULL, name, ball, mirror_mat);
        if (!n) { r = OB_ERR_OUT_OF_HOST_MEMORY; goto done; }
        double a = 2.0 * 3.14159265358979 * i / 3.0;
        double p[3] = {3.2 * cos(a), 1.6, 3.2 * sin(a)};
        ob_node_set_position(n, p);
    }

    /* Orbiting, spinning objects in rings around the mirrors. */
    uint32_t seed = d->opt.seed;
    for (uint32_t i = 0; i < d->opt.objects; i++) {
        char name[32];
        snprintf(name, sizeof name, "object%u", i);
        uint32_t kind = next_random(&seed) % KINDS;
        ob_material *m = palette[next_random(&seed) % PALETTE];
        ob_node *n = ob_demo_entity(d, NULL, name, kinds[kind], m);
        if (!n) { r = OB_ERR_OUT_OF_HOST_MEMORY; goto done; }
        double radius = 6.0 + 14.0 * random01(&seed);
        double center[3] = {0.0, 0.4 + 3.0 * random01(&seed), 0.0};
        float axis[3] = {0.0f, 1.0f, 0.0f};
        float speed = (0.1f + 0.3f * random01(&seed)) * (random01(&seed) < 0.5f ? -1.0f : 1.0f);
        ob_node_add_orbit_controller(n, center, axis, radius, speed, 6.2831853f * random01(&seed));
        float spin[3] = {random01(&seed) - 0.5f, 1.0f, random01(&seed) - 0.5f};
        ob_node_add_rotation_controller(n, spin, 0.5f + 2.0f * random01(&seed));
    }

    ob_node *sun = ob_node_create(d->scene, NULL, "sun", &r);
    if (!sun) goto done;
    ob_light_desc ld = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.96f, 0.9f},
                        .intensity = 1.0f, .casts_shadows = true};
    if ((r = ob_node_set_light(sun, &ld)) != OB_OK) goto done;
    double sun_pos[3] = {12.0, 20.0, 8.0}, origin[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    ob_node_set_position(sun, sun_pos);
    ob_node_look_at(sun, origin, up);

    static const float point_colors[2][3] = {{1.0f, 0.4f, 0.2f}, {0.2f, 0.5f, 1.0f}};
    for (int i = 0; i < 2; i++) {
        ob_node *pl = ob_node_create(d->scene, NULL, i ? "blue-light" : "red-light", &r);
        if (!pl) goto done;
        ob_light_desc pd = {.type = OB_LIGHT_POINT, .intensity = 2.0f, .range = 14.0f};
        memcpy(pd.color, point_colors[i], sizeof pd.color);
        ob_node_set_light(pl, &pd);
        double p[3] = {i ? -7.0 : 7.0, 2.5, i ? 5.0 : -5.0};
        ob_node_set_position(pl, p);
    }

    ob_node *fountain = ob_node_create(d->scene, NULL, "fountain", &r);
    if (!fountain) goto done;
    double fp[3] = {0.0, 0.2, 0.0};
    ob_node_set_position(fountain, fp);
    ob_particle_desc pdesc = {.name = "sparks", .count = 4096, .seed = d->opt.seed,
                              .lifetime = 2.5f, .speed = 3.0f, .size = 0.06f,
                              .gravity = {0.0f, -2.5f, 0.0f}};
    if (!ob_demo_particles(d, fountain, &pdesc)) { r = OB_ERR_OUT_OF_HOST_MEMORY; goto done; }

done:
    for (int i = 0; i < KINDS + 2; i++) ob_mesh_release(&meshes[i]);
    return r;
}

/* The camera circles the mirrors slowly, looking at their centre. */
static void animate(ob_demo *d, uint32_t frame, double time, void *user)
{
    (void)frame;
    (void)user;
    double a = 0.15 * time + 0.6;
    double eye[3] = {17.0 * cos(a), 7.0, 17.0 * sin(a)}, target[3] = {0.0, 1.2, 0.0};
    double up[3] = {0.0, 1.0, 0.0};
    ob_node_set_position(d->camera, eye);
    ob_node_look_at(d->camera, target, up);
}

int main(int argc, char **argv)
{
    ob_demo_options opt;
    int code;
    if (!ob_demo_options_parse(argc, argv, "  --objects N       orbiting objects (default 200, up to 100000)\n",
                               false, &opt, &code))
        return code;
    ob_demo d;
    ob_result r = ob_demo_init(&d, &opt);
    if (r == OB_OK) r = build_scene(&d);
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-mirror: set-up failed: %s (%s)\n", ob_result_name(r), ob_result_text(r));
        ob_demo_shutdown(&d);
        return 1;
    }
    printf("obelisk-mirror: %s, %u objects, %ux%u, %s\n",
           ob_device_name(ob_renderer_device(d.r)), opt.objects, opt.width, opt.height,
           opt.threads == 0 ? "single-threaded" : opt.threads < 0 ? "auto" : "multi-threaded");
    code = ob_demo_run(&d, animate, NULL);
    ob_demo_shutdown(&d);
    return code;
}
