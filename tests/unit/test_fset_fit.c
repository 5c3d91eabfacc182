/* test_fset_fit.c — fset_chaos_fit's window against its definition, and
 * tails.h against sorting.
 *
 * The window is defined (fset.h) as four passes of the chaos game into a
 * 256×256 histogram, each narrowed to the occupied cells plus one cell on
 * each side; fset.c takes the passes from one game's extremes when every
 * point lies in every window and runs them as defined otherwise. The
 * reference here is that definition written out again, on fset_chaos (the
 * game that renders), and the two windows must be equal bit for bit: on
 * random and periodic orders, weighted maps, walks, a point, a line, rare
 * far excursions (points outside the first window), overflow and NaN. */
#include <string.h>

#include "check.h"
#include "fset.h"
#include "rng.h"
#include "tails.h"

/* The definition (fset.h), independent of fset.c's passes. */
static rt_code window_by_definition(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, int w, int h,
                                    double lo[2], double hi[2], rt_error *e)
{
    double R = 0;
    int contractive = 1;
    for (int s = 0; s < fs->n; s++)
        for (int m = 0; m < fs->sets[s].n; m++) {
            const affine *a = &fs->sets[s].maps[m];
            double c = affine_contraction(a);
            if (!(c < 0.999))
                contractive = 0;
            else
                R = fmax(R, hypot(a->t[0], a->t[1]) / (1 - c));
        }
    R = contractive ? R + hypot(opts->start[0], opts->start[1]) + 1e-9 : 1e6;
    lo[0] = lo[1] = -R;
    hi[0] = hi[1] = R;
    fset_chaos_opts fo = *opts;
    fo.points = opts->points < 50000 ? opts->points : 50000;
    for (int pass = 0; pass < 4; pass++) {
        hist2 hs;
        rt_code c = hist2_init(&hs, 256, 256, lo, hi, 0, e);
        if (c)
            return c;
        if ((c = fset_chaos(fs, o, &fo, &hs, NULL, e))) {
            hist2_free(&hs);
            return c;
        }
        int x0 = 256, x1 = -1, y0 = 256, y1 = -1;
        for (int b = 0; b < 256 * 256; b++)
            if (hs.count[b]) {
                int i = b % 256, j = b / 256;
                x0 = i < x0 ? i : x0;
                x1 = i > x1 ? i : x1;
                y0 = j < y0 ? j : y0;
                y1 = j > y1 ? j : y1;
            }
        hist2_free(&hs);
        if (x1 < 0)
            return rt_fail(e, RT_EINVAL, "no point");
        double bx = (hi[0] - lo[0]) / 256, by = (hi[1] - lo[1]) / 256;
        double nlo0 = lo[0] + (x0 - 1) * bx, nhi0 = lo[0] + (x1 + 2) * bx;
        double nhi1 = hi[1] - (y0 - 1) * by, nlo1 = hi[1] - (y1 + 2) * by;
        lo[0] = nlo0, hi[0] = nhi0, lo[1] = nlo1, hi[1] = nhi1;
    }
    fset_fit_aspect(lo, hi, w, h, 0.03);
    return RT_OK;
}

