#define _POSIX_C_SOURCE 200809L
#include "ob_shader.h"

#include <spirv_cross/spirv_cross_c.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Growth bookkeeping while a reflection is built; ob_reflection itself only
 * carries counts. */
typedef struct refl_builder {
    ob_reflection *r;
    uint32_t block_cap, binding_cap, input_cap;
} refl_builder;

static const char *const kind_names[] = {"uniform buffer", "storage buffer",
                                         "combined image sampler", "sampled image",
                                         "sampler", "storage image"};

static const char *kind_name(ob_binding_kind k)
{
    return (unsigned)k < OB_ARRAY_COUNT(kind_names) ? kind_names[k] : "binding";
}

VkShaderStageFlagBits ob_shader_stage_vk(ob_shader_stage stage)
{
    switch (stage) {
    case OB_SHADER_VERTEX: return VK_SHADER_STAGE_VERTEX_BIT;
    case OB_SHADER_FRAGMENT: return VK_SHADER_STAGE_FRAGMENT_BIT;
    case OB_SHADER_COMPUTE: return VK_SHADER_STAGE_COMPUTE_BIT;
    default: return 0;
    }
}

const char *ob_shader_stage_name(ob_shader_stage stage)
{
    switch (stage) {
    case OB_SHADER_VERTEX: return "vertex";
    case OB_SHADER_FRAGMENT: return "fragment";
    case OB_SHADER_COMPUTE: return "compute";
    default: return "unknown";
    }
}

/* "vertex|fragment" for messages. */
static const char *stages_text(VkShaderStageFlags s, char buf[64])
{
    buf[0] = '\0';
    static const struct { VkShaderStageFlags bit; const char *name; } names[] = {
        {VK_SHADER_STAGE_VERTEX_BIT, "vertex"},
        {VK_SHADER_STAGE_FRAGMENT_BIT, "fragment"},
        {VK_SHADER_STAGE_COMPUTE_BIT, "compute"},
    };
    for (size_t i = 0; i < OB_ARRAY_COUNT(names); i++) {
        if (!(s & names[i].bit)) continue;
        if (buf[0]) strcat(buf, "|");
        strcat(buf, names[i].name);
    }
    if (!buf[0]) strcpy(buf, "no stage");
    return buf;
}

static void reflection_init(ob_reflection *r)
{
    memset(r, 0, sizeof *r);
    r->push_block = -1;
}

void ob_reflection_release(ob_reflection *refl)
{
    if (!refl) return;
    for (uint32_t i = 0; i < refl->block_count; i++) ob_free(refl->blocks[i].members);
    ob_free(refl->blocks);
    ob_free(refl->bindings);
    ob_free(refl->vertex_inputs);
    reflection_init(refl);
}

const ob_block_layout *ob_reflection_find_block(const ob_reflection *refl, const char *name)
{
    if (!refl || !name) return NULL;
    for (uint32_t i = 0; i < refl->block_count; i++)
        if (strcmp(refl->blocks[i].name, name) == 0) return &refl->blocks[i];
    return NULL;
}

const ob_binding *ob_reflection_find_binding(const ob_reflection *refl, const char *name)
{
    if (!refl || !name) return NULL;
    for (uint32_t i = 0; i < refl->binding_count; i++)
        if (strcmp(refl->bindings[i].name, name) == 0) return &refl->bindings[i];
    return NULL;
}

const ob_block_member *ob_block_find_member(const ob_block_layout *block, const char *name)
{
    if (!block || !name) return NULL;
    for (uint32_t i = 0; i < block->member_count; i++)
        if (strcmp(block->members[i].name, name) == 0) return &block->members[i];
    return NULL;
}

/* ------------------------------------------------------------ building */

static ob_result copy_block(const ob_block_layout *src, ob_block_layout *dst)
{
    *dst = *src;
    dst->members = NULL;
    if (src->member_count) {
        dst->members = ob_malloc(src->member_count * sizeof *dst->members);
        if (!dst->members) return OB_ERR_OUT_OF_HOST_MEMORY;
        memcpy(dst->members, src->members, src->member_count * sizeof *dst->members);
    }
    return OB_OK;
}

