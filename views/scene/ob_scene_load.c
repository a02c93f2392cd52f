#define _XOPEN_SOURCE 700
#include "ob_scene_load.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_framing.h"
#include "ob_mesh.h"
#include "ob_model_instance.h"
#include "ob_scene_layer_internal.h"

#define DEG (3.14159265358979323846 / 180.0)
#define LOG_MODULE "scene"

/* One uploaded (or failed) geometry, shared by entities that describe it alike. */
typedef struct shared_geometry {
    const ob_scene_file_geometry *desc;
    ob_geometry *geometry;   /* NULL: the model failed to load ... */
    ob_result result;        /* ... with this result */
} shared_geometry;

/* One opened (or failed) model, shared by entities naming the same file. */
typedef struct shared_model {
    const ob_scene_file_geometry *desc;
    ob_model_assets *assets;   /* NULL: the model failed to open ... */
    ob_result result;          /* ... with this result */
} shared_model;

typedef struct loader {
    ob_scene_load_target t;
    const ob_scene_load_desc *desc;
    const ob_scene_file *sf;
    ob_scene_loaded *out;
    ob_scene_file_error *err;
    shared_geometry *shared;
    uint32_t shared_count, shared_cap;
    shared_model *shared_models;   /* [out->model_count], parallel to out->models */
    uint32_t geometry_cap, left_out_cap, model_cap, models_cap;
    uint32_t ids_used;         /* geometry ids handed out from desc->first_geometry_id */
} loader;

/* ------------------------------------------------------------ errors */

/* Records a hard failure: "FILE: PATH: what (RESULT: text)". Returns r. */
static ob_result fail(loader *L, ob_result r, const char *json_path, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static ob_result fail(loader *L, ob_result r, const char *json_path, const char *fmt, ...)
{
    ob_scene_file_error *e = L->err;
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    memset(e, 0, sizeof *e);
    snprintf(e->json_path, sizeof e->json_path, "%s", json_path);
    snprintf(e->message, sizeof e->message, "%s: %s%s%s (%s: %s)",
             L->sf->path ? L->sf->path : "scene", json_path,
             json_path[0] ? ": " : "", what, ob_result_name(r), ob_result_text(r));
    return r;
}

/* "materials.gold", or materials["two words"] for keys that are not identifiers
 * (as the parser writes paths). An inline material's name is its path already. */
static void material_path(const ob_scene_file_material *m, char *buf, size_t size)
{
    bool ident = isalpha((unsigned char)m->name[0]) || m->name[0] == '_';
    for (const char *c = m->name; *c && ident; c++) ident = isalnum((unsigned char)*c) || *c == '_';
    if (m->inline_material) snprintf(buf, size, "%s", m->name);
    else if (ident) snprintf(buf, size, "materials.%s", m->name);
    else snprintf(buf, size, "materials[\"%s\"]", m->name);
}

/* ------------------------------------------------------------ geometry */

static ob_result generate_mesh(const ob_scene_file_geometry *g, ob_mesh *mesh);

_Static_assert(OB_SCENE_FILE_MAX_LODS == OB_GEOMETRY_MAX_LODS - 1,
               "a scene file asks for as many levels as a geometry holds");

/* The generator's mesh at level of detail `level`: level 0 as the file
 * gives it, each level after with 0.6 times the segments of the one before
 * (at least the generator's minimum). */
static ob_result generate_mesh_level(const ob_scene_file_geometry *g, uint32_t level, ob_mesh *mesh)
{
    ob_scene_file_geometry c = *g;
    double f = pow(0.6, level);
    uint32_t least[2] = {3, g->kind == OB_SCENE_GEOMETRY_SPHERE ? 2u : 3u};
    for (int k = 0; k < 2; k++)
        if (c.segments[k]) c.segments[k] = OB_MAX(least[k], (uint32_t)lround(c.segments[k] * f));
    return generate_mesh(&c, mesh);
}

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
    case OB_SCENE_GEOMETRY_MODEL:   /* models keep their structure: entity_model */
    case OB_SCENE_GEOMETRY_NONE: break;
    }
    return OB_ERR_INVALID_ARGUMENT;
}

