#include "ob_program.h"

#include <stdio.h>
#include <string.h>

static VkShaderStageFlags all_stages(bool compute)
{
    return compute ? VK_SHADER_STAGE_COMPUTE_BIT
                   : (VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT);
}

/* The parameter type a block member maps to, or -1 if none can. */
static int member_param_type(const ob_block_member *m, uint32_t *out_count)
{
    *out_count = 1;
    if (m->type == OB_MEMBER_MAT4 && m->array_len > 0) {
        *out_count = m->array_len;
        return OB_PARAM_MAT4_ARRAY;
    }
    if (m->array_len > 0) {
        *out_count = m->size;
        return OB_PARAM_BYTES;
    }
    switch (m->type) {
    case OB_MEMBER_VEC4: return OB_PARAM_VEC4;
    case OB_MEMBER_MAT4: return OB_PARAM_MAT4;
    case OB_MEMBER_OTHER: return -1;
    default: *out_count = m->size; return OB_PARAM_BYTES;
    }
}

/* Members the application has not registered yet become parameters of the
 * declared type, so a shader can add a member and have it set by name. */
/* A member whose parameter cannot be registered (out of memory, the
 * registry full) fails the program: its mapping would leave the member
 * unfed, a silently wrong picture. */
static ob_result register_block_params(ob_param_registry *reg, const ob_block_layout *b,
                                       const char *program)
{
    for (uint32_t i = 0; i < b->member_count; i++) {
        const ob_block_member *m = &b->members[i];
        if (ob_param_find(reg, m->name).id) continue;
        uint32_t count;
        int type = member_param_type(m, &count);
        if (type < 0) continue;
        ob_result r = OB_OK;
        if (!ob_param_register(reg, m->name, (ob_param_type)type, count, &r).id) {
            OB_LOG_E("program", "program '%s': parameter '%s' of block '%s' not registered: %s",
                     program, m->name, b->name, ob_result_name(r));
            return r != OB_OK ? r : OB_ERR_OUT_OF_HOST_MEMORY;
        }
    }
    return OB_OK;
}

static ob_param resource_param(ob_param_registry *reg, const char *name, ob_param_type type)
{
    ob_param p = ob_param_find(reg, name);
    if (p.id) return p;
    ob_result r;
    return ob_param_register(reg, name, type, 1, &r);
}

static ob_result add_resource(ob_program *prog, ob_param_registry *reg, const ob_binding *b)
{
    if (prog->resource_count >= OB_PROGRAM_MAX_RESOURCES) {
        OB_LOG_E("program", "program '%s': more than %u resource bindings", prog->name,
                 OB_PROGRAM_MAX_RESOURCES);
        return OB_ERR_UNSUPPORTED;
    }
    ob_program_resource *res = &prog->resources[prog->resource_count++];
    res->binding = b->binding;
    res->kind = b->kind;
    char sampler_name[OB_REFLECT_NAME_MAX + 8];
    switch (b->kind) {
    case OB_BINDING_COMBINED_IMAGE_SAMPLER:
        res->param = resource_param(reg, b->name, OB_PARAM_TEXTURE);
        snprintf(sampler_name, sizeof sampler_name, "%sSampler", b->name);
        res->sampler = resource_param(reg, sampler_name, OB_PARAM_SAMPLER);
        break;
    case OB_BINDING_SAMPLED_IMAGE:
    case OB_BINDING_STORAGE_IMAGE:
        res->param = resource_param(reg, b->name, OB_PARAM_TEXTURE);
        break;
    case OB_BINDING_SAMPLER:
        res->param = resource_param(reg, b->name, OB_PARAM_SAMPLER);
        break;
    case OB_BINDING_STORAGE_BUFFER:
        res->param = resource_param(reg, b->name, OB_PARAM_STORAGE_BUFFER);
        break;
    case OB_BINDING_UNIFORM_BUFFER:
        res->param = resource_param(reg, b->name, OB_PARAM_UNIFORM_BUFFER);
        break;
    }
    if (!res->param.id) {
        OB_LOG_E("program", "program '%s': binding '%s' has no parameter", prog->name, b->name);
        return OB_ERR_TYPE_MISMATCH;
    }
    return OB_OK;
}

