/* field.c — field graph nodes, printing, and the compiler to block
 * programs. See field.h; evaluation is in field_eval.c. */
#include "field.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "noise.h"

#include "field_node.h"

/* ---- names */

static const char *const unop_names[FIELD_UNOP_COUNT] = {
    "neg", "not", "abs", "floor", "ceil", "round", "fract", "sign", "sqrt", "exp",
    "log", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh",
};
static const char *const binop_names[FIELD_BINOP_COUNT] = {
    "+", "-", "*", "/", "pow", "min", "max", "<", "<=", ">", ">=", "==", "!=", "and", "or",
    "atan2", "mod",
};

const char *field_unop_name(field_unop op)
{
    return (unsigned)op < FIELD_UNOP_COUNT ? unop_names[op] : "?";
}

const char *field_binop_name(field_binop op)
{
    return (unsigned)op < FIELD_BINOP_COUNT ? binop_names[op] : "?";
}

int field_unop_lookup(const char *name)
{
    for (int i = 0; i < FIELD_UNOP_COUNT; i++)
        if (strcmp(name, unop_names[i]) == 0)
            return i;
    return -1;
}

int field_binop_lookup(const char *name)
{
    for (int i = 0; i < FIELD_BINOP_COUNT; i++)
        if (strcmp(name, binop_names[i]) == 0)
            return i;
    return -1;
}

/* ---- reference counting */

field *field_ref(field *f)
{
    if (f)
        f->refs++;
    return f;
}

void field_unref(field *f)
{
    if (!f || --f->refs > 0)
        return;
    f->next = NULL;
    field *work = f;
    while (work) {
        field *n = work;
        work = n->next;
        for (int i = 0; i < n->nkids; i++) {
            field *k = n->kid[i];
            if (k && --k->refs == 0) {
                k->next = work;
                work = k;
            }
        }
        if (n->release)
            n->release(n->ctx);
        rt_free(n->perm);
        rt_free(n);
    }
}

/* A node with kids (consumed). Any NULL kid or allocation failure releases
 * the kids and gives NULL. */
static field *node_new(int kind, int op, int nkids, field *k0, field *k1, field *k2, field *k3)
{
    field *kids[4] = {k0, k1, k2, k3};
    int bad = 0;
    for (int i = 0; i < nkids; i++)
        bad |= kids[i] == NULL;
    field *f = bad ? NULL : rt_calloc(1, sizeof *f);
    if (!f) {
        for (int i = 0; i < nkids; i++)
            field_unref(kids[i]);
        return NULL;
    }
    f->refs = 1;
    f->kind = kind;
    f->op = op;
    f->nkids = nkids;
    for (int i = 0; i < nkids; i++)
        f->kid[i] = kids[i];
    return f;
}

field *field_const(double v)
{
    field *f = node_new(FK_CONST, 0, 0, NULL, NULL, NULL, NULL);
    if (f)
        f->k[0] = v;
    return f;
}

field *field_coord(int axis)
{
    return node_new(FK_COORD, axis < 0 ? 0 : axis > 2 ? 2 : axis, 0, NULL, NULL, NULL, NULL);
}

field *field_unary(field_unop op, field *a)
{
    if ((unsigned)op >= FIELD_UNOP_COUNT)
        op = FIELD_NEG;
    return node_new(FK_UNARY, (int)op, 1, a, NULL, NULL, NULL);
}

field *field_binary(field_binop op, field *a, field *b)
{
    if ((unsigned)op >= FIELD_BINOP_COUNT)
        op = FIELD_ADD;
    return node_new(FK_BINARY, (int)op, 2, a, b, NULL, NULL);
}

field *field_select(field *cond, field *a, field *b)
{
    return node_new(FK_SELECT, 0, 3, cond, a, b, NULL);
}

field *field_clamp(field *v, field *lo, field *hi)
{
    return node_new(FK_CLAMP, 0, 3, v, lo, hi, NULL);
}

