/* Device creation, selection, validation capture, OB_VK_CHECK, deferred
 * deletion, device loss and fault injection on every creation point. */
#define _GNU_SOURCE /* dl_iterate_phdr */
#include "ob_test.h"
#include "ob_resources.h"

#include <dlfcn.h>
#include <link.h>

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static ob_device *create_with(const char *selector, int validation, ob_result *out_result)
{
    ob_device_desc desc = {.app_name = "test_device", .device = selector, .validation = validation};
    return ob_device_create(&desc, out_result);
}

static void device_reports_name_driver_and_timestamps(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    assert_true(ob_device_validation_enabled(dev));
    assert_true(strlen(ob_device_name(dev)) > 0);
    assert_true(strlen(ob_device_driver_info(dev)) > 0);
    assert_true(ob_device_timestamp_period_ns(dev) > 0.0);
    assert_non_null(ob_device_push_descriptor_fn(dev));
    assert_non_null(ob_device_vk_queue(dev));
    assert_int_equal(ob_device_frames_in_flight(dev), 2);
    assert_int_equal(ob_device_properties(dev)->apiVersion >= VK_API_VERSION_1_3, 1);
    assert_false(ob_device_is_lost(dev));
    /* The chosen family must really do graphics and compute. */
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(ob_device_vk_physical(dev), &n, NULL);
    assert_true(ob_device_queue_family(dev) < n);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
}

/* Whether the loader lists a CPU device (lavapipe), asked of Vulkan directly
 * so that the answer does not depend on the selection under test. */
static bool loader_lists_a_cpu_device(void)
{
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .apiVersion = VK_API_VERSION_1_3};
    VkInstanceCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO, .pApplicationInfo = &app};
    VkInstance inst = VK_NULL_HANDLE;
    if (vkCreateInstance(&ci, NULL, &inst) != VK_SUCCESS) return false;
    VkPhysicalDevice devices[16];
    uint32_t n = 16;
    bool found = false;
    VkResult res = vkEnumeratePhysicalDevices(inst, &n, devices);
    for (uint32_t i = 0; (res == VK_SUCCESS || res == VK_INCOMPLETE) && i < n; i++) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(devices[i], &p);
        if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) found = true;
    }
    vkDestroyInstance(inst, NULL);
    return found;
}

static void env_lavapipe_selects_the_cpu_device(void **state)
{
    (void)state;
    ob_test_setup_log();
    if (!loader_lists_a_cpu_device()) {
        /* A GPU machine without mesa-vulkan-drivers: nothing to select. */
        fprintf(stderr, "[  SKIPPED ] no CPU Vulkan device (lavapipe) is installed\n");
        skip();
    }
    setenv("OB_DEVICE", "lavapipe", 1);
    ob_result r;
    ob_device *dev = create_with(NULL, 1, &r);
    unsetenv("OB_DEVICE");
    assert_int_equal(r, OB_OK);
    assert_non_null(dev);
    assert_true(ob_device_is_cpu(dev));
    assert_int_equal(ob_device_get_caps(dev)->device_type, VK_PHYSICAL_DEVICE_TYPE_CPU);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);

    /* An explicit index picks exactly that device. */
    dev = create_with("0", 1, &r);
    assert_non_null(dev);
    assert_int_equal(ob_device_get_caps(dev)->device_index, 0);
    ob_device_destroy(dev);
}

static void gpu_selector_never_returns_the_cpu_device(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_test_log_clear();
    ob_result r;
    ob_device *dev = create_with("gpu", 1, &r);
    if (dev) {
        assert_false(ob_device_is_cpu(dev));
        ob_device_destroy(dev);
    } else {
        /* Only lavapipe here: the refusal says why. */
        assert_int_equal(r, OB_ERR_NO_DEVICE);
        assert_true(ob_test_log_has("no suitable Vulkan device", "'gpu'", "not selected", NULL));
    }
}

static void unknown_index_fails_with_a_list_of_devices(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_test_log_clear();
    ob_result r = OB_OK;
    ob_device *dev = create_with("99", 1, &r);
    assert_null(dev);
    assert_int_equal(r, OB_ERR_NO_DEVICE);
    assert_true(ob_test_log_has("no suitable Vulkan device", "'99'", "#0", "out of range", NULL));

    r = OB_OK;
    dev = create_with("banana", 1, &r);
    assert_null(dev);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'banana'", "lavapipe", NULL));
}

