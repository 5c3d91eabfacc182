/* field.h — scalar fields as graphs of native nodes, compiled to block
 * programs.
 *
 * A field is a function of a point P = (x, y, z). The interpreter builds a
 * graph of immutable, reference-counted nodes when a script does arithmetic
 * on fields or applies a user function to a symbolic field (no interpreter
 * work per point); field_compile flattens the graph into a program that
 * evaluates blocks of points, paying node dispatch once per block.
 *
 * Nodes and ownership.
 *   - Constructors CONSUME the references to their child fields (so
 *     field_binary(FIELD_ADD, field_coord(0), field_const(1)) leaks
 *     nothing) and return a new node with one reference. To keep using a
 *     child, pass field_ref(child).
 *   - A constructor returns NULL only when memory runs out; it then releases
 *     the children it was given. A NULL child makes it return NULL (after
 *     releasing the other children), so OOM propagates through nested calls.
 *   - Nodes are immutable; a node may be the child of several parents (a
 *     DAG: common subexpressions are shared and evaluated once per block).
 *   - field_ref / field_unref are NOT thread-safe: build and release graphs
 *     on one thread (the interpreter's). A compiled field_prog holds its own
 *     reference to the root, so the graph lives as long as the program.
 *     field_unref is iterative (deep chains cannot overflow the C stack).
 *
 * The nodes:
 *   field_const(v), field_coord(axis)  axis 0, 1, 2 = x, y, z of the current
 *                                  frame (see warp)
 *   field_unary(op, a)             FIELD_NEG ... (field_unop); not(a) = a == 0
 *   field_binary(op, a, b)         + - * / pow min max < <= > >= == != and
 *                                  or atan2 mod; comparisons and logic give
 *                                  1 or 0 (non-zero is true); mod is floored,
 *                                  a - b floor(a / b) (the sign of b, like the
 *                                  language's %); min/max are a < b ? a : b
 *                                  and a > b ? a : b
 *   field_select(c, a, b)          c != 0 ? a : b (both sides are evaluated)
 *   field_clamp(v, lo, hi)         v < lo ? lo : v > hi ? hi : v
 *   field_lerp(a, b, t)            a + t (b - a)
 *   field_warp(child, fx, fy, fz)  child evaluated at (fx(P), fy(P), fz(P)):
 *                                  translate/rotate/scale of space, the seed
 *                                  000 perturbation P' = P + (0, 0, k D(P)),
 *                                  any deformation. Inside child, coord nodes
 *                                  mean the warped point.
 *   field_external(fn, ctx, release, name)
 *                                  a native engine (volume, midpoint
 *                                  displacement...) through rt_field_fn; fn
 *                                  must be reentrant and pointwise (a value
 *                                  depends only on its own point). release(ctx)
 *                                  is called (if not NULL) when the node dies,
 *                                  or at once if the node cannot be made.
 *   field_perlin(seed), field_fbm(seed, octaves, lacunarity, gain),
 *   field_turbulence(seed, octaves)
 *                                  noise.h; the permutation comes from the
 *                                  seed (octaves are clamped to 0..64)
 *   field_density(&shape)          a soft shape of density.h (copied; the
 *                                  constructors do not validate parameters:
 *                                  call density_check / dmf_check_* first)
 *   field_smooth_union(a, b, k), field_bias(t, b), field_gain(t, g),
 *   field_smoothstep(t, e0, e1), field_step(t, edge)
 *                                  density.h; parameters are numbers (build
 *                                  bias with a field parameter from pow/log)
 *   field_affine(t, a, b)          a t + b (scale/offset)
 *   field_translate / field_scale / field_transform: warps made of the above.
 *
 * Compilation (field_compile). The DAG is flattened in dependency order into
 * instructions over value registers of up to RT_BLOCK doubles. Each node is
 * compiled once per coordinate frame (memoised on (node, frame)); a warp
 * opens the frame whose coordinates are the registers holding fx, fy, fz
 * (identical frames are shared). Coordinates therefore cost nothing: coord
 * nodes are just the frame's registers. Constant subgraphs are folded, equal
 * constants share a register (filled once per call), dead code is dropped,
 * and registers are reused after their last use. Compilation fails (NULL,
 * e filled) only on out-of-memory or a graph nested deeper than
 * FIELD_MAX_DEPTH.
 *
 * Evaluation. field_prog_eval runs the program over n points (any n) in
 * blocks; each instruction is one switch case with a tight loop over the
 * block. Programs are immutable: evaluation is reentrant and thread-safe.
 * Scratch registers live on the C stack (32 KiB: for big programs the block
 * is shortened, values do not depend on it) or, beyond 256 registers, in a
 * buffer malloc'd per call; if that malloc fails the output is NaN.
 * field_prog_eval_scratch takes caller-provided scratch of
 * field_prog_scratch_size doubles instead (no allocation at all).
 * field_prog_fn has the exact rt_field_fn signature (ctx = the field_prog).
 *
 * Distances (field_sdf.c). Where a field's solid {f >= level} is bounded
 * by shapes, the runtime derives a second field g, its signed distance:
 * g <= 0 exactly on the solid (up to the boundary itself), g = 0 on the
 * surface, and |g| the Euclidean distance to the surface (exact) or a lower
 * bound on it. The density values are not touched; g is a separate graph.
 *   field_shape_sdf(&shape, level)  the distance to {D = level} of a shape
 *                                  (density.h density_sdf; 0 < level <= 1)
 *   field_level_sdf(f, level, &g, &exact)
 *                                  g for {f >= level}, or *g = NULL when none
 *                                  can be derived. What survives:
 *     shape                     sdf (exact: hard shapes, soft sphere/torus)
 *     translate/rotate/scale, and any warp whose x, y, z are affine in the
 *       point, M P + t          g(M P + t) / sigma_max(M) (exact when M is a
 *                               rotation times a positive scale; a lower
 *                               bound otherwise)
 *     c * f, f * c, f / c (c > 0), f + c, c + f, f - c, affine(f, a, b)
 *                               the level moves (exactness kept)
 *     c - f, -f, affine with a < 0, f < c, f <= c, c > f ...
 *                               -g of the moved level (the complement)
 *     f >= c, f > c, c <= f, step(f, c)   g of f at level c
 *     clamp(f, lo, hi), bias, gain, smoothstep(e0 < e1)
 *                               g of f at the inverse of the level
 *     min(a, b) -> max(ga, gb), max(a, b) -> min(ga, gb) (a bound)
 *     a * b, a and b, a or b, not a   for 0/1 fields ("indicators": hard
 *                               shapes, comparisons, steps, and these)
 *   Anything else (noise, smooth_union, a non-affine warp, a product with a
 *   field that is not 0/1, numbers) gives none: the engines then use the
 *   density alone, as before.
 *   field_hard_support(f, &g)      g with f = 0 (or NaN) wherever g > 0, for
 *                                  fields that vanish outside a hard region:
 *                                  0/1 fields, and products, quotients,
 *                                  maxima, affine(f, a, 0), bias and gain of
 *                                  them, through affine warps. *g = NULL if
 *                                  none.
 *   field_prog_level_sdf / field_prog_hard_support: the same for a compiled
 *   program's root, compiled (NULL when none).
 * Analysis errors are only out-of-memory (RT_ENOMEM); a graph too large or
 * too deep for it (over FIELD_SDF_BUDGET node visits) has no distance.
 *
 * field_sample_volume fills an initialised volume (its nx, ny, nz, lo, hi
 * and v) with any rt_field_fn at the sample centres given in volume.h,
 * with par_for over z-slabs (one chunk per slice): the result does not
 * depend on run->threads.
 *
 * field_preview draws a program's slice z = 0 over [-1, 1]^2 (y up, one
 * sample at each pixel centre) into an allocated image as grey, scaled so
 * the smallest finite value is 0 and the largest 1 (0 where the value is not
 * finite or the slice is constant), alpha 1: show(field) in the terminal.
 */
