/* ob_readback.c — copying buffers and images back to the host, and PNGs.
 *
 * Read-backs are for tests, screenshots and headless output, not the frame
 * loop: each one waits for the device to be idle, so the caller need not
 * know which frame last touched the resource, and then copies in a one-shot
 * that ends with a barrier to the host.
 */
#include "ob_resources_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

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

/* PNG: 8-bit RGBA, each row filtered as stb_image_write does (the filter
 * with the smallest sum of absolute residuals), deflated by zlib, chunks
 * checked with zlib's CRC-32. Every failure frees what it made and returns
 * NULL (stbi_write_png_to_mem crashed on a failed realloc, then leaked on a
 * failed malloc: issue 25.10). */
static uint8_t paeth(int a, int b, int c)
{
    int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return (uint8_t)(pa <= pb && pa <= pc ? a : pb <= pc ? b : c);
}

static void png_filter_row(const uint8_t *row, const uint8_t *above, uint32_t bytes, int type, uint8_t *out)
{
    for (uint32_t i = 0; i < bytes; i++) {
        int a = i >= 4 ? row[i - 4] : 0, b = above ? above[i] : 0, c = above && i >= 4 ? above[i - 4] : 0;
        int pred = type == 1 ? a : type == 2 ? b : type == 3 ? (a + b) / 2 : type == 4 ? paeth(a, b, c) : 0;
        out[i] = (uint8_t)(row[i] - pred);
    }
}

static uint8_t *png_put32(uint8_t *o, uint32_t v)
{
    o[0] = (uint8_t)(v >> 24);
    o[1] = (uint8_t)(v >> 16);
    o[2] = (uint8_t)(v >> 8);
    o[3] = (uint8_t)v;
    return o + 4;
}

static uint8_t *png_chunk(uint8_t *o, const char tag[4], const uint8_t *data, uint32_t len)
{
    o = png_put32(o, len);
    uint8_t *start = o;
    memcpy(o, tag, 4);
    if (len) memcpy(o + 4, data, len);
    o += 4 + len;
    return png_put32(o, (uint32_t)crc32(crc32(0L, Z_NULL, 0), start, 4 + len));
}

static uint8_t *png_encode(const uint8_t *rgba, uint32_t w, uint32_t h, size_t *out_size)
{
    const uint32_t row_bytes = w * 4;
    uint8_t *filtered = ob_malloc((size_t)(row_bytes + 1) * h);
    uint8_t *trial = ob_malloc(row_bytes);
    uint8_t *z = NULL, *png = NULL;
    size_t zlen = 0;
    if (!filtered || !trial) goto done;
    for (uint32_t y = 0; y < h; y++) {
        const uint8_t *row = rgba + (size_t)y * row_bytes, *above = y ? row - row_bytes : NULL;
        uint8_t *dst = filtered + (size_t)y * (row_bytes + 1);
        uint64_t best = UINT64_MAX;
        for (int type = 0; type < 5; type++) {
            png_filter_row(row, above, row_bytes, type, trial);
            uint64_t cost = 0;
            for (uint32_t i = 0; i < row_bytes; i++) cost += (uint64_t)abs((int8_t)trial[i]);
            if (cost < best) {
                best = cost;
                dst[0] = (uint8_t)type;
                memcpy(dst + 1, trial, row_bytes);
            }
        }
    }
    z = ob_res_deflate(filtered, (size_t)(row_bytes + 1) * h, 8, &zlen);
    if (!z || zlen > UINT32_MAX - 64) goto done;
    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    uint8_t ihdr[13];
    png_put32(png_put32(ihdr, w), h);
    ihdr[8] = 8;    /* bits per channel */
    ihdr[9] = 6;    /* RGBA */
    ihdr[10] = ihdr[11] = ihdr[12] = 0;
    *out_size = 8 + (12 + 13) + (12 + zlen) + 12;
    png = ob_malloc(*out_size);
    if (!png) goto done;
    memcpy(png, signature, 8);
    uint8_t *o = png_chunk(png + 8, "IHDR", ihdr, 13);
    o = png_chunk(o, "IDAT", z, (uint32_t)zlen);
    png_chunk(o, "IEND", NULL, 0);
done:
    ob_free(z);
    ob_free(trial);
    ob_free(filtered);
    return png;
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
    size_t size = 0;
    uint8_t *png = png_encode(pixels, w, h, &size);
    if (!png) {
        OB_LOG_E("resources", "image '%s': PNG encoding for '%s' failed (out of host memory)", rec->name, path);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
    } else {
        r = ob_file_write(path, png, size);
    }
    ob_free(png);
done:
    ob_free(pixels);
    return r;
}
