/* ob_device.c — instance, validation capture, logical device and one-shot
 * command buffers. Frame slots and deferred deletion are ob_frame_slots.c,
 * the Vulkan allocation callbacks ob_vk_allocators.c.
 *
 * Creation runs in stages (slots → instance → physical choice → logical
 * device → one-shot objects → resource registry); each stage undoes itself
 * on failure and create unwinds the earlier ones, so every fault-injection
 * point leaves nothing behind. An adopted device (desc.adopt) replaces the
 * instance, choice and logical stages by one that checks the application's
 * handles and only adds a messenger; the unwinding then leaves them alive.
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_device_internal.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#define OB_VALIDATION_LAYER "VK_LAYER_KHRONOS_validation"

struct ob_device {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger;
    PFN_vkSetDebugUtilsObjectNameEXT set_object_name;
    bool validation;
    bool validation_required;   /* desc.validation > 0, not only $OB_VALIDATION */
    const char *const *extra_instance_exts;
    uint32_t extra_instance_ext_count;
    bool swapchain;
    /* The instance and device are the application's (desc.adopt): the
     * engine destroys its messenger and its own objects, never those. */
    bool adopted;
    /* Info/verbose messages (about 90 loader lines per device) are logged
     * only with OB_LOG=debug; otherwise they would swamp log captures. */
    bool log_infos;

    VkPhysicalDevice physical;
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties mem_props;
    char driver_info[VK_MAX_DRIVER_INFO_SIZE + VK_MAX_DRIVER_NAME_SIZE + 4];
    ob_device_caps caps;

    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    PFN_vkCmdPushDescriptorSetKHR push_descriptor;

    /* Written by the validation callback on whichever thread made the call. */
    atomic_uint val_errors, val_warnings, val_infos;
    atomic_bool lost;

    ob_frame_slots slots;    /* frame slots and their deferred deletions (ob_frame_slots.c) */

    VkCommandPool oneshot_pool;
    VkFence oneshot_fence;

    ob_resource_registry *registry;
    char *shader_dir;        /* desc.shader_dir copied; NULL when not given */
    bool heap_kept;          /* desc.driver_heap took effect (ob_device_keeps_driver_heap) */
};

/* -------------------------------------------------------- validation capture */

static VKAPI_ATTR VkBool32 VKAPI_CALL validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    ob_device *dev = user;
    ob_log_level level;
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        atomic_fetch_add(&dev->val_errors, 1);
        level = OB_LOG_ERROR;
    } else if ((severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) ||
               ((types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT) &&
                (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT))) {
        atomic_fetch_add(&dev->val_warnings, 1);
        level = OB_LOG_WARN;
    } else {
        atomic_fetch_add(&dev->val_infos, 1);
        if (!dev->log_infos) return VK_FALSE;
        level = OB_LOG_DEBUG;
    }
    const char *id = data && data->pMessageIdName ? data->pMessageIdName : NULL;
    const char *msg = data && data->pMessage ? data->pMessage : "(no message text)";
    if (id && !strstr(msg, id))
        ob_log_write(level, "vk-validation", __FILE__, __LINE__, "[%s] %s", id, msg);
    else
        ob_log_write(level, "vk-validation", __FILE__, __LINE__, "%s", msg);
    return VK_FALSE;   /* never abort the call: the test decides what fails */
}

static bool validation_wanted(int requested)
{
    if (requested > 0) return true;
    if (requested < 0) return false;
    const char *env = getenv("OB_VALIDATION");
    return env && env[0] && strcmp(env, "0") != 0;
}

/* Fills *out_list (ob_free it) with the extensions of `layer` (NULL = the
 * implementation and implicit layers). */
