#include "ob_pipeline_manager.h"

#include "ob_math.h"
#include "ob_resources_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FRAME_SLOTS 4
#define MAX_CHUNKS 64
#define PACK_CACHE_SIZE 256     /* power of two */
#define SET_CACHE_MIN 64        /* power of two; the set cache doubles when half full */
#define SETS_PER_POOL 128
#define MAX_POOLS 32
/* Set-0 sets a frame slot's cache may keep from frame to frame: past this,
 * the slot's pools are reset and the cache emptied when the slot begins its
 * next frame (the sets of programs no longer drawn would otherwise be kept
 * forever, issue 25.9). A frame may still use up to MAX_POOLS pools. */
#define SET_CACHE_LIMIT 1024

/* Ring chunks are raw Vulkan objects, not ob_buffer handles: a worker may
 * grow its ring while recording, and the handle pool belongs to the render
 * thread (creating one here raced with other workers' handle lookups). */
typedef struct ring_chunk {
    VkDeviceMemory memory;
    VkBuffer vk;                /* what the draws read: bound, and in the sets */
    uint8_t *mapped;            /* what the host writes: vk's memory, or stage's */
    VkBuffer stage;             /* a staged ring: the host buffer copied to vk */
    VkDeviceMemory stage_memory;
    uint64_t size, used;
} ring_chunk;

/* Where a block was last packed in this frame, and what it contained. An
 * entry belongs to the frame it was last claimed in; `packed` says it holds
 * a block packed in that frame (a claimed entry is packed in the same draw). */
typedef struct pack_entry {
    const ob_param_mapping *mapping;
    uint64_t frame_serial;
    bool packed;
    uint32_t chunk;
    uint32_t offset;
    uint64_t content_hash;
} pack_entry;

/* Set-0 descriptor set of a (layout, ring chunk) pair; sets live as long as
 * the chunk, so they are written once. */
typedef struct set_entry {
    VkDescriptorSetLayout layout;
    uint32_t chunk;
    VkDescriptorSet set;
} set_entry;

typedef struct frame_ring {
    ring_chunk chunks[MAX_CHUNKS];
    uint32_t chunk_count, current;
    VkDescriptorPool pools[MAX_POOLS];
    uint32_t pool_count;
    uint32_t pool_in_use, sets_in_pool;   /* pools after pool_in_use are empty */
    set_entry *sets;            /* open addressing, set_cap entries (power of two) */
    uint32_t set_cap, set_count;
} frame_ring;

typedef struct bound_state {
    VkPipeline pipeline;
    VkPipelineLayout layout;
    VkDescriptorSet set0;
    uint32_t offsets[OB_PROGRAM_MAX_UBOS];
    uint32_t resource_ids[OB_PROGRAM_MAX_RESOURCES * 2];
    bool resources_valid;
    uint8_t push[OB_PUSH_CONSTANT_MAX];
    bool push_valid;
    VkBuffer vb, ib;
    VkBuffer instances;         /* binding 1: the ring chunk of the per-instance blocks */
    uint32_t vb_id, ib_id;      /* handles of vb and ib: an equal id needs no lookup */
    uint64_t vb_offset, ib_offset;
    VkIndexType index_type;
    VkViewport viewport;
    VkRect2D scissor;
    bool viewport_valid, scissor_valid;
    bool front_face_valid;
    VkFrontFace front_face;
} bound_state;

/* Blocks up to this size are packed here and copied to the ring: the ring
 * may be write-combined memory (NVIDIA's host-visible types), which the
 * host must not read back (the content hash read each byte of it). */
#define PACK_SCRATCH_BYTES 16384u

struct ob_pipeline_manager {
    ob_device *dev;
    VkDevice vk;
    ob_params params;
    char name[32];
    uint32_t frames_in_flight;
    uint32_t set_cache_limit;   /* SET_CACHE_LIMIT unless a test lowers it */
    uint64_t chunk_size;
    bool staged;                /* desc.staged */
    ob_instance_runs runs;      /* desc.runs, AUTO taken as INSTANCED */
    uint32_t max_draw_indirect; /* draws one multi-draw indirect may hold */
    uint32_t ubo_align;
    PFN_vkCmdPushDescriptorSetKHR push_descriptor;

    frame_ring rings[MAX_FRAME_SLOTS];
    frame_ring *ring;
    uint64_t frame_serial;
    pack_entry pack_cache[PACK_CACHE_SIZE];

    VkCommandBuffer cmd;
    bound_state cur;
    /* desired */
    VkPipeline pipeline;
    uint32_t pipeline_id;
    const ob_program *program;
    ob_buffer vb, ib;
    uint64_t vb_offset, ib_offset;
    VkIndexType index_type;
    VkViewport viewport;
    VkRect2D scissor;
    bool viewport_set, scissor_set;

    const float *world;         /* ob_pipeline_manager_set_world's world and normal, for the next draw */
    bool world_pending;
    bool world_mirrors;         /* the world's 3x3 has a negative determinant */
    bool instances_mirror;      /* the same, for the instanced draw being applied */

    /* What the last full apply of uniforms and resources was made from: while
     * the program and the slot's parameter serial are unchanged, the bound
     * sets are still right and their hash is reused. */
    const ob_program *applied_program;
    uint64_t applied_serial;
    uint64_t applied_hash;
    uint64_t state_hash;        /* pipeline, program and applied_hash folded */
    uint32_t state_pipeline_id; /* the pipeline state_hash was made with */

    ob_cmd_hash hash;
    ob_pipeline_manager_stats stats;
    bool logged_error;
    _Alignas(16) uint8_t pack_scratch[PACK_SCRATCH_BYTES];
};

/* ------------------------------------------------------------ utilities */

static void log_once(ob_pipeline_manager *pm, const char *what)
{
    if (pm->logged_error) return;
    pm->logged_error = true;
    OB_LOG_E("pm", "pipeline manager '%s': %s; draw skipped (further errors this frame "
             "are counted, not logged)", pm->name, what);
}

/* ------------------------------------------------------------ lifecycle */

