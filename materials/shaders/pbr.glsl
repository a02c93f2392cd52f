// pbr.glsl — the BRDF of the glTF 2 metallic-roughness material (pbr.frag).
//
//   f(l, v) = f_diffuse + f_specular, evaluated per light as f * E with
//   E = radiance * NdotL, where
//     f_specular = D(h) * Vis(l, v) * F(v, h)               (Cook-Torrance)
//     D   = a^2 / (pi ((n.h)^2 (a^2 - 1) + 1)^2)            GGX / Trowbridge-Reitz, a = roughness^2
//     Vis = G / (4 n.l n.v) = 0.5 / (n.l sqrt((n.v)^2 (1 - a^2) + a^2)
//                                  + n.v sqrt((n.l)^2 (1 - a^2) + a^2))
//                                                           Smith, height-correlated GGX
//     F   = F0 + (1 - F0) (1 - v.h)^5                       Schlick, F0 = mix(0.04, base, metallic)
//     f_diffuse = (1 - F) (1 - metallic) base / pi          Lambert
//
// Light units: the engine's lights are given as radiance at normal
// incidence (LightColor.rgb * w, a local light's colour * intensity times the
// attenuation), and a white Lambert surface facing a unit light shows
// white (diffuse * NdotL, no 1/pi): every BRDF term is multiplied by pi
// (the usual "punctual light intensity" convention), so a white dielectric
// at roughness 1 shows its colour * NdotL up to the Fresnel and specular
// terms. This is the one BRDF: LIT and REFLECTIVE materials draw with it too.
#ifndef OB_PBR_GLSL
#define OB_PBR_GLSL

const float OB_PI = 3.14159265358979;

float ob_ggx_d(float ndoth, float a)
{
    float a2 = a * a;
    float d = ndoth * ndoth * (a2 - 1.0) + 1.0;
    return a2 / max(OB_PI * d * d, 1e-12);
}

float ob_smith_vis(float ndotl, float ndotv, float a)
{
    float a2 = a * a;
    float gv = ndotl * sqrt(ndotv * ndotv * (1.0 - a2) + a2);
    float gl = ndotv * sqrt(ndotl * ndotl * (1.0 - a2) + a2);
    float s = gv + gl;
    return s > 0.0 ? 0.5 / s : 0.0;
}

// x^5 by multiplication: pow() is exp2(5 log2 x) on lavapipe, and every
// lit fragment takes it once per light and once for the ambient term.
float ob_pow5(float x)
{
    float x2 = x * x;
    return x2 * x2 * x;
}

vec3 ob_fresnel_schlick(vec3 f0, float vdoth)
{
    return f0 + (1.0 - f0) * ob_pow5(clamp(1.0 - vdoth, 0.0, 1.0));
}

// Surface description at one fragment.
struct ob_surface {
    vec3 n, v;          // unit normal and direction to the eye
    vec3 base;          // linear base colour
    float metallic;
    float a;            // GGX alpha = roughness^2 (roughness clamped to 0.03 to keep the peak finite)
    vec3 f0;
#if defined(HAS_CLEARCOAT)
    vec3 cn;            // the coat's unit normal (its normal map, else the geometric normal)
    float clearcoat;    // layer intensity in [0, 1]
    float ca;           // the coat's GGX alpha
#endif
};

#if defined(HAS_CLEARCOAT)
// KHR_materials_clearcoat: a dielectric layer (IOR 1.5, F0 = 0.04) with its
// own GGX lobe over the base, which it attenuates by 1 - clearcoat * F_c,
// F_c = Schlick at the coat normal and the view (the Khronos sample
// viewer's layering).
float ob_clearcoat_fresnel(ob_surface s)
{
    float ndotv = clamp(dot(s.cn, s.v), 0.0, 1.0);
    return 0.04 + 0.96 * ob_pow5(1.0 - ndotv);
}

vec3 ob_clearcoat_light(ob_surface s, vec3 l, vec3 radiance)
{
    float ndotl = dot(s.cn, l);
    if (ndotl <= 0.0 || s.clearcoat <= 0.0) return vec3(0.0);
    float ndotv = max(dot(s.cn, s.v), 1e-4);
    vec3 h = ob_safe_normalize(l + s.v);
    float ndoth = max(dot(s.cn, h), 0.0);
    float vdoth = max(dot(s.v, h), 0.0);
    vec3 f = ob_fresnel_schlick(vec3(0.04), vdoth);
    vec3 spec = ob_ggx_d(ndoth, s.ca) * ob_smith_vis(ndotl, ndotv, s.ca) * f;
    return OB_PI * s.clearcoat * spec * radiance * ndotl;
}
#endif

// Contribution of one light of `radiance` arriving from unit direction l
// (pi * f * radiance * NdotL: see the light units above).
// With HAS_CLEARCOAT the coat is layered here, so every light gets it.
vec3 ob_pbr_light(ob_surface s, vec3 l, vec3 radiance)
{
    float ndotl = dot(s.n, l);
#if defined(HAS_CLEARCOAT)
    vec3 coat = ob_clearcoat_light(s, l, radiance);
    if (ndotl <= 0.0) return coat;
#else
    if (ndotl <= 0.0) return vec3(0.0);
#endif
    float ndotv = max(dot(s.n, s.v), 1e-4);
    vec3 h = ob_safe_normalize(l + s.v);
    float ndoth = max(dot(s.n, h), 0.0);
    float vdoth = max(dot(s.v, h), 0.0);
    vec3 f = ob_fresnel_schlick(s.f0, vdoth);
    vec3 spec = ob_ggx_d(ndoth, s.a) * ob_smith_vis(ndotl, ndotv, s.a) * f;
    vec3 diffuse = (1.0 - f) * (1.0 - s.metallic) * s.base / OB_PI;
#if defined(HAS_CLEARCOAT)
    return OB_PI * (diffuse + spec) * radiance * ndotl * (1.0 - s.clearcoat * ob_clearcoat_fresnel(s)) + coat;
#else
    return OB_PI * (diffuse + spec) * radiance * ndotl;
#endif
}

// Fresnel for the environment and ambient terms, where no single half
// vector exists: Schlick at n.v with the roughness-limited reflectance
// (Fdez-Aguera's max(1 - roughness, F0) form).
vec3 ob_fresnel_ambient(ob_surface s)
{
    float ndotv = max(dot(s.n, s.v), 0.0);
    float roughness = sqrt(s.a);
    vec3 fmax = max(vec3(1.0 - roughness), s.f0);
    return s.f0 + (fmax - s.f0) * ob_pow5(1.0 - ndotv);
}

#endif
