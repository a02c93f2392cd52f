#define _XOPEN_SOURCE 700
#include "ob_core.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

/* ---------------------------------------------------------------- results */

static const char *const result_names[] = {
#define OB_RESULT_NAME(name, text) #name,
    OB_RESULT_LIST(OB_RESULT_NAME)
#undef OB_RESULT_NAME
};
static const char *const result_texts[] = {
#define OB_RESULT_TEXT(name, text) text,
    OB_RESULT_LIST(OB_RESULT_TEXT)
#undef OB_RESULT_TEXT
};

const char *ob_result_name(ob_result r)
{
    return (unsigned)r < OB_RESULT_COUNT ? result_names[r] : "OB_RESULT_UNKNOWN";
}

const char *ob_result_text(ob_result r)
{
    return (unsigned)r < OB_RESULT_COUNT ? result_texts[r] : "unknown result";
}

/* ------------------------------------------------------ process-wide state */

/* One lock for every set-up: they run once per process, so contention is
 * nil, and one lock cannot be taken in two orders. */
static pthread_mutex_t once_lock = PTHREAD_MUTEX_INITIALIZER;
static ob_once *once_ran;   /* newest first; guarded by once_lock */

ob_result ob_once_run(ob_once *once)
{
    if (__atomic_load_n(&once->state, __ATOMIC_ACQUIRE)) return once->result;
    pthread_mutex_lock(&once_lock);
    if (!once->state) {
        once->result = once->init ? once->init() : OB_OK;
        if (once->result != OB_OK)
            OB_LOG_E("core", "one-time set-up '%s' failed: %s; what needs it fails too", once->name,
                     ob_result_name(once->result));
        once->next = once_ran;
        once_ran = once;
        __atomic_store_n(&once->state, 1, __ATOMIC_RELEASE);
    }
    pthread_mutex_unlock(&once_lock);
    return once->result;
}

uint32_t ob_once_list(const char **names, uint32_t cap)
{
    pthread_mutex_lock(&once_lock);
    uint32_t n = 0;
    for (const ob_once *o = once_ran; o; o = o->next) n++;
    uint32_t i = n;
    for (const ob_once *o = once_ran; o; o = o->next) {
        i--;
        if (i < cap) names[i] = o->name;
    }
    pthread_mutex_unlock(&once_lock);
    return n;
}

/* ---------------------------------------------------------------- logging */

static _Atomic(ob_log_fn) log_sink;
static _Atomic(void *) log_user;
static atomic_uint_fast64_t log_counts[4];

static void default_sink(void *user, ob_log_level level, const char *module,
                         const char *file, int line, const char *message)
{
    static const char *const names[] = {"debug", "info", "warn", "error"};
    (void)user;
    ob_log_level threshold = OB_LOG_WARN;
    const char *env = getenv("OB_LOG");
    if (env && strcmp(env, "debug") == 0) threshold = OB_LOG_DEBUG;
    else if (env && strcmp(env, "info") == 0) threshold = OB_LOG_INFO;
    if (level < threshold) return;
    const char *base = strrchr(file, '/');
    fprintf(stderr, "[%s][%s] %s (%s:%d)\n", names[level], module, message,
            base ? base + 1 : file, line);
}

ob_log_fn ob_log_set_sink(ob_log_fn fn, void *user, void **out_prev_user)
{
    ob_log_fn prev = atomic_exchange(&log_sink, fn);
    void *prev_user = atomic_exchange(&log_user, user);
    if (out_prev_user) *out_prev_user = prev_user;
    return prev;
}

uint64_t ob_log_count(ob_log_level level)
{
    return (unsigned)level < 4 ? atomic_load(&log_counts[level]) : 0;
}

void ob_log_writev(ob_log_level level, const char *module, const char *file,
                   int line, const char *fmt, va_list ap)
{
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if ((unsigned)level < 4) atomic_fetch_add(&log_counts[level], 1);
    ob_log_fn fn = atomic_load(&log_sink);
    if (!fn) fn = default_sink;
    fn(atomic_load(&log_user), level, module, file, line, msg);
}

void ob_log_write(ob_log_level level, const char *module, const char *file,
                  int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    ob_log_writev(level, module, file, line, fmt, ap);
    va_end(ap);
}

/* ---------------------------------------------------------- fault injection */

