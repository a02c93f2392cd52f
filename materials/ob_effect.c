#define _POSIX_C_SOURCE 200809L
#include "ob_effect.h"
#include "ob_shader_source.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

/* One pipeline per target-format pair. Entries below `count` are complete and
 * never change again, so readers scan them without a lock; the mutex only
 * serialises creators (double-checked under it). */
typedef struct effect_pipeline {
    VkFormat color, depth;
    uint32_t samples;        /* rasterizationSamples: part of the key */
    bool wireframe;          /* VK_POLYGON_MODE_LINE: part of the key */
    VkPipeline pipeline;     /* VK_NULL_HANDLE when creation failed */
    uint32_t id;
} effect_pipeline;

struct ob_effect {
    ob_effect_context *ctx;
    char name[64];
    bool compute;
    uint32_t stage_count;
    VkShaderStageFlagBits stages[2];
    VkShaderModule modules[2];
    ob_program *program;
    uint32_t local_size[3];

    /* Fixed-function state, defaults resolved. */
    VkPrimitiveTopology topology;
    bool depth_test, depth_write, blend;
    VkCompareOp depth_compare;
    VkCullModeFlags cull;
    float depth_bias_constant, depth_bias_slope;
    uint32_t stride;
    uint32_t attribute_count;                    /* only those the shader reads */
    VkVertexInputAttributeDescription attributes[OB_EFFECT_MAX_INPUTS];
    bool instanced;                              /* binding 1: the per-instance block */

    pthread_mutex_t lock;
    _Atomic uint32_t pipeline_count;
    effect_pipeline pipelines[OB_EFFECT_MAX_PIPELINES];
};

struct ob_effect_context {
    ob_device *dev;
    ob_param_registry *reg;
    ob_shader_compiler *compiler;
    VkPipelineCache cache;
    char *cache_dir;
    char *cache_path;
    _Atomic uint32_t pipelines_created;
    _Atomic uint32_t pipelines_from_cache_hint;
    _Atomic uint32_t variants_compiled;
    _Atomic uint32_t pipelines_failed;
    uint32_t cache_loaded_bytes;
};

/* ---------------------------------------------------------------- context */

static char *path_join(const char *dir, const char *file)
{
    size_t n = strlen(dir) + strlen(file) + 2;
    char *s = ob_malloc(n);
    if (s) snprintf(s, n, "%s/%s", dir, file);
    return s;
}

/* Returns the number of bytes of `data` the device will accept as initial
 * cache data, 0 (with a log line) when the header does not match. */
static size_t validate_cache_blob(const ob_effect_context *ctx, const uint8_t *data, size_t size)
{
    VkPipelineCacheHeaderVersionOne hdr;
    if (size < sizeof hdr) {
        OB_LOG_W("effect", "pipeline cache '%s' ignored: %zu bytes is shorter than its header",
                 ctx->cache_path, size);
        return 0;
    }
    memcpy(&hdr, data, sizeof hdr);
    const VkPhysicalDeviceProperties *props = ob_device_properties(ctx->dev);
    if (hdr.headerSize < sizeof hdr || hdr.headerSize > size ||
        hdr.headerVersion != VK_PIPELINE_CACHE_HEADER_VERSION_ONE) {
        OB_LOG_W("effect", "pipeline cache '%s' ignored: corrupt header (size %u, version %d)",
                 ctx->cache_path, hdr.headerSize, (int)hdr.headerVersion);
        return 0;
    }
    if (hdr.vendorID != props->vendorID || hdr.deviceID != props->deviceID ||
        memcmp(hdr.pipelineCacheUUID, props->pipelineCacheUUID, VK_UUID_SIZE) != 0) {
        OB_LOG_W("effect", "pipeline cache '%s' ignored: made by another device or driver "
                 "(vendor 0x%x device 0x%x, this is vendor 0x%x device 0x%x)",
                 ctx->cache_path, hdr.vendorID, hdr.deviceID, props->vendorID, props->deviceID);
        return 0;
    }
    return size;
}

