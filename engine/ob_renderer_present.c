/* ob_renderer_present.c — the renderer's swapchain: presenting a frame to
 * the application's surface in the frame's own submission.
 *
 * Per frame: begin_frame acquires an image (signalling the frame slot's
 * `acquired` semaphore); the primary ends with a blit of the present image
 * (the composite's target) into it and its transition to PRESENT_SRC; the
 * frame's one vkQueueSubmit2 waits for `acquired` and signals the image's
 * `ready` semaphore; end_frame queues the present, which waits for `ready`.
 *
 * Semaphores: `acquired` is per frame slot — the slot's fence, waited at
 * begin_frame, covers the submission that waited on it. `ready` is per
 * swapchain image — a present has no fence, and the image coming back from
 * vkAcquireNextImageKHR is what says its last present is done with it.
 *
 * The swapchain is rebuilt at begin_frame when the surface's size differs
 * from it, or when the last acquire or present said suboptimal or out of
 * date; the device is waited idle first, which is simple and costs nothing
 * outside a resize. A surface of size 0x0 (a minimised window) gets no
 * swapchain and no acquire: the frame is rendered and not presented.
 */
#include "ob_renderer_internal.h"

#include <stdio.h>
#include <string.h>

#define OB_PRESENT_MAX_IMAGES 8

struct ob_present {
    VkSurfaceKHR surface;          /* the application's */
    VkSurfaceFormatKHR format;
    VkPresentModeKHR mode;
    uint32_t hint_width, hint_height; /* for surfaces whose size is the swapchain's */

    VkSwapchainKHR swapchain;
    VkExtent2D extent;
    VkImage images[OB_PRESENT_MAX_IMAGES];
    uint32_t image_count;
    VkSemaphore ready[OB_PRESENT_MAX_IMAGES];      /* per image: rendered, may present */
    VkSemaphore acquired[OB_MAX_FRAMES_IN_FLIGHT]; /* per frame slot: image acquired */
    bool stale;                    /* suboptimal, out of date or resized: rebuild */
    bool broken;                   /* an acquired image's semaphore was never waited on */

    /* The frame being recorded. */
    bool have_image, sync_taken, submitted;
    uint32_t image_index, slot;
    ob_image source;
    bool warned_no_source;

    ob_present_stats stats;
};

/* ------------------------------------------------------------ swapchain */

static void destroy_ready(ob_renderer *r, ob_present *p)
{
    VkDevice vk = ob_device_vk(r->dev);
    for (uint32_t i = 0; i < OB_PRESENT_MAX_IMAGES; i++) {
        if (p->ready[i]) vkDestroySemaphore(vk, p->ready[i], NULL);
        p->ready[i] = VK_NULL_HANDLE;
    }
}

static void destroy_acquired(ob_renderer *r, ob_present *p)
{
    VkDevice vk = ob_device_vk(r->dev);
    for (uint32_t i = 0; i < OB_MAX_FRAMES_IN_FLIGHT; i++) {
        if (p->acquired[i]) vkDestroySemaphore(vk, p->acquired[i], NULL);
        p->acquired[i] = VK_NULL_HANDLE;
    }
}

static ob_result create_semaphores(ob_renderer *r, VkSemaphore *out, uint32_t count, const char *what)
{
    VkSemaphoreCreateInfo sci = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    for (uint32_t i = 0; i < count; i++) {
        VkResult vr = OB_VK_CHECK_CREATE(vkCreateSemaphore(ob_device_vk(r->dev), &sci, NULL, &out[i]));
        if (vr != VK_SUCCESS) {
            out[i] = VK_NULL_HANDLE;
            OB_LOG_E("present", "the '%s' semaphore %u of %u cannot be created", what, i, count);
            return ob_result_from_vk(vr);
        }
        char name[32];
        snprintf(name, sizeof name, "present.%s[%u]", what, i);
        ob_device_set_name(r->dev, VK_OBJECT_TYPE_SEMAPHORE, (uint64_t)(uintptr_t)out[i], name);
    }
    return OB_OK;
}

