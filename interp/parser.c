/* parser.c — recursive descent, one function per production (each starts
 * with its grammar rule, as in Lua's lparser.c); expressions by precedence
 * climbing over one operator table, ops[] (docs/language.md shows it).
 *
 * Newlines end statements and separate table rows; they are skipped inside
 * (), [] and record braces. In a table row, entries are separated by white
 * space: a '+' or '-' with space before it and none after starts a new entry
 * (`0.5 -0.5` is two entries, `0.5 - 0.5` is one), and a call's '(' must
 * follow the name directly.
 */
#include "parser.h"

#include <stdlib.h>
#include <string.h>

#include "lexer.h"
#include "parse_impl.h"


/* The window could not grow, or the lexer ran out of memory: the parser
 * sees the end of the input and reports nothing more (failed); parse_source
 * says where (the script's start) and why. */
static token *window_failed(parser *p)
{
    if (!p->failed)
        mem_engine_error(p->I, NULL, "out of memory"); /* the hook's reason, if no error came first */
    p->failed = 1;
    p->eof = (token){.start = "", .line = p->lx.line, .col = 1, .src = (unsigned short)p->lx.src, .type = T_EOF};
    p->cur = &p->eof;
    p->end = p->cur + 1;
    p->lx.done = 1;
    return p->cur;
}

/* The slow path of ahead and advance: moves the window to start at the next
 * token (a new block, the old one freed, so under ASan a token pointer kept
 * across a move is caught), doubling it while k needs more room, and lexes
 * on until the k-th token after the next one is in it. */
token *parse_fill(parser *p, size_t k)
{
    /* before the first window all three pointers are NULL: no arithmetic on
     * them (NULL + 0 is undefined, and clang's UBSan says so) */
    while (k >= (p->buf ? (size_t)(p->end - p->cur) : 0)) {
        if (p->lx.done) {
            if (p->cur == p->end) /* not reached: the parser stops at T_EOF */
                p->cur--;
            return p->end - 1;
        }
        if (!p->buf || p->end == p->buf + p->cap) {
            size_t keep = p->buf ? (size_t)(p->end - p->cur) : 0;
            size_t cap = p->cap ? p->cap : PARSE_WINDOW;
            while (keep + k + 1 > cap / 2)
                cap *= 2;
            token *nb = mem_alloc(p->I, cap * sizeof *nb);
            if (!nb)
                return window_failed(p);
            if (keep)
                memcpy(nb, p->cur, keep * sizeof *nb);
            if (p->buf)
                p->base += (size_t)(p->cur - p->buf);
            mem_free(p->I, p->buf);
            p->buf = p->cur = nb;
            p->end = nb + keep;
            p->cap = cap;
        }
        token *from = p->end;
        int got = lex_next(&p->lx, from, (int)(p->buf + p->cap - from));
        if (got < 0)
            return window_failed(p);
        p->end += got;
    }
    return p->cur + k;
}

token *parse_peek2_slow(parser *p)
{
    size_t k = 0;
    if (p->skip_nl)
        while (ahead(p, k)->type == T_NEWLINE)
            k++;
    if (ahead(p, k)->type == T_EOF)
        return ahead(p, k);
    k++;
    if (p->skip_nl)
        while (ahead(p, k)->type == T_NEWLINE)
            k++;
    return ahead(p, k);
}

/* ---- node construction --------------------------------------------------- */

/* A node, and room for `extra` bytes after it in the same piece of the arena
 * (a node's size is a multiple of 16, so what follows is aligned). */
static inline node *mk_extra(parser *p, node_kind k, const token *at, size_t extra)
{
    node *n = mem_arena_raw(p->I, sizeof(node) + extra);
    if (!n) {
        p->failed = 1;
        return NULL;
    }
    /* zeroed in constant pieces of at most 64 bytes, which compilers store
     * inline (a single memset of the whole node becomes a `rep stos`) */
    char *q = (char *)n;
    size_t i = 0;
    for (; i + 64 <= sizeof *n; i += 64)
        memset(q + i, 0, 64);
    memset(q + i, 0, sizeof *n - i);
    n->kind = k;
    n->src = at->src;
    n->line = at->line;
    n->col = at->col;
    return n;
}

static node *mk(parser *p, node_kind k, const token *at) { return mk_extra(p, k, at, 0); }

/* A node with one or two children, their array right after it. */
static node *mk1(parser *p, node_kind k, const token *at, node *a)
{
    node *n = mk_extra(p, k, at, sizeof(node *));
    if (!n)
        return NULL;
    n->kids = (node **)(n + 1);
    n->nkids = 1;
    n->kids[0] = a;
    return n;
}

static node *mk2(parser *p, node_kind k, const token *at, node *a, node *b)
{
    node *n = mk_extra(p, k, at, 2 * sizeof(node *));
    if (!n)
        return NULL;
    n->kids = (node **)(n + 1);
    n->nkids = 2;
    n->kids[0] = a;
    n->kids[1] = b;
    return n;
}

/* The items of a list being parsed (arguments, parameters, fields, rows,
 * entries, statements) wait on one stack in the parser, and only the finished
 * list is copied into the arena at its exact size (nv_close), so no array is
 * left in the syntax tree half empty or outgrown. Lists nest last in, first
 * out: an inner list is closed before its outer list takes its next item. */
typedef struct pending {
    node *n;
    const char *name;
} pending;

typedef struct nodevec {
    size_t base; /* its first item in p->items */
    int n;
} nodevec;

static inline nodevec nv_open(const parser *p) { return (nodevec){p->nitems, 0}; }

