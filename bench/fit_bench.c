/* fit_bench.c — quality and speed of fit_run (runtime/fit.h) on targets drawn
 * here by an independent plain C chaos loop (its own generator, its own
 * window), not by frac's chaos game.
 *
 *   build/bench/fit_bench [SIZE [ITERATIONS [NAME [SEED]]]]     (default 128 600, all, 1)
 *
 * For each target: draw it at SIZE×SIZE, fit it with its reference number of
 * maps, render the fit with the same plain loop in the target's frame, and
 * score the two masks:
 *   overlap   = (|A ∩ dil(B)| + |B ∩ dil(A)|) / (|A| + |B|), dil = 3×3
 *               dilation (a 1-pixel tolerance); 1 = the same shape
 *   Hausdorff = max over both masks of the distance (pixels) from a pixel of
 *               one to the nearest pixel of the other (brute force)
 * plus the CPU time of the fit (one thread). Then Tu et al.'s protocol
 * (AAAI 2023): the target drawn at 32×32, fitted at 32×32, and the mean
 * squared error of the fitted attractor's binary 32×32 render.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fit.h"

typedef struct map6 {
    double a, b, c, d, e, f, p;
} map6;

typedef struct target {
    const char *name;
    int n;          /* maps of the reference IFS; 0: not an IFS (drawn otherwise) */
    map6 m[4];
    int fit_maps;   /* maps to fit with */
} target;

/* Classic codes (Fractint order x' = a x + b y + e, y' = c x + d y + f). */
static const target targets[] = {
    {"sierpinski", 3, {{0.5, 0, 0, 0.5, 0, 0, 1}, {0.5, 0, 0, 0.5, 0.5, 0, 1}, {0.5, 0, 0, 0.5, 0.25, 0.5, 1}}, 3},
    {"fern", 4,
     {{0, 0, 0, 0.16, 0, 0, 0.01}, {0.85, 0.04, -0.04, 0.85, 0, 1.6, 0.85}, {0.2, -0.26, 0.23, 0.22, 0, 1.6, 0.07},
      {-0.15, 0.28, 0.26, 0.24, 0, 0.44, 0.07}},
     4},
    /* Heighway: f1(z) = (1+i) z / 2, f2(z) = 1 - (1-i) z / 2 */
    {"dragon", 2, {{0.5, -0.5, 0.5, 0.5, 0, 0, 1}, {-0.5, -0.5, 0.5, -0.5, 1, 0, 1}}, 2},
    /* Koch: four copies at 1/3, the middle two rotated by ±60° */
    {"koch", 4,
     {{1.0 / 3, 0, 0, 1.0 / 3, 0, 0, 1},
      {1.0 / 6, -0.28867513459481287, 0.28867513459481287, 1.0 / 6, 1.0 / 3, 0, 1},
      {1.0 / 6, 0.28867513459481287, -0.28867513459481287, 1.0 / 6, 0.5, 0.28867513459481287, 1},
      {1.0 / 3, 0, 0, 1.0 / 3, 2.0 / 3, 0, 1}},
     4},
    /* the maple leaf often reproduced from Barnsley's "Fractals Everywhere" */
    {"maple", 4,
     {{0.14, 0.01, 0, 0.51, -0.08, -1.31, 1}, {0.43, 0.52, -0.45, 0.5, 1.49, -0.75, 1},
      {0.45, -0.49, 0.47, 0.47, -1.62, -0.74, 1}, {0.49, 0, 0, 0.51, 0.02, 1.62, 1}},
     4},
    {"disc", 0, {{0, 0, 0, 0, 0, 0, 0}}, 4},
    {"letter F", 0, {{0, 0, 0, 0, 0, 0, 0}}, 4},
};