/* A left-out entity: logged with the file and the entity, listed in out. */
static ob_result left_out(loader *L, const ob_scene_file_entity *e, ob_result why)
{
    ob_scene_loaded *o = L->out;
    ob_result r = ob_array_reserve((void **)&o->left_out, &L->left_out_cap, o->left_out_count + 1,
                                   sizeof *o->left_out);
    if (r != OB_OK) return fail(L, r, "", "out of memory");
    o->left_out[o->left_out_count++] = (ob_scene_load_left_out){.entity = e->index, .result = why};
    char where[32];
    snprintf(where, sizeof where, "entities[%u]", e->index);
    bool named = strcmp(e->name, where) != 0;
    OB_LOG_W(LOG_MODULE, "%s: %s%s%s%s: model '%s' did not load (%s: %s); the entity is left out",
             L->sf->path ? L->sf->path : "scene", where, named ? " '" : "", named ? e->name : "", named ? "'" : "",
             e->geometry.model, ob_result_name(why), ob_result_text(why));
    return OB_OK;
}

/* The coarser levels the entity's generator asks for ("lods") of level 0
 * in mesh[0], generated into mesh[1..] and measured into lods; how many.
 * Levels that would repeat the one before (the segments at their minimum)
 * are not made. Levels that cannot be made or measured (no memory) are
 * logged naming the file and the entity, and the geometry goes on without
 * levels. */
static uint32_t entity_lods(loader *L, const ob_scene_file_entity *e, ob_mesh mesh[OB_GEOMETRY_MAX_LODS],
                            ob_geometry_lod lods[OB_GEOMETRY_MAX_LODS - 1])
{
    const ob_scene_file_geometry *g = &e->geometry;
    if (!g->lods) return 0;
    ob_result r = OB_OK;
    uint32_t n = 0;
    while (r == OB_OK && n < g->lods) {
        ob_mesh *m = &mesh[n + 1];
        if ((r = generate_mesh_level(g, n + 1, m)) != OB_OK) break;
        if (m->index_count == mesh[n].index_count) {
            ob_mesh_release(m);
            break;
        }
        lods[n++].mesh = m;
    }
    if (r == OB_OK) r = ob_geometry_measure_lods(&mesh[0], lods, n);
    if (r == OB_OK) return n;
    OB_LOG_W(LOG_MODULE, "%s: entities[%u] '%s': its %u levels of detail not made (%s); the "
             "geometry has level 0 only", L->sf->path ? L->sf->path : "scene", e->index, e->name,
             g->lods, ob_result_name(r));
    for (uint32_t l = 1; l < OB_GEOMETRY_MAX_LODS; l++) ob_mesh_release(&mesh[l]);
    return 0;
}

/* The entity's geometry, uploaded once per distinct description into *out_g.
 * *out_g NULL with OB_OK: its model did not load (reported, left out). */
static ob_result entity_geometry(loader *L, const ob_scene_file_entity *e, ob_geometry **out_g)
{
    *out_g = NULL;
    for (uint32_t i = 0; i < L->shared_count; i++) {
        if (!ob_scene_file_geometry_equal(L->shared[i].desc, &e->geometry)) continue;
        *out_g = L->shared[i].geometry;
        return *out_g ? OB_OK : left_out(L, e, L->shared[i].result);
    }
    ob_scene_loaded *o = L->out;
    ob_result r = ob_array_reserve((void **)&L->shared, &L->shared_cap, L->shared_count + 1,
                                   sizeof *L->shared);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&o->geometry, &L->geometry_cap, o->geometry_count + 1,
                             sizeof *o->geometry);
    if (r != OB_OK) return fail(L, r, "", "out of memory");

    ob_mesh mesh[OB_GEOMETRY_MAX_LODS] = {{0}};
    ob_geometry_lod lods[OB_GEOMETRY_MAX_LODS - 1] = {{0}};
    ob_geometry *g = NULL;
    r = generate_mesh(&e->geometry, &mesh[0]);
    if (r == OB_OK) {
        uint32_t levels = entity_lods(L, e, mesh, lods);
        uint32_t id = L->desc->first_geometry_id ? L->desc->first_geometry_id + L->ids_used : 0;
        ob_geometry_desc gd = {.mesh = &mesh[0], .name = ob_scene_file_geometry_kind_name(e->geometry.kind),
                               .id = id, .lods = lods, .lod_count = levels};
        g = ob_geometry_create(ob_renderer_device(L->t.renderer), &gd, &r);
    }
    for (uint32_t l = 0; l < OB_GEOMETRY_MAX_LODS; l++) ob_mesh_release(&mesh[l]);
    if (!g) {
        char path[48];
        snprintf(path, sizeof path, "entities[%u].geometry", e->index);
        return fail(L, r, path, "entity '%s': %s geometry failed", e->name,
                    ob_scene_file_geometry_kind_name(e->geometry.kind));
    }
    L->ids_used++;
    o->geometry[o->geometry_count++] = g;
    L->shared[L->shared_count++] = (shared_geometry){.desc = &e->geometry, .geometry = g, .result = r};
    *out_g = g;
    return OB_OK;
}

