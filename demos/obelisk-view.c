/* obelisk-view — renders a scene file (.json, see docs/scene-format.md) or a
 * single model file (.gltf, .glb, .obj, .ply and whatever else assimp reads).
 *
 * A model keeps its structure (ob_model_open, ob_model_instance.h): one
 * entity per node of the file and one per primitive, each with the model's
 * own material, under one root entity. It is framed automatically: a camera
 * fitted to its bounding sphere looking at its centre from a 3/4 view, a
 * shadow-casting directional light and a ground plane under it. A model
 * that does not open (a parse error, a failed check, a required glTF
 * extension the engine lacks) exits with code 2 and the loader's message. A scene file is parsed and checked completely
 * before the device is created: a malformed one exits with code 2 and one
 * message naming the file and the JSON path. The library's loader
 * (ob_scene_load.h) then builds it: a model of the scene that fails to load
 * is reported (entity and file) and left out; the rest renders, and the
 * exit code is 2 unless --allow-missing. Files a model or a scene refers to
 * must stay inside its folder unless --allow-any-folder.
 *
 * Output, threading and stats options are those of obelisk-mirror
 * (ob_demo_run); command-line options win over the file's "settings".
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "ob_demo.h"
#include "ob_scene_load.h"

#define EXIT_BAD_INPUT 2
/* How far from the origin a framed model may reach: the ground plane is 12
 * radii wide and the camera stands a few radii off, all in single
 * precision (docs/limits.md). */
#define OB_VIEW_MAX_EXTENT 1e15

/* ------------------------------------------------------------ one model */

/* The model (its assets already made) on a ground plane under a
 * shadow-casting sun, framed. *out_root gets the model's root entity. */
static ob_result build_model_view(ob_demo *d, ob_model_assets *assets, const char *path,
                                  ob_node **out_root)
{
    ob_result r = OB_OK;
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    ob_node *root = ob_node_create(d->scene, NULL, base, &r);
    if (!root) return r;
    *out_root = root;
    uint32_t entities = 0;
    if ((r = ob_model_assets_instantiate(assets, d->scene, root, NULL, &entities)) != OB_OK) return r;
    double lo[3], hi[3], center[3], radius;
    if ((r = ob_framing_measure(d->scene, NULL, lo, hi, center, &radius)) != OB_OK) return r;
    /* Bounds that overflowed (node scales of 1e38 nested) or are too large to
     * frame (positions near 3e38) are the model's problem: said so here,
     * before the automatic ground and sun fail on sizes nobody asked for. */
    bool finite = isfinite(radius) && isfinite(center[0]) && isfinite(center[1]) && isfinite(center[2]);
    double reach = finite ? radius + fmax(fabs(center[0]), fmax(fabs(center[1]), fabs(center[2]))) : INFINITY;
    if (!(hi[0] >= lo[0]) || !(reach <= OB_VIEW_MAX_EXTENT)) {
        fprintf(stderr, "obelisk-view: %s: the model cannot be framed: its world bounds %s (centre %g %g %g, "
                "radius %g; at most %g from the origin): check its units and node scales\n", path,
                !(hi[0] >= lo[0]) ? "are empty" : !finite ? "are not finite (they overflowed)" : "are too large",
                center[0], center[1],
                center[2], radius, OB_VIEW_MAX_EXTENT);
        return OB_ERR_BAD_MODEL;
    }
    if (!(radius > 0.0)) radius = 1.0;
    const ob_model *model = ob_model_assets_model(assets);
    printf("obelisk-view: %s: %u nodes, %u primitives, %u materials, %u images: %u entities\n", path,
           model->node_count, model->primitive_count, model->material_count, model->image_count, entities);
    ob_mesh plane = {0};
    if ((r = ob_mesh_plane((float)(radius * 12.0), (float)(radius * 12.0), 1, &plane)) != OB_OK) return r;
    ob_geometry *ground = ob_demo_geometry(d, &plane, "ground");
    ob_mesh_release(&plane);
    if (!ground) return OB_ERR_OUT_OF_DEVICE_MEMORY;
    ob_material_desc gd = {.name = "ground", .kind = OB_MATERIAL_LIT,
                           .diffuse = {0.45f, 0.47f, 0.5f, 1.0f}, .specular = {0.05f, 0.05f, 0.05f, 8.0f}};
    ob_material *gm = ob_material_create(d->lib, &gd, &r);
    if (!gm) return r;
    ob_node *floor = ob_demo_entity(d, NULL, "ground", ground, gm);
    if (!floor) return OB_ERR_OUT_OF_HOST_MEMORY;
    /* A hair below the lowest point, so the contact shadow is not z-fighting. */
    double floor_pos[3] = {center[0], lo[1] - radius * 1e-3, center[2]};
    ob_node_set_position(floor, floor_pos);
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
    return ob_framing_aim_camera(d->camera, center, radius, (double)d->opt.width / d->opt.height);
}

/* ------------------------------------------------------------ main */

