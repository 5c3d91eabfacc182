/* raster.c — tiled, deterministic Z-buffer rasteriser (see raster.h). */
#include "raster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"

#define SUB 256     /* sub-pixel steps: screen coordinates snapped to 1/256 px */
#define GUARD 1048576.0 /* ±2^20 px guard band */
#define TRI_CHUNK 4096  /* least triangles per set-up and binning chunk */
#define MAX_CHUNKS 64   /* most chunks (bounds the per-chunk bin counts) */
#define MAX_BINS ((size_t)1 << 22) /* most chunks × tiles counters */

void raster_opts_default(raster_opts *o)
{
    memset(o, 0, sizeof *o);
    o->background[3] = 1;
    for (int i = 0; i < 4; i++)
        o->colour[i] = 1;
    o->ambient = 0.2;
    o->diffuse = 0.8;
    o->near = 1e-3;
    o->tile = 32;
}

typedef struct rtri {
    int64_t x[3], y[3]; /* snapped screen coordinates, 1/SUB px */
    int64_t area;       /* twice the signed area, > 0 after reordering */
    double iz[3];       /* 1 / view depth */
    float c[3][4];      /* shaded straight RGBA */
    double zmean;
    int x0, y0, x1, y1; /* pixel bounding box, inclusive; x0 > x1 when invisible */
    int opaque;
} rtri;

typedef struct setup_job {
    const mesh *m;
    const camera *cam;
    const raster_opts *o;
    int w, h;
    double light[3];
    rtri *t;
    size_t csz;     /* triangles per chunk */
    size_t *bins;   /* per chunk: triangles listed in each tile, then where they go */
    uint32_t *list; /* the tile lists, filled by fill_chunk */
    size_t ntiles;
    int ts, tiles_x;
} setup_job;

static int64_t floordiv(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

static void setup_chunk(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    setup_job *J = ctx;
    const mesh *m = J->m;
    size_t end = (chunk + 1) * J->csz < m->nt ? (chunk + 1) * J->csz : m->nt;
    for (size_t ti = chunk * J->csz; ti < end; ti++) {
        rtri *t = &J->t[ti];
        t->x0 = 1, t->x1 = 0;
        const uint32_t *v = m->tri + 3 * ti;
        if (v[0] >= m->nv || v[1] >= m->nv || v[2] >= m->nv)
            continue;
        double sx[3], sy[3], z[3], wp[3][3];
        int ok = 1;
        for (int k = 0; k < 3; k++) {
            const float *p = m->pos + 3 * (size_t)v[k];
            wp[k][0] = p[0], wp[k][1] = p[1], wp[k][2] = p[2];
            if (camera_project(J->cam, J->w, J->h, wp[k], &sx[k], &sy[k], &z[k]) || z[k] <= J->o->near ||
                !(fabs(sx[k]) < GUARD && fabs(sy[k]) < GUARD))
                ok = 0;
        }
        if (!ok)
            continue;
        /* shading at the corners */
        double fn[3], e1[3], e2[3];
        for (int d = 0; d < 3; d++)
            e1[d] = wp[1][d] - wp[0][d], e2[d] = wp[2][d] - wp[0][d];
        fn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        fn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        fn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double fl = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
        for (int k = 0; k < 3; k++) {
            const float *c = m->col ? m->col + 4 * (size_t)v[k] : J->o->colour;
            double f = 1;
            if (!J->o->unlit) {
                double n[3] = {fn[0], fn[1], fn[2]}, l = fl;
                if (m->nrm && !J->o->flat) {
                    const float *q = m->nrm + 3 * (size_t)v[k];
                    n[0] = q[0], n[1] = q[1], n[2] = q[2];
                    l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                }
                double nl = l > 0 ? fabs(n[0] * J->light[0] + n[1] * J->light[1] + n[2] * J->light[2]) / l : 0;
                f = J->o->ambient + J->o->diffuse * nl;
            }
            for (int d = 0; d < 3; d++)
                t->c[k][d] = (float)(c[d] * f);
            t->c[k][3] = c[3];
        }
        for (int k = 0; k < 3; k++) {
            t->x[k] = llround(sx[k] * SUB);
            t->y[k] = llround(sy[k] * SUB);
            t->iz[k] = 1.0 / z[k];
        }
        int64_t area = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]) - (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
        if (area == 0)
            continue;
        if (area < 0) { /* make the edge functions positive inside */
            int64_t tx = t->x[1], ty = t->y[1];
            t->x[1] = t->x[2], t->y[1] = t->y[2], t->x[2] = tx, t->y[2] = ty;
            double tz = t->iz[1];
            t->iz[1] = t->iz[2], t->iz[2] = tz;
            float tc[4];
            memcpy(tc, t->c[1], sizeof tc);
            memcpy(t->c[1], t->c[2], sizeof tc);
            memcpy(t->c[2], tc, sizeof tc);
            area = -area;
        }
        t->area = area;
        t->zmean = (z[0] + z[1] + z[2]) / 3;
        t->opaque = t->c[0][3] >= 1 && t->c[1][3] >= 1 && t->c[2][3] >= 1;
        int64_t mnx = t->x[0], mxx = t->x[0], mny = t->y[0], mxy = t->y[0];
        for (int k = 1; k < 3; k++) {
            mnx = t->x[k] < mnx ? t->x[k] : mnx;
            mxx = t->x[k] > mxx ? t->x[k] : mxx;
            mny = t->y[k] < mny ? t->y[k] : mny;
            mxy = t->y[k] > mxy ? t->y[k] : mxy;
        }
        /* pixels whose centre (x + 1/2)·SUB lies in [mn, mx] */
        int64_t x0 = -floordiv(-(mnx - SUB / 2), SUB), x1 = floordiv(mxx - SUB / 2, SUB);
        int64_t y0 = -floordiv(-(mny - SUB / 2), SUB), y1 = floordiv(mxy - SUB / 2, SUB);
        if (x0 < 0) x0 = 0;
        if (y0 < 0) y0 = 0;
        if (x1 > J->w - 1) x1 = J->w - 1;
        if (y1 > J->h - 1) y1 = J->h - 1;
        if (x0 > x1 || y0 > y1)
            continue;
        t->x0 = (int)x0, t->x1 = (int)x1, t->y0 = (int)y0, t->y1 = (int)y1;
    }
    /* binning, part 1: how many of this chunk's triangles each tile lists */
    size_t *cnt = J->bins + chunk * J->ntiles, tx = (size_t)J->tiles_x;
    int ts = J->ts;
    const rtri *tr = J->t;
    for (size_t ti = chunk * J->csz; ti < end; ti++) {
        const rtri *t = &tr[ti];
        if (t->x0 > t->x1)
            continue;
        int bx0 = t->x0 / ts, bx1 = t->x1 / ts, by1 = t->y1 / ts;
        for (int by = t->y0 / ts; by <= by1; by++)
            for (int bx = bx0; bx <= bx1; bx++)
                cnt[(size_t)by * tx + (size_t)bx]++;
    }
}

