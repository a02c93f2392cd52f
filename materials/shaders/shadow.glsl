// shadow.glsl — the shadowed directional light's visibility, shared by
// lit.frag and pbr.frag (SHADOWS variants).
//
// "ShadowMap" is the light's depth (reversed-Z: larger is nearer the light),
// sampled with the compare sampler "ShadowMapSampler" (GREATER_OR_EQUAL),
// 2x2 PCF. ShadowMatrix maps camera-relative world positions to the light's
// clip space.
#ifndef OB_SHADOW_GLSL
#define OB_SHADOW_GLSL

layout(set = 1, binding = 0) uniform sampler2DShadow ShadowMap;

float ob_shadow_visibility(vec3 p)
{
    vec4 clip = ShadowMatrix * vec4(p, 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 s = clip.xyz / clip.w;
    vec2 uv = s.xy * 0.5 + 0.5;
    // Outside the shadow volume nothing was rendered: treat as lit.
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) ||
        s.z < 0.0 || s.z > 1.0)
        return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(ShadowMap, 0));
    float lit = texture(ShadowMap, vec3(uv + vec2(-0.5, -0.5) * texel, s.z))
              + texture(ShadowMap, vec3(uv + vec2( 0.5, -0.5) * texel, s.z))
              + texture(ShadowMap, vec3(uv + vec2(-0.5,  0.5) * texel, s.z))
              + texture(ShadowMap, vec3(uv + vec2( 0.5,  0.5) * texel, s.z));
    return lit * 0.25;
}

#endif
