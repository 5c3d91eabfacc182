/* mpd.h — the 3-D random fractal D(P) by midpoint displacement, Types I–IV
 * (seed 000: Okada, Taga, Yokoi, Toriwaki).
 *
 * Lattice and coordinates. The field covers the unit cube [0,1]^3. With
 * maximum level R the lattice has 2^R + 1 nodes per axis; node (i, j, k),
 * 0 <= i, j, k <= 2^R, sits at P = (i, j, k) / 2^R. The 8 outer corners
 * (index x + 2y + 4z, x, y, z in {0, 1}) take the values given in
 * mpd_params.corner. A node's level is n = R - b, b the lowest set bit of
 * its coordinates (seed 000 eq. (8), taken over the three axes; the corners
 * are level 0). A node of level n >= 1 has one, two or three coordinates
 * that are odd multiples of h = 2^(R-n); its parents are its neighbours at
 * +-h along exactly those axes: an edge midpoint (2 parents, eq. (1)), a
 * face centre (4 edge midpoints, eq. (3)) or a cube centre (6 face centres,
 * eq. (4)). Its value is
 *     D = mean(parents) + g * L(n),   L(n) = exp(-(n-1) beta)   (eq. (2))
 * with the parents summed in a fixed order (x-, x+, y-, y+, z-, z+, pairs
 * added left to right) and the mean taken as *0.5, *0.25 or /6.
 *
 * The random g. g is a pure function of the seed and the node's normalised
 * key (n, i/2^(R-n), j/2^(R-n), k/2^(R-n)): the node's position as a dyadic
 * fraction of the cube in lowest terms. The same physical node has the same
 * key for every R, so raising R only adds finer nodes and never changes
 * coarser ones. (The paper's Type III seeds its PRNG with the R-dependent
 * s = x(2^R+1)^2 + y(2^R+1) + z, eq. (12); we depart from it for that
 * reason.) The key is hashed with rng_hash3 and the 53-bit uniform turned
 * into N(0,1) by the inverse normal CDF (Acklam's rational approximation,
 * relative error < 1.2e-9): no log/cos per node except in the 5% tails,
 * about 3x cheaper than Box–Muller and exactly deterministic (mpd_normal).
 *
 * Node values are computed in double and stored rounded to float (4 bytes a
 * node, the paper's "word"), in every type, so all four types compute
 * every node with the same arithmetic from the same float parents:
 * Types I–IV are bit-identical, interchangeable strategies.
 *
 * Between lattice nodes D is interpolated trilinearly: u = P * 2^R per axis,
 * cell c = min(floor(u), 2^R - 1), t = u - c, lerp along x, then y, then z
 * (a + t (b - a)). Coordinates outside [0, 1] (and NaN) are clamped to the
 * cube.
 *
 * The four types (mpd_params.type):
 *   1  Type I: the whole (2^R+1)^3 float array, filled level by level
 *      (eqs. (1)–(4)); memory C1 = N^3 words (eq. (13)). mpd_create refuses
 *      it beyond mem_limit and names Type IV's largest R2 that fits.
 *   2  Type II: nothing precomputed; the nodes a point needs are found by
 *      walking parents recursively (eqs. (8)–(11) per axis) and memoised in
 *      an open-addressing hash table that lives for one evaluation call (one
 *      per chunk of points in the parallel calls), so evaluation is
 *      reentrant. Memory grows with the nodes touched (eq. C2 = O(N^3)).
 *   3  Type III: per point, descend the octree from the root: at each level
 *      the 19 new nodes of the current cell (12 edge midpoints, 6 face
 *      centres, 1 centre) are computed from its 8 corners and the child
 *      cell holding the point is taken. The last path is kept (one 3x3x3
 *      block per level, 27 R words against the paper's 13*19*R, eq. (15)),
 *      and points are visited in Morton order so that neighbours share it.
 *   4  Type IV: Type I for levels <= R2 (an array of (2^R2+1)^3, eq. (16)),
 *      Type III below.
 *   0  automatic: Type I if it fits in mem_limit and max_nodes and the
 *      expected number of points (npoints_hint, 0 = unknown = many) is at
 *      least N^3/8; else Type IV with the largest R2 whose array fits in
 *      budget and max_nodes; else Type III.
 * Node limit. max_nodes (the interpreter passes --max-voxels) bounds every
 * store of lattice nodes that grows with R: an explicit Type I or IV whose
 * array has more nodes is refused (RT_EINVAL, the message names the
 * strategy that fits), the automatic choice stays within it, and Type II's
 * memo stops growing at max_nodes slots (points past that are computed by
 * the descent, with the same values). The fixed per-thread buffers — a
 * Type III path, a grid tile of (2^MPD_TILE_LOG+1)^3 floats — are working
 * memory, counted only as bytes.
 * Grid evaluation (mpd_eval_grid) of Types III and IV works per tile — a
 * cell of side 2^MPD_TILE_LOG lattice steps: its corners come from the
 * array or a descent, the nodes inside are filled level by level into a
 * (2^MPD_TILE_LOG+1)^3 buffer (Type I's code on a small box), and the grid
 * points in the tile are interpolated from it. Values are the same.
 *
 * Threads. mpd_create fills its array with par_for (each node is a pure
 * function of its parents and key, so the result does not depend on the
 * thread count). mpd_eval (the rt_field_fn) is single-threaded, reentrant
 * and uses no heap except Type II's memo (if that allocation fails it falls
 * back to the descent, which gives the same values). mpd_eval_points and
 * mpd_eval_grid split the work into fixed chunks with par_for.
 */
