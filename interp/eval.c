/* eval.c — evaluation of expressions and statements. */
#define _XOPEN_SOURCE 700
#include "eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "compile.h"
#include "contract.h"
#include "cstack.h"
#include "fileio.h"
#include "lang_objects.h"
#include "lexer.h"
#include "parser.h"
#include "resolve.h"
#include "shard.h"
#include "stdlib_embed.h"

value *eval_scope_search(interp *I, env *e, const node *n)
{
    I->count.name_searches++;
    return val_env_lookup(e, n->str);
}

/* A name's value (a new reference), or the error for an unknown one. */
static inline int eval_name(interp *I, env *e, const node *n, value *out)
{
    value *v = scope_lookup(I, e, n);
    if (!v)
        return err_at(I, n, ERR_NAME, "unknown name '%s'", n->str);
    *out = *v;
    val_ref(*out);
    return 0;
}

static int check_interrupt(interp *I, const node *at)
{
    if (I->interrupt && *I->interrupt)
        return err_at(I, at, ERR_INTERRUPT, "interrupted");
    return 0;
}

/* ---- arithmetic ----------------------------------------------------------- */

static const char *op_text(int op)
{
    switch (op) {
    case T_PLUS: return "+";
    case T_MINUS: return "-";
    case T_STAR: return "*";
    case T_SLASH: return "/";
    case T_PERCENT: return "%";
    case T_CARET: return "^";
    case T_LT: return "<";
    case T_LE: return "<=";
    case T_GT: return ">";
    case T_GE: return ">=";
    default: return "?";
    }
}

static double num_op(int op, double a, double b)
{
    switch (op) {
    case T_PLUS: return a + b;
    case T_MINUS: return a - b;
    case T_STAR: return a * b;
    case T_SLASH: return a / b;
    case T_PERCENT: return a - b * floor(a / b); /* sign of the divisor, like Python */
    case T_CARET: return pow(a, b);
    default: return NAN;
    }
}

static int obj_arith(interp *I, int op, value a, value b, value *out, int *handled)
{
    *handled = 0;
    vobj *o = a.k == V_OBJ ? AS_OBJ(a) : b.k == V_OBJ ? AS_OBJ(b) : NULL;
    if (o && o->cls->arith) {
        int r = o->cls->arith(I, op, a, b, out);
        if (r < 0)
            return -1;
        *handled = r;
    }
    if (!*handled && a.k == V_OBJ && b.k == V_OBJ && AS_OBJ(b)->cls->arith && AS_OBJ(b) != o) {
        int r = AS_OBJ(b)->cls->arith(I, op, a, b, out);
        if (r < 0)
            return -1;
        *handled = r;
    }
    return 0;
}

static int binary_op(interp *I, int op, value a, value b, value *out, const node *at);

int eval_binary(interp *I, int op, value a, value b, value *out, const node *at)
{
    if (a.k == V_NUM && b.k == V_NUM)
        return binary_op(I, op, a, b, out, at);
    /* allocation failures (a memory limit inside `+`) are reported at the operator */
    const node *save = I->cur;
    if (at)
        I->cur = at;
    int r = binary_op(I, op, a, b, out, at);
    I->cur = save;
    return r;
}

static int binary_op(interp *I, int op, value a, value b, value *out, const node *at)
{
    *out = val_nil();
    if (a.k == V_NUM && b.k == V_NUM) {
        switch (op) {
        case T_LT: *out = val_bool(a.u.n < b.u.n); return 0;
        case T_LE: *out = val_bool(a.u.n <= b.u.n); return 0;
        case T_GT: *out = val_bool(a.u.n > b.u.n); return 0;
        case T_GE: *out = val_bool(a.u.n >= b.u.n); return 0;
        default: *out = val_num(num_op(op, a.u.n, b.u.n)); return 0;
        }
    }
    int handled;
    if (obj_arith(I, op, a, b, out, &handled))
        return -1;
    if (handled)
        return 0;
    if (op == T_PLUS && a.k == V_STR && b.k == V_STR) {
        vstr *x = AS_STR(a), *y = AS_STR(b);
        char *buf = mem_alloc(I, x->len + y->len + 1);
        if (!buf)
            return -1;
        memcpy(buf, x->s, x->len);
        memcpy(buf + x->len, y->s, y->len);
        *out = val_str(I, buf, x->len + y->len);
        mem_free(I, buf);
        return out->k == V_NIL ? -1 : 0;
    }
    if ((op == T_LT || op == T_LE || op == T_GT || op == T_GE) && a.k == V_STR && b.k == V_STR) {
        int c = strcmp(AS_STR(a)->s, AS_STR(b)->s);
        int r = op == T_LT ? c < 0 : op == T_LE ? c <= 0 : op == T_GT ? c > 0 : c >= 0;
        *out = val_bool(r);
        return 0;
    }
    int arith = op == T_PLUS || op == T_MINUS || op == T_STAR || op == T_SLASH || op == T_PERCENT ||
                op == T_CARET;
    if (arith && (a.k == V_LIST || b.k == V_LIST) &&
        (a.k == V_LIST || a.k == V_NUM) && (b.k == V_LIST || b.k == V_NUM)) {
        /* element-wise: vectors are lists of numbers (nested lists recurse) */
        if (cstack_exhausted())
            return cstack_error(I, at, "lists nested too deeply");
        size_t n = a.k == V_LIST ? AS_LIST(a)->n : AS_LIST(b)->n;
        if (a.k == V_LIST && b.k == V_LIST && AS_LIST(a)->n != AS_LIST(b)->n)
            return err_at(I, at, ERR_TYPE, "cannot apply '%s' to lists of different lengths (%zu and %zu)",
                          op_text(op), AS_LIST(a)->n, AS_LIST(b)->n);
        value res = val_list(I, n);
        if (res.k == V_NIL)
            return -1;
        for (size_t i = 0; i < n; i++) {
            value x = a.k == V_LIST ? AS_LIST(a)->items[i] : a;
            value y = b.k == V_LIST ? AS_LIST(b)->items[i] : b;
            value r;
            if (binary_op(I, op, x, y, &r, at) || val_list_push(I, AS_LIST(res), r)) {
                val_unref(I, res);
                return -1;
            }
        }
        *out = res;
        return 0;
    }
    return err_at(I, at, ERR_TYPE, "cannot apply '%s' to %s and %s", op_text(op), val_type_name(a),
                  val_type_name(b));
}

