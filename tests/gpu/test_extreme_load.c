/* Extreme workloads: 64 views in one frame (62 environment maps, each before
 * main) and the 128-view cap (the 129th refused, named, run the next frame),
 * environment-map recursion bounds 0..4 (the image changes less and less),
 * 100,000 objects recorded single- and multi-threaded (same image, same
 * command hash), and a shadow-casting light with no caster. Times are
 * printed, never asserted.
 *
 * The scenes, measurements and bounds are the stability cases of
 * demos/stability/ob_stab_load.c, which obelisk-bench reports too; each test
 * runs one and asserts every row's bound itself; rows without one are
 * measured only. */
#include "ob_test_stability.h"

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        OB_TEST_STABILITY_CASE("64 views"),
        OB_TEST_STABILITY_CASE("128-view cap"),
        OB_TEST_STABILITY_CASE("env-map recursion 0..4"),
        OB_TEST_STABILITY_CASE("shadow map without casters"),
        OB_TEST_STABILITY_CASE("many objects"),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