/* Binning, part 2: the chunk's triangles, in mesh order, into the slots
 * raster_render reserved for the chunk in each tile list (after those of
 * the chunks before it), so every list is in mesh order whatever the
 * thread count. */
static void fill_chunk(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    setup_job *J = ctx;
    size_t end = (chunk + 1) * J->csz < J->m->nt ? (chunk + 1) * J->csz : J->m->nt;
    size_t *fill = J->bins + chunk * J->ntiles, tx = (size_t)J->tiles_x;
    int ts = J->ts;
    const rtri *tr = J->t;
    uint32_t *list = J->list;
    for (size_t i = chunk * J->csz; i < end; i++) {
        const rtri *t = &tr[i];
        if (t->x0 > t->x1)
            continue;
        int bx0 = t->x0 / ts, bx1 = t->x1 / ts, by1 = t->y1 / ts;
        for (int by = t->y0 / ts; by <= by1; by++)
            for (int bx = bx0; bx <= bx1; bx++)
                list[fill[(size_t)by * tx + (size_t)bx]++] = (uint32_t)i;
    }
}

typedef struct tile_job {
    const rtri *t;
    const uint32_t *list;
    const size_t *start;
    int tw, tiles_x, tile;
    image *im;
    const raster_opts *o;
} tile_job;

typedef struct zsort {
    double z;
    uint32_t i;
} zsort;

static int zsort_cmp(const void *pa, const void *pb)
{
    const zsort *a = pa, *b = pb;
    if (a->z != b->z)
        return a->z < b->z ? 1 : -1; /* far first */
    return (a->i > b->i) - (a->i < b->i);
}

