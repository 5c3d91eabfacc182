/* test_chaos.c — the chaos game against independent facts: box-counting
 * dimensions of known attractors, RIFS cell measures against a stationary
 * distribution solved here, forbidden addresses, thread-count invariance,
 * tone-mapping formulas by hand. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "chaos.h"
#include "check.h"
#include "fern.h"
#include "rng.h"
#include "tonemap.h"

/* Number of occupied boxes of side `side` bins (boxes tile from the top-left;
 * the last row/column may be partial). */
static long box_count(const hist2 *hs, int side)
{
    long occ = 0;
    for (int by = 0; by * side < hs->h; by++)
        for (int bx = 0; bx * side < hs->w; bx++) {
            uint64_t t = 0;
            for (int y = by * side; y < (by + 1) * side && y < hs->h && !t; y++)
                for (int x = bx * side; x < (bx + 1) * side && x < hs->w; x++)
                    t += hs->count[(size_t)y * hs->w + x];
            occ += t > 0;
        }
    return occ;
}

/* Least-squares slope of log N(side) against -log(side). */
static double box_dimension(const hist2 *hs, const int *sides, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < n; i++) {
        double X = -log((double)sides[i]), Y = log((double)box_count(hs, sides[i]));
        sx += X, sy += Y, sxx += X * X, sxy += X * Y;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

static void test_sierpinski(void)
{
    rt_error e;
    ifs f;
    /* right-angled Sierpinski triangle: level-k cells are dyadic squares, so
     * exactly 3^k boxes of side 2^-k are occupied, dimension log 3 / log 2 */
    affine m[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                   affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5)};
    CHECK(ifs_build(&f, m, 3, NULL, 0, &e) == RT_OK, "build");
    hist2 hs;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    CHECK(hist2_init(&hs, 512, 512, lo, hi, 0, &e) == RT_OK, "hist");
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 2000000;
    o.seed = 7;
    chaos_stats st;
    CHECK(chaos_hist2(&s, &o, &hs, &st, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(st.plotted == 2000000 && st.inside == 2000000, "plotted %llu inside %llu",
          (unsigned long long)st.plotted, (unsigned long long)st.inside);
    /* Range k = 2..8: at k = 8 there are 6561 boxes and ~300 points per box
     * (a box is missed with probability ~e^-300); k = 9 (~100 per box) is
     * also safe, but beyond the box is a single bin. Below 2 the count is
     * just the few quadrants. */
    static const int dyadic[7] = {2, 4, 8, 16, 32, 64, 128}; /* k = 8 .. 2 */
    double D = box_dimension(&hs, dyadic, 7);
    CHECK_NEAR(D, log(3.0) / log(2.0), 0.05, "Sierpinski box dimension");
    long p3 = 9;
    for (int k = 2; k <= 8; k++, p3 *= 3) {
        long c = box_count(&hs, 512 >> k);
        CHECK(c == p3, "level %d: %ld boxes, expected 3^%d = %ld", k, c, k, p3);
    }
    /* fitted window: the triangle [0,1]² with a 5 % margin each side */
    double flo[2], fhi[2];
    CHECK(chaos_fit(&s, &o, 100, 100, flo, fhi, &e) == RT_OK, "fit");
        /* (0.1 % quantiles trimmed: the interval is within [0, 1] and nearly all of it) */
    CHECK(flo[0] > -0.06 && flo[0] < -0.03 && fhi[0] > 1.03 && fhi[0] < 1.06, "fit x [%g, %g]", flo[0], fhi[0]);
    CHECK(flo[1] > -0.06 && fhi[1] < 1.06, "fit y [%g, %g]", flo[1], fhi[1]);
    /* aspect 2:1 widens x about its centre */
    CHECK(chaos_fit(&s, &o, 200, 100, flo, fhi, &e) == RT_OK, "fit 2:1");
    CHECK_NEAR((fhi[0] - flo[0]) / (fhi[1] - flo[1]), 2.0, 1e-9, "fit aspect");
    CHECK_NEAR(flo[0] + fhi[0], 1.0, 0.02, "fit centre");
    hist2_free(&hs);
    ifs_free(&f);
}

static void test_koch(void)
{
    rt_error e;
    ifs f;
    /* seed 003 Table 1: two similarities of ratio 1/√3 (the matrices are
     * symmetric with eigenvalues ±1/√3), so D = log 2 / log √3 ≈ 1.2619 */
    double r = sqrt(3.0) / 6;
    affine m[2] = {affine_from_2d(0.5, r, r, -0.5, 0, 0), affine_from_2d(0.5, -r, -r, -0.5, 0.5, r)};
    CHECK(ifs_build(&f, m, 2, NULL, 0, &e) == RT_OK, "build");
    CHECK_NEAR(f.max_contraction, 1 / sqrt(3.0), 1e-12, "Koch map ratio");
    hist2 hs;
    double lo[2] = {0, -0.35}, hi[2] = {1, 0.65}; /* the curve spans [0,1] × [0, √3/6] */
    CHECK(hist2_init(&hs, 1024, 1024, lo, hi, 0, &e) == RT_OK, "hist");
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 3000000;
    o.seed = 11;
    chaos_stats st;
    CHECK(chaos_hist2(&s, &o, &hs, &st, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(st.inside == st.plotted, "Koch curve inside the window");
    /* Box sides from one bin (1/1024 of the curve's length: ~400 points per
     * occupied bin, so none is missed) to 64 bins (1/16: coarser, the curve
     * covers < 50 boxes and its two ends dominate). Sides 2^k and 3·2^k are
     * interleaved because the Koch count oscillates log-periodically with
     * period log √3, which dyadic boxes alone would alias. */
    static const int sides[12] = {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64};
    double D = box_dimension(&hs, sides, 12);
    CHECK_NEAR(D, log(2.0) / log(sqrt(3.0)), 0.05, "Koch box dimension");
    hist2_free(&hs);
    ifs_free(&f);
}

/* seed 001 Table 1 */
static const double T1[64] = {
    0.13, 0.14, 0.15, 0.09, 0.07, 0.15, 0.15, 0.07, 0.12, 0.07, 0.08, 0.15, 0.17, 0.08, 0.08, 0.21,
    0.16, 0.14, 0.08, 0.07, 0.16, 0.14, 0.09, 0.11, 0.13, 0.12, 0.14, 0.15, 0.07, 0.17, 0.15, 0.02,
    0.12, 0.08, 0.13, 0.16, 0.10, 0.10, 0.14, 0.13, 0.13, 0.15, 0.13, 0.11, 0.07, 0.08, 0.10, 0.18,
    0.09, 0.13, 0.14, 0.16, 0.13, 0.09, 0.14, 0.07, 0.15, 0.15, 0.14, 0.17, 0.07, 0.16, 0.11, 0.01};
static const double OCT[8][3] = {{0, 0, 0},   {128, 0, 0},   {128, 0, 128}, {0, 0, 128},
                                 {0, 128, 0}, {128, 128, 0}, {0, 128, 128}, {128, 128, 128}};

static void octant_maps(affine *m)
{
    double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
    for (int i = 0; i < 8; i++)
        m[i] = affine_from_3d(m9, OCT[i]);
}

/* π P = π, Σ π = 1 by Gaussian elimination with partial pivoting on the
 * transposed system (P^T - I) π = 0 with the last equation replaced. */
static void solve_stationary(const double *P, int n, double *pi)
{
    double A[8][9];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++)
            A[i][j] = P[j * n + i] - (i == j);
        A[i][n] = 0;
    }
    for (int j = 0; j < n; j++)
        A[n - 1][j] = 1;
    A[n - 1][n] = 1;
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r][c]) > fabs(A[p][c]))
                p = r;
        for (int k = 0; k <= n; k++) {
            double t = A[c][k];
            A[c][k] = A[p][k];
            A[p][k] = t;
        }
        for (int r = 0; r < n; r++)
            if (r != c) {
                double f = A[r][c] / A[c][c];
                for (int k = c; k <= n; k++)
                    A[r][k] -= f * A[c][k];
            }
    }
    for (int i = 0; i < n; i++)
        pi[i] = A[i][n] / A[i][i];
}

