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
 *
 * Controls (the window, or --input headless; the runner's keys F1, S, W,
 * O and Escape come first): the left button drags the camera round its
 * target, the middle or right button (or shift + left) pans, the wheel
 * zooms (ob_orbit.h); F frames the whole scene's bounds; R reloads the
 * scene file. A scene file is also reloaded when it changes on disk
 * (its modification time, looked at about once a second). A reload that
 * does not parse, or does not build, keeps the old scene on screen and
 * prints why. The camera is left alone until the first control moves it,
 * so a run without input renders what it always did.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "ob_demo.h"
#include "ob_orbit.h"
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
    ob_node *root = ob_node_create(d->world.scene, NULL, base, &r);
    if (!root) return r;
    *out_root = root;
    uint32_t entities = 0;
    if ((r = ob_model_assets_instantiate(assets, d->world.scene, root, NULL, &entities)) != OB_OK) return r;
    double lo[3], hi[3], center[3], radius;
    if ((r = ob_framing_measure(d->world.scene, NULL, lo, hi, center, &radius)) != OB_OK) return r;
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
    ob_material *gm = ob_material_create(d->world.lib, &gd, &r);
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
    ob_node *sun = ob_node_create(d->world.scene, NULL, "sun", &r);
    if (!sun) return r;
    if ((r = ob_node_set_light(sun, &sun_desc)) != OB_OK || (r = ob_node_look_at(sun, sun_direction, up)) != OB_OK)
        return r;
    ob_node_set_position(sun, center);
    return ob_framing_aim_camera(d->world.camera, center, radius, (double)d->opt.width / d->opt.height);
}

/* ------------------------------------------------------------ controls */

/* How often a scene file's modification time is looked at. */
#define RELOAD_POLL_NS 1000000000ull

typedef enum drag_mode { DRAG_NONE, DRAG_ORBIT, DRAG_PAN } drag_mode;

/* What the viewer's controls and the reload work on. */
typedef struct viewer {
    ob_demo *d;
    const char *path;
    bool is_scene;
    ob_scene_file sf;             /* the scene on screen's description */
    ob_scene_loaded loaded;
    ob_scene_load_desc ld;        /* how it was loaded (file: &sf) */
    /* The camera: an orbit set up from the camera once the scene is built,
     * applied to the camera node only after a control moved it. */
    ob_orbit orbit;
    bool orbit_valid, moved, user_moved;
    drag_mode drag;
    ob_mouse_button drag_button;
    double last_x, last_y;
    bool have_cursor;
    /* Reloading. */
    struct timespec mtime;
    uint64_t next_poll_ns;
    bool reload_now;
    uint32_t reloads;
} viewer;

static double camera_fovy(const viewer *v)
{
    const ob_camera_desc *c = ob_node_get_camera(v->d->world.camera);
    return c && c->fovy > 0.0f ? c->fovy : 1.0;
}

static double viewport_height(const viewer *v)
{
    uint32_t w = 0, h = 0;
    if (v->d->window) ob_window_size(v->d->window, &w, &h);
    return h ? h : v->d->opt.height;
}

static double aspect(const viewer *v)
{
    uint32_t w = 0, h = 0;
    if (v->d->window) ob_window_size(v->d->window, &w, &h);
    return w && h ? (double)w / h : (double)v->d->opt.width / v->d->opt.height;
}

/* The scene's bounds now (after an update): centre and radius. */
static bool scene_sphere(viewer *v, double center[3], double *radius)
{
    double lo[3], hi[3];
    if (ob_framing_measure(v->d->world.scene, NULL, lo, hi, center, radius) != OB_OK) return false;
    return hi[0] >= lo[0] && isfinite(*radius) && *radius > 0.0;
}

/* The orbit that reproduces the camera as it stands: its eye, looking along
 * its forward axis at the depth of the scene's centre. */
