/* ist_bench.c — IST evaluation, wrinkly tessellation, rasteriser scaling and
 * LOD. Ratios are against plain C loops run in the same process.
 *   ./build/bench/ist_bench
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ist.h"
#include "raster.h"
#include "wrinkly.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Baseline: the bare base-(2M+1) digit arithmetic of one evaluation. */
static double baseline_digits(int b, int k, uint64_t s, size_t n, double *sink)
{
    double acc = 0, t0 = now();
    for (size_t q = 0; q < n; q++) {
        double u = (double)(q % 1000003) * (64.0 / 1000003.0);
        double fl = (double)(long)u;
        uint64_t idx = (uint64_t)((u - fl) * (double)s), src = 0;
        long sum = 0;
        for (int m = 0; m < k; m++) {
            uint64_t p = idx % (uint64_t)b;
            idx /= (uint64_t)b;
            sum += (long)p;
            src = src * (uint64_t)b + p;
        }
        acc += (double)src + (double)sum;
    }
    *sink += acc;
    return now() - t0;
}

static double time_inv(const ist *t, size_t n, double *sink)
{
    double acc = 0, t0 = now();
    for (size_t q = 0; q < n; q++)
        acc += ist_inv(t, (double)(q % 1000003) * (64.0 / 1000003.0));
    *sink += acc;
    return now() - t0;
}

/* The same n evaluations through ist_inv_block, 4096 at a time (the u are
 * generated as in time_inv, inside the timing). */
static double time_inv_block(const ist *t, size_t n, double *sink)
{
    static double u[4096], f[4096];
    double acc = 0, t0 = now();
    for (size_t q0 = 0; q0 < n; q0 += 4096) {
        size_t c = n - q0 < 4096 ? n - q0 : 4096;
        for (size_t q = 0; q < c; q++)
            u[q] = (double)((q0 + q) % 1000003) * (64.0 / 1000003.0);
        ist_inv_block(t, c, u, f);
        for (size_t q = 0; q < c; q++)
            acc += f[q];
    }
    *sink += acc;
    return now() - t0;
}

static double best3(double (*f)(void *), void *c)
{
    double b = 1e30;
    for (int r = 0; r < 3; r++) {
        double t = f(c);
        b = t < b ? t : b;
    }
    return b;
}

static wrinkly_point *torus(int nu, int nv)
{
    wrinkly_point *p = calloc((size_t)nu * nv, sizeof *p);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            wrinkly_point *q = &p[j * nu + i];
            double a = 6.283185307179586 * i / nu, b = 6.283185307179586 * j / nv;
            q->pos[0] = (3 + cos(b)) * cos(a), q->pos[1] = sin(b), q->pos[2] = (3 + cos(b)) * sin(a);
            q->h = 0.05 * ((i * 7 + j * 3) % 5);
            q->rgb[0] = 0.3 + 0.05 * (i % 8), q->rgb[1] = 0.6, q->rgb[2] = 0.2 + 0.1 * (j % 5);
            q->opacity = 1;
        }
    return p;
}

typedef struct tess_ctx {
    wrinkly_surface *s;
    wrinkly_opts *o;
    rt_run run;
    size_t nv;
} tess_ctx;

static double tess_once(void *c)
{
    tess_ctx *T = c;
    mesh m;
    rt_error e;
    double t0 = now();
    wrinkly_surface_mesh(T->s, T->o, &T->run, &m, NULL, &e);
    double t = now() - t0;
    T->nv = m.nv;
    mesh_free(&m);
    return t;
}

typedef struct rast_ctx {
    mesh *m;
    camera *cam;
    raster_opts *o;
    rt_run run;
    image *im;
} rast_ctx;

static double rast_once(void *c)
{
    rast_ctx *R = c;
    rt_error e;
    double t0 = now();
    raster_render(R->m, R->cam, R->o, &R->run, R->im, &e);
    return now() - t0;
}

