/* test_ist.c — Iterated Shuffle Transformation (seed 002 §4.1, §5.2). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
#include "fileio.h"
#include "ist.h"
#include "rng.h"

static uint64_t ipow(int b, int k)
{
    uint64_t s = 1;
    while (k-- > 0)
        s *= (uint64_t)b;
    return s;
}

/* Fig. 2 (M = 1, K = 2): interval 5 holds, by top digit, {3,4,5},{4,5,6},{5,6,7},
 * interval 6 {4,5,6},{5,6,7},{6,7,8}. Entries: source interval then its
 * sub-interval digits; hand-derived from §4.1 for interval 5. */
static void test_fig2(void)
{
    for (int method = 1; method <= 2; method++) {
        ist t;
        ist_spec s = {.n = 10, .m = 1, .k = 2, .axis = IST_CYCLIC, .method = (ist_method)method};
        rt_error e;
        CHECK(ist_init(&t, &s, &e) == RT_OK, "init: %s", e.msg);
        static const int top5[9] = {3, 4, 5, 4, 5, 6, 5, 6, 7};
        static const int top6[9] = {4, 5, 6, 5, 6, 7, 6, 7, 8};
        for (int q = 0; q < 9; q++) {
            double u5 = 5 + (q + 0.5) / 9.0, u6 = 6 + (q + 0.5) / 9.0;
            CHECK((int)floor(ist_inv(&t, u5)) == top5[q], "method %d interval 5 slot %d: %g", method,
                  q, ist_inv(&t, u5));
            CHECK((int)floor(ist_inv(&t, u6)) == top6[q], "method %d interval 6 slot %d", method, q);
        }
        bytebuf b;
        bytebuf_init(&b);
        CHECK(ist_print(&t, &b, &e) == RT_OK, "print: %s", e.msg);
        bytebuf_byte(&b, 0);
        const char *want = "L5: 322 412 502 | 421 511 601 | 520 610 700\n";
        CHECK(b.data && strstr((const char *)b.data, want) != NULL, "Fig. 2 list of interval 5 not found in:\n%s",
              b.data ? (const char *)b.data : "(null)");
        bytebuf_free(&b);
        ist_free(&t);
    }
}

/* One-to-one: the S slots of every base interval map onto distinct source
 * sub-intervals, all N·S of them; centres fixed; F(F^{-1}(u)) = u. */
static void test_bijective(void)
{
    for (int axis = 0; axis < 2; axis++)
        for (int m = 0; m <= 2; m++)
            for (int k = 0; k <= 3; k++) {
                int n = 7;
                ist t;
                ist_spec s = {.n = n, .m = m, .k = k, .axis = (ist_axis_type)axis};
                rt_error e;
                CHECK(ist_init(&t, &s, &e) == RT_OK, "init: %s", e.msg);
                uint64_t S = ipow(2 * m + 1, k);
                size_t tot = (size_t)n * S;
                unsigned char *seen = rt_calloc(tot, 1);
                size_t distinct = 0;
                for (int i = 0; i < n; i++)
                    for (uint64_t q = 0; q < S; q++) {
                        double src = ist_inv(&t, i + (q + 0.5) / (double)S);
                        double y = src * (double)S;
                        long id = (long)floor(y);
                        CHECK(fabs(y - (id + 0.5)) < 1e-6, "slot centre maps to a sub-interval centre");
                        if (id >= 0 && (size_t)id < tot && !seen[id]) {
                            seen[id] = 1;
                            distinct++;
                        }
                    }
                CHECK(distinct == tot, "axis %d M %d K %d: %zu distinct of %zu", axis, m, k, distinct,
                      tot);
                rt_free(seen);
                for (int i = 0; i < n; i++) {
                    CHECK_NEAR(ist_inv(&t, i + 0.5), i + 0.5, 1e-12, "centre fixed");
                    CHECK_NEAR(ist_fwd(&t, i + 0.5), i + 0.5, 1e-12, "centre fixed (F)");
                }
                if (axis == IST_TRANSLATION)
                    CHECK(ist_inv(&t, 0.0) == 0.0, "left end fixed");
                rng r;
                rng_init(&r, 7, (uint64_t)(axis * 100 + m * 10 + k));
                for (int q = 0; q < 2000; q++) {
                    double u = rng_uniform(&r) * n;
                    CHECK_NEAR(ist_fwd(&t, ist_inv(&t, u)), u, 1e-12, "F(F^-1(u))");
                    CHECK_NEAR(ist_inv(&t, ist_fwd(&t, u)), u, 1e-12, "F^-1(F(u))");
                }
                if (axis == IST_CYCLIC)
                    CHECK_NEAR(ist_inv(&t, 3.3 + 2 * n), ist_inv(&t, 3.3) + 2 * n, 1e-12, "periodic");
                else
                    CHECK(ist_inv(&t, -1.25) == -1.25 && ist_inv(&t, n + 0.5) == n + 0.5,
                          "identity outside a translation axis");
                ist_free(&t);
            }
}