static ob_result list_instance_extensions(const char *layer, VkExtensionProperties **out_list,
                                          uint32_t *out_count)
{
    *out_list = NULL;
    *out_count = 0;
    uint32_t n = 0;
    VkResult vr = OB_VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &n, NULL));
    if (vr < 0) return ob_result_from_vk(vr);
    VkExtensionProperties *list = ob_calloc(n, sizeof *list);
    if (!list) return OB_ERR_OUT_OF_HOST_MEMORY;
    vr = OB_VK_CHECK(vkEnumerateInstanceExtensionProperties(layer, &n, list));
    if (vr < 0) {
        ob_free(list);
        return ob_result_from_vk(vr);
    }
    *out_list = list;
    *out_count = n;
    return OB_OK;
}

static bool list_has(const VkExtensionProperties *list, uint32_t n, const char *name)
{
    for (uint32_t i = 0; i < n; i++)
        if (strcmp(list[i].extensionName, name) == 0) return true;
    return false;
}

static ob_result validation_layer_present(bool *out_present)
{
    *out_present = false;
    uint32_t n = 0;
    VkResult vr = OB_VK_CHECK(vkEnumerateInstanceLayerProperties(&n, NULL));
    if (vr < 0) return ob_result_from_vk(vr);
    VkLayerProperties *layers = ob_calloc(n, sizeof *layers);
    if (!layers) return OB_ERR_OUT_OF_HOST_MEMORY;
    vr = OB_VK_CHECK(vkEnumerateInstanceLayerProperties(&n, layers));
    for (uint32_t i = 0; vr >= 0 && i < n; i++)
        if (strcmp(layers[i].layerName, OB_VALIDATION_LAYER) == 0) *out_present = true;
    ob_free(layers);
    return vr < 0 ? ob_result_from_vk(vr) : OB_OK;
}

/* ------------------------------------------------------------------ instance */

static void instance_destroy(ob_device *dev)
{
    if (dev->messenger) dev->destroy_messenger(dev->instance, dev->messenger, NULL);
    dev->messenger = VK_NULL_HANDLE;
    /* The messenger chained into VkInstanceCreateInfo still reports here. */
    if (dev->instance && !dev->adopted) vkDestroyInstance(dev->instance, NULL);
    dev->instance = VK_NULL_HANDLE;
}

static VkDebugUtilsMessengerCreateInfoEXT messenger_info(ob_device *dev)
{
    return (VkDebugUtilsMessengerCreateInfoEXT){
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_VERBOSE_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT,
        .pfnUserCallback = validation_message,
        .pUserData = dev,
    };
}

/* The debug-utils entry points of dev->instance, and with validation the
 * messenger that routes its messages into the log. On failure nothing is
 * left to undo but the instance. */
static ob_result messenger_create(ob_device *dev, bool debug_utils)
{
    if (debug_utils) {
        dev->set_object_name = (PFN_vkSetDebugUtilsObjectNameEXT)vkGetInstanceProcAddr(
            dev->instance, "vkSetDebugUtilsObjectNameEXT");
    }
    if (!dev->validation) return OB_OK;
    PFN_vkCreateDebugUtilsMessengerEXT pfn_vkCreateDebugUtilsMessengerEXT =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(dev->instance,
                                                                  "vkCreateDebugUtilsMessengerEXT");
    dev->destroy_messenger = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(
        dev->instance, "vkDestroyDebugUtilsMessengerEXT");
    if (!pfn_vkCreateDebugUtilsMessengerEXT || !dev->destroy_messenger) {
        OB_LOG_E("device", "validation is on but vkCreateDebugUtilsMessengerEXT is missing: "
                           "messages could not be captured");
        return OB_ERR_UNSUPPORTED;
    }
    VkDebugUtilsMessengerCreateInfoEXT info = messenger_info(dev);
    VkResult vr = OB_VK_CHECK_CREATE(pfn_vkCreateDebugUtilsMessengerEXT(dev->instance, &info, NULL, &dev->messenger));
    if (vr < 0) {
        dev->messenger = VK_NULL_HANDLE;
        return ob_result_from_vk(vr);
    }
    return OB_OK;
}

