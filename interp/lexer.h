/* lexer.h — turns script text into tokens.
 *
 * The whole source is tokenised up front into an array (the parser needs a
 * little lookahead for lambdas and table rows). Newlines are tokens: they end
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

/* Tokenise text (NUL-terminated). Returns 0, or -1 if out of memory (out is
 * then empty: nothing to free). The list always ends with T_EOF; lexical
 * errors are T_ERROR tokens. */
int lex_all(const char *text, int src, int first_line, token_list *out);
void lex_free(token_list *tl);
const char *lex_name(tok_type t); /* human name for messages: "')'", "number" */

#endif