static void vk_check_logs_call_text_and_result_name(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_test_log_clear();
    uint32_t n = 0;
    VkResult vr = OB_VK_CHECK(vkEnumerateInstanceExtensionProperties("VK_LAYER_OBELISK_not_there", &n, NULL));
    assert_int_equal(vr, VK_ERROR_LAYER_NOT_PRESENT);
    assert_true(ob_test_log_has("[vk]", "vkEnumerateInstanceExtensionProperties(\"VK_LAYER_OBELISK_not_there\"",
                                "VK_ERROR_LAYER_NOT_PRESENT", "test_device.c", NULL));

    /* Success and positive statuses log nothing and pass through. */
    ob_test_log_clear();
    assert_int_equal(OB_VK_CHECK(VK_SUCCESS), VK_SUCCESS);
    assert_int_equal(OB_VK_CHECK(VK_INCOMPLETE), VK_INCOMPLETE);
    assert_int_equal(ob_test_log_count(OB_LOG_DEBUG), 0);

    assert_string_equal(ob_vk_result_name(VK_ERROR_DEVICE_LOST), "VK_ERROR_DEVICE_LOST");
    assert_string_equal(ob_vk_result_name(VK_ERROR_OUT_OF_POOL_MEMORY), "VK_ERROR_OUT_OF_POOL_MEMORY");
    assert_string_equal(ob_vk_result_name(VK_PIPELINE_COMPILE_REQUIRED), "VK_PIPELINE_COMPILE_REQUIRED");
    assert_string_equal(ob_vk_result_name((VkResult)-424242), "VK_RESULT_UNKNOWN");

    assert_int_equal(ob_result_from_vk(VK_SUCCESS), OB_OK);
    assert_int_equal(ob_result_from_vk(VK_TIMEOUT), OB_OK);
    assert_int_equal(ob_result_from_vk(VK_ERROR_OUT_OF_HOST_MEMORY), OB_ERR_OUT_OF_HOST_MEMORY);
    assert_int_equal(ob_result_from_vk(VK_ERROR_OUT_OF_DEVICE_MEMORY), OB_ERR_OUT_OF_DEVICE_MEMORY);
    assert_int_equal(ob_result_from_vk(VK_ERROR_DEVICE_LOST), OB_ERR_DEVICE_LOST);
    assert_int_equal(ob_result_from_vk(VK_ERROR_FORMAT_NOT_SUPPORTED), OB_ERR_UNSUPPORTED);
    assert_int_equal(ob_result_from_vk(VK_ERROR_UNKNOWN), OB_ERR_VULKAN);
}

static void validation_messages_are_captured_and_counted(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_test_log_clear();
    /* A device of its own: it is made dirty on purpose and then thrown away. */
    ob_device *dev = ob_test_device_create();
    assert_int_equal(ob_device_validation_counts(dev).errors, 0);
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = 0,   /* VUID-VkBufferCreateInfo-size-00912 */
        .usage = VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
    };
    VkBuffer buf = VK_NULL_HANDLE;
    vkCreateBuffer(ob_device_vk(dev), &info, NULL, &buf);
    if (buf) vkDestroyBuffer(ob_device_vk(dev), buf, NULL);
    assert_true(ob_device_validation_counts(dev).errors >= 1);
    assert_true(ob_test_log_has("[vk-validation]", "VUID-VkBufferCreateInfo-size", NULL));

    /* Synchronization validation is on: two unordered writes are a hazard. */
    uint32_t errors = ob_device_validation_counts(dev).errors;
    ob_result r;
    ob_buffer target = ob_buffer_create(dev, &(ob_buffer_desc){.size = 64, .usage = OB_BUFFER_STORAGE, .name = "hazard"}, &r);
    assert_int_equal(r, OB_OK);
    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
    vkCmdFillBuffer(cmd, ob_buffer_vk(dev, target), 0, VK_WHOLE_SIZE, 1);
    vkCmdFillBuffer(cmd, ob_buffer_vk(dev, target), 0, VK_WHOLE_SIZE, 2);
    assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);
    assert_true(ob_device_validation_counts(dev).errors > errors);
    assert_true(ob_test_log_has("[vk-validation]", "SYNC-HAZARD-WRITE", "hazard", NULL));
    ob_buffer_destroy(dev, target);
    ob_device_destroy(dev);
}

