#version 450
#extension GL_GOOGLE_include_directive : require
// depth.vert — depth-only rendering (shadow maps). The effect has no fragment
// stage; depth bias comes from the effect's rasterizer state.
#define OB_VERTEX_STAGE
#include "common.glsl"

layout(location = 0) in vec3 inPosition;

void main()
{
    gl_Position = ViewProjMatrix * (WorldMatrix * vec4(inPosition, 1.0));
}