static int nv_grow(parser *p);

static inline int nv_push(parser *p, nodevec *nv, node *n, const char *name)
{
    if (p->nitems == p->cap_items && nv_grow(p))
        return -1;
    p->items[p->nitems++] = (pending){n, name};
    nv->n++;
    return 0;
}

static inline const pending *nv_item(const parser *p, const nodevec *nv, int i) { return &p->items[nv->base + (size_t)i]; }

/* Double the stack (through the allocation hook; freed by parse_source). */
static int nv_grow(parser *p)
{
    size_t nc = p->cap_items ? p->cap_items * 2 : 256;
    pending *a = mem_realloc(p->I, p->items, nc * sizeof *a);
    if (!a) {
        p->failed = 1;
        return -1;
    }
    p->items = a;
    p->cap_items = nc;
    return 0;
}

/* Move a list's items into the arena after `lead` leading slots (a call's
 * callee), as kids and, when names is not NULL, their names in the same
 * piece; pops them. An empty list with no lead has NULL arrays. */
static int nv_close(parser *p, nodevec *nv, int lead, node ***kids, const char ***names)
{
    size_t k = (size_t)lead + (size_t)nv->n;
    *kids = NULL;
    if (names)
        *names = NULL;
    if (k) {
        node **a = mem_arena_raw(p->I, k * (names ? sizeof(node *) + sizeof(char *) : sizeof(node *)));
        if (!a) {
            p->failed = 1;
            return -1;
        }
        const pending *it = nv->n ? &p->items[nv->base] : NULL; /* no items yet: NULL, not NULL + 0 */
        if (names) {
            const char **b = (const char **)(a + k);
            for (int i = 0; i < nv->n; i++) {
                a[lead + i] = it[i].n;
                b[lead + i] = it[i].name;
            }
            *names = b;
        } else {
            for (int i = 0; i < nv->n; i++)
                a[lead + i] = it[i].n;
        }
        *kids = a;
    }
    p->nitems = nv->base;
    return 0;
}

static const char *tok_name(parser *p, const token *t)
{
    const char *s = interp_intern(p->I, t->start, (size_t)t->len);
    if (!s)
        p->failed = 1;
    return s;
}

/* Decode a string literal's escapes into the arena. */
static node *string_node(parser *p, const token *t)
{
    node *n = mk(p, N_STR, t);
    if (!n)
        return NULL;
    char *s = mem_arena_raw(p->I, (size_t)t->len + 1);
    if (!s)
        return NULL;
    size_t k = 0;
    for (int i = 1; i < t->len - 1; i++) {
        char c = t->start[i];
        if (c == '\\') {
            char e = t->start[++i];
            switch (e) {
            case 'n': c = '\n'; break;
            case 't': c = '\t'; break;
            case 'r': c = '\r'; break;
            case '0': c = '\0'; break;
            case '\\': c = '\\'; break;
            case '"': c = '"'; break;
            case '{': c = '{'; break;
            default: {
                token bad = *t;
                bad.col += i - 1;
                bad.type = T_STRING;
                parse_syntax_error(p, &bad, "unknown escape sequence '\\%s' in string",
                             (char[2]){e, 0});
                return NULL;
            }
            }
        }
        s[k++] = c;
    }
    s[k] = 0;
    n->str = s;
    n->slen = k;
    return n;
}

/* ---- operators: one Pratt table ----------------------------------------------
 *
 * Every operator has one row: the token, whether it is written before its
 * operand (PREFIX) or between two (INFIX), its binding level (higher binds
 * tighter) and its associativity, which says at which level its right
 * operand is parsed:
 *   LEFT   at level+1           `a - b - c` is `(a - b) - c`
 *   RIGHT  at level itself      `2^3^2` is `2^(3^2)`; a prefix operator nests
 *                               in itself (`not not x`, `- -x`)
 *   NONE   at level+1, and the same level may not follow (`a < b < c`)
 * A prefix operator may start an operand only where its level is allowed, so
 * `a * not b` is an error while `2^-1` is not (unary minus shares `^`'s
 * level, so `-2^2` is `-(2^2)`). `kind` is the node an operator builds;
 * N_CALL marks the pipe, `x |> f(a)` built as the call `f(x, a)`. An operator
 * marked `leads` may begin the next line (a pipe chain written one step per
 * line). After an infix operator the operand may continue on the next line.
 * docs/language.md shows this table. */
enum { PREFIX, INFIX };
enum { LEFT, RIGHT, NONE };

typedef struct oprow {
    tok_type tok;
    unsigned char fix, prec, assoc, leads;
    node_kind kind;
    int op; /* the node's op: the token type, or '-', '+', 'n' for N_UNARY */
} oprow;

static const oprow ops[] = {
    {T_PIPE, INFIX, 1, LEFT, 1, N_CALL, T_PIPE},
    {T_OR, INFIX, 2, LEFT, 0, N_OR, T_OR},
    {T_AND, INFIX, 3, LEFT, 0, N_AND, T_AND},
    {T_NOT, PREFIX, 4, RIGHT, 0, N_UNARY, 'n'},
    {T_EQ, INFIX, 5, NONE, 0, N_BINARY, T_EQ},
    {T_NE, INFIX, 5, NONE, 0, N_BINARY, T_NE},
    {T_LT, INFIX, 5, NONE, 0, N_BINARY, T_LT},
    {T_LE, INFIX, 5, NONE, 0, N_BINARY, T_LE},
    {T_GT, INFIX, 5, NONE, 0, N_BINARY, T_GT},
    {T_GE, INFIX, 5, NONE, 0, N_BINARY, T_GE},
    {T_PLUS, INFIX, 6, LEFT, 0, N_BINARY, T_PLUS},
    {T_MINUS, INFIX, 6, LEFT, 0, N_BINARY, T_MINUS},
    {T_STAR, INFIX, 7, LEFT, 0, N_BINARY, T_STAR},
    {T_SLASH, INFIX, 7, LEFT, 0, N_BINARY, T_SLASH},
    {T_PERCENT, INFIX, 7, LEFT, 0, N_BINARY, T_PERCENT},
    {T_MINUS, PREFIX, 8, RIGHT, 0, N_UNARY, '-'},
    {T_PLUS, PREFIX, 8, RIGHT, 0, N_UNARY, '+'},
    {T_CARET, INFIX, 8, RIGHT, 0, N_BINARY, T_CARET},
};

