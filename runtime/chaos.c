/* chaos.c — the chaos game (random iteration algorithm) for IFS and RIFS
 * (seed 003 §2; RIFS: seed 001 §2, measure μ(B) ≈ N(B,n)/(n+1): seed 001 §5).
 *
 * The hot loops are specialised by hand-written inline templates: the system
 * kind (IFS / RIFS order 1 / order 2) and colour mode are compile-time
 * constants in each instantiation, maps are plain arrays of 6 (2-D) or 12
 * (3-D) doubles, and the map choice is an alias-table lookup (ifs.h). */
#include "chaos.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"
#include "rng.h"
#include "tails.h"

#if defined(__GNUC__)
#define INLINE static inline __attribute__((always_inline))
#define PREFETCHW(p) __builtin_prefetch((p), 1, 0)
#define COLD static __attribute__((noinline, cold))
#else
#define COLD static
#define INLINE static inline
#define PREFETCHW(p) ((void)(p))
#endif

enum { KIND_IFS, KIND_R1, KIND_R2 };

/* Everything a chunk needs, flattened for the inner loop. */
typedef struct sysdata {
    int n, dim, kind;
    uint32_t *thr; /* rows * n */
    uint32_t *sel; /* rows * n * 2, map indices 0 .. n-1 */
    double *m;     /* n * 6 (2-D: a b e c d f) or n * 12 (3-D: row-major M | t) */
    uint32_t start_state, start_map;
    double x0[3];
    double *mc;                      /* n colour coordinates */
    uint32_t pal[CHAOS_PALETTE][4];  /* 1 (the hit) and the ramp's r, g, b in 16-bit fixed point */
    float palf[CHAOS_PALETTE][4];    /* ramp, float */
} sysdata;

static void sys_free(sysdata *d)
{
    rt_free(d->thr);
    rt_free(d->sel);
    rt_free(d->m);
    rt_free(d->mc);
    rt_free(d);
}

static void fixed_point(const affine *a, double out[3])
{
    /* (I - A) x = t */
    affine b = *a, inv;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            b.m[i][j] = (i == j ? 1.0 : 0.0) - a->m[i][j];
    if (a->dim == 2) {
        b.m[2][2] = 1;
        b.m[0][2] = b.m[1][2] = b.m[2][0] = b.m[2][1] = 0;
    }
    for (int i = 0; i < 3; i++)
        b.t[i] = 0;
    out[0] = out[1] = out[2] = 0;
    if (affine_invert(&b, &inv) == 0) {
        double t[3] = {a->t[0], a->t[1], a->dim == 3 ? a->t[2] : 0};
        affine_apply(&inv, t, out);
        for (int i = 0; i < 3; i++)
            if (!isfinite(out[i]))
                out[i] = 0;
    }
}

/* palette: 0 when no loop reads pal/palf (the window pre-pass, counts
 * without colour), which spares 1024 ramp evaluations. */
static sysdata *sys_make(const chaos_sys *s, const chaos_opts *o, int want_dim, int palette, rt_error *e)
{
    const affine *maps;
    int n, dim, rows;
    if ((s->ifs != NULL) == (s->rifs != NULL)) {
        rt_fail(e, RT_EINVAL, "chaos game needs exactly one IFS or RIFS");
        return NULL;
    }
    if (s->ifs) {
        maps = s->ifs->maps, n = s->ifs->n, dim = s->ifs->dim, rows = 1;
    } else {
        maps = s->rifs->maps, n = s->rifs->n, dim = s->rifs->dim, rows = s->rifs->rows;
    }
    if (n < 1 || !maps) {
        rt_fail(e, RT_EINVAL, "IFS has no maps");
        return NULL;
    }
    if (want_dim && dim != want_dim) {
        rt_fail(e, RT_EINVAL, "this needs %d-D maps, but the %s has %d-D maps", want_dim,
                s->ifs ? "IFS" : "RIFS", dim);
        return NULL;
    }
    if (o->map_c)
        for (int k = 0; k < n; k++)
            if (!(o->map_c[k] >= 0 && o->map_c[k] <= 1)) {
                rt_fail(e, RT_EINVAL, "colour %d is %.6g (expected 0 .. 1)", k + 1, o->map_c[k]);
                return NULL;
            }
    sysdata *d = rt_calloc(1, sizeof *d);
    if (!d) {
        rt_fail(e, RT_ENOMEM, "out of memory for the chaos game");
        return NULL;
    }
    d->n = n;
    d->dim = dim;
    size_t cols = (size_t)rows * (size_t)n;
    d->thr = rt_calloc(cols, sizeof *d->thr);
    d->sel = rt_calloc(cols * 2, sizeof *d->sel);
    d->m = rt_calloc((size_t)n * 12, sizeof *d->m);
    d->mc = rt_calloc((size_t)n, sizeof *d->mc);
    if (!d->thr || !d->sel || !d->m || !d->mc) {
        sys_free(d);
        rt_fail(e, RT_ENOMEM, "out of memory for the chaos game");
        return NULL;
    }
    for (int r = 0; r < rows; r++) {
        const ifs_alias *a = s->ifs ? &s->ifs->alias : &s->rifs->row[r];
        if (a->n != n) /* unused order-2 row: never visited */
            continue;
        memcpy(d->thr + (size_t)r * n, a->thresh, sizeof *d->thr * (size_t)n);
        memcpy(d->sel + (size_t)r * n * 2, a->sel, sizeof *d->sel * 2 * (size_t)n);
    }
    for (int k = 0; k < n; k++) {
        const affine *a = &maps[k];
        double *m = d->m + (size_t)k * (dim == 2 ? 6 : 12);
        if (dim == 2) {
            m[0] = a->m[0][0], m[1] = a->m[0][1], m[2] = a->t[0];
            m[3] = a->m[1][0], m[4] = a->m[1][1], m[5] = a->t[1];
        } else {
            for (int i = 0; i < 3; i++) {
                m[4 * i] = a->m[i][0], m[4 * i + 1] = a->m[i][1], m[4 * i + 2] = a->m[i][2];
                m[4 * i + 3] = a->t[i];
            }
        }
        d->mc[k] = o->map_c ? o->map_c[k] : n > 1 ? (double)k / (n - 1) : 0;
    }
    if (s->ifs) {
        d->kind = KIND_IFS;
        d->start_state = 0;
        d->start_map = 0;
    } else if (s->rifs->order == 1) {
        d->kind = KIND_R1;
        d->start_state = d->start_map = (uint32_t)s->rifs->start;
    } else {
        d->kind = KIND_R2;
        d->start_state = (uint32_t)s->rifs->start;
        d->start_map = (uint32_t)(s->rifs->start % n);
    }
    fixed_point(&maps[d->start_map], d->x0);
    if (!palette)
        return d;
    ramp grey = ramp_grey();
    const ramp *rp = o->ramp ? o->ramp : &grey;
    for (int i = 0; i < CHAOS_PALETTE; i++) {
        ramp_eval(rp, (double)i / (CHAOS_PALETTE - 1), d->palf[i]);
        d->pal[i][0] = 1;
        for (int ch = 0; ch < 3; ch++) {
            double v = d->palf[i][ch];
            v = v < 0 ? 0 : v > 1 ? 1 : v;
            d->pal[i][ch + 1] = (uint32_t)(v * 65535.0 + 0.5);
        }
    }
    return d;
}

static uint32_t pal_index(double c)
{
    return (uint32_t)(c * (CHAOS_PALETTE - 1) + 0.5);
}

/* ---------- the orbit: state, choice, colour ---------- */

