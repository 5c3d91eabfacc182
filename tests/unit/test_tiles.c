/* test_tiles.c — symmetric tiles and tiled patterns (seed 003 §4-1). */
#include <string.h>

#include "check.h"
#include "rng.h"
#include "tiles.h"

static int same(const float *a, const float *b) { return memcmp(a, b, 4 * sizeof *a) == 0; }

int main(void)
{
    rt_error e;
    image src;
    enum { W = 7, H = 5 }; /* odd sizes: the middle column/row maps to itself */
    image_init(&src, W, H, &e);
    rng r;
    rng_init(&r, 1, 0);
    for (int i = 0; i < W * H * 4; i++)
        src.px[i] = (float)rng_uniform(&r);
    for (int i = 0; i < W * H; i++)
        src.px[4 * i + 3] = 1; /* opaque */

    const char *names[3] = {"max", "mean", "over"};
    for (int rule = 0; rule < 2; rule++)
        for (int mirror = 1; mirror <= 3; mirror++) {
            image t;
            CHECK(tiles_symmetric(&src, mirror, (tiles_overlay)rule, &t, &e) == RT_OK, "tile");
            int lr = 1, tb = 1, val = 1;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    lr &= same(image_at(&t, x, y), image_at(&t, W - 1 - x, y));
                    tb &= same(image_at(&t, x, y), image_at(&t, x, H - 1 - y));
                    if (mirror == 1) {
                        /* computed here: max / mean of the pixel and its mirror */
                        for (int c = 0; c < 4; c++) {
                            float a = image_at(&src, x, y)[c], b = image_at(&src, W - 1 - x, y)[c];
                            float want = rule == 0 ? (a > b ? a : b) : (a + b) / 2;
                            val &= fabsf(image_at(&t, x, y)[c] - want) <= 1e-7f;
                        }
                    }
                }
            if (mirror & 1)
                CHECK(lr, "%s tile (mirror %d): pixel (x,y) = (w-1-x,y)", names[rule], mirror);
            if (mirror & 2)
                CHECK(tb, "%s tile (mirror %d): pixel (x,y) = (x,h-1-y)", names[rule], mirror);
            if (mirror == 1)
                CHECK(val, "%s tile values", names[rule]);
            /* The asymmetric source is not symmetric, so the checks can fail. */
            image_free(&t);
        }
    int srclr = 1;
    for (int x = 0; x < W; x++)
        srclr &= same(image_at(&src, x, 0), image_at(&src, W - 1 - x, 0));
    CHECK(!srclr, "the source itself is not symmetric");
    /* OVER with opaque copies: the last copy (the mirror) covers the original. */
    image t;
    CHECK(tiles_symmetric(&src, TILES_LR, TILES_OVER, &t, &e) == RT_OK, "over");
    CHECK(same(image_at(&t, 1, 2), image_at(&src, W - 2, 2)), "opaque over shows the mirror");
    image_free(&t);

    /* Tiling: period (tw, th); mirrored tiling: seamless, period 2tw × 2th. */
    image p;
    CHECK(tiles_fill(&src, 30, 17, 0, &p, &e) == RT_OK, "fill");
    int per = 1;
    for (int y = 0; y < 17; y++)
        for (int x = 0; x < 30; x++) {
            per &= same(image_at(&p, x, y), image_at(&src, x % W, y % H));
            if (x + W < 30)
                per &= same(image_at(&p, x, y), image_at(&p, x + W, y));
            if (y + H < 17)
                per &= same(image_at(&p, x, y), image_at(&p, x, y + H));
        }
    CHECK(per, "tiling is periodic with the tile size");
    image_free(&p);
    CHECK(tiles_fill(&src, 30, 17, 1, &p, &e) == RT_OK, "mirrored fill");
    int mp = 1;
    for (int y = 0; y < 17; y++)
        for (int x = 0; x < 30; x++) {
            if (x + 2 * W < 30)
                mp &= same(image_at(&p, x, y), image_at(&p, x + 2 * W, y));
            if (y + 2 * H < 17)
                mp &= same(image_at(&p, x, y), image_at(&p, x, y + 2 * H));
            if (x < 2 * W)
                mp &= same(image_at(&p, x, y), image_at(&p, 2 * W - 1 - x, y));
            if (y < 2 * H)
                mp &= same(image_at(&p, x, y), image_at(&p, x, 2 * H - 1 - y));
        }
    CHECK(mp, "mirrored tiling: period 2tw x 2th, mirror-symmetric across tile seams");
    CHECK(same(image_at(&p, W, 0), image_at(&src, W - 1, 0)), "second tile is flipped");
    image_free(&p);
    CHECK(tiles_fill(&src, 0, 5, 0, &p, &e) == RT_EINVAL &&
              strcmp(e.msg, "tiled canvas 0×5 is empty") == 0,
          "empty canvas: %s", e.msg);
    image_free(&src);
    return check_done("test_tiles");
}
