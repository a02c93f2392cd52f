/* ob_sanitizer_support.c — compiled into every executable of an address- or
 * thread-sanitizer build (tests and demos; see CMakeLists.txt), nowhere else.
 *
 * Both: the loader unloads the Vulkan driver and layer with each instance.
 * Keeping them mapped keeps leak reports attributable (address) and keeps
 * ThreadSanitizer's called_from_lib suppressions valid (thread: it aborts when
 * a library it suppresses by name is unloaded); see tests/tsan.supp.
 *
 * Address:
 * VK_LAYER_KHRONOS_validation 1.3.239 (Debian 12) leaks the state of every
 * command buffer when synchronization validation is on: shared_ptr cycles
 * inside the layer (KhronosGroup/Vulkan-ValidationLayers #5382, #6033; each
 * such leak is "indirect"). Its allocations come through libstdc++'s
 * operator new, where LeakSanitizer's fast unwinder stops (no frame
 * pointers), so they can only be told apart by that frame. The slow unwinder
 * would reach the layer's frames, but it deadlocks inside libgcc's unwinder
 * when lavapipe's threads allocate at the same time (seen here: two threads
 * in _Unwind_Find_FDE), so it is not an option.
 *
 * So leaks whose allocation stack runs through libstdc++ are suppressed:
 * those of the validation layer, and equally any of glslang, spirv-cross or
 * assimp (C++ libraries). Every allocation of Obelisk itself is C through
 * ob_malloc and keeps its full stack, so our leaks are still reported
 * (checked by removing an ob_free: the leak is reported with its stack).
 * Variables in $ASAN_OPTIONS / $LSAN_OPTIONS still override these. */
#define _POSIX_C_SOURCE 200809L

#include <dlfcn.h>

#if defined(__SANITIZE_ADDRESS__)
#define OB_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define OB_ASAN 1
#endif
#endif

/* RTLD_NODELETE: never closed, by design. */
__attribute__((constructor)) static void pin_vulkan_modules(void)
{
    (void)dlopen("libVkLayer_khronos_validation.so", RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    (void)dlopen("libvulkan_lvp.so", RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
}

#ifdef OB_ASAN
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:libstdc++.so\n"
           "leak:libVkLayer_khronos_validation.so\n";
}
#endif
