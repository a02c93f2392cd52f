/* Degenerate and invalid input, rendered: zero scale (singular normal
 * matrix), an up vector parallel to the view direction, zero-size views and
 * bad cameras, an empty scene, switched-off lights, NaN/Inf in transforms,
 * lights, the camera, materials and parameters. Each case compares the image
 * with the scene without the bad part (no pixel differs, none turns
 * NaN-black) and checks the message a user would read names the rejected
 * entity, and that the image comes back once the input is fixed.
 *
 * The scenes, measurements and bounds are the stability cases of
 * demos/stability/ob_stab_input.c, which obelisk-bench reports too; each test
 * runs one and asserts every row's bound itself; rows without one are
 * measured only. */
#include "ob_test_stability.h"

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        OB_TEST_STABILITY_CASE("zero scale"),
        OB_TEST_STABILITY_CASE("flattened box"),
        OB_TEST_STABILITY_CASE("up parallel to direction"),
        OB_TEST_STABILITY_CASE("refused views and cameras"),
        OB_TEST_STABILITY_CASE("empty scene"),
        OB_TEST_STABILITY_CASE("light at intensity 0"),
        OB_TEST_STABILITY_CASE("non-finite transforms"),
        OB_TEST_STABILITY_CASE("non-finite light and camera"),
        OB_TEST_STABILITY_CASE("non-finite material"),
        OB_TEST_STABILITY_CASE("non-finite parameter"),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