static void destroy_swapchain(ob_renderer *r, ob_present *p)
{
    destroy_ready(r, p);
    if (p->swapchain) vkDestroySwapchainKHR(ob_device_vk(r->dev), p->swapchain, NULL);
    p->swapchain = VK_NULL_HANDLE;
    p->image_count = 0;
    p->extent = (VkExtent2D){0, 0};
}

/* The size the swapchain should have now; 0x0 when the window is minimised. */
static VkExtent2D wanted_extent(const ob_present *p, const VkSurfaceCapabilitiesKHR *caps)
{
    if (caps->currentExtent.width != UINT32_MAX) return caps->currentExtent;
    /* The surface takes the swapchain's size (Wayland): the application's. */
    VkExtent2D e = {OB_MIN(OB_MAX(p->hint_width, caps->minImageExtent.width), caps->maxImageExtent.width),
                    OB_MIN(OB_MAX(p->hint_height, caps->minImageExtent.height), caps->maxImageExtent.height)};
    if (p->hint_width == 0 || p->hint_height == 0) e = (VkExtent2D){0, 0};
    return e;
}

/* A swapchain of `extent` replacing the old one. The device is idle (the
 * caller waited), so the old swapchain and its semaphores can go at once. */
static ob_result build_swapchain(ob_renderer *r, ob_present *p, const VkSurfaceCapabilitiesKHR *caps,
                                 VkExtent2D extent)
{
    VkDevice vk = ob_device_vk(r->dev);
    if (!(caps->supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        OB_LOG_E("present", "the surface's images cannot be written by a blit (no TRANSFER_DST usage)");
        return OB_ERR_UNSUPPORTED;
    }
    uint32_t count = caps->minImageCount + 1;
    if (caps->maxImageCount && count > caps->maxImageCount) count = caps->maxImageCount;
    if (count > OB_PRESENT_MAX_IMAGES) count = OB_PRESENT_MAX_IMAGES;
    VkSwapchainCreateInfoKHR ci = {
        .sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR,
        .surface = p->surface,
        .minImageCount = count,
        .imageFormat = p->format.format,
        .imageColorSpace = p->format.colorSpace,
        .imageExtent = extent,
        .imageArrayLayers = 1,
        .imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .preTransform = caps->currentTransform,
        .compositeAlpha = (caps->supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                              ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                              : VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR,
        .presentMode = p->mode,
        .clipped = VK_TRUE,
        .oldSwapchain = p->swapchain,
    };
    VkSwapchainKHR sc = VK_NULL_HANDLE;
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateSwapchainKHR(vk, &ci, NULL, &sc));
    destroy_swapchain(r, p);   /* retired either way */
    if (vr != VK_SUCCESS) {
        OB_LOG_E("present", "no swapchain of %ux%u: %s", extent.width, extent.height,
                 ob_vk_result_name(vr));
        return ob_result_from_vk(vr);
    }
    p->swapchain = sc;
    uint32_t n = 0;
    vr = OB_VK_CHECK(vkGetSwapchainImagesKHR(vk, sc, &n, NULL));
    if (vr == VK_SUCCESS && n > OB_PRESENT_MAX_IMAGES) {
        OB_LOG_E("present", "the swapchain has %u images; at most %u are handled", n,
                 OB_PRESENT_MAX_IMAGES);
        destroy_swapchain(r, p);
        return OB_ERR_LIMIT;
    }
    if (vr == VK_SUCCESS) vr = OB_VK_CHECK(vkGetSwapchainImagesKHR(vk, sc, &n, p->images));
    if (vr != VK_SUCCESS) {
        destroy_swapchain(r, p);
        return ob_result_from_vk(vr);
    }
    p->image_count = n;
    ob_result res = create_semaphores(r, p->ready, n, "ready");
    if (res != OB_OK) {
        destroy_swapchain(r, p);
        return res;
    }
    for (uint32_t i = 0; i < n; i++) {
        char name[32];
        snprintf(name, sizeof name, "swapchain[%u]", i);
        ob_device_set_name(r->dev, VK_OBJECT_TYPE_IMAGE, (uint64_t)(uintptr_t)p->images[i], name);
    }
    p->extent = extent;
    p->stale = false;
    p->stats.swapchains++;
    OB_LOG_I("present", "swapchain %u: %ux%u, %u images", p->stats.swapchains, extent.width,
             extent.height, n);
    return OB_OK;
}

/* Rebuilds what a resize or a lost acquire needs rebuilt, after waiting idle. */
static ob_result rebuild(ob_renderer *r, ob_present *p, const VkSurfaceCapabilitiesKHR *caps,
                         VkExtent2D extent)
{
    if (p->swapchain || p->broken) {
        ob_result res = ob_device_wait_idle(r->dev);
        if (res != OB_OK) return res;
    }
    if (p->broken) {
        /* A semaphore signalled by an acquire that no submission waited on
         * cannot be used again: replace them all. */
        destroy_acquired(r, p);
        ob_result res = create_semaphores(r, p->acquired, r->frames_in_flight, "acquired");
        if (res != OB_OK) return res;
        p->broken = false;
    }
    return build_swapchain(r, p, caps, extent);
}

/* ------------------------------------------------------------ attach */

static ob_result choose_format(ob_renderer *r, ob_present *p)
{
    VkPhysicalDevice phys = ob_device_vk_physical(r->dev);
    uint32_t n = 0;
    VkResult vr = OB_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(phys, p->surface, &n, NULL));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    VkSurfaceFormatKHR *formats = ob_calloc(n ? n : 1, sizeof *formats);
    if (!formats) return OB_ERR_OUT_OF_HOST_MEMORY;
    vr = OB_VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(phys, p->surface, &n, formats));
    if (vr < 0 || n == 0) {
        ob_free(formats);
        if (n == 0) OB_LOG_E("present", "the surface offers no image format");
        return vr < 0 ? ob_result_from_vk(vr) : OB_ERR_UNSUPPORTED;
    }
    /* sRGB, like the composite's target: a blit between two sRGB formats
     * decodes and encodes again, so the window shows the bytes the headless
     * image holds. Into a UNORM image the blit would write the decoded
     * (linear) values and the picture would come out too dark: that
     * fallback is said in the log. */
    p->format = formats[0];
    bool srgb = false;
    for (uint32_t i = n; i-- > 0;) {
        VkFormat f = formats[i].format;
        bool is_srgb = (f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_SRGB) &&
                       formats[i].colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
        if (is_srgb || (!srgb && (f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_R8G8B8A8_UNORM))) {
            p->format = formats[i];
            srgb = srgb || is_srgb;
        }
    }
    ob_free(formats);
    if (!srgb)
        OB_LOG_W("present", "the surface offers no B8G8R8A8/R8G8B8A8 sRGB format; format %d is used and "
                 "the window shows the sRGB image darker than the PNG output", (int)p->format.format);
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(phys, p->format.format, &fp);
    if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
        OB_LOG_E("present", "the surface's format %d cannot be blitted into", (int)p->format.format);
        return OB_ERR_UNSUPPORTED;
    }
    return OB_OK;
}