static int eval_unary(interp *I, int op, value a, value *out, const node *at)
{
    if (op == 'n') {
        *out = val_bool(!val_truthy(a));
        return 0;
    }
    if (a.k == V_NUM) {
        *out = val_num(op == '-' ? -a.u.n : a.u.n);
        return 0;
    }
    if (op == '+' && (a.k == V_LIST || a.k == V_OBJ)) {
        val_ref(a);
        *out = a;
        return 0;
    }
    if (a.k == V_LIST)
        return eval_binary(I, T_STAR, a, val_num(-1), out, at);
    int handled;
    if (obj_arith(I, OP_NEG, a, val_nil(), out, &handled))
        return -1;
    if (handled)
        return 0;
    return err_at(I, at, ERR_TYPE, "cannot negate %s", val_type_name(a));
}

/* ---- calls ------------------------------------------------------------------ */

static int push_frame(interp *I, const char *name, const node *call)
{
    if (I->depth >= I->lim.max_depth)
        return err_at(I, call, ERR_LIMIT,
                      "call depth limit of %d reached (infinite recursion? raise it with --max-depth)",
                      I->lim.max_depth);
    if (I->depth == I->stack_cap) {
        int nc = I->stack_cap ? I->stack_cap * 2 : 64;
        frame *ns = mem_realloc(I, I->stack, (size_t)nc * sizeof *ns);
        if (!ns)
            return -1;
        I->stack = ns;
        I->stack_cap = nc;
    }
    I->stack[I->depth].fname = name;
    I->stack[I->depth].call = call;
    I->depth++;
    return 0;
}

/* Call a user function with positional args and named args. Arguments are
 * matched with contract_match, as the static check and builtins do, so an
 * error about one argument puts the caret on it (anodes, may be NULL). */
static int call_user(interp *I, vfunc *f, const value *pos, int npos, const char **names,
                     const value *named, int nnamed, const node *const *anodes, const node *call, value *out)
{
    const node *l = f->lambda;
    const char *fname = f->name ? f->name : "<lambda>";
    if (l->nparams > MAX_ARGS)
        return err_at(I, call, ERR_LIMIT, "too many parameters");
    if (npos + nnamed > MAX_ARGS)
        return err_at(I, call, ERR_TYPE, "%s: too many arguments", fname);
    value bound[MAX_ARGS];
    int have[MAX_ARGS];
    if (nnamed == 0 && npos == l->nparams) {
        /* every parameter given in order: nothing for contract_match to report */
        for (int i = 0; i < npos; i++) {
            bound[i] = pos[i];
            have[i] = 1;
        }
    } else {
        const char *anames[MAX_ARGS];
        int required[MAX_ARGS], slot[MAX_ARGS];
        for (int j = 0; j < l->nparams; j++) {
            required[j] = l->kids[j] == NULL;
            have[j] = 0;
        }
        for (int i = 0; i < npos; i++)
            anames[i] = NULL;
        for (int k = 0; k < nnamed; k++)
            anames[npos + k] = names[k];
        if (contract_match(I, fname, l->names, required, l->nparams, 0, "", anames, anodes, npos + nnamed, call,
                           slot))
            return -1;
        for (int i = 0; i < npos + nnamed; i++) {
            bound[slot[i]] = i < npos ? pos[i] : named[i - npos];
            have[slot[i]] = 1;
        }
    }
    env *e = val_env_new(I, f->closure);
    if (!e)
        return -1;
    int rc = -1;
    for (int j = 0; j < l->nparams; j++) {
        value v;
        if (have[j]) {
            v = bound[j];
            val_ref(v);
        } else {
            /* defaults are evaluated in the new scope, so they can use earlier parameters */
            if (eval_expr(I, e, l->kids[j], &v))
                goto done;
        }
        if ((size_t)j == e->n && e->n < e->cap) {
            /* parameter j goes to slot j: the parser refuses duplicate names */
            e->names[j] = l->names[j];
            e->vals[j] = v;
            e->n++;
        } else if ((size_t)j == e->n ? val_env_append(I, e, l->names[j], v) : val_env_define(I, e, l->names[j], v)) {
            goto done;
        }
    }
    if (push_frame(I, fname, call))
        goto done;
    const cnode *body = compile_lambda(I, l); /* compile.c: the first call compiles it */
    rc = body ? body->fn(I, e, body, out) : -1;
    I->depth--;
done:
    val_heap_unref(I, &e->h);
    return rc;
}

/* Bind a builtin's arguments to its declared parameters and check each
 * against its declaration (contract.c): the one place builtin arguments are
 * checked. anodes (may be NULL) are the argument expressions, for carets. */
