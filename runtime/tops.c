/* tops.c — fractal tops (seed 004 eqs. (4)–(9)), colour stealing (§4) and
 * the fractal filter (§6). */
#include "tops.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"
#include "rng.h"

#define TOPS_CHUNK ((uint64_t)1 << 16)

typedef struct tops_ctx {
    const fset_ifs *f, *g;
    const draw_view *screen, *src_view;
    const tops_opts *opts;
    tops_buf *out;
    double cum[FSET_MAX_MAPS];
    double fa[2], fb[2]; /* orbit starts: fixed points of f_0 and g_0 */
    tops_cell **cells;   /* per worker */
} tops_ctx;

/* (key, aux) ordered lexicographically: the greater wins a pixel. */
static int cell_greater(uint64_t key, uint32_t aux, const tops_cell *c)
{
    return !c->hit || key > c->key || (key == c->key && aux > c->aux);
}

/* Merging shards' tops: the same order-free max as merging workers. */
static void combine_cells(void *ctx, void *acc, const void *part, size_t n)
{
    (void)ctx;
    tops_cell *a = acc;
    const tops_cell *p = part;
    for (size_t k = 0; k < n; k++)
        if (p[k].hit && cell_greater(p[k].key, p[k].aux, &a[k]))
            a[k] = p[k];
}

static void fixed_point(const affine *m, double out[2])
{
    double a = m->m[0][0], b = m->m[0][1], c = m->m[1][0], d = m->m[1][1];
    double det = (1 - a) * (1 - d) - b * c;
    if (fabs(det) > 1e-12) {
        out[0] = ((1 - d) * m->t[0] + b * m->t[1]) / det;
        out[1] = (c * m->t[0] + (1 - a) * m->t[1]) / det;
        return;
    }
    double x = 0, y = 0;
    for (int i = 0; i < 200; i++)
        fset_apply2(m, &x, &y);
    out[0] = x;
    out[1] = y;
}

static void tops_chunk(void *p, size_t chunk, int worker)
{
    tops_ctx *c = p;
    const tops_buf *t = c->out;
    tops_cell *cell = c->cells[worker];
    uint64_t first = (uint64_t)chunk * TOPS_CHUNK, total = c->opts->points;
    uint64_t n = total - first < TOPS_CHUNK ? total - first : TOPS_CHUNK;
    uint64_t N = (uint64_t)c->f->n, lead = t->lead;
    int w = t->w, h = t->h, nm = c->f->n;
    rng r;
    rng_init(&r, c->opts->seed, chunk);
    double ax = c->fa[0], ay = c->fa[1], bx = c->fb[0], by = c->fb[1];
    uint64_t key = 0; /* address 000…: exactly the fixed point of map 0 */
    for (uint64_t i = 0; i < n; i++) {
        int m = fset_pick(c->cum, nm, rng_uniform(&r));
        fset_apply2(&c->f->maps[m], &ax, &ay);
        key = key / N + (uint64_t)m * lead; /* T_m(ω, x) = (mω, f_m(x)), eq. (6) */
        uint32_t aux = 0;
        if (c->g) {
            fset_apply2(&c->g->maps[m], &bx, &by);
            double sx, sy;
            draw_to_px(c->src_view, bx, by, &sx, &sy);
            int ix = !(sx >= 0) ? 0 : sx >= t->src_w ? t->src_w - 1 : (int)sx;
            int iy = !(sy >= 0) ? 0 : sy >= t->src_h ? t->src_h - 1 : (int)sy;
            aux = (uint32_t)iy * (uint32_t)t->src_w + (uint32_t)ix;
        }
        double px, py;
        draw_to_px(c->screen, ax, ay, &px, &py);
        if (!(px >= 0 && px < w && py >= 0 && py < h))
            continue;
        tops_cell *q = &cell[(size_t)(int)py * (size_t)w + (size_t)(int)px];
        if (cell_greater(key, aux, q)) { /* Top(·), eq. (7) */
            q->key = key;
            q->aux = aux;
            q->hit = 1;
        }
    }
}

static rt_code check_ifs(const fset_ifs *f, const char *what, rt_error *e)
{
    fset fs = {1, f};
    rt_error sub;
    if (fset_validate(&fs, &sub)) {
        /* "function set W1: probability 2 is …" → "fractal top: probability 2 is …" */
        const char *m = sub.msg;
        if (strncmp(m, "function set W1", 15) == 0)
            m += 15;
        return rt_fail(e, RT_EINVAL, "%s%s", what, m);
    }
    if (f->maps[0].dim != 2)
        return rt_fail(e, RT_EINVAL, "%s needs 2-D maps (got %d-D)", what, f->maps[0].dim);
    return RT_OK;
}

