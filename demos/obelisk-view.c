/* obelisk-view — renders a scene file (.json, see docs/scene-format.md) or a
 * single model file (.gltf, .glb, .obj, .ply and whatever else assimp reads).
 *
 * A model is framed automatically: a camera fitted to its bounding sphere
 * looking at its centre from a 3/4 view, a shadow-casting directional light
 * and a ground plane under it. A scene file is parsed and checked completely
 * before the device is created: a malformed one exits with code 2 and one
 * message naming the file and the JSON path. A model of the scene that fails
 * to load is reported (entity and file) and left out; the rest renders.
 *
 * Output, threading and stats options are those of obelisk-mirror
 * (ob_demo_run); command-line options win over the file's "settings".
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "ob_demo.h"
#include "ob_scene_file.h"

#define DEG (3.14159265358979323846 / 180.0)
#define EXIT_BAD_INPUT 2

/* One uploaded (or failed) geometry, shared by entities that describe it alike. */
typedef struct shared_geometry {
    const ob_scene_file_geometry *desc;
    ob_geometry *geometry;   /* NULL: the model failed to load ... */
    ob_result result;        /* ... with this result */
} shared_geometry;

typedef struct scene_builder {
    ob_demo *d;
    const ob_scene_file *sf;
    ob_material **materials;
    ob_material *default_material;
    ob_node **nodes;
    shared_geometry *shared;
    uint32_t shared_count, shared_cap;
    uint32_t left_out;       /* entities whose model did not load */
} scene_builder;

/* ------------------------------------------------------------ geometry */

static ob_result generate_mesh(const ob_scene_file_geometry *g, ob_mesh *mesh)
{
    switch (g->kind) {
    case OB_SCENE_GEOMETRY_BOX: {
        float half[3] = {g->size[0] * 0.5f, g->size[1] * 0.5f, g->size[2] * 0.5f};
        return ob_mesh_box(half, mesh);
    }
    case OB_SCENE_GEOMETRY_SPHERE: return ob_mesh_sphere(g->radius, g->segments[0], g->segments[1], mesh);
    case OB_SCENE_GEOMETRY_PLANE: return ob_mesh_plane(g->width, g->depth, g->segments[0], mesh);
    case OB_SCENE_GEOMETRY_CONE: return ob_mesh_cone(g->radius, g->height, g->segments[0], mesh);
    case OB_SCENE_GEOMETRY_TORUS:
        return ob_mesh_torus(g->major_radius, g->minor_radius, g->segments[0], g->segments[1], mesh);
    case OB_SCENE_GEOMETRY_MODEL: return ob_model_load(&(ob_model_desc){.path = g->model}, mesh, NULL);
    case OB_SCENE_GEOMETRY_NONE: break;
    }
    return OB_ERR_INVALID_ARGUMENT;
}

static void report_left_out(scene_builder *b, const ob_scene_file_entity *e, ob_result r)
{
    char where[96];
    snprintf(where, sizeof where, "entities[%u]", e->index);
    fprintf(stderr, "obelisk-view: %s: %s%s%s%s: model '%s' did not load (%s: %s); the entity is left out\n",
            b->sf->path, where, strcmp(e->name, where) ? " '" : "", strcmp(e->name, where) ? e->name : "",
            strcmp(e->name, where) ? "'" : "", e->geometry.model, ob_result_name(r), ob_result_text(r));
    b->left_out++;
}

/* The entity's geometry, uploaded once per distinct description. NULL with
 * *out_result OB_OK when a model did not load (reported, entity left out). */
