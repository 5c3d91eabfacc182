/* raster.c — tiled, deterministic Z-buffer rasteriser (see raster.h). */
#include "raster.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"

#define SUB 256     /* sub-pixel steps: screen coordinates snapped to 1/256 px */
#define GUARD 1048576.0 /* ±2^20 px guard band */
#define TRI_CHUNK 4096  /* least triangles per set-up and binning chunk */
#define MAX_CHUNKS 64   /* most chunks (bounds the per-chunk bin counts) */
#define MAX_BINS ((size_t)1 << 22) /* most chunks × tiles counters */
#define NEAR_MIN 1e-6   /* least near plane depth (camera_project needs z > 1e-9) */

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
    int more; /* pieces of the same mesh triangle that follow it in its chunk's extras */
} rtri;

/* The pieces beyond the first of the clipped triangles of one set-up chunk,
 * in mesh order; appended after the mesh's triangles once set-up is done. */
typedef struct chunk_extra {
    rtri *t;
    size_t n, cap;
    size_t base; /* index of the first in the whole array */
    int oom;
} chunk_extra;

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
    chunk_extra *ex; /* per chunk */
    double zn;       /* near plane used for the test and the clipping */
} setup_job;

static int64_t floordiv(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

/* Snap a projected triangle and fill t. Returns 0 when it covers no pixel
 * centre of the image (t is then marked invisible). */
static int make_tri(const setup_job *J, rtri *t, const double sx[3], const double sy[3], const double z[3],
                    const float c[3][4], int opaque)
{
    t->x0 = 1, t->x1 = 0;
    memcpy(t->c, c, sizeof t->c);
    for (int k = 0; k < 3; k++) {
        t->x[k] = llround(sx[k] * SUB);
        t->y[k] = llround(sy[k] * SUB);
        t->iz[k] = 1.0 / z[k];
    }
    int64_t area = (t->x[1] - t->x[0]) * (t->y[2] - t->y[0]) - (t->y[1] - t->y[0]) * (t->x[2] - t->x[0]);
    if (area == 0)
        return 0;
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
    t->opaque = opaque;
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
        return 0;
    t->x0 = (int)x0, t->x1 = (int)x1, t->y0 = (int)y0, t->y1 = (int)y1;
    return 1;
}

/* A polygon corner during clipping: world position, view coordinates
 * (right, up, depth) and shaded straight colour. */
typedef struct cvert {
    double p[3], v[3];
    float c[4];
} cvert;

#define CLIP_PLANES 5
#define CLIP_MAX 16 /* a convex polygon gains at most one corner a plane: 3 + 5 */

/* Signed distance of a corner from clip plane k (>= 0 inside), in view
 * space: the near plane, then the planes through the eye on which the
 * screen x or y is ±GUARD/2, so a clipped corner projects well inside the
 * guard band. g = {gx-, gx+, gy-, gy+} (see clip_tri). */
static double clip_dist(int k, const double v[3], double zn, const double g[4])
{
    switch (k) {
    case 0: return v[2] - zn;
    case 1: return v[0] + v[2] * g[0];
    case 2: return v[2] * g[1] - v[0];
    case 3: return v[2] * g[2] - v[1];
    default: return v[1] + v[2] * g[3];
    }
}

/* Append a piece to the chunk's extras. */
static rtri *extra_slot(chunk_extra *X)
{
    if (X->n == X->cap) {
        size_t cap = X->cap ? 2 * X->cap : 64;
        rtri *nt = rt_realloc(X->t, sizeof *nt * cap);
        if (!nt) {
            X->oom = 1;
            return NULL;
        }
        X->t = nt, X->cap = cap;
    }
    return &X->t[X->n++];
}

/* A triangle with a corner at or behind the near plane or outside the guard
 * band: Sutherland–Hodgman against the near plane and the four guard-band
 * planes in view space (Sutherland & Hodgman 1974, "Reentrant polygon
 * clipping"), then the convex polygon left is projected and drawn as a fan.
 * World position, view coordinates and shaded colour are interpolated
 * linearly along the clipped edges, which is what the perspective-correct
 * interpolation inside the triangle does, so the pieces show the same
 * colours and depths as the unclipped triangle would. A cut point is always
 * computed from the inside corner toward the outside one, so an edge shared
 * by two triangles is cut at bit-identical points in both and the top-left
 * rule still draws its pixels once. The first visible piece goes to *t,
 * the others to the chunk's extras (t->more counts them). */
static void clip_tri(const setup_job *J, chunk_extra *X, rtri *t, const double wp[3][3], const float col[3][4],
                     int opaque)
{
    const camera *cam = J->cam;
    double asp = (double)J->w / (double)J->h, gb = GUARD / 2, g[4];
    g[0] = cam->tan_half * asp * (2 * gb / J->w + 1);
    g[1] = cam->tan_half * asp * (2 * gb / J->w - 1);
    g[2] = cam->tan_half * (1 + 2 * gb / J->h);
    g[3] = cam->tan_half * (2 * gb / J->h - 1);
    cvert buf[2][CLIP_MAX];
    cvert *poly = buf[0], *out = buf[1];
    int n = 3;
    for (int k = 0; k < 3; k++) {
        double d[3];
        for (int a = 0; a < 3; a++)
            poly[k].p[a] = wp[k][a], d[a] = wp[k][a] - cam->eye[a];
        poly[k].v[0] = d[0] * cam->right[0] + d[1] * cam->right[1] + d[2] * cam->right[2];
        poly[k].v[1] = d[0] * cam->upv[0] + d[1] * cam->upv[1] + d[2] * cam->upv[2];
        poly[k].v[2] = d[0] * cam->fwd[0] + d[1] * cam->fwd[1] + d[2] * cam->fwd[2];
        memcpy(poly[k].c, col[k], sizeof poly[k].c);
    }
    for (int pl = 0; pl < CLIP_PLANES && n >= 3; pl++) {
        int m = 0;
        for (int i = 0; i < n; i++) {
            if (m + 2 > CLIP_MAX) { /* rounding made it non-convex: give up on a sliver */
                n = 0;
                break;
            }
            const cvert *a = &poly[i], *b = &poly[(i + 1) % n];
            double da = clip_dist(pl, a->v, J->zn, g), db = clip_dist(pl, b->v, J->zn, g);
            if (da >= 0)
                out[m++] = *a;
            if ((da >= 0) != (db >= 0)) {
                const cvert *in = da >= 0 ? a : b, *ou = da >= 0 ? b : a;
                double din = da >= 0 ? da : db, dou = da >= 0 ? db : da;
                double s = din / (din - dou);
                cvert *q = &out[m++];
                for (int d = 0; d < 3; d++) {
                    q->p[d] = in->p[d] + s * (ou->p[d] - in->p[d]);
                    q->v[d] = in->v[d] + s * (ou->v[d] - in->v[d]);
                }
                for (int d = 0; d < 4; d++)
                    q->c[d] = (float)(in->c[d] + s * (ou->c[d] - in->c[d]));
            }
        }
        if (n == 0)
            break;
        cvert *sw = poly;
        poly = out, out = sw;
        n = m;
    }
    if (n < 3)
        return;
    double sx[CLIP_MAX], sy[CLIP_MAX], z[CLIP_MAX];
    for (int i = 0; i < n; i++)
        if (camera_project(cam, J->w, J->h, poly[i].p, &sx[i], &sy[i], &z[i]) ||
            !(fabs(sx[i]) < GUARD && fabs(sy[i]) < GUARD))
            return; /* only on overflow: the polygon is inside the planes */
    rtri *dst = t;
    for (int i = 1; i + 1 < n; i++) {
        double fx[3] = {sx[0], sx[i], sx[i + 1]}, fy[3] = {sy[0], sy[i], sy[i + 1]}, fz[3] = {z[0], z[i], z[i + 1]};
        float fc[3][4];
        memcpy(fc[0], poly[0].c, sizeof fc[0]);
        memcpy(fc[1], poly[i].c, sizeof fc[1]);
        memcpy(fc[2], poly[i + 1].c, sizeof fc[2]);
        rtri piece;
        if (!make_tri(J, &piece, fx, fy, fz, (const float(*)[4])fc, opaque))
            continue;
        piece.more = 0;
        if (dst) {
            *dst = piece;
            dst = NULL;
        } else {
            rtri *x = extra_slot(X);
            if (!x)
                return;
            *x = piece;
            t->more++;
        }
    }
}

static void bin_count(const setup_job *J, const rtri *t, size_t *cnt)
{
    if (t->x0 > t->x1)
        return;
    int ts = J->ts, bx0 = t->x0 / ts, bx1 = t->x1 / ts, by1 = t->y1 / ts;
    for (int by = t->y0 / ts; by <= by1; by++)
        for (int bx = bx0; bx <= bx1; bx++)
            cnt[(size_t)by * (size_t)J->tiles_x + (size_t)bx]++;
}

static void setup_chunk(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    setup_job *J = ctx;
    const mesh *m = J->m;
    chunk_extra *X = &J->ex[chunk];
    size_t end = (chunk + 1) * J->csz < m->nt ? (chunk + 1) * J->csz : m->nt;
    for (size_t ti = chunk * J->csz; ti < end; ti++) {
        rtri *t = &J->t[ti];
        t->x0 = 1, t->x1 = 0, t->more = 0;
        const uint32_t *v = m->tri + 3 * ti;
        if (v[0] >= m->nv || v[1] >= m->nv || v[2] >= m->nv)
            continue;
        double sx[3], sy[3], z[3], wp[3][3];
        int ok = 1;
        for (int k = 0; k < 3; k++) {
            const float *p = m->pos + 3 * (size_t)v[k];
            wp[k][0] = p[0], wp[k][1] = p[1], wp[k][2] = p[2];
            if (camera_project(J->cam, J->w, J->h, wp[k], &sx[k], &sy[k], &z[k]) || z[k] <= J->zn ||
                !(fabs(sx[k]) < GUARD && fabs(sy[k]) < GUARD))
                ok = 0;
        }
        /* shading at the corners */
        double fn[3], e1[3], e2[3];
        for (int d = 0; d < 3; d++)
            e1[d] = wp[1][d] - wp[0][d], e2[d] = wp[2][d] - wp[0][d];
        fn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        fn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        fn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double fl = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
        float col[3][4];
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
                col[k][d] = (float)(c[d] * f);
            col[k][3] = c[3];
        }
        int opaque = col[0][3] >= 1 && col[1][3] >= 1 && col[2][3] >= 1;
        if (ok)
            make_tri(J, t, sx, sy, z, (const float(*)[4])col, opaque);
        else
            clip_tri(J, X, t, (const double(*)[3])wp, (const float(*)[4])col, opaque);
    }
    /* binning, part 1: how many of this chunk's triangles each tile lists */
    size_t *cnt = J->bins + chunk * J->ntiles, xi = 0;
    for (size_t ti = chunk * J->csz; ti < end; ti++) {
        const rtri *t = &J->t[ti];
        bin_count(J, t, cnt);
        for (int k = 0; k < t->more; k++)
            bin_count(J, &X->t[xi++], cnt);
    }
}

