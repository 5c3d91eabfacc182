/* test_pnm.c — P5/P6, PF/Pf, and image_save / image_load dispatch.
 *
 * Independent facts: tiny files written byte by byte here (headers with
 * comments, 16-bit big-endian samples, PFM floats in both byte orders with
 * rows bottom-to-top), checked value by value; exact round trips; malformed
 * headers rejected with precise messages. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "rt_alloc.h"
#include "fileio.h"
#include "image.h"
#include "png.h"
#include "pnm.h"

static void put_f32(bytebuf *b, float v, int le)
{
    if (le)
        bytebuf_f32le(b, v);
    else
        bytebuf_f32be(b, v);
}

static void test_handwritten(void)
{
    rt_error e = {0};
    image im;
    pnm_info info;
    /* PGM with comments everywhere whitespace may be */
    static const char pgm[] = "P5\n# made by hand\n3 # width\n2\n# maxval next\n255\n";
    bytebuf b;
    bytebuf_init(&b);
    bytebuf_append(&b, pgm, strlen(pgm));
    unsigned char px[6] = {0, 128, 255, 10, 20, 30};
    bytebuf_append(&b, px, 6);
    rt_code c = pnm_decode(b.data, b.len, &im, &info, &e);
    CHECK(c == RT_OK, "pgm: %s", e.msg);
    if (!c) {
        CHECK(im.w == 3 && im.h == 2 && info.channels == 1 && info.maxval == 255, "pgm header");
        for (int i = 0; i < 6; i++) {
            const float *p = im.px + 4 * i;
            CHECK(p[0] == (float)(px[i] / 255.0) && p[1] == p[0] && p[2] == p[0] && p[3] == 1,
                  "pgm pixel %d: %g", i, p[0]);
        }
        image_free(&im);
    }
    bytebuf_free(&b);

    /* 16-bit PPM, maxval 1000: samples 0 500 1000 | 1 2 999, big-endian */
    static const char ppm[] = "P6 2 1 1000\n";
    static const unsigned char s16[12] = {0, 0, 0x01, 0xF4, 0x03, 0xE8, 0, 1, 0, 2, 0x03, 0xE7};
    bytebuf_init(&b);
    bytebuf_append(&b, ppm, strlen(ppm));
    bytebuf_append(&b, s16, 12);
    c = pnm_decode(b.data, b.len, &im, &info, &e);
    CHECK(c == RT_OK, "ppm16: %s", e.msg);
    if (!c) {
        const float *p = im.px;
        CHECK(p[0] == 0 && p[1] == 0.5f && p[2] == 1 && p[3] == 1, "ppm16 pixel 0: %g %g %g",
              p[0], p[1], p[2]);
        CHECK(p[4] == (float)(1 / 1000.0) && p[5] == (float)(2 / 1000.0) &&
                  p[6] == (float)(999 / 1000.0),
              "ppm16 pixel 1");
        image_free(&im);
    }
    bytebuf_free(&b);

    /* maxval 1 */
    static const unsigned char pbm_like[] = "P5 2 1 1\n\x01\x00";
    c = pnm_decode(pbm_like, sizeof pbm_like - 1, &im, NULL, &e);
    CHECK(c == RT_OK && im.px[0] == 1 && im.px[4] == 0, "maxval 1: %s", e.msg);
    image_free(&im);

    /* PFM, little-endian, 2×2: rows bottom-to-top */
    for (int le = 0; le <= 1; le++) {
        bytebuf_init(&b);
        bytebuf_printf(&b, "PF\n2 2\n%s\n", le ? "-1.0" : "1.0");
        float bottom[6] = {1, 2, 3, 4, 5, 6}, top[6] = {7, 8, 9, -1, 0.5f, 1e10f};
        for (int i = 0; i < 6; i++)
            put_f32(&b, bottom[i], le);
        for (int i = 0; i < 6; i++)
            put_f32(&b, top[i], le);
        c = pfm_decode(b.data, b.len, &im, &info, &e);
        CHECK(c == RT_OK, "pfm: %s", e.msg);
        if (!c) {
            CHECK(info.little_endian == le && info.channels == 3, "pfm info");
            const float *p = image_at(&im, 0, 0);
            CHECK(p[0] == 7 && p[1] == 8 && p[2] == 9 && p[3] == 1, "pfm top-left %g %g %g", p[0],
                  p[1], p[2]);
            p = image_at(&im, 1, 0);
            CHECK(p[0] == -1 && p[1] == 0.5f && p[2] == 1e10f, "pfm top-right");
            p = image_at(&im, 0, 1);
            CHECK(p[0] == 1 && p[1] == 2 && p[2] == 3, "pfm bottom-left");
            p = image_at(&im, 1, 1);
            CHECK(p[0] == 4 && p[1] == 5 && p[2] == 6, "pfm bottom-right");
            image_free(&im);
        }
        bytebuf_free(&b);
    }
    /* Pf grey, big-endian, 1×2 */
    bytebuf_init(&b);
    bytebuf_printf(&b, "Pf\n1 2\n1.0\n");
    bytebuf_f32be(&b, 0.25f); /* bottom */
    bytebuf_f32be(&b, 2.5f);  /* top */
    c = pfm_decode(b.data, b.len, &im, NULL, &e);
    CHECK(c == RT_OK && im.px[0] == 2.5f && im.px[2] == 2.5f && im.px[4] == 0.25f && im.px[7] == 1,
          "Pf: %s", e.msg);
    image_free(&im);
    bytebuf_free(&b);
}

