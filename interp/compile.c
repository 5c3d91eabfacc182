/* compile.c — closure compilation of function and loop bodies (compile.h). */
#include "compile.h"

#include "cstack.h"
#include "eval.h"
#include "lexer.h"

/* ---- running ----------------------------------------------------------------- */

static int check_interrupt(interp *I, const node *at)
{
    if (I->interrupt && *I->interrupt)
        return err_at(I, at, ERR_INTERRUPT, "interrupted");
    return 0;
}

static inline int truthy(value v) /* val_truthy */
{
    return v.k == V_BOOL ? v.u.b : v.k != V_NIL;
}

/* What the compiled form leaves to the tree walker. */
static int c_walk(interp *I, env *e, const cnode *c, value *out)
{
    return eval_expr(I, e, c->n, out);
}

static int c_stmt_walk(interp *I, env *e, const cnode *c, value *last)
{
    return eval_stmt(I, e, c->n, last);
}

static int c_num(interp *I, env *e, const cnode *c, value *out)
{
    (void)I, (void)e;
    *out = val_num(c->num);
    return 0;
}

static int c_const(interp *I, env *e, const cnode *c, value *out)
{
    (void)I, (void)e;
    *out = c->k;
    return 0;
}

static int c_name(interp *I, env *e, const cnode *c, value *out)
{
    value *v = scope_lookup(I, e, c->n);
    if (!v)
        return err_at(I, c->n, ERR_NAME, "unknown name '%s'", c->n->str);
    *out = *v;
    val_ref(*out);
    return 0;
}

/* a OP b with the number case inline; anything else as the walker does it.
 * NAME_pp: both operands are numbers or names (CT_NUM, CT_LOCAL, CT_NAME),
 * so a look at them (no effects) decides whether the number case applies. */
#define BINARY_FN(NAME, OP, RESULT)                                            \
    static int NAME(interp *I, env *e, const cnode *c, value *out)             \
    {                                                                          \
        value a, b;                                                            \
        if (cnode_eval(I, e, c->a, &a))                                        \
            return -1;                                                         \
        if (cnode_eval(I, e, c->b, &b)) {                                      \
            val_unref(I, a);                                                   \
            return -1;                                                         \
        }                                                                      \
        if (a.k == V_NUM && b.k == V_NUM) {                                    \
            double x = a.u.n, y = b.u.n;                                       \
            *out = RESULT;                                                     \
            return 0;                                                          \
        }                                                                      \
        return eval_binary_node(I, c->n, a, b, out);                           \
    }                                                                          \
    static int NAME##_pp(interp *I, env *e, const cnode *c, value *out)        \
    {                                                                          \
        const value *pa = cnode_peek(I, e, c->a), *pb = cnode_peek(I, e, c->b); \
        if (pa && pb && pa->k == V_NUM && pb->k == V_NUM) {                    \
            double x = pa->u.n, y = pb->u.n;                                   \
            *out = RESULT;                                                     \
            return 0;                                                          \
        }                                                                      \
        return NAME(I, e, c, out);                                             \
    }
BINARY_FN(c_add, T_PLUS, val_num(x + y))
BINARY_FN(c_sub, T_MINUS, val_num(x - y))
BINARY_FN(c_mul, T_STAR, val_num(x * y))
BINARY_FN(c_div, T_SLASH, val_num(x / y))
BINARY_FN(c_lt, T_LT, val_bool(x < y))
BINARY_FN(c_le, T_LE, val_bool(x <= y))
BINARY_FN(c_gt, T_GT, val_bool(x > y))
BINARY_FN(c_ge, T_GE, val_bool(x >= y))
BINARY_FN(c_eq, T_EQ, val_bool(x == y)) /* as val_equal */
BINARY_FN(c_ne, T_NE, val_bool(x != y))

static int c_binary(interp *I, env *e, const cnode *c, value *out)
{
    value a, b;
    if (cnode_eval(I, e, c->a, &a))
        return -1;
    if (cnode_eval(I, e, c->b, &b)) {
        val_unref(I, a);
        return -1;
    }
    return eval_binary_node(I, c->n, a, b, out);
}