static int call_builtin(interp *I, const builtin *b, const value *pos, int npos, const char **names,
                        const value *named, int nnamed, const node *const *anodes, const node *call,
                        value *out)
{
    if (I->shard && shard_scan_args(I, b->name, call, pos, npos, named, nnamed))
        return -1; /* a partial value passed on: re-run with its call computed fully */
    const bspec *spec = contract_spec(I, b);
    if (!spec)
        return err_at(I, call, ERR_RUNTIME, "internal error: builtin %s is not registered", b->name);
    if ((b->variadic ? npos : 0) + b->nparams > MAX_ARGS || npos + nnamed > MAX_ARGS)
        return err_at(I, call, ERR_TYPE, "%s: too many arguments", b->name);
    const char *pnames[MAX_ARGS], *anames[MAX_ARGS];
    int required[MAX_ARGS], slot[MAX_ARGS];
    for (int j = 0; j < spec->n; j++) {
        pnames[j] = spec->p[j].name;
        required[j] = spec->p[j].required;
    }
    for (int i = 0; i < npos; i++)
        anames[i] = NULL;
    for (int k = 0; k < nnamed; k++)
        anames[npos + k] = names[k];
    if (contract_match(I, b->name, pnames, required, spec->n, b->variadic, "at most ", anames, anodes,
                       npos + nnamed, call, slot))
        return -1;
    value args[MAX_ARGS];
    const node *nodes[MAX_ARGS];
    int have[MAX_ARGS] = {0};
    int base = b->variadic ? npos : 0;
    int nargs = base + spec->n;
    for (int i = 0; i < npos + nnamed; i++) {
        int s = slot[i] < 0 ? i : base + slot[i];
        args[s] = i < npos ? pos[i] : named[i - npos];
        nodes[s] = anodes ? anodes[i] : NULL;
        have[s] = 1;
    }
    for (int j = 0; j < spec->n; j++) {
        const cparam *cp = &spec->p[j];
        int s = base + j;
        if (!have[s]) {
            if (contract_default(I, spec, j, &args[s]))
                return -1;
            nodes[s] = NULL;
            continue;
        }
        if (args[s].k == V_NIL && cp->def_nil)
            continue;
        char what[160]; /* "argument 'NAME'", without snprintf: every call builds it */
        size_t nl = strlen(cp->name);
        if (nl > sizeof what - 13)
            nl = sizeof what - 13;
        memcpy(what, "argument '", 10);
        memcpy(what + 10, cp->name, nl);
        memcpy(what + 10 + nl, "'", 2);
        cpos at = {nodes[s] ? nodes[s] : call, -1, 0, 0};
        if (contract_check_value(I, cp->type, args[s], b->name, what, at))
            return -1;
    }
    const node *save = I->cur;
    const bcall *save_call = I->bcall;
    bcall bc = {b, args, nodes, nargs};
    I->cur = call;
    I->bcall = &bc;
    int rc = b->fn(I, args, b->variadic ? npos : nargs, out);
    if (I->shard)
        rc = shard_after_builtin(I, rc, out); /* a sharded engine call's result becomes a partial value */
    I->cur = save;
    I->bcall = save_call;
    if (rc == 0 && I->err.active)
        rc = -1;
    return rc;
}

static int call_any(interp *I, value fn, const value *pos, int npos, const char **names,
                    const value *named, int nnamed, const node *const *anodes, const node *call, value *out)
{
    *out = val_nil();
    if (check_interrupt(I, call))
        return -1;
    if (fn.k == V_FUNC)
        return call_user(I, AS_FUNC(fn), pos, npos, names, named, nnamed, anodes, call, out);
    if (fn.k == V_BUILTIN)
        return call_builtin(I, fn.u.bi, pos, npos, names, named, nnamed, anodes, call, out);
    return err_at(I, call, ERR_TYPE, "cannot call %s (it is not a function)", val_type_name(fn));
}

int eval_call_value(interp *I, value fn, const value *args, int nargs, value *out)
{
    return call_any(I, fn, args, nargs, NULL, NULL, 0, NULL, I->cur, out);
}

/* Kept out of eval_expr so its argument arrays do not enlarge every nested
 * evaluation's frame (the C stack is the nesting limit, see cstack.h).
 * lazy (may be NULL): if the callee is the builtin range, its items are
 * described there instead of built (`for` and comprehensions). assign (may
 * be NULL): the `x = …` this call is the value of; if the callee is the
 * builtin concat and its first argument is the list x still holds, concat
 * may extend that list in place (builtins_core.c checks nothing else holds it). */
__attribute__((noinline)) static int eval_call_in(interp *I, env *e, const node *n, value *out, range_spec *lazy,
                                                  const node *assign)
{
    value fn;
    if (eval_expr(I, e, n->kids[0], &fn))
        return -1;
    int nargs = n->nkids - 1;
    if (nargs > MAX_ARGS) {
        val_unref(I, fn);
        return err_at(I, n, ERR_LIMIT, "too many arguments (at most %d)", MAX_ARGS);
    }
    value pos[MAX_ARGS], named[MAX_ARGS];
    const char *names[MAX_ARGS];
    const node *posn[MAX_ARGS], *anodes[MAX_ARGS];
    int npos = 0, nnamed = 0, rc = -1;
    for (int i = 1; i <= nargs; i++) {
        value v;
        if (eval_expr(I, e, n->kids[i], &v))
            goto done;
        if (n->names[i]) {
            names[nnamed] = n->names[i];
            anodes[MAX_ARGS - 1 - nnamed] = n->kids[i];
            named[nnamed++] = v;
        } else {
            posn[npos] = n->kids[i];
            pos[npos++] = v;
        }
    }
    /* argument nodes in call order: positional ones, then named ones */
    for (int k = 0; k < nnamed; k++)
        posn[npos + k] = anodes[MAX_ARGS - 1 - k];
    if (lazy && fn.k == V_BUILTIN && strcmp(fn.u.bi->name, "range") == 0) {
        I->lazy_range = lazy;
        rc = call_any(I, fn, pos, npos, names, named, nnamed, posn, n, out);
        I->lazy_range = NULL;
    } else if (assign && npos > 0 && pos[0].k == V_LIST && fn.k == V_BUILTIN &&
               strcmp(fn.u.bi->name, "concat") == 0) {
        value *x = scope_lookup(I, e, assign); /* the arguments may have reassigned it */
        I->append_target = x && x->k == V_LIST && x->u.h == pos[0].u.h ? pos[0].u.h : NULL;
        rc = call_any(I, fn, pos, npos, names, named, nnamed, posn, n, out);
        I->append_target = NULL;
    } else {
        rc = call_any(I, fn, pos, npos, names, named, nnamed, posn, n, out);
    }
done:
    for (int i = 0; i < npos; i++)
        val_unref(I, pos[i]);
    for (int i = 0; i < nnamed; i++)
        val_unref(I, named[i]);
    val_unref(I, fn);
    return rc;
}

static int eval_call(interp *I, env *e, const node *n, value *out)
{
    return eval_call_in(I, e, n, out, NULL, NULL);
}

/* ---- indexing --------------------------------------------------------------- */