static ob_result create_pipeline_cache(ob_effect_context *ctx)
{
    size_t size = 0;
    ob_result fr;
    char *blob = NULL;
    FILE *probe = ctx->cache_path ? fopen(ctx->cache_path, "rb") : NULL;
    if (probe) {
        fclose(probe);
        blob = ob_file_read(ctx->cache_path, &size, &fr);
        if (!blob && fr == OB_ERR_OUT_OF_HOST_MEMORY) return fr;
    }
    size_t accepted = blob ? validate_cache_blob(ctx, (const uint8_t *)blob, size) : 0;
    VkPipelineCacheCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO,
        .initialDataSize = accepted,
        .pInitialData = accepted ? blob : NULL,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreatePipelineCache(ob_device_vk(ctx->dev), &info, NULL,
                                                           &ctx->cache));
    ob_free(blob);
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    ctx->cache_loaded_bytes = (uint32_t)accepted;
    if (accepted)
        OB_LOG_I("effect", "pipeline cache loaded from '%s' (%zu bytes)", ctx->cache_path, accepted);
    return OB_OK;
}

ob_effect_context *ob_effect_context_create(ob_device *dev, ob_param_registry *reg,
                                            const char *cache_dir, ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_effect_context *ctx = NULL;
    if (!dev || !reg) {
        OB_LOG_E("effect", "effect context needs a device and a parameter registry");
        r = OB_ERR_INVALID_ARGUMENT;
        goto fail_log;
    }
    ctx = ob_calloc(1, sizeof *ctx);
    if (!ctx) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    ctx->dev = dev;
    ctx->reg = reg;
    /* The device's shader folder (ob_device_desc.shader_dir) reaches every
     * effect made through this context; NULL lets the compiler choose. */
    ctx->compiler = ob_shader_compiler_create(&(ob_shader_compiler_desc){
        .shader_dir = ob_device_shader_dir(dev), .cache_dir = cache_dir}, &r);
    if (!ctx->compiler) goto fail_free_context;
    /* One cache folder for SPIR-V and pipelines; "" means the compiler could
     * not create it, and then pipelines are not persisted either. */
    const char *dir = cache_dir ? cache_dir : ob_shader_compiler_cache_dir(ctx->compiler);
    if (dir[0]) {
        ctx->cache_dir = ob_strdup(dir);
        ctx->cache_path = ctx->cache_dir ? path_join(ctx->cache_dir, "pipelines.bin") : NULL;
        if (!ctx->cache_path) {
            r = OB_ERR_OUT_OF_HOST_MEMORY;
            goto fail_free_context;
        }
    } else {
        OB_LOG_W("effect", "no cache folder: pipelines will not be saved across runs");
    }
    r = create_pipeline_cache(ctx);
    if (r != OB_OK) goto fail_free_context;
    if (out_result) *out_result = OB_OK;
    return ctx;

fail_free_context:
    ob_shader_compiler_destroy(ctx->compiler);
    ob_free(ctx->cache_path);
    ob_free(ctx->cache_dir);
    ob_free(ctx);
fail_log:
    OB_LOG_E("effect", "effect context creation failed: %s", ob_result_name(r));
    if (out_result) *out_result = r;
    return NULL;
}

