/* Scene files as a user sees them, without a device: a complete file parses
 * to the description the format documents (defaults filled in, model paths
 * resolved against the file's directory); every malformed input fails with
 * the exact JSON path of the offending value and says what was expected;
 * syntax errors give line and column; the shipped scenes parse; the bad
 * files of the demo test fail as their sidecars say; allocation failures at
 * every point fail cleanly (the ASan build checks that nothing leaks). */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_scene_file.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define SCENES OB_SOURCE_DIR "/demos/scenes/"
#define BAD OB_SOURCE_DIR "/tests/data/scenes/"

static ob_result parse(const char *json, ob_scene_file *sf, ob_scene_file_error *err)
{
    return ob_scene_file_parse(json, strlen(json), "dir/sub/test.json", sf, err);
}

/* ------------------------------------------------------------ good files */

static const char full_scene[] =
    "{\n"
    "  \"description\": \"everything\",\n"
    "  \"settings\": { \"size\": [320, 200], \"env_map_size\": 64, \"shadow_map_size\": 512,\n"
    "                \"shadow_cascades\": 3, \"shadow_distance\": 80, \"shadow_split_lambda\": 0.5,\n"
    "                \"threads\": \"auto\", \"clear_color\": [0.1, 0.2, 0.3], \"ambient\": [1, 1, 1, 0],\n"
    "                \"exposure\": 1.5, \"env_map\": \"cube\", \"sky_color\": [2, 1, 0.5, 0.25] },\n"
    "  \"camera\": { \"position\": [1, 2, 3], \"target\": [1, 2, 0], \"fov_degrees\": 40, \"near\": 0.5 },\n"
    "  \"lights\": [\n"
    "    { \"type\": \"directional\", \"position\": [0, 10, 0], \"target\": [0, 0, 0], \"shadows\": true },\n"
    "    { \"name\": \"lamp\", \"type\": \"point\", \"position\": [1, 1, 1], \"color\": [1, 0.5, 0],\n"
    "      \"intensity\": 2, \"range\": 5 }\n"
    "  ],\n"
    "  \"materials\": {\n"
    "    \"mirror\": { \"kind\": \"reflective\", \"reflectivity\": 0, \"roughness\": 0.25 },\n"
    "    \"glass\": { \"diffuse\": [0.5, 0.6, 0.7, 0.25], \"blended\": true, \"casts_shadows\": false,\n"
    "               \"specular\": [0, 0, 0], \"emissive\": [0.1, 0, 0], \"priority\": 3 }\n"
    "  },\n"
    "  \"entities\": [\n"
    "    { \"name\": \"root\" },\n"
    "    { \"name\": \"ball\", \"parent\": \"root\", \"geometry\": { \"generator\": \"sphere\" },\n"
    "      \"material\": \"mirror\", \"hidden\": true,\n"
    "      \"transform\": { \"position\": [1e10, -2, 3.5], \"rotation\": { \"euler_degrees\": [10, 20, 30] },\n"
    "                     \"scale\": 2 } },\n"
    "    { \"geometry\": { \"generator\": \"box\", \"size\": [1, 2, 3] },\n"
    "      \"material\": { \"kind\": \"unlit\", \"diffuse\": [1, 0, 0] },\n"
    "      \"transform\": { \"rotation\": { \"quaternion\": [0, 0, 0, 2] }, \"scale\": [1, 0, -1] },\n"
    "      \"controllers\": [ { \"rotate\": { \"axis\": [0, 0, 5], \"speed_degrees\": -90 } },\n"
    "                       { \"orbit\": { \"center\": [1, 2, 3], \"radius\": 4, \"phase_degrees\": 45 } } ] },\n"
    "    { \"name\": \"crate\", \"geometry\": { \"model\": \"models/crate.obj\" } },\n"
    "    { \"name\": \"abs\", \"geometry\": { \"model\": \"/abs/crate.obj\" } },\n"
    "    { \"name\": \"t\", \"geometry\": { \"generator\": \"torus\", \"major_radius\": 2, \"minor_radius\": 1,\n"
    "                                     \"major_segments\": 5, \"minor_segments\": 4 } },\n"
    "    { \"name\": \"p\", \"geometry\": { \"generator\": \"plane\" } },\n"
    "    { \"name\": \"c\", \"geometry\": { \"generator\": \"cone\", \"height\": 3 } },\n"
    "    { \"name\": \"s2\", \"geometry\": { \"generator\": \"sphere\" } }\n"
    "  ],\n"
    "  \"particles\": [ { \"parent\": \"ball\", \"count\": 100, \"gravity\": [0, -1, 0] }, {} ]\n"
    "}\n";

