/* test_texture.c — textures as a user sees them: a checkerboard drawn
 * head-on gives back its texels, sRGB data decodes to linear light, the
 * cache shares identical content, a missing or corrupt file is a warning and
 * a NULL (and the cache goes on working), a full mip chain exists and a
 * minified quad samples it, an image past the device limit is downscaled,
 * and every host-allocation and Vulkan-object failure while loading (mips
 * made on the device and on the CPU) fails cleanly without leaking.
 *
 * The quad is drawn by a tiny test effect (a textured rectangle in clip
 * space written to an R8G8B8A8_UNORM target), so what is read back is what
 * the sampler returned, with no lighting or tone mapping in between.
 */
#define _XOPEN_SOURCE 700
#include "ob_test.h"

#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <stb_image_write.h>
/* Defined by stb_image_write (engine/ob_stb_impl.c) but declared only in its
 * implementation section. */
unsigned char *stbi_write_png_to_mem(const unsigned char *pixels, int stride_bytes, int x, int y, int n,
                                     int *out_len);

#include "ob_effect.h"
#include "ob_pipeline_manager.h"
#include "ob_resources.h"
#include "ob_texture.h"

#define SIZE 64

typedef struct fixture {
    ob_device *dev;
    ob_param_registry *reg;
    ob_effect_context *ctx;
    ob_effect *quad;
    ob_pipeline_manager *pm;
    ob_image color;
    char dir[64];
    uint64_t serial;
} fixture;

static const char quad_vert[] =
    "#version 450\n"
    "layout(set = 0, binding = 0, std140) uniform Quad { vec4 QuadRect; };\n"
    "layout(location = 0) out vec2 vUV;\n"
    "void main() {\n"
    "    vec2 c = vec2((gl_VertexIndex & 1) != 0 ? 1.0 : 0.0, (gl_VertexIndex & 2) != 0 ? 1.0 : 0.0);\n"
    "    vUV = c;\n"
    "    gl_Position = vec4(mix(QuadRect.xy, QuadRect.zw, c), 0.5, 1.0);\n"
    "}\n";
static const char quad_frag[] =
    "#version 450\n"
    "layout(location = 0) in vec2 vUV;\n"
    "layout(set = 1, binding = 0) uniform sampler2D Tex;\n"
    "layout(location = 0) out vec4 outColor;\n"
    "void main() { outColor = texture(Tex, vUV); }\n";

static void write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, size, f), size);
    fclose(f);
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb, (void)flag, (void)ftw;
    return remove(path);
}

static int setup(void **state)
{
    static fixture f;
    f.dev = ob_test_device_create();
    ob_result r;
    f.reg = ob_param_registry_create(&(ob_param_registry_desc){.slot_count = 1}, &r);
    assert_non_null(f.reg);
    snprintf(f.dir, sizeof f.dir, "/tmp/ob-texture-test-XXXXXX");
    assert_non_null(mkdtemp(f.dir));
    char vpath[128], fpath[128];
    snprintf(vpath, sizeof vpath, "%s/quad.vert", f.dir);
    snprintf(fpath, sizeof fpath, "%s/quad.frag", f.dir);
    write_file(vpath, quad_vert, sizeof quad_vert - 1);
    write_file(fpath, quad_frag, sizeof quad_frag - 1);
    f.ctx = ob_effect_context_create(f.dev, f.reg, NULL, &r);
    assert_non_null(f.ctx);
    f.quad = ob_effect_create(f.ctx, &(ob_effect_desc){
        .name = "textured quad", .vertex = vpath, .fragment = fpath,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP}, &r);
    assert_non_null(f.quad);
    f.pm = ob_pipeline_manager_create(&(ob_pipeline_manager_desc){
        .device = f.dev, .registry = f.reg, .slot = 0, .name = "immediate"}, &r);
    assert_non_null(f.pm);
    f.color = ob_image_create(f.dev, &(ob_image_desc){
        .width = SIZE, .height = SIZE, .format = VK_FORMAT_R8G8B8A8_UNORM,
        .usage = OB_IMAGE_COLOR_TARGET | OB_IMAGE_TRANSFER_SRC, .name = "target"}, &r);
    assert_int_not_equal(f.color.id, 0);
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    ob_test_assert_no_validation(f->dev);
    ob_image_destroy(f->dev, f->color);
    ob_pipeline_manager_destroy(f->pm);
    ob_effect_destroy(f->quad);
    ob_effect_context_destroy(f->ctx);
    ob_param_registry_destroy(f->reg);
    ob_device_destroy(f->dev);
    nftw(f->dir, remove_entry, 8, FTW_DEPTH | FTW_PHYS);
    return 0;
}

