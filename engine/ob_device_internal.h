/* ob_device_internal.h — engine-private glue between the device and the
 * resource modules. Not API: nothing outside engine/ob_device*.c,
 * engine/ob_frame_slots.c and engine/ob_resources*.c / ob_readback.c
 * includes it.
 *
 * The device owns the resource registry so that ob_device_destroy can free
 * whatever the application leaked; the registry code lives with the
 * resources. Physical-device probing lives in ob_device_select.c, the
 * checks of an application's own Vulkan objects in ob_device_adopt.c.
 */
#ifndef OB_DEVICE_INTERNAL_H
#define OB_DEVICE_INTERNAL_H

#include "ob_device.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

/* ---- physical device selection (ob_device_select.c) ---- */

typedef struct ob_physical_choice {
    VkPhysicalDevice physical;
    uint32_t queue_family;
    VkPhysicalDeviceProperties props;
    char driver_info[VK_MAX_DRIVER_INFO_SIZE + VK_MAX_DRIVER_NAME_SIZE + 4];
    ob_device_caps caps;   /* what the device supports; enabled as-is */
} ob_physical_choice;

/* Keeps every shared object loaded at the call (the Vulkan loader, the
 * drivers, the layers) loaded for the rest of the process (ob_device_pin.c
 * says why). Called right after an instance is created. [any thread] */
void ob_device_pin_drivers(void);

/* Picks a physical device for `selector` (NULL/"" = automatic, "lavapipe",
 * "gpu" or a decimal index). On failure logs every device seen with the
 * reason it was rejected and returns OB_ERR_NO_DEVICE (or
 * OB_ERR_INVALID_ARGUMENT for a malformed selector). */
ob_result ob_device_select_physical(VkInstance instance, const char *selector,
                                    ob_physical_choice *out_choice);

/* Probes one physical device against the requirements of ob_device.h:
 * fills *out_choice (the first graphics + compute family; caps = what the
 * hardware supports) and *out_suitable; when unsuitable, `reason` says why.
 * Only a host allocation failure is an error. */
ob_result ob_device_probe_physical(VkPhysicalDevice pd, uint32_t index, ob_physical_choice *out_choice,
                                   bool *out_suitable, char *reason, size_t reason_size);

/* ---- adopted handles (ob_device_adopt.c) ---- */

/* What an application's instance and device have enabled that the engine
 * cares about beyond the requirements. */
typedef struct ob_adopted_info {
    bool debug_utils;   /* VK_EXT_debug_utils on the instance */
    bool swapchain;     /* VK_KHR_swapchain on the device */
} ob_adopted_info;

/* Checks an application's handles against the engine's requirements (see
 * ob_vulkan_handles) and fills *out_choice with the physical device, the
 * application's queue family and caps = supported and enabled. On failure
 * logs every requirement that is missing and returns OB_ERR_UNSUPPORTED
 * (OB_ERR_INVALID_ARGUMENT for null or inconsistent handles). */
ob_result ob_device_check_adopted(const ob_vulkan_handles *a, ob_physical_choice *out_choice,
                                  ob_adopted_info *out_info);

/* ---- frame slots and deferred deletion (ob_frame_slots.c) ---- */

typedef struct ob_defer_queue ob_defer_queue;

/* The device's frame slots: one deferred-deletion queue per slot, run when
 * the renderer says the slot's previous work is complete
 * (ob_device_begin_frame_slot). Part of the device; the public functions of
 * ob_device.h reach it through ob_device_frame_slots. */
typedef struct ob_frame_slots {
    ob_defer_queue *queues;   /* one per slot */
    uint32_t frames_in_flight, current_slot;
} ob_frame_slots;

/* frames 0 → 2; more than OB_MAX_FRAMES_IN_FLIGHT is refused (logged,
 * OB_ERR_INVALID_ARGUMENT). On failure nothing is left to release. */
ob_result ob_frame_slots_init(ob_frame_slots *s, uint32_t frames);
/* Runs every queue, oldest slot first, until no deferred function defers
 * more (the device is idle: ob_device_destroy). */
void ob_frame_slots_drain(ob_frame_slots *s, ob_device *dev);
/* Frees the queues (drained or not). Safe on a zeroed struct. */
void ob_frame_slots_release(ob_frame_slots *s);
/* The device's slots (never NULL for a created device). */
ob_frame_slots *ob_device_frame_slots(ob_device *dev);

/* ---- resource registry (ob_resources.c) ---- */

typedef struct ob_resource_registry ob_resource_registry;

ob_resource_registry *ob_resource_registry_create(ob_result *out_result);
/* Frees every resource still registered (the application leaked them),
 * logging one warning that names them, then the registry. The device must be
 * idle. NULL is a no-op. */
void ob_resource_registry_destroy(ob_device *dev, ob_resource_registry *reg);
/* The device's registry (never NULL for a created device). */
ob_resource_registry *ob_device_registry(const ob_device *dev);

#pragma GCC visibility pop

#endif /* OB_DEVICE_INTERNAL_H */