static atomic_uint_fast64_t fault_nth[OB_FAULT_KIND_COUNT];
static atomic_uint_fast64_t fault_calls[OB_FAULT_KIND_COUNT];
static atomic_bool fault_fired[OB_FAULT_KIND_COUNT];

void ob_fault_arm(ob_fault_kind kind, uint64_t nth)
{
    atomic_store(&fault_calls[kind], 0);
    atomic_store(&fault_fired[kind], false);
    atomic_store(&fault_nth[kind], nth);
}

bool ob_fault_hit(ob_fault_kind kind) { return atomic_load(&fault_fired[kind]); }

uint64_t ob_fault_count(ob_fault_kind kind) { return atomic_load(&fault_calls[kind]); }

bool ob_fault_should_fail(ob_fault_kind kind)
{
    uint64_t n = atomic_fetch_add(&fault_calls[kind], 1) + 1;
    uint64_t nth = atomic_load(&fault_nth[kind]);
    if (nth != 0 && n == nth) {
        atomic_store(&fault_fired[kind], true);
        return true;
    }
    return false;
}

/* ------------------------------------------------------------- allocation */

/* What Obelisk holds on the C heap, so that a long run can tell its own
 * memory from the driver's and the allocator's (ob_heap_stats_now). Block
 * sizes come from the allocator (malloc_usable_size), so nothing is stored
 * next to a block; without glibc only blocks are counted. */
static atomic_llong heap_live_bytes, heap_live_blocks;

static size_t block_size(void *p)
{
#if defined(__GLIBC__)
    return malloc_usable_size(p);
#else
    (void)p;
    return 0;
#endif
}

static void *counted(void *p)
{
    if (p) {
        atomic_fetch_add_explicit(&heap_live_bytes, (long long)block_size(p), memory_order_relaxed);
        atomic_fetch_add_explicit(&heap_live_blocks, 1, memory_order_relaxed);
    }
    return p;
}

ob_heap_stats ob_heap_stats_now(void)
{
    long long bytes = atomic_load_explicit(&heap_live_bytes, memory_order_relaxed);
    long long blocks = atomic_load_explicit(&heap_live_blocks, memory_order_relaxed);
#if defined(__GLIBC__)
    bool sized = true;
#else
    bool sized = false;
#endif
    return (ob_heap_stats){bytes > 0 ? (uint64_t)bytes : 0, blocks > 0 ? (uint64_t)blocks : 0, sized};
}

void *ob_malloc(size_t size)
{
    if (ob_fault_should_fail(OB_FAULT_HOST_ALLOC)) return NULL;
    return counted(malloc(size ? size : 1));
}

void *ob_calloc(size_t count, size_t size)
{
    if (ob_fault_should_fail(OB_FAULT_HOST_ALLOC)) return NULL;
    return counted(calloc(count ? count : 1, size ? size : 1));
}

void *ob_realloc(void *ptr, size_t size)
{
    if (ob_fault_should_fail(OB_FAULT_HOST_ALLOC)) return NULL;
    if (!ptr) return counted(malloc(size ? size : 1));
    size_t before = block_size(ptr);
    void *q = realloc(ptr, size ? size : 1);
    if (q)
        atomic_fetch_add_explicit(&heap_live_bytes, (long long)block_size(q) - (long long)before,
                                  memory_order_relaxed);
    return q;
}

void ob_free(void *ptr)
{
    if (!ptr) return;
    atomic_fetch_sub_explicit(&heap_live_bytes, (long long)block_size(ptr), memory_order_relaxed);
    atomic_fetch_sub_explicit(&heap_live_blocks, 1, memory_order_relaxed);
    free(ptr);
}

void *ob_aligned_alloc(size_t alignment, size_t size)
{
    if (ob_fault_should_fail(OB_FAULT_HOST_ALLOC)) return NULL;
    void *p = NULL;
    if (alignment < sizeof(void *)) alignment = sizeof(void *);
    if (posix_memalign(&p, alignment, size ? size : 1) != 0) return NULL;
    return counted(p);
}

void ob_aligned_free(void *ptr) { ob_free(ptr); }