static void full_file_parses_to_its_description(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(parse(full_scene, &sf, &err), OB_OK);
    assert_string_equal(err.message, "");
    assert_string_equal(sf.path, "dir/sub/test.json");
    assert_string_equal(sf.description, "everything");

    const ob_scene_file_settings *s = &sf.settings;
    assert_true(s->has_size);
    assert_int_equal(s->width, 320);
    assert_int_equal(s->height, 200);
    assert_int_equal(s->env_map_size, 64);
    assert_int_equal(s->shadow_map_size, 512);
    assert_int_equal(s->shadow_cascades, 3);
    assert_near(s->shadow_distance, 80.0, 0);
    assert_near(s->shadow_split_lambda, 0.5, 0);
    assert_true(s->has_threads);
    assert_int_equal(s->threads, -1);
    assert_true(s->has_clear_color);
    /* Colours are written sRGB-encoded and read back linear. */
    assert_near(s->clear_color[2], pow((0.3 + 0.055) / 1.055, 2.4), 1e-6);
    assert_near(s->exposure, 1.5, 0);
    assert_near(s->clear_color[3], 1.0, 0);   /* alpha 1 when three numbers are given */
    assert_true(s->has_ambient);              /* intensity 0 means no ambient light */
    assert_near(s->ambient[0], 0.0, 0);
    assert_near(s->ambient[3], 1.0, 0);
    assert_true(s->has_env_map_kind);
    assert_int_equal(s->env_map_kind, OB_ENV_MAP_CUBE);
    assert_true(s->has_sky_color);            /* sRGB-decoded, may exceed 1; alpha ignored */
    assert_near(s->sky_color[0], pow((2.0 + 0.055) / 1.055, 2.4), 1e-5);
    assert_near(s->sky_color[3], 1.0, 0);

    assert_true(sf.camera.present);
    assert_near(sf.camera.position[2], 3.0, 0);
    assert_near(sf.camera.target[2], 0.0, 0);
    assert_near(sf.camera.up[1], 1.0, 0);
    assert_near(sf.camera.fov_degrees, 40.0, 0);
    assert_near(sf.camera.znear, 0.5, 1e-7);

    assert_true(sf.has_lights);
    assert_int_equal(sf.light_count, 2);
    assert_string_equal(sf.lights[0].name, "lights[0]");
    assert_int_equal(sf.lights[0].desc.type, OB_LIGHT_DIRECTIONAL);
    assert_true(sf.lights[0].desc.casts_shadows);
    assert_near(sf.lights[0].direction[1], -1.0, 1e-12);   /* target - position, unit */
    assert_near(sf.lights[0].desc.intensity, 1.0, 0);
    assert_string_equal(sf.lights[1].name, "lamp");
    assert_int_equal(sf.lights[1].desc.type, OB_LIGHT_POINT);
    assert_near(sf.lights[1].desc.color[1], pow((0.5 + 0.055) / 1.055, 2.4), 1e-6);
    assert_near(sf.lights[1].desc.range, 5.0, 0);

    assert_int_equal(sf.material_count, 3);   /* two named, one inline */
    const ob_scene_file_material *mirror = &sf.materials[0], *glass = &sf.materials[1];
    assert_string_equal(mirror->name, "mirror");
    assert_int_equal(mirror->desc.kind, OB_MATERIAL_REFLECTIVE);
    assert_near(mirror->desc.reflectivity, 0.0, 0);   /* explicit 0 stays 0 */
    assert_near(mirror->desc.roughness, 0.25, 0);
    assert_true(mirror->desc.casts_shadows);
    assert_near(mirror->desc.diffuse[3], 1.0, 0);
    assert_near(mirror->desc.specular[3], 32.0, 0);
    assert_ptr_equal(mirror->desc.name, mirror->name);
    assert_near(glass->desc.diffuse[3], 0.25, 1e-7);
    assert_true(glass->desc.blended);
    assert_false(glass->desc.casts_shadows);
    assert_near(glass->desc.specular[0], 0.0, 0);
    assert_near(glass->desc.specular[3], 32.0, 0);
    assert_near(glass->desc.emissive[0], 0.1, 1e-7);
    assert_int_equal(glass->desc.priority, 3);
    assert_true(sf.materials[2].inline_material);
    assert_string_equal(sf.materials[2].name, "entities[2].material");
    assert_int_equal(sf.materials[2].desc.kind, OB_MATERIAL_UNLIT);

    assert_int_equal(sf.entity_count, 9);
    const ob_scene_file_entity *e = sf.entities;
    assert_int_equal(e[0].geometry.kind, OB_SCENE_GEOMETRY_NONE);
    assert_int_equal(e[0].parent, OB_SCENE_FILE_NONE);
    assert_int_equal(e[0].material, OB_SCENE_FILE_NONE);
    assert_near(e[0].scale[1], 1.0, 0);
    assert_int_equal(e[0].rotation_kind, OB_SCENE_ROTATION_NONE);

    assert_int_equal(e[1].parent, 0);
    assert_int_equal(e[1].material, 0);
    assert_true(e[1].hidden);
    assert_int_equal(e[1].geometry.kind, OB_SCENE_GEOMETRY_SPHERE);
    assert_near(e[1].geometry.radius, 0.5, 0);
    assert_int_equal(e[1].geometry.segments[0], 32);
    assert_int_equal(e[1].geometry.segments[1], 16);
    assert_near(e[1].position[0], 1e10, 0);   /* doubles stay doubles */
    assert_int_equal(e[1].rotation_kind, OB_SCENE_ROTATION_EULER);
    assert_near(e[1].rotation[2], 30.0, 0);
    assert_near(e[1].scale[0], 2.0, 0);
    assert_near(e[1].scale[2], 2.0, 0);

    assert_string_equal(e[2].name, "entities[2]");
    assert_int_equal(e[2].material, 2);
    assert_near(e[2].geometry.size[1], 2.0, 0);
    assert_int_equal(e[2].rotation_kind, OB_SCENE_ROTATION_QUATERNION);
    assert_near(e[2].rotation[3], 1.0, 0);   /* normalized */
    assert_near(e[2].scale[1], 0.0, 0);
    assert_near(e[2].scale[2], -1.0, 0);
    assert_int_equal(e[2].controller_count, 2);
    assert_int_equal(e[2].controllers[0].kind, OB_SCENE_CONTROLLER_ROTATE);
    assert_near(e[2].controllers[0].axis[2], 1.0, 0);
    assert_near(e[2].controllers[0].speed_degrees, -90.0, 0);
    assert_int_equal(e[2].controllers[1].kind, OB_SCENE_CONTROLLER_ORBIT);
    assert_near(e[2].controllers[1].center[2], 3.0, 0);
    assert_near(e[2].controllers[1].radius, 4.0, 0);
    assert_near(e[2].controllers[1].axis[1], 1.0, 0);
    assert_near(e[2].controllers[1].speed_degrees, 30.0, 0);
    assert_near(e[2].controllers[1].phase_degrees, 45.0, 0);

    assert_string_equal(e[3].geometry.model, "dir/sub/models/crate.obj");
    assert_string_equal(e[4].geometry.model, "/abs/crate.obj");
    assert_near(e[5].geometry.minor_radius, 1.0, 0);
    assert_int_equal(e[5].geometry.segments[1], 4);
    assert_near(e[6].geometry.width, 10.0, 0);
    assert_int_equal(e[6].geometry.segments[0], 1);
    assert_near(e[7].geometry.height, 3.0, 0);
    assert_near(e[7].geometry.radius, 0.5, 0);

    /* Same parameters share geometry; different ones do not. */
    assert_true(ob_scene_file_geometry_equal(&e[1].geometry, &e[8].geometry));
    assert_false(ob_scene_file_geometry_equal(&e[1].geometry, &e[7].geometry));
    assert_false(ob_scene_file_geometry_equal(&e[3].geometry, &e[4].geometry));

    assert_int_equal(sf.particle_count, 2);
    assert_int_equal(sf.particles[0].parent, 1);
    assert_int_equal(sf.particles[0].desc.count, 100);
    assert_near(sf.particles[0].desc.gravity[1], -1.0, 0);
    assert_string_equal(sf.particles[1].name, "particles[1]");
    assert_int_equal(sf.particles[1].parent, OB_SCENE_FILE_NONE);
    assert_int_equal(sf.particles[1].desc.count, 4096);
    assert_near(sf.particles[1].desc.lifetime, 3.0, 0);
    assert_near(sf.particles[1].desc.color[3], 1.0, 0);

    ob_scene_file_release(&sf);
    assert_null(sf.entities);
    ob_scene_file_release(&sf);   /* twice is fine: it is zeroed */
    ob_scene_file_release(NULL);
}

