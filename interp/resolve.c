/* resolve.c — static name resolution. */
#include "resolve.h"

#include <string.h>

#include "check.h"
#include "cstack.h"
#include "eval.h"
#include "lexer.h"
#include "parser.h"
#include "stdlib_embed.h"

typedef struct scope {
    const char **names; /* `small` until it holds more */
    int n, cap;
    const char *small[8]; /* most scopes (parameters, loop variables) are small: no allocation */
    const char **set; /* pointer hash set of names, for large scopes */
    size_t set_cap;
    struct scope *parent;
} scope;

static void scope_free(interp *I, scope *s)
{
    if (s->names != s->small)
        mem_free(I, s->names);
    mem_free(I, s->set);
}

static int set_insert(interp *I, scope *s, const char *name)
{
    if (!s->set && s->n > 16) {
        /* first time: index every name so far */
        s->set_cap = 64;
        while (s->set_cap < (size_t)s->n * 2 + 2)
            s->set_cap *= 2;
        s->set = mem_alloc(I, s->set_cap * sizeof *s->set);
        if (!s->set)
            return -1;
        memset(s->set, 0, s->set_cap * sizeof *s->set);
        for (int i = 0; i < s->n; i++) {
            size_t h = name_hash(s->names[i]) & (s->set_cap - 1);
            while (s->set[h] && s->set[h] != s->names[i])
                h = (h + 1) & (s->set_cap - 1);
            s->set[h] = s->names[i];
        }
        return 0;
    }
    if ((size_t)s->n * 2 >= s->set_cap) {
        size_t cap = s->set_cap ? s->set_cap * 2 : 64;
        const char **ns = mem_alloc(I, cap * sizeof *ns);
        if (!ns)
            return -1;
        memset(ns, 0, cap * sizeof *ns);
        for (size_t i = 0; i < s->set_cap; i++)
            if (s->set[i]) {
                size_t h = name_hash(s->set[i]) & (cap - 1);
                while (ns[h])
                    h = (h + 1) & (cap - 1);
                ns[h] = s->set[i];
            }
        mem_free(I, s->set);
        s->set = ns;
        s->set_cap = cap;
    }
    size_t h = name_hash(name) & (s->set_cap - 1);
    while (s->set[h] && s->set[h] != name)
        h = (h + 1) & (s->set_cap - 1);
    s->set[h] = name;
    return 0;
}

static int scope_has(const scope *s, const char *name)
{
    if (s->set) {
        for (size_t h = name_hash(name) & (s->set_cap - 1); s->set[h]; h = (h + 1) & (s->set_cap - 1))
            if (s->set[h] == name)
                return 1;
        return 0;
    }
    for (int i = 0; i < s->n; i++)
        if (s->names[i] == name)
            return 1;
    return 0;
}

/* The call checks (check.c) need every name the program binds, the whole
 * program's, before the first call is checked. The walk below visits every
 * binding anyway, so it collects them itself and puts the calls off until
 * its end, then checks them in the order it met them: one walk instead of
 * two. What a reader sees stays as if each call were checked where the walk
 * meets it: when the walk stops at an error, or reaches an import (which
 * loads a module: its effects must not come before an earlier call's
 * error), the resolver settles: it collects the names with check_collect,
 * checks the calls put off so far (the first failing one is the error
 * reported, as it came first), and from then on checks each call at once. */
typedef struct pending_call {
    const node *call;
    int nmods;
} pending_call;

typedef struct resolver {
    interp *I;
    env *globals;
    const node *prog;
    const char *visiting[64]; /* modules being scanned (cycle guard) */
    int nvisiting;
    check_names bound;        /* names the program binds, for the call checks */
    int settled;              /* bound is complete: check calls at once */
    pending_call *pend;       /* calls met before then, in order */
    int npend, cap_pend;
    env *mods[64];            /* scopes of the modules imported without an alias */
    int nmods;
} resolver;

/* A name bound (for the call checks), while the walk collects them. */
static int bind(resolver *r, const char *name, const node *def)
{
    return r->settled ? 0 : check_bind(r->I, &r->bound, name, def);
}

static int call_check(resolver *r, const node *call)
{
    if (r->settled)
        return check_call(r->I, &r->bound, r->mods, r->nmods, call);
    if (r->npend == r->cap_pend) {
        int nc = r->cap_pend ? r->cap_pend * 2 : 64;
        pending_call *np = mem_realloc(r->I, r->pend, (size_t)nc * sizeof *np);
        if (!np)
            return -1;
        r->pend = np;
        r->cap_pend = nc;
    }
    r->pend[r->npend++] = (pending_call){call, r->nmods};
    return 0;
}

