/* ob_model_material.c — assimp materials into ob_model_material, and the
 * images their textures use into ob_model_image (ob_model.h says what is
 * mapped from which format; this file is how).
 *
 * Which assimp keys (5.2, see its glTF2Importer and ObjFileImporter):
 * glTF sets AI_MATKEY_BASE_COLOR, METALLIC_FACTOR, ROUGHNESS_FACTOR,
 * COLOR_EMISSIVE, TWOSIDED, GLTF_ALPHAMODE / ALPHACUTOFF, and the textures
 * as BASE_COLOR (and DIFFUSE), UNKNOWN slot 0 (metallicRoughness; also
 * METALNESS and DIFFUSE_ROUGHNESS), NORMALS (+ GLTF_TEXTURE_SCALE), LIGHTMAP
 * (occlusion, + GLTF_TEXTURE_STRENGTH) and EMISSIVE, each with UVWSRC,
 * MAPPINGMODE_U/V and, when the sampler has them, GLTF_MAPPINGFILTER_MAG/MIN.
 * The presence of GLTF_ALPHAMODE tells a glTF 2 material: only then are
 * UNKNOWN and LIGHTMAP read as metallicRoughness and occlusion (in other
 * formats they mean something else). OBJ sets COLOR_DIFFUSE, OPACITY (d,
 * or 1 − Tr), SHININESS (Ns), COLOR_EMISSIVE, DIFFUSE / HEIGHT (map_Bump,
 * bump) / NORMALS (norm) textures and OBJ_BUMPMULT (-bm).
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_model.h"
#include "ob_model_internal.h"

#include <assimp/GltfMaterial.h>
#include <assimp/ObjMaterial.h>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* stb is compiled once in engine/ob_stb_impl.c (its allocations go through
 * ob_malloc). Only the declarations are needed here. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstrict-prototypes"
#include <stb_image.h>
#include <stb_image_write.h>
#pragma GCC diagnostic pop

/* Raw embedded textures larger than this are refused (they would be 256 MiB
 * of texels); compressed ones are passed on at any size. */
#define OB_MODEL_RAW_TEXTURE_MAX 8192u

typedef struct material_ctx {
    ob_model_check *chk;
    const struct aiScene *scene;
    ob_model *model;
    uint32_t image_cap;
    int32_t *embedded_image;   /* per scene texture: its image index, -1 not yet */
    char *dir;                 /* the model's folder, with a trailing '/', or "" */
    bool flip_uv;              /* the meshes' uv convention (ob_model_desc.flip_uv) */
    bool gltf;                 /* the material being read is glTF's (its uv transforms are) */
} material_ctx;

typedef struct slot_info {
    const char *material;      /* name, for messages */
    uint32_t material_index;
    const char *slot;          /* "baseColorTexture", … */
} slot_info;

/* ------------------------------------------------------------ images */

static char *dup_range(const char *s, size_t n)
{
    char *d = ob_malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, s, n);
    d[n] = '\0';
    return d;
}

