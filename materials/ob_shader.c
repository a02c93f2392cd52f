#define _POSIX_C_SOURCE 200809L
#include "ob_shader.h"
#include "ob_shader_source.h"

#include <errno.h>
#include <glslang/Include/glslang_c_interface.h>
#include <glslang/Public/resource_limits_c.h>
#include <glslang/build_info.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Bump when anything that changes the SPIR-V for the same source changes
 * (target versions, glslang options); the glslang version is mixed in too. */
#define COMPILER_REVISION 1u
#define COMPILER_VERSION                                                               \
    (((uint64_t)COMPILER_REVISION << 32) | ((uint64_t)GLSLANG_VERSION_MAJOR << 16) |   \
     ((uint64_t)GLSLANG_VERSION_MINOR << 8) | (uint64_t)GLSLANG_VERSION_PATCH)

#define SPIRV_MAGIC 0x07230203u
#define CACHE_MAGIC 0x5653424fu /* "OBSV" */
#define CACHE_FORMAT 1u
#define INITIAL_BUCKETS 64u

/* On-disk header of <cache_dir>/spirv/<hash>.spv, followed by the words. */
typedef struct cache_header {
    uint32_t magic;
    uint32_t format;
    uint64_t key;
    uint32_t words;
    uint32_t stage;
    uint64_t checksum;   /* ob_hash_bytes of the words */
} cache_header;

typedef enum variant_state { VARIANT_BUILDING, VARIANT_READY, VARIANT_FAILED } variant_state;

typedef struct variant {
    ob_shader shader;          /* shader.name is owned here */
    struct variant *next;      /* bucket chain */
    uint64_t key_hash;
    bool has_source;
    uint64_t source_hash;
    variant_state state;
    ob_result result;          /* VARIANT_FAILED: what waiters return */
    uint32_t waiters;
} variant;

struct ob_shader_compiler {
    char *shader_dir;
    char *cache_dir;           /* "" when the disk cache is off */
    char *spirv_dir;           /* NULL when the disk cache is off */
    pthread_mutex_t lock;      /* guards the table and variant states */
    pthread_cond_t finished;   /* a variant left VARIANT_BUILDING */
    variant **buckets;
    uint32_t bucket_count;
    uint32_t variant_count;
    atomic_uint compiled, memory_hits, disk_hits, disk_rejected, failed;
};

/* ---------------------------------------------------------------- glslang */

static const glslang_stage_t glslang_stages[OB_SHADER_STAGE_COUNT] = {
    GLSLANG_STAGE_VERTEX, GLSLANG_STAGE_FRAGMENT, GLSLANG_STAGE_COMPUTE};

static glslang_input_t glslang_input(ob_shader_stage stage, const char *code)
{
    return (glslang_input_t){
        .language = GLSLANG_SOURCE_GLSL,
        .stage = glslang_stages[stage],
        .client = GLSLANG_CLIENT_VULKAN,
        .client_version = GLSLANG_TARGET_VULKAN_1_3,
        .target_language = GLSLANG_TARGET_SPV,
        .target_language_version = GLSLANG_TARGET_SPV_1_6,
        .code = code,
        .default_version = 450,
        .default_profile = GLSLANG_NO_PROFILE,
        .messages = GLSLANG_MSG_SPV_RULES_BIT | GLSLANG_MSG_VULKAN_RULES_BIT,
        .resource = glslang_default_resource(),
    };
}

/* glslang's process-wide set-up, listed with the rest of Obelisk's
 * process-wide state in ob_core.h. */
