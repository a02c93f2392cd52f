#version 450
#extension GL_GOOGLE_include_directive : require
// pbr.vert — vertex stage of the glTF metallic-roughness material (pbr.frag).
// LIT and REFLECTIVE draw it in the standard layout (position, normal, uv;
// stride 32): with no colour, tangent or TEXCOORD1 it reads nothing else.
// Input: the extended vertex layout (position, normal, uv, colour RGBA8 at
// location 3, tangent xyz + bitangent sign at location 4; stride 52); only
// what the variant uses is declared, so unused attributes cost nothing.
//
// Variants: VERTEX_COLOR (colour passed on), HAS_NORMAL_TEXTURE (tangent
// passed on, in world space: it transforms with WorldMatrix, not the normal
// matrix), PARABOLOID (dual-paraboloid projection of paraboloid.glsl; the
// fragment stage discards the other hemisphere),
// DEPTH_ONLY (shadow pass of ALPHA_MASK materials: position and uv only),
// HAS_TEXCOORD1 (the second uv set, location 5 of the extended layout with
// TEXCOORD1, passed on), HAS_CLEARCOAT_NORMAL_TEXTURE (tangent passed on, as
// for the normal texture).
#define OB_VERTEX_STAGE
#include "common.glsl"
#if defined(PARABOLOID)
#include "paraboloid.glsl"
#endif

layout(location = 0) in vec3 inPosition;
layout(location = 2) in vec2 inUV;
#if !defined(DEPTH_ONLY)
layout(location = 1) in vec3 inNormal;
#endif
#if defined(VERTEX_COLOR)
layout(location = 3) in vec4 inColor;
#endif
#if (defined(HAS_NORMAL_TEXTURE) || defined(HAS_CLEARCOAT_NORMAL_TEXTURE)) && !defined(DEPTH_ONLY)
#define OB_TANGENT_FRAME
layout(location = 4) in vec4 inTangent;
#endif
#if defined(HAS_TEXCOORD1)
layout(location = 5) in vec2 inUV1;
layout(location = 6) out vec2 vUV1;
#endif

layout(location = 0) out vec3 vPosition;   // camera-relative world
layout(location = 1) out vec3 vNormal;     // world, unit (zero for a zero scale)
layout(location = 2) out vec2 vUV;
#if defined(VERTEX_COLOR)
layout(location = 3) out vec4 vColor;
#endif
#if defined(OB_TANGENT_FRAME)
layout(location = 4) out vec4 vTangent;    // world xyz, w = bitangent sign
#endif
#if defined(PARABOLOID)
layout(location = 5) out float vHemisphere;
#endif

// The normal matrix is derived from WorldMatrix (ob_normal_matrix) on both
// paths, so that one draw per entity and an instanced run give the same
// pixels.
void main()
{
    vec4 world = WorldMatrix * vec4(inPosition, 1.0);
    vPosition = world.xyz;
    vUV = inUV;
#if defined(HAS_TEXCOORD1)
    vUV1 = inUV1;
#endif
#if defined(DEPTH_ONLY)
    vNormal = vec3(0.0);
#else
    vNormal = ob_unit_normal(ob_normal_matrix(WorldMatrix) * inNormal);
#endif
#if defined(VERTEX_COLOR)
    vColor = inColor;
#endif
#if defined(OB_TANGENT_FRAME)
    vTangent = vec4(ob_unit_normal(mat3(WorldMatrix) * inTangent.xyz),
                    (inTangent.w < 0.0 ? -1.0 : 1.0) * ob_mirror_sign(mat3(WorldMatrix)));
#endif
#if defined(PARABOLOID)
    gl_Position = ob_paraboloid_position(world.xyz, vHemisphere);
#else
    gl_Position = ViewProjMatrix * world;
#endif
}
