/* ob_stb_impl.c — the one translation unit that compiles stb_image,
 * stb_image_write and stb_image_resize (textures above the device limit). Everyone else includes the headers without the
 * IMPLEMENTATION defines and links against these definitions.
 *
 * Their allocations go through ob_malloc & co., so fault injection reaches
 * them too; memory they return (stbi_load*) is freed with stbi_image_free.
 * PNGs are deflated by zlib (below), whose failures are reported.
 */
#include "ob_resources_internal.h"

#include <limits.h>
#include <stdint.h>
#include <zlib.h>

static voidpf ob_zlib_alloc(voidpf opaque, uInt items, uInt size)
{
    (void)opaque;
    if (size && items > SIZE_MAX / size) return Z_NULL;
    return ob_malloc((size_t)items * size);
}

static void ob_zlib_free(voidpf opaque, voidpf p)
{
    (void)opaque;
    ob_free(p);
}

uint8_t *ob_res_deflate(const uint8_t *data, size_t len, int level, size_t *out_len)
{
    z_stream zs = {.zalloc = ob_zlib_alloc, .zfree = ob_zlib_free};
    if (len > UINT_MAX || deflateInit(&zs, level < 1 ? 1 : level > 9 ? 9 : level) != Z_OK) return NULL;
    uLong bound = deflateBound(&zs, (uLong)len);
    uint8_t *out = bound <= UINT_MAX ? ob_malloc(bound) : NULL;
    if (!out) {
        deflateEnd(&zs);
        return NULL;
    }
    zs.next_in = (Bytef *)data;   /* zlib does not write through it */
    zs.avail_in = (uInt)len;
    zs.next_out = out;
    zs.avail_out = (uInt)bound;
    int z = deflate(&zs, Z_FINISH);
    *out_len = zs.total_out;
    deflateEnd(&zs);
    if (z != Z_STREAM_END) {
        ob_free(out);
        return NULL;
    }
    return out;
}

#define STBI_MALLOC(sz) ob_malloc(sz)
#define STBI_REALLOC(p, newsz) ob_realloc(p, newsz)
#define STBI_FREE(p) ob_free(p)
#define STBIW_MALLOC(sz) ob_malloc(sz)
#define STBIW_REALLOC(p, newsz) ob_realloc(p, newsz)
#define STBIW_FREE(p) ob_free(p)

/* stb_image_write's own deflate grows its buffers with an unchecked realloc:
 * a failed allocation there writes past the old buffer (issue 25.10). Its
 * PNG writer uses zlib instead (ob_res_deflate), which reports every
 * failure; stb frees the result with STBIW_FREE. The engine's own PNGs go
 * through ob_readback.c's encoder, which frees everything on every failure
 * (stbi_write_png_to_mem leaks the deflated data when its last allocation
 * fails). */
static unsigned char *ob_stbiw_zlib_compress(unsigned char *data, int data_len, int *out_len, int quality)
{
    size_t len = 0;
    uint8_t *out = data_len >= 0 ? ob_res_deflate(data, (size_t)data_len, quality, &len) : NULL;
    if (out && len > INT_MAX) {
        ob_free(out);
        out = NULL;
    }
    if (out) *out_len = (int)len;
    return out;
}
#define STBIW_ZLIB_COMPRESS ob_stbiw_zlib_compress
#define STBIR_MALLOC(sz, ctx) ((void)(ctx), ob_malloc(sz))
#define STBIR_FREE(p, ctx) ((void)(ctx), ob_free(p))

/* Third-party code: its warnings are not ours to fix. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wtype-limits"
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
#define STB_IMAGE_RESIZE_IMPLEMENTATION
#include <stb_image_resize.h>
#pragma GCC diagnostic pop
