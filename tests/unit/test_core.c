/* Core services every module relies on: handles, results, allocation faults. */
#include "ob_test.h"

#include <string.h>

static void handle_generation_rejects_stale(void **state)
{
    (void)state;
    ob_pool pool;
    ob_pool_init(&pool);
    int a = 1, b = 2;
    ob_result r;
    uint32_t ida = ob_pool_insert(&pool, &a, &r);
    assert_int_equal(r, OB_OK);
    assert_ptr_equal(ob_pool_get(&pool, ida), &a);
    assert_ptr_equal(ob_pool_remove(&pool, ida), &a);
    assert_null(ob_pool_get(&pool, ida));
    uint32_t idb = ob_pool_insert(&pool, &b, &r);
    /* The slot is reused but the old handle stays dead. */
    assert_int_equal(idb & OB_HANDLE_INDEX_MASK, ida & OB_HANDLE_INDEX_MASK);
    assert_int_not_equal(idb, ida);
    assert_null(ob_pool_get(&pool, ida));
    assert_ptr_equal(ob_pool_get(&pool, idb), &b);
    assert_null(ob_pool_get(&pool, 0));
    assert_null(ob_pool_remove(&pool, ida));
    ob_pool_release(&pool);
}

static void pool_grows_and_iterates(void **state)
{
    (void)state;
    ob_pool pool;
    ob_pool_init(&pool);
    static int items[1000];
    uint32_t ids[1000];
    for (int i = 0; i < 1000; i++) ids[i] = ob_pool_insert(&pool, &items[i], NULL);
    for (int i = 0; i < 1000; i += 2) ob_pool_remove(&pool, ids[i]);
    uint32_t cursor = 0, id, seen = 0;
    while (ob_pool_next(&pool, &cursor, &id)) seen++;
    assert_int_equal(seen, 500);
    assert_int_equal(pool.count, 500);
    ob_pool_release(&pool);
}

static void result_names_are_stable(void **state)
{
    (void)state;
    assert_string_equal(ob_result_name(OB_OK), "OB_OK");
    assert_string_equal(ob_result_name(OB_ERR_INVALID_HANDLE), "OB_ERR_INVALID_HANDLE");
    assert_string_equal(ob_result_name((ob_result)9999), "OB_RESULT_UNKNOWN");
}

static void nth_host_allocation_fails(void **state)
{
    (void)state;
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 3);
    void *a = ob_malloc(8), *b = ob_malloc(8), *c = ob_malloc(8), *d = ob_malloc(8);
    assert_non_null(a);
    assert_non_null(b);
    assert_null(c);
    assert_non_null(d);
    assert_true(ob_fault_hit(OB_FAULT_HOST_ALLOC));
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    ob_free(a);
    ob_free(b);
    ob_free(d);
}

/* The live count follows every allocation function, back to where it
 * started once all is freed (the soak tells Obelisk's memory from the
 * driver's with it). */
static void heap_stats_follow_every_allocation(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    void *a = ob_malloc(1000);
    void *b = ob_calloc(10, 100);
    void *c = ob_aligned_alloc(64, 256);
    char *d = ob_strdup("obelisk");
    assert_non_null(a);
    assert_non_null(b);
    assert_non_null(c);
    assert_non_null(d);
    ob_heap_stats mid = ob_heap_stats_now();
    assert_int_equal(mid.live_blocks, before.live_blocks + 4);
    if (mid.sized) assert_true(mid.live_bytes >= before.live_bytes + 1000 + 1000 + 256 + 8);
    a = ob_realloc(a, 100000);
    assert_non_null(a);
    ob_heap_stats grown = ob_heap_stats_now();
    assert_int_equal(grown.live_blocks, mid.live_blocks);
    if (grown.sized) assert_true(grown.live_bytes >= mid.live_bytes + 99000);
    void *e = ob_realloc(NULL, 10);
    assert_non_null(e);
    assert_int_equal(ob_heap_stats_now().live_blocks, mid.live_blocks + 1);
    ob_free(a);
    ob_free(b);
    ob_aligned_free(c);
    ob_free(d);
    ob_free(e);
    ob_free(NULL);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
    assert_int_equal(after.live_bytes, before.live_bytes);
    /* A failed allocation counts nothing. */
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    assert_null(ob_malloc(64));
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_int_equal(ob_heap_stats_now().live_blocks, before.live_blocks);
}

static void missing_file_names_path(void **state)
{
    (void)state;
    ob_test_log_clear();
    ob_result r;
    char *s = ob_file_read("/nonexistent/obelisk.txt", NULL, &r);
    assert_null(s);
    assert_int_equal(r, OB_ERR_IO);
    assert_true(ob_test_log_has("/nonexistent/obelisk.txt", NULL));
}

/* What a "did you mean" depends on: typos are near, unrelated names are
 * not suggested, and an exact match never is. */
static void closest_name_suggests_typos_only(void **state)
{
    (void)state;
    assert_int_equal(ob_edit_distance("", ""), 0);
    assert_int_equal(ob_edit_distance("gold", ""), 4);
    assert_int_equal(ob_edit_distance("kitten", "sitting"), 3);
    assert_int_equal(ob_edit_distance("--frmaes", "--frames"), 1);   /* a swap is one edit */
    assert_int_equal(ob_edit_distance("Gold", "gold"), 0);           /* case is free */
    static const char *const options[] = {"--frames", "--threads", "--size", "--seed", "--out",
                                          "--no-overlay", "--overlay", NULL};
    uint32_t n = OB_ARRAY_COUNT(options);
    assert_string_equal(ob_closest_name("--frmaes", options, n, 0), "--frames");
    assert_string_equal(ob_closest_name("--thread", options, n, 0), "--threads");
    assert_string_equal(ob_closest_name("--no-overlya", options, n, 0), "--no-overlay");
    assert_string_equal(ob_closest_name("--sizes", options, n, 0), "--size");
    assert_null(ob_closest_name("--verbose", options, n, 0));
    assert_null(ob_closest_name("--size", options, n, 0));            /* exact: nothing to say */
    assert_null(ob_closest_name("x", options, n, 0));
    assert_null(ob_closest_name(NULL, options, n, 0));
    assert_null(ob_closest_name("--frames", NULL, 0, 0));
    /* An explicit bound wins over the default. */
    assert_string_equal(ob_closest_name("--thrads", options, n, 1), "--threads");
    assert_null(ob_closest_name("--thrds", options, n, 1));
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(handle_generation_rejects_stale),
        cmocka_unit_test(pool_grows_and_iterates),
        cmocka_unit_test(result_names_are_stable),
        cmocka_unit_test(nth_host_allocation_fails),
        cmocka_unit_test(heap_stats_follow_every_allocation),
        cmocka_unit_test(missing_file_names_path),
        cmocka_unit_test(closest_name_suggests_typos_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
