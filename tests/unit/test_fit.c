/* test_fit.c — fit_run's contracts: the SVD of a 2×2 map, the errors, the
 * same fit on any thread count, a range of map counts, a RIFS's chain.
 * (test_fit_recover.c: recovering known IFSs from their pictures.) */
#include <math.h>
#include <string.h>

#include "check.h"
#include "fit.h"

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

/* The chaos game of a loss starts at the fixed point of map 1, so a
 * one-map IFS draws that one point: a start map whose fixed point is the
 * centre of the only foreground pixel (16, 16) — t = (I - A) z; a weak
 * contraction 0.97 with a turn of 0.3 rad, so b f != 0 and a wrong start is
 * not forgotten in the burn-in — has loss 0 (every target cell covered, no
 * point off it), which no candidate can beat. */
static void test_one_point(void)
{
    unsigned char T[32 * 32] = {0};
    T[16 * 32 + 16] = 1;
    double a = 0.97 * cos(0.3), b = -0.97 * sin(0.3), c = -b, d = a, zx = 16.5 / 32, zy = 1 - 16.5 / 32;
    affine m = affine_from_2d(a, b, c, d, (1 - a) * zx - b * zy, -c * zx + (1 - d) * zy);
    fit_opts o = {.nmin = 1, .nmax = 1, .iterations = 2, .seed = 1, .start = &m, .nstart = 1};
    fit_result r;
    rt_error e;
    CHECK(fit_run(&(fit_mask){32, 32, T}, &o, NULL, &r, &e) == RT_OK, "%s", e.msg);
    CHECK(r.n == 1 && r.loss == 0, "one map onto its fixed point: %d maps, loss %g (expected 0)", r.n, r.loss);
}

int main(void)
{
    test_svd();
    test_errors();
    test_deterministic();
    test_rifs();
    test_one_point();
    return check_done("test_fit");
}