static ob_result instance_create(ob_device *dev, const char *app_name)
{
    uint32_t loader_version = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_3) {
        OB_LOG_E("device", "the Vulkan loader supports %u.%u; Obelisk needs 1.3",
                 VK_API_VERSION_MAJOR(loader_version), VK_API_VERSION_MINOR(loader_version));
        return OB_ERR_NO_DEVICE;
    }
    bool sync_validation = false;
    if (dev->validation) {
        bool present;
        ob_result r = validation_layer_present(&present);
        if (r != OB_OK) return r;
        if (!present) {
            OB_LOG_E("device", "validation was requested (OB_VALIDATION / desc.validation) but %s is "
                               "not installed (Debian: vulkan-validationlayers); refusing to run unchecked",
                     OB_VALIDATION_LAYER);
            return OB_ERR_UNSUPPORTED;
        }
        VkExtensionProperties *layer_exts;
        uint32_t n;
        r = list_instance_extensions(OB_VALIDATION_LAYER, &layer_exts, &n);
        if (r != OB_OK) return r;
        sync_validation = list_has(layer_exts, n, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        ob_free(layer_exts);
        if (!sync_validation)
            OB_LOG_W("device", "%s lacks %s: synchronization validation is off", OB_VALIDATION_LAYER,
                     VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    }
    VkExtensionProperties *exts;
    uint32_t ext_count;
    ob_result r = list_instance_extensions(NULL, &exts, &ext_count);
    if (r != OB_OK) return r;
    /* The validation layer provides debug utils itself when the loader does not. */
    bool debug_utils = dev->validation || list_has(exts, ext_count, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    const char *enabled_exts[2 + 16];
    uint32_t enabled_count = 0;
    for (uint32_t i = 0; i < dev->extra_instance_ext_count; i++) {
        const char *name = dev->extra_instance_exts[i];
        if (!list_has(exts, ext_count, name) || enabled_count >= 16) {
            OB_LOG_E("device", "instance extension %s is %s", name,
                     enabled_count >= 16 ? "one too many (at most 16 extra)" : "not available");
            ob_free(exts);
            return OB_ERR_UNSUPPORTED;
        }
        enabled_exts[enabled_count++] = name;
    }
    ob_free(exts);

    if (debug_utils) enabled_exts[enabled_count++] = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    if (sync_validation) enabled_exts[enabled_count++] = VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME;
    const char *layers[] = {OB_VALIDATION_LAYER};

    VkDebugUtilsMessengerCreateInfoEXT messenger = messenger_info(dev);
    const VkValidationFeatureEnableEXT enables[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features = {
        .sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
        .pNext = &messenger,
        .enabledValidationFeatureCount = OB_ARRAY_COUNT(enables),
        .pEnabledValidationFeatures = enables,
    };
    VkApplicationInfo app = {
        .sType = VK_STRUCTURE_TYPE_APPLICATION_INFO,
        .pApplicationName = app_name,
        .applicationVersion = 1,
        .pEngineName = "obelisk",
        .engineVersion = VK_MAKE_API_VERSION(0, 0, 1, 0),
        .apiVersion = VK_API_VERSION_1_3,
    };
    VkInstanceCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = dev->validation ? (sync_validation ? (const void *)&features : (const void *)&messenger)
                                 : NULL,
        .pApplicationInfo = &app,
        .enabledLayerCount = dev->validation ? 1u : 0u,
        .ppEnabledLayerNames = layers,
        .enabledExtensionCount = enabled_count,
        .ppEnabledExtensionNames = enabled_exts,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateInstance(&info, NULL, &dev->instance));
    if (vr < 0) {
        dev->instance = VK_NULL_HANDLE;
        return vr == VK_ERROR_INCOMPATIBLE_DRIVER ? OB_ERR_NO_DEVICE : ob_result_from_vk(vr);
    }
    ob_device_pin_drivers();
    r = messenger_create(dev, debug_utils);
    if (r != OB_OK) instance_destroy(dev);
    return r;
}

/* ------------------------------------------------------------ logical device */

static void logical_destroy(ob_device *dev)
{
    if (dev->device && !dev->adopted) vkDestroyDevice(dev->device, NULL);
    dev->device = VK_NULL_HANDLE;
    dev->queue = VK_NULL_HANDLE;
}

/* Device-level entry points of extensions the engine needs. */
static ob_result logical_entry_points(ob_device *dev)
{
    dev->push_descriptor =
        (PFN_vkCmdPushDescriptorSetKHR)vkGetDeviceProcAddr(dev->device, "vkCmdPushDescriptorSetKHR");
    if (!dev->push_descriptor) {
        OB_LOG_E("device", "'%s' advertises %s but has no vkCmdPushDescriptorSetKHR",
                 dev->props.deviceName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
        return OB_ERR_UNSUPPORTED;
    }
    return OB_OK;
}

static ob_result logical_create(ob_device *dev)
{
    const ob_device_caps *caps = &dev->caps;
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = dev->queue_family,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    VkPhysicalDeviceVulkan13Features f13 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .dynamicRendering = VK_TRUE,
        .synchronization2 = VK_TRUE,
        /* Required by every Vulkan 1.3 device; SPIR-V 1.6 compute shaders
         * from glslang declare their local size with LocalSizeId, which
         * needs it enabled. */
        .maintenance4 = VK_TRUE,
    };
    VkPhysicalDeviceVulkan12Features f12 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES,
        .pNext = &f13,
        .timelineSemaphore = caps->timeline_semaphore,
        .hostQueryReset = caps->host_query_reset,
    };
    VkPhysicalDeviceFeatures2 f2 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
        .pNext = &f12,
        .features = {
            .samplerAnisotropy = caps->sampler_anisotropy,
            .fillModeNonSolid = caps->fill_mode_non_solid,
            .depthClamp = caps->depth_clamp,
            .depthBiasClamp = caps->depth_bias_clamp,
            .wideLines = caps->wide_lines,
            .independentBlend = caps->independent_blend,
            .multiDrawIndirect = caps->multi_draw_indirect,
            .drawIndirectFirstInstance = caps->draw_indirect_first_instance,
            .textureCompressionBC = caps->texture_compression_bc,
        },
    };
    const char *exts[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    VkDeviceCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = &f2,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queue_info,
        .enabledExtensionCount = dev->swapchain ? 2u : 1u,
        .ppEnabledExtensionNames = exts,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateDevice(dev->physical, &info, NULL, &dev->device));
    if (vr < 0) {
        dev->device = VK_NULL_HANDLE;
        return ob_result_from_vk(vr);
    }
    vkGetDeviceQueue(dev->device, dev->queue_family, 0, &dev->queue);
    ob_result r = logical_entry_points(dev);
    if (r != OB_OK) {
        logical_destroy(dev);
        return r;
    }
    ob_device_set_name(dev, VK_OBJECT_TYPE_DEVICE, (uint64_t)(uintptr_t)dev->device, "obelisk device");
    ob_device_set_name(dev, VK_OBJECT_TYPE_QUEUE, (uint64_t)(uintptr_t)dev->queue, "obelisk queue");
    return OB_OK;
}