field *field_lerp(field *a, field *b, field *t) { return node_new(FK_LERP, 0, 3, a, b, t, NULL); }

field *field_warp(field *child, field *fx, field *fy, field *fz)
{
    return node_new(FK_WARP, 0, 4, child, fx, fy, fz);
}

field *field_external(rt_field_fn fn, void *ctx, void (*release)(void *ctx), const char *name)
{
    field *f = node_new(FK_EXTERNAL, 0, 0, NULL, NULL, NULL, NULL);
    if (!f) {
        if (release)
            release(ctx);
        return NULL;
    }
    f->fn = fn;
    f->ctx = ctx;
    f->release = release;
    snprintf(f->name, sizeof f->name, "%s", name ? name : "external");
    return f;
}

static int clamp_octaves(int o) { return o < 0 ? 0 : o > 64 ? 64 : o; }

static field *noise_node(int kind, uint64_t seed, int octaves, double lac, double gain)
{
    field *f = node_new(kind, 0, 0, NULL, NULL, NULL, NULL);
    if (!f)
        return NULL;
    f->perm = rt_malloc(sizeof *f->perm);
    if (!f->perm) {
        rt_free(f);
        return NULL;
    }
    noise_perm_init(f->perm, seed);
    f->seed = seed;
    f->octaves = clamp_octaves(octaves);
    f->k[0] = lac;
    f->k[1] = gain;
    return f;
}

field *field_perlin(uint64_t seed) { return noise_node(FK_PERLIN, seed, 1, 2, 0.5); }

field *field_fbm(uint64_t seed, int octaves, double lacunarity, double gain)
{
    return noise_node(FK_FBM, seed, octaves, lacunarity, gain);
}

field *field_turbulence(uint64_t seed, int octaves)
{
    return noise_node(FK_TURB, seed, octaves, 2, 0.5);
}

field *field_density(const density_shape *shape)
{
    field *f = node_new(FK_DENSITY, 0, 0, NULL, NULL, NULL, NULL);
    if (f)
        f->shape = *shape;
    return f;
}

field *field_shape_sdf(const density_shape *shape, double level)
{
    field *f = node_new(FK_SDF, 0, 0, NULL, NULL, NULL, NULL);
    if (f) {
        f->shape = *shape;
        f->k[0] = level;
    }
    return f;
}

static field *param_node(int kind, field *t, field *u, double k0, double k1)
{
    field *f = node_new(kind, 0, u ? 2 : 1, t, u, NULL, NULL);
    if (f) {
        f->k[0] = k0;
        f->k[1] = k1;
    }
    return f;
}

field *field_smooth_union(field *a, field *b, double k)
{
    if (!b) { /* param_node would take a NULL b as "one kid" */
        field_unref(a);
        return NULL;
    }
    return param_node(FK_SUNION, a, b, k, 0);
}

field *field_bias(field *t, double b) { return param_node(FK_BIAS, t, NULL, b, 0); }
field *field_gain(field *t, double g) { return param_node(FK_GAIN, t, NULL, g, 0); }
field *field_smoothstep(field *t, double e0, double e1)
{
    return param_node(FK_SMOOTHSTEP, t, NULL, e0, e1);
}
field *field_step(field *t, double edge) { return param_node(FK_STEP, t, NULL, edge, 0); }
field *field_affine(field *t, double a, double b) { return param_node(FK_AFFINE, t, NULL, a, b); }

field *field_translate(field *child, double dx, double dy, double dz)
{
    return field_warp(child, field_affine(field_coord(0), 1, -dx), field_affine(field_coord(1), 1, -dy),
                      field_affine(field_coord(2), 1, -dz));
}

field *field_scale(field *child, double s)
{
    double inv = 1 / s;
    return field_warp(child, field_affine(field_coord(0), inv, 0),
                      field_affine(field_coord(1), inv, 0), field_affine(field_coord(2), inv, 0));
}

