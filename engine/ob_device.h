/* ob_device.h — the Vulkan instance, physical device, logical device and queue.
 *
 * Lifecycle: ob_device_create → (frames) → ob_device_destroy. The renderer
 * creates one device and exposes it through ob_renderer_device(); tests and
 * tools may create a device alone.
 *
 * Device choice: a real GPU (discrete, then integrated) is preferred; lavapipe
 * (VK_PHYSICAL_DEVICE_TYPE_CPU) is the fallback. OB_DEVICE=lavapipe|gpu|<index>
 * overrides, as does ob_device_desc.device. Requirements: Vulkan 1.3 with
 * dynamicRendering and synchronization2, one queue family with graphics +
 * compute + transfer, VK_KHR_push_descriptor.
 *
 * Validation: with OB_VALIDATION=1 (or desc.validation > 0) the instance
 * enables VK_LAYER_KHRONOS_validation with synchronization validation. Every
 * message goes into the engine log (module "vk-validation": errors at ERROR,
 * warnings and performance warnings at WARN, info and verbose at DEBUG but
 * only when OB_LOG=debug, as the loader alone sends ~90 per device) and is
 * counted; tests read the counts through ob_device_validation_counts(). If
 * validation is requested but the layer is not installed, creation fails with
 * OB_ERR_UNSUPPORTED rather than running unchecked.
 *
 * Thread rule: creation and destruction [render thread]. The accessors are
 * [any thread]. The queue is owned by the render thread (submission), and so
 * are the frame slots, ob_device_defer and the one-shot command buffers.
 * The validation callback may run on any thread that makes a Vulkan call; its
 * counters are atomics, as are the device-lost latch and ob_device_note_result.
 */
#ifndef OB_DEVICE_H
#define OB_DEVICE_H

#include "ob_core.h"

#include <stdatomic.h>
#include <vulkan/vulkan.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Always runs `call`; on failure logs file, line, the call text and the
 * VkResult name (module "vk") and evaluates to the VkResult. Never returns
 * from the caller by itself. */
#define OB_VK_CHECK(call) ob_vk_check((call), #call, __FILE__, __LINE__)
VkResult ob_vk_check(VkResult res, const char *call_text, const char *file, int line);
const char *ob_vk_result_name(VkResult res);
/* Wrap every vkCreate* / vkAllocate* call of the engine in OB_VK_CREATE so the
 * fault-injection tests can fail the Nth one (it then yields
 * VK_ERROR_OUT_OF_DEVICE_MEMORY without making the call). */
#define OB_VK_CREATE(call) \
    (ob_fault_should_fail(OB_FAULT_VK_OBJECT) ? VK_ERROR_OUT_OF_DEVICE_MEMORY : (call))
/* OB_VK_CHECK for a result obtained earlier (a helper's return value, a
 * result that needs a look first): logs `call_name`, the Vulkan command that
 * produced it, never the variable's name. */
#define OB_VK_CHECK_AS(res, call_name) ob_vk_check((res), (call_name), __FILE__, __LINE__)
/* OB_VK_CHECK(OB_VK_CREATE(call)) that logs the call text without the wrapper. */
#define OB_VK_CHECK_CREATE(call) ob_vk_check(OB_VK_CREATE(call), #call, __FILE__, __LINE__)
/* Wrap every vkQueueSubmit* in OB_VK_SUBMIT: a test can make the Nth
 * submission report VK_ERROR_DEVICE_LOST (OB_FAULT_DEVICE_LOST) or
 * VK_ERROR_OUT_OF_DEVICE_MEMORY (OB_FAULT_SUBMIT_OOM) without submitting. */
#define OB_VK_SUBMIT(call)                                                              \
    (ob_fault_should_fail(OB_FAULT_DEVICE_LOST)  ? VK_ERROR_DEVICE_LOST                 \
     : ob_fault_should_fail(OB_FAULT_SUBMIT_OOM) ? VK_ERROR_OUT_OF_DEVICE_MEMORY        \
                                                 : (call))
/* Wrap every vkWaitForFences / vkDeviceWaitIdle of a frame in OB_VK_WAIT: the
 * wait always happens (so nothing is left running), then a test can make
 * the Nth wait report VK_ERROR_DEVICE_LOST (OB_FAULT_DEVICE_LOST). */
