/* ob_program.h — the binding plan of one shader program, derived from reflection.
 *
 * A program turns a merged ob_reflection into what the pipeline manager needs
 * to bind a draw's inputs with no string lookups:
 *   set 0: every uniform block, as UNIFORM_BUFFER_DYNAMIC, packed from the
 *          parameter system into the recording thread's uniform ring and bound
 *          through dynamic offsets;
 *   set 1: images, samplers and storage buffers, bound with push descriptors
 *          (VK_KHR_push_descriptor) from resource parameters of the same name;
 *   push constants: one block, packed from parameters like a uniform block.
 * Every block member, image, sampler and buffer is matched to the parameter of
 * the same name; a name with no parameter yet is registered with the type the
 * shader declares, so a shader can add `vec4 Tint;` and the application can
 * set "Tint" with no C change. A combined image sampler named "X" takes its
 * image from parameter "X" and its sampler from parameter "XSampler".
 *
 * Lifecycle: create (render thread, not while recording: it may register
 * parameters) → used by any number of pipeline managers → destroy (deferred
 * by the caller until no frame uses it; the effect owns its programs).
 * Thread rule: immutable after creation; [any thread] reads.
 */
#ifndef OB_PROGRAM_H
#define OB_PROGRAM_H

#include "ob_device.h"
#include "ob_params.h"
#include "ob_reflect.h"

#define OB_PROGRAM_MAX_UBOS 8
/* The PBR kind with every texture (8), the shadow map, the env map and the
 * local lights' shadow array: 11. */
#define OB_PROGRAM_MAX_RESOURCES 12
/* The largest push-constant block a program may declare: the pipeline
 * manager packs and compares push data in buffers of this size (lavapipe's
 * limit; Vulkan guarantees 128). A bigger block fails ob_program_create even
 * where the device allows more. */
#define OB_PUSH_CONSTANT_MAX 128u

typedef enum ob_program_set {
    OB_PROGRAM_SET_UNIFORMS = 0,
    OB_PROGRAM_SET_RESOURCES = 1,
} ob_program_set;

typedef struct ob_program_ubo {
    uint32_t binding;
    uint32_t size;                 /* block size, rounded up to 16 */
    ob_param_mapping *mapping;
} ob_program_ubo;

typedef struct ob_program_resource {
    uint32_t binding;
    ob_binding_kind kind;
    ob_param param;                /* image, buffer or sampler parameter */
    ob_param sampler;              /* combined image samplers: the "<name>Sampler" parameter */
} ob_program_resource;

typedef struct ob_program {
    uint32_t id;                   /* stable: hash of the program name (command hashes use it) */
    char name[64];
    VkPipelineBindPoint bind_point;
    VkDescriptorSetLayout set_layouts[2];
    VkPipelineLayout layout;
    uint32_t ubo_count;
    ob_program_ubo ubos[OB_PROGRAM_MAX_UBOS];
    uint32_t resource_count;
    ob_program_resource resources[OB_PROGRAM_MAX_RESOURCES];
    ob_param_mapping *push_mapping; /* NULL when the program has no push constants */
    uint32_t push_size;
    VkShaderStageFlags push_stages;
    /* The push block is the standard per-draw block (WorldMatrix, NormalMatrix)
     * and no uniform block reads the world matrix: a draw's world matrix goes
     * straight into the push constants, not through the parameters. */
    bool push_world_normal;
    /* The vertex stage reads the world matrix per instance (the standard
     * shaders' INSTANCED variant: locations OB_INSTANCE_LOCATION..+2 of
     * vertex binding 1, instance rate, OB_INSTANCE_STRIDE bytes): a run of
     * draws of one mesh and material is one instanced draw. Set by the
     * effect from reflection, never by the user. */
    bool instanced;
} ob_program;

/* The per-instance block: the world matrix's three rows (the translation,
 * camera-relative, in their w; ob_render_proxy_instance), as vertex
 * attributes of binding 1. The shader derives the normal matrix. */
#define OB_INSTANCE_LOCATION 8u
#define OB_INSTANCE_ROWS 3u
#define OB_INSTANCE_FLOATS (4u * OB_INSTANCE_ROWS)
#define OB_INSTANCE_STRIDE (4u * OB_INSTANCE_FLOATS)

/* Builds set layouts, the pipeline layout and parameter mappings. Errors: a
 * uniform block outside set 0 or a resource outside set 1, too many bindings
 * (OB_ERR_UNSUPPORTED, naming the program and binding); Vulkan failures. */
ob_program *ob_program_create(ob_device *dev, ob_param_registry *reg,
                              const ob_reflection *refl, bool compute,
                              const char *name, ob_result *out_result);
/* Destroys now: the caller guarantees no pending frame uses it. NULL ok. */
void ob_program_destroy(ob_device *dev, ob_program *prog);

#endif /* OB_PROGRAM_H */
