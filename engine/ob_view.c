#include "ob_renderer.h"
#include "ob_renderer_layer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ob_math.h"
#include "ob_view_sort_internal.h"

#include <float.h>
#include <stdatomic.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
/* The frustum test in AVX2's eight lanes where the CPU has them (asked at
 * each view's setup), in SSE2's four elsewhere. */
#define OB_CULL_LANES8 1
#endif

const char *ob_view_type_name(ob_view_type t)
{
    static const char *const names[OB_VIEW_TYPE_COUNT] = {
        "perspective", "shadow", "paraboloid", "simulation", "overlay", "composite", "cube",
    };
    return (unsigned)t < OB_VIEW_TYPE_COUNT ? names[t] : "unknown";
}

void ob_view_init(ob_view *v, const ob_view_vtbl *vtbl, ob_view_type type, const char *name)
{
    memset(v, 0, sizeof *v);
    v->vtbl = vtbl;
    v->type = type;
    snprintf(v->name, sizeof v->name, "%s", name ? name : ob_view_type_name(type));
    v->id = (uint32_t)ob_hash_str(OB_HASH_SEED, v->name);
    v->layer_count = 1;
    v->cull_thread = OB_VIEW_NO_THREAD;
}

static VkFormat image_format(const ob_device *dev, ob_image img)
{
    ob_image_info info;
    if (!img.id || ob_image_get_info(dev, img, &info) != OB_OK) return VK_FORMAT_UNDEFINED;
    return info.format;
}

void ob_view_attachment_formats(const ob_view *v, const ob_device *dev, VkFormat *out_color,
                                VkFormat *out_depth, uint32_t *out_samples)
{
    bool ms = v->samples > 1;
    *out_color = image_format(dev, ms && v->msaa_color.id ? v->msaa_color : v->color);
    *out_depth = image_format(dev, ms ? v->msaa_depth : v->depth);
    *out_samples = ms ? v->samples : 1;
}

bool ob_view_resize(ob_view *v, uint32_t width, uint32_t height)
{
    if (!v || width == 0 || height == 0) {
        OB_LOG_E("view", "view '%s': resize to %ux%u refused (a side is zero)", v ? v->name : "?",
                 width, height);
        return false;
    }
    v->resize_width = width;
    v->resize_height = height;
    return true;
}

ob_result ob_view_set_wireframe(ob_view *v, const ob_device *dev, bool on)
{
    if (!v || !dev) return OB_ERR_INVALID_ARGUMENT;
    if (on && !ob_device_get_caps(dev)->fill_mode_non_solid) {
        OB_LOG_E("view", "view '%s': wireframe refused: the device (%s) lacks the feature "
                 "fillModeNonSolid (VK_POLYGON_MODE_LINE); the view stays filled", v->name,
                 ob_device_name(dev));
        return OB_ERR_UNSUPPORTED;
    }
    v->wireframe = on;
    return OB_OK;
}

bool ob_view_take_resize(ob_view *v, uint32_t *out_width, uint32_t *out_height)
{
    if (!v->resize_width || !v->resize_height) return false;
    *out_width = v->resize_width;
    *out_height = v->resize_height;
    v->resize_width = v->resize_height = 0;
    return true;
}

void ob_view_release(ob_view *v)
{
    if (!v) return;
    ob_free(v->items);
    ob_free(v->materials);
    ob_free(v->material_items);
    ob_aligned_free(v->cull_mem);
    v->items = NULL;
    v->materials = NULL;
    v->material_items = NULL;
    v->material_item_count = v->material_item_cap = 0;
    v->material_items_valid = false;
    v->cull_mem = NULL;
    v->cull_mem_size = 0;
    v->item_count = v->item_cap = 0;
    v->material_count = v->material_cap = 0;
}

void ob_view_add_dependency(ob_view *v, ob_view *dep)
{
    if (!v || !dep || v == dep) return;
    for (uint32_t i = 0; i < v->dep_count; i++)
        if (v->deps[i] == dep) return;
    if (v->dep_count < OB_VIEW_MAX_DEPS) {
        v->deps[v->dep_count++] = dep;
    } else {
        OB_LOG_E("view", "view '%s': more than %u dependencies; '%s' is not ordered before it",
                 v->name, OB_VIEW_MAX_DEPS, dep->name);
    }
}

/* The draw-list key (bgfx-style): sort_hi holds the class (opaque first)
 * and the priority; sort_key, for opaque items, a coarse depth band (the
 * distance's exponent in steps of 4x), the material's state group, the mesh
 * and the fine depth, so that draws binding the same state follow each
 * other while the front-to-back order survives between bands; for blended
 * items the full depth, back to front, then state group and mesh. dist2 is
 * >= 0, and positive floats order like their bits.
 *
 * The fine depth is the band's last two exponent bits and the mantissa's
 * top eight: d² to 1/256 of its octave (distance to about 0.2%), ample for
 * early depth rejection, which is all the opaque order is for. Each bit
 * more is one more bit the sort moves items on: with twenty, a 10k-object
 * view's opaque list had 31 differing bits (three 11-bit passes); with ten,
 * 21 (two). */
#define KEY_FINE_BITS 10u

static uint64_t item_key(uint32_t sort_hi, uint32_t state, uint32_t mesh, float dist2)
{
    uint32_t bits;
    memcpy(&bits, &dist2, sizeof bits);
    if (sort_hi >> 31)
        return ((uint64_t)~bits << 32) | ((uint64_t)(state & 0xffffu) << 16) | (mesh & 0xffffu);
    uint64_t band = bits >> 25; /* sign 0, top 6 bits of the exponent */
    uint64_t fine = (bits >> (25 - KEY_FINE_BITS)) & ((1u << KEY_FINE_BITS) - 1u);
    return (band << 58) | ((uint64_t)(state & 0xfffu) << 46) | ((uint64_t)(mesh & 0x3ffffu) << 28) |
           (fine << (28 - KEY_FINE_BITS));
}

/* Entities per index of the culling loop: ~10-20 us of work each at most,
 * and at least a few us; in between, as many as give each thread four
 * indices of the wave, so that a wave of one view (a shadow map after the
 * cameras) is shared too. */
#define CULL_GRAIN 4096u
#define CULL_GRAIN_MIN 512u
/* Entities tested per block: the frustum pass writes a byte and a float
 * per entity into the block's stack scratch, the pass after it keys the
 * visible ones. */
#define CULL_BLOCK 256u
/* Entities beyond float range a chunk keeps to log by name. */
#define CULL_LOG_MAX 4u

typedef struct cull_chunk {
    uint64_t ns;                        /* the chunk's time */
    uint32_t culled;                    /* what it kept: segments[chunk].count */
    uint32_t far_count;                 /* beyond float range */
    uint32_t far[CULL_LOG_MAX];         /* the first ones, snapshot indices */
} cull_chunk;