/* Draw one triangle into the tile buffers. */
static void draw_tri(const rtri *t, int tx0, int ty0, int tx1, int ty1, int ts, double *zb, float *cb,
                     int blend)
{
    int x0 = t->x0 > tx0 ? t->x0 : tx0, x1 = t->x1 < tx1 ? t->x1 : tx1;
    int y0 = t->y0 > ty0 ? t->y0 : ty0, y1 = t->y1 < ty1 ? t->y1 : ty1;
    if (x0 > x1 || y0 > y1)
        return;
    int64_t bias[3], ex[3], ey[3], e0[3];
    int64_t px = (int64_t)x0 * SUB + SUB / 2, py = (int64_t)y0 * SUB + SUB / 2;
    for (int k = 0; k < 3; k++) {
        int a = (k + 1) % 3, b = (k + 2) % 3; /* edge a→b, opposite vertex k */
        int64_t dx = t->x[b] - t->x[a], dy = t->y[b] - t->y[a];
        int own = dy < 0 || (dy == 0 && dx > 0); /* top or left edge */
        bias[k] = own ? 0 : 1;
        ex[k] = -dy * SUB;
        ey[k] = dx * SUB;
        e0[k] = dx * (py - t->y[a]) - dy * (px - t->x[a]);
    }
    double inva = 1.0 / (double)t->area;
    for (int y = y0; y <= y1; y++) {
        int64_t e[3];
        for (int k = 0; k < 3; k++)
            e[k] = e0[k] + ey[k] * (y - y0);
        for (int x = x0; x <= x1; x++, e[0] += ex[0], e[1] += ex[1], e[2] += ex[2]) {
            if (e[0] < bias[0] || e[1] < bias[1] || e[2] < bias[2])
                continue;
            double w0 = (double)e[0] * inva * t->iz[0], w1 = (double)e[1] * inva * t->iz[1],
                   w2 = (double)e[2] * inva * t->iz[2];
            double iz = w0 + w1 + w2;
            size_t p = (size_t)(y - ty0) * (size_t)ts + (size_t)(x - tx0);
            if (!(iz > zb[p]))
                continue;
            double r = 1.0 / iz;
            float c[4];
            for (int d = 0; d < 4; d++)
                c[d] = (float)((w0 * t->c[0][d] + w1 * t->c[1][d] + w2 * t->c[2][d]) * r);
            float *o = cb + 4 * p;
            if (!blend) {
                zb[p] = iz;
                o[0] = c[0], o[1] = c[1], o[2] = c[2], o[3] = 1;
            } else {
                float a = c[3] < 0 ? 0 : c[3] > 1 ? 1 : c[3];
                for (int d = 0; d < 3; d++)
                    o[d] = a * c[d] + (1 - a) * o[d];
                o[3] = a + (1 - a) * o[3];
            }
        }
    }
}

static void tile_fn(void *ctx, size_t tile, int worker)
{
    (void)worker;
    tile_job *J = ctx;
    int ts = J->tile, tx = (int)(tile % (size_t)J->tiles_x), ty = (int)(tile / (size_t)J->tiles_x);
    int x0 = tx * ts, y0 = ty * ts;
    int x1 = x0 + ts - 1 < J->im->w - 1 ? x0 + ts - 1 : J->im->w - 1;
    int y1 = y0 + ts - 1 < J->im->h - 1 ? y0 + ts - 1 : J->im->h - 1;
    size_t np = (size_t)ts * (size_t)ts;
    double *zb = malloc(sizeof(double) * np);
    float *cb = malloc(sizeof(float) * 4 * np);
    size_t n = J->start[tile + 1] - J->start[tile];
    zsort *zs = malloc(sizeof(zsort) * (n ? n : 1));
    if (!zb || !cb || !zs) { /* cannot report from here; leave the tile as background */
        free(zb);
        free(cb);
        free(zs);
        return;
    }
    const float *bg = J->o->background;
    float ba = bg[3] < 0 ? 0 : bg[3] > 1 ? 1 : bg[3];
    for (size_t p = 0; p < np; p++) {
        zb[p] = 0;
        cb[4 * p] = bg[0] * ba, cb[4 * p + 1] = bg[1] * ba, cb[4 * p + 2] = bg[2] * ba, cb[4 * p + 3] = ba;
    }
    const uint32_t *L = J->list + J->start[tile];
    size_t nt = 0;
    for (size_t q = 0; q < n; q++) {
        const rtri *t = &J->t[L[q]];
        if (t->opaque)
            draw_tri(t, x0, y0, x1, y1, ts, zb, cb, 0);
        else
            zs[nt++] = (zsort){t->zmean, L[q]};
    }
    qsort(zs, nt, sizeof *zs, zsort_cmp);
    for (size_t q = 0; q < nt; q++)
        draw_tri(&J->t[zs[q].i], x0, y0, x1, y1, ts, zb, cb, 1);
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            const float *c = cb + 4 * ((size_t)(y - y0) * (size_t)ts + (size_t)(x - x0));
            float *o = image_at(J->im, x, y);
            float a = c[3];
            for (int d = 0; d < 3; d++)
                o[d] = a > 0 ? (a == 1 ? c[d] : c[d] / a) : 0;
            o[3] = a;
        }
    free(zb);
    free(cb);
    free(zs);
}

