/* tails.h — the k-th smallest and k-th largest of a stream of values, in
 * two heaps of k values, without storing the stream: what sorting all the
 * values and reading a[k-1] and a[n-k] gives (for values that are not NaN;
 * among values that compare equal only +0 and -0 differ in their bits).
 * The pre-passes that fit a window or a box to a chaos game take their
 * 0.1 % quantiles this way (chaos.c fit_tails, fset.c fset_chaos_box).
 *
 * Fill: tails_heap_offer(h, i, k, v) for the i-th value (i < k), and
 * tails_heap_offer(hh, i, k, -v) for the largest. Then, with *lo = hl[0]
 * and *hi = -hh[0] kept in registers, tails_offer for each further value:
 * almost every value of a long stream fails both tests and costs two
 * comparisons. hl[0] is the k-th smallest, -hh[0] the k-th largest. */
#ifndef TAILS_H
#define TAILS_H

#include <stddef.h>

#if defined(__GNUC__)
#define TAILS_INLINE static inline __attribute__((always_inline))
#define TAILS_CALL static __attribute__((noinline, unused)) /* rare: out of the hot loop */
#else
#define TAILS_INLINE static inline
#define TAILS_CALL static inline
#endif

/* Offer v to a max-heap h of at most k values (n of them now): it keeps
 * the k smallest values offered, the k-th smallest on top. */
TAILS_CALL void tails_heap_offer(double *h, size_t n, size_t k, double v)
{
    size_t i;
    if (n < k) {
        for (i = n; i > 0 && h[(i - 1) / 2] < v; i = (i - 1) / 2)
            h[i] = h[(i - 1) / 2];
        h[i] = v;
        return;
    }
    if (!(v < h[0]))
        return;
    for (i = 0;;) {
        size_t c = 2 * i + 1;
        if (c >= k)
            break;
        if (c + 1 < k && h[c + 1] > h[c])
            c++;
        if (!(h[c] > v))
            break;
        h[i] = h[c];
        i = c;
    }
    h[i] = v;
}

/* Offer v to full heaps hl (smallest) and hh (largest, negated); *lo and
 * *hi hold their tops (hl[0] and -hh[0]). The tests are
 * tails_heap_offer's own (v < hl[0], and -v < hh[0]), made before the call. */
TAILS_INLINE void tails_offer(double *hl, double *hh, size_t k, double v, double *lo, double *hi)
{
    if (v < *lo) {
        tails_heap_offer(hl, k, k, v);
        *lo = hl[0];
    }
    if (v > *hi) {
        tails_heap_offer(hh, k, k, -v);
        *hi = -hh[0];
    }
}

#endif
