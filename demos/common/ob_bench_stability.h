/* ob_bench_stability.h — obelisk-bench's "stability" section: numerical
 * precision and extreme cases, each measured for real and set against the
 * bound its test asserts (tests/gpu/test_extreme_{depth,scale,input,load}.c,
 * tests/unit/test_scene_extreme.c; the same scenes, sizes and numbers).
 *
 *   depth_precision     reversed-Z, znear 1e-3: two quads 0.1% of the
 *                       distance apart at 1e3, 1e4, 1e5 units, both draw
 *                       orders; and the smallest gap still resolved
 *   large_coordinates   a lit, shadowed, reflective scene at 1e7 (+ fractions)
 *                       against the same at the origin; 1e9..1e13 measured
 *                       only; the scene graph's camera-relative matrices
 *   scale_invariance    a shadowed scene scaled 1e-30..1e30 against scale 1
 *   deep_hierarchy      10,000- and 100,000-level chains against a closed form
 *   long_run_rotation   10 million rotation-controller updates (1 million
 *                       with quick)
 *   degenerate input    zero scale, up parallel to the view direction, refused
 *                       views and cameras, empty scene, switched-off light,
 *                       NaN/Inf in transforms, lights, camera, materials,
 *                       parameters, an entity beyond float range
 *   workloads           64 views in one frame, the 128-view cap, env-map
 *                       recursion bounds 0..4, 100,000 objects ST vs MT
 *                       (10,000 with quick), a shadow map without casters
 *
 * Every row: name, what is measured, the error with its unit, the bound
 * (NAN: measured only), pass, and a run time in ms (median of the case's
 * frames after each renderer's first, or of repeated updates).
 *
 * Messages the cases provoke on purpose (a refused NaN, a named entity left
 * out) are caught and checked, not printed; they are counted in
 * expected_errors / expected_warnings so the program can tell them from real
 * errors. Validation-layer messages are never expected: with validation on
 * they are counted and reported as the row "validation_layer" (bound 0).
 *
 * Lifecycle: ob_bench_stability_run → report it (ob_bench_report.h: table,
 * JSON, CSV) → ob_bench_stability_release. Thread rule: render thread; the run creates and
 * destroys its own renderers and replaces the log sink for its duration
 * (restored before it returns).
 */
#ifndef OB_BENCH_STABILITY_H
#define OB_BENCH_STABILITY_H

#include "ob_bench_progress.h"
#include "ob_demo.h"

typedef struct ob_bench_stability_row {
    char name[48];
    char measure[128];         /* what the error is */
    double error;              /* NAN when it could not be measured (then pass is false) */
    char unit[24];
    double bound;              /* NAN: measured only (pass is then true) */
    bool pass;                 /* error <= bound and the case's other checks held */
    double ms;                 /* run time, NAN when none applies */
    char detail[224];          /* the other numbers of the case, or why it failed */
} ob_bench_stability_row;

typedef struct ob_bench_stability_desc {
    bool quick;                     /* shrink the two long cases (said in their rows) */
    uint32_t workers;               /* renderer worker pool, 0 → 4 (as the tests) */
    ob_bench_progress *progress;    /* NULL: none; one tick per case, labelled */
    const char *only;               /* NULL: every case; else the one case with this label */
} ob_bench_stability_desc;

/* Progress ticks a run of every case gives (one per case). */
uint32_t ob_bench_stability_case_count(void);

typedef struct ob_bench_stability {
    ob_bench_stability_row *rows;   /* ob_malloc'ed */
    uint32_t count, cap;
    uint32_t failed;                /* rows that did not pass */
    uint32_t cases, workers;        /* cases run (a case gives one or more rows), worker pool */
    bool quick, validation;
    uint32_t validation_messages;   /* errors + warnings of the validation layer */
    uint64_t expected_errors, expected_warnings;
    double seconds;
    char device_name[256], driver_info[256];
} ob_bench_stability;

/* Runs every case (or desc->only) into *out (zeroed first). Failure: a
 * renderer, scene or allocation failure, or an unknown `only` (logged); out
 * holds the rows done so far and must still be released. A case over its
 * bound is not a failure here: it is a row with pass = false, counted in
 * out->failed. */
ob_result ob_bench_stability_run(const ob_bench_stability_desc *desc, ob_bench_stability *out);
/* Frees the rows; zeroed s ok. */
void ob_bench_stability_release(ob_bench_stability *s);

#endif /* OB_BENCH_STABILITY_H */
