#define _POSIX_C_SOURCE 200809L
#include "ob_bench_progress.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "ob_core.h"

#define BAR_WIDTH 30

static void draw(ob_bench_progress *p)
{
    uint64_t now = ob_time_ns();
    /* Redraw at most every 100 ms, and always at the end. */
    if (p->done < p->total && p->drawn_ns && now - p->drawn_ns < 100000000ull) return;
    p->drawn_ns = now;
    uint64_t done = p->done < p->total ? p->done : p->total;
    int filled = p->total ? (int)(BAR_WIDTH * done / p->total) : BAR_WIDTH;
    char bar[BAR_WIDTH + 1];
    memset(bar, '#', (size_t)filled);
    memset(bar + filled, '.', (size_t)(BAR_WIDTH - filled));
    bar[BAR_WIDTH] = '\0';
    double elapsed = (double)(now - p->start_ns) * 1e-9;
    double left = done ? elapsed * (double)(p->total - done) / (double)done : 0.0;
    fprintf(stderr, "\r[%s] %3d%%  %5.0fs elapsed, ~%4.0fs left  %-40.40s", bar,
            p->total ? (int)(100 * done / p->total) : 100, elapsed, left, p->label);
    fflush(stderr);
}

void ob_bench_progress_init(ob_bench_progress *p, uint64_t total, bool want)
{
    memset(p, 0, sizeof *p);
    p->enabled = want && isatty(STDERR_FILENO);
    p->total = total;
    p->unit = 1;
    p->start_ns = ob_time_ns();
}

void ob_bench_progress_label(ob_bench_progress *p, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->label, sizeof p->label, fmt, ap);
    va_end(ap);
    if (p->enabled) {
        p->drawn_ns = 0;
        draw(p);
    }
}

void ob_bench_progress_tick(void *user)
{
    ob_bench_progress *p = user;
    p->done += p->unit;
    if (p->enabled) draw(p);
}

void ob_bench_progress_finish(ob_bench_progress *p)
{
    if (!p->enabled) return;
    fprintf(stderr, "\r%*s\r", BAR_WIDTH + 70, "");
    fflush(stderr);
}
