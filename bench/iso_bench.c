/* iso_bench.c — iso-surface extraction and ray marching of a hypertexture-
 * like field (soft sphere × an analytic "noise" of products of sines).
 *
 * Reports, best of R runs each:
 *   - field sampling of an n³ grid, and the marching-cubes extractor on it,
 *     for n = 64, 128 and 256, with 1 and 2 threads, against VTK's
 *     vtkFlyingEdges3D on the same samples (one thread, bench/iso_vtk.py,
 *     when python3-vtk9 is installed), a plain marching-cubes loop (below:
 *     unwelded triangle soup, one thread) and, with the argument `tets`,
 *     the previous extractor (marching tetrahedra, bench/iso_tet_ref.inc);
 *   - ray marching a 512² image (emission–absorption with lighting, and the
 *     thresholded solid) with 1 and 2 threads;
 * with ratios against plain C baseline loops run in the same process:
 *   - iso: one pass over the volume comparing each sample with its +x, +y,
 *     +z neighbours against the level (the least any extractor must do);
 *   - raymarch: the same number of field evaluations as the render made,
 *     in a plain loop over points (no blocks, no compositing).
 *
 *   build/bench/iso_bench [runs] [iso|rm|all] [tets]
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "fileio.h"
#include "isosurf.h"
#include "raymarch.h"

#include "iso_tet_ref.inc"

/* Plain marching cubes, the textbook loop: per cell, the mask, the crossing
 * edges interpolated, the case's triangles appended as a soup of 9 floats
 * (no shared vertices, no padding, no normals). Its table separates inside
 * corners on every ambiguous face and fans each cycle (generated below). */
static unsigned char pm_nt[256], pm_e[256][12][3];
static const int pm_lo[12] = {0, 2, 4, 6, 0, 1, 4, 5, 0, 1, 2, 3}, pm_ax[12] = {1, 1, 1, 1, 2, 2, 2, 2, 4, 4, 4, 4};

static int pm_edge(int c0, int c1)
{
    for (int e = 0; e < 12; e++)
        if (pm_lo[e] == (c0 & c1) && pm_ax[e] == (c0 ^ c1))
            return e;
    return -1;
}

