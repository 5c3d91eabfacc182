/* field_bench.c — field graphs and noise against plain C in the same run.
 *
 *   build/bench/field_bench [grid] [points] [repeats]
 *
 * (1) The hypertexture DMF chain of seed 001,
 *       gain(0.7, bias(0.3, sphere(r 0.8, soft 0.4) * turbulence(6 octaves)))
 *     built as a field graph, compiled, and sampled into a grid^3 volume with
 *     field_sample_volume (1 thread), against the same chain hand-written
 *     as one C loop (inline soft sphere, scalar turbulence, pow with the
 *     exponents hoisted) filling the same volume. Target: ratio <= 1.5.
 * (2) Block 3-D Perlin noise (noise_perlin3_block, table gradients) against
 *     the plain scalar transcription of Perlin's 2002 reference
 *     (noise_reference3, branchy grad) on scattered points (uniform in
 *     [-200, 200]^3, every point in a different cell). Target: >= 1.5x.
 * Each measurement is the best of `repeats` runs.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"

#include "density.h"
#include "field.h"
#include "noise.h"
#include "rng.h"
#include "volume.h"

static double sink;

/* The chain written by hand: one loop, no graph. */
static void chain_c(volume *v, const noise_perm *np)
{
    double r = 0.8, s = 0.4, r1 = r - s / 2, r0 = r + s / 2;
    double r1sq = r1 * r1, r0sq = r0 * r0;
    double kb = log(0.3) / log(0.5), kg = log(1 - 0.7) / log(0.5);
    for (int k = 0; k < v->nz; k++) {
        double z = v->lo[2] + (v->hi[2] - v->lo[2]) * (k + 0.5) / v->nz;
        for (int j = 0; j < v->ny; j++) {
            double y = v->lo[1] + (v->hi[1] - v->lo[1]) * (j + 0.5) / v->ny;
            float *dst = volume_at(v, 0, j, k);
            for (int i = 0; i < v->nx; i++) {
                double x = v->lo[0] + (v->hi[0] - v->lo[0]) * (i + 0.5) / v->nx;
                double d2 = x * x + y * y + z * z, sp;
                if (d2 <= r1sq)
                    sp = 1;
                else if (d2 >= r0sq)
                    sp = 0;
                else
                    sp = (r0sq - d2) / (r0sq - r1sq);
                double t = sp * noise_turbulence3(np, 6, x, y, z);
                t = t < 0 ? 0 : t > 1 ? 1 : t;
                t = pow(t, kb); /* bias */
                t = t < 0.5 ? pow(2 * t, kg) * 0.5 : 1 - pow(2 - 2 * t, kg) * 0.5; /* gain */
                dst[i] = (float)t;
            }
        }
    }
}

int main(int argc, char **argv)
{
    int grid = argc > 1 ? atoi(argv[1]) : 128;
    long npts = argc > 2 ? atol(argv[2]) : 2000000;
    int reps = argc > 3 ? atoi(argv[3]) : 5;
    rt_error e;

    /* (1) DMF chain */
    density_shape sph;
    memset(&sph, 0, sizeof sph);
    sph.kind = DENSITY_SPHERE, sph.r = 0.8, sph.s = 0.4;
    field *f = field_binary(FIELD_MUL, field_density(&sph), field_turbulence(42, 6));
    f = field_gain(field_bias(f, 0.3), 0.7);
    field_prog *p = field_compile(f, &e);
    field_unref(f);
    noise_perm np;
    noise_perm_init(&np, 42);
    const double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    volume va, vb;
    if (!p || volume_init(&va, grid, grid, grid, lo, hi, &e) ||
        volume_init(&vb, grid, grid, grid, lo, hi, &e)) {
        fprintf(stderr, "field_bench: %s\n", e.msg);
        return 1;
    }
    rt_run run1 = {1, NULL, 0};
    double tg = 1e30, tc = 1e30;
    for (int r = 0; r < reps; r++) {
        double t0 = bench_now();
        chain_c(&vb, &np);
        double t1 = bench_now();
        field_sample_volume(field_prog_fn, p, &va, &run1, &e);
        double t2 = bench_now();
        tc = t1 - t0 < tc ? t1 - t0 : tc;
        tg = t2 - t1 < tg ? t2 - t1 : tg;
    }
    size_t nv = (size_t)grid * grid * grid;
    size_t diff = 0;
    for (size_t i = 0; i < nv; i++)
        diff += va.v[i] != vb.v[i];
    printf("dmf chain %d^3: graph %.3f s, hand C %.3f s, ratio %.3f (target <= 1.5); "
           "%.1f ns/voxel; %zu voxels differ\n",
           grid, tg, tc, tg / tc, 1e9 * tg / (double)nv, diff);
    volume_free(&va);
    volume_free(&vb);
    field_prog_free(p);

    /* (2) scattered Perlin noise */
    double *x = malloc(sizeof *x * (size_t)npts), *y = malloc(sizeof *y * (size_t)npts),
           *z = malloc(sizeof *z * (size_t)npts), *o = malloc(sizeof *o * (size_t)npts);
    if (!x || !y || !z || !o)
        return 1;
    rng rg;
    rng_init(&rg, 1, 0);
    for (long i = 0; i < npts; i++) {
        x[i] = rng_uniform(&rg) * 400 - 200;
        y[i] = rng_uniform(&rg) * 400 - 200;
        z[i] = rng_uniform(&rg) * 400 - 200;
    }
    noise_perm ref;
    noise_perm_reference(&ref);
    double tr = 1e30, tb = 1e30, ts = 1e30;
    long mismatch = 0;
    for (int r = 0; r < reps; r++) {
        double t0 = bench_now(), acc = 0;
        for (long i = 0; i < npts; i++)
            acc += noise_reference3(x[i], y[i], z[i]);
        double t1 = bench_now();
        noise_perlin3_block(&ref, (size_t)npts, x, y, z, o);
        double t2 = bench_now();
        double acc2 = 0;
        for (long i = 0; i < npts; i++)
            acc2 += noise_perlin3(&ref, x[i], y[i], z[i]);
        double t3 = bench_now();
        sink += acc + acc2;
        tr = t1 - t0 < tr ? t1 - t0 : tr;
        tb = t2 - t1 < tb ? t2 - t1 : tb;
        ts = t3 - t2 < ts ? t3 - t2 : ts;
    }
    for (long i = 0; i < npts; i += 97)
        mismatch += o[i] != noise_reference3(x[i], y[i], z[i]);
    printf("perlin scattered %ld points: reference %.1f M/s, block %.1f M/s (%.2fx, target >= "
           "1.5x), scalar table %.1f M/s; %ld sampled mismatches\n",
           npts, npts / tr * 1e-6, npts / tb * 1e-6, tr / tb, npts / ts * 1e-6, mismatch);
    free(x), free(y), free(z), free(o);
    return sink == 12345.678 ? 2 : 0;
}
