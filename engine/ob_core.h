/* ob_core.h — results, logging, allocation, handles, hashing and time.
 *
 * The bottom of the engine: every other module includes this header and
 * nothing below it but libc. It has no lifecycle of its own.
 *
 * Thread rule: every function here is [any thread]. This header is the one
 * place that lists Obelisk's process-wide state ("process-wide state" below:
 * the log sink, the fault-injection and heap counters, and the one-time
 * set-up of third-party libraries, each run through ob_once_run); anything
 * else hangs off an explicit object.
 */
#ifndef OB_CORE_H
#define OB_CORE_H

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- results */

/* X-macro: one place defines every result and its name. */
#define OB_RESULT_LIST(X)                                                        \
    X(OB_OK, "ok")                                                               \
    X(OB_ERR_INVALID_ARGUMENT, "invalid argument")                               \
    X(OB_ERR_INVALID_HANDLE, "invalid or stale handle")                          \
    X(OB_ERR_OUT_OF_HOST_MEMORY, "out of host memory")                           \
    X(OB_ERR_OUT_OF_DEVICE_MEMORY, "out of device memory")                       \
    X(OB_ERR_NO_DEVICE, "no suitable Vulkan device")                             \
    X(OB_ERR_DEVICE_LOST, "device lost")                                         \
    X(OB_ERR_VULKAN, "Vulkan call failed")                                       \
    X(OB_ERR_UNSUPPORTED, "unsupported")                                         \
    X(OB_ERR_IO, "file input/output error")                                      \
    X(OB_ERR_PARSE, "parse error")                                               \
    X(OB_ERR_SHADER_COMPILE, "shader compile error")                             \
    X(OB_ERR_TYPE_MISMATCH, "type mismatch")                                     \
    X(OB_ERR_OUT_OF_RANGE, "out of range")                                       \
    X(OB_ERR_DUPLICATE, "duplicate")                                             \
    X(OB_ERR_NOT_FOUND, "not found")                                             \
    X(OB_ERR_WRONG_STATE, "call not allowed in the current state")               \
    X(OB_ERR_NON_FINITE, "non-finite value")                                     \
    X(OB_ERR_BAD_MODEL, "model failed validation")                               \
    X(OB_ERR_LIMIT, "limit exceeded")

typedef enum ob_result {
#define OB_RESULT_ENUM(name, text) name,
    OB_RESULT_LIST(OB_RESULT_ENUM)
#undef OB_RESULT_ENUM
    OB_RESULT_COUNT
} ob_result;

/* Stable name of a result ("OB_ERR_IO"); never NULL. */
const char *ob_result_name(ob_result r);
/* Human text of a result ("file input/output error"); never NULL. */
const char *ob_result_text(ob_result r);

/* ---------------------------------------------------------------- logging */

typedef enum ob_log_level {
    OB_LOG_DEBUG = 0,
    OB_LOG_INFO = 1,
    OB_LOG_WARN = 2,
    OB_LOG_ERROR = 3,
} ob_log_level;

/* A sink receives one fully formatted line (no trailing newline).
 * module is a short tag ("vk", "params", "shader", ...); file/line locate the
 * caller. The default sink prints "[level][module] message (file:line)" to
 * stderr for WARN and above, and for INFO when OB_LOG=info|debug is set. */
typedef void (*ob_log_fn)(void *user, ob_log_level level, const char *module,
                          const char *file, int line, const char *message);

/* Replace the sink (NULL restores the default). [any thread] but meant to be
 * called once, before work starts; returns the previous sink. */
ob_log_fn ob_log_set_sink(ob_log_fn fn, void *user, void **out_prev_user);

/* Count of lines logged at WARN and at ERROR since start (any sink). */
uint64_t ob_log_count(ob_log_level level);