/* What culling knows of one geometry (by its scene index): each level of
 * detail's error over the bound radius and the mesh field of its keys.
 * Asked of the geometry interface once per wave. */
typedef struct cull_geometry {
    /* Levels 1.. (entry l - 1 for level l); +infinity past the last, so
     * that every geometry is tested over the same lanes. */
    float rel_error[OB_LOD_MAX - 1];
    /* The mesh id shifted by three bits: level l keys as mesh | l, next to
     * its level 0, so a run never mixes levels and small ids (a stack's)
     * keep few differing bits for the sort. */
    uint32_t mesh;
} cull_geometry;

/* A payload's proxy_lod holds the snapshot index below this bit and the
 * level of detail from it up (snapshots stay far below 2^28 entities:
 * culling draws level 0 beyond). */
#define CULL_LOD_SHIFT 28u
#define CULL_INDEX_MASK ((1u << CULL_LOD_SHIFT) - 1u)

/* What a kept entity's draw item takes from the snapshot besides its key,
 * written by the chunk beside its pair, at the same position. The chunk
 * reads the snapshot in order, where each line it loads serves several
 * entities; the draw list, in key order, would read it scattered (four
 * arrays, an entity's fields on four lines): at 8 views x 10k, that
 * gather cost as much as the sort. */
typedef struct cull_payload {
    ob_node *node;
    uint32_t node_id;
    uint32_t proxy_lod;                 /* snapshot index | level << CULL_LOD_SHIFT */
    uint32_t material, geometry;
} cull_payload;

typedef struct cull_ctx {
    const ob_view *v;
    ob_render_soa soa;
    const ob_view_material *mt;
    const cull_geometry *geo;           /* per geometry index */
    float lod_scale;                    /* the view's; 0: level 0 always */
    bool lod_ortho;                     /* the view's: the same scale at any distance */
    uint32_t exclude_id;                /* 0: none (ids start at 1) */
    float planes[6][4];                 /* unused planes test nothing */
    uint32_t lanes;                     /* the frustum test's width: 8, 4 or 1 */
    uint32_t grain;                     /* entities per chunk */
    ob_sort_pair *pairs;                /* chunk c writes from c * grain, */
    cull_payload *payload;              /* both, */
    ob_sort_segment *segments;          /* and says where in segments[c] */
    cull_chunk *chunks;
} cull_ctx;

#if defined(OB_CULL_LANES8)
/* cull_block's test over whole groups of eight, in AVX2; returns how many
 * it tested. Each lane does the four-lane form's operations (no fused
 * multiply-add; the ordered compares give false on NaN as SSE's do), so
 * both keep the same entities with the same distances. */
__attribute__((target("avx2"), noinline)) static uint32_t
cull_block8(const cull_ctx *c, const double *x, const double *y, const double *z,
            const float *rad, uint32_t n, uint8_t *vis, float *d2)
{
    const __m256d vox = _mm256_set1_pd(c->v->origin[0]), voy = _mm256_set1_pd(c->v->origin[1]),
                  voz = _mm256_set1_pd(c->v->origin[2]);
    const __m256 big = _mm256_set1_ps(FLT_MAX), sign = _mm256_set1_ps(-0.0f);
    const __m256i one = _mm256_set1_epi32(1), two = _mm256_set1_epi32(2);
    __m256 pl[6][4];
    for (int p = 0; p < 6; p++)
        for (int k = 0; k < 4; k++) pl[p][k] = _mm256_set1_ps(c->planes[p][k]);
    uint32_t j = 0;
/* Eight coordinates relative to the origin, in double, then in float. */
#define CULL_REL8(a, o)                                                                            \
    _mm256_insertf128_ps(                                                                          \
        _mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd((a) + j), o))),        \
        _mm256_cvtpd_ps(_mm256_sub_pd(_mm256_loadu_pd((a) + j + 4), o)), 1)
    for (; j + 8 <= n; j += 8) {
        __m256 rx = CULL_REL8(x, vox), ry = CULL_REL8(y, voy), rz = CULL_REL8(z, voz);
        __m256 r = _mm256_loadu_ps(rad + j), nr = _mm256_xor_ps(r, sign);
        __m256 fin = _mm256_and_ps(
            _mm256_and_ps(_mm256_cmp_ps(_mm256_andnot_ps(sign, rx), big, _CMP_LE_OQ),
                          _mm256_cmp_ps(_mm256_andnot_ps(sign, ry), big, _CMP_LE_OQ)),
            _mm256_and_ps(_mm256_cmp_ps(_mm256_andnot_ps(sign, rz), big, _CMP_LE_OQ),
                          _mm256_cmp_ps(_mm256_andnot_ps(sign, r), big, _CMP_LE_OQ)));
        __m256 out = _mm256_setzero_ps();
        for (int p = 0; p < 6; p++) {
            __m256 d = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(pl[p][0], rx),
                                                                 _mm256_mul_ps(pl[p][1], ry)),
                                                   _mm256_mul_ps(pl[p][2], rz)),
                                     pl[p][3]);
            out = _mm256_or_ps(out, _mm256_cmp_ps(d, nr, _CMP_LT_OQ));
        }
        _mm256_storeu_ps(d2 + j, _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(rx, rx),
                                                             _mm256_mul_ps(ry, ry)),
                                               _mm256_mul_ps(rz, rz)));
        /* vis = 2 where not finite, else 1 where inside: packed to bytes. */
        __m256i f = _mm256_castps_si256(fin), in = _mm256_andnot_si256(_mm256_castps_si256(out), f);
        __m256i v = _mm256_or_si256(_mm256_and_si256(in, one), _mm256_andnot_si256(f, two));
        __m128i v16 = _mm_packs_epi32(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
        _mm_storel_epi64((__m128i *)(void *)(vis + j), _mm_packus_epi16(v16, v16));
    }
#undef CULL_REL8
    return j;
}
#endif

/* Frustum and range test of a block: vis[j] 1 inside, 0 outside, 2 not
 * finite in float relative to the origin; d2[j] the squared distance. The
 * arithmetic is ob_frustum_test_sphere's, operation for operation, so the
 * SIMD and scalar forms keep exactly the same entities. Eight at a time,
 * then four, then one, as wide as c->lanes allows. */
