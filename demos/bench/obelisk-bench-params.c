/* obelisk-bench-params — cost of a typical per-draw parameter update.
 *
 * One update = set WorldMatrix (which derives WorldView, ViewProj,
 * WorldViewProj and NormalMatrix) + two vec4 + pack a 256-byte uniform block
 * into a ring. Measured on 1 thread and on N = 2, 4, 8 threads at once, each
 * in its own slot. Each configuration: one warm-up run, then the median of
 * repeated runs. Fixed data (no randomness), so runs are comparable.
 *
 * Usage: obelisk-bench-params [--iterations N] [--runs R] [--json FILE]
 */
#define _POSIX_C_SOURCE 200809L
#include "ob_core.h"
#include "ob_params.h"

#include <cglm/cglm.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAX_THREADS 8u
#define BLOCK_SIZE 256u
#define RING_BLOCKS 64u
#define DRAW_VARIETY 1024u   /* distinct worlds and colours cycled through */

static const uint32_t thread_counts[] = {1, 2, 4, 8};

typedef struct bench {
    ob_param_registry *reg;
    ob_param diffuse, specular;
    ob_param_mapping *map;
    float (*worlds)[16];     /* DRAW_VARIETY matrices, 32-byte aligned */
    float (*colors)[4];      /* 2 * DRAW_VARIETY */
    uint32_t iterations;
    pthread_barrier_t start;
} bench;

typedef struct runner {
    bench *b;
    pthread_t thread;
    uint32_t slot;
    uint64_t t0, t1;
    uint64_t failures;       /* calls that failed, or packs that did not happen */
} runner;

typedef struct result {
    uint32_t threads;
    double ns_thread;        /* median of (thread time / updates), averaged over threads */
    double ns_wall;          /* median of (wall time / all updates) */
} result;

