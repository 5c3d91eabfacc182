/* value.h — the values of the language.
 *
 * A value is a small tagged struct passed by copy. Numbers, booleans and nil
 * are immediate; strings, lists, records, closures, environments and engine
 * objects live on the heap, reference-counted, and every heap object is also
 * on one list in the interpreter state so a session can free everything at
 * the end even when closures and their environments form cycles.
 *
 * Ownership convention: a function that returns a value (or writes one
 * through an out-parameter) hands over one reference; arguments are borrowed.
 * Use val_ref to keep a borrowed value, val_unref to drop an owned one.
 *
 * Engine objects (image now; ifs, field, volume, mesh… later) are values of
 * kind V_OBJ with a class that gives their type name (used in messages), a
 * destructor and a one-line summary (the REPL prints it).
 */
#ifndef VALUE_H
#define VALUE_H

#include <stddef.h>
#include <stdint.h>

struct interp;
struct node;
struct bytebuf;
struct image;

typedef enum vkind { V_NIL, V_BOOL, V_NUM, V_STR, V_LIST, V_REC, V_FUNC, V_BUILTIN, V_OBJ } vkind;

typedef struct heap {
    uint32_t rc;
    uint8_t kind; /* H_* */
    struct heap *prev, *next;
} heap;

enum { H_STR, H_LIST, H_REC, H_FUNC, H_ENV, H_OBJ };

typedef struct value {
    vkind k;
    union {
        int b;
        double n;
        heap *h;
        const struct builtin *bi;
    } u;
} value;

typedef struct vstr {
    heap h;
    size_t len;
    char s[]; /* NUL-terminated */
} vstr;

typedef struct vlist {
    heap h;
    size_t n, cap;
    value *items;
} vlist;

typedef struct vrec {
    heap h;
    size_t n, cap;
    const char **keys; /* interned */
    value *vals;
} vrec;

typedef struct env env;

typedef struct vfunc {
    heap h;
    const struct node *lambda;
    env *closure;
    const char *name; /* interned, may be NULL for anonymous */
} vfunc;

/* Environments are scopes: a small array of (interned name, value) plus a
 * parent; the global scope uses the same structure (linear search is fine:
 * the interpreter never runs per point). */
struct env {
    heap h;
    env *parent;
    size_t n, cap;
    const char **names;
    value *vals;
    uint32_t *index;  /* open addressing: slot + 1, 0 = empty; NULL while small */
    size_t index_cap;
    int loose;        /* a name was added by name (val_env_define), not at its slot: the
                       * slots resolve.c gave may not describe this scope (compile.h) */
    int borrowed;     /* names and vals are the caller's arrays (a call's scope on the C
                       * stack, compile.c): growing copies them out, nothing frees them */
};

/* Freed scopes with at most ENV_POOL_CAP slots are kept (up to ENV_POOL_MAX)
 * and reused by val_env_new. */
#define ENV_POOL_CAP 8
#define ENV_POOL_MAX 256

/* Hash of an interned name (its address). */
static inline size_t name_hash(const char *name)
{
    uint64_t x = (uint64_t)(uintptr_t)name;
    x ^= x >> 29;
    x *= 0xbf58476d1ce4e5b9ull;
    return (size_t)(x ^ (x >> 32));
}

typedef struct obj_class {
    const char *name;                              /* "image", "ifs", … */
    void (*destroy)(void *payload);
    void (*summary)(const void *payload, struct bytebuf *out); /* one line */
    /* Optional: arithmetic where either operand is of this class (op is the
     * token type: T_PLUS…, or an OP_* code of builtin.h with b nil for unary ones).
     * Return 1 if handled (result in *out), 0 to fall through to the
     * generic "cannot add image and string" error, -1 on error. */
    int (*arith)(struct interp *I, int op, value a, value b, value *out);
    /* Optional: obj.name (a new reference in *out; 0 ok, 1 no such field, -1 error). */
    int (*get)(struct interp *I, const void *payload, const char *name, value *out);
    /* Optional: a picture of the object for show() in the terminal: a new
     * malloc'd image in *out (0), or -1 after an error. */
    int (*preview)(struct interp *I, const void *payload, struct image **out);
    /* Optional: save to a file (path already joined with --out-dir; the
     * extension picks the format). 0 ok, -1 error. */
    int (*save)(struct interp *I, const void *payload, const char *path, value opts);
} obj_class;

