/* builtin.c — the builtin registry (builtin.h): registering tables of
 * builtins as globals (each compiled into its contract), finding them by
 * name, their signatures for help, and the argument readers builtins share.
 * The calls themselves are checked and run by eval.c. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "builtin.h"
#include "contract.h"
#include "fileio.h"

/* ---- registry and helpers ---------------------------------------------------- */

int builtin_register(interp *I, const builtin *b, int n)
{
    env *root = I->globals;
    while (root->parent)
        root = root->parent;
    for (int i = 0; i < n; i++) {
        /* two builtins with one name would silently hide each other; the
         * builtin scope is hashed, so this costs one lookup, not a scan */
        const char *name = interp_intern(I, b[i].name, strlen(b[i].name));
        if (!name)
            return -1;
        const value *old = val_env_lookup(root, name);
        if (old && old->k == V_BUILTIN)
            return err_at(I, NULL, ERR_RUNTIME, "internal error: builtin '%s' is defined twice", b[i].name);
        if (I->nbuiltins == I->cap_builtins) {
            int nc = I->cap_builtins ? I->cap_builtins * 2 : 256;
            const builtin **nb = mem_realloc(I, I->builtins, (size_t)nc * sizeof *nb);
            if (!nb)
                return -1;
            I->builtins = nb;
            I->cap_builtins = nc;
        }
        I->builtins[I->nbuiltins++] = &b[i]; /* its contract is compiled at its first call */
        value v;
        v.k = V_BUILTIN;
        v.u.bi = &b[i];
        if (val_env_define(I, root, name, v))
            return -1;
    }
    return 0;
}

const builtin *builtin_find(interp *I, const char *name)
{
    for (int i = 0; i < I->nbuiltins; i++)
        if (strcmp(I->builtins[i]->name, name) == 0)
            return I->builtins[i];
    return NULL;
}

int builtin_arg_error(interp *I, const builtin *b, const char *param, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (param)
        return err_at(I, NULL, ERR_VALUE, "%s: argument '%s' %s", b->name, param, msg);
    return err_at(I, NULL, ERR_VALUE, "%s: %s", b->name, msg);
}

int builtin_get_vec(interp *I, value v, double *out, size_t n, const char *what)
{
    if (v.k != V_LIST)
        return err_value(I, v, ERR_TYPE, "%s must be a list of %zu numbers, got %s", what, n,
                         val_type_name(v));
    vlist *l = AS_LIST(v);
    if (n && l->n != n)
        return err_value(I, v, ERR_VALUE, "%s must be a list of %zu numbers, got %zu items", what, n, l->n);
    for (size_t i = 0; i < l->n; i++) {
        if (l->items[i].k != V_NUM)
            return err_item(I, v, i, ERR_TYPE, "%s must contain numbers, but item %zu is %s", what, i + 1,
                            val_type_name(l->items[i]));
        if (!isfinite(l->items[i].u.n))
            return err_item(I, v, i, ERR_VALUE, "%s item %zu must be a finite number, got %s", what, i + 1,
                            isnan(l->items[i].u.n) ? "nan" : l->items[i].u.n < 0 ? "-inf" : "inf");
        if (out)
            out[i] = l->items[i].u.n;
    }
    return 0;
}

int builtin_get_int(interp *I, value v, long lo, long hi, long *out, const char *what)
{
    if (v.k != V_NUM || !isfinite(v.u.n) || v.u.n != floor(v.u.n)) {
        if (v.k == V_NUM) {
            char got[40];
            val_fmt_number(v.u.n, got, sizeof got);
            return err_value(I, v, ERR_TYPE, "%s must be a whole number, got %s", what,
                          isnan(v.u.n) ? "nan" : isinf(v.u.n) ? (v.u.n < 0 ? "-inf" : "inf") : got);
        }
        return err_value(I, v, ERR_TYPE, "%s must be a whole number, got %s", what, val_type_name(v));
    }
    if (v.u.n < (double)lo || v.u.n > (double)hi)
        return err_value(I, v, ERR_VALUE, "%s must be between %ld and %ld, got %.17g", what, lo, hi, v.u.n);
    *out = (long)v.u.n;
    return 0;
}

void builtin_signature(const builtin *b, bytebuf *out)
{
    bytebuf_printf(out, "%s(", b->name);
    if (b->variadic)
        bytebuf_printf(out, "…%s", b->nparams ? ", " : "");
    for (int i = 0; i < b->nparams; i++) {
        const bparam *p = &b->params[i];
        bytebuf_printf(out, "%s%s", i ? ", " : "", p->name);
        if (p->type && strcmp(p->type, "any") != 0)
            bytebuf_printf(out, ": %s", p->type);
        if (p->def)
            bytebuf_printf(out, " = %s", p->def);
    }
    bytebuf_printf(out, ")");
}