static void minimal_file_gets_documented_defaults(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(parse("{\"entities\": []}", &sf, &err), OB_OK);
    assert_false(sf.camera.present);   /* the viewer frames the scene */
    assert_false(sf.has_lights);       /* the viewer adds a sun */
    assert_false(sf.settings.has_size);
    assert_false(sf.settings.has_env_map_kind);   /* the views' default: paraboloid */
    assert_false(sf.settings.has_sky_color);      /* the clear colour */
    assert_int_equal(sf.entity_count, 0);
    assert_null(sf.description);
    ob_scene_file_release(&sf);

    /* An explicit empty light list means no lights; unterminated text is fine. */
    static const char text[] = "{\"lights\": [], \"entities\": []}GARBAGE";
    assert_int_equal(ob_scene_file_parse(text, strlen(text) - 7, NULL, &sf, &err), OB_OK);
    assert_true(sf.has_lights);
    assert_int_equal(sf.light_count, 0);
    assert_string_equal(sf.path, "scene");
    ob_scene_file_release(&sf);
}

/* Spot lights: cone half-angles in degrees become radians in the light's
 * desc, aimed like a directional light; many point lights parse (the
 * renderer, not the parser, applies OB_MAX_LIGHTS and names what is over). */
/* Lit and reflective materials in the metallic-roughness model: metallic
 * (either) or roughness (lit) gives the factors directly; a lit material
 * given only metallic keeps the roughness its specular power maps to; a
 * reflective one's roughness alone keeps the rest mapped. */
static void metallic_and_roughness_keys(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    static const char text[] =
        "{\"materials\": {\"steel\": {\"metallic\": 1, \"roughness\": 0.3},"
        " \"satin\": {\"roughness\": 0.6}, \"plain\": {\"specular\": [0.2, 0.2, 0.2, 14], \"metallic\": 0.5},"
        " \"chrome\": {\"kind\": \"reflective\", \"roughness\": 0.1},"
        " \"brass\": {\"kind\": \"reflective\", \"metallic\": 0.8}}, \"entities\": []}";
    assert_int_equal(parse(text, &sf, &err), OB_OK);
    assert_int_equal(sf.material_count, 5);
    const ob_material_desc *steel = &sf.materials[0].desc, *satin = &sf.materials[1].desc,
                           *plain = &sf.materials[2].desc, *chrome = &sf.materials[3].desc,
                           *brass = &sf.materials[4].desc;
    assert_true(steel->metallic_roughness);
    assert_near(steel->metallic, 1.0, 0);
    assert_near(steel->roughness, 0.3, 1e-7);
    assert_true(satin->metallic_roughness);
    assert_near(satin->metallic, 0.0, 0);
    assert_near(satin->roughness, 0.6, 1e-7);
    assert_true(plain->metallic_roughness);   /* its roughness: what power 14 maps to */
    assert_near(plain->roughness, pow(2.0 / 16.0, 0.25), 1e-6);
    assert_near(plain->metallic, 0.5, 0);
    assert_false(chrome->metallic_roughness);
    assert_near(chrome->roughness, 0.1, 1e-7);
    assert_true(brass->metallic_roughness);
    assert_near(brass->metallic, 0.8, 1e-7);
    assert_near(brass->roughness, 0.0, 0);
    ob_scene_file_release(&sf);
}

static void spot_and_many_point_lights_parse(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    static const char text[] =
        "{\"lights\": [{\"name\": \"torch\", \"type\": \"spot\", \"position\": [0, 4, 0],"
        " \"target\": [0, 0, 0], \"range\": 9, \"inner_angle\": 15, \"outer_angle\": 30,"
        " \"shadows\": true},"
        " {\"type\": \"spot\"}, {\"type\": \"point\", \"shadows\": true}], \"entities\": []}";
    assert_int_equal(parse(text, &sf, &err), OB_OK);
    assert_int_equal(sf.light_count, 3);
    /* Shadows on spot and point lights (issue 28); off by default. */
    assert_true(sf.lights[0].desc.casts_shadows);
    assert_false(sf.lights[1].desc.casts_shadows);
    assert_true(sf.lights[2].desc.casts_shadows);
    const ob_scene_file_light *l = &sf.lights[0];
    assert_int_equal(l->desc.type, OB_LIGHT_SPOT);
    assert_string_equal(l->name, "torch");
    assert_float_equal(l->desc.range, 9.0, 1e-6);
    assert_float_equal(l->desc.inner_angle, 15.0 * OB_PI / 180.0, 1e-6);
    assert_float_equal(l->desc.outer_angle, 30.0 * OB_PI / 180.0, 1e-6);
    assert_float_equal(l->direction[1], -1.0, 1e-12);
    /* Defaults: no fully lit core, a 45-degree cone, no cut-off. */
    l = &sf.lights[1];
    assert_float_equal(l->desc.inner_angle, 0.0, 0.0);
    assert_float_equal(l->desc.outer_angle, OB_PI / 4.0, 1e-6);
    assert_float_equal(l->desc.range, 0.0, 0.0);
    ob_scene_file_release(&sf);

    char many[300 * 24 + 64];
    size_t n = (size_t)snprintf(many, sizeof many, "{\"lights\": [");
    for (int i = 0; i < 300; i++)
        n += (size_t)snprintf(many + n, sizeof many - n, "%s{\"type\": \"point\"}", i ? ", " : "");
    snprintf(many + n, sizeof many - n, "], \"entities\": []}");
    assert_int_equal(parse(many, &sf, &err), OB_OK);
    assert_int_equal(sf.light_count, 300);
    ob_scene_file_release(&sf);
}

