/* chaos_bench.c — chaos game throughput against a plain C loop doing the
 * same work in the same process (xoshiro256++, alias choice, 2-D fern into a
 * private 1024² count array; 3-D RIFS of seed 001 Table 1 into 256³ voxels,
 * plain and with a 32-deep prefetch ring), then the fixed cost and peak RSS
 * of one render in a fresh process (fork; CPU time and ru_maxrss from wait4):
 * the render as chaos() leaves it (pixels pending, tonemap.h), made ready,
 * and saved as PNG against the plain loop plus a PNG of its counts.
 *
 *   make build/bench/chaos_bench && ./build/bench/chaos_bench [Mpoints]
 *
 * Each throughput is the best of 3 runs. One-thread figures are thread CPU
 * time (CLOCK_THREAD_CPUTIME_ID: time slices lost to other jobs on the
 * shared machine do not count), two-thread figures wall time. */
#define _DEFAULT_SOURCE /* wait4 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "chaos.h"
#include "png.h"
#include "rng.h"
#include "tonemap.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
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

/* one step of the plain 3-D loops: the next map k from state s's row of
 * the RIFS (alias choice), the point halved towards octant k's corner;
 * returns k, the new state */
static inline uint32_t oct_step(const rifs *rf, rng *r, uint32_t s, double *x, double *y, double *z)
{
    uint64_t w = rng_next(r);
    const ifs_alias *al = &rf->row[s];
    uint32_t col = (uint32_t)(((w >> 32) * 8) >> 32);
    uint32_t k = al->sel[2 * col + ((uint32_t)w < al->thresh[col])];
    *x = 0.5 * *x + OCT[k][0], *y = 0.5 * *y + OCT[k][1], *z = 0.5 * *z + OCT[k][2];
    return k;
}

static uint64_t plain3(uint64_t npts, const rifs *rf, uint32_t *cnt)
{
    rng r;
    rng_init(&r, 1, 0);
    double x = 0, y = 0, z = 0;
    uint32_t s = 0;
    uint64_t inside = 0;
    for (uint64_t i = 0; i < npts; i++) {
        s = oct_step(rf, &r, s, &x, &y, &z);
        double fx = x, fy = y, fz = z; /* box [0,256]³, 256 voxels: scale 1 */
        if (fx >= 0 && fx < 256 && fy >= 0 && fy < 256 && fz >= 0 && fz < 256) {
            cnt[(size_t)(int)fx + 256 * ((size_t)(int)fy + 256 * (size_t)(int)fz)]++;
            inside++;
        }
    }
    return inside;
}

/* the plain loop with the facts' prefetch ring: each voxel is prefetched
 * when computed and counted 32 points later (outside: a spare slot) */
static uint64_t plain3p(uint64_t npts, const rifs *rf, uint32_t *cnt)
{
    enum { R = 32 };
    const size_t trash = (size_t)256 * 256 * 256;
    size_t ring[R];
    for (int q = 0; q < R; q++)
        ring[q] = trash;
    rng r;
    rng_init(&r, 1, 0);
    double x = 0, y = 0, z = 0;
    uint32_t s = 0;
    uint64_t inside = 0;
    for (uint64_t i = 0; i < npts; i++) {
        s = oct_step(rf, &r, s, &x, &y, &z);
        size_t b = trash;
        if (x >= 0 && x < 256 && y >= 0 && y < 256 && z >= 0 && z < 256) {
            b = (size_t)(int)x + 256 * ((size_t)(int)y + 256 * (size_t)(int)z);
            inside++;
        }
        __builtin_prefetch(&cnt[b], 1, 0);
        cnt[ring[i % R]]++;
        ring[i % R] = b;
    }
    for (int q = 0; q < R; q++)
        cnt[ring[q]]++;
    return inside;
}

/* ---- fresh-process measurements: CPU seconds and peak RSS of one job ---- */

typedef struct fresh { double cpu, rss_mb; long faults; } fresh;

