/* mpd_bench.c — seed 000's experiments for the random fractal D(P), Types I–IV.
 *
 *   build/bench/mpd_bench [threads] [maxR]
 *
 * Tables (best of 3 runs each; times in ms):
 *   0. Type I fill against a plain C triple loop over the same lattice that
 *      stores the same hashed normal deviate per node (no parents): the
 *      ratio baseline/fill (>= 0.8 wanted).
 *   1. Experiment 1: all lattice points, time and memory vs R.
 *   2. Experiment 2: the digital sphere inscribed in the lattice (lattice
 *      points inside the sphere with a 6-neighbour outside), Type IV with
 *      R2 = 6 as in the paper's fig. 10.
 *   3. Surface texturing (marble on D through a textured sphere) vs image
 *      size at R = 8 and vs R at 256 x 256.
 * Memory: bytes the engine holds (array + largest per-worker working set).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpd.h"
#include "rng.h"
#include "solid.h"
#include "texobj.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static rt_run RUN = {1, NULL, 0};

/* The baseline: every node's normalised key, hash and normal deviate, in
 * raster order, stored as float. */
static double baseline(int R, float *a)
{
    uint32_t N = 1u << R;
    size_t S1 = (size_t)N + 1;
    double t0 = now();
    for (uint32_t k = 0; k <= N; k++)
        for (uint32_t j = 0; j <= N; j++)
            for (uint32_t i = 0; i <= N; i++) {
                uint32_t low = (i | j | k) & (N - 1);
                int b = low ? __builtin_ctz(low) : R;
                int n = R - b;
                uint64_t h = rng_hash3(1, ((uint64_t)n << 32) | (i >> b), j >> b, k >> b);
                a[i + S1 * (j + S1 * (size_t)k)] = (float)(mpd_normal(h) * 0.5);
            }
    return now() - t0;
}

static mpd make(int R, int type, int R2)
{
    mpd_params p;
    mpd_params_default(&p);
    p.R = R;
    p.type = type;
    p.R2 = R2;
    p.seed = 1;
    mpd m;
    rt_error e;
    if (mpd_init(&m, &p, &RUN, &e)) {
        fprintf(stderr, "mpd_init: %s\n", e.msg);
        exit(1);
    }
    return m;
}


static void table0(int maxR)
{
    printf("\n## 0. Type I fill vs plain C loop (same lattice, same hash + normal per node)\n\n");
    printf("| R | nodes | baseline ms | Type I fill ms | ns/node fill | baseline/fill |\n|---|---|---|---|---|---|\n");
    for (int R = 6; R <= maxR; R++) {
        size_t S1 = ((size_t)1 << R) + 1, nn = S1 * S1 * S1;
        float *a = malloc(nn * sizeof *a);
        double tb = 1e30, tf = 1e30;
        for (int rep = 0; rep < 3; rep++) {
            double t = baseline(R, a);
            tb = t < tb ? t : tb;
            double t0 = now();
            mpd m = make(R, MPD_TYPE1, 0);
            t = now() - t0;
            tf = t < tf ? t : tf;
            mpd_free(&m);
        }
        printf("| %d | %zu | %.1f | %.1f | %.1f | %.2f |\n", R, nn, tb * 1e3, tf * 1e3, tf * 1e9 / nn, tb / tf);
        free(a);
    }
}

typedef struct result {
    double ms;
    size_t bytes;
} result;

/* Best of 3 runs of Type `type` at level R: the (2^R+1)^3 lattice points of
 * experiment 1 when x is NULL, else the n points x, y, z of experiment 2.
 * A run over 20 s ends the repeats (Type II on the large spheres). */