ob_result ob_effect_context_save_cache(ob_effect_context *ctx)
{
    if (!ctx || !ctx->cache) return OB_ERR_INVALID_ARGUMENT;
    if (!ctx->cache_path) return OB_ERR_IO;
    VkDevice vk = ob_device_vk(ctx->dev);
    size_t size = 0;
    if (OB_VK_CHECK(vkGetPipelineCacheData(vk, ctx->cache, &size, NULL)) != VK_SUCCESS)
        return OB_ERR_VULKAN;
    if (size == 0) return OB_OK;
    void *data = ob_malloc(size);
    if (!data) {
        OB_LOG_W("effect", "pipeline cache not saved to '%s': no memory for %zu bytes",
                 ctx->cache_path, size);
        return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    VkResult vr = vkGetPipelineCacheData(vk, ctx->cache, &size, data);
    ob_result r = OB_OK;
    if (vr != VK_SUCCESS && vr != VK_INCOMPLETE) {
        OB_VK_CHECK_AS(vr, "vkGetPipelineCacheData");
        r = ob_result_from_vk(vr);
        goto done;
    }
    r = ob_dir_make(ctx->cache_dir);
    if (r == OB_OK) r = ob_file_write(ctx->cache_path, data, size);
    if (r != OB_OK)
        OB_LOG_W("effect", "pipeline cache not saved to '%s': %s", ctx->cache_path,
                 ob_result_text(r));
    else
        OB_LOG_I("effect", "pipeline cache saved to '%s' (%zu bytes)", ctx->cache_path, size);
done:
    ob_free(data);
    return r;
}

void ob_effect_context_destroy(ob_effect_context *ctx)
{
    if (!ctx) return;
    if (ctx->cache) {
        if (ctx->cache_path) ob_effect_context_save_cache(ctx);
        vkDestroyPipelineCache(ob_device_vk(ctx->dev), ctx->cache, NULL);
    }
    ob_shader_compiler_destroy(ctx->compiler);
    ob_free(ctx->cache_path);
    ob_free(ctx->cache_dir);
    ob_free(ctx);
}

ob_effect_counters ob_effect_context_counters(const ob_effect_context *ctx)
{
    ob_effect_counters c = {0};
    if (!ctx) return c;
    c.pipelines_created = atomic_load(&ctx->pipelines_created);
    c.pipelines_from_cache_hint = atomic_load(&ctx->pipelines_from_cache_hint);
    c.variants_compiled = atomic_load(&ctx->variants_compiled);
    c.pipelines_failed = atomic_load(&ctx->pipelines_failed);
    c.cache_loaded_bytes = ctx->cache_loaded_bytes;
    return c;
}

ob_shader_compiler *ob_effect_context_compiler(ob_effect_context *ctx) { return ctx->compiler; }
ob_device *ob_effect_context_device(const ob_effect_context *ctx) { return ctx->dev; }
ob_param_registry *ob_effect_context_registry(const ob_effect_context *ctx) { return ctx->reg; }
const char *ob_effect_context_cache_path(const ob_effect_context *ctx)
{
    return ctx->cache_path ? ctx->cache_path : "";
}

ob_result ob_effect_context_check_shaders(ob_effect_context *ctx, const char *what,
                                          const char *const *paths, uint32_t count)
{
    const char *dir = ob_shader_compiler_shader_dir(ctx->compiler);
    for (uint32_t i = 0; i < count; i++) {
        ob_shader_source src;
        ob_result r = ob_shader_source_load(dir, paths[i], NULL, &src);
        if (r != OB_OK) {
            OB_LOG_E("effect", "%s: shader '%s' (folder '%s') cannot be read: %s", what, paths[i],
                     dir ? dir : "", ob_result_name(r));
            return r;
        }
        ob_shader_source_release(&src);
    }
    return OB_OK;
}

/* ----------------------------------------------------------------- effect */

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* "pbr.vert+pbr.frag SHADOWS=1": names a variant when the desc gives none. */
static void default_name(const ob_effect_desc *desc, char *out, size_t cap)
{
    size_t n = 0;
    const char *first = desc->compute ? desc->compute : desc->vertex;
    n += (size_t)snprintf(out, cap, "%s", first ? base_name(first) : "effect");
    if (desc->fragment && n < cap)
        n += (size_t)snprintf(out + n, cap - n, "+%s", base_name(desc->fragment));
    for (uint32_t i = 0; i < desc->define_count && n < cap; i++) {
        const ob_shader_define *d = &desc->defines[i];
        n += (size_t)snprintf(out + n, cap - n, " %s=%s", d->name ? d->name : "?",
                              d->value ? d->value : "1");
    }
}

static ob_result check_desc(const ob_effect_desc *desc, const char *name)
{
    if (desc->compute && (desc->vertex || desc->fragment)) {
        OB_LOG_E("effect", "effect '%s': a compute effect cannot have vertex or fragment stages", name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (!desc->compute && !desc->vertex) {
        OB_LOG_E("effect", "effect '%s': needs a vertex (or compute) shader", name);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->define_count && !desc->defines) {
        OB_LOG_E("effect", "effect '%s': define_count %u with no defines", name, desc->define_count);
        return OB_ERR_INVALID_ARGUMENT;
    }
    if (desc->layout && desc->layout->attribute_count > OB_EFFECT_MAX_ATTRIBUTES) {
        OB_LOG_E("effect", "effect '%s': %u vertex attributes (at most %u)", name,
                 desc->layout->attribute_count, OB_EFFECT_MAX_ATTRIBUTES);
        return OB_ERR_INVALID_ARGUMENT;
    }
    return OB_OK;
}

/* Keep only the layout's attributes the vertex shader reads; every input it
 * reads must be there, else the pipeline would read undefined data. */
static ob_result resolve_vertex_input(ob_effect *e, const ob_effect_desc *desc,
                                      const ob_reflection *vs)
{
    const ob_effect_vertex_input *layout = desc->layout;
    if (layout) e->stride = layout->stride;
    for (uint32_t i = 0; i < vs->vertex_input_count; i++) {
        const ob_vertex_input *in = &vs->vertex_inputs[i];
        if (in->location >= OB_INSTANCE_LOCATION &&
            in->location < OB_INSTANCE_LOCATION + OB_INSTANCE_ROWS) {
            /* The per-instance block: row k at byte 16 k of binding 1. */
            e->attributes[e->attribute_count++] = (VkVertexInputAttributeDescription){
                .location = in->location,
                .binding = 1,
                .format = VK_FORMAT_R32G32B32A32_SFLOAT,
                .offset = 16u * (in->location - OB_INSTANCE_LOCATION),
            };
            e->instanced = true;
            continue;
        }
        bool found = false;
        for (uint32_t a = 0; layout && a < layout->attribute_count; a++) {
            if (layout->attributes[a].location != in->location) continue;
            e->attributes[e->attribute_count++] = (VkVertexInputAttributeDescription){
                .location = in->location,
                .binding = 0,
                .format = layout->attributes[a].format,
                .offset = layout->attributes[a].offset,
            };
            found = true;
            break;
        }
        if (!found) {
            OB_LOG_E("effect", "effect '%s': vertex shader input '%s' (location %u) has no "
                     "attribute in the vertex layout", e->name, in->name, in->location);
            return OB_ERR_INVALID_ARGUMENT;
        }
    }
    return OB_OK;
}

static ob_result create_module(ob_effect *e, const ob_shader *sh, VkShaderModule *out)
{
    VkShaderModuleCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
        .codeSize = sh->spirv_words * sizeof(uint32_t),
        .pCode = sh->spirv,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateShaderModule(ob_device_vk(e->ctx->dev), &info, NULL, out));
    if (vr != VK_SUCCESS) {
        OB_LOG_E("effect", "effect '%s': shader module for '%s' not created", e->name, sh->name);
        return ob_result_from_vk(vr);
    }
    return OB_OK;
}

static void resolve_state(ob_effect *e, const ob_effect_desc *desc)
{
    e->topology = desc->points ? VK_PRIMITIVE_TOPOLOGY_POINT_LIST
                  : desc->topology ? desc->topology
                                   : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    e->depth_test = desc->depth_test;
    e->depth_write = desc->depth_write;
    e->depth_compare = desc->depth_compare ? desc->depth_compare : VK_COMPARE_OP_GREATER_OR_EQUAL;
    e->cull = desc->cull;
    e->blend = desc->blend;
    e->depth_bias_constant = desc->depth_bias_constant;
    e->depth_bias_slope = desc->depth_bias_slope;
}

typedef struct stage_source {
    const char *path;
    ob_shader_stage stage;
} stage_source;

ob_effect *ob_effect_create(ob_effect_context *ctx, const ob_effect_desc *desc,
                            ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_effect *e = NULL;
    char name[64];
    if (!ctx || !desc) {
        OB_LOG_E("effect", "ob_effect_create: missing context or desc");
        if (out_result) *out_result = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    if (desc->name) snprintf(name, sizeof name, "%s", desc->name);
    else default_name(desc, name, sizeof name);
    r = check_desc(desc, name);
    if (r != OB_OK) goto fail_log;

    e = ob_calloc(1, sizeof *e);
    if (!e) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }
    e->ctx = ctx;
    memcpy(e->name, name, sizeof name);
    e->compute = desc->compute != NULL;
    e->local_size[0] = e->local_size[1] = e->local_size[2] = 1;
    resolve_state(e, desc);
    if (pthread_mutex_init(&e->lock, NULL) != 0) {
        ob_free(e);
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_log;
    }

    stage_source wanted[2];
    uint32_t n = 0;
    if (e->compute) {
        wanted[n++] = (stage_source){desc->compute, OB_SHADER_COMPUTE};
    } else {
        wanted[n++] = (stage_source){desc->vertex, OB_SHADER_VERTEX};
        if (desc->fragment) wanted[n++] = (stage_source){desc->fragment, OB_SHADER_FRAGMENT};
    }
    const ob_shader *shaders[2] = {NULL, NULL};
    for (uint32_t i = 0; i < n; i++) {
        ob_shader_desc sd = {
            .path = wanted[i].path,
            .stage = wanted[i].stage,
            .define_count = desc->define_count,
            .defines = desc->defines,
        };
        shaders[i] = ob_shader_get(ctx->compiler, &sd, &r);
        if (!shaders[i]) {
            OB_LOG_E("effect", "effect '%s': %s shader '%s' failed: %s", e->name,
                     ob_shader_stage_name(wanted[i].stage), wanted[i].path, ob_result_text(r));
            goto fail_destroy_effect;
        }
    }

    const ob_reflection *refls[2];
    for (uint32_t i = 0; i < n; i++) refls[i] = &shaders[i]->reflection;
    ob_reflection merged;
    r = ob_reflection_merge(refls, n, &merged);
    if (r != OB_OK) {
        OB_LOG_E("effect", "effect '%s': the stages' interfaces do not merge: %s", e->name,
                 ob_result_text(r));
        goto fail_destroy_effect;
    }
    if (e->compute) memcpy(e->local_size, shaders[0]->reflection.local_size, sizeof e->local_size);
    else r = resolve_vertex_input(e, desc, &shaders[0]->reflection);
    if (r == OB_OK) {
        e->program = ob_program_create(ctx->dev, ctx->reg, &merged, e->compute, e->name, &r);
        if (!e->program)
            OB_LOG_E("effect", "effect '%s': program not created: %s", e->name, ob_result_text(r));
        else e->program->instanced = e->instanced;
    }
    ob_reflection_release(&merged);
    if (r != OB_OK) goto fail_destroy_effect;

    for (uint32_t i = 0; i < n; i++) {
        e->stages[i] = ob_shader_stage_vk(wanted[i].stage);
        r = create_module(e, shaders[i], &e->modules[i]);
        if (r != OB_OK) goto fail_destroy_effect;
        e->stage_count = i + 1;
    }
    atomic_fetch_add(&ctx->variants_compiled, 1);
    if (out_result) *out_result = OB_OK;
    return e;

fail_destroy_effect:
    ob_effect_destroy(e);
fail_log:
    OB_LOG_E("effect", "effect '%s' not created: %s", name, ob_result_name(r));
    if (out_result) *out_result = r;
    return NULL;
}

static bool has_stencil(VkFormat f)
{
    return f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT ||
           f == VK_FORMAT_D16_UNORM_S8_UINT || f == VK_FORMAT_S8_UINT;
}

static VkPipelineShaderStageCreateInfo stage_info(const ob_effect *e, uint32_t i)
{
    return (VkPipelineShaderStageCreateInfo){
        .sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
        .stage = e->stages[i],
        .module = e->modules[i],
        .pName = "main",
    };
}

static VkResult create_graphics(ob_effect *e, VkFormat color, VkFormat depth, uint32_t samples,
                                bool wireframe, const void *feedback, VkPipeline *out)
{
    VkPipelineShaderStageCreateInfo stages[2];
    for (uint32_t i = 0; i < e->stage_count; i++) stages[i] = stage_info(e, i);
    VkVertexInputBindingDescription bindings[2] = {
        {0, e->stride, VK_VERTEX_INPUT_RATE_VERTEX},
        {1, OB_INSTANCE_STRIDE, VK_VERTEX_INPUT_RATE_INSTANCE},
    };
    VkPipelineVertexInputStateCreateInfo vi = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
        .vertexBindingDescriptionCount = e->instanced ? 2u : e->attribute_count ? 1u : 0u,
        .pVertexBindingDescriptions = bindings,
        .vertexAttributeDescriptionCount = e->attribute_count,
        .pVertexAttributeDescriptions = e->attributes,
    };
    VkPipelineInputAssemblyStateCreateInfo ia = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = e->topology,
    };
    VkPipelineViewportStateCreateInfo vp = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1,
        .scissorCount = 1,
    };
    bool bias = e->depth_bias_constant != 0.0f || e->depth_bias_slope != 0.0f;
    VkPipelineRasterizationStateCreateInfo rs = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .polygonMode = wireframe ? VK_POLYGON_MODE_LINE : VK_POLYGON_MODE_FILL,
        .cullMode = e->cull,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE,
        .depthBiasEnable = bias,
        .depthBiasConstantFactor = e->depth_bias_constant,
        .depthBiasSlopeFactor = e->depth_bias_slope,
        .lineWidth = 1.0f,
    };
    VkPipelineMultisampleStateCreateInfo ms = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = (VkSampleCountFlagBits)samples,
    };
    bool has_depth = depth != VK_FORMAT_UNDEFINED;
    VkPipelineDepthStencilStateCreateInfo ds = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = has_depth && e->depth_test,
        .depthWriteEnable = has_depth && e->depth_write,
        .depthCompareOp = e->depth_compare,
    };
    VkPipelineColorBlendAttachmentState blend = {
        .blendEnable = e->blend,
        .srcColorBlendFactor = VK_BLEND_FACTOR_ONE,
        .dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
        .colorBlendOp = VK_BLEND_OP_ADD,
        .srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE,
        .dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
        .alphaBlendOp = VK_BLEND_OP_ADD,
        .colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                          VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT,
    };
    bool has_color = color != VK_FORMAT_UNDEFINED;
    VkPipelineColorBlendStateCreateInfo cb = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = has_color ? 1u : 0u,
        .pAttachments = &blend,
    };
    /* The front face is the pipeline manager's per draw: an entity whose
     * world transform mirrors (negative determinant) turns its triangles
     * clockwise (core dynamic state in Vulkan 1.3). */
    VkDynamicState dyn_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                   VK_DYNAMIC_STATE_FRONT_FACE};
    VkPipelineDynamicStateCreateInfo dyn = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 3,
        .pDynamicStates = dyn_states,
    };
    VkPipelineRenderingCreateInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .pNext = feedback,
        .colorAttachmentCount = has_color ? 1u : 0u,
        .pColorAttachmentFormats = &color,
        .depthAttachmentFormat = depth,
        .stencilAttachmentFormat = has_stencil(depth) ? depth : VK_FORMAT_UNDEFINED,
    };
    VkGraphicsPipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO,
        .pNext = &rendering,
        .stageCount = e->stage_count,
        .pStages = stages,
        .pVertexInputState = &vi,
        .pInputAssemblyState = &ia,
        .pViewportState = &vp,
        .pRasterizationState = &rs,
        .pMultisampleState = &ms,
        .pDepthStencilState = &ds,
        .pColorBlendState = &cb,
        .pDynamicState = &dyn,
        .layout = e->program->layout,
    };
    return OB_VK_CREATE(vkCreateGraphicsPipelines(ob_device_vk(e->ctx->dev), e->ctx->cache, 1,
                                                  &info, NULL, out));
}

