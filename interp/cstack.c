/* cstack.c — the interpreter thread and the stack check (see cstack.h). */
#define _GNU_SOURCE /* pthread_getattr_np */
#include "cstack.h"

#include <pthread.h>
#include <signal.h>

_Thread_local uintptr_t cstack_floor;

int cstack_init(void)
{
    pthread_attr_t a;
    void *lo = NULL;
    size_t size = 0;
    if (pthread_getattr_np(pthread_self(), &a) == 0) {
        if (pthread_attr_getstack(&a, &lo, &size) != 0)
            size = 0;
        pthread_attr_destroy(&a);
    }
    if (!lo || size == 0) {
        cstack_floor = 1; /* unknown: do not pretend to know (never exhausted) */
        return 0;
    }
    /* small stacks (a default 8 MiB main thread) keep a quarter free */
    size_t margin = size >= 4 * CSTACK_MARGIN ? CSTACK_MARGIN : size / 4;
    cstack_floor = (uintptr_t)lo + margin;
    return (uintptr_t)__builtin_frame_address(0) < cstack_floor;
}

int cstack_error(interp *I, const node *at, const char *what)
{
    if (I->depth > 0)
        return err_at(I, at, ERR_LIMIT, "stack overflow: %s (at call depth %d)", what, I->depth);
    return err_at(I, at, ERR_LIMIT, "stack overflow: %s", what);
}

typedef struct main_call {
    int (*fn)(int, char **);
    int argc;
    char **argv;
    int rc;
} main_call;

static void *run_main(void *p)
{
    main_call *m = p;
    m->rc = m->fn(m->argc, m->argv);
    return NULL;
}

int cstack_main(int (*fn)(int, char **), int argc, char **argv)
{
    main_call m = {fn, argc, argv, 0};
    pthread_attr_t a;
    pthread_t t;
    if (pthread_attr_init(&a) != 0)
        return fn(argc, argv);
    int ok = pthread_attr_setstacksize(&a, CSTACK_SIZE) == 0 && pthread_create(&t, &a, run_main, &m) == 0;
    pthread_attr_destroy(&a);
    if (!ok)
        return fn(argc, argv);
    /* The new thread inherited the signal mask; block everything here so
     * SIGINT interrupts the interpreter's own system calls (the REPL's read). */
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, NULL);
    pthread_join(t, NULL);
    return m.rc;
}