static ob_result choose_mode(ob_renderer *r, ob_present *p, bool no_vsync)
{
    p->mode = VK_PRESENT_MODE_FIFO_KHR;   /* always there */
    if (!no_vsync) return OB_OK;
    VkPhysicalDevice phys = ob_device_vk_physical(r->dev);
    VkPresentModeKHR modes[16];
    uint32_t n = OB_ARRAY_COUNT(modes);
    VkResult vr = OB_VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(phys, p->surface, &n, modes));
    if (vr < 0) return ob_result_from_vk(vr);
    for (uint32_t i = 0; i < n; i++)
        if (modes[i] == VK_PRESENT_MODE_IMMEDIATE_KHR) p->mode = modes[i];
    for (uint32_t i = 0; i < n; i++)
        if (modes[i] == VK_PRESENT_MODE_MAILBOX_KHR) p->mode = modes[i];
    return OB_OK;
}

ob_result ob_renderer_attach_surface(ob_renderer *r, const ob_surface_desc *desc)
{
    if (!desc || !desc->surface) {
        OB_LOG_E("present", "ob_renderer_attach_surface: no surface given");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (r->in_frame || r->present) {
        OB_LOG_E("present", "ob_renderer_attach_surface: %s",
                 r->in_frame ? "called inside a frame" : "a surface is already attached (detach it first)");
        return OB_ERR_WRONG_STATE;
    }
    if (!ob_device_has_swapchain(r->dev)) {
        OB_LOG_E("present", "the device was created without %s: set ob_device_desc.swapchain, or "
                 "enable it on the application's device", VK_KHR_SWAPCHAIN_EXTENSION_NAME);
        return OB_ERR_UNSUPPORTED;
    }
    VkBool32 can_present = VK_FALSE;
    VkResult vr = OB_VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(
        ob_device_vk_physical(r->dev), ob_device_queue_family(r->dev), desc->surface, &can_present));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    if (!can_present) {
        OB_LOG_E("present", "queue family %u of '%s' cannot present to this surface",
                 ob_device_queue_family(r->dev), ob_device_name(r->dev));
        return OB_ERR_UNSUPPORTED;
    }
    ob_present *p = ob_calloc(1, sizeof *p);
    if (!p) return OB_ERR_OUT_OF_HOST_MEMORY;
    p->surface = desc->surface;
    p->hint_width = desc->width;
    p->hint_height = desc->height;
    ob_result res = choose_format(r, p);
    if (res == OB_OK) res = choose_mode(r, p, desc->no_vsync);
    if (res == OB_OK) res = create_semaphores(r, p->acquired, r->frames_in_flight, "acquired");
    if (res != OB_OK) {
        destroy_acquired(r, p);
        ob_free(p);
        OB_LOG_E("present", "surface not attached: %s", ob_result_name(res));
        return res;
    }
    /* The swapchain itself comes with the first frame, at the size the
     * surface has then. */
    r->present = p;
    return OB_OK;
}

