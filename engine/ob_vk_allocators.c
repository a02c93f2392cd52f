/* ob_vk_allocators.c — VkAllocationCallbacks the engine hands to Vulkan
 * (ob_device.h): a counting allocator (how often a driver allocates, for
 * tests and the benchmark) and the arena a command pool records through.
 */
#include "ob_device.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------ counting allocator */

/* Blocks carry their start in front of the aligned pointer, so frees and
 * reallocations of any alignment go back to malloc. */
typedef struct alloc_header {
    void *base;
    size_t size;
} alloc_header;

static void *VKAPI_PTR counted_alloc(void *user, size_t size, size_t align,
                                     VkSystemAllocationScope scope)
{
    (void)scope;
    ob_counting_allocator *a = user;
    if (align < _Alignof(alloc_header)) align = _Alignof(alloc_header);
    uint8_t *base = malloc(size + align + sizeof(alloc_header));
    if (!base) return NULL;
    uintptr_t p = ((uintptr_t)base + sizeof(alloc_header) + align - 1) & ~(uintptr_t)(align - 1);
    ((alloc_header *)p)[-1] = (alloc_header){base, size};
    atomic_fetch_add_explicit(&a->allocations, 1, memory_order_relaxed);
    return (void *)p;
}

static void VKAPI_PTR counted_free(void *user, void *mem)
{
    (void)user;
    if (mem) free(((alloc_header *)mem)[-1].base);
}

/* Reallocation of either allocator below: a new block, the old contents,
 * the old block freed. Both keep an alloc_header in front of each block. */
static void *realloc_by_copy(void *user, void *old, size_t size, size_t align,
                             VkSystemAllocationScope scope, PFN_vkAllocationFunction alloc,
                             PFN_vkFreeFunction release)
{
    if (!old) return alloc(user, size, align, scope);
    if (size == 0) {
        release(user, old);
        return NULL;
    }
    void *mem = alloc(user, size, align, scope);
    if (!mem) return NULL;
    size_t old_size = ((alloc_header *)old)[-1].size;
    memcpy(mem, old, old_size < size ? old_size : size);
    release(user, old);
    return mem;
}

static void *VKAPI_PTR counted_realloc(void *user, void *old, size_t size, size_t align,
                                       VkSystemAllocationScope scope)
{
    return realloc_by_copy(user, old, size, align, scope, counted_alloc, counted_free);
}

void ob_counting_allocator_init(ob_counting_allocator *a)
{
    a->callbacks = (VkAllocationCallbacks){
        .pUserData = a,
        .pfnAllocation = counted_alloc,
        .pfnReallocation = counted_realloc,
        .pfnFree = counted_free,
    };
    atomic_init(&a->allocations, 0);
}

uint64_t ob_counting_allocator_count(ob_counting_allocator *a)
{
    return atomic_load_explicit(&a->allocations, memory_order_relaxed);
}

/* --------------------------------------------------------- arena allocator */

#define ARENA_CHUNK_BYTES (64u * 1024u)

struct ob_arena_chunk {
    ob_arena_chunk *next;       /* in the spare list */
    size_t used;
    uint32_t live;              /* blocks not yet freed */
    _Alignas(16) uint8_t data[ARENA_CHUNK_BYTES];
};

/* In front of every block, an alloc_header whose base is its chunk, or (low
 * bit set) the malloc'd start of a block too big for a chunk. */

static ob_arena_chunk *arena_take_chunk(ob_arena_allocator *a)
{
    ob_arena_chunk *c = a->spare;
    if (c) {
        a->spare = c->next;
    } else {
        c = malloc(sizeof *c);
        if (!c) return NULL;
    }
    c->next = NULL;
    c->used = 0;
    c->live = 0;
    return c;
}

static void *VKAPI_PTR arena_alloc(void *user, size_t size, size_t align,
                                   VkSystemAllocationScope scope)
{
    (void)scope;
    ob_arena_allocator *a = user;
    if (align < _Alignof(alloc_header)) align = _Alignof(alloc_header);
    size_t need = size + align + sizeof(alloc_header);
    atomic_fetch_add_explicit(&a->allocations, 1, memory_order_relaxed);
    if (need > ARENA_CHUNK_BYTES / 4) {
        uint8_t *base = malloc(need);
        if (!base) return NULL;
        uintptr_t p = ((uintptr_t)base + sizeof(alloc_header) + align - 1) & ~(uintptr_t)(align - 1);
        ((alloc_header *)p)[-1] = (alloc_header){(void *)((uintptr_t)base | 1u), size};
        return (void *)p;
    }
    ob_arena_chunk *c = a->current;
    if (!c || c->used + need > ARENA_CHUNK_BYTES) {
        /* The old chunk lives on until its last block is freed. */
        if (c && c->live == 0) {
            c->next = a->spare;
            a->spare = c;
        }
        c = a->current = arena_take_chunk(a);
        if (!c) return NULL;
    }
    uintptr_t start = (uintptr_t)(c->data + c->used);
    uintptr_t p = (start + sizeof(alloc_header) + align - 1) & ~(uintptr_t)(align - 1);
    ((alloc_header *)p)[-1] = (alloc_header){c, size};
    c->used = p + size - (uintptr_t)c->data;
    c->live++;
    return (void *)p;
}

static void VKAPI_PTR arena_free(void *user, void *mem)
{
    ob_arena_allocator *a = user;
    if (!mem) return;
    uintptr_t owner = (uintptr_t)((alloc_header *)mem)[-1].base;
    if (owner & 1u) {
        free((void *)(owner & ~(uintptr_t)1u));
        return;
    }
    ob_arena_chunk *c = (ob_arena_chunk *)owner;
    if (--c->live > 0) return;
    if (c == a->current) {
        c->used = 0;   /* empty again: refill it from the start (still warm) */
    } else {
        c->next = a->spare;
        a->spare = c;
    }
}

static void *VKAPI_PTR arena_realloc(void *user, void *old, size_t size, size_t align,
                                     VkSystemAllocationScope scope)
{
    return realloc_by_copy(user, old, size, align, scope, arena_alloc, arena_free);
}

void ob_arena_allocator_init(ob_arena_allocator *a)
{
    a->callbacks = (VkAllocationCallbacks){
        .pUserData = a,
        .pfnAllocation = arena_alloc,
        .pfnReallocation = arena_realloc,
        .pfnFree = arena_free,
    };
    a->current = a->spare = NULL;
    atomic_init(&a->allocations, 0);
}

void ob_arena_allocator_release(ob_arena_allocator *a)
{
    if (a->current && a->current->live == 0) {
        a->current->next = a->spare;
        a->spare = a->current;
    } else if (a->current) {
        OB_LOG_E("device", "arena allocator released with %u blocks in use; they are leaked",
                 a->current->live);
    }
    a->current = NULL;
    while (a->spare) {
        ob_arena_chunk *next = a->spare->next;
        free(a->spare);
        a->spare = next;
    }
}

uint64_t ob_arena_allocator_count(ob_arena_allocator *a)
{
    return atomic_load_explicit(&a->allocations, memory_order_relaxed);
}