/* xorshift64*, unrelated to runtime/rng.h */
static uint64_t xs_state;
static double xs_unit(void)
{
    xs_state ^= xs_state >> 12;
    xs_state ^= xs_state << 25;
    xs_state ^= xs_state >> 27;
    return (double)((xs_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

static void chaos_plain(const map6 *m, int n, double x0, double x1, double y0, double y1, int w, int h, long pts,
                        unsigned char *out)
{
    double sum = 0;
    for (int i = 0; i < n; i++)
        sum += m[i].p;
    double x = 0, y = 0;
    memset(out, 0, (size_t)w * h);
    xs_state = 0x9e3779b97f4a7c15ull;
    for (long i = 0; i < pts + 100; i++) {
        double u = xs_unit() * sum;
        int k = 0;
        while (k < n - 1 && u >= m[k].p) {
            u -= m[k].p;
            k++;
        }
        double nx = m[k].a * x + m[k].b * y + m[k].e, ny = m[k].c * x + m[k].d * y + m[k].f;
        x = nx, y = ny;
        if (i < 100)
            continue;
        int px = (int)floor((x - x0) / (x1 - x0) * w), py = (int)floor((y1 - y) / (y1 - y0) * h);
        if (px >= 0 && px < w && py >= 0 && py < h)
            out[(size_t)py * w + px] = 1;
    }
}

/* the target, framed with a 6 % margin and the aspect kept (square picture) */
static void draw_target(const target *t, int s, unsigned char *out)
{
    if (t->n) {
        map6 m[4];
        memcpy(m, t->m, sizeof m);
        if (strcmp(t->name, "fern") != 0) /* not the fern: equal-ish weights by |det| */
            for (int i = 0; i < t->n; i++)
                m[i].p = fmax(fabs(m[i].a * m[i].d - m[i].b * m[i].c), 0.01);
        /* bounding box by a pre-pass */
        double x = 0, y = 0, x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
        xs_state = 12345;
        for (int i = 0; i < 200000; i++) {
            double u = xs_unit() * t->n;
            int k = (int)u;
            double nx = m[k].a * x + m[k].b * y + m[k].e, ny = m[k].c * x + m[k].d * y + m[k].f;
            x = nx, y = ny;
            if (i > 100) {
                x0 = fmin(x0, x), x1 = fmax(x1, x), y0 = fmin(y0, y), y1 = fmax(y1, y);
            }
        }
        double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2, half = fmax(x1 - x0, y1 - y0) / 2 * 1.12;
        chaos_plain(m, t->n, cx - half, cx + half, cy - half, cy + half, s, s, (long)s * s * 40, out);
    } else if (!strcmp(t->name, "disc")) {
        for (int py = 0; py < s; py++)
            for (int px = 0; px < s; px++) {
                double dx = (px + 0.5) / s - 0.5, dy = (py + 0.5) / s - 0.5;
                out[(size_t)py * s + px] = dx * dx + dy * dy <= 0.4 * 0.4;
            }
    } else { /* a hand-drawn 7×9 "F", scaled up with a margin of one cell */
        static const char *F[9] = {".......", ".#####.", ".#.....", ".#.....", ".####..",
                                   ".#.....", ".#.....", ".#.....", "......."};
        for (int py = 0; py < s; py++)
            for (int px = 0; px < s; px++)
                out[(size_t)py * s + px] = F[py * 9 / s][px * 7 / s] == '#';
    }
}

static void render_fit(const fit_result *r, int w, int h, unsigned char *out)
{
    map6 m[FIT_MAX_MAPS];
    for (int i = 0; i < r->n; i++) {
        const affine *a = &r->maps[i];
        m[i] = (map6){a->m[0][0], a->m[0][1], a->m[1][0], a->m[1][1], a->t[0], a->t[1], r->p[i]};
    }
    chaos_plain(m, r->n, 0, 1, 0, 1, w, h, (long)w * h * 40, out);
}

static double overlap(const unsigned char *A, const unsigned char *B, int w, int h)
{
    long na = 0, nb = 0, ab = 0, ba = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int ia = A[(size_t)y * w + x], ib = B[(size_t)y * w + x], da = 0, db = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int u = x + dx, v = y + dy;
                    if (u < 0 || v < 0 || u >= w || v >= h)
                        continue;
                    da |= A[(size_t)v * w + u];
                    db |= B[(size_t)v * w + u];
                }
            na += ia, nb += ib;
            ab += ia && db;
            ba += ib && da;
        }
    return na + nb ? (double)(ab + ba) / (double)(na + nb) : 1;
}

static double directed(const unsigned char *A, const unsigned char *B, int w, int h)
{
    int *bx = malloc(sizeof(int) * (size_t)w * h), *by = malloc(sizeof(int) * (size_t)w * h), nb = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (B[(size_t)y * w + x])
                bx[nb] = x, by[nb++] = y;
    double worst = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (!A[(size_t)y * w + x])
                continue;
            double best = 1e18;
            for (int k = 0; k < nb && best > worst; k++) {
                double dx = x - bx[k], dy = y - by[k], d = dx * dx + dy * dy;
                if (d < best)
                    best = d;
            }
            if (best > worst)
                worst = best;
        }
    free(bx);
    free(by);
    return sqrt(worst);
}