/* A relative model path must resolve, after symbolic links, inside the
 * scene file's folder (ob_scene_load_desc.allow_any_folder). OB_ERR_IO,
 * logged naming the entity and the path, when it does not. */
static ob_result model_inside_scene_folder(loader *L, const ob_scene_file_entity *e)
{
    if (L->desc->allow_any_folder || !e->geometry.model_relative) return OB_OK;
    const char *scene = L->sf->path ? L->sf->path : "scene";
    const char *slash = strrchr(scene, '/');
    char dir[4096];
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - scene) : 1, slash ? scene : ".");
    if (slash == scene) snprintf(dir, sizeof dir, "/");
    char *root = realpath(dir, NULL), *real = realpath(e->geometry.model, NULL);
    size_t n = root ? strlen(root) : 0;
    bool inside = !real || (root && strncmp(real, root, n) == 0 && (real[n] == '/' || (n == 1 && root[0] == '/')));
    /* A path that does not resolve (missing) is the model loader's to report. */
    if (!inside)
        OB_LOG_E(LOG_MODULE, "%s: entities[%u] '%s': refused model '%s': it resolves to '%s', outside the "
                 "scene file's folder '%s' (other folders must be allowed explicitly)", scene, e->index,
                 e->name, e->geometry.model, real, root ? root : dir);
    free(root);
    free(real);
    return inside ? OB_OK : OB_ERR_IO;
}

/* The entity's model, opened and given its materials once per file into
 * *out_a. *out_a NULL with OB_OK: it did not open (reported, left out). */
static ob_result entity_model(loader *L, const ob_scene_file_entity *e, ob_model_assets **out_a)
{
    *out_a = NULL;
    ob_scene_loaded *o = L->out;
    for (uint32_t i = 0; i < o->model_count; i++) {
        const shared_model *sm = &L->shared_models[i];
        if (!ob_scene_file_geometry_equal(sm->desc, &e->geometry)) continue;
        *out_a = sm->assets;
        return sm->assets ? OB_OK : left_out(L, e, sm->result);
    }
    ob_result r = ob_array_reserve((void **)&L->shared_models, &L->model_cap, o->model_count + 1,
                                   sizeof *L->shared_models);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&o->models, &L->models_cap, o->model_count + 1, sizeof *o->models);
    if (r != OB_OK) return fail(L, r, "", "out of memory");
    /* flip_uv: the engine samples images with Vulkan's top-left origin. */
    ob_model *model = NULL;
    ob_model_assets *a = NULL;
    r = model_inside_scene_folder(L, e);
    if (r == OB_OK)
        r = ob_model_open(&(ob_model_desc){.path = e->geometry.model, .flip_uv = true,
                                           .allow_any_folder = L->desc->allow_any_folder},
                          &model);
    if (r == OB_OK) {
        uint32_t first = L->desc->first_geometry_id ? L->desc->first_geometry_id + L->ids_used : 0;
        L->ids_used += OB_MODEL_ASSETS_IDS_PER_PRIMITIVE * model->primitive_count;
        if (model->image_count > 0 && !o->textures) {
            o->textures = ob_texture_cache_create(ob_renderer_device(L->t.renderer), &r);
            if (!o->textures) {
                ob_model_close(model);
                return fail(L, r, "", "no texture cache");
            }
        }
        ob_model_assets_desc ad = {.renderer = L->t.renderer, .materials = L->t.materials,
                                   .textures = o->textures, .first_geometry_id = first,
                                   .lods = e->geometry.lods};
        a = ob_model_assets_create(&ad, model, &r);   /* takes the model */
        /* A model that reads but whose materials cannot be made is left out
         * like one that does not read; the library's error says why. */
    }
    L->shared_models[o->model_count] = (shared_model){.desc = &e->geometry, .assets = a, .result = r};
    o->models[o->model_count++] = a;
    *out_a = a;
    return a ? OB_OK : left_out(L, e, r);
}

