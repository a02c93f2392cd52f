/* Buffers, images and samplers: handles, argument checks, uploads and
 * read-backs, clears, array layers, PNG, depth, compare samplers, layout
 * tracking, deferred destruction, leaks and allocation faults. Every test
 * ends with zero validation messages on the shared device. */
#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"
#include "ob_resources.h"

#include <stb_image.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int group_setup(void **state)
{
    *state = ob_test_device_create();
    return 0;
}

static int group_teardown(void **state)
{
    ob_device_destroy(*state);
    return 0;
}

static void pattern(uint8_t *out, size_t n, uint32_t seed)
{
    for (size_t i = 0; i < n; i++) out[i] = (uint8_t)((i * 131u + seed * 7u) ^ (i >> 8));
}

/* ------------------------------------------------------------------ helpers */

static const ob_image_state color_target_state = {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                                  VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                                  VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT};

static void transition(ob_device *dev, VkCommandBuffer cmd, ob_image img, const ob_image_state *next)
{
    VkImageMemoryBarrier2 barrier;
    if (!ob_image_transition(dev, img, next, &barrier)) return;
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1,
                            .pImageMemoryBarriers = &barrier};
    vkCmdPipelineBarrier2(cmd, &dep);
}

/* Clears `view` by an empty dynamic-rendering pass with LOAD_OP_CLEAR. */
static void record_clear(VkCommandBuffer cmd, VkImageView view, uint32_t w, uint32_t h, const float rgba[4])
{
    VkRenderingAttachmentInfo color = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = view,
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.color.float32 = {rgba[0], rgba[1], rgba[2], rgba[3]},
    };
    VkRenderingInfo info = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .renderArea = {{0, 0}, {w, h}},
        .layerCount = 1,
        .colorAttachmentCount = 1,
        .pColorAttachments = &color,
    };
    vkCmdBeginRendering(cmd, &info);
    vkCmdEndRendering(cmd);
}

static void assert_all_pixels(const uint8_t *px, uint32_t count, const uint8_t expect[4])
{
    for (uint32_t i = 0; i < count; i++) {
        if (memcmp(px + 4 * i, expect, 4) != 0)
            fail_msg("pixel %u is %u,%u,%u,%u, expected %u,%u,%u,%u", i, px[4 * i], px[4 * i + 1], px[4 * i + 2],
                     px[4 * i + 3], expect[0], expect[1], expect[2], expect[3]);
    }
}

/* -------------------------------------------------------------------- tests */

