/* noise_simd.c — Perlin noise several points at a time (noise.h, "SIMD"),
 * on three levels chosen at run time with __builtin_cpu_supports:
 *   SSE2    four points (GCC/Clang vector extensions, each 4-double vector
 *           split into two 128-bit halves; noise_kernel.inc), hash lane by
 *           lane; the x86-64 baseline;
 *   AVX2    eight points, the hash chains as 32-bit gathers (vpgatherdd),
 *           the arithmetic on 4-double vectors (target("avx2"));
 *   AVX-512 eight points in 8-double vectors, the hash chains as byte-lane
 *           table lookups (vpermi2b; F, BW, VL, DQ, VBMI).
 * Every lane performs exactly the scalar perlin()'s operations in the same
 * order — IEEE +, −, × are the same in a vector lane, the build has
 * -ffp-contract=off so nothing fuses into an FMA (FMA is available inside
 * the AVX2 and AVX-512 regions), the floors are exact, and the gradient
 * coefficients are the same exact values ±1, 0 — so the result is
 * bit-identical to the scalar path on every level (AVX2 computes with
 * twice the coefficients where that is exact; see there). A group with a
 * point the vector lattice cannot take (|coordinate| >= 2^30, or 2^31 on
 * AVX2; NaN, infinity) goes through the scalar perlin() point by point. */
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

/* The per-point loop: the scalar level, the groups with a point a vector
 * kernel cannot take, and the last few points (noise_kernel). */
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

#define K(name) name##_sse2
#include "noise_kernel.inc"
#undef K

#ifdef NOISE_X86
/* the end of a target region (clang spells GCC's pop_options as an
 * attribute pop) */
#if defined(__clang__)
#define NOISE_TARGET_POP _Pragma("clang attribute pop")
#else
#define NOISE_TARGET_POP _Pragma("GCC pop_options")
#endif

/* every function from here to the pop is compiled for AVX2 (clang spells
 * GCC's push_options/target pragma as an attribute pragma) */
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
/* Eight points at a time: the hash chain runs in 32-bit lanes, one gather
 * per level and corner pair (seven per eight points, instead of 56 scalar
 * loads with their index arithmetic), while the floors, fades, gradients
 * and lerps run on two 4-double vectors per quantity.
 *
 * The gradient coefficients are doubles made by byte shuffles alone, no
 * int -> double conversion: the top byte of 2.0, -2.0 and +0.0 (0x40,
 * 0xC0, 0x00; their other seven bytes are zero) comes from the hash by a
 * 16-entry table lookup (pshufb, coef8_avx2), and one pshufb per
 * coefficient vector puts four points' bytes into the top bytes of four
 * zeroed lanes (coef4). So the kernel computes with 2g for every gradient
 * coefficient g, and every value it forms is exactly twice perlin()'s,
 * rounded the same, as long as no product rounds to a subnormal:
 *   - 2c * d = 2 (c * d) exactly for c in {-1, 0, 1} (zeros keep their
 *     sign: (2 * 0) * -0 = -0 = 2 * (0 * -0)); |d| <= 1, no overflow;
 *   - sums and differences of doubles scale exactly by 2 (when the result
 *     is subnormal the operation is exact, in either computation);
 *   - a product t * 2e rounds like 2 (t * e) when t * e is normal: rounding
 *     commutes with a power of two in the normal range;
 *   - 0.5 * 2r = r exactly.
 * Products round to subnormals only if a fraction (x - floor x etc.) is
 * tiny, so a group goes the fast way only if all 24 of its fractions are
 * >= 2^-30 (which also excludes ±0): then every gradient is a multiple of
 * 2^-82 (as doubles >= 2^-30 and their differences with 1 are), the fades
 * are >= 2^-90 (fade(t) >= t^3 on [0, 1]), the first products
 * |u (b - a)| >= 2^-172 and
 * the values after them multiples of 2^-224, the second products
 * >= 2^-314, multiples of 2^-366 after, the last >= 2^-456: all normal.
 * (The same chain with 2^-m gives 2^-(10m + 156): any bound up to 2^-86
 * would do; 2^-30 costs nothing more, since only coordinates within 2^-30
 * above a lattice point have such fractions.) The guard is necessary, for
 * two reasons each caught by test_noise: the fast way's fractions of -0 are
 * +0 (cell8_avx2), and a subnormal fade makes the doubled computation round
 * differently — at (0.5, 1.25·2^-356, -0.5) with Perlin's table perlin()
 * halves an odd multiple of 2^-1074 where the doubled values halve exactly
 * and the final halving rounds instead, one unit apart (worked out in
 * test_subnormal_halving; with the guard off, a search of 2·10^8 stressed
 * and random inputs found differences only with a -0 coordinate or a
 * fraction below 2^-265; with it, none).
 * Other groups (lattice points, -0, tiny coordinates; rare on scattered
 * points) multiply the shuffled coefficients by 0.5 first — exactly ±1, +0,
 * the scalar's own coefficients — and compute perlin()'s operations as they
 * are (half4 with exact = 1).
 *
 * coef4: the eight bytes are loaded by an asm statement that GCC can neither
 * merge with the same load for the other layer nor hoist: with a plain load
 * it broadcast once per half, kept the 24 broadcasts live across the half
 * and spilled them (47 more stack accesses in the kernel, 3% slower). */
