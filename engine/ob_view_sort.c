/* ob_view_sort.c — the draw list's sort (ob_view_sort_internal.h): a
 * stable LSD radix sort of (hi, key) pairs over the bits that differ. */
#include "ob_view_sort_internal.h"

#include <stdbool.h>
#include <string.h>

/* Stable insertion sort on (hi, key), for short lists where the radix
 * sort's counting tables cost more than the items. */
static void sort_pairs_short(ob_sort_pair *a, uint32_t n)
{
    for (uint32_t i = 1; i < n; i++) {
        ob_sort_pair x = a[i];
        uint32_t j = i;
        while (j > 0 && (a[j - 1].hi > x.hi || (a[j - 1].hi == x.hi && a[j - 1].key > x.key))) {
            a[j] = a[j - 1];
            j--;
        }
        a[j] = x;
    }
}

/* Stable LSD radix sort on (hi, key), a byte per pass, for lists whose
 * differing bits do not fit the compact key below (kdiff, hdiff: the bits
 * where the OR and the AND of all keys differ). A byte that is the same in
 * every item needs neither counting nor a pass. Returns the buffer that
 * holds the result (a or b). */
static ob_sort_pair *sort_pairs_bytes(ob_sort_pair *a, ob_sort_pair *b, uint32_t n, uint64_t kdiff,
                                   uint32_t hdiff)
{
    uint32_t digits[12], nd = 0;
    for (uint32_t d = 0; d < 8; d++)
        if ((kdiff >> (8 * d)) & 0xffu) digits[nd++] = d;
    for (uint32_t d = 0; d < 4; d++)
        if ((hdiff >> (8 * d)) & 0xffu) digits[nd++] = 8 + d;
    uint32_t count[12][256];
    for (uint32_t k = 0; k < nd; k++) memset(count[k], 0, sizeof count[k]);
    for (uint32_t i = 0; i < n; i++) {
        for (uint32_t k = 0; k < nd; k++) {
            uint32_t d = digits[k];
            uint32_t byte = d < 8 ? (uint32_t)(a[i].key >> (8 * d)) & 0xffu
                                  : (a[i].hi >> (8 * (d - 8))) & 0xffu;
            count[k][byte]++;
        }
    }
    ob_sort_pair *src = a, *dst = b;
    for (uint32_t k = 0; k < nd; k++) {
        uint32_t *c = count[k], sum = 0;
        for (uint32_t x = 0; x < 256; x++) {
            uint32_t t = c[x];
            c[x] = sum;
            sum += t;
        }
        uint32_t d = digits[k];
        if (d < 8) {
            uint32_t shift = 8 * d;
            for (uint32_t i = 0; i < n; i++) dst[c[(src[i].key >> shift) & 0xffu]++] = src[i];
        } else {
            uint32_t shift = 8 * (d - 8);
            for (uint32_t i = 0; i < n; i++) dst[c[(src[i].hi >> shift) & 0xffu]++] = src[i];
        }
        ob_sort_pair *t = src;
        src = dst;
        dst = t;
    }
    return src;
}

/* The bits of the sort's (hi, key) that differ between items, as runs
 * gathered into one compact key: run r takes (word >> shift[r]) & mask[r]
 * to bit dest[r]. The first KEY_RUNS runs read the key, the next HI_RUNS
 * hi; a run not used has mask 0. Fixed counts, so that the gathering is a
 * straight line of shifts and masks per item. */
#define KEY_RUNS 4u
#define HI_RUNS 2u

typedef struct bit_runs {
    uint64_t mask[KEY_RUNS + HI_RUNS];
    uint32_t shift[KEY_RUNS + HI_RUNS], dest[KEY_RUNS + HI_RUNS];
    uint32_t total;            /* bits of the compact key */
    uint32_t key_runs, hi_runs; /* runs used of each */
} bit_runs;

static uint64_t low_mask(uint32_t width)
{
    return width >= 64 ? ~(uint64_t)0 : ((uint64_t)1 << width) - 1;
}

