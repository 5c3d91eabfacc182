/* noise_impl.h — the scalar Perlin evaluation shared by noise.c and the
 * SIMD kernels in noise_simd.c (private to the runtime; see noise.h). The
 * SIMD kernels fall back to perlin() for points it handles specially. */
#ifndef NOISE_IMPL_H
#define NOISE_IMPL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* The reference grad(h, x, y, z) as a table: h = 0..15 selects
 * (±u) + (±v) with u = h<8 ? x : y, v = h<4 ? y : (h==12||h==14) ? x : z. */
static const double grad_x[16] = {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, 0, -1, 0};
static const double grad_y[16] = {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, -1, 1, -1};
static const double grad_z[16] = {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 1, 0, -1};

/* floor(v) and its lattice index mod 256, never converting an out-of-range
 * double to int. */
static inline double lattice(double v, unsigned *ix)
{
    if (fabs(v) < 1073741824.0) { /* inline floor: libm's is a call without SSE4.1 */
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

static inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
static inline double lerp(double t, double a, double b) { return a + t * (b - a); }

static inline double grad(unsigned h, double x, double y, double z)
{
    h &= 15u;
    return grad_x[h] * x + grad_y[h] * y + grad_z[h] * z;
}

/* Perlin 2002, "Improving Noise", the reference noise() with a table grad. */
static inline double perlin(const uint8_t *p, double x, double y, double z)
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

/* One block kernel for the three block functions: out[i] = n(p_i) (mode
 * NOISE_SET, no scaling), out[i] += a·n(s·p_i) (NOISE_ADD) or
 * out[i] += a·|n(s·p_i)| (NOISE_ADD_ABS); level: NOISE_LEVEL_*. */
enum { NOISE_SET, NOISE_ADD, NOISE_ADD_ABS };
void noise_kernel(int level, const uint8_t *p, size_t n, const double *x, const double *y,
                  const double *z, double s, double a, int mode, double *out);

#endif
