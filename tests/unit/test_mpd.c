/* test_mpd.c — the random fractal D(P) of seed 000, Types I–IV. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
#include "mpd.h"
#include "rng.h"

static mpd make(int R, int type, int R2, uint64_t seed, double beta, int threads)
{
    mpd_params p;
    mpd_params_default(&p);
    p.R = R;
    p.type = type;
    p.R2 = R2;
    p.seed = seed;
    p.beta = beta;
    for (int i = 0; i < 8; i++)
        p.corner[i] = 0.25 * i - 1.0;
    rt_run run = {threads, NULL, 0};
    mpd m;
    rt_error e = {0};
    rt_code rc = mpd_init(&m, &p, &run, &e);
    CHECK(rc == RT_OK, "mpd_init R=%d type=%d: %s", R, type, e.msg);
    return m;
}

/* Acklam's approximation against the normal CDF from libm's erfc: one Newton
 * step on Phi(x) = p gives the exact quantile to ~1e-15. */
static void test_inv_normal(void)
{
    CHECK(mpd_inv_normal(0.5) == 0.0, "median");
    CHECK_NEAR(mpd_inv_normal(0.975), 1.959963984540054, 3e-9, "97.5% quantile");
    CHECK_NEAR(mpd_inv_normal(0.025), -1.959963984540054, 3e-9, "2.5% quantile");
    double worst = 0;
    for (int i = 1; i < 2000; i++) {
        double p = i / 2000.0;
        for (int tail = 0; tail < 2; tail++) {
            if (tail)
                p = pow(10.0, -1.0 - 14.0 * i / 2000.0); /* 1e-1 .. 1e-15 */
            double x = mpd_inv_normal(p);
            double phi = exp(-0.5 * x * x) / sqrt(2 * 3.14159265358979323846);
            double xt = x - (0.5 * erfc(-x / sqrt(2.0)) - p) / phi;
            double rel = fabs(x - xt) / (fabs(xt) > 1e-3 ? fabs(xt) : 1e-3);
            if (rel > worst)
                worst = rel;
        }
    }
    CHECK(worst < 2e-9, "inverse normal relative error %g", worst);
}

/* Node randoms are N(0,1): mean, variance and the 5% two-sided tail. */
static void test_node_randoms(void)
{
    const int m = 200000;
    double s = 0, s2 = 0;
    int tail = 0;
    for (int i = 0; i < m; i++) {
        double g = mpd_node_random(42, 1 + i % 9, (uint32_t)i, (uint32_t)(i * 7 + 1), 3);
        s += g;
        s2 += g * g;
        tail += fabs(g) > 1.959963984540054;
    }
    double mean = s / m, var = s2 / m - mean * mean;
    CHECK(fabs(mean) < 5 / sqrt(m), "mean of node randoms %g", mean);
    CHECK(fabs(var - 1) < 5 * sqrt(2.0 / m), "variance of node randoms %g", var);
    double f = (double)tail / m;
    CHECK(fabs(f - 0.05) < 5 * sqrt(0.05 * 0.95 / m), "tail fraction %g (expected 0.05)", f);
}

static void random_points(size_t n, double *x, double *y, double *z, uint64_t seed)
{
    rng r;
    rng_init(&r, seed, 0);
    for (size_t i = 0; i < n; i++) {
        x[i] = rng_uniform(&r);
        y[i] = rng_uniform(&r);
        z[i] = rng_uniform(&r);
    }
    /* a few edge cases: the faces, outside, NaN */
    x[0] = 0, y[0] = 0, z[0] = 0;
    x[1] = 1, y[1] = 1, z[1] = 1;
    x[2] = -0.5, y[2] = 1.5, z[2] = 0.5;
    x[3] = NAN, y[3] = 0.25, z[3] = 1;
}