ALWAYS_INLINE v4d coef4(const int8_t *c8, __m256i place)
{
    __m256i b;
    __asm__ volatile("vpbroadcastq %1, %0" : "=x"(b) : "m"(*(const int64_t *)(const void *)c8));
    return (v4d)_mm256_shuffle_epi8(b, place);
}

/* floor of each lane as perlin() computes it: +0 for -0 */
ALWAYS_INLINE v4d floor4(v4d v)
{
    const v4d zero = {0, 0, 0, 0};
    return (v4d)_mm256_floor_pd((__m256d)v) + zero;
}

ALWAYS_INLINE v4d fade4(v4d t) { return t * t * t * (t * (t * 6 - 15) + 10); }

/* the lerps of four points (lanes 4k..4k+3 of the eight); exact: see above */
ALWAYS_INLINE v4d half4(const int8_t cf[3][2][32], int k, v4d x0, v4d y0, v4d z0, int exact)
{
    const v4d one = {1, 1, 1, 1}, half = {0.5, 0.5, 0.5, 0.5};
    v4d u = fade4(x0), v = fade4(y0), w = fade4(z0);
    v4d x1 = x0 - one, y1 = y0 - one, z1 = z0 - one;
    /* byte 7 of lane j <- byte j (at z) or 4 + j (at z + 1) of the four
     * points' eight coefficient bytes, every other byte zero */
#define PL(b) _mm256_setr_epi8(-1, -1, -1, -1, -1, -1, -1, (char)(b), -1, -1, -1, -1, -1, -1, -1, (char)((b) + 1), \
                               -1, -1, -1, -1, -1, -1, -1, (char)((b) + 2), -1, -1, -1, -1, -1, -1, -1, (char)((b) + 3))
    const __m256i pl0 = PL(0), pl1 = PL(4);
#undef PL
#define CF(c, ax) &cf[ax][(c) >> 1][16 * k + 8 * ((c) & 1)]
#define C(c, ax, pl) (exact ? coef4(CF(c, ax), pl) * half : coef4(CF(c, ax), pl))
#define G(c, xc, yc, zc, pl) (C(c, 0, pl) * (xc) + C(c, 1, pl) * (yc) + C(c, 2, pl) * (zc))
    v4d g00 = G(0, x0, y0, z0, pl0), g10 = G(1, x1, y0, z0, pl0);
    v4d g01 = G(2, x0, y1, z0, pl0), g11 = G(3, x1, y1, z0, pl0);
    v4d a = g00 + u * (g10 - g00), b = g01 + u * (g11 - g01);
    v4d c0 = a + v * (b - a);
    g00 = G(0, x0, y0, z1, pl1), g10 = G(1, x1, y0, z1, pl1);
    g01 = G(2, x0, y1, z1, pl1), g11 = G(3, x1, y1, z1, pl1);
    a = g00 + u * (g10 - g00), b = g01 + u * (g11 - g01);
    v4d c1 = a + v * (b - a);
