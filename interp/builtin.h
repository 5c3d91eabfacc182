/* builtin.h — native functions callable from scripts.
 *
 * Each builtin declares its parameters (name, type, default) in a table;
 * the table is the contract: argument matching, every check of types,
 * ranges and finiteness, the messages ("chaos: argument 'points' must be a
 * number, got string"), `frac check` and `:help NAME` all come from it
 * (contract.c compiles it once, at its first call; call_builtin checks
 * it before the builtin runs). A builtin only reads what was declared.
 *
 * Types: '|'-separated alternatives, each a base name with optional parts:
 *   num int str bool list vec rec func nil any, or an engine class (image, ifs…)
 *   vec3            a list of exactly 3 numbers
 *   ivec3           a list of exactly 3 whole numbers (ivec: any length)
 *   [lo,hi] (lo,hi) a range ('(' ')' open ends), also >=x >x <=x <x;
 *                   for vec it applies to every item
 *   {8,16}          choices (num/int), {log,linear} (str, with did-you-mean)
 *   rec{k: T, …}    the keys an (option) record may have, each with its type;
 *                   any other key is an error (with did-you-mean); "k!: T"
 *                   marks a key the record must have ("is missing key 'k'")
 *   +inf +nan       infinities / NaN allowed; numbers are finite otherwise,
 *                   also inside lists ("list": numbers at any depth)
 * e.g. "int[1,8]", "num>0", "vec2|num>0", "str{log,linear,sqrt}",
 * "rec{bits: int{8,16}, channels: int[1,4]}".
 * A default is literal text ("512", "[0, 0, 0]", "\"png\"", "true", "nil")
 * or an expression evaluated once ("orbit()"); NULL means required; a nil
 * default also accepts nil. A builtin with variadic = 1 receives all
 * positional arguments as given (unchecked; named ones matched by name).
 */
#ifndef BUILTIN_H
#define BUILTIN_H

#include "state.h"
#include "value.h"

typedef struct bparam {
    const char *name;
    const char *type;
    const char *def;
} bparam;

/* Type texts shared by several tables. */
#define TY_COLOUR "num|vec|str"
#define TY_CAMERA "rec{eye!: vec3, target!: vec3, up: vec3, fov: num(0,179)}"
#define TY_SIZE "vec2[1,1000000]|int[1,1000000]"

#define MAX_ARGS 32

/* Operation codes passed to obj_class.arith beyond the operator tokens
 * (T_PLUS…, '-' unary minus): math functions applied to an object (fields
 * build graph nodes, images apply per pixel), min/max and atan2. */
enum {
    OP_SQRT = 256, OP_EXP, OP_LOG, OP_SIN, OP_COS, OP_TAN, OP_ABS, OP_FLOOR, OP_CEIL, OP_ROUND, OP_SIGN,
    OP_ASIN, OP_ACOS, OP_ATAN,
    OP_MAX = 512, OP_MIN = 513, OP_ATAN2 = 514, OP_NEG = 515
};

/* args: one slot per declared parameter, in declaration order (defaults
 * filled in; borrowed). For variadic builtins, args[0..nargs-1] are the
 * positional arguments followed by the named parameters. Write the result
 * (a new reference) to *out; return 0, or -1 after recording an error. */
typedef int (*builtin_fn)(interp *I, value *args, int nargs, value *out);

typedef struct builtin {
    const char *name;
    builtin_fn fn;
    const bparam *params;
    int nparams;
    int variadic;
    const char *doc; /* one paragraph for :help */
} builtin;

#define BUILTIN(name, fn, params, doc) {name, fn, params, (int)(sizeof params / sizeof params[0]), 0, doc}
/* Register a static table of builtins: BUILTIN_REGISTER(I, field_builtins). */
#define BUILTIN_REGISTER(I, table) builtin_register((I), (table), (int)(sizeof(table) / sizeof((table)[0])))
#define BUILTIN_VAR(name, fn, params, doc) {name, fn, params, (int)(sizeof params / sizeof params[0]), 1, doc}

/* The registry (builtin.c). Register a table of builtins (static storage) as globals. */
int builtin_register(interp *I, const builtin *b, int n);
/* All modules' registration functions, called by interp setup. */
int builtin_core_init(interp *I);
int builtin_image_init(interp *I);
/* Engine bindings (interp/bind_*.c), registered by bindings.c. */
int bind_all_init(interp *I);
int bind_volume_init(interp *I);
int bind_field_init(interp *I);
int bind_ifs_init(interp *I);
int bind_solid_init(interp *I);
int bind_ist_init(interp *I);
int bind_wrinkly_init(interp *I);
int bind_raster_init(interp *I);
int bind_show_init(interp *I);
int bind_fset_init(interp *I);
int bind_shape_init(interp *I);
int bind_tops_init(interp *I);
int bind_superifs_init(interp *I);
int bind_tiles_init(interp *I);
int bind_fit_init(interp *I);

/* Call any function value with positional arguments (borrowed). */
int eval_call_value(interp *I, value fn, const value *args, int nargs, value *out);

/* Helpers for builtins. */
int builtin_arg_error(interp *I, const builtin *b, const char *param, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Check that v is a list of n numbers (n = 0: any length); copy to out. */
int builtin_get_vec(interp *I, value v, double *out, size_t n, const char *what);
int builtin_get_int(interp *I, value v, long lo, long hi, long *out, const char *what);
/* Shared argument readers (args.c): a seed (nil: the global --seed), an
 * image size (n or [w, h] whole pixels), a list of numbers as a value, and a
 * path relative to the folder of the script being run. `what` prefixes
 * messages ("chaos: size"); lang_arg_seed accepts NULL. */
int lang_arg_seed(interp *I, value v, uint64_t *seed, const char *what);
int lang_arg_size2(interp *I, value v, int *w, int *h, const char *what);
int lang_num_list_value(interp *I, const double *x, size_t n, value *out);
/* A path string v relative to the script's folder, into buf; 0, or -1 with
 * an error "WHAT: path too long: …" (never truncated) or a NUL byte error. */
int lang_script_path(interp *I, value v, char *buf, size_t n, const char *what);
/* dir/p (p alone if it is absolute or dir is NULL or "."), checked the same
 * way; errors are at node at (NULL: the current call). */
int lang_join_path(interp *I, const node *at, const char *dir, const char *p, size_t plen, char *buf, size_t n,
                   const char *what);

/* Errors about part of an argument: item `index` (0-based) of the list
 * `container`, an argument of the builtin running. The caret goes on that
 * item (a table's row) when the argument is a literal at the call, else on
 * the argument, else on the call. index SIZE_MAX: the argument itself. */
int err_item(interp *I, value container, size_t index, err_kind k, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
/* An error about argument `slot` of the running builtin (its index in the
 * builtin's args) that its declaration cannot say, such as one depending on
 * several arguments: the caret goes on that argument when it was written
 * at the call, else on the call. */
int err_arg(interp *I, int slot, err_kind k, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
/* An error about the argument whose value is v (a list, record, string or
 * object passed to the current builtin; the caret lands on it), or at the
 * call when v is not one of its arguments. */
int err_value(interp *I, value v, err_kind k, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
/* Check an option record whose keys depend on the value it goes with (save
 * of an image, a mesh…) against a declared type text "rec{…}" (compiled
 * once); nil passes. Errors point at the record's key when it is written at
 * the call. */
int contract_check_opts(interp *I, value opts, const char *type, const char *who);

/* Signature text "name(a, b: num[0,1] = 2)" for help: the declared types. */
void builtin_signature(const builtin *b, struct bytebuf *out);
const builtin *builtin_find(interp *I, const char *name);

#endif
