/* Numerical precision of rendering: reversed-Z depth ordering of nearly
 * coplanar surfaces far from the camera, and a whole lit, shadowed,
 * reflective scene moved 1e7 units from the origin (and, measured only, up to
 * 1e13).
 *
 * The scenes, measurements and bounds are the stability cases of
 * demos/stability/ob_stab_precision.c, which obelisk-bench reports too; each
 * test runs one and asserts every row's bound itself; rows without one are
 * measured only (see ob_test_stability.h). */
#include "ob_test_stability.h"

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        /* Two quads 0.1% of the distance apart at 1e3, 1e4, 1e5 units, znear
         * 1e-3, both draw orders: no wrong pixel; smaller gaps measured. */
        OB_TEST_STABILITY_CASE("depth precision"),
        /* The scene at 1e7 (with fractions) renders exactly as at the origin,
         * shadow and env map included; 1e9..1e13 measured only. */
        OB_TEST_STABILITY_CASE("large coordinates"),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
