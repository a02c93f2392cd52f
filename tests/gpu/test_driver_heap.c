/* A CPU device keeps the C library's freed heap (ob_device_desc.driver_heap,
 * $OB_DRIVER_HEAP): llvmpipe frees its bins after every render pass, and a
 * heap handed back to the kernel faults those pages in again each frame.
 *
 * The setting is process-wide and cannot be undone, so the order of the
 * tests below matters: the ones that leave the heap alone run first. What
 * is checked is what the driver sees: 96 MiB freed at the top of the heap
 * stays there (glibc's mallinfo2 keepcost) once a device keeps the heap,
 * and goes back to the kernel before. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include "ob_test.h"

#include <stdlib.h>
#include <string.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

/* Under a sanitizer, mallopt and mallinfo2 do not reach the allocator in
 * use (GCC says so with __SANITIZE_*__, Clang with __has_feature). */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZER_ALLOCATOR 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define SANITIZER_ALLOCATOR 1
#endif
#endif
#ifndef SANITIZER_ALLOCATOR
#define SANITIZER_ALLOCATOR 0
#endif

#define BLOCK (64u << 10)   /* llvmpipe's data block size: below any mmap threshold */
#define BLOCKS 1536u        /* 96 MiB: above glibc's largest self-raised trim threshold (64 MiB) */

/* Bytes left at the top of the heap after BLOCKS blocks were allocated and
 * freed, newest first, as a scene's blocks are; SIZE_MAX where the C
 * library cannot say. */
static size_t freed_top_kept(void)
{
#if defined(__GLIBC__) && !SANITIZER_ALLOCATOR
    void **blocks = malloc(BLOCKS * sizeof *blocks);
    assert_non_null(blocks);
    for (uint32_t i = 0; i < BLOCKS; i++) {
        blocks[i] = malloc(BLOCK);
        assert_non_null(blocks[i]);
        memset(blocks[i], (int)i, BLOCK);   /* faulted in, as the driver's bins are */
    }
    for (uint32_t i = BLOCKS; i-- > 0;) free(blocks[i]);
    size_t kept = mallinfo2().keepcost;
    free(blocks);
    return kept;
#else
    return SIZE_MAX;
#endif
}

static ob_device *create(int driver_heap)
{
    ob_device_desc desc = {.app_name = "test_driver_heap", .validation = 1, .driver_heap = driver_heap};
    ob_result r;
    ob_device *dev = ob_device_create(&desc, &r);
    assert_int_equal(r, OB_OK);
    return dev;
}

/* dev says it left the heap alone, and glibc still hands a freed top back. */
static void assert_heap_left_alone(ob_device *dev)
{
    assert_false(ob_device_keeps_driver_heap(dev));
    size_t kept = freed_top_kept();
    if (kept != SIZE_MAX) assert_true(kept < (32u << 20));
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

static void env_system_leaves_the_heap_to_the_c_library(void **state)
{
    (void)state;
    setenv("OB_DRIVER_HEAP", "system", 1);
    ob_device *dev = create(0);
    unsetenv("OB_DRIVER_HEAP");
    assert_heap_left_alone(dev);
}

static void negative_request_leaves_the_heap_to_the_c_library(void **state)
{
    (void)state;
    assert_heap_left_alone(create(-1));
}

static void cpu_device_keeps_the_freed_heap(void **state)
{
    (void)state;
    ob_device *dev = create(0);   /* the default: keep */
#if defined(__GLIBC__) && !SANITIZER_ALLOCATOR
    assert_int_equal(ob_device_keeps_driver_heap(dev), ob_device_is_cpu(dev));
#endif
    if (ob_device_keeps_driver_heap(dev)) {
        size_t kept = freed_top_kept();
        assert_true(kept >= (size_t)BLOCKS * BLOCK - (1u << 20));
    }
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
    /* A device made after that says what it asked for; the process keeps
     * the setting (mallopt cannot be undone). */
    dev = create(-1);
    assert_false(ob_device_keeps_driver_heap(dev));
    ob_device_destroy(dev);
}

static void unknown_env_value_is_reported_and_keeps_the_heap(void **state)
{
    (void)state;
    ob_test_log_clear();
    setenv("OB_DRIVER_HEAP", "sometimes", 1);
    ob_device *dev = create(0);
    unsetenv("OB_DRIVER_HEAP");
    assert_logged("OB_DRIVER_HEAP='sometimes'", "keeping the heap");
#if defined(__GLIBC__) && !SANITIZER_ALLOCATOR
    assert_int_equal(ob_device_keeps_driver_heap(dev), ob_device_is_cpu(dev));
#endif
    ob_device_destroy(dev);
}

int main(void)
{
    /* In this order: the heap is kept from the third test on. */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(env_system_leaves_the_heap_to_the_c_library),
        cmocka_unit_test(negative_request_leaves_the_heap_to_the_c_library),
        cmocka_unit_test(cpu_device_keeps_the_freed_heap),
        cmocka_unit_test(unknown_env_value_is_reported_and_keeps_the_heap),
    };
    ob_test_setup_log();
    return cmocka_run_group_tests(tests, NULL, NULL);
}
