// lighting.glsl — the lights of the lit shaders (pbr.frag, which lights
// every LIT, REFLECTIVE and PBR material with pbr.glsl's BRDF), in
// camera-relative world space (the eye is at the origin): the point and spot
// lights' table and tile grid, and what one of them sends to a point. The
// directional light is common.glsl's LightDirection and LightColor.
//
// Point and spot lights: views/ob_views_lights.c fills PerViewLights per view
// with the scene's first OB_MAX_LIGHTS lights (node-id order) and a 16 x 16
// grid of screen tiles, each a 256-bit mask of the lights whose range sphere
// may reach it. A fragment loops over its tile's bits in ascending order, so
// the sum runs in node-id order whatever the tiling: every view, thread count
// and instancing run lights a point with the same lights in the same order.
// Views that are not perspective (paraboloid) set LightGrid.w = 0: tile 0
// then holds every light.
#ifndef OB_LIGHTING_GLSL
#define OB_LIGHTING_GLSL

// Smooth window so a bounded light reaches exactly zero at its range.
float ob_point_attenuation(float dist, float range)
{
    float falloff = 1.0 / (1.0 + dist * dist);
    if (range <= 0.0) return falloff;
    float r = dist / range;
    float window = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return falloff * window * window;
}

#define OB_MAX_LIGHTS 256
#define OB_LIGHT_TILES_X 16
#define OB_LIGHT_TILES 256

layout(set = 0, binding = 4, std140) uniform PerViewLights {
    vec4 LightGrid;                        // tile width, height in pixels; mask words in use
                                           // (ceil(lights / 32)); 1 = tiled, 0 = tile 0 only
    vec4 LightTable[4 * OB_MAX_LIGHTS];    // per light: position.xyz, range (0 = unbounded) |
                                           // colour rgb, intensity | axis xyz (where it shines),
                                           // cos outer (< -1: a point light) | cos inner
    uvec4 LightTiles[2 * OB_LIGHT_TILES];  // 8 words a tile: bit i = light i may reach it
};

// The tile gl_FragCoord falls in (fragment stage only).
uint ob_light_tile()
{
    if (LightGrid.w <= 0.0) return 0u;
    uvec2 t = min(uvec2(gl_FragCoord.xy / LightGrid.xy), uvec2(OB_LIGHT_TILES_X - 1));
    return t.y * uint(OB_LIGHT_TILES_X) + t.x;
}

// Word w (0..7) of a tile's mask.
uint ob_light_word(uint tile, uint w)
{
    return LightTiles[tile * 2u + w / 4u][w % 4u];
}

// Light i seen from p: the unit direction toward it and the radiance
// arriving (colour * intensity * distance attenuation * spot cone).
void ob_local_light(uint i, vec3 p, out vec3 l, out vec3 radiance)
{
    vec4 position = LightTable[4u * i];
    vec4 color = LightTable[4u * i + 1u];
    vec4 axis = LightTable[4u * i + 2u];
    vec3 to_light = position.xyz - p;
    l = ob_safe_normalize(to_light);
    float att = ob_point_attenuation(length(to_light), position.w);
    if (axis.w >= -1.0) {
        // Spot: full inside the inner cone, smoothstep down to zero at the
        // outer one (the divisor is kept positive for inner == outer).
        float cos_inner = LightTable[4u * i + 3u].x;
        float t = clamp((dot(-l, axis.xyz) - axis.w) / max(cos_inner - axis.w, 1e-4), 0.0, 1.0);
        att *= t * t * (3.0 - 2.0 * t);
    }
    radiance = color.rgb * color.w * att;
}

#endif