static ob_result glslang_init(void)
{
    if (!glslang_initialize_process()) {
        OB_LOG_E("shader", "glslang failed to initialise (glslang_initialize_process)");
        return OB_ERR_UNSUPPORTED;
    }
    /* glslang builds some tables lazily in function-local statics on the
     * first compile of each stage. Doing that here, inside ob_once_run,
     * orders it before every concurrent compile in a way the thread
     * sanitizer can see (glslang itself is not instrumented). */
    static const char *const warm_up[OB_SHADER_STAGE_COUNT] = {
        "#version 450\nvoid main() { gl_Position = vec4(0.0); }\n",
        "#version 450\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(1.0); }\n",
        "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
    };
    for (int s = 0; s < OB_SHADER_STAGE_COUNT; s++) {
        glslang_input_t in = glslang_input((ob_shader_stage)s, warm_up[s]);
        glslang_shader_t *sh = glslang_shader_create(&in);
        glslang_program_t *prog = glslang_program_create();
        if (sh && prog && glslang_shader_preprocess(sh, &in) && glslang_shader_parse(sh, &in)) {
            glslang_program_add_shader(prog, sh);
            if (glslang_program_link(prog, in.messages)) {
                glslang_spv_options_t opts = {.disable_optimizer = true};
                glslang_program_SPIRV_generate_with_options(prog, in.stage, &opts);
            }
        }
        glslang_program_delete(prog);
        glslang_shader_delete(sh);
    }
    return OB_OK;
}
static ob_once glslang_once = OB_ONCE_INIT("glslang", glslang_init);

/* ------------------------------------------------------------ create/destroy */

/* NULL with *oom false: no cache folder can be named (no $HOME). */
static char *default_cache_dir(bool *oom)
{
    static const struct { const char *var, *suffix; } tries[] = {
        {"OB_CACHE_DIR", NULL}, {"XDG_CACHE_HOME", "obelisk"}, {"HOME", ".cache/obelisk"}};
    *oom = false;
    for (size_t i = 0; i < OB_ARRAY_COUNT(tries); i++) {
        const char *v = getenv(tries[i].var);
        if (!v || !v[0]) continue;
        char *dir = tries[i].suffix ? ob_shader_path_join(v, tries[i].suffix) : ob_strdup(v);
        *oom = dir == NULL;
        return dir;
    }
    return NULL;
}

ob_shader_compiler *ob_shader_compiler_create(const ob_shader_compiler_desc *desc,
                                              ob_result *out_result)
{
    ob_shader_compiler_desc d = desc ? *desc : (ob_shader_compiler_desc){0};
    ob_result r = ob_once_run(&glslang_once);
    if (r != OB_OK) goto fail_log;
    r = OB_ERR_OUT_OF_HOST_MEMORY;
    ob_shader_compiler *c = ob_calloc(1, sizeof *c);
    if (!c) goto fail_log;
    const char *env_shaders = getenv("OB_SHADER_DIR");
    c->shader_dir = d.shader_dir                    ? ob_strdup(d.shader_dir)
                    : env_shaders && env_shaders[0] ? ob_strdup(env_shaders)
                                                    : ob_shader_dir_default();
    if (!c->shader_dir) goto fail_free_compiler;

    if (!d.no_disk_cache) {
        bool oom = false;
        char *dir = d.cache_dir ? ob_strdup(d.cache_dir) : default_cache_dir(&oom);
        if (!dir && (d.cache_dir || oom)) goto fail_free_compiler;
        if (!dir) {
            OB_LOG_I("shader", "no cache folder ($OB_CACHE_DIR, $XDG_CACHE_HOME, $HOME unset): "
                     "shaders are cached in memory only");
        } else {
            c->spirv_dir = ob_shader_path_join(dir, "spirv");
            if (!c->spirv_dir) {
                ob_free(dir);
                goto fail_free_compiler;
            }
            if (ob_dir_make(c->spirv_dir) != OB_OK) {
                OB_LOG_W("shader", "cannot create shader cache folder '%s': shaders are cached "
                         "in memory only", c->spirv_dir);
                ob_free(c->spirv_dir);
                c->spirv_dir = NULL;
                ob_free(dir);
            } else {
                c->cache_dir = dir;
            }
        }
    }
    if (!c->cache_dir && !(c->cache_dir = ob_strdup(""))) goto fail_free_compiler;

    c->bucket_count = INITIAL_BUCKETS;
    c->buckets = ob_calloc(c->bucket_count, sizeof *c->buckets);
    if (!c->buckets) goto fail_free_compiler;
    if (pthread_mutex_init(&c->lock, NULL) != 0) goto fail_free_compiler;
    if (pthread_cond_init(&c->finished, NULL) != 0) goto fail_destroy_mutex;
    if (out_result) *out_result = OB_OK;
    return c;

fail_destroy_mutex:
    pthread_mutex_destroy(&c->lock);
fail_free_compiler:
    ob_free(c->buckets);
    ob_free(c->spirv_dir);
    ob_free(c->cache_dir);
    ob_free(c->shader_dir);
    ob_free(c);
fail_log:
    if (r == OB_ERR_OUT_OF_HOST_MEMORY) OB_LOG_E("shader", "out of host memory creating the shader compiler");
    if (out_result) *out_result = r;
    return NULL;
}