static int run_pending(resolver *r)
{
    const node *save = r->I->cur; /* an allocation refused while checking is reported at the call */
    for (int i = 0; i < r->npend; i++) {
        r->I->cur = r->pend[i].call;
        if (check_call(r->I, &r->bound, r->mods, r->pend[i].nmods, r->pend[i].call)) {
            r->I->cur = save;
            return -1;
        }
    }
    r->I->cur = save;
    r->npend = 0;
    return 0;
}

/* The names from the whole program, then the calls put off so far. */
static int settle(resolver *r)
{
    r->settled = 1;
    check_names_free(r->I, &r->bound);
    if (check_collect(r->I, r->prog, &r->bound))
        return -1;
    return run_pending(r);
}

static int declare(resolver *r, scope *s, const char *name)
{
    if (!s->cap) {
        s->names = s->small;
        s->cap = (int)(sizeof s->small / sizeof s->small[0]);
    } else if (s->n == s->cap) {
        int nc = s->cap * 2;
        const char **nn = mem_alloc(r->I, (size_t)nc * sizeof *nn);
        if (!nn)
            return -1;
        memcpy(nn, s->names, (size_t)s->n * sizeof *nn);
        if (s->names != s->small)
            mem_free(r->I, s->names);
        s->names = nn;
        s->cap = nc;
    }
    s->names[s->n++] = name;
    return s->n > 16 ? set_insert(r->I, s, name) : 0;
}

static int visible(resolver *r, scope *s, const char *name)
{
    for (; s; s = s->parent)
        if (scope_has(s, name))
            return 1;
    return val_env_lookup(r->globals, name) != NULL;
}

/* `frame` and `clock` as the builtin scope defines them (not shadowed by a
 * let, a param or a parameter): assigning to them is an error. */
static int read_only_frame_name(resolver *r, scope *s, const char *name)
{
    if (strcmp(name, "frame") != 0 && strcmp(name, "clock") != 0)
        return 0;
    for (; s; s = s->parent)
        if (scope_has(s, name))
            return 0;
    env *root = r->globals;
    while (root->parent)
        root = root->parent;
    value *slot = val_env_lookup(r->globals, name);
    return slot && slot == val_env_lookup(root, name);
}

/* Append a name to a growable array (freed on failure). */
static int push_candidate(interp *I, const char ***c, size_t *n, size_t *cap, const char *name)
{
    if (*n == *cap) {
        size_t nc = *cap ? *cap * 2 : 64;
        const char **grown = mem_realloc(I, *c, nc * sizeof *grown);
        if (!grown) {
            mem_free(I, *c);
            *c = NULL;
            return -1;
        }
        *c = grown;
        *cap = nc;
    }
    (*c)[(*n)++] = name;
    return 0;
}

/* The standard module whose top level defines `name` (a `let`, `fn` or
 * `param` at the start of a statement outside any bracket or block) in
 * *mod, or NULL. Only scanned when a name is unknown, so the modules are
 * lexed then, not at every start. -1 when out of memory (not "no module":
 * the message would lose its hint). */
static int stdlib_defining(interp *I, const char *name, const char **mod)
{
    size_t nl = strlen(name);
    *mod = NULL;
    for (const stdlib_module *m = stdlib_modules; m->name; m++) {
        token_list tl;
        if (lex_all(m->source, 0, 1, &tl))
            return mem_engine_error(I, NULL, "out of memory");
        int depth = 0, at_start = 1, found = 0;
        for (size_t i = 0; i + 1 < tl.n && !found; i++) {
            const token *t = &tl.toks[i];
            tok_type k = (tok_type)t->type;
            if (k == T_LPAREN || k == T_LBRACKET || k == T_LBRACE || k == T_DO)
                depth++;
            else if ((k == T_RPAREN || k == T_RBRACKET || k == T_RBRACE || k == T_END) && depth > 0)
                depth--;
            const token *nt = t + 1;
            if (depth == 0 && at_start && (k == T_LET || k == T_FN || k == T_PARAM) && nt->type == T_IDENT &&
                (size_t)nt->len == nl && memcmp(nt->start, name, nl) == 0)
                found = 1;
            at_start = k == T_NEWLINE || k == T_SEMI;
        }
        lex_free(&tl);
        if (found) {
            *mod = m->name;
            return 0;
        }
    }
    return 0;
}