static fresh run_fresh(void (*job)(void))
{
    fresh f = {-1, -1, -1};
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        job();
        _exit(0);
    }
    int st;
    struct rusage ru;
    if (pid < 0 || wait4(pid, &st, 0, &ru) != pid || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
        return f;
    f.cpu = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
    f.rss_mb = ru.ru_maxrss / 1024.0; /* KiB on Linux */
    f.faults = ru.ru_minflt + ru.ru_majflt;
    return f;
}

static ifs g_fern;
static rifs g_rifs;
static const double FLO[2] = {-2.5, -0.2}, FHI[2] = {2.9, 10.2};
#define FRESH_POINTS 100000

static void job_empty(void) {}

static void job_plain2(void)
{
    uint32_t *cnt = calloc(1024 * 1024, 4);
    uint64_t in = plain2(FRESH_POINTS, &g_fern.alias, FLO, FHI, cnt);
    if (!cnt || in == 42)
        _exit(1);
    free(cnt);
}

/* the plain loop and a PNG of its counts: log grey of each count, straight
 * into 8-bit RGBA samples (a 256-entry table up to the maximum), then the
 * same encoder; the pairing for "render + save" below */
static void job_plain2_png(void)
{
    uint32_t *cnt = calloc(1024 * 1024, 4);
    unsigned char *smp = malloc((size_t)1024 * 1024 * 4);
    if (!cnt || !smp)
        _exit(1);
    plain2(FRESH_POINTS, &g_fern.alias, FLO, FHI, cnt);
    uint32_t mx = 0;
    for (size_t b = 0; b < 1024 * 1024; b++)
        mx = cnt[b] > mx ? cnt[b] : mx;
    double lmx = log1p((double)mx);
    unsigned char t[256];
    for (uint32_t c = 0; c < 256; c++)
        t[c] = (unsigned char)(c > mx ? 255 : (int)(255 * log1p((double)c) / lmx + 0.5));
    for (size_t b = 0; b < 1024 * 1024; b++) {
        uint32_t c = cnt[b];
        unsigned char v = c < 256 ? t[c] : (unsigned char)(255 * log1p((double)c) / lmx + 0.5);
        smp[4 * b] = smp[4 * b + 1] = smp[4 * b + 2] = v;
        smp[4 * b + 3] = c ? 255 : 0;
    }
    free(cnt);
    rt_error e;
    bytebuf b;
    bytebuf_init(&b);
    if (png_encode_samples(smp, 1024, 1024, 4, 8, PNG_DEFAULT_LEVEL, &b, NULL, &e))
        _exit(1);
    bytebuf_free(&b);
    free(smp);
}

/* what chaos(fern, size: [1024, 1024]) does: fit, count, tone map with the
 * pixels pending (tonemap_defer: the maximum pass; the float image is
 * allocated, not written). ready: then made ready (image_ready writes the
 * 16 MB float image, what a script that reads pixels causes, and what this
 * job ended with before session 8); png: saved instead (png_encode tone-maps
 * band by band into the samples) */
enum { R_PENDING, R_READY, R_PNG };
static void render2(int colour, int then)
{
    rt_error e;
    chaos_sys s = {&g_fern, NULL};
    chaos_opts o = {0};
    o.points = FRESH_POINTS;
    o.seed = 1;
    o.colour = colour ? CHAOS_COLOUR_BLEND : CHAOS_COLOUR_NONE;
    rt_run r1 = {1, NULL, 0};
    double lo[2], hi[2];
    hist2 hs;
    image im;
    tonemap_opts t = {0};
    t.colour = colour ? TONEMAP_MEAN : TONEMAP_RAMP;
    if (chaos_fit(&s, &o, 1024, 1024, lo, hi, &e) || hist2_init_for(&hs, 1024, 1024, lo, hi, colour, o.points, &e) ||
        chaos_hist2(&s, &o, &hs, NULL, &r1, &e) || image_init(&im, 1024, 1024, &e) || tonemap_defer(&hs, &t, &im, &e))
        _exit(1);
    hist2_free(&hs);
    if (then == R_READY)
        image_ready(&im);
    if (then == R_PNG) {
        bytebuf b;
        bytebuf_init(&b);
        if (png_encode(&im, 8, 4, &b, &e))
            _exit(1);
        bytebuf_free(&b);
    }
    image_free(&im);
}
static void job_render2(void) { render2(0, R_PENDING); }
static void job_render2_ready(void) { render2(0, R_READY); }
static void job_render2_png(void) { render2(0, R_PNG); }
static void job_render2_colour(void) { render2(1, R_PENDING); }