/* ------------------------------------------------------------ malformed files */

typedef struct bad_case {
    const char *json;
    const char *path;   /* exact JSON path */
    const char *what;   /* part of the message after the path */
} bad_case;

#define E "\"entities\": "
#define BOX "\"geometry\": {\"generator\": \"box\"}"

static const bad_case bad_cases[] = {
    /* missing required keys */
    {"{}", "entities", "missing (expected an array of entities)"},
    {"{\"lights\": [{}], " E "[]}", "lights[0].type", "missing (expected \"directional\", \"point\" or \"spot\")"},
    {"{" E "[{\"geometry\": {}}]}", "entities[0].geometry", "expected \"generator\""},
    {"{" E "[{\"geometry\": {\"size\": 1}}]}", "entities[0].geometry", "or \"model\" (a file path)"},
    {"{" E "[{\"transform\": {\"rotation\": {}}}]}", "entities[0].transform.rotation",
     "expected euler_degrees [pitch, yaw, roll] or quaternion [x, y, z, w]"},
    /* wrong types */
    {"[]", "", "expected a JSON object at the top level, got an array"},
    {"{\"settings\": [], " E "[]}", "settings", "expected an object, got an array"},
    {"{\"camera\": {\"position\": \"here\"}, " E "[]}", "camera.position", "expected 3 numbers, got a string"},
    {"{" E "{}}", "entities", "expected an array of entities, got an object"},
    {"{\"materials\": [], " E "[]}", "materials", "expected an object of named materials, got an array"},
    {"{" E "[{\"hidden\": \"yes\"}]}", "entities[0].hidden", "expected true or false, got a string"},
    {"{" E "[{\"name\": 7}]}", "entities[0].name", "expected a non-empty name, got a number"},
    {"{" E "[{\"name\": \"\"}]}", "entities[0].name", "expected a non-empty name, got an empty string"},
    {"{" E "[{\"controllers\": {}}]}", "entities[0].controllers", "expected an array of controllers"},
    {"{" E "[{" BOX ", \"material\": 3}]}", "entities[0].material",
     "expected a material name or a material object, got a number"},
    {"{" E "[{\"name\": \"a\"}, {\"parent\": 0}]}", "entities[1].parent",
     "expected the name of an earlier entity, got a number"},
    {"{" E "[42]}", "entities[0]", "expected an entity object, got a number"},
    {"{" E "[{" BOX ", \"transform\": {\"position\": [0, null, 0]}}]}", "entities[0].transform.position[1]",
     "expected a number, got null"},
    {"{\"settings\": {\"shadow_cascades\": 5}, " E "[]}", "settings.shadow_cascades", "from 1 to 4"},
    {"{\"settings\": {\"shadow_split_lambda\": 0}, " E "[]}", "settings.shadow_split_lambda",
     "above 0 and at most 1"},
    {"{\"settings\": {\"shadow_distance\": -1}, " E "[]}", "settings.shadow_distance", "expected"},
    {"{\"settings\": {\"threads\": \"many\"}, " E "[]}", "settings.threads",
     "expected an integer from 0 to 16 or \"auto\", got a string"},
    {"{\"lights\": [{\"type\": 1}], " E "[]}", "lights[0].type",
     "expected \"directional\", \"point\" or \"spot\", got a number"},
    {"{\"materials\": {\"m\": {\"kind\": \"shiny\"}}, " E "[]}", "materials.m.kind",
     "expected \"lit\", \"reflective\" or \"unlit\", got a string"},
    /* wrong array lengths */
    {"{\"camera\": {\"position\": [1, 2]}, " E "[]}", "camera.position", "expected 3 numbers, got 2"},
    {"{\"materials\": {\"m\": {\"diffuse\": [1, 1, 1, 1, 1]}}, " E "[]}", "materials.m.diffuse",
     "expected 3 or 4 numbers >= 0, got 5"},
    {"{\"settings\": {\"size\": [1, 2, 3]}, " E "[]}", "settings.size",
     "expected 2 integers from 1 to 8192, got 3"},
    {"{" E "[{\"transform\": {\"rotation\": {\"quaternion\": [0, 0, 1]}}}]}",
     "entities[0].transform.rotation.quaternion", "expected 4 numbers, got 3"},
    {"{" E "[{}, {}, {}, {\"transform\": {\"scale\": [1, 2]}}]}", "entities[3].transform.scale",
     "expected a number or 3 numbers, got an array of 2"},
    {"{" E "[{\"transform\": {\"scale\": \"big\"}}]}", "entities[0].transform.scale",
     "expected a number or 3 numbers, got a string"},
    {"{" E "[{\"geometry\": {\"generator\": \"box\", \"size\": [1, 1]}}]}", "entities[0].geometry.size",
     "expected a number or 3 numbers > 0, got an array of 2"},
    /* unknown keys, at every level, with a suggestion when one is close */
    {"{\"entites\": []}", "entites", "unknown key (did you mean 'entities'?"},
    {"{\"settings\": {\"colour\": 1}, " E "[]}", "settings.colour", "unknown key (expected one of: size,"},
    {"{\"camera\": {\"fov\": 60}, " E "[]}", "camera.fov", "unknown key"},
    {"{\"lights\": [{\"type\": \"point\", \"colour\": [1, 1, 1]}], " E "[]}", "lights[0].colour",
     "did you mean 'color'?"},
    {"{\"materials\": {\"m\": {\"Diffuse\": [1, 1, 1]}}, " E "[]}", "materials.m.Diffuse",
     "did you mean 'diffuse'?"},
    {"{" E "[{\"Name\": \"a\"}]}", "entities[0].Name", "did you mean 'name'?"},
    {"{" E "[{\"geometry\": {\"generator\": \"box\", \"radius\": 1}}]}", "entities[0].geometry.radius",
     "unknown key (expected one of: generator, size)"},
    {"{" E "[{\"geometry\": {\"model\": \"a.obj\", \"scale\": 2}}]}", "entities[0].geometry.scale", "unknown key"},
    {"{" E "[{\"transform\": {\"translation\": [0, 0, 0]}}]}", "entities[0].transform.translation", "unknown key"},
    {"{" E "[{\"transform\": {\"rotation\": {\"euler\": [0, 0, 0]}}}]}", "entities[0].transform.rotation.euler",
     "unknown key"},
    {"{" E "[{\"controllers\": [{\"spin\": {}}]}]}", "entities[0].controllers[0].spin", "unknown key"},
    {"{" E "[{\"controllers\": [{\"orbit\": {\"speed\": 1}}]}]}", "entities[0].controllers[0].orbit.speed",
     "did you mean 'speed_degrees'?"},
    {"{" E "[], \"particles\": [{\"rate\": 3}]}", "particles[0].rate", "unknown key"},
    {"{" E "[{\"my key\": 1}]}", "entities[0][\"my key\"]", "unknown key"},
    {"{" E "[{\"hidden\": true, \"hidden\": false}]}", "entities[0].hidden", "duplicate key"},
    {"{\"materials\": {\"m\": {}, \"m\": {}}, " E "[]}", "materials.m", "duplicate material name"},
    /* references */
    {"{\"materials\": {\"stone\": {}}, " E "[{" BOX ", \"material\": \"stoen\"}]}", "entities[0].material",
     "unknown material 'stoen' (did you mean 'stone'?"},
    {"{\"materials\": {\"stone\": {}, \"gold\": {}}, " E "[{" BOX ", \"material\": \"Glod\"}]}",
     "entities[0].material", "unknown material 'Glod' (did you mean 'gold'?"},
    /* nothing close: no suggestion, and an inline material's path is never one */
    {"{\"materials\": {\"stone\": {}}, " E "[{" BOX ", \"material\": {}}, {" BOX ", \"material\": \"glass\"}]}",
     "entities[1].material", "unknown material 'glass' (not among \"materials\")"},
    {"{" E "[{\"material\": {}}]}", "entities[0].material", "an entity without geometry"},
    {"{" E "[{\"name\": \"a\"}, {\"name\": \"b\", \"parent\": \"c\"}]}", "entities[1].parent",
     "no entity is named 'c'"},
    {"{" E "[{\"name\": \"a\", \"parent\": \"b\"}, {\"name\": \"b\", \"parent\": \"a\"}]}", "entities[0].parent",
     "'b' is entities[1], which comes later"},
    {"{" E "[{\"name\": \"a\", \"parent\": \"a\"}]}", "entities[0].parent", "cannot be its own parent"},
    {"{" E "[{\"name\": \"a\"}, {\"name\": \"a\"}]}", "entities[1].name", "'a' is already the name of entities[0]"},
    {"{" E "[], \"particles\": [{\"parent\": \"ghost\"}]}", "particles[0].parent", "no entity is named 'ghost'"},
    /* bad generator parameters */
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"radius\": 0}}]}", "entities[0].geometry.radius",
     "expected a number > 0, got 0"},
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"slices\": 2.5}}]}", "entities[0].geometry.slices",
     "expected an integer from 3 to 4096, got 2.5"},
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"stacks\": 5000}}]}", "entities[0].geometry.stacks",
     "expected an integer from 2 to 4096"},
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"lods\": 8}}]}", "entities[0].geometry.lods",
     "expected an integer from 0 to 7, got 8"},
    {"{" E "[{\"geometry\": {\"generator\": \"box\", \"lods\": 2}}]}", "entities[0].geometry.lods",
     "unknown key"},
    {"{" E "[{\"geometry\": {\"model\": \"a.obj\", \"lods\": -1}}]}", "entities[0].geometry.lods",
     "expected an integer from 0 to 7, got -1"},
    {"{" E "[{\"geometry\": {\"generator\": \"torus\", \"minor_radius\": 0.6}}]}",
     "entities[0].geometry.minor_radius", "must be smaller than major_radius"},
    {"{" E "[{\"geometry\": {\"generator\": \"box\", \"size\": -1}}]}", "entities[0].geometry.size",
     "expected a number > 0, got -1"},
    {"{" E "[{\"geometry\": {\"generator\": \"plane\", \"subdivisions\": 0}}]}",
     "entities[0].geometry.subdivisions", "expected an integer from 1 to 4096, got 0"},
    {"{" E "[{\"geometry\": {\"generator\": \"cone\", \"height\": -2}}]}", "entities[0].geometry.height",
     "expected a number > 0"},
    {"{" E "[{\"geometry\": {\"generator\": \"teapot\"}}]}", "entities[0].geometry.generator",
     "expected box, sphere, plane, cone or torus, got \"teapot\""},
    {"{" E "[{\"geometry\": {\"generator\": \"box\", \"model\": \"a.obj\"}}]}", "entities[0].geometry.model",
     "either generator or model, not both"},
    {"{" E "[{\"geometry\": {\"model\": \"\"}}]}", "entities[0].geometry.model",
     "expected a model file path, got an empty string"},
    /* non-finite and out-of-range numbers */
    {"{\"camera\": {\"position\": [1e400, 0, 0]}, " E "[]}", "camera.position[0]",
     "got a number too large to represent"},
    {"{\"lights\": [{\"type\": \"point\", \"color\": [1, -1e999, 1]}], " E "[]}", "lights[0].color[1]",
     "got a number too large to represent"},
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"radius\": 1e39}}]}", "entities[0].geometry.radius",
     "within single precision"},
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"radius\": 1e-300}}]}", "entities[0].geometry.radius",
     "too small for single precision"},
    {"{\"camera\": {\"fov_degrees\": 180}, " E "[]}", "camera.fov_degrees", "expected a number from 1 to 170"},
    {"{\"materials\": {\"m\": {\"diffuse\": [1, 1, 1, 2]}}, " E "[]}", "materials.m.diffuse[3]",
     "expected an alpha from 0 to 1"},
    {"{\"materials\": {\"m\": {\"diffuse\": [-0.5, 1, 1]}}, " E "[]}", "materials.m.diffuse[0]",
     "expected a number >= 0, got -0.5"},
    {"{\"materials\": {\"m\": {\"specular\": [1, 1, 1, 0]}}, " E "[]}", "materials.m.specular[3]",
     "specular power > 0"},
    {"{" E "[{\"transform\": {\"rotation\": {\"quaternion\": [0, 0, 0, 0]}}}]}",
     "entities[0].transform.rotation.quaternion", "expected a non-zero quaternion"},
    {"{" E "[], \"particles\": [{\"count\": 0}]}", "particles[0].count", "expected an integer from 1 to 1048576"},
    {"{" E "[], \"particles\": [{\"color\": [1, 1, 1, 0]}]}", "particles[0].color[3]", "expected an alpha > 0"},
    /* things that parse but cannot be right */
    {"{\"camera\": {\"position\": [0, 1, 0], \"target\": [0, 1, 0]}, " E "[]}", "camera.target",
     "must differ from camera.position"},
    {"{\"camera\": {\"position\": [0, 5, 0], \"target\": [0, 0, 0]}, " E "[]}", "camera.up",
     "must not be parallel to the viewing direction"},
    {"{\"lights\": [{\"type\": \"point\", \"direction\": [0, -1, 0]}], " E "[]}", "lights[0].direction",
     "only a directional or spot light has a direction"},
    {"{\"lights\": [{\"type\": \"directional\", \"range\": 3}], " E "[]}", "lights[0].range",
     "only a point or spot light has a range"},
    {"{\"lights\": [{\"type\": \"directional\", \"target\": [0, 0, 0], \"direction\": [0, -1, 0]}], " E "[]}",
     "lights[0].direction", "either target or direction, not both"},
    {"{\"lights\": [{\"type\": \"directional\", \"direction\": [0, 0, 0]}], " E "[]}", "lights[0].direction",
     "expected a non-zero vector"},
    {"{\"lights\": [{\"type\": \"directional\"}, {\"type\": \"directional\"}], " E "[]}", "lights[1]",
     "only one directional light is drawn"},
    {"{\"lights\": [{\"type\": \"spot\", \"inner_angle\": 30, \"outer_angle\": 20}], " E "[]}",
     "lights[0].inner_angle", "must not be larger than outer_angle (20 degrees), got 30"},
    {"{\"lights\": [{\"type\": \"spot\", \"outer_angle\": 90}], " E "[]}", "lights[0].outer_angle",
     "expected a number from 0 to 89.9, got 90"},
    {"{\"lights\": [{\"type\": \"spot\", \"inner_angle\": -5}], " E "[]}", "lights[0].inner_angle",
     "expected a number from 0 to 89.9, got -5"},
    {"{\"lights\": [{\"type\": \"spot\", \"outer_angle\": \"wide\"}], " E "[]}", "lights[0].outer_angle",
     "expected a number"},
    {"{\"lights\": [{\"type\": \"point\", \"outer_angle\": 30}], " E "[]}", "lights[0].outer_angle",
     "only a spot light has cone angles"},
    {"{\"lights\": [{\"type\": \"directional\", \"inner_angle\": 10}], " E "[]}", "lights[0].inner_angle",
     "only a spot light has cone angles"},
    {"{\"materials\": {\"m\": {\"reflectivity\": 0.5}}, " E "[]}", "materials.m.reflectivity",
     "only a \"reflective\" material has a reflectivity"},
    {"{\"materials\": {\"m\": {\"kind\": \"unlit\", \"roughness\": 0.5}}, " E "[]}", "materials.m.roughness",
     "an \"unlit\" material has no roughness (it is not lit)"},
    {"{\"materials\": {\"m\": {\"kind\": \"unlit\", \"metallic\": 1}}, " E "[]}", "materials.m.metallic",
     "an \"unlit\" material has no metallic (it is not lit)"},
    {"{\"materials\": {\"m\": {\"metallic\": -0.1}}, " E "[]}", "materials.m.metallic",
     "expected a number from 0 to 1"},
    {"{\"materials\": {\"m\": {\"kind\": \"reflective\", \"roughness\": 2}}, " E "[]}",
     "materials.m.roughness", "expected a number from 0 to 1"},
    {"{\"settings\": {\"env_map\": \"sphere\"}, " E "[]}", "settings.env_map",
     "expected \"paraboloid\" or \"cube\""},
    {"{\"settings\": {\"env_map\": 1}, " E "[]}", "settings.env_map",
     "expected \"paraboloid\" or \"cube\", got a number"},
    {"{" E "[{\"controllers\": [{\"rotate\": {}, \"orbit\": {}}]}]}", "entities[0].controllers[0]",
     "expected exactly one of rotate or orbit"},
    {"{" E "[{\"controllers\": [{\"orbit\": {\"radius\": -1}}]}]}", "entities[0].controllers[0].orbit.radius",
     "expected a number >= 0, got -1"},    /* hostile input (issue 26): bounds checked before memory is committed,
     * text a terminal would interpret refused */
    {"{" E "[{\"geometry\": {\"generator\": \"sphere\", \"slices\": 4096, \"stacks\": 4096}}]}",
     "entities[0].geometry.stacks", "slices x stacks = 4096 x 4096 = 16777216 cells, more than the limit of 1048576"},
    {"{" E "[{\"geometry\": {\"generator\": \"plane\", \"subdivisions\": 2048}}]}",
     "entities[0].geometry.subdivisions", "more than the limit of 1048576"},
    {"{" E "[{\"name\": \"a\\u001b[31mred\"}]}", "entities[0].name",
     "expected a non-empty name of printable UTF-8 text, got a control character or invalid UTF-8 at byte 1"},
    {"{" E "[{\"name\": \"bad\xff\"}]}", "entities[0].name", "invalid UTF-8 at byte 3"},
    {"{\"description\": \"\\u009b2J\", " E "[]}", "description", "a control character"},
};