/* ------------------------------------------------------------ nodes */

static ob_result add_light(loader *L, const char *name, const ob_light_desc *desc,
                           const double position[3], const double direction[3])
{
    ob_scene_loaded *o = L->out;
    ob_result r;
    ob_node *n = ob_node_create(L->t.scene, NULL, name, &r);
    if (!n) return r;
    o->lights[o->light_count++] = n;   /* room for every light was made up front */
    if ((r = ob_node_set_light(n, desc)) != OB_OK) return r;
    /* The engine reads a zero colour as white (its default): hide a black
     * light instead. Intensity 0 is literal and needs nothing here. */
    bool black = desc->color[0] == 0.0f && desc->color[1] == 0.0f && desc->color[2] == 0.0f;
    ob_node_set_hidden(n, black);
    /* Directional and spot lights shine along the node's forward. Aimed
     * from the origin: position + direction could round back to a far-away
     * position, and a directional light's position is unused. */
    if (desc->type != OB_LIGHT_POINT && (r = ob_light_aim(n, direction)) != OB_OK) return r;
    ob_node_set_position(n, position);
    return OB_OK;
}

static ob_result add_entity(loader *L, const ob_scene_file_entity *e)
{
    ob_scene_loaded *o = L->out;
    ob_node *parent = e->parent != OB_SCENE_FILE_NONE ? o->entities[e->parent] : NULL;
    char path[32];
    snprintf(path, sizeof path, "entities[%u]", e->index);
    ob_geometry *g = NULL;
    ob_model_assets *model = NULL;
    ob_result r = OB_OK;
    if (e->geometry.kind == OB_SCENE_GEOMETRY_MODEL) {
        if ((r = entity_model(L, e, &model)) != OB_OK) return r;   /* the error is recorded */
    } else if (e->geometry.kind != OB_SCENE_GEOMETRY_NONE && (r = entity_geometry(L, e, &g)) != OB_OK) {
        return r;
    }
    /* Without geometry (transform-only, or its model failed) the node stays
     * so that its children still render. */
    ob_node *n = ob_node_create(L->t.scene, parent, e->name, &r);
    if (!n) return fail(L, r, path, "entity '%s' could not be made", e->name);
    o->entities[o->entity_count++] = n;
    if (g) {
        const ob_bounds *b = ob_geometry_bounds(g);
        ob_renderable rd = {
            .material = e->material != OB_SCENE_FILE_NONE ? o->materials[e->material]
                                                          : o->materials[o->material_count - 1],
            .geometry = g, .local_radius = b->radius};
        memcpy(rd.local_center, b->center, sizeof rd.local_center);
        if ((r = ob_node_set_renderable(n, &rd)) != OB_OK)
            return fail(L, r, path, "entity '%s' could not be made renderable", e->name);
    }
    if (model) {
        /* The entity is the model's root; a material the entity names
         * overrides the model's own for every primitive. */
        ob_material *override = e->material != OB_SCENE_FILE_NONE ? o->materials[e->material] : NULL;
        uint32_t made = 0;
        if ((r = ob_model_assets_instantiate(model, L->t.scene, n, override, &made)) != OB_OK)
            return fail(L, r, path, "entity '%s': model '%s' could not be placed", e->name, e->geometry.model);
        o->model_entity_count += made;
    }
    ob_node_set_position(n, e->position);
    if (e->rotation_kind == OB_SCENE_ROTATION_EULER)
        ob_node_set_euler(n, (float)(e->rotation[0] * DEG), (float)(e->rotation[1] * DEG),
                          (float)(e->rotation[2] * DEG));
    else if (e->rotation_kind == OB_SCENE_ROTATION_QUATERNION)
        ob_node_set_rotation_d(n, e->rotation);
    ob_node_set_scale(n, e->scale);
    ob_node_set_hidden(n, e->hidden);
    for (uint32_t k = 0; k < e->controller_count; k++) {
        const ob_scene_file_controller *c = &e->controllers[k];
        float rate = (float)(c->speed_degrees * DEG);
        if (c->kind == OB_SCENE_CONTROLLER_ROTATE)
            r = ob_node_add_rotation_controller(n, c->axis, rate);
        else
            r = ob_node_add_orbit_controller(n, c->center, c->axis, c->radius, rate,
                                             (float)(c->phase_degrees * DEG));
        if (r != OB_OK) {
            char cpath[80];
            snprintf(cpath, sizeof cpath, "%s.controllers[%u]", path, k);
            return fail(L, r, cpath, "the controller could not be added");
        }
    }
    return OB_OK;
}

