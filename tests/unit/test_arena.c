/* The command pools' arena allocator (engine/ob_device.h), driven through
 * its VkAllocationCallbacks the way a driver drives it. */
#include "ob_test.h"

#include "ob_device.h"

#include <stdint.h>
#include <string.h>

static void *alloc(ob_arena_allocator *a, size_t size, size_t align)
{
    return a->callbacks.pfnAllocation(a->callbacks.pUserData, size, align,
                                      VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
}

static void *re(ob_arena_allocator *a, void *old, size_t size, size_t align)
{
    return a->callbacks.pfnReallocation(a->callbacks.pUserData, old, size, align,
                                        VK_SYSTEM_ALLOCATION_SCOPE_OBJECT);
}

static void release(ob_arena_allocator *a, void *mem)
{
    a->callbacks.pfnFree(a->callbacks.pUserData, mem);
}

/* Every requested alignment is honoured, blocks do not overlap, and each
 * request is counted. */
static void blocks_are_aligned_and_distinct(void **state)
{
    (void)state;
    ob_arena_allocator a;
    ob_arena_allocator_init(&a);
    uint8_t *blocks[9];
    for (uint32_t i = 0; i < 9; i++) {
        size_t align = (size_t)1 << i;   /* 1 .. 256 */
        blocks[i] = alloc(&a, 40 + i, align);
        assert_non_null(blocks[i]);
        assert_int_equal((uintptr_t)blocks[i] % align, 0);
        memset(blocks[i], (int)i, 40 + i);
    }
    for (uint32_t i = 0; i < 9; i++)
        for (uint32_t k = 0; k < 40 + i; k++) assert_int_equal(blocks[i][k], i);
    assert_int_equal(ob_arena_allocator_count(&a), 9);
    for (uint32_t i = 0; i < 9; i++) release(&a, blocks[i]);
    release(&a, NULL);   /* as free(NULL) */
    ob_arena_allocator_release(&a);
}

/* What a pool reset does every frame: free everything, record again. The
 * second frame gets the same memory back (no system allocation). */
static void a_reset_frame_reuses_the_same_memory(void **state)
{
    (void)state;
    ob_arena_allocator a;
    ob_arena_allocator_init(&a);
    enum { N = 3000 };   /* ~600 KB: many chunks */
    static void *first[N], *second[N];
    for (int frame = 0; frame < 2; frame++) {
        void **b = frame ? second : first;
        for (int i = 0; i < N; i++) {
            b[i] = alloc(&a, 64 + (size_t)(i % 7) * 24, 8);
            assert_non_null(b[i]);
        }
        for (int i = 0; i < N; i++) release(&a, b[i]);
    }
    /* Chunks come back in another order (the one in use at the reset is
     * refilled from its start, so the second frame may reach further into
     * it), but every block of the second frame lies in the chunks the first
     * frame used: within a chunk's size past the first frame's last block. */
    uintptr_t lo = UINTPTR_MAX, hi = 0;
    for (int i = 0; i < N; i++) {
        lo = OB_MIN(lo, (uintptr_t)first[i]);
        hi = OB_MAX(hi, (uintptr_t)first[i]);
    }
    hi += 64 * 1024;
    uint32_t inside = 0;
    for (int i = 0; i < N; i++) inside += (uintptr_t)second[i] >= lo && (uintptr_t)second[i] <= hi;
    assert_int_equal(inside, N);
    ob_arena_allocator_release(&a);
}

/* A long-lived block (a command buffer object) pins its chunk only: the
 * blocks around it are reused and it keeps its contents. */
static void a_live_block_survives_reuse_around_it(void **state)
{
    (void)state;
    ob_arena_allocator a;
    ob_arena_allocator_init(&a);
    char *keep = alloc(&a, 32, 8);
    strcpy(keep, "command buffer");
    for (int frame = 0; frame < 4; frame++) {
        void *b[2000];
        for (int i = 0; i < 2000; i++) {
            b[i] = alloc(&a, 100, 16);
            memset(b[i], 0xab, 100);
        }
        for (int i = 0; i < 2000; i++) release(&a, b[i]);
    }
    assert_string_equal(keep, "command buffer");
    release(&a, keep);
    ob_arena_allocator_release(&a);
}

/* Reallocation keeps the contents, growing and shrinking, in a chunk or in
 * a block too big for one; zero size frees. */
static void reallocation_keeps_contents(void **state)
{
    (void)state;
    ob_arena_allocator a;
    ob_arena_allocator_init(&a);
    uint8_t *p = re(&a, NULL, 100, 8);
    assert_non_null(p);
    for (int i = 0; i < 100; i++) p[i] = (uint8_t)i;
    p = re(&a, p, 40000, 64);   /* past a quarter chunk: its own block */
    assert_non_null(p);
    assert_int_equal((uintptr_t)p % 64, 0);
    for (int i = 0; i < 100; i++) assert_int_equal(p[i], i);
    memset(p + 100, 7, 40000 - 100);
    p = re(&a, p, 50, 8);
    for (int i = 0; i < 50; i++) assert_int_equal(p[i], i);
    assert_null(re(&a, p, 0, 8));
    assert_int_equal(ob_arena_allocator_count(&a), 3);
    ob_arena_allocator_release(&a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(blocks_are_aligned_and_distinct),
        cmocka_unit_test(a_reset_frame_reuses_the_same_memory),
        cmocka_unit_test(a_live_block_survives_reuse_around_it),
        cmocka_unit_test(reallocation_keeps_contents),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