static ob_geometry *entity_geometry(scene_builder *b, const ob_scene_file_entity *e, ob_result *out_result)
{
    *out_result = OB_OK;
    for (uint32_t i = 0; i < b->shared_count; i++) {
        if (!ob_scene_file_geometry_equal(b->shared[i].desc, &e->geometry)) continue;
        if (!b->shared[i].geometry) report_left_out(b, e, b->shared[i].result);
        return b->shared[i].geometry;
    }
    ob_result r = ob_array_reserve((void **)&b->shared, &b->shared_cap, b->shared_count + 1, sizeof *b->shared);
    if (r != OB_OK) {
        *out_result = r;
        return NULL;
    }
    ob_mesh mesh = {0};
    ob_geometry *g = NULL;
    r = generate_mesh(&e->geometry, &mesh);
    if (r == OB_OK) {
        char name[64];
        snprintf(name, sizeof name, "%s", e->geometry.kind == OB_SCENE_GEOMETRY_MODEL
                 ? (strrchr(e->geometry.model, '/') ? strrchr(e->geometry.model, '/') + 1 : e->geometry.model)
                 : ob_scene_file_geometry_kind_name(e->geometry.kind));
        g = ob_demo_geometry(b->d, &mesh, name);
        if (!g) r = e->geometry.kind == OB_SCENE_GEOMETRY_MODEL ? OB_ERR_BAD_MODEL : OB_ERR_OUT_OF_DEVICE_MEMORY;
    }
    ob_mesh_release(&mesh);
    if (!g && e->geometry.kind != OB_SCENE_GEOMETRY_MODEL) {
        fprintf(stderr, "obelisk-view: %s: entities[%u] '%s': %s geometry failed: %s\n", b->sf->path,
                e->index, e->name, ob_scene_file_geometry_kind_name(e->geometry.kind), ob_result_name(r));
        *out_result = r;
        return NULL;
    }
    if (!g) report_left_out(b, e, r);
    b->shared[b->shared_count++] = (shared_geometry){.desc = &e->geometry, .geometry = g, .result = r};
    return g;
}

/* ------------------------------------------------------------ scene */

static ob_result add_light(ob_demo *d, const char *name, const ob_light_desc *desc,
                           const double position[3], const double direction[3])
{
    ob_result r;
    ob_node *n = ob_node_create(d->scene, NULL, name, &r);
    if (!n) return r;
    if ((r = ob_node_set_light(n, desc)) != OB_OK) return r;
    /* The engine reads a zero colour as white (its default): hide a black
     * light instead. Intensity 0 is literal and needs nothing here. */
    bool black = desc->color[0] == 0.0f && desc->color[1] == 0.0f && desc->color[2] == 0.0f;
    ob_node_set_hidden(n, black);
    if (desc->type == OB_LIGHT_DIRECTIONAL) {
        /* Aimed from the origin: position + direction could round back to a
         * far-away position, and a directional light's position is unused. */
        double up[3] = {0, 1, 0};
        if (fabs(direction[1]) > 0.99) up[1] = 0, up[2] = -1;
        if ((r = ob_node_look_at(n, direction, up)) != OB_OK) return r;
    }
    ob_node_set_position(n, position);
    return OB_OK;
}

static ob_result add_entity(scene_builder *b, const ob_scene_file_entity *e)
{
    ob_demo *d = b->d;
    ob_node *parent = e->parent != OB_SCENE_FILE_NONE ? b->nodes[e->parent] : NULL;
    ob_result r = OB_OK;
    ob_geometry *g = NULL;
    if (e->geometry.kind != OB_SCENE_GEOMETRY_NONE) {
        g = entity_geometry(b, e, &r);
        if (r != OB_OK) return r;
    }
    ob_node *n;
    if (g) {
        ob_material *m = e->material != OB_SCENE_FILE_NONE ? b->materials[e->material] : b->default_material;
        n = ob_demo_entity(d, parent, e->name, g, m);
        if (!n) return OB_ERR_OUT_OF_HOST_MEMORY;
    } else {
        /* Transform-only, or its model failed: kept so its children still render. */
        n = ob_node_create(d->scene, parent, e->name, &r);
        if (!n) return r;
    }
    b->nodes[e->index] = n;
    ob_node_set_position(n, e->position);
    if (e->rotation_kind == OB_SCENE_ROTATION_EULER)
        ob_node_set_euler(n, (float)(e->rotation[0] * DEG), (float)(e->rotation[1] * DEG),
                          (float)(e->rotation[2] * DEG));
    else if (e->rotation_kind == OB_SCENE_ROTATION_QUATERNION)
        ob_node_set_rotation_d(n, e->rotation);
    ob_node_set_scale(n, e->scale);
    ob_node_set_hidden(n, e->hidden);
    for (uint32_t k = 0; k < e->controller_count && r == OB_OK; k++) {
        const ob_scene_file_controller *c = &e->controllers[k];
        float rate = (float)(c->speed_degrees * DEG);
        if (c->kind == OB_SCENE_CONTROLLER_ROTATE)
            r = ob_node_add_rotation_controller(n, c->axis, rate);
        else
            r = ob_node_add_orbit_controller(n, c->center, c->axis, c->radius, rate,
                                             (float)(c->phase_degrees * DEG));
    }
    return r;
}

