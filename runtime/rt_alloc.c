/* rt_alloc.c — the runtime's allocator and its one hook (see rt_alloc.h). */
#define _DEFAULT_SOURCE /* madvise's MADV_HUGEPAGE (Linux) */
#include "rt_alloc.h"

#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

/* Each block starts with its size, padded to keep max_align_t alignment,
 * so rt_free can tell the hook how many bytes it releases. */
typedef union blkhdr {
    size_t size;
    max_align_t align;
} blkhdr;

static const rt_alloc_hook *_Atomic g_hook;

void rt_alloc_set_hook(const rt_alloc_hook *h)
{
    atomic_store(&g_hook, h);
}

static void *raw(void *p, size_t osize, size_t nsize)
{
    const rt_alloc_hook *h = atomic_load(&g_hook);
    if (h && h->alloc)
        return h->alloc(h->ud, p, osize, nsize);
    if (nsize == 0) {
        free(p);
        return NULL;
    }
    return realloc(p, nsize);
}

/* Big fresh buffers (histograms, images, volumes, codec rows) are touched
 * for the first time soon after they are allocated: in 4 KiB pages that is
 * one page fault per page, which on these virtual machines costs more than
 * writing the page. Asking for transparent huge pages on the 2 MiB-aligned
 * interior makes it one fault per 2 MiB where the kernel allows it (a hint:
 * without THP nothing changes; the bytes and the accounting are the same). */
#define HUGE_HINT ((size_t)4 << 20)
static void huge_hint(void *p, size_t n)
{
#if defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    uintptr_t a = ((uintptr_t)p + huge - 1) & ~(huge - 1), b = ((uintptr_t)p + n) & ~(huge - 1);
    if (b > a)
        (void)madvise((void *)a, b - a, MADV_HUGEPAGE);
#else
    (void)p, (void)n;
#endif
}

void *rt_realloc(void *p, size_t n)
{
    if (n > SIZE_MAX - sizeof(blkhdr))
        return NULL;
    blkhdr *old = p ? (blkhdr *)p - 1 : NULL;
    size_t osize = old ? old->size + sizeof(blkhdr) : 0;
    blkhdr *b = raw(old, osize, n + sizeof(blkhdr));
    if (!b)
        return NULL;
    b->size = n;
    if (!old && n >= HUGE_HINT)
        huge_hint(b, n + sizeof(blkhdr));
    return b + 1;
}

void *rt_malloc(size_t n)
{
    return rt_realloc(NULL, n);
}

void *rt_mallocn(size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return NULL;
    return rt_realloc(NULL, count * size);
}

void *rt_calloc(size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return NULL;
    size_t n = count * size;
    const rt_alloc_hook *h = atomic_load(&g_hook);
    if (n > SIZE_MAX - sizeof(blkhdr) || (h && h->alloc && !h->zalloc)) {
        void *p = rt_malloc(n);
        if (p)
            memset(p, 0, n);
        return p;
    }
    /* zeroed by calloc (fresh pages from the kernel are not written) */
    blkhdr *b = h ? h->zalloc(h->ud, n + sizeof(blkhdr)) : calloc(1, n + sizeof(blkhdr));
    if (!b)
        return NULL;
    b->size = n;
    if (n >= HUGE_HINT)
        huge_hint(b, n + sizeof(blkhdr));
    return b + 1;
}

void *rt_reallocn(void *p, size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size)
        return NULL;
    return rt_realloc(p, count * size);
}

void rt_free(void *p)
{
    if (!p)
        return;
    blkhdr *b = (blkhdr *)p - 1;
    raw(b, b->size + sizeof(blkhdr), 0);
}

#define HUGE_ALIGN ((size_t)2 << 20)
void *rt_calloc_huge(size_t count, size_t size, void **mem)
{
    size_t bytes = size && count > SIZE_MAX / size ? SIZE_MAX : count * size;
    if (bytes < 2 * HUGE_ALIGN || bytes > SIZE_MAX - 2 * HUGE_ALIGN)
        return *mem = rt_calloc(count, size);
    /* rt_calloc, not malloc + memset: a fresh block of this size comes from
     * the kernel already zero, and calloc then skips the clearing */
    char *p = *mem = rt_calloc(bytes + HUGE_ALIGN, 1);
    if (!p)
        return NULL;
    return p + (HUGE_ALIGN - (uintptr_t)p % HUGE_ALIGN) % HUGE_ALIGN;
}

char *rt_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = rt_malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* ---- limits a decoder checks before allocating ---------------------------------- */

static double get_limit(rt_limit k, const char **flag)
{
    const rt_alloc_hook *h = atomic_load(&g_hook);
    *flag = NULL;
    if (!h || !h->limit)
        return -1;
    return h->limit(h->ud, k, flag);
}

static rt_code over(rt_error *e, const char *what, double lim, const char *unit, const char *flag)
{
    if (flag)
        return rt_fail(e, RT_ELIMIT, "%s exceeds the limit of %.0f %s (raise it with %s)", what, lim, unit, flag);
    return rt_fail(e, RT_ELIMIT, "%s exceeds the limit of %.0f %s", what, lim, unit);
}

rt_code rt_check_pixels(double w, double h, rt_error *e)
{
    const char *flag;
    double lim = get_limit(RT_LIMIT_PIXELS, &flag);
    if (lim >= 0 && !(w * h <= lim)) {
        char what[128];
        snprintf(what, sizeof what, "image of %.0f×%.0f pixels", w, h);
        return over(e, what, lim, "pixels", flag);
    }
    return RT_OK;
}

rt_code rt_check_voxels(double nx, double ny, double nz, rt_error *e)
{
    const char *flag;
    double lim = get_limit(RT_LIMIT_VOXELS, &flag);
    if (lim >= 0 && !(nx * ny * nz <= lim)) {
        char what[160];
        snprintf(what, sizeof what, "volume of %.0f×%.0f×%.0f voxels", nx, ny, nz);
        return over(e, what, lim, "voxels", flag);
    }
    return RT_OK;
}

rt_code rt_check_bytes(double bytes, const char *what, rt_error *e)
{
    const char *flag;
    double left = get_limit(RT_LIMIT_MEMORY, &flag);
    if (left >= 0 && !(bytes <= left)) {
        if (flag)
            return rt_fail(e, RT_ELIMIT,
                           "%s needs %.0f MiB, more than the %.0f MiB left under the memory limit "
                           "(raise it with %s)",
                           what, bytes / 1048576.0, left / 1048576.0, flag);
        return rt_fail(e, RT_ELIMIT, "%s needs %.0f MiB, more than the %.0f MiB left under the memory limit",
                       what, bytes / 1048576.0, left / 1048576.0);
    }
    return RT_OK;
}