#undef G
#undef C
#undef CF
    v4d r = c0 + w * (c1 - c0);
    return exact ? r : r * half;
}

/* The gradient coefficients of the 64 corners of eight points from their
 * pairs' gradient numbers: byte 3 of lane j of hq[c] = p[512 + the pair
 * index] (noise.h) of corner pair c (AA, BA, AB, BB) of point j (as
 * stage3_avx2 gathers them). cf[axis][c / 2] holds the top bytes of twice
 * the coefficients (above) of pairs c = 0, 1 or 2, 3: 128-bit half k for
 * points 4k..4k+3, in it eight bytes per pair, the four points at z, then
 * at z + 1 (so that half4 reads the eight bytes of its four points). Two
 * pairs per 256-bit operation: the packs gather the pair bytes of all four
 * pairs in one register, points 0..3 in the low half, 4..7 in the high. */
ALWAYS_INLINE void coef8_avx2(const __m256i hq[4], int8_t cf[3][2][32])
{
#define TOP(g) (char)((g) > 0 ? 0x40 : (g) < 0 ? 0xC0 : 0) /* 2.0, -2.0, +0.0 */
#define T16(G) TOP(G(0)), TOP(G(1)), TOP(G(2)), TOP(G(3)), TOP(G(4)), TOP(G(5)), TOP(G(6)), TOP(G(7)), \
               TOP(G(8)), TOP(G(9)), TOP(G(10)), TOP(G(11)), TOP(G(12)), TOP(G(13)), TOP(G(14)), TOP(G(15))
    const __m256i tgx = _mm256_setr_epi8(T16(NOISE_GX), T16(NOISE_GX));
    const __m256i tgy = _mm256_setr_epi8(T16(NOISE_GY), T16(NOISE_GY));
    const __m256i tgz = _mm256_setr_epi8(T16(NOISE_GZ), T16(NOISE_GZ));
#undef T16
#undef TOP
    const __m256i low4 = _mm256_set1_epi8(15);
    /* per half: words [pair 0 points, pair 1 points], then bytes [0, 1, 2, 3] */
    __m256i w01 = _mm256_packus_epi32(_mm256_srli_epi32(hq[0], 24), _mm256_srli_epi32(hq[1], 24));
    __m256i w23 = _mm256_packus_epi32(_mm256_srli_epi32(hq[2], 24), _mm256_srli_epi32(hq[3], 24));
    __m256i b = _mm256_packus_epi16(w01, w23);
    __m256i lo = _mm256_and_si256(b, low4), hi = _mm256_and_si256(_mm256_srli_epi16(b, 4), low4);
    __m256i h01 = _mm256_unpacklo_epi32(lo, hi), h23 = _mm256_unpackhi_epi32(lo, hi);
    _mm256_storeu_si256((__m256i *)(void *)cf[0][0], _mm256_shuffle_epi8(tgx, h01));
    _mm256_storeu_si256((__m256i *)(void *)cf[0][1], _mm256_shuffle_epi8(tgx, h23));
    _mm256_storeu_si256((__m256i *)(void *)cf[1][0], _mm256_shuffle_epi8(tgy, h01));
    _mm256_storeu_si256((__m256i *)(void *)cf[1][1], _mm256_shuffle_epi8(tgy, h23));
    _mm256_storeu_si256((__m256i *)(void *)cf[2][0], _mm256_shuffle_epi8(tgz, h01));
    _mm256_storeu_si256((__m256i *)(void *)cf[2][1], _mm256_shuffle_epi8(tgz, h23));
}

ALWAYS_INLINE v4d ld4(const double *p) { return (v4d)_mm256_loadu_pd(p); }
ALWAYS_INLINE void st4(double *p, v4d v) { _mm256_storeu_pd(p, (__m256d)v); }

/* (int)floor of eight lanes given as two 4-double halves (INT32_MIN where
 * floor is out of the int range, infinite or NaN: cvttpd2dq's "integer
 * indefinite"), and in fr[0], fr[1] the fractions a - floor(a), b - floor(b) */
