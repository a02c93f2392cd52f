#define _POSIX_C_SOURCE 200809L
#include "ob_scene_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ob_json_read.h"

typedef struct sf_ctx {
    ob_json_reader rd;
    ob_scene_file *sf;
    uint32_t material_cap;
    ob_json_names materials, entities;
    char *dir;   /* base for relative model paths; "" = the working directory */
} sf_ctx;

static bool opt_axis(sf_ctx *c, const cJSON *obj, const char *key, float out[3])
{
    double v[3] = {out[0], out[1], out[2]};
    if (!ob_json_opt_direction(&c->rd, obj, key, v)) return false;
    for (int i = 0; i < 3; i++) out[i] = (float)v[i];
    return true;
}

static char *dup_or_oom(sf_ctx *c, const char *s)
{
    char *d = ob_strdup(s);
    if (!d) ob_json_out_of_memory(&c->rd);
    return d;
}

/* A name given by the file, or "<section>[i]". */
static char *name_or_default(sf_ctx *c, const cJSON *obj, const char *section, uint32_t i)
{
    const cJSON *j = ob_json_member(obj, "name");
    if (j) {
        size_t mark = ob_json_push_key(&c->rd, "name");
        const char *s = ob_json_string(&c->rd, j, "a non-empty name");
        if (!s) return NULL;
        ob_json_pop(&c->rd, mark);
        return dup_or_oom(c, s);
    }
    char buf[48];
    snprintf(buf, sizeof buf, "%s[%u]", section, i);
    return dup_or_oom(c, buf);
}

/* ------------------------------------------------------------ colours */

/* Colours in a scene file are written sRGB-encoded, as a colour picker
 * shows them; the engine shades in linear light, so the red, green and blue
 * read here are decoded (the sRGB transfer function, IEC 61966-2-1). Alpha
 * and the w of a specular colour (a power) are not colours and stay as
 * written; emissive, which may exceed 1, is read as linear. A key that is
 * absent leaves out[] as it was. */
static bool opt_srgb_color(sf_ctx *c, const cJSON *j, const char *key, float w, float out[4])
{
    bool present = ob_json_member(j, key) != NULL;
    if (!ob_json_opt_color(&c->rd, j, key, w, out)) return false;
    for (int i = 0; present && i < 3; i++) out[i] = ob_srgb_to_linear(out[i]);
    return true;
}

/* ------------------------------------------------------------ settings & camera */

static bool parse_settings(sf_ctx *c, const cJSON *j, ob_scene_file_settings *s)
{
    static const char *const keys[] = {"size", "env_map_size", "shadow_map_size", "threads",
                                       "clear_color", "ambient", "exposure", "env_map", "sky_color",
                                       "shadow_cascades", "shadow_distance", "shadow_split_lambda"};
    if (!ob_json_check_object(&c->rd, j, "an object", keys, OB_ARRAY_COUNT(keys))) return false;
    const cJSON *size = ob_json_member(j, "size");
    if (size) {
        size_t mark = ob_json_push_key(&c->rd, "size");
        double wh[2];
        if (!ob_json_vector(&c->rd, size, 2, 2, OB_JSON_INT(1, OB_SETTING_SIZE_MAX), false, wh, NULL)) return false;
        s->has_size = true;
        s->width = (uint32_t)wh[0];
        s->height = (uint32_t)wh[1];
        ob_json_pop(&c->rd, mark);
    }
    if (!ob_json_opt_u32(&c->rd, j, "env_map_size", OB_SETTING_ENV_MAP_MIN, OB_SETTING_ENV_MAP_MAX,
                         &s->env_map_size) ||
        !ob_json_opt_u32(&c->rd, j, "shadow_map_size", OB_SETTING_SHADOW_MAP_MIN, OB_SETTING_SHADOW_MAP_MAX,
                         &s->shadow_map_size) ||
        !ob_json_opt_u32(&c->rd, j, "shadow_cascades", 1, OB_SHADOW_MAX_CASCADES, &s->shadow_cascades) ||
        !ob_json_opt_float(&c->rd, j, "shadow_distance", OB_JSON_POSITIVE, &s->shadow_distance) ||
        !ob_json_opt_float(&c->rd, j, "shadow_split_lambda", OB_JSON_RANGE(0.0, 1.0),
                           &s->shadow_split_lambda))
        return false;
    if (ob_json_member(j, "shadow_split_lambda") && !(s->shadow_split_lambda > 0.0f)) {
        ob_json_push_key(&c->rd, "shadow_split_lambda");
        return ob_json_fail(&c->rd, "expected a number above 0 and at most 1 (the share of "
                            "logarithmic splits), got 0");
    }
    const cJSON *threads = ob_json_member(j, "threads");
    if (threads) {
        size_t mark = ob_json_push_key(&c->rd, "threads");
        s->has_threads = true;
        if (cJSON_IsString(threads) && strcmp(threads->valuestring, "auto") == 0) {
            s->threads = -1;
        } else {
            double t;
            if (!cJSON_IsNumber(threads))
                return ob_json_fail(&c->rd, "expected an integer from 0 to %u or \"auto\", got %s",
                            OB_MAX_WORKERS, ob_json_type_name(threads));
            if (!ob_json_number(&c->rd, threads, OB_JSON_INT(0, OB_MAX_WORKERS), false, &t)) return false;
            s->threads = (int)t;
        }
        ob_json_pop(&c->rd, mark);
    }
    if (ob_json_member(j, "exposure")) {
        if (!ob_json_opt_float(&c->rd, j, "exposure",
                               OB_JSON_RANGE(OB_SETTING_EXPOSURE_MIN, OB_SETTING_EXPOSURE_MAX), &s->exposure))
            return false;
    }
    if (ob_json_member(j, "clear_color")) {
        s->has_clear_color = true;
        if (!opt_srgb_color(c, j, "clear_color", 1.0f, s->clear_color)) return false;
    }
    const cJSON *env = ob_json_member(j, "env_map");
    if (env) {
        size_t mark = ob_json_push_key(&c->rd, "env_map");
        bool cube = cJSON_IsString(env) && strcmp(env->valuestring, "cube") == 0;
        if (!cube && !(cJSON_IsString(env) && strcmp(env->valuestring, "paraboloid") == 0))
            return ob_json_fail(&c->rd, "expected \"paraboloid\" or \"cube\", got %s",
                                cJSON_IsString(env) ? "another string" : ob_json_type_name(env));
        s->has_env_map_kind = true;
        s->env_map_kind = cube ? OB_ENV_MAP_CUBE : OB_ENV_MAP_PARABOLOID;
        ob_json_pop(&c->rd, mark);
    }
    if (ob_json_member(j, "sky_color")) {
        s->has_sky_color = true;
        if (!opt_srgb_color(c, j, "sky_color", 1.0f, s->sky_color)) return false;
        s->sky_color[3] = 1.0f;
    }
    if (ob_json_member(j, "ambient")) {
        s->has_ambient = true;
        if (!opt_srgb_color(c, j, "ambient", 1.0f, s->ambient)) return false;
        if (s->ambient[3] == 0.0f) {   /* the engine reads intensity 0 as "default" */
            s->ambient[0] = s->ambient[1] = s->ambient[2] = 0.0f;
            s->ambient[3] = 1.0f;
        }
    }
    return true;
}

