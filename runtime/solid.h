/* solid.h — solid textures of seed 000: base functions G, the fluctuation
 * D(P) and the perturbation P' = F(P, D(P)).
 *
 * Base functions (scalar fields of the point P = (x, y, z)):
 *   marble  G(P) = sum_i g_i(z), g_i(z) = exp(-alpha_i d_i) if d_i > 0 else 1,
 *           d_i = |z - c_i| - w_i / 2                    (seed 000 eq. (6))
 *           layer i: centre c_i, width w_i >= 0, decay alpha_i > 0. Layers
 *           may overlap, so G can exceed 1 (the ramp clamps).
 *   wood    concentric rings around the axis through `origin` along `axis`:
 *           r = distance of P from the axis, f = frac(r / spacing),
 *           G(P) = ((1 - cos(2 pi f)) / 2)^sharpness
 *           i.e. 0 at r = 0, spacing, 2 spacing, … (early wood) and 1 half
 *           way between (the dark late-wood ring); sharpness > 0 narrows
 *           the dark rings (1 = a plain cosine profile). The paper only
 *           names "concentric circles displaced radially"; this profile is
 *           our choice: smooth, periodic, one parameter for the ring width.
 *   field   any rt_field_fn.
 *
 * Fluctuation. D is any rt_field_fn (normally mpd_eval with an mpd) seen
 * through a box: world point P is passed to D as (P - d_lo) / (d_hi - d_lo)
 * per axis, so the box [d_lo, d_hi] maps onto D's unit cube (default box:
 * the unit cube itself). No D (d_fn NULL) means D = 0.
 *
 * Perturbation F (the paper's "fluctuation application function"):
 *   SOLID_WARP_NONE    P' = P
 *   SOLID_WARP_Z       P' = P + (0, 0, k D(P))                 (eq. (7))
 *   SOLID_WARP_RADIAL  P' = P + k D(P) u, u the unit vector from the wood
 *                      axis to P, so r' = r + k D (wood, "displaced
 *                      radially"); on the axis itself P' = P
 *   SOLID_WARP_USER    P' = warp_fn(P, D(P)) (a block callback)
 *
 * Texture value. value(P) = G(F(P, D(P))). The paper states the texture
 * observed at P' is G(P) (eq. (5)), which would need F inverted; like the
 * solid-texture literature after it we evaluate G at the displaced point —
 * the same family of textures, since F^-1 is again a displacement by about
 * -k D. solid_eval is an rt_field_fn (reentrant, no heap), solid_color maps
 * the value through a ramp (solid_ramp_marble / solid_ramp_wood are the
 * palettes the stdlib mirrors).
 */
#ifndef SOLID_H
#define SOLID_H

#include <stddef.h>

#include "ramp.h"
#include "rt.h"

#define SOLID_MAX_LAYERS 64

typedef struct solid_layer {
    double c, w, alpha; /* centre z, width, decay */
} solid_layer;

typedef struct solid_marble {
    int n; /* 1 .. SOLID_MAX_LAYERS */
    solid_layer layer[SOLID_MAX_LAYERS];
} solid_marble;

typedef struct solid_wood {
    double origin[3], axis[3]; /* axis need not be unit length, must be non-zero */
    double spacing;            /* > 0 */
    double sharpness;          /* > 0 */
} solid_wood;

enum { SOLID_BASE_MARBLE = 0, SOLID_BASE_WOOD = 1, SOLID_BASE_FIELD = 2 };
enum { SOLID_WARP_NONE = 0, SOLID_WARP_Z = 1, SOLID_WARP_RADIAL = 2, SOLID_WARP_USER = 3 };

/* User perturbation: write P' for n points given P and D(P). Reentrant. */
typedef void (*solid_warp_fn)(const void *ctx, size_t n, const double *x, const double *y,
                              const double *z, const double *d, double *xo, double *yo, double *zo);

typedef struct solid_texture {
    int base;                 /* SOLID_BASE_* */
    solid_marble marble;
    solid_wood wood;          /* also gives the axis of SOLID_WARP_RADIAL */
    rt_field_fn base_fn;      /* SOLID_BASE_FIELD */
    const void *base_ctx;
    rt_field_fn d_fn;         /* the fluctuation D, or NULL */
    const void *d_ctx;
    double d_lo[3], d_hi[3];  /* world box mapped onto D's unit cube */
    int warp;                 /* SOLID_WARP_* */
    double k;                 /* contribution of D */
    solid_warp_fn warp_fn;    /* SOLID_WARP_USER */
    const void *warp_ctx;
} solid_texture;

/* One marble layer g_i(z) and the sum G (eq. (6)). */
double solid_layer_value(const solid_layer *l, double z);
double solid_marble_value(const solid_marble *m, double z);
/* rt_field_fn, ctx = const solid_marble * */
void solid_marble_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out);
rt_code solid_marble_check(const solid_marble *m, rt_error *e);

double solid_wood_radius(const solid_wood *w, const double p[3]);
double solid_wood_profile(const solid_wood *w, double r);
/* rt_field_fn, ctx = const solid_wood * */
void solid_wood_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                   double *out);
rt_code solid_wood_check(const solid_wood *w, rt_error *e);

/* Marble base, no fluctuation, k = 0, D box = unit cube, wood axis +z at
 * the origin with spacing 0.1 and sharpness 1. */
void solid_texture_default(solid_texture *t);
rt_code solid_texture_check(const solid_texture *t, rt_error *e);

/* rt_field_fn, ctx = const solid_texture *: value(P) = G(F(P, D(P))). */
void solid_eval(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                double *out);
/* Colours: rgba has 4 n floats. */
void solid_color(const solid_texture *t, const ramp *r, size_t n, const double *x, const double *y,
                 const double *z, float *rgba);

/* Palettes: marble (white stone, grey-green veins at high G) and wood
 * (light early wood at 0, dark late-wood ring at 1). */
ramp solid_ramp_marble(void);
ramp solid_ramp_wood(void);

#endif