/* The runs of set bits of diff (bits wide) into runs[first ..
 * first + max), their number in *n, a gap of up to 7 equal bits taken in
 * (one shift and mask cover both sides). False when they need more runs or
 * the compact key more than 64 bits. */
static bool add_runs(uint64_t diff, int bits, bit_runs *out, uint32_t first, uint32_t max,
                     uint32_t *count)
{
    int start = -1, last = -1;
    uint32_t n = 0;
    for (int b = 0; b <= bits; b++) {
        bool set = b < bits && ((diff >> b) & 1u);
        if (set && start >= 0 && b - last <= 8) {
            last = b;
            continue;
        }
        if (start >= 0 && (set || b == bits)) {
            /* The run [start, last] ends: a new one starts at b, or the end. */
            uint32_t width = (uint32_t)(last - start + 1);
            if (n >= max || out->total + width > 64) return false;
            out->mask[first + n] = low_mask(width);
            out->shift[first + n] = (uint32_t)start;
            out->dest[first + n] = out->total;
            out->total += width;
            n++;
            start = -1;
        }
        if (set) start = last = b;
    }
    *count = n;
    return true;
}

/* kr, hr: the runs used (constants where the callers are inlined, so that
 * the loops unroll to kr + hr shifts and masks). */
static inline __attribute__((always_inline)) uint64_t compact_key(const bit_runs *r, uint32_t kr,
                                                                  uint32_t hr, uint64_t key,
                                                                  uint32_t hi)
{
    uint64_t ck = 0;
#pragma GCC unroll 4
    for (uint32_t k = 0; k < kr; k++) ck |= ((key >> r->shift[k]) & r->mask[k]) << r->dest[k];
#pragma GCC unroll 2
    for (uint32_t k = KEY_RUNS; k < KEY_RUNS + hr; k++)
        ck |= (((uint64_t)hi >> r->shift[k]) & r->mask[k]) << r->dest[k];
    return ck;
}

/* The key back from its compact form: the bits no run covers from any
 * item (fixed), the runs of the key from ck. */
static inline __attribute__((always_inline)) uint64_t expand_key(const bit_runs *r, uint32_t kr,
                                                                 uint64_t fixed, uint64_t ck)
{
    uint64_t key = fixed;
#pragma GCC unroll 4
    for (uint32_t k = 0; k < kr; k++) key |= ((ck >> r->dest[k]) & r->mask[k]) << r->shift[k];
    return key;
}

/* The counting pass: each item's key replaced by its compact key, and the
 * counts of its digits (bits wide, `passes` of them). */
static inline __attribute__((always_inline)) void count_compact(ob_sort_pair *a, uint32_t n,
                                                                const bit_runs *r, uint32_t kr,
                                                                uint32_t hr, uint32_t bits,
                                                                uint32_t passes,
                                                                uint32_t (*count)[2048])
{
    uint64_t digit = ((uint64_t)1 << bits) - 1;
    for (uint32_t i = 0; i < n; i++) {
        uint64_t ck = compact_key(r, kr, hr, a[i].key, a[i].hi);
        a[i].key = ck;
        for (uint32_t k = 0; k < passes; k++) count[k][(ck >> (bits * k)) & digit]++;
    }
}

/* The last pass, each key restored as it is moved. */
static inline __attribute__((always_inline)) void last_pass(const ob_sort_pair *src, ob_sort_pair *dst,
                                                            uint32_t n, const bit_runs *r,
                                                            uint32_t kr, uint64_t fixed,
                                                            uint32_t shift, uint64_t digit,
                                                            uint32_t *c)
{
    for (uint32_t i = 0; i < n; i++) {
        ob_sort_pair p = src[i];
        uint32_t at = c[(p.key >> shift) & digit]++;
        p.key = expand_key(r, kr, fixed, p.key);
        dst[at] = p;
    }
}