/* up must not be parallel to a unit direction. */
static bool up_is_usable(const double dir[3], const double up[3])
{
    double x = dir[1] * up[2] - dir[2] * up[1], y = dir[2] * up[0] - dir[0] * up[2],
           z = dir[0] * up[1] - dir[1] * up[0];
    return x * x + y * y + z * z > 1e-12;
}

static bool parse_camera(sf_ctx *c, const cJSON *j, ob_scene_file_camera *cam)
{
    static const char *const keys[] = {"position", "target", "up", "fov_degrees", "near"};
    if (!ob_json_check_object(&c->rd, j, "an object", keys, OB_ARRAY_COUNT(keys))) return false;
    *cam = (ob_scene_file_camera){.present = true, .position = {0, 2, 8}, .up = {0, 1, 0},
                                  .fov_degrees = 60.0f, .znear = 0.1f};
    if (!ob_json_opt_vec3d(&c->rd, j, "position", OB_JSON_ANY, cam->position) || !ob_json_opt_vec3d(&c->rd, j, "target", OB_JSON_ANY, cam->target) ||
        !ob_json_opt_direction(&c->rd, j, "up", cam->up) ||
        !ob_json_opt_float(&c->rd, j, "fov_degrees", OB_JSON_RANGE(1, 170), &cam->fov_degrees) ||
        !ob_json_opt_float(&c->rd, j, "near", OB_JSON_POSITIVE, &cam->znear))
        return false;
    double dir[3] = {cam->target[0] - cam->position[0], cam->target[1] - cam->position[1],
                     cam->target[2] - cam->position[2]};
    if (!ob_json_normalize(dir, 3) || !isfinite(dir[0] + dir[1] + dir[2])) {
        ob_json_push_key(&c->rd, "target");
        return ob_json_fail(&c->rd, "must differ from camera.position (the camera looks from position to target)");
    }
    if (!up_is_usable(dir, cam->up)) {
        ob_json_push_key(&c->rd, "up");
        return ob_json_fail(&c->rd, "must not be parallel to the viewing direction (target - position)");
    }
    return true;
}

/* ------------------------------------------------------------ lights */

static bool parse_light(sf_ctx *c, const cJSON *j, uint32_t i, uint32_t *directional,
                        ob_scene_file_light *l)
{
    static const char *const keys[] = {"name", "type", "position", "target", "direction", "color",
                                       "intensity", "range", "shadows", "inner_angle",
                                       "outer_angle"};
    if (!ob_json_check_object(&c->rd, j, "a light object", keys, OB_ARRAY_COUNT(keys))) return false;
    const cJSON *type = ob_json_member(j, "type");
    if (!type) return ob_json_missing(&c->rd, "type", "\"directional\", \"point\" or \"spot\"");
    size_t mark = ob_json_push_key(&c->rd, "type");
    if (cJSON_IsString(type) && strcmp(type->valuestring, "directional") == 0)
        l->desc.type = OB_LIGHT_DIRECTIONAL;
    else if (cJSON_IsString(type) && strcmp(type->valuestring, "point") == 0)
        l->desc.type = OB_LIGHT_POINT;
    else if (cJSON_IsString(type) && strcmp(type->valuestring, "spot") == 0)
        l->desc.type = OB_LIGHT_SPOT;
    else if (cJSON_IsString(type))
        return ob_json_fail(&c->rd, "expected \"directional\", \"point\" or \"spot\", got \"%.40s\"",
                            type->valuestring);
    else
        return ob_json_fail(&c->rd, "expected \"directional\", \"point\" or \"spot\", got %s",
                            ob_json_type_name(type));
    ob_json_pop(&c->rd, mark);
    bool point = l->desc.type == OB_LIGHT_POINT, spot = l->desc.type == OB_LIGHT_SPOT;
    if (!(l->name = name_or_default(c, j, "lights", i))) return false;
    float color[4] = {1, 1, 1, 1};
    float inner_degrees = 0.0f, outer_degrees = 45.0f;
    l->desc.intensity = 1.0f;
    l->direction[0] = -1.0, l->direction[1] = -2.0, l->direction[2] = -1.0;
    ob_json_normalize(l->direction, 3);
    if (!ob_json_opt_vec3d(&c->rd, j, "position", OB_JSON_ANY, l->position) || !opt_srgb_color(c, j, "color", 1.0f, color) ||
        !ob_json_opt_float(&c->rd, j, "intensity", OB_JSON_NON_NEGATIVE, &l->desc.intensity) ||
        !ob_json_opt_float(&c->rd, j, "range", OB_JSON_NON_NEGATIVE, &l->desc.range) ||
        !ob_json_opt_bool(&c->rd, j, "shadows", &l->desc.casts_shadows))
        return false;
    memcpy(l->desc.color, color, sizeof l->desc.color);
    static const char *const directional_only[] = {"target", "direction"};
    for (int k = 0; k < 2; k++)
        if (point && ob_json_member(j, directional_only[k])) {
            ob_json_push_key(&c->rd, directional_only[k]);
            return ob_json_fail(&c->rd, "only a directional or spot light has a direction (a point light shines every way)");
        }
    if (!point && !spot && ob_json_member(j, "range")) {
        ob_json_push_key(&c->rd, "range");
        return ob_json_fail(&c->rd, "only a point or spot light has a range");
    }
    if (!spot) {
        static const char *const spot_only[] = {"inner_angle", "outer_angle"};
        for (int k = 0; k < 2; k++)
            if (ob_json_member(j, spot_only[k])) {
                ob_json_push_key(&c->rd, spot_only[k]);
                return ob_json_fail(&c->rd, "only a spot light has cone angles");
            }
    }
    /* Half-angles of the cone in degrees: 0 <= inner <= outer < 90. */
    if (spot && (!ob_json_opt_float(&c->rd, j, "outer_angle", OB_JSON_RANGE(0, 89.9), &outer_degrees) ||
                 !ob_json_opt_float(&c->rd, j, "inner_angle", OB_JSON_RANGE(0, 89.9), &inner_degrees)))
        return false;
    if (spot && inner_degrees > outer_degrees) {
        ob_json_push_key(&c->rd, "inner_angle");
        return ob_json_fail(&c->rd, "must not be larger than outer_angle (%g degrees), got %g",
                            (double)outer_degrees, (double)inner_degrees);
    }
    if (spot) {
        l->desc.inner_angle = inner_degrees * (float)(OB_PI / 180.0);
        l->desc.outer_angle = outer_degrees * (float)(OB_PI / 180.0);
        /* outer_angle 0 is a zero-width cone here, not the engine's default. */
        if (l->desc.outer_angle == 0.0f) l->desc.outer_angle = 1e-6f;
    }
    if (ob_json_member(j, "target") && ob_json_member(j, "direction")) {
        ob_json_push_key(&c->rd, "direction");
        return ob_json_fail(&c->rd, "give either target or direction, not both");
    }
    if (!ob_json_opt_direction(&c->rd, j, "direction", l->direction)) return false;
    if (ob_json_member(j, "target")) {
        double t[3];
        if (!ob_json_opt_vec3d(&c->rd, j, "target", OB_JSON_ANY, t)) return false;
        for (int k = 0; k < 3; k++) l->direction[k] = t[k] - l->position[k];
        if (!ob_json_normalize(l->direction, 3) || !isfinite(l->direction[0] + l->direction[1] + l->direction[2])) {
            ob_json_push_key(&c->rd, "target");
            return ob_json_fail(&c->rd, "must differ from position (the light points from position to target)");
        }
    }
    /* The lit shaders shade one directional light; point and spot lights
     * over OB_MAX_LIGHTS are reported by the renderer, by name. */
    if (!point && !spot && (*directional)++)
        return ob_json_fail(&c->rd, "only one directional light is drawn, and this is the second");
    return true;
}

