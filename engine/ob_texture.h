/* ob_texture.h — textures decoded with stb_image, uploaded with a mip chain,
 * and shared through a cache.
 *
 * A texture is an RGBA8 image (R8G8B8A8_SRGB for colour data such as base
 * colour and emissive, R8G8B8A8_UNORM for data maps such as normals or
 * metallic-roughness) with every mip level down to 1x1, plus a sampler.
 * Mips are made on the device with a chain of linear blits when the format
 * supports linear blit filtering, else on the CPU (a 2x2 box filter, in
 * linear space for sRGB data) and uploaded with the image; the log says
 * which at INFO level. An image wider or taller than the device's
 * maxImageDimension2D is downscaled first (stb_image_resize), with a warning.
 *
 * Sharing: the cache keys images by a 64-bit hash of the encoded bytes (the
 * file's content, not its name), their size and the srgb flag, so the same
 * picture in two files, or embedded twice, is decoded and uploaded once.
 * Samplers are keyed by their (normalised) ob_texture_sampling. A texture is
 * the pair (image, sampler): loading the same bytes with the same sampling
 * returns the same ob_texture pointer.
 *
 * Lifecycle: cache_create → load* → (frames sample the textures) →
 * cache_destroy, which destroys every image and sampler (deferred by the
 * device until frames that used them are done). Textures are owned by their
 * cache and live as long as it does.
 *
 * Thread rule: create, load and destroy are [render thread, not while
 * recording] (they create resources); ob_texture_image/_sampler/_info are
 * [any thread].
 *
 * Failure: load returns NULL, sets *out_result and logs one warning naming
 * desc->context and the file (or "bytes in memory"): a missing file
 * (OB_ERR_IO), bytes stb_image cannot decode (OB_ERR_PARSE, with stb's
 * reason), or a resource that could not be created (its result). Nothing is
 * left behind and the cache stays usable. A failed load is not remembered:
 * loading again tries again.
 */
#ifndef OB_TEXTURE_H
#define OB_TEXTURE_H

#include "ob_resources.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Pixels an image may declare (width x height, read from its header before
 * decoding): 8192 x 8192, 256 MiB of RGBA8. A larger image is refused
 * (OB_ERR_LIMIT, logged) without being decoded. */
#define OB_TEXTURE_MAX_PIXELS (8192u * 8192u)

typedef struct ob_texture_cache ob_texture_cache;
typedef struct ob_texture ob_texture; /* owned by its cache */

typedef enum ob_texture_filter {
    OB_TEXTURE_FILTER_DEFAULT = 0,
    OB_TEXTURE_FILTER_NEAREST,
    OB_TEXTURE_FILTER_LINEAR
} ob_texture_filter;

typedef enum ob_texture_wrap {
    OB_TEXTURE_WRAP_REPEAT = 0,
    OB_TEXTURE_WRAP_CLAMP,
    OB_TEXTURE_WRAP_MIRROR
} ob_texture_wrap;

typedef struct ob_texture_sampling {
    ob_texture_filter mag, min;  /* DEFAULT → LINEAR */
    ob_texture_filter mip;       /* between mip levels; DEFAULT → LINEAR */
    bool no_mips;                /* sample level 0 only (glTF min filter NEAREST/LINEAR) */
    ob_texture_wrap wrap_u, wrap_v;
} ob_texture_sampling;

/* The sampling of a glTF 2 sampler from its numeric codes (0 = unspecified
 * → the default): mag 9728 NEAREST / 9729 LINEAR; min 9728 NEAREST and 9729
 * LINEAR (no mips), 9984..9987 NEAREST_MIPMAP_NEAREST, LINEAR_MIPMAP_NEAREST,
 * NEAREST_MIPMAP_LINEAR, LINEAR_MIPMAP_LINEAR; wrap 10497 REPEAT, 33071
 * CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT. An unknown code is taken as
 * unspecified. [any thread] */
ob_texture_sampling ob_texture_sampling_from_gltf(uint32_t mag_filter, uint32_t min_filter, uint32_t wrap_s,
                                                  uint32_t wrap_t);

typedef struct ob_texture_desc {
    const char *path;            /* an image file stb_image reads (PNG, JPEG, ...), or ... */
    const void *data;            /* ... encoded image bytes in memory (.glb buffer view, */
    size_t size;                 /*     decoded data URI); used when path is NULL */
    bool srgb;                   /* colour data → *_SRGB; data maps → UNORM */
    ob_texture_sampling sampling;
    const char *context;         /* for messages: "BoxTextured.glb: material 'Texture' baseColorTexture" */
} ob_texture_desc;

typedef struct ob_texture_info {
    uint32_t width, height;      /* of level 0, after any downscaling */
    uint32_t mip_levels;         /* floor(log2(max(width, height))) + 1 */
    VkFormat format;             /* R8G8B8A8_SRGB or R8G8B8A8_UNORM */
    bool downscaled;             /* the source exceeded maxImageDimension2D */
    bool cpu_mips;               /* mips were made on the CPU (no linear blit for the format) */
    uint64_t hash;               /* the cache key's content hash */
} ob_texture_info;

typedef struct ob_texture_cache_counts {
    uint32_t textures, images, samplers;
    uint32_t loads, hits;        /* successful load calls; of those, served from the cache */
} ob_texture_cache_counts;

/* dev must outlive the cache. Failure: NULL, *out_result
 * (OB_ERR_OUT_OF_HOST_MEMORY), logged. [render thread] */
ob_texture_cache *ob_texture_cache_create(ob_device *dev, ob_result *out_result);
/* Destroys every texture, image and sampler of the cache (resource
 * destruction is deferred past pending frames). NULL ok. [render thread] */
void ob_texture_cache_destroy(ob_texture_cache *cache);

/* The texture for desc, loaded on first request. Identical content (hash of
 * the encoded bytes + size + srgb) is decoded and uploaded once and shared.
 * Failure: NULL, *out_result, a warning naming desc->context and the file;
 * nothing leaked. [render thread, not while recording] */
const ob_texture *ob_texture_cache_load(ob_texture_cache *cache, const ob_texture_desc *desc,
                                        ob_result *out_result);
ob_texture_cache_counts ob_texture_cache_get_counts(const ob_texture_cache *cache);

/* The texture's image (all mip levels) and sampler; zero handles for NULL.
 * [any thread] */
ob_image ob_texture_image(const ob_texture *t);
ob_sampler ob_texture_sampler(const ob_texture *t);
/* Zeroes for NULL. [any thread] */
ob_texture_info ob_texture_get_info(const ob_texture *t);

#ifdef __cplusplus
}
#endif
#endif /* OB_TEXTURE_H */