/* The order of the n items of a's segments whose compact keys fit 32
 * bits: 8-byte entries (compact key above, position in a below) in b,
 * radix-sorted between its halves; the last pass writes the positions
 * alone, as 32-bit words. */
static inline __attribute__((always_inline)) const uint32_t *
order_compact(const ob_sort_pair *a, ob_sort_pair *b, const ob_sort_segment *seg, uint32_t segs,
              uint32_t n, const bit_runs *r, uint32_t kr, uint32_t hr, uint32_t bits,
              uint32_t passes, uint32_t (*count)[2048])
{
    uint64_t *src = (uint64_t *)(void *)b, *dst = src + n;
    const uint64_t digit = ((uint64_t)1 << bits) - 1;
    const uint32_t size = 1u << bits;
    /* At most four passes (32 bits at 8): straight-line counting, the
     * tests on `passes` the same every item. */
    uint64_t *w = src;
    for (uint32_t s = 0; s < segs; s++) {
        for (uint32_t i = seg[s].start, end = seg[s].start + seg[s].count; i < end; i++) {
            uint64_t ck = compact_key(r, kr, hr, a[i].key, a[i].hi);
            *w++ = ck << 32 | i;
            count[0][ck & digit]++;
            if (passes > 1) count[1][(ck >> bits) & digit]++;
            if (passes > 2) count[2][(ck >> (2 * bits)) & digit]++;
            if (passes > 3) count[3][(ck >> (3 * bits)) & digit]++;
        }
    }
    for (uint32_t k = 0;; k++) {
        uint32_t *c = count[k], sum = 0, shift = 32 + bits * k;
        for (uint32_t x = 0; x < size; x++) {
            uint32_t t = c[x];
            c[x] = sum;
            sum += t;
        }
        if (k + 1 == passes) {
            uint32_t *order = (uint32_t *)(void *)dst;
            for (uint32_t i = 0; i < n; i++) order[c[(src[i] >> shift) & digit]++] = (uint32_t)src[i];
            return order;
        }
        for (uint32_t i = 0; i < n; i++) dst[c[(src[i] >> shift) & digit]++] = src[i];
        uint64_t *t = src;
        src = dst;
        dst = t;
    }
}

/* Stable LSD radix sort on (hi, key). Only the bits that differ between
 * items decide the order, so only they are sorted on: one counting pass
 * gathers them into a compact key, which takes 11 bits per pass on lists
 * long enough for 2048-entry counting tables (8 on shorter ones). On an
 * opaque list the 64 bits of (band, state group, mesh, depth) and the 32
 * of hi shrink to some 21: two passes over 8-byte (compact key, position)
 * entries, whose result is the order, the pairs left in place (half the
 * bytes moved, and no pass to put the keys back). Past 32 bits the pairs
 * themselves move, the compact key stored in place of the key and
 * restored by the last pass. The order is the same as sorting the whole
 * (hi, key). */
ob_sort_result ob_sort_pairs(ob_sort_pair *a, ob_sort_pair *b, uint32_t n)
{
    const ob_sort_segment whole = {0, n};
    return ob_sort_pairs_segments(a, b, &whole, 1, n);
}

