/* flam3.h — export a 2-D IFS or an order-1 RIFS as a flam3 flame (XML),
 * for rendering in flam3 / Apophysis / JWildfire.
 *
 * Output: one <flame> element with size="W H", center="x y", scale (pixels
 * per unit), a 256-entry palette (<color index rgb>, from the ramp) and one
 * <xform> per map with the linear variation:
 *     <xform weight=".." color=".." linear="1" coefs="A B C D E F" [chaos=".."]/>
 * flam3's convention: x' = A x + C y + E, y' = B x + D y + F — i.e. for a map
 * x' = a x + b y + c, y' = d x + e y + f the attribute is "a d b e c f".
 * From our affine (Fractint order: x' = m00 x + m01 y + t0,
 * y' = m10 x + m11 y + t1) that is coefs = "m00 m10 m01 m11 t0 t1".
 *
 * Orientation: flam3 puts +y DOWN the image (image row grows with y), our
 * histograms put +y up. By default every map is conjugated by the flip
 * S(x, y) = (x, −y) — S∘ω∘S: m01, m10 and t1 change sign — and the centre's
 * y is negated, so flam3 shows the picture the same way up as frac.
 * opts.keep_y = 1 writes the maps unchanged.
 *
 * Probabilities: an IFS writes weight = p_i. An order-1 RIFS writes
 * weight = 1 on every xform and chaos = "p_i1 … p_iN" (flam3's "xaos": the
 * next xform after i is j with probability weight_j·chaos_ij / Σ_k
 * weight_k·chaos_ik, which with unit weights is exactly p_ij). An order-2
 * RIFS or 3-D maps cannot be expressed and are errors.
 * color = c_i (opts.map_c, default i/(n−1)), the flam3 colour coordinate.
 */
#ifndef FLAM3_H
#define FLAM3_H

#include "chaos.h"
#include "fileio.h"
#include "ramp.h"
#include "rt.h"

typedef struct flam3_opts {
    const char *name;      /* flame name, NULL = "frac" */
    int width, height;     /* size in pixels */
    double lo[2], hi[2];   /* the window shown: centre and scale derive from it */
    const double *map_c;   /* n colour coordinates, or NULL */
    const ramp *ramp;      /* palette, NULL = grey */
    int keep_y;            /* 1: write maps as they are (no upright flip) */
} flam3_opts;

/* Append the flame XML to out. */
rt_code flam3_write(const chaos_sys *s, const flam3_opts *o, bytebuf *out, rt_error *e);
/* Write to a file (atomically). */
rt_code flam3_save(const char *path, const chaos_sys *s, const flam3_opts *o, rt_error *e);

#endif
