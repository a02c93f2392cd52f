// paraboloid.glsl — the dual-paraboloid mapping shared by the map generation
// (paraboloid.vert) and the lookup (lit.frag with ENVMAP).
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

#endif
