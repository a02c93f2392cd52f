#define _GNU_SOURCE
#include "ob_bench_machine.h"

#include "ob_core.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#define BATCHES 5u
#define ROUND_TRIPS 20000u

/* A whole measurement that takes longer gives up (NAN): two threads that
 * could not run at once (a CPU quota, say) would hand the line over once a
 * time slice. */
#define GIVE_UP_NS 2000000000ull

typedef struct ping {
    _Alignas(64) atomic_uint turn;  /* odd: the other thread's move; even: ours */
    int cpu;                        /* the other thread's CPU */
    int pinned;
    char pad[64 - sizeof(atomic_uint) - 2 * sizeof(int)];
    _Alignas(64) atomic_bool stop;  /* the measurement gave up: the other thread ends */
} ping;

/* Spins until p->turn is `want` (true) or the measurement gave up (false);
 * the clock is read once every 1024 polls. */
static bool wait_turn(ping *p, unsigned want, uint64_t deadline, bool timer)
{
    for (unsigned k = 1;; k++) {
        if (atomic_load_explicit(&p->turn, memory_order_acquire) == want) return true;
        if (k % 1024 != 0) continue;
        if (atomic_load_explicit(&p->stop, memory_order_relaxed)) return false;
        if (timer && ob_time_ns() > deadline) {
            atomic_store_explicit(&p->stop, true, memory_order_relaxed);
            return false;
        }
    }
}

static int pin_self(int cpu)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

static void *pong(void *arg)
{
    ping *p = arg;
    p->pinned = pin_self(p->cpu);
    atomic_store_explicit(&p->turn, 1, memory_order_release); /* ready */
    for (unsigned i = 1; i <= BATCHES * ROUND_TRIPS; i++) {
        if (!wait_turn(p, 2 * i, 0, false)) break;
        atomic_store_explicit(&p->turn, 2 * i + 1, memory_order_release);
    }
    return NULL;
}

double ob_bench_core_to_core_ns(void)
{
    cpu_set_t allowed;
    if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return NAN;
    int cpus[2], n = 0;
    for (int c = 0; c < CPU_SETSIZE && n < 2; c++)
        if (CPU_ISSET(c, &allowed)) cpus[n++] = c;
    if (n < 2) return NAN;
    static ping p;
    atomic_store(&p.turn, 0);
    atomic_store(&p.stop, false);
    p.cpu = cpus[1];
    p.pinned = 0;
    pthread_t t;
    if (pthread_create(&t, NULL, pong, &p) != 0) return NAN;
    /* Pinned for the measurement only: the caller's own set comes back. */
    int mine = pin_self(cpus[0]);
    uint64_t deadline = ob_time_ns() + GIVE_UP_NS;
    bool done = wait_turn(&p, 1, deadline, true);
    double ns[BATCHES];
    unsigned i = 1;
    for (unsigned b = 0; b < BATCHES && done; b++) {
        uint64_t t0 = ob_time_ns();
        for (unsigned k = 0; k < ROUND_TRIPS && done; k++, i++) {
            atomic_store_explicit(&p.turn, 2 * i, memory_order_release);
            done = wait_turn(&p, 2 * i + 1, deadline, true);
        }
        ns[b] = (double)(ob_time_ns() - t0) / ROUND_TRIPS;
    }
    pthread_join(t, NULL);
    pthread_setaffinity_np(pthread_self(), sizeof allowed, &allowed);
    if (!done || !mine || !p.pinned) return NAN;
    return ob_median(ns, BATCHES);
}