static int same_bits(const double *a, const double *b, int n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

/* fset_chaos_fit against the definition: the same window bit for bit, or
 * both an error (the same code). */
static void check_window(const char *what, const fset *fs, const fset_order *o, const fset_chaos_opts *co, int w,
                         int h)
{
    double lo[2], hi[2], rlo[2], rhi[2];
    rt_error e = {0}, re = {0};
    rt_code c = fset_chaos_fit(fs, o, co, w, h, lo, hi, NULL, &e);
    rt_code rc = window_by_definition(fs, o, co, w, h, rlo, rhi, &re);
    CHECK(c == rc, "%s: code %d (%s), by definition %d (%s)", what, c, e.msg, rc, re.msg);
    if (c || rc)
        return;
    CHECK(same_bits(lo, rlo, 2) && same_bits(hi, rhi, 2),
          "%s: [%.17g, %.17g]x[%.17g, %.17g], by definition [%.17g, %.17g]x[%.17g, %.17g]", what, lo[0], hi[0],
          lo[1], hi[1], rlo[0], rhi[0], rlo[1], rhi[1]);
}

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

static double unit(uint64_t *s)
{
    return (double)lcg(s) / 9007199254740992.0;
}

/* tails.h on a stream: the k-th smallest and largest against a sort. */
static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void check_tails(const char *what, const double *v, size_t n, size_t k)
{
    double hl[64], hh[64];
    for (size_t i = 0; i < k; i++) {
        tails_heap_offer(hl, i, k, v[i]);
        tails_heap_offer(hh, i, k, -v[i]);
    }
    double lo = hl[0], hi = -hh[0];
    for (size_t i = k; i < n; i++)
        tails_offer(hl, hh, k, v[i], &lo, &hi);
    double *s = malloc(n * sizeof *s);
    memcpy(s, v, n * sizeof *s);
    qsort(s, n, sizeof *s, cmp);
    CHECK(lo == s[k - 1] && hi == s[n - k] && lo == hl[0] && hi == -hh[0],
          "%s (n %zu, k %zu): %.17g %.17g, sorted %.17g %.17g", what, n, k, lo, hi, s[k - 1], s[n - k]);
    free(s);
}

/* fset_chaos_box against its definition (fset.h): the orbit of the game
 * (seed rng_hash3(seed, 2^63, 0, 0), chunk 0, burn-in, plot period) written
 * out again, each axis sorted, the 0.1 % and 99.9 % quantiles widened by 5 %.
 * The same box bit for bit. */
static void check_box(const char *what, const fset *fs, const fset_order *o, const fset_chaos_opts *co)
{
    enum { N = FSET_BOX_POINTS };
    double *pts = malloc(3 * N * sizeof *pts), *ax = malloc(N * sizeof *ax), cum[4 * FSET_MAX_MAPS];
    for (int s = 0; s < fs->n; s++)
        fset_cumulative(fs->sets[s].p, fs->sets[s].n, cum + s * FSET_MAX_MAPS);
    uint64_t period = co->plot_period && o->kind != FSET_RANDOM ? (uint64_t)o->len : 1, k = 0;
    uint64_t k0 = (co->burn + period - 1) / period * period; /* whole periods, at least the burn-in */
    rng r;
    rng_init(&r, rng_hash3(co->seed, 1ull << 63, 0, 0), 0);
    double p[3] = {co->start[0], co->start[1], co->start[2]};
    for (size_t done = 0; done < N;) {
        int s = fset_order_at(o, fs->n, k);
        int m = fset_pick(cum + s * FSET_MAX_MAPS, fs->sets[s].n, rng_uniform(&r));
        double q[3];
        affine_apply(&fs->sets[s].maps[m], p, q);
        memcpy(p, q, sizeof q);
        if (++k > k0 && k % period == 0)
            memcpy(pts + 3 * done++, p, sizeof p);
    }
    double lo[3], hi[3], rlo[3], rhi[3];
    for (int a = 0; a < 3; a++) {
        for (size_t i = 0; i < N; i++)
            ax[i] = pts[3 * i + (size_t)a];
        qsort(ax, N, sizeof *ax, cmp);
        double l = ax[N / 1000], u = ax[N - 1 - N / 1000];
        rlo[a] = l - 0.05 * (u - l);
        rhi[a] = u + 0.05 * (u - l);
    }
    rt_error e = {0};
    CHECK(fset_chaos_box(fs, o, co, lo, hi, &e) == RT_OK, "%s: %s", what, e.msg);
    CHECK(same_bits(lo, rlo, 3) && same_bits(hi, rhi, 3), "%s: x %.17g..%.17g y %.17g..%.17g z %.17g..%.17g, sorted x %.17g..%.17g",
          what, lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], rlo[0], rhi[0]);
    free(pts);
    free(ax);
}

