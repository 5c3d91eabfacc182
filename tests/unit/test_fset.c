/* test_fset.c — function sets, orders, the composition parser and the chaos
 * game with an order (seed 003 §3). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
#include "fset.h"

static const double R3 = 1.7320508075688772;

static int parse_is(const char *text, int nsets, const int *want, int n)
{
    int *seq, len;
    size_t off;
    rt_error e;
    if (fset_order_parse(text, nsets, &seq, &len, &off, &e) != RT_OK) {
        fprintf(stderr, "parse '%s': %s\n", text, e.msg);
        return 0;
    }
    int ok = len == n && memcmp(seq, want, (size_t)n * sizeof *want) == 0;
    rt_free(seq);
    return ok;
}

static int parse_err(const char *text, int nsets, const char *msg, size_t offset)
{
    int *seq, len;
    size_t off = 999;
    rt_error e = {0};
    rt_code c = fset_order_parse(text, nsets, &seq, &len, &off, &e);
    if (c != RT_EINVAL || strcmp(e.msg, msg) != 0 || off != offset) {
        fprintf(stderr, "parse '%s': code %d offset %zu msg '%s'\n", text, c, off, e.msg);
        return 0;
    }
    return seq == NULL;
}

static long total(const hist2 *h)
{
    long s = 0;
    for (int i = 0; i < h->w * h->h; i++)
        s += (long)h->count[i];
    return s;
}

int main(void)
{
    rt_error e;
    /* ---- composition notation: rightmost applied first ---- */
    CHECK(parse_is("W2 ∘ W5 ∘ W1 ∘ W2", 0, (int[]){1, 0, 4, 1}, 4), "basic ∘");
    CHECK(parse_is("W_2 o W_5*W1", 6, (int[]){0, 4, 1}, 3), "o and * and W_n");
    CHECK(parse_is("  W3  ", 6, (int[]){2}, 1), "single set");
    /* Seed 003 Table 3b b., as printed (with (K_0)). */
    CHECK(parse_is("W_2 ∘ W_3 ∘ W_5 ∘ W_4 ∘ W_6 ∘ W_1 ∘ W_2 ∘ W_3 ∘ W_5 ∘ W_4 ∘ W_6 ∘ W_1(K_0)", 6,
                   (int[]){0, 5, 3, 4, 2, 1, 0, 5, 3, 4, 2, 1}, 12),
          "Table 3b b");
    CHECK(parse_err("W2 ∘ X1", 0, "order: expected a set name like W3 at character 5", 5),
          "bad name (offset counts ∘ as one character)");
    CHECK(parse_err("W2 ∘ W0", 0,
                    "order: set W0 at character 5 does not exist (sets are numbered from 1)", 5),
          "W0");
    CHECK(parse_err("W1 o W7", 6,
                    "order: set W7 at character 5 does not exist (the function set has 6 sets)", 5),
          "W7 of 6");
    CHECK(parse_err("W2 W3", 0, "order: expected '∘', 'o' or '*' between sets at character 3", 3),
          "missing operator");
    CHECK(parse_err("W2 ∘", 0, "order: expected a set name like W3 at character 4", 4),
          "dangling operator");
    CHECK(parse_err("", 0, "order: empty composition (expected e.g. W2 ∘ W1)", 0), "empty");
    CHECK(parse_err("Wx", 0, "order: expected a set number after 'W' at character 1", 1), "W x");
    CHECK(parse_err("W1(K0) o W2", 0, "order: unexpected text after (K0) at character 7", 7),
          "text after K0");

    /* ---- validation ---- */
    affine half[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0)};
    double badp[2] = {1.2, -0.2}, shortp[2] = {0.5, 0.4};
    fset_ifs s1[2] = {{2, half, NULL}, {2, half, badp}};
    fset f1 = {2, s1};
    CHECK(fset_validate(&f1, &e) == RT_EINVAL &&
              strcmp(e.msg, "function set W2: probability 2 is -0.2 (expected a number >= 0)") == 0,
          "negative p: %s", e.msg);
    s1[1].p = shortp;
    CHECK(fset_validate(&f1, &e) == RT_EINVAL &&
              strcmp(e.msg, "function set W2: probabilities sum to 0.9 (expected 1)") == 0,
          "sum: %s", e.msg);
    int seqbad[2] = {0, 2};
    fset_order ob = {FSET_SEQUENCE, 2, seqbad, NULL, 0};
    CHECK(fset_order_validate(&ob, 2, &e) == RT_EINVAL &&
              strcmp(e.msg, "order step 2 names set W3 but the function set has 2 sets") == 0,
          "order: %s", e.msg);

    /* ---- orders ---- */
    int seq3[3] = {2, 0, 1};
    fset_order per = {FSET_PERIODIC, 3, seq3, NULL, 0};
    CHECK(fset_order_at(&per, 3, 0) == 2 && fset_order_at(&per, 3, 4) == 0 &&
              fset_order_at(&per, 3, 3000002) == 1,
          "periodic order");
    double pr[2] = {0.3, 0.7};
    fset_order rnd = {FSET_RANDOM, 0, NULL, pr, 77};
    int n0 = 0, N = 100000, same = 1;
    fset_order rnd2 = rnd;
    for (int k = 0; k < N; k++) {
        int s = fset_order_at(&rnd, 2, (uint64_t)k);
        n0 += s == 0;
        same &= s == fset_order_at(&rnd2, 2, (uint64_t)k);
    }
    CHECK_NEAR((double)n0 / N, 0.3, 5 * sqrt(0.21 / N), "random order frequency of W1");
    CHECK(same, "random order is a pure function of (seed, k)");

    /* ---- chaos game, periodic order ----
     * W1 = {x/2}, W2 = {x/2 + 1/2} on the x axis. W2 ∘ W1 (x) = x/4 + 1/2 has
     * the fixed point 2/3, and W1 maps it to 1/3. Plotting once per period
     * puts every point at 2/3; plotting every step splits them evenly
     * between 1/3 and 2/3. */
    affine a1 = affine_from_2d(0.5, 0, 0, 0.5, 0, 0), a2 = affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0);
    fset_ifs w12[2] = {{1, &a1, NULL}, {1, &a2, NULL}};
    fset f12 = {2, w12};
    int alt[2] = {0, 1};
    fset_order o12 = {FSET_PERIODIC, 2, alt, NULL, 0};
    hist2 h;
    CHECK(hist2_init(&h, 5, 1, (double[]){0, -0.5}, (double[]){1, 0.5}, 0, &e) == RT_OK, "hist");
    fset_chaos_opts co = {FSET_ORBIT, 200000, 5, 64, 1, 0, {0.9, 0}};
    CHECK(fset_chaos(&f12, &o12, &co, &h, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(h.count[3] == 200000 && total(&h) == 200000, "period plotting: all at 2/3 (%lu)",
          (unsigned long)h.count[3]);
    memset(h.count, 0, 5 * sizeof *h.count);
    co.plot_period = 0;
    CHECK(fset_chaos(&f12, &o12, &co, &h, NULL, &e) == RT_OK, "chaos: %s", e.msg);
    CHECK(h.count[1] + h.count[3] == 200000 && h.count[1] > 99000 && h.count[3] > 99000,
          "every-step plotting: half at 1/3, half at 2/3 (%lu %lu)", (unsigned long)h.count[1],
          (unsigned long)h.count[3]);
    hist2_free(&h);

    /* ---- walk of depth 1: the end points are f_m(x0) with probability p_m */
    affine b[2] = {affine_from_2d(0.5, 0, 0, 0.5, 0, 0), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0)};
    double pb[2] = {0.25, 0.75};
    fset_ifs wb = {2, b, pb};
    fset fb = {1, &wb};
    int z = 0;
    fset_order o0 = {FSET_PERIODIC, 1, &z, NULL, 0};
    CHECK(hist2_init(&h, 4, 1, (double[]){0, -0.5}, (double[]){1, 0.5}, 0, &e) == RT_OK, "hist");
    fset_chaos_opts wo = {FSET_WALK, 50000, 9, 0, 0, 1, {0, 0}};
    CHECK(fset_chaos(&fb, &o0, &wo, &h, NULL, &e) == RT_OK, "walk: %s", e.msg);
    CHECK(h.count[0] + h.count[2] == 50000, "walk end points at 0 and 1/2");
    CHECK_NEAR(h.count[0] / 50000.0, 0.25, 5 * sqrt(0.1875 / 50000), "walk map frequency");
    hist2_free(&h);

    /* ---- window fitting (fset_fit_aspect, fset_chaos_fit) ----
     * [0, 2]×[0, 1], margin 1/4: extents 3 × 1.5 about the centre (1, 1/2);
     * for 4:1 the x side becomes 1.5·4 = 6: [-2, 4]×[-1/4, 5/4]. */
    double wlo[2] = {0, 0}, whi[2] = {2, 1};
    fset_fit_aspect(wlo, whi, 4, 1, 0.25);
    CHECK(wlo[0] == -2 && whi[0] == 4 && wlo[1] == -0.25 && whi[1] == 1.25, "aspect 4:1: [%g, %g]×[%g, %g]",
          wlo[0], whi[0], wlo[1], whi[1]);
    /* 1:2, no margin: the y side becomes 2/(1/2) = 4 about 1/2: [-3/2, 5/2]. */
    wlo[0] = wlo[1] = 0, whi[0] = 2, whi[1] = 1;
    fset_fit_aspect(wlo, whi, 1, 2, 0);
    CHECK(wlo[0] == 0 && whi[0] == 2 && wlo[1] == -1.5 && whi[1] == 2.5, "aspect 1:2: [%g, %g]×[%g, %g]", wlo[0],
          whi[0], wlo[1], whi[1]);
    /* A point at (5, 5): each extent becomes 10 % of 5 = 1/2: [4.75, 5.25]². */
    wlo[0] = wlo[1] = whi[0] = whi[1] = 5;
    fset_fit_aspect(wlo, whi, 1, 1, 0);
    CHECK(wlo[0] == 4.75 && whi[0] == 5.25 && wlo[1] == 4.75 && whi[1] == 5.25, "degenerate: [%g, %g]×[%g, %g]",
          wlo[0], whi[0], wlo[1], whi[1]);
    /* The periodic game above plots only (1/3, 0) and (2/3, 0). R = 0.5/(1 - 0.5)
     * + |start| = 1.9; pass 1 has cells of 3.8/256 and each later window is the
     * occupied cells plus one cell each side, so the x extent before the margin
     * is in [1/3, 1/3 + 3·b4] with b4 <= 0.3378/256 (bounds by hand: E2 <= 1/3 +
     * 3·3.8/256, E3 <= 1/3 + 3·E2/256 ...), centred within 2 cells of 1/2; y is
     * widened to the same extent (square image), centred within 2 cells of 0. */
    co.plot_period = 0;
    co.points = 20000;
    CHECK(fset_chaos_fit(&f12, &o12, &co, 100, 100, wlo, whi, NULL, &e) == RT_OK, "fit: %s", e.msg);
    double ex = whi[0] - wlo[0], ey = whi[1] - wlo[1];
    CHECK(ex >= 1.06 / 3 && ex <= 1.06 * (1.0 / 3 + 3 * 0.3378 / 256), "fit x extent %.9g", ex);
    CHECK_NEAR(ey, ex, 1e-12, "fit square window");
    CHECK_NEAR((wlo[0] + whi[0]) / 2, 0.5, 2 * 0.3378 / 256, "fit x centre");
    CHECK_NEAR((wlo[1] + whi[1]) / 2, 0, 2 * 0.3378 / 256, "fit y centre");
    CHECK(wlo[0] <= 1.0 / 3 && whi[0] >= 2.0 / 3, "fit holds both points");
    CHECK(fset_chaos_fit(&f12, &o12, &co, 300, 100, wlo, whi, NULL, &e) == RT_OK, "fit 3:1: %s", e.msg);
    CHECK_NEAR((whi[0] - wlo[0]) / (whi[1] - wlo[1]), 3, 1e-12, "fit aspect 3:1");
    /* x + 3e6 is not contractive (R = 1e6) and every plotted point lies
     * beyond 3e6 · 64 steps of burn-in: no point in the window. */
    affine far = affine_from_2d(1, 0, 0, 1, 3e6, 0);
    fset_ifs wf = {1, &far, NULL};
    fset ff = {1, &wf};
    CHECK(fset_chaos_fit(&ff, &o0, &co, 100, 100, wlo, whi, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "no point of the chaos game fell near the origin; give window: [xmin, xmax, ymin, ymax]") == 0,
          "fit with no point: %s", e.msg);

    /* ---- Koch with a random order of Koch and its mirror image in the x
     * axis: every map has ratio s = 1/√3 and moves c = (1/2, 0) by
     * d = |ω(c) − c| = √(1/16 + 1/48), so all maps send the disc of centre c
     * and radius d/(1 − s) into itself: no hits in bins wholly outside it.
     * Byte-identical for 1, 2, 4 threads. */
    affine koch[2] = {affine_from_2d(0.5, R3 / 6, R3 / 6, -0.5, 0, 0),
                      affine_from_2d(0.5, -R3 / 6, -R3 / 6, -0.5, 0.5, R3 / 6)};
    affine mir[2];
    for (int i = 0; i < 2; i++) {
        mir[i] = koch[i];
        mir[i].m[0][1] = -koch[i].m[0][1];
        mir[i].m[1][0] = -koch[i].m[1][0];
        mir[i].t[1] = -koch[i].t[1];
    }
    double rad = sqrt(1.0 / 16 + 1.0 / 48) / (1 - 1 / R3);
    fset_ifs km[2] = {{2, koch, NULL}, {2, mir, NULL}};
    fset fk = {2, km};
    fset_order ork = {FSET_RANDOM, 0, NULL, NULL, 3};
    uint64_t *ref[2] = {NULL, NULL};
    for (int t = 1; t <= 4; t *= 2) {
        for (int mode = 0; mode < 2; mode++) {
            CHECK(hist2_init(&h, 40, 40, (double[]){-0.25, -0.75}, (double[]){1.25, 0.75}, 0, &e) ==
                      RT_OK,
                  "hist");
            fset_chaos_opts ko = {mode ? FSET_WALK : FSET_ORBIT, 150000, 11, 30, 0, 30, {0, 0}};
            rt_run run = {t, NULL, 0};
            CHECK(fset_chaos(&fk, &ork, &ko, &h, &run, &e) == RT_OK, "koch chaos: %s", e.msg);
            CHECK(total(&h) == 150000, "every point lands in the window (%ld)", total(&h));
            int outside = 0;
            for (int iy = 0; iy < 40; iy++)
                for (int ix = 0; ix < 40; ix++) {
                    double x0 = -0.25 + ix * 1.5 / 40, x1 = x0 + 1.5 / 40;
                    double y1 = 0.75 - iy * 1.5 / 40, y0 = y1 - 1.5 / 40;
                    double dx = fmax(0, fmax(x0 - 0.5, 0.5 - x1)), dy = fmax(0, fmax(y0, -y1));
                    int meets = dx * dx + dy * dy <= rad * rad;
                    if (!meets && h.count[iy * 40 + ix])
                        outside++;
                }
            CHECK(outside == 0, "no hits outside the invariant disc (%d bins)", outside);
            if (t == 1) {
                ref[mode] = rt_malloc(1600 * sizeof *ref[mode]);
                memcpy(ref[mode], h.count, 1600 * sizeof *ref[mode]);
            } else {
                CHECK(memcmp(ref[mode], h.count, 1600 * sizeof *ref[mode]) == 0,
                      "mode %d identical with %d threads", mode, t);
            }
            hist2_free(&h);
        }
    }
    rt_free(ref[0]);
    rt_free(ref[1]);
    return check_done("test_fset");
}