static ob_result add_image(material_ctx *c, ob_model_image **out)
{
    ob_model *m = c->model;
    if (ob_array_reserve((void **)&m->images, &c->image_cap, m->image_count + 1,
                         sizeof *m->images) != OB_OK) {
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory for image %u", c->chk->path, m->image_count);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    *out = &m->images[m->image_count++];
    memset(*out, 0, sizeof **out);
    return OB_OK;
}

typedef struct png_sink {
    uint8_t *data;
    size_t size, cap;
    bool failed;
} png_sink;

static void png_write(void *context, void *bytes, int size)
{
    png_sink *s = context;
    if (s->failed || size <= 0) return;
    if (s->size + (size_t)size > s->cap) {
        size_t cap = s->cap ? s->cap * 2 : 4096;
        while (cap < s->size + (size_t)size) cap *= 2;
        uint8_t *grown = ob_realloc(s->data, cap);
        if (!grown) {
            s->failed = true;
            return;
        }
        s->data = grown;
        s->cap = cap;
    }
    memcpy(s->data + s->size, bytes, (size_t)size);
    s->size += (size_t)size;
}

/* assimp's uncompressed texels (BGRA8, row after row) as a PNG. */
static ob_result encode_raw(material_ctx *c, const struct aiTexture *t, uint32_t index,
                            ob_model_image *img)
{
    if (t->mWidth > OB_MODEL_RAW_TEXTURE_MAX || t->mHeight > OB_MODEL_RAW_TEXTURE_MAX) {
        ob_model_bad(c->chk, "embedded texture %u is %ux%u texels, over the %u limit", index,
                     t->mWidth, t->mHeight, OB_MODEL_RAW_TEXTURE_MAX);
        return OB_ERR_BAD_MODEL;
    }
    size_t count = (size_t)t->mWidth * t->mHeight;
    uint8_t *rgba = ob_malloc(count * 4);
    if (!rgba) {
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory converting embedded texture %u", c->chk->path, index);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    for (size_t i = 0; i < count; i++) {
        rgba[4 * i + 0] = t->pcData[i].r;
        rgba[4 * i + 1] = t->pcData[i].g;
        rgba[4 * i + 2] = t->pcData[i].b;
        rgba[4 * i + 3] = t->pcData[i].a;
    }
    png_sink sink = {0};
    int ok = stbi_write_png_to_func(png_write, &sink, (int)t->mWidth, (int)t->mHeight, 4, rgba,
                                    (int)t->mWidth * 4);
    ob_free(rgba);
    if (!ok || sink.failed) {
        ob_free(sink.data);
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory encoding embedded texture %u as PNG",
                 c->chk->path, index);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    img->data = sink.data;
    img->size = sink.size;
    return OB_OK;
}

static const char *short_name(const char *s)
{
    const char *a = strrchr(s, '/'), *b = strrchr(s, '\\');
    const char *last = a > b ? a : b;
    return last ? last + 1 : s;
}

/* The scene texture a reference names ("*N", or an embedded texture's file
 * name, as aiScene::GetEmbeddedTexture matches them), -1 for none. */
static int32_t embedded_index(const struct aiScene *s, const char *ref)
{
    if (ref[0] == '*') {
        char *end;
        long n = strtol(ref + 1, &end, 10);
        if (end == ref + 1 || *end || n < 0 || (unsigned long)n >= s->mNumTextures) return -1;
        return s->mTextures && s->mTextures[n] ? (int32_t)n : -1;
    }
    const char *want = short_name(ref);
    for (uint32_t i = 0; i < s->mNumTextures && s->mTextures; i++) {
        const struct aiTexture *t = s->mTextures[i];
        if (t && t->mFilename.length && strcmp(short_name(t->mFilename.data), want) == 0)
            return (int32_t)i;
    }
    return -1;
}

static ob_result embedded_image(material_ctx *c, uint32_t index, const char *ref, int32_t *out)
{
    if (c->embedded_image[index] >= 0) {
        *out = c->embedded_image[index];
        return OB_OK;
    }
    const struct aiTexture *t = c->scene->mTextures[index];
    if (!t->pcData || !t->mWidth) {
        ob_model_bad(c->chk, "embedded texture %u ('%s') has no data", index, ref);
        return OB_ERR_BAD_MODEL;
    }
    ob_model_image *img;
    ob_result r = add_image(c, &img);
    if (r != OB_OK) return r;
    const char *name = t->mFilename.length ? t->mFilename.data : ref;
    img->name = ob_strdup(name);
    if (!img->name) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_model_sanitize_text(img->name, strlen(img->name));
    if (t->mHeight == 0) {   /* compressed: mWidth bytes of a PNG, JPEG, … file */
        img->data = ob_malloc(t->mWidth);
        if (!img->data) return OB_ERR_OUT_OF_HOST_MEMORY;
        memcpy(img->data, t->pcData, t->mWidth);
        img->size = t->mWidth;
    } else {
        r = encode_raw(c, t, index, img);
        if (r != OB_OK) return r;
    }
    *out = c->embedded_image[index] = (int32_t)(c->model->image_count - 1);
    return OB_OK;
}

static bool is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* Why an image path is not a readable file: "not found", "a FIFO, not a
 * regular file", ... */
static const char *why_not_file(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return errno == ENOENT || errno == ENOTDIR ? "not found" : strerror(errno);
    return S_ISDIR(st.st_mode) ? "a directory, not a regular file"
           : S_ISFIFO(st.st_mode) ? "a FIFO, not a regular file"
           : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device, not a regular file"
           : "not a regular file";
}

/* "%20" and friends decoded (glTF URIs are URI-encoded); NULL when out of
 * memory or nothing to decode. */
static char *percent_decoded(const char *s)
{
    if (!strchr(s, '%')) return NULL;
    char *d = ob_malloc(strlen(s) + 1), *o = d;
    if (!d) return NULL;
    for (const char *p = s; *p; p++) {
        unsigned v;
        if (p[0] == '%' && p[1] && p[2] && sscanf(p + 1, "%2x", &v) == 1 && v) {
            *o++ = (char)v;
            p += 2;
        } else {
            *o++ = *p;
        }
    }
    *o = '\0';
    return d;
}

static char *join_path(const char *dir, const char *ref)
{
    size_t a = ref[0] == '/' ? 0 : strlen(dir), b = strlen(ref);
    char *p = ob_malloc(a + b + 1);
    if (!p) return NULL;
    memcpy(p, dir, a);
    memcpy(p + a, ref, b + 1);
    for (char *q = p + a; *q; q++)
        if (*q == '\\') *q = '/';   /* Windows-made OBJ/MTL files */
    return p;
}

static ob_result external_image(material_ctx *c, const slot_info *si, const char *ref, int32_t *out)
{
    *out = -1;
    char *path = join_path(c->dir, ref);
    if (!path) return OB_ERR_OUT_OF_HOST_MEMORY;
    if (!is_file(path)) {
        char *decoded = percent_decoded(ref);
        char *alt = decoded ? join_path(c->dir, decoded) : NULL;
        ob_free(decoded);
        if (alt && is_file(alt)) {
            ob_free(path);
            path = alt;
        } else {
            ob_free(alt);
            OB_LOG_W(OB_MODEL_LOG, "%s: material %u '%s' %s: image file '%s' %s; the "
                     "material uses its factors instead", c->chk->path, si->material_index,
                     si->material, si->slot, path, why_not_file(path));
            ob_free(path);
            return OB_OK;
        }
    }
    char why[512];
    if (c->chk->io && !ob_model_io_inside(c->chk->io, path, why, sizeof why)) {
        OB_LOG_E(OB_MODEL_LOG, "%s: material %u '%s' %s: refused to read image '%s': %s",
                 c->chk->path, si->material_index, si->material, si->slot, ref, why);
        ob_free(path);
        return OB_ERR_IO;
    }
    for (uint32_t i = 0; i < c->model->image_count; i++) {
        const ob_model_image *img = &c->model->images[i];
        if (img->path && strcmp(img->path, path) == 0) {
            ob_free(path);
            *out = (int32_t)i;
            return OB_OK;
        }
    }
    ob_model_image *img;
    ob_result r = add_image(c, &img);
    if (r != OB_OK) {
        ob_free(path);
        return r;
    }
    img->path = path;
    img->name = ob_strdup(ref);
    if (!img->name) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_model_sanitize_text(img->name, strlen(img->name));
    *out = (int32_t)(c->model->image_count - 1);
    return OB_OK;
}

/* ------------------------------------------------------------ textures */

static uint32_t wrap_code(int mode)
{
    switch (mode) {
    case aiTextureMapMode_Wrap: return OB_MODEL_WRAP_REPEAT;
    case aiTextureMapMode_Clamp:
    case aiTextureMapMode_Decal: return OB_MODEL_WRAP_CLAMP;
    case aiTextureMapMode_Mirror: return OB_MODEL_WRAP_MIRROR;
    default: return 0;
    }
}

static bool get_int(const struct aiMaterial *m, const char *key, unsigned type, unsigned index,
                    int *out)
{
    unsigned max = 1;
    return aiGetMaterialIntegerArray(m, key, type, index, out, &max) == AI_SUCCESS && max == 1;
}

static bool get_float(const struct aiMaterial *m, const char *key, unsigned type, unsigned index,
                      float *out)
{
    unsigned max = 1;
    return aiGetMaterialFloatArray(m, key, type, index, out, &max) == AI_SUCCESS && max == 1;
}

static bool texture_ref(const struct aiMaterial *m, enum aiTextureType type, struct aiString *ref)
{
    return aiGetMaterialString(m, AI_MATKEY_TEXTURE(type, 0), ref) == AI_SUCCESS && ref->length > 0;
}

/* The image a texture reference names: embedded or an external file. */
static ob_result resolve_image(material_ctx *c, const slot_info *si, const char *ref, int32_t *out)
{
    int32_t e = embedded_index(c->scene, ref);
    if (e >= 0) return embedded_image(c, (uint32_t)e, ref, out);
    if (ref[0] == '*') {
        ob_model_bad(c->chk, "material %u '%s' %s names embedded texture '%s', which the file "
                     "does not have", si->material_index, si->material, si->slot, ref);
        return OB_ERR_BAD_MODEL;
    }
    return external_image(c, si, ref, out);
}

/* KHR_texture_transform back from assimp's aiUVTransform. assimp 5.2
 * (glTF2Importer's SetMaterialTextureProperty) stores scale as is, the
 * rotation negated and a translation re-expressed for its own convention
 * (rotation about the image centre, v mirrored):
 *   tx = sx/2 (1 − cos r + sin r) + offset.x
 *   ty = sy/2 (sin r + cos r − 1) + 1 − sy − offset.y
 * which this inverts exactly (checked against TextureTransformTest's
 * values); with aiProcess_FlipUVs, ty and the rotation arrive negated. Then the glTF map uv' = T R S uv, in the file's uv, and the same
 * map for the meshes' uv: with flip_uv they are the file's; without, v is
 * mirrored (v_mesh = 1 − v_file), so the map is conjugated by that mirror. */
static bool uv_transform_from_assimp(const float t[5], bool flip_uv, ob_model_uv_transform *out)
{
    /* aiProcess_FlipUVs (flip_uv) negates the stored translation.y and
     * rotation: undone first. */
    const double flip = flip_uv ? -1.0 : 1.0;
    const double tx = t[0], ty = flip * t[1], sx = t[2], sy = t[3], r = -flip * t[4];
    const double c = cos(r), s = sin(r);
    const double ox = tx - 0.5 * sx * (1.0 - c + s);
    const double oy = -(ty - 0.5 * sy * (s + c - 1.0) - 1.0 + sy);
    if (!isfinite(ox) || !isfinite(oy) || !isfinite(sx) || !isfinite(sy) || !isfinite(r)) return false;
    /* Near-identity values are what assimp's arithmetic leaves of none. */
    const double eps = 1e-6;
    out->present = fabs(ox) > eps || fabs(oy) > eps || fabs(r) > eps || fabs(sx - 1.0) > eps ||
                   fabs(sy - 1.0) > eps;
    out->offset[0] = fabs(ox) > eps ? (float)ox : 0.0f;
    out->offset[1] = fabs(oy) > eps ? (float)oy : 0.0f;
    out->rotation = fabs(r) > eps ? (float)r : 0.0f;
    out->scale[0] = (float)sx;
    out->scale[1] = (float)sy;
    /* File uv: u' = c sx u + s sy v + ox, v' = −s sx u + c sy v + oy. */
    double m[6] = {c * sx, s * sy, ox, -s * sx, c * sy, oy};
    if (!flip_uv) {
        /* v_file = 1 − v: u' = m0 u − m1 v + (m1 + m2), v' = 1 − v'_file. */
        const double k[6] = {m[0], -m[1], m[1] + m[2], -m[3], m[4], 1.0 - m[4] - m[5]};
        memcpy(m, k, sizeof m);
    }
    for (int i = 0; i < 6; i++) out->uv[i] = (float)m[i];
    if (!out->present) {
        const float id[6] = {1, 0, 0, 0, 1, 0};
        memcpy(out->uv, id, sizeof id);
    }
    return true;
}

/* Reads texture slot `slot` of `type` into *tex (image -1 when absent or
 * its file is missing). */
static ob_result read_texture_n(material_ctx *c, const struct aiMaterial *m, enum aiTextureType type,
                                unsigned slot, const slot_info *si, ob_model_texture *tex)
{
    struct aiString ref;
    if (aiGetMaterialString(m, AI_MATKEY_TEXTURE(type, slot), &ref) != AI_SUCCESS || !ref.length)
        return OB_OK;
    ob_result r = resolve_image(c, si, ref.data, &tex->image);
    if (r != OB_OK || tex->image < 0) return r;
    int v;
    if (get_int(m, AI_MATKEY_UVWSRC(type, slot), &v) && v > 0) {
        tex->uv_set = (uint32_t)v;
        if (v > 1)
            OB_LOG_W(OB_MODEL_LOG, "%s: material %u '%s' %s uses TEXCOORD_%d; only TEXCOORD_0 and "
                     "TEXCOORD_1 are loaded", c->chk->path, si->material_index, si->material, si->slot, v);
    }
    float t[5];
    unsigned count = 5;
    /* Other importers fill the key in their own conventions: only glTF's is inverted. */
    if (c->gltf &&
        aiGetMaterialFloatArray(m, AI_MATKEY_UVTRANSFORM(type, slot), t, &count) == AI_SUCCESS && count == 5 &&
        !uv_transform_from_assimp(t, c->flip_uv, &tex->transform))
        OB_LOG_W(OB_MODEL_LOG, "%s: material %u '%s' %s: KHR_texture_transform is not finite; "
                 "not applied", c->chk->path, si->material_index, si->material, si->slot);
    if (get_int(m, AI_MATKEY_GLTF_MAPPINGFILTER_MAG(type, slot), &v) && v > 0)
        tex->sampler.mag_filter = (uint32_t)v;
    if (get_int(m, AI_MATKEY_GLTF_MAPPINGFILTER_MIN(type, slot), &v) && v > 0)
        tex->sampler.min_filter = (uint32_t)v;
    if (get_int(m, AI_MATKEY_MAPPINGMODE_U(type, slot), &v)) tex->sampler.wrap_s = wrap_code(v);
    if (get_int(m, AI_MATKEY_MAPPINGMODE_V(type, slot), &v)) tex->sampler.wrap_t = wrap_code(v);
    return OB_OK;
}

static ob_result read_texture(material_ctx *c, const struct aiMaterial *m, enum aiTextureType type,
                              const slot_info *si, ob_model_texture *tex)
{
    return read_texture_n(c, m, type, 0, si, tex);
}

/* The first of `types` that the material names a texture for. */
static ob_result read_first_texture(material_ctx *c, const struct aiMaterial *m,
                                    const enum aiTextureType *types, int count,
                                    const slot_info *si, ob_model_texture *tex)
{
    struct aiString ref;
    for (int i = 0; i < count; i++)
        if (texture_ref(m, types[i], &ref)) return read_texture(c, m, types[i], si, tex);
    return OB_OK;
}

/* An image's channel count, and for 3 or 4 channels whether every texel is
 * grey (r = g = b): a height map saved as RGB. 0 when it cannot be read
 * (the texture loader will say why). */
static int image_channels(const ob_model_image *img, bool *out_grey)
{
    *out_grey = false;
    int w, h, n;
    if (!img->path && img->size > (size_t)INT32_MAX) return 0;
    stbi_uc *px = img->path ? stbi_load(img->path, &w, &h, &n, 0)
                            : stbi_load_from_memory(img->data, (int)img->size, &w, &h, &n, 0);
    if (!px) return 0;
    if (n >= 3) {
        bool grey = true;
        for (size_t i = 0, count = (size_t)w * (size_t)h; i < count && grey; i++) {
            const stbi_uc *p = px + i * (size_t)n;
            grey = p[0] == p[1] && p[1] == p[2];
        }
        *out_grey = grey;
    }
    stbi_image_free(px);
    return n;
}

/* The normal texture: NORMALS, else a "bump" map (HEIGHT) that is really a
 * normal map (colour, not grey). */
static ob_result read_normal_texture(material_ctx *c, const struct aiMaterial *m,
                                     const slot_info *si, ob_model_material *out)
{
    ob_model_texture *tex = &out->normal_texture;
    float scale;
    ob_result r = read_texture(c, m, aiTextureType_NORMALS, si, tex);
    if (r != OB_OK) return r;
    if (tex->image >= 0) {
        if (get_float(m, AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0), &scale) ||
            get_float(m, AI_MATKEY_OBJ_BUMPMULT_NORMALS(0), &scale))
            out->normal_scale = scale;
        return OB_OK;
    }
    slot_info bump = *si;
    bump.slot = "bump map";
    r = read_texture(c, m, aiTextureType_HEIGHT, &bump, tex);
    if (r != OB_OK || tex->image < 0) return r;
    bool grey;
    int channels = image_channels(&c->model->images[tex->image], &grey);
    if (channels != 0 && (channels < 3 || grey)) {
        OB_LOG_I(OB_MODEL_LOG, "%s: material %u '%s': bump map '%s' is a height map (%s), not a "
                 "normal map; not used", c->chk->path, si->material_index, si->material,
                 c->model->images[tex->image].name, channels < 3 ? "one or two channels" : "grey");
        *tex = (ob_model_texture){.image = -1};
        return OB_OK;
    }
    if (get_float(m, AI_MATKEY_OBJ_BUMPMULT_HEIGHT(0), &scale)) out->normal_scale = scale;
    return OB_OK;
}