/* The chosen physical device, its queue family and properties, into dev. */
static void take_physical(ob_device *dev, const ob_physical_choice *choice)
{
    dev->physical = choice->physical;
    dev->props = choice->props;
    dev->caps = choice->caps;
    dev->queue_family = choice->queue_family;
    memcpy(dev->driver_info, choice->driver_info, sizeof dev->driver_info);
    vkGetPhysicalDeviceMemoryProperties(dev->physical, &dev->mem_props);
}


/* The application's instance, physical device, device and queue, checked;
 * the engine adds only its messenger. On failure the messenger is gone and
 * the handles are untouched. */
static ob_result adopt_create(ob_device *dev, const ob_vulkan_handles *a)
{
    ob_physical_choice choice;
    ob_adopted_info info;
    ob_result r = ob_device_check_adopted(a, &choice, &info);
    if (r != OB_OK) return r;
    dev->adopted = true;
    dev->instance = a->instance;
    take_physical(dev, &choice);
    dev->device = a->device;
    dev->queue = a->queue;
    dev->swapchain = info.swapchain;
    if (dev->validation && !info.debug_utils) {
        /* The application decides what its instance enables: without debug
         * utils nothing can be captured. Asked for in the desc, that is an
         * error; asked for by $OB_VALIDATION alone, a warning. */
        if (dev->validation_required) {
            OB_LOG_E("device", "validation was requested (desc.validation) but the application's "
                     "instance lacks %s: messages could not be captured", VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
            r = OB_ERR_UNSUPPORTED;
            goto fail_destroy_instance;
        }
        OB_LOG_W("device", "OB_VALIDATION is set but the application's instance lacks %s: "
                 "validation messages are not captured", VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        dev->validation = false;
    }
    r = messenger_create(dev, info.debug_utils);
    if (r != OB_OK) goto fail_destroy_instance;
    r = logical_entry_points(dev);
    if (r != OB_OK) goto fail_destroy_instance;
    return OB_OK;
fail_destroy_instance:
    instance_destroy(dev);
    dev->device = VK_NULL_HANDLE;
    dev->queue = VK_NULL_HANDLE;
    return r;
}

/* ----------------------------------------------------------------- one-shot */

static void oneshot_destroy(ob_device *dev)
{
    if (dev->oneshot_fence) vkDestroyFence(dev->device, dev->oneshot_fence, NULL);
    if (dev->oneshot_pool) vkDestroyCommandPool(dev->device, dev->oneshot_pool, NULL);
    dev->oneshot_fence = VK_NULL_HANDLE;
    dev->oneshot_pool = VK_NULL_HANDLE;
}

static ob_result oneshot_create(ob_device *dev)
{
    VkCommandPoolCreateInfo pool_info = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
        .queueFamilyIndex = dev->queue_family,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateCommandPool(dev->device, &pool_info, NULL, &dev->oneshot_pool));
    if (vr < 0) {
        dev->oneshot_pool = VK_NULL_HANDLE;
        return ob_result_from_vk(vr);
    }
    VkFenceCreateInfo fence_info = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vr = OB_VK_CHECK_CREATE(vkCreateFence(dev->device, &fence_info, NULL, &dev->oneshot_fence));
    if (vr < 0) {
        dev->oneshot_fence = VK_NULL_HANDLE;
        oneshot_destroy(dev);
        return ob_result_from_vk(vr);
    }
    ob_device_set_name(dev, VK_OBJECT_TYPE_COMMAND_POOL, (uint64_t)(uintptr_t)dev->oneshot_pool,
                       "obelisk one-shot pool");
    ob_device_set_name(dev, VK_OBJECT_TYPE_FENCE, (uint64_t)(uintptr_t)dev->oneshot_fence,
                       "obelisk one-shot fence");
    return OB_OK;
}

ob_result ob_device_oneshot_begin(ob_device *dev, VkCommandBuffer *out_cmd)
{
    *out_cmd = VK_NULL_HANDLE;
    if (ob_device_is_lost(dev)) return OB_ERR_DEVICE_LOST;
    VkCommandBufferAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = dev->oneshot_pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 1,
    };
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkResult vr = OB_VK_CHECK_CREATE(vkAllocateCommandBuffers(dev->device, &alloc, &cmd));
    if (vr < 0) {
        ob_device_note_result(dev, vr);
        return ob_result_from_vk(vr);
    }
    VkCommandBufferBeginInfo begin = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT,
    };
    vr = OB_VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
    if (vr < 0) {
        vkFreeCommandBuffers(dev->device, dev->oneshot_pool, 1, &cmd);
        ob_device_note_result(dev, vr);
        return ob_result_from_vk(vr);
    }
    *out_cmd = cmd;
    return OB_OK;
}

