/* eval.c — evaluation of expressions and statements. */
#define _XOPEN_SOURCE 700
#include "eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "cstack.h"
#include "fileio.h"
#include "lexer.h"
#include "parser.h"
#include "stdlib_embed.h"

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
            if (binary_op(I, op, x, y, &r, at) || list_push(I, AS_LIST(res), r)) {
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

/* Call a user function with positional args and named args. */
static int call_user(interp *I, vfunc *f, const value *pos, int npos, const char **names,
                     const value *named, int nnamed, const node *call, value *out)
{
    const node *l = f->lambda;
    const char *fname = f->name ? f->name : "<lambda>";
    if (npos > l->nparams)
        return err_at(I, call, ERR_TYPE, "%s takes %d argument%s, but %d were given", fname,
                      l->nparams, l->nparams == 1 ? "" : "s", npos);
    env *e = env_new(I, f->closure);
    if (!e)
        return -1;
    int rc = -1;
    value bound[MAX_ARGS];
    int have[MAX_ARGS] = {0};
    if (l->nparams > MAX_ARGS) {
        err_at(I, call, ERR_LIMIT, "too many parameters");
        goto done;
    }
    for (int i = 0; i < npos; i++) {
        bound[i] = pos[i];
        have[i] = 1;
    }
    for (int k = 0; k < nnamed; k++) {
        int j;
        for (j = 0; j < l->nparams; j++)
            if (l->names[j] == names[k])
                break;
        if (j == l->nparams) {
            const char *s = suggest_name(names[k], l->names, (size_t)l->nparams);
            err_at(I, call, ERR_TYPE, "%s has no parameter '%s'%s%s%s", fname, names[k],
                   s ? " (did you mean '" : "", s ? s : "", s ? "'?)" : "");
            goto done;
        }
        if (have[j]) {
            err_at(I, call, ERR_TYPE, "%s: argument '%s' given twice", fname, names[k]);
            goto done;
        }
        bound[j] = named[k];
        have[j] = 1;
    }
    for (int j = 0; j < l->nparams; j++) {
        value v;
        if (have[j]) {
            v = bound[j];
            val_ref(v);
        } else if (l->kids[j]) {
            /* defaults are evaluated in the new scope, so they can use earlier parameters */
            if (eval_expr(I, e, l->kids[j], &v))
                goto done;
        } else {
            err_at(I, call, ERR_TYPE, "%s: missing argument '%s'", fname, l->names[j]);
            goto done;
        }
        if (env_define(I, e, l->names[j], v))
            goto done;
    }
    if (push_frame(I, fname, call))
        goto done;
    if (l->body->kind == N_BLOCK)
        rc = eval_block(I, e, l->body, out);
    else
        rc = eval_expr(I, e, l->body, out);
    I->depth--;
done:
    heap_unref(I, &e->h);
    return rc;
}

static int type_matches(value v, const char *types)
{
    const char *p = types;
    while (*p) {
        const char *q = strchr(p, '|');
        size_t n = q ? (size_t)(q - p) : strlen(p);
#define IS(s) (n == sizeof(s) - 1 && memcmp(p, s, n) == 0)
        if (IS("any"))
            return 1;
        if (IS("num") && v.k == V_NUM)
            return 1;
        if (IS("int") && v.k == V_NUM && v.u.n == floor(v.u.n) && fabs(v.u.n) < 9e15)
            return 1;
        if (IS("str") && v.k == V_STR)
            return 1;
        if (IS("bool") && v.k == V_BOOL)
            return 1;
        if (IS("list") && v.k == V_LIST)
            return 1;
        if (IS("vec") && v.k == V_LIST) {
            int ok = 1;
            for (size_t i = 0; i < AS_LIST(v)->n; i++)
                ok &= AS_LIST(v)->items[i].k == V_NUM;
            if (ok)
                return 1;
        }
        if (IS("rec") && v.k == V_REC)
            return 1;
        if (IS("func") && (v.k == V_FUNC || v.k == V_BUILTIN))
            return 1;
        if (IS("nil") && v.k == V_NIL)
            return 1;
        if (v.k == V_OBJ && strlen(AS_OBJ(v)->cls->name) == n && memcmp(AS_OBJ(v)->cls->name, p, n) == 0)
            return 1;
#undef IS
        if (!q)
            break;
        p = q + 1;
    }
    return 0;
}

static void describe_types(const char *types, char *buf, size_t size)
{
    size_t k = 0;
    const char *p = types;
    buf[0] = 0;
    while (*p && k + 32 < size) {
        const char *q = strchr(p, '|');
        size_t n = q ? (size_t)(q - p) : strlen(p);
        const char *word = NULL;
#define IS(s) (n == sizeof(s) - 1 && memcmp(p, s, n) == 0)
        if (IS("num")) word = "a number";
        else if (IS("int")) word = "a whole number";
        else if (IS("str")) word = "a string";
        else if (IS("bool")) word = "a boolean";
        else if (IS("list")) word = "a list";
        else if (IS("vec")) word = "a list of numbers";
        else if (IS("rec")) word = "a record";
        else if (IS("func")) word = "a function";
        else if (IS("nil")) word = "nil";
#undef IS
        if (k)
            k += (size_t)snprintf(buf + k, size - k, q ? ", " : " or ");
        if (word)
            k += (size_t)snprintf(buf + k, size - k, "%s", word);
        else
            k += (size_t)snprintf(buf + k, size - k, "%s %.*s",
                                  strchr("aeiou", *p) ? "an" : "a", (int)n, p);
        if (!q)
            break;
        p = q + 1;
    }
}

int eval_text(interp *I, const char *srcname, const char *text, value *out);

static int default_value(interp *I, const builtin *b, const bparam *bp, value *out)
{
    if (strcmp(bp->def, "nil") == 0) {
        *out = val_nil();
        return 0;
    }
    char *endp;
    double d = strtod(bp->def, &endp);
    if (*endp == 0 && endp != bp->def) {
        *out = val_num(d);
        return 0;
    }
    char name[128];
    snprintf(name, sizeof name, "<default of %s %s>", b->name, bp->name);
    return eval_text(I, name, bp->def, out);
}

static int call_builtin(interp *I, const builtin *b, const value *pos, int npos, const char **names,
                        const value *named, int nnamed, const node *call, value *out)
{
    value args[MAX_ARGS];
    int owned[MAX_ARGS] = {0};
    int have[MAX_ARGS] = {0};
    int nargs;
    int fixed = b->variadic ? 0 : b->nparams;
    if (b->variadic) {
        if (npos + b->nparams > MAX_ARGS)
            return err_at(I, call, ERR_TYPE, "%s: too many arguments", b->name);
        for (int i = 0; i < npos; i++)
            args[i] = pos[i];
        nargs = npos + b->nparams;
        for (int j = 0; j < b->nparams; j++)
            have[npos + j] = 0;
    } else {
        if (npos > b->nparams)
            return err_at(I, call, ERR_TYPE, "%s takes at most %d argument%s, but %d were given",
                          b->name, b->nparams, b->nparams == 1 ? "" : "s", npos);
        for (int i = 0; i < npos; i++) {
            args[i] = pos[i];
            have[i] = 1;
        }
        nargs = b->nparams;
    }
    int base = b->variadic ? npos : 0;
    for (int k = 0; k < nnamed; k++) {
        int j;
        for (j = 0; j < b->nparams; j++)
            if (strcmp(b->params[j].name, names[k]) == 0)
                break;
        if (j == b->nparams) {
            const char *cands[MAX_ARGS];
            for (int i = 0; i < b->nparams && i < MAX_ARGS; i++)
                cands[i] = b->params[i].name;
            const char *s = suggest_name(names[k], cands, (size_t)b->nparams);
            return err_at(I, call, ERR_TYPE, "%s has no parameter '%s'%s%s%s", b->name, names[k],
                          s ? " (did you mean '" : "", s ? s : "", s ? "'?)" : "");
        }
        if (have[base + j])
            return err_at(I, call, ERR_TYPE, "%s: argument '%s' given twice", b->name, names[k]);
        args[base + j] = named[k];
        have[base + j] = 1;
    }
    int rc = -1;
    for (int j = 0; j < b->nparams; j++) {
        const bparam *bp = &b->params[j];
        int slot = base + j;
        if (!have[slot]) {
            if (!bp->def) {
                err_at(I, call, ERR_TYPE, "%s: missing argument '%s'", b->name, bp->name);
                goto done;
            }
            if (default_value(I, b, bp, &args[slot]))
                goto done;
            owned[slot] = 1;
        } else if (bp->type && !(args[slot].k == V_NIL && bp->def && strcmp(bp->def, "nil") == 0) &&
                   !type_matches(args[slot], bp->type)) {
            char want[160];
            describe_types(bp->type, want, sizeof want);
            const node *at = call;
            err_at(I, at, ERR_TYPE, "%s: argument '%s' must be %s, got %s", b->name, bp->name, want,
                   val_type_name(args[slot]));
            goto done;
        }
    }
    (void)fixed;
    {
        const node *save = I->cur;
        I->cur = call;
        rc = b->fn(I, args, b->variadic ? npos : nargs, out);
        I->cur = save;
        if (rc == 0 && I->err.active)
            rc = -1;
    }
done:
    for (int j = 0; j < nargs; j++)
        if (owned[j])
            val_unref(I, args[j]);
    return rc;
}

static int call_any(interp *I, value fn, const value *pos, int npos, const char **names,
                    const value *named, int nnamed, const node *call, value *out)
{
    *out = val_nil();
    if (check_interrupt(I, call))
        return -1;
    if (fn.k == V_FUNC)
        return call_user(I, AS_FUNC(fn), pos, npos, names, named, nnamed, call, out);
    if (fn.k == V_BUILTIN)
        return call_builtin(I, fn.u.bi, pos, npos, names, named, nnamed, call, out);
    return err_at(I, call, ERR_TYPE, "cannot call %s (it is not a function)", val_type_name(fn));
}

int call_value(interp *I, value fn, const value *args, int nargs, value *out)
{
    return call_any(I, fn, args, nargs, NULL, NULL, 0, I->cur, out);
}

/* Kept out of eval_expr so its argument arrays do not enlarge every nested
 * evaluation's frame (the C stack is the nesting limit, see cstack.h). */
__attribute__((noinline)) static int eval_call(interp *I, env *e, const node *n, value *out)
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
    int npos = 0, nnamed = 0, rc = -1;
    for (int i = 1; i <= nargs; i++) {
        value v;
        if (eval_expr(I, e, n->kids[i], &v))
            goto done;
        if (n->names[i]) {
            names[nnamed] = n->names[i];
            named[nnamed++] = v;
        } else {
            pos[npos++] = v;
        }
    }
    rc = call_any(I, fn, pos, npos, names, named, nnamed, n, out);
done:
    for (int i = 0; i < npos; i++)
        val_unref(I, pos[i]);
    for (int i = 0; i < nnamed; i++)
        val_unref(I, named[i]);
    val_unref(I, fn);
    return rc;
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
        const char *key = intern(I, AS_STR(ix)->s, AS_STR(ix)->len);
        value *v = key ? rec_get(AS_REC(a), key) : NULL;
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
        value *v = rec_get(AS_REC(a), name);
        if (!v) {
            vrec *r = AS_REC(a);
            const char *s = suggest_name(name, r->keys, r->n);
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
            if (list_push(I, AS_LIST(rv), v)) {
                val_unref(I, rv);
                goto fail;
            }
        }
        if (list_push(I, AS_LIST(t), rv))
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

__attribute__((noinline)) static int eval_comp(interp *I, env *e, const node *n, value *out)
{
    value it;
    if (eval_expr(I, e, n->kids[1], &it))
        return -1;
    if (iterate_list(I, it, n->kids[1])) {
        val_unref(I, it);
        return -1;
    }
    value res = val_list(I, AS_LIST(it)->n);
    if (res.k == V_NIL) {
        val_unref(I, it);
        return -1;
    }
    for (size_t i = 0; i < AS_LIST(it)->n; i++) {
        if (check_interrupt(I, n))
            goto fail;
        env *s = env_new(I, e);
        if (!s)
            goto fail;
        value x = AS_LIST(it)->items[i];
        val_ref(x);
        int ok = env_define(I, s, n->str, x) == 0;
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
            ok = eval_expr(I, s, n->kids[0], &v) == 0 && list_push(I, AS_LIST(res), v) == 0;
        }
        heap_unref(I, &s->h);
        if (!ok)
            goto fail;
    }
    val_unref(I, it);
    *out = res;
    return 0;
fail:
    val_unref(I, it);
    val_unref(I, res);
    return -1;
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
    case N_STR:
        *out = val_str(I, n->str, n->slen);
        return out->k == V_NIL ? -1 : 0;
    case N_BOOL:
        *out = val_bool((int)n->num);
        return 0;
    case N_NIL:
        return 0;
    case N_NAME: {
        value *v = env_lookup(e, n->str);
        if (!v)
            return err_at(I, n, ERR_NAME, "unknown name '%s'", n->str);
        *out = *v;
        val_ref(*out);
        return 0;
    }
    case N_LIST: {
        value l = val_list(I, (size_t)n->nkids);
        if (l.k == V_NIL)
            return -1;
        for (int i = 0; i < n->nkids; i++) {
            value v;
            if (eval_expr(I, e, n->kids[i], &v) || list_push(I, AS_LIST(l), v)) {
                val_unref(I, l);
                return -1;
            }
        }
        *out = l;
        return 0;
    }
    case N_COMP:
        return eval_comp(I, e, n, out);
    case N_RECORD: {
        value r = val_rec(I);
        if (r.k == V_NIL)
            return -1;
        for (int i = 0; i < n->nkids; i++) {
            value v;
            if (eval_expr(I, e, n->kids[i], &v) || rec_set(I, AS_REC(r), n->names[i], v)) {
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
    case N_BLOCK: {
        env *s = env_new(I, e);
        if (!s)
            return -1;
        int r = eval_block(I, s, n, out);
        heap_unref(I, &s->h);
        return r;
    }
    case N_LAMBDA:
        *out = val_func(I, n, e, n->str);
        return out->k == V_NIL ? -1 : 0;
    default:
        return err_at(I, n, ERR_RUNTIME, "internal error: statement in expression position");
    }
}

/* ---- statements --------------------------------------------------------------- */

static int apply_param_override(interp *I, const node *n, value def, value *out)
{
    for (int i = 0; i < I->noverrides; i++) {
        param_override *o = &I->overrides[i];
        if (o->name != n->str)
            continue;
        o->used = 1;
        char srcname[160];
        snprintf(srcname, sizeof srcname, "-D %s", n->str);
        value v;
        int save_depth = I->depth;
        if (eval_text(I, srcname, o->text, &v)) {
            /* a bare word is a string */
            if (I->err.kind != ERR_NAME || def.k != V_STR) {
                if (def.k == V_NUM || def.k == V_BOOL || def.k == V_LIST) {
                    err_clear(I);
                    I->depth = save_depth;
                    return err_at(I, n, ERR_USAGE, "-D %s=%s: the parameter is a %s, and '%s' is not one",
                                  n->str, o->text, val_type_name(def), o->text);
                }
                return -1;
            }
            err_clear(I);
            I->depth = save_depth;
            v = val_cstr(I, o->text);
            if (v.k == V_NIL)
                return -1;
        }
        if (def.k != V_NIL && v.k != def.k) {
            err_at(I, n, ERR_TYPE, "-D %s=%s: the parameter is a %s (default ", n->str, o->text,
                   val_type_name(def));
            bytebuf b;
            bytebuf_init(&b);
            val_print(I, def, &b, 1);
            bytebuf_byte(&b, 0);
            size_t l = strlen(I->err.msg);
            snprintf(I->err.msg + l, sizeof I->err.msg - l, "%s), but the value given is a %s",
                     b.data ? (char *)b.data : "", val_type_name(v));
            bytebuf_free(&b);
            val_unref(I, v);
            return -1;
        }
        *out = v;
        return 1;
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
        return env_define(I, e, n->str, v);
    }
    case N_ASSIGN: {
        value *slot = env_lookup(e, n->str);
        if (!slot)
            return err_at(I, n, ERR_NAME, "cannot assign to '%s': it is not defined (use 'let %s = …')",
                          n->str, n->str);
        value v;
        if (eval_expr(I, e, n->kids[0], &v))
            return -1;
        slot = env_lookup(e, n->str); /* the evaluation may have grown the scope */
        val_unref(I, *slot);
        *slot = v;
        return 0;
    }
    case N_PARAM: {
        value def;
        if (eval_expr(I, e, n->kids[0], &def))
            return -1;
        value ov;
        int r = apply_param_override(I, n, def, &ov);
        if (r < 0) {
            val_unref(I, def);
            return -1;
        }
        if (r == 1) {
            val_unref(I, def);
            def = ov;
        }
        return env_define(I, e, n->str, def);
    }
    case N_FNDEF: {
        value f = val_func(I, n->kids[0], e, n->str);
        if (f.k == V_NIL)
            return -1;
        return env_define(I, e, n->str, f);
    }
    case N_IMPORT: {
        env *m;
        if (eval_import(I, n, n->str, &m))
            return -1;
        if (n->names[0]) {
            value r = val_rec(I);
            if (r.k == V_NIL)
                return -1;
            for (size_t i = 0; i < m->n; i++) {
                val_ref(m->vals[i]);
                if (rec_set(I, AS_REC(r), m->names[i], m->vals[i])) {
                    val_unref(I, r);
                    return -1;
                }
            }
            return env_define(I, e, n->names[0], r);
        }
        for (size_t i = 0; i < m->n; i++) {
            val_ref(m->vals[i]);
            if (env_define(I, e, m->names[i], m->vals[i]))
                return -1;
        }
        return 0;
    }
    case N_FOR: {
        value it;
        if (eval_expr(I, e, n->kids[0], &it))
            return -1;
        if (iterate_list(I, it, n->kids[0])) {
            val_unref(I, it);
            return -1;
        }
        int rc = 0;
        for (size_t i = 0; i < AS_LIST(it)->n && rc == 0; i++) {
            if (check_interrupt(I, n)) {
                rc = -1;
                break;
            }
            env *s = env_new(I, e);
            if (!s) {
                rc = -1;
                break;
            }
            value x = AS_LIST(it)->items[i];
            val_ref(x);
            rc = env_define(I, s, n->str, x);
            if (rc == 0)
                rc = eval_block(I, s, n->kids[1], NULL);
            heap_unref(I, &s->h);
        }
        val_unref(I, it);
        return rc;
    }
    case N_EXPR: {
        value v;
        if (eval_expr(I, e, n->kids[0], &v))
            return -1;
        if (last) {
            val_unref(I, *last);
            *last = v;
        } else {
            val_unref(I, v);
        }
        return 0;
    }
    default:
        return eval_expr(I, e, n, last ? last : &(value){0}) == 0 ? 0 : -1;
    }
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
            return -1;
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

int eval_import(interp *I, const node *at, const char *name, env **out)
{
    char key[4096];
    const char *text = NULL;
    unsigned char *filedata = NULL;
    size_t filelen = 0;
    if (is_file_import(name)) {
        const char *dir = at && at->src >= 0 ? I->srcs[at->src].dir : ".";
        if (name[0] == '/')
            snprintf(key, sizeof key, "%s", name);
        else
            snprintf(key, sizeof key, "%s/%s", dir, name);
    } else {
        snprintf(key, sizeof key, "std:%s", name);
    }
    /* canonicalise file paths so a module is loaded once however it is named */
    if (strncmp(key, "std:", 4) != 0) {
        char *real = realpath(key, NULL);
        if (real) {
            snprintf(key, sizeof key, "%s", real);
            free(real);
        }
    }
    for (int i = 0; i < I->nmods; i++) {
        if (strcmp(I->mods[i].key, key) == 0) {
            if (I->mods[i].state == 1) {
                return err_at(I, at, ERR_VALUE, "import cycle: \"%s\" is already being imported", name);
            }
            *out = I->mods[i].exports;
            return 0;
        }
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
            const char *s = suggest_name(name, cands, nc);
            return err_at(I, at, ERR_NAME,
                          "no standard module named \"%s\"%s%s%s (to import a file, write \"./%s.frac\")",
                          name, s ? " (did you mean \"" : "", s ? s : "", s ? "\"?)" : "", name);
        }
        snprintf(display, sizeof display, "<stdlib>/%s.frac", name);
        filelen = strlen(text);
    } else {
        rt_error re;
        if (fileio_read_all(key, 64u << 20, &filedata, &filelen, &re))
            return err_at(I, at, ERR_IO, "cannot import \"%s\": %s", name, re.msg);
        text = (const char *)filedata;
        const char *dir = at && at->src >= 0 ? I->srcs[at->src].dir : ".";
        if (name[0] == '/')
            snprintf(display, sizeof display, "%s", name);
        else if (strcmp(dir, ".") == 0)
            snprintf(display, sizeof display, "%s", name);
        else
            snprintf(display, sizeof display, "%s/%s", dir, name);
    }
    int src = interp_add_source(I, display, text, filelen);
    free(filedata);
    if (src < 0)
        return -1;
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
    m->exports = env_new(I, root);
    if (!m->exports) {
        mem_free(I, m->key);
        return -1;
    }
    int idx = I->nmods++;
    node *prog;
    if (parse_source(I, src, &prog) || eval_block(I, I->mods[idx].exports, prog, NULL))
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
