/* compile.h — the compiled form of hot code (closure compilation).
 *
 * A function body or a loop body is compiled, the first time it runs, into
 * a tree of cnodes: each node of the syntax tree becomes a C function
 * pointer plus its operands, chosen once for the node's kind and operator
 * (an addition, a local name, a call with three positional arguments…), so
 * running it pays neither eval_expr's switch nor its per-node checks.
 * Numbers and names in the innermost scope are read inline by the parent
 * (cnode_eval), without a call. What the compiled form does not cover
 * (strings, records, comprehensions, named arguments, imports…) is a cnode
 * that hands its syntax node to the tree walker (eval.c), so the two always
 * agree: same order of evaluation, same errors at the same positions, same
 * interrupt checks (every call, every loop iteration), the same frames for
 * --max-depth and the call trace.
 *
 * The C stack: a compiled expression nests at most COMPILE_MAX_NEST cnodes
 * (deeper subtrees stay with the walker, which checks the stack per node),
 * and compiled blocks and calls check cstack_exhausted() like the walker.
 *
 * cnodes live in the syntax-tree arena (mem_arena_alloc) for the session,
 * as the nodes do; the compiled body of a lambda is kept in its node's
 * `code` field, that of a block in the block's.
 */
#ifndef COMPILE_H
#define COMPILE_H

#include "state.h"

typedef struct cnode cnode;
/* Run c in scope e. Expressions write a new reference to *out on success;
 * statements get the block's "last value" slot (may be NULL). 0 or -1. */
typedef int (*cnode_fn)(interp *I, env *e, const cnode *c, value *out);

enum { CT_OTHER, CT_NUM, CT_LOCAL, CT_NAME };

#define COMPILE_MAX_NEST 48 /* cnodes nested in one compiled expression */
#define COMPILE_MAX_ARGS 8  /* positional arguments of a compiled call */

struct cnode {
    cnode_fn fn;
    const node *n;        /* the syntax node: positions, names, fallback */
    int tag;              /* CT_NUM: num (and k); CT_LOCAL: slot `slot` of e, checked;
                           * CT_NAME: a name further out (scope_lookup) */
    int slot;
    double num;
    value k;              /* an immediate constant (nil, booleans, CT_NUM's number) */
    const cnode *a, *b, *c;
    const cnode **kids;   /* call arguments, block statements */
    int nkids;
    int pure;             /* no call or scope below: cannot grow a scope */
    const node *assign;   /* a call that is the value of `x = …` (concat appends) */
    int local_scope;      /* a lambda's body that makes no closure: nothing in it can keep
                           * the call's scope, which may then live on the C stack */
};

/* The compiled body of a lambda (run it in the call's scope, as
 * call_user would evaluate the body), compiled on first use; NULL after an
 * error (out of memory) recorded in I. */
const cnode *compile_lambda(interp *I, const node *lambda);
/* A block's statements, run in the scope given (eval_block's meaning). */
const cnode *compile_block(interp *I, const node *block);

/* ---- shared with eval.c (the walker) ---- */

/* The search by name behind scope_lookup (eval.c), counted in
 * I->count.name_searches. */
value *eval_scope_search(interp *I, env *e, const node *n);

/* A name by its slot (resolve.c), checked: the slot must hold the name
 * (it may not be defined yet, or a REPL input may have stopped half-way),
 * else the search by name decides, as it always did. Resolved code that
 * runs as resolve.c saw it never searches (tests/unit/test_interp_counts.c). */
static inline value *scope_lookup(interp *I, env *e, const node *n)
{
    if (n->slot) {
        env *t = e;
        for (int h = n->hops; h > 0 && t; h--)
            t = t->parent;
        /* t is NULL only if the scopes are not the ones resolve.c saw */
        size_t k = (size_t)n->slot - 1;
        if (t && k < t->n && t->names[k] == n->str)
            return &t->vals[k];
    }
    return eval_scope_search(I, e, n);
}

/* Define n->str in e (takes v): in place when the slot already holds it;
 * appended when the slot is the next one and every name in e sits at its
 * own slot (no name was added by name: e->loose), since then n->str, whose
 * one slot is k, cannot be elsewhere in e; else by name. */
static inline int scope_define_at(interp *I, env *e, int slot, const char *name, value v)
{
    size_t k = (size_t)slot - 1;
    if (slot && k < e->n && e->names[k] == name) {
        val_unref(I, e->vals[k]);
        e->vals[k] = v;
        return 0;
    }
    if (slot && k == e->n && !e->loose)
        return val_env_append(I, e, name, v);
    return val_env_define(I, e, name, v);
}

static inline int scope_define(interp *I, env *e, const node *n, value v)
{
    return scope_define_at(I, e, n->slot, n->str, v);
}

/* Evaluate an operand: numbers and names inline (the cnode's function
 * runs only for other kinds, and for a name that is not defined, to report
 * it). */
__attribute__((always_inline)) static inline int cnode_eval(interp *I, env *e, const cnode *c, value *out)
{
    if (c->tag == CT_NUM) {
        *out = c->k;
        return 0;
    }
    if (c->tag == CT_LOCAL) {
        size_t k = (size_t)c->slot;
        if (k < e->n && e->names[k] == c->n->str) {
            *out = e->vals[k];
            val_ref(*out);
            return 0;
        }
    } else if (c->tag == CT_NAME) {
        value *v = scope_lookup(I, e, c->n);
        if (v) {
            *out = *v;
            val_ref(*out);
            return 0;
        }
    }
    return c->fn(I, e, c, out);
}

/* An operand's value without evaluating it (borrowed), for numbers and
 * defined names; NULL for anything else. Looking has no effects, so an
 * operator can peek at both operands and evaluate them after all if they
 * are not both numbers. */
__attribute__((always_inline)) static inline const value *cnode_peek(interp *I, env *e, const cnode *c)
{
    if (c->tag == CT_NUM)
        return &c->k;
    if (c->tag == CT_LOCAL) {
        size_t k = (size_t)c->slot;
        return k < e->n && e->names[k] == c->n->str ? &e->vals[k] : NULL;
    }
    if (c->tag == CT_NAME)
        return scope_lookup(I, e, c->n);
    return NULL;
}

/* val_unref, with a reference that is not the last dropped inline */
__attribute__((always_inline)) static inline void cnode_unref(interp *I, value v)
{
    if (v.k >= V_STR && v.k != V_BUILTIN) {
        if (v.u.h->rc > 1)
            v.u.h->rc--;
        else
            val_heap_unref(I, v.u.h);
    }
}

/* eval.c's pieces the compiled form calls (not for other modules). */
int eval_binary_node(interp *I, const node *n, value a, value b, value *out); /* takes a, b */
int eval_unary_node(interp *I, const node *n, value a, value *out);           /* borrows a */
int eval_index_node(interp *I, const node *n, value a, value ix, value *out); /* borrows */
int eval_field_node(interp *I, const node *n, value a, value *out);           /* borrows */
/* fn(args) for the call node `call` whose arguments are all positional
 * (call->kids + 1); assign: the `x = …` it is the value of, or NULL. */
int eval_call_positional(interp *I, env *e, value fn, const value *args, int nargs, const node *call,
                         const node *assign, value *out);
int eval_stmt(interp *I, env *e, const node *n, value *last);
int eval_push_frame(interp *I, const char *name, const node *call);
int eval_stack_overflow(interp *I, const node *n);

#endif