/* A 7×3 image with different channels, values on the 1/65535 grid. */
static void make_image(image *im)
{
    image_init(im, 7, 3, NULL);
    for (int y = 0; y < 3; y++)
        for (int x = 0; x < 7; x++) {
            float *p = image_at(im, x, y);
            p[0] = (float)((x * 9000 + y * 7) / 65535.0);
            p[1] = (float)((65535 - x * 3000 - y * 11000) / 65535.0);
            p[2] = x == 0 && y == 0 ? 1.0f : 0.0f;
            p[3] = 0.5f;
        }
}

static void test_roundtrips(void)
{
    rt_error e = {0};
    image im, back;
    make_image(&im);
    for (int bits = 8; bits <= 16; bits += 8)
        for (int ch = 1; ch <= 3; ch += 2) {
            unsigned maxval = bits == 16 ? 65535 : 255;
            bytebuf b;
            bytebuf_init(&b);
            rt_code c = pnm_encode(&im, bits, ch, &b, &e);
            CHECK(c == RT_OK, "encode: %s", e.msg);
            pnm_info info;
            c = pnm_decode(b.data, b.len, &back, &info, &e);
            CHECK(c == RT_OK && info.maxval == maxval && info.channels == ch, "decode: %s", e.msg);
            if (!c) {
                int bad = 0;
                for (int y = 0; y < 3; y++)
                    for (int x = 0; x < 7; x++) {
                        const float *p = image_at(&im, x, y), *q = image_at(&back, x, y);
                        for (int k = 0; k < 3; k++) {
                            float v = ch == 1 ? png_luma(p) : p[k];
                            bad += png_sample(q[k], maxval) != png_sample(v, maxval);
                        }
                        bad += q[3] != 1;
                    }
                CHECK(bad == 0, "bits %d channels %d: %d samples differ", bits, ch, bad);
                image_free(&back);
            }
            /* header, exactly */
            char want[64];
            snprintf(want, sizeof want, "P%c\n7 3\n%u\n", ch == 1 ? '5' : '6', maxval);
            CHECK(b.len == strlen(want) + 21 * (size_t)ch * (size_t)(bits / 8) &&
                      memcmp(b.data, want, strlen(want)) == 0,
                  "pnm header / size");
            bytebuf_free(&b);
        }
    /* PFM keeps floats exactly, including values outside [0, 1] */
    float *p = image_at(&im, 3, 1);
    p[0] = -2.5f, p[1] = 1e-30f, p[2] = 12345.678f;
    bytebuf b;
    bytebuf_init(&b);
    pfm_encode(&im, 3, &b, &e);
    static const char hdr[] = "PF\n7 3\n-1.0\n";
    CHECK(b.len == strlen(hdr) + 7 * 3 * 12 && memcmp(b.data, hdr, strlen(hdr)) == 0,
          "pfm header");
    /* the first stored float is the bottom-left red value, little-endian */
    float first;
    unsigned char le4[4];
    memcpy(le4, b.data + strlen(hdr), 4);
    uint32_t u = (uint32_t)le4[0] | (uint32_t)le4[1] << 8 | (uint32_t)le4[2] << 16 |
                 (uint32_t)le4[3] << 24;
    memcpy(&first, &u, 4);
    CHECK(first == image_at(&im, 0, 2)[0], "pfm bottom row first: %g", first);
    rt_code c = pfm_decode(b.data, b.len, &back, NULL, &e);
    CHECK(c == RT_OK, "pfm: %s", e.msg);
    if (!c) {
        int bad = 0;
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 7; x++)
                for (int k = 0; k < 3; k++)
                    bad += image_at(&back, x, y)[k] != image_at(&im, x, y)[k];
        CHECK(bad == 0, "pfm round trip: %d values differ", bad);
        image_free(&back);
    }
    bytebuf_free(&b);
    image_free(&im);
}