/* the window pre-pass alone (chaos_fit, helper ovh17's; counted in the
 * render above), to state the render's cost without it */
static void job_fit(void)
{
    rt_error e;
    chaos_sys s = {&g_fern, NULL};
    chaos_opts o = {0};
    o.points = FRESH_POINTS;
    o.seed = 1;
    double lo[2], hi[2];
    if (chaos_fit(&s, &o, 1024, 1024, lo, hi, &e))
        _exit(1);
}

static void job_plain3(void)
{
    uint32_t *cnt = calloc((size_t)256 * 256 * 256 + 1, 4);
    uint64_t in = plain3p(FRESH_POINTS, &g_rifs, cnt);
    if (!cnt || in == 42)
        _exit(1);
    free(cnt);
}

static void job_measure3(void)
{
    rt_error e;
    volume vol;
    double vlo[3] = {0, 0, 0}, vhi[3] = {256, 256, 256};
    chaos_sys s3 = {NULL, &g_rifs};
    chaos_opts o = {0};
    o.points = FRESH_POINTS;
    o.seed = 1;
    rt_run r1 = {1, NULL, 0};
    if (volume_init(&vol, 256, 256, 256, vlo, vhi, &e) || chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r1, &e))
        _exit(1);
    volume_free(&vol);
}

/* A fresh job of ~10 ms swings several-fold on the shared machine (one
 * sample of the plain loop took 2–13 ms in the same minute): each job runs
 * FRESH_REPS times and reports its best and median CPU, the fewest faults
 * and the smallest peak RSS; the ratio is best against best. */
#define FRESH_REPS 5

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static fresh run_fresh_best(void (*job)(void), double *median)
{
    double t[FRESH_REPS];
    fresh best = run_fresh(job);
    t[0] = best.cpu;
    for (int r = 1; r < FRESH_REPS; r++) {
        fresh f = run_fresh(job);
        t[r] = f.cpu;
        best.cpu = f.cpu < best.cpu ? f.cpu : best.cpu;
        best.rss_mb = f.rss_mb < best.rss_mb ? f.rss_mb : best.rss_mb;
        best.faults = f.faults < best.faults ? f.faults : best.faults;
    }
    qsort(t, FRESH_REPS, sizeof t[0], cmp_double);
    *median = t[FRESH_REPS / 2];
    return best;
}

