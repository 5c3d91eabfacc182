/* fset.h — iterated function sets and their orders (seed 003 §3).
 *
 * An IFS here is a plain array of affine maps with optional probabilities
 * (fset_ifs). A *function set* {W_1 .. W_N} (seed 003 def. 3.1) is an array
 * of such IFSs; at every iteration step one W is chosen and applied.
 * Which one is chosen is the *order* (fset_order):
 *
 *   FSET_SEQUENCE  a finite list of set indices, stored in APPLICATION
 *                  order: seq[0] is applied first (to K_0). The paper writes
 *                  compositions W_2 ∘ W_5 ∘ … ∘ W_1(K_0), rightmost first;
 *                  fset_order_parse turns that notation into this order.
 *   FSET_PERIODIC  the same list repeated forever: step k uses seq[k % len].
 *   FSET_RANDOM    step k uses W_n with probability p_n (seed 003 def. 3.2).
 *                  The choice at step k is a pure function of (seed, k)
 *                  (a hash, no state), so every chunk of a parallel run and
 *                  every engine (detiter, superifs) sees the SAME sequence
 *                  σ(0), σ(1), … : this is the "random function set" A_n =
 *                  W_σ(n-1) ∘ … ∘ W_σ(0)(A_0), one random shape per seed.
 * Set indices are 0-based in C (W1 of the paper is index 0).
 *
 * Validation (fset_validate, fset_order_validate) names the set and map:
 * "function set W2: probability 3 is -0.1 (expected >= 0)". Probabilities
 * must be >= 0 and sum to 1 within 1e-6; they are normalised internally.
 * All maps of a function set must have the same dimension (2 or 3).
 *
 * Chaos game (fset_chaos) — random iteration with a function set into a
 * hist2 (2-D maps only). The work is cut into fixed chunks; chunk c draws
 * from rng stream (opts->seed, c) and the result is byte-identical for any
 * thread count. Two modes:
 *   FSET_ORBIT  each chunk runs ONE orbit starting at order position 0 and
 *               at opts->start: step k applies a map of W_σ(k) (chosen by its
 *               probabilities). The first opts->burn steps are not plotted.
 *               With plot_period set (periodic / sequence orders) a point is
 *               plotted only after the last set of each period, i.e. the
 *               orbit samples the attractor of the composition
 *               W_seq[len-1] ∘ … ∘ W_seq[0] — what seed 003 draws as K_n
 *               for large n; without it every step is plotted (the union of
 *               the attractors of the cyclic shifts). A SEQUENCE order is
 *               treated as periodic here (an orbit has no end).
 *   FSET_WALK   every sample is a fresh walk of exactly opts->depth steps
 *               from opts->start through σ(0) .. σ(depth-1), and only its end
 *               point is plotted: a sample of W_σ(depth-1) ∘ … ∘ W_σ(0)({x0}),
 *               the random-iteration counterpart of detiter. Samples advance in
 *               lock-step per chunk of FSET_WALK_CHUNK samples, with the map
 *               choices of step k drawn from stream rng_hash3(seed, k, 0,
 *               FSET_WALK_TAG), chunk c — the draws a V = 1 super IFS makes
 *               (superifs.h), so the two give identical histograms.
 * opts->points counts plotted points. Hits outside the histogram window are
 * dropped; the histogram's counts are added to (not cleared); csum is not
 * touched.
 */
#ifndef FSET_H
#define FSET_H

#include <stddef.h>
#include <stdint.h>

#include "affine.h"
#include "camera.h"
#include "hist.h"
#include "image.h"
#include "mesh.h"
#include "rt.h"

#define FSET_MAX_MAPS 256 /* maps per IFS */
#define FSET_WALK_CHUNK 4096
#define FSET_WALK_TAG 0x57a1cULL

typedef struct fset_ifs {
    int n;              /* number of maps, 1 .. FSET_MAX_MAPS */
    const affine *maps; /* n maps */
    const double *p;    /* n probabilities, or NULL for equal ones */
} fset_ifs;

