// shadow.glsl — the shadowed directional light's visibility, shared by
// lit.frag and pbr.frag (SHADOWS variants).
//
// Cascaded shadow maps (docs/architecture.md, "Shadows"): "ShadowMap" holds
// one depth layer per cascade (reversed-Z: larger is nearer the light),
// sampled with the compare sampler "ShadowMapSampler" (GREATER_OR_EQUAL),
// 2x2 PCF. ShadowMatrices[i] maps camera-relative world positions to cascade
// i's clip space; cascade i covers distances up to ShadowSplits[i] along
// ShadowAxis, and over the last ShadowCascades.y of its slice it blends into
// cascade i + 1 (the last one fades to lit), so no seam shows.
#ifndef OB_SHADOW_GLSL
#define OB_SHADOW_GLSL

#include "pcf.glsl"

layout(set = 1, binding = 0) uniform sampler2DArrayShadow ShadowMap;

// Cascade i's visibility at p; `inside` false (and lit) where p lies
// outside its map.
float ob_shadow_cascade(int i, vec3 p, out bool inside)
{
    vec4 clip = ShadowMatrices[i] * vec4(p, 1.0);
    vec3 s = clip.xyz / clip.w;
    vec2 uv = s.xy * 0.5 + 0.5;
    inside = clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) &&
             all(lessThanEqual(uv, vec2(1.0))) && s.z >= 0.0 && s.z <= 1.0;
    if (!inside) return 1.0;
    return ob_pcf4(ShadowMap, uv, float(i), s.z);
}

float ob_shadow_visibility(vec3 p)
{
    int count = int(ShadowCascades.x);
    float d = dot(p, ShadowAxis.xyz) + ShadowAxis.w;
    int i = 0;
    while (i < count && d > ShadowSplits[i]) i++;
    if (i >= count) return 1.0;   // beyond the shadow distance
    bool inside;
    float vis = ob_shadow_cascade(i, p, inside);
    // Another consumer than the fitted camera may see p outside cascade i's
    // map: the next cascade that holds it.
    while (!inside && i + 1 < count) vis = ob_shadow_cascade(++i, p, inside);
    float start = i > 0 ? ShadowSplits[i - 1] : 0.0;
    float band = ShadowCascades.y * (ShadowSplits[i] - start);
    float w = band > 0.0 ? clamp((d - (ShadowSplits[i] - band)) / band, 0.0, 1.0) : 0.0;
    if (w > 0.0) {
        bool next_inside = true;
        float next = i + 1 < count ? ob_shadow_cascade(i + 1, p, next_inside) : 1.0;
        vis = mix(vis, next, next_inside ? w : 0.0);
    }
    return vis;
}

#endif