/* the only non-associative operators are the comparisons */
#define CHAIN_ERROR "comparisons cannot be chained; use 'and'"

/* ops[] by fix and token, so finding an operator is one load, not a search
 * of the table at every operand (filled once per parse, from ops[]). */
static void op_index(parser *p)
{
    for (size_t i = 0; i < sizeof ops / sizeof ops[0]; i++)
        p->row[ops[i].fix][ops[i].tok] = &ops[i];
}

static const oprow *op_row(const parser *p, tok_type t, int fix) { return p->row[fix][t]; }

/* The level of the right operand of row r. */
static int operand_level(const oprow *r) { return r->assoc == RIGHT ? r->prec : r->prec + 1; }

/* The infix operator at the next token, or NULL. In a table row a '+' or '-' with space
 * before it and none after starts a new entry instead (`1 -2`). */
static const oprow *infix_in_row(parser *p, const oprow *r)
{
    const token *after = ahead(p, 1);
    return !after->space_before && after->type != T_NEWLINE ? NULL : r;
}

static inline const oprow *infix_at(parser *p)
{
    const token *t = peek(p);
    const oprow *r = op_row(p, t->type, INFIX);
    if (r && p->table_mode && (t->type == T_PLUS || t->type == T_MINUS) && t->space_before)
        return infix_in_row(p, r);
    return r;
}

/* Outside a table row, newlines before an operator that may lead a line are
 * skipped (`x\n|> f`). */
static void skip_to_leading_op(parser *p)
{
    if (p->table_mode || peek_raw(p)->type != T_NEWLINE)
        return;
    size_t i = 1;
    while (ahead(p, i)->type == T_NEWLINE)
        i++;
    const oprow *r = op_row(p, ahead(p, i)->type, INFIX);
    if (r && r->leads)
        while (i--)
            advance(p);
}


/* ---- expressions ----------------------------------------------------------- */

static node *parse_expr(parser *p);
static node *parse_block_until(parser *p, const token *open);
static node *parse_lambda_rest(parser *p, const tokmark *at, const char *name);

/* The parser's line mode: inside brackets newlines are skipped; a block
 * (do … end, a function body) reads them as statement ends; neither is in a
 * table's rows. enter_mode sets a mode and returns the old one, which
 * restore_mode puts back on the way out. */
typedef struct parse_mode {
    int skip_nl, table_mode;
} parse_mode;

static parse_mode enter_mode(parser *p, int skip_nl)
{
    parse_mode m = {p->skip_nl, p->table_mode};
    p->skip_nl = skip_nl;
    p->table_mode = 0;
    return m;
}

static void restore_mode(parser *p, parse_mode m)
{
    p->skip_nl = m.skip_nl;
    p->table_mode = m.table_mode;
}

/* enclosed -> expr CLOSE   (after the opener; newlines skipped inside) */
static node *parse_enclosed(parser *p, tok_type close, const token *open)
{
    parse_mode m = enter_mode(p, 1);
    node *e = parse_expr(p);
    if (e)
        expect_close(p, close, open);
    restore_mode(p, m);
    return p->failed ? NULL : e;
}

/* One comma-separated list, the shape every bracketed construct shares:
 *   list -> [item {',' item} [',']] CLOSE
 * (the opener is consumed by the caller). Inside it newlines are white space
 * and table rows are off; item parses one entry and returns 0 to go on, or
 * non-zero to stop (after an error, or when the list ends early: a
 * comprehension). */
typedef int (*list_item)(parser *p, void *ctx);

static int parse_comma_list(parser *p, const token *open, tok_type close, list_item item, void *ctx)
{
    parse_mode m = enter_mode(p, 1);
    while (!check(p, close) && !check(p, T_EOF))
        if (item(p, ctx) || p->failed || !match(p, T_COMMA))
            break;
    if (!p->failed)
        expect_close(p, close, open);
    restore_mode(p, m);
    return p->failed ? -1 : 0;
}

/* arg -> [NAME ':'] expr   (no positional argument after a named one) */
typedef struct args_ctx {
    nodevec *args;
    int named_seen;
} args_ctx;

static int parse_arg(parser *p, void *ctx)
{
    args_ctx *c = ctx;
    const char *name = NULL;
    if (check(p, T_IDENT) && peek2(p)->type == T_COLON) {
        token t = next(p);
        name = tok_name(p, &t);
        next(p);
        c->named_seen = 1;
    } else if (c->named_seen) {
        parse_syntax_error(p, peek(p), "%s", "positional argument after a named argument");
        return -1;
    }
    node *a = parse_expr(p);
    return !a || nv_push(p, c->args, a, name) ? -1 : 0;
}