#define OB_VK_WAIT(call) ob_vk_wait_result(call)
VkResult ob_vk_wait_result(VkResult res);
/* Maps a VkResult to an ob_result (OUT_OF_DEVICE_MEMORY, DEVICE_LOST, ...).
 * Non-negative results (VK_SUCCESS, VK_INCOMPLETE, VK_TIMEOUT, ...) map to OB_OK. */
ob_result ob_result_from_vk(VkResult res);

typedef struct ob_device ob_device;

/* Vulkan objects the application already owns, for ob_device_desc.adopt
 * (programs that already use Vulkan). The engine creates its own objects on
 * them and destroys only those: none of these handles is destroyed, and the
 * application destroys them after ob_device_destroy / ob_renderer_destroy.
 * Requirements, checked at creation (a missing one fails it with
 * OB_ERR_UNSUPPORTED and a log line naming it): an instance created for
 * Vulkan 1.3 (api_version), a 1.3 physical device, a queue family with
 * graphics + compute, VK_KHR_push_descriptor enabled on the device, and
 * dynamicRendering, synchronization2 and maintenance4 enabled (in a
 * VkPhysicalDeviceVulkan13Features, or their own feature structs, in the
 * `features` chain). VK_KHR_swapchain must be enabled to present
 * (ob_renderer_attach_surface). Optional features (timeline semaphores,
 * anisotropy, wireframe, ...) count as available only where the chain
 * enabled them. The engine submits to `queue` from the render thread: the
 * application must not use the queue at the same time (Vulkan's external
 * synchronization rule). The strings and the chain are read during
 * creation only. */
typedef struct ob_vulkan_handles {
    VkInstance instance;
    VkPhysicalDevice physical;
    VkDevice device;
    uint32_t queue_family;
    VkQueue queue;                        /* a queue of queue_family */
    uint32_t api_version;                 /* VkApplicationInfo.apiVersion of the instance */
    /* What the instance enabled: with VK_EXT_debug_utils (and the
     * validation layer) the engine names its objects and captures
     * validation messages with a messenger of its own. */
    const char *const *instance_extensions;
    uint32_t instance_extension_count;
    const char *const *device_extensions; /* what vkCreateDevice enabled */
    uint32_t device_extension_count;
    /* The VkPhysicalDeviceFeatures2 chain given to vkCreateDevice (its
     * pNext); NULL means no features were enabled, which fails the check. */
    const VkPhysicalDeviceFeatures2 *features;
} ob_vulkan_handles;

/* The most frame slots a device (and so a renderer) has: ob_device_create
 * refuses more (OB_ERR_INVALID_ARGUMENT, logged); ob_renderer_create clamps
 * ob_renderer_desc.device.frames_in_flight to it. */
#define OB_MAX_FRAMES_IN_FLIGHT 4u

typedef struct ob_device_desc {
    const char *app_name;     /* NULL → "obelisk" */
    const char *device;       /* NULL → $OB_DEVICE → auto ("lavapipe", "gpu" or an index) */
    int validation;           /* 0 → $OB_VALIDATION; >0 on; <0 off */
    uint32_t frames_in_flight;/* 0 → 2; the number of frame slots for deferred deletion
                               * (at most OB_MAX_FRAMES_IN_FLIGHT) */
    /* Presentation (windowed demos): extra instance extensions (e.g. what
     * glfwGetRequiredInstanceExtensions returns; the strings must outlive
     * creation) and VK_KHR_swapchain on the device. Missing ones fail
     * creation with OB_ERR_UNSUPPORTED naming the extension. */
    const char *const *instance_extensions;
    uint32_t instance_extension_count;
    bool swapchain;
    /* Non-NULL: use the application's instance, device and queue instead of
     * creating them (app_name, device, instance_extensions and swapchain are
     * then ignored; validation only captures messages, see
     * ob_vulkan_handles). */
    const ob_vulkan_handles *adopt;
    /* The folder of the library's shaders for everything built on this
     * device: every effect context made on it (ob_effect_context_create,
     * and so ob_stack, the material library and the standard views) compiles
     * from here. Copied. NULL → $OB_SHADER_DIR → share/obelisk/shaders
     * beside the binary holding the engine (ob_shader_compiler_desc). For a
     * program that keeps its own copy of the shaders, or a static program
     * outside the install prefix. */
    const char *shader_dir;
    /* On a CPU device (lavapipe), keep the C library's freed heap memory
     * mapped instead of handing it back to the kernel: 0 → $OB_DRIVER_HEAP
     * ("keep", the default, or "system"); > 0 keep; < 0 leave the C
     * library's settings alone. llvmpipe allocates its bins (every
     * triangle it draws, tens of MB a frame) from the heap and frees them
     * after each render pass; glibc gives that memory back at once and the
     * next pass faults it in again, page by page: a third of lavapipe's
     * frame at 8 views x 10k objects (docs/benchmark.md, session 11).
     * Keeping it sets glibc's M_TRIM_THRESHOLD to OB_DRIVER_HEAP_KEEP_BYTES
     * for the whole process, once, and for good (it also stops glibc
     * from raising its mmap threshold by itself). No effect on a GPU,
     * with another C library, or under a sanitizer's allocator. */
    int driver_heap;
} ob_device_desc;

