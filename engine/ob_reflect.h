/* ob_reflect.h — shader interface descriptions shared by the parameter
 * system (engine), the shader compiler (materials) and the pipeline manager.
 *
 * These are plain data: materials/ob_shader.c fills them from SPIR-V through
 * spirv-cross; ob_params.c maps uniform-block members to parameters; the
 * pipeline manager binds descriptors from them. No functions, no lifecycle.
 */
#ifndef OB_REFLECT_H
#define OB_REFLECT_H

#include <stdint.h>
#include <vulkan/vulkan.h>

#define OB_REFLECT_NAME_MAX 64

typedef enum ob_member_type {
    OB_MEMBER_OTHER = 0,   /* structs and anything else: never mapped */
    OB_MEMBER_FLOAT,
    OB_MEMBER_VEC2,
    OB_MEMBER_VEC3,
    OB_MEMBER_VEC4,
    OB_MEMBER_MAT4,
    OB_MEMBER_INT,
    OB_MEMBER_UINT,
    OB_MEMBER_IVEC4,
    OB_MEMBER_UVEC4,
} ob_member_type;

/* One member of a uniform block or push-constant block. */
typedef struct ob_block_member {
    char name[OB_REFLECT_NAME_MAX];
    ob_member_type type;
    uint32_t offset;        /* bytes from the block start */
    uint32_t size;          /* bytes of the whole member (all array elements) */
    uint32_t array_len;     /* 0 = not an array, else element count */
    uint32_t array_stride;  /* bytes between elements (0 if not an array) */
} ob_block_member;

/* A uniform block (std140), storage block (std430) or push-constant block. */
typedef struct ob_block_layout {
    char name[OB_REFLECT_NAME_MAX];  /* block type name, e.g. "PerDraw" */
    uint32_t set, binding;           /* unused for push constants */
    uint32_t size;                   /* declared size in bytes */
    uint32_t member_count;
    ob_block_member *members;
} ob_block_layout;

typedef enum ob_binding_kind {
    OB_BINDING_UNIFORM_BUFFER = 0,
    OB_BINDING_STORAGE_BUFFER,
    OB_BINDING_COMBINED_IMAGE_SAMPLER,
    OB_BINDING_SAMPLED_IMAGE,
    OB_BINDING_SAMPLER,
    OB_BINDING_STORAGE_IMAGE,
} ob_binding_kind;

/* One descriptor binding. name is the variable name for images/samplers and
 * the block instance's type name for buffers (what parameters are matched by). */
typedef struct ob_binding {
    char name[OB_REFLECT_NAME_MAX];
    ob_binding_kind kind;
    uint32_t set, binding;
    uint32_t count;                  /* array size, 1 if not an array */
    VkShaderStageFlags stages;
    int32_t block;                   /* index into ob_reflection.blocks for uniform and
                                        storage buffers, -1 otherwise */
} ob_binding;

typedef struct ob_vertex_input {
    char name[OB_REFLECT_NAME_MAX];
    uint32_t location;
    VkFormat format;                 /* float/vec2/vec3/vec4 → R32..._SFLOAT etc. */
} ob_vertex_input;

/* Everything reflected from one stage, or merged over a pipeline's stages. */
typedef struct ob_reflection {
    uint32_t block_count;
    ob_block_layout *blocks;         /* uniform and storage blocks */
    uint32_t binding_count;
    ob_binding *bindings;            /* sorted by (set, binding) */
    int32_t push_block;              /* index into blocks of the push-constant block, -1 none */
    VkShaderStageFlags push_stages;
    uint32_t vertex_input_count;
    ob_vertex_input *vertex_inputs;  /* vertex stage only, sorted by location */
    uint32_t local_size[3];          /* compute stage only */
} ob_reflection;

#endif /* OB_REFLECT_H */