/* Draws t over the clip-space rectangle (x0, y0)-(x1, y1) on a black
 * target and reads the target back into out (SIZE * SIZE * 4). */
static void draw_quad(fixture *f, const ob_texture *t, const float rect[4], uint8_t *out)
{
    VkCommandBuffer cmd;
    assert_int_equal(ob_device_oneshot_begin(f->dev, &cmd), OB_OK);
    VkImageMemoryBarrier2 b;
    ob_image_state target = {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                             VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                             VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT};
    if (ob_image_transition(f->dev, f->color, &target, &b))
        vkCmdPipelineBarrier2(cmd, &(VkDependencyInfo){.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                                                       .imageMemoryBarrierCount = 1,
                                                       .pImageMemoryBarriers = &b});
    VkRenderingAttachmentInfo color_att = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(f->dev, f->color),
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
        .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
        .clearValue.color.float32 = {0, 0, 0, 1},
    };
    vkCmdBeginRendering(cmd, &(VkRenderingInfo){.sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
                                                 .renderArea = {{0, 0}, {SIZE, SIZE}},
                                                 .layerCount = 1,
                                                 .colorAttachmentCount = 1,
                                                 .pColorAttachments = &color_att});
    ob_pipeline_manager_begin_frame(f->pm, 0, ++f->serial);
    ob_pipeline_manager_begin(f->pm, cmd);
    ob_pipeline_manager_set_viewport(f->pm, 0, 0, SIZE, SIZE);
    ob_pipeline_manager_set_scissor(f->pm, 0, 0, SIZE, SIZE);
    uint32_t id;
    VkPipeline p = ob_effect_pipeline(f->quad, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_UNDEFINED, &id);
    assert_non_null(p);
    ob_pipeline_manager_set_pipeline(f->pm, p, id, ob_effect_program(f->quad));
    ob_params *params = ob_pipeline_manager_params(f->pm);
    assert_int_equal(ob_params_set_vec4(params, ob_param_find(f->reg, "QuadRect"), rect), OB_OK);
    assert_int_equal(ob_params_set_texture(params, ob_param_find(f->reg, "Tex"), ob_texture_image(t)), OB_OK);
    assert_int_equal(ob_params_set_sampler(params, ob_param_find(f->reg, "TexSampler"), ob_texture_sampler(t)),
                     OB_OK);
    assert_int_equal(ob_pipeline_manager_draw(f->pm, 4, 1, 0, 0), OB_OK);
    ob_pipeline_manager_end(f->pm);
    vkCmdEndRendering(cmd);
    assert_int_equal(ob_device_oneshot_submit(f->dev, cmd), OB_OK);
    assert_int_equal(ob_image_read_rgba8(f->dev, f->color, out), OB_OK);
}

static const float full_rect[4] = {-1, -1, 1, 1};

/* An n x n board of `cell`-texel squares of colours a and b, as a PNG in memory. */
/* (The PNG comes from stb_image_write, which allocates with ob_malloc: ob_free it.) */
static uint8_t *checker_png(uint32_t n, uint32_t cell, const uint8_t a[4], const uint8_t b[4], int *out_size)
{
    uint8_t *px = malloc((size_t)n * n * 4);
    assert_non_null(px);
    for (uint32_t y = 0; y < n; y++)
        for (uint32_t x = 0; x < n; x++) memcpy(px + 4 * (y * n + x), ((x / cell + y / cell) & 1) ? b : a, 4);
    uint8_t *png = stbi_write_png_to_mem(px, (int)n * 4, (int)n, (int)n, 4, out_size);
    free(px);
    assert_non_null(png);
    return png;
}

static const uint8_t warm[4] = {188, 64, 255, 255}, cool[4] = {0, 128, 32, 255};

static uint8_t srgb_decoded(uint8_t c)
{
    double v = c / 255.0;
    double l = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
    return (uint8_t)lrint(l * 255.0);
}

