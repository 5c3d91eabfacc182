/* ifs.h — iterated function systems (IFS) and recurrent IFS (RIFS), validated
 * and ready for the chaos game (chaos.h).
 *
 * IFS (seed 003 §2: {X; ω_1..ω_N} with probabilities p_1..p_N). Built by
 * ifs_build from N affine maps (affine.h), all of one dimension (2 or 3),
 * and a probability vector, or NULL for the default weights
 *     p_i ∝ max(|det A_i|, IFS_DET_FLOOR)
 * (Barnsley's rule: a map's share of the attractor's area/volume is its
 * determinant). A map with det 0 (a map onto a line, like the fern's stem)
 * would then never be chosen, so every weight gets the floor IFS_DET_FLOOR =
 * 0.01 of the *largest* |det| (or 1 if all are 0, i.e. equal weights).
 * Validation, in this order, stopping at the first failure:
 *     "IFS has no maps"
 *     "map 2 is 3-D but map 1 is 2-D (all maps need the same dimension)"
 *     "probability 3 is -0.1 (expected >= 0)"             (1-based index)
 *     "probabilities sum to 0.97, not 1 (use normalise to rescale them)"
 *     "probabilities are all 0"                             (even with normalise)
 *     "map 2 is not contractive: its norm is 1.2 (expected < 1)"
 * Probabilities must sum to 1 within IFS_SUM_TOL = 1e-9 unless
 * IFS_NORMALISE is set, in which case they are divided by their sum. The
 * contraction test uses the operator 2-norm (largest singular value,
 * affine_contraction); with IFS_ALLOW_EXPANDING the expanding map is accepted
 * and the message is left in ifs.warning (artistic IFSs sometimes have an
 * expanding map of small probability; the chaos game still converges if the
 * *average* contraction is < 1). ifs.max_contraction and ifs.worst_map
 * report the largest norm and its map (0-based).
 *
 * RIFS (seed 001 §2). Maps ω_1..ω_N and a Markov chain on map indices.
 *   Order 1: an N×N row-major matrix, P[i*N + j] = probability that ω_j is
 *     applied next when ω_i was applied last ("state i" = map i was last).
 *     Conditions: entries >= 0; every row sums to 1 within 1e-9 (or
 *     RIFS_NORMALISE divides each row by its sum; an all-zero row is an error
 *     either way); irreducible — the directed graph i → j (p_ij > 0) is
 *     strongly connected. Messages:
 *       "matrix entry (2, 3) is -0.1 (expected >= 0)"     (row, column, 1-based)
 *       "row 2 sums to 0.9, row 5 sums to 1.1 (each row must sum to 1)"
 *       "row 4 is all zero (the chain cannot leave state 4)"
 *       "matrix is not irreducible: state 3 cannot reach state 1"
 *     (the first unreachable pair in row-major order).
 *   Order 2 (seed 001 §5 "higher Markov order"): the next map depends on the
 *     last two. An (N·N)×N matrix: row r = i*N + j (ω_i applied, then ω_j)
 *     gives P[r*N + k] = probability of ω_k next. States are the pairs (i, j);
 *     (i, j) → (j, k) when P[(i,j)][k] > 0.
 *     *Our definition of irreducible for order 2*: not every pair need occur
 *     (if ω_i is never followed by ω_j, the pair (i, j) never happens and its
 *     row may be all zero). A row must either sum to 1 or be all zero; an
 *     all-zero row marks an unused pair. Among the used pairs (non-zero
 *     rows), the transition graph must have exactly one closed communicating
 *     class C (a strongly connected set with no edge leaving it): the chain
 *     started anywhere enters C and stays there, and on C it is irreducible.
 *     Used pairs outside C are transient (visited at most during the burn-in).
 *     No edge may lead into an unused pair, and every map must occur in C.
 *     Messages (pairs 1-based):
 *       "row (1, 2) sums to 0.9 (each row must sum to 1, or be all zero for an unused pair)"
 *       "pair (1, 2) can be followed by map 3, but row (2, 3) is all zero"
 *       "matrix is not irreducible: pair (1, 1) cannot reach pair (2, 2)"
 *       "map 3 never occurs in the recurrent pairs"
 *     rifs.start is the smallest pair (row index) of C: the chain starts there.
 *   For order 1, rifs.start = 0. Maps follow the IFS rules for dimension and
 *   contraction (with RIFS_ALLOW_EXPANDING).
 *
 * Alias tables (Walker 1977, Vose 1991): a probability vector of n entries is
 * turned into n columns; a 64-bit random word r picks column
 * c = ((r >> 32) * n) >> 32 and then sel[2c + (low32(r) < thresh[c])]:
 * sel[2c+1] = c itself, sel[2c] = its alias. The choice is a table lookup
 * indexed by a comparison result: no branch, no loop. thresh is a 32-bit
 * fixed-point fraction; a column that keeps all of its own mass has its alias
 * set to itself, and zero-probability entries are never an alias, so a
 * probability 0 is exactly never chosen (forbidden RIFS transitions stay
 * forbidden). Other probabilities are exact to about n·2^-32.
 */