void ob_device_oneshot_cancel(ob_device *dev, VkCommandBuffer cmd)
{
    if (!dev || !cmd) return;
    vkFreeCommandBuffers(dev->device, dev->oneshot_pool, 1, &cmd);
}

ob_result ob_device_oneshot_submit(ob_device *dev, VkCommandBuffer cmd)
{
    if (!cmd) {
        OB_LOG_E("device", "one-shot submit of a null command buffer");
        return OB_ERR_INVALID_ARGUMENT;
    }
    VkResult vr = OB_VK_CHECK(vkEndCommandBuffer(cmd));
    if (vr >= 0 && ob_device_is_lost(dev)) vr = VK_ERROR_DEVICE_LOST;
    if (vr >= 0) {
        VkCommandBufferSubmitInfo cmd_info = {
            .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
            .commandBuffer = cmd,
        };
        VkSubmitInfo2 submit = {
            .sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
            .commandBufferInfoCount = 1,
            .pCommandBufferInfos = &cmd_info,
        };
        vr = OB_VK_CHECK(OB_VK_SUBMIT(vkQueueSubmit2(dev->queue, 1, &submit, dev->oneshot_fence)));
        if (vr >= 0) {
            vr = OB_VK_CHECK(OB_VK_WAIT(
                vkWaitForFences(dev->device, 1, &dev->oneshot_fence, VK_TRUE, UINT64_MAX)));
            /* A fence left signalled would fail the next one-shot submission. */
            VkResult reset = OB_VK_CHECK(vkResetFences(dev->device, 1, &dev->oneshot_fence));
            if (vr >= 0 && reset < 0) vr = reset;
            if (vr < 0) {
                /* Possibly still pending: the pool frees it at destroy. */
                ob_device_note_result(dev, vr);
                return ob_result_from_vk(vr);
            }
        }
    }
    vkFreeCommandBuffers(dev->device, dev->oneshot_pool, 1, &cmd);
    ob_device_note_result(dev, vr);
    return ob_result_from_vk(vr);
}