/* Appends a deep copy of block; *out_index is its index. */
static ob_result add_block(refl_builder *b, const ob_block_layout *block, int32_t *out_index)
{
    ob_reflection *r = b->r;
    ob_result res = ob_array_reserve((void **)&r->blocks, &b->block_cap, r->block_count + 1,
                                     sizeof *r->blocks);
    if (res != OB_OK) return res;
    res = copy_block(block, &r->blocks[r->block_count]);
    if (res != OB_OK) return res;
    *out_index = (int32_t)r->block_count++;
    return OB_OK;
}

static bool members_equal(const ob_block_member *a, const ob_block_member *b)
{
    return strcmp(a->name, b->name) == 0 && a->type == b->type && a->offset == b->offset &&
           a->size == b->size && a->array_len == b->array_len && a->array_stride == b->array_stride;
}

static bool blocks_equal(const ob_block_layout *a, const ob_block_layout *b)
{
    if (strcmp(a->name, b->name) != 0 || a->size != b->size || a->member_count != b->member_count)
        return false;
    for (uint32_t i = 0; i < a->member_count; i++)
        if (!members_equal(&a->members[i], &b->members[i])) return false;
    return true;
}

/* Adds a binding, or ORs its stages into an identical one at the same
 * set/binding. block is the binding's block (buffers) or NULL. */
static ob_result add_binding(refl_builder *b, const ob_binding *binding,
                             const ob_block_layout *block, const char *where)
{
    ob_reflection *r = b->r;
    for (uint32_t i = 0; i < r->binding_count; i++) {
        ob_binding *have = &r->bindings[i];
        if (have->set != binding->set || have->binding != binding->binding) continue;
        const ob_block_layout *have_block = have->block >= 0 ? &r->blocks[have->block] : NULL;
        bool same = have->kind == binding->kind && have->count == binding->count &&
                    strcmp(have->name, binding->name) == 0 && !have_block == !block &&
                    (!block || blocks_equal(have_block, block));
        if (!same) {
            char s1[64], s2[64];
            OB_LOG_E("shader",
                     "%s: set %u binding %u is declared twice differently: %s '%s' [%u] (%s) "
                     "and %s '%s' [%u] (%s)%s",
                     where, binding->set, binding->binding, kind_name(have->kind), have->name,
                     have->count, stages_text(have->stages, s1), kind_name(binding->kind),
                     binding->name, binding->count, stages_text(binding->stages, s2),
                     block && have_block && strcmp(block->name, have_block->name) == 0
                         ? " (same block name, different layout)" : "");
            return OB_ERR_TYPE_MISMATCH;
        }
        have->stages |= binding->stages;
        return OB_OK;
    }
    ob_result res = ob_array_reserve((void **)&r->bindings, &b->binding_cap, r->binding_count + 1,
                                     sizeof *r->bindings);
    if (res != OB_OK) return res;
    ob_binding copy = *binding;
    copy.block = -1;
    if (block) {
        res = add_block(b, block, &copy.block);
        if (res != OB_OK) return res;
    }
    r->bindings[r->binding_count++] = copy;
    return OB_OK;
}

static ob_result add_vertex_input(refl_builder *b, const ob_vertex_input *in, const char *where)
{
    ob_reflection *r = b->r;
    for (uint32_t i = 0; i < r->vertex_input_count; i++) {
        const ob_vertex_input *have = &r->vertex_inputs[i];
        if (have->location != in->location) continue;
        if (strcmp(have->name, in->name) == 0 && have->format == in->format) return OB_OK;
        OB_LOG_E("shader", "%s: vertex input location %u is both '%s' (format %d) and '%s' (format %d)",
                 where, in->location, have->name, (int)have->format, in->name, (int)in->format);
        return OB_ERR_TYPE_MISMATCH;
    }
    ob_result res = ob_array_reserve((void **)&r->vertex_inputs, &b->input_cap,
                                     r->vertex_input_count + 1, sizeof *r->vertex_inputs);
    if (res != OB_OK) return res;
    r->vertex_inputs[r->vertex_input_count++] = *in;
    return OB_OK;
}

static int compare_bindings(const void *a, const void *b)
{
    const ob_binding *x = a, *y = b;
    if (x->set != y->set) return x->set < y->set ? -1 : 1;
    return x->binding < y->binding ? -1 : x->binding > y->binding;
}

static int compare_inputs(const void *a, const void *b)
{
    const ob_vertex_input *x = a, *y = b;
    return x->location < y->location ? -1 : x->location > y->location;
}

