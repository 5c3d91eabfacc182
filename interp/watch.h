/* watch.h — `frac watch SCRIPT`: render, then render again whenever a file
 * the render read changes.
 *
 * watch_main calls render(ud, cancel) once, then again each time one of
 * the files the last render read — the script, what it imports, what it
 * loads: every path fileio_read_all opened (fileio_set_path_hook) — changes.
 * A file's signature is its mtime (ns), size, inode and device, or its
 * absence; a poll thread stats every file about every 100 ms, so editors
 * that save by writing a new file and renaming it over the old one are seen
 * (the inode changes), and a file that was missing and appears is a change.
 * When a file changes while a render runs, *cancel is set: the render stops
 * at its next check (the interpreter's interrupt flag, which rt_run's
 * par_for honours) and starts again. A failed render is reported by render
 * itself; watching goes on. Files the render writes are not changes (their
 * signatures are taken after the write), so a script that loads its own
 * output does not loop.
 *
 * With show, the first image file (.png .ppm .pgm .pfm) a successful render
 * wrote is previewed on the terminal (termview.h), when standard output is
 * one. Status lines go to stderr unless quiet. *interrupted (set by the
 * SIGINT handler) ends the watch: the render in progress is cancelled and
 * watch_main returns 0 — Ctrl-C is how a watch normally ends. */
#ifndef WATCH_H
#define WATCH_H

#include <signal.h>

#include "state.h"

typedef int (*watch_render_fn)(void *ud, volatile sig_atomic_t *cancel);

/* T: the interpreter whose allocation hook is installed between renders
 * (render installs its own fresh interpreter's and restores T's). */
int watch_main(interp *T, watch_render_fn render, void *ud, volatile sig_atomic_t *interrupted, int show,
               int quiet);

#endif
