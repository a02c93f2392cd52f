/* ob_resources_image.c — images, their views, initial uploads and layout
 * tracking for barrier generation.
 *
 * Tracking is whole-image (every layer moves together): the engine renders
 * each paraboloid half into its own layer view but transitions the map as
 * one, which is all the views need.
 */
#include "ob_resources_internal.h"

#include <stdio.h>
#include <string.h>

#define OB_IMAGE_USAGE_ALL                                                                   \
    (OB_IMAGE_SAMPLED | OB_IMAGE_COLOR_TARGET | OB_IMAGE_DEPTH_TARGET | OB_IMAGE_STORAGE |   \
     OB_IMAGE_TRANSFER_SRC | OB_IMAGE_TRANSFER_DST)

#define OB_ACCESS_WRITES                                                                     \
    (VK_ACCESS_2_SHADER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |                   \
     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | \
     VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_HOST_WRITE_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT)

/* ------------------------------------------------------------------ formats */

static VkImageAspectFlags format_aspect(VkFormat f)
{
    switch (f) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D32_SFLOAT:
        return VK_IMAGE_ASPECT_DEPTH_BIT;
    case VK_FORMAT_D16_UNORM_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
        return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    case VK_FORMAT_S8_UINT:
        return VK_IMAGE_ASPECT_STENCIL_BIT;
    default:
        return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

/* Bytes per texel (or per 4x4 block for BC formats) of formats whose data
 * the engine can upload; false for the rest. */
static bool format_block(VkFormat f, uint32_t *out_bytes, uint32_t *out_block_dim)
{
    static const struct { VkFormat first, last; uint32_t bytes; } texel[] = {
        {VK_FORMAT_R4G4_UNORM_PACK8, VK_FORMAT_R4G4_UNORM_PACK8, 1},
        {VK_FORMAT_R4G4B4A4_UNORM_PACK16, VK_FORMAT_A1R5G5B5_UNORM_PACK16, 2},
        {VK_FORMAT_R8_UNORM, VK_FORMAT_R8_SRGB, 1},
        {VK_FORMAT_R8G8_UNORM, VK_FORMAT_R8G8_SRGB, 2},
        {VK_FORMAT_R8G8B8_UNORM, VK_FORMAT_B8G8R8_SRGB, 3},
        {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_A2B10G10R10_SINT_PACK32, 4},
        {VK_FORMAT_R16_UNORM, VK_FORMAT_R16_SFLOAT, 2},
        {VK_FORMAT_R16G16_UNORM, VK_FORMAT_R16G16_SFLOAT, 4},
        {VK_FORMAT_R16G16B16_UNORM, VK_FORMAT_R16G16B16_SFLOAT, 6},
        {VK_FORMAT_R16G16B16A16_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT, 8},
        {VK_FORMAT_R32_UINT, VK_FORMAT_R32_SFLOAT, 4},
        {VK_FORMAT_R32G32_UINT, VK_FORMAT_R32G32_SFLOAT, 8},
        {VK_FORMAT_R32G32B32_UINT, VK_FORMAT_R32G32B32_SFLOAT, 12},
        {VK_FORMAT_R32G32B32A32_UINT, VK_FORMAT_R32G32B32A32_SFLOAT, 16},
        {VK_FORMAT_B10G11R11_UFLOAT_PACK32, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4},
        {VK_FORMAT_D16_UNORM, VK_FORMAT_D16_UNORM, 2},
        {VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D32_SFLOAT, 4},
    };
    static const struct { VkFormat first, last; uint32_t bytes; } block[] = {
        {VK_FORMAT_BC1_RGB_UNORM_BLOCK, VK_FORMAT_BC1_RGBA_SRGB_BLOCK, 8},
        {VK_FORMAT_BC2_UNORM_BLOCK, VK_FORMAT_BC3_SRGB_BLOCK, 16},
        {VK_FORMAT_BC4_UNORM_BLOCK, VK_FORMAT_BC4_SNORM_BLOCK, 8},
        {VK_FORMAT_BC5_UNORM_BLOCK, VK_FORMAT_BC7_SRGB_BLOCK, 16},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(texel); i++) {
        if (f >= texel[i].first && f <= texel[i].last) {
            *out_bytes = texel[i].bytes;
            *out_block_dim = 1;
            return true;
        }
    }
    for (size_t i = 0; i < OB_ARRAY_COUNT(block); i++) {
        if (f >= block[i].first && f <= block[i].last) {
            *out_bytes = block[i].bytes;
            *out_block_dim = 4;
            return true;
        }
    }
    return false;
}

static VkImageUsageFlags image_vk_usage(uint32_t usage, bool with_data)
{
    VkImageUsageFlags f = 0;
    if (usage & OB_IMAGE_SAMPLED) f |= VK_IMAGE_USAGE_SAMPLED_BIT;
    if (usage & OB_IMAGE_COLOR_TARGET) f |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    if (usage & OB_IMAGE_DEPTH_TARGET) f |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    if (usage & OB_IMAGE_STORAGE) f |= VK_IMAGE_USAGE_STORAGE_BIT;
    if (usage & OB_IMAGE_TRANSFER_SRC) f |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    if (usage & OB_IMAGE_TRANSFER_DST || with_data) f |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    return f;
}

static VkFormatFeatureFlags needed_features(VkImageUsageFlags u)
{
    VkFormatFeatureFlags f = 0;
    if (u & VK_IMAGE_USAGE_SAMPLED_BIT) f |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    if (u & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) f |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
    if (u & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) f |= VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT;
    if (u & VK_IMAGE_USAGE_STORAGE_BIT) f |= VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
    if (u & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) f |= VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    if (u & VK_IMAGE_USAGE_TRANSFER_DST_BIT) f |= VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    return f;
}

/* Checks the format against the usage on this device; the message names the
 * format number and the usage so the user can look both up. */
static ob_result image_support_check(ob_device *dev, const char *name, const ob_image_desc *desc,
                                     uint32_t layers, VkImageUsageFlags vk_usage)
{
    VkPhysicalDevice pd = ob_device_vk_physical(dev);
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(pd, desc->format, &fp);
    VkFormatFeatureFlags need = needed_features(vk_usage);
    VkFormatFeatureFlags missing = need & ~fp.optimalTilingFeatures;
    if (missing) {
        OB_LOG_E("resources", "image '%s': format %d does not support usage 0x%x (Vulkan usage 0x%x) on '%s': "
                              "missing format features 0x%x",
                 name, (int)desc->format, desc->usage, (unsigned)vk_usage, ob_device_name(dev), (unsigned)missing);
        return OB_ERR_UNSUPPORTED;
    }
    VkImageFormatProperties ip;
    VkResult vr = vkGetPhysicalDeviceImageFormatProperties(pd, desc->format, VK_IMAGE_TYPE_2D,
                                                           VK_IMAGE_TILING_OPTIMAL, vk_usage, 0, &ip);
    if (vr == VK_ERROR_FORMAT_NOT_SUPPORTED) {
        OB_LOG_E("resources", "image '%s': format %d with usage 0x%x (Vulkan usage 0x%x) is not supported on '%s'",
                 name, (int)desc->format, desc->usage, (unsigned)vk_usage, ob_device_name(dev));
        return OB_ERR_UNSUPPORTED;
    }
    if (vr < 0) return ob_result_from_vk(OB_VK_CHECK_AS(vr, "vkGetPhysicalDeviceImageFormatProperties"));
    uint32_t samples = desc->samples > 1 ? desc->samples : 1;
    if (!(ip.sampleCounts & samples)) {
        OB_LOG_E("resources", "image '%s': format %d with usage 0x%x offers no %u samples per pixel "
                              "on '%s' (sample counts 0x%x)",
                 name, (int)desc->format, desc->usage, samples, ob_device_name(dev),
                 (unsigned)ip.sampleCounts);
        return OB_ERR_UNSUPPORTED;
    }
    if (desc->width > ip.maxExtent.width || desc->height > ip.maxExtent.height || layers > ip.maxArrayLayers) {
        OB_LOG_E("resources", "image '%s': %ux%u with %u layers exceeds the limits for format %d "
                              "(%ux%u, %u layers)",
                 name, desc->width, desc->height, layers, (int)desc->format, ip.maxExtent.width,
                 ip.maxExtent.height, ip.maxArrayLayers);
        return OB_ERR_UNSUPPORTED;
    }
    return OB_OK;
}

static ob_result image_desc_check(const ob_image_desc *desc, const char *name, uint64_t *out_data_size)
{
    *out_data_size = 0;
    if (desc->width == 0 || desc->height == 0) {
        OB_LOG_E("resources", "image '%s': extent %ux%u has a zero side", name, desc->width, desc->height);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->format == VK_FORMAT_UNDEFINED) {
        OB_LOG_E("resources", "image '%s': format is VK_FORMAT_UNDEFINED", name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->usage == 0 || (desc->usage & ~(uint32_t)OB_IMAGE_USAGE_ALL)) {
        OB_LOG_E("resources", "image '%s': usage 0x%x is %s", name, desc->usage,
                 desc->usage ? "not a set of ob_image_usage bits" : "empty");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if ((desc->usage & OB_IMAGE_COLOR_TARGET) && (desc->usage & OB_IMAGE_DEPTH_TARGET)) {
        OB_LOG_E("resources", "image '%s': usage 0x%x asks for both a colour and a depth target", name, desc->usage);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->samples > 1) {
        bool pow2 = (desc->samples & (desc->samples - 1)) == 0 && desc->samples <= 64;
        uint32_t attachment_only = OB_IMAGE_COLOR_TARGET | OB_IMAGE_DEPTH_TARGET;
        if (!pow2 || (desc->usage & ~attachment_only) || desc->data || (desc->layers > 1)) {
            OB_LOG_E("resources", "image '%s': %u samples per pixel need a power of two up to 64, "
                     "one layer, no initial data and only target usage (usage 0x%x)", name,
                     desc->samples, desc->usage);
            return OB_ERR_INVALID_ARGUMENT;
        }
    }
    /* A colour target may have mips (rendered into level 0 through its
     * layer views, the rest made by ob_image_record_mips); a depth target
     * may not. */
    if (desc->mip_levels > ob_image_mip_levels_max(desc->width, desc->height) ||
        (desc->mip_levels > 1 && (desc->usage & OB_IMAGE_DEPTH_TARGET))) {
        OB_LOG_E("resources", "image '%s': %u mip levels for %ux%u%s", name, desc->mip_levels, desc->width,
                 desc->height, desc->mip_levels > 1 ? " (too many, or on a depth target)" : "");
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (!desc->data) return OB_OK;
    uint32_t bytes, dim;
    if (format_aspect(desc->format) != VK_IMAGE_ASPECT_COLOR_BIT &&
        format_aspect(desc->format) != VK_IMAGE_ASPECT_DEPTH_BIT) {
        OB_LOG_E("resources", "image '%s': initial data for format %d (stencil) is not supported", name,
                 (int)desc->format);
        return OB_ERR_UNSUPPORTED;
    }
    if (!format_block(desc->format, &bytes, &dim)) {
        OB_LOG_E("resources", "image '%s': initial data for format %d is not supported (unknown texel size)", name,
                 (int)desc->format);
        return OB_ERR_UNSUPPORTED;
    }
    uint64_t layers = desc->layers ? desc->layers : 1;
    uint32_t levels = desc->data_mips && desc->mip_levels ? desc->mip_levels : 1;
    for (uint32_t l = 0; l < levels; l++) {
        uint32_t w = OB_MAX(desc->width >> l, 1u), h = OB_MAX(desc->height >> l, 1u);
        *out_data_size += (uint64_t)((w + dim - 1) / dim) * ((h + dim - 1) / dim) * bytes * layers;
    }
    return OB_OK;
}

/* ----------------------------------------------------------- create/destroy */

void ob_res_image_free(ob_device *dev, ob_image_rec *rec)
{
    VkDevice vk = ob_device_vk(dev);
    if (rec->layer_views) {
        for (uint32_t i = 0; i < rec->info.layers; i++)
            if (rec->layer_views[i]) vkDestroyImageView(vk, rec->layer_views[i], NULL);
        ob_free(rec->layer_views);
    }
    if (rec->view) vkDestroyImageView(vk, rec->view, NULL);
    if (rec->image) vkDestroyImage(vk, rec->image, NULL);
    if (rec->memory) vkFreeMemory(vk, rec->memory, NULL);
    ob_free(rec->name);
    ob_free(rec);
}

static void image_free_deferred(ob_device *dev, void *payload) { ob_res_image_free(dev, payload); }

static VkImageAspectFlags view_aspect(const ob_image_rec *rec)
{
    /* A sampled view may have only one aspect; attachments take both. */
    VkImageAspectFlags a = rec->info.aspect;
    if ((a & VK_IMAGE_ASPECT_DEPTH_BIT) && (rec->info.usage & OB_IMAGE_SAMPLED)) a = VK_IMAGE_ASPECT_DEPTH_BIT;
    return a;
}

static ob_result image_view_create(ob_device *dev, ob_image_rec *rec, VkImageViewType type, uint32_t first_layer,
                                   uint32_t layer_count, uint32_t levels, VkImageView *out_view)
{
    VkImageViewCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = rec->image,
        .viewType = type,
        .format = rec->info.format,
        .subresourceRange = {view_aspect(rec), 0, levels, first_layer, layer_count},
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateImageView(ob_device_vk(dev), &info, NULL, out_view));
    if (vr < 0) {
        *out_view = VK_NULL_HANDLE;
        ob_device_note_result(dev, vr);
        OB_LOG_E("resources", "image '%s': cannot create the view of layers %u..%u", rec->name, first_layer,
                 first_layer + layer_count - 1);
        return ob_result_from_vk(vr);
    }
    char suffix[32] = " (view)";
    if (layer_count == 1 && rec->info.layers > 1) snprintf(suffix, sizeof suffix, " (layer %u)", first_layer);
    ob_res_set_name(dev, VK_OBJECT_TYPE_IMAGE_VIEW, (uint64_t)(uintptr_t)*out_view, rec->name, suffix);
    return OB_OK;
}

static ob_result image_views_create(ob_device *dev, ob_image_rec *rec)
{
    uint32_t layers = rec->info.layers;
    bool array = layers > 1 || rec->array;
    ob_result r = image_view_create(dev, rec, array ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D, 0,
                                    layers, rec->info.mip_levels, &rec->view);
    /* Layer views are attachments: level 0 only. A single-layer target with
     * mips needs one too, since its whole view covers every level. */
    bool mipped_target = rec->info.mip_levels > 1 && (rec->info.usage & OB_IMAGE_COLOR_TARGET);
    if (r != OB_OK || (layers == 1 && !mipped_target && !rec->array)) return r;
    rec->layer_views = ob_calloc(layers, sizeof *rec->layer_views);
    if (!rec->layer_views) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < layers && r == OB_OK; i++)
        r = image_view_create(dev, rec, VK_IMAGE_VIEW_TYPE_2D, i, 1, 1, &rec->layer_views[i]);
    return r;
}

/* Staging upload of every layer, leaving the image shader-readable. */
static ob_result image_upload(ob_device *dev, ob_image_rec *rec, const void *data, uint64_t size, bool data_mips)
{
    ob_staging staging;
    ob_result r = ob_staging_create(dev, size, rec->name, &staging);
    if (r != OB_OK) return r;
    memcpy(staging.mapped, data, (size_t)size);
    VkCommandBuffer cmd;
    r = ob_device_oneshot_begin(dev, &cmd);
    if (r != OB_OK) goto done;
    ob_image_state saved = rec->state;
    VkImageMemoryBarrier2 barrier;
    /* Blits write the levels below 0 after this transition: make it wait for them too. */
    ob_image_state to_copy = {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                              rec->info.mip_levels > 1 ? VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT
                                                       : VK_PIPELINE_STAGE_2_COPY_BIT,
                              VK_ACCESS_2_TRANSFER_WRITE_BIT};
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .imageMemoryBarrierCount = 1,
        .pImageMemoryBarriers = &barrier,
    };
    if (ob_res_image_transition(rec, &to_copy, &barrier)) vkCmdPipelineBarrier2(cmd, &dep);
    if (data_mips) {
        uint32_t bytes = 4, dim = 1;
        format_block(rec->info.format, &bytes, &dim);   /* known: image_desc_check passed */
        ob_res_image_copy_levels(cmd, staging.buffer, rec, bytes, dim);
    } else {
        VkBufferImageCopy region = {
            .imageSubresource = {rec->info.aspect, 0, 0, rec->info.layers},
            .imageExtent = {rec->info.width, rec->info.height, 1},
        };
        vkCmdCopyBufferToImage(cmd, staging.buffer, rec->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        if (rec->info.mip_levels > 1) ob_res_image_blit_mips(cmd, rec, VK_PIPELINE_STAGE_2_COPY_BIT);
    }
    /* Any shader stage may sample it next; ALL_COMMANDS keeps that true for
     * compute and vertex fetches as well as fragment shaders. */
    ob_image_state readable = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                               VK_ACCESS_2_SHADER_READ_BIT};
    if (ob_res_image_transition(rec, &readable, &barrier)) vkCmdPipelineBarrier2(cmd, &dep);
    r = ob_device_oneshot_submit(dev, cmd);
    if (r != OB_OK) {
        rec->state = saved;
        OB_LOG_E("resources", "image '%s': upload of %llu bytes failed: %s", rec->name, (unsigned long long)size,
                 ob_result_name(r));
    }
done:
    ob_staging_destroy(dev, &staging);
    return r;
}

ob_image ob_image_create(ob_device *dev, const ob_image_desc *desc, ob_result *out_result)
{
    ob_image handle = {0};
    ob_result r;
    const char *name = desc && desc->name ? desc->name : "(unnamed)";
    uint64_t data_size = 0;
    if (!desc) {
        OB_LOG_E("resources", "ob_image_create: desc is NULL");
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    if (ob_device_is_lost(dev)) {
        r = OB_ERR_DEVICE_LOST;
        goto fail_log;
    }
    r = image_desc_check(desc, name, &data_size);
    if (r != OB_OK) goto fail_log;
    uint32_t layers = desc->layers ? desc->layers : 1;
    uint32_t levels = desc->mip_levels ? desc->mip_levels : 1;
    bool blit_mips = desc->data && levels > 1 && !desc->data_mips;
    VkImageUsageFlags vk_usage = image_vk_usage(desc->usage, desc->data != NULL);
    if (blit_mips) vk_usage |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    r = image_support_check(dev, name, desc, layers, vk_usage);
    if (r == OB_OK && blit_mips) r = ob_res_mips_blit_check(dev, name, desc->format);
    if (r != OB_OK) goto fail_log;

    VkDevice vk = ob_device_vk(dev);
    ob_image_rec *rec = ob_calloc(1, sizeof *rec);
    if (!rec) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    rec->info = (ob_image_info){desc->width, desc->height, layers, desc->format, desc->usage,
                                format_aspect(desc->format), levels, desc->samples > 1 ? desc->samples : 1};
    rec->state = (ob_image_state){VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
    rec->array = desc->array;
    rec->name = ob_strdup(name);
    if (!rec->name) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_free_rec;
    }
    VkImageCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = desc->format,
        .extent = {desc->width, desc->height, 1},
        .mipLevels = levels,
        .arrayLayers = layers,
        .samples = (VkSampleCountFlagBits)rec->info.samples,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = vk_usage,
        .sharingMode = VK_SHARING_MODE_EXCLUSIVE,
        .initialLayout = VK_IMAGE_LAYOUT_UNDEFINED,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateImage(vk, &info, NULL, &rec->image));
    if (vr < 0) {
        rec->image = VK_NULL_HANDLE;
        ob_device_note_result(dev, vr);
        r = ob_result_from_vk(vr);
        goto fail_free_rec;
    }
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(vk, rec->image, &req);
    r = ob_res_memory_alloc(dev, &req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "image", name, &rec->memory);
    if (r != OB_OK) goto fail_free_rec;
    rec->mem_size = req.size;
    vr = OB_VK_CHECK(vkBindImageMemory(vk, rec->image, rec->memory, 0));
    if (vr < 0) {
        ob_device_note_result(dev, vr);
        r = ob_result_from_vk(vr);
        goto fail_free_rec;
    }
    ob_res_set_name(dev, VK_OBJECT_TYPE_IMAGE, (uint64_t)(uintptr_t)rec->image, name, NULL);
    ob_res_set_name(dev, VK_OBJECT_TYPE_DEVICE_MEMORY, (uint64_t)(uintptr_t)rec->memory, name, " (memory)");
    r = image_views_create(dev, rec);
    if (r != OB_OK) goto fail_free_rec;
    if (desc->data) {
        r = image_upload(dev, rec, desc->data, data_size, desc->data_mips);
        if (r != OB_OK) goto fail_free_rec;
    }
    handle.id = ob_res_register(dev, &ob_device_registry(dev)->images, rec, rec->mem_size, &r);
    if (!handle.id) goto fail_free_rec;
    if (out_result) *out_result = OB_OK;
    return handle;

fail_free_rec:
    ob_res_image_free(dev, rec);
fail_log:
    OB_LOG_E("resources", "image '%s' not created: %s", name, ob_result_name(r));
    if (out_result) *out_result = r;
    return handle;
}

void ob_image_destroy(ob_device *dev, ob_image img)
{
    if (!img.id) return;
    ob_resource_registry *reg = ob_device_registry(dev);
    ob_image_rec *rec = ob_res_retire(&reg->images, img.id, "ob_image_destroy", "image");
    if (!rec) return;
    reg->device_bytes -= rec->mem_size;
    ob_device_defer(dev, image_free_deferred, rec);
}

/* ---------------------------------------------------------------- accessors */

ob_image_rec *ob_res_image_get(const ob_device *dev, ob_image img, const char *caller)
{
    ob_image_rec *rec = ob_pool_get(&ob_device_registry(dev)->images, img.id);
    if (!rec)
        OB_LOG_E("resources", "%s: %s image handle 0x%08x", caller, img.id ? "invalid or stale" : "null", img.id);
    return rec;
}

bool ob_image_is_valid(const ob_device *dev, ob_image img)
{
    return ob_pool_get(&ob_device_registry(dev)->images, img.id) != NULL;
}

VkImage ob_image_vk(const ob_device *dev, ob_image img)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_vk");
    return rec ? rec->image : VK_NULL_HANDLE;
}