/* m row i: m[4i] x + m[4i+1] y + m[4i+2] z + m[4i+3], summed left to right. */
static field *row(const double *m)
{
    field *s = field_binary(
        FIELD_ADD,
        field_binary(FIELD_ADD, field_affine(field_coord(0), m[0], 0),
                     field_affine(field_coord(1), m[1], 0)),
        field_affine(field_coord(2), m[2], 0));
    return field_affine(s, 1, m[3]);
}

field *field_transform(field *child, const double m[12])
{
    return field_warp(child, row(m), row(m + 4), row(m + 8));
}

int field_is_const(const field *f, double *v)
{
    if (f && f->kind == FK_CONST) {
        if (v)
            *v = f->k[0];
        return 1;
    }
    return 0;
}

/* ---- printing */

static void print_rec(const field *f, bytebuf *b, size_t maxlen, int top)
{
    if (b->len > maxlen)
        return;
    static const char axes[3] = {'x', 'y', 'z'};
    switch (f->kind) {
    case FK_CONST: bytebuf_printf(b, "%g", f->k[0]); return;
    case FK_COORD: bytebuf_byte(b, (unsigned char)axes[f->op]); return;
    case FK_UNARY:
        if (f->op == FIELD_NEG) {
            bytebuf_printf(b, "-");
            print_rec(f->kid[0], b, maxlen, 0);
            return;
        }
        bytebuf_printf(b, "%s(", unop_names[f->op]);
        print_rec(f->kid[0], b, maxlen, 1);
        bytebuf_printf(b, ")");
        return;
    case FK_BINARY:
        if (f->op == FIELD_POW || f->op == FIELD_MIN || f->op == FIELD_MAX ||
            f->op == FIELD_ATAN2 || f->op == FIELD_MOD) {
            bytebuf_printf(b, "%s(", binop_names[f->op]);
            print_rec(f->kid[0], b, maxlen, 1);
            bytebuf_printf(b, ", ");
            print_rec(f->kid[1], b, maxlen, 1);
            bytebuf_printf(b, ")");
            return;
        }
        if (!top)
            bytebuf_byte(b, '(');
        print_rec(f->kid[0], b, maxlen, 0);
        bytebuf_printf(b, " %s ", binop_names[f->op]);
        print_rec(f->kid[1], b, maxlen, 0);
        if (!top)
            bytebuf_byte(b, ')');
        return;
    case FK_EXTERNAL: bytebuf_printf(b, "%s", f->name); return;
    case FK_PERLIN:
        bytebuf_printf(b, "perlin(seed: %llu)", (unsigned long long)f->seed);
        return;
    case FK_FBM:
        bytebuf_printf(b, "fbm(seed: %llu, octaves: %d, lacunarity: %g, gain: %g)",
                       (unsigned long long)f->seed, f->octaves, f->k[0], f->k[1]);
        return;
    case FK_TURB:
        bytebuf_printf(b, "turbulence(seed: %llu, octaves: %d)", (unsigned long long)f->seed,
                       f->octaves);
        return;
    case FK_SDF:
    case FK_DENSITY: {
        const density_shape *s = &f->shape;
        if (f->kind == FK_SDF)
            bytebuf_printf(b, "sdf(");
        bytebuf_printf(b, "%s(centre: [%g, %g, %g]", density_name(s->kind), s->c[0], s->c[1],
                       s->c[2]);
        if (s->kind == DENSITY_BOX)
            bytebuf_printf(b, ", half: [%g, %g, %g]", s->h[0], s->h[1], s->h[2]);
        if (s->kind == DENSITY_TORUS)
            bytebuf_printf(b, ", R: %g", s->R);
        if (s->kind != DENSITY_BOX)
            bytebuf_printf(b, ", r: %g", s->r);
        if (s->kind == DENSITY_CYLINDER)
            bytebuf_printf(b, ", half height: %g", s->h[2]);
        bytebuf_printf(b, ", soft: %g)", s->s);
        if (f->kind == FK_SDF)
            bytebuf_printf(b, ", level: %g)", f->k[0]);
        return;
    }
    default: break;
    }
    /* name(kids..., parameters...) */
    const char *nm = "?";
    int np = 0;
    switch (f->kind) {
    case FK_SELECT: nm = "select"; break;
    case FK_CLAMP: nm = "clamp"; break;
    case FK_LERP: nm = "lerp"; break;
    case FK_WARP: nm = "warp"; break;
    case FK_SUNION: nm = "smooth_union", np = 1; break;
    case FK_BIAS: nm = "bias", np = 1; break;
    case FK_GAIN: nm = "gain", np = 1; break;
    case FK_SMOOTHSTEP: nm = "smoothstep", np = 2; break;
    case FK_STEP: nm = "step", np = 1; break;
    case FK_AFFINE: nm = "affine", np = 2; break;
    }
    bytebuf_printf(b, "%s(", nm);
    for (int i = 0; i < f->nkids; i++) {
        if (i)
            bytebuf_printf(b, ", ");
        print_rec(f->kid[i], b, maxlen, 1);
    }
    for (int i = 0; i < np; i++)
        bytebuf_printf(b, ", %g", f->k[i]);
    bytebuf_byte(b, ')');
}

