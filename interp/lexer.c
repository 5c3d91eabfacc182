/* lexer.c — the scanner. */
#include "lexer.h"
#include "rt_alloc.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Character classes, one table lookup per byte (as Lua's lctype.c): digits,
 * letters and '_' (a name), and the bytes that start white space or a
 * comment. Bytes >= 0x80 are in no class, as isalpha/isdigit have them in
 * the C locale. */
enum { C_DIGIT = 1, C_ALPHA = 2, C_NAME = C_DIGIT | C_ALPHA, C_SKIP = 4 };
#define D C_DIGIT
#define A C_ALPHA
#define S C_SKIP
static const unsigned char cls[256] = {
    0, 0, 0, 0, 0, 0, 0, 0, 0, S, 0, 0, 0, S, 0, 0, /* '\t' '\r' */
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    S, 0, 0, S, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, /* ' ' '#' */
    D, D, D, D, D, D, D, D, D, D, 0, 0, 0, 0, 0, 0,
    0, A, A, A, A, A, A, A, A, A, A, A, A, A, A, A,
    A, A, A, A, A, A, A, A, A, A, A, 0, S, 0, 0, A, /* '\\' '_' */
    0, A, A, A, A, A, A, A, A, A, A, A, A, A, A, A,
    A, A, A, A, A, A, A, A, A, A, A, 0, 0, 0, 0, 0,
};
#undef D
#undef A
#undef S

static int is_digit(char c) { return cls[(unsigned char)c] & C_DIGIT; }
static int is_alpha(char c) { return (cls[(unsigned char)c] & C_NAME) == C_ALPHA && c != '_'; }

/* A keyword's token type, or T_IDENT: by length, then by the first byte. */
static tok_type keyword(const char *s, int len)
{
#define KW(w, t)                                                                                         \
    if (memcmp(s, w, sizeof w - 1) == 0)                                                                 \
        return t;
    switch (len) {
    case 2:
        switch (s[0]) {
        case 'a': KW("as", T_AS) break;
        case 'd': KW("do", T_DO) break;
        case 'f': KW("fn", T_FN) break;
        case 'i': KW("if", T_IF) KW("in", T_IN) break;
        case 'o': KW("or", T_OR) break;
        }
        break;
    case 3:
        switch (s[0]) {
        case 'a': KW("and", T_AND) break;
        case 'e': KW("end", T_END) break;
        case 'f': KW("for", T_FOR) break;
        case 'l': KW("let", T_LET) break;
        case 'n': KW("nil", T_NIL) KW("not", T_NOT) break;
        }
        break;
    case 4:
        switch (s[0]) {
        case 'e': KW("else", T_ELSE) KW("elif", T_ELIF) break;
        case 't': KW("then", T_THEN) KW("true", T_TRUE) break;
        }
        break;
    case 5:
        KW("param", T_PARAM)
        KW("false", T_FALSE)
        break;
    case 6:
        KW("import", T_IMPORT)
        break;
    }
#undef KW
    return T_IDENT;
}

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
 * --fail-alloc); lex_all's caller reports the failure. Doubles the array;
 * -1 if refused (the tokens so far stay in tl, for lex_free). */
static int grow(token_list *tl)
{
    size_t nc = tl->cap ? tl->cap * 2 : 1024;
    token *nt = rt_realloc(tl->toks, nc * sizeof *nt);
    if (!nt)
        return -1;
    tl->toks = nt;
    tl->cap = nc;
    return 0;
}

void lex_free(token_list *tl)
{
    rt_free(tl->toks);
    tl->toks = NULL;
    tl->n = tl->cap = 0;
}

/* 10^0 … 10^22: the powers of ten a double holds exactly. */
static const double pow10_exact[] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
};

/* Parse a number literal: digits, optional fraction, optional exponent;
 * also leading-dot fractions like .5. Returns length consumed.
 *
 * Most literals are read without strtod: when the significant digits form
 * an integer m < 2^53 and the decimal exponent e is within ±22, m and 10^|e|
 * are both exact doubles, so the one IEEE multiplication or division m·10^e
 * (m/10^-e) is the correctly rounded value, the same double strtod gives
 * (Clinger's fast path, "How to read floating point numbers accurately",
 * PLDI 1990). Anything else goes to strtod, with every digit (a literal of
 * 128 characters or more is copied to the heap). -1: out of memory. */
