/* contract.c — compile and check the declared contract of builtins (see contract.h). */
#include "contract.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "eval.h"
#include "fileio.h"

enum { K_ANY, K_NUM, K_INT, K_STR, K_BOOL, K_LIST, K_VEC, K_REC, K_FUNC, K_NIL, K_CLASS };

typedef struct ckey {
    const char *name; /* interned */
    const ctype *type;
    int required;     /* written "name!: T" */
} ckey;

typedef struct calt {
    int kind;
    int len;                 /* K_VEC: exact length, 0 any */
    int whole;               /* K_VEC written "ivec": whole-number items */
    int has_lo, has_hi, lo_open, hi_open;
    double lo, hi;
    int inf, nan;            /* non-finite numbers allowed */
    const char *cls;         /* K_CLASS */
    size_t clslen;
    int nchoice;             /* K_NUM/K_INT/K_STR {…} */
    double *nchoices;
    const char **schoices;
    int nkeys;               /* K_REC {…}: the keys it may have; -1 any */
    ckey *keys;
} calt;

struct ctype {
    const char *text;
    int n;
    calt *alt;
};

/* The per-interpreter cache: declarations by address (type texts and
 * builtins), in the arena, so it lives as long as the session. */
typedef struct centry {
    const void *key;
    void *val;
} centry;

typedef struct contract_cache {
    centry *tab;
    size_t cap, n;
} contract_cache;

static contract_cache *cache_of(interp *I)
{
    if (!I->contract) {
        contract_cache *c = mem_arena_alloc(I, sizeof *c);
        if (!c)
            return NULL;
        memset(c, 0, sizeof *c);
        I->contract = c;
    }
    return I->contract;
}

static void *cache_get(interp *I, const void *key)
{
    contract_cache *c = I->contract;
    if (!c || !c->cap)
        return NULL;
    size_t h = name_hash(key) & (c->cap - 1);
    while (c->tab[h].key) {
        if (c->tab[h].key == key)
            return c->tab[h].val;
        h = (h + 1) & (c->cap - 1);
    }
    return NULL;
}

static int cache_put(interp *I, const void *key, void *val)
{
    contract_cache *c = cache_of(I);
    if (!c)
        return -1;
    if ((c->n + 1) * 2 > c->cap) {
        size_t cap = c->cap ? c->cap * 2 : 512;
        centry *t = mem_arena_alloc(I, cap * sizeof *t);
        if (!t)
            return -1;
        memset(t, 0, cap * sizeof *t);
        for (size_t i = 0; i < c->cap; i++)
            if (c->tab[i].key) {
                size_t h = name_hash(c->tab[i].key) & (cap - 1);
                while (t[h].key)
                    h = (h + 1) & (cap - 1);
                t[h] = c->tab[i];
            }
        c->tab = t; /* the old table stays in the arena */
        c->cap = cap;
    }
    size_t h = name_hash(key) & (c->cap - 1);
    while (c->tab[h].key && c->tab[h].key != key)
        h = (h + 1) & (c->cap - 1);
    if (!c->tab[h].key)
        c->n++;
    c->tab[h].key = key;
    c->tab[h].val = val;
    return 0;
}

/* ---- compiling type texts --------------------------------------------------------- */

typedef struct tparser {
    interp *I;
    const char *text, *p;
    const char *err;
} tparser;

static void skip_ws(tparser *t)
{
    while (*t->p == ' ')
        t->p++;
}

static int tp_number(tparser *t, double *out)
{
    skip_ws(t);
    char *end;
    if (strncmp(t->p, "inf", 3) == 0 || strncmp(t->p, "-inf", 4) == 0) {
        *out = t->p[0] == '-' ? -INFINITY : INFINITY;
        t->p += t->p[0] == '-' ? 4 : 3;
        return 0;
    }
    *out = strtod(t->p, &end);
    if (end == t->p) {
        t->err = "a number";
        return -1;
    }
    t->p = end;
    skip_ws(t);
    return 0;
}

/* The text up to a ',' '}' or '|' at bracket depth 0 (for nested types). */
static const char *tp_span(tparser *t, const char *stops)
{
    int depth = 0;
    const char *s = t->p;
    for (; *t->p; t->p++) {
        char c = *t->p;
        if (c == '[' || c == '(' || c == '{')
            depth++;
        else if ((c == ']' || c == ')' || c == '}') && depth > 0)
            depth--;
        else if (depth == 0 && strchr(stops, c))
            break;
    }
    return s;
}

static const ctype *compile_text(interp *I, const char *text, size_t len, const char **err);

