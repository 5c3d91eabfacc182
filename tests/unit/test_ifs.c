/* test_ifs.c — IFS / RIFS validation messages, contraction factors, alias
 * tables. Expected values are worked out by hand in the comments. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "ifs.h"

static affine scale2(double s, double tx, double ty)
{
    return affine_from_2d(s, 0, 0, s, tx, ty);
}

static void expect_msg(rt_code rc, const rt_error *e, const char *want, const char *what)
{
    CHECK(rc == RT_EINVAL, "%s: code %d", what, (int)rc);
    CHECK(strcmp(e->msg, want) == 0, "%s: got \"%s\", want \"%s\"", what, e->msg, want);
}

static void test_ifs_validation(void)
{
    rt_error e;
    ifs f;
    affine m[3] = {scale2(0.5, 0, 0), scale2(0.5, 0.5, 0), scale2(0.5, 0, 0.5)};

    expect_msg(ifs_build(&f, m, 0, NULL, 0, &e), &e, "IFS has no maps", "empty");

    double pneg[3] = {0.5, -0.1, 0.6};
    expect_msg(ifs_build(&f, m, 3, pneg, 0, &e), &e, "probability 2 is -0.1 (expected >= 0)",
               "negative");

    double p97[3] = {0.3, 0.3, 0.37};
    expect_msg(ifs_build(&f, m, 3, p97, 0, &e), &e,
               "probabilities sum to 0.97, not 1 (use normalize: true to rescale them)", "sum");
    /* normalise: 0.3/0.97 etc. */
    CHECK(ifs_build(&f, m, 3, p97, IFS_NORMALISE, &e) == RT_OK, "normalise: %s", e.msg);
    CHECK_NEAR(f.p[2], 0.37 / 0.97, 1e-15, "normalised p3");
    ifs_free(&f);

    /* within 1e-9 is accepted */
    double pok[3] = {0.3, 0.3, 0.4 + 5e-10};
    CHECK(ifs_build(&f, m, 3, pok, 0, &e) == RT_OK, "tolerance: %s", e.msg);
    ifs_free(&f);

    affine mixed[2] = {scale2(0.5, 0, 0), affine_identity(3)};
    mixed[1].m[0][0] = mixed[1].m[1][1] = mixed[1].m[2][2] = 0.5;
    expect_msg(ifs_build(&f, mixed, 2, NULL, 0, &e), &e,
               "map 2 is 3-D but map 1 is 2-D (all maps need the same dimension)", "mixed dims");

    /* expanding map: diag(1.25, 0.5) has norm 1.25 */
    affine ex[2] = {scale2(0.5, 0, 0), affine_from_2d(1.25, 0, 0, 0.5, 0, 0)};
    expect_msg(ifs_build(&f, ex, 2, NULL, 0, &e), &e,
               "map 2 is not contractive: its norm is 1.25 (expected < 1)", "expanding");
    CHECK(ifs_build(&f, ex, 2, NULL, IFS_ALLOW_EXPANDING, &e) == RT_OK, "allow expanding");
    CHECK(strcmp(f.warning, "map 2 is not contractive: its norm is 1.25 (expected < 1)") == 0,
          "warning: %s", f.warning);
    CHECK_NEAR(f.max_contraction, 1.25, 1e-12, "max contraction");
    CHECK(f.worst_map == 1, "worst map %d", f.worst_map);
    ifs_free(&f);
    /* a probability error is reported before the norm */
    double pbad[2] = {0.5, -2};
    expect_msg(ifs_build(&f, ex, 2, pbad, 0, &e), &e, "probability 2 is -2 (expected >= 0)",
               "prob before norm");
}