static void reflection_sort(ob_reflection *r)
{
    if (r->binding_count > 1) qsort(r->bindings, r->binding_count, sizeof *r->bindings, compare_bindings);
    if (r->vertex_input_count > 1)
        qsort(r->vertex_inputs, r->vertex_input_count, sizeof *r->vertex_inputs, compare_inputs);
}

/* ---------------------------------------------------------- spirv-cross */

typedef struct spv_ctx {
    spvc_compiler comp;
    const char *name;
    ob_shader_stage stage;
    refl_builder b;
} spv_ctx;

static void spvc_error(void *user, const char *error)
{
    OB_LOG_E("shader", "%s: SPIR-V reflection: %s", (const char *)user, error);
}

static ob_result copy_name(const spv_ctx *x, char dst[OB_REFLECT_NAME_MAX], const char *name,
                           const char *what)
{
    size_t n = strlen(name);
    if (n >= OB_REFLECT_NAME_MAX) {
        OB_LOG_E("shader", "%s: %s name '%s' is longer than %d characters", x->name, what, name,
                 OB_REFLECT_NAME_MAX - 1);
        return OB_ERR_UNSUPPORTED;
    }
    memcpy(dst, name, n + 1);
    return OB_OK;
}

static ob_member_type member_type(spvc_type t)
{
    unsigned vec = spvc_type_get_vector_size(t), cols = spvc_type_get_columns(t);
    switch (spvc_type_get_basetype(t)) {
    case SPVC_BASETYPE_FP32:
        if (cols == 1 && vec >= 1 && vec <= 4) return (ob_member_type)(OB_MEMBER_FLOAT + vec - 1);
        if (cols == 4 && vec == 4) return OB_MEMBER_MAT4;
        return OB_MEMBER_OTHER;
    case SPVC_BASETYPE_INT32:
        return cols != 1 ? OB_MEMBER_OTHER : vec == 1 ? OB_MEMBER_INT : vec == 4 ? OB_MEMBER_IVEC4 : OB_MEMBER_OTHER;
    case SPVC_BASETYPE_UINT32:
        return cols != 1 ? OB_MEMBER_OTHER : vec == 1 ? OB_MEMBER_UINT : vec == 4 ? OB_MEMBER_UVEC4 : OB_MEMBER_OTHER;
    default:
        return OB_MEMBER_OTHER;
    }
}

/* Element count of an array type (product over dimensions); 0 when a
 * dimension is unsized or a specialization constant. */
static uint32_t array_elements(spvc_type t, bool *is_array)
{
    unsigned dims = spvc_type_get_num_array_dimensions(t);
    *is_array = dims > 0;
    uint64_t n = 1;
    for (unsigned d = 0; d < dims; d++) {
        if (!spvc_type_array_dimension_is_literal(t, d)) return 0;
        n *= spvc_type_get_array_dimension(t, d);
    }
    return n > UINT32_MAX ? 0 : (uint32_t)n;
}

static ob_result reflect_block(spv_ctx *x, const spvc_reflected_resource *res, ob_block_layout *out)
{
    memset(out, 0, sizeof *out);
    spvc_type bt = spvc_compiler_get_type_handle(x->comp, res->base_type_id);
    const char *type_name = spvc_compiler_get_name(x->comp, res->base_type_id);
    ob_result r = copy_name(x, out->name, type_name && type_name[0] ? type_name : res->name, "block");
    if (r != OB_OK) return r;
    size_t size = 0;
    if (spvc_compiler_get_declared_struct_size(x->comp, bt, &size) != SPVC_SUCCESS)
        return OB_ERR_SHADER_COMPILE;
    out->size = (uint32_t)size;
    out->member_count = spvc_type_get_num_member_types(bt);
    if (out->member_count) {
        out->members = ob_calloc(out->member_count, sizeof *out->members);
        if (!out->members) return OB_ERR_OUT_OF_HOST_MEMORY;
    }
    for (uint32_t i = 0; i < out->member_count; i++) {
        ob_block_member *m = &out->members[i];
        spvc_type mt = spvc_compiler_get_type_handle(x->comp, spvc_type_get_member_type(bt, i));
        const char *mname = spvc_compiler_get_member_name(x->comp, res->base_type_id, i);
        r = copy_name(x, m->name, mname ? mname : "", "block member");
        if (r != OB_OK) return r;
        unsigned offset = 0, stride = 0;
        size_t msize = 0;
        if (spvc_compiler_type_struct_member_offset(x->comp, bt, i, &offset) != SPVC_SUCCESS ||
            spvc_compiler_get_declared_struct_member_size(x->comp, bt, i, &msize) != SPVC_SUCCESS)
            return OB_ERR_SHADER_COMPILE;
        m->offset = offset;
        m->size = (uint32_t)msize;
        m->type = member_type(mt);
        bool is_array;
        uint32_t elements = array_elements(mt, &is_array);
        if (is_array) {
            if (spvc_compiler_type_struct_member_array_stride(x->comp, bt, i, &stride) != SPVC_SUCCESS)
                return OB_ERR_SHADER_COMPILE;
            m->array_len = elements;
            m->array_stride = stride;
            /* Only one-dimensional arrays of a mappable type are mappable. */
            if (spvc_type_get_num_array_dimensions(mt) > 1) m->type = OB_MEMBER_OTHER;
        }
    }
    return OB_OK;
}

