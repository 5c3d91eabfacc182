/* state.h — the interpreter state, passed as the first argument everywhere.
 *
 * Holds the sources (for diagnostics), the interned names, the syntax-tree
 * arena, the global scope, the limits, the one allocation hook, the current
 * error and the call stack. There are no mutable globals in interp/.
 *
 * Errors: code that detects an error calls one of the err_* functions, which
 * record the error in I->err (first error wins) and return -1; callers
 * propagate -1 up to the single catch point (the script runner or the REPL),
 * which prints it with diag_print and picks the exit code.
 */
#ifndef STATE_H
#define STATE_H

#include <signal.h>
#include <stdint.h>
#include <stdio.h>

#include "ast.h"
#include "rt_alloc.h"
#include "value.h"

/* Error classes; the X-macro gives the enum, the name and the exit code
 * together, so tests can assert on them. */
#define ERROR_KINDS(X)                                            \
    X(ERR_USAGE, "usage", 64)                                     \
    X(ERR_SYNTAX, "syntax", 65)                                   \
    X(ERR_NAME, "name", 65)                                       \
    X(ERR_TYPE, "type", 65)                                       \
    X(ERR_VALUE, "value", 65)                                     \
    X(ERR_LIMIT, "limit", 65)                                     \
    X(ERR_IO, "io", 74)                                           \
    X(ERR_MEMORY, "memory", 70)                                   \
    X(ERR_RUNTIME, "runtime", 70)                                 \
    X(ERR_INTERRUPT, "interrupted", 130)

typedef enum err_kind {
#define X(id, name, code) id,
    ERROR_KINDS(X)
#undef X
} err_kind;

const char *err_kind_name(err_kind k);
int err_kind_exit(err_kind k);

typedef struct frame {
    const char *fname;    /* function name, or "<lambda>" */
    const node *call;     /* call site */
} frame;

#define MAX_TRACE 16

typedef struct err_state {
    int active;
    err_kind kind;
    char msg[1024];
    char note[512];        /* optional extra line, e.g. "'(' opened here" */
    int src, line, col;    /* position (src < 0: none) */
    int note_src, note_line, note_col;
    int incomplete;        /* syntax error at end of input (REPL continues) */
    int ntrace;
    struct { const char *fname; int src, line, col; } trace[MAX_TRACE];
    int trace_dropped;
} err_state;

typedef struct source {
    char *name; /* as shown in diagnostics */
    char *text;
    char *dir;  /* directory for relative imports */
    int first_line; /* line number of the text's first line (REPL entries) */
    int is_module;  /* an imported module (its params are not the script's: -D skips them) */
} source;

typedef struct limits {
    size_t max_memory;   /* bytes the interpreter may allocate (--max-memory) */
    int max_depth;       /* call depth (--max-depth) */
    double max_pixels;   /* per image (--max-pixels) */
    double max_points;   /* chaos game points, samples (--max-points) */
    double max_voxels;   /* per volume (--max-voxels) */
    double max_list;     /* list length (--max-list) */
    double max_fit_seconds; /* > 0: fit()'s time budget is at most this (and fit stops after it
                             * even without time:); no flag, set by the fuzz harness; 0 = none */
} limits;

typedef struct param_override {
    const char *name; /* interned */
    const char *text; /* value text from -D */
    int used;
} param_override;

typedef struct module {
    char *key;        /* "std:NAME" or canonical path */
    int state;        /* 1 loading, 2 loaded */
    env *exports;     /* the module's top-level scope */
} module;

typedef struct builtin builtin;

/* Counts of the evaluator's slow paths, so tests can see that resolved code
 * takes the fast ones (no flag shows them; each is one increment where the
 * slow path already costs far more, except `scopes`, one per scope made). */
typedef struct interp_counts {
    long name_searches;  /* a scope searched by name: a use or definition whose slot did not
                          * hold its name (compile.h scope_lookup / scope_define), or any
                          * val_env_define into a scope that already holds names */
    long scopes;         /* scopes made (val_env_new) */
    long scope_allocs;   /* of those, not taken from the pool (a new heap object) */
    long list_grows;     /* a list's item array reallocated to a larger capacity */
    long types_compiled; /* builtin parameter types compiled from their text (contract.c) */
} interp_counts;

