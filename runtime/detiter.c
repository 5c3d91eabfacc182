/* detiter.c — deterministic iteration W^n(K_0) of polylines
 * (seed 003 thm 2.1: W(B) = ∪ ω_n(B); §3-2: a function set applies W_σ(k)
 * at step k). */
#include "detiter.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"

#define VERT_CHUNK 65536

rt_code detiter_shape_make(detiter_shape *s, int dim, size_t n, const double *v,
                           detiter_kind kind, rt_error *e)
{
    memset(s, 0, sizeof *s);
    if (dim != 2 && dim != 3)
        return rt_fail(e, RT_EINVAL, "shape dimension %d (expected 2 or 3)", dim);
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "shape has no vertices (expected at least 1)");
    if (kind == DETITER_POLYGON && n < 3)
        return rt_fail(e, RT_EINVAL, "polygon has %zu vertices (expected at least 3)", n);
    if (kind == DETITER_POLYLINE && n < 2)
        return rt_fail(e, RT_EINVAL, "polyline has %zu vertex (expected at least 2)", n);
    size_t np = kind == DETITER_POINTS ? n : 1;
    s->v = rt_malloc(rt_mul_size(n, (size_t)dim) * sizeof *s->v);
    s->start = rt_malloc((np + 1) * sizeof *s->start);
    s->closed = rt_malloc(np);
    if (!s->v || !s->start || !s->closed) {
        detiter_shape_free(s);
        return rt_fail(e, RT_ENOMEM, "out of memory for a shape of %zu vertices", n);
    }
    s->dim = dim;
    s->nverts = n;
    s->npoly = np;
    memcpy(s->v, v, n * (size_t)dim * sizeof *v);
    for (size_t i = 0; i < np; i++) {
        s->start[i] = kind == DETITER_POINTS ? i : 0;
        s->closed[i] = kind == DETITER_POLYGON;
    }
    s->start[np] = n;
    return RT_OK;
}

void detiter_shape_free(detiter_shape *s)
{
    rt_free(s->v);
    rt_free(s->start);
    rt_free(s->closed);
    memset(s, 0, sizeof *s);
}

rt_code detiter_count(const fset *fs, const fset_order *o, size_t steps, size_t nverts0,
                      size_t *out, rt_error *e)
{
    size_t n = nverts0;
    for (size_t k = 0; k < steps; k++) {
        int m = fs->sets[fset_order_at(o, fs->n, k)].n;
        size_t nn = rt_mul_size(n, (size_t)m);
        if (n && !nn)
            return rt_fail(e, RT_EINVAL,
                           "deterministic iteration of %zu steps overflows the vertex count at "
                           "step %zu",
                           steps, k + 1);
        n = nn;
    }
    *out = n;
    return RT_OK;
}

typedef struct step_ctx {
    const fset_ifs *w;
    const detiter_shape *cur;
    detiter_shape *next;
} step_ctx;

static void step_chunk(void *p, size_t chunk, int worker)
{
    (void)worker;
    step_ctx *c = p;
    size_t nv = c->cur->nverts, total = nv * (size_t)c->w->n;
    size_t lo = chunk * VERT_CHUNK, hi = lo + VERT_CHUNK < total ? lo + VERT_CHUNK : total;
    int dim = c->cur->dim;
    for (size_t j = lo; j < hi; j++) {
        size_t m = j / nv, i = j % nv;
        const affine *a = &c->w->maps[m];
        const double *src = c->cur->v + i * (size_t)dim;
        double *dst = c->next->v + j * (size_t)dim;
        if (dim == 2) {
            double x = src[0], y = src[1];
            fset_apply2(a, &x, &y);
            dst[0] = x;
            dst[1] = y;
        } else {
            affine_apply(a, src, dst);
        }
    }
}