static ob_result build(loader *L)
{
    const ob_scene_file *sf = L->sf;
    ob_scene_loaded *o = L->out;
    uint32_t light_n = sf->has_lights ? sf->light_count : 1u;
    o->materials = ob_calloc(sf->material_count + 1u, sizeof *o->materials);
    o->entities = ob_calloc(sf->entity_count + 1u, sizeof *o->entities);
    o->lights = ob_calloc(light_n + 1u, sizeof *o->lights);
    o->particles = ob_calloc(sf->particle_count + 1u, sizeof *o->particles);
    if (!o->materials || !o->entities || !o->lights || !o->particles)
        return fail(L, OB_ERR_OUT_OF_HOST_MEMORY, "", "out of memory");
    ob_result r = OB_OK;
    char path[400];
    for (uint32_t i = 0; i < sf->material_count; i++) {
        const ob_scene_file_material *m = &sf->materials[i];
        material_path(m, path, sizeof path);
        if (!(o->materials[i] = ob_material_create(L->t.materials, &m->desc, &r)))
            return fail(L, r, path, "the material could not be made");
        o->material_count++;
        /* desc.reflectivity 0 means "default" to the library; the file means 0. */
        if (m->desc.kind == OB_MATERIAL_REFLECTIVE &&
            (r = ob_material_set_reflectivity(o->materials[i], m->desc.reflectivity)) != OB_OK)
            return fail(L, r, path, "reflectivity %g was refused", (double)m->desc.reflectivity);
    }
    ob_material_desc dm = {.name = "default", .kind = OB_MATERIAL_LIT, .casts_shadows = true,
                           .diffuse = {0.8f, 0.8f, 0.8f, 1.0f}};
    if (!(o->materials[o->material_count] = ob_material_create(L->t.materials, &dm, &r)))
        return fail(L, r, "", "the default material could not be made");
    o->material_count++;
    for (uint32_t i = 0; i < sf->entity_count; i++)
        if ((r = add_entity(L, &sf->entities[i])) != OB_OK) return r;
    if (!sf->has_lights) {
        double origin[3] = {0, 0, 0};
        if ((r = add_light(L, "sun", &ob_sun_light, origin, ob_sun_direction)) != OB_OK)
            return fail(L, r, "", "the default light (no \"lights\" in the file) could not be made");
    }
    for (uint32_t i = 0; i < sf->light_count; i++) {
        const ob_scene_file_light *l = &sf->lights[i];
        if ((r = add_light(L, l->name, &l->desc, l->position, l->direction)) != OB_OK) {
            snprintf(path, sizeof path, "lights[%u]", i);
            return fail(L, r, path, "light '%s' could not be made", l->name);
        }
    }
    for (uint32_t i = 0; i < sf->particle_count; i++) {
        const ob_scene_file_particles *p = &sf->particles[i];
        ob_particle_desc pd = p->desc;
        pd.seed = L->desc->seed + i;
        ob_node *parent = p->parent != OB_SCENE_FILE_NONE ? o->entities[p->parent] : NULL;
        if (!(o->particles[i] = ob_particle_system_create(L->t.views, L->t.scene, parent, &pd, &r))) {
            snprintf(path, sizeof path, "particles[%u]", i);
            return fail(L, r, path, "particle system '%s' could not be made", p->name);
        }
        o->particle_count++;
    }
    return OB_OK;
}

