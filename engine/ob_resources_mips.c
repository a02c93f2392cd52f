/* ob_resources_mips.c — mip chains of uploaded images: generated on the
 * device with linear blits, or copied level by level when the caller made
 * them (ob_image_desc.data_mips).
 *
 * Barriers of the blit chain, per level i ≥ 1 (all levels start in
 * TRANSFER_DST_OPTIMAL after a transition that waited for ALL_TRANSFER):
 *   level i-1: DST → SRC, its write (copy for 0, blit for the others) made
 *              visible to the blit's read;
 *   blit i-1 → i (level i stays DST and is written).
 * The last level then goes DST → SRC too, so the whole image is in one
 * layout again and the tracked whole-image state can describe it: the
 * caller's next transition (to SHADER_READ_ONLY) waits for the blits.
 */
#include "ob_resources_internal.h"

uint32_t ob_image_mip_levels_max(uint32_t width, uint32_t height)
{
    uint32_t m = OB_MAX(width, height), levels = 1;
    while (m > 1) {
        m >>= 1;
        levels++;
    }
    return levels;
}

static const VkFormatFeatureFlags linear_blit_features =
    VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;

static VkFormatFeatureFlags missing_blit_features(const ob_device *dev, VkFormat format)
{
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(ob_device_vk_physical(dev), format, &fp);
    return linear_blit_features & ~fp.optimalTilingFeatures;
}

bool ob_image_format_blits_linear(const ob_device *dev, VkFormat format)
{
    return missing_blit_features(dev, format) == 0;
}

ob_result ob_res_mips_blit_check(ob_device *dev, const char *name, VkFormat format)
{
    VkFormatFeatureFlags missing = missing_blit_features(dev, format);
    if (!missing) return OB_OK;
    OB_LOG_E("resources", "image '%s': format %d cannot be blitted with linear filtering on '%s' "
                          "(features 0x%x missing): its mip levels cannot be made on the device",
             name, (int)format, ob_device_name(dev), (unsigned)missing);
    return OB_ERR_UNSUPPORTED;
}

static VkImageMemoryBarrier2 level_to_src(const ob_image_rec *rec, uint32_t level, VkPipelineStageFlags2 written_by)
{
    return (VkImageMemoryBarrier2){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = written_by,
        .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
        .dstStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT,
        .dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT,
        .oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
        .newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = rec->image,
        .subresourceRange = {rec->info.aspect, level, 1, 0, rec->info.layers},
    };
}

void ob_res_image_blit_mips(VkCommandBuffer cmd, ob_image_rec *rec, VkPipelineStageFlags2 level0_written_by)
{
    const uint32_t levels = rec->info.mip_levels;
    VkImageMemoryBarrier2 barrier;
    VkDependencyInfo dep = {
        .sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
        .imageMemoryBarrierCount = 1,
        .pImageMemoryBarriers = &barrier,
    };
    for (uint32_t i = 1; i < levels; i++) {
        barrier = level_to_src(rec, i - 1, i == 1 ? level0_written_by : VK_PIPELINE_STAGE_2_BLIT_BIT);
        vkCmdPipelineBarrier2(cmd, &dep);
        int32_t sw = (int32_t)OB_MAX(rec->info.width >> (i - 1), 1u);
        int32_t sh = (int32_t)OB_MAX(rec->info.height >> (i - 1), 1u);
        int32_t dw = (int32_t)OB_MAX(rec->info.width >> i, 1u);
        int32_t dh = (int32_t)OB_MAX(rec->info.height >> i, 1u);
        VkImageBlit2 region = {
            .sType = VK_STRUCTURE_TYPE_IMAGE_BLIT_2,
            .srcSubresource = {rec->info.aspect, i - 1, 0, rec->info.layers},
            .srcOffsets = {{0, 0, 0}, {sw, sh, 1}},
            .dstSubresource = {rec->info.aspect, i, 0, rec->info.layers},
            .dstOffsets = {{0, 0, 0}, {dw, dh, 1}},
        };
        VkBlitImageInfo2 blit = {
            .sType = VK_STRUCTURE_TYPE_BLIT_IMAGE_INFO_2,
            .srcImage = rec->image,
            .srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
            .dstImage = rec->image,
            .dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
            .regionCount = 1,
            .pRegions = &region,
            .filter = VK_FILTER_LINEAR,
        };
        vkCmdBlitImage2(cmd, &blit);
    }
    barrier = level_to_src(rec, levels - 1, levels == 1 ? level0_written_by : VK_PIPELINE_STAGE_2_BLIT_BIT);
    vkCmdPipelineBarrier2(cmd, &dep);
    /* Reads by the blits are what the next layout change must wait for; the
     * writes were made available by the barriers above. */
    rec->state = (ob_image_state){VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                                  VK_ACCESS_2_TRANSFER_READ_BIT};
}

bool ob_image_record_mips(ob_device *dev, VkCommandBuffer cmd, ob_image img)
{
    ob_image_rec *rec = ob_res_image_get(dev, img, "ob_image_record_mips");
    if (!rec || rec->info.mip_levels < 2) return false;
    /* Every level to TRANSFER_DST, level 0's contents kept (its last writer,
     * the rendering, is waited for); the blits' barriers chain from BLIT. */
    ob_image_state to_dst = {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_BLIT_BIT,
                             VK_ACCESS_2_TRANSFER_WRITE_BIT};
    VkImageMemoryBarrier2 barrier;
    if (ob_res_image_transition(rec, &to_dst, &barrier)) {
        VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                                .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &barrier};
        vkCmdPipelineBarrier2(cmd, &dep);
    }
    ob_res_image_blit_mips(cmd, rec, VK_PIPELINE_STAGE_2_BLIT_BIT);
    return true;
}

void ob_res_image_copy_levels(VkCommandBuffer cmd, VkBuffer staging, const ob_image_rec *rec, uint32_t block_bytes,
                              uint32_t block_dim)
{
    VkDeviceSize offset = 0;
    for (uint32_t l = 0; l < rec->info.mip_levels; l++) {
        uint32_t w = OB_MAX(rec->info.width >> l, 1u), h = OB_MAX(rec->info.height >> l, 1u);
        VkBufferImageCopy region = {
            .bufferOffset = offset,
            .imageSubresource = {rec->info.aspect, l, 0, rec->info.layers},
            .imageExtent = {w, h, 1},
        };
        vkCmdCopyBufferToImage(cmd, staging, rec->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
        offset += (VkDeviceSize)((w + block_dim - 1) / block_dim) * ((h + block_dim - 1) / block_dim) * block_bytes *
                  rec->info.layers;
    }
}
