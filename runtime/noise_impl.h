/* noise_impl.h — the per-point Perlin evaluation shared by noise.c and the
 * SIMD kernels in noise_simd.c (private to the runtime; see noise.h). The
 * SIMD kernels fall back to perlin() for points it handles specially. */
#ifndef NOISE_IMPL_H
#define NOISE_IMPL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* GCC/Clang vector extensions, two doubles: SSE2 registers on x86-64 (the
 * baseline), lowered to scalar code elsewhere. */
typedef double noise_v2d __attribute__((vector_size(16)));
typedef int64_t noise_v2l __attribute__((vector_size(16)));
typedef int32_t noise_v2i __attribute__((vector_size(8)));

/* The reference grad(h, x, y, z) as coefficients: h = 0..15 selects
 * (±u) + (±v) with u = h<8 ? x : y, v = h<4 ? y : (h==12||h==14) ? x : z,
 * signs from bits 0 and 1; grad = gx*x + gy*y + gz*z, evaluated in that
 * order (the products by ±1 and 0 are exact). */
#define NOISE_S1(h) (((h) & 1) ? -1 : 1)
#define NOISE_S2(h) (((h) & 2) ? -1 : 1)
#define NOISE_GX(h) (((h) < 8 ? NOISE_S1(h) : 0) + ((h) == 12 || (h) == 14 ? NOISE_S2(h) : 0))
#define NOISE_GY(h) (((h) >= 8 ? NOISE_S1(h) : 0) + ((h) < 4 ? NOISE_S2(h) : 0))
#define NOISE_GZ(h) (((h) >= 4 && (h) != 12 && (h) != 14) ? NOISE_S2(h) : 0)

/* The coefficients of a pair of corners (i, j, 0) and (i, j, 1), indexed by
 * (h0 & 15) | (h1 & 15) << 4 (as noise_perm keeps them at p[512 + i]): one
 * 16-byte load per axis for both (noise.c). */
typedef struct noise_gpair {
    noise_v2d gx, gy, gz;
} noise_gpair;
extern const noise_gpair noise_gpairs[256];

/* p[i] | p[i + 1] << 8: the two permutation entries a corner pair needs, in
 * one load (i <= 510). */
static inline unsigned perm_pair(const uint8_t *p, unsigned i)
{
    uint16_t v;
    memcpy(&v, p + i, 2);
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    v = (uint16_t)(v >> 8 | v << 8);
#endif
    return v;
}

static inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static inline noise_v2d fade2(noise_v2d t) { return t * t * t * (t * (t * 6 - 15) + 10); }

/* grad() of the two corners (i, j, 0), (i, j, 1): gi = the pair's entry
 * p[512 + index] (noise.h), xc, yc their x and y offsets, zz = {z, z - 1}. */
static inline noise_v2d grad_pair(unsigned gi, double xc, double yc, noise_v2d zz)
{
    const noise_gpair *g = &noise_gpairs[gi];
    noise_v2d xv = {xc, xc}, yv = {yc, yc};
    return g->gx * xv + g->gy * yv + g->gz * zz;
}

/* Perlin 2002 for |x|, |y|, |z| >= 2^30, NaN and infinities (noise.c). */
double noise_perlin_far(const uint8_t *p, double x, double y, double z);

/* Perlin 2002, "Improving Noise", the reference noise() with table
 * gradients; x and y share two-lane vectors, each pair of corners along z
 * is one two-lane gradient, the lerps along x and y run on the pairs. Every
 * lane does exactly the reference's operations in its order, so the value
 * is the same for every input (bit for bit what noise_perlin_far gives).
 * The lattice index is an inline floor (libm's floor is a call without
 * SSE4.1): truncate, step down where that went up. p is noise_perm.p (all
 * 1024 bytes: the last level reads the gradient numbers at p + 512). */
static inline double perlin(const uint8_t *p, double x, double y, double z)
{
    if (!(fabs(x) < 1073741824.0 && fabs(y) < 1073741824.0 && fabs(z) < 1073741824.0))
        return noise_perlin_far(p, x, y, z);
    const noise_v2d one = {1, 1};
    noise_v2d xy = {x, y};
    noise_v2i ti = __builtin_convertvector(xy, noise_v2i);
    noise_v2d tf = __builtin_convertvector(ti, noise_v2d);
    noise_v2l up = xy < tf; /* -1 where truncation went up */
    tf -= (noise_v2d)((noise_v2l)one & up);
    unsigned X = (unsigned)(ti[0] + (int32_t)up[0]) & 255u;
    unsigned Y = (unsigned)(ti[1] + (int32_t)up[1]) & 255u;
    int iz = (int)z;
    iz -= z < (double)iz;
    unsigned Z = (unsigned)iz & 255u;
    z -= (double)iz;
    xy -= tf;
    noise_v2d uv = fade2(xy), xy1 = xy - one;
    double w = fade(z);
    unsigned hx = perm_pair(p, X);
    unsigned hA = perm_pair(p, (hx & 255u) + Y), hB = perm_pair(p, (hx >> 8) + Y);
    const uint8_t *pg = p + 512; /* the pairs' gradient numbers */
    unsigned hAA = pg[(hA & 255u) + Z], hAB = pg[(hA >> 8) + Z];
    unsigned hBA = pg[(hB & 255u) + Z], hBB = pg[(hB >> 8) + Z];
    double x0 = xy[0], y0 = xy[1], x1 = xy1[0], y1 = xy1[1];
    noise_v2d zz = {z, z - 1};
    noise_v2d uu = {uv[0], uv[0]}, vv = {uv[1], uv[1]};
    noise_v2d g00 = grad_pair(hAA, x0, y0, zz), g10 = grad_pair(hBA, x1, y0, zz);
    noise_v2d g01 = grad_pair(hAB, x0, y1, zz), g11 = grad_pair(hBB, x1, y1, zz);
    noise_v2d a = g00 + uu * (g10 - g00), b = g01 + uu * (g11 - g01);
    noise_v2d c = a + vv * (b - a); /* {lerp at z, lerp at z - 1} */
    return c[0] + w * (c[1] - c[0]);
}

/* One block kernel for the three block functions: out[i] = n(p_i) (mode
 * NOISE_SET, no scaling), out[i] += a·n(s·p_i) (NOISE_ADD) or
 * out[i] += a·|n(s·p_i)| (NOISE_ADD_ABS); level: NOISE_LEVEL_*. */
enum { NOISE_SET, NOISE_ADD, NOISE_ADD_ABS };
void noise_kernel(int level, const uint8_t *p, size_t n, const double *x, const double *y,
                  const double *z, double s, double a, int mode, double *out);

#endif