static void pm_table(void)
{
    static const int face[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (int m = 0; m < 256; m++) {
        int next[12];
        for (int e = 0; e < 12; e++)
            next[e] = -1;
        for (int f = 0; f < 6; f++)
            for (int k = 0; k < 4; k++) {
                int a = face[f][k], b = face[f][(k + 1) & 3];
                if ((m >> a & 1) || !(m >> b & 1))
                    continue;
                /* entry at (a, b): the exit is where the run of inside corners from b ends */
                int i = (k + 1) & 3;
                while (m >> face[f][(i + 1) & 3] & 1)
                    i = (i + 1) & 3;
                next[pm_edge(a, b)] = pm_edge(face[f][i], face[f][(i + 1) & 3]);
            }
        int seen[12] = {0}, nt = 0;
        for (int e0 = 0; e0 < 12; e0++) {
            if (next[e0] < 0 || seen[e0])
                continue;
            int cyc[12], k = 0;
            for (int e = e0; e >= 0 && !seen[e]; e = next[e])
                seen[e] = 1, cyc[k++] = e;
            for (int i = 1; i + 1 < k && nt < 12; i++, nt++)
                pm_e[m][nt][0] = (unsigned char)cyc[0], pm_e[m][nt][1] = (unsigned char)cyc[i],
                pm_e[m][nt][2] = (unsigned char)cyc[i + 1];
        }
        pm_nt[m] = (unsigned char)nt;
    }
}

static size_t plain_mc(const volume *v, float level, float **soup, size_t *cap)
{
    size_t n = 0;
    for (int z = 0; z + 1 < v->nz; z++)
        for (int y = 0; y + 1 < v->ny; y++)
            for (int x = 0; x + 1 < v->nx; x++) {
                float s[8];
                int m = 0;
                for (int c = 0; c < 8; c++) {
                    s[c] = *volume_at(v, x + (c & 1), y + (c >> 1 & 1), z + (c >> 2 & 1));
                    m |= (s[c] >= level) << c;
                }
                if (!pm_nt[m])
                    continue;
                float p[12][3];
                for (int e = 0; e < 12; e++) {
                    int a = pm_lo[e], b = a | pm_ax[e];
                    if (((m >> a) ^ (m >> b)) & 1) {
                        float t = (level - s[a]) / (s[b] - s[a]);
                        p[e][0] = x + (a & 1) + t * (pm_ax[e] == 1);
                        p[e][1] = y + (a >> 1 & 1) + t * (pm_ax[e] == 2);
                        p[e][2] = z + (a >> 2 & 1) + t * (pm_ax[e] == 4);
                    }
                }
                if (n + 12 > *cap) {
                    *cap = *cap ? *cap * 2 : 1 << 16;
                    *soup = realloc(*soup, *cap * 9 * sizeof(float));
                    if (!*soup)
                        exit(1);
                }
                for (int t = 0; t < pm_nt[m]; t++, n++)
                    for (int r = 0; r < 3; r++)
                        memcpy(*soup + 9 * n + 3 * r, p[pm_e[m][t][r]], 3 * sizeof(float));
            }
    return n;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static atomic_size_t evals;

static double field1(double x, double y, double z)
{
    double d2 = x * x + y * y + z * z, r1 = 0.55, r0 = 0.95; /* seed 001 soft sphere */
    double s = d2 < r1 * r1 ? 1 : d2 > r0 * r0 ? 0 : (r0 * r0 - d2) / (r0 * r0 - r1 * r1);
    double n = sin(7.1 * x + 1.3) * sin(8.3 * y + 0.7) * sin(9.7 * z + 2.1) +
               0.5 * sin(15.3 * x + 0.4) * sin(17.9 * y + 1.9) * sin(19.1 * z + 0.3);
    return s * (0.6 + 0.4 * n);
}

static void field(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                  double *out)
{
    (void)ctx;
    atomic_fetch_add_explicit(&evals, n, memory_order_relaxed);
    for (size_t i = 0; i < n; i++)
        out[i] = field1(x[i], y[i], z[i]);
}

static size_t baseline_scan(const volume *v, float level)
{
    size_t c = 0;
    for (int z = 0; z + 1 < v->nz; z++)
        for (int y = 0; y + 1 < v->ny; y++)
            for (int x = 0; x + 1 < v->nx; x++) {
                int a = *volume_at(v, x, y, z) >= level;
                c += (size_t)(a != (*volume_at(v, x + 1, y, z) >= level));
                c += (size_t)(a != (*volume_at(v, x, y + 1, z) >= level));
                c += (size_t)(a != (*volume_at(v, x, y, z + 1) >= level));
            }
    return c;
}

/* CPU seconds of the whole process (all threads). */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* VTK's vtkFlyingEdges3D, one thread, on the same samples: v is written to a
 * temporary file that bench/iso_vtk.py (found beside this program's source,
 * from the current directory or from argv[0]) reads and meshes; its line is
 * parsed and the ratios printed. Skipped with a reason when python3-vtk9 is
 * missing. */
static void flying_edges(const char *argv0, const volume *v, double level, int runs, double ours_cpu,
                         double ours_wall, double warm_cpu, double warm_wall, double first_cpu, size_t ours_nt)
{
    char script[4096], path[64], cmd[8192];
    snprintf(script, sizeof script, "bench/iso_vtk.py");
    FILE *f = fopen(script, "r");
    if (!f) {
        const char *sl = strrchr(argv0, '/');
        int len = sl ? (int)(sl - argv0) : 1;
        snprintf(script, sizeof script, "%.*s/../../bench/iso_vtk.py", len, sl ? argv0 : ".");
        f = fopen(script, "r");
    }
    if (!f) {
        printf("  FlyingEdges    skipped: bench/iso_vtk.py not found\n");
        return;
    }
    fclose(f);
    snprintf(path, sizeof path, "/tmp/frac-iso-bench-%ld.f32", (long)getpid());
    rt_error e;
    size_t count = (size_t)v->nx * (size_t)v->ny * (size_t)v->nz;
    if (fileio_write_atomic(path, v->v, count * sizeof(float), &e)) {
        printf("  FlyingEdges    skipped: %s\n", e.msg);
        return;
    }
    snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s' '%s' %d %.17g %d 2>&1", script, path, v->nx, level, runs);
    FILE *p = popen(cmd, "r");
    char line[512] = "";
    int ok = 0;
    double cpu = 0, wall = 0, fe_first = 0;
    long tris = 0, pts = 0;
    char backend[64] = "";
    while (p && fgets(line, sizeof line, p)) {
        int nn;
        if (sscanf(line, "fe %d %lf %lf %ld %ld %63s %lf", &nn, &cpu, &wall, &tris, &pts, backend, &fe_first) == 7) {
            ok = 1;
            break;
        }
        if (strncmp(line, "skipped", 7) == 0 || strncmp(line, "error", 5) == 0)
            break;
    }
    if (p)
        pclose(p);
    unlink(path);
    if (!ok) {
        line[strcspn(line, "\n")] = 0;
        printf("  FlyingEdges    skipped: %s\n", line[0] ? line : "iso_vtk.py printed nothing");
        return;
    }
    printf("  VTK FlyingEdges 1 thr (%s) CPU %.4f s wall %.4f s   %ld triangles, %ld points\n", backend, cpu, wall,
           tris, pts);
    printf("  ours / FlyingEdges: time %.2f (1 thr CPU), %.2f (1 thr wall); triangles %.3f\n", ours_cpu / cpu,
           ours_wall / wall, (double)ours_nt / (double)tris);
    if (warm_cpu < 1e9)
        printf("  ours / FlyingEdges, both on a warm heap: time %.2f (1 thr CPU), %.2f (1 thr wall)\n",
               warm_cpu / cpu, warm_wall / wall);
    printf("  first call of each (fresh memory): ours CPU %.4f s, FlyingEdges CPU %.4f s, ratio %.2f\n", first_cpu,
           fe_first, first_cpu / fe_first);
}

int main(int argc, char **argv)
{
    int runs = argc > 1 ? atoi(argv[1]) : 3;
    const char *only = argc > 2 ? argv[2] : "";
    int tets = argc > 3 && strcmp(argv[3], "tets") == 0;
    if (runs < 1)
        runs = 1;
    rt_error e;
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    iso_opts o;
    memset(&o, 0, sizeof o);
    o.level = 0.3;
    o.normals = 1;
    printf("iso_bench: best of %d runs\n", runs);
    int sizes[3] = {64, 128, 256};
    for (int si = 0; si < 3 && strcmp(only, "rm") != 0; si++) {
        int n = sizes[si];
        volume v;
        if (volume_init(&v, n, n, n, lo, hi, &e))
            return 1;
        double tsample[3] = {1e9, 1e9, 1e9}, tiso[3] = {1e9, 1e9, 1e9}, ttet[3] = {1e9, 1e9, 1e9};
        double tbase = 1e9, tplain = 1e9, ciso = 1e9, cfirst = -1;
        size_t nv = 0, nt = 0, sink = 0, tet_nt = 0, plain_nt = 0;
        for (int th = 1; th <= 2; th++) {
            rt_run run = {th, NULL, 0};
            for (int r = 0; r < runs; r++) {
                double t0 = now();
                iso_sample_field(field, NULL, &v, &run, &e);
                double t1 = now(), c1 = cpu_now();
                mesh m;
                if (iso_from_volume(&v, &o, &run, &m, &e)) {
                    fprintf(stderr, "%s\n", e.msg);
                    return 1;
                }
                double t2 = now(), c2 = cpu_now();
                nv = m.nv;
                nt = m.nt;
                mesh_free(&m);
                if (t1 - t0 < tsample[th])
                    tsample[th] = t1 - t0;
                if (t2 - t1 < tiso[th])
                    tiso[th] = t2 - t1;
                if (th == 1 && c2 - c1 < ciso)
                    ciso = c2 - c1;
                if (cfirst < 0)
                    cfirst = c2 - c1;
                if (!tets)
                    continue;
                if (tet_from_volume(&v, &o, &run, &m, &e)) {
                    fprintf(stderr, "%s\n", e.msg);
                    return 1;
                }
                double t3 = now();
                tet_nt = m.nt;
                mesh_free(&m);
                if (t3 - t2 < ttet[th])
                    ttet[th] = t3 - t2;
            }
        }
        /* The same extractor on a warm heap: glibc hands every big block of
         * the same size to mmap again after it is freed (its dynamic threshold
         * only rises above the sizes seen), so each run above pays one page
         * fault per 4 KiB of output (about 15 us each on these virtual
         * machines); VTK's repeated Update() reuses its freed blocks (no page
         * faults after the first, measured with perf stat). Here the mmap
         * threshold is raised so our freed blocks are reused too, then reset. */
        double twarm = 1e9, cwarm = 1e9;
#ifdef __GLIBC__
        mallopt(M_MMAP_THRESHOLD, 32 << 20);
        mallopt(M_TRIM_THRESHOLD, 256 << 20);
        for (int r = 0; r < runs + 1; r++) {
            rt_run run = {1, NULL, 0};
            mesh m;
            double t1 = now(), c1 = cpu_now();
            if (iso_from_volume(&v, &o, &run, &m, &e)) {
                fprintf(stderr, "%s\n", e.msg);
                return 1;
            }
            double t2 = now(), c2 = cpu_now();
            mesh_free(&m);
            if (r && t2 - t1 < twarm) /* run 0 fills the heap */
                twarm = t2 - t1;
            if (r && c2 - c1 < cwarm)
                cwarm = c2 - c1;
        }
        mallopt(M_MMAP_THRESHOLD, 128 << 10);
        mallopt(M_TRIM_THRESHOLD, 128 << 10);
#endif
        pm_table();
        float *soup = NULL;
        size_t cap = 0;
        for (int r = 0; r < runs; r++) {
            double t0 = now();
            plain_nt = plain_mc(&v, 0.3f, &soup, &cap);
            double t1 = now();
            if (t1 - t0 < tplain)
                tplain = t1 - t0;
        }
        free(soup);
        for (int r = 0; r < runs; r++) {
            double t0 = now();
            sink += baseline_scan(&v, 0.3f);
            double t1 = now();
            if (t1 - t0 < tbase)
                tbase = t1 - t0;
        }
        printf("%3d^3: %zu vertices, %zu triangles (sink %zu)\n", n, nv, nt, sink % 7);
        printf("  sample field   1 thr %7.3f s   2 thr %7.3f s   speed-up %.2fx\n", tsample[1], tsample[2],
               tsample[1] / tsample[2]);
        printf("  marching cubes 1 thr %7.4f s   2 thr %7.4f s   speed-up %.2fx   (1 thr CPU %.4f s)\n",
               tiso[1], tiso[2], tiso[1] / tiso[2], ciso);
        if (twarm < 1e9)
            printf("  marching cubes 1 thr, warm heap %7.4f s   (CPU %.4f s)\n", twarm, cwarm);
        if (tets)
            printf("  old tets       1 thr %7.3f s   2 thr %7.3f s   %zu triangles; new/old time %.2f (1 thr) %.2f (2 thr)\n",
                   ttet[1], ttet[2], tet_nt, tiso[1] / ttet[1], tiso[2] / ttet[2]);
        printf("  plain MC soup  1 thr %7.3f s   %zu triangles; new/plain time %.2f (1 thr), triangles %.3f\n",
               tplain, plain_nt, tiso[1] / tplain, (double)nt / plain_nt);
        printf("  baseline scan  1 thr %7.3f s   ratio march/baseline (1 thr) %.1fx\n", tbase, tiso[1] / tbase);
        flying_edges(argv[0], &v, 0.3, runs, ciso, tiso[1], cwarm, twarm, cfirst, nt);
        volume_free(&v);
    }

    camera cam;
    double tgt[3] = {0, 0, 0};
    camera_orbit(&cam, tgt, 3.2, 30, 20, 40);
    rm_opts ro;
    rm_defaults(&ro);
    ro.step = 1.0 / 128;
    ro.lighting = 1;
    ro.sigma = 6;
    static const char *mname[2] = {"emission+light", "solid t=0.3"};
    for (int mode = 0; mode < 2 && strcmp(only, "iso") != 0; mode++) {
        ro.mode = mode;
        ro.threshold = 0.3;
        double t[3] = {1e9, 1e9, 1e9};
        size_t ne = 0;
        image im;
        if (image_init(&im, 512, 512, &e))
            return 1;
        for (int th = 1; th <= 2; th++) {
            rt_run run = {th, NULL, 0};
            for (int r = 0; r < runs; r++) {
                atomic_store(&evals, 0);
                double t0 = now();
                if (rm_render(field, NULL, &cam, &ro, &run, &im, &e)) {
                    fprintf(stderr, "%s\n", e.msg);
                    return 1;
                }
                double t1 = now();
                ne = atomic_load(&evals);
                if (t1 - t0 < t[th])
                    t[th] = t1 - t0;
            }
        }
        /* baseline: the same number of evaluations in a plain loop */
        double tb = 1e9, acc = 0;
        for (int r = 0; r < runs; r++) {
            double t0 = now();
            for (size_t i = 0; i < ne; i++) {
                double u = (double)(i % 4096) / 4096.0 * 2 - 1, w = (double)(i / 4096 % 4096) / 4096.0 * 2 - 1;
                acc += field1(u, w, 0.37 * u - 0.2);
            }
            double t1 = now();
            if (t1 - t0 < tb)
                tb = t1 - t0;
        }
        printf("raymarch 512^2 %-15s %zu evals: 1 thr %6.3f s  2 thr %6.3f s  speed-up %.2fx  "
               "baseline %6.3f s  ratio %.2fx (acc %d)\n",
               mname[mode], ne, t[1], t[2], t[1] / t[2], tb, t[1] / tb, (int)acc % 2);
        image_free(&im);
    }
    return 0;
}