static void test_contraction(void)
{
    rt_error e;
    ifs f;
    /* rotation by 30° times s = 0.7: norm exactly 0.7 */
    double s = 0.7, c = sqrt(3.0) / 2, sn = 0.5;
    affine m[2] = {affine_from_2d(s * c, -s * sn, s * sn, s * c, 0, 0),
                   affine_from_2d(0.5, 0, 0, 0.25, 1, 0)};
    CHECK(ifs_build(&f, m, 2, NULL, 0, &e) == RT_OK, "build: %s", e.msg);
    CHECK_NEAR(f.max_contraction, 0.7, 1e-12, "rotation·scale");
    CHECK(f.worst_map == 0, "worst map %d", f.worst_map);
    /* default weights: |det| = 0.49 and 0.125 → 0.49/0.615, 0.125/0.615 */
    CHECK_NEAR(f.p[0], 0.49 / 0.615, 1e-12, "det weight 1");
    CHECK_NEAR(f.p[1], 0.125 / 0.615, 1e-12, "det weight 2");
    ifs_free(&f);
    affine d[1] = {affine_from_2d(0.5, 0, 0, 0.25, 0, 0)};
    CHECK(ifs_build(&f, d, 1, NULL, 0, &e) == RT_OK, "diag");
    CHECK_NEAR(f.max_contraction, 0.5, 1e-12, "diag(0.5, 0.25)");
    ifs_free(&f);
    /* fern stem (det 0) gets the floor 0.01 × largest |det| */
    affine fern[2] = {affine_from_2d(0, 0, 0, 0.16, 0, 0), affine_from_2d(0.85, 0.04, -0.04, 0.85, 0, 1.6)};
    CHECK(ifs_build(&f, fern, 2, NULL, 0, &e) == RT_OK, "fern");
    double big = 0.85 * 0.85 + 0.04 * 0.04;
    CHECK_NEAR(f.p[0], 0.01 * big / (1.01 * big), 1e-12, "det floor");
    ifs_free(&f);
}

static void test_alias(void)
{
    rt_error e;
    ifs_alias a;
    double w[5] = {0.1, 0, 0.45, 0.05, 0.4};
    CHECK(ifs_alias_build(&a, w, 5, &e) == RT_OK, "alias");
    for (int i = 0; i < 5; i++)
        CHECK_NEAR(ifs_alias_prob(&a, i), w[i], 5 * 5 * 0x1.0p-32, "alias probability");
    CHECK(ifs_alias_prob(&a, 1) == 0, "zero weight is exactly never drawn");
    /* empirical: draw through the public inline with fixed words */
    int hits[5] = {0};
    uint64_t x = 1;
    for (int i = 0; i < 200000; i++) {
        x = x * 6364136223846793005ull + 1442695040888963407ull;
        hits[ifs_alias_pick(&a, x ^ (x >> 29))]++;
    }
    CHECK(hits[1] == 0, "zero weight drawn %d times", hits[1]);
    /* binomial sd for p=0.45, n=2e5: 222; allow 5 sd */
    CHECK(abs(hits[2] - 90000) < 1200, "p=0.45 drawn %d of 200000", hits[2]);
    ifs_alias_free(&a);
}

/* seed 001 Table 1 maps (scale 0.5, octant translations) */
static void octants(affine *m)
{
    static const double t[8][3] = {{0, 0, 0},     {128, 0, 0},   {128, 0, 128}, {0, 0, 128},
                                   {0, 128, 0},   {128, 128, 0}, {0, 128, 128}, {128, 128, 128}};
    double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
    for (int i = 0; i < 8; i++)
        m[i] = affine_from_3d(m9, t[i]);
}

