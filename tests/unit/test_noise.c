/* test_noise.c — Perlin's improved noise, fBm and turbulence (noise.h). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "noise.h"
#include "noise_impl.h"
#include "rng.h"

#define NPTS 20000

static double px[NPTS], py[NPTS], pz[NPTS], o1[NPTS], o2[NPTS];

static void random_points(uint64_t seed, double scale)
{
    rng r;
    rng_init(&r, seed, 1);
    for (int i = 0; i < NPTS; i++) {
        px[i] = (rng_uniform(&r) * 2 - 1) * scale;
        py[i] = (rng_uniform(&r) * 2 - 1) * scale;
        pz[i] = (rng_uniform(&r) * 2 - 1) * scale;
    }
}

static void test_reference(void)
{
    noise_perm np;
    noise_perm_reference(&np);
    /* Perlin's table is a permutation of 0..255, doubled. */
    int seen[256] = {0}, dup = 0;
    for (int i = 0; i < 256; i++) {
        dup += seen[np.p[i]]++ != 0;
        dup += np.p[i] != np.p[i + 256];
    }
    CHECK(dup == 0, "reference table is not a doubled permutation (%d bad)", dup);

    /* Published values of the 2002 reference (Java, doubles): e.g. Rosetta
     * Code's "Perlin noise" task, n(3.14, 42, 7) = 0.13691995878400012. */
    CHECK(noise_reference3(3.14, 42, 7) == 0.13691995878400012, "ref(3.14,42,7) = %.17g",
          noise_reference3(3.14, 42, 7));
    CHECK(noise_reference3(-4.2, 10, 6) == 0.14208000000000043, "ref(-4.2,10,6) = %.17g",
          noise_reference3(-4.2, 10, 6));
    CHECK(noise_perlin3(&np, 3.14, 42, 7) == 0.13691995878400012, "ours(3.14,42,7) = %.17g",
          noise_perlin3(&np, 3.14, 42, 7));
    CHECK(noise_perlin3(&np, -4.2, 10, 6) == 0.14208000000000043, "ours(-4.2,10,6) = %.17g",
          noise_perlin3(&np, -4.2, 10, 6));

    /* By hand, n(0.25, 0, 0) with Perlin's table: X = Y = Z = 0, so
     * A = P[0] = 151, AA = P[151] = 17, B = P[1] = 160, BA = P[160] = 119;
     * v = w = fade(0) = 0, so n = lerp(u, grad(P[17], .25,0,0),
     * grad(P[119], -.75,0,0)). P[17] = 36, 36 & 15 = 4: x + z = 0.25.
     * P[119] = 86, 86 & 15 = 6: x - z = -0.75. u = fade(0.25) =
     * 0.25^3 (0.25 (1.5 - 15) + 10) = 0.015625 * 6.625 = 0.103515625.
     * n = 0.25 + 0.103515625 * (-0.75 - 0.25) = 0.146484375 (exact). */
    CHECK(np.p[17] == 36 && np.p[119] == 86 && np.p[151] == 17 && np.p[160] == 119,
          "table entries %d %d %d %d", np.p[17], np.p[119], np.p[151], np.p[160]);
    CHECK(noise_perlin3(&np, 0.25, 0, 0) == 0.146484375, "n(.25,0,0) = %.17g",
          noise_perlin3(&np, 0.25, 0, 0));
    CHECK(noise_reference3(0.25, 0, 0) == 0.146484375, "ref(.25,0,0) = %.17g",
          noise_reference3(0.25, 0, 0));

    /* With the reference permutation, ours equals the transcription. */
    random_points(7, 300);
    int bad = 0;
    for (int i = 0; i < NPTS; i++)
        bad += noise_perlin3(&np, px[i], py[i], pz[i]) != noise_reference3(px[i], py[i], pz[i]);
    CHECK(bad == 0, "%d of %d points differ from the reference", bad, NPTS);
}