/* ----------------------------------------------------------- materials */

static float clamp01(float v) { return v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v; }

static void defaults(ob_model_material *out)
{
    const ob_model_texture none = {.image = -1, .transform = {.scale = {1, 1}, .uv = {1, 0, 0, 0, 1, 0}}};
    *out = (ob_model_material){
        .base_color = {1, 1, 1, 1}, .metallic = 0.0f, .roughness = 1.0f,
        .normal_scale = 1.0f, .occlusion_strength = 1.0f,
        .base_color_texture = none, .metallic_roughness_texture = none,
        .normal_texture = none, .occlusion_texture = none, .emissive_texture = none,
        .alpha_mode = OB_MODEL_ALPHA_OPAQUE, .alpha_cutoff = 0.5f,
        .clearcoat_normal_scale = 1.0f, .clearcoat_texture = none,
        .clearcoat_roughness_texture = none, .clearcoat_normal_texture = none,
    };
}

static bool all_finite(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

/* KHR_materials_clearcoat: assimp's factor and roughness keys and its
 * CLEARCOAT texture slots 0 (intensity), 1 (roughness), 2 (normal). */
static ob_result read_clearcoat(material_ctx *c, const struct aiMaterial *m, slot_info *si,
                                ob_model_material *out)
{
    float f;
    if (!get_float(m, AI_MATKEY_CLEARCOAT_FACTOR, &f)) return OB_OK;
    out->clearcoat = f;
    if (get_float(m, AI_MATKEY_CLEARCOAT_ROUGHNESS_FACTOR, &f)) out->clearcoat_roughness = f;
    si->slot = "clearcoatTexture";
    ob_result r = read_texture_n(c, m, aiTextureType_CLEARCOAT, 0, si, &out->clearcoat_texture);
    si->slot = "clearcoatRoughnessTexture";
    if (r == OB_OK) r = read_texture_n(c, m, aiTextureType_CLEARCOAT, 1, si, &out->clearcoat_roughness_texture);
    si->slot = "clearcoatNormalTexture";
    if (r == OB_OK) r = read_texture_n(c, m, aiTextureType_CLEARCOAT, 2, si, &out->clearcoat_normal_texture);
    if (r == OB_OK && out->clearcoat_normal_texture.image >= 0 &&
        get_float(m, AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_CLEARCOAT, 2), &f))
        out->clearcoat_normal_scale = f;
    return r;
}