static int eval_index(interp *I, value a, value ix, value *out, const node *at)
{
    if (a.k == V_LIST || a.k == V_STR) {
        if (ix.k != V_NUM || ix.u.n != floor(ix.u.n))
            return err_at(I, at, ERR_TYPE, "%s index must be a whole number, got %s",
                          a.k == V_LIST ? "list" : "string",
                          ix.k == V_NUM ? "a fraction" : val_type_name(ix));
        double len = a.k == V_LIST ? (double)AS_LIST(a)->n : (double)AS_STR(a)->len;
        double i = ix.u.n < 0 ? ix.u.n + len : ix.u.n;
        if (i < 0 || i >= len)
            return err_at(I, at, ERR_VALUE, "index %.0f is out of range for a %s of length %.0f",
                          ix.u.n, a.k == V_LIST ? "list" : "string", len);
        if (a.k == V_LIST) {
            *out = AS_LIST(a)->items[(size_t)i];
            val_ref(*out);
        } else {
            *out = val_str(I, AS_STR(a)->s + (size_t)i, 1);
        }
        return 0;
    }
    if (a.k == V_REC) {
        if (ix.k != V_STR)
            return err_at(I, at, ERR_TYPE, "record index must be a string, got %s", val_type_name(ix));
        const char *key = interp_intern(I, AS_STR(ix)->s, AS_STR(ix)->len);
        value *v = key ? val_rec_get(AS_REC(a), key) : NULL;
        if (!v)
            return err_at(I, at, ERR_VALUE, "record has no field \"%s\"", AS_STR(ix)->s);
        *out = *v;
        val_ref(*out);
        return 0;
    }
    return err_at(I, at, ERR_TYPE, "cannot index %s", val_type_name(a));
}

static int eval_field(interp *I, value a, const char *name, value *out, const node *at)
{
    if (a.k == V_REC) {
        value *v = val_rec_get(AS_REC(a), name);
        if (!v) {
            vrec *r = AS_REC(a);
            const char *s = interp_suggest_name(name, r->keys, r->n);
            return err_at(I, at, ERR_VALUE, "record has no field '%s'%s%s%s", name,
                          s ? " (did you mean '" : "", s ? s : "", s ? "'?)" : "");
        }
        *out = *v;
        val_ref(*out);
        return 0;
    }
    if (a.k == V_OBJ && AS_OBJ(a)->cls->get) {
        int r = AS_OBJ(a)->cls->get(I, AS_OBJ(a)->payload, name, out);
        if (r <= 0)
            return r;
        return err_at(I, at, ERR_VALUE, "%s has no field '%s'", AS_OBJ(a)->cls->name, name);
    }
    return err_at(I, at, ERR_TYPE, "%s has no fields (looking up '.%s')", val_type_name(a), name);
}

/* ---- expressions ------------------------------------------------------------- */

__attribute__((noinline)) static int eval_table(interp *I, env *e, const node *n, value *out)
{
    value t = val_list(I, (size_t)n->nkids);
    if (t.k == V_NIL)
        return -1;
    for (int r = 0; r < n->nkids; r++) {
        const node *row = n->kids[r];
        value rv = val_list(I, (size_t)row->nkids);
        if (rv.k == V_NIL)
            goto fail;
        for (int c = 0; c < row->nkids; c++) {
            value v;
            if (eval_expr(I, e, row->kids[c], &v)) {
                val_unref(I, rv);
                goto fail;
            }
            if (v.k != V_NUM) {
                err_at(I, row->kids[c], ERR_TYPE, "table entries must be numbers, got %s",
                       val_type_name(v));
                val_unref(I, v);
                val_unref(I, rv);
                goto fail;
            }
            if (val_list_push(I, AS_LIST(rv), v)) {
                val_unref(I, rv);
                goto fail;
            }
        }
        if (val_list_push(I, AS_LIST(t), rv))
            goto fail;
    }
    *out = t;
    return 0;
fail:
    val_unref(I, t);
    return -1;
}

static int iterate_list(interp *I, value it, const node *at)
{
    if (it.k != V_LIST)
        return err_at(I, at, ERR_TYPE, "'for' needs a list to iterate over, got %s (use range(n) for numbers)",
                      val_type_name(it));
    return 0;
}

/* What a `for` or comprehension walks: a list in *it, or (rs->used) the
 * items of range(…) without the list, *it nil. *count is the number of items. */
static int eval_iterable(interp *I, env *e, const node *n, value *it, range_spec *rs, size_t *count)
{
    memset(rs, 0, sizeof *rs);
    if (n->kind == N_CALL) {
        if (eval_call_in(I, e, n, it, rs, NULL))
            return -1;
    } else if (eval_expr(I, e, n, it)) {
        return -1;
    }
    if (rs->used) {
        *count = rs->count;
        return 0;
    }
    if (iterate_list(I, *it, n)) {
        val_unref(I, *it);
        return -1;
    }
    *count = AS_LIST(*it)->n;
    return 0;
}

/* Item i of what eval_iterable gave (a new reference). */
static inline value iter_item(value it, const range_spec *rs, size_t i)
{
    if (rs->used)
        return val_num(rs->start + rs->step * (double)i);
    value x = AS_LIST(it)->items[i];
    val_ref(x);
    return x;
}

/* After an iteration: the scope is emptied for the next one unless a
 * closure made in the body kept it (then the next iteration gets a new
 * one, so each closure keeps its own iteration's values). */
static env *iter_scope_next(interp *I, env *s)
{
    if (s->h.rc == 1 && !s->index) {
        for (size_t k = 0; k < s->n; k++)
            val_unref(I, s->vals[k]);
        s->n = 0;
        s->loose = 0;
        return s;
    }
    val_heap_unref(I, &s->h);
    return NULL;
}

__attribute__((noinline)) static int eval_comp(interp *I, env *e, const node *n, value *out)
{
    value it;
    range_spec rs;
    size_t count;
    env *s = NULL;
    if (eval_iterable(I, e, n->kids[1], &it, &rs, &count))
        return -1;
    /* with a filter the result may be much shorter: grow it as it fills */
    value res = val_list(I, n->kids[2] ? 0 : count);
    if (res.k == V_NIL) {
        val_unref(I, it);
        return -1;
    }
    for (size_t i = 0; i < count; i++) {
        if (check_interrupt(I, n))
            goto fail;
        if (!s && !(s = val_env_new(I, e)))
            goto fail;
        value x = iter_item(it, &rs, i);
        /* the variable is the scope's first name, slot 1 (resolve.c) */
        int ok = (s->n == 0 ? val_env_append(I, s, n->str, x) : val_env_define(I, s, n->str, x)) == 0;
        int keep = 1;
        if (ok && n->kids[2]) {
            value c;
            ok = eval_expr(I, s, n->kids[2], &c) == 0;
            if (ok) {
                keep = val_truthy(c);
                val_unref(I, c);
            }
        }
        value v = val_nil();
        if (ok && keep) {
            ok = eval_expr(I, s, n->kids[0], &v) == 0 && val_list_push(I, AS_LIST(res), v) == 0;
        }
        if (!ok)
            goto fail;
        s = iter_scope_next(I, s);
    }
    if (s)
        val_heap_unref(I, &s->h);
    val_unref(I, it);
    *out = res;
    return 0;
fail:
    if (s)
        val_heap_unref(I, &s->h);
    val_unref(I, it);
    val_unref(I, res);
    return -1;
}