static ob_result get_resources(spvc_resources res, spvc_resource_type type,
                               const spvc_reflected_resource **list, size_t *count)
{
    *list = NULL;
    *count = 0;
    if (spvc_resources_get_resource_list_for_type(res, type, list, count) != SPVC_SUCCESS)
        return OB_ERR_SHADER_COMPILE;
    return OB_OK;
}

/* The descriptor part of a binding: set, binding, array count, stage. */
static ob_result describe_binding(spv_ctx *x, const spvc_reflected_resource *res,
                                  ob_binding_kind kind, const char *name, ob_binding *out)
{
    memset(out, 0, sizeof *out);
    ob_result r = copy_name(x, out->name, name, kind_name(kind));
    if (r != OB_OK) return r;
    out->kind = kind;
    out->stages = ob_shader_stage_vk(x->stage);
    out->block = -1;
    out->set = spvc_compiler_get_decoration(x->comp, res->id, SpvDecorationDescriptorSet);
    out->binding = spvc_compiler_get_decoration(x->comp, res->id, SpvDecorationBinding);
    bool is_array;
    uint32_t n = array_elements(spvc_compiler_get_type_handle(x->comp, res->type_id), &is_array);
    if (is_array && n == 0) {
        OB_LOG_E("shader", "%s: %s '%s' is an unsized array (descriptor indexing is not supported)",
                 x->name, kind_name(kind), name);
        return OB_ERR_UNSUPPORTED;
    }
    out->count = is_array ? n : 1;
    return OB_OK;
}

static ob_result reflect_buffers(spv_ctx *x, spvc_resources res, spvc_resource_type type,
                                 ob_binding_kind kind)
{
    const spvc_reflected_resource *list;
    size_t count;
    ob_result r = get_resources(res, type, &list, &count);
    for (size_t i = 0; i < count && r == OB_OK; i++) {
        ob_block_layout block;
        ob_binding bnd;
        r = reflect_block(x, &list[i], &block);
        if (r == OB_OK) r = describe_binding(x, &list[i], kind, block.name, &bnd);
        if (r == OB_OK) r = add_binding(&x->b, &bnd, &block, x->name);
        ob_free(block.members);
    }
    return r;
}

static ob_result reflect_images(spv_ctx *x, spvc_resources res, spvc_resource_type type,
                                ob_binding_kind kind)
{
    const spvc_reflected_resource *list;
    size_t count;
    ob_result r = get_resources(res, type, &list, &count);
    for (size_t i = 0; i < count && r == OB_OK; i++) {
        spvc_type base = spvc_compiler_get_type_handle(x->comp, list[i].base_type_id);
        if (kind != OB_BINDING_SAMPLER && spvc_type_get_image_dimension(base) == SpvDimBuffer) {
            OB_LOG_E("shader", "%s: '%s' is a texel buffer, which Obelisk does not bind", x->name,
                     list[i].name);
            return OB_ERR_UNSUPPORTED;
        }
        ob_binding bnd;
        r = describe_binding(x, &list[i], kind, list[i].name, &bnd);
        if (r == OB_OK) r = add_binding(&x->b, &bnd, NULL, x->name);
    }
    return r;
}

