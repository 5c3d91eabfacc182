/* test_field.c — field graphs, the compiler and the block evaluator
 * (field.h): compiled evaluation against the same expression written
 * directly in C, sharing, folding, warps, externals, volumes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
#include "density.h"
#include "field.h"
#include "image.h"
#include "noise.h"
#include "rng.h"

#define N 1000 /* more than RT_BLOCK, not a multiple of it */

static double X[N], Y[N], Z[N], OUT[N];

static void points(uint64_t seed, double scale)
{
    rng r;
    rng_init(&r, seed, 0);
    for (int i = 0; i < N; i++) {
        X[i] = (rng_uniform(&r) * 2 - 1) * scale;
        Y[i] = (rng_uniform(&r) * 2 - 1) * scale;
        Z[i] = (rng_uniform(&r) * 2 - 1) * scale;
    }
}

static field *X_(void) { return field_coord(0); }
static field *Y_(void) { return field_coord(1); }
static field *Z_(void) { return field_coord(2); }
static field *K(double v) { return field_const(v); }
static field *B(field_binop op, field *a, field *b) { return field_binary(op, a, b); }
static field *U(field_unop op, field *a) { return field_unary(op, a); }

typedef double (*direct_fn)(double x, double y, double z);

/* Compile f (consumed), evaluate at the points through the rt_field_fn
 * adapter, compare with direct(); returns the number of mismatches (exact
 * comparison: same operations in the same order; NaN == NaN here). */
static int compare(field *f, direct_fn direct, const char *what, size_t *ninstr)
{
    rt_error e;
    CHECK(f != NULL, "%s: construction failed", what);
    field_prog *p = field_compile(f, &e);
    field_unref(f);
    CHECK(p != NULL, "%s: compile failed: %s", what, e.msg);
    if (!p)
        return -1;
    rt_field_fn fn = field_prog_fn;
    fn(p, N, X, Y, Z, OUT);
    int bad = 0;
    for (int i = 0; i < N; i++) {
        double want = direct(X[i], Y[i], Z[i]);
        if (!(OUT[i] == want || (isnan(OUT[i]) && isnan(want)))) {
            if (bad < 3)
                fprintf(stderr, "%s: point %d (%g, %g, %g): got %.17g want %.17g\n", what, i,
                        X[i], Y[i], Z[i], OUT[i], want);
            bad++;
        }
    }
    CHECK(bad == 0, "%s: %d mismatches", what, bad);
    double one = field_prog_eval1(p, X[7], Y[7], Z[7]);
    CHECK(one == OUT[7] || (isnan(one) && isnan(OUT[7])), "%s: eval1", what);
    if (ninstr)
        field_prog_stats(p, ninstr, NULL);
    field_prog_free(p);
    return bad;
}

/* ---- expressions */

static double d_arith(double x, double y, double z)
{
    return sin(x) * y + z / 2 - pow(fabs(x), 1.5) + fmax(0, 0) * 0 +
           (x - 0.7 * floor(x / 0.7)) + atan2(y, x);
}
static field *g_arith(void)
{
    field *a = B(FIELD_MUL, U(FIELD_SIN, X_()), Y_());
    a = B(FIELD_ADD, a, B(FIELD_DIV, Z_(), K(2)));
    a = B(FIELD_SUB, a, B(FIELD_POW, U(FIELD_ABS, X_()), K(1.5)));
    a = B(FIELD_ADD, a, B(FIELD_MUL, B(FIELD_MAX, K(0), K(0)), K(0)));
    a = B(FIELD_ADD, a, B(FIELD_MOD, X_(), K(0.7)));
    return B(FIELD_ADD, a, B(FIELD_ATAN2, Y_(), X_()));
}

