/* ob_test.h — helpers shared by every test suite.
 *
 * Log capture: every test installs the capture sink (ob_test_setup_log) so a
 * test can assert on the messages a user would see, and so any message from
 * the Vulkan validation layer (module "vk-validation") fails the test.
 */
#ifndef OB_TEST_H
#define OB_TEST_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "ob_core.h"
#include "ob_device.h"

/* Install the capturing log sink (idempotent). Lines are kept and echoed to stderr. */
void ob_test_setup_log(void);
/* Forget captured lines. */
void ob_test_log_clear(void);
/* Echo captured WARN/ERROR lines to stderr (the default) or keep them
 * quiet; fault-injection walks log thousands of expected errors. */
void ob_test_log_set_echo(bool on);
/* True if any captured line (since the last clear) contains every given
 * substring (NULL-terminated list). */
bool ob_test_log_has(const char *needle, ...);
/* Count of captured lines at or above level since the last clear. */
uint32_t ob_test_log_count(ob_log_level min_level);
/* Print up to max captured lines at or above level (since the last clear)
 * to stderr, to show what led to a failed assertion. */
void ob_test_log_dump(ob_log_level min_level, uint32_t max);
/* Fails the test, showing what was captured, unless one captured line
 * (since the last clear) contains every given substring:
 * assert_logged("'box'", "pbr.frag"). */
#define assert_logged(...) ob_test_assert_logged(__FILE__, __LINE__, __VA_ARGS__, (const char *)NULL)
void ob_test_assert_logged(const char *file, int line, const char *needle, ...);
/* cmocka setup and teardown for a test that provokes errors on purpose:
 * before, echo off and the captured lines forgotten; after, echo on and
 * every fault kind disarmed. */
int ob_test_errors_setup(void **state);
int ob_test_errors_teardown(void **state);
/* A cmocka test entry with those two around it. */
#define ob_test_expecting_errors(f) cmocka_unit_test_setup_teardown(f, ob_test_errors_setup, ob_test_errors_teardown)

/* Copies every file of the library's default shader folder into the
 * existing folder `to` (for tests that point a device at a folder of their
 * own, or break one shader in a copy); returns the number copied. Fails
 * the test on any error. */
uint32_t ob_test_copy_shader_folder(const char *to);

/* A device with validation (and synchronization validation) forced on.
 * Fails the test if no device exists. */
ob_device *ob_test_device_create(void);
/* Fails the test if the validation layer reported any error or warning. */
void ob_test_assert_no_validation(const ob_device *dev);

/* |a - b| <= tol in double precision (cmocka's float assert casts to float). */
void ob_test_assert_near(double a, double b, double tol, const char *expr, const char *file,
                         int line);
#define assert_near(a, b, tol) ob_test_assert_near((a), (b), (tol), #a " ~ " #b, __FILE__, __LINE__)

/* Skips the calling test in the thread sanitizer build (tests/CMakeLists.txt
 * defines OB_TEST_TSAN there): for a fault walk that runs on the render
 * thread alone, where that sanitizer has no race to find and each point
 * costs a whole stack several times over. The plain and address builds walk
 * it (leaks, memory errors, the pictures after each fault). */
#ifdef OB_TEST_TSAN
#define ob_test_skip_under_tsan(why)                                                     \
    do {                                                                                 \
        print_message("[ skipped  ] under the thread sanitizer: %s\n", why);            \
        skip();                                                                          \
    } while (0)
#else
#define ob_test_skip_under_tsan(why) ((void)0)
#endif

/* Largest absolute per-channel difference of two RGBA8 images. */
uint32_t ob_test_image_max_diff(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h);

#endif