/* One line per material naming what assimp read of it that the material
 * does not carry (glTF material extensions past clearcoat). */
static void log_unsupported(material_ctx *c, const struct aiMaterial *m, uint32_t index, const char *name)
{
    static const struct { const char *key; const char *what; } keys[] = {
        {"$clr.sheen.factor", "KHR_materials_sheen"},
        {"$mat.transmission.factor", "KHR_materials_transmission"},
        {"$mat.volume.thicknessFactor", "KHR_materials_volume"},
        {"$mat.specularFactor", "KHR_materials_specular"},
        {"$mat.glossinessFactor", "KHR_materials_pbrSpecularGlossiness"},
    };
    char list[256] = "";
    size_t n = 0;
    for (uint32_t i = 0; i < OB_ARRAY_COUNT(keys); i++) {
        const struct aiMaterialProperty *prop;
        if (aiGetMaterialProperty(m, keys[i].key, 0, 0, &prop) != AI_SUCCESS || n >= sizeof list) continue;
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", n ? ", " : "", keys[i].what);
    }
    int shading;
    if (get_int(m, AI_MATKEY_SHADING_MODEL, &shading) && shading == aiShadingMode_Unlit && n < sizeof list)
        n += (size_t)snprintf(list + n, sizeof list - n, "%sKHR_materials_unlit", n ? ", " : "");
    if (n)
        OB_LOG_I(OB_MODEL_LOG, "%s: material %u '%s' uses %s, which the engine does not support; "
                 "drawn without", c->chk->path, index, name, list);
}

