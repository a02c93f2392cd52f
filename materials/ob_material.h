/* ob_material.h — materials and the library of standard effects
 * (Hieroglyph 3's MaterialDX11 with Params[VT_NUM_VIEW_TYPES]).
 *
 * A material says, per view type, whether an entity using it is drawn there
 * and with which effect, plus its own parameters, which it writes into the
 * recording manager's slot when applied.
 *
 * One lighting model: LIT, REFLECTIVE and PBR are all drawn by the glTF 2
 * metallic-roughness model of pbr.frag (docs/materials.md). LIT and
 * REFLECTIVE keep their Blinn-Phong-style description (diffuse, specular
 * colour and power, emissive, reflectivity, roughness) and are mapped to
 * that model's base colour, metallic and roughness (the PbrMaterial block;
 * ob_material_desc_to_pbr says what a description becomes), or take
 * metallic and roughness as given (metallic_roughness). UNLIT is not lit. The engine reaches materials only
 * through ob_material_iface (engine/ob_renderer.h), which
 * ob_material_iface_get() implements.
 *
 * Standard kinds and the effect used per view type:
 *   LIT         perspective: lit (pbr.vert + pbr.frag with no texture, the
 *               standard vertex layout; +SHADOWS when the view depends on a
 *               shadow view this frame); shadow: depth-only when casts_shadows;
 *               paraboloid: paraboloid generation (the same shading).
 *   REFLECTIVE  perspective: lit + ENVMAP (paraboloid lookup) when the entity
 *               has an environment-map view attached this frame
 *               (ob_renderer_attached_view), plain lit otherwise;
 *               paraboloid: generation (the view excludes the owner);
 *               shadow: depth-only when casts_shadows. Its pre_render asks the
 *               queue hook for the entity's PARABOLOID view.
 *   UNLIT       perspective: unlit (DiffuseColor); overlay: screen-space
 *               unlit with vertex colours, alpha blended, no depth (text);
 *               shadow: depth-only when casts_shadows.
 *   CUSTOM      only the effects given with ob_material_set_view_effect.
 *   PBR         glTF 2 metallic-roughness (ob_material_pbr; docs/materials.md):
 *               perspective: pbr.vert + pbr.frag with the defines of the
 *               features the material uses (+SHADOWS, +ENVMAP as LIT and
 *               REFLECTIVE); paraboloid: the same with PARABOLOID; shadow
 *               (casts_shadows): depth only, the ALPHA_MASK cut-out included.
 *               Extended vertex layout. Alpha BLEND draws in the blended
 *               class (back to front, no depth write). With reflectivity > 0
 *               it asks for an environment map like REFLECTIVE, and
 *               reflectivity scales that map's specular term (1 = as lit).
 * A view type with no effect is not drawn (renders() is false, so culling
 * counts the entity as culled).
 *
 * Lazy creation: an effect variant is compiled the first time a material
 * needs it for a view (pre_render or ob_material_library_prepare_view on the
 * render thread), and its pipeline for the view's target formats is created
 * then too, so recording normally finds both cached. If recording needs a
 * variant that does not exist yet (a shadow view queued after the entity's
 * PreRender), it falls back to the variant without SHADOWS / ENVMAP when that
 * one exists; otherwise the draw is skipped and logged once per material.
 *
 * Standard shader parameters the library sets up: it registers the material
 * parameters and gives "ShadowMapSampler" (depth compare GREATER_OR_EQUAL,
 * linear, clamp), "EnvMapSampler" and "SourceImageSampler" (linear, clamp) a
 * default in every slot. Views provide the rest: per-view matrices and
 * lights (materials/shaders/common.glsl), "ShadowMap" + "ShadowMatrices",
 * "ShadowSplits", "ShadowCascades", "ShadowAxis" from the shadow cascades, "EnvMap" + "EnvMapMatrix" (world → owner-frame rotation, the
 * env-map view's ViewMatrix) + "ParaboloidDirection" from env-map views.
 *
 * Lifecycle: library_create → material_create* → frames → library_destroy
 * (destroys its materials and effects; the device must be idle or the
 * library's effects otherwise unused). Materials may be destroyed earlier
 * when no pending frame uses them.
 * Thread rule: creation, destruction, setters, pre_render and
 * prepare_view are [render thread, not while recording]; renders,
 * sort_info and apply are [any thread] (apply writes only the given
 * manager's slot).
 */
