/* png.c — PNG encoder and decoder. Not from the seed papers: the format is
 * the PNG specification (W3C, 2nd edition); section numbers below refer to
 * it. Compression is our deflate.c / inflate.c. */
#include "png.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "deflate.h"
#include "provenance.h"

#define PNG_MAX_DIM 0x7FFFFFFFu /* §11.2.2: width and height fit in 31 bits */
#define PNG_MAX_FILE ((size_t)1 << 31)

static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

/* ---------------------------------------------------------- conversions */

unsigned png_sample(float v, unsigned maxval)
{
    double d = v;
    if (!(d > 0)) /* also NaN */
        return 0;
    if (d > 1)
        d = 1;
    /* round(d * maxval): d * maxval + 0.5 > 0, so truncation is the floor
     * (without SSE4.1 floor is a libm call per sample, 2/3 of converting
     * a 1024² image) */
    return (unsigned)(d * maxval + 0.5);
}

float png_luma(const float *px)
{
    /* ITU-R BT.709 luminance of linear RGB */
    return (float)(0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2]);
}

/* ------------------------------------------------------------- encoding */

static void put_chunk(bytebuf *out, const char *type, const unsigned char *data, size_t len)
{
    bytebuf_u32be(out, (uint32_t)len);
    bytebuf_append(out, type, 4);
    bytebuf_append(out, data, len);
    uint32_t crc = deflate_crc32(0, type, 4);
    crc = deflate_crc32(crc, data, len);
    bytebuf_u32be(out, crc);
}

void png_write_chunk(bytebuf *out, const char *type, const unsigned char *data, size_t len)
{
    put_chunk(out, type, data, len);
}

static int paeth(int a, int b, int c) /* §9.4 */
{
    int p = a + b - c;
    int pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    if (pa <= pb && pa <= pc)
        return a;
    return pb <= pc ? b : c;
}

/* Adaptive filtering (§12.8's heuristic): for each row the filter type whose
 * output bytes, read as signed, have the least sum of |v| (|v| of a byte is
 * min(v, 256 - v)); ties go to the lower type. Filtering has no loop-carried
 * dependency (it reads only the unfiltered rows), so one pass over the row
 * computes the five costs at once, 8 bytes per step in 16-bit lanes with
 * GCC/Clang vector extensions (SSE2 on x86-64, NEON on ARM), and a second
 * pass writes only the chosen filter. The scalar code below is the
 * reference and the fallback; both give the same bytes. */

/* Paeth predictor on bytes, branch-free (§9.4: p - a = b - c, p - b =
 * a - c, p - c = (b - c) + (a - c)). */
