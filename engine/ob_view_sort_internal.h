/* ob_view_sort_internal.h — the sort of a view's draw list (ob_view.c
 * culls and keys, ob_view_sort.c sorts); tests/unit/test_view_sort.c
 * checks it against a comparison sort. Not part of the API. */
#ifndef OB_VIEW_SORT_INTERNAL_H
#define OB_VIEW_SORT_INTERNAL_H

#include <stdint.h>

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

/* What the sort moves: 16 bytes per visible item. index is the caller's
 * (ob_view.c: the item's position before the sort, where its payload lies)
 * and is not sorted on. Ties keep their order: the snapshot is in ascending
 * entity id, each chunk emits its items in that order and the sort is
 * stable, so equal keys stay in id order. */
typedef struct ob_sort_pair {
    uint64_t key;
    uint32_t hi;
    uint32_t index;
} ob_sort_pair;

/* A sorted list: pairs in order, or (order not NULL) pairs as they were
 * with order[j] the position in pairs of the jth. */
typedef struct ob_sort_result {
    const ob_sort_pair *pairs;
    const uint32_t *order;
} ob_sort_result;

/* The jth pair of a sorted list. */
static inline const ob_sort_pair *ob_sort_at(ob_sort_result s, uint32_t j)
{
    return s.order ? &s.pairs[s.order[j]] : &s.pairs[j];
}

/* Sorts a[0..n) by (hi, key), stably, using b (n pairs) as room; the
 * result lies in a or b. Only the bits that differ between the items are
 * sorted on (see ob_view_sort.c): for a typical opaque view of thousands
 * of items, some 21 bits, two passes of 11 over 8-byte (bits, position)
 * entries that leave a's pairs where they are and return their order.
 * [any thread; a and b the caller's] */
ob_sort_result ob_sort_pairs(ob_sort_pair *a, ob_sort_pair *b, uint32_t n);

/* A piece of a list held in pieces: a[start .. start + count). */
typedef struct ob_sort_segment {
    uint32_t start, count;
} ob_sort_segment;

/* ob_sort_pairs of the list whose n pairs lie in a's segments, in
 * segment order (ascending starts, disjoint): the culling chunks' outputs,
 * sorted where they lie without being moved side by side first. With an
 * order, its positions are a's (up to the last segment's end); every other
 * way the pieces are first moved to a[0..n), and the result is sorted
 * pairs. b: room for n pairs. [any thread; a and b the caller's] */
ob_sort_result ob_sort_pairs_segments(ob_sort_pair *a, ob_sort_pair *b, const ob_sort_segment *seg,
                                      uint32_t segs, uint32_t n);

#pragma GCC visibility pop

#endif /* OB_VIEW_SORT_INTERNAL_H */