static void variant_free(variant *v)
{
    ob_free((char *)v->shader.name);
    ob_free((uint32_t *)v->shader.spirv);
    ob_reflection_release(&v->shader.reflection);
    ob_free(v);
}

void ob_shader_compiler_destroy(ob_shader_compiler *c)
{
    if (!c) return;
    for (uint32_t i = 0; i < c->bucket_count; i++) {
        for (variant *v = c->buckets[i], *next; v; v = next) {
            next = v->next;
            variant_free(v);
        }
    }
    pthread_cond_destroy(&c->finished);
    pthread_mutex_destroy(&c->lock);
    ob_free(c->buckets);
    ob_free(c->spirv_dir);
    ob_free(c->cache_dir);
    ob_free(c->shader_dir);
    ob_free(c);
}

ob_shader_compiler_stats ob_shader_compiler_get_stats(const ob_shader_compiler *c)
{
    ob_shader_compiler_stats s = {0};
    if (!c) return s;
    s.compiled = atomic_load(&c->compiled);
    s.memory_hits = atomic_load(&c->memory_hits);
    s.disk_hits = atomic_load(&c->disk_hits);
    s.disk_rejected = atomic_load(&c->disk_rejected);
    s.failed = atomic_load(&c->failed);
    return s;
}

const char *ob_shader_compiler_shader_dir(const ob_shader_compiler *c) { return c ? c->shader_dir : ""; }
const char *ob_shader_compiler_cache_dir(const ob_shader_compiler *c) { return c ? c->cache_dir : ""; }

/* --------------------------------------------------------- variant table */

static variant *table_find(const ob_shader_compiler *c, const variant *key)
{
    for (variant *v = c->buckets[key->key_hash & (c->bucket_count - 1)]; v; v = v->next) {
        if (v->key_hash == key->key_hash && v->shader.stage == key->shader.stage &&
            v->has_source == key->has_source && v->source_hash == key->source_hash &&
            strcmp(v->shader.name, key->shader.name) == 0)
            return v;
    }
    return NULL;
}

/* Doubling the buckets is an optimisation: when it cannot allocate, the
 * chains just get longer. */
static void table_grow(ob_shader_compiler *c)
{
    uint32_t n = c->bucket_count * 2;
    variant **b = ob_calloc(n, sizeof *b);
    if (!b) return;
    for (uint32_t i = 0; i < c->bucket_count; i++) {
        for (variant *v = c->buckets[i], *next; v; v = next) {
            next = v->next;
            v->next = b[v->key_hash & (n - 1)];
            b[v->key_hash & (n - 1)] = v;
        }
    }
    ob_free(c->buckets);
    c->buckets = b;
    c->bucket_count = n;
}

static void table_insert(ob_shader_compiler *c, variant *v)
{
    if (c->variant_count >= c->bucket_count && c->bucket_count < (1u << 30)) table_grow(c);
    variant **head = &c->buckets[v->key_hash & (c->bucket_count - 1)];
    v->next = *head;
    *head = v;
    c->variant_count++;
}

