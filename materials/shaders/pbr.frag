#version 450
#extension GL_GOOGLE_include_directive : require
// pbr.frag — glTF 2 metallic-roughness material: the one lighting model of
// the LIT, REFLECTIVE (their parameter sets, ob_material_lit.c, with no
// texture and the standard vertex layout) and PBR kinds.
//
// Lighting model (docs/materials.md has the long form):
//   colour = emissive
//          + sum over lights of  pi * (f_diffuse + f_specular) * radiance * NdotL
//          + ambient:  AmbientColor * occlusion * ((1 - F_a)(1 - metallic) base + F_a * k)
//          + ENVMAP:   env(R, lod(roughness)) * F_a * occlusion * Reflectivity.x
//   with the BRDF of pbr.glsl (Cook-Torrance: GGX D, height-correlated Smith
//   visibility, Schlick F with F0 = mix(0.04, base, metallic); Lambert
//   diffuse) for the directional light (shadowed with SHADOWS) and the
//   point and spot lights of lighting.glsl's tile grid; F_a is Schlick at n.v with roughness-limited
//   reflectance (ob_fresnel_ambient).
//   The environment map (envmap.glsl: paraboloid or cube, linear HDR) has a
//   box-filtered mip chain; it is sampled at the level whose texel spans
//   the GGX lobe (alpha = roughness^2 radians, ob_env_lod), so a smooth
//   metal mirrors its surroundings and a rough one reflects them blurred.
//   This approximates a GGX prefilter (a box, not the lobe's shape). The
//   ambient term's specular part (F_a * AmbientColor) stands for the
//   environment where there is none: k = 1 - clamp(Reflectivity.x) with
//   ENVMAP, 1 without.
// Output: linear radiance (no gamma: the composite tone maps and encodes),
// premultiplied alpha (the blend state is ONE, ONE_MINUS_SRC_ALPHA).
//
// Variants (defines; a material compiles only what it uses, so a material
// without a normal map has no normal-map code and binds no sampler for it):
//   HAS_BASE_COLOR_TEXTURE          base colour *= BaseColorTexture (sRGB)
//   HAS_METALLIC_ROUGHNESS_TEXTURE  metallic *= B, roughness *= G
//   HAS_NORMAL_TEXTURE              tangent-space normal map, xy * normal scale,
//                                   tangent frame from the vertex TANGENT (w = sign)
//   HAS_OCCLUSION_TEXTURE           ambient and environment *= 1 + strength * (R - 1)
//   HAS_EMISSIVE_TEXTURE            emissive *= EmissiveTexture (sRGB)
//   VERTEX_COLOR                    base colour *= COLOR0
//   ALPHA_MASK                      discard below the cutoff, alpha 1
//   BLENDED                         alpha blended (alpha mode BLEND)
//   DOUBLE_SIDED                    back faces drawn with the normal flipped
//   SHADOWS                         the directional light shadowed (shadow.glsl)
//   ENVMAP                          the entity's environment map (envmap.glsl)
//   PARABOLOID                      drawn into an environment map (pbr.vert)
//   DEPTH_ONLY                      shadow pass of an ALPHA_MASK material: the
//                                   cut-out only, no colour
//   HAS_UV_TRANSFORM                each texture sampled at its own 2x3 transform
//                                   of the uv (KHR_texture_transform), rows of
//                                   PbrUvTransforms (material parameters)
//   HAS_TEXCOORD1                   textures whose row says set 1 read TEXCOORD1
//   HAS_CLEARCOAT                   KHR_materials_clearcoat over the base (pbr.glsl):
//                                   PbrClearcoat x intensity, y roughness, z normal scale
//   HAS_CLEARCOAT_TEXTURE           intensity *= ClearcoatTexture.r
//   HAS_CLEARCOAT_ROUGHNESS_TEXTURE coat roughness *= ClearcoatRoughnessTexture.g
//   HAS_CLEARCOAT_NORMAL_TEXTURE    the coat's own tangent-space normal map
#include "common.glsl"
#include "lighting.glsl"
#include "pbr.glsl"
#if defined(SHADOWS)
#include "shadow.glsl"
#endif