ALWAYS_INLINE __m256i cell8_avx2(v4d a, v4d b, v4d fr[2])
{
    /* without floor4's +0: the fraction of -0 comes out +0 here, not
     * perlin()'s -0, but that sends the group the exact way (stage1_avx2),
     * which computes its fractions again */
    v4d fa = (v4d)_mm256_floor_pd((__m256d)a), fb = (v4d)_mm256_floor_pd((__m256d)b);
    fr[0] = a - fa, fr[1] = b - fb;
    __m128i lo = _mm256_cvttpd_epi32((__m256d)fa), hi = _mm256_cvttpd_epi32((__m256d)fb);
    return _mm256_set_m128i(hi, lo);
}

/* the groups with a tiny fraction (rare; a call of its own, so that the
 * compiler does not share the coefficient shuffles of the two ways) */
static __attribute__((noinline)) void exact8_avx2(const int8_t cf[3][2][32], const v4d fr[3][2], v4d *ra,
                                                  v4d *rb)
{
    *ra = half4(cf, 0, fr[0][0], fr[1][0], fr[2][0], 1);
    *rb = half4(cf, 1, fr[0][1], fr[1][1], fr[2][1], 1);
}

/* A group of eight points between the stages of kernel8_avx2: the fractions
 * of x, y, z (points 0..3 and 4..7), the way it goes, the hash chain's
 * last gather results and lattice indices, the coefficient bytes. */
enum { WAY_FAST, WAY_EXACT, WAY_SCALAR };
typedef struct group8 {
    v4d fr[3][2];
    __m256i h0, h1, Y, Z;
    int8_t cf[3][2][32];
    int way;
} group8;

/* stage one: cells, fractions, the way, and the first gather of the hash
 * chain, [P[X], P[X+1]], of points xs[0..7] ... (scaled by s unless mode is
 * NOISE_SET). The chain (4-byte gathers; only the low bytes count):
 * [P[X], P[X+1]], then [P[A], P[A+1]] and [P[B], P[B+1]], then the four pair
 * bytes p[512 + AA] ... in byte 3 (that load starts 3 bytes early, so it
 * never reads past p[1023]; every index is <= 510). */
ALWAYS_INLINE void stage1_avx2(const uint8_t *p, const double *xs, const double *ys, const double *zs,
                               double s, int mode, group8 *q)
{
    const v4d lim = {0x1p-30, 0x1p-30, 0x1p-30, 0x1p-30}; /* half4's fast-way bound */
    v4d xa = ld4(xs), xb = ld4(xs + 4), ya = ld4(ys), yb = ld4(ys + 4), za = ld4(zs), zb = ld4(zs + 4);
    if (mode != NOISE_SET) {
        xa *= s, xb *= s, ya *= s, yb *= s, za *= s, zb *= s;
    }
    /* Any lane whose floor is not an int (|coordinate| >= 2^31, infinite,
     * NaN) sends the group through perlin() point by point. The others need
     * not be below perlin()'s 2^30: from 2^30 to 2^31 its far path takes the
     * same floor, the same index mod 256 and the same operations. */
    const __m256i ff = _mm256_set1_epi32(255), indef = _mm256_set1_epi32(INT32_MIN);
    __m256i X = cell8_avx2(xa, xb, q->fr[0]), Y = cell8_avx2(ya, yb, q->fr[1]);
    __m256i Z = cell8_avx2(za, zb, q->fr[2]);
    __m256i bad = _mm256_or_si256(_mm256_or_si256(_mm256_cmpeq_epi32(X, indef), _mm256_cmpeq_epi32(Y, indef)),
                                  _mm256_cmpeq_epi32(Z, indef));
    if (!_mm256_testz_si256(bad, bad)) {
        q->way = WAY_SCALAR;
        return;
    }
    X = _mm256_and_si256(X, ff), q->Y = _mm256_and_si256(Y, ff), q->Z = _mm256_and_si256(Z, ff);
    /* the least fraction of each lane (no NaN here; ±0 compare equal) */
#define MIN(a, b) ((v4d)_mm256_min_pd((__m256d)(a), (__m256d)(b)))
    v4d least = MIN(MIN(MIN(q->fr[0][0], q->fr[0][1]), MIN(q->fr[1][0], q->fr[1][1])),
                    MIN(q->fr[2][0], q->fr[2][1]));
#undef MIN
    q->way = _mm256_movemask_pd((__m256d)(least < lim)) ? WAY_EXACT : WAY_FAST;
    if (q->way == WAY_EXACT) { /* perlin()'s fractions: -0 for -0 */
        q->fr[0][0] = xa - floor4(xa), q->fr[0][1] = xb - floor4(xb);
        q->fr[1][0] = ya - floor4(ya), q->fr[1][1] = yb - floor4(yb);
        q->fr[2][0] = za - floor4(za), q->fr[2][1] = zb - floor4(zb);
    }
    q->h0 = _mm256_i32gather_epi32((const int *)(const void *)p, X, 1);
}