ob_sort_result ob_sort_pairs_segments(ob_sort_pair *a, ob_sort_pair *b, const ob_sort_segment *seg,
                                      uint32_t segs, uint32_t n)
{
    bit_runs runs = {0};
    uint64_t kor = 0, kand = ~(uint64_t)0;
    uint32_t hor = 0, hand = ~0u;
    bool compact = false;
    if (n > 48) {
        for (uint32_t s = 0; s < segs; s++) {
            for (uint32_t i = seg[s].start, end = seg[s].start + seg[s].count; i < end; i++) {
                kor |= a[i].key;
                kand &= a[i].key;
                hor |= a[i].hi;
                hand &= a[i].hi;
            }
        }
        /* Up to 96 bits can differ, in any pattern: past 64 bits or the
         * runs the gathering has, the byte digits of the whole. */
        compact = add_runs(kor ^ kand, 64, &runs, 0, KEY_RUNS, &runs.key_runs) &&
                  add_runs(hor ^ hand, 32, &runs, KEY_RUNS, HI_RUNS, &runs.hi_runs);
    }
    const uint32_t bits = n >= 2048 ? 11u : 8u, size = 1u << bits;
    uint32_t passes = compact ? (runs.total + bits - 1) / bits : 0;
    uint32_t count[8][2048]; /* 64 bits at 8 a pass */
    uint32_t kr = runs.key_runs, hr = runs.hi_runs;
    for (uint32_t k = 0; k < passes; k++) memset(count[k], 0, sizeof(uint32_t) * size);
    if (compact && runs.total > 0 && runs.total <= 32) {
        /* The usual lists (opaque: hi all equal) get loops of their own;
         * the pieces are read where they lie. */
        const uint32_t *order;
        if (hr == 0 && kr == 1)
            order = order_compact(a, b, seg, segs, n, &runs, 1, 0, bits, passes, count);
        else if (hr == 0 && kr == 2)
            order = order_compact(a, b, seg, segs, n, &runs, 2, 0, bits, passes, count);
        else if (hr == 0 && kr == 3)
            order = order_compact(a, b, seg, segs, n, &runs, 3, 0, bits, passes, count);
        else
            order = order_compact(a, b, seg, segs, n, &runs, KEY_RUNS, HI_RUNS, bits, passes, count);
        return (ob_sort_result){a, order};
    }
    /* Every other way sorts a[0..n): the pieces side by side first (each
     * moves down, or stays). */
    uint32_t at = 0;
    for (uint32_t s = 0; s < segs; s++) {
        if (at != seg[s].start) memmove(a + at, a + seg[s].start, sizeof *a * seg[s].count);
        at += seg[s].count;
    }
    if (n <= 48) {
        sort_pairs_short(a, n);
        return (ob_sort_result){a, NULL};
    }
    if (!compact) return (ob_sort_result){sort_pairs_bytes(a, b, n, kor ^ kand, hor ^ hand), NULL};
    if (runs.total == 0) return (ob_sort_result){a, NULL}; /* all equal: stable means as they are */
    uint64_t fixed = kand;
    for (uint32_t k = 0; k < kr; k++) fixed &= ~(runs.mask[k] << runs.shift[k]);
    if (hr == 0 && kr == 1) count_compact(a, n, &runs, 1, 0, bits, passes, count);
    else if (hr == 0 && kr == 2) count_compact(a, n, &runs, 2, 0, bits, passes, count);
    else if (hr == 0 && kr == 3) count_compact(a, n, &runs, 3, 0, bits, passes, count);
    else count_compact(a, n, &runs, KEY_RUNS, HI_RUNS, bits, passes, count);
    ob_sort_pair *src = a, *dst = b;
    for (uint32_t k = 0; k < passes; k++) {
        uint32_t *c = count[k], sum = 0, shift = bits * k;
        for (uint32_t x = 0; x < size; x++) {
            uint32_t t = c[x];
            c[x] = sum;
            sum += t;
        }
        if (k + 1 < passes) {
            for (uint32_t i = 0; i < n; i++) dst[c[(src[i].key >> shift) & (size - 1)]++] = src[i];
        } else {
            if (kr == 1) last_pass(src, dst, n, &runs, 1, fixed, shift, size - 1, c);
            else if (kr == 2) last_pass(src, dst, n, &runs, 2, fixed, shift, size - 1, c);
            else if (kr == 3) last_pass(src, dst, n, &runs, 3, fixed, shift, size - 1, c);
            else last_pass(src, dst, n, &runs, KEY_RUNS, fixed, shift, size - 1, c);
        }
        ob_sort_pair *t = src;
        src = dst;
        dst = t;
    }
    return (ob_sort_result){src, NULL};
}