ob_result ob_device_wait_idle(ob_device *dev)
{
    VkResult vr = OB_VK_CHECK(OB_VK_WAIT(vkDeviceWaitIdle(dev->device)));
    ob_device_note_result(dev, vr);
    return ob_result_from_vk(vr);
}

/* Instance, physical device choice and logical device of the engine's own.
 * On failure *stage names the step, and nothing of them is left. */
static ob_result own_create(ob_device *dev, const ob_device_desc *desc, const char **stage)
{
    *stage = "instance";
    dev->extra_instance_exts = desc->instance_extensions;
    dev->extra_instance_ext_count = desc->instance_extensions ? desc->instance_extension_count : 0;
    dev->swapchain = desc->swapchain;
    ob_result r = instance_create(dev, desc->app_name ? desc->app_name : "obelisk");
    if (r != OB_OK) return r;

    const char *selector = desc->device ? desc->device : getenv("OB_DEVICE");
    ob_physical_choice choice;
    *stage = "device selection";
    r = ob_device_select_physical(dev->instance, selector, &choice);
    if (r != OB_OK) goto fail_destroy_instance;
    take_physical(dev, &choice);

    *stage = "logical device";
    r = logical_create(dev);
    if (r != OB_OK) goto fail_destroy_instance;
    return OB_OK;

fail_destroy_instance:
    instance_destroy(dev);
    return r;
}

/* ------------------------------------------------------- a CPU device's heap */

/* desc.driver_heap: whether a CPU device keeps the C library's freed heap.
 * An unknown $OB_DRIVER_HEAP is reported and taken as the default. */
static bool driver_heap_wanted(int requested)
{
    if (requested) return requested > 0;
    static const char *const words[] = {"keep", "system"};
    return ob_env_choice("OB_DRIVER_HEAP", words, 2, "device", "keeping the heap") != 1;
}

/* The driver runs in this process on a CPU device, and llvmpipe frees its
 * bins (the scene's triangles and tile commands, 64 KiB blocks from its
 * queue thread's arena) after every render pass. glibc then trims the
 * arena (madvise) and the next pass faults every page in again, zeroed:
 * 21% of all CPU samples at 8 views x 10k (docs/benchmark.md, session 11).
 * A trim threshold above what a frame frees keeps the pages. mallopt is
 * process-wide and cannot be read back, so it is set once; a sanitizer's
 * allocator refuses it (returns 0), and the device then says so. */