void field_print(const field *f, bytebuf *b, size_t maxlen)
{
    size_t start = b->len;
    if (!f) {
        bytebuf_printf(b, "(null)");
        return;
    }
    print_rec(f, b, start + maxlen, 1);
    if (b->len > start + maxlen) {
        b->len = start + maxlen;
        bytebuf_printf(b, "...");
    }
}

/* ---- the compiler
 *
 * Pass 1 emits SSA instructions (one new value per instruction; values 0..2
 * are the input coordinates), memoised on (node, frame), folding
 * instructions whose operands are all constants. Pass 2 drops dead
 * instructions, gives constants their registers and reuses temporaries
 * after their last use (a destination is taken before the operands are
 * freed, so it never aliases an operand). */

typedef struct cval {
    double k;
    int is_const;
} cval;

typedef struct slot {
    uint64_t a, b;
    int v; /* -1: empty */
} slot;

typedef struct comp {
    rt_error *e;
    rt_code err;
    field_instr *code;
    size_t ncode, capcode;
    cval *val;
    size_t nval, capval;
    slot *tab;
    size_t tabcap, tabn;
    int (*frame)[3];
    size_t nframe, capframe;
} comp;

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t nc = *cap ? *cap * 2 : 64;
    while (nc < need)
        nc *= 2;
    void *q = rt_realloc(*p, rt_mul_size(nc, elem));
    if (!q)
        return 0;
    *p = q;
    *cap = nc;
    return 1;
}

static int oom(comp *c)
{
    if (!c->err)
        c->err = rt_fail(c->e, RT_ENOMEM, "out of memory compiling a field");
    return -1;
}

static uint64_t key_hash(uint64_t a, uint64_t b)
{
    uint64_t h = (a ^ (b * 0x9e3779b97f4a7c15ull)) * 0xbf58476d1ce4e5b9ull;
    return h ^ (h >> 29);
}

static int tab_get(const comp *c, uint64_t a, uint64_t b)
{
    if (!c->tabcap)
        return -1;
    size_t m = c->tabcap - 1;
    for (size_t i = key_hash(a, b) & m;; i = (i + 1) & m) {
        if (c->tab[i].v < 0)
            return -1;
        if (c->tab[i].a == a && c->tab[i].b == b)
            return c->tab[i].v;
    }
}

