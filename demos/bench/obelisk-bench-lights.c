/* obelisk-bench-lights — what the screen-tile light grid saves (docs/
 * architecture.md, "Many lights").
 *
 * A wall facing the camera with 120 boxes in front of it and N point lights
 * of range 2.5 on a grid 0.6 in front of the wall, rendered single-threaded
 * at 640 x 480 with the grid on and off (ob_views_set_light_tiles: off,
 * every fragment evaluates every light, which is what per-object light
 * lists would give the wall, since every light reaches it). The cost of a
 * frame is the process's CPU time (user + system) while it renders and is
 * waited for: on lavapipe that is the execution's work and, unlike wall
 * time, it does not move with other load on these shared cores; run it
 * with LP_NUM_THREADS=1 to keep lavapipe's thread handoffs out of it.
 *
 * Rounds are interleaved (on, off, on, off ...) after a warm-up; the output
 * is CSV on stdout: lights, tiles, median ms, p25, p75, and the ratio
 * off/on of the medians. Fixed scene, no randomness.
 *
 * usage: obelisk-bench-lights [--frames N] (default 15 a round, 3 rounds) */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "ob_world.h"

#define ROUNDS 3
#define MAX_FRAMES 200

static double cpu_ms(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
           (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e3;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The scene with `lights` point lights; false (logged by the engine) when a
 * step failed. */
static bool build(ob_world *w, int lights)
{
    ob_world_desc d = ob_world_desc_small("obelisk-bench-lights");
    d.stack.width = 640;
    d.stack.height = 480;
    if (ob_world_create(w, &d) != OB_OK) return false;
    ob_world_look(w, 0, 0, 8, 0, 0, 0);
    ob_material *m = ob_world_material(w, "wall", OB_MATERIAL_LIT, 0.8f, 0.8f, 0.8f, false);
    ob_node *wall = ob_world_entity(w, NULL, "wall", w->plane, m, 0, 0, 0);
    if (wall) ob_node_set_rotation_d(wall, (const double[4]){sqrt(0.5), 0, 0, sqrt(0.5)});
    for (int i = 0; i < 120; i++)
        ob_world_entity(w, NULL, "box", w->box, m, -5.5 + 1.0 * (i % 12), -4 + 0.8 * (i / 12), 0.4);
    int g = (int)ceil(sqrt((double)lights));
    for (int i = 0; i < lights && w->err == OB_OK; i++) {
        ob_result r;
        ob_node *n = ob_node_create(w->scene, NULL, "lamp", &r);
        if (!n) return false;
        ob_light_desc ld = {.type = OB_LIGHT_POINT, .intensity = 0.5f, .range = 2.5f};
        if (ob_node_set_light(n, &ld) != OB_OK) return false;
        ob_node_set_position(n, (const double[3]){-6.0 + 12.0 * (i % g) / g, -4.5 + 9.0 * (i / g) / g, 0.6});
    }
    return w->err == OB_OK;
}

int main(int argc, char **argv)
{
    int frames = 15;
    if (argc == 3 && strcmp(argv[1], "--frames") == 0) frames = atoi(argv[2]);
    if (frames < 1 || frames > MAX_FRAMES || (argc != 1 && argc != 3)) {
        fprintf(stderr, "usage: %s [--frames N (1 to %d)]\n", argv[0], MAX_FRAMES);
        return 2;
    }
    static const int counts[] = {0, 4, 64, 256};
    printf("lights,tiles,median_ms,p25_ms,p75_ms,off_over_on\n");
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
        ob_world w;
        if (!build(&w, counts[c])) {
            fprintf(stderr, "obelisk-bench-lights: scene of %d lights failed: %s\n", counts[c],
                    ob_result_name(w.err));
            ob_world_destroy(&w);
            return 1;
        }
        double ms[2][ROUNDS * MAX_FRAMES];
        int n[2] = {0, 0};
        for (int warm = 0; warm < 3; warm++) ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0);
        for (int round = 0; round < 2 * ROUNDS; round++) {
            int tiles = round % 2 == 0;
            ob_views_set_light_tiles(w.views, tiles);
            ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0);   /* the switch's first frame */
            for (int f = 0; f < frames; f++) {
                double t0 = cpu_ms();
                if (ob_world_frame(&w, OB_THREADING_SINGLE, 0, NULL, 0) != OB_OK) {
                    fprintf(stderr, "obelisk-bench-lights: a frame failed\n");
                    ob_world_destroy(&w);
                    return 1;
                }
                ms[tiles][n[tiles]++] = cpu_ms() - t0;
            }
        }
        double median[2];
        for (int t = 1; t >= 0; t--) {
            qsort(ms[t], (size_t)n[t], sizeof ms[t][0], compare_doubles);
            median[t] = ms[t][n[t] / 2];
            printf("%d,%s,%.2f,%.2f,%.2f,", counts[c], t ? "on" : "off", median[t], ms[t][n[t] / 4],
                   ms[t][3 * n[t] / 4]);
            if (t) printf("\n");
        }
        printf("%.2f\n", median[1] > 0 ? median[0] / median[1] : 0.0);
        ob_world_destroy(&w);
    }
    return 0;
}