/* The general list construction and the closed form agree on unit intervals. */

/* (2M+1)^K beyond 2^32 takes the 64-bit per-digit branches of the closed
 * form: slot centres must map to sub-interval centres and F must send them
 * back to the same slot (an independent check of inv and fwd, which are
 * separate code). A wrong digit moves a point by whole sub-intervals. */
static void test_large_k(void)
{
    /* at S near 2^52 sub-intervals near u = n are narrower than one ulp of
     * u, so no double-precision F^{-1} can be one-to-one there: K stops
     * where sub-intervals are IST_MIN_ULPS = 64 ulps of 7 = 2^-44 wide.
     * With n = 7 that is 3^27 <= 2^44 < 3^28, 5^18 <= 2^44 < 5^19 and
     * 7^15 <= 2^44 < 7^16; the limit itself round-trips, one more is refused. */
    static const int mk[7][2] = {{1, 21}, {1, 24}, {2, 14}, {3, 12}, {1, 27}, {2, 18}, {3, 15}};
    static const int lim[3] = {27, 18, 15};
    for (int m = 1; m <= 3; m++) {
        ist_spec s = {.n = 7, .m = m, .k = lim[m - 1] + 1, .axis = IST_CYCLIC};
        CHECK(ist_k_limit(&s) == lim[m - 1], "M %d: limit %d", m, ist_k_limit(&s));
        ist t;
        rt_error e;
        CHECK(ist_init(&t, &s, &e) == RT_EINVAL, "M %d: K = limit + 1 refused", m);
        char want[300];
        snprintf(want, sizeof want,
                 "IST iterations K = %d make sub-intervals %.3g wide, under 64 ulps (5.68e-14) of coordinates up to 7, so double precision cannot keep F one-to-one; at most K = %d for this axis",
                 lim[m - 1] + 1, 1 / pow(2 * m + 1, lim[m - 1] + 1), lim[m - 1]);
        CHECK(strcmp(e.msg, want) == 0, "message: %s", e.msg);
    }
    {   /* M = 0 never narrows; no axis with M >= 1 passes K = 30 */
        ist_spec s = {.n = 1, .m = 0, .k = IST_MAX_K};
        CHECK(ist_k_limit(&s) == IST_MAX_K, "M = 0: any K");
        s.m = 1;
        CHECK(ist_k_limit(&s) == 29 && IST_MAX_K == 29, "n = 1, M = 1: K up to 29, the global cap");
        double b[2] = {0, 1.99};
        s.bounds = b;
        CHECK(ist_k_limit(&s) == 29, "[0, 1.99]: 29");
        ist t;
        rt_error e;
        s.k = 29;
        CHECK(ist_init(&t, &s, &e) == RT_OK, "K = 29 on [0, 1.99): %s", e.msg);
        ist_free(&t);
        s.k = 30;
        CHECK(ist_init(&t, &s, &e) == RT_EINVAL && strcmp(e.msg, "IST iterations K = 30; expected 0..29") == 0,
              "K = 30: %s", e.msg);
    }
    for (int axis = 0; axis < 2; axis++)
        for (int c = 0; c < 7; c++) {
            int n = 7, m = mk[c][0], k = mk[c][1];
            ist t;
            ist_spec s = {.n = n, .m = m, .k = k, .axis = (ist_axis_type)axis};
            rt_error e;
            CHECK(ist_init(&t, &s, &e) == RT_OK, "init K %d: %s", k, e.msg);
            double S = (double)ipow(2 * m + 1, k);
            CHECK(t.closed && S > 4294967296.0, "closed form beyond 2^32 (M %d K %d)", m, k);
            rng r;
            rng_init(&r, 3, (uint64_t)(axis * 10 + c));
            int bad = 0;
            for (int q = 0; q < 4000; q++) {
                int i = (int)(rng_uniform(&r) * n);
                double slot = floor(rng_uniform(&r) * S);
                double u = i + (slot + 0.5) / S;
                double y = ist_inv(&t, u) * S;
                double id = floor(y);
                double back = ist_fwd(&t, (id + 0.5) / S) * S;
                if (!(fabs(y - (id + 0.5)) < 0.05) || !(floor(back) == i * S + slot))
                    bad++;
            }
            CHECK(bad == 0, "axis %d M %d K %d: %d of 4000 slot centres do not round-trip", axis, m, k, bad);
            ist_free(&t);
        }
}

