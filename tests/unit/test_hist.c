/* test_hist.c — where a plane point lands in a histogram (fset_hist_bin,
 * hist.h: row 0 at the top), the measure image of a histogram
 * (chaos_measure2, seed 001 §5: μ(B) ≈ N(B)/n) and the equal-probability
 * choice of fset_choose(NULL, …). Every expected value is worked out by hand
 * in the comments; each check was added for a mutation the suite let pass
 * (tests/README.md, "Mutation table"). */
#include "check.h"
#include "chaos.h"
#include "fset.h"
#include "hist.h"
#include "image.h"
#include "rng.h"

/* a 4×2 histogram over [0,4]×[0,2]: cells are 1×1, row 0 holds 1 <= y < 2 */
static void test_bins(void)
{
    hist2 hs;
    rt_error e;
    CHECK(hist2_init(&hs, 4, 2, (double[]){0, 0}, (double[]){4, 2}, 0, &e) == RT_OK, "init: %s", e.msg);
    CHECK(fset_hist_bin(&hs, 0.5, 1.5) == 0, "(0.5, 1.5) is the top-left cell");
    CHECK(fset_hist_bin(&hs, 3.5, 1.5) == 3, "(3.5, 1.5) is the top-right cell");
    CHECK(fset_hist_bin(&hs, 0.5, 0.5) == 4, "(0.5, 0.5) is the bottom-left cell");
    CHECK(fset_hist_bin(&hs, 2.5, 0.25) == 6, "(2.5, 0.25): column 2 of row 1");
    CHECK(fset_hist_bin(&hs, 1.0, 2.0) == 1, "the top edge y = 2 is in row 0");
    CHECK(fset_hist_bin(&hs, 1.0, 0.0) == -1, "the bottom edge y = 0 is outside");
    CHECK(fset_hist_bin(&hs, 4.0, 1.0) == -1, "the right edge x = 4 is outside");
    CHECK(fset_hist_bin(&hs, -0.1, 1.0) == -1, "left of the window");
    CHECK(fset_hist_bin(&hs, NAN, 1.0) == -1, "NaN");
    hist2_free(&hs);
}

/* counts 3 in cell 0 and 1 in cell 5 of 8 plotted points (4 fell outside) */
static void test_measure(void)
{
    hist2 hs;
    image im;
    rt_error e;
    CHECK(hist2_init(&hs, 4, 2, (double[]){0, 0}, (double[]){4, 2}, 0, &e) == RT_OK, "init: %s", e.msg);
    CHECK(image_init(&im, 4, 2, &e) == RT_OK, "image: %s", e.msg);
    hs.count[0] = 3;
    hs.count[5] = 1;
    const struct {
        chaos_norm norm;
        double c0, c5;
        const char *what;
    } want[] = {
        {CHAOS_NORM_TOTAL, 3.0 / 8, 1.0 / 8, "total: N(B)/8"},
        {CHAOS_NORM_MAX, 1.0, 1.0 / 3, "max: N(B)/3"},
        {CHAOS_NORM_COUNT, 3.0, 1.0, "count: N(B)"},
    };
    for (int k = 0; k < 3; k++) {
        CHECK(chaos_measure2(&hs, want[k].norm, 8, &im, &e) == RT_OK, "measure: %s", e.msg);
        CHECK_NEAR(im.px[0], want[k].c0, 1e-7, want[k].what);
        CHECK_NEAR(im.px[4 * 5 + 2], want[k].c5, 1e-7, want[k].what);
        CHECK(im.px[4 * 1] == 0 && im.px[4 * 7 + 1] == 0, "%s: empty cells are 0", want[k].what);
        CHECK(im.px[3] == 1 && im.px[4 * 7 + 3] == 1, "%s: alpha 1", want[k].what);
    }
    image_free(&im);
    hist2_free(&hs);
}

/* fset_choose(NULL, n, h): index floor(u n) with u = h / 2^64 (53 bits) */
static void test_choose_uniform(void)
{
    CHECK(fset_choose(NULL, 3, 0) == 0, "h = 0 picks the first index");
    CHECK(fset_choose(NULL, 3, UINT64_MAX) == 2, "the largest h picks the last index");
    CHECK(fset_choose(NULL, 4, (uint64_t)1 << 63) == 2, "u = 1/2 of 4 is index 2");
    int n[3] = {0, 0, 0};
    for (uint64_t k = 0; k < 30000; k++)
        n[fset_choose(NULL, 3, rng_hash3(7, k, 0, 0))]++;
    /* 10000 each; one standard deviation is sqrt(30000 · 1/3 · 2/3) ≈ 82 */
    for (int i = 0; i < 3; i++)
        CHECK(n[i] > 9600 && n[i] < 10400, "index %d chosen %d times of 30000", i, n[i]);
}

/* Big arrays start on a 2 MiB boundary (hist.c: all of them in huge pages)
 * and are zero; small ones are plain blocks. 1024² counts are 8 MiB, the
 * colour sums 12 MiB. */
static void test_alignment(void)
{
    hist2 hs;
    rt_error e;
    CHECK(hist2_init(&hs, 1024, 1024, (double[]){0, 0}, (double[]){1, 1}, 1, &e) == RT_OK, "init: %s", e.msg);
    CHECK((uintptr_t)hs.count % (2u << 20) == 0, "counts at %p", (void *)hs.count);
    CHECK((uintptr_t)hs.csum % (2u << 20) == 0, "colour sums at %p", (void *)hs.csum);
    int nonzero = 0;
    for (size_t b = 0; b < 1024 * 1024; b++)
        nonzero += hs.count[b] != 0 || hs.csum[3 * b] != 0 || hs.csum[3 * b + 2] != 0;
    CHECK(nonzero == 0, "%d bins not zero", nonzero);
    hs.count[1024 * 1024 - 1] = 7; /* the last bin is inside the block */
    hist2_free(&hs);
    CHECK(hs.count == NULL && hs.csum == NULL, "freed");
    CHECK(hist2_init(&hs, 4, 2, (double[]){0, 0}, (double[]){4, 2}, 0, &e) == RT_OK, "small: %s", e.msg);
    CHECK(hs.count == hs.mem_count && hs.csum == NULL, "a small histogram is its block");
    hist2_free(&hs);
}

/* hist_zeroed's array lies inside the block it asked for, however far the
 * 2 MiB boundary is from the block's start, and a size the slack would
 * wrap past SIZE_MAX is refused, not served from a small block. */
static void test_zeroed_block(void)
{
    void *mem;
    check_limits(-1, -1, -1); /* records the largest block asked for */
    size_t bytes = (size_t)5 << 20;
    unsigned char *p = hist_zeroed(bytes, 1, &mem);
    size_t asked = check_hs.peak;
    check_limits_off();
    CHECK(p != NULL, "5 MiB");
    CHECK(p && (unsigned char *)mem <= p && p + bytes <= (unsigned char *)mem + asked,
          "array [%p, +%zu) outside its block [%p, +%zu)", (void *)p, bytes, mem, asked);
    rt_free(mem);
    CHECK(hist_zeroed(SIZE_MAX - 1, 1, &mem) == NULL, "SIZE_MAX - 1 bytes were served");
    rt_free(mem);
}

int main(void)
{
    test_alignment();
    test_zeroed_block();
    test_bins();
    test_measure();
    test_choose_uniform();
    return check_done("test_hist");
}
