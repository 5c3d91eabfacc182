/* test_hist_width.c — 32-bit and 64-bit histogram counts (hist.h).
 *
 * A histogram made for fewer than 2^32 hits holds uint32 counts, otherwise
 * uint64. hist2_init always makes the wide one, so at small sizes the same
 * render runs through both paths: every writer (chaos_hist2 with and without
 * colour, 1 to 3 threads; fset_chaos; superifs_render) and reader (the tone
 * map, chaos_measure2) must give the same counts and the same pixels. The
 * fixed facts: the counts sum to the points inside (chaos_stats), and a
 * histogram of 32-bit counts refuses a call of 2^32 points or more, and a
 * shard hands the same numbers to its part from either width (a fake sharder
 * records them and a merge of them gives the single run's counts). */
#include <string.h>

#include "check.h"
#include "fern.h"
#include "chaos.h"
#include "fset.h"
#include "hist.h"
#include "image.h"
#include "par.h"
#include "superifs.h"
#include "tonemap.h"

#define W 48
#define H 40

/* The width choice: uint32 below 2^32 hits, uint64 from there and for hist2_init. */
static void test_choice(void)
{
    CHECK(hist2_narrow(0) && hist2_narrow(1000000) && hist2_narrow(UINT32_MAX), "below 2^32: narrow");
    CHECK(!hist2_narrow((uint64_t)UINT32_MAX + 1) && !hist2_narrow(UINT64_MAX), "2^32 and above: wide");
    rt_error e;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    hist2 a, b, c;
    CHECK(hist2_init_for(&a, 4, 3, lo, hi, 0, 1000000, &e) == RT_OK, "narrow: %s", e.msg);
    CHECK(a.count32 && !a.count, "an ordinary render's million points: 32-bit counts");
    CHECK(hist2_init_for(&b, 4, 3, lo, hi, 1, (uint64_t)1 << 32, &e) == RT_OK, "wide: %s", e.msg);
    CHECK(b.count && !b.count32 && b.csum, "2^32 points: 64-bit counts (and colour sums)");
    CHECK(hist2_init(&c, 4, 3, lo, hi, 0, &e) == RT_OK && c.count && !c.count32, "hist2_init: 64-bit");
    int zero = 1;
    for (size_t i = 0; i < 12; i++)
        zero = zero && a.count32[i] == 0 && b.count[i] == 0;
    CHECK(zero, "fresh counts are zero");
    hist2_add(&a, 5, 3);
    hist2_add(&b, 5, (uint64_t)1 << 40);
    CHECK(hist2_get(&a, 5) == 3 && a.count32[5] == 3, "add and get, 32-bit");
    CHECK(hist2_get(&b, 5) == (uint64_t)1 << 40, "add and get, 64-bit");
    hist2_free(&a);
    hist2_free(&b);
    hist2_free(&c);
    CHECK(!a.count32 && !a.count, "free clears both");
}

static int same_counts(const hist2 *a, const hist2 *b, uint64_t *sum)
{
    int bad = 0;
    *sum = 0;
    for (size_t i = 0; i < (size_t)a->w * (size_t)a->h; i++) {
        bad += hist2_get(a, i) != hist2_get(b, i);
        *sum += hist2_get(a, i);
    }
    return bad;
}

static int same_pixels(const image *a, const image *b)
{
    return memcmp(a->px, b->px, sizeof *a->px * 4 * (size_t)a->w * (size_t)a->h) == 0;
}

/* tone map (ramp, and the colour mean where there are sums) and measure both */
static void check_readers(const hist2 *n, const hist2 *w, int k, uint64_t total, const char *what)
{
    rt_error e;
    image a, b;
    CHECK(image_init(&a, n->w / k, n->h / k, &e) == RT_OK && image_init(&b, n->w / k, n->h / k, &e) == RT_OK,
          "image");
    for (int mode = 0; mode < 2; mode++) {
        tonemap_opts t;
        memset(&t, 0, sizeof t);
        t.bg[3] = 1;
        t.colour = mode && n->csum ? TONEMAP_MEAN : TONEMAP_RAMP;
        t.curve = mode ? TONEMAP_LINEAR : TONEMAP_LOG;
        CHECK(tonemap_apply(n, &t, &a, &e) == RT_OK && tonemap_apply(w, &t, &b, &e) == RT_OK, "tone map");
        CHECK(same_pixels(&a, &b), "%s: tone map %d, k = %d: the same pixels", what, mode, k);
    }
    if (k == 1) {
        CHECK(chaos_measure2(n, CHAOS_NORM_MAX, total, &a, &e) == RT_OK &&
                  chaos_measure2(w, CHAOS_NORM_MAX, total, &b, &e) == RT_OK,
              "measure");
        CHECK(same_pixels(&a, &b), "%s: the same measure", what);
    }
    image_free(&a);
    image_free(&b);
}