static VkResult create_compute(ob_effect *e, const void *feedback, VkPipeline *out)
{
    VkComputePipelineCreateInfo info = {
        .sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO,
        .pNext = feedback,
        .stage = stage_info(e, 0),
        .layout = e->program->layout,
    };
    return OB_VK_CREATE(vkCreateComputePipelines(ob_device_vk(e->ctx->dev), e->ctx->cache, 1,
                                                 &info, NULL, out));
}

static const effect_pipeline *find_pipeline(const ob_effect *e, uint32_t count, VkFormat color,
                                            VkFormat depth, uint32_t samples, bool wireframe)
{
    for (uint32_t i = 0; i < count; i++)
        if (e->pipelines[i].color == color && e->pipelines[i].depth == depth &&
            e->pipelines[i].samples == samples && e->pipelines[i].wireframe == wireframe)
            return &e->pipelines[i];
    return NULL;
}

static uint32_t pipeline_id(const ob_effect *e, VkFormat color, VkFormat depth, uint32_t samples,
                            bool wireframe)
{
    uint64_t h = ob_hash_str(OB_HASH_SEED, e->name);
    h = ob_hash_u64(h, ((uint64_t)(uint32_t)color << 32) | (uint32_t)depth);
    /* Single-sampled filled pipelines keep the ids they had before sample
     * counts and polygon modes were part of the key (command hashes stay
     * comparable). */
    if (samples > 1) h = ob_hash_u64(h, samples);
    if (wireframe) h = ob_hash_str(h, "wireframe");
    uint32_t id = (uint32_t)(h ^ (h >> 32));
    return id ? id : 1u;
}