typedef struct vobj {
    heap h;
    const obj_class *cls;
    void *payload;
} vobj;

static inline value val_nil(void) { value v; v.k = V_NIL; v.u.n = 0; return v; }
static inline value val_bool(int b) { value v; v.k = V_BOOL; v.u.b = b != 0; return v; }
static inline value val_num(double n) { value v; v.k = V_NUM; v.u.n = n; return v; }

#define AS_STR(v) ((vstr *)(v).u.h)
#define AS_LIST(v) ((vlist *)(v).u.h)
#define AS_REC(v) ((vrec *)(v).u.h)
#define AS_FUNC(v) ((vfunc *)(v).u.h)
#define AS_OBJ(v) ((vobj *)(v).u.h)

void val_heap_unref(struct interp *I, heap *h);
/* Inline: numbers, booleans and nil (most values in a loop) cost a test. */
static inline void val_ref(value v)
{
    if (v.k >= V_STR && v.k != V_BUILTIN)
        v.u.h->rc++;
}
static inline void val_unref(struct interp *I, value v)
{
    if (v.k >= V_STR && v.k != V_BUILTIN)
        val_heap_unref(I, v.u.h);
}

/* Constructors return a new reference, or a nil value with an out-of-memory
 * error raised in I (check I->err.active or use the eval helpers). */
value val_str(struct interp *I, const char *s, size_t len);
value val_cstr(struct interp *I, const char *s);
value val_list(struct interp *I, size_t cap);
int val_list_push(struct interp *I, vlist *l, value v); /* takes ownership of v */
/* *out = [item(0), …, item(n - 1)]: item(I, ctx, i, &v) makes element i (a
 * new reference; 0 ok, -1 error). 0 ok; -1 after an error, nothing built. */
typedef int (*val_item_fn)(struct interp *I, const void *ctx, size_t i, value *out);
int val_list_build(struct interp *I, size_t n, val_item_fn item, const void *ctx, value *out);
value val_rec(struct interp *I);
int val_rec_set(struct interp *I, vrec *r, const char *key, value v); /* key interned; takes v */
value *val_rec_get(const vrec *r, const char *key);                 /* borrowed, or NULL */
value val_func(struct interp *I, const struct node *lambda, env *closure, const char *name);
value val_obj(struct interp *I, const obj_class *cls, void *payload); /* destroys payload on OOM */

env *val_env_new(struct interp *I, env *parent);
int val_env_define(struct interp *I, env *e, const char *name, value v); /* takes v; redefines */
/* Add name (which e does not hold: the caller knows) as e's next slot, without searching; takes v. */
int val_env_append(struct interp *I, env *e, const char *name, value v);
value *val_env_lookup(env *e, const char *name);                        /* borrowed, or NULL */

/* The type name used in messages: "number", "string", "list", "image"… */
const char *val_type_name(value v);
int val_truthy(value v);
/* Structural equality: 1 equal, 0 not, -1 with an error recorded (values
 * nested deeper than the C stack allows: "stack overflow", see cstack.h). */
int val_equal(struct interp *I, value a, value b);
/* Printed form: strings quoted when repr is set (inside lists). Iterative:
 * values nested any depth print. */
void val_print(struct interp *I, value v, struct bytebuf *out, int repr);

/* Free every heap object (end of session): ignores reference counts. */
void val_heap_free_all(struct interp *I);



/* Shortest decimal that reads back to the same double. */
void val_fmt_number(double n, char *buf, size_t size);

#endif