rt_code detiter_run(const fset *fs, const fset_order *o, size_t steps, const detiter_shape *k0,
                    size_t max_vertices, detiter_shape *out, const rt_run *run, rt_error *e)
{
    memset(out, 0, sizeof *out);
    rt_code code = fset_validate(fs, e);
    if (code)
        return code;
    if ((code = fset_order_validate(o, fs->n, e)))
        return code;
    if (o->kind == FSET_SEQUENCE && steps > (size_t)o->len)
        return rt_fail(e, RT_EINVAL,
                       "order has %d steps but deterministic iteration asks for %zu", o->len,
                       steps);
    if (!k0 || k0->nverts < 1 || k0->npoly < 1)
        return rt_fail(e, RT_EINVAL, "initial set K0 is empty");
    int mdim = fs->sets[0].maps[0].dim;
    if (mdim > k0->dim)
        return rt_fail(e, RT_EINVAL, "the maps are %d-D but the initial set K0 is %d-D", mdim,
                       k0->dim);
    size_t need;
    if ((code = detiter_count(fs, o, steps, k0->nverts, &need, e)))
        return code;
    if (need > max_vertices)
        return rt_fail(e, RT_EINVAL,
                       "deterministic iteration of %zu steps would need %zu vertices (limit %zu)",
                       steps, need, max_vertices);

    detiter_shape cur;
    if ((code = detiter_shape_make(&cur, k0->dim, k0->nverts, k0->v, DETITER_POINTS, e)))
        return code;
    /* Replace the point structure by k0's polylines. */
    rt_free(cur.start);
    rt_free(cur.closed);
    cur.npoly = k0->npoly;
    cur.start = rt_malloc((k0->npoly + 1) * sizeof *cur.start);
    cur.closed = rt_malloc(k0->npoly);
    if (!cur.start || !cur.closed) {
        detiter_shape_free(&cur);
        return rt_fail(e, RT_ENOMEM, "out of memory for the initial set");
    }
    memcpy(cur.start, k0->start, (k0->npoly + 1) * sizeof *cur.start);
    memcpy(cur.closed, k0->closed, k0->npoly);

    for (size_t k = 0; k < steps; k++) {
        const fset_ifs *w = &fs->sets[fset_order_at(o, fs->n, k)];
        size_t M = (size_t)w->n;
        detiter_shape nx = {cur.dim, cur.nverts * M, NULL, cur.npoly * M, NULL, NULL};
        nx.v = rt_malloc(nx.nverts * (size_t)nx.dim * sizeof *nx.v);
        nx.start = rt_malloc((nx.npoly + 1) * sizeof *nx.start);
        nx.closed = rt_malloc(nx.npoly);
        if (!nx.v || !nx.start || !nx.closed) {
            detiter_shape_free(&nx);
            detiter_shape_free(&cur);
            return rt_fail(e, RT_ENOMEM, "out of memory for %zu vertices at step %zu", nx.nverts,
                           k + 1);
        }
        for (size_t m = 0; m < M; m++)
            for (size_t i = 0; i < cur.npoly; i++) {
                nx.start[m * cur.npoly + i] = m * cur.nverts + cur.start[i];
                nx.closed[m * cur.npoly + i] = cur.closed[i];
            }
        nx.start[nx.npoly] = nx.nverts;
        step_ctx c = {w, &cur, &nx};
        code = par_for(run, "iterate", (nx.nverts + VERT_CHUNK - 1) / VERT_CHUNK, step_chunk, &c);
        detiter_shape_free(&cur);
        cur = nx;
        if (code) {
            detiter_shape_free(&cur);
            return rt_fail(e, code, "interrupted");
        }
    }
    *out = cur;
    return RT_OK;
}

double detiter_length(const detiter_shape *s)
{
    double total = 0;
    int d = s->dim;
    for (size_t p = 0; p < s->npoly; p++) {
        size_t a = s->start[p], b = s->start[p + 1];
        if (b - a < 2)
            continue;
        size_t last = s->closed[p] ? b : b - 1;
        for (size_t i = a; i < last; i++) {
            size_t j = i + 1 < b ? i + 1 : a;
            double q = 0;
            for (int c = 0; c < d; c++) {
                double t = s->v[j * (size_t)d + c] - s->v[i * (size_t)d + c];
                q += t * t;
            }
            total += sqrt(q);
        }
    }
    return total;
}

/* ---- shape arithmetic ---------------------------------------------------- */

void detiter_bounds(const detiter_shape *s, double lo[2], double hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    for (size_t i = 0; i < s->nverts; i++)
        for (int k = 0; k < 2; k++) {
            double x = s->v[i * (size_t)s->dim + (size_t)k];
            if (x < lo[k])
                lo[k] = x;
            if (x > hi[k])
                hi[k] = x;
        }
}