#ifndef OB_MATERIAL_H
#define OB_MATERIAL_H

#include "ob_effect.h"
#include "ob_renderer.h"
#include "ob_texture.h"
#include "ob_view.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The lit shaders' PerViewLights block (materials/shaders/lighting.glsl):
 * "LightGrid" (vec4), "LightTable" (OB_LIGHT_TABLE_BYTES: four vec4 a light,
 * OB_MAX_LIGHTS lights) and "LightTiles" (OB_LIGHT_TILES_BYTES: a 256-bit
 * mask per tile of a 16 x 16 screen grid), registered by the library and
 * filled per view by the views layer. */
#define OB_LIGHT_TILES_X 16u
#define OB_LIGHT_TILES_Y 16u
#define OB_LIGHT_TABLE_BYTES (OB_MAX_LIGHTS * 4u * 16u)
#define OB_LIGHT_TILES_BYTES (OB_LIGHT_TILES_X * OB_LIGHT_TILES_Y * (OB_MAX_LIGHTS / 8u))

typedef struct ob_material_library ob_material_library;
struct ob_material;  /* the engine forward-declares it */
typedef struct ob_material ob_material;

typedef enum ob_material_kind {
    OB_MATERIAL_LIT = 0,
    OB_MATERIAL_REFLECTIVE,
    OB_MATERIAL_UNLIT,
    OB_MATERIAL_CUSTOM,
    OB_MATERIAL_PBR,          /* glTF 2 metallic-roughness (desc.pbr) */
    OB_MATERIAL_KIND_COUNT
} ob_material_kind;

/* Standard effects of the library; variants are flags. */
typedef enum ob_std_effect {
    OB_STD_LIT = 0,           /* pbr.vert + pbr.frag, no texture, standard layout (LIT, REFLECTIVE) */
    OB_STD_DEPTH,             /* depth.vert, no fragment stage, depth bias */
    OB_STD_PARABOLOID,        /* the same with PARABOLOID, no culling */
    OB_STD_UNLIT,             /* unlit.vert + unlit.frag, standard layout */
    OB_STD_OVERLAY,           /* unlit SCREEN_SPACE + VERTEX_COLOR, text layout, blended */
    OB_STD_FULLSCREEN,        /* fullscreen.vert + .frag, no vertex input, no depth */
    OB_STD_PARTICLES_SIM,     /* particles.comp */
    OB_STD_PARTICLES_DRAW,    /* particles.vert + .frag, pulled quads, blended */
    OB_STD_EFFECT_COUNT
} ob_std_effect;

/* glTF 2 alpha modes. */
typedef enum ob_alpha_mode { OB_ALPHA_OPAQUE = 0, OB_ALPHA_MASK, OB_ALPHA_BLEND } ob_alpha_mode;

/* A texture slot of a PBR material: the texture (owned by its cache, which
 * must outlive the material), the uv set it reads (0 = TEXCOORD0, 1 =
 * TEXCOORD1: the material then draws in the extended layout with TEXCOORD1,
 * ob_vertex_layout_extended_uv1; sets past 1 are drawn with set 0 and a
 * warning) and its uv transform (KHR_texture_transform): with
 * has_transform, the texture is sampled at
 *   (transform[0] u + transform[1] v + transform[2],
 *    transform[3] u + transform[4] v + transform[5])
 * of the mesh's uv (top-left origin). Either makes the variant carry the
 * per-texture transforms (material parameters, not per draw). */
typedef struct ob_material_texture {
    const ob_texture *texture;   /* NULL = none */
    uint32_t uv_set;
    bool has_transform;
    float transform[6];
} ob_material_texture;