static void every_malformed_case_names_its_path(void **state)
{
    (void)state;
    for (size_t i = 0; i < OB_ARRAY_COUNT(bad_cases); i++) {
        const bad_case *c = &bad_cases[i];
        ob_scene_file sf;
        ob_scene_file_error err;
        ob_result r = parse(c->json, &sf, &err);
        char expected_prefix[512];
        if (c->path[0]) snprintf(expected_prefix, sizeof expected_prefix, "dir/sub/test.json: %s: ", c->path);
        else snprintf(expected_prefix, sizeof expected_prefix, "dir/sub/test.json: ");
        if (r != OB_ERR_PARSE || strcmp(err.json_path, c->path) != 0 ||
            strncmp(err.message, expected_prefix, strlen(expected_prefix)) != 0 ||
            !strstr(err.message, c->what)) {
            print_error("case %zu: %s\n  result %s, path '%s' (want '%s')\n  message '%s'\n  want '%s...%s'\n",
                        i, c->json, ob_result_name(r), err.json_path, c->path, err.message,
                        expected_prefix, c->what);
            fail();
        }
        assert_null(sf.entities);   /* nothing is left behind on failure */
        assert_null(sf.path);
        assert_int_equal(err.line, 0);
    }
}

static void syntax_errors_give_line_and_column(void **state)
{
    (void)state;
    static const struct {
        const char *json;
        uint32_t line, column;
        const char *what;
    } cases[] = {
        {"{\n  \"entities\": [\n    {}\n    {}\n  ]\n}\n", 4, 5, "invalid JSON near '{}'"},
        {"{\"entities\": []} }", 1, 18, "invalid JSON near '}'"},
        {"{\"entities\": [\n", 2, 1, "unexpected end of file"},
        {"{\n\"entities\": [tru]}", 2, 14, "invalid JSON near 'tru]}'"},
        {"\n\n  {\"a\": 'single'}", 3, 9, "invalid JSON near"},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases); i++) {
        ob_scene_file sf;
        ob_scene_file_error err;
        assert_int_equal(parse(cases[i].json, &sf, &err), OB_ERR_PARSE);
        char prefix[64];
        snprintf(prefix, sizeof prefix, "dir/sub/test.json:%u:%u: ", cases[i].line, cases[i].column);
        if (err.line != cases[i].line || err.column != cases[i].column ||
            strncmp(err.message, prefix, strlen(prefix)) != 0 || !strstr(err.message, cases[i].what)) {
            print_error("case %zu: got %u:%u '%s', want '%s%s'\n", i, err.line, err.column, err.message,
                        prefix, cases[i].what);
            fail();
        }
        assert_string_equal(err.json_path, "");
    }
    /* A NUL byte inside the text, and empty text. */
    ob_scene_file sf;
    ob_scene_file_error err;
    static const char with_nul[] = "{\"entities\"\0: []}";
    assert_int_equal(ob_scene_file_parse(with_nul, sizeof with_nul - 1, "n.json", &sf, &err), OB_ERR_PARSE);
    assert_string_equal(err.message, "n.json:1:12: invalid JSON: a NUL byte in the text");
    assert_int_equal(ob_scene_file_parse(" \n\t", 3, "e.json", &sf, &err), OB_ERR_PARSE);
    assert_string_equal(err.message, "e.json: the file is empty (expected a JSON object)");
}

