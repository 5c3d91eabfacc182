/* noise_simd.c — Perlin noise four points at a time (GCC vector extensions;
 * noise.h, "SIMD"). One kernel, compiled twice: for the x86-64 baseline
 * (SSE2: the compiler splits each 4-double vector into two 128-bit halves)
 * and with target("avx2") (256-bit), chosen at run time with
 * __builtin_cpu_supports. Every lane performs exactly the scalar perlin()'s
 * operations in the same order — IEEE +, −, × are the same in a vector
 * lane, the build has -ffp-contract=off so nothing fuses into an FMA, and
 * the gradient coefficients are the same exact values ±1, 0 — so the result
 * is bit-identical to the scalar path on every level. Points the fast
 * lattice path cannot take (|coordinate| >= 2^30, NaN, infinity) go through
 * the scalar perlin(), four at a time. */
#include "noise.h"
#include "noise_impl.h"

#include <string.h>

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define NOISE_X86 1
#endif

/* 32-byte vectors passed between always_inline functions only: no call
 * boundary, so GCC's note that their ABI differs with AVX does not apply. */
#pragma GCC diagnostic ignored "-Wpsabi"

typedef double v4d __attribute__((vector_size(32)));
typedef int64_t v4l __attribute__((vector_size(32)));
typedef int32_t v4i __attribute__((vector_size(16)));

#define ALWAYS_INLINE static inline __attribute__((always_inline))

#define K(name) name##_sse2
#define KHASH K(hash_lanes)
#include "noise_kernel.inc"
#undef K
#undef KHASH

#ifdef NOISE_X86
/* every function from here to the pop is compiled for AVX2 (clang spells
 * GCC's push_options/target pragma as an attribute pragma) */
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
/* The same with AVX2 gathers: p32 is the permutation widened to int32
 * (512 entries), so each step of the chain is one 4-lane gather. */
ALWAYS_INLINE v4i gather(const int32_t *p32, v4i i)
{
    return (v4i)_mm_i32gather_epi32(p32, (__m128i)i, 4);
}

ALWAYS_INLINE void hash_gather(const uint8_t *p, const int32_t *p32, v4i X, v4i Y, v4i Z, v4i h[8])
{
    (void)p;
    v4i A = gather(p32, X) + Y, B = gather(p32, X + 1) + Y;
    v4i AA = gather(p32, A) + Z, AB = gather(p32, A + 1) + Z;
    v4i BA = gather(p32, B) + Z, BB = gather(p32, B + 1) + Z;
    h[0] = gather(p32, AA), h[1] = gather(p32, BA), h[2] = gather(p32, AB), h[3] = gather(p32, BB);
    h[4] = gather(p32, AA + 1), h[5] = gather(p32, BA + 1), h[6] = gather(p32, AB + 1);
    h[7] = gather(p32, BB + 1);
}

#define K(name) name##_avx2
#define KHASH hash_gather
#include "noise_kernel.inc"
#undef K
#undef KHASH
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

static void kernel_scalar(const uint8_t *p, size_t n, const double *xs, const double *ys,
                          const double *zs, double s, double a, int mode, double *out)
{
    for (size_t i = 0; i < n; i++) {
        if (mode == NOISE_SET)
            out[i] = perlin(p, xs[i], ys[i], zs[i]);
        else if (mode == NOISE_ADD)
            out[i] += a * perlin(p, xs[i] * s, ys[i] * s, zs[i] * s);
        else
            out[i] += a * fabs(perlin(p, xs[i] * s, ys[i] * s, zs[i] * s));
    }
}

static void kernel_sse2(const uint8_t *p, size_t n, const double *xs, const double *ys,
                        const double *zs, double s, double a, int mode, double *out)
{
    kernel4_sse2(p, NULL, n, xs, ys, zs, s, a, mode, out);
}

#ifdef NOISE_X86
__attribute__((target("avx2"))) static void kernel_avx2(const uint8_t *p, size_t n, const double *xs,
                                                        const double *ys, const double *zs, double s,
                                                        double a, int mode, double *out)
{
    int32_t p32[512];
    for (int i = 0; i < 512; i++)
        p32[i] = p[i];
    kernel4_avx2(p, p32, n, xs, ys, zs, s, a, mode, out);
}
#endif

int noise_simd_best(void)
{
#ifdef NOISE_X86
    if (__builtin_cpu_supports("avx2"))
        return NOISE_LEVEL_AVX2;
#endif
    return NOISE_LEVEL_SSE2;
}

void noise_kernel(int level, const uint8_t *p, size_t n, const double *x, const double *y,
                  const double *z, double s, double a, int mode, double *out)
{
    if (level == NOISE_LEVEL_SCALAR)
        kernel_scalar(p, n, x, y, z, s, a, mode, out);
#ifdef NOISE_X86
    else if (level == NOISE_LEVEL_AVX2)
        kernel_avx2(p, n, x, y, z, s, a, mode, out);
#endif
    else
        kernel_sse2(p, n, x, y, z, s, a, mode, out);
}
