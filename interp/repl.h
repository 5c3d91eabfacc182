/* repl.h — the interactive session (and its piped, script-like mode). */
#ifndef REPL_H
#define REPL_H

#include <signal.h>

#include "state.h"

/* Called before each entry runs, with the session so far as a script: the
 * entries that ran without error, in order, then this one (each with its
 * line break; :load adds the file's text, :reset starts again from
 * nothing). main.c installs it as the recipe the files written from now on
 * carry, so `frac rerun` of such a file runs that script. 0, or -1 out of
 * memory (the entry does not run). */
typedef int (*repl_recipe_fn)(void *ud, const char *text, size_t len);

/* Run the REPL on stdin/stdout. Returns the exit code: 0, or 65 if any
 * input failed when stdin is not a terminal. recipe may be NULL. */
int repl_main(interp *I, volatile sig_atomic_t *interrupted, repl_recipe_fn recipe, void *ud);

#endif
