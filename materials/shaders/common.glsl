// common.glsl — declarations shared by Obelisk's standard shaders.
//
// Binding plan (engine/ob_program.h): uniform blocks live in set 0 and are
// packed from parameters whose names equal the member names; images, samplers
// and storage buffers live in set 1 (push descriptors); per-draw data is the
// one push-constant block. Every member is a vec4 or a mat4 because those are
// the parameter types the registry stores.
//
// Space: rendering is camera-relative. WorldMatrix maps model space to world
// space minus the view's origin, ViewMatrix is rotation only, CameraPosition
// is therefore always zero. ProjMatrix is reversed-Z with an infinite far
// plane (depth 1 at the near plane, 0 at infinity) in Vulkan clip space (y
// already flipped).
//
// Lights: one directional light here, as vec4 parameters; point and spot
// lights, any number up to OB_MAX_LIGHTS, come in the PerViewLights block of
// lighting.glsl (a table and a screen-tile grid the views fill per view).
#ifndef OB_COMMON_GLSL
#define OB_COMMON_GLSL

layout(set = 0, binding = 0, std140) uniform PerView {
    mat4 ViewMatrix;           // rotation only
    mat4 ProjMatrix;           // reversed-Z, infinite far plane
    mat4 ViewProjMatrix;       // ProjMatrix * ViewMatrix
    mat4 ShadowMatrices[4];    // camera-relative world -> clip space of shadow cascade i
    vec4 CameraPosition;       // always 0 (camera-relative); kept for shaders
    vec4 ScreenSize;           // width, height, 1/width, 1/height in pixels
    vec4 AmbientColor;         // rgb, w = intensity
    vec4 LightDirection;       // xyz toward the light (need not be unit length)
    vec4 LightColor;           // rgb, w = intensity (0 = no directional light)
    vec4 ParaboloidDirection;  // x: +1 front layer (0), -1 back layer (1); y: near distance
    vec4 ShadowSplits;         // far distance of cascade i's slice along ShadowAxis
    vec4 ShadowCascades;       // x: cascade count (0: none), y: blend band (part of a slice)
    vec4 ShadowAxis;           // xyz: forward of the camera the cascades were fitted for;
                               // distance of p = dot(p, xyz) + w
};

layout(set = 0, binding = 1, std140) uniform PerMaterial {
    vec4 DiffuseColor;         // rgba (unlit.frag; alpha used when blended)
    vec4 SpecularColor;        // unused by the standard shaders (LIT maps it to PbrMaterial)
    vec4 EmissiveColor;        // unused by the standard shaders (LIT maps it to PbrMaterial)
    vec4 Reflectivity;         // x = scale of pbr.frag's environment-map term
};

#if defined(INSTANCED)
// Instanced (the INSTANCED variant): the world matrix comes per instance
// from a vertex buffer of instance rate (binding 1, 48 bytes an instance:
// its three rows, the translation in w), so one draw covers a run of
// entities with one material and mesh. Only the vertex stage reads it; a
// vertex shader says which it is with OB_VERTEX_STAGE before including this
// file. NormalMatrix is derived from it (ob_normal_matrix), as the
// standard shaders do on both paths.
#if defined(OB_VERTEX_STAGE)
layout(location = 8) in vec4 obInstanceRow0;
layout(location = 9) in vec4 obInstanceRow1;
layout(location = 10) in vec4 obInstanceRow2;
#define WorldMatrix mat4(vec4(obInstanceRow0.x, obInstanceRow1.x, obInstanceRow2.x, 0.0), \
                         vec4(obInstanceRow0.y, obInstanceRow1.y, obInstanceRow2.y, 0.0), \
                         vec4(obInstanceRow0.z, obInstanceRow1.z, obInstanceRow2.z, 0.0), \
                         vec4(obInstanceRow0.w, obInstanceRow1.w, obInstanceRow2.w, 1.0))
#define NormalMatrix mat4(ob_normal_matrix(WorldMatrix))
#endif
#else
// 128 bytes: exactly the smallest push-constant limit (lavapipe's).
// NormalMatrix is there for custom effects; the standard shaders derive it
// from WorldMatrix (ob_normal_matrix), as the instanced variant must.
layout(push_constant, std430) uniform PerDraw {
    mat4 WorldMatrix;          // model -> camera-relative world
    mat4 NormalMatrix;         // inverse transpose of WorldMatrix's upper 3x3
};
#endif

// The normal matrix of world matrix w: the cofactor matrix of its upper
// 3x3 (det * inverse-transpose) times the determinant's sign, so normals
// stay outward under a mirror, as the engine's ob_mat3_normal_cofactor
// gives it; of that 3x3 divided by its largest entry first, so that
// nothing under- or overflows at any scale. Its size means nothing:
// normals through it go through ob_unit_normal.
mat3 ob_normal_matrix(mat4 w)
{
    mat3 m = mat3(w);
    vec3 a = max(abs(m[0]), max(abs(m[1]), abs(m[2])));
    float big = max(a.x, max(a.y, a.z));
    if (big > 0.0) m *= 1.0 / big;
    vec3 c0 = cross(m[1], m[2]);
    float s = dot(m[0], c0) < 0.0 ? -1.0 : 1.0;
    return s * mat3(c0, cross(m[2], m[0]), cross(m[0], m[1]));
}

// normalize() of a zero vector is NaN; a zero scale produces zero normals,
// and a NaN would poison the whole pixel (and blending around it).
vec3 ob_safe_normalize(vec3 v)
{
    float len2 = dot(v, v);
    return len2 > 1e-24 ? v * inversesqrt(len2) : vec3(0.0);
}

// NormalMatrix is the cofactor matrix (det * inverse-transpose): its size
// goes as scale^2, so a 1e-6 scale gives normals of length 1e-12, which
// ob_safe_normalize takes for zero. Dividing by the largest component first
// keeps the direction for any finite size; zero stays zero.
vec3 ob_unit_normal(vec3 n)
{
    float m = max(abs(n.x), max(abs(n.y), abs(n.z)));
    return m > 0.0 ? normalize(n / m) : vec3(0.0);
}

// -1 where the world transform mirrors (negative determinant), else 1: the
// bitangent's sign turns with it (the normal matrix keeps normals outward).
// Divided by the largest entry first, so the determinant neither underflows
// nor overflows at any scale.
float ob_mirror_sign(mat3 w)
{
    vec3 a = max(abs(w[0]), max(abs(w[1]), abs(w[2])));
    float m = max(a.x, max(a.y, a.z));
    return m > 0.0 && determinant(w * (1.0 / m)) < 0.0 ? -1.0 : 1.0;
}

#endif
