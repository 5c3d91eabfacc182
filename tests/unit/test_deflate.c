/* test_deflate.c — deflate/inflate, zlib wrapper, CRC-32, Adler-32.
 *
 * Independent facts used: the standard check values of CRC-32 and Adler-32,
 * zlib streams produced by CPython's zlib (tests/data/zlib/, data regenerated
 * here by formula), the size zlib level 6 reaches on the same text, and
 * invariants (round trip, corrupt input never accepted with wrong data). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
#include "deflate.h"
#include "fileio.h"

static unsigned char *lcg_bytes(size_t n, uint32_t seed)
{
    unsigned char *p = rt_malloc(n ? n : 1);
    uint32_t x = seed;
    for (size_t i = 0; i < n; i++) {
        x = (x * 1103515245u + 12345u) & 0x7FFFFFFFu;
        p[i] = (unsigned char)((x >> 16) & 255);
    }
    return p;
}

static void gen_text(bytebuf *b)
{
    for (int i = 0; i < 400; i++)
        bytebuf_printf(b, "line %d: %d\n", i, i * i * 31 % 1000);
}

/* Compress at level, inflate, compare; returns the compressed size. */
static size_t roundtrip(const unsigned char *p, size_t n, int level, const char *what)
{
    bytebuf z, o;
    bytebuf_init(&z);
    bytebuf_init(&o);
    rt_error e = {0};
    rt_code c = deflate_zlib(p, n, level, &z, &e);
    CHECK(c == RT_OK, "%s level %d: deflate failed: %s", what, level, e.msg);
    c = inflate_zlib(z.data, z.len, n, &o, &e);
    CHECK(c == RT_OK, "%s level %d: inflate failed: %s", what, level, e.msg);
    CHECK(o.len == n && (n == 0 || memcmp(o.data, p, n) == 0), "%s level %d: data differ", what,
          level);
    /* determinism: the same input gives the same bytes */
    bytebuf z2;
    bytebuf_init(&z2);
    deflate_zlib(p, n, level, &z2, &e);
    CHECK(z2.len == z.len && memcmp(z2.data, z.data, z.len) == 0, "%s: not deterministic", what);
    size_t len = z.len;
    bytebuf_free(&z);
    bytebuf_free(&z2);
    bytebuf_free(&o);
    return len;
}

static void test_checksums(void)
{
    /* CRC-32 check value of "123456789" (the catalogue value for CRC-32/ISO-HDLC) */
    CHECK(deflate_crc32(0, "123456789", 9) == 0xCBF43926u, "crc32 check value");
    CHECK(deflate_crc32(0, "", 0) == 0, "crc32 of empty");
    uint32_t c = deflate_crc32(0, "1234", 4);
    CHECK(deflate_crc32(c, "56789", 5) == 0xCBF43926u, "crc32 piecewise");
    /* Adler-32 of "Wikipedia" = 0x11E60398 (RFC 1950 worked example on Wikipedia) */
    CHECK(deflate_adler32(1, "Wikipedia", 9) == 0x11E60398u, "adler32 Wikipedia");
    CHECK(deflate_adler32(1, "", 0) == 1, "adler32 of empty");
    /* by hand: a = 1 + 255*n mod 65521, b = sum_{k=1..n} (1 + 255 k) mod 65521 */
    size_t n = 100000;
    unsigned char *ff = rt_malloc(n);
    memset(ff, 0xFF, n);
    uint64_t a = (1 + 255ull * n) % 65521, b = (n + 255ull * n * (n + 1) / 2) % 65521;
    CHECK(deflate_adler32(1, ff, n) == (uint32_t)(b << 16 | a), "adler32 of 100000 x 0xFF");
    rt_free(ff);

    /* every length 0..100 at every offset 0..7 (the 8-byte steps and their
     * tails) against the CRC computed one bit at a time from the polynomial */
    unsigned char buf[108];
    for (int i = 0; i < 108; i++)
        buf[i] = (unsigned char)(i * 167 + 13);
    int bad = 0;
    for (int off = 0; off < 8; off++)
        for (int len = 0; len <= 100; len++) {
            uint32_t r = 0xFFFFFFFFu;
            for (int i = 0; i < len; i++) {
                r ^= buf[off + i];
                for (int k = 0; k < 8; k++)
                    r = (r >> 1) ^ (0xEDB88320u & (0u - (r & 1)));
            }
            bad += deflate_crc32(0, buf + off, (size_t)len) != (r ^ 0xFFFFFFFFu);
        }
    CHECK(bad == 0, "crc32 differs from the bitwise CRC in %d of 808 cases", bad);
    /* Adler-32 by its definition, sums reduced at the end (no overflow in 64 bits) */
    uint64_t sa = 1, sb = 0;
    for (int i = 0; i < 108; i++)
        sa += buf[i], sb += sa;
    CHECK(deflate_adler32(1, buf, 108) == (uint32_t)((sb % 65521) << 16 | (sa % 65521)),
          "adler32 of 108 bytes");
}

