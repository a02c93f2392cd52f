#include "ob_stack_content.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ob_model_instance.h"
#include "ob_scene_layer_internal.h"

#define LOG_MODULE "stack"

const ob_light_desc ob_sun_light = {.type = OB_LIGHT_DIRECTIONAL, .color = {1.0f, 0.97f, 0.92f},
                                    .intensity = 1.0f, .casts_shadows = true};
const double ob_sun_direction[3] = {-0.11, -0.77, -0.63};

/* One model file the stack opened, shared by every instance of it. */
typedef struct stack_model {
    char *path;                  /* as the program gave it */
    bool allow_any_folder;       /* part of the key: the same file may be refused without it */
    uint32_t lods;               /* part of the key: its geometry has these levels */
    ob_model_assets *assets;
} stack_model;

struct ob_stack_content {
    stack_model *models;
    uint32_t model_count, model_cap;
    ob_texture_cache *textures;  /* every model's textures; NULL until one has images */
    ob_scene_loaded **scenes;    /* heap records: programs keep pointers to them */
    uint32_t scene_count, scene_cap;
};

ob_result ob_light_aim(ob_node *n, const double direction[3])
{
    double up[3] = {0, 1, 0};
    if (fabs(direction[1]) > 0.99) up[1] = 0, up[2] = -1;
    return ob_node_look_at(n, direction, up);
}

static ob_result content_of(ob_stack *s, struct ob_stack_content **out)
{
    if (!s->content && !(s->content = ob_calloc(1, sizeof *s->content))) {
        OB_LOG_E(LOG_MODULE, "no memory to keep what the stack loads");
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    *out = s->content;
    return OB_OK;
}

static const char *file_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash && slash[1] ? slash + 1 : path;
}

/* ------------------------------------------------------------ models */

/* The assets of desc->path: opened before, or opened now with their
 * materials (and textures in the stack's cache) and kept. */
static ob_result model_assets(ob_stack *s, const ob_stack_model_desc *desc, ob_model_assets **out)
{
    struct ob_stack_content *c;
    ob_result r = content_of(s, &c);
    if (r != OB_OK) return r;
    for (uint32_t i = 0; i < c->model_count; i++) {
        if (strcmp(c->models[i].path, desc->path) != 0 ||
            c->models[i].allow_any_folder != desc->allow_any_folder || c->models[i].lods != desc->lods)
            continue;
        *out = c->models[i].assets;
        return OB_OK;
    }
    if ((r = ob_array_reserve((void **)&c->models, &c->model_cap, c->model_count + 1,
                              sizeof *c->models)) != OB_OK)
        return r;
    char *path = ob_strdup(desc->path);
    if (!path) return OB_ERR_OUT_OF_HOST_MEMORY;
    /* flip_uv: the engine samples images with Vulkan's top-left origin. */
    ob_model *model = NULL;
    r = ob_model_open(&(ob_model_desc){.path = desc->path, .flip_uv = true,
                                       .allow_any_folder = desc->allow_any_folder},
                      &model);
    if (r == OB_OK && model->image_count > 0 && !c->textures &&
        !(c->textures = ob_texture_cache_create(s->device, &r)))
        ob_model_close(model);
    ob_model_assets *a = NULL;
    if (r == OB_OK) {
        ob_model_assets_desc ad = {.renderer = s->renderer, .materials = s->materials,
                                   .textures = c->textures, .lods = desc->lods};
        a = ob_model_assets_create(&ad, model, &r);   /* takes the model */
    }
    if (!a) {
        ob_free(path);
        return r;
    }
    c->models[c->model_count++] = (stack_model){.path = path, .allow_any_folder = desc->allow_any_folder,
                                                .lods = desc->lods, .assets = a};
    *out = a;
    return OB_OK;
}

static bool all_zero(const void *p, size_t size)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < size; i++)
        if (b[i]) return false;
    return true;
}

ob_node *ob_stack_add_model(ob_stack *s, const ob_stack_model_desc *desc, ob_result *out_result)
{
    ob_result r = OB_ERR_INVALID_ARGUMENT;
    ob_node *root = NULL;
    const char *path = desc && desc->path ? desc->path : NULL;
    if (!s || !path) {
        OB_LOG_E(LOG_MODULE, "ob_stack_add_model: %s", !s ? "no stack" : "no model path");
        goto done;
    }
    const ob_stack_model_desc *d = desc;
    double sum = d->position[0] + d->position[1] + d->position[2] + d->rotation[0] + d->rotation[1] +
                 d->rotation[2] + d->rotation[3] + d->scale[0] + d->scale[1] + d->scale[2];
    if (!isfinite(sum)) {
        OB_LOG_E(LOG_MODULE, "model '%s' not added: its position, rotation or scale is not finite", path);
        goto done;
    }
    ob_model_assets *assets = NULL;
    if ((r = model_assets(s, d, &assets)) != OB_OK) goto fail_log;
    if (!(root = ob_node_create(s->scene, d->parent, d->name ? d->name : file_name(path), &r)))
        goto fail_log;
    ob_node_set_position(root, d->position);
    if (!all_zero(d->rotation, sizeof d->rotation)) ob_node_set_rotation_d(root, d->rotation);
    if (!all_zero(d->scale, sizeof d->scale)) ob_node_set_scale(root, d->scale);
    if ((r = ob_model_assets_instantiate(assets, s->scene, root, d->material, NULL)) != OB_OK)
        goto fail_destroy_root;
    goto done;

fail_destroy_root:
    ob_node_destroy(root);
    root = NULL;
fail_log:
    OB_LOG_E(LOG_MODULE, "model '%s' not added (%s: %s); the stack renders without it", path,
             ob_result_name(r), ob_result_text(r));
done:
    if (out_result) *out_result = r;
    return root;
}