static void test_rifs_measure(void)
{
    rt_error e;
    rifs r;
    affine m[8];
    octant_maps(m);
    /* Table 1 with some transitions forbidden, rows renormalised here */
    double P[64];
    memcpy(P, T1, sizeof P);
    P[0 * 8 + 1] = 0;
    P[3 * 8 + 7] = 0;
    P[7 * 8 + 7] = 0;
    P[5 * 8 + 2] = 0;
    for (int i = 0; i < 8; i++) {
        double s = 0;
        for (int j = 0; j < 8; j++)
            s += P[i * 8 + j];
        for (int j = 0; j < 8; j++)
            P[i * 8 + j] /= s;
    }
    CHECK(rifs_build(&r, m, 8, 1, P, 0, &e) == RT_OK, "build: %s", e.msg);
    double pi[8];
    solve_stationary(P, 8, pi);
    /* Dobrushin coefficient δ = max_{i,i'} ½ Σ_j |p_ij − p_i'j|: the chain
     * forgets its state at rate δ^t, so |Cov(1_A(X_0), 1_B(X_t))| ≤ π(A) δ^t. */
    double delta = 0;
    for (int i = 0; i < 8; i++)
        for (int i2 = 0; i2 < 8; i2++) {
            double d = 0;
            for (int j = 0; j < 8; j++)
                d += fabs(P[i * 8 + j] - P[i2 * 8 + j]);
            if (d / 2 > delta)
                delta = d / 2;
        }
    CHECK(delta < 0.5, "Dobrushin coefficient %g", delta);

    volume vol;
    double lo[3] = {0, 0, 0}, hi[3] = {256, 256, 256};
    CHECK(volume_init(&vol, 4, 4, 4, lo, hi, &e) == RT_OK, "volume");
    chaos_sys s = {NULL, &r};
    chaos_opts o = {0};
    o.points = 4000000;
    o.seed = 3;
    chaos_stats st;
    CHECK(chaos_volume(&s, &o, CHAOS_NORM_TOTAL, &vol, &st, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(st.inside == st.plotted, "all inside the cube");
    double N = (double)st.plotted, total = 0;
    /* Level-2 cell ω_j∘ω_i(cube) = t_j + t_i/2 + [0, 64)³ is voxel
     * 2·b_j + b_i per axis; its measure is P(previous map i, current j) =
     * π_i p_ij. Pair indicators: lag-1 covariance ≤ p, lag t ≥ 2 ≤ p δ^(t-1),
     * so the variance factor τ ≤ 1 + 2/((1−δ)(1−p)); we allow 5 standard
     * errors sqrt(τ p (1−p) / N) (plus 1e-6 for the burn-in and alias
     * rounding). */
    int worst_ok = 1;
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 8; j++) {
            int v[3];
            for (int a = 0; a < 3; a++)
                v[a] = 2 * (OCT[j][a] > 0) + (OCT[i][a] > 0);
            double mu = *volume_at(&vol, v[0], v[1], v[2]);
            double p = pi[i] * P[i * 8 + j];
            total += mu;
            if (p == 0) {
                CHECK(mu == 0, "forbidden address %d→%d has measure %g", i + 1, j + 1, mu);
                continue;
            }
            double tau = 1 + 2 / ((1 - delta) * (1 - p));
            double tol = 5 * sqrt(tau * p * (1 - p) / N) + 1e-6;
            if (fabs(mu - p) > tol) {
                worst_ok = 0;
                CHECK(0, "cell %d→%d: measure %g vs π_i p_ij %g (tol %g)", i + 1, j + 1, mu, p, tol);
            }
        }
    CHECK(worst_ok, "level-2 measures");
    CHECK_NEAR(total, 1.0, 1e-5, "measure total");
    /* level 1: octant j has measure π_j (state indicators: τ ≤ 1 + 2δ/((1−δ)(1−p))) */
    for (int j = 0; j < 8; j++) {
        double mu = 0;
        for (int z = 0; z < 2; z++)
            for (int y = 0; y < 2; y++)
                for (int x = 0; x < 2; x++)
                    mu += *volume_at(&vol, 2 * (OCT[j][0] > 0) + x, 2 * (OCT[j][1] > 0) + y,
                                     2 * (OCT[j][2] > 0) + z);
        double p = pi[j], tau = 1 + 2 * delta / ((1 - delta) * (1 - p));
        CHECK_NEAR(mu, p, 5 * sqrt(tau * p * (1 - p) / N) + 1e-6, "octant measure = stationary π");
    }
    /* library's stationary distribution agrees with the one solved here */
    double pi2[8];
    CHECK(rifs_stationary(&r, pi2, &e) == RT_OK, "stationary");
    for (int j = 0; j < 8; j++)
        CHECK_NEAR(pi2[j], pi[j], 1e-9, "rifs_stationary");
    /* normalise by max: the densest voxel is 1 */
    CHECK(chaos_volume(&s, &o, CHAOS_NORM_MAX, &vol, &st, NULL, &e) == RT_OK, "max");
    float mx = 0;
    for (int i = 0; i < 64; i++)
        mx = vol.v[i] > mx ? vol.v[i] : mx;
    CHECK(mx == 1.0f, "max norm %g", mx);
    volume_free(&vol);
    rifs_free(&r);
}

static void test_order2(void)
{
    rt_error e;
    rifs r;
    /* binary digits: x/2 and x/2 + 1/2; an order-2 chain that forbids three
     * equal maps in a row: after (1,1) always 2, after (2,2) always 1, else
     * ½/½. Pair stationary law by hand: π(11) = π(22) = 1/6, π(12) = π(21)
     * = 1/3, so each allowed triple has probability 1/6 and 111, 222 have 0.
     * Bin floor(8x) = 4 k_n + 2 k_{n-1} + k_{n-2} (latest map most significant). */
    affine m[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0)};
    double P[8] = {0, 1, 0.5, 0.5, 0.5, 0.5, 1, 0};
    CHECK(rifs_build(&r, m, 2, 2, P, 0, &e) == RT_OK, "build: %s", e.msg);
    hist2 hs;
    double lo[2] = {0, -0.5}, hi[2] = {1, 0.5};
    CHECK(hist2_init(&hs, 8, 1, lo, hi, 0, &e) == RT_OK, "hist");
    chaos_sys s = {NULL, &r};
    chaos_opts o = {0};
    o.points = 1000000;
    o.seed = 5;
    CHECK(chaos_hist2(&s, &o, &hs, NULL, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(hs.count[0] == 0 && hs.count[7] == 0, "forbidden triples: %llu %llu",
          (unsigned long long)hs.count[0], (unsigned long long)hs.count[7]);
    /* se of 1/6 over 1e6 points ≈ 3.7e-4 × sqrt(τ); 0.005 is > 10 se for τ ≤ 2 */
    for (int b = 1; b < 7; b++)
        CHECK_NEAR(hs.count[b] / 1e6, 1.0 / 6, 0.005, "allowed triple");
    double pi[2];
    CHECK(rifs_stationary(&r, pi, &e) == RT_OK, "stationary");
    CHECK_NEAR(pi[0], 0.5, 1e-9, "order-2 last-map law");
    hist2_free(&hs);
    rifs_free(&r);
}

static void test_threads(void)
{
    rt_error e;
    ifs f;
    fern_build(&f);
    chaos_sys s = {&f, NULL};
    ramp rp = ramp_grey();
    rp.rgba[1][0] = 0.2f;
    chaos_opts o = {0};
    o.points = 300000;
    o.seed = 99;
    o.chunk = 1 << 14; /* 19 chunks */
    o.colour = CHAOS_COLOUR_BLEND;
    o.ramp = &rp;
    double lo[2], hi[2];
    CHECK(chaos_fit(&s, &o, 64, 64, lo, hi, &e) == RT_OK, "fit");
    /* fern spans x ≈ [-2.2, 2.7], y ≈ [0, 10] */
    CHECK(lo[1] < 0.1 && hi[1] > 9.5 && lo[0] < -2 && hi[0] > 2.5, "fern window");
    hist2 h[3];
    int th[3] = {1, 2, 4};
    for (int t = 0; t < 3; t++) {
        rt_run run = {th[t], NULL, 0};
        CHECK(hist2_init(&h[t], 64, 64, lo, hi, 1, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s, &o, &h[t], NULL, &run, &e) == RT_OK, "chaos");
    }
    for (int t = 1; t < 3; t++) {
        CHECK(memcmp(h[0].count, h[t].count, 64 * 64 * 8) == 0, "counts differ with %d threads", th[t]);
        CHECK(memcmp(h[0].csum, h[t].csum, 64 * 64 * 12) == 0, "colours differ with %d threads", th[t]);
    }
    /* colour sums are in range: mean colour of a bin in [0, 1] */
    int bad = 0;
    for (int b = 0; b < 64 * 64; b++)
        if (h[0].count[b] && (h[0].csum[3 * b + 1] < 0 || h[0].csum[3 * b + 1] > h[0].count[b] * 1.0001f))
            bad++;
    CHECK(bad == 0, "%d bins with colour out of range", bad);
    for (int t = 0; t < 3; t++)
        hist2_free(&h[t]);
    ifs_free(&f);

    /* 3-D: volume and projection */
    rifs r;
    affine m[8];
    octant_maps(m);
    CHECK(rifs_build(&r, m, 8, 1, T1, RIFS_NORMALISE, &e) == RT_OK, "rifs");
    chaos_sys s3 = {NULL, &r};
    volume v[3];
    image im[3];
    double vlo[3] = {0, 0, 0}, vhi[3] = {256, 256, 256};
    camera cam;
    double tgt[3] = {128, 128, 128};
    camera_orbit(&cam, tgt, 600, 30, 20, 40);
    CHECK(camera_setup(&cam) == 0, "camera");
    for (int t = 0; t < 3; t++) {
        rt_run run = {th[t], NULL, 0};
        CHECK(volume_init(&v[t], 16, 16, 16, vlo, vhi, &e) == RT_OK, "vol");
        CHECK(chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &v[t], NULL, &run, &e) == RT_OK, "vol chaos");
        CHECK(image_init(&im[t], 48, 32, &e) == RT_OK, "image");
        CHECK(chaos_project(&s3, &o, &cam, &im[t], NULL, &run, &e) == RT_OK, "project");
    }
    for (int t = 1; t < 3; t++) {
        CHECK(memcmp(v[0].v, v[t].v, 16 * 16 * 16 * 4) == 0, "volume differs with %d threads", th[t]);
        CHECK(memcmp(im[0].px, im[t].px, 48 * 32 * 16) == 0, "projection differs with %d threads", th[t]);
    }
    /* the projection of the cube-filling attractor covers the image centre */
    CHECK(image_at(&im[0], 24, 16)[3] == 1, "centre pixel hit");
    CHECK(image_at(&im[0], 0, 0)[3] == 0, "corner is background");
    for (int t = 0; t < 3; t++) {
        volume_free(&v[t]);
        image_free(&im[t]);
    }
    /* point cloud: every point inside the cube [0, 256]³ */
    mesh pc;
    mesh_init(&pc, 0, 1);
    o.points = 5000;
    CHECK(chaos_points(&s3, &o, &pc, NULL, &e) == RT_OK, "points");
    CHECK(pc.nv == 5000 && pc.nt == 0, "point cloud size %zu", pc.nv);
    int out = 0;
    for (size_t i = 0; i < 3 * pc.nv; i++)
        out += pc.pos[i] < 0 || pc.pos[i] > 256;
    CHECK(out == 0, "%d coordinates outside the cube", out);
    mesh_free(&pc);
    /* wrong dimension is an error */
    hist2 hh;
    CHECK(hist2_init(&hh, 4, 4, lo, hi, 0, &e) == RT_OK, "hist");
    o.colour = CHAOS_COLOUR_NONE;
    CHECK(chaos_hist2(&s3, &o, &hh, NULL, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "this needs 2-D maps, but the RIFS has 3-D maps") == 0,
          "dimension message: %s", e.msg);
    hist2_free(&hh);
    rifs_free(&r);

    /* one map x/2 + (0.25, 0.25): every point near the fixed point (0.5, 0.5),
     * so one bin gets all 300000 hits — beyond the 65536-hit flush of the
     * colour cells; map colour 1 = white: colour sum = count exactly */
    affine one[1] = {affine_from_2d(0.5, 0, 0, 0.5, 0.25, 0.25)};
    ifs f1;
    CHECK(ifs_build(&f1, one, 1, NULL, 0, &e) == RT_OK, "one map");
    chaos_sys s1 = {&f1, NULL};
    double c1[1] = {1}, lo1[2] = {0, 0}, hi1[2] = {1, 1};
    chaos_opts o1 = {0};
    o1.points = 300000;
    o1.colour = CHAOS_COLOUR_LAST;
    o1.map_c = c1;
    CHECK(hist2_init(&hh, 3, 3, lo1, hi1, 1, &e) == RT_OK, "hist");
    CHECK(chaos_hist2(&s1, &o1, &hh, NULL, NULL, &e) == RT_OK, "chaos");
    CHECK(hh.count[4] == 300000 && hh.csum[12] == 300000.0f && hh.csum[14] == 300000.0f,
          "centre bin %llu hits, colour %g", (unsigned long long)hh.count[4], hh.csum[12]);
    hist2_free(&hh);
    /* exactly 2 × 65536 hits: the cell was just flushed (its own count is 0,
     * everything is in the side sums) and must still be merged */
    o1.points = 2 * 65536;
    o1.burn = -1;
    CHECK(hist2_init(&hh, 3, 3, lo1, hi1, 1, &e) == RT_OK, "hist");
    CHECK(chaos_hist2(&s1, &o1, &hh, NULL, NULL, &e) == RT_OK, "chaos");
    CHECK(hh.count[4] == 131072 && hh.csum[12] == 131072.0f && hh.csum[13] == 131072.0f,
          "flushed centre bin %llu hits, colour %g", (unsigned long long)hh.count[4], hh.csum[12]);
    hist2_free(&hh);
    ifs_free(&f1);
}

static void test_tonemap(void)
{
    rt_error e;
    hist2 hs;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    CHECK(hist2_init(&hs, 4, 2, lo, hi, 1, &e) == RT_OK, "hist");
    /* 2× supersampled: pixel 0 = bins (0..1, 0..1), pixel 1 = bins (2..3, 0..1) */
    hs.count[0] = 1;                 /* pixel 0: C = 1 */
    hs.count[2] = 3, hs.count[7] = 4; /* pixel 1: C = 7 */
    hs.csum[0] = 1;                  /* pixel 0 mean colour (1, 0, 0) */
    hs.csum[3 * 2 + 1] = 3, hs.csum[3 * 7 + 1] = 2, hs.csum[3 * 7 + 2] = 4; /* (0, 5/7, 4/7) */
    image im;
    CHECK(image_init(&im, 2, 1, &e) == RT_OK, "image");
    tonemap_opts o = {0};
    o.curve = TONEMAP_LOG;
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "log");
    CHECK_NEAR(im.px[0], log(2.0) / log(8.0), 1e-6, "log density 1/3"); /* grey ramp */
    CHECK_NEAR(im.px[4], 1.0, 1e-6, "log density max");
    o.curve = TONEMAP_LINEAR;
    o.gamma = 2;
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "linear");
    CHECK_NEAR(im.px[0], sqrt(1.0 / 7), 1e-6, "linear gamma 2");
    o.gamma = 1;
    o.brightness = 3.5;
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "bright");
    CHECK_NEAR(im.px[0], 0.5, 1e-6, "brightness 3.5 × 1/7");
    o.brightness = 1;
    o.colour = TONEMAP_MEAN;
    o.bg[2] = 0.5f, o.bg[3] = 1;
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "mean");
    /* pixel 0: v = 1/7, bg (0, 0, .5), mean (1, 0, 0) */
    CHECK_NEAR(im.px[0], 1.0 / 7, 1e-6, "mean r");
    CHECK_NEAR(im.px[2], 0.5 - 0.5 / 7, 1e-6, "mean b toward bg");
    CHECK_NEAR(im.px[5], 5.0 / 7, 1e-6, "mean g at max");
    CHECK_NEAR(im.px[6], 4.0 / 7, 1e-6, "mean b at max");
    /* alpha: over a half-transparent background, a + (1 - a) v */
    o.bg[3] = 0.25f;
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "mean over alpha 1/4");
    CHECK_NEAR(im.px[3], 0.25 + 0.75 / 7, 1e-6, "alpha at v = 1/7");
    CHECK_NEAR(im.px[7], 1.0, 1e-6, "alpha at max");
    image_free(&im);
    CHECK(image_init(&im, 3, 1, &e) == RT_OK, "image");
    CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_EINVAL &&
              strcmp(e.msg, "histogram 4×2 is not a whole multiple k×k of the image 3×1") == 0,
          "size message: %s", e.msg);
    image_free(&im);
    hist2_free(&hs);
    /* counts on both sides of the 4096-entry table of v, k = 1 */
    CHECK(hist2_init(&hs, 4, 1, lo, hi, 0, &e) == RT_OK, "hist");
    hs.count[0] = 4095, hs.count[1] = 4096, hs.count[2] = 70000, hs.count[3] = 3;
    CHECK(image_init(&im, 4, 1, &e) == RT_OK, "image");
    tonemap_opts g = {0};
    g.curve = TONEMAP_LOG;
    g.gamma = 2.2;
    CHECK(tonemap_apply(&hs, &g, &im, &e) == RT_OK, "log gamma");
    for (int i = 0; i < 4; i++) {
        double v = pow(log(1.0 + (double)hs.count[i]) / log(70001.0), 1 / 2.2);
        CHECK_NEAR(im.px[4 * i], v, 1e-6, "log density, gamma 2.2");
    }
    /* the ramp colours of small counts come from a table (k = 1): each
     * channel against the ramp worked out by hand, beside the background
     * and a count past the table. Ramp red (1, 0, 0, 1) at 0 to blue
     * (0, 0, 1, 0.5) at 1; linear curve, M = 5000: v = C / 5000. */
    ramp rp = ramp_grey();
    for (int ch = 0; ch < 4; ch++)
        rp.rgba[0][ch] = ch == 0 || ch == 3 ? 1.0f : 0.0f, rp.rgba[1][ch] = ch == 2 ? 1.0f : ch == 3 ? 0.5f : 0.0f;
    g = (tonemap_opts){0};
    g.curve = TONEMAP_LINEAR;
    g.ramp = &rp;
    g.bg[0] = 0.25f, g.bg[1] = 0.5f, g.bg[2] = 0.75f, g.bg[3] = 1;
    hs.count[0] = 0, hs.count[1] = 1250, hs.count[2] = 5000, hs.count[3] = 4095;
    CHECK(tonemap_apply(&hs, &g, &im, &e) == RT_OK, "ramp");
    const float want[4][4] = {{0.25f, 0.5f, 0.75f, 1}, /* empty: the background */
                              {0.75f, 0, 0.25f, 0.875f}, /* v = 1/4 */
                              {0, 0, 1, 0.5f},           /* v = 1, past the table */
                              {(float)(1 - 0.819), 0, (float)0.819, (float)(1 - 0.5 * 0.819)}}; /* v = 0.819 */
    for (int i = 0; i < 4; i++)
        for (int ch = 0; ch < 4; ch++)
            CHECK_NEAR(im.px[4 * i + ch], want[i][ch], 1e-6, "ramp colour");
    image_free(&im);
    hist2_free(&hs);
}


