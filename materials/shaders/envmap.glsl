// envmap.glsl — sampling an entity's environment map (pbr.frag with
// ENVMAP), whichever kind the views layer made for it:
//   EnvMapInfo.x = 0  dual paraboloid: layer 0 the +Z hemisphere, layer 1 -Z
//                     (paraboloid.glsl);
//   EnvMapInfo.x = 1  cube map in a 2D array of six layers, faces +X, -X,
//                     +Y, -Y, +Z, -Z, each a 90-degree perspective view from
//                     the owner's centre (ob_view_cube.c renders them with the
//                     bases of ob_cube_face below: the two must agree);
//   EnvMapInfo.y      the highest mip level (a box-filtered chain of level 0);
//   EnvMapInfo.z      texels per radian of a direction change at level 0, at
//                     the centre of a face or paraboloid half.
// Kept as a 2D array for both kinds: one sampler type, one binding, no cube-
// compatible image; the price is bilinear filtering that does not cross a
// cube face's edge (a faint seam, mostly in blurred levels).
#ifndef OB_ENVMAP_GLSL
#define OB_ENVMAP_GLSL

#include "paraboloid.glsl"

// Face f's forward and up directions in the map's frame.
void ob_cube_face(int f, out vec3 forward, out vec3 up)
{
    const vec3 fwd[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),
                                vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
    const vec3 ups[6] = vec3[6](vec3(0, 1, 0), vec3(0, 1, 0), vec3(0, 0, -1),
                                vec3(0, 0, 1), vec3(0, 1, 0), vec3(0, 1, 0));
    forward = fwd[f];
    up = ups[f];
}

// Texture coordinate and layer of direction d (any length but zero) in the
// cube map. A face's camera looks along forward with up as +Y, right =
// forward x up; Vulkan's clip y points down, texcoord v = 0 is the top row.
vec3 ob_cube_lookup(vec3 d)
{
    vec3 a = abs(d);
    int f = a.x >= a.y && a.x >= a.z ? (d.x >= 0.0 ? 0 : 1)
          : a.y >= a.z               ? (d.y >= 0.0 ? 2 : 3)
                                     : (d.z >= 0.0 ? 4 : 5);
    vec3 fw, up;
    ob_cube_face(f, fw, up);
    vec3 right = cross(fw, up);
    float z = max(dot(d, fw), 1e-20);
    return vec3(vec2(dot(d, right), -dot(d, up)) / z * 0.5 + 0.5, float(f));
}

// Mip level for a reflection lobe `alpha` radians wide (GGX alpha =
// roughness^2 is about the half-width of its lobe): the level whose texel
// covers that angle, from EnvMapInfo.z. A mirror (alpha -> 0) gets level 0.
float ob_env_lod(float alpha)
{
    return clamp(log2(max(alpha * EnvMapInfo.z, 1.0)), 0.0, EnvMapInfo.y);
}

// Radiance the map holds in direction d (map frame) at mip level lod.
vec3 ob_env_sample(sampler2DArray map, vec3 d, float lod)
{
    vec3 uvw = EnvMapInfo.x > 0.5 ? ob_cube_lookup(d) : ob_paraboloid_lookup(d);
    return textureLod(map, uvw, lod).rgb;
}

#endif
