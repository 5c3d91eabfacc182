/* fset.c — iterated function sets (seed 003 def. 3.1, 3.2), their orders,
 * the composition-notation parser and the chaos game with an order. */
#include "fset.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"
#include "rng.h"
#include "tails.h"

#define CHAOS_CHUNK ((uint64_t)1 << 16) /* plotted points per ORBIT chunk */

#if defined(__GNUC__)
#define INLINE static inline __attribute__((always_inline))
#else
#define INLINE static inline
#endif

/* ---- validation ---------------------------------------------------- */

static rt_code check_probs(const double *p, int n, const char *what, rt_error *e)
{
    if (!p)
        return RT_OK;
    double s = 0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(p[i]) || p[i] < 0)
            return rt_fail(e, RT_EINVAL, "%s: probability %d is %g (expected a number >= 0)", what,
                           i + 1, p[i]);
        s += p[i];
    }
    if (!(fabs(s - 1) <= 1e-6))
        return rt_fail(e, RT_EINVAL, "%s: probabilities sum to %.9g (expected 1)", what, s);
    return RT_OK;
}

rt_code fset_validate(const fset *fs, rt_error *e)
{
    if (!fs || fs->n < 1 || !fs->sets)
        return rt_fail(e, RT_EINVAL, "function set has no sets (expected at least 1)");
    int dim = 0;
    for (int s = 0; s < fs->n; s++) {
        const fset_ifs *w = &fs->sets[s];
        char what[48];
        snprintf(what, sizeof what, "function set W%d", s + 1);
        if (w->n < 1 || w->n > FSET_MAX_MAPS || !w->maps)
            return rt_fail(e, RT_EINVAL, "%s has %d maps (expected 1 to %d)", what, w->n,
                           FSET_MAX_MAPS);
        for (int m = 0; m < w->n; m++) {
            const affine *a = &w->maps[m];
            if (a->dim != 2 && a->dim != 3)
                return rt_fail(e, RT_EINVAL, "%s: map %d has dimension %d (expected 2 or 3)", what,
                               m + 1, a->dim);
            if (!dim)
                dim = a->dim;
            if (a->dim != dim)
                return rt_fail(e, RT_EINVAL,
                               "%s: map %d is %d-D but the first map is %d-D (expected all the same)",
                               what, m + 1, a->dim, dim);
            for (int i = 0; i < 3; i++) {
                int ok = isfinite(a->t[i]);
                for (int j = 0; j < 3; j++)
                    ok &= isfinite(a->m[i][j]);
                if (!ok)
                    return rt_fail(e, RT_EINVAL, "%s: map %d has a non-finite coefficient", what,
                                   m + 1);
            }
        }
        rt_code c = check_probs(w->p, w->n, what, e);
        if (c)
            return c;
    }
    return RT_OK;
}

rt_code fset_order_validate(const fset_order *o, int nsets, rt_error *e)
{
    if (!o)
        return rt_fail(e, RT_EINVAL, "order is missing");
    if (o->kind == FSET_RANDOM)
        return check_probs(o->p, nsets, "random order", e);
    if (o->kind != FSET_SEQUENCE && o->kind != FSET_PERIODIC)
        return rt_fail(e, RT_EINVAL, "order has an unknown kind %d", (int)o->kind);
    if (o->len < 1 || !o->seq)
        return rt_fail(e, RT_EINVAL, "order is empty (expected at least one set)");
    for (int i = 0; i < o->len; i++)
        if (o->seq[i] < 0 || o->seq[i] >= nsets)
            return rt_fail(e, RT_EINVAL,
                           "order step %d names set W%d but the function set has %d sets", i + 1,
                           o->seq[i] + 1, nsets);
    return RT_OK;
}

void fset_cumulative(const double *p, int n, double *cum)
{
    double total = 0;
    for (int i = 0; i < n; i++)
        total += p ? p[i] : 1.0;
    double s = 0;
    for (int i = 0; i < n; i++) {
        s += p ? p[i] : 1.0;
        cum[i] = total > 0 ? s / total : (double)(i + 1) / n;
    }
    cum[n - 1] = 1.0;
}

int fset_choose(const double *p, int n, uint64_t h)
{
    double u = rng_to_unit(h);
    if (!p) {
        int i = (int)(u * n);
        return i < n ? i : n - 1;
    }
    double total = 0, s = 0;
    for (int i = 0; i < n; i++)
        total += p[i];
    for (int i = 0; i < n - 1; i++) {
        s += p[i];
        if (u < s / total)
            return i;
    }
    return n - 1;
}

int fset_order_at(const fset_order *o, int nsets, uint64_t k)
{
    /* RANDOM: a pure function of (seed, k), the same σ(k) in every chunk
     * and every engine. */
    if (o->kind == FSET_RANDOM)
        return fset_choose(o->p, nsets, rng_hash3(o->seed, k, 0, 0));
    return o->seq[k % (uint64_t)o->len];
}

/* ---- composition notation ------------------------------------------ */

typedef struct scan {
    const char *s;
    size_t i;
} scan;

static size_t char_offset(const scan *sc, size_t byte)
{
    size_t n = 0;
    for (size_t i = 0; i < byte; i++)
        n += ((unsigned char)sc->s[i] & 0xC0) != 0x80;
    return n;
}

static void skip_space(scan *sc)
{
    while (sc->s[sc->i] == ' ' || sc->s[sc->i] == '\t' || sc->s[sc->i] == '\n' ||
           sc->s[sc->i] == '\r')
        sc->i++;
}

