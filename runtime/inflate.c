/* inflate.c — DEFLATE decompressor (RFC 1951) and zlib unwrapping (RFC 1950).
 *
 * Written for robustness first: every read of the input is bounds-checked
 * (a 64-bit bit buffer refilled byte by byte; asking for bits that are not
 * there is "truncated"), every back-reference is checked against the bytes
 * already written, the output is capped by max_out, and every loop consumes
 * input or stops. Huffman codes decode through a 10-bit lookup table with a
 * canonical (count-per-length) walk for longer codes.
 *
 * Incomplete codes are accepted only in the one case RFC 1951 allows
 * (§3.2.7: a single distance code of one bit, or none at all) and the same
 * for literal/length codes, as zlib does; over-subscribed codes never.
 */
#include <stdlib.h>
#include <string.h>

#include "deflate.h"
#include "rt_alloc.h"

#define FAST 10
#define MAXBITS 15

typedef struct huff {
    uint16_t fast[1 << FAST]; /* (symbol << 4) | length, 0 = use the slow path */
    uint16_t count[MAXBITS + 1];
    uint16_t symbol[288];
} huff;

typedef struct inf {
    const unsigned char *in;
    size_t n, pos;
    uint64_t bits;
    int nbits;
    bytebuf *out;
    size_t base, max; /* output starts at out->data + base; at most max bytes */
    rt_error *e;
} inf;

static inline void refill(inf *s)
{
    while (s->nbits <= 56 && s->pos < s->n) {
        s->bits |= (uint64_t)s->in[s->pos++] << s->nbits;
        s->nbits += 8;
    }
}

static rt_code truncated(inf *s)
{
    return rt_fail(s->e, RT_EFORMAT, "compressed data are truncated");
}

/* Read k (<= 32) bits into *v. */
static inline rt_code getbits(inf *s, int k, unsigned *v)
{
    if (s->nbits < k) {
        refill(s);
        if (s->nbits < k) {
            *v = 0;
            return truncated(s);
        }
    }
    *v = (unsigned)(s->bits & ((1ull << k) - 1));
    s->bits >>= k;
    s->nbits -= k;
    return RT_OK;
}

/* Build the decoding tables for code lengths len[0..n-1]; what names the code
 * in error messages. */
static rt_code huff_build(inf *s, huff *h, const uint8_t *len, int n, const char *what,
                          int allow_single)
{
    uint16_t offs[MAXBITS + 2];
    memset(h->count, 0, sizeof h->count);
    memset(h->fast, 0, sizeof h->fast);
    for (int i = 0; i < n; i++)
        h->count[len[i]]++;
    h->count[0] = 0;
    int left = 1, ncodes = 0;
    for (int l = 1; l <= MAXBITS; l++) {
        left <<= 1;
        left -= h->count[l];
        ncodes += h->count[l];
        if (left < 0)
            return rt_fail(s->e, RT_EFORMAT, "over-subscribed %s code", what);
    }
    if (left > 0 && !(allow_single && (ncodes == 0 || (ncodes == 1 && h->count[1] == 1))))
        return rt_fail(s->e, RT_EFORMAT, "incomplete %s code", what);
    offs[1] = 0;
    for (int l = 1; l <= MAXBITS; l++)
        offs[l + 1] = (uint16_t)(offs[l] + h->count[l]);
    for (int i = 0; i < n; i++)
        if (len[i])
            h->symbol[offs[len[i]]++] = (uint16_t)i;
    /* fast table: walk the canonical codes in order */
    unsigned code = 0;
    int idx = 0;
    for (int l = 1; l <= FAST; l++) {
        for (int k = 0; k < h->count[l]; k++, idx++, code++) {
            unsigned r = 0, c = code;
            for (int b = 0; b < l; b++) {
                r = (r << 1) | (c & 1);
                c >>= 1;
            }
            uint16_t entry = (uint16_t)((h->symbol[idx] << 4) | l);
            for (unsigned f = r; f < (1u << FAST); f += 1u << l)
                h->fast[f] = entry;
        }
        code <<= 1;
    }
    return RT_OK;
}