static int tp_keys(tparser *t, calt *a)
{
    /* '{' name ':' type {',' name ':' type} '}' */
    ckey keys[64];
    int n = 0;
    t->p++;
    skip_ws(t);
    while (*t->p && *t->p != '}') {
        const char *s = t->p;
        while (isalnum((unsigned char)*t->p) || *t->p == '_')
            t->p++;
        if (t->p == s || n == 64) {
            t->err = "a key name";
            return -1;
        }
        keys[n].name = interp_intern(t->I, s, (size_t)(t->p - s));
        keys[n].required = *t->p == '!';
        if (keys[n].required)
            t->p++;
        skip_ws(t);
        if (*t->p != ':') {
            t->err = "':' after the key name";
            return -1;
        }
        t->p++;
        skip_ws(t);
        const char *ts = tp_span(t, ",}");
        const char *e = NULL;
        keys[n].type = compile_text(t->I, ts, (size_t)(t->p - ts), &e);
        if (!keys[n].name || !keys[n].type) {
            t->err = e ? e : "a key type";
            return -1;
        }
        n++;
        if (*t->p == ',')
            t->p++;
        skip_ws(t);
    }
    if (*t->p != '}') {
        t->err = "'}'";
        return -1;
    }
    t->p++;
    a->nkeys = n;
    a->keys = mem_arena_alloc(t->I, sizeof(ckey) * (size_t)(n ? n : 1));
    if (!a->keys)
        return -1;
    memcpy(a->keys, keys, sizeof(ckey) * (size_t)n);
    return 0;
}

static int tp_choices(tparser *t, calt *a)
{
    /* '{' word {',' word} '}' — numbers for num/int, names for str */
    const char *words[64];
    double nums[64];
    int n = 0;
    t->p++;
    while (*t->p && *t->p != '}') {
        skip_ws(t);
        if (n == 64) {
            t->err = "at most 64 choices";
            return -1;
        }
        if (a->kind == K_STR) {
            const char *s = t->p;
            while (*t->p && *t->p != ',' && *t->p != '}')
                t->p++;
            const char *e = t->p;
            while (e > s && e[-1] == ' ')
                e--;
            words[n] = interp_intern(t->I, s, (size_t)(e - s));
            if (!words[n])
                return -1;
        } else if (tp_number(t, &nums[n])) {
            return -1;
        }
        n++;
        if (*t->p == ',')
            t->p++;
    }
    if (*t->p != '}') {
        t->err = "'}'";
        return -1;
    }
    t->p++;
    a->nchoice = n;
    if (a->kind == K_STR) {
        a->schoices = mem_arena_alloc(t->I, sizeof(char *) * (size_t)n);
        if (!a->schoices)
            return -1;
        memcpy(a->schoices, words, sizeof(char *) * (size_t)n);
    } else {
        a->nchoices = mem_arena_alloc(t->I, sizeof(double) * (size_t)n);
        if (!a->nchoices)
            return -1;
        memcpy(a->nchoices, nums, sizeof(double) * (size_t)n);
    }
    return 0;
}

static int tp_alt(tparser *t, calt *a)
{
    memset(a, 0, sizeof *a);
    a->nkeys = -1;
    skip_ws(t);
    const char *s = t->p;
    while (isalpha((unsigned char)*t->p) || *t->p == '_' || (t->p > s && isdigit((unsigned char)*t->p) && 0))
        t->p++;
    size_t n = (size_t)(t->p - s);
    static const struct { const char *w; int k; } words[] = {
        {"any", K_ANY}, {"num", K_NUM}, {"int", K_INT}, {"str", K_STR}, {"bool", K_BOOL}, {"list", K_LIST},
        {"vec", K_VEC}, {"ivec", K_VEC}, {"rec", K_REC}, {"func", K_FUNC}, {"nil", K_NIL}};
    a->kind = K_CLASS;
    a->whole = n == 4 && memcmp(s, "ivec", 4) == 0;
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
        if (strlen(words[i].w) == n && memcmp(words[i].w, s, n) == 0)
            a->kind = words[i].k;
    if (n == 0) {
        t->err = "a type name";
        return -1;
    }
    if (a->kind == K_CLASS) {
        a->cls = s;
        a->clslen = n;
    }
    if (a->kind == K_VEC && isdigit((unsigned char)*t->p)) {
        a->len = (int)strtol(t->p, (char **)&t->p, 10);
    }
    if (*t->p == '{') {
        if (a->kind == K_REC) {
            if (tp_keys(t, a))
                return -1;
        } else if (a->kind == K_NUM || a->kind == K_INT || a->kind == K_STR) {
            if (tp_choices(t, a))
                return -1;
        } else {
            t->err = "no '{' after this type";
            return -1;
        }
    }
    if (*t->p == '[' || *t->p == '(') {
        a->lo_open = *t->p == '(';
        t->p++;
        if (tp_number(t, &a->lo))
            return -1;
        if (*t->p != ',') {
            t->err = "',' in the range";
            return -1;
        }
        t->p++;
        if (tp_number(t, &a->hi))
            return -1;
        if (*t->p != ']' && *t->p != ')') {
            t->err = "']' or ')' closing the range";
            return -1;
        }
        a->hi_open = *t->p == ')';
        t->p++;
        a->has_lo = a->has_hi = 1;
    } else if (*t->p == '>' || *t->p == '<') {
        int lower = *t->p == '>';
        t->p++;
        int open = *t->p != '=';
        if (!open)
            t->p++;
        double x;
        if (tp_number(t, &x))
            return -1;
        if (lower) {
            a->has_lo = 1, a->lo = x, a->lo_open = open;
        } else {
            a->has_hi = 1, a->hi = x, a->hi_open = open;
        }
    }
    while (*t->p == '+') {
        if (strncmp(t->p, "+inf", 4) == 0)
            a->inf = 1, t->p += 4;
        else if (strncmp(t->p, "+nan", 4) == 0)
            a->nan = 1, t->p += 4;
        else {
            t->err = "+inf or +nan";
            return -1;
        }
    }
    skip_ws(t);
    return 0;
}