layout(set = 0, binding = 3, std140) uniform PbrMaterial {
    vec4 PbrBaseColor;         // linear rgba factor
    vec4 PbrFactors;           // x metallic, y roughness, z normal scale, w occlusion strength
    vec4 PbrEmissive;          // rgb emissive factor, w alpha cutoff
#if defined(HAS_CLEARCOAT)
    vec4 PbrClearcoat;         // x intensity, y roughness, z normal scale
#endif
#if defined(HAS_UV_TRANSFORM) || defined(HAS_TEXCOORD1)
    // Per texture slot (base, mr, normal, occlusion, emissive, cc, cc roughness,
    // cc normal) two rows: (a, b, tx, uv set), (c, d, ty, 0); as vec4 k of mat4 k/4.
    mat4 PbrUvTransforms[4];
#endif
};

layout(location = 0) in vec3 vPosition;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec2 vUV;
#if defined(VERTEX_COLOR)
layout(location = 3) in vec4 vColor;
#endif
#if (defined(HAS_NORMAL_TEXTURE) || defined(HAS_CLEARCOAT_NORMAL_TEXTURE)) && !defined(DEPTH_ONLY)
layout(location = 4) in vec4 vTangent;
#endif
#if defined(PARABOLOID)
layout(location = 5) in float vHemisphere;
#endif
#if defined(HAS_TEXCOORD1)
layout(location = 6) in vec2 vUV1;
#endif
#if (defined(HAS_NORMAL_TEXTURE) || defined(HAS_CLEARCOAT_NORMAL_TEXTURE)) && !defined(DEPTH_ONLY)
#define OB_TANGENT_FRAME
#endif

#if defined(ENVMAP)
layout(set = 0, binding = 2, std140) uniform PerEnvMap {
    mat4 EnvMapMatrix;         // world -> env-map owner frame (rotation)
    vec4 EnvMapInfo;           // x kind (0 paraboloid, 1 cube), y top level, z texels/radian
};
layout(set = 1, binding = 1) uniform sampler2DArray EnvMap;
#include "envmap.glsl"
#endif
#if defined(HAS_BASE_COLOR_TEXTURE)
layout(set = 1, binding = 2) uniform sampler2D BaseColorTexture;
#endif
#if !defined(DEPTH_ONLY)
#if defined(HAS_METALLIC_ROUGHNESS_TEXTURE)
layout(set = 1, binding = 3) uniform sampler2D MetallicRoughnessTexture;
#endif
#if defined(HAS_NORMAL_TEXTURE)
layout(set = 1, binding = 4) uniform sampler2D NormalTexture;
#endif
#if defined(HAS_OCCLUSION_TEXTURE)
layout(set = 1, binding = 5) uniform sampler2D OcclusionTexture;
#endif
#if defined(HAS_EMISSIVE_TEXTURE)
layout(set = 1, binding = 6) uniform sampler2D EmissiveTexture;
#endif
#if defined(HAS_CLEARCOAT_TEXTURE)
layout(set = 1, binding = 7) uniform sampler2D ClearcoatTexture;
#endif
#if defined(HAS_CLEARCOAT_ROUGHNESS_TEXTURE)
layout(set = 1, binding = 8) uniform sampler2D ClearcoatRoughnessTexture;
#endif
#if defined(HAS_CLEARCOAT_NORMAL_TEXTURE)
layout(set = 1, binding = 9) uniform sampler2D ClearcoatNormalTexture;
#endif
layout(location = 0) out vec4 outColor;
#endif