static result exp_run(int R, int type, int R2, size_t n, const double *x, const double *y, const double *z,
                      double *out)
{
    result r = {1e30, 0};
    int N = (1 << R) + 1;
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    for (int rep = 0; rep < 3; rep++) {
        double t0 = now();
        mpd m = make(R, type, R2);
        mpd_stats st;
        rt_error e;
        if (x ? mpd_eval_points(&m, &RUN, n, x, y, z, out, &st, &e)
              : mpd_eval_grid(&m, &RUN, lo, hi, N, N, N, out, &st, &e)) {
            fprintf(stderr, "%s\n", e.msg);
            exit(1);
        }
        double t = (now() - t0) * 1e3;
        if (t < r.ms)
            r.ms = t;
        r.bytes = st.array_bytes + st.work_bytes * st.workers;
        mpd_free(&m);
        if (type == MPD_TYPE2 && t > 20000)
            break;
    }
    return r;
}

static void table1(int maxR)
{
    printf("\n## 1. Experiment 1: all (2^R+1)^3 lattice points (time ms / engine memory)\n\n");
    printf("| R | Type I | Type II | Type III | Type IV (R2 = R-3) | IV/I time | IV/I memory |\n|---|---|---|---|---|---|---|\n");
    for (int R = 4; R <= maxR && R <= 8; R++) {
        size_t N = ((size_t)1 << R) + 1;
        double *out = malloc(N * N * N * sizeof *out);
        result r1 = exp_run(R, MPD_TYPE1, 0, 0, NULL, NULL, NULL, out);
        result r2 = {0, 0};
        if (R <= 6)
            r2 = exp_run(R, MPD_TYPE2, 0, 0, NULL, NULL, NULL, out);
        result r3 = exp_run(R, MPD_TYPE3, 0, 0, NULL, NULL, NULL, out);
        result r4 = exp_run(R, MPD_TYPE4, R - 3 > 0 ? R - 3 : 0, 0, NULL, NULL, NULL, out);
        char c2[64];
        if (R <= 6)
            snprintf(c2, sizeof c2, "%.1f / %.1f MB", r2.ms, r2.bytes / 1e6);
        else
            snprintf(c2, sizeof c2, "-");
        printf("| %d | %.1f / %.2f MB | %s | %.1f / %.3f MB | %.1f / %.3f MB | %.2f | 1/%.0f |\n", R, r1.ms,
               r1.bytes / 1e6, c2, r3.ms, r3.bytes / 1e6, r4.ms, r4.bytes / 1e6, r4.ms / r1.ms,
               (double)r1.bytes / r4.bytes);
        free(out);
    }
}

static void table2(int maxR)
{
    printf("\n## 2. Experiment 2: digital sphere inscribed in the lattice (surface points; time ms / memory)\n\n");
    printf("| R | points | Type I | Type II | Type III | Type IV (R2 = 6) | I/IV time |\n|---|---|---|---|---|---|---|\n");
    for (int R = 6; R <= maxR && R <= 9; R++) {
        int N = 1 << R;
        double c = N / 2.0, r2 = c * c;
        size_t cap = 1 << 20, n = 0;
        double *x = NULL, *y = NULL, *z = NULL;
        for (int pass = 0; pass < 2; pass++) {
            n = 0;
            for (int k = 0; k <= N; k++)
                for (int j = 0; j <= N; j++)
                    for (int i = 0; i <= N; i++) {
#define INSIDE(a, b, d) (((a) - c) * ((a) - c) + ((b) - c) * ((b) - c) + ((d) - c) * ((d) - c) <= r2)
                        if (!INSIDE(i, j, k))
                            continue;
                        if (INSIDE(i + 1, j, k) && INSIDE(i - 1, j, k) && INSIDE(i, j + 1, k) &&
                            INSIDE(i, j - 1, k) && INSIDE(i, j, k + 1) && INSIDE(i, j, k - 1))
                            continue;
                        if (pass == 1) {
                            x[n] = (double)i / N;
                            y[n] = (double)j / N;
                            z[n] = (double)k / N;
                        }
                        n++;
                    }
            if (pass == 0) {
                cap = n;
                x = malloc(cap * sizeof *x);
                y = malloc(cap * sizeof *y);
                z = malloc(cap * sizeof *z);
            }
        }
        double *out = malloc(n * sizeof *out);
        result a = exp_run(R, MPD_TYPE1, 0, n, x, y, z, out);
        result b = {0, 0};
        if (R <= 7)
            b = exp_run(R, MPD_TYPE2, 0, n, x, y, z, out);
        result c3 = exp_run(R, MPD_TYPE3, 0, n, x, y, z, out);
        result d = exp_run(R, MPD_TYPE4, 6, n, x, y, z, out);
        char cb[64];
        if (R <= 7)
            snprintf(cb, sizeof cb, "%.1f / %.1f MB", b.ms, b.bytes / 1e6);
        else
            snprintf(cb, sizeof cb, "-");
        printf("| %d | %zu | %.1f / %.1f MB | %s | %.1f / %.3f MB | %.1f / %.2f MB | %.2f |\n", R, n, a.ms,
               a.bytes / 1e6, cb, c3.ms, c3.bytes / 1e6, d.ms, d.bytes / 1e6, a.ms / d.ms);
        free(x), free(y), free(z), free(out);
    }
}

