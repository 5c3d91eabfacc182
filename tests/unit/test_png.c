/* test_png.c — PNG encoder and decoder.
 *
 * Independent facts: PngSuite (primary/X.png must decode to the pixels of
 * the 8-bit RGBA primary_check/X.png; 16-bit values from a separate decoder;
 * corrupt/ files must be rejected), hand-computed quantisation and luminance
 * values, hand-built PNG files (chunks assembled here) for the error cases,
 * and exact round trips of small asymmetric images. Run from the repo root. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "deflate.h"
#include "png.h"

#define SUITE "tests/data/pngsuite/"

/* ------------------------------------------------------------ round trips */

/* A w×h image whose channels all differ: a red "F" on blue for 6×5, with a
 * per-pixel varying green and alpha; values are exact multiples of
 * 1/maxval so every sample must survive exactly. */
static void make_test_image(image *im, int w, int h, unsigned maxval)
{
    static const char *F[5] = {"RRRRR.", "R.....", "RRRR..", "R.....", "R....."};
    image_init(im, w, h, NULL);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = image_at(im, x, y);
            int red = y < 5 && x < 6 && F[y][x] == 'R';
            unsigned g = (unsigned)((x * 37 + y * 101) % (int)(maxval + 1));
            unsigned a = maxval - (unsigned)((x * 13 + y * 7) % 50);
            p[0] = red ? 1.0f : 0.0f;
            p[1] = (float)(g / (double)maxval);
            p[2] = red ? 0.0f : 1.0f;
            p[3] = (float)(a / (double)maxval);
        }
}

