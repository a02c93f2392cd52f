#version 450
#include "broken.glsl"
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(broken_helper(1.0)); }
