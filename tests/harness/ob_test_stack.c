#define _POSIX_C_SOURCE 200809L
#include "ob_test_stack.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ob_result ob_test_stack_start(ob_test_stack *s, const ob_test_stack_desc *desc)
{
    ob_test_setup_log();
    ob_test_stack_desc d = desc ? *desc : (ob_test_stack_desc){0};
    memset(s, 0, sizeof *s);
    s->workers = d.workers ? d.workers : 2;
    s->width = d.width ? d.width : 48;
    s->height = d.height ? d.height : 32;
    s->env_map_size = d.env_map_size ? d.env_map_size : 16;
    s->shadow_map_size = d.shadow_map_size ? d.shadow_map_size : 32;
    if (d.cache_dir) {
        snprintf(s->cache_dir, sizeof s->cache_dir, "%s", d.cache_dir);
    } else {
        const char *base = getenv("OB_CACHE_DIR");
        snprintf(s->cache_dir, sizeof s->cache_dir, "%s", base && *base ? base : "/tmp/obelisk-test-stack");
        if (base && *base) strncat(s->cache_dir, "/stack", sizeof s->cache_dir - strlen(s->cache_dir) - 1);
    }

    ob_world_desc wd = {.stack = {
        .renderer = {.device = {.app_name = "obelisk-test-stack", .validation = 1, .adopt = d.adopt},
                     .worker_count = s->workers, .chunk_draws = d.chunk_draws,
                     .parallel_grain = d.parallel_grain},
        .cache_dir = s->cache_dir,
        .width = s->width, .height = s->height,
        .clear_color = {0.1f, 0.2f, 0.3f, 1.0f},
        .camera = {.fovy = 1.0f, .znear = 0.1f},
        .env_map_size = s->env_map_size, .shadow_map_size = s->shadow_map_size,
        .msaa = d.msaa,
        .env_map_kind = d.env_map_kind,
    }};
    if (d.clear_color[3] > 0.0f) memcpy(wd.stack.clear_color, d.clear_color, sizeof d.clear_color);
    ob_result r = ob_world_create(&s->world, &wd);
    if (r != OB_OK) ob_test_stack_stop(s);
    return r;
}

/* Uploads the mesh `made` filled (a failed make passes its result on) and
 * releases it. */
static ob_result add_geometry(ob_test_stack *s, ob_result made, ob_mesh *m, const char *name,
                              ob_geometry **out)
{
    *out = NULL;
    ob_result r = made;
    if (r == OB_OK) *out = ob_stack_add_geometry(s->world.stack, m, name, &r);
    ob_mesh_release(m);
    return r;
}

static ob_node *add_entity(ob_test_stack *s, const char *name, ob_geometry *g, ob_material *m,
                           double x, double y, double z, ob_result *out_result)
{
    ob_node *n = ob_stack_add_entity(s->world.stack, NULL, name, g, m, out_result);
    if (n) ob_node_set_position(n, (const double[3]){x, y, z});
    return n;
}

