/* test_session.h — an interpreter for the unit tests that link interp/:
 * one thread, quiet, its output into a temporary file (*out; fclose it), the
 * session set up. Returns session_setup's code, or -1 (no file: a failed
 * CHECK). Include after check.h. */
#ifndef TEST_SESSION_H
#define TEST_SESSION_H

#include <stdio.h>

#include "session.h"
#include "state.h"

static int test_session(interp *st, int repl, FILE **out)
{
    interp_init(st);
    st->threads = 1;
    st->quiet = 1;
    st->is_repl = repl;
    *out = tmpfile();
    CHECK(*out != NULL, "tmpfile");
    if (!*out)
        return -1;
    st->out = *out;
    return session_setup(st);
}

#endif