static double d_logic(double x, double y, double z)
{
    double c = (x < y && !(z >= 0.5)) || x == 0.25 ? 1 : 0;
    double s = c != 0 ? exp(-x * x) : sqrt(fabs(y)) + ceil(z);
    double cl = s < -0.2 ? -0.2 : s > 0.9 ? 0.9 : s;
    double lo = cl + (y - cl) * z; /* lerp(cl, y, z) */
    return lo + (x > 0 ? 1 : x < 0 ? -1 : x) + (x - floor(x)) + floor(y + 0.5) + (x <= y) +
           (y > z) + (x != z) + tanh(y);
}
static field *g_logic(void)
{
    field *c = B(FIELD_OR,
                 B(FIELD_AND, B(FIELD_LT, X_(), Y_()), U(FIELD_NOT, B(FIELD_GE, Z_(), K(0.5)))),
                 B(FIELD_EQ, X_(), K(0.25)));
    field *s = field_select(c, U(FIELD_EXP, U(FIELD_NEG, B(FIELD_MUL, X_(), X_()))),
                            B(FIELD_ADD, U(FIELD_SQRT, U(FIELD_ABS, Y_())), U(FIELD_CEIL, Z_())));
    field *cl = field_clamp(s, K(-0.2), K(0.9));
    field *lo = field_lerp(cl, Y_(), Z_());
    field *r = B(FIELD_ADD, lo, U(FIELD_SIGN, X_()));
    r = B(FIELD_ADD, r, U(FIELD_FRACT, X_()));
    r = B(FIELD_ADD, r, U(FIELD_ROUND, Y_()));
    r = B(FIELD_ADD, r, B(FIELD_LE, X_(), Y_()));
    r = B(FIELD_ADD, r, B(FIELD_GT, Y_(), Z_()));
    r = B(FIELD_ADD, r, B(FIELD_NE, X_(), Z_()));
    return B(FIELD_ADD, r, U(FIELD_TANH, Y_()));
}

/* Shared subexpression: s = x*x + y*y; s*s + sqrt(s) + s. */
static double d_shared(double x, double y, double z)
{
    (void)z;
    double s = x * x + y * y;
    return s * s + sqrt(s) + s;
}
static field *g_shared(void)
{
    field *s = B(FIELD_ADD, B(FIELD_MUL, X_(), X_()), B(FIELD_MUL, Y_(), Y_()));
    field *r = B(FIELD_ADD, B(FIELD_MUL, field_ref(s), field_ref(s)), U(FIELD_SQRT, field_ref(s)));
    return B(FIELD_ADD, r, s);
}

/* Warps. The seed-000 perturbation P' = P + (0, 0, k D(P)) of a noise:
 * perlin(x, y, z + 0.5 fbm(x, y, z)). */
static noise_perm perm_a, perm_b;
static double d_warp(double x, double y, double z)
{
    double D = noise_fbm3(&perm_b, 4, 2, 0.5, x, y, z);
    return noise_perlin3(&perm_a, x, y, z + 0.5 * D);
}
static field *g_warp(void)
{
    field *D = field_fbm(22, 4, 2, 0.5);
    return field_warp(field_perlin(11), X_(), Y_(), B(FIELD_ADD, Z_(), B(FIELD_MUL, K(0.5), D)));
}

/* Coordinates inside a warp are the warped point; nested warps compose:
 * warp(warp(x * y + z, 2x, y, z), x + 1, z, y) = 2 (x + 1) * z + y. */
static double d_nested(double x, double y, double z) { return 2 * (x + 1) * z + y; }
static field *g_nested(void)
{
    field *inner = field_warp(B(FIELD_ADD, B(FIELD_MUL, X_(), Y_()), Z_()),
                              B(FIELD_MUL, K(2), X_()), Y_(), Z_());
    return field_warp(inner, B(FIELD_ADD, X_(), K(1)), Z_(), Y_());
}

/* A shared node used both outside and inside a warp must be evaluated in
 * each frame: s = x*x; s + warp(s, x + 3, y, z) = x^2 + (x + 3)^2. */
static double d_frames(double x, double y, double z)
{
    (void)y, (void)z;
    return x * x + (x + 3) * (x + 3);
}
static field *g_frames(void)
{
    field *s = B(FIELD_MUL, X_(), X_());
    return B(FIELD_ADD, field_ref(s), field_warp(s, B(FIELD_ADD, X_(), K(3)), Y_(), Z_()));
}