static int tab_put(comp *c, uint64_t a, uint64_t b, int v)
{
    if ((c->tabn + 1) * 2 > c->tabcap) {
        size_t nc = c->tabcap ? c->tabcap * 2 : 256;
        slot *t = rt_malloc(rt_mul_size(nc, sizeof *t));
        if (!t)
            return 0;
        for (size_t i = 0; i < nc; i++)
            t[i].v = -1;
        for (size_t j = 0; j < c->tabcap; j++) {
            if (c->tab[j].v < 0)
                continue;
            size_t i = key_hash(c->tab[j].a, c->tab[j].b) & (nc - 1);
            while (t[i].v >= 0)
                i = (i + 1) & (nc - 1);
            t[i] = c->tab[j];
        }
        rt_free(c->tab);
        c->tab = t;
        c->tabcap = nc;
    }
    size_t m = c->tabcap - 1, i = key_hash(a, b) & m;
    while (c->tab[i].v >= 0)
        i = (i + 1) & m;
    c->tab[i].a = a;
    c->tab[i].b = b;
    c->tab[i].v = v;
    c->tabn++;
    return 1;
}

static int new_val(comp *c, int is_const, double k)
{
    if (!grow((void **)&c->val, &c->capval, c->nval + 1, sizeof *c->val))
        return oom(c);
    c->val[c->nval].is_const = is_const;
    c->val[c->nval].k = k;
    return (int)c->nval++;
}

/* Key spaces of the table: nodes (ptr, frame < 2^31), constants
 * (bits, UINT64_MAX), frames (vx << 32 | vy, 2^63 | vz). */
static int const_val(comp *c, double k)
{
    uint64_t bits;
    memcpy(&bits, &k, sizeof bits);
    int v = tab_get(c, bits, UINT64_MAX);
    if (v >= 0)
        return v;
    v = new_val(c, 1, k);
    if (v >= 0 && !tab_put(c, bits, UINT64_MAX, v))
        return oom(c);
    return v;
}

static int frame_of(comp *c, int vx, int vy, int vz)
{
    uint64_t a = (uint64_t)(unsigned)vx << 32 | (unsigned)vy, b = 1ull << 63 | (unsigned)vz;
    int f = tab_get(c, a, b);
    if (f >= 0)
        return f;
    if (!grow((void **)&c->frame, &c->capframe, c->nframe + 1, sizeof *c->frame))
        return oom(c);
    f = (int)c->nframe++;
    c->frame[f][0] = vx;
    c->frame[f][1] = vy;
    c->frame[f][2] = vz;
    if (!tab_put(c, a, b, f))
        return oom(c);
    return f;
}

static int instr_nargs(int op)
{
    if (op < FOP_BINARY)
        return 1;
    if (op < FOP_SELECT)
        return 2;
    switch (op) {
    case FOP_SUNION: return 2;
    case FOP_BIAS:
    case FOP_GAIN:
    case FOP_SMOOTHSTEP:
    case FOP_STEP:
    case FOP_AFFINE: return 1;
    default: return 3;
    }
}

/* Append instruction in (dst filled here), or fold it to a constant. */
static int emit(comp *c, field_instr in)
{
    int na = instr_nargs(in.op), args[3] = {in.a, in.b, in.c}, all_const = 1;
    for (int i = 0; i < na; i++)
        all_const &= args[i] >= 3 && c->val[args[i]].is_const;
    if (all_const) {
        double kv[4] = {0, 0, 0, 0};
        double *reg[4] = {&kv[0], &kv[1], &kv[2], &kv[3]};
        for (int i = 0; i < na; i++)
            kv[i] = c->val[args[i]].k;
        in.a = 0, in.b = na > 1 ? 1 : 0, in.c = na > 2 ? 2 : 0, in.dst = 3;
        field_run(&in, 1, reg, 1);
        return const_val(c, kv[3]);
    }
    int v = new_val(c, 0, 0);
    if (v < 0)
        return -1;
    if (!grow((void **)&c->code, &c->capcode, c->ncode + 1, sizeof *c->code))
        return oom(c);
    in.dst = v;
    c->code[c->ncode++] = in;
    return v;
}