static inline int paeth_pred(int a, int b, int c)
{
    int pa = b - c, pb = a - c, pc = pa + pb;
    pa = pa < 0 ? -pa : pa;
    pb = pb < 0 ? -pb : pb;
    pc = pc < 0 ? -pc : pc;
    return (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
}

static inline unsigned filt_byte(int ft, int x, int a, int b, int c)
{
    switch (ft) {
    case 0: return (unsigned char)x;
    case 1: return (unsigned char)(x - a);
    case 2: return (unsigned char)(x - b);
    case 3: return (unsigned char)(x - ((a + b) >> 1));
    default: return (unsigned char)(x - paeth_pred(a, b, c));
    }
}

static inline unsigned byte_cost(unsigned v)
{
    return v < 256 - v ? v : 256 - v;
}

/* Costs of bytes [i0, i1) of the row, all five filters, scalar; the first
 * bpp bytes have no left neighbour (a = c = 0). */
static void row_costs_scalar(const unsigned char *cur, const unsigned char *prev, size_t i0,
                             size_t i1, size_t bpp, uint64_t cost[5])
{
    for (size_t i = i0; i < i1; i++) {
        int x = cur[i], b = prev[i];
        int a = i >= bpp ? cur[i - bpp] : 0, c = i >= bpp ? prev[i - bpp] : 0;
        for (int ft = 0; ft < 5; ft++)
            cost[ft] += byte_cost(filt_byte(ft, x, a, b, c));
    }
}

static void filter_scalar(int ft, const unsigned char *cur, const unsigned char *prev, size_t i0,
                          size_t i1, size_t bpp, unsigned char *dst)
{
    for (size_t i = i0; i < i1; i++) {
        int a = i >= bpp ? cur[i - bpp] : 0, c = i >= bpp ? prev[i - bpp] : 0;
        dst[i] = (unsigned char)filt_byte(ft, cur[i], a, prev[i], c);
    }
}

#if defined(__GNUC__) || defined(__clang__)
#define PNG_VEC 1
typedef uint8_t png_v8u8 __attribute__((vector_size(8)));
typedef int16_t png_v8i16 __attribute__((vector_size(16)));

static inline png_v8i16 vload8(const unsigned char *p)
{
    png_v8u8 v;
    memcpy(&v, p, 8);
    return __builtin_convertvector(v, png_v8i16);
}

static inline png_v8i16 vabs16(png_v8i16 v)
{
    png_v8i16 m = v >> 15;
    return (v ^ m) - m;
}

/* lanes where m is all ones take x, the others y */
static inline png_v8i16 vsel(png_v8i16 m, png_v8i16 x, png_v8i16 y)
{
    return (x & m) | (y & ~m);
}

static inline png_v8i16 vpaeth(png_v8i16 a, png_v8i16 b, png_v8i16 c)
{
    png_v8i16 pa = b - c, pb = a - c, pc = pa + pb;
    pa = vabs16(pa), pb = vabs16(pb), pc = vabs16(pc);
    png_v8i16 take_a = (pa <= pb) & (pa <= pc), take_b = pb <= pc;
    return vsel(take_a, a, vsel(take_b, b, c));
}

/* |v| of the low byte read as signed: min(t, 256 - t), t = v & 255 */
static inline png_v8i16 vcost(png_v8i16 v)
{
    png_v8i16 t = v & 255, u = 256 - t;
    return vsel(t < u, t, u);
}

/* The five costs of bytes [i0, i1), i0 >= bpp. Lane sums stay below 2^15:
 * each step adds at most 128 per lane, and they are flushed every 128
 * steps. */
static size_t row_costs_vec(const unsigned char *cur, const unsigned char *prev, size_t i0,
                            size_t i1, size_t bpp, uint64_t cost[5])
{
    size_t i = i0;
    while (i + 8 <= i1) {
        png_v8i16 s0 = {0}, s1 = {0}, s2 = {0}, s3 = {0}, s4 = {0};
        for (int k = 0; k < 128 && i + 8 <= i1; k++, i += 8) {
            png_v8i16 x = vload8(cur + i), a = vload8(cur + i - bpp);
            png_v8i16 b = vload8(prev + i), c = vload8(prev + i - bpp);
            s0 += vcost(x);
            s1 += vcost(x - a);
            s2 += vcost(x - b);
            s3 += vcost(x - ((a + b) >> 1));
            s4 += vcost(x - vpaeth(a, b, c));
        }
        for (int l = 0; l < 8; l++) {
            cost[0] += (uint64_t)s0[l];
            cost[1] += (uint64_t)s1[l];
            cost[2] += (uint64_t)s2[l];
            cost[3] += (uint64_t)s3[l];
            cost[4] += (uint64_t)s4[l];
        }
    }
    return i;
}

static size_t filter_vec(int ft, const unsigned char *cur, const unsigned char *prev, size_t i0,
                         size_t i1, size_t bpp, unsigned char *dst)
{
    size_t i = i0;
    for (; i + 8 <= i1; i += 8) {
        png_v8i16 x = vload8(cur + i), a = vload8(cur + i - bpp);
        png_v8i16 b = vload8(prev + i), c = vload8(prev + i - bpp), r;
        switch (ft) {
        case 1: r = x - a; break;
        case 2: r = x - b; break;
        case 3: r = x - ((a + b) >> 1); break;
        default: r = x - vpaeth(a, b, c); break;
        }
        png_v8u8 o = __builtin_convertvector(r & 255, png_v8u8);
        memcpy(dst + i, &o, 8);
    }
    return i;
}
#endif

/* Filter row cur (prev = the previous row, all zero for the first) with
 * the adaptive choice into dst[0] (type) and dst[1..rb]. */
static void filter_adaptive(const unsigned char *cur, const unsigned char *prev, size_t rb,
                            size_t bpp, unsigned char *dst)
{
    uint64_t cost[5] = {0};
    size_t k = bpp < rb ? bpp : rb, i = k;
    row_costs_scalar(cur, prev, 0, k, bpp, cost);
#ifdef PNG_VEC
    i = row_costs_vec(cur, prev, k, rb, bpp, cost);
#endif
    row_costs_scalar(cur, prev, i, rb, bpp, cost);
    int ft = 0;
    for (int t = 1; t < 5; t++)
        if (cost[t] < cost[ft])
            ft = t;
    dst[0] = (unsigned char)ft;
    unsigned char *o = dst + 1;
    if (ft == 0) {
        memcpy(o, cur, rb);
        return;
    }
    filter_scalar(ft, cur, prev, 0, k, bpp, o);
    i = k;
#ifdef PNG_VEC
    i = filter_vec(ft, cur, prev, k, rb, bpp, o);
#endif
    filter_scalar(ft, cur, prev, i, rb, bpp, o);
}

/* The provenance chunks (provenance.h), between IHDR and IDAT: tEXt
 * Software (§11.3.4.2's keyword) and a compressed iTXt `frac:recipe`
 * (§11.3.4.5: keyword, NUL, compression flag 1, method 0, empty language
 * tag and translated keyword, each ended by NUL, then the zlib stream of
 * the UTF-8 text). */
rt_code png_put_recipe(bytebuf *out, rt_error *e)
{
    const prov *p = prov_get();
    if (!p)
        return RT_OK;
    if (p->software) {
        bytebuf t;
        bytebuf_init(&t);
        bytebuf_append(&t, "Software", 9);
        bytebuf_append(&t, p->software, strlen(p->software));
        if (t.failed) {
            bytebuf_free(&t);
            return rt_fail(e, RT_ENOMEM, "out of memory writing the PNG recipe");
        }
        put_chunk(out, "tEXt", t.data, t.len);
        bytebuf_free(&t);
    }
    if (p->recipe) {
        bytebuf t;
        bytebuf_init(&t);
        bytebuf_append(&t, "frac:recipe\0\1\0\0\0", 16); /* 11 + 5 bytes */
        rt_code c = deflate_zlib((const unsigned char *)p->recipe, p->recipe_len, 9, &t, e);
        if (!c && t.failed)
            c = rt_fail(e, RT_ENOMEM, "out of memory writing the PNG recipe");
        if (!c)
            put_chunk(out, "iTXt", t.data, t.len);
        bytebuf_free(&t);
        return c;
    }
    return RT_OK;
}

static rt_code check_enc_args(int w, int h, int channels, int bits, rt_error *e)
{
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "PNG image size %d×%d is empty", w, h);
    if (channels < 1 || channels > 4)
        return rt_fail(e, RT_EINVAL, "PNG channels %d is invalid (expected 1, 2, 3 or 4)",
                       channels);
    if (bits != 8 && bits != 16)
        return rt_fail(e, RT_EINVAL, "PNG bit depth %d is invalid (expected 8 or 16)", bits);
    return RT_OK;
}