static void test_lists_vs_closed(void)
{
    for (int axis = 0; axis < 2; axis++)
        for (int m = 1; m <= 3; m++)
            for (int k = 0; k <= 4; k++) {
                int n = m == 3 ? 9 : 5; /* n < 2M+1 exercises pieces held back at both ends */
                if (m == 3 && k == 4)
                    continue;
                ist a, b;
                ist_spec s = {.n = n, .m = m, .k = k, .axis = (ist_axis_type)axis, .method = IST_LISTS};
                rt_error e;
                CHECK(ist_init(&a, &s, &e) == RT_OK, "lists: %s", e.msg);
                /* the per-digit closed form against the lists (an independent
                 * construction); the grouped fast path is held to the per-digit
                 * form bit for bit in test_fast_bits */
                s.method = IST_CLOSED_DIGITS;
                CHECK(ist_init(&b, &s, &e) == RT_OK, "closed: %s", e.msg);
                CHECK(a.closed == 0 && b.closed == 1 && !b.ftab, "methods chosen");
                rng r;
                rng_init(&r, 11, (uint64_t)(axis * 100 + m * 10 + k));
                double worst = 0, worstf = 0;
                for (int q = 0; q < 3000; q++) {
                    double u = rng_uniform(&r) * n;
                    double d = fabs(ist_inv(&a, u) - ist_inv(&b, u));
                    double df = fabs(ist_fwd(&a, u) - ist_fwd(&b, u));
                    worst = d > worst ? d : worst;
                    worstf = df > worstf ? df : worstf;
                }
                CHECK(worst <= 1e-12, "axis %d M %d K %d: F^-1 differs by %g", axis, m, k, worst);
                CHECK(worstf <= 1e-12, "axis %d M %d K %d: F differs by %g", axis, m, k, worstf);
                ist_free(&a);
                ist_free(&b);
            }
}

/* Unequal lengths and per-interval M: the pieces still partition the axis,
 * F is one-to-one, and a symmetric neighbourhood keeps its centre fixed. */
static void test_general(void)
{
    double bounds[7] = {0, 1, 3, 3.5, 4.5, 6.5, 7};
    for (int axis = 0; axis < 2; axis++) {
        /* M = 3 on a translation axis (pieces held back at the ends); a
         * cyclic axis of 6 intervals takes at most M = 2 (2M+1 <= N) */
        int ms[6] = {1, 2, 0, 1, axis ? 2 : 3, 1};
        ist t;
        ist_spec s = {.n = 6, .bounds = bounds, .m_each = ms, .k = 3, .axis = (ist_axis_type)axis};
        rt_error e;
        CHECK(ist_init(&t, &s, &e) == RT_OK, "init: %s", e.msg);
        CHECK(t.closed == 0, "general case uses the lists");
        double sum = 0;
        for (size_t r = 0; r < t.ne; r++)
            sum += t.len[r];
        CHECK_NEAR(sum, 7.0, 1e-12, "entries partition the axis");
        for (size_t r = 1; r < t.ne; r++) {
            size_t p = t.by_x[r - 1], q = t.by_x[r];
            CHECK_NEAR(t.x[p] + t.len[p], t.x[q], 1e-12, "entries are contiguous in the source");
        }
        rng rr;
        rng_init(&rr, 3, (uint64_t)axis);
        for (int q = 0; q < 2000; q++) {
            double u = rng_uniform(&rr) * 7;
            CHECK_NEAR(ist_fwd(&t, ist_inv(&t, u)), u, 1e-12, "F(F^-1(u)) general");
        }
        ist_free(&t);
    }
    /* symmetric lengths around interval 2 (cyclic, equal M): fixed centre */
    double b2[6] = {0, 2, 3, 5, 6, 8};
    ist t;
    ist_spec s = {.n = 5, .bounds = b2, .m = 1, .k = 3, .axis = IST_CYCLIC};
    rt_error e;
    CHECK(ist_init(&t, &s, &e) == RT_OK, "init: %s", e.msg);
    CHECK_NEAR(ist_inv(&t, 4.0), 4.0, 1e-12, "centre of a symmetric neighbourhood is fixed");
    /* ...but unequal lengths move the others: the centre 1 of [0, 2), whose
     * neighbours are 3 and 1 long, goes to 0.63 (the docs' condition for
     * fixed centres: equal lengths and one M) */
    CHECK_NEAR(ist_inv(&t, 1.0), 0.63, 1e-12, "unequal lengths: centre of [0, 2) moves");
    CHECK_NEAR(ist_inv(&t, 2.5), 2.6415, 1e-12, "unequal lengths: centre of [2, 3) moves");
    ist_free(&t);
    /* equal lengths but several M: centres move too (interval 0 to 1.12) */
    int ms2[5] = {1, 1, 2, 1, 1};
    ist_spec s2 = {.n = 5, .m_each = ms2, .k = 2, .axis = IST_CYCLIC};
    CHECK(ist_init(&t, &s2, &e) == RT_OK, "init: %s", e.msg);
    int moved = 0;
    for (int i = 0; i < 5; i++)
        moved += fabs(ist_inv(&t, i + 0.5) - (i + 0.5)) > 1e-9;
    CHECK(moved == 4, "several M: %d centres move", moved);
    CHECK_NEAR(ist_inv(&t, 0.5), 1.12, 1e-12, "several M: centre of interval 0");
    ist_free(&t);
}

