/* ob_readback.c — copying buffers and images back to the host, and PNGs.
 *
 * Read-backs are for tests, screenshots and headless output, not the frame
 * loop: each one waits for the device to be idle, so the caller need not
 * know which frame last touched the resource, and then copies in a one-shot
 * that ends with a barrier to the host.
 */
#include "ob_resources_internal.h"

#include <stb_image_write.h>
#include <math.h>
#include <string.h>

static const VkMemoryBarrier2 to_host = {
    .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
    .srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
    .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT,
    .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT,
    .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT,
};

static void record_memory_barrier(VkCommandBuffer cmd, const VkMemoryBarrier2 *barrier)
{
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .memoryBarrierCount = 1,
        .pMemoryBarriers = barrier,
    };
    vkCmdPipelineBarrier2(cmd, &dep);
}

/* Staging of staging_size bytes (none for 0), an idle device and a begun
 * one-shot; on failure nothing is left behind. */
static ob_result readback_begin(ob_device *dev, uint64_t staging_size, const char *name, ob_staging *out_staging,
                                VkCommandBuffer *out_cmd)
{
    memset(out_staging, 0, sizeof *out_staging);
    ob_result r = staging_size ? ob_staging_create(dev, staging_size, name, out_staging) : OB_OK;
    if (r == OB_OK) r = ob_device_wait_idle(dev);
    if (r == OB_OK) r = ob_device_oneshot_begin(dev, out_cmd);
    if (r != OB_OK) ob_staging_destroy(dev, out_staging);
    return r;
}

/* ------------------------------------------------------------------ buffers */

ob_result ob_buffer_read(ob_device *dev, ob_buffer buf, uint64_t offset, uint64_t size, void *out)
{
    ob_buffer_rec *rec = ob_res_buffer_get(dev, buf, "ob_buffer_read");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    if (ob_device_is_lost(dev)) return OB_ERR_DEVICE_LOST;
    if (size == 0) return OB_OK;
    if (!out) {
        OB_LOG_E("resources", "buffer '%s': read of %llu bytes into NULL", rec->name, (unsigned long long)size);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (offset > rec->size || size > rec->size - offset) {
        OB_LOG_E("resources", "buffer '%s': read of %llu bytes at offset %llu exceeds its size %llu", rec->name,
                 (unsigned long long)size, (unsigned long long)offset, (unsigned long long)rec->size);
        return OB_ERR_OUT_OF_RANGE;
    }
    ob_staging staging;
    VkCommandBuffer cmd;
    ob_result r = readback_begin(dev, rec->host_visible ? 0 : size, rec->name, &staging, &cmd);
    if (r != OB_OK) goto fail_log;
    if (!rec->host_visible) {
        VkMemoryBarrier2 to_copy = {
            .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
            .srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
            .srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT,
            .dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
            .dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT,
        };
        record_memory_barrier(cmd, &to_copy);
        VkBufferCopy region = {.srcOffset = offset, .dstOffset = 0, .size = size};
        vkCmdCopyBuffer(cmd, rec->buffer, staging.buffer, 1, &region);
    }
    record_memory_barrier(cmd, &to_host);
    r = ob_device_oneshot_submit(dev, cmd);
    if (r == OB_OK)
        memcpy(out, rec->host_visible ? (const char *)rec->mapped + offset : staging.mapped, (size_t)size);
    ob_staging_destroy(dev, &staging);
    if (r == OB_OK) return OB_OK;
fail_log:
    OB_LOG_E("resources", "buffer '%s': read-back failed: %s", rec->name, ob_result_name(r));
    return r;
}

/* ------------------------------------------------------------------- images */

static bool rgba8_format(VkFormat f, bool *out_bgra)
{
    *out_bgra = f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB;
    return *out_bgra || f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB ||
           f == VK_FORMAT_R8G8B8A8_UINT || f == VK_FORMAT_R16G16B16A16_SFLOAT;
}

/* IEEE half to float (normals, subnormals, infinities, NaN). */
static float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h >> 15) << 31, exp = (h >> 10) & 0x1fu, mant = h & 0x3ffu;
    float f;
    if (exp == 0) {
        f = ldexpf((float)mant, -24);
    } else if (exp == 31) {
        f = mant ? NAN : INFINITY;
    } else {
        f = ldexpf((float)(mant | 0x400u), (int)exp - 25);
    }
    return sign ? -f : f;
}

/* A linear half-float value as an 8-bit UNORM byte: clamped, rounded, not
 * encoded (what a blit to R8G8B8A8_UNORM would write). */
static uint8_t half_to_unorm8(uint16_t h)
{
    float f = half_to_float(h);
    if (!(f > 0.0f)) return 0;   /* also NaN */
    if (f >= 1.0f) return 255;
    return (uint8_t)(f * 255.0f + 0.5f);
}