/* args -> '(' [arg {',' arg}] ')' */
static int parse_args(parser *p, nodevec *args)
{
    token open = next(p); /* '(' */
    args_ctx c = {args, 0};
    return parse_comma_list(p, &open, T_RPAREN, parse_arg, &c);
}

static node *make_call(parser *p, node *callee, nodevec *args, const token *at)
{
    node *c = mk(p, N_CALL, at);
    if (!c)
        return NULL;
    /* report calls at the callee's name, which is what the reader looks for */
    if (callee->kind == N_NAME || callee->kind == N_FIELD) {
        c->src = callee->src;
        c->line = callee->line;
        c->col = callee->col;
    }
    c->nkids = args->n + 1;
    if (nv_close(p, args, 1, &c->kids, &c->names))
        return NULL;
    c->kids[0] = callee;
    c->names[0] = NULL;
    return c;
}

static node *parse_brace(parser *p);

/* postfix -> primary { '(' args ')' | '[' expr ']' | '.' NAME | NAME '{' … '}' } */
static node *parse_postfix(parser *p, node *e)
{
    for (;;) {
        const token *at = peek_raw(p);
        if (p->skip_nl && at->type == T_NEWLINE)
            at = peek(p);
        if (p->table_mode && at->space_before)
            return e;
        tok_type k = at->type;
        if (k != T_LPAREN && k != T_LBRACKET && k != T_DOT &&
            !(k == T_LBRACE && (e->kind == N_NAME || e->kind == N_FIELD)))
            return e;
        token t = *at; /* kept: the window may move on while the suffix is parsed */
        if (t.type == T_LPAREN) {
            nodevec args = nv_open(p);
            if (parse_args(p, &args))
                return NULL;
            e = make_call(p, e, &args, &t);
        } else if (t.type == T_LBRACKET) {
            next(p);
            node *ix = parse_enclosed(p, T_RBRACKET, &t);
            if (!ix)
                return NULL;
            e = mk2(p, N_INDEX, &t, e, ix);
        } else if (t.type == T_DOT) {
            next(p);
            token name = *peek(p);
            if (name.type != T_IDENT) {
                char buf[64];
                parse_syntax_error(p, &name, "expected a field name after '.', found %s",
                             parse_tok_desc(&name, buf, sizeof buf));
                return NULL;
            }
            next(p);
            node *n = mk1(p, N_FIELD, &t, e);
            if (!n)
                return NULL;
            n->str = tok_name(p, &name);
            e = n;
        } else if (t.type == T_LBRACE && (e->kind == N_NAME || e->kind == N_FIELD)) {
            /* `ifs { rows }` is `ifs({ rows })` */
            node *arg = parse_brace(p);
            if (!arg)
                return NULL;
            nodevec args = nv_open(p);
            if (nv_push(p, &args, arg, NULL))
                return NULL;
            e = make_call(p, e, &args, &t);
        }
        if (!e)
            return NULL;
    }
}

/* params -> '(' [NAME ['=' expr] {',' NAME ['=' expr]}] ')' */
/* param -> NAME ['=' expr]   (unique names; no default-less one after a default) */
static int parse_param(parser *p, void *ctx)
{
    nodevec *params = ctx;
    token t = *peek(p);
    if (t.type != T_IDENT) {
        char buf[64];
        parse_syntax_error(p, &t, "expected a parameter name, found %s", parse_tok_desc(&t, buf, sizeof buf));
        return -1;
    }
    next(p);
    const char *name = tok_name(p, &t);
    for (int i = 0; i < params->n; i++)
        if (nv_item(p, params, i)->name == name) {
            parse_syntax_error(p, &t, "duplicate parameter '%s'", name);
            return -1;
        }
    node *def = NULL;
    if (match(p, T_ASSIGN)) {
        if (!(def = parse_expr(p)))
            return -1;
    } else if (params->n && nv_item(p, params, params->n - 1)->n) {
        parse_syntax_error(p, &t, "parameter '%s' without a default follows one with a default", name);
        return -1;
    }
    return nv_push(p, params, def, name) ? -1 : 0;
}

/* params -> '(' [param {',' param}] ')' */
static int parse_params(parser *p, nodevec *params)
{
    token open = *peek(p);
    if (expect(p, T_LPAREN, "to start the parameter list"))
        return -1;
    return parse_comma_list(p, &open, T_RPAREN, parse_param, params);
}

static node *make_lambda(parser *p, const token *at, nodevec *params, node *body, const char *name)
{
    node *l = mk(p, N_LAMBDA, at);
    if (!l)
        return NULL;
    l->nparams = params->n;
    l->nkids = params->n;
    if (nv_close(p, params, 0, &l->kids, &l->names))
        return NULL;
    l->body = body;
    l->str = name;
    return l;
}

/* lambda_body -> '=' expr | 'do' block 'end' | '=>' expr */
static node *parse_lambda_rest(parser *p, const tokmark *at, const char *name)
{
    tokmark save_c = p->construct;
    if (at->t.type == T_FN)
        p->construct = *at;
    nodevec params = nv_open(p);
    if (parse_params(p, &params))
        return NULL;
    node *body;
    token t = *peek(p);
    if (t.type == T_ASSIGN || t.type == T_ARROW) {
        next(p);
        body = parse_expr(p);
    } else if (t.type == T_DO) {
        next(p);
        body = parse_block_until(p, &t);
        if (body && expect_close(p, T_END, &t))
            return NULL;
    } else {
        char buf[64];
        parse_syntax_error(p, &t, "expected '=' or 'do' after the parameter list, found %s",
                     parse_tok_desc(&t, buf, sizeof buf));
        return NULL;
    }
    if (!body)
        return NULL;
    p->construct = save_c;
    return make_lambda(p, &at->t, &params, body, name);
}

