/* superifs.h — super IFS / V-variable fractals (seed 004 §5, eqs. (10)–(14)).
 *
 * N IFSs F^1 .. F^N (an fset, fset.h: F^n = sets[n-1], each with its maps
 * f^n_m and probabilities p^n_m) and probabilities P^1 .. P^N of choosing
 * them (eq. (11)). V buffers K_1 .. K_V. One step (eq. (14)) replaces every
 * buffer v by  ∪_m f^{n_v}_m(K_{v,m}),  where the IFS index n_v (with
 * probabilities P) and, for every map m, the input buffer K_{v,m} (uniform
 * over the V buffers) are drawn at random.
 *
 * Buffers are point sets, the chaos-game way: every buffer holds S points.
 * Point i of the new buffer v is f^{n_v}_m(point i of buffer K_{v,m}) with m
 * drawn by p^{n_v}: a sample of the union above, since point i of a buffer
 * is a random sample of that buffer's set (each index i follows its own
 * lineage back to A_0). Every buffer starts as S copies of opts->start.
 *
 * Draws (all from opts->seed; none depends on the thread count):
 *   n_v at step k          fset_choose(P, N, rng_hash3(seed, k, v, 0))
 *   K_{v,m} at step k      rng_hash3(seed, k, v, 1 + m) mod V
 *   map of point i         stream rng_hash3(seed, k, v, FSET_WALK_TAG),
 *                          chunk c = i / FSET_WALK_CHUNK, in order of i.
 * With V = 1 these are exactly the draws of fset_chaos in FSET_WALK mode
 * with the order {FSET_RANDOM, P, seed} and depth = steps: a 1-variable
 * super IFS is Asai's random function set (seed 004 §5 citing seed 003),
 * and the two give byte-identical histograms (test_superifs checks it).
 *
 * Maps must be 2-D. Work is chunked per (buffer, FSET_WALK_CHUNK points),
 * each chunk writing its own slice.
 *
 * Sharded (par.h): point i of every buffer depends only on points i of the
 * step before, so a run splits by chunks of FSET_WALK_CHUNK point indices
 * (the same in every buffer): a shard runs every step for its own chunks
 * and records, buffer by buffer, their rows of final points (PAR_OP_ROWS);
 * the merge places every shard's rows and has the single run's points.
 */
#ifndef SUPERIFS_H
#define SUPERIFS_H

#include <stddef.h>
#include <stdint.h>

#include "fset.h"
#include "hist.h"
#include "rt.h"

typedef struct superifs_opts {
    int V;           /* buffers, >= 1 */
    size_t points;   /* S, points per buffer, >= 1 */
    uint64_t steps;  /* iterations of eq. (14) */
    uint64_t seed;
    double start[2]; /* A_0 = {start} */
} superifs_opts;

typedef struct superifs_state {
    int V;
    size_t points;
    double *pts; /* V * points * 2: buffer v, point i at pts[2 (v S + i)] */
    int *ifs_of; /* V: n_v chosen at the last step (0-based), -1 if none */
} superifs_state;

/* The errors superifs_run would give for these arguments, without running. */
rt_code superifs_check(const fset *fs, const double *P, const superifs_opts *opts, rt_error *e);
/* ifs_of (V values) of the state superifs_run makes, from the draws alone. */
void superifs_last_ifs(const fset *fs, const double *P, const superifs_opts *opts, int *ifs_of);
/* Run opts->steps steps from A_0. P: N probabilities or NULL (equal). */
rt_code superifs_run(const fset *fs, const double *P, const superifs_opts *opts,
                     superifs_state *out, const rt_run *run, rt_error *e);
/* Add buffer v's points (0-based) to a histogram's counts. */
rt_code superifs_render(const superifs_state *s, int v, hist2 *hs, rt_error *e);
/* The box lo..hi of the finite points of all buffers (so every buffer can be
 * drawn at one scale); -1 if there are none. */
int superifs_bounds(const superifs_state *s, double lo[2], double hi[2]);
void superifs_free(superifs_state *s);

#endif