typedef struct orbit {
    rng r;
    uint32_t s, cur;
    double x, y, z, c;
} orbit;

static void orbit_start(orbit *ob, const sysdata *d, uint64_t seed, uint64_t chunk)
{
    rng_init(&ob->r, seed, chunk);
    ob->s = d->start_state;
    ob->cur = d->start_map;
    ob->x = d->x0[0], ob->y = d->x0[1], ob->z = d->x0[2];
    ob->c = d->mc[d->start_map];
}

/* The one orbit step every loop uses, written once: draw the next map from
 * the alias table of the current state's row (the comparison result indexes
 * the pair, no branch), advance the RIFS state, then apply the map. The hot
 * loops call these on locals; always_inline keeps them in registers. */
INLINE uint32_t step_choose(rng *r, uint32_t n, const uint32_t *thr, const uint32_t *sel,
                            uint32_t *st, uint32_t *cur, const int kind)
{
    uint64_t w = rng_next(r);
    uint32_t col = (uint32_t)(((w >> 32) * n) >> 32);
    if (kind != KIND_IFS)
        col += *st * n;
    uint32_t k = sel[2 * col + ((uint32_t)w < thr[col])];
    if (kind == KIND_R1)
        *st = k;
    else if (kind == KIND_R2)
        *st = *cur * n + k;
    *cur = k;
    return k;
}

/* 2-D map k: m = a b e c d f (x' = a x + b y + e, y' = c x + d y + f). */
INLINE void step_map2(const double *m, double *x, double *y)
{
    double nx = m[0] * *x + m[1] * *y + m[2];
    double ny = m[3] * *x + m[4] * *y + m[5];
    *x = nx, *y = ny;
}

/* 3-D map k: m = row-major [M | t], 3 rows of 4. */
INLINE void step_map3(const double *m, double *x, double *y, double *z)
{
    double nx = m[0] * *x + m[1] * *y + m[2] * *z + m[3];
    double ny = m[4] * *x + m[5] * *y + m[6] * *z + m[7];
    double nz = m[8] * *x + m[9] * *y + m[10] * *z + m[11];
    *x = nx, *y = ny, *z = nz;
}

INLINE void orbit_step2(orbit *ob, const sysdata *d, const int kind)
{
    uint32_t k = step_choose(&ob->r, (uint32_t)d->n, d->thr, d->sel, &ob->s, &ob->cur, kind);
    step_map2(d->m + 6 * (size_t)k, &ob->x, &ob->y);
}

INLINE void orbit_step3(orbit *ob, const sysdata *d, const int kind)
{
    uint32_t k = step_choose(&ob->r, (uint32_t)d->n, d->thr, d->sel, &ob->s, &ob->cur, kind);
    step_map3(d->m + 12 * (size_t)k, &ob->x, &ob->y, &ob->z);
}

/* One step of any system (kind and dimension tested at run time): for the
 * loops that are not hot. */
INLINE void orbit_step_any(orbit *ob, const sysdata *d)
{
    if (d->dim == 2)
        d->kind == KIND_IFS ? orbit_step2(ob, d, KIND_IFS)
        : d->kind == KIND_R1 ? orbit_step2(ob, d, KIND_R1) : orbit_step2(ob, d, KIND_R2);
    else
        d->kind == KIND_IFS ? orbit_step3(ob, d, KIND_IFS)
        : d->kind == KIND_R1 ? orbit_step3(ob, d, KIND_R1) : orbit_step3(ob, d, KIND_R2);
}

/* Palette index of the current hit's colour. */
INLINE uint32_t orbit_colour(orbit *ob, const sysdata *d, const int colour)
{
    if (colour == CHAOS_COLOUR_BLEND) {
        ob->c = (ob->c + d->mc[ob->cur]) * 0.5; /* flam3's colour coordinate */
        return pal_index(ob->c);
    }
    return pal_index(d->mc[ob->cur]);
}

/* ---------- common driver ---------- */

typedef struct worker {
    uint32_t *cnt;
    void *mem;       /* the block cnt lies in (hist_zeroed), NULL if cnt is not ours */
    uint64_t *carry; /* lazily allocated on the first 32-bit wrap */
    double *zb;      /* projection: depth per pixel */
    uint32_t *tag;   /* projection: palette index of the nearest point */
    uint64_t inside, plotted;
    uint64_t outwrap; /* wraps of a loop's 32-bit outside cell (bump_at) */
    int oom;
} worker;

typedef struct job {
    const sysdata *d;
    const chaos_opts *o;
    uint64_t points, burn;
    uint32_t chunk;
    size_t nchunks;
    worker *w;
    size_t nbins; /* bins/voxels/pixels */
    uint64_t *direct;   /* 2-D counts: worker 0 adds its hits here (the histogram), */
    uint32_t *direct32; /* or here when the histogram's counts are 32-bit */
    /* 2-D window */
    int hw, hh;
    double lox, hiy, sx, sy;
    /* 3-D box */
    int nx, ny, nz;
    double lo3[3], s3[3];
    /* point cloud */
    float *pos, *col;
    /* projection */
    const camera *cam;
    int iw, ih;
} job;

static void chunk_range(const job *j, size_t chunk, uint64_t *count)
{
    uint64_t first = (uint64_t)chunk * j->chunk;
    uint64_t left = j->points - first;
    *count = left < j->chunk ? left : j->chunk;
}

/* The 32-bit wrap of a count (cold): one more 2^32 in the 64-bit side
 * array, or, for the outside cell (p == out, not a bin), in w->outwrap. */
COLD void carry_wrap(worker *w, const uint32_t *cnt, const uint32_t *p, const uint32_t *out, size_t nbins)
{
    if (p == out) {
        w->outwrap++;
        return;
    }
    if (!w->carry)
        w->carry = rt_calloc(nbins + 1, sizeof *w->carry);
    if (w->carry)
        w->carry[p - cnt]++;
    else
        w->oom = 1;
}

INLINE void bump(worker *w, uint32_t *cnt, size_t b, size_t nbins)
{
    if (!++cnt[b]) /* exact carry on 32-bit wrap-around */
        carry_wrap(w, cnt, cnt + b, NULL, nbins);
}

/* A pending hit by address: the bin, or the worker's outside cell *out (the
 * ring needs no test for outside points, and *out counts them). */
INLINE void bump_at(worker *w, uint32_t *cnt, uint32_t *p, const uint32_t *out, size_t nbins)
{
    if (!++*p)
        carry_wrap(w, cnt, p, out, nbins);
}

/* ---------- 2-D histogram ---------- */

/* The cell of a coordinate f already tested to be in [0, n), n an int: the
 * same value as (size_t)(int)f, in one 64-bit conversion (no sign extension). */
INLINE size_t cell_of(double f)
{
    return (size_t)(int64_t)f;
}

#define RING 32 /* pending increments: prefetch this many points ahead */

/* A colour cell's 65536th hit (cold): the cell is added into the 64-bit
 * side sums and cleared. */
COLD void flush_cell(worker *w, const uint32_t *cnt, uint32_t *cell, size_t nbins)
{
    if (!w->carry) /* the bins' cells and the outside cell (flushed too, never read) */
        w->carry = rt_calloc(4 * (nbins + 1), sizeof *w->carry);
    if (!w->carry) {
        w->oom = 1;
        return;
    }
    size_t b = (size_t)(cell - cnt);
    for (int q = 0; q < 4; q++)
        w->carry[b + q] += cell[q];
    cell[0] = cell[1] = cell[2] = cell[3] = 0;
}