/* 3-D maps with every matrix entry distinct and non-zero: the centroid of
 * the invariant measure solves c = sum_i p_i (M_i c + t_i), i.e.
 * (I - sum p_i M_i) c = sum p_i t_i, solved here by Cramer's rule. Both 3-D
 * paths (the voxel hot loop and the point cloud) must reproduce it, so a
 * swapped or mis-signed matrix term in either loop is caught. */
static double det3(const double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

static void test_3d_nondiagonal(void)
{
    static const double M[2][9] = {{0.50, 0.20, -0.10, 0.10, 0.40, 0.15, -0.05, 0.12, 0.45},
                                   {0.30, -0.15, 0.22, 0.25, 0.35, -0.11, 0.13, -0.20, 0.40}};
    static const double T[2][3] = {{0.1, -0.2, 0.3}, {0.5, 0.4, -0.1}};
    double p[2] = {0.4, 0.6};
    double A[3][3], b[3], c[3];
    for (int i = 0; i < 3; i++) {
        b[i] = p[0] * T[0][i] + p[1] * T[1][i];
        for (int j = 0; j < 3; j++)
            A[i][j] = (i == j) - (p[0] * M[0][3 * i + j] + p[1] * M[1][3 * i + j]);
    }
    double D = det3(A);
    for (int k = 0; k < 3; k++) {
        double Ak[3][3];
        memcpy(Ak, A, sizeof Ak);
        for (int i = 0; i < 3; i++)
            Ak[i][k] = b[i];
        c[k] = det3(Ak) / D;
    }
    rt_error e;
    affine maps[2] = {affine_from_3d(M[0], T[0]), affine_from_3d(M[1], T[1])};
    ifs f;
    CHECK(ifs_build(&f, maps, 2, p, 0, &e) == RT_OK, "3-D build: %s", e.msg);
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 4000000;
    o.seed = 7;
    double lo[3], hi[3];
    CHECK(chaos_fit(&s, &o, 0, 0, lo, hi, &e) == RT_OK, "3-D fit");
    /* voxels: measure-weighted mean of voxel centres */
    volume vol;
    int nv = 96;
    CHECK(volume_init(&vol, nv, nv, nv, lo, hi, &e) == RT_OK, "volume");
    rt_run run = {2, NULL, 0};
    CHECK(chaos_volume(&s, &o, CHAOS_NORM_TOTAL, &vol, NULL, &run, &e) == RT_OK, "chaos_volume");
    double m[3] = {0, 0, 0}, tot = 0;
    for (int z = 0; z < nv; z++)
        for (int y = 0; y < nv; y++)
            for (int x = 0; x < nv; x++) {
                double w = *volume_at(&vol, x, y, z);
                int q[3] = {x, y, z};
                for (int a = 0; a < 3; a++)
                    m[a] += w * (lo[a] + (q[a] + 0.5) * (hi[a] - lo[a]) / nv);
                tot += w;
            }
    double worst = 0;
    for (int a = 0; a < 3; a++) {
        double err = fabs(m[a] / tot - c[a]) / (hi[a] - lo[a]);
        worst = err > worst ? err : worst;
    }
    /* sampling error ~ extent / sqrt(points) ≈ 5e-4; a swapped term moves it by > 1e-2 */
    CHECK(worst < 3e-3, "3-D voxel centroid off by %.2g of the box (c = %.4f %.4f %.4f)", worst, c[0],
          c[1], c[2]);
    volume_free(&vol);
    /* point cloud: plain mean of the positions */
    mesh pts = {0};
    o.points = 1000000;
    CHECK(chaos_points(&s, &o, &pts, &run, &e) == RT_OK, "chaos_points");
    double pm[3] = {0, 0, 0};
    for (size_t i = 0; i < pts.nv; i++)
        for (int a = 0; a < 3; a++)
            pm[a] += pts.pos[3 * i + a];
    worst = 0;
    for (int a = 0; a < 3; a++) {
        double err = fabs(pm[a] / (double)pts.nv - c[a]) / (hi[a] - lo[a]);
        worst = err > worst ? err : worst;
    }
    CHECK(pts.nv == 1000000 && worst < 3e-3, "3-D point centroid off by %.2g of the box", worst);
    mesh_free(&pts);
    ifs_free(&f);
}

/* chaos_hist2 ADDS to the histogram's counts (counts only: worker 0 counts
 * straight into them, the others merge into them), for 1 and 2 threads. */
static void test_hist_adds(void)
{
    rt_error e;
    ifs f;
    fern_build(&f);
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 200000;
    o.seed = 5;
    o.chunk = 1 << 14;
    double lo[2] = {-2.5, -0.2}, hi[2] = {2.9, 10.2};
    hist2 a, b;
    CHECK(hist2_init(&a, 48, 40, lo, hi, 0, &e) == RT_OK, "hist");
    rt_run r1 = {1, NULL, 0};
    CHECK(chaos_hist2(&s, &o, &a, NULL, &r1, &e) == RT_OK, "chaos");
    uint64_t sum = 0;
    for (size_t i = 0; i < 48 * 40; i++)
        sum += a.count[i];
    CHECK(sum > 190000 && sum <= 200000, "hits in the window: %llu", (unsigned long long)sum);
    for (int t = 1; t <= 2; t++) {
        rt_run run = {t, NULL, 0};
        CHECK(hist2_init(&b, 48, 40, lo, hi, 0, &e) == RT_OK, "hist");
        for (size_t i = 0; i < 48 * 40; i++)
            b.count[i] = 7 + ((uint64_t)1 << 40); /* above 32 bits: no narrowing either */
        CHECK(chaos_hist2(&s, &o, &b, NULL, &run, &e) == RT_OK, "chaos");
        int bad = 0;
        for (size_t i = 0; i < 48 * 40; i++)
            bad += b.count[i] != a.count[i] + 7 + ((uint64_t)1 << 40);
        CHECK(bad == 0, "%d bins not added to with %d thread(s)", bad, t);
        hist2_free(&b);
    }
    hist2_free(&a);
    ifs_free(&f);
}

static int cmp_float(const void *x, const void *y)
{
    float a = *(const float *)x, b = *(const float *)y;
    return (a > b) - (a < b);
}

/* chaos_fit against its definition (chaos.h), recomputed here from the same
 * pre-pass points (chaos_points with the pre-pass seed and one chunk of
 * CHAOS_FIT_POINTS) by sorting: 0.1 % quantiles, 5 % margins, then the
 * aspect. The fern's stem puts ~1 % of the points on x = 0 exactly: ties. */
static void test_fit_quantiles(void)
{
    rt_error e;
    ifs f;
    fern_build(&f);
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.seed = 31;
    double lo[2], hi[2];
    CHECK(chaos_fit(&s, &o, 300, 200, lo, hi, &e) == RT_OK, "fit");
    chaos_opts po = o;
    po.points = CHAOS_FIT_POINTS;
    po.chunk = CHAOS_FIT_POINTS;
    po.seed = rng_hash3(o.seed, 1ull << 63, 0, 0);
    mesh m;
    mesh_init(&m, 0, 0);
    CHECK(chaos_points(&s, &po, &m, NULL, &e) == RT_OK, "points");
    size_t np = CHAOS_FIT_POINTS, cut = np / 1000;
    float *ax = malloc(np * sizeof *ax);
    double wlo[2], whi[2];
    long zeros = 0;
    for (int a = 0; a < 2; a++) {
        for (size_t i = 0; i < np; i++) {
            ax[i] = m.pos[3 * i + a];
            zeros += a == 0 && ax[i] == 0;
        }
        qsort(ax, np, sizeof *ax, cmp_float);
        double c = 0.5 * ((double)ax[cut] + ax[np - 1 - cut]), x = ((double)ax[np - 1 - cut] - ax[cut]) * 1.1;
        wlo[a] = c - 0.5 * x, whi[a] = c + 0.5 * x;
    }
    CHECK(zeros > 300, "stem points on x = 0: %ld", zeros);
    double ex = whi[0] - wlo[0], ey = whi[1] - wlo[1], want = 1.5;
    CHECK(ex / ey < want, "the fern is taller than 3:2");
    double c = 0.5 * (wlo[0] + whi[0]);
    wlo[0] = c - 0.5 * ey * want, whi[0] = c + 0.5 * ey * want;
    for (int a = 0; a < 2; a++)
        CHECK(lo[a] == wlo[a] && hi[a] == whi[a], "axis %d: [%.17g, %.17g], by sorting [%.17g, %.17g]",
              a, lo[a], hi[a], wlo[a], whi[a]);
    free(ax);
    mesh_free(&m);
    ifs_free(&f);
}

/* The window chaos.h defines, computed the straightforward way: the
 * pre-pass points stored (chaos_points with the pre-pass seed, one chunk of
 * np points, the same burn), each axis sorted (as floats, what the points
 * hold), the (cut+1)-th smallest and largest taken, then the rules for a
 * non-finite or degenerate extent, the 5 % margins and the aspect. */
static void fit_by_sorting(const chaos_sys *s, const chaos_opts *o, int dim, int w, int h, double *lo, double *hi)
{
    rt_error e;
    size_t np = o->fit_points && o->fit_points < CHAOS_FIT_POINTS ? (size_t)o->fit_points : CHAOS_FIT_POINTS;
    size_t cut = np / 1000;
    chaos_opts po = *o;
    po.points = np;
    po.chunk = (uint32_t)np;
    po.colour = CHAOS_COLOUR_NONE;
    po.seed = rng_hash3(o->seed, 1ull << 63, 0, 0);
    mesh m;
    mesh_init(&m, 0, 0);
    CHECK(chaos_points(s, &po, &m, NULL, &e) == RT_OK, "points: %s", e.msg);
    float *ax = malloc(np * sizeof *ax);
    double ext[3], big = 0;
    for (int a = 0; a < dim; a++) {
        for (size_t i = 0; i < np; i++)
            ax[i] = m.pos[3 * i + a];
        qsort(ax, np, sizeof *ax, cmp_float);
        lo[a] = ax[cut], hi[a] = ax[np - 1 - cut];
        if (!isfinite(lo[a]) || !isfinite(hi[a]))
            lo[a] = -1, hi[a] = 1;
        ext[a] = hi[a] - lo[a];
        big = ext[a] > big ? ext[a] : big;
    }
    for (int a = 0; a < dim; a++) {
        double c = 0.5 * (lo[a] + hi[a]), x = ext[a];
        if (!(x > 1e-12 * (fabs(c) + 1)))
            x = big > 0 ? 0.1 * big : 1;
        x *= 1.1;
        lo[a] = c - 0.5 * x, hi[a] = c + 0.5 * x;
    }
    if (dim == 2 && w > 0 && h > 0) {
        double ex = hi[0] - lo[0], ey = hi[1] - lo[1], want = (double)w / h;
        int ax0 = ex / ey < want ? 0 : 1;
        double c = 0.5 * (lo[ax0] + hi[ax0]), half = ax0 == 0 ? 0.5 * ey * want : 0.5 * ex / want;
        lo[ax0] = c - half, hi[ax0] = c + half;
    }
    free(ax);
    mesh_free(&m);
}

/* chaos_fit keeps only the tails of the pre-pass (two heaps an axis, a value
 * tested against the heap's top first, non-finite values detected once at
 * the end): it must give the sorted window bit for bit, on a 2-D IFS, both
 * RIFS orders, a 3-D IFS, rare far excursions (dozens of points enter the
 * tails late), degenerate attractors (a point; a line), float overflow that
 * the double orbit recovers from (the stored points are sorted instead),
 * and fewer pre-pass points (cut 0 and 5). */
static void check_fit(const char *what, const chaos_sys *s, uint64_t fit_points, int dim, int w, int h,
                      double *lo_out, double *hi_out)
{
    rt_error e;
    chaos_opts o = {0};
    o.seed = 77;
    o.fit_points = fit_points;
    double lo[3], hi[3], rlo[3], rhi[3];
    CHECK(chaos_fit(s, &o, w, h, lo, hi, &e) == RT_OK, "%s: fit: %s", what, e.msg);
    fit_by_sorting(s, &o, dim, w, h, rlo, rhi);
    for (int a = 0; a < dim; a++) {
        CHECK(memcmp(&lo[a], &rlo[a], sizeof lo[a]) == 0 && memcmp(&hi[a], &rhi[a], sizeof hi[a]) == 0,
              "%s: axis %d: [%.17g, %.17g], by sorting [%.17g, %.17g]", what, a, lo[a], hi[a], rlo[a], rhi[a]);
        if (lo_out)
            lo_out[a] = lo[a], hi_out[a] = hi[a];
    }
}

static void test_fit_tails(void)
{
    rt_error e;
    ifs f;
    fern_build(&f);
    chaos_sys s = {&f, NULL};
    check_fit("fern", &s, 0, 2, 300, 200, NULL, NULL);
    check_fit("fern, 2 points", &s, 2, 2, 64, 64, NULL, NULL); /* the tails: 1 point each */
    check_fit("fern, 3 points", &s, 3, 2, 64, 64, NULL, NULL);
    check_fit("fern, 500 points", &s, 500, 2, 64, 64, NULL, NULL);
    check_fit("fern, 1000 points", &s, 1000, 2, 64, 64, NULL, NULL); /* cut 1 */
    check_fit("fern, 5000 points", &s, 5000, 2, 100, 300, NULL, NULL);
    ifs_free(&f);

    /* far excursions: one step in ~5000 jumps by (400, -300), and halving
     * brings it back over ~10 steps: ~130 far points, the tails' 66 among them */
    affine far[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0.5),
                     affine_from_2d(0.5, 0, 0, 0.5, 400, -300)};
    double pfar[3] = {0.4999, 0.4999, 0.0002};
    CHECK(ifs_build(&f, far, 3, pfar, 0, &e) == RT_OK, "far: %s", e.msg);
    s.ifs = &f;
    double lo[3], hi[3];
    check_fit("far excursions", &s, 0, 2, 100, 100, lo, hi);
    CHECK(hi[0] > 5 && lo[1] < -5, "the excursions are in the tails: x up to %g, y down to %g", hi[0], lo[1]);
    ifs_free(&f);

    /* a point: every coordinate 2 exactly, so the extent is 0 -> 1 unit */
    affine pt[1] = {affine_from_2d(0.5, 0, 0, 0.5, 1, 1)};
    CHECK(ifs_build(&f, pt, 1, NULL, 0, &e) == RT_OK, "point: %s", e.msg);
    s.ifs = &f;
    check_fit("a point", &s, 0, 2, 0, 0, lo, hi);
    CHECK(lo[0] == 2 - 0.55 && hi[0] == 2 + 0.55 && lo[1] == 2 - 0.55, "point window [%g, %g]", lo[0], hi[0]);
    ifs_free(&f);

    /* a line: y = 0.25 always, so y gets 10 % of x's extent */
    affine line[2] = {affine_from_2d(0.5, 0, 0, 0, 0, 0.25), affine_from_2d(0.5, 0, 0, 0, 0.5, 0.25)};
    CHECK(ifs_build(&f, line, 2, NULL, 0, &e) == RT_OK, "line: %s", e.msg);
    s.ifs = &f;
    check_fit("a line", &s, 0, 2, 0, 0, lo, hi);
    CHECK(fabs((hi[1] - lo[1]) - 0.1 * (hi[0] - lo[0])) < 1e-12, "line: y extent %g, x extent %g",
          hi[1] - lo[1], hi[0] - lo[0]);
    ifs_free(&f);

    /* float overflow: one step in 10^4 puts x at 10^39 (a float infinity,
     * a finite double), and halving brings it back below FLT_MAX */
    affine big[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5), affine_from_2d(0, 0, 0, 0.5, 1e39, 0)};
    double pbig[2] = {0.9999, 0.0001};
    CHECK(ifs_build(&f, big, 2, pbig, 0, &e) == RT_OK, "overflow: %s", e.msg);
    s.ifs = &f;
    check_fit("float overflow", &s, 0, 2, 0, 0, NULL, NULL);
    ifs_free(&f);

    /* NaN: x = 10^308, then ×10 overflows the double, and the next 0·x
     * (map 1) makes x NaN for good: the heaps cannot order NaN, so the
     * stored points are sorted instead (and the x window is the default) */
    affine nan[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5), affine_from_2d(0, 0, 0, 0.5, 1e308, 0),
                     affine_from_2d(10, 0, 0, 0.5, 0, 0)};
    double pnan[3] = {0.98, 0.01, 0.01};
    CHECK(ifs_build(&f, nan, 3, pnan, IFS_ALLOW_EXPANDING, &e) == RT_OK, "NaN: %s", e.msg);
    s.ifs = &f;
    check_fit("NaN", &s, 0, 2, 0, 0, lo, hi);
    CHECK(lo[0] == -1.1 && hi[0] == 1.1, "NaN: x window [%g, %g]", lo[0], hi[0]);
    ifs_free(&f);

    /* RIFS of order 1 and 2 (the chain of test_order2) */
    rifs r;
    affine bin[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.6, 0.5, 0.4)};
    double P1[4] = {0.3, 0.7, 0.6, 0.4};
    CHECK(rifs_build(&r, bin, 2, 1, P1, 0, &e) == RT_OK, "order 1: %s", e.msg);
    chaos_sys sr = {NULL, &r};
    check_fit("RIFS order 1", &sr, 0, 2, 120, 80, NULL, NULL);
    rifs_free(&r);
    double P2[8] = {0, 1, 0.5, 0.5, 0.5, 0.5, 1, 0};
    CHECK(rifs_build(&r, bin, 2, 2, P2, 0, &e) == RT_OK, "order 2: %s", e.msg);
    check_fit("RIFS order 2", &sr, 0, 2, 80, 120, NULL, NULL);
    rifs_free(&r);

    /* 3-D: three rotating maps (the box is returned without an aspect) */
    double M[3][9] = {{0.5, -0.2, 0, 0.2, 0.5, 0, 0, 0, 0.5},
                      {0.5, 0, 0.1, 0, 0.5, 0, -0.1, 0, 0.5},
                      {0.4, 0, 0, 0, 0.4, 0.2, 0, -0.2, 0.4}};
    double T[3][3] = {{0, 0, 0}, {1, 0, 0.5}, {0, 1, 1}};
    affine m3[3] = {affine_from_3d(M[0], T[0]), affine_from_3d(M[1], T[1]), affine_from_3d(M[2], T[2])};
    CHECK(ifs_build(&f, m3, 3, NULL, 0, &e) == RT_OK, "3-D: %s", e.msg);
    s.ifs = &f;
    check_fit("3-D", &s, 0, 3, 0, 0, NULL, NULL);
    check_fit("3-D, 900 points", &s, 900, 3, 0, 0, NULL, NULL);
    ifs_free(&f);
}

