/* ob_bench_machine.h — what the machine itself does to the figures.
 *
 * The development VM's two cores are sometimes close (a cache line goes
 * from one to the other and back in 110-180 ns) and sometimes far apart
 * (450-520 ns), and the placement changes within minutes while the
 * single-threaded figures stay put. Every multithreaded figure follows it:
 * the parallel frame hands each entity's data from thread to thread
 * (session 23, 8 views x 10k: frame_cpu_speedup's median 1.74 close and
 * 1.51 far over 24 interleaved runs, docs/benchmark.md). So the benchmark measures it at its start and end and prints it
 * next to the figures, as it does the load average.
 *
 * Thread rule: call from one thread; it starts and joins one of its own.
 */
#ifndef OB_BENCH_MACHINE_H
#define OB_BENCH_MACHINE_H

/* The median round trip, in ns, of a cache line written in turn by two
 * threads pinned to two different CPUs of the process's set (the first
 * two): 5 batches of 20,000 round trips, some 50 ms at 500 ns. NAN with
 * fewer than two CPUs, when a thread cannot be started or pinned, or when
 * the whole takes over 2 s (the threads could not run at once). */
double ob_bench_core_to_core_ns(void);

#endif /* OB_BENCH_MACHINE_H */