/* The fern at 48×40 and supersampled 96×80: both widths, every colour mode, 1–3 threads. */
static void test_chaos_widths(void)
{
    rt_error e;
    ifs f;
    fern_build(&f);
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 300000;
    o.seed = 9;
    o.chunk = 1 << 14;
    double lo[2] = {-2.5, -0.2}, hi[2] = {2.0, 10.2}; /* a little of the fern falls outside */
    for (int k = 1; k <= 2; k++)
        for (int colour = 0; colour < 3; colour++)
            for (int t = 1; t <= 3; t++) {
                rt_run run = {t, NULL, 0};
                o.colour = colour == 0 ? CHAOS_COLOUR_NONE : colour == 1 ? CHAOS_COLOUR_LAST : CHAOS_COLOUR_BLEND;
                hist2 n, w;
                chaos_stats sn, sw;
                CHECK(hist2_init_for(&n, W * k, H * k, lo, hi, colour != 0, o.points, &e) == RT_OK, "narrow");
                CHECK(hist2_init(&w, W * k, H * k, lo, hi, colour != 0, &e) == RT_OK, "wide");
                CHECK(n.count32 && w.count, "the two widths");
                CHECK(chaos_hist2(&s, &o, &n, &sn, &run, &e) == RT_OK, "chaos narrow: %s", e.msg);
                CHECK(chaos_hist2(&s, &o, &w, &sw, &run, &e) == RT_OK, "chaos wide: %s", e.msg);
                uint64_t sum;
                int bad = same_counts(&n, &w, &sum);
                CHECK(bad == 0, "k %d colour %d threads %d: %d bins differ", k, colour, t, bad);
                CHECK(sum == sn.inside && sn.inside == sw.inside && sn.inside < o.points && sn.inside > o.points / 2,
                      "k %d colour %d threads %d: counts sum to the %llu inside, not %llu", k, colour, t,
                      (unsigned long long)sn.inside, (unsigned long long)sum);
                if (colour)
                    CHECK(memcmp(n.csum, w.csum, sizeof *n.csum * 3 * (size_t)n.w * (size_t)n.h) == 0,
                          "k %d colour %d threads %d: the same colour sums", k, colour, t);
                check_readers(&n, &w, k, sn.plotted, "chaos");
                hist2_free(&n);
                hist2_free(&w);
            }
    /* a second call adds to the counts (the caller keeps the total below 2^32) */
    hist2 n;
    o.colour = CHAOS_COLOUR_NONE;
    CHECK(hist2_init_for(&n, W, H, lo, hi, 0, 2 * o.points, &e) == RT_OK, "narrow");
    rt_run r2 = {2, NULL, 0};
    chaos_stats st;
    uint64_t total = 0, sum = 0;
    for (int i = 0; i < 2; i++) {
        CHECK(chaos_hist2(&s, &o, &n, &st, &r2, &e) == RT_OK, "chaos: %s", e.msg);
        total += st.inside;
    }
    for (size_t i = 0; i < W * H; i++)
        sum += n.count32[i];
    CHECK(sum == total, "two calls add: %llu vs %llu", (unsigned long long)sum, (unsigned long long)total);
    o.points = (uint64_t)1 << 32;
    CHECK(chaos_hist2(&s, &o, &n, NULL, &r2, &e) == RT_EINVAL, "2^32 points into 32-bit counts: refused");
    hist2_free(&n);
    ifs_free(&f);
}