static void test_properties(void)
{
    noise_perm a, b, a2;
    noise_perm_init(&a, 1);
    noise_perm_init(&a2, 1);
    noise_perm_init(&b, 2);
    CHECK(memcmp(&a, &a2, sizeof a) == 0, "same seed, different permutation");
    CHECK(memcmp(&a, &b, sizeof a) != 0, "seeds 1 and 2 give the same permutation");
    int seen[256] = {0}, dup = 0;
    for (int i = 0; i < 256; i++)
        dup += seen[a.p[i]]++ != 0 || a.p[i] != a.p[i + 256];
    CHECK(dup == 0, "seeded table is not a doubled permutation");
    /* A uniform shuffle (Fisher–Yates: j in [0, i]) leaves some entries in
     * place: a random permutation of 256 has no fixed point with probability
     * about 1/e, so 16 seeds without one would be a 1-in-10^7 event. The
     * off-by-one j in [0, i) (Sattolo's algorithm) makes one 256-cycle, never
     * a fixed point. */
    int fixed = 0;
    for (uint64_t seed = 1; seed <= 16; seed++) {
        noise_perm q;
        noise_perm_init(&q, seed);
        for (int i = 0; i < 256; i++)
            fixed += q.p[i] == i;
    }
    CHECK(fixed > 0, "16 seeded permutations without a fixed point: not a uniform shuffle");

    /* Zero at every integer lattice point (also negative and far ones). */
    int nz = 0;
    for (int i = -6; i <= 6; i++)
        for (int j = -6; j <= 6; j++)
            for (int k = -6; k <= 6; k++)
                nz += noise_perlin3(&a, i * 37, j * 3 + 1000, k - 1e6) != 0;
    CHECK(nz == 0, "%d lattice points with non-zero noise", nz);

    /* Bounded: |n| <= 1.04 for 3-D improved noise (we check 1.05), and not
     * degenerate (values of both signs above 0.5 in magnitude occur). */
    random_points(3, 50);
    double mx = -9, mn = 9;
    int differ = 0;
    for (int i = 0; i < NPTS; i++) {
        double v = noise_perlin3(&a, px[i], py[i], pz[i]);
        mx = v > mx ? v : mx;
        mn = v < mn ? v : mn;
        differ += v != noise_perlin3(&b, px[i], py[i], pz[i]);
    }
    CHECK(mx <= 1.05 && mn >= -1.05, "range [%g, %g]", mn, mx);
    CHECK(mx > 0.5 && mn < -0.5, "range [%g, %g] too small", mn, mx);
    CHECK(differ > NPTS * 9 / 10, "seeds 1 and 2 agree at %d of %d points", NPTS - differ, NPTS);

    /* Lipschitz. n = sum_c w_c (g_c . (p - c)); per axis the fade
     * derivative is at most 30/16 = 1.875 and |g . (p - c)| <= 2, the two
     * weights along an axis give 2 * 1.875 * 2 = 7.5, plus sum w |g_x| <= 1:
     * |dn/dx| <= 8.5, |grad n| <= 8.5 sqrt(3) < 14.8. Steps that cross cell
     * faces (x near an integer) would show a discontinuity as a huge ratio. */
    double worst = 0;
    for (int i = 0; i < NPTS; i++) {
        double x = px[i], y = py[i], z = pz[i];
        if (i % 4 == 0)
            x = floor(x) - 5e-8; /* straddle a face */
        double h = 1e-7, dx = h * 0.6, dy = -h * 0.48, dz = h * 0.64;
        double d = fabs(noise_perlin3(&a, x + dx, y + dy, z + dz) - noise_perlin3(&a, x, y, z));
        double ratio = d / sqrt(dx * dx + dy * dy + dz * dz);
        worst = ratio > worst ? ratio : worst;
    }
    CHECK(worst < 14.8, "Lipschitz ratio %g", worst);
    CHECK(worst > 0.1, "noise looks constant (ratio %g)", worst);

    /* Large and non-finite coordinates: defined, bounded. */
    double big = noise_perlin3(&a, 1e15 + 0.5, -3e12 + 0.25, 7.5);
    CHECK(isfinite(big) && fabs(big) <= 1.05, "far value %g", big);
    CHECK(isnan(noise_perlin3(&a, NAN, 0.5, 0.5)), "NaN in, NaN out");
    CHECK(isnan(noise_perlin3(&a, INFINITY, 0.5, 0.5)), "inf in, NaN out");
}