/* The stage chain holds no copies (the allocation hook sees every block):
 * counts without colour on one thread go straight into the histogram and a
 * 3-D measure into the volume's own memory; tone mapping allocates nothing.
 * With two threads one private array (the second worker's) is the largest
 * block. */
static void test_no_copies(void)
{
    rt_error e;
    rifs r;
    affine m[8];
    octant_maps(m);
    CHECK(rifs_build(&r, m, 8, 1, T1, RIFS_NORMALISE, &e) == RT_OK, "build: %s", e.msg);
    chaos_sys s3 = {NULL, &r};
    chaos_opts o = {0};
    o.points = 1 << 18;
    o.chunk = 1 << 14;
    o.seed = 3;
    double lo[3] = {0, 0, 0}, hi[3] = {256, 256, 256}; /* the maps' attractor */
    volume vol;
    CHECK(volume_init(&vol, 64, 64, 64, lo, hi, &e) == RT_OK, "volume");
    size_t voxels = 64 * 64 * 64;
    rt_run r1 = {1, NULL, 0}, r2 = {2, NULL, 0};
    check_limits(-1, -1, -1);
    CHECK(chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r1, &e) == RT_OK, "volume 1");
    CHECK(check_hs.peak < voxels, "1 thread: a block of %zu bytes beside the %zu voxels", check_hs.peak, voxels);
    float *one = malloc(voxels * sizeof *one);
    memcpy(one, vol.v, voxels * sizeof *one);
    check_hs.peak = 0;
    CHECK(chaos_volume(&s3, &o, CHAOS_NORM_TOTAL, &vol, NULL, &r2, &e) == RT_OK, "volume 2");
    CHECK(check_hs.peak >= 4 * voxels && check_hs.peak < 4 * voxels + 64, "2 threads: largest block %zu", check_hs.peak);
    CHECK(memcmp(one, vol.v, voxels * sizeof *one) == 0, "volume differs with 2 threads");
    double sum = 0;
    for (size_t i = 0; i < voxels; i++)
        sum += vol.v[i];
    CHECK_NEAR(sum, 1.0, 1e-5, "total measure");
    check_limits_off();
    free(one);
    volume_free(&vol);
    rifs_free(&r);

    ifs f;
    affine tri[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                     affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5)};
    CHECK(ifs_build(&f, tri, 3, NULL, 0, &e) == RT_OK, "triangle");
    chaos_sys s2 = {&f, NULL};
    hist2 hs;
    double lo2[2] = {0, 0}, hi2[2] = {1, 1};
    CHECK(hist2_init(&hs, 256, 256, lo2, hi2, 0, &e) == RT_OK, "hist");
    image im;
    CHECK(image_init(&im, 128, 128, &e) == RT_OK, "image");
    check_limits(-1, -1, -1);
    CHECK(chaos_hist2(&s2, &o, &hs, NULL, &r1, &e) == RT_OK, "hist 1");
    CHECK(check_hs.peak < 256 * 256, "1 thread: a block of %zu bytes beside the histogram", check_hs.peak);
    check_hs.peak = 0;
    tonemap_opts t = {0};
    CHECK(tonemap_apply(&hs, &t, &im, &e) == RT_OK, "tonemap");
    CHECK(check_hs.peak == 0, "tone mapping allocated %zu bytes", check_hs.peak);
    check_limits_off();
    image_free(&im);
    hist2_free(&hs);
    ifs_free(&f);
}

