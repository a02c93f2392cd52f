#define _POSIX_C_SOURCE 200809L
#include "ob_bench_lights.h"

#include <math.h>
#include <stdio.h>
#include <sys/resource.h>

#include "ob_world.h"

const uint32_t ob_bench_light_counts[OB_BENCH_LIGHT_COUNTS] = {0, 4, 16, 64, 256};

/* The wall is 12 x 9 where the lights stand. */
#define WALL_W 12.0
#define WALL_H 9.0

static double process_cpu_ms(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
           (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e3;
}

static float light_range(uint32_t lights)
{
    if (!lights) return 0.0f;
    uint32_t g = (uint32_t)ceil(sqrt((double)(lights ? lights : 1)));
    return (float)(1.25 * WALL_W / g);
}

/* The scene with `lights` point lights; w->err says what failed. */
static ob_result build(ob_world *w, const ob_bench_lights_desc *d, uint32_t lights)
{
    ob_world_desc wd = ob_world_desc_small("obelisk-bench lights");
    wd.stack.width = d->width;
    wd.stack.height = d->height;
    ob_result r = ob_world_create(w, &wd);
    if (r != OB_OK) return r;
    ob_world_look(w, 0, 0, 8, 0, 0, 0);
    ob_material *m = ob_world_material(w, "wall", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, false);
    ob_node *wall = ob_world_entity(w, NULL, "wall", w->plane, m, 0, 0, 0);
    if (wall) ob_node_set_rotation_d(wall, (const double[4]){sqrt(0.5), 0, 0, sqrt(0.5)});
    for (int i = 0; i < 120; i++)
        ob_world_entity(w, NULL, "box", w->box, m, -5.5 + 1.0 * (i % 12), -4 + 0.8 * (i / 12), 0.4);
    uint32_t g = (uint32_t)ceil(sqrt((double)(lights ? lights : 1)));
    ob_light_desc ld = {.type = OB_LIGHT_POINT, .intensity = 0.5f, .range = light_range(lights)};
    for (uint32_t i = 0; i < lights && w->err == OB_OK; i++) {
        ob_node *n = ob_node_create(w->scene, NULL, "lamp", &r);
        if (!n) return r;
        if ((r = ob_node_set_light(n, &ld)) != OB_OK) return r;
        ob_node_set_position(n, (const double[3]){-WALL_W / 2 + WALL_W * ((i % g) + 0.5) / g,
                                                  -WALL_H / 2 + WALL_H * ((i / g) + 0.5) / g, 0.6});
    }
    return w->err;
}

uint64_t ob_bench_lights_frames(const ob_bench_lights_desc *d)
{
    /* Per count: 3 warm-up frames, then per round and mode one unmeasured
     * frame after the switch and the measured ones. */
    return (uint64_t)OB_BENCH_LIGHT_COUNTS * (3 + 2ull * d->rounds * (d->frames + 1));
}

ob_result ob_bench_lights_run(const ob_bench_lights_desc *d, ob_bench_lights_row **out_rows,
                              uint32_t *out_count)
{
    *out_rows = NULL;
    *out_count = 0;
    uint32_t per_mode = d->rounds * d->frames;
    ob_bench_lights_row *rows = ob_calloc(2 * OB_BENCH_LIGHT_COUNTS, sizeof *rows);
    double *samples = ob_calloc(2 * (size_t)per_mode, sizeof *samples);
    ob_result r = rows && samples ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t c = 0; c < OB_BENCH_LIGHT_COUNTS && r == OB_OK; c++) {
        uint32_t lights = ob_bench_light_counts[c];
        ob_world w;
        r = build(&w, d, lights);
        bool cpu = r == OB_OK && ob_device_is_cpu(w.dev);
        for (int warm = 0; warm < 3 && r == OB_OK; warm++) {
            r = ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0);
            if (d->tick) d->tick(d->tick_user);
        }
        uint32_t n[2] = {0, 0};
        for (uint32_t round = 0; round < 2 * d->rounds && r == OB_OK; round++) {
            int tiles = round % 2 == 0;
            ob_views_set_light_tiles(w.views, tiles);
            r = ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0);   /* the switch's first */
            if (d->tick) d->tick(d->tick_user);
            for (uint32_t f = 0; f < d->frames && r == OB_OK; f++) {
                double t0 = process_cpu_ms();
                r = ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0);
                double ms = cpu ? process_cpu_ms() - t0 : ob_world_stats(&w)->gpu_ms;
                samples[tiles * per_mode + n[tiles]++] = ms >= 0.0 ? ms : NAN;
                if (d->tick) d->tick(d->tick_user);
            }
        }
        for (int t = 1; t >= 0 && r == OB_OK; t--) {
            ob_bench_lights_row *row = &rows[(*out_count)++];
            *row = (ob_bench_lights_row){.lights = lights, .range = light_range(lights),
                                         .tiles = t, .cpu_measure = cpu};
            ob_bench_spread_of(samples + t * per_mode, n[t], &row->cost_ms);
        }
        ob_world_destroy(&w);
    }
    ob_free(samples);
    if (r != OB_OK) {
        ob_free(rows);
        *out_count = 0;
        return r;
    }
    *out_rows = rows;
    return OB_OK;
}

static double cost_of(const ob_bench_lights_row *rows, uint32_t count, uint32_t lights, bool tiles)
{
    for (uint32_t i = 0; i < count; i++)
        if (rows[i].lights == lights && rows[i].tiles == tiles) return rows[i].cost_ms.median;
    return NAN;
}

double ob_bench_lights_exponent(const ob_bench_lights_row *rows, uint32_t count, bool tiles)
{
    double a = cost_of(rows, count, 4, tiles), b = cost_of(rows, count, 256, tiles);
    return a > 0.0 && b > 0.0 ? log(b / a) / log(64.0) : NAN;
}