void ob_renderer_detach_surface(ob_renderer *r)
{
    ob_present *p = r ? r->present : NULL;
    if (!p) return;
    /* Submitted frames may still wait on the semaphores and write the images. */
    ob_device_wait_idle(r->dev);
    destroy_swapchain(r, p);
    destroy_acquired(r, p);
    ob_free(p);
    r->present = NULL;
}

void ob_renderer_surface_resized(ob_renderer *r, uint32_t width, uint32_t height)
{
    ob_present *p = r->present;
    if (!p) return;
    /* Only the size: begin_frame compares the size wanted (the surface's,
     * or this one where the surface has none) with the swapchain's, so a
     * resize the surface reported already is not rebuilt twice. */
    p->hint_width = width;
    p->hint_height = height;
}

void ob_renderer_present_image(ob_renderer *r, ob_image image)
{
    ob_present *p = r->present;
    if (!p || !r->in_frame) return;
    ob_image_info info = {0};
    if (ob_image_get_info(r->dev, image, &info) != OB_OK || !(info.usage & OB_IMAGE_TRANSFER_SRC)) {
        OB_LOG_E("present", "image 0x%08x cannot be presented (%s): the window shows black this "
                 "frame", image.id, info.usage ? "no OB_IMAGE_TRANSFER_SRC usage" : "not a live image");
        ob_renderer_note_error(r, "present", OB_ERR_INVALID_ARGUMENT);
        p->source = (ob_image){0};
        return;
    }
    p->source = image;
}

bool ob_renderer_present_extent(const ob_renderer *r, uint32_t *out_width, uint32_t *out_height)
{
    const ob_present *p = r->present;
    bool have = p && r->in_frame && p->have_image;
    *out_width = have ? p->extent.width : 0;
    *out_height = have ? p->extent.height : 0;
    return have;
}

