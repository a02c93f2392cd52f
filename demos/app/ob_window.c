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
    bool has_input;
    ob_input_handler input;
};

/* GLFW's key codes to ob_input's: letters and digits are ASCII in both. */
static int input_key(int key)
{
    if ((key >= GLFW_KEY_A && key <= GLFW_KEY_Z) || (key >= GLFW_KEY_0 && key <= GLFW_KEY_9)) return key;
    if (key >= GLFW_KEY_F1 && key <= GLFW_KEY_F12) return OB_KEY_F1 + (key - GLFW_KEY_F1);
    if (key == GLFW_KEY_ESCAPE) return OB_KEY_ESCAPE;
    return -1;
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)scancode;
    ob_window *w = glfwGetWindowUserPointer(win);
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(win, GLFW_TRUE);
    int k = input_key(key);
    if (w->has_input && k >= 0 && k != OB_KEY_ESCAPE)
        ob_input_deliver(&(ob_input_event){.kind = OB_INPUT_KEY, .key = k,
                                           .shift = (mods & GLFW_MOD_SHIFT) != 0},
                         &w->input);
    else if (key == GLFW_KEY_F1)
        w->toggle = true;
}

static void on_button(GLFWwindow *win, int button, int action, int mods)
{
    ob_window *w = glfwGetWindowUserPointer(win);
    if (!w->has_input || button > GLFW_MOUSE_BUTTON_MIDDLE || action == GLFW_REPEAT) return;
    /* GLFW numbers left, right, middle as ob_mouse_button does. */
    ob_input_deliver(&(ob_input_event){.kind = OB_INPUT_BUTTON, .button = (ob_mouse_button)button,
                                       .down = action == GLFW_PRESS,
                                       .shift = (mods & GLFW_MOD_SHIFT) != 0},
                     &w->input);
}

static void on_cursor(GLFWwindow *win, double x, double y)
{
    ob_window *w = glfwGetWindowUserPointer(win);
    if (w->has_input) ob_input_deliver(&(ob_input_event){.kind = OB_INPUT_CURSOR, .x = x, .y = y}, &w->input);
}

static void on_scroll(GLFWwindow *win, double dx, double dy)
{
    (void)dx;
    ob_window *w = glfwGetWindowUserPointer(win);
    if (w->has_input) ob_input_deliver(&(ob_input_event){.kind = OB_INPUT_SCROLL, .x = dy}, &w->input);
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
    glfwSetMouseButtonCallback(w->win, on_button);
    glfwSetCursorPosCallback(w->win, on_cursor);
    glfwSetScrollCallback(w->win, on_scroll);
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

void ob_window_set_input(ob_window *w, const ob_input_handler *h)
{
    w->has_input = h != NULL;
    if (h) w->input = *h;
}

void ob_window_size(ob_window *w, uint32_t *out_width, uint32_t *out_height)
{
    int width = 0, height = 0;
    glfwGetFramebufferSize(w->win, &width, &height);
    *out_width = (uint32_t)OB_MAX(width, 0);
    *out_height = (uint32_t)OB_MAX(height, 0);
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
void ob_window_set_input(ob_window *w, const ob_input_handler *h)
{
    (void)w;
    (void)h;
}
void ob_window_size(ob_window *w, uint32_t *out_width, uint32_t *out_height)
{
    (void)w;
    *out_width = *out_height = 0;
}
void ob_window_close(ob_window *w) { (void)w; }

#endif
