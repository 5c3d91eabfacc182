/* detiter.h — deterministic iteration K_n = W^n(K_0) (seed 003 §2-2, §3-2).
 *
 * A shape is a list of polylines in 2-D or 3-D: all vertices in one array
 * (dim doubles each), polyline i owning vertices start[i] .. start[i+1]-1,
 * with a closed flag (a polygon: the last vertex joins the first). A point
 * set is a list of one-vertex polylines.
 *
 * One step with an IFS W = {ω_1 .. ω_M} replaces the shape by the union of
 * its images, ω_1(K) ∪ … ∪ ω_M(K) (seed 003 thm 2.1), laid out map-major:
 * first every polyline of K mapped by ω_1 (in K's order), then every one
 * mapped by ω_2, and so on. With a function set, step k (k = 0 first) uses
 * the set W_σ(k) named by the order (fset.h): K_4 = W_2(W_1(W_2(W_1(K_0))))
 * is the order {W1, W2, W1, W2} in application order. A SEQUENCE order must
 * be at least as long as the number of steps.
 *
 * The number of vertices grows as |K_0|·M_1·M_2·…: detiter_count computes
 * it first (with overflow check) and detiter_run fails with RT_EINVAL
 * naming it and the limit when it exceeds max_vertices — before allocating.
 * The mapping of each step runs in parallel over fixed chunks of vertices
 * (pure per-vertex work, so the result is the same for any thread count).
 */
#ifndef DETITER_H
#define DETITER_H

#include <stddef.h>

#include "fset.h"
#include "rt.h"

typedef struct detiter_shape {
    int dim;               /* 2 or 3 */
    size_t nverts;
    double *v;             /* nverts * dim */
    size_t npoly;
    size_t *start;         /* npoly + 1 entries, start[npoly] == nverts */
    unsigned char *closed; /* npoly flags */
} detiter_shape;

typedef enum detiter_kind { DETITER_POINTS, DETITER_POLYLINE, DETITER_POLYGON } detiter_kind;

/* A shape from n vertices (dim doubles each, copied): n separate points,
 * one open polyline, or one closed polygon. */
rt_code detiter_shape_make(detiter_shape *s, int dim, size_t n, const double *v,
                           detiter_kind kind, rt_error *e);
void detiter_shape_free(detiter_shape *s);

/* Vertices after `steps` steps from a shape of nverts0 vertices; returns
 * RT_EINVAL (message naming the overflow) if it does not fit a size_t. */
rt_code detiter_count(const fset *fs, const fset_order *o, size_t steps, size_t nverts0,
                      size_t *out, rt_error *e);

/* out = W_σ(steps-1) ∘ … ∘ W_σ(0)(k0). steps may be 0 (a copy). The maps'
 * dimension must equal k0->dim (2-D maps may iterate a 3-D shape: z is
 * then kept as it is). */
rt_code detiter_run(const fset *fs, const fset_order *o, size_t steps, const detiter_shape *k0,
                    size_t max_vertices, detiter_shape *out, const rt_run *run, rt_error *e);

/* Total length of all segments (closing segments of polygons included). */
double detiter_length(const detiter_shape *s);

/* ---- shape arithmetic (new shapes; the arguments are not changed) ----
 * Bounds of the x, y of every vertex (lo > hi on an axis when s is empty). */
void detiter_bounds(const detiter_shape *s, double lo[2], double hi[2]);
/* out = x ∪ y: x's polylines, then y's (same dimension, else RT_EINVAL). */
rt_code detiter_shape_join(const detiter_shape *x, const detiter_shape *y, detiter_shape *out, rt_error *e);
/* out = m(s), polylines as in s; a 2-D map on a 3-D shape keeps z; a 3-D
 * map on a 2-D shape is RT_EINVAL. */
rt_code detiter_shape_map(const detiter_shape *s, const affine *m, detiter_shape *out, rt_error *e);
/* out = s + t (t has s->dim numbers) and out = k·s, vertex by vertex. */
rt_code detiter_shape_shift(const detiter_shape *s, const double *t, detiter_shape *out, rt_error *e);
rt_code detiter_shape_scale(const detiter_shape *s, double k, detiter_shape *out, rt_error *e);

#endif