#ifndef FIELD_H
#define FIELD_H

#include <stddef.h>
#include <stdint.h>

#include "density.h"
#include "fileio.h"
#include "rt.h"
#include "volume.h"

#define FIELD_MAX_DEPTH 10000

typedef struct field field;
typedef struct field_prog field_prog;

typedef enum field_unop {
    FIELD_NEG,
    FIELD_NOT,
    FIELD_ABS,
    FIELD_FLOOR,
    FIELD_CEIL,
    FIELD_ROUND, /* floor(a + 0.5), like the language's round */
    FIELD_FRACT, /* a - floor(a) */
    FIELD_SIGN,  /* 1, -1, or a itself (0, -0, NaN) */
    FIELD_SQRT,
    FIELD_EXP,
    FIELD_LOG,
    FIELD_SIN,
    FIELD_COS,
    FIELD_TAN,
    FIELD_ASIN,
    FIELD_ACOS,
    FIELD_ATAN,
    FIELD_SINH,
    FIELD_COSH,
    FIELD_TANH,
    FIELD_UNOP_COUNT
} field_unop;

typedef enum field_binop {
    FIELD_ADD,
    FIELD_SUB,
    FIELD_MUL,
    FIELD_DIV,
    FIELD_POW,
    FIELD_MIN,
    FIELD_MAX,
    FIELD_LT,
    FIELD_LE,
    FIELD_GT,
    FIELD_GE,
    FIELD_EQ,
    FIELD_NE,
    FIELD_AND,
    FIELD_OR,
    FIELD_ATAN2,
    FIELD_MOD,
    FIELD_BINOP_COUNT
} field_binop;

/* Names ("neg", "sqrt", ...; "+", "min", "atan2", ...) and lookup by name
 * (-1 if unknown) for the interpreter's bindings. */
const char *field_unop_name(field_unop op);
const char *field_binop_name(field_binop op);
int field_unop_lookup(const char *name);
int field_binop_lookup(const char *name);

field *field_ref(field *f);
void field_unref(field *f);

