/* ob_resources_internal.h — records behind the resource handles and the
 * helpers shared by ob_resources.c (registry, buffers, samplers),
 * ob_resources_image.c (images, layout tracking) and ob_readback.c.
 * Engine-private: not API.
 *
 * Thread rule as in ob_resources.h: records are created, changed and freed
 * on the render thread; workers only read them through the accessors.
 */
#ifndef OB_RESOURCES_INTERNAL_H
#define OB_RESOURCES_INTERNAL_H

#include "ob_device_internal.h"
#include "ob_resources.h"

/* Internal: not exported from libobelisk.so (cmake/obelisk.map). */
#pragma GCC visibility push(hidden)

typedef struct ob_buffer_rec {
    VkBuffer buffer;
    VkDeviceMemory memory;
    uint64_t size;        /* requested bytes */
    uint64_t mem_size;    /* bytes of the allocation */
    uint32_t usage;       /* ob_buffer_usage bits */
    bool host_visible;
    void *mapped;         /* persistent mapping when host visible */
    char *name;
} ob_buffer_rec;

typedef struct ob_image_rec {
    VkImage image;
    VkDeviceMemory memory;
    VkImageView view;          /* all layers: 2D or 2D array */
    VkImageView *layer_views;  /* one 2D view per layer when layers > 1 */
    bool array;                /* `view` is a 2D array even with one layer */
    uint64_t mem_size;
    ob_image_info info;
    ob_image_state state;
    char *name;
} ob_image_rec;

typedef struct ob_sampler_rec {
    VkSampler sampler;
    char *name;
} ob_sampler_rec;

struct ob_resource_registry {
    ob_pool buffers, images, samplers;
    uint64_t device_bytes;
};

/* A VkBuffer with its own memory: what ob_res_vk_buffer_make gives. */
typedef struct ob_res_vk_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *mapped;                /* with map; NULL otherwise */
    VkDeviceSize mem_size;       /* bytes of memory allocated */
} ob_res_vk_buffer;

/* The engine's one path to a VkBuffer and its memory (buffers, staging):
 * creates it (exclusive, `usage`), allocates memory of `flags` for it
 * (ob_res_memory_alloc), binds it and, with map, maps all of it. Failure:
 * the error (the VkResult noted on the device), logged as "<what> '<name>'
 * ...", *out zeroed with nothing left behind. [any thread]: it touches no
 * shared engine state (pipeline managers grow their uniform rings with it
 * on their workers). */
ob_result ob_res_vk_buffer_make(ob_device *dev, VkDeviceSize size, VkBufferUsageFlags usage,
                                VkMemoryPropertyFlags flags, bool map, const char *what,
                                const char *name, ob_res_vk_buffer *out);
/* Destroys the buffer and frees (so unmaps) its memory; zeroes *b. A zeroed
 * *b is a no-op. */
void ob_res_vk_buffer_free(ob_device *dev, ob_res_vk_buffer *b);

/* A host-visible, coherent, mapped scratch buffer for one upload or
 * read-back; destroyed right after its one-shot has completed. */
typedef ob_res_vk_buffer ob_staging;

ob_result ob_staging_create(ob_device *dev, uint64_t size, const char *owner_name, ob_staging *out_staging);
void ob_staging_destroy(ob_device *dev, ob_staging *staging);

/* Allocates memory of `flags` for req (falls back to any type when no
 * DEVICE_LOCAL type matches). Logs `what` 'name' on failure. */
ob_result ob_res_memory_alloc(ob_device *dev, const VkMemoryRequirements *req, VkMemoryPropertyFlags flags,
                              const char *what, const char *name, VkDeviceMemory *out_memory);

/* Gives obj the debug name "<name><suffix>". */
void ob_res_set_name(ob_device *dev, VkObjectType type, uint64_t handle, const char *name, const char *suffix);

/* Puts a finished record into its pool and counts its device memory;
 * 0 (with *out_result set) when the pool cannot grow. */
uint32_t ob_res_register(ob_device *dev, ob_pool *pool, void *rec, uint64_t mem_size, ob_result *out_result);
/* Takes id out of its pool at once (so the handle is dead) and returns the
 * record for the caller to uncount and defer; NULL, logged as coming from
 * `caller`, when id is stale. */
void *ob_res_retire(ob_pool *pool, uint32_t id, const char *caller, const char *kind);

/* Resolve a handle; log "<caller>: invalid or stale <kind> handle" and return
 * NULL when it does not resolve. */
ob_buffer_rec *ob_res_buffer_get(const ob_device *dev, ob_buffer buf, const char *caller);
ob_image_rec *ob_res_image_get(const ob_device *dev, ob_image img, const char *caller);

/* Fills *out_barrier for moving rec from its tracked state to next and
 * records the new state; false when no barrier is needed. */
bool ob_res_image_transition(ob_image_rec *rec, const ob_image_state *next, VkImageMemoryBarrier2 *out_barrier);

/* Mip levels (ob_resources_mips.c). */
/* OB_OK when format's optimal tiling supports blits with linear filtering on
 * this device; else logs naming the image and returns OB_ERR_UNSUPPORTED. */
ob_result ob_res_mips_blit_check(ob_device *dev, const char *name, VkFormat format);
/* Records the chain of linear blits level i-1 → i for every level of rec,
 * whose level 0 has just been written (by a transfer in stage
 * level0_written_by: the upload's copy, or the transition into
 * TRANSFER_DST, waited for in BLIT, of ob_image_record_mips) and whose
 * levels are all in TRANSFER_DST_OPTIMAL (made wait for ALL_TRANSFER, or BLIT). Leaves every level in
 * TRANSFER_SRC_OPTIMAL and rec's tracked state saying so. */
void ob_res_image_blit_mips(VkCommandBuffer cmd, ob_image_rec *rec, VkPipelineStageFlags2 level0_written_by);
/* Records the copy of every level from a staging buffer that holds them
 * tightly packed, level 0 first (all in TRANSFER_DST_OPTIMAL). */
void ob_res_image_copy_levels(VkCommandBuffer cmd, VkBuffer staging, const ob_image_rec *rec, uint32_t block_bytes,
                              uint32_t block_dim);

/* Freed here so that the registry can release leaked images at destroy. */
void ob_res_image_free(ob_device *dev, ob_image_rec *rec);

/* zlib's deflate of data at `level` (1-9), every allocation through
 * ob_malloc: an ob_malloc'ed stream and its length, NULL on any failure
 * (logged by the caller). [any thread] (engine/ob_stb_impl.c) */
uint8_t *ob_res_deflate(const uint8_t *data, size_t len, int level, size_t *out_len);

#pragma GCC visibility pop

#endif /* OB_RESOURCES_INTERNAL_H */