static int scan_number(const char *p, double *out)
{
    const char *s = p;
    uint64_t m = 0;
    int nd = 0;   /* significant digits (from the first non-zero one) */
    int frac = 0; /* digits after the point */
    for (;; p++) {
        if (is_digit(*p)) {
            if (nd || *p != '0') {
                if (++nd <= 19)
                    m = m * 10 + (uint64_t)(*p - '0');
            }
        } else if (*p != '_') {
            break;
        }
    }
    if (*p == '.' && is_digit(p[1])) {
        p++;
        for (;; p++) {
            if (is_digit(*p)) {
                frac++;
                if (nd || *p != '0') {
                    if (++nd <= 19)
                        m = m * 10 + (uint64_t)(*p - '0');
                }
            } else if (*p != '_') {
                break;
            }
        }
    } else if (*p == '.' && p > s && !is_alpha(p[1]) && p[1] != '.') {
        p++; /* "1." is 1.0, but not "1.foo" or "1.." */
    }
    int exp = 0, eneg = 0;
    if ((*p == 'e' || *p == 'E') &&
        (is_digit(p[1]) || ((p[1] == '+' || p[1] == '-') && is_digit(p[2])))) {
        eneg = p[1] == '-';
        p += is_digit(p[1]) ? 1 : 2;
        for (; is_digit(*p); p++)
            if (exp < 100000)
                exp = exp * 10 + (*p - '0');
    }
    int e10 = (eneg ? -exp : exp) - frac;
#if FLT_EVAL_METHOD == 0 /* double arithmetic rounds to double (no x87 excess precision) */
    if (nd <= 19 && m <= (UINT64_C(1) << 53) && e10 >= -22 && e10 <= 22 && p - s < 128) {
        double v = (double)m;
        *out = e10 >= 0 ? v * pow10_exact[e10] : v / pow10_exact[-e10];
        return (int)(p - s);
    }
#endif
    char small[128], *buf = small; /* strtod reads every digit: a long literal gets a buffer of its own */
    if ((size_t)(p - s) >= sizeof small && !(buf = rt_malloc((size_t)(p - s) + 1)))
        return -1;
    size_t n = 0;
    for (const char *q = s; q < p; q++)
        if (*q != '_')
            buf[n++] = *q;
    buf[n] = 0;
    *out = strtod(buf, NULL);
    if (buf != small)
        rt_free(buf);
    return (int)(p - s);
}

void lex_init(lexer *L, const char *text, int src, int first_line)
{
    L->text = text;
    L->p = text;
    L->line_start = text;
    L->src = src;
    L->first_line = first_line;
    L->line = first_line;
    L->space = 1;
    L->done = 0;
    /* A shebang line is a comment. */
    if (text[0] == '#' && text[1] == '!')
        while (*L->p && *L->p != '\n')
            L->p++;
}

