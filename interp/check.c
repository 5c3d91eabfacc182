/* check.c — static checks of calls, before anything runs (see check.h).
 *
 * A call whose callee is a name the program never binds is a call to a
 * builtin, to a function of an imported module, or to a `fn` of the
 * program defined once at top level; its arguments are matched against the
 * callee's declared parameters with the same function the evaluator uses
 * (contract_match), and constant arguments (literals and operators on them)
 * are checked against the builtin's declared types (contract_check_value),
 * so `frac check` and a run report the same message at the same place. */
#include "check.h"

#include <string.h>

#include "contract.h"
#include "eval.h"

int check_bind(interp *I, check_names *b, const char *name, const node *def)
{
    if (b->n == b->cap) {
        int nc = b->cap ? b->cap * 2 : 64;
        void *nn = mem_realloc(I, b->v, (size_t)nc * sizeof *b->v);
        if (!nn)
            return -1;
        b->v = nn;
        b->cap = nc;
    }
    b->v[b->n].name = name;
    b->v[b->n].def = def;
    b->n++;
    return 0;
}

/* Every name the program binds anywhere (let, param, fn, assignment, loop
 * and comprehension variables, lambda parameters, import aliases). */
static int collect(interp *I, check_names *b, const node *n, int top)
{
    if (!n)
        return 0;
    switch (n->kind) {
    case N_LET:
    case N_ASSIGN:
    case N_PARAM:
    case N_FOR:
    case N_COMP:
        if (check_bind(I, b, n->str, NULL))
            return -1;
        break;
    case N_FNDEF:
        if (check_bind(I, b, n->str, top ? n : NULL))
            return -1;
        break;
    case N_LAMBDA:
        for (int i = 0; i < n->nparams; i++)
            if (check_bind(I, b, n->names[i], NULL))
                return -1;
        if (collect(I, b, n->body, 0))
            return -1;
        break;
    case N_IMPORT:
        if (n->names && n->names[0] && check_bind(I, b, n->names[0], NULL))
            return -1;
        return 0;
    default:
        break;
    }
    for (int i = 0; i < n->nkids; i++) {
        const node *k = n->kids[i];
        /* literals and names bind nothing and have no children: no call */
        if (k && k->kind != N_NAME && k->kind != N_NUM && k->kind != N_STR && collect(I, b, k, 0))
            return -1;
    }
    return 0;
}

int check_collect(interp *I, const node *prog, check_names *out)
{
    memset(out, 0, sizeof *out);
    for (int i = 0; i < prog->nkids; i++)
        if (collect(I, out, prog->kids[i], 1))
            return -1;
    return check_index(I, out);
}

int check_index(interp *I, check_names *out)
{
    /* check_call looks every call's name up here: hashed, not scanned */
    size_t cap = 16;
    while (cap < (size_t)out->n * 2 + 2)
        cap *= 2;
    out->index = mem_calloc(I, cap, sizeof *out->index);
    out->count = mem_calloc(I, cap, sizeof *out->count);
    if (!out->index || !out->count)
        return -1;
    out->index_cap = cap;
    for (int i = 0; i < out->n; i++) {
        size_t h = name_hash(out->v[i].name) & (cap - 1);
        while (out->index[h] && out->v[out->index[h] - 1].name != out->v[i].name)
            h = (h + 1) & (cap - 1);
        out->index[h] = i + 1;
        out->count[h]++;
    }
    return 0;
}

void check_names_free(interp *I, check_names *b)
{
    mem_free(I, b->v);
    mem_free(I, b->index);
    mem_free(I, b->count);
    memset(b, 0, sizeof *b);
}

/* How many times the program binds name, and the def of its last binding. */
static int bound_count(const check_names *b, const char *name, const node **def)
{
    *def = NULL;
    if (!b->index_cap)
        return 0;
    size_t h = name_hash(name) & (b->index_cap - 1);
    while (b->index[h] && b->v[b->index[h] - 1].name != name)
        h = (h + 1) & (b->index_cap - 1);
    if (!b->index[h])
        return 0;
    *def = b->v[b->index[h] - 1].def;
    return b->count[h];
}

