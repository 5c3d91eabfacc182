/* test_field_sdf.c — signed distances of shapes (density_sdf) and what the
 * field graph keeps of them (field_level_sdf, field_hard_support): exact
 * distances at hand-computed points, the sign agreeing with the solid
 * {f >= level} at random points for every rule, exactness flags, the graphs
 * that have no distance, and the printed form of a distance node. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "field.h"
#include "noise.h"

static density_shape shape(density_kind k, double s)
{
    density_shape d;
    memset(&d, 0, sizeof d);
    d.kind = k;
    d.r = 0.5;
    d.R = 0.6;
    d.h[0] = 0.4, d.h[1] = 0.5, d.h[2] = 0.6;
    d.s = s;
    return d;
}

static void test_shape_distances(void)
{
    density_shape sp = shape(DENSITY_SPHERE, 0), bx = shape(DENSITY_BOX, 0);
    density_shape cy = shape(DENSITY_CYLINDER, 0), to = shape(DENSITY_TORUS, 0);
    sp.r = 0.7;
    CHECK_NEAR(density_sdf(&sp, 0.5, 1, 2, 2), 3 - 0.7, 1e-15, "sphere outside");
    CHECK_NEAR(density_sdf(&sp, 0.5, 0, 0.2, 0), -0.5, 1e-15, "sphere inside");
    CHECK_NEAR(density_sdf(&bx, 0.5, 1.4, 0, 0), 1.0, 1e-15, "box face");
    CHECK_NEAR(density_sdf(&bx, 0.5, 1.4, 1.5, 1.6), sqrt(3.0), 1e-15, "box corner");
    CHECK_NEAR(density_sdf(&bx, 0.5, 0.1, 0, 0), -0.3, 1e-15, "box inside: nearest face x");
    CHECK_NEAR(density_sdf(&cy, 0.5, 0, 0.8, 0), 0.3, 1e-15, "cylinder side");
    CHECK_NEAR(density_sdf(&cy, 0.5, 0, 0, -1), 0.4, 1e-15, "cylinder cap");
    CHECK_NEAR(density_sdf(&cy, 0.5, 0.9, 0, 1), sqrt(0.32), 1e-15, "cylinder rim (0.4, 0.4)");
    to.r = 0.25;
    CHECK_NEAR(density_sdf(&to, 0.5, 0.6, 0, 0), -0.25, 1e-15, "torus core");
    CHECK_NEAR(density_sdf(&to, 0.5, 0, 0, 0), sqrt(0.36) - 0.25, 1e-15, "torus centre");
    /* Soft shapes: the level surface. Sphere r 0.5 soft 0.2: r1 0.4, r0 0.6,
     * level 0.5: rho^2 = 0.36 - 0.5 (0.36 - 0.16) = 0.26. */
    density_shape ss = shape(DENSITY_SPHERE, 0.2);
    CHECK_NEAR(density_sdf(&ss, 0.5, 1, 0, 0), 1 - sqrt(0.26), 1e-15, "soft sphere level 0.5");
    CHECK(density_sdf_exact(&ss, 0.9) && density_sdf_exact(&bx, 0.9), "exact flags");
    density_shape sb = shape(DENSITY_BOX, 0.2);
    CHECK(density_sdf_exact(&sb, 0.5) && !density_sdf_exact(&sb, 0.9), "soft box: exact at <= 1/2 only");
    /* The sign agrees with the density at every level, for every shape. */
    uint64_t st = 12345;
    int bad = 0, n = 0;
    for (int k = 0; k < 4; k++)
        for (int soft = 0; soft < 2; soft++) {
            density_shape d = shape((density_kind)k, soft ? 0.3 : 0);
            double levels[3] = {0.2, 0.5, 1};
            for (int l = 0; l < 3; l++)
                for (int i = 0; i < 2000; i++) {
                    double p[3];
                    for (int a = 0; a < 3; a++) {
                        st = st * 6364136223846793005ull + 1442695040888963407ull;
                        p[a] = ((double)(st >> 11) / 9007199254740992.0) * 2.4 - 1.2;
                    }
                    double g = density_sdf(&d, levels[l], p[0], p[1], p[2]);
                    double D = density_eval(&d, p[0], p[1], p[2]);
                    if (fabs(g) < 1e-9)
                        continue;
                    n++;
                    bad += (g <= 0) != (D >= levels[l]);
                }
        }
    CHECK(n > 40000 && bad == 0, "sign of sdf vs density >= level: %d of %d disagree", bad, n);
}

/* Compile f and g; at random points in [-1.2, 1.2]^3, g <= 0 iff f >= L
 * (except within 1e-9 of the surface). */