static void test_roundtrips(void)
{
    unsigned char one = 'x';
    for (int level = 0; level <= 9; level += 3) {
        roundtrip(NULL, 0, level, "empty");
        roundtrip(&one, 1, level, "1 byte");
    }
    /* incompressible: stored blocks, 5 bytes per block of <= 16384 symbols */
    size_t n = 200000;
    unsigned char *r = lcg_bytes(n, 7);
    size_t zr = roundtrip(r, n, 6, "random");
    CHECK(zr <= n + 6 + 5 * (n / 16384 + 1), "random data grew to %zu bytes", zr);
    roundtrip(r, n, 1, "random");
    roundtrip(r, n, 0, "random");
    roundtrip(r, n, 9, "random");

    /* long runs (> 258): 100000 equal bytes need matches of length 258 */
    unsigned char *run = rt_malloc(n);
    memset(run, 'a', n);
    size_t zrun = roundtrip(run, n, 6, "run");
    CHECK(zrun < 400, "a run of %zu bytes compressed to %zu bytes", n, zrun);
    roundtrip(run, n, 1, "run");
    /* levels 2..5 (4-byte hash; level 2 inserts only the ends of long matches) */
    for (int level = 2; level <= 5; level++) {
        size_t zl = roundtrip(run, n, level, "run");
        CHECK(zl < 400, "level %d: a run of %zu bytes compressed to %zu bytes", level, n, zl);
        roundtrip(r, n, level, "random");
    }

    /* repetitive with distances up to 32768: a random block repeated at 32768 */
    unsigned char *far = rt_malloc(70000);
    unsigned char *blk = lcg_bytes(32768, 3);
    memcpy(far, blk, 32768);
    memcpy(far + 32768, blk, 32768);
    memcpy(far + 65536, blk, 70000 - 65536);
    size_t zfar = roundtrip(far, 70000, 9, "distance 32768");
    /* the second copy must be found at distance exactly 32768 (the window) */
    CHECK(zfar < 32768 + 2000, "period-32768 data compressed to %zu bytes", zfar);
    roundtrip(far, 70000, 6, "distance 32768");
    for (int level = 2; level <= 5; level++) {
        size_t zl = roundtrip(far, 70000, level, "distance 32768");
        CHECK(zl < 32768 + 2000, "level %d: period-32768 data compressed to %zu bytes", level, zl);
    }
    /* a period one beyond the window cannot be matched */
    unsigned char *far2 = rt_malloc(65538);
    memcpy(far2, blk, 32768);
    far2[32768] = 0;
    memcpy(far2 + 32769, blk, 32768);
    rt_free(blk);
    roundtrip(far2, 65537, 9, "distance 32769");

    /* text, and the size zlib level 6 reaches on it (1544 bytes, CPython zlib) */
    bytebuf t;
    bytebuf_init(&t);
    gen_text(&t);
    size_t zt = roundtrip(t.data, t.len, 6, "text");
    for (int level = 2; level <= 5; level++)
        roundtrip(t.data, t.len, level, "text");
    CHECK(zt <= 1544 * 115 / 100, "text: %zu bytes vs zlib level 6's 1544", zt);
    bytebuf_free(&t);

    /* skewed frequencies (Fibonacci counts) force Huffman codes longer than
     * 15 bits unless the code is length-limited */
    bytebuf fib;
    bytebuf_init(&fib);
    uint32_t f0 = 1, f1 = 1, x = 99;
    unsigned char syms[27];
    size_t counts[27], total = 0;
    for (int s = 0; s < 27; s++) {
        counts[s] = f0;
        total += f0;
        uint32_t f2 = f0 + f1;
        f0 = f1;
        f1 = f2;
        syms[s] = (unsigned char)(s * 9 + 1);
    }
    /* interleave pseudo-randomly so LZ77 finds few matches */
    while (total > 0) {
        x = x * 1664525u + 1013904223u;
        uint64_t k = ((uint64_t)(x >> 8) * total) >> 24;
        int s = 0;
        while (k >= counts[s])
            k -= counts[s++];
        counts[s]--;
        total--;
        bytebuf_byte(&fib, syms[s]);
    }
    roundtrip(fib.data, fib.len, 6, "fibonacci");
    roundtrip(fib.data, fib.len, 1, "fibonacci");
    roundtrip(fib.data, fib.len, 2, "fibonacci");
    bytebuf_free(&fib);
    rt_free(r);
    rt_free(run);
    rt_free(far);
    rt_free(far2);
}