static void only_the_first_error_is_reported(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(parse("{" E "[{\"hidden\": 1}, {\"hidden\": 2}]}", &sf, &err), OB_ERR_PARSE);
    assert_string_equal(err.json_path, "entities[0].hidden");
    /* NULL error struct is allowed. */
    assert_int_equal(parse("{" E "[{\"hidden\": 1}]}", &sf, NULL), OB_ERR_PARSE);
}

/* ------------------------------------------------------------ files on disk */

static void shipped_scenes_parse(void **state)
{
    (void)state;
    DIR *dir = opendir(SCENES);
    assert_non_null(dir);
    uint32_t count = 0;
    struct dirent *de;
    while ((de = readdir(dir))) {
        size_t n = strlen(de->d_name);
        if (n < 5 || strcmp(de->d_name + n - 5, ".json") != 0) continue;
        char path[512];
        snprintf(path, sizeof path, SCENES "%s", de->d_name);
        ob_scene_file sf;
        ob_scene_file_error err;
        ob_result r = ob_scene_file_load(path, &sf, &err);
        if (r != OB_OK) print_error("%s\n", err.message);
        assert_int_equal(r, OB_OK);
        assert_true(sf.entity_count > 0);
        assert_true(sf.camera.present);
        ob_scene_file_release(&sf);
        count++;
    }
    closedir(dir);
    assert_true(count >= 3);   /* mirror, primitives, models at least */
}

