/* ob_bench_progress.h — a one-line progress bar on stderr, drawn only when
 * stderr is a terminal (isatty), so piped or captured output stays clean.
 *
 * Lifecycle: init(total units) → { set_label; tick per unit } → finish.
 * Thread rule: one thread.
 */
#ifndef OB_BENCH_PROGRESS_H
#define OB_BENCH_PROGRESS_H

#include <stdbool.h>
#include <stdint.h>

typedef struct ob_bench_progress {
    bool enabled;
    uint64_t total, done;
    uint64_t unit;           /* units one tick counts for (1 after init) */
    uint64_t start_ns, drawn_ns;
    char label[64];
} ob_bench_progress;

/* enabled only if want && isatty(stderr). */
void ob_bench_progress_init(ob_bench_progress *p, uint64_t total, bool want);
void ob_bench_progress_label(ob_bench_progress *p, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* p->unit units done (an ob_bench_tick_fn: user is the ob_bench_progress). */
void ob_bench_progress_tick(void *user);
/* Clears the line. */
void ob_bench_progress_finish(ob_bench_progress *p);

#endif /* OB_BENCH_PROGRESS_H */
