/* png_bench.c — PNG encoding speed and size on two deterministic 1024×1024
 * images: "texture", RGB 8-bit (smooth gradients + noise-like detail), and
 * "turb16", RGB 16-bit smooth (5-octave turbulence (3 cycles per image at the base) through a colour ramp,
 * the kind of image a field render saves at 16 bits), and "render8", RGBA
 * 8-bit: a soft turbulent ball on a transparent background (like a
 * raymarched hypertexture: large empty areas, smooth detail).
 *
 *   build/bench/png_bench [PREFIX]
 *
 * Prints MB/s of raw pixels (best of several runs) for: memcpy of the pixels
 * (plain C baseline), PNG with store-only deflate (filters + CRC + Adler, no
 * LZ77/Huffman), level 1, the default (PNG_DEFAULT_LEVEL) and level 6, with
 * file sizes. For each image it writes the filtered-row stream (the exact
 * bytes given to deflate) to PREFIX_NAME.bin (default PREFIX
 * /tmp/png_bench) and the default-level PNG to PREFIX_NAME.png;
 * bench/png_zlib_ref.py compresses the former with zlib levels 2 and 6
 * (CPython's zlib: the speed and size reference) in the same run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"

#include "deflate.h"
#include "noise.h"
#include "png.h"
#include "rng.h"

#define W 1024
#define H 1024
#define RUNS 5

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

/* 16-bit RGB: t = 5-octave turbulence, through a smooth ramp (the channels
 * are correlated as in a rendered image); big-endian samples. */
static void make_turb16(unsigned char *px)
{
    noise_perm np;
    noise_perm_init(&np, 7);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double u = x / (double)W, v = y / (double)H;
            double t = noise_turbulence3(&np, 5, 3.0 * u, 3.0 * v, 0.37);
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            double c[3] = {0.15 + 0.8 * t, 0.1 + 0.6 * t * t + 0.2 * u, 0.6 - 0.5 * t + 0.3 * v};
            unsigned char *p = px + 6 * ((size_t)y * W + (size_t)x);
            for (int k = 0; k < 3; k++) {
                double d = c[k] < 0 ? 0 : c[k] > 1 ? 1 : c[k];
                unsigned q = (unsigned)floor(d * 65535 + 0.5);
                p[2 * k] = (unsigned char)(q >> 8);
                p[2 * k + 1] = (unsigned char)q;
            }
        }
}

/* RGBA 8-bit: inside a disc of radius 0.4 (image widths) colour and alpha
 * follow 4-octave turbulence and the distance from the centre; outside all
 * zero. */
static void make_render8(unsigned char *px)
{
    noise_perm np;
    noise_perm_init(&np, 3);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double u = x / (double)W - 0.5, v = y / (double)H - 0.5, r = sqrt(u * u + v * v);
            unsigned char *p = px + 4 * ((size_t)y * W + (size_t)x);
            if (r >= 0.4) {
                p[0] = p[1] = p[2] = p[3] = 0;
                continue;
            }
            double t = noise_turbulence3(&np, 4, 4.0 * u, 4.0 * v, 0.61);
            double a = (1 - r / 0.4) * (0.4 + t);
            a = a > 1 ? 1 : a;
            p[0] = clamp8(255 * a);
            p[1] = clamp8(255 * a * (0.3 + 0.7 * t));
            p[2] = clamp8(255 * a * t * t);
            p[3] = clamp8(255 * a);
        }
}

/* Encode once at level; returns seconds, fills *size. */
static double encode_once(const unsigned char *px, int channels, int bits, int level, size_t *size,
                          bytebuf *filtered, const char *save)
{
    bytebuf out;
    bytebuf_init(&out);
    rt_error e;
    double t0 = bench_now();
    rt_code c = png_encode_samples(px, W, H, channels, bits, level, &out, filtered, &e);
    double t1 = bench_now();
    if (c) {
        fprintf(stderr, "png_bench: %s\n", e.msg);
        exit(1);
    }
    *size = out.len;
    if (save && fileio_write_atomic(save, out.data, out.len, &e)) {
        fprintf(stderr, "png_bench: %s\n", e.msg);
        exit(1);
    }
    bytebuf_free(&out);
    return t1 - t0;
}

static void run_image(const char *name, const unsigned char *px, int channels, int bits,
                      const char *prefix)
{
    size_t raw = (size_t)W * H * (size_t)channels * (size_t)bits / 8;
    unsigned char *copy = malloc(raw);
    if (!copy)
        exit(1);
    char png_path[512], bin_path[512];
    snprintf(png_path, sizeof png_path, "%s_%s.png", prefix, name);
    snprintf(bin_path, sizeof bin_path, "%s_%s.bin", prefix, name);
    static const int levels[4] = {0, 1, PNG_DEFAULT_LEVEL, 6};
    double t_memcpy = 1e30, t[4] = {1e30, 1e30, 1e30, 1e30};
    size_t size[4] = {0};
    unsigned sum = 0;
    for (int r = 0; r < RUNS; r++) {
        double t0 = bench_now();
        memcpy(copy, px, raw);
        double t1 = bench_now();
        sum += copy[(size_t)r * 7919];
        if (t1 - t0 < t_memcpy)
            t_memcpy = t1 - t0;
        for (int k = 0; k < 4; k++) {
            double s = encode_once(px, channels, bits, levels[k], &size[k], NULL,
                                   r == 0 && k == 2 ? png_path : NULL);
            if (s < t[k])
                t[k] = s;
        }
    }
    bytebuf filt;
    bytebuf_init(&filt);
    size_t dummy;
    encode_once(px, channels, bits, 0, &dummy, &filt, NULL);
    rt_error e;
    if (fileio_write_atomic(bin_path, filt.data, filt.len, &e)) {
        fprintf(stderr, "png_bench: %s\n", e.msg);
        exit(1);
    }
    double mb = raw / 1e6;
    printf("png_bench %s: %dx%d %s %d-bit, %.2f MB raw pixels, best of %d (checksum %u)\n",
           name, W, H, channels == 4 ? "RGBA" : "RGB", bits, mb, RUNS, sum);
    printf("  memcpy (baseline)      %8.1f MB/s\n", mb / t_memcpy);
    for (int k = 0; k < 4; k++)
        printf("  PNG level %d%-12s %8.1f MB/s  %9zu bytes  time %6.1fx memcpy\n", levels[k],
               k == 0 ? " (stored)" : k == 2 ? " (default)" : "", mb / t[k], size[k],
               t[k] / t_memcpy);
    printf("  compare: python3 bench/png_zlib_ref.py %s %zu %.6f\n", bin_path, size[2], t[2]);
    bytebuf_free(&filt);
    free(copy);
}

int main(int argc, char **argv)
{
    const char *prefix = argc > 1 ? argv[1] : "/tmp/png_bench";
    unsigned char *px = malloc((size_t)W * H * 6);
    if (!px)
        return 1;
    make_texture(px);
    run_image("texture", px, 3, 8, prefix);
    make_turb16(px);
    run_image("turb16", px, 3, 16, prefix);
    make_render8(px);
    run_image("render8", px, 4, 8, prefix);
    free(px);
    return 0;
}
