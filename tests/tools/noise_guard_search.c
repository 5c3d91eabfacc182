/* noise_guard_search.c — the search behind test_noise's
 * test_subnormal_halving: the AVX2 noise kernel (noise_simd.c) against the
 * scalar perlin() and fBm, bit for bit, on inputs chosen to stress the fast
 * way's exactness argument. Not part of the build; run by hand:
 *
 *   make build/libfracrt.a
 *   sed 's/(least < lim)) ?/(least < lim)) \& 0 ?/' runtime/noise_simd.c > /tmp/simd_noguard.c
 *   cc -std=c11 -O2 -ffp-contract=off -Iruntime -c /tmp/simd_noguard.c -o /tmp/noguard.o
 *   cc -std=c11 -O2 -ffp-contract=off -Iruntime tests/tools/noise_guard_search.c \
 *      /tmp/noguard.o build/libfracrt.a -lm -o /tmp/search      (guard off)
 *   cc ... tests/tools/noise_guard_search.c build/libfracrt.a -lm -o /tmp/search  (as built)
 *   /tmp/search ROUNDS MODE SEED      (ROUNDS of 4096 points; MODE 0 stressed, 1 random bits)
 *
 * Stressed coordinates: a cell (0, -1, a small or a random one, or near
 * 2^30 and 2^31) plus a fraction that is 0, tiny (2^-30 down to subnormal),
 * in the range where fade() is subnormal (2^-330 .. 2^-370), a multiple of
 * 1/8, random, the previous coordinate's, just below 1, or 2^-1 .. 2^-60;
 * some negated. Prints the number of differing values (those with a -0
 * coordinate apart) and the largest least positive fraction among the others.
 * Session 8: guard off, 5,470 of 1.02·10^8 stressed points differ (448 with
 * a -0 coordinate; the others all have a fraction below 2^-265), 84 fBm
 * values; as built, none of 2.05·10^8. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "noise.h"
#include "noise_impl.h"

static uint64_t state = 88172645463325252ull;
static uint64_t rnd(void) /* xorshift64 */
{
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return state;
}
static double uni(void) { return (double)(rnd() >> 11) * 0x1p-53; }

static double fraction(int kind, double prev)
{
    switch (kind) {
    case 0: return 0;
    case 1: return ldexp(1 + uni(), -(int)(30 + rnd() % 1045));
    case 2: return ldexp(1 + uni(), -(int)(330 + rnd() % 40));
    case 3: return (double)(rnd() % 8) / 8;
    case 4: return uni();
    case 5: return prev;
    case 6: return 1 - ldexp((double)(1 + rnd() % 16), -53);
    case 7: return ldexp(1 + uni(), -(int)(1 + rnd() % 60));
    default: return 0.5;
    }
}

static double coordinate(int mode, double prev)
{
    if (mode == 1) {
        uint64_t b = rnd();
        double v;
        memcpy(&v, &b, sizeof v);
        return isfinite(v) ? v : 0.25;
    }
    double f = fraction((int)(rnd() % 9), prev);
    int r = (int)(rnd() % 4);
    double cell = r == 0 ? 0 : r == 1 ? (double)((int)(rnd() % 512) - 256) : r == 2 ? -1 : (double)(rnd() % 8);
    if (cell != 0 && f != 0 && f < 0x1p-40) /* the least fraction a cell this size has */
        f = 0x1p-52 * (double)(1 + rnd() % 4);
    double c = cell + f;
    if (rnd() % 16 == 0)
        c = -c;
    if (rnd() % 64 == 0)
        c = (rnd() & 1 ? 1073741824.0 : 2147483648.0) - f * 4;
    return c;
}

static int has_negative_zero(double x, double y, double z)
{
    return (x == 0 && signbit(x)) || (y == 0 && signbit(y)) || (z == 0 && signbit(z));
}

int main(int argc, char **argv)
{
    long rounds = argc > 1 ? atol(argv[1]) : 1000;
    int mode = argc > 2 ? atoi(argv[2]) : 0;
    if (argc > 3)
        state ^= (uint64_t)atoll(argv[3]) * 0x9E3779B97F4A7C15ull;
    enum { N = 4096 };
    static double x[N], y[N], z[N], out[N];
    noise_perm np;
    noise_perm_init(&np, 12345);
    long bad = 0, bad_negzero = 0, bad_fbm = 0, total = 0;
    double largest = 0;
    for (long it = 0; it < rounds; it++) {
        for (int i = 0; i < N; i++) {
            x[i] = coordinate(mode, 0.5);
            y[i] = coordinate(mode, x[i] - floor(x[i]));
            z[i] = coordinate(mode, y[i] - floor(y[i]));
        }
        noise_perlin3_block_at(NOISE_LEVEL_AVX2, &np, N, x, y, z, out);
        for (int i = 0; i < N; i++, total++) {
            double e = noise_perlin3(&np, x[i], y[i], z[i]);
            if (memcmp(&e, &out[i], sizeof e) == 0)
                continue;
            if (bad++ < 5)
                printf("%a %a %a: perlin %a, AVX2 %a\n", x[i], y[i], z[i], e, out[i]);
            if (has_negative_zero(x[i], y[i], z[i])) {
                bad_negzero++;
                continue;
            }
            double f[3] = {x[i] - floor(x[i]), y[i] - floor(y[i]), z[i] - floor(z[i])}, least = 1;
            for (int k = 0; k < 3; k++)
                if (f[k] > 0 && f[k] < least)
                    least = f[k];
            if (least > largest)
                largest = least;
        }
        if (it % 4 == 0)
            for (int oct = 3; oct <= 6; oct += 3) {
                noise_fbm3_block_at(NOISE_LEVEL_AVX2, &np, oct, 2.0, 0.5, N, x, y, z, out);
                for (int i = 0; i < N; i++) {
                    double e = noise_fbm3(&np, oct, 2.0, 0.5, x[i], y[i], z[i]);
                    bad_fbm += memcmp(&e, &out[i], sizeof e) != 0;
                }
            }
    }
    printf("%ld of %ld perlin values differ (%ld with a -0 coordinate; the others' largest least "
           "fraction %a), %ld fBm values\n", bad, total, bad_negzero, largest, bad_fbm);
    return bad != 0 || bad_fbm != 0;
}