/* glTF 2 metallic-roughness material. Textures: base colour and emissive
 * are colour data (load them with srgb = true), the others data maps
 * (UNORM): metallic-roughness reads B = metallic, G = roughness; occlusion
 * reads R; the normal map is tangent space (needs the vertex TANGENT). */
typedef struct ob_material_pbr {
    float base_color[4];               /* linear RGBA factor */
    float metallic, roughness;         /* factors in [0, 1] */
    float emissive[3];                 /* linear factor (may exceed 1) */
    float normal_scale, occlusion_strength;
    ob_material_texture base_color_texture, metallic_roughness_texture, normal_texture,
        occlusion_texture, emissive_texture;
    ob_alpha_mode alpha_mode;
    float alpha_cutoff;                /* MASK: alpha below it is cut out */
    bool double_sided;                 /* no culling; back faces lit with the normal flipped */
    bool vertex_colors;                /* multiply the base colour by COLOR0 */
    /* KHR_materials_clearcoat: a clear dielectric layer (IOR 1.5) over the
     * base, its own GGX lobe with clearcoat_roughness and its own normal
     * (the clearcoat normal texture, else the geometric normal); the base is
     * attenuated by 1 − clearcoat · F_c. clearcoat 0 = no layer (and no
     * clearcoat code in the shader). Textures: intensity *= R, roughness
     * *= G (UNORM), the coat's normal map (tangent space, xy *
     * clearcoat_normal_scale). */
    float clearcoat, clearcoat_roughness, clearcoat_normal_scale;
    ob_material_texture clearcoat_texture, clearcoat_roughness_texture, clearcoat_normal_texture;
} ob_material_pbr;

/* glTF defaults: base (1,1,1,1), metallic 1, roughness 1, emissive 0,
 * normal_scale 1, occlusion_strength 1, OPAQUE, cutoff 0.5, single-sided,
 * no textures, no vertex colours, no clearcoat (clearcoat_normal_scale 1).
 * [any thread] */
ob_material_pbr ob_material_pbr_defaults(void);

typedef enum ob_std_variant {
    OB_VARIANT_SHADOWS = 1u << 0,  /* lit: shadowed directional light */
    OB_VARIANT_ENVMAP = 1u << 1,   /* lit: paraboloid environment lookup */
    OB_VARIANT_BLENDED = 1u << 2,  /* lit/paraboloid/unlit: alpha blended, no depth write */
    OB_VARIANT_INSTANCED = 1u << 3, /* lit/depth/paraboloid/unlit: the per-draw block per
                                       instance (ob_material_library_set_instancing) */
    OB_VARIANT_LOCAL_SHADOWS = 1u << 4, /* lit: point and spot lights' shadow array */
} ob_std_variant;

/* A view type of a material: render flag and the base effect (NULL until the
 * library first needs it, for standard kinds). */
typedef struct ob_material_view_params {
    bool render;
    ob_effect *effect;
} ob_material_view_params;