static ob_result read_material(material_ctx *c, uint32_t index, const struct aiMaterial *m,
                               ob_model_material *out)
{
    struct aiString name;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "material %u", index);
    bool named = aiGetMaterialString(m, AI_MATKEY_NAME, &name) == AI_SUCCESS && name.length;
    if (named) ob_model_sanitize_text(name.data, name.length);
    out->name = ob_strdup(named ? name.data : fallback);
    if (!out->name) return OB_ERR_OUT_OF_HOST_MEMORY;
    const slot_info base = {.material = out->name, .material_index = index};

    struct aiString mode;
    const bool gltf = aiGetMaterialString(m, AI_MATKEY_GLTF_ALPHAMODE, &mode) == AI_SUCCESS;
    c->gltf = gltf;
    struct aiColor4D col;
    if (aiGetMaterialColor(m, AI_MATKEY_BASE_COLOR, &col) == AI_SUCCESS ||
        aiGetMaterialColor(m, AI_MATKEY_COLOR_DIFFUSE, &col) == AI_SUCCESS) {
        out->base_color[0] = col.r;
        out->base_color[1] = col.g;
        out->base_color[2] = col.b;
        out->base_color[3] = col.a;
    }
    float f;
    if (gltf) {
        if (strcmp(mode.data, "MASK") == 0) out->alpha_mode = OB_MODEL_ALPHA_MASK;
        else if (strcmp(mode.data, "BLEND") == 0) out->alpha_mode = OB_MODEL_ALPHA_BLEND;
        if (get_float(m, AI_MATKEY_GLTF_ALPHACUTOFF, &f)) out->alpha_cutoff = f;
    } else if (get_float(m, AI_MATKEY_OPACITY, &f)) {
        out->base_color[3] = f;
        if (f < 1.0f) out->alpha_mode = OB_MODEL_ALPHA_BLEND;
    }
    if (get_float(m, AI_MATKEY_METALLIC_FACTOR, &f)) out->metallic = f;
    if (get_float(m, AI_MATKEY_ROUGHNESS_FACTOR, &f)) out->roughness = f;
    else if (!gltf && get_float(m, AI_MATKEY_SHININESS, &f) && isfinite(f))
        out->roughness = (float)pow(2.0 / ((f > 0.0f ? f : 0.0f) + 2.0), 0.25);
    if (aiGetMaterialColor(m, AI_MATKEY_COLOR_EMISSIVE, &col) == AI_SUCCESS) {
        out->emissive[0] = col.r;
        out->emissive[1] = col.g;
        out->emissive[2] = col.b;
    }
    int two_sided;
    if (get_int(m, AI_MATKEY_TWOSIDED, &two_sided)) out->double_sided = two_sided != 0;

    const float *values[] = {out->base_color, &out->metallic, &out->roughness, out->emissive,
                             &out->alpha_cutoff};
    const int counts[] = {4, 1, 1, 3, 1};
    const char *what[] = {"base colour", "metallic factor", "roughness factor", "emissive colour",
                          "alpha cutoff"};
    for (int i = 0; i < 5; i++) {
        if (!all_finite(values[i], counts[i])) {
            ob_model_bad(c->chk, "material %u '%s': %s is not finite", index, out->name, what[i]);
            return OB_ERR_BAD_MODEL;
        }
    }
    for (int k = 0; k < 4; k++) out->base_color[k] = clamp01(out->base_color[k]);
    for (int k = 0; k < 3; k++) out->emissive[k] = out->emissive[k] < 0.0f ? 0.0f : out->emissive[k];
    out->metallic = clamp01(out->metallic);
    out->roughness = clamp01(out->roughness);
    out->alpha_cutoff = out->alpha_cutoff < 0.0f ? 0.0f : out->alpha_cutoff;

    /* Textures: for each slot, the first assimp type the file fills (glTF
     * files fill BASE_COLOR and DIFFUSE with the same texture: one warning
     * if its file is missing, not two). */
    slot_info si = base;
    si.slot = "baseColorTexture";
    const enum aiTextureType base_types[] = {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE};
    ob_result r = read_first_texture(c, m, base_types, 2, &si, &out->base_color_texture);
    if (r == OB_OK && gltf) {
        si.slot = "metallicRoughnessTexture";
        r = read_texture(c, m, aiTextureType_UNKNOWN, &si, &out->metallic_roughness_texture);
    }
    si.slot = "normalTexture";
    if (r == OB_OK) r = read_normal_texture(c, m, &si, out);
    si.slot = "occlusionTexture";
    const enum aiTextureType occlusion_types[] = {aiTextureType_AMBIENT_OCCLUSION, aiTextureType_LIGHTMAP};
    if (r == OB_OK)   /* LIGHTMAP is glTF's occlusion; elsewhere it is baked light */
        r = read_first_texture(c, m, occlusion_types, gltf ? 2 : 1, &si, &out->occlusion_texture);
    if (r == OB_OK && out->occlusion_texture.image >= 0 &&
        get_float(m, AI_MATKEY_GLTF_TEXTURE_STRENGTH(aiTextureType_LIGHTMAP, 0), &f))
        out->occlusion_strength = f;
    si.slot = "emissiveTexture";
    const enum aiTextureType emissive_types[] = {aiTextureType_EMISSIVE, aiTextureType_EMISSION_COLOR};
    if (r == OB_OK) r = read_first_texture(c, m, emissive_types, 2, &si, &out->emissive_texture);
    if (r == OB_OK && gltf) r = read_clearcoat(c, m, &si, out);
    if (r != OB_OK) return r;
    if (gltf) log_unsupported(c, m, index, out->name);
    if (!isfinite(out->normal_scale) || !isfinite(out->occlusion_strength) || !isfinite(out->clearcoat) ||
        !isfinite(out->clearcoat_roughness) || !isfinite(out->clearcoat_normal_scale)) {
        ob_model_bad(c->chk, "material %u '%s': normal scale, occlusion strength or a clearcoat "
                     "factor is not finite", index, out->name);
        return OB_ERR_BAD_MODEL;
    }
    out->occlusion_strength = clamp01(out->occlusion_strength);
    out->clearcoat = clamp01(out->clearcoat);
    out->clearcoat_roughness = clamp01(out->clearcoat_roughness);
    return OB_OK;
}