static VkDescriptorType descriptor_type(ob_binding_kind kind)
{
    switch (kind) {
    case OB_BINDING_UNIFORM_BUFFER: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case OB_BINDING_STORAGE_BUFFER: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case OB_BINDING_COMBINED_IMAGE_SAMPLER: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    case OB_BINDING_SAMPLED_IMAGE: return VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    case OB_BINDING_SAMPLER: return VK_DESCRIPTOR_TYPE_SAMPLER;
    case OB_BINDING_STORAGE_IMAGE: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    }
    return VK_DESCRIPTOR_TYPE_MAX_ENUM;
}

ob_program *ob_program_create(ob_device *dev, ob_param_registry *reg,
                              const ob_reflection *refl, bool compute,
                              const char *name, ob_result *out_result)
{
    ob_result r = OB_OK;
    VkDevice vk = ob_device_vk(dev);
    VkShaderStageFlags stages = all_stages(compute);
    ob_program *prog = ob_calloc(1, sizeof *prog);
    if (!prog) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto fail_report;
    }
    snprintf(prog->name, sizeof prog->name, "%s", name ? name : "program");
    prog->id = (uint32_t)ob_hash_str(OB_HASH_SEED, prog->name);
    prog->bind_point = compute ? VK_PIPELINE_BIND_POINT_COMPUTE : VK_PIPELINE_BIND_POINT_GRAPHICS;

    VkDescriptorSetLayoutBinding ubo_bindings[OB_PROGRAM_MAX_UBOS];
    VkDescriptorSetLayoutBinding res_bindings[OB_PROGRAM_MAX_RESOURCES];
    for (uint32_t i = 0; i < refl->binding_count; i++) {
        const ob_binding *b = &refl->bindings[i];
        bool is_ubo = b->kind == OB_BINDING_UNIFORM_BUFFER && b->block >= 0;
        uint32_t want_set = is_ubo ? OB_PROGRAM_SET_UNIFORMS : OB_PROGRAM_SET_RESOURCES;
        if (b->set != want_set || b->count != 1) {
            OB_LOG_E("program", "program '%s': binding '%s' (set %u, binding %u, count %u) must be "
                     "in set %u and not an array", prog->name, b->name, b->set, b->binding,
                     b->count, want_set);
            r = OB_ERR_UNSUPPORTED;
            goto fail_destroy_program;
        }
        if (is_ubo) {
            if (prog->ubo_count >= OB_PROGRAM_MAX_UBOS) {
                OB_LOG_E("program", "program '%s': more than %u uniform blocks", prog->name,
                         OB_PROGRAM_MAX_UBOS);
                r = OB_ERR_UNSUPPORTED;
                goto fail_destroy_program;
            }
            const ob_block_layout *layout = &refl->blocks[b->block];
            r = register_block_params(reg, layout, prog->name);
            if (r != OB_OK) goto fail_destroy_program;
            ob_program_ubo *u = &prog->ubos[prog->ubo_count];
            u->binding = b->binding;
            u->size = (layout->size + 15u) & ~15u;
            u->mapping = ob_param_mapping_create(reg, layout, prog->name, &r);
            if (!u->mapping) goto fail_destroy_program;
            ubo_bindings[prog->ubo_count] = (VkDescriptorSetLayoutBinding){
                .binding = b->binding,
                .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
                .descriptorCount = 1,
                .stageFlags = stages,
            };
            prog->ubo_count++;
        } else {
            r = add_resource(prog, reg, b);
            if (r != OB_OK) goto fail_destroy_program;
            res_bindings[prog->resource_count - 1] = (VkDescriptorSetLayoutBinding){
                .binding = b->binding,
                .descriptorType = descriptor_type(b->kind),
                .descriptorCount = 1,
                .stageFlags = stages,
            };
        }
    }
    if (refl->push_block >= 0) {
        const ob_block_layout *pb = &refl->blocks[refl->push_block];
        r = register_block_params(reg, pb, prog->name);
        if (r != OB_OK) goto fail_destroy_program;
        prog->push_mapping = ob_param_mapping_create(reg, pb, prog->name, &r);
        if (!prog->push_mapping) goto fail_destroy_program;
        prog->push_size = (pb->size + 3u) & ~3u;
        /* Only the stages that read the block (ob_shader_reflect): a push
         * then reaches no stage that merely declares it. */
        prog->push_stages = refl->push_stages ? refl->push_stages : stages;
        uint32_t limit = OB_MIN(ob_device_properties(dev)->limits.maxPushConstantsSize,
                                OB_PUSH_CONSTANT_MAX);
        if (prog->push_size > limit) {
            OB_LOG_E("program", "program '%s': push constants of %u bytes exceed the limit %u "
                     "(the device's %u, the engine's %u)", prog->name, prog->push_size, limit,
                     ob_device_properties(dev)->limits.maxPushConstantsSize, OB_PUSH_CONSTANT_MAX);
            r = OB_ERR_UNSUPPORTED;
            goto fail_destroy_program;
        }
        prog->push_world_normal = ob_param_mapping_is_world_normal(prog->push_mapping);
        for (uint32_t i = 0; i < prog->ubo_count; i++)
            if (ob_param_mapping_reads_world(prog->ubos[i].mapping)) prog->push_world_normal = false;
    }

    VkDescriptorSetLayoutCreateInfo set0 = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .bindingCount = prog->ubo_count,
        .pBindings = ubo_bindings,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateDescriptorSetLayout(vk, &set0, NULL, &prog->set_layouts[0]));
    if (vr != VK_SUCCESS) goto fail_note_vk;
    VkDescriptorSetLayoutCreateInfo set1 = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO,
        .flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR,
        .bindingCount = prog->resource_count,
        .pBindings = res_bindings,
    };
    vr = OB_VK_CHECK_CREATE(vkCreateDescriptorSetLayout(vk, &set1, NULL, &prog->set_layouts[1]));
    if (vr != VK_SUCCESS) goto fail_note_vk;
    VkPushConstantRange push = {.stageFlags = prog->push_stages, .size = prog->push_size};
    VkPipelineLayoutCreateInfo pl = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
        .setLayoutCount = 2,
        .pSetLayouts = prog->set_layouts,
        .pushConstantRangeCount = prog->push_size ? 1u : 0u,
        .pPushConstantRanges = &push,
    };
    vr = OB_VK_CHECK_CREATE(vkCreatePipelineLayout(vk, &pl, NULL, &prog->layout));
    if (vr != VK_SUCCESS) goto fail_note_vk;
    ob_device_set_name(dev, VK_OBJECT_TYPE_PIPELINE_LAYOUT, (uint64_t)prog->layout, prog->name);
    if (out_result) *out_result = OB_OK;
    return prog;

fail_note_vk:
    r = ob_result_from_vk(vr);
fail_destroy_program:
    ob_program_destroy(dev, prog);
    prog = NULL;
fail_report:
    if (out_result) *out_result = r;
    return NULL;
}

void ob_program_destroy(ob_device *dev, ob_program *prog)
{
    if (!prog) return;
    VkDevice vk = ob_device_vk(dev);
    if (prog->layout) vkDestroyPipelineLayout(vk, prog->layout, NULL);
    for (uint32_t i = 0; i < 2; i++)
        if (prog->set_layouts[i]) vkDestroyDescriptorSetLayout(vk, prog->set_layouts[i], NULL);
    for (uint32_t i = 0; i < prog->ubo_count; i++) ob_param_mapping_destroy(prog->ubos[i].mapping);
    ob_param_mapping_destroy(prog->push_mapping);
    ob_free(prog);
}