/* Is the '(' at pos the start of `(a, b) => …`? */
static int is_paren_lambda(parser *p)
{
    size_t i = 0;
    int depth = 0;
    for (;; i++) {
        tok_type t = ahead(p, i)->type;
        if (t == T_EOF)
            return 0;
        if (t == T_LPAREN || t == T_LBRACKET || t == T_LBRACE)
            depth++;
        else if (t == T_RPAREN || t == T_RBRACKET || t == T_RBRACE) {
            if (--depth == 0)
                break;
        }
    }
    i++;
    while (ahead(p, i)->type == T_NEWLINE && p->skip_nl)
        i++;
    return ahead(p, i)->type == T_ARROW;
}

/* field -> (NAME | STRING) ':' expr   (unique keys) */
static int parse_field(parser *p, void *ctx)
{
    nodevec *fields = ctx;
    token k = *peek(p);
    const char *key;
    if (k.type == T_IDENT) {
        key = tok_name(p, &k);
    } else if (k.type == T_STRING) {
        node *s = string_node(p, &k);
        key = s ? interp_intern(p->I, s->str, s->slen) : NULL;
    } else {
        char buf[64];
        parse_syntax_error(p, &k, "expected a field name in record, found %s", parse_tok_desc(&k, buf, sizeof buf));
        return -1;
    }
    next(p);
    if (expect(p, T_COLON, "after the field name"))
        return -1;
    node *v = parse_expr(p);
    if (!v)
        return -1;
    for (int j = 0; j < fields->n; j++)
        if (nv_item(p, fields, j)->name == key) {
            parse_syntax_error(p, &k, "duplicate field '%s' in record", key);
            return -1;
        }
    return nv_push(p, fields, v, key) ? -1 : 0;
}

/* brace -> '{' '}' | '{' NAME ':' expr {',' NAME ':' expr} '}' | '{' rows '}' */
static node *parse_brace(parser *p)
{
    token open = next(p);
    parse_mode m = enter_mode(p, p->skip_nl);
    /* look past newlines to decide between record and table */
    size_t i = 0;
    while (ahead(p, i)->type == T_NEWLINE)
        i++;
    tok_type first = ahead(p, i)->type;
    int is_record = first == T_RBRACE || (first == T_IDENT && ahead(p, i + 1)->type == T_COLON) ||
                    (first == T_STRING && ahead(p, i + 1)->type == T_COLON);
    node *n;
    if (is_record) {
        n = mk(p, N_RECORD, &open);
        nodevec fields = nv_open(p);
        if (n && !parse_comma_list(p, &open, T_RBRACE, parse_field, &fields)) {
            n->nkids = fields.n;
            nv_close(p, &fields, 0, &n->kids, &n->names);
        }
    } else {
        /* table: rows separated by newlines or ';', entries by white space or ',' */
        p->skip_nl = 0;
        n = mk(p, N_TABLE, &open);
        nodevec rows = nv_open(p);
        skip_newlines(p);
        while (n && !p->failed && !check(p, T_RBRACE) && !check(p, T_EOF)) {
            node *row = mk(p, N_ROW, peek(p));
            nodevec entries = nv_open(p);
            while (row && !p->failed) {
                tok_type t = peek_raw(p)->type;
                if (t == T_NEWLINE || t == T_SEMI || t == T_RBRACE || t == T_EOF)
                    break;
                p->table_mode = 1;
                node *e = parse_expr(p);
                p->table_mode = 0;
                if (!e || nv_push(p, &entries, e, NULL))
                    break;
                match(p, T_COMMA);
            }
            if (p->failed || !row)
                break;
            row->nkids = entries.n;
            if (nv_close(p, &entries, 0, &row->kids, NULL) || nv_push(p, &rows, row, NULL))
                break;
            skip_newlines(p);
        }
        if (n && !p->failed) {
            expect_close(p, T_RBRACE, &open);
            n->nkids = rows.n;
            nv_close(p, &rows, 0, &n->kids, NULL);
        }
    }
    restore_mode(p, m);
    return p->failed ? NULL : n;
}

/* item -> expr, or for the first item: expr 'for' NAME 'in' expr ['if' expr]
 * (a comprehension, which ends the list) */
typedef struct list_ctx {
    node *n;
    nodevec items;
} list_ctx;

static int parse_list_item(parser *p, void *ctx)
{
    list_ctx *c = ctx;
    node *e = parse_expr(p);
    if (!e)
        return -1;
    if (c->items.n || !check(p, T_FOR))
        return nv_push(p, &c->items, e, NULL) ? -1 : 0;
    next(p);
    token var = *peek(p);
    if (var.type != T_IDENT) {
        char buf[64];
        parse_syntax_error(p, &var, "expected a variable name after 'for', found %s", parse_tok_desc(&var, buf, sizeof buf));
        return -1;
    }
    next(p);
    if (expect(p, T_IN, "after the loop variable"))
        return -1;
    node *it = parse_expr(p);
    node *cond = NULL;
    if (!it || (match(p, T_IF) && !(cond = parse_expr(p))))
        return -1;
    node *n = c->n;
    n->kind = N_COMP;
    n->str = tok_name(p, &var);
    n->nkids = 3;
    if (!(n->kids = mem_arena_alloc(p->I, 3 * sizeof(node *))))
        return -1;
    n->kids[0] = e;
    n->kids[1] = it;
    n->kids[2] = cond;
    return 1;
}