static void stale_handles_are_rejected_everywhere(void **state)
{
    ob_device *dev = *state;
    ob_resource_counts before = ob_resource_counts_get(dev);
    ob_result r;
    ob_buffer a = ob_buffer_create(dev, &(ob_buffer_desc){.size = 64, .usage = OB_BUFFER_UNIFORM, .host_visible = true, .name = "gen-a"}, &r);
    assert_int_equal(r, OB_OK);
    assert_true(ob_buffer_is_valid(dev, a));
    ob_buffer_destroy(dev, a);
    assert_false(ob_buffer_is_valid(dev, a));   /* invalid at once, though freeing is deferred */
    ob_buffer b = ob_buffer_create(dev, &(ob_buffer_desc){.size = 64, .usage = OB_BUFFER_UNIFORM, .host_visible = true, .name = "gen-b"}, &r);
    assert_int_equal(b.id & OB_HANDLE_INDEX_MASK, a.id & OB_HANDLE_INDEX_MASK);   /* slot reused */
    assert_int_not_equal(b.id, a.id);                                             /* new generation */
    assert_true(ob_buffer_is_valid(dev, b));

    ob_test_log_clear();
    uint8_t bytes[16] = {0};
    assert_null(ob_buffer_vk(dev, a));
    assert_int_equal(ob_buffer_size(dev, a), 0);
    assert_null(ob_buffer_mapped(dev, a));
    assert_int_equal(ob_buffer_upload(dev, a, 0, bytes, sizeof bytes), OB_ERR_INVALID_HANDLE);
    assert_int_equal(ob_buffer_read(dev, a, 0, sizeof bytes, bytes), OB_ERR_INVALID_HANDLE);
    ob_buffer_destroy(dev, a);   /* a second destroy is refused, not a double free */
    assert_true(ob_test_log_has("ob_buffer_upload", "invalid or stale buffer handle", NULL));
    assert_true(ob_test_log_has("ob_buffer_destroy", "invalid or stale", NULL));
    assert_non_null(ob_buffer_vk(dev, b));   /* the new owner of the slot is untouched */
    assert_null(ob_buffer_vk(dev, (ob_buffer){0}));
    ob_buffer_destroy(dev, (ob_buffer){0});   /* zero handle: no-op */

    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = 4, .height = 4, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC, .name = "gen-img"}, &r);
    assert_int_equal(r, OB_OK);
    ob_image_destroy(dev, img);
    ob_image_info info;
    ob_image_state st;
    VkImageMemoryBarrier2 barrier;
    uint8_t px[4 * 4 * 4];
    assert_null(ob_image_vk(dev, img));
    assert_null(ob_image_view(dev, img));
    assert_null(ob_image_layer_view(dev, img, 0));
    assert_int_equal(ob_image_get_info(dev, img, &info), OB_ERR_INVALID_HANDLE);
    assert_int_equal(ob_image_get_state(dev, img, &st), OB_ERR_INVALID_HANDLE);
    assert_false(ob_image_transition(dev, img, &color_target_state, &barrier));
    assert_int_equal(ob_image_read_rgba8(dev, img, px), OB_ERR_INVALID_HANDLE);
    assert_int_equal(ob_image_write_png(dev, img, "/tmp/never-written.png"), OB_ERR_INVALID_HANDLE);
    assert_false(ob_image_is_valid(dev, img));
    ob_image_destroy(dev, img);

    ob_sampler s = ob_sampler_create(dev, &(ob_sampler_desc){.name = "gen-sampler"}, &r);
    assert_int_equal(r, OB_OK);
    ob_sampler_destroy(dev, s);
    assert_null(ob_sampler_vk(dev, s));
    ob_sampler_destroy(dev, s);

    ob_buffer_destroy(dev, b);
    ob_resource_counts after = ob_resource_counts_get(dev);
    assert_int_equal(after.buffers, before.buffers);
    assert_int_equal(after.images, before.images);
    assert_int_equal(after.samplers, before.samplers);
    assert_int_equal(after.device_bytes, before.device_bytes);
    ob_test_assert_no_validation(dev);
}

static void bad_sizes_and_usages_are_rejected_by_name(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    ob_test_log_clear();
    ob_buffer buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 0, .usage = OB_BUFFER_VERTEX, .name = "empty-vb"}, &r);
    assert_int_equal(buf.id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'empty-vb'", "size is 0", NULL));

    buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 16, .usage = 0, .name = "no-usage"}, &r);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'no-usage'", "usage", NULL));
    uint8_t data[32] = {0};
    buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 16, .usage = OB_BUFFER_VERTEX, .data = data,
                                                   .data_size = 32, .name = "too-much"}, &r);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'too-much'", "exceed", NULL));

    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = 0, .height = 16, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_SAMPLED, .name = "flat-image"}, &r);
    assert_int_equal(img.id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'flat-image'", "0x16", NULL));
    img = ob_image_create(dev, &(ob_image_desc){.width = 8, .height = 8, .format = VK_FORMAT_D32_SFLOAT,
                                                .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_DEPTH_TARGET, .name = "both-targets"}, &r);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'both-targets'", NULL));
    img = ob_image_create(dev, &(ob_image_desc){.width = 8, .height = 8, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                .usage = 1u << 20, .name = "odd-usage"}, &r);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);

    ob_sampler s = ob_sampler_create(dev, &(ob_sampler_desc){.compare = true, .compare_op = (VkCompareOp)99, .name = "odd-sampler"}, &r);
    assert_int_equal(s.id, 0);
    assert_int_equal(r, OB_ERR_INVALID_ARGUMENT);
    assert_true(ob_test_log_has("'odd-sampler'", NULL));
    ob_test_assert_no_validation(dev);
}

