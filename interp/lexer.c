/* lexer.c — the scanner. */
#include "lexer.h"
#include "rt_alloc.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

static const struct {
    const char *word;
    tok_type type;
    int len; /* strlen(word) */
} keywords[] = {
    {"let", T_LET, 3},   {"param", T_PARAM, 5}, {"fn", T_FN, 2},     {"import", T_IMPORT, 6}, {"as", T_AS, 2},
    {"if", T_IF, 2},     {"then", T_THEN, 4},   {"else", T_ELSE, 4}, {"elif", T_ELIF, 4},     {"do", T_DO, 2},
    {"end", T_END, 3},   {"for", T_FOR, 3},     {"in", T_IN, 2},     {"and", T_AND, 3},       {"or", T_OR, 2},
    {"not", T_NOT, 3},   {"true", T_TRUE, 4},   {"false", T_FALSE, 5}, {"nil", T_NIL, 3},
};

const char *lex_name(tok_type t)
{
    static const char *names[T_COUNT] = {
        [T_EOF] = "end of input", [T_NEWLINE] = "end of line", [T_NUMBER] = "number",
        [T_STRING] = "string", [T_IDENT] = "name", [T_LET] = "'let'", [T_PARAM] = "'param'",
        [T_FN] = "'fn'", [T_IMPORT] = "'import'", [T_AS] = "'as'", [T_IF] = "'if'",
        [T_THEN] = "'then'", [T_ELSE] = "'else'", [T_ELIF] = "'elif'", [T_DO] = "'do'",
        [T_END] = "'end'", [T_FOR] = "'for'", [T_IN] = "'in'", [T_AND] = "'and'", [T_OR] = "'or'",
        [T_NOT] = "'not'", [T_TRUE] = "'true'", [T_FALSE] = "'false'", [T_NIL] = "'nil'",
        [T_LPAREN] = "'('", [T_RPAREN] = "')'", [T_LBRACKET] = "'['", [T_RBRACKET] = "']'",
        [T_LBRACE] = "'{'", [T_RBRACE] = "'}'", [T_COMMA] = "','", [T_COLON] = "':'",
        [T_SEMI] = "';'", [T_DOT] = "'.'", [T_ASSIGN] = "'='", [T_ARROW] = "'=>'",
        [T_PIPE] = "'|>'", [T_PLUS] = "'+'", [T_MINUS] = "'-'", [T_STAR] = "'*'",
        [T_SLASH] = "'/'", [T_PERCENT] = "'%'", [T_CARET] = "'^'", [T_EQ] = "'=='",
        [T_NE] = "'!='", [T_LT] = "'<'", [T_LE] = "'<='", [T_GT] = "'>'", [T_GE] = "'>='",
        [T_ERROR] = "invalid token",
    };
    return t < T_COUNT && names[t] ? names[t] : "token";
}

/* The lexer has no interpreter state: it allocates with rt_realloc, which
 * goes through the same allocation hook as mem_alloc (counted, and failed by
 * --fail-alloc); lex_all's caller reports the failure. */
static int push(token_list *tl, token t)
{
    if (tl->n == tl->cap) {
        size_t nc = tl->cap ? tl->cap * 2 : 1024;
        token *nt = rt_realloc(tl->toks, nc * sizeof *nt);
        if (!nt)
            return -1;
        tl->toks = nt;
        tl->cap = nc;
    }
    tl->toks[tl->n++] = t;
    return 0;
}

void lex_free(token_list *tl)
{
    rt_free(tl->toks);
    tl->toks = NULL;
    tl->n = tl->cap = 0;
}

/* Parse a number literal: digits, optional fraction, optional exponent;
 * also leading-dot fractions like .5. Returns length consumed. */
static int scan_number(const char *p, double *out)
{
    const char *s = p;
    while (isdigit((unsigned char)*p) || *p == '_')
        p++;
    if (*p == '.' && isdigit((unsigned char)p[1])) {
        p++;
        while (isdigit((unsigned char)*p) || *p == '_')
            p++;
    } else if (*p == '.' && p > s && !isalpha((unsigned char)p[1]) && p[1] != '.') {
        p++; /* "1." is 1.0, but not "1.foo" or "1.." */
    }
    if ((*p == 'e' || *p == 'E') &&
        (isdigit((unsigned char)p[1]) ||
         ((p[1] == '+' || p[1] == '-') && isdigit((unsigned char)p[2])))) {
        p += 2;
        while (isdigit((unsigned char)*p))
            p++;
    }
    char buf[128];
    size_t n = 0;
    for (const char *q = s; q < p && n + 1 < sizeof buf; q++)
        if (*q != '_')
            buf[n++] = *q;
    buf[n] = 0;
    *out = strtod(buf, NULL);
    return (int)(p - s);
}

