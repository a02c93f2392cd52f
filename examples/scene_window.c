/* scene_window — a scene file (docs/scene-format.md) shown live in a window:
 * GLFW makes the window and its surface, Obelisk renders and presents
 * (ob_renderer_attach_surface), resizing follows the window.
 *
 *   scene_window SCENE.json [FRAMES]     (FRAMES: stop after so many; default: until closed)
 *
 * Needs a display (X11 or Wayland) and GLFW (Debian: libglfw3-dev).
 */
#include <obelisk/obelisk.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>

static void on_resize(GLFWwindow *win, int width, int height)
{
    ob_renderer_surface_resized(glfwGetWindowUserPointer(win), (uint32_t)width, (uint32_t)height);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: scene_window SCENE.json [FRAMES]\n");
        return 2;
    }
    long frames = argc > 2 ? strtol(argv[2], NULL, 10) : -1;
    ob_scene_file file = {0};
    ob_scene_file_error err;
    if (ob_scene_file_load(argv[1], &file, &err) != OB_OK) {   /* before any window or device */
        fprintf(stderr, "scene_window: %s\n", err.message);
        return 2;
    }
    ob_stack_desc desc = {.width = 960, .height = 540};
    ob_scene_load_stack_desc(&file.settings, &desc);           /* the file's size, colours, threads */
    if (!glfwInit() || !glfwVulkanSupported()) {
        fprintf(stderr, "scene_window: no display, or GLFW without Vulkan\n");
        ob_scene_file_release(&file);
        return 1;
    }
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    GLFWwindow *win = glfwCreateWindow((int)desc.width, (int)desc.height, argv[1], NULL, NULL);
    desc.renderer.device.instance_extensions = glfwGetRequiredInstanceExtensions(
        &desc.renderer.device.instance_extension_count);
    desc.renderer.device.swapchain = true;

    ob_result r = OB_ERR_UNSUPPORTED;
    ob_stack *s = win ? ob_stack_create(&desc, &r) : NULL;
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    ob_scene_loaded loaded = {0};
    if (s && glfwCreateWindowSurface(ob_device_vk_instance(s->device), win, NULL, &surface) != VK_SUCCESS)
        r = OB_ERR_UNSUPPORTED;
    if (surface) {
        int w, h;
        glfwGetFramebufferSize(win, &w, &h);
        ob_surface_desc sd = {.surface = surface, .width = (uint32_t)w, .height = (uint32_t)h};
        r = ob_renderer_attach_surface(s->renderer, &sd);
    }
    if (r == OB_OK) {
        glfwSetWindowUserPointer(win, s->renderer);
        glfwSetFramebufferSizeCallback(win, on_resize);
        ob_composite_view_set_presenting(s->composite, true);  /* its target follows the window */
        r = ob_scene_load_stack(s, &(ob_scene_load_desc){.file = &file}, &loaded, &err);
        if (r != OB_OK) fprintf(stderr, "scene_window: %s\n", err.message);
    }
    /* A model that does not load is logged and left out; the rest renders. */
    for (long i = 0; r == OB_OK && i != frames && !glfwWindowShouldClose(win); i++) {
        glfwPollEvents();
        r = ob_stack_frame(s, 1.0 / 60.0);
    }
    if (s) ob_renderer_wait_idle(s->renderer);
    ob_scene_unload(&loaded);
    if (s) ob_renderer_detach_surface(s->renderer);
    if (surface) vkDestroySurfaceKHR(ob_device_vk_instance(s->device), surface, NULL);
    ob_stack_destroy(s);
    if (win) glfwDestroyWindow(win);
    glfwTerminate();
    ob_scene_file_release(&file);
    if (r != OB_OK) fprintf(stderr, "scene_window: %s\n", ob_result_text(r));
    return r == OB_OK ? 0 : 1;
}
