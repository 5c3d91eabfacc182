/* noise.h — Perlin's improved gradient noise (2002), fBm and turbulence.
 *
 * Noise. noise_perlin3 is Ken Perlin's "Improving Noise" (SIGGRAPH 2002),
 * the noise the hypertexture of seed 001 (Perlin & Hoffert 1989) is built
 * on: integer lattice, a pseudo-random gradient at each lattice point chosen
 * by hashing the point through a permutation P of 0..255 (doubled to 512
 * entries so that P[P[P[X]+Y]+Z] needs no masking), the quintic fade
 * f(t) = 6t^5 - 15t^4 + 10t^3, and trilinear blending of the eight corner
 * dot products:
 *     h   = P[P[P[X]+Y]+Z] & 15          (X, Y, Z = floor(p) mod 256)
 *     g_h = one of 12 edge directions of the cube (±1, ±1, 0) etc.; 16
 *           table entries, the 4 extra repeating (1,1,0), (-1,1,0),
 *           (0,-1,1), (0,-1,-1) exactly as the reference grad() does
 *     n(p) = lerp(w, lerp(v, lerp(u, ...)))    u, v, w = f(fractional part)
 * Values lie in about [-1.04, 1.04]; n = 0 at every integer lattice point.
 * We evaluate grad() with gradient coefficients (gx*x + gy*y + gz*z, products
 * by ±1 and 0, exact) instead of the reference's branches: the same value for
 * every input, and no data-dependent branches, which matters on scattered
 * points (octave sums are scattered): see DESIGN.md, "Facts measured". The
 * per-point code (noise_impl.h) pairs the corners (i, j, 0) and (i, j, 1) in
 * two-lane vectors, loads P[i] and P[i+1] together, takes the last level of
 * the hash chain from a second table of the pairs' gradient numbers (kept
 * after P in noise_perm) and the coefficients of a pair from one 256-entry
 * table; every lane does the reference's operations
 * in its order, so the value is bit for bit that of the plain formulation
 * (noise_perlin_far, which also takes the far and non-finite coordinates).
 *
 * Permutation. noise_perm_init makes P from a seed by a Fisher–Yates shuffle
 * driven by rng stream (seed, 0x6e6f697365 "noise"), with unbiased bounded
 * integers from unsigned arithmetic only. noise_perm_reference gives
 * Perlin's own table, with which noise_perlin3 equals the reference
 * (noise_reference3, a plain transcription of the 2002 Java code, kept for
 * the benchmark baseline and the cross-check): n(3.14, 42, 7) =
 * 0.13691995878400012.
 *
 * Large and non-finite coordinates. The lattice index is floor(p) reduced
 * mod 256 exactly (fmod on the integral double when |p| >= 2^30), so no
 * float-to-int conversion can overflow. A NaN coordinate gives NaN; an
 * infinite one gives NaN too (its fractional part is undefined).
 *
 * Sums of octaves (same permutation at every octave, as Perlin):
 *     fBm:        sum_{i<oct} gain^i * n(lac^i * p)
 *     turbulence: sum_{i<oct} |n(2^i * p)| / 2^i        (Perlin 1985/1989)
 * (libnoise's "turbulence" is domain warping, a different thing.) The
 * scaled coordinates of octave i are computed as p * s_i with s_0 = 1,
 * s_{i+1} = s_i * lac, and the amplitude a_{i+1} = a_i * gain; the sum is
 * accumulated in octave order, so scalar and block versions agree bit for
 * bit.
 *
 * Blocks. The *_block functions evaluate n points given as coordinate
 * arrays (any n, including n > RT_BLOCK) and give exactly the scalar
 * function's values. All functions are pure and reentrant; a noise_perm is
 * read-only after init and can be shared between threads.
 *
 * SIMD (noise_simd.c). Several points at a time on three levels found at
 * run time (noise_simd_best: the highest level __builtin_cpu_supports
 * allows): SSE2 (the x86-64 baseline, four points), AVX2 (eight points; the
 * hash chains as 32-bit gathers from the permutation, software-pipelined
 * with the arithmetic of earlier groups, which runs on 4-double vectors)
 * and AVX-512 (eight points in 8-double vectors, the permutation lookups as
 * byte-lane table permutes, vpermi2b). The gradient coefficients come from
 * the hash by register table lookups (AVX2: byte shuffles that build ±2.0
 * and +0.0, where computing with twice the coefficients is provably exact,
 * noise_simd.c). Every level gives bit for bit the scalar values (same
 * operations in the same order, no FMA), so a result never depends on the
 * machine. The blocks use
 * the best level except SSE2, which measured slower than the per-point loop
 * (bench/noise_bench.c). The *_block_at variants take the level
 * (NOISE_LEVEL_SCALAR runs the per-point loop), for tests and benchmarks.
 */
#ifndef NOISE_H
#define NOISE_H

#include <stddef.h>
#include <stdint.h>

typedef struct noise_perm {
    /* p[i + 256] == p[i] (i < 256); p[512 + i] = (p[i] & 15) | (p[i + 1] & 15) << 4
     * (i < 511), the gradient numbers of a pair of corners (noise_impl.h) */
    uint8_t p[1024];
} noise_perm;

void noise_perm_init(noise_perm *np, uint64_t seed);
void noise_perm_reference(noise_perm *np);

double noise_perlin3(const noise_perm *np, double x, double y, double z);
void noise_perlin3_block(const noise_perm *np, size_t n, const double *x, const double *y,
                         const double *z, double *out);

double noise_fbm3(const noise_perm *np, int octaves, double lacunarity, double gain, double x,
                  double y, double z);
void noise_fbm3_block(const noise_perm *np, int octaves, double lacunarity, double gain, size_t n,
                      const double *x, const double *y, const double *z, double *out);

double noise_turbulence3(const noise_perm *np, int octaves, double x, double y, double z);
void noise_turbulence3_block(const noise_perm *np, int octaves, size_t n, const double *x,
                             const double *y, const double *z, double *out);

enum { NOISE_LEVEL_SCALAR, NOISE_LEVEL_SSE2, NOISE_LEVEL_AVX2, NOISE_LEVEL_AVX512 };
int noise_simd_best(void);
/* The level the *_block functions use: noise_simd_best(), except SSE2,
 * where they run the per-point loop (NOISE_LEVEL_SCALAR). */
int noise_block_level(void);
void noise_perlin3_block_at(int level, const noise_perm *np, size_t n, const double *x,
                            const double *y, const double *z, double *out);
void noise_fbm3_block_at(int level, const noise_perm *np, int octaves, double lacunarity,
                         double gain, size_t n, const double *x, const double *y, const double *z,
                         double *out);
void noise_turbulence3_block_at(int level, const noise_perm *np, int octaves, size_t n,
                                const double *x, const double *y, const double *z, double *out);

/* Perlin's 2002 reference implementation transcribed literally (branchy
 * grad(), his permutation table, (int)floor). Defined only for
 * |coordinates| < 2^31. For tests and the benchmark baseline. */
double noise_reference3(double x, double y, double z);

#endif
