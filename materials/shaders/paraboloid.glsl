// paraboloid.glsl — the dual-paraboloid mapping shared by the map generation
// (pbr.vert with PARABOLOID) and the lookup (envmap.glsl, pbr.frag with ENVMAP).
//
// A direction d, expressed in the map's frame (the paraboloid view's
// ViewMatrix, i.e. the owner's world->local rotation, also bound to lookups as
// EnvMapMatrix), lands in layer 0 when d.z >= 0 (the owner's +Z hemisphere)
// and in layer 1 otherwise, at
//     uv = d.xy / (1 + |d.z|)      in [-1, 1]^2,
// i.e. clip-space xy while generating and texcoord uv * 0.5 + 0.5 when
// sampling (Vulkan: clip y = -1 is the top row, texcoord v = 0 likewise).
#ifndef OB_PARABOLOID_GLSL
#define OB_PARABOLOID_GLSL

// Projection of a unit direction onto the paraboloid of hemisphere `side`
// (+1 front, -1 back). Directions from the other hemisphere map outside the
// unit disc; the denominator is kept away from 0 so they stay finite.
vec2 ob_paraboloid_uv(vec3 d, float side)
{
    return d.xy / max(1.0 + d.z * side, 1e-4);
}

// Texture coordinate and layer of direction d (need not be unit length).
vec3 ob_paraboloid_lookup(vec3 d)
{
    d = ob_safe_normalize(d);
    float side = d.z >= 0.0 ? 1.0 : -1.0;
    return vec3(ob_paraboloid_uv(d, side) * 0.5 + 0.5, side > 0.0 ? 0.0 : 1.0);
}

// Generation: clip position of camera-relative world position `world` in the
// hemisphere ParaboloidDirection.x picks (+1 layer 0, -1 layer 1), and in
// *out_hemisphere how far it lies in that hemisphere (< 0: the other one,
// which the fragment stage discards). ParaboloidDirection.y is the near
// distance (0 -> 0.05): depth is near/dist, reversed-Z like every other view.
// (Needs common.glsl's PerView.)
vec4 ob_paraboloid_position(vec3 world, out float out_hemisphere)
{
    vec3 q = mat3(ViewMatrix) * world;
    float dist = length(q);
    vec3 d = dist > 1e-12 ? q / dist : vec3(0.0, 0.0, 1.0);
    float side = ParaboloidDirection.x >= 0.0 ? 1.0 : -1.0;
    float near_dist = ParaboloidDirection.y > 0.0 ? ParaboloidDirection.y : 0.05;
    out_hemisphere = d.z * side;
    return vec4(ob_paraboloid_uv(d, side), near_dist / max(dist, 1e-12), 1.0);
}

#endif