static void test_validation(void)
{
    ist t;
    rt_error e;
    double bad[4] = {0, 1, 1, 2};
    ist_spec s = {.n = 3, .bounds = bad, .m = 1, .k = 2};
    CHECK(ist_init(&t, &s, &e) == RT_EINVAL, "non-increasing bounds refused");
    CHECK(strcmp(e.msg, "IST bounds must increase: bound 2 = 1 is not greater than bound 1 = 1") == 0,
          "message: %s", e.msg);
    int ms[3] = {1, -2, 1};
    ist_spec s2 = {.n = 3, .m_each = ms, .k = 2};
    CHECK(ist_init(&t, &s2, &e) == RT_EINVAL, "negative M refused");
    CHECK(strcmp(e.msg, "IST crossing count M of interval 1 is -2; expected 0..1000") == 0, "message: %s",
          e.msg);
    ist_spec s3 = {.n = 3, .bounds = (double[]){0, 1, 3, 4}, .m = 1, .k = 2, .method = IST_CLOSED};
    CHECK(ist_init(&t, &s3, &e) == RT_EINVAL, "closed form refused for unequal lengths");
    ist_spec s4 = {.n = 50, .m = 5, .k = 8, .method = IST_LISTS};
    CHECK(ist_init(&t, &s4, &e) == RT_EINVAL, "huge lists refused: %s", e.msg);
    ist_spec s5 = {.n = 0, .m = 1, .k = 1};
    CHECK(ist_init(&t, &s5, &e) == RT_EINVAL && strstr(e.msg, "at least 1 base interval"), "n = 0");
    /* a cyclic axis needs 2M+1 <= N (a translation axis holds pieces back instead) */
    ist_spec s6 = {.n = 4, .m = 2, .k = 1, .axis = IST_CYCLIC};
    CHECK(ist_init(&t, &s6, &e) == RT_EINVAL, "cyclic 2M+1 > N refused");
    CHECK(strcmp(e.msg, "IST on a cyclic axis needs 2M+1 <= N, got M = 2 with N = 4 (the pieces would wrap onto one interval twice)") == 0,
          "message: %s", e.msg);
    int ms7[3] = {0, 1, 2};
    ist_spec s7 = {.n = 3, .m_each = ms7, .k = 1, .axis = IST_CYCLIC};
    CHECK(ist_init(&t, &s7, &e) == RT_EINVAL, "cyclic 2M_i+1 > N refused");
    CHECK(strcmp(e.msg, "IST on a cyclic axis needs 2M+1 <= N, but interval 2 has M = 2 with N = 3 (its pieces would wrap onto one interval twice)") == 0,
          "message: %s", e.msg);
    ist_spec s8 = {.n = 5, .m = 2, .k = 2, .axis = IST_CYCLIC};
    CHECK(ist_init(&t, &s8, &e) == RT_OK, "cyclic 2M+1 = N accepted: %s", e.msg);
    ist_free(&t);
    s8.axis = IST_TRANSLATION, s8.n = 2;
    CHECK(ist_init(&t, &s8, &e) == RT_OK, "translation 2M+1 > N accepted: %s", e.msg);
    ist_free(&t);
    /* unequal lengths: the lists' narrowest piece is checked too */
    double tiny[4] = {0, 1e-13, 1, 2};
    ist_spec s9 = {.n = 3, .bounds = tiny, .m = 1, .k = 3};
    CHECK(ist_init(&t, &s9, &e) == RT_EINVAL && strstr(e.msg, "so double precision cannot keep F one-to-one"),
          "a 1e-13 interval cut 27 ways is refused: %s", e.msg);
}