// The uv texture slot i samples at (see PbrUvTransforms); plain vUV when
// the variant has no transforms and no second set.
#if defined(HAS_UV_TRANSFORM) || defined(HAS_TEXCOORD1)
vec2 ob_texture_uv(int i)
{
    vec4 r0 = PbrUvTransforms[(2 * i) / 4][(2 * i) % 4];
    vec4 r1 = PbrUvTransforms[(2 * i + 1) / 4][(2 * i + 1) % 4];
#if defined(HAS_TEXCOORD1)
    vec2 uv = r0.w > 0.5 ? vUV1 : vUV;
#else
    vec2 uv = vUV;
#endif
    return vec2(dot(r0.xy, uv) + r0.z, dot(r1.xy, uv) + r1.z);
}
#define OB_UV(i) ob_texture_uv(i)
#else
#define OB_UV(i) vUV
#endif

#if defined(OB_TANGENT_FRAME)
// A tangent-space normal map (glTF: bitangent = cross(normal, tangent.xyz) *
// tangent.w), the frame made orthogonal to the interpolated normal and
// reversed with it on back faces; n when the map gives nothing usable.
vec3 ob_mapped_normal(vec3 tn, float scale, vec3 n, bool back)
{
    vec3 front_n = back ? -n : n;
    vec3 t = ob_safe_normalize(vTangent.xyz - front_n * dot(front_n, vTangent.xyz));
    vec3 b = cross(front_n, t) * vTangent.w;
    if (back) {
        t = -t;
        b = -b;
    }
    tn.xy *= scale;
    vec3 mapped = ob_safe_normalize(mat3(t, b, n) * tn);
    return dot(mapped, mapped) > 0.0 ? mapped : n;
}
#endif

vec4 ob_base_color()
{
    vec4 base = PbrBaseColor;
#if defined(HAS_BASE_COLOR_TEXTURE)
    base *= texture(BaseColorTexture, OB_UV(0));
#endif
#if defined(VERTEX_COLOR)
    base *= vColor;
#endif
    return base;
}

