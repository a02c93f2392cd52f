/* ob_texture.c — texture decoding (stb_image), downscaling (stb_image_resize),
 * CPU mips where the device cannot blit, and the content-hash cache. */
#include "ob_texture.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>
#include <stb_image_resize.h>

typedef struct tex_image {
    uint64_t hash;
    size_t size;            /* encoded bytes: part of the key */
    bool srgb;
    ob_image image;
    ob_texture_info info;
} tex_image;

typedef struct tex_sampler {
    ob_texture_sampling key;   /* normalised */
    ob_sampler sampler;
} tex_sampler;

struct ob_texture {
    tex_image *img;
    tex_sampler *smp;
};

struct ob_texture_cache {
    ob_device *dev;
    bool force_cpu_mips;    /* OB_TEXTURE_MIPS=cpu: walk the CPU path on any device */
    tex_image **images;
    uint32_t image_count, image_cap;
    tex_sampler **samplers;
    uint32_t sampler_count, sampler_cap;
    ob_texture **textures;
    uint32_t texture_count, texture_cap;
    uint32_t loads, hits;
};

ob_texture_cache *ob_texture_cache_create(ob_device *dev, ob_result *out_result)
{
    ob_texture_cache *c = dev ? ob_calloc(1, sizeof *c) : NULL;
    if (!c) {
        ob_result r = dev ? OB_ERR_OUT_OF_HOST_MEMORY : OB_ERR_INVALID_ARGUMENT;
        OB_LOG_E("texture", "texture cache not created: %s", ob_result_name(r));
        if (out_result) *out_result = r;
        return NULL;
    }
    c->dev = dev;
    const char *mips = getenv("OB_TEXTURE_MIPS");
    c->force_cpu_mips = mips && strcmp(mips, "cpu") == 0;
    if (out_result) *out_result = OB_OK;
    return c;
}

void ob_texture_cache_destroy(ob_texture_cache *c)
{
    if (!c) return;
    for (uint32_t i = 0; i < c->texture_count; i++) ob_free(c->textures[i]);
    for (uint32_t i = 0; i < c->image_count; i++) {
        ob_image_destroy(c->dev, c->images[i]->image);
        ob_free(c->images[i]);
    }
    for (uint32_t i = 0; i < c->sampler_count; i++) {
        ob_sampler_destroy(c->dev, c->samplers[i]->sampler);
        ob_free(c->samplers[i]);
    }
    ob_free(c->textures);
    ob_free(c->images);
    ob_free(c->samplers);
    ob_free(c);
}

ob_texture_cache_counts ob_texture_cache_get_counts(const ob_texture_cache *c)
{
    if (!c) return (ob_texture_cache_counts){0};
    return (ob_texture_cache_counts){c->texture_count, c->image_count, c->sampler_count, c->loads, c->hits};
}

ob_image ob_texture_image(const ob_texture *t) { return t ? t->img->image : (ob_image){0}; }
ob_sampler ob_texture_sampler(const ob_texture *t) { return t ? t->smp->sampler : (ob_sampler){0}; }
ob_texture_info ob_texture_get_info(const ob_texture *t) { return t ? t->img->info : (ob_texture_info){0}; }

/* ----------------------------------------------------------------- samplers */

/* Field by field: padding makes memcmp unreliable on this struct. */
static bool sampling_equal(const ob_texture_sampling *a, const ob_texture_sampling *b)
{
    return a->mag == b->mag && a->min == b->min && a->mip == b->mip && a->no_mips == b->no_mips &&
           a->wrap_u == b->wrap_u && a->wrap_v == b->wrap_v;
}

static ob_texture_sampling sampling_normalise(const ob_texture_sampling *s)
{
    ob_texture_sampling n = *s;
    if (n.mag == OB_TEXTURE_FILTER_DEFAULT) n.mag = OB_TEXTURE_FILTER_LINEAR;
    if (n.min == OB_TEXTURE_FILTER_DEFAULT) n.min = OB_TEXTURE_FILTER_LINEAR;
    if (n.mip == OB_TEXTURE_FILTER_DEFAULT) n.mip = OB_TEXTURE_FILTER_LINEAR;
    if (n.no_mips) n.mip = OB_TEXTURE_FILTER_NEAREST;  /* irrelevant: one key for both */
    return n;
}