static void keep_driver_heap(ob_device *dev, int requested)
{
    /* The setting is read on every device, so a wrong value is reported
     * where it has no effect too (the GPU run of 2026-11-28 found it silent). */
    if (!driver_heap_wanted(requested) || dev->props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) return;
#if defined(__GLIBC__) && defined(M_TRIM_THRESHOLD)
    static atomic_int state;   /* 0 not tried, 1 set, -1 refused */
    if (atomic_load(&state) == 0) {
        bool ok = mallopt(M_TRIM_THRESHOLD, (int)OB_DRIVER_HEAP_KEEP_BYTES) == 1;
        atomic_store(&state, ok ? 1 : -1);
        if (ok)
            OB_LOG_I("device", "CPU device: freed heap memory is kept up to %u MiB (glibc M_TRIM_THRESHOLD), "
                     "so the driver's per-pass allocations do not fault their pages in again",
                     OB_DRIVER_HEAP_KEEP_BYTES >> 20);
    }
    dev->heap_kept = atomic_load(&state) == 1;
#else
    (void)dev;
#endif
}

/* ------------------------------------------------------- create and destroy */

ob_device *ob_device_create(const ob_device_desc *desc, ob_result *out_result)
{
    static const ob_device_desc defaults = {0};
    if (!desc) desc = &defaults;
    ob_result r;
    const char *stage = "device allocation";
    ob_device *dev = ob_calloc(1, sizeof *dev);
    if (!dev) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    atomic_init(&dev->val_errors, 0);
    atomic_init(&dev->val_warnings, 0);
    atomic_init(&dev->val_infos, 0);
    atomic_init(&dev->lost, false);
    dev->validation = validation_wanted(desc->validation);
    dev->validation_required = desc->validation > 0;
    const char *log_env = getenv("OB_LOG");
    dev->log_infos = log_env && strcmp(log_env, "debug") == 0;
    if (desc->shader_dir && !(dev->shader_dir = ob_strdup(desc->shader_dir))) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_dev;
    }

    stage = "frame slots";
    r = ob_frame_slots_init(&dev->slots, desc->frames_in_flight);
    if (r != OB_OK) goto fail_free_dev;
    if (desc->adopt) {
        stage = "adopting the application's device";
        r = adopt_create(dev, desc->adopt);
        if (r != OB_OK) goto fail_destroy_slots;
    } else {
        r = own_create(dev, desc, &stage);
        if (r != OB_OK) goto fail_destroy_slots;
    }
    stage = "one-shot command pool";
    r = oneshot_create(dev);
    if (r != OB_OK) goto fail_destroy_logical;
    stage = "resource registry";
    dev->registry = ob_resource_registry_create(&r);
    if (!dev->registry) goto fail_destroy_oneshot;
    keep_driver_heap(dev, desc->driver_heap);

    OB_LOG_I("device", "using #%u '%s' (%s), Vulkan %u.%u.%u, validation %s%s", dev->caps.device_index,
             dev->props.deviceName, dev->driver_info, VK_API_VERSION_MAJOR(dev->props.apiVersion),
             VK_API_VERSION_MINOR(dev->props.apiVersion), VK_API_VERSION_PATCH(dev->props.apiVersion),
             dev->validation ? "on" : "off", dev->adopted ? ", the application's device" : "");
    if (out_result) *out_result = OB_OK;
    return dev;

fail_destroy_oneshot:
    oneshot_destroy(dev);
fail_destroy_logical:
    logical_destroy(dev);
    instance_destroy(dev);
fail_destroy_slots:
    ob_frame_slots_release(&dev->slots);
fail_free_dev:
    ob_free(dev->shader_dir);
    ob_free(dev);
fail_log:
    OB_LOG_E("device", "device creation failed at %s: %s", stage, ob_result_name(r));
    if (out_result) *out_result = r;
    return NULL;
}

void ob_device_destroy(ob_device *dev)
{
    if (!dev) return;
    ob_device_wait_idle(dev);
    ob_frame_slots_drain(&dev->slots, dev);
    ob_resource_registry_destroy(dev, dev->registry);
    dev->registry = NULL;
    oneshot_destroy(dev);
    logical_destroy(dev);
    instance_destroy(dev);
    ob_frame_slots_release(&dev->slots);
    ob_free(dev->shader_dir);
    ob_free(dev);
}

