/* test_density.c — soft shapes and DMFs (density.h), against the formulas
 * of seed 001 / Perlin evaluated by hand. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "density.h"
#include "rng.h"

static density_shape shape(density_kind k)
{
    density_shape d;
    memset(&d, 0, sizeof d);
    d.kind = k;
    return d;
}

static void test_sphere(void)
{
    /* c = (1, 2, 3), r = 2, s = 1: r1 = 1.5, r1^2 = 2.25; r0 = 2.5,
     * r0^2 = 6.25; r0^2 - r1^2 = 4. */
    density_shape d = shape(DENSITY_SPHERE);
    d.c[0] = 1, d.c[1] = 2, d.c[2] = 3, d.r = 2, d.s = 1;
    CHECK(density_eval(&d, 1, 2, 3) == 1, "centre");
    CHECK(density_eval(&d, 2, 2, 3) == 1, "d = 1 is hard");
    CHECK(density_eval(&d, 1, 3.5, 3) == 1, "d = r1 = 1.5: 1");
    CHECK(density_eval(&d, 1, 2, 5.5) == 0, "d = r0 = 2.5: 0");
    CHECK(density_eval(&d, 4, 2, 3) == 0, "d = 3 outside");
    /* d = 2: d^2 = 4, (6.25 - 4) / 4 = 0.5625 */
    CHECK_NEAR(density_eval(&d, 1, 0, 3), 0.5625, 1e-15, "d = 2");
    /* (3, 3, 3): d^2 = 4 + 1 = 5, (6.25 - 5) / 4 = 0.3125 */
    CHECK_NEAR(density_eval(&d, 3, 3, 3), 0.3125, 1e-15, "d^2 = 5");
    /* just inside r1 and just outside r0 */
    CHECK(density_eval(&d, 1, 2, 3 + 1.5 - 1e-9) == 1, "inside r1");
    CHECK(density_eval(&d, 1, 2, 3 + 2.5 + 1e-9) == 0, "outside r0");
    double v = density_eval(&d, 1, 2, 3 + 1.5 + 1e-6);
    CHECK(v < 1 && v > 0.999998, "just past r1: %.17g", v);

    /* s = 0: a hard sphere, no 0/0 at the surface. */
    d.s = 0;
    CHECK(density_eval(&d, 1, 2, 5) == 1 && density_eval(&d, 1, 2, 5.0001) == 0, "hard sphere");
    /* s > 2r: r1 = 0. r = 1, s = 3: r0 = 2.5; d = 1: (6.25 - 1) / 6.25 = 0.84 */
    d.r = 1, d.s = 3;
    CHECK_NEAR(density_eval(&d, 2, 2, 3), 0.84, 1e-15, "s > 2r");
    CHECK(density_eval(&d, 1, 2, 3) == 1, "s > 2r centre");
}