static void unsupported_format_and_usage_is_refused(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    ob_test_log_clear();
    /* A block-compressed format can never be a colour target. */
    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = 16, .height = 16, .format = VK_FORMAT_BC1_RGBA_UNORM_BLOCK,
                                                         .usage = OB_IMAGE_COLOR_TARGET, .name = "bc1-target"}, &r);
    assert_int_equal(img.id, 0);
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    char format_text[32];
    snprintf(format_text, sizeof format_text, "format %d", (int)VK_FORMAT_BC1_RGBA_UNORM_BLOCK);
    assert_true(ob_test_log_has("'bc1-target'", format_text, "usage 0x2", NULL));

    /* Nor a depth format a colour target. */
    img = ob_image_create(dev, &(ob_image_desc){.width = 16, .height = 16, .format = VK_FORMAT_D32_SFLOAT,
                                                .usage = OB_IMAGE_COLOR_TARGET, .name = "depth-as-color"}, &r);
    assert_int_equal(r, OB_ERR_UNSUPPORTED);
    assert_true(ob_test_log_has("'depth-as-color'", NULL));

    /* Read-back of a non-RGBA8 image is refused with the reason. */
    img = ob_image_create(dev, &(ob_image_desc){.width = 4, .height = 4, .format = VK_FORMAT_R32_SFLOAT,
                                                .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_TRANSFER_SRC, .name = "float-target"}, &r);
    assert_int_equal(r, OB_OK);
    uint8_t px[4 * 4 * 4];
    assert_int_equal(ob_image_read_rgba8(dev, img, px), OB_ERR_UNSUPPORTED);
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

static void buffer_uploads_read_back_equal(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { N = 4096 };
    uint8_t data[N], back[N], patch[100];
    pattern(data, N, 1);
    pattern(patch, sizeof patch, 2);

    for (int host = 0; host < 2; host++) {
        ob_buffer buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = N, .usage = OB_BUFFER_VERTEX | OB_BUFFER_STORAGE,
                                                                 .host_visible = host, .data = data,
                                                                 .name = host ? "host-vb" : "device-vb"}, &r);
        assert_int_equal(r, OB_OK);
        assert_int_equal(ob_buffer_size(dev, buf), N);
        if (host) {
            assert_non_null(ob_buffer_mapped(dev, buf));
            assert_memory_equal(ob_buffer_mapped(dev, buf), data, N);
        } else {
            assert_null(ob_buffer_mapped(dev, buf));
        }
        memset(back, 0, N);
        assert_int_equal(ob_buffer_read(dev, buf, 0, N, back), OB_OK);
        assert_memory_equal(back, data, N);

        assert_int_equal(ob_buffer_upload(dev, buf, 1000, patch, sizeof patch), OB_OK);
        memcpy(data + 1000, patch, sizeof patch);
        assert_int_equal(ob_buffer_read(dev, buf, 0, N, back), OB_OK);
        assert_memory_equal(back, data, N);
        assert_int_equal(ob_buffer_read(dev, buf, 1000, sizeof patch, back), OB_OK);
        assert_memory_equal(back, patch, sizeof patch);
        pattern(data, N, 1);

        ob_test_log_clear();
        assert_int_equal(ob_buffer_upload(dev, buf, N - 50, patch, sizeof patch), OB_ERR_OUT_OF_RANGE);
        assert_true(ob_test_log_has(host ? "'host-vb'" : "'device-vb'", "exceeds its size", NULL));
        assert_int_equal(ob_buffer_read(dev, buf, UINT64_MAX, 2, back), OB_ERR_OUT_OF_RANGE);
        ob_buffer_destroy(dev, buf);
    }
    /* Partial initial data: the rest is still uploadable. */
    ob_buffer part = ob_buffer_create(dev, &(ob_buffer_desc){.size = 256, .usage = OB_BUFFER_INDEX, .data = data,
                                                              .data_size = 16, .name = "partial"}, &r);
    assert_int_equal(r, OB_OK);
    assert_int_equal(ob_buffer_read(dev, part, 0, 16, back), OB_OK);
    assert_memory_equal(back, data, 16);
    ob_buffer_destroy(dev, part);
    ob_test_assert_no_validation(dev);
}