char *ob_strdup(const char *s)
{
    if (!s) return NULL;
    size_t n = strlen(s) + 1;
    char *d = ob_malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

ob_result ob_array_reserve(void **items, uint32_t *cap, uint32_t need, size_t elem_size)
{
    if (need <= *cap) return OB_OK;
    uint32_t new_cap = *cap ? *cap : 8;
    while (new_cap < need) {
        if (new_cap > UINT32_MAX / 2) return OB_ERR_LIMIT;
        new_cap *= 2;
    }
    void *p = ob_realloc(*items, (size_t)new_cap * elem_size);
    if (!p) return OB_ERR_OUT_OF_HOST_MEMORY;
    *items = p;
    *cap = new_cap;
    return OB_OK;
}

ob_result ob_array_reserve_aligned(void **items, uint32_t *cap, uint32_t need, size_t elem_size,
                                   size_t alignment)
{
    if (need <= *cap) return OB_OK;
    uint32_t new_cap = *cap ? *cap : 8;
    while (new_cap < need) {
        if (new_cap > UINT32_MAX / 2) return OB_ERR_LIMIT;
        new_cap *= 2;
    }
    void *p = ob_aligned_alloc(alignment, (size_t)new_cap * elem_size);
    if (!p) return OB_ERR_OUT_OF_HOST_MEMORY;
    if (*items) memcpy(p, *items, (size_t)*cap * elem_size);
    ob_aligned_free(*items);
    *items = p;
    *cap = new_cap;
    return OB_OK;
}

/* ---------------------------------------------------------------- handles */

#define GEN_SHIFT OB_HANDLE_INDEX_BITS
#define GEN_MASK 0xfffu

void ob_pool_init(ob_pool *pool) { memset(pool, 0, sizeof *pool); }

void ob_pool_release(ob_pool *pool)
{
    ob_free(pool->gen);
    ob_free(pool->next_free);
    ob_free(pool->items);
    memset(pool, 0, sizeof *pool);
}

uint32_t ob_pool_insert(ob_pool *pool, void *item, ob_result *out_result)
{
    if (out_result) *out_result = OB_OK;
    if (!pool->free_head) {
        if (pool->cap >= OB_HANDLE_MAX_SLOTS) {
            if (out_result) *out_result = OB_ERR_LIMIT;
            return 0;
        }
        uint32_t new_cap = pool->cap ? pool->cap * 2 : 16;
        if (new_cap > OB_HANDLE_MAX_SLOTS) new_cap = OB_HANDLE_MAX_SLOTS;
        uint32_t *gen = ob_realloc(pool->gen, new_cap * sizeof *gen);
        if (gen) pool->gen = gen;
        uint32_t *nf = gen ? ob_realloc(pool->next_free, new_cap * sizeof *nf) : NULL;
        if (nf) pool->next_free = nf;
        void **items = nf ? ob_realloc(pool->items, new_cap * sizeof *items) : NULL;
        if (!items) {
            if (out_result) *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
            return 0;
        }
        pool->items = items;
        for (uint32_t i = new_cap; i > pool->cap; i--) {
            pool->gen[i - 1] = 1;
            pool->items[i - 1] = NULL;
            pool->next_free[i - 1] = pool->free_head;
            pool->free_head = i;
        }
        pool->cap = new_cap;
    }
    uint32_t slot = pool->free_head; /* 1-based */
    pool->free_head = pool->next_free[slot - 1];
    pool->items[slot - 1] = item;
    pool->count++;
    return (pool->gen[slot - 1] << GEN_SHIFT) | slot;
}

static uint32_t pool_slot(const ob_pool *pool, uint32_t id)
{
    uint32_t slot = id & OB_HANDLE_INDEX_MASK;
    if (id == 0 || slot == 0 || slot > pool->cap) return 0;
    if (pool->gen[slot - 1] != (id >> GEN_SHIFT) || !pool->items[slot - 1]) return 0;
    return slot;
}

void *ob_pool_get(const ob_pool *pool, uint32_t id)
{
    uint32_t slot = pool_slot(pool, id);
    return slot ? pool->items[slot - 1] : NULL;
}

void *ob_pool_remove(ob_pool *pool, uint32_t id)
{
    uint32_t slot = pool_slot(pool, id);
    if (!slot) return NULL;
    void *item = pool->items[slot - 1];
    pool->items[slot - 1] = NULL;
    uint32_t g = (pool->gen[slot - 1] + 1) & GEN_MASK;
    pool->gen[slot - 1] = g ? g : 1;
    pool->next_free[slot - 1] = pool->free_head;
    pool->free_head = slot;
    pool->count--;
    return item;
}

void *ob_pool_next(const ob_pool *pool, uint32_t *cursor, uint32_t *out_id)
{
    while (*cursor < pool->cap) {
        uint32_t i = (*cursor)++;
        if (pool->items[i]) {
            if (out_id) *out_id = (pool->gen[i] << GEN_SHIFT) | (i + 1);
            return pool->items[i];
        }
    }
    return NULL;
}

/* ----------------------------------------------------------- hash & time */

uint64_t ob_hash_bytes(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

static inline uint64_t hash_lane(uint64_t acc, uint64_t w)
{
    acc += w * 0xc2b2ae3d27d4eb4full;
    acc = (acc << 31) | (acc >> 33);
    return acc * 0x9e3779b97f4a7c15ull;
}

uint64_t ob_hash_block(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    /* The size goes into the lanes' start: no extra step at the end. */
    uint64_t lane[4] = {h ^ size, h ^ 0x60bee2bee120fc15ull, h + 0x94d049bb133111ebull,
                        h - 0x6a09e667f3bcc909ull};
    size_t i = 0;
    for (; i + 32 <= size; i += 32) {
        uint64_t w[4];
        memcpy(w, p + i, 32);
        for (int k = 0; k < 4; k++) lane[k] = hash_lane(lane[k], w[k]);
    }
    if (size >= 32) {
        /* The lanes rotated apart and summed (as xxHash folds them). */
        uint64_t sum = 0;
        static const int rot[4] = {1, 7, 12, 18};
        for (int k = 0; k < 4; k++) sum += (lane[k] << rot[k]) | (lane[k] >> (64 - rot[k]));
        h = ob_hash_u64(h, sum);
    }
    for (; i + 8 <= size; i += 8) {
        uint64_t w;
        memcpy(&w, p + i, 8);
        h = ob_hash_u64(h, w);
    }
    if (i < size) {
        uint64_t w = 0;
        memcpy(&w, p + i, size - i);
        h = ob_hash_u64(h, w);
    }
    return size < 32 ? ob_hash_u64(h, size) : h;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double ob_median(double *v, uint32_t n)
{
    uint32_t k = 0;
    for (uint32_t i = 0; i < n; i++)
        if (!isnan(v[i])) v[k++] = v[i];
    if (!k) return NAN;
    qsort(v, k, sizeof *v, compare_double);
    return k % 2 ? v[k / 2] : 0.5 * (v[k / 2 - 1] + v[k / 2]);
}

/* Optimal string alignment over two rows plus the one before (for swaps),
 * on the stack: names are short, and a message about a typo should not
 * fail for want of memory. */
#define OB_EDIT_MAX 63
static int fold_ascii(int c) { return c >= 'A' && c <= 'Z' ? c + ('a' - 'A') : c; }

uint32_t ob_edit_distance(const char *a, const char *b)
{
    size_t n = strnlen(a, OB_EDIT_MAX), m = strnlen(b, OB_EDIT_MAX);
    uint32_t rows[3][OB_EDIT_MAX + 1];
    uint32_t *before = rows[0], *prev = rows[1], *cur = rows[2];
    for (size_t j = 0; j <= m; j++) prev[j] = (uint32_t)j;
    for (size_t i = 1; i <= n; i++) {
        cur[0] = (uint32_t)i;
        for (size_t j = 1; j <= m; j++) {
            int ca = fold_ascii((unsigned char)a[i - 1]), cb = fold_ascii((unsigned char)b[j - 1]);
            uint32_t best = prev[j - 1] + (ca != cb);
            if (prev[j] + 1 < best) best = prev[j] + 1;
            if (cur[j - 1] + 1 < best) best = cur[j - 1] + 1;
            if (i > 1 && j > 1 && ca == fold_ascii((unsigned char)b[j - 2]) &&
                fold_ascii((unsigned char)a[i - 2]) == cb && before[j - 2] + 1 < best)
                best = before[j - 2] + 1;
            cur[j] = best;
        }
        uint32_t *t = before;
        before = prev;
        prev = cur;
        cur = t;
    }
    return prev[m];
}

int ob_env_choice(const char *name, const char *const *words, uint32_t count, const char *module,
                  const char *otherwise)
{
    const char *env = getenv(name);
    if (!env || !*env) return -1;
    char list[128] = "";
    for (uint32_t i = 0; i < count; i++) {
        if (strcmp(env, words[i]) == 0) return (int)i;
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s'%s'", i ? ", " : "", words[i]);
    }
    ob_log_write(OB_LOG_WARN, module, __FILE__, __LINE__, "%s='%s' is none of %s: %s", name, env, list,
                 otherwise);
    return -1;
}

const char *ob_closest_name(const char *name, const char *const *candidates, uint32_t count,
                            uint32_t max_distance)
{
    if (!name || !candidates) return NULL;
    if (!max_distance) {
        size_t len = strnlen(name, OB_EDIT_MAX);
        max_distance = len >= 6 ? (uint32_t)(len / 3) : 1;
    }
    const char *best = NULL;
    uint32_t best_d = max_distance + 1;
    for (uint32_t i = 0; i < count; i++) {
        if (!candidates[i] || !strcmp(candidates[i], name)) continue;
        uint32_t d = ob_edit_distance(name, candidates[i]);
        if (d < best_d && d < strnlen(candidates[i], OB_EDIT_MAX)) best = candidates[i], best_d = d;
    }
    return best;
}

uint64_t ob_time_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

uint64_t ob_thread_cpu_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

/* ----------------------------------------------------------------- files */

/* The reason a file could not be read: into why when the caller wants it
 * for its own message, otherwise logged as "cannot read WHAT 'PATH': ...". */
static void read_failed(const char *path, const char *what, char *why, size_t why_size,
                        const char *fmt, ...) __attribute__((format(printf, 5, 6)));

static void read_failed(const char *path, const char *what, char *why, size_t why_size,
                        const char *fmt, ...)
{
    char text[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (why && why_size) snprintf(why, why_size, "%s", text);
    else OB_LOG_E("io", "cannot read %s '%s': %s", what ? what : "file", path, text);
}

static const char *special_kind(mode_t mode)
{
    return S_ISDIR(mode) ? "a directory" : S_ISFIFO(mode) ? "a FIFO"
           : S_ISCHR(mode) || S_ISBLK(mode) ? "a device" : S_ISSOCK(mode) ? "a socket"
           : "a special file";
}

/* Opens path for reading without ever blocking: O_NONBLOCK keeps open()
 * from waiting for a FIFO's writer, and fstat on the opened descriptor (not
 * a stat before the open, which a rename could race) refuses anything that
 * is not a regular file — a FIFO, a device such as /dev/zero, a directory —
 * before a byte is read. Then blocking reads are restored. */
int ob_file_open_regular(const char *path, const char *what, uint64_t max_size, uint64_t *out_size,
                         char *why, size_t why_size, ob_result *out_result)
{
    ob_result r = OB_ERR_IO;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        read_failed(path, what, why, why_size, "%s", strerror(errno));
        goto fail;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        read_failed(path, what, why, why_size, "%s", strerror(errno));
        goto fail_close;
    }
    if (!S_ISREG(st.st_mode)) {
        read_failed(path, what, why, why_size, "not a regular file (%s)", special_kind(st.st_mode));
        goto fail_close;
    }
    if (max_size && (uint64_t)st.st_size > max_size) {
        read_failed(path, what, why, why_size, "%llu bytes, more than the limit of %llu",
                    (unsigned long long)st.st_size, (unsigned long long)max_size);
        r = OB_ERR_LIMIT;
        goto fail_close;
    }
    int flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        read_failed(path, what, why, why_size, "%s", strerror(errno));
        goto fail_close;
    }
    if (out_size) *out_size = (uint64_t)st.st_size;
    if (out_result) *out_result = OB_OK;
    return fd;
fail_close:
    close(fd);
fail:
    if (out_result) *out_result = r;
    return -1;
}

char *ob_file_read_limited(const char *path, const char *what, uint64_t max_size, size_t *out_size,
                           char *why, size_t why_size, ob_result *out_result)
{
    ob_result r;
    uint64_t size = 0;
    char *buf = NULL;
    int fd = ob_file_open_regular(path, what, max_size, &size, why, why_size, &r);
    if (fd < 0) goto done;
    if (size >= SIZE_MAX) {
        read_failed(path, what, why, why_size, "too large for this address space");
        r = OB_ERR_LIMIT;
        goto fail_close;
    }
    buf = ob_malloc((size_t)size + 1);
    if (!buf) {
        read_failed(path, what, why, why_size, "out of memory for %llu bytes",
                    (unsigned long long)size);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_close;
    }
    size_t got = 0;
    while (got < size) {
        ssize_t n = read(fd, buf + got, (size_t)size - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            read_failed(path, what, why, why_size, "%s",
                        n < 0 ? strerror(errno) : "the file shrank while being read");
            ob_free(buf);
            buf = NULL;
            r = OB_ERR_IO;
            goto fail_close;
        }
        got += (size_t)n;
    }
    buf[got] = '\0';
    if (out_size) *out_size = got;
fail_close:
    close(fd);
done:
    if (out_result) *out_result = r;
    return buf;
}

char *ob_file_read(const char *path, size_t *out_size, ob_result *out_result)
{
    return ob_file_read_limited(path, "file", 0, out_size, NULL, 0, out_result);
}

/* The file a write to path lands in, into target (size bytes): path itself,
 * or, when path is a symbolic link, what it points to (resolved, so the
 * temporary file sits in the real target's folder and the rename replaces
 * the target, not the link). Refuses an existing path that is not a regular
 * file: a FIFO, a device (/dev/full), a directory — renaming over those
 * would replace the node. No allocation of ours (fault-injection walks
 * count them). OB_ERR_IO or OB_ERR_INVALID_ARGUMENT (too long), logged. */
static ob_result write_target(const char *path, char *target, size_t size)
{
    struct stat st;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode)) {
            OB_LOG_E("io", "cannot write '%s': not a regular file (%s); refusing to replace it", path,
                     special_kind(st.st_mode));
            return OB_ERR_IO;
        }
    } else if (errno != ENOENT) {
        OB_LOG_E("io", "cannot write '%s': %s", path, strerror(errno));
        return OB_ERR_IO;
    }
    int n;
    struct stat lst;
    if (lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode)) {
        /* An existing target (stat succeeded above): write through it. A
         * dangling link is written as a new file where it points; realpath
         * needs the target to exist, so the link's text is resolved against
         * the link's folder instead. */
        char *real = realpath(path, NULL);
        if (real) {
            n = snprintf(target, size, "%s", real);
            free(real);
        } else {
            char link[4096];
            ssize_t len = readlink(path, link, sizeof link - 1);
            if (len <= 0) {
                OB_LOG_E("io", "cannot write '%s': unreadable symbolic link", path);
                return OB_ERR_IO;
            }
            link[len] = '\0';
            const char *slash = strrchr(path, '/');
            int dir = link[0] == '/' || !slash ? 0 : (int)(slash - path) + 1;
            n = snprintf(target, size, "%.*s%s", dir, path, link);
        }
    } else {
        n = snprintf(target, size, "%s", path);
    }
    if (n < 0 || (size_t)n >= size) {
        OB_LOG_E("io", "cannot write '%s': the path is too long", path);
        return OB_ERR_INVALID_ARGUMENT;
    }
    return OB_OK;
}

