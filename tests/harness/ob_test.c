#define _POSIX_C_SOURCE 200809L
#include "ob_test.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CAPTURE_MAX 4096

static pthread_mutex_t capture_lock = PTHREAD_MUTEX_INITIALIZER;
static char *captured[CAPTURE_MAX];
static ob_log_level captured_level[CAPTURE_MAX];
static uint32_t captured_count;
static atomic_bool echo_off;

static void capture_sink(void *user, ob_log_level level, const char *module,
                         const char *file, int line, const char *message)
{
    (void)user;
    char buf[1400];
    const char *base = strrchr(file, '/');
    snprintf(buf, sizeof buf, "[%s] %s (%s:%d)", module, message, base ? base + 1 : file, line);
    if ((level >= OB_LOG_WARN && !atomic_load(&echo_off)) || getenv("OB_LOG")) fprintf(stderr, "%s\n", buf);
    pthread_mutex_lock(&capture_lock);
    if (captured_count < CAPTURE_MAX) {
        size_t n = strlen(buf) + 1;
        char *copy = malloc(n); /* test-side bookkeeping: not an engine allocation */
        if (copy) {
            memcpy(copy, buf, n);
            captured_level[captured_count] = level;
            captured[captured_count++] = copy;
        }
    }
    pthread_mutex_unlock(&capture_lock);
}

static void free_captured(void)
{
    pthread_mutex_lock(&capture_lock);
    for (uint32_t i = 0; i < captured_count; i++) free(captured[i]);
    captured_count = 0;
    pthread_mutex_unlock(&capture_lock);
}

void ob_test_setup_log(void)
{
    static int installed;
    if (installed) return;
    installed = 1;
    ob_log_set_sink(capture_sink, NULL, NULL);
    atexit(free_captured);
}

void ob_test_log_clear(void) { free_captured(); }

void ob_test_log_set_echo(bool on) { atomic_store(&echo_off, !on); }

/* Whether one captured line contains needle and every string of ap. */
static bool log_has_v(const char *needle, va_list ap)
{
    bool found = false;
    pthread_mutex_lock(&capture_lock);
    for (uint32_t i = 0; i < captured_count && !found; i++) {
        va_list each;
        va_copy(each, ap);
        bool all = true;
        for (const char *n = needle; n; n = va_arg(each, const char *)) {
            if (!strstr(captured[i], n)) { all = false; break; }
        }
        va_end(each);
        found = all;
    }
    pthread_mutex_unlock(&capture_lock);
    return found;
}

bool ob_test_log_has(const char *needle, ...)
{
    va_list ap;
    va_start(ap, needle);
    bool found = log_has_v(needle, ap);
    va_end(ap);
    return found;
}

void ob_test_assert_logged(const char *file, int line, const char *needle, ...)
{
    va_list ap;
    va_start(ap, needle);
    bool found = log_has_v(needle, ap);
    va_end(ap);
    if (found) return;
    print_error("no captured log line contains all of:");
    va_start(ap, needle);
    for (const char *n = needle; n; n = va_arg(ap, const char *)) print_error(" \"%s\"", n);
    va_end(ap);
    print_error("\n");
    ob_test_log_dump(OB_LOG_DEBUG, 30);
    _fail(file, line);
}

int ob_test_errors_setup(void **state)
{
    (void)state;
    ob_test_log_set_echo(false);
    ob_test_log_clear();
    return 0;
}

int ob_test_errors_teardown(void **state)
{
    (void)state;
    for (int k = 0; k < OB_FAULT_KIND_COUNT; k++) ob_fault_arm((ob_fault_kind)k, 0);
    ob_test_log_set_echo(true);
    return 0;
}

uint32_t ob_test_log_count(ob_log_level min_level)
{
    uint32_t n = 0;
    pthread_mutex_lock(&capture_lock);
    for (uint32_t i = 0; i < captured_count; i++) n += captured_level[i] >= min_level;
    pthread_mutex_unlock(&capture_lock);
    return n;
}

void ob_test_log_dump(ob_log_level min_level, uint32_t max)
{
    uint32_t shown = 0;
    pthread_mutex_lock(&capture_lock);
    for (uint32_t i = 0; i < captured_count && shown < max; i++) {
        if (captured_level[i] < min_level) continue;
        fprintf(stderr, "    | %s\n", captured[i]);
        shown++;
    }
    pthread_mutex_unlock(&capture_lock);
}

uint32_t ob_test_image_max_diff(const uint8_t *a, const uint8_t *b, uint32_t w, uint32_t h)
{
    uint32_t m = 0;
    for (size_t i = 0; i < (size_t)w * h * 4; i++) {
        uint32_t d = a[i] > b[i] ? a[i] - b[i] : b[i] - a[i];
        if (d > m) m = d;
    }
    return m;
}

void ob_test_assert_near(double a, double b, double tol, const char *expr, const char *file,
                         int line)
{
    double d = a > b ? a - b : b - a;
    if (!(d <= tol)) {
        print_error("%s: %.17g vs %.17g differ by %.3g (tolerance %.3g)\n", expr, a, b, d, tol);
        _fail(file, line);
    }
}
