/* ist.h — the Iterated Shuffle Transformation (seed 002 §4.1, Fig. 2, Fig. 3)
 * and the adaptive choice of sampled sub-intervals (seed 002 §5.2, eq. 12-14).
 *
 * An IST is a discontinuous one-to-one map u_d = F(u_s) of an axis onto
 * itself. The axis [a, b] is split into N base intervals A_i = [a_i, a_{i+1});
 * each has a crossing count M_i. Start with the lists L_i^0 = {A_i}. In each
 * of K rounds every small interval in L_j^{k-1} is cut into 2M_j+1 pieces, in
 * proportion to the lengths of the base intervals the pieces go to, and piece
 * t (t = 0..2M_j, left to right) goes to the base interval j - M_j + t, into
 * the list L_i^k. After K rounds A_i corresponds linearly, piece by piece, to
 * the small intervals of L_i^K; a joint belongs to the right-hand piece.
 *
 * Our readings, where §4.1 leaves a choice (documented in SEEDS.md style):
 *  - Order of L_i^k. Every piece arriving at i carries a key (d, t): d is the
 *    signed distance (unwrapped on a cyclic axis) from i to the interval it
 *    came from, t its piece index. L_i^k is ordered by d, then t, then by the
 *    order inside the source list L_j^{k-1}. For one M on a cyclic axis this
 *    is the order of the paper's Fig. 2 (checked: interval 5 holds top digits
 *    {3,4,5},{4,5,6},{5,6,7} for M = 1, K = 2).
 *  - Translation axis ends (Fig. 3a). A piece whose target j - M_j + t lies
 *    beyond an end stays in its own interval j (key d = 0, ordered by t). With
 *    one M and equal lengths every list then still holds 2M+1 entries per
 *    round, the interval's own centre piece stays at the middle slot, so the
 *    centres of the base intervals stay fixed, and so do both ends a and b.
 *    F is one-to-one because every piece goes to exactly one list.
 *  - Linear correspondence. A_i is cut into consecutive destination slots of
 *    lengths proportional to the (source) lengths of the entries of L_i^K, so
 *    on A_i the map F^{-1} has slope (Σ entry lengths)/|A_i|. With equal base
 *    lengths and one M all slots are |A_i|/(2M+1)^K and every base
 *    interval's centre is fixed. With unequal lengths or several M the
 *    centres are fixed only where the neighbourhood is symmetric (tests:
 *    test_general).
 *  - Cyclic axes need 2M_i+1 <= N for every interval: the 2M+1 pieces of an
 *    interval go to 2M+1 different intervals. A larger M would deal several
 *    pieces of one interval to the same list; ist_init refuses it.
 *  - Cyclic axes wrap with period b - a: F^{-1}(u + P) = F^{-1}(u) + P.
 *    Translation axes are the identity outside [a, b).
 *
 * Two evaluators, which agree (tests check it to 1e-12):
 *  - the general one builds the lists L_i^K exactly as §4.1 describes (cost
 *    Σ|L_i^K| entries; refused above IST_MAX_ENTRIES) and evaluates F and
 *    F^{-1} by binary search;
 *  - the closed form for equal lengths and one M (SEEDS.md 002): write the
 *    offset of u in A_i in base B = 2M+1 as digits p_1..p_K; each digit picks
 *    a slot (d, t) of the current interval, so the source interval is
 *    i + Σ d_m (on a cyclic axis d_m = p_m - M) and the source offset is
 *    0.t_K t_{K-1} … t_1 in base B plus the remainder. O(K), no memory.
 *    This is the default whenever it applies (ist_spec.method = IST_AUTO).
 *
 * Usage:
 *     ist t; ist_spec s = {.n = 10, .m = 1, .k = 3, .axis = IST_CYCLIC};
 *     if (ist_init(&t, &s, &err)) ...;
 *     double src = ist_inv(&t, u);   // F^{-1}(u)
 *     ist_free(&t);
 *
 * Adaptive sampling (§5.2): with S = B^K sub-intervals per base interval and
 * a level K_i ≤ K for interval i, S_i = B^{K_i} sub-intervals are sampled:
 * the ((S/S_i + 1)/2)-th (1-based) and every (S/S_i)-th after it, i.e. the
 * 0-based indices (S/S_i - 1)/2 + m·S/S_i, m = 0..S_i-1. Because S/S_i is
 * odd, the centre of each chosen sub-interval is the centre of a level-K_i
 * sub-interval, so raising K keeps the top-digit structure (Fig. 7).
 */
#ifndef IST_H
#define IST_H

#include <stddef.h>
#include <stdint.h>

#include "fileio.h"
#include "rt.h"

#define IST_MAX_ENTRIES ((size_t)1 << 24) /* cap on Σ|L_i^K| for the list evaluator */
/* K's range. Double precision bounds it: a sub-interval narrower than
 * IST_MIN_ULPS ulps of the axis's largest |coordinate| X cannot be kept
 * apart from its neighbours (with (2M+1)^K near 2^52 the sub-intervals near
 * u = N are narrower than one ulp of u), so ist_init refuses such a K with
 * a message naming the largest K that works (ist_k_limit). No axis with
 * M >= 1 passes above K = 29: h/X <= 2 (up to rounding), so
 * 3^K <= 2^53/64 = 2^47 and 3^29 < 2^47 < 3^30. */
#define IST_MAX_K 29
#define IST_MIN_ULPS 64

typedef enum ist_axis_type { IST_TRANSLATION = 0, IST_CYCLIC = 1 } ist_axis_type;
/* IST_CLOSED_DIGITS: the closed form evaluated one base-B digit at a time,
 * never the grouped fast path: the reference the fast path is tested
 * against (tests/unit/test_ist.c), also usable to measure the gain. */
