#version 450
#extension GL_GOOGLE_include_directive : require
// lit.vert — standard vertex stage for lit and reflective surfaces.
// Input: the standard vertex layout (position, normal, uv; stride 32).
#define OB_VERTEX_STAGE
#include "common.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(location = 0) out vec3 vPosition;   // camera-relative world
layout(location = 1) out vec3 vNormal;     // world, unit (zero for a zero scale)
layout(location = 2) out vec2 vUV;

void main()
{
    vec4 world = WorldMatrix * vec4(inPosition, 1.0);
    vPosition = world.xyz;
    vNormal = ob_unit_normal(mat3(NormalMatrix) * inNormal);
    vUV = inUV;
    gl_Position = ViewProjMatrix * world;
}
