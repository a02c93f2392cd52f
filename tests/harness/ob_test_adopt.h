/* ob_test_adopt — one Vulkan instance and device made by the test, for
 * renderers and stacks created on it through ob_device_desc.adopt.
 *
 * Fault walks create hundreds of renderers. Each with its own instance
 * loads and unloads the driver as many times, which a real driver does not
 * survive (NVIDIA 580: "cannot allocate memory in static TLS block", then
 * "Found no drivers"). The points that are not about instance and device
 * creation are walked on one of these instead; test_device walks the
 * creation points themselves.
 *
 * The device is the one the engine picks (same name, vendor and device id
 * as ob_device_create with the same $OB_DEVICE) with the features and
 * extensions the engine enables on its own device, the validation layer with
 * synchronization validation and debug utils, so the engine's messenger
 * captures every message as it does on its own instance. [test thread] */
#ifndef OB_TEST_ADOPT_H
#define OB_TEST_ADOPT_H

#include "ob_device.h"

typedef struct ob_test_vulkan {
    VkInstance instance;
    VkPhysicalDevice physical;
    VkDevice device;
    VkQueue queue;
    uint32_t family;
    const char *instance_exts[2];
    const char *device_exts[1];
    VkPhysicalDeviceVulkan13Features f13;
    VkPhysicalDeviceVulkan12Features f12;
    VkPhysicalDeviceFeatures2 f2;
    ob_vulkan_handles handles;   /* for ob_device_desc.adopt */
} ob_test_vulkan;

/* The instance alone: Vulkan 1.3, the validation layer with synchronization
 * validation, VK_EXT_debug_utils and VK_EXT_validation_features (their names
 * in `exts`, which must outlive the instance's use as adopted handles);
 * `next` (a messenger's create info, or NULL) is chained after the
 * validation features. Fails the test when it cannot. */
VkInstance ob_test_vulkan_instance(const char *app_name, const void *next, const char *exts[2]);
/* Creates the instance and device; fails the test when it cannot. */
void ob_test_vulkan_create(ob_test_vulkan *out);
/* Waits idle and destroys the device and instance. */
void ob_test_vulkan_destroy(ob_test_vulkan *tv);

#endif