typedef struct fset {
    int n;                /* number of sets, >= 1 */
    const fset_ifs *sets; /* W_1 .. W_N (index 0 .. n-1) */
} fset;

typedef enum fset_order_kind { FSET_SEQUENCE, FSET_PERIODIC, FSET_RANDOM } fset_order_kind;

typedef struct fset_order {
    fset_order_kind kind;
    int len;         /* SEQUENCE / PERIODIC: length of seq, >= 1 */
    const int *seq;  /* set indices, 0-based, application order */
    const double *p; /* RANDOM: one probability per set, or NULL for equal */
    uint64_t seed;   /* RANDOM */
} fset_order;

/* Check every IFS of fs: map counts, one dimension, probabilities. */
rt_code fset_validate(const fset *fs, rt_error *e);
/* Check an order against a function set of nsets sets. */
rt_code fset_order_validate(const fset_order *o, int nsets, rt_error *e);
/* The set index used at step k (0-based). SEQUENCE wraps like PERIODIC;
 * callers that need a finite sequence check k < len themselves. */
int fset_order_at(const fset_order *o, int nsets, uint64_t k);
/* Index 0 .. n-1 chosen with probabilities p (NULL: equal) by the hash value
 * h; FSET_RANDOM's step k uses h = rng_hash3(seed, k, 0, 0). */
int fset_choose(const double *p, int n, uint64_t h);

/* Parse the paper's composition notation, e.g. "W2 ∘ W5 ∘ W1 ∘ W2" (also
 * "W_2 o W_5", "W2*W5"; spaces optional; an optional trailing "(K0)" or
 * "(K_0)"). The rightmost set is applied first. On success *seq is a
 * malloc'd array of *len 0-based indices in application order (W1 → 0).
 * If nsets > 0 indices above nsets are errors. On error *err_offset is the
 * 0-based character (UTF-8 code point) offset of the problem and the message
 * names it: "order: expected a set name like W3 at character 4". */
rt_code fset_order_parse(const char *text, int nsets, int **seq, int *len, size_t *err_offset,
                         rt_error *e);

/* Cumulative probabilities: cum[i] = (p_0 + … + p_i) / total, cum[n-1] = 1;
 * p NULL gives equal ones. Shared by every engine that picks maps so that
 * equal draws give equal picks. */
void fset_cumulative(const double *p, int n, double *cum);
/* The index i with u < cum[i] (first such), for u in [0, 1). */
static inline int fset_pick(const double *cum, int n, double u)
{
    int i = 0;
    while (i < n - 1 && !(u < cum[i]))
        i++;
    return i;
}

/* x' = a x + b y + e, y' = c x + d y + f (the 2-D part of an affine map);
 * every 2-D engine uses this one expression so equal inputs give equal
 * bits. */
static inline void fset_apply2(const affine *a, double *x, double *y)
{
    double nx = a->m[0][0] * *x + a->m[0][1] * *y + a->t[0];
    double ny = a->m[1][0] * *x + a->m[1][1] * *y + a->t[1];
    *x = nx;
    *y = ny;
}

typedef enum fset_mode { FSET_ORBIT, FSET_WALK } fset_mode;

typedef struct fset_chaos_opts {
    fset_mode mode;
    uint64_t points;  /* plotted points */
    uint64_t seed;    /* map choices */
    uint64_t burn;    /* ORBIT: unplotted steps at the start of every chunk */
    int plot_period;  /* ORBIT: plot only after each full period */
    uint64_t depth;   /* WALK: steps per sample, >= 1 */
    double start[3];  /* first point of every orbit / walk (z: 3-D sets only) */
} fset_chaos_opts;

rt_code fset_chaos(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, hist2 *hs,
                   const rt_run *run, rt_error *e);

/* The chaos game of a 3-D function set (3×3 + 3 maps; seed 003 §3-4) seen
 * through a camera (camera_setup done): the same orbits and walks as
 * fset_chaos, chunk for chunk, with every plotted point projected by
 * camera_project; each pixel keeps its nearest view depth (per-worker
 * buffers merged by min, so the result does not depend on the thread
 * count) and is shaded like chaos_project's view: white times 1 at the
 * nearest pixel depth, 0.25 at the farthest, linear between; pixels no
 * point reached get bg. im must be allocated (any size). */
