/* ob_device_adopt.c — checking the application's own Vulkan objects
 * (ob_device_desc.adopt) against what the engine needs.
 *
 * The engine cannot enable anything on a device it did not create, so every
 * requirement is checked against what the application *enabled*, not what
 * the hardware supports, and everything missing is named in one log line:
 * the application has to change its vkCreateDevice call, and should learn
 * all it must change at once.
 */
#include "ob_device_internal.h"

#include <stdio.h>
#include <string.h>

typedef struct enabled_features {
    VkPhysicalDeviceFeatures base;
    bool dynamic_rendering, synchronization2, maintenance4;
    bool timeline_semaphore, host_query_reset;
} enabled_features;

/* Longer chains than this are taken for a loop in the pNext pointers. */
#define MAX_CHAIN 64

static ob_result read_features(const VkPhysicalDeviceFeatures2 *f2, enabled_features *e)
{
    memset(e, 0, sizeof *e);
    if (!f2) return OB_OK;
    if (f2->sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2) {
        OB_LOG_E("device", "ob_vulkan_handles.features is not a VkPhysicalDeviceFeatures2 (sType %d)",
                 (int)f2->sType);
        return OB_ERR_INVALID_ARGUMENT;
    }
    e->base = f2->features;
    uint32_t n = 0;
    for (const VkBaseInStructure *s = f2->pNext; s; s = s->pNext) {
        if (++n > MAX_CHAIN) {
            OB_LOG_E("device", "ob_vulkan_handles.features: the pNext chain is longer than %u "
                     "structures (a loop?)", MAX_CHAIN);
            return OB_ERR_INVALID_ARGUMENT;
        }
        switch (s->sType) {
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES: {
            const VkPhysicalDeviceVulkan13Features *f = (const void *)s;
            e->dynamic_rendering |= f->dynamicRendering == VK_TRUE;
            e->synchronization2 |= f->synchronization2 == VK_TRUE;
            e->maintenance4 |= f->maintenance4 == VK_TRUE;
            break;
        }
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES: {
            const VkPhysicalDeviceVulkan12Features *f = (const void *)s;
            e->timeline_semaphore |= f->timelineSemaphore == VK_TRUE;
            e->host_query_reset |= f->hostQueryReset == VK_TRUE;
            break;
        }
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES:
            e->dynamic_rendering |=
                ((const VkPhysicalDeviceDynamicRenderingFeatures *)(const void *)s)->dynamicRendering == VK_TRUE;
            break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES:
            e->synchronization2 |=
                ((const VkPhysicalDeviceSynchronization2Features *)(const void *)s)->synchronization2 == VK_TRUE;
            break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES:
            e->maintenance4 |=
                ((const VkPhysicalDeviceMaintenance4Features *)(const void *)s)->maintenance4 == VK_TRUE;
            break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_FEATURES:
            e->timeline_semaphore |=
                ((const VkPhysicalDeviceTimelineSemaphoreFeatures *)(const void *)s)->timelineSemaphore == VK_TRUE;
            break;
        case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_HOST_QUERY_RESET_FEATURES:
            e->host_query_reset |=
                ((const VkPhysicalDeviceHostQueryResetFeatures *)(const void *)s)->hostQueryReset == VK_TRUE;
            break;
        default:
            break;
        }
    }
    return OB_OK;
}

static bool named(const char *const *list, uint32_t count, const char *name)
{
    for (uint32_t i = 0; list && i < count; i++)
        if (list[i] && strcmp(list[i], name) == 0) return true;
    return false;
}

/* Appends "what" to a comma-separated list in buf. */
static void add_missing(char *buf, size_t cap, const char *what)
{
    size_t len = strlen(buf);
    snprintf(buf + len, cap - len, "%s%s", len ? ", " : "", what);
}

/* The index of the application's physical device in its instance's list. */
static ob_result find_index(const ob_vulkan_handles *a, uint32_t *out_index)
{
    uint32_t count = 0;
    VkResult vr = OB_VK_CHECK(vkEnumeratePhysicalDevices(a->instance, &count, NULL));
    if (vr < 0) return ob_result_from_vk(vr);
    VkPhysicalDevice *pds = ob_calloc(count ? count : 1, sizeof *pds);
    if (!pds) return OB_ERR_OUT_OF_HOST_MEMORY;
    vr = OB_VK_CHECK(vkEnumeratePhysicalDevices(a->instance, &count, pds));
    ob_result r = vr < 0 ? ob_result_from_vk(vr) : OB_ERR_INVALID_ARGUMENT;
    for (uint32_t i = 0; vr >= 0 && i < count; i++) {
        if (pds[i] == a->physical) {
            *out_index = i;
            r = OB_OK;
        }
    }
    ob_free(pds);
    if (r == OB_ERR_INVALID_ARGUMENT)
        OB_LOG_E("device", "ob_vulkan_handles.physical is not one of the %u physical devices of "
                 "ob_vulkan_handles.instance", count);
    return r;
}

