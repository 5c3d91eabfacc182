/* test_tonemap.c — pending pixels (image.h) from tonemap_defer: the same
 * floats and file bytes as tonemap_apply, band boundaries of the PNG
 * encoder, ownership of the histogram, and pixel values worked out by hand.
 * (The tone-map formulas themselves: test_chaos.c's test_tonemap.) */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "png.h"
#include "pnm.h"
#include "tonemap.h"

/* A histogram whose bins all differ in an asymmetric pattern (no two rows,
 * no two columns alike), counts both below and past the 4096-entry table. */
static void fill(hist2 *hs)
{
    for (int y = 0; y < hs->h; y++)
        for (int x = 0; x < hs->w; x++) {
            size_t b = (size_t)y * hs->w + x;
            hs->count[b] = (x * 7 + y * y * 3) % 11 == 0 ? 0 : (uint64_t)(x * 13 + y * 5) % 5000;
            if (x == 3 && y == 2)
                hs->count[b] = 100000; /* M */
            if (hs->csum)
                for (int ch = 0; ch < 3; ch++)
                    hs->csum[3 * b + ch] = (float)hs->count[b] * (float)((x + ch * y) % 5) / 4.0f;
        }
}

static int same_bytes(const bytebuf *a, const bytebuf *b)
{
    return a->len == b->len && memcmp(a->data, b->data, a->len) == 0;
}

/* One render both ways: im_a eagerly, im_b pending; then PNG (8 and 16 bit),
 * PPM and the floats compared. w = 700 makes the PNG encoder's bands 23
 * rows (65536 / (700 * 4)), so 50 rows end in a short band. */
static void both_ways(int k, const tonemap_opts *o, int with_colour, const char *what)
{
    rt_error e;
    const int w = 700, h = 50;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    hist2 ha, hb;
    CHECK(hist2_init(&ha, w * k, h * k, lo, hi, with_colour, &e) == RT_OK &&
              hist2_init(&hb, w * k, h * k, lo, hi, with_colour, &e) == RT_OK,
          "%s: histograms", what);
    fill(&ha);
    fill(&hb);
    image a, b;
    CHECK(image_init(&a, w, h, &e) == RT_OK && image_init(&b, w, h, &e) == RT_OK, "%s: images", what);
    CHECK(tonemap_apply(&ha, o, &a, &e) == RT_OK, "%s: apply", what);
    CHECK(tonemap_defer(&hb, o, &b, &e) == RT_OK, "%s: defer", what);
    CHECK(b.src != NULL && hb.count == NULL && hb.csum == NULL && hb.mem_count == NULL,
          "%s: the image owns the bins", what);
    hist2_free(&hb); /* harmless on the emptied histogram */
    size_t nf = (size_t)w * h * 4, unwritten = 0;
    for (size_t i = 0; i < nf; i++)
        unwritten += b.px[i] == 0.0f;
    CHECK(unwritten == nf, "%s: pending pixels are not written (%zu of %zu zero)", what, unwritten, nf);
    int bits[2] = {8, 16}, chans[2] = {4, 1};
    for (int t = 0; t < 2; t++) {
        bytebuf pa, pb;
        bytebuf_init(&pa), bytebuf_init(&pb);
        CHECK(png_encode(&a, bits[t], chans[t], &pa, &e) == RT_OK &&
                  png_encode(&b, bits[t], chans[t], &pb, &e) == RT_OK,
              "%s: png", what);
        CHECK(same_bytes(&pa, &pb), "%s: %d-bit PNG, pending and ready give the same bytes (%zu, %zu)",
              what, bits[t], pa.len, pb.len);
        bytebuf_free(&pa), bytebuf_free(&pb);
    }
    CHECK(b.src != NULL, "%s: the PNG encode leaves the pixels pending", what);
    /* rows of a pending image, a band not starting at row 0 */
    float row[2][700 * 4];
    image_rows(&a, 37, 38, row[0]);
    image_rows(&b, 37, 38, row[1]);
    CHECK(memcmp(row[0], row[1], sizeof row[0]) == 0, "%s: image_rows 37", what);
    bytebuf qa, qb;
    bytebuf_init(&qa), bytebuf_init(&qb);
    CHECK(pnm_encode(&a, 16, 3, &qa, &e) == RT_OK && pnm_encode(&b, 16, 3, &qb, &e) == RT_OK, "%s: ppm", what);
    CHECK(same_bytes(&qa, &qb), "%s: PPM of the pending image", what);
    CHECK(b.src == NULL, "%s: the PPM writer made the pixels ready", what);
    bytebuf_free(&qa), bytebuf_free(&qb);
    CHECK(memcmp(a.px, b.px, nf * sizeof(float)) == 0, "%s: the same floats", what);
    image_free(&a), image_free(&b);
    hist2_free(&ha);
}