void eval_keep_last(interp *I, value *last, value v)
{
    if (last) {
        val_unref(I, *last);
        *last = v;
    } else {
        val_unref(I, v);
    }
}

/* element i of a list literal: kid i evaluated (eval_kids) */
static int list_kid(interp *I, const void *ctx, size_t i, value *out)
{
    const eval_kids *k = ctx;
    const node *n = k->of;
    return eval_expr(I, k->e, n->kids[i], out);
}

/* The C stack is nearly full. Inside a function the error is reported at
 * the innermost call (the recursion the reader looks for; where exactly the
 * stack ran out depends on frame sizes), else at the node. */
static int stack_overflow(interp *I, const node *n)
{
    if (I->depth > 0 && I->stack[I->depth - 1].call)
        n = I->stack[I->depth - 1].call;
    return cstack_error(I, n, "calls and expressions nested too deeply");
}

static int binary_values(interp *I, const node *n, value a, value b, value *out);

/* The node kinds eval_expr leaves to this function: kept out of it so the
 * frequent ones (numbers, names, arithmetic, calls, conditions) run in a
 * small frame. */
__attribute__((noinline)) static int eval_cold(interp *I, env *e, const node *n, value *out)
{
    *out = val_nil();
    switch (n->kind) {
    case N_NUM:
        *out = val_num(n->num);
        return 0;
    case N_STR:
        *out = val_str(I, n->str, n->slen);
        return out->k == V_NIL ? -1 : 0;
    case N_BOOL:
        *out = val_bool((int)n->num);
        return 0;
    case N_NIL:
        return 0;
    case N_NAME:
        return eval_name(I, e, n, out);
    case N_LIST: {
        const eval_kids k = {e, n};
        return val_list_build(I, (size_t)n->nkids, list_kid, &k, out);
    }
    case N_COMP:
        return eval_comp(I, e, n, out);
    case N_RECORD: {
        value r = val_rec(I);
        if (r.k == V_NIL)
            return -1;
        for (int i = 0; i < n->nkids; i++) {
            value v;
            if (eval_expr(I, e, n->kids[i], &v) || val_rec_set(I, AS_REC(r), n->names[i], v)) {
                val_unref(I, r);
                return -1;
            }
        }
        *out = r;
        return 0;
    }
    case N_TABLE:
        return eval_table(I, e, n, out);
    case N_UNARY: {
        value a;
        if (eval_expr(I, e, n->kids[0], &a))
            return -1;
        int r = eval_unary(I, n->op, a, out, n);
        val_unref(I, a);
        return r;
    }
    case N_BINARY: {
        value a, b;
        if (eval_expr(I, e, n->kids[0], &a))
            return -1;
        if (eval_expr(I, e, n->kids[1], &b)) {
            val_unref(I, a);
            return -1;
        }
        return binary_values(I, n, a, b, out);
    }
    case N_INDEX: {
        value a, ix;
        if (eval_expr(I, e, n->kids[0], &a))
            return -1;
        if (eval_expr(I, e, n->kids[1], &ix)) {
            val_unref(I, a);
            return -1;
        }
        int r = eval_index(I, a, ix, out, n);
        val_unref(I, a);
        val_unref(I, ix);
        return r;
    }
    case N_FIELD: {
        value a;
        if (eval_expr(I, e, n->kids[0], &a))
            return -1;
        int r = eval_field(I, a, n->str, out, n);
        val_unref(I, a);
        return r;
    }
    case N_BLOCK: {
        env *s = val_env_new(I, e);
        if (!s)
            return -1;
        int r = eval_block(I, s, n, out);
        val_heap_unref(I, &s->h);
        return r;
    }
    case N_LAMBDA:
        *out = val_func(I, n, e, n->str);
        return out->k == V_NIL ? -1 : 0;
    default:
        return err_at(I, n, ERR_RUNTIME, "internal error: statement in expression position");
    }
}

/* a op b for the operator node n; takes a and b. */
__attribute__((noinline)) static int binary_values(interp *I, const node *n, value a, value b, value *out)
{
    {
        int r;
        if (n->op == T_EQ || n->op == T_NE) {
            int handled = 0;
            r = 0;
            if (a.k == V_OBJ || b.k == V_OBJ)
                r = obj_arith(I, n->op, a, b, out, &handled);
            if (!handled && r == 0) {
                const node *save = I->cur;
                I->cur = n; /* a stack overflow comparing deep lists is reported here */
                int eq = val_equal(I, a, b);
                I->cur = save;
                if (eq < 0)
                    r = -1;
                else
                    *out = val_bool(eq == (n->op == T_EQ));
            }
        } else {
            r = eval_binary(I, n->op, a, b, out, n);
        }
        val_unref(I, a);
        val_unref(I, b);
        return r;
    }
}

/* An operand that needs no recursion: a number or a resolved name. */
static inline int eval_leaf(interp *I, env *e, const node *n, value *out)
{
    if (n->kind == N_NUM) {
        *out = val_num(n->num);
        return 0;
    }
    if (n->kind == N_NAME) {
        value *v = scope_lookup(I, e, n);
        if (v) {
            *out = *v;
            val_ref(*out);
            return 0;
        }
    }
    return eval_expr(I, e, n, out);
}