static int c_unary(interp *I, env *e, const cnode *c, value *out)
{
    value a;
    if (cnode_eval(I, e, c->a, &a))
        return -1;
    if (a.k == V_NUM && c->n->op != 'n') {
        *out = val_num(c->n->op == '-' ? -a.u.n : a.u.n);
        return 0;
    }
    int r = eval_unary_node(I, c->n, a, out);
    val_unref(I, a);
    return r;
}

static int c_andor(interp *I, env *e, const cnode *c, value *out)
{
    value a;
    if (cnode_eval(I, e, c->a, &a))
        return -1;
    int t = truthy(a);
    if ((c->n->kind == N_AND && !t) || (c->n->kind == N_OR && t)) {
        *out = a;
        return 0;
    }
    val_unref(I, a);
    return cnode_eval(I, e, c->b, out);
}

static int c_if(interp *I, env *e, const cnode *c, value *out)
{
    value v;
    if (cnode_eval(I, e, c->a, &v))
        return -1;
    int t = truthy(v);
    val_unref(I, v);
    if (t)
        return cnode_eval(I, e, c->b, out);
    if (c->c)
        return cnode_eval(I, e, c->c, out);
    *out = val_nil();
    return 0;
}

/* if a CMP b then … with a and b numbers or names: compared in place when
 * both are numbers, else as c_if. */
#define IF_CMP_FN(NAME, CMP)                                                   \
    static int NAME(interp *I, env *e, const cnode *c, value *out)             \
    {                                                                          \
        const value *pa = cnode_peek(I, e, c->a->a), *pb = cnode_peek(I, e, c->a->b); \
        int t;                                                                 \
        if (pa && pb && pa->k == V_NUM && pb->k == V_NUM) {                    \
            t = pa->u.n CMP pb->u.n;                                           \
        } else {                                                               \
            value v;                                                           \
            if (cnode_eval(I, e, c->a, &v))                                    \
                return -1;                                                     \
            t = truthy(v);                                                     \
            val_unref(I, v);                                                   \
        }                                                                      \
        if (t)                                                                 \
            return cnode_eval(I, e, c->b, out);                                \
        if (c->c)                                                              \
            return cnode_eval(I, e, c->c, out);                                \
        *out = val_nil();                                                      \
        return 0;                                                              \
    }
IF_CMP_FN(c_if_lt, <)
IF_CMP_FN(c_if_le, <=)
IF_CMP_FN(c_if_gt, >)
IF_CMP_FN(c_if_ge, >=)
IF_CMP_FN(c_if_eq, ==)
IF_CMP_FN(c_if_ne, !=)

static int c_index(interp *I, env *e, const cnode *c, value *out)
{
    value a, ix;
    if (cnode_eval(I, e, c->a, &a))
        return -1;
    if (cnode_eval(I, e, c->b, &ix)) {
        val_unref(I, a);
        return -1;
    }
    int r = eval_index_node(I, c->n, a, ix, out);
    val_unref(I, a);
    val_unref(I, ix);
    return r;
}

static int c_field(interp *I, env *e, const cnode *c, value *out)
{
    value a;
    if (cnode_eval(I, e, c->a, &a))
        return -1;
    int r = eval_field_node(I, c->n, a, out);
    val_unref(I, a);
    return r;
}

/* element i of a list literal: compiled kid i run (eval_kids) */
static int list_kid(interp *I, const void *ctx, size_t i, value *out)
{
    const eval_kids *k = ctx;
    const cnode *c = k->of;
    return cnode_eval(I, k->e, c->kids[i], out);
}

static int c_list(interp *I, env *e, const cnode *c, value *out)
{
    const eval_kids k = {e, c};
    return val_list_build(I, (size_t)c->nkids, list_kid, &k, out);
}

/* do … end as an expression: a new scope for its statements */
static int c_doblock(interp *I, env *e, const cnode *c, value *out)
{
    env *s = val_env_new(I, e);
    if (!s)
        return -1;
    int r = c->a->fn(I, s, c->a, out);
    val_heap_unref(I, &s->h);
    return r;
}

/* The frame of a call (eval_push_frame's common case inline). */
static inline int push_frame(interp *I, const vfunc *f, const node *call)
{
    if (I->depth < I->lim.max_depth && I->depth < I->stack_cap) {
        I->stack[I->depth].fname = f->name ? f->name : "<lambda>";
        I->stack[I->depth].call = call;
        I->depth++;
        return 0;
    }
    return eval_push_frame(I, f->name ? f->name : "<lambda>", call);
}