static int cnode(comp *c, const field *f, int fr, int depth)
{
    if (depth > FIELD_MAX_DEPTH) {
        if (!c->err)
            c->err = rt_fail(c->e, RT_EINVAL, "field graph nested deeper than %d nodes",
                             FIELD_MAX_DEPTH);
        return -1;
    }
    if (f->kind == FK_COORD)
        return c->frame[fr][f->op];
    if (f->kind == FK_CONST)
        return const_val(c, f->k[0]);
    int v = tab_get(c, (uint64_t)(uintptr_t)f, (uint64_t)fr);
    if (v >= 0)
        return v;
    int arg[4] = {0, 0, 0, 0};
    int nk = f->kind == FK_WARP ? 4 : f->nkids;
    for (int i = f->kind == FK_WARP ? 1 : 0; i < nk; i++)
        if ((arg[i] = cnode(c, f->kid[i], fr, depth + 1)) < 0)
            return -1;
    field_instr in;
    memset(&in, 0, sizeof in);
    in.a = arg[0], in.b = arg[1], in.c = arg[2];
    const int *co = c->frame[fr];
    switch (f->kind) {
    case FK_WARP: {
        int nf = frame_of(c, arg[1], arg[2], arg[3]);
        if (nf < 0)
            return -1;
        v = cnode(c, f->kid[0], nf, depth + 1);
        if (v < 0)
            return -1;
        goto memo;
    }
    case FK_UNARY: in.op = FOP_UNARY + f->op; break;
    case FK_BINARY: in.op = FOP_BINARY + f->op; break;
    case FK_SELECT: in.op = FOP_SELECT; break;
    case FK_CLAMP: in.op = FOP_CLAMP; break;
    case FK_LERP: in.op = FOP_LERP; break;
    case FK_SUNION: in.op = FOP_SUNION; break;
    case FK_BIAS: in.op = FOP_BIAS; break;
    case FK_GAIN: in.op = FOP_GAIN; break;
    case FK_SMOOTHSTEP: in.op = FOP_SMOOTHSTEP; break;
    case FK_STEP: in.op = FOP_STEP; break;
    case FK_AFFINE: in.op = FOP_AFFINE; break;
    case FK_EXTERNAL:
    case FK_PERLIN:
    case FK_FBM:
    case FK_TURB:
    case FK_DENSITY:
    case FK_SDF:
        in.op = f->kind == FK_EXTERNAL  ? FOP_EXTERNAL
                : f->kind == FK_SDF     ? FOP_SDF
                : f->kind == FK_PERLIN  ? FOP_PERLIN
                : f->kind == FK_FBM     ? FOP_FBM
                : f->kind == FK_TURB    ? FOP_TURB
                                        : FOP_DENSITY;
        in.a = co[0], in.b = co[1], in.c = co[2];
        in.ptr = f->kind == FK_EXTERNAL  ? (const void *)f->ctx
                 : f->kind == FK_DENSITY || f->kind == FK_SDF ? (const void *)&f->shape
                                         : (const void *)f->perm;
        in.fn = f->fn;
        break;
    }
    in.octaves = f->octaves;
    in.k[0] = f->k[0];
    in.k[1] = f->k[1];
    v = emit(c, in);
    if (v < 0)
        return -1;
memo:
    if (!tab_put(c, (uint64_t)(uintptr_t)f, (uint64_t)fr, v))
        return oom(c);
    return v;
}

void field_prog_free(field_prog *p)
{
    if (!p)
        return;
    field_unref(p->root);
    rt_free(p->code);
    rt_free(p->consts);
    rt_free(p);
}