ob_pipeline_manager *ob_pipeline_manager_create(const ob_pipeline_manager_desc *desc,
                                                ob_result *out_result)
{
    ob_result r = OB_OK;
    ob_pipeline_manager *pm = NULL;
    if (!desc || !desc->device || !desc->registry) {
        r = OB_ERR_INVALID_ARGUMENT;
        goto done;
    }
    pm = ob_calloc(1, sizeof *pm);
    if (!pm) {
        r = OB_ERR_OUT_OF_HOST_MEMORY;
        goto done;
    }
    pm->dev = desc->device;
    pm->vk = ob_device_vk(desc->device);
    r = ob_params_manager(desc->registry, desc->slot, &pm->params);
    if (r != OB_OK) goto fail_free_pm;
    snprintf(pm->name, sizeof pm->name, "%s", desc->name ? desc->name : "pm");
    pm->frames_in_flight = desc->frames_in_flight ? desc->frames_in_flight : 2;
    if (pm->frames_in_flight > MAX_FRAME_SLOTS) pm->frames_in_flight = MAX_FRAME_SLOTS;
    pm->chunk_size = desc->ring_chunk_size ? desc->ring_chunk_size : (4u << 20);
    pm->staged = desc->staged;
    pm->runs = desc->runs == OB_INSTANCE_RUNS_AUTO ? OB_INSTANCE_RUNS_INSTANCED : desc->runs;
    /* $OB_SET_CACHE_LIMIT lowers the bound for tests (tests/gpu/test_pipeline_manager.c)
     * that cannot afford a thousand programs. */
    const char *limit = getenv("OB_SET_CACHE_LIMIT");
    pm->set_cache_limit = limit && atoi(limit) > 0 ? (uint32_t)atoi(limit) : SET_CACHE_LIMIT;
    const VkPhysicalDeviceLimits *lim = &ob_device_properties(pm->dev)->limits;
    pm->ubo_align = (uint32_t)OB_MAX(lim->minUniformBufferOffsetAlignment, 16u);
    pm->max_draw_indirect = OB_MAX(lim->maxDrawIndirectCount, 1u);
    pm->push_descriptor = ob_device_push_descriptor_fn(pm->dev);
    pm->ring = &pm->rings[0];
    pm->hash = ob_cmd_hash_empty();
    goto done;

fail_free_pm:
    ob_free(pm);
    pm = NULL;
done:
    if (r != OB_OK)
        OB_LOG_E("pm", "pipeline manager '%s' not created: %s",
                 desc && desc->name ? desc->name : "pm", ob_result_name(r));
    if (out_result) *out_result = r;
    return pm;
}

static void chunk_destroy(ob_pipeline_manager *pm, ring_chunk *c)
{
    ob_res_vk_buffer b = {.buffer = c->vk, .memory = c->memory};
    ob_res_vk_buffer st = {.buffer = c->stage, .memory = c->stage_memory};
    ob_res_vk_buffer_free(pm->dev, &b);
    ob_res_vk_buffer_free(pm->dev, &st);
    memset(c, 0, sizeof *c);
}

/* A chunk of uniform blocks and per-instance blocks, through the resources'
 * one buffer path: a host-visible, coherent, persistently mapped buffer the
 * draws read, or, staged, such a buffer that the frame copies to a
 * device-local one the draws read. Never a discrete GPU's device-local
 * host-visible (BAR) memory: on the H100 machine that memory is mapped
 * uncached, and recording 8 views x 10k took 14.2 ms there instead of 2.7
 * (the GPU's reads got faster: 5.9 ms against 10.7 from host memory). On
 * the H200 (2026-11-28), with the host only writing whole blocks, it still
 * took 14-15 ms against 2.0 staged, and the GPU time of 16 views x 100k
 * grew from 11.4 ms staged to 30.5 (docs/benchmark.md, session 21). The
 * host only writes the ring, never reads it (blocks are packed in
 * pm->pack_scratch and copied): NVIDIA's host-visible memory is
 * write-combined. [own thread] */
static ob_result chunk_create(ob_pipeline_manager *pm, ring_chunk *c)
{
    ob_res_vk_buffer host, dev;
    memset(c, 0, sizeof *c);
    const VkBufferUsageFlags read = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    ob_result r = ob_res_vk_buffer_make(pm->dev, pm->chunk_size,
                                        pm->staged ? VK_BUFFER_USAGE_TRANSFER_SRC_BIT : read,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                            VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                        true, pm->staged ? "uniform ring (host side) of pipeline manager"
                                                         : "uniform ring of pipeline manager",
                                        pm->name, &host);
    if (r != OB_OK) return r;
    c->mapped = host.mapped;
    c->size = pm->chunk_size;
    if (!pm->staged) {
        c->vk = host.buffer;
        c->memory = host.memory;
    } else {
        r = ob_res_vk_buffer_make(pm->dev, pm->chunk_size, read | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, false,
                                  "uniform ring of pipeline manager", pm->name, &dev);
        if (r != OB_OK) {
            ob_res_vk_buffer_free(pm->dev, &host);
            memset(c, 0, sizeof *c);
            return r;
        }
        c->stage = host.buffer;
        c->stage_memory = host.memory;
        c->vk = dev.buffer;
        c->memory = dev.memory;
        ob_device_set_name(pm->dev, VK_OBJECT_TYPE_BUFFER, (uint64_t)c->stage, pm->name);
    }
    ob_device_set_name(pm->dev, VK_OBJECT_TYPE_BUFFER, (uint64_t)c->vk, pm->name);
    return OB_OK;
}

uint64_t ob_pipeline_manager_record_uploads(ob_pipeline_manager *pm, VkCommandBuffer cmd)
{
    if (!pm->staged) return 0;
    uint64_t bytes = 0;
    const frame_ring *fr = pm->ring;
    for (uint32_t i = 0; i < fr->chunk_count; i++) {
        const ring_chunk *c = &fr->chunks[i];
        if (!c->used) continue;
        VkBufferCopy region = {.srcOffset = 0, .dstOffset = 0, .size = c->used};
        vkCmdCopyBuffer(cmd, c->stage, c->vk, 1, &region);
        bytes += c->used;
    }
    return bytes;
}

void ob_pipeline_manager_destroy(ob_pipeline_manager *pm)
{
    if (!pm) return;
    for (uint32_t s = 0; s < MAX_FRAME_SLOTS; s++) {
        frame_ring *fr = &pm->rings[s];
        for (uint32_t i = 0; i < fr->chunk_count; i++) chunk_destroy(pm, &fr->chunks[i]);
        for (uint32_t i = 0; i < fr->pool_count; i++)
            vkDestroyDescriptorPool(pm->vk, fr->pools[i], NULL);
        ob_free(fr->sets);
    }
    ob_free(pm);
}

/* Empties a frame slot's set cache: its previous frame has completed, so
 * none of its sets is in use. */
static void set_cache_reset(ob_pipeline_manager *pm, frame_ring *fr)
{
    for (uint32_t i = 0; i < fr->pool_count; i++) vkResetDescriptorPool(pm->vk, fr->pools[i], 0);
    fr->pool_in_use = fr->sets_in_pool = 0;
    if (fr->sets) memset(fr->sets, 0, (size_t)fr->set_cap * sizeof *fr->sets);
    fr->set_count = 0;
    pm->stats.descriptor_set_cache_resets++;
}

void ob_pipeline_manager_begin_frame(ob_pipeline_manager *pm, uint32_t slot, uint64_t frame_serial)
{
    pm->ring = &pm->rings[slot % MAX_FRAME_SLOTS];
    if (pm->ring->set_count > pm->set_cache_limit) set_cache_reset(pm, pm->ring);
    for (uint32_t i = 0; i < pm->ring->chunk_count; i++) pm->ring->chunks[i].used = 0;
    pm->ring->current = 0;
    pm->frame_serial = frame_serial;
    pm->logged_error = false;
}

void ob_pipeline_manager_begin(ob_pipeline_manager *pm, VkCommandBuffer cmd)
{
    pm->cmd = cmd;
    memset(&pm->cur, 0, sizeof pm->cur);
    pm->pipeline = VK_NULL_HANDLE;
    pm->program = NULL;
    pm->vb = pm->ib = (ob_buffer){0};
    pm->viewport_set = pm->scissor_set = false;
    pm->world_pending = false;
    pm->applied_program = NULL;
    pm->hash = ob_cmd_hash_empty();
}