#if defined(__GNUC__)
typedef uint32_t cell4 __attribute__((vector_size(16)));
#endif

/* One coloured hit: the palette entry (1, r, g, b) added to the cell
 * (count, r, g, b) in one 16-byte add. The outside cell is one more cell:
 * it is flushed like the others (no test in the loop), its sums are never
 * read, and its count between flushes gives the loop its outside hits. */
INLINE void add_cell(worker *w, const uint32_t *cnt, uint32_t *cell, const uint32_t *pe, size_t nbins)
{
#if defined(__GNUC__)
    cell4 a, h;
    memcpy(&a, cell, sizeof a);
    memcpy(&h, pe, sizeof h);
    a += h;
    memcpy(cell, &a, sizeof a);
    uint32_t n = a[0];
#else
    for (int q = 0; q < 4; q++)
        cell[q] += pe[q];
    uint32_t n = cell[0];
#endif
    if (!(n & 0xffffu))
        flush_cell(w, cnt, cell, nbins);
}

/* The start of a hot loop's chunk: its point count and its orbit after the
 * burn-in, in dim 2 or 3 with the loop's kind and colour (with
 * CHAOS_COLOUR_BLEND the burn-in moves the colour coordinate too). */
INLINE void chunk_orbit(const job *j, size_t chunk, orbit *ob, uint64_t *count, const int dim, const int kind,
                        const int colour)
{
    const sysdata *d = j->d;
    chunk_range(j, chunk, count);
    orbit_start(ob, d, j->o->seed, chunk);
    for (uint64_t i = 0; i < j->burn; i++) {
        if (dim == 2)
            orbit_step2(ob, d, kind);
        else
            orbit_step3(ob, d, kind);
        if (colour == CHAOS_COLOUR_BLEND)
            (void)orbit_colour(ob, d, colour);
    }
}

/* Hits of the outside colour cell so far: its count and what flushes moved
 * into the side sums. */
INLINE uint64_t out_hits(const worker *w, const uint32_t *out, size_t nbins)
{
    return out[0] + (w->carry ? w->carry[4 * nbins] : 0);
}

/* Both 2-D loops prefetch the hit's bin and add the hit RING points later
 * (the facts' prefetch ring): with it the counts-only loop runs faster than
 * a plain loop into a private uint32 array, even with worker 0 adding into
 * the 8-byte counts of the histogram itself.
 * The 2-D loop keeps the orbit in locals and every pointer in a local: the
 * build uses -fno-strict-aliasing, so a store into the counts would otherwise
 * force the compiler to reload all of them after every hit. With colour a
 * bin is 4 uint32 (count, r, g, b) in one 16-byte cell — one cache line per
 * hit; after 65536 hits of a bin (at most 65535 per channel each, so no
 * wrap) the cell is flushed into 64-bit side sums. */
INLINE void hist_chunk(const job *j, size_t chunk, int wid, const int kind, const int colour,
                       const int wide)
{
    const sysdata *d = j->d;
    worker *w = &j->w[wid];
    uint64_t count;
    orbit ob;
    chunk_orbit(j, chunk, &ob, &count, 2, kind, colour);
    const double lox = j->lox, hiy = j->hiy, sx = j->sx, sy = j->sy;
    const double fw = j->hw, fh = j->hh;
    const size_t hw = (size_t)j->hw;
    const uint32_t n = (uint32_t)d->n;
    const uint32_t *const thr = d->thr, *const sel = d->sel;
    const double *const M = d->m, *const mc = d->mc;
    const uint32_t(*const pal)[4] = d->pal;
    const size_t nbins = j->nbins;
    uint32_t *const cnt = w->cnt, *const out = w->cnt + 4 * nbins; /* colour: the outside cell */
    uint64_t *const cnt64 = j->direct;
    uint32_t *const cnt32 = j->direct32;
    rng r = ob.r;
    uint32_t st = ob.s, cur = ob.cur;
    double x = ob.x, y = ob.y, c = ob.c;
    uint64_t inside = 0;
    size_t ring[RING];
    uint32_t *ringp[RING];       /* colour: the cells, */
    uint32_t ringe[RING];        /* and their hits' palette indices */
    for (int q = 0; q < RING; q++)
        ring[q] = nbins, ringp[q] = out, ringe[q] = 0;
    uint64_t out0 = colour != CHAOS_COLOUR_NONE ? out_hits(w, out, nbins) : 0;
#pragma GCC unroll 2
    for (uint64_t i = 0; i < count; i++) {
        uint32_t k = step_choose(&r, n, thr, sel, &st, &cur, kind);
        step_map2(M + 6 * (size_t)k, &x, &y);
        uint32_t pc = 0;
        if (colour == CHAOS_COLOUR_BLEND) {
            c = (c + mc[k]) * 0.5; /* flam3's colour coordinate */
            pc = pal_index(c);
        } else if (colour == CHAOS_COLOUR_LAST) {
            pc = pal_index(mc[k]);
        }
        double fx = (x - lox) * sx, fy = (hiy - y) * sy;
        if (colour == CHAOS_COLOUR_NONE) {
            /* prefetch this hit's bin, count the hit RING points back
             * (outside: b = nbins, one past the end, not counted) */
            size_t b = j->nbins;
            if (fx >= 0 && fx < fw && fy >= 0 && fy < fh) {
                b = cell_of(fy) * hw + cell_of(fx);
                inside++;
            }
            size_t slot = (size_t)(i % RING), old = ring[slot];
            ring[slot] = b;
            if (wide == 1) {
                PREFETCHW(cnt64 + b);
                if (old != j->nbins)
                    cnt64[old]++;
            } else if (wide == 2) { /* fewer than 2^32 points: no bin wraps */
                PREFETCHW(cnt32 + b);
                if (old != j->nbins)
                    cnt32[old]++;
            } else {
                PREFETCHW(cnt + b);
                if (old != j->nbins)
                    bump(w, cnt, old, j->nbins);
            }
            continue;
        }
        /* colour: prefetch this hit's cell, add the hit RING points back
         * (outside points go to the extra cell nbins, which counts them) */
        uint32_t *cell = out;
        if (fx >= 0 && fx < fw && fy >= 0 && fy < fh)
            cell = cnt + 4 * (cell_of(fy) * hw + cell_of(fx));
        PREFETCHW(cell);
        size_t slot = (size_t)(i % RING);
        add_cell(w, cnt, ringp[slot], pal[ringe[slot]], nbins);
        ringp[slot] = cell;
        ringe[slot] = pc;
    }
    for (int q = 0; q < RING; q++) {
        if (colour != CHAOS_COLOUR_NONE)
            add_cell(w, cnt, ringp[q], pal[ringe[q]], nbins);
        else if (ring[q] != j->nbins && wide == 1)
            cnt64[ring[q]]++;
        else if (ring[q] != j->nbins && wide == 2)
            cnt32[ring[q]]++;
        else if (ring[q] != j->nbins)
            bump(w, cnt, ring[q], j->nbins);
    }
    if (colour != CHAOS_COLOUR_NONE) /* the outside cell got RING placeholders and the outside hits */
        inside = count - (out_hits(w, out, nbins) - out0 - RING);
    w->inside += inside;
    w->plotted += count;
}

/* Counts only: worker 0 adds straight into the histogram's counts, 64-bit
 * (wide 1) or 32-bit (wide 2: the call plots fewer than 2^32 points) — no
 * private array, no merge pass, no carry; the others count privately. */
