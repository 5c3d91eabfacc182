/* lang_ifs.h — IFS values shared by the IFS bindings (bind_ifs.c and the
 * function-set / fractal-top / super-IFS bindings). */
#ifndef LANG_IFS_H
#define LANG_IFS_H

#include "affine.h"
#include "chaos.h"
#include "ifs.h"
#include "state.h"

typedef struct lang_ifs {
    ifs f;
} lang_ifs;

typedef struct lang_rifs { /* the payload of lang_rifs_class */
    rifs r;
} lang_rifs;

extern const obj_class lang_ifs_class, lang_rifs_class, lang_map_class;

const lang_ifs *lang_as_ifs(value v);
/* The system behind an ifs or rifs value. */
int lang_get_sys(interp *I, value v, chaos_sys *s, const char *what);
/* chaos_fit with its pre-pass bounded by --max-points (every binding
 * fitting a window calls this, not chaos_fit). */
rt_code lang_chaos_fit(interp *I, const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                       rt_error *e);
/* lang_chaos_fit for the window of the engine call the binding makes next
 * (chaos, measure, view, top, steal…): a shard records the window in its
 * part, and merge takes it from there instead of running the pre-pass
 * (shard_window_put/take, shard.h). */
rt_code lang_chaos_fit_call(interp *I, const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                            rt_error *e);
/* Maps (and probabilities) from a table of rows, a list of maps or an ifs:
 * malloc'd arrays; returns 1 if probabilities were given, 0 if not, -1 on
 * error. */
int lang_get_maps(interp *I, value v, affine **maps, double **p, int *n, const char *what);

#endif