static void test_other_shapes(void)
{
    /* Box: c = 0, h = (1, 2, 3), s = 0.5 (shell from sd = -0.25 to 0.25). */
    density_shape b = shape(DENSITY_BOX);
    b.h[0] = 1, b.h[1] = 2, b.h[2] = 3, b.s = 0.5;
    CHECK(density_eval(&b, 0, 0, 0) == 1, "box centre (sd = -1)");
    CHECK_NEAR(density_eval(&b, 1, 0, 0), 0.5, 1e-15, "box face: sd = 0");
    CHECK_NEAR(density_eval(&b, 1.1, 0, 0), 0.3, 1e-15, "sd = 0.1: (0.25 - 0.1)/0.5");
    CHECK_NEAR(density_eval(&b, 0, -1.9, 0), 0.7, 1e-15, "sd = -0.1: (0.25 + 0.1)/0.5");
    CHECK_NEAR(density_eval(&b, 1.1, 2.1, 0), (0.25 - sqrt(0.02)) / 0.5, 1e-15,
               "edge: sd = sqrt(0.1^2 + 0.1^2)");
    CHECK(density_eval(&b, 0, 0, 3.3) == 0, "box outside");
    CHECK(density_eval(&b, 0, 0, -2.7) == 1, "box hard (sd = -0.3)");

    /* Torus: R = 2, tube r = 0.5, s = 0.2: r1^2 = 0.16, r0^2 = 0.36. */
    density_shape t = shape(DENSITY_TORUS);
    t.R = 2, t.r = 0.5, t.s = 0.2;
    CHECK(density_eval(&t, 2, 0, 0) == 1, "on the core circle");
    CHECK_NEAR(density_eval(&t, 2.5, 0, 0), 0.55, 1e-15, "d^2 = .25: (.36 - .25)/.2");
    CHECK_NEAR(density_eval(&t, 0, -2, 0.5), 0.55, 1e-15, "above the circle");
    CHECK(density_eval(&t, 0, 0, 0) == 0, "hole of the torus");

    /* Cylinder: r = 1, half height 2, s = 0.4. */
    density_shape c = shape(DENSITY_CYLINDER);
    c.r = 1, c.h[2] = 2, c.s = 0.4;
    CHECK(density_eval(&c, 0, 0, 0) == 1, "cylinder axis");
    CHECK_NEAR(density_eval(&c, 0, 1, 0), 0.5, 1e-15, "side: sd = 0");
    CHECK_NEAR(density_eval(&c, 0, 0, 2.1), 0.25, 1e-15, "cap: sd = .1: (.2 - .1)/.4");
    CHECK_NEAR(density_eval(&c, 0.6, 0.8, -2.1), (0.2 - 0.1) / 0.4, 1e-15, "rim: sd = 0.1");
    CHECK(density_eval(&c, 1.3, 0, 0) == 0, "outside");

    /* Block = scalar, bit for bit, all shapes. */
    enum { N = 1000 };
    static double x[N], y[N], z[N], o[N];
    rng r;
    rng_init(&r, 4, 0);
    for (int i = 0; i < N; i++)
        x[i] = rng_uniform(&r) * 7 - 3.5, y[i] = rng_uniform(&r) * 7 - 3.5,
        z[i] = rng_uniform(&r) * 7 - 3.5;
    density_shape sp = shape(DENSITY_SPHERE);
    sp.r = 2, sp.s = 1.5;
    const density_shape *all[4] = {&sp, &b, &t, &c};
    for (int k = 0; k < 4; k++) {
        density_eval_block(all[k], N, x, y, z, o);
        int bad = 0, range = 0;
        for (int i = 0; i < N; i++) {
            bad += o[i] != density_eval(all[k], x[i], y[i], z[i]);
            range += !(o[i] >= 0 && o[i] <= 1);
        }
        CHECK(bad == 0 && range == 0, "%s: %d block mismatches, %d out of [0,1]",
              density_name(all[k]->kind), bad, range);
    }
}

static void test_validation(void)
{
    rt_error e;
    density_shape d = shape(DENSITY_SPHERE);
    d.r = -1;
    CHECK(density_check(&d, &e) == RT_EINVAL &&
              strcmp(e.msg, "sphere: radius r = -1, expected a finite number > 0") == 0,
          "msg '%s'", e.msg);
    d.r = 1, d.s = -0.5;
    CHECK(density_check(&d, &e) == RT_EINVAL &&
              strcmp(e.msg, "sphere: softness s = -0.5, expected a finite number >= 0") == 0,
          "msg '%s'", e.msg);
    d.s = 0.5, d.c[1] = NAN;
    CHECK(density_check(&d, &e) == RT_EINVAL && strstr(e.msg, "sphere: centre y = nan") == e.msg,
          "msg '%s'", e.msg);
    d.c[1] = 0;
    CHECK(density_check(&d, &e) == RT_OK, "valid sphere");
    density_shape b = shape(DENSITY_BOX);
    b.h[0] = 1, b.h[1] = 0, b.h[2] = 1;
    CHECK(density_check(&b, &e) == RT_EINVAL &&
              strcmp(e.msg, "box: half size y = 0, expected a finite number > 0") == 0,
          "msg '%s'", e.msg);
    density_shape t = shape(DENSITY_TORUS);
    t.R = 2;
    CHECK(density_check(&t, &e) == RT_EINVAL &&
              strcmp(e.msg, "torus: tube radius r = 0, expected a finite number > 0") == 0,
          "msg '%s'", e.msg);
    CHECK(dmf_check_bias(1.5, &e) == RT_EINVAL &&
              strcmp(e.msg, "bias: b = 1.5, expected 0 < b < 1") == 0,
          "msg '%s'", e.msg);
    CHECK(dmf_check_gain(0, &e) == RT_EINVAL &&
              strcmp(e.msg, "gain: g = 0, expected 0 < g < 1") == 0,
          "msg '%s'", e.msg);
    CHECK(dmf_check_bias(0.3, &e) == RT_OK && dmf_check_gain(0.7, &e) == RT_OK, "valid b, g");
}