static int unknown(resolver *r, scope *s, const node *at, const char *name)
{
    /* gather candidates from every scope and the globals */
    const char **c = NULL;
    size_t n = 0, cap = 0;
    for (scope *t = s; t; t = t->parent)
        for (int i = 0; i < t->n; i++)
            if (push_candidate(r->I, &c, &n, &cap, t->names[i]))
                return -1;
    for (env *e = r->globals; e; e = e->parent)
        for (size_t i = 0; i < e->n; i++)
            if (push_candidate(r->I, &c, &n, &cap, e->names[i]))
                return -1;
    const char *mod;
    if (stdlib_defining(r->I, name, &mod)) {
        mem_free(r->I, c);
        return -1;
    }
    const char *sug = mod ? NULL : interp_suggest_name(name, c, n);
    if (mod)
        err_at(r->I, at, ERR_NAME, "unknown name '%s' (import \"%s\" defines it)", name, mod);
    else
        err_at(r->I, at, ERR_NAME, "unknown name '%s'%s%s%s", name, sug ? " (did you mean '" : "",
               sug ? sug : "", sug ? "'?)" : "");
    mem_free(r->I, c);
    return -1;
}

static int resolve_node(resolver *r, scope *s, const node *n);
static int resolve_block(resolver *r, scope *s, const node *b);

static int module_names(resolver *r, scope *s, const node *imp)
{
    /* Parse the module (not run it) and declare its top-level names. */
    env *m;
    (void)m;
    const char *name = imp->str;
    if (!r->settled && settle(r))
        return -1;
    for (int i = 0; i < r->nvisiting; i++)
        if (strcmp(r->visiting[i], name) == 0)
            return err_at(r->I, imp, ERR_VALUE, "import cycle: \"%s\" is already being imported", name);
    /* Loading a module only defines things (modules are libraries), so use
     * the evaluator's loader: it caches the module, detects cycles and
     * reports errors inside the module at their own positions. */
    if (eval_import(r->I, imp, name, &m))
        return -1;
    if (imp->names[0])
        return declare(r, s, imp->names[0]);
    if (r->nmods < 64)
        r->mods[r->nmods++] = m;
    for (size_t i = 0; i < m->n; i++)
        if (declare(r, s, m->names[i]))
            return -1;
    return 0;
}

static int resolve_lambda(resolver *r, scope *s, const node *l)
{
    scope inner = {0};
    inner.parent = s;
    int rc = 0;
    for (int i = 0; i < l->nparams && rc == 0; i++) {
        if (l->kids[i])
            rc = resolve_node(r, &inner, l->kids[i]);
        if (rc == 0)
            rc = declare(r, &inner, l->names[i]);
        if (rc == 0)
            rc = bind(r, l->names[i], NULL);
    }
    if (rc == 0)
        rc = l->body->kind == N_BLOCK ? resolve_block(r, &inner, l->body) : resolve_node(r, &inner, l->body);
    scope_free(r->I, &inner);
    return rc;
}

/* A literal has nothing to resolve: its parent does not call for it. */
_Static_assert(N_NUM == 0 && N_STR == 1 && N_BOOL == 2 && N_NIL == 3,
               "is_literal takes the literals to be the first node kinds");
static int is_literal(const node *n)
{
    return n->kind <= N_NIL; /* N_NUM, N_STR, N_BOOL, N_NIL come first in node_kind */
}

static int resolve_kid(resolver *r, scope *s, const node *k);

/* The loop of a for or a comprehension: `iter` resolves in s, then the loop
 * variable `name` is declared in a scope of its own inside s, where `first`
 * and then `second` (either may be NULL) resolve. */
static int resolve_loop(resolver *r, scope *s, const char *name, const node *iter, const node *first,
                        const node *second)
{
    if (resolve_node(r, s, iter))
        return -1;
    scope inner = {0};
    inner.parent = s;
    int rc = declare(r, &inner, name);
    if (rc == 0)
        rc = bind(r, name, NULL);
    if (rc == 0)
        rc = resolve_node(r, &inner, first);
    if (rc == 0)
        rc = resolve_node(r, &inner, second);
    scope_free(r->I, &inner);
    return rc;
}