VkImageView ob_image_view(const ob_device *dev, ob_image img)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_view");
    return rec ? rec->view : VK_NULL_HANDLE;
}

VkImageView ob_image_layer_view(const ob_device *dev, ob_image img, uint32_t layer)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_layer_view");
    if (!rec) return VK_NULL_HANDLE;
    if (layer >= rec->info.layers) {
        OB_LOG_E("resources", "image '%s': layer %u out of range (%u layers)", rec->name, layer, rec->info.layers);
        return VK_NULL_HANDLE;
    }
    return rec->layer_views ? rec->layer_views[layer] : rec->view;
}

ob_result ob_image_get_info(const ob_device *dev, ob_image img, ob_image_info *out_info)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_get_info");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    *out_info = rec->info;
    return OB_OK;
}

ob_result ob_image_get_state(const ob_device *dev, ob_image img, ob_image_state *out_state)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_get_state");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    *out_state = rec->state;
    return OB_OK;
}

/* --------------------------------------------------------- layout tracking */

static bool access_is_read_only(VkAccessFlags2 a) { return (a & OB_ACCESS_WRITES) == 0; }

static VkAccessFlags2 expand_reads(VkAccessFlags2 a)
{
    if (a & VK_ACCESS_2_SHADER_READ_BIT)
        a |= VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
    return a;
}