static void missing_validation_layer_refuses_to_run_unchecked(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_test_log_clear();
    /* The loader hides the layer as if it were not installed. */
    setenv("VK_LOADER_LAYERS_DISABLE", "VK_LAYER_KHRONOS_validation", 1);
    ob_result r = OB_OK;
    ob_device *dev = create_with(NULL, 1, &r);
    if (dev) {
        /* A loader older than 1.3.234 ignores the variable: nothing to test. */
        unsetenv("VK_LOADER_LAYERS_DISABLE");
        ob_device_destroy(dev);
        skip();
    }
    ob_device *unchecked = create_with(NULL, -1, NULL);   /* without validation it works */
    unsetenv("VK_LOADER_LAYERS_DISABLE");
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    assert_true(ob_test_log_has("VK_LAYER_KHRONOS_validation", "not installed", NULL));
    assert_non_null(unchecked);
    assert_false(ob_device_validation_enabled(unchecked));
    ob_device_destroy(unchecked);
}

static void count_calls(ob_device *dev, void *payload)
{
    (void)dev;
    (*(int *)payload)++;
}

typedef struct order_log {
    int seen[8];
    int count;
} order_log;

static int order_tags[3] = {1, 2, 3};
static order_log order;

static void note_order(ob_device *dev, void *payload)
{
    (void)dev;
    if (order.count < 8) order.seen[order.count++] = *(int *)payload;
}

static void deferred_deletion_waits_for_its_slot(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_result r;
    ob_device_desc desc = {.app_name = "test_device", .validation = 1, .frames_in_flight = 3};
    ob_device *dev = ob_device_create(&desc, &r);
    assert_non_null(dev);
    assert_int_equal(ob_device_frames_in_flight(dev), 3);

    int calls = 0;
    ob_device_begin_frame_slot(dev, 0);
    ob_device_defer(dev, count_calls, &calls);
    assert_int_equal(ob_device_current_slot(dev), 0);
    ob_device_begin_frame_slot(dev, 1);
    assert_int_equal(calls, 0);
    ob_device_begin_frame_slot(dev, 2);
    assert_int_equal(calls, 0);
    ob_device_begin_frame_slot(dev, 0);   /* slot 0 came round: its work is done */
    assert_int_equal(calls, 1);
    ob_device_begin_frame_slot(dev, 1);
    ob_device_begin_frame_slot(dev, 2);
    ob_device_begin_frame_slot(dev, 0);
    assert_int_equal(calls, 1);            /* ran once, not again */

    /* FIFO within a slot. */
    order.count = 0;
    for (int i = 0; i < 3; i++) ob_device_defer(dev, note_order, &order_tags[i]);
    ob_device_begin_frame_slot(dev, 1);
    ob_device_begin_frame_slot(dev, 0);
    assert_int_equal(order.count, 3);
    assert_int_equal(order.seen[0], 1);
    assert_int_equal(order.seen[1], 2);
    assert_int_equal(order.seen[2], 3);

    /* Out-of-range slots are refused, not run. */
    ob_test_log_clear();
    ob_device_begin_frame_slot(dev, 7);
    assert_int_equal(ob_device_current_slot(dev), 0);
    assert_true(ob_test_log_has("frame slot 7 out of range", NULL));

    /* Whatever is still queued runs at destroy. */
    ob_device_begin_frame_slot(dev, 2);
    ob_device_defer(dev, count_calls, &calls);
    ob_device_begin_frame_slot(dev, 1);
    ob_device_defer(dev, count_calls, &calls);
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);
    assert_int_equal(calls, 3);

    /* A queue that cannot grow: wait idle and run the deletion at once. */
    dev = ob_device_create(&desc, &r);
    assert_non_null(dev);
    calls = 0;
    ob_test_log_clear();
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 1);
    ob_device_defer(dev, count_calls, &calls);
    bool hit = ob_fault_hit(OB_FAULT_HOST_ALLOC);
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_true(hit);
    assert_int_equal(calls, 1);
    assert_true(ob_test_log_has("cannot grow", NULL));
    ob_device_destroy(dev);
    assert_int_equal(calls, 1);
}

static void device_loss_latches_and_refuses_work(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_test_log_clear();
    ob_device_note_result(dev, VK_SUCCESS);
    ob_device_note_result(dev, VK_ERROR_OUT_OF_DEVICE_MEMORY);
    assert_false(ob_device_is_lost(dev));
    ob_device_note_result(dev, VK_ERROR_DEVICE_LOST);
    assert_true(ob_device_is_lost(dev));
    assert_true(ob_test_log_has("lost", NULL));
    ob_device_note_result(dev, VK_SUCCESS);
    assert_true(ob_device_is_lost(dev));   /* latched */

    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_ERR_DEVICE_LOST);
    assert_null(cmd);
    ob_result r;
    ob_buffer buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 16, .usage = OB_BUFFER_VERTEX, .name = "after-loss"}, &r);
    assert_int_equal(buf.id, 0);
    assert_int_equal(r, OB_ERR_DEVICE_LOST);
    ob_device_destroy(dev);   /* still destroyable */
}

