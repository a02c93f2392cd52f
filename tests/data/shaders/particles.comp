#version 450
layout(local_size_x = 8, local_size_y = 4, local_size_z = 1) in;

layout(set = 1, binding = 0, std430) buffer Particles {
    vec4 positions[];
} particles;

layout(set = 1, binding = 1, rgba8) uniform writeonly image2D Target;

void main()
{
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * 64u;
    vec4 p = particles.positions[i];
    particles.positions[i] = p + vec4(0.0, -0.01, 0.0, 0.0);
    imageStore(Target, ivec2(gl_GlobalInvocationID.xy), p);
}