/* stage two: [P[A], P[A+1]] and [P[B], P[B+1]] */
ALWAYS_INLINE void stage2_avx2(const uint8_t *p, group8 *q)
{
    if (q->way == WAY_SCALAR)
        return;
    const __m256i ff = _mm256_set1_epi32(255);
    const int *pp = (const int *)(const void *)p;
    __m256i hA = _mm256_add_epi32(_mm256_and_si256(q->h0, ff), q->Y);
    __m256i hB = _mm256_add_epi32(_mm256_and_si256(_mm256_srli_epi32(q->h0, 8), ff), q->Y);
    q->h0 = _mm256_i32gather_epi32(pp, hA, 1);
    q->h1 = _mm256_i32gather_epi32(pp, hB, 1);
}

/* stage three: the corner pairs' gradient numbers and the coefficients */
ALWAYS_INLINE void stage3_avx2(const uint8_t *p, group8 *q)
{
    if (q->way == WAY_SCALAR)
        return;
    const __m256i ff = _mm256_set1_epi32(255);
    const int *pg = (const int *)(const void *)(p + 512 - 3);
    __m256i hA = q->h0, hB = q->h1, Z = q->Z, hq[4];
    hq[0] = _mm256_i32gather_epi32(pg, _mm256_add_epi32(_mm256_and_si256(hA, ff), Z), 1);
    hq[1] = _mm256_i32gather_epi32(pg, _mm256_add_epi32(_mm256_and_si256(hB, ff), Z), 1);
    hq[2] = _mm256_i32gather_epi32(pg, _mm256_add_epi32(_mm256_and_si256(_mm256_srli_epi32(hA, 8), ff), Z), 1);
    hq[3] = _mm256_i32gather_epi32(pg, _mm256_add_epi32(_mm256_and_si256(_mm256_srli_epi32(hB, 8), ff), Z), 1);
    coef8_avx2(hq, q->cf);
}

/* stage four: the arithmetic of a group, into out[0..7] */
ALWAYS_INLINE void stage4_avx2(const uint8_t *p, const group8 *q, const double *xs, const double *ys,
                               const double *zs, double s, double a, int mode, double *out)
{
    const v4l sign = {INT64_MIN, INT64_MIN, INT64_MIN, INT64_MIN};
    if (q->way == WAY_SCALAR) {
        kernel_scalar(p, 8, xs, ys, zs, s, a, mode, out);
        return;
    }
    v4d ra, rb;
    if (q->way == WAY_EXACT) {
        exact8_avx2(q->cf, q->fr, &ra, &rb);
    } else {
        ra = half4(q->cf, 0, q->fr[0][0], q->fr[1][0], q->fr[2][0], 0);
        rb = half4(q->cf, 1, q->fr[0][1], q->fr[1][1], q->fr[2][1], 0);
    }
    if (mode == NOISE_SET) {
        st4(out, ra), st4(out + 4, rb);
        return;
    }
    if (mode == NOISE_ADD_ABS) {
        ra = (v4d)((v4l)ra & ~sign), rb = (v4d)((v4l)rb & ~sign); /* fabs */
    }
    st4(out, ld4(out) + a * ra);
    st4(out + 4, ld4(out + 4) + a * rb);
}