static ob_result image_read_check(const ob_image_rec *rec, uint32_t layer, const uint8_t *out, bool *out_bgra)
{
    if (!out) {
        OB_LOG_E("resources", "image '%s': read-back into NULL", rec->name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (!rgba8_format(rec->info.format, out_bgra)) {
        OB_LOG_E("resources", "image '%s': read-back to RGBA8 needs an R8G8B8A8, B8G8R8A8 or R16G16B16A16_SFLOAT format, not format %d",
                 rec->name, (int)rec->info.format);
        return OB_ERR_UNSUPPORTED;
    }
    if (!(rec->info.usage & OB_IMAGE_TRANSFER_SRC)) {
        OB_LOG_E("resources", "image '%s': read-back needs OB_IMAGE_TRANSFER_SRC usage (usage is 0x%x)", rec->name,
                 rec->info.usage);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (layer >= rec->info.layers) {
        OB_LOG_E("resources", "image '%s': read-back of layer %u, but it has %u", rec->name, layer,
                 rec->info.layers);
        return OB_ERR_OUT_OF_RANGE;
    }
    if (rec->state.layout == VK_IMAGE_LAYOUT_UNDEFINED) {
        OB_LOG_E("resources", "image '%s': read-back before anything was written (layout UNDEFINED)", rec->name);
        return OB_ERR_WRONG_STATE;
    }
    return OB_OK;
}

/* Records: tracked state → TRANSFER_SRC, copy of `layer`, back to the
 * tracked state, host barrier on the staging buffer. */
static void record_image_copy(VkCommandBuffer cmd, ob_image_rec *rec, uint32_t layer, VkBuffer dst)
{
    VkImageMemoryBarrier2 barrier;
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .imageMemoryBarrierCount = 1,
        .pImageMemoryBarriers = &barrier,
    };
    ob_image_state restore = rec->state;
    /* A state with no stages would break the barrier chain to later work. */
    if (restore.stages == VK_PIPELINE_STAGE_2_NONE) restore.stages = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    ob_image_state to_copy = {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                              VK_ACCESS_2_TRANSFER_READ_BIT};
    if (ob_res_image_transition(rec, &to_copy, &barrier)) vkCmdPipelineBarrier2(cmd, &dep);
    VkBufferImageCopy region = {
        .imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1},
        .imageExtent = {rec->info.width, rec->info.height, 1},
    };
    vkCmdCopyImageToBuffer(cmd, rec->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst, 1, &region);
    bool back = ob_res_image_transition(rec, &restore, &barrier);
    dep.imageMemoryBarrierCount = back ? 1u : 0u;
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &to_host;
    vkCmdPipelineBarrier2(cmd, &dep);
}

ob_result ob_image_read_layer_rgba8(ob_device *dev, ob_image img, uint32_t layer, uint8_t *out)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_read_rgba8");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    if (ob_device_is_lost(dev)) return OB_ERR_DEVICE_LOST;
    bool bgra;
    ob_result r = image_read_check(rec, layer, out, &bgra);
    if (r != OB_OK) return r;
    size_t pixels = (size_t)rec->info.width * rec->info.height;
    bool half = rec->info.format == VK_FORMAT_R16G16B16A16_SFLOAT;
    ob_staging staging;
    VkCommandBuffer cmd;
    r = readback_begin(dev, pixels * (half ? 8 : 4), rec->name, &staging, &cmd);
    if (r != OB_OK) goto fail_log;
    ob_image_state saved = rec->state;
    record_image_copy(cmd, rec, layer, staging.buffer);
    r = ob_device_oneshot_submit(dev, cmd);
    if (r != OB_OK) {
        rec->state = saved;
        goto done;
    }
    const uint8_t *src = staging.mapped;
    if (half) {
        for (size_t i = 0; i < pixels * 4; i++) {
            uint16_t h;
            memcpy(&h, src + 2 * i, sizeof h);
            out[i] = half_to_unorm8(h);
        }
    } else if (!bgra) {
        memcpy(out, src, pixels * 4);
    } else {
        for (size_t i = 0; i < pixels; i++) {
            out[4 * i + 0] = src[4 * i + 2];
            out[4 * i + 1] = src[4 * i + 1];
            out[4 * i + 2] = src[4 * i + 0];
            out[4 * i + 3] = src[4 * i + 3];
        }
    }
done:
    ob_staging_destroy(dev, &staging);
    if (r == OB_OK) return OB_OK;
fail_log:
    OB_LOG_E("resources", "image '%s': read-back failed: %s", rec->name, ob_result_name(r));
    return r;
}

ob_result ob_image_read_rgba8(ob_device *dev, ob_image img, uint8_t *out)
{
    return ob_image_read_layer_rgba8(dev, img, 0, out);
}

/* ---------------------------------------------------------------------- PNG */

typedef struct png_sink {
    unsigned char *data;
    size_t size;
    bool failed;
} png_sink;

/* stb calls this once with the whole encoded file. */
static void png_collect(void *context, void *data, int size)
{
    png_sink *sink = context;
    if (sink->failed || size <= 0) return;
    unsigned char *grown = ob_realloc(sink->data, sink->size + (size_t)size);
    if (!grown) {
        sink->failed = true;
        return;
    }
    memcpy(grown + sink->size, data, (size_t)size);
    sink->data = grown;
    sink->size += (size_t)size;
}

ob_result ob_image_write_png(ob_device *dev, ob_image img, const char *path)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_write_png");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    if (!path || !path[0]) {
        OB_LOG_E("resources", "image '%s': PNG path is empty", rec->name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    uint32_t w = rec->info.width, h = rec->info.height;
    if (w > INT32_MAX / 4 || h > INT32_MAX / 4) {
        OB_LOG_E("resources", "image '%s': %ux%u is too large for a PNG", rec->name, w, h);
        return OB_ERR_LIMIT;
    }
    uint8_t *pixels = ob_malloc((size_t)w * h * 4);
    if (!pixels) {
        OB_LOG_E("resources", "image '%s': out of host memory for the PNG of %ux%u", rec->name, w, h);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    ob_result r = ob_image_read_rgba8(dev, img, pixels);
    if (r != OB_OK) goto done;
    png_sink sink = {0};
    if (!stbi_write_png_to_func(png_collect, &sink, (int)w, (int)h, 4, pixels, (int)(w * 4)) || sink.failed) {
        OB_LOG_E("resources", "image '%s': PNG encoding for '%s' failed (out of host memory)", rec->name, path);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
    } else {
        r = ob_file_write(path, sink.data, sink.size);
    }
    ob_free(sink.data);
done:
    ob_free(pixels);
    return r;
}
