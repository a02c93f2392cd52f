/* Many workers hammering their own slots at once, with no locks: every read
 * returns what that thread wrote, no slot sees another's writes, and packing
 * one shared mapping concurrently gives each slot its own bytes. Run it under
 * -DOB_SANITIZE=thread as well. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_params.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

#define WORKERS 8u               /* more threads than the machine's cores */
#define SLOTS (WORKERS + 1u)     /* slot 0 is the immediate manager, never touched here */
#define ITERATIONS 1000000u
#define PACK_EVERY 16u
#define BONES 4u
#define BLOCK_SIZE 352u

typedef struct blob {
    uint32_t slot, iteration, check;
} blob;

typedef struct shared {
    ob_param_registry *reg;
    ob_param color, bones, data;
    ob_param_mapping *map;
    pthread_barrier_t start;
} shared;

typedef struct worker {
    shared *sh;
    pthread_t thread;
    uint32_t slot;
    uint64_t errors;       /* calls that did not return OB_OK */
    uint64_t mismatches;   /* reads that differ from the write before them */
    uint64_t bad_packs;    /* packed blocks that differ from the expected bytes */
    uint64_t packs;
} worker;

/* Values depend on slot and iteration, so a value seen in the wrong slot or
 * a stale one is always different from the expected one. */
static void color_for(uint32_t slot, uint32_t i, float v[4])
{
    v[0] = (float)slot;
    v[1] = (float)i;
    v[2] = (float)(slot * 1000u + (i & 1023u));
    v[3] = 1.0f;
}

static void world_for(uint32_t slot, uint32_t i, float m[16])
{
    memset(m, 0, 64);
    m[0] = m[5] = m[10] = (float)(1u + slot);
    m[12] = (float)i;
    m[13] = (float)slot;
    m[14] = -(float)(i & 4095u);
    m[15] = 1.0f;
}

static void bone_for(uint32_t slot, uint32_t i, float m[16])
{
    for (uint32_t k = 0; k < 16; k++) m[k] = (float)((i ^ k) & 0xffffu) + (float)slot * 0.5f;
}

static blob blob_for(uint32_t slot, uint32_t i)
{
    return (blob){slot, i, slot * 2654435761u ^ i};
}

static void expected_block(uint32_t slot, uint32_t i, const float bones[BONES][16],
                           uint8_t out[BLOCK_SIZE])
{
    float m[16], v[4];
    memset(out, 0, BLOCK_SIZE);
    world_for(slot, i, m);
    memcpy(out, m, 64);
    color_for(slot, i, v);
    memcpy(out + 64, v, 16);
    for (uint32_t k = 0; k < BONES; k++) memcpy(out + 80 + 64 * k, bones[k], 64);
    blob b = blob_for(slot, i);
    memcpy(out + 336, &b, sizeof b);
}

static void *worker_main(void *arg)
{
    worker *w = arg;
    shared *sh = w->sh;
    const ob_param_builtins *bi = ob_param_registry_builtins(sh->reg);
    ob_params pm;
    if (ob_params_manager(sh->reg, w->slot, &pm) != OB_OK) {
        w->errors++;
        return NULL;
    }
    float bones[BONES][16] = {{0}};
    uint8_t block[BLOCK_SIZE], expect[BLOCK_SIZE];
    pthread_barrier_wait(&sh->start);
    for (uint32_t i = 0; i < ITERATIONS; i++) {
        float v[4], m[16], got[16];
        color_for(w->slot, i, v);
        w->errors += ob_params_set_vec4(&pm, sh->color, v) != OB_OK;
        w->errors += ob_params_get_vec4(&pm, sh->color, got) != OB_OK;
        w->mismatches += memcmp(got, v, 16) != 0;

        world_for(w->slot, i, m);
        w->errors += ob_params_set_mat4(&pm, bi->world, m) != OB_OK;
        w->errors += ob_params_get_mat4(&pm, bi->world, got) != OB_OK;
        w->mismatches += memcmp(got, m, 64) != 0;

        uint32_t e = i % BONES;
        bone_for(w->slot, i, bones[e]);
        w->errors += ob_params_set_mat4_array_at(&pm, sh->bones, e, bones[e], 1) != OB_OK;
        w->errors += ob_params_get_mat4_array_at(&pm, sh->bones, e, 1, got) != OB_OK;
        w->mismatches += memcmp(got, bones[e], 64) != 0;

        blob b = blob_for(w->slot, i), gb;
        w->errors += ob_params_set_bytes(&pm, sh->data, &b, sizeof b) != OB_OK;
        w->errors += ob_params_get_bytes(&pm, sh->data, sizeof gb, &gb) != OB_OK;
        w->mismatches += memcmp(&gb, &b, sizeof b) != 0;

        if (i % PACK_EVERY == PACK_EVERY - 1) {
            /* Every mapped value changed since the last pack, so it must pack. */
            if (!ob_params_pack(&pm, sh->map, block, false)) {
                w->bad_packs++;
                continue;
            }
            w->packs++;
            expected_block(w->slot, i, (const float(*)[16])bones, expect);
            w->bad_packs += memcmp(block, expect, BLOCK_SIZE) != 0;
            w->bad_packs += ob_params_pack_needed(&pm, sh->map);
        }
    }
    return NULL;
}

static ob_block_member member(const char *name, ob_member_type type, uint32_t offset,
                              uint32_t size, uint32_t array_len, uint32_t stride)
{
    ob_block_member m = {.type = type, .offset = offset, .size = size,
                         .array_len = array_len, .array_stride = stride};
    snprintf(m.name, sizeof m.name, "%s", name);
    return m;
}