static void assert_pixel(const uint8_t *img, uint32_t x, uint32_t y, const uint8_t want[4], int tol)
{
    const uint8_t *p = img + 4 * (y * SIZE + x);
    for (int c = 0; c < 3; c++)
        if (abs((int)p[c] - (int)want[c]) > tol)
            fail_msg("pixel (%u, %u) is (%u, %u, %u), expected (%u, %u, %u) within %d", x, y, p[0], p[1], p[2],
                     want[0], want[1], want[2], tol);
}

static const ob_texture_sampling nearest = {OB_TEXTURE_FILTER_NEAREST, OB_TEXTURE_FILTER_NEAREST,
                                            OB_TEXTURE_FILTER_NEAREST, false, OB_TEXTURE_WRAP_CLAMP,
                                            OB_TEXTURE_WRAP_CLAMP};

/* An 8x8 board on a 64x64 quad, from a PNG file and from the same bytes in
 * memory: every 8x8 pixel block shows its texel exactly; the second load is
 * the same texture; sRGB decoding gives linear light. */
static void checkerboard_gives_its_texels(void **state)
{
    fixture *f = *state;
    int size;
    uint8_t *png = checker_png(8, 1, warm, cool, &size);
    char path[128];
    snprintf(path, sizeof path, "%s/checker.png", f->dir);
    write_file(path, png, (size_t)size);
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(f->dev, &r);
    assert_non_null(cache);
    const ob_texture *from_file = ob_texture_cache_load(cache, &(ob_texture_desc){
        .path = path, .sampling = nearest, .context = "test: checker file"}, &r);
    assert_non_null(from_file);
    const ob_texture *from_memory = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .sampling = nearest, .context = "test: checker bytes"}, &r);
    assert_ptr_equal(from_file, from_memory);
    ob_texture_cache_counts counts = ob_texture_cache_get_counts(cache);
    assert_int_equal(counts.images, 1);
    assert_int_equal(counts.textures, 1);
    assert_int_equal(counts.hits, 1);
    ob_texture_info info = ob_texture_get_info(from_file);
    assert_int_equal(info.width, 8);
    assert_int_equal(info.format, VK_FORMAT_R8G8B8A8_UNORM);

    uint8_t img[SIZE * SIZE * 4];
    draw_quad(f, from_file, full_rect, img);
    for (uint32_t ty = 0; ty < 8; ty++)
        for (uint32_t tx = 0; tx < 8; tx++)
            for (uint32_t k = 0; k < 4; k++)   /* corners and middle of the texel's block */
                assert_pixel(img, tx * 8 + (k & 1) * 7, ty * 8 + (k >> 1) * 7, ((tx + ty) & 1) ? cool : warm, 0);

    /* The same bytes as colour data: another image, decoded to linear. */
    const ob_texture *as_srgb = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .srgb = true, .sampling = nearest, .context = "test: sRGB"}, &r);
    assert_non_null(as_srgb);
    assert_ptr_not_equal(as_srgb, from_file);
    assert_int_equal(ob_texture_get_info(as_srgb).format, VK_FORMAT_R8G8B8A8_SRGB);
    assert_int_equal(ob_texture_cache_get_counts(cache).images, 2);
    draw_quad(f, as_srgb, full_rect, img);
    const uint8_t warm_lin[4] = {srgb_decoded(warm[0]), srgb_decoded(warm[1]), srgb_decoded(warm[2]), 255};
    const uint8_t cool_lin[4] = {srgb_decoded(cool[0]), srgb_decoded(cool[1]), srgb_decoded(cool[2]), 255};
    assert_int_equal(warm_lin[0], 128);   /* sRGB 188 is linear 0.5 */
    assert_pixel(img, 4, 4, warm_lin, 1);
    assert_pixel(img, 12, 4, cool_lin, 1);

    /* Another sampling of the same content shares the image, not the sampler. */
    const ob_texture *linear = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .context = "test: linear"}, &r);
    assert_non_null(linear);
    assert_ptr_not_equal(linear, from_file);
    assert_int_equal(ob_texture_image(linear).id, ob_texture_image(from_file).id);
    assert_int_not_equal(ob_texture_sampler(linear).id, ob_texture_sampler(from_file).id);
    counts = ob_texture_cache_get_counts(cache);
    assert_int_equal(counts.images, 2);
    assert_int_equal(counts.samplers, 2);

    ob_texture_cache_destroy(cache);
    ob_free(png);
    ob_test_assert_no_validation(f->dev);
}

/* A missing file and corrupt bytes: NULL, a warning naming the context and
 * the file; the cache keeps serving good textures. */