/* The 3-D loop counts outside points in a spare cell and derives inside
 * from it: inside must equal the sum of the voxel counts, and a box over
 * the lower half z < 128 of the cube holds the points whose last map has
 * t_z = 0 (maps 0, 1, 4, 5): the stationary share of those states of Table
 * 1's chain is 0.50157 (π P = π by power iteration in python3), i.e. 50159
 * of 100003 points; ±2 % is ~12 binomial standard deviations. Checked with
 * 1 and 2 threads and a chunk shorter than the prefetch ring. */
static void test_volume_inside(void)
{
    rt_error e;
    rifs r;
    affine m[8];
    octant_maps(m);
    CHECK(rifs_build(&r, m, 8, 1, T1, RIFS_NORMALISE, &e) == RT_OK, "rifs");
    chaos_sys s3 = {NULL, &r};
    double lo[3] = {0, 0, 0}, hi[3] = {256, 256, 128};
    for (int t = 1; t <= 2; t++)
        for (int ch = 0; ch < 2; ch++) {
            chaos_opts o = {0};
            o.points = 100003;
            o.seed = 5;
            o.chunk = ch ? 7 : 1 << 14; /* 7 < the ring of 32 */
            rt_run run = {t, NULL, 0};
            volume v;
            CHECK(volume_init(&v, 8, 8, 4, lo, hi, &e) == RT_OK, "volume");
            chaos_stats st;
            CHECK(chaos_volume(&s3, &o, CHAOS_NORM_COUNT, &v, &st, &run, &e) == RT_OK, "volume: %s", e.msg);
            double sum = 0;
            for (size_t b = 0; b < 8 * 8 * 4; b++)
                sum += v.v[b];
            CHECK(st.plotted == 100003, "plotted %llu", (unsigned long long)st.plotted);
            CHECK(sum == (double)st.inside, "%d thread(s), chunk %u: voxel counts sum to %.0f, inside %llu", t,
                  o.chunk, sum, (unsigned long long)st.inside);
            CHECK(st.inside > 48150 && st.inside < 52160, "inside %llu of 100003", (unsigned long long)st.inside);
            volume_free(&v);
        }
    rifs_free(&r);
}