/* The bad files the demo test feeds obelisk-view fail here the same way. */
static void bad_files_fail_as_their_sidecars_say(void **state)
{
    (void)state;
    DIR *dir = opendir(BAD);
    assert_non_null(dir);
    uint32_t count = 0;
    struct dirent *de;
    while ((de = readdir(dir))) {
        size_t n = strlen(de->d_name);
        if (strncmp(de->d_name, "bad_", 4) != 0 || n < 5 || strcmp(de->d_name + n - 5, ".json") != 0) continue;
        char path[512], expect_path[512];
        snprintf(path, sizeof path, BAD "%s", de->d_name);
        snprintf(expect_path, sizeof expect_path, BAD "%.*s.expect", (int)(n - 5), de->d_name);
        ob_result r;
        size_t size;
        char *expect = ob_file_read(expect_path, &size, &r);
        assert_non_null(expect);
        while (size && (expect[size - 1] == '\n' || expect[size - 1] == '\r')) expect[--size] = '\0';
        ob_scene_file sf;
        ob_scene_file_error err;
        assert_int_equal(ob_scene_file_load(path, &sf, &err), OB_ERR_PARSE);
        if (!strstr(err.message, expect)) {
            print_error("%s: message '%s' lacks '%s'\n", de->d_name, err.message, expect);
            fail();
        }
        ob_free(expect);
        count++;
    }
    closedir(dir);
    assert_true(count >= 10);
}

/* The complete example of docs/scene-format.md is a valid scene. */
static void documented_example_parses(void **state)
{
    (void)state;
    ob_result r;
    size_t size;
    char *doc = ob_file_read(OB_SOURCE_DIR "/docs/scene-format.md", &size, &r);
    assert_non_null(doc);
    char *start = strstr(doc, "## Complete example");
    assert_non_null(start);
    start = strstr(start, "```json\n");
    assert_non_null(start);
    start += 8;
    char *end = strstr(start, "```");
    assert_non_null(end);
    ob_scene_file sf;
    ob_scene_file_error err;
    r = ob_scene_file_parse(start, (size_t)(end - start), "scene-format.md", &sf, &err);
    if (r != OB_OK) print_error("%s\n", err.message);
    assert_int_equal(r, OB_OK);
    assert_int_equal(sf.entity_count, 7);
    assert_int_equal(sf.light_count, 2);
    assert_int_equal(sf.particle_count, 1);
    ob_scene_file_release(&sf);
    ob_free(doc);
}