static void cull_block(const cull_ctx *c, uint32_t first, uint32_t n, uint8_t *vis, float *d2)
{
    const double *x = c->soa.x + first, *y = c->soa.y + first, *z = c->soa.z + first;
    const float *rad = c->soa.radius + first;
    const double ox = c->v->origin[0], oy = c->v->origin[1], oz = c->v->origin[2];
    uint32_t j = 0;
#if defined(OB_CULL_LANES8)
    if (c->lanes == 8) j = cull_block8(c, x, y, z, rad, n, vis, d2);
#endif
#if defined(__SSE2__)
    const __m128d vox = _mm_set1_pd(ox), voy = _mm_set1_pd(oy), voz = _mm_set1_pd(oz);
    const __m128 big = _mm_set1_ps(FLT_MAX), sign = _mm_set1_ps(-0.0f);
    __m128 pl[6][4];
    for (int p = 0; p < 6; p++)
        for (int k = 0; k < 4; k++) pl[p][k] = _mm_set1_ps(c->planes[p][k]);
    for (; c->lanes >= 4 && j + 4 <= n; j += 4) {
        __m128 rx = _mm_movelh_ps(_mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(x + j), vox)),
                                  _mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(x + j + 2), vox)));
        __m128 ry = _mm_movelh_ps(_mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(y + j), voy)),
                                  _mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(y + j + 2), voy)));
        __m128 rz = _mm_movelh_ps(_mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(z + j), voz)),
                                  _mm_cvtpd_ps(_mm_sub_pd(_mm_loadu_pd(z + j + 2), voz)));
        __m128 r = _mm_loadu_ps(rad + j), nr = _mm_xor_ps(r, sign);
        /* |v| <= FLT_MAX is false for infinities and NaN. */
        __m128 fin = _mm_and_ps(_mm_and_ps(_mm_cmple_ps(_mm_andnot_ps(sign, rx), big),
                                           _mm_cmple_ps(_mm_andnot_ps(sign, ry), big)),
                                _mm_and_ps(_mm_cmple_ps(_mm_andnot_ps(sign, rz), big),
                                           _mm_cmple_ps(_mm_andnot_ps(sign, r), big)));
        __m128 out = _mm_setzero_ps();
        for (int p = 0; p < 6; p++) {
            __m128 d = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(pl[p][0], rx),
                                                        _mm_mul_ps(pl[p][1], ry)),
                                             _mm_mul_ps(pl[p][2], rz)),
                                  pl[p][3]);
            out = _mm_or_ps(out, _mm_cmplt_ps(d, nr));
        }
        int fm = _mm_movemask_ps(fin), om = _mm_movemask_ps(out);
        _mm_storeu_ps(d2 + j, _mm_add_ps(_mm_add_ps(_mm_mul_ps(rx, rx), _mm_mul_ps(ry, ry)),
                                         _mm_mul_ps(rz, rz)));
        for (int k = 0; k < 4; k++)
            vis[j + k] = (uint8_t)(!(fm >> k & 1) ? 2u : !(om >> k & 1));
    }
#endif
    for (; j < n; j++) {
        float rx = (float)(x[j] - ox), ry = (float)(y[j] - oy), rz = (float)(z[j] - oz);
        float r = rad[j];
        if (!(fabsf(rx) <= FLT_MAX && fabsf(ry) <= FLT_MAX && fabsf(rz) <= FLT_MAX &&
              fabsf(r) <= FLT_MAX)) {
            vis[j] = 2;
            d2[j] = 0.0f;
            continue;
        }
        bool in = true;
        for (int p = 0; p < 6; p++) {
            const float *q = c->planes[p];
            float d = q[0] * rx + q[1] * ry + q[2] * rz + q[3];
            in &= !(d < -r);
        }
        vis[j] = in;
        d2[j] = rx * rx + ry * ry + rz * rz;
    }
}

/* How many of the levels 1.. pass: those whose error over the bound
 * radius, rel[l - 1], gives need = rel * t_err + base with need^2 <=
 * reach2. The same float operations in either form, so the same count:
 * four levels to a compare, the second group's first lane (level 4, in
 * the first group too) masked off. */
static inline uint32_t lod_levels_passing(const float rel[OB_LOD_MAX - 1], float t_err, float base,
                                          float reach2)
{
#if defined(__SSE2__)
    _Static_assert(OB_LOD_MAX - 1 == 7, "the levels fill two groups of four, one lane shared");
    static const uint8_t bits4[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
    const __m128 t = _mm_set1_ps(t_err), b = _mm_set1_ps(base), reach = _mm_set1_ps(reach2);
    __m128 lo = _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(rel), t), b);
    __m128 hi = _mm_add_ps(_mm_mul_ps(_mm_loadu_ps(rel + 3), t), b);
    int m_lo = _mm_movemask_ps(_mm_cmple_ps(_mm_mul_ps(lo, lo), reach));
    int m_hi = _mm_movemask_ps(_mm_cmple_ps(_mm_mul_ps(hi, hi), reach)) & 0xe;
    return (uint32_t)bits4[m_lo] + bits4[m_hi];
#else
    uint32_t level = 0;
    for (uint32_t l = 0; l < OB_LOD_MAX - 1; l++) {
        float need = rel[l] * t_err + base;
        level += need * need <= reach2;
    }
    return level;
#endif
}

/* Whether the view draws entity i at all: its material renders in the
 * view's type and it is not the excluded one. */
static inline bool cull_drawn_here(const cull_ctx *c, uint32_t i, uint32_t type_bit)
{
    return (c->mt[c->soa.material[i]].mask & type_bit) != 0 && c->soa.node_id[i] != c->exclude_id;
}

/* An entity the view would draw that lies beyond float range: the first
 * CULL_LOG_MAX of a chunk are kept by index for the log. */
static inline void cull_note_far(cull_chunk *out, uint32_t i)
{
    if (out->far_count < CULL_LOG_MAX) out->far[out->far_count] = i;
    out->far_count++;
}

/* Which entities of block [b, b + n) the view keeps, into keep (block
 * offsets, ascending); their count is returned. Kept: inside the frustum
 * (vis 1), of non-zero size, drawn here (cull_drawn_here). Noted as far:
 * the same with vis 2, in order (an entity not drawn here or of no size is
 * not reported). Sixteen at a time the frustum and size tests are two byte
 * compares, and only their survivors (a third or so, in no order a
 * predictor could learn: hence no branch per entity before them) have
 * their material looked up. */
static uint32_t cull_keep(const cull_ctx *c, cull_chunk *out, uint32_t b, uint32_t n,
                          const uint8_t *vis, uint32_t type_bit, uint16_t *keep)
{
    const uint8_t *flags = c->soa.flags + b;
    uint32_t nk = 0, j = 0;
#if defined(__SSE2__)
    const __m128i one = _mm_set1_epi8(1), two = _mm_set1_epi8(2), zero = _mm_setzero_si128(),
                  zero_scale = _mm_set1_epi8((char)OB_RENDER_ZERO_SCALE);
    for (; c->lanes > 1 && j + 16 <= n; j += 16) {
        __m128i v = _mm_loadu_si128((const __m128i *)(vis + j));
        __m128i f = _mm_loadu_si128((const __m128i *)(flags + j));
        __m128i sized = _mm_cmpeq_epi8(_mm_and_si128(f, zero_scale), zero);
        uint32_t in = (uint32_t)_mm_movemask_epi8(_mm_and_si128(_mm_cmpeq_epi8(v, one), sized));
        uint32_t far = (uint32_t)_mm_movemask_epi8(_mm_and_si128(_mm_cmpeq_epi8(v, two), sized));
        if (__builtin_expect(far != 0, 0))
            for (; far; far &= far - 1) {
                uint32_t i = b + j + (uint32_t)__builtin_ctz(far);
                if (cull_drawn_here(c, i, type_bit)) cull_note_far(out, i);
            }
        for (; in; in &= in - 1) {
            uint32_t k = j + (uint32_t)__builtin_ctz(in);
            keep[nk] = (uint16_t)k;
            nk += cull_drawn_here(c, b + k, type_bit);
        }
    }
#endif
    for (; j < n; j++) {
        if (vis[j] == 0 || (flags[j] & OB_RENDER_ZERO_SCALE) ||
            !cull_drawn_here(c, b + j, type_bit))
            continue;
        if (vis[j] == 2) cull_note_far(out, b + j);
        else keep[nk++] = (uint16_t)j;
    }
    return nk;
}