/* Decode one symbol; returns it, or -1 after filling the error. */
static int decode(inf *s, const huff *h)
{
    if (s->nbits < MAXBITS)
        refill(s);
    unsigned entry = h->fast[s->bits & ((1u << FAST) - 1)];
    if (entry) {
        int l = (int)(entry & 15);
        if (l > s->nbits) {
            truncated(s);
            return -1;
        }
        s->bits >>= l;
        s->nbits -= l;
        return (int)(entry >> 4);
    }
    int code = 0, first = 0, index = 0;
    for (int l = 1; l <= MAXBITS; l++) {
        if (l > s->nbits) {
            truncated(s);
            return -1;
        }
        code |= (int)((s->bits >> (l - 1)) & 1);
        int cnt = h->count[l];
        if (code - cnt < first) {
            s->bits >>= l;
            s->nbits -= l;
            return h->symbol[index + (code - first)];
        }
        index += cnt;
        first += cnt;
        first <<= 1;
        code <<= 1;
    }
    rt_fail(s->e, RT_EFORMAT, "invalid Huffman code in compressed data");
    return -1;
}

static rt_code too_big(inf *s)
{
    return rt_fail(s->e, RT_EFORMAT, "decompressed data exceed the limit of %zu bytes", s->max);
}

/* Make room for k more output bytes. */
static rt_code room(inf *s, size_t k)
{
    bytebuf *o = s->out;
    size_t used = o->len - s->base;
    if (k > s->max - used)
        return too_big(s);
    if (o->len + k <= o->cap)
        return RT_OK;
    size_t want = o->len + k, ncap = o->cap ? o->cap : 4096;
    while (ncap < want)
        ncap = ncap > SIZE_MAX / 2 ? want : ncap * 2;
    if (ncap - s->base > s->max) /* do not reserve beyond the cap */
        ncap = s->base + s->max;
    unsigned char *nd = rt_realloc(o->data, ncap);
    if (!nd)
        return rt_fail(s->e, RT_ENOMEM, "out of memory for decompressed data");
    o->data = nd;
    o->cap = ncap;
    return RT_OK;
}

static rt_code stored_block(inf *s)
{
    /* drop to a byte boundary, then give back the whole bytes still buffered */
    s->bits >>= s->nbits & 7;
    s->nbits -= s->nbits & 7;
    s->pos -= (size_t)(s->nbits / 8);
    s->bits = 0;
    s->nbits = 0;
    if (s->n - s->pos < 4)
        return truncated(s);
    const unsigned char *p = s->in + s->pos;
    unsigned len = p[0] | (unsigned)p[1] << 8, nlen = p[2] | (unsigned)p[3] << 8;
    if (len != (~nlen & 0xFFFF))
        return rt_fail(s->e, RT_EFORMAT,
                       "stored block length %u does not match its complement %u", len, nlen);
    s->pos += 4;
    if (s->n - s->pos < len)
        return truncated(s);
    rt_code c = room(s, len);
    if (c || len == 0)
        return c;
    memcpy(s->out->data + s->out->len, s->in + s->pos, len);
    s->out->len += len;
    s->pos += len;
    return RT_OK;
}