static void test_octaves(void)
{
    noise_perm np;
    noise_perm_reference(&np);
    /* Turbulence = sum |n(2^i p)| / 2^i. At p = (1.57, 21, 3.5) octave 1 is
     * n(3.14, 42, 7) = 0.13691995878400012 (published), octave 0 comes from
     * the reference transcription, octave 2 likewise at 4p. */
    double n0 = noise_reference3(1.57, 21, 3.5), n2 = noise_reference3(6.28, 84, 14);
    double t2 = fabs(n0) + 0.13691995878400012 / 2;
    CHECK_NEAR(noise_turbulence3(&np, 2, 1.57, 21, 3.5), t2, 1e-15, "turbulence 2 octaves");
    CHECK_NEAR(noise_turbulence3(&np, 3, 1.57, 21, 3.5), t2 + fabs(n2) / 4, 1e-15,
               "turbulence 3 octaves");
    CHECK(noise_turbulence3(&np, 0, 1.57, 21, 3.5) == 0, "0 octaves");
    /* fBm(lac 2, gain 0.5) differs from turbulence only by the abs. */
    CHECK_NEAR(noise_fbm3(&np, 2, 2, 0.5, 1.57, 21, 3.5), n0 + 0.5 * 0.13691995878400012, 1e-15,
               "fbm 2 octaves");
    /* lacunarity 3, gain 0.25: n(p) + 0.25 n(3p) + 0.0625 n(9p). */
    double f3 = noise_reference3(0.3, 0.7, 1.1) + 0.25 * noise_reference3(0.9, 2.1, 3.3) +
                0.0625 * noise_reference3(2.7, 6.3, 9.9);
    CHECK_NEAR(noise_fbm3(&np, 3, 3, 0.25, 0.3, 0.7, 1.1), f3, 1e-14, "fbm lac 3");

    /* Turbulence of 6 octaves lies in [0, 1.05 * (2 - 1/32)]. */
    noise_perm s;
    noise_perm_init(&s, 99);
    random_points(5, 10);
    double mx = 0;
    int neg = 0;
    for (int i = 0; i < NPTS; i++) {
        double t = noise_turbulence3(&s, 6, px[i], py[i], pz[i]);
        neg += !(t >= 0);
        mx = t > mx ? t : mx;
    }
    CHECK(neg == 0, "%d negative turbulence values", neg);
    CHECK(mx <= 1.05 * (2 - 1.0 / 32) && mx > 0.3, "turbulence max %g", mx);
}

static void test_blocks(void)
{
    noise_perm np;
    noise_perm_init(&np, 12345);
    random_points(11, 1000);
    for (int i = 0; i < 100; i++) /* include far points and lattice points */
        px[i] = i < 50 ? 1e11 * (i + 0.37) : (double)(i - 75);
    noise_perlin3_block(&np, NPTS, px, py, pz, o1);
    for (int i = 0; i < NPTS; i++)
        o2[i] = noise_perlin3(&np, px[i], py[i], pz[i]);
    CHECK(memcmp(o1, o2, sizeof o1) == 0, "block perlin differs from scalar");
    noise_fbm3_block(&np, 5, 2.1, 0.55, NPTS, px, py, pz, o1);
    for (int i = 0; i < NPTS; i++)
        o2[i] = noise_fbm3(&np, 5, 2.1, 0.55, px[i], py[i], pz[i]);
    CHECK(memcmp(o1, o2, sizeof o1) == 0, "block fbm differs from scalar");
    noise_turbulence3_block(&np, 6, NPTS, px, py, pz, o1);
    for (int i = 0; i < NPTS; i++)
        o2[i] = noise_turbulence3(&np, 6, px[i], py[i], pz[i]);
    CHECK(memcmp(o1, o2, sizeof o1) == 0, "block turbulence differs from scalar");
    /* n = 0 and odd n work */
    noise_perlin3_block(&np, 0, px, py, pz, o1);
    noise_perlin3_block(&np, 3, px + 200, py + 200, pz + 200, o1);
    CHECK(o1[2] == noise_perlin3(&np, px[202], py[202], pz[202]), "short block");
}