static int at_operator(const scan *sc, size_t *len)
{
    const char *p = sc->s + sc->i;
    if (p[0] == '*' || p[0] == 'o') {
        *len = 1;
        return 1;
    }
    if ((unsigned char)p[0] == 0xE2 && (unsigned char)p[1] == 0x88 && (unsigned char)p[2] == 0x98) {
        *len = 3; /* U+2218 RING OPERATOR */
        return 1;
    }
    return 0;
}

/* "(K0)" or "(K_0)" at the end. */
static int at_k0(const scan *sc, size_t *len)
{
    const char *p = sc->s + sc->i;
    const char *forms[] = {"(K0)", "(K_0)", "(k0)", "(k_0)", "(K_{0})"};
    for (size_t f = 0; f < sizeof forms / sizeof forms[0]; f++) {
        size_t n = strlen(forms[f]);
        if (strncmp(p, forms[f], n) == 0) {
            *len = n;
            return 1;
        }
    }
    return 0;
}

rt_code fset_order_parse(const char *text, int nsets, int **seq, int *len, size_t *err_offset,
                         rt_error *e)
{
    *seq = NULL;
    *len = 0;
    if (err_offset)
        *err_offset = 0;
    scan sc = {text ? text : "", 0};
    size_t cap = 0, n = 0;
    int *v = NULL;
    size_t bad = 0;
    rt_code code = RT_OK;
    skip_space(&sc);
    if (!sc.s[sc.i]) {
        code = rt_fail(e, RT_EINVAL, "order: empty composition (expected e.g. W2 ∘ W1)");
        goto fail;
    }
    for (;;) {
        skip_space(&sc);
        size_t name_at = sc.i;
        if (sc.s[sc.i] != 'W' && sc.s[sc.i] != 'w') {
            bad = sc.i;
            code = rt_fail(e, RT_EINVAL, "order: expected a set name like W3 at character %zu",
                           char_offset(&sc, bad));
            goto fail;
        }
        sc.i++;
        if (sc.s[sc.i] == '_')
            sc.i++;
        int brace = sc.s[sc.i] == '{';
        if (brace)
            sc.i++;
        if (sc.s[sc.i] < '0' || sc.s[sc.i] > '9') {
            bad = sc.i;
            code = rt_fail(e, RT_EINVAL,
                           "order: expected a set number after 'W' at character %zu",
                           char_offset(&sc, bad));
            goto fail;
        }
        long idx = 0;
        while (sc.s[sc.i] >= '0' && sc.s[sc.i] <= '9') {
            if (idx < 100000000)
                idx = idx * 10 + (sc.s[sc.i] - '0');
            sc.i++;
        }
        if (brace) {
            if (sc.s[sc.i] != '}') {
                bad = sc.i;
                code = rt_fail(e, RT_EINVAL, "order: expected '}' at character %zu",
                               char_offset(&sc, bad));
                goto fail;
            }
            sc.i++;
        }
        if (idx < 1) {
            bad = name_at;
            code = rt_fail(e, RT_EINVAL,
                           "order: set W%ld at character %zu does not exist (sets are numbered "
                           "from 1)",
                           idx, char_offset(&sc, bad));
            goto fail;
        }
        if (nsets > 0 && idx > nsets) {
            bad = name_at;
            code = rt_fail(e, RT_EINVAL,
                           "order: set W%ld at character %zu does not exist (the function set has "
                           "%d sets)",
                           idx, char_offset(&sc, bad), nsets);
            goto fail;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            int *nv = rt_realloc(v, cap * sizeof *nv);
            if (!nv) {
                code = rt_fail(e, RT_ENOMEM, "out of memory parsing an order");
                goto fail;
            }
            v = nv;
        }
        v[n++] = (int)(idx - 1);
        skip_space(&sc);
        size_t ol;
        if (!sc.s[sc.i])
            break;
        if (at_k0(&sc, &ol)) {
            sc.i += ol;
            skip_space(&sc);
            if (sc.s[sc.i]) {
                bad = sc.i;
                code = rt_fail(e, RT_EINVAL, "order: unexpected text after (K0) at character %zu",
                               char_offset(&sc, bad));
                goto fail;
            }
            break;
        }
        if (!at_operator(&sc, &ol)) {
            bad = sc.i;
            code = rt_fail(e, RT_EINVAL,
                           "order: expected '∘', 'o' or '*' between sets at character %zu",
                           char_offset(&sc, bad));
            goto fail;
        }
        sc.i += ol;
    }
    /* Rightmost is applied first: reverse into application order. */
    for (size_t i = 0; i < n / 2; i++) {
        int t = v[i];
        v[i] = v[n - 1 - i];
        v[n - 1 - i] = t;
    }
    *seq = v;
    *len = (int)n;
    return RT_OK;
fail:
    rt_free(v);
    if (err_offset)
        *err_offset = char_offset(&sc, bad);
    return code;
}

/* ---- chaos game ------------------------------------------------------ */

long fset_hist_bin(const hist2 *hs, double x, double y)
{
    double fx = (x - hs->lo[0]) / (hs->hi[0] - hs->lo[0]) * hs->w;
    double fy = (hs->hi[1] - y) / (hs->hi[1] - hs->lo[1]) * hs->h;
    if (!(fx >= 0 && fx < hs->w && fy >= 0 && fy < hs->h))
        return -1;
    int ix = (int)fx, iy = (int)fy;
    if (ix >= hs->w)
        ix = hs->w - 1;
    if (iy >= hs->h)
        iy = hs->h - 1;
    return (long)iy * hs->w + ix;
}

