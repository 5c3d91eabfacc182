/* apng.c — animated PNG writer (APNG 1.0 specification; layout in apng.h). */
#include "apng.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "deflate.h"
#include "png.h"
#include "rt_alloc.h"

/* What one input PNG contributes: its IHDR, PLTE and tRNS, and its image
 * data (the IDAT chunks' bytes, concatenated). */
typedef struct pngparts {
    const unsigned char *ihdr; /* 13 bytes */
    const unsigned char *plte, *trns;
    uint32_t nplte, ntrns;
    bytebuf data;
} pngparts;

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static const char *frame_name(const char *const *names, int i, char *buf, size_t n)
{
    if (names && names[i])
        return names[i];
    snprintf(buf, n, "frame %d", i + 1);
    return buf;
}

/* Check that the PNG decodes (CRCs, zlib data, sizes: png_decode's checks)
 * and pick out its chunks. */
static rt_code split_png(const unsigned char *d, size_t n, const char *name, pngparts *p, rt_error *e)
{
    memset(p, 0, sizeof *p);
    bytebuf_init(&p->data);
    image im;
    png_info info;
    rt_code c = png_decode(d, n, &im, &info, e);
    if (c) {
        char why[sizeof e->msg];
        snprintf(why, sizeof why, "%s", e->msg);
        return rt_fail(e, c, "%s: %s", name, why);
    }
    image_free(&im);
    /* png_decode accepted it: the chunk structure is sound */
    for (size_t pos = 8; pos + 12 <= n;) {
        uint32_t len = be32(d + pos);
        const unsigned char *type = d + pos + 4, *body = d + pos + 8;
        if (!memcmp(type, "IHDR", 4))
            p->ihdr = body;
        else if (!memcmp(type, "PLTE", 4))
            p->plte = body, p->nplte = len;
        else if (!memcmp(type, "tRNS", 4))
            p->trns = body, p->ntrns = len;
        else if (!memcmp(type, "IDAT", 4))
            bytebuf_append(&p->data, body, len);
        else if (!memcmp(type, "IEND", 4))
            break;
        pos += 12 + (size_t)len;
    }
    if (p->data.failed) {
        bytebuf_free(&p->data);
        return rt_fail(e, RT_ENOMEM, "out of memory reading %s", name);
    }
    return RT_OK;
}

static void describe(const unsigned char *ihdr, char *buf, size_t n)
{
    static const char *const kinds[7] = {"grey", "?", "RGB", "palette", "grey+alpha", "?", "RGBA"};
    unsigned ct = ihdr[9] < 7 ? ihdr[9] : 1;
    snprintf(buf, n, "%u-bit %s%s %u×%u", ihdr[8], kinds[ct], ihdr[12] ? " interlaced" : "", (unsigned)be32(ihdr),
             (unsigned)be32(ihdr + 4));
}

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24), p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8), p[3] = (unsigned char)v;
}

/* fcTL (APNG §4.2): the whole canvas at (0, 0), no disposal, source blend */
static void put_fctl(bytebuf *out, uint32_t *seq, const unsigned char *ihdr, const apng_opts *o)
{
    unsigned char f[26];
    put_u32(f, (*seq)++);
    memcpy(f + 4, ihdr, 8); /* width, height */
    put_u32(f + 12, 0);     /* x_offset */
    put_u32(f + 16, 0);     /* y_offset */
    f[20] = (unsigned char)(o->delay_ms >> 8), f[21] = (unsigned char)o->delay_ms; /* delay_num */
    f[22] = 1000 >> 8, f[23] = 1000 & 255;                                        /* delay_den */
    f[24] = 0; /* dispose_op: APNG_DISPOSE_OP_NONE */
    f[25] = 0; /* blend_op: APNG_BLEND_OP_SOURCE */
    png_write_chunk(out, "fcTL", f, sizeof f);
}

