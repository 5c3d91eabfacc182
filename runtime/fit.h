/* fit.h — fitting a 2-D IFS to a picture (the inverse problem; issue 16).
 *
 * Given a binary target mask, find N contractive affine maps whose attractor
 * draws it. Coordinates: the target's pixels normalised to the unit square,
 * y up: pixel (px, py) of a w×h mask (row 0 at the top) is the square
 * [px/w, (px+1)/w] × [1 - (py+1)/h, 1 - py/h]. The fitted maps act in that
 * frame, so the attractor rendered with the window [0, 1, 0, 1] at w×h lies
 * on the target.
 *
 * Parameterisation (every map contractive by construction). Map i is
 *     A_i = R(θ_i) · diag(s1_i, s2_i) · R(φ_i),   s = 0.98 · tanh(u)
 * plus a translation t_i: the singular value decomposition of a 2×2 matrix,
 * so every linear map with both singular values below 0.98 is reachable and
 * none above (a negative s is a reflection). The brief suggested a shear in
 * place of R(φ); a shear can make the norm exceed 1 even with |s| < 1, the
 * second rotation cannot. Probabilities p_i ∝ max(|det A_i|, 0.01·max|det|)
 * (Barnsley's rule, as ifs_build's default); the last stage refines them.
 *
 * Method.
 *  1. Levels. The target is max-pooled to grids of 32, 64, 128 and 256 cells
 *     on its longer side (only the levels not finer than the mask itself;
 *     the last level is the mask when it is smaller than 256). Each level
 *     has the target's Euclidean distance transform D_T (Felzenszwalb and
 *     Huttenlocher 2012, the 1-D lower envelope of parabolas, per axis).
 *  2. Collage initialisation (Barnsley's collage theorem: if the union of
 *     the w_i(T) is close to T, the attractor is close to T). The target's
 *     centroid c and principal axis angle α come from its moments. Maps are
 *     chosen greedily, one at a time, among A = R(β + a) diag(s1, ±s2) R(-a)
 *     with a = α or 0 (the principal axis of a shape with isotropic moments,
 *     like an equilateral triangle, is noise), β in 12 steps of 30°, eight
 *     (s1, s2) pairs and a reflection or not, translated so that A c lands on
 *     a candidate position. A candidate's score is the number of target
 *     cells its image w(T) newly covers minus the sum of D_T over the image
 *     points that fall outside T (times |s1·s2|, the image's area per mapped
 *     cell; points outside the frame count as a quarter of the grid's side).
 *     The best candidate is kept, its image marked covered, and the next map
 *     chosen. Two variants: (a) on the 64-cell grid, positions on a 12×12
 *     grid over the target's bounding box (the image of the centroid often
 *     falls in a hole), the search scoring at most ~600 target cells, each
 *     winner then polished (shifts of up to 2 cells, scale ±10 %, rotation
 *     ±5°, twice); (b) on the 32-cell grid, positions on up to 64 target
 *     cells. Neither wins on every target, so both start the refinement.
 *  3. Refinement against the attractor, level by level, coarse to fine. The
 *     loss of a parameter vector is computed from its attractor A rendered
 *     by a chaos game of P = clamp(10·|T|, 20000, 2^20) points (at most opts.max_points) (after 20
 *     burn-in steps, starting at the fixed point of map 1) into the level's
 *     grid (a cell is in A if one point falls in it):
 *         loss = mean_{t in T} d_A(t) + mean_{a in A} d_T(a) + (g/4)·f_out
 *     — coverage of the target by the attractor and the attractor outside
 *     the target, both as distances in cells (a symmetric chamfer
 *     distance, zero only when the masks agree), f_out the fraction of
 *     points outside the frame, g the grid's longer side. Every evaluation
 *     of a level uses the same random stream (common random numbers), so
 *     the loss is a fixed function of the parameters. The optimiser is a
 *     (1+4)-evolution strategy: each generation makes 4 offspring from the
 *     current parameters (mostly one map moved by Gaussian steps: half the
 *     time all its 6 parameters, a quarter of the time only its linear part
 *     θ, φ, u1, u2, a quarter only its translation — near the optimum a
 *     step in all six rarely improves all of them; sometimes all maps by
 *     smaller steps), evaluates them (in
 *     parallel, each its own buffers) and keeps the best if it is no worse;
 *     the step size grows by 1.2 on success and shrinks by 0.97 otherwise.
 *     The generations are split among the levels 40/30/20/10 % (coarse to
 *     fine); the step size restarts at each level at 0.6 of the last one.
 *     Multi-start: the coarse levels (the 32- and 64-cell grids when there
 *     are three or more levels, else the first) are run FIT_STARTS = 8 times:
 *     start k begins from collage (a) (k even) or (b) (k odd), moved by a
 *     Gaussian step of every parameter (0.1 of the step scales) when
 *     k mod 4 >= 2, and each start has its own offspring streams; the start
 *     with the smallest loss on the last coarse level goes on to the finer
 *     levels. (Without this, a fit often settles on a covering by misplaced
 *     copies; and two runs of the strategy from the same collage end at
 *     different precisions, so several streams per collage make the best of
 *     them a safer pick: on the Sierpinski triangle, four starts missed the
 *     goal on one seed in five.) With `start`, one start only.
 *  4. Probabilities: on the finest level, a few generations perturb the
 *     log-weights only (the support of the attractor does not depend on
 *     them, but with a finite number of points, coverage does).
 *
 * Randomness: all from rng streams of opts.seed (offspring k of generation
 * g: stream (level, g, k); the chaos game of level l: its own stream), and
 * the offspring are compared in index order, so the result is the same for
 * any thread count. A time budget (opts.time_s > 0) is checked after each
 * generation: the result then depends on the machine's speed; only an
 * iteration budget is deterministic.
 *
 * Recurrent IFS (opts.rifs). The parameters also hold an n×n pattern of
 * allowed transitions, all allowed at first; P_ij ∝ allowed_ij · p_j. A
 * fifth of the shape offspring flip one entry instead of moving a map; an
 * offspring whose pattern is not irreducible (seed 001 §2, condition (ii))
 * is rejected without being drawn. The chaos game of a RIFS picks the next
 * map from the row of the last one.
 *
 * A small cap (opts.max_points > 0, --max-points). Every chaos game of the loss draws
 * min(P, max_points) points. Below FIT_MIN_POINTS — where every target's P is capped — the
 * fit is a quick one, so that a small cap bounds the whole fit and not only its chaos games:
 * both collages try 4 rotations (steps of 90°, not 30°), collage (a) places its maps on a
 * 4×4 grid (not 12×12), scores at most ~100 target cells and polishes once, collage (b)
 * places them on at most 16 target cells (not 64), and the coarse levels run from 2 starts
 * (the two collages as they are), not FIT_STARTS. Without a cap, or with one at or above FIT_MIN_POINTS, nothing else changes.
 *
 * Map counts: opts.nmin..opts.nmax (one number when equal). For a range,
 * every count is fitted with the full budget and the one with the smallest
 *     loss_256 + FIT_PENALTY · N
 * is returned, loss_256 the final loss rescaled to a 256-cell grid.
 */