#define HIST_FN(name, kind, colour)                                                              \
    static void name(void *ctx, size_t chunk, int wid)                                           \
    {                                                                                            \
        const job *j = ctx;                                                                      \
        if (colour == CHAOS_COLOUR_NONE && wid == 0 && j->direct)                                \
            hist_chunk(j, chunk, wid, kind, colour, 1);                                          \
        else if (colour == CHAOS_COLOUR_NONE && wid == 0 && j->direct32)                         \
            hist_chunk(j, chunk, wid, kind, colour, 2);                                          \
        else                                                                                     \
            hist_chunk(j, chunk, wid, kind, colour, 0);                                          \
    }
HIST_FN(hist_i0, KIND_IFS, CHAOS_COLOUR_NONE)
HIST_FN(hist_i1, KIND_IFS, CHAOS_COLOUR_LAST)
HIST_FN(hist_i2, KIND_IFS, CHAOS_COLOUR_BLEND)
HIST_FN(hist_a0, KIND_R1, CHAOS_COLOUR_NONE)
HIST_FN(hist_a1, KIND_R1, CHAOS_COLOUR_LAST)
HIST_FN(hist_a2, KIND_R1, CHAOS_COLOUR_BLEND)
HIST_FN(hist_b0, KIND_R2, CHAOS_COLOUR_NONE)
HIST_FN(hist_b1, KIND_R2, CHAOS_COLOUR_LAST)
HIST_FN(hist_b2, KIND_R2, CHAOS_COLOUR_BLEND)

static const par_fn hist_fns[3][3] = {
    {hist_i0, hist_i1, hist_i2}, {hist_a0, hist_a1, hist_a2}, {hist_b0, hist_b1, hist_b2}};

/* ---------- 3-D volume ---------- */


/* diag: every map is a scaling per axis plus a translation (M diagonal, as
 * in seed 001's octant maps), so a step is 3 multiply-adds instead of 9;
 * the dropped terms are 0·y etc., which change at most the sign of a zero
 * coordinate, never a count. */
INLINE void vol_chunk(const job *j, size_t chunk, int wid, const int kind, const int diag)
{
    const sysdata *d = j->d;
    worker *w = &j->w[wid];
    uint64_t count;
    orbit ob;
    chunk_orbit(j, chunk, &ob, &count, 3, kind, CHAOS_COLOUR_NONE);
    const double lx = j->lo3[0], ly = j->lo3[1], lz = j->lo3[2];
    const double sx = j->s3[0], sy = j->s3[1], sz = j->s3[2];
    const double fx_n = j->nx, fy_n = j->ny, fz_n = j->nz;
    const size_t nx = (size_t)j->nx, nxy = (size_t)j->nx * (size_t)j->ny;
    const size_t nbins = j->nbins;
    const uint32_t n = (uint32_t)d->n;
    const uint32_t *const thr = d->thr, *const sel = d->sel;
    const double *const M = d->m;
    uint32_t *const cnt = w->cnt;
    rng r = ob.r;
    uint32_t st = ob.s, cur = ob.cur;
    double x = ob.x, y = ob.y, z = ob.z;
    /* the ring holds addresses; outside points (and the empty slots at the
     * start, RING of them) count in out, so inside = count - (out - RING) */
    uint32_t out = 0;
    uint32_t *ring[RING];
    for (int i = 0; i < RING; i++)
        ring[i] = &out;
    for (uint64_t i = 0; i < count; i++) {
        uint32_t k = step_choose(&r, n, thr, sel, &st, &cur, kind);
        if (diag) {
            const double *m = M + 12 * (size_t)k;
            x = m[0] * x + m[3], y = m[5] * y + m[7], z = m[10] * z + m[11];
        } else {
            step_map3(M + 12 * (size_t)k, &x, &y, &z);
        }
        double fx = (x - lx) * sx, fy = (y - ly) * sy, fz = (z - lz) * sz;
        uint32_t *p = &out;
        if (fx >= 0 && fx < fx_n && fy >= 0 && fy < fy_n && fz >= 0 && fz < fz_n)
            p = cnt + (cell_of(fx) + nx * cell_of(fy) + nxy * cell_of(fz));
        /* prefetch this point's voxel, count the one RING points back */
        PREFETCHW(p);
        size_t slot = (size_t)(i % RING);
        bump_at(w, cnt, ring[slot], &out, nbins);
        ring[slot] = p;
    }
    for (int i = 0; i < RING; i++)
        bump_at(w, cnt, ring[i], &out, nbins);
    uint64_t outside = ((uint64_t)out | w->outwrap << 32) - RING;
    w->outwrap = 0;
    w->inside += count - outside;
    w->plotted += count;
}

#define VOL_FN(name, kind, diag)                                                                 \
    static void name(void *ctx, size_t chunk, int wid) { vol_chunk((const job *)ctx, chunk, wid, kind, diag); }
VOL_FN(vol_i, KIND_IFS, 0)
VOL_FN(vol_a, KIND_R1, 0)
VOL_FN(vol_b, KIND_R2, 0)
VOL_FN(vol_id, KIND_IFS, 1)
VOL_FN(vol_ad, KIND_R1, 1)
VOL_FN(vol_bd, KIND_R2, 1)
static const par_fn vol_fns[2][3] = {{vol_i, vol_a, vol_b}, {vol_id, vol_ad, vol_bd}};

static int maps_diagonal(const sysdata *d)
{
    for (int k = 0; k < d->n; k++) {
        const double *m = d->m + 12 * (size_t)k;
        if (m[1] != 0 || m[2] != 0 || m[4] != 0 || m[6] != 0 || m[8] != 0 || m[9] != 0)
            return 0;
    }
    return 1;
}

/* ---------- points (point cloud, fit pre-pass, projection) ---------- */

/* Generic 3-D/2-D orbit writing positions (and palette colours) of chunk
 * points into j->pos / j->col at the chunk's offset. Not the hot path. */
static void points_chunk(void *ctx, size_t chunk, int wid)
{
    const job *j = ctx;
    const sysdata *d = j->d;
    uint64_t count;
    chunk_range(j, chunk, &count);
    orbit ob;
    orbit_start(&ob, d, j->o->seed, chunk);
    int colour = j->o->colour;
    for (uint64_t i = 0; i < j->burn + count; i++) {
        orbit_step_any(&ob, d);
        uint32_t pc = colour == CHAOS_COLOUR_BLEND ? orbit_colour(&ob, d, CHAOS_COLOUR_BLEND)
                                                   : orbit_colour(&ob, d, CHAOS_COLOUR_LAST);
        if (i < j->burn)
            continue;
        size_t at = (size_t)chunk * j->chunk + (size_t)(i - j->burn);
        if (j->pos) {
            j->pos[3 * at] = (float)ob.x;
            j->pos[3 * at + 1] = (float)ob.y;
            j->pos[3 * at + 2] = (float)ob.z;
        }
        if (j->col)
            memcpy(j->col + 4 * at, d->palf[pc], 4 * sizeof(float));
        if (j->cam) {
            worker *w = &j->w[wid];
            double p[3] = {ob.x, ob.y, ob.z}, sx, sy, z;
            w->plotted++;
            if (camera_project(j->cam, j->iw, j->ih, p, &sx, &sy, &z) != 0)
                continue;
            if (!(sx >= 0 && sx < j->iw && sy >= 0 && sy < j->ih))
                continue;
            w->inside++;
            size_t b = (size_t)(int)sy * (size_t)j->iw + (size_t)(int)sx;
            uint32_t tag = colour == CHAOS_COLOUR_NONE ? 0 : pc;
            if (z < w->zb[b] || (z == w->zb[b] && tag < w->tag[b])) {
                w->zb[b] = z;
                w->tag[b] = tag;
            }
        }
    }
}

