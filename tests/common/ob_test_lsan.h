/* ob_test_lsan.h — leak checking of the address-sanitizer build for tests
 * that render (compile pipelines on lavapipe). Include it in exactly one
 * file of a test executable (the one with main); it defines symbols.
 *
 * Two kinds of third-party memory would otherwise be reported as leaks:
 * - VK_LAYER_KHRONOS_validation 1.3.239 leaks the state of command buffers
 *   (shared_ptr cycles under synchronization validation, all "indirect",
 *   allocated by C++ operator new). Allocation stacks stop at operator new
 *   (the layer has no frame pointers); the slow unwinder that would reach
 *   the layer deadlocks in libgcc as soon as lavapipe's LLVM JIT registers
 *   a new pipeline's frames (_Unwind_Find_FDE holds its lock, mallocs, and
 *   ASan's malloc unwinds into it again). So leaks allocated through
 *   libstdc++ are suppressed: those are the C++ libraries' (layer, glslang,
 *   SPIRV-Cross, assimp, LLVM). Ours are C, allocate through ob_malloc and
 *   stay reported; a Vulkan object left behind is reported by the
 *   validation layer when the device is destroyed.
 * - lavapipe keeps allocations in its globals until the loader unloads it
 *   with the instance; once unmapped they look leaked. The driver and the
 *   layer are pinned (never unloaded), so that memory stays reachable.
 *
 * Outside the address-sanitizer build this header defines nothing.
 */
#ifndef OB_TEST_LSAN_H
#define OB_TEST_LSAN_H

#if defined(__SANITIZE_ADDRESS__)
#define OB_TEST_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OB_TEST_LSAN 1
#endif
#endif

#ifdef OB_TEST_LSAN
#include <dlfcn.h>

const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libstdc++.so\n"; }

__attribute__((constructor)) static void ob_test_lsan_pin_drivers(void)
{
    /* Never closed: RTLD_NODELETE keeps them mapped until exit by design.
     * Absent libraries (another driver in use) are simply not pinned. */
    (void)dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    (void)dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
}
#endif

#endif /* OB_TEST_LSAN_H */