#define LOCAL_NAMES 4 /* names a call's scope on the C stack holds before it grows */

/* call_user_exact for a body that makes no closure (body->local_scope):
 * its scope is a local here, not a pooled heap object, since no closure
 * (the only thing that keeps a scope: directly, or through the loop and
 * block scopes inside it) can be made in it. Scopes made inside it (loops,
 * blocks) point to it while they run and are released before it is. */
static int call_local(interp *I, vfunc *f, const value *args, int nargs, const node *call, const cnode *body,
                      value *out)
{
    const node *l = f->lambda;
    const char *names[LOCAL_NAMES];
    value vals[LOCAL_NAMES];
    env s = {.h = {.rc = 1, .kind = H_ENV}, .parent = f->closure, .cap = LOCAL_NAMES, .names = names,
             .vals = vals, .borrowed = 1};
    if (s.parent)
        s.parent->h.rc++;
    for (int j = 0; j < nargs; j++) {
        names[j] = l->names[j];
        vals[j] = args[j];
        val_ref(vals[j]);
    }
    s.n = (size_t)nargs;
    int rc = -1;
    if (push_frame(I, f, call) == 0) {
        rc = body->fn(I, &s, body, out);
        I->depth--;
    }
    for (size_t k = 0; k < s.n; k++)
        val_unref(I, s.vals[k]);
    if (!s.borrowed) {
        mem_free(I, s.names);
        mem_free(I, s.vals);
    }
    mem_free(I, s.index);
    if (s.parent)
        val_heap_unref(I, &s.parent->h);
    return rc;
}

/* A user function called with exactly its parameters, in order: what
 * call_user does then (no argument matching, no defaults), with the
 * compiled body. */
static int call_user_exact(interp *I, vfunc *f, const value *args, int nargs, const node *call, value *out)
{
    const node *l = f->lambda;
    if (l->code && l->code->local_scope && nargs <= LOCAL_NAMES) /* compiled already (the first call compiles) */
        return call_local(I, f, args, nargs, call, l->code, out);
    env *ne = val_env_new(I, f->closure);
    if (!ne)
        return -1;
    int rc = -1;
    for (int j = 0; j < nargs; j++) {
        value v = args[j];
        val_ref(v);
        if ((size_t)j == ne->n && ne->n < ne->cap) {
            /* parameter j goes to slot j: the parser refuses duplicate names */
            ne->names[j] = l->names[j];
            ne->vals[j] = v;
            ne->n++;
        } else if ((size_t)j == ne->n ? val_env_append(I, ne, l->names[j], v)
                                      : val_env_define(I, ne, l->names[j], v)) {
            goto done;
        }
    }
    if (push_frame(I, f, call))
        goto done;
    const cnode *body = compile_lambda(I, l); /* after the frame, as in call_user */
    rc = body ? body->fn(I, ne, body, out) : -1;
    I->depth--;
done:
    val_heap_unref(I, &ne->h);
    return rc;
}

static int c_call(interp *I, env *e, const cnode *c, value *out)
{
    /* the walker checks the stack at every node; here at calls and blocks */
    if (cstack_exhausted())
        return eval_stack_overflow(I, c->n);
    value fn, args[COMPILE_MAX_ARGS];
    if (cnode_eval(I, e, c->a, &fn))
        return -1;
    int i, rc = -1;
    for (i = 0; i < c->nkids; i++)
        if (cnode_eval(I, e, c->kids[i], &args[i]))
            goto done;
    if (fn.k == V_FUNC && AS_FUNC(fn)->lambda->nparams == c->nkids) {
        *out = val_nil();
        if (check_interrupt(I, c->n) == 0)
            rc = call_user_exact(I, AS_FUNC(fn), args, c->nkids, c->n, out);
    } else {
        rc = eval_call_positional(I, e, fn, args, c->nkids, c->n, c->assign, out);
    }
done:
    while (i-- > 0)
        val_unref(I, args[i]);
    cnode_unref(I, fn);
    return rc;
}

