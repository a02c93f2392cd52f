#version 450
#extension GL_GOOGLE_include_directive : require
// pbr.frag — glTF 2 metallic-roughness material.
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
//   SHADOWS, ENVMAP                 as lit.frag
//   PARABOLOID                      drawn into an environment map (pbr.vert)
//   DEPTH_ONLY                      shadow pass of an ALPHA_MASK material: the
//                                   cut-out only, no colour
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
};

layout(location = 0) in vec3 vPosition;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec2 vUV;
#if defined(VERTEX_COLOR)
layout(location = 3) in vec4 vColor;
#endif
#if defined(HAS_NORMAL_TEXTURE) && !defined(DEPTH_ONLY)
layout(location = 4) in vec4 vTangent;
#endif
#if defined(PARABOLOID)
layout(location = 5) in float vHemisphere;
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
layout(location = 0) out vec4 outColor;
#endif

vec4 ob_base_color()
{
    vec4 base = PbrBaseColor;
#if defined(HAS_BASE_COLOR_TEXTURE)
    base *= texture(BaseColorTexture, vUV);
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
#if defined(HAS_NORMAL_TEXTURE)
    // Tangent frame (glTF: bitangent = cross(normal, tangent.xyz) * tangent.w),
    // made orthogonal to the interpolated normal; reversed with it on back faces.
    vec3 front_n = back ? -n : n;
    vec3 t = ob_safe_normalize(vTangent.xyz - front_n * dot(front_n, vTangent.xyz));
    vec3 b = cross(front_n, t) * vTangent.w;
    if (back) {
        t = -t;
        b = -b;
    }
    vec3 tn = texture(NormalTexture, vUV).xyz * 2.0 - 1.0;
    tn.xy *= PbrFactors.z;
    vec3 mapped = ob_safe_normalize(mat3(t, b, n) * tn);
    if (dot(mapped, mapped) > 0.0) n = mapped;
#endif
    float metallic = PbrFactors.x;
    float roughness = PbrFactors.y;
#if defined(HAS_METALLIC_ROUGHNESS_TEXTURE)
    vec4 mr = texture(MetallicRoughnessTexture, vUV);
    metallic *= mr.b;
    roughness *= mr.g;
#endif
    metallic = clamp(metallic, 0.0, 1.0);
    roughness = clamp(roughness, 0.03, 1.0);
    float occlusion = 1.0;
#if defined(HAS_OCCLUSION_TEXTURE)
    occlusion = 1.0 + PbrFactors.w * (texture(OcclusionTexture, vUV).r - 1.0);
#endif
    vec3 emissive = PbrEmissive.rgb;
#if defined(HAS_EMISSIVE_TEXTURE)
    emissive *= texture(EmissiveTexture, vUV).rgb;
#endif

    ob_surface s;
    s.n = n;
    s.v = ob_unit_normal(CameraPosition.xyz - vPosition);   // any scale (issue 25.2)
    s.base = base.rgb;
    s.metallic = metallic;
    s.a = roughness * roughness;
    s.f0 = mix(vec3(0.04), base.rgb, metallic);

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
    float ambient_specular = 1.0;
#if defined(ENVMAP)
    ambient_specular = 1.0 - clamp(Reflectivity.x, 0.0, 1.0);
    vec3 r = reflect(-s.v, n);
    vec3 env = ob_env_sample(EnvMap, mat3(EnvMapMatrix) * r, ob_env_lod(s.a));
    color += env * fa * occlusion * max(Reflectivity.x, 0.0);
#endif
    color += ambient * occlusion * ((1.0 - fa) * (1.0 - metallic) * base.rgb + fa * ambient_specular);
    outColor = vec4(color * base.a, base.a);
#endif
}