static int resolve_node(resolver *r, scope *s, const node *n)
{
    if (!n)
        return 0;
    /* nesting is bounded by the parser, but flat chains (1+1+…) are left-deep trees */
    if (cstack_exhausted())
        return cstack_error(r->I, n, "expression nested too deeply");
    switch (n->kind) {
    case N_NAME:
        return visible(r, s, n->str) ? 0 : unknown(r, s, n, n->str);
    case N_LAMBDA:
        return resolve_lambda(r, s, n);
    case N_BLOCK: {
        scope inner = {0};
        inner.parent = s;
        int rc = resolve_block(r, &inner, n);
        scope_free(r->I, &inner);
        return rc;
    }
    case N_COMP: /* [kids[0] for str in kids[1] if kids[2]] */
        return resolve_loop(r, s, n->str, n->kids[1], n->kids[2], n->kids[0]);
    case N_FIELD:
        return resolve_node(r, s, n->kids[0]);
    case N_CALL:
        for (int i = 0; i < n->nkids; i++)
            if (resolve_kid(r, s, n->kids[i]))
                return -1;
        return call_check(r, n);
    default:
        for (int i = 0; i < n->nkids; i++)
            if (resolve_kid(r, s, n->kids[i]))
                return -1;
        return 0;
    }
}

/* resolve_node for a child, with the leaves (most children) done here */
static inline int resolve_kid(resolver *r, scope *s, const node *k)
{
    if (!k || is_literal(k))
        return 0;
    if (k->kind == N_NAME)
        return visible(r, s, k->str) ? 0 : unknown(r, s, k, k->str);
    return resolve_node(r, s, k);
}

static int resolve_block(resolver *r, scope *s, const node *b)
{
    if (cstack_exhausted())
        return cstack_error(r->I, b, "blocks nested too deeply");
    /* functions defined in a block are visible throughout it */
    for (int i = 0; i < b->nkids; i++)
        if (b->kids[i]->kind == N_FNDEF && declare(r, s, b->kids[i]->str))
            return -1;
    for (int i = 0; i < b->nkids; i++) {
        const node *st = b->kids[i];
        switch (st->kind) {
        case N_LET:
        case N_PARAM:
            if (bind(r, st->str, NULL))
                return -1;
            if (st->kids[0]->kind == N_LAMBDA) {
                if (declare(r, s, st->str) || resolve_node(r, s, st->kids[0]))
                    return -1;
            } else if (resolve_node(r, s, st->kids[0]) || declare(r, s, st->str)) {
                return -1;
            }
            break;
        case N_ASSIGN:
            if (bind(r, st->str, NULL))
                return -1;
            if (!visible(r, s, st->str))
                return err_at(r->I, st, ERR_NAME, "cannot assign to '%s': it is not defined (use 'let %s = …')",
                              st->str, st->str);
            if (read_only_frame_name(r, s, st->str))
                return err_at(r->I, st, ERR_NAME,
                              "cannot assign to '%s': it is read-only (set by --frames; 'let %s = …' defines "
                              "your own)",
                              st->str, st->str);
            if (resolve_node(r, s, st->kids[0]))
                return -1;
            break;
        case N_FNDEF:
            if (bind(r, st->str, b == r->prog ? st : NULL) || resolve_lambda(r, s, st->kids[0]))
                return -1;
            break;
        case N_IMPORT:
            if (module_names(r, s, st))
                return -1;
            break;
        case N_FOR:
            if (resolve_loop(r, s, st->str, st->kids[0], st->kids[1], NULL))
                return -1;
            break;
        case N_EXPR:
            if (resolve_node(r, s, st->kids[0]))
                return -1;
            break;
        default:
            if (resolve_node(r, s, st))
                return -1;
        }
    }
    return 0;
}


int resolve_program(interp *I, node *prog, env *globals)
{
    int rc = resolve_check(I, prog, globals);
    return rc ? rc : resolve_slots(I, prog, globals, I->is_repl);
}

int resolve_check(interp *I, node *prog, env *globals)
{
    resolver r;
    memset(&r, 0, sizeof r);
    r.I = I;
    r.globals = globals;
    r.prog = prog;
    scope top = {0};
    int rc = resolve_block(&r, &top, prog);
    if (!r.settled && rc == 0) {
        /* the walk saw every binding: index them, check the calls */
        r.settled = 1;
        rc = check_index(I, &r.bound);
        if (rc == 0)
            rc = run_pending(&r);
    } else if (!r.settled) {
        /* an error before any import: a call met before it may fail first */
        err_state e = I->err;
        err_clear(I);
        if (settle(&r) == 0)
            I->err = e; /* no: the walk's error stands */
        rc = -1;
    }
    scope_free(I, &top);
    check_names_free(I, &r.bound);
    mem_free(I, r.pend);
    return rc;
}