static void roundtrip(int w, int h, int bits, int channels)
{
    unsigned maxval = bits == 16 ? 65535 : 255;
    image im, back;
    make_test_image(&im, w, h, maxval);
    bytebuf b;
    bytebuf_init(&b);
    rt_error e = {0};
    rt_code c = png_encode(&im, bits, channels, &b, &e);
    CHECK(c == RT_OK, "%dx%d/%d/%d encode: %s", w, h, bits, channels, e.msg);
    png_info info;
    c = png_decode(b.data, b.len, &back, &info, &e);
    CHECK(c == RT_OK, "%dx%d/%d/%d decode: %s", w, h, bits, channels, e.msg);
    if (c) {
        bytebuf_free(&b);
        image_free(&im);
        return;
    }
    static const int ctype[5] = {0, 0, 4, 2, 6};
    CHECK(info.w == w && info.h == h && info.bit_depth == bits &&
              info.color_type == ctype[channels] && info.interlace == 0,
          "header %dx%d depth %d type %d", info.w, info.h, info.bit_depth, info.color_type);
    int bad = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *p = image_at(&im, x, y), *q = image_at(&back, x, y);
            unsigned want[4], got[4];
            for (int k = 0; k < 4; k++) {
                want[k] = (unsigned)lround(p[k] * (double)maxval);
                got[k] = (unsigned)lround(q[k] * (double)maxval);
            }
            if (channels <= 2) {
                /* grey = Rec. 709 luminance, computed here by hand */
                double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                want[0] = want[1] = want[2] = (unsigned)floor(l * maxval + 0.5);
            }
            if (channels == 1 || channels == 3)
                want[3] = maxval;
            for (int k = 0; k < 4; k++)
                if (want[k] != got[k] || fabs(q[k] * (double)maxval - got[k]) > 1e-3)
                    bad++;
        }
    CHECK(bad == 0, "%dx%d bits %d channels %d: %d samples differ", w, h, bits, channels, bad);
    /* determinism */
    bytebuf b2;
    bytebuf_init(&b2);
    png_encode(&im, bits, channels, &b2, &e);
    CHECK(b2.len == b.len && memcmp(b.data, b2.data, b.len) == 0, "encoding not deterministic");
    bytebuf_free(&b2);
    bytebuf_free(&b);
    image_free(&im);
    image_free(&back);
}

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void test_encoder(void)
{
    int sizes[][2] = {{6, 5}, {1, 1}, {7, 3}, {3, 7}, {13, 11}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        for (int bits = 8; bits <= 16; bits += 8)
            for (int ch = 1; ch <= 4; ch++)
                roundtrip(sizes[s][0], sizes[s][1], bits, ch);

    /* quantisation by hand: round(clamp(v) * 255) */
    CHECK(png_sample(0.5f, 255) == 128, "0.5 -> %u", png_sample(0.5f, 255));
    CHECK(png_sample(-0.5f, 255) == 0 && png_sample(1.7f, 255) == 255, "clamp");
    CHECK(png_sample(NAN, 255) == 0, "NaN -> %u", png_sample(NAN, 255));
    CHECK(png_sample(0.2f, 65535) == 13107, "0.2 -> %u of 65535", png_sample(0.2f, 65535));
    CHECK(png_sample(1.0f / 255.0f, 255) == 1, "1/255");
    /* grey of pure red, green, blue: 0.2126*255 = 54.2, 0.7152*255 = 182.4, 0.0722*255 = 18.4 */
    float red[4] = {1, 0, 0, 1}, green[4] = {0, 1, 0, 1}, blue[4] = {0, 0, 1, 1};
    CHECK(png_sample(png_luma(red), 255) == 54, "luma red");
    CHECK(png_sample(png_luma(green), 255) == 182, "luma green");
    CHECK(png_sample(png_luma(blue), 255) == 18, "luma blue");

    /* file layout: signature, then exactly IHDR, IDAT..., IEND with valid CRCs */
    image im;
    make_test_image(&im, 6, 5, 255);
    bytebuf b;
    bytebuf_init(&b);
    rt_error e = {0};
    png_encode(&im, 8, 4, &b, &e);
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    CHECK(b.len > 8 && memcmp(b.data, sig, 8) == 0, "signature");
    size_t pos = 8;
    int k = 0, layout_ok = 1;
    while (pos + 12 <= b.len) {
        uint32_t len = be32(b.data + pos);
        const char *t = (const char *)b.data + pos + 4;
        if (k == 0)
            layout_ok &= memcmp(t, "IHDR", 4) == 0 && len == 13;
        else
            layout_ok &= memcmp(t, "IDAT", 4) == 0 || memcmp(t, "IEND", 4) == 0;
        layout_ok &= deflate_crc32(0, b.data + pos + 4, len + 4) == be32(b.data + pos + 8 + len);
        pos += 12 + len;
        k++;
    }
    CHECK(layout_ok && pos == b.len && memcmp(b.data + b.len - 8, "IEND", 4) == 0,
          "chunk layout");
    /* IHDR of 6×5 RGBA 8-bit, byte by byte */
    static const unsigned char ihdr[13] = {0, 0, 0, 6, 0, 0, 0, 5, 8, 6, 0, 0, 0};
    CHECK(memcmp(b.data + 16, ihdr, 13) == 0, "IHDR fields");
    bytebuf_free(&b);
    image_free(&im);

    /* a smooth gradient compresses well thanks to the filters */
    image g;
    image_init(&g, 64, 64, NULL);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            float *p = image_at(&g, x, y);
            p[0] = (float)x / 63, p[1] = (float)y / 63, p[2] = (float)(x + y) / 126, p[3] = 1;
        }
    bytebuf_init(&b);
    png_encode(&g, 8, 3, &b, &e);
    CHECK(b.len < 64 * 64 * 3 / 10, "gradient: %zu bytes", b.len);
    bytebuf_free(&b);
    image_free(&g);

    /* bad arguments */
    image one;
    image_init(&one, 1, 1, NULL);
    bytebuf_init(&b);
    CHECK(png_encode(&one, 12, 3, &b, &e) == RT_EINVAL && strstr(e.msg, "12"), "%s", e.msg);
    CHECK(png_encode(&one, 8, 5, &b, &e) == RT_EINVAL && strstr(e.msg, "channels"), "%s", e.msg);
    bytebuf_free(&b);
    image_free(&one);
}

/* --------------------------------------------------------------- PngSuite */

static const char *primary[] = {
    "basi0g01", "basi0g02", "basi0g04", "basi0g08", "basi2c08", "basi3p01", "basi3p02", "basi3p04",
    "basi3p08", "basi4a08", "basi6a08", "basn0g01", "basn0g02", "basn0g04", "basn0g08", "basn2c08",
    "basn3p01", "basn3p02", "basn3p04", "basn3p08", "basn4a08", "basn6a08", "bgai4a08", "bgan6a08",
    "bgbn4a08", "bgwn6a08", "s01i3p01", "s01n3p01", "s02i3p01", "s02n3p01", "s03i3p01", "s03n3p01",
    "s04i3p01", "s04n3p01", "s05i3p02", "s05n3p02", "s06i3p02", "s06n3p02", "s07i3p02", "s07n3p02",
    "s08i3p02", "s08n3p02", "s09i3p02", "s09n3p02", "s32i3p04", "s32n3p04", "s33i3p04", "s33n3p04",
    "s34i3p04", "s34n3p04", "s35i3p04", "s35n3p04", "s36i3p04", "s36n3p04", "s37i3p04", "s37n3p04",
    "s38i3p04", "s38n3p04", "s39i3p04", "s39n3p04", "s40i3p04", "s40n3p04", "tbbn0g04", "tbbn3p08",
    "tbgn3p08", "tbrn2c08", "tbwn3p08", "tbyn3p08", "tm3n3p02", "tp0n0g08", "tp0n2c08", "tp0n3p08",
    "tp1n3p08", "z00n2c08", "z03n2c08", "z06n2c08", "z09n2c08",
};

