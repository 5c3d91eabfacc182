/* lang_fset.h — function sets and the readers shared by the function-set,
 * shape, fractal-top and super-IFS bindings (bind_fset.c defines them;
 * bind_shape.c, bind_tops.c and bind_superifs.c use them). */
#ifndef LANG_FSET_H
#define LANG_FSET_H

#include "fset.h"
#include "ramp.h"
#include "state.h"
#include "tonemap.h"

typedef struct lang_fset {
    int n;
    affine **maps;   /* n arrays */
    double **p;      /* n arrays (always set: given or |det| weights via ifs) */
    fset_ifs *sets;  /* n views */
    fset fs;
    int dim;
} lang_fset;

/* The function set of an fset value, NULL for any other value. */
lang_fset *lang_as_fset(value v);
/* fset, ifs, table or list of ifs/tables -> a function set value (new ref). */
int lang_get_fset(interp *I, value v, int list_is_sets, value *out, const char *what);
/* The order to use with a function set of nsets sets: given, or periodic
 * W1, W2, …, WN. *tmp holds a default's storage. */
int lang_order_arg(interp *I, value v, int slot, int nsets, fset_order *o, int **tmp, const char *what);
/* points: declared int>=1; the limit is the session's. */
int lang_points_arg(interp *I, value v, uint64_t *out, const char *what);
/* A window [xmin, xmax, ymin, ymax] with min < max. */
int lang_window_arg(interp *I, value v, double lo[2], double hi[2], const char *what);
/* Tone-mapping arguments shared by chaos_fset and superifs_image. */
int lang_tone_args(interp *I, value palette, value curve, value gamma, value bright, value bg, tonemap_opts *t,
                   ramp *r, const char *what);

#endif
