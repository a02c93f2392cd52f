// particles.glsl — the particle buffer and simulation parameters shared by
// the simulation (particles.comp) and the drawing (particles.vert).
//
// "Particles" (storage buffer parameter): per particle two vec4s,
//   position: xyz in the emitter entity's model space, w = remaining life (s)
//   velocity: xyz per second,                       w = unused
// A particle with life <= 0 is dead: it is respawned by the next step and
// not drawn.
// SimParams (uniform block, every member a vec4 parameter):
//   SimStep    x = dt (s), y = time (s), z = particle count, w = drawn size
//   SimEmitter xyz = spawn point (model space), w = lifetime (s)
//   SimForce   xyz = acceleration, w = initial speed
#ifndef OB_PARTICLES_GLSL
#define OB_PARTICLES_GLSL

#ifndef PARTICLES_ACCESS
#define PARTICLES_ACCESS readonly
#endif

struct ob_particle {
    vec4 position;
    vec4 velocity;
};

layout(set = 1, binding = 0, std430) PARTICLES_ACCESS buffer Particles {
    ob_particle particles[];
};

layout(set = 0, binding = 3, std140) uniform SimParams {
    vec4 SimStep;
    vec4 SimEmitter;
    vec4 SimForce;
};

#endif