static void unreadable_file_is_an_io_error_naming_it(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    assert_int_equal(ob_scene_file_load("/nonexistent/scene.json", &sf, &err), OB_ERR_IO);
    assert_non_null(strstr(err.message, "/nonexistent/scene.json: cannot open the scene file: "));
    assert_int_equal(ob_scene_file_load(BAD, &sf, &err), OB_ERR_IO);   /* a directory */
    assert_non_null(strstr(err.message, "cannot open the scene file: not a regular file (a directory)"));
    assert_null(sf.path);
}

/* Files that would block, grow without bound or cut strings short are
 * refused before anything is read or allocated, each with a message naming
 * the file and what was wrong. */
static void hostile_files_are_refused_with_a_reason(void **state)
{
    (void)state;
    char dir[] = "/tmp/ob_test_scene_hostile_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[128];
    ob_scene_file sf;
    ob_scene_file_error err;

    /* A FIFO nobody writes to: opening it for reading would block forever. */
    snprintf(path, sizeof path, "%s/fifo.json", dir);
    assert_int_equal(mkfifo(path, 0600), 0);
    assert_int_equal(ob_scene_file_load(path, &sf, &err), OB_ERR_IO);
    assert_non_null(strstr(err.message, "fifo.json: cannot open the scene file: not a regular file (a FIFO)"));
    remove(path);

    /* A link to /dev/zero would be read until memory runs out. */
    snprintf(path, sizeof path, "%s/zero.json", dir);
    assert_int_equal(symlink("/dev/zero", path), 0);
    assert_int_equal(ob_scene_file_load(path, &sf, &err), OB_ERR_IO);
    assert_non_null(strstr(err.message, "zero.json: cannot open the scene file: not a regular file (a device)"));
    remove(path);

    /* A file over the bound is refused from its size (sparse: no disk used). */
    snprintf(path, sizeof path, "%s/huge.json", dir);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(ftruncate(fileno(f), (off_t)OB_SCENE_FILE_MAX_BYTES + 1), 0);
    fclose(f);
    assert_int_equal(ob_scene_file_load(path, &sf, &err), OB_ERR_LIMIT);
    assert_non_null(strstr(err.message, "huge.json: cannot open the scene file: 67108865 bytes, more than "
                                        "the limit of 67108864"));
    remove(path);
    rmdir(dir);

    /* More entities than the bound: refused from the array's length. */
    size_t n = (size_t)OB_SCENE_FILE_MAX_ENTITIES + 1, size = 16 + 3 * n;
    char *text = malloc(size);
    assert_non_null(text);
    size_t at = (size_t)snprintf(text, size, "{" E "[");
    for (size_t i = 0; i < n; i++) at += (size_t)snprintf(text + at, size - at, "%s{}", i ? "," : "");
    at += (size_t)snprintf(text + at, size - at, "]}");
    assert_int_equal(ob_scene_file_parse(text, at, "many.json", &sf, &err), OB_ERR_PARSE);
    assert_non_null(strstr(err.message, "many.json: entities: 262145 entities, more than the limit of 262144"));
    free(text);

    /* Nesting past cJSON's limit says so, instead of "invalid JSON near '[[[['". */
    char deep[3000];
    at = (size_t)snprintf(deep, sizeof deep, "{\"description\": ");
    for (int i = 0; i < 1100; i++) deep[at++] = '[';
    deep[at] = '\0';
    assert_int_equal(parse(deep, &sf, &err), OB_ERR_PARSE);
    assert_non_null(strstr(err.message, "invalid JSON: arrays and objects nested deeper than 1000 levels"));

    /* A \u0000 would silently cut a model path short. */
    assert_int_equal(parse("{" E "[{\"geometry\": {\"model\": \"a.obj\\u0000.png\"}}]}", &sf, &err),
                     OB_ERR_PARSE);
    assert_non_null(strstr(err.message, "test.json:1:"));
    assert_non_null(strstr(err.message, "(NUL) escape in a string"));
}

/* ------------------------------------------------------------ allocation failures */

static void every_allocation_failure_is_clean(void **state)
{
    (void)state;
    ob_scene_file sf;
    ob_scene_file_error err;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_int_equal(parse(full_scene, &sf, &err), OB_OK);
    ob_scene_file_release(&sf);
    uint64_t calls = ob_fault_count(OB_FAULT_HOST_ALLOC);
    assert_true(calls > 50);
    for (uint64_t n = 1; n <= calls; n++) {
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        ob_result r = parse(full_scene, &sf, &err);
        bool hit = ob_fault_hit(OB_FAULT_HOST_ALLOC);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        if (hit) {
            if (r != OB_ERR_OUT_OF_HOST_MEMORY) {
                print_error("allocation %llu: %s, '%s'\n", (unsigned long long)n, ob_result_name(r), err.message);
                fail();
            }
            assert_null(sf.entities);
            assert_null(sf.materials);
            assert_null(sf.path);
            assert_non_null(strstr(err.message, "out of memory"));
        } else {
            assert_int_equal(r, OB_OK);
            ob_scene_file_release(&sf);
        }
    }
}

int main(void)
{
    ob_test_setup_log();
    /* The fault walks reach cJSON's allocations too (the program's choice:
     * cJSON's hooks are process-wide). */
    ob_scene_file_hook_cjson();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(full_file_parses_to_its_description),
        cmocka_unit_test(minimal_file_gets_documented_defaults),
        cmocka_unit_test(spot_and_many_point_lights_parse),
        cmocka_unit_test(metallic_and_roughness_keys),
        cmocka_unit_test(every_malformed_case_names_its_path),
        cmocka_unit_test(syntax_errors_give_line_and_column),
        cmocka_unit_test(only_the_first_error_is_reported),
        cmocka_unit_test(shipped_scenes_parse),
        cmocka_unit_test(bad_files_fail_as_their_sidecars_say),
        cmocka_unit_test(documented_example_parses),
        cmocka_unit_test(unreadable_file_is_an_io_error_naming_it),
        cmocka_unit_test(hostile_files_are_refused_with_a_reason),
        cmocka_unit_test(every_allocation_failure_is_clean),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