/* ------------------------------------------------------------ materials */

static bool parse_material(sf_ctx *c, const cJSON *j, ob_scene_file_material *m)
{
    static const char *const keys[] = {"kind", "diffuse", "specular", "emissive", "reflectivity",
                                       "roughness", "metallic", "casts_shadows", "blended", "priority"};
    if (!ob_json_check_object(&c->rd, j, "a material object or the name of one", keys, OB_ARRAY_COUNT(keys)))
        return false;
    ob_material_desc *d = &m->desc;
    d->name = m->name;
    d->kind = OB_MATERIAL_LIT;
    const cJSON *kind = ob_json_member(j, "kind");
    if (kind) {
        static const char *const kinds[] = {"lit", "reflective", "unlit"};
        size_t mark = ob_json_push_key(&c->rd, "kind");
        uint32_t k = 0;
        while (k < 3 && !(cJSON_IsString(kind) && strcmp(kind->valuestring, kinds[k]) == 0)) k++;
        if (k == 3) return ob_json_fail(&c->rd, "expected \"lit\", \"reflective\" or \"unlit\", got %s", ob_json_type_name(kind));
        d->kind = (ob_material_kind)k;   /* the same order as ob_material_kind */
        ob_json_pop(&c->rd, mark);
    }
    float diffuse[4] = {1, 1, 1, 1}, specular[4] = {0.25f, 0.25f, 0.25f, 32.0f}, emissive[4] = {0};
    d->reflectivity = d->kind == OB_MATERIAL_REFLECTIVE ? 0.6f : 0.0f;
    d->casts_shadows = true;
    if (!opt_srgb_color(c, j, "diffuse", 1.0f, diffuse) || !opt_srgb_color(c, j, "specular", 32.0f, specular))
        return false;
    const cJSON *em = ob_json_member(j, "emissive");
    if (em) {
        size_t mark = ob_json_push_key(&c->rd, "emissive");
        double v[3];
        if (!ob_json_vector(&c->rd, em, 3, 3, OB_JSON_NON_NEGATIVE, true, v, NULL)) return false;
        for (int i = 0; i < 3; i++) emissive[i] = (float)v[i];
        ob_json_pop(&c->rd, mark);
    }
    if (diffuse[3] > 1.0f) {
        ob_json_push_key(&c->rd, "diffuse");
        ob_json_push_index(&c->rd, 3);
        return ob_json_fail(&c->rd, "expected an alpha from 0 to 1, got %g", (double)diffuse[3]);
    }
    if (!(specular[3] > 0.0f)) {
        ob_json_push_key(&c->rd, "specular");
        ob_json_push_index(&c->rd, 3);
        return ob_json_fail(&c->rd, "expected a specular power > 0 (use [0, 0, 0] for no highlight)");
    }
    if (ob_json_member(j, "reflectivity") && d->kind != OB_MATERIAL_REFLECTIVE) {
        ob_json_push_key(&c->rd, "reflectivity");
        return ob_json_fail(&c->rd, "only a \"reflective\" material has a reflectivity");
    }
    static const char *const factors[] = {"roughness", "metallic"};
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(factors); i++) {
        if (!ob_json_member(j, factors[i]) || d->kind != OB_MATERIAL_UNLIT) continue;
        ob_json_push_key(&c->rd, factors[i]);
        return ob_json_fail(&c->rd, "an \"unlit\" material has no %s (it is not lit)", factors[i]);
    }
    memcpy(d->diffuse, diffuse, sizeof diffuse);
    memcpy(d->specular, specular, sizeof specular);
    memcpy(d->emissive, emissive, sizeof emissive);
    double prio = 0;
    if (!ob_json_opt_float(&c->rd, j, "reflectivity", OB_JSON_RANGE(0, 1), &d->reflectivity) ||
        !ob_json_opt_float(&c->rd, j, "roughness", OB_JSON_RANGE(0, 1), &d->roughness) ||
        !ob_json_opt_float(&c->rd, j, "metallic", OB_JSON_RANGE(0, 1), &d->metallic) ||
        !ob_json_opt_bool(&c->rd, j, "casts_shadows", &d->casts_shadows) || !ob_json_opt_bool(&c->rd, j, "blended", &d->blended) ||
        !ob_json_opt_double(&c->rd, j, "priority", OB_JSON_INT(0, 1000000), &prio))
        return false;
    d->priority = (uint32_t)prio;
    /* metallic (lit or reflective) or roughness (lit) describes the surface
     * in the metallic-roughness model directly; a lit one given only its
     * metallic keeps the roughness its specular power maps to, and a
     * reflective one's roughness alone keeps the rest mapped. */
    const bool metallic = ob_json_member(j, "metallic") != NULL, roughness = ob_json_member(j, "roughness") != NULL;
    if (d->kind == OB_MATERIAL_LIT && metallic && !roughness) d->roughness = ob_material_desc_to_pbr(d).pbr.roughness;
    d->metallic_roughness = metallic || (d->kind == OB_MATERIAL_LIT && roughness);
    return true;
}

