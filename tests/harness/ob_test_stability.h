/* ob_test_stability.h — the extreme-case tests run the stability cases of
 * demos/stability (the ones obelisk-bench reports) and assert every bound
 * themselves, so a case's scene and measurement exist once and its bound
 * is checked by the test, not taken from the case's verdict.
 *
 * Each case is one cmocka test named by its label:
 *     const struct CMUnitTest tests[] = {OB_TEST_STABILITY_CASE("depth precision")};
 * The test runs the case (a renderer, scene or allocation failure fails it)
 * and then, for every row it gave:
 *   - the case's other checks held, else it fails naming the case, the row
 *     and the row's detail;
 *   - a row with a bound: the measured error is a number and within the
 *     bound, else it fails naming the case, the row, the measured value and
 *     the bound;
 *   - a row without a bound is measured only: printed, counted neither as a
 *     pass nor as a fail;
 *   - the verdict the benchmark reports for the row is the one the test
 *     reached (pass, or measured only).
 * A case must give at least one row with a bound. The validation layer must
 * be on and silent for every renderer the case made, and Obelisk's heap back
 * where it was once the case is done. Every row is printed, so the measured
 * numbers can be quoted.
 *
 * Thread rule: the test's thread (the cases' [render thread]).
 */
#ifndef OB_TEST_STABILITY_H
#define OB_TEST_STABILITY_H

#include "ob_test.h"

/* The cmocka test body: state is the case's label. */
void ob_test_stability_run(void **state);

#define OB_TEST_STABILITY_CASE(label) {(label), ob_test_stability_run, NULL, NULL, (void *)(label)}

#endif
