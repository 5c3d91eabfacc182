/* draw.c — coverage-based antialiased strokes, discs and even–odd fills,
 * and byte-stable SVG (seed 003 Fig. 1, 3: drawing K_n). */
#include "draw.h"
#include "rt_alloc.h"
#include "provenance.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

rt_code draw_view_fit(draw_view *v, int w, int h, const double lo[2], const double hi[2],
                      int keep_aspect, rt_error *e)
{
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "view size %d×%d is empty", w, h);
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1];
    if (!(dx > 0) || !(dy > 0) || !isfinite(dx) || !isfinite(dy))
        return rt_fail(e, RT_EINVAL,
                       "view window [%g, %g]×[%g, %g] is empty (expected lo < hi on both axes)",
                       lo[0], hi[0], lo[1], hi[1]);
    v->w = w;
    v->h = h;
    v->sx = w / dx;
    v->sy = h / dy;
    if (keep_aspect) {
        double s = v->sx < v->sy ? v->sx : v->sy;
        v->sx = v->sy = s;
    }
    /* Centre the window: its middle maps to the image middle. */
    v->ox = 0.5 * w - v->sx * 0.5 * (lo[0] + hi[0]);
    v->oy = 0.5 * h + v->sy * 0.5 * (lo[1] + hi[1]);
    return RT_OK;
}

void draw_clear(image *im, const float rgba[4])
{
    size_t n = (size_t)im->w * (size_t)im->h;
    for (size_t i = 0; i < n; i++)
        memcpy(im->px + 4 * i, rgba, 4 * sizeof(float));
}

static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }

static void cov_max(float *cov, int w, int x, int y, double c)
{
    float f = (float)c;
    float *p = &cov[(size_t)y * (size_t)w + (size_t)x];
    if (f > *p)
        *p = f;
}

/* Coverage of one segment into cov (max). With col, a pixel whose coverage
 * the segment raises also takes the segment's colour c (draw_polyline_rgba). */
static void stroke_segment(float *cov, float *col, const float c[4], int w, int h, double ax, double ay, double bx,
                           double by, double hw)
{
    double r = hw + 0.5;
    int x0 = (int)floor(fmin(ax, bx) - r), x1 = (int)ceil(fmax(ax, bx) + r);
    int y0 = (int)floor(fmin(ay, by) - r), y1 = (int)ceil(fmax(ay, by) + r);
    if (x1 < 0 || y1 < 0 || x0 >= w || y0 >= h || !isfinite(ax + ay + bx + by))
        return;
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    x1 = x1 >= w ? w - 1 : x1;
    y1 = y1 >= h ? h - 1 : y1;
    double dx = bx - ax, dy = by - ay, ll = dx * dx + dy * dy;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double cx = x + 0.5 - ax, cy = y + 0.5 - ay;
            double t = ll > 0 ? clamp01((cx * dx + cy * dy) / ll) : 0;
            double ex = cx - t * dx, ey = cy - t * dy;
            double k = clamp01(r - sqrt(ex * ex + ey * ey));
            size_t id = (size_t)y * (size_t)w + (size_t)x;
            if (!col) {
                if (k > 0)
                    cov_max(cov, w, x, y, k);
            } else if (k > cov[id]) { /* compared in double: the winner as it always was */
                cov[id] = (float)k;
                memcpy(col + 4 * id, c, 4 * sizeof *c);
            }
        }
}

typedef struct xsort {
    double *x;
    size_t n, cap;
} xsort;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Even–odd fill of one polygon (pixel coordinates px[2n]). */
static int fill_polygon(float *cov, int w, int h, const double *px, size_t n, xsort *xs)
{
    double ylo = INFINITY, yhi = -INFINITY, xlo = INFINITY, xhi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        xlo = fmin(xlo, px[2 * i]);
        xhi = fmax(xhi, px[2 * i]);
        ylo = fmin(ylo, px[2 * i + 1]);
        yhi = fmax(yhi, px[2 * i + 1]);
    }
    if (!isfinite(xlo + xhi + ylo + yhi) || xhi < 0 || yhi < 0 || xlo >= w || ylo >= h)
        return 0;
    int bx0 = xlo < 0 ? 0 : (int)xlo, bx1 = xhi >= w ? w - 1 : (int)xhi;
    int by0 = ylo < 0 ? 0 : (int)ylo, by1 = yhi >= h ? h - 1 : (int)yhi;
    int bw = bx1 - bx0 + 1;
    double *row = rt_malloc((size_t)bw * sizeof *row);
    if (!row)
        return -1;
    if (xs->cap < n) {
        double *nx = rt_realloc(xs->x, n * sizeof *nx);
        if (!nx) {
            rt_free(row);
            return -1;
        }
        xs->x = nx;
        xs->cap = n;
    }
    for (int y = by0; y <= by1; y++) {
        for (int i = 0; i < bw; i++)
            row[i] = 0;
        for (int sub = 0; sub < 4; sub++) {
            double sy = y + 0.125 + 0.25 * sub;
            xs->n = 0;
            for (size_t i = 0; i < n; i++) {
                size_t j = i + 1 < n ? i + 1 : 0;
                double ay = px[2 * i + 1], by = px[2 * j + 1];
                /* Half-open rule: an edge counts if sy is in [min, max). */
                if ((ay <= sy && sy < by) || (by <= sy && sy < ay)) {
                    double t = (sy - ay) / (by - ay);
                    xs->x[xs->n++] = px[2 * i] + t * (px[2 * j] - px[2 * i]);
                }
            }
            qsort(xs->x, xs->n, sizeof *xs->x, cmp_double);
            for (size_t k = 0; k + 1 < xs->n; k += 2) {
                double xa = fmax(xs->x[k], bx0), xb = fmin(xs->x[k + 1], bx1 + 1.0);
                for (int x = (int)floor(xa); x < bx1 + 1 && x < xb; x++) {
                    double o = fmin(xb, x + 1.0) - fmax(xa, (double)x);
                    if (o > 0)
                        row[x - bx0] += 0.25 * o;
                }
            }
        }
        for (int i = 0; i < bw; i++)
            if (row[i] > 0)
                cov_max(cov, w, bx0 + i, y, row[i] > 1 ? 1 : row[i]);
    }
    rt_free(row);
    return 0;
}

