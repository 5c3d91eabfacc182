/* parse_error.c — the parser's error reports: a syntax error with the
 * construct it is inside, a token described for a message, a missing token
 * or closer, and the nesting limit (PARSE_MAX_NESTING). */
#include <stdio.h>
#include <string.h>

#include "parse_impl.h"

static int innermost_open(const parser *p, tokmark *out)
{
    lexer L;
    lex_init(&L, p->lx.text, p->lx.src, p->lx.first_line);
    tokmark stack[MAX_OPEN];
    size_t n = 0, deeper = 0, num = 0;
    token batch[256];
    int got;
    while ((got = lex_next(&L, batch, (int)(sizeof batch / sizeof batch[0]))) > 0) {
        for (int i = 0; i < got; i++, num++) {
            int d = nesting[batch[i].type];
            if (d > 0) {
                if (n < MAX_OPEN)
                    stack[n++] = (tokmark){batch[i], num};
                else
                    deeper++;
            } else if (d < 0) {
                if (deeper)
                    deeper--;
                else if (n)
                    n--;
            }
        }
    }
    if (got < 0 || !n) /* out of memory (a long number literal): no note */
        return 0;
    *out = stack[n - 1];
    return 1;
}

static void note_opened_here(parser *p, const token *open)
{
    err_state *e = &p->I->err;
    tok_type k = open->type;
    int bracket = is_opener(k);
    snprintf(e->note, sizeof e->note, "%s %s here", lex_name(k), bracket ? "opened" : "started");
    e->note_src = open->src;
    e->note_line = open->line;
    e->note_col = open->col;
}

int parse_syntax_error(parser *p, const token *t, const char *fmt, const char *a)
{
    if (p->failed)
        return -1;
    p->failed = 1;
    if (t->type == T_ERROR) {
        err_pos(p->I, t->src, t->line, t->col, ERR_SYNTAX, "%s", t->err);
        /* a '\' ending the input asks for the line it joins (REPL) */
        if (t->start[0] == '\\' && t->start[1] == 0)
            p->I->err.incomplete = 1;
        return -1;
    }
    err_pos(p->I, t->src, t->line, t->col, ERR_SYNTAX, fmt, a);
    if (t->type == T_EOF) {
        p->I->err.incomplete = 1;
        /* input that ends inside a construct names where it opened (an
         * expected closer says so itself, see expect_close) */
        tokmark opened;
        const tokmark *open = !p->closing && innermost_open(p, &opened) ? &opened : NULL;
        const tokmark *c = p->closing || p->construct.at == NO_TOKEN ? NULL : &p->construct;
        if (c && (!open || c->at > open->at)) {
            err_state *e = &p->I->err;
            size_t l = strlen(e->msg);
            snprintf(e->msg + l, sizeof e->msg - l, " (%s at line %d is not finished)", lex_name(c->t.type),
                     c->t.line);
            note_opened_here(p, &c->t);
        } else if (open) {
            err_state *e = &p->I->err;
            size_t l = strlen(e->msg);
            snprintf(e->msg + l, sizeof e->msg - l, " (%s opened at line %d is not closed)",
                     lex_name(open->t.type), open->t.line);
            note_opened_here(p, &open->t);
        }
    }
    return -1;
}

const char *parse_tok_desc(const token *t, char *buf, size_t n)
{
    if (t->type == T_IDENT || t->type == T_NUMBER || t->type == T_STRING)
        snprintf(buf, n, "'%.*s'", t->len > 40 ? 40 : t->len, t->start);
    else
        snprintf(buf, n, "%s", lex_name(t->type));
    return buf;
}

/* Enter one nesting level; past PARSE_MAX_NESTING, fail at the token that
 * went too deep. Every recursive production passes here (parse_subexpr,
 * that is every operand of an operator, and the body of 'for' and of a
 * named 'fn'),
 * so the recursion of every walk over the tree is bounded. At the end of
 * the input the usual "expected …, found end of input" follows instead (the
 * REPL asks for more). Callers that succeed must leave with p->depth--. */


int parse_too_deep(parser *p)
{
    token *t = peek(p);
    if (t->type == T_EOF)
        return 0;
    p->depth--;
    if (!p->failed) {
        p->failed = 1;
        err_pos(p->I, t->src, t->line, t->col, ERR_SYNTAX,
                "nested too deeply: more than %d levels of brackets, blocks or operators",
                PARSE_MAX_NESTING);
    }
    return -1;
}

/* Expect token type t; `what` describes the context for the message. The
 * test is inline, the message out of line. */


int parse_expected(parser *p, tok_type t, const char *what)
{
    token *k = peek(p);
    char buf[64], msg[256];
    snprintf(msg, sizeof msg, "expected %s %s, found %%s", lex_name(t), what);
    return parse_syntax_error(p, k, msg, parse_tok_desc(k, buf, sizeof buf));
}

/* Expect a closing bracket; on failure note where it was opened. */


int parse_expected_close(parser *p, tok_type t, const token *open)
{
    token *k = peek(p);
    char buf[64], msg[256];
    snprintf(msg, sizeof msg, "expected %s to close %s opened at line %d, found %%s", lex_name(t),
             lex_name(open->type), open->line);
    p->closing = 1;
    parse_syntax_error(p, k, msg, parse_tok_desc(k, buf, sizeof buf));
    note_opened_here(p, open);
    return -1;
}