static void test_dmfs(void)
{
    /* bias(b, 0.5) = 0.5^(ln b / ln 0.5) = b */
    const double bs[5] = {0.1, 0.25, 0.5, 0.7, 0.95};
    for (int i = 0; i < 5; i++) {
        CHECK_NEAR(dmf_bias(bs[i], 0.5), bs[i], 1e-15, "bias(b, 0.5) = b");
        CHECK(dmf_gain(bs[i], 0.5) == 0.5, "gain(g, 0.5) = 0.5: %.17g", dmf_gain(bs[i], 0.5));
        CHECK(dmf_bias(bs[i], 0) == 0 && dmf_bias(bs[i], 1) == 1, "bias ends");
        CHECK(dmf_gain(bs[i], 0) == 0 && dmf_gain(bs[i], 1) == 1, "gain ends");
        /* gain is symmetric: gain(g, t) + gain(g, 1 - t) = 1 */
        CHECK_NEAR(dmf_gain(bs[i], 0.2) + dmf_gain(bs[i], 0.8), 1, 1e-15, "gain symmetry");
    }
    /* b = 0.25: exponent ln .25 / ln .5 = 2: bias = t^2. */
    CHECK_NEAR(dmf_bias(0.25, 0.3), 0.09, 1e-15, "bias(.25, .3) = .3^2");
    /* b = 2^-1/2: exponent 1/2: bias = sqrt(t). */
    CHECK_NEAR(dmf_bias(sqrt(0.5), 0.49), 0.7, 1e-15, "bias(1/sqrt2, .49) = .7");
    /* b = 0.8: exponent ln .8 / ln .5 = 0.32192809488736235;
     * .64^0.3219... = exp(0.32192809488736235 * ln .64) = exp(-0.14367...) */
    CHECK_NEAR(dmf_bias(0.8, 0.64), exp(0.32192809488736235 * log(0.64)), 1e-15, "bias(.8,.64)");
    /* g = 0.75: bias(0.25, .) = square. t < .5: (2t)^2 / 2 = 2 t^2;
     * gain(.75, .25) = 0.125; t >= .5: 1 - (2 - 2t)^2 / 2: gain(.75, .75) = .875,
     * gain(.75, .6) = 1 - .8^2/2 = 0.68. */
    CHECK_NEAR(dmf_gain(0.75, 0.25), 0.125, 1e-15, "gain(.75,.25)");
    CHECK_NEAR(dmf_gain(0.75, 0.75), 0.875, 1e-15, "gain(.75,.75)");
    CHECK_NEAR(dmf_gain(0.75, 0.6), 0.68, 1e-15, "gain(.75,.6)");
    /* inputs outside [0, 1] are clamped */
    CHECK(dmf_bias(0.3, -1) == 0 && dmf_bias(0.3, 2) == 1, "bias clamps");
    CHECK(dmf_gain(0.3, -1) == 0 && dmf_gain(0.3, 1.5) == 1, "gain clamps");
    CHECK(isnan(dmf_bias(0.3, NAN)), "NaN stays NaN");

    /* step and smoothstep */
    CHECK(dmf_step(0.3, 0.3) == 1 && dmf_step(0.3, 0.29) == 0, "step at the edge");
    CHECK(dmf_smoothstep(0, 1, 0.5) == 0.5, "smoothstep midpoint");
    /* u = (1.5 - 1)/2 = .25: .0625 * (3 - .5) = 0.15625 */
    CHECK_NEAR(dmf_smoothstep(1, 3, 1.5), 0.15625, 1e-15, "smoothstep(1,3,1.5)");
    CHECK(dmf_smoothstep(1, 3, 0) == 0 && dmf_smoothstep(1, 3, 4) == 1, "smoothstep clamps");
    CHECK(dmf_smoothstep(2, 2, 2) == 1 && dmf_smoothstep(2, 2, 1.9) == 0, "e0 == e1: step");

    /* smooth union: a = b = .5, k = .2: h = 1, .5 + .2/4 = .55 */
    CHECK_NEAR(density_smooth_union(0.5, 0.5, 0.2), 0.55, 1e-15, "smooth union at a = b");
    CHECK(density_smooth_union(0.9, 0.2, 0.2) == 0.9, "far apart: max");
    /* |a - b| = .1, k = .2: h = .5, .6 + .25 * .2 / 4 = .6125 */
    CHECK_NEAR(density_smooth_union(0.6, 0.5, 0.2), 0.6125, 1e-15, "smooth union near");
    CHECK(density_smooth_union(0.99, 0.99, 0.5) == 1, "clamped to 1");
    CHECK(density_smooth_union(0.3, 0.4, 0) == 0.4, "k = 0: max");

    /* blocks = scalar */
    enum { N = 333 };
    double t[N], o[N];
    for (int i = 0; i < N; i++)
        t[i] = -0.1 + 1.2 * i / (N - 1);
    int bad = 0;
    dmf_bias_block(0.3, N, t, o);
    for (int i = 0; i < N; i++)
        bad += o[i] != dmf_bias(0.3, t[i]);
    dmf_gain_block(0.8, N, t, o);
    for (int i = 0; i < N; i++)
        bad += o[i] != dmf_gain(0.8, t[i]);
    dmf_smoothstep_block(0.2, 0.7, N, t, o);
    for (int i = 0; i < N; i++)
        bad += o[i] != dmf_smoothstep(0.2, 0.7, t[i]);
    CHECK(bad == 0, "%d DMF block mismatches", bad);
}