rt_code png_encode_samples(const unsigned char *rows, int w, int h, int channels, int bits,
                           int level, bytebuf *out, bytebuf *filtered, rt_error *e)
{
    rt_code c = check_enc_args(w, h, channels, bits, e);
    if (c)
        return c;
    size_t bpp = (size_t)channels * (size_t)bits / 8;
    size_t rb = rt_mul_size((size_t)w, bpp);
    size_t total = rt_mul_size((size_t)h, rb + 1);
    if (rb == 0 || total == 0)
        return rt_fail(e, RT_EINVAL, "PNG image size %d×%d is too large", w, h);
    unsigned char *f = rt_malloc(total), *zero = rt_calloc(1, rb);
    if (!f || !zero) {
        rt_free(f), rt_free(zero);
        return rt_fail(e, RT_ENOMEM, "out of memory encoding a %d×%d PNG", w, h);
    }
    for (int y = 0; y < h; y++) {
        const unsigned char *cur = rows + (size_t)y * rb;
        filter_adaptive(cur, y ? cur - rb : zero, rb, bpp, f + (size_t)y * (rb + 1));
    }
    rt_free(zero);
    if (filtered)
        bytebuf_append(filtered, f, total);

    bytebuf z;
    bytebuf_init(&z);
    c = deflate_zlib(f, total, level, &z, e);
    rt_free(f);
    if (c) {
        bytebuf_free(&z);
        return c;
    }
    static const int ctype[5] = {0, 0, 4, 2, 6};
    unsigned char ihdr[13];
    ihdr[0] = (unsigned char)(w >> 24), ihdr[1] = (unsigned char)(w >> 16);
    ihdr[2] = (unsigned char)(w >> 8), ihdr[3] = (unsigned char)w;
    ihdr[4] = (unsigned char)(h >> 24), ihdr[5] = (unsigned char)(h >> 16);
    ihdr[6] = (unsigned char)(h >> 8), ihdr[7] = (unsigned char)h;
    ihdr[8] = (unsigned char)bits;
    ihdr[9] = (unsigned char)ctype[channels];
    ihdr[10] = ihdr[11] = ihdr[12] = 0; /* deflate, adaptive filtering, no interlace */
    bytebuf_append(out, png_sig, 8);
    put_chunk(out, "IHDR", ihdr, 13);
    c = png_put_recipe(out, e);
    if (c) {
        bytebuf_free(&z);
        return c;
    }
    const size_t piece = (size_t)1 << 20;
    for (size_t off = 0; off < z.len; off += piece)
        put_chunk(out, "IDAT", z.data + off, z.len - off < piece ? z.len - off : piece);
    put_chunk(out, "IEND", NULL, 0);
    bytebuf_free(&z);
    if (out->failed || (filtered && filtered->failed))
        return rt_fail(e, RT_ENOMEM, "out of memory encoding a %d×%d PNG", w, h);
    return RT_OK;
}