ob_result ob_file_write(const char *path, const void *data, size_t size)
{
    char target[4096], tmp[4096 + 32];
    ob_result r = write_target(path, target, sizeof target);
    if (r != OB_OK) return r;
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", target, (long)getpid());
    /* Exclusively: whatever is already at the temporary name (a link planted
     * there, a FIFO) makes the write fail instead of being followed. */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOCTTY, 0666);
    if (fd < 0) {
        OB_LOG_E("io", "cannot create '%s': %s", tmp, strerror(errno));
        return OB_ERR_IO;
    }
    const char *p = data;
    size_t left = size;
    int err = 0;
    while (left > 0) {
        ssize_t w = write(fd, p, left);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            err = w < 0 ? errno : ENOSPC;
            break;
        }
        p += w;
        left -= (size_t)w;
    }
    if (close(fd) != 0 && !err) err = errno;
    if (!err && rename(tmp, target) != 0) err = errno;
    if (err) {
        OB_LOG_E("io", "cannot write '%s': %s", path, strerror(err));
        unlink(tmp);
        return OB_ERR_IO;
    }
    return OB_OK;
}

ob_result ob_dir_make(const char *path)
{
    char buf[4096];
    size_t n = strlen(path);
    if (n == 0 || n >= sizeof buf) return OB_ERR_INVALID_ARGUMENT;
    memcpy(buf, path, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (buf[i] == '/' || buf[i] == '\0') {
            char c = buf[i];
            buf[i] = '\0';
            if (mkdir(buf, 0755) != 0 && errno != EEXIST) {
                OB_LOG_E("io", "cannot create directory '%s': %s", buf, strerror(errno));
                return OB_ERR_IO;
            }
            buf[i] = c;
        }
    }
    return OB_OK;
}
