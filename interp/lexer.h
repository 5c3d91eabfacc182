/* lexer.h — turns script text into tokens.
 *
 * lex_next hands out the tokens a batch at a time, as the parser asks for
 * them: it keeps only a window of tokens around the one it is at (parser.c),
 * not the whole script's, which for a large script was megabytes of memory
 * touched once. lex_all tokenises a whole text into one array, for code that
 * scans every token (resolve.c, the lexer's tests). Newlines are tokens: they end
 * statements and separate the rows of a table literal; the parser skips them
 * inside brackets. Each token remembers whether white space came before it,
 * which is how a table row tells `1 -2` (two entries) from `1 - 2` (one).
 */
#ifndef LEXER_H
#define LEXER_H

#include <stddef.h>

typedef enum tok_type {
    T_EOF, T_NEWLINE, T_NUMBER, T_STRING, T_IDENT,
    /* keywords */
    T_LET, T_PARAM, T_FN, T_IMPORT, T_AS, T_IF, T_THEN, T_ELSE, T_ELIF, T_DO, T_END,
    T_FOR, T_IN, T_AND, T_OR, T_NOT, T_TRUE, T_FALSE, T_NIL,
    /* punctuation */
    T_LPAREN, T_RPAREN, T_LBRACKET, T_RBRACKET, T_LBRACE, T_RBRACE,
    T_COMMA, T_COLON, T_SEMI, T_DOT, T_ASSIGN, T_ARROW, T_PIPE,
    T_PLUS, T_MINUS, T_STAR, T_SLASH, T_PERCENT, T_CARET,
    T_EQ, T_NE, T_LT, T_LE, T_GT, T_GE,
    T_ERROR, /* lexical error: text in err */
    T_COUNT
} tok_type;

typedef struct token {
    const char *start; /* into the source text */
    union {
        double num;      /* T_NUMBER */
        const char *err; /* T_ERROR: static message */
    };
    int line, col;     /* 1-based; col counts bytes */
    int len;
    unsigned short src; /* source index (see state.h) */
    unsigned char type; /* tok_type */
    unsigned char space_before; /* white space (or start of line) precedes it */
} token;

typedef struct token_list {
    token *toks;
    size_t n, cap;
} token_list;

/* The scanner's place in a text (NUL-terminated). */
typedef struct lexer {
    const char *text, *p, *line_start;
    int src, first_line, line, space, done;
} lexer;

void lex_init(lexer *L, const char *text, int src, int first_line);
/* Up to max (>= 1) more tokens into toks: returns how many, the last being
 * T_EOF when the text ended (then done is set, and later calls return 0), or
 * -1 if out of memory (a number literal of 128 characters or more needs a
 * buffer). Lexical errors are T_ERROR tokens. */
int lex_next(lexer *L, token *toks, int max);
/* Tokenise the whole text. Returns 0, or -1 if out of memory. The list
 * always ends with T_EOF. */
int lex_all(const char *text, int src, int first_line, token_list *out);
void lex_free(token_list *tl);
const char *lex_name(tok_type t); /* human name for messages: "')'", "number" */

#endif