typedef struct chaos_ctx {
    const fset *fs;
    const fset_order *o;
    const fset_chaos_opts *opts;
    const hist2 *hs;
    double *cum;      /* fs->n * FSET_MAX_MAPS */
    uint64_t *count;  /* per worker: worker i's w × h counts at count + i w h, */
    uint32_t *count32; /* or here, 32-bit, when hs's counts are (fewer than 2^32 points) */
    int failed;       /* a worker could not allocate */
} chaos_ctx;

/* A hit of bin b (>= 0: inside) by worker wid. */
static void plot_hit(const chaos_ctx *c, int wid, long b)
{
    if (b < 0)
        return;
    size_t at = (size_t)wid * (size_t)c->hs->w * (size_t)c->hs->h + (size_t)b;
    if (c->count32)
        c->count32[at]++;
    else
        c->count[at]++;
}

/* What a parallel game ends with: interrupted, a worker out of memory, or
 * the code par_for gave. */
static rt_code workers_done(rt_code code, int failed, rt_error *e)
{
    if (code == RT_ECANCEL)
        return rt_fail(e, code, "interrupted");
    if (failed)
        return rt_fail(e, RT_ENOMEM, "out of memory in the chaos game");
    return code;
}

/* Every set's cumulative probabilities, FSET_MAX_MAPS per set (rt_free it);
 * NULL when out of memory. */
static double *cumulative_tables(const fset *fs)
{
    double *cum = rt_malloc((size_t)fs->n * FSET_MAX_MAPS * sizeof *cum);
    for (int s = 0; cum && s < fs->n; s++)
        fset_cumulative(fs->sets[s].p, fs->sets[s].n, cum + (size_t)s * FSET_MAX_MAPS);
    return cum;
}

/* The chaos game's fixed chunks: a walk's are shorter (FSET_WALK_CHUNK). */
static size_t chunk_count(const fset_chaos_opts *opts)
{
    uint64_t per = opts->mode == FSET_WALK ? FSET_WALK_CHUNK : CHAOS_CHUNK;
    return (size_t)((opts->points + per - 1) / per);
}

/* Step k of an orbit; *at is k mod the order's length, kept by a counter
 * rather than a division (the set fset_order_at gives). */
INLINE void chaos_step(const chaos_ctx *c, uint64_t k, uint64_t *at, rng *r, double *x, double *y)
{
    const fset_order *o = c->o;
    int s;
    if (o->kind == FSET_RANDOM) {
        s = fset_order_at(o, c->fs->n, k);
    } else {
        s = o->seq[*at];
        *at = *at + 1 == (uint64_t)o->len ? 0 : *at + 1;
    }
    const fset_ifs *w = &c->fs->sets[s];
    int m = fset_pick(c->cum + (size_t)s * FSET_MAX_MAPS, w->n, rng_uniform(r));
    fset_apply2(&w->maps[m], x, y);
}

/* The plotted points' extremes and sum (ext: min x, max x, min y, max y). */
typedef struct extremes {
    double ext[4], sum;
} extremes;

static inline void extremes_add(extremes *x, double px, double py)
{
    x->ext[0] = px < x->ext[0] ? px : x->ext[0];
    x->ext[1] = px > x->ext[1] ? px : x->ext[1];
    x->ext[2] = py < x->ext[2] ? py : x->ext[2];
    x->ext[3] = py > x->ext[3] ? py : x->ext[3];
    x->sum += px + py;
}

/* One chunk of an orbit: its plotted points binned into worker's counts, or
 * (xt not NULL, the window's pre-pass) added to xt. Inlined into both
 * callers, so the test on xt is made at compile time. */
INLINE void orbit_chunk(const chaos_ctx *c, size_t chunk, int worker, extremes *xt)
{
    const fset_chaos_opts *op = c->opts;
    uint64_t first = (uint64_t)chunk * CHAOS_CHUNK;
    uint64_t npts = op->points - first < CHAOS_CHUNK ? op->points - first : CHAOS_CHUNK;
    uint64_t period = (op->plot_period && c->o->kind != FSET_RANDOM) ? (uint64_t)c->o->len : 1;
    rng r;
    rng_init(&r, op->seed, chunk);
    double x = op->start[0], y = op->start[1];
    uint64_t k = 0, at = 0;
    for (; k < op->burn; k++)
        chaos_step(c, k, &at, &r, &x, &y);
    /* Plot after complete periods counted from the orbit's start. */
    while (k % period)
        chaos_step(c, k++, &at, &r, &x, &y);
    for (uint64_t done = 0, ph = 0; done < npts;) { /* ph: k mod period */
        chaos_step(c, k++, &at, &r, &x, &y);
        ph = ph + 1 == period ? 0 : ph + 1;
        if (ph == 0) {
            if (!xt)
                plot_hit(c, worker, fset_hist_bin(c->hs, x, y));
            else
                extremes_add(xt, x, y);
            done++;
        }
    }
}

static void chaos_orbit(void *p, size_t chunk, int worker)
{
    chaos_ctx *c = p;
    orbit_chunk(c, chunk, worker, NULL);
}

/* The end points of one chunk's walks (dim doubles each, *n of them; rt_free
 * them): every walk starts at opts->start and takes opts->depth steps, step k
 * a map of W_σ(k) drawn from the stream of (seed, k) at the chunk's index.
 * NULL when out of memory. */
