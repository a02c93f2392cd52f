#include "ob_bench_raw.h"

#include <cglm/cglm.h>
#include <math.h>
#include <string.h>

#include "ob_bench_run.h"
#include "ob_renderer_layer.h"

#define COLOR_FORMAT VK_FORMAT_R8G8B8A8_UNORM
#define DEPTH_FORMAT VK_FORMAT_D32_SFLOAT
#define PUSH_SIZE 128u
#define ROW_FLOATS 12u              /* the engine's per-instance block (OB_INSTANCE_FLOATS) */
#define ROW_SIZE (4u * ROW_FLOATS)

/* The per-draw loop's: its WorldMatrix is the view's view-projection times
 * the world matrix (clip from model), so the draws land where the engine's
 * do and a timed execution prices the same triangles. */
static const char raw_vert[] =
    "#version 450\n"
    "layout(push_constant, std430) uniform PerDraw { mat4 WorldMatrix; mat4 NormalMatrix; };\n"
    "layout(location = 0) in vec3 inPosition;\n"
    "layout(location = 0) out vec3 vNormal;\n"
    "void main() {\n"
    "    vNormal = mat3(NormalMatrix) * vec3(0.0, 1.0, 0.0);\n"
    "    gl_Position = WorldMatrix * vec4(inPosition, 1.0);\n"
    "}\n";
/* The instanced loop's: the engine's per-instance block, the world
 * matrix's three rows from binding 1, the normal matrix derived from it
 * as the standard shaders do (ob_normal_matrix, common.glsl), and the
 * view-projection pushed once. */
static const char raw_vert_instanced[] =
    "#version 450\n"
    "layout(push_constant, std430) uniform PerRun { mat4 ViewProj; };\n"
    "layout(location = 0) in vec3 inPosition;\n"
    "layout(location = 8) in vec4 r0;\n"
    "layout(location = 9) in vec4 r1;\n"
    "layout(location = 10) in vec4 r2;\n"
    "layout(location = 0) out vec3 vNormal;\n"
    "void main() {\n"
    "    mat4 w = mat4(vec4(r0.x, r1.x, r2.x, 0.0), vec4(r0.y, r1.y, r2.y, 0.0),\n"
    "                  vec4(r0.z, r1.z, r2.z, 0.0), vec4(r0.w, r1.w, r2.w, 1.0));\n"
    "    mat3 m = mat3(w);\n"
    "    vec3 a = max(abs(m[0]), max(abs(m[1]), abs(m[2])));\n"
    "    float big = max(a.x, max(a.y, a.z));\n"
    "    if (big > 0.0) m *= 1.0 / big;\n"
    "    vNormal = mat3(cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])) *\n"
    "              vec3(0.0, 1.0, 0.0);\n"
    "    gl_Position = ViewProj * (w * vec4(inPosition, 1.0));\n"
    "}\n";
static const char raw_frag[] =
    "#version 450\n"
    "layout(location = 0) in vec3 vNormal;\n"
    "layout(location = 0) out vec4 outColor;\n"
    "void main() { outColor = vec4(normalize(vNormal) * 0.5 + 0.5, 1.0); }\n";

/* What one draw needs, gathered before timing. */
typedef struct raw_draw {
    VkBuffer vb, ib;
    uint32_t index_count, first_index;  /* the level of detail the engine drew */
    int32_t vertex_offset;
} raw_draw;

struct ob_bench_raw {
    VkDevice vk;
    ob_device *dev;
    VkShaderModule vert, frag, vert_instanced;
    VkPipelineLayout layout, layout_instanced;
    VkPipeline pipeline, pipeline_instanced;
    ob_buffer instances;       /* the world rows of each draw, as instance data */
    void *instance_data;       /* its mapping: written at each recording */
    VkCommandPool pool;
    VkCommandBuffer cmd;
    raw_draw *draws;
    float *push;               /* 32 floats per draw, 32-byte aligned */
    float *rows;               /* ROW_FLOATS per draw: the world matrix's rows */
    uint32_t count;
    uint32_t width, height;    /* the view's, for viewport and scissor */
    float view_proj[16];       /* the view's (relative to its origin) */
    /* GPU timing (ob_bench_raw_gpu_ms): view-sized targets of the recording's
     * formats, a timestamp pair, nanoseconds per tick (0: no timestamps). */
    ob_image color, depth;
    VkQueryPool queries;
    double tick_ns;
    /* The pool's allocator: the engine's own (a recording pool's), so that
     * the two loops record into memory managed the same way and the raw
     * figure prices Vulkan, not glibc malloc's state; it counts the
     * driver's allocations per draw. */
    ob_arena_allocator pool_alloc;
};

