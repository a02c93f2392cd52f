/* ob_resources.h — buffers, images and samplers behind generation-checked handles.
 *
 * Lifecycle: create → use in frames → destroy. Destruction is deferred until
 * the frame slot that was current at destroy time has finished on the GPU
 * (ob_device_defer), so a handle may be destroyed right after recording a
 * draw that uses it. The handle itself is invalid at once.
 *
 * Memory: one VkDeviceMemory per resource (no sub-allocation). Simple and
 * exact to free; its limit is maxMemoryAllocationCount (4096 on many
 * desktop drivers, unlimited on lavapipe), so geometry should be batched
 * into few large buffers on a real GPU. Uniform data does not allocate per
 * draw: it goes through per-thread rings (one buffer each).
 *
 * Thread rule: create/destroy/upload/read-back are [render thread]. The
 * ob_*_vk accessors are [any thread] during recording: workers may resolve
 * handles while the render thread does not create or destroy resources.
 * Failure: creation returns a zero handle and sets *out_result; a zero or stale
 * handle anywhere returns OB_ERR_INVALID_HANDLE (and logs), never crashes.
 */
#ifndef OB_RESOURCES_H
#define OB_RESOURCES_H

#include "ob_device.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ob_buffer_usage {
    OB_BUFFER_VERTEX = 1u << 0,
    OB_BUFFER_INDEX = 1u << 1,
    OB_BUFFER_UNIFORM = 1u << 2,
    OB_BUFFER_STORAGE = 1u << 3,
    OB_BUFFER_INDIRECT = 1u << 4,
    OB_BUFFER_TRANSFER_SRC = 1u << 5,
    OB_BUFFER_TRANSFER_DST = 1u << 6,
} ob_buffer_usage;

typedef struct ob_buffer_desc {
    uint64_t size;          /* bytes; 0 is an error */
    uint32_t usage;         /* ob_buffer_usage bits */
    bool host_visible;      /* mapped, host-coherent (rings, read-back); else device-local
                               (device-local buffers always allow transfers, for staging) */
    const void *data;       /* optional initial contents (staged when not host visible) */
    uint64_t data_size;     /* bytes of data (≤ size); 0 → size when data is set */
    const char *name;       /* debug name (copied) */
} ob_buffer_desc;

ob_buffer ob_buffer_create(ob_device *dev, const ob_buffer_desc *desc, ob_result *out_result);
void ob_buffer_destroy(ob_device *dev, ob_buffer buf);   /* deferred; zero handle is a no-op */
bool ob_buffer_is_valid(const ob_device *dev, ob_buffer buf);
VkBuffer ob_buffer_vk(const ob_device *dev, ob_buffer buf);        /* VK_NULL_HANDLE if invalid */
uint64_t ob_buffer_size(const ob_device *dev, ob_buffer buf);
void *ob_buffer_mapped(const ob_device *dev, ob_buffer buf);       /* NULL unless host visible */
/* Copies data into the buffer (memcpy when host visible, else staging + one-shot
 * copy that waits). Range-checked. */
ob_result ob_buffer_upload(ob_device *dev, ob_buffer buf, uint64_t offset,
                           const void *data, uint64_t size);
/* Copies `size` bytes at `offset` out of the buffer (staging + one-shot copy
 * for device-local buffers, a host-visibility barrier for mapped ones).
 * Waits for the device to be idle first. Range-checked. */
ob_result ob_buffer_read(ob_device *dev, ob_buffer buf, uint64_t offset, uint64_t size, void *out);

typedef enum ob_image_usage {
    OB_IMAGE_SAMPLED = 1u << 0,
    OB_IMAGE_COLOR_TARGET = 1u << 1,
    OB_IMAGE_DEPTH_TARGET = 1u << 2,
    OB_IMAGE_STORAGE = 1u << 3,
    OB_IMAGE_TRANSFER_SRC = 1u << 4,   /* read-back */
    OB_IMAGE_TRANSFER_DST = 1u << 5,   /* upload */
} ob_image_usage;