static rt_code finish_par(rt_code rc, worker *w, int nw, rt_error *e)
{
    int oom = 0;
    for (int i = 0; i < nw; i++)
        oom |= w[i].oom;
    if (rc == RT_ECANCEL)
        return rt_fail(e, RT_ECANCEL, "interrupted");
    if (oom)
        return rt_fail(e, RT_ENOMEM, "out of memory in the chaos game");
    return rc;
}

static void free_workers(worker *w, int nw)
{
    if (!w)
        return;
    for (int i = 0; i < nw; i++) {
        rt_free(w[i].mem);
        rt_free(w[i].carry);
        rt_free(w[i].zb);
        rt_free(w[i].tag);
    }
    rt_free(w);
}

static void job_init(job *j, const sysdata *d, const chaos_opts *o)
{
    memset(j, 0, sizeof *j);
    j->d = d;
    j->o = o;
    j->points = o->points;
    j->chunk = o->chunk ? o->chunk : CHAOS_CHUNK;
    j->burn = o->burn == 0 ? CHAOS_BURN : o->burn < 0 ? 0 : (uint64_t)o->burn;
    j->nchunks = (size_t)((o->points + j->chunk - 1) / j->chunk);
}

/* ---------- window fitting ---------- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

enum { FIT_TAIL = CHAOS_FIT_POINTS / 1000 + 1 };

/* The tails of one run of the pre-pass, per axis: hl keeps the cut+1
 * smallest coordinates (a max-heap), hh the cut+1 largest, negated. */
typedef struct tails {
    double hl[3][FIT_TAIL], hh[3][FIT_TAIL];
} tails;

/* One orbit step of the pre-pass on locals (dimension and kind constant). */
INLINE void fit_step(rng *r, const sysdata *d, uint32_t *st, uint32_t *cur, double *x, double *y,
                     double *z, const int dim, const int kind)
{
    uint32_t m = step_choose(r, (uint32_t)d->n, d->thr, d->sel, st, cur, kind);
    if (dim == 2)
        step_map2(d->m + 6 * (size_t)m, x, y);
    else
        step_map3(d->m + 12 * (size_t)m, x, y, z);
}

/* The pre-pass without storing its points: per axis the (cut+1)-th smallest
 * and largest coordinate (as floats, what a stored point cloud holds) in
 * two heaps of cut+1 values — the same order statistics a selection over
 * all the points gives (chaos.h). Specialised like the hot loops (the
 * dimension and system kind are constants, the orbit in locals). Once the
 * heaps are full a value is compared with the heap's top first: after the
 * first few thousand points almost none enters a 0.1 % tail, so a point
 * costs its orbit step and two comparisons an axis; what enters does so
 * exactly as tails_heap_offer would have it, so the heaps hold the same values.
 * Non-finite values are not tested point by point: sum adds every value,
 * and a sum of at most 3·2^16 floats cannot overflow a double, so it is
 * finite exactly when every value is (an infinity or NaN makes it infinite
 * or NaN for good). 0 if a coordinate was not finite (the caller then sorts
 * the stored points). */
INLINE int fit_tails_run(const job *j, size_t cut, tails *t, const int dim, const int kind)
{
    const sysdata *d = j->d;
    size_t k = cut + 1, np = (size_t)j->points;
    orbit ob;
    orbit_start(&ob, d, j->o->seed, 0);
    rng r = ob.r;
    uint32_t st = ob.s, cur = ob.cur;
    double x = ob.x, y = ob.y, z = ob.z, sum = 0;
    for (uint64_t i = 0; i < j->burn; i++)
        fit_step(&r, d, &st, &cur, &x, &y, &z, dim, kind);
    for (size_t i = 0; i < k; i++) { /* filling the heaps (k <= np) */
        fit_step(&r, d, &st, &cur, &x, &y, &z, dim, kind);
        double v[3] = {(float)x, (float)y, (float)z};
        for (int a = 0; a < dim; a++) {
            sum += v[a];
            tails_heap_offer(t->hl[a], i, k, v[a]);
            tails_heap_offer(t->hh[a], i, k, -v[a]);
        }
    }
    double lx = t->hl[0][0], hx = -t->hh[0][0], ly = t->hl[1][0], hy = -t->hh[1][0];
    double lz = dim == 3 ? t->hl[2][0] : 0, hz = dim == 3 ? -t->hh[2][0] : 0;
    for (size_t i = k; i < np; i++) {
        fit_step(&r, d, &st, &cur, &x, &y, &z, dim, kind);
        double vx = (float)x, vy = (float)y;
        sum += vx + vy;
        tails_offer(t->hl[0], t->hh[0], k, vx, &lx, &hx);
        tails_offer(t->hl[1], t->hh[1], k, vy, &ly, &hy);
        if (dim == 3) {
            double vz = (float)z;
            sum += vz;
            tails_offer(t->hl[2], t->hh[2], k, vz, &lz, &hz);
        }
    }
    return isfinite(sum);
}

static int fit_tails(const job *j, size_t cut, double *lo, double *hi)
{
    tails t;
    int dim = j->d->dim, kind = j->d->kind, ok;
    if (dim == 2)
        ok = kind == KIND_IFS ? fit_tails_run(j, cut, &t, 2, KIND_IFS)
           : kind == KIND_R1 ? fit_tails_run(j, cut, &t, 2, KIND_R1) : fit_tails_run(j, cut, &t, 2, KIND_R2);
    else
        ok = kind == KIND_IFS ? fit_tails_run(j, cut, &t, 3, KIND_IFS)
           : kind == KIND_R1 ? fit_tails_run(j, cut, &t, 3, KIND_R1) : fit_tails_run(j, cut, &t, 3, KIND_R2);
    for (int a = 0; a < dim; a++)
        lo[a] = t.hl[a][0], hi[a] = -t.hh[a][0];
    return ok;
}

rt_code chaos_fit(const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                  rt_error *e)
{
    sysdata *d = sys_make(s, o, 0, 0, e);
    if (!d)
        return e ? e->code : RT_EINVAL;
    size_t np = o->fit_points && o->fit_points < CHAOS_FIT_POINTS ? (size_t)o->fit_points : CHAOS_FIT_POINTS;
    chaos_opts fo = *o;
    fo.points = np;
    fo.colour = CHAOS_COLOUR_NONE;
    fo.chunk = (uint32_t)np;
    fo.seed = rng_hash3(o->seed, 1ull << 63, 0, 0); /* independent of the chunks' streams */
    job j;
    job_init(&j, d, &fo);
    int dim = d->dim;
    size_t cut = np / 1000; /* 0.1 % each side */
    double *ax = NULL;
    if (!fit_tails(&j, cut, lo, hi)) { /* a coordinate overflowed: sort the stored points */
        j.pos = rt_malloc(sizeof *j.pos * 3 * np);
        ax = rt_malloc(sizeof *ax * np);
        if (!j.pos || !ax) {
            rt_free(j.pos);
            rt_free(ax);
            sys_free(d);
            return rt_fail(e, RT_ENOMEM, "out of memory fitting a window");
        }
        points_chunk(&j, 0, 0);
        for (int a = 0; a < dim; a++) {
            for (size_t i = 0; i < np; i++)
                ax[i] = j.pos[3 * i + a];
            qsort(ax, np, sizeof *ax, cmp_double);
            lo[a] = ax[cut];
            hi[a] = ax[np - 1 - cut];
        }
    }
    double ext[3];
    for (int a = 0; a < dim; a++) {
        if (!isfinite(lo[a]) || !isfinite(hi[a]))
            lo[a] = -1, hi[a] = 1;
        ext[a] = hi[a] - lo[a];
    }
    double big = 0;
    for (int a = 0; a < dim; a++)
        if (ext[a] > big)
            big = ext[a];
    for (int a = 0; a < dim; a++) {
        double c = 0.5 * (lo[a] + hi[a]);
        double x = ext[a];
        if (!(x > 1e-12 * (fabs(c) + 1)))
            x = big > 0 ? 0.1 * big : 1;
        x *= 1.1; /* 5 % margin each side */
        lo[a] = c - 0.5 * x;
        hi[a] = c + 0.5 * x;
    }
    if (dim == 2 && w > 0 && h > 0) {
        double ex = hi[0] - lo[0], ey = hi[1] - lo[1];
        double want = (double)w / h;
        if (ex / ey < want) {
            double c = 0.5 * (lo[0] + hi[0]);
            lo[0] = c - 0.5 * ey * want, hi[0] = c + 0.5 * ey * want;
        } else {
            double c = 0.5 * (lo[1] + hi[1]);
            lo[1] = c - 0.5 * ex / want, hi[1] = c + 0.5 * ex / want;
        }
    }
    rt_free(j.pos);
    rt_free(ax);
    sys_free(d);
    return RT_OK;
}