typedef struct ob_bench_raw raw_state;

static ob_result make_module(ob_demo *d, const char *name, const char *source, ob_shader_stage stage,
                             VkShaderModule *out)
{
    ob_result r;
    ob_shader_desc sd = {.path = name, .source = source, .stage = stage};
    const ob_shader *sh = ob_shader_get(ob_effect_context_compiler(d->world.stack->effects), &sd, &r);
    if (!sh) return r;
    VkShaderModuleCreateInfo ci = {.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO,
                                   .codeSize = sh->spirv_words * 4, .pCode = sh->spirv};
    VkResult vr = OB_VK_CHECK(vkCreateShaderModule(ob_device_vk(ob_renderer_device(d->world.r)), &ci, NULL, out));
    return ob_result_from_vk(vr);
}

/* The per-draw pipeline (push constants), or the instanced one (binding 1,
 * instance rate, no push constants). */
static ob_result make_pipeline(ob_demo *d, raw_state *s, bool instanced)
{
    ob_result r = OB_OK;
    VkShaderModule *vert = instanced ? &s->vert_instanced : &s->vert;
    if (instanced)
        r = make_module(d, "bench_raw_instanced.vert", raw_vert_instanced, OB_SHADER_VERTEX, vert);
    else
        r = make_module(d, "bench_raw.vert", raw_vert, OB_SHADER_VERTEX, vert);
    if (r == OB_OK && !s->frag)
        r = make_module(d, "bench_raw.frag", raw_frag, OB_SHADER_FRAGMENT, &s->frag);
    if (r != OB_OK) return r;
    VkPushConstantRange range = {VK_SHADER_STAGE_VERTEX_BIT, 0, instanced ? 64u : PUSH_SIZE};
    VkPipelineLayoutCreateInfo lci = {.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO,
                                      .pushConstantRangeCount = 1, .pPushConstantRanges = &range};
    VkPipelineLayout *layout = instanced ? &s->layout_instanced : &s->layout;
    VkResult vr = OB_VK_CHECK(vkCreatePipelineLayout(s->vk, &lci, NULL, layout));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    VkPipelineShaderStageCreateInfo stages[2] = {
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
         .stage = VK_SHADER_STAGE_VERTEX_BIT, .module = *vert, .pName = "main"},
        {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO,
         .stage = VK_SHADER_STAGE_FRAGMENT_BIT, .module = s->frag, .pName = "main"},
    };
    VkVertexInputBindingDescription bindings[2] = {
        {0, sizeof(ob_vertex), VK_VERTEX_INPUT_RATE_VERTEX},
        {1, ROW_SIZE, VK_VERTEX_INPUT_RATE_INSTANCE}};
    VkVertexInputAttributeDescription attributes[4] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}};
    for (uint32_t k = 0; k < 3; k++)
        attributes[1 + k] = (VkVertexInputAttributeDescription){8 + k, 1,
                                                                VK_FORMAT_R32G32B32A32_SFLOAT, 16 * k};
    VkPipelineVertexInputStateCreateInfo vi = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO,
        .vertexBindingDescriptionCount = instanced ? 2u : 1u, .pVertexBindingDescriptions = bindings,
        .vertexAttributeDescriptionCount = instanced ? 4u : 1u,
        .pVertexAttributeDescriptions = attributes};
    VkPipelineInputAssemblyStateCreateInfo ia = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO,
        .topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST};
    VkPipelineViewportStateCreateInfo vp = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO,
        .viewportCount = 1, .scissorCount = 1};
    VkPipelineRasterizationStateCreateInfo rs = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO,
        .polygonMode = VK_POLYGON_MODE_FILL, .cullMode = VK_CULL_MODE_BACK_BIT,
        .frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE, .lineWidth = 1.0f};
    VkPipelineMultisampleStateCreateInfo ms = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO,
        .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
    VkPipelineDepthStencilStateCreateInfo ds = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO,
        .depthTestEnable = VK_TRUE, .depthWriteEnable = VK_TRUE,
        .depthCompareOp = VK_COMPARE_OP_GREATER_OR_EQUAL};
    VkPipelineColorBlendAttachmentState att = {.colorWriteMask = 0xf};
    VkPipelineColorBlendStateCreateInfo cb = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO,
        .attachmentCount = 1, .pAttachments = &att};
    VkDynamicState dyn[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dy = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO,
        .dynamicStateCount = 2, .pDynamicStates = dyn};
    VkFormat color = COLOR_FORMAT;
    VkPipelineRenderingCreateInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO,
        .colorAttachmentCount = 1, .pColorAttachmentFormats = &color,
        .depthAttachmentFormat = DEPTH_FORMAT};
    VkGraphicsPipelineCreateInfo pci = {
        .sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, .pNext = &rendering,
        .stageCount = 2, .pStages = stages, .pVertexInputState = &vi,
        .pInputAssemblyState = &ia, .pViewportState = &vp, .pRasterizationState = &rs,
        .pMultisampleState = &ms, .pDepthStencilState = &ds, .pColorBlendState = &cb,
        .pDynamicState = &dy, .layout = *layout};
    vr = OB_VK_CHECK(vkCreateGraphicsPipelines(s->vk, VK_NULL_HANDLE, 1, &pci, NULL,
                                               instanced ? &s->pipeline_instanced : &s->pipeline));
    return ob_result_from_vk(vr);
}