/* list -> '[' ']' | '[' expr {',' expr} [','] ']' | '[' expr 'for' NAME 'in' expr ['if' expr] ']' */
static node *parse_list(parser *p)
{
    token open = next(p);
    list_ctx c = {mk(p, N_LIST, &open), nv_open(p)};
    if (!c.n || parse_comma_list(p, &open, T_RBRACKET, parse_list_item, &c))
        return NULL;
    if (c.n->kind == N_LIST) {
        c.n->nkids = c.items.n;
        if (nv_close(p, &c.items, 0, &c.n->kids, NULL))
            return NULL;
    }
    return c.n;
}

/* if -> 'if' expr 'then' expr {'elif' expr 'then' expr} ['else' expr]
 * An elif chain is built by a loop (each elif is the else branch of the
 * one before), so a long chain is not nesting. */
static node *parse_if(parser *p)
{
    tokmark at = next_mark(p);
    int save_tm = p->table_mode;
    tokmark save_c = p->construct;
    p->table_mode = 0;
    node *first = NULL, **slot = &first;
    for (;;) {
        node *n = mk(p, N_IF, &at.t);
        if (!n)
            return NULL;
        n->nkids = 3;
        n->kids = mem_arena_alloc(p->I, 3 * sizeof(node *));
        if (!n->kids)
            return NULL;
        *slot = n;
        p->construct = at; /* an unfinished 'if' / 'elif' names where it began */
        n->kids[0] = parse_expr(p);
        if (!n->kids[0] || expect(p, T_THEN, "after the condition of 'if'"))
            return NULL;
        n->kids[1] = parse_expr(p);
        if (!n->kids[1])
            return NULL;
        /* 'else' may start the next line */
        size_t k = 0;
        while (ahead(p, k)->type == T_NEWLINE)
            k++;
        tok_type t = ahead(p, k)->type;
        if (t == T_ELIF || t == T_ELSE)
            while (k--)
                advance(p);
        if (t == T_ELIF) {
            at = next_mark(p);
            slot = &n->kids[2];
            continue;
        }
        if (t == T_ELSE) {
            next(p);
            n->kids[2] = parse_expr(p);
            if (!n->kids[2])
                return NULL;
        }
        break;
    }
    p->table_mode = save_tm;
    p->construct = save_c;
    return first;
}

/* literal -> NUMBER | STRING | 'true' | 'false' | 'nil' */
static node *parse_literal(parser *p)
{
    token t = next(p);
    node *n;
    switch (t.type) {
    case T_NUMBER:
        if ((n = mk(p, N_NUM, &t)))
            n->num = t.num;
        return n;
    case T_STRING:
        return string_node(p, &t);
    case T_NIL:
        return mk(p, N_NIL, &t);
    default: /* 'true' | 'false' */
        if ((n = mk(p, N_BOOL, &t)))
            n->num = t.type == T_TRUE;
        return n;
    }
}

/* name -> NAME | NAME '=>' expr   (a one-parameter lambda; not in a table row) */
static node *parse_name(parser *p)
{
    if (peek2(p)->type == T_ARROW && !p->table_mode) {
        token t = next(p);
        next(p);
        nodevec params = nv_open(p);
        if (nv_push(p, &params, NULL, tok_name(p, &t)))
            return NULL;
        node *body = parse_expr(p);
        return body ? make_lambda(p, &t, &params, body, NULL) : NULL;
    }
    token t = next(p);
    node *n = mk(p, N_NAME, &t);
    if (n)
        n->str = tok_name(p, &t);
    return n;
}

/* paren -> params '=>' expr | '(' expr ')'   (newlines are white space inside) */
static node *parse_paren(parser *p)
{
    token t = *peek(p);
    if (is_paren_lambda(p)) {
        nodevec params = nv_open(p);
        if (parse_params(p, &params) || expect(p, T_ARROW, "after the parameter list"))
            return NULL;
        node *body = parse_expr(p);
        return body ? make_lambda(p, &t, &params, body, NULL) : NULL;
    }
    next(p);
    return parse_enclosed(p, T_RPAREN, &t);
}

/* doblock -> 'do' block 'end' */
static node *parse_do(parser *p)
{
    token t = next(p);
    parse_mode m = enter_mode(p, 0);
    node *b = parse_block_until(p, &t);
    restore_mode(p, m);
    if (b && expect_close(p, T_END, &t))
        return NULL;
    return b;
}

/* fnexpr -> 'fn' params lambda_body   (an anonymous function) */
static node *parse_fn_expr(parser *p)
{
    tokmark t = next_mark(p);
    parse_mode m = enter_mode(p, 0);
    node *l = parse_lambda_rest(p, &t, NULL);
    restore_mode(p, m);
    return l;
}

/* primary -> literal | name | paren | list | brace | if | doblock | fnexpr */
static node *parse_primary(parser *p)
{
    token *t = peek(p);
    char buf[64];
    switch (t->type) {
    case T_NUMBER:
    case T_STRING:
    case T_TRUE:
    case T_FALSE:
    case T_NIL:
        return parse_literal(p);
    case T_IDENT:
        return parse_name(p);
    case T_LPAREN:
        return parse_paren(p);
    case T_LBRACKET:
        return parse_list(p);
    case T_LBRACE:
        return parse_brace(p);
    case T_IF:
        return parse_if(p);
    case T_DO:
        return parse_do(p);
    case T_FN:
        return parse_fn_expr(p);
    default:
        parse_syntax_error(p, t, "expected an expression, found %s", parse_tok_desc(t, buf, sizeof buf));
        return NULL;
    }
}

static node *parse_subexpr(parser *p, int level);