ob_cmd_hash ob_pipeline_manager_end(ob_pipeline_manager *pm)
{
    ob_cmd_hash h = pm->hash;
    pm->cmd = VK_NULL_HANDLE;
    pm->hash = ob_cmd_hash_empty();
    return h;
}

VkCommandBuffer ob_pipeline_manager_command_buffer(const ob_pipeline_manager *pm) { return pm->cmd; }
ob_params *ob_pipeline_manager_params(ob_pipeline_manager *pm) { return &pm->params; }

/* ------------------------------------------------------------ desired state */

void ob_pipeline_manager_set_pipeline(ob_pipeline_manager *pm, VkPipeline pipeline, uint32_t pipeline_id,
                        const ob_program *program)
{
    pm->pipeline = pipeline;
    pm->pipeline_id = pipeline_id;
    pm->program = program;
}

/* The per-draw block's world matrix (column-major 4x4) mirrors. */
static bool world_mirrors(const float world_normal[32])
{
    return ob_det3_negative(world_normal, 4, 1);
}

/* The same of a per-instance block (three rows of the world matrix). */
static bool rows_mirror(const float rows[OB_INSTANCE_FLOATS])
{
    return ob_det3_negative(rows, 1, 4);
}

void ob_pipeline_manager_set_world(ob_pipeline_manager *pm, const float world_normal[32])
{
    pm->world = world_normal;
    pm->world_pending = true;
    pm->world_mirrors = world_mirrors(world_normal);
}

void ob_pipeline_manager_set_vertex_buffer(ob_pipeline_manager *pm, ob_buffer buf, uint64_t offset)
{
    pm->vb = buf;
    pm->vb_offset = offset;
}

void ob_pipeline_manager_set_index_buffer(ob_pipeline_manager *pm, ob_buffer buf, uint64_t offset,
                            VkIndexType type)
{
    pm->ib = buf;
    pm->ib_offset = offset;
    pm->index_type = type;
}

void ob_pipeline_manager_set_viewport(ob_pipeline_manager *pm, float x, float y, float w, float h)
{
    pm->viewport = (VkViewport){x, y, w, h, 0.0f, 1.0f};
    pm->viewport_set = true;
}

void ob_pipeline_manager_set_scissor(ob_pipeline_manager *pm, int32_t x, int32_t y, uint32_t w, uint32_t h)
{
    pm->scissor = (VkRect2D){{x, y}, {w, h}};
    pm->scissor_set = true;
}

/* ------------------------------------------------------------ uniform ring */

static ob_result ring_alloc_aligned(ob_pipeline_manager *pm, uint32_t size, uint32_t align,
                                    uint32_t *out_chunk, uint32_t *out_offset)
{
    frame_ring *fr = pm->ring;
    for (;;) {
        if (fr->current < fr->chunk_count) {
            ring_chunk *c = &fr->chunks[fr->current];
            uint64_t off = (c->used + align - 1) / align * align;
            if (off + size <= c->size) {
                c->used = off + size;
                *out_chunk = fr->current;
                *out_offset = (uint32_t)off;
                return OB_OK;
            }
            fr->current++;
            continue;
        }
        if (fr->chunk_count >= MAX_CHUNKS) return OB_ERR_LIMIT;
        ob_result r = chunk_create(pm, &fr->chunks[fr->chunk_count]);
        if (r != OB_OK) return r;
        fr->chunk_count++;
    }
}

static ob_result ring_alloc(ob_pipeline_manager *pm, uint32_t size, uint32_t *out_chunk,
                            uint32_t *out_offset)
{
    return ring_alloc_aligned(pm, size, pm->ubo_align, out_chunk, out_offset);
}

/* The cache entry of a mapping, claimed for this frame: its own entry, or a
 * stale one of an earlier frame, or an empty one. An entry claimed in this
 * frame is never handed to another mapping, so the blocks of one draw get
 * distinct entries. Entries never become empty again, so probing may stop at
 * the first empty one. NULL when the cache is full of this frame's blocks. */
static pack_entry *pack_slot(ob_pipeline_manager *pm, const ob_param_mapping *map)
{
    uint32_t h = (uint32_t)(((uintptr_t)map >> 4) * 2654435761u) & (PACK_CACHE_SIZE - 1);
    pack_entry *reuse = NULL;
    for (uint32_t i = 0; i < PACK_CACHE_SIZE; i++) {
        pack_entry *e = &pm->pack_cache[(h + i) & (PACK_CACHE_SIZE - 1)];
        if (e->mapping == map) {
            if (e->frame_serial != pm->frame_serial)
                *e = (pack_entry){.mapping = map, .frame_serial = pm->frame_serial};
            return e;
        }
        if (!e->mapping) {
            if (!reuse) reuse = e;
            break;
        }
        if (!reuse && e->frame_serial != pm->frame_serial) reuse = e;
    }
    if (!reuse) return NULL;
    *reuse = (pack_entry){.mapping = map, .frame_serial = pm->frame_serial};
    return reuse;
}

static ob_result new_pool(ob_pipeline_manager *pm, frame_ring *fr)
{
    if (fr->pool_count >= MAX_POOLS) return OB_ERR_LIMIT;
    VkDescriptorPoolSize size = {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
                                 SETS_PER_POOL * OB_PROGRAM_MAX_UBOS};
    VkDescriptorPoolCreateInfo ci = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO,
        .maxSets = SETS_PER_POOL,
        .poolSizeCount = 1,
        .pPoolSizes = &size,
    };
    VkResult vr = OB_VK_CHECK_CREATE(vkCreateDescriptorPool(pm->vk, &ci, NULL, &fr->pools[fr->pool_count]));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    fr->pool_in_use = fr->pool_count++;
    fr->sets_in_pool = 0;
    return OB_OK;
}

static set_entry *set_probe(set_entry *sets, uint32_t cap, VkDescriptorSetLayout layout,
                            uint32_t chunk)
{
    uint32_t h = (uint32_t)((((uintptr_t)layout >> 4) ^ chunk) * 2654435761u);
    for (uint32_t i = 0;; i++) {
        set_entry *e = &sets[(h + i) & (cap - 1)];
        if (!e->set || (e->layout == layout && e->chunk == chunk)) return e;
    }
}

/* Keeps the set cache at most half full (a frame may use any number of
 * programs). The old table is kept when growing fails. */
static ob_result set_cache_reserve(frame_ring *fr)
{
    if (fr->set_cap && (fr->set_count + 1) * 2 <= fr->set_cap) return OB_OK;
    uint32_t cap = fr->set_cap ? fr->set_cap * 2 : SET_CACHE_MIN;
    set_entry *sets = ob_calloc(cap, sizeof *sets);
    if (!sets) return OB_ERR_OUT_OF_HOST_MEMORY;
    for (uint32_t i = 0; i < fr->set_cap; i++) {
        const set_entry *e = &fr->sets[i];
        if (e->set) *set_probe(sets, cap, e->layout, e->chunk) = *e;
    }
    ob_free(fr->sets);
    fr->sets = sets;
    fr->set_cap = cap;
    return OB_OK;
}