ob_result ob_device_check_adopted(const ob_vulkan_handles *a, ob_physical_choice *out_choice,
                                  ob_adopted_info *out_info)
{
    memset(out_choice, 0, sizeof *out_choice);
    memset(out_info, 0, sizeof *out_info);
    const char *null_field = !a->instance ? "instance"
                             : !a->physical ? "physical"
                             : !a->device   ? "device"
                             : !a->queue    ? "queue"
                                            : NULL;
    if (null_field) {
        OB_LOG_E("device", "ob_vulkan_handles.%s is null: an adopted device needs the instance, "
                 "physical device, device and queue", null_field);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (a->api_version < VK_API_VERSION_1_3) {
        OB_LOG_E("device", "the application's instance was created for Vulkan %u.%u "
                 "(ob_vulkan_handles.api_version); Obelisk needs 1.3",
                 VK_API_VERSION_MAJOR(a->api_version), VK_API_VERSION_MINOR(a->api_version));
        return OB_ERR_UNSUPPORTED;
    }
    enabled_features en;
    ob_result r = read_features(a->features, &en);
    if (r != OB_OK) return r;
    uint32_t index = 0;
    r = find_index(a, &index);
    if (r != OB_OK) return r;

    bool suitable;
    char reason[160];
    r = ob_device_probe_physical(a->physical, index, out_choice, &suitable, reason, sizeof reason);
    if (r != OB_OK) return r;
    if (!suitable) {
        OB_LOG_E("device", "the application's physical device '%s' cannot run Obelisk: it %s",
                 out_choice->props.deviceName, reason);
        return OB_ERR_UNSUPPORTED;
    }

    uint32_t qf_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(a->physical, &qf_count, NULL);
    VkQueueFamilyProperties *qf = ob_calloc(qf_count ? qf_count : 1, sizeof *qf);
    if (!qf) return OB_ERR_OUT_OF_HOST_MEMORY;
    vkGetPhysicalDeviceQueueFamilyProperties(a->physical, &qf_count, qf);
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    bool family_ok = a->queue_family < qf_count && (qf[a->queue_family].queueFlags & need) == need;
    uint32_t ts_bits = a->queue_family < qf_count ? qf[a->queue_family].timestampValidBits : 0;
    ob_free(qf);
    if (!family_ok) {
        OB_LOG_E("device", "the application's queue family %u (of %u) %s", a->queue_family, qf_count,
                 a->queue_family < qf_count ? "lacks graphics + compute" : "does not exist");
        return OB_ERR_UNSUPPORTED;
    }

    char missing[320] = "";
    if (!en.dynamic_rendering) add_missing(missing, sizeof missing, "feature dynamicRendering");
    if (!en.synchronization2) add_missing(missing, sizeof missing, "feature synchronization2");
    if (!en.maintenance4) add_missing(missing, sizeof missing, "feature maintenance4");
    if (!named(a->device_extensions, a->device_extension_count, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME))
        add_missing(missing, sizeof missing, "extension " VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    if (missing[0]) {
        OB_LOG_E("device", "the application's device on '%s' lacks what Obelisk needs: %s (enable "
                 "them in its vkCreateDevice and list them in ob_vulkan_handles)",
                 out_choice->props.deviceName, missing);
        return OB_ERR_UNSUPPORTED;
    }

    /* Usable = supported (the probe) and enabled (the application). */
    ob_device_caps *caps = &out_choice->caps;
    caps->timeline_semaphore &= en.timeline_semaphore;
    caps->host_query_reset &= en.host_query_reset;
    caps->sampler_anisotropy &= en.base.samplerAnisotropy == VK_TRUE;
    caps->fill_mode_non_solid &= en.base.fillModeNonSolid == VK_TRUE;
    caps->depth_clamp &= en.base.depthClamp == VK_TRUE;
    caps->depth_bias_clamp &= en.base.depthBiasClamp == VK_TRUE;
    caps->wide_lines &= en.base.wideLines == VK_TRUE;
    caps->independent_blend &= en.base.independentBlend == VK_TRUE;
    caps->multi_draw_indirect &= en.base.multiDrawIndirect == VK_TRUE;
    caps->draw_indirect_first_instance &= en.base.drawIndirectFirstInstance == VK_TRUE;
    caps->texture_compression_bc &= en.base.textureCompressionBC == VK_TRUE;
    caps->timestamp_valid_bits = ts_bits;
    out_choice->queue_family = a->queue_family;
    out_info->debug_utils =
        named(a->instance_extensions, a->instance_extension_count, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    out_info->swapchain =
        named(a->device_extensions, a->device_extension_count, VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    return OB_OK;
}