/* Every SIMD level this machine runs (noise_simd_best and below) against the
 * scalar functions, bit for bit: coherent and scattered points, negative
 * ones, lattice points and half-integers, values near ±2^30 (the fast
 * lattice path's bound), huge, infinite and NaN coordinates, fractions
 * near the AVX2 kernel's 2^-30 bound and tiny or subnormal ones, in runs of
 * one kind and mixed into the same groups, block lengths that leave a tail
 * of 1..7. */
static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* A coordinate whose fraction is at the AVX2 kernel's fast-way bound 2^-30
 * (noise_simd.c) or just either side of it, tiny or subnormal, or 1 (the
 * fraction of -1e-300 rounds to 1), or an ordinary one. In every other
 * group of eight only the kinds the fast way takes (fraction >= 2^-30), so
 * that some groups go the fast way right at the bound and the rest the
 * exact way. */
static double near_lattice(double u, size_t i)
{
    static const int fast[5] = {0, 2, 4, 6, 7};
    double cell = floor(u * 64) - 32; /* |cell| <= 32: ulp <= 2^-47 */
    switch ((i / 8) % 2 ? (int)(i % 8) : fast[i % 5]) {
    case 0: return cell + 0x1p-30;
    case 1: return cell + (0x1p-30 - 0x1p-47);
    case 2: return cell + (0x1p-30 + 0x1p-47);
    case 3: return cell == 0 ? 4.9e-324 * (1 + floor(u * 1000)) : cell + 1e-300;
    case 4: return -1e-300 * (u + 0.5);
    case 5: return cell - 0x1p-60;
    case 6: return cell + (u + 1) * 0x1p-20;
    default: return u * 7 - 3;
    }
}