static ob_result uniform_set(ob_pipeline_manager *pm, const ob_program *prog, uint32_t chunk,
                             VkDescriptorSet *out_set)
{
    frame_ring *fr = pm->ring;
    ob_result res = set_cache_reserve(fr);
    if (res != OB_OK) return res;
    set_entry *slot = set_probe(fr->sets, fr->set_cap, prog->set_layouts[0], chunk);
    if (slot->set) {
        *out_set = slot->set;
        return OB_OK;
    }
    if (fr->pool_count == 0 || fr->sets_in_pool >= SETS_PER_POOL) {
        if (fr->pool_count > 0 && fr->pool_in_use + 1 < fr->pool_count) {
            fr->pool_in_use++;   /* emptied by the last reset */
            fr->sets_in_pool = 0;
        } else {
            ob_result r = new_pool(pm, fr);
            if (r != OB_OK) return r;
        }
    }
    VkDescriptorSetAllocateInfo ai = {
        .sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO,
        .descriptorPool = fr->pools[fr->pool_in_use],
        .descriptorSetCount = 1,
        .pSetLayouts = &prog->set_layouts[0],
    };
    VkDescriptorSet set;
    VkResult vr = OB_VK_CHECK_CREATE(vkAllocateDescriptorSets(pm->vk, &ai, &set));
    if (vr != VK_SUCCESS) return ob_result_from_vk(vr);
    fr->sets_in_pool++;
    pm->stats.descriptor_sets_allocated++;
    VkDescriptorBufferInfo infos[OB_PROGRAM_MAX_UBOS];
    VkWriteDescriptorSet writes[OB_PROGRAM_MAX_UBOS];
    for (uint32_t i = 0; i < prog->ubo_count; i++) {
        infos[i] = (VkDescriptorBufferInfo){fr->chunks[chunk].vk, 0, prog->ubos[i].size};
        writes[i] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstSet = set,
            .dstBinding = prog->ubos[i].binding,
            .descriptorCount = 1,
            .descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC,
            .pBufferInfo = &infos[i],
        };
    }
    vkUpdateDescriptorSets(pm->vk, prog->ubo_count, writes, 0, NULL);
    *slot = (set_entry){prog->set_layouts[0], chunk, set};
    fr->set_count++;
    *out_set = set;
    return OB_OK;
}

/* Pack the program's uniform blocks (only those whose parameters changed)
 * and bind set 0 if the set or any offset differs. */
static ob_result apply_uniforms(ob_pipeline_manager *pm, const ob_program *prog, uint64_t *h)
{
    if (prog->ubo_count == 0) return OB_OK;
    pack_entry *entries[OB_PROGRAM_MAX_UBOS];
    pack_entry uncached[OB_PROGRAM_MAX_UBOS];
    bool pack[OB_PROGRAM_MAX_UBOS];
    uint32_t chunk = UINT32_MAX;
    bool all_same_chunk = true;
    for (uint32_t i = 0; i < prog->ubo_count; i++) {
        const ob_param_mapping *map = prog->ubos[i].mapping;
        pack_entry *e = pack_slot(pm, map);
        if (!e) {
            uncached[i] = (pack_entry){.mapping = map, .frame_serial = pm->frame_serial};
            e = &uncached[i];
        }
        bool fresh = e->packed && !ob_params_pack_needed(&pm->params, map);
        pack[i] = !fresh;
        entries[i] = e;
        if (fresh) {
            if (chunk == UINT32_MAX) chunk = e->chunk;
            else if (chunk != e->chunk) all_same_chunk = false;
        }
    }
    /* Blocks of one draw share one set, so they must sit in one chunk:
     * repack everything when the fresh ones are spread or stale. */
    if (!all_same_chunk || (chunk != UINT32_MAX && chunk != pm->ring->current)) {
        for (uint32_t i = 0; i < prog->ubo_count; i++) pack[i] = true;
        chunk = UINT32_MAX;
    }
    for (uint32_t i = 0; i < prog->ubo_count; i++)
        if (!pack[i]) pm->stats.blocks_reused++;
    for (int attempt = 0; attempt < 2; attempt++) {
        bool moved = false;
        for (uint32_t i = 0; i < prog->ubo_count; i++) {
            if (!pack[i]) continue;
            uint32_t c = 0, off = 0;
            ob_result r = ring_alloc(pm, prog->ubos[i].size, &c, &off);
            if (r != OB_OK) {
                for (uint32_t j = 0; j < prog->ubo_count; j++)
                    if (pack[j]) entries[j]->packed = false;
                return r;
            }
            if (chunk != UINT32_MAX && c != chunk) {
                /* Ring moved to a new chunk mid-draw: repack all there. */
                for (uint32_t j = 0; j < prog->ubo_count; j++) pack[j] = true;
                chunk = UINT32_MAX;
                moved = true;
                break;
            }
            chunk = c;
            uint8_t *dst = pm->ring->chunks[c].mapped + off;
            const uint32_t size = prog->ubos[i].size;
            uint8_t *packed = size <= PACK_SCRATCH_BYTES ? pm->pack_scratch : dst;
            ob_params_pack(&pm->params, prog->ubos[i].mapping, packed, true);
            if (packed != dst) memcpy(dst, packed, size);
            *entries[i] = (pack_entry){prog->ubos[i].mapping, pm->frame_serial, true, c, off,
                                       ob_hash_block(OB_HASH_SEED, packed, size)};
            pack[i] = false;
            pm->stats.blocks_packed++;
            pm->stats.uniform_bytes += prog->ubos[i].size;
        }
        if (!moved) break;
    }
    VkDescriptorSet set;
    ob_result r = uniform_set(pm, prog, chunk, &set);
    if (r != OB_OK) return r;
    uint32_t offsets[OB_PROGRAM_MAX_UBOS];
    bool same = pm->cur.set0 == set;
    for (uint32_t i = 0; i < prog->ubo_count; i++) {
        offsets[i] = entries[i]->offset;
        *h = ob_hash_u64(*h, entries[i]->content_hash);
        if (pm->cur.offsets[i] != offsets[i]) same = false;
    }
    pm->stats.descriptor_binds_requested++;
    if (!same) {
        vkCmdBindDescriptorSets(pm->cmd, prog->bind_point, prog->layout, 0, 1, &set,
                                prog->ubo_count, offsets);
        pm->cur.set0 = set;
        memcpy(pm->cur.offsets, offsets, sizeof offsets[0] * prog->ubo_count);
        pm->stats.descriptor_binds_issued++;
    }
    return OB_OK;
}

static bool sampler_is_valid(const ob_device *dev, ob_sampler s)
{
    return ob_pool_get(&ob_device_registry(dev)->samplers, s.id) != NULL;
}