static void test_primary(void)
{
    int interlaced = 0;
    for (size_t i = 0; i < sizeof primary / sizeof primary[0]; i++) {
        char p1[256], p2[256];
        snprintf(p1, sizeof p1, SUITE "primary/%s.png", primary[i]);
        snprintf(p2, sizeof p2, SUITE "primary_check/%s.png", primary[i]);
        image a, b;
        png_info ia, ib;
        rt_error e = {0};
        rt_code c = png_load(p1, &a, &ia, &e);
        CHECK(c == RT_OK, "%s: %s", p1, e.msg);
        rt_code c2 = png_load(p2, &b, &ib, &e);
        CHECK(c2 == RT_OK, "%s: %s", p2, e.msg);
        if (c || c2) {
            image_free(&a);
            image_free(&b);
            continue;
        }
        interlaced += ia.interlace;
        /* the file name encodes colour type and depth: e.g. basn3p04 */
        int ct = primary[i][4] - '0', depth = atoi(primary[i] + 6);
        CHECK(ia.color_type == ct && ia.bit_depth == depth, "%s: type %d depth %d", primary[i],
              ia.color_type, ia.bit_depth);
        CHECK(ib.color_type == 6 && ib.bit_depth == 8, "%s check file is not 8-bit RGBA",
              primary[i]);
        CHECK(a.w == b.w && a.h == b.h, "%s: size %dx%d vs %dx%d", primary[i], a.w, a.h, b.w, b.h);
        if (a.w == b.w && a.h == b.h) {
            int bad = 0;
            for (size_t k = 0; k < (size_t)a.w * (size_t)a.h * 4; k++)
                if (lround(a.px[k] * 255.0) != lround(b.px[k] * 255.0))
                    bad++;
            CHECK(bad == 0, "%s: %d samples differ from the check image", primary[i], bad);
        }
        image_free(&a);
        image_free(&b);
    }
    CHECK(interlaced >= 30, "only %d interlaced files", interlaced);
}

/* Values from an independent decoder: a 60-line python3 script using only the
 * standard library (zlib.decompress + the filter/Adam7 rules written out),
 * run once at development time over tests/data/pngsuite/16bit/. Raw 16-bit
 * samples at pixels (0,0), (5,3), (31,31), (17,29). */