static void orbit_from_camera(viewer *v)
{
    double center[3] = {0, 0, 0}, radius = 1.0;
    bool bounded = scene_sphere(v, center, &radius);
    double eye[3];
    float right[3], up[3], fwd[3];
    ob_node_world_position(v->d->world.camera, eye);
    ob_node_world_axes(v->d->world.camera, right, up, fwd);
    double depth = 0.0;
    for (int k = 0; k < 3; k++) depth += (center[k] - eye[k]) * fwd[k];
    if (!(depth > radius * 1e-3)) depth = radius;   /* the scene behind or around the eye */
    double target[3];
    for (int k = 0; k < 3; k++) target[k] = eye[k] + fwd[k] * depth;
    v->orbit_valid = ob_orbit_from_eye(&v->orbit, eye, target);
    if (v->orbit_valid && bounded) {
        v->orbit.min_distance = fmin(radius * 1e-2, v->orbit.distance);
        v->orbit.max_distance = fmax(radius * 1e3, v->orbit.distance);
    }
}

static void note_camera(viewer *v)
{
    double eye[3];
    ob_orbit_eye(&v->orbit, eye);
    snprintf(v->d->overlay_extra, sizeof v->d->overlay_extra,
             "camera: eye %.3g %.3g %.3g  target %.3g %.3g %.3g  distance %.3g", eye[0], eye[1],
             eye[2], v->orbit.target[0], v->orbit.target[1], v->orbit.target[2], v->orbit.distance);
}

/* The orbit onto the camera node, before the frame's update. */
static void apply_camera(viewer *v)
{
    if (!v->moved || !v->orbit_valid) return;
    v->moved = false;
    double eye[3];
    static const double up[3] = {0, 1, 0};
    ob_orbit_eye(&v->orbit, eye);
    ob_node_set_position(v->d->world.camera, eye);
    ob_node_look_at(v->d->world.camera, v->orbit.target, up);
    const ob_camera_desc *c = ob_node_get_camera(v->d->world.camera);
    ob_camera_desc cam = c ? *c : (ob_camera_desc){.fovy = 1.0f};
    cam.znear = (float)ob_orbit_znear(&v->orbit);
    ob_node_set_camera(v->d->world.camera, &cam);
    note_camera(v);
}

static void moved(viewer *v, bool ok)
{
    if (!ok) return;
    v->moved = v->user_moved = true;
}

static void frame_all(viewer *v)
{
    double center[3], radius;
    if (!scene_sphere(v, center, &radius)) {
        printf("input: F: nothing to frame (the scene draws nothing)\n");
        return;
    }
    bool ok = ob_orbit_frame(&v->orbit, center, radius, camera_fovy(v), aspect(v));
    moved(v, ok);
    if (ok)
        printf("input: F: framed the scene (centre %.4g %.4g %.4g, radius %.4g)\n", center[0],
               center[1], center[2], radius);
}

static void on_key(void *user, int key, bool shift)
{
    viewer *v = user;
    if (key == 'F' && !shift) frame_all(v);
    else if (key == 'R' && !shift) {
        if (v->is_scene) v->reload_now = true;
        else printf("input: R: only scene files (.json) reload; %s is a model\n", v->path);
    }
}

static void on_button(void *user, ob_mouse_button b, bool down, bool shift)
{
    viewer *v = user;
    if (down && v->drag == DRAG_NONE) {
        v->drag = b == OB_BUTTON_LEFT && !shift ? DRAG_ORBIT : DRAG_PAN;
        v->drag_button = b;
    } else if (!down && b == v->drag_button) {
        v->drag = DRAG_NONE;
    }
}

static void on_cursor(void *user, double x, double y)
{
    viewer *v = user;
    double dx = x - v->last_x, dy = y - v->last_y;
    bool had = v->have_cursor;
    v->last_x = x, v->last_y = y, v->have_cursor = true;
    if (!had || v->drag == DRAG_NONE || !v->orbit_valid) return;
    if (v->drag == DRAG_ORBIT) moved(v, ob_orbit_rotate(&v->orbit, dx, dy, viewport_height(v)));
    else moved(v, ob_orbit_pan(&v->orbit, dx, dy, viewport_height(v), camera_fovy(v)));
}

static void on_scroll(void *user, double steps)
{
    viewer *v = user;
    if (v->orbit_valid) moved(v, ob_orbit_zoom(&v->orbit, steps));
}

