#version 450
#include "common.glsl"

layout(location = 0) in vec3 Position;
layout(location = 1) in vec3 Normal;
layout(location = 2) in vec2 TexCoord;
layout(location = 3) in uvec4 Joints;

layout(location = 0) out vec3 vNormal;
layout(location = 1) out vec2 vUV;

void main()
{
    mat4 skin = frame.Bones[Joints.x] + frame.Bones[Joints.y];
    gl_Position = frame.ViewProj * draw.World * skin * vec4(Position, 1.0);
    vNormal = Normal * saturate1(frame.Time);
    vUV = TexCoord;
}