static ob_result make_commands(ob_demo *d, raw_state *s)
{
    VkCommandPoolCreateInfo pci = {.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
                                   .flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT,
                                   .queueFamilyIndex = ob_device_queue_family(ob_renderer_device(d->world.r))};
    ob_arena_allocator_init(&s->pool_alloc);
    VkResult vr = OB_VK_CHECK(vkCreateCommandPool(s->vk, &pci, &s->pool_alloc.callbacks, &s->pool));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    VkCommandBufferAllocateInfo ai = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                      .commandPool = s->pool,
                                      .level = VK_COMMAND_BUFFER_LEVEL_SECONDARY,
                                      .commandBufferCount = 1};
    vr = OB_VK_CHECK(vkAllocateCommandBuffers(s->vk, &ai, &s->cmd));
    return ob_result_from_vk(vr);
}

/* World and normal matrices as the engine computes them for v; the
 * per-draw push block's world matrix with v's view-projection applied. */
static ob_result gather(ob_demo *d, const ob_view *v, raw_state *s)
{
    ob_device *dev = ob_renderer_device(d->world.r);
    s->draws = ob_calloc(v->item_count, sizeof *s->draws);
    s->push = ob_aligned_alloc(32, sizeof(float) * 32 * v->item_count);
    s->rows = ob_aligned_alloc(16, sizeof(float) * ROW_FLOATS * v->item_count);
    if (!s->draws || !s->push || !s->rows) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < v->item_count; i++) {
        const ob_node *n = v->items[i].node;
        const ob_renderable *rd = ob_node_get_renderable(n);
        const ob_geometry *g = rd ? (const ob_geometry *)rd->geometry : NULL;
        if (!g || ob_geometry_index_count(g) == 0) continue;
        float *clip = &s->push[32 * s->count], *normal = clip + 16;
        float world[16];
        ob_node_world_relative(n, v->origin, world);
        mat4 inv;
        glm_mat4_inv((vec4 *)world, inv);
        glm_mat4_transpose_to(inv, (vec4 *)normal);
        ob_mat4_mul(v->view_proj, world, clip);
        float *rows = &s->rows[ROW_FLOATS * s->count];
        for (uint32_t r = 0; r < 3; r++)
            for (uint32_t c = 0; c < 4; c++) rows[4 * r + c] = world[4 * c + r];
        ob_draw_data dd;
        ob_geometry_iface_get()->draw_data((const struct ob_geometry *)g, v->items[i].lod, &dd);
        s->draws[s->count++] = (raw_draw){ob_buffer_vk(dev, dd.vertex_buffer),
                                          ob_buffer_vk(dev, dd.index_buffer), dd.count, dd.first,
                                          dd.vertex_offset};
    }
    return s->count ? OB_OK : OB_ERR_INVALID_ARGUMENT;
}