/* density_sdf's zero set is the level set {D = level}: from a point at
 * distance t along a ray out of the centre, the surface is t - sdf away
 * (exact for a sphere, and for a box and a torus along an axis), and D
 * there is the level. */
static void test_sdf_levels(void)
{
    density_kind kinds[3] = {DENSITY_SPHERE, DENSITY_TORUS, DENSITY_BOX};
    double levels[3] = {0.25, 0.6, 0.9};
    for (int k = 0; k < 3; k++)
        for (int l = 0; l < 3; l++) {
            density_shape d = shape(kinds[k]);
            d.c[0] = 1, d.c[1] = -2, d.c[2] = 0.5, d.r = 0.7, d.R = 2, d.s = 0.4;
            d.h[0] = d.h[1] = d.h[2] = 0.8;
            double base = kinds[k] == DENSITY_TORUS ? d.R : 0; /* the tube's centre line on +x */
            double t = 1.5, x = d.c[0] + base + t;
            double rho = t - density_sdf(&d, levels[l], x, d.c[1], d.c[2]);
            double D = density_eval(&d, d.c[0] + base + rho, d.c[1], d.c[2]);
            CHECK(fabs(D - levels[l]) < 1e-12, "%s, level %g: D = %.15g where the sdf is 0",
                  density_name(kinds[k]), levels[l], D);
        }
}

int main(void)
{
    test_sphere();
    test_other_shapes();
    test_validation();
    test_dmfs();
    test_sdf_levels();
    return check_done("test_density");
}