static ob_scene_file_material *add_material(sf_ctx *c, const char *name, bool inline_material)
{
    ob_scene_file *sf = c->sf;
    if (ob_array_reserve((void **)&sf->materials, &c->material_cap, sf->material_count + 1,
                         sizeof *sf->materials) != OB_OK) {
        ob_json_out_of_memory(&c->rd);
        return NULL;
    }
    ob_scene_file_material *m = &sf->materials[sf->material_count];
    memset(m, 0, sizeof *m);
    if (!(m->name = dup_or_oom(c, name))) return NULL;
    m->inline_material = inline_material;
    sf->material_count++;
    return m;
}

static bool parse_materials(sf_ctx *c, const cJSON *j)
{
    if (!cJSON_IsObject(j))
        return ob_json_fail(&c->rd, "expected an object of named materials, got %s", ob_json_type_name(j));
    uint32_t n = (uint32_t)cJSON_GetArraySize(j);
    if (!ob_json_names_init(&c->rd, &c->materials, n)) return false;
    for (const cJSON *it = j->child; it; it = it->next) {
        size_t mark = ob_json_push_key(&c->rd, it->string);
        if (!it->string[0]) return ob_json_fail(&c->rd, "a material needs a non-empty name");
        if (!ob_json_check_text(&c->rd, it->string, "a material name")) return false;
        if (ob_json_names_find(&c->materials, it->string) != OB_SCENE_FILE_NONE) return ob_json_fail(&c->rd, "duplicate material name");
        ob_scene_file_material *m = add_material(c, it->string, false);
        if (!m || !parse_material(c, it, m)) return false;
        ob_json_names_put(&c->materials, it->string, c->sf->material_count - 1);
        ob_json_pop(&c->rd, mark);
    }
    return true;
}

/* ------------------------------------------------------------ geometry */

typedef struct generator_info {
    const char *name;
    ob_scene_file_geometry_kind kind;
    const char *keys[6];
    uint32_t key_count;
} generator_info;

static const generator_info generators[] = {
    {"box", OB_SCENE_GEOMETRY_BOX, {"generator", "size"}, 2},
    {"sphere", OB_SCENE_GEOMETRY_SPHERE, {"generator", "radius", "slices", "stacks", "lods"}, 5},
    {"plane", OB_SCENE_GEOMETRY_PLANE, {"generator", "width", "depth", "subdivisions"}, 4},
    {"cone", OB_SCENE_GEOMETRY_CONE, {"generator", "radius", "height", "slices", "lods"}, 5},
    {"torus", OB_SCENE_GEOMETRY_TORUS,
     {"generator", "major_radius", "minor_radius", "major_segments", "minor_segments", "lods"}, 6},
};

static bool parse_model(sf_ctx *c, const cJSON *j, ob_scene_file_geometry *g)
{
    static const char *const keys[] = {"model", "lods"};
    if (!ob_json_check_object(&c->rd, j, "an object", keys, 2) ||
        !ob_json_opt_u32(&c->rd, j, "lods", 0, OB_SCENE_FILE_MAX_LODS, &g->lods))
        return false;
    size_t mark = ob_json_push_key(&c->rd, "model");
    const char *p = ob_json_string(&c->rd, ob_json_member(j, "model"), "a model file path");
    if (!p) return false;
    size_t dl = p[0] == '/' ? 0 : strlen(c->dir), pl = strlen(p);
    if (!(g->model = ob_malloc(dl + pl + 1))) return ob_json_out_of_memory(&c->rd);
    memcpy(g->model, c->dir, dl);
    memcpy(g->model + dl, p, pl + 1);
    g->kind = OB_SCENE_GEOMETRY_MODEL;
    g->model_relative = p[0] != '/';
    ob_json_pop(&c->rd, mark);
    return true;
}

static bool parse_generator(sf_ctx *c, const cJSON *j, ob_scene_file_geometry *g, uint32_t max);

static bool parse_geometry(sf_ctx *c, const cJSON *j, ob_scene_file_geometry *g)
{
    if (!cJSON_IsObject(j))
        return ob_json_fail(&c->rd, "expected an object with \"generator\" or \"model\", got %s", ob_json_type_name(j));
    const cJSON *gen = ob_json_member(j, "generator");
    if (gen && ob_json_member(j, "model")) {
        ob_json_push_key(&c->rd, "model");
        return ob_json_fail(&c->rd, "give either generator or model, not both");
    }
    if (ob_json_member(j, "model")) return parse_model(c, j, g);
    if (!gen)
        return ob_json_fail(&c->rd, "expected \"generator\" (box, sphere, plane, cone or torus) or \"model\" "
                       "(a file path)");
    size_t mark = ob_json_push_key(&c->rd, "generator");
    const generator_info *info = NULL;
    for (size_t i = 0; i < OB_ARRAY_COUNT(generators); i++)
        if (cJSON_IsString(gen) && strcmp(gen->valuestring, generators[i].name) == 0) info = &generators[i];
    if (!info) {
        if (cJSON_IsString(gen))
            return ob_json_fail(&c->rd, "expected box, sphere, plane, cone or torus, got \"%.40s\"", gen->valuestring);
        return ob_json_fail(&c->rd, "expected box, sphere, plane, cone or torus, got %s", ob_json_type_name(gen));
    }
    ob_json_pop(&c->rd, mark);
    if (!ob_json_check_object(&c->rd, j, "an object", info->keys, info->key_count)) return false;
    g->kind = info->kind;
    const uint32_t max = OB_MESH_MAX_SEGMENTS;
    if (!parse_generator(c, j, g, max)) return false;
    /* The generators' own bound (ob_mesh.h), named here with the file's keys. */
    static const char *const pairs[][2] = {[OB_SCENE_GEOMETRY_SPHERE] = {"slices", "stacks"},
                                           [OB_SCENE_GEOMETRY_PLANE] = {"subdivisions", "subdivisions"},
                                           [OB_SCENE_GEOMETRY_TORUS] = {"major_segments", "minor_segments"}};
    uint32_t b = g->kind == OB_SCENE_GEOMETRY_PLANE ? g->segments[0] : g->segments[1];
    if ((size_t)g->kind < OB_ARRAY_COUNT(pairs) && pairs[g->kind][0] &&
        (uint64_t)g->segments[0] * b > OB_MESH_MAX_GENERATED_CELLS) {
        ob_json_push_key(&c->rd, ob_json_member(j, pairs[g->kind][1]) ? pairs[g->kind][1] : pairs[g->kind][0]);
        return ob_json_fail(&c->rd, "%s x %s = %u x %u = %llu cells, more than the limit of %u",
                            pairs[g->kind][0], pairs[g->kind][1], g->segments[0], b,
                            (unsigned long long)g->segments[0] * b, OB_MESH_MAX_GENERATED_CELLS);
    }
    return true;
}