static void table_remove(ob_shader_compiler *c, variant *v)
{
    for (variant **p = &c->buckets[v->key_hash & (c->bucket_count - 1)]; *p; p = &(*p)->next) {
        if (*p == v) {
            *p = v->next;
            c->variant_count--;
            return;
        }
    }
}

/* ------------------------------------------------------------ disk cache */

static char *cache_path(const ob_shader_compiler *c, uint64_t hash)
{
    char file[32];
    snprintf(file, sizeof file, "%016llx.spv", (unsigned long long)hash);
    return ob_shader_path_join(c->spirv_dir, file);
}

/* The cached words, or NULL (a miss; *out_result says OOM apart from a miss).
 * A file that fails any check is deleted and counted as rejected. */
static uint32_t *cache_load(ob_shader_compiler *c, const variant *v, const char *path,
                            size_t *out_words, ob_result *out_result)
{
    *out_result = OB_OK;
    struct stat st;
    if (stat(path, &st) != 0) return NULL;
    const char *why = NULL;
    uint32_t *words = NULL;
    char *data = NULL;
    size_t size = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        why = strerror(errno);
    } else {
        size = (size_t)st.st_size;
        data = ob_malloc(size ? size : 1);
        if (!data) {
            fclose(f);
            *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
            return NULL;
        }
        if (fread(data, 1, size, f) != size) why = "short read";
        fclose(f);
    }
    cache_header h;
    if (!why && size < sizeof h) why = "truncated header";
    if (!why) {
        memcpy(&h, data, sizeof h);
        if (h.magic != CACHE_MAGIC) why = "bad magic";
        else if (h.format != CACHE_FORMAT) why = "other format version";
        else if (h.key != v->shader.hash || h.stage != (uint32_t)v->shader.stage) why = "key mismatch";
        else if (h.words == 0 || size != sizeof h + (size_t)h.words * 4u) why = "truncated or padded";
        else if (ob_hash_bytes(OB_HASH_SEED, data + sizeof h, (size_t)h.words * 4u) != h.checksum)
            why = "checksum mismatch";
    }
    if (!why) {
        words = ob_malloc((size_t)h.words * 4u);
        if (!words) {
            ob_free(data);
            *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
            return NULL;
        }
        memcpy(words, data + sizeof h, (size_t)h.words * 4u);
        if (words[0] != SPIRV_MAGIC) why = "not SPIR-V";
    }
    ob_free(data);
    if (why) {
        ob_free(words);
        OB_LOG_W("shader", "shader cache file '%s' for '%s' is corrupt (%s): deleted, recompiling",
                 path, v->shader.name, why);
        remove(path);
        atomic_fetch_add(&c->disk_rejected, 1);
        return NULL;
    }
    *out_words = h.words;
    return words;
}

/* A failed write only costs a recompile next run: warn and go on. */
static void cache_store(const variant *v, const char *path)
{
    size_t bytes = v->shader.spirv_words * 4u;
    cache_header h = {CACHE_MAGIC, CACHE_FORMAT, v->shader.hash, (uint32_t)v->shader.spirv_words,
                      (uint32_t)v->shader.stage, ob_hash_bytes(OB_HASH_SEED, v->shader.spirv, bytes)};
    char *data = ob_malloc(sizeof h + bytes);
    if (!data) {
        OB_LOG_W("shader", "out of memory writing the cache file of '%s'", v->shader.name);
        return;
    }
    memcpy(data, &h, sizeof h);
    memcpy(data + sizeof h, v->shader.spirv, bytes);
    if (ob_file_write(path, data, sizeof h + bytes) != OB_OK)
        OB_LOG_W("shader", "cannot write shader cache file '%s' for '%s'", path, v->shader.name);
    ob_free(data);
}

/* ---------------------------------------------------------------- compile */