/* Types I–IV give bit-identical values on random and lattice points. */
static void test_types_identical(void)
{
    enum { NP = 3000 };
    double *x = rt_malloc(NP * sizeof *x), *y = rt_malloc(NP * sizeof *y), *z = rt_malloc(NP * sizeof *z);
    double *ref = rt_malloc(NP * sizeof *ref), *o = rt_malloc(NP * sizeof *o);
    random_points(NP, x, y, z, 7);
    for (int R = 3; R <= 7; R++) {
        mpd m1 = make(R, MPD_TYPE1, 0, 99, 0.6, 1);
        mpd_eval(&m1, NP, x, y, z, ref);
        int cases[6][2] = {{MPD_TYPE2, 0}, {MPD_TYPE3, 0}, {MPD_TYPE4, 0},
                           {MPD_TYPE4, 1}, {MPD_TYPE4, R - 2}, {MPD_TYPE4, R}};
        for (int c = 0; c < 6; c++) {
            mpd mk = make(R, cases[c][0], cases[c][1], 99, 0.6, 2);
            mpd_eval(&mk, NP, x, y, z, o);
            CHECK(memcmp(o, ref, NP * sizeof *o) == 0, "R=%d type %d R2=%d differs from Type I (random points)",
                  R, cases[c][0], cases[c][1]);
            /* the parallel point API and the grid API agree too */
            rt_run run = {3, NULL, 0};
            memset(o, 0, NP * sizeof *o);
            CHECK(mpd_eval_points(&mk, &run, NP, x, y, z, o, NULL, NULL) == RT_OK, "eval_points");
            CHECK(memcmp(o, ref, NP * sizeof *o) == 0, "R=%d type %d: eval_points differs", R, cases[c][0]);
            /* every lattice node: grid at the lattice = mpd_node of Type I */
            int N = (1 << R) + 1;
            double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
            double *g = rt_malloc((size_t)N * N * N * sizeof *g);
            CHECK(mpd_eval_grid(&mk, &run, lo, hi, N, N, N, g, NULL, NULL) == RT_OK, "grid");
            int bad = 0;
            for (int k = 0; k < N; k++)
                for (int j = 0; j < N; j++)
                    for (int i = 0; i < N; i++) {
                        double v1 = mpd_node(&m1, (uint32_t)i, (uint32_t)j, (uint32_t)k);
                        /* mpd_node of Types II-IV descends afresh: sample it */
                        if (R <= 4 || (i * 7 + j * 3 + k) % 61 == 0)
                            bad += v1 != mpd_node(&mk, (uint32_t)i, (uint32_t)j, (uint32_t)k);
                        bad += g[i + N * (j + (size_t)N * k)] != v1;
                    }
            CHECK(bad == 0, "R=%d type %d R2=%d: %d lattice nodes differ", R, cases[c][0], cases[c][1], bad);
            rt_free(g);
            /* a grid off the lattice against point evaluation */
            double lo2[3] = {0.1, -0.05, 0.3}, hi2[3] = {0.9, 0.77, 1.2};
            double gx[7 * 5 * 6], px[7 * 5 * 6], py[7 * 5 * 6], pz[7 * 5 * 6], pv[7 * 5 * 6];
            CHECK(mpd_eval_grid(&mk, &run, lo2, hi2, 7, 5, 6, gx, NULL, NULL) == RT_OK, "grid 2");
            for (int k = 0, q = 0; k < 6; k++)
                for (int j = 0; j < 5; j++)
                    for (int i = 0; i < 7; i++, q++) {
                        px[q] = lo2[0] + (hi2[0] - lo2[0]) * i / 6.0;
                        py[q] = lo2[1] + (hi2[1] - lo2[1]) * j / 4.0;
                        pz[q] = lo2[2] + (hi2[2] - lo2[2]) * k / 5.0;
                    }
            mpd_eval(&m1, 7 * 5 * 6, px, py, pz, pv);
            CHECK(memcmp(gx, pv, sizeof gx) == 0, "R=%d type %d: off-lattice grid differs", R, cases[c][0]);
            mpd_free(&mk);
        }
        mpd_free(&m1);
    }
    rt_free(x), rt_free(y), rt_free(z), rt_free(ref), rt_free(o);
}

/* The corners keep their values; trilinear interpolation between nodes:
 * the centre of the finest cell at the origin is the mean of its 8 nodes. */