ob_result ob_test_stack_build_scene(ob_test_stack *s)
{
    ob_stack *st = s->world.stack;
    ob_node_set_position(st->camera, (const double[3]){0.0, 1.6, 4.0});
    ob_result r = ob_node_look_at(st->camera, (const double[3]){0.0, 0.4, 0.0},
                                  (const double[3]){0, 1, 0});
    if (r != OB_OK) return r;

    ob_geometry *box, *sphere, *plane;
    ob_mesh m = {0};
    if ((r = add_geometry(s, ob_mesh_box((const float[3]){0.4f, 0.4f, 0.4f}, &m), &m, "box", &box)) != OB_OK)
        return r;
    if ((r = add_geometry(s, ob_mesh_sphere(0.45f, 12, 8, &m), &m, "sphere", &sphere)) != OB_OK)
        return r;
    if ((r = add_geometry(s, ob_mesh_plane(8.0f, 8.0f, 1, &m), &m, "ground", &plane)) != OB_OK)
        return r;

    ob_material_desc lit = {.name = "red", .kind = OB_MATERIAL_LIT, .diffuse = {0.9f, 0.3f, 0.2f, 1.0f},
                            .casts_shadows = true};
    ob_material *red = ob_material_create(st->materials, &lit, &r);
    if (!red) return r;
    ob_material_desc ground = {.name = "ground", .kind = OB_MATERIAL_LIT,
                               .diffuse = {0.6f, 0.6f, 0.55f, 1.0f}};
    ob_material *grey = ob_material_create(st->materials, &ground, &r);
    if (!grey) return r;
    ob_material_desc mirror = {.name = "mirror", .kind = OB_MATERIAL_REFLECTIVE,
                               .diffuse = {0.9f, 0.9f, 0.95f, 1.0f}, .reflectivity = 0.8f,
                               .casts_shadows = true};
    ob_material *shiny = ob_material_create(st->materials, &mirror, &r);
    if (!shiny) return r;

    if (!add_entity(s, "ground", plane, grey, 0.0, 0.0, 0.0, &r)) return r;
    if (!add_entity(s, "box", box, red, -0.8, 0.4, 0.0, &r)) return r;
    if (!add_entity(s, "ball", sphere, shiny, 0.8, 0.45, 0.0, &r)) return r;

    ob_node *sun = ob_node_create(st->scene, NULL, "sun", &r);
    if (!sun) return r;
    ob_light_desc ld = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 1.0f, 1.0f},
                        .intensity = 1.0f, .casts_shadows = true};
    if ((r = ob_node_set_light(sun, &ld)) != OB_OK) return r;
    ob_node_set_position(sun, (const double[3]){3.0, 6.0, 4.0});
    if ((r = ob_node_look_at(sun, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0})) != OB_OK)
        return r;

    /* Shadowed local lights (issue 28): a spot's perspective map and a
     * point light's cube, layers of the shared local shadow array. */
    ob_node *spot = ob_node_create(st->scene, NULL, "torch", &r);
    if (!spot) return r;
    ob_light_desc sd = {.type = OB_LIGHT_SPOT, .intensity = 3.0f, .range = 8.0f,
                        .inner_angle = 0.4f, .outer_angle = 0.7f, .casts_shadows = true};
    if ((r = ob_node_set_light(spot, &sd)) != OB_OK) return r;
    ob_node_set_position(spot, (const double[3]){-0.5, 2.5, 1.0});
    if ((r = ob_node_look_at(spot, (const double[3]){0, 0, 0}, (const double[3]){0, 1, 0})) != OB_OK)
        return r;
    ob_node *bulb = ob_node_create(st->scene, NULL, "bulb", &r);
    if (!bulb) return r;
    ob_light_desc bd = {.type = OB_LIGHT_POINT, .intensity = 1.5f, .range = 5.0f, .casts_shadows = true};
    if ((r = ob_node_set_light(bulb, &bd)) != OB_OK) return r;
    ob_node_set_position(bulb, (const double[3]){0.0, 1.0, 0.8});

    ob_node *fountain = ob_node_create(st->scene, NULL, "fountain", &r);
    if (!fountain) return r;
    ob_node_set_position(fountain, (const double[3]){0.0, 1.2, 0.6});
    /* Shorter than a frame: every step respawns every particle from the
     * simulation time, so no frame's pixels depend on an earlier frame. */
    ob_particle_desc pdesc = {.name = "sparks", .count = 64, .seed = 7, .lifetime = 0.005f,
                              .speed = 1.0f, .size = 0.15f};
    s->particles = ob_particle_system_create(st->views, st->scene, fountain, &pdesc, &r);
    if (!s->particles) return r;
    return OB_OK;
}

ob_result ob_test_stack_frame(ob_test_stack *s, ob_threading mode, uint32_t workers)
{
    ob_result r = ob_test_stack_frame_begin(s, mode, workers);
    return r == OB_OK ? ob_test_stack_frame_end(s) : r;
}

ob_result ob_test_stack_frame_begin(ob_test_stack *s, ob_threading mode, uint32_t workers)
{
    s->frames++;
    ob_result r = ob_world_frame_begin(&s->world, mode, workers, NULL, 0);
    for (int k = 0; r == OB_OK && k < OB_FAULT_KIND_COUNT; k++)
        s->fault_points_before_record[k] = ob_fault_count((ob_fault_kind)k);
    return r;
}

ob_result ob_test_stack_frame_end(ob_test_stack *s) { return ob_world_frame_end(&s->world); }

ob_result ob_test_stack_read(ob_test_stack *s, uint8_t *out)
{
    return ob_image_read_rgba8(s->world.dev, ob_stack_final_image(s->world.stack), out);
}

void ob_test_stack_stop(ob_test_stack *s)
{
    if (s->world.r) ob_renderer_wait_idle(s->world.r);
    if (s->world.stack) ob_particle_system_destroy(s->world.views, s->particles);
    ob_world_destroy(&s->world);
    memset(s, 0, sizeof *s);
}
