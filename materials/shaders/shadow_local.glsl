// shadow_local.glsl — visibility of a point or spot light's shadow map, for
// lighting.glsl's ob_local_light (LOCAL_SHADOWS variants only).
//
// views/ob_view_local_shadow.c renders every shadowed local light into
// layers of one depth 2D array, LocalShadowMaps: a spot light one layer (a
// perspective map over its outer cone), a point light six (cube faces +X,
// -X, +Y, -Y, +Z, -Z, 90 degrees each). LightTable[4i + 3].y is the light's
// first layer, or -1 when it has no map in this view. LocalShadowMatrices
// [layer] maps camera-relative world positions to that layer's clip space
// (reversed-Z: larger is nearer the light), so the compare sampler
// (GREATER_OR_EQUAL, as the directional map's) answers "lit". 2x2 PCF.
#ifndef OB_SHADOW_LOCAL_GLSL
#define OB_SHADOW_LOCAL_GLSL

#include "pcf.glsl"

#define OB_MAX_LOCAL_SHADOW_LAYERS 16

layout(set = 0, binding = 5, std140) uniform PerViewLocalShadows {
    mat4 LocalShadowMatrices[OB_MAX_LOCAL_SHADOW_LAYERS];
};
layout(set = 1, binding = 10) uniform sampler2DArrayShadow LocalShadowMaps;

// The cube face (0..5: +X, -X, +Y, -Y, +Z, -Z) that d, from the light,
// falls in: its largest axis (the C side's per-item face reach agrees).
int ob_cube_face_of(vec3 d)
{
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
    if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
    return d.z >= 0.0 ? 4 : 5;
}

// 1 = lit, 0 = in shadow, for light `first_layer` seen from p; `point`
// picks the cube face from the light's position.
float ob_local_shadow(int first_layer, bool point, vec3 light_pos, vec3 p)
{
    int layer = first_layer + (point ? ob_cube_face_of(p - light_pos) : 0);
    vec4 clip = LocalShadowMatrices[layer] * vec4(p, 1.0);
    if (clip.w <= 0.0) return 1.0;
    vec3 s = clip.xyz / clip.w;
    vec2 uv = s.xy * 0.5 + 0.5;
    // Outside the map (beyond a spot's cone) the light gives nothing anyway.
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || s.z > 1.0)
        return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(LocalShadowMaps, 0).xy);
    // Receiver bias: depth is near / distance (reversed-Z, infinite far), so
    // scaling it moves p toward the light by a fraction of its distance:
    // about a texel's angle at 90 degrees. The casters' slope bias alone
    // leaves a surface facing the light (no slope) to the rounding of two
    // matrix paths, which shows as lines of shadow.
    s.z *= 1.0 + 2.0 * texel.x;
    return ob_pcf4(LocalShadowMaps, uv, float(layer), s.z);
}

#endif
