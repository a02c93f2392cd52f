#include "ob_window.h"

#ifdef OB_WITH_WINDOW

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <string.h>

#define MAX_IMAGES 8
#define SLOTS 2

struct ob_window {
    GLFWwindow *win;
    ob_device *dev;
    VkSurfaceKHR surface;
    VkSwapchainKHR swapchain;
    VkImage images[MAX_IMAGES];
    uint32_t image_count;
    VkExtent2D extent;
    VkSemaphore acquired[SLOTS], ready[MAX_IMAGES];
    VkFence fences[SLOTS];
    VkCommandPool pool;
    VkCommandBuffer cmds[SLOTS];
    uint32_t frame;
    uint32_t presented, skipped;
    bool toggle;
};

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)scancode;
    (void)mods;
    ob_window *w = glfwGetWindowUserPointer(win);
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_F1) w->toggle = true;
    if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(win, GLFW_TRUE);
}

ob_window *ob_window_open(uint32_t width, uint32_t height, const char *title,
                          const char *const **out_exts, uint32_t *out_ext_count)
{
    if (!glfwInit()) {
        OB_LOG_E("window", "GLFW could not start (no display? set DISPLAY or run headless)");
        return NULL;
    }
    if (!glfwVulkanSupported()) {
        OB_LOG_E("window", "GLFW found no Vulkan loader with surface support");
        glfwTerminate();
        return NULL;
    }
    ob_window *w = ob_calloc(1, sizeof *w);
    if (!w) {
        glfwTerminate();
        return NULL;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    w->win = glfwCreateWindow((int)width, (int)height, title, NULL, NULL);
    if (!w->win) {
        OB_LOG_E("window", "cannot create a %ux%u window", width, height);
        ob_free(w);
        glfwTerminate();
        return NULL;
    }
    glfwSetWindowUserPointer(w->win, w);
    glfwSetKeyCallback(w->win, on_key);
    *out_exts = glfwGetRequiredInstanceExtensions(out_ext_count);
    return w;
}

static ob_result create_swapchain(ob_window *w)
{
    VkPhysicalDevice phys = ob_device_vk_physical(w->dev);
    VkDevice vk = ob_device_vk(w->dev);
    VkSurfaceCapabilitiesKHR caps;
    if (OB_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(phys, w->surface, &caps)) != VK_SUCCESS)
        return OB_ERR_VULKAN;
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
        OB_LOG_E("window", "the surface's images cannot be blitted into (no TRANSFER_DST usage)");
        return OB_ERR_UNSUPPORTED;
    }
    VkSurfaceFormatKHR formats[32];
    uint32_t n = OB_ARRAY_COUNT(formats);
    vkGetPhysicalDeviceSurfaceFormatsKHR(phys, w->surface, &n, formats);
    if (n == 0) return OB_ERR_UNSUPPORTED;
    VkSurfaceFormatKHR chosen = formats[0];
    for (uint32_t i = 0; i < n; i++)
        if (formats[i].format == VK_FORMAT_B8G8R8A8_UNORM || formats[i].format == VK_FORMAT_R8G8B8A8_UNORM)
            chosen = formats[i];
    w->extent = caps.currentExtent.width != UINT32_MAX ? caps.currentExtent : caps.minImageExtent;
    uint32_t count = caps.minImageCount + 1;
    if (caps.maxImageCount && count > caps.maxImageCount) count = caps.maxImageCount;
    if (count > MAX_IMAGES) count = MAX_IMAGES;
    VkSwapchainCreateInfoKHR ci = {
        .sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR,
        .surface = w->surface,
        .minImageCount = count,
        .imageFormat = chosen.format,
        .imageColorSpace = chosen.colorSpace,
        .imageExtent = w->extent,
        .imageArrayLayers = 1,
        .imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT,
        .imageSharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .preTransform = caps.currentTransform,
        .compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR,
        .presentMode = VK_PRESENT_MODE_FIFO_KHR,
        .clipped = VK_TRUE,
    };
    if (OB_VK_CHECK(vkCreateSwapchainKHR(vk, &ci, NULL, &w->swapchain)) != VK_SUCCESS)
        return OB_ERR_VULKAN;
    w->image_count = MAX_IMAGES;
    vkGetSwapchainImagesKHR(vk, w->swapchain, &w->image_count, w->images);
    return OB_OK;
}