/* Binning, part 2: the chunk's triangles, in mesh order, into the slots
 * raster_render reserved for the chunk in each tile list (after those of
 * the chunks before it), so every list is in mesh order whatever the
 * thread count. */
static void bin_fill(const setup_job *J, const rtri *t, size_t *fill, uint32_t i)
{
    if (t->x0 > t->x1)
        return;
    int ts = J->ts, bx0 = t->x0 / ts, bx1 = t->x1 / ts, by1 = t->y1 / ts;
    for (int by = t->y0 / ts; by <= by1; by++)
        for (int bx = bx0; bx <= bx1; bx++)
            J->list[fill[(size_t)by * (size_t)J->tiles_x + (size_t)bx]++] = i;
}

static void fill_chunk(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    setup_job *J = ctx;
    size_t end = (chunk + 1) * J->csz < J->m->nt ? (chunk + 1) * J->csz : J->m->nt;
    size_t *fill = J->bins + chunk * J->ntiles, xi = J->m->nt + J->ex[chunk].base;
    for (size_t i = chunk * J->csz; i < end; i++) {
        const rtri *t = &J->t[i];
        bin_fill(J, t, fill, (uint32_t)i);
        for (int k = 0; k < t->more; k++, xi++) /* its pieces right after it */
            bin_fill(J, &J->t[xi], fill, (uint32_t)xi);
    }
}