/* An empty shape with room for nv vertices and np polylines. */
static rt_code shape_alloc(detiter_shape *s, int dim, size_t nv, size_t np, rt_error *e)
{
    memset(s, 0, sizeof *s);
    s->dim = dim;
    size_t vb = rt_mul_size(nv ? nv : 1, (size_t)dim * sizeof(double)), sb = rt_mul_size(np + 1, sizeof(size_t));
    s->v = vb ? rt_malloc(vb) : NULL; /* 0: the size overflowed */
    s->start = sb ? rt_malloc(sb) : NULL;
    s->closed = rt_malloc(np ? np : 1);
    if (!s->v || !s->start || !s->closed) {
        detiter_shape_free(s);
        return rt_fail(e, RT_ENOMEM, "out of memory for a shape of %zu vertices", nv);
    }
    s->nverts = nv;
    s->npoly = np;
    return RT_OK;
}

rt_code detiter_shape_join(const detiter_shape *x, const detiter_shape *y, detiter_shape *out, rt_error *e)
{
    if (x->dim != y->dim)
        return rt_fail(e, RT_EINVAL, "a %d-D and a %d-D shape cannot be joined", x->dim, y->dim);
    rt_code c = shape_alloc(out, x->dim, x->nverts + y->nverts, x->npoly + y->npoly, e);
    if (c)
        return c;
    memcpy(out->v, x->v, sizeof(double) * x->nverts * (size_t)x->dim);
    memcpy(out->v + x->nverts * (size_t)x->dim, y->v, sizeof(double) * y->nverts * (size_t)y->dim);
    for (size_t i = 0; i < x->npoly; i++) {
        out->start[i] = x->start[i];
        out->closed[i] = x->closed[i];
    }
    for (size_t i = 0; i < y->npoly; i++) {
        out->start[x->npoly + i] = x->nverts + y->start[i];
        out->closed[x->npoly + i] = y->closed[i];
    }
    out->start[out->npoly] = out->nverts;
    return RT_OK;
}

typedef enum { MOVE_MAP, MOVE_SHIFT, MOVE_SCALE } move_kind;

/* out = src with every vertex mapped, shifted by t or scaled by k. */
static rt_code shape_move(const detiter_shape *src, move_kind kind, const affine *m, const double *t, double k,
                          detiter_shape *out, rt_error *e)
{
    rt_code c = shape_alloc(out, src->dim, src->nverts, src->npoly, e);
    if (c)
        return c;
    memcpy(out->start, src->start, sizeof(size_t) * (src->npoly + 1));
    memcpy(out->closed, src->closed, src->npoly);
    for (size_t i = 0; i < src->nverts; i++) {
        const double *p = src->v + i * (size_t)src->dim;
        double *q = out->v + i * (size_t)src->dim;
        if (kind == MOVE_MAP) {
            double in[3] = {p[0], p[1], src->dim == 3 ? p[2] : 0}, o3[3];
            affine_apply(m, in, o3);
            for (int d = 0; d < m->dim; d++)
                q[d] = o3[d];
            if (m->dim < src->dim)
                q[2] = p[2];
        } else {
            for (int d = 0; d < src->dim; d++)
                q[d] = kind == MOVE_SHIFT ? p[d] + t[d] : p[d] * k;
        }
    }
    return RT_OK;
}

rt_code detiter_shape_map(const detiter_shape *s, const affine *m, detiter_shape *out, rt_error *e)
{
    if (m->dim > s->dim)
        return rt_fail(e, RT_EINVAL, "a %d-D map cannot apply to a %d-D shape", m->dim, s->dim);
    return shape_move(s, MOVE_MAP, m, NULL, 1, out, e);
}

rt_code detiter_shape_shift(const detiter_shape *s, const double *t, detiter_shape *out, rt_error *e)
{
    return shape_move(s, MOVE_SHIFT, NULL, t, 1, out, e);
}

rt_code detiter_shape_scale(const detiter_shape *s, double k, detiter_shape *out, rt_error *e)
{
    return shape_move(s, MOVE_SCALE, NULL, NULL, k, out, e);
}
