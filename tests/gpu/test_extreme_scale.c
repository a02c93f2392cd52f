/* Extreme sizes: the same shadowed scene scaled by 1e-30 ... 1e30 (camera,
 * near plane and light fit scaled with it) renders exactly like the unit one
 * (1e36 measured only), and an entity whose camera-relative transform does
 * not fit in a float is left out, named once in the log, instead of being
 * drawn with another entity's matrix.
 *
 * The scenes, measurements and bounds are the stability cases of
 * demos/stability/ob_stab_{precision,input}.c, which obelisk-bench reports
 * too; each test runs one and asserts every row's bound itself; rows without
 * one are measured only. */
#include "ob_test_stability.h"

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        OB_TEST_STABILITY_CASE("scale invariance"),
        OB_TEST_STABILITY_CASE("entity beyond float range"),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
