/* hist.h — 2-D hit-count histograms, what every chaos game accumulates into.
 *
 * A histogram covers the window [lo[0], hi[0]] × [lo[1], hi[1]] of the plane
 * with w × h bins; bin (0, 0) is the top-left of the picture, i.e. x = lo[0]
 * and y = hi[1] (y grows upward in the plane, downward in the image).
 * count[i] is the number of hits; csum (optional, 3 floats per bin) is the
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
    uint64_t *count; /* w * h */
    float *csum;     /* w * h * 3, or NULL */
    void *mem_count, *mem_csum; /* the blocks they lie in (hist.c aligns big arrays) */
} hist2;

rt_code hist2_init(hist2 *hs, int w, int h, const double lo[2], const double hi[2], int with_colour,
                   rt_error *e);
void hist2_free(hist2 *hs);

/* n × size zero bytes for a big accumulator; arrays of 4 MiB and more start
 * on a 2 MiB boundary inside a larger block (all in huge pages, see
 * rt_calloc_huge). *mem gets the block to rt_free; NULL when out of memory. */
void *hist_zeroed(size_t n, size_t size, void **mem);

#endif