/* Resolve the program's images, samplers and buffers from parameters and push
 * them when any differs from what is bound. A zero or stale handle fails with
 * OB_ERR_INVALID_HANDLE and *out_bad naming the parameter; handles are checked
 * before they are resolved so that the caller logs one line, not one per
 * lookup. */
static ob_result apply_resources(ob_pipeline_manager *pm, const ob_program *prog, uint64_t *h,
                                 ob_param *out_bad)
{
    if (prog->resource_count == 0) return OB_OK;
    uint32_t ids[OB_PROGRAM_MAX_RESOURCES * 2];
    VkDescriptorImageInfo images[OB_PROGRAM_MAX_RESOURCES];
    VkDescriptorBufferInfo buffers[OB_PROGRAM_MAX_RESOURCES];
    VkWriteDescriptorSet writes[OB_PROGRAM_MAX_RESOURCES];
    for (uint32_t i = 0; i < prog->resource_count; i++) {
        const ob_program_resource *res = &prog->resources[i];
        ob_image img = {0};
        ob_sampler smp = {0};
        ob_buffer buf = {0};
        writes[i] = (VkWriteDescriptorSet){
            .sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,
            .dstBinding = res->binding,
            .descriptorCount = 1,
        };
        images[i] = (VkDescriptorImageInfo){0};
        switch (res->kind) {
        case OB_BINDING_COMBINED_IMAGE_SAMPLER:
            ob_params_get_texture(&pm->params, res->param, &img);
            ob_params_get_sampler(&pm->params, res->sampler, &smp);
            if (!ob_image_is_valid(pm->dev, img)) goto bad_param;
            if (!sampler_is_valid(pm->dev, smp)) {
                *out_bad = res->sampler;
                return OB_ERR_INVALID_HANDLE;
            }
            images[i].imageView = ob_image_view(pm->dev, img);
            images[i].sampler = ob_sampler_vk(pm->dev, smp);
            images[i].imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
            writes[i].pImageInfo = &images[i];
            break;
        case OB_BINDING_SAMPLED_IMAGE:
        case OB_BINDING_STORAGE_IMAGE:
            ob_params_get_texture(&pm->params, res->param, &img);
            if (!ob_image_is_valid(pm->dev, img)) goto bad_param;
            images[i].imageView = ob_image_view(pm->dev, img);
            images[i].imageLayout = res->kind == OB_BINDING_STORAGE_IMAGE
                                        ? VK_IMAGE_LAYOUT_GENERAL
                                        : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            writes[i].descriptorType = res->kind == OB_BINDING_STORAGE_IMAGE
                                           ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE
                                           : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
            writes[i].pImageInfo = &images[i];
            break;
        case OB_BINDING_SAMPLER:
            ob_params_get_sampler(&pm->params, res->param, &smp);
            if (!sampler_is_valid(pm->dev, smp)) goto bad_param;
            images[i].sampler = ob_sampler_vk(pm->dev, smp);
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_SAMPLER;
            writes[i].pImageInfo = &images[i];
            break;
        case OB_BINDING_STORAGE_BUFFER:
        case OB_BINDING_UNIFORM_BUFFER:
            ob_params_get_buffer(&pm->params, res->param, &buf);
            if (!ob_buffer_is_valid(pm->dev, buf)) goto bad_param;
            buffers[i] = (VkDescriptorBufferInfo){ob_buffer_vk(pm->dev, buf), 0, VK_WHOLE_SIZE};
            writes[i].descriptorType = res->kind == OB_BINDING_STORAGE_BUFFER
                                           ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                           : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
            writes[i].pBufferInfo = &buffers[i];
            break;
        }
        ids[2 * i] = img.id ? img.id : buf.id;
        ids[2 * i + 1] = smp.id;
        *h = ob_hash_u64(*h, ((uint64_t)ids[2 * i] << 32) | ids[2 * i + 1]);
        continue;
    bad_param:
        *out_bad = res->param;
        return OB_ERR_INVALID_HANDLE;
    }
    pm->stats.push_descriptor_requested++;
    size_t n = sizeof ids[0] * 2 * prog->resource_count;
    if (!pm->cur.resources_valid || memcmp(pm->cur.resource_ids, ids, n) != 0) {
        pm->push_descriptor(pm->cmd, prog->bind_point, prog->layout, OB_PROGRAM_SET_RESOURCES,
                            prog->resource_count, writes);
        memcpy(pm->cur.resource_ids, ids, n);
        pm->cur.resources_valid = true;
        pm->stats.push_descriptor_issued++;
    }
    return OB_OK;
}

/* The push block from parameters, or for the standard per-draw block
 * straight from ob_pipeline_manager_set_world (world = true). */
static void apply_push_constants(ob_pipeline_manager *pm, const ob_program *prog, bool world,
                                 uint64_t *h)
{
    if (!prog->push_mapping) return;
    pm->stats.push_constant_requested++;
    if (world && prog->push_world_normal) {
        /* Another entity's transforms: always new, not worth a compare. The
         * normal matrix follows from the world matrix: hash the input. */
        *h = ob_hash_block(*h, pm->world, 64);
        vkCmdPushConstants(pm->cmd, prog->layout, prog->push_stages, 0, prog->push_size,
                           pm->world);
        pm->cur.push_valid = false;
        pm->stats.push_constant_issued++;
        return;
    }
    _Alignas(16) uint8_t bytes[OB_PUSH_CONSTANT_MAX];
    ob_params_pack(&pm->params, prog->push_mapping, bytes, true);
    *h = ob_hash_block(*h, bytes, prog->push_size);
    if (!pm->cur.push_valid || memcmp(pm->cur.push, bytes, prog->push_size) != 0) {
        vkCmdPushConstants(pm->cmd, prog->layout, prog->push_stages, 0, prog->push_size, bytes);
        memcpy(pm->cur.push, bytes, prog->push_size);
        pm->cur.push_valid = true;
        pm->stats.push_constant_issued++;
    }
}

/* Everything a draw or dispatch needs, bound only where it differs. Returns
 * the draw-state hash through *h. */
