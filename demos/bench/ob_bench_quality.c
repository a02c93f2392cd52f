#include "ob_bench_quality.h"

#include <math.h>
#include <string.h>

#define MAX_IMAGE_FRAMES 64

const char *ob_bench_quality_kind_name(ob_bench_quality_kind k)
{
    switch (k) {
    case OB_BENCH_QUALITY_REFERENCE: return "reference";
    case OB_BENCH_QUALITY_ENV: return "env-map";
    case OB_BENCH_QUALITY_SHADOW: return "shadow-map";
    case OB_BENCH_QUALITY_THREADING: return "threading";
    case OB_BENCH_QUALITY_MSAA_REFERENCE: return "msaa-reference";
    case OB_BENCH_QUALITY_MSAA: return "msaa";
    case OB_BENCH_QUALITY_ENV_CUBE_REFERENCE: return "env-cube-reference";
    case OB_BENCH_QUALITY_ENV_CUBE: return "env-cube";
    }
    return "unknown";
}

void ob_bench_image_error(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h,
                          uint32_t *out_max_abs, double *out_psnr_db)
{
    uint32_t max_abs = 0;
    double sum2 = 0.0;
    size_t n = (size_t)w * h;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) {
            int d = (int)a[4 * i + c] - (int)b[4 * i + c];
            uint32_t ad = (uint32_t)(d < 0 ? -d : d);
            if (ad > max_abs) max_abs = ad;
            sum2 += (double)d * d;
        }
    }
    double mse = n ? sum2 / (3.0 * (double)n) : 0.0;
    *out_max_abs = max_abs;
    *out_psnr_db = mse > 0.0 ? 10.0 * log10(255.0 * 255.0 / mse) : INFINITY;
}

static double srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static double linear_to_srgb(double c)
{
    return c <= 0.0031308 ? c * 12.92 : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

void ob_bench_image_downsample_srgb(const uint8_t *src, uint32_t w, uint32_t h, uint32_t scale,
                                    uint8_t *dst)
{
    double lin[256];
    for (int i = 0; i < 256; i++) lin[i] = srgb_to_linear(i / 255.0);
    size_t sw = (size_t)w * scale;
    double inv = 1.0 / ((double)scale * scale);
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            double sum[3] = {0, 0, 0};
            for (uint32_t j = 0; j < scale; j++) {
                const uint8_t *row = src + 4 * (((size_t)y * scale + j) * sw + (size_t)x * scale);
                for (uint32_t i = 0; i < scale; i++)
                    for (int c = 0; c < 3; c++) sum[c] += lin[row[4 * i + c]];
            }
            uint8_t *out = dst + 4 * ((size_t)y * w + x);
            for (int c = 0; c < 3; c++) {
                double v = linear_to_srgb(OB_MIN(OB_MAX(sum[c] * inv, 0.0), 1.0)) * 255.0 + 0.5;
                out[c] = (uint8_t)OB_MIN(v, 255.0);
            }
            out[3] = 255;
        }
    }
}

uint32_t ob_bench_msaa_counts(uint32_t max_offered, uint32_t offered, uint32_t out[4])
{
    uint32_t n = 0;
    for (uint32_t s = 1; s <= 8 && s <= OB_MAX(max_offered, 1u); s <<= 1)
        if (s == 1 || (offered & s)) out[n++] = s;
    return n;
}

/* One rendered configuration: its image, per-frame hashes and timings. */
typedef struct rendering {
    uint8_t *pixels;
    uint64_t hashes[MAX_IMAGE_FRAMES];
    ob_bench_result timing;
    uint32_t samples;              /* the main view's, as made */
    uint32_t offered;              /* sample counts the device's limits offer for colour
                                      and depth framebuffers (VkSampleCountFlags) */
} rendering;