/* ------------------------------------------------------------ bounds, camera */

/* Bounds of every renderable (after one update, so world bounds exist). */
static ob_result scene_bounds(loader *L)
{
    ob_scene_loaded *o = L->out;
    ob_result r = ob_framing_measure(L->t.scene, NULL, o->min, o->max, o->center, &o->radius);
    if (r != OB_OK) return fail(L, r, "", "the scene did not update");
    o->has_bounds = o->max[0] >= o->min[0];
    if (!o->has_bounds) {
        memset(o->min, 0, sizeof o->min);
        memset(o->max, 0, sizeof o->max);
    }
    return OB_OK;
}

/* The camera node as it was, to put back if the load fails after touching it. */
typedef struct camera_state {
    bool had_camera;
    ob_camera_desc desc;
    double position[3], rotation[4];
} camera_state;

static camera_state camera_save(const ob_node *n)
{
    camera_state s = {.had_camera = ob_node_get_camera(n) != NULL};
    if (s.had_camera) s.desc = *ob_node_get_camera(n);
    ob_node_get_position(n, s.position);
    ob_node_get_rotation(n, s.rotation);
    return s;
}

static void camera_restore(ob_node *n, const camera_state *s)
{
    ob_node_set_camera(n, s->had_camera ? &s->desc : NULL);
    ob_node_set_position(n, s->position);
    ob_node_set_rotation_d(n, s->rotation);
}

static ob_result place_camera(loader *L)
{
    const ob_scene_file_camera *c = &L->sf->camera;
    ob_scene_loaded *o = L->out;
    ob_node *n = L->desc->camera;
    ob_result r = OB_OK;
    if (!c->present) {
        if (!(L->desc->frame_aspect > 0.0)) return OB_OK;
        camera_state saved = camera_save(n);
        if ((r = ob_framing_aim_camera(n, o->center, o->radius, L->desc->frame_aspect)) != OB_OK) {
            camera_restore(n, &saved);
            return fail(L, r, "", "the camera could not be framed on the scene");
        }
        o->framed = true;
        return OB_OK;
    }
    camera_state saved = {0};
    if (n) {
        saved = camera_save(n);
    } else {
        if (!(n = ob_node_create(L->t.scene, NULL, "camera", &r)))
            return fail(L, r, "camera", "the camera node could not be made");
        o->camera = n;
        o->camera_created = true;
    }
    ob_camera_desc cam = {.fovy = (float)(c->fov_degrees * DEG), .znear = c->znear};
    if ((r = ob_node_set_camera(n, &cam)) == OB_OK) {
        ob_node_set_position(n, c->position);
        r = ob_node_look_at(n, c->target, c->up);
    }
    if (r != OB_OK) {
        if (!o->camera_created) camera_restore(n, &saved);
        return fail(L, r, "camera", "the camera could not be placed");
    }
    o->camera = n;
    return OB_OK;
}

/* ------------------------------------------------------------ load, unload */

