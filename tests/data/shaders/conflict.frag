#version 450
// Declares set 0 binding 0 as a different block than common.glsl's PerFrame.
layout(set = 0, binding = 0, std140) uniform Material {
    vec4 Albedo;
} material;
layout(location = 0) out vec4 outColor;
void main() { outColor = material.Albedo; }