static bool sampling_valid(const ob_texture_sampling *s)
{
    return (unsigned)s->mag <= OB_TEXTURE_FILTER_LINEAR && (unsigned)s->min <= OB_TEXTURE_FILTER_LINEAR &&
           (unsigned)s->mip <= OB_TEXTURE_FILTER_LINEAR && (unsigned)s->wrap_u <= OB_TEXTURE_WRAP_MIRROR &&
           (unsigned)s->wrap_v <= OB_TEXTURE_WRAP_MIRROR;
}

static ob_texture_wrap gltf_wrap(uint32_t code)
{
    return code == 33071 ? OB_TEXTURE_WRAP_CLAMP : code == 33648 ? OB_TEXTURE_WRAP_MIRROR : OB_TEXTURE_WRAP_REPEAT;
}

ob_texture_sampling ob_texture_sampling_from_gltf(uint32_t mag_filter, uint32_t min_filter, uint32_t wrap_s,
                                                  uint32_t wrap_t)
{
    ob_texture_sampling s = {.wrap_u = gltf_wrap(wrap_s), .wrap_v = gltf_wrap(wrap_t)};
    if (mag_filter == 9728) s.mag = OB_TEXTURE_FILTER_NEAREST;
    else if (mag_filter == 9729) s.mag = OB_TEXTURE_FILTER_LINEAR;
    switch (min_filter) {
    case 9728: s.min = OB_TEXTURE_FILTER_NEAREST; s.no_mips = true; break;
    case 9729: s.min = OB_TEXTURE_FILTER_LINEAR; s.no_mips = true; break;
    case 9984: s.min = OB_TEXTURE_FILTER_NEAREST; s.mip = OB_TEXTURE_FILTER_NEAREST; break;
    case 9985: s.min = OB_TEXTURE_FILTER_LINEAR; s.mip = OB_TEXTURE_FILTER_NEAREST; break;
    case 9986: s.min = OB_TEXTURE_FILTER_NEAREST; s.mip = OB_TEXTURE_FILTER_LINEAR; break;
    case 9987: s.min = OB_TEXTURE_FILTER_LINEAR; s.mip = OB_TEXTURE_FILTER_LINEAR; break;
    default: break;
    }
    return s;
}

static VkSamplerAddressMode vk_wrap(ob_texture_wrap w)
{
    return w == OB_TEXTURE_WRAP_CLAMP    ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
           : w == OB_TEXTURE_WRAP_MIRROR ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                                         : VK_SAMPLER_ADDRESS_MODE_REPEAT;
}

static VkFilter vk_filter(ob_texture_filter f) { return f == OB_TEXTURE_FILTER_NEAREST ? VK_FILTER_NEAREST : VK_FILTER_LINEAR; }

/* The cache's sampler for key (normalised), created on first need. The
 * array has room for one more (reserved by the caller). */
static tex_sampler *sampler_get(ob_texture_cache *c, const ob_texture_sampling *key, ob_result *out_result)
{
    for (uint32_t i = 0; i < c->sampler_count; i++)
        if (sampling_equal(&c->samplers[i]->key, key)) return c->samplers[i];
    tex_sampler *s = ob_calloc(1, sizeof *s);
    if (!s) {
        *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
        return NULL;
    }
    s->key = *key;
    char name[64];
    snprintf(name, sizeof name, "texture sampler %u", c->sampler_count);
    ob_sampler_desc sd = {
        .name = name,
        .detailed = true,
        .mag_filter = vk_filter(key->mag),
        .min_filter = vk_filter(key->min),
        .mipmap_mode = key->mip == OB_TEXTURE_FILTER_NEAREST ? VK_SAMPLER_MIPMAP_MODE_NEAREST
                                                             : VK_SAMPLER_MIPMAP_MODE_LINEAR,
        .address_u = vk_wrap(key->wrap_u),
        .address_v = vk_wrap(key->wrap_v),
        .max_lod = key->no_mips ? 0.0f : VK_LOD_CLAMP_NONE,
    };
    s->sampler = ob_sampler_create(c->dev, &sd, out_result);
    if (!s->sampler.id) {
        ob_free(s);
        return NULL;
    }
    c->samplers[c->sampler_count++] = s;
    return s;
}