int lex_next(lexer *L, token *toks, int max)
{
    if (L->done)
        return 0;
    /* the state is read into locals and written back on the way out, so the
     * loop keeps it in registers (-fno-strict-aliasing: a store into a
     * token may alias anything in memory for the compiler) */
    const char *text = L->text, *p = L->p, *line_start = L->line_start;
    int line = L->line, space = L->space, first_line = L->first_line;
    unsigned short src = (unsigned short)L->src;
    int n = 0;
    for (;;) {
        if (n == max) {
            L->p = p;
            L->line_start = line_start;
            L->line = line;
            L->space = space;
            return n;
        }
        /* white space and comments */
        while (cls[(unsigned char)*p] & C_SKIP) {
            if (*p == '#') {
                while (*p && *p != '\n')
                    p++;
            } else if (*p == '\\') { /* explicit line continuation */
                if (p[1] == '\n')
                    p += 2;
                else if (p[1] == '\r' && p[2] == '\n')
                    p += 3;
                else
                    break;
                line++;
                line_start = p;
            } else {
                p++;
            }
            space = 1;
        }
        token *t = &toks[n++];
        t->src = src;
        t->line = line;
        t->col = (int)(p - line_start) + 1;
        t->start = p;
        t->space_before = (unsigned char)space;
        space = 0;
        char c = *p;
        unsigned char k = cls[(unsigned char)c];
        if (k & C_ALPHA) {
            const char *b = p;
            while (cls[(unsigned char)*++p] & C_NAME)
                ;
            t->len = (int)(p - b);
            t->type = (unsigned char)keyword(b, t->len);
        } else if (k & C_DIGIT || (c == '.' && is_digit(p[1]))) {
            t->type = T_NUMBER;
            t->len = scan_number(p, &t->num);
            if (t->len < 0)
                return -1;
            p += t->len;
            if (cls[(unsigned char)*p] & C_ALPHA) {
                t->type = T_ERROR;
                t->err = "invalid number literal";
                while (cls[(unsigned char)*p] & C_NAME)
                    p++;
                t->len = (int)(p - t->start);
            }
        } else if (c == '\n') {
            t->type = T_NEWLINE;
            t->len = 1;
            p++;
            line++;
            line_start = p;
            space = 1;
        } else if (c == 0) {
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
                t->line = l;
                t->col = (int)(q - ls) + 1;
            }
            t->type = T_EOF;
            t->len = 0;
            L->done = 1;
            return n;
        } else if (c == '"') {
            p++;
            while (*p && *p != '"' && *p != '\n') {
                if (*p == '\\' && p[1] && p[1] != '\n')
                    p++;
                p++;
            }
            if (*p != '"') {
                t->type = T_ERROR;
                t->err = "unterminated string";
            } else {
                p++;
                t->type = T_STRING;
            }
            t->len = (int)(p - t->start);
        } else {
            int two = 0;
            tok_type ty = T_ERROR;
            const char *err = NULL;
            switch (c) {
            case '(': ty = T_LPAREN; break;
            case ')': ty = T_RPAREN; break;
            case '[': ty = T_LBRACKET; break;
            case ']': ty = T_RBRACKET; break;
            case '{': ty = T_LBRACE; break;
            case '}': ty = T_RBRACE; break;
            case ',': ty = T_COMMA; break;
            case ':': ty = T_COLON; break;
            case ';': ty = T_SEMI; break;
            case '.': ty = T_DOT; break;
            case '+': ty = T_PLUS; break;
            case '-': ty = T_MINUS; break;
            case '*': ty = T_STAR; break;
            case '/': ty = T_SLASH; break;
            case '%': ty = T_PERCENT; break;
            case '^': ty = T_CARET; break;
            case '=':
                if (p[1] == '=') { ty = T_EQ; two = 1; }
                else if (p[1] == '>') { ty = T_ARROW; two = 1; }
                else ty = T_ASSIGN;
                break;
            case '!':
                if (p[1] == '=') { ty = T_NE; two = 1; }
                else err = "unexpected '!' (use 'not' for negation)";
                break;
            case '<':
                if (p[1] == '=') { ty = T_LE; two = 1; } else ty = T_LT;
                break;
            case '>':
                if (p[1] == '=') { ty = T_GE; two = 1; } else ty = T_GT;
                break;
            case '|':
                if (p[1] == '>') { ty = T_PIPE; two = 1; }
                else err = "unexpected '|' (the pipe is '|>')";
                break;
            case '\\':
                /* the REPL asks for the next line (the parser marks this
                 * error incomplete); a script has none to join */
                err = p[1] == 0 ? "'\\' at the end of the input has no next line to join"
                                : "unexpected '\\' (only at the end of a line, to join it with the next)";
                break;
            default:
                err = "unexpected character";
                break;
            }
            t->type = (unsigned char)ty;
            if (ty == T_ERROR)
                t->err = err;
            if (ty == T_ERROR && (unsigned char)c >= 0x80) {
                /* one whole UTF-8 character, so the message and caret are right */
                p++;
                while (((unsigned char)*p & 0xC0) == 0x80)
                    p++;
                t->len = (int)(p - t->start);
            } else {
                t->len = two ? 2 : 1;
                p += t->len;
            }
        }
    }
}

int lex_all(const char *text, int src, int first_line, token_list *out)
{
    lexer L;
    lex_init(&L, text, src, first_line);
    out->toks = NULL;
    out->n = out->cap = 0;
    for (;;) {
        if (out->n == out->cap && grow(out))
            return -1;
        int k = lex_next(&L, out->toks + out->n, (int)(out->cap - out->n));
        if (k < 0)
            return -1;
        out->n += (size_t)k;
        if (L.done)
            return 0;
    }
}