/* Software-pipelined over the groups: iteration j runs stage one of group
 * j, two of j - D, three of j - 2D and four of j - 3D (R slots hold the
 * groups in flight). Each stage starts from gathers issued D iterations
 * (several hundred instructions) earlier, so their long latency overlaps
 * the other groups' arithmetic instead of stalling it; D = 2 measured
 * better than 1 and 3 (bench/README_field.md). Stage one also prefetches
 * the inputs (and out) PF doubles ahead: on arrays larger than the caches
 * the hardware prefetcher alone left the kernel waiting for memory. */
enum { D = 2, R = 8, PF = 64 };

ALWAYS_INLINE void kernel8_avx2(const uint8_t *p, size_t n, const double *xs, const double *ys,
                                const double *zs, double s, double a, int mode, double *out)
{
    group8 q[R];
    size_t ng = n / 8;
    for (size_t j = 0; j < ng + 3 * D; j++) {
        if (j < ng) {
            if (8 * j + PF < n) {
                _mm_prefetch((const char *)(xs + 8 * j + PF), _MM_HINT_T0);
                _mm_prefetch((const char *)(ys + 8 * j + PF), _MM_HINT_T0);
                _mm_prefetch((const char *)(zs + 8 * j + PF), _MM_HINT_T0);
                _mm_prefetch((const char *)(out + 8 * j + PF), _MM_HINT_T0);
            }
            stage1_avx2(p, xs + 8 * j, ys + 8 * j, zs + 8 * j, s, mode, &q[j % R]);
        }
        if (j >= D && j - D < ng)
            stage2_avx2(p, &q[(j - D) % R]);
        if (j >= 2 * D && j - 2 * D < ng)
            stage3_avx2(p, &q[(j - 2 * D) % R]);
        if (j >= 3 * D && j - 3 * D < ng) {
            size_t k = j - 3 * D;
            stage4_avx2(p, &q[k % R], xs + 8 * k, ys + 8 * k, zs + 8 * k, s, a, mode, out + 8 * k);
        }
    }
}

NOISE_TARGET_POP
#endif

static void kernel_sse2(const uint8_t *p, size_t n, const double *xs, const double *ys,
                        const double *zs, double s, double a, int mode, double *out)
{
    kernel4_sse2(p, n, xs, ys, zs, s, a, mode, out);
}

#ifdef NOISE_X86
__attribute__((target("avx2"))) static void kernel_avx2(const uint8_t *p, size_t n, const double *xs,
                                                        const double *ys, const double *zs, double s,
                                                        double a, int mode, double *out)
{
    kernel8_avx2(p, n, xs, ys, zs, s, a, mode, out);
}
#endif

#ifdef NOISE_X86
/* AVX-512 (F, BW, VL, DQ, VBMI): eight points in one 8-double vector per
 * quantity, and the whole hash chain in byte lanes, where arithmetic is
 * mod 256 by itself (P[i + 256] = P[i]): one 256-entry table lookup is two
 * vpermi2b over the four 64-byte quarters of P and a blend on bit 7, and
 * each level of the chain is one lookup for all its corners — [X, X+1],
 * then [A, B, A+1, B+1], then the 64 corner hashes. The coefficients come
 * from a 16-entry double table (vpermi2pd on the hash's low four bits). */
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx512f,avx512bw,avx512vl,avx512dq,avx512vbmi"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx512f,avx512bw,avx512vl,avx512dq,avx512vbmi")
#endif
typedef double v8d __attribute__((vector_size(64)));
typedef int64_t v8l __attribute__((vector_size(64)));

typedef struct perm512 {
    __m512i q[4]; /* P[0..63], P[64..127], P[128..191], P[192..255] */
} perm512;

ALWAYS_INLINE __m512i lookup512(const perm512 *t, __m512i i)
{
    __m512i lo = _mm512_permutex2var_epi8(t->q[0], i, t->q[1]);
    __m512i hi = _mm512_permutex2var_epi8(t->q[2], i, t->q[3]);
    return _mm512_mask_blend_epi8(_mm512_movepi8_mask(i), lo, hi);
}