/* Walks every failure point of device creation: each must give a clean
 * error and free everything made so far (the ASan build checks the leaks). */
static void walk_creation_faults(ob_fault_kind kind, int validation)
{
    ob_result r;
    ob_fault_arm(kind, 0);
    ob_device *dev = create_with(NULL, validation, &r);
    uint64_t points = ob_fault_count(kind);
    assert_non_null(dev);
    ob_device_destroy(dev);
    assert_true(points >= 1);
    for (uint64_t n = 1; n <= points; n++) {
        ob_test_log_clear();
        ob_fault_arm(kind, n);
        r = OB_OK;
        dev = create_with(NULL, validation, &r);
        bool hit = ob_fault_hit(kind);
        ob_fault_arm(kind, 0);
        assert_true(hit);
        if (dev) fail_msg("creation succeeded with fault %d armed at point %llu", (int)kind, (unsigned long long)n);
        assert_int_not_equal(r, OB_OK);
        assert_true(ob_test_log_has("device creation failed", NULL));
    }
}

static void every_vulkan_creation_point_fails_cleanly(void **state)
{
    (void)state;
    ob_test_setup_log();
    ob_fault_arm(OB_FAULT_VK_OBJECT, 0);
    ob_device *dev = create_with(NULL, 1, NULL);
    uint64_t points = ob_fault_count(OB_FAULT_VK_OBJECT);
    ob_device_destroy(dev);
    /* instance, messenger, device, one-shot pool, one-shot fence */
    assert_int_equal(points, 5);
    walk_creation_faults(OB_FAULT_VK_OBJECT, 1);
    walk_creation_faults(OB_FAULT_VK_OBJECT, -1);
}

static void every_host_allocation_of_creation_fails_cleanly(void **state)
{
    (void)state;
    ob_test_setup_log();
    walk_creation_faults(OB_FAULT_HOST_ALLOC, 1);
}

/* The shared objects loaded while a device exists (the driver among them)
 * stay loaded after the last device is destroyed: unloading and reloading
 * NVIDIA's driver exhausts glibc's static TLS after about a dozen instances
 * (ob_device_pin.c), so a program that makes renderers in turn must not
 * cycle it. */
typedef struct loaded_list {
    char names[512][256];
    int count;
} loaded_list;

static int note_loaded(struct dl_phdr_info *info, size_t size, void *data)
{
    (void)size;
    loaded_list *l = data;
    if (info->dlpi_name && info->dlpi_name[0] && l->count < 512)
        snprintf(l->names[l->count++], sizeof l->names[0], "%s", info->dlpi_name);
    return 0;
}

static void driver_stays_loaded_after_the_last_device(void **state)
{
    (void)state;
    static loaded_list during;
    during.count = 0;
    ob_device *dev = ob_test_device_create();
    assert_non_null(dev);
    dl_iterate_phdr(note_loaded, &during);
    ob_device_destroy(dev);
    assert_true(during.count > 0);
    int gone = 0;
    for (int i = 0; i < during.count; i++) {
        void *h = dlopen(during.names[i], RTLD_LAZY | RTLD_NOLOAD);
        if (h) {
            dlclose(h);
        } else {
            print_message("unloaded with the last device: %s\n", during.names[i]);
            gone++;
        }
    }
    assert_int_equal(gone, 0);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(device_reports_name_driver_and_timestamps),
        cmocka_unit_test(driver_stays_loaded_after_the_last_device),
        cmocka_unit_test(env_lavapipe_selects_the_cpu_device),
        cmocka_unit_test(gpu_selector_never_returns_the_cpu_device),
        cmocka_unit_test(unknown_index_fails_with_a_list_of_devices),
        cmocka_unit_test(vk_check_logs_call_text_and_result_name),
        cmocka_unit_test(validation_messages_are_captured_and_counted),
        cmocka_unit_test(missing_validation_layer_refuses_to_run_unchecked),
        cmocka_unit_test(deferred_deletion_waits_for_its_slot),
        cmocka_unit_test(device_loss_latches_and_refuses_work),
        cmocka_unit_test(every_vulkan_creation_point_fails_cleanly),
        cmocka_unit_test(every_host_allocation_of_creation_fails_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