static void test_corners_and_interp(void)
{
    mpd m = make(4, MPD_TYPE3, 0, 5, 0.5, 1);
    for (int c = 0; c < 8; c++) {
        uint32_t N = 16;
        double v = mpd_node(&m, c & 1 ? N : 0, c & 2 ? N : 0, c & 4 ? N : 0);
        CHECK(v == 0.25 * c - 1.0, "corner %d = %g", c, v);
    }
    double x = 1.5 / 16, y = 2.5 / 16, z = 0.5 / 16, out;
    mpd_eval(&m, 1, &x, &y, &z, &out);
    double s = 0;
    for (int q = 0; q < 8; q++)
        s += mpd_node(&m, 1 + (q & 1), 2 + (q >> 1 & 1), (q >> 2 & 1));
    CHECK_NEAR(out, s / 8, 1e-12, "cell centre = mean of the 8 corners");
    /* a quarter along x on an edge: 3/4 a + 1/4 b */
    x = 3.25 / 16, y = 4.0 / 16, z = 8.0 / 16;
    mpd_eval(&m, 1, &x, &y, &z, &out);
    CHECK_NEAR(out, 0.75 * mpd_node(&m, 3, 4, 8) + 0.25 * mpd_node(&m, 4, 4, 8), 1e-12, "edge lerp");
    mpd_free(&m);
}

/* Raising R only adds finer nodes: node (i,j,k) at R is node (4i,4j,4k) at R+2. */
static void test_refinement(void)
{
    for (int t = 0; t < 2; t++) {
        int type = t ? MPD_TYPE3 : MPD_TYPE1;
        mpd a = make(4, type, 0, 1234, 0.7, 1), b = make(6, type, 0, 1234, 0.7, 2);
        int bad = 0;
        for (uint32_t k = 0; k <= 16; k++)
            for (uint32_t j = 0; j <= 16; j++)
                for (uint32_t i = 0; i <= 16; i++)
                    bad += mpd_node(&a, i, j, k) != mpd_node(&b, 4 * i, 4 * j, 4 * k);
        CHECK(bad == 0, "type %d: %d coarse nodes change when R goes 4 -> 6", type, bad);
        /* and the fine lattice is not just a copy: a level-5 node is not the mean of its parents */
        double v = mpd_node(&b, 2, 0, 0), mean = 0.5 * (mpd_node(&b, 0, 0, 0) + mpd_node(&b, 4, 0, 0));
        CHECK(fabs(v - mean) > 1e-6, "fine node displaced");
        mpd_free(&a);
        mpd_free(&b);
    }
    /* a different seed gives a different field */
    mpd a = make(3, MPD_TYPE1, 0, 1, 0.5, 1), b = make(3, MPD_TYPE1, 0, 2, 0.5, 1);
    CHECK(mpd_node(&a, 4, 4, 4) != mpd_node(&b, 4, 4, 4), "seed matters");
    mpd_free(&a);
    mpd_free(&b);
}

/* Structure of eqs. (1)–(4): at level n the offset of a node from the mean
 * of its 2 (edge), 4 (face) or 6 (centre) parents is N(0, L(n)^2),
 * L(n) = exp(-(n-1) beta). For m nodes the sample mean has standard error
 * L/sqrt(m) and the sample SD about L/sqrt(2m): allow 5 of each (plus 1e-5
 * for the float rounding of stored values). */