static void image_data_reads_back_equal(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { W = 16, H = 8 };
    uint8_t texels[W * H * 4], back[W * H * 4], swizzled[W * H * 4];
    pattern(texels, sizeof texels, 3);

    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC,
                                                         .data = texels, .name = "rgba-texture"}, &r);
    assert_int_equal(r, OB_OK);
    ob_image_state st;
    assert_int_equal(ob_image_get_state(dev, img, &st), OB_OK);
    assert_int_equal(st.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    assert_int_equal(ob_image_read_rgba8(dev, img, back), OB_OK);
    assert_memory_equal(back, texels, sizeof texels);
    ob_image_state after;
    assert_int_equal(ob_image_get_state(dev, img, &after), OB_OK);
    assert_int_equal(after.layout, st.layout);   /* read-back restores the layout */
    /* Sampling in a fragment shader now needs no barrier. */
    VkImageMemoryBarrier2 barrier;
    ob_image_state sample = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                             VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    assert_false(ob_image_transition(dev, img, &sample, &barrier));
    ob_image_destroy(dev, img);

    /* B8G8R8A8 data comes back swizzled to RGBA. */
    img = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = VK_FORMAT_B8G8R8A8_UNORM,
                                                .usage = OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC,
                                                .data = texels, .name = "bgra-texture"}, &r);
    assert_int_equal(r, OB_OK);
    for (size_t i = 0; i < W * H; i++) {
        swizzled[4 * i + 0] = texels[4 * i + 2];
        swizzled[4 * i + 1] = texels[4 * i + 1];
        swizzled[4 * i + 2] = texels[4 * i + 0];
        swizzled[4 * i + 3] = texels[4 * i + 3];
    }
    assert_int_equal(ob_image_read_rgba8(dev, img, back), OB_OK);
    assert_memory_equal(back, swizzled, sizeof swizzled);
    ob_image_destroy(dev, img);

    /* Nothing written yet: refused, not garbage. */
    img = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_TRANSFER_SRC, .name = "blank"}, &r);
    assert_int_equal(ob_image_read_rgba8(dev, img, back), OB_ERR_WRONG_STATE);
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

static void cleared_color_reads_back_exactly(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { W = 32, H = 24 };
    static const VkFormat formats[] = {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM};
    const float clear[4] = {0.2f, 0.4f, 0.6f, 1.0f};
    const uint8_t expect[4] = {51, 102, 153, 255};
    uint8_t px[W * H * 4];
    for (size_t f = 0; f < OB_ARRAY_COUNT(formats); f++) {
        ob_image img = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = formats[f],
                                                             .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_TRANSFER_SRC,
                                                             .name = "clear-target"}, &r);
        assert_int_equal(r, OB_OK);
        VkCommandBuffer cmd;
        assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
        transition(dev, cmd, img, &color_target_state);
        record_clear(cmd, ob_image_view(dev, img), W, H, clear);
        assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);
        memset(px, 0, sizeof px);
        assert_int_equal(ob_image_read_rgba8(dev, img, px), OB_OK);
        assert_all_pixels(px, W * H, expect);
        ob_image_state st;
        ob_image_get_state(dev, img, &st);
        assert_int_equal(st.layout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
        ob_image_destroy(dev, img);
    }
    ob_test_assert_no_validation(dev);
}

static void array_image_has_a_view_per_layer(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { W = 8, H = 8 };
    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .layers = 2,
                                                         .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC,
                                                         .name = "paraboloid"}, &r);
    assert_int_equal(r, OB_OK);
    ob_image_info info;
    assert_int_equal(ob_image_get_info(dev, img, &info), OB_OK);
    assert_int_equal(info.layers, 2);
    assert_int_equal(info.aspect, VK_IMAGE_ASPECT_COLOR_BIT);
    VkImageView all = ob_image_view(dev, img), l0 = ob_image_layer_view(dev, img, 0), l1 = ob_image_layer_view(dev, img, 1);
    assert_non_null(all);
    assert_non_null(l0);
    assert_non_null(l1);
    assert_true(all != l0 && all != l1 && l0 != l1);
    ob_test_log_clear();
    assert_null(ob_image_layer_view(dev, img, 2));
    assert_true(ob_test_log_has("'paraboloid'", "layer 2 out of range", NULL));

    const float red[4] = {1, 0, 0, 1}, green[4] = {0, 1, 0, 1};
    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
    transition(dev, cmd, img, &color_target_state);
    record_clear(cmd, l0, W, H, red);
    record_clear(cmd, l1, W, H, green);
    ob_image_state sample = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                             VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    transition(dev, cmd, img, &sample);
    assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);

    uint8_t px[W * H * 4];
    const uint8_t want_red[4] = {255, 0, 0, 255}, want_green[4] = {0, 255, 0, 255};
    assert_int_equal(ob_image_read_layer_rgba8(dev, img, 0, px), OB_OK);
    assert_all_pixels(px, W * H, want_red);
    assert_int_equal(ob_image_read_layer_rgba8(dev, img, 1, px), OB_OK);
    assert_all_pixels(px, W * H, want_green);
    assert_int_equal(ob_image_read_layer_rgba8(dev, img, 2, px), OB_ERR_OUT_OF_RANGE);

    /* A single-layer image's layer view is its only view. */
    ob_image flat = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                          .usage = OB_IMAGE_SAMPLED, .name = "flat"}, &r);
    assert_ptr_equal(ob_image_layer_view(dev, flat, 0), ob_image_view(dev, flat));
    ob_image_destroy(dev, flat);
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