static int agree(field *f, field *g, double L, int *tested)
{
    rt_error e;
    field_prog *pf = field_compile(f, &e), *pg = field_compile(g, &e);
    int bad = 0;
    *tested = 0;
    uint64_t st = 99;
    for (int i = 0; i < 4000 && pf && pg; i++) {
        double p[3];
        for (int a = 0; a < 3; a++) {
            st = st * 6364136223846793005ull + 1442695040888963407ull;
            p[a] = ((double)(st >> 11) / 9007199254740992.0) * 2.4 - 1.2;
        }
        double gv = field_prog_eval1(pg, p[0], p[1], p[2]), fv = field_prog_eval1(pf, p[0], p[1], p[2]);
        if (fabs(gv) < 1e-9)
            continue;
        ++*tested;
        bad += (gv <= 0) != (fv >= L);
    }
    field_prog_free(pf);
    field_prog_free(pg);
    return bad;
}

static field *fsh(density_kind k, double s) { density_shape d = shape(k, s); return field_density(&d); }

static void check_rule(field *f, double L, int want_exact, const char *what)
{
    rt_error e;
    field *g = NULL;
    int exact = -1, tested;
    CHECK(field_level_sdf(f, L, &g, &exact, &e) == RT_OK, "%s: %s", what, e.msg);
    CHECK(g != NULL, "%s: no distance", what);
    if (g) {
        int bad = agree(f, g, L, &tested);
        CHECK(bad == 0 && tested > 3000, "%s: %d of %d points disagree", what, bad, tested);
        CHECK(exact == want_exact, "%s: exact %d, expected %d", what, exact, want_exact);
    }
    field_unref(g);
    field_unref(f);
}

static void check_none(field *f, double L, const char *what)
{
    rt_error e;
    field *g = (field *)1;
    CHECK(field_level_sdf(f, L, &g, NULL, &e) == RT_OK && g == NULL, "%s: has a distance", what);
    field_unref(f);
}

static void test_rules(void)
{
    double rot[12] = {0, -1, 0, 0.1, 1, 0, 0, 0, 0, 0, 1, -0.2}; /* a quarter turn and a shift */
    double shear[12] = {1, 0.5, 0, 0, 0, 1, 0, 0, 0, 0, 2, 0};
    check_rule(fsh(DENSITY_SPHERE, 0), 0.5, 1, "hard sphere");
    check_rule(fsh(DENSITY_TORUS, 0.2), 0.7, 1, "soft torus");
    check_rule(fsh(DENSITY_BOX, 0.3), 0.8, 0, "soft box inside half");
    check_rule(field_translate(fsh(DENSITY_BOX, 0), 0.2, -0.1, 0.3), 0.5, 1, "translate");
    check_rule(field_scale(fsh(DENSITY_CYLINDER, 0), 1.5), 0.5, 1, "scale");
    check_rule(field_transform(fsh(DENSITY_BOX, 0), rot), 0.5, 1, "rotation");
    check_rule(field_transform(fsh(DENSITY_BOX, 0), shear), 0.5, 0, "shear: a bound");
    check_rule(field_binary(FIELD_MUL, fsh(DENSITY_SPHERE, 0.4), field_const(2)), 0.6, 1, "density * 2");
    check_rule(field_binary(FIELD_SUB, field_const(1), fsh(DENSITY_SPHERE, 0)), 0.5, 1, "1 - hard: outside");
    check_rule(field_unary(FIELD_NOT, fsh(DENSITY_BOX, 0)), 0.5, 1, "not hard");
    check_rule(field_binary(FIELD_GE, fsh(DENSITY_SPHERE, 0.3), field_const(0.4)), 1, 1, "density >= 0.4");
    check_rule(field_binary(FIELD_LT, fsh(DENSITY_SPHERE, 0.3), field_const(0.4)), 0.5, 1, "density < 0.4");
    check_rule(field_step(fsh(DENSITY_TORUS, 0.2), 0.3), 0.5, 1, "step");
    check_rule(field_affine(fsh(DENSITY_SPHERE, 0.3), -2, 1.5), 0.2, 1, "affine, negative scale");
    check_rule(field_bias(fsh(DENSITY_SPHERE, 0.4), 0.7), 0.5, 1, "bias");
    check_rule(field_gain(fsh(DENSITY_SPHERE, 0.4), 0.3), 0.2, 1, "gain below 1/2");
    check_rule(field_gain(fsh(DENSITY_SPHERE, 0.4), 0.3), 0.8, 1, "gain above 1/2");
    check_rule(field_smoothstep(fsh(DENSITY_SPHERE, 0.4), 0.2, 0.9), 0.3, 1, "smoothstep");
    check_rule(field_binary(FIELD_MAX, fsh(DENSITY_SPHERE, 0),
                            field_translate(fsh(DENSITY_BOX, 0), 0.5, 0, 0)), 0.5, 0, "union");
    check_rule(field_binary(FIELD_MIN, fsh(DENSITY_SPHERE, 0.2),
                            field_translate(fsh(DENSITY_BOX, 0.2), 0.5, 0, 0)), 0.5, 0, "intersection");
    check_rule(field_binary(FIELD_MUL, fsh(DENSITY_SPHERE, 0),
                            field_binary(FIELD_SUB, field_const(1), fsh(DENSITY_BOX, 0))), 0.5, 0,
               "hard product: difference");
    /* No distance: noise, smooth unions, non-affine warps, non-0/1 products,
     * levels outside (0, 1] of a density, numbers. */
    check_none(field_binary(FIELD_MUL, fsh(DENSITY_SPHERE, 0), field_turbulence(3, 4)), 0.5, "noise");
    check_none(field_smooth_union(fsh(DENSITY_SPHERE, 0), fsh(DENSITY_BOX, 0), 0.1), 0.5, "smooth union");
    check_none(field_warp(fsh(DENSITY_SPHERE, 0), field_unary(FIELD_SIN, field_coord(0)), field_coord(1),
                          field_coord(2)), 0.5, "sin warp");
    check_none(field_binary(FIELD_MUL, fsh(DENSITY_SPHERE, 0.3), fsh(DENSITY_BOX, 0.3)), 0.5, "soft product");
    check_none(fsh(DENSITY_SPHERE, 0), 0, "level 0");
    check_none(fsh(DENSITY_SPHERE, 0), 1.5, "level above 1");
    check_none(field_const(1), 0.5, "number");
    check_none(field_scale(fsh(DENSITY_SPHERE, 0), 0), 0.5, "scale 0: degenerate map");
}