/* A read-only state `cur` serves a read `next` in the same layout when its
 * (already made visible) stages and accesses include next's. */
static bool read_state_covers(const ob_image_state *cur, const ob_image_state *next)
{
    bool stages = (cur->stages & VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT) || (next->stages & ~cur->stages) == 0;
    bool access = (cur->access & VK_ACCESS_2_MEMORY_READ_BIT) ||
                  (expand_reads(next->access) & ~expand_reads(cur->access)) == 0;
    return stages && access;
}

bool ob_res_image_transition(ob_image_rec *rec, const ob_image_state *next, VkImageMemoryBarrier2 *out_barrier)
{
    const ob_image_state cur = rec->state;
    bool read_to_read = cur.layout == next->layout && access_is_read_only(cur.access) &&
                        access_is_read_only(next->access);
    if (read_to_read && read_state_covers(&cur, next)) return false;
    *out_barrier = (VkImageMemoryBarrier2){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = cur.stages,
        .srcAccessMask = cur.access,
        .dstStageMask = next->stages,
        .dstAccessMask = next->access,
        .oldLayout = cur.layout,
        .newLayout = next->layout,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = rec->image,
        .subresourceRange = {rec->info.aspect, 0, VK_REMAINING_MIP_LEVELS, 0, rec->info.layers},
    };
    if (read_to_read) {
        /* Keep every reader in the state, so the next write waits for all. */
        rec->state.stages |= next->stages;
        rec->state.access |= next->access;
    } else {
        rec->state = *next;
    }
    return true;
}

bool ob_image_transition(ob_device *dev, ob_image img, const ob_image_state *next,
                         VkImageMemoryBarrier2 *out_barrier)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_transition");
    if (!rec) return false;
    if (!next || !out_barrier || next->layout == VK_IMAGE_LAYOUT_UNDEFINED ||
        next->layout == VK_IMAGE_LAYOUT_PREINITIALIZED) {
        OB_LOG_E("resources", "image '%s': transition needs a barrier to fill and a target layout that is not "
                              "UNDEFINED/PREINITIALIZED", rec->name);
        return false;
    }
    return ob_res_image_transition(rec, next, out_barrier);
}

ob_result ob_image_set_state(ob_device *dev, ob_image img, const ob_image_state *state)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_set_state");
    if (!rec) return OB_ERR_INVALID_HANDLE;
    if (!state) {
        OB_LOG_E("resources", "image '%s': ob_image_set_state without a state", rec->name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    rec->state = *state;
    return OB_OK;
}