static const ctype *compile_text(interp *I, const char *text, size_t len, const char **err)
{
    I->count.types_compiled++;
    char buf[1024];
    if (len >= sizeof buf) {
        *err = "a shorter type";
        return NULL;
    }
    memcpy(buf, text, len);
    buf[len] = 0;
    tparser t = {I, buf, buf, NULL};
    calt alts[8];
    int n = 0;
    for (;;) {
        if (n == 8) {
            *err = "at most 8 alternatives";
            return NULL;
        }
        if (tp_alt(&t, &alts[n]))
            break;
        n++;
        if (*t.p == '|') {
            t.p++;
            continue;
        }
        if (*t.p)
            t.err = "'|' or the end";
        break;
    }
    if (t.err) {
        *err = t.err;
        return NULL;
    }
    ctype *ct = mem_arena_alloc(I, sizeof *ct);
    calt *al = mem_arena_alloc(I, sizeof *al * (size_t)n);
    char *keep = mem_arena_alloc(I, len + 1);
    if (!ct || !al || !keep)
        return NULL;
    memcpy(keep, buf, len + 1);
    /* class names point into the kept copy */
    for (int i = 0; i < n; i++)
        if (alts[i].cls)
            alts[i].cls = keep + (alts[i].cls - buf);
    memcpy(al, alts, sizeof *al * (size_t)n);
    ct->text = keep;
    ct->n = n;
    ct->alt = al;
    return ct;
}

const ctype *contract_type(interp *I, const char *text)
{
    if (!text)
        return NULL;
    const ctype *t = cache_get(I, text);
    if (t)
        return t;
    const char *err = NULL;
    t = compile_text(I, text, strlen(text), &err);
    if (!t) {
        if (!I->err.active)
            err_at(I, NULL, ERR_RUNTIME, "internal error: bad type '%s': expected %s", text, err ? err : "?");
        return NULL;
    }
    return cache_put(I, text, (void *)t) ? NULL : t;
}

/* ---- defaults ----------------------------------------------------------------------- */

/* Literal defaults become values at registration; anything else (orbit())
 * is evaluated on first use and kept. */
static int literal_default(interp *I, const char *d, value *out)
{
    char *end;
    if (strcmp(d, "nil") == 0 || strcmp(d, "true") == 0 || strcmp(d, "false") == 0) {
        *out = d[0] == 'n' ? val_nil() : val_bool(d[0] == 't');
        return 1;
    }
    double x = strtod(d, &end);
    if (end != d && *end == 0) {
        *out = val_num(x);
        return 1;
    }
    size_t n = strlen(d);
    if (n >= 2 && d[0] == '"' && d[n - 1] == '"' && !memchr(d + 1, '"', n - 2) && !memchr(d, '\\', n)) {
        *out = val_str(I, d + 1, n - 2);
        return out->k == V_NIL ? -1 : 1;
    }
    if (d[0] == '[') {
        value l = val_list(I, 4);
        if (l.k == V_NIL)
            return -1;
        const char *p = d + 1;
        while (*p == ' ')
            p++;
        while (*p && *p != ']') {
            x = strtod(p, &end);
            if (end == p) {
                val_unref(I, l);
                return 0;
            }
            if (val_list_push(I, AS_LIST(l), val_num(x))) {
                val_unref(I, l);
                return -1;
            }
            p = end;
            while (*p == ' ' || *p == ',')
                p++;
        }
        if (*p != ']' || p[1]) {
            val_unref(I, l);
            return 0;
        }
        *out = l;
        return 1;
    }
    return 0;
}