rt_code draw_shape(image *im, const draw_view *v, const detiter_shape *s, const draw_style *st,
                   rt_error *e)
{
    if (v->w != im->w || v->h != im->h)
        return rt_fail(e, RT_EINVAL, "view is %d×%d but the image is %d×%d", v->w, v->h, im->w,
                       im->h);
    if (!(st->width >= 0) || !(st->radius >= 0))
        return rt_fail(e, RT_EINVAL, "line width %g and point radius %g must be >= 0", st->width,
                       st->radius);
    int w = im->w, h = im->h, d = s->dim;
    float *cov = rt_calloc((size_t)w * (size_t)h, sizeof *cov);
    xsort xs = {NULL, 0, 0};
    double *poly = NULL;
    size_t polycap = 0;
    rt_code code = RT_OK;
    if (!cov)
        return rt_fail(e, RT_ENOMEM, "out of memory for a %d×%d coverage buffer", w, h);
    for (size_t p = 0; p < s->npoly; p++) {
        size_t a = s->start[p], b = s->start[p + 1], n = b - a;
        if (n == 0)
            continue;
        if (polycap < n) {
            double *np = rt_realloc(poly, 2 * n * sizeof *np);
            if (!np) {
                code = rt_fail(e, RT_ENOMEM, "out of memory drawing a polyline of %zu vertices", n);
                goto done;
            }
            poly = np;
            polycap = n;
        }
        for (size_t i = 0; i < n; i++)
            draw_to_px(v, s->v[(a + i) * (size_t)d], s->v[(a + i) * (size_t)d + 1], &poly[2 * i],
                       &poly[2 * i + 1]);
        if (n == 1) {
            if (st->radius > 0)
                stroke_segment(cov, NULL, NULL, w, h, poly[0], poly[1], poly[0], poly[1], st->radius - 0.5);
            continue;
        }
        if (st->fill && s->closed[p] && n >= 3 && fill_polygon(cov, w, h, poly, n, &xs) < 0) {
            code = rt_fail(e, RT_ENOMEM, "out of memory filling a polygon");
            goto done;
        }
        if (st->width > 0) {
            size_t last = s->closed[p] ? n : n - 1;
            for (size_t i = 0; i < last; i++) {
                size_t j = i + 1 < n ? i + 1 : 0;
                stroke_segment(cov, NULL, NULL, w, h, poly[2 * i], poly[2 * i + 1], poly[2 * j],
                               poly[2 * j + 1], 0.5 * st->width);
            }
        }
    }
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        if (cov[i] <= 0)
            continue;
        float al = st->color[3] * cov[i];
        float *px = im->px + 4 * i;
        for (int c = 0; c < 3; c++)
            px[c] = px[c] * (1 - al) + st->color[c] * al;
        px[3] = px[3] + (1 - px[3]) * al;
    }
done:
    rt_free(cov);
    rt_free(xs.x);
    rt_free(poly);
    return code;
}

rt_code draw_polyline_rgba(image *im, const draw_view *v, size_t n, const double *xy, const float *rgba, int closed,
                           double width, rt_error *e)
{
    if (v->w != im->w || v->h != im->h)
        return rt_fail(e, RT_EINVAL, "view is %d×%d but the image is %d×%d", v->w, v->h, im->w, im->h);
    if (!(width >= 0))
        return rt_fail(e, RT_EINVAL, "line width %g must be >= 0", width);
    size_t np = (size_t)im->w * (size_t)im->h;
    float *cov = rt_calloc(np, sizeof *cov);
    float *col = rt_calloc(np, 4 * sizeof *col);
    if (!cov || !col) {
        rt_free(cov);
        rt_free(col);
        return rt_fail(e, RT_ENOMEM, "out of memory drawing a curve");
    }
    size_t nseg = n < 2 ? 0 : closed ? n : n - 1;
    for (size_t s = 0; s < nseg; s++) {
        size_t i = s, j = (s + 1) % n;
        double ax, ay, bx, by;
        draw_to_px(v, xy[2 * i], xy[2 * i + 1], &ax, &ay);
        draw_to_px(v, xy[2 * j], xy[2 * j + 1], &bx, &by);
        float c[4];
        for (int q = 0; q < 4; q++)
            c[q] = 0.5f * (rgba[4 * i + q] + rgba[4 * j + q]);
        stroke_segment(cov, col, c, im->w, im->h, ax, ay, bx, by, width / 2);
    }
    for (size_t id = 0; id < np; id++) {
        if (cov[id] <= 0)
            continue;
        float *p = im->px + 4 * id, *c = col + 4 * id;
        float k = (float)clamp01(c[3]) * cov[id];
        for (int q = 0; q < 3; q++)
            p[q] = p[q] * (1 - k) + c[q] * k;
        p[3] = p[3] + (1 - p[3]) * k;
    }
    rt_free(cov);
    rt_free(col);
    return RT_OK;
}

