#version 450
// composite.frag — the composite pass: the scene's linear HDR colour
// ("SourceImage", sampler "SourceImageSampler") scaled by the exposure, tone
// mapped and written to an sRGB target, whose format does the sRGB encode
// (so blending over it, e.g. the overlay's text, happens in linear space).
//
// Tone map: Krzysztof Narkowicz's ACES filmic fit (2016), per channel,
//     x = Exposure * c
//     f(x) = clamp(x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), 0, 1)
// With ToneMap.y = 0 the curve is left out: f(x) = clamp(x, 0, 1) (tests,
// or an application that tone maps itself). Alpha is passed through,
// clamped to [0, 1].

layout(set = 0, binding = 0, std140) uniform Composite {
    vec4 ToneMap;              // x = exposure (linear scale), y = 1 tone map / 0 clamp only
};

layout(set = 1, binding = 0) uniform sampler2D SourceImage;

layout(location = 0) in vec2 vUV;
layout(location = 0) out vec4 outColor;

vec3 aces_narkowicz(vec3 x)
{
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main()
{
    vec4 hdr = texture(SourceImage, vUV);
    // A NaN or negative value from a shading bug must not spread: max() maps
    // NaN to 0 on every implementation that follows IEEE min/max.
    vec3 x = max(hdr.rgb * ToneMap.x, vec3(0.0));
    vec3 c = ToneMap.y > 0.5 ? aces_narkowicz(x) : clamp(x, 0.0, 1.0);
    outColor = vec4(c, clamp(hdr.a, 0.0, 1.0));
}
