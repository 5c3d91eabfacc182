/* test_tops.c — fractal tops and colour stealing (seed 004 §3, §4, §6). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "tops.h"

/* Four maps of ratio s toward the corners of the unit square, in the order
 * lower-left, lower-right, upper-left, upper-right (indices 0..3). */
static void corners(affine m[4], double s)
{
    double t = 1 - s;
    m[0] = affine_from_2d(s, 0, 0, s, 0, 0);
    m[1] = affine_from_2d(s, 0, 0, s, t, 0);
    m[2] = affine_from_2d(s, 0, 0, s, 0, t);
    m[3] = affine_from_2d(s, 0, 0, s, t, t);
}

/* The corner map whose image holds (x, y), preferring the greater index:
 * right if x >= cut, upper if y >= cut. */
static int top_corner(double x, double y, double cut) { return (x >= cut) + 2 * (y >= cut); }

static int near_line(int i, int n, const double *lines, int nl)
{
    for (int k = 0; k < nl; k++) {
        double edge = lines[k] * n; /* pixel coordinate of the line */
        if (i + 1 >= edge - 1e-9 && i <= edge + 1e-9)
            return 1;
    }
    return 0;
}

int main(void)
{
    rt_error e;
    affine quad[4], over[4];
    corners(quad, 0.5);
    corners(over, 0.6);

    /* ---- non-overlapping: the first two symbols of every pixel's top are
     * its quadrant and sub-quadrant (pixels touching the lines x, y ∈
     * {1/4, 1/2, 3/4} are left out: boundary points belong to two pieces). */
    enum { W = 32 };
    draw_view v;
    CHECK(draw_view_fit(&v, W, W, (double[]){0, 0}, (double[]){1, 1}, 1, &e) == RT_OK, "view");
    fset_ifs fq = {4, quad, NULL};
    tops_opts o = {300000, 1, 0};
    tops_buf t;
    CHECK(tops_run(&fq, &v, &o, &t, NULL, &e) == RT_OK, "tops: %s", e.msg);
    CHECK(t.depth == 31, "4 maps keep 31 symbols (got %d)", t.depth);
    double lines[3] = {0.25, 0.5, 0.75};
    int bad = 0, tested = 0;
    for (int iy = 0; iy < W; iy++)
        for (int ix = 0; ix < W; ix++) {
            if (near_line(ix, W, lines, 3) || near_line(iy, W, lines, 3))
                continue;
            double x = (ix + 0.5) / W, y = 1 - (iy + 0.5) / W;
            int q1 = top_corner(x, y, 0.5);
            double x2 = 2 * x - (q1 & 1), y2 = 2 * y - (q1 >> 1); /* undo map q1 */
            int q2 = top_corner(x2, y2, 0.5);
            const tops_cell *c = &t.cell[iy * W + ix];
            tested++;
            bad += !c->hit || tops_symbol(&t, c->key, 0) != q1 || tops_symbol(&t, c->key, 1) != q2;
        }
    CHECK(bad == 0 && tested == 26 * 26, "address prefix = quadrant, sub-quadrant (%d of %d wrong)",
          bad, tested);
    tops_free(&t);

    /* ---- overlapping maps of ratio 0.6: [0,0.6]² ∪ [0.4,1]×[0,0.6] ∪ …;
     * in every overlap the greater map owns the pixel, whatever the
     * probabilities (here the smallest map index is the most likely). */
    enum { W2 = 40 };
    double pr[4] = {0.31, 0.23, 0.23, 0.23};
    fset_ifs fo = {4, over, pr};
    draw_view v2;
    draw_view_fit(&v2, W2, W2, (double[]){0, 0}, (double[]){1, 1}, 1, &e);
    tops_opts o2 = {400000, 2, 0};
    tops_buf ref;
    CHECK(tops_run(&fo, &v2, &o2, &ref, NULL, &e) == RT_OK, "tops: %s", e.msg);
    double cut[1] = {0.4}, cut_rows[1] = {0.6}; /* rows count from the top */
    bad = tested = 0;
    for (int iy = 0; iy < W2; iy++)
        for (int ix = 0; ix < W2; ix++) {
            if (near_line(ix, W2, cut, 1) || near_line(iy, W2, cut_rows, 1))
                continue;
            double x = (ix + 0.5) / W2, y = 1 - (iy + 0.5) / W2;
            const tops_cell *c = &ref.cell[iy * W2 + ix];
            tested++;
            bad += !c->hit || tops_symbol(&ref, c->key, 0) != top_corner(x, y, 0.4);
        }
    CHECK(bad == 0 && tested == 38 * 38, "overlaps: the greater map wins (%d of %d wrong)", bad,
          tested);
    /* Colour by the first symbol through a grey ramp: s/3, as chaos colours map s. */
    image im;
    image_init(&im, W2, W2, &e);
    ramp g = ramp_grey();
    float bg[4] = {1, 0, 0, 1};
    CHECK(tops_colour(&ref, 1, &g, bg, &im, &e) == RT_OK, "colour");
    CHECK_NEAR(image_at(&im, 35, 5)[0], 1, 1e-6, "upper-right pixel grey for map 4");
    CHECK_NEAR(image_at(&im, 5, 35)[0], 0, 1e-6, "lower-left pixel grey for map 1");
    image_free(&im);
    /* Identical for 1, 2, 4 threads. */
    for (int th = 2; th <= 4; th += 2) {
        rt_run run = {th, NULL, 0};
        tops_buf tt;
        CHECK(tops_run(&fo, &v2, &o2, &tt, &run, &e) == RT_OK, "tops threads");
        CHECK(memcmp(tt.cell, ref.cell, sizeof *tt.cell * W2 * W2) == 0,
              "top identical with %d threads", th);
        tops_free(&tt);
    }
    tops_free(&ref);

    /* ---- colour stealing with f = g and a gradient source: every painted
     * pixel shows the source colour at its own point, within half a screen
     * pixel plus half a source pixel. The source is 40×30 (not the screen
     * size) so the lookup is not an identity. */
    enum { SW = 40, SH = 30 };
    image src;
    image_init(&src, SW, SH, &e);
    for (int iy = 0; iy < SH; iy++)
        for (int ix = 0; ix < SW; ix++) {
            float *p = image_at(&src, ix, iy);
            p[0] = (float)((ix + 0.5) / SW);
            p[1] = (float)(1 - (iy + 0.5) / SH);
            p[2] = 0.25f;
            p[3] = 1;
        }
    draw_view sv;
    draw_view_fit(&sv, SW, SH, (double[]){0, 0}, (double[]){1, 1}, 0, &e);
    tops_buf st;
    CHECK(tops_steal(&fo, &v2, &fo, &sv, &o2, &st, NULL, &e) == RT_OK, "steal: %s", e.msg);
    image out;
    image_init(&out, W2, W2, &e);
    CHECK(tops_steal_apply(&st, &src, bg, &out, &e) == RT_OK, "apply");
    int painted = 0;
    bad = 0;
    for (int iy = 0; iy < W2; iy++)
        for (int ix = 0; ix < W2; ix++) {
            const float *p = image_at(&out, ix, iy);
            if (p[2] != 0.25f)
                continue;
            painted++;
            double x = (ix + 0.5) / W2, y = 1 - (iy + 0.5) / W2;
            bad += fabs(p[0] - x) > 0.5 / W2 + 0.5 / SW + 1e-6 ||
                   fabs(p[1] - y) > 0.5 / W2 + 0.5 / SH + 1e-6;
        }
    CHECK(painted == W2 * W2, "every pixel of the square painted (%d)", painted);
    CHECK(bad == 0, "stolen colour = source colour at the same point (%d wrong)", bad);
    /* The same map with a different source IFS steals elsewhere: g = the
     * mirror of f in x (g_m(x, y) = (1 − f_m(x, y).x, f_m(x, y).y)), so the
     * colour's red channel is 1 − x. */
    affine mir[4];
    for (int i = 0; i < 4; i++) {
        mir[i] = over[i];
        mir[i].m[0][0] = over[i].m[0][0];
        mir[i].t[0] = 1 - over[i].t[0] - over[i].m[0][0];
    }
    /* f_m(x) = s x + t; mirrored: 1 − (s (1 − x) + t) = s x + (1 − s − t). */
    fset_ifs gm = {4, mir, pr};
    tops_buf st2;
    CHECK(tops_steal(&fo, &v2, &gm, &sv, &o2, &st2, NULL, &e) == RT_OK, "steal mirror");
    tops_steal_apply(&st2, &src, bg, &out, &e);
    bad = 0;
    for (int iy = 0; iy < W2; iy++)
        for (int ix = 0; ix < W2; ix++) {
            double x = (ix + 0.5) / W2;
            bad += fabs(image_at(&out, ix, iy)[0] - (1 - x)) > 0.5 / W2 + 0.5 / SW + 1e-6;
        }
    CHECK(bad == 0, "mirrored source IFS steals the mirrored colour (%d wrong)", bad);
    tops_free(&st2);

    /* Mismatched map counts. */
    tops_buf tb;
    fset_ifs g3 = {3, over, NULL};
    CHECK(tops_steal(&fo, &v2, &g3, &sv, &o2, &tb, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "colour stealing needs IFSs with the same number of maps (screen has "
                            "4, source has 3)") == 0,
          "mismatch: %s", e.msg);

    /* ---- fractal filter: frame 2 is frame 1 with red inverted, so output 2
     * is output 1 with red inverted (one top for all frames). */
    image frames[2], outs[2];
    image_copy(&frames[0], &src, &e);
    image_copy(&frames[1], &src, &e);
    for (int i = 0; i < SW * SH; i++)
        frames[1].px[4 * i] = 1 - frames[1].px[4 * i];
    CHECK(tops_filter(&fo, &v2, &fo, (double[]){0, 0}, (double[]){1, 1}, frames, 2, &o2, bg, outs,
                      NULL, &e) == RT_OK,
          "filter: %s", e.msg);
    int inv = 1;
    for (int i = 0; i < W2 * W2; i++)
        inv &= outs[0].px[4 * i + 2] != 0.25f || (outs[1].px[4 * i] == 1 - outs[0].px[4 * i] &&
                                                  outs[1].px[4 * i + 1] == outs[0].px[4 * i + 1]);
    CHECK(inv, "filter output follows its frame");
    tops_steal_apply(&st, &src, bg, &out, &e);
    CHECK(memcmp(outs[0].px, out.px, sizeof(float) * 4 * W2 * W2) == 0,
          "filter frame 1 equals stealing from it");
    image_free(&outs[0]);
    image_free(&outs[1]);
    image_free(&frames[1]);
    image_init(&frames[1], 8, 8, &e);
    CHECK(tops_filter(&fo, &v2, &fo, (double[]){0, 0}, (double[]){1, 1}, frames, 2, &o2, bg, outs,
                      NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "fractal filter frame 2 is 8×8 but frame 1 is 40×30") == 0,
          "frame sizes: %s", e.msg);
    image_free(&frames[0]);
    image_free(&frames[1]);
    image_free(&out);
    image_free(&src);
    tops_free(&st);

    /* One map: every orbit point is the map's fixed point (the orbit starts
     * there, eq. (6) with the address 000…), so exactly one pixel is hit. A
     * map with a shear (b c != 0) whose fixed point (0.8387, 0.0645) solves
     * x = 0.5x + 0.3y + 0.4, y = -0.2x + 0.5y + 0.2. */
    affine one[1] = {affine_from_2d(0.5, 0.3, -0.2, 0.5, 0.4, 0.2)};
    fset_ifs f1 = {1, one, NULL};
    tops_opts o1 = {20000, 1, 0};
    tops_buf t1;
    CHECK(tops_run(&f1, &v, &o1, &t1, NULL, &e) == RT_OK, "one-map tops: %s", e.msg);
    int hits = 0, at = -1;
    for (int i = 0; i < W * W; i++)
        if (t1.cell[i].hit)
            hits++, at = i;
    /* the pixel of (0.8387, 0.0645) in the 32×32 view of the unit square: column floor(32x) = 26, row floor(32(1 - y)) = 29 */
    CHECK(hits == 1 && at == 29 * W + 26, "one map: %d pixels hit (expected 1, pixel (26, 29)), last %d", hits, at);
    tops_free(&t1);
    return check_done("test_tops");
}
