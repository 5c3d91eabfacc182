/* noise.c — Perlin's improved noise (2002), fBm, turbulence. See noise.h. */
#include "noise.h"

#include <math.h>

#include "noise_impl.h"
#include "rng.h"
#include "rt.h"

/* Perlin's permutation from the 2002 reference implementation
 * (https://mrl.cs.nyu.edu/~perlin/noise/), a data table. */
static const uint8_t ref_perm[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,
    103, 30,  69,  142, 8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,
    0,   26,  197, 62,  94,  252, 219, 203, 117, 35,  11,  32,  57,  177, 33,  88,  237, 149,
    56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165, 71,  134, 139, 48,  27,  166,
    77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,  55,  46,
    245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187,
    208, 89,  18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186,
    3,   64,  52,  217, 226, 250, 124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212,
    207, 206, 59,  227, 47,  16,  58,  17,  182, 189, 28,  42,  223, 183, 170, 213, 119, 248,
    152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,   129, 22,  39,  253,
    19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107,
    49,  192, 214, 31,  181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,
    150, 254, 138, 236, 205, 93,  222, 114, 67,  29,  24,  72,  243, 141, 128, 195, 78,  66,
    215, 61,  156, 180,
};

/* noise_impl.h's pair table: entry h0 | h1 << 4 holds the coefficients of
 * gradients h0 and h1, lane 0 and lane 1. */
#define GP(i)                                                                                    \
    {{NOISE_GX((i) & 15), NOISE_GX((i) >> 4)},                                                   \
     {NOISE_GY((i) & 15), NOISE_GY((i) >> 4)},                                                   \
     {NOISE_GZ((i) & 15), NOISE_GZ((i) >> 4)}}
#define GP16(hi)                                                                                 \
    GP(16 * (hi) + 0), GP(16 * (hi) + 1), GP(16 * (hi) + 2), GP(16 * (hi) + 3),                  \
        GP(16 * (hi) + 4), GP(16 * (hi) + 5), GP(16 * (hi) + 6), GP(16 * (hi) + 7),              \
        GP(16 * (hi) + 8), GP(16 * (hi) + 9), GP(16 * (hi) + 10), GP(16 * (hi) + 11),            \
        GP(16 * (hi) + 12), GP(16 * (hi) + 13), GP(16 * (hi) + 14), GP(16 * (hi) + 15)
const noise_gpair noise_gpairs[256] = {GP16(0), GP16(1),  GP16(2),  GP16(3),  GP16(4),  GP16(5),
                                       GP16(6), GP16(7),  GP16(8),  GP16(9),  GP16(10), GP16(11),
                                       GP16(12), GP16(13), GP16(14), GP16(15)};
#undef GP
#undef GP16

/* floor(v) and its lattice index mod 256 for any v, never converting an
 * out-of-range double to int (the fmod is exact on the integral double). */
static double lattice(double v, unsigned *ix)
{
    if (fabs(v) < 1073741824.0) {
        int i = (int)v;
        i -= v < (double)i;
        *ix = (unsigned)i & 255u;
        return (double)i;
    }
    double f = floor(v);
    if (isfinite(f))
        *ix = (unsigned)(int)fmod(f, 256.0) & 255u;
    else
        *ix = 0;
    return f;
}

static double grad(unsigned h, double x, double y, double z)
{
    static const double gx[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, 0, -1, 0};
    static const double gy[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1};
    static const double gz[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 1, 0, -1};
    h &= 15u;
    return gx[h] * x + gy[h] * y + gz[h] * z;
}

static double lerp(double t, double a, double b) { return a + t * (b - a); }

/* The reference noise() point by point, for the coordinates perlin() does
 * not take (|v| >= 2^30, NaN, infinity): same operations, same order. */
double noise_perlin_far(const uint8_t *p, double x, double y, double z)
{
    unsigned X, Y, Z;
    x -= lattice(x, &X);
    y -= lattice(y, &Y);
    z -= lattice(z, &Z);
    double u = fade(x), v = fade(y), w = fade(z);
    unsigned A = p[X] + Y, AA = p[A] + Z, AB = p[A + 1] + Z;
    unsigned B = p[X + 1] + Y, BA = p[B] + Z, BB = p[B + 1] + Z;
    double x1 = x - 1, y1 = y - 1, z1 = z - 1;
    return lerp(w,
                lerp(v, lerp(u, grad(p[AA], x, y, z), grad(p[BA], x1, y, z)),
                     lerp(u, grad(p[AB], x, y1, z), grad(p[BB], x1, y1, z))),
                lerp(v, lerp(u, grad(p[AA + 1], x, y, z1), grad(p[BA + 1], x1, y, z1)),
                     lerp(u, grad(p[AB + 1], x, y1, z1), grad(p[BB + 1], x1, y1, z1))));
}

/* p[512..1023] from p[0..511] (noise.h) */
static void perm_pairs(noise_perm *np)
{
    for (int i = 0; i < 511; i++)
        np->p[512 + i] = (uint8_t)((np->p[i] & 15) | (np->p[i + 1] & 15) << 4);
    np->p[1023] = np->p[511] & 15;
}

void noise_perm_reference(noise_perm *np)
{
    for (int i = 0; i < 256; i++)
        np->p[i] = np->p[i + 256] = ref_perm[i];
    perm_pairs(np);
}

/* Uniform integer in [0, n), n >= 1, without modulo bias. */
static unsigned bounded(rng *r, unsigned n)
{
    uint64_t rem = (UINT64_MAX % n + 1u) % n; /* 2^64 mod n */
    for (;;) {
        uint64_t v = rng_next(r);
        if (rem == 0 || v < (uint64_t)0 - rem)
            return (unsigned)(v % n);
    }
}

