/* superifs.c — V-variable super IFS with point-set buffers (seed 004 eq. (14)). */
#include "superifs.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"
#include "rng.h"

typedef struct step_ctx {
    const fset *fs;
    const superifs_opts *opts;
    uint64_t k;
    size_t first, chunks_per_buf; /* the point chunks first .. first + chunks_per_buf - 1 of every buffer */
    const int *nv;      /* V: IFS of each buffer this step */
    const int *input;   /* V * FSET_MAX_MAPS: K_{v,m} */
    const double *cum;  /* N * FSET_MAX_MAPS */
    const double *from; /* old buffers */
    double *to;         /* new buffers */
} step_ctx;

static void step_chunk(void *p, size_t chunk, int worker)
{
    (void)worker;
    step_ctx *c = p;
    size_t S = c->opts->points;
    int v = (int)(chunk / c->chunks_per_buf);
    size_t ch = c->first + chunk % c->chunks_per_buf;
    size_t lo = ch * FSET_WALK_CHUNK, hi = lo + FSET_WALK_CHUNK < S ? lo + FSET_WALK_CHUNK : S;
    int n = c->nv[v];
    const fset_ifs *F = &c->fs->sets[n];
    const double *cum = c->cum + (size_t)n * FSET_MAX_MAPS;
    rng r;
    rng_init(&r, rng_hash3(c->opts->seed, c->k, (uint64_t)v, FSET_WALK_TAG), ch);
    for (size_t i = lo; i < hi; i++) {
        int m = fset_pick(cum, F->n, rng_uniform(&r));
        int src = c->input[(size_t)v * FSET_MAX_MAPS + (size_t)m];
        const double *q = c->from + 2 * ((size_t)src * S + i);
        double x = q[0], y = q[1];
        fset_apply2(&F->maps[m], &x, &y);
        double *d = c->to + 2 * ((size_t)v * S + i);
        d[0] = x;
        d[1] = y;
    }
}

rt_code superifs_check(const fset *fs, const double *P, const superifs_opts *opts, rt_error *e)
{
    rt_code code = fset_validate(fs, e);
    if (code)
        return code;
    fset_order ord = {FSET_RANDOM, 0, NULL, P, opts->seed};
    if ((code = fset_order_validate(&ord, fs->n, e)))
        return code;
    for (int s = 0; s < fs->n; s++)
        if (fs->sets[s].maps[0].dim != 2)
            return rt_fail(e, RT_EINVAL, "super IFS needs 2-D maps (F%d is %d-D)", s + 1,
                           fs->sets[s].maps[0].dim);
    if (opts->V < 1)
        return rt_fail(e, RT_EINVAL, "super IFS has %d buffers (expected at least 1)", opts->V);
    if (opts->points < 1)
        return rt_fail(e, RT_EINVAL, "super IFS buffers have no points (expected at least 1)");
    if (!rt_mul_size(rt_mul_size((size_t)opts->V, opts->points), 2))
        return rt_fail(e, RT_EINVAL, "super IFS of %d buffers of %zu points is too large", opts->V, opts->points);
    return RT_OK;
}

/* n_v and K_{v,m} of step k (the draws of superifs.h) */
static void step_draws(const fset *fs, const double *P, const superifs_opts *opts, uint64_t k, int *nv, int *input)
{
    size_t V = (size_t)opts->V;
    for (size_t v = 0; v < V; v++) {
        nv[v] = fset_choose(P, fs->n, rng_hash3(opts->seed, k, v, 0));
        for (int m = 0; input && m < fs->sets[nv[v]].n; m++)
            input[v * FSET_MAX_MAPS + (size_t)m] = (int)(rng_hash3(opts->seed, k, v, 1 + (uint64_t)m) % V);
    }
}

void superifs_last_ifs(const fset *fs, const double *P, const superifs_opts *opts, int *ifs_of)
{
    for (int v = 0; v < opts->V; v++)
        ifs_of[v] = -1;
    if (opts->steps)
        step_draws(fs, P, opts, opts->steps - 1, ifs_of, NULL);
}

