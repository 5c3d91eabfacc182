/* session.h — setting up an interpreter and running source text in it. */
#ifndef SESSION_H
#define SESSION_H

#include "state.h"

#define FRAC_VERSION "0.1.0"

/* Create the builtin scope and the global scope, register every builtin. */
int session_setup(interp *I);
/* After session_setup: the names `frame` and `clock` take I->frame and
 * I->clock again (frac rerun of a frame sets them from the recipe). */
void session_set_frame(interp *I);
/* Parse, resolve and run source text; the value of the last expression
 * statement goes to *last (if not NULL). check_only: parse and resolve
 * without running. */
int session_run(interp *I, const char *name, const char *text, size_t len, int check_only, value *last);
/* The same for a REPL entry whose first line is line `first_line` of the session. */
int session_run_lines(interp *I, const char *name, const char *text, size_t len, int first_line,
                      int check_only, value *last);
/* Print the pending error to stderr and return its exit code. */
int session_report(interp *I);

#endif
