/* LIT and REFLECTIVE as parameter sets of the metallic-roughness model
 * (materials/ob_material_lit.c, docs/materials.md): what a description
 * becomes, each expectation derived from the mapping's definition. No
 * device: ob_material_desc_to_pbr is pure. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include "ob_material.h"
#include "ob_test.h"

/* The reflectance at normal incidence the model draws with. */
static float model_f0(const ob_material_pbr *p, int k)
{
    return 0.04f * (1.0f - p->metallic) + p->base_color[k] * p->metallic;
}

static ob_material_pbr lit(const ob_material_desc *d) { return ob_material_desc_to_pbr(d).pbr; }

/* The faintest highlight ({0, 0, 0, 1}) is a plain dielectric: base colour
 * = diffuse exactly, metallic 0 (F0 the floor 0.04), roughness
 * (2 / (1 + 2))^(1/4). */
static void faintest_highlight_is_a_dielectric(void **state)
{
    (void)state;
    const ob_material_desc d = {.kind = OB_MATERIAL_LIT, .diffuse = {0.8f, 0.4f, 0.2f, 1}, .specular = {0, 0, 0, 1},
                                .emissive = {0.5f, 0.25f, 0, 0}};
    const ob_material_desc out = ob_material_desc_to_pbr(&d);
    assert_int_equal(out.kind, OB_MATERIAL_PBR);
    assert_float_equal(out.reflectivity, 0.0f, 0.0f);
    const ob_material_pbr *p = &out.pbr;
    for (int k = 0; k < 4; k++) assert_float_equal(p->base_color[k], d.diffuse[k], 1e-6f);
    assert_float_equal(p->metallic, 0.0f, 0.0f);
    assert_float_equal(p->roughness, powf(2.0f / 3.0f, 0.25f), 1e-6f);
    for (int k = 0; k < 3; k++) assert_float_equal(p->emissive[k], d.emissive[k], 0.0f);
    assert_int_equal(p->alpha_mode, OB_ALPHA_OPAQUE);
}

/* The default highlight (0.25 grey, power 32): roughness (2/34)^(1/4), and
 * F0 = 8 * 0.25 / 34 (the GGX peak F0 (p + 2) / 8 equal to the old peak
 * 0.25), barely above a dielectric's: almost no metal, the diffuse kept. */
static void default_highlight_keeps_its_peak(void **state)
{
    (void)state;
    const ob_material_pbr p = lit(&(ob_material_desc){.kind = OB_MATERIAL_LIT});
    assert_float_equal(p.roughness, powf(2.0f / 34.0f, 0.25f), 1e-6f);
    const float f0 = 8.0f * 0.25f / 34.0f;
    for (int k = 0; k < 3; k++) assert_float_equal(model_f0(&p, k), f0, 2e-3f);
    assert_true(p.metallic > 0.0f && p.metallic < 0.05f);
    for (int k = 0; k < 3; k++) assert_float_equal(p.base_color[k], 1.0f, 0.02f);
    /* The peak: pi D Vis F0 at n = l = v with D = 1 / (pi a^2), Vis = 1/4. */
    const float a = p.roughness * p.roughness;
    assert_float_equal(model_f0(&p, 0) / (4.0f * a * a), 0.25f, 0.01f);
}

/* A highlight as bright as it can be (F0 = 8 ks / (p + 2) = 1) is a metal:
 * white for a grey highlight, of its colour for a coloured one, whatever
 * the (dark) diffuse. */