/* What a kept driver heap may hold unused before glibc trims it. */
#define OB_DRIVER_HEAP_KEEP_BYTES (256u << 20)

typedef struct ob_validation_counts {
    uint32_t errors;
    uint32_t warnings;   /* warnings + performance warnings */
    uint32_t infos;
} ob_validation_counts;

/* Creates the device, or adopts the application's (desc.adopt). On failure
 * returns NULL, sets *out_result (OB_ERR_NO_DEVICE when no device meets the
 * requirements, OB_ERR_UNSUPPORTED when an adopted device lacks one) and
 * logs why. */
ob_device *ob_device_create(const ob_device_desc *desc, ob_result *out_result);
/* Waits idle, runs every deferred deletion, destroys what the engine
 * created (an adopted instance and device are left alive). NULL is a no-op. */
void ob_device_destroy(ob_device *dev);
/* True when the instance and device are the application's (desc.adopt). */
bool ob_device_is_adopted(const ob_device *dev);
/* Whether VK_KHR_swapchain is enabled on the device (desc.swapchain, or in
 * the adopted device's extensions). */
bool ob_device_has_swapchain(const ob_device *dev);

VkInstance ob_device_vk_instance(const ob_device *dev);
VkPhysicalDevice ob_device_vk_physical(const ob_device *dev);
VkDevice ob_device_vk(const ob_device *dev);
VkQueue ob_device_vk_queue(const ob_device *dev);
uint32_t ob_device_queue_family(const ob_device *dev);
const VkPhysicalDeviceProperties *ob_device_properties(const ob_device *dev);
/* "llvmpipe (LLVM 15.0.6, 256 bits)" and "Mesa 22.3.6 (LLVM 15.0.6)". */
const char *ob_device_name(const ob_device *dev);
const char *ob_device_driver_info(const ob_device *dev);
/* desc.shader_dir as given (a copy owned by the device), NULL when none was. */
const char *ob_device_shader_dir(const ob_device *dev);
bool ob_device_is_cpu(const ob_device *dev);
/* Whether this device keeps the C library's freed heap (desc.driver_heap):
 * true only on a CPU device whose creation set the trim threshold. */
bool ob_device_keeps_driver_heap(const ob_device *dev);
/* Nanoseconds per timestamp tick (0 if timestamps are unsupported). */
double ob_device_timestamp_period_ns(const ob_device *dev);
PFN_vkCmdPushDescriptorSetKHR ob_device_push_descriptor_fn(const ob_device *dev);

/* Optional capabilities, enabled on the device when the hardware has them. */
typedef struct ob_device_caps {
    bool timeline_semaphore;     /* VkPhysicalDeviceVulkan12Features.timelineSemaphore */
    bool host_query_reset;       /* vkResetQueryPool from the host */
    bool sampler_anisotropy;
    bool fill_mode_non_solid;    /* wireframe */
    bool depth_clamp;
    bool depth_bias_clamp;
    bool wide_lines;
    bool independent_blend;
    bool multi_draw_indirect;
    bool draw_indirect_first_instance;  /* firstInstance of indirect draws honoured */
    bool texture_compression_bc;
    uint32_t timestamp_valid_bits;   /* of the chosen queue family; 0 = none */
    uint32_t device_index;           /* index in vkEnumeratePhysicalDevices */
    VkPhysicalDeviceType device_type;
} ob_device_caps;
const ob_device_caps *ob_device_get_caps(const ob_device *dev);

ob_validation_counts ob_device_validation_counts(const ob_device *dev);
bool ob_device_validation_enabled(const ob_device *dev);

