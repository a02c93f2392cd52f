/* ob_resources.c — the resource registry, buffers, samplers and the memory
 * and staging helpers the image and read-back code share.
 *
 * One VkDeviceMemory per resource (see ob_resources.h for why). A handle is
 * removed from its pool at destroy time, so it is rejected at once; the
 * Vulkan objects go through ob_device_defer and die when the frame slot
 * that may still use them has completed.
 */
#include "ob_resources_internal.h"

#include <stdio.h>
#include <string.h>

#define OB_BUFFER_USAGE_ALL                                                                  \
    (OB_BUFFER_VERTEX | OB_BUFFER_INDEX | OB_BUFFER_UNIFORM | OB_BUFFER_STORAGE |            \
     OB_BUFFER_INDIRECT | OB_BUFFER_TRANSFER_SRC | OB_BUFFER_TRANSFER_DST)

/* ------------------------------------------------------------------ helpers */

void ob_res_set_name(ob_device *dev, VkObjectType type, uint64_t handle, const char *name, const char *suffix)
{
    char full[256];
    snprintf(full, sizeof full, "%s%s", name, suffix ? suffix : "");
    ob_device_set_name(dev, type, handle, full);
}

ob_result ob_res_memory_alloc(ob_device *dev, const VkMemoryRequirements *req, VkMemoryPropertyFlags flags,
                              const char *what, const char *name, VkDeviceMemory *out_memory)
{
    *out_memory = VK_NULL_HANDLE;
    uint32_t type = ob_device_memory_type(dev, req->memoryTypeBits, flags);
    if (type == UINT32_MAX && flags == VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT)
        type = ob_device_memory_type(dev, req->memoryTypeBits, 0);
    if (type == UINT32_MAX) {
        OB_LOG_E("resources", "%s '%s': no memory type with properties 0x%x among types 0x%x", what, name,
                 (unsigned)flags, req->memoryTypeBits);
        return OB_ERR_UNSUPPORTED;
    }
    VkMemoryAllocateInfo info = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req->size,
        .memoryTypeIndex = type,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkAllocateMemory(ob_device_vk(dev), &info, NULL, out_memory));
    if (vr < 0) {
        *out_memory = VK_NULL_HANDLE;
        ob_device_note_result(dev, vr);
        OB_LOG_E("resources", "%s '%s': cannot allocate %llu bytes of device memory", what, name,
                 (unsigned long long)req->size);
        return ob_result_from_vk(vr);
    }
    return OB_OK;
}

void ob_res_vk_buffer_free(ob_device *dev, ob_res_vk_buffer *b)
{
    VkDevice vk = ob_device_vk(dev);
    if (b->buffer) vkDestroyBuffer(vk, b->buffer, NULL);
    if (b->memory) vkFreeMemory(vk, b->memory, NULL);   /* unmaps too */
    memset(b, 0, sizeof *b);
}

ob_result ob_res_vk_buffer_make(ob_device *dev, VkDeviceSize size, VkBufferUsageFlags usage,
                                VkMemoryPropertyFlags flags, bool map, const char *what,
                                const char *name, ob_res_vk_buffer *out)
{
    memset(out, 0, sizeof *out);
    VkDevice vk = ob_device_vk(dev);
    VkBufferCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = size,
        .usage = usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateBuffer(vk, &info, NULL, &out->buffer));
    if (vr < 0) {
        out->buffer = VK_NULL_HANDLE;
        ob_device_note_result(dev, vr);
        OB_LOG_E("resources", "%s '%s': cannot create a %llu-byte buffer", what, name,
                 (unsigned long long)size);
        return ob_result_from_vk(vr);
    }
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(vk, out->buffer, &req);
    ob_result r = ob_res_memory_alloc(dev, &req, flags, what, name, &out->memory);
    if (r != OB_OK) goto fail_free_buffer;
    out->mem_size = req.size;
    vr = OB_VK_CHECK(vkBindBufferMemory(vk, out->buffer, out->memory, 0));
    if (vr >= 0 && map) vr = OB_VK_CHECK(vkMapMemory(vk, out->memory, 0, VK_WHOLE_SIZE, 0, &out->mapped));
    if (vr < 0) {
        ob_device_note_result(dev, vr);
        r = ob_result_from_vk(vr);
        goto fail_free_buffer;
    }
    return OB_OK;