static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
    int s = argc > 1 ? atoi(argv[1]) : 128;
    long iters = argc > 2 ? atol(argv[2]) : 600;
    const char *only = argc > 3 && strcmp(argv[3], "all") != 0 ? argv[3] : NULL;
    uint64_t seed = argc > 4 ? (uint64_t)atoll(argv[4]) : 1;
    unsigned char *T = malloc((size_t)s * s), *A = malloc((size_t)s * s);
    unsigned char T32[32 * 32], A32[32 * 32];
    printf("| target | maps | overlap (1 px) | Hausdorff (px) | CPU s | Tu et al. MSE 32² |\n|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < sizeof targets / sizeof *targets; i++) {
        const target *t = &targets[i];
        if (only && strcmp(only, t->name) != 0)
            continue;
        draw_target(t, s, T);
        fit_opts o = {.nmin = t->fit_maps, .nmax = t->fit_maps, .iterations = iters, .seed = seed};
        rt_run run = {.threads = 1};
        fit_result r;
        rt_error e;
        double c0 = cpu_s();
        rt_code c = fit_run(&(fit_mask){s, s, T}, &o, &run, &r, &e);
        double c1 = cpu_s();
        if (c) {
            printf("%s: %s\n", t->name, e.msg);
            return 1;
        }
        render_fit(&r, s, s, A);
        double ov = overlap(A, T, s, s), hd = fmax(directed(A, T, s, s), directed(T, A, s, s));
        /* Tu et al.: 32×32 */
        draw_target(t, 32, T32);
        fit_result r32;
        c = fit_run(&(fit_mask){32, 32, T32}, &o, &run, &r32, &e);
        double mse = -1;
        if (!c) {
            render_fit(&r32, 32, 32, A32);
            long d = 0;
            for (int k = 0; k < 32 * 32; k++)
                d += A32[k] != T32[k];
            mse = d / 1024.0;
        }
        printf("| %s | %d | %.3f | %.1f | %.1f | %.4f |\n", t->name, t->fit_maps, ov, hd, c1 - c0, mse);
        fflush(stdout);
        if (getenv("FIT_BENCH_DUMP")) {
            char path[256];
            snprintf(path, sizeof path, "%s/%s.pgm", getenv("FIT_BENCH_DUMP"), t->name);
            FILE *f = fopen(path, "wb");
            if (f) {
                fprintf(f, "P5\n%d %d\n255\n", 2 * s, s);
                for (int y = 0; y < s; y++) {
                    for (int x = 0; x < s; x++)
                        fputc(T[(size_t)y * s + x] ? 255 : 0, f);
                    for (int x = 0; x < s; x++)
                        fputc(A[(size_t)y * s + x] ? 255 : 0, f);
                }
                fclose(f);
            }
        }
    }
    free(T);
    free(A);
    return 0;
}
