#version 450
#extension GL_GOOGLE_include_directive : require
// lit.frag — Blinn-Phong with one directional light and the point and spot
// lights of lighting.glsl's tile grid.
//
// Variants (each compiled only when a material needs it):
//   SHADOWS     the directional light is shadowed by "ShadowMap"
//               (shadow.glsl: compare sampler, 2x2 PCF).
//   ENVMAP      reflective surfaces: the reflected view vector, rotated by
//               EnvMapMatrix, samples "EnvMap" (envmap.glsl: dual paraboloid
//               or cube, by EnvMapInfo) at the mip level of roughness
//               Reflectivity.y (0: level 0, a mirror); mixed over the lit
//               colour by Reflectivity.x.
//   PARABOLOID  paired with paraboloid.vert: discards the other hemisphere.
// Output is premultiplied alpha (the blend state is ONE, ONE_MINUS_SRC_ALPHA).
#include "common.glsl"
#include "lighting.glsl"
layout(location = 0) in vec3 vPosition;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec2 vUV;
#if defined(PARABOLOID)
layout(location = 3) in float vHemisphere;
#endif

layout(location = 0) out vec4 outColor;

#if defined(SHADOWS)
#include "shadow.glsl"
#endif

#if defined(ENVMAP)
layout(set = 0, binding = 2, std140) uniform PerEnvMap {
    mat4 EnvMapMatrix;         // world -> env-map owner frame (rotation)
    vec4 EnvMapInfo;           // x kind (0 paraboloid, 1 cube), y top level, z texels/radian
};
layout(set = 1, binding = 1) uniform sampler2DArray EnvMap;
#include "envmap.glsl"
#endif

void main()
{
#if defined(PARABOLOID)
    if (vHemisphere < 0.0) discard;
#endif
    vec3 n = ob_safe_normalize(vNormal);
    vec3 v = ob_unit_normal(CameraPosition.xyz - vPosition);   // any scale (issue 25.2)
#if !defined(PARABOLOID)
    // Two-sided lighting for open meshes seen from behind. (The paraboloid
    // projection mirrors the back hemisphere, so facing means nothing there.)
    if (!gl_FrontFacing) n = -n;
#endif

    float visibility = 1.0;
#if defined(SHADOWS)
    visibility = ob_shadow_visibility(vPosition);
#endif
    vec3 diffuse = DiffuseColor.rgb;
    vec3 color = AmbientColor.rgb * AmbientColor.w * diffuse + EmissiveColor.rgb
               + ob_directional_light(n, v, diffuse, SpecularColor, visibility)
               + ob_local_lights(vPosition, n, v, diffuse, SpecularColor);
#if defined(ENVMAP)
    vec3 r = reflect(-v, n);
    float rough = clamp(Reflectivity.y, 0.0, 1.0);
    vec3 env = ob_env_sample(EnvMap, mat3(EnvMapMatrix) * r, ob_env_lod(rough * rough));
    color = mix(color, env, clamp(Reflectivity.x, 0.0, 1.0));
#endif
    float alpha = DiffuseColor.a;
    outColor = vec4(color * alpha, alpha);
}