ob_present_stats ob_renderer_present_stats(const ob_renderer *r)
{
    ob_present_stats s = {0};
    if (r->present) {
        s = r->present->stats;
        s.width = r->present->extent.width;
        s.height = r->present->extent.height;
    }
    return s;
}

/* ------------------------------------------------------------ per frame */

ob_result ob_renderer_present_acquire(ob_renderer *r)
{
    ob_present *p = r->present;
    if (!p) return OB_OK;
    p->have_image = p->sync_taken = p->submitted = false;
    p->source = (ob_image){0};
    p->slot = r->slot;
    VkPhysicalDevice phys = ob_device_vk_physical(r->dev);
    VkDevice vk = ob_device_vk(r->dev);
    for (int attempt = 0; attempt < 2; attempt++) {
        VkSurfaceCapabilitiesKHR caps;
        VkResult vr = OB_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(phys, p->surface, &caps));
        if (vr != VK_SUCCESS) {
            ob_device_note_result(r->dev, vr);
            return ob_result_from_vk(vr);
        }
        VkExtent2D want = wanted_extent(p, &caps);
        if (want.width == 0 || want.height == 0) return OB_OK;   /* minimised: not presented */
        if (!p->swapchain || p->stale || p->broken || want.width != p->extent.width ||
            want.height != p->extent.height) {
            ob_result res = rebuild(r, p, &caps, want);
            if (res != OB_OK) return res;
        }
        uint32_t index = 0;
        vr = vkAcquireNextImageKHR(vk, p->swapchain, UINT64_MAX, p->acquired[p->slot], VK_NULL_HANDLE,
                                   &index);
        if (vr == VK_ERROR_OUT_OF_DATE_KHR) {
            /* Resized between the size query and the acquire: once more. */
            OB_LOG_I("present", "vkAcquireNextImageKHR: the swapchain is out of date; rebuilding");
            p->stale = true;
            continue;
        }
        if (vr < 0) {
            OB_LOG_E("present", "frame %llu: vkAcquireNextImageKHR failed: %s",
                     (unsigned long long)r->serial, ob_vk_result_name(vr));
            ob_device_note_result(r->dev, vr);
            return ob_result_from_vk(vr);
        }
        if (vr == VK_SUBOPTIMAL_KHR) p->stale = true;   /* present this one, rebuild next frame */
        if (index >= p->image_count) {
            OB_LOG_E("present", "vkAcquireNextImageKHR returned image %u of %u", index, p->image_count);
            p->broken = true;
            return OB_ERR_VULKAN;
        }
        p->image_index = index;
        p->have_image = true;
        return OB_OK;
    }
    return OB_OK;   /* still out of date after a rebuild: this frame is not presented */
}