static void test_level_statistics(void)
{
    const int R = 6;
    const double beta = 0.45;
    mpd m = make(R, MPD_TYPE1, 0, 2024, beta, 2);
    const uint32_t N = 1u << R;
    for (int n = 1; n <= R; n++) {
        uint32_t h = 1u << (R - n);
        double L = exp(-(n - 1) * beta);
        for (int cnt = 1; cnt <= 3; cnt++) {
            double s = 0, s2 = 0;
            long mcount = 0;
            for (uint32_t k = 0; k <= N; k += h)
                for (uint32_t j = 0; j <= N; j += h)
                    for (uint32_t i = 0; i <= N; i += h) {
                        uint32_t c[3] = {i, j, k};
                        int odd = 0;
                        for (int ax = 0; ax < 3; ax++)
                            odd += (c[ax] / h) & 1;
                        if (odd != cnt)
                            continue;
                        double sum = 0;
                        for (int ax = 0; ax < 3; ax++) {
                            if (!((c[ax] / h) & 1))
                                continue;
                            uint32_t q[3] = {i, j, k};
                            q[ax] = c[ax] - h;
                            sum += mpd_node(&m, q[0], q[1], q[2]);
                            q[ax] = c[ax] + h;
                            sum += mpd_node(&m, q[0], q[1], q[2]);
                        }
                        double off = mpd_node(&m, i, j, k) - sum / (2 * cnt);
                        s += off;
                        s2 += off * off;
                        mcount++;
                    }
            /* known counts: edges 3 a b^2, faces 3 a^2 b, centres a^3 (a = 2^(n-1), b = a + 1) */
            long a = 1L << (n - 1), b = a + 1;
            long expect = cnt == 1 ? 3 * a * b * b : cnt == 2 ? 3 * a * a * b : a * a * a;
            CHECK(mcount == expect, "level %d class %d: %ld nodes, expected %ld", n, cnt, mcount, expect);
            double mean = s / mcount;
            double sd = sqrt(s2 / mcount - mean * mean);
            CHECK(fabs(mean) <= 5 * L / sqrt((double)mcount) + 1e-5, "level %d class %d: mean offset %g (L=%g, m=%ld)",
                  n, cnt, mean, L, mcount);
            if (mcount >= 20)
                CHECK(fabs(sd - L) <= 5 * L / sqrt(2.0 * mcount) + 1e-5,
                      "level %d class %d: SD %g, expected L(n) = %g (m=%ld)", n, cnt, sd, L, mcount);
        }
    }
    mpd_free(&m);
}

/* Memory: formulas (13)–(16) of seed 000, in 4-byte words. */
static void test_memory(void)
{
    for (int R = 2; R <= 12; R++) {
        double N = (double)(1 << R) + 1;
        CHECK((double)mpd_type1_bytes(R) == 4 * N * N * N, "C1 = N^3 words at R=%d", R);
        double c3 = 4.0 * 13 * 19 * R;           /* eq. (15) */
        double ratio = (double)mpd_path_bytes(R) / c3;
        CHECK(ratio > 0.1 && ratio <= 1.0, "Type III path %zu bytes vs C3 %g at R=%d", mpd_path_bytes(R), c3, R);
        CHECK(mpd_path_bytes(R) == (size_t)R * mpd_path_bytes(1), "Type III memory linear in R");
        for (int R2 = 0; R2 <= R; R2 += 3) {
            double N2 = (double)(1 << R2) + 1;
            double c4 = 4.0 * (N2 * N2 * N2 + 13.0 * 19 * (R - R2)); /* eq. (16) */
            double r4 = (double)mpd_type4_bytes(R, R2) / c4;
            CHECK(r4 > 0.1 && r4 <= 1.0, "Type IV R=%d R2=%d: %zu bytes vs C4 %g", R, R2, mpd_type4_bytes(R, R2), c4);
        }
    }
    /* the object and the evaluation report the same */
    mpd m = make(6, MPD_TYPE4, 3, 1, 0.5, 1);
    CHECK(m.arr_bytes == 4 * 9 * 9 * 9, "Type IV R2=3 array %zu bytes", m.arr_bytes);
    double x[2] = {0.1, 0.7}, out[2];
    mpd_stats st;
    CHECK(mpd_eval_points(&m, NULL, 2, x, x, x, out, &st, NULL) == RT_OK, "eval");
    CHECK(st.array_bytes == m.arr_bytes && st.work_bytes == mpd_path_bytes(3), "stats %zu %zu", st.array_bytes,
          st.work_bytes);
    CHECK(st.nodes == 2 * 19 * 3, "descent computes 19 nodes per level: %llu", (unsigned long long)st.nodes);
    mpd_free(&m);

    /* Type I refuses what does not fit and names Type IV's largest R2:
     * N = 2^14 + 1 = 16385, 4 N^3 = 1.7596e13 bytes = 17.6 TB; with 4 GiB
     * = 4294967296 bytes, R2 = 9 fits (4 * 513^3 = 5.4e8) but R2 = 10 does
     * not (4 * 1025^3 = 4.3077e9). */
    mpd_params p;
    mpd_params_default(&p);
    p.R = 14;
    p.type = MPD_TYPE1;
    rt_error e = {0};
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL, "Type I R=14 refused");
    CHECK(strstr(e.msg, "Type I at R = 14 needs 17.6 TB (limit 4 GiB); use Type IV (strategy: 4) with R2 = 9"),
          "message: %s", e.msg);
    /* a small limit: R = 6 needs 4 * 65^3 = 1098500 bytes > 1 MiB; R2 = 5 fits */
    p.R = 6;
    p.mem_limit = 1 << 20;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strstr(e.msg, "needs 1.1 MB (limit 1 MiB)") &&
              strstr(e.msg, "R2 = 5"),
          "message: %s", e.msg);
    /* automatic: few points -> Type IV with the largest R2 in the budget
     * (64 MiB: 4 * 257^3 = 67.9e6 > 67.1e6, so R2 = 7); many -> Type I */
    p.R = 10;
    p.mem_limit = 0;
    p.type = MPD_AUTO;
    p.npoints_hint = 1000;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK && m.type == MPD_TYPE4 && m.R2 == 7, "auto: type %d R2 %d",
          m.type, m.R2);
    mpd_free(&m);
    p.R = 5;
    p.npoints_hint = 0;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK && m.type == MPD_TYPE1, "auto small: type %d", m.type);
    mpd_free(&m);
}