static double *walk_chunk(const fset *fs, const fset_order *o, const double *cum, const fset_chaos_opts *op,
                          size_t chunk, int dim, size_t *n)
{
    uint64_t first = (uint64_t)chunk * FSET_WALK_CHUNK;
    *n = (size_t)(op->points - first < FSET_WALK_CHUNK ? op->points - first : FSET_WALK_CHUNK);
    double *pt = rt_malloc(*n * (size_t)dim * sizeof *pt);
    if (!pt)
        return NULL;
    for (size_t i = 0; i < *n; i++)
        memcpy(pt + (size_t)dim * i, op->start, (size_t)dim * sizeof(double));
    for (uint64_t k = 0; k < op->depth; k++) {
        int s = fset_order_at(o, fs->n, k);
        const fset_ifs *w = &fs->sets[s];
        const double *cw = cum + (size_t)s * FSET_MAX_MAPS;
        rng r;
        rng_init(&r, rng_hash3(op->seed, k, 0, FSET_WALK_TAG), chunk);
        for (size_t i = 0; i < *n; i++) {
            int m = fset_pick(cw, w->n, rng_uniform(&r));
            double *p = pt + (size_t)dim * i;
            if (dim == 2) {
                fset_apply2(&w->maps[m], &p[0], &p[1]);
            } else {
                double q[3];
                affine_apply(&w->maps[m], p, q);
                memcpy(p, q, sizeof q);
            }
        }
    }
    return pt;
}

static void chaos_walk(void *p, size_t chunk, int worker)
{
    chaos_ctx *c = p;
    size_t n;
    double *pt = walk_chunk(c->fs, c->o, c->cum, c->opts, chunk, 2, &n);
    if (!pt) {
        c->failed = 1;
        return;
    }
    for (size_t i = 0; i < n; i++)
        plot_hit(c, worker, fset_hist_bin(c->hs, pt[2 * i], pt[2 * i + 1]));
    rt_free(pt);
}

/* What a 2-D game checks before it runs, but its histogram. */
static rt_code game_check(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, rt_error *e)
{
    rt_code code = fset_validate(fs, e);
    if (code)
        return code;
    if ((code = fset_order_validate(o, fs->n, e)))
        return code;
    for (int s = 0; s < fs->n; s++)
        if (fs->sets[s].maps[0].dim != 2)
            return rt_fail(e, RT_EINVAL,
                           "chaos game with a function set needs 2-D maps (W%d is %d-D)", s + 1,
                           fs->sets[s].maps[0].dim);
    if (opts->mode == FSET_WALK && opts->depth < 1)
        return rt_fail(e, RT_EINVAL, "chaos game walk depth is 0 (expected at least 1)");
    return RT_OK;
}

rt_code fset_chaos(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, hist2 *hs,
                   const rt_run *run, rt_error *e)
{
    rt_code code = game_check(fs, o, opts, e);
    if (code)
        return code;
    if ((!hs->count && !hs->count32) || hs->w < 1 || hs->h < 1)
        return rt_fail(e, RT_EINVAL, "chaos game: the histogram is not allocated");
    if (hs->count32 && !hist2_narrow(opts->points))
        return rt_fail(e, RT_EINVAL, "chaos game: a histogram with 32-bit counts cannot take %llu points",
                       (unsigned long long)opts->points);
    if (!(hs->hi[0] > hs->lo[0]) || !(hs->hi[1] > hs->lo[1]))
        return rt_fail(e, RT_EINVAL, "chaos game: the histogram window is empty");
    if (opts->points == 0)
        return RT_OK;

    chaos_ctx c = {fs, o, opts, hs, NULL, NULL, NULL, 0};
    size_t nchunks = chunk_count(opts);
    int nw = par_workers(run, nchunks);
    size_t nbins = (size_t)hs->w * (size_t)hs->h;
    c.cum = cumulative_tables(fs);
    int narrow = hs->count32 != NULL;
    if (narrow)
        c.count32 = rt_calloc((size_t)nw * nbins, sizeof *c.count32);
    else
        c.count = rt_calloc((size_t)nw * nbins, sizeof *c.count);
    if (!c.cum || (narrow ? !c.count32 : !c.count)) {
        code = rt_fail(e, RT_ENOMEM, "out of memory for %d per-thread histograms", nw);
        goto done;
    }
    par_part pp; /* a shard runs its chunks; counts are exact sums (par.h) */
    code = par_part_begin(&pp, run, "fset chaos", nchunks, e);
    if (code)
        goto done;
    code = par_part_for(&pp, "chaos", opts->mode == FSET_WALK ? chaos_walk : chaos_orbit, &c);
    if ((code = workers_done(code, c.failed, e)))
        goto done;
    for (int i = 1; pp.mode != PAR_FULL && i < nw; i++) /* the shard's sums into worker 0's */
        for (size_t b = 0; b < nbins; b++) {
            if (narrow)
                c.count32[b] += c.count32[(size_t)i * nbins + b];
            else
                c.count[b] += c.count[(size_t)i * nbins + b];
        }
    if (pp.mode != PAR_FULL &&
        (code = narrow ? par_part_sum32(&pp, c.count32, nbins, e) : par_part_sum(&pp, c.count, nbins, e)))
        goto done;
    for (int i = 0; i < (pp.mode != PAR_FULL ? 1 : nw); i++)
        for (size_t b = 0; b < nbins; b++)
            hist2_add(hs, b, narrow ? c.count32[(size_t)i * nbins + b] : c.count[(size_t)i * nbins + b]);
done:
    rt_free(c.count);
    rt_free(c.count32);
    rt_free(c.cum);
    return code;
}