/* ---- slots ------------------------------------------------------------------------------------------
 *
 * After the checks above pass, a second walk gives each name its place in the
 * evaluator's scopes, so eval.c finds a variable with an index instead of a
 * search by name. It mirrors how eval.c makes scopes: one per call (the
 * parameters, then the statements of a block body), per `do … end` block,
 * per loop iteration (the variable, then the body's statements) and per
 * comprehension item; a scope's names take slots in the order its statements
 * first define them, as val_env_define appends them.
 *
 * A use of x is bound to the innermost scope among those around it that
 * defines x anywhere in its statements (a scope that never defines x cannot
 * hold it at run time, so lookups skip it). Whether x is defined yet when the
 * use runs is the evaluator's question: it checks that the slot holds x and
 * otherwise searches by name, which is then the same search as before. The
 * REPL's top level is open (later inputs add names), so uses are not bound
 * past it. */

typedef struct rscope {
    struct rscope *parent;
    const char **keys; /* open addressing: name -> slot */
    int *slots;
    size_t cap, n;
    int next;     /* the next slot to give */
    int open;     /* may hold names this walk does not know */
    env *fixed;   /* the builtins' scope: slots are its own */
} rscope;

static int rs_slot(const rscope *s, const char *name)
{
    if (s->fixed) {
        value *v = val_env_lookup(s->fixed, name);
        return v ? (int)(v - s->fixed->vals) : -1;
    }
    if (!s->cap)
        return -1;
    for (size_t h = name_hash(name) & (s->cap - 1); s->keys[h]; h = (h + 1) & (s->cap - 1))
        if (s->keys[h] == name)
            return s->slots[h];
    return -1;
}

static int rs_put(interp *I, rscope *s, const char *name, int slot)
{
    if ((s->n + 1) * 2 > s->cap) {
        size_t cap = s->cap ? s->cap * 2 : 16;
        const char **nk = mem_calloc(I, cap, sizeof *nk);
        int *ns = mem_alloc(I, cap * sizeof *ns);
        if (!nk || !ns) {
            mem_free(I, nk);
            mem_free(I, ns);
            return -1;
        }
        for (size_t i = 0; i < s->cap; i++)
            if (s->keys[i]) {
                size_t h = name_hash(s->keys[i]) & (cap - 1);
                while (nk[h])
                    h = (h + 1) & (cap - 1);
                nk[h] = s->keys[i];
                ns[h] = s->slots[i];
            }
        mem_free(I, s->keys);
        mem_free(I, s->slots);
        s->keys = nk;
        s->slots = ns;
        s->cap = cap;
    }
    size_t h = name_hash(name) & (s->cap - 1);
    while (s->keys[h])
        h = (h + 1) & (s->cap - 1);
    s->keys[h] = name;
    s->slots[h] = slot;
    s->n++;
    return 0;
}

/* A definition: a new name takes the next slot; a redefinition keeps its own. */
static int rs_define(interp *I, rscope *s, const char *name)
{
    if (rs_slot(s, name) >= 0)
        return 0;
    return rs_put(I, s, name, s->next++);
}

static void rs_free(interp *I, rscope *s)
{
    mem_free(I, s->keys);
    mem_free(I, s->slots);
}

static void bind_use(const rscope *s, const char *name, node *n)
{
    for (int hops = 0; s; s = s->parent, hops++) {
        int slot = rs_slot(s, name);
        if (slot >= 0) {
            n->slot = slot + 1;
            n->hops = hops;
            return;
        }
        if (s->open)
            return;
    }
}

static int slots_node(interp *I, rscope *s, node *n);
static int slots_stmts(interp *I, rscope *s, const node *b);

/* The names a block's statements define, in the order they define them. */
static int slots_defs(interp *I, rscope *s, const node *b)
{
    for (int i = 0; i < b->nkids; i++) {
        node *st = b->kids[i];
        switch (st->kind) {
        case N_LET:
        case N_PARAM:
        case N_FNDEF:
            if (rs_define(I, s, st->str))
                return -1;
            st->slot = rs_slot(s, st->str) + 1;
            break;
        case N_IMPORT:
            if (st->names[0]) {
                if (rs_define(I, s, st->names[0]))
                    return -1;
                st->slot = rs_slot(s, st->names[0]) + 1;
            } else {
                /* a script's modules were loaded by its checks; a module's own
                 * imports load when they run: until then its names are found
                 * by name (the slots of the names after them may be off too),
                 * and no use is bound past this scope (they may hide builtins) */
                env *m = eval_module_loaded(I, st, st->str);
                if (!m) {
                    s->open = 1;
                    break;
                }
                int *slots = mem_arena_alloc(I, (m->n + 1) * sizeof *slots);
                if (!slots)
                    return -1;
                slots[0] = (int)m->n;
                for (size_t k = 0; k < m->n; k++) {
                    if (rs_define(I, s, m->names[k]))
                        return -1;
                    slots[k + 1] = rs_slot(s, m->names[k]) + 1;
                }
                st->slots = slots;
            }
            break;
        default:
            break;
        }
    }
    return 0;
}