/* ------------------------------------------------------------------- pixels */

/* sRGB ↔ linear for the CPU box filter (colour data is averaged as light). */
static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}
static uint8_t linear_to_srgb8(float l)
{
    float c = l <= 0.0031308f ? l * 12.92f : 1.055f * powf(l, 1.0f / 2.4f) - 0.055f;
    c = c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c;
    return (uint8_t)lrintf(c * 255.0f);
}

static size_t level_bytes(uint32_t w, uint32_t h, uint32_t level)
{
    return (size_t)OB_MAX(w >> level, 1u) * OB_MAX(h >> level, 1u) * 4;
}

/* Every level of an RGBA8 image, level 0 first, each made from the one
 * above by a 2x2 box (an odd last row or column of the level above is
 * dropped, like a blit's footprint at that size). NULL when out of memory. */
static uint8_t *cpu_mip_chain(const uint8_t *base, uint32_t w, uint32_t h, uint32_t levels, bool srgb,
                              size_t *out_size)
{
    size_t total = 0;
    for (uint32_t l = 0; l < levels; l++) total += level_bytes(w, h, l);
    uint8_t *out = ob_malloc(total);
    if (!out) return NULL;
    float lut[256];
    for (int i = 0; i < 256; i++) lut[i] = srgb ? srgb_to_linear(i / 255.0f) : i / 255.0f;
    memcpy(out, base, level_bytes(w, h, 0));
    const uint8_t *src = out;
    uint8_t *dst = out + level_bytes(w, h, 0);
    for (uint32_t l = 1; l < levels; l++) {
        uint32_t sw = OB_MAX(w >> (l - 1), 1u), sh = OB_MAX(h >> (l - 1), 1u);
        uint32_t dw = OB_MAX(w >> l, 1u), dh = OB_MAX(h >> l, 1u);
        for (uint32_t y = 0; y < dh; y++) {
            for (uint32_t x = 0; x < dw; x++) {
                uint32_t x0 = OB_MIN(2 * x, sw - 1), x1 = OB_MIN(2 * x + 1, sw - 1);
                uint32_t y0 = OB_MIN(2 * y, sh - 1), y1 = OB_MIN(2 * y + 1, sh - 1);
                const uint8_t *p[4] = {src + 4 * ((size_t)y0 * sw + x0), src + 4 * ((size_t)y0 * sw + x1),
                                       src + 4 * ((size_t)y1 * sw + x0), src + 4 * ((size_t)y1 * sw + x1)};
                uint8_t *d = dst + 4 * ((size_t)y * dw + x);
                for (int ch = 0; ch < 3; ch++) {
                    float sum = lut[p[0][ch]] + lut[p[1][ch]] + lut[p[2][ch]] + lut[p[3][ch]];
                    d[ch] = srgb ? linear_to_srgb8(sum * 0.25f) : (uint8_t)lrintf(sum * 0.25f * 255.0f);
                }
                d[3] = (uint8_t)((p[0][3] + p[1][3] + p[2][3] + p[3][3] + 2) / 4);
            }
        }
        src = dst;
        dst += level_bytes(w, h, l);
    }
    *out_size = total;
    return out;
}

/* Decodes bytes, fits them to the device, makes the mips and uploads.
 * `what` names the source for messages. */
