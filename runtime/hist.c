/* hist.c — allocation of 2-D hit-count histograms. */
#include "hist.h"
#include "rt_alloc.h"

#include <stdlib.h>
#include <string.h>

/* Big arrays start on a 2 MiB boundary inside a block 2 MiB larger: the
 * allocator asks for transparent huge pages on a block's 2 MiB-aligned
 * interior (rt_alloc.c), so the whole array is in huge pages and zeroing a
 * 1024² histogram costs 4 page faults instead of ~520 (the unaligned head
 * and tail in 4 KiB pages; a fault costs more than writing its page on
 * these machines). The slack is never touched (no RSS) but is counted by
 * the memory budget. */
#define HUGE_ALIGN ((size_t)2 << 20)

void *hist_zeroed(size_t n, size_t size, void **mem)
{
    size_t bytes = rt_mul_size(n, size);
    if (bytes < 2 * HUGE_ALIGN || bytes > SIZE_MAX - HUGE_ALIGN)
        return *mem = rt_calloc(n, size);
    /* rt_calloc, not malloc + memset: a fresh block of this size comes from
     * the kernel already zero, and calloc then skips the clearing */
    char *p = *mem = rt_calloc(bytes + HUGE_ALIGN, 1);
    if (!p)
        return NULL;
    p += (HUGE_ALIGN - (uintptr_t)p % HUGE_ALIGN) % HUGE_ALIGN;
    return p;
}

rt_code hist2_init(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                   rt_error *e)
{
    hs->w = hs->h = 0;
    hs->count = NULL;
    hs->csum = NULL;
    hs->mem_count = hs->mem_csum = NULL;
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "histogram size %d×%d is empty", w, h);
    size_t n = rt_mul_size((size_t)w, (size_t)h);
    hs->count = hist_zeroed(n, sizeof *hs->count, &hs->mem_count);
    if (with_colour)
        hs->csum = hist_zeroed(rt_mul_size(n, 3), sizeof *hs->csum, &hs->mem_csum);
    if (!hs->count || (with_colour && !hs->csum)) {
        hist2_free(hs);
        return rt_fail(e, RT_ENOMEM, "out of memory for a %d×%d histogram", w, h);
    }
    hs->w = w;
    hs->h = h;
    for (int i = 0; i < 2; i++) {
        hs->lo[i] = lo[i];
        hs->hi[i] = hi[i];
    }
    return RT_OK;
}

void hist2_free(hist2 *hs)
{
    rt_free(hs->mem_count);
    rt_free(hs->mem_csum);
    hs->count = NULL;
    hs->csum = NULL;
    hs->mem_count = hs->mem_csum = NULL;
}