/* ---------- public evaluations ---------- */

/* counts: 0 none, 1 every worker, 2 every worker but 0 (it counts into the result) */
static rt_code alloc_workers(worker **out, int nw, size_t nbins, int counts, int colour, int zbuf,
                             rt_error *e)
{
    worker *w = rt_calloc((size_t)nw, sizeof *w);
    int bad = !w;
    for (int i = 0; !bad && i < nw; i++) {
        /* with colour: 4 uint32 per bin (count, r, g, b), see hist_chunk */
        if (counts && !(counts == 2 && i == 0) &&
            !(w[i].cnt = hist_zeroed(colour ? rt_mul_size(nbins + 1, 4) : nbins + 1, sizeof *w[i].cnt, &w[i].mem)))
            bad = 1;
        if (zbuf) {
            w[i].zb = rt_malloc(sizeof *w[i].zb * nbins);
            w[i].tag = rt_malloc(sizeof *w[i].tag * nbins);
            if (!w[i].zb || !w[i].tag)
                bad = 1;
            else
                for (size_t b = 0; b < nbins; b++)
                    w[i].zb[b] = INFINITY, w[i].tag[b] = 0;
        }
    }
    if (bad) {
        free_workers(w, nw);
        return rt_fail(e, RT_ENOMEM, "out of memory for the chaos game's accumulators");
    }
    *out = w;
    return RT_OK;
}

static uint64_t total_count(const worker *w, int nw, size_t b)
{
    uint64_t t = 0;
    for (int i = 0; i < nw; i++)
        if (w[i].cnt)
            t += (uint64_t)w[i].cnt[b] + (w[i].carry ? w[i].carry[b] << 32 : 0);
    return t;
}

/* v[b] = c[b] / den in place (c and v are the same memory): blocks of 16
 * read before they are written, so the compiler may vectorise the block. */
static void counts_to_float(const uint32_t *c, float *v, size_t n, double den)
{
    size_t b = 0;
    for (; b + 16 <= n; b += 16) {
        uint32_t t[16];
        memcpy(t, c + b, sizeof t);
        for (int q = 0; q < 16; q++)
            v[b + q] = (float)((double)t[q] / den);
    }
    for (; b < n; b++) {
        uint32_t t = c[b];
        v[b] = (float)((double)t / den);
    }
}

static void fill_stats(chaos_stats *st, const worker *w, int nw)
{
    if (!st)
        return;
    st->plotted = st->inside = 0;
    for (int i = 0; i < nw; i++) {
        st->plotted += w[i].plotted;
        st->inside += w[i].inside;
    }
}

/* A sharded or merging call (par.h): the workers' exact integer sums —
 * k = 1 (count) or 4 (count, r, g, b) per bin — then plotted and inside, go
 * through par_part_sum as one section. tot (n = nbins * k + 2 words, zeroed
 * by the caller) may already hold worker 0's counts (it counted there
 * directly); workers without counts (a merge computes no chunks) add nothing. */
static rt_code shard_sums(const par_part *pp, const worker *w, int nw, size_t nbins, int colour,
                          uint64_t *tot, size_t n, rt_error *e)
{
    size_t k = colour ? 4 : 1;
    for (int i = 0; i < nw; i++) {
        if (!w[i].cnt)
            continue;
        if (!colour)
            for (size_t b = 0; b < nbins; b++)
                tot[b] += (uint64_t)w[i].cnt[b] + (w[i].carry ? w[i].carry[b] << 32 : 0);
        else
            for (size_t q = 0; q < 4 * nbins; q++)
                tot[q] += w[i].cnt[q] + (w[i].carry ? w[i].carry[q] : 0);
    }
    for (int i = 0; i < nw; i++) {
        tot[nbins * k] += w[i].plotted;
        tot[nbins * k + 1] += w[i].inside;
    }
    return par_part_sum(pp, tot, n, e);
}