static void test_simd_levels(void)
{
    enum { N = 20003 };
    static double x[N], y[N], z[N], out[N];
    rng r;
    rng_init(&r, 77, 1);
    for (size_t i = 0; i < N; i++) {
        double u = rng_uniform(&r), v = rng_uniform(&r), w = rng_uniform(&r);
        /* the first half in runs of 16 of one kind (whole groups of the 8-point
         * kernels take the vector path), the second half mixed point by point */
        switch (i < N / 2 ? i / 16 % 9 : i % 9) {
        case 0: x[i] = u * 10, y[i] = v * 10, z[i] = w * 10; break;           /* coherent-ish */
        case 1: x[i] = (u - .5) * 1e6, y[i] = (v - .5) * 1e6, z[i] = w * -3e5; break; /* scattered */
        case 2: x[i] = floor(u * 40) - 20, y[i] = floor(v * 40) * 0.5, z[i] = -0.0; break; /* lattice */
        case 3: x[i] = 1073741824.0 * (u < .5 ? 1 : -1) - (v - .5) * 4, y[i] = w, z[i] = u; break; /* ±2^30 */
        case 4: x[i] = u * 1e300, y[i] = v, z[i] = w; break;
        case 5: x[i] = u < .3 ? INFINITY : u < .6 ? -INFINITY : NAN, y[i] = v, z[i] = w; break;
        case 7: /* fractions at and around the AVX2 fast way's 2^-30 bound, subnormal
                 * and tiny ones, fractions that round to 1 (noise_simd.c) */
            x[i] = near_lattice(u, i), y[i] = near_lattice(v, i + 1), z[i] = near_lattice(w, i + 2);
            break;
        default: x[i] = (u - .5) * 300, y[i] = (v - .5) * 300, z[i] = (w - .5) * 300; break;
        }
    }
    noise_perm np;
    noise_perm_init(&np, 12345);
    int best = noise_simd_best();
    CHECK(best >= NOISE_LEVEL_SSE2, "an x86-64 machine has at least SSE2 (level %d)", best);
    int bl = noise_block_level();
    CHECK(bl == (best >= NOISE_LEVEL_AVX2 ? best : NOISE_LEVEL_SCALAR),
          "the blocks use the best level but SSE2 (per-point loop instead): %d of best %d", bl, best);
    for (int level = NOISE_LEVEL_SCALAR; level <= best; level++) {
        /* 8, 23, 47, 57: fewer groups than the AVX2 pipeline is deep (noise_simd.c) */
        size_t lens[9] = {N, N - 1, N - 2, N - 5, 5, 8, 23, 47, 57};
        for (int li = 0; li < 9; li++) {
            size_t n = lens[li];
            long bad = 0;
            noise_perlin3_block_at(level, &np, n, x, y, z, out);
            for (size_t i = 0; i < n; i++)
                bad += !same_bits(out[i], noise_perlin3(&np, x[i], y[i], z[i]));
            CHECK(bad == 0, "level %d, n %zu: %ld perlin values differ from the scalar ones", level, n, bad);
            bad = 0;
            noise_fbm3_block_at(level, &np, 6, 2.0, 0.5, n, x, y, z, out);
            for (size_t i = 0; i < n; i++)
                bad += !same_bits(out[i], noise_fbm3(&np, 6, 2.0, 0.5, x[i], y[i], z[i]));
            CHECK(bad == 0, "level %d, n %zu: %ld fBm values differ", level, n, bad);
            bad = 0;
            noise_fbm3_block_at(level, &np, 3, 1.9, 0.6, n, x, y, z, out);
            for (size_t i = 0; i < n; i++)
                bad += !same_bits(out[i], noise_fbm3(&np, 3, 1.9, 0.6, x[i], y[i], z[i]));
            CHECK(bad == 0, "level %d, n %zu: %ld fBm (1.9, 0.6) values differ", level, n, bad);
            bad = 0;
            noise_turbulence3_block_at(level, &np, 5, n, x, y, z, out);
            for (size_t i = 0; i < n; i++)
                bad += !same_bits(out[i], noise_turbulence3(&np, 5, x[i], y[i], z[i]));
            CHECK(bad == 0, "level %d, n %zu: %ld turbulence values differ", level, n, bad);
        }
    }
    /* the reference value through the blocks (noise.h) */
    noise_perm_reference(&np);
    double rx[5] = {3.14, 3.14, 3.14, 3.14, 3.14}, ry[5] = {42, 42, 42, 42, 42}, rz[5] = {7, 7, 7, 7, 7};
    for (int level = NOISE_LEVEL_SCALAR; level <= best; level++) {
        noise_perlin3_block_at(level, &np, 5, rx, ry, rz, out);
        CHECK(out[0] == 0.13691995878400012 && out[4] == 0.13691995878400012, "level %d: n(3.14, 42, 7) = %.17g",
              level, out[0]);
    }
}

/* Why the AVX2 kernel's fast way needs its fraction guard (noise_simd.c): it
 * computes twice perlin()'s values and halves at the end, which is exact
 * only while no operation rounds in the subnormal range. By hand, with
 * Perlin's table at (0.5, y, -0.5), y = 1.25·2^-356 = 5·2^-358 (cell
 * X = Y = 0, Z = 255; fractions 0.5, y, 0.5; u = w = fade(0.5) = 0.5,
 * v = fade(y) = 125·2^-1074 · 10 = 1250·2^-1074 exactly, a subnormal): the
 * gradients are, at z, 12 (x + y), 15 (-y - z), 2 (x - y), 13 (-y + z) and
 * at z - 1, 4 (x + z), 6 (x - z), 12, 0 (x + y), so with y absorbed into
 * 0.5 and 1: g = 0.5, -0.5, 1.5, 1.5 and 0, 0, -0.5, -1.5; the x lerps give
 * 0 and 1.5, 0 and -1; c0 = 1.5 v = 1875·2^-1074, c1 = -v = -1250·2^-1074,
 * and n = c0 + 0.5 (c1 - c0) = 1875 - 1562.5 -> 313 (the half rounds to
 * even, 1562) times 2^-1074. The doubled computation halves -6250 exactly
 * to -3125, gets 625, and its final halving rounds 312.5 to 312: wrong by
 * one unit. Every level must give 313·2^-1074, alone in a group and mixed
 * with ordinary points. */