/* ---- SVG ------------------------------------------------------------- */

static void put_num(bytebuf *b, double x, int prec)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%.*f", prec, x);
    /* "-0.000" → "0.000": the sign of zero is not a visible difference. */
    if (buf[0] == '-') {
        int zero = 1;
        for (const char *c = buf + 1; *c; c++)
            zero &= *c == '0' || *c == '.';
        if (zero) {
            bytebuf_printf(b, "%s", buf + 1);
            return;
        }
    }
    bytebuf_printf(b, "%s", buf);
}

static void put_colour(bytebuf *b, const char *attr, const float c[4])
{
    int v[3];
    for (int i = 0; i < 3; i++)
        v[i] = (int)lround(clamp01(c[i]) * 255);
    bytebuf_printf(b, " %s=\"#%02x%02x%02x\"", attr, v[0], v[1], v[2]);
    if (c[3] < 1)
        bytebuf_printf(b, " %s-opacity=\"%.3f\"", attr, clamp01(c[3]));
}

rt_code draw_svg(bytebuf *b, const draw_view *v, const detiter_shape *s, const draw_style *st,
                 const float *bg, int precision, rt_error *e)
{
    return draw_svg_fill(b, v, s, st, NULL, bg, precision, e);
}

rt_code draw_svg_fill(bytebuf *b, const draw_view *v, const detiter_shape *s, const draw_style *st,
                      const float *fill_rgba, const float *bg, int precision, rt_error *e)
{
    if (precision < 0 || precision > 9)
        return rt_fail(e, RT_EINVAL, "SVG precision %d (expected 0 to 9)", precision);
    int d = s->dim;
    bytebuf_printf(b,
                   "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    prov_put_xml_comment(b);
    bytebuf_printf(b,
                   "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
                   "viewBox=\"0 0 %d %d\">\n",
                   v->w, v->h, v->w, v->h);
    if (bg) {
        bytebuf_printf(b, "<rect width=\"%d\" height=\"%d\"", v->w, v->h);
        put_colour(b, "fill", bg);
        bytebuf_printf(b, "/>\n");
    }
    bytebuf_printf(b, "<g");
    const float *fillc = fill_rgba ? fill_rgba : st->color;
    if (st->fill)
        put_colour(b, "fill", fillc);
    else
        bytebuf_printf(b, " fill=\"none\"");
    if (st->width > 0) {
        put_colour(b, "stroke", st->color);
        bytebuf_printf(b, " stroke-width=\"");
        put_num(b, st->width, precision);
        bytebuf_printf(b, "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"");
    }
    bytebuf_printf(b, ">\n");
    for (size_t p = 0; p < s->npoly; p++) {
        size_t a = s->start[p], n = s->start[p + 1] - a;
        double x, y;
        if (n == 0)
            continue;
        if (n == 1) {
            draw_to_px(v, s->v[a * (size_t)d], s->v[a * (size_t)d + 1], &x, &y);
            bytebuf_printf(b, "<circle cx=\"");
            put_num(b, x, precision);
            bytebuf_printf(b, "\" cy=\"");
            put_num(b, y, precision);
            bytebuf_printf(b, "\" r=\"");
            put_num(b, st->radius, precision);
            bytebuf_printf(b, "\"");
            /* points are discs of the stroke colour, as draw() paints them
             * over the fill (without a stroke, of the fill colour) */
            if (!st->fill || (fillc != st->color && st->width > 0))
                put_colour(b, "fill", st->color);
            bytebuf_printf(b, "/>\n");
            continue;
        }
        bytebuf_printf(b, "<%s points=\"", s->closed[p] ? "polygon" : "polyline");
        for (size_t i = 0; i < n; i++) {
            draw_to_px(v, s->v[(a + i) * (size_t)d], s->v[(a + i) * (size_t)d + 1], &x, &y);
            if (i)
                bytebuf_byte(b, ' ');
            put_num(b, x, precision);
            bytebuf_byte(b, ',');
            put_num(b, y, precision);
        }
        bytebuf_printf(b, "\"/>\n");
    }
    bytebuf_printf(b, "</g>\n</svg>\n");
    if (b->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing SVG");
    return RT_OK;
}