/* Pass 2: dead code, constants, register reuse. */
static field_prog *allocate(comp *c, int result)
{
    size_t nv = c->nval;
    int *phys = rt_malloc(rt_mul_size(nv, sizeof *phys));
    int *last = rt_malloc(rt_mul_size(nv, sizeof *last));
    char *live = rt_calloc(nv ? nv : 1, 1);
    field_prog *p = rt_calloc(1, sizeof *p);
    int *freel = rt_malloc(rt_mul_size(c->ncode + 1, sizeof *freel));
    double *consts = rt_malloc(rt_mul_size(nv, sizeof *consts));
    if (!phys || !last || !live || !p || !freel || !consts) {
        rt_free(phys), rt_free(last), rt_free(live), rt_free(p), rt_free(freel), rt_free(consts);
        oom(c);
        return NULL;
    }
    live[result] = 1;
    for (size_t i = c->ncode; i-- > 0;) {
        field_instr *in = &c->code[i];
        if (!live[in->dst])
            continue;
        int args[3] = {in->a, in->b, in->c};
        for (int j = 0; j < instr_nargs(in->op); j++)
            live[args[j]] = 1;
    }
    /* compact in order, and find last uses */
    size_t n = 0;
    for (size_t i = 0; i < nv; i++)
        last[i] = -1, phys[i] = -1;
    for (size_t i = 0; i < c->ncode; i++) {
        field_instr in = c->code[i];
        if (!live[in.dst])
            continue;
        int args[3] = {in.a, in.b, in.c};
        for (int j = 0; j < instr_nargs(in.op); j++)
            last[args[j]] = (int)n;
        c->code[n++] = in;
    }
    last[result] = (int)n; /* never freed */
    phys[0] = 0, phys[1] = 1, phys[2] = 2;
    size_t nconst = 0, ntemp = 0, nfree = 0;
    for (size_t v = 3; v < nv; v++)
        if (live[v] && c->val[v].is_const) {
            consts[nconst] = c->val[v].k;
            phys[v] = (int)(3 + nconst++);
        }
    int base = (int)(3 + nconst);
    for (size_t i = 0; i < n; i++) {
        field_instr *in = &c->code[i];
        int d = nfree ? freel[--nfree] : base + (int)ntemp++;
        int *args[3] = {&in->a, &in->b, &in->c};
        int na = instr_nargs(in->op);
        for (int j = 0; j < na; j++) {
            int v = *args[j];
            *args[j] = phys[v];
            if (last[v] == (int)i && v >= 3 && !c->val[v].is_const) {
                freel[nfree++] = phys[v];
                last[v] = -2; /* freed once even if used twice here */
            }
        }
        for (int j = na; j < 3; j++)
            *args[j] = 0;
        phys[in->dst] = d;
        in->dst = d;
    }
    p->code = c->code;
    p->ncode = n;
    c->code = NULL;
    p->nconst = nconst;
    p->ntemp = ntemp;
    p->consts = consts;
    p->result = phys[result];
    rt_free(phys), rt_free(last), rt_free(live), rt_free(freel);
    return p;
}

field_prog *field_compile(const field *root, rt_error *e)
{
    comp c;
    memset(&c, 0, sizeof c);
    c.e = e;
    field_prog *p = NULL;
    if (!root) {
        rt_fail(e, RT_EINVAL, "no field to compile");
        return NULL;
    }
    int ok = 1; /* values 0, 1, 2 are x, y, z: every later index relies on them */
    for (int i = 0; i < 3; i++)
        ok = ok && new_val(&c, 0, 0) == i;
    int f0 = ok ? frame_of(&c, 0, 1, 2) : -1;
    int r = f0 < 0 ? -1 : cnode(&c, root, f0, 0);
    if (r >= 0)
        p = allocate(&c, r);
    if (p)
        p->root = field_ref((field *)root);
    else if (!c.err)
        oom(&c);
    rt_free(c.code);
    rt_free(c.val);
    rt_free(c.tab);
    rt_free(c.frame);
    return p;
}

void field_prog_stats(const field_prog *p, size_t *ninstr, size_t *nregs)
{
    if (ninstr)
        *ninstr = p->ncode;
    if (nregs)
        *nregs = 3 + p->nconst + p->ntemp;
}