int main(void)
{
    fset_chaos_opts co = {FSET_ORBIT, 20000, 7, 20, 0, 1, {0, 0, 0}};

    /* tests/shard/fit_fset.frac's 2-D set: halves and thirds, random order. */
    affine half[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                      affine_from_2d(0.5, 0, 0, 0.5, 0.25, 0.5)};
    affine third[4] = {affine_from_2d(1.0 / 3, 0, 0, 1.0 / 3, 0, 0), affine_from_2d(1.0 / 3, 0, 0, 1.0 / 3, 2.0 / 3, 0),
                       affine_from_2d(1.0 / 3, 0, 0, 1.0 / 3, 1.0 / 3, 1.0 / 3),
                       affine_from_2d(1.0 / 3, 0, 0, 1.0 / 3, 1.0 / 3, 2.0 / 3)};
    double p4[4] = {0.7, 0.1, 0.1, 0.1};
    fset_ifs sets[2] = {{3, half, NULL}, {4, third, NULL}};
    fset fs = {2, sets};
    fset_order rnd = {FSET_RANDOM, 0, NULL, NULL, 3};
    check_window("half and third, random order", &fs, &rnd, &co, 32, 32);
    check_window("half and third, 3:1", &fs, &rnd, &co, 300, 100);
    double po[2] = {0.9, 0.1};
    fset_order rnd9 = {FSET_RANDOM, 0, NULL, po, 3};
    sets[1].p = p4;
    check_window("weighted order and maps", &fs, &rnd9, &co, 64, 48);
    int seq[3] = {0, 1, 1};
    fset_order per = {FSET_PERIODIC, 3, seq, NULL, 0};
    co.plot_period = 1;
    check_window("periodic order, plotted per period", &fs, &per, &co, 50, 50);
    co.plot_period = 0;
    fset_order sq = {FSET_SEQUENCE, 3, seq, NULL, 0};
    check_window("sequence order", &fs, &sq, &co, 50, 50);
    co.points = 100000; /* more than the pre-pass's 50,000 */
    check_window("100,000 points", &fs, &rnd, &co, 50, 50);
    co.points = 1;
    check_window("one point", &fs, &rnd, &co, 50, 50);
    co.points = 20000;
    fset_chaos_opts wo = {FSET_WALK, 30000, 11, 0, 0, 9, {0.3, -0.2, 0}};
    check_window("walks (several chunks)", &fs, &rnd, &wo, 40, 30);
    sets[1].p = NULL;

    /* Degenerate: every map sends the plane to one point; to a line. */
    affine pt[2] = {affine_from_2d(0, 0, 0, 0, 0.3, 0.7), affine_from_2d(0, 0, 0, 0, 0.3, 0.7)};
    fset_ifs ps = {2, pt, NULL};
    fset fpt = {1, &ps};
    check_window("a point", &fpt, &rnd, &co, 20, 20);
    affine line[2] = {affine_from_2d(0.5, 0, 0, 0, 0, -2), affine_from_2d(0.5, 0, 0, 0, 0.5, -2)};
    fset_ifs ls = {2, line, NULL};
    fset fl = {1, &ls};
    check_window("a line", &fl, &rnd, &co, 20, 20);

    /* Rare far excursions: a map that is not contractive (R = 1e6) jumps by
     * 3e6, beyond the first window, once in ~1000 steps; the next steps
     * halve the way back through the later windows. */
    affine far[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0.25), affine_from_2d(1, 0, 0, 1, 3e6, 0)};
    double pfar[2] = {0.999, 0.001};
    fset_ifs fa = {2, far, pfar};
    fset ffar = {1, &fa};
    check_window("rare far excursions", &ffar, &rnd, &co, 32, 32);
    /* Excursions within the first window: ±1e6, a jump of 2e5 in x and y. */
    far[1] = affine_from_2d(1, 0, 0, 1, 2e5, -2e5);
    pfar[0] = 0.99, pfar[1] = 0.01;
    check_window("excursions in the first window", &ffar, &rnd, &co, 32, 32);
    /* Overflow: x' = 1e300 x + 1 reaches infinity, and x - y then gives NaN. */
    affine ov[2] = {affine_from_2d(1e300, 0, 0, 1e300, 1, 2), affine_from_2d(1, -1, 1, -1, 0, 0)};
    double pov[2] = {0.98, 0.02};
    fset_ifs os = {2, ov, pov};
    fset fo = {1, &os};
    check_window("overflow and NaN", &fo, &rnd, &co, 32, 32);
    /* Mostly contractive, a NaN now and then: the halving map of `far`
     * beside the overflow maps, rarely. */
    affine mix[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0.25), ov[0], ov[1]};
    double pmix[3] = {0.9, 0.05, 0.05};
    fset_ifs ms = {3, mix, pmix};
    fset fmix = {1, &ms};
    check_window("rare overflow among contractions", &fmix, &rnd, &co, 32, 32);

    /* A NaN in x beside a finite y: walks of one step from (10, -10) by
     * x' = 1e308 x + 1e308 y (+inf plus -inf), y' = 0.9, or by a halving.
     * The histogram drops (NaN, 0.9); its y must not widen the window. */
    affine nan1[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(1e308, 1e308, 0, 0, 0, 0.9)};
    fset_ifs ns = {2, nan1, NULL};
    fset fnan = {1, &ns};
    fset_chaos_opts no = {FSET_WALK, 5000, 5, 0, 0, 1, {10, -10, 0}};
    check_window("NaN in x only", &fnan, &rnd, &no, 32, 32);

    /* Random contractive sets: 1 to 3 sets of 1 to 5 maps, random orders. */
    uint64_t s = 42;
    for (int t = 0; t < 8; t++) {
        affine maps[3][5];
        fset_ifs rs[3];
        int nsets = 1 + (int)(lcg(&s) % 3);
        for (int i = 0; i < nsets; i++) {
            int n = 1 + (int)(lcg(&s) % 5);
            for (int m = 0; m < n; m++) {
                double r = 0.2 + 0.6 * unit(&s), a = 6.283185307179586 * unit(&s);
                maps[i][m] = affine_from_2d(r * cos(a), -r * sin(a), r * sin(a), r * cos(a) * (unit(&s) < 0.5 ? 1 : -1),
                                            4 * unit(&s) - 2, 4 * unit(&s) - 2);
            }
            rs[i] = (fset_ifs){n, maps[i], NULL};
        }
        fset rf = {nsets, rs};
        fset_chaos_opts ro = co;
        ro.seed = lcg(&s);
        ro.points = 1000 + lcg(&s) % 60000;
        char what[48];
        snprintf(what, sizeof what, "random set %d", t);
        check_window(what, &rf, &rnd, &ro, 16 + (int)(lcg(&s) % 100), 16 + (int)(lcg(&s) % 100));
    }

    /* ---- fset_chaos_box: a gasket and a twisted set, random and periodic. */
    affine g3[4];
    for (int i = 0; i < 4; i++) {
        double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5}, t3[3] = {i == 1 ? 0.5 : 0, i == 2 ? 0.5 : 0, i == 3 ? 0.5 : 0};
        g3[i] = affine_from_3d(m9, t3);
    }
    double m9t[9] = {0.3, -0.4, 0.1, 0.4, 0.3, 0, 0, 0.1, -0.5}, t3t[3] = {1, -2, 0.25};
    affine tw[2] = {affine_from_3d(m9t, t3t), g3[1]};
    double ptw[2] = {0.8, 0.2};
    fset_ifs s3[2] = {{4, g3, NULL}, {2, tw, ptw}};
    fset f3 = {2, s3};
    fset_chaos_opts bo = {FSET_ORBIT, 100000, 5, 20, 0, 1, {0.1, 0.2, 0.3}};
    check_box("3-D, random order", &f3, &rnd, &bo);
    bo.plot_period = 1;
    check_box("3-D, periodic order, plotted per period", &f3, &per, &bo);
    bo.seed = 77, bo.burn = 0;
    check_box("3-D, sequence order, no burn-in", &f3, &sq, &bo);

    /* ---- tails.h against a sort: random values, many equal ones, n = k. */
    double v[5000];
    for (size_t i = 0; i < 5000; i++)
        v[i] = unit(&s) - 0.5;
    check_tails("uniform", v, 5000, 6);
    check_tails("uniform, k 1", v, 5000, 1);
    check_tails("n = k", v, 17, 17);
    for (size_t i = 0; i < 5000; i++)
        v[i] = (double)(lcg(&s) % 7);
    check_tails("seven values", v, 5000, 17);
    for (size_t i = 0; i < 5000; i++)
        v[i] = (double)i; /* increasing: every value enters the largest tail */
    check_tails("increasing", v, 5000, 17);
    for (size_t i = 0; i < 5000; i++)
        v[i] = -(double)i;
    check_tails("decreasing", v, 5000, 17);

    return check_done("test_fset_fit");
}