field *field_const(double v);
field *field_coord(int axis);
field *field_unary(field_unop op, field *a);
field *field_binary(field_binop op, field *a, field *b);
field *field_select(field *cond, field *a, field *b);
field *field_clamp(field *v, field *lo, field *hi);
field *field_lerp(field *a, field *b, field *t);
field *field_warp(field *child, field *fx, field *fy, field *fz);
field *field_external(rt_field_fn fn, void *ctx, void (*release)(void *ctx), const char *name);
field *field_perlin(uint64_t seed);
field *field_fbm(uint64_t seed, int octaves, double lacunarity, double gain);
field *field_turbulence(uint64_t seed, int octaves);
field *field_density(const density_shape *shape);
field *field_smooth_union(field *a, field *b, double k);
field *field_bias(field *t, double b);
field *field_gain(field *t, double g);
field *field_smoothstep(field *t, double e0, double e1);
field *field_step(field *t, double edge);
field *field_affine(field *t, double a, double b);

/* child(P - d) */
field *field_translate(field *child, double dx, double dy, double dz);
/* child(P / s), s != 0 */
field *field_scale(field *child, double s);
/* child(M P + t): m = {a b c tx; d e f ty; g h o tz} row-major 3x4 — pass the
 * inverse of the map that moves the object. */
field *field_transform(field *child, const double m[12]);

field *field_shape_sdf(const density_shape *shape, double level);

#define FIELD_SDF_BUDGET 100000
rt_code field_level_sdf(const field *f, double level, field **g, int *exact, rt_error *e);
rt_code field_hard_support(const field *f, field **g, rt_error *e);

/* 1 and *v = the value if f is a constant node. */
int field_is_const(const field *f, double *v);

/* A readable, fully parenthesised expression, cut at about maxlen bytes
 * with "..." (shared subgraphs are printed at each use). */
void field_print(const field *f, bytebuf *b, size_t maxlen);

field_prog *field_compile(const field *root, rt_error *e);
void field_prog_free(field_prog *p);

void field_prog_eval(const field_prog *p, size_t n, const double *x, const double *y,
                     const double *z, double *out);
void field_prog_fn(const void *prog, size_t n, const double *x, const double *y, const double *z,
                   double *out);
double field_prog_eval1(const field_prog *p, double x, double y, double z);

size_t field_prog_scratch_size(const field_prog *p); /* in doubles */
void field_prog_eval_scratch(const field_prog *p, double *scratch, size_t n, const double *x,
                             const double *y, const double *z, double *out);

rt_code field_prog_level_sdf(const field_prog *p, double level, field_prog **g, int *exact,
                             rt_error *e);
rt_code field_prog_hard_support(const field_prog *p, field_prog **g, rt_error *e);

/* Number of instructions and of registers (for tests and the REPL). */
void field_prog_stats(const field_prog *p, size_t *ninstr, size_t *nregs);

struct image;
rt_code field_preview(const field_prog *p, struct image *im, rt_error *e);

rt_code field_sample_volume(rt_field_fn fn, const void *ctx, volume *vol, const rt_run *run,
                            rt_error *e);

/* ---- Internal: the compiled program, shared by field.c (compiler) and
 * field_eval.c (evaluator). Not for use outside these two files. */
enum {
    FOP_UNARY = 0,                           /* + field_unop */
    FOP_BINARY = FIELD_UNOP_COUNT,           /* + field_binop */
    FOP_SELECT = FOP_BINARY + FIELD_BINOP_COUNT, /* a ? b : c */
    FOP_CLAMP,                               /* clamp(a, b, c) */
    FOP_LERP,                                /* a + c (b - a) */
    FOP_EXTERNAL,                            /* fn(ptr, a, b, c) */
    FOP_PERLIN,                              /* ptr = noise_perm */
    FOP_FBM,                                 /* octaves, k[0] = lacunarity, k[1] = gain */
    FOP_TURB,                                /* octaves */
    FOP_DENSITY,                             /* ptr = density_shape */
    FOP_SUNION,                              /* k[0] = k */
    FOP_BIAS,                                /* k[0] = b */
    FOP_GAIN,                                /* k[0] = g */
    FOP_SMOOTHSTEP,                          /* k[0], k[1] = e0, e1 */
    FOP_STEP,                                /* k[0] = edge */
    FOP_AFFINE,                              /* k[0] a + k[1] */
    FOP_SDF,                                 /* ptr = density_shape, k[0] = level */
    FOP_COUNT
};

typedef struct field_instr {
    int op;
    int dst, a, b, c; /* registers; coordinates of the frame for noise etc. */
    int octaves;
    double k[2];
    const void *ptr;
    rt_field_fn fn;
} field_instr;

struct field_prog {
    field *root; /* a reference, keeping node data (perm, shape, ctx) alive */
    field_instr *code;
    size_t ncode;
    size_t nconst, ntemp; /* registers: 0..2 x y z, then constants, then temporaries */
    double *consts;
    int result;
};

/* Run instructions over blocks of n points; reg[i] points at register i. */
void field_run(const field_instr *code, size_t ncode, double *const *reg, size_t n);

#endif