int eval_expr(interp *I, env *e, const node *n, value *out)
{
    *out = val_nil();
    /* every nested evaluation passes here: the C stack bounds the nesting */
    if (cstack_exhausted())
        return stack_overflow(I, n);
    switch (n->kind) {
    case N_NUM:
        *out = val_num(n->num);
        return 0;
    case N_NAME:
        return eval_name(I, e, n, out);
    case N_BINARY: {
        value a, b;
        if (eval_leaf(I, e, n->kids[0], &a))
            return -1;
        if (eval_leaf(I, e, n->kids[1], &b)) {
            val_unref(I, a);
            return -1;
        }
        if (a.k == V_NUM && b.k == V_NUM) {
            double x = a.u.n, y = b.u.n;
            switch (n->op) {
            case T_PLUS: *out = val_num(x + y); return 0;
            case T_MINUS: *out = val_num(x - y); return 0;
            case T_STAR: *out = val_num(x * y); return 0;
            case T_SLASH: *out = val_num(x / y); return 0;
            case T_LT: *out = val_bool(x < y); return 0;
            case T_LE: *out = val_bool(x <= y); return 0;
            case T_GT: *out = val_bool(x > y); return 0;
            case T_GE: *out = val_bool(x >= y); return 0;
            case T_EQ: *out = val_bool(x == y); return 0; /* as val_equal */
            case T_NE: *out = val_bool(x != y); return 0;
            default: break;
            }
        }
        return binary_values(I, n, a, b, out);
    }
    case N_AND:
    case N_OR: {
        value a;
        if (eval_expr(I, e, n->kids[0], &a))
            return -1;
        int t = val_truthy(a);
        if ((n->kind == N_AND && !t) || (n->kind == N_OR && t)) {
            *out = a;
            return 0;
        }
        val_unref(I, a);
        return eval_expr(I, e, n->kids[1], out);
    }
    case N_CALL:
        return eval_call(I, e, n, out);
    case N_IF: {
        value c;
        if (eval_expr(I, e, n->kids[0], &c))
            return -1;
        int t = val_truthy(c);
        val_unref(I, c);
        if (t)
            return eval_expr(I, e, n->kids[1], out);
        if (n->kids[2])
            return eval_expr(I, e, n->kids[2], out);
        return 0;
    }
    default:
        return eval_cold(I, e, n, out);
    }
}

/* ---- statements --------------------------------------------------------------- */

/* -D NAME=VALUE for `param NAME = default` (main.c runs this before the script
 * for literal defaults). A string param takes the text as it is, or a quoted
 * "string"; anything else is an expression evaluated among the builtins only
 * (so the result does not depend on where the script is), and must have the
 * default's type (any type for a nil default), a number being finite, as are
 * the numbers in a list. A wrong value is a usage error at the `param`. */
static int apply_param_override(interp *I, const node *n, value def, value *out)
{
    for (int i = 0; i < I->noverrides; i++) {
        param_override *o = &I->overrides[i];
        if (o->name != n->str)
            continue;
        o->used = 1;
        const node *at = n;
        const char *tn = val_type_name(def), *t = o->text;
        const char *article = def.k == V_NIL ? "" : strchr("aeiou", tn[0]) ? "an " : "a ";
        value v;
        if (def.k == V_STR && t[0] != '"') {
            v = val_cstr(I, t);
            if (v.k == V_NIL)
                return -1;
        } else {
            char srcname[160];
            snprintf(srcname, sizeof srcname, "-D %s", n->str);
            int src = interp_add_source(I, srcname, t, strlen(t));
            if (src < 0)
                return -1;
            env *root = I->globals;
            while (root->parent)
                root = root->parent;
            int save_depth = I->depth;
            node *prog;
            int bad = parse_source(I, src, &prog) || prog->nkids != 1 || prog->kids[0]->kind != N_EXPR ||
                      eval_expr(I, root, prog->kids[0]->kids[0], &v);
            if (bad) {
                err_kind k = I->err.active ? I->err.kind : ERR_SYNTAX;
                if (k != ERR_SYNTAX && k != ERR_NAME && k != ERR_TYPE && k != ERR_VALUE)
                    return -1; /* out of memory, interrupted…: not about the text */
                err_clear(I);
                I->depth = save_depth;
                if (def.k == V_NIL)
                    return err_at(I, at, ERR_USAGE,
                                  "-D %s=%s: '%s' is not a value (the default is nil, so any value "
                                  "goes; quote a string: -D '%s=\"%s\"')",
                                  n->str, t, t, n->str, t);
                return err_at(I, at, ERR_USAGE, "-D %s=%s: the parameter is %s%s%s, and '%s' is not one",
                              n->str, t, article, tn, def.k == V_BOOL ? " (true or false)" : "", t);
            }
        }
        if (def.k != V_NIL && v.k != def.k) {
            const char *vn = val_type_name(v);
            err_at(I, at, ERR_USAGE, "-D %s=%s: the parameter is %s%s%s, and '%s' is %s%s", n->str, t,
                   article, tn, def.k == V_BOOL ? " (true or false)" : "", t,
                   strchr("aeiou", vn[0]) ? "an " : "a ", vn);
            val_unref(I, v);
            return -1;
        }
        const value *items = &v;
        size_t nitems = 1;
        if (v.k == V_LIST) {
            items = AS_LIST(v)->items;
            nitems = AS_LIST(v)->n;
        }
        for (size_t j = 0; j < nitems; j++) {
            if (items[j].k == V_NUM && !isfinite(items[j].u.n)) {
                char where[48] = "";
                if (v.k == V_LIST)
                    snprintf(where, sizeof where, "item %zu of ", j + 1);
                err_at(I, at, ERR_USAGE, "-D %s=%s: %s'%s' is %s; the parameter takes finite numbers", n->str,
                       t, where, t, isnan(items[j].u.n) ? "not a number (nan)" : "infinite");
                val_unref(I, v);
                return -1;
            }
        }
        *out = v;
        return 1;
    }
    return 0;
}

