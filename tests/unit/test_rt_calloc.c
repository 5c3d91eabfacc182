/* test_rt_calloc.c — rt_calloc through the hook's zalloc (rt_alloc.h): the
 * block is zeroed, counted like any allocation, and a hook without zalloc
 * still gets zeroed blocks (alloc + memset), also where the memory was
 * dirty before. */
#include <stdint.h>
#include <string.h>

#include "check.h"

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
    rt_alloc_set_hook(NULL);
    return check_done("test_rt_calloc");
}
