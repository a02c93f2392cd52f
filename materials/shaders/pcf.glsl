// pcf.glsl — the percentage-closer filter of Obelisk's shadow maps, shared
// by the directional cascades (shadow.glsl) and the point and spot lights'
// maps (shadow_local.glsl). Fragment stage.
#ifndef OB_PCF_GLSL
#define OB_PCF_GLSL

// 2x2 percentage-closer filter of layer `layer` of a depth array at uv,
// compared with `depth` (the sampler's compare op): the share of the four
// taps half a texel around uv that pass, 0 (shadowed) to 1 (lit).
float ob_pcf4(sampler2DArrayShadow map, vec2 uv, float layer, float depth)
{
    vec2 texel = 1.0 / vec2(textureSize(map, 0).xy);
    return 0.25 * (texture(map, vec4(uv + vec2(-0.5, -0.5) * texel, layer, depth))
                 + texture(map, vec4(uv + vec2( 0.5, -0.5) * texel, layer, depth))
                 + texture(map, vec4(uv + vec2(-0.5,  0.5) * texel, layer, depth))
                 + texture(map, vec4(uv + vec2( 0.5,  0.5) * texel, layer, depth)));
}

#endif