static void bad_files_warn_and_return_null(void **state)
{
    fixture *f = *state;
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(f->dev, &r);
    assert_non_null(cache);
    ob_resource_counts before = ob_resource_counts_get(f->dev);
    ob_test_log_clear();
    char missing[128];
    snprintf(missing, sizeof missing, "%s/no-such-texture.png", f->dir);
    assert_null(ob_texture_cache_load(cache, &(ob_texture_desc){
        .path = missing, .context = "Box.glb: material 'Red' baseColorTexture"}, &r));
    assert_int_equal(r, OB_ERR_IO);
    assert_true(ob_test_log_has("[WARN]", "Box.glb: material 'Red' baseColorTexture", "no-such-texture.png", NULL) ||
                ob_test_log_has("Box.glb: material 'Red' baseColorTexture", "no-such-texture.png", NULL));

    char corrupt[128];
    snprintf(corrupt, sizeof corrupt, "%s/corrupt.png", f->dir);
    int size;
    uint8_t *png = checker_png(8, 1, warm, cool, &size);
    uint8_t *broken = malloc((size_t)size);
    memcpy(broken, png, (size_t)size);
    memset(broken + 8, 0xA5, (size_t)size - 8);   /* the signature survives, nothing else */
    write_file(corrupt, broken, (size_t)size);
    ob_test_log_clear();
    assert_null(ob_texture_cache_load(cache, &(ob_texture_desc){
        .path = corrupt, .context = "Leaf.gltf: material 'Leaf' normalTexture"}, &r));
    assert_int_equal(r, OB_ERR_PARSE);
    assert_true(ob_test_log_has("Leaf.gltf: material 'Leaf' normalTexture", "corrupt.png", NULL));
    assert_true(ob_test_log_count(OB_LOG_WARN) > 0);
    ob_test_log_clear();
    assert_null(ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = "not an image", .size = 12, .context = "embedded image 3"}, &r));
    assert_true(ob_test_log_has("embedded image 3", "in memory", NULL));
    ob_resource_counts after = ob_resource_counts_get(f->dev);
    assert_int_equal(after.images, before.images);

    /* The rest goes on: a good texture still loads and draws. */
    const ob_texture *good = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .sampling = nearest, .context = "good"}, &r);
    assert_non_null(good);
    uint8_t img[SIZE * SIZE * 4];
    draw_quad(f, good, full_rect, img);
    assert_pixel(img, 0, 0, warm, 0);
    ob_texture_cache_destroy(cache);
    ob_free(png);
    free(broken);
    ob_test_assert_no_validation(f->dev);
}

/* A 64x64 board of single-texel black and white squares: levels =
 * floor(log2(64)) + 1 = 7; drawn 8x8 pixels large, mipmapped sampling
 * averages to grey while level-0-only sampling shows black or white. */
static void minify_through_mips(fixture *f, bool cpu)
{
    static const uint8_t black[4] = {0, 0, 0, 255}, white[4] = {255, 255, 255, 255};
    if (cpu) setenv("OB_TEXTURE_MIPS", "cpu", 1);
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(f->dev, &r);
    unsetenv("OB_TEXTURE_MIPS");
    assert_non_null(cache);
    int size;
    uint8_t *png = checker_png(64, 1, black, white, &size);
    const ob_texture *mipped = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .context = "mipped"}, &r);
    assert_non_null(mipped);
    ob_texture_info info = ob_texture_get_info(mipped);
    assert_int_equal(info.mip_levels, 7);
    assert_int_equal(info.cpu_mips, cpu);
    ob_image_info ii;
    assert_int_equal(ob_image_get_info(f->dev, ob_texture_image(mipped), &ii), OB_OK);
    assert_int_equal(ii.mip_levels, 7);
    const ob_texture *level0 = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .context = "level 0 only",
        .sampling = {.min = OB_TEXTURE_FILTER_NEAREST, .mag = OB_TEXTURE_FILTER_NEAREST, .no_mips = true}}, &r);
    assert_non_null(level0);

    const float small[4] = {-0.125f, -0.125f, 0.125f, 0.125f};  /* 8x8 pixels in the middle */
    uint8_t img[SIZE * SIZE * 4];
    draw_quad(f, mipped, small, img);
    for (uint32_t y = 29; y < 35; y++)
        for (uint32_t x = 29; x < 35; x++) {
            const uint8_t *p = img + 4 * (y * SIZE + x);
            if (abs((int)p[0] - 128) > 8 || abs((int)p[1] - 128) > 8)
                fail_msg("%s mips: pixel (%u, %u) is %u, expected the grey average of black and white",
                         cpu ? "CPU" : "device", x, y, p[0]);
        }
    draw_quad(f, level0, small, img);
    for (uint32_t y = 29; y < 35; y++)
        for (uint32_t x = 29; x < 35; x++) {
            const uint8_t *p = img + 4 * (y * SIZE + x);
            assert_true(p[0] == 0 || p[0] == 255);
        }
    ob_texture_cache_destroy(cache);
    ob_free(png);
    ob_test_assert_no_validation(f->dev);
}