static void full_highlight_is_a_metal(void **state)
{
    (void)state;
    const ob_material_pbr grey = lit(&(ob_material_desc){.kind = OB_MATERIAL_LIT, .diffuse = {0.05f, 0.05f, 0.05f, 1},
                                                         .specular = {1, 1, 1, 6}});
    assert_float_equal(grey.metallic, 1.0f, 1e-4f);
    for (int k = 0; k < 3; k++) assert_float_equal(grey.base_color[k], 1.0f, 1e-3f);
    assert_float_equal(grey.roughness, powf(2.0f / 8.0f, 0.25f), 1e-6f);
    const float gold[3] = {1.0f, 0.8f, 0.35f};
    const ob_material_pbr g = lit(&(ob_material_desc){.kind = OB_MATERIAL_LIT, .diffuse = {0.01f, 0.01f, 0.01f, 1},
                                                      .specular = {gold[0], gold[1], gold[2], 6}});
    assert_true(g.metallic > 0.95f);
    for (int k = 0; k < 3; k++) assert_float_equal(model_f0(&g, k), gold[k], 0.03f);
}

/* REFLECTIVE: the mix is the share it mirrors, its F0 (the env term then
 * at full strength, reflectivity 1); its roughness is the model's. */
static void reflective_mix_is_its_reflectance(void **state)
{
    (void)state;
    const float mixes[] = {0.6f, 0.85f, 1.0f};
    for (uint32_t i = 0; i < 3; i++) {
        const ob_material_desc out = ob_material_desc_to_pbr(&(ob_material_desc){
            .kind = OB_MATERIAL_REFLECTIVE, .diffuse = {0.9f, 0.9f, 0.95f, 1}, .reflectivity = mixes[i],
            .roughness = 0.3f});
        assert_float_equal(out.reflectivity, 1.0f, 0.0f);
        assert_float_equal(out.pbr.roughness, 0.3f, 0.0f);
        for (int k = 0; k < 3; k++) assert_float_equal(model_f0(&out.pbr, k), mixes[i], 0.03f);
    }
    /* Defaults: mix 0.6, a mirror (roughness 0). */
    const ob_material_pbr d = lit(&(ob_material_desc){.kind = OB_MATERIAL_REFLECTIVE});
    assert_float_equal(d.roughness, 0.0f, 0.0f);
    assert_float_equal(model_f0(&d, 1), 0.6f, 0.03f);
}

/* metallic_roughness: the factors as given (clamped), base = diffuse; the
 * specular colour and power are not read. Blended keeps the alpha. */
static void given_factors_and_blending(void **state)
{
    (void)state;
    const ob_material_pbr p = lit(&(ob_material_desc){
        .kind = OB_MATERIAL_LIT, .diffuse = {0.3f, 0.5f, 0.9f, 0.4f}, .specular = {1, 1, 1, 6}, .metallic = 0.4f,
        .roughness = 1.5f, .metallic_roughness = true, .blended = true});
    assert_float_equal(p.metallic, 0.4f, 0.0f);
    assert_float_equal(p.roughness, 1.0f, 0.0f);
    const float want[4] = {0.3f, 0.5f, 0.9f, 0.4f};
    for (int k = 0; k < 4; k++) assert_float_equal(p.base_color[k], want[k], 0.0f);
    assert_int_equal(p.alpha_mode, OB_ALPHA_BLEND);
}

/* UNLIT, CUSTOM and PBR descriptions are returned as they are. */
static void other_kinds_unchanged(void **state)
{
    (void)state;
    const ob_material_desc u = {.kind = OB_MATERIAL_UNLIT, .diffuse = {1, 0, 0, 1}};
    const ob_material_desc out = ob_material_desc_to_pbr(&u);
    assert_int_equal(out.kind, OB_MATERIAL_UNLIT);
    assert_float_equal(out.diffuse[0], 1.0f, 0.0f);
    assert_int_equal(ob_material_desc_to_pbr(NULL).kind, OB_MATERIAL_LIT);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(faintest_highlight_is_a_dielectric),
        cmocka_unit_test(default_highlight_keeps_its_peak),
        cmocka_unit_test(full_highlight_is_a_metal),
        cmocka_unit_test(reflective_mix_is_its_reflectance),
        cmocka_unit_test(given_factors_and_blending),
        cmocka_unit_test(other_kinds_unchanged),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