static bool parse_generator(sf_ctx *c, const cJSON *j, ob_scene_file_geometry *g, uint32_t max)
{
    switch (g->kind) {
    case OB_SCENE_GEOMETRY_BOX:
        g->size[0] = g->size[1] = g->size[2] = 1.0f;
        return ob_json_opt_number_or_vec3(&c->rd, j, "size", OB_JSON_POSITIVE, g->size);
    case OB_SCENE_GEOMETRY_SPHERE:
        g->radius = 0.5f;
        g->segments[0] = 32, g->segments[1] = 16;
        return ob_json_opt_float(&c->rd, j, "radius", OB_JSON_POSITIVE, &g->radius) &&
               ob_json_opt_u32(&c->rd, j, "slices", 3, max, &g->segments[0]) &&
               ob_json_opt_u32(&c->rd, j, "stacks", 2, max, &g->segments[1]) &&
               ob_json_opt_u32(&c->rd, j, "lods", 0, OB_SCENE_FILE_MAX_LODS, &g->lods);
    case OB_SCENE_GEOMETRY_PLANE:
        g->width = g->depth = 10.0f;
        g->segments[0] = 1;
        return ob_json_opt_float(&c->rd, j, "width", OB_JSON_POSITIVE, &g->width) &&
               ob_json_opt_float(&c->rd, j, "depth", OB_JSON_POSITIVE, &g->depth) &&
               ob_json_opt_u32(&c->rd, j, "subdivisions", 1, max, &g->segments[0]);
    case OB_SCENE_GEOMETRY_CONE:
        g->radius = 0.5f;
        g->height = 1.0f;
        g->segments[0] = 32;
        return ob_json_opt_float(&c->rd, j, "radius", OB_JSON_POSITIVE, &g->radius) &&
               ob_json_opt_float(&c->rd, j, "height", OB_JSON_POSITIVE, &g->height) &&
               ob_json_opt_u32(&c->rd, j, "slices", 3, max, &g->segments[0]) &&
               ob_json_opt_u32(&c->rd, j, "lods", 0, OB_SCENE_FILE_MAX_LODS, &g->lods);
    case OB_SCENE_GEOMETRY_TORUS:
        g->major_radius = 0.5f;
        g->minor_radius = 0.15f;
        g->segments[0] = 32, g->segments[1] = 16;
        if (!ob_json_opt_float(&c->rd, j, "major_radius", OB_JSON_POSITIVE, &g->major_radius) ||
            !ob_json_opt_float(&c->rd, j, "minor_radius", OB_JSON_POSITIVE, &g->minor_radius) ||
            !ob_json_opt_u32(&c->rd, j, "major_segments", 3, max, &g->segments[0]) ||
            !ob_json_opt_u32(&c->rd, j, "minor_segments", 3, max, &g->segments[1]) ||
            !ob_json_opt_u32(&c->rd, j, "lods", 0, OB_SCENE_FILE_MAX_LODS, &g->lods))
            return false;
        if (!(g->minor_radius < g->major_radius)) {
            ob_json_push_key(&c->rd, ob_json_member(j, "minor_radius") ? "minor_radius" : "major_radius");
            return ob_json_fail(&c->rd, "minor_radius (%g) must be smaller than major_radius (%g)",
                        (double)g->minor_radius, (double)g->major_radius);
        }
        return true;
    default:
        return ob_json_fail(&c->rd, "unhandled generator");   /* unreachable: the table has every kind */
    }
}

/* ------------------------------------------------------------ entities */

static bool parse_transform(sf_ctx *c, const cJSON *j, ob_scene_file_entity *e)
{
    static const char *const keys[] = {"position", "rotation", "scale"};
    static const char *const rotation_keys[] = {"euler_degrees", "quaternion"};
    if (!ob_json_check_object(&c->rd, j, "an object", keys, OB_ARRAY_COUNT(keys)) ||
        !ob_json_opt_vec3d(&c->rd, j, "position", OB_JSON_ANY, e->position) ||
        !ob_json_opt_number_or_vec3(&c->rd, j, "scale", OB_JSON_ANY, e->scale))
        return false;
    const cJSON *rot = ob_json_member(j, "rotation");
    if (!rot) return true;
    size_t mark = ob_json_push_key(&c->rd, "rotation");
    if (!ob_json_check_object(&c->rd, rot, "an object with euler_degrees or quaternion", rotation_keys, 2)) return false;
    const cJSON *euler = ob_json_member(rot, "euler_degrees"), *quat = ob_json_member(rot, "quaternion");
    if (!euler && !quat) return ob_json_fail(&c->rd, "expected euler_degrees [pitch, yaw, roll] or quaternion [x, y, z, w]");
    if (euler && quat) {
        ob_json_push_key(&c->rd, "quaternion");
        return ob_json_fail(&c->rd, "give either euler_degrees or quaternion, not both");
    }
    size_t inner = ob_json_push_key(&c->rd, euler ? "euler_degrees" : "quaternion");
    if (euler) {
        if (!ob_json_vector(&c->rd, euler, 3, 3, OB_JSON_ANY, true, e->rotation, NULL)) return false;
        e->rotation_kind = OB_SCENE_ROTATION_EULER;
    } else {
        if (!ob_json_vector(&c->rd, quat, 4, 4, OB_JSON_ANY, false, e->rotation, NULL)) return false;
        if (!ob_json_normalize(e->rotation, 4)) return ob_json_fail(&c->rd, "expected a non-zero quaternion");
        e->rotation_kind = OB_SCENE_ROTATION_QUATERNION;
    }
    ob_json_pop(&c->rd, inner);
    ob_json_pop(&c->rd, mark);
    return true;
}