static ob_result apply(ob_pipeline_manager *pm, bool indexed, uint64_t *h)
{
    const ob_program *prog = pm->program;
    if (!pm->cmd) return OB_ERR_WRONG_STATE;
    if (!prog || !pm->pipeline) {
        pm->stats.skipped_draws++;
        log_once(pm, "no pipeline set");
        return OB_ERR_WRONG_STATE;
    }
    bool world = pm->world_pending;
    bool mirrors = world ? pm->world_mirrors : pm->instances_mirror;
    pm->world_pending = false;
    if (world && !prog->push_world_normal) {
        /* Another push layout, or a uniform block reads the world: the
         * parameters derive what the program reads. */
        ob_result wr = ob_params_set_mat4(&pm->params,
                                          ob_param_registry_builtins(pm->params.reg)->world,
                                          pm->world);
        if (wr != OB_OK) {
            pm->stats.skipped_draws++;
            return wr;
        }
    }
    pm->stats.pipeline_binds_requested++;
    if (pm->cur.pipeline != pm->pipeline) {
        vkCmdBindPipeline(pm->cmd, prog->bind_point, pm->pipeline);
        pm->cur.pipeline = pm->pipeline;
        pm->stats.pipeline_binds_issued++;
    }
    if (pm->cur.layout != prog->layout) {
        /* Sets and push constants bound under another layout are not reusable. */
        pm->cur.layout = prog->layout;
        pm->cur.set0 = VK_NULL_HANDLE;
        pm->cur.resources_valid = false;
        pm->cur.push_valid = false;
        pm->applied_program = NULL;
    }
    uint64_t serial = ob_params_serial(&pm->params);
    if (pm->applied_program == prog && pm->applied_serial == serial) {
        /* No parameter changed since this program's sets were bound. */
        pm->stats.blocks_reused += prog->ubo_count;
        pm->stats.descriptor_binds_requested += prog->ubo_count ? 1u : 0u;
        pm->stats.push_descriptor_requested += prog->resource_count ? 1u : 0u;
        if (pm->state_pipeline_id != pm->pipeline_id) {
            pm->state_hash = ob_hash_u64(
                ob_hash_u64(OB_HASH_SEED, ((uint64_t)pm->pipeline_id << 32) | prog->id),
                pm->applied_hash);
            pm->state_pipeline_id = pm->pipeline_id;
        }
        *h = pm->state_hash;
    } else {
        uint64_t hs = OB_HASH_SEED;
        ob_param bad = {0};
        pm->applied_program = NULL;
        ob_result r = apply_uniforms(pm, prog, &hs);
        if (r == OB_OK) r = apply_resources(pm, prog, &hs, &bad);
        if (r != OB_OK) {
            pm->stats.skipped_draws++;
            if (r == OB_ERR_INVALID_HANDLE) {
                char what[160];
                snprintf(what, sizeof what, "parameter '%s' of program '%s' holds an invalid or "
                         "stale handle", ob_param_name(pm->params.reg, bad), prog->name);
                log_once(pm, what);
            } else {
                log_once(pm, ob_result_text(r));
            }
            return r;
        }
        pm->applied_program = prog;
        pm->applied_serial = serial;
        pm->applied_hash = hs;
        pm->state_hash = ob_hash_u64(
            ob_hash_u64(OB_HASH_SEED, ((uint64_t)pm->pipeline_id << 32) | prog->id), hs);
        pm->state_pipeline_id = pm->pipeline_id;
        *h = pm->state_hash;
    }
    apply_push_constants(pm, prog, world, h);
    if (prog->bind_point == VK_PIPELINE_BIND_POINT_COMPUTE) return OB_OK;

    /* A buffer bound in this command buffer is still valid (resources are
     * not destroyed while recording): an equal handle skips the lookup. */
    if (pm->vb.id) {
        if (pm->vb.id != pm->cur.vb_id || pm->vb_offset != pm->cur.vb_offset) {
            VkBuffer vb = ob_buffer_vk(pm->dev, pm->vb);
            if (!vb) {
                pm->stats.skipped_draws++;
                log_once(pm, "the vertex buffer handle is invalid");
                return OB_ERR_INVALID_HANDLE;
            }
            vkCmdBindVertexBuffers(pm->cmd, 0, 1, &vb, &pm->vb_offset);
            pm->cur.vb = vb;
            pm->cur.vb_id = pm->vb.id;
            pm->cur.vb_offset = pm->vb_offset;
            pm->stats.vertex_binds_issued++;
        }
        pm->stats.vertex_binds_requested++;
        *h = ob_hash_u64(*h, ((uint64_t)pm->vb.id << 32) ^ pm->vb_offset);
    }
    if (indexed) {
        if (!pm->ib.id || pm->ib.id != pm->cur.ib_id || pm->ib_offset != pm->cur.ib_offset ||
            pm->index_type != pm->cur.index_type) {
            VkBuffer ib = ob_buffer_vk(pm->dev, pm->ib);
            if (!ib) {
                pm->stats.skipped_draws++;
                log_once(pm, "the index buffer handle is invalid");
                return OB_ERR_INVALID_HANDLE;
            }
            vkCmdBindIndexBuffer(pm->cmd, ib, pm->ib_offset, pm->index_type);
            pm->cur.ib = ib;
            pm->cur.ib_id = pm->ib.id;
            pm->cur.ib_offset = pm->ib_offset;
            pm->cur.index_type = pm->index_type;
            pm->stats.index_binds_issued++;
        }
        pm->stats.index_binds_requested++;
        *h = ob_hash_u64(*h, ((uint64_t)pm->ib.id << 32) ^ pm->ib_offset);
    }
    /* Counter-clockwise is front, as every pipeline had it; a mirroring
     * world transform turns the triangles, so its draws take clockwise
     * (their normals are turned by the normal matrix). Hashed only when
     * clockwise: the hashes of scenes without mirrors stay as they were. */
    VkFrontFace face = mirrors ? VK_FRONT_FACE_CLOCKWISE : VK_FRONT_FACE_COUNTER_CLOCKWISE;
    if (!pm->cur.front_face_valid || pm->cur.front_face != face) {
        vkCmdSetFrontFace(pm->cmd, face);
        pm->cur.front_face = face;
        pm->cur.front_face_valid = true;
    }
    if (mirrors) *h = ob_hash_u64(*h, VK_FRONT_FACE_CLOCKWISE);
    if (pm->viewport_set &&
        (!pm->cur.viewport_valid || memcmp(&pm->cur.viewport, &pm->viewport, sizeof pm->viewport))) {
        vkCmdSetViewport(pm->cmd, 0, 1, &pm->viewport);
        pm->cur.viewport = pm->viewport;
        pm->cur.viewport_valid = true;
    }
    if (pm->scissor_set &&
        (!pm->cur.scissor_valid || memcmp(&pm->cur.scissor, &pm->scissor, sizeof pm->scissor))) {
        vkCmdSetScissor(pm->cmd, 0, 1, &pm->scissor);
        pm->cur.scissor = pm->scissor;
        pm->cur.scissor_valid = true;
    }
    return OB_OK;
}

static void fold(ob_pipeline_manager *pm, uint64_t h)
{
    pm->hash = ob_cmd_hash_concat(pm->hash, (ob_cmd_hash){h, OB_CMD_HASH_BASE, 1});
}

static inline ob_result draw_plain(ob_pipeline_manager *pm, uint32_t vertex_count,
                                   uint32_t instance_count, uint32_t first_vertex,
                                   uint32_t first_instance)
{
    uint64_t h;
    ob_result r = apply(pm, false, &h);
    if (r != OB_OK) return r;
    vkCmdDraw(pm->cmd, vertex_count, instance_count, first_vertex, first_instance);
    h = ob_hash_u64(h, ((uint64_t)vertex_count << 32) | instance_count);
    fold(pm, ob_hash_u64(h, ((uint64_t)first_vertex << 32) | first_instance));
    pm->stats.draws++;
    pm->stats.draw_calls++;
    pm->stats.vertices += (uint64_t)vertex_count * instance_count;
    return OB_OK;
}