static ob_result reflect_push(spv_ctx *x, spvc_resources res)
{
    const spvc_reflected_resource *list;
    size_t count;
    ob_result r = get_resources(res, SPVC_RESOURCE_TYPE_PUSH_CONSTANT, &list, &count);
    if (r != OB_OK || count == 0) return r;
    ob_block_layout block;
    r = reflect_block(x, &list[0], &block);
    if (r == OB_OK) r = add_block(&x->b, &block, &x->b.r->push_block);
    if (r == OB_OK) x->b.r->push_stages = ob_shader_stage_vk(x->stage);
    ob_free(block.members);
    return r;
}

static VkFormat input_format(spvc_type t)
{
    static const VkFormat f32[] = {VK_FORMAT_R32_SFLOAT, VK_FORMAT_R32G32_SFLOAT,
                                   VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT};
    static const VkFormat i32[] = {VK_FORMAT_R32_SINT, VK_FORMAT_R32G32_SINT,
                                   VK_FORMAT_R32G32B32_SINT, VK_FORMAT_R32G32B32A32_SINT};
    static const VkFormat u32[] = {VK_FORMAT_R32_UINT, VK_FORMAT_R32G32_UINT,
                                   VK_FORMAT_R32G32B32_UINT, VK_FORMAT_R32G32B32A32_UINT};
    unsigned vec = spvc_type_get_vector_size(t);
    if (vec < 1 || vec > 4) return VK_FORMAT_UNDEFINED;
    switch (spvc_type_get_basetype(t)) {
    case SPVC_BASETYPE_FP32: return f32[vec - 1];
    case SPVC_BASETYPE_INT32: return i32[vec - 1];
    case SPVC_BASETYPE_UINT32: return u32[vec - 1];
    default: return VK_FORMAT_UNDEFINED;
    }
}

/* A matrix or array input takes one location per column and element; each
 * becomes its own entry ("name[i]"). */
static ob_result reflect_vertex_inputs(spv_ctx *x, spvc_resources res)
{
    const spvc_reflected_resource *list;
    size_t count;
    ob_result r = get_resources(res, SPVC_RESOURCE_TYPE_STAGE_INPUT, &list, &count);
    for (size_t i = 0; i < count && r == OB_OK; i++) {
        if (spvc_compiler_has_decoration(x->comp, list[i].id, SpvDecorationBuiltIn)) continue;
        spvc_type t = spvc_compiler_get_type_handle(x->comp, list[i].type_id);
        VkFormat format = input_format(t);
        bool is_array;
        uint32_t elements = array_elements(t, &is_array);
        uint32_t slots = spvc_type_get_columns(t) * (is_array ? elements : 1);
        if (format == VK_FORMAT_UNDEFINED || slots == 0) {
            OB_LOG_E("shader", "%s: vertex input '%s' has a type Obelisk cannot feed "
                     "(32-bit float/int/uint scalars, vectors and float matrices only)",
                     x->name, list[i].name);
            r = OB_ERR_UNSUPPORTED;
            break;
        }
        uint32_t location = spvc_compiler_get_decoration(x->comp, list[i].id, SpvDecorationLocation);
        for (uint32_t s = 0; s < slots && r == OB_OK; s++) {
            ob_vertex_input in = {.location = location + s, .format = format};
            char name[OB_REFLECT_NAME_MAX * 2];
            if (slots == 1) snprintf(name, sizeof name, "%s", list[i].name);
            else snprintf(name, sizeof name, "%s[%u]", list[i].name, s);
            r = copy_name(x, in.name, name, "vertex input");
            if (r == OB_OK) r = add_vertex_input(&x->b, &in, x->name);
        }
    }
    return r;
}

static void reflect_local_size(spv_ctx *x)
{
    const SpvExecutionMode *modes;
    size_t count;
    if (spvc_compiler_get_execution_modes(x->comp, &modes, &count) != SPVC_SUCCESS) return;
    for (size_t i = 0; i < count; i++) {
        for (unsigned d = 0; d < 3; d++) {
            unsigned arg = spvc_compiler_get_execution_mode_argument_by_index(x->comp, modes[i], d);
            if (modes[i] == SpvExecutionModeLocalSize) {
                x->b.r->local_size[d] = arg;
            } else if (modes[i] == SpvExecutionModeLocalSizeId) {
                spvc_constant c = spvc_compiler_get_constant_handle(x->comp, arg);
                x->b.r->local_size[d] = c ? spvc_constant_get_scalar_u32(c, 0, 0) : 0;
            }
        }
    }
}

/* Interfaces with no ob_binding_kind: fail clearly rather than build a
 * pipeline layout that misses them. */
