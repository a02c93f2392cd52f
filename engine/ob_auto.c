#include "ob_auto_internal.h"

#include "ob_core.h"

/* AUTO: record the way that measured cheaper for this scene (per draw, or
 * per frame before any frame had draws); measure a way never measured (or
 * with another worker count) first. The way in use is kept unless the other
 * is cheaper by AUTO_MARGIN_PCT, so two nearly equal ways do not alternate
 * on noise.
 *
 * The way not chosen is re-measured by one frame (a probe) when the draw
 * count has moved by a quarter since it was taken, or when it is
 * AUTO_REMEASURE_FRAMES old. A probe costs what the worse way costs (on a
 * frame where workers pay 1.8x, one probe in 33 frames adds 2.4% on
 * average), so each probe that finds the way not chosen still dearer by
 * AUTO_CLEAR_PCT doubles the interval, up to AUTO_REMEASURE_FRAMES <<
 * AUTO_BACKOFF_STEPS; a probe that comes closer, a change of way or a
 * resized scene starts it again at AUTO_REMEASURE_FRAMES. */
#define AUTO_MARGIN_PCT 3u
#define AUTO_REMEASURE_FRAMES 32u
#define AUTO_CLEAR_PCT 25u
#define AUTO_BACKOFF_STEPS 4u
/* Worker counts next to the chosen one are re-measured less often than the
 * other way (a count changes what recording costs less than inline against
 * the workers does), and when the scene has grown or shrunk by a quarter. */
#define AUTO_COUNT_REMEASURE_FRAMES 256u

/* The last frame's cost of a way (per draw when both ways have one). */
static uint64_t latest_cost(const ob_record_cost *m, bool per_draw)
{
    return per_draw ? m->recent_ps[(m->recent_count - 1) % 3] : m->cost_ns;
}

uint32_t ob_auto_remeasure_interval(const ob_auto_state *s)
{
    return AUTO_REMEASURE_FRAMES << s->confirmed;
}

bool ob_auto_choose(ob_auto_state *s, const ob_record_cost *inline_way,
                    const ob_record_cost *worker_way)
{
    const ob_record_cost *way[2] = {inline_way, worker_way};
    bool was_probing = s->probing;
    s->probing = false;
    if (way[0]->cost_ns == 0) return false;
    if (way[1]->cost_ns == 0) return true;
    bool per_draw = way[0]->per_draw_ps > 0 && way[1]->per_draw_ps > 0;
    uint64_t cost[2] = {per_draw ? way[0]->per_draw_ps : way[0]->cost_ns,
                        per_draw ? way[1]->per_draw_ps : way[1]->cost_ns};
    bool cur = s->way;
    bool multi = cur;
    if (cost[!cur] * (100u + AUTO_MARGIN_PCT) < cost[cur] * 100u) multi = !cur;
    const ob_record_cost *other = way[!multi], *chosen = way[multi];
    /* What the last probe found: its own frame, not the way's figure (the
     * fastest of three), which a probe that came out dearer does not move. */
    if (multi != cur) {
        s->confirmed = 0;
    } else if (was_probing) {
        bool clear = latest_cost(other, per_draw) * 100u >= cost[multi] * (100u + AUTO_CLEAR_PCT);
        s->confirmed = clear ? OB_MIN(s->confirmed + 1, AUTO_BACKOFF_STEPS) : 0;
    }
    s->way = multi;
    uint32_t now = chosen->draws, then = other->draws;
    bool resized = 4ull * (now > then ? now - then : then - now) > (uint64_t)OB_MAX(now, then);
    if (resized) s->confirmed = 0;
    s->probing = other->age >= ob_auto_remeasure_interval(s) || resized;
    return s->probing ? !multi : multi;
}

/* The candidate worker counts: 2, 4, 8, ... below active, and active. */
static uint32_t candidates(uint32_t active, uint32_t out[32])
{
    uint32_t n = 0;
    for (uint32_t c = 2; c < active && n < 31; c *= 2) out[n++] = c;
    out[n++] = active;
    return n;
}

static uint64_t count_cost(const ob_record_cost *m)
{
    return m->per_draw_ps ? m->per_draw_ps : m->cost_ns;
}

uint32_t ob_auto_best_workers(ob_auto_state *s, const ob_record_cost *measured, uint32_t active)
{
    uint32_t c[32], n = candidates(active, c);
    uint32_t cur = s->workers;
    bool known = false;
    for (uint32_t i = 0; i < n; i++) known |= c[i] == cur;
    if (!known || count_cost(&measured[cur]) == 0) cur = active;
    uint32_t best = cur;
    for (uint32_t i = 0; i < n; i++) {
        uint64_t cost = count_cost(&measured[c[i]]);
        if (cost == 0 || c[i] == best) continue;
        uint64_t best_cost = count_cost(&measured[best]);
        if (best_cost == 0 || cost * (100u + AUTO_MARGIN_PCT) < best_cost * 100u) best = c[i];
    }
    s->workers = best;
    return best;
}

uint32_t ob_auto_probe_workers(ob_auto_state *s, const ob_record_cost *measured, uint32_t active)
{
    uint32_t c[32], n = candidates(active, c), at = n;
    s->count_probing = false;
    for (uint32_t i = 0; i < n; i++)
        if (c[i] == s->workers) at = i;
    if (at == n) return s->workers ? s->workers : active;
    /* Up first: more workers is where a bigger scene goes. */
    const uint32_t next[2] = {at + 1 < n ? c[at + 1] : 0, at > 0 ? c[at - 1] : 0};
    for (uint32_t k = 0; k < 2; k++) {
        if (!next[k]) continue;
        const ob_record_cost *m = &measured[next[k]];
        uint32_t now = measured[s->workers].draws, then = m->draws;
        bool resized = 4ull * (now > then ? now - then : then - now) > (uint64_t)OB_MAX(now, then);
        if (m->cost_ns == 0 || m->age >= AUTO_COUNT_REMEASURE_FRAMES || resized) {
            s->count_probing = true;
            return next[k];
        }
    }
    return s->workers;
}

void ob_record_cost_note(ob_record_cost *m, uint64_t ns, uint32_t draws)
{
    bool fresh = m->cost_ns == 0;
    m->cost_ns = fresh ? ns : (3 * m->cost_ns + ns) / 4;
    m->cost_ns = OB_MAX(m->cost_ns, (uint64_t)1);
    if (draws > 0) {
        /* Per draw, so that frames that add views now and then (an env map
         * refreshed every few frames) compare with those that do not; the
         * fastest of the last three, since interference (a preempted
         * thread, a late wake-up, a pipeline compiled) only ever adds
         * time: slow frames decide nothing unless three in a row are slow,
         * and a way that became cheaper shows in its first frame. */
        m->recent_ps[m->recent_count++ % 3] = OB_MAX(ns * 1000u / draws, (uint64_t)1);
        uint32_t n = OB_MIN(m->recent_count, 3u);
        m->per_draw_ps = m->recent_ps[0];
        for (uint32_t i = 1; i < n; i++) m->per_draw_ps = OB_MIN(m->per_draw_ps, m->recent_ps[i]);
    }
    /* Smoothed too: a view refreshed every few frames is not a new scene. */
    m->draws = fresh ? draws : (uint32_t)((3ull * m->draws + draws) / 4);
    m->age = 0;
}