static void *run_updates(void *arg)
{
    runner *r = arg;
    bench *b = r->b;
    const ob_param_builtins *bi = ob_param_registry_builtins(b->reg);
    ob_params pm;
    if (ob_params_manager(b->reg, r->slot, &pm) != OB_OK) {
        r->failures++;
        return NULL;
    }
    unsigned char *ring = ob_aligned_alloc(OB_CACHE_LINE, (size_t)RING_BLOCKS * BLOCK_SIZE);
    if (!ring) {
        r->failures++;
        return NULL;
    }
    pthread_barrier_wait(&b->start);
    r->t0 = ob_time_ns();
    for (uint32_t i = 0; i < b->iterations; i++) {
        /* Threads walk the draws from different starting points, like workers
         * recording different views. */
        uint32_t d = (i + r->slot * 97u) % DRAW_VARIETY;
        r->failures += ob_params_set_mat4(&pm, bi->world, b->worlds[d]) != OB_OK;
        r->failures += ob_params_set_vec4(&pm, b->diffuse, b->colors[2 * d]) != OB_OK;
        r->failures += ob_params_set_vec4(&pm, b->specular, b->colors[2 * d + 1]) != OB_OK;
        unsigned char *dst = ring + (size_t)(i % RING_BLOCKS) * BLOCK_SIZE;
        r->failures += !ob_params_pack(&pm, b->map, dst, false);
    }
    r->t1 = ob_time_ns();
    ob_aligned_free(ring);
    return NULL;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, uint32_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* One run of `threads` concurrent runners; false if anything failed. */
static bool run_once(bench *b, uint32_t threads, double *out_ns_thread, double *out_ns_wall)
{
    runner runners[MAX_THREADS];
    if (pthread_barrier_init(&b->start, NULL, threads) != 0) return false;
    uint32_t started = 0;
    for (; started < threads; started++) {
        runners[started] = (runner){.b = b, .slot = started + 1};
        if (pthread_create(&runners[started].thread, NULL, run_updates, &runners[started]) != 0)
            break;
    }
    /* A thread that failed to start would leave the others at the barrier. */
    if (started < threads) {
        fprintf(stderr, "cannot start thread %u\n", started);
        exit(1);
    }
    for (uint32_t t = 0; t < threads; t++) pthread_join(runners[t].thread, NULL);
    pthread_barrier_destroy(&b->start);

    uint64_t first = UINT64_MAX, last = 0, failures = 0;
    double sum = 0;
    for (uint32_t t = 0; t < threads; t++) {
        failures += runners[t].failures;
        first = OB_MIN(first, runners[t].t0);
        last = OB_MAX(last, runners[t].t1);
        sum += (double)(runners[t].t1 - runners[t].t0) / b->iterations;
    }
    if (failures) {
        fprintf(stderr, "%llu failed updates with %u threads\n", (unsigned long long)failures,
                threads);
        return false;
    }
    *out_ns_thread = sum / threads;
    *out_ns_wall = (double)(last - first) / ((double)b->iterations * threads);
    return true;
}

static ob_block_member member(const char *name, ob_member_type type, uint32_t offset,
                              uint32_t size)
{
    ob_block_member m = {.type = type, .offset = offset, .size = size};
    snprintf(m.name, sizeof m.name, "%s", name);
    return m;
}

static bool bench_setup(bench *b)
{
    ob_result r;
    b->reg = ob_param_registry_create(&(ob_param_registry_desc){1 + MAX_THREADS}, &r);
    if (!b->reg) return false;
    b->diffuse = ob_param_register(b->reg, "DiffuseColor", OB_PARAM_VEC4, 1, &r);
    if (r != OB_OK) return false;
    b->specular = ob_param_register(b->reg, "SpecularColor", OB_PARAM_VEC4, 1, &r);
    if (r != OB_OK) return false;

    const ob_param_builtins *bi = ob_param_registry_builtins(b->reg);
    mat4 view, proj;
    glm_lookat((vec3){0, 5, 20}, (vec3){0, 0, 0}, (vec3){0, 1, 0}, view);
    glm_perspective(glm_rad(60.0f), 16.0f / 9.0f, 0.1f, 500.0f, proj);
    if (ob_params_init_mat4(b->reg, bi->view, &view[0][0]) != OB_OK ||
        ob_params_init_mat4(b->reg, bi->proj, &proj[0][0]) != OB_OK)
        return false;

    /* A std140 per-draw block as a lit shader would declare it. */
    ob_block_member members[] = {
        member("WorldMatrix", OB_MEMBER_MAT4, 0, 64),
        member("WorldViewProjMatrix", OB_MEMBER_MAT4, 64, 64),
        member("NormalMatrix", OB_MEMBER_MAT4, 128, 64),
        member("DiffuseColor", OB_MEMBER_VEC4, 192, 16),
        member("SpecularColor", OB_MEMBER_VEC4, 208, 16),
    };
    ob_block_layout layout = {.name = "PerDraw", .size = BLOCK_SIZE,
                              .member_count = OB_ARRAY_COUNT(members), .members = members};
    b->map = ob_param_mapping_create(b->reg, &layout, "bench.vert", &r);
    if (!b->map) return false;

    b->worlds = ob_aligned_alloc(32, sizeof(float[16]) * DRAW_VARIETY);
    b->colors = ob_aligned_alloc(32, sizeof(float[4]) * 2 * DRAW_VARIETY);
    if (!b->worlds || !b->colors) return false;
    for (uint32_t d = 0; d < DRAW_VARIETY; d++) {
        mat4 w;
        float a = (float)d * 0.013f;
        glm_euler_xyz((vec3){a, 2.0f * a, 0.5f * a}, w);
        glm_scale_uni(w, 0.5f + (float)(d % 7) * 0.1f);
        w[3][0] = (float)(d % 32) - 16.0f;
        w[3][2] = (float)(d / 32) - 16.0f;
        memcpy(b->worlds[d], w, 64);
        for (uint32_t k = 0; k < 4; k++) {
            b->colors[2 * d][k] = (float)((d * 7 + k * 3) % 256) / 255.0f;
            b->colors[2 * d + 1][k] = (float)((d * 11 + k * 5) % 256) / 255.0f;
        }
    }
    return true;
}

static void bench_teardown(bench *b)
{
    ob_aligned_free(b->worlds);
    ob_aligned_free(b->colors);
    ob_param_mapping_destroy(b->map);
    ob_param_registry_destroy(b->reg);
}

static ob_result write_json(const char *path, const bench *b, uint32_t runs, long cores,
                            const result *res, uint32_t n)
{
    char buf[4096];
    size_t len = 0;
    len += (size_t)snprintf(buf + len, sizeof buf - len,
                            "{\n  \"benchmark\": \"params\",\n"
                            "  \"update\": \"set WorldMatrix + 2 vec4 + pack %u-byte block\",\n"
                            "  \"iterations_per_thread\": %u,\n  \"runs\": %u,\n"
                            "  \"cores\": %ld,\n  \"results\": [\n",
                            BLOCK_SIZE, b->iterations, runs, cores);
    for (uint32_t i = 0; i < n && len < sizeof buf; i++) {
        len += (size_t)snprintf(buf + len, sizeof buf - len,
                                "    {\"threads\": %u, \"ns_per_update_thread\": %.2f, "
                                "\"ns_per_update_wall\": %.2f, \"updates_per_second\": %.0f, "
                                "\"throughput_vs_1_thread\": %.3f}%s\n",
                                res[i].threads, res[i].ns_thread, res[i].ns_wall,
                                1e9 / res[i].ns_wall, res[0].ns_wall / res[i].ns_wall,
                                i + 1 < n ? "," : "");
    }
    if (len < sizeof buf) len += (size_t)snprintf(buf + len, sizeof buf - len, "  ]\n}\n");
    if (len >= sizeof buf) return OB_ERR_LIMIT;
    return ob_file_write(path, buf, len);
}

static void usage(const char *argv0)
{
    fprintf(stderr, "usage: %s [--iterations N] [--runs R] [--json FILE]\n"
                    "  --iterations N  updates per thread per run (default 200000)\n"
                    "  --runs R        measured runs after the warm-up; median reported "
                    "(default 7)\n"
                    "  --json FILE     also write the results as JSON\n", argv0);
}

int main(int argc, char **argv)
{
    uint32_t iterations = 200000, runs = 7;
    const char *json = NULL;
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        if (strcmp(argv[i], "--iterations") == 0 && val) {
            unsigned long v = strtoul(val, &end, 10);
            if (*end || v == 0 || v > 100000000ul) { usage(argv[0]); return 2; }
            iterations = (uint32_t)v;
            i++;
        } else if (strcmp(argv[i], "--runs") == 0 && val) {
            unsigned long v = strtoul(val, &end, 10);
            if (*end || v == 0 || v > 1000ul) { usage(argv[0]); return 2; }
            runs = (uint32_t)v;
            i++;
        } else if (strcmp(argv[i], "--json") == 0 && val) {
            json = val;
            i++;
        } else {
            usage(argv[0]);
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }

    bench b = {.iterations = iterations};
    if (!bench_setup(&b)) {
        fprintf(stderr, "setup failed (see the log above)\n");
        bench_teardown(&b);
        return 1;
    }
    double *thread_ns = ob_calloc(runs, sizeof *thread_ns);
    double *wall_ns = ob_calloc(runs, sizeof *wall_ns);
    if (!thread_ns || !wall_ns) {
        ob_free(thread_ns);
        ob_free(wall_ns);
        bench_teardown(&b);
        return 1;
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    result res[OB_ARRAY_COUNT(thread_counts)];
    int status = 0;
    printf("per-draw parameter update: set WorldMatrix + 2 vec4 + pack %u-byte block\n"
           "%u updates per thread per run, median of %u runs after a warm-up, %ld cores\n\n",
           BLOCK_SIZE, iterations, runs, cores);
    printf("threads  ns/update/thread  ns/update (wall)  updates/s    throughput vs 1\n");
    for (uint32_t c = 0; c < OB_ARRAY_COUNT(thread_counts) && !status; c++) {
        uint32_t n = thread_counts[c];
        double warm_thread, warm_wall;
        if (!run_once(&b, n, &warm_thread, &warm_wall)) { status = 1; break; }
        for (uint32_t r = 0; r < runs && !status; r++)
            if (!run_once(&b, n, &thread_ns[r], &wall_ns[r])) status = 1;
        if (status) break;
        res[c] = (result){n, median(thread_ns, runs), median(wall_ns, runs)};
        printf("%7u  %16.1f  %16.1f  %10.0f  %14.2fx\n", n, res[c].ns_thread, res[c].ns_wall,
               1e9 / res[c].ns_wall, res[0].ns_wall / res[c].ns_wall);
    }
    if (!status && json) {
        ob_result r = write_json(json, &b, runs, cores, res, OB_ARRAY_COUNT(thread_counts));
        if (r != OB_OK) {
            fprintf(stderr, "cannot write %s: %s\n", json, ob_result_text(r));
            status = 1;
        }
    }
    ob_free(thread_ns);
    ob_free(wall_ns);
    bench_teardown(&b);
    return status;
}
