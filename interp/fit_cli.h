/* fit_cli.h — `frac fit TARGET.png --maps N …` (interp/bind_fit.c): fit an
 * IFS to a picture and write a script that draws it. argv[0] is "fit".
 * Returns the exit code. */
#ifndef FIT_CLI_H
#define FIT_CLI_H

#include <signal.h>

#include "state.h"

int fit_command(interp *I, int argc, char **argv, volatile sig_atomic_t *cancel);

#endif
