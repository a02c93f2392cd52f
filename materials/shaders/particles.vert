#version 450
#extension GL_GOOGLE_include_directive : require
// particles.vert — camera-facing quads pulled from the "Particles" buffer:
// draw 6 vertices with one instance per particle (gl_InstanceIndex picks the
// particle, gl_VertexIndex the corner). No vertex input.
#include "common.glsl"
#include "particles.glsl"

layout(location = 0) out vec4 vColor;
layout(location = 1) out vec2 vCorner;

const vec2 corners[6] = vec2[6](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(1.0, 1.0),
                                vec2(-1.0, -1.0), vec2(1.0, 1.0), vec2(-1.0, 1.0));

void main()
{
    ob_particle p = particles[gl_InstanceIndex];
    vec2 corner = corners[gl_VertexIndex % 6];
    vCorner = corner;
    float life = max(SimEmitter.w, 1e-3);
    vColor = vec4(DiffuseColor.rgb, DiffuseColor.a * clamp(p.position.w / life, 0.0, 1.0));
    if (p.position.w <= 0.0) {
        // Dead: every corner at one point, so the quad has no area.
        gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 world = (WorldMatrix * vec4(p.position.xyz, 1.0)).xyz;
    vec3 view = mat3(ViewMatrix) * world + vec3(corner * (0.5 * SimStep.w), 0.0);
    gl_Position = ProjMatrix * vec4(view, 1.0);
}