/* Where and in which colour a coloured hit lands, against facts of the
 * maps alone (mutation table: chaos-colour-cell, chaos-blend-order,
 * chaos-palette-round). */
static void test_colour_hits(void)
{
    rt_error e;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    int th[2] = {1, 3};
    /* one map x/2 + 0.05: every point at the fixed point (0.1, 0.1), which is
     * column 0 and, counted from the top, row 3 of a 4×4 window: bin 12 */
    affine one[1] = {affine_from_2d(0.5, 0, 0, 0.5, 0.05, 0.05)};
    ifs f1;
    CHECK(ifs_build(&f1, one, 1, NULL, 0, &e) == RT_OK, "one map");
    chaos_sys s1 = {&f1, NULL};
    /* colour 0.0015: palette entry round(0.0015 × 1023) = 2 (truncating gives 1) */
    double c1[1] = {0.0015};
    for (int t = 0; t < 2; t++) {
        rt_run run = {th[t], NULL, 0};
        chaos_opts o = {0};
        o.points = 40000;
        o.chunk = 1 << 12;
        o.colour = CHAOS_COLOUR_LAST;
        o.map_c = c1;
        hist2 hh;
        CHECK(hist2_init(&hh, 4, 4, lo, hi, 1, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s1, &o, &hh, NULL, &run, &e) == RT_OK, "chaos");
        CHECK(hh.count[12] == 40000, "%d thread(s): bin (0, 3) has %llu of 40000 hits", th[t],
              (unsigned long long)hh.count[12]);
        double mean = hh.csum[3 * 12] / 40000.0;
        CHECK(fabs(mean - 2.0 / 1023) < 2e-5, "%d thread(s): colour 0.0015 gave %.6f, not palette entry 2 (%.6f)",
              th[t], mean, 2.0 / 1023);
        hist2_free(&hh);
    }
    ifs_free(&f1);
    /* a chunk starts at the fixed point of map 0 (chaos.h), so without a
     * burn-in a one-map orbit never leaves it: a map with a shear (b, c != 0,
     * which a wrong inverse of I - A gets wrong) and t = (I - A) z, z the
     * centre (6.5/64, 1 - 57.5/64) of bin (6, 57) of a 64×64 window, puts
     * all its hits in that bin from the first one */
    double ax = 0.5, bx = 0.3, cx = -0.2, dx = 0.5, z = 6.5 / 64;
    affine sh[1] = {affine_from_2d(ax, bx, cx, dx, (1 - ax) * z - bx * z, -cx * z + (1 - dx) * z)};
    CHECK(ifs_build(&f1, sh, 1, NULL, 0, &e) == RT_OK, "sheared map");
    {
        chaos_opts o = {0};
        o.points = 40000;
        o.chunk = 1 << 12;
        o.burn = -1;
        hist2 hh;
        CHECK(hist2_init(&hh, 64, 64, lo, hi, 0, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s1, &o, &hh, NULL, NULL, &e) == RT_OK, "chaos");
        CHECK(hh.count[57 * 64 + 6] == 40000, "sheared map without burn-in: %llu of 40000 hits at its fixed point",
              (unsigned long long)hh.count[57 * 64 + 6]);
        hist2_free(&hh);
    }
    ifs_free(&f1);
    /* x/2 and x/2 + 1/2 (y/2 both), colours 0 and 1, blended: a hit of the
     * right map lands in x >= 1/2 with colour (c + 1)/2 >= 1/2, a hit of the
     * left one in x < 1/2 with colour c/2 <= 1/2; c is 1/2 on average, so
     * the mean colours of the two halves are 3/4 and 1/4 */
    affine two[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0)};
    ifs f2;
    CHECK(ifs_build(&f2, two, 2, NULL, 0, &e) == RT_OK, "two maps");
    chaos_sys s2 = {&f2, NULL};
    double c2[2] = {0, 1}, lo2[2] = {0, -1}, hi2[2] = {1, 1};
    for (int t = 0; t < 2; t++) {
        rt_run run = {th[t], NULL, 0};
        chaos_opts o = {0};
        o.points = 200000;
        o.seed = 3;
        o.chunk = 1 << 12;
        o.colour = CHAOS_COLOUR_BLEND;
        o.map_c = c2;
        hist2 hh;
        CHECK(hist2_init(&hh, 2, 1, lo2, hi2, 1, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s2, &o, &hh, NULL, &run, &e) == RT_OK, "chaos");
        CHECK(hh.count[0] + hh.count[1] == 200000 && hh.count[0] > 90000 && hh.count[1] > 90000,
              "%d thread(s): halves %llu, %llu", th[t], (unsigned long long)hh.count[0],
              (unsigned long long)hh.count[1]);
        double ml = hh.csum[0] / (double)hh.count[0], mr = hh.csum[3] / (double)hh.count[1];
        CHECK(fabs(ml - 0.25) < 0.01 && fabs(mr - 0.75) < 0.01,
              "%d thread(s): mean colours %.4f (left, expected 1/4) and %.4f (right, 3/4)", th[t], ml, mr);
        hist2_free(&hh);
    }
    ifs_free(&f2);
}