/* ------------------------------------------------------------ reload */

static bool file_mtime(const char *path, struct timespec *out)
{
    struct stat st;
    if (stat(path, &st) != 0) return false;
    *out = st.st_mtim;
    return true;
}

/* Builds v->sf into the scene (the camera follows the file unless the user
 * has moved it). */
static ob_result load_scene(viewer *v, ob_scene_file_error *err)
{
    ob_demo *d = v->d;
    ob_scene_load_target t = {.renderer = d->world.r, .materials = d->world.lib, .views = d->world.views, .scene = d->world.scene};
    v->ld.file = &v->sf;
    return ob_scene_load(&t, &v->ld, &v->loaded, err);
}

/* The file again: parsed first, so a broken file leaves the scene on
 * screen as it is; then the old scene goes and the new one is built. If
 * that fails, the old description is built again. */
static void reload_scene(viewer *v)
{
    ob_scene_file next = {0};
    ob_scene_file_error err;
    ob_result r = ob_scene_file_load(v->path, &next, &err);
    if (r != OB_OK) {
        printf("obelisk-view: reload: %s\nobelisk-view: reload: keeping the scene on screen\n",
               err.message);
        ob_scene_file_release(&next);
        return;
    }
    if ((r = ob_renderer_wait_idle(v->d->world.r)) != OB_OK) {
        ob_scene_file_release(&next);
        return;
    }
    ob_scene_unload(&v->loaded);
    ob_scene_file previous = v->sf;
    v->sf = next;
    if ((r = load_scene(v, &err)) != OB_OK) {
        printf("obelisk-view: reload: %s\nobelisk-view: reload: building the previous version "
               "again\n", err.message);
        ob_scene_file_release(&v->sf);
        v->sf = previous;
        if (load_scene(v, &err) != OB_OK) printf("obelisk-view: reload: %s\n", err.message);
    } else {
        ob_scene_file_release(&previous);
        v->reloads++;
        printf("obelisk-view: reloaded %s: %u entities (%u left out), %u lights\n", v->path,
               v->loaded.entity_count, v->loaded.left_out_count, v->loaded.light_count);
    }
    /* The user's camera stays; otherwise the file's (or the framing) is the
     * new starting point. */
    if (v->user_moved) v->moved = true;
    else orbit_from_camera(v);
}

/* Each frame, before the update: the orbit onto the camera, and a reload
 * when the file changed (looked at about once a second) or R asked. */
