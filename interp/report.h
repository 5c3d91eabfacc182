/* report.h — the render report: at the end of a run one line on stderr
 * gives the wall time and, per engine, the work done and its rate:
 *
 *   frac: 2.41 s; chaos game 2e+07 points in 1.90 s (10.5 M/s); raymarch 65536 pixels in 0.40 s (164 k/s)
 *
 * Bindings count their work with report_work after an engine call succeeds
 * (points of a chaos game, voxels sampled, pixels ray-marched …); the
 * counts live in a small fixed table in the interpreter state (no
 * allocation, so counting can never fail). main.c prints the line when
 * stderr is a terminal and --quiet was not given (and then only if some
 * engine ran), or always with --stats. */
#ifndef REPORT_H
#define REPORT_H

#include <stdio.h>

#include "state.h"

/* Seconds on a monotonic clock. */
double report_clock(void);
/* Count `amount` units of work of `engine` (string literals), which ran
 * since t0 (a report_clock() value). Engines beyond the table's size are
 * counted under the last entry's name "other". */
void report_work(interp *I, const char *engine, const char *unit, double amount, double t0);
/* The report line (with its newline) for a run that took `wall` seconds. */
void report_print(const interp *I, double wall, FILE *f);

#endif