/* The 2-D colour loop counts outside points in its outside cell (flushed
 * like every cell after 65536 hits) and derives inside from it. Right-angled
 * Sierpinski, window y in [0, 0.5]: a point is inside when its last map is 0
 * or 1 (map 2 adds 0.5 to y; y = 0.5 itself is never reached), 2/3 of the
 * points, and ~100,000 of 300,007 outside, so each worker's outside cell
 * flushes; ±1 % is ~12 binomial standard deviations. The counts-only loop on
 * the same orbit must see the same inside, and the counts sum to it. */
static void test_colour_inside(void)
{
    rt_error e;
    ifs f;
    affine m[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                   affine_from_2d(0.5, 0, 0, 0.5, 0, 0.5)};
    CHECK(ifs_build(&f, m, 3, NULL, 0, &e) == RT_OK, "build");
    chaos_sys s = {&f, NULL};
    double lo[2] = {0, 0}, hi[2] = {1, 0.5};
    for (int t = 1; t <= 2; t++)
        for (int ch = 0; ch < 2; ch++) {
            uint64_t inside[2];
            for (int col = 0; col < 2; col++) {
                hist2 hs;
                CHECK(hist2_init(&hs, 64, 32, lo, hi, col, &e) == RT_OK, "hist");
                chaos_opts o = {0};
                o.points = 300007;
                o.seed = 3;
                o.chunk = ch ? 7 : 0; /* 7 < the ring of 32 */
                o.colour = col ? CHAOS_COLOUR_BLEND : CHAOS_COLOUR_NONE;
                rt_run run = {t, NULL, 0};
                chaos_stats st;
                CHECK(chaos_hist2(&s, &o, &hs, &st, &run, &e) == RT_OK, "chaos: %s", e.msg);
                uint64_t sum = 0;
                for (size_t b = 0; b < 64 * 32; b++)
                    sum += hs.count[b];
                CHECK(sum == st.inside, "%d thread(s), chunk %u, colour %d: counts sum to %llu, inside %llu", t,
                      o.chunk, col, (unsigned long long)sum, (unsigned long long)st.inside);
                CHECK(st.inside > 198000 && st.inside < 202000, "inside %llu of 300007 (2/3: 200005)",
                      (unsigned long long)st.inside);
                inside[col] = st.inside;
                hist2_free(&hs);
            }
            CHECK(inside[0] == inside[1], "colour and counts-only loops: inside %llu and %llu",
                  (unsigned long long)inside[1], (unsigned long long)inside[0]);
        }
    ifs_free(&f);
}

int main(void)
{
    test_sierpinski();
    test_koch();
    test_rifs_measure();
    test_order2();
    test_threads();
    test_colour_hits();
    test_3d_nondiagonal();
    test_tonemap();
    test_hist_adds();
    test_fit_quantiles();
    test_fit_tails();
    test_no_copies();
    test_volume_inside();
    test_colour_inside();
    return check_done("test_chaos");
}
