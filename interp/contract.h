/* contract.h — the declared contract of builtin parameters and option keys.
 *
 * Every builtin declares, for each parameter, a type text (see builtin.h for
 * the mini-language: "num[0,1]", "int>=1", "vec3", "str{log,linear}",
 * "rec{bits: int{8,16}, channels: int[1,4]}", "num+inf" …). contract.c
 * compiles each text once per interpreter (on the builtin's first call, with
 * the parameter defaults) and checks values against it in one function,
 * contract_check_value, used by call_builtin at run time, by the static
 * call checks of resolve.c before anything runs, and by option readers
 * whose keys depend on the value (save).
 *
 * Positions: a check carries the syntax node the value came from, so an
 * error in an item of a list or table literal puts the caret on that item
 * (the row of a table), and an unknown key of a record literal on the key.
 */
#ifndef CONTRACT_H
#define CONTRACT_H

#include "builtin.h"

typedef struct ctype ctype;

/* One compiled parameter of a builtin. */
typedef struct cparam {
    const char *name;   /* interned */
    const ctype *type;  /* NULL: any */
    int required;       /* no default */
    int def_nil;        /* default is nil (nil is then accepted too) */
    int def_ready;      /* def holds the default value */
    value def;
} cparam;

typedef struct bspec {
    const builtin *b;
    int n;
    cparam *p;
} bspec;

/* Where a value being checked came from: a syntax node (may be NULL) or an
 * explicit position (src < 0: none; then the node's or I->cur's). */
typedef struct cpos {
    const node *n;
    int src, line, col;
} cpos;

/* The running builtin call (I->bcall): its arguments and their nodes, so
 * readers can point at the argument or table row a value came from. */
typedef struct bcall {
    const builtin *b;
    const value *args;
    const node *const *nodes; /* per slot, NULL where unknown */
    int n;
} bcall;

/* The compiled declaration of b: every parameter's type and default,
 * compiled on the first call (once per interpreter, then cached). NULL after
 * recording an error: out of memory, or an internal error naming the
 * builtin when its declaration does not compile. */
const bspec *contract_spec(interp *I, const builtin *b);
/* Compile every registered builtin's declaration (`:help` does, so a bad
 * declaration fails the REPL tests, not only the first script calling it). */
int contract_compile_all(interp *I);
/* The default of parameter j (a borrowed value). */
int contract_default(interp *I, const bspec *s, int j, value *out);
/* A type text compiled once per interpreter (cached by address). */
const ctype *contract_type(interp *I, const char *text);

/* Check v against t. who: "save"; what: "argument 'options'". */
int contract_check_value(interp *I, const ctype *t, value v, const char *who, const char *what, cpos at);

/* Match call arguments to parameter names. anames[i] is NULL for a
 * positional argument; anodes may be NULL. slot[i] receives the parameter
 * index of argument i (-1 for the positional arguments of a variadic
 * callee). `most` words the arity message ("at most " for builtins). */
int contract_match(interp *I, const char *fname, const char *const *pnames, const int *required, int np,
                   int variadic, const char *most, const char *const *anames, const node *const *anodes, int na,
                   const node *call, int *slot);

/* The position of the name written before a value node: the key of a
 * record entry or the name of a named argument (`key: value`). */
cpos contract_name_pos(interp *I, const node *value_node);

/* Is n a constant expression (literals and operators on literals)? */
int contract_is_constant(const node *n);

#endif