typedef struct interp {
    /* allocation (the hook runs on engine worker threads too: atomics) */
    _Atomic size_t mem_used;
    limits lim;
    long fail_alloc_at; /* testing: fail the N-th allocation (0 = never) */
    _Atomic long alloc_count;
    _Atomic int mem_fail;        /* why the hook last refused (mem_fail_kind in state.c) */
    _Atomic size_t mem_fail_size;
    _Atomic long mem_fail_n;
    rt_alloc_hook hook;

    /* sources, names, syntax trees */
    source *srcs;
    int nsrc, cap_src;
    char **intern_tab;
    size_t intern_n, intern_cap;
    struct arena_block *arena;

    /* scopes and values */
    heap *heap_all;
    env *env_pool;       /* freed small scopes kept for reuse (value.c) */
    int env_pool_n;
    env *globals;
    module *mods;
    int nmods, cap_mods;
    param_override *overrides;
    int noverrides;
    /* params declared (for `frac check --params`) */
    struct { const char *name; const node *decl; } *params;
    int nparams, cap_params;
    int list_params;     /* check --params: collect, do not evaluate */

    /* evaluation */
    int depth;
    frame *stack;
    int stack_cap;
    const node *cur;     /* node being evaluated (for builtin errors) */
    err_state err;
    volatile sig_atomic_t *interrupt;

    /* settings */
    uint64_t seed;
    int threads;
    int quiet;
    int progress;
    const char *out_dir; /* NULL: current directory */
    /* work the engines did, for the render report (report.h) */
#define WORK_MAX 12
    struct { const char *engine, *unit; double amount, seconds; } work[WORK_MAX];
    int nwork;
    int is_repl;
    FILE *out;           /* where print() writes (stdout) */
    /* frames (frac run --frames A..B[:STEP]): the names `frame` and `clock`,
     * and what `%f` in an output path becomes; all 0 outside --frames */
    long frame;          /* this frame's number */
    int frames_given;    /* 1 when --frames was given */
    double clock;        /* 0 at A, 1 at B (0 for A..A) */
    int frame_width;     /* digits of %f: those of the largest |A|, |B| */
    long frame_count;    /* frames in the range (>= 2: every path needs %f) */
    long frame_first, frame_last, frame_step; /* the range A..B:STEP (for the recipe) */
    struct shard *shard; /* --shard / merge (shard.h); NULL otherwise */

    /* builtin registry */
    const builtin **builtins;
    int nbuiltins, cap_builtins;
    struct contract_cache *contract; /* compiled declarations (contract.c) */
    const struct bcall *bcall;       /* the builtin call running, for positions */
    struct range_spec *lazy_range;   /* set by `for`: range() describes its items here (eval.c) */
    const heap *append_target;       /* x = concat(x, …): x's list, which concat may extend (eval.c) */
    interp_counts count;             /* what the evaluator did (tests/unit/test_interp_counts.c) */
} interp;

/* The items start + step * i, i < count, of a range() that a `for` loop or
 * comprehension walks without building the list. */
typedef struct range_spec {
    double start, step;
    size_t count;
    int used; /* range() filled it in */
} range_spec;

/* Allocation: every interpreter allocation goes through mem_alloc /
 * mem_calloc / mem_realloc / mem_free, which are the runtime's allocator
 * (rt_alloc.h) plus an error: on failure they record ERR_LIMIT ("memory limit
 * of N MiB exceeded (raise it with --max-memory MiB)") or ERR_MEMORY (out of
 * memory, or the allocation --fail-alloc asked to fail) and return NULL.
 * interp_init installs the one allocation hook (mem_hook in state.c): it
 * counts every block — interpreter values and every engine, image, volume,
 * mesh and decoder buffer alike — against lim.max_memory, thread-safely, and
 * fails the fail_alloc_at-th allocation. Blocks are interchangeable with the
 * runtime's: mem_free(I, p) is rt_free(p), and code that has no interp at
 * hand (object destructors) calls rt_free. */
void *mem_alloc(interp *I, size_t n);
void *mem_calloc(interp *I, size_t count, size_t size); /* zeroed, count * size checked */
void *mem_realloc(interp *I, void *p, size_t n);
void mem_free(interp *I, void *p);
/* Before a large engine allocation: is `bytes` still free under the memory
 * limit? Records "WHAT needs N MiB, over the memory limit of M MiB (K MiB in
 * use; raise it with --max-memory MiB)" (ERR_LIMIT) and returns -1 if not.
 * Counts nothing: the hook counts the engine's blocks when they are made. */
int mem_precheck(interp *I, double bytes, const char *what);
/* The error for an engine that returned RT_ENOMEM: why the hook refused
 * (memory limit, --fail-alloc, or the system), "WHAT: reason"; msg (the
 * engine's message) when the hook refused nothing. */
int mem_engine_error(interp *I, const char *what, const char *msg);

void interp_init(interp *I);
void interp_free(interp *I);
int interp_add_source(interp *I, const char *name, const char *text, size_t len);
const char *interp_intern(interp *I, const char *s, size_t len);
void *mem_arena_alloc(interp *I, size_t n);
/* The same piece of the arena, not zeroed: for the parser's nodes and arrays,
 * which it fills entirely. Inline, as the parser takes one per node: the
 * arena is a list of blocks of at least 64 KiB, handed out in multiples of
 * 16 bytes from the newest one; mem_arena_grow starts a new block (4× the
 * last, up to 8 MiB). */
typedef struct arena_block {
    struct arena_block *next;
    void *mem; /* what was allocated (the block may start inside it, state.c) */
    size_t used, cap;
    max_align_t data[];
} arena_block;
void *mem_arena_grow(interp *I, size_t n);
static inline void *mem_arena_raw(interp *I, size_t n)
{
    arena_block *b = I->arena;
    n = (n + 15) & ~(size_t)15;
    if (!b || n > b->cap - b->used)
        return mem_arena_grow(I, n);
    void *p = (char *)b->data + b->used;
    b->used += n;
    return p;
}

/* Record an error at a node's position (or at I->cur when at is NULL). */
int err_at(interp *I, const node *at, err_kind k, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int err_pos(interp *I, int src, int line, int col, err_kind k, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
void err_clear(interp *I);

/* The one function that prints positions: `file:line:col: error: msg`,
 * the source line and a caret; then the note and the call trace. */
void diag_print(interp *I, FILE *f, const err_state *e);

/* Names closest to `name` among candidates, for "did you mean" (NULL if none
 * is close enough). */
const char *interp_suggest_name(const char *name, const char *const *cands, size_t n);

#endif