rt_code png_encode(const image *im, int bits, int channels, bytebuf *out, rt_error *e)
{
    rt_code c = check_enc_args(im->w, im->h, channels, bits, e);
    if (c)
        return c;
    size_t bps = (size_t)bits / 8, np = rt_mul_size((size_t)im->w, (size_t)im->h);
    size_t n = rt_mul_size(np, (size_t)channels * bps);
    if (n == 0)
        return rt_fail(e, RT_EINVAL, "PNG image size %d×%d is too large", im->w, im->h);
    unsigned char *s = rt_malloc(n);
    if (!s)
        return rt_fail(e, RT_ENOMEM, "out of memory encoding a %d×%d PNG", im->w, im->h);
    unsigned maxval = bits == 16 ? 65535 : 255;
    unsigned char *o = s;
    /* pending pixels (image.h) are made band by band into a small buffer,
     * so the float image is never written whole */
    size_t band = (size_t)im->h, bw = (size_t)im->w * 4; /* rows at a time */
    float *buf = NULL;
    if (im->src) {
        band = bw >= 65536 ? 1 : 65536 / bw;
        buf = rt_mallocn(band, bw * sizeof(float));
        if (!buf) {
            rt_free(s);
            return rt_fail(e, RT_ENOMEM, "out of memory encoding a %d×%d PNG", im->w, im->h);
        }
    }
    for (int y0 = 0; y0 < im->h; y0 += (int)band) {
        int y1 = y0 + (int)band < im->h ? y0 + (int)band : im->h;
        const float *p = im->px + (size_t)y0 * bw;
        if (buf) {
            image_rows(im, y0, y1, buf);
            p = buf;
        }
        size_t npx = (size_t)(y1 - y0) * (size_t)im->w;
        if (channels == 4 && bits == 8) { /* the default: every float a byte */
            for (size_t j = 0; j < 4 * npx; j++)
                o[j] = (unsigned char)png_sample(p[j], 255);
            o += 4 * npx;
            continue;
        }
        for (size_t i = 0; i < npx; i++, p += 4) {
            float v[4];
            int k = 0;
            if (channels <= 2)
                v[k++] = png_luma(p);
            else
                v[k++] = p[0], v[k++] = p[1], v[k++] = p[2];
            if (channels == 2 || channels == 4)
                v[k++] = p[3];
            for (int j = 0; j < k; j++) {
                unsigned q = png_sample(v[j], maxval);
                if (bits == 16)
                    *o++ = (unsigned char)(q >> 8);
                *o++ = (unsigned char)q;
            }
        }
    }
    rt_free(buf);
    c = png_encode_samples(s, im->w, im->h, channels, bits, PNG_DEFAULT_LEVEL, out, NULL, e);
    rt_free(s);
    return c;
}

rt_code png_save(const image *im, const char *path, int bits, int channels, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code c = png_encode(im, bits, channels, &b, e);
    if (!c)
        c = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return c;
}

/* ------------------------------------------------------------- decoding */

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static rt_code check_sig(const unsigned char *d, size_t n, rt_error *e)
{
    if (n >= 8 && memcmp(d, png_sig, 8) == 0)
        return RT_OK;
    if (n >= 8 && d[0] == 0x89 && memcmp(d + 1, "PNG", 3) == 0)
        return rt_fail(e, RT_EFORMAT,
                       "bad PNG signature (bytes 5-8 are %02x %02x %02x %02x, expected 0d 0a 1a "
                       "0a: altered by a text-mode transfer?)",
                       d[4], d[5], d[6], d[7]);
    return rt_fail(e, RT_EFORMAT, "not a PNG file (bad signature)");
}