static int slots_block(interp *I, rscope *s, const node *b)
{
    return slots_defs(I, s, b) || slots_stmts(I, s, b) ? -1 : 0;
}

/* The slots of a for (body; an N_BLOCK's statements share the loop
 * variable's scope) or a comprehension (its condition cond, then its
 * element elem): iter in s, then the loop variable in a scope of its own. */
static int slots_loop(interp *I, rscope *s, const char *name, node *iter, node *body, node *cond, node *elem)
{
    if (slots_node(I, s, iter))
        return -1;
    rscope inner = {.parent = s};
    int rc = rs_define(I, &inner, name);
    if (rc == 0 && body)
        rc = body->kind == N_BLOCK ? slots_block(I, &inner, body) : slots_node(I, &inner, body);
    if (rc == 0)
        rc = slots_node(I, &inner, cond);
    if (rc == 0)
        rc = slots_node(I, &inner, elem);
    rs_free(I, &inner);
    return rc;
}

static int slots_stmts(interp *I, rscope *s, const node *b)
{
    if (cstack_exhausted())
        return cstack_error(I, b, "blocks nested too deeply");
    for (int i = 0; i < b->nkids; i++) {
        node *st = b->kids[i];
        switch (st->kind) {
        case N_LET:
        case N_PARAM:
        case N_FNDEF:
        case N_EXPR:
            if (slots_node(I, s, st->kids[0]))
                return -1;
            break;
        case N_ASSIGN:
            bind_use(s, st->str, st);
            if (slots_node(I, s, st->kids[0]))
                return -1;
            break;
        case N_IMPORT:
            break;
        case N_FOR:
            if (slots_loop(I, s, st->str, st->kids[0], st->kids[1], NULL, NULL))
                return -1;
            break;
        default:
            if (slots_node(I, s, st))
                return -1;
        }
    }
    return 0;
}

static int slots_node(interp *I, rscope *s, node *n)
{
    if (!n)
        return 0;
    if (cstack_exhausted())
        return cstack_error(I, n, "expression nested too deeply");
    int rc = 0;
    switch (n->kind) {
    case N_NAME:
        bind_use(s, n->str, n);
        return 0;
    case N_LAMBDA: {
        rscope inner = {.parent = s};
        for (int i = 0; i < n->nparams && rc == 0; i++)
            rc = rs_define(I, &inner, n->names[i]);
        if (rc == 0 && n->body->kind == N_BLOCK)
            rc = slots_defs(I, &inner, n->body);
        for (int i = 0; i < n->nparams && rc == 0; i++)
            rc = slots_node(I, &inner, n->kids[i]);
        if (rc == 0)
            rc = n->body->kind == N_BLOCK ? slots_stmts(I, &inner, n->body) : slots_node(I, &inner, n->body);
        rs_free(I, &inner);
        return rc;
    }
    case N_BLOCK: {
        rscope inner = {.parent = s};
        rc = slots_block(I, &inner, n);
        rs_free(I, &inner);
        return rc;
    }
    case N_COMP:
        return slots_loop(I, s, n->str, n->kids[1], NULL, n->kids[2], n->kids[0]);
    default:
        for (int i = 0; i < n->nkids && rc == 0; i++)
            rc = slots_node(I, s, n->kids[i]);
        return rc;
    }
}

int resolve_slots(interp *I, node *prog, env *globals, int open)
{
    rscope root = {.fixed = globals->parent};
    rscope top = {.parent = globals->parent ? &root : NULL, .open = open};
    int rc = 0;
    /* the names the scope already holds keep their slots */
    for (size_t i = 0; i < globals->n && rc == 0; i++)
        rc = rs_define(I, &top, globals->names[i]);
    if (rc == 0)
        rc = slots_block(I, &top, prog);
    rs_free(I, &top);
    return rc;
}