static void test_16bit(void)
{
    static const unsigned grey[4][1] = {{0}, {13056}, {255}, {54016}};
    static const unsigned rgb[4][3] = {
        {65535, 65535, 0}, {54965, 59193, 0}, {0, 0, 65535}, {29596, 4228, 31710}};
    static const unsigned ga[4][2] = {{0, 0}, {10485, 12685}, {0, 0}, {58253, 8457}};
    static const unsigned rgba[4][4] = {{65535, 65535, 0, 0},
                                        {60292, 65535, 0, 12685},
                                        {0, 0, 65535, 0},
                                        {29126, 0, 36408, 8457}};
    static const int pts[4][2] = {{0, 0}, {5, 3}, {31, 31}, {17, 29}};
    static const char *files[] = {"basi0g16", "basi2c16", "basi4a16", "basi6a16", "basn0g16",
                                  "basn2c16", "basn4a16", "basn6a16", "bgai4a16", "bgan6a16",
                                  "bggn4a16", "bgyn6a16", "oi1n0g16", "oi1n2c16", "oi2n0g16",
                                  "oi2n2c16", "oi4n0g16", "oi4n2c16", "oi9n0g16", "oi9n2c16",
                                  "tbbn2c16", "tbgn2c16", "tbwn0g16"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[256];
        snprintf(path, sizeof path, SUITE "16bit/%s.png", files[i]);
        image im;
        png_info info;
        rt_error e = {0};
        rt_code c = png_load(path, &im, &info, &e);
        CHECK(c == RT_OK, "%s: %s", path, e.msg);
        if (c)
            continue;
        CHECK(info.bit_depth == 16 && im.w == 32 && im.h == 32, "%s: depth %d", files[i],
              info.bit_depth);
        int tb = files[i][0] == 't';
        for (int p = 0; p < 4; p++) {
            const float *px = image_at(&im, pts[p][0], pts[p][1]);
            unsigned want[4];
            if (tb) {
                /* tbbn2c16/tbgn2c16/tbwn0g16: tRNS key is white (ffff); those
                 * pixels are transparent, the grey ones (52428) are opaque */
                unsigned v = p == 3 ? 52428 : 65535;
                want[0] = want[1] = want[2] = v;
                want[3] = p == 3 ? 65535 : 0;
            } else {
                switch (info.color_type) {
                case 0: want[0] = want[1] = want[2] = grey[p][0], want[3] = 65535; break;
                case 2: memcpy(want, rgb[p], sizeof rgb[p]), want[3] = 65535; break;
                case 4: want[0] = want[1] = want[2] = ga[p][0], want[3] = ga[p][1]; break;
                default: memcpy(want, rgba[p], sizeof rgba[p]); break;
                }
            }
            for (int k = 0; k < 4; k++)
                CHECK(lround(px[k] * 65535.0) == (long)want[k], "%s (%d,%d)[%d]: %ld vs %u",
                      files[i], pts[p][0], pts[p][1], k, lround(px[k] * 65535.0), want[k]);
        }
        image_free(&im);
    }
}

static void test_corrupt_suite(void)
{
    static const struct {
        const char *file, *want;
    } cases[] = {
        {"xc1n0g08", "colour type 1"}, {"xc9n2c08", "colour type 9"}, {"xcrn0g04", "signature"},
        {"xcsn0g01", "CRC"},           {"xd0n2c08", "bit depth 0"},   {"xd3n2c08", "bit depth 3"},
        {"xd9n2c08", "bit depth 99"},  {"xdtn0g01", "IDAT"},          {"xhdn0g08", "CRC"},
        {"xlfn0g04", "signature"},     {"xs1n0g01", "signature"},     {"xs2n0g01", "signature"},
        {"xs4n0g01", "signature"},     {"xs7n0g01", "signature"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[256];
        snprintf(path, sizeof path, SUITE "corrupt/%s.png", cases[i].file);
        image im;
        rt_error e = {0};
        rt_code c = png_load(path, &im, NULL, &e);
        CHECK(c == RT_EFORMAT && strstr(e.msg, cases[i].want), "%s: code %d, '%s' (want '%s')",
              cases[i].file, (int)c, e.msg, cases[i].want);
        CHECK(im.px == NULL, "%s: image left allocated", cases[i].file);
    }
}

/* ---------------------------------------------------- hand-built files */

static void chunk(bytebuf *b, const char *type, const void *data, size_t len)
{
    bytebuf_u32be(b, (uint32_t)len);
    bytebuf_append(b, type, 4);
    bytebuf_append(b, data, len);
    uint32_t crc = deflate_crc32(deflate_crc32(0, type, 4), data, len);
    bytebuf_u32be(b, crc);
}

/* A PNG from an IHDR and raw (already filtered) scanlines. */
static void build(bytebuf *b, int w, int h, int depth, int ct, int interlace, const void *plte,
                  size_t nplte, const void *trns, size_t ntrns, const unsigned char *raw,
                  size_t nraw)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    bytebuf_init(b);
    bytebuf_append(b, sig, 8);
    unsigned char ihdr[13] = {0,
                              0,
                              (unsigned char)(w >> 8),
                              (unsigned char)w,
                              0,
                              0,
                              (unsigned char)(h >> 8),
                              (unsigned char)h,
                              (unsigned char)depth,
                              (unsigned char)ct,
                              0,
                              0,
                              (unsigned char)interlace};
    chunk(b, "IHDR", ihdr, 13);
    if (plte)
        chunk(b, "PLTE", plte, nplte);
    if (trns)
        chunk(b, "tRNS", trns, ntrns);
    chunk(b, "tEXt", "Comment\0ignored", 15); /* ancillary: skipped */
    bytebuf z;
    bytebuf_init(&z);
    deflate_zlib(raw, nraw, 6, &z, NULL);
    /* split the data over two IDAT chunks */
    chunk(b, "IDAT", z.data, z.len / 2);
    chunk(b, "IDAT", z.data + z.len / 2, z.len - z.len / 2);
    chunk(b, "IEND", NULL, 0);
    bytebuf_free(&z);
}

