#include "ob_material_internal.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

/* What a material draws with in one view: a standard variant or a custom effect. */
typedef struct effect_choice {
    ob_effect *custom;
    ob_std_effect kind;
    uint32_t variant;
    bool standard;
} effect_choice;

/* ------------------------------------------------------- standard effects */

static const uint32_t allowed_variants[OB_STD_EFFECT_COUNT] = {
    [OB_STD_LIT] = OB_VARIANT_SHADOWS | OB_VARIANT_ENVMAP | OB_VARIANT_BLENDED |
                   OB_VARIANT_INSTANCED | OB_VARIANT_LOCAL_SHADOWS,
    [OB_STD_DEPTH] = OB_VARIANT_INSTANCED,
    [OB_STD_PARABOLOID] = OB_VARIANT_BLENDED | OB_VARIANT_INSTANCED,
    [OB_STD_UNLIT] = OB_VARIANT_BLENDED | OB_VARIANT_INSTANCED,
};

static const char *const std_names[OB_STD_EFFECT_COUNT] = {
    "lit", "depth", "paraboloid", "unlit", "overlay", "fullscreen", "particles-sim",
    "particles-draw",
};

static void variant_name(ob_std_effect kind, uint32_t variant, char *out, size_t cap)
{
    snprintf(out, cap, "%s%s%s%s%s%s", std_names[kind],
             variant & OB_VARIANT_SHADOWS ? "+SHADOWS" : "",
             variant & OB_VARIANT_LOCAL_SHADOWS ? "+LOCAL_SHADOWS" : "",
             variant & OB_VARIANT_ENVMAP ? "+ENVMAP" : "",
             variant & OB_VARIANT_BLENDED ? "+BLENDED" : "",
             variant & OB_VARIANT_INSTANCED ? "+INSTANCED" : "");
}

/* Defines a standard variant can have: LIT's INSTANCED, SHADOWS, ENVMAP,
 * BLENDED and LOCAL_SHADOWS at most, with room to spare. */
#define STD_MAX_DEFINES 8

/* Fills desc (and its defines) for a standard variant. */
static void std_desc(const ob_material_library *lib, ob_std_effect kind, uint32_t variant,
                     ob_effect_desc *desc, ob_shader_define defines[STD_MAX_DEFINES])
{
    bool blended = variant & OB_VARIANT_BLENDED;
    uint32_t n = 0;
    if (variant & OB_VARIANT_INSTANCED) defines[n++] = (ob_shader_define){"INSTANCED", "1"};
    *desc = (ob_effect_desc){
        .layout = &lib->standard_layout,
        .depth_test = true,
        .depth_write = !blended,
        .cull = VK_CULL_MODE_BACK_BIT,
        .blend = blended,
    };
    switch (kind) {
    case OB_STD_LIT:
        /* The metallic-roughness model with no texture: LIT and REFLECTIVE
         * (ob_material_lit.c), in the standard layout (pbr.vert then reads
         * only position, normal and uv). */
        desc->vertex = "pbr.vert";
        desc->fragment = "pbr.frag";
        if (variant & OB_VARIANT_SHADOWS) defines[n++] = (ob_shader_define){"SHADOWS", "1"};
        if (variant & OB_VARIANT_ENVMAP) defines[n++] = (ob_shader_define){"ENVMAP", "1"};
        if (blended) defines[n++] = (ob_shader_define){"BLENDED", "1"};
        if (variant & OB_VARIANT_LOCAL_SHADOWS)
            defines[n++] = (ob_shader_define){"LOCAL_SHADOWS", "1"};
        break;
    case OB_STD_DEPTH:
        desc->vertex = "depth.vert";
        desc->depth_bias_constant = lib->bias_constant;
        desc->depth_bias_slope = lib->bias_slope;
        break;
    case OB_STD_PARABOLOID:
        /* The paraboloid mirrors the back hemisphere: winding means nothing. */
        desc->vertex = "pbr.vert";
        desc->fragment = "pbr.frag";
        desc->cull = 0;
        defines[n++] = (ob_shader_define){"PARABOLOID", "1"};
        if (blended) defines[n++] = (ob_shader_define){"BLENDED", "1"};
        break;
    case OB_STD_UNLIT:
        desc->vertex = "unlit.vert";
        desc->fragment = "unlit.frag";
        break;
    case OB_STD_OVERLAY:
        desc->vertex = "unlit.vert";
        desc->fragment = "unlit.frag";
        desc->layout = &lib->text_layout;
        desc->depth_test = desc->depth_write = false;
        desc->cull = 0;
        desc->blend = true;
        defines[n++] = (ob_shader_define){"SCREEN_SPACE", "1"};
        defines[n++] = (ob_shader_define){"VERTEX_COLOR", "1"};
        break;
    case OB_STD_FULLSCREEN:
        desc->vertex = "fullscreen.vert";
        desc->fragment = "fullscreen.frag";
        desc->layout = NULL;
        desc->depth_test = desc->depth_write = false;
        desc->cull = 0;
        break;
    case OB_STD_PARTICLES_SIM:
        *desc = (ob_effect_desc){.compute = "particles.comp"};
        break;
    case OB_STD_PARTICLES_DRAW:
        desc->vertex = "particles.vert";
        desc->fragment = "particles.frag";
        desc->layout = NULL;
        desc->depth_write = false;
        desc->cull = 0;
        desc->blend = true;
        break;
    case OB_STD_EFFECT_COUNT:
        break;
    }
    desc->define_count = n;
    desc->defines = n ? defines : NULL;
}

