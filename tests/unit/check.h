/* check.h — the tiny harness every C unit test uses.
 *
 * Each tests/unit/test_NAME.c is one program: CHECK(cond, ...) records a
 * failure with file:line and a message and carries on; check_done() prints
 * "test_NAME: N checks, N failed" and returns the exit status for main.
 */
#ifndef CHECK_H
#define CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "rt_alloc.h"

static int check_count, check_failed;

#define CHECK(cond, ...)                                                      \
    do {                                                                      \
        check_count++;                                                        \
        if (!(cond)) {                                                        \
            check_failed++;                                                   \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                     \
            fprintf(stderr, "\n");                                            \
        }                                                                     \
    } while (0)

#define CHECK_NEAR(a, b, tol, what)                                           \
    CHECK(fabs((double)(a) - (double)(b)) <= (tol), "%s: %.17g vs %.17g (tol %g)", what, \
          (double)(a), (double)(b), (double)(tol))

/* A test allocation hook (rt_alloc.h): limits like the interpreter's, and
 * the largest block asked for while it is installed, so a test can show a
 * decoder refused a declared size before allocating for it.
 * check_limits(pixels, voxels, memory_left) installs it (< 0: no limit of
 * that kind); check_limits_off() removes it. */
typedef struct check_hook_state {
    double pixels, voxels, memory;
    size_t peak;
} check_hook_state;
static check_hook_state check_hs;

static inline void *check_hook_alloc(void *ud, void *p, size_t osize, size_t nsize)
{
    (void)ud;
    (void)osize;
    if (nsize == 0) {
        free(p);
        return NULL;
    }
    if (nsize > check_hs.peak)
        check_hs.peak = nsize;
    return realloc(p, nsize);
}

static inline double check_hook_limit(void *ud, rt_limit k, const char **flag)
{
    (void)ud;
    *flag = k == RT_LIMIT_PIXELS ? "--max-pixels" : k == RT_LIMIT_VOXELS ? "--max-voxels" : "--max-memory MiB";
    return k == RT_LIMIT_PIXELS ? check_hs.pixels : k == RT_LIMIT_VOXELS ? check_hs.voxels : check_hs.memory;
}

static inline void check_limits(double pixels, double voxels, double memory)
{
    static const rt_alloc_hook h = {check_hook_alloc, check_hook_limit, NULL, NULL};
    check_hs.pixels = pixels;
    check_hs.voxels = voxels;
    check_hs.memory = memory;
    check_hs.peak = 0;
    rt_alloc_set_hook(&h);
}

static inline void check_limits_off(void)
{
    rt_alloc_set_hook(NULL);
}

static inline int check_done(const char *name)
{
    printf("%s: %d checks, %d failed\n", name, check_count, check_failed);
    return check_failed ? 1 : 0;
}

#endif
