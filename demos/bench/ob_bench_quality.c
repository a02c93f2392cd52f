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

/* One rendered configuration: its image, per-frame hashes and timings. */
typedef struct rendering {
    uint8_t *pixels;
    uint64_t hashes[MAX_IMAGE_FRAMES];
    ob_bench_result timing;
} rendering;

static ob_result render_config(const ob_bench_quality_desc *desc, uint32_t env, uint32_t shadow,
                               const ob_bench_mode *mode, rendering *out)
{
    ob_demo_options o = desc->base;
    o.env_size = env;
    o.shadow_size = shadow;
    o.threads = (int)desc->pool_workers;
    o.quiet = true;
    o.overlay = false;
    o.stats_json = NULL;
    ob_demo d;
    ob_bench_scene s = {0};
    ob_result r = ob_demo_init(&d, &o);
    ob_bench_scene_desc sd = {.kind = OB_BENCH_SCENE_MIRROR, .objects = o.objects, .seed = o.seed};
    if (r == OB_OK) r = ob_bench_scene_build(&s, &d, &sd);
    /* Drop the demo's per-frame history: these frames are counted here. */
    if (r == OB_OK) ob_renderer_set_stats_callback(d.r, NULL, NULL);
    const double dt = 1.0 / 60.0;
    uint32_t frames = OB_MIN(desc->image_frames, (uint32_t)MAX_IMAGE_FRAMES);
    for (uint32_t f = 0; f < frames && r == OB_OK; f++) {
        ob_bench_set_mode(d.r, mode);
        r = ob_bench_scene_frame(&s, true, dt);
        if (r == OB_OK) out->hashes[f] = ob_renderer_current_stats(d.r)->frame_hash;
        if (desc->tick) desc->tick(desc->tick_user);
    }
    if (r == OB_OK) r = ob_renderer_wait_idle(d.r);
    if (r == OB_OK) {
        out->pixels = ob_malloc((size_t)o.width * o.height * 4);
        r = out->pixels ? ob_image_read_rgba8(ob_renderer_device(d.r),
                                              ob_composite_view_target(d.composite), out->pixels)
                        : OB_ERR_OUT_OF_HOST_MEMORY;
    }
    if (r == OB_OK && (desc->rounds || desc->flight)) {
        ob_bench_run_desc rd = {.modes = mode, .mode_count = 1, .rounds = desc->rounds,
                                .flight = desc->flight, .dt = dt, .tick = desc->tick,
                                .tick_user = desc->tick_user};
        r = ob_bench_run_modes(&s, &rd, &out->timing);
    }
    if (r != OB_OK)
        OB_LOG_E("bench", "mirror scene with env map %u, shadow map %u, mode %s failed: %s", env,
                 shadow, mode->name, ob_result_name(r));
    if (d.r) ob_renderer_wait_idle(d.r);
    ob_bench_scene_release(&s);
    ob_demo_shutdown(&d);
    return r;
}

static void fill_row(ob_bench_quality_row *row, ob_bench_quality_kind kind, uint32_t env,
                     uint32_t shadow, const ob_bench_mode *mode, const rendering *ref,
                     const rendering *got, const ob_bench_quality_desc *desc)
{
    *row = (ob_bench_quality_row){.kind = kind, .env_size = env, .shadow_size = shadow,
                                  .mode = *mode};
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

ob_result ob_bench_quality_run(const ob_bench_quality_desc *desc, ob_bench_quality_row **out_rows,
                               uint32_t *out_count)
{
    *out_rows = NULL;
    *out_count = 0;
    if (!desc->env_count || !desc->shadow_count || !desc->mode_count || !desc->image_frames)
        return OB_ERR_INVALID_ARGUMENT;
    uint32_t env_ref = desc->env_sizes[desc->env_count - 1];
    uint32_t shadow_ref = desc->shadow_sizes[desc->shadow_count - 1];
    uint32_t cap = 1 + desc->env_count + desc->shadow_count + desc->mode_count;
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
    for (uint32_t i = 0; i + 1 < desc->shadow_count && r == OB_OK; i++) {
        rendering got = {0};
        r = render_config(desc, env_ref, desc->shadow_sizes[i], st, &got);
        if (r == OB_OK)
            fill_row(&rows[n++], OB_BENCH_QUALITY_SHADOW, env_ref, desc->shadow_sizes[i], st, &ref,
                     &got, desc);
        ob_free(got.pixels);
    }
    ob_free(ref.pixels);
    if (r != OB_OK) {
        ob_free(rows);
        return r;
    }
    *out_rows = rows;
    *out_count = n;
    return OB_OK;
}