/* Called with e->lock held and the pair known to be missing. */
static const effect_pipeline *create_entry(ob_effect *e, uint32_t count, VkFormat color,
                                           VkFormat depth, uint32_t samples, bool wireframe)
{
    if (count >= OB_EFFECT_MAX_PIPELINES) {
        OB_LOG_E("effect", "effect '%s': more than %u target format pairs; no pipeline for "
                 "colour format %d, depth format %d", e->name, OB_EFFECT_MAX_PIPELINES,
                 (int)color, (int)depth);
        return NULL;
    }
    VkPipelineCreationFeedback whole = {0};
    VkPipelineCreationFeedback per_stage[2] = {{0}};
    VkPipelineCreationFeedbackCreateInfo feedback = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO,
        .pPipelineCreationFeedback = &whole,
        .pipelineStageCreationFeedbackCount = e->stage_count,
        .pPipelineStageCreationFeedbacks = per_stage,
    };
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkResult vr = e->compute ? create_compute(e, &feedback, &pipeline)
                             : create_graphics(e, color, depth, samples, wireframe, &feedback,
                                               &pipeline);
    effect_pipeline *entry = &e->pipelines[count];
    *entry = (effect_pipeline){color, depth, samples, wireframe, VK_NULL_HANDLE,
                               pipeline_id(e, color, depth, samples, wireframe)};
    if (OB_VK_CHECK_AS(vr, e->compute ? "vkCreateComputePipelines" : "vkCreateGraphicsPipelines") !=
        VK_SUCCESS) {
        ob_device_note_result(e->ctx->dev, vr);
        atomic_fetch_add(&e->ctx->pipelines_failed, 1);
        bool transient = vr == VK_ERROR_OUT_OF_HOST_MEMORY || vr == VK_ERROR_OUT_OF_DEVICE_MEMORY;
        OB_LOG_E("effect", "effect '%s': pipeline for colour format %d, depth format %d, %u "
                 "sample(s) not created (%s); its draws are skipped%s", e->name, (int)color,
                 (int)depth, samples, ob_vk_result_name(vr),
                 transient ? " until a later try succeeds" : "");
        /* Memory may come back: leave the pair unpublished so the next
         * request tries again (a frame that failed must not stay broken). */
        if (transient) return NULL;
    } else {
        entry->pipeline = pipeline;
        atomic_fetch_add(&e->ctx->pipelines_created, 1);
        if ((whole.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT) &&
            (whole.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT))
            atomic_fetch_add(&e->ctx->pipelines_from_cache_hint, 1);
        char label[96];
        snprintf(label, sizeof label, "%s/%d/%d/%ux%s", e->name, (int)color, (int)depth, samples,
                 wireframe ? "/wireframe" : "");
        ob_device_set_name(e->ctx->dev, VK_OBJECT_TYPE_PIPELINE, (uint64_t)pipeline, label);
    }
    /* Failed pairs are published too, so later draws fail fast and quietly. */
    atomic_store_explicit(&e->pipeline_count, count + 1, memory_order_release);
    return entry;
}