/* Verify the chunk at d[pos..]: enough bytes, valid type, CRC. */
static rt_code read_chunk(const unsigned char *d, size_t n, size_t pos, uint32_t *len,
                          char type[5], rt_error *e)
{
    if (n - pos < 12)
        return rt_fail(e, RT_EFORMAT, "PNG file is truncated (chunk header at byte %zu)", pos);
    uint32_t l = be32(d + pos);
    memcpy(type, d + pos + 4, 4);
    type[4] = 0;
    for (int i = 0; i < 4; i++) {
        unsigned char ch = (unsigned char)type[i];
        if (!((ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z'))) {
            return rt_fail(e, RT_EFORMAT, "invalid PNG chunk type (bytes %02x %02x %02x %02x) at byte %zu",
                           d[pos + 4], d[pos + 5], d[pos + 6], d[pos + 7], pos);
        }
    }
    if (l > 0x7FFFFFFFu)
        return rt_fail(e, RT_EFORMAT, "PNG chunk '%s' length %u is too large", type, (unsigned)l);
    if (n - pos - 12 < l)
        return rt_fail(e, RT_EFORMAT, "PNG chunk '%s' is truncated (%u data bytes, %zu left)",
                       type, (unsigned)l, n - pos - 12);
    uint32_t stored = be32(d + pos + 8 + l), crc = deflate_crc32(0, d + pos + 4, (size_t)l + 4);
    if (stored != crc)
        return rt_fail(e, RT_EFORMAT, "CRC mismatch in PNG chunk '%s' (stored %08x, computed %08x)",
                       type, (unsigned)stored, (unsigned)crc);
    *len = l;
    return RT_OK;
}

rt_code png_text(const unsigned char *data, size_t n, const char *keyword, size_t max_len,
                 bytebuf *out, int *found, rt_error *e)
{
    *found = 0;
    rt_code c = check_sig(data, n, e);
    if (c)
        return c;
    size_t klen = strlen(keyword);
    for (size_t pos = 8; pos < n;) {
        uint32_t len;
        char type[5];
        if ((c = read_chunk(data, n, pos, &len, type, e)))
            return c;
        const unsigned char *p = data + pos + 8;
        pos += (size_t)len + 12;
        if (!strcmp(type, "IEND"))
            break;
        int is_t = !strcmp(type, "tEXt"), is_z = !strcmp(type, "zTXt"), is_i = !strcmp(type, "iTXt");
        if (!(is_t || is_z || is_i) || len < klen + 1 || memcmp(p, keyword, klen) || p[klen])
            continue;
        const unsigned char *q = p + klen + 1, *end = p + len;
        int compressed = is_z;
        if (is_z) {
            if (q >= end || *q != 0)
                return rt_fail(e, RT_EFORMAT, "PNG zTXt '%s': unknown compression method", keyword);
            q++;
        } else if (is_i) {
            if (end - q < 2 || q[0] > 1 || q[1] != 0)
                return rt_fail(e, RT_EFORMAT, "PNG iTXt '%s': bad compression flag or method", keyword);
            compressed = q[0];
            q += 2;
            for (int k = 0; k < 2; k++) { /* language tag, translated keyword */
                const unsigned char *z = memchr(q, 0, (size_t)(end - q));
                if (!z)
                    return rt_fail(e, RT_EFORMAT, "PNG iTXt '%s' is truncated", keyword);
                q = z + 1;
            }
        }
        if (compressed) {
            if ((c = inflate_zlib(q, (size_t)(end - q), max_len, out, e)))
                return c;
        } else {
            if ((size_t)(end - q) > max_len)
                return rt_fail(e, RT_ELIMIT, "PNG text '%s' is longer than %zu bytes", keyword, max_len);
            bytebuf_append(out, q, (size_t)(end - q));
        }
        if (out->failed)
            return rt_fail(e, RT_ENOMEM, "out of memory reading PNG text '%s'", keyword);
        *found = 1;
        return RT_OK;
    }
    return RT_OK;
}

static rt_code parse_ihdr(const unsigned char *p, uint32_t len, png_info *info, rt_error *e)
{
    if (len != 13)
        return rt_fail(e, RT_EFORMAT, "PNG IHDR has %u bytes (expected 13)", (unsigned)len);
    uint32_t w = be32(p), h = be32(p + 4);
    int depth = p[8], ct = p[9];
    if (w == 0 || h == 0 || w > PNG_MAX_DIM || h > PNG_MAX_DIM)
        return rt_fail(e, RT_EFORMAT, "invalid PNG image size %u×%u", (unsigned)w, (unsigned)h);
    static const int chans[7] = {1, 0, 3, 1, 2, 0, 4};
    if (ct > 6 || chans[ct] == 0)
        return rt_fail(e, RT_EFORMAT, "invalid PNG colour type %d (expected 0, 2, 3, 4 or 6)", ct);
    int ok;
    const char *allowed;
    switch (ct) {
    case 0: ok = depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16;
        allowed = "1, 2, 4, 8 or 16"; break;
    case 3: ok = depth == 1 || depth == 2 || depth == 4 || depth == 8;
        allowed = "1, 2, 4 or 8"; break;
    default: ok = depth == 8 || depth == 16; allowed = "8 or 16"; break;
    }
    if (!ok)
        return rt_fail(e, RT_EFORMAT, "invalid PNG bit depth %d for colour type %d (expected %s)",
                       depth, ct, allowed);
    if (p[10] != 0)
        return rt_fail(e, RT_EFORMAT, "unknown PNG compression method %d", p[10]);
    if (p[11] != 0)
        return rt_fail(e, RT_EFORMAT, "unknown PNG filter method %d", p[11]);
    if (p[12] > 1)
        return rt_fail(e, RT_EFORMAT, "unknown PNG interlace method %d", p[12]);
    info->w = (int)w;
    info->h = (int)h;
    info->bit_depth = depth;
    info->color_type = ct;
    info->interlace = p[12];
    info->channels = chans[ct];
    info->has_trns = 0;
    return RT_OK;
}

rt_code png_read_info(const unsigned char *data, size_t n, png_info *info, rt_error *e)
{
    rt_code c = check_sig(data, n, e);
    if (c)
        return c;
    uint32_t len;
    char type[5];
    if ((c = read_chunk(data, n, 8, &len, type, e)))
        return c;
    if (strcmp(type, "IHDR") != 0)
        return rt_fail(e, RT_EFORMAT, "first PNG chunk is '%s', expected IHDR", type);
    png_info tmp;
    return parse_ihdr(data + 16, len, info ? info : &tmp, e);
}

typedef struct dec {
    png_info info;
    unsigned char pal[256][3];
    int npal;
    unsigned char trns_a[256];
    int ntrns;
    unsigned trns_key[3]; /* grey or RGB key colour, raw sample values */
} dec;

static size_t row_bytes(const png_info *f, size_t pw)
{
    return (pw * (size_t)f->channels * (size_t)f->bit_depth + 7) / 8;
}

/* Adam7 (§8.2): pass origin and step; pass 0 of a non-interlaced image is
 * the whole image. */
static const int a7[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                             {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};

static void pass_dims(const png_info *f, int p, size_t *pw, size_t *ph, int g[4])
{
    if (!f->interlace) {
        g[0] = g[1] = 0, g[2] = g[3] = 1;
    } else
        memcpy(g, a7[p], sizeof a7[p]);
    size_t w = (size_t)f->w, h = (size_t)f->h;
    *pw = w > (size_t)g[0] ? (w - (size_t)g[0] + (size_t)g[2] - 1) / (size_t)g[2] : 0;
    *ph = h > (size_t)g[1] ? (h - (size_t)g[1] + (size_t)g[3] - 1) / (size_t)g[3] : 0;
}

static inline unsigned get_sample(const unsigned char *row, size_t i, int depth)
{
    if (depth == 8)
        return row[i];
    if (depth == 16)
        return (unsigned)row[2 * i] << 8 | row[2 * i + 1];
    size_t bit = i * (size_t)depth;
    return (row[bit / 8] >> (8 - depth - (int)(bit % 8))) & ((1u << depth) - 1);
}

/* Unfilter (§9) and convert one pass into im. raw points at the pass data. */
static rt_code decode_pass(const dec *D, int p, unsigned char *raw, image *im, rt_error *e)
{
    const png_info *f = &D->info;
    size_t pw, ph;
    int g[4];
    pass_dims(f, p, &pw, &ph, g);
    if (pw == 0 || ph == 0)
        return RT_OK;
    size_t rb = row_bytes(f, pw);
    size_t bpp = (size_t)f->channels * (size_t)f->bit_depth / 8;
    if (bpp == 0)
        bpp = 1;
    double maxv = (double)((1u << f->bit_depth) - 1);
    unsigned char *prev = NULL;
    for (size_t y = 0; y < ph; y++) {
        unsigned char *row = raw + y * (rb + 1);
        int ft = row[0];
        unsigned char *cur = row + 1;
        switch (ft) {
        case 0: break;
        case 1:
            for (size_t i = bpp; i < rb; i++)
                cur[i] = (unsigned char)(cur[i] + cur[i - bpp]);
            break;
        case 2:
            if (prev)
                for (size_t i = 0; i < rb; i++)
                    cur[i] = (unsigned char)(cur[i] + prev[i]);
            break;
        case 3:
            for (size_t i = 0; i < rb; i++) {
                int a = i >= bpp ? cur[i - bpp] : 0, b = prev ? prev[i] : 0;
                cur[i] = (unsigned char)(cur[i] + ((a + b) >> 1));
            }
            break;
        case 4:
            for (size_t i = 0; i < rb; i++) {
                int a = i >= bpp ? cur[i - bpp] : 0, b = prev ? prev[i] : 0;
                int c = prev && i >= bpp ? prev[i - bpp] : 0;
                cur[i] = (unsigned char)(cur[i] + paeth(a, b, c));
            }
            break;
        default:
            return rt_fail(e, RT_EFORMAT, "invalid PNG filter type %d in row %zu%s", ft, y,
                           f->interlace ? " of an Adam7 pass" : "");
        }
        prev = cur;
        size_t yy = (size_t)g[1] + y * (size_t)g[3];
        for (size_t x = 0; x < pw; x++) {
            float *o = image_at(im, (int)((size_t)g[0] + x * (size_t)g[2]), (int)yy);
            switch (f->color_type) {
            case 0: {
                unsigned s = get_sample(cur, x, f->bit_depth);
                o[0] = o[1] = o[2] = (float)(s / maxv);
                o[3] = D->ntrns && s == D->trns_key[0] ? 0.0f : 1.0f;
                break;
            }
            case 2: {
                unsigned r = get_sample(cur, 3 * x, f->bit_depth);
                unsigned gg = get_sample(cur, 3 * x + 1, f->bit_depth);
                unsigned b = get_sample(cur, 3 * x + 2, f->bit_depth);
                o[0] = (float)(r / maxv), o[1] = (float)(gg / maxv), o[2] = (float)(b / maxv);
                o[3] = D->ntrns && r == D->trns_key[0] && gg == D->trns_key[1] &&
                               b == D->trns_key[2]
                           ? 0.0f
                           : 1.0f;
                break;
            }
            case 3: {
                unsigned k = get_sample(cur, x, f->bit_depth);
                if ((int)k >= D->npal)
                    return rt_fail(e, RT_EFORMAT,
                                   "PNG palette index %u out of range (palette has %d entries)",
                                   k, D->npal);
                o[0] = (float)(D->pal[k][0] / 255.0);
                o[1] = (float)(D->pal[k][1] / 255.0);
                o[2] = (float)(D->pal[k][2] / 255.0);
                o[3] = (int)k < D->ntrns ? (float)(D->trns_a[k] / 255.0) : 1.0f;
                break;
            }
            case 4: {
                unsigned s = get_sample(cur, 2 * x, f->bit_depth);
                o[0] = o[1] = o[2] = (float)(s / maxv);
                o[3] = (float)(get_sample(cur, 2 * x + 1, f->bit_depth) / maxv);
                break;
            }
            default:
                for (int j = 0; j < 4; j++)
                    o[j] = (float)(get_sample(cur, 4 * x + (size_t)j, f->bit_depth) / maxv);
                break;
            }
        }
    }
    return RT_OK;
}

static rt_code parse_trns(dec *D, const unsigned char *p, uint32_t len, rt_error *e)
{
    int ct = D->info.color_type;
    if (ct == 3) {
        if (D->npal == 0)
            return rt_fail(e, RT_EFORMAT, "PNG tRNS chunk comes before PLTE");
        if ((int)len > D->npal)
            return rt_fail(e, RT_EFORMAT, "PNG tRNS has %u entries but the palette only %d",
                           (unsigned)len, D->npal);
        memcpy(D->trns_a, p, len);
        D->ntrns = (int)len;
    } else if (ct == 0 || ct == 2) {
        uint32_t want = ct == 0 ? 2 : 6;
        if (len != want)
            return rt_fail(e, RT_EFORMAT, "PNG tRNS has %u bytes (expected %u for colour type %d)",
                           (unsigned)len, (unsigned)want, ct);
        for (uint32_t i = 0; i < want / 2; i++)
            D->trns_key[i] = (unsigned)p[2 * i] << 8 | p[2 * i + 1];
        D->ntrns = 1;
    } else
        return rt_fail(e, RT_EFORMAT, "PNG tRNS is not allowed for colour type %d", ct);
    D->info.has_trns = 1;
    return RT_OK;
}

rt_code png_decode(const unsigned char *data, size_t n, image *im, png_info *info, rt_error *e)
{
    im->w = im->h = 0;
    im->px = NULL;
    im->src = NULL;
    rt_code c = check_sig(data, n, e);
    if (c)
        return c;
    dec *D = rt_calloc(1, sizeof *D);
    if (!D)
        return rt_fail(e, RT_ENOMEM, "out of memory");
    bytebuf idat, raw;
    bytebuf_init(&idat);
    bytebuf_init(&raw);
    int idat_state = 0, seen_iend = 0; /* idat_state: 0 none yet, 1 in IDATs, 2 after */
    size_t pos = 8;
    while (!seen_iend) {
        uint32_t len;
        char type[5];
        if (pos == n) {
            c = rt_fail(e, RT_EFORMAT, "PNG file is truncated (no IEND chunk)");
            goto fail;
        }
        if ((c = read_chunk(data, n, pos, &len, type, e)))
            goto fail;
        const unsigned char *p = data + pos + 8;
        if (pos == 8) {
            if (strcmp(type, "IHDR") != 0) {
                c = rt_fail(e, RT_EFORMAT, "first PNG chunk is '%s', expected IHDR", type);
                goto fail;
            }
            if ((c = parse_ihdr(p, len, &D->info, e)) ||
                (c = rt_check_pixels(D->info.w, D->info.h, e))) /* before any buffer of that size */
                goto fail;
        } else if (!strcmp(type, "IHDR")) {
            c = rt_fail(e, RT_EFORMAT, "PNG has a second IHDR chunk");
            goto fail;
        } else if (!strcmp(type, "IDAT")) {
            if (idat_state == 2) {
                c = rt_fail(e, RT_EFORMAT, "PNG IDAT chunks are not consecutive");
                goto fail;
            }
            idat_state = 1;
            bytebuf_append(&idat, p, len);
        } else {
            if (idat_state == 1)
                idat_state = 2;
            if (!strcmp(type, "IEND")) {
                seen_iend = 1;
            } else if (!strcmp(type, "PLTE")) {
                int ct = D->info.color_type;
                if (idat_state) {
                    c = rt_fail(e, RT_EFORMAT, "PNG PLTE chunk comes after IDAT");
                    goto fail;
                }
                if (D->npal) {
                    c = rt_fail(e, RT_EFORMAT, "PNG has a second PLTE chunk");
                    goto fail;
                }
                if (ct == 0 || ct == 4) {
                    c = rt_fail(e, RT_EFORMAT, "PNG PLTE is not allowed for grey colour type %d",
                                ct);
                    goto fail;
                }
                if (len == 0 || len % 3 || len > 768 ||
                    (ct == 3 && (int)len / 3 > (1 << D->info.bit_depth))) {
                    c = rt_fail(e, RT_EFORMAT, "PNG PLTE has an invalid length of %u bytes",
                                (unsigned)len);
                    goto fail;
                }
                D->npal = (int)len / 3;
                memcpy(D->pal, p, len);
            } else if (!strcmp(type, "tRNS")) {
                if (idat_state) {
                    c = rt_fail(e, RT_EFORMAT, "PNG tRNS chunk comes after IDAT");
                    goto fail;
                }
                if ((c = parse_trns(D, p, len, e)))
                    goto fail;
            } else if (type[0] >= 'A' && type[0] <= 'Z') {
                c = rt_fail(e, RT_EFORMAT, "unknown critical PNG chunk '%s'", type);
                goto fail;
            }
            /* other ancillary chunks: skipped (CRC already checked) */
        }
        pos += 12 + (size_t)len;
    }
    if (idat_state == 0) {
        c = rt_fail(e, RT_EFORMAT, "PNG has no IDAT chunk");
        goto fail;
    }
    if (D->info.color_type == 3 && D->npal == 0) {
        c = rt_fail(e, RT_EFORMAT, "PNG palette image has no PLTE chunk");
        goto fail;
    }
    if (idat.failed) {
        c = rt_fail(e, RT_ENOMEM, "out of memory");
        goto fail;
    }

    /* expected size of the decompressed data */
    size_t total = 0, off[8];
    int npass = D->info.interlace ? 7 : 1;
    for (int p = 0; p < npass; p++) {
        size_t pw, ph;
        int g[4];
        pass_dims(&D->info, p, &pw, &ph, g);
        off[p] = total;
        if (pw && ph) {
            size_t k = rt_mul_size(ph, row_bytes(&D->info, pw) + 1);
            if (k == 0 || total + k < total) {
                c = rt_fail(e, RT_EFORMAT, "PNG image size %d×%d is too large", D->info.w,
                            D->info.h);
                goto fail;
            }
            total += k;
        }
    }
    /* the inflated rows and the float image, before either is allocated */
    if ((c = rt_check_bytes((double)total + (double)D->info.w * D->info.h * 4 * sizeof(float),
                            "decoding the PNG image", e)))
        goto fail;
    c = inflate_zlib(idat.data, idat.len, total, &raw, e);
    if (c) {
        if (c == RT_EFORMAT) {
            char m[sizeof e->msg];
            memcpy(m, e->msg, sizeof m);
            if (strstr(m, "exceed"))
                rt_fail(e, RT_EFORMAT, "PNG image data are longer than the %zu bytes expected",
                        total);
            else
                rt_fail(e, RT_EFORMAT, "PNG image data are corrupt: %s", m);
        }
        goto fail;
    }
    if (raw.len != total) {
        c = rt_fail(e, RT_EFORMAT, "PNG image data are too short (%zu of %zu bytes)", raw.len,
                    total);
        goto fail;
    }
    if ((c = image_init(im, D->info.w, D->info.h, e)))
        goto fail;
    for (int p = 0; p < npass; p++)
        if ((c = decode_pass(D, p, raw.data + off[p], im, e))) {
            image_free(im);
            goto fail;
        }
    if (info)
        *info = D->info;
fail:
    bytebuf_free(&idat);
    bytebuf_free(&raw);
    rt_free(D);
    return c;
}

rt_code png_load(const char *path, image *im, png_info *info, rt_error *e)
{
    unsigned char *d;
    size_t n;
    rt_code c = image_read_file(path, PNG_MAX_FILE, im, &d, &n, e);
    if (c)
        return c;
    c = png_decode(d, n, im, info, e);
    rt_free(d);
    return c;
}
