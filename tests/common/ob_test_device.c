#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"

#include <dlfcn.h>

/* Kept apart from ob_test.c so that unit tests, which never touch a device,
 * do not pull the device code into their link. */

ob_device *ob_test_device_create(void)
{
    ob_test_setup_log();
    ob_result r;
    ob_device_desc desc = {.app_name = "obelisk-test", .validation = 1};
    ob_device *dev = ob_device_create(&desc, &r);
    if (!dev) fail_msg("no Vulkan device with validation: %s (see the [device] log lines above)", ob_result_name(r));
    if (!ob_device_validation_enabled(dev)) fail_msg("device created without validation");
    return dev;
}

void ob_test_assert_no_validation(const ob_device *dev)
{
    ob_validation_counts c = ob_device_validation_counts(dev);
    if (c.errors || c.warnings)
        fail_msg("validation layer reported %u errors and %u warnings (see the [vk-validation] lines above)",
                 c.errors, c.warnings);
}

/* ---- AddressSanitizer builds --------------------------------------------
 * VK_LAYER_KHRONOS_validation 1.3.239 (Debian 12) leaks the state of every
 * command buffer when synchronization validation is on: shared_ptr cycles
 * inside the layer (KhronosGroup/Vulkan-ValidationLayers #5382, #6033; every
 * such leak is "indirect"). Those allocations are the layer's own, so they
 * are suppressed by module. The loader unloads the layer with each instance,
 * which would leave the leak stacks pointing at "<unknown module>": pinning
 * the layer in memory from start-up keeps them attributable, so only the
 * layer's leaks are suppressed and ours are still reported. The fast
 * unwinder stops at libstdc++'s operator new (no frame pointers), so
 * allocation stacks are taken with the slow unwinder, 10 frames deep: enough
 * to reach the layer's frame, about 5x slower than the fast one on
 * device-heavy tests (measured: 1.5 s → 7.7 s for test_device). Variables in
 * $ASAN_OPTIONS still override these defaults. */
#if defined(__SANITIZE_ADDRESS__)
#define OB_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OB_TEST_ASAN 1
#endif
#endif

#ifdef OB_TEST_ASAN
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "fast_unwind_on_malloc=0:malloc_context_size=10";
}

const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:libVkLayer_khronos_validation.so\n";
}

__attribute__((constructor)) static void pin_validation_layer(void)
{
    /* Never closed: RTLD_NODELETE keeps it mapped until exit by design. */
    (void)dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
}
#endif