/* The arguments of a call as the evaluator passes them: positional ones
 * first, then named ones (anames[i] NULL for a positional argument). */
static void call_args(const node *call, int na, const char **anames, const node **anodes)
{
    int k = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int i = 1; i <= na; i++)
            if ((call->names[i] != NULL) == pass) {
                anames[k] = call->names[i];
                anodes[k++] = call->kids[i];
            }
}

static int check_builtin(interp *I, const builtin *b, const node *call)
{
    const bspec *spec = contract_spec(I, b);
    int na = call->nkids - 1;
    if (!spec)
        return I->err.active ? -1 : 0;
    if (na > MAX_ARGS || spec->n > MAX_ARGS)
        return 0;
    const char *pnames[MAX_ARGS], *anames[MAX_ARGS];
    const node *anodes[MAX_ARGS];
    int required[MAX_ARGS], slot[MAX_ARGS];
    for (int j = 0; j < spec->n; j++) {
        pnames[j] = spec->p[j].name;
        required[j] = spec->p[j].required;
    }
    call_args(call, na, anames, anodes);
    if (contract_match(I, b->name, pnames, required, spec->n, b->variadic, "at most ", anames, anodes, na, call,
                       slot))
        return -1;
    for (int i = 0; i < na; i++) {
        if (slot[i] < 0 || !contract_is_constant(anodes[i]))
            continue;
        const cparam *cp = &spec->p[slot[i]];
        if (!cp->type)
            continue;
        value v;
        if (eval_expr(I, I->globals, anodes[i], &v)) {
            /* out of memory is not the argument's error: skipping the check
             * would run a script this check refuses (its prints first) */
            if (I->err.kind == ERR_MEMORY)
                return -1;
            err_clear(I); /* the run reports it where it happens */
            continue;
        }
        int rc = 0;
        if (!(v.k == V_NIL && cp->def_nil)) {
            /* "argument 'NAME'", built without snprintf: one per constant argument */
            char what[160];
            size_t nl = strlen(cp->name);
            if (nl > sizeof what - 13)
                nl = sizeof what - 13;
            memcpy(what, "argument '", 10);
            memcpy(what + 10, cp->name, nl);
            memcpy(what + 10 + nl, "'", 2);
            cpos at = {anodes[i], -1, 0, 0};
            rc = contract_check_value(I, cp->type, v, b->name, what, at);
        }
        val_unref(I, v);
        if (rc)
            return -1;
    }
    return 0;
}

static int check_lambda(interp *I, const char *fname, const node *l, const node *call)
{
    int na = call->nkids - 1;
    if (na > MAX_ARGS || l->nparams > MAX_ARGS)
        return 0;
    const char *anames[MAX_ARGS];
    const node *anodes[MAX_ARGS];
    int required[MAX_ARGS], slot[MAX_ARGS];
    for (int j = 0; j < l->nparams; j++)
        required[j] = l->kids[j] == NULL;
    call_args(call, na, anames, anodes);
    return contract_match(I, fname, l->names, required, l->nparams, 0, "", anames, anodes, na, call, slot);
}

int check_call(interp *I, const check_names *bound, env *const *mods, int nmods, const node *call)
{
    const node *callee = call->kids[0];
    if (callee->kind != N_NAME)
        return 0;
    const char *name = callee->str;
    const node *def;
    int nbound = bound_count(bound, name, &def);
    if (nbound > 1 || (nbound == 1 && !def))
        return 0; /* a variable, or a name given more than one meaning: checked when it runs */
    if (def)
        return check_lambda(I, name, def->kids[0], call);
    value *v = NULL;
    for (int m = nmods - 1; m >= 0 && !v; m--)
        v = val_env_lookup(mods[m], name);
    if (!v)
        v = val_env_lookup(I->globals, name);
    if (!v)
        return 0;
    if (v->k == V_BUILTIN)
        return check_builtin(I, v->u.bi, call);
    if (v->k == V_FUNC)
        return check_lambda(I, AS_FUNC(*v)->name ? AS_FUNC(*v)->name : name, AS_FUNC(*v)->lambda, call);
    return 0;
}