/* ------------------------------------------------------------ sun, camera */

ob_node *ob_stack_add_sun(ob_stack *s, const double direction[3], ob_result *out_result)
{
    const double *dir = direction ? direction : ob_sun_direction;
    double len2 = dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2];
    ob_result r = OB_ERR_INVALID_ARGUMENT;
    ob_node *n = NULL;
    if (!s || !(len2 > 0.0) || !isfinite(len2)) {
        OB_LOG_E(LOG_MODULE, "ob_stack_add_sun: %s", !s ? "no stack"
                 : "the direction must be finite and not zero");
        goto done;
    }
    /* Unit length: ob_light_aim picks its up vector by the y component. */
    double len = sqrt(len2), unit[3] = {dir[0] / len, dir[1] / len, dir[2] / len};
    if (!(n = ob_node_create(s->scene, NULL, "sun", &r))) goto done;
    if ((r = ob_node_set_light(n, &ob_sun_light)) != OB_OK || (r = ob_light_aim(n, unit)) != OB_OK) {
        ob_node_destroy(n);
        n = NULL;
    }
done:
    if (out_result) *out_result = r;
    return n;
}

ob_result ob_stack_fit_camera(ob_stack *s, const ob_node *node)
{
    const char *what = node ? ob_node_name(node) : "the scene";
    double lo[3], hi[3], center[3], radius;
    ob_result r = ob_framing_measure(s->scene, node, lo, hi, center, &radius);
    if (r == OB_OK && !(hi[0] >= lo[0])) r = OB_ERR_NOT_FOUND;
    else if (r == OB_OK && !isfinite(radius + center[0] + center[1] + center[2])) r = OB_ERR_NON_FINITE;
    ob_image_info info = {0};
    if (r == OB_OK && (r = ob_image_get_info(s->device, ob_stack_final_image(s), &info)) == OB_OK)
        r = ob_framing_aim_camera(s->camera, center, radius, (double)info.width / (double)info.height);
    if (r != OB_OK)
        OB_LOG_E(LOG_MODULE, "the camera was not fitted to '%s': %s (%s: %s)", what,
                 r == OB_ERR_NOT_FOUND ? "nothing renderable there"
                 : r == OB_ERR_NON_FINITE ? "its bounds are not finite" : "a step failed",
                 ob_result_name(r), ob_result_text(r));
    return r;
}

/* ------------------------------------------------------------ scene files */

ob_result ob_stack_load_scene(ob_stack *s, const char *path, const ob_scene_loaded **out_loaded,
                              ob_scene_file_error *out_error)
{
    ob_scene_file_error local;
    ob_scene_file_error *err = out_error ? out_error : &local;
    memset(err, 0, sizeof *err);
    if (out_loaded) *out_loaded = NULL;
    struct ob_stack_content *c = NULL;
    ob_scene_loaded *l = NULL;
    ob_result r = OB_ERR_INVALID_ARGUMENT;
    if (!s || !path) {
        snprintf(err->message, sizeof err->message, "ob_stack_load_scene: no %s", !s ? "stack" : "path");
        goto fail_log;
    }
    if ((r = content_of(s, &c)) != OB_OK ||
        (r = ob_array_reserve((void **)&c->scenes, &c->scene_cap, c->scene_count + 1,
                              sizeof *c->scenes)) != OB_OK)
        goto fail_no_memory;
    if (!(l = ob_calloc(1, sizeof *l))) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_no_memory;
    }
    if ((r = ob_scene_load_stack(s, &(ob_scene_load_desc){.path = path}, l, err)) != OB_OK) {
        ob_free(l);
        goto fail_log;
    }
    c->scenes[c->scene_count++] = l;
    if (out_loaded) *out_loaded = l;
    return OB_OK;

fail_no_memory:
    snprintf(err->message, sizeof err->message, "%s: no memory to keep the load", path);
fail_log:
    OB_LOG_E(LOG_MODULE, "scene file not loaded: %s", err->message);
    return r;
}

/* ------------------------------------------------------------ teardown */

void ob_stack_content_unload_scenes(ob_stack *s)
{
    struct ob_stack_content *c = s->content;
    if (!c) return;
    for (uint32_t i = c->scene_count; i-- > 0;) {   /* later loads may hang under earlier ones */
        ob_scene_unload(c->scenes[i]);
        ob_free(c->scenes[i]);
    }
    ob_free(c->scenes);
    c->scenes = NULL;
    c->scene_count = c->scene_cap = 0;
}

void ob_stack_content_destroy(ob_stack *s)
{
    struct ob_stack_content *c = s->content;
    if (!c) return;
    ob_stack_content_unload_scenes(s);
    for (uint32_t i = c->model_count; i-- > 0;) {
        ob_model_assets_destroy(c->models[i].assets);
        ob_free(c->models[i].path);
    }
    ob_texture_cache_destroy(c->textures);   /* after the materials sampling its textures */
    ob_free(c->models);
    ob_free(c);
    s->content = NULL;
}
