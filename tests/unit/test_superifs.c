/* test_superifs.c — V-variable super IFS (seed 004 §5). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "superifs.h"

static const double CX[3] = {0, 1, 0.5}, CY[3] = {0, 0, 0.8660254037844386};

/* Sierpinski maps of ratio s toward the corners of the triangle above. */
static void sierp(affine m[3], double s)
{
    for (int i = 0; i < 3; i++)
        m[i] = affine_from_2d(s, 0, 0, s, (1 - s) * CX[i], (1 - s) * CY[i]);
}

static int in_triangle(double x, double y)
{
    /* y >= 0, left edge y <= √3 x, right edge y <= √3 (1 − x). */
    double e = 1e-12;
    return y >= -e && y <= 1.7320508075688772 * x + e && y <= 1.7320508075688772 * (1 - x) + e;
}

int main(void)
{
    rt_error e;
    affine half[3], third[3];
    sierp(half, 0.5);
    sierp(third, 1.0 / 3);
    fset_ifs F[2] = {{3, half, NULL}, {3, third, (double[]){0.5, 0.25, 0.25}}};
    fset fs = {2, F};
    double P[2] = {0.4, 0.6};

    /* ---- V = 1 is the random function set: same draws, same histogram. */
    superifs_opts so = {1, 10000, 20, 5, {0.3, 0.2}};
    superifs_state st;
    CHECK(superifs_run(&fs, P, &so, &st, NULL, &e) == RT_OK, "V=1: %s", e.msg);
    hist2 h1, h2;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    hist2_init(&h1, 64, 64, lo, hi, 0, &e);
    hist2_init(&h2, 64, 64, lo, hi, 0, &e);
    CHECK(superifs_render(&st, 0, &h1, &e) == RT_OK, "render");
    fset_order ord = {FSET_RANDOM, 0, NULL, P, 5};
    fset_chaos_opts co = {FSET_WALK, 10000, 5, 0, 0, 20, {0.3, 0.2}};
    CHECK(fset_chaos(&fs, &ord, &co, &h2, NULL, &e) == RT_OK, "walk: %s", e.msg);
    CHECK(memcmp(h1.count, h2.count, 64 * 64 * sizeof *h1.count) == 0,
          "V = 1 super IFS equals the random function set");
    /* …and the comparison can fail: another seed gives another shape. */
    superifs_state st2;
    so.seed = 6;
    superifs_run(&fs, P, &so, &st2, NULL, &e);
    memset(h2.count, 0, 64 * 64 * sizeof *h2.count);
    superifs_render(&st2, 0, &h2, &e);
    CHECK(memcmp(h1.count, h2.count, 64 * 64 * sizeof *h1.count) != 0, "seed 6 differs from 5");
    superifs_free(&st2);
    superifs_free(&st);

    /* ---- the paper's example: V = 3, Sierpinski 1/2 and 1/3, M = 3, N = 2.
     * Every map sends the triangle into itself, so every buffer stays in
     * it. Identical for 1, 2, 4 threads. */
    superifs_opts s3 = {3, 9000, 25, 11, {0.5, 0.3}};
    superifs_state ref;
    CHECK(superifs_run(&fs, P, &s3, &ref, NULL, &e) == RT_OK, "V=3: %s", e.msg);
    int inside = 1;
    for (size_t i = 0; i < 3 * ref.points; i++)
        inside &= in_triangle(ref.pts[2 * i], ref.pts[2 * i + 1]);
    CHECK(inside, "all buffers inside the triangle");
    CHECK(ref.ifs_of[0] >= 0 && ref.ifs_of[0] < 2 && ref.ifs_of[2] >= 0 && ref.ifs_of[2] < 2,
          "IFS of each buffer recorded");
    for (int t = 2; t <= 4; t += 2) {
        rt_run run = {t, NULL, 0};
        superifs_state o;
        CHECK(superifs_run(&fs, P, &s3, &o, &run, &e) == RT_OK, "threads");
        CHECK(memcmp(o.pts, ref.pts, 3 * ref.points * 2 * sizeof(double)) == 0,
              "identical with %d threads", t);
        superifs_free(&o);
    }
    superifs_free(&ref);

    /* ---- one IFS, the right Sierpinski triangle f_0 = p/2, f_1 = p/2 +
     * (1/2, 0), f_2 = p/2 + (0, 1/2), V = 3 from (0, 0): after k steps every
     * point is (X, Y)/2^k with integers X, Y having no common 1 bit (each
     * step adds a binary digit to x or to y, never both: Lucas / Pascal
     * mod 2). */
    affine r[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                   affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5)};
    fset_ifs R = {3, r, NULL};
    fset fr = {1, &R};
    superifs_opts sr = {3, 5000, 20, 3, {0, 0}};
    superifs_state rs;
    CHECK(superifs_run(&fr, NULL, &sr, &rs, NULL, &e) == RT_OK, "right Sierpinski");
    int gasket = 1, hasx = 0, hasy = 0;
    for (size_t i = 0; i < 3 * rs.points; i++) {
        double x = rs.pts[2 * i] * (1 << 20), y = rs.pts[2 * i + 1] * (1 << 20);
        unsigned long X = (unsigned long)x, Y = (unsigned long)y;
        gasket &= (double)X == x && (double)Y == y && (X & Y) == 0;
        hasx |= X != 0;
        hasy |= Y != 0;
    }
    CHECK(gasket && hasx && hasy, "points on the Sierpinski gasket (binary digits disjoint)");
    superifs_free(&rs);

    /* superifs_bounds: the box of the finite points of every buffer (V = 2,
     * 3 points each; NaN and inf are passed over), by hand: x in -2 .. 4,
     * y in -1 .. 5. */
    double pts[12] = {1, 5, NAN, 0, 4, 2, /* buffer 1 */ -2, INFINITY, 0, -1, 3, 0.5};
    superifs_state bs = {2, 3, pts, NULL};
    double blo[2], bhi[2];
    CHECK(superifs_bounds(&bs, blo, bhi) == 0 && blo[0] == -2 && bhi[0] == 4 && blo[1] == -1 && bhi[1] == 5,
          "bounds of all buffers: [%g, %g] x [%g, %g]", blo[0], bhi[0], blo[1], bhi[1]);
    double none[4] = {NAN, 1, -INFINITY, 2}; /* y finite, x not */
    superifs_state ns = {1, 2, none, NULL};
    CHECK(superifs_bounds(&ns, blo, bhi) == -1, "no finite x: no bounds");

    /* Errors. */
    superifs_opts bad = {0, 10, 1, 1, {0, 0}};
    CHECK(superifs_run(&fs, P, &bad, &st, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "super IFS has 0 buffers (expected at least 1)") == 0,
          "V = 0: %s", e.msg);
    CHECK(superifs_render(&rs, 0, &h1, &e) == RT_EINVAL, "render of a freed state");
    hist2_free(&h1);
    hist2_free(&h2);
    return check_done("test_superifs");
}
