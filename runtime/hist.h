/* hist.h — 2-D hit-count histograms, what every chaos game accumulates into.
 *
 * A histogram covers the window [lo[0], hi[0]] × [lo[1], hi[1]] of the plane
 * with w × h bins; bin (0, 0) is the top-left of the picture, i.e. x = lo[0]
 * and y = hi[1] (y grows upward in the plane, downward in the image).
 * Bin i holds the number of hits, in one of two widths: count32[i] (uint32)
 * when the histogram is made for fewer than 2^32 hits in all, so no bin can
 * overflow — half the memory for the kernel to zero and the caches to hold
 * — and count[i] (uint64) otherwise; exactly one of the two is non-NULL.
 * hist2_get reads either. csum (optional, 3 floats per bin) is the
 * sum of the colours of the hits (colour by map index or colour coordinate),
 * so the mean colour of a bin is csum/count. Tone mapping to an image lives
 * in tonemap.h.
 */
#ifndef HIST_H
#define HIST_H

#include <stddef.h>
#include <stdint.h>

#include "rt.h"

typedef struct hist2 {
    int w, h;
    double lo[2], hi[2];
    uint64_t *count;   /* w * h, or NULL (narrow) */
    uint32_t *count32; /* w * h, or NULL (wide) */
    float *csum;     /* w * h * 3, or NULL */
    void *mem_count, *mem_csum; /* the blocks they lie in (hist.c aligns big arrays) */
} hist2;

/* A histogram with uint64 counts (any number of hits). */
rt_code hist2_init(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                   rt_error *e);
/* A histogram for at most `hits` hits over its whole life (every call that
 * adds to it): uint32 counts when hist2_narrow(hits), else uint64. */
rt_code hist2_init_for(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                       uint64_t hits, rt_error *e);
void hist2_free(hist2 *hs);

/* Whether `hits` hits fit every bin in 32 bits: hits < 2^32. */
static inline int hist2_narrow(uint64_t hits) { return hits <= UINT32_MAX; }

/* The count of bin b. */
static inline uint64_t hist2_get(const hist2 *hs, size_t b)
{
    return hs->count32 ? hs->count32[b] : hs->count[b];
}

/* Add v hits to bin b (the caller keeps the total within the width). */
static inline void hist2_add(hist2 *hs, size_t b, uint64_t v)
{
    if (hs->count32)
        hs->count32[b] += (uint32_t)v;
    else
        hs->count[b] += v;
}

/* n × size zero bytes for a big accumulator; arrays of 4 MiB and more start
 * on a 2 MiB boundary inside a larger block (all in huge pages, see
 * rt_calloc_huge). *mem gets the block to rt_free; NULL when out of memory. */
void *hist_zeroed(size_t n, size_t size, void **mem);

#endif