/* ----------------------------------------------------------------- accessors */

VkInstance ob_device_vk_instance(const ob_device *dev) { return dev->instance; }
VkPhysicalDevice ob_device_vk_physical(const ob_device *dev) { return dev->physical; }
VkDevice ob_device_vk(const ob_device *dev) { return dev->device; }
VkQueue ob_device_vk_queue(const ob_device *dev) { return dev->queue; }
uint32_t ob_device_queue_family(const ob_device *dev) { return dev->queue_family; }
const VkPhysicalDeviceProperties *ob_device_properties(const ob_device *dev) { return &dev->props; }
const char *ob_device_name(const ob_device *dev) { return dev->props.deviceName; }
const char *ob_device_shader_dir(const ob_device *dev) { return dev->shader_dir; }
const char *ob_device_driver_info(const ob_device *dev) { return dev->driver_info; }
bool ob_device_is_cpu(const ob_device *dev) { return dev->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
bool ob_device_keeps_driver_heap(const ob_device *dev) { return dev->heap_kept; }
PFN_vkCmdPushDescriptorSetKHR ob_device_push_descriptor_fn(const ob_device *dev) { return dev->push_descriptor; }
const ob_device_caps *ob_device_get_caps(const ob_device *dev) { return &dev->caps; }
bool ob_device_validation_enabled(const ob_device *dev) { return dev->validation; }
bool ob_device_is_adopted(const ob_device *dev) { return dev->adopted; }
bool ob_device_has_swapchain(const ob_device *dev) { return dev->swapchain; }
ob_resource_registry *ob_device_registry(const ob_device *dev) { return dev->registry; }
ob_frame_slots *ob_device_frame_slots(ob_device *dev) { return &dev->slots; }

double ob_device_timestamp_period_ns(const ob_device *dev)
{
    return dev->caps.timestamp_valid_bits ? (double)dev->props.limits.timestampPeriod : 0.0;
}

ob_validation_counts ob_device_validation_counts(const ob_device *dev)
{
    /* The counters are written from any thread; reading through a const
     * device is still an atomic load. */
    ob_device *d = (ob_device *)dev;
    ob_validation_counts c = {
        .errors = atomic_load(&d->val_errors),
        .warnings = atomic_load(&d->val_warnings),
        .infos = atomic_load(&d->val_infos),
    };
    return c;
}

void ob_device_set_name(ob_device *dev, VkObjectType type, uint64_t handle, const char *name)
{
    if (!dev || !dev->set_object_name || !dev->device || !handle || !name) return;
    VkDebugUtilsObjectNameInfoEXT info = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT,
        .objectType = type,
        .objectHandle = handle,
        .pObjectName = name,
    };
    OB_VK_CHECK(dev->set_object_name(dev->device, &info));
}

uint32_t ob_device_memory_type(const ob_device *dev, uint32_t type_bits, VkMemoryPropertyFlags required)
{
    for (uint32_t i = 0; i < dev->mem_props.memoryTypeCount; i++) {
        if ((type_bits & (1u << i)) && (dev->mem_props.memoryTypes[i].propertyFlags & required) == required)
            return i;
    }
    return UINT32_MAX;
}

bool ob_device_host_memory_is_device_local(const ob_device *dev)
{
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    uint32_t type = ob_device_memory_type(dev, UINT32_MAX, host);
    return type != UINT32_MAX &&
           (dev->mem_props.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
}

void ob_device_note_result(ob_device *dev, VkResult res)
{
    if (res != VK_ERROR_DEVICE_LOST || !dev) return;
    if (!atomic_exchange(&dev->lost, true))
        OB_LOG_E("device", "device '%s' lost: new work is refused; destroy and recreate the device",
                 dev->props.deviceName);
}

bool ob_device_is_lost(const ob_device *dev)
{
    return atomic_load(&((ob_device *)dev)->lost);
}
