/* tops.h — fractal tops and colour stealing (seed 004 §3, §4, §6).
 *
 * Fractal top (seed 004 eqs. (4)–(9)). Random iteration runs on pairs
 * (address, point): T_n(ω, x) = (nω, f_n(x)) — the newest map index is
 * prepended, so an address lists the maps applied, most recent first. Where
 * several points fall in one pixel the one with the greatest address
 * (lexicographic, map 1 < map 2 < …; in C map index 0 < 1 < …) wins the
 * pixel (eq. (7)): overlaps are decided by address, not blurred by the
 * probabilities. The probabilities only decide how fast the pixels fill.
 *
 * Truncation. A pixel keeps the K most significant symbols of its top
 * address packed base N into a 64-bit key (K = the largest with N^K < 2^64
 * if opts->depth is 0: 63 symbols for N = 2, 40 for N = 3, 31 for N = 4;
 * otherwise min(depth, that)). Two points whose addresses agree in K
 * symbols lie within s^K·diam(A) of each other (s the largest contraction),
 * e.g. 0.5^31 ≈ 5·10^-10 of the attractor: far below a pixel, so comparing
 * truncated keys decides every pixel as the full addresses would, except for
 * ties between points closer than that, which do not matter at pixel
 * resolution. Ties are broken by an auxiliary value (the source pixel for
 * colour stealing) so the winner never depends on the order points arrive.
 *
 * Orbits. Each chunk starts its own orbit at the fixed point x* of map 0
 * with address 000… (key 0): that pair is exactly on the top's attractor,
 * so no burn-in is needed and every plotted pair has an exact (truncated)
 * address. (If map 0 has no fixed point, 1 − A singular, the orbit starts at
 * the origin after 200 steps of map 0.) Chunks of fixed size use rng stream
 * (seed, chunk); workers keep private key buffers merged with max, which is
 * order-free, so results are identical for any thread count.
 *
 * Colour stealing (seed 004 §4). Two IFSs with the same number of maps, f on
 * the screen and g on a source picture, run on ONE index sequence (chosen
 * with f's probabilities): a_n = f_σn(a_{n-1}), b_n = g_σn(b_{n-1}). The
 * pixel at a_n takes the colour of the source pixel at b_n, the greatest
 * address owning the pixel. The source window maps g's plane onto the source
 * picture (points outside are clamped to its border). Which source pixel
 * each screen pixel steals does not depend on the picture's colours, only
 * on its size, so it is computed once (tops_steal) and applied to any number
 * of pictures (tops_steal_apply); the "fractal filter" (§6) applies one map
 * to every frame of a sequence (tops_filter).
 */
#ifndef TOPS_H
#define TOPS_H

#include <stdint.h>

#include "draw.h"
#include "fset.h"
#include "image.h"
#include "ramp.h"
#include "rt.h"

typedef struct tops_cell {
    uint64_t key;  /* top address, most recent symbol most significant */
    uint32_t aux;  /* source pixel index (colour stealing), else 0 */
    uint32_t hit;  /* 0: no point fell in this pixel */
} tops_cell;

typedef struct tops_buf {
    int w, h;
    int nmaps;        /* N */
    int depth;        /* K symbols kept */
    uint64_t lead;    /* N^(K-1): the weight of the first symbol */
    int src_w, src_h; /* colour stealing: size of the source picture */
    tops_cell *cell;  /* w * h, top row first */
} tops_buf;

typedef struct tops_opts {
    uint64_t points; /* plotted points */
    uint64_t seed;
    int depth;       /* K; 0 = as many as fit in 64 bits */
} tops_opts;

/* Fractal top of a 2-D IFS f over a view (draw.h). */
rt_code tops_run(const fset_ifs *f, const draw_view *view, const tops_opts *opts, tops_buf *out,
                 const rt_run *run, rt_error *e);
void tops_free(tops_buf *t);

/* Symbol i (0 = most recent / most significant) of a key, 0 .. N-1. */
int tops_symbol(const tops_buf *t, uint64_t key, int i);

/* Colour each pixel by the first nsym symbols of its top address, read as a
 * base-N number p, through the ramp at p/(N^nsym − 1) (0 for one map); empty
 * pixels get bg. With nsym = 1 that is k/(N − 1) for map k, the colour
 * chaos() gives map k (CHAOS_COLOUR_LAST), so a palette of one colour per map
 * shows each map in its own colour in both.
 * out must be t->w × t->h. */
rt_code tops_colour(const tops_buf *t, int nsym, const ramp *r, const float bg[4], image *out,
                    rt_error *e);

/* Colour stealing: the top of f over the screen view, every pixel also
 * recording the index of the source pixel its winning point stole from.
 * src_view maps g's plane onto the source picture; its w × h is the
 * picture's size (draw_view_fit with the picture's size and g's window). */
rt_code tops_steal(const fset_ifs *f, const draw_view *screen, const fset_ifs *g,
                   const draw_view *src_view, const tops_opts *opts, tops_buf *out,
                   const rt_run *run, rt_error *e);
/* Paint out (t->w × t->h) from a source picture of the size given to
 * tops_steal; empty pixels get bg. */
rt_code tops_steal_apply(const tops_buf *t, const image *src, const float bg[4], image *out,
                         rt_error *e);
/* Fractal filter: steal from n frames of one size with one top; out is an
 * array of n images the caller has not allocated (freed with image_free). */
rt_code tops_filter(const fset_ifs *f, const draw_view *screen, const fset_ifs *g,
                    const double src_lo[2], const double src_hi[2], const image *frames, int n,
                    const tops_opts *opts, const float bg[4], image *out, const rt_run *run,
                    rt_error *e);

#endif
