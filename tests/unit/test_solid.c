/* test_solid.c — base functions and perturbation of seed 000 §3. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "mpd.h"
#include "solid.h"

static void const_d(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    (void)x, (void)y, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = *(const double *)ctx;
}

static void x_d(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    (void)ctx, (void)y, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = x[i];
}

/* user F: swap x and z, ignore D */
static void swap_warp(const void *ctx, size_t n, const double *x, const double *y, const double *z, const double *d,
                      double *xo, double *yo, double *zo)
{
    (void)ctx, (void)d;
    for (size_t i = 0; i < n; i++) {
        xo[i] = z[i];
        yo[i] = y[i];
        zo[i] = x[i];
    }
}

static solid_marble two_layers(void)
{
    solid_marble m;
    memset(&m, 0, sizeof m);
    m.n = 2;
    m.layer[0] = (solid_layer){0.5, 0.2, 10.0};
    m.layer[1] = (solid_layer){0.8, 0.1, 5.0};
    return m;
}

/* eq. (6) by hand */
static void test_marble(void)
{
    solid_marble m = two_layers();
    /* z = 0.5: d1 = 0 - 0.1 < 0 -> 1; d2 = 0.3 - 0.05 = 0.25 -> e^(-5*0.25) = e^-1.25 = 0.28650479686 */
    CHECK_NEAR(solid_marble_value(&m, 0.5), 1.0 + 0.28650479686019010, 1e-12, "G(z=0.5)");
    /* z = 0.65: d1 = 0.15 - 0.1 = 0.05 -> e^(-10*0.05) = e^-0.5; d2 = 0.15 - 0.05 = 0.1 -> e^(-5*0.1) = e^-0.5 */
    CHECK_NEAR(solid_marble_value(&m, 0.65), 2 * 0.60653065971263342, 1e-12, "G(z=0.65)");
    /* z = 0.0: d1 = 0.5 - 0.1 = 0.4 -> e^-4; d2 = 0.8 - 0.05 = 0.75 -> e^-3.75 */
    CHECK_NEAR(solid_marble_value(&m, 0.0), 0.018315638888734179 + 0.023517745856009107, 1e-12, "G(z=0)");
    /* inside layer 2 (|z - 0.8| <= 0.05): g2 = 1; z = 0.82: d1 = 0.32 - 0.1 = 0.22 -> e^-2.2 */
    CHECK_NEAR(solid_marble_value(&m, 0.82), 1.0 + 0.11080315836233387, 1e-12, "G(z=0.82)");
    /* symmetric about each centre, and 1 on the plateau */
    CHECK_NEAR(solid_layer_value(&m.layer[0], 0.37), solid_layer_value(&m.layer[0], 0.63), 1e-15, "symmetry");
    CHECK(solid_layer_value(&m.layer[0], 0.41) == 1.0, "plateau");
    /* the block function agrees and ignores x, y */
    double x[2] = {5, -3}, y[2] = {1, 2}, z[2] = {0.5, 0.65}, o[2];
    solid_marble_fn(&m, 2, x, y, z, o);
    CHECK(o[0] == solid_marble_value(&m, 0.5) && o[1] == solid_marble_value(&m, 0.65), "block marble");
    rt_error e;
    m.layer[1].alpha = -1;
    CHECK(solid_marble_check(&m, &e) == RT_EINVAL && strcmp(e.msg, "marble layer 2: decay alpha = -1 must be > 0") == 0,
          "%s", e.msg);
    m.layer[1].alpha = 5;
    m.layer[0].w = -0.1;
    CHECK(solid_marble_check(&m, &e) == RT_EINVAL && strstr(e.msg, "marble layer 1: width w = -0.1"), "%s", e.msg);
}

static void test_wood(void)
{
    solid_wood w = {{0, 0, 0}, {0, 0, 2}, 0.1, 1.0};
    double p[3] = {0.3, 0.4, 7.0}; /* r = 0.5 = 5 spacings: early wood, 0 */
    CHECK_NEAR(solid_wood_radius(&w, p), 0.5, 1e-15, "radius");
    CHECK_NEAR(solid_wood_profile(&w, 0.5), 0.0, 1e-12, "ring boundary");
    CHECK_NEAR(solid_wood_profile(&w, 0.55), 1.0, 1e-12, "ring centre (half spacing)");
    CHECK_NEAR(solid_wood_profile(&w, 0.525), 0.5, 1e-12, "quarter: (1 - cos(pi/2))/2");
    w.sharpness = 3;
    CHECK_NEAR(solid_wood_profile(&w, 0.525), 0.125, 1e-12, "sharpness 3: 0.5^3");
    /* axis through (1, 1, 0) along x: r of (5, 1, 2) is 2 */
    solid_wood w2 = {{1, 1, 0}, {3, 0, 0}, 0.3, 1};
    double q[3] = {5, 1, 2};
    CHECK_NEAR(solid_wood_radius(&w2, q), 2.0, 1e-15, "radius about x axis");
    rt_error e;
    w2.spacing = 0;
    CHECK(solid_wood_check(&w2, &e) == RT_EINVAL && strstr(e.msg, "ring spacing = 0 must be > 0"), "%s", e.msg);
}

