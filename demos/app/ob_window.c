#include "ob_window.h"

#ifdef OB_WITH_WINDOW

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

struct ob_window {
    GLFWwindow *win;
    ob_renderer *r;           /* the surface's renderer, once attached */
    VkInstance instance;
    VkSurfaceKHR surface;
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

/* Pixels, not screen coordinates; 0x0 while minimised. */
static void on_framebuffer_size(GLFWwindow *win, int width, int height)
{
    ob_window *w = glfwGetWindowUserPointer(win);
    if (w->r) ob_renderer_surface_resized(w->r, (uint32_t)OB_MAX(width, 0), (uint32_t)OB_MAX(height, 0));
}

ob_window *ob_window_open(uint32_t width, uint32_t height, const char *title,
                          const char *const **out_exts, uint32_t *out_ext_count)
{
    *out_exts = NULL;
    *out_ext_count = 0;
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
    glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
    w->win = glfwCreateWindow((int)width, (int)height, title, NULL, NULL);
    if (!w->win) {
        OB_LOG_E("window", "cannot create a %ux%u window", width, height);
        ob_free(w);
        glfwTerminate();
        return NULL;
    }
    glfwSetWindowUserPointer(w->win, w);
    glfwSetKeyCallback(w->win, on_key);
    glfwSetFramebufferSizeCallback(w->win, on_framebuffer_size);
    *out_exts = glfwGetRequiredInstanceExtensions(out_ext_count);
    return w;
}

ob_result ob_window_attach(ob_window *w, ob_renderer *r)
{
    VkInstance instance = ob_device_vk_instance(ob_renderer_device(r));
    VkResult vr = OB_VK_CHECK_CREATE(glfwCreateWindowSurface(instance, w->win, NULL, &w->surface));
    if (vr != VK_SUCCESS) {
        w->surface = VK_NULL_HANDLE;
        return ob_result_from_vk(vr);
    }
    w->instance = instance;
    int width = 0, height = 0;
    glfwGetFramebufferSize(w->win, &width, &height);
    ob_surface_desc sd = {.surface = w->surface,
                          .width = (uint32_t)OB_MAX(width, 0),
                          .height = (uint32_t)OB_MAX(height, 0)};
    ob_result res = ob_renderer_attach_surface(r, &sd);
    if (res != OB_OK) {
        vkDestroySurfaceKHR(instance, w->surface, NULL);
        w->surface = VK_NULL_HANDLE;
        return res;
    }
    w->r = r;
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

void ob_window_request_size(ob_window *w, uint32_t width, uint32_t height)
{
    glfwSetWindowSize(w->win, (int)width, (int)height);
}

void ob_window_close(ob_window *w)
{
    if (!w) return;
    if (w->r) ob_renderer_detach_surface(w->r);
    if (w->surface) vkDestroySurfaceKHR(w->instance, w->surface, NULL);
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
ob_result ob_window_attach(ob_window *w, ob_renderer *r)
{
    (void)w;
    (void)r;
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
void ob_window_request_size(ob_window *w, uint32_t width, uint32_t height)
{
    (void)w;
    (void)width;
    (void)height;
}
void ob_window_close(ob_window *w) { (void)w; }

#endif