/* translate / scale / transform helpers */
static double d_moves(double x, double y, double z)
{
    double a = (x - 1) * (y + 2) * (z - 0.5);                /* translate (1, -2, 0.5) */
    double b = (x * 0.25) + (y * 0.25);                      /* scale 4: P / 4 */
    double tx = 0 * x + -1 * y + 0 * z + 0.5, ty = 1 * x + 0 * y + 0 * z + 0, tz = z * 1 + 0;
    double c = tx * 10 + ty; /* transform of 10 x + y */
    (void)tz;
    return a + b + c;
}
static field *g_moves(void)
{
    field *a = field_translate(B(FIELD_MUL, B(FIELD_MUL, X_(), Y_()), Z_()), 1, -2, 0.5);
    field *b = field_scale(B(FIELD_ADD, X_(), Y_()), 4);
    static const double m[12] = {0, -1, 0, 0.5, 1, 0, 0, 0, 0, 0, 1, 0};
    field *c = field_transform(B(FIELD_ADD, B(FIELD_MUL, X_(), K(10)), Y_()), m);
    return B(FIELD_ADD, B(FIELD_ADD, a, b), c);
}

/* An external engine: ctx holds coefficients; release counts. */
typedef struct ext_ctx {
    double k[3];
    int released;
} ext_ctx;
static void ext_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                   double *out)
{
    const ext_ctx *c = ctx;
    for (size_t i = 0; i < n; i++)
        out[i] = c->k[0] * x[i] + c->k[1] * y[i] * y[i] + c->k[2] * cos(z[i]);
}
static void ext_release(void *ctx) { ((ext_ctx *)ctx)->released++; }
static ext_ctx ectx = {{0.5, -2, 3}, 0};
static double d_ext(double x, double y, double z)
{
    double e1 = 0.5 * x + -2 * y * y + 3 * cos(z);
    double wx = y, wy = x * 2, wz = z; /* external under a warp */
    double e2 = 0.5 * wx + -2 * wy * wy + 3 * cos(wz);
    return e1 * e2 + e1;
}
static field *g_ext(void)
{
    field *e = field_external(ext_fn, &ectx, ext_release, "myengine");
    field *w = field_warp(field_ref(e), Y_(), B(FIELD_MUL, X_(), K(2)), Z_());
    return B(FIELD_ADD, B(FIELD_MUL, field_ref(e), w), e);
}

/* The hypertexture chain of seed 001: sphere * turbulence |> bias |> gain,
 * smooth union with a torus, smoothstep, step, affine. */
static density_shape sph, tor;
static double d_dmf(double x, double y, double z)
{
    double d = density_eval(&sph, x, y, z) * noise_turbulence3(&perm_a, 6, x, y, z);
    d = dmf_gain(0.7, dmf_bias(0.3, d));
    d = density_smooth_union(d, density_eval(&tor, x, y, z), 0.25);
    return dmf_smoothstep(0.1, 0.8, d) * 0.5 + 0.25 + dmf_step(0.3, d);
}
static field *g_dmf(void)
{
    field *d = B(FIELD_MUL, field_density(&sph), field_turbulence(11, 6));
    d = field_gain(field_bias(d, 0.3), 0.7);
    d = field_smooth_union(d, field_density(&tor), 0.25);
    return B(FIELD_ADD, field_affine(field_smoothstep(field_ref(d), 0.1, 0.8), 0.5, 0.25),
             field_step(d, 0.3));
}

/* Many live registers (> 256): t_i = x + i used by two sums. */
enum { WIDE = 600 };
static double d_wide(double x, double y, double z)
{
    (void)y, (void)z;
    double s1 = x + 0, s2 = x + 0;
    for (int i = 1; i < WIDE; i++)
        s1 = s1 + (x + i);
    for (int i = 1; i < WIDE; i++)
        s2 = s2 + (x + i);
    return s1 * s2;
}
static field *g_wide(int width)
{
    field **t = rt_malloc(sizeof *t * (size_t)width);
    for (int i = 0; i < width; i++)
        t[i] = B(FIELD_ADD, X_(), K(i));
    field *s1 = field_ref(t[0]), *s2 = field_ref(t[0]);
    for (int i = 1; i < width; i++)
        s1 = B(FIELD_ADD, s1, field_ref(t[i]));
    for (int i = 1; i < width; i++)
        s2 = B(FIELD_ADD, s2, field_ref(t[i]));
    for (int i = 0; i < width; i++)
        field_unref(t[i]);
    rt_free(t);
    return B(FIELD_MUL, s1, s2);
}
enum { MID = 100 };
static double d_mid(double x, double y, double z)
{
    (void)y, (void)z;
    double s1 = x + 0, s2 = x + 0;
    for (int i = 1; i < MID; i++)
        s1 = s1 + (x + i);
    for (int i = 1; i < MID; i++)
        s2 = s2 + (x + i);
    return s1 * s2;
}

