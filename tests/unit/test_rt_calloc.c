/* test_rt_calloc.c — rt_calloc through the hook's zalloc (rt_alloc.h): the
 * block is zeroed, counted like any allocation, and a hook without zalloc
 * still gets zeroed blocks (alloc + memset), also where the memory was
 * dirty before. rt_calloc_huge: big arrays start on a 2 MiB boundary (so
 * images and histograms lie in huge pages), zeroed, inside a block the hook
 * sees 2 MiB larger; small ones are plain blocks. */
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "image.h"

static size_t n_alloc, n_zalloc, live;

static void *t_alloc(void *ud, void *p, size_t osize, size_t nsize)
{
    (void)ud;
    live -= osize;
    if (nsize == 0) {
        free(p);
        return NULL;
    }
    n_alloc++;
    live += nsize;
    void *q = realloc(p, nsize);
    if (q && !p)
        memset(q, 0xA5, nsize); /* dirty, as reused memory would be */
    return q;
}

static void *t_zalloc(void *ud, size_t nsize)
{
    (void)ud;
    n_zalloc++;
    live += nsize;
    return calloc(1, nsize);
}

static int all_zero(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i])
            return 0;
    return 1;
}

int main(void)
{
    const size_t big = (size_t)9 << 20, small = 1000;
    /* no hook: libc calloc */
    for (int r = 0; r < 2; r++) {
        unsigned char *p = rt_calloc(big, 1);
        CHECK(p && all_zero(p, big), "rt_calloc without a hook: round %d not zeroed", r);
        if (p)
            memset(p, 0xFF, big); /* the next round must not see this */
        rt_free(p);
    }
    CHECK(rt_calloc(SIZE_MAX / 2, 4) == NULL, "an overflowing count * size fails");

    /* a hook with zalloc: used for rt_calloc, and accounted */
    static const rt_alloc_hook hz = {t_alloc, NULL, NULL, t_zalloc};
    rt_alloc_set_hook(&hz);
    unsigned char *a = rt_calloc(big / 8, 8), *b = rt_calloc(small, 1);
    CHECK(a && all_zero(a, big) && b && all_zero(b, small), "zalloc blocks are zero");
    CHECK(n_zalloc == 2 && n_alloc == 0, "rt_calloc went through zalloc (%zu zalloc, %zu alloc)", n_zalloc, n_alloc);
    CHECK(live >= big + small && live < big + small + 128, "the hook saw %zu bytes for %zu", live, big + small);
    unsigned char *c = rt_realloc(b, 2 * small); /* a zalloc block grows like any */
    CHECK(c && all_zero(c, small), "realloc keeps the zeroed bytes");
    rt_free(a);
    rt_free(c);
    CHECK(live == 0, "everything freed through the hook (%zu left)", live);

    /* a hook without zalloc: alloc (dirty memory) then cleared */
    static const rt_alloc_hook ha = {t_alloc, NULL, NULL, NULL};
    rt_alloc_set_hook(&ha);
    n_alloc = n_zalloc = 0;
    unsigned char *d = rt_calloc(small, 3);
    CHECK(d && all_zero(d, 3 * small), "alloc + memset zeroes dirty memory");
    CHECK(n_alloc == 1 && n_zalloc == 0, "no zalloc: alloc used (%zu alloc)", n_alloc);
    rt_free(d);
    CHECK(live == 0, "freed (%zu left)", live);

    /* rt_calloc_huge through the zalloc hook, over dirty memory around it */
    rt_alloc_set_hook(&hz);
    const size_t two = (size_t)2 << 20;
    void *mem = NULL, *mem2 = NULL;
    unsigned char *h = rt_calloc_huge(big / 4, 4, &mem), *s2 = rt_calloc_huge(small, 4, &mem2);
    CHECK(h && mem && (uintptr_t)h % two == 0, "a 9 MiB array starts on a 2 MiB boundary (%p)", (void *)h);
    CHECK(h && h >= (unsigned char *)mem && h < (unsigned char *)mem + two, "it lies in its block's first 2 MiB");
    CHECK(h && all_zero(h, big), "and is zero");
    CHECK(s2 && s2 == mem2 && all_zero(s2, 4 * small), "a small array is its own block, zeroed");
    CHECK(live >= big + two + 4 * small && live < big + two + 4 * small + 256,
          "the hook counts the 2 MiB slack (%zu bytes for %zu)", live, big + 4 * small);
    rt_free(mem);
    rt_free(mem2);
    CHECK(live == 0, "freed through mem (%zu left)", live);
    CHECK(rt_calloc_huge(SIZE_MAX / 2, 4, &mem) == NULL && mem == NULL, "an overflowing size fails");

    /* images use it: a 1024² image (16 MiB) is aligned, a 10×10 one is not padded */
    rt_error e;
    image im, sm;
    CHECK(image_init(&im, 1024, 1024, &e) == RT_OK && (uintptr_t)im.px % two == 0,
          "a 1024² image starts on a 2 MiB boundary");
    CHECK(image_init(&sm, 10, 10, &e) == RT_OK && (void *)sm.px == sm.mem, "a 10×10 image is its own block");
    CHECK(all_zero((const unsigned char *)im.px, (size_t)1024 * 1024 * 16), "the image is transparent black");
    image_free(&im);
    image_free(&sm);
    CHECK(live == 0, "images freed (%zu left)", live);
    rt_alloc_set_hook(NULL);
    return check_done("test_rt_calloc");
}