/* floor as perlin() computes it (+0 for -0) and the lattice index bytes */
ALWAYS_INLINE v8d floor8(v8d v)
{
    const v8d zero = {0, 0, 0, 0, 0, 0, 0, 0};
    return (v8d)_mm512_roundscale_pd((__m512d)v, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC) + zero;
}

ALWAYS_INLINE __m128i cell8(v8d f) /* 8 bytes: (int)f & 255 */
{
    return _mm256_cvtepi32_epi8(_mm512_cvttpd_epi32((__m512d)f));
}

ALWAYS_INLINE v8d fade8(v8d t) { return t * t * t * (t * (t * 6 - 15) + 10); }

ALWAYS_INLINE v8d perlin8_avx512(const perm512 *t, v8d x, v8d y, v8d z)
{
    const v8d one = {1, 1, 1, 1, 1, 1, 1, 1};
    v8d fxv = floor8(x), fyv = floor8(y), fzv = floor8(z);
    __m128i X = cell8(fxv), Y = cell8(fyv), Z = cell8(fzv);
    x -= fxv, y -= fyv, z -= fzv;
    const __m128i one8 = _mm_set1_epi8(1);
    /* [P[X] | P[X+1]] + [Y | Y] = [A | B] */
    __m128i i1 = _mm_unpacklo_epi64(X, _mm_add_epi8(X, one8));
    __m128i ab = _mm_add_epi8(_mm512_castsi512_si128(lookup512(t, _mm512_zextsi128_si512(i1))),
                              _mm_unpacklo_epi64(Y, Y));
    /* [P[A] | P[B] | P[A+1] | P[B+1]] + Z = [AA | BA | AB | BB] */
    __m256i i2 = _mm256_inserti128_si256(_mm256_castsi128_si256(ab), _mm_add_epi8(ab, one8), 1);
    __m256i l2 = _mm256_add_epi8(_mm512_castsi512_si256(lookup512(t, _mm512_zextsi256_si512(i2))),
                                 _mm256_broadcastq_epi64(Z));
    /* the 64 corner hashes: 8 bytes per corner slot, AA BA AB BB at z, then at z + 1 */
    __m512i i3 = _mm512_inserti64x4(_mm512_castsi256_si512(l2),
                                    _mm256_add_epi8(l2, _mm256_set1_epi8(1)), 1);
    __m512i h = lookup512(t, i3);
#define GD(G, o) G(o + 0), G(o + 1), G(o + 2), G(o + 3), G(o + 4), G(o + 5), G(o + 6), G(o + 7)
    const v8d gxl = {GD(NOISE_GX, 0)}, gxh = {GD(NOISE_GX, 8)};
    const v8d gyl = {GD(NOISE_GY, 0)}, gyh = {GD(NOISE_GY, 8)};
    const v8d gzl = {GD(NOISE_GZ, 0)}, gzh = {GD(NOISE_GZ, 8)};
#undef GD
    v8d u = fade8(x), v = fade8(y), w = fade8(z);
    v8d x1 = x - one, y1 = y - one, z1 = z - one;
    v8d g[8];
    for (int q = 0; q < 8; q++) {
        /* every byte of qword j = the hash of slot q, point j */
        __m512i sel = _mm512_add_epi8(_mm512_set1_epi8((char)(8 * q)),
                                      _mm512_set_epi64(0x0707070707070707, 0x0606060606060606,
                                                       0x0505050505050505, 0x0404040404040404,
                                                       0x0303030303030303, 0x0202020202020202,
                                                       0x0101010101010101, 0));
        __m512i hq = _mm512_permutexvar_epi8(sel, h);
        v8d cx = (v8d)_mm512_permutex2var_pd((__m512d)gxl, hq, (__m512d)gxh);
        v8d cy = (v8d)_mm512_permutex2var_pd((__m512d)gyl, hq, (__m512d)gyh);
        v8d cz = (v8d)_mm512_permutex2var_pd((__m512d)gzl, hq, (__m512d)gzh);
        v8d xc = q & 1 ? x1 : x, yc = q & 2 ? y1 : y, zc = q & 4 ? z1 : z;
        g[q] = cx * xc + cy * yc + cz * zc;
    }
    v8d a0 = g[0] + u * (g[1] - g[0]), b0 = g[2] + u * (g[3] - g[2]);
    v8d c0 = a0 + v * (b0 - a0);
    v8d a1 = g[4] + u * (g[5] - g[4]), b1 = g[6] + u * (g[7] - g[6]);
    v8d c1 = a1 + v * (b1 - a1);
    return c0 + w * (c1 - c0);
}