/* Streams from another implementation (CPython zlib). */
static void test_known_streams(void)
{
    bytebuf text;
    bytebuf_init(&text);
    gen_text(&text);
    unsigned char *stored = lcg_bytes(300, 1);
    unsigned char *far = rt_malloc(34000), *r = lcg_bytes(2000, 2);
    memcpy(far, r, 2000);
    memset(far + 2000, 0, 30000);
    memcpy(far + 32000, r, 2000);
    const char *hello = "hello, hello, hello world";
    struct {
        const char *file;
        const unsigned char *data;
        size_t n;
    } cases[] = {
        {"tests/data/zlib/text9.z", text.data, text.len},
        {"tests/data/zlib/text1.z", text.data, text.len},
        {"tests/data/zlib/short6.z", (const unsigned char *)hello, strlen(hello)},
        {"tests/data/zlib/stored0.z", stored, 300},
        {"tests/data/zlib/far9.z", far, 34000},
        {"tests/data/zlib/empty6.z", (const unsigned char *)"", 0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        unsigned char *z;
        size_t zn;
        rt_error e = {0};
        rt_code c = fileio_read_all(cases[i].file, 1 << 20, &z, &zn, &e);
        CHECK(c == RT_OK, "%s: %s (run tests from the repository root)", cases[i].file, e.msg);
        if (c)
            continue;
        bytebuf o;
        bytebuf_init(&o);
        c = inflate_zlib(z, zn, 1 << 20, &o, &e);
        CHECK(c == RT_OK, "%s: %s", cases[i].file, e.msg);
        CHECK(o.len == cases[i].n && (o.len == 0 || memcmp(o.data, cases[i].data, o.len) == 0),
              "%s: decoded data differ (%zu bytes, expected %zu)", cases[i].file, o.len,
              cases[i].n);
        /* the output cap: one byte less than needed is refused */
        if (cases[i].n > 0) {
            bytebuf_free(&o);
            c = inflate_zlib(z, zn, cases[i].n - 1, &o, &e);
            CHECK(c == RT_EFORMAT && strstr(e.msg, "exceed"), "%s: cap not enforced: %s",
                  cases[i].file, e.msg);
        }
        bytebuf_free(&o);
        rt_free(z);
    }
    bytebuf_free(&text);
    rt_free(stored);
    rt_free(far);
    rt_free(r);
}

static void test_corrupt(void)
{
    bytebuf t, z;
    bytebuf_init(&t);
    bytebuf_init(&z);
    gen_text(&t);
    rt_error e = {0};
    deflate_zlib(t.data, 600, 6, &z, &e);
    /* every truncation is an error */
    int bad = 0;
    for (size_t k = 0; k < z.len; k++) {
        bytebuf o;
        bytebuf_init(&o);
        rt_code c = inflate_zlib(z.data, k, 1 << 20, &o, &e);
        if (c != RT_EFORMAT)
            bad++;
        bytebuf_free(&o);
    }
    CHECK(bad == 0, "%d truncations accepted", bad);
    /* every single-bit flip is an error, or gives the same data (padding
     * bits), or is an Adler-32 collision (Adler-32 is weak on short inputs:
     * the flip at bit 1530 rotates 4 bytes without changing either sum) */
    int wrong = 0, errors = 0;
    uint32_t want = deflate_adler32(1, t.data, 600);
    for (size_t k = 0; k < z.len * 8; k++) {
        z.data[k / 8] ^= (unsigned char)(1u << (k % 8));
        bytebuf o;
        bytebuf_init(&o);
        rt_code c = inflate_zlib(z.data, z.len, 1 << 20, &o, &e);
        if (c == RT_OK && (o.len != 600 || memcmp(o.data, t.data, 600) != 0)) {
            wrong++;
            CHECK(deflate_adler32(1, o.data, o.len) == want, "flip %zu accepted wrong data", k);
        }
        if (c != RT_OK) {
            errors++;
            CHECK(c == RT_EFORMAT && e.msg[0], "flip %zu: code %d", k, (int)c);
        }
        bytebuf_free(&o);
        z.data[k / 8] ^= (unsigned char)(1u << (k % 8));
    }
    CHECK(wrong <= 2, "%d bit flips decoded to wrong data", wrong);
    CHECK(errors >= (int)(z.len * 8) - 8, "only %d of %zu flips detected", errors, z.len * 8);

    /* specific messages */
    bytebuf o;
    bytebuf_init(&o);
    unsigned char hdr[] = {0x78, 0x9D, 0x03, 0x00};
    CHECK(inflate_zlib(hdr, 4, 100, &o, &e) == RT_EFORMAT && strstr(e.msg, "check bits"), "%s",
          e.msg);
    unsigned char meth[] = {0x79, 0x00};
    CHECK(inflate_zlib(meth, 2, 100, &o, &e) == RT_EFORMAT && strstr(e.msg, "method"), "%s", e.msg);
    /* block type 3: bits 1 (final), 11 (type) */
    unsigned char bt3[] = {0x78, 0x9C, 0x07, 0, 0, 0, 0};
    CHECK(inflate_zlib(bt3, sizeof bt3, 100, &o, &e) == RT_EFORMAT && strstr(e.msg, "block type"),
          "%s", e.msg);
    /* stored block whose NLEN is not the complement of LEN */
    unsigned char st[] = {0x78, 0x9C, 0x01, 0x05, 0x00, 0xFA, 0xFE, 1, 2, 3, 4, 5, 0, 0, 0, 0};
    CHECK(inflate_zlib(st, sizeof st, 100, &o, &e) == RT_EFORMAT && strstr(e.msg, "complement"),
          "%s", e.msg);
    /* fixed block: literal 'a' then length 3 distance 2 (only 1 byte written).
     * Bits: 1 01 | 'a'=0x61 -> code 0x91 (8 bits) | 257 -> 0000001 | dist 1 -> 00001 */
    {
        uint64_t bits = 0;
        int nb = 0;
#define PUT(v, n) (bits |= (uint64_t)(v) << nb, nb += (n))
#define PUTREV(v, n)                                                                             \
    do {                                                                                         \
        for (int q = (n)-1; q >= 0; q--)                                                         \
            PUT(((v) >> q) & 1, 1);                                                              \
    } while (0)
        PUT(1, 1);
        PUT(1, 2);
        PUTREV(0x30 + 0x61, 8);
        PUTREV(1, 7);
        PUTREV(1, 5);
        PUTREV(0, 7);
        unsigned char fx[12] = {0x78, 0x9C};
        for (int i = 0; i < 8; i++)
            fx[2 + i] = (unsigned char)(bits >> (8 * i));
        CHECK(inflate_zlib(fx, 12, 100, &o, &e) == RT_EFORMAT && strstr(e.msg, "distance 2"),
              "%s", e.msg);
        /* distance 1 is fine: "aaaa" */
        bits = 0;
        nb = 0;
        PUT(1, 1);
        PUT(1, 2);
        PUTREV(0x30 + 0x61, 8);
        PUTREV(1, 7);
        PUTREV(0, 5);
        PUTREV(0, 7);
        for (int i = 0; i < 8; i++)
            fx[2 + i] = (unsigned char)(bits >> (8 * i));
        bytebuf_free(&o);
        size_t used = 0;
        CHECK(inflate_raw(fx + 2, 8, 100, &o, &used, &e) == RT_OK && o.len == 4 &&
                  memcmp(o.data, "aaaa", 4) == 0 && used == (size_t)(nb + 7) / 8,
              "hand-made fixed block: %s", e.msg);
    }
    bytebuf_free(&o);

    /* decompression bomb: 10 MB of zeros, refused at 1 MB */
    size_t big = 10u << 20;
    unsigned char *zero = rt_calloc(1, big);
    bytebuf zz;
    bytebuf_init(&zz);
    deflate_zlib(zero, big, 6, &zz, &e);
    CHECK(zz.len < big / 500, "10 MB of zeros compressed to %zu bytes", zz.len);
    bytebuf_init(&o);
    CHECK(inflate_zlib(zz.data, zz.len, 1u << 20, &o, &e) == RT_EFORMAT && strstr(e.msg, "exceed"),
          "bomb: %s", e.msg);
    CHECK(o.cap <= (1u << 20), "bomb: reserved %zu bytes", o.cap);
    bytebuf_free(&o);
    bytebuf_free(&zz);
    rt_free(zero);
    bytebuf_free(&t);
    bytebuf_free(&z);
}

/* Found by the fuzzer (tests/fuzz/README.md): an empty stream into an empty
 * buffer took the Adler-32 of out->data + 0 with out->data NULL (undefined
 * behaviour, reported by UBSan under make asan). */
static void test_empty_stream(void)
{
    rt_error e;
    bytebuf o;
    bytebuf_init(&o);
    const unsigned char z[] = {0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01};
    rt_code c = inflate_zlib(z, sizeof z, 100, &o, &e);
    CHECK(c == RT_OK && o.len == 0, "empty zlib stream: code %d, %zu bytes", (int)c, o.len);
    bytebuf_free(&o);
    bytebuf_init(&o);
    unsigned char bad[] = {0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x02};
    c = inflate_zlib(bad, sizeof bad, 100, &o, &e);
    CHECK(c == RT_EFORMAT && strstr(e.msg, "Adler-32 mismatch (stored 00000002, computed 00000001)"),
          "empty stream, bad Adler-32: code %d, '%s'", (int)c, e.msg);
    bytebuf_free(&o);
}

int main(void)
{
    test_empty_stream();
    test_checksums();
    test_roundtrips();
    test_known_streams();
    test_corrupt();
    return check_done("test_deflate");
}