/* M, the largest count, wherever it lies: first bin, the end of a 64-bin
 * block, the start of the next, the short tail (the maximum pass skips
 * blocks by their OR); every other bin holds an OR-rich pattern below M.
 * Linear grey: a bin of count c is c / M, so a wrong M shows everywhere. */
static void test_max_anywhere(void)
{
    rt_error e;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    const int w = 64 * 3 + 5; /* 197 bins: three blocks and a tail of 5 */
    int where[] = {0, 63, 64, 130, 191, 192, 196};
    for (size_t t = 0; t < sizeof where / sizeof where[0]; t++) {
        hist2 hs;
        image im;
        CHECK(hist2_init(&hs, w, 1, lo, hi, 0, &e) == RT_OK && image_init(&im, w, 1, &e) == RT_OK, "hist");
        const uint64_t M = 1000;
        for (int b = 0; b < w; b++)
            hs.count[b] = (uint64_t)(b * 37 % 999); /* below M; ORs of blocks reach 1023 > M */
        hs.count[where[t]] = M;
        tonemap_opts o = {0};
        o.curve = TONEMAP_LINEAR;
        CHECK(tonemap_apply(&hs, &o, &im, &e) == RT_OK, "apply");
        int bad = 0;
        for (int b = 0; b < w; b++) {
            double want = hs.count[b] ? (double)hs.count[b] / (double)M : 0;
            bad += fabs(im.px[4 * b] - want) > 1e-6;
        }
        CHECK(bad == 0, "maximum at bin %d: %d pixels off", where[t], bad);
        image_free(&im);
        hist2_free(&hs);
    }
}

int main(void)
{
    test_max_anywhere();
    ramp rp = ramp_grey();
    rp.n = 3; /* red, green at 0.3, blue: channels that differ */
    double pos[3] = {0, 0.3, 1};
    float col[3][4] = {{1, 0, 0, 1}, {0, 1, 0, 0.5f}, {0, 0, 1, 0.25f}};
    for (int i = 0; i < 3; i++) {
        rp.pos[i] = pos[i];
        memcpy(rp.rgba[i], col[i], sizeof col[i]);
    }
    tonemap_opts o = {0};
    o.curve = TONEMAP_LOG;
    o.gamma = 2.2;
    o.ramp = &rp;
    o.bg[0] = 0.1f, o.bg[3] = 1;
    both_ways(1, &o, 0, "ramp, k = 1");
    both_ways(2, &o, 0, "ramp, k = 2");
    o.colour = TONEMAP_MEAN;
    o.curve = TONEMAP_LINEAR;
    both_ways(1, &o, 1, "mean colour, k = 1");
    both_ways(3, &o, 1, "mean colour, k = 3");

    /* values by hand, read through the pending path only: grey log ramp,
     * M = 100000 at (3, 2); bin (0, 0) is empty (background) */
    rt_error e;
    double lo[2] = {0, 0}, hi[2] = {1, 1};
    hist2 hs;
    image im;
    CHECK(hist2_init(&hs, 5, 4, lo, hi, 0, &e) == RT_OK && image_init(&im, 5, 4, &e) == RT_OK, "small");
    fill(&hs);
    tonemap_opts g = {0};
    g.bg[2] = 0.5f, g.bg[3] = 1;
    uint64_t c41 = hs.count[1 * 5 + 4];
    CHECK(hs.count[0] == 0 && c41 > 0, "bins of the small case");
    CHECK(tonemap_defer(&hs, &g, &im, &e) == RT_OK, "defer");
    float px[5 * 4 * 4];
    image_rows(&im, 0, 4, px);
    CHECK(px[0] == 0 && px[1] == 0 && px[2] == 0.5f && px[3] == 1, "empty bin: the background");
    CHECK_NEAR(px[4 * (2 * 5 + 3)], 1.0, 1e-6, "the maximum is white");
    CHECK_NEAR(px[4 * (1 * 5 + 4) + 1], log1p((double)c41) / log1p(100000.0), 1e-6, "log density of (4, 1)");
    image_free(&im); /* frees the bins it owns (ASan: no leak) */

    /* a failed defer leaves both sides alone */
    CHECK(hist2_init(&hs, 4, 2, lo, hi, 0, &e) == RT_OK && image_init(&im, 3, 1, &e) == RT_OK, "mismatch");
    CHECK(tonemap_defer(&hs, &g, &im, &e) == RT_EINVAL &&
              strcmp(e.msg, "histogram 4×2 is not a whole multiple k×k of the image 3×1") == 0,
          "size message: %s", e.msg);
    CHECK(hs.count != NULL && hs.w == 4 && im.src == NULL, "nothing moved on failure");
    image_free(&im);
    hist2_free(&hs);
    return check_done("test_tonemap");
}