ob_effect *ob_material_library_find_effect(const ob_material_library *lib, ob_std_effect kind,
                                           uint32_t variant)
{
    if (!lib || (unsigned)kind >= OB_STD_EFFECT_COUNT) return NULL;
    variant &= allowed_variants[kind];
    return atomic_load_explicit(&lib->slots[kind][variant].effect, memory_order_acquire);
}

ob_effect *ob_material_library_effect(ob_material_library *lib, ob_std_effect kind,
                                      uint32_t variant, ob_result *out_result)
{
    if (!lib || (unsigned)kind >= OB_STD_EFFECT_COUNT) {
        OB_LOG_E("material", "no standard effect %d", (int)kind);
        if (out_result) *out_result = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    variant &= allowed_variants[kind];
    std_slot *slot = &lib->slots[kind][variant];
    ob_effect *e = atomic_load_explicit(&slot->effect, memory_order_acquire);
    ob_result r = slot->failure;
    if (!e && r == OB_OK) {
        char name[64];
        ob_effect_desc desc;
        ob_shader_define defines[STD_MAX_DEFINES];
        variant_name(kind, variant, name, sizeof name);
        std_desc(lib, kind, variant, &desc, defines);
        desc.name = name;
        e = ob_effect_create(lib->ctx, &desc, &r);
        if (e) atomic_store_explicit(&slot->effect, e, memory_order_release);
        /* Memory may come back; a broken shader or device limit will not. */
        else if (r != OB_ERR_OUT_OF_HOST_MEMORY && r != OB_ERR_OUT_OF_DEVICE_MEMORY) slot->failure = r;
    }
    if (out_result) *out_result = e ? OB_OK : r;
    return e;
}

void ob_material_library_set_instancing(ob_material_library *lib, bool on)
{
    if (lib) lib->instancing = on;
}

bool ob_material_library_instancing(const ob_material_library *lib)
{
    return lib && lib->instancing;
}

/* ---------------------------------------------------------------- library */

static const ob_effect_vertex_input builtin_standard_layout = {
    .stride = 32,
    .attribute_count = 3,
    .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, VK_FORMAT_R32G32_SFLOAT, 24}},
};

static const ob_effect_vertex_input builtin_extended_layout = {
    .stride = 52,
    .attribute_count = 5,
    .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, VK_FORMAT_R32G32_SFLOAT, 24},
                   {3, VK_FORMAT_R8G8B8A8_UNORM, 32},
                   {4, VK_FORMAT_R32G32B32A32_SFLOAT, 36}},
};

/* The extended layout plus TEXCOORD1 (geometry's ob_vertex_layout_extended_uv1):
 * PBR variants whose textures read the second uv set. */
static const ob_effect_vertex_input builtin_extended_uv1_layout = {
    .stride = 60,
    .attribute_count = 6,
    .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                   {1, VK_FORMAT_R32G32B32_SFLOAT, 12},
                   {2, VK_FORMAT_R32G32_SFLOAT, 24},
                   {3, VK_FORMAT_R8G8B8A8_UNORM, 32},
                   {4, VK_FORMAT_R32G32B32A32_SFLOAT, 36},
                   {5, VK_FORMAT_R32G32_SFLOAT, 52}},
};