static rt_code dec(const bytebuf *b, image *im, rt_error *e)
{
    return png_decode(b->data, b->len, im, NULL, e);
}

static void test_handmade(void)
{
    rt_error e = {0};
    image im;
    bytebuf b;
    /* 3×2 palette image, 2-bit, with tRNS; rows use Sub and Up filters.
     * Palette: 0 red, 1 green, 2 blue (alpha 128/255), 3 = white
     * row 0 indices 0 1 2 -> packed 00 01 10 00 = 0x18, filter None
     * row 1 indices 3 3 3 -> packed 11 11 11 00 = 0xFC, filter Up: 0xFC - 0x18 = 0xE4 */
    unsigned char pal[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    unsigned char tr[3] = {255, 255, 128};
    unsigned char raw[4] = {0, 0x18, 2, 0xE4};
    build(&b, 3, 2, 2, 3, 0, pal, 12, tr, 3, raw, 4);
    rt_code c = dec(&b, &im, &e);
    CHECK(c == RT_OK, "palette: %s", e.msg);
    if (!c) {
        const float *p = image_at(&im, 2, 0);
        CHECK(p[0] == 0 && p[1] == 0 && p[2] == 1 && fabsf(p[3] - 128 / 255.0f) < 1e-7f,
              "blue pixel %g %g %g %g", p[0], p[1], p[2], p[3]);
        p = image_at(&im, 1, 0);
        CHECK(p[0] == 0 && p[1] == 1 && p[3] == 1, "green pixel");
        p = image_at(&im, 2, 1);
        CHECK(p[0] == 1 && p[1] == 1 && p[2] == 1 && p[3] == 1, "white pixel (beyond tRNS)");
        image_free(&im);
    }
    bytebuf_free(&b);

    /* palette index out of range: palette of 3 entries, index 3 */
    build(&b, 3, 2, 2, 3, 0, pal, 9, NULL, 0, raw, 4);
    c = dec(&b, &im, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "palette index 3"), "%s", e.msg);
    bytebuf_free(&b);

    /* invalid filter type 5 in row 1 */
    unsigned char rawf[4] = {0, 0x18, 5, 0xE4};
    build(&b, 3, 2, 2, 3, 0, pal, 12, NULL, 0, rawf, 4);
    c = dec(&b, &im, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "filter type 5 in row 1"), "%s", e.msg);
    bytebuf_free(&b);

    /* palette image without PLTE */
    build(&b, 3, 2, 2, 3, 0, NULL, 0, NULL, 0, raw, 4);
    c = dec(&b, &im, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "PLTE"), "%s", e.msg);
    bytebuf_free(&b);

    /* too little and too much image data */
    build(&b, 3, 2, 2, 3, 0, pal, 12, NULL, 0, raw, 3);
    c = dec(&b, &im, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "too short"), "%s", e.msg);
    bytebuf_free(&b);
    unsigned char raw5[5] = {0, 0x18, 2, 0xE4, 0};
    build(&b, 3, 2, 2, 3, 0, pal, 12, NULL, 0, raw5, 5);
    c = dec(&b, &im, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "longer"), "%s", e.msg);
    bytebuf_free(&b);

    /* grey 16-bit with tRNS key 0x1234: 2×1, Sub filter on the second pixel
     * (bpp 2: 0x1234 + 0x0101 = 0x1335) */
    unsigned char rg[5] = {1, 0x12, 0x34, 0x01, 0x01};
    unsigned char key[2] = {0x12, 0x34};
    build(&b, 2, 1, 16, 0, 0, NULL, 0, key, 2, rg, 5);
    c = dec(&b, &im, &e);
    CHECK(c == RT_OK, "grey16: %s", e.msg);
    if (!c) {
        CHECK(lround(im.px[0] * 65535.0) == 0x1234 && im.px[3] == 0, "grey16 pixel 0");
        CHECK(lround(im.px[4] * 65535.0) == 0x1335 && im.px[7] == 1, "grey16 pixel 1");
        CHECK(im.px[4] == im.px[5] && im.px[5] == im.px[6], "grey replicated");
        image_free(&im);
    }
    bytebuf_free(&b);

    /* Adam7 on a 3×3 RGB 8-bit image, the passes worked out by hand from
     * the pass origins and steps (passes 2 and 3 are empty):
     *   pass 1: (0,0)   pass 4: (2,0)   pass 5: (0,2),(2,2)
     *   pass 6: two rows (1,0) and (1,2)   pass 7: (0,1),(1,1),(2,1)
     * pixel (x,y) = (10x + y, 100 + x, 200 + y) */
    {
        unsigned char r[64];
        size_t k = 0;
        int order[][2] = {{0, 0}, {2, 0}, {0, 2}, {2, 2}, {1, 0}, {1, 2}, {0, 1}, {1, 1}, {2, 1}};
        int rowlen[] = {1, 1, 2, 1, 1, 3}; /* pixels per scanline, in file order */
        int idx = 0;
        for (int row = 0; row < 6; row++) {
            r[k++] = 0;
            for (int j = 0; j < rowlen[row]; j++, idx++) {
                int x = order[idx][0], y = order[idx][1];
                r[k++] = (unsigned char)(10 * x + y);
                r[k++] = (unsigned char)(100 + x);
                r[k++] = (unsigned char)(200 + y);
            }
        }
        build(&b, 3, 3, 8, 2, 1, NULL, 0, NULL, 0, r, k);
        c = dec(&b, &im, &e);
        CHECK(c == RT_OK, "adam7: %s", e.msg);
        if (!c) {
            int bad = 0;
            for (int y = 0; y < 3; y++)
                for (int x = 0; x < 3; x++) {
                    const float *p = image_at(&im, x, y);
                    bad += lround(p[0] * 255) != 10 * x + y || lround(p[1] * 255) != 100 + x ||
                           lround(p[2] * 255) != 200 + y || p[3] != 1;
                }
            CHECK(bad == 0, "adam7 3x3: %d pixels wrong", bad);
            image_free(&im);
        }
        bytebuf_free(&b);
    }

    /* chunk order: IDAT before IHDR */
    {
        static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
        bytebuf_init(&b);
        bytebuf_append(&b, sig, 8);
        chunk(&b, "IDAT", "x", 1);
        c = dec(&b, &im, &e);
        CHECK(c == RT_EFORMAT && strstr(e.msg, "expected IHDR"), "%s", e.msg);
        bytebuf_free(&b);
    }

    /* every truncation of a valid file is rejected */
    image src;
    make_test_image(&src, 7, 3, 255);
    bytebuf_init(&b);
    png_encode(&src, 8, 4, &b, &e);
    int accepted = 0;
    for (size_t n = 0; n < b.len; n++) {
        if (png_decode(b.data, n, &im, NULL, &e) != RT_EFORMAT)
            accepted++;
        image_free(&im);
    }
    CHECK(accepted == 0, "%d truncated files accepted", accepted);
    /* every bit flip is rejected (CRCs cover all chunk bytes) */
    int flips = 0;
    for (size_t k = 0; k < b.len * 8; k++) {
        b.data[k / 8] ^= (unsigned char)(1u << (k % 8));
        if (png_decode(b.data, b.len, &im, NULL, &e) == RT_OK)
            flips++;
        image_free(&im);
        b.data[k / 8] ^= (unsigned char)(1u << (k % 8));
    }
    CHECK(flips == 0, "%d bit flips accepted", flips);
    bytebuf_free(&b);
    image_free(&src);
}