fail_free_buffer:
    ob_res_vk_buffer_free(dev, out);
    return r;
}

void ob_staging_destroy(ob_device *dev, ob_staging *staging)
{
    ob_res_vk_buffer_free(dev, staging);
}

ob_result ob_staging_create(ob_device *dev, uint64_t size, const char *owner_name, ob_staging *out_staging)
{
    ob_result r = ob_res_vk_buffer_make(dev, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                        true, "staging for", owner_name, out_staging);
    if (r == OB_OK)
        ob_res_set_name(dev, VK_OBJECT_TYPE_BUFFER, (uint64_t)(uintptr_t)out_staging->buffer, owner_name,
                        " (staging)");
    return r;
}

uint32_t ob_res_register(ob_device *dev, ob_pool *pool, void *rec, uint64_t mem_size, ob_result *out_result)
{
    uint32_t id = ob_pool_insert(pool, rec, out_result);
    if (id) ob_device_registry(dev)->device_bytes += mem_size;
    return id;
}

void *ob_res_retire(ob_pool *pool, uint32_t id, const char *caller, const char *kind)
{
    void *rec = ob_pool_remove(pool, id);
    if (!rec) OB_LOG_E("resources", "%s: invalid or stale %s handle 0x%08x", caller, kind, id);
    return rec;
}

ob_buffer_rec *ob_res_buffer_get(const ob_device *dev, ob_buffer buf, const char *caller)
{
    ob_buffer_rec *rec = ob_pool_get(&ob_device_registry(dev)->buffers, buf.id);
    if (!rec)
        OB_LOG_E("resources", "%s: %s buffer handle 0x%08x", caller, buf.id ? "invalid or stale" : "null", buf.id);
    return rec;
}

/* ------------------------------------------------------------------ buffers */

static void buffer_rec_free(ob_device *dev, ob_buffer_rec *rec)
{
    VkDevice vk = ob_device_vk(dev);
    if (rec->buffer) vkDestroyBuffer(vk, rec->buffer, NULL);
    if (rec->memory) vkFreeMemory(vk, rec->memory, NULL);
    ob_free(rec->name);
    ob_free(rec);
}

static void buffer_free_deferred(ob_device *dev, void *payload) { buffer_rec_free(dev, payload); }

static VkBufferUsageFlags buffer_vk_usage(uint32_t usage, bool host_visible)
{
    VkBufferUsageFlags f = 0;
    if (usage & OB_BUFFER_VERTEX) f |= VK_BUFFER_USAGE_VERTEX_BUFFER_BIT;
    if (usage & OB_BUFFER_INDEX) f |= VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    if (usage & OB_BUFFER_UNIFORM) f |= VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
    if (usage & OB_BUFFER_STORAGE) f |= VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    if (usage & OB_BUFFER_INDIRECT) f |= VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    if (usage & OB_BUFFER_TRANSFER_SRC) f |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    if (usage & OB_BUFFER_TRANSFER_DST) f |= VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    /* Device-local buffers are filled (ob_buffer_upload) and read back
     * (ob_buffer_read) through staging copies. */
    if (!host_visible) f |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    return f;
}

/* Copies through a staging buffer in a one-shot that waits. The barriers
 * order the copy after earlier work on the buffer and make it visible to any
 * later work, so callers need not know what the queue did before. */