/* One chunk of the snapshot: test, then key the entities the view keeps
 * into the chunk's part of the pair array, in snapshot order. */
static void cull_chunk_run(void *user, uint32_t chunk, uint32_t thread)
{
    (void)thread;
    const cull_ctx *c = user;
    uint32_t first = chunk * c->grain, end = OB_MIN(c->soa.count, first + c->grain);
    uint32_t type_bit = 1u << c->v->type;
    cull_chunk *out = &c->chunks[chunk];
    ob_sort_pair *pairs = c->pairs + first;
    cull_payload *payload = c->payload + first;
    *out = (cull_chunk){0};
    uint32_t kept = 0;
    uint8_t vis[CULL_BLOCK];
    _Alignas(16) float d2[CULL_BLOCK];
    for (uint32_t b = first; b < end; b += CULL_BLOCK) {
        uint32_t n = OB_MIN(CULL_BLOCK, end - b);
        cull_block(c, b, n, vis, d2);
        uint16_t keep[CULL_BLOCK];
        uint32_t nk = cull_keep(c, out, b, n, vis, type_bit, keep);
        for (uint32_t t = 0; t < nk; t++) {
            uint32_t j = keep[t], i = b + j;
            uint32_t material = c->soa.material[i], geometry = c->soa.geometry[i];
            const ob_view_material *m = &c->mt[material];
            const cull_geometry *g = &c->geo[geometry];
            /* The coarsest level whose error, seen from the nearest point of
             * the bound, stays within the tolerance. */
            uint32_t level = 0;
            if (c->lod_scale > 0.0f) {
                /* Errors do not go down with the level, so the levels that
                 * pass are 1..level: count them, without branches (the
                 * level changes with distance in no order a predictor
                 * learns). Orthographic: the error in pixels is the same
                 * at any distance, measured against one pixel. */
                float r = c->soa.radius[i], t_err = r * c->lod_scale;
                float base = c->lod_ortho ? 0.0f : r, reach2 = c->lod_ortho ? 1.0f : d2[j];
                level = lod_levels_passing(g->rel_error, t_err, base, reach2);
            }
            uint32_t at = kept++;
            /* The pair's index: where it and its payload lie (the sort may
             * move pairs, never payloads). */
            pairs[at] = (ob_sort_pair){
                .key = item_key(m->sort_hi, m->state, g->mesh | level, d2[j]),
                .hi = m->sort_hi,
                .index = first + at,
            };
            payload[at] = (cull_payload){.node = c->soa.node[i], .node_id = c->soa.node_id[i],
                                         .proxy_lod = i | level << CULL_LOD_SHIFT,
                                         .material = material, .geometry = geometry};
        }
        out->culled += n - nk;
    }
    c->segments[chunk] = (ob_sort_segment){first, kept};
}

/* The view's table of the snapshot's materials: one interface call per
 * material, not per entity. */
static ob_result cull_materials(ob_view *v, const ob_scene *scene, const ob_material_iface *mi)
{
    uint32_t mc = ob_scene_material_count(scene);
    ob_result res = ob_array_reserve((void **)&v->materials, &v->material_cap, mc,
                                     sizeof *v->materials);
    if (res != OB_OK) return res;
    v->material_count = mc;
    for (uint32_t k = 0; k < mc; k++) {
        struct ob_material *m = ob_scene_material(scene, k);
        ob_view_material *e = &v->materials[k];
        *e = (ob_view_material){0};
        if (!m) continue;
        for (uint32_t t = 0; t < OB_VIEW_TYPE_COUNT; t++)
            e->mask |= (uint8_t)(mi->renders(m, (ob_view_type)t) ? 1u << t : 0u);
        uint32_t cls = 0, priority = 0, state = 0;
        mi->sort_info(m, v->type, &cls, &priority, &state);
        e->sort_hi = ((cls & 1u) << 31) | (priority & 0x7fffffffu);
        e->state = state;
        e->per_entity = !mi->pre_render_per_entity || mi->pre_render_per_entity(m, v->type);
    }
    return OB_OK;
}

/* Working memory: two pair arrays of `count` (the chunks' output and the
 * sort's other buffer), the payloads, the chunk records and their
 * segments. */
static ob_result cull_reserve(ob_view *v, uint32_t count, uint32_t chunks)
{
    size_t need = (2 * sizeof(ob_sort_pair) + sizeof(cull_payload)) * (size_t)OB_MAX(count, 1u) +
                  (sizeof(cull_chunk) + sizeof(ob_sort_segment)) * (size_t)OB_MAX(chunks, 1u);
    need = (need + 63) & ~(size_t)63;
    if (need <= v->cull_mem_size) return OB_OK;
    size_t size = OB_MAX(need, v->cull_mem_size + v->cull_mem_size / 2);
    void *mem = ob_aligned_alloc(OB_CACHE_LINE, size);
    if (!mem) return OB_ERR_OUT_OF_HOST_MEMORY;
    ob_aligned_free(v->cull_mem);
    v->cull_mem = mem;
    v->cull_mem_size = size;
    return OB_OK;
}

/* One view of a wave being culled. */
typedef struct cull_view {
    ob_view *v;
    cull_ctx c;
    uint32_t count;
    uint64_t ns;                /* its tasks' time, summed */
    ob_result res;
    atomic_uint chunks_left;    /* of its chunk tasks; the one that ends them finishes the view */
    /* A big view's draw items are gathered in parts that any thread of the
     * wave may take (wave_idle): its sorted list, published with
     * parts_ready by the thread that sorted it, which then takes parts
     * itself until none is left. */
    ob_sort_result sorted;
    uint32_t n;                 /* visible items */
    uint64_t own_ns;            /* the sorting thread's time before the parts */
    atomic_uint parts_ready;    /* 0 until the list is sorted, then the part count */
    atomic_uint part_next;      /* the next part to take */
    atomic_uint parts_left;     /* parts not done; the one that ends them finishes the view */
    atomic_uint coarse;         /* items drawn at a coarser level, summed over the parts */
    _Atomic uint64_t parts_ns;  /* the parts' time, summed */
    atomic_bool done;           /* finished (wave_view_done) */
} cull_view;