typedef struct ob_material_desc {
    const char *name;          /* copied; NULL → "material" */
    ob_material_kind kind;
    /* Zero means default: diffuse (1,1,1,1); specular (0.25,0.25,0.25, power
     * 32) — {0,0,0,1} for the faintest highlight (a dielectric's); emissive
     * none; reflectivity 0.6 for REFLECTIVE (ignored otherwise).
     * LIT and REFLECTIVE are drawn by the metallic-roughness model: diffuse
     * is the base colour (its alpha used only when blended); the specular
     * power gives roughness (2 / (power + 2))^(1/4); the specular colour
     * ks the reflectance F0 = 8 ks / (power + 2) (the highlight's peak kept),
     * REFLECTIVE's reflectivity raises F0 to at least itself (the share it
     * mirrors); an F0 over a dielectric's 0.04 becomes metallic, by the glTF
     * specular-glossiness conversion. docs/materials.md has the table. */
    float diffuse[4], specular[4], emissive[4];
    float reflectivity;
    /* REFLECTIVE: its roughness in the model, 0 (a mirror, default) to 1:
     * the environment map is sampled at a coarser mip level (blurred) and
     * the highlights spread the rougher it is (the specular power then
     * only sets F0). LIT: read only with metallic_roughness. Clamped to [0, 1]. */
    float roughness;
    /* LIT and REFLECTIVE: take metallic (0..1) and roughness as given, base
     * colour = diffuse, instead of deriving them from the specular colour,
     * power and reflectivity (then unused); a REFLECTIVE material's
     * environment map is then weighted by the model's Fresnel alone. */
    float metallic;
    bool metallic_roughness;
    bool casts_shadows;
    bool blended;              /* sorted back to front, drawn with the BLENDED variant */
    uint32_t priority;         /* orders materials within a sort class */
    /* Read when kind == OB_MATERIAL_PBR (start from ob_material_pbr_defaults():
     * a zeroed struct is a black, fully metallic surface). blended is then
     * taken from alpha_mode; reflectivity > 0 asks for an environment map. */
    ob_material_pbr pbr;
} ob_material_desc;

/* Called from pre_render for each view type a material needs for an entity
 * (PARABOLOID for reflective materials in perspective views). The views
 * layer queues (or finds) the entity's view and attaches it with
 * ob_renderer_attach_view. [render thread] */
typedef void (*ob_material_queue_fn)(void *user, ob_node *entity, ob_renderer *r,
                                     ob_view *requesting_view, ob_view_type needed);

typedef struct ob_material_library_desc {
    /* The standard vertex layout (position vec3 @0, normal vec3 @12, uv
     * vec2 @24, stride 32; locations 0, 1, 2). NULL → that built-in copy of
     * geometry's ob_vertex_layout_standard(). Copied. */
    const ob_effect_vertex_input *standard_layout;
    /* Overlay text vertices. NULL → stb_easy_font's 16 bytes: position vec3
     * at location 0, colour R8G8B8A8_UNORM at location 3, offset 12. Copied. */
    const ob_effect_vertex_input *text_layout;
    /* The extended layout PBR effects use (position @0, normal @12, uv @24,
     * colour R8G8B8A8_UNORM @32 at location 3, tangent vec4 @36 at location
     * 4; stride 52). NULL → that built-in copy of geometry's
     * ob_vertex_layout_extended(). Copied. */
    const ob_effect_vertex_input *extended_layout;
    /* Shadow depth bias (reversed-Z: negative pushes away from the light).
     * 0 → -1.0 constant, -1.75 slope. */
    float shadow_bias_constant, shadow_bias_slope;
} ob_material_library_desc;

/* desc may be NULL. Registers the material parameters and the default
 * samplers. Compiles nothing. Failure: NULL, *out_result, logged.
 * [render thread, not while recording] */
ob_material_library *ob_material_library_create(ob_effect_context *ctx,
                                                const ob_material_library_desc *desc,
                                                ob_result *out_result);
/* Whether the standard effects draw instanced (default true): a run of
 * entities of one material and mesh is then one draw. false keeps one draw
 * per entity (the per-draw push block), for comparison and tests. Takes
 * effect at the next PreRender. [render thread, between frames] */
void ob_material_library_set_instancing(ob_material_library *lib, bool on);
bool ob_material_library_instancing(const ob_material_library *lib);
/* Destroys every material and effect of the library and its samplers. NULL ok. */
void ob_material_library_destroy(ob_material_library *lib);
void ob_material_library_set_queue_hook(ob_material_library *lib, ob_material_queue_fn fn,
                                        void *user);
ob_effect_context *ob_material_library_context(const ob_material_library *lib);

/* The standard effect variant, compiled and built on first request.
 * Failure: NULL, *out_result, logged (and not retried: later calls return
 * NULL with the same result quietly — unless it ran out of host or device
 * memory, which the next call tries again). [render thread, not while recording] */
ob_effect *ob_material_library_effect(ob_material_library *lib, ob_std_effect kind,
                                      uint32_t variant, ob_result *out_result);