/* Give a Vulkan object a debug name (no-op without debug utils). */
void ob_device_set_name(ob_device *dev, VkObjectType type, uint64_t handle, const char *name);

/* Returns the memory type index with all `required` property flags among
 * type_bits, or UINT32_MAX. */
uint32_t ob_device_memory_type(const ob_device *dev, uint32_t type_bits,
                               VkMemoryPropertyFlags required);
/* Whether the memory the engine maps (the first host-visible, coherent type)
 * is also device-local: true on lavapipe and integrated GPUs, false on a
 * discrete GPU, where it is host memory the GPU reads across PCIe. */
bool ob_device_host_memory_is_device_local(const ob_device *dev);

/* ---- frame slots and deferred deletion --------------------------------
 * The renderer tells the device which frame slot it is recording (after the
 * slot's fence has signalled). Destruction of a resource used in the current
 * frame is deferred until that slot comes round again. */
uint32_t ob_device_frames_in_flight(const ob_device *dev);
/* The slot's previous work is complete: run its deferred deletions and make
 * it current. [render thread] */
void ob_device_begin_frame_slot(ob_device *dev, uint32_t slot);
uint32_t ob_device_current_slot(const ob_device *dev);
typedef void (*ob_deferred_fn)(ob_device *dev, void *payload);
/* Queue fn(dev, payload) to run when the current slot's work is complete.
 * If the queue cannot grow, waits idle and runs it now. [render thread] */
void ob_device_defer(ob_device *dev, ob_deferred_fn fn, void *payload);

/* One-shot command buffer for uploads and read-backs: begin, record, then
 * submit and wait. [render thread] */
ob_result ob_device_oneshot_begin(ob_device *dev, VkCommandBuffer *out_cmd);
ob_result ob_device_oneshot_submit(ob_device *dev, VkCommandBuffer cmd);
/* Abandons a begun one-shot without submitting it (error paths). NULL is a no-op. */
void ob_device_oneshot_cancel(ob_device *dev, VkCommandBuffer cmd);
/* vkDeviceWaitIdle, with the result noted (device loss latches). [render thread] */
ob_result ob_device_wait_idle(ob_device *dev);

/* Records a device-loss or out-of-memory result seen anywhere; once lost the
 * device refuses new work with OB_ERR_DEVICE_LOST but can still be destroyed. */
void ob_device_note_result(ob_device *dev, VkResult res);
bool ob_device_is_lost(const ob_device *dev);

/* VkAllocationCallbacks that count the host allocations a driver makes
 * through them (malloc underneath, any alignment): give `callbacks` to the
 * create and destroy calls of one object, a command pool say, to see what
 * recording into it allocates (lavapipe: a block per command). The count is
 * atomic: any thread may allocate through it and read it. */
typedef struct ob_counting_allocator {
    VkAllocationCallbacks callbacks;
    atomic_uint_fast64_t allocations;   /* allocations + reallocations */
} ob_counting_allocator;
void ob_counting_allocator_init(ob_counting_allocator *a);
uint64_t ob_counting_allocator_count(ob_counting_allocator *a);

/* VkAllocationCallbacks for one command pool (the spec allows an allocator
 * per pool): blocks are carved in order from 64 KiB chunks and a chunk is
 * used again once all its blocks are freed, which a pool reset does. In the
 * steady state recording asks the system for nothing and writes the same
 * warm memory every frame, where malloc costs lavapipe a call per recorded
 * command. Blocks over 16 KiB come from malloc. Counts allocations as
 * ob_counting_allocator does. Not thread-safe, which a pool never needs:
 * everything that allocates or frees through a pool is externally
 * synchronized on it. */
typedef struct ob_arena_chunk ob_arena_chunk;
typedef struct ob_arena_allocator {
    VkAllocationCallbacks callbacks;
    ob_arena_chunk *current, *spare;
    atomic_uint_fast64_t allocations;   /* allocations + reallocations */
} ob_arena_allocator;
void ob_arena_allocator_init(ob_arena_allocator *a);
/* Frees the chunks. Destroy the pool first: a block still in use is logged
 * and leaked, never freed under the driver. */
void ob_arena_allocator_release(ob_arena_allocator *a);
uint64_t ob_arena_allocator_count(ob_arena_allocator *a);

#ifdef __cplusplus
}
#endif
#endif /* OB_DEVICE_H */