/* Every view of a wave culls the same snapshot, so each has the same
 * number of chunks, and the wave has chunks x view_count tasks, numbered
 * view by view: task t is chunk t % chunks of view t / chunks. The loop's
 * home blocks (run_tasks) then give each thread a run of whole views (with
 * fewer views than threads, a run of one view's chunks), so that a view's
 * chunks' pairs and payloads, its sort and its draw items stay in the
 * caches of the core that made them; a thread steals another's chunks
 * only when its own run is done. Measured on the 2-core VM at 8 views x
 * 10k: numbered by entity share instead (each thread the t-th share of
 * every view, as the update's loops), each view's finish read the other
 * core's half of its pairs and payloads, and the wave took 25% more CPU
 * than single-threaded, against 4% now. */
typedef struct cull_wave {
    cull_view *views;
    uint32_t chunks, view_count;
    bool parallel;              /* on the pool: the finishing thread is noted */
    uint32_t part_items;        /* a view of twice this many items or more is gathered in parts */
    atomic_uint open;           /* views not finished yet */
    /* Per loop thread: when its idle calls began finding nothing (0: they
     * have not, or it found work since); wave_idle's bound. */
    uint64_t idle_since[OB_MAX_WORKERS + 1];
} cull_wave;

/* Items per part of a big view's gather (wave_gather_part) when the
 * renderer gives no grain: some 50 us of work on the 2-core VM (13 ns an
 * item at 34k items, the payload read in sort order). A view of fewer than
 * two parts is gathered by the thread that sorted it, in one pass with its
 * list of one item per material. Measured at 1 view x 100k objects (34k
 * drawn): the chunks' culling 0.69 ms, shared on the pool, then the sort
 * 0.32 ms and the gather 0.44 ms on that one thread. */
#define GATHER_PART 4096u

/* How long a thread of the wave with no chunk left waits for work to
 * share: while some view is being sorted (its parts come after), up to
 * the longer bound, a big view's sort; otherwise (views whose last chunks
 * run elsewhere) the shorter, about a chunk's work. Bounded because
 * helping is only an offer: a thread that spins while the one it waits for
 * is off its CPU (tests side by side, sanitizers) only delays it. */
#define WAVE_WAIT_SORT_NS 1000000u
#define WAVE_WAIT_CHUNKS_NS 50000u

/* The frustum test's width for v: the widest the CPU has, unless the
 * view's cull_lanes (a test's switch) asks for four or one. */
static uint32_t cull_lanes(const ob_view *v)
{
    if (v->cull_lanes == 1) return 1;
#if defined(OB_CULL_LANES8)
    if (v->cull_lanes != 4 && __builtin_cpu_supports("avx2")) return 8;
#endif
#if defined(__SSE2__)
    return 4;
#else
    return 1;
#endif
}

/* Sets up a view of a wave on the render thread: its snapshot, working
 * memory, material table and planes. geo: the wave's geometry table. */
static ob_result cull_setup(cull_view *cv, ob_renderer *r, const ob_scene *scene,
                            const ob_material_iface *mi, const cull_geometry *geo, uint32_t grain)
{
    ob_view *v = cv->v;
    uint32_t count = 0;
    v->proxies = ob_scene_render_proxies(scene, &count);
    ob_scene_render_soa(scene, &v->soa);
    v->item_count = 0;
    v->culled = 0;
    v->lod_items = 0;
    v->material_count = 0;
    v->material_items_valid = false;
    v->cull_ns = 0;
    v->cull_thread = OB_VIEW_NO_THREAD;
    cv->count = count;
    if (!mi) return OB_ERR_WRONG_STATE;
    uint32_t chunks = (count + grain - 1) / grain;
    ob_result res = ob_array_reserve((void **)&v->items, &v->item_cap, count, sizeof *v->items);
    if (res == OB_OK) res = cull_reserve(v, count, chunks);
    if (res == OB_OK) res = cull_materials(v, scene, mi);
    if (res != OB_OK) {
        /* The view goes on empty this frame; the next frame tries again. */
        OB_LOG_E("view", "view '%s': no draw list for %u renderables (%s); it draws nothing this frame",
                 v->name, count, ob_result_name(res));
        ob_renderer_note_error(r, v->name, res);
        v->material_count = 0;
        return res;
    }
    ob_sort_pair *pairs = v->cull_mem, *other = pairs + OB_MAX(count, 1u);
    cull_payload *payload = (cull_payload *)(void *)(other + OB_MAX(count, 1u));
    cv->c = (cull_ctx){
        .v = v, .soa = v->soa, .mt = v->materials, .geo = geo,
        .lod_scale = count <= CULL_INDEX_MASK && isfinite(v->lod_scale) ? v->lod_scale : 0.0f,
        .lod_ortho = v->lod_ortho, .lanes = cull_lanes(v),
        .exclude_id = v->cull_exclude ? ob_node_id(v->cull_exclude) : 0u,
        .grain = grain, .pairs = pairs, .payload = payload,
        .chunks = (cull_chunk *)(void *)(payload + OB_MAX(count, 1u)),
    };
    cv->c.segments = (ob_sort_segment *)(void *)(cv->c.chunks + OB_MAX(chunks, 1u));
    /* Planes the frustum lacks (all of them without one) test nothing. */
    for (int p = 0; p < 6; p++) {
        cv->c.planes[p][0] = cv->c.planes[p][1] = cv->c.planes[p][2] = 0.0f;
        cv->c.planes[p][3] = FLT_MAX;
    }
    if (!v->no_frustum) {
        ob_frustum frustum;
        ob_frustum_from_matrix(v->view_proj, &frustum);
        memcpy(cv->c.planes, frustum.planes, sizeof(float) * 4 * frustum.plane_count);
    }
    return OB_OK;
}

/* Draw item j of the sorted list, from its pair and the payload at the
 * pair's position in the chunks' space; returns the payload. */
static inline const cull_payload *gather_item(ob_view *v, ob_sort_result sorted,
                                              const cull_payload *payload, uint32_t j)
{
    uint32_t at = sorted.order ? sorted.order[j] : sorted.pairs[j].index;
    const ob_sort_pair *p = sorted.order ? &sorted.pairs[at] : &sorted.pairs[j];
    const cull_payload *e = &payload[at];
    v->items[j] = (ob_draw_item){.sort_key = p->key, .sort_hi = p->hi,
                                 .node_id = e->node_id, .node = e->node,
                                 .proxy = e->proxy_lod & CULL_INDEX_MASK,
                                 .material = e->material, .geometry = e->geometry,
                                 .lod = (uint8_t)(e->proxy_lod >> CULL_LOD_SHIFT)};
    return e;
}