/* An opaque RGBA8 image of w x h pattern texels (kept in `texels`) that can
 * be read back, and a path for its PNG in the test cache folder. */
static ob_image png_source(ob_device *dev, uint32_t w, uint32_t h, uint8_t *texels, uint32_t seed,
                           const char *name, char *path, size_t path_size)
{
    ob_result r;
    pattern(texels, (size_t)w * h * 4, seed);
    for (size_t i = 0; i < (size_t)w * h; i++) texels[4 * i + 3] = 255;
    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = w, .height = h, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC,
                                                         .data = texels, .name = name}, &r);
    assert_int_equal(r, OB_OK);
    const char *dir = getenv("OB_CACHE_DIR");
    if (!dir) dir = "/tmp";
    assert_int_equal(ob_dir_make(dir), OB_OK);
    snprintf(path, path_size, "%s/%s_%ld.png", dir, name, (long)getpid());
    return img;
}

/* The PNG at path holds exactly texels (w x h); then it is removed. */
static void assert_png_holds(const char *path, const uint8_t *texels, uint32_t w, uint32_t h)
{
    int lw = 0, lh = 0, comp = 0;
    unsigned char *loaded = stbi_load(path, &lw, &lh, &comp, 4);
    assert_non_null(loaded);
    assert_int_equal(lw, (int)w);
    assert_int_equal(lh, (int)h);
    assert_int_equal(ob_test_image_max_diff(loaded, texels, w, h), 0);
    stbi_image_free(loaded);
    remove(path);
}