VkPipeline ob_effect_pipeline(ob_effect *e, VkFormat color, VkFormat depth,
                              uint32_t *out_pipeline_id)
{
    return ob_effect_pipeline_for(e, &(ob_effect_targets){color, depth, 1, false}, out_pipeline_id);
}

VkPipeline ob_effect_pipeline_for(ob_effect *e, const ob_effect_targets *targets,
                                  uint32_t *out_pipeline_id)
{
    if (out_pipeline_id) *out_pipeline_id = 0;
    if (!e || !targets) return VK_NULL_HANDLE;
    VkFormat color = targets->color, depth = targets->depth;
    uint32_t samples = targets->samples > 1 ? targets->samples : 1;
    /* Edges of triangles only: points and lines draw as they are, and a
     * device without fillModeNonSolid (ob_view_set_wireframe refuses it)
     * never gets an invalid pipeline. */
    bool wireframe = targets->wireframe && !e->compute &&
                     e->topology >= VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST &&
                     e->topology <= VK_PRIMITIVE_TOPOLOGY_TRIANGLE_FAN &&
                     ob_device_get_caps(e->ctx->dev)->fill_mode_non_solid;
    if (e->compute) {
        color = depth = VK_FORMAT_UNDEFINED;
        samples = 1;
    }
    uint32_t count = atomic_load_explicit(&e->pipeline_count, memory_order_acquire);
    const effect_pipeline *p = find_pipeline(e, count, color, depth, samples, wireframe);
    if (!p) {
        pthread_mutex_lock(&e->lock);
        count = atomic_load_explicit(&e->pipeline_count, memory_order_acquire);
        p = find_pipeline(e, count, color, depth, samples, wireframe);
        if (!p) p = create_entry(e, count, color, depth, samples, wireframe);
        pthread_mutex_unlock(&e->lock);
        if (!p) return VK_NULL_HANDLE;
    }
    if (p->pipeline && out_pipeline_id) *out_pipeline_id = p->id;
    return p->pipeline;
}