static double render_ms(int R, int type, int size, unsigned long long *hits)
{
    mpd m = make(R, type, -1);
    solid_texture tex;
    solid_texture_default(&tex);
    tex.marble.n = 3;
    tex.marble.layer[0] = (solid_layer){0.2, 0.05, 20};
    tex.marble.layer[1] = (solid_layer){0.5, 0.1, 15};
    tex.marble.layer[2] = (solid_layer){0.8, 0.03, 30};
    tex.d_fn = mpd_eval;
    tex.d_ctx = &m;
    tex.k = 0.1;
    tex.warp = SOLID_WARP_Z;
    for (int i = 0; i < 3; i++)
        tex.d_lo[i] = -1, tex.d_hi[i] = 1;
    ramp r = solid_ramp_marble();
    texobj_source src = {solid_eval, &tex, &r, NULL, NULL};
    texobj_opts o;
    texobj_opts_default(&o);
    camera cam;
    double target[3] = {0, 0, 0};
    camera_orbit(&cam, target, 3.2, 30, 20, 45);
    texobj_shape s = {TEXOBJ_SPHERE, {0, 0, 0}, 1.0, 0, {0, 0, 0}};
    image im;
    image_init(&im, size, size, NULL);
    double best = 1e30;
    for (int rep = 0; rep < 3; rep++) {
        texobj_stats st;
        double t0 = now();
        texobj_render(&s, &cam, &src, &o, &RUN, &im, &st, NULL);
        double t = now() - t0;
        best = t < best ? t : best;
        *hits = st.hits;
    }
    image_free(&im);
    mpd_free(&m);
    return best * 1e3;
}

static void table3(int maxR)
{
    unsigned long long hits;
    printf("\n## 3. Surface texturing: marble sphere (texture only at hit pixels)\n\n");
    printf("| image | hits | Type IV ms (R = 8, auto R2) | ns/hit | Type III ms | ns/hit |\n|---|---|---|---|---|---|\n");
    for (int size = 128; size <= 512; size *= 2) {
        double t4 = render_ms(8, MPD_TYPE4, size, &hits);
        double t3 = render_ms(8, MPD_TYPE3, size, &hits);
        printf("| %d^2 | %llu | %.1f | %.0f | %.1f | %.0f |\n", size, hits, t4, t4 * 1e6 / hits, t3,
               t3 * 1e6 / hits);
    }
    printf("\n| R | Type IV ms at 256^2 (R2 = min(R, 7)) | Type III ms |\n|---|---|---|\n");
    for (int R = 6; R <= maxR + 2 && R <= 14; R += 2) {
        double t4 = render_ms(R, MPD_TYPE4, 256, &hits);
        double t3 = render_ms(R, MPD_TYPE3, 256, &hits);
        printf("| %d | %.1f | %.1f |\n", R, t4, t3);
    }
}

int main(int argc, char **argv)
{
    RUN.threads = argc > 1 ? atoi(argv[1]) : 1;
    int maxR = argc > 2 ? atoi(argv[2]) : 8;
    if (RUN.threads < 1)
        RUN.threads = 1;
    printf("mpd_bench: threads %d, max R %d (best of 3)\n", RUN.threads, maxR);
    table0(maxR);
    table1(maxR);
    table2(maxR + 1);
    table3(maxR);
    return 0;
}