/* c_call for one argument */
static int c_call1(interp *I, env *e, const cnode *c, value *out)
{
    if (cstack_exhausted())
        return eval_stack_overflow(I, c->n);
    value fn, arg;
    if (cnode_eval(I, e, c->a, &fn))
        return -1;
    if (cnode_eval(I, e, c->kids[0], &arg)) {
        val_unref(I, fn);
        return -1;
    }
    int rc = -1;
    if (fn.k == V_FUNC && AS_FUNC(fn)->lambda->nparams == 1) {
        *out = val_nil();
        if (check_interrupt(I, c->n) == 0)
            rc = call_user_exact(I, AS_FUNC(fn), &arg, 1, c->n, out);
    } else {
        rc = eval_call_positional(I, e, fn, &arg, 1, c->n, c->assign, out);
    }
    val_unref(I, arg);
    cnode_unref(I, fn);
    return rc;
}

/* ---- statements ---- */

static int c_block(interp *I, env *e, const cnode *c, value *out)
{
    if (cstack_exhausted()) /* as eval_block */
        return eval_stack_overflow(I, c->n);
    if (!out) {
        for (int i = 0; i < c->nkids; i++)
            if (c->kids[i]->fn(I, e, c->kids[i], NULL))
                return -1;
        return 0;
    }
    value last = val_nil();
    for (int i = 0; i < c->nkids; i++) {
        const cnode *s = c->kids[i];
        if (s->n->kind != N_EXPR) {
            val_unref(I, last);
            last = val_nil();
        }
        if (s->fn(I, e, s, &last)) {
            val_unref(I, last);
            return -1;
        }
    }
    *out = last;
    return 0;
}

static int c_exprstmt(interp *I, env *e, const cnode *c, value *last)
{
    value v;
    if (cnode_eval(I, e, c->a, &v))
        return -1;
    eval_keep_last(I, last, v);
    return 0;
}

static int c_let(interp *I, env *e, const cnode *c, value *last)
{
    (void)last;
    value v;
    if (cnode_eval(I, e, c->a, &v))
        return -1;
    return scope_define(I, e, c->n, v);
}

static int c_assign(interp *I, env *e, const cnode *c, value *last)
{
    (void)last;
    const node *n = c->n;
    value *slot = scope_lookup(I, e, n);
    if (!slot)
        return err_at(I, n, ERR_NAME, "cannot assign to '%s': it is not defined (use 'let %s = …')", n->str,
                      n->str);
    value v;
    if (cnode_eval(I, e, c->a, &v))
        return -1;
    if (!c->a->pure)
        slot = scope_lookup(I, e, n); /* a call may have grown the scope */
    val_unref(I, *slot);
    *slot = v;
    return 0;
}

/* x = x OP b with b pure (compiled so only then): x is read once, and when
 * x and b are numbers the sum is written in place. In the walker's order: x
 * is looked up (an error if it is not defined), then x and b are read (b
 * has no effects, so the order of the two reads does not matter). */
#define UPDATE_FN(NAME, OP)                                                    \
    static int NAME(interp *I, env *e, const cnode *c, value *last)            \
    {                                                                          \
        (void)last;                                                            \
        const node *n = c->n;                                                  \
        value *slot = scope_lookup(I, e, n);                                   \
        if (!slot)                                                             \
            return err_at(I, n, ERR_NAME,                                      \
                          "cannot assign to '%s': it is not defined (use 'let %s = …')", \
                          n->str, n->str);                                     \
        value b;                                                               \
        if (cnode_eval(I, e, c->b, &b))                                        \
            return -1;                                                         \
        if (slot->k == V_NUM && b.k == V_NUM) {                                \
            slot->u.n = slot->u.n OP b.u.n;                                    \
            return 0;                                                          \
        }                                                                      \
        value a = *slot, v;                                                    \
        val_ref(a);                                                            \
        if (eval_binary_node(I, c->a->n, a, b, &v))                            \
            return -1;                                                         \
        val_unref(I, *slot);                                                   \
        *slot = v;                                                             \
        return 0;                                                              \
    }
UPDATE_FN(c_update_add, +)
UPDATE_FN(c_update_sub, -)
UPDATE_FN(c_update_mul, *)
UPDATE_FN(c_update_div, /)

/* ---- compiling ---------------------------------------------------------------- */

