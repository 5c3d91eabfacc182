/* parse_impl.h — what parser.c and parse_error.c share: the parser's state,
 * its token window (tokens come from the lexer as the parser reaches them)
 * and the token access the productions use, inline. Private to the parser:
 * parser.h is its interface. */
#ifndef FRAC_PARSE_IMPL_H
#define FRAC_PARSE_IMPL_H

#include <stddef.h>

#include "lexer.h"
#include "parser.h"

/* A token kept by value, with its number in the script (tokens are numbered
 * from 0), for what must outlive the window: the construct an error at the
 * end of the input names. */
typedef struct tokmark {
    token t;
    size_t at;
} tokmark;

#define NO_TOKEN ((size_t)-1)

/* Tokens come from the lexer as the parser reaches them, into a window that
 * holds the next token and those after it the parser has looked at; tokens
 * before the next one are dropped when the window moves on (PARSE_WINDOW
 * tokens at first; it doubles while a lookahead needs more). So a token
 * pointer (peek, ahead) is good only until the parser moves: what a
 * production keeps for later (where it started, its opening bracket) it keeps
 * by value, a token or a tokmark. */
#ifndef PARSE_WINDOW
#define PARSE_WINDOW 2048
#endif
#define MAX_OPEN 64

typedef struct parser {
    interp *I;
    lexer lx;
    token *buf;     /* the window: token number base is buf[0] */
    token *cur;     /* the next token, in buf */
    token *end;     /* past the last token lexed */
    size_t cap;     /* tokens buf holds */
    size_t base;
    token first;    /* the script's first token (the top block's position) */
    token eof;      /* the rest of the input when the window could not move */
    int skip_nl;    /* newlines are insignificant here */
    int table_mode; /* parsing an entry of a table row */
    int closing;    /* the error being reported is a missing closer */
    tokmark construct; /* innermost 'if', 'fn' or 'for' being parsed (at NO_TOKEN: none) */
    int failed;
    int depth;      /* nesting levels entered (PARSE_MAX_NESTING) */
    const struct oprow *row[2][T_COUNT]; /* ops[] indexed by fix and token (op_index) */
    struct pending *items; /* the open lists' items (nodevec), reused for every list */
    size_t nitems, cap_items;
} parser;

/* ---- token access ---------------------------------------------------------- */

token *parse_fill(parser *p, size_t k); /* parser.c */

/* The k-th token after the next one (0: the next one), lexing on as needed;
 * k never reaches past T_EOF (the parser stops there). */
static inline token *ahead(parser *p, size_t k)
{
    if (k < (size_t)(p->end - p->cur))
        return p->cur + k;
    return parse_fill(p, k);
}

/* Past the next token (never past T_EOF). */
static inline void advance(parser *p)
{
    if (++p->cur == p->end)
        parse_fill(p, 0);
}

/* +1 for the tokens that open a bracket or block, -1 for those that close one */
static const signed char nesting[T_COUNT] = {
    [T_LPAREN] = 1, [T_LBRACKET] = 1, [T_LBRACE] = 1, [T_DO] = 1,
    [T_RPAREN] = -1, [T_RBRACKET] = -1, [T_RBRACE] = -1, [T_END] = -1,
};

static inline int is_opener(tok_type k) { return nesting[k] > 0; }

static inline size_t tok_number(const parser *p, const token *t) { return p->base + (size_t)(t - p->buf); }

static inline tokmark mark(const parser *p, const token *t) { return (tokmark){*t, tok_number(p, t)}; }


static inline token *peek_raw(parser *p) { return p->cur; }

static inline token *peek(parser *p)
{
    if (p->skip_nl)
        while (p->cur->type == T_NEWLINE)
            advance(p);
    return p->cur;
}

token *parse_peek2_slow(parser *p); /* parser.c */

static inline token *peek2(parser *p) /* the token after peek(), skipping newlines if skip_nl */
{
    token *t = p->cur;
    if (t + 1 < p->end && t->type != T_NEWLINE && t->type != T_EOF && t[1].type != T_NEWLINE)
        return t + 1;
    return parse_peek2_slow(p);
}


/* The next token, by value (the window may move on past it), and past it. */
static inline token next(parser *p)
{
    token t = *peek(p);
    if (t.type != T_EOF)
        advance(p);
    return t;
}

/* next, with the token's number */
static inline tokmark next_mark(parser *p)
{
    tokmark m = mark(p, peek(p));
    next(p);
    return m;
}

static inline int check(parser *p, tok_type t) { return peek(p)->type == t; }

static inline int match(parser *p, tok_type t)
{
    if (check(p, t)) {
        next(p);
        return 1;
    }
    return 0;
}

static inline void skip_newlines(parser *p)
{
    while (peek_raw(p)->type == T_NEWLINE || peek_raw(p)->type == T_SEMI)
        advance(p);
}

/* The innermost bracket or 'do' still open at the end of the input (closers
 * pop whatever is open, so a mismatch is reported elsewhere): 1 and *out, or
 * 0 if none. Only an error at the end of the input asks, so the text is lexed
 * again from its start rather than the parser tracking every token. */
/* parse_error.c: syntax errors (the innermost construct still open at the
 * end of the input named), a token described for a message, and the
 * nesting limit. */
int parse_syntax_error(parser *p, const token *t, const char *fmt, const char *a);
const char *parse_tok_desc(const token *t, char *buf, size_t n);
int parse_too_deep(parser *p);
int parse_expected(parser *p, tok_type t, const char *what);
int parse_expected_close(parser *p, tok_type t, const token *open);

static inline int enter_level(parser *p)
{
    if (++p->depth <= PARSE_MAX_NESTING)
        return 0;
    return parse_too_deep(p);
}

static inline int expect(parser *p, tok_type t, const char *what)
{
    if (peek(p)->type == t) {
        next(p);
        return 0;
    }
    return parse_expected(p, t, what);
}

static inline int expect_close(parser *p, tok_type t, const token *open)
{
    if (peek(p)->type == t) {
        next(p);
        return 0;
    }
    return parse_expected_close(p, t, open);
}

#endif
