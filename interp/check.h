/* check.h — static checks of calls against declared parameters.
 *
 * Run by the resolver before anything is evaluated (so by `frac check` and
 * before every run): calls to builtins, to functions of imported modules
 * and to top-level `fn`s whose name the program binds only there are
 * checked for unknown named arguments (with did-you-mean), arity, missing
 * arguments and, for builtins, constant arguments against the declared
 * types and ranges — the same checks and messages as at run time. */
#ifndef CHECK_H
#define CHECK_H

#include "state.h"

typedef struct check_names {
    struct { const char *name; const node *def; } *v; /* def: a top-level N_FNDEF, else NULL */
    int n, cap;
    int *index; /* open addressing over v by name: i + 1 of the name's last entry, 0 empty */
    int *count; /* per index slot: how many entries have that name */
    size_t index_cap;
} check_names;

/* Collect every name the program binds (anywhere). */
int check_collect(interp *I, const node *prog, check_names *out);
/* The same piece by piece, for a walk that visits every binding itself (the
 * resolver): check_bind for each name bound (def: the N_FNDEF of a top-level
 * `fn`, else NULL), in any order, then check_index once, before check_call.
 * Starts from a zeroed check_names. */
int check_bind(interp *I, check_names *b, const char *name, const node *def);
int check_index(interp *I, check_names *b);
void check_names_free(interp *I, check_names *b);
/* Check one N_CALL; mods are the scopes of the modules imported so far. */
int check_call(interp *I, const check_names *bound, env *const *mods, int nmods, const node *call);

#endif
