// Declarations shared by basic.vert and basic.frag (test data for test_shader).
#pragma once
#include "lib/math.glsl"

// std140: ViewProj 0 (64), CameraPos 64 (16), Bones 80 (4 x 64), Time 336 (4).
layout(set = 0, binding = 0, std140) uniform PerFrame {
    mat4 ViewProj;
    vec4 CameraPos;
    mat4 Bones[4];
    float Time;
} frame;

layout(push_constant) uniform PerDraw {
    mat4 World;
    vec4 Tint;
} draw;
