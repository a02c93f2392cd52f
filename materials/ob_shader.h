/* ob_shader.h — run-time GLSL → SPIR-V compilation of shader variants, with
 * an in-memory and on-disk cache and SPIR-V reflection.
 *
 * A variant is (file or in-memory source, stage, defines). GLSL is compiled
 * with glslang as #version 450 for Vulkan 1.3 (SPIR-V 1.6); `#include "x"`
 * and `#include <x>` are resolved by Obelisk (the including file's folder
 * first, then shader_dir; `#pragma once` is honoured; an include of a file
 * already being included is skipped, so guarded include cycles work). A
 * missing include is reported only if the preprocessor reaches it, so an
 * #include inside an inactive #if branch may name a file that does not exist.
 *
 * Cache: variants live in memory until the compiler is destroyed, keyed by
 * the request (path or source text, stage, defines: a file edited on disk is
 * picked up by a new compiler, not by an existing one). On disk,
 * <cache_dir>/spirv/<hash>.spv is keyed by a hash of the preprocessed source
 * (so edits to included files invalidate it), the stage, the defines and the
 * compiler version. A corrupt cache file is logged, deleted and rebuilt.
 * Reflection is always recomputed from SPIR-V (spirv-cross).
 *
 * Lifecycle: ob_shader_compiler_create → ob_shader_get (any number of times,
 * from any thread) → ob_shader_compiler_destroy, which frees every variant.
 *
 * Thread rule: create/destroy [one thread, no get in flight]. ob_shader_get
 * and ob_shader_compiler_get_stats are [any thread]: one mutex guards the
 * variant table and compiles run outside it, so different variants compile
 * in parallel and one variant requested by several threads compiles once.
 * Returned ob_shader objects are immutable. The reflection helpers touch
 * only their arguments and are [any thread].
 *
 * glslang's process-wide initialisation runs once (pthread_once) on the first
 * compiler creation and is never finalised: finalising could race with a
 * compile on another thread, and glslang keeps nothing that leak checkers see.
 */
#ifndef OB_SHADER_H
#define OB_SHADER_H

#include "ob_core.h"
#include "ob_reflect.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ob_shader_compiler ob_shader_compiler;

typedef enum ob_shader_stage {
    OB_SHADER_VERTEX = 0,
    OB_SHADER_FRAGMENT,
    OB_SHADER_COMPUTE,
    OB_SHADER_STAGE_COUNT
} ob_shader_stage;

typedef struct ob_shader_define {
    const char *name;   /* an identifier; each name at most once per variant */
    const char *value;  /* NULL → "1"; one line (no newline, no trailing '\') */
} ob_shader_define;

typedef struct ob_shader_compiler_desc {
    /* NULL → $OB_SHADER_DIR → share/obelisk/shaders beside the binary holding
     * the engine: <libobelisk.so's folder>/../share/obelisk/shaders installed,
     * build/share/obelisk/shaders in the build tree (then the configured
     * install folder, for static programs outside the prefix). The effect
     * context passes ob_device_desc.shader_dir here, so one field points a
     * whole renderer (ob_renderer_desc.device, ob_stack_desc.renderer.device)
     * at a folder. */
    const char *shader_dir;
    /* NULL → $OB_CACHE_DIR → $XDG_CACHE_HOME/obelisk → $HOME/.cache/obelisk.
     * Created if missing; SPIR-V goes in <cache_dir>/spirv/. If it cannot be
     * created the compiler logs a warning and keeps a memory cache only. */
    const char *cache_dir;
    bool no_disk_cache;
} ob_shader_compiler_desc;

typedef struct ob_shader_desc {
    /* A file, relative to shader_dir or absolute. With `source` set it is only
     * the name used in messages and the folder for relative includes. */
    const char *path;
    const char *source;   /* optional in-memory GLSL */
    ob_shader_stage stage;
    uint32_t define_count;
    const ob_shader_define *defines;
} ob_shader_desc;

/* Immutable once returned; owned by its compiler until the compiler is destroyed. */
typedef struct ob_shader {
    const char *name;          /* path + defines sorted by name: "pbr.frag [SHADOWS=1]" */
    ob_shader_stage stage;
    uint64_t hash;             /* preprocessed source + stage + defines + compiler version */
    const uint32_t *spirv;
    size_t spirv_words;
    ob_reflection reflection;  /* this stage only; see ob_reflection_merge */
} ob_shader;

typedef struct ob_shader_compiler_stats {
    uint32_t compiled;       /* variants compiled by glslang */
    uint32_t memory_hits;    /* gets answered from memory (including waits for another thread's compile) */
    uint32_t disk_hits;      /* variants loaded from the disk cache */
    uint32_t disk_rejected;  /* corrupt or stale cache files deleted and rebuilt */
    uint32_t failed;         /* compiles that failed (not cached: the next get retries) */
} ob_shader_compiler_stats;