static void test_expressions(void)
{
    noise_perm_init(&perm_a, 11);
    noise_perm_init(&perm_b, 22);
    memset(&sph, 0, sizeof sph);
    sph.kind = DENSITY_SPHERE, sph.r = 0.8, sph.s = 0.4;
    memset(&tor, 0, sizeof tor);
    tor.kind = DENSITY_TORUS, tor.R = 0.9, tor.r = 0.2, tor.s = 0.1, tor.c[2] = 0.1;
    points(1, 2);
    X[3] = 0.25; /* hit the x == 0.25 branch */
    size_t ni;
    compare(g_arith(), d_arith, "arithmetic", &ni);
    CHECK(ni == 12, "max(0,0)*0 folded: %zu instructions, expected 12", ni);
    compare(g_logic(), d_logic, "logic/select/clamp/lerp", NULL);
    compare(g_shared(), d_shared, "shared subexpression", &ni);
    /* x*x, y*y, +, s*s, sqrt, +, + : s is computed once */
    CHECK(ni == 7, "shared: %zu instructions, expected 7", ni);
    compare(g_warp(), d_warp, "warp (seed 000 perturbation)", NULL);
    compare(g_nested(), d_nested, "nested warps", NULL);
    compare(g_frames(), d_frames, "node in two frames", &ni);
    CHECK(ni == 4, "frames: %zu instructions, expected 4", ni);
    compare(g_moves(), d_moves, "translate/scale/transform", NULL);
    compare(g_ext(), d_ext, "external", &ni);
    CHECK(ni == 5 && ectx.released == 1, "external: %zu instructions, released %d", ni,
          ectx.released);
    compare(g_dmf(), d_dmf, "DMF chain", NULL);
    points(2, 1000);
    compare(g_wide(MID), d_mid, "200 live registers (shorter blocks)", NULL);
    compare(g_wide(WIDE), d_wide, "1200 live registers (heap)", NULL);
}