static void workers_own_their_slots_without_locks(void **state)
{
    (void)state;
    ob_result r;
    shared sh = {0};
    sh.reg = ob_param_registry_create(&(ob_param_registry_desc){SLOTS}, &r);
    assert_int_equal(r, OB_OK);
    sh.color = ob_param_register(sh.reg, "Color", OB_PARAM_VEC4, 1, &r);
    assert_int_equal(r, OB_OK);
    sh.bones = ob_param_register(sh.reg, "Bones", OB_PARAM_MAT4_ARRAY, BONES, &r);
    assert_int_equal(r, OB_OK);
    sh.data = ob_param_register(sh.reg, "Data", OB_PARAM_BYTES, sizeof(blob), &r);
    assert_int_equal(r, OB_OK);
    const float sentinel[4] = {-1, -2, -3, -4};
    assert_int_equal(ob_params_init_vec4(sh.reg, sh.color, sentinel), OB_OK);

    ob_block_member members[] = {
        member("WorldMatrix", OB_MEMBER_MAT4, 0, 64, 0, 0),
        member("Color", OB_MEMBER_VEC4, 64, 16, 0, 0),
        member("Bones", OB_MEMBER_MAT4, 80, 256, BONES, 64),
        member("Data", OB_MEMBER_VEC3, 336, 12, 0, 0),
    };
    ob_block_layout layout = {.name = "PerDraw", .size = BLOCK_SIZE,
                              .member_count = OB_ARRAY_COUNT(members), .members = members};
    sh.map = ob_param_mapping_create(sh.reg, &layout, "threads.vert", &r);
    assert_int_equal(r, OB_OK);
    assert_int_equal(ob_param_mapping_unmapped_count(sh.map), 0);

    worker workers[WORKERS];
    assert_int_equal(pthread_barrier_init(&sh.start, NULL, WORKERS), 0);
    ob_param_registry_begin_recording(sh.reg);
    for (uint32_t t = 0; t < WORKERS; t++) {
        workers[t] = (worker){.sh = &sh, .slot = t + 1};
        assert_int_equal(pthread_create(&workers[t].thread, NULL, worker_main, &workers[t]), 0);
    }
    for (uint32_t t = 0; t < WORKERS; t++) pthread_join(workers[t].thread, NULL);
    ob_param_registry_end_recording(sh.reg);
    pthread_barrier_destroy(&sh.start);

    const ob_param_builtins *bi = ob_param_registry_builtins(sh.reg);
    for (uint32_t t = 0; t < WORKERS; t++) {
        const worker *w = &workers[t];
        if (w->errors || w->mismatches || w->bad_packs)
            fail_msg("slot %u: %llu errors, %llu mismatched reads, %llu bad packs", w->slot,
                     (unsigned long long)w->errors, (unsigned long long)w->mismatches,
                     (unsigned long long)w->bad_packs);
        assert_int_equal(w->packs, ITERATIONS / PACK_EVERY);

        /* Each slot holds exactly its own thread's last values, and its value
         * ids count exactly its own thread's changes: nobody else wrote. */
        ob_params pm;
        assert_int_equal(ob_params_manager(sh.reg, w->slot, &pm), OB_OK);
        float v[4], m[16], got[16];
        color_for(w->slot, ITERATIONS - 1, v);
        assert_int_equal(ob_params_get_vec4(&pm, sh.color, got), OB_OK);
        assert_memory_equal(got, v, 16);
        assert_int_equal(ob_params_value_id(&pm, sh.color), 1 + ITERATIONS);
        world_for(w->slot, ITERATIONS - 1, m);
        assert_int_equal(ob_params_get_mat4(&pm, bi->world, got), OB_OK);
        assert_memory_equal(got, m, 64);
        assert_int_equal(ob_params_value_id(&pm, bi->world), ITERATIONS);
        /* View and projection are identity, so WorldViewProj is the world. */
        assert_int_equal(ob_params_get_mat4(&pm, bi->world_view_proj, got), OB_OK);
        for (int k = 0; k < 16; k++) assert_float_equal(got[k], m[k], 0);
        for (uint32_t e = 0; e < BONES; e++) {
            bone_for(w->slot, ITERATIONS - BONES + e, m);
            assert_int_equal(ob_params_get_mat4_array_at(&pm, sh.bones, e, 1, got), OB_OK);
            assert_memory_equal(got, m, 64);
        }
        assert_int_equal(ob_params_value_id(&pm, sh.bones), ITERATIONS);
        blob b = blob_for(w->slot, ITERATIONS - 1), gb;
        assert_int_equal(ob_params_get_bytes(&pm, sh.data, sizeof gb, &gb), OB_OK);
        assert_memory_equal(&gb, &b, sizeof b);
        assert_int_equal(ob_params_value_id(&pm, sh.data), ITERATIONS);
    }
    /* The immediate slot saw none of it. */
    ob_params pm0;
    assert_int_equal(ob_params_manager(sh.reg, 0, &pm0), OB_OK);
    float got[16];
    assert_int_equal(ob_params_get_vec4(&pm0, sh.color, got), OB_OK);
    assert_memory_equal(got, sentinel, 16);
    assert_int_equal(ob_params_value_id(&pm0, sh.color), 1);
    assert_int_equal(ob_params_value_id(&pm0, bi->world), 0);
    assert_int_equal(ob_params_value_id(&pm0, sh.bones), 0);
    assert_int_equal(ob_params_value_id(&pm0, sh.data), 0);
    assert_true(ob_params_pack_needed(&pm0, sh.map));

    ob_param_mapping_destroy(sh.map);
    ob_param_registry_destroy(sh.reg);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(workers_own_their_slots_without_locks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