static cnode *cn_new(interp *I, cnode_fn fn, const node *n)
{
    cnode *c = mem_arena_alloc(I, sizeof *c);
    if (c) {
        c->fn = fn;
        c->n = n;
    }
    return c;
}

static const cnode *comp_expr(interp *I, const node *n, int depth);
static const cnode *comp_block(interp *I, const node *b, int depth);

static cnode_fn binary_fn(int op, int peek)
{
#define BINARY_CASE(TOK, NAME) \
    case TOK: return peek ? NAME##_pp : NAME;
    switch (op) {
    BINARY_CASE(T_PLUS, c_add)
    BINARY_CASE(T_MINUS, c_sub)
    BINARY_CASE(T_STAR, c_mul)
    BINARY_CASE(T_SLASH, c_div)
    BINARY_CASE(T_LT, c_lt)
    BINARY_CASE(T_LE, c_le)
    BINARY_CASE(T_GT, c_gt)
    BINARY_CASE(T_GE, c_ge)
    BINARY_CASE(T_EQ, c_eq)
    BINARY_CASE(T_NE, c_ne)
    default: return c_binary;
    }
#undef BINARY_CASE
}

static const cnode *comp_expr(interp *I, const node *n, int depth)
{
    cnode *c;
    if (depth >= COMPILE_MAX_NEST)
        return cn_new(I, c_walk, n);
    switch (n->kind) {
    case N_NUM:
        if ((c = cn_new(I, c_num, n))) {
            c->tag = CT_NUM;
            c->num = n->num;
            c->k = val_num(n->num);
            c->pure = 1;
        }
        return c;
    case N_BOOL:
    case N_NIL:
        if ((c = cn_new(I, c_const, n))) {
            c->k = n->kind == N_BOOL ? val_bool((int)n->num) : val_nil();
            c->pure = 1;
        }
        return c;
    case N_NAME:
        if ((c = cn_new(I, c_name, n))) {
            c->pure = 1;
            c->tag = n->slot && n->hops == 0 ? CT_LOCAL : CT_NAME;
            c->slot = n->slot - 1;
        }
        return c;
    case N_BINARY:
    case N_AND:
    case N_OR:
    case N_INDEX:
        if (!(c = cn_new(I, n->kind == N_INDEX ? c_index : c_andor, n)) ||
            !(c->a = comp_expr(I, n->kids[0], depth + 1)) || !(c->b = comp_expr(I, n->kids[1], depth + 1)))
            return NULL;
        c->pure = c->a->pure && c->b->pure;
        if (n->kind == N_BINARY)
            c->fn = binary_fn(n->op, c->a->tag != CT_OTHER && c->b->tag != CT_OTHER);
        return c;
    case N_UNARY:
    case N_FIELD:
        if (!(c = cn_new(I, n->kind == N_UNARY ? c_unary : c_field, n)) ||
            !(c->a = comp_expr(I, n->kids[0], depth + 1)))
            return NULL;
        c->pure = c->a->pure;
        return c;
    case N_IF:
        if (!(c = cn_new(I, c_if, n)) || !(c->a = comp_expr(I, n->kids[0], depth + 1)) ||
            !(c->b = comp_expr(I, n->kids[1], depth + 1)) ||
            (n->kids[2] && !(c->c = comp_expr(I, n->kids[2], depth + 1))))
            return NULL;
        c->pure = c->a->pure && c->b->pure && (!c->c || c->c->pure);
        {
            const node *k = n->kids[0];
            if (k->kind == N_BINARY && c->a->a && c->a->a->tag != CT_OTHER && c->a->b->tag != CT_OTHER &&
                (k->op == T_LT || k->op == T_LE || k->op == T_GT || k->op == T_GE || k->op == T_EQ ||
                 k->op == T_NE)) {
                c->fn = k->op == T_LT ? c_if_lt : k->op == T_LE ? c_if_le : k->op == T_GT ? c_if_gt
                        : k->op == T_GE ? c_if_ge : k->op == T_EQ ? c_if_eq : c_if_ne;
            }
        }
        return c;
    case N_LIST:
        if (!(c = cn_new(I, c_list, n)))
            return NULL;
        c->nkids = n->nkids;
        if (n->nkids && !(c->kids = mem_arena_alloc(I, (size_t)n->nkids * sizeof *c->kids)))
            return NULL;
        for (int i = 0; i < n->nkids; i++)
            if (!(c->kids[i] = comp_expr(I, n->kids[i], depth + 1)))
                return NULL;
        return c;
    case N_CALL: {
        int nargs = n->nkids - 1;
        int positional = nargs <= COMPILE_MAX_ARGS;
        for (int i = 1; i <= nargs && positional; i++)
            positional = n->names[i] == NULL;
        if (!positional)
            return cn_new(I, c_walk, n);
        if (!(c = cn_new(I, c_call, n)) || !(c->a = comp_expr(I, n->kids[0], depth + 1)))
            return NULL;
        c->nkids = nargs;
        if (nargs && !(c->kids = mem_arena_alloc(I, (size_t)nargs * sizeof *c->kids)))
            return NULL;
        for (int i = 0; i < nargs; i++)
            if (!(c->kids[i] = comp_expr(I, n->kids[i + 1], depth + 1)))
                return NULL;
        if (nargs == 1)
            c->fn = c_call1;
        return c;
    }
    case N_BLOCK:
        if (!(c = cn_new(I, c_doblock, n)) || !(c->a = comp_block(I, n, depth + 1)))
            return NULL;
        return c;
    default:
        return cn_new(I, c_walk, n);
    }
}