static ob_result image_create(ob_texture_cache *c, const ob_texture_desc *desc, const uint8_t *bytes, size_t size,
                              const char *context, const char *what, tex_image *out)
{
    int w = 0, h = 0, comp = 0;
    /* The header first: a 1 MB PNG may declare 16384x16384 (1 GiB of RGBA)
     * and the decoder would commit it before finding the data short. */
    if (!stbi_info_from_memory(bytes, (int)size, &w, &h, &comp)) {
        const char *why = stbi_failure_reason();
        OB_LOG_W("texture", "%s: cannot decode %s: not an image stb_image reads (%s)", context, what,
                 why && *why ? why : "unknown header");
        return OB_ERR_PARSE;
    }
    if ((uint64_t)w * (uint64_t)h > OB_TEXTURE_MAX_PIXELS) {
        OB_LOG_W("texture", "%s: %s declares %dx%d pixels, more than the limit of %u; not decoded", context,
                 what, w, h, OB_TEXTURE_MAX_PIXELS);
        return OB_ERR_LIMIT;
    }
    uint8_t *pixels = stbi_load_from_memory(bytes, (int)size, &w, &h, &comp, 4);
    if (!pixels) {
        const char *why = stbi_failure_reason();
        bool oom = why && strcmp(why, "outofmem") == 0;
        /* stb says little ("", "bad png"); a short file is the common case. */
        OB_LOG_W("texture", "%s: cannot decode %s: %s (a %dx%d image in %zu bytes: truncated or corrupt "
                 "data?)", context, what, why && *why ? why : "the decoder gave no reason", w, h, size);
        return oom ? OB_ERR_OUT_OF_HOST_MEMORY : OB_ERR_PARSE;
    }
    ob_result r = OB_OK;
    uint32_t width = (uint32_t)w, height = (uint32_t)h;
    const uint32_t limit = ob_device_properties(c->dev)->limits.maxImageDimension2D;
    out->info.downscaled = width > limit || height > limit;
    if (out->info.downscaled) {
        double scale = (double)limit / (double)OB_MAX(width, height);
        uint32_t nw = OB_MAX((uint32_t)(width * scale), 1u), nh = OB_MAX((uint32_t)(height * scale), 1u);
        nw = OB_MIN(nw, limit);
        nh = OB_MIN(nh, limit);
        uint8_t *small = ob_malloc((size_t)nw * nh * 4);
        int ok = small && (desc->srgb ? stbir_resize_uint8_srgb(pixels, w, h, 0, small, (int)nw, (int)nh, 0, 4, 3, 0)
                                      : stbir_resize_uint8(pixels, w, h, 0, small, (int)nw, (int)nh, 0, 4));
        if (!ok) {
            ob_free(small);
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            OB_LOG_W("texture", "%s: %s (%ux%u) could not be downscaled: %s", context, what, width, height,
                     ob_result_name(r));
            goto done;
        }
        OB_LOG_W("texture", "%s: %s is %ux%u, larger than this device's limit of %u texels a side: "
                            "downscaled to %ux%u", context, what, width, height, limit, nw, nh);
        stbi_image_free(pixels);
        pixels = small;
        width = nw;
        height = nh;
    }
    VkFormat format = desc->srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
    uint32_t levels = ob_image_mip_levels_max(width, height);
    bool cpu = levels > 1 && (c->force_cpu_mips || !ob_image_format_blits_linear(c->dev, format));
    uint8_t *chain = NULL;
    size_t chain_size = 0;
    if (cpu) {
        chain = cpu_mip_chain(pixels, width, height, levels, desc->srgb, &chain_size);
        if (!chain) {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            OB_LOG_W("texture", "%s: no memory for the mip levels of %s", context, what);
            goto done;
        }
        OB_LOG_I("texture", "%s: %u mip levels made on the CPU (format %d has no linear blit here)", context,
                 levels, (int)format);
    }
    ob_image_desc id = {
        .width = width,
        .height = height,
        .format = format,
        .usage = OB_IMAGE_SAMPLED,
        .data = cpu ? (const void *)chain : (const void *)pixels,
        .name = context,
        .mip_levels = levels,
        .data_mips = cpu,
    };
    out->image = ob_image_create(c->dev, &id, &r);
    ob_free(chain);
    if (!out->image.id) {
        OB_LOG_W("texture", "%s: %s decoded (%ux%u) but its image was not created: %s", context, what, width,
                 height, ob_result_name(r));
        goto done;
    }
    out->info.width = width;
    out->info.height = height;
    out->info.mip_levels = levels;
    out->info.format = format;
    out->info.cpu_mips = cpu;
done:
    /* stb's and ours both come from ob_malloc (STBI_FREE is ob_free). */
    stbi_image_free(pixels);
    return r;
}