static void update(ob_demo *d, uint32_t frame, double time, void *user)
{
    (void)d;
    (void)frame;
    (void)time;
    viewer *v = user;
    if (v->is_scene) {
        uint64_t now = ob_time_ns();
        bool reload = v->reload_now;
        if (now >= v->next_poll_ns) {
            struct timespec m;
            v->next_poll_ns = now + RELOAD_POLL_NS;
            if (file_mtime(v->path, &m) && (m.tv_sec != v->mtime.tv_sec || m.tv_nsec != v->mtime.tv_nsec)) {
                v->mtime = m;
                reload = true;
            }
        }
        if (v->reload_now) file_mtime(v->path, &v->mtime);
        v->reload_now = false;
        if (reload) reload_scene(v);
    }
    apply_camera(v);
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
    /* cJSON's allocations counted with Obelisk's (the heap figures). */
    ob_scene_file_hook_cjson();
    int code;
    if (!ob_demo_options_parse(argc, argv,
                               "  FILE              a scene (.json, docs/scene-format.md) or a model file\n"
                               "                    (.gltf .glb .obj .ply ...), framed automatically\n"
                               "  --allow-missing   render a scene whose models did not all load and exit 0\n"
                               "                    (without it: the rest renders, then exit 2)\n"
                               "  --allow-any-folder  let models and scene files refer to files outside\n"
                               "                    their own folder (trusted content only)\n"
                               "mouse and keys of obelisk-view (in the window, or from --input):\n"
                               "  left drag         orbit the camera round its target\n"
                               "  middle or right drag, or shift + left drag\n"
                               "                    pan (the scene follows the cursor)\n"
                               "  wheel             zoom towards / away from the target\n"
                               "  F                 frame the whole scene (its bounds)\n"
                               "  R                 reload the scene file now; it also reloads when it\n"
                               "                    changes on disk (a file that does not parse keeps\n"
                               "                    the old scene on screen and prints the error)\n",
                               true, &opt, &code))
        return code;
    viewer v = {.path = opt.input, .is_scene = has_suffix(opt.input, ".json")};
    ob_model *model = NULL;
    ob_result r;
    if (v.is_scene) {
        ob_scene_file_error err;
        file_mtime(opt.input, &v.mtime);   /* before the parse: a change after it reloads */
        if ((r = ob_scene_file_load(opt.input, &v.sf, &err)) != OB_OK) {
            fprintf(stderr, "obelisk-view: %s\n", err.message);
            return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
        }
        apply_settings(&opt, &v.sf.settings);
    } else if ((r = ob_model_open(&(ob_model_desc){.path = opt.input, .flip_uv = true,
                                                   .allow_any_folder = opt.allow_any_folder},
                                  &model)) != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: the model did not load (%s: %s)\n", opt.input,
                ob_result_name(r), ob_result_text(r));
        return r == OB_ERR_OUT_OF_HOST_MEMORY ? 1 : EXIT_BAD_INPUT;
    }

    ob_demo d;
    ob_model_assets *assets = NULL;
    ob_node *model_root = NULL;
    r = ob_demo_init(&d, &opt);
    v.d = &d;
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                ob_result_text(r));
    } else if (v.is_scene) {
        /* Settings were applied to the options above (the command line wins). */
        v.ld = (ob_scene_load_desc){.camera = d.world.camera, .frame_aspect = (double)opt.width / opt.height,
                                    .seed = opt.seed, .first_geometry_id = d.world.stack->geometry_count + 1,
                                    .allow_any_folder = opt.allow_any_folder};
        ob_scene_file_error err;
        if ((r = load_scene(&v, &err)) != OB_OK) fprintf(stderr, "obelisk-view: %s\n", err.message);
    } else {
        /* Geometry ids derived from the contents: the ground uploaded after
         * takes the stack's next id. */
        ob_model_assets_desc ad = {.renderer = d.world.r, .materials = d.world.lib};
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
        code = !v.is_scene && assets && r == OB_ERR_BAD_MODEL ? EXIT_BAD_INPUT : 1;
    } else {
        printf("obelisk-view: %s: %s, %ux%u, threading %s (%u workers)", opt.input,
               ob_device_name(ob_renderer_device(d.world.r)), opt.width, opt.height,
               ob_threading_name(ob_demo_options_threading(&opt)), ob_renderer_worker_count(d.world.r));
        if (v.is_scene)
            printf(", %u entities (%u left out), %u lights, %u particle systems%s%s", v.loaded.entity_count,
                   v.loaded.left_out_count, v.loaded.light_count, v.loaded.particle_count,
                   v.sf.description ? "\n  " : "", v.sf.description ? v.sf.description : "");
        printf("\n");
        orbit_from_camera(&v);
        if (v.orbit_valid) note_camera(&v);
        ob_demo_set_input(&d, &(ob_input_handler){on_key, on_button, on_cursor, on_scroll, &v});
        v.next_poll_ns = ob_time_ns() + RELOAD_POLL_NS;
        code = ob_demo_run(&d, update, &v);
        if (code == 0 && v.is_scene && v.loaded.left_out_count && !opt.allow_missing)
            code = report_left_out(opt.input, &v.sf, &v.loaded);
    }
    /* The loaded scene's geometry and particle systems are its own: they go
     * once no frame uses them, before the demo takes the scene and views down. */
    if (d.world.r) ob_renderer_wait_idle(d.world.r);
    ob_scene_unload(&v.loaded);
    /* The model's entities draw with its assets: they go first. */
    if (model_root) ob_node_destroy(model_root);
    ob_model_assets_destroy(assets);
    ob_demo_shutdown(&d);
    ob_scene_file_release(&v.sf);
    return code;
}