static void fresh_report(void)
{
    double base_med;
    fresh base = run_fresh_best(job_empty, &base_med);
    struct { const char *what; void (*job)(void); double data_mb; } jobs[] = {
        {"plain 2-D loop (1024^2 uint32 counts)", job_plain2, 4},
        {"chaos render 1024^2 (fit, counts, tone map*)", job_render2, 4},
        {"  ... pixels made ready (float image written)", job_render2_ready, 20},
        {"  the window pre-pass alone (chaos_fit)", job_fit, 0},
        {"plain 2-D loop + PNG of its counts", job_plain2_png, 8},
        {"chaos render 1024^2 + PNG encode (RGBA 8-bit)", job_render2_png, 12},
        {"chaos render 1024^2, colour blend", job_render2_colour, 32},
        {"plain 3-D loop (256^3 uint32, prefetch ring)", job_plain3, 64},
        {"chaos measure 256^3 (counts, float volume)", job_measure3, 64},
    };
    printf("fresh process, %d points, 1 thread, best and median of %d (CPU s above an empty child's\n"
           "  best %.4f s; peak RSS above its %.1f MB)\n", FRESH_POINTS, FRESH_REPS, base.cpu, base.rss_mb);
    printf("  %-46s %8s %8s %8s %8s %8s %7s\n", "job", "CPU best", "median", "RSS MB", "data MB", "RSS/data",
           "faults");
    double cpu[sizeof jobs / sizeof jobs[0]];
    for (size_t i = 0; i < sizeof jobs / sizeof jobs[0]; i++) {
        double med;
        fresh f = run_fresh_best(jobs[i].job, &med);
        double rss = f.rss_mb - base.rss_mb;
        cpu[i] = f.cpu - base.cpu;
        if (jobs[i].data_mb > 0)
            printf("  %-46s %8.4f %8.4f %8.1f %8.0f %7.2fx %7ld\n", jobs[i].what, cpu[i], med - base_med, rss,
                   jobs[i].data_mb, rss / jobs[i].data_mb, f.faults - base.faults);
        else
            printf("  %-46s %8.4f %8.4f %8.1f %8s %8s %7ld\n", jobs[i].what, cpu[i], med - base_med, rss, "-", "-",
                   f.faults - base.faults);
    }
    printf("  (* as chaos() returns it: the maximum found, the pixels pending (tonemap_defer); the\n"
           "   float image is written only when a script reads it (made ready) and a PNG save\n"
           "   tone-maps in bands instead)\n");
    printf("  (data: what the job must hold at once. 2-D render: 4 B/px counts (uint32: fewer than 2^32\n"
           "   points; the pixels pending: the\n"
           "   image's 16 B/px are allocated, not touched); made ready: + the 16 B/px float RGBA image;\n"
           "   + PNG: the counts, 4 B/px samples and 4 B/px filtered rows; plain + PNG: samples and filtered\n"
           "   rows (its counts are freed first); colour: 16 B/px histogram + the worker's 16 B/px cells;\n"
           "   3-D: the 4 B/voxel float volume)\n");
    printf("  fixed cost of a 1024^2 chaos render (fit, counts, tone map*) vs the plain loop: %.2fx CPU,"
           " best of %d each (goal <= 2x); without the pre-pass %.2fx\n", cpu[1] / cpu[0], FRESH_REPS,
           (cpu[1] - cpu[3]) / cpu[0]);
    printf("  pixels made ready: %.2fx; render + PNG vs plain loop + PNG: %.2fx\n", cpu[2] / cpu[0],
           cpu[5] / cpu[4]);
}

/* best-of-3 timer: thread CPU time for one thread, wall time otherwise */
#define TIME_BEST(best, cpu, stmt)                                                                \
    do {                                                                                         \
        double t0_ = (cpu) ? cpu_now() : now();                                                  \
        stmt;                                                                                    \
        double t_ = ((cpu) ? cpu_now() : now()) - t0_;                                           \
        if (t_ < (best))                                                                         \
            (best) = t_;                                                                         \
    } while (0)

