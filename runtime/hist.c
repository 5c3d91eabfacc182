/* hist.c — allocation of 2-D hit-count histograms. */
#include "hist.h"
#include "rt_alloc.h"

#include <stdlib.h>

rt_code hist2_init(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                   rt_error *e)
{
    hs->w = hs->h = 0;
    hs->count = NULL;
    hs->csum = NULL;
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "histogram size %d×%d is empty", w, h);
    size_t n = rt_mul_size((size_t)w, (size_t)h);
    hs->count = rt_calloc(n, sizeof *hs->count);
    if (with_colour)
        hs->csum = rt_calloc(rt_mul_size(n, 3), sizeof *hs->csum);
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
    rt_free(hs->count);
    rt_free(hs->csum);
    hs->count = NULL;
    hs->csum = NULL;
}