/* How one configuration is drawn besides its quality settings. */
typedef struct render_how {
    uint32_t msaa;                 /* asked for: 0 or 1 → none */
    uint32_t scale;                /* size factor per axis: 0 or 1 → the desc's size */
    bool timed;                    /* timing rounds after the image */
    bool exact;                    /* draw nothing unless the view got msaa samples */
    ob_env_map_kind env_kind;      /* environment maps: paraboloid (0) or cube */
} render_how;

static ob_result render_config_as(const ob_bench_quality_desc *desc, uint32_t env, uint32_t shadow,
                                  const ob_bench_mode *mode, render_how how, rendering *out)
{
    ob_demo_options o = desc->base;
    uint32_t scale = how.scale > 1 ? how.scale : 1;
    o.width *= scale;
    o.height *= scale;
    o.msaa = how.msaa;
    o.env_size = env;
    o.shadow_size = shadow;
    o.env_map_kind = how.env_kind;
    o.threads = (int)desc->pool_workers;
    o.quiet = true;
    o.overlay = false;
    o.stats_json = NULL;
    ob_demo d;
    ob_bench_scene s = {0};
    ob_result r = ob_demo_init(&d, &o);
    ob_bench_scene_desc sd = {.kind = OB_BENCH_SCENE_MIRROR, .objects = o.objects, .seed = o.seed};
    if (r == OB_OK) {
        const VkPhysicalDeviceLimits *lim = &ob_device_properties(ob_renderer_device(d.world.r))->limits;
        out->offered = lim->framebufferColorSampleCounts & lim->framebufferDepthSampleCounts;
        out->samples = ob_perspective_view_samples(d.world.main);
        /* The format's own counts may be fewer than the limits say: the
         * view was made with fewer samples (logged), so there is no row. */
        if (how.exact && out->samples != OB_MAX(how.msaa, 1u)) {
            ob_demo_shutdown(&d);
            return OB_OK;
        }
    }
    if (r == OB_OK) r = ob_bench_scene_build(&s, &d, &sd);
    /* Drop the demo's per-frame history: these frames are counted here. */
    if (r == OB_OK) ob_renderer_set_stats_callback(d.world.r, NULL, NULL);
    const double dt = 1.0 / 60.0;
    uint32_t frames = OB_MIN(desc->image_frames, (uint32_t)MAX_IMAGE_FRAMES);
    for (uint32_t f = 0; f < frames && r == OB_OK; f++) {
        ob_bench_set_mode(d.world.r, mode);
        r = ob_bench_scene_frame(&s, true, dt);
        if (r == OB_OK) out->hashes[f] = ob_renderer_current_stats(d.world.r)->frame_hash;
        if (desc->tick) desc->tick(desc->tick_user);
    }
    if (r == OB_OK) r = ob_renderer_wait_idle(d.world.r);
    if (r == OB_OK) {
        out->pixels = ob_malloc((size_t)o.width * o.height * 4);
        r = out->pixels ? ob_image_read_rgba8(ob_renderer_device(d.world.r),
                                              ob_composite_view_target(d.world.composite), out->pixels)
                        : OB_ERR_OUT_OF_HOST_MEMORY;
    }
    if (r == OB_OK && how.timed && (desc->rounds || desc->flight)) {
        ob_bench_run_desc rd = {.modes = mode, .mode_count = 1, .rounds = desc->rounds,
                                .flight = desc->flight, .dt = dt, .tick = desc->tick,
                                .tick_user = desc->tick_user};
        r = ob_bench_run_modes(&s, &rd, &out->timing);
    }
    if (r != OB_OK)
        OB_LOG_E("bench", "mirror scene %ux%u with %s env map %u, shadow map %u, MSAA %ux, mode %s "
                 "failed: %s", o.width, o.height, how.env_kind == OB_ENV_MAP_CUBE ? "cube" : "paraboloid",
                 env, shadow, OB_MAX(how.msaa, 1u), mode->name, ob_result_name(r));
    if (d.world.r) ob_renderer_wait_idle(d.world.r);
    ob_bench_scene_release(&s);
    ob_demo_shutdown(&d);
    return r;
}

