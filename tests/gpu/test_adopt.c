/* test_adopt.c — the renderer on the application's own Vulkan objects
 * (ob_device_desc.adopt): the test creates the instance (with the
 * validation layer and a messenger of its own) and the device, renders
 * through an ob_stack on them — the same pixels and command hash as on the
 * engine's own device — destroys the stack, and the device is still the
 * test's: it waits idle, makes a fence, and is destroyed with the validation
 * layer silent (a Vulkan object the engine left behind would be reported as
 * a leak there). A device that lacks a feature or an extension the engine
 * needs, or an instance made for Vulkan 1.2, is refused with a message
 * naming what is missing, and stays usable. */
#include "ob_test.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_stack.h"
#include "ob_test_adopt.h"

#define W 64u
#define H 48u

typedef struct app_vulkan {
    VkInstance instance;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice physical;
    uint32_t family;
    VkDevice device;
    VkQueue queue;
    atomic_uint complaints;   /* validation errors and warnings the app's messenger saw */
    const char *instance_exts[2];
    const char *device_exts[1];
    uint32_t device_ext_count;
    VkPhysicalDeviceVulkan13Features f13;
    VkPhysicalDeviceFeatures2 f2;
    ob_vulkan_handles handles;
} app_vulkan;

static VKAPI_ATTR VkBool32 VKAPI_CALL app_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT types,
                                                  const VkDebugUtilsMessengerCallbackDataEXT *data,
                                                  void *user)
{
    (void)types;
    app_vulkan *app = user;
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)) {
        atomic_fetch_add(&app->complaints, 1);
        fprintf(stderr, "[app messenger] %s\n", data && data->pMessage ? data->pMessage : "?");
    }
    return VK_FALSE;
}

/* The application's instance: Vulkan 1.3, the validation layer with
 * synchronization validation, debug utils and its own messenger. */
