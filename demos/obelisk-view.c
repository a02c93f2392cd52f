/* obelisk-view — renders a scene file (.json, see docs/scene-format.md) or a
 * single model file (.gltf, .glb, .obj, .ply and whatever else assimp reads).
 *
 * A model is framed automatically: a camera fitted to its bounding sphere
 * looking at its centre from a 3/4 view, a shadow-casting directional light
 * and a ground plane under it. A scene file is parsed and checked completely
 * before the device is created: a malformed one exits with code 2 and one
 * message naming the file and the JSON path. The library's loader
 * (ob_scene_load.h) then builds it: a model of the scene that fails to load
 * is reported (entity and file) and left out; the rest renders.
 *
 * Output, threading and stats options are those of obelisk-mirror
 * (ob_demo_run); command-line options win over the file's "settings".
 */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "ob_demo.h"
#include "ob_scene_load.h"

#define EXIT_BAD_INPUT 2

/* ------------------------------------------------------------ one model */

/* The model on a ground plane under a shadow-casting sun, framed. */
static ob_result build_model_view(ob_demo *d, const ob_mesh *mesh, const char *path)
{
    ob_result r = OB_OK;
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    ob_geometry *model = ob_demo_geometry(d, mesh, base);
    if (!model) return OB_ERR_BAD_MODEL;
    const ob_bounds *bb = ob_geometry_bounds(model);
    double radius = bb->radius > 0.0f ? bb->radius : 1.0;
    ob_mesh plane = {0};
    if ((r = ob_mesh_plane((float)(radius * 12.0), (float)(radius * 12.0), 1, &plane)) != OB_OK) return r;
    ob_geometry *ground = ob_demo_geometry(d, &plane, "ground");
    ob_mesh_release(&plane);
    if (!ground) return OB_ERR_OUT_OF_DEVICE_MEMORY;
    ob_material_desc md = {.name = "model", .kind = OB_MATERIAL_LIT, .casts_shadows = true,
                           .diffuse = {0.82f, 0.8f, 0.76f, 1.0f}, .specular = {0.3f, 0.3f, 0.3f, 48.0f}};
    ob_material_desc gd = {.name = "ground", .kind = OB_MATERIAL_LIT,
                           .diffuse = {0.45f, 0.47f, 0.5f, 1.0f}, .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
    ob_material *mm = ob_material_create(d->lib, &md, &r);
    ob_material *gm = mm ? ob_material_create(d->lib, &gd, &r) : NULL;
    if (!gm) return r;
    if (!ob_demo_entity(d, NULL, base, model, mm)) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_node *floor = ob_demo_entity(d, NULL, "ground", ground, gm);
    if (!floor) return OB_ERR_OUT_OF_HOST_MEMORY;
    /* A hair below the lowest point, so the contact shadow is not z-fighting. */
    double floor_pos[3] = {bb->center[0], bb->min[1] - radius * 1e-3, bb->center[2]};
    ob_node_set_position(floor, floor_pos);
    double center[3] = {bb->center[0], bb->center[1], bb->center[2]};
    /* The sun a scene file without "lights" gets (ob_scene_load.h), aimed
     * from the origin: a directional light's position is unused. */
    static const ob_light_desc sun_desc = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.97f, 0.92f},
                                           .intensity = 1.0f, .casts_shadows = true};
    static const double sun_direction[3] = {-0.11, -0.77, -0.63}, up[3] = {0, 1, 0};
    ob_node *sun = ob_node_create(d->scene, NULL, "sun", &r);
    if (!sun) return r;
    if ((r = ob_node_set_light(sun, &sun_desc)) != OB_OK || (r = ob_node_look_at(sun, sun_direction, up)) != OB_OK)
        return r;
    ob_node_set_position(sun, center);
    return ob_scene_load_frame_sphere(d->camera, center, radius, (double)d->opt.width / d->opt.height);
}

/* ------------------------------------------------------------ main */

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* Scene settings fill what the command line left open. */
static void apply_settings(ob_demo_options *o, const ob_scene_file_settings *s)
{
    if (s->has_size && !o->size_given) o->width = s->width, o->height = s->height;
    if (s->has_threads && !o->threads_given) o->threads = s->threads;
    if (s->env_map_size && !o->env_size) o->env_size = s->env_map_size;
    if (s->shadow_map_size && !o->shadow_size) o->shadow_size = s->shadow_map_size;
    if (s->has_clear_color) memcpy(o->clear_color, s->clear_color, sizeof o->clear_color);
    if (s->has_ambient) memcpy(o->ambient, s->ambient, sizeof o->ambient);
    if (s->exposure > 0.0f && !o->exposure_given) o->exposure = s->exposure;
}

int main(int argc, char **argv)
{
    ob_demo_options opt;
    int code;
    if (!ob_demo_options_parse(argc, argv,
                               "  FILE              a scene (.json, docs/scene-format.md) or a model file\n"
                               "                    (.gltf .glb .obj .ply ...), framed automatically\n",
                               true, &opt, &code))
        return code;
    bool is_scene = has_suffix(opt.input, ".json");
    ob_scene_file sf = {0};
    ob_mesh mesh = {0};
    ob_result r;
    if (is_scene) {
        ob_scene_file_error err;
        if ((r = ob_scene_file_load(opt.input, &sf, &err)) != OB_OK) {
            fprintf(stderr, "obelisk-view: %s\n", err.message);
            return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
        }
        apply_settings(&opt, &sf.settings);
    } else if ((r = ob_model_load(&(ob_model_desc){.path = opt.input}, &mesh, NULL)) != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: the model did not load (%s: %s)\n", opt.input,
                ob_result_name(r), ob_result_text(r));
        return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
    }

    ob_demo d;
    ob_scene_loaded loaded = {0};
    r = ob_demo_init(&d, &opt);
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                ob_result_text(r));
    } else if (is_scene) {
        /* Settings were applied to the options above (the command line wins). */
        ob_scene_load_target t = {.renderer = d.r, .materials = d.lib, .views = d.views, .scene = d.scene};
        ob_scene_load_desc ld = {.file = &sf, .camera = d.camera,
                                 .frame_aspect = (double)opt.width / opt.height, .seed = opt.seed,
                                 .first_geometry_id = d.stack->geometry_count + 1};
        ob_scene_file_error err;
        if ((r = ob_scene_load(&t, &ld, &loaded, &err)) != OB_OK)
            fprintf(stderr, "obelisk-view: %s\n", err.message);
    } else if ((r = build_model_view(&d, &mesh, opt.input)) != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                ob_result_text(r));
    }
    ob_mesh_release(&mesh);
    if (r != OB_OK) {
        code = 1;
    } else {
        printf("obelisk-view: %s: %s, %ux%u, %s", opt.input, ob_device_name(ob_renderer_device(d.r)),
               opt.width, opt.height,
               opt.threads == 0 ? "single-threaded" : opt.threads < 0 ? "auto" : "multi-threaded");
        if (is_scene)
            printf(", %u entities (%u left out), %u lights, %u particle systems%s%s", loaded.entity_count,
                   loaded.left_out_count, loaded.light_count, loaded.particle_count,
                   sf.description ? "\n  " : "", sf.description ? sf.description : "");
        printf("\n");
        code = ob_demo_run(&d, NULL, NULL);
    }
    /* The loaded scene's geometry and particle systems are its own: they go
     * once no frame uses them, before the demo takes the scene and views down. */
    if (d.r) ob_renderer_wait_idle(d.r);
    ob_scene_unload(&loaded);
    ob_demo_shutdown(&d);
    ob_scene_file_release(&sf);
    return code;
}