ob_result ob_scene_load(const ob_scene_load_target *t, const ob_scene_load_desc *desc,
                        ob_scene_loaded *out, ob_scene_file_error *out_error)
{
    ob_scene_file_error local;
    ob_scene_file_error *err = out_error ? out_error : &local;
    memset(err, 0, sizeof *err);
    if (out) memset(out, 0, sizeof *out);
    const char *name = desc && desc->file ? desc->file->path : desc ? desc->path : NULL;
    const char *missing = !out ? "out" : !desc ? "desc" : !desc->file && !desc->path ? "desc.path"
                          : !t ? "target" : !t->renderer ? "target.renderer"
                          : !t->materials ? "target.materials" : !t->views ? "target.views"
                          : !t->scene ? "target.scene"
                          : desc->frame_aspect > 0.0 && !desc->camera ? "desc.camera (frame_aspect is set)"
                          : NULL;
    if (missing) {
        snprintf(err->message, sizeof err->message, "%s: ob_scene_load: no %s",
                 name ? name : "scene", missing);
        return OB_ERR_INVALID_ARGUMENT;
    }
    ob_scene_file parsed = {0};
    const ob_scene_file *sf = desc->file;
    ob_result r;
    if (!sf) {
        if ((r = ob_scene_file_load(desc->path, &parsed, err)) != OB_OK) return r;
        sf = &parsed;
    }
    loader L = {.t = *t, .desc = desc, .sf = sf, .out = out, .err = err};
    out->scene = t->scene;
    out->views = t->views;
    out->device = ob_renderer_device(t->renderer);
    bool updated = false;
    r = build(&L);
    if (r == OB_OK) {
        r = scene_bounds(&L);
        updated = true;
    }
    if (r == OB_OK) r = place_camera(&L);
    ob_free(L.shared);
    ob_free(L.shared_models);
    ob_scene_file_release(&parsed);
    if (r != OB_OK) {
        ob_scene_unload(out);
        /* The update for the bounds took the load's nodes into the scene's
         * snapshot: take it again without them. */
        if (updated) ob_scene_update(t->scene, 0.0);
        return r;
    }
    return OB_OK;
}

ob_result ob_scene_load_stack(ob_stack *s, const ob_scene_load_desc *desc, ob_scene_loaded *out,
                              ob_scene_file_error *out_error)
{
    if (!s || !desc) return ob_scene_load(NULL, desc, out, out_error);   /* reports what is missing */
    ob_scene_load_desc d = *desc;
    if (!d.camera) d.camera = s->camera;
    if (d.frame_aspect == 0.0) {
        ob_image_info info;
        if (ob_image_get_info(s->device, ob_stack_final_image(s), &info) == OB_OK && info.height)
            d.frame_aspect = (double)info.width / (double)info.height;
    }
    /* Parsed here rather than in ob_scene_load: the settings are read after. */
    ob_scene_file parsed = {0};
    ob_result r;
    if (!d.file && d.path) {
        if ((r = ob_scene_file_load(d.path, &parsed, out_error)) != OB_OK) {
            if (out) memset(out, 0, sizeof *out);
            return r;
        }
        d.file = &parsed;
    }
    ob_scene_load_target t = {.renderer = s->renderer, .materials = s->materials,
                              .views = s->views, .scene = s->scene};
    r = ob_scene_load(&t, &d, out, out_error);
    /* A setting the device cannot take fails the load like any other part
     * of the file: what the load made is taken back. */
    if (r == OB_OK && (r = ob_scene_load_apply_settings(s->renderer, s->views,
                                                        &d.file->settings)) != OB_OK) {
        OB_LOG_E("scene", "%s: settings not applied (%s); the scene is unloaded",
                 d.path ? d.path : "scene", ob_result_name(r));
        ob_scene_unload(out);
    }
    ob_scene_file_release(&parsed);
    return r;
}

void ob_scene_unload(ob_scene_loaded *l)
{
    if (!l) return;
    /* Children before parents: a particle system's emitter may hang under an
     * entity, and a later entity under an earlier one (the file's rule). */
    for (uint32_t i = l->particle_count; i-- > 0;) ob_particle_system_destroy(l->views, l->particles[i]);
    if (l->camera_created) ob_node_destroy(l->camera);
    for (uint32_t i = l->light_count; i-- > 0;) ob_node_destroy(l->lights[i]);
    for (uint32_t i = l->entity_count; i-- > 0;) ob_node_destroy(l->entities[i]);
    for (uint32_t i = l->model_count; i-- > 0;) ob_model_assets_destroy(l->models[i]);
    ob_texture_cache_destroy(l->textures);   /* after the materials sampling its textures */
    for (uint32_t i = l->material_count; i-- > 0;) ob_material_destroy(l->materials[i]);
    for (uint32_t i = l->geometry_count; i-- > 0;) ob_geometry_destroy(l->device, l->geometry[i]);
    ob_free(l->models);
    ob_free(l->particles);
    ob_free(l->lights);
    ob_free(l->entities);
    ob_free(l->materials);
    ob_free(l->geometry);
    ob_free(l->left_out);
    memset(l, 0, sizeof *l);
}

