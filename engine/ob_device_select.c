/* ob_device_select.c — probing physical devices and choosing one.
 *
 * Every device is probed against the requirements of ob_device.h; the
 * selector (desc.device or $OB_DEVICE) then narrows the suitable ones and the
 * preference order (discrete, integrated, virtual, CPU) breaks ties. When
 * nothing is left, one log line lists every device seen and why it was
 * rejected: "no device" is the first thing a user hits on a new machine.
 */
#include "ob_device_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef enum selector_kind {
    SELECT_AUTO,
    SELECT_CPU,
    SELECT_GPU,
    SELECT_INDEX,
} selector_kind;

typedef struct candidate {
    ob_physical_choice choice;
    bool suitable;
    char reason[160];   /* why it was rejected, when !suitable */
} candidate;

static const char *type_name(VkPhysicalDeviceType type)
{
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
    }
}

static int type_rank(VkPhysicalDeviceType type)
{
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
    }
}

static ob_result parse_selector(const char *selector, selector_kind *out_kind, uint32_t *out_index)
{
    *out_kind = SELECT_AUTO;
    *out_index = 0;
    if (!selector || !selector[0]) return OB_OK;
    if (strcmp(selector, "lavapipe") == 0 || strcmp(selector, "cpu") == 0) {
        *out_kind = SELECT_CPU;
        return OB_OK;
    }
    if (strcmp(selector, "gpu") == 0) {
        *out_kind = SELECT_GPU;
        return OB_OK;
    }
    char *end = NULL;
    unsigned long v = strtoul(selector, &end, 10);
    if (selector[0] >= '0' && selector[0] <= '9' && end && *end == '\0' && v < UINT32_MAX) {
        *out_kind = SELECT_INDEX;
        *out_index = (uint32_t)v;
        return OB_OK;
    }
    OB_LOG_E("device", "device selector '%s' is not \"lavapipe\", \"gpu\" or a decimal index", selector);
    return OB_ERR_INVALID_ARGUMENT;
}

static bool has_extension(const VkExtensionProperties *exts, uint32_t count, const char *name)
{
    for (uint32_t i = 0; i < count; i++)
        if (strcmp(exts[i].extensionName, name) == 0) return true;
    return false;
}

/* Fills c->choice and decides c->suitable. Only a host allocation failure is
 * an error; an unmet requirement is a rejection with a reason. */
static ob_result probe(VkPhysicalDevice pd, uint32_t index, candidate *c)
{
    memset(c, 0, sizeof *c);
    c->choice.physical = pd;
    c->choice.caps.device_index = index;

    VkPhysicalDeviceDriverProperties driver = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    vkGetPhysicalDeviceProperties(pd, &c->choice.props);
    c->choice.caps.device_type = c->choice.props.deviceType;
    uint32_t api = c->choice.props.apiVersion;
    if (VK_API_VERSION_MAJOR(api) < 1 || (VK_API_VERSION_MAJOR(api) == 1 && VK_API_VERSION_MINOR(api) < 3)) {
        snprintf(c->reason, sizeof c->reason, "supports Vulkan %u.%u, needs 1.3",
                 VK_API_VERSION_MAJOR(api), VK_API_VERSION_MINOR(api));
        return OB_OK;
    }
    /* Vulkan 1.2+ devices have the driver-properties query in core. */
    props2.pNext = &driver;
    vkGetPhysicalDeviceProperties2(pd, &props2);
    if (driver.driverInfo[0])
        snprintf(c->choice.driver_info, sizeof c->choice.driver_info, "%s", driver.driverInfo);
    else
        snprintf(c->choice.driver_info, sizeof c->choice.driver_info, "%s (driver version 0x%x)",
                 driver.driverName[0] ? driver.driverName : "unknown driver",
                 c->choice.props.driverVersion);

    VkPhysicalDeviceVulkan13Features f13 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceVulkan12Features f12 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES,
                                            .pNext = &f13};
    VkPhysicalDeviceFeatures2 f2 = {.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &f12};
    vkGetPhysicalDeviceFeatures2(pd, &f2);
    if (!f13.dynamicRendering || !f13.synchronization2) {
        snprintf(c->reason, sizeof c->reason, "lacks %s%s%s", f13.dynamicRendering ? "" : "dynamicRendering",
                 !f13.dynamicRendering && !f13.synchronization2 ? " and " : "",
                 f13.synchronization2 ? "" : "synchronization2");
        return OB_OK;
    }
    ob_device_caps *caps = &c->choice.caps;
    caps->timeline_semaphore = f12.timelineSemaphore;
    caps->host_query_reset = f12.hostQueryReset;
    caps->sampler_anisotropy = f2.features.samplerAnisotropy;
    caps->fill_mode_non_solid = f2.features.fillModeNonSolid;
    caps->depth_clamp = f2.features.depthClamp;
    caps->depth_bias_clamp = f2.features.depthBiasClamp;
    caps->wide_lines = f2.features.wideLines;
    caps->independent_blend = f2.features.independentBlend;
    caps->multi_draw_indirect = f2.features.multiDrawIndirect;
    caps->draw_indirect_first_instance = f2.features.drawIndirectFirstInstance;
    caps->texture_compression_bc = f2.features.textureCompressionBC;

    uint32_t ext_count = 0;
    VkResult vr = OB_VK_CHECK(vkEnumerateDeviceExtensionProperties(pd, NULL, &ext_count, NULL));
    if (vr < 0) {
        snprintf(c->reason, sizeof c->reason, "cannot list extensions (%s)", ob_vk_result_name(vr));
        return OB_OK;
    }
    VkExtensionProperties *exts = ob_calloc(ext_count, sizeof *exts);
    if (!exts) return OB_ERR_OUT_OF_HOST_MEMORY;
    vr = OB_VK_CHECK(vkEnumerateDeviceExtensionProperties(pd, NULL, &ext_count, exts));
    bool push = vr >= 0 && has_extension(exts, ext_count, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    ob_free(exts);
    if (!push) {
        snprintf(c->reason, sizeof c->reason, "lacks %s", VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
        return OB_OK;
    }

    uint32_t qf_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qf_count, NULL);
    VkQueueFamilyProperties *qf = ob_calloc(qf_count, sizeof *qf);
    if (!qf) return OB_ERR_OUT_OF_HOST_MEMORY;
    vkGetPhysicalDeviceQueueFamilyProperties(pd, &qf_count, qf);
    /* Graphics and compute families support transfer implicitly, whether or
     * not they report the bit. */
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    bool found = false;
    for (uint32_t i = 0; i < qf_count && !found; i++) {
        if ((qf[i].queueFlags & need) == need && qf[i].queueCount > 0) {
            c->choice.queue_family = i;
            caps->timestamp_valid_bits = qf[i].timestampValidBits;
            found = true;
        }
    }
    ob_free(qf);
    if (!found) {
        snprintf(c->reason, sizeof c->reason, "has no queue family with graphics + compute + transfer");
        return OB_OK;
    }
    c->suitable = true;
    return OB_OK;
}