rt_code chaos_hist2(const chaos_sys *s, const chaos_opts *o, hist2 *hs, chaos_stats *st,
                    const rt_run *run, rt_error *e)
{
    if (st)
        st->plotted = st->inside = 0;
    if (o->colour != CHAOS_COLOUR_NONE && !hs->csum)
        return rt_fail(e, RT_EINVAL, "colouring needs a histogram with colour sums");
    if (hs->count32 && !hist2_narrow(o->points))
        return rt_fail(e, RT_EINVAL, "a histogram with 32-bit counts cannot take %llu points",
                       (unsigned long long)o->points);
    if (!(hs->hi[0] > hs->lo[0]) || !(hs->hi[1] > hs->lo[1]))
        return rt_fail(e, RT_EINVAL, "histogram window [%g, %g] x [%g, %g] is empty", hs->lo[0],
                       hs->hi[0], hs->lo[1], hs->hi[1]);
    sysdata *d = sys_make(s, o, 2, o->colour != CHAOS_COLOUR_NONE, e);
    if (!d)
        return e ? e->code : RT_EINVAL;
    job j;
    job_init(&j, d, o);
    j.hw = hs->w, j.hh = hs->h;
    j.nbins = (size_t)hs->w * (size_t)hs->h;
    j.lox = hs->lo[0], j.hiy = hs->hi[1];
    j.sx = hs->w / (hs->hi[0] - hs->lo[0]);
    j.sy = hs->h / (hs->hi[1] - hs->lo[1]);
    int nw = par_workers(run, j.nchunks);
    par_part pp;
    rt_code rc = par_part_begin(&pp, run, o->colour != CHAOS_COLOUR_NONE ? "chaos colour" : "chaos", j.nchunks, e);
    if (rc) {
        sys_free(d);
        return rc;
    }
    /* Worker 0 counts straight into the histogram, in a shard too: without
     * colour the histogram's own counts are the section (merge adds the
     * parts into them), then plotted and inside as a second one. With colour
     * the sums (count, r, g, b per bin) go through tot. A merge computes no
     * chunks and needs no counts of its own. */
    int colour = o->colour != CHAOS_COLOUR_NONE;
    size_t ntot = pp.mode == PAR_FULL ? 0 : colour ? j.nbins * 4 + 2 : 2;
    uint64_t *tot = ntot ? rt_calloc(ntot, sizeof *tot) : NULL;
    if (ntot && !tot) {
        sys_free(d);
        return rt_fail(e, RT_ENOMEM, "out of memory for the chaos game's sums");
    }
    if (!colour && pp.mode != PAR_MERGE) {
        j.direct = hs->count;
        j.direct32 = hs->count32;
    }
    int direct = j.direct || j.direct32;
    rc = alloc_workers(&j.w, nw, j.nbins, pp.mode == PAR_MERGE ? 0 : direct ? 2 : 1, colour, 0, e);
    if (rc) {
        rt_free(tot);
        sys_free(d);
        return rc;
    }
    rc = par_part_for(&pp, "chaos game", hist_fns[d->kind][o->colour], &j);
    rc = finish_par(rc, j.w, nw, e);
    if (!rc && pp.mode != PAR_FULL && !colour) {
        for (size_t b = 0; b < j.nbins && nw > 1 && pp.mode == PAR_SHARD; b++)
            hist2_add(hs, b, total_count(j.w, nw, b)); /* worker 0's are there already */
        for (int i = 0; i < nw; i++) {
            tot[0] += j.w[i].plotted;
            tot[1] += j.w[i].inside;
        }
        rc = hs->count32 ? par_part_sum32(&pp, hs->count32, j.nbins, e) : par_part_sum(&pp, hs->count, j.nbins, e);
        if (!rc)
            rc = par_part_sum(&pp, tot, 2, e);
        if (!rc && st) {
            st->plotted = tot[0];
            st->inside = tot[1];
        }
    } else if (!rc && pp.mode != PAR_FULL) {
        rc = shard_sums(&pp, j.w, nw, j.nbins, colour, tot, ntot, e);
        /* a shard's histogram is never used (its result is a partial value) */
        for (size_t b = 0; !rc && pp.mode == PAR_MERGE && b < j.nbins; b++) {
            hist2_add(hs, b, tot[4 * b]);
            for (int ch = 0; ch < 3; ch++)
                hs->csum[3 * b + ch] += (float)((double)tot[4 * b + ch + 1] / 65535.0);
        }
        if (!rc && st) {
            st->plotted = tot[ntot - 2];
            st->inside = tot[ntot - 1];
        }
    } else if (!rc) {
        size_t merge = direct && nw == 1 ? 0 : j.nbins; /* worker 0 alone: nothing to add */
        for (size_t b = 0; b < merge; b++) {
            if (o->colour == CHAOS_COLOUR_NONE) {
                hist2_add(hs, b, total_count(j.w, nw, b));
                continue;
            }
            uint64_t t[4] = {0, 0, 0, 0};
            for (int i = 0; i < nw; i++)
                t[0] += j.w[i].cnt[4 * b] + (j.w[i].carry ? j.w[i].carry[4 * b] : 0);
            if (!t[0]) /* no hits, so no colour: nothing to add (the sums are >= 0, never -0) */
                continue;
            for (int i = 0; i < nw; i++)
                for (int q = 1; q < 4; q++)
                    t[q] += j.w[i].cnt[4 * b + q] + (j.w[i].carry ? j.w[i].carry[4 * b + q] : 0);
            hist2_add(hs, b, t[0]);
            for (int ch = 0; ch < 3; ch++)
                hs->csum[3 * b + ch] += (float)((double)t[ch + 1] / 65535.0);
        }
        fill_stats(st, j.w, nw);
    }
    rt_free(tot);
    free_workers(j.w, nw);
    sys_free(d);
    return rc;
}

rt_code chaos_volume(const chaos_sys *s, const chaos_opts *o, chaos_norm norm, volume *vol,
                     chaos_stats *st, const rt_run *run, rt_error *e)
{
    if (st)
        st->plotted = st->inside = 0;
    for (int a = 0; a < 3; a++)
        if (!(vol->hi[a] > vol->lo[a]))
            return rt_fail(e, RT_EINVAL, "volume box is empty on axis %c", "xyz"[a]);
    sysdata *d = sys_make(s, o, 3, 0, e);
    if (!d)
        return e ? e->code : RT_EINVAL;
    job j;
    job_init(&j, d, o);
    j.nx = vol->nx, j.ny = vol->ny, j.nz = vol->nz;
    int nn[3] = {vol->nx, vol->ny, vol->nz};
    for (int a = 0; a < 3; a++) {
        j.lo3[a] = vol->lo[a];
        j.s3[a] = nn[a] / (vol->hi[a] - vol->lo[a]);
    }
    j.nbins = (size_t)vol->nx * (size_t)vol->ny * (size_t)vol->nz;
    int nw = par_workers(run, j.nchunks);
    rt_code rc = alloc_workers(&j.w, nw, j.nbins, 2, 0, 0, e);
    if (rc) {
        sys_free(d);
        return rc;
    }
    /* Worker 0 counts in the volume's own memory (uint32 where the floats
     * will be; converted in place below), so one thread needs nothing but
     * the volume; in a shard shard_sums reads it there like any worker's. */
    memset(vol->v, 0, j.nbins * sizeof *vol->v);
    j.w[0].cnt = (uint32_t *)(void *)vol->v;
    par_part pp;
    rc = par_part_begin(&pp, run, "chaos volume", j.nchunks, e);
    if (!rc)
        rc = par_part_for(&pp, "chaos game", vol_fns[maps_diagonal(d)][d->kind], &j);
    rc = finish_par(rc, j.w, nw, e);
    if (!rc && pp.mode != PAR_FULL) {
        size_t n = j.nbins + 2;
        uint64_t *tot = rt_calloc(n, sizeof *tot);
        rc = tot ? shard_sums(&pp, j.w, nw, j.nbins, 0, tot, n, e) : rt_fail(e, RT_ENOMEM, "out of memory for the chaos game's sums");
        if (!rc) {
            uint64_t mx = 0;
            for (size_t b = 0; b < j.nbins; b++)
                if (tot[b] > mx)
                    mx = tot[b];
            if (st) {
                st->plotted = tot[n - 2];
                st->inside = tot[n - 1];
            }
            double den = norm == CHAOS_NORM_TOTAL ? (double)tot[n - 2] : norm == CHAOS_NORM_MAX ? (double)mx : 1;
            if (!(den > 0))
                den = 1;
            for (size_t b = 0; b < j.nbins; b++)
                vol->v[b] = (float)((double)tot[b] / den);
        }
        rt_free(tot);
    } else if (!rc) {
        fill_stats(st, j.w, nw);
        uint64_t plotted = 0;
        for (int i = 0; i < nw; i++)
            plotted += j.w[i].plotted;
        int alone = nw == 1 && !j.w[0].carry; /* the counts are the uint32 in vol->v */
        uint64_t mx = 0;
        for (size_t b = 0; norm == CHAOS_NORM_MAX && b < j.nbins; b++) {
            uint64_t t = alone ? j.w[0].cnt[b] : total_count(j.w, nw, b);
            if (t > mx)
                mx = t;
        }
        double den = norm == CHAOS_NORM_TOTAL ? (double)plotted : norm == CHAOS_NORM_MAX ? (double)mx : 1;
        if (!(den > 0))
            den = 1;
        if (alone)
            counts_to_float(j.w[0].cnt, vol->v, j.nbins, den);
        else
            for (size_t b = 0; b < j.nbins; b++) {
                uint64_t t = total_count(j.w, nw, b); /* read the count before the float replaces it */
                vol->v[b] = (float)((double)t / den);
            }
    }
    j.w[0].cnt = NULL; /* the volume's memory */
    free_workers(j.w, nw);
    sys_free(d);
    return rc;
}

