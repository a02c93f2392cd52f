/* ob_bench_lights.h — obelisk-bench's lights section: what a frame costs
 * as the number of point lights grows at fixed coverage, with the screen
 * tile grid (the default) and with every light in every fragment
 * (ob_views_set_light_tiles off, which is what per-object light lists would
 * give the wall: every light reaches it).
 *
 * The scene: a wall facing the camera, 120 boxes in front of it, and N
 * point lights on a g x g grid (g = ceil(sqrt(N))) 0.6 in front of the
 * wall. "Fixed coverage": a light's range is 1.25 grid spacings, so each
 * point of the wall is within reach of about the same number of lights
 * (about five) whatever N; what grows with N is the work that does not
 * depend on coverage: filling the light table, the tile masks, the loop
 * over mask words. Rendered single-threaded; rounds alternate grid on and
 * off after a warm-up.
 *
 * A frame's cost: on a CPU device (lavapipe) the process's CPU time while
 * the frame is rendered and waited for (the execution is CPU work there,
 * and unlike wall time it does not move with other load); on a GPU the
 * frame's GPU time from timestamps. Fixed scene, no randomness.
 *
 * Lifecycle: ob_bench_lights_run fills rows (ob_free them). Thread rule:
 * the calling thread renders. */
#ifndef OB_BENCH_LIGHTS_H
#define OB_BENCH_LIGHTS_H

#include "ob_bench_run.h"

typedef struct ob_bench_lights_desc {
    uint32_t width, height;    /* image size */
    uint32_t frames, rounds;   /* measured frames per round and mode; rounds (each on + off) */
    void (*tick)(void *user);  /* after every frame (progress); may be NULL */
    void *tick_user;
} ob_bench_lights_desc;

typedef struct ob_bench_lights_row {
    uint32_t lights;
    float range;               /* each light's, fixed coverage */
    bool tiles;                /* the grid on (the default) or every light everywhere */
    bool cpu_measure;          /* cost is process CPU time (CPU device), else GPU time */
    ob_bench_spread cost_ms;   /* per frame, over every measured frame */
} ob_bench_lights_row;

/* The light counts measured, 0 first. */
#define OB_BENCH_LIGHT_COUNTS 5
extern const uint32_t ob_bench_light_counts[OB_BENCH_LIGHT_COUNTS];

/* Frames ob_bench_lights_run renders (for a progress total). */
uint64_t ob_bench_lights_frames(const ob_bench_lights_desc *d);

/* Two rows per light count (tiles on, then off), 2 * OB_BENCH_LIGHT_COUNTS
 * in all, into *out_rows. */
ob_result ob_bench_lights_run(const ob_bench_lights_desc *d, ob_bench_lights_row **out_rows,
                              uint32_t *out_count);

/* log(cost(256) / cost(4)) / log(64), grid on or off: the exponent of the
 * cost's growth with light count (below 1: sub-linear). NAN when missing. */
double ob_bench_lights_exponent(const ob_bench_lights_row *rows, uint32_t count, bool tiles);

#endif /* OB_BENCH_LIGHTS_H */
