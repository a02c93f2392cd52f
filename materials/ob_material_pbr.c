/* ob_material_pbr.c — the glTF 2 metallic-roughness material kind: its
 * parameters, its shader variants (one per set of used features, shared by
 * every material with the same set) and its apply.
 *
 * Variant keys are OB_PBR_F_* feature bits (what the material uses) plus
 * pass bits (shadowed, env-mapped, paraboloid, depth). The library keeps
 * one ob_pbr_variant per key (render thread); each material keeps atomic
 * pointers to the variants it draws with, set in PreRender, so recording
 * never searches the table.
 */
#include "ob_material_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

enum {
    OB_PBR_F_BASE = 1u << 0,
    OB_PBR_F_MR = 1u << 1,
    OB_PBR_F_NORMAL = 1u << 2,
    OB_PBR_F_OCCLUSION = 1u << 3,
    OB_PBR_F_EMISSIVE = 1u << 4,
    OB_PBR_F_MASK = 1u << 5,
    OB_PBR_F_VERTEX_COLOR = 1u << 6,
    OB_PBR_F_DOUBLE_SIDED = 1u << 7,
    OB_PBR_F_BLENDED = 1u << 8,
    OB_PBR_F_UV_TRANSFORM = 1u << 9,   /* a texture has a KHR_texture_transform */
    OB_PBR_F_TEXCOORD1 = 1u << 10,     /* a texture reads TEXCOORD1 (the uv1 vertex layout) */
    OB_PBR_F_CLEARCOAT = 1u << 11,
    OB_PBR_F_CC_TEX = 1u << 12,
    OB_PBR_F_CC_ROUGH_TEX = 1u << 13,
    OB_PBR_F_CC_NORMAL_TEX = 1u << 14,
    OB_PBR_FEATURES = (1u << 15) - 1u,
    OB_PBR_P_SHADOWS = 1u << 15,
    OB_PBR_P_ENVMAP = 1u << 16,
    OB_PBR_P_PARABOLOID = 1u << 17,
    OB_PBR_P_DEPTH = 1u << 18,
    OB_PBR_P_INSTANCED = 1u << 19,  /* the per-draw block per instance */
};

/* Define, short name token, and what a report calls the feature. */
static const struct {
    uint32_t bit;
    const char *define, *token, *feature;
} pbr_bits[] = {
    {OB_PBR_F_BASE, "HAS_BASE_COLOR_TEXTURE", "base", "base colour texture"},
    {OB_PBR_F_MR, "HAS_METALLIC_ROUGHNESS_TEXTURE", "mr", "metallic-roughness texture"},
    {OB_PBR_F_NORMAL, "HAS_NORMAL_TEXTURE", "nrm", "normal texture"},
    {OB_PBR_F_OCCLUSION, "HAS_OCCLUSION_TEXTURE", "occ", "occlusion texture"},
    {OB_PBR_F_EMISSIVE, "HAS_EMISSIVE_TEXTURE", "emi", "emissive texture"},
    {OB_PBR_F_MASK, "ALPHA_MASK", "mask", "alpha mask"},
    {OB_PBR_F_VERTEX_COLOR, "VERTEX_COLOR", "vc", "vertex colours"},
    {OB_PBR_F_DOUBLE_SIDED, "DOUBLE_SIDED", "2s", "double-sided lighting"},
    {OB_PBR_F_BLENDED, "BLENDED", "blend", "alpha blending"},
    {OB_PBR_F_UV_TRANSFORM, "HAS_UV_TRANSFORM", "uvx", "texture transforms"},
    {OB_PBR_F_TEXCOORD1, "HAS_TEXCOORD1", "uv1", "second uv set"},
    {OB_PBR_F_CLEARCOAT, "HAS_CLEARCOAT", "cc", "clearcoat"},
    {OB_PBR_F_CC_TEX, "HAS_CLEARCOAT_TEXTURE", "cct", "clearcoat texture"},
    {OB_PBR_F_CC_ROUGH_TEX, "HAS_CLEARCOAT_ROUGHNESS_TEXTURE", "ccr", "clearcoat roughness texture"},
    {OB_PBR_F_CC_NORMAL_TEX, "HAS_CLEARCOAT_NORMAL_TEXTURE", "ccn", "clearcoat normal texture"},
    {OB_PBR_P_SHADOWS, "SHADOWS", "sh", NULL},
    {OB_PBR_P_ENVMAP, "ENVMAP", "env", NULL},
    {OB_PBR_P_PARABOLOID, "PARABOLOID", "para", NULL},
    {OB_PBR_P_DEPTH, "DEPTH_ONLY", "depth", NULL},
    {OB_PBR_P_INSTANCED, "INSTANCED", "inst", NULL},
};
#define PBR_MAX_DEFINES 20