static void test_folding_and_print(void)
{
    rt_error e;
    /* (2 + 3) * x: one instruction; a constant graph: none. */
    field *f = B(FIELD_MUL, B(FIELD_ADD, K(2), K(3)), X_());
    field_prog *p = field_compile(f, &e);
    size_t ni, nr;
    field_prog_stats(p, &ni, &nr);
    CHECK(ni == 1 && field_prog_eval1(p, 7, 0, 0) == 35, "fold: %zu instrs", ni);
    field_prog_free(p);
    field_unref(f);
    f = field_warp(field_perlin(5), K(0.5), K(0.25), K(0)); /* noise at a constant point */
    p = field_compile(f, &e);
    field_prog_stats(p, &ni, &nr);
    noise_perm np;
    noise_perm_init(&np, 5);
    CHECK(ni == 0 && field_prog_eval1(p, 9, 9, 9) == noise_perlin3(&np, 0.5, 0.25, 0),
          "constant warp folded: %zu", ni);
    field_prog_free(p);
    field_unref(f);
    /* dead code: warp(x, x + 1, sin(y), cos(z)) needs only x + 1 */
    f = field_warp(X_(), B(FIELD_ADD, X_(), K(1)), U(FIELD_SIN, Y_()), U(FIELD_COS, Z_()));
    p = field_compile(f, &e);
    field_prog_stats(p, &ni, &nr);
    CHECK(ni == 1 && field_prog_eval1(p, 2, 0, 0) == 3, "dead code: %zu instrs", ni);
    field_prog_free(p);
    field_unref(f);
    /* a bare coordinate: no instructions, the input itself */
    f = Y_();
    p = field_compile(f, &e);
    CHECK(field_prog_eval1(p, 1, 2, 3) == 2, "coordinate");
    field_prog_free(p);
    field_unref(f);

    bytebuf b;
    bytebuf_init(&b);
    f = B(FIELD_MUL, B(FIELD_ADD, X_(), K(1)), U(FIELD_SIN, Y_()));
    field_print(f, &b, 1000);
    bytebuf_byte(&b, 0);
    CHECK(strcmp((char *)b.data, "(x + 1) * sin(y)") == 0, "print '%s'", (char *)b.data);
    field_unref(f);
    b.len = 0;
    f = field_bias(B(FIELD_MUL, field_density(&sph), field_turbulence(3, 6)), 0.7);
    field_print(f, &b, 1000);
    bytebuf_byte(&b, 0);
    CHECK(strcmp((char *)b.data, "bias(sphere(centre: [0, 0, 0], r: 0.8, soft: 0.4) * "
                                 "turbulence(seed: 3, octaves: 6), 0.7)") == 0,
          "print '%s'", (char *)b.data);
    field_unref(f);
    /* a DAG with exponential tree size prints in bounded length */
    b.len = 0;
    f = X_();
    for (int i = 0; i < 60; i++)
        f = B(FIELD_ADD, field_ref(f), f);
    field_print(f, &b, 200);
    CHECK(b.len == 203 && memcmp(b.data + 200, "...", 3) == 0, "cut print: %zu", b.len);
    p = field_compile(f, &e);
    field_prog_stats(p, &ni, &nr);
    CHECK(ni == 60 && field_prog_eval1(p, 1, 0, 0) == ldexp(1, 60), "2^60 x: %zu instrs", ni);
    field_prog_free(p);
    field_unref(f);
    bytebuf_free(&b);

    CHECK(field_binop_lookup("atan2") == FIELD_ATAN2 && field_unop_lookup("sqrt") == FIELD_SQRT &&
              field_unop_lookup("nope") == -1,
          "name lookup");
}

static void test_depth(void)
{
    rt_error e;
    field *f = X_();
    for (int i = 0; i < 5000; i++)
        f = B(FIELD_ADD, f, K(1));
    field_prog *p = field_compile(f, &e);
    CHECK(p && field_prog_eval1(p, 0.5, 0, 0) == 5000.5, "deep chain");
    field_prog_free(p);
    for (int i = 0; i < 7000; i++)
        f = B(FIELD_ADD, f, K(1));
    p = field_compile(f, &e);
    CHECK(!p && e.code == RT_EINVAL &&
              strcmp(e.msg, "field graph nested deeper than 10000 nodes") == 0,
          "too deep: '%s'", e.msg);
    field_unref(f); /* iterative: no stack overflow */
    /* NULL children propagate (as after an allocation failure) */
    CHECK(field_binary(FIELD_ADD, X_(), NULL) == NULL, "NULL child");
    CHECK(field_warp(X_(), NULL, Y_(), Z_()) == NULL, "NULL warp child");
    CHECK(field_smooth_union(X_(), NULL, 0.1) == NULL, "NULL smooth union child");
}

/* Volume fill: values at the cell centres of volume.h, and byte-identical
 * for 1, 2 and 4 threads. */
