/* termview_bench.c — terminal preview speed on a 1920×1080 RGBA image.
 *
 *   build/bench/termview_bench
 *
 * Baseline (plain C, same process): one pass over every pixel compositing
 * it over black and summing (the least any box-filter preview must do).
 * Measured: termview_render to 160 columns in colour and in greyscale, and
 * to 40 columns. Best of RUNS runs each; prints milliseconds and the ratio
 * to the baseline, plus the output size.
 */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench.h"

#include "termview.h"

#define W 1920
#define H 1080
#define RUNS 7

static volatile double sink;

static double baseline(const image *im)
{
    double t0 = bench_now(), acc = 0;
    const float *p = im->px;
    for (size_t i = 0; i < (size_t)W * H; i++, p += 4) {
        double a = p[3];
        acc += a * p[0] + a * p[1] + a * p[2];
    }
    sink = acc;
    return bench_now() - t0;
}

static double render(const image *im, int cols, int color, size_t *bytes)
{
    termview_opts o = {.cols = cols, .color = color};
    bytebuf b;
    bytebuf_init(&b);
    double t0 = bench_now();
    if (termview_render(im, &o, &b, NULL) != RT_OK) {
        fprintf(stderr, "render failed\n");
        exit(1);
    }
    double t = bench_now() - t0;
    *bytes = b.len;
    bytebuf_free(&b);
    return t;
}

int main(void)
{
    image im;
    if (image_init(&im, W, H, NULL) != RT_OK)
        return 1;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *p = image_at(&im, x, y);
            p[0] = (float)x / W;
            p[1] = (float)y / H;
            p[2] = (float)((x ^ y) & 255) / 255.0f;
            p[3] = (x / 64 + y / 64) % 5 ? 1.0f : 0.5f;
        }
    double best_base = 1e9;
    for (int r = 0; r < RUNS; r++) {
        double t = baseline(&im);
        if (t < best_base)
            best_base = t;
    }
    printf("termview %dx%d: baseline pass %.2f ms\n", W, H, best_base * 1e3);
    struct { int cols, color; const char *name; } cases[] = {
        {160, 1, "colour 160 cols"}, {160, 0, "grey 160 cols"}, {40, 1, "colour 40 cols"}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double best = 1e9;
        size_t bytes = 0;
        for (int r = 0; r < RUNS; r++) {
            double t = render(&im, cases[c].cols, cases[c].color, &bytes);
            if (t < best)
                best = t;
        }
        printf("  %-16s %7.2f ms  %5.2fx baseline  %zu bytes\n", cases[c].name, best * 1e3,
               best / best_base, bytes);
    }
    image_free(&im);
    return 0;
}
