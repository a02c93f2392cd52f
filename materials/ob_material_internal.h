/* ob_material_internal.h — INTERNAL to materials/ob_material*.c (not API):
 * the library and material records shared by the standard kinds
 * (ob_material.c) and the PBR kind (ob_material_pbr.c).
 *
 * Thread rule as in ob_material.h: records change on the render thread
 * outside recording; effect pointers read while recording are atomics
 * published once created.
 */
#ifndef OB_MATERIAL_INTERNAL_H
#define OB_MATERIAL_INTERNAL_H

#include <stdatomic.h>

#include "ob_material.h"
#include "ob_renderer_layer.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

#define VARIANT_COUNT 16u  /* every combination of the ob_std_variant bits */

typedef struct std_slot {
    _Atomic(ob_effect *) effect;   /* published once created; read while recording */
    ob_result failure;             /* OB_OK until a creation failed (not retried) */
} std_slot;

enum { SAMPLER_SHADOW, SAMPLER_ENV, SAMPLER_SOURCE, SAMPLER_COUNT };

/* PBR texture slots, in ob_material_pbr's order. */
enum { OB_PBR_TEX_BASE, OB_PBR_TEX_MR, OB_PBR_TEX_NORMAL, OB_PBR_TEX_OCCLUSION, OB_PBR_TEX_EMISSIVE,
       OB_PBR_TEX_CC, OB_PBR_TEX_CC_ROUGH, OB_PBR_TEX_CC_NORMAL, OB_PBR_TEX_COUNT };

/* PbrUvTransforms: two vec4 per texture slot, (a, b, tx, uv set) and
 * (c, d, ty, 0), packed as this many mat4 (pbr.frag indexes it as vec4s). */
#define OB_PBR_UV_MATRICES ((2u * OB_PBR_TEX_COUNT + 3u) / 4u)

/* One compiled PBR shader variant, shared by every material with its key. */
typedef struct ob_pbr_variant {
    uint32_t key;                  /* OB_PBR_* feature and pass bits */
    ob_effect *effect;
    ob_result failure;             /* OB_OK until a creation failed (not retried) */
} ob_pbr_variant;

typedef struct ob_pbr_params {
    ob_param base_color, factors, emissive, clearcoat, uv_transforms;
    ob_param textures[OB_PBR_TEX_COUNT], samplers[OB_PBR_TEX_COUNT];
} ob_pbr_params;

struct ob_material_library {
    ob_effect_context *ctx;
    ob_device *dev;
    ob_param_registry *reg;
    ob_effect_vertex_input standard_layout, text_layout, extended_layout, extended_uv1_layout;
    float bias_constant, bias_slope;
    bool instancing;               /* standard effects draw the INSTANCED variant */
    std_slot slots[OB_STD_EFFECT_COUNT][VARIANT_COUNT];
    ob_material_queue_fn queue_fn;
    void *queue_user;
    ob_param diffuse, specular, emissive, reflectivity;
    ob_sampler samplers[SAMPLER_COUNT];
    ob_material **materials;
    uint32_t material_count, material_cap;
    uint32_t next_id;
    ob_pbr_params pbr;
    ob_pbr_variant **pbr_variants; /* render thread only; materials keep their own pointers */
    uint32_t pbr_variant_count, pbr_variant_cap;
};

/* Per-material effect slots of a PBR material: the main pass by its
 * +SHADOWS (1) and +ENVMAP (2) bits, then the paraboloid and shadow passes. */
enum { OB_PBR_PASS_MAIN = 0, OB_PBR_PASS_PARABOLOID = 4, OB_PBR_PASS_DEPTH = 5, OB_PBR_PASS_COUNT = 6 };

typedef struct ob_material_pbr_state {
    ob_material_pbr desc;
    uint32_t features;             /* OB_PBR_F_* bits the material uses */
    float block[4][4];             /* PbrBaseColor, PbrFactors, PbrEmissive, PbrClearcoat */
    float uv[16u * OB_PBR_UV_MATRICES];   /* PbrUvTransforms: 8 floats (two vec4 rows) per slot */
    _Atomic(ob_effect *) effects[OB_PBR_PASS_COUNT];
} ob_material_pbr_state;

struct ob_material {
    ob_material_library *lib;
    char name[48];
    ob_material_kind kind;
    /* As given (desc, setters). LIT and REFLECTIVE draw with pbr.block,
     * mapped from these by ob_lit_refresh; reflectivity.x: the REFLECTIVE
     * mix, or PBR's environment scale. */
    float diffuse[4], specular[4], emissive[4], reflectivity[4];
    float metallic, roughness;     /* LIT, REFLECTIVE: desc's (ob_lit_refresh reads them) */
    bool metallic_roughness;
    bool casts_shadows, blended;
    uint32_t priority;
    uint32_t id;                   /* creation order in its library: groups draws */
    bool render[OB_VIEW_TYPE_COUNT];
    ob_effect *custom[OB_VIEW_TYPE_COUNT];
    atomic_bool warned;            /* a skipped draw is logged once */
    /* kind == OB_MATERIAL_PBR: all of it; LIT and REFLECTIVE: block[0..2]
     * (their parameter set of the same model, ob_lit_refresh). */
    ob_material_pbr_state pbr;
};

/* ob_material.c helpers the PBR kind shares. */
bool ob_material_view_depends_on(const ob_view *v, ob_view_type type);
ob_view *ob_material_attached_env_map(const ob_renderer *r, const ob_node *entity);

/* ob_material_lit.c */
/* desc's diffuse and specular with zero meaning default (white; 0.25 grey,
 * power 32), as every kind but PBR keeps them. */
void ob_lit_defaults(const ob_material_desc *desc, float diffuse[4], float specular[4]);
/* Maps m's LIT or REFLECTIVE parameters (diffuse, specular, emissive,
 * reflectivity, metallic/roughness) to the metallic-roughness factors in
 * m->pbr.block[0..2]; after creation and after each setter. */
void ob_lit_refresh(ob_material *m);

/* ob_material_pbr.c */
/* Registers PbrBaseColor, PbrFactors, PbrEmissive, PbrClearcoat,
 * PbrUvTransforms and the eight texture and sampler parameters. */
ob_result ob_pbr_register_params(ob_material_library *lib);
/* Destroys the PBR variants and their table. */
void ob_pbr_library_release(ob_material_library *lib);
/* Checks desc->pbr and fills m->pbr (logs naming the material). */
ob_result ob_pbr_material_init(ob_material *m, const ob_material_desc *desc);
/* The effect m draws with in v (create: compile what is missing [render
 * thread]; else find, falling back to fewer inputs like the standard kinds).
 * *out_env says whether it is the ENVMAP variant. */
ob_effect *ob_pbr_resolve(ob_material *m, ob_renderer *r, const ob_node *entity, const ob_view *v, bool create,
                          bool *out_env, ob_result *out_result);
/* The PbrMaterial factors of m->pbr.block[0..2] and Reflectivity = env
 * (the environment term's scale), the rest of PerMaterial zeroed: what
 * every metallic-roughness draw sets (PBR, LIT and REFLECTIVE). */
void ob_pbr_set_factors(const ob_material *m, ob_params *params, const float env[4]);
/* apply's PBR part, after the shared code set the pipeline: the material's
 * factors and textures, and with `env` the entity's environment map. */
ob_apply_result ob_pbr_set_params(ob_material *m, ob_node *entity, ob_renderer *r, ob_params *params,
                                  const ob_view *v, bool env);

#pragma GCC visibility pop

#endif /* OB_MATERIAL_INTERNAL_H */