ob_result ob_window_attach(ob_window *w, ob_device *dev)
{
    w->dev = dev;
    VkDevice vk = ob_device_vk(dev);
    if (OB_VK_CHECK(glfwCreateWindowSurface(ob_device_vk_instance(dev), w->win, NULL, &w->surface)) !=
        VK_SUCCESS)
        return OB_ERR_VULKAN;
    VkBool32 can_present = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(ob_device_vk_physical(dev), ob_device_queue_family(dev),
                                         w->surface, &can_present);
    if (!can_present) {
        OB_LOG_E("window", "the device's queue cannot present to this window");
        return OB_ERR_UNSUPPORTED;
    }
    ob_result r = create_swapchain(w);
    if (r != OB_OK) return r;
    VkCommandPoolCreateInfo pci = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                   .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
                                   .queueFamilyIndex = ob_device_queue_family(dev)};
    if (OB_VK_CHECK(vkCreateCommandPool(vk, &pci, NULL, &w->pool)) != VK_SUCCESS) return OB_ERR_VULKAN;
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                      .commandPool = w->pool,
                                      .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                      .commandBufferCount = SLOTS};
    if (OB_VK_CHECK(vkAllocateCommandBuffers(vk, &ai, w->cmds)) != VK_SUCCESS) return OB_ERR_VULKAN;
    VkSemaphoreCreateInfo sci = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkFenceCreateInfo fci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO,
                             .flags = VK_FENCE_CREATE_SIGNALED_BIT};
    for (uint32_t i = 0; i < SLOTS; i++) {
        if (OB_VK_CHECK(vkCreateSemaphore(vk, &sci, NULL, &w->acquired[i])) != VK_SUCCESS ||
            OB_VK_CHECK(vkCreateFence(vk, &fci, NULL, &w->fences[i])) != VK_SUCCESS)
            return OB_ERR_VULKAN;
    }
    for (uint32_t i = 0; i < w->image_count; i++)
        if (OB_VK_CHECK(vkCreateSemaphore(vk, &sci, NULL, &w->ready[i])) != VK_SUCCESS)
            return OB_ERR_VULKAN;
    return OB_OK;
}

bool ob_window_poll(ob_window *w)
{
    glfwPollEvents();
    return !glfwWindowShouldClose(w->win);
}

bool ob_window_take_toggle(ob_window *w)
{
    bool t = w->toggle;
    w->toggle = false;
    return t;
}

ob_result ob_window_present(ob_window *w, ob_image image)
{
    VkDevice vk = ob_device_vk(w->dev);
    uint32_t slot = w->frame++ % SLOTS;
    vkWaitForFences(vk, 1, &w->fences[slot], VK_TRUE, UINT64_MAX);
    uint32_t index;
    VkResult vr = vkAcquireNextImageKHR(vk, w->swapchain, UINT64_MAX, w->acquired[slot],
                                        VK_NULL_HANDLE, &index);
    if (vr == VK_ERROR_OUT_OF_DATE_KHR) { /* not resizable: skip this frame */
        w->skipped++;
        return OB_OK;
    }
    if (vr < 0) return ob_result_from_vk(OB_VK_CHECK(vr));
    vkResetFences(vk, 1, &w->fences[slot]);
    VkCommandBuffer cmd = w->cmds[slot];
    vkResetCommandBuffer(cmd, 0);
    VkCommandBufferBeginInfo bi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
                                   .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT};
    vkBeginCommandBuffer(cmd, &bi);
    VkImageMemoryBarrier2 barriers[2];
    uint32_t n = 0;
    ob_image_state src = {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                          VK_ACCESS_2_TRANSFER_READ_BIT};
    if (ob_image_transition(w->dev, image, &src, &barriers[n])) n++;
    VkImageSubresourceRange range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    barriers[n++] = (VkImageMemoryBarrier2){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT,
        .dstStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT,
        .dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
        .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED,
        .newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = w->images[index],
        .subresourceRange = range,
    };
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                            .imageMemoryBarrierCount = n,
                            .pImageMemoryBarriers = barriers};
    vkCmdPipelineBarrier2(cmd, &dep);
    ob_image_info info;
    ob_image_get_info(w->dev, image, &info);
    VkImageBlit blit = {
        .srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .srcOffsets = {{0, 0, 0}, {(int32_t)info.width, (int32_t)info.height, 1}},
        .dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1},
        .dstOffsets = {{0, 0, 0}, {(int32_t)w->extent.width, (int32_t)w->extent.height, 1}},
    };
    vkCmdBlitImage(cmd, ob_image_vk(w->dev, image), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                   w->images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
    VkImageMemoryBarrier2 to_present = barriers[n - 1];
    to_present.srcStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT;
    to_present.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_present.dstStageMask = VK_PIPELINE_STAGE_2_NONE;
    to_present.dstAccessMask = 0;
    to_present.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_present.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &to_present;
    vkCmdPipelineBarrier2(cmd, &dep);
    vkEndCommandBuffer(cmd);

    VkSemaphoreSubmitInfo wait = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                                  .semaphore = w->acquired[slot],
                                  .stageMask = VK_PIPELINE_STAGE_2_BLIT_BIT};
    VkSemaphoreSubmitInfo signal = {.sType = VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO,
                                    .semaphore = w->ready[index],
                                    .stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT};
    VkCommandBufferSubmitInfo cbi = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO,
                                     .commandBuffer = cmd};
    VkSubmitInfo2 si = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2,
                        .waitSemaphoreInfoCount = 1, .pWaitSemaphoreInfos = &wait,
                        .commandBufferInfoCount = 1, .pCommandBufferInfos = &cbi,
                        .signalSemaphoreInfoCount = 1, .pSignalSemaphoreInfos = &signal};
    vr = OB_VK_CHECK(vkQueueSubmit2(ob_device_vk_queue(w->dev), 1, &si, w->fences[slot]));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    VkPresentInfoKHR pi = {.sType = VK_STRUCTURE_TYPE_PRESENT_INFO_KHR,
                           .waitSemaphoreCount = 1, .pWaitSemaphores = &w->ready[index],
                           .swapchainCount = 1, .pSwapchains = &w->swapchain,
                           .pImageIndices = &index};
    vr = vkQueuePresentKHR(ob_device_vk_queue(w->dev), &pi);
    if (vr == VK_ERROR_OUT_OF_DATE_KHR) {
        w->skipped++;
        return OB_OK;
    }
    if (vr < 0) return ob_result_from_vk(OB_VK_CHECK(vr));
    w->presented++;
    return OB_OK;
}

