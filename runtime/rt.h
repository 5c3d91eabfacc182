/* rt.h — what every runtime engine shares: error reporting and small helpers.
 *
 * The runtime knows engines and file formats and nothing about the language.
 * Engines report failure by returning a non-zero rt_code and filling an
 * rt_error (a code and a one-line message without position: the interpreter
 * adds file:line:col). Engines never print and never exit.
 *
 * Memory: engines allocate only through rt_alloc.h (rt_malloc, rt_calloc,
 * rt_realloc, rt_free, with overflow-checked sizes), never with malloc. The
 * interpreter installs one process-wide hook there at start, so every engine
 * and codec buffer is counted against --max-memory and can be failed by the
 * fail-the-N-th-allocation test. The hook is process-wide, not a parameter,
 * because most runtime calls (codecs, images, meshes) take no context object
 * and a process runs one interpreter at a time; it is set before any worker
 * thread starts, and the interpreter's hook counts with C11 atomics because
 * engines allocate on their worker threads (details in rt_alloc.h). Without
 * a hook (C tests) it is plain malloc.
 * The interpreter checks user-controlled sizes before calling an engine for
 * a clear message; an engine handles a NULL from rt_malloc (RT_ENOMEM).
 * Decoders check the sizes a file declares with rt_check_pixels/_voxels/
 * _bytes before allocating (RT_ELIMIT).
 */
#ifndef RT_H
#define RT_H

#include <stddef.h>
#include <stdint.h>
#include <signal.h>

typedef enum rt_code {
    RT_OK = 0,
    RT_ENOMEM,   /* allocation failed */
    RT_EIO,      /* a file could not be read or written */
    RT_EFORMAT,  /* a file is not in the expected format, or is corrupt */
    RT_EINVAL,   /* invalid parameters (validation failed) */
    RT_ECANCEL,  /* interrupted by the user (Ctrl-C) */
    RT_ELIMIT,   /* a size exceeds a limit set through the allocation hook (rt_alloc.h) */
} rt_code;

typedef struct rt_error {
    rt_code code;
    char msg[512];
} rt_error;

/* Fill e (if not NULL) with code and a printf-style message; returns code. */
rt_code rt_fail(rt_error *e, rt_code code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Settings an evaluation runs under. Passed by pointer to engines that loop
 * over many points; NULL means: one thread, no cancel, no progress. */
typedef struct rt_run {
    int threads;                        /* >= 1 */
    volatile sig_atomic_t *cancel;      /* non-zero: stop soon, RT_ECANCEL */
    int progress;                       /* show a progress bar on stderr if it is a tty */
} rt_run;

/* Size of a * b * c ... with overflow check; returns 0 on overflow. */
size_t rt_mul_size(size_t a, size_t b);

/* The universal way one engine asks another for values of a scalar field:
 * evaluate at n points given as separate coordinate arrays (a block, n is at
 * most a few hundred) and write n values to out. Must be reentrant: it is
 * called from several threads at once with the same ctx. Engines that sample
 * a field (textured objects, ray marching, iso-surfaces, volumes) take one of
 * these, so they work with any field graph, volume or hand-written C. */
typedef void (*rt_field_fn)(const void *ctx, size_t n, const double *x, const double *y,
                            const double *z, double *out);

#define RT_BLOCK 256 /* the usual block size for field evaluation */
#endif
