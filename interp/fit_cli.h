/* fit_cli.h — `frac fit TARGET.png --maps N …` (interp/bind_fit.c): fit an
 * IFS to a picture and write a script that draws it. */
#ifndef FIT_CLI_H
#define FIT_CLI_H

#include <signal.h>

#include "state.h"

/* The index in argv of the word "fit" when it is the command: the first word that is
 * neither an option nor an option's value (so `frac --seed 3 fit T.png` is fit); 0 if not. */
int bind_fit_command_index(int argc, char **argv);

/* Run `frac fit` on the whole command line (argv[0] the program), argv[at] the word fit;
 * options may come before or after it. Returns the exit code. */
int bind_fit_command(interp *I, int argc, char **argv, int at, volatile sig_atomic_t *cancel);

#endif