/* Item j in the list of one item per material (the first of a material,
 * every one of a material that prepares per entity): the items the view's
 * post-cull work visits (for_each_material_item), found on the pool rather
 * than by a pass over the draw list per use on the render thread. */
static inline void list_material_item(ob_view *v, uint32_t material, ob_node *node, uint32_t j,
                                      uint32_t *listed)
{
    ob_view_material *m = &v->materials[material];
    if (m->seen && !m->per_entity) return;
    m->seen = 1;
    if (v->material_items_valid)
        v->material_items[(*listed)++] =
            (ob_view_material_item){.node = node, .material = v->soa.materials[material], .item = j};
}

/* The view is done: its counts, and the wave has one view less to wait
 * for (release: the view's items are seen by whoever reads open). */
static void wave_view_done(cull_wave *w, cull_view *cv, uint32_t n, uint32_t coarse,
                           uint32_t listed, uint64_t ns)
{
    ob_view *v = cv->v;
    v->item_count = n;
    v->lod_items = coarse;
    v->material_item_count = listed;
    cv->ns = ns;
    atomic_store_explicit(&cv->done, true, memory_order_relaxed);
    atomic_fetch_sub_explicit(&w->open, 1, memory_order_release);
}

/* Part `part` of a big view's gather; the thread that ends the last part
 * lists the items per material over the whole list, in order, and
 * finishes the view (acquire-release: every part's items are seen). */
static void wave_gather_part(cull_wave *w, cull_view *cv, uint32_t part)
{
    uint64_t t0 = ob_time_ns();
    ob_view *v = cv->v;
    uint32_t first = part * w->part_items, end = OB_MIN(first + w->part_items, cv->n);
    uint32_t coarse = 0;
    for (uint32_t j = first; j < end; j++)
        coarse += gather_item(v, cv->sorted, cv->c.payload, j)->proxy_lod > CULL_INDEX_MASK;
    atomic_fetch_add_explicit(&cv->coarse, coarse, memory_order_relaxed);
    atomic_fetch_add_explicit(&cv->parts_ns, ob_time_ns() - t0, memory_order_relaxed);
    if (atomic_fetch_sub_explicit(&cv->parts_left, 1, memory_order_acq_rel) != 1) return;
    uint64_t t1 = ob_time_ns();
    uint32_t listed = 0;
    for (uint32_t j = 0; j < cv->n; j++)
        list_material_item(v, v->items[j].material, v->items[j].node, j, &listed);
    uint64_t ns = cv->own_ns + atomic_load_explicit(&cv->parts_ns, memory_order_relaxed) +
                  (ob_time_ns() - t1);
    wave_view_done(w, cv, cv->n, atomic_load_explicit(&cv->coarse, memory_order_relaxed), listed,
                   ns);
}

/* Takes and gathers one part of cv, if one is ready and left. */
static bool wave_take_part(cull_wave *w, cull_view *cv)
{
    uint32_t ready = atomic_load_explicit(&cv->parts_ready, memory_order_acquire);
    uint32_t p = atomic_load_explicit(&cv->part_next, memory_order_relaxed);
    while (p < ready)
        if (atomic_compare_exchange_weak_explicit(&cv->part_next, &p, p + 1, memory_order_relaxed,
                                                  memory_order_relaxed)) {
            wave_gather_part(w, cv, p);
            return true;
        }
    return false;
}

/* A view's sort (of its chunks' pieces in chunk order, so ascending id),
 * draw items and list of one item per material. A big view's items are
 * gathered in parts (wave_gather_part) that the wave's other threads may
 * share once they have no chunk left (wave_idle); this thread takes them
 * too, until none is left. */
static void wave_finish_view(cull_wave *w, cull_view *cv, uint32_t thread)
{
    ob_view *v = cv->v;
    v->cull_thread = w->parallel ? thread : OB_VIEW_NO_THREAD;
    uint64_t t0 = ob_time_ns();
    ob_sort_pair *pairs = cv->c.pairs, *other = pairs + OB_MAX(cv->count, 1u);
    uint32_t n = 0;
    uint64_t chunk_ns = 0;
    for (uint32_t k2 = 0; k2 < w->chunks; k2++) {
        const cull_chunk *ch = &cv->c.chunks[k2];
        chunk_ns += ch->ns;
        n += cv->c.segments[k2].count;
        v->culled += ch->culled;
    }
    /* Sorted where the chunks left them: an order of positions in the
     * chunks' space, or (other lists) sorted pairs, whose index is that
     * position still. Either way the payload is found there. */
    ob_sort_result sorted = ob_sort_pairs_segments(pairs, other, cv->c.segments, w->chunks, n);
    v->material_item_count = 0;
    v->material_items_valid =
        ob_array_reserve((void **)&v->material_items, &v->material_item_cap, OB_MAX(n, 1u),
                         sizeof *v->material_items) == OB_OK;
    if (!v->material_items_valid)
        OB_LOG_W("view", "view '%s': no memory for its list of one item per material; its "
                 "PreRender asks every item's material this frame", v->name);
    for (uint32_t k2 = 0; k2 < v->material_count; k2++) v->materials[k2].seen = 0;
    if (w->parallel && n >= 2 * w->part_items) {
        cv->sorted = sorted;
        cv->n = n;
        uint32_t parts = (n + w->part_items - 1) / w->part_items;
        atomic_store_explicit(&cv->parts_left, parts, memory_order_relaxed);
        cv->own_ns = chunk_ns + (ob_time_ns() - t0);
        atomic_store_explicit(&cv->parts_ready, parts, memory_order_release);
        while (wave_take_part(w, cv)) {}
        return;
    }
    uint32_t coarse = 0, listed = 0;
    for (uint32_t j = 0; j < n; j++) {
        const cull_payload *e = gather_item(v, sorted, cv->c.payload, j);
        coarse += e->proxy_lod > CULL_INDEX_MASK;
        list_material_item(v, e->material, e->node, j, &listed);
    }
    wave_view_done(w, cv, n, coarse, listed, chunk_ns + (ob_time_ns() - t0));
}

/* A thread of the wave with no chunk left: a part of a big view's gather
 * if one is ready, else a bounded wait while some view is still culled or
 * sorted on another thread (every chunk is taken by now, so each of those
 * ends without this thread). */
