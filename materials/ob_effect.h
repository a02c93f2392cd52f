/* ob_effect.h — render effects: shader variant + fixed-function state + lazily
 * created pipelines (Hieroglyph 3's RenderEffectDX11).
 *
 * An effect is one shader variant (GLSL files + defines, compiled through the
 * shader compiler, which caches SPIR-V in memory and on disk), its merged
 * reflection turned into an ob_program (binding plan), its fixed-function
 * state and vertex input. Its VkPipeline depends on the target formats, so it
 * is created on first use per (colour format, depth format) pair and cached
 * in the effect. All pipelines go through the context's VkPipelineCache,
 * which is loaded from <cache_dir>/pipelines.bin at start-up and saved back
 * when the context is destroyed.
 *
 * Conventions the state defaults encode: reversed-Z (depth compare defaults
 * to GREATER_OR_EQUAL, clear depth 0), counter-clockwise front faces, dynamic
 * viewport and scissor, dynamic rendering (no render passes), premultiplied
 * alpha blending (ONE, ONE_MINUS_SRC_ALPHA) when `blend` is set.
 *
 * Lifecycle: context_create → effect_create* → (frames: effect_pipeline) →
 * effect_destroy* (after the device no longer uses them) → context_destroy.
 *
 * Thread rule: context and effect creation/destruction are [render thread]
 * (program creation may register parameters). ob_effect_pipeline is
 * [any thread]: lookups of existing pipelines take no lock; creating a
 * missing one takes the effect's mutex. ob_effect_program and the accessors
 * are [any thread]. Counters are atomics.
 */
#ifndef OB_EFFECT_H
#define OB_EFFECT_H

#include "ob_device.h"
#include "ob_params.h"
#include "ob_program.h"
#include "ob_shader.h"