#ifndef FIT_H
#define FIT_H

#include <stdint.h>

#include "affine.h"
#include "image.h"
#include "rt.h"

#define FIT_MAX_MAPS 16
#define FIT_PENALTY 0.5
#define FIT_LAMBDA 4
#define FIT_STARTS 8
#define FIT_MIN_POINTS 20000 /* chaos-game points per evaluation without a smaller cap */

typedef struct fit_mask {
    int w, h;                /* >= 2 each */
    const unsigned char *m;  /* w*h, row 0 at the top; non-zero = foreground */
} fit_mask;

typedef struct fit_opts {
    int nmin, nmax;          /* 1 <= nmin <= nmax <= FIT_MAX_MAPS */
    long iterations;         /* generations per map count, >= 1 */
    uint64_t seed;
    double time_s;           /* > 0: stop after this many seconds (not deterministic) */
    const affine *start;     /* optional: nstart maps (frame coordinates) to refine */
    int nstart;
    int rifs;                /* fit a Recurrent IFS: the maps and which transitions are forbidden */
    double max_points;       /* > 0: at most this many chaos-game points per loss evaluation
                              * (--max-points); below FIT_MIN_POINTS also a quick search (see
                              * "A small cap" above); 0: no cap */
} fit_opts;

typedef struct fit_result {
    int n;
    affine maps[FIT_MAX_MAPS];  /* 2-D, frame coordinates */
    double p[FIT_MAX_MAPS];     /* sum 1 */
    int rifs;                   /* opts.rifs: P holds the fitted transition matrix */
    double P[FIT_MAX_MAPS * FIT_MAX_MAPS]; /* n×n row-major, rows sum 1 (an IFS: every row is p) */
    double loss;                /* final loss on the finest level (cells) */
    double loss256;             /* the same, rescaled to a 256-cell grid */
    long generations;           /* generations run (all map counts) */
    double points;              /* chaos-game points drawn by all loss evaluations */
} fit_result;

/* Foreground of an image. FIT_FG_AUTO: alpha if some pixel has alpha < 1,
 * else dark if the mean luma of the border pixels is >= 0.5 (a light
 * background), else light. Luma = 0.2126 r + 0.7152 g + 0.0722 b (Rec. 709,
 * on the stored values). dark: luma < threshold; light: luma >= threshold;
 * alpha: alpha >= threshold. out has w*h bytes (1 = foreground). Returns the
 * mode used. */
typedef enum fit_fg { FIT_FG_AUTO, FIT_FG_DARK, FIT_FG_LIGHT, FIT_FG_ALPHA } fit_fg;
fit_fg fit_mask_from_image(const image *im, fit_fg mode, double threshold, unsigned char *out);

/* Validate the mask (size, not empty, not all foreground) and fit. */
rt_code fit_run(const fit_mask *t, const fit_opts *o, const rt_run *run, fit_result *r, rt_error *e);

/* Decompose a 2-D linear part into θ, s1, s2, φ with A = R(θ) diag(s1, s2) R(φ)
 * (s1 >= |s2|). Exposed for tests. */
void fit_svd2(const double m[2][2], double *theta, double *s1, double *s2, double *phi);

#endif