void noise_perm_init(noise_perm *np, uint64_t seed)
{
    rng r;
    rng_init(&r, seed, 0x6e6f697365ull);
    for (int i = 0; i < 256; i++)
        np->p[i] = (uint8_t)i;
    for (unsigned i = 255; i > 0; i--) { /* Fisher–Yates */
        unsigned j = bounded(&r, i + 1);
        uint8_t t = np->p[i];
        np->p[i] = np->p[j];
        np->p[j] = t;
    }
    for (int i = 0; i < 256; i++)
        np->p[i + 256] = np->p[i];
    perm_pairs(np);
}

double noise_perlin3(const noise_perm *np, double x, double y, double z)
{
    return perlin(np->p, x, y, z);
}

/* The level the blocks use: the best the machine has, except SSE2, whose
 * four-lane kernel measured slower than the per-point loop's paired lanes
 * (bench/noise_bench.c). The choice never changes a value. */
int noise_block_level(void)
{
    int best = noise_simd_best();
    return best >= NOISE_LEVEL_AVX2 ? best : NOISE_LEVEL_SCALAR;
}

void noise_perlin3_block_at(int level, const noise_perm *np, size_t n, const double *x,
                            const double *y, const double *z, double *out)
{
    noise_kernel(level, np->p, n, x, y, z, 1, 1, NOISE_SET, out);
}

void noise_perlin3_block(const noise_perm *np, size_t n, const double *x, const double *y,
                         const double *z, double *out)
{
    noise_perlin3_block_at(noise_block_level(), np, n, x, y, z, out);
}

double noise_fbm3(const noise_perm *np, int octaves, double lacunarity, double gain, double x,
                  double y, double z)
{
    double s = 1, a = 1, sum = 0;
    for (int o = 0; o < octaves; o++) {
        sum += a * perlin(np->p, x * s, y * s, z * s);
        s *= lacunarity;
        a *= gain;
    }
    return sum;
}

void noise_fbm3_block_at(int level, const noise_perm *np, int octaves, double lacunarity,
                         double gain, size_t n, const double *x, const double *y, const double *z,
                         double *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = 0;
    double s = 1, a = 1;
    for (int o = 0; o < octaves; o++) {
        noise_kernel(level, np->p, n, x, y, z, s, a, NOISE_ADD, out);
        s *= lacunarity;
        a *= gain;
    }
}

void noise_fbm3_block(const noise_perm *np, int octaves, double lacunarity, double gain, size_t n,
                      const double *x, const double *y, const double *z, double *out)
{
    noise_fbm3_block_at(noise_block_level(), np, octaves, lacunarity, gain, n, x, y, z, out);
}

double noise_turbulence3(const noise_perm *np, int octaves, double x, double y, double z)
{
    double s = 1, a = 1, sum = 0;
    for (int o = 0; o < octaves; o++) {
        sum += a * fabs(perlin(np->p, x * s, y * s, z * s));
        s *= 2;
        a *= 0.5;
    }
    return sum;
}

void noise_turbulence3_block_at(int level, const noise_perm *np, int octaves, size_t n,
                                const double *x, const double *y, const double *z, double *out)
{
    for (size_t i = 0; i < n; i++)
        out[i] = 0;
    double s = 1, a = 1;
    for (int o = 0; o < octaves; o++) {
        noise_kernel(level, np->p, n, x, y, z, s, a, NOISE_ADD_ABS, out);
        s *= 2;
        a *= 0.5;
    }
}

void noise_turbulence3_block(const noise_perm *np, int octaves, size_t n, const double *x,
                             const double *y, const double *z, double *out)
{
    noise_turbulence3_block_at(noise_block_level(), np, octaves, n, x, y, z, out);
}

/* ---- The 2002 reference, transcribed literally (baseline and cross-check). */

static double ref_fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static double ref_lerp(double t, double a, double b) { return a + t * (b - a); }
static double ref_grad(int hash, double x, double y, double z)
{
    int h = hash & 15;
    double u = h < 8 ? x : y, v = h < 4 ? y : h == 12 || h == 14 ? x : z;
    return ((h & 1) == 0 ? u : -u) + ((h & 2) == 0 ? v : -v);
}

static int ref_p(int i) { return ref_perm[i & 255]; }

double noise_reference3(double x, double y, double z)
{
    int X = (int)floor(x) & 255, Y = (int)floor(y) & 255, Z = (int)floor(z) & 255;
    x -= floor(x);
    y -= floor(y);
    z -= floor(z);
    double u = ref_fade(x), v = ref_fade(y), w = ref_fade(z);
    int A = ref_p(X) + Y, AA = ref_p(A) + Z, AB = ref_p(A + 1) + Z, B = ref_p(X + 1) + Y,
        BA = ref_p(B) + Z, BB = ref_p(B + 1) + Z;
    return ref_lerp(
        w,
        ref_lerp(v,
                 ref_lerp(u, ref_grad(ref_p(AA), x, y, z), ref_grad(ref_p(BA), x - 1, y, z)),
                 ref_lerp(u, ref_grad(ref_p(AB), x, y - 1, z),
                          ref_grad(ref_p(BB), x - 1, y - 1, z))),
        ref_lerp(v,
                 ref_lerp(u, ref_grad(ref_p(AA + 1), x, y, z - 1),
                          ref_grad(ref_p(BA + 1), x - 1, y, z - 1)),
                 ref_lerp(u, ref_grad(ref_p(AB + 1), x, y - 1, z - 1),
                          ref_grad(ref_p(BB + 1), x - 1, y - 1, z - 1))));
}