static void test_volume(void)
{
    rt_error e;
    field *f = B(FIELD_MUL, field_density(&sph), field_turbulence(11, 6));
    f = field_gain(field_bias(f, 0.3), 0.7);
    field_prog *p = field_compile(f, &e);
    field_unref(f);
    const double lo[3] = {-1, -1.2, -0.9}, hi[3] = {1, 0.8, 1.1};
    volume v[3];
    const int threads[3] = {1, 2, 4};
    for (int t = 0; t < 3; t++) {
        CHECK(volume_init(&v[t], 300, 13, 11, lo, hi, &e) == RT_OK, "volume_init");
        rt_run run = {threads[t], NULL, 0};
        CHECK(field_sample_volume(field_prog_fn, p, &v[t], &run, &e) == RT_OK, "fill");
    }
    size_t nb = (size_t)300 * 13 * 11 * sizeof(float);
    CHECK(memcmp(v[0].v, v[1].v, nb) == 0, "threads 1 vs 2");
    CHECK(memcmp(v[0].v, v[2].v, nb) == 0, "threads 1 vs 4");
    int bad = 0, nonzero = 0;
    for (int k = 0; k < 11; k += 5)
        for (int j = 0; j < 13; j += 3)
            for (int i = 0; i < 300; i += 7) {
                double x = -1 + 2 * (i + 0.5) / 300, y = -1.2 + 2 * (j + 0.5) / 13,
                       z = -0.9 + 2 * (k + 0.5) / 11;
                double d = density_eval(&sph, x, y, z) * noise_turbulence3(&perm_a, 6, x, y, z);
                float want = (float)dmf_gain(0.7, dmf_bias(0.3, d));
                bad += *volume_at(&v[0], i, j, k) != want;
                nonzero += want > 0;
            }
    CHECK(bad == 0 && nonzero > 50, "volume values: %d bad, %d non-zero", bad, nonzero);
    volatile sig_atomic_t stop = 1;
    rt_run cancel = {2, &stop, 0};
    CHECK(field_sample_volume(field_prog_fn, p, &v[0], &cancel, &e) == RT_ECANCEL, "cancel");
    for (int t = 0; t < 3; t++)
        volume_free(&v[t]);
    field_prog_free(p);
}

/* The grey of field_preview at pixel (i, j) of a w x h preview of f. */
static int preview(field *f, int w, int h, image *im)
{
    rt_error e;
    field_prog *p = field_compile(f, &e);
    field_unref(f);
    int ok = p && image_init(im, w, h, &e) == RT_OK && field_preview(p, im, &e) == RT_OK;
    field_prog_free(p);
    return ok;
}

/* field_preview against hand values: pixel centres of [-1, 1]^2 (y up),
 * scaled from the smallest to the largest finite value. */
static void test_preview(void)
{
    image im;
    /* x + 4y on 4 x 2: x = -0.75 -0.25 0.25 0.75, y = 0.5 (top row), -0.5;
     * values 1.25 .. 2.75 and -2.75 .. -1.25, grey (v + 2.75) / 5.5 */
    CHECK(preview(B(FIELD_ADD, X_(), B(FIELD_MUL, K(4), Y_())), 4, 2, &im), "x + 4y");
    const double want[8] = {4 / 5.5, 4.5 / 5.5, 5 / 5.5, 1, 0, 0.5 / 5.5, 1 / 5.5, 1.5 / 5.5};
    int bad = 0;
    for (int i = 0; i < 8; i++)
        bad += fabs(im.px[4 * i] - want[i]) > 1e-6 || im.px[4 * i + 1] != im.px[4 * i] ||
               im.px[4 * i + 2] != im.px[4 * i] || im.px[4 * i + 3] != 1;
    CHECK(bad == 0, "x + 4y: %d pixels off (first %g, want %g)", bad, im.px[0], want[0]);
    image_free(&im);
    /* a row wider than one block (RT_BLOCK = 256): x gives grey i / (w - 1) */
    CHECK(preview(X_(), 600, 1, &im), "x on 600 x 1");
    bad = 0;
    for (int i = 0; i < 600; i++)
        bad += fabs(im.px[4 * i] - i / 599.0) > 1e-6;
    CHECK(bad == 0, "x on 600 x 1: %d pixels off", bad);
    image_free(&im);
    /* log x: NaN for x < 0 is 0, log 0.25 is 0, log 0.75 is 1 */
    CHECK(preview(U(FIELD_LOG, X_()), 4, 1, &im), "log x");
    CHECK(im.px[0] == 0 && im.px[4] == 0 && im.px[8] == 0 && im.px[12] == 1, "log x: %g %g %g %g", im.px[0],
          im.px[4], im.px[8], im.px[12]);
    image_free(&im);
    /* a constant slice is black */
    CHECK(preview(K(3), 2, 2, &im), "constant");
    CHECK(im.px[0] == 0 && im.px[12] == 0 && im.px[15] == 1, "constant: black, opaque");
    image_free(&im);
}

int main(void)
{
    test_preview();
    test_expressions();
    test_folding_and_print();
    test_depth();
    test_volume();
    return check_done("test_field");
}