static const char *const texture_names[OB_PBR_TEX_COUNT] = {
    "BaseColorTexture", "MetallicRoughnessTexture", "NormalTexture", "OcclusionTexture", "EmissiveTexture",
    "ClearcoatTexture", "ClearcoatRoughnessTexture", "ClearcoatNormalTexture",
};
static const uint32_t texture_bits[OB_PBR_TEX_COUNT] = {
    OB_PBR_F_BASE, OB_PBR_F_MR, OB_PBR_F_NORMAL, OB_PBR_F_OCCLUSION, OB_PBR_F_EMISSIVE,
    OB_PBR_F_CC_TEX, OB_PBR_F_CC_ROUGH_TEX, OB_PBR_F_CC_NORMAL_TEX,
};

/* The texture slots of a PBR description, in OB_PBR_TEX_* order. */
static void texture_slots(const ob_material_pbr *p, const ob_material_texture *out[OB_PBR_TEX_COUNT])
{
    out[OB_PBR_TEX_BASE] = &p->base_color_texture;
    out[OB_PBR_TEX_MR] = &p->metallic_roughness_texture;
    out[OB_PBR_TEX_NORMAL] = &p->normal_texture;
    out[OB_PBR_TEX_OCCLUSION] = &p->occlusion_texture;
    out[OB_PBR_TEX_EMISSIVE] = &p->emissive_texture;
    out[OB_PBR_TEX_CC] = &p->clearcoat_texture;
    out[OB_PBR_TEX_CC_ROUGH] = &p->clearcoat_roughness_texture;
    out[OB_PBR_TEX_CC_NORMAL] = &p->clearcoat_normal_texture;
}

ob_material_pbr ob_material_pbr_defaults(void)
{
    return (ob_material_pbr){
        .base_color = {1, 1, 1, 1},
        .metallic = 1.0f,
        .roughness = 1.0f,
        .normal_scale = 1.0f,
        .occlusion_strength = 1.0f,
        .alpha_mode = OB_ALPHA_OPAQUE,
        .alpha_cutoff = 0.5f,
        .clearcoat_normal_scale = 1.0f,
    };
}

/* --------------------------------------------------------------- library */

ob_result ob_pbr_register_params(ob_material_library *lib)
{
    ob_result r = OB_OK;
    ob_pbr_params *p = &lib->pbr;
    const struct { ob_param *out; const char *name; ob_param_type type; } list[] = {
        {&p->base_color, "PbrBaseColor", OB_PARAM_VEC4},
        {&p->factors, "PbrFactors", OB_PARAM_VEC4},
        {&p->emissive, "PbrEmissive", OB_PARAM_VEC4},
        {&p->clearcoat, "PbrClearcoat", OB_PARAM_VEC4},
        {&p->uv_transforms, "PbrUvTransforms", OB_PARAM_MAT4_ARRAY},
    };
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(list); i++) {
        const uint32_t count = list[i].type == OB_PARAM_MAT4_ARRAY ? OB_PBR_UV_MATRICES : 1u;
        *list[i].out = ob_param_register(lib->reg, list[i].name, list[i].type, count, &r);
        if (!list[i].out->id) goto fail_log;
    }
    for (uint32_t i = 0; i < OB_PBR_TEX_COUNT; i++) {
        char name[64];
        p->textures[i] = ob_param_register(lib->reg, texture_names[i], OB_PARAM_TEXTURE, 1, &r);
        if (!p->textures[i].id) goto fail_log;
        snprintf(name, sizeof name, "%sSampler", texture_names[i]);
        p->samplers[i] = ob_param_register(lib->reg, name, OB_PARAM_SAMPLER, 1, &r);
        if (!p->samplers[i].id) goto fail_log;
    }
    return OB_OK;
fail_log:
    OB_LOG_E("material", "PBR parameters not registered: %s", ob_result_text(r));
    return r;
}