__attribute__((noinline)) static int exec_for(interp *I, env *e, const node *n)
{
    value it;
    range_spec rs;
    size_t count;
    if (eval_iterable(I, e, n->kids[0], &it, &rs, &count))
        return -1;
    /* the body's compiled form (compile.c), made on the loop's first run */
    const cnode *body = compile_block(I, n->kids[1]); /* kids[1] is an N_BLOCK (parser.c) */
    int rc = 0;
    if (!body) {
        val_unref(I, it);
        return -1;
    }
    /* The body's statements run here, not through eval_block: the C stack
     * it checks is as deep at every iteration, so it is checked once. */
    if (count > 0 && cstack_exhausted()) {
        val_unref(I, it);
        return stack_overflow(I, n->kids[1]);
    }
    env *s = NULL;
    for (size_t i = 0; i < count && rc == 0; i++) {
        if (check_interrupt(I, n)) {
            rc = -1;
            break;
        }
        if (!s && !(s = val_env_new(I, e))) {
            rc = -1;
            break;
        }
        if (s->n == 0 && s->cap > 0) { /* a new or emptied scope: the variable is its first name */
            s->names[0] = n->str;
            s->vals[0] = iter_item(it, &rs, i);
            s->n = 1;
        } else {
            rc = val_env_append(I, s, n->str, iter_item(it, &rs, i)); /* s is empty */
        }
        for (int k = 0; k < body->nkids && rc == 0; k++)
            rc = body->kids[k]->fn(I, s, body->kids[k], NULL);
        if (rc == 0)
            s = iter_scope_next(I, s);
    }
    if (s)
        val_heap_unref(I, &s->h);
    val_unref(I, it);
    return rc;
}

__attribute__((noinline)) static int exec_param(interp *I, env *e, const node *n)
{
    value def;
    if (eval_expr(I, e, n->kids[0], &def))
        return -1;
    value ov;
    /* -D overrides the params of the script run, not those of the
     * modules it imports */
    int r = I->srcs[n->src].is_module ? 0 : apply_param_override(I, n, def, &ov);
    if (r < 0) {
        val_unref(I, def);
        return -1;
    }
    if (r == 1) {
        val_unref(I, def);
        def = ov;
    }
    return scope_define(I, e, n, def);
}

__attribute__((noinline)) static int exec_import(interp *I, env *e, const node *n)
{
    env *m;
    if (eval_import(I, n, n->str, &m))
        return -1;
    if (n->names[0]) {
        value r = val_rec(I);
        if (r.k == V_NIL)
            return -1;
        for (size_t i = 0; i < m->n; i++) {
            val_ref(m->vals[i]);
            if (val_rec_set(I, AS_REC(r), m->names[i], m->vals[i])) {
                val_unref(I, r);
                return -1;
            }
        }
        return scope_define_at(I, e, n->slot, n->names[0], r);
    }
    /* each name at the slot resolve.c gave it (the module is the one it saw: loaded once) */
    const int *slot = n->slots && (size_t)n->slots[0] == m->n ? n->slots + 1 : NULL;
    for (size_t i = 0; i < m->n; i++) {
        val_ref(m->vals[i]);
        if (scope_define_at(I, e, slot ? slot[i] : 0, m->names[i], m->vals[i]))
            return -1;
    }
    return 0;
}

static int exec_stmt(interp *I, env *e, const node *n, value *last)
{
    switch (n->kind) {
    case N_LET: {
        value v;
        if (eval_expr(I, e, n->kids[0], &v))
            return -1;
        return scope_define(I, e, n, v);
    }
    case N_ASSIGN: {
        value *slot = scope_lookup(I, e, n);
        if (!slot)
            return err_at(I, n, ERR_NAME, "cannot assign to '%s': it is not defined (use 'let %s = …')",
                          n->str, n->str);
        value v;
        const node *rhs = n->kids[0];
        if (rhs->kind == N_CALL ? eval_call_in(I, e, rhs, &v, NULL, n) : eval_expr(I, e, rhs, &v))
            return -1;
        slot = scope_lookup(I, e, n); /* the evaluation may have grown the scope */
        val_unref(I, *slot);
        *slot = v;
        return 0;
    }
    case N_PARAM:
        return exec_param(I, e, n);
    case N_FNDEF: {
        value f = val_func(I, n->kids[0], e, n->str);
        if (f.k == V_NIL)
            return -1;
        return scope_define(I, e, n, f);
    }
    case N_IMPORT:
        return exec_import(I, e, n);
    case N_FOR:
        return exec_for(I, e, n);
    case N_EXPR: {
        value v;
        if (eval_expr(I, e, n->kids[0], &v))
            return -1;
        eval_keep_last(I, last, v);
        return 0;
    }
    default:
        return eval_expr(I, e, n, last ? last : &(value){0}) == 0 ? 0 : -1;
    }
}

/* A memory error raised where no node was at hand (an allocation refused
 * while a value, a list or a scope grew: the hook knows no position) is reported at
 * the innermost statement that was running, so every error inside a script
 * has a line and column. */
static int stmt_failed(interp *I, const node *s)
{
    err_state *er = &I->err;
    if (er->active && er->src < 0 && (er->kind == ERR_MEMORY || er->kind == ERR_LIMIT) && s->line > 0)
        er->src = s->src, er->line = s->line, er->col = s->col;
    return -1;
}

int eval_block(interp *I, env *e, const node *block, value *out)
{
    if (cstack_exhausted()) /* imports nest blocks without an expression between */
        return stack_overflow(I, block);
    value last = val_nil();
    for (int i = 0; i < block->nkids; i++) {
        const node *s = block->kids[i];
        if (s->kind != N_EXPR && out) {
            val_unref(I, last);
            last = val_nil();
        }
        if (exec_stmt(I, e, s, out ? &last : NULL)) {
            val_unref(I, last);
            return stmt_failed(I, s);
        }
    }
    if (out)
        *out = last;
    else
        val_unref(I, last);
    return 0;
}

/* ---- modules ------------------------------------------------------------------- */

static int is_file_import(const char *name)
{
    size_t n = strlen(name);
    return name[0] == '.' || name[0] == '/' || (n > 5 && strcmp(name + n - 5, ".frac") == 0);
}

/* The key a module is loaded under: "std:NAME", or the file's canonical path. */
static int module_key(interp *I, const node *at, const char *name, char *key, size_t cap)
{
    if (is_file_import(name)) {
        const char *dir = at ? I->srcs[at->src].dir : ".";
        if (lang_join_path(I, at, dir, name, strlen(name), key, cap, "import"))
            return -1;
    } else {
        snprintf(key, cap, "std:%s", name);
    }
    /* canonicalise file paths so a module is loaded once however it is named */
    if (strncmp(key, "std:", 4) != 0) {
        char *real = realpath(key, NULL);
        if (real) {
            snprintf(key, cap, "%s", real);
            free(real); /* realpath() allocates with malloc: stays raw */
        }
    }
    return 0;
}

