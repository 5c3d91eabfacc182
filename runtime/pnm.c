/* pnm.c — P5/P6 (netpbm) and PF/Pf (Portable Float Map) reading and writing.
 * Not from the seed papers; formats as described in pnm.h. */
#include "pnm.h"
#include "rt_alloc.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "png.h"
#include "provenance.h"
#include "sample.h"

typedef struct hdr {
    const unsigned char *d;
    size_t n, pos;
    const char *what; /* "PGM", "PPM", "PFM" for messages */
    int ch;           /* 1 grey, 3 RGB */
    unsigned long w, ht;
} hdr;

static int is_space(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Skip whitespace and '#' comments; returns 1 if at least one byte skipped. */
static int skip_ws(hdr *h)
{
    size_t start = h->pos;
    while (h->pos < h->n) {
        unsigned char c = h->d[h->pos];
        if (is_space(c))
            h->pos++;
        else if (c == '#')
            while (h->pos < h->n && h->d[h->pos] != '\n' && h->d[h->pos] != '\r')
                h->pos++;
        else
            break;
    }
    return h->pos > start;
}

/* A header field: whitespace, then a decimal number in 1..max. */
static rt_code read_num(hdr *h, const char *field, unsigned long max, unsigned long *v,
                        rt_error *e)
{
    int skipped = skip_ws(h);
    if (h->pos >= h->n)
        return rt_fail(e, RT_EFORMAT, "%s header is truncated (no %s)", h->what, field);
    if (!skipped)
        return rt_fail(e, RT_EFORMAT, "%s header: expected whitespace before the %s", h->what,
                       field);
    if (h->d[h->pos] < '0' || h->d[h->pos] > '9')
        return rt_fail(e, RT_EFORMAT, "%s header: expected the %s, found '%c'", h->what, field,
                       h->d[h->pos] >= 32 && h->d[h->pos] < 127 ? h->d[h->pos] : '?');
    unsigned long x = 0;
    while (h->pos < h->n && h->d[h->pos] >= '0' && h->d[h->pos] <= '9') {
        x = x * 10 + (unsigned long)(h->d[h->pos++] - '0');
        if (x > max)
            return rt_fail(e, RT_EFORMAT, "%s %s is out of range (expected 1..%lu)", h->what,
                           field, max);
    }
    if (x == 0)
        return rt_fail(e, RT_EFORMAT, "%s %s is 0 (expected 1..%lu)", h->what, field, max);
    *v = x;
    return RT_OK;
}

/* The single whitespace byte that ends a header. */
static rt_code end_header(hdr *h, rt_error *e)
{
    if (h->pos >= h->n || !is_space(h->d[h->pos]))
        return rt_fail(e, RT_EFORMAT, "%s header must end with one whitespace byte", h->what);
    h->pos++;
    return RT_OK;
}

/* The start every netpbm-style header shares: 'P', a kind byte (kinds[0]
 * gives 1 channel, kinds[1] 3), the width and the height; im is empty until
 * start_data. */
static rt_code read_head(image *im, const unsigned char *d, size_t n, const char kinds[2], const char *what1,
                         const char *what3, const char *not_msg, hdr *h, rt_error *e)
{
    im->w = im->h = 0;
    im->px = NULL;
    im->src = NULL;
    if (n < 2 || d[0] != 'P' || (d[1] != kinds[0] && d[1] != kinds[1]))
        return rt_fail(e, RT_EFORMAT, "%s", not_msg);
    int ch = d[1] == kinds[0] ? 1 : 3;
    *h = (hdr){d, n, 2, ch == 1 ? what1 : what3, ch, 0, 0};
    rt_code c = read_num(h, "width", INT_MAX, &h->w, e);
    return c ? c : read_num(h, "height", INT_MAX, &h->ht, e);
}

/* The end every header shares: the one whitespace byte, then room for the
 * samples (bps bytes each) and the image. */
static rt_code start_data(hdr *h, size_t bps, image *im, rt_error *e)
{
    unsigned long w = h->w, ht = h->ht;
    int channels = h->ch;
    rt_code c = end_header(h, e);
    if (c)
        return c;
    size_t k = rt_mul_size(rt_mul_size(rt_mul_size((size_t)w, (size_t)ht), (size_t)channels), bps);
    if (k == 0)
        return rt_fail(e, RT_EFORMAT, "%s size %d×%d is too large", h->what, (int)w, (int)ht);
    if (h->n - h->pos < k)
        return rt_fail(e, RT_EFORMAT, "%s data are truncated (%zu of %zu bytes)", h->what, h->n - h->pos, k);
    if ((c = rt_check_pixels((double)w, (double)ht, e)))
        return c;
    return image_init(im, (int)w, (int)ht, e);
}

/* ---------------------------------------------------------------- P5/P6 */

rt_code pnm_encode(const image *im, int bits, int channels, bytebuf *out, rt_error *e)
{
    image_ready(im);
    if (bits != 8 && bits != 16)
        return rt_fail(e, RT_EINVAL, "PGM/PPM bit depth %d is invalid (expected 8 or 16)", bits);
    if (channels != 1 && channels != 3)
        return rt_fail(e, RT_EINVAL, "PGM/PPM channels %d is invalid (expected 1 or 3)",
                       channels);
    unsigned maxval = bits == 16 ? 65535 : 255;
    bytebuf_printf(out, "P%c\n", channels == 1 ? '5' : '6');
    prov_put_lines(out, "# "); /* the recipe, as header comments */
    bytebuf_printf(out, "%d %d\n%u\n", im->w, im->h, maxval);
    size_t rb = (size_t)im->w * (size_t)channels * (size_t)(bits / 8);
    unsigned char *row = rt_malloc(rb ? rb : 1);
    if (!row)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a %d×%d image", im->w, im->h);
    for (int y = 0; y < im->h; y++) {
        unsigned char *o = row;
        for (int x = 0; x < im->w; x++) {
            const float *p = image_at(im, x, y);
            float v[3] = {p[0], p[1], p[2]};
            if (channels == 1)
                v[0] = png_luma(p);
            for (int k = 0; k < channels; k++) {
                unsigned q = png_sample(v[k], maxval);
                if (bits == 16)
                    *o++ = (unsigned char)(q >> 8);
                *o++ = (unsigned char)q;
            }
        }
        bytebuf_append(out, row, rb);
    }
    rt_free(row);
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a %d×%d image", im->w, im->h);
    return RT_OK;
}

rt_code pnm_decode(const unsigned char *d, size_t n, image *im, pnm_info *info, rt_error *e)
{
    hdr h;
    unsigned long maxval;
    rt_code c;
    const char *not_msg = "not a binary PGM/PPM file (expected 'P5' or 'P6')";
    if ((c = read_head(im, d, n, "56", "PGM", "PPM", not_msg, &h, e)) ||
        (c = read_num(&h, "maxval", 65535, &maxval, e)))
        return c;
    size_t bps = maxval < 256 ? 1 : 2;
    if ((c = start_data(&h, bps, im, e)))
        return c;
    const int ch = h.ch;
    const unsigned long w = h.w, ht = h.ht;
    const unsigned char *s = d + h.pos;
    size_t np = (size_t)w * (size_t)ht;
    double mv = (double)maxval;
    for (size_t i = 0; i < np; i++) {
        float *o = im->px + 4 * i;
        for (int k = 0; k < ch; k++) {
            unsigned v = bps == 1 ? s[0] : (unsigned)s[0] << 8 | s[1];
            s += bps;
            if (v > maxval) {
                rt_code r = rt_fail(e, RT_EFORMAT,
                                    "%s sample value %u at pixel (%zu, %zu) exceeds maxval %lu",
                                    h.what, v, i % w, i / w, maxval);
                image_free(im);
                return r;
            }
            o[k] = (float)(v / mv);
        }
        if (ch == 1)
            o[1] = o[2] = o[0];
        o[3] = 1.0f;
    }
    if (info)
        *info = (pnm_info){(int)w, (int)ht, ch, (unsigned)maxval, 0};
    return RT_OK;
}

/* ------------------------------------------------------------------ PFM */

rt_code pfm_encode(const image *im, int channels, bytebuf *out, rt_error *e)
{
    image_ready(im);
    if (channels != 1 && channels != 3)
        return rt_fail(e, RT_EINVAL, "PFM channels %d is invalid (expected 1 or 3)", channels);
    bytebuf_printf(out, "P%c\n%d %d\n-1.0\n", channels == 1 ? 'f' : 'F', im->w, im->h);
    for (int y = im->h - 1; y >= 0; y--) /* bottom row first */
        for (int x = 0; x < im->w; x++) {
            const float *p = image_at(im, x, y);
            if (channels == 1)
                bytebuf_f32le(out, png_luma(p));
            else
                for (int k = 0; k < 3; k++)
                    bytebuf_f32le(out, p[k]);
        }
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a %d×%d PFM", im->w, im->h);
    return RT_OK;
}

rt_code pfm_decode(const unsigned char *d, size_t n, image *im, pnm_info *info, rt_error *e)
{
    hdr h;
    rt_code c;
    if ((c = read_head(im, d, n, "fF", "PFM", "PFM", "not a PFM file (expected 'PF' or 'Pf')", &h, e)))
        return c;
    if (!skip_ws(&h) || h.pos >= h.n)
        return rt_fail(e, RT_EFORMAT, "PFM header is truncated (no scale)");
    char tok[64];
    size_t k = 0;
    while (h.pos < h.n && !is_space(h.d[h.pos])) {
        if (k + 1 >= sizeof tok)
            return rt_fail(e, RT_EFORMAT, "PFM scale is too long");
        tok[k++] = (char)h.d[h.pos++];
    }
    tok[k] = 0;
    char *end;
    double scale = strtod(tok, &end);
    if (end == tok || *end || !(scale != 0) || !isfinite(scale))
        return rt_fail(e, RT_EFORMAT, "PFM scale '%s' is not a non-zero number", tok);
    if ((c = start_data(&h, 4, im, e)))
        return c;
    const int ch = h.ch, le = scale < 0;
    const unsigned long w = h.w, ht = h.ht;
    const unsigned char *s = d + h.pos;
    for (int y = (int)ht - 1; y >= 0; y--)
        for (int x = 0; x < (int)w; x++) {
            float *o = image_at(im, x, y);
            for (int j = 0; j < ch; j++, s += 4) {
                sample_f32(s, !le, &o[j]);
            }
            if (ch == 1)
                o[1] = o[2] = o[0];
            o[3] = 1.0f;
        }
    if (info)
        *info = (pnm_info){(int)w, (int)ht, ch, 0, le};
    return RT_OK;
}