static ob_result render_config(const ob_bench_quality_desc *desc, uint32_t env, uint32_t shadow,
                               const ob_bench_mode *mode, rendering *out)
{
    return render_config_as(desc, env, shadow, mode, (render_how){.timed = true}, out);
}

static void fill_row(ob_bench_quality_row *row, ob_bench_quality_kind kind, uint32_t env,
                     uint32_t shadow, const ob_bench_mode *mode, const rendering *ref,
                     const rendering *got, const ob_bench_quality_desc *desc)
{
    *row = (ob_bench_quality_row){.kind = kind, .env_size = env, .shadow_size = shadow,
                                  .mode = *mode, .msaa_samples = OB_MAX(got->samples, 1u),
                                  .supersample = 1};
    ob_bench_image_error(ref->pixels, got->pixels, desc->base.width, desc->base.height,
                         &row->max_abs_diff, &row->psnr_db);
    row->frame_ms = got->timing.frame_ms;
    row->gpu_ms = got->timing.gpu_ms;
    row->record_total_ms = got->timing.record_total_ms;
    row->cpu_frame_ms = got->timing.cpu_frame_ms;
    row->draws = got->timing.draws;
    /* Other quality settings record other commands: only modes compare. */
    for (uint32_t f = 0; kind == OB_BENCH_QUALITY_THREADING && f < desc->image_frames &&
                         f < MAX_IMAGE_FRAMES; f++)
        if (ref->hashes[f] != got->hashes[f]) row->hash_mismatches++;
}

/* The MSAA rows: the supersampled reference, then each offered count (1x
 * is the reference rendering ref, drawn with the same settings). */
static ob_result msaa_series(const ob_bench_quality_desc *desc, uint32_t env, uint32_t shadow,
                             const ob_bench_mode *st, const rendering *ref,
                             ob_bench_quality_row *rows, uint32_t *n)
{
    uint32_t w = desc->base.width, h = desc->base.height;
    uint32_t scale = desc->msaa_scale ? desc->msaa_scale : 4;
    while (scale > 1 && (w * scale > 4096 || h * scale > 4096)) scale--;
    rendering big = {0};
    ob_result r = render_config_as(desc, env, shadow, st,
                                   (render_how){.msaa = 8, .scale = scale}, &big);
    rendering aa = {.samples = big.samples};
    if (r == OB_OK) {
        aa.pixels = ob_malloc((size_t)w * h * 4);
        if (!aa.pixels) r = OB_ERR_OUT_OF_HOST_MEMORY;
    }
    if (r == OB_OK) {
        ob_bench_image_downsample_srgb(big.pixels, w, h, scale, aa.pixels);
        ob_bench_quality_row *row = &rows[(*n)++];
        fill_row(row, OB_BENCH_QUALITY_MSAA_REFERENCE, env, shadow, st, &aa, &aa, desc);
        row->supersample = scale;
        row->frame_ms = row->gpu_ms = row->record_total_ms = row->cpu_frame_ms = NAN;
    }
    ob_free(big.pixels);
    uint32_t counts[4];
    uint32_t count = r == OB_OK ? ob_bench_msaa_counts(aa.samples, big.offered, counts) : 0;
    for (uint32_t i = 0; i < count && r == OB_OK; i++) {
        if (counts[i] == 1) {
            fill_row(&rows[(*n)++], OB_BENCH_QUALITY_MSAA, env, shadow, st, &aa, ref, desc);
            continue;
        }
        rendering got = {0};
        r = render_config_as(desc, env, shadow, st,
                             (render_how){.msaa = counts[i], .timed = true, .exact = true}, &got);
        if (r == OB_OK && got.pixels)
            fill_row(&rows[(*n)++], OB_BENCH_QUALITY_MSAA, env, shadow, st, &aa, &got, desc);
        ob_free(got.pixels);
    }
    ob_free(aa.pixels);
    return r;
}

