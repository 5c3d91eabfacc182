/* cstack.h — the C stack as a bounded resource.
 *
 * The parser counts its own nesting (PARSE_MAX_NESTING in parser.h), but the
 * evaluator, the resolver and the walks over values recurse as deep as the
 * data: a left-deep chain `1+1+…+1`, a recursive function, a list nested
 * 10^5 deep. Instead of guessing a safe depth, frac runs the whole
 * interpreter on a thread whose stack size it chooses (cstack_main:
 * CSTACK_SIZE reserved; only the pages touched cost memory), and every
 * recursive step asks cstack_exhausted(). That compares the current frame
 * address with a floor CSTACK_MARGIN above the end of the thread's stack, so
 * a walk stops with a clear error while there is still room for a builtin's
 * or an engine's own frames below it (Lua's luaE_checkcstack, measured in
 * bytes instead of levels).
 *
 * The floor belongs to the thread, not to the interpreter: it is found once
 * per thread with pthread_getattr_np, so the check is also right on threads
 * frac did not start (the fuzz harness, C unit tests), with a smaller margin
 * on small stacks.
 *
 * CSTACK_MAX_DEPTH is the largest --max-depth accepted: that many calls of a
 * simple recursive function fit in CSTACK_SIZE even under ASan. Deeper
 * bodies reach the stack check first and stop with "stack overflow: …".
 */
#ifndef CSTACK_H
#define CSTACK_H

#include <stdint.h>

#include "state.h"

#define CSTACK_SIZE ((size_t)256 << 20)   /* reserved for the interpreter thread */
#define CSTACK_MARGIN ((size_t)8 << 20)   /* left free below the floor */
#define CSTACK_MAX_DEPTH 20000            /* the largest --max-depth */
#define CSTACK_STR_(x) #x
#define CSTACK_STR(x) CSTACK_STR_(x)      /* CSTACK_STR(CSTACK_MAX_DEPTH) is "20000" */

/* The lowest frame address a recursive walk may reach on this thread
 * (0: not known yet). Stacks grow down on every platform frac supports. */
extern _Thread_local uintptr_t cstack_floor;

/* Find this thread's floor; returns cstack_exhausted() for the caller. */
int cstack_init(void);

/* Nonzero when the calling frame is below the floor: the caller must stop
 * recursing and report cstack_error. */
static inline int cstack_exhausted(void)
{
    uintptr_t here = (uintptr_t)__builtin_frame_address(0);
    if (here < cstack_floor)
        return 1;
    return cstack_floor ? 0 : cstack_init();
}

/* Record "stack overflow: WHAT" (ERR_LIMIT, exit 65) at `at` (NULL: the
 * node being evaluated), with the call depth when inside a function. */
int cstack_error(interp *I, const node *at, const char *what);

/* Run fn(argc, argv) on a new thread with a CSTACK_SIZE stack and return its
 * result; all signals are delivered to that thread. If the thread cannot be
 * created (address-space limits), fn runs on the calling thread and the
 * check uses that thread's real stack. */
int cstack_main(int (*fn)(int, char **), int argc, char **argv);

#endif