/* ---- deterministic iteration of a mesh ------------------------------------ */

#define MESH_COPY_CHUNK 4096 /* copies per parallel chunk */

typedef struct mesh_iter_ctx {
    const mesh *k0;
    const affine *comp; /* one composed map per copy */
    size_t copies;
    mesh *out;
} mesh_iter_ctx;

static void mesh_iter_chunk(void *p, size_t chunk, int worker)
{
    (void)worker;
    mesh_iter_ctx *c = p;
    const mesh *k = c->k0;
    size_t lo = chunk * MESH_COPY_CHUNK, hi = lo + MESH_COPY_CHUNK < c->copies ? lo + MESH_COPY_CHUNK : c->copies;
    for (size_t cp = lo; cp < hi; cp++) {
        const affine *a = &c->comp[cp];
        size_t vb = cp * k->nv, tb = cp * k->nt;
        for (size_t i = 0; i < k->nv; i++) {
            double in[3] = {k->pos[3 * i], k->pos[3 * i + 1], k->pos[3 * i + 2]}, r[3];
            affine_apply(a, in, r);
            for (int d = 0; d < 3; d++)
                c->out->pos[3 * (vb + i) + (size_t)d] = (float)r[d];
            if (k->col)
                memcpy(c->out->col + 4 * (vb + i), k->col + 4 * i, 4 * sizeof(float));
        }
        int flip = affine_det(a) < 0;
        for (size_t t = 0; t < k->nt; t++) {
            const uint32_t *s = k->tri + 3 * t;
            uint32_t *d = c->out->tri + 3 * (tb + t);
            d[0] = (uint32_t)vb + s[0];
            d[1] = (uint32_t)vb + (flip ? s[2] : s[1]);
            d[2] = (uint32_t)vb + (flip ? s[1] : s[2]);
        }
    }
}

rt_code fset_iterate_mesh(const fset *fs, const fset_order *o, size_t steps, size_t copies, const mesh *k0,
                          mesh *out, const rt_run *run, rt_error *e)
{
    memset(out, 0, sizeof *out);
    size_t nv = rt_mul_size(k0->nv, copies), nt = rt_mul_size(k0->nt, copies);
    if ((k0->nv && !nv) || (k0->nt && !nt) || nv >= UINT32_MAX)
        return rt_fail(e, RT_EINVAL, "K_%zu would have %zu copies of %zu vertices, more than 32-bit indices hold",
                       steps, copies, k0->nv);
    affine *cur = rt_mallocn(copies ? copies : 1, sizeof *cur), *nx = rt_mallocn(copies ? copies : 1, sizeof *nx);
    rt_code code = RT_OK;
    if (!cur || !nx) {
        code = rt_fail(e, RT_ENOMEM, "out of memory composing %zu maps", copies);
        goto done;
    }
    cur[0] = affine_identity(3);
    size_t n = 1;
    for (size_t k = 0; k < steps; k++) {
        const fset_ifs *w = &fs->sets[fset_order_at(o, fs->n, k)];
        if (n * (size_t)w->n > copies) {
            code = rt_fail(e, RT_EINVAL, "iterate: the copy count does not match the order");
            goto done;
        }
        for (int j = 0; j < w->n; j++)
            for (size_t r = 0; r < n; r++)
                nx[(size_t)j * n + r] = affine_compose(&w->maps[j], &cur[r]);
        n *= (size_t)w->n;
        affine *t = cur;
        cur = nx;
        nx = t;
    }
    if (n != copies) {
        code = rt_fail(e, RT_EINVAL, "iterate: the copy count does not match the order");
        goto done;
    }
    out->pos = rt_mallocn(nv ? nv : 1, 3 * sizeof(float));
    out->tri = rt_mallocn(nt ? nt : 1, 3 * sizeof(uint32_t));
    out->col = k0->col ? rt_mallocn(nv ? nv : 1, 4 * sizeof(float)) : NULL;
    if (!out->pos || !out->tri || (k0->col && !out->col)) {
        mesh_free(out);
        code = rt_fail(e, RT_ENOMEM, "out of memory for K_%zu (%zu vertices, %zu triangles)", steps, nv, nt);
        goto done;
    }
    out->nv = out->cap_v = nv;
    out->nt = out->cap_t = nt;
    mesh_iter_ctx c = {k0, cur, copies, out};
    code = par_for(run, "iterate", (copies + MESH_COPY_CHUNK - 1) / MESH_COPY_CHUNK, mesh_iter_chunk, &c);
    if (code) {
        mesh_free(out);
        rt_fail(e, code, "interrupted");
    }
done:
    rt_free(cur);
    rt_free(nx);
    return code;
}

/* ---- chaos game in 3-D, seen through a camera ------------------------------- */

typedef struct view_ctx {
    const fset *fs;
    const fset_order *o;
    const fset_chaos_opts *opts;
    const camera *cam; /* NULL: the box pre-pass, points into pts */
    int w, h;
    double *cum;
    double *zb;   /* per worker: worker i's w × h depths at zb + i w h */
    double *pts;  /* box pass: 3 per plotted point */
    int failed;
} view_ctx;