void ob_pbr_library_release(ob_material_library *lib)
{
    for (uint32_t i = 0; i < lib->pbr_variant_count; i++) {
        ob_effect_destroy(lib->pbr_variants[i]->effect);
        ob_free(lib->pbr_variants[i]);
    }
    ob_free(lib->pbr_variants);
    lib->pbr_variants = NULL;
    lib->pbr_variant_count = lib->pbr_variant_cap = 0;
}

static void variant_name(uint32_t key, char *out, size_t cap)
{
    size_t n = (size_t)snprintf(out, cap, "pbr");
    bool first = true;
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(pbr_bits) && n < cap; i++) {
        if (!(key & pbr_bits[i].bit)) continue;
        n += (size_t)snprintf(out + n, cap - n, "%s%s", first ? ":" : "+", pbr_bits[i].token);
        first = false;
    }
}

static void variant_desc(const ob_material_library *lib, uint32_t key, ob_effect_desc *desc,
                         ob_shader_define defines[PBR_MAX_DEFINES])
{
    const bool depth = key & OB_PBR_P_DEPTH, mask = key & OB_PBR_F_MASK;
    const bool blended = key & OB_PBR_F_BLENDED;
    uint32_t n = 0;
    *desc = (ob_effect_desc){
        .layout = (key & OB_PBR_F_TEXCOORD1) ? &lib->extended_uv1_layout : &lib->extended_layout,
        .depth_test = true,
        .depth_write = depth || !blended,
        .cull = (key & (OB_PBR_F_DOUBLE_SIDED | OB_PBR_P_PARABOLOID)) ? 0 : VK_CULL_MODE_BACK_BIT,
        .blend = !depth && blended,
        .vertex = "pbr.vert",
        .fragment = "pbr.frag",
    };
    if (depth) {
        desc->depth_bias_constant = lib->bias_constant;
        desc->depth_bias_slope = lib->bias_slope;
        if (!mask) {
            /* Nothing to cut out: the plain depth stage reads only the position. */
            desc->vertex = "depth.vert";
            desc->fragment = NULL;
            if (key & OB_PBR_P_INSTANCED) {
                defines[0] = (ob_shader_define){"INSTANCED", "1"};
                desc->define_count = 1;
                desc->defines = defines;
            }
            return;
        }
    }
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(pbr_bits); i++)
        if (key & pbr_bits[i].bit && pbr_bits[i].bit != OB_PBR_F_DOUBLE_SIDED)
            defines[n++] = (ob_shader_define){pbr_bits[i].define, "1"};
    /* DOUBLE_SIDED changes the shading only where facing means something. */
    if ((key & OB_PBR_F_DOUBLE_SIDED) && !depth && !(key & OB_PBR_P_PARABOLOID))
        defines[n++] = (ob_shader_define){"DOUBLE_SIDED", "1"};
    desc->define_count = n;
    desc->defines = n ? defines : NULL;
}

uint32_t ob_material_pbr_left_out(const ob_material *m, char *out, size_t cap)
{
    if (out && cap) out[0] = '\0';
    if (!m || m->kind != OB_MATERIAL_PBR) return 0;
    uint32_t count = 0;
    size_t n = 0;
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(pbr_bits); i++) {
        if (!pbr_bits[i].feature || (m->pbr.features & pbr_bits[i].bit)) continue;
        /* Without a coat its textures are implied: "clearcoat" says it. */
        if ((pbr_bits[i].bit & (OB_PBR_F_CC_TEX | OB_PBR_F_CC_ROUGH_TEX | OB_PBR_F_CC_NORMAL_TEX)) &&
            !(m->pbr.features & OB_PBR_F_CLEARCOAT))
            continue;
        if (out && n < cap)
            n += (size_t)snprintf(out + n, cap - n, "%s%s", count ? ", " : "", pbr_bits[i].feature);
        count++;
    }
    /* What the material asked for and cannot have, with the reason. */
    const ob_material_texture *slots[OB_PBR_TEX_COUNT];
    texture_slots(&m->pbr.desc, slots);
    for (uint32_t i = 0; i < OB_PBR_TEX_COUNT; i++) {
        if (!slots[i]->texture || slots[i]->uv_set <= 1) continue;
        if (out && n < cap)
            n += (size_t)snprintf(out + n, cap - n, "%s%s uv set %u (only TEXCOORD_0 and _1 are drawn)",
                                  count ? ", " : "", texture_names[i], slots[i]->uv_set);
        count++;
    }
    return count;
}