static void png_round_trips_through_stb(void **state)
{
    ob_device *dev = *state;
    enum { W = 13, H = 7 };   /* odd sizes catch stride mistakes */
    uint8_t texels[W * H * 4];
    char path[512];
    ob_image img = png_source(dev, W, H, texels, 4, "png-source", path, sizeof path);
    assert_int_equal(ob_image_write_png(dev, img, path), OB_OK);
    assert_png_holds(path, texels, W, H);

    ob_test_log_clear();
    assert_int_equal(ob_image_write_png(dev, img, "/nonexistent-obelisk-dir/x.png"), OB_ERR_IO);
    assert_true(ob_test_log_has("nonexistent-obelisk-dir", NULL));
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

/* Issue 25.10: stb_image_write's own deflate grows its buffers with an
 * unchecked realloc, so a failed allocation while encoding wrote past the
 * old buffer (a crash). Every host allocation of ob_image_write_png fails in
 * turn now: an error with a message, no file, nothing left on the heap;
 * then the same call writes the same picture. */
static void png_writing_survives_every_allocation_failure(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { W = 61, H = 37 };   /* big enough for the encoder to grow its buffers */
    uint8_t texels[W * H * 4];
    char path[512];
    ob_image img = png_source(dev, W, H, texels, 6, "png-faults", path, sizeof path);
    remove(path);
    ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
    assert_int_equal(ob_image_write_png(dev, img, path), OB_OK);
    uint64_t points = ob_fault_count(OB_FAULT_HOST_ALLOC);
    remove(path);
    assert_true(points >= 3);   /* pixels, the encoder's buffers, the file's */
    ob_test_log_set_echo(false);
    for (uint64_t n = 1; n <= points; n++) {
        ob_heap_stats before = ob_heap_stats_now();
        ob_test_log_clear();
        ob_fault_arm(OB_FAULT_HOST_ALLOC, n);
        r = ob_image_write_png(dev, img, path);
        bool hit = ob_fault_hit(OB_FAULT_HOST_ALLOC);
        ob_fault_arm(OB_FAULT_HOST_ALLOC, 0);
        ob_heap_stats after = ob_heap_stats_now();
        assert_true(hit);
        if (r != OB_ERR_OUT_OF_HOST_MEMORY)
            fail_msg("point %llu of %llu: %s", (unsigned long long)n, (unsigned long long)points, ob_result_name(r));
        if (!ob_test_log_has("png-faults", NULL)) fail_msg("point %llu: failed without a message", (unsigned long long)n);
        if (access(path, F_OK) == 0) fail_msg("point %llu: a file was written", (unsigned long long)n);
        if (after.live_blocks != before.live_blocks)
            fail_msg("point %llu: %lld blocks left", (unsigned long long)n,
                     (long long)(after.live_blocks - before.live_blocks));
    }
    ob_test_log_set_echo(true);
    assert_int_equal(ob_image_write_png(dev, img, path), OB_OK);
    assert_png_holds(path, texels, W, H);
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

static void depth_image_clears_and_copies_out(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    enum { W = 16, H = 16 };
    ob_image depth = ob_image_create(dev, &(ob_image_desc){.width = W, .height = H, .format = VK_FORMAT_D32_SFLOAT,
                                                           .usage = OB_IMAGE_DEPTH_TARGET | OB_IMAGE_SAMPLED | OB_IMAGE_TRANSFER_SRC,
                                                           .name = "shadow-map"}, &r);
    assert_int_equal(r, OB_OK);
    ob_image_info info;
    ob_image_get_info(dev, depth, &info);
    assert_int_equal(info.aspect, VK_IMAGE_ASPECT_DEPTH_BIT);
    assert_non_null(ob_image_view(dev, depth));
    ob_buffer out = ob_buffer_create(dev, &(ob_buffer_desc){.size = W * H * 4, .usage = OB_BUFFER_TRANSFER_DST,
                                                             .host_visible = true, .name = "depth-out"}, &r);
    assert_int_equal(r, OB_OK);

    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
    ob_image_state target = {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                             VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                             VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT};
    transition(dev, cmd, depth, &target);
    VkRenderingAttachmentInfo att = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(dev, depth),
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.depthStencil = {0.75f, 0},
    };
    VkRenderingInfo ri = {.sType = VK_STRUCTURE_TYPE_RENDERING_INFO, .renderArea = {{0, 0}, {W, H}},
                          .layerCount = 1, .pDepthAttachment = &att};
    vkCmdBeginRendering(cmd, &ri);
    vkCmdEndRendering(cmd);
    ob_image_state copy_src = {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                               VK_ACCESS_2_TRANSFER_READ_BIT};
    transition(dev, cmd, depth, &copy_src);
    VkBufferImageCopy region = {.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1}, .imageExtent = {W, H, 1}};
    vkCmdCopyImageToBuffer(cmd, ob_image_vk(dev, depth), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, ob_buffer_vk(dev, out), 1, &region);
    ob_image_state sample = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                             VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    transition(dev, cmd, depth, &sample);
    assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);

    float values[W * H];
    assert_int_equal(ob_buffer_read(dev, out, 0, sizeof values, values), OB_OK);
    for (int i = 0; i < W * H; i++) assert_true(values[i] == 0.75f);
    uint8_t px[W * H * 4];
    assert_int_equal(ob_image_read_rgba8(dev, depth, px), OB_ERR_UNSUPPORTED);
    ob_buffer_destroy(dev, out);
    ob_image_destroy(dev, depth);
    ob_test_assert_no_validation(dev);
}

static void compare_sampler_is_created(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    ob_sampler s = ob_sampler_create(dev, &(ob_sampler_desc){.filter = VK_FILTER_LINEAR,
                                                              .address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER,
                                                              .compare = true, .name = "shadow-sampler"}, &r);
    assert_int_equal(r, OB_OK);
    assert_non_null(ob_sampler_vk(dev, s));
    ob_sampler plain = ob_sampler_create(dev, NULL, &r);   /* all defaults */
    assert_int_equal(r, OB_OK);
    assert_true(ob_sampler_vk(dev, plain) != ob_sampler_vk(dev, s));
    assert_int_equal(ob_resource_counts_get(dev).samplers, 2);
    ob_sampler_destroy(dev, s);
    ob_sampler_destroy(dev, plain);
    assert_int_equal(ob_resource_counts_get(dev).samplers, 0);
    ob_test_assert_no_validation(dev);
}