/* pipe -> left '|>' (NAME | call | operand): the call gets left as its first
 * argument, `x |> f(a)` is `f(x, a)` and `x |> f` is `f(x)` */
static node *make_pipe(parser *p, const token *op, node *left, node *rhs)
{
    nodevec args = nv_open(p);
    if (nv_push(p, &args, left, NULL))
        return NULL;
    if (rhs->kind != N_CALL)
        return make_call(p, rhs, &args, op);
    for (int i = 1; i < rhs->nkids; i++)
        if (nv_push(p, &args, rhs->kids[i], rhs->names[i]))
            return NULL;
    return make_call(p, rhs->kids[0], &args, op);
}

/* prefixexp -> PREFIXOP subexpr(level of the operator) | primary postfix */
static node *parse_operand(parser *p, int level)
{
    const oprow *r = op_row(p, peek(p)->type, PREFIX);
    if (!r || r->prec < level) { /* `a * not b`: the primary reports 'not' */
        node *e = parse_primary(p);
        return e ? parse_postfix(p, e) : NULL;
    }
    token t = next(p);
    node *a = parse_subexpr(p, operand_level(r));
    node *n = a ? mk1(p, r->kind, &t, a) : NULL;
    if (n)
        n->op = r->op;
    return n;
}

/* subexpr(level) -> prefixexp { INFIXOP subexpr(operand level) }
 * taking only operators of at least `level` (precedence climbing). Each
 * operand is one nesting level (enter_level), so deep nesting of brackets,
 * prefix operators or '^' is refused while a long flat chain is a loop. */
static node *parse_subexpr(parser *p, int level)
{
    if (enter_level(p))
        return NULL;
    node *left = parse_operand(p, level);
    while (left) {
        skip_to_leading_op(p);
        const oprow *r = infix_at(p);
        if (!r || r->prec < level)
            break;
        token op = next(p);
        while (peek_raw(p)->type == T_NEWLINE) /* the operand may start the next line */
            advance(p);
        node *rhs = parse_subexpr(p, operand_level(r));
        if (!rhs) {
            left = NULL;
            break;
        }
        if (r->kind == N_CALL) {
            left = make_pipe(p, &op, left, rhs);
            continue;
        }
        left = mk2(p, r->kind, &op, left, rhs);
        if (!left)
            break;
        left->op = r->op;
        const oprow *again = r->assoc == NONE ? infix_at(p) : NULL;
        if (again && again->prec == r->prec) {
            parse_syntax_error(p, peek(p), "%s", CHAIN_ERROR);
            left = NULL;
        }
    }
    p->depth--;
    return left;
}

/* expr -> subexpr(1) */
static node *parse_expr(parser *p) { return parse_subexpr(p, 1); }

/* ---- statements ------------------------------------------------------------ */

static node *one_kid(parser *p, node_kind k, const token *at, node *kid, const char *str)
{
    node *n = mk1(p, k, at, kid);
    if (n)
        n->str = str;
    return n;
}

static const char *expect_name(parser *p, const char *what)
{
    token *t = peek(p);
    if (t->type != T_IDENT) {
        char buf[64], msg[128];
        snprintf(msg, sizeof msg, "expected %s, found %%s", what);
        parse_syntax_error(p, t, msg, parse_tok_desc(t, buf, sizeof buf));
        return NULL;
    }
    const char *name = tok_name(p, t); /* before next: the window may move on */
    next(p);
    return name;
}

/* Trailing comment on the line of token t (for param docs). */
static const char *trailing_comment(parser *p, const token *t)
{
    const char *s = t->start;
    while (*s && *s != '\n' && *s != '#')
        s++;
    if (*s != '#')
        return NULL;
    s++;
    while (*s == ' ')
        s++;
    const char *e = s;
    while (*e && *e != '\n')
        e++;
    char *d = mem_arena_alloc(p->I, (size_t)(e - s) + 1);
    if (d)
        memcpy(d, s, (size_t)(e - s));
    return d;
}

/* letstat -> 'let' NAME '=' expr   (a lambda takes the name) */
static node *parse_let(parser *p)
{
    token t = next(p);
    const char *name = expect_name(p, "a name after 'let'");
    if (!name || expect(p, T_ASSIGN, "after the name in 'let'"))
        return NULL;
    node *v = parse_expr(p);
    if (v && v->kind == N_LAMBDA && !v->str)
        v->str = name;
    return v ? one_kid(p, N_LET, &t, v, name) : NULL;
}

/* paramstat -> 'param' NAME '=' expr ['#' doc]   (the default is required) */
static node *parse_param_decl(parser *p)
{
    token t = next(p);
    const char *name = expect_name(p, "a name after 'param'");
    if (!name || expect(p, T_ASSIGN, "after the name in 'param' (a default value is required)"))
        return NULL;
    node *v = parse_expr(p);
    node *n = v ? one_kid(p, N_PARAM, &t, v, name) : NULL;
    if (n)
        n->doc = trailing_comment(p, &t);
    return n;
}

/* fnstat -> 'fn' NAME params lambda_body   (one nesting level) */
static node *parse_fndef(parser *p)
{
    tokmark t = next_mark(p);
    const char *name = expect_name(p, "a function name");
    if (!name || enter_level(p))
        return NULL;
    node *l = parse_lambda_rest(p, &t, name);
    p->depth--;
    return l ? one_kid(p, N_FNDEF, &t.t, l, name) : NULL;
}