static void test_rifs_validation(void)
{
    rt_error e;
    rifs r;
    affine m[3] = {scale2(0.5, 0, 0), scale2(0.5, 0.5, 0), scale2(0.5, 0, 0.5)};
    double neg[9] = {0.5, 0.5, 0, 0.2, 0.9, -0.1, 0.3, 0.3, 0.4};
    expect_msg(rifs_build(&r, m, 3, 1, neg, 0, &e), &e, "matrix entry (2, 3) is -0.1 (expected >= 0)",
               "negative entry");
    double rows[9] = {0.5, 0.5, 0, 0.2, 0.5, 0.2, 0.3, 0.3, 0.5};
    expect_msg(rifs_build(&r, m, 3, 1, rows, 0, &e), &e,
               "row 2 sums to 0.9, row 3 sums to 1.1 (each row must sum to 1)", "row sums");
    CHECK(rifs_build(&r, m, 3, 1, rows, RIFS_NORMALISE, &e) == RT_OK, "normalise rows: %s", e.msg);
    CHECK_NEAR(r.P[3 * 1 + 1], 0.5 / 0.9, 1e-15, "normalised row 2");
    rifs_free(&r);
    double zero[9] = {0.5, 0.5, 0, 0, 0, 0, 0.3, 0.3, 0.4};
    expect_msg(rifs_build(&r, m, 3, 1, zero, RIFS_NORMALISE, &e), &e,
               "row 2 is all zero (the chain cannot leave state 2)", "zero row");
    /* state 3 only goes to 3: 3 cannot reach 1 (1 reaches everything) */
    double red[9] = {0.5, 0.25, 0.25, 0.5, 0.5, 0, 0, 0, 1};
    expect_msg(rifs_build(&r, m, 3, 1, red, 0, &e), &e,
               "matrix is not irreducible: state 3 cannot reach state 1", "reducible");
    /* two closed classes {1,2}, {3}: 1 cannot reach 3 */
    double red2[9] = {0.5, 0.5, 0, 0.5, 0.5, 0, 0, 0, 1};
    expect_msg(rifs_build(&r, m, 3, 1, red2, 0, &e), &e,
               "matrix is not irreducible: state 1 cannot reach state 3", "reducible 2");
    /* a cyclic (periodic) chain is irreducible */
    double cyc[9] = {0, 1, 0, 0, 0, 1, 1, 0, 0};
    CHECK(rifs_build(&r, m, 3, 1, cyc, 0, &e) == RT_OK, "cycle: %s", e.msg);
    double pi[3];
    CHECK(rifs_stationary(&r, pi, &e) == RT_OK, "stationary");
    CHECK_NEAR(pi[0], 1.0 / 3, 1e-9, "cycle stationary");
    rifs_free(&r);
    expect_msg(rifs_build(&r, m, 3, 3, cyc, 0, &e), &e,
               "Markov order 3 is not supported (expected 1 or 2)", "order 3");
    affine ex[3] = {scale2(0.5, 0, 0), scale2(1.5, 0, 0), scale2(0.5, 0, 1)};
    expect_msg(rifs_build(&r, ex, 3, 1, cyc, 0, &e), &e,
               "map 2 is not contractive: its norm is 1.5 (expected < 1)", "rifs expanding");
    CHECK(rifs_build(&r, ex, 3, 1, cyc, RIFS_ALLOW_EXPANDING, &e) == RT_OK, "allowed");
    rifs_free(&r);

    /* the 8×8 Table 1 matrix is valid (rows sum to 1 as printed) */
    static const double T1[64] = {
        0.13, 0.14, 0.15, 0.09, 0.07, 0.15, 0.15, 0.07, 0.12, 0.07, 0.08, 0.15, 0.17, 0.08, 0.08, 0.21,
        0.16, 0.14, 0.08, 0.07, 0.16, 0.14, 0.09, 0.11, 0.13, 0.12, 0.14, 0.15, 0.07, 0.17, 0.15, 0.02,
        0.12, 0.08, 0.13, 0.16, 0.10, 0.10, 0.14, 0.13, 0.13, 0.15, 0.13, 0.11, 0.07, 0.08, 0.10, 0.18,
        0.09, 0.13, 0.14, 0.16, 0.13, 0.09, 0.14, 0.07, 0.15, 0.15, 0.14, 0.17, 0.07, 0.16, 0.11, 0.01};
    affine oct[8];
    octants(oct);
    /* As printed, Table 1's rows sum to 0.95 or 0.96 (hand sums), violating
     * the paper's own condition (i): the check must say so, row by row. */
    expect_msg(rifs_build(&r, oct, 8, 1, T1, 0, &e), &e,
               "row 1 sums to 0.95, row 2 sums to 0.96, row 3 sums to 0.95, row 4 sums to 0.95, "
               "row 5 sums to 0.96, row 6 sums to 0.95, row 7 sums to 0.95, row 8 sums to 0.96 "
               "(each row must sum to 1)",
               "Table 1 as printed");
    if (rifs_build(&r, oct, 8, 1, T1, RIFS_NORMALISE, &e) != RT_OK) {
        CHECK(0, "Table 1 normalised: %s", e.msg);
        return;
    }
    CHECK_NEAR(r.max_contraction, 0.5, 1e-12, "Table 1 contraction");
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 8; j++)
            CHECK_NEAR(ifs_alias_prob(&r.row[i], j), r.P[8 * i + j], 8 * 8 * 0x1.0p-32, "row alias");
    rifs_free(&r);
}

