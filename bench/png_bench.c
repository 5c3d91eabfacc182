/* png_bench.c — PNG encoding speed and size on a 1024×1024 RGB procedural
 * texture (smooth gradients + noise-like detail, deterministic).
 *
 *   build/bench/png_bench [filtered-out]
 *
 * Prints MB/s of raw pixels (best of several runs) for: memcpy of the pixels
 * (plain C baseline), PNG with store-only deflate (filters + CRC + Adler, no
 * LZ77/Huffman), level 1, the default (PNG_DEFAULT_LEVEL) and level 6, with
 * file sizes. Writes
 * the filtered-row stream (the exact bytes given to deflate) to filtered-out
 * (default /tmp/png_bench_filtered.bin) and the PNG to /tmp/png_bench.png;
 * bench/png_zlib_ref.py compresses the former with zlib level 6 to compare.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "deflate.h"
#include "png.h"
#include "rng.h"

#define W 1024
#define H 1024
#define RUNS 5

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static unsigned char clamp8(double v)
{
    return (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
}

static void make_texture(unsigned char *px)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double u = x / (double)W, v = y / (double)H;
            /* smooth part: gradients and slow waves */
            double r = 40 + 170 * u + 20 * sin(9.0 * v + 3.0 * u);
            double g = 60 + 120 * v + 30 * cos(7.0 * u) * sin(5.0 * v);
            double b = 200 - 120 * u * v + 25 * sin(13.0 * (u + v));
            /* detail: a ridged pattern plus small hashed noise (±3) */
            double ridge = 12 * fabs(sin(40.0 * u + 25.0 * sin(6.0 * v)));
            uint64_t h = rng_hash3(1, (uint64_t)x, (uint64_t)y, 0);
            int n0 = (int)(h & 7) - 3, n1 = (int)((h >> 8) & 7) - 3, n2 = (int)((h >> 16) & 7) - 3;
            unsigned char *p = px + 3 * ((size_t)y * W + (size_t)x);
            p[0] = clamp8(r + ridge + n0);
            p[1] = clamp8(g + ridge * 0.5 + n1);
            p[2] = clamp8(b - ridge + n2);
        }
}

/* Encode once at level; returns seconds, fills *size. */
static double encode_once(const unsigned char *px, int level, size_t *size, bytebuf *filtered,
                          const char *save)
{
    bytebuf out;
    bytebuf_init(&out);
    rt_error e;
    double t0 = now();
    rt_code c = png_encode_samples(px, W, H, 3, 8, level, &out, filtered, &e);
    double t1 = now();
    if (c) {
        fprintf(stderr, "png_bench: %s\n", e.msg);
        exit(1);
    }
    *size = out.len;
    if (save)
        fileio_write_atomic(save, out.data, out.len, &e);
    bytebuf_free(&out);
    return t1 - t0;
}

int main(int argc, char **argv)
{
    const char *fpath = argc > 1 ? argv[1] : "/tmp/png_bench_filtered.bin";
    size_t raw = (size_t)W * H * 3;
    unsigned char *px = malloc(raw), *copy = malloc(raw);
    if (!px || !copy)
        return 1;
    make_texture(px);

    double t_memcpy = 1e30, t_store = 1e30, t_png = 1e30, t_fast = 1e30, t_six = 1e30;
    size_t size_store = 0, size_png = 0, size_fast = 0, size_six = 0;
    unsigned sum = 0;
    for (int r = 0; r < RUNS; r++) {
        double t0 = now();
        memcpy(copy, px, raw);
        double t1 = now();
        sum += copy[(size_t)r * 7919];
        if (t1 - t0 < t_memcpy)
            t_memcpy = t1 - t0;
        double t = encode_once(px, 0, &size_store, NULL, NULL);
        if (t < t_store)
            t_store = t;
        t = encode_once(px, 1, &size_fast, NULL, NULL);
        if (t < t_fast)
            t_fast = t;
        t = encode_once(px, PNG_DEFAULT_LEVEL, &size_png, NULL,
                        r == 0 ? "/tmp/png_bench.png" : NULL);
        if (t < t_png)
            t_png = t;
        t = encode_once(px, 6, &size_six, NULL, r == 0 ? "/tmp/png_bench6.png" : NULL);
        if (t < t_six)
            t_six = t;
    }
    bytebuf filt;
    bytebuf_init(&filt);
    size_t dummy;
    encode_once(px, 0, &dummy, &filt, NULL);
    rt_error e;
    if (fileio_write_atomic(fpath, filt.data, filt.len, &e)) {
        fprintf(stderr, "png_bench: %s\n", e.msg);
        return 1;
    }
    double mb = raw / 1e6;
    printf("png_bench: %dx%d RGB 8-bit, %.2f MB raw pixels, best of %d (checksum %u)\n", W, H,
           mb, RUNS, sum);
    printf("  memcpy (baseline)      %8.1f MB/s\n", mb / t_memcpy);
    printf("  PNG level 0 (stored)   %8.1f MB/s  %9zu bytes  time %6.1fx memcpy\n",
           mb / t_store, size_store, t_store / t_memcpy);
    printf("  PNG level 1            %8.1f MB/s  %9zu bytes  time %6.1fx memcpy\n", mb / t_fast,
           size_fast, t_fast / t_memcpy);
    printf("  PNG level %d (default)  %8.1f MB/s  %9zu bytes  time %6.1fx memcpy, %.2fx stored\n",
           PNG_DEFAULT_LEVEL, mb / t_png, size_png, t_png / t_memcpy, t_png / t_store);
    printf("  PNG level 6            %8.1f MB/s  %9zu bytes  time %6.1fx memcpy\n", mb / t_six,
           size_six, t_six / t_memcpy);
    printf("  filtered rows: %s (%zu bytes)\n", fpath, filt.len);
    printf("  compare: python3 bench/png_zlib_ref.py %s %zu\n", fpath, size_png);
    bytebuf_free(&filt);
    free(px);
    free(copy);
    return 0;
}