rt_code apng_assemble(const unsigned char *const *pngs, const size_t *lens, int n, const char *const *names,
                      const apng_opts *o, bytebuf *out, rt_error *e)
{
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "an animated PNG needs at least one frame");
    if (o->delay_ms < 0 || o->delay_ms > APNG_MAX_DELAY_MS)
        return rt_fail(e, RT_EINVAL, "APNG frame delay %d ms is out of range (0 to %d)", o->delay_ms,
                       APNG_MAX_DELAY_MS);
    if (o->loop < 0 || o->loop > APNG_MAX_LOOP)
        return rt_fail(e, RT_EINVAL, "APNG loop count %ld is out of range (0 to %d)", o->loop, APNG_MAX_LOOP);
    pngparts *p = rt_calloc((size_t)n, sizeof *p);
    if (!p)
        return rt_fail(e, RT_ENOMEM, "out of memory assembling %d frames", n);
    rt_code c = RT_OK;
    int done = 0;
    char nb0[32], nb1[32], d0[96], d1[96];
    for (; done < n && !c; done++) {
        const char *name = frame_name(names, done, nb1, sizeof nb1);
        c = split_png(pngs[done], lens[done], name, &p[done], e);
        if (c)
            break;
        if (done == 0)
            continue;
        const char *first = frame_name(names, 0, nb0, sizeof nb0);
        if (memcmp(p[done].ihdr, p[0].ihdr, 13) != 0) {
            describe(p[done].ihdr, d1, sizeof d1);
            describe(p[0].ihdr, d0, sizeof d0);
            c = rt_fail(e, RT_EINVAL, "%s is %s, the first frame %s is %s: all frames must have the same size and format",
                        name, d1, first, d0);
        } else if (p[done].nplte != p[0].nplte || p[done].ntrns != p[0].ntrns ||
                   (p[0].nplte && memcmp(p[done].plte, p[0].plte, p[0].nplte)) ||
                   (p[0].ntrns && memcmp(p[done].trns, p[0].trns, p[0].ntrns))) {
            c = rt_fail(e, RT_EINVAL,
                        "%s has another palette or transparency (PLTE / tRNS) than the first frame %s: all frames "
                        "must share them",
                        name, first);
        }
    }
    if (c) {
        for (int i = 0; i <= done && i < n; i++)
            bytebuf_free(&p[i].data);
        rt_free(p);
        return c;
    }

    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    bytebuf_append(out, sig, 8);
    png_write_chunk(out, "IHDR", p[0].ihdr, 13);
    unsigned char actl[8];
    put_u32(actl, (uint32_t)n);
    put_u32(actl + 4, (uint32_t)o->loop);
    png_write_chunk(out, "acTL", actl, 8);
    rt_code rc = png_put_recipe(out, e); /* the run's recipe, when one is installed (save of a list) */
    if (rc) {
        for (int i = 0; i < n; i++)
            bytebuf_free(&p[i].data);
        rt_free(p);
        return rc;
    }
    if (p[0].nplte)
        png_write_chunk(out, "PLTE", p[0].plte, p[0].nplte);
    if (p[0].ntrns)
        png_write_chunk(out, "tRNS", p[0].trns, p[0].ntrns);
    uint32_t seq = 0;
    const size_t piece = (size_t)1 << 20; /* chunk size, as png_encode_samples splits IDAT */
    unsigned char *fd = rt_malloc(piece + 4);
    if (!fd)
        out->failed = 1;
    for (int i = 0; i < n && fd; i++) {
        put_fctl(out, &seq, p[i].ihdr, o);
        const bytebuf *z = &p[i].data;
        for (size_t off = 0; off < z->len; off += piece) {
            size_t len = z->len - off < piece ? z->len - off : piece;
            if (i == 0) { /* the first frame is the default image: IDAT */
                png_write_chunk(out, "IDAT", z->data + off, len);
            } else {
                put_u32(fd, seq++);
                memcpy(fd + 4, z->data + off, len);
                png_write_chunk(out, "fdAT", fd, len + 4);
            }
        }
    }
    png_write_chunk(out, "IEND", NULL, 0);
    rt_free(fd);
    for (int i = 0; i < n; i++)
        bytebuf_free(&p[i].data);
    rt_free(p);
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory assembling %d frames", n);
    return RT_OK;
}

rt_code apng_encode(const image *const *ims, int n, int bits, int channels, const apng_opts *o, bytebuf *out,
                    rt_error *e)
{
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "an animated PNG needs at least one frame");
    for (int i = 1; i < n; i++)
        if (ims[i]->w != ims[0]->w || ims[i]->h != ims[0]->h)
            return rt_fail(e, RT_EINVAL, "frame %d is %d×%d, frame 1 is %d×%d: all frames must have the same size",
                           i + 1, ims[i]->w, ims[i]->h, ims[0]->w, ims[0]->h);
    bytebuf *enc = rt_calloc((size_t)n, sizeof *enc);
    const unsigned char **data = rt_calloc((size_t)n, sizeof *data);
    size_t *lens = rt_calloc((size_t)n, sizeof *lens);
    rt_code c = enc && data && lens ? RT_OK : rt_fail(e, RT_ENOMEM, "out of memory encoding %d frames", n);
    int made = 0;
    for (; made < n && !c; made++) {
        bytebuf_init(&enc[made]);
        c = png_encode(ims[made], bits, channels, &enc[made], e);
        data[made] = enc[made].data;
        lens[made] = enc[made].len;
    }
    if (!c)
        c = apng_assemble(data, lens, n, NULL, o, out, e);
    for (int i = 0; i < made; i++)
        bytebuf_free(&enc[i]);
    rt_free(enc);
    rt_free(data);
    rt_free(lens);
    return c;
}

rt_code apng_save(const image *const *ims, int n, int bits, int channels, const apng_opts *o, const char *path,
                  rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code c = apng_encode(ims, n, bits, channels, o, &b, e);
    if (!c)
        c = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return c;
}
