#include "ob_test.h"
#include "ob_test_adopt.h"

#include <string.h>

/* The physical device the engine picks, by name and ids: the handles of one
 * instance mean nothing in another. */
static void engine_choice(VkPhysicalDeviceProperties *out)
{
    ob_device *dev = ob_test_device_create();
    *out = *ob_device_properties(dev);
    ob_device_destroy(dev);
}

VkInstance ob_test_vulkan_instance(const char *app_name, const void *next, const char *exts[2])
{
    exts[0] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    exts[1] = VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME;
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const VkValidationFeatureEnableEXT enables[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT vf = {.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
                                  .pNext = next,
                                  .enabledValidationFeatureCount = 1,
                                  .pEnabledValidationFeatures = enables};
    VkApplicationInfo ai = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
                            .pApplicationName = app_name,
                            .apiVersion = VK_API_VERSION_1_3};
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
                               .pNext = &vf,
                               .pApplicationInfo = &ai,
                               .enabledLayerCount = 1,
                               .ppEnabledLayerNames = layers,
                               .enabledExtensionCount = 2,
                               .ppEnabledExtensionNames = exts};
    VkInstance instance = VK_NULL_HANDLE;
    assert_int_equal(vkCreateInstance(&ci, NULL, &instance), VK_SUCCESS);
    return instance;
}

void ob_test_vulkan_create(ob_test_vulkan *tv)
{
    memset(tv, 0, sizeof *tv);
    VkPhysicalDeviceProperties want;
    engine_choice(&want);

    tv->instance = ob_test_vulkan_instance("obelisk-test-adopt", NULL, tv->instance_exts);

    VkPhysicalDevice pds[16];
    uint32_t n = 16;
    assert_true(vkEnumeratePhysicalDevices(tv->instance, &n, pds) >= 0);
    for (uint32_t i = 0; i < n && !tv->physical; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pds[i], &p);
        if (p.vendorID == want.vendorID && p.deviceID == want.deviceID &&
            strcmp(p.deviceName, want.deviceName) == 0)
            tv->physical = pds[i];
    }
    if (!tv->physical) fail_msg("the engine's device '%s' is not listed on a second instance", want.deviceName);

    VkQueueFamilyProperties qf[16];
    n = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(tv->physical, &n, qf);
    tv->family = UINT32_MAX;
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    for (uint32_t i = 0; i < n && tv->family == UINT32_MAX; i++)
        if ((qf[i].queueFlags & need) == need) tv->family = i;
    assert_true(tv->family != UINT32_MAX);

    /* What the engine enables on its own device, where supported. */
    VkPhysicalDeviceVulkan12Features has12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 has = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &has12};
    vkGetPhysicalDeviceFeatures2(tv->physical, &has);
    tv->f13 = (VkPhysicalDeviceVulkan13Features){
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .dynamicRendering = VK_TRUE, .synchronization2 = VK_TRUE, .maintenance4 = VK_TRUE};
    tv->f12 = (VkPhysicalDeviceVulkan12Features){
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES,
        .pNext = &tv->f13,
        .timelineSemaphore = has12.timelineSemaphore,
        .hostQueryReset = has12.hostQueryReset};
    tv->f2 = (VkPhysicalDeviceFeatures2){
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
        .pNext = &tv->f12,
        .features = {.samplerAnisotropy = has.features.samplerAnisotropy,
                     .fillModeNonSolid = has.features.fillModeNonSolid,
                     .depthClamp = has.features.depthClamp,
                     .depthBiasClamp = has.features.depthBiasClamp,
                     .wideLines = has.features.wideLines,
                     .independentBlend = has.features.independentBlend,
                     .multiDrawIndirect = has.features.multiDrawIndirect,
                     .textureCompressionBC = has.features.textureCompressionBC}};
    tv->device_exts[0] = VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qi = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
                                  .queueFamilyIndex = tv->family,
                                  .queueCount = 1,
                                  .pQueuePriorities = &priority};
    VkDeviceCreateInfo di = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
                             .pNext = &tv->f2,
                             .queueCreateInfoCount = 1,
                             .pQueueCreateInfos = &qi,
                             .enabledExtensionCount = 1,
                             .ppEnabledExtensionNames = tv->device_exts};
    assert_int_equal(vkCreateDevice(tv->physical, &di, NULL, &tv->device), VK_SUCCESS);
    vkGetDeviceQueue(tv->device, tv->family, 0, &tv->queue);
    tv->handles = (ob_vulkan_handles){
        .instance = tv->instance,
        .physical = tv->physical,
        .device = tv->device,
        .queue_family = tv->family,
        .queue = tv->queue,
        .api_version = VK_API_VERSION_1_3,
        .instance_extensions = tv->instance_exts,
        .instance_extension_count = 2,
        .device_extensions = tv->device_exts,
        .device_extension_count = 1,
        .features = &tv->f2,
    };
}

void ob_test_vulkan_destroy(ob_test_vulkan *tv)
{
    if (tv->device) {
        vkDeviceWaitIdle(tv->device);
        vkDestroyDevice(tv->device, NULL);
    }
    if (tv->instance) vkDestroyInstance(tv->instance, NULL);
    memset(tv, 0, sizeof *tv);
}