static void test_subnormal_halving(void)
{
    const double y = 0x1.4p-356, want = 0x139p-1074;
    CHECK(noise_reference3(0.5, y, -0.5) == want, "ref(0.5, 1.25*2^-356, -0.5) = %a, want %a",
          noise_reference3(0.5, y, -0.5), want);
    noise_perm np;
    noise_perm_reference(&np);
    CHECK(noise_perlin3(&np, 0.5, y, -0.5) == want, "ours(0.5, 1.25*2^-356, -0.5) = %a",
          noise_perlin3(&np, 0.5, y, -0.5));
    double xs[16], ys[16], zs[16], out[16];
    for (int i = 0; i < 16; i++) { /* a group of the point alone, one with it in lane 3 */
        int it = i < 8 || i == 11;
        xs[i] = it ? 0.5 : 0.3 + i, ys[i] = it ? y : 1.7 * i, zs[i] = it ? -0.5 : 2.9 - i;
    }
    for (int level = NOISE_LEVEL_SCALAR; level <= noise_simd_best(); level++) {
        noise_perlin3_block_at(level, &np, 16, xs, ys, zs, out);
        int bad = 0;
        for (int i = 0; i < 16; i++)
            bad += !same_bits(out[i], noise_perlin3(&np, xs[i], ys[i], zs[i]));
        CHECK(bad == 0 && out[0] == want && out[7] == want && out[11] == want,
              "level %d: n(0.5, 1.25*2^-356, -0.5) = %a, %a, %a (want %a); %d differ", level, out[0],
              out[7], out[11], want, bad);
    }
}

/* The fast path of perlin() (paired lanes, pair loads, the coefficient pair
 * table) against noise_perlin_far, the point-by-point reference order with
 * 16-entry gradient tables and the general floor, bit for bit, including
 * the signs of zeros: integers, -0, half-integers, negatives, values just
 * below the 2^30 bound of the fast path. */
static void test_fast_path(void)
{
    noise_perm np;
    noise_perm_init(&np, 4242);
    rng r;
    rng_init(&r, 31, 2);
    long bad = 0, n = 0;
    for (int i = 0; i < 200000; i++) {
        double c[3];
        for (int k = 0; k < 3; k++) {
            double u = rng_uniform(&r), v = rng_uniform(&r);
            switch ((i + k) % 7) {
            case 0: c[k] = (u - .5) * 600; break;
            case 1: c[k] = floor((u - .5) * 600); break;
            case 2: c[k] = u < .5 ? -0.0 : 0.0; break;
            case 3: c[k] = floor((u - .5) * 80) * 0.5; break;
            case 4: c[k] = (u < .5 ? -1 : 1) * (1073741824.0 - v * 3); break;
            case 5: c[k] = (u - .5) * 1e-300; break;
            default: c[k] = (u - .5) * 2e7; break;
            }
        }
        double a = noise_perlin3(&np, c[0], c[1], c[2]), b = noise_perlin_far(np.p, c[0], c[1], c[2]);
        bad += memcmp(&a, &b, sizeof a) != 0;
        n++;
    }
    CHECK(bad == 0, "%ld of %ld fast-path values differ from noise_perlin_far", bad, n);
    /* the pair table holds the reference coefficients (noise.h) */
    static const double gx[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, 0, -1, 0};
    static const double gy[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1};
    static const double gz[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 1, 0, -1};
    int tbad = 0;
    for (int i = 0; i < 256; i++) {
        const noise_gpair *g = &noise_gpairs[i];
        int lo = i & 15, hi = i >> 4;
        tbad += g->gx[0] != gx[lo] || g->gx[1] != gx[hi] || g->gy[0] != gy[lo] ||
                g->gy[1] != gy[hi] || g->gz[0] != gz[lo] || g->gz[1] != gz[hi];
    }
    CHECK(tbad == 0, "%d pair-table entries differ from the gradient table", tbad);
}

int main(void)
{
    test_reference();
    test_properties();
    test_octaves();
    test_blocks();
    test_fast_path();
    test_simd_levels();
    test_subnormal_halving();
    return check_done("test_noise");
}