bool ob_material_reads_texcoord1(const ob_material *m)
{
    return m && m->kind == OB_MATERIAL_PBR && (m->pbr.features & OB_PBR_F_TEXCOORD1);
}

/* The library's variant for key, compiled on first request. */
static ob_effect *variant_get(ob_material_library *lib, const ob_material *m, uint32_t key, ob_result *out_result)
{
    ob_pbr_variant *var = NULL;
    for (uint32_t i = 0; i < lib->pbr_variant_count && !var; i++)
        if (lib->pbr_variants[i]->key == key) var = lib->pbr_variants[i];
    if (!var) {
        ob_result r = ob_array_reserve((void **)&lib->pbr_variants, &lib->pbr_variant_cap,
                                       lib->pbr_variant_count + 1, sizeof *lib->pbr_variants);
        var = r == OB_OK ? ob_calloc(1, sizeof *var) : NULL;
        if (!var) {
            OB_LOG_E("material", "material '%s': no memory for a PBR variant", m->name);
            *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
            return NULL;
        }
        var->key = key;
        lib->pbr_variants[lib->pbr_variant_count++] = var;
    }
    if (var->effect || var->failure != OB_OK) {
        *out_result = var->effect ? OB_OK : var->failure;
        return var->effect;
    }
    char name[64];
    ob_effect_desc desc;
    ob_shader_define defines[PBR_MAX_DEFINES];
    variant_name(key, name, sizeof name);
    variant_desc(lib, key, &desc, defines);
    desc.name = name;
    ob_result r;
    var->effect = ob_effect_create(lib->ctx, &desc, &r);
    if (!var->effect) {
        /* Memory may come back; a broken shader or device limit will not. */
        if (r != OB_ERR_OUT_OF_HOST_MEMORY && r != OB_ERR_OUT_OF_DEVICE_MEMORY) var->failure = r;
    } else {
        char left[256];
        if (ob_material_pbr_left_out(m, left, sizeof left))
            OB_LOG_I("material", "PBR variant '%s' (first for material '%s') compiled without: %s", name, m->name,
                     left);
    }
    *out_result = var->effect ? OB_OK : r;
    return var->effect;
}

/* -------------------------------------------------------------- material */