int lex_all(const char *text, int src, int first_line, token_list *out)
{
    const char *p = text;
    int line = first_line;
    const char *line_start = text;
    int space = 1;
    out->toks = NULL;
    out->n = out->cap = 0;
    /* A shebang line is a comment. */
    if (p[0] == '#' && p[1] == '!')
        while (*p && *p != '\n')
            p++;
    for (;;) {
        token t;
        memset(&t, 0, sizeof t);
        /* white space and comments */
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '#' ||
               (*p == '\\' && (p[1] == '\n' || (p[1] == '\r' && p[2] == '\n')))) {
            if (*p == '#') {
                while (*p && *p != '\n')
                    p++;
            } else if (*p == '\\') { /* explicit line continuation */
                p += p[1] == '\r' ? 3 : 2;
                line++;
                line_start = p;
            } else {
                p++;
            }
            space = 1;
        }
        t.src = (unsigned short)src;
        t.line = line;
        t.col = (int)(p - line_start) + 1;
        t.start = p;
        t.space_before = space;
        space = 0;
        char c = *p;
        if (c == 0) {
            /* Report "end of input" at the end of the last line with any
             * text (a comment counts), not on an empty line after it. */
            const char *q = p;
            int l = line;
            while (q > text && (q[-1] == '\n' || q[-1] == ' ' || q[-1] == '\t' || q[-1] == '\r')) {
                if (q[-1] == '\n')
                    l--;
                q--;
            }
            if (q > text && l >= first_line) {
                const char *ls = q;
                while (ls > text && ls[-1] != '\n')
                    ls--;
                t.line = l;
                t.col = (int)(q - ls) + 1;
            }
            t.type = T_EOF;
            if (push(out, t))
                return -1;
            return 0;
        }
        if (c == '\n') {
            t.type = T_NEWLINE;
            t.len = 1;
            p++;
            line++;
            line_start = p;
            space = 1;
        } else if (isdigit((unsigned char)c) || (c == '.' && isdigit((unsigned char)p[1]))) {
            t.type = T_NUMBER;
            t.len = scan_number(p, &t.num);
            p += t.len;
            if (isalpha((unsigned char)*p) || *p == '_') {
                t.type = T_ERROR;
                t.err = "invalid number literal";
                while (isalnum((unsigned char)*p) || *p == '_')
                    p++;
                t.len = (int)(p - t.start);
            }
        } else if (isalpha((unsigned char)c) || c == '_') {
            while (isalnum((unsigned char)*p) || *p == '_')
                p++;
            t.len = (int)(p - t.start);
            t.type = T_IDENT;
            for (size_t i = 0; i < sizeof keywords / sizeof keywords[0]; i++)
                if (keywords[i].len == t.len && memcmp(keywords[i].word, t.start, (size_t)t.len) == 0) {
                    t.type = keywords[i].type;
                    break;
                }
        } else if (c == '"') {
            p++;
            while (*p && *p != '"' && *p != '\n') {
                if (*p == '\\' && p[1] && p[1] != '\n')
                    p++;
                p++;
            }
            if (*p != '"') {
                t.type = T_ERROR;
                t.err = "unterminated string";
            } else {
                p++;
                t.type = T_STRING;
            }
            t.len = (int)(p - t.start);
        } else {
            int two = 0;
            t.type = T_ERROR;
            switch (c) {
            case '(': t.type = T_LPAREN; break;
            case ')': t.type = T_RPAREN; break;
            case '[': t.type = T_LBRACKET; break;
            case ']': t.type = T_RBRACKET; break;
            case '{': t.type = T_LBRACE; break;
            case '}': t.type = T_RBRACE; break;
            case ',': t.type = T_COMMA; break;
            case ':': t.type = T_COLON; break;
            case ';': t.type = T_SEMI; break;
            case '.': t.type = T_DOT; break;
            case '+': t.type = T_PLUS; break;
            case '-': t.type = T_MINUS; break;
            case '*': t.type = T_STAR; break;
            case '/': t.type = T_SLASH; break;
            case '%': t.type = T_PERCENT; break;
            case '^': t.type = T_CARET; break;
            case '=':
                if (p[1] == '=') { t.type = T_EQ; two = 1; }
                else if (p[1] == '>') { t.type = T_ARROW; two = 1; }
                else t.type = T_ASSIGN;
                break;
            case '!':
                if (p[1] == '=') { t.type = T_NE; two = 1; }
                else t.err = "unexpected '!' (use 'not' for negation)";
                break;
            case '<':
                if (p[1] == '=') { t.type = T_LE; two = 1; } else t.type = T_LT;
                break;
            case '>':
                if (p[1] == '=') { t.type = T_GE; two = 1; } else t.type = T_GT;
                break;
            case '|':
                if (p[1] == '>') { t.type = T_PIPE; two = 1; }
                else t.err = "unexpected '|' (the pipe is '|>')";
                break;
            case '\\':
                /* the REPL asks for the next line (the parser marks this
                 * error incomplete); a script has none to join */
                t.err = p[1] == 0 ? "'\\' at the end of the input has no next line to join"
                                  : "unexpected '\\' (only at the end of a line, to join it with the next)";
                break;
            default:
                t.err = "unexpected character";
                break;
            }
            if (t.type == T_ERROR && (unsigned char)c >= 0x80) {
                /* one whole UTF-8 character, so the message and caret are right */
                p++;
                while (((unsigned char)*p & 0xC0) == 0x80)
                    p++;
                t.len = (int)(p - t.start);
            } else {
                t.len = two ? 2 : 1;
                p += t.len;
            }
        }
        if (push(out, t))
            return -1;
    }
}