static module *module_find(interp *I, const char *key)
{
    for (int i = 0; i < I->nmods; i++)
        if (strcmp(I->mods[i].key, key) == 0)
            return &I->mods[i];
    return NULL;
}

env *eval_module_loaded(interp *I, const node *at, const char *name)
{
    char key[4096];
    err_state save = I->err;
    if (module_key(I, at, name, key, sizeof key)) {
        I->err = save; /* the import reports it when it runs */
        return NULL;
    }
    const module *m = module_find(I, key);
    return m && m->state == 2 ? m->exports : NULL;
}

int eval_import(interp *I, const node *at, const char *name, env **out)
{
    char key[4096];
    const char *text = NULL;
    unsigned char *filedata = NULL;
    size_t filelen = 0;
    if (module_key(I, at, name, key, sizeof key))
        return -1;
    const module *found = module_find(I, key);
    if (found) {
        if (found->state == 1)
            return err_at(I, at, ERR_VALUE, "import cycle: \"%s\" is already being imported", name);
        *out = found->exports;
        return 0;
    }
    char display[4096];
    if (strncmp(key, "std:", 4) == 0) {
        for (const stdlib_module *m = stdlib_modules; m->name; m++)
            if (strcmp(m->name, name) == 0)
                text = m->source;
        if (!text) {
            const char *cands[256];
            size_t nc = 0;
            for (const stdlib_module *m = stdlib_modules; m->name && nc < 256; m++)
                cands[nc++] = m->name;
            const char *s = interp_suggest_name(name, cands, nc);
            return err_at(I, at, ERR_NAME,
                          "no standard module named \"%s\"%s%s%s (to import a file, write \"./%s.frac\")",
                          name, s ? " (did you mean \"" : "", s ? s : "", s ? "\"?)" : "", name);
        }
        snprintf(display, sizeof display, "<stdlib>/%s.frac", name);
        filelen = strlen(text);
    } else {
        rt_error re;
        if (fileio_read_all(key, 64u << 20, &filedata, &filelen, &re))
            return err_at(I, at, lang_rt_kind(re.code), "cannot import \"%s\": %s", name, re.msg);
        text = (const char *)filedata;
        const char *dir = at ? I->srcs[at->src].dir : ".";
        if (name[0] == '/')
            snprintf(display, sizeof display, "%s", name);
        else if (strcmp(dir, ".") == 0)
            snprintf(display, sizeof display, "%s", name);
        else
            snprintf(display, sizeof display, "%s/%s", dir, name);
    }
    int src = interp_add_source(I, display, text, filelen);
    mem_free(I, filedata);
    if (src < 0)
        return -1;
    I->srcs[src].is_module = 1;
    if (I->nmods == I->cap_mods) {
        int nc = I->cap_mods ? I->cap_mods * 2 : 8;
        module *nm = mem_realloc(I, I->mods, (size_t)nc * sizeof *nm);
        if (!nm)
            return -1;
        I->mods = nm;
        I->cap_mods = nc;
    }
    module *m = &I->mods[I->nmods];
    m->key = mem_alloc(I, strlen(key) + 1);
    if (!m->key)
        return -1;
    strcpy(m->key, key);
    m->state = 1;
    /* a module sees the builtins, not the importer's names */
    env *root = I->globals;
    while (root->parent)
        root = root->parent;
    m->exports = val_env_new(I, root);
    if (!m->exports) {
        mem_free(I, m->key);
        return -1;
    }
    int idx = I->nmods++;
    node *prog;
    /* the module's names by slot too (its checks are its run: nothing more is reported here) */
    if (parse_source(I, src, &prog) || resolve_slots(I, prog, I->mods[idx].exports, 0) ||
        eval_block(I, I->mods[idx].exports, prog, NULL))
        return -1; /* the module stays marked as loading; the session reports the error */
    I->mods[idx].state = 2;
    *out = I->mods[idx].exports;
    return 0;
}

int eval_text(interp *I, const char *srcname, const char *text, value *out)
{
    int src = interp_add_source(I, srcname, text, strlen(text));
    if (src < 0)
        return -1;
    node *prog;
    if (parse_source(I, src, &prog))
        return -1;
    if (prog->nkids != 1 || prog->kids[0]->kind != N_EXPR)
        return err_pos(I, src, 1, 1, ERR_SYNTAX, "expected a single value");
    env *root = I->globals;
    while (root->parent)
        root = root->parent;
    return eval_expr(I, I->globals ? I->globals : root, prog->kids[0]->kids[0], out);
}

/* ---- for compile.c (compile.h) ------------------------------------------------- */

int eval_binary_node(interp *I, const node *n, value a, value b, value *out)
{
    return binary_values(I, n, a, b, out);
}

int eval_unary_node(interp *I, const node *n, value a, value *out)
{
    return eval_unary(I, n->op, a, out, n);
}

int eval_index_node(interp *I, const node *n, value a, value ix, value *out)
{
    return eval_index(I, a, ix, out, n);
}

int eval_field_node(interp *I, const node *n, value a, value *out)
{
    return eval_field(I, a, n->str, out, n);
}

/* eval_call_in after its arguments, all positional, are evaluated */
int eval_call_positional(interp *I, env *e, value fn, const value *args, int nargs, const node *call,
                         const node *assign, value *out)
{
    const node *const *anodes = (const node *const *)call->kids + 1;
    if (assign && nargs > 0 && args[0].k == V_LIST && fn.k == V_BUILTIN && strcmp(fn.u.bi->name, "concat") == 0) {
        value *x = scope_lookup(I, e, assign); /* the arguments may have reassigned it */
        I->append_target = x && x->k == V_LIST && x->u.h == args[0].u.h ? args[0].u.h : NULL;
        int rc = call_any(I, fn, args, nargs, NULL, NULL, 0, anodes, call, out);
        I->append_target = NULL;
        return rc;
    }
    return call_any(I, fn, args, nargs, NULL, NULL, 0, anodes, call, out);
}

int eval_stmt(interp *I, env *e, const node *n, value *last)
{
    return exec_stmt(I, e, n, last);
}

int eval_push_frame(interp *I, const char *name, const node *call)
{
    return push_frame(I, name, call);
}

int eval_stack_overflow(interp *I, const node *n)
{
    return stack_overflow(I, n);
}