/* fset_chaos (orbit and walk) and superifs_render through both widths. */
static void test_fset_widths(void)
{
    rt_error e;
    /* two Sierpinski-like IFS of ratios 0.45 and 0.5, unequal probabilities */
    affine m[2][3];
    double pr[2][3] = {{0.5, 0.25, 0.25}, {0.25, 0.25, 0.5}};
    double tri[3][2] = {{0, 0}, {0.5, 0}, {0.25, 0.5}};
    fset_ifs sets[2];
    for (int k = 0; k < 2; k++) {
        double r = k ? 0.5 : 0.45;
        for (int q = 0; q < 3; q++)
            m[k][q] = affine_from_2d(r, 0, 0, r, tri[q][0], tri[q][1]);
        sets[k] = (fset_ifs){3, m[k], pr[k]};
    }
    fset fs = {2, sets};
    fset_order ord;
    memset(&ord, 0, sizeof ord);
    ord.kind = FSET_RANDOM;
    ord.seed = 3;
    double lo[2] = {0, 0}, hi[2] = {0.9, 0.9};
    for (int mode = 0; mode < 2; mode++)
        for (int t = 1; t <= 2; t++) {
            fset_chaos_opts co;
            memset(&co, 0, sizeof co);
            co.mode = mode ? FSET_WALK : FSET_ORBIT;
            co.points = 100000;
            co.seed = 11;
            co.burn = 20;
            co.depth = 20;
            rt_run run = {t, NULL, 0};
            hist2 n, w;
            CHECK(hist2_init_for(&n, W, H, lo, hi, 0, co.points, &e) == RT_OK && n.count32, "narrow");
            CHECK(hist2_init(&w, W, H, lo, hi, 0, &e) == RT_OK, "wide");
            CHECK(fset_chaos(&fs, &ord, &co, &n, &run, &e) == RT_OK, "fset narrow: %s", e.msg);
            CHECK(fset_chaos(&fs, &ord, &co, &w, &run, &e) == RT_OK, "fset wide: %s", e.msg);
            uint64_t sum;
            int bad = same_counts(&n, &w, &sum);
            CHECK(bad == 0 && sum > co.points / 2 && sum <= co.points, "fset mode %d threads %d: %d bins differ, %llu hits",
                  mode, t, bad, (unsigned long long)sum);
            check_readers(&n, &w, 1, co.points, "fset");
            co.points = (uint64_t)1 << 32;
            CHECK(fset_chaos(&fs, &ord, &co, &n, &run, &e) == RT_EINVAL, "2^32 points into 32-bit counts: refused");
            hist2_free(&n);
            hist2_free(&w);
        }
    superifs_opts so;
    memset(&so, 0, sizeof so);
    so.V = 2;
    so.points = 5000;
    so.steps = 12;
    so.seed = 5;
    superifs_state st;
    CHECK(superifs_run(&fs, NULL, &so, &st, NULL, &e) == RT_OK, "superifs: %s", e.msg);
    hist2 n, w;
    CHECK(hist2_init_for(&n, W, H, lo, hi, 0, so.points, &e) == RT_OK && n.count32, "narrow");
    CHECK(hist2_init(&w, W, H, lo, hi, 0, &e) == RT_OK, "wide");
    CHECK(superifs_render(&st, 1, &n, &e) == RT_OK && superifs_render(&st, 1, &w, &e) == RT_OK, "render");
    uint64_t sum;
    int bad = same_counts(&n, &w, &sum);
    CHECK(bad == 0 && sum > 0 && sum <= so.points, "superifs: %d bins differ, %llu hits", bad, (unsigned long long)sum);
    check_readers(&n, &w, 1, so.points, "superifs");
    hist2_free(&n);
    hist2_free(&w);
    superifs_free(&st);
}

/* A sharder that records a shard's sums as numbers and adds them back in a
 * merge, whatever the width (unit 8: uint64, unit 4: uint32). */
typedef struct rec_sharder {
    rt_sharder rt;
    int mode, sec;
    size_t n[4], unit[4];
    uint64_t *v[4];
} rec_sharder;

static int rs_begin(rt_sharder *s, const char *kind, size_t nchunks, size_t *lo, size_t *hi)
{
    rec_sharder *r = (rec_sharder *)s;
    (void)kind;
    *lo = 0;
    *hi = nchunks;
    r->sec = 0;
    return r->mode;
}

