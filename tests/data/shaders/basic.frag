#version 450
#include "common.glsl"
#include "common.glsl"

layout(set = 1, binding = 0) uniform sampler2D DiffuseMap;
#ifdef USE_FOG
layout(set = 1, binding = 1) uniform sampler2D FogMap;
#endif

layout(location = 0) in vec3 vNormal;
layout(location = 1) in vec2 vUV;
layout(location = 0) out vec4 outColor;

void main()
{
    vec4 c = texture(DiffuseMap, vUV) * draw.Tint * frame.CameraPos.w;
#ifdef USE_FOG
    c.rgb = mix(c.rgb, texture(FogMap, vUV).rgb, FOG_AMOUNT);
#endif
#if VARIANT == 1
    c *= 0.5;
#elif VARIANT == 2
    c += 0.25;
#elif VARIANT == 3
    c = c.bgra;
#endif
    outColor = c * saturate1(dot(vNormal, vNormal));
}