static void expect_bad(const char *data, size_t n, int pfm, const char *want)
{
    image im;
    rt_error e = {0};
    rt_code c = pfm ? pfm_decode((const unsigned char *)data, n, &im, NULL, &e)
                    : pnm_decode((const unsigned char *)data, n, &im, NULL, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, want) && im.px == NULL, "'%.12s...': '%s' (want '%s')",
          data, e.msg, want);
    if (c == RT_OK)
        image_free(&im);
}

static void test_malformed(void)
{
    expect_bad("P3 1 1 255\n1 2 3", 15, 0, "P5");
    expect_bad("P5 0 2 255\n", 11, 0, "width is 0");
    expect_bad("P5 3 2 70000\n", 13, 0, "maxval is out of range");
    expect_bad("P5 3 2 0\n", 9, 0, "maxval is 0");
    expect_bad("P6 3 2 255\n12345", 16, 0, "truncated (5 of 18 bytes)");
    expect_bad("P5 3x 2 255\n", 12, 0, "whitespace before the height");
    expect_bad("P5 3 2 255", 10, 0, "end with one whitespace");
    expect_bad("P5 3", 4, 0, "no height");
    expect_bad("P5 99999999999 1 255\n", 21, 0, "width is out of range");
    expect_bad("P5 1 1 100\n\xc8", 12, 0, "sample value 200");
    expect_bad("P6 1 1 1000\n\x00\x01\x00\x02", 16, 0, "truncated");
    expect_bad("PF 1 1 0\n\0\0\0\0\0\0\0\0\0\0\0\0", 21, 1, "scale '0'");
    expect_bad("PF 1 1 abc\n", 11, 1, "scale 'abc'");
    expect_bad("PF 1 1 -1.0\n\0\0\0\0", 16, 1, "truncated (4 of 12 bytes)");
    expect_bad("PX 1 1 -1\n", 10, 1, "not a PFM");
}