static inline ob_result draw_indexed(ob_pipeline_manager *pm, uint32_t index_count,
                                     uint32_t instance_count, uint32_t first_index,
                                     int32_t vertex_offset, uint32_t first_instance)
{
    uint64_t h;
    ob_result r = apply(pm, true, &h);
    if (r != OB_OK) return r;
    vkCmdDrawIndexed(pm->cmd, index_count, instance_count, first_index, vertex_offset,
                     first_instance);
    h = ob_hash_u64(h, ((uint64_t)index_count << 32) | instance_count);
    h = ob_hash_u64(h, (((uint64_t)first_index << 32) | (uint32_t)vertex_offset) ^
                           ((uint64_t)first_instance * 0x9e3779b97f4a7c15ull));
    fold(pm, h);
    pm->stats.draws++;
    pm->stats.draw_calls++;
    pm->stats.vertices += (uint64_t)index_count * instance_count;
    return OB_OK;
}

ob_result ob_pipeline_manager_draw(ob_pipeline_manager *pm, uint32_t vertex_count, uint32_t instance_count,
                     uint32_t first_vertex, uint32_t first_instance)
{
    return draw_plain(pm, vertex_count, instance_count, first_vertex, first_instance);
}

ob_result ob_pipeline_manager_draw_indexed(ob_pipeline_manager *pm, uint32_t index_count,
                             uint32_t instance_count, uint32_t first_index,
                             int32_t vertex_offset, uint32_t first_instance)
{
    return draw_indexed(pm, index_count, instance_count, first_index, vertex_offset,
                        first_instance);
}

ob_result ob_pipeline_manager_draw_data(ob_pipeline_manager *pm, const ob_draw_data *d,
                                        const float world_normal[32])
{
    if (world_normal) ob_pipeline_manager_set_world(pm, world_normal);
    pm->vb = d->vertex_buffer;
    pm->vb_offset = d->vertex_buffer_offset;
    ob_result r;
    if (d->index_buffer.id) {
        pm->ib = d->index_buffer;
        pm->ib_offset = d->index_buffer_offset;
        pm->index_type = d->index_type;
        r = draw_indexed(pm, d->count, d->instance_count, d->first, d->vertex_offset, 0);
    } else {
        r = draw_plain(pm, d->count, d->instance_count, d->first, 0);
    }
    /* The caller's array is not read after the call. */
    pm->world = NULL;
    pm->world_pending = false;
    return r;
}

bool ob_pipeline_manager_instanced(const ob_pipeline_manager *pm)
{
    return pm->program && pm->program->instanced;
}

/* The arguments of a run drawn as multi-draw indirect: count draws of
 * one instance each, the k-th drawing block first + k, written to this
 * frame's ring beside the blocks. */
static ob_result write_run_args(ob_pipeline_manager *pm, const ob_draw_data *d, bool indexed,
                                uint32_t first, uint32_t count, uint32_t *out_chunk,
                                uint32_t *out_offset)
{
    uint32_t stride = indexed ? (uint32_t)sizeof(VkDrawIndexedIndirectCommand)
                              : (uint32_t)sizeof(VkDrawIndirectCommand);
    ob_result r = ring_alloc_aligned(pm, count * stride, 4, out_chunk, out_offset);
    if (r != OB_OK) return r;
    uint8_t *dst = pm->ring->chunks[*out_chunk].mapped + *out_offset;
    if (indexed) {
        VkDrawIndexedIndirectCommand c = {d->count, 1, d->first, d->vertex_offset, first};
        for (uint32_t k = 0; k < count; k++, c.firstInstance++) memcpy(dst + k * stride, &c, sizeof c);
    } else {
        VkDrawIndirectCommand c = {d->count, 1, d->first, first};
        for (uint32_t k = 0; k < count; k++, c.firstInstance++) memcpy(dst + k * stride, &c, sizeof c);
    }
    return OB_OK;
}

/* Count blocks that mirror alike (mirrors), as pm->runs says: one
 * instanced draw, one multi-draw indirect of one instance each, or a
 * direct draw per instance (a single block is an instanced draw of one
 * on every path). */
static ob_result draw_instance_run(ob_pipeline_manager *pm, const ob_draw_data *d,
                                   const float *blocks, uint32_t count, bool mirrors)
{
    /* The blocks go to this frame's ring, at a multiple of the block size
     * from the chunk's start: the chunk is bound once at offset 0 and the
     * draw's first instance picks the blocks. */
    uint32_t chunk, off, size = count * OB_INSTANCE_STRIDE;
    if (size > pm->chunk_size) {
        pm->stats.skipped_draws += count;
        log_once(pm, "an instanced draw's blocks do not fit a ring chunk");
        return OB_ERR_LIMIT;
    }
    ob_result r = ring_alloc_aligned(pm, size, OB_INSTANCE_STRIDE, &chunk, &off);
    if (r != OB_OK) {
        pm->stats.skipped_draws += count;
        log_once(pm, "the ring could not grow for per-instance blocks");
        return r;
    }
    memcpy(pm->ring->chunks[chunk].mapped + off, blocks, size);
    uint32_t first = off / OB_INSTANCE_STRIDE;
    bool indexed = d->index_buffer.id != 0;
    bool multi = pm->runs == OB_INSTANCE_RUNS_MULTI_DRAW && count > 1;
    bool direct = pm->runs == OB_INSTANCE_RUNS_DIRECT;
    uint32_t args_chunk = 0, args_off = 0;
    if (multi) {
        r = write_run_args(pm, d, indexed, first, count, &args_chunk, &args_off);
        if (r != OB_OK) {
            pm->stats.skipped_draws += count;
            log_once(pm, "the ring could not grow for a run's indirect arguments");
            return r;
        }
    }
    pm->world_pending = false;
    pm->vb = d->vertex_buffer;
    pm->vb_offset = d->vertex_buffer_offset;
    if (indexed) {
        pm->ib = d->index_buffer;
        pm->ib_offset = d->index_buffer_offset;
        pm->index_type = d->index_type;
    }
    uint64_t h;
    pm->instances_mirror = mirrors;
    r = apply(pm, indexed, &h);
    pm->instances_mirror = false;
    if (r != OB_OK) {
        pm->stats.skipped_draws += count - 1;  /* apply counted one */
        return r;
    }
    VkBuffer vk = pm->ring->chunks[chunk].vk;
    if (pm->cur.instances != vk) {
        const VkDeviceSize zero = 0;
        vkCmdBindVertexBuffers(pm->cmd, 1, 1, &vk, &zero);
        pm->cur.instances = vk;
        pm->stats.vertex_binds_requested++;  /* the instance binding's own, so issued <= requested */
        pm->stats.vertex_binds_issued++;
    }
    if (multi && indexed)
        vkCmdDrawIndexedIndirect(pm->cmd, pm->ring->chunks[args_chunk].vk, args_off, count,
                                 sizeof(VkDrawIndexedIndirectCommand));
    else if (multi)
        vkCmdDrawIndirect(pm->cmd, pm->ring->chunks[args_chunk].vk, args_off, count,
                          sizeof(VkDrawIndirectCommand));
    else if (direct && indexed)
        for (uint32_t k = 0; k < count; k++)
            vkCmdDrawIndexed(pm->cmd, d->count, 1, d->first, d->vertex_offset, first + k);
    else if (direct)
        for (uint32_t k = 0; k < count; k++) vkCmdDraw(pm->cmd, d->count, 1, d->first, first + k);
    else if (indexed)
        vkCmdDrawIndexed(pm->cmd, d->count, count, d->first, d->vertex_offset, first);
    else
        vkCmdDraw(pm->cmd, d->count, count, d->first, first);
    if (multi) pm->stats.multi_draw_runs++;
    /* One fold per instance, as a draw of it alone would give: the hash
     * does not depend on how a run is cut into draws (recording jobs cut
     * draw lists anywhere). */
    uint64_t tail = indexed ? (((uint64_t)d->first << 32) | (uint32_t)d->vertex_offset)
                            : ((uint64_t)d->first << 32);
    for (uint32_t k = 0; k < count; k++) {
        uint64_t hk = ob_hash_block(h, blocks + OB_INSTANCE_FLOATS * k, OB_INSTANCE_STRIDE);
        hk = ob_hash_u64(hk, ((uint64_t)d->count << 32) | 1u);
        fold(pm, ob_hash_u64(hk, tail));
    }
    pm->stats.draws += count;
    pm->stats.draw_calls += direct ? count : 1;
    pm->stats.instances += count;
    pm->stats.vertices += (uint64_t)d->count * count;
    if (count > pm->stats.longest_run) pm->stats.longest_run = count;
    return OB_OK;
}