static ob_result record(ob_bench_raw *s, ob_bench_raw_sample *out, bool instanced)
{
    memset(out, 0, sizeof *out);
    VkFormat color = COLOR_FORMAT;
    VkCommandBufferInheritanceRenderingInfo rendering = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO,
        .colorAttachmentCount = 1, .pColorAttachmentFormats = &color,
        .depthAttachmentFormat = DEPTH_FORMAT, .rasterizationSamples = VK_SAMPLE_COUNT_1_BIT};
    VkCommandBufferInheritanceInfo inherit = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO, .pNext = &rendering};
    VkCommandBufferBeginInfo bi = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO,
        .flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT |
                 VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT,
        .pInheritanceInfo = &inherit};
    if (OB_VK_CHECK(vkResetCommandPool(s->vk, s->pool, 0)) != VK_SUCCESS) return OB_ERR_VULKAN;
    uint64_t allocs0 = ob_arena_allocator_count(&s->pool_alloc);
    uint64_t t0 = ob_time_ns();
    if (OB_VK_CHECK(vkBeginCommandBuffer(s->cmd, &bi)) != VK_SUCCESS) return OB_ERR_VULKAN;
    vkCmdBindPipeline(s->cmd, VK_PIPELINE_BIND_POINT_GRAPHICS,
                      instanced ? s->pipeline_instanced : s->pipeline);
    VkViewport viewport = {0.0f, 0.0f, (float)s->width, (float)s->height, 0.0f, 1.0f};
    VkRect2D scissor = {{0, 0}, {s->width, s->height}};
    vkCmdSetViewport(s->cmd, 0, 1, &viewport);
    vkCmdSetScissor(s->cmd, 0, 1, &scissor);
    VkBuffer vb = VK_NULL_HANDLE, ib = VK_NULL_HANDLE;
    uint32_t binds = 0, commands = 3;
    if (instanced) {
        /* The frame's instance data written (as a dynamic scene must), bound
         * once. */
        memcpy(s->instance_data, s->rows, (size_t)ROW_SIZE * s->count);
        VkBuffer inst = ob_buffer_vk(s->dev, s->instances);
        VkDeviceSize zero = 0;
        vkCmdBindVertexBuffers(s->cmd, 1, 1, &inst, &zero);
        vkCmdPushConstants(s->cmd, s->layout_instanced, VK_SHADER_STAGE_VERTEX_BIT, 0, 64,
                           s->view_proj);
        binds++;
        commands++;
    }
    /* Buffers bound when the mesh changes; per draw the push block and the
     * draw, or, instanced, a run of one mesh in one draw. */
    for (uint32_t i = 0; i < s->count;) {
        const raw_draw *dr = &s->draws[i];
        if (dr->vb != vb) {
            VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(s->cmd, 0, 1, &dr->vb, &offset);
            vb = dr->vb;
            binds++;
        }
        if (dr->ib != ib) {
            vkCmdBindIndexBuffer(s->cmd, dr->ib, 0, VK_INDEX_TYPE_UINT32);
            ib = dr->ib;
            binds++;
        }
        uint32_t j = i + 1;
        if (instanced) {
            while (j < s->count && s->draws[j].vb == vb && s->draws[j].ib == ib &&
                   s->draws[j].index_count == dr->index_count &&
                   s->draws[j].first_index == dr->first_index &&
                   s->draws[j].vertex_offset == dr->vertex_offset)
                j++;
        } else {
            vkCmdPushConstants(s->cmd, s->layout, VK_SHADER_STAGE_VERTEX_BIT, 0, PUSH_SIZE,
                               &s->push[32 * i]);
            commands++;
        }
        vkCmdDrawIndexed(s->cmd, dr->index_count, j - i, dr->first_index, dr->vertex_offset,
                         instanced ? i : 0);
        commands++;
        i = j;
    }
    if (OB_VK_CHECK(vkEndCommandBuffer(s->cmd)) != VK_SUCCESS) return OB_ERR_VULKAN;
    uint64_t ns = ob_time_ns() - t0;
    /* Pipeline, viewport, scissor, then per draw push + draw, plus binds. */
    *out = (ob_bench_raw_sample){.ns = ns, .draws = s->count, .buffer_binds = binds,
                                 .commands = commands + binds,
                                 .host_allocs = ob_arena_allocator_count(&s->pool_alloc) - allocs0};
    return OB_OK;
}

