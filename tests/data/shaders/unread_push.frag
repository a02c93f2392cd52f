#version 450
// Includes the push-constant block (common.glsl's PerDraw) but never reads
// it: test_shader checks that it is left out of the block's stages.
#include "common.glsl"

layout(location = 0) in vec3 vNormal;
layout(location = 0) out vec4 outColor;

void main()
{
    outColor = vec4(vNormal, 1.0) * frame.CameraPos.w;
}