uint32_t ob_window_presented(const ob_window *w, uint32_t *out_skipped)
{
    *out_skipped = w->skipped;
    return w->presented;
}

void ob_window_close(ob_window *w)
{
    if (!w) return;
    if (w->dev) {
        VkDevice vk = ob_device_vk(w->dev);
        vkDeviceWaitIdle(vk);
        for (uint32_t i = 0; i < SLOTS; i++) {
            if (w->acquired[i]) vkDestroySemaphore(vk, w->acquired[i], NULL);
            if (w->fences[i]) vkDestroyFence(vk, w->fences[i], NULL);
        }
        for (uint32_t i = 0; i < w->image_count; i++)
            if (w->ready[i]) vkDestroySemaphore(vk, w->ready[i], NULL);
        if (w->pool) vkDestroyCommandPool(vk, w->pool, NULL);
        if (w->swapchain) vkDestroySwapchainKHR(vk, w->swapchain, NULL);
        if (w->surface) vkDestroySurfaceKHR(ob_device_vk_instance(w->dev), w->surface, NULL);
    }
    glfwDestroyWindow(w->win);
    glfwTerminate();
    ob_free(w);
}

#else /* !OB_WITH_WINDOW */

/* Headless builds keep the API so demos link; opening a window says how to
 * get one. */
ob_window *ob_window_open(uint32_t width, uint32_t height, const char *title,
                          const char *const **out_exts, uint32_t *out_ext_count)
{
    (void)width;
    (void)height;
    (void)title;
    *out_exts = NULL;
    *out_ext_count = 0;
    OB_LOG_E("window", "this build has no window support: configure with -DOB_WITH_WINDOW=ON "
                       "(needs libglfw3-dev)");
    return NULL;
}
ob_result ob_window_attach(ob_window *w, ob_device *dev)
{
    (void)w;
    (void)dev;
    return OB_ERR_UNSUPPORTED;
}
bool ob_window_poll(ob_window *w)
{
    (void)w;
    return false;
}
bool ob_window_take_toggle(ob_window *w)
{
    (void)w;
    return false;
}
ob_result ob_window_present(ob_window *w, ob_image image)
{
    (void)w;
    (void)image;
    return OB_ERR_UNSUPPORTED;
}
uint32_t ob_window_presented(const ob_window *w, uint32_t *out_skipped)
{
    (void)w;
    *out_skipped = 0;
    return 0;
}
void ob_window_close(ob_window *w) { (void)w; }

#endif
