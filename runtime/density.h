/* density.h — soft shapes (densities) and density modulation functions
 * (DMFs) of hypertexture (Perlin & Hoffert 1989, as used by seed 001).
 *
 * An object is a density D(x) in [0, 1]: the hard region D = 1, a soft
 * shell 0 < D < 1, and outside D = 0. A chain of DMFs shapes it:
 * H(D(x), x) = f_n(...f_1(D(x))) (seed 001, hypertexture section).
 *
 * Shapes (density_shape; torus and cylinder have their axis along z, the
 * box is axis-aligned; rotate or move any of them with a field warp):
 *   SPHERE   centre c, radius r, softness s — the seed's soft sphere exactly:
 *              r1^2 = (r - s/2)^2, r0^2 = (r + s/2)^2, d^2 = |x - c|^2,
 *              D = 1 if d^2 <= r1^2, 0 if d^2 >= r0^2,
 *              else (r0^2 - d^2) / (r0^2 - r1^2).
 *            (The seed writes < and >; at equality its middle formula gives
 *            the same 1 and 0, and s = 0 then needs no 0/0.) If s > 2r we
 *            take r1 = 0 (the seed's (r - s/2)^2 would grow a hard core
 *            again as s grows).
 *   TORUS    centre c, major radius R (circle in the plane z = c_z), tube
 *            radius r, softness s: the soft sphere's formula with d^2 the
 *            squared distance to the core circle,
 *              d^2 = (sqrt((x-cx)^2 + (y-cy)^2) - R)^2 + (z - cz)^2.
 *   BOX      centre c, half extents h[0..2], softness s; and
 *   CYLINDER centre c, radius r, half height h[2] (capped), softness s:
 *            these have no natural d^2, so they use the signed distance
 *            sd to the surface (negative inside; Euclidean outside):
 *              box:      q = |x - c| - h per axis,
 *              cylinder: q = (sqrt((x-cx)^2 + (y-cy)^2) - r, |z - cz| - h[2]),
 *              sd = |max(q, 0)| + min(max_i q_i, 0),
 *            and a shell of width s centred on the surface, linear in sd:
 *              D = 1 if sd <= -s/2, 0 if sd >= s/2, else (s/2 - sd) / s.
 *
 * Signed distance (density_sdf): the distance from x to the surface
 * {D = level} of a shape, negative where D >= level (inside), for
 * 0 < level <= 1. A hard shape (s = 0) is a 0/1 density and its surface is
 * the same for every such level: the shape's own boundary. The distance is
 *   sphere:   |x - c| - rho,          rho^2 = r0^2 - level (r0^2 - r1^2)
 *   torus:    sqrt(q^2 + dz^2) - rho, q = sqrt(dx^2 + dy^2) - R, same rho
 *   box, cylinder: sd - s (1/2 - level), sd as above.
 * It is exact (the Euclidean distance to the surface, with sign) for every
 * hard shape and for soft spheres and tori; for a soft box or cylinder it is
 * exact outside the level surface and a lower bound inside it when
 * level > 1/2 (an inward offset of a box by a constant is not its distance
 * inside). Its zero set is the surface exactly in every case, and its
 * gradient is the outward unit normal wherever the surface is smooth.
 * density_eval is unchanged by this: the density values stay the seed's.
 *
 * Combinations of densities: product, min, max are plain field ops;
 * density_smooth_union(a, b, k) is the polynomial smooth maximum
 *     h = max(k - |a - b|, 0) / k,  max(a, b) + h^2 k / 4,
 * clamped to at most 1 (k <= 0: plain max). It equals max(a, b) where
 * |a - b| >= k and is smooth across a = b.
 *
 * DMFs (t is the density; bias and gain clamp t to [0, 1] first, because
 * their formulas need t in [0, 1] — a NaN stays NaN):
 *   bias(b, t)  = t^(ln b / ln 0.5)                 (Perlin 1985), 0 < b < 1;
 *                 bias(b, 0.5) = b, bias(b, 0) = 0, bias(b, 1) = 1
 *   gain(g, t)  = t < 0.5 ? bias(1 - g, 2t) / 2 : 1 - bias(1 - g, 2 - 2t) / 2,
 *                 0 < g < 1; gain(g, 0.5) = 0.5
 *   step(e, t)  = t >= e ? 1 : 0            (threshold; seed 001 uses 0.3, 0.5)
 *   smoothstep(e0, e1, t) = u^2 (3 - 2u), u = clamp((t - e0)/(e1 - e0), 0, 1)
 *                 (e0 == e1: step(e0, t))
 *   clamp(lo, hi, t), scale/offset a t + b: plain field ops.
 * The exponent ln b / ln 0.5 is computed once per call of a block function
 * and in the same way by the scalar function, so they agree bit for bit.
 *
 * Validation: density_check and dmf_check_* return RT_EINVAL with a
 * one-line message naming the shape, the parameter, its value and what was
 * expected.
 */
#ifndef DENSITY_H
#define DENSITY_H

#include <stddef.h>

#include "rt.h"

typedef enum density_kind {
    DENSITY_SPHERE,
    DENSITY_BOX,
    DENSITY_TORUS,
    DENSITY_CYLINDER,
} density_kind;

typedef struct density_shape {
    density_kind kind;
    double c[3]; /* centre */
    double r;    /* sphere radius, torus tube radius, cylinder radius */
    double R;    /* torus major radius */
    double h[3]; /* box half extents; cylinder half height in h[2] */
    double s;    /* softness: width of the soft shell, >= 0 */
} density_shape;

/* Names for messages and printing: "sphere", "box", "torus", "cylinder". */
const char *density_name(density_kind k);

rt_code density_check(const density_shape *d, rt_error *e);
double density_eval(const density_shape *d, double x, double y, double z);
void density_eval_block(const density_shape *d, size_t n, const double *x, const double *y,
                        const double *z, double *out);

/* The signed distance to {D = level}; 0 < level <= 1 (callers check). */
double density_sdf(const density_shape *d, double level, double x, double y, double z);
void density_sdf_block(const density_shape *d, double level, size_t n, const double *x,
                       const double *y, const double *z, double *out);
/* 1 if density_sdf is the exact distance for this shape at this level. */
int density_sdf_exact(const density_shape *d, double level);

double density_smooth_union(double a, double b, double k);

rt_code dmf_check_bias(double b, rt_error *e);
rt_code dmf_check_gain(double g, rt_error *e);

double dmf_bias(double b, double t);
double dmf_gain(double g, double t);
double dmf_step(double edge, double t);
double dmf_smoothstep(double e0, double e1, double t);

void dmf_bias_block(double b, size_t n, const double *t, double *out);
void dmf_gain_block(double g, size_t n, const double *t, double *out);
void dmf_smoothstep_block(double e0, double e1, size_t n, const double *t, double *out);

#endif
