#include "ob_test.h"

/* Kept apart from ob_test.c so that unit tests, which never touch a device,
 * do not pull the device code into their link. */

ob_device *ob_test_device_create(void)
{
    ob_test_setup_log();
    ob_result r;
    ob_device_desc desc = {.app_name = "obelisk-test", .validation = 1};
    ob_device *dev = ob_device_create(&desc, &r);
    if (!dev) fail_msg("no Vulkan device with validation: %s (see the [device] log lines above)", ob_result_name(r));
    if (!ob_device_validation_enabled(dev)) fail_msg("device created without validation");
    return dev;
}

void ob_test_assert_no_validation(const ob_device *dev)
{
    ob_validation_counts c = ob_device_validation_counts(dev);
    if (c.errors || c.warnings)
        fail_msg("validation layer reported %u errors and %u warnings (see the [vk-validation] lines above)",
                 c.errors, c.warnings);
}
