/* chaos_bench.c — chaos game throughput against a plain C loop doing the
 * same work in the same process (xoshiro256++, alias choice, 2-D fern into a
 * private 1024² count array; 3-D RIFS of seed 001 Table 1 into 256³ voxels).
 *
 *   make build/bench/chaos_bench && ./build/bench/chaos_bench [Mpoints]
 *
 * Each measurement is the best of 3 runs. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "chaos.h"
#include "rng.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static const double FERN[4][6] = {{0, 0, 0, 0, 0.16, 0},
                                  {0.85, 0.04, 0, -0.04, 0.85, 1.6},
                                  {0.2, -0.26, 0, 0.23, 0.22, 1.6},
                                  {-0.15, 0.28, 0, 0.26, 0.24, 0.44}}; /* a b e c d f */
static const double FERN_P[4] = {0.01, 0.85, 0.07, 0.07};

/* the plain loop: everything inline, one orbit */
static uint64_t plain2(uint64_t npts, const ifs_alias *al, const double lo[2], const double hi[2],
                       uint32_t *cnt)
{
    rng r;
    rng_init(&r, 1, 0);
    double x = 0, y = 0, sx = 1024 / (hi[0] - lo[0]), sy = 1024 / (hi[1] - lo[1]);
    uint64_t inside = 0;
    for (uint64_t i = 0; i < npts; i++) {
        uint64_t w = rng_next(&r);
        uint32_t col = (uint32_t)(((w >> 32) * 4) >> 32);
        uint32_t k = al->sel[2 * col + ((uint32_t)w < al->thresh[col])];
        const double *m = FERN[k];
        double nx = m[0] * x + m[1] * y + m[2];
        double ny = m[3] * x + m[4] * y + m[5];
        x = nx, y = ny;
        double fx = (x - lo[0]) * sx, fy = (hi[1] - y) * sy;
        if (fx >= 0 && fx < 1024 && fy >= 0 && fy < 1024) {
            cnt[(size_t)(int)fy * 1024 + (size_t)(int)fx]++;
            inside++;
        }
    }
    return inside;
}

static const double T1[64] = {
    0.13, 0.14, 0.15, 0.09, 0.07, 0.15, 0.15, 0.07, 0.12, 0.07, 0.08, 0.15, 0.17, 0.08, 0.08, 0.21,
    0.16, 0.14, 0.08, 0.07, 0.16, 0.14, 0.09, 0.11, 0.13, 0.12, 0.14, 0.15, 0.07, 0.17, 0.15, 0.02,
    0.12, 0.08, 0.13, 0.16, 0.10, 0.10, 0.14, 0.13, 0.13, 0.15, 0.13, 0.11, 0.07, 0.08, 0.10, 0.18,
    0.09, 0.13, 0.14, 0.16, 0.13, 0.09, 0.14, 0.07, 0.15, 0.15, 0.14, 0.17, 0.07, 0.16, 0.11, 0.01};
static const double OCT[8][3] = {{0, 0, 0},   {128, 0, 0},   {128, 0, 128}, {0, 0, 128},
                                 {0, 128, 0}, {128, 128, 0}, {0, 128, 128}, {128, 128, 128}};

static uint64_t plain3(uint64_t npts, const rifs *rf, uint32_t *cnt)
{
    rng r;
    rng_init(&r, 1, 0);
    double x = 0, y = 0, z = 0;
    uint32_t s = 0;
    uint64_t inside = 0;
    for (uint64_t i = 0; i < npts; i++) {
        uint64_t w = rng_next(&r);
        const ifs_alias *al = &rf->row[s];
        uint32_t col = (uint32_t)(((w >> 32) * 8) >> 32);
        uint32_t k = al->sel[2 * col + ((uint32_t)w < al->thresh[col])];
        s = k;
        x = 0.5 * x + OCT[k][0], y = 0.5 * y + OCT[k][1], z = 0.5 * z + OCT[k][2];
        double fx = x, fy = y, fz = z; /* box [0,256]³, 256 voxels: scale 1 */
        if (fx >= 0 && fx < 256 && fy >= 0 && fy < 256 && fz >= 0 && fz < 256) {
            cnt[(size_t)(int)fx + 256 * ((size_t)(int)fy + 256 * (size_t)(int)fz)]++;
            inside++;
        }
    }
    return inside;
}

