/* ob_auto_internal.h — OB_THREADING_AUTO's choice between recording inline
 * and on the workers, from the measured cost of each (ob_auto.c). The
 * renderer keeps one ob_record_cost per way and one ob_auto_state;
 * tests/unit/test_auto.c drives them with made-up costs. Not part of the API. */
#ifndef OB_AUTO_INTERNAL_H
#define OB_AUTO_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

/* What recording a scene one way (inline or on n workers) cost. */
typedef struct ob_record_cost {
    uint64_t cost_ns;           /* moving average of a frame's; 0 = never measured */
    uint64_t per_draw_ps;       /* the lowest of the last three frames' cost per draw */
    uint64_t recent_ps[3];      /* those frames' (frames with draws), a ring */
    uint32_t recent_count;
    uint32_t draws;             /* moving average */
    uint32_t age;               /* frames of the other way since this was taken */
} ob_record_cost;

typedef struct ob_auto_state {
    bool way;                   /* the choice: true = the workers */
    bool probing;               /* the last frame re-measured the way not chosen */
    uint32_t confirmed;         /* probes in a row that left the choice clear */
    uint32_t workers;           /* worker count of the workers' way (0: not chosen yet) */
    bool count_probing;         /* the last frame re-measured another worker count */
} ob_auto_state;

/* A frame recorded this way took ns (recording wall time) for draws draws.
 * Resets the way's age; the caller ages the other way. */
void ob_record_cost_note(ob_record_cost *m, uint64_t ns, uint32_t draws);

/* The way the next AUTO frame records (true = the workers), from the two
 * ways' figures; a way never measured is measured first. */
bool ob_auto_choose(ob_auto_state *s, const ob_record_cost *inline_way,
                    const ob_record_cost *worker_way);

/* Frames of the chosen way before the other is re-measured, now. */
uint32_t ob_auto_remeasure_interval(const ob_auto_state *s);

/* The worker count of the workers' way: among 2, 4, 8, ... below `active`
 * and `active` itself (the most the frame may use), the one measured
 * cheapest per draw (kept unless another is cheaper by the margin), in
 * s->workers. measured[n] is the way of n workers (n = 0..active). [any] */
uint32_t ob_auto_best_workers(ob_auto_state *s, const ob_record_cost *measured, uint32_t active);
/* The count a frame that records on the workers uses: s->workers, or, one
 * frame at a time, the next count above or below it when that one was
 * never measured, is stale (256 frames old) or was measured at a draw
 * count a quarter away, so the choice follows the scene. [any] */
uint32_t ob_auto_probe_workers(ob_auto_state *s, const ob_record_cost *measured, uint32_t active);

#pragma GCC visibility pop

#endif
