#version 450
#include "common.glsl"
#include "lib/consts.glsl"
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(OB_ONE) + not_declared; }