static ob_result buffer_upload_staged(ob_device *dev, ob_buffer_rec *rec, uint64_t offset, const void *data,
                                      uint64_t size)
{
    ob_staging staging;
    ob_result r = ob_staging_create(dev, size, rec->name, &staging);
    if (r != OB_OK) return r;
    memcpy(staging.mapped, data, (size_t)size);
    VkCommandBuffer cmd;
    r = ob_device_oneshot_begin(dev, &cmd);
    if (r != OB_OK) goto done;
    VkBufferMemoryBarrier2 before = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2,
        .srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
        .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT,
        .dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
        .dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .buffer = rec->buffer,
        .offset = offset,
        .size = size,
    };
    VkBufferMemoryBarrier2 after = before;
    after.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    after.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    after.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    after.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .bufferMemoryBarrierCount = 1,
        .pBufferMemoryBarriers = &before,
    };
    vkCmdPipelineBarrier2(cmd, &dep);
    VkBufferCopy region = {.srcOffset = 0, .dstOffset = offset, .size = size};
    vkCmdCopyBuffer(cmd, staging.buffer, rec->buffer, 1, &region);
    dep.pBufferMemoryBarriers = &after;
    vkCmdPipelineBarrier2(cmd, &dep);
    r = ob_device_oneshot_submit(dev, cmd);
    if (r != OB_OK) OB_LOG_E("resources", "buffer '%s': staged upload of %llu bytes failed: %s", rec->name,
                             (unsigned long long)size, ob_result_name(r));
done:
    ob_staging_destroy(dev, &staging);
    return r;
}