rt_code raster_render(const mesh *m, const camera *cam, const raster_opts *o, const rt_run *run,
                      image *im, rt_error *e)
{
    if (!im || !im->px || im->w < 1 || im->h < 1)
        return rt_fail(e, RT_EINVAL, "raster: the image has no pixels");
    int ts = o->tile > 0 ? o->tile : 32;
    if (ts > 1024)
        ts = 1024;
    int tiles_x = (im->w + ts - 1) / ts, tiles_y = (im->h + ts - 1) / ts;
    size_t ntiles = (size_t)tiles_x * (size_t)tiles_y;
    rtri *t = malloc(sizeof *t * (m->nt ? m->nt : 1));
    size_t *start = calloc(ntiles + 1, sizeof(size_t));
    uint32_t *list = NULL;
    size_t *bins = NULL;
    rt_code rc = RT_OK;
    if (!t || !start || m->nt >= UINT32_MAX) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory rasterising %zu triangles", m->nt);
        goto done;
    }
    /* chunks depend on the triangle and tile counts only, never on threads */
    size_t nch = (m->nt + TRI_CHUNK - 1) / TRI_CHUNK, maxch = MAX_BINS / (ntiles ? ntiles : 1);
    if (nch > MAX_CHUNKS)
        nch = MAX_CHUNKS;
    if (nch > maxch)
        nch = maxch;
    if (nch < 1)
        nch = 1;
    size_t csz = (m->nt + nch - 1) / nch;
    if (csz < 1)
        csz = 1;
    nch = (m->nt + csz - 1) / csz;
    setup_job S = {m, cam, o, im->w, im->h, {0, 0, 0}, t, csz, NULL, NULL, ntiles, ts, tiles_x};
    bins = S.bins = calloc(nch * ntiles + 1, sizeof(size_t));
    if (!bins) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory binning %zu triangles", m->nt);
        goto done;
    }
    double ll = sqrt(o->light[0] * o->light[0] + o->light[1] * o->light[1] + o->light[2] * o->light[2]);
    if (ll > 0) {
        for (int d = 0; d < 3; d++)
            S.light[d] = o->light[d] / ll;
    } else {
        double l[3], n2 = 0;
        for (int d = 0; d < 3; d++) {
            l[d] = -cam->fwd[d] + 0.5 * cam->upv[d] - 0.5 * cam->right[d];
            n2 += l[d] * l[d];
        }
        for (int d = 0; d < 3; d++)
            S.light[d] = l[d] / sqrt(n2);
    }
    rc = par_for(run, "raster setup", nch, setup_chunk, &S);
    if (rc) {
        rt_fail(e, rc, "rasterising interrupted");
        goto done;
    }
    /* tile lists in tile order; inside a tile, the chunks in chunk order:
     * each chunk's count becomes where its first entry goes */
    size_t tot = 0;
    for (size_t q = 0; q < ntiles; q++) {
        start[q] = tot;
        for (size_t c = 0; c < nch; c++) {
            size_t k = S.bins[c * ntiles + q];
            S.bins[c * ntiles + q] = tot;
            tot += k;
        }
    }
    start[ntiles] = tot;
    list = malloc(sizeof(uint32_t) * (tot ? tot : 1));
    if (!list) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory binning %zu triangles", m->nt);
        goto done;
    }
    S.list = list;
    rc = par_for(run, "raster binning", nch, fill_chunk, &S);
    if (rc) {
        rt_fail(e, rc, "rasterising interrupted");
        goto done;
    }
    tile_job T = {t, list, start, im->w, tiles_x, ts, im, o};
    rc = par_for(run, "raster", ntiles, tile_fn, &T);
    if (rc)
        rt_fail(e, rc, "rasterising interrupted");
    (void)tiles_y;
done:
    free(bins);
    free(t);
    free(start);
    free(list);
    return rc;
}
