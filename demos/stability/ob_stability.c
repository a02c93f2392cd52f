#define _POSIX_C_SOURCE 200809L
#include "ob_stab_world.h"

#include <stdlib.h>
#include <stdio.h>
#include <string.h>

/* ------------------------------------------------------------ log sink */

/* What the default sink does (it cannot be called once replaced). */
static void print_default(ob_log_level level, const char *module, const char *file, int line,
                          const char *message)
{
    static const char *const names[] = {"debug", "info", "warn", "error"};
    ob_log_level threshold = OB_LOG_WARN;
    const char *env = getenv("OB_LOG");
    if (env && strcmp(env, "debug") == 0) threshold = OB_LOG_DEBUG;
    else if (env && strcmp(env, "info") == 0) threshold = OB_LOG_INFO;
    if (level < threshold || (unsigned)level > OB_LOG_ERROR) return;
    const char *base = strrchr(file, '/');
    fprintf(stderr, "[%s][%s] %s (%s:%d)\n", names[level], module, message, base ? base + 1 : file,
            line);
}

/* Lines a case provokes on purpose are kept for its checks and counted;
 * the validation layer's and every other line go on as before. */
static void capture_sink(void *user, ob_log_level level, const char *module, const char *file,
                         int line, const char *message)
{
    ob_stab_log *l = user;
    bool expected = false;
    if (strcmp(module, "vk-validation") != 0) {
        pthread_mutex_lock(&l->lock);
        for (uint32_t i = 0; i < l->needle_count && !expected; i++)
            expected = strstr(message, l->needles[i]) != NULL;
        if (expected) {
            if (l->line_count < OB_STAB_LOG_LINES)
                snprintf(l->lines[l->line_count++], sizeof l->lines[0], "%s", message);
            if ((unsigned)level <= OB_LOG_ERROR) l->expected[level]++;
        }
        pthread_mutex_unlock(&l->lock);
    }
    if (expected) return;
    if (l->prev) l->prev(l->prev_user, level, module, file, line, message);
    else print_default(level, module, file, line, message);
}

/* ------------------------------------------------------------ cases */

static ob_result deep_10k(ob_stab_ctx *c) { return ob_stab_deep_hierarchy(c, 10000); }
static ob_result deep_100k(ob_stab_ctx *c) { return ob_stab_deep_hierarchy(c, 100000); }

static const struct {
    const char *label;
    ob_result (*run)(ob_stab_ctx *c);
} cases[] = {
    {"depth precision", ob_stab_depth_precision},
    {"large coordinates", ob_stab_large_coordinates},
    {"large coordinates, scene graph", ob_stab_scene_matrices},
    {"scale invariance", ob_stab_scale_invariance},
    {"10,000-level hierarchy", deep_10k},
    {"100,000-level hierarchy", deep_100k},
    {"long-run rotation", ob_stab_long_run_rotation},
    {"zero scale", ob_stab_zero_scale},
    {"flattened box", ob_stab_flattened_box},
    {"up parallel to direction", ob_stab_up_parallel},
    {"refused views and cameras", ob_stab_refused_views},
    {"empty scene", ob_stab_empty_scene},
    {"light at intensity 0", ob_stab_light_off},
    {"non-finite transforms", ob_stab_non_finite_transform},
    {"non-finite light and camera", ob_stab_non_finite_light_camera},
    {"non-finite material", ob_stab_non_finite_material},
    {"non-finite parameter", ob_stab_non_finite_parameter},
    {"entity beyond float range", ob_stab_beyond_float},
    {"64 views", ob_stab_views_64},
    {"128-view cap", ob_stab_view_cap},
    {"env-map recursion 0..4", ob_stab_env_recursion},
    {"many objects", ob_stab_many_objects},
    {"shadow map without casters", ob_stab_no_casters},
};

uint32_t ob_stability_case_count(void) { return OB_ARRAY_COUNT(cases); }

const char *ob_stability_verdict_name(ob_stability_verdict v)
{
    switch (v) {
    case OB_STABILITY_PASS: return "pass";
    case OB_STABILITY_MEASURED: return "measured";
    case OB_STABILITY_FAIL: break;
    }
    return "fail";
}

ob_result ob_stability_run(const ob_stability_desc *desc, ob_stability *out)
{
    memset(out, 0, sizeof *out);
    out->quick = desc->quick;
    ob_stab_ctx *c = ob_calloc(1, sizeof *c);
    if (!c) {
        OB_LOG_E("bench", "stability: no memory for the run");
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    c->out = out;
    c->quick = desc->quick;
    c->workers = desc->workers ? desc->workers : 4;
    out->workers = c->workers;
    if (pthread_mutex_init(&c->log.lock, NULL) != 0) {
        ob_free(c);
        OB_LOG_E("bench", "stability: cannot create the log lock");
        return OB_ERR_UNSUPPORTED;
    }
    c->log.prev = ob_log_set_sink(capture_sink, &c->log, &c->log.prev_user);
    uint64_t t0 = ob_time_ns();
    ob_result r = OB_OK;
    for (size_t i = 0; i < OB_ARRAY_COUNT(cases) && r == OB_OK; i++) {
        if (desc->only && strcmp(desc->only, cases[i].label) != 0) continue;
        if (desc->on_case) desc->on_case(desc->on_case_user, cases[i].label, false);
        r = cases[i].run(c);
        out->cases++;
        if (desc->on_case) desc->on_case(desc->on_case_user, cases[i].label, true);
    }
    if (desc->only && out->cases == 0) {
        OB_LOG_E("bench", "stability: no case is called '%s'", desc->only);
        r = OB_ERR_INVALID_ARGUMENT;
    }
    if (r == OB_OK && out->validation)
        r = ob_stab_add(c, "validation_layer", "validation-layer errors and warnings over every "
                                               "renderer of this section",
                        out->validation_messages, "messages", 0, true, NAN,
                        "VK_LAYER_KHRONOS_validation with synchronization validation");
    ob_log_set_sink(c->log.prev, c->log.prev_user, NULL);
    out->expected_errors = c->log.expected[OB_LOG_ERROR];
    out->expected_warnings = c->log.expected[OB_LOG_WARN];
    out->seconds = (double)(ob_time_ns() - t0) * 1e-9;
    pthread_mutex_destroy(&c->log.lock);
    ob_free(c);
    return r;
}

void ob_stability_release(ob_stability *s)
{
    ob_free(s->rows);
    s->rows = NULL;
    s->count = s->cap = 0;
}
