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

/* A device with validation (and synchronization validation) forced on.
 * Fails the test if no device exists. */
ob_device *ob_test_device_create(void);
/* Fails the test if the validation layer reported any error or warning. */
void ob_test_assert_no_validation(const ob_device *dev);

/* |a - b| <= tol in double precision (cmocka's float assert casts to float). */
void ob_test_assert_near(double a, double b, double tol, const char *expr, const char *file,
                         int line);
#define assert_near(a, b, tol) ob_test_assert_near((a), (b), (tol), #a " ~ " #b, __FILE__, __LINE__)

/* Largest absolute per-channel difference of two RGBA8 images. */
uint32_t ob_test_image_max_diff(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h);

#endif