typedef struct ob_image_desc {
    uint32_t width, height;  /* 0 is an error */
    uint32_t layers;         /* 0 → 1; >1 makes a 2D array (paraboloid maps use 2) */
    bool array;              /* sampled as a 2D array even with one layer (a shader's
                                sampler2DArray: shadow cascades, however many) */
    VkFormat format;         /* must support the usage on this device, else OB_ERR_UNSUPPORTED */
    uint32_t usage;          /* ob_image_usage bits */
    uint32_t samples;        /* 0 or 1 → single-sampled; 2, 4, 8...: a multisampled
                                attachment (one layer, no data, no sampling or
                                transfers), OB_ERR_UNSUPPORTED where the format
                                and usage do not offer that count */
    const void *data;        /* optional tightly packed texels for every layer (colour,
                                D16/D32 or BC formats); staged, leaving the image in
                                SHADER_READ_ONLY_OPTIMAL (TRANSFER_DST is implied) */
    const char *name;
    /* Mip levels: 0 → 1; at most floor(log2(max(width, height))) + 1. With
     * data and more than one level, level 0 comes from data and the others
     * are made from it on the device (a chain of linear blits; TRANSFER_SRC
     * is implied): the format must support linear blit filtering
     * (OB_ERR_UNSUPPORTED otherwise) unless data_mips is set. Sampled views
     * cover every level; targets and read-back use level 0 (a colour target
     * may have mips: ob_image_record_mips fills them; a depth target may
     * not). */
    uint32_t mip_levels;
    /* data holds every level, level 0 first, each tightly packed (mips the
     * caller made, e.g. on the CPU where the format cannot be blitted). */
    bool data_mips;
} ob_image_desc;

ob_image ob_image_create(ob_device *dev, const ob_image_desc *desc, ob_result *out_result);
/* floor(log2(max(width, height))) + 1: the levels of a full mip chain. [any thread] */
uint32_t ob_image_mip_levels_max(uint32_t width, uint32_t height);
/* True when format's optimal tiling can be blitted with linear filtering on
 * this device (what device-made mips need). [any thread] */
bool ob_image_format_blits_linear(const ob_device *dev, VkFormat format);
void ob_image_destroy(ob_device *dev, ob_image img);      /* deferred */
bool ob_image_is_valid(const ob_device *dev, ob_image img);
VkImage ob_image_vk(const ob_device *dev, ob_image img);
/* The view over all layers and levels (2D or 2D array), and a view of a
 * single layer at level 0 (for rendering into one paraboloid half or cube
 * face, or into a single-layer target with mips). */
VkImageView ob_image_view(const ob_device *dev, ob_image img);
VkImageView ob_image_layer_view(const ob_device *dev, ob_image img, uint32_t layer);
typedef struct ob_image_info {
    uint32_t width, height, layers;
    VkFormat format;
    uint32_t usage;
    VkImageAspectFlags aspect;
    uint32_t mip_levels;     /* ≥ 1 */
    uint32_t samples;        /* 1 unless made multisampled */
} ob_image_info;
ob_result ob_image_get_info(const ob_device *dev, ob_image img, ob_image_info *out_info);

/* Layout tracking for barrier generation, whole image. The state is what the
 * image will be in after all work recorded so far (render thread only). */
typedef struct ob_image_state {
    VkImageLayout layout;
    VkPipelineStageFlags2 stages;
    VkAccessFlags2 access;
} ob_image_state;
ob_result ob_image_get_state(const ob_device *dev, ob_image img, ob_image_state *out_state);
/* Fills *out_barrier for moving img to `next` and records next as the state.
 * Returns false (no barrier needed) when the image is already in a read-only
 * state equal to next — or, more generally, in the same layout with read
 * accesses already made visible to next's stages and accesses (so a texture
 * uploaded at creation, tracked as {SHADER_READ_ONLY_OPTIMAL, ALL_COMMANDS,
 * SHADER_READ}, needs no barrier before a fragment shader samples it).
 * A read-to-read barrier in one layout records the union of both states, so
 * a later write waits for every reader. Layout is whole-image (all layers).
 * src of the barrier = tracked stages/access/layout, dst = next. */