static rt_code run_tops(const fset_ifs *f, const draw_view *screen, const fset_ifs *g,
                        const draw_view *src_view, int src_w, int src_h, const tops_opts *opts,
                        tops_buf *out, const rt_run *run, rt_error *e)
{
    memset(out, 0, sizeof *out);
    rt_code code = check_ifs(f, g ? "colour stealing screen IFS" : "fractal top", e);
    if (code)
        return code;
    if (g) {
        if ((code = check_ifs(g, "colour stealing source IFS", e)))
            return code;
        if (g->n != f->n)
            return rt_fail(e, RT_EINVAL,
                           "colour stealing needs IFSs with the same number of maps (screen has "
                           "%d, source has %d)",
                           f->n, g->n);
        if (src_w < 1 || src_h < 1 || (uint64_t)src_w * (uint64_t)src_h > UINT32_MAX)
            return rt_fail(e, RT_EINVAL, "colour stealing source size %d×%d is not supported",
                           src_w, src_h);
    }
    if (screen->w < 1 || screen->h < 1)
        return rt_fail(e, RT_EINVAL, "fractal top view %d×%d is empty", screen->w, screen->h);
    if (opts->depth < 0)
        return rt_fail(e, RT_EINVAL, "fractal top depth %d (expected >= 0)", opts->depth);

    /* K symbols with N^K < 2^64; lead = N^(K-1). */
    uint64_t N = (uint64_t)f->n, lead = 1;
    int K = 1;
    if (N >= 2)
        while (lead <= (UINT64_MAX / N) / N && (opts->depth == 0 || K < opts->depth)) {
            lead *= N;
            K++;
        }
    out->w = screen->w;
    out->h = screen->h;
    out->nmaps = f->n;
    out->depth = K;
    out->lead = lead;
    out->src_w = g ? src_w : 0;
    out->src_h = g ? src_h : 0;
    size_t npx = (size_t)screen->w * (size_t)screen->h;
    out->cell = rt_calloc(npx, sizeof *out->cell);
    if (!out->cell)
        return rt_fail(e, RT_ENOMEM, "out of memory for a %d×%d fractal top", screen->w,
                       screen->h);
    if (opts->points == 0)
        return RT_OK;

    tops_ctx c = {.f = f, .g = g, .screen = screen, .src_view = src_view, .opts = opts, .out = out};
    fset_cumulative(f->p, f->n, c.cum);
    fixed_point(&f->maps[0], c.fa);
    if (g)
        fixed_point(&g->maps[0], c.fb);
    size_t nchunks = (size_t)((opts->points + TOPS_CHUNK - 1) / TOPS_CHUNK);
    int nw = par_workers(run, nchunks);
    c.cells = rt_calloc((size_t)nw, sizeof *c.cells);
    if (!c.cells) {
        tops_free(out);
        return rt_fail(e, RT_ENOMEM, "out of memory for the fractal top");
    }
    c.cells[0] = out->cell;
    for (int i = 1; i < nw; i++)
        if (!(c.cells[i] = rt_calloc(npx, sizeof **c.cells))) {
            code = rt_fail(e, RT_ENOMEM, "out of memory for %d per-thread fractal tops", nw);
            goto done;
        }
    par_part pp; /* a shard runs its chunks; the cells merge by the same max (par.h) */
    code = par_part_begin(&pp, run, g ? "colour stealing" : "fractal top", nchunks, e);
    if (code)
        goto done;
    code = par_part_for(&pp, g ? "colour stealing" : "fractal top", tops_chunk, &c);
    if (code) {
        rt_fail(e, code, "interrupted");
        goto done;
    }
    /* Max is order-free: merging per-worker tops gives the same result for
     * any thread count. */
    for (int i = 1; i < nw; i++)
        for (size_t k = 0; k < npx; k++) {
            const tops_cell *s = &c.cells[i][k];
            if (s->hit && cell_greater(s->key, s->aux, &out->cell[k]))
                out->cell[k] = *s;
        }
    code = par_part_combine(&pp, out->cell, npx, sizeof *out->cell, combine_cells, NULL, e);
done:
    for (int i = 1; i < nw; i++)
        rt_free(c.cells[i]);
    rt_free(c.cells);
    if (code)
        tops_free(out);
    return code;
}