static uint64_t variant_hash(const char *preprocessed, ob_shader_stage stage, const char *preamble)
{
    uint64_t h = ob_hash_str(OB_HASH_SEED, preprocessed);
    h = ob_hash_u64(h, (uint64_t)stage);
    h = ob_hash_str(h, preamble);
    return ob_hash_u64(h, COMPILER_VERSION);
}

/* glslang: parse, link, generate SPIR-V into v. */
static ob_result compile_spirv(const ob_shader_source *src, glslang_shader_t *sh,
                               glslang_input_t *in, variant *v)
{
    ob_result r = OB_ERR_SHADER_COMPILE;
    uint32_t *words = NULL;
    glslang_program_t *prog = NULL;
    if (!glslang_shader_parse(sh, in)) {
        ob_shader_source_log(src, v->shader.name, glslang_shader_get_info_log(sh));
        goto done;
    }
    ob_shader_source_log(src, v->shader.name, glslang_shader_get_info_log(sh)); /* warnings */
    prog = glslang_program_create();
    if (!prog) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    glslang_program_add_shader(prog, sh);
    if (!glslang_program_link(prog, in->messages)) {
        ob_shader_source_log(src, v->shader.name, glslang_program_get_info_log(prog));
        goto done;
    }
    glslang_spv_options_t opts = {.disable_optimizer = true};
    glslang_program_SPIRV_generate_with_options(prog, in->stage, &opts);
    const char *spv_messages = glslang_program_SPIRV_get_messages(prog);
    if (spv_messages && spv_messages[0])
        OB_LOG_W("shader", "%s: SPIR-V generation: %s", v->shader.name, spv_messages);
    size_t count = glslang_program_SPIRV_get_size(prog);
    if (count == 0) {
        OB_LOG_E("shader", "%s: glslang generated no SPIR-V", v->shader.name);
        goto done;
    }
    words = ob_malloc(count * sizeof *words);
    if (!words) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    glslang_program_SPIRV_get(prog, words);
    v->shader.spirv = words;
    v->shader.spirv_words = count;
    r = OB_OK;
done:
    glslang_program_delete(prog);
    return r;
}

/* Fills v (hash, SPIR-V, reflection) from the disk cache or by compiling.
 * Runs without the table lock. */
static ob_result variant_build(ob_shader_compiler *c, const ob_shader_desc *desc,
                               const char *preamble, variant *v)
{
    ob_shader_source src;
    ob_result r = ob_shader_source_load(c->shader_dir, desc->path, desc->source, &src);
    if (r != OB_OK) return r;
    char *path = NULL;
    glslang_input_t in = glslang_input(desc->stage, src.text);
    glslang_shader_t *sh = glslang_shader_create(&in);
    if (!sh) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    glslang_shader_set_preamble(sh, preamble);
    if (!glslang_shader_preprocess(sh, &in)) {
        ob_shader_source_log(&src, v->shader.name, glslang_shader_get_info_log(sh));
        r = OB_ERR_SHADER_COMPILE;
        goto done;
    }
    v->shader.hash = variant_hash(glslang_shader_get_preprocessed_code(sh), desc->stage, preamble);

    if (c->spirv_dir) {
        path = cache_path(c, v->shader.hash);
        if (!path) {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            goto done;
        }
        size_t count = 0;
        uint32_t *words = cache_load(c, v, path, &count, &r);
        if (r != OB_OK) goto done;
        if (words) {
            r = ob_reflection_from_spirv(words, count, desc->stage, v->shader.name,
                                         &v->shader.reflection);
            if (r == OB_OK) {
                v->shader.spirv = words;
                v->shader.spirv_words = count;
                atomic_fetch_add(&c->disk_hits, 1);
                goto done;
            }
            ob_free(words);
            if (r == OB_ERR_OUT_OF_HOST_MEMORY) goto done;
            /* Well-formed but unreflectable: written by another build; rebuild it. */
            OB_LOG_W("shader", "shader cache file '%s' for '%s' cannot be reflected: deleted, "
                     "recompiling", path, v->shader.name);
            remove(path);
            atomic_fetch_add(&c->disk_rejected, 1);
        }
    }

    r = compile_spirv(&src, sh, &in, v);
    if (r != OB_OK) goto done;
    r = ob_reflection_from_spirv(v->shader.spirv, v->shader.spirv_words, desc->stage,
                                 v->shader.name, &v->shader.reflection);
    if (r != OB_OK) goto done;
    atomic_fetch_add(&c->compiled, 1);
    if (path) cache_store(v, path);
done:
    if (r != OB_OK) {
        ob_free((uint32_t *)v->shader.spirv);
        v->shader.spirv = NULL;
        v->shader.spirv_words = 0;
        if (r == OB_ERR_SHADER_COMPILE || r == OB_ERR_UNSUPPORTED)
            OB_LOG_E("shader", "cannot compile %s shader '%s'", ob_shader_stage_name(desc->stage),
                     v->shader.name);
    }
    glslang_shader_delete(sh);
    ob_free(path);
    ob_shader_source_release(&src);
    return r;
}