ob_result ob_bench_raw_record(ob_bench_raw *s, ob_bench_raw_sample *out)
{
    return record(s, out, false);
}

ob_result ob_bench_raw_record_instanced(ob_bench_raw *s, ob_bench_raw_sample *out)
{
    return record(s, out, true);
}

/* The targets and the timestamp pair of ob_bench_raw_gpu_ms. */
static ob_result make_timing(raw_state *s)
{
    ob_result r = OB_OK;
    s->color = ob_image_create(s->dev, &(ob_image_desc){
        .width = s->width, .height = s->height, .format = COLOR_FORMAT,
        .usage = OB_IMAGE_COLOR_TARGET, .name = "raw baseline color"}, &r);
    if (r == OB_OK)
        s->depth = ob_image_create(s->dev, &(ob_image_desc){
            .width = s->width, .height = s->height, .format = DEPTH_FORMAT,
            .usage = OB_IMAGE_DEPTH_TARGET, .name = "raw baseline depth"}, &r);
    s->tick_ns = ob_device_timestamp_period_ns(s->dev);
    if (r != OB_OK || s->tick_ns <= 0.0) return r;
    VkQueryPoolCreateInfo qci = {.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO,
                                 .queryType = VK_QUERY_TYPE_TIMESTAMP, .queryCount = 2};
    return ob_result_from_vk(OB_VK_CHECK(vkCreateQueryPool(s->vk, &qci, NULL, &s->queries)));
}

/* A target's contents discarded (UNDEFINED) for `layout`, after the last
 * execution's writes at `stages`, before this one's reads and writes. */
static VkImageMemoryBarrier2 target_barrier(VkImage image, VkImageAspectFlags aspect,
                                            VkPipelineStageFlags2 stages, VkAccessFlags2 write,
                                            VkAccessFlags2 read, VkImageLayout layout)
{
    return (VkImageMemoryBarrier2){
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = stages, .srcAccessMask = write,
        .dstStageMask = stages, .dstAccessMask = write | read,
        .oldLayout = VK_IMAGE_LAYOUT_UNDEFINED, .newLayout = layout,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = image, .subresourceRange = {aspect, 0, 1, 0, 1}};
}

/* Executes the recording in the secondary: the targets cleared (their old
 * contents discarded: UNDEFINED, after the last execution's writes), the
 * secondary inside dynamic rendering, a timestamp on each side; submitted
 * and waited for. */
static ob_result execute(raw_state *s, double *out_ms)
{
    *out_ms = NAN;
    if (!s->queries) return OB_OK;
    VkCommandBuffer cmd;
    ob_result r = ob_device_oneshot_begin(s->dev, &cmd);
    if (r != OB_OK) return r;
    vkCmdResetQueryPool(cmd, s->queries, 0, 2);
    const VkPipelineStageFlags2 tests = VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                                        VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    VkImageMemoryBarrier2 barriers[2] = {
        target_barrier(ob_image_vk(s->dev, s->color), VK_IMAGE_ASPECT_COLOR_BIT,
                       VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT,
                       VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL),
        target_barrier(ob_image_vk(s->dev, s->depth), VK_IMAGE_ASPECT_DEPTH_BIT, tests,
                       VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                       VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
                       VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL),
    };
    vkCmdPipelineBarrier2(cmd, &(VkDependencyInfo){.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO,
                                                   .imageMemoryBarrierCount = 2,
                                                   .pImageMemoryBarriers = barriers});
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, s->queries, 0);
    VkRenderingAttachmentInfo color = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(s->dev, s->color),
        .imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    VkRenderingAttachmentInfo depth = {
        .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
        .imageView = ob_image_view(s->dev, s->depth),
        .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR, .storeOp = VK_ATTACHMENT_STORE_OP_STORE};
    /* Reversed Z: the far plane at depth 0. */
    depth.clearValue.depthStencil.depth = 0.0f;
    vkCmdBeginRendering(cmd, &(VkRenderingInfo){
        .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
        .flags = VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT,
        .renderArea = {{0, 0}, {s->width, s->height}}, .layerCount = 1,
        .colorAttachmentCount = 1, .pColorAttachments = &color, .pDepthAttachment = &depth});
    vkCmdExecuteCommands(cmd, 1, &s->cmd);
    vkCmdEndRendering(cmd);
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, s->queries, 1);
    r = ob_device_oneshot_submit(s->dev, cmd);
    if (r != OB_OK) return r;
    uint64_t ts[2];
    VkResult vr = OB_VK_CHECK(vkGetQueryPoolResults(s->vk, s->queries, 0, 2, sizeof ts, ts,
                                                    sizeof ts[0], VK_QUERY_RESULT_64_BIT |
                                                                      VK_QUERY_RESULT_WAIT_BIT));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    *out_ms = (double)(ts[1] - ts[0]) * s->tick_ns * 1e-6;
    return OB_OK;
}

