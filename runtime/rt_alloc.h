/* rt_alloc.h — the one allocator of the runtime (and of the interpreter).
 *
 * Every byte the runtime allocates — images, volumes, meshes, decoder
 * buffers, engine scratch — goes through rt_malloc / rt_calloc / rt_realloc
 * and is freed with rt_free (never with free(): each block carries a small
 * header with its size). The sizes of the *n variants are products checked
 * for overflow; an overflow is a failed allocation (NULL).
 *
 * A program may install one allocation hook (Lua's lua_Alloc): a function
 * that sees every allocation, reallocation and free with its old and new
 * size, so it can count bytes against a budget, refuse an allocation, or fail
 * the N-th one for testing. With no hook installed the runtime uses plain
 * malloc/realloc/free — that is what the C unit tests get.
 *
 * Fresh blocks of 4 MiB and more (not growing reallocations) get a
 * transparent-huge-page hint (madvise MADV_HUGEPAGE on their 2 MiB-aligned
 * interior, where the system has it): their first touch then costs one page
 * fault per 2 MiB instead of one per 4 KiB. Bytes and accounting are the same.
 *
 * Why a process-wide hook rather than a parameter: most runtime calls
 * (codecs, images, meshes) take no context object, and threading an
 * allocator argument through ~200 call sites would change every engine's
 * interface for no gain — a process has one interpreter at a time. The hook
 * is installed once by the interpreter at start (interp_init) before any
 * worker thread runs, and removed at the end; the pointer is read with an
 * atomic load. The hook itself must be thread-safe: engines allocate on
 * their worker threads (the interpreter's hook counts with C11 atomics).
 *
 * The same hook answers the decoders' question "is a file that declares
 * this size allowed?" (rt_check_pixels / rt_check_voxels / rt_check_bytes):
 * every decoder asks before it allocates anything for the declared size, so
 * a 10 KB file declaring 9000×9000 pixels fails with a limit error instead
 * of allocating 1.2 GB first.
 */
#ifndef RT_ALLOC_H
#define RT_ALLOC_H

#include <stddef.h>

#include "rt.h"

typedef enum rt_limit {
    RT_LIMIT_MEMORY, /* bytes still free under the memory budget */
    RT_LIMIT_PIXELS, /* pixels per image */
    RT_LIMIT_VOXELS, /* voxels per volume */
} rt_limit;

typedef struct rt_alloc_hook {
    /* ptr NULL: allocate nsize bytes. nsize 0: free ptr (of osize bytes),
     * return NULL. Otherwise resize ptr from osize to nsize bytes, keeping
     * ptr valid when it returns NULL (like realloc). Called from any thread. */
    void *(*alloc)(void *ud, void *ptr, size_t osize, size_t nsize);
    /* The current limit of one kind (< 0: none) and, in *flag, the text
     * that says how to raise it (e.g. "--max-pixels"; may stay NULL).
     * May be NULL: no limits. */
    double (*limit)(void *ud, rt_limit kind, const char **flag);
    void *ud;
    /* May be NULL (alloc and a memset are used): allocate nsize zeroed
     * bytes, accounted like alloc(ud, NULL, 0, nsize). calloc can hand out
     * fresh pages from the kernel without writing them, so rt_calloc of a
     * big buffer (an 8 MiB histogram) faults in only the pages later used. */
    void *(*zalloc)(void *ud, size_t nsize);
} rt_alloc_hook;

/* Install h (kept by pointer; it must outlive its use) or, with NULL, go back
 * to plain malloc. Install before any allocation that the hook should see
 * and free those blocks before removing it. */
void rt_alloc_set_hook(const rt_alloc_hook *h);

void *rt_malloc(size_t n);
void *rt_calloc(size_t count, size_t size);  /* zeroed; count * size checked */
void *rt_mallocn(size_t count, size_t size); /* count * size checked, not zeroed */
void *rt_realloc(void *p, size_t n);
void *rt_reallocn(void *p, size_t count, size_t size);
void rt_free(void *p);
char *rt_strdup(const char *s);
/* count * size zero bytes for a big buffer that is filled soon after
 * (histograms, images): from 4 MiB on, the array starts on a 2 MiB boundary
 * inside a block 2 MiB larger, so all of it lies in huge pages (the plain
 * rt_calloc block's unaligned head and tail would be ~520 faults of 4 KiB
 * for 16 MiB). *mem gets the block to rt_free; returns NULL (and *mem NULL)
 * when out of memory. The slack is never touched but counts in the budget. */
void *rt_calloc_huge(size_t count, size_t size, void **mem);

/* Checks a decoder makes before allocating for sizes a file declares:
 * RT_OK, or RT_ELIMIT with a message naming the limit ("image of 9000×9000
 * pixels exceeds the limit of 1000000 pixels (raise it with --max-pixels)").
 * Without a hook (or a limit of that kind) everything is allowed. */
rt_code rt_check_pixels(double w, double h, rt_error *e);
rt_code rt_check_voxels(double nx, double ny, double nz, rt_error *e);
/* `what` names the buffer: "the mesh's 1e9 vertices need 22888 MiB, …". */
rt_code rt_check_bytes(double bytes, const char *what, rt_error *e);

#endif
