/* The draw list's sort (engine/ob_view_sort.c) against a comparison sort:
 * the same order, stable, for lists of every length and every pattern of
 * differing bits: the compact-key paths (8- and 11-bit passes, runs in the
 * key and in hi; up to 32 bits an order of the pairs left in place, past
 * that the pairs moved), the byte-wise fallback (more runs, or more than 64
 * differing bits), all-equal lists and the short insertion sort; and the
 * same lists held in pieces with gaps between them (as culling's chunks
 * leave them), sorted where they lie. Fixed seeds: the same lists every
 * run. */
#include "ob_test.h"

#include "ob_view_sort_internal.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define MAX_N 20000u

static uint64_t rng_state;

static uint64_t next(void)
{
    /* xorshift64 */
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

/* (hi, key), then the input position: a stable sort's order. */
static int compare(const void *pa, const void *pb)
{
    const ob_sort_pair *a = pa, *b = pb;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return a->index < b->index ? -1 : a->index > b->index;
}

/* Lists sorted by their order (the pairs left in place). */
static uint32_t orders;

/* n pairs whose keys vary in the bits of kmask and his in those of hmask,
 * over `values` distinct draws (few: many ties), sorted both ways. */
static void check(uint32_t n, uint64_t kmask, uint32_t hmask, uint32_t values)
{
    static ob_sort_pair a[MAX_N], b[MAX_N], want[MAX_N];
    uint64_t kbase = next();
    uint32_t hbase = (uint32_t)next();
    for (uint32_t i = 0; i < n; i++) {
        uint64_t r = (next() % values) * 0x9E3779B97F4A7C15ull;
        a[i] = (ob_sort_pair){.key = (kbase & ~kmask) | (r & kmask),
                              .hi = (hbase & ~hmask) | ((uint32_t)(r >> 20) & hmask),
                              .index = i};
        want[i] = a[i];
    }
    qsort(want, n, sizeof *want, compare);
    ob_sort_result got = ob_sort_pairs(a, b, n);
    assert_true(got.pairs == a || got.pairs == b);
    if (got.order) {
        orders++;
        /* The order of a's pairs, left where they were: every position once. */
        assert_ptr_equal(got.pairs, a);
        static uint8_t seen[MAX_N];
        memset(seen, 0, n);
        for (uint32_t i = 0; i < n; i++) {
            assert_true(got.order[i] < n);
            assert_false(seen[got.order[i]]);
            seen[got.order[i]] = 1;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        const ob_sort_pair *g = ob_sort_at(got, i);
        if (g->key != want[i].key || g->hi != want[i].hi || g->index != want[i].index)
            fail_msg("n %u, key mask %016llx, hi mask %08x: item %u is (%08x, %016llx, %u), "
                     "want (%08x, %016llx, %u)", n, (unsigned long long)kmask, hmask, i,
                     g->hi, (unsigned long long)g->key, g->index, want[i].hi,
                     (unsigned long long)want[i].key, want[i].index);
    }
}

/* The list of check(n, ...) cut into pieces at random, a random gap (up
 * to 40 pairs, garbage in it) before each, and sorted by
 * ob_sort_pairs_segments: the same order, read through positions in the
 * pieces or from the pairs moved side by side. */
static void check_segments(uint32_t n, uint64_t kmask, uint32_t hmask, uint32_t values)
{
    enum { MAX_SEGS = 64 };
    static ob_sort_pair a[2 * MAX_N + 64 * 41], b[MAX_N], want[MAX_N];
    ob_sort_segment seg[MAX_SEGS];
    uint64_t kbase = next();
    uint32_t hbase = (uint32_t)next();
    uint32_t segs = 0, at = 0, placed = 0;
    while (placed < n || segs == 0) {
        uint32_t left = n - placed;
        uint32_t len = segs + 1 == MAX_SEGS ? left : (uint32_t)(next() % (left / 2 + 2));
        if (len > left) len = left;
        uint32_t gap = (uint32_t)(next() % 41);
        for (uint32_t g = 0; g < gap; g++)
            a[at + g] = (ob_sort_pair){.key = next(), .hi = (uint32_t)next(), .index = ~0u};
        at += gap;
        seg[segs++] = (ob_sort_segment){at, len};
        for (uint32_t t = 0; t < len; t++) {
            uint32_t i = placed + t;
            uint64_t r = (next() % values) * 0x9E3779B97F4A7C15ull;
            a[at + t] = (ob_sort_pair){.key = (kbase & ~kmask) | (r & kmask),
                                       .hi = (hbase & ~hmask) | ((uint32_t)(r >> 20) & hmask),
                                       .index = i};
            want[i] = a[at + t];
        }
        at += len;
        placed += len;
    }
    qsort(want, n, sizeof *want, compare);
    ob_sort_result got = ob_sort_pairs_segments(a, b, seg, segs, n);
    if (got.order) orders++;
    for (uint32_t j = 0; j < n; j++) {
        const ob_sort_pair *g = got.order ? &a[got.order[j]] : &got.pairs[j];
        if (got.order) assert_true(got.order[j] < at);
        if (g->key != want[j].key || g->hi != want[j].hi || g->index != want[j].index)
            fail_msg("pieces: n %u in %u segments, key mask %016llx, hi mask %08x: item %u is "
                     "index %u, want %u", n, segs, (unsigned long long)kmask, hmask, j, g->index,
                     want[j].index);
    }
}

/* The keys the culling builds: opaque (band, state, mesh, fine depth) and
 * blended (depth, state, mesh), long enough for 11-bit passes and not. */
static void view_like_lists(void **state)
{
    (void)state;
    rng_state = 0x2545F4914F6CDD1Dull;
    const uint64_t opaque = 0xfc01c0007fffff00ull;  /* the sweep's differing bits */
    /* 8 x 10k's main view: 21 bits in three runs, sorted by order. */
    const uint64_t bench = 0x0403c003bffc0000ull;
    orders = 0;
    for (uint32_t n = 2; n <= 12000; n = n * 3 + 1) {
        check(n, bench, 0, 100000);
        check(n, opaque, 0, 100000);
        check(n, opaque, 0x80000003u, 100000); /* and blended, with priorities */
        check(n, 0xffffffff0003000full, 0, 7);  /* blended: many equal keys */
    }
    assert_true(orders >= 6); /* n = 53 .. 12000 of the bench's bits at least */
    orders = 0;
    for (uint32_t n = 1; n <= 12000; n = n * 3 + 1) {
        check_segments(n, bench, 0, 100000);
        check_segments(n, opaque, 0x80000003u, 100000);
        check_segments(n, 0xffffffff0003000full, 0, 7);
        check_segments(n, 0, 0, 1); /* all equal */
    }
    assert_true(orders >= 5); /* in pieces, by order: the bench's bits at n = 121 .. 9841 */
}

/* Random bit patterns: any number of runs, up to all 96 bits differing
 * (the byte-wise fallback), single bits, nothing differing. */
static void random_patterns(void **state)
{
    (void)state;
    rng_state = 0x9E3779B97F4A7C15ull;
    for (uint32_t t = 0; t < 400; t++) {
        uint32_t n = 1 + (uint32_t)(next() % (t % 4 == 0 ? MAX_N : 3000u));
        uint64_t kmask = next() & next();
        uint32_t hmask = t % 3 == 0 ? (uint32_t)(next() & next()) : 0u;
        if (t % 7 == 0) kmask = ~0ull;
        if (t % 11 == 0) hmask = ~0u;
        if (t % 13 == 0) kmask = 1ull << (next() % 64);
        if (t % 17 == 0) kmask = hmask = 0;
        uint32_t values = 1 + (uint32_t)(next() % (t % 5 == 0 ? 4u : 100000u));
        check(n, kmask, hmask, values);
        check_segments(n, kmask, hmask, values);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(view_like_lists),
        cmocka_unit_test(random_patterns),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