rt_code superifs_run(const fset *fs, const double *P, const superifs_opts *opts,
                     superifs_state *out, const rt_run *run, rt_error *e)
{
    memset(out, 0, sizeof *out);
    rt_code code = superifs_check(fs, P, opts, e);
    if (code)
        return code;
    size_t V = (size_t)opts->V, S = opts->points;
    size_t n = V * S * 2;
    double *a = rt_malloc(n * sizeof *a), *b = rt_malloc(n * sizeof *b);
    double *cum = rt_malloc((size_t)fs->n * FSET_MAX_MAPS * sizeof *cum);
    int *nv = rt_malloc(V * sizeof *nv), *input = rt_malloc(V * FSET_MAX_MAPS * sizeof *input);
    if (!a || !b || !cum || !nv || !input) {
        code = rt_fail(e, RT_ENOMEM, "out of memory for %zu buffers of %zu points", V, S);
        goto done;
    }
    for (int s = 0; s < fs->n; s++)
        fset_cumulative(fs->sets[s].p, fs->sets[s].n, cum + (size_t)s * FSET_MAX_MAPS);
    for (size_t i = 0; i < V * S; i++) { /* both: a shard's other points stay defined */
        a[2 * i] = b[2 * i] = opts->start[0];
        a[2 * i + 1] = b[2 * i + 1] = opts->start[1];
    }
    for (size_t v = 0; v < V; v++)
        nv[v] = -1;
    /* Split across processes by point chunks: point i of every buffer
     * depends only on points i of the buffers of the step before, so a
     * shard runs every step for its own chunks of points (in all V
     * buffers) and hands each buffer's rows of points to the part. */
    size_t cpb = (S + FSET_WALK_CHUNK - 1) / FSET_WALK_CHUNK;
    par_part pp;
    if ((code = par_part_begin(&pp, run, "super IFS", cpb, e)))
        goto done;
    size_t mine = pp.hi - pp.lo;
    for (uint64_t k = 0; k < opts->steps; k++) {
        step_draws(fs, P, opts, k, nv, input);
        step_ctx c = {fs, opts, k, pp.lo, mine, nv, input, cum, a, b};
        code = mine ? par_for(run, "super IFS", V * mine, step_chunk, &c) : RT_OK;
        if (code) {
            rt_fail(e, code, "interrupted");
            goto done;
        }
        double *t = a;
        a = b;
        b = t;
    }
    for (size_t v = 0; v < V && !code; v++) /* the final points, buffer by buffer */
        code = par_part_rows(&pp, a + 2 * v * S, S * 2 * sizeof *a, FSET_WALK_CHUNK * 2 * sizeof *a, e);
    if (code)
        goto done;
    out->V = opts->V;
    out->points = S;
    out->pts = a;
    out->ifs_of = nv;
    a = NULL;
    nv = NULL;
done:
    rt_free(a);
    rt_free(b);
    rt_free(cum);
    rt_free(nv);
    rt_free(input);
    return code;
}

rt_code superifs_render(const superifs_state *s, int v, hist2 *hs, rt_error *e)
{
    if (v < 0 || v >= s->V)
        return rt_fail(e, RT_EINVAL, "super IFS buffer %d does not exist (expected 1 to %d)", v + 1,
                       s->V);
    if ((!hs->count && !hs->count32) || !(hs->hi[0] > hs->lo[0]) || !(hs->hi[1] > hs->lo[1]))
        return rt_fail(e, RT_EINVAL, "super IFS render: the histogram is not allocated or empty");
    const double *p = s->pts + 2 * (size_t)v * s->points;
    for (size_t i = 0; i < s->points; i++) {
        long b = fset_hist_bin(hs, p[2 * i], p[2 * i + 1]);
        if (b >= 0)
            hist2_add(hs, (size_t)b, 1);
    }
    return RT_OK;
}

int superifs_bounds(const superifs_state *s, double lo[2], double hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    size_t np = (size_t)s->V * s->points;
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < 2; k++) {
            double x = s->pts[2 * i + (size_t)k];
            if (!isfinite(x))
                continue;
            if (x < lo[k])
                lo[k] = x;
            if (x > hi[k])
                hi[k] = x;
        }
    return hi[0] >= lo[0] && hi[1] >= lo[1] ? 0 : -1;
}

void superifs_free(superifs_state *s)
{
    rt_free(s->pts);
    rt_free(s->ifs_of);
    memset(s, 0, sizeof *s);
}