static void test_validation(void)
{
    mpd m;
    mpd_params p;
    rt_error e;
    mpd_params_default(&p);
    p.R = 0;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strcmp(e.msg, "R = 0 is out of range (expected 1 .. 20)") == 0,
          "%s", e.msg);
    mpd_params_default(&p);
    p.beta = NAN;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strstr(e.msg, "beta = nan is not a finite number"), "%s", e.msg);
    mpd_params_default(&p);
    p.corner[5] = INFINITY;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strstr(e.msg, "corner 5 = inf"), "%s", e.msg);
    mpd_params_default(&p);
    p.type = 7;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strstr(e.msg, "strategy = 7 is not one of"), "%s", e.msg);
    mpd_params_default(&p);
    p.type = MPD_TYPE4;
    p.R2 = 9;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL &&
              strstr(e.msg, "R2 = 9 is out of range for Type IV (expected 0 .. R = 6)"),
          "%s", e.msg);
}

/* max_nodes bounds every store of lattice nodes: explicit arrays over it
 * are refused (9^3 = 729 <= 1000 < 17^3 = 4913, so R2 <= 3), the automatic
 * choice stays within it, and Type II's memo stops growing at max_nodes
 * slots (it doubles from 1024: 1024, 2048, 4096 <= 5000 < 8192) while its
 * values stay those of the descent. */
