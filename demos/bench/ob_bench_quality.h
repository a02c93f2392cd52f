/* ob_bench_quality.h — image error against run time, and the threading
 * modes' identity check, on the mirror scene.
 *
 * Every configuration is a fresh demo (renderer, views, scene built from the
 * same seed) that renders the same sequence of `image_frames` frames with a
 * fixed time step and reads the final image back; then it is timed (idle
 * rounds for CPU and GPU time, then frames in flight for the frame period).
 *   reference   highest env-map and shadow-map size, single-threaded
 *   quality     each env-map size (shadow map at its highest) and each
 *               shadow-map size (env map at its highest), single-threaded:
 *               max abs difference and PSNR over RGB against the reference
 *   env-cube-reference  (desc.env_cube) the reference with cube maps (six
 *               faces of the same side instead of two paraboloid halves),
 *               against the reference: how far the two kinds differ (the
 *               paraboloid bends long straight edges, the cube does not)
 *   env-cube    each smaller env-map size with cube maps against the cube
 *               reference: the cube series' error next to its cost, as the
 *               env-map rows are the paraboloid's
 *   threading   every other mode at the reference quality: its image must be
 *               byte-identical to the reference and the command hash of each
 *               of its frames equal to the reference's frame of the same index
 *   msaa        (desc.msaa) the main view's samples per pixel: each count
 *               the device offers of 1, 2, 4, 8
 *               (lavapipe: 1 and 4; a count whose format the device does
 *               not offer has no row) at the reference quality,
 *               single-threaded, against the antialiasing reference: the
 *               same configuration rendered at msaa_scale times the size in
 *               each axis with the highest MSAA the device offers (8x asked
 *               for), box-downsampled msaa_scale x msaa_scale in linear
 *               light (sRGB decoded, averaged, encoded again). That row
 *               (OB_BENCH_QUALITY_MSAA_REFERENCE) says its samples and scale
 *               and has no times: it is drawn at another size. The 1x row is
 *               the reference rendering itself (same configuration), not a
 *               second run.
 *
 * Lifecycle: one call; rows are ob_malloc'ed, the caller ob_frees them.
 * Thread rule: render thread; creates and destroys its own renderers.
 */
#ifndef OB_BENCH_QUALITY_H
#define OB_BENCH_QUALITY_H

#include "ob_bench_run.h"

typedef enum ob_bench_quality_kind {
    OB_BENCH_QUALITY_REFERENCE = 0,
    OB_BENCH_QUALITY_ENV,
    OB_BENCH_QUALITY_SHADOW,
    OB_BENCH_QUALITY_THREADING,
    OB_BENCH_QUALITY_MSAA_REFERENCE,
    OB_BENCH_QUALITY_MSAA,
    OB_BENCH_QUALITY_ENV_CUBE_REFERENCE, /* cube maps at the reference size, against the reference */
    OB_BENCH_QUALITY_ENV_CUBE,     /* smaller cube maps, against the cube reference */
} ob_bench_quality_kind;

typedef struct ob_bench_quality_desc {
    ob_demo_options base;          /* size, seed, objects (200) */
    uint32_t pool_workers;         /* renderer worker pool (largest mode) */
    uint32_t image_frames;         /* frames before the image is read (≥ 1) */
    uint32_t rounds, flight;       /* timing after the image (ob_bench_run_modes) */
    const uint32_t *env_sizes;     /* ascending; the last is the reference's */
    uint32_t env_count;
    const uint32_t *shadow_sizes;  /* ascending; the last is the reference's */
    uint32_t shadow_count;
    const ob_bench_mode *modes;    /* modes[0] is the reference mode (single-threaded) */
    uint32_t mode_count;
    bool msaa;                     /* also the MSAA series */
    bool env_cube;                 /* also the env-map sizes as cube maps (the cube series) */
    uint32_t msaa_scale;           /* its reference's size factor per axis: 0 → 4; lowered so
                                      that neither side passes 4096 (at least 1) */
    ob_bench_tick_fn tick;
    void *tick_user;
} ob_bench_quality_desc;

typedef struct ob_bench_quality_row {
    ob_bench_quality_kind kind;
    uint32_t env_size, shadow_size;
    ob_bench_mode mode;
    uint32_t max_abs_diff;         /* over R, G, B of every pixel */
    double psnr_db;                /* INFINITY when identical */
    double frame_ms, gpu_ms, record_total_ms, cpu_frame_ms;
    uint32_t hash_mismatches;      /* threading rows: frames whose hash differs from the
                                      reference's (0 in other rows) */
    uint32_t draws;
    uint32_t msaa_samples;         /* main view's samples per pixel as drawn (1 but in the
                                      MSAA rows) */
    uint32_t supersample;          /* size factor per axis the image was drawn at before
                                      the box downsample (1 but in the MSAA reference) */
} ob_bench_quality_row;

ob_result ob_bench_quality_run(const ob_bench_quality_desc *desc, ob_bench_quality_row **out_rows,
                               uint32_t *out_count);

/* Error of b against a, RGBA8 images of w*h pixels (alpha ignored). */
void ob_bench_image_error(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h,
                          uint32_t *out_max_abs, double *out_psnr_db);

/* Box-downsamples src (RGBA8, sRGB-encoded, (w*scale) x (h*scale)) into
 * dst (w x h): each scale x scale block averaged in linear light, alpha
 * 255. Any thread; no failure. */
void ob_bench_image_downsample_srgb(const uint8_t *src, uint32_t w, uint32_t h, uint32_t scale,
                                    uint8_t *dst);

/* MSAA counts measured for a device whose view got at most max_offered
 * samples and whose limits offer the VkSampleCountFlags `offered`: 1, then
 * the powers of two 2..8 up to max_offered that offered has, ascending,
 * into out (4 entries); returns how many. */
uint32_t ob_bench_msaa_counts(uint32_t max_offered, uint32_t offered, uint32_t out[4]);

const char *ob_bench_quality_kind_name(ob_bench_quality_kind k);

#endif /* OB_BENCH_QUALITY_H */