static const ob_effect_vertex_input builtin_text_layout = {
    .stride = 16,
    .attribute_count = 2,
    .attributes = {{0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {3, VK_FORMAT_R8G8B8A8_UNORM, 12}},
};

static ob_param register_param(ob_param_registry *reg, const char *name, ob_param_type type,
                               ob_result *out_result)
{
    ob_param p = ob_param_register(reg, name, type, 1, out_result);
    if (!p.id)
        OB_LOG_E("material", "parameter '%s' (%s) not registered: %s", name,
                 ob_param_type_name(type), ob_result_text(*out_result));
    return p;
}

/* The standard shaders' whole parameter interface (materials/shaders),
 * registered up front so views and applications can look every name up
 * before the first variant is compiled. Programs map members to these. */
static ob_result register_standard_params(ob_material_library *lib)
{
    static const struct {
        const char *name;
        ob_param_type type;
    } params[] = {
        {"CameraPosition", OB_PARAM_VEC4},      {"ScreenSize", OB_PARAM_VEC4},
        {"AmbientColor", OB_PARAM_VEC4},        {"LightDirection", OB_PARAM_VEC4},
        {"LightColor", OB_PARAM_VEC4},          {"LightGrid", OB_PARAM_VEC4},
        {"ParaboloidDirection", OB_PARAM_VEC4},
        {"SimStep", OB_PARAM_VEC4},             {"SimEmitter", OB_PARAM_VEC4},
        {"SimForce", OB_PARAM_VEC4},            {"ShadowSplits", OB_PARAM_VEC4},
        {"ShadowCascades", OB_PARAM_VEC4},      {"ShadowAxis", OB_PARAM_VEC4},
        {"EnvMapMatrix", OB_PARAM_MAT4},        {"ShadowMap", OB_PARAM_TEXTURE},
        {"EnvMap", OB_PARAM_TEXTURE},           {"SourceImage", OB_PARAM_TEXTURE},
        {"Particles", OB_PARAM_STORAGE_BUFFER},
    };
    ob_result r = OB_OK;
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(params); i++)
        if (!register_param(lib->reg, params[i].name, params[i].type, &r).id) return r;
    /* The shadow cascades' matrices (OB_SHADOW_MAX_CASCADES in views/ob_views.h,
     * the array in materials/shaders/common.glsl). */
    if (!ob_param_register(lib->reg, "ShadowMatrices", OB_PARAM_MAT4_ARRAY, 4, &r).id) {
        OB_LOG_E("material", "parameter 'ShadowMatrices' (mat4[4]) not registered: %s",
                 ob_result_text(r));
        return r;
    }
    static const struct {
        const char *name;
        uint32_t bytes;
    } blocks[] = {{"LightTable", OB_LIGHT_TABLE_BYTES}, {"LightTiles", OB_LIGHT_TILES_BYTES}};
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(blocks); i++) {
        if (!ob_param_register(lib->reg, blocks[i].name, OB_PARAM_BYTES, blocks[i].bytes, &r).id) {
            OB_LOG_E("material", "parameter '%s' (%u bytes) not registered: %s", blocks[i].name,
                     blocks[i].bytes, ob_result_text(r));
            return r;
        }
    }
    lib->diffuse = register_param(lib->reg, "DiffuseColor", OB_PARAM_VEC4, &r);
    if (lib->diffuse.id) lib->specular = register_param(lib->reg, "SpecularColor", OB_PARAM_VEC4, &r);
    if (lib->specular.id) lib->emissive = register_param(lib->reg, "EmissiveColor", OB_PARAM_VEC4, &r);
    if (lib->emissive.id)
        lib->reflectivity = register_param(lib->reg, "Reflectivity", OB_PARAM_VEC4, &r);
    return lib->reflectivity.id ? OB_OK : r;
}

/* Default samplers of the standard shaders, in every slot: a view or the
 * application may set its own. */
static ob_result create_samplers(ob_material_library *lib)
{
    static const struct {
        const char *param;
        bool compare;
    } specs[SAMPLER_COUNT] = {
        [SAMPLER_SHADOW] = {"ShadowMapSampler", true},
        [SAMPLER_ENV] = {"EnvMapSampler", false},
        [SAMPLER_SOURCE] = {"SourceImageSampler", false},
    };
    for (uint32_t i = 0; i < SAMPLER_COUNT; i++) {
        ob_result r;
        ob_sampler_desc sd = {
            .filter = VK_FILTER_LINEAR,
            .address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
            .compare = specs[i].compare,
            .compare_op = VK_COMPARE_OP_GREATER_OR_EQUAL,   /* reversed-Z: nearer is greater */
            .name = specs[i].param,
        };
        if (i == SAMPLER_ENV) {
            /* Env maps have mips, sampled by roughness (envmap.glsl). */
            sd.detailed = true;
            sd.mag_filter = sd.min_filter = VK_FILTER_LINEAR;
            sd.mipmap_mode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
            sd.address_u = sd.address_v = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
            sd.max_lod = VK_LOD_CLAMP_NONE;
        }
        lib->samplers[i] = ob_sampler_create(lib->dev, &sd, &r);
        if (!lib->samplers[i].id) {
            OB_LOG_E("material", "default sampler '%s' not created: %s", specs[i].param,
                     ob_result_text(r));
            return r;
        }
        ob_param p = register_param(lib->reg, specs[i].param, OB_PARAM_SAMPLER, &r);
        if (!p.id) return r;
        r = ob_params_init_sampler(lib->reg, p, lib->samplers[i]);
        if (r != OB_OK) return r;
    }
    return OB_OK;
}