#ifndef IFS_H
#define IFS_H

#include <stddef.h>
#include <stdint.h>

#include "affine.h"
#include "rt.h"

#define IFS_MAX_MAPS 256
#define IFS_SUM_TOL 1e-9
#define IFS_DET_FLOOR 0.01

/* flags for ifs_build / rifs_build */
#define IFS_NORMALISE 1        /* rescale probabilities (rows) to sum 1 */
#define IFS_ALLOW_EXPANDING 2  /* an expanding map is a warning, not an error */
#define RIFS_NORMALISE IFS_NORMALISE
#define RIFS_ALLOW_EXPANDING IFS_ALLOW_EXPANDING

typedef struct ifs_alias {
    int n;
    uint32_t *thresh; /* n */
    uint32_t *sel;    /* 2n: sel[2c] alias, sel[2c+1] = c */
} ifs_alias;

/* Build an alias table from n >= 1 non-negative weights (any positive sum;
 * they are normalised). Returns RT_EINVAL if the sum is not > 0. */
rt_code ifs_alias_build(ifs_alias *a, const double *w, int n, rt_error *e);
void ifs_alias_free(ifs_alias *a);

/* The branch-free draw described above. */
static inline uint32_t ifs_alias_pick(const ifs_alias *a, uint64_t r)
{
    uint32_t c = (uint32_t)(((r >> 32) * (uint64_t)a->n) >> 32);
    return a->sel[2 * c + ((uint32_t)r < a->thresh[c])];
}

/* The exact probability the table gives entry i (for tests). */
double ifs_alias_prob(const ifs_alias *a, int i);

typedef struct ifs {
    int n;      /* maps, 1 .. IFS_MAX_MAPS */
    int dim;    /* 2 or 3 */
    affine *maps;      /* n, owned copy */
    double *p;         /* n, normalised probabilities actually used */
    ifs_alias alias;   /* built from p */
    double max_contraction; /* largest operator norm */
    int worst_map;          /* 0-based map with that norm */
    char warning[256];      /* non-empty if an expanding map was allowed */
} ifs;

/* Validate and build. p may be NULL (default |det| weights). On failure *out
 * is left empty (safe to ifs_free). */
rt_code ifs_build(ifs *out, const affine *maps, int n, const double *p, int flags, rt_error *e);
void ifs_free(ifs *f);

typedef struct rifs {
    int n, dim;
    int order;       /* 1 or 2 */
    int rows;        /* n (order 1) or n*n (order 2) */
    affine *maps;    /* n, owned */
    double *P;       /* rows × n, normalised, owned */
    ifs_alias *row;  /* rows alias tables (an all-zero row has n = 0) */
    int start;       /* starting state: map index (order 1) or pair row (order 2) */
    double max_contraction;
    int worst_map;
    char warning[256];
} rifs;

/* Validate and build. P has (order == 1 ? n : n*n) rows of n entries. */
rt_code rifs_build(rifs *out, const affine *maps, int n, int order, const double *P, int flags,
                   rt_error *e);
void rifs_free(rifs *r);

/* Stationary distribution over maps of an order-1 RIFS (pi P = pi), by power
 * iteration on the lazy chain (P + I)/2; pi has n entries. For order 2 the
 * distribution of the last map. Used for documentation and checks. */
rt_code rifs_stationary(const rifs *r, double *pi, rt_error *e);

/* Check maps only (count, dimension, contraction); shared by both builders.
 * Fills *dim, *maxc, *worst; warn (256 bytes) gets the expanding-map message
 * when allowed. */
rt_code ifs_check_maps(const affine *maps, int n, int allow_expanding, int *dim, double *maxc,
                       int *worst, char *warn, rt_error *e);

#endif