void ob_log_write(ob_log_level level, const char *module, const char *file,
                  int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
void ob_log_writev(ob_log_level level, const char *module, const char *file,
                   int line, const char *fmt, va_list ap);

#define OB_LOG_E(module, ...) ob_log_write(OB_LOG_ERROR, module, __FILE__, __LINE__, __VA_ARGS__)
#define OB_LOG_W(module, ...) ob_log_write(OB_LOG_WARN, module, __FILE__, __LINE__, __VA_ARGS__)
#define OB_LOG_I(module, ...) ob_log_write(OB_LOG_INFO, module, __FILE__, __LINE__, __VA_ARGS__)
#define OB_LOG_D(module, ...) ob_log_write(OB_LOG_DEBUG, module, __FILE__, __LINE__, __VA_ARGS__)

/* ------------------------------------------------------------- allocation */

/* Every host allocation in Obelisk goes through these, so tests can fail the
 * Nth one (ob_fault_*). They behave like malloc/calloc/realloc/free;
 * ob_free(NULL) is a no-op. ob_aligned_alloc's memory is freed with
 * ob_aligned_free (alignment must be a power of two). */
void *ob_malloc(size_t size);
void *ob_calloc(size_t count, size_t size);
void *ob_realloc(void *ptr, size_t size);
void ob_free(void *ptr);
void *ob_aligned_alloc(size_t alignment, size_t size);
void ob_aligned_free(void *ptr);
char *ob_strdup(const char *s);

/* Live blocks allocated through the functions above and not yet freed, and
 * their bytes as the allocator sized them (sized = false where the C library
 * cannot tell a block's size: then live_bytes stays 0). Everything Obelisk
 * allocates on the host, the libraries it hooks (stb; cJSON when the
 * program asks: ob_scene_file_hook_cjson) included; not the driver's or the
 * validation layer's memory. [any thread; a snapshot: other threads may
 * allocate meanwhile] */
typedef struct ob_heap_stats {
    uint64_t live_bytes, live_blocks;
    bool sized;
} ob_heap_stats;
ob_heap_stats ob_heap_stats_now(void);

/* Grow a dynamic array so it holds at least `need` elements of elem_size.
 * *items and *cap are updated only on success. */
ob_result ob_array_reserve(void **items, uint32_t *cap, uint32_t need, size_t elem_size);
/* The same for an array from ob_aligned_alloc (freed with ob_aligned_free):
 * the contents move to a new block aligned to `alignment`. */
ob_result ob_array_reserve_aligned(void **items, uint32_t *cap, uint32_t need, size_t elem_size,
                                   size_t alignment);

/* ---------------------------------------------------------- fault injection */

typedef enum ob_fault_kind {
    OB_FAULT_HOST_ALLOC = 0,   /* ob_malloc & co. return NULL */
    OB_FAULT_VK_OBJECT = 1,    /* a Vulkan allocation or object creation fails */
    OB_FAULT_DEVICE_LOST = 2,  /* a queue submission or a wait reports VK_ERROR_DEVICE_LOST */
    OB_FAULT_SUBMIT_OOM = 3,   /* a queue submission reports VK_ERROR_OUT_OF_DEVICE_MEMORY */
    OB_FAULT_KIND_COUNT
} ob_fault_kind;

/* Arm: the nth (1-based) call of that kind from now on fails; 0 disarms.
 * ob_fault_hit says whether an armed fault fired since arming; ob_fault_count
 * how many calls of that kind were made since arming (walk every point by
 * running once unarmed and looping n from 1 to that count). [any thread] */
void ob_fault_arm(ob_fault_kind kind, uint64_t nth);
bool ob_fault_hit(ob_fault_kind kind);
uint64_t ob_fault_count(ob_fault_kind kind);
/* Called at each fault point; true means "fail this one". */
bool ob_fault_should_fail(ob_fault_kind kind);

/* ------------------------------------------------------ process-wide state */

/* Obelisk's process-wide state, all of it:
 *  - the log sink and the log counters, the fault-injection counters and
 *    the heap counters above: atomics, set up by tests or the application
 *    before renderers exist;
 *  - one-time set-up, each an ob_once defined in the one file of the layer
 *    that needs it (the engine links no third-party library, and a lower
 *    layer never calls a higher one), run through ob_once_run on first use
 *    and listed by ob_once_list under these names:
 *      "glslang"          materials/ob_shader.c: glslang_initialize_process
 *                         and a warm-up compile per stage, at the first
 *                         ob_shader_compiler_create; never finalised, since
 *                         a compiler may be made again (the OS reclaims it);
 *      "cJSON hooks"      views/scene/ob_json_read.c: cJSON_InitHooks with
 *                         ob_malloc/ob_free, only when the program calls
 *                         ob_scene_file_hook_cjson: cJSON's hooks are
 *                         process-wide, and a program that uses cJSON itself
 *                         must not find them changed behind its back (its
 *                         own hooks replaced, or its blocks freed by ours);
 *      "standard input"   views/ob_views.c: the standard vertex layout as an
 *                         effect's vertex input, a constant made once;
 *  - one lock that needs no set-up: geometry/ob_model.c's around assimp's
 *    import, whose error text (aiGetErrorString) is one process-wide string.
 * stb is compiled into the engine (engine/ob_stb_impl.c, its own copy, not
 * a program's): its failure text is per thread and its global flags are
 * never set. Nothing else in the library changes after start-up outside an
 * object. */
typedef struct ob_once {
    const char *name;        /* as listed above */
    ob_result (*init)(void); /* runs once; must not run another ob_once */
    int state;               /* 0 until init has run (atomic, read by ob_once_run) */
    ob_result result;        /* init's result, kept */
    struct ob_once *next;    /* the list of set-ups that ran */
} ob_once;
#define OB_ONCE_INIT(name, init) {(name), (init), 0, OB_OK, NULL}

/* Runs once->init the first time any thread gets here (others wait for it)
 * and returns its result, then and on every later call: a set-up that
 * failed stays failed (logged once, naming it). [any thread] */
ob_result ob_once_run(ob_once *once);
/* The names of the set-ups that have run, in the order they ran: up to cap
 * into names (may be NULL with cap 0); returns how many have run.
 * [any thread] */
uint32_t ob_once_list(const char **names, uint32_t cap);

/* ---------------------------------------------------------------- handles */

/* Resource handles: id 0 is invalid; the low 20 bits are a pool index + 1,
 * the high 12 bits a generation that changes on every reuse of the slot. */
typedef struct ob_buffer { uint32_t id; } ob_buffer;
typedef struct ob_image { uint32_t id; } ob_image;
typedef struct ob_sampler { uint32_t id; } ob_sampler;

#define OB_HANDLE_INDEX_BITS 20u
#define OB_HANDLE_INDEX_MASK ((1u << OB_HANDLE_INDEX_BITS) - 1u)
#define OB_HANDLE_MAX_SLOTS (OB_HANDLE_INDEX_MASK - 1u)

/* A generation-checked slot pool (render thread). Slots hold a user pointer. */
typedef struct ob_pool {
    uint32_t cap;        /* allocated slots */
    uint32_t count;      /* live slots */
    uint32_t free_head;  /* 1-based index of the first free slot, 0 = none */
    uint32_t *gen;       /* generation per slot (1..4095) */
    uint32_t *next_free; /* free-list links */
    void **items;        /* payload per slot, NULL when free */
} ob_pool;

void ob_pool_init(ob_pool *pool);
void ob_pool_release(ob_pool *pool);
/* Stores item, returns its id (0 with *out_result set on failure). */
uint32_t ob_pool_insert(ob_pool *pool, void *item, ob_result *out_result);
/* The item for id, or NULL if id is zero, out of range or stale. */
void *ob_pool_get(const ob_pool *pool, uint32_t id);
/* Frees id's slot and returns its item (NULL if stale). */
void *ob_pool_remove(ob_pool *pool, uint32_t id);
/* Iterate live items: start with *cursor = 0; returns NULL at the end. */
void *ob_pool_next(const ob_pool *pool, uint32_t *cursor, uint32_t *out_id);

/* ----------------------------------------------------------- hash & time */

#define OB_HASH_SEED 0xcbf29ce484222325ull
/* 64-bit hash of bytes, continuing from h (start with OB_HASH_SEED).
 * Stable across runs and platforms of the same endianness. */
uint64_t ob_hash_bytes(uint64_t h, const void *data, size_t size);
/* One 64-bit word into h (splitmix-style; inline: it is on every draw). */
static inline uint64_t ob_hash_u64(uint64_t h, uint64_t v)
{
    h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ull;
    h ^= h >> 27;
    return h;
}
/* A block of bytes into h, 32 bytes per step in four independent lanes:
 * several times the throughput of a chain of ob_hash_u64 (for push
 * constants and uniform blocks). */
uint64_t ob_hash_block(uint64_t h, const void *data, size_t size);
static inline uint64_t ob_hash_str(uint64_t h, const char *s);

/* Monotonic time in nanoseconds. */
uint64_t ob_time_ns(void);
/* Median of v[0..n), NaNs left out (v is reordered); NAN if none is left.
 * [any thread] */
double ob_median(double *v, uint32_t n);
/* CPU time the calling thread has used, in nanoseconds. */
uint64_t ob_thread_cpu_ns(void);

/* Edit distance between a and b: insertions, deletions, substitutions and
 * swaps of two neighbouring characters count 1 each ("--frmaes" is 1 from
 * "--frames"); letters compare case-insensitively (ASCII) at no cost.
 * Strings past 63 bytes are compared on their first 63. [any thread] */
uint32_t ob_edit_distance(const char *a, const char *b);
/* The candidate closest to name, for a "did you mean" in an error message:
 * the first of the nearest, NULL when none is within max_distance (0: a
 * third of name's length, at least 1, so that "--size" does not suggest
 * "--seed"), nor one that every character would have to change (a
 * one-letter name does not suggest "x"). An exact match is never suggested
 * (the caller would not have failed); NULL names and candidates are skipped. Allocates nothing.
 * [any thread] */
const char *ob_closest_name(const char *name, const char *const *candidates, uint32_t count,
                            uint32_t max_distance);
/* Which of words[0..count) the environment variable `name` holds: its
 * index, or -1 when it is unset or empty. Any other value is named in a
 * warning from `module` with the words it may be and `otherwise` (what the
 * caller then does: "ignored"), and gives -1. [any thread] */
int ob_env_choice(const char *name, const char *const *words, uint32_t count, const char *module,
                  const char *otherwise);

/* One index of a parallel loop. `thread` (0 .. threads-1; 0 is the calling
 * thread) names the thread running it, for per-thread scratch: two calls
 * with the same thread never overlap. Results that must not depend on the
 * thread count are written per index and combined in index order. */
typedef void (*ob_task_fn)(void *user, uint32_t index, uint32_t thread);

/* Help a loop's thread may give once no index is left to take: work the
 * indices made that any thread may share (a big view's draw list to
 * gather), or a short wait for some. Returns false when there is none and
 * none is coming. Only an offer: every piece of that work must also be
 * done by the thread that made it, so that the loop is complete whether
 * helpers come or not, and its results must not depend on who helped. */
typedef bool (*ob_idle_fn)(void *user, uint32_t thread);

/* A way to run a parallel loop: run(ctx, count, fn, user) calls fn once for
 * every index in [0, count), on at most `threads` threads, and returns when
 * all calls are done. The renderer lends its worker pool this way
 * (ob_renderer_parallel); threads = 1 means everything runs on the caller. */
typedef struct ob_parallel {
    void (*run)(void *ctx, uint32_t count, ob_task_fn fn, void *user);
    void *ctx;
    uint32_t threads;
    /* Items (entities, nodes) per loop index the caller should take, and
     * half of what each thread must get for a loop worth handing out; 0:
     * the caller's own default. */
    uint32_t grain;
    /* run, with every thread calling idle after its last index until it
     * returns false; NULL: run, then idle on the caller alone. */
    void (*run_helped)(void *ctx, uint32_t count, ob_task_fn fn, ob_idle_fn idle, void *user);
} ob_parallel;

/* Whether a loop over `items` (grain per index) is worth handing to par:
 * each thread gets two indices' worth, since waking a pool thread costs
 * some 30-50 us on a 2-core VM. [any thread] */
static inline bool ob_parallel_worth(const ob_parallel *par, uint64_t items, uint32_t grain)
{
    return par && par->threads > 1 && items >= 2ull * grain * par->threads;
}

/* Runs the loop through par, or on the caller when par is NULL or has one
 * thread (or count < 2). [any thread] */
static inline void ob_parallel_run(const ob_parallel *par, uint32_t count, ob_task_fn fn,
                                   void *user)
{
    if (par && par->run && par->threads > 1 && count > 1) {
        par->run(par->ctx, count, fn, user);
        return;
    }
    for (uint32_t i = 0; i < count; i++) fn(user, i, 0);
}

/* ob_parallel_run, with the threads helping through idle once the indices
 * are gone (ob_idle_fn). [any thread] */
static inline void ob_parallel_run_helped(const ob_parallel *par, uint32_t count, ob_task_fn fn,
                                          ob_idle_fn idle, void *user)
{
    if (par && par->run_helped && par->threads > 1 && count > 1) {
        par->run_helped(par->ctx, count, fn, idle, user);
        return;
    }
    ob_parallel_run(par, count, fn, user);
    while (idle(user, 0)) {}
}

/* Read a whole file into a NUL-terminated buffer (ob_free it). Only a
 * regular file is read: a FIFO, a device or a directory is refused without
 * blocking (opened O_NONBLOCK, checked with fstat before any read). On
 * failure returns NULL, logs the path and the reason, and sets *out_result
 * (OB_ERR_IO, OB_ERR_OUT_OF_HOST_MEMORY). [any thread] */
char *ob_file_read(const char *path, size_t *out_size, ob_result *out_result);
/* ob_file_read with a size bound checked before memory is committed: a
 * file over max_size bytes (0 = no bound) is refused with OB_ERR_LIMIT.
 * what names the file in the log ("scene file"). With why (why_size
 * bytes) the reason goes there, for the caller's own message, instead of
 * the log. [any thread] */
char *ob_file_read_limited(const char *path, const char *what, uint64_t max_size, size_t *out_size,
                           char *why, size_t why_size, ob_result *out_result);
/* The descriptor of a regular file opened for reading (blocking reads),
 * with its size in *out_size; -1 for anything else, without ever blocking
 * on a FIFO: the reason logged, or put in why, and *out_result set
 * (OB_ERR_IO; OB_ERR_LIMIT over max_size when that is not 0). close() it.
 * [any thread] */
int ob_file_open_regular(const char *path, const char *what, uint64_t max_size, uint64_t *out_size,
                         char *why, size_t why_size, ob_result *out_result);
/* Write a file atomically: a temporary file beside the target, created
 * exclusively (O_EXCL: nothing already at that name is followed), every
 * write and the close checked, then renamed over the target. A symbolic
 * link is written through (the file it names is replaced, the link stays);
 * an existing FIFO, device or directory is refused (OB_ERR_IO, logged),
 * never replaced. [any thread] */
ob_result ob_file_write(const char *path, const void *data, size_t size);
/* mkdir -p. */
ob_result ob_dir_make(const char *path);

static inline uint64_t ob_hash_str(uint64_t h, const char *s)
{
    size_t n = 0;
    while (s[n]) n++;
    return ob_hash_bytes(h, s, n);
}

#define OB_ARRAY_COUNT(a) (sizeof(a) / sizeof((a)[0]))
#define OB_MIN(a, b) ((a) < (b) ? (a) : (b))
#define OB_MAX(a, b) ((a) > (b) ? (a) : (b))
#define OB_CACHE_LINE 64u

#ifdef __cplusplus
}
#endif
#endif /* OB_CORE_H */
