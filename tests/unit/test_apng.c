/* test_apng.c — the animated PNG writer (runtime/apng.c).
 *
 * Independent facts: the APNG 1.0 specification's chunk layout (acTL 8
 * bytes, fcTL 26 bytes, one sequence counter over fcTL and fdAT starting at
 * 0, the first frame's data in IDAT), checked by walking the file's chunks
 * here; each frame's data, put back into a plain PNG (signature, IHDR, IDAT,
 * IEND assembled here), must decode to exactly the source image; palette
 * inputs from PngSuite keep their PLTE. Errors: frames of different sizes or
 * formats, a corrupt input, no frames, a delay out of range. Run from the
 * repo root. */
#include <stdint.h>
#include <string.h>

#include "apng.h"
#include "check.h"
#include "deflate.h"
#include "png.h"

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* 6×5, a red "F" on blue whose green and alpha vary with the pixel and k */
static void make_frame(image *im, int k)
{
    static const char *F[5] = {"RRRRR.", "R.....", "RRRR..", "R.....", "R....."};
    image_init(im, 6, 5, NULL);
    for (int y = 0; y < 5; y++)
        for (int x = 0; x < 6; x++) {
            float *p = image_at(im, x, y);
            int red = F[y][x] == 'R';
            p[0] = red ? 1.0f : 0.0f;
            p[1] = (float)(((x * 37 + y * 101 + k * 53) % 256) / 255.0);
            p[2] = red ? 0.0f : (float)((255 - 40 * k) / 255.0);
            p[3] = (float)((255 - (x * 13 + y * 7 + k) % 50) / 255.0);
        }
}

typedef struct chunk {
    char type[5];
    const unsigned char *body;
    uint32_t len;
} chunk;

/* Walk the chunks, checking lengths and CRCs; returns the count or -1. */
static int chunks(const unsigned char *d, size_t n, chunk *out, int max)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (n < 8 || memcmp(d, sig, 8))
        return -1;
    int k = 0;
    for (size_t pos = 8; pos < n && k < max; k++) {
        if (pos + 12 > n)
            return -1;
        uint32_t len = be32(d + pos);
        if (pos + 12 + len > n)
            return -1;
        uint32_t crc = deflate_crc32(0, d + pos + 4, 4 + (size_t)len);
        if (crc != be32(d + pos + 8 + len))
            return -1;
        memcpy(out[k].type, d + pos + 4, 4);
        out[k].type[4] = 0;
        out[k].body = d + pos + 8;
        out[k].len = len;
        pos += 12 + (size_t)len;
    }
    return k;
}

static void put_chunk(bytebuf *b, const char *type, const unsigned char *data, size_t len)
{
    bytebuf_u32be(b, (uint32_t)len);
    bytebuf_append(b, type, 4);
    bytebuf_append(b, data, len);
    uint32_t crc = deflate_crc32(deflate_crc32(0, type, 4), data, len);
    bytebuf_u32be(b, crc);
}

/* A plain PNG of one frame's zlib data, decoded and compared with src. */
static void check_frame(const unsigned char *ihdr, const unsigned char *z, size_t zn, const image *src, int k)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    bytebuf b;
    bytebuf_init(&b);
    bytebuf_append(&b, sig, 8);
    put_chunk(&b, "IHDR", ihdr, 13);
    put_chunk(&b, "IDAT", z, zn);
    put_chunk(&b, "IEND", NULL, 0);
    image im;
    rt_error e = {0};
    rt_code c = png_decode(b.data, b.len, &im, NULL, &e);
    CHECK(c == RT_OK, "frame %d decodes: %s", k, e.msg);
    if (!c) {
        int same = im.w == src->w && im.h == src->h;
        for (int i = 0; same && i < 4 * im.w * im.h; i++)
            same = fabsf(im.px[i] - src->px[i]) < 0.5f / 255;
        CHECK(same, "frame %d has the source pixels", k);
        image_free(&im);
    }
    bytebuf_free(&b);
}