static void test_values_and_print(void)
{
    rt_error e;
    field *g;
    int exact;
    /* scale(sphere r 0.5, 2): the sphere of radius 1; distance at (3, 0, 0) is 2 */
    field *f = field_scale(fsh(DENSITY_SPHERE, 0), 2);
    CHECK(field_level_sdf(f, 0.5, &g, &exact, &e) == RT_OK && g && exact, "scale");
    field_prog *p = g ? field_compile(g, &e) : NULL;
    CHECK(p && fabs(field_prog_eval1(p, 3, 0, 0) - 2) < 1e-15, "scaled distance %g",
          p ? field_prog_eval1(p, 3, 0, 0) : NAN);
    field_prog_free(p);
    field_unref(g);
    field_unref(f);
    density_shape d = shape(DENSITY_SPHERE, 0);
    field *n = field_shape_sdf(&d, 0.5);
    bytebuf b;
    bytebuf_init(&b);
    field_print(n, &b, 200);
    bytebuf_byte(&b, 0);
    CHECK(strcmp((char *)b.data, "sdf(sphere(centre: [0, 0, 0], r: 0.5, soft: 0), level: 0.5)") == 0,
          "printed %s", (char *)b.data);
    bytebuf_free(&b);
    field_unref(n);
    /* The hard support of sphere * (0.5 + noise): the density is 0 outside. */
    f = field_binary(FIELD_MUL, fsh(DENSITY_SPHERE, 0),
                     field_binary(FIELD_ADD, field_const(0.5), field_turbulence(7, 3)));
    CHECK(field_hard_support(f, &g, &e) == RT_OK && g, "support of a hard product");
    field_prog *pf = field_compile(f, &e), *pg = g ? field_compile(g, &e) : NULL;
    int bad = 0;
    for (int i = 0; i < 1000 && pf && pg; i++) {
        double x = -1 + 0.002 * i, y = 0.3 * sin(i), z = 0.2 * cos(3 * i);
        if (field_prog_eval1(pg, x, y, z) > 0 && field_prog_eval1(pf, x, y, z) != 0)
            bad++;
    }
    CHECK(pf && pg && bad == 0, "density outside the support at %d points", bad);
    field_prog_free(pf);
    field_prog_free(pg);
    field_unref(g);
    field_unref(f);
    f = fsh(DENSITY_SPHERE, 0.3);
    g = (field *)1;
    CHECK(field_hard_support(f, &g, &e) == RT_OK && g == NULL, "a soft shape has no hard support");
    field_unref(f);
}

int main(void)
{
    test_shape_distances();
    test_rules();
    test_values_and_print();
    return check_done("test_field_sdf");
}