/* ------------------------------------------------------------ settings */

void ob_scene_load_stack_desc(const ob_scene_file_settings *s, ob_stack_desc *desc)
{
    if (!s || !desc) return;
    if (s->has_size) desc->width = s->width, desc->height = s->height;
    if (s->has_threads) {
        desc->renderer.threading = s->threads == 0 ? OB_THREADING_SINGLE
                                   : s->threads < 0 ? OB_THREADING_AUTO : OB_THREADING_MULTI;
        if (s->threads > 0) desc->renderer.worker_count = (uint32_t)s->threads;
    }
    if (s->env_map_size) desc->env_map_size = s->env_map_size;
    if (s->shadow_map_size) desc->shadow_map_size = s->shadow_map_size;
    if (s->shadow_cascades) desc->shadow_cascades = s->shadow_cascades;
    if (s->shadow_distance > 0.0f) desc->shadow_distance = s->shadow_distance;
    if (s->shadow_split_lambda > 0.0f) desc->shadow_split_lambda = s->shadow_split_lambda;
    if (s->has_clear_color) memcpy(desc->clear_color, s->clear_color, sizeof desc->clear_color);
    if (s->has_ambient) memcpy(desc->ambient, s->ambient, sizeof desc->ambient);
    if (s->exposure > 0.0f) desc->exposure = s->exposure;
    if (s->has_env_map_kind) desc->env_map_kind = s->env_map_kind;
    if (s->has_sky_color) memcpy(desc->sky_color, s->sky_color, sizeof desc->sky_color);
}

ob_result ob_scene_load_apply_settings(ob_renderer *r, ob_views *views,
                                       const ob_scene_file_settings *s)
{
    if (!s) return OB_OK;
    ob_result first = OB_OK, res;
    if (r && s->has_threads) {
        ob_threading mode = s->threads == 0 ? OB_THREADING_SINGLE
                            : s->threads < 0 ? OB_THREADING_AUTO : OB_THREADING_MULTI;
        uint32_t active = s->threads > 0 ? (uint32_t)s->threads : 0;
        if (active > ob_renderer_worker_count(r)) active = 0;   /* all the renderer has */
        if ((res = ob_renderer_set_threading(r, mode, active)) != OB_OK && first == OB_OK) first = res;
    }
    if (views && s->env_map_size && (res = ob_views_set_env_map_size(views, s->env_map_size)) != OB_OK &&
        first == OB_OK)
        first = res;
    if (views && s->shadow_map_size &&
        (res = ob_views_set_shadow_map_size(views, s->shadow_map_size)) != OB_OK && first == OB_OK)
        first = res;
    if (views && s->shadow_cascades &&
        (res = ob_views_set_shadow_cascades(views, s->shadow_cascades)) != OB_OK && first == OB_OK)
        first = res;
    if (views && s->shadow_distance > 0.0f &&
        (res = ob_views_set_shadow_distance(views, s->shadow_distance)) != OB_OK && first == OB_OK)
        first = res;
    if (views && s->shadow_split_lambda > 0.0f &&
        (res = ob_views_set_shadow_split_lambda(views, s->shadow_split_lambda)) != OB_OK &&
        first == OB_OK)
        first = res;
    if (views && s->has_env_map_kind && !ob_views_set_env_map_kind(views, s->env_map_kind) &&
        first == OB_OK)
        first = OB_ERR_INVALID_ARGUMENT;
    if (views && s->has_sky_color) ob_views_set_sky_color(views, s->sky_color);
    return first;
}
