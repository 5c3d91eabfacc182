/* test_fit.c — fit_run recovers known IFSs from their own pictures.
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

static void test_deterministic(void)
{
    /* same seed, 1 and 3 threads: the same maps, bit for bit */
    unsigned char T[32 * 32];
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++)
            T[y * 32 + x] = (x - 16) * (x - 16) + (y - 12) * (y - 12) < 80;
    fit_opts o = {.nmin = 2, .nmax = 3, .iterations = 30, .seed = 3};
    fit_result a, b;
    rt_error e;
    rt_run r1 = {.threads = 1}, r3 = {.threads = 3};
    CHECK(fit_run(&(fit_mask){32, 32, T}, &o, &r1, &a, &e) == RT_OK, "%s", e.msg);
    CHECK(fit_run(&(fit_mask){32, 32, T}, &o, &r3, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(a.n == b.n && memcmp(a.maps, b.maps, sizeof a.maps) == 0 && memcmp(a.p, b.p, sizeof a.p) == 0,
          "threads change the fit");
    /* a range returns one of its counts and runs every count */
    CHECK(a.n >= 2 && a.n <= 3, "n %d", a.n);
    CHECK(a.generations == 2 * (FIT_STARTS * 30 + 3), "generations %ld", a.generations);
}

static void test_rifs(void)
{
    /* rifs: rows of P sum to 1; the zero pattern keeps the chain irreducible (checked here
     * by a reachability closure, Floyd–Warshall style) */
    unsigned char T[32 * 32];
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++)
            T[y * 32 + x] = (x < 16) != (y < 16);
    fit_opts o = {.nmin = 4, .nmax = 4, .iterations = 40, .seed = 9, .rifs = 1};
    fit_result r;
    rt_error e;
    CHECK(fit_run(&(fit_mask){32, 32, T}, &o, NULL, &r, &e) == RT_OK, "%s", e.msg);
    CHECK(r.rifs == 1 && r.n == 4, "rifs %d n %d", r.rifs, r.n);
    int reach[4][4];
    for (int i = 0; i < 4; i++) {
        double sum = 0;
        for (int j = 0; j < 4; j++) {
            sum += r.P[i * 4 + j];
            CHECK(r.P[i * 4 + j] >= 0, "P %d %d", i, j);
            reach[i][j] = r.P[i * 4 + j] > 0;
        }
        CHECK_NEAR(sum, 1, 1e-12, "row sum");
    }
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++)
                reach[i][j] |= reach[i][k] && reach[k][j];
    int all = 1;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            all &= reach[i][j];
    CHECK(all, "the fitted chain is not irreducible");
}

static void test_svd(void)
{
    double m[2][2] = {{0.2, -0.26}, {0.23, 0.22}}, th, s1, s2, ph;
    fit_svd2(m, &th, &s1, &s2, &ph);
    double ct = cos(th), st = sin(th), cp = cos(ph), sp = sin(ph);
    CHECK_NEAR(ct * s1 * cp - st * s2 * sp, 0.2, 1e-12, "a");
    CHECK_NEAR(-ct * s1 * sp - st * s2 * cp, -0.26, 1e-12, "b");
    CHECK_NEAR(st * s1 * cp + ct * s2 * sp, 0.23, 1e-12, "c");
    CHECK_NEAR(-st * s1 * sp + ct * s2 * cp, 0.22, 1e-12, "d");
    /* singular values of the fern's third map: s1 s2 = |det| = 0.1038, s1 = its norm */
    CHECK_NEAR(fabs(s1 * s2), 0.2 * 0.22 + 0.26 * 0.23, 1e-12, "det");
    affine a = affine_from_2d(0.2, -0.26, 0.23, 0.22, 0, 0);
    CHECK_NEAR(s1, affine_contraction(&a), 1e-9, "norm");
}

static void test_errors(void)
{
    unsigned char z[4] = {0, 0, 0, 0}, one[4] = {1, 1, 1, 1}, dot[1] = {1};
    fit_opts o = {.nmin = 2, .nmax = 2, .iterations = 5, .seed = 1};
    fit_result r;
    rt_error e;
    CHECK(fit_run(&(fit_mask){2, 2, z}, &o, NULL, &r, &e) == RT_EINVAL &&
              !strcmp(e.msg, "the target has no foreground pixels (nothing to fit)"),
          "%s", e.msg);
    CHECK(fit_run(&(fit_mask){2, 2, one}, &o, NULL, &r, &e) == RT_EINVAL &&
              !strcmp(e.msg, "every pixel of the target is foreground (a fit needs some background)"),
          "%s", e.msg);
    CHECK(fit_run(&(fit_mask){1, 1, dot}, &o, NULL, &r, &e) == RT_EINVAL &&
              !strcmp(e.msg, "the target is 1×1 pixels (a target needs at least 2×2)"),
          "%s", e.msg);
    o.nmin = 0;
    unsigned char t[4] = {1, 0, 0, 0};
    CHECK(fit_run(&(fit_mask){2, 2, t}, &o, NULL, &r, &e) == RT_EINVAL &&
              !strcmp(e.msg, "maps must be from 1 to 16 (got 0..2)"),
          "%s", e.msg);
}

int main(void)
{
    test_svd();
    test_errors();
    test_deterministic();
    test_rifs();
    test_recover();
    return check_done("test_fit");
}