uint32_t ob_effect_pipeline_count(const ob_effect *e)
{
    if (!e) return 0;
    uint32_t count = atomic_load_explicit(&e->pipeline_count, memory_order_acquire);
    uint32_t live = 0;
    for (uint32_t i = 0; i < count; i++) live += e->pipelines[i].pipeline != VK_NULL_HANDLE;
    return live;
}

const ob_program *ob_effect_program(const ob_effect *e) { return e ? e->program : NULL; }
const char *ob_effect_name(const ob_effect *e) { return e ? e->name : ""; }
bool ob_effect_is_compute(const ob_effect *e) { return e && e->compute; }

void ob_effect_local_size(const ob_effect *e, uint32_t out_size[3])
{
    for (int i = 0; i < 3; i++) out_size[i] = e ? e->local_size[i] : 1u;
}

void ob_effect_destroy(ob_effect *e)
{
    if (!e) return;
    VkDevice vk = ob_device_vk(e->ctx->dev);
    uint32_t count = atomic_load(&e->pipeline_count);
    for (uint32_t i = 0; i < count; i++)
        if (e->pipelines[i].pipeline) vkDestroyPipeline(vk, e->pipelines[i].pipeline, NULL);
    for (uint32_t i = 0; i < 2; i++)
        if (e->modules[i]) vkDestroyShaderModule(vk, e->modules[i], NULL);
    ob_program_destroy(e->ctx->dev, e->program);
    pthread_mutex_destroy(&e->lock);
    ob_free(e);
}