static void kernel_avx512(const uint8_t *p, size_t n, const double *xs, const double *ys,
                          const double *zs, double s, double a, int mode, double *out)
{
    perm512 t;
    for (int k = 0; k < 4; k++)
        t.q[k] = _mm512_loadu_si512((const void *)(p + 64 * k));
    const v8d big = {1073741824.0, 1073741824.0, 1073741824.0, 1073741824.0,
                     1073741824.0, 1073741824.0, 1073741824.0, 1073741824.0};
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        if (i + PF < n) { /* as kernel8_avx2 */
            _mm_prefetch((const char *)(xs + i + PF), _MM_HINT_T0);
            _mm_prefetch((const char *)(ys + i + PF), _MM_HINT_T0);
            _mm_prefetch((const char *)(zs + i + PF), _MM_HINT_T0);
            _mm_prefetch((const char *)(out + i + PF), _MM_HINT_T0);
        }
        v8d x = (v8d)_mm512_loadu_pd(xs + i), y = (v8d)_mm512_loadu_pd(ys + i);
        v8d z = (v8d)_mm512_loadu_pd(zs + i);
        if (mode != NOISE_SET)
            x *= s, y *= s, z *= s;
        __mmask8 ok = _mm512_cmp_pd_mask(_mm512_abs_pd((__m512d)x), (__m512d)big, _CMP_LT_OQ) &
                      _mm512_cmp_pd_mask(_mm512_abs_pd((__m512d)y), (__m512d)big, _CMP_LT_OQ) &
                      _mm512_cmp_pd_mask(_mm512_abs_pd((__m512d)z), (__m512d)big, _CMP_LT_OQ);
        if (ok != 0xff) {
            kernel_scalar(p, 8, xs + i, ys + i, zs + i, s, a, mode, out + i);
            continue;
        }
        v8d r = perlin8_avx512(&t, x, y, z);
        if (mode == NOISE_SET) {
            _mm512_storeu_pd(out + i, (__m512d)r);
            continue;
        }
        if (mode == NOISE_ADD_ABS)
            r = (v8d)_mm512_abs_pd((__m512d)r);
        _mm512_storeu_pd(out + i, (__m512d)((v8d)_mm512_loadu_pd(out + i) + a * r));
    }
}
NOISE_TARGET_POP
#endif

int noise_simd_best(void)
{
#ifdef NOISE_X86
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
        __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512vbmi"))
        return NOISE_LEVEL_AVX512;
    if (__builtin_cpu_supports("avx2"))
        return NOISE_LEVEL_AVX2;
#endif
    return NOISE_LEVEL_SSE2;
}

/* The vector kernels take whole groups (of 8, or 4 for SSE2); the last
 * points go through the per-point loop. */
void noise_kernel(int level, const uint8_t *p, size_t n, const double *x, const double *y,
                  const double *z, double s, double a, int mode, double *out)
{
    size_t done = 0;
    if (level == NOISE_LEVEL_SSE2)
        kernel_sse2(p, done = n & ~(size_t)3, x, y, z, s, a, mode, out);
#ifdef NOISE_X86
    else if (level == NOISE_LEVEL_AVX2)
        kernel_avx2(p, done = n & ~(size_t)7, x, y, z, s, a, mode, out);
    else if (level == NOISE_LEVEL_AVX512)
        kernel_avx512(p, done = n & ~(size_t)7, x, y, z, s, a, mode, out);
#endif
    kernel_scalar(p, n - done, x + done, y + done, z + done, s, a, mode, out + done);
}