typedef struct tile_job {
    const rtri *t;
    const uint32_t *list;
    const size_t *start;
    int tw, tiles_x, tile;
    image *im;
    const raster_opts *o;
    size_t first; /* the first tile drawn (a shard draws its bands of tiles only) */
    atomic_int oom; /* a tile could not get its buffers: the render fails */
} tile_job;

typedef struct zsort {
    double z;
    uint32_t i;
    size_t q; /* place in the tile list: mesh order, pieces after their triangle */
} zsort;

/* Back to front; at equal depth the later triangle first, so the earlier
 * one is blended last and shows in front, as the opaque depth test keeps
 * the earlier triangle at a tie. (Ties by ascending index put the later one
 * in front: a copy of a transparent patch at the same depth replaced it,
 * exactly where the interpolated alpha rounds to 1.) */
static int zsort_cmp(const void *pa, const void *pb)
{
    const zsort *a = pa, *b = pb;
    if (a->z != b->z)
        return a->z < b->z ? 1 : -1; /* far first */
    return (a->q < b->q) - (a->q > b->q);
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
    tile += J->first;
    int ts = J->tile, tx = (int)(tile % (size_t)J->tiles_x), ty = (int)(tile / (size_t)J->tiles_x);
    int x0 = tx * ts, y0 = ty * ts;
    int x1 = x0 + ts - 1 < J->im->w - 1 ? x0 + ts - 1 : J->im->w - 1;
    int y1 = y0 + ts - 1 < J->im->h - 1 ? y0 + ts - 1 : J->im->h - 1;
    size_t np = (size_t)ts * (size_t)ts;
    double *zb = rt_malloc(sizeof(double) * np);
    float *cb = rt_malloc(sizeof(float) * 4 * np);
    size_t n = J->start[tile + 1] - J->start[tile];
    zsort *zs = rt_malloc(sizeof(zsort) * (n ? n : 1));
    if (!zb || !cb || !zs) { /* reported by raster_render after the tiles */
        atomic_store(&J->oom, 1);
        rt_free(zb);
        rt_free(cb);
        rt_free(zs);
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
            zs[nt++] = (zsort){t->zmean, L[q], q};
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
    rt_free(zb);
    rt_free(cb);
    rt_free(zs);
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
    /* Sharded (par.h): the chunks are the bands of tiles_x tiles, ts image
     * rows each (the last one shorter); set-up and binning run in full in
     * every shard, a merge only places the bands. */
    par_part pp;
    size_t band = (size_t)ts * (size_t)im->w * 4 * sizeof *im->px;
    size_t all = (size_t)im->h * (size_t)im->w * 4 * sizeof *im->px;
    rt_code rc = par_part_begin(&pp, run, "rasterize", (size_t)tiles_y, e);
    if (rc || pp.mode == PAR_MERGE || pp.hi == pp.lo) /* nothing to draw here */
        return rc ? rc : par_part_rows(&pp, im->px, all, band, e);
    rtri *t = rt_malloc(sizeof *t * (m->nt ? m->nt : 1));
    size_t *start = rt_calloc(ntiles + 1, sizeof(size_t));
    uint32_t *list = NULL;
    size_t *bins = NULL;
    chunk_extra *ex = NULL;
    size_t nch = 0;
    if (!t || !start || m->nt >= UINT32_MAX) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory rasterising %zu triangles", m->nt);
        goto done;
    }
    /* chunks depend on the triangle and tile counts only, never on threads */
    nch = (m->nt + TRI_CHUNK - 1) / TRI_CHUNK;
    size_t maxch = MAX_BINS / (ntiles ? ntiles : 1);
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
    setup_job S = {m, cam, o, im->w, im->h, {0, 0, 0}, t, csz, NULL, NULL, ntiles, ts, tiles_x, NULL,
                   o->near > NEAR_MIN ? o->near : NEAR_MIN};
    bins = S.bins = rt_calloc(nch * ntiles + 1, sizeof(size_t));
    ex = S.ex = rt_calloc(nch ? nch : 1, sizeof *ex);
    if (!bins || !ex) {
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
    /* the clipped triangles' further pieces go after the mesh's, chunk by chunk */
    size_t nex = 0;
    for (size_t c = 0; c < nch; c++) {
        if (ex[c].oom) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory clipping %zu triangles", m->nt);
            goto done;
        }
        ex[c].base = nex;
        nex += ex[c].n;
    }
    if (nex) {
        rtri *t2 = nex < UINT32_MAX - m->nt ? rt_realloc(t, sizeof *t * (m->nt + nex)) : NULL;
        if (!t2) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory clipping %zu triangles", m->nt);
            goto done;
        }
        t = S.t = t2;
        for (size_t c = 0; c < nch; c++)
            if (ex[c].n)
                memcpy(t + m->nt + ex[c].base, ex[c].t, sizeof *t * ex[c].n);
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
    list = rt_malloc(sizeof(uint32_t) * (tot ? tot : 1));
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
    tile_job T = {t, list, start, im->w, tiles_x, ts, im, o, pp.lo * (size_t)tiles_x, 0};
    rc = par_for(run, "raster", (pp.hi - pp.lo) * (size_t)tiles_x, tile_fn, &T);
    if (rc)
        rt_fail(e, rc, "rasterising interrupted");
    else if (atomic_load(&T.oom))
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the rasteriser's tile buffers");
    else
        rc = par_part_rows(&pp, im->px, all, band, e);
done:
    for (size_t c = 0; ex && c < nch; c++)
        rt_free(ex[c].t);
    rt_free(ex);
    rt_free(bins);
    rt_free(t);
    rt_free(start);
    rt_free(list);
    return rc;
}