/* importstat -> 'import' STRING ['as' NAME] */
static node *parse_import(parser *p)
{
    token t = next(p);
    token s = *peek(p);
    if (s.type != T_STRING) {
        char buf[64];
        parse_syntax_error(p, &s, "expected a module name in quotes after 'import', found %s",
                     parse_tok_desc(&s, buf, sizeof buf));
        return NULL;
    }
    next(p);
    node *sn = string_node(p, &s);
    if (!sn)
        return NULL;
    node *n = mk(p, N_IMPORT, &t);
    if (!n)
        return NULL;
    n->str = sn->str;
    n->slen = sn->slen;
    n->names = mem_arena_alloc(p->I, sizeof(char *));
    if (!n->names)
        return NULL;
    if (match(p, T_AS)) {
        n->names[0] = expect_name(p, "a name after 'as'");
        if (!n->names[0])
            return NULL;
    }
    return n;
}

/* forstat -> 'for' NAME 'in' expr 'do' block 'end'   (the body is one nesting level) */
static node *parse_for(parser *p)
{
    tokmark t = next_mark(p);
    tokmark save_c = p->construct;
    p->construct = t;
    const char *var = expect_name(p, "a variable name after 'for'");
    if (!var || expect(p, T_IN, "after the loop variable"))
        return NULL;
    node *it = parse_expr(p);
    if (!it)
        return NULL;
    token d = *peek(p);
    if (expect(p, T_DO, "to start the body of 'for'") || enter_level(p))
        return NULL;
    node *body = parse_block_until(p, &d);
    p->depth--;
    if (!body || expect_close(p, T_END, &d))
        return NULL;
    p->construct = save_c;
    node *n = mk2(p, N_FOR, &t.t, it, body);
    if (n)
        n->str = var;
    return n;
}

/* assignstat -> NAME '=' expr */
static node *parse_assign(parser *p)
{
    token t = next(p);
    next(p); /* '=' */
    node *v = parse_expr(p);
    return v ? one_kid(p, N_ASSIGN, &t, v, tok_name(p, &t)) : NULL;
}

/* exprstat -> expr */
static node *parse_expr_statement(parser *p)
{
    token t = *peek(p);
    node *e = parse_expr(p);
    return e ? one_kid(p, N_EXPR, &t, e, NULL) : NULL;
}

/* statement -> letstat | paramstat | fnstat | importstat | forstat | assignstat | exprstat
 * ('fn' without a name starts an expression, as does a NAME not followed by '=') */
static node *parse_statement(parser *p)
{
    switch (peek(p)->type) {
    case T_LET:
        return parse_let(p);
    case T_PARAM:
        return parse_param_decl(p);
    case T_FN:
        return peek2(p)->type == T_IDENT ? parse_fndef(p) : parse_expr_statement(p);
    case T_IMPORT:
        return parse_import(p);
    case T_FOR:
        return parse_for(p);
    case T_IDENT:
        return peek2(p)->type == T_ASSIGN ? parse_assign(p) : parse_expr_statement(p);
    default:
        return parse_expr_statement(p);
    }
}

/* block -> { statement (NEWLINE | ';') } up to 'end' (inside 'do')
 * or end of input. */
static node *parse_block_until(parser *p, const token *open)
{
    parse_mode m = enter_mode(p, 0);
    node *b = mk(p, N_BLOCK, open ? open : &p->first);
    nodevec stmts = nv_open(p);
    for (;;) {
        skip_newlines(p);
        tok_type t = peek_raw(p)->type;
        if (t == T_EOF || (open && t == T_END))
            break;
        if (!open && t == T_END) {
            parse_syntax_error(p, peek_raw(p), "%s", "'end' without a matching 'do'");
            break;
        }
        node *s = parse_statement(p);
        if (!s || nv_push(p, &stmts, s, NULL))
            break;
        token *after = peek_raw(p);
        if (after->type != T_NEWLINE && after->type != T_SEMI && after->type != T_EOF &&
            !(open && after->type == T_END)) {
            char buf[64];
            parse_syntax_error(p, after, "expected the end of the statement, found %s",
                         parse_tok_desc(after, buf, sizeof buf));
            break;
        }
    }
    restore_mode(p, m);
    if (p->failed || !b)
        return NULL;
    b->nkids = stmts.n;
    return nv_close(p, &stmts, 0, &b->kids, NULL) ? NULL : b;
}

int parse_source(interp *I, int src, node **out)
{
    parser p;
    memset(&p, 0, sizeof p);
    p.I = I;
    op_index(&p);
    *out = NULL;
    p.construct.at = NO_TOKEN;
    lex_init(&p.lx, I->srcs[src].text, src, I->srcs[src].first_line);
    node *b = NULL;
    if (parse_fill(&p, 0), !p.failed) { /* the first window */
        p.first = *p.cur;
        b = parse_block_until(&p, NULL);
    }
    mem_free(I, p.buf);
    mem_free(I, p.items);
    if (!b || p.failed) {
        err_state *e = &I->err;
        if (!e->active) {
            err_pos(I, src, 1, 1, ERR_MEMORY, "out of memory while parsing");
        } else if ((e->kind == ERR_LIMIT || e->kind == ERR_MEMORY) && e->src < 0) {
            /* the tree, the window or a name was refused (the memory limit,
             * --fail-alloc or the system): say so at the script's start */
            static const char what[] = "reading the script: ";
            size_t l = strnlen(e->msg, sizeof e->msg - sizeof what);
            memmove(e->msg + sizeof what - 1, e->msg, l);
            memcpy(e->msg, what, sizeof what - 1);
            e->msg[sizeof what - 1 + l] = 0;
            e->src = src, e->line = I->srcs[src].first_line, e->col = 1;
        }
        return -1;
    }
    *out = b;
    return 0;
}