ob_material_library *ob_material_library_create(ob_effect_context *ctx,
                                                const ob_material_library_desc *desc,
                                                ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_material_library_desc d = desc ? *desc : (ob_material_library_desc){0};
    ob_material_library *lib = NULL;
    if (!ctx) {
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    if ((d.standard_layout && d.standard_layout->attribute_count > OB_EFFECT_MAX_ATTRIBUTES) ||
        (d.text_layout && d.text_layout->attribute_count > OB_EFFECT_MAX_ATTRIBUTES) ||
        (d.extended_layout && d.extended_layout->attribute_count > OB_EFFECT_MAX_ATTRIBUTES)) {
        OB_LOG_E("material", "material library: a vertex layout has more than %u attributes",
                 OB_EFFECT_MAX_ATTRIBUTES);
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    lib = ob_calloc(1, sizeof *lib);
    if (!lib) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    lib->ctx = ctx;
    lib->instancing = true;
    lib->dev = ob_effect_context_device(ctx);
    lib->reg = ob_effect_context_registry(ctx);
    lib->standard_layout = d.standard_layout ? *d.standard_layout : builtin_standard_layout;
    lib->text_layout = d.text_layout ? *d.text_layout : builtin_text_layout;
    lib->extended_layout = d.extended_layout ? *d.extended_layout : builtin_extended_layout;
    lib->extended_uv1_layout = builtin_extended_uv1_layout;
    lib->bias_constant = d.shadow_bias_constant != 0.0f ? d.shadow_bias_constant : -1.0f;
    lib->bias_slope = d.shadow_bias_slope != 0.0f ? d.shadow_bias_slope : -1.75f;

    /* Every shader of the standard effects, read now: their effects are
     * made on first use, in a frame, where a missing file could only be
     * logged (issue 25.8). */
    static const char *const standard_shaders[] = {
        "pbr.vert", "pbr.frag", "depth.vert", "unlit.vert", "unlit.frag", "fullscreen.vert",
        "fullscreen.frag", "particles.comp", "particles.vert", "particles.frag"};
    r = ob_effect_context_check_shaders(ctx, "material library", standard_shaders,
                                        OB_ARRAY_COUNT(standard_shaders));
    if (r != OB_OK) goto fail_destroy_library;
    r = register_standard_params(lib);
    if (r == OB_OK) r = ob_pbr_register_params(lib);
    if (r == OB_OK) r = create_samplers(lib);
    if (r != OB_OK) goto fail_destroy_library;
    if (out_result) *out_result = OB_OK;
    return lib;

fail_destroy_library:
    ob_material_library_destroy(lib);
fail_log:
    OB_LOG_E("material", "material library not created: %s", ob_result_name(r));
    if (out_result) *out_result = r;
    return NULL;
}

void ob_material_library_destroy(ob_material_library *lib)
{
    if (!lib) return;
    while (lib->material_count) ob_material_destroy(lib->materials[lib->material_count - 1]);
    ob_free(lib->materials);
    for (uint32_t k = 0; k < OB_STD_EFFECT_COUNT; k++)
        for (uint32_t v = 0; v < VARIANT_COUNT; v++) ob_effect_destroy(lib->slots[k][v].effect);
    ob_pbr_library_release(lib);
    for (uint32_t i = 0; i < SAMPLER_COUNT; i++)
        if (lib->samplers[i].id) ob_sampler_destroy(lib->dev, lib->samplers[i]);
    ob_free(lib);
}

void ob_material_library_set_queue_hook(ob_material_library *lib, ob_material_queue_fn fn,
                                        void *user)
{
    lib->queue_fn = fn;
    lib->queue_user = user;
}

ob_effect_context *ob_material_library_context(const ob_material_library *lib)
{
    return lib ? lib->ctx : NULL;
}

/* --------------------------------------------------------------- materials */

static bool all_finite(const float *v, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

static void set_render_flags(ob_material *m)
{
    memset(m->render, 0, sizeof m->render);
    switch (m->kind) {
    case OB_MATERIAL_LIT:
    case OB_MATERIAL_REFLECTIVE:
        m->render[OB_VIEW_PERSPECTIVE] = true;
        m->render[OB_VIEW_PARABOLOID] = true;
        m->render[OB_VIEW_CUBE] = true;
        m->render[OB_VIEW_SHADOW] = m->casts_shadows;
        break;
    case OB_MATERIAL_PBR:
        m->render[OB_VIEW_PERSPECTIVE] = true;
        m->render[OB_VIEW_PARABOLOID] = true;
        m->render[OB_VIEW_CUBE] = true;
        m->render[OB_VIEW_SHADOW] = m->casts_shadows;
        break;
    case OB_MATERIAL_UNLIT:
        m->render[OB_VIEW_PERSPECTIVE] = true;
        m->render[OB_VIEW_OVERLAY] = true;
        m->render[OB_VIEW_SHADOW] = m->casts_shadows;
        break;
    case OB_MATERIAL_CUSTOM:
    case OB_MATERIAL_KIND_COUNT:
        break;
    }
}

ob_material *ob_material_create(ob_material_library *lib, const ob_material_desc *desc,
                                ob_result *out_result)
{
    ob_result r = OB_OK;
    const char *name = desc && desc->name ? desc->name : "material";
    ob_material *m = NULL;
    if (!lib || !desc || (unsigned)desc->kind >= OB_MATERIAL_KIND_COUNT) {
        OB_LOG_E("material", "material '%s': bad library, desc or kind", name);
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    if (!all_finite(desc->diffuse, 4) || !all_finite(desc->specular, 4) ||
        !all_finite(desc->emissive, 4) || !isfinite(desc->reflectivity) || !isfinite(desc->roughness) ||
        !isfinite(desc->metallic)) {
        OB_LOG_E("material", "material '%s': non-finite colour or reflectivity", name);
        r = OB_ERR_NON_FINITE;
        goto fail_log;
    }
    r = ob_array_reserve((void **)&lib->materials, &lib->material_cap, lib->material_count + 1,
                         sizeof *lib->materials);
    if (r != OB_OK) goto fail_log;
    m = ob_calloc(1, sizeof *m);
    if (!m) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    m->lib = lib;
    snprintf(m->name, sizeof m->name, "%s", name);
    m->kind = desc->kind;
    ob_lit_defaults(desc, m->diffuse, m->specular);
    memcpy(m->emissive, desc->emissive, sizeof m->emissive);
    m->reflectivity[0] = desc->kind == OB_MATERIAL_PBR         ? OB_MAX(desc->reflectivity, 0.0f)
                         : desc->kind != OB_MATERIAL_REFLECTIVE ? 0.0f
                         : desc->reflectivity != 0.0f          ? desc->reflectivity
                                                               : 0.6f;
    m->metallic = desc->metallic;
    m->roughness = desc->roughness;
    m->metallic_roughness = desc->metallic_roughness;
    ob_lit_refresh(m);
    m->casts_shadows = desc->casts_shadows;
    m->blended = desc->blended;
    if (desc->kind == OB_MATERIAL_PBR) {
        r = ob_pbr_material_init(m, desc);
        if (r != OB_OK) {
            ob_free(m);
            goto fail_log;
        }
        m->blended = desc->pbr.alpha_mode == OB_ALPHA_BLEND;
    }
    m->priority = desc->priority;
    m->id = lib->next_id++;
    set_render_flags(m);
    lib->materials[lib->material_count++] = m;
    if (out_result) *out_result = OB_OK;
    return m;

fail_log:
    OB_LOG_E("material", "material '%s' not created: %s", name, ob_result_name(r));
    if (out_result) *out_result = r;
    return NULL;
}

void ob_material_destroy(ob_material *m)
{
    if (!m) return;
    ob_material_library *lib = m->lib;
    for (uint32_t i = 0; i < lib->material_count; i++) {
        if (lib->materials[i] != m) continue;
        lib->materials[i] = lib->materials[--lib->material_count];
        break;
    }
    ob_free(m);
}

const char *ob_material_name(const ob_material *m) { return m ? m->name : ""; }
ob_material_kind ob_material_get_kind(const ob_material *m) { return m->kind; }

static bool renders(const ob_material *m, ob_view_type type)
{
    return m && (unsigned)type < OB_VIEW_TYPE_COUNT && m->render[type];
}

ob_result ob_material_set_view_effect(ob_material *m, ob_view_type type, ob_effect *effect)
{
    if (!m || (unsigned)type >= OB_VIEW_TYPE_COUNT) return OB_ERR_INVALID_ARGUMENT;
    m->custom[type] = effect;
    if (effect) m->render[type] = true;
    else if (m->kind == OB_MATERIAL_CUSTOM) m->render[type] = false;
    else {
        /* Back to the kind's standard behaviour for every type, then the
         * other overrides again. */
        set_render_flags(m);
        for (uint32_t t = 0; t < OB_VIEW_TYPE_COUNT; t++)
            if (m->custom[t]) m->render[t] = true;
    }
    return OB_OK;
}

static ob_result set_color(ob_material *m, float dest[4], const float v[4])
{
    if (!m || !v) return OB_ERR_INVALID_ARGUMENT;
    if (!all_finite(v, 4)) {
        OB_LOG_E("material", "material '%s': non-finite colour refused", m->name);
        return OB_ERR_NON_FINITE;
    }
    memcpy(dest, v, 4 * sizeof *v);
    ob_lit_refresh(m);
    return OB_OK;
}

ob_result ob_material_set_diffuse(ob_material *m, const float rgba[4])
{
    return set_color(m, m ? m->diffuse : NULL, rgba);
}
ob_result ob_material_set_specular(ob_material *m, const float rgb_power[4])
{
    return set_color(m, m ? m->specular : NULL, rgb_power);
}
ob_result ob_material_set_emissive(ob_material *m, const float rgb[4])
{
    return set_color(m, m ? m->emissive : NULL, rgb);
}
ob_result ob_material_set_reflectivity(ob_material *m, float reflectivity)
{
    float v[4] = {reflectivity, 0, 0, 0};
    return set_color(m, m ? m->reflectivity : NULL, v);
}

/* ---------------------------------------------------------- view effects */

bool ob_material_view_depends_on(const ob_view *v, ob_view_type type)
{
    for (uint32_t i = 0; i < v->dep_count; i++)
        if (v->deps[i] && v->deps[i]->type == type) return true;
    return false;
}

void ob_material_view_shadows(const ob_view *v, bool *out_directional, bool *out_local)
{
    *out_directional = *out_local = false;
    for (uint32_t i = 0; i < v->dep_count; i++) {
        if (!v->deps[i] || v->deps[i]->type != OB_VIEW_SHADOW) continue;
        if (v->deps[i]->local_shadow) *out_local = true;
        else *out_directional = true;
    }
}

ob_view *ob_material_attached_env_map(const ob_renderer *r, const ob_node *entity)
{
    if (!r || !entity) return NULL;
    ob_view *env = ob_renderer_attached_view(r, entity, OB_VIEW_PARABOLOID);
    return env ? env : ob_renderer_attached_view(r, entity, OB_VIEW_CUBE);
}

/* The effect a material wants in view v; false when it is not drawn there. */
static bool choose(const ob_material *m, const ob_renderer *r, const ob_node *entity,
                   const ob_view *v, effect_choice *out)
{
    *out = (effect_choice){0};
    if (!renders(m, v->type)) return false;
    if (m->custom[v->type]) {
        out->custom = m->custom[v->type];
        return true;
    }
    uint32_t blended = m->blended ? OB_VARIANT_BLENDED : 0u;
    out->standard = true;
    uint32_t instanced = m->lib->instancing ? OB_VARIANT_INSTANCED : 0u;
    switch (v->type) {
    case OB_VIEW_PERSPECTIVE:
        if (m->kind == OB_MATERIAL_UNLIT) {
            out->kind = OB_STD_UNLIT;
            out->variant = blended | instanced;
            return true;
        }
        out->kind = OB_STD_LIT;
        out->variant = blended | instanced;
        bool directional, local;
        ob_material_view_shadows(v, &directional, &local);
        if (directional) out->variant |= OB_VARIANT_SHADOWS;
        if (local) out->variant |= OB_VARIANT_LOCAL_SHADOWS;
        if (m->kind == OB_MATERIAL_REFLECTIVE && ob_material_attached_env_map(r, entity))
            out->variant |= OB_VARIANT_ENVMAP;
        return true;
    case OB_VIEW_SHADOW:
        out->kind = OB_STD_DEPTH;
        out->variant = instanced;
        return true;
    case OB_VIEW_PARABOLOID:
        out->kind = OB_STD_PARABOLOID;
        out->variant = blended | instanced;
        return true;
    case OB_VIEW_CUBE:
        /* A cube face is a plain 90-degree camera: no shadows, and no
         * reflections (as in a paraboloid map) — it depends on no other map. */
        out->kind = m->kind == OB_MATERIAL_UNLIT ? OB_STD_UNLIT : OB_STD_LIT;
        out->variant = blended | instanced;
        return true;
    case OB_VIEW_OVERLAY:
        out->kind = OB_STD_OVERLAY;
        return true;
    default:
        return false;
    }
}

/* Without creating: the wanted variant, else the closest existing one that
 * needs fewer inputs (no shadow map, no env map). *io_variant is updated. */
static ob_effect *find_with_fallback(const ob_material_library *lib, ob_std_effect kind,
                                     uint32_t *io_variant)
{
    /* Every subset of the three inputs, fewest dropped first. */
    enum { S = OB_VARIANT_SHADOWS, E = OB_VARIANT_ENVMAP, L = OB_VARIANT_LOCAL_SHADOWS };
    static const uint32_t drop[] = {0u, L, S, E, S | L, L | E, S | E, S | E | L};
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(drop); i++) {
        if (i && (*io_variant & drop[i]) != drop[i]) continue;
        uint32_t variant = *io_variant & ~drop[i];
        ob_effect *e = ob_material_library_find_effect(lib, kind, variant);
        if (e) {
            *io_variant = variant;
            return e;
        }
    }
    return NULL;
}

static ob_effect *resolve(ob_material *m, ob_renderer *r, const ob_node *entity,
                          const ob_view *v, bool create, uint32_t *out_variant,
                          ob_result *out_result)
{
    effect_choice c;
    *out_variant = 0;
    if (out_result) *out_result = OB_OK;
    if (v && m->kind == OB_MATERIAL_PBR && renders(m, v->type) && !m->custom[v->type]) {
        bool env = false;
        ob_effect *e = ob_pbr_resolve(m, r, entity, v, create, &env, out_result);
        *out_variant = env ? OB_VARIANT_ENVMAP : 0u;
        return e;
    }
    if (!v || !choose(m, r, entity, v, &c)) {
        if (out_result) *out_result = OB_ERR_NOT_FOUND;
        return NULL;
    }
    if (c.custom) return c.custom;
    ob_effect *e = NULL;
    if (create) {
        e = ob_material_library_effect(m->lib, c.kind, c.variant, out_result);
        /* A broken variant must not hide the surface: fall back like apply. */
        if (!e) e = find_with_fallback(m->lib, c.kind, &c.variant);
    } else {
        e = find_with_fallback(m->lib, c.kind, &c.variant);
        if (!e && out_result) *out_result = OB_ERR_NOT_FOUND;
    }
    *out_variant = c.variant;
    return e;
}

ob_effect *ob_material_get_view_effect(ob_material *m, ob_renderer *r, const ob_node *entity,
                                   const ob_view *v, bool create, ob_result *out_result)
{
    uint32_t variant;
    return m ? resolve(m, r, entity, v, create, &variant, out_result) : NULL;
}

ob_material_view_params ob_material_get_view_params(const ob_material *m, ob_view_type type)
{
    ob_material_view_params p = {0};
    if (!renders(m, type)) return p;
    p.render = true;
    ob_view probe;
    memset(&probe, 0, sizeof probe);
    probe.type = type;
    if (m->kind == OB_MATERIAL_PBR && !m->custom[type]) {
        bool env;
        p.effect = ob_pbr_resolve((ob_material *)m, NULL, NULL, &probe, false, &env, NULL);
        return p;
    }
    effect_choice c;
    if (choose(m, NULL, NULL, &probe, &c))
        p.effect = c.custom ? c.custom : ob_material_library_find_effect(m->lib, c.kind, c.variant);
    return p;
}

/* What pipelines drawing in v are made for (formats and sample count). */
static ob_effect_targets view_targets(ob_device *dev, const ob_view *v)
{
    ob_effect_targets t = {.wireframe = v->wireframe};
    ob_view_attachment_formats(v, dev, &t.color, &t.depth, &t.samples);
    return t;
}

/* A material that cannot draw as asked in v this frame (its effect variant
 * failed, maybe drawn with a simpler one, or its pipeline failed, its draws
 * skipped) goes into the frame's errors as "material:<name>": the cause is
 * logged where it happened, and the frame goes on. */
static void note_failure(const ob_material *m, ob_renderer *r, ob_result res)
{
    char name[64];
    snprintf(name, sizeof name, "material:%s", m->name);
    ob_renderer_note_error(r, name, res);
}

static void prepare(ob_material *m, ob_renderer *r, ob_node *entity, const ob_view *v,
                    const ob_effect_targets *targets)
{
    uint32_t variant;
    ob_result res = OB_OK;
    ob_effect *e = resolve(m, r, entity, v, true, &variant, &res);
    /* NOT_FOUND: the material does not draw in v (or its custom effect
     * is unset): nothing failed. */
    if (res != OB_OK && res != OB_ERR_NOT_FOUND) note_failure(m, r, res);
    if (e && !ob_effect_pipeline_for(e, targets, NULL)) note_failure(m, r, OB_ERR_VULKAN);
}

typedef struct prepare_ctx {
    ob_material_library *lib;
    ob_renderer *r;
    ob_effect_targets targets;
} prepare_ctx;

static void prepare_item(void *user, ob_view *v, const ob_view_material_item *e)
{
    const prepare_ctx *c = user;
    if (!e->material || e->material->lib != c->lib) return;
    prepare(e->material, c->r, e->node, v, &c->targets);
}

void ob_material_library_prepare_view(ob_material_library *lib, ob_renderer *r, ob_view *v)
{
    if (!lib || !v) return;
    /* Once per material, per entity only where the entity decides the
     * effect (its own env map). */
    prepare_ctx c = {lib, r, view_targets(lib->dev, v)};
    ob_view_for_each_material_item(v, prepare_item, &c);
}

/* ------------------------------------------------------ engine interface */

static bool iface_renders(const struct ob_material *m, ob_view_type type)
{
    return renders(m, type);
}

static void iface_sort_info(const struct ob_material *m, ob_view_type type,
                            uint32_t *out_class, uint32_t *out_priority, uint32_t *out_state)
{
    /* Overlay elements blend over each other: back to front, then priority. */
    *out_class = m->blended || type == OB_VIEW_OVERLAY ? 1u : 0u;
    *out_priority = m->priority;
    *out_state = m->id;
}

/* A reflective surface in a camera asks for its own entity's env map, and
 * its effect variant depends on whether that map renders. */
static bool wants_env_map(const ob_material *m, ob_view_type type)
{
    bool reflective = m->kind == OB_MATERIAL_REFLECTIVE ||
                      (m->kind == OB_MATERIAL_PBR && m->reflectivity[0] > 0.0f);
    return reflective && !m->custom[type] && type == OB_VIEW_PERSPECTIVE;
}

static bool iface_pre_render_per_entity(const struct ob_material *m, ob_view_type type)
{
    return renders(m, type) && wants_env_map(m, type);
}

static void iface_pre_render(struct ob_material *m, ob_node *entity, ob_renderer *r, ob_view *v)
{
    if (!renders(m, v->type)) return;
    ob_material_library *lib = m->lib;
    if (wants_env_map(m, v->type) && lib->queue_fn)
        lib->queue_fn(lib->queue_user, entity, r, v, OB_VIEW_PARABOLOID);
    ob_effect_targets targets = view_targets(lib->dev, v);
    prepare(m, r, entity, v, &targets);
}

static ob_apply_result iface_apply(struct ob_material *m, ob_node *entity, ob_renderer *r,
                                   ob_pipeline_manager *pm, const ob_view *v)
{
    uint32_t variant;
    ob_effect *e = resolve(m, r, entity, v, false, &variant, NULL);
    if (!e) {
        if (renders(m, v->type) && !atomic_exchange(&m->warned, true))
            OB_LOG_W("material", "material '%s': no effect prepared for %s view '%s'; its "
                     "draws are skipped (was PreRender run for this view?)", m->name,
                     ob_view_type_name(v->type), v->name);
        return OB_APPLY_SKIP;
    }
    ob_effect_targets targets = view_targets(m->lib->dev, v);
    uint32_t pipeline_id;
    VkPipeline pipeline = ob_effect_pipeline_for(e, &targets, &pipeline_id);
    if (!pipeline) return OB_APPLY_SKIP;
    ob_pipeline_manager_set_pipeline(pm, pipeline, pipeline_id, ob_effect_program(e));

    ob_params *params = ob_pipeline_manager_params(pm);
    if (m->kind == OB_MATERIAL_PBR && !m->custom[v->type])
        return ob_pbr_set_params(m, entity, r, params, v, variant & OB_VARIANT_ENVMAP);
    const ob_material_library *lib = m->lib;
    if ((m->kind == OB_MATERIAL_LIT || m->kind == OB_MATERIAL_REFLECTIVE) && !m->custom[v->type]) {
        /* The mirror share is in the mapped F0: the map at full strength.
         * (An effect of the application's own gets the description as
         * given, in PerMaterial, below.) */
        const float env[4] = {m->kind == OB_MATERIAL_REFLECTIVE ? 1.0f : 0.0f, 0, 0, 0};
        ob_pbr_set_factors(m, params, env);
    } else {
        ob_params_set_vec4(params, lib->diffuse, m->diffuse);
        ob_params_set_vec4(params, lib->specular, m->specular);
        ob_params_set_vec4(params, lib->emissive, m->emissive);
        ob_params_set_vec4(params, lib->reflectivity, m->reflectivity);
    }
    if (variant & OB_VARIANT_ENVMAP) {
        /* Each reflective entity samples its own map: bind it per draw. */
        ob_view *env = ob_material_attached_env_map(r, entity);
        if (env && env->vtbl && env->vtbl->set_usage_params)
            env->vtbl->set_usage_params(env, r, params, v);
    }
    /* Only a reflective surface in a perspective view depends on the entity
     * (its own env map decides the variant and is bound per draw). */
    bool per_entity = m->kind == OB_MATERIAL_REFLECTIVE && v->type == OB_VIEW_PERSPECTIVE &&
                      !m->custom[v->type];
    return per_entity ? OB_APPLY_ENTITY : OB_APPLY_MATERIAL;
}

static const ob_material_iface material_iface = {
    .renders = iface_renders,
    .sort_info = iface_sort_info,
    .pre_render = iface_pre_render,
    .pre_render_per_entity = iface_pre_render_per_entity,
    .apply = iface_apply,
};

const ob_material_iface *ob_material_iface_get(void) { return &material_iface; }