static const ob_light_desc default_sun = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.97f, 0.92f},
                                          .intensity = 1.0f, .casts_shadows = true};
static const double default_sun_direction[3] = {-0.11, -0.77, -0.63};

static ob_result build_scene(scene_builder *b)
{
    ob_demo *d = b->d;
    const ob_scene_file *sf = b->sf;
    ob_result r = OB_OK;
    b->materials = ob_calloc(sf->material_count + 1u, sizeof *b->materials);
    b->nodes = ob_calloc(sf->entity_count + 1u, sizeof *b->nodes);
    if (!b->materials || !b->nodes) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < sf->material_count; i++) {
        const ob_scene_file_material *m = &sf->materials[i];
        if (!(b->materials[i] = ob_material_create(d->lib, &m->desc, &r))) return r;
        /* desc.reflectivity 0 means "default" to the library; the file means 0. */
        if (m->desc.kind == OB_MATERIAL_REFLECTIVE &&
            (r = ob_material_set_reflectivity(b->materials[i], m->desc.reflectivity)) != OB_OK)
            return r;
    }
    ob_material_desc dm = {.name = "default", .kind = OB_MATERIAL_LIT, .casts_shadows = true,
                           .diffuse = {0.8f, 0.8f, 0.8f, 1.0f}};
    if (!(b->default_material = ob_material_create(d->lib, &dm, &r))) return r;
    for (uint32_t i = 0; i < sf->entity_count; i++)
        if ((r = add_entity(b, &sf->entities[i])) != OB_OK) return r;
    if (!sf->has_lights) {
        double origin[3] = {0, 0, 0};
        if ((r = add_light(d, "sun", &default_sun, origin, default_sun_direction)) != OB_OK) return r;
    }
    for (uint32_t i = 0; i < sf->light_count; i++) {
        const ob_scene_file_light *l = &sf->lights[i];
        if ((r = add_light(d, l->name, &l->desc, l->position, l->direction)) != OB_OK) return r;
    }
    for (uint32_t i = 0; i < sf->particle_count; i++) {
        const ob_scene_file_particles *p = &sf->particles[i];
        ob_particle_desc pd = p->desc;
        pd.seed = d->opt.seed + i;
        ob_node *parent = p->parent != OB_SCENE_FILE_NONE ? b->nodes[p->parent] : NULL;
        if (!ob_demo_particles(d, parent, &pd)) return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    return OB_OK;
}

static void builder_release(scene_builder *b)
{
    ob_free(b->materials);
    ob_free(b->nodes);
    ob_free(b->shared);
}

/* ------------------------------------------------------------ camera */

/* Points the camera at a bounding sphere from a 3/4 view above it, at the
 * distance where the sphere fills the narrower field of view. */
