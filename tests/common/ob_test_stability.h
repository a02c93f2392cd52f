/* ob_test_stability.h — the extreme-case tests run the stability cases of
 * demos/common/ob_bench_stab_*.c (the ones obelisk-bench reports) and assert
 * on their rows, so a case's scene, measurement and bound exist once.
 *
 * Each case is one cmocka test named by its label:
 *     const struct CMUnitTest tests[] = {OB_TEST_STABILITY_CASE("depth precision")};
 * The test passes when the case ran without error and every row it gave
 * passed (error within the bound and the case's other checks), with the
 * validation layer on and silent for every renderer the case made, and
 * Obelisk's heap back where it was once the case is done. The rows are
 * printed, so the measured numbers can be quoted.
 */
#ifndef OB_TEST_STABILITY_H
#define OB_TEST_STABILITY_H

#include "ob_test.h"

/* The cmocka test body: state is the case's label. */
void ob_test_stability_run(void **state);

#define OB_TEST_STABILITY_CASE(label) {(label), ob_test_stability_run, NULL, NULL, (void *)(label)}

#endif