static void test_perturbation(void)
{
    solid_texture t;
    solid_texture_default(&t);
    t.marble = two_layers();
    double dv = 0.3;
    t.d_fn = const_d;
    t.d_ctx = &dv;
    t.k = 0.5;
    t.warp = SOLID_WARP_Z;
    rt_error e;
    CHECK(solid_texture_check(&t, &e) == RT_OK, "%s", e.msg);
    /* eq. (7): P' = P + (0, 0, k D) = z + 0.15 -> G(0.5 + 0.15) = G(0.65) = 2 e^-0.5 */
    double x = 0.2, y = 0.9, z = 0.5, o;
    solid_eval(&t, 1, &x, &y, &z, &o);
    CHECK_NEAR(o, 2 * 0.60653065971263342, 1e-12, "marble displaced along z");
    /* D seen through the box [-1, 1]^3: D(P) = (x + 1) / 2; at x = 0.4 D = 0.7, z' = 0.5 + 0.35 = 0.85:
     * d1 = 0.35 - 0.1 = 0.25 -> e^-2.5; g2 = 1 (|0.85 - 0.8| = 0.05 <= 0.05) */
    t.d_fn = x_d;
    for (int i = 0; i < 3; i++)
        t.d_lo[i] = -1, t.d_hi[i] = 1;
    x = 0.4;
    solid_eval(&t, 1, &x, &y, &z, &o);
    CHECK_NEAR(o, 0.082084998623898795 + 1.0, 1e-12, "D box mapping");
    /* wood displaced radially: r = 0.5 -> r' = 0.5 + 0.5 * 0.1 = 0.55: the dark ring */
    solid_texture_default(&t);
    t.base = SOLID_BASE_WOOD;
    t.warp = SOLID_WARP_RADIAL;
    dv = 0.1;
    t.d_fn = const_d;
    t.d_ctx = &dv;
    t.k = 0.5;
    double px = 0.3, py = 0.4, pz = 3.0;
    solid_eval(&t, 1, &px, &py, &pz, &o);
    CHECK_NEAR(o, 1.0, 1e-12, "wood ring displaced radially");
    t.k = 0;
    solid_eval(&t, 1, &px, &py, &pz, &o);
    CHECK_NEAR(o, 0.0, 1e-12, "undisplaced wood");
    /* user F swapping x and z: marble reads x as its z */
    solid_texture_default(&t);
    t.marble = two_layers();
    t.warp = SOLID_WARP_USER;
    t.warp_fn = swap_warp;
    x = 0.65, y = 0, z = 0.0;
    solid_eval(&t, 1, &x, &y, &z, &o);
    CHECK_NEAR(o, 2 * 0.60653065971263342, 1e-12, "user perturbation");
    t.warp_fn = NULL;
    CHECK(solid_texture_check(&t, &e) == RT_EINVAL && strstr(e.msg, "user perturbation function missing"), "%s", e.msg);
    solid_texture_default(&t);
    t.d_hi[1] = -2;
    CHECK(solid_texture_check(&t, &e) == RT_EINVAL && strstr(e.msg, "D box hi.y = -2 must be greater than lo.y = 0"),
          "%s", e.msg);
}

/* A real fractal: marble with D from Type III; the veins move with D, the
 * colour is the ramp of the value, and a large block equals point by point. */
static void test_with_mpd(void)
{
    mpd_params p;
    mpd_params_default(&p);
    p.R = 5;
    p.type = MPD_TYPE3;
    p.seed = 11;
    mpd m;
    rt_error e;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK, "%s", e.msg);
    solid_texture t;
    solid_texture_default(&t);
    t.marble = two_layers();
    t.d_fn = mpd_eval;
    t.d_ctx = &m;
    t.k = 0.05;
    t.warp = SOLID_WARP_Z;
    enum { N = 700 };
    double x[N], y[N], z[N], v[N], d[N];
    for (int i = 0; i < N; i++) {
        x[i] = (i % 17) / 16.0;
        y[i] = (i % 13) / 12.0;
        z[i] = (i % 29) / 28.0;
    }
    solid_eval(&t, N, x, y, z, v);
    mpd_eval(&m, N, x, y, z, d);
    int bad = 0, moved = 0;
    for (int i = 0; i < N; i++) {
        double expect = solid_marble_value(&t.marble, z[i] + 0.05 * d[i]);
        bad += v[i] != expect;
        moved += fabs(expect - solid_marble_value(&t.marble, z[i])) > 1e-9;
        double one;
        solid_eval(&t, 1, &x[i], &y[i], &z[i], &one);
        bad += one != v[i];
    }
    CHECK(bad == 0, "%d values differ from G(z + k D)", bad);
    CHECK(moved > N / 2, "D moves the layers (%d of %d)", moved, N);
    ramp r = solid_ramp_marble();
    float rgba[4 * 3];
    solid_color(&t, &r, 3, x, y, z, rgba);
    for (int i = 0; i < 3; i++) {
        float c[4];
        ramp_eval(&r, v[i], c);
        CHECK(memcmp(c, rgba + 4 * i, sizeof c) == 0, "colour = ramp(value)");
    }
    ramp rw = solid_ramp_wood();
    CHECK(r.n >= 2 && rw.n >= 2 && r.pos[0] == 0 && r.pos[r.n - 1] == 1 && rw.pos[rw.n - 1] == 1, "ramps span [0,1]");
    mpd_free(&m);
}

int main(void)
{
    test_marble();
    test_wood();
    test_perturbation();
    test_with_mpd();
    return check_done("test_solid");
}