/* --------------------------------------------------------------------- load */

static ob_result reserve_all(ob_texture_cache *c)
{
    ob_result r = ob_array_reserve((void **)&c->images, &c->image_cap, c->image_count + 1, sizeof *c->images);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&c->samplers, &c->sampler_cap, c->sampler_count + 1, sizeof *c->samplers);
    if (r == OB_OK)
        r = ob_array_reserve((void **)&c->textures, &c->texture_cap, c->texture_count + 1, sizeof *c->textures);
    return r;
}

const ob_texture *ob_texture_cache_load(ob_texture_cache *c, const ob_texture_desc *desc, ob_result *out_result)
{
    ob_result r = OB_OK;
    const char *context = desc && desc->context ? desc->context : "texture";
    char what[300];
    snprintf(what, sizeof what, "'%s'", desc && desc->path ? desc->path : "(encoded bytes in memory)");
    uint8_t *file = NULL;
    const uint8_t *bytes = NULL;
    size_t size = 0;
    tex_image *img = NULL;
    bool new_image = false;
    if (!c || !desc || (!desc->path && (!desc->data || desc->size == 0)) || !sampling_valid(&desc->sampling) ||
        desc->size > (size_t)INT32_MAX) {
        OB_LOG_W("texture", "%s: texture %s not loaded: no cache, no file or bytes, too many bytes, or a "
                            "sampling value out of range", context, what);
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_free_decoded;
    }
    r = reserve_all(c);
    if (r != OB_OK) goto fail_log;
    if (desc->path) {
        file = (uint8_t *)ob_file_read(desc->path, &size, &r);
        if (!file) goto fail_log;
        if (size == 0 || size > (size_t)INT32_MAX) {
            OB_LOG_W("texture", "%s: %s is %s", context, what, size ? "too large" : "empty");
            r = OB_ERR_PARSE;
            goto fail_free_decoded;
        }
        bytes = file;
    } else {
        bytes = desc->data;
        size = desc->size;
    }
    const uint64_t hash = ob_hash_bytes(OB_HASH_SEED, bytes, size);
    for (uint32_t i = 0; i < c->image_count && !img; i++)
        if (c->images[i]->hash == hash && c->images[i]->size == size && c->images[i]->srgb == desc->srgb)
            img = c->images[i];
    ob_texture_sampling key = sampling_normalise(&desc->sampling);
    tex_sampler *smp = sampler_get(c, &key, &r);
    if (!smp) goto fail_log;
    if (!img) {
        img = ob_calloc(1, sizeof *img);
        if (!img) {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            goto fail_log;
        }
        new_image = true;
        img->hash = hash;
        img->size = size;
        img->srgb = desc->srgb;
        img->info.hash = hash;
        r = image_create(c, desc, bytes, size, context, what, img);
        if (r != OB_OK) goto fail_free_decoded; /* logged with the reason */
        c->images[c->image_count++] = img;
    }
    ob_free(file);
    file = NULL;
    for (uint32_t i = 0; i < c->texture_count; i++) {
        if (c->textures[i]->img == img && c->textures[i]->smp == smp) {
            c->loads++;
            c->hits++;
            if (out_result) *out_result = OB_OK;
            return c->textures[i];
        }
    }
    ob_texture *t = ob_calloc(1, sizeof *t);
    if (!t) {
        /* The image stays cached (it is valid); only this pairing failed. */
        new_image = false;
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    t->img = img;
    t->smp = smp;
    c->textures[c->texture_count++] = t;
    c->loads++;
    if (!new_image) c->hits++;
    if (out_result) *out_result = OB_OK;
    return t;

fail_log:
    OB_LOG_W("texture", "%s: texture %s not loaded: %s", context, what, ob_result_name(r));
fail_free_decoded:
    if (new_image) ob_free(img);
    ob_free(file);
    if (out_result) *out_result = r;
    return NULL;
}