static rt_code rs_section(rt_sharder *s, par_part_op op, void *buf, size_t total, size_t unit, par_combine_fn fn,
                          void *ctx, rt_error *e)
{
    rec_sharder *r = (rec_sharder *)s;
    (void)fn, (void)ctx, (void)e;
    int k = r->sec++;
    if (op != PAR_OP_SUM || k >= 4 || (unit != 4 && unit != 8))
        return RT_EINVAL;
    size_t n = total / unit;
    if (r->mode == PAR_SHARD) {
        r->n[k] = n;
        r->unit[k] = unit;
        r->v[k] = calloc(n ? n : 1, sizeof *r->v[k]);
        for (size_t i = 0; i < n; i++)
            r->v[k][i] = unit == 4 ? ((uint32_t *)buf)[i] : ((uint64_t *)buf)[i];
    } else {
        if (n != r->n[k])
            return RT_EINVAL;
        for (size_t i = 0; i < n; i++) {
            if (unit == 4)
                ((uint32_t *)buf)[i] += (uint32_t)r->v[k][i];
            else
                ((uint64_t *)buf)[i] += r->v[k][i];
        }
    }
    return RT_OK;
}

static void test_shard_widths(void)
{
    rt_error e;
    ifs f;
    affine tri[3] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0),
                     affine_from_2d(0.5, 0, 0, 0.5, 0.25, 0.5)};
    CHECK(ifs_build(&f, tri, 3, NULL, 0, &e) == RT_OK, "ifs");
    chaos_sys s = {&f, NULL};
    chaos_opts o = {0};
    o.points = 2000000; /* 123 chunks: both workers get some */
    o.seed = 4;
    o.chunk = 1 << 14;
    double lo[2] = {0, 0}, hi[2] = {0.9, 0.9};
    rt_run r2 = {2, NULL, 0};
    hist2 full;
    chaos_stats st;
    CHECK(hist2_init(&full, W, H, lo, hi, 0, &e) == RT_OK, "hist");
    CHECK(chaos_hist2(&s, &o, &full, &st, &r2, &e) == RT_OK, "full run: %s", e.msg);
    uint64_t shard_vals[2][W * H];
    for (int narrow = 0; narrow < 2; narrow++) {
        rec_sharder rs;
        memset(&rs, 0, sizeof rs);
        rs.rt.begin = rs_begin;
        rs.rt.section = rs_section;
        rt_sharder *old = par_set_sharder(&rs.rt);
        hist2 a, m;
        rs.mode = PAR_SHARD;
        CHECK(hist2_init_for(&a, W, H, lo, hi, 0, narrow ? o.points : UINT64_MAX, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s, &o, &a, NULL, &r2, &e) == RT_OK, "shard: %s", e.msg);
        CHECK(rs.sec == 2 && rs.n[0] == W * H && rs.unit[0] == (narrow ? 4u : 8u) && rs.n[1] == 2 && rs.unit[1] == 8,
              "narrow %d: sections of %zu (unit %zu) and %zu counts", narrow, rs.n[0], rs.unit[0], rs.n[1]);
        for (size_t i = 0; rs.v[0] && i < W * H; i++)
            shard_vals[narrow][i] = rs.v[0][i];
        rs.mode = PAR_MERGE;
        chaos_stats sm;
        CHECK(hist2_init_for(&m, W, H, lo, hi, 0, narrow ? o.points : UINT64_MAX, &e) == RT_OK, "hist");
        CHECK(chaos_hist2(&s, &o, &m, &sm, &r2, &e) == RT_OK, "merge: %s", e.msg);
        uint64_t sum;
        CHECK(same_counts(&m, &full, &sum) == 0 && sum == st.inside, "narrow %d: the merge has the single run's counts",
              narrow);
        CHECK(sm.plotted == st.plotted && sm.inside == st.inside, "narrow %d: the merge's stats", narrow);
        par_set_sharder(old);
        for (int k = 0; k < 4; k++)
            free(rs.v[k]);
        hist2_free(&a);
        hist2_free(&m);
    }
    CHECK(memcmp(shard_vals[0], shard_vals[1], sizeof shard_vals[0]) == 0, "a shard's sums: the same numbers from either width");
    hist2_free(&full);
    ifs_free(&f);
}

int main(void)
{
    test_choice();
    test_chaos_widths();
    test_fset_widths();
    test_shard_widths();
    return check_done("test_hist_width");
}