#ifdef __cplusplus
extern "C" {
#endif

#define OB_EFFECT_MAX_ATTRIBUTES 8
/* Vertex inputs of the pipeline: the layout's, and the per-instance block's
 * three rows (ob_program.instanced, OB_INSTANCE_ROWS). */
#define OB_EFFECT_MAX_INPUTS (OB_EFFECT_MAX_ATTRIBUTES + 3u)
#define OB_EFFECT_MAX_PIPELINES 16

/* Vertex input of an effect: one interleaved vertex buffer (binding 0).
 * Mirrors geometry's ob_vertex_layout (materials must not include geometry
 * headers); the views layer converts one into the other. */
typedef struct ob_effect_vertex_input {
    uint32_t stride;
    uint32_t attribute_count;
    struct {
        uint32_t location;
        VkFormat format;
        uint32_t offset;
    } attributes[OB_EFFECT_MAX_ATTRIBUTES];
} ob_effect_vertex_input;

typedef struct ob_effect_context ob_effect_context;
typedef struct ob_effect ob_effect;

typedef struct ob_effect_desc {
    const char *name;                  /* NULL → the vertex (or compute) path; copied */
    /* Shader paths, relative to materials/shaders (or absolute). A graphics
     * effect needs `vertex`; `fragment` may be NULL (depth-only). A compute
     * effect sets only `compute`. */
    const char *vertex, *fragment, *compute;
    uint32_t define_count;
    const ob_shader_define *defines;   /* applied to every stage; copied */
    /* NULL → no vertex input (vertex pulling, full-screen triangle). Every
     * input the vertex shader declares must have an attribute here; attributes
     * the shader does not read are left out of the pipeline. Copied. */
    const ob_effect_vertex_input *layout;
    /* 0 → TRIANGLE_LIST (Vulkan's 0 is POINT_LIST: ask for it with `points`). */
    VkPrimitiveTopology topology;
    bool points;
    /* Fixed-function state. */
    bool depth_test, depth_write;
    VkCompareOp depth_compare;         /* 0 → GREATER_OR_EQUAL (reversed-Z) */
    VkCullModeFlags cull;              /* 0 = none; front faces are CCW */
    bool blend;                        /* premultiplied alpha: ONE, ONE_MINUS_SRC_ALPHA */
    /* Depth bias (shadow maps). With reversed-Z, pushing a caster away from
     * the light means negative values. Zero both → bias disabled. */
    float depth_bias_constant, depth_bias_slope;
} ob_effect_desc;

/* ---------------------------------------------------------------- context */

typedef struct ob_effect_counters {
    uint32_t pipelines_created;         /* VkPipelines created (all effects) */
    uint32_t pipelines_from_cache_hint; /* of those, reported as pipeline-cache hits by
                                           VK_EXT_pipeline_creation_feedback (core 1.3) */
    uint32_t variants_compiled;         /* effects created (one per shader variant) */
    uint32_t pipelines_failed;          /* creations that failed (draws then skipped) */
    uint32_t cache_loaded_bytes;        /* bytes of pipelines.bin accepted at create, 0 = none */
} ob_effect_counters;

/* Creates the shared pieces: a shader compiler (shaders read from the
 * device's folder, ob_device_desc.shader_dir, else the compiler's default;
 * SPIR-V cached under cache_dir), and the VkPipelineCache, seeded from <cache_dir>/pipelines.bin
 * when the file's VkPipelineCacheHeaderVersionOne matches this device (vendor,
 * device, pipelineCacheUUID); a missing file is normal, a mismatched or
 * corrupt one is ignored with a log line. cache_dir NULL → the shader
 * compiler's default ($OB_CACHE_DIR, else $XDG_CACHE_HOME/obelisk, else
 * ~/.cache/obelisk); if that folder cannot be created, pipelines are simply
 * not persisted. dev and reg must outlive the context.
 * Failure: NULL, *out_result set, logged. [render thread] */
ob_effect_context *ob_effect_context_create(ob_device *dev, ob_param_registry *reg,
                                            const char *cache_dir, ob_result *out_result);
/* Saves the pipeline cache to <cache_dir>/pipelines.bin (a failure is logged,
 * not fatal), then destroys. Effects must be destroyed first. NULL ok.
 * [render thread] */
void ob_effect_context_destroy(ob_effect_context *ctx);
/* Writes the pipeline cache now (also done by destroy). [render thread] */
ob_result ob_effect_context_save_cache(ob_effect_context *ctx);

ob_effect_counters ob_effect_context_counters(const ob_effect_context *ctx);
ob_shader_compiler *ob_effect_context_compiler(ob_effect_context *ctx);
ob_device *ob_effect_context_device(const ob_effect_context *ctx);
ob_param_registry *ob_effect_context_registry(const ob_effect_context *ctx);
/* Path of pipelines.bin (owned by the context). */
const char *ob_effect_context_cache_path(const ob_effect_context *ctx);
/* Reads each of `paths` (relative to the compiler's shader folder unless
 * absolute) with its includes, as compiling would, and keeps nothing: what
 * creates effects lazily calls it at its own creation, so that a shader that
 * cannot be read fails there, where the caller sees it, instead of every
 * frame later. `what` names the caller in the log line. Failure: the first
 * error (OB_ERR_IO for a missing or unreadable file,
 * OB_ERR_OUT_OF_HOST_MEMORY), logged with the path. [render thread] */
ob_result ob_effect_context_check_shaders(ob_effect_context *ctx, const char *what,
                                          const char *const *paths, uint32_t count);

/* ----------------------------------------------------------------- effect */

/* Compiles the variant's stages (cached by the compiler), merges their
 * reflection, checks the vertex input against the layout, creates the shader
 * modules and the program. Failure: NULL with *out_result
 * (OB_ERR_SHADER_COMPILE with the file and line logged by the compiler,
 * OB_ERR_INVALID_ARGUMENT for a bad desc or a vertex input the layout lacks,
 * OB_ERR_UNSUPPORTED for a binding plan the program refuses), logged with
 * the effect's name; nothing leaks. [render thread] */
ob_effect *ob_effect_create(ob_effect_context *ctx, const ob_effect_desc *desc,
                            ob_result *out_result);

/* The pipeline for the given target formats (VK_FORMAT_UNDEFINED = no
 * colour / no depth attachment; ignored for compute effects), created on
 * first use and cached. *out_pipeline_id (optional) receives a stable id
 * (hash of the effect name and formats) for command hashes. On failure
 * returns VK_NULL_HANDLE after logging once with the effect's name; later
 * calls for the same formats fail fast without logging again — except after
 * an out-of-memory result, which is transient: the next call tries again.
 * [any thread] */
VkPipeline ob_effect_pipeline(ob_effect *e, VkFormat color, VkFormat depth,
                              uint32_t *out_pipeline_id);

/* What a pipeline is made for: the target formats (VK_FORMAT_UNDEFINED =
 * none), the rasterization sample count (0 or 1 → one sample) and whether
 * triangles are drawn as their edges (a wireframe view, ob_view.wireframe;
 * ignored for point and line topologies, compute effects and devices
 * without fillModeNonSolid, which ob_view_set_wireframe refuses). */
typedef struct ob_effect_targets {
    VkFormat color, depth;
    uint32_t samples;
    bool wireframe;
} ob_effect_targets;

/* ob_effect_pipeline for any targets, multisampled and wireframe ones
 * included: the sample count and the polygon mode are part of the key and
 * of the id (single-sampled filled pipelines have the ids
 * ob_effect_pipeline gives them). Same failure rule.
 * [any thread] */
VkPipeline ob_effect_pipeline_for(ob_effect *e, const ob_effect_targets *targets,
                                  uint32_t *out_pipeline_id);

/* Number of pipelines this effect holds. [any thread] */
uint32_t ob_effect_pipeline_count(const ob_effect *e);
const ob_program *ob_effect_program(const ob_effect *e);
const char *ob_effect_name(const ob_effect *e);
bool ob_effect_is_compute(const ob_effect *e);
/* Local size of a compute effect (1,1,1 for graphics). */
void ob_effect_local_size(const ob_effect *e, uint32_t out_size[3]);

/* Destroys pipelines, modules and program now: the caller guarantees that no
 * pending frame uses them (wait idle, or defer). NULL ok. [render thread] */
void ob_effect_destroy(ob_effect *e);

#ifdef __cplusplus
}
#endif
#endif /* OB_EFFECT_H */
