/* fractint.h — Fractint .ifs files: named IFS entries.
 *
 *   ; a comment runs to the end of the line (anywhere, also inside entries)
 *   fern {
 *     0     0    0    .16 0 0   .01     ; a b c d e f p
 *     .85  .04 -.04  .85  0 1.6 .85
 *   }
 *   3dfern (3D) {
 *     ; a b c d e f g h i j k l p
 *     .00 .00 0 .0 .18 .0 0 0.0 0.00 .00 0.0 .0 .01
 *   }
 *
 * 2-D rows: x' = a x + b y + e, y' = c x + d y + f, probability p (affine.h's
 * affine_from_2d order). 3-D rows: x' = ax+by+cz+j, y' = dx+ey+fz+k,
 * z' = gx+hy+iz+l, probability p. As in Fractint, the numbers of an entry
 * are one stream split into rows of 7 (or 13), so a row may wrap lines; the
 * name is everything before "{" or "(3D)" (trimmed, at most 63 bytes; the
 * "(3D)" tag is case-insensitive). Probabilities are returned as written:
 * Fractint itself does not insist that they sum to 1, so the caller decides
 * (ifs_build with or without IFS_NORMALISE).
 *
 * Errors name the line (1-based):
 *   "line 7: expected a number or '}', found 'x1'"
 *   "line 9: entry 'fern' has 20 numbers, not a whole number of 7-number rows"
 *   "line 12: entry 'fern' opened at line 3 is not closed with '}'"
 *   "line 4: entry 'x' has no maps"
 *   "line 2: expected '{' after the entry name 'fern'"
 */
#ifndef FRACTINT_H
#define FRACTINT_H

#include <stddef.h>

#include "affine.h"
#include "rt.h"

typedef struct fractint_entry {
    char name[64];
    int dim;       /* 2 or 3 */
    int n;         /* maps */
    int line;      /* line of the name */
    affine *maps;  /* n */
    double *p;     /* n, as written */
} fractint_entry;

typedef struct fractint_list {
    int n;
    fractint_entry *e;
} fractint_list;

rt_code fractint_parse(const char *text, size_t len, fractint_list *out, rt_error *e);
/* Read and parse a file (at most 16 MiB). */
rt_code fractint_load(const char *path, fractint_list *out, rt_error *e);
/* The entry named name (case-insensitive, as Fractint), or NULL. */
const fractint_entry *fractint_find(const fractint_list *l, const char *name);
void fractint_free(fractint_list *l);

#endif
