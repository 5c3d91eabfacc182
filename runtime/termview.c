/* termview.c — image preview as 24-bit colour half blocks or greyscale text.
 *
 * Terminal machinery, not from a paper. The half-block technique (two
 * pixels per cell: foreground colour for the upper half via U+2580, the
 * background colour for the lower half) and the SGR 38;2 / 48;2 true-colour
 * codes are the common xterm practice; the luminance weights are Rec. 709.
 */
#define _POSIX_C_SOURCE 200809L
#include "termview.h"
#include "rt_alloc.h"

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char RAMP[] = " .:-=+*#%@"; /* 10 levels, dark to light */

int termview_env_color(const char *no_color, const char *term)
{
    if (no_color && no_color[0])
        return 0;
    if (!term || !term[0] || strcmp(term, "dumb") == 0)
        return 0;
    return 1;
}

/* round(h * cols / w), halves up, at least 1 */
static int64_t rows_for(int64_t w, int64_t h, int64_t cols)
{
    int64_t p = (2 * h * cols + w) / (2 * w);
    return p < 1 ? 1 : p;
}

void termview_size(int w, int h, const termview_opts *o, int *cols, int *pixel_rows)
{
    int64_t c = o->cols, p;
    if (w < 1 || h < 1 || c < 1) {
        *cols = *pixel_rows = 0;
        return;
    }
    p = rows_for(w, h, c);
    if (o->max_rows > 0 && (p + 1) / 2 > o->max_rows) {
        c = (int64_t)2 * o->max_rows * w / h;
        if (c < 1)
            c = 1;
        if (c > o->cols)
            c = o->cols;
        p = rows_for(w, h, c);
        if ((p + 1) / 2 > o->max_rows)
            p = (int64_t)2 * o->max_rows;
    }
    *cols = (int)c;
    *pixel_rows = (int)p;
}

static double clamp01(float v)
{
    /* NaN fails both comparisons below and is mapped to 0 */
    if (!(v > 0.0f))
        return 0.0;
    return v < 1.0f ? (double)v : 1.0;
}

/* Source coverage of one output interval: output index o of n spans
 * [o * src, (o + 1) * src) and source index s spans [s * n, (s + 1) * n) in
 * the same integer units; the weight of s is the overlap length. */
typedef struct span {
    int first, count; /* source indices first .. first + count - 1 */
    int64_t *wt;      /* count weights, summing to src */
} span;

static void span_make(span *sp, int64_t *wt, int o, int n, int src)
{
    int64_t a = (int64_t)o * src, b = a + src;
    int s0 = (int)(a / n), s1 = (int)((b + n - 1) / n); /* [s0, s1) */
    sp->first = s0;
    sp->count = s1 - s0;
    sp->wt = wt;
    for (int s = s0; s < s1; s++) {
        int64_t lo = (int64_t)s * n, hi = lo + n;
        if (lo < a)
            lo = a;
        if (hi > b)
            hi = b;
        wt[s - s0] = hi - lo;
    }
}

/* Mean composited colour of output pixel (sx span, sy span). */
static void box_mean(const image *im, const span *xs, const span *ys, const double bg[3], double out[3])
{
    double acc[3] = {0, 0, 0};
    for (int j = 0; j < ys->count; j++) {
        const float *row = image_at(im, 0, ys->first + j);
        double wy = (double)ys->wt[j];
        for (int i = 0; i < xs->count; i++) {
            const float *p = row + (size_t)(xs->first + i) * 4;
            double a = clamp01(p[3]), wgt = wy * (double)xs->wt[i];
            for (int k = 0; k < 3; k++)
                acc[k] += wgt * (a * clamp01(p[k]) + (1.0 - a) * bg[k]);
        }
    }
    double total = (double)im->w * (double)im->h; /* weights sum to w in x, h in y */
    for (int k = 0; k < 3; k++) {
        double v = acc[k] / total;
        out[k] = v < 0 ? 0 : v > 1 ? 1 : v;
    }
}

static int to8(double v) { return (int)(v * 255.0 + 0.5); }

static double luma(const double c[3]) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

