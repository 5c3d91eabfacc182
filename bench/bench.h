/* bench.h — what the benchmark programs share: the wall clock. */
#ifndef BENCH_H
#define BENCH_H

#include <time.h>

/* Seconds on the monotonic clock (only differences mean anything). */
static inline double bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

#endif
