/* eval.h — the tree-walking evaluator.
 *
 * All functions return 0 on success and -1 after recording an error in
 * I->err. Results are new references.
 */
#ifndef EVAL_H
#define EVAL_H

#include "state.h"

int eval_expr(interp *I, env *e, const node *n, value *out);
/* The context of val_list_build for a list literal [a, b, …]: its kids run
 * in scope e; `of` is the literal's node (the walker) or cnode (compile.c). */
typedef struct eval_kids {
    env *e;
    const void *of;
} eval_kids;
/* Run the statements of a block in scope e; *out (if not NULL) receives the
 * value of the last expression statement (nil if none). */
int eval_block(interp *I, env *e, const node *block, value *out);
/* An expression statement's value v becomes the block's last value *last
 * (dropped when last is NULL: nobody keeps it). Takes v. */
void eval_keep_last(interp *I, value *last, value v);
/* Element-wise arithmetic shared by operators and builtins: op is a token
 * type (T_PLUS, T_MINUS, T_STAR, T_SLASH, T_PERCENT, T_CARET, comparisons). */
int eval_binary(interp *I, int op, value a, value b, value *out, const node *at);
/* Load (once) and run a module; returns its scope (borrowed). */
int eval_import(interp *I, const node *at, const char *name, env **out);
/* The scope of module `name` if it is loaded already, else NULL (loads nothing, records nothing). */
env *eval_module_loaded(interp *I, const node *at, const char *name);
/* Parse a -D override or other value text as an expression and evaluate it. */
int eval_text(interp *I, const char *srcname, const char *text, value *out);

#endif
