/* repl.h — the interactive session (and its piped, script-like mode). */
#ifndef REPL_H
#define REPL_H

#include <signal.h>

#include "state.h"

/* Run the REPL on stdin/stdout. Returns the exit code: 0, or 65 if any
 * input failed when stdin is not a terminal. */
int repl_main(interp *I, volatile sig_atomic_t *interrupted);

#endif