void ob_renderer_present_record(ob_renderer *r, VkCommandBuffer cmd)
{
    ob_present *p = r->present;
    if (!p || !p->have_image) return;
    VkImage dst = p->images[p->image_index];
    ob_image_info info = {0};
    bool blit = p->source.id && ob_image_get_info(r->dev, p->source, &info) == OB_OK;
    if (blit && !(info.usage & OB_IMAGE_TRANSFER_SRC)) {
        OB_LOG_E("present", "the present image 0x%08x lacks OB_IMAGE_TRANSFER_SRC usage: the window "
                 "shows black", p->source.id);
        blit = false;
    }
    if (!p->source.id && !p->warned_no_source) {
        OB_LOG_W("present", "frame %llu: nothing was given to present (a presenting composite view, "
                 "or ob_renderer_present_image): the window shows black", (unsigned long long)r->serial);
        p->warned_no_source = true;
    }
    VkImageMemoryBarrier2 barriers[2];
    uint32_t n = 0;
    if (blit) {
        ob_renderer_note_image_state(r, p->source);
        ob_image_state src = {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                              VK_ACCESS_2_TRANSFER_READ_BIT};
        if (ob_image_transition(r->dev, p->source, &src, &barriers[n])) n++;
    }
    const VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    /* From the acquire: the submission waits for it at ALL_TRANSFER, so the
     * layout change comes after the presentation engine let go of the image. */
    barriers[n++] = (VkImageMemoryBarrier2){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
        .dstStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
        .dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
        .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED,
        .newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = dst,
        .subresourceRange = range,
    };
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                            .imageMemoryBarrierCount = n,
                            .pImageMemoryBarriers = barriers};
    vkCmdPipelineBarrier2(cmd, &dep);
    if (blit) {
        bool same = info.width == p->extent.width && info.height == p->extent.height;
        VkImageBlit region = {
            .srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
            .srcOffsets = {{0, 0, 0}, {(int32_t)info.width, (int32_t)info.height, 1}},
            .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
            .dstOffsets = {{0, 0, 0}, {(int32_t)p->extent.width, (int32_t)p->extent.height, 1}},
        };
        vkCmdBlitImage(cmd, ob_image_vk(r->dev, p->source), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region,
                       same ? VK_FILTER_NEAREST : VK_FILTER_LINEAR);
    } else {
        const VkClearColorValue black = {{0.0f, 0.0f, 0.0f, 1.0f}};
        vkCmdClearColorImage(cmd, dst, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &black, 1, &range);
    }
    /* To the presentation engine: the submission's `ready` signal (at
     * ALL_COMMANDS) orders the present after the write. */
    VkImageMemoryBarrier2 to_present = barriers[n - 1];
    to_present.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
    to_present.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_present.dstStageMask = VK_PIPELINE_STAGE_2_NONE;
    to_present.dstAccessMask = VK_ACCESS_2_NONE;
    to_present.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_present.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &to_present;
    vkCmdPipelineBarrier2(cmd, &dep);
}

uint32_t ob_renderer_present_sync(ob_renderer *r, VkSemaphoreSubmitInfo *out_wait,
                                  VkSemaphoreSubmitInfo *out_signal)
{
    ob_present *p = r->present;
    if (!p || !p->have_image) return 0;
    p->sync_taken = true;
    *out_wait = (VkSemaphoreSubmitInfo){.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                                        .semaphore = p->acquired[p->slot],
                                        .stageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT};
    *out_signal = (VkSemaphoreSubmitInfo){.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                                          .semaphore = p->ready[p->image_index],
                                          .stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    return 1;
}

void ob_renderer_present_submitted(ob_renderer *r, bool submitted)
{
    if (r->present && r->present->sync_taken) r->present->submitted = submitted;
}

ob_result ob_renderer_present_queue(ob_renderer *r)
{
    ob_present *p = r->present;
    if (!p) return OB_OK;
    if (!p->have_image) {
        p->stats.skipped++;
        return OB_OK;
    }
    p->have_image = false;
    if (!p->submitted) {
        /* The frame was not submitted: its acquire semaphore stays signalled
         * and the image acquired. The next begin_frame replaces both. */
        p->broken = true;
        p->stats.skipped++;
        return OB_OK;
    }
    VkPresentInfoKHR pi = {
        .sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR,
        .waitSemaphoreCount = 1,
        .pWaitSemaphores = &p->ready[p->image_index],
        .swapchainCount = 1,
        .pSwapchains = &p->swapchain,
        .pImageIndices = &p->image_index,
    };
    VkResult vr = vkQueuePresentKHR(ob_device_vk_queue(r->dev), &pi);
    if (vr == VK_ERROR_OUT_OF_DATE_KHR) {
        /* The wait on `ready` still happens; the image is not shown. */
        OB_LOG_I("present", "vkQueuePresentKHR: the swapchain is out of date; rebuilt next frame");
        p->stale = true;
        p->stats.skipped++;
        return OB_OK;
    }
    if (vr < 0) {
        OB_LOG_E("present", "frame %llu: vkQueuePresentKHR failed: %s", (unsigned long long)r->serial,
                 ob_vk_result_name(vr));
        ob_device_note_result(r->dev, vr);
        p->stale = true;
        return ob_result_from_vk(vr);
    }
    if (vr == VK_SUBOPTIMAL_KHR) p->stale = true;
    p->stats.presented++;
    return OB_OK;
}