static bool wave_idle(void *user, uint32_t thread)
{
    cull_wave *w = user;
    if (atomic_load_explicit(&w->open, memory_order_acquire) == 0) return false;
    uint64_t *since = &w->idle_since[OB_MIN(thread, (uint32_t)OB_MAX_WORKERS)];
    bool sorting = false;
    for (uint32_t k = 0; k < w->view_count; k++) {
        cull_view *cv = &w->views[k];
        if (wave_take_part(w, cv)) {
            *since = 0;
            return true;
        }
        sorting |= cv->res == OB_OK &&
                   atomic_load_explicit(&cv->chunks_left, memory_order_relaxed) == 0 &&
                   atomic_load_explicit(&cv->parts_ready, memory_order_relaxed) == 0 &&
                   !atomic_load_explicit(&cv->done, memory_order_relaxed);
    }
    uint64_t now = ob_time_ns();
    if (*since == 0) *since = now;
    return now - *since < (sorting ? WAVE_WAIT_SORT_NS : WAVE_WAIT_CHUNKS_NS);
}

static void wave_chunk_task(void *user, uint32_t task, uint32_t thread)
{
    cull_wave *w = user;
    cull_view *cv = &w->views[task / w->chunks];
    if (cv->res != OB_OK) return;
    uint32_t chunk = task % w->chunks;
    uint64_t t0 = ob_time_ns();
    cull_chunk_run(&cv->c, chunk, thread);
    cv->c.chunks[chunk].ns = ob_time_ns() - t0;
    /* The last of a view's chunks to end finishes the view on its thread
     * (acquire-release: the other chunks' results are seen). Views are
     * sorted while later ones still cull, with no barrier and no second
     * wake of the pool between; each thread takes its chunks view by
     * view, so its first views finish first. */
    if (atomic_fetch_sub_explicit(&cv->chunks_left, 1, memory_order_acq_rel) == 1)
        wave_finish_view(w, cv, thread);
}

/* The entities of a view beyond float range, logged on the caller in view
 * and chunk order (so in the same order whatever the thread count), once
 * until the view has none again. */
static void wave_report_far(const cull_wave *w, cull_view *cv)
{
    ob_view *v = cv->v;
    bool far = false;
    for (uint32_t k2 = 0; k2 < w->chunks; k2++) {
        const cull_chunk *ch = &cv->c.chunks[k2];
        for (uint32_t f = 0; f < OB_MIN(ch->far_count, CULL_LOG_MAX) && !v->range_reported; f++) {
            uint32_t i = ch->far[f];
            /* Finite in double, not in float: no matrix the GPU could take
             * places it, and as a "visible" shadow caster it would blow up
             * the light's fit. */
            OB_LOG_E("view", "view '%s': entity '%s' (id %u) lies beyond float range from "
                     "the view's origin (bound at %.3g, %.3g, %.3g, radius %.3g); not drawn",
                     v->name, ob_node_name(v->soa.node[i]), v->soa.node_id[i],
                     v->soa.x[i] - v->origin[0], v->soa.y[i] - v->origin[1],
                     v->soa.z[i] - v->origin[2], (double)v->soa.radius[i]);
        }
        if (ch->far_count > CULL_LOG_MAX && !v->range_reported)
            OB_LOG_E("view", "view '%s': %u more entities after id %u lie beyond float range "
                     "from the view's origin; not drawn", v->name, ch->far_count - CULL_LOG_MAX,
                     v->soa.node_id[ch->far[CULL_LOG_MAX - 1]]);
        far |= ch->far_count > 0;
    }
    v->range_reported = far;
}

ob_result ob_view_cull_many(ob_renderer *r, const ob_scene *scene, ob_view *const *views,
                            uint32_t count)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    const ob_geometry_iface *gi = ob_renderer_get_geometry_iface(r);
    if (count == 0) return OB_OK;
    if (!scene) {
        /* A frame begun without a scene: nothing to draw. */
        for (uint32_t k = 0; k < count; k++) views[k]->item_count = 0;
        return OB_ERR_INVALID_ARGUMENT;
    }
    /* The views, then the snapshot's geometries (mesh ids, levels of
     * detail): one interface call each per geometry for the whole wave. */
    uint32_t gc = ob_scene_geometry_count(scene);
    cull_wave w = {0};
    w.views = ob_calloc(1, sizeof *w.views * count + sizeof(cull_geometry) * OB_MAX(gc, 1u));
    if (!w.views) {
        OB_LOG_E("view", "%u views not culled: out of host memory; they draw nothing this frame",
                 count);
        for (uint32_t k = 0; k < count; k++) {
            views[k]->item_count = 0;
            ob_renderer_note_error(r, views[k]->name, OB_ERR_OUT_OF_HOST_MEMORY);
        }
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    cull_geometry *geo = (cull_geometry *)(void *)(w.views + count);
    for (uint32_t k = 0; k < gc; k++) {
        struct ob_geometry *g = ob_scene_geometry(scene, k);
        cull_geometry *cg = &geo[k];
        float rel[OB_LOD_MAX] = {0};
        uint32_t levels = 1, id = 0;
        if (gi && g) {
            id = gi->id(g);
            if (gi->lods) levels = OB_MIN(OB_MAX(gi->lods(g, rel), 1u), OB_LOD_MAX);
        }
        /* A level's error not a number, or below the one before, ends the
         * chain there: culling never picks what it cannot compare. */
        rel[0] = 0.0f;
        for (uint32_t l = 1; l < levels; l++)
            if (!(rel[l] >= rel[l - 1]) || !isfinite(rel[l])) {
                levels = l;
                break;
            }
        for (uint32_t l = 1; l < OB_LOD_MAX; l++)
            cg->rel_error[l - 1] = l < levels ? rel[l] : INFINITY;
        _Static_assert(OB_LOD_MAX == 8u, "three bits of the mesh field hold the level");
        cg->mesh = id << 3;
    }
    ob_parallel par = ob_renderer_parallel(r);
    uint32_t entities = 0;
    ob_scene_render_proxies(scene, &entities);
    uint32_t grain = par.grain;
    bool fixed = grain != 0;
    if (!fixed) {
        uint64_t share = (uint64_t)entities * count / (4u * OB_MAX(par.threads, 1u));
        grain = (uint32_t)OB_MIN(CULL_GRAIN, OB_MAX(CULL_GRAIN_MIN, share));
    }
    bool parallel = ob_parallel_worth(&par, (uint64_t)entities * count, grain);
    w.view_count = count;
    w.chunks = (entities + grain - 1) / grain;
    w.part_items = fixed ? grain : GATHER_PART;
    ob_result first_error = OB_OK;
    uint32_t open = 0;
    for (uint32_t k = 0; k < count; k++) {
        cull_view *cv = &w.views[k];
        cv->v = views[k];
        cv->res = cull_setup(cv, r, scene, mi, geo, grain);
        atomic_init(&cv->chunks_left, w.chunks);
        atomic_init(&cv->parts_ready, 0u);
        atomic_init(&cv->part_next, 0u);
        atomic_init(&cv->parts_left, 0u);
        atomic_init(&cv->coarse, 0u);
        atomic_init(&cv->parts_ns, 0u);
        atomic_init(&cv->done, false);
        if (cv->res != OB_OK && first_error == OB_OK) first_error = cv->res;
        open += cv->res == OB_OK && w.chunks > 0;
    }
    atomic_init(&w.open, open);
    if (!parallel) par.threads = 1;
    w.parallel = par.threads > 1;
    ob_parallel_run_helped(&par, w.chunks * count, wave_chunk_task, wave_idle, &w);
    for (uint32_t k = 0; k < count; k++) {
        cull_view *cv = &w.views[k];
        if (cv->res != OB_OK) continue;
        if (w.chunks == 0) {
            atomic_fetch_add_explicit(&w.open, 1, memory_order_relaxed);
            wave_finish_view(&w, cv, 0); /* no entities: an empty list */
        }
        wave_report_far(&w, cv);
        cv->v->cull_ns = cv->ns;
    }
    ob_free(w.views);
    return first_error;
}