static void layout(void)
{
    image ims[3];
    const image *p[3];
    for (int k = 0; k < 3; k++) {
        make_frame(&ims[k], k);
        p[k] = &ims[k];
    }
    apng_opts o = {.delay_ms = 250, .loop = 2};
    bytebuf b;
    bytebuf_init(&b);
    rt_error e = {0};
    rt_code c = apng_encode(p, 3, 8, 4, &o, &b, &e);
    CHECK(c == RT_OK, "encode: %s", e.msg);
    chunk ch[32];
    int n = chunks(b.data, b.len, ch, 32);
    CHECK(n == 9, "9 chunks, got %d", n);
    static const char *want[9] = {"IHDR", "acTL", "fcTL", "IDAT", "fcTL", "fdAT", "fcTL", "fdAT", "IEND"};
    for (int i = 0; i < n && i < 9; i++)
        CHECK(!strcmp(ch[i].type, want[i]), "chunk %d is %s, got %s", i, want[i], ch[i].type);
    if (n != 9) {
        bytebuf_free(&b);
        return;
    }
    CHECK(ch[1].len == 8 && be32(ch[1].body) == 3 && be32(ch[1].body + 4) == 2, "acTL: 3 frames, 2 plays");
    uint32_t seq = 0;
    for (int f = 0; f < 3; f++) {
        const chunk *fc = &ch[2 + 2 * f], *dat = &ch[3 + 2 * f];
        const unsigned char *q = fc->body;
        CHECK(fc->len == 26, "fcTL %d is 26 bytes", f);
        CHECK(be32(q) == seq, "fcTL %d sequence %u, got %u", f, seq, be32(q));
        seq++;
        CHECK(be32(q + 4) == 6 && be32(q + 8) == 5 && be32(q + 12) == 0 && be32(q + 16) == 0,
              "fcTL %d: the whole 6×5 canvas at (0, 0)", f);
        CHECK((q[20] << 8 | q[21]) == 250 && (q[22] << 8 | q[23]) == 1000, "fcTL %d: delay 250/1000 s", f);
        CHECK(q[24] == 0 && q[25] == 0, "fcTL %d: dispose none, blend source", f);
        if (f == 0) {
            check_frame(ch[0].body, dat->body, dat->len, &ims[0], 0);
        } else {
            CHECK(be32(dat->body) == seq, "fdAT %d sequence %u, got %u", f, seq, be32(dat->body));
            seq++;
            check_frame(ch[0].body, dat->body + 4, dat->len - 4, &ims[f], f);
        }
    }
    /* the same frames give the same bytes */
    bytebuf b2;
    bytebuf_init(&b2);
    c = apng_encode(p, 3, 8, 4, &o, &b2, &e);
    CHECK(c == RT_OK && b2.len == b.len && !memcmp(b2.data, b.data, b.len), "deterministic");
    bytebuf_free(&b2);
    bytebuf_free(&b);

    /* a frame of another size */
    image small;
    image_init(&small, 5, 5, NULL);
    const image *q[2] = {&ims[0], &small};
    bytebuf_init(&b);
    c = apng_encode(q, 2, 8, 4, &o, &b, &e);
    CHECK(c == RT_EINVAL && !strcmp(e.msg, "frame 2 is 5×5, frame 1 is 6×5: all frames must have the same size"),
          "size mismatch: %s", e.msg);
    bytebuf_free(&b);
    image_free(&small);

    /* PNGs of other formats, and a corrupt one */
    bytebuf a8, a16;
    bytebuf_init(&a8);
    bytebuf_init(&a16);
    png_encode(&ims[0], 8, 3, &a8, &e);
    png_encode(&ims[1], 16, 4, &a16, &e);
    const unsigned char *d[2] = {a8.data, a16.data};
    size_t l[2] = {a8.len, a16.len};
    const char *names[2] = {"a.png", "b.png"};
    bytebuf_init(&b);
    c = apng_assemble(d, l, 2, names, &o, &b, &e);
    CHECK(c == RT_EINVAL && !strcmp(e.msg, "b.png is 16-bit RGBA 6×5, the first frame a.png is 8-bit RGB 6×5: all "
                                           "frames must have the same size and format"),
          "format mismatch: %s", e.msg);
    bytebuf_free(&b);
    a16.data[a16.len - 20] ^= 1; /* inside the last IDAT's data or CRC */
    d[0] = a16.data;
    bytebuf_init(&b);
    c = apng_assemble(d, l + 1, 1, names + 1, &o, &b, &e);
    CHECK(c == RT_EFORMAT && !strncmp(e.msg, "b.png: ", 7), "corrupt input named: %s", e.msg);
    bytebuf_free(&b);
    bytebuf_free(&a8);
    bytebuf_free(&a16);

    bytebuf_init(&b);
    c = apng_encode(p, 0, 8, 4, &o, &b, &e);
    CHECK(c == RT_EINVAL && !strcmp(e.msg, "an animated PNG needs at least one frame"), "no frames: %s", e.msg);
    o.delay_ms = 70000;
    c = apng_encode(p, 1, 8, 4, &o, &b, &e);
    CHECK(c == RT_EINVAL && !strcmp(e.msg, "APNG frame delay 70000 ms is out of range (0 to 65535)"), "delay: %s",
          e.msg);
    bytebuf_free(&b);
    for (int k = 0; k < 3; k++)
        image_free(&ims[k]);
}

/* Palette PNGs (PngSuite basn3p08: 8-bit palette, 32×32) keep PLTE, and the
 * frame data is copied as it is: the fdAT data equals the input's IDAT. */
static void palette(void)
{
    unsigned char *d;
    size_t n;
    rt_error e = {0};
    rt_code c = fileio_read_all("tests/data/pngsuite/primary/basn3p08.png", 1 << 20, &d, &n, &e);
    CHECK(c == RT_OK, "read basn3p08: %s", e.msg);
    if (c)
        return;
    chunk in[16];
    int ni = chunks(d, n, in, 16);
    const chunk *idat = NULL, *plte = NULL;
    for (int i = 0; i < ni; i++) {
        if (!strcmp(in[i].type, "IDAT"))
            idat = &in[i];
        if (!strcmp(in[i].type, "PLTE"))
            plte = &in[i];
    }
    CHECK(idat && plte, "basn3p08 has one IDAT and a PLTE");
    const unsigned char *dd[2] = {d, d};
    size_t ll[2] = {n, n};
    apng_opts o = {.delay_ms = 40, .loop = 0};
    bytebuf b;
    bytebuf_init(&b);
    c = apng_assemble(dd, ll, 2, NULL, &o, &b, &e);
    CHECK(c == RT_OK, "assemble palette frames: %s", e.msg);
    chunk ch[16];
    int k = chunks(b.data, b.len, ch, 16);
    CHECK(k == 8, "8 chunks, got %d", k);
    if (k == 8 && idat && plte) {
        CHECK(!strcmp(ch[2].type, "PLTE") && ch[2].len == plte->len && !memcmp(ch[2].body, plte->body, plte->len),
              "the palette is copied");
        CHECK(!strcmp(ch[6].type, "fdAT") && ch[6].len == idat->len + 4 &&
                  !memcmp(ch[6].body + 4, idat->body, idat->len),
              "the second frame's data is the input's IDAT data");
        CHECK(be32(ch[1].body + 4) == 0, "loop 0: forever");
    }
    bytebuf_free(&b);
    rt_free(d);
}

int main(void)
{
    layout();
    palette();
    return check_done("test_apng");
}