/* §5.2: Σ S_i samples at the sub-intervals the formula names (indices
 * computed here by hand for K = 3, B = 3); Fig. 7: raising K keeps the top
 * digit of every sample. */
static void test_sampling(void)
{
    ist t;
    ist_spec s = {.n = 6, .m = 1, .k = 3, .axis = IST_CYCLIC};
    rt_error e;
    CHECK(ist_init(&t, &s, &e) == RT_OK, "init");
    int ki[6] = {0, 1, 2, 3, 1, 0};
    double pos[200];
    size_t n = ist_sample_positions(&t, ki, 0, 1, pos, 200);
    CHECK(n == 1 + 3 + 9 + 27 + 3 + 1, "Σ S_i samples: %zu", n);
    /* hand: K_i = 0 → the 14th of 27 (index 13); K_i = 1 → 5th, 14th, 23rd;
     * K_i = 2 → 2nd and every 3rd; K_i = 3 → all */
    CHECK_NEAR(pos[0], 0 + 13.5 / 27, 1e-12, "interval 0");
    CHECK_NEAR(pos[1], 1 + 4.5 / 27, 1e-12, "interval 1 first");
    CHECK_NEAR(pos[2], 1 + 13.5 / 27, 1e-12, "interval 1 second");
    CHECK_NEAR(pos[3], 1 + 22.5 / 27, 1e-12, "interval 1 third");
    for (int q = 0; q < 9; q++)
        CHECK_NEAR(pos[4 + q], 2 + (1 + 3 * q + 0.5) / 27, 1e-12, "interval 2");
    for (int q = 0; q < 27; q++)
        CHECK_NEAR(pos[13 + q], 3 + (q + 0.5) / 27, 1e-12, "interval 3");
    CHECK(ist_sample_index(3, 3, 1, 2) == 22, "index formula");
    CHECK(ist_sample_index(5, 2, 0, 0) == 12, "index formula M = 2");
    /* Fig. 7: the same sampling at K = 2 and K = 3 gives the same top digits */
    for (int m = 1; m <= 2; m++) {
        ist t2, t3;
        ist_spec a = {.n = 9, .m = m, .k = 2, .axis = IST_CYCLIC}, b = a;
        b.k = 3;
        ist_init(&t2, &a, &e);
        ist_init(&t3, &b, &e);
        int k2[9] = {0, 1, 2, 2, 1, 2, 0, 1, 2};
        double p2[300], p3[300];
        size_t n2 = ist_sample_positions(&t2, k2, 0, 0, p2, 300);
        size_t n3 = ist_sample_positions(&t3, k2, 0, 0, p3, 300);
        CHECK(n2 == n3, "same count when only K changes");
        int same = 1;
        for (size_t q = 0; q < n2 && q < 300; q++) {
            CHECK_NEAR(p2[q], p3[q], 1e-12, "same positions");
            if (floor(ist_inv(&t2, p2[q])) != floor(ist_inv(&t3, p3[q])))
                same = 0;
        }
        CHECK(same, "M %d: top digits kept when K rises", m);
        ist_free(&t2);
        ist_free(&t3);
    }
    /* jitter stays inside the chosen sub-intervals */
    size_t nj = ist_sample_positions(&t, ki, 1, 99, pos, 200);
    CHECK(nj == n, "jittered count");
    CHECK(pos[0] >= 13.0 / 27 && pos[0] < 14.0 / 27, "jitter inside sub-interval 13");
    CHECK(pos[1] >= 1 + 4.0 / 27 && pos[1] < 1 + 5.0 / 27, "jitter inside sub-interval 4");
    ist_free(&t);
}


static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (a != a && b != b);
}

/* The grouped fast path (and ist_inv_block) equals the library's per-digit evaluation (IST_CLOSED_DIGITS) bit
 * for bit: M = 1..3, K = 0..8 and a few larger K, both axis types, unit and
 * other interval lengths, many u including every sub-interval boundary of
 * some intervals and its neighbouring doubles. */