ob_result ob_bench_raw_gpu_ms(ob_bench_raw *s, bool instanced, double *out_ms)
{
    ob_bench_raw_sample sample;
    ob_result r = record(s, &sample, instanced);
    if (r == OB_OK) r = execute(s, out_ms);
    else *out_ms = NAN;
    return r;
}

void ob_bench_raw_destroy(ob_bench_raw *s)
{
    if (!s) return;
    if (s->queries) vkDestroyQueryPool(s->vk, s->queries, NULL);
    if (s->color.id) ob_image_destroy(s->dev, s->color);
    if (s->depth.id) ob_image_destroy(s->dev, s->depth);
    if (s->pool) vkDestroyCommandPool(s->vk, s->pool, &s->pool_alloc.callbacks);
    ob_arena_allocator_release(&s->pool_alloc);
    if (s->pipeline) vkDestroyPipeline(s->vk, s->pipeline, NULL);
    if (s->pipeline_instanced) vkDestroyPipeline(s->vk, s->pipeline_instanced, NULL);
    if (s->layout) vkDestroyPipelineLayout(s->vk, s->layout, NULL);
    if (s->layout_instanced) vkDestroyPipelineLayout(s->vk, s->layout_instanced, NULL);
    if (s->vert) vkDestroyShaderModule(s->vk, s->vert, NULL);
    if (s->vert_instanced) vkDestroyShaderModule(s->vk, s->vert_instanced, NULL);
    if (s->instances.id) ob_buffer_destroy(s->dev, s->instances);
    if (s->frag) vkDestroyShaderModule(s->vk, s->frag, NULL);
    ob_free(s->draws);
    ob_aligned_free(s->push);
    ob_aligned_free(s->rows);
    ob_free(s);
}

ob_bench_raw *ob_bench_raw_create(ob_demo *d, const ob_view *v, ob_result *out_result)
{
    if (!v || v->item_count == 0) {
        OB_LOG_E("bench", "raw baseline: view '%s' has no draws to record",
                 v ? v->name : "(none)");
        *out_result = OB_ERR_INVALID_ARGUMENT;
        return NULL;
    }
    ob_bench_raw *s = ob_calloc(1, sizeof *s);
    if (!s) {
        *out_result = OB_ERR_OUT_OF_HOST_MEMORY;
        return NULL;
    }
    *s = (ob_bench_raw){.vk = ob_device_vk(ob_renderer_device(d->world.r)),
                        .dev = ob_renderer_device(d->world.r), .width = v->width, .height = v->height};
    memcpy(s->view_proj, v->view_proj, sizeof s->view_proj);
    ob_result r = gather(d, v, s);
    if (r == OB_OK) r = make_pipeline(d, s, false);
    if (r == OB_OK) r = make_pipeline(d, s, true);
    if (r == OB_OK) {
        s->instances = ob_buffer_create(s->dev, &(ob_buffer_desc){
            .size = (uint64_t)ROW_SIZE * s->count, .usage = OB_BUFFER_VERTEX,
            .host_visible = true, .name = "raw baseline instances"}, &r);
        s->instance_data = ob_buffer_mapped(s->dev, s->instances);
    }
    if (r == OB_OK) r = make_commands(d, s);
    if (r == OB_OK) r = make_timing(s);
    *out_result = r;
    if (r == OB_OK) return s;
    OB_LOG_E("bench", "raw baseline on view '%s' failed: %s", v->name, ob_result_name(r));
    ob_bench_raw_destroy(s);
    return NULL;
}