/* A scene rendered without some of its models is bad input: each is named
 * (the loader's own lines said why), and the exit is 2 unless
 * --allow-missing. */
static int report_left_out(const char *path, const ob_scene_file *sf, const ob_scene_loaded *loaded)
{
    fprintf(stderr, "obelisk-view: %s: %u %s left out because %s model did not load:\n", path,
            loaded->left_out_count, loaded->left_out_count == 1 ? "entity was" : "entities were",
            loaded->left_out_count == 1 ? "its" : "their");
    for (uint32_t i = 0; i < loaded->left_out_count; i++) {
        const ob_scene_file_entity *e = &sf->entities[loaded->left_out[i].entity];
        fprintf(stderr, "  entities[%u] '%s': model '%s' (%s)\n", e->index, e->name, e->geometry.model,
                ob_result_name(loaded->left_out[i].result));
    }
    fprintf(stderr, "obelisk-view: the rest was rendered; --allow-missing accepts this and exits 0\n");
    return EXIT_BAD_INPUT;
}

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
    if (s->has_env_map_kind && !o->env_map_given) o->env_map_kind = s->env_map_kind;
    if (s->has_sky_color) memcpy(o->sky_color, s->sky_color, sizeof o->sky_color);
}

int main(int argc, char **argv)
{
    ob_demo_options opt;
    int code;
    if (!ob_demo_options_parse(argc, argv,
                               "  FILE              a scene (.json, docs/scene-format.md) or a model file\n"
                               "                    (.gltf .glb .obj .ply ...), framed automatically\n"
                               "  --allow-missing   render a scene whose models did not all load and exit 0\n"
                               "                    (without it: the rest renders, then exit 2)\n"
                               "  --allow-any-folder  let models and scene files refer to files outside\n"
                               "                    their own folder (trusted content only)\n",
                               true, &opt, &code))
        return code;
    bool is_scene = has_suffix(opt.input, ".json");
    ob_scene_file sf = {0};
    ob_model *model = NULL;
    ob_result r;
    if (is_scene) {
        ob_scene_file_error err;
        if ((r = ob_scene_file_load(opt.input, &sf, &err)) != OB_OK) {
            fprintf(stderr, "obelisk-view: %s\n", err.message);
            return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
        }
        apply_settings(&opt, &sf.settings);
    } else if ((r = ob_model_open(&(ob_model_desc){.path = opt.input, .flip_uv = true,
                                                   .allow_any_folder = opt.allow_any_folder},
                                  &model)) != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: the model did not load (%s: %s)\n", opt.input,
                ob_result_name(r), ob_result_text(r));
        return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
    }

    ob_demo d;
    ob_scene_loaded loaded = {0};
    ob_model_assets *assets = NULL;
    ob_node *model_root = NULL;
    r = ob_demo_init(&d, &opt);
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                ob_result_text(r));
    } else if (is_scene) {
        /* Settings were applied to the options above (the command line wins). */
        ob_scene_load_target t = {.renderer = d.r, .materials = d.lib, .views = d.views, .scene = d.scene};
        ob_scene_load_desc ld = {.file = &sf, .camera = d.camera,
                                 .frame_aspect = (double)opt.width / opt.height, .seed = opt.seed,
                                 .first_geometry_id = d.stack->geometry_count + 1,
                                 .allow_any_folder = opt.allow_any_folder};
        ob_scene_file_error err;
        if ((r = ob_scene_load(&t, &ld, &loaded, &err)) != OB_OK)
            fprintf(stderr, "obelisk-view: %s\n", err.message);
    } else {
        /* Geometry ids derived from the contents: the ground uploaded after
         * takes the stack's next id. */
        ob_model_assets_desc ad = {.renderer = d.r, .materials = d.lib};
        assets = ob_model_assets_create(&ad, model, &r);   /* takes the model */
        model = NULL;
        if (assets) r = build_model_view(&d, assets, opt.input, &model_root);
        if (r != OB_OK)
            fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                    ob_result_text(r));
    }
    ob_model_close(model);   /* only when the device did not come up */
    if (r != OB_OK) {
        /* The model's own bounds are bad input; the rest is the engine's. */
        code = !is_scene && assets && r == OB_ERR_BAD_MODEL ? EXIT_BAD_INPUT : 1;
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
        if (code == 0 && is_scene && loaded.left_out_count && !opt.allow_missing)
            code = report_left_out(opt.input, &sf, &loaded);
    }
    /* The loaded scene's geometry and particle systems are its own: they go
     * once no frame uses them, before the demo takes the scene and views down. */
    if (d.r) ob_renderer_wait_idle(d.r);
    ob_scene_unload(&loaded);
    /* The model's entities draw with its assets: they go first. */
    if (model_root) ob_node_destroy(d.scene, model_root);
    ob_model_assets_destroy(assets);
    ob_demo_shutdown(&d);
    ob_scene_file_release(&sf);
    return code;
}
