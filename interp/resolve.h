/* resolve.h — static checks before running: every name used is defined.
 *
 * Scopes follow the evaluator: a block's `fn` definitions are visible in the
 * whole block (so functions can call each other), `let`/`param` names from
 * their statement on (a `let` of a lambda sees its own name, for recursion),
 * parameters and loop variables inside their bodies. An import contributes
 * the top-level names of the module (found by parsing it, not running it).
 * Unknown names are reported with the nearest known name.
 */
#ifndef RESOLVE_H
#define RESOLVE_H

#include "state.h"

/* Check a parsed program against the names visible in scope `globals`,
 * then give its names their slots (node.slot, node.hops) for the evaluator. */
int resolve_program(interp *I, node *prog, env *globals);
/* The slots alone, for a module as it loads (eval.c): scope is its top-level
 * scope; open: later inputs may add names to it (the REPL's). Reports
 * only running out of memory or of C stack. */
int resolve_slots(interp *I, node *prog, env *scope, int open);
/* The checks alone, without the slots: for `frac check`, which runs nothing. */
int resolve_check(interp *I, node *prog, env *globals);

#endif