const ob_shader *ob_shader_get(ob_shader_compiler *c, const ob_shader_desc *desc,
                               ob_result *out_result)
{
    ob_result r = OB_OK;
    const ob_shader *result = NULL;
    char *name = NULL, *preamble = NULL;
    if (!c || !desc || !desc->path || !desc->path[0] || (unsigned)desc->stage >= OB_SHADER_STAGE_COUNT) {
        OB_LOG_E("shader", "ob_shader_get: %s", !c ? "no compiler" : !desc ? "no desc"
                 : (!desc->path || !desc->path[0]) ? "no path" : "bad stage");
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    r = ob_shader_variant_describe(desc, &name, &preamble);
    if (r != OB_OK) goto done;

    variant key = {.shader = {.name = name, .stage = desc->stage}, .has_source = desc->source != NULL};
    if (desc->source) key.source_hash = ob_hash_str(OB_HASH_SEED, desc->source);
    key.key_hash = ob_hash_u64(ob_hash_u64(ob_hash_str(OB_HASH_SEED, name), (uint64_t)desc->stage),
                               key.source_hash);

    pthread_mutex_lock(&c->lock);
    variant *v = table_find(c, &key);
    if (v) {
        v->waiters++;
        while (v->state == VARIANT_BUILDING) pthread_cond_wait(&c->finished, &c->lock);
        v->waiters--;
        if (v->state == VARIANT_READY) {
            atomic_fetch_add(&c->memory_hits, 1);
            result = &v->shader;
        } else {
            r = v->result;
            if (v->waiters == 0) variant_free(v);
        }
        pthread_mutex_unlock(&c->lock);
        goto done;
    }
    v = ob_calloc(1, sizeof *v);
    if (!v) {
        pthread_mutex_unlock(&c->lock);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    *v = key;
    name = NULL; /* owned by v now */
    v->shader.reflection.push_block = -1;
    v->state = VARIANT_BUILDING;
    table_insert(c, v);
    pthread_mutex_unlock(&c->lock);

    r = variant_build(c, desc, preamble, v);

    pthread_mutex_lock(&c->lock);
    if (r == OB_OK) {
        v->state = VARIANT_READY;
        result = &v->shader;
    } else {
        /* Not cached: the next get compiles again (the user may fix the file). */
        table_remove(c, v);
        v->state = VARIANT_FAILED;
        v->result = r;
        atomic_fetch_add(&c->failed, 1);
        if (v->waiters == 0) variant_free(v);
    }
    pthread_cond_broadcast(&c->finished);
    pthread_mutex_unlock(&c->lock);
done:
    if (r == OB_ERR_OUT_OF_HOST_MEMORY)
        OB_LOG_E("shader", "out of host memory getting shader '%s'", desc->path);
    ob_free(name);
    ob_free(preamble);
    if (out_result) *out_result = r;
    return result;
}