bool ob_image_transition(ob_device *dev, ob_image img, const ob_image_state *next,
                         VkImageMemoryBarrier2 *out_barrier);
/* Sets the tracked state without recording anything: rolls the tracking
 * back when recorded barriers were never submitted (a failed frame).
 * OB_ERR_INVALID_HANDLE / OB_ERR_INVALID_ARGUMENT, logged. [render thread] */
ob_result ob_image_set_state(ob_device *dev, ob_image img, const ob_image_state *state);

/* Records, into cmd, the mip chain of img made from its level 0 (linear
 * blits, each level a box filter of the one above; every layer): for a
 * colour target with mips after it was rendered. Transitions from the
 * tracked state and leaves every level in TRANSFER_SRC_OPTIMAL, tracked,
 * so the next transition (to sampling) waits for the blits. false, nothing
 * recorded, for an invalid handle or a single level. The format must blit
 * with linear filtering (ob_image_format_blits_linear). [render thread,
 * recording the primary] */
bool ob_image_record_mips(ob_device *dev, VkCommandBuffer cmd, ob_image img);

/* Reads the image (layer 0) back as tightly packed RGBA8 (colour formats
 * R8G8B8A8/B8G8R8A8 UNORM/SRGB and R8G8B8A8_UINT, swizzled to RGBA, bytes as
 * stored — sRGB-encoded for the SRGB formats; R16G16B16A16_SFLOAT as linear
 * values clamped to [0, 1] and scaled to 0..255, not encoded). Waits
 * for the device to be idle, so everything recorded for the image must have
 * been submitted. Needs OB_IMAGE_TRANSFER_SRC usage and defined contents
 * (OB_ERR_WRONG_STATE while the layout is UNDEFINED). The tracked state is
 * restored afterwards. out must hold width*height*4 bytes. */
ob_result ob_image_read_rgba8(ob_device *dev, ob_image img, uint8_t *out);
/* The same for one layer of an array image (layer < layers). */
ob_result ob_image_read_layer_rgba8(ob_device *dev, ob_image img, uint32_t layer, uint8_t *out);
/* Reads back and writes a PNG (stb_image_write). */
ob_result ob_image_write_png(ob_device *dev, ob_image img, const char *path);

typedef struct ob_sampler_desc {
    VkFilter filter;                   /* 0 = NEAREST; use LINEAR explicitly */
    VkSamplerAddressMode address;      /* 0 = REPEAT; CLAMP_TO_BORDER uses opaque white */
    bool compare;                      /* depth comparison (shadow maps) */
    VkCompareOp compare_op;            /* with compare: 0 (NEVER) → LESS_OR_EQUAL */
    const char *name;
    /* Per-axis control (textures from models): when set, the fields below
     * replace filter and address (W follows U). */
    bool detailed;
    VkFilter mag_filter, min_filter;
    VkSamplerMipmapMode mipmap_mode;
    VkSamplerAddressMode address_u, address_v;
    float max_lod;                     /* highest level sampled; 0 → level 0 only */
} ob_sampler_desc;

ob_sampler ob_sampler_create(ob_device *dev, const ob_sampler_desc *desc, ob_result *out_result);
void ob_sampler_destroy(ob_device *dev, ob_sampler s);    /* deferred */
VkSampler ob_sampler_vk(const ob_device *dev, ob_sampler s);

/* Counts of live resources (leak checks in tests). */
typedef struct ob_resource_counts {
    uint32_t buffers, images, samplers;
    uint64_t device_bytes;
} ob_resource_counts;
ob_resource_counts ob_resource_counts_get(const ob_device *dev);

#ifdef __cplusplus
}
#endif
#endif /* OB_RESOURCES_H */
