/* ob_stability.h — the stability cases: numerical precision and extreme
 * cases, each measured for real and set against its bound. One library
 * (demos/stability, target ob_stability) that the tests and the benchmark
 * both link: the tests
 * (tests/gpu/test_extreme_{depth,scale,input,load}.c,
 * tests/unit/test_scene_extreme.c) run one case each and assert every
 * bound, and obelisk-bench's "stability" section runs them all and reports
 * the rows (the same scenes, sizes and numbers).
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
 * Every row: name, what is measured, the error with its unit, the bound,
 * whether the case's other checks held, a verdict, and a run time in ms
 * (median of the case's frames after each renderer's first, or of repeated
 * updates). A row without a bound (NAN) is measured only: it is neither a
 * pass nor a fail, and is counted apart (out->measured), unless its checks
 * failed or nothing could be measured, which fails it like any other row.
 *
 * Messages the cases provoke on purpose (a refused NaN, a named entity left
 * out) are caught and checked, not printed; they are counted in
 * expected_errors / expected_warnings so the program can tell them from real
 * errors. Validation-layer messages are never expected: with validation on
 * they are counted and reported as the row "validation_layer" (bound 0).
 *
 * Lifecycle: ob_stability_run → read or report the rows (obelisk-bench:
 * demos/bench/ob_bench_report.h) → ob_stability_release. Thread rule:
 * [render thread] for both; the run creates and destroys its own renderers
 * and replaces the log sink for its duration (restored before it returns),
 * so no other renderer may run beside it.
 */
#ifndef OB_STABILITY_H
#define OB_STABILITY_H

#include "ob_views.h"

typedef enum ob_stability_verdict {
    OB_STABILITY_FAIL = 0,     /* a check failed, no error was measured, or it is over the bound */
    OB_STABILITY_PASS,         /* the checks held and error <= bound */
    OB_STABILITY_MEASURED,     /* no bound: measured only (the checks held) */
} ob_stability_verdict;

typedef struct ob_stability_row {
    char name[48];
    char measure[128];         /* what the error is */
    double error;              /* NAN when it could not be measured (a fail) */
    char unit[24];
    double bound;              /* NAN: measured only */
    bool checks_ok;            /* the case's other checks held (detail says which) */
    ob_stability_verdict verdict;
    double ms;                 /* run time, NAN when none applies */
    char detail[224];          /* the other numbers of the case, or why it failed */
} ob_stability_row;

/* "pass", "fail" or "measured". */
const char *ob_stability_verdict_name(ob_stability_verdict v);

/* Called before each case runs (label: its name, as desc.only takes it) and
 * after it ran; [render thread], from inside ob_stability_run. */
typedef void (*ob_stability_case_fn)(void *user, const char *label, bool done);

typedef struct ob_stability_desc {
    bool quick;                     /* shrink the two long cases (said in their rows) */
    uint32_t workers;               /* renderer worker pool, 0 → 4 (as the tests) */
    ob_stability_case_fn on_case;   /* NULL: none (obelisk-bench: its progress bar) */
    void *on_case_user;
    const char *only;               /* NULL: every case; else the one case with this label */
} ob_stability_desc;

/* Cases a run of every case runs. [any thread] */
uint32_t ob_stability_case_count(void);

typedef struct ob_stability {
    ob_stability_row *rows;         /* ob_malloc'ed */
    uint32_t count, cap;
    uint32_t failed;                /* rows with verdict OB_STABILITY_FAIL */
    uint32_t measured;              /* rows with verdict OB_STABILITY_MEASURED */
    uint32_t cases, workers;        /* cases run (a case gives one or more rows), worker pool */
    bool quick, validation;
    uint32_t validation_messages;   /* errors + warnings of the validation layer */
    uint64_t expected_errors, expected_warnings;
    double seconds;
    char device_name[256], driver_info[256];
} ob_stability;

/* Runs every case (or desc->only) into *out (zeroed first). Failure: a
 * renderer, scene or allocation failure, or an unknown `only` (logged); out
 * holds the rows done so far and must still be released. A case over its
 * bound is not a failure here: it is a row with verdict OB_STABILITY_FAIL,
 * counted in out->failed. [render thread] */
ob_result ob_stability_run(const ob_stability_desc *desc, ob_stability *out);
/* Frees the rows; a zeroed s is fine. [render thread] */
void ob_stability_release(ob_stability *s);

#endif /* OB_STABILITY_H */
