/* Parameter registry and managers: slots, value ids, derived matrices,
 * resources, packing against a reflected layout, and every refused input. */
#include "ob_test.h"
#include "ob_params.h"

#include <cglm/cglm.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define SLOTS 4u

static ob_param_registry *make_registry(uint32_t slots)
{
    ob_result r;
    ob_param_registry *reg = ob_param_registry_create(&(ob_param_registry_desc){slots}, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(reg);
    return reg;
}

static ob_params manager(ob_param_registry *reg, uint32_t slot)
{
    ob_params pm;
    assert_int_equal(ob_params_manager(reg, slot, &pm), OB_OK);
    return pm;
}

static ob_param reg_param(ob_param_registry *reg, const char *name, ob_param_type type,
                          uint32_t count)
{
    ob_result r;
    ob_param p = ob_param_register(reg, name, type, count, &r);
    assert_int_equal(r, OB_OK);
    assert_int_not_equal(p.id, 0);
    return p;
}

static void assert_mat4_near(const float *a, const float *b, float eps)
{
    for (int i = 0; i < 16; i++) {
        if (fabsf(a[i] - b[i]) > eps) fail_msg("element %d: %g vs %g", i, a[i], b[i]);
    }
}

static void get_mat(ob_params *pm, ob_param p, mat4 out)
{
    assert_int_equal(ob_params_get_mat4(pm, p, &out[0][0]), OB_OK);
}

/* ------------------------------------------------------------------ slots */

static void write_to_one_slot_is_invisible_in_others(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    ob_param color = reg_param(reg, "Color", OB_PARAM_VEC4, 1);
    ob_param xform = reg_param(reg, "Xform", OB_PARAM_MAT4, 1);
    ob_param blob = reg_param(reg, "Blob", OB_PARAM_BYTES, 12);
    ob_params pm2 = manager(reg, 2);
    const float v[4] = {1, 2, 3, 4};
    float m[16];
    for (int i = 0; i < 16; i++) m[i] = (float)i;
    const uint8_t bytes[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    assert_int_equal(ob_params_set_vec4(&pm2, color, v), OB_OK);
    assert_int_equal(ob_params_set_mat4(&pm2, xform, m), OB_OK);
    assert_int_equal(ob_params_set_bytes(&pm2, blob, bytes, 12), OB_OK);

    for (uint32_t s = 0; s < SLOTS; s++) {
        ob_params pm = manager(reg, s);
        float got[16];
        uint8_t gb[12];
        assert_int_equal(ob_params_get_vec4(&pm, color, got), OB_OK);
        assert_int_equal(memcmp(got, s == 2 ? v : (float[4]){0}, 16), 0);
        assert_int_equal(ob_params_get_mat4(&pm, xform, got), OB_OK);
        assert_true(s == 2 ? memcmp(got, m, 64) == 0 : got[5] == 0.0f && got[15] == 0.0f);
        assert_int_equal(ob_params_get_bytes(&pm, blob, 12, gb), OB_OK);
        assert_true(s == 2 ? memcmp(gb, bytes, 12) == 0 : gb[0] == 0 && gb[11] == 0);
        assert_int_equal(ob_params_value_id(&pm, color), s == 2 ? 1 : 0);
    }
    ob_param_registry_destroy(reg);
}

static void init_writes_every_slot(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    ob_param color = reg_param(reg, "Color", OB_PARAM_VEC4, 1);
    ob_param tex = reg_param(reg, "ColorMap", OB_PARAM_TEXTURE, 1);
    const float v[4] = {0.5f, 0.25f, 1, 1};
    assert_int_equal(ob_params_init_vec4(reg, color, v), OB_OK);
    assert_int_equal(ob_params_init_texture(reg, tex, (ob_image){77}), OB_OK);
    for (uint32_t s = 0; s < SLOTS; s++) {
        ob_params pm = manager(reg, s);
        float got[4];
        ob_image img;
        assert_int_equal(ob_params_get_vec4(&pm, color, got), OB_OK);
        assert_memory_equal(got, v, 16);
        assert_int_equal(ob_params_get_texture(&pm, tex, &img), OB_OK);
        assert_int_equal(img.id, 77);
        assert_int_equal(ob_params_value_id(&pm, color), 1);
    }
    /* init while workers record would race their slots. */
    ob_test_log_clear();
    ob_param_registry_begin_recording(reg);
    assert_int_equal(ob_params_init_vec4(reg, color, (float[4]){9, 9, 9, 9}), OB_ERR_WRONG_STATE);
    ob_param_registry_end_recording(reg);
    assert_true(ob_test_log_has("[params]", "init_vec4", "Color", "recording", NULL));
    ob_params pm = manager(reg, 3);
    float got[4];
    ob_params_get_vec4(&pm, color, got);
    assert_memory_equal(got, v, 16);
    ob_param_registry_destroy(reg);
}

static void value_id_moves_only_on_real_change(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(2);
    ob_param color = reg_param(reg, "Color", OB_PARAM_VEC4, 1);
    ob_params pm = manager(reg, 1);
    const float zero[4] = {0}, one[4] = {1, 1, 1, 1};
    assert_int_equal(ob_params_value_id(&pm, color), 0);
    /* The first write counts even if it stores the initial zeros. */
    ob_params_set_vec4(&pm, color, zero);
    assert_int_equal(ob_params_value_id(&pm, color), 1);
    ob_params_set_vec4(&pm, color, zero);
    assert_int_equal(ob_params_value_id(&pm, color), 1);
    ob_params_set_vec4(&pm, color, one);
    ob_params_set_vec4(&pm, color, one);
    assert_int_equal(ob_params_value_id(&pm, color), 2);
    ob_params_set_vec4(&pm, color, zero);
    assert_int_equal(ob_params_value_id(&pm, color), 3);

    /* Derived matrices follow the same rule. */
    const ob_param_builtins *b = ob_param_registry_builtins(reg);
    mat4 w;
    glm_translate_make(w, (vec3){1, 2, 3});
    ob_params_set_mat4(&pm, b->world, &w[0][0]);
    ob_params_set_mat4(&pm, b->world, &w[0][0]);
    assert_int_equal(ob_params_value_id(&pm, b->world), 1);
    assert_int_equal(ob_params_value_id(&pm, b->world_view_proj), 1);
    /* A new translation leaves the normal matrix as it was. */
    glm_translate_make(w, (vec3){4, 5, 6});
    ob_params_set_mat4(&pm, b->world, &w[0][0]);
    assert_int_equal(ob_params_value_id(&pm, b->world_view_proj), 2);
    assert_int_equal(ob_params_value_id(&pm, b->normal), 1);
    assert_int_equal(ob_params_value_id(&pm, b->view_proj), 0);
    ob_param_registry_destroy(reg);
}

/* --------------------------------------------------------- derived matrices */

static void derived_matrices_match_cglm(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    const ob_param_builtins *b = ob_param_registry_builtins(reg);
    ob_params pm = manager(reg, 1);
    mat4 world, view, proj, got, ref, tmp;

    /* Identity until written. */
    get_mat(&pm, b->world_view_proj, got);
    glm_mat4_identity(ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 0);

    glm_euler_xyz((vec3){0.3f, -0.7f, 1.1f}, world);
    glm_scale(world, (vec3){2.0f, 0.5f, 3.0f});
    world[3][0] = 1.5f, world[3][1] = -2.0f, world[3][2] = 4.0f;
    glm_lookat((vec3){3, 4, 5}, (vec3){0, 0, 0}, (vec3){0, 1, 0}, view);
    glm_perspective(glm_rad(60.0f), 16.0f / 9.0f, 0.1f, 100.0f, proj);
    assert_int_equal(ob_params_set_mat4(&pm, b->view, &view[0][0]), OB_OK);
    assert_int_equal(ob_params_set_mat4(&pm, b->proj, &proj[0][0]), OB_OK);
    assert_int_equal(ob_params_set_mat4(&pm, b->world, &world[0][0]), OB_OK);

    get_mat(&pm, b->world_view, got);
    glm_mat4_mul(view, world, ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 1e-6f);
    get_mat(&pm, b->view_proj, got);
    glm_mat4_mul(proj, view, ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 1e-6f);
    get_mat(&pm, b->world_view_proj, got);
    glm_mat4_mul(proj, view, tmp);
    glm_mat4_mul(tmp, world, ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 1e-6f);

    /* NormalMatrix = det(W3) * inverse-transpose(W3) in the upper 3x3. */
    mat3 w3, inv;
    glm_mat4_pick3(world, w3);
    float det = glm_mat3_det(w3);
    glm_mat3_inv(w3, inv);
    glm_mat3_transpose(inv);
    get_mat(&pm, b->normal, got);
    for (int c = 0; c < 3; c++)
        for (int r = 0; r < 3; r++) assert_float_equal(got[c][r], det * inv[c][r], 1e-4);
    assert_float_equal(got[3][3], 1.0f, 0);

    /* Other slots are untouched. */
    ob_params pm0 = manager(reg, 0);
    get_mat(&pm0, b->world_view_proj, got);
    glm_mat4_identity(ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 0);

    /* Zero scale: the cofactor matrix stays finite (zero), no NaN. */
    mat4 flat;
    glm_scale_make(flat, (vec3){1.0f, 0.0f, 1.0f});
    assert_int_equal(ob_params_set_mat4(&pm, b->world, &flat[0][0]), OB_OK);
    get_mat(&pm, b->normal, got);
    for (int i = 0; i < 16; i++) assert_true(isfinite((&got[0][0])[i]));
    glm_scale_make(flat, (vec3){0.0f, 0.0f, 0.0f});
    assert_int_equal(ob_params_set_mat4(&pm, b->world, &flat[0][0]), OB_OK);
    get_mat(&pm, b->normal, got);
    for (int i = 0; i < 16; i++) assert_true(isfinite((&got[0][0])[i]));

    /* init of a source recomputes every slot against that slot's world. */
    ob_params pm3 = manager(reg, 3);
    assert_int_equal(ob_params_set_mat4(&pm3, b->world, &world[0][0]), OB_OK);
    assert_int_equal(ob_params_init_mat4(reg, b->view, &view[0][0]), OB_OK);
    assert_int_equal(ob_params_init_mat4(reg, b->proj, &proj[0][0]), OB_OK);
    get_mat(&pm3, b->world_view_proj, got);
    glm_mat4_mul(proj, view, tmp);
    glm_mat4_mul(tmp, world, ref);
    assert_mat4_near(&got[0][0], &ref[0][0], 1e-6f);
    get_mat(&pm0, b->world_view_proj, got);
    assert_mat4_near(&got[0][0], &tmp[0][0], 1e-6f);
    ob_param_registry_destroy(reg);
}

/* ------------------------------------------------------ arrays, resources */

static void mat4_arrays_are_per_slot(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    ob_param bones = reg_param(reg, "Bones", OB_PARAM_MAT4_ARRAY, 4);
    assert_int_equal(ob_param_count(reg, bones), 4);
    assert_int_equal(ob_param_value_size(reg, bones), 256);
    ob_params pm1 = manager(reg, 1), pm2 = manager(reg, 2);
    float in[5 * 16], got[4 * 16];
    for (int i = 0; i < 5 * 16; i++) in[i] = (float)(i + 1);

    assert_int_equal(ob_params_set_mat4_array(&pm1, bones, in, 2), OB_OK);
    assert_int_equal(ob_params_get_mat4_array(&pm1, bones, 4, got), OB_OK);
    assert_memory_equal(got, in, 2 * 64);
    for (int i = 2 * 16; i < 4 * 16; i++) assert_float_equal(got[i], 0.0f, 0);
    assert_int_equal(ob_params_get_mat4_array(&pm2, bones, 4, got), OB_OK);
    for (int i = 0; i < 4 * 16; i++) assert_float_equal(got[i], 0.0f, 0);

    /* One element in the middle, e.g. a single bone. */
    assert_int_equal(ob_params_set_mat4_array_at(&pm2, bones, 3, in + 16, 1), OB_OK);
    assert_int_equal(ob_params_get_mat4_array_at(&pm2, bones, 3, 1, got), OB_OK);
    assert_memory_equal(got, in + 16, 64);

    ob_test_log_clear();
    uint64_t id = ob_params_value_id(&pm1, bones);
    assert_int_equal(ob_params_set_mat4_array(&pm1, bones, in + 16, 5), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("[params]", "Bones", "slot 1", NULL));
    assert_int_equal(ob_params_set_mat4_array_at(&pm1, bones, 3, in, 2), OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_params_set_mat4_array_at(&pm1, bones, UINT32_MAX, in, 2),
                     OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_params_get_mat4_array(&pm1, bones, 5, got), OB_ERR_OUT_OF_RANGE);
    assert_int_equal(ob_params_value_id(&pm1, bones), id);
    assert_int_equal(ob_params_get_mat4_array(&pm1, bones, 4, got), OB_OK);
    assert_memory_equal(got, in, 2 * 64);

    assert_int_equal(ob_params_init_mat4_array(reg, bones, in, 4), OB_OK);
    assert_int_equal(ob_params_get_mat4_array(&pm2, bones, 4, got), OB_OK);
    assert_memory_equal(got, in, 4 * 64);
    ob_param_registry_destroy(reg);
}

static void resource_params_are_per_slot(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    ob_param tex = reg_param(reg, "ColorMap", OB_PARAM_TEXTURE, 1);
    ob_param smp = reg_param(reg, "LinearClamp", OB_PARAM_SAMPLER, 1);
    ob_param ubo = reg_param(reg, "Lights", OB_PARAM_UNIFORM_BUFFER, 1);
    ob_param ssbo = reg_param(reg, "Particles", OB_PARAM_STORAGE_BUFFER, 1);
    for (uint32_t s = 0; s < SLOTS; s++) {
        ob_params pm = manager(reg, s);
        assert_int_equal(ob_params_set_texture(&pm, tex, (ob_image){100 + s}), OB_OK);
        assert_int_equal(ob_params_set_sampler(&pm, smp, (ob_sampler){200 + s}), OB_OK);
        assert_int_equal(ob_params_set_buffer(&pm, ubo, (ob_buffer){300 + s}), OB_OK);
        assert_int_equal(ob_params_set_buffer(&pm, ssbo, (ob_buffer){400 + s}), OB_OK);
    }
    for (uint32_t s = 0; s < SLOTS; s++) {
        ob_params pm = manager(reg, s);
        ob_image img;
        ob_sampler sm;
        ob_buffer b;
        assert_int_equal(ob_params_get_texture(&pm, tex, &img), OB_OK);
        assert_int_equal(img.id, 100 + s);
        assert_int_equal(ob_params_get_sampler(&pm, smp, &sm), OB_OK);
        assert_int_equal(sm.id, 200 + s);
        assert_int_equal(ob_params_get_buffer(&pm, ubo, &b), OB_OK);
        assert_int_equal(b.id, 300 + s);
        assert_int_equal(ob_params_get_buffer(&pm, ssbo, &b), OB_OK);
        assert_int_equal(b.id, 400 + s);
        assert_int_equal(*(const uint32_t *)ob_params_value_ptr(&pm, tex), 100 + s);
    }
    ob_params pm = manager(reg, 1);
    ob_test_log_clear();
    assert_int_equal(ob_params_set_texture(&pm, smp, (ob_image){1}), OB_ERR_TYPE_MISMATCH);
    assert_true(ob_test_log_has("[params]", "LinearClamp", "slot 1", "sampler", NULL));
    assert_int_equal(ob_params_set_buffer(&pm, tex, (ob_buffer){1}), OB_ERR_TYPE_MISMATCH);
    ob_sampler sm;
    assert_int_equal(ob_params_get_sampler(&pm, smp, &sm), OB_OK);
    assert_int_equal(sm.id, 201);
    ob_param_registry_destroy(reg);
}

/* ---------------------------------------------------------------- packing */

static ob_block_member member(const char *name, ob_member_type type, uint32_t offset,
                              uint32_t size, uint32_t array_len, uint32_t stride)
{
    ob_block_member m = {.type = type, .offset = offset, .size = size,
                         .array_len = array_len, .array_stride = stride};
    snprintf(m.name, sizeof m.name, "%s", name);
    return m;
}

static void packing_follows_reflected_layout(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    const ob_param_builtins *b = ob_param_registry_builtins(reg);
    ob_param bones = reg_param(reg, "Bones", OB_PARAM_MAT4_ARRAY, 4);
    ob_param tint = reg_param(reg, "Tint", OB_PARAM_VEC4, 1);
    ob_param wrong = reg_param(reg, "Wrong", OB_PARAM_VEC4, 1);
    ob_param light = reg_param(reg, "Light", OB_PARAM_BYTES, 32);
    ob_param many = reg_param(reg, "Many", OB_PARAM_MAT4_ARRAY, 2);
    /* std140: mat4 at 0, mat4[3] at 64 (stride 64), vec4s at 256.., a struct
     * of 32 bytes at 304, then members that must stay zero. */
    ob_block_member members[] = {
        member("WorldMatrix", OB_MEMBER_MAT4, 0, 64, 0, 0),
        member("Bones", OB_MEMBER_MAT4, 64, 192, 3, 64),
        member("Tint", OB_MEMBER_VEC4, 256, 16, 0, 0),
        member("Missing", OB_MEMBER_VEC4, 272, 16, 0, 0),
        member("Wrong", OB_MEMBER_MAT4, 288, 64, 0, 0),
        member("Light", OB_MEMBER_OTHER, 352, 32, 0, 0),
        member("Many", OB_MEMBER_MAT4, 384, 192, 3, 64),
    };
    ob_block_layout layout = {.name = "PerDraw", .size = 576,
                              .member_count = OB_ARRAY_COUNT(members), .members = members};
    ob_test_log_clear();
    ob_result r;
    ob_param_mapping *map = ob_param_mapping_create(reg, &layout, "lit.frag", &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(map);
    assert_int_equal(ob_param_mapping_block_size(map), 576);
    assert_int_equal(ob_param_mapping_unmapped_count(map), 3);
    assert_true(ob_test_log_has("[params]", "lit.frag", "Missing", NULL));
    assert_true(ob_test_log_has("[params]", "lit.frag", "'Wrong'", "vec4", NULL));
    assert_true(ob_test_log_has("[params]", "lit.frag", "'Many'", NULL));
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 3);

    ob_params pm = manager(reg, 2);
    mat4 w;
    glm_translate_make(w, (vec3){1, 2, 3});
    float bone[3 * 16], t[4] = {0.1f, 0.2f, 0.3f, 1.0f}, wv[4] = {7, 7, 7, 7};
    uint8_t lb[32];
    for (int i = 0; i < 48; i++) bone[i] = (float)(i + 1);
    for (int i = 0; i < 32; i++) lb[i] = (uint8_t)(0xc0 + i);
    ob_params_set_mat4(&pm, b->world, &w[0][0]);
    ob_params_set_mat4_array(&pm, bones, bone, 3);
    ob_params_set_vec4(&pm, tint, t);
    ob_params_set_vec4(&pm, wrong, wv);
    ob_params_set_bytes(&pm, light, lb, 32);
    ob_params_set_mat4_array(&pm, many, bone, 2);

    uint8_t block[576];
    memset(block, 0xab, sizeof block);
    assert_true(ob_params_pack_needed(&pm, map));
    assert_true(ob_params_pack(&pm, map, block, false));
    assert_memory_equal(block, w, 64);
    for (int k = 0; k < 3; k++) assert_memory_equal(block + 64 + 64 * k, bone + 16 * k, 64);
    assert_memory_equal(block + 256, t, 16);
    assert_memory_equal(block + 352, lb, 32);
    for (int i = 272; i < 352; i++) assert_int_equal(block[i], 0);
    for (int i = 384; i < 576; i++) assert_int_equal(block[i], 0);

    /* Nothing changed: no repack; the same value again is no change either. */
    memset(block, 0xab, sizeof block);
    assert_false(ob_params_pack_needed(&pm, map));
    ob_params_set_vec4(&pm, tint, t);
    assert_false(ob_params_pack(&pm, map, block, false));
    assert_int_equal(block[0], 0xab);
    /* Unmapped parameters do not trigger a repack. */
    ob_params_set_vec4(&pm, wrong, (float[4]){8, 8, 8, 8});
    assert_false(ob_params_pack_needed(&pm, map));
    /* A real change does; force always writes. */
    t[0] = 0.9f;
    ob_params_set_vec4(&pm, tint, t);
    assert_true(ob_params_pack_needed(&pm, map));
    assert_true(ob_params_pack(&pm, map, block, false));
    assert_memory_equal(block + 256, t, 16);
    assert_true(ob_params_pack(&pm, map, block, true));

    /* Slots pack independently. */
    ob_params pm0 = manager(reg, 0);
    assert_true(ob_params_pack_needed(&pm0, map));
    assert_true(ob_params_pack(&pm0, map, block, false));
    mat4 id;
    glm_mat4_identity(id);
    assert_memory_equal(block, id, 64);
    assert_false(ob_params_pack_needed(&pm, map));

    uint64_t *u0 = ob_param_mapping_slot_user(map, 0), *u2 = ob_param_mapping_slot_user(map, 2);
    assert_non_null(u0);
    assert_int_equal(*u2, 0);
    *u2 = 4096;
    assert_int_equal(*u0, 0);
    assert_int_equal(*ob_param_mapping_slot_user(map, 2), 4096);
    assert_true((uintptr_t)u2 / OB_CACHE_LINE != (uintptr_t)u0 / OB_CACHE_LINE);

    /* Packing never logs again about the unmapped members. */
    assert_int_equal(ob_test_log_count(OB_LOG_WARN), 3);
    assert_null(ob_param_mapping_slot_user(map, SLOTS));
    ob_params bad = {reg, SLOTS};
    assert_false(ob_params_pack(&bad, map, block, true));
    assert_true(ob_test_log_has("[params]", "pack", "slot 4", NULL));
    ob_param_mapping_destroy(map);

    /* A member reaching past the block is refused, not packed out of bounds. */
    ob_block_member past = member("Tint", OB_MEMBER_VEC4, 60, 16, 0, 0);
    ob_block_layout small = {.name = "Small", .size = 64, .member_count = 1, .members = &past};
    ob_test_log_clear();
    map = ob_param_mapping_create(reg, &small, "tiny.vert", &r);
    assert_int_equal(r, OB_OK);
    assert_int_equal(ob_param_mapping_unmapped_count(map), 1);
    assert_true(ob_test_log_has("tiny.vert", "Tint", "past", NULL));
    ob_param_mapping_destroy(map);
    ob_param_registry_destroy(reg);
}

/* ----------------------------------------------------------- refused input */

static void bad_input_is_refused_logged_and_harmless(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    const ob_param_builtins *b = ob_param_registry_builtins(reg);
    ob_param color = reg_param(reg, "Color", OB_PARAM_VEC4, 1);
    ob_param blob = reg_param(reg, "Blob", OB_PARAM_BYTES, 8);
    ob_params pm = manager(reg, 2);
    const float good[4] = {1, 2, 3, 4};
    ob_params_set_vec4(&pm, color, good);
    const uint8_t gb[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    ob_params_set_bytes(&pm, blob, gb, 8);
    mat4 m, saved;
    glm_mat4_identity(m);
    float nan_v[4] = {1, NAN, 3, 4};

    ob_test_log_clear();
    assert_int_equal(ob_params_set_mat4(&pm, color, &m[0][0]), OB_ERR_TYPE_MISMATCH);
    assert_true(ob_test_log_has("[params]", "set_mat4", "Color", "slot 2", NULL));
    ob_test_log_clear();
    assert_int_equal(ob_params_set_vec4(&pm, color, nan_v), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("[params]", "Color", "slot 2", "NaN", NULL));
    ob_test_log_clear();
    assert_int_equal(ob_params_set_bytes(&pm, blob, gb, 7), OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("[params]", "Blob", "slot 2", "7 bytes", NULL));
    assert_int_equal(ob_params_set_vec4(&pm, (ob_param){0}, good), OB_ERR_INVALID_HANDLE);
    ob_param stale = {color.id + (1u << OB_HANDLE_INDEX_BITS)};
    ob_test_log_clear();
    assert_int_equal(ob_params_set_vec4(&pm, stale, good), OB_ERR_INVALID_HANDLE);
    assert_true(ob_test_log_has("[params]", "stale", "slot 2", NULL));
    assert_int_equal(ob_params_set_vec4(&pm, (ob_param){0xfffff}, good), OB_ERR_INVALID_HANDLE);
    float out[4] = {0};
    assert_int_equal(ob_params_get_vec4(&pm, stale, out), OB_ERR_INVALID_HANDLE);
    assert_null(ob_params_value_ptr(&pm, stale));
    assert_int_equal(ob_params_value_id(&pm, stale), 0);
    assert_null(ob_param_name(reg, stale));
    assert_int_equal(ob_param_get_type(reg, stale), OB_PARAM_TYPE_COUNT);

    /* Slot out of range, from the manager call or a hand-made manager. */
    ob_params out_of_range;
    ob_test_log_clear();
    assert_int_equal(ob_params_manager(reg, SLOTS, &out_of_range), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("[params]", "slot 4", NULL));
    ob_params forged = {reg, 9};
    ob_test_log_clear();
    assert_int_equal(ob_params_set_vec4(&forged, color, good), OB_ERR_OUT_OF_RANGE);
    assert_true(ob_test_log_has("[params]", "Color", "slot 9", NULL));
    assert_int_equal(ob_params_get_vec4(&forged, color, out), OB_ERR_OUT_OF_RANGE);

    /* Inf in a matrix, and finite matrices whose product overflows. */
    float inf_m[16];
    memcpy(inf_m, m, 64);
    inf_m[5] = INFINITY;
    ob_test_log_clear();
    assert_int_equal(ob_params_set_mat4(&pm, b->world, inf_m), OB_ERR_NON_FINITE);
    assert_true(ob_test_log_has("[params]", "WorldMatrix", "slot 2", NULL));
    glm_scale_make(m, (vec3){1e30f, 1e30f, 1e30f});
    assert_int_equal(ob_params_set_mat4(&pm, b->view, &m[0][0]), OB_OK);
    assert_int_equal(ob_params_set_mat4(&pm, b->world, &m[0][0]), OB_ERR_NON_FINITE);
    assert_int_equal(ob_params_init_mat4(reg, b->world, &m[0][0]), OB_ERR_NON_FINITE);
    assert_int_equal(ob_params_value_id(&pm, b->world), 0);
    get_mat(&pm, b->world, m);
    glm_mat4_identity(saved);
    assert_mat4_near(&m[0][0], &saved[0][0], 0);

    /* The earlier good values survived every refused write. */
    assert_int_equal(ob_params_get_vec4(&pm, color, out), OB_OK);
    assert_memory_equal(out, good, 16);
    assert_int_equal(ob_params_value_id(&pm, color), 1);
    uint8_t gotb[8];
    assert_int_equal(ob_params_get_bytes(&pm, blob, 8, gotb), OB_OK);
    assert_memory_equal(gotb, gb, 8);
    assert_int_equal(ob_params_get_bytes(&pm, blob, 9, gotb), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_params_set_vec4(&pm, color, NULL), OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_params_set_vec4(NULL, color, good), OB_ERR_INVALID_ARGUMENT);
    ob_param_registry_destroy(reg);
}

static void registration_rules(void **state)
{
    (void)state;
    ob_param_registry *reg = make_registry(SLOTS);
    uint32_t builtins = ob_param_registry_param_count(reg);
    assert_int_equal(builtins, 7);
    const ob_param_builtins *b = ob_param_registry_builtins(reg);
    assert_int_equal(ob_param_find(reg, "WorldViewProjMatrix").id, b->world_view_proj.id);
    assert_string_equal(ob_param_name(reg, b->normal), "NormalMatrix");
    assert_int_equal(ob_param_find(reg, "NoSuchThing").id, 0);

    ob_result r;
    ob_param bones = reg_param(reg, "Bones", OB_PARAM_MAT4_ARRAY, 8);
    assert_int_equal(ob_param_register(reg, "Bones", OB_PARAM_MAT4_ARRAY, 8, &r).id, bones.id);
    assert_int_equal(r, OB_OK);
    ob_test_log_clear();
    assert_int_equal(ob_param_register(reg, "Bones", OB_PARAM_VEC4, 1, &r).id, 0);
    assert_int_equal(r, OB_ERR_DUPLICATE);
    assert_true(ob_test_log_has("[params]", "Bones", "mat4 array", NULL));
    assert_int_equal(ob_param_register(reg, "Bones", OB_PARAM_MAT4_ARRAY, 9, &r).id, 0);
    assert_int_equal(r, OB_ERR_DUPLICATE);
    assert_int_equal(ob_param_register(reg, "WorldMatrix", OB_PARAM_MAT4, 1, &r).id, b->world.id);
    assert_int_equal(ob_param_get_type(reg, bones), OB_PARAM_MAT4_ARRAY);

    ob_param_registry_begin_recording(reg);
    ob_test_log_clear();
    assert_int_equal(ob_param_register(reg, "Late", OB_PARAM_VEC4, 1, &r).id, 0);
    assert_int_equal(r, OB_ERR_WRONG_STATE);
    assert_true(ob_test_log_has("[params]", "Late", "recording", NULL));
    ob_param_registry_end_recording(reg);
    reg_param(reg, "Late", OB_PARAM_VEC4, 1);

    assert_int_equal(ob_param_register(reg, "", OB_PARAM_VEC4, 1, &r).id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_param_register(reg, "NoCount", OB_PARAM_BYTES, 0, &r).id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_int_equal(ob_param_register(reg, "Huge", OB_PARAM_MAT4_ARRAY, 1u << 20, &r).id, 0);
    assert_int_equal(r, OB_ERR_LIMIT);

    /* The name table grows; every name still resolves to its handle. */
    ob_param many[500];
    char name[32];
    for (int i = 0; i < 500; i++) {
        snprintf(name, sizeof name, "P%d", i);
        many[i] = reg_param(reg, name, i % 2 ? OB_PARAM_VEC4 : OB_PARAM_SAMPLER, 1);
    }
    for (int i = 0; i < 500; i++) {
        snprintf(name, sizeof name, "P%d", i);
        assert_int_equal(ob_param_find(reg, name).id, many[i].id);
    }
    assert_int_equal(ob_param_registry_param_count(reg), builtins + 2 + 500);
    ob_param_registry_destroy(reg);

    assert_null(ob_param_registry_create(&(ob_param_registry_desc){OB_PARAM_MAX_SLOTS + 1}, &r));
    assert_int_equal(r, OB_ERR_OUT_OF_RANGE);
    reg = ob_param_registry_create(NULL, &r);
    assert_int_equal(ob_param_registry_slot_count(reg), 1);
    ob_param_registry_destroy(reg);
}

/* Builds a registry, registers parameters and maps a block: one walk of
 * every host allocation on the path. Returns the first failure. */
static ob_result build_everything(void)
{
    ob_result r;
    ob_param_registry *reg = ob_param_registry_create(&(ob_param_registry_desc){9}, &r);
    if (!reg) return r;
    char name[32];
    for (int i = 0; i < 40 && r == OB_OK; i++) {
        snprintf(name, sizeof name, "Param%d", i);
        ob_param p = ob_param_register(reg, name, i % 3 ? OB_PARAM_VEC4 : OB_PARAM_MAT4_ARRAY,
                                       3, &r);
        if (r == OB_OK && !p.id) fail_msg("OB_OK without a handle");
    }
    if (r == OB_OK) {
        ob_block_member m[] = {member("Param1", OB_MEMBER_VEC4, 0, 16, 0, 0),
                               member("Param0", OB_MEMBER_MAT4, 64, 192, 3, 64)};
        ob_block_layout layout = {.name = "B", .size = 256, .member_count = 2, .members = m};
        ob_param_mapping *map = ob_param_mapping_create(reg, &layout, "fault.frag", &r);
        if (map && r != OB_OK) fail_msg("mapping returned with an error");
        ob_param_mapping_destroy(map);
    }
    ob_param_registry_destroy(reg);
    return r;
}

static void host_allocation_failures_are_clean(void **state)
{
    (void)state;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_int_equal(build_everything(), OB_OK);
    uint64_t total = ob_fault_count(OB_FAULT_HOST_ALLOC);
    assert_true(total > 10);
    for (uint64_t n = 1; n <= total; n++) {
        ob_test_log_clear();
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        ob_result r = build_everything();
        assert_true(ob_fault_hit(OB_FAULT_HOST_ALLOC));
        if (r != OB_ERR_OUT_OF_HOST_MEMORY)
            fail_msg("allocation %llu: got %s", (unsigned long long)n, ob_result_name(r));
        assert_true(ob_test_log_has("[params]", "out of host memory", NULL));
    }
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(write_to_one_slot_is_invisible_in_others),
        cmocka_unit_test(init_writes_every_slot),
        cmocka_unit_test(value_id_moves_only_on_real_change),
        cmocka_unit_test(derived_matrices_match_cglm),
        cmocka_unit_test(mat4_arrays_are_per_slot),
        cmocka_unit_test(resource_params_are_per_slot),
        cmocka_unit_test(packing_follows_reflected_layout),
        cmocka_unit_test(bad_input_is_refused_logged_and_harmless),
        cmocka_unit_test(registration_rules),
        cmocka_unit_test(host_allocation_failures_are_clean),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