/* Filtering by the rules of §9.2–9.4 and the §12.8 heuristic (minimum sum
 * of |residual| read as signed bytes; the lowest filter type wins a tie),
 * written out here from the spec, against the encoder's filtered bytes, on
 * rows of few distinct values so Paeth's ties (prefer a, then b, then c)
 * are frequent. The test insists that Paeth wins rows with b/c ties, so a
 * tie broken the wrong way in the encoder cannot hide. (An a/b tie with
 * a != b cannot happen: |b-c| = |a-c| and |a-c| <= |a+b-2c| force a = b = c.) */
static int paeth_ref(int a, int b, int c)
{
    int p = a + b - c;
    int pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

static void test_paeth_ties(void)
{
    enum { W = 40, H = 300 };
    unsigned char *rows = malloc(W * H), *want = malloc((W + 1) * H);
    CHECK(rows && want, "memory");
    uint32_t x = 12345;
    for (int i = 0; i < W * H; i++) {
        x = x * 1103515245u + 12345u;
        rows[i] = (unsigned char)(100 + ((x >> 16) % 4) * 3 + (i % W) / 8);
    }
    int paeth_rows_with_ties = 0;
    for (int y = 0; y < H; y++) {
        const unsigned char *cur = rows + y * W;
        unsigned char res[5][W];
        long cost[5] = {0};
        int ties = 0;
        for (int i = 0; i < W; i++) {
            int a = i ? cur[i - 1] : 0, b = y ? cur[i - W] : 0, c = i && y ? cur[i - W - 1] : 0;
            int p = a + b - c, pa = abs(p - a), pb = abs(p - b), pc = abs(p - c);
            ties += pb == pc && pb < pa && b != c;
            int pred[5] = {0, a, b, (a + b) / 2, paeth_ref(a, b, c)};
            for (int f = 0; f < 5; f++) {
                res[f][i] = (unsigned char)(cur[i] - pred[f]);
                cost[f] += res[f][i] < 128 ? res[f][i] : 256 - res[f][i];
            }
        }
        int best = 0;
        for (int f = 1; f < 5; f++)
            if (cost[f] < cost[best])
                best = f;
        want[y * (W + 1)] = (unsigned char)best;
        memcpy(want + y * (W + 1) + 1, res[best], W);
        paeth_rows_with_ties += best == 4 && ties >= 2;
    }
    CHECK(paeth_rows_with_ties >= 20, "Paeth wins %d rows that have b/c ties", paeth_rows_with_ties);
    bytebuf out, filt;
    bytebuf_init(&out);
    bytebuf_init(&filt);
    rt_error e;
    CHECK(png_encode_samples(rows, W, H, 1, 8, 6, &out, &filt, &e) == RT_OK, "encode: %s", e.msg);
    int bad = -1;
    if (filt.len == (size_t)(W + 1) * H)
        for (bad = 0; bad < H && !memcmp(filt.data + bad * (W + 1), want + bad * (W + 1), W + 1); bad++)
            ;
    CHECK(bad == H, "filtered rows differ from the spec's rules first at row %d", bad);
    image im;
    png_info info;
    CHECK(png_decode(out.data, out.len, &im, &info, &e) == RT_OK, "decode: %s", e.msg);
    int diff = 0;
    for (int i = 0; i < W * H; i++)
        diff += png_sample(image_at(&im, i % W, i / W)[0], 255) != rows[i];
    CHECK(diff == 0, "decoded image differs in %d pixels", diff);
    image_free(&im);
    bytebuf_free(&out);
    bytebuf_free(&filt);
    free(rows);
    free(want);
}

/* The same rules for every pixel size (bpp 1..8 bytes, 8- and 16-bit) on
 * rows longer than the encoder's vector blocks and of a length that is not
 * a multiple of 8, so the block loops, their tails and the 128-step partial
 * sums are all exercised. Rows are built to make each filter type win
 * somewhere: noise (None), horizontal ramps (Sub), copies of the row above
 * (Up), the mean of left and above (Average) and planes (Paeth), each with a
 * little noise. The want rows come from the spec's formulas, written out
 * per byte here. */
static void test_filter_all_depths(void)
{
    static const int cfg[][2] = {{1, 8}, {2, 8}, {3, 8}, {4, 8}, {1, 16}, {2, 16}, {3, 16}, {4, 16}};
    enum { W = 1031, H = 40 };
    int wins[5] = {0};
    uint32_t x = 777;
    for (size_t k = 0; k < sizeof cfg / sizeof cfg[0]; k++) {
        int channels = cfg[k][0], bits = cfg[k][1];
        int bpp = channels * bits / 8, rb = W * bpp;
        unsigned char *rows = malloc((size_t)rb * H), *want = malloc((size_t)(rb + 1) * H);
        CHECK(rows && want, "memory");
        for (int y = 0; y < H; y++)
            for (int i = 0; i < rb; i++) {
                x = x * 1103515245u + 12345u;
                int noise = (int)((x >> 16) % 3), kind = (y / 2) % 5, v;
                int a = i >= bpp ? rows[y * rb + i - bpp] : 0, b = y ? rows[(y - 1) * rb + i] : 0;
                switch (kind) {
                case 0: v = (int)(x >> 20); break;
                case 1: v = a + 3 + noise; break;
                case 2: v = b + noise; break;
                case 3: v = (a + b) / 2 + noise; break;
                default: v = i >= bpp && y ? a + b - rows[(y - 1) * rb + i - bpp] + noise : 7 * i;
                }
                rows[y * rb + i] = (unsigned char)v;
            }
        for (int y = 0; y < H; y++) {
            const unsigned char *cur = rows + y * rb;
            long cost[5] = {0};
            for (int i = 0; i < rb; i++) {
                int a = i >= bpp ? cur[i - bpp] : 0, b = y ? cur[i - rb] : 0;
                int c = i >= bpp && y ? cur[i - rb - bpp] : 0;
                int pred[5] = {0, a, b, (a + b) / 2, paeth_ref(a, b, c)};
                for (int f = 0; f < 5; f++) {
                    unsigned char r = (unsigned char)(cur[i] - pred[f]);
                    cost[f] += r < 128 ? r : 256 - r;
                }
            }
            int best = 0;
            for (int f = 1; f < 5; f++)
                if (cost[f] < cost[best])
                    best = f;
            wins[best]++;
            unsigned char *o = want + y * (rb + 1);
            o[0] = (unsigned char)best;
            for (int i = 0; i < rb; i++) {
                int a = i >= bpp ? cur[i - bpp] : 0, b = y ? cur[i - rb] : 0;
                int c = i >= bpp && y ? cur[i - rb - bpp] : 0;
                int pred[5] = {0, a, b, (a + b) / 2, paeth_ref(a, b, c)};
                o[1 + i] = (unsigned char)(cur[i] - pred[best]);
            }
        }
        bytebuf out, filt;
        bytebuf_init(&out);
        bytebuf_init(&filt);
        rt_error e;
        CHECK(png_encode_samples(rows, W, H, channels, bits, PNG_DEFAULT_LEVEL, &out, &filt, &e) ==
                  RT_OK,
              "encode: %s", e.msg);
        int bad = -1;
        if (filt.len == (size_t)(rb + 1) * H)
            for (bad = 0; bad < H && !memcmp(filt.data + bad * (rb + 1), want + bad * (rb + 1),
                                             (size_t)rb + 1);
                 bad++)
                ;
        CHECK(bad == H, "%d channels, %d bits: filtered rows differ from the spec first at row %d",
              channels, bits, bad);
        bytebuf_free(&out);
        bytebuf_free(&filt);
        free(rows);
        free(want);
    }
    for (int f = 0; f < 5; f++)
        CHECK(wins[f] >= 8, "filter type %d wins only %d rows", f, wins[f]);
}

/* A small file that declares a huge image: refused by the pixel limit at
 * IHDR, before anything of that size is allocated; the memory check comes
 * before the rows are inflated. */
static void test_declared_size(void)
{
    rt_error e = {0};
    image im;
    bytebuf b;
    size_t rb = 1 + 9000 / 8, nraw = rb * 9000; /* 1-bit grey, filter 0, all zero */
    unsigned char *raw = rt_calloc(nraw, 1);
    build(&b, 9000, 9000, 1, 0, 0, NULL, 0, NULL, 0, raw, nraw);
    rt_free(raw);
    CHECK(b.len < 64 * 1024, "the 9000×9000 file is small: %zu bytes", b.len);
    check_limits(1e6, -1, -1);
    rt_code c = dec(&b, &im, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "image of 9000×9000 pixels exceeds the limit of 1000000 pixels "
                                          "(raise it with --max-pixels)") == 0, "%d %s", c, e.msg);
    CHECK(check_hs.peak < 64 * 1024, "largest block before the refusal: %zu bytes", check_hs.peak);
    check_limits(1e8, -1, 1 << 20); /* pixels allowed, 1 MiB of memory left */
    c = dec(&b, &im, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "decoding the PNG image needs 1246 MiB, more than the 1 MiB left under "
                                          "the memory limit (raise it with --max-memory MiB)") == 0, "%d %s", c, e.msg);
    CHECK(check_hs.peak < 64 * 1024, "largest block before the refusal: %zu bytes", check_hs.peak);
    check_limits_off();
    bytebuf_free(&b);
    /* at the limit exactly: decodes */
    raw = rt_calloc(1 + 1000 / 8, 1000);
    build(&b, 1000, 1000, 1, 0, 0, NULL, 0, NULL, 0, raw, (1 + 1000 / 8) * 1000);
    rt_free(raw);
    check_limits(1e6, -1, -1);
    c = dec(&b, &im, &e);
    check_limits_off();
    CHECK(c == RT_OK && im.w == 1000 && im.h == 1000, "%d %s", c, e.msg);
    if (c == RT_OK)
        image_free(&im);
    bytebuf_free(&b);
}

int main(void)
{
    test_encoder();
    test_primary();
    test_16bit();
    test_corrupt_suite();
    test_handmade();
    test_paeth_ties();
    test_filter_all_depths();
    test_declared_size();
    return check_done("test_png");
}
