/* ob_vk_result.c — VkResult names, OB_VK_CHECK and the VkResult → ob_result map. */
#include "ob_device.h"

/* Every VkResult of the core 1.3 API plus the extension results of the
 * headers we build against: a log line must never say "unknown" for a
 * result a driver can really return. */
#define OB_VK_RESULT_LIST(X)                                   \
    X(VK_SUCCESS)                                              \
    X(VK_NOT_READY)                                            \
    X(VK_TIMEOUT)                                              \
    X(VK_EVENT_SET)                                            \
    X(VK_EVENT_RESET)                                          \
    X(VK_INCOMPLETE)                                           \
    X(VK_ERROR_OUT_OF_HOST_MEMORY)                             \
    X(VK_ERROR_OUT_OF_DEVICE_MEMORY)                           \
    X(VK_ERROR_INITIALIZATION_FAILED)                          \
    X(VK_ERROR_DEVICE_LOST)                                    \
    X(VK_ERROR_MEMORY_MAP_FAILED)                              \
    X(VK_ERROR_LAYER_NOT_PRESENT)                              \
    X(VK_ERROR_EXTENSION_NOT_PRESENT)                          \
    X(VK_ERROR_FEATURE_NOT_PRESENT)                            \
    X(VK_ERROR_INCOMPATIBLE_DRIVER)                            \
    X(VK_ERROR_TOO_MANY_OBJECTS)                               \
    X(VK_ERROR_FORMAT_NOT_SUPPORTED)                           \
    X(VK_ERROR_FRAGMENTED_POOL)                                \
    X(VK_ERROR_UNKNOWN)                                        \
    X(VK_ERROR_OUT_OF_POOL_MEMORY)                             \
    X(VK_ERROR_INVALID_EXTERNAL_HANDLE)                        \
    X(VK_ERROR_FRAGMENTATION)                                  \
    X(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)                 \
    X(VK_PIPELINE_COMPILE_REQUIRED)                            \
    X(VK_ERROR_SURFACE_LOST_KHR)                               \
    X(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)                       \
    X(VK_SUBOPTIMAL_KHR)                                       \
    X(VK_ERROR_OUT_OF_DATE_KHR)                                \
    X(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)                       \
    X(VK_ERROR_VALIDATION_FAILED_EXT)                          \
    X(VK_ERROR_INVALID_SHADER_NV)                              \
    X(VK_ERROR_IMAGE_USAGE_NOT_SUPPORTED_KHR)                  \
    X(VK_ERROR_VIDEO_PICTURE_LAYOUT_NOT_SUPPORTED_KHR)         \
    X(VK_ERROR_VIDEO_PROFILE_OPERATION_NOT_SUPPORTED_KHR)      \
    X(VK_ERROR_VIDEO_PROFILE_FORMAT_NOT_SUPPORTED_KHR)         \
    X(VK_ERROR_VIDEO_PROFILE_CODEC_NOT_SUPPORTED_KHR)          \
    X(VK_ERROR_VIDEO_STD_VERSION_NOT_SUPPORTED_KHR)            \
    X(VK_ERROR_INVALID_DRM_FORMAT_MODIFIER_PLANE_LAYOUT_EXT)   \
    X(VK_ERROR_NOT_PERMITTED_KHR)                              \
    X(VK_ERROR_FULL_SCREEN_EXCLUSIVE_MODE_LOST_EXT)            \
    X(VK_THREAD_IDLE_KHR)                                      \
    X(VK_THREAD_DONE_KHR)                                      \
    X(VK_OPERATION_DEFERRED_KHR)                               \
    X(VK_OPERATION_NOT_DEFERRED_KHR)                           \
    X(VK_ERROR_COMPRESSION_EXHAUSTED_EXT)

const char *ob_vk_result_name(VkResult res)
{
    switch (res) {
#define OB_VK_RESULT_CASE(name) case name: return #name;
        OB_VK_RESULT_LIST(OB_VK_RESULT_CASE)
#undef OB_VK_RESULT_CASE
    default: return "VK_RESULT_UNKNOWN";
    }
}

VkResult ob_vk_check(VkResult res, const char *call_text, const char *file, int line)
{
    /* Positive results (VK_INCOMPLETE, VK_TIMEOUT, VK_SUBOPTIMAL_KHR) are
     * statuses the caller handles, not failures. */
    if (res < 0) {
        ob_log_write(OB_LOG_ERROR, "vk", file, line, "%s failed: %s (%d)",
                     call_text ? call_text : "(unknown call)", ob_vk_result_name(res), (int)res);
    }
    return res;
}

VkResult ob_vk_wait_result(VkResult res)
{
    return ob_fault_should_fail(OB_FAULT_DEVICE_LOST) ? VK_ERROR_DEVICE_LOST : res;
}

ob_result ob_result_from_vk(VkResult res)
{
    if (res >= 0) return OB_OK;
    switch (res) {
    case VK_ERROR_OUT_OF_HOST_MEMORY:
        return OB_ERR_OUT_OF_HOST_MEMORY;
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
    case VK_ERROR_OUT_OF_POOL_MEMORY:
    case VK_ERROR_FRAGMENTED_POOL:
    case VK_ERROR_FRAGMENTATION:
    case VK_ERROR_MEMORY_MAP_FAILED:
        return OB_ERR_OUT_OF_DEVICE_MEMORY;
    case VK_ERROR_DEVICE_LOST:
        return OB_ERR_DEVICE_LOST;
    case VK_ERROR_LAYER_NOT_PRESENT:
    case VK_ERROR_EXTENSION_NOT_PRESENT:
    case VK_ERROR_FEATURE_NOT_PRESENT:
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
    case VK_ERROR_IMAGE_USAGE_NOT_SUPPORTED_KHR:
        return OB_ERR_UNSUPPORTED;
    case VK_ERROR_INCOMPATIBLE_DRIVER:
        return OB_ERR_NO_DEVICE;
    case VK_ERROR_TOO_MANY_OBJECTS:
        return OB_ERR_LIMIT;
    default:
        return OB_ERR_VULKAN;
    }
}