/* The variant if it exists already, else NULL; never compiles. [any thread] */
ob_effect *ob_material_library_find_effect(const ob_material_library *lib, ob_std_effect kind,
                                           uint32_t variant);

/* Make sure every effect variant and pipeline the materials of v's draw list
 * need exists (for entities whose PreRender ran before v's shadow views were
 * queued, say). The views layer calls it at the end of a view's pre_render.
 * [render thread, not while recording] */
void ob_material_library_prepare_view(ob_material_library *lib, ob_renderer *r, ob_view *v);

/* The library owns the material. Failure: NULL, *out_result, logged.
 * [render thread] */
ob_material *ob_material_create(ob_material_library *lib, const ob_material_desc *desc,
                                ob_result *out_result);
/* Now: no pending frame may use it. NULL ok. [render thread] */
void ob_material_destroy(ob_material *m);

const char *ob_material_name(const ob_material *m);
ob_material_kind ob_material_get_kind(const ob_material *m);
ob_material_view_params ob_material_get_view_params(const ob_material *m, ob_view_type type);
/* CUSTOM materials (any kind may override): draw with `effect` in views of
 * `type`; NULL stops drawing there. The caller owns the effect and keeps it
 * alive as long as the material. [render thread, not while recording] */
ob_result ob_material_set_view_effect(ob_material *m, ob_view_type type, ob_effect *effect);
/* What a LIT or REFLECTIVE description is in the metallic-roughness model:
 * a PBR description (pbr: base colour, metallic, roughness, emissive, alpha
 * mode from blended; reflectivity 1 for REFLECTIVE, 0 for LIT) that draws
 * the same surface (in the extended vertex layout). Other kinds: *desc
 * unchanged. NULL: a zeroed desc. [any thread] */
ob_material_desc ob_material_desc_to_pbr(const ob_material_desc *desc);

/* Parameters; non-finite values are refused (OB_ERR_NON_FINITE). A LIT or
 * REFLECTIVE material maps them to its model factors again. [render thread] */
ob_result ob_material_set_diffuse(ob_material *m, const float rgba[4]);
ob_result ob_material_set_specular(ob_material *m, const float rgb_power[4]);
ob_result ob_material_set_emissive(ob_material *m, const float rgb[4]);
ob_result ob_material_set_reflectivity(ob_material *m, float reflectivity);

/* The effect (and variant) the material draws with in view v for entity
 * (r and entity may be NULL: no env-map attachment known). With create, a
 * missing variant is compiled [render thread]; without, falls back as apply
 * does [any thread]. NULL when the material does not render in v->type or
 * the effect failed (logged). */
ob_effect *ob_material_get_view_effect(ob_material *m, ob_renderer *r, const ob_node *entity,
                                   const ob_view *v, bool create, ob_result *out_result);

/* PBR variants: the defines the material's effect for view v uses, as the
 * effect's name, e.g. "pbr:base+mask+sh" (base colour texture, alpha mask,
 * shadows); features a material does not use are left out of its shaders.
 * ob_material_pbr_left_out writes the features of the PBR feature set that
 * the material's variants leave out ("metallic-roughness texture, normal
 * texture, ...") into out (cap bytes, NUL-terminated) for reports; returns
 * the number left out, 0 for a non-PBR material. [any thread] */
uint32_t ob_material_pbr_left_out(const ob_material *m, char *out, size_t cap);

/* True when m is a PBR material whose effects read TEXCOORD1, i.e. draw in
 * the extended layout with TEXCOORD1 (a texture with uv_set 1): its
 * geometry must be uploaded in that layout (ob_geometry_desc.texcoord1).
 * [any thread] */
bool ob_material_reads_texcoord1(const ob_material *m);

/* The engine interface: renders, sort_info, pre_render, apply. Static data. */
const ob_material_iface *ob_material_iface_get(void);

#ifdef __cplusplus
}
#endif
#endif /* OB_MATERIAL_H */