/* Compile b's declaration into the cache (first use: contract_spec). */
static int contract_compile(interp *I, const builtin *b)
{
    bspec *s = mem_arena_alloc(I, sizeof *s);
    cparam *p = mem_arena_alloc(I, sizeof *p * (size_t)(b->nparams ? b->nparams : 1));
    if (!s || !p)
        return -1;
    memset(p, 0, sizeof *p * (size_t)(b->nparams ? b->nparams : 1));
    s->b = b;
    s->n = b->nparams;
    s->p = p;
    for (int j = 0; j < b->nparams; j++) {
        const bparam *bp = &b->params[j];
        p[j].name = interp_intern(I, bp->name, strlen(bp->name));
        if (!p[j].name)
            return -1;
        if (bp->type && strcmp(bp->type, "any") != 0) {
            const char *err = NULL;
            p[j].type = compile_text(I, bp->type, strlen(bp->type), &err);
            if (!p[j].type)
                return I->err.active ? -1
                                     : err_at(I, NULL, ERR_RUNTIME,
                                              "internal error: builtin %s, parameter '%s': bad type '%s': expected %s",
                                              b->name, bp->name, bp->type, err ? err : "?");
        }
        p[j].required = bp->def == NULL;
        if (bp->def) {
            p[j].def_nil = strcmp(bp->def, "nil") == 0;
            int r = literal_default(I, bp->def, &p[j].def);
            if (r < 0)
                return -1;
            p[j].def_ready = r;
        }
    }
    return cache_put(I, b, s);
}

const bspec *contract_spec(interp *I, const builtin *b)
{
    /* compiled on first use, not at registration: a session that calls five
     * builtins compiles five declarations, not all ~300 (this was most of
     * the setup of a short run; tests/fuzz/README.md has the measurements) */
    const bspec *s = cache_get(I, b);
    if (!s && !contract_compile(I, b))
        s = cache_get(I, b);
    return s;
}

int contract_compile_all(interp *I)
{
    for (int i = 0; i < I->nbuiltins; i++)
        if (!contract_spec(I, I->builtins[i]))
            return -1;
    return 0;
}

int contract_default(interp *I, const bspec *s, int j, value *out)
{
    cparam *p = &((bspec *)s)->p[j];
    if (!p->def_ready) {
        char name[128];
        snprintf(name, sizeof name, "<default of %s %s>", s->b->name, s->b->params[j].name);
        value v;
        if (eval_text(I, name, s->b->params[j].def, &v))
            return -1;
        p->def = v; /* kept for the session (freed with every heap object at the end) */
        p->def_ready = 1;
    }
    *out = p->def;
    return 0;
}

/* ---- positions ----------------------------------------------------------------------- */

static cpos pos_of(const node *n)
{
    cpos p = {n, -1, 0, 0};
    return p;
}

cpos contract_name_pos(interp *I, const node *v)
{
    cpos p = pos_of(NULL);
    if (!v || v->src >= I->nsrc)
        return p;
    const char *text = I->srcs[v->src].text;
    /* the offset of the value: line v->line, column v->col (1-based) */
    const char *q = text;
    for (int l = I->srcs[v->src].first_line; l < v->line && q; l++) {
        q = strchr(q, '\n');
        if (q)
            q++;
    }
    if (!q)
        return p;
    q += v->col - 1;
    /* back over white space, the ':' and the name */
    while (q > text && isspace((unsigned char)q[-1]))
        q--;
    if (q == text || q[-1] != ':')
        return p;
    q--;
    while (q > text && (q[-1] == ' ' || q[-1] == '\t'))
        q--;
    const char *end = q;
    if (q > text && q[-1] == '"') {
        q--;
        while (q > text && q[-1] != '"')
            q--;
        if (q == text)
            return p;
        q--;
    } else {
        while (q > text && (isalnum((unsigned char)q[-1]) || q[-1] == '_'))
            q--;
    }
    if (q == end)
        return p;
    int line = I->srcs[v->src].first_line;
    const char *ls = text;
    for (const char *c = text; c < q; c++)
        if (*c == '\n') {
            line++;
            ls = c + 1;
        }
    p.src = v->src;
    p.line = line;
    p.col = (int)(q - ls) + 1;
    return p;
}

