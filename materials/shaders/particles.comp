#version 450
#extension GL_GOOGLE_include_directive : require
// particles.comp — one step of the particle simulation (dispatch
// ceil(count / 64) groups). Deterministic: respawn randomness is a hash of
// the particle index and the simulation time, never of thread timing.
#define PARTICLES_ACCESS
#include "particles.glsl"

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

uint ob_hash_u32(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

float ob_random(inout uint state)
{
    state = ob_hash_u32(state);
    return float(state >> 8) * (1.0 / 16777216.0);
}

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(SimStep.z)) return;

    float dt = SimStep.x;
    ob_particle p = particles[i];
    p.velocity.xyz += SimForce.xyz * dt;
    p.position.xyz += p.velocity.xyz * dt;
    p.position.w -= dt;

    if (p.position.w <= 0.0) {
        uint state = ob_hash_u32(i * 0x9e3779b9u ^ floatBitsToUint(SimStep.y));
        float z = ob_random(state) * 0.5 + 0.5;          // upper cone
        float a = ob_random(state) * 6.28318530718;
        float r = sqrt(max(1.0 - z * z, 0.0));
        vec3 dir = vec3(r * cos(a), z, r * sin(a));
        float life = max(SimEmitter.w, 1e-3);
        p.position = vec4(SimEmitter.xyz, life * (0.5 + 0.5 * ob_random(state)));
        p.velocity = vec4(dir * SimForce.w * (0.75 + 0.5 * ob_random(state)), 0.0);
    }
    particles[i] = p;
}