typedef enum ist_method { IST_AUTO = 0, IST_LISTS = 1, IST_CLOSED = 2, IST_CLOSED_DIGITS = 3 } ist_method;

typedef struct ist_spec {
    int n;                /* number of base intervals N >= 1 */
    const double *bounds; /* N+1 strictly increasing bounds, or NULL for [i, i+1), i = 0..N-1 */
    int m;                /* crossing count of every interval (when m_each is NULL), >= 0 */
    const int *m_each;    /* N crossing counts, or NULL */
    int k;                /* iterations K >= 0 */
    ist_axis_type axis;
    ist_method method;    /* AUTO: closed form when it applies, else lists */
} ist_spec;

typedef struct ist {
    int n, k, axis;
    int closed;   /* 1: closed-form evaluator, 0: lists */
    int m;        /* the one M (closed form) */
    int b;        /* 2M+1 (closed form) */
    uint64_t s;   /* B^K (closed form) */
    double a0, h; /* closed form: a_i = a0 + i·h */
    double *bounds; /* n+1 */
    int *ms;        /* n crossing counts */
    /* list evaluator (and ist_print): the entries of L_i^K for i = 0..n-1,
     * stored one list after another */
    size_t ne;
    size_t *start;     /* n+1 offsets into the entry arrays */
    double *x, *len;   /* source start and length of each entry */
    double *cum;       /* start of each entry inside its list, in source-length units */
    double *total;     /* n: Σ lengths of L_i^K */
    uint64_t *label;   /* Fig. 2 digits, 6 bits each, first piece first (NULL if K > 9 or M > 31) */
    uint32_t *slot;    /* slot index of the last round (for the '|' separators of ist_print) */
    uint32_t *owner;   /* list each entry belongs to */
    size_t *by_x;      /* entries sorted by source start (for F) */
    /* closed-form fast path of F^{-1} (ist.c) when 3 <= B and B^K < 2^32:
     * the K base-B digits are taken g at a time with small tables (one
     * multiply-by-reciprocal division per group instead of one division
     * per digit); bit-identical to the per-digit evaluation. ftab is NULL
     * when the fast path is not in use. */
    uint32_t *ftab;   /* B^g entries: reversed complement | digit sum << 16 */
    uint32_t *ftop;   /* the same for the r = K mod g top digits (or ftab) */
    uint32_t *fdig;   /* B^g packed digits, 4 bits each (translation axis, B <= 15), or NULL */
    uint32_t *fpre, *fpretop; /* with fdig: prefix-sum ranges of the groups (ist.c) */
    int fg, fdiv;     /* g, and the number of group divisions */
    int ftopd;        /* digits in the top group (r, or g when r = 0) */
    uint32_t fbg;     /* B^g */
    uint32_t fmul;    /* floor(2^32 / B^g) */
    uint32_t fbtop;   /* B^ftopd */
    int fh2;          /* h is a power of two: x/h computed exactly as x·fih */
    double fih;
} ist;

/* Validate spec and prepare the evaluator (builds the lists when needed).
 * Errors: RT_EINVAL with a message naming the offending value, RT_ENOMEM. */
rt_code ist_init(ist *t, const ist_spec *spec, rt_error *e);
void ist_free(ist *t);
/* The largest K (<= IST_MAX_K) that keeps sub-intervals IST_MIN_ULPS ulps
 * wide for spec's axis: exact for equal lengths and one M (the narrowest
 * base interval and the largest M otherwise, where ist_init also checks the
 * pieces the lists actually hold). IST_MAX_K when every M is 0. */
int ist_k_limit(const ist_spec *spec);

/* F^{-1}(u): the source coordinate whose attributes appear at u (eq. 9). */
double ist_inv(const ist *t, double u);
/* F^{-1} of n coordinates: out[q] = ist_inv(t, u[q]) bit for bit (out may
 * be u). A tight loop for tessellation and benchmarks. */
void ist_inv_block(const ist *t, size_t n, const double *u, double *out);
/* F(u): where the source coordinate u is moved to (eq. 6). */
double ist_fwd(const ist *t, double u);

/* Build the lists (if the closed form is in use) so ist_print works. */
rt_code ist_build_lists(ist *t, rt_error *e);

/* Print L_i^K for every base interval in Fig. 2 notation: each entry is the
 * number of its source base interval followed by its sub-interval digits
 * (6 → {60,61,62} → {600,601,…}); '|' separates the blocks that arrived in
 * the last round. One line per interval: "L5: 322 412 502 | 421 …".
 * Numbers are written without separators when N <= 10 and 2M+1 <= 10, else
 * as "j:d.d.d". Builds the lists if needed; refuses K > 9 or M > 31. */
rt_code ist_print(ist *t, bytebuf *out, rt_error *e);

/* 0-based index of the m-th sampled sub-interval among s = b^k when s_i =
 * b^{k_i} are sampled (§5.2). */
uint64_t ist_sample_index(int b, int k, int ki, uint64_t m);

/* Sample positions on the destination axis (§5.2): for each base interval i
 * (in order) the centres of its chosen sub-intervals, with K = t->k and
 * levels ki[i] (clamped to [0, K]); jitter = 0 samples the centre of each
 * chosen sub-interval, jitter = 1 a uniform random point inside it (rng
 * stream = interval index, seeded with seed). Writes at most cap positions
 * to out (increasing) and returns the number that would be written
 * (Σ (2M_i+1)^{ki[i]}). */
size_t ist_sample_positions(const ist *t, const int *ki, int jitter, uint64_t seed, double *out,
                            size_t cap);

#endif