static void test_dispatch(void)
{
    rt_error e = {0};
    image im, back;
    make_image(&im);
    char path[128];
    const char *exts[] = {"png", "ppm", "pgm", "pfm", "PNG"};
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "/tmp/test_pnm_%ld.%s", (long)getpid(), exts[i]);
        rt_code c = image_save(&im, path, NULL, &e);
        CHECK(c == RT_OK, "save %s: %s", path, e.msg);
        c = image_load(&back, path, &e);
        CHECK(c == RT_OK, "load %s: %s", path, e.msg);
        if (!c) {
            const float *p = image_at(&back, 0, 0), *q = image_at(&im, 0, 0);
            if (i == 2) /* grey */
                CHECK(png_sample(p[0], 255) == png_sample(png_luma(q), 255), "%s", path);
            else
                CHECK(png_sample(p[0], 255) == png_sample(q[0], 255) &&
                          png_sample(p[2], 255) == 255,
                      "%s: first pixel", path);
            /* alpha: kept by PNG (0.5), 1 elsewhere */
            CHECK(p[3] == ((i == 0 || i == 4) ? (float)(128 / 255.0) : 1.0f), "%s alpha %g", path,
                  p[3]);
            image_free(&back);
        }
        remove(path);
    }
    /* content, not extension, decides the loader: a PNG named .pfm */
    snprintf(path, sizeof path, "/tmp/test_pnm_%ld.pfm", (long)getpid());
    bytebuf b;
    bytebuf_init(&b);
    png_encode(&im, 16, 3, &b, &e);
    fileio_write_atomic(path, b.data, b.len, &e);
    bytebuf_free(&b);
    rt_code c = image_load(&back, path, &e);
    CHECK(c == RT_OK && back.w == 7 && back.h == 3, "png named .pfm: %s", e.msg);
    if (!c) {
        CHECK(png_sample(back.px[0], 65535) == png_sample(im.px[0], 65535), "16-bit value");
        image_free(&back);
    }
    /* unknown content */
    fileio_write_atomic(path, "hello", 5, &e);
    c = image_load(&back, path, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "not a PNG") && strstr(e.msg, path), "%s", e.msg);
    /* a corrupt file's message names the file */
    fileio_write_atomic(path, "P5 1 1 255\n", 11, &e);
    c = image_load(&back, path, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "truncated") && strstr(e.msg, path), "%s", e.msg);
    remove(path);
    /* unsupported extension */
    c = image_save(&im, "/tmp/x.jpg", NULL, &e);
    CHECK(c == RT_EINVAL && strstr(e.msg, "'.jpg'") && strstr(e.msg, ".png") &&
              strstr(e.msg, ".pfm"),
          "%s", e.msg);
    c = image_save(&im, "/tmp/noext", NULL, &e);
    CHECK(c == RT_EINVAL && strstr(e.msg, "no file extension"), "%s", e.msg);
    image_save_opts o = {16, 1};
    c = image_save(&im, "/tmp/x.ppm", &o, &e);
    CHECK(c == RT_EINVAL && strstr(e.msg, "3 channels, not 1"), "%s", e.msg);
    o.channels = 5;
    c = image_save(&im, "/tmp/x.png", &o, &e);
    CHECK(c == RT_EINVAL && strstr(e.msg, "channels 5"), "%s", e.msg);
    image_free(&im);
}

/* The pixel limit is checked after the header and before the image is
 * allocated (the samples must be in the file, so the memory check is the
 * hook's own). */
static void test_declared_size(void)
{
    size_t n = 20 + 2000 * 1000;
    unsigned char *d = rt_calloc(n, 1);
    int k = snprintf((char *)d, 20, "P5 2000 1000 255\n");
    image im;
    rt_error e = {0};
    check_limits(1e6, -1, -1);
    rt_code c = pnm_decode(d, (size_t)k + 2000 * 1000, &im, NULL, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "image of 2000×1000 pixels exceeds the limit of 1000000 pixels "
                                          "(raise it with --max-pixels)") == 0, "%d %s", c, e.msg);
    CHECK(check_hs.peak < 4096, "largest block before the refusal: %zu", check_hs.peak);
    k = snprintf((char *)d, 20, "PF 400 400 -1.0\n");
    memset(d + k, 0, n - (size_t)k);
    check_limits(1e5, -1, -1);
    c = pfm_decode(d, (size_t)k + 400 * 400 * 12, &im, NULL, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "image of 400×400 pixels exceeds the limit of 100000 pixels "
                                          "(raise it with --max-pixels)") == 0, "%d %s", c, e.msg);
    check_limits_off();
    rt_free(d);
}

int main(void)
{
    test_handwritten();
    test_roundtrips();
    test_malformed();
    test_dispatch();
    test_declared_size();
    return check_done("test_pnm");
}