static void mips_made_on_the_device(void **state) { minify_through_mips(*state, false); }
static void mips_made_on_the_cpu(void **state) { minify_through_mips(*state, true); }

/* One texel wider than the device allows: downscaled, with a warning. */
static void oversized_texture_is_downscaled(void **state)
{
    fixture *f = *state;
    const uint32_t limit = ob_device_properties(f->dev)->limits.maxImageDimension2D;
    const uint32_t w = limit + 1, h = 2;
    uint8_t *px = malloc((size_t)w * h * 4);
    assert_non_null(px);
    for (size_t i = 0; i < (size_t)w * h; i++) memcpy(px + 4 * i, warm, 4);
    int size;
    uint8_t *png = stbi_write_png_to_mem(px, (int)w * 4, (int)w, (int)h, 4, &size);
    free(px);
    assert_non_null(png);
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(f->dev, &r);
    ob_test_log_clear();
    const ob_texture *t = ob_texture_cache_load(cache, &(ob_texture_desc){
        .data = png, .size = (size_t)size, .context = "panorama"}, &r);
    assert_non_null(t);
    ob_texture_info info = ob_texture_get_info(t);
    assert_true(info.downscaled);
    assert_true(info.width <= limit);
    assert_int_equal(info.height, 1);
    assert_true(ob_test_log_has("panorama", "downscaled", NULL));
    uint8_t img[SIZE * SIZE * 4];
    draw_quad(f, t, full_rect, img);
    assert_pixel(img, 10, 10, warm, 1);
    ob_texture_cache_destroy(cache);
    ob_free(png);
    ob_test_assert_no_validation(f->dev);
}

/* glTF sampler codes map to the sampling a glTF viewer would use. */
static void gltf_sampler_codes_map(void **state)
{
    (void)state;
    ob_texture_sampling s = ob_texture_sampling_from_gltf(0, 0, 0, 0);
    assert_int_equal(s.mag, OB_TEXTURE_FILTER_DEFAULT);
    assert_int_equal(s.min, OB_TEXTURE_FILTER_DEFAULT);
    assert_false(s.no_mips);
    assert_int_equal(s.wrap_u, OB_TEXTURE_WRAP_REPEAT);
    s = ob_texture_sampling_from_gltf(9728, 9986, 33071, 33648);
    assert_int_equal(s.mag, OB_TEXTURE_FILTER_NEAREST);
    assert_int_equal(s.min, OB_TEXTURE_FILTER_NEAREST);
    assert_int_equal(s.mip, OB_TEXTURE_FILTER_LINEAR);
    assert_int_equal(s.wrap_u, OB_TEXTURE_WRAP_CLAMP);
    assert_int_equal(s.wrap_v, OB_TEXTURE_WRAP_MIRROR);
    s = ob_texture_sampling_from_gltf(9729, 9729, 10497, 10497);
    assert_int_equal(s.min, OB_TEXTURE_FILTER_LINEAR);
    assert_true(s.no_mips);
    s = ob_texture_sampling_from_gltf(9729, 9985, 0, 0);
    assert_int_equal(s.mip, OB_TEXTURE_FILTER_NEAREST);
    assert_false(s.no_mips);
}

/* -------------------------------------------------------------- faults */

typedef struct fault_run {
    uint32_t loaded, failed;
} fault_run;

/* Cache, two loads (a file as sRGB, the bytes as UNORM: two images, one
 * sampler), destroy, and the deferred frees run. */
