/* ob_frame_slots.c — the device's frame slots and deferred deletion.
 *
 * The renderer tells the device which frame slot it is recording once the
 * slot's fence has signalled; what was deferred while that slot was last
 * current runs then, so a resource used by a frame in flight is destroyed
 * only after the GPU is done with it.
 */
#include "ob_device_internal.h"

typedef struct defer_item {
    ob_deferred_fn fn;
    void *payload;
} defer_item;

struct ob_defer_queue {
    defer_item *items;
    uint32_t count, cap;
};

ob_result ob_frame_slots_init(ob_frame_slots *s, uint32_t frames)
{
    *s = (ob_frame_slots){0};
    if (frames > OB_MAX_FRAMES_IN_FLIGHT) {
        OB_LOG_E("device", "frames_in_flight %u exceeds the limit of %u", frames, OB_MAX_FRAMES_IN_FLIGHT);
        return OB_ERR_INVALID_ARGUMENT;
    }
    s->frames_in_flight = frames ? frames : 2;
    s->queues = ob_calloc(s->frames_in_flight, sizeof *s->queues);
    return s->queues ? OB_OK : OB_ERR_OUT_OF_HOST_MEMORY;
}

void ob_frame_slots_release(ob_frame_slots *s)
{
    for (uint32_t i = 0; s->queues && i < s->frames_in_flight; i++) ob_free(s->queues[i].items);
    ob_free(s->queues);
    s->queues = NULL;
}

/* Runs a slot's queue. The queue is detached first so that work deferred by
 * a deferred function lands in a fresh queue and waits a full cycle. */
static uint32_t run_deferred(ob_frame_slots *s, ob_device *dev, uint32_t slot)
{
    ob_defer_queue *q = &s->queues[slot];
    defer_item *items = q->items;
    uint32_t count = q->count, cap = q->cap;
    q->items = NULL;
    q->count = q->cap = 0;
    for (uint32_t i = 0; i < count; i++) items[i].fn(dev, items[i].payload);
    if (!q->items) {
        q->items = items;   /* keep the capacity for the next cycle */
        q->cap = cap;
    } else {
        ob_free(items);
    }
    return count;
}

void ob_frame_slots_drain(ob_frame_slots *s, ob_device *dev)
{
    /* Oldest slot first; repeat in case a deferred function deferred more. */
    for (uint32_t pass = 0; s->queues && pass < 4; pass++) {
        uint32_t ran = 0;
        for (uint32_t k = 1; k <= s->frames_in_flight; k++)
            ran += run_deferred(s, dev, (s->current_slot + k) % s->frames_in_flight);
        if (!ran) break;
    }
}

uint32_t ob_device_frames_in_flight(const ob_device *dev)
{
    return ob_device_frame_slots((ob_device *)dev)->frames_in_flight;
}

uint32_t ob_device_current_slot(const ob_device *dev)
{
    return ob_device_frame_slots((ob_device *)dev)->current_slot;
}

void ob_device_begin_frame_slot(ob_device *dev, uint32_t slot)
{
    ob_frame_slots *s = ob_device_frame_slots(dev);
    if (slot >= s->frames_in_flight) {
        OB_LOG_E("device", "frame slot %u out of range (frames in flight: %u); ignored", slot,
                 s->frames_in_flight);
        return;
    }
    s->current_slot = slot;
    run_deferred(s, dev, slot);
}

void ob_device_defer(ob_device *dev, ob_deferred_fn fn, void *payload)
{
    if (!dev || !fn) return;
    ob_frame_slots *s = ob_device_frame_slots(dev);
    ob_defer_queue *q = &s->queues[s->current_slot];
    if (ob_array_reserve((void **)&q->items, &q->cap, q->count + 1, sizeof *q->items) != OB_OK) {
        OB_LOG_W("device", "deferred-deletion queue of slot %u cannot grow: waiting idle and running "
                           "the deletion now", s->current_slot);
        ob_device_wait_idle(dev);
        fn(dev, payload);
        return;
    }
    q->items[q->count++] = (defer_item){fn, payload};
}