static ob_result reject_unsupported(spv_ctx *x, spvc_resources res)
{
    static const struct { spvc_resource_type type; const char *what; } kinds[] = {
        {SPVC_RESOURCE_TYPE_SUBPASS_INPUT, "subpass input"},
        {SPVC_RESOURCE_TYPE_ATOMIC_COUNTER, "atomic counter"},
        {SPVC_RESOURCE_TYPE_ACCELERATION_STRUCTURE, "acceleration structure"},
        {SPVC_RESOURCE_TYPE_SHADER_RECORD_BUFFER, "shader record buffer"},
    };
    for (size_t k = 0; k < OB_ARRAY_COUNT(kinds); k++) {
        const spvc_reflected_resource *list;
        size_t count;
        ob_result r = get_resources(res, kinds[k].type, &list, &count);
        if (r != OB_OK) return r;
        if (count) {
            OB_LOG_E("shader", "%s: '%s' is a %s, which Obelisk does not bind", x->name,
                     list[0].name, kinds[k].what);
            return OB_ERR_UNSUPPORTED;
        }
    }
    return OB_OK;
}

ob_result ob_reflection_from_spirv(const uint32_t *spirv, size_t words, ob_shader_stage stage,
                                   const char *name, ob_reflection *out)
{
    reflection_init(out);
    if (!spirv || words == 0 || (unsigned)stage >= OB_SHADER_STAGE_COUNT) {
        OB_LOG_E("shader", "%s: nothing to reflect (no SPIR-V or bad stage)", name ? name : "?");
        return OB_ERR_INVALID_ARGUMENT;
    }
    spv_ctx x = {.name = name ? name : "shader", .stage = stage, .b = {.r = out}};
    spvc_context ctx = NULL;
    if (spvc_context_create(&ctx) != SPVC_SUCCESS) return OB_ERR_OUT_OF_HOST_MEMORY;
    spvc_context_set_error_callback(ctx, spvc_error, (void *)x.name);

    ob_result r = OB_ERR_SHADER_COMPILE;
    spvc_parsed_ir ir;
    spvc_resources res, used;
    spvc_set active;
    if (spvc_context_parse_spirv(ctx, spirv, words, &ir) != SPVC_SUCCESS ||
        spvc_context_create_compiler(ctx, SPVC_BACKEND_NONE, ir, SPVC_CAPTURE_MODE_TAKE_OWNERSHIP,
                                     &x.comp) != SPVC_SUCCESS ||
        spvc_compiler_create_shader_resources(x.comp, &res) != SPVC_SUCCESS ||
        spvc_compiler_get_active_interface_variables(x.comp, &active) != SPVC_SUCCESS ||
        spvc_compiler_create_shader_resources_for_active_variables(x.comp, &used, active) != SPVC_SUCCESS)
        goto done;

    r = reject_unsupported(&x, res);
    if (r == OB_OK) r = reflect_buffers(&x, res, SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, OB_BINDING_UNIFORM_BUFFER);
    if (r == OB_OK) r = reflect_buffers(&x, res, SPVC_RESOURCE_TYPE_STORAGE_BUFFER, OB_BINDING_STORAGE_BUFFER);
    if (r == OB_OK) r = reflect_images(&x, res, SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, OB_BINDING_COMBINED_IMAGE_SAMPLER);
    if (r == OB_OK) r = reflect_images(&x, res, SPVC_RESOURCE_TYPE_SEPARATE_IMAGE, OB_BINDING_SAMPLED_IMAGE);
    if (r == OB_OK) r = reflect_images(&x, res, SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, OB_BINDING_SAMPLER);
    if (r == OB_OK) r = reflect_images(&x, res, SPVC_RESOURCE_TYPE_STORAGE_IMAGE, OB_BINDING_STORAGE_IMAGE);
    /* The push block only where the stage reads it (the push-constant
     * interface is the statically used block): a stage that merely
     * includes the declaration, as the standard fragment shaders include
     * common.glsl's PerDraw, stays out of the range, so no push reaches it
     * (on lavapipe such a push re-stores llvmpipe's fragment state, 33 KB
     * a draw). Every other resource is bound for all stages anyway. */
    if (r == OB_OK) r = reflect_push(&x, used);
    if (r == OB_OK && stage == OB_SHADER_VERTEX) r = reflect_vertex_inputs(&x, res);
    if (r == OB_OK && stage == OB_SHADER_COMPUTE) reflect_local_size(&x);
    if (r == OB_OK) reflection_sort(out);
done:
    spvc_context_destroy(ctx);
    if (r == OB_ERR_SHADER_COMPILE)
        OB_LOG_E("shader", "%s: cannot reflect its SPIR-V (%zu words)", x.name, words);
    if (r != OB_OK) ob_reflection_release(out);
    return r;
}