rt_code fset_chaos_view(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, const camera *cam,
                        const float bg[4], image *im, const rt_run *run, rt_error *e);
/* The box of a 3-D function set's chaos game for framing: FSET_BOX_POINTS
 * plotted points of the same game (the first chunks of a game on a stream
 * independent of the picture's), per axis the 0.1 % and 99.9 % quantiles widened by 5 % of
 * the extent on each side (chaos_fit's rule for IFSs). The quantiles come
 * from two heaps per axis (tails.h); the points are sorted only when their
 * sum is not finite or a quantile is 0 (the sort's sign of zero). */
#define FSET_BOX_POINTS 16384
rt_code fset_chaos_box(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, double lo[3], double hi[3],
                       rt_error *e);

/* Widen the window lo..hi about its centre: each extent (a degenerate one,
 * <= 1e-12, first becomes max(1e-3, 10 % of the larger |bound|)) grows by
 * `margin` of itself on each side, then the shorter side grows until the
 * window has the aspect w:h of the image. */
void fset_fit_aspect(double lo[2], double hi[2], int w, int h, double margin);
/* The window of a 2-D function set's chaos game for a w×h image. Start from
 * the square ±R, R = max over the maps of |t|/(1 - c) (c the contraction
 * factor, affine_contraction) plus |start|, or ±1e6 when a map has c >= 0.999;
 * then four passes of the same game (at most 50,000 points, run in full in
 * every shard) into a 256×256 histogram of the window each narrow it to the
 * occupied cells plus one cell on each side, and
 * fset_fit_aspect with a 3 % margin ends it. RT_EINVAL when no point falls
 * in the first window. The passes play the same game, so when every point
 * lies in every window the cells of its extremes give each pass's result:
 * one game and no histograms (the passes as defined otherwise, e.g. for a
 * point beyond the first window or a NaN; tests/unit/test_fset_fit.c). */
rt_code fset_chaos_fit(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, int w, int h, double lo[2],
                       double hi[2], const rt_run *run, rt_error *e);

/* Bin of a plane point in a histogram (hist.h conventions), or -1 if it
 * falls outside (or is NaN). */
long fset_hist_bin(const hist2 *hs, double x, double y);

/* ---- deterministic iteration of a triangle mesh (seed 003 §3-4) ----------
 * The 3-D counterpart of detiter (detiter.h): one step with an IFS
 * W = {ω_1 .. ω_M} replaces the mesh K by ω_1(K) ∪ … ∪ ω_M(K), laid out
 * map-major (every vertex and triangle of K under ω_1 first, then under ω_2,
 * …; so the map applied first varies fastest along the copies); step k
 * uses W_σ(k) of the order. `copies` is M_σ(0)·…·M_σ(steps-1)
 * (detiter_count with one vertex gives it), so K_n has |V(K0)|·copies
 * vertices and |T(K0)|·copies triangles. Copy c is K0 under the composition
 * of its maps, composed once per copy in double, so every vertex is one
 * affine evaluation of a K0 vertex (not n rounded steps). A copy whose
 * composed linear part has det < 0 (it mirrors) has its triangles' winding
 * reversed: a K0 wound counter-clockwise seen from outside stays so, and a
 * closed K0 of volume v gives closed pieces of volume |det|·v each. Vertex
 * colours are carried along; normals are not (out has none; renderers then
 * use face normals). 2-D maps act on x, y and keep z. Fails with RT_EINVAL
 * when K_n would have 2^32 - 1 vertices or more (32-bit indices). Pure
 * per-copy work in parallel chunks: the same result for any thread count. */
rt_code fset_iterate_mesh(const fset *fs, const fset_order *o, size_t steps, size_t copies, const mesh *k0,
                          mesh *out, const rt_run *run, rt_error *e);

#endif