static void test_rifs_order2(void)
{
    rt_error e;
    rifs r;
    affine m[2] = {scale2(0.5, 0, 0), scale2(0.5, 0.5, 0)};
    /* rows (1,1) (1,2) (2,1) (2,2): after 1,1 always 2; after 1,2 either; after 2,1 either;
     * after 2,2 always 1 — no three equal maps in a row. Irreducible on all 4 pairs. */
    double P[8] = {0, 1, 0.5, 0.5, 0.5, 0.5, 1, 0};
    CHECK(rifs_build(&r, m, 2, 2, P, 0, &e) == RT_OK, "order 2: %s", e.msg);
    CHECK(r.rows == 4 && r.start == 0, "rows %d start %d", r.rows, r.start);
    rifs_free(&r);
    /* pair (1,1) unused: row all zero, and nothing leads into it (row (2,1) never picks 1) */
    double Pu[8] = {0, 0, 0.5, 0.5, 0, 1, 0.5, 0.5};
    CHECK(rifs_build(&r, m, 2, 2, Pu, 0, &e) == RT_OK, "unused pair: %s", e.msg);
    CHECK(r.start == 1, "start pair %d (expected (1,2) = row 1)", r.start);
    rifs_free(&r);
    /* but leading into an all-zero row is an error: (1,2) can pick 1 → (2,1), (2,1) picks 1 → (1,1) */
    double Pz[8] = {0, 0, 0.5, 0.5, 1, 0, 0.5, 0.5};
    expect_msg(rifs_build(&r, m, 2, 2, Pz, 0, &e), &e,
               "pair (2, 1) can be followed by map 1, but row (1, 1) is all zero", "into zero row");
    double Pbad[8] = {0, 0.9, 0.5, 0.5, 0.5, 0.5, 1, 0.2};
    expect_msg(rifs_build(&r, m, 2, 2, Pbad, 0, &e), &e,
               "row (1, 1) sums to 0.9, row (2, 2) sums to 1.2 (each row must sum to 1, or be all "
               "zero for an unused pair)",
               "order-2 row sums");
    /* two closed classes: (1,1) → (1,1) forever and (2,2) → (2,2) forever */
    double Pr[8] = {1, 0, 0.5, 0.5, 0.5, 0.5, 0, 1};
    expect_msg(rifs_build(&r, m, 2, 2, Pr, 0, &e), &e,
               "matrix is not irreducible: pair (1, 1) cannot reach pair (2, 2)", "order-2 reducible");
    /* one closed class {(1,1)} plus transients: map 2 never recurs */
    double Pm[8] = {1, 0, 1, 0, 1, 0, 1, 0};
    expect_msg(rifs_build(&r, m, 2, 2, Pm, 0, &e), &e, "map 2 never occurs in the recurrent pairs",
               "map missing");
    double Pn[8] = {0, 1, 0.5, 0.5, 0.5, -0.5, 1, 0};
    expect_msg(rifs_build(&r, m, 2, 2, Pn, 0, &e), &e,
               "matrix entry row (2, 1), column 2 is -0.5 (expected >= 0)", "order-2 negative");
}

int main(void)
{
    test_ifs_validation();
    test_contraction();
    test_alias();
    test_rifs_validation();
    test_rifs_order2();
    return check_done("test_ifs");
}