static const uint16_t len_base[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                      31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
static const uint8_t len_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                      2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
static const uint16_t dist_base[30] = {1,   2,   3,    4,    5,    7,    9,    13,    17,    25,
                                       33,  49,  65,   97,   129,  193,  257,  385,   513,   769,
                                       1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
static const uint8_t dist_extra[30] = {0, 0, 0, 0, 1, 1, 2, 2,  3,  3,  4,  4,  5,  5,  6,
                                       6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

static rt_code codes(inf *s, const huff *lh, const huff *dh)
{
    bytebuf *o = s->out;
    for (;;) {
        int sym = decode(s, lh);
        if (sym < 0)
            return s->e ? s->e->code : RT_EFORMAT;
        if (sym < 256) {
            if (o->len == o->cap || o->len - s->base >= s->max) {
                rt_code c = room(s, 1);
                if (c)
                    return c;
            }
            o->data[o->len++] = (unsigned char)sym;
            continue;
        }
        if (sym == 256)
            return RT_OK;
        sym -= 257;
        if (sym >= 29)
            return rt_fail(s->e, RT_EFORMAT, "invalid length symbol %d", sym + 257);
        unsigned x = 0;
        rt_code c = getbits(s, len_extra[sym], &x);
        if (c)
            return c;
        size_t len = len_base[sym] + x;
        int ds = decode(s, dh);
        if (ds < 0)
            return s->e ? s->e->code : RT_EFORMAT;
        if (ds >= 30)
            return rt_fail(s->e, RT_EFORMAT, "invalid distance symbol %d", ds);
        if ((c = getbits(s, dist_extra[ds], &x)))
            return c;
        size_t dist = dist_base[ds] + x, have = o->len - s->base;
        if (dist > have)
            return rt_fail(s->e, RT_EFORMAT, "invalid distance %zu (only %zu bytes written)", dist,
                           have);
        if ((c = room(s, len)))
            return c;
        unsigned char *dst = o->data + o->len;
        const unsigned char *src = dst - dist;
        if (dist >= len)
            memcpy(dst, src, len);
        else
            for (size_t i = 0; i < len; i++)
                dst[i] = src[i];
        o->len += len;
    }
}

static rt_code fixed_block(inf *s)
{
    uint8_t len[288];
    huff *t = rt_malloc(2 * sizeof *t);
    if (!t)
        return rt_fail(s->e, RT_ENOMEM, "out of memory");
    for (int i = 0; i < 288; i++)
        len[i] = i < 144 ? 8 : i < 256 ? 9 : i < 280 ? 7 : 8;
    rt_code c = huff_build(s, &t[0], len, 288, "literal/length", 1);
    for (int i = 0; i < 32; i++) /* 30 and 31 complete the code but are invalid */
        len[i] = 5;
    if (!c)
        c = huff_build(s, &t[1], len, 32, "distance", 1);
    if (!c)
        c = codes(s, &t[0], &t[1]);
    rt_free(t);
    return c;
}

static const uint8_t cl_order[19] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};

static rt_code dynamic_block(inf *s)
{
    unsigned hlit, hdist, hclen;
    rt_code c;
    if ((c = getbits(s, 5, &hlit)) || (c = getbits(s, 5, &hdist)) || (c = getbits(s, 4, &hclen)))
        return c;
    hlit += 257;
    hdist += 1;
    hclen += 4;
    if (hlit > 286)
        return rt_fail(s->e, RT_EFORMAT, "too many literal/length codes (%u, at most 286)", hlit);
    if (hdist > 30)
        return rt_fail(s->e, RT_EFORMAT, "too many distance codes (%u, at most 30)", hdist);
    huff *t = rt_malloc(2 * sizeof *t);
    if (!t)
        return rt_fail(s->e, RT_ENOMEM, "out of memory");
    uint8_t len[286 + 30];
    memset(len, 0, sizeof len);
    for (unsigned i = 0; i < hclen; i++) {
        unsigned v;
        if ((c = getbits(s, 3, &v)))
            goto done;
        len[cl_order[i]] = (uint8_t)v;
    }
    if ((c = huff_build(s, &t[0], len, 19, "code-length", 0)))
        goto done;
    unsigned nall = hlit + hdist;
    memset(len, 0, sizeof len);
    for (unsigned i = 0; i < nall;) {
        int sym = decode(s, &t[0]);
        if (sym < 0) {
            c = s->e ? s->e->code : RT_EFORMAT;
            goto done;
        }
        if (sym < 16) {
            len[i++] = (uint8_t)sym;
            continue;
        }
        unsigned rep, v, val = 0;
        if (sym == 16) {
            if (i == 0) {
                c = rt_fail(s->e, RT_EFORMAT, "repeat code 16 with no previous length");
                goto done;
            }
            val = len[i - 1];
            if ((c = getbits(s, 2, &v)))
                goto done;
            rep = 3 + v;
        } else if (sym == 17) {
            if ((c = getbits(s, 3, &v)))
                goto done;
            rep = 3 + v;
        } else {
            if ((c = getbits(s, 7, &v)))
                goto done;
            rep = 11 + v;
        }
        if (i + rep > nall) {
            c = rt_fail(s->e, RT_EFORMAT, "code lengths overflow (%u + %u > %u)", i, rep, nall);
            goto done;
        }
        while (rep--)
            len[i++] = (uint8_t)val;
    }
    if (len[256] == 0) {
        c = rt_fail(s->e, RT_EFORMAT, "dynamic block has no end-of-block code");
        goto done;
    }
    if ((c = huff_build(s, &t[0], len, (int)hlit, "literal/length", 1)))
        goto done;
    if ((c = huff_build(s, &t[1], len + hlit, (int)hdist, "distance", 1)))
        goto done;
    c = codes(s, &t[0], &t[1]);
done:
    rt_free(t);
    return c;
}

rt_code inflate_raw(const unsigned char *in, size_t n, size_t max_out, bytebuf *out,
                    size_t *used, rt_error *e)
{
    inf s = {0};
    s.in = in;
    s.n = n;
    s.out = out;
    s.base = out->len;
    s.max = max_out;
    s.e = e;
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory");
    unsigned final = 0, type;
    rt_code c = RT_OK;
    while (!final) {
        if ((c = getbits(&s, 1, &final)) || (c = getbits(&s, 2, &type)))
            break;
        if (type == 0)
            c = stored_block(&s);
        else if (type == 1)
            c = fixed_block(&s);
        else if (type == 2)
            c = dynamic_block(&s);
        else
            c = rt_fail(e, RT_EFORMAT, "invalid block type 3");
        if (c)
            break;
    }
    if (used)
        *used = s.pos - (size_t)(s.nbits / 8);
    return c;
}

rt_code inflate_zlib(const unsigned char *in, size_t n, size_t max_out, bytebuf *out,
                     rt_error *e)
{
    if (n < 2)
        return rt_fail(e, RT_EFORMAT, "zlib stream is truncated (no header)");
    unsigned cmf = in[0], flg = in[1];
    if ((cmf & 15) != 8)
        return rt_fail(e, RT_EFORMAT, "unsupported zlib compression method %u (expected 8)",
                       cmf & 15);
    if ((cmf >> 4) > 7)
        return rt_fail(e, RT_EFORMAT, "invalid zlib window size 2^%u", (cmf >> 4) + 8);
    if ((cmf * 256 + flg) % 31 != 0)
        return rt_fail(e, RT_EFORMAT, "bad zlib header check bits (0x%02x%02x)", cmf, flg);
    if (flg & 0x20)
        return rt_fail(e, RT_EFORMAT, "zlib preset dictionary is not supported");
    size_t base = out->len, used = 0;
    rt_code c = inflate_raw(in + 2, n - 2, max_out, out, &used, e);
    if (c)
        return c;
    if (n - 2 - used < 4)
        return rt_fail(e, RT_EFORMAT, "zlib stream is truncated (no Adler-32 checksum)");
    const unsigned char *t = in + 2 + used;
    uint32_t want = (uint32_t)t[0] << 24 | (uint32_t)t[1] << 16 | (uint32_t)t[2] << 8 | t[3];
    /* out->data is NULL when nothing was ever appended (an empty stream):
     * no pointer arithmetic on it */
    uint32_t got = out->len > base ? deflate_adler32(1, out->data + base, out->len - base) : 1;
    if (want != got)
        return rt_fail(e, RT_EFORMAT, "Adler-32 mismatch (stored %08x, computed %08x)",
                       (unsigned)want, (unsigned)got);
    return RT_OK;
}