ob_result ob_view_cull(ob_view *v, ob_renderer *r, const ob_scene *scene, const ob_node *exclude)
{
    v->cull_exclude = exclude;
    return ob_view_cull_many(r, scene, &v, 1);
}

uint32_t ob_view_item_material(const ob_view *v, uint32_t item)
{
    return v->soa.material[v->items[item].proxy];
}

void ob_view_item_sphere(const ob_view *v, uint32_t item, double center[3], float *radius)
{
    uint32_t i = v->items[item].proxy;
    center[0] = v->soa.x[i];
    center[1] = v->soa.y[i];
    center[2] = v->soa.z[i];
    *radius = v->soa.radius[i];
}

void ob_view_for_each_material_item(ob_view *v,
                                    void (*fn)(void *user, ob_view *v,
                                               const ob_view_material_item *e),
                                    void *user)
{
    if (!v->material_count || !v->material_items_valid) {
        /* Not culled through ob_view_cull (a custom list), or no memory
         * for the short list: every item. */
        for (uint32_t i = 0; i < v->item_count; i++) {
            ob_node *n = v->items[i].node;
            const ob_renderable *rd = n ? ob_node_get_renderable(n) : NULL;
            ob_view_material_item e = {.node = n, .material = rd ? rd->material : NULL, .item = i};
            fn(user, v, &e);
        }
        return;
    }
    for (uint32_t k = 0; k < v->material_item_count; k++)
        if (v->material_items[k].item < v->item_count) fn(user, v, &v->material_items[k]);
}

typedef struct pre_render_ctx {
    const ob_material_iface *mi;
    ob_renderer *r;
} pre_render_ctx;

static void pre_render_item(void *user, ob_view *v, const ob_view_material_item *e)
{
    const pre_render_ctx *c = user;
    if (e->material) c->mi->pre_render(e->material, e->node, c->r, v);
}

void ob_view_pre_render_items(ob_view *v, ob_renderer *r)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    if (!mi || !mi->pre_render) return;
    /* Items can be appended to other views during this loop, never to v. */
    pre_render_ctx c = {mi, r};
    ob_view_for_each_material_item(v, pre_render_item, &c);
}

/* Items ahead of the one being drawn whose proxy is prefetched. */
#define PROXY_PREFETCH 16u

/* Instances gathered before a draw: a longer run takes several draws (its
 * hash is the same either way). 6 KiB of stack. */
#define RUN_BLOCKS 128u

static void log_not_finite(const ob_view *v, const ob_draw_item *it)
{
    OB_LOG_E("view", "view '%s': entity '%s' (id %u): world matrix not finite in float "
             "(or its derived matrices); not drawn", v->name, ob_node_name(it->node), it->node_id);
}

void ob_view_record_items(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                          uint32_t first, uint32_t count)
{
    const ob_material_iface *mi = ob_renderer_get_material_iface(r);
    const ob_geometry_iface *gi = ob_renderer_get_geometry_iface(r);
    /* Items are sorted by state: a run of one material is applied once, a
     * run of one geometry asks for its draw data once, and with an
     * instanced program a run of both is one draw. The list says where a
     * run ends; of an entity, only its proxy's line is read. */
    uint32_t applied = 0, described = 0, described_lod = 0;
    ob_draw_data dd = {0};
    _Alignas(16) float block[32];
    _Alignas(16) float rows[RUN_BLOCKS][OB_INSTANCE_FLOATS];
    const ob_draw_item *items = v->items;
    uint32_t end = first + count < v->item_count ? first + count : v->item_count;
    for (uint32_t i = first; i < end;) {
        /* Items are in draw order, proxies in id order: fetch a few ahead so
         * the loop does not wait on memory. */
        if (i + PROXY_PREFETCH < end)
            __builtin_prefetch(&v->proxies[items[i + PROXY_PREFETCH].proxy]);
        const ob_draw_item *it = &items[i];
        if (!it->material) {
            i++;
            continue;
        }
        if (it->material != applied) {
            ob_apply_result a = mi->apply(v->soa.materials[it->material], it->node, r, pm, v);
            applied = a == OB_APPLY_MATERIAL ? it->material : 0;
            if (a == OB_APPLY_SKIP) {
                i++;
                continue;
            }
        }
        uint32_t lod = it->lod;
        if (it->geometry != described || lod != described_lod) {
            gi->draw_data(v->soa.geometries[it->geometry], lod, &dd);
            described = it->geometry;
            described_lod = lod;
        }
        if (!ob_pipeline_manager_instanced(pm)) {
            /* A refused matrix is not drawn (a stale one would put this
             * entity where the previous one was). */
            bool finite = ob_render_proxy_per_draw(&v->proxies[it->proxy], v->origin, block);
            if (!finite || ob_pipeline_manager_draw_data(pm, &dd, block) == OB_ERR_NON_FINITE)
                log_not_finite(v, it);
            i++;
            continue;
        }
        /* The run: this item and the next ones of the material applied for
         * all (an entity-dependent one is applied per item), this mesh and
         * the same front face (the update found which entities mirror). */
        uint32_t n = 0, j = i;
        uint8_t mirrors = v->proxies[it->proxy].mirrors;
        do {
            if (j + PROXY_PREFETCH < end)
                __builtin_prefetch(&v->proxies[items[j + PROXY_PREFETCH].proxy]);
            if (ob_render_proxy_instance(&v->proxies[items[j].proxy], v->origin, rows[n])) n++;
            else log_not_finite(v, &items[j]);
            j++;
        } while (j < end && n < RUN_BLOCKS && applied && items[j].material == applied &&
                 items[j].geometry == it->geometry && items[j].lod == lod &&
                 v->proxies[items[j].proxy].mirrors == mirrors);
        if (n) ob_pipeline_manager_draw_instances_facing(pm, &dd, &rows[0][0], n, mirrors);
        i = j;
    }
}

void ob_view_record_draw_list(ob_view *v, ob_renderer *r, ob_pipeline_manager *pm,
                              uint32_t layer, uint32_t first, uint32_t count)
{
    (void)layer;
    ob_view_record_items(v, r, pm, first, count);
}