static void app_instance(app_vulkan *app)
{
    memset(app, 0, sizeof *app);
    atomic_init(&app->complaints, 0);
    VkDebugUtilsMessengerCreateInfoEXT mi = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT,
        .pfnUserCallback = app_message,
        .pUserData = app,
    };
    app->instance = ob_test_vulkan_instance("test_adopt", &mi, app->instance_exts);
    PFN_vkCreateDebugUtilsMessengerEXT create = (PFN_vkCreateDebugUtilsMessengerEXT)
        vkGetInstanceProcAddr(app->instance, "vkCreateDebugUtilsMessengerEXT");
    assert_non_null(create);
    assert_int_equal(create(app->instance, &mi, NULL, &app->messenger), VK_SUCCESS);

    /* lavapipe where present (what every other test runs on), else the first 1.3 device. */
    VkPhysicalDevice pds[16];
    uint32_t n = 16;
    assert_true(vkEnumeratePhysicalDevices(app->instance, &n, pds) >= 0);
    assert_true(n > 0);
    for (uint32_t i = 0; i < n; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pds[i], &p);
        if (p.apiVersion < VK_API_VERSION_1_3) continue;
        if (!app->physical || p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) app->physical = pds[i];
    }
    assert_non_null(app->physical);
    VkQueueFamilyProperties qf[16];
    n = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(app->physical, &n, qf);
    app->family = UINT32_MAX;
    for (uint32_t i = n; i-- > 0;)
        if ((qf[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
            (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
            app->family = i;
    assert_true(app->family != UINT32_MAX);
}

/* The application's device with what the engine needs, less what a test
 * leaves out. */
static void app_device(app_vulkan *app, bool synchronization2, bool push_descriptor)
{
    float priority = 1.0f;
    VkDeviceQueueCreateInfo qi = {.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
                                  .queueFamilyIndex = app->family,
                                  .queueCount = 1,
                                  .pQueuePriorities = &priority};
    app->f13 = (VkPhysicalDeviceVulkan13Features){
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .dynamicRendering = VK_TRUE,
        .synchronization2 = synchronization2 ? VK_TRUE : VK_FALSE,
        .maintenance4 = VK_TRUE};
    app->f2 = (VkPhysicalDeviceFeatures2){.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
                                          .pNext = &app->f13};
    app->device_ext_count = 0;
    if (push_descriptor) app->device_exts[app->device_ext_count++] = VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME;
    VkDeviceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
                             .pNext = &app->f2,
                             .queueCreateInfoCount = 1,
                             .pQueueCreateInfos = &qi,
                             .enabledExtensionCount = app->device_ext_count,
                             .ppEnabledExtensionNames = app->device_exts};
    assert_int_equal(vkCreateDevice(app->physical, &ci, NULL, &app->device), VK_SUCCESS);
    vkGetDeviceQueue(app->device, app->family, 0, &app->queue);
    app->handles = (ob_vulkan_handles){
        .instance = app->instance,
        .physical = app->physical,
        .device = app->device,
        .queue_family = app->family,
        .queue = app->queue,
        .api_version = VK_API_VERSION_1_3,
        .instance_extensions = app->instance_exts,
        .instance_extension_count = 2,
        .device_extensions = app->device_exts,
        .device_extension_count = app->device_ext_count,
        .features = &app->f2,
    };
}

/* The device is still the application's after the engine let go: it waits
 * idle and makes an object; then it is destroyed, silently. */
static void app_device_destroy(app_vulkan *app)
{
    assert_int_equal(vkDeviceWaitIdle(app->device), VK_SUCCESS);
    VkFenceCreateInfo fi = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    assert_int_equal(vkCreateFence(app->device, &fi, NULL, &fence), VK_SUCCESS);
    vkDestroyFence(app->device, fence, NULL);
    vkDestroyDevice(app->device, NULL);
    app->device = VK_NULL_HANDLE;
    assert_int_equal(atomic_load(&app->complaints), 0);
}

static void app_instance_destroy(app_vulkan *app)
{
    PFN_vkDestroyDebugUtilsMessengerEXT destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)
        vkGetInstanceProcAddr(app->instance, "vkDestroyDebugUtilsMessengerEXT");
    assert_non_null(destroy);
    destroy(app->instance, app->messenger, NULL);
    vkDestroyInstance(app->instance, NULL);
    assert_int_equal(atomic_load(&app->complaints), 0);
}

/* A red box in front of the camera, two frames; the image and the last
 * frame's command hash. */
static void render_box(const ob_vulkan_handles *adopt, uint8_t *out_px, uint64_t *out_hash)
{
    ob_result r;
    ob_stack_desc d = {.renderer = {.device = {.app_name = "test_adopt", .validation = 1,
                                               .adopt = adopt},
                                    .worker_count = 2, .threading = OB_THREADING_MULTI},
                       .width = W, .height = H, .shadow_map_size = 64,
                       .clear_color = {0.0f, 0.0f, 1.0f, 1.0f}};
    ob_stack *s = ob_stack_create(&d, &r);
    assert_non_null(s);
    assert_int_equal(ob_device_is_adopted(s->device), adopt != NULL);
    if (adopt) {
        assert_ptr_equal(ob_device_vk(s->device), adopt->device);
        assert_ptr_equal(ob_device_vk_instance(s->device), adopt->instance);
        assert_ptr_equal(ob_device_vk_queue(s->device), adopt->queue);
        assert_true(ob_device_validation_enabled(s->device));
    }
    ob_mesh m = {0};
    assert_int_equal(ob_mesh_box((const float[3]){0.5f, 0.5f, 0.5f}, &m), OB_OK);
    ob_geometry *box = ob_stack_add_geometry(s, &m, "box", &r);
    ob_mesh_release(&m);
    assert_non_null(box);
    ob_material_desc md = {.name = "red", .kind = OB_MATERIAL_LIT, .diffuse = {1, 0, 0, 1},
                           .emissive = {1, 0, 0, 1}};
    ob_material *red = ob_material_create(s->materials, &md, &r);
    assert_non_null(red);
    assert_non_null(ob_stack_add_entity(s, NULL, "box", box, red, &r));
    ob_node_set_position(s->camera, (const double[3]){0.0, 0.0, 3.0});
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_stack_frame(s, 1.0 / 60.0), OB_OK);
    assert_int_equal(ob_renderer_wait_idle(s->renderer), OB_OK);
    *out_hash = ob_renderer_last_stats(s->renderer)->frame_hash;
    assert_int_equal(ob_image_read_rgba8(s->device, ob_stack_final_image(s), out_px), OB_OK);
    ob_test_assert_no_validation(s->device);
    ob_stack_destroy(s);
}

