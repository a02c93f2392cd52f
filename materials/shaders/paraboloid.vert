#version 450
#extension GL_GOOGLE_include_directive : require
// paraboloid.vert — renders one hemisphere of a dual-paraboloid environment map.
//
// The view's origin is the map owner's centre, so WorldMatrix already yields
// positions relative to it; ViewMatrix rotates them into the owner's frame.
// ParaboloidDirection.x picks the hemisphere (+1 layer 0, -1 layer 1) and
// ParaboloidDirection.y is the near distance (0 -> 0.05): depth is near/dist,
// reversed-Z like every other view, so anything closer than near is clipped.
// Fragments of the other hemisphere are discarded in lit.frag (PARABOLOID)
// through vHemisphere, which avoids needing the shaderClipDistance feature.
#define OB_VERTEX_STAGE
#include "common.glsl"
#include "paraboloid.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUV;

layout(location = 0) out vec3 vPosition;
layout(location = 1) out vec3 vNormal;
layout(location = 2) out vec2 vUV;
layout(location = 3) out float vHemisphere;

void main()
{
    vec4 world = WorldMatrix * vec4(inPosition, 1.0);
    vPosition = world.xyz;
    vNormal = ob_unit_normal(mat3(NormalMatrix) * inNormal);
    vUV = inUV;

    gl_Position = ob_paraboloid_position(world.xyz, vHemisphere);
}