/* The folder of path with a trailing '/', or "" for a bare file name. */
static char *folder_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return dup_range(path, slash ? (size_t)(slash - path) + 1 : 0);
}

ob_result ob_model_read_materials(ob_model_check *chk, const struct aiScene *s, bool flip_uv,
                                  ob_model *model)
{
    material_ctx c = {.chk = chk, .scene = s, .model = model, .flip_uv = flip_uv};
    if (s->mNumMaterials && !s->mMaterials) {
        ob_model_bad(chk, "%u materials but no material array", s->mNumMaterials);
        return OB_ERR_BAD_MODEL;
    }
    uint32_t count = s->mNumMaterials ? s->mNumMaterials : 1;
    model->materials = ob_calloc(count, sizeof *model->materials);
    c.dir = folder_of(chk->path);
    c.embedded_image = ob_malloc((size_t)(s->mNumTextures + 1) * sizeof *c.embedded_image);
    ob_result r = OB_OK;
    if (!model->materials || !c.dir || !c.embedded_image) {
        OB_LOG_E(OB_MODEL_LOG, "%s: out of memory for %u materials", chk->path, count);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    for (uint32_t i = 0; i <= s->mNumTextures; i++) c.embedded_image[i] = -1;
    for (uint32_t i = 0; i < count; i++) {
        ob_model_material *mat = &model->materials[i];
        defaults(mat);
        model->material_count = i + 1;   /* so ob_model_close frees what this one got */
        if (!s->mNumMaterials) {
            mat->name = ob_strdup("default");
            r = mat->name ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
        } else if (!s->mMaterials[i]) {
            ob_model_bad(chk, "material %u is missing", i);
            r = OB_ERR_BAD_MODEL;
        } else {
            r = read_material(&c, i, s->mMaterials[i], mat);
        }
        if (r == OB_ERR_OUT_OF_HOST_MEMORY)
            OB_LOG_E(OB_MODEL_LOG, "%s: out of memory reading material %u", chk->path, i);
        if (r != OB_OK) break;
    }
done:
    ob_free(c.dir);
    ob_free(c.embedded_image);
    return r;
}
