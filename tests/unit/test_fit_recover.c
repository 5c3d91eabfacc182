/* test_fit_recover.c — fit_run recovers known IFSs from their own pictures
 * (a binary of its own: the slowest fit test, with its own time limit).
 *
 * The targets are drawn here with a plain chaos loop (its own generator, not
 * runtime/rng.h or chaos.c) in the fit's frame ([0, 1]², y up), the fitted
 * maps are drawn with the same loop, and the two masks are compared by the
 * symmetric overlap with a 1-pixel tolerance computed here:
 *     (|A ∩ dil(B)| + |B ∩ dil(A)|) / (|A| + |B|),   dil = 3×3 dilation.
 * None of this uses the fit's own loss. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "fit.h"

typedef struct m6 {
    double a, b, c, d, e, f, p;
} m6;

static void draw(const m6 *m, int n, int s, unsigned char *out)
{
    uint64_t st = 88172645463325252ull; /* Marsaglia's xorshift64 */
    double x = 0, y = 0, sum = 0;
    for (int i = 0; i < n; i++)
        sum += m[i].p;
    memset(out, 0, (size_t)s * s);
    for (long i = 0; i < 60L * s * s; i++) {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        double u = (double)(st >> 11) / 9007199254740992.0 * sum;
        int k = 0;
        while (k < n - 1 && u >= m[k].p)
            u -= m[k++].p;
        double nx = m[k].a * x + m[k].b * y + m[k].e, ny = m[k].c * x + m[k].d * y + m[k].f;
        x = nx, y = ny;
        if (i < 50)
            continue;
        int px = (int)floor(x * s), py = (int)floor((1 - y) * s);
        if (px >= 0 && px < s && py >= 0 && py < s)
            out[py * s + px] = 1;
    }
}

static double overlap(const unsigned char *A, const unsigned char *B, int s)
{
    long na = 0, nb = 0, hit = 0;
    for (int y = 0; y < s; y++)
        for (int x = 0; x < s; x++) {
            int da = 0, db = 0;
            for (int v = y - 1; v <= y + 1; v++)
                for (int u = x - 1; u <= x + 1; u++)
                    if (u >= 0 && v >= 0 && u < s && v < s) {
                        da |= A[v * s + u];
                        db |= B[v * s + u];
                    }
            na += A[y * s + x];
            nb += B[y * s + x];
            hit += (A[y * s + x] && db) + (B[y * s + x] && da);
        }
    return (double)hit / (double)(na + nb);
}

static double fit_overlap(const m6 *m, int n, int s, long iters, fit_result *r)
{
    static unsigned char T[128 * 128], A[128 * 128];
    draw(m, n, s, T);
    fit_opts o = {.nmin = n, .nmax = n, .iterations = iters, .seed = 7};
    rt_run run = {.threads = 2};
    rt_error e;
    rt_code c = fit_run(&(fit_mask){s, s, T}, &o, &run, r, &e);
    CHECK(c == RT_OK, "fit: %s", e.msg);
    if (c)
        return 0;
    m6 f[FIT_MAX_MAPS];
    for (int i = 0; i < r->n; i++)
        f[i] = (m6){r->maps[i].m[0][0], r->maps[i].m[0][1], r->maps[i].m[1][0], r->maps[i].m[1][1],
                    r->maps[i].t[0], r->maps[i].t[1], r->p[i]};
    draw(f, r->n, s, A);
    /* every fitted map is a contraction (largest singular value < 1) */
    for (int i = 0; i < r->n; i++)
        CHECK(affine_contraction(&r->maps[i]) < 0.98 + 1e-12, "map %d norm %g", i, affine_contraction(&r->maps[i]));
    return overlap(A, T, s);
}

static void test_recover(void)
{
    fit_result r;
    /* Sierpinski triangle inside the frame: three maps at 1/2 */
    m6 sier[3] = {{0.5, 0, 0, 0.5, 0.05, 0.05, 1}, {0.5, 0, 0, 0.5, 0.5, 0.05, 1}, {0.5, 0, 0, 0.5, 0.275, 0.5, 1}};
    double ov = fit_overlap(sier, 3, 64, 250, &r); /* 0.968 when written */
    CHECK(ov >= 0.95, "3-map Sierpinski: overlap %.3f", ov);
    CHECK(r.n == 3, "3 maps, got %d", r.n);
    /* a 2-map IFS: two copies at 0.6 turned by ±35 degrees (a "tree" of two branches) */
    double c = 0.6 * cos(35 * 3.14159265358979323846 / 180), s = 0.6 * sin(35 * 3.14159265358979323846 / 180);
    m6 two[2] = {{c, -s, s, c, 0.35, 0.1, 1}, {c, s, -s, c, 0.3, 0.5, 1}};
    ov = fit_overlap(two, 2, 64, 150, &r); /* 0.994 when written */
    CHECK(ov >= 0.95, "2-map: overlap %.3f", ov);
}


int main(void)
{
    test_recover();
    return check_done("test_fit_recover");
}
