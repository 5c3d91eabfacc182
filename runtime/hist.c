/* hist.c — allocation of 2-D hit-count histograms. */
#include "hist.h"
#include "rt_alloc.h"

#include <stdlib.h>
#include <string.h>

/* big arrays lie in huge pages: zeroing a 1024² histogram costs 4 page
 * faults instead of ~520 (rt_calloc_huge) */
void *hist_zeroed(size_t n, size_t size, void **mem)
{
    return rt_calloc_huge(n, size, mem);
}

rt_code hist2_init(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                   rt_error *e)
{
    return hist2_init_for(hs, w, h, lo, hi, with_colour, UINT64_MAX, e);
}

rt_code hist2_init_for(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                       uint64_t hits, rt_error *e)
{
    hs->w = hs->h = 0;
    hs->count = NULL;
    hs->count32 = NULL;
    hs->csum = NULL;
    hs->mem_count = hs->mem_csum = NULL;
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "histogram size %d×%d is empty", w, h);
    size_t n = rt_mul_size((size_t)w, (size_t)h);
    int narrow = hist2_narrow(hits);
    if (narrow)
        hs->count32 = hist_zeroed(n, sizeof *hs->count32, &hs->mem_count);
    else
        hs->count = hist_zeroed(n, sizeof *hs->count, &hs->mem_count);
    if (with_colour)
        hs->csum = hist_zeroed(rt_mul_size(n, 3), sizeof *hs->csum, &hs->mem_csum);
    if (!(narrow ? (void *)hs->count32 : (void *)hs->count) || (with_colour && !hs->csum)) {
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
    hs->count32 = NULL;
    hs->csum = NULL;
    hs->mem_count = hs->mem_csum = NULL;
}