static void test_fast_bits(void)
{
    static const double a0s[5] = {0, -2.5, 0.1, 3, -1}, hs[5] = {1, 0.25, 0.37, 1.5, 2};
    double *u = rt_malloc(sizeof(double) * 40000), *got = rt_malloc(sizeof(double) * 40000);
    CHECK(u && got, "memory");
    long tested = 0, fast = 0;
    for (int axis = 0; axis < 2; axis++)
        for (int m = 1; m <= 3; m++)
            for (int k = 0; k <= 11; k++)
                for (int g = 0; g < 5; g++) {
                    if (k > 8 && (m > 1 || g > 0))
                        continue;
                    /* 64, 43, 22 intervals: ends and interior, K·M > N/2; M + 2 and 1:
                     * pieces held back at both ends */
                    int n = g < 3 ? 64 - 21 * g : g == 3 ? m + 2 : 1;
                    if (axis == IST_CYCLIC && 2 * m + 1 > n)
                        continue; /* refused (test_validation) */
                    double bounds[65];
                    for (int i = 0; i <= n; i++)
                        bounds[i] = a0s[g] + (double)i * hs[g];
                    ist t, ref;
                    ist_spec s = {.n = n, .bounds = bounds, .m = m, .k = k, .axis = (ist_axis_type)axis};
                    rt_error e;
                    CHECK(ist_init(&t, &s, &e) == RT_OK, "init: %s", e.msg);
                    s.method = IST_CLOSED_DIGITS;
                    CHECK(ist_init(&ref, &s, &e) == RT_OK, "per-digit init: %s", e.msg);
                    CHECK(t.closed && ref.closed && !ref.ftab, "closed form, reference per digit");
                    fast += t.ftab != NULL;
                    rng r;
                    rng_init(&r, 5, (uint64_t)(axis * 1000 + m * 100 + k * 5 + g));
                    size_t nu = 0;
                    double lo = bounds[0], len = bounds[n] - bounds[0];
                    for (int q = 0; q < 20000; q++) /* mostly inside, some outside */
                        u[nu++] = lo - 0.1 * len + 1.2 * len * rng_uniform(&r);
                    /* sub-interval boundaries of intervals 0, 1, n/2, n-1 */
                    int iv[4] = {0, 1, n / 2, n - 1};
                    uint64_t S = ipow(2 * m + 1, k), step = S / 2000 + 1;
                    for (int w = 0; w < 4; w++)
                        for (uint64_t q = 0; q <= S && nu + 3 <= 40000; q += step) {
                            double x = bounds[iv[w]] + hs[g] * ((double)q / (double)S);
                            u[nu++] = x;
                            u[nu++] = nextafter(x, -1e300);
                            u[nu++] = nextafter(x, 1e300);
                        }
                    u[0] = bounds[n], u[1] = nextafter(bounds[n], -1e300), u[2] = bounds[0];
                    u[3] = bounds[0] + 1e3 * len, u[4] = -0.0, u[5] = NAN, u[6] = INFINITY;
                    ist_inv_block(&t, nu, u, got);
                    int bad = 0;
                    for (size_t q = 0; q < nu; q++) {
                        double want = ist_inv(&ref, u[q]), one = ist_inv(&t, u[q]);
                        if (!same_bits(want, one) || !same_bits(want, got[q])) {
                            if (bad++ < 3)
                                CHECK(0, "axis %d M %d K %d set %d: u = %.17g: %.17g / block %.17g, per-digit %.17g",
                                      axis, m, k, g, u[q], one, got[q], want);
                        }
                    }
                    CHECK(bad == 0, "axis %d M %d K %d set %d: %d of %zu differ", axis, m, k, g, bad, nu);
                    tested += (long)nu;
                    /* in place */
                    memcpy(got, u, sizeof(double) * 100);
                    ist_inv_block(&t, 100, got, got);
                    for (int q = 0; q < 100; q++)
                        CHECK(same_bits(got[q], ist_inv(&ref, u[q])), "in place");
                    ist_free(&t);
                    ist_free(&ref);
                }
    CHECK(fast > 100, "the fast path is used (%ld configurations)", fast);
    CHECK(tested > 1000000, "%ld evaluations compared", tested);
    rt_free(u);
    rt_free(got);
}

int main(void)
{
    test_fig2();
    test_bijective();
    test_large_k();
    test_lists_vs_closed();
    test_general();
    test_validation();
    test_sampling();
    test_fast_bits();
    return check_done("test_ist");
}