int main(int argc, char **argv)
{
    uint64_t N = (uint64_t)(argc > 1 ? atof(argv[1]) : 64) * 1000000;
    rt_error e;
    affine fm[4];
    for (int k = 0; k < 4; k++)
        fm[k] = affine_from_2d(FERN[k][0], FERN[k][1], FERN[k][3], FERN[k][4], FERN[k][2], FERN[k][5]);
    affine om[8];
    double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
    for (int i = 0; i < 8; i++)
        om[i] = affine_from_3d(m9, OCT[i]);
    if (ifs_build(&g_fern, fm, 4, FERN_P, 0, &e) || rifs_build(&g_rifs, om, 8, 1, T1, RIFS_NORMALISE, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return 1;
    }
    fresh_report(); /* first, while this process is small */

    const double *lo = FLO, *hi = FHI;
    uint32_t *cnt = calloc(1024 * 1024, 4);
    double best_plain = 1e9, best_eng = 1e9, best_col = 1e9, best_2t = 1e9, q_plain = 1e9, q_eng = 1e9;
    uint64_t Nq = N / 4; /* rates as slopes between N/4 and N: fixed costs drop out */
    uint64_t sink = 0;
    chaos_sys s = {&g_fern, NULL};
    chaos_opts o = {0};
    o.points = N;
    o.seed = 1;
    rt_run r1 = {1, NULL, 0}, r2 = {2, NULL, 0};
    for (int rep = 0; rep < 3; rep++) {
        memset(cnt, 0, 1024 * 1024 * 4);
        TIME_BEST(best_plain, 1, sink += plain2(N, &g_fern.alias, lo, hi, cnt));
        TIME_BEST(q_plain, 1, sink += plain2(Nq, &g_fern.alias, lo, hi, cnt));
        hist2 hs; /* every call below adds into it: 32-bit counts while their points total < 2^32 */
        hist2_init_for(&hs, 1024, 1024, lo, hi, 1, 3 * N + Nq, &e);
        o.colour = CHAOS_COLOUR_NONE;
        TIME_BEST(best_eng, 1, chaos_hist2(&s, &o, &hs, NULL, &r1, &e));
        o.points = Nq;
        TIME_BEST(q_eng, 1, chaos_hist2(&s, &o, &hs, NULL, &r1, &e));
        o.points = N;
        o.colour = CHAOS_COLOUR_BLEND;
        TIME_BEST(best_col, 1, chaos_hist2(&s, &o, &hs, NULL, &r1, &e));
        o.colour = CHAOS_COLOUR_NONE;
        TIME_BEST(best_2t, 0, chaos_hist2(&s, &o, &hs, NULL, &r2, &e));
        hist2_free(&hs);
    }
    double Mp = N / 1e6;
    printf("2-D fern, 1024^2 counts, %.0f M points (best of 3; 1 thread: CPU time, 2 threads: wall)\n", Mp);
    printf("  plain C loop           %7.1f M points/s\n", Mp / best_plain);
    printf("  chaos_hist2, 1 thread  %7.1f M points/s  (%.2fx plain)\n", Mp / best_eng, best_plain / best_eng);
    printf("  slopes N/4..N: plain %.1f, chaos_hist2 %.1f M points/s (%.2fx plain)\n", 0.75 * Mp / (best_plain - q_plain),
           0.75 * Mp / (best_eng - q_eng), (best_plain - q_plain) / (best_eng - q_eng));
    printf("  with colour (blend)    %7.1f M points/s  (%.2fx plain; goal >= 0.90x)\n", Mp / best_col, best_plain / best_col);
    printf("  2 threads              %7.1f M points/s  (%.2fx 1 thread)\n", Mp / best_2t, best_eng / best_2t);
    free(cnt);

    uint32_t *vc = calloc((size_t)256 * 256 * 256 + 1, 4);
    volume vol;
    double vlo[3] = {0, 0, 0}, vhi[3] = {256, 256, 256};
    volume_init(&vol, 256, 256, 256, vlo, vhi, &e);
    chaos_sys s3 = {NULL, &g_rifs};
    o.colour = CHAOS_COLOUR_NONE;
    double bp = 1e9, bpp = 1e9, be = 1e9, b2 = 1e9, qpp = 1e9, qe = 1e9;
    for (int rep = 0; rep < 3; rep++) {
        TIME_BEST(bp, 1, sink += plain3(N, &g_rifs, vc));
        TIME_BEST(bpp, 1, sink += plain3p(N, &g_rifs, vc));
        TIME_BEST(be, 1, chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r1, &e));
        TIME_BEST(qpp, 1, sink += plain3p(Nq, &g_rifs, vc));
        o.points = Nq;
        TIME_BEST(qe, 1, chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r1, &e));
        o.points = N;
        TIME_BEST(b2, 0, chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r2, &e));
    }
    printf("3-D RIFS (seed 001 Table 1), 256^3 voxels, %.0f M points (best of 3; engine time includes\n"
           "  zeroing the counts and writing the float volume)\n", Mp);
    printf("  plain C loop           %7.1f M points/s\n", Mp / bp);
    printf("  plain, prefetch ring   %7.1f M points/s\n", Mp / bpp);
    printf("  chaos_volume, 1 thread %7.1f M points/s  (%.2fx prefetch loop; goal >= 0.90x)\n", Mp / be, bpp / be);
    printf("  slopes N/4..N: prefetch loop %.1f, chaos_volume %.1f M points/s (%.2fx)\n", 0.75 * Mp / (bpp - qpp),
           0.75 * Mp / (be - qe), (bpp - qpp) / (be - qe));
    printf("  2 threads              %7.1f M points/s  (%.2fx 1 thread)\n", Mp / b2, be / b2);
    volume_free(&vol);
    free(vc);
    ifs_free(&g_fern);
    rifs_free(&g_rifs);
    return sink == 42 ? 2 : 0;
}