static bool parse_controller(sf_ctx *c, const cJSON *j, ob_scene_file_controller *k)
{
    static const char *const keys[] = {"rotate", "orbit"};
    static const char *const rotate_keys[] = {"axis", "speed_degrees"};
    static const char *const orbit_keys[] = {"center", "axis", "radius", "speed_degrees", "phase_degrees"};
    if (!ob_json_check_object(&c->rd, j, "an object with rotate or orbit", keys, 2)) return false;
    if (cJSON_GetArraySize(j) != 1)
        return ob_json_fail(&c->rd, "expected exactly one of rotate or orbit (use one array entry per controller)");
    bool orbit = ob_json_member(j, "orbit") != NULL;
    const cJSON *body = orbit ? ob_json_member(j, "orbit") : ob_json_member(j, "rotate");
    size_t mark = ob_json_push_key(&c->rd, orbit ? "orbit" : "rotate");
    *k = (ob_scene_file_controller){.kind = orbit ? OB_SCENE_CONTROLLER_ORBIT : OB_SCENE_CONTROLLER_ROTATE,
                                    .axis = {0, 1, 0}, .speed_degrees = 30.0f, .radius = 1.0};
    if (!ob_json_check_object(&c->rd, body, "an object", orbit ? orbit_keys : rotate_keys,
                      orbit ? OB_ARRAY_COUNT(orbit_keys) : OB_ARRAY_COUNT(rotate_keys)) ||
        !opt_axis(c, body, "axis", k->axis) || !ob_json_opt_float(&c->rd, body, "speed_degrees", OB_JSON_ANY, &k->speed_degrees) ||
        !ob_json_opt_vec3d(&c->rd, body, "center", OB_JSON_ANY, k->center) ||
        !ob_json_opt_double(&c->rd, body, "radius", OB_JSON_NON_NEGATIVE, &k->radius) ||
        !ob_json_opt_float(&c->rd, body, "phase_degrees", OB_JSON_ANY, &k->phase_degrees))
        return false;
    ob_json_pop(&c->rd, mark);
    return true;
}

/* The index of the entity named `name` among all of `entities` (only on the
 * error path: says whether a missing parent comes later or does not exist). */
static uint32_t find_entity_json(const cJSON *entities, const char *name)
{
    uint32_t i = 0;
    for (const cJSON *it = entities->child; it; it = it->next, i++) {
        const cJSON *n = cJSON_IsObject(it) ? ob_json_member(it, "name") : NULL;
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0) return i;
    }
    return OB_SCENE_FILE_NONE;
}

/* A name "materials" does not hold, with the closest one it does when a
 * typo explains it. The names of inline materials (paths) are no
 * candidates; without memory for the list the message has no suggestion. */
static bool unknown_material(sf_ctx *c, const char *name)
{
    const ob_scene_file *sf = c->sf;
    const char **names = sf->material_count ? ob_malloc(sizeof *names * sf->material_count) : NULL;
    uint32_t n = 0;
    for (uint32_t i = 0; names && i < sf->material_count; i++)
        if (!sf->materials[i].inline_material) names[n++] = sf->materials[i].name;
    const char *near = ob_closest_name(name, names, n, 0);
    bool r = near ? ob_json_fail(&c->rd, "unknown material '%.60s' (did you mean '%.60s'? not among \"materials\")",
                                 name, near)
                  : ob_json_fail(&c->rd, "unknown material '%.60s' (not among \"materials\")", name);
    ob_free(names);
    return r;
}

static bool parse_entity_material(sf_ctx *c, const cJSON *j, ob_scene_file_entity *e)
{
    if (cJSON_IsString(j)) {
        e->material = ob_json_names_find(&c->materials, j->valuestring);
        if (e->material == OB_SCENE_FILE_NONE) return unknown_material(c, j->valuestring);
        return true;
    }
    if (!cJSON_IsObject(j))
        return ob_json_fail(&c->rd, "expected a material name or a material object, got %s", ob_json_type_name(j));
    ob_scene_file_material *m = add_material(c, c->rd.path, true);
    if (!m || !parse_material(c, j, m)) return false;
    e->material = c->sf->material_count - 1;
    return true;
}