void main()
{
#if defined(PARABOLOID)
    if (vHemisphere < 0.0) discard;
#endif
    vec4 base = ob_base_color();
#if defined(ALPHA_MASK)
    if (base.a < PbrEmissive.w) discard;
    base.a = 1.0;
#elif !defined(BLENDED)
    base.a = 1.0;
#endif
#if !defined(DEPTH_ONLY)
    vec3 n = ob_safe_normalize(vNormal);
    bool back = false;
#if defined(DOUBLE_SIDED) && !defined(PARABOLOID)
    back = !gl_FrontFacing;
    if (back) n = -n;
#endif
#if defined(HAS_CLEARCOAT)
    vec3 coat_n = n;   // the geometric normal unless the coat has its own map
#if defined(HAS_CLEARCOAT_NORMAL_TEXTURE)
    coat_n = ob_mapped_normal(texture(ClearcoatNormalTexture, OB_UV(7)).xyz * 2.0 - 1.0, PbrClearcoat.z, n, back);
#endif
#endif
#if defined(HAS_NORMAL_TEXTURE)
    n = ob_mapped_normal(texture(NormalTexture, OB_UV(2)).xyz * 2.0 - 1.0, PbrFactors.z, n, back);
#endif
    float metallic = PbrFactors.x;
    float roughness = PbrFactors.y;
#if defined(HAS_METALLIC_ROUGHNESS_TEXTURE)
    vec4 mr = texture(MetallicRoughnessTexture, OB_UV(1));
    metallic *= mr.b;
    roughness *= mr.g;
#endif
    metallic = clamp(metallic, 0.0, 1.0);
    roughness = clamp(roughness, 0.03, 1.0);
    float occlusion = 1.0;
#if defined(HAS_OCCLUSION_TEXTURE)
    occlusion = 1.0 + PbrFactors.w * (texture(OcclusionTexture, OB_UV(3)).r - 1.0);
#endif
    vec3 emissive = PbrEmissive.rgb;
#if defined(HAS_EMISSIVE_TEXTURE)
    emissive *= texture(EmissiveTexture, OB_UV(4)).rgb;
#endif

    ob_surface s;
    s.n = n;
    s.v = ob_unit_normal(CameraPosition.xyz - vPosition);   // any scale (issue 25.2)
    s.base = base.rgb;
    s.metallic = metallic;
    s.a = roughness * roughness;
    s.f0 = mix(vec3(0.04), base.rgb, metallic);
#if defined(HAS_CLEARCOAT)
    s.cn = coat_n;
    s.clearcoat = clamp(PbrClearcoat.x, 0.0, 1.0);
    float coat_roughness = PbrClearcoat.y;
#if defined(HAS_CLEARCOAT_TEXTURE)
    s.clearcoat *= texture(ClearcoatTexture, OB_UV(5)).r;
#endif
#if defined(HAS_CLEARCOAT_ROUGHNESS_TEXTURE)
    coat_roughness *= texture(ClearcoatRoughnessTexture, OB_UV(6)).g;
#endif
    coat_roughness = clamp(coat_roughness, 0.03, 1.0);
    s.ca = coat_roughness * coat_roughness;
#endif

    vec3 color = emissive;
    if (LightColor.w > 0.0) {
        float visibility = 1.0;
#if defined(SHADOWS)
        visibility = ob_shadow_visibility(vPosition);
#endif
        color += visibility * ob_pbr_light(s, ob_safe_normalize(LightDirection.xyz), LightColor.rgb * LightColor.w);
    }
    // Point and spot lights of this fragment's tile, in light order
    // (lighting.glsl).
    uint tile = ob_light_tile();
    for (uint w = 0u; w < uint(LightGrid.z); w++) {
        uint bits = ob_light_word(tile, w);
        while (bits != 0u) {
            uint i = w * 32u + uint(findLSB(bits));
            bits &= bits - 1u;
            vec3 l, radiance;
            ob_local_light(i, vPosition, l, radiance);
            color += ob_pbr_light(s, l, radiance);
        }
    }
    vec3 fa = ob_fresnel_ambient(s);
    vec3 ambient = AmbientColor.rgb * AmbientColor.w;
#if defined(HAS_CLEARCOAT)
    vec3 lit = color;   // emissive + lights (the lights already layered)
#endif
    float ambient_specular = 1.0;
#if defined(ENVMAP)
    ambient_specular = 1.0 - clamp(Reflectivity.x, 0.0, 1.0);
    vec3 r = reflect(-s.v, n);
    vec3 env = ob_env_sample(EnvMap, mat3(EnvMapMatrix) * r, ob_env_lod(s.a));
    color += env * fa * occlusion * max(Reflectivity.x, 0.0);
#endif
    color += ambient * occlusion * ((1.0 - fa) * (1.0 - metallic) * base.rgb + fa * ambient_specular);
#if defined(HAS_CLEARCOAT)
    // The coat over the emissive, ambient and environment terms: the base's
    // attenuated by 1 - clearcoat * F_c, the coat's own reflection added
    // (blurred by the coat's roughness, as the base's is by its own).
    float coat_f = ob_clearcoat_fresnel(s);
    float keep = 1.0 - s.clearcoat * coat_f;
    vec3 coat = ambient * occlusion * s.clearcoat * coat_f;
#if defined(ENVMAP)
    vec3 coat_r = reflect(-s.v, s.cn);
    vec3 coat_env = ob_env_sample(EnvMap, mat3(EnvMapMatrix) * coat_r, ob_env_lod(s.ca));
    coat += coat_env * s.clearcoat * coat_f * occlusion * max(Reflectivity.x, 0.0);
#endif
    color = (lit - emissive) + (emissive + color - lit) * keep + coat;
#endif
    outColor = vec4(color * base.a, base.a);
#endif
}