int main(void)
{
    double sink = 0;
    size_t n = 20000000;
    printf("IST F^-1 on 64 unit intervals, %zu evaluations, best of 3\n", n);
    for (int axis = 0; axis < 2; axis++)
        for (int m = 1; m <= 2; m++)
            for (int k = 4; k <= 8; k += 4) {
                ist t;
                rt_error e;
                ist_spec s = {.n = 64, .m = m, .k = k, .axis = (ist_axis_type)axis};
                ist_init(&t, &s, &e);
                double tb = 1e30, ti = 1e30, tk = 1e30;
                for (int r = 0; r < 3; r++) {
                    double a = baseline_digits(2 * m + 1, k, t.s, n, &sink);
                    double b = time_inv(&t, n, &sink);
                    double c = time_inv_block(&t, n, &sink);
                    tb = a < tb ? a : tb;
                    ti = b < ti ? b : ti;
                    tk = c < tk ? c : tk;
                }
                printf("  %-11s M=%d K=%d: %6.1f M evals/s, block %6.1f M/s  (digit loop %6.1f M/s, "
                       "ratio %.2f, block %.2f)\n",
                       axis ? "cyclic" : "translation", m, k, n / ti * 1e-6, n / tk * 1e-6, n / tb * 1e-6,
                       ti / tb, tk / tb);
                ist_free(&t);
            }

    wrinkly_point *p = torus(24, 16);
    wrinkly_surface s = {p, 24, 16, {1, 1, 1}, {1, 1, 1}};
    wrinkly_opts o;
    wrinkly_opts_default(&o);
    o.k = 3;
    tess_ctx T = {&s, &o, {1, NULL, 0}, 0};
    double t1 = best3(tess_once, &T);
    T.run.threads = 2;
    double t2 = best3(tess_once, &T);
    printf("tessellation: %zu vertices, 1 thread %.1f M vertices/s, 2 threads %.1f M/s (x%.2f)\n", T.nv,
           T.nv / t1 * 1e-6, T.nv / t2 * 1e-6, t1 / t2);

    mesh m;
    rt_error e;
    o.k = 2;
    wrinkly_surface_mesh(&s, &o, NULL, &m, NULL, &e);
    camera cam;
    camera_orbit(&cam, (double[3]){0, 0, 0}, 9, 30, 35, 45);
    raster_opts ro;
    raster_opts_default(&ro);
    image im;
    image_init(&im, 1024, 768, &e);
    rast_ctx R = {&m, &cam, &ro, {1, NULL, 0}, &im};
    double r1 = best3(rast_once, &R);
    R.run.threads = 2;
    double r2 = best3(rast_once, &R);
    printf("raster: %zu triangles into 1024x768, 1 thread %.1f ms, 2 threads %.1f ms (x%.2f)\n", m.nt,
           r1 * 1e3, r2 * 1e3, r1 / r2);
    mesh_free(&m);
    image_free(&im);

    printf("LOD (200x200 image, 1 px sub-intervals, kmax 8):\n");
    for (int q = 0; q < 5; q++) {
        double dist = 8.0 * pow(2.0, q);
        camera c2;
        camera_orbit(&c2, (double[3]){0, 0, 0}, dist, 20, 30, 40);
        wrinkly_opts lo;
        wrinkly_opts_default(&lo);
        lo.cam = &c2;
        lo.width = lo.height = 200;
        wrinkly_info info;
        mesh lm;
        wrinkly_surface_mesh(&s, &lo, NULL, &lm, &info, &e);
        /* how many pixels the surface covers */
        image li;
        image_init(&li, 200, 200, &e);
        raster_opts lr;
        raster_opts_default(&lr);
        lr.background[3] = 0;
        raster_render(&lm, &c2, &lr, NULL, &li, &e);
        size_t cov = 0;
        for (size_t i = 0; i < 200 * 200; i++)
            cov += li.px[4 * i + 3] > 0;
        double full = 2.0 * 24 * 16 * pow(3.0, 2 * (info.k[0] > info.k[1] ? info.k[0] : info.k[1]));
        printf("  distance %5.0f: K=(%d,%d) %8zu triangles, %6zu pixels covered, %.1f tri/px; "
               "uniform (2M+1)^K grid would be %.0f\n",
               dist, info.k[0], info.k[1], lm.nt, cov, cov ? (double)lm.nt / cov : 0.0, full);
        image_free(&li);
        mesh_free(&lm);
    }
    free(p);
    if (sink == 1234.5)
        printf("%g\n", sink);
    return 0;
}