static const cnode *comp_stmt(interp *I, const node *s, int depth)
{
    cnode *c;
    cnode_fn fn = s->kind == N_EXPR ? c_exprstmt : s->kind == N_LET ? c_let : s->kind == N_ASSIGN ? c_assign : NULL;
    if (!fn || depth >= COMPILE_MAX_NEST)
        return cn_new(I, c_stmt_walk, s);
    if (!(c = cn_new(I, fn, s)) || !(c->a = comp_expr(I, s->kids[0], depth + 1)))
        return NULL;
    if (s->kind == N_ASSIGN && (c->a->fn == c_call || c->a->fn == c_call1))
        ((cnode *)c->a)->assign = s;
    const node *r = s->kids[0];
    if (s->kind == N_ASSIGN && r->kind == N_BINARY && c->a->b->pure && r->kids[0]->kind == N_NAME &&
        r->kids[0]->str == s->str && r->kids[0]->slot == s->slot && r->kids[0]->hops == s->hops &&
        s->slot) {
        cnode_fn up = r->op == T_PLUS ? c_update_add : r->op == T_MINUS ? c_update_sub
                      : r->op == T_STAR ? c_update_mul : r->op == T_SLASH ? c_update_div : NULL;
        if (up) {
            c->fn = up;
            c->b = c->a->b;
        }
    }
    return c;
}

static const cnode *comp_block(interp *I, const node *b, int depth)
{
    if (b->code)
        return b->code;
    cnode *c = cn_new(I, c_block, b);
    if (!c)
        return NULL;
    c->nkids = b->nkids;
    if (b->nkids && !(c->kids = mem_arena_alloc(I, (size_t)b->nkids * sizeof *c->kids)))
        return NULL;
    for (int i = 0; i < b->nkids; i++)
        if (!(c->kids[i] = comp_stmt(I, b->kids[i], depth + 1)))
            return NULL;
    ((node *)b)->code = c;
    return c;
}

const cnode *compile_block(interp *I, const node *block)
{
    return comp_block(I, block, 0);
}

/* Can running n make a closure (a lambda, or a fn definition's)? The only
 * way a scope outlives its run. Nesting deeper than `depth` allows: 1. */
static int makes_closure(const node *n, int depth)
{
    if (!n)
        return 0;
    if (n->kind == N_LAMBDA || depth == 0)
        return 1;
    for (int i = 0; i < n->nkids; i++)
        if (makes_closure(n->kids[i], depth - 1))
            return 1;
    return 0;
}

const cnode *compile_lambda(interp *I, const node *lambda)
{
    if (lambda->code)
        return lambda->code;
    cnode *c = (cnode *)(lambda->body->kind == N_BLOCK ? comp_block(I, lambda->body, 0)
                                                        : comp_expr(I, lambda->body, 0));
    if (c)
        c->local_scope = !makes_closure(lambda->body, 256);
    ((node *)lambda)->code = c;
    return c;
}
