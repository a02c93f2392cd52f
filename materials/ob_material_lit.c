/* ob_material_lit.c — LIT and REFLECTIVE as parameter sets of the glTF
 * metallic-roughness model (pbr.frag), so a scene is lit one way.
 *
 * Their parameters were a Blinn-Phong surface's: diffuse colour, specular
 * colour and power, emissive, and for REFLECTIVE an environment mix and a
 * blur roughness. docs/materials.md has the mapping and why; in short:
 *   roughness   (2 / (power + 2))^(1/4): GGX alpha = roughness^2 =
 *               sqrt(2 / (power + 2)), the lobe whose peak and width match
 *               the normalised Blinn-Phong lobe of that power (the OBJ
 *               loader maps Ns the same way); REFLECTIVE: its roughness.
 *   F0          8 ks / (power + 2): the reflectance whose GGX highlight peaks
 *               where the old (unnormalised) ks (n.h)^power did; REFLECTIVE:
 *               at least the mix, the share of the surroundings it mirrors.
 *   base, metallic  from diffuse and F0 by the glTF specular-glossiness to
 *               metallic-roughness conversion: an F0 the dielectric 0.04
 *               covers leaves base = diffuse, metallic 0; above it the metal
 *               share that gives that F0 while keeping the diffuse energy.
 * With metallic_roughness the factors are taken as given instead.
 */
#include "ob_material_internal.h"

#include <math.h>
#include <string.h>

#define DIELECTRIC_F0 0.04f

static float clamp01(float x) { return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x; }

static float perceived(const float c[3])
{
    return sqrtf(0.299f * c[0] * c[0] + 0.587f * c[1] * c[1] + 0.114f * c[2] * c[2]);
}

/* KHR_materials_pbrSpecularGlossiness's converter: the metallic that keeps
 * a surface's diffuse and specular brightness. */
static float solve_metallic(float diffuse, float specular, float one_minus_specular)
{
    if (specular <= DIELECTRIC_F0) return 0.0f;
    const float a = DIELECTRIC_F0;
    const float b = diffuse * one_minus_specular / (1.0f - DIELECTRIC_F0) + specular - 2.0f * DIELECTRIC_F0;
    const float c = DIELECTRIC_F0 - specular;
    const float d = b * b - 4.0f * a * c;
    return clamp01((-b + sqrtf(d > 0.0f ? d : 0.0f)) / (2.0f * a));
}

/* The mapped factors: base (rgb, a = diffuse alpha), metallic, roughness. */
typedef struct lit_factors {
    float base[4], metallic, roughness;
} lit_factors;

static lit_factors map_factors(ob_material_kind kind, const float diffuse[4], const float specular[4],
                               float mix, float roughness, bool given, float metallic)
{
    lit_factors f = {.base = {diffuse[0], diffuse[1], diffuse[2], diffuse[3]}};
    if (given) {
        f.metallic = clamp01(metallic);
        f.roughness = clamp01(roughness);
        return f;
    }
    const float power = specular[3] > 0.0f ? specular[3] : 0.0f;
    f.roughness = kind == OB_MATERIAL_REFLECTIVE ? clamp01(roughness) : powf(2.0f / (power + 2.0f), 0.25f);
    float f0[3];
    for (int k = 0; k < 3; k++) {
        f0[k] = OB_MAX(specular[k], 0.0f) * 8.0f / (power + 2.0f);
        if (kind == OB_MATERIAL_REFLECTIVE) f0[k] = OB_MAX(f0[k], clamp01(mix));
        f0[k] = OB_MIN(OB_MAX(f0[k], DIELECTRIC_F0), 1.0f);   /* the model's floor */
    }
    const float strength = OB_MAX(f0[0], OB_MAX(f0[1], f0[2]));
    f.metallic = solve_metallic(perceived(diffuse), perceived(f0), 1.0f - strength);
    const float m = f.metallic;
    for (int k = 0; k < 3; k++) {
        const float from_diffuse = diffuse[k] * (1.0f - strength) / (1.0f - DIELECTRIC_F0) / OB_MAX(1.0f - m, 1e-6f);
        const float from_specular = (f0[k] - DIELECTRIC_F0 * (1.0f - m)) / OB_MAX(m, 1e-6f);
        f.base[k] = clamp01(from_diffuse + (from_specular - from_diffuse) * m * m);
    }
    return f;
}

void ob_lit_defaults(const ob_material_desc *desc, float diffuse[4], float specular[4])
{
    static const float white[4] = {1, 1, 1, 1}, soft_highlight[4] = {0.25f, 0.25f, 0.25f, 32};
    const float *d = desc->diffuse, *s = desc->specular;
    memcpy(diffuse, (d[0] || d[1] || d[2] || d[3]) ? d : white, 4 * sizeof *diffuse);
    memcpy(specular, (s[0] || s[1] || s[2] || s[3]) ? s : soft_highlight, 4 * sizeof *specular);
}

void ob_lit_refresh(ob_material *m)
{
    if (m->kind != OB_MATERIAL_LIT && m->kind != OB_MATERIAL_REFLECTIVE) return;
    const lit_factors f = map_factors(m->kind, m->diffuse, m->specular, m->reflectivity[0], m->roughness,
                                      m->metallic_roughness, m->metallic);
    float (*block)[4] = m->pbr.block;
    memcpy(block[0], f.base, sizeof block[0]);
    block[1][0] = f.metallic;
    block[1][1] = f.roughness;
    block[1][2] = 1.0f;   /* normal scale, occlusion strength: no maps */
    block[1][3] = 1.0f;
    memcpy(block[2], m->emissive, 3 * sizeof(float));
    block[2][3] = 0.5f;   /* alpha cutoff: no mask */
}

ob_material_desc ob_material_desc_to_pbr(const ob_material_desc *desc)
{
    ob_material_desc out = desc ? *desc : (ob_material_desc){0};
    if (!desc || (desc->kind != OB_MATERIAL_LIT && desc->kind != OB_MATERIAL_REFLECTIVE)) return out;
    float diffuse[4], specular[4];
    ob_lit_defaults(desc, diffuse, specular);
    const float mix = desc->reflectivity != 0.0f ? desc->reflectivity : 0.6f;
    const lit_factors f = map_factors(desc->kind, diffuse, specular, mix, desc->roughness,
                                      desc->metallic_roughness, desc->metallic);
    out.kind = OB_MATERIAL_PBR;
    out.pbr = ob_material_pbr_defaults();
    memcpy(out.pbr.base_color, f.base, sizeof f.base);
    out.pbr.metallic = f.metallic;
    out.pbr.roughness = f.roughness;
    memcpy(out.pbr.emissive, desc->emissive, sizeof out.pbr.emissive);
    out.pbr.alpha_mode = desc->blended ? OB_ALPHA_BLEND : OB_ALPHA_OPAQUE;
    /* The mirror share is in F0 now: the map's term at full strength. */
    out.reflectivity = desc->kind == OB_MATERIAL_REFLECTIVE ? 1.0f : 0.0f;
    out.roughness = 0.0f;
    out.metallic = 0.0f;
    out.metallic_roughness = false;
    return out;
}