#ifndef MPD_H
#define MPD_H

#include <stddef.h>
#include <stdint.h>

#include "rt.h"

#define MPD_MAX_R 20
#define MPD_TILE_LOG 5

enum { MPD_AUTO = 0, MPD_TYPE1 = 1, MPD_TYPE2 = 2, MPD_TYPE3 = 3, MPD_TYPE4 = 4 };

typedef struct mpd_params {
    int R;                  /* maximum level, 1 .. MPD_MAX_R */
    double beta;            /* decay constant of L(n), finite */
    uint64_t seed;
    double corner[8];       /* level-0 values, index x + 2y + 4z */
    int type;               /* MPD_AUTO or MPD_TYPE1..4 */
    int R2;                 /* Type IV: levels held in the array, 0 .. R (-1: largest fitting budget) */
    size_t mem_limit;       /* bytes allowed for a Type I/IV array; 0 = 4 GiB */
    size_t budget;          /* automatic Type IV array budget in bytes; 0 = 64 MiB */
    size_t npoints_hint;    /* automatic strategy: expected number of points; 0 = unknown */
    double max_nodes;       /* lattice nodes allowed in an array or a memo; 0 = no limit */
} mpd_params;

/* Defaults: R = 6, beta = 0.5, seed 1, corners 0, automatic. */
void mpd_params_default(mpd_params *p);

typedef struct mpd {
    int R, type, R2;        /* resolved type (1..4); R2 = R for Type I, 0 for II/III */
    uint64_t seed;
    double beta;
    double corner[8];
    double L[MPD_MAX_R + 1];/* L(n) = exp(-(n-1) beta), n >= 1 */
    float *arr;             /* Type I (R2 = R) / Type IV: (2^R2+1)^3 nodes, x fastest */
    size_t arr_bytes;
    double max_nodes;       /* from mpd_params: caps Type II's memo (0 = no limit) */
} mpd;

/* Validate, choose the type, allocate and fill the array (Types I, IV).
 * Errors (RT_EINVAL) name the parameter, e.g. "R = 0 is out of range
 * (expected 1 .. 20)" or "Type I at R = 14 needs 17.6 TB (limit 4 GiB); use
 * Type IV (strategy: 4) with R2 = 9, or Type III (strategy: 3)". */
rt_code mpd_init(mpd *m, const mpd_params *p, const rt_run *run, rt_error *e);
void mpd_free(mpd *m);

/* rt_field_fn: ctx is a const mpd *. n points, any n. */
void mpd_eval(const void *ctx, size_t n, const double *x, const double *y, const double *z,
              double *out);

/* Work statistics of one parallel evaluation. */
typedef struct mpd_stats {
    size_t array_bytes;     /* the persistent array (Types I, IV) */
    size_t work_bytes;      /* largest working memory of one chunk (path, memo, tile) */
    size_t workers;         /* chunks in flight at once (threads used) */
    uint64_t nodes;         /* node values computed during evaluation (not the fill) */
} mpd_stats;

/* Evaluate n scattered points in parallel (fixed chunks of MPD_CHUNK points). */
#define MPD_CHUNK 4096
rt_code mpd_eval_points(const mpd *m, const rt_run *run, size_t n, const double *x, const double *y,
                        const double *z, double *out, mpd_stats *st, rt_error *e);

/* Evaluate the grid of nx*ny*nz points lo + (hi - lo) * i / (n - 1) per axis
 * (lo itself when n = 1), written x fastest into out. With lo = 0, hi = 1 and
 * n = 2^R + 1 these are exactly the lattice nodes. */
rt_code mpd_eval_grid(const mpd *m, const rt_run *run, const double lo[3], const double hi[3], int nx,
                      int ny, int nz, double *out, mpd_stats *st, rt_error *e);

/* Value of lattice node (i, j, k), 0 <= i, j, k <= 2^R (any type). */
double mpd_node(const mpd *m, uint32_t i, uint32_t j, uint32_t k);

/* The node random: N(0,1) deviate for normalised key (n, X, Y, Z). */
double mpd_node_random(uint64_t seed, int n, uint32_t X, uint32_t Y, uint32_t Z);
/* Inverse standard normal CDF of u in (0, 1) (Acklam's approximation). */
double mpd_inv_normal(double u);
/* N(0,1) from a 64-bit hash: mpd_inv_normal(((h >> 11) + 0.5) * 2^-53). */
double mpd_normal(uint64_t h);

/* Memory of the types in bytes, as this implementation uses it: Type I
 * array (4 N^3), Type III per-evaluator path (levels from..R-1), Type IV
 * array + path. 0 on overflow. */
size_t mpd_type1_bytes(int R);
size_t mpd_path_bytes(int levels);
size_t mpd_type4_bytes(int R, int R2);
/* Largest R2 <= R whose array fits in bytes and has at most nodes lattice
 * nodes (nodes 0 = no node limit); -1 if not even R2 = 0 fits. */
int mpd_largest_r2(int R, size_t bytes, double nodes);

#endif