static bool finite_n(const float *v, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

ob_result ob_pbr_material_init(ob_material *m, const ob_material_desc *desc)
{
    const ob_material_pbr *p = &desc->pbr;
    if (!finite_n(p->base_color, 4) || !finite_n(p->emissive, 3) || !isfinite(p->metallic) ||
        !isfinite(p->roughness) || !isfinite(p->normal_scale) || !isfinite(p->occlusion_strength) ||
        !isfinite(p->alpha_cutoff)) {
        OB_LOG_E("material", "material '%s': non-finite PBR factor", m->name);
        return OB_ERR_NON_FINITE;
    }
    if ((unsigned)p->alpha_mode > OB_ALPHA_BLEND) {
        OB_LOG_E("material", "material '%s': alpha mode %d is not OPAQUE, MASK or BLEND", m->name,
                 (int)p->alpha_mode);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (!isfinite(p->clearcoat) || !isfinite(p->clearcoat_roughness) || !isfinite(p->clearcoat_normal_scale)) {
        OB_LOG_E("material", "material '%s': non-finite clearcoat factor", m->name);
        return OB_ERR_NON_FINITE;
    }
    ob_material_pbr_state *s = &m->pbr;
    s->desc = *p;
    const ob_material_texture *slots[OB_PBR_TEX_COUNT];
    texture_slots(p, slots);
    s->features = 0;
    const bool coat = p->clearcoat > 0.0f;
    if (coat) s->features |= OB_PBR_F_CLEARCOAT;
    /* Unused rows stay the identity on set 0. */
    memset(s->uv, 0, sizeof s->uv);
    for (uint32_t i = 0; i < OB_PBR_TEX_COUNT; i++) {
        float *row = s->uv + 8u * i;
        row[0] = 1.0f;
        row[5] = 1.0f;
    }
    for (uint32_t i = 0; i < OB_PBR_TEX_COUNT; i++) {
        if (!slots[i]->texture) continue;
        if (i >= OB_PBR_TEX_CC && !coat) continue;   /* no layer, nothing to texture */
        s->features |= texture_bits[i];
        float *row = s->uv + 8u * i;   /* two vec4: (a, b, tx, set), (c, d, ty, 0) */
        if (slots[i]->has_transform) {
            if (!finite_n(slots[i]->transform, 6)) {
                OB_LOG_E("material", "material '%s': %s has a non-finite uv transform", m->name, texture_names[i]);
                return OB_ERR_NON_FINITE;
            }
            const float *t = slots[i]->transform;
            row[0] = t[0], row[1] = t[1], row[2] = t[2];
            row[4] = t[3], row[5] = t[4], row[6] = t[5];
            s->features |= OB_PBR_F_UV_TRANSFORM;
        }
        if (slots[i]->uv_set == 1) {
            row[3] = 1.0f;
            s->features |= OB_PBR_F_TEXCOORD1;
        } else if (slots[i]->uv_set > 1) {
            OB_LOG_W("material", "material '%s': %s reads uv set %u; only sets 0 and 1 (TEXCOORD_0, _1) are "
                                 "drawn, so it uses set 0", m->name, texture_names[i], slots[i]->uv_set);
        }
    }
    if (p->alpha_mode == OB_ALPHA_MASK) s->features |= OB_PBR_F_MASK;
    if (p->alpha_mode == OB_ALPHA_BLEND) s->features |= OB_PBR_F_BLENDED;
    if (p->vertex_colors) s->features |= OB_PBR_F_VERTEX_COLOR;
    if (p->double_sided) s->features |= OB_PBR_F_DOUBLE_SIDED;
    memcpy(s->block[0], p->base_color, sizeof s->block[0]);
    s->block[1][0] = p->metallic;
    s->block[1][1] = p->roughness;
    s->block[1][2] = p->normal_scale;
    s->block[1][3] = p->occlusion_strength;
    memcpy(s->block[2], p->emissive, 3 * sizeof(float));
    s->block[2][3] = p->alpha_cutoff;
    s->block[3][0] = p->clearcoat < 1.0f ? p->clearcoat : 1.0f;
    s->block[3][1] = p->clearcoat_roughness < 0.0f ? 0.0f : p->clearcoat_roughness > 1.0f ? 1.0f : p->clearcoat_roughness;
    s->block[3][2] = p->clearcoat_normal_scale;
    s->block[3][3] = 0.0f;
    for (uint32_t i = 0; i < OB_PBR_PASS_COUNT; i++) atomic_init(&s->effects[i], NULL);
    return OB_OK;
}

/* The per-material slot and the variant key for view v. */
static bool pass_of(const ob_material *m, const ob_renderer *r, const ob_node *entity, const ob_view *v,
                    uint32_t *out_slot, uint32_t *out_key)
{
    const uint32_t f = m->pbr.features;
    const uint32_t inst = m->lib->instancing ? OB_PBR_P_INSTANCED : 0u;
    switch (v->type) {
    case OB_VIEW_PERSPECTIVE: {
        uint32_t slot = OB_PBR_PASS_MAIN, key = f | inst;
        if (ob_material_view_depends_on(v, OB_VIEW_SHADOW)) {
            slot |= 1u;
            key |= OB_PBR_P_SHADOWS;
        }
        if (m->reflectivity[0] > 0.0f && ob_material_attached_env_map(r, entity)) {
            slot |= 2u;
            key |= OB_PBR_P_ENVMAP;
        }
        *out_slot = slot;
        *out_key = key;
        return true;
    }
    case OB_VIEW_CUBE:
        /* A cube face draws like a camera without shadows or reflections. */
        *out_slot = OB_PBR_PASS_MAIN;
        *out_key = f | inst;
        return true;
    case OB_VIEW_PARABOLOID:
        *out_slot = OB_PBR_PASS_PARABOLOID;
        *out_key = OB_PBR_P_PARABOLOID | inst | (f & ~OB_PBR_F_DOUBLE_SIDED);
        return true;
    case OB_VIEW_SHADOW:
        *out_slot = OB_PBR_PASS_DEPTH;
        /* Only a cut-out changes what casts a shadow; TEXCOORD1 changes the
         * vertex layout every pass must read. */
        *out_key = OB_PBR_P_DEPTH | inst | (f & (OB_PBR_F_DOUBLE_SIDED | OB_PBR_F_TEXCOORD1)) |
                   ((f & OB_PBR_F_MASK) ? f & (OB_PBR_F_MASK | OB_PBR_F_BASE | OB_PBR_F_VERTEX_COLOR |
                                               OB_PBR_F_UV_TRANSFORM)
                                        : 0u);
        return true;
    default:
        return false;
    }
}

ob_effect *ob_pbr_resolve(ob_material *m, ob_renderer *r, const ob_node *entity, const ob_view *v, bool create,
                          bool *out_env, ob_result *out_result)
{
    uint32_t slot, key;
    *out_env = false;
    if (!pass_of(m, r, entity, v, &slot, &key)) {
        if (out_result) *out_result = OB_ERR_NOT_FOUND;
        return NULL;
    }
    ob_result res = OB_OK;
    ob_effect *e = NULL;
    if (create) {
        e = variant_get(m->lib, m, key, &res);
        if (e) atomic_store_explicit(&m->pbr.effects[slot], e, memory_order_release);
    }
    if (!e) {
        /* The wanted one, else the closest existing one needing fewer inputs
         * (no shadow map, no env map), as the standard kinds fall back. */
        static const uint32_t drop[] = {0u, 1u, 2u, 3u};
        for (uint32_t i = 0; i < OB_ARRAY_COUNT(drop) && !e; i++) {
            if (i && (slot >= OB_PBR_PASS_PARABOLOID || !(slot & drop[i]))) continue;
            uint32_t s = slot & ~drop[i];
            e = atomic_load_explicit(&m->pbr.effects[s], memory_order_acquire);
            if (e) slot = s;
        }
        if (!e && res == OB_OK) res = OB_ERR_NOT_FOUND;
    }
    *out_env = e && slot < OB_PBR_PASS_PARABOLOID && (slot & 2u);
    /* A fallback drawn in place of a variant that failed still reports the
     * failure, as the standard kinds do (resolve in ob_material.c). */
    if (out_result) *out_result = res;
    return e;
}

void ob_pbr_set_factors(const ob_material *m, ob_params *params, const float env[4])
{
    const ob_material_library *lib = m->lib;
    const ob_pbr_params *p = &lib->pbr;
    ob_params_set_vec4(params, p->base_color, m->pbr.block[0]);
    ob_params_set_vec4(params, p->factors, m->pbr.block[1]);
    ob_params_set_vec4(params, p->emissive, m->pbr.block[2]);
    ob_params_set_vec4(params, lib->reflectivity, env);
    /* The rest of the shared PerMaterial block (pbr.frag declares it through
     * common.glsl but reads only Reflectivity) gets a defined value too: its
     * packed bytes, and so the command hashes, must not carry the last unlit
     * material this slot applied, which differs between ST and MT. */
    static const float unused[4] = {0, 0, 0, 0};
    ob_params_set_vec4(params, lib->diffuse, unused);
    ob_params_set_vec4(params, lib->specular, unused);
    ob_params_set_vec4(params, lib->emissive, unused);
}

ob_apply_result ob_pbr_set_params(ob_material *m, ob_node *entity, ob_renderer *r, ob_params *params,
                                  const ob_view *v, bool env)
{
    const ob_material_library *lib = m->lib;
    const ob_pbr_params *p = &lib->pbr;
    ob_pbr_set_factors(m, params, m->reflectivity);
    /* Only variants that declare these read them: others set nothing new. */
    if (m->pbr.features & OB_PBR_F_CLEARCOAT) ob_params_set_vec4(params, p->clearcoat, m->pbr.block[3]);
    if (m->pbr.features & (OB_PBR_F_UV_TRANSFORM | OB_PBR_F_TEXCOORD1))
        ob_params_set_mat4_array(params, p->uv_transforms, m->pbr.uv, OB_PBR_UV_MATRICES);
    const ob_material_texture *slots[OB_PBR_TEX_COUNT];
    texture_slots(&m->pbr.desc, slots);
    for (uint32_t i = 0; i < OB_PBR_TEX_COUNT; i++) {
        if (!(m->pbr.features & texture_bits[i])) continue;
        ob_params_set_texture(params, p->textures[i], ob_texture_image(slots[i]->texture));
        ob_params_set_sampler(params, p->samplers[i], ob_texture_sampler(slots[i]->texture));
    }
    if (env) {
        /* Each reflective entity samples its own map: bind it per draw. */
        ob_view *map = ob_material_attached_env_map(r, entity);
        if (map && map->vtbl && map->vtbl->set_usage_params) map->vtbl->set_usage_params(map, r, params, v);
        return OB_APPLY_ENTITY;
    }
    return OB_APPLY_MATERIAL;
}