static ob_result buffer_desc_check(const ob_buffer_desc *desc, const char *name, uint64_t *out_data_size)
{
    if (desc->size == 0) {
        OB_LOG_E("resources", "buffer '%s': size is 0", name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->usage == 0 || (desc->usage & ~(uint32_t)OB_BUFFER_USAGE_ALL)) {
        OB_LOG_E("resources", "buffer '%s': usage 0x%x is %s", name, desc->usage,
                 desc->usage ? "not a set of ob_buffer_usage bits" : "empty");
        return OB_ERR_INVALID_ARGUMENT;
    }
    uint64_t data_size = desc->data ? (desc->data_size ? desc->data_size : desc->size) : 0;
    if (!desc->data && desc->data_size) {
        OB_LOG_E("resources", "buffer '%s': data_size %llu without data", name, (unsigned long long)desc->data_size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (data_size > desc->size) {
        OB_LOG_E("resources", "buffer '%s': %llu bytes of data exceed its size %llu", name,
                 (unsigned long long)data_size, (unsigned long long)desc->size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    *out_data_size = data_size;
    return OB_OK;
}

ob_buffer ob_buffer_create(ob_device *dev, const ob_buffer_desc *desc, ob_result *out_result)
{
    ob_buffer handle = {0};
    ob_result r;
    const char *name = desc && desc->name ? desc->name : "(unnamed)";
    uint64_t data_size = 0;
    if (!desc) {
        OB_LOG_E("resources", "ob_buffer_create: desc is NULL");
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    if (ob_device_is_lost(dev)) {
        r = OB_ERR_DEVICE_LOST;
        goto fail_log;
    }
    r = buffer_desc_check(desc, name, &data_size);
    if (r != OB_OK) goto fail_log;

    ob_buffer_rec *rec = ob_calloc(1, sizeof *rec);
    if (!rec) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    rec->size = desc->size;
    rec->usage = desc->usage;
    rec->host_visible = desc->host_visible;
    rec->name = ob_strdup(name);
    if (!rec->name) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_rec;
    }
    VkMemoryPropertyFlags flags = desc->host_visible
                                      ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                      : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    ob_res_vk_buffer made;
    r = ob_res_vk_buffer_make(dev, desc->size, buffer_vk_usage(desc->usage, desc->host_visible), flags,
                              desc->host_visible, "buffer", name, &made);
    if (r != OB_OK) goto fail_free_rec;
    rec->buffer = made.buffer;
    rec->memory = made.memory;
    rec->mapped = made.mapped;
    rec->mem_size = made.mem_size;
    ob_res_set_name(dev, VK_OBJECT_TYPE_BUFFER, (uint64_t)(uintptr_t)rec->buffer, name, NULL);
    ob_res_set_name(dev, VK_OBJECT_TYPE_DEVICE_MEMORY, (uint64_t)(uintptr_t)rec->memory, name, " (memory)");

    if (data_size && desc->host_visible) {
        memcpy(rec->mapped, desc->data, (size_t)data_size);
    } else if (data_size) {
        r = buffer_upload_staged(dev, rec, 0, desc->data, data_size);
        if (r != OB_OK) goto fail_free_rec;
    }
    handle.id = ob_res_register(dev, &ob_device_registry(dev)->buffers, rec, rec->mem_size, &r);
    if (!handle.id) goto fail_free_rec;
    if (out_result) *out_result = OB_OK;
    return handle;

fail_free_rec:
    buffer_rec_free(dev, rec);
fail_log:
    OB_LOG_E("resources", "buffer '%s' not created: %s", name, ob_result_name(r));
    if (out_result) *out_result = r;
    return handle;
}

void ob_buffer_destroy(ob_device *dev, ob_buffer buf)
{
    if (!buf.id) return;
    ob_resource_registry *reg = ob_device_registry(dev);
    ob_buffer_rec *rec = ob_res_retire(&reg->buffers, buf.id, "ob_buffer_destroy", "buffer");
    if (!rec) return;
    reg->device_bytes -= rec->mem_size;
    ob_device_defer(dev, buffer_free_deferred, rec);
}

bool ob_buffer_is_valid(const ob_device *dev, ob_buffer buf)
{
    return ob_pool_get(&ob_device_registry(dev)->buffers, buf.id) != NULL;
}

VkBuffer ob_buffer_vk(const ob_device *dev, ob_buffer buf)
{
    ob_buffer_rec *rec = ob_res_buffer_get(dev, buf, "ob_buffer_vk");
    return rec ? rec->buffer : VK_NULL_HANDLE;
}

uint64_t ob_buffer_size(const ob_device *dev, ob_buffer buf)
{
    ob_buffer_rec *rec = ob_res_buffer_get(dev, buf, "ob_buffer_size");
    return rec ? rec->size : 0;
}

void *ob_buffer_mapped(const ob_device *dev, ob_buffer buf)
{
    ob_buffer_rec *rec = ob_res_buffer_get(dev, buf, "ob_buffer_mapped");
    return rec ? rec->mapped : NULL;
}

ob_result ob_buffer_upload(ob_device *dev, ob_buffer buf, uint64_t offset, const void *data, uint64_t size)
{
    ob_buffer_rec *rec = ob_res_buffer_get(dev, buf, "ob_buffer_upload");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    if (ob_device_is_lost(dev)) return OB_ERR_DEVICE_LOST;
    if (size == 0) return OB_OK;
    if (!data) {
        OB_LOG_E("resources", "buffer '%s': upload of %llu bytes from NULL", rec->name, (unsigned long long)size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (offset > rec->size || size > rec->size - offset) {
        OB_LOG_E("resources", "buffer '%s': upload of %llu bytes at offset %llu exceeds its size %llu", rec->name,
                 (unsigned long long)size, (unsigned long long)offset, (unsigned long long)rec->size);
        return OB_ERR_OUT_OF_RANGE;
    }
    if (rec->host_visible) {
        memcpy((char *)rec->mapped + offset, data, (size_t)size);
        return OB_OK;
    }
    return buffer_upload_staged(dev, rec, offset, data, size);
}

/* ----------------------------------------------------------------- samplers */

static void sampler_rec_free(ob_device *dev, ob_sampler_rec *rec)
{
    if (rec->sampler) vkDestroySampler(ob_device_vk(dev), rec->sampler, NULL);
    ob_free(rec->name);
    ob_free(rec);
}

static void sampler_free_deferred(ob_device *dev, void *payload) { sampler_rec_free(dev, payload); }

ob_sampler ob_sampler_create(ob_device *dev, const ob_sampler_desc *desc, ob_result *out_result)
{
    static const ob_sampler_desc defaults = {0};
    ob_sampler handle = {0};
    ob_result r = OB_OK;
    if (!desc) desc = &defaults;
    const char *name = desc->name ? desc->name : "(unnamed)";
    if (ob_device_is_lost(dev)) {
        r = OB_ERR_DEVICE_LOST;
        goto fail_log;
    }
    if ((unsigned)desc->filter > VK_FILTER_LINEAR ||
        (unsigned)desc->address > VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER ||
        (unsigned)desc->compare_op > VK_COMPARE_OP_ALWAYS ||
        (desc->detailed && ((unsigned)desc->mag_filter > VK_FILTER_LINEAR || (unsigned)desc->min_filter > VK_FILTER_LINEAR ||
                            (unsigned)desc->mipmap_mode > VK_SAMPLER_MIPMAP_MODE_LINEAR ||
                            (unsigned)desc->address_u > VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER ||
                            (unsigned)desc->address_v > VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER ||
                            !(desc->max_lod >= 0.0f && desc->max_lod <= VK_LOD_CLAMP_NONE)))) {
        OB_LOG_E("resources", "sampler '%s': filter %d, address mode %d, compare op %d or a detailed "
                              "filter, mip mode, address mode or max_lod is out of range", name,
                 (int)desc->filter, (int)desc->address, (int)desc->compare_op);
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    ob_sampler_rec *rec = ob_calloc(1, sizeof *rec);
    if (!rec) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    rec->name = ob_strdup(name);
    if (!rec->name) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_rec;
    }
    VkSamplerCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO,
        .magFilter = desc->filter,
        .minFilter = desc->filter,
        .mipmapMode = desc->filter == VK_FILTER_LINEAR ? VK_SAMPLER_MIPMAP_MODE_LINEAR
                                                       : VK_SAMPLER_MIPMAP_MODE_NEAREST,
        .addressModeU = desc->address,
        .addressModeV = desc->address,
        .addressModeW = desc->address,
        .compareEnable = desc->compare,
        /* NEVER (0) is useless for shadow lookups: zero means the usual test. */
        .compareOp = desc->compare && desc->compare_op == VK_COMPARE_OP_NEVER ? VK_COMPARE_OP_LESS_OR_EQUAL
                                                                               : desc->compare_op,
        .minLod = 0.0f,
        .maxLod = VK_LOD_CLAMP_NONE,
        /* Outside a clamped shadow map counts as lit. */
        .borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
    };
    if (desc->detailed) {
        info.magFilter = desc->mag_filter;
        info.minFilter = desc->min_filter;
        info.mipmapMode = desc->mipmap_mode;
        info.addressModeU = info.addressModeW = desc->address_u;
        info.addressModeV = desc->address_v;
        info.maxLod = desc->max_lod;
    }
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateSampler(ob_device_vk(dev), &info, NULL, &rec->sampler));
    if (vr < 0) {
        rec->sampler = VK_NULL_HANDLE;
        ob_device_note_result(dev, vr);
        r = ob_result_from_vk(vr);
        goto fail_free_rec;
    }
    ob_res_set_name(dev, VK_OBJECT_TYPE_SAMPLER, (uint64_t)(uintptr_t)rec->sampler, name, NULL);
    handle.id = ob_res_register(dev, &ob_device_registry(dev)->samplers, rec, 0, &r);
    if (!handle.id) goto fail_free_rec;
    if (out_result) *out_result = OB_OK;
    return handle;

fail_free_rec:
    sampler_rec_free(dev, rec);
fail_log:
    OB_LOG_E("resources", "sampler '%s' not created: %s", name, ob_result_name(r));
    if (out_result) *out_result = r;
    return handle;
}

void ob_sampler_destroy(ob_device *dev, ob_sampler s)
{
    if (!s.id) return;
    ob_sampler_rec *rec = ob_res_retire(&ob_device_registry(dev)->samplers, s.id, "ob_sampler_destroy", "sampler");
    if (!rec) return;
    ob_device_defer(dev, sampler_free_deferred, rec);
}

VkSampler ob_sampler_vk(const ob_device *dev, ob_sampler s)
{
    ob_sampler_rec *rec = ob_pool_get(&ob_device_registry(dev)->samplers, s.id);
    if (!rec) {
        OB_LOG_E("resources", "ob_sampler_vk: %s sampler handle 0x%08x", s.id ? "invalid or stale" : "null", s.id);
        return VK_NULL_HANDLE;
    }
    return rec->sampler;
}

/* ----------------------------------------------------------------- registry */

ob_resource_registry *ob_resource_registry_create(ob_result *out_result)
{
    ob_resource_registry *reg = ob_calloc(1, sizeof *reg);
    if (!reg) {
        *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
        return NULL;
    }
    ob_pool_init(&reg->buffers);
    ob_pool_init(&reg->images);
    ob_pool_init(&reg->samplers);
    *out_result = OB_OK;
    return reg;
}

static void append_name(char *list, size_t cap, size_t *len, const char *kind, const char *name)
{
    if (*len + 1 >= cap) return;
    int n = snprintf(list + *len, cap - *len, "%s%s '%s'", *len ? ", " : "", kind, name);
    if (n > 0) *len = OB_MIN(cap - 1, *len + (size_t)n);
}

void ob_resource_registry_destroy(ob_device *dev, ob_resource_registry *reg)
{
    if (!reg) return;
    uint32_t leaked = reg->buffers.count + reg->images.count + reg->samplers.count;
    if (leaked) {
        char names[800];
        size_t len = 0;
        names[0] = '\0';
        uint32_t cursor = 0;
        ob_buffer_rec *b;
        while ((b = ob_pool_next(&reg->buffers, &cursor, NULL))) append_name(names, sizeof names, &len, "buffer", b->name);
        cursor = 0;
        ob_image_rec *im;
        while ((im = ob_pool_next(&reg->images, &cursor, NULL))) append_name(names, sizeof names, &len, "image", im->name);
        cursor = 0;
        ob_sampler_rec *s;
        while ((s = ob_pool_next(&reg->samplers, &cursor, NULL))) append_name(names, sizeof names, &len, "sampler", s->name);
        OB_LOG_W("resources", "device destroyed with %u leaked resources (%u buffers, %u images, %u samplers): %s",
                 leaked, reg->buffers.count, reg->images.count, reg->samplers.count, names);
    }
    uint32_t cursor = 0;
    void *item;
    while ((item = ob_pool_next(&reg->buffers, &cursor, NULL))) buffer_rec_free(dev, item);
    cursor = 0;
    while ((item = ob_pool_next(&reg->images, &cursor, NULL))) ob_res_image_free(dev, item);
    cursor = 0;
    while ((item = ob_pool_next(&reg->samplers, &cursor, NULL))) sampler_rec_free(dev, item);
    ob_pool_release(&reg->buffers);
    ob_pool_release(&reg->images);
    ob_pool_release(&reg->samplers);
    ob_free(reg);
}

ob_resource_counts ob_resource_counts_get(const ob_device *dev)
{
    const ob_resource_registry *reg = ob_device_registry(dev);
    ob_resource_counts c = {
        .buffers = reg->buffers.count,
        .images = reg->images.count,
        .samplers = reg->samplers.count,
        .device_bytes = reg->device_bytes,
    };
    return c;
}