static void test_node_limit(void)
{
    mpd m;
    mpd_params p;
    rt_error e = {0};
    mpd_params_default(&p);
    p.R = 4;
    p.type = MPD_TYPE1;
    p.max_nodes = 1000;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL &&
              strstr(e.msg, "Type I at R = 4 needs 17^3 = 4913 lattice nodes (limit 1000); use Type IV "
                            "(strategy: 4) with R2 = 3"),
          "%s", e.msg);
    p.R = 3;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK && m.type == MPD_TYPE1, "R = 3 fits: %s", e.msg);
    mpd_free(&m);
    p.R = 9;
    p.type = MPD_TYPE4;
    p.R2 = 4;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL &&
              strstr(e.msg, "Type IV with R2 = 4 needs 17^3 = 4913 lattice nodes in its array (limit 1000); use R2 <= 3"),
          "%s", e.msg);
    p.max_nodes = 7; /* not even R2 = 0 (8 corners) */
    p.R2 = 0;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_EINVAL && strstr(e.msg, "use Type III (strategy: 3)"), "%s", e.msg);
    p.type = MPD_AUTO;
    p.R2 = -1;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK && m.type == MPD_TYPE3 && m.arr == NULL, "auto, 7 nodes: type %d",
          m.type);
    mpd_free(&m);
    p.max_nodes = 1000;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK && m.type == MPD_TYPE4 && m.R2 == 3, "auto, 1000 nodes: type %d R2 %d",
          m.type, m.R2);
    mpd_free(&m);

    /* Type II at R = 20 over 4096 scattered points: unlimited, the memo
     * grows well past 4096 slots; limited, it stops at 4096 and the values
     * are still Type III's */
    enum { NP = 4096 };
    static double x[NP], y[NP], z[NP], o2[NP], o3[NP], ol[NP];
    rng r;
    rng_init(&r, 77, 0);
    for (int i = 0; i < NP; i++) {
        x[i] = rng_uniform(&r);
        y[i] = rng_uniform(&r);
        z[i] = rng_uniform(&r);
    }
    mpd m2 = make(20, MPD_TYPE2, -1, 3, 0.5, 1), m3 = make(20, MPD_TYPE3, -1, 3, 0.5, 1);
    mpd_stats s2, sl;
    CHECK(mpd_eval_points(&m2, NULL, NP, x, y, z, o2, &s2, NULL) == RT_OK, "Type II unlimited");
    CHECK(mpd_eval_points(&m3, NULL, NP, x, y, z, o3, NULL, NULL) == RT_OK, "Type III");
    m2.max_nodes = 5000;
    CHECK(mpd_eval_points(&m2, NULL, NP, x, y, z, ol, &sl, NULL) == RT_OK, "Type II limited");
    CHECK(s2.work_bytes > 4096 * 12, "unlimited memo %zu bytes", s2.work_bytes);
    CHECK(sl.work_bytes == 4096 * 12, "limited memo %zu bytes (4096 slots of 12 bytes)", sl.work_bytes);
    CHECK(memcmp(o2, o3, sizeof o2) == 0 && memcmp(ol, o3, sizeof ol) == 0, "Type II = Type III with and without limit");
    mpd_free(&m2);
    mpd_free(&m3);
}

/* Byte-identical output for 1, 2 and 4 threads (array fill, points, grid). */
static void test_threads(void)
{
    enum { NP = 9000 };
    double *x = rt_malloc(NP * sizeof *x), *y = rt_malloc(NP * sizeof *y), *z = rt_malloc(NP * sizeof *z);
    double *o[3];
    random_points(NP, x, y, z, 3);
    int types[4] = {MPD_TYPE1, MPD_TYPE2, MPD_TYPE3, MPD_TYPE4};
    for (int t = 0; t < 4; t++) {
        double *gr[3];
        for (int q = 0; q < 3; q++) {
            mpd m = make(7, types[t], 4, 77, 0.5, 1 << q);
            rt_run run = {1 << q, NULL, 0};
            o[q] = rt_malloc(NP * sizeof *o[q]);
            gr[q] = rt_malloc(20 * 20 * 20 * sizeof *gr[q]);
            mpd_eval_points(&m, &run, NP, x, y, z, o[q], NULL, NULL);
            double lo[3] = {0, 0, 0}, hi[3] = {1, 0.5, 0.25};
            mpd_eval_grid(&m, &run, lo, hi, 20, 20, 20, gr[q], NULL, NULL);
            mpd_free(&m);
        }
        for (int q = 1; q < 3; q++) {
            CHECK(memcmp(o[0], o[q], NP * sizeof *o[0]) == 0, "type %d points: threads 1 vs %d", types[t], 1 << q);
            CHECK(memcmp(gr[0], gr[q], 8000 * sizeof *gr[0]) == 0, "type %d grid: threads 1 vs %d", types[t], 1 << q);
        }
        for (int q = 0; q < 3; q++)
            rt_free(o[q]), rt_free(gr[q]);
    }
    rt_free(x), rt_free(y), rt_free(z);
}

int main(void)
{
    test_inv_normal();
    test_node_randoms();
    test_types_identical();
    test_corners_and_interp();
    test_refinement();
    test_level_statistics();
    test_memory();
    test_validation();
    test_node_limit();
    test_threads();
    return check_done("test_mpd");
}