ob_result ob_bench_quality_run(const ob_bench_quality_desc *desc, ob_bench_quality_row **out_rows,
                               uint32_t *out_count)
{
    *out_rows = NULL;
    *out_count = 0;
    if (!desc->env_count || !desc->shadow_count || !desc->mode_count || !desc->image_frames)
        return OB_ERR_INVALID_ARGUMENT;
    uint32_t env_ref = desc->env_sizes[desc->env_count - 1];
    uint32_t shadow_ref = desc->shadow_sizes[desc->shadow_count - 1];
    uint32_t cap = 1 + desc->env_count + desc->shadow_count + desc->mode_count + (desc->msaa ? 5 : 0) +
                   (desc->env_cube ? desc->env_count : 0);
    ob_bench_quality_row *rows = ob_calloc(cap, sizeof *rows);
    if (!rows) return OB_ERR_OUT_OF_HOST_MEMORY;
    uint32_t n = 0;
    const ob_bench_mode *st = &desc->modes[0];
    rendering ref = {0};
    ob_result r = render_config(desc, env_ref, shadow_ref, st, &ref);
    if (r == OB_OK) fill_row(&rows[n++], OB_BENCH_QUALITY_REFERENCE, env_ref, shadow_ref, st, &ref, &ref, desc);
    for (uint32_t m = 1; m < desc->mode_count && r == OB_OK; m++) {
        rendering got = {0};
        r = render_config(desc, env_ref, shadow_ref, &desc->modes[m], &got);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_THREADING, env_ref, shadow_ref, &desc->modes[m],
                     &ref, &got, desc);
        ob_free(got.pixels);
    }
    /* The reference is also the last step of both quality series. */
    for (uint32_t i = 0; i + 1 < desc->env_count && r == OB_OK; i++) {
        rendering got = {0};
        r = render_config(desc, desc->env_sizes[i], shadow_ref, st, &got);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_ENV, desc->env_sizes[i], shadow_ref, st, &ref,
                     &got, desc);
        ob_free(got.pixels);
    }
    /* The cube series: its own reference (the two kinds differ at any
     * size: the paraboloid bends what the cube draws straight), then each
     * smaller size against it. */
    rendering cube_ref = {0};
    const render_how cube = {.timed = true, .env_kind = OB_ENV_MAP_CUBE};
    if (desc->env_cube && r == OB_OK) {
        r = render_config_as(desc, env_ref, shadow_ref, st, cube, &cube_ref);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_ENV_CUBE_REFERENCE, env_ref, shadow_ref, st, &ref,
                     &cube_ref, desc);
    }
    for (uint32_t i = 0; desc->env_cube && i + 1 < desc->env_count && r == OB_OK; i++) {
        rendering got = {0};
        r = render_config_as(desc, desc->env_sizes[i], shadow_ref, st, cube, &got);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_ENV_CUBE, desc->env_sizes[i], shadow_ref, st,
                     &cube_ref, &got, desc);
        ob_free(got.pixels);
    }
    ob_free(cube_ref.pixels);
    for (uint32_t i = 0; i + 1 < desc->shadow_count && r == OB_OK; i++) {
        rendering got = {0};
        r = render_config(desc, env_ref, desc->shadow_sizes[i], st, &got);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_SHADOW, env_ref, desc->shadow_sizes[i], st, &ref,
                     &got, desc);
        ob_free(got.pixels);
    }
    if (r == OB_OK && desc->msaa) r = msaa_series(desc, env_ref, shadow_ref, st, &ref, rows, &n);
    ob_free(ref.pixels);
    if (r != OB_OK) {
        ob_free(rows);
        return r;
    }
    *out_rows = rows;
    *out_count = n;
    return OB_OK;
}