rt_code termview_render(const image *im, const termview_opts *o, bytebuf *out, rt_error *e)
{
    if (!im || !im->px || im->w < 1 || im->h < 1)
        return rt_fail(e, RT_EINVAL, "preview: the image is empty");
    if (o->cols < 1)
        return rt_fail(e, RT_EINVAL, "preview: width must be at least 1 column (got %d)", o->cols);
    if (o->max_rows < 0)
        return rt_fail(e, RT_EINVAL, "preview: max_rows must be 0 (no limit) or more (got %d)", o->max_rows);
    int cols, prow;
    termview_size(im->w, im->h, o, &cols, &prow);
    double bg[3];
    for (int k = 0; k < 3; k++)
        bg[k] = clamp01(o->bg[k]);

    /* x spans are the same for every row: build them once */
    size_t xw = 0;
    for (int c = 0; c < cols; c++) {
        int64_t a = (int64_t)c * im->w, b = a + im->w;
        xw += (size_t)((b + cols - 1) / cols - a / cols);
    }
    span *xs = rt_malloc((size_t)cols * sizeof *xs);
    int64_t *xwt = rt_malloc(xw * sizeof *xwt);
    int64_t *ywt = rt_malloc((size_t)(2 * ((int64_t)im->h / prow + 2)) * sizeof *ywt);
    double *up = rt_malloc((size_t)cols * 3 * sizeof *up), *lo = rt_malloc((size_t)cols * 3 * sizeof *lo);
    rt_code rc = RT_OK;
    if (!xs || !xwt || !ywt || !up || !lo) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the preview");
        goto done;
    }
    for (int c = 0, off = 0; c < cols; c++) {
        span_make(&xs[c], xwt + off, c, cols, im->w);
        off += xs[c].count;
    }
    for (int r = 0; 2 * r < prow; r++) {
        span ys;
        for (int c = 0; c < cols; c++) {
            span_make(&ys, ywt, 2 * r, prow, im->h);
            box_mean(im, &xs[c], &ys, bg, up + 3 * c);
            if (2 * r + 1 < prow) {
                span_make(&ys, ywt, 2 * r + 1, prow, im->h);
                box_mean(im, &xs[c], &ys, bg, lo + 3 * c);
            } else { /* odd number of pixel rows: pad with the background */
                memcpy(lo + 3 * c, bg, sizeof bg);
            }
        }
        if (o->color) {
            int pf[3] = {-1, -1, -1}, pb[3] = {-1, -1, -1};
            for (int c = 0; c < cols; c++) {
                int f[3], b[3];
                for (int k = 0; k < 3; k++) {
                    f[k] = to8(up[3 * c + k]);
                    b[k] = to8(lo[3 * c + k]);
                }
                if (memcmp(f, pf, sizeof f) != 0)
                    bytebuf_printf(out, "\x1b[38;2;%d;%d;%dm", f[0], f[1], f[2]);
                if (memcmp(b, pb, sizeof b) != 0)
                    bytebuf_printf(out, "\x1b[48;2;%d;%d;%dm", b[0], b[1], b[2]);
                bytebuf_append(out, "\xe2\x96\x80", 3); /* U+2580 */
                memcpy(pf, f, sizeof f);
                memcpy(pb, b, sizeof b);
            }
            bytebuf_append(out, "\x1b[0m\n", 5);
        } else {
            for (int c = 0; c < cols; c++) {
                double y = 0.5 * (luma(up + 3 * c) + luma(lo + 3 * c));
                int i = (int)(y * 9.0 + 0.5);
                bytebuf_byte(out, (unsigned char)RAMP[i < 0 ? 0 : i > 9 ? 9 : i]);
            }
            bytebuf_byte(out, '\n');
        }
    }
    if (out->failed)
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the preview");
done:
    rt_free(xs);
    rt_free(xwt);
    rt_free(ywt);
    rt_free(up);
    rt_free(lo);
    return rc;
}

rt_code termview_write(int fd, const image *im, const termview_opts *o, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code rc = termview_render(im, o, &b, e);
    size_t done = 0;
    while (rc == RT_OK && done < b.len) {
        ssize_t w = write(fd, b.data + done, b.len - done);
        if (w < 0) {
            if (errno == EINTR || errno == EAGAIN)
                continue;
            rc = rt_fail(e, RT_EIO, "preview: cannot write to the terminal: %s", strerror(errno));
        } else {
            done += (size_t)w;
        }
    }
    bytebuf_free(&b);
    return rc;
}