int main(int argc, char **argv)
{
    uint64_t N = (uint64_t)(argc > 1 ? atof(argv[1]) : 64) * 1000000;
    rt_error e;
    affine fm[4];
    for (int k = 0; k < 4; k++)
        fm[k] = affine_from_2d(FERN[k][0], FERN[k][1], FERN[k][3], FERN[k][4], FERN[k][2], FERN[k][5]);
    ifs f;
    if (ifs_build(&f, fm, 4, FERN_P, 0, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return 1;
    }
    double lo[2] = {-2.5, -0.2}, hi[2] = {2.9, 10.2};
    uint32_t *cnt = calloc(1024 * 1024, 4);
    double best_plain = 1e9, best_eng = 1e9, best_col = 1e9, best_2t = 1e9;
    uint64_t sink = 0;
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = N;
    o.seed = 1;
    rt_run r1 = {1, NULL, 0}, r2 = {2, NULL, 0};
    for (int rep = 0; rep < 3; rep++) {
        memset(cnt, 0, 1024 * 1024 * 4);
        double t = now();
        sink += plain2(N, &f.alias, lo, hi, cnt);
        t = now() - t;
        best_plain = t < best_plain ? t : best_plain;
        hist2 hs;
        hist2_init(&hs, 1024, 1024, lo, hi, 1, &e);
        o.colour = CHAOS_COLOUR_NONE;
        t = now();
        chaos_hist2(&s, &o, &hs, NULL, &r1, &e);
        t = now() - t;
        best_eng = t < best_eng ? t : best_eng;
        o.colour = CHAOS_COLOUR_BLEND;
        t = now();
        chaos_hist2(&s, &o, &hs, NULL, &r1, &e);
        t = now() - t;
        best_col = t < best_col ? t : best_col;
        o.colour = CHAOS_COLOUR_NONE;
        t = now();
        chaos_hist2(&s, &o, &hs, NULL, &r2, &e);
        t = now() - t;
        best_2t = t < best_2t ? t : best_2t;
        hist2_free(&hs);
    }
    double Mp = N / 1e6;
    printf("2-D fern, 1024^2 counts, %.0f M points (best of 3)\n", Mp);
    printf("  plain C loop           %7.1f M points/s\n", Mp / best_plain);
    printf("  chaos_hist2, 1 thread  %7.1f M points/s  (%.2fx plain)\n", Mp / best_eng, best_plain / best_eng);
    printf("  with colour (blend)    %7.1f M points/s  (%.2fx plain)\n", Mp / best_col, best_plain / best_col);
    printf("  2 threads              %7.1f M points/s  (%.2fx 1 thread)\n", Mp / best_2t, best_eng / best_2t);
    free(cnt);
    ifs_free(&f);

    affine om[8];
    double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
    for (int i = 0; i < 8; i++)
        om[i] = affine_from_3d(m9, OCT[i]);
    rifs rf;
    if (rifs_build(&rf, om, 8, 1, T1, RIFS_NORMALISE, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return 1;
    }
    uint32_t *vc = calloc((size_t)256 * 256 * 256, 4);
    volume vol;
    double vlo[3] = {0, 0, 0}, vhi[3] = {256, 256, 256};
    volume_init(&vol, 256, 256, 256, vlo, vhi, &e);
    chaos_sys s3 = {NULL, &rf};
    o.colour = CHAOS_COLOUR_NONE;
    double bp = 1e9, be = 1e9, b2 = 1e9;
    for (int rep = 0; rep < 3; rep++) {
        double t = now();
        sink += plain3(N, &rf, vc);
        t = now() - t;
        bp = t < bp ? t : bp;
        t = now();
        chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r1, &e);
        t = now() - t;
        be = t < be ? t : be;
        t = now();
        chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r2, &e);
        t = now() - t;
        b2 = t < b2 ? t : b2;
    }
    printf("3-D RIFS (seed 001 Table 1), 256^3 voxels, %.0f M points (best of 3; engine time includes\n"
           "  allocating/zeroing the 64 MB per-worker counts and writing the float volume)\n", Mp);
    printf("  plain C loop           %7.1f M points/s\n", Mp / bp);
    printf("  chaos_volume, 1 thread %7.1f M points/s  (%.2fx plain)\n", Mp / be, bp / be);
    printf("  2 threads              %7.1f M points/s  (%.2fx 1 thread)\n", Mp / b2, be / b2);
    volume_free(&vol);
    free(vc);
    rifs_free(&rf);
    return sink == 42 ? 2 : 0;
}