/* Creates a compiler. desc may be NULL (all defaults). Failure: NULL with
 * *out_result = OB_ERR_OUT_OF_HOST_MEMORY, or OB_ERR_UNSUPPORTED if glslang
 * cannot initialise. [one thread] */
ob_shader_compiler *ob_shader_compiler_create(const ob_shader_compiler_desc *desc,
                                              ob_result *out_result);
/* Frees the compiler and every ob_shader it returned. NULL is a no-op.
 * [one thread; no ob_shader_get in flight] */
void ob_shader_compiler_destroy(ob_shader_compiler *c);

/* Returns the compiled variant: from memory, else from the disk cache, else
 * compiles it (glslang) and stores it in both. [any thread]
 * Failure: NULL with *out_result set and every problem logged (module "shader"):
 *   OB_ERR_INVALID_ARGUMENT  no path, bad stage, a bad or duplicate define name;
 *   OB_ERR_IO                the shader file cannot be read (names the path);
 *   OB_ERR_SHADER_COMPILE    one line "<file>:<line>: <glslang text>" per error,
 *                            naming the included file when the error is there;
 *                            also a missing include (names the include and the
 *                            folders searched) and reflection failures;
 *   OB_ERR_UNSUPPORTED       an interface reflection cannot describe (texel
 *                            buffers, subpass inputs, 64-bit vertex inputs);
 *   OB_ERR_OUT_OF_HOST_MEMORY.
 * Failures are not cached; threads that waited for a failing compile get the
 * same result without compiling again. */
const ob_shader *ob_shader_get(ob_shader_compiler *c, const ob_shader_desc *desc,
                               ob_result *out_result);

/* A snapshot of the counters. [any thread] */
ob_shader_compiler_stats ob_shader_compiler_get_stats(const ob_shader_compiler *c);

/* The folders the compiler resolved at creation (never NULL; cache_dir is ""
 * when the disk cache is off). Owned by the compiler. [any thread] */
const char *ob_shader_compiler_shader_dir(const ob_shader_compiler *c);
const char *ob_shader_compiler_cache_dir(const ob_shader_compiler *c);

/* ------------------------------------------------------------ reflection */

/* Reflects one stage's SPIR-V (spirv-cross): uniform and storage blocks with
 * their members, the push-constant block, images and samplers, vertex inputs
 * (vertex stage), the local size (compute stage). Bindings are sorted by
 * (set, binding) and carry the stage's flag. A runtime array (last member of
 * a storage block) has array_len 0, array_stride > 0 and size 0. name is used
 * in messages only. out is owned by the caller: ob_reflection_release.
 * Failure: *out zeroed (push_block -1), OB_ERR_SHADER_COMPILE (malformed
 * SPIR-V), OB_ERR_UNSUPPORTED, OB_ERR_OUT_OF_HOST_MEMORY. [any thread] */
ob_result ob_reflection_from_spirv(const uint32_t *spirv, size_t words, ob_shader_stage stage,
                                   const char *name, ob_reflection *out);

/* Merges the per-stage reflections of one pipeline: bindings are matched by
 * (set, binding) and their stage flags OR-ed (a block used by two stages
 * appears once); push-constant blocks are merged member by member (by name);
 * vertex inputs and the local size are taken from the stage that has them.
 * Conflicting declarations (at one set/binding, or one push-constant member)
 * → OB_ERR_TYPE_MISMATCH, logged naming both. out is owned by the caller:
 * ob_reflection_release. On failure *out is left empty. [any thread] */
ob_result ob_reflection_merge(const ob_reflection *const *stages, uint32_t count,
                              ob_reflection *out);
/* Frees what ob_reflection_merge / ob_reflection_from_spirv allocated and
 * empties *refl. NULL or an empty reflection is a no-op. */
void ob_reflection_release(ob_reflection *refl);

/* Lookups by name (block type name / binding name); NULL when absent. */
const ob_block_layout *ob_reflection_find_block(const ob_reflection *refl, const char *name);
const ob_binding *ob_reflection_find_binding(const ob_reflection *refl, const char *name);
/* The member of block by name, NULL when absent. */
const ob_block_member *ob_block_find_member(const ob_block_layout *block, const char *name);

/* Vulkan stage flag of a stage (VK_SHADER_STAGE_VERTEX_BIT, ...). */
VkShaderStageFlagBits ob_shader_stage_vk(ob_shader_stage stage);
/* "vertex", "fragment", "compute" ("unknown" otherwise). */
const char *ob_shader_stage_name(ob_shader_stage stage);

#ifdef __cplusplus
}
#endif
#endif /* OB_SHADER_H */