static ob_result frame_sphere(ob_demo *d, const double sphere_center[3], double radius)
{
    double center[3] = {0, 0, 0};
    if (isfinite(sphere_center[0] + sphere_center[1] + sphere_center[2]))
        memcpy(center, sphere_center, sizeof center);
    if (!(radius > 0.0) || !isfinite(radius)) radius = 1.0;
    const double fovy = 45.0 * DEG;
    double aspect = (double)d->opt.width / (double)d->opt.height;
    double half = fmin(fovy * 0.5, atan(tan(fovy * 0.5) * aspect));
    double dist = radius / sin(half) * 1.08;
    double dir[3] = {sin(35.0 * DEG) * cos(25.0 * DEG), sin(25.0 * DEG), cos(35.0 * DEG) * cos(25.0 * DEG)};
    double eye[3], up[3] = {0, 1, 0};
    for (int k = 0; k < 3; k++) eye[k] = center[k] + dir[k] * dist;
    ob_camera_desc cam = {.fovy = (float)fovy, .znear = (float)fmax(dist * 0.01, 1e-4)};
    ob_result r = ob_node_set_camera(d->camera, &cam);
    if (r != OB_OK) return r;
    ob_node_set_position(d->camera, eye);
    return ob_node_look_at(d->camera, center, up);
}

/* Frames every renderable of the scene (after one update, so world bounds exist). */
static ob_result frame_scene(ob_demo *d)
{
    ob_result r = ob_scene_update(d->scene, 0.0);
    if (r != OB_OK) return r;
    uint32_t n = 0;
    ob_node *const *nodes = ob_scene_renderables(d->scene, &n);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++) {
        double c[3];
        float rad;
        ob_node_world_sphere(nodes[i], c, &rad);
        for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], c[k] - rad), hi[k] = fmax(hi[k], c[k] + rad);
    }
    double center[3] = {0, 0, 0}, radius = 1.0;
    if (n) {
        for (int k = 0; k < 3; k++) center[k] = 0.5 * (lo[k] + hi[k]);
        radius = 0.0;
        for (uint32_t i = 0; i < n; i++) {
            double c[3];
            float rad;
            ob_node_world_sphere(nodes[i], c, &rad);
            double dx = c[0] - center[0], dy = c[1] - center[1], dz = c[2] - center[2];
            radius = fmax(radius, sqrt(dx * dx + dy * dy + dz * dz) + rad);
        }
    }
    return frame_sphere(d, center, radius);
}

static ob_result place_camera(ob_demo *d, const ob_scene_file_camera *c)
{
    ob_camera_desc cam = {.fovy = (float)(c->fov_degrees * DEG), .znear = c->znear};
    ob_result r = ob_node_set_camera(d->camera, &cam);
    if (r != OB_OK) return r;
    ob_node_set_position(d->camera, c->position);
    return ob_node_look_at(d->camera, c->target, c->up);
}

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
    if ((r = add_light(d, "sun", &default_sun, center, default_sun_direction)) != OB_OK) return r;
    return frame_sphere(d, center, radius);
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
    scene_builder b = {.d = &d, .sf = &sf};
    r = ob_demo_init(&d, &opt);
    if (r == OB_OK && is_scene) {
        r = build_scene(&b);
        if (r == OB_OK) r = sf.camera.present ? place_camera(&d, &sf.camera) : frame_scene(&d);
    } else if (r == OB_OK) {
        r = build_model_view(&d, &mesh, opt.input);
    }
    ob_mesh_release(&mesh);
    if (r != OB_OK) {
        fprintf(stderr, "obelisk-view: %s: set-up failed: %s (%s)\n", opt.input, ob_result_name(r),
                ob_result_text(r));
        code = 1;
    } else {
        printf("obelisk-view: %s: %s, %ux%u, %s", opt.input, ob_device_name(ob_renderer_device(d.r)),
               opt.width, opt.height,
               opt.threads == 0 ? "single-threaded" : opt.threads < 0 ? "auto" : "multi-threaded");
        if (is_scene)
            printf(", %u entities (%u left out), %u lights, %u particle systems%s%s", sf.entity_count,
                   b.left_out, sf.has_lights ? sf.light_count : 1u, sf.particle_count,
                   sf.description ? "\n  " : "", sf.description ? sf.description : "");
        printf("\n");
        code = ob_demo_run(&d, NULL, NULL);
    }
    ob_demo_shutdown(&d);
    builder_release(&b);
    ob_scene_file_release(&sf);
    return code;
}