ob_result ob_device_probe_physical(VkPhysicalDevice pd, uint32_t index, ob_physical_choice *out_choice,
                                   bool *out_suitable, char *reason, size_t reason_size)
{
    candidate c;
    ob_result r = probe(pd, index, &c);
    *out_choice = c.choice;
    *out_suitable = r == OB_OK && c.suitable;
    if (reason_size) snprintf(reason, reason_size, "%s", c.reason);
    return r;
}

static bool matches(const candidate *c, selector_kind kind, uint32_t want_index, uint32_t index)
{
    switch (kind) {
    case SELECT_CPU: return c->choice.props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    case SELECT_GPU: return c->choice.props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
    case SELECT_INDEX: return index == want_index;
    default: return true;
    }
}

/* Appends to a fixed buffer; the text is cut (never overrun) when it is full. */
static void append(char *buf, size_t cap, size_t *len, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void append(char *buf, size_t cap, size_t *len, const char *fmt, ...)
{
    if (*len + 1 >= cap) return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + *len, cap - *len, fmt, ap);
    va_end(ap);
    if (n > 0) *len = OB_MIN(cap - 1, *len + (size_t)n);
}

ob_result ob_device_select_physical(VkInstance instance, const char *selector,
                                    ob_physical_choice *out_choice)
{
    selector_kind kind;
    uint32_t want_index;
    ob_result r = parse_selector(selector, &kind, &want_index);
    if (r != OB_OK) return r;

    uint32_t count = 0;
    VkResult vr = OB_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, NULL));
    if (vr < 0) return vr == VK_ERROR_INITIALIZATION_FAILED ? OB_ERR_NO_DEVICE : ob_result_from_vk(vr);
    if (count == 0) {
        OB_LOG_E("device", "no Vulkan devices found: install a driver (mesa-vulkan-drivers "
                           "provides lavapipe, a CPU device)");
        return OB_ERR_NO_DEVICE;
    }
    VkPhysicalDevice *pds = ob_calloc(count, sizeof *pds);
    candidate *cands = ob_calloc(count, sizeof *cands);
    if (!pds || !cands) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    vr = OB_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, pds));
    if (vr < 0) {
        r = ob_result_from_vk(vr);
        goto done;
    }

    int best = -1;
    for (uint32_t i = 0; i < count; i++) {
        r = probe(pds[i], i, &cands[i]);
        if (r != OB_OK) goto done;
        if (!cands[i].suitable) continue;
        if (!matches(&cands[i], kind, want_index, i)) {
            cands[i].suitable = false;
            snprintf(cands[i].reason, sizeof cands[i].reason, "not selected by device '%s'", selector);
            continue;
        }
        if (best < 0 || type_rank(cands[i].choice.props.deviceType) >
                            type_rank(cands[best].choice.props.deviceType))
            best = (int)i;
    }
    if (best >= 0) {
        *out_choice = cands[best].choice;
        r = OB_OK;
        goto done;
    }

    char msg[960];
    size_t len = 0;
    append(msg, sizeof msg, &len, "no suitable Vulkan device (selector '%s'); %u seen:",
           selector && selector[0] ? selector : "auto", count);
    if (kind == SELECT_INDEX && want_index >= count)
        append(msg, sizeof msg, &len, " index %u is out of range;", want_index);
    for (uint32_t i = 0; i < count; i++) {
        append(msg, sizeof msg, &len, " #%u '%s' (%s): %s;", i, cands[i].choice.props.deviceName,
               type_name(cands[i].choice.props.deviceType),
               cands[i].reason[0] ? cands[i].reason : "not selected");
    }
    OB_LOG_E("device", "%s", msg);
    r = OB_ERR_NO_DEVICE;
done:
    ob_free(cands);
    ob_free(pds);
    return r;
}