static void transitions_follow_the_tracked_state(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    ob_image img = ob_image_create(dev, &(ob_image_desc){.width = 4, .height = 4, .layers = 2, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                         .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_SAMPLED, .name = "tracked"}, &r);
    VkImageMemoryBarrier2 b;
    assert_true(ob_image_transition(dev, img, &color_target_state, &b));
    assert_int_equal(b.oldLayout, VK_IMAGE_LAYOUT_UNDEFINED);
    assert_int_equal(b.newLayout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    assert_int_equal(b.srcStageMask, VK_PIPELINE_STAGE_2_NONE);
    assert_int_equal(b.dstAccessMask, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    assert_int_equal(b.subresourceRange.layerCount, 2);
    assert_ptr_equal(b.image, ob_image_vk(dev, img));
    /* Write after write needs a barrier even in the same layout. */
    assert_true(ob_image_transition(dev, img, &color_target_state, &b));
    assert_int_equal(b.srcAccessMask, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);

    ob_image_state frag = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    ob_image_state vert = {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT};
    assert_true(ob_image_transition(dev, img, &frag, &b));
    assert_int_equal(b.srcStageMask, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT);
    assert_int_equal(b.oldLayout, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    assert_false(ob_image_transition(dev, img, &frag, &b));   /* already readable there */
    assert_true(ob_image_transition(dev, img, &vert, &b));    /* a new reader stage */
    ob_image_state st;
    ob_image_get_state(dev, img, &st);
    assert_int_equal(st.stages, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT);
    assert_false(ob_image_transition(dev, img, &vert, &b));
    /* The next write waits for both readers. */
    assert_true(ob_image_transition(dev, img, &color_target_state, &b));
    assert_int_equal(b.srcStageMask, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT);

    ob_image_state undefined = {VK_IMAGE_LAYOUT_UNDEFINED, 0, 0};
    assert_false(ob_image_transition(dev, img, &undefined, &b));
    ob_image_destroy(dev, img);
    ob_test_assert_no_validation(dev);
}

static void destroy_right_after_recording_is_safe(void **state)
{
    ob_device *dev = *state;
    ob_result r;
    ob_device_begin_frame_slot(dev, 0);
    ob_buffer buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 256, .usage = OB_BUFFER_STORAGE, .name = "in-flight"}, &r);
    uint64_t bytes = ob_resource_counts_get(dev).device_bytes;
    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(dev, &cmd), OB_OK);
    vkCmdFillBuffer(cmd, ob_buffer_vk(dev, buf), 0, VK_WHOLE_SIZE, 0xdeadbeef);
    /* Destroyed while the recorded work still refers to it: the VkBuffer must
     * outlive the submission, or validation reports a destroyed object. */
    ob_buffer_destroy(dev, buf);
    assert_false(ob_buffer_is_valid(dev, buf));
    assert_true(ob_resource_counts_get(dev).device_bytes < bytes);
    assert_int_equal(ob_device_oneshot_submit(dev, cmd), OB_OK);
    ob_device_begin_frame_slot(dev, 1);
    ob_device_begin_frame_slot(dev, 0);   /* now it is really freed */
    ob_test_assert_no_validation(dev);
}

static void leaked_resources_are_named_at_device_destroy(void **state)
{
    (void)state;
    ob_device *dev = ob_test_device_create();
    ob_result r;
    ob_buffer_create(dev, &(ob_buffer_desc){.size = 64, .usage = OB_BUFFER_VERTEX, .name = "forgotten-vb"}, &r);
    ob_image_create(dev, &(ob_image_desc){.width = 4, .height = 4, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                          .usage = OB_IMAGE_SAMPLED, .name = "forgotten-tex"}, &r);
    ob_resource_counts c = ob_resource_counts_get(dev);
    assert_int_equal(c.buffers, 1);
    assert_int_equal(c.images, 1);
    assert_true(c.device_bytes >= 64);
    ob_test_log_clear();
    ob_test_assert_no_validation(dev);
    ob_device_destroy(dev);   /* frees them; ASan would see a leak otherwise */
    assert_true(ob_test_log_has("2 leaked", "buffer 'forgotten-vb'", "image 'forgotten-tex'", NULL));
}

/* Creates case `what` (0: staged buffer, 1: array image + uploaded image,
 * 2: sampler) and returns true when every creation succeeded. The handles
 * are returned so that destruction happens with the fault disarmed. */
typedef struct fault_case {
    ob_buffer buf;
    ob_image img[2];
    ob_sampler smp;
} fault_case;