/* ----------------------------------------------------------------- merge */

static bool ranges_overlap(const ob_block_member *a, const ob_block_member *b)
{
    uint32_t ae = a->offset + OB_MAX(a->size, 1u), be = b->offset + OB_MAX(b->size, 1u);
    return a->offset < be && b->offset < ae;
}

/* Push-constant blocks: stages may each declare only what they read, so the
 * merged block is the union of members; a member must mean the same in every
 * stage and differently named members must not share bytes. */
static ob_result merge_push(refl_builder *b, const ob_block_layout *in, VkShaderStageFlags stages)
{
    ob_reflection *r = b->r;
    if (r->push_block < 0) {
        ob_result res = add_block(b, in, &r->push_block);
        if (res == OB_OK) r->push_stages = stages;
        return res;
    }
    ob_block_layout *have = &r->blocks[r->push_block];
    char s1[64], s2[64];
    for (uint32_t i = 0; i < in->member_count; i++) {
        const ob_block_member *m = &in->members[i];
        const ob_block_member *same = ob_block_find_member(have, m->name);
        if (same && members_equal(same, m)) continue;
        for (uint32_t j = 0; j < have->member_count; j++) {
            const ob_block_member *o = &have->members[j];
            if (o == same || ranges_overlap(o, m)) {
                OB_LOG_E("shader",
                         "push constants: '%s.%s' (offset %u, %u bytes, %s) conflicts with "
                         "'%s.%s' (offset %u, %u bytes, %s)",
                         have->name, o->name, o->offset, o->size, stages_text(r->push_stages, s1),
                         in->name, m->name, m->offset, m->size, stages_text(stages, s2));
                return OB_ERR_TYPE_MISMATCH;
            }
        }
        ob_block_member *members = ob_realloc(have->members, (have->member_count + 1) * sizeof *members);
        if (!members) return OB_ERR_OUT_OF_HOST_MEMORY;
        uint32_t at = have->member_count;
        while (at > 0 && members[at - 1].offset > m->offset) {
            members[at] = members[at - 1];
            at--;
        }
        members[at] = *m;
        have->members = members;
        have->member_count++;
    }
    have->size = OB_MAX(have->size, in->size);
    r->push_stages |= stages;
    return OB_OK;
}

ob_result ob_reflection_merge(const ob_reflection *const *stages, uint32_t count, ob_reflection *out)
{
    reflection_init(out);
    if (!stages && count) return OB_ERR_INVALID_ARGUMENT;
    refl_builder b = {.r = out};
    ob_result r = OB_OK;
    for (uint32_t s = 0; s < count && r == OB_OK; s++) {
        const ob_reflection *in = stages[s];
        if (!in) continue;
        char where[32];
        snprintf(where, sizeof where, "pipeline stage %u", s);
        for (uint32_t i = 0; i < in->binding_count && r == OB_OK; i++) {
            const ob_binding *bnd = &in->bindings[i];
            const ob_block_layout *blk = bnd->block >= 0 ? &in->blocks[bnd->block] : NULL;
            r = add_binding(&b, bnd, blk, where);
        }
        if (r == OB_OK && in->push_block >= 0)
            r = merge_push(&b, &in->blocks[in->push_block], in->push_stages);
        for (uint32_t i = 0; i < in->vertex_input_count && r == OB_OK; i++)
            r = add_vertex_input(&b, &in->vertex_inputs[i], where);
        if (r == OB_OK && (in->local_size[0] | in->local_size[1] | in->local_size[2])) {
            if ((out->local_size[0] | out->local_size[1] | out->local_size[2]) &&
                memcmp(out->local_size, in->local_size, sizeof out->local_size) != 0) {
                OB_LOG_E("shader", "%s: two compute stages with different local sizes", where);
                r = OB_ERR_TYPE_MISMATCH;
            } else {
                memcpy(out->local_size, in->local_size, sizeof out->local_size);
            }
        }
    }
    if (r == OB_OK) reflection_sort(out);
    else ob_reflection_release(out);
    return r;
}