static void view_plot(view_ctx *c, int worker, uint64_t idx, const double p[3])
{
    if (!c->cam) {
        memcpy(c->pts + 3 * idx, p, 3 * sizeof(double));
        return;
    }
    double sx, sy, z;
    if (camera_project(c->cam, c->w, c->h, p, &sx, &sy, &z) != 0)
        return;
    if (!(sx >= 0 && sx < c->w && sy >= 0 && sy < c->h))
        return;
    size_t b = (size_t)(int)sy * (size_t)c->w + (size_t)(int)sx;
    double *zb = c->zb + (size_t)worker * (size_t)c->w * (size_t)c->h;
    if (z < zb[b])
        zb[b] = z;
}

static void view_step(const view_ctx *c, uint64_t k, rng *r, double p[3])
{
    int s = fset_order_at(c->o, c->fs->n, k);
    const fset_ifs *w = &c->fs->sets[s];
    int m = fset_pick(c->cum + (size_t)s * FSET_MAX_MAPS, w->n, rng_uniform(r));
    double q[3];
    affine_apply(&w->maps[m], p, q);
    memcpy(p, q, sizeof q);
}

static void view_orbit(void *pp, size_t chunk, int worker)
{
    view_ctx *c = pp;
    const fset_chaos_opts *op = c->opts;
    uint64_t first = (uint64_t)chunk * CHAOS_CHUNK;
    uint64_t npts = op->points - first < CHAOS_CHUNK ? op->points - first : CHAOS_CHUNK;
    uint64_t period = (op->plot_period && c->o->kind != FSET_RANDOM) ? (uint64_t)c->o->len : 1;
    rng r;
    rng_init(&r, op->seed, chunk);
    double p[3] = {op->start[0], op->start[1], op->start[2]};
    uint64_t k = 0;
    for (; k < op->burn; k++)
        view_step(c, k, &r, p);
    while (k % period)
        view_step(c, k++, &r, p);
    for (uint64_t done = 0; done < npts;) {
        view_step(c, k++, &r, p);
        if (k % period == 0)
            view_plot(c, worker, first + done++, p);
    }
}

static void view_walk(void *pp, size_t chunk, int worker)
{
    view_ctx *c = pp;
    size_t n;
    double *pt = walk_chunk(c->fs, c->o, c->cum, c->opts, chunk, 3, &n);
    if (!pt) {
        c->failed = 1;
        return;
    }
    uint64_t first = (uint64_t)chunk * FSET_WALK_CHUNK;
    for (size_t i = 0; i < n; i++)
        view_plot(c, worker, first + i, pt + 3 * i);
    rt_free(pt);
}