static bool fault_case_create(ob_device *dev, int what, const uint8_t *data, fault_case *out)
{
    ob_result r;
    memset(out, 0, sizeof *out);
    if (what == 0) {
        out->buf = ob_buffer_create(dev, &(ob_buffer_desc){.size = 256, .usage = OB_BUFFER_VERTEX, .data = data,
                                                            .name = "faulty-vb"}, &r);
        return out->buf.id != 0;
    }
    if (what == 1) {
        out->img[0] = ob_image_create(dev, &(ob_image_desc){.width = 8, .height = 8, .layers = 2,
                                                            .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                            .usage = OB_IMAGE_SAMPLED, .name = "faulty-array"}, &r);
        out->img[1] = ob_image_create(dev, &(ob_image_desc){.width = 8, .height = 8, .format = VK_FORMAT_R8G8B8A8_UNORM,
                                                            .usage = OB_IMAGE_SAMPLED, .data = data,
                                                            .name = "faulty-upload"}, &r);
        return out->img[0].id && out->img[1].id;
    }
    out->smp = ob_sampler_create(dev, &(ob_sampler_desc){.compare = true, .name = "faulty-sampler"}, &r);
    return out->smp.id != 0;
}

static void fault_case_destroy(ob_device *dev, fault_case *c)
{
    ob_buffer_destroy(dev, c->buf);
    ob_image_destroy(dev, c->img[0]);
    ob_image_destroy(dev, c->img[1]);
    ob_sampler_destroy(dev, c->smp);
    ob_device_begin_frame_slot(dev, 1);
    ob_device_begin_frame_slot(dev, 0);
}

/* Every allocation point of those creations fails cleanly and leaves the
 * counts as they were (the ASan build checks that nothing leaks). */
static void creation_survives_every_allocation_failure(void **state)
{
    ob_device *dev = *state;
    uint8_t data[8 * 8 * 4];
    pattern(data, sizeof data, 5);
    ob_resource_counts before = ob_resource_counts_get(dev);
    /* The creation kinds: a device loss (OB_FAULT_DEVICE_LOST) latches and
     * refuses everything after it; tests/gpu/test_device_loss.c covers it. */
    for (int kind = OB_FAULT_HOST_ALLOC; kind <= OB_FAULT_VK_OBJECT; kind++) {
        for (int what = 0; what < 3; what++) {
            fault_case c;
            ob_fault_arm((ob_fault_kind)kind, 0);
            bool ok = fault_case_create(dev, what, data, &c);
            uint64_t points = ob_fault_count((ob_fault_kind)kind);
            fault_case_destroy(dev, &c);
            assert_true(ok);
            if (kind == OB_FAULT_VK_OBJECT) assert_true(points >= (what == 2 ? 1u : 2u));
            for (uint64_t n = 1; n <= points; n++) {
                ob_fault_arm((ob_fault_kind)kind, n);
                ok = fault_case_create(dev, what, data, &c);
                bool hit = ob_fault_hit((ob_fault_kind)kind);
                ob_fault_arm((ob_fault_kind)kind, 0);
                fault_case_destroy(dev, &c);
                assert_true(hit);
                if (ok) fail_msg("fault kind %d at point %llu of case %d did not fail creation", kind,
                                 (unsigned long long)n, what);
            }
        }
    }
    ob_resource_counts after = ob_resource_counts_get(dev);
    assert_int_equal(after.buffers, before.buffers);
    assert_int_equal(after.images, before.images);
    assert_int_equal(after.samplers, before.samplers);
    assert_int_equal(after.device_bytes, before.device_bytes);
    ob_test_assert_no_validation(dev);
}

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stale_handles_are_rejected_everywhere),
        cmocka_unit_test(bad_sizes_and_usages_are_rejected_by_name),
        cmocka_unit_test(unsupported_format_and_usage_is_refused),
        cmocka_unit_test(buffer_uploads_read_back_equal),
        cmocka_unit_test(image_data_reads_back_equal),
        cmocka_unit_test(cleared_color_reads_back_exactly),
        cmocka_unit_test(array_image_has_a_view_per_layer),
        cmocka_unit_test(png_round_trips_through_stb),
        cmocka_unit_test(png_writing_survives_every_allocation_failure),
        cmocka_unit_test(depth_image_clears_and_copies_out),
        cmocka_unit_test(compare_sampler_is_created),
        cmocka_unit_test(transitions_follow_the_tracked_state),
        cmocka_unit_test(destroy_right_after_recording_is_safe),
        cmocka_unit_test(leaked_resources_are_named_at_device_destroy),
        cmocka_unit_test(creation_survives_every_allocation_failure),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
