/* test_par.c — the parallel loop and the counter-based random streams. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "par.h"
#include "rng.h"

typedef struct ctx {
    double *out;
    int *hits;
} ctx;

static void fill(void *p, size_t chunk, int worker)
{
    (void)worker;
    ctx *c = p;
    rng r;
    rng_init(&r, 42, chunk);
    double s = 0;
    for (int i = 0; i < 1000; i++)
        s += rng_uniform(&r);
    c->out[chunk] = s;
    c->hits[chunk]++;
}

int main(void)
{
    enum { N = 97 };
    double ref[N];
    int hits[N];
    for (int t = 1; t <= 4; t++) {
        double out[N];
        memset(hits, 0, sizeof hits);
        ctx c = {out, hits};
        rt_run run = {t, NULL, 0};
        CHECK(par_for(&run, "test", N, fill, &c) == RT_OK, "par_for failed with %d threads", t);
        int once = 1;
        for (int i = 0; i < N; i++)
            once &= hits[i] == 1;
        CHECK(once, "every chunk runs exactly once with %d threads", t);
        if (t == 1)
            memcpy(ref, out, sizeof ref);
        else
            CHECK(memcmp(ref, out, sizeof ref) == 0, "results identical for 1 and %d threads", t);
    }
    /* Uniform deviates: mean 1/2 and variance 1/12 within 5 standard errors. */
    rng r;
    rng_init(&r, 7, 0);
    double s = 0, s2 = 0;
    int n = 200000;
    for (int i = 0; i < n; i++) {
        double u = rng_uniform(&r);
        CHECK(u >= 0 && u < 1, "uniform in [0,1): %g", u);
        s += u;
        s2 += u * u;
    }
    double mean = s / n, var = s2 / n - mean * mean;
    CHECK_NEAR(mean, 0.5, 5 * sqrt(1.0 / 12 / n), "uniform mean");
    CHECK_NEAR(var, 1.0 / 12, 5 * sqrt(1.0 / 180 / n), "uniform variance");
    /* Different streams differ; the same stream repeats. */
    rng a, b, c2;
    rng_init(&a, 1, 5);
    rng_init(&b, 1, 6);
    rng_init(&c2, 1, 5);
    uint64_t x = rng_next(&a);
    CHECK(x != rng_next(&b), "streams 5 and 6 differ");
    CHECK(x == rng_next(&c2), "stream 5 repeats");
    /* Cancellation stops the loop. */
    volatile sig_atomic_t cancel = 1;
    rt_run run = {2, &cancel, 0};
    double out[N];
    memset(hits, 0, sizeof hits);
    ctx cc = {out, hits};
    CHECK(par_for(&run, NULL, N, fill, &cc) == RT_ECANCEL, "cancelled loop reports RT_ECANCEL");
    return check_done("test_par");
}
