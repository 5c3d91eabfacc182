/* ast.h — the syntax tree.
 *
 * One node type for everything; fields are used per kind as noted. Nodes
 * live in an arena owned by the interpreter state for the whole session,
 * because closures keep pointing at their bodies.
 */
#ifndef AST_H
#define AST_H

#include <stddef.h>

typedef enum node_kind {
    /* expressions */
    N_NUM,     /* num */
    N_STR,     /* str, slen: the decoded string */
    N_BOOL,    /* num: 0 or 1 */
    N_NIL,
    N_NAME,    /* str: interned name */
    N_LIST,    /* kids: items */
    N_COMP,    /* list comprehension [a for name in b if c]: kids[0]=a, kids[1]=b, kids[2]=c or NULL, str=name */
    N_RECORD,  /* names[i]: key, kids[i]: value */
    N_TABLE,   /* kids: rows (N_ROW) */
    N_ROW,     /* kids: entries */
    N_UNARY,   /* op: '-', '+', 'n' (not); kids[0] */
    N_BINARY,  /* op: token type; kids[0], kids[1] */
    N_AND, N_OR, /* kids[0], kids[1] */
    N_CALL,    /* kids[0]: callee; kids[1..]: args; names[i] for arg i (NULL = positional) */
    N_INDEX,   /* kids[0][kids[1]] */
    N_FIELD,   /* kids[0].str */
    N_IF,      /* kids[0] cond, kids[1] then, kids[2] else (or NULL) */
    N_BLOCK,   /* kids: statements; value is the last expression statement's */
    N_LAMBDA,  /* names: params; kids[0..nparams-1]: defaults (NULL = required); body; str: name for messages */
    /* statements */
    N_LET,     /* str: name; kids[0]: value */
    N_ASSIGN,  /* str: name; kids[0]: value */
    N_PARAM,   /* str: name; kids[0]: default value; doc: trailing comment */
    N_FNDEF,   /* str: name; kids[0]: N_LAMBDA */
    N_IMPORT,  /* str: module path (decoded); names[0]: alias or NULL */
    N_FOR,     /* str: variable; kids[0]: iterable; kids[1]: body (N_BLOCK) */
    N_EXPR,    /* kids[0] */
} node_kind;

typedef struct node {
    node_kind kind;
    unsigned short src; /* source index (state.h: at most 65535 sources) */
    unsigned short op;  /* N_UNARY, N_BINARY */
    int line, col;
    int nkids;
    int nparams;       /* N_LAMBDA */
    /* Set by resolve.c (0 = not resolved: look the name up by name). For
     * N_NAME and N_ASSIGN: the name is slot - 1 of the scope `hops` parents
     * up from the one the node is evaluated in; for N_LET, N_PARAM and
     * N_FNDEF (and N_IMPORT's alias): the slot it defines in its own scope. The evaluator checks
     * the slot still holds that name before using it (see eval.c). */
    int slot, hops;
    /* The pointers and the kinds' own fields: a node is 80 bytes (one in
     * each of a check's ~135,000 nodes for 10,000 lines is memory touched). */
    union {
        double num;    /* N_NUM, N_BOOL */
        size_t slen;   /* N_STR, N_IMPORT */
    };
    const char *str;
    struct node **kids;
    const char **names;
    union {
        struct node *body; /* N_LAMBDA */
        const char *doc;   /* N_PARAM: trailing comment text (may be NULL) */
        const int *slots;  /* N_IMPORT without alias (resolve.c): slots[0] names of the module,
                            * slots[1 + i] the slot + 1 its name i takes in the importer's scope */
    };
    /* Set by compile.c: the compiled form of a lambda's body or of a block's
     * statements, made the first time it runs (NULL until then). */
    const struct cnode *code;
} node;

_Static_assert(sizeof(node) % 16 == 0, "the parser puts a node's children right after it");

#endif