static bool parse_entity(sf_ctx *c, const cJSON *all, const cJSON *j, uint32_t i, ob_scene_file_entity *e)
{
    static const char *const keys[] = {"name", "geometry", "transform", "material",
                                       "parent", "hidden", "controllers"};
    if (!ob_json_check_object(&c->rd, j, "an entity object", keys, OB_ARRAY_COUNT(keys))) return false;
    e->index = i;
    e->material = e->parent = OB_SCENE_FILE_NONE;
    e->scale[0] = e->scale[1] = e->scale[2] = 1.0f;
    if (!(e->name = name_or_default(c, j, "entities", i))) return false;
    if (ob_json_member(j, "name")) {
        uint32_t other = ob_json_names_find(&c->entities, e->name);
        if (other != OB_SCENE_FILE_NONE) {
            ob_json_push_key(&c->rd, "name");
            return ob_json_fail(&c->rd, "'%.60s' is already the name of entities[%u]", e->name, other);
        }
        ob_json_names_put(&c->entities, e->name, i);
    }
    const cJSON *g = ob_json_member(j, "geometry"), *t = ob_json_member(j, "transform"), *m = ob_json_member(j, "material");
    const cJSON *p = ob_json_member(j, "parent"), *ctl = ob_json_member(j, "controllers");
    size_t mark;
    if (g) {
        mark = ob_json_push_key(&c->rd, "geometry");
        if (!parse_geometry(c, g, &e->geometry)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if (t) {
        mark = ob_json_push_key(&c->rd, "transform");
        if (!parse_transform(c, t, e)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if (m) {
        mark = ob_json_push_key(&c->rd, "material");
        if (!g) return ob_json_fail(&c->rd, "an entity without geometry has nothing to draw with a material");
        if (!parse_entity_material(c, m, e)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if (p) {
        mark = ob_json_push_key(&c->rd, "parent");
        const char *name = ob_json_string(&c->rd, p, "the name of an earlier entity");
        if (!name) return false;
        e->parent = ob_json_names_find(&c->entities, name);
        if (e->parent == i) return ob_json_fail(&c->rd, "an entity cannot be its own parent");
        if (e->parent == OB_SCENE_FILE_NONE) {
            uint32_t later = find_entity_json(all, name);
            if (later != OB_SCENE_FILE_NONE)
                return ob_json_fail(&c->rd, "'%.60s' is entities[%u], which comes later: a parent must come before "
                               "its children (this also rules out cycles)", name, later);
            return ob_json_fail(&c->rd, "no entity is named '%.60s'", name);
        }
        ob_json_pop(&c->rd, mark);
    }
    if (!ob_json_opt_bool(&c->rd, j, "hidden", &e->hidden)) return false;
    if (ctl) {
        mark = ob_json_push_key(&c->rd, "controllers");
        if (!cJSON_IsArray(ctl)) return ob_json_fail(&c->rd, "expected an array of controllers, got %s", ob_json_type_name(ctl));
        uint32_t n = (uint32_t)cJSON_GetArraySize(ctl), k = 0;
        if (n && !(e->controllers = ob_calloc(n, sizeof *e->controllers))) return ob_json_out_of_memory(&c->rd);
        e->controller_count = n;
        for (const cJSON *it = ctl->child; it; it = it->next, k++) {
            size_t m2 = ob_json_push_index(&c->rd, k);
            if (!parse_controller(c, it, &e->controllers[k])) return false;
            ob_json_pop(&c->rd, m2);
        }
        ob_json_pop(&c->rd, mark);
    }
    return true;
}

static bool parse_entities(sf_ctx *c, const cJSON *j)
{
    if (!cJSON_IsArray(j)) return ob_json_fail(&c->rd, "expected an array of entities, got %s", ob_json_type_name(j));
    ob_scene_file *sf = c->sf;
    int count = cJSON_GetArraySize(j);
    if (count > (int)OB_SCENE_FILE_MAX_ENTITIES)
        return ob_json_fail(&c->rd, "%d entities, more than the limit of %u", count, OB_SCENE_FILE_MAX_ENTITIES);
    uint32_t n = (uint32_t)count, i = 0;
    if (!ob_json_names_init(&c->rd, &c->entities, n)) return false;
    if (n && !(sf->entities = ob_calloc(n, sizeof *sf->entities))) return ob_json_out_of_memory(&c->rd);
    for (const cJSON *it = j->child; it; it = it->next, i++) {
        size_t mark = ob_json_push_index(&c->rd, i);
        sf->entity_count = i + 1;
        if (!parse_entity(c, j, it, i, &sf->entities[i])) return false;
        ob_json_pop(&c->rd, mark);
    }
    return true;
}

/* ------------------------------------------------------------ particles */

static bool parse_particle_system(sf_ctx *c, const cJSON *j, uint32_t i, ob_scene_file_particles *p)
{
    static const char *const keys[] = {"name", "parent", "count", "lifetime", "speed",
                                       "size", "gravity", "color"};
    if (!ob_json_check_object(&c->rd, j, "a particle system object", keys, OB_ARRAY_COUNT(keys))) return false;
    ob_particle_desc *d = &p->desc;
    *d = (ob_particle_desc){.count = 4096, .lifetime = 3.0f, .speed = 2.0f, .size = 0.05f,
                            .color = {1.0f, 0.8f, 0.5f, 1.0f}};
    p->parent = OB_SCENE_FILE_NONE;
    if (!(p->name = name_or_default(c, j, "particles", i))) return false;
    d->name = p->name;
    const cJSON *parent = ob_json_member(j, "parent");
    if (parent) {
        size_t mark = ob_json_push_key(&c->rd, "parent");
        const char *name = ob_json_string(&c->rd, parent, "the name of an entity");
        if (!name) return false;
        if ((p->parent = ob_json_names_find(&c->entities, name)) == OB_SCENE_FILE_NONE)
            return ob_json_fail(&c->rd, "no entity is named '%.60s'", name);
        ob_json_pop(&c->rd, mark);
    }
    if (!ob_json_opt_u32(&c->rd, j, "count", 1, OB_SCENE_FILE_MAX_PARTICLES, &d->count) ||
        !ob_json_opt_float(&c->rd, j, "lifetime", OB_JSON_POSITIVE, &d->lifetime) ||
        !ob_json_opt_float(&c->rd, j, "speed", OB_JSON_POSITIVE, &d->speed) || !ob_json_opt_float(&c->rd, j, "size", OB_JSON_POSITIVE, &d->size) ||
        !ob_json_opt_vec3f(&c->rd, j, "gravity", OB_JSON_ANY, d->gravity) || !opt_srgb_color(c, j, "color", 1.0f, d->color))
        return false;
    if (!(d->color[3] > 0.0f && d->color[3] <= 1.0f)) {
        ob_json_push_key(&c->rd, "color");
        ob_json_push_index(&c->rd, 3);
        return ob_json_fail(&c->rd, "expected an alpha > 0 and <= 1, got %g", (double)d->color[3]);
    }
    return true;
}

static bool parse_particles(sf_ctx *c, const cJSON *j)
{
    if (!cJSON_IsArray(j)) return ob_json_fail(&c->rd, "expected an array of particle systems, got %s", ob_json_type_name(j));
    ob_scene_file *sf = c->sf;
    uint32_t n = (uint32_t)cJSON_GetArraySize(j), i = 0;
    if (n && !(sf->particles = ob_calloc(n, sizeof *sf->particles))) return ob_json_out_of_memory(&c->rd);
    for (const cJSON *it = j->child; it; it = it->next, i++) {
        size_t mark = ob_json_push_index(&c->rd, i);
        sf->particle_count = i + 1;
        if (!parse_particle_system(c, it, i, &sf->particles[i])) return false;
        ob_json_pop(&c->rd, mark);
    }
    return true;
}

/* ------------------------------------------------------------ top level */

static bool parse_document(sf_ctx *c, const cJSON *root)
{
    static const char *const keys[] = {"description", "settings", "camera", "lights",
                                       "materials", "entities", "particles"};
    if (!cJSON_IsObject(root)) return ob_json_fail(&c->rd, "expected a JSON object at the top level, got %s", ob_json_type_name(root));
    if (!ob_json_check_object(&c->rd, root, "an object", keys, OB_ARRAY_COUNT(keys))) return false;
    ob_scene_file *sf = c->sf;
    const cJSON *j;
    size_t mark;
    if ((j = ob_json_member(root, "description"))) {
        mark = ob_json_push_key(&c->rd, "description");
        if (!cJSON_IsString(j)) return ob_json_fail(&c->rd, "expected a string, got %s", ob_json_type_name(j));
        if (!ob_json_check_text(&c->rd, j->valuestring, "a description")) return false;
        if (!(sf->description = dup_or_oom(c, j->valuestring))) return false;
        ob_json_pop(&c->rd, mark);
    }
    if ((j = ob_json_member(root, "settings"))) {
        mark = ob_json_push_key(&c->rd, "settings");
        if (!parse_settings(c, j, &sf->settings)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if ((j = ob_json_member(root, "camera"))) {
        mark = ob_json_push_key(&c->rd, "camera");
        if (!parse_camera(c, j, &sf->camera)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if ((j = ob_json_member(root, "materials"))) {
        mark = ob_json_push_key(&c->rd, "materials");
        if (!parse_materials(c, j)) return false;
        ob_json_pop(&c->rd, mark);
    }
    if ((j = ob_json_member(root, "lights"))) {
        mark = ob_json_push_key(&c->rd, "lights");
        if (!cJSON_IsArray(j)) return ob_json_fail(&c->rd, "expected an array of lights, got %s", ob_json_type_name(j));
        sf->has_lights = true;
        uint32_t n = (uint32_t)cJSON_GetArraySize(j), i = 0, directional = 0;
        if (n && !(sf->lights = ob_calloc(n, sizeof *sf->lights))) return ob_json_out_of_memory(&c->rd);
        for (const cJSON *it = j->child; it; it = it->next, i++) {
            size_t m = ob_json_push_index(&c->rd, i);
            sf->light_count = i + 1;
            if (!parse_light(c, it, i, &directional, &sf->lights[i])) return false;
            ob_json_pop(&c->rd, m);
        }
        ob_json_pop(&c->rd, mark);
    }
    if (!(j = ob_json_member(root, "entities"))) return ob_json_missing(&c->rd, "entities", "an array of entities");
    mark = ob_json_push_key(&c->rd, "entities");
    if (!parse_entities(c, j)) return false;
    ob_json_pop(&c->rd, mark);
    if ((j = ob_json_member(root, "particles"))) {
        mark = ob_json_push_key(&c->rd, "particles");
        if (!parse_particles(c, j)) return false;
        ob_json_pop(&c->rd, mark);
    }
    return true;
}

/* The directory part of path with its slash ("" when there is none). */
static char *directory_of(const char *path)
{
    const char *slash = path ? strrchr(path, '/') : NULL;
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    char *dir = ob_malloc(n + 1);
    if (!dir) return NULL;
    if (n) memcpy(dir, path, n);
    dir[n] = '\0';
    return dir;
}

ob_result ob_scene_file_parse(const char *text, size_t size, const char *path,
                              ob_scene_file *out, ob_scene_file_error *out_error)
{
    sf_ctx c = {.sf = out};
    ob_json_reader_init(&c.rd, path ? path : "scene", out_error);
    if (!out) return OB_ERR_INVALID_ARGUMENT;
    memset(out, 0, sizeof *out);
    cJSON *root = ob_json_parse(&c.rd, text, size);
    if (!root) return c.rd.result;
    if (!(c.dir = directory_of(path))) ob_json_out_of_memory(&c.rd);
    else if ((out->path = dup_or_oom(&c, c.rd.file)))
        parse_document(&c, root);
    cJSON_Delete(root);
    ob_free(c.dir);
    ob_json_names_release(&c.materials);
    ob_json_names_release(&c.entities);
    if (c.rd.result != OB_OK) ob_scene_file_release(out);
    return c.rd.result;
}

ob_result ob_scene_file_load(const char *path, ob_scene_file *out, ob_scene_file_error *out_error)
{
    ob_scene_file_error local;
    ob_scene_file_error *e = out_error ? out_error : &local;
    memset(e, 0, sizeof *e);
    if (out) memset(out, 0, sizeof *out);
    if (!path || !out) return OB_ERR_INVALID_ARGUMENT;
    /* A regular file no bigger than the bound, checked before anything is
     * read or allocated: a FIFO would block, /dev/zero would grow forever. */
    char why[256];
    size_t size = 0;
    ob_result r;
    char *text = ob_file_read_limited(path, "scene file", OB_SCENE_FILE_MAX_BYTES, &size, why,
                                      sizeof why, &r);
    if (!text) {
        snprintf(e->message, sizeof e->message, "%s: cannot open the scene file: %s", path, why);
        return r == OB_ERR_OUT_OF_HOST_MEMORY ? r : r == OB_ERR_LIMIT ? OB_ERR_LIMIT : OB_ERR_IO;
    }
    r = ob_scene_file_parse(text, size, path, out, e);
    ob_free(text);
    return r;
}

void ob_scene_file_release(ob_scene_file *sf)
{
    if (!sf) return;
    for (uint32_t i = 0; i < sf->light_count; i++) ob_free(sf->lights[i].name);
    for (uint32_t i = 0; i < sf->material_count; i++) ob_free(sf->materials[i].name);
    for (uint32_t i = 0; i < sf->entity_count; i++) {
        ob_free(sf->entities[i].name);
        ob_free(sf->entities[i].geometry.model);
        ob_free(sf->entities[i].controllers);
    }
    for (uint32_t i = 0; i < sf->particle_count; i++) ob_free(sf->particles[i].name);
    ob_free(sf->lights);
    ob_free(sf->materials);
    ob_free(sf->entities);
    ob_free(sf->particles);
    ob_free(sf->description);
    ob_free(sf->path);
    memset(sf, 0, sizeof *sf);
}

bool ob_scene_file_geometry_equal(const ob_scene_file_geometry *a, const ob_scene_file_geometry *b)
{
    if (a->kind != b->kind) return false;
    if (a->kind == OB_SCENE_GEOMETRY_MODEL) return strcmp(a->model, b->model) == 0 && a->lods == b->lods;
    return memcmp(a->size, b->size, sizeof a->size) == 0 && a->radius == b->radius &&
           a->height == b->height && a->width == b->width && a->depth == b->depth &&
           a->major_radius == b->major_radius && a->minor_radius == b->minor_radius &&
           a->segments[0] == b->segments[0] && a->segments[1] == b->segments[1] &&
           a->lods == b->lods;
}

const char *ob_scene_file_geometry_kind_name(ob_scene_file_geometry_kind kind)
{
    static const char *const names[] = {"none", "box", "sphere", "plane", "cone", "torus", "model"};
    return (unsigned)kind < OB_ARRAY_COUNT(names) ? names[kind] : "unknown";
}

void ob_scene_file_hook_cjson(void) { ob_json_hook_allocations(); }