static void test_adopted_device_renders_and_survives(void **state)
{
    (void)state;
    ob_heap_stats before = ob_heap_stats_now();
    uint8_t *own = malloc((size_t)W * H * 4), *adopted = malloc((size_t)W * H * 4);
    assert_non_null(own);
    assert_non_null(adopted);
    uint64_t own_hash = 0, adopted_hash = 0;
    render_box(NULL, own, &own_hash);

    app_vulkan app;
    app_instance(&app);
    app_device(&app, true, true);
    render_box(&app.handles, adopted, &adopted_hash);
    app_device_destroy(&app);
    app_instance_destroy(&app);

    const uint8_t *centre = adopted + ((size_t)(H / 2) * W + W / 2) * 4;
    assert_true(centre[0] > 200 && centre[2] < 50);   /* the red box */
    assert_memory_equal(own, adopted, (size_t)W * H * 4);
    assert_true(own_hash != 0);
    assert_true(own_hash == adopted_hash);
    free(own);
    free(adopted);
    ob_heap_stats after = ob_heap_stats_now();
    assert_int_equal(after.live_blocks, before.live_blocks);
}

static void expect_refusal(const ob_vulkan_handles *h, ob_result want, const char *needle)
{
    ob_test_log_clear();
    ob_result r = OB_OK;
    ob_renderer_desc rd = {.device = {.validation = 1, .adopt = h}, .worker_count = 1};
    ob_renderer *ren = ob_renderer_create(&rd, &r);
    assert_null(ren);
    assert_int_equal(r, want);
    if (!ob_test_log_has(needle, NULL)) {
        ob_test_log_dump(OB_LOG_WARN, 20);
        fail_msg("no log line names '%s'", needle);
    }
}

static void test_missing_requirements_are_refused_by_name(void **state)
{
    (void)state;
    app_vulkan app;
    app_instance(&app);

    app_device(&app, false, true);
    expect_refusal(&app.handles, OB_ERR_UNSUPPORTED, "synchronization2");
    app_device_destroy(&app);

    app_device(&app, true, false);
    expect_refusal(&app.handles, OB_ERR_UNSUPPORTED, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    /* Both at once: one line names both. */
    app.handles.features = NULL;
    expect_refusal(&app.handles, OB_ERR_UNSUPPORTED, "dynamicRendering");
    assert_true(ob_test_log_has("synchronization2", VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, NULL));
    app_device_destroy(&app);

    app_device(&app, true, true);
    app.handles.api_version = VK_API_VERSION_1_2;
    expect_refusal(&app.handles, OB_ERR_UNSUPPORTED, "Vulkan 1.2");
    app.handles.api_version = VK_API_VERSION_1_3;
    app.handles.queue = VK_NULL_HANDLE;
    expect_refusal(&app.handles, OB_ERR_INVALID_ARGUMENT, "ob_vulkan_handles.queue");
    app_device_destroy(&app);
    app_instance_destroy(&app);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_adopted_device_renders_and_survives),
        cmocka_unit_test(test_missing_requirements_are_refused_by_name),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