rt_code tops_run(const fset_ifs *f, const draw_view *view, const tops_opts *opts, tops_buf *out,
                 const rt_run *run, rt_error *e)
{
    return run_tops(f, view, NULL, NULL, 0, 0, opts, out, run, e);
}

void tops_free(tops_buf *t)
{
    rt_free(t->cell);
    t->cell = NULL;
}

int tops_symbol(const tops_buf *t, uint64_t key, int i)
{
    if (t->nmaps < 2 || i < 0 || i >= t->depth)
        return 0;
    uint64_t w = t->lead;
    for (int k = 0; k < i; k++)
        w /= (uint64_t)t->nmaps;
    return (int)((key / w) % (uint64_t)t->nmaps);
}

static rt_code check_out(const tops_buf *t, const image *out, rt_error *e)
{
    if (out->w != t->w || out->h != t->h)
        return rt_fail(e, RT_EINVAL, "output image is %d×%d but the fractal top is %d×%d", out->w,
                       out->h, t->w, t->h);
    return RT_OK;
}

rt_code tops_colour(const tops_buf *t, int nsym, const ramp *r, const float bg[4], image *out,
                    rt_error *e)
{
    rt_code code = check_out(t, out, e);
    if (code)
        return code;
    if (nsym < 1 || nsym > t->depth)
        return rt_fail(e, RT_EINVAL, "colouring by %d address symbols (expected 1 to %d)", nsym,
                       t->depth);
    uint64_t div = 1;
    double span = 1;
    for (int k = 0; k < nsym; k++)
        span *= t->nmaps;
    for (int k = nsym; k < t->depth; k++)
        div *= (uint64_t)t->nmaps;
    size_t npx = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < npx; i++) {
        float *px = out->px + 4 * i;
        if (!t->cell[i].hit) {
            memcpy(px, bg, 4 * sizeof *px);
            continue;
        }
        double prefix = t->nmaps < 2 ? 0 : (double)(t->cell[i].key / div);
        ramp_eval(r, span > 1 ? prefix / (span - 1) : 0, px);
    }
    return RT_OK;
}

rt_code tops_steal(const fset_ifs *f, const draw_view *screen, const fset_ifs *g,
                   const draw_view *src_view, const tops_opts *opts, tops_buf *out,
                   const rt_run *run, rt_error *e)
{
    return run_tops(f, screen, g, src_view, src_view->w, src_view->h, opts, out, run, e);
}

rt_code tops_steal_apply(const tops_buf *t, const image *src, const float bg[4], image *out,
                         rt_error *e)
{
    rt_code code = check_out(t, out, e);
    if (code)
        return code;
    if (src->w != t->src_w || src->h != t->src_h)
        return rt_fail(e, RT_EINVAL,
                       "colour stealing source picture is %d×%d but the top was made for %d×%d",
                       src->w, src->h, t->src_w, t->src_h);
    size_t npx = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < npx; i++) {
        const float *from = t->cell[i].hit ? src->px + 4 * (size_t)t->cell[i].aux : bg;
        memcpy(out->px + 4 * i, from, 4 * sizeof(float));
    }
    return RT_OK;
}

rt_code tops_filter(const fset_ifs *f, const draw_view *screen, const fset_ifs *g,
                    const double src_lo[2], const double src_hi[2], const image *frames, int n,
                    const tops_opts *opts, const float bg[4], image *out, const rt_run *run,
                    rt_error *e)
{
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "fractal filter has no frames (expected at least 1)");
    for (int i = 1; i < n; i++)
        if (frames[i].w != frames[0].w || frames[i].h != frames[0].h)
            return rt_fail(e, RT_EINVAL, "fractal filter frame %d is %d×%d but frame 1 is %d×%d",
                           i + 1, frames[i].w, frames[i].h, frames[0].w, frames[0].h);
    draw_view sv;
    rt_code code = draw_view_fit(&sv, frames[0].w, frames[0].h, src_lo, src_hi, 0, e);
    if (code)
        return code;
    tops_buf t;
    if ((code = tops_steal(f, screen, g, &sv, opts, &t, run, e)))
        return code;
    int made = 0;
    for (; made < n; made++) {
        if ((code = image_init(&out[made], t.w, t.h, e)))
            break;
        if ((code = tops_steal_apply(&t, &frames[made], bg, &out[made], e))) {
            made++;
            break;
        }
    }
    if (code)
        for (int i = 0; i < made; i++)
            image_free(&out[i]);
    tops_free(&t);
    return code;
}