rt_code chaos_points(const chaos_sys *s, const chaos_opts *o, mesh *m, const rt_run *run,
                     rt_error *e)
{
    sysdata *d = sys_make(s, o, 0, 1, e);
    if (!d)
        return e ? e->code : RT_EINVAL;
    job j;
    job_init(&j, d, o);
    size_t np = (size_t)o->points;
    j.pos = rt_malloc(sizeof *j.pos * rt_mul_size(np ? np : 1, 3));
    int want_col = m->col && o->colour != CHAOS_COLOUR_NONE;
    if (want_col)
        j.col = rt_malloc(sizeof *j.col * rt_mul_size(np ? np : 1, 4));
    if (!j.pos || (want_col && !j.col)) {
        rt_free(j.pos);
        rt_free(j.col);
        sys_free(d);
        return rt_fail(e, RT_ENOMEM, "out of memory for %zu points", np);
    }
    /* chunk c writes points [c*chunk, (c+1)*chunk): a shard fills its
     * chunks' points, merge places them (par.h) */
    par_part pp;
    rt_code rc = par_part_begin(&pp, run, "chaos points", j.nchunks, e);
    if (!rc)
        rc = par_part_for(&pp, "chaos game", points_chunk, &j);
    rc = finish_par(rc, NULL, 0, e);
    if (!rc)
        rc = par_part_rows(&pp, j.pos, sizeof *j.pos * 3 * np, sizeof *j.pos * 3 * (size_t)j.chunk, e);
    if (!rc && j.col)
        rc = par_part_rows(&pp, j.col, sizeof *j.col * 4 * np, sizeof *j.col * 4 * (size_t)j.chunk, e);
    for (size_t i = 0; !rc && i < np; i++)
        if (mesh_add_vertex(m, j.pos + 3 * i, NULL, j.col ? j.col + 4 * i : NULL) == UINT32_MAX)
            rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu points", np);
    rt_free(j.pos);
    rt_free(j.col);
    sys_free(d);
    return rc;
}

typedef struct zcell {
    double z;
    uint32_t tag, pad;
} zcell;

static void combine_z(void *ctx, void *acc, const void *part, size_t n)
{
    (void)ctx;
    zcell *a = acc;
    const zcell *p = part;
    for (size_t b = 0; b < n; b++)
        if (p[b].z < a[b].z || (p[b].z == a[b].z && p[b].tag < a[b].tag))
            a[b] = p[b];
}

/* Sharded projection: the workers' nearest points, merged with the shards'
 * (par_part_combine), land in worker 0's arrays; the others are reset. */
static rt_code shard_zbuf(const par_part *pp, worker *w, int nw, size_t nbins, rt_error *e)
{
    zcell *zc = rt_calloc(nbins, sizeof *zc);
    if (!zc)
        return rt_fail(e, RT_ENOMEM, "out of memory for the shard's z-buffer");
    for (size_t b = 0; b < nbins; b++) {
        zc[b].z = w[0].zb[b];
        zc[b].tag = w[0].tag[b];
        for (int i = 1; i < nw; i++)
            combine_z(NULL, &zc[b], &(zcell){w[i].zb[b], w[i].tag[b], 0}, 1);
    }
    rt_code rc = par_part_combine(pp, zc, nbins, sizeof *zc, combine_z, NULL, e);
    for (size_t b = 0; !rc && b < nbins; b++) {
        w[0].zb[b] = zc[b].z;
        w[0].tag[b] = zc[b].tag;
        for (int i = 1; i < nw; i++)
            w[i].zb[b] = INFINITY, w[i].tag[b] = 0;
    }
    rt_free(zc);
    return rc;
}

rt_code chaos_project(const chaos_sys *s, const chaos_opts *o, const camera *cam, image *im,
                      chaos_stats *st, const rt_run *run, rt_error *e)
{
    if (st)
        st->plotted = st->inside = 0;
    sysdata *d = sys_make(s, o, 3, 1, e);
    if (!d)
        return e ? e->code : RT_EINVAL;
    job j;
    job_init(&j, d, o);
    j.cam = cam;
    j.iw = im->w, j.ih = im->h;
    j.nbins = (size_t)im->w * (size_t)im->h;
    int nw = par_workers(run, j.nchunks);
    rt_code rc = alloc_workers(&j.w, nw, j.nbins, 0, 0, 1, e);
    if (rc) {
        sys_free(d);
        return rc;
    }
    par_part pp;
    rc = par_part_begin(&pp, run, "chaos view", j.nchunks, e);
    if (!rc)
        rc = par_part_for(&pp, "chaos game", points_chunk, &j);
    rc = finish_par(rc, j.w, nw, e);
    if (!rc && pp.mode != PAR_FULL) /* the shards' z-buffers merge by the same nearest-point rule */
        rc = shard_zbuf(&pp, j.w, nw, j.nbins, e);
    if (!rc) {
        /* merge: nearest depth, ties by smaller tag (order-free) */
        double zmin = INFINITY, zmax = -INFINITY;
        for (size_t b = 0; b < j.nbins; b++) {
            for (int i = 1; i < nw; i++)
                if (j.w[i].zb[b] < j.w[0].zb[b] ||
                    (j.w[i].zb[b] == j.w[0].zb[b] && j.w[i].tag[b] < j.w[0].tag[b])) {
                    j.w[0].zb[b] = j.w[i].zb[b];
                    j.w[0].tag[b] = j.w[i].tag[b];
                }
            double z = j.w[0].zb[b];
            if (z < INFINITY) {
                if (z < zmin)
                    zmin = z;
                if (z > zmax)
                    zmax = z;
            }
        }
        double nb = o->near_b, fb = o->far_b;
        if (nb == 0 && fb == 0)
            nb = 1, fb = 0.25;
        double span = zmax > zmin ? zmax - zmin : 1;
        for (size_t b = 0; b < j.nbins; b++) {
            float *px = im->px + 4 * b;
            double z = j.w[0].zb[b];
            if (!(z < INFINITY)) {
                memcpy(px, o->bg, 4 * sizeof(float));
                continue;
            }
            double br = nb + (fb - nb) * ((z - zmin) / span);
            static const float white[4] = {1, 1, 1, 1};
            const float *c = o->colour == CHAOS_COLOUR_NONE ? white : d->palf[j.w[0].tag[b]];
            for (int ch = 0; ch < 3; ch++)
                px[ch] = (float)(c[ch] * br);
            px[3] = 1;
        }
        fill_stats(st, j.w, nw);
    }
    free_workers(j.w, nw);
    sys_free(d);
    return rc;
}

rt_code chaos_measure2(const hist2 *hs, chaos_norm norm, uint64_t total, image *im, rt_error *e)
{
    if (im->w != hs->w || im->h != hs->h)
        return rt_fail(e, RT_EINVAL, "measure image is %d×%d but the histogram is %d×%d", im->w,
                       im->h, hs->w, hs->h);
    size_t nb = (size_t)hs->w * (size_t)hs->h;
    uint64_t mx = 0;
    for (size_t b = 0; b < nb; b++)
        if (hist2_get(hs, b) > mx)
            mx = hist2_get(hs, b);
    double den = norm == CHAOS_NORM_TOTAL ? (double)total : norm == CHAOS_NORM_MAX ? (double)mx : 1;
    if (!(den > 0))
        den = 1;
    for (size_t b = 0; b < nb; b++) {
        float v = (float)((double)hist2_get(hs, b) / den);
        float *px = im->px + 4 * b;
        px[0] = px[1] = px[2] = v;
        px[3] = 1;
    }
    return RT_OK;
}