/* Whether the program set reads a per-instance block; else count draws are
 * refused, counted and logged. */
static bool instances_drawable(ob_pipeline_manager *pm, uint32_t count)
{
    if (pm->program && pm->program->instanced) return true;
    pm->stats.skipped_draws += count;
    log_once(pm, "instanced draw with a program that reads no per-instance block");
    return false;
}

ob_result ob_pipeline_manager_draw_instances_facing(ob_pipeline_manager *pm,
                                                    const ob_draw_data *d, const float *blocks,
                                                    uint32_t count, bool mirrors)
{
    if (count == 0) return OB_OK;
    if (!instances_drawable(pm, count)) return OB_ERR_WRONG_STATE;
    /* A multi-draw indirect holds at most maxDrawIndirectCount draws. */
    uint32_t most = pm->runs == OB_INSTANCE_RUNS_MULTI_DRAW ? pm->max_draw_indirect : UINT32_MAX;
    for (uint32_t start = 0; start < count;) {
        uint32_t n = OB_MIN(count - start, most);
        ob_result r = draw_instance_run(pm, d, blocks + OB_INSTANCE_FLOATS * start, n, mirrors);
        if (r != OB_OK) return r;
        start += n;
    }
    return OB_OK;
}

ob_result ob_pipeline_manager_draw_instances(ob_pipeline_manager *pm, const ob_draw_data *d,
                                             const float *blocks, uint32_t count)
{
    if (count == 0) return OB_OK;
    if (!instances_drawable(pm, count)) return OB_ERR_WRONG_STATE;
    /* A mirroring instance needs the other front face: the run is cut
     * where the determinant's sign changes. */
    for (uint32_t start = 0; start < count;) {
        bool mirrors = rows_mirror(blocks + OB_INSTANCE_FLOATS * start);
        uint32_t end = start + 1;
        while (end < count && rows_mirror(blocks + OB_INSTANCE_FLOATS * end) == mirrors) end++;
        ob_result r = ob_pipeline_manager_draw_instances_facing(
            pm, d, blocks + OB_INSTANCE_FLOATS * start, end - start, mirrors);
        if (r != OB_OK) return r;
        start = end;
    }
    return OB_OK;
}

/* The indirect draws: args checked, state applied, the command and its
 * hash (the arguments are read by the device, so their buffer, offset and
 * count are what the hash can know). */
static ob_result draw_indirect(ob_pipeline_manager *pm, ob_buffer args, uint64_t offset,
                               uint32_t draw_count, bool indexed)
{
    VkBuffer vk = ob_buffer_vk(pm->dev, args);
    if (!vk) {
        pm->stats.skipped_draws++;
        log_once(pm, "the indirect argument buffer handle is invalid");
        return OB_ERR_INVALID_HANDLE;
    }
    uint64_t h;
    ob_result r = apply(pm, indexed, &h);
    if (r != OB_OK) return r;
    if (indexed)
        vkCmdDrawIndexedIndirect(pm->cmd, vk, offset, draw_count,
                                 sizeof(VkDrawIndexedIndirectCommand));
    else
        vkCmdDrawIndirect(pm->cmd, vk, offset, draw_count, sizeof(VkDrawIndirectCommand));
    h = ob_hash_u64(h, ((uint64_t)args.id << 32) | draw_count);
    fold(pm, ob_hash_u64(h, offset ^ (indexed ? 0x8000000000000000ull : 0u)));
    pm->stats.draws++;
    pm->stats.draw_calls++;
    return OB_OK;
}

ob_result ob_pipeline_manager_draw_indirect(ob_pipeline_manager *pm, ob_buffer args, uint64_t offset,
                              uint32_t draw_count)
{
    return draw_indirect(pm, args, offset, draw_count, false);
}

ob_result ob_pipeline_manager_draw_indexed_indirect(ob_pipeline_manager *pm, ob_buffer args,
                                                    uint64_t offset, uint32_t draw_count)
{
    return draw_indirect(pm, args, offset, draw_count, true);
}

ob_result ob_pipeline_manager_dispatch(ob_pipeline_manager *pm, uint32_t x, uint32_t y, uint32_t z)
{
    uint64_t h;
    ob_result r = apply(pm, false, &h);
    if (r != OB_OK) return r;
    vkCmdDispatch(pm->cmd, x, y, z);
    h = ob_hash_u64(h, ((uint64_t)x << 32) | y);
    fold(pm, ob_hash_u64(h, z));
    pm->stats.dispatches++;
    return OB_OK;
}

ob_pipeline_manager_stats ob_pipeline_manager_stats_take(ob_pipeline_manager *pm)
{
    ob_pipeline_manager_stats s = pm->stats;
    memset(&pm->stats, 0, sizeof pm->stats);
    s.descriptor_sets_held = pm->ring ? pm->ring->set_count : 0;
    return s;
}

void ob_pipeline_manager_stats_add(ob_pipeline_manager_stats *into, const ob_pipeline_manager_stats *s)
{
    /* Every field is a counter: add them as an array of the same layout. */
    uint32_t *a = (uint32_t *)into;
    const uint32_t *b = (const uint32_t *)s;
    size_t n32 = offsetof(ob_pipeline_manager_stats, uniform_bytes) / sizeof(uint32_t);
    for (size_t i = 0; i < n32; i++) a[i] += b[i];
    into->uniform_bytes += s->uniform_bytes;
    into->skipped_draws += s->skipped_draws;
    into->vertices += s->vertices;
    /* A level, not a counter: the largest of any manager. */
    if (s->descriptor_sets_held > into->descriptor_sets_held) into->descriptor_sets_held = s->descriptor_sets_held;
    if (s->longest_run > into->longest_run) into->longest_run = s->longest_run;
}