static rt_code view_check(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, rt_error *e)
{
    rt_code code = fset_validate(fs, e);
    if (code || (code = fset_order_validate(o, fs->n, e)))
        return code;
    for (int s = 0; s < fs->n; s++)
        if (fs->sets[s].maps[0].dim != 3)
            return rt_fail(e, RT_EINVAL, "a 3-D chaos game needs 3-D maps (W%d is %d-D)", s + 1,
                           fs->sets[s].maps[0].dim);
    if (opts->mode == FSET_WALK && opts->depth < 1)
        return rt_fail(e, RT_EINVAL, "chaos game walk depth is 0 (expected at least 1)");
    return RT_OK;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Widen lo..hi by a margin and to the aspect w:h about its centre. */
void fset_fit_aspect(double lo[2], double hi[2], int w, int h, double margin)
{
    double ext[2];
    for (int k = 0; k < 2; k++) {
        ext[k] = hi[k] - lo[k];
        if (!(ext[k] > 1e-12))
            ext[k] = fmax(1e-3, fmax(fabs(lo[k]), fabs(hi[k])) * 0.1);
        ext[k] *= 1 + 2 * margin;
    }
    double aspect = (double)w / h;
    if (ext[0] / ext[1] < aspect)
        ext[0] = ext[1] * aspect;
    else
        ext[1] = ext[0] / aspect;
    for (int k = 0; k < 2; k++) {
        double c = (lo[k] + hi[k]) / 2;
        lo[k] = c - ext[k] / 2;
        hi[k] = c + ext[k] / 2;
    }
}

enum { FIT_GRID = 256, FIT_PASSES = 4 };

/* One pass's narrowing: the occupied cells x0..x1, y0..y1 (y0 the top row)
 * of the FIT_GRID² histogram of lo..hi, plus one cell on each side. */
static void fit_narrow(double lo[2], double hi[2], int x0, int x1, int y0, int y1)
{
    double bx = (hi[0] - lo[0]) / FIT_GRID, by = (hi[1] - lo[1]) / FIT_GRID;
    double nlo0 = lo[0] + (x0 - 1) * bx, nhi0 = lo[0] + (x1 + 2) * bx;
    double nhi1 = hi[1] - (y0 - 1) * by, nlo1 = hi[1] - (y1 + 2) * by;
    lo[0] = nlo0;
    hi[0] = nhi0;
    lo[1] = nlo1;
    hi[1] = nhi1;
}

/* The passes as defined: the game into a histogram each time. */
static rt_code fit_by_histograms(const fset *fs, const fset_order *o, const fset_chaos_opts *fo, double lo[2],
                                 double hi[2], const rt_run *run, rt_error *e)
{
    for (int pass = 0; pass < FIT_PASSES; pass++) {
        hist2 hs;
        const int G = FIT_GRID;
        rt_code c = hist2_init_for(&hs, G, G, lo, hi, 0, fo->points, e);
        if (c)
            return c;
        rt_sharder *sv = par_set_sharder(NULL); /* a pre-pass: in full in every shard (par.h) */
        c = fset_chaos(fs, o, fo, &hs, run, e);
        par_set_sharder(sv);
        if (c) {
            hist2_free(&hs);
            return c;
        }
        int x0 = G, x1 = -1, y0 = G, y1 = -1;
        for (int j = 0; j < G; j++)
            for (int i = 0; i < G; i++)
                if (hist2_get(&hs, (size_t)j * G + i)) {
                    if (i < x0)
                        x0 = i;
                    if (i > x1)
                        x1 = i;
                    if (j < y0)
                        y0 = j;
                    if (j > y1)
                        y1 = j;
                }
        hist2_free(&hs);
        if (x1 < 0)
            return rt_fail(e, RT_EINVAL, "no point of the chaos game fell near the origin; give window: [xmin, xmax, ymin, ymax]");
        fit_narrow(lo, hi, x0, x1, y0, y1);
    }
    return RT_OK;
}

/* The passes from the game's extremes, run once: every pass plays the same
 * game (same seed, same points), and fset_hist_bin's cell is monotone in x
 * and in y (a difference, a quotient and a product by positive numbers,
 * each correctly rounded, then a truncation). So when the cells of (min x,
 * max y) and (max x, min y) both lie in a pass's grid, every point does,
 * and those two cells are the corners of the occupied cells: the pass's
 * result without its histogram. 0 when that does not hold for some pass
 * (a point outside the window, a NaN, an infinity, no point at all): the
 * caller then runs the passes as defined. lo and hi are changed only on 1. */
static int fit_by_extremes(const fset *fs, const fset_order *o, const fset_chaos_opts *fo, double lo[2],
                           double hi[2])
{
    if (fo->points == 0)
        return 0;
    extremes xt = {{INFINITY, -INFINITY, INFINITY, -INFINITY}, 0};
    chaos_ctx c = {.fs = fs, .o = o, .opts = fo, .cum = cumulative_tables(fs)};
    if (!c.cum)
        return 0;
    for (size_t ch = 0; ch < chunk_count(fo); ch++) {
        if (fo->mode != FSET_WALK) {
            orbit_chunk(&c, ch, 0, &xt);
            continue;
        }
        size_t n;
        double *pt = walk_chunk(fs, o, c.cum, fo, ch, 2, &n);
        if (!pt) {
            rt_free(c.cum);
            return 0;
        }
        for (size_t i = 0; i < n; i++)
            extremes_add(&xt, pt[2 * i], pt[2 * i + 1]);
        rt_free(pt);
    }
    rt_free(c.cum);
    if (!isfinite(xt.sum)) /* a NaN would be dropped from the cells, not from the extremes */
        return 0;
    double wlo[2] = {lo[0], lo[1]}, whi[2] = {hi[0], hi[1]};
    for (int pass = 0; pass < FIT_PASSES; pass++) {
        hist2 hs = {.w = FIT_GRID, .h = FIT_GRID, .lo = {wlo[0], wlo[1]}, .hi = {whi[0], whi[1]}};
        if (!(whi[0] > wlo[0]) || !(whi[1] > wlo[1]))
            return 0;
        long b0 = fset_hist_bin(&hs, xt.ext[0], xt.ext[3]), b1 = fset_hist_bin(&hs, xt.ext[1], xt.ext[2]);
        if (b0 < 0 || b1 < 0)
            return 0;
        fit_narrow(wlo, whi, (int)(b0 % FIT_GRID), (int)(b1 % FIT_GRID), (int)(b0 / FIT_GRID),
                   (int)(b1 / FIT_GRID));
    }
    memcpy(lo, wlo, sizeof wlo);
    memcpy(hi, whi, sizeof whi);
    return 1;
}

/* The window of a function-set chaos game: a bound from the maps'
 * contractions, narrowed by four coarse histogram passes (fit_by_extremes
 * gives their result without the histograms when it can). */
rt_code fset_chaos_fit(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, int w, int h, double lo[2],
                       double hi[2], const rt_run *run, rt_error *e)
{
    double R = 0;
    int contractive = 1;
    for (int s = 0; s < fs->n; s++)
        for (int m = 0; m < fs->sets[s].n; m++) {
            const affine *a = &fs->sets[s].maps[m];
            double c = affine_contraction(a);
            if (!(c < 0.999))
                contractive = 0;
            else
                R = fmax(R, hypot(a->t[0], a->t[1]) / (1 - c));
        }
    R = contractive ? R + hypot(opts->start[0], opts->start[1]) + 1e-9 : 1e6;
    lo[0] = lo[1] = -R;
    hi[0] = hi[1] = R;
    fset_chaos_opts fo = *opts;
    fo.points = opts->points < 50000 ? opts->points : 50000;
    rt_code code = game_check(fs, o, &fo, e);
    if (code)
        return code;
    if (!fit_by_extremes(fs, o, &fo, lo, hi) && (code = fit_by_histograms(fs, o, &fo, lo, hi, run, e)))
        return code;
    fset_fit_aspect(lo, hi, w, h, 0.03);
    return RT_OK;
}

enum { BOX_TAIL = FSET_BOX_POINTS / 1000 + 1 };

/* Per axis the (cut+1)-th smallest and largest of the box pass's points
 * (tails.h): what sorting them gives. 0 when their sum is not finite (a
 * NaN, an infinity, or finite values too large to add; the caller sorts). */
static int box_tails(const double *pts, size_t cut, double lo[3], double hi[3])
{
    double hl[3][BOX_TAIL], hh[3][BOX_TAIL], sum = 0;
    size_t k = cut + 1;
    for (size_t i = 0; i < k; i++)
        for (int a = 0; a < 3; a++) {
            double v = pts[3 * i + (size_t)a];
            sum += v;
            tails_heap_offer(hl[a], i, k, v);
            tails_heap_offer(hh[a], i, k, -v);
        }
    for (int a = 0; a < 3; a++) {
        lo[a] = hl[a][0], hi[a] = -hh[a][0];
        for (size_t i = k; i < FSET_BOX_POINTS; i++) {
            double v = pts[3 * i + (size_t)a];
            sum += v;
            tails_offer(hl[a], hh[a], k, v, &lo[a], &hi[a]);
        }
    }
    return isfinite(sum);
}

rt_code fset_chaos_box(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, double lo[3], double hi[3],
                       rt_error *e)
{
    rt_code code = view_check(fs, o, opts, e);
    if (code)
        return code;
    fset_chaos_opts bo = *opts;
    bo.points = FSET_BOX_POINTS; /* one chunk in either mode */
    bo.seed = rng_hash3(opts->seed, 1ull << 63, 0, 0);
    view_ctx c = {fs, o, &bo, NULL, 0, 0, NULL, NULL, NULL, 0};
    c.cum = cumulative_tables(fs);
    c.pts = rt_malloc(3 * FSET_BOX_POINTS * sizeof *c.pts);
    double *ax = rt_malloc(FSET_BOX_POINTS * sizeof *ax);
    if (!c.cum || !c.pts || !ax) {
        code = rt_fail(e, RT_ENOMEM, "out of memory fitting the view");
        goto done;
    }
    uint64_t per = bo.mode == FSET_WALK ? FSET_WALK_CHUNK : CHAOS_CHUNK;
    for (size_t ch = 0; ch * per < FSET_BOX_POINTS; ch++) {
        if (bo.mode == FSET_WALK)
            view_walk(&c, ch, 0);
        else
            view_orbit(&c, ch, 0);
    }
    if (c.failed) {
        code = rt_fail(e, RT_ENOMEM, "out of memory fitting the view");
        goto done;
    }
    size_t cut = FSET_BOX_POINTS / 1000;
    double tl[3], tu[3];
    int tails_ok = box_tails(c.pts, cut, tl, tu);
    for (int a = 0; a < 3; a++) {
        double l = tl[a], u = tu[a];
        if (!tails_ok || l == 0 || u == 0) { /* as defined: sort (+0 and -0 as the sort leaves them) */
            for (size_t i = 0; i < FSET_BOX_POINTS; i++)
                ax[i] = c.pts[3 * i + (size_t)a];
            qsort(ax, FSET_BOX_POINTS, sizeof *ax, cmp_dbl);
            l = ax[cut], u = ax[FSET_BOX_POINTS - 1 - cut];
        }
        if (!isfinite(l) || !isfinite(u)) {
            code = rt_fail(e, RT_EINVAL, "the chaos game left every bound (a map is not contractive?)");
            goto done;
        }
        lo[a] = l - 0.05 * (u - l);
        hi[a] = u + 0.05 * (u - l);
    }
done:
    rt_free(c.cum);
    rt_free(c.pts);
    rt_free(ax);
    return code;
}

rt_code fset_chaos_view(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, const camera *cam,
                        const float bg[4], image *im, const rt_run *run, rt_error *e)
{
    rt_code code = view_check(fs, o, opts, e);
    if (code)
        return code;
    view_ctx c = {fs, o, opts, cam, im->w, im->h, NULL, NULL, NULL, 0};
    size_t nchunks = chunk_count(opts);
    int nw = par_workers(run, nchunks ? nchunks : 1);
    size_t nb = (size_t)im->w * (size_t)im->h;
    c.cum = cumulative_tables(fs);
    c.zb = rt_mallocn((size_t)nw * nb, sizeof *c.zb);
    if (!c.cum || !c.zb) {
        code = rt_fail(e, RT_ENOMEM, "out of memory for %d per-thread depth buffers", nw);
        goto done;
    }
    for (size_t b = 0; b < (size_t)nw * nb; b++)
        c.zb[b] = INFINITY;
    if (nchunks)
        code = par_for(run, "chaos", nchunks, opts->mode == FSET_WALK ? view_walk : view_orbit, &c);
    if ((code = workers_done(code, c.failed, e)))
        goto done;
    double zmin = INFINITY, zmax = -INFINITY;
    for (size_t b = 0; b < nb; b++) {
        for (int i = 1; i < nw; i++)
            if (c.zb[(size_t)i * nb + b] < c.zb[b])
                c.zb[b] = c.zb[(size_t)i * nb + b];
        double z = c.zb[b];
        if (z < INFINITY) {
            zmin = z < zmin ? z : zmin;
            zmax = z > zmax ? z : zmax;
        }
    }
    double span = zmax > zmin ? zmax - zmin : 1;
    for (size_t b = 0; b < nb; b++) {
        float *px = im->px + 4 * b;
        double z = c.zb[b];
        if (!(z < INFINITY)) {
            memcpy(px, bg, 4 * sizeof(float));
            continue;
        }
        float br = (float)(1 + (0.25 - 1) * ((z - zmin) / span));
        px[0] = px[1] = px[2] = br;
        px[3] = 1;
    }
done:
    rt_free(c.zb);
    rt_free(c.cum);
    return code;
}