static fault_run load_and_destroy(fixture *f, const char *path, const uint8_t *png, int size)
{
    fault_run run = {0};
    ob_result r;
    ob_texture_cache *cache = ob_texture_cache_create(f->dev, &r);
    if (!cache) {
        run.failed = 2;
        return run;
    }
    const ob_texture_desc descs[2] = {
        {.path = path, .srgb = true, .context = "fault walk: file"},
        {.data = png, .size = (size_t)size, .context = "fault walk: bytes"},
    };
    for (int i = 0; i < 2; i++) {
        if (ob_texture_cache_load(cache, &descs[i], &r)) run.loaded++;
        else run.failed++;
    }
    ob_texture_cache_destroy(cache);
    ob_device_wait_idle(f->dev);
    ob_device_begin_frame_slot(f->dev, 1);
    ob_device_begin_frame_slot(f->dev, 0);
    return run;
}

static void walk_faults(fixture *f, bool cpu)
{
    int size;
    uint8_t *png = checker_png(16, 2, warm, cool, &size);
    char path[128];
    snprintf(path, sizeof path, "%s/walk.png", f->dir);
    write_file(path, png, (size_t)size);
    if (cpu) setenv("OB_TEXTURE_MIPS", "cpu", 1);
    ob_test_log_set_echo(false);   /* hundreds of expected warnings */
    /* One unarmed run first, so lazily made device objects exist. */
    fault_run run = load_and_destroy(f, path, png, size);
    assert_int_equal(run.loaded, 2);
    ob_resource_counts before = ob_resource_counts_get(f->dev);
    ob_heap_stats heap = ob_heap_stats_now();
    for (int kind = OB_FAULT_HOST_ALLOC; kind <= OB_FAULT_VK_OBJECT; kind++) {
        ob_fault_arm((ob_fault_kind)kind, 0);
        run = load_and_destroy(f, path, png, size);
        uint64_t points = ob_fault_count((ob_fault_kind)kind);
        assert_int_equal(run.loaded, 2);
        assert_true(points > 0);
        for (uint64_t n = 1; n <= points; n++) {
            ob_test_log_clear();
            ob_fault_arm((ob_fault_kind)kind, n);
            run = load_and_destroy(f, path, png, size);
            bool hit = ob_fault_hit((ob_fault_kind)kind);
            ob_fault_arm((ob_fault_kind)kind, 0);
            if (!hit) fail_msg("%s mips, fault kind %d point %llu: never reached", cpu ? "CPU" : "device", kind,
                               (unsigned long long)n);
            if (run.failed && ob_test_log_count(OB_LOG_WARN) == 0)
                fail_msg("fault kind %d point %llu: a load failed without a message", kind, (unsigned long long)n);
            if (ob_test_log_has("[vk-validation]", NULL))
                fail_msg("fault kind %d point %llu: the validation layer spoke", kind, (unsigned long long)n);
            ob_resource_counts now = ob_resource_counts_get(f->dev);
            ob_heap_stats h = ob_heap_stats_now();
            if (now.images != before.images || now.samplers != before.samplers ||
                now.buffers != before.buffers || now.device_bytes != before.device_bytes ||
                h.live_blocks != heap.live_blocks)
                fail_msg("fault kind %d point %llu: resources or host blocks leaked (%u images, %llu blocks; "
                         "before %u, %llu)", kind, (unsigned long long)n, now.images,
                         (unsigned long long)h.live_blocks, before.images, (unsigned long long)heap.live_blocks);
        }
        printf("[ texture  ] %s mips, fault kind %d: %llu points walked\n", cpu ? "CPU" : "device", kind,
               (unsigned long long)points);
    }
    unsetenv("OB_TEXTURE_MIPS");
    ob_test_log_set_echo(true);
    ob_free(png);
    ob_test_assert_no_validation(f->dev);
}

static void loading_survives_every_fault_device_mips(void **state) { walk_faults(*state, false); }
static void loading_survives_every_fault_cpu_mips(void **state) { walk_faults(*state, true); }

int main(void)
{
    ob_test_setup_log();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(checkerboard_gives_its_texels),
        cmocka_unit_test(bad_files_warn_and_return_null),
        cmocka_unit_test(mips_made_on_the_device),
        cmocka_unit_test(mips_made_on_the_cpu),
        cmocka_unit_test(oversized_texture_is_downscaled),
        cmocka_unit_test(gltf_sampler_codes_map),
        cmocka_unit_test(loading_survives_every_fault_device_mips),
        cmocka_unit_test(loading_survives_every_fault_cpu_mips),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