static int err_cpos(interp *I, cpos at, err_kind k, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static int err_cpos(interp *I, cpos at, err_kind k, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (at.src >= 0)
        return err_pos(I, at.src, at.line, at.col, k, "%s", msg);
    return err_at(I, at.n, k, "%s", msg);
}

/* The node of item i of the literal a value came from (the row of a table). */
static cpos item_pos(cpos at, size_t i)
{
    const node *n = at.n;
    if (n && (n->kind == N_LIST || n->kind == N_TABLE) && i < (size_t)n->nkids)
        return pos_of(n->kids[i]);
    cpos p = at;
    if (n && n->kind == N_ROW)
        return at; /* a row's entries keep the caret on the row */
    return p;
}

static cpos key_pos(interp *I, cpos at, const char *key, int want_key)
{
    const node *n = at.n;
    if (n && n->kind == N_RECORD)
        for (int i = 0; i < n->nkids; i++)
            if (n->names[i] == key) {
                if (!want_key)
                    return pos_of(n->kids[i]);
                cpos p = contract_name_pos(I, n->kids[i]);
                if (p.src < 0)
                    p = pos_of(n->kids[i]);
                p.n = n->kids[i];
                return p;
            }
    cpos p = at;
    if (p.src < 0 && p.n) { /* not a literal: the value's whole node */
        p.src = p.n->src;
        p.line = p.n->line;
        p.col = p.n->col;
    }
    p.n = NULL; /* no finer position inside it */
    return p;
}

/* ---- checking ------------------------------------------------------------------------- */

static void fmt_num(double x, char *buf, size_t n)
{
    if (isnan(x))
        snprintf(buf, n, "nan");
    else if (isinf(x))
        snprintf(buf, n, "%s", x < 0 ? "-inf" : "inf");
    else
        val_fmt_number(x, buf, n);
}

/* A small text buffer for messages. */
typedef struct sbuf {
    char data[512];
    size_t len;
} sbuf;

static void sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(sbuf *b, const char *fmt, ...)
{
    if (b->len + 1 >= sizeof b->data)
        return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(b->data + b->len, sizeof b->data - b->len, fmt, ap);
    va_end(ap);
    if (k > 0)
        b->len = b->len + (size_t)k < sizeof b->data ? b->len + (size_t)k : sizeof b->data - 1;
}

static void describe_alt(const calt *a, sbuf *out)
{
    switch (a->kind) {
    case K_ANY: sb_printf(out, "anything"); break;
    case K_NUM:
    case K_INT:
        if (a->nchoice) {
            for (int i = 0; i < a->nchoice; i++) {
                char b[32];
                fmt_num(a->nchoices[i], b, sizeof b);
                sb_printf(out, "%s%s", i == 0 ? "" : i == a->nchoice - 1 ? " or " : ", ", b);
            }
        } else {
            sb_printf(out, a->kind == K_NUM ? "a number" : "a whole number");
        }
        break;
    case K_STR:
        if (a->nchoice) {
            sb_printf(out, "one of");
            for (int i = 0; i < a->nchoice; i++)
                sb_printf(out, "%s\"%s\"", i ? ", " : " ", a->schoices[i]);
        } else {
            sb_printf(out, "a string");
        }
        break;
    case K_BOOL: sb_printf(out, "a boolean"); break;
    case K_LIST: sb_printf(out, "a list"); break;
    case K_VEC:
        if (a->len)
            sb_printf(out, "a list of %d %s", a->len, a->whole ? "whole numbers" : "numbers");
        else
            sb_printf(out, "a list of %s", a->whole ? "whole numbers" : "numbers");
        break;
    case K_REC: sb_printf(out, "a record"); break;
    case K_FUNC: sb_printf(out, "a function"); break;
    case K_NIL: sb_printf(out, "nil"); break;
    default: {
        /* classes a script makes with a builtin of another name: say how */
        static const struct { const char *cls, *how; } hints[] = {
            {"order", " (order([1, 2]), order(\"W2 ∘ W1\"), …)"},
            {"shape", " (polygon(…), polyline(…) or pointset(…))"},
        };
        const char *how = "";
        for (size_t i = 0; i < sizeof hints / sizeof hints[0]; i++)
            if (strlen(hints[i].cls) == a->clslen && memcmp(hints[i].cls, a->cls, a->clslen) == 0)
                how = hints[i].how;
        sb_printf(out, "%s %.*s%s", strchr("aeiou", a->cls[0]) ? "an" : "a", (int)a->clslen, a->cls, how);
    }
    }
}

static void describe_type(const ctype *t, sbuf *out)
{
    for (int i = 0; i < t->n; i++) {
        if (i)
            sb_printf(out, i == t->n - 1 ? " or " : ", ");
        describe_alt(&t->alt[i], out);
    }
}

static void describe_range(const calt *a, sbuf *out)
{
    char lo[32], hi[32];
    fmt_num(a->lo, lo, sizeof lo);
    fmt_num(a->hi, hi, sizeof hi);
    if (a->has_lo && a->has_hi)
        sb_printf(out, "in %c%s, %s%c", a->lo_open ? '(' : '[', lo, hi, a->hi_open ? ')' : ']');
    else if (a->has_lo)
        sb_printf(out, "%s %s", a->lo_open ? ">" : ">=", lo);
    else
        sb_printf(out, "%s %s", a->hi_open ? "<" : "<=", hi);
}

static int base_matches(const calt *a, value v)
{
    switch (a->kind) {
    case K_ANY: return 1;
    case K_NUM: return v.k == V_NUM;
    case K_INT: return v.k == V_NUM && (!isfinite(v.u.n) || v.u.n == floor(v.u.n));
    case K_STR: return v.k == V_STR;
    case K_BOOL: return v.k == V_BOOL;
    case K_LIST: return v.k == V_LIST;
    case K_VEC:
        if (v.k != V_LIST || (a->len && AS_LIST(v)->n != (size_t)a->len))
            return 0;
        for (size_t i = 0; i < AS_LIST(v)->n; i++)
            if (AS_LIST(v)->items[i].k != V_NUM)
                return 0;
        return 1;
    case K_REC: return v.k == V_REC;
    case K_FUNC: return v.k == V_FUNC || v.k == V_BUILTIN;
    case K_NIL: return v.k == V_NIL;
    default:
        return v.k == V_OBJ && strlen(AS_OBJ(v)->cls->name) == a->clslen &&
               memcmp(AS_OBJ(v)->cls->name, a->cls, a->clslen) == 0;
    }
}

typedef struct cctx {
    interp *I;
    const char *who;
} cctx;

static const char *num_text(double x, char *buf, size_t n)
{
    fmt_num(x, buf, n);
    return buf;
}

/* A number against an alternative's finiteness, range and choices. */
static int check_num(cctx *c, const calt *a, double x, const char *what, cpos at)
{
    char got[40];
    /* x is formatted only for a message (num_text): the shortest round-trip
     * form costs thousands of instructions, and every call passes here */
    if ((isnan(x) && !a->nan) || (isinf(x) && !a->inf))
        return err_cpos(c->I, at, ERR_VALUE, "%s: %s must be a finite number, got %s", c->who, what, num_text(x, got, sizeof got));
    if (a->kind == K_INT && isfinite(x) && fabs(x) > 9007199254740992.0)
        return err_cpos(c->I, at, ERR_VALUE, "%s: %s must be a whole number of at most 2^53, got %s", c->who, what,
                        num_text(x, got, sizeof got));
    int bad = 0;
    if (a->has_lo && (a->lo_open ? !(x > a->lo) : !(x >= a->lo)) && !isnan(x))
        bad = 1;
    if (a->has_hi && (a->hi_open ? !(x < a->hi) : !(x <= a->hi)) && !isnan(x))
        bad = 1;
    if (bad) {
        sbuf r = {{0}, 0};
        describe_range(a, &r);
        int rc = err_cpos(c->I, at, ERR_VALUE, "%s: %s must be %s, got %s", c->who, what, r.data,
                          num_text(x, got, sizeof got));
        return rc;
    }
    if (a->nchoice && a->kind != K_STR) {
        for (int i = 0; i < a->nchoice; i++)
            if (a->nchoices[i] == x)
                return 0;
        sbuf d = {{0}, 0};
        describe_alt(a, &d);
        int rc = err_cpos(c->I, at, ERR_VALUE, "%s: %s must be %s, got %s", c->who, what, d.data,
                          num_text(x, got, sizeof got));
        return rc;
    }
    return 0;
}

static int deep_finite(cctx *c, const calt *a, value v, const char *what, cpos at, int depth, int rows);

static int check_alt(cctx *c, const calt *a, value v, const char *what, cpos at)
{
    char w[300];
    switch (a->kind) {
    case K_NUM:
    case K_INT:
        return check_num(c, a, v.u.n, what, at);
    case K_STR:
        if (a->nchoice) {
            for (int i = 0; i < a->nchoice; i++)
                if (strcmp(a->schoices[i], AS_STR(v)->s) == 0)
                    return 0;
            sbuf d = {{0}, 0};
            describe_alt(a, &d);
            const char *s = interp_suggest_name(AS_STR(v)->s, a->schoices, (size_t)a->nchoice);
            int rc = err_cpos(c->I, at, ERR_VALUE, "%s: %s must be %s, got \"%s\"%s%s%s", c->who, what,
                              d.data, AS_STR(v)->s, s ? " (did you mean \"" : "", s ? s : "",
                              s ? "\"?)" : "");
            return rc;
        }
        return 0;
    case K_VEC:
        for (size_t i = 0; i < AS_LIST(v)->n; i++) {
            snprintf(w, sizeof w, "%s item %zu", what, i + 1);
            if (check_num(c, a, AS_LIST(v)->items[i].u.n, w, item_pos(at, i)))
                return -1;
            double x = AS_LIST(v)->items[i].u.n;
            if (a->whole && x != floor(x)) {
                char got[40];
                fmt_num(x, got, sizeof got);
                return err_cpos(c->I, item_pos(at, i), ERR_VALUE, "%s: %s must be a whole number, got %s", c->who, w,
                                got);
            }
        }
        return 0;
    case K_LIST:
        return a->inf && a->nan ? 0 : deep_finite(c, a, v, what, at, 0, 1);
    case K_REC: {
        if (a->nkeys < 0)
            return 0;
        vrec *r = AS_REC(v);
        int opts = strcmp(what, "argument 'options'") == 0;
        for (size_t i = 0; i < r->n; i++) {
            const ckey *k = NULL;
            for (int j = 0; j < a->nkeys; j++)
                if (a->keys[j].name == r->keys[i])
                    k = &a->keys[j];
            if (!k) {
                const char *cands[64];
                for (int j = 0; j < a->nkeys; j++)
                    cands[j] = a->keys[j].name;
                const char *s = interp_suggest_name(r->keys[i], cands, (size_t)a->nkeys);
                char sug[128] = "";
                if (s)
                    snprintf(sug, sizeof sug, " (did you mean '%s'?)", s);
                cpos kp = key_pos(c->I, at, r->keys[i], 1);
                if (opts)
                    return err_cpos(c->I, kp, ERR_VALUE, "%s: unknown option '%s'%s", c->who, r->keys[i], sug);
                return err_cpos(c->I, kp, ERR_VALUE, "%s: %s has no key '%s'%s", c->who, what, r->keys[i], sug);
            }
            if (opts)
                snprintf(w, sizeof w, "option '%s'", r->keys[i]);
            else
                snprintf(w, sizeof w, "%s, key '%s'", what, r->keys[i]);
            if (contract_check_value(c->I, k->type, r->vals[i], c->who, w, key_pos(c->I, at, r->keys[i], 0)))
                return -1;
        }
        for (int j = 0; j < a->nkeys; j++)
            if (a->keys[j].required && !val_rec_get(r, a->keys[j].name)) {
                if (opts)
                    return err_cpos(c->I, at, ERR_VALUE, "%s: missing option '%s'", c->who, a->keys[j].name);
                return err_cpos(c->I, at, ERR_VALUE, "%s: %s is missing key '%s'", c->who, what, a->keys[j].name);
            }
        return 0;
    }
    default:
        return 0;
    }
}

/* Numbers anywhere inside a list (not inside objects) must be finite. */
static int deep_finite(cctx *c, const calt *a, value v, const char *what, cpos at, int depth, int rows)
{
    if (depth > 8 || v.k != V_LIST)
        return 0;
    vlist *l = AS_LIST(v);
    int nested = 0;
    for (size_t i = 0; i < l->n && !nested; i++)
        nested = l->items[i].k == V_LIST;
    char w[300];
    for (size_t i = 0; i < l->n; i++) {
        value x = l->items[i];
        cpos ip = item_pos(at, i);
        if (x.k == V_NUM && ((isnan(x.u.n) && !a->nan) || (isinf(x.u.n) && !a->inf))) {
            if (depth == 1 && rows)
                snprintf(w, sizeof w, "%s, column %zu", what, i + 1);
            else
                snprintf(w, sizeof w, "%s %s %zu", what, nested && depth == 0 ? "row" : "item", i + 1);
            char got[16];
            fmt_num(x.u.n, got, sizeof got);
            return err_cpos(c->I, ip, ERR_VALUE, "%s: %s must be a finite number, got %s", c->who, w, got);
        }
        if (x.k == V_LIST) {
            snprintf(w, sizeof w, "%s %s %zu", what, depth == 0 ? "row" : "item", i + 1);
            if (deep_finite(c, a, x, w, ip, depth + 1, depth == 0))
                return -1;
        }
    }
    return 0;
}

int contract_check_value(interp *I, const ctype *t, value v, const char *who, const char *what, cpos at)
{
    if (!t)
        return 0;
    cctx c = {I, who};
    for (int i = 0; i < t->n; i++)
        if (base_matches(&t->alt[i], v))
            return check_alt(&c, &t->alt[i], v, what, at);
    /* no alternative takes it: say what was wanted */
    sbuf d = {{0}, 0};
    describe_type(t, &d);
    char got[64];
    snprintf(got, sizeof got, "%s", val_type_name(v));
    for (int i = 0; i < t->n; i++) {
        const calt *a = &t->alt[i];
        if (a->kind == K_INT && v.k == V_NUM) {
            fmt_num(v.u.n, got, sizeof got);
            break;
        }
        if (a->kind == K_VEC && v.k == V_LIST) {
            vlist *l = AS_LIST(v);
            size_t j;
            for (j = 0; j < l->n && l->items[j].k == V_NUM; j++)
                ;
            if (j < l->n)
                snprintf(got, sizeof got, "a list whose item %zu is %s", j + 1, val_type_name(l->items[j]));
            else
                snprintf(got, sizeof got, "%zu item%s", l->n, l->n == 1 ? "" : "s");
            break;
        }
    }
    int rc = err_cpos(I, at, ERR_TYPE, "%s: %s must be %s, got %s", who, what, d.data, got);
    return rc;
}

/* ---- argument matching ------------------------------------------------------------------- */

static cpos arg_pos(interp *I, const node *const *anodes, int i, int named)
{
    if (!anodes || !anodes[i])
        return pos_of(NULL);
    if (named) {
        cpos p = contract_name_pos(I, anodes[i]);
        if (p.src >= 0)
            return p;
    }
    return pos_of(anodes[i]);
}

int contract_match(interp *I, const char *fname, const char *const *pnames, const int *required, int np,
                   int variadic, const char *most, const char *const *anames, const node *const *anodes, int na,
                   const node *call, int *slot)
{
    int have[MAX_ARGS] = {0};
    int npos = 0;
    for (int i = 0; i < na; i++) {
        if (anames[i]) {
            int j;
            for (j = 0; j < np; j++)
                if (strcmp(pnames[j], anames[i]) == 0)
                    break;
            if (j == np) {
                const char *s = interp_suggest_name(anames[i], pnames, (size_t)np);
                cpos p = arg_pos(I, anodes, i, 1);
                if (!p.n && p.src < 0)
                    p.n = call;
                return err_cpos(I, p, ERR_TYPE, "%s has no parameter '%s'%s%s%s", fname, anames[i],
                                s ? " (did you mean '" : "", s ? s : "", s ? "'?)" : "");
            }
            if (have[j]) {
                cpos p = arg_pos(I, anodes, i, 1);
                if (!p.n && p.src < 0)
                    p.n = call;
                return err_cpos(I, p, ERR_TYPE, "%s: argument '%s' given twice", fname, anames[i]);
            }
            have[j] = 1;
            slot[i] = j;
        } else if (variadic) {
            slot[i] = -1;
        } else {
            if (npos >= np) {
                int given = 0;
                for (int k = 0; k < na; k++)
                    given += anames[k] == NULL;
                cpos p = arg_pos(I, anodes, i, 0);
                if (!p.n)
                    p.n = call;
                return err_cpos(I, p, ERR_TYPE, "%s takes %s%d argument%s, but %d were given", fname, most, np,
                                np == 1 ? "" : "s", given);
            }
            if (have[npos]) {
                cpos p = arg_pos(I, anodes, i, 0);
                if (!p.n)
                    p.n = call;
                return err_cpos(I, p, ERR_TYPE, "%s: argument '%s' given twice", fname, pnames[npos]);
            }
            have[npos] = 1;
            slot[i] = npos++;
        }
    }
    for (int j = 0; j < np; j++)
        if (!have[j] && required[j])
            return err_at(I, call, ERR_TYPE, "%s: missing argument '%s'", fname, pnames[j]);
    return 0;
}

/* ---- constants ---------------------------------------------------------------------------- */

int contract_is_constant(const node *n)
{
    if (!n)
        return 1;
    switch (n->kind) {
    case N_NUM:
    case N_STR:
    case N_BOOL:
    case N_NIL:
        return 1;
    case N_LIST:
    case N_RECORD:
    case N_TABLE:
    case N_ROW:
    case N_UNARY:
    case N_BINARY:
        for (int i = 0; i < n->nkids; i++)
            if (!contract_is_constant(n->kids[i]))
                return 0;
        return 1;
    default:
        return 0;
    }
}

/* ---- helpers for readers ------------------------------------------------------------------ */

static const node *arg_node_of(interp *I, value v)
{
    const bcall *c = I->bcall;
    if (!c || v.k < V_STR)
        return NULL;
    for (int i = 0; i < c->n; i++)
        if (c->args[i].k == v.k && c->args[i].u.h == v.u.h)
            return c->nodes[i];
    return NULL;
}

int err_item(interp *I, value container, size_t index, err_kind k, const char *fmt, ...)
{
    char msg[900];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const node *n = arg_node_of(I, container);
    cpos at = item_pos(pos_of(n), index);
    return err_cpos(I, at, k, "%s", msg);
}

static int err_node_v(interp *I, const node *n, err_kind k, const char *fmt, va_list ap)
{
    char msg[900];
    vsnprintf(msg, sizeof msg, fmt, ap);
    return err_at(I, n, k, "%s", msg);
}

int err_value(interp *I, value v, err_kind k, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = err_node_v(I, arg_node_of(I, v), k, fmt, ap);
    va_end(ap);
    return rc;
}

int err_arg(interp *I, int slot, err_kind k, const char *fmt, ...)
{
    const bcall *c = I->bcall;
    va_list ap;
    va_start(ap, fmt);
    int rc = err_node_v(I, c && slot >= 0 && slot < c->n ? c->nodes[slot] : NULL, k, fmt, ap);
    va_end(ap);
    return rc;
}

int contract_check_opts(interp *I, value opts, const char *type, const char *who)
{
    if (opts.k == V_NIL)
        return 0;
    const ctype *t = contract_type(I, type);
    if (!t)
        return -1;
    return contract_check_value(I, t, opts, who, "argument 'options'", pos_of(arg_node_of(I, opts)));
}
