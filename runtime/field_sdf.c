/* field_sdf.c — signed distances derived from field graphs. See field.h
 * ("Distances") for what survives which operation.
 *
 * Why a separate graph: a hard shape's density is 0/1, so its samples say
 * only inside or outside, and everything built from them (linearly
 * interpolated iso-surface vertices, central-difference normals, midpoint
 * opacity) is a staircase. The shapes know their distance exactly
 * (density_sdf); the analysis below carries it through the operations that
 * keep the solid {f >= level} a set the distance still describes.
 */
#include "field_node.h"

#include <math.h>
#include <string.h>

#define PI_ 3.14159265358979323846

typedef struct an {
    long budget; /* node visits left */
    int oom;
} an;

/* The result of a rule: a new graph (one reference) or NULL. */
static field *fail_oom(an *A)
{
    A->oom = 1;
    return NULL;
}

/* Wrap a constructor's result: NULL there means out of memory. */
static field *made(an *A, field *g)
{
    return g ? g : fail_oom(A);
}

static int level_ok(double L) { return L > 0 && L <= 1; }

static int is_const(const field *f, double *v)
{
    if (f->kind != FK_CONST)
        return 0;
    *v = f->k[0];
    return isfinite(*v);
}

static int is_cmp(int op)
{
    return op == FIELD_LT || op == FIELD_LE || op == FIELD_GT || op == FIELD_GE;
}

/* A 0/1-valued field (an indicator of a set). */
static int is_ind(an *A, const field *f, int depth)
{
    if (--A->budget < 0 || depth > 200)
        return 0;
    double c;
    switch (f->kind) {
    case FK_CONST: return f->k[0] == 0 || f->k[0] == 1;
    case FK_DENSITY: return f->shape.s == 0;
    case FK_STEP: return 1;
    case FK_WARP: return is_ind(A, f->kid[0], depth + 1);
    case FK_UNARY: return f->op == FIELD_NOT;
    case FK_SELECT: return is_ind(A, f->kid[1], depth + 1) && is_ind(A, f->kid[2], depth + 1);
    case FK_BINARY:
        if (is_cmp(f->op) || f->op == FIELD_EQ || f->op == FIELD_NE || f->op == FIELD_AND ||
            f->op == FIELD_OR)
            return 1;
        if (f->op == FIELD_MIN || f->op == FIELD_MAX || f->op == FIELD_MUL)
            return is_ind(A, f->kid[0], depth + 1) && is_ind(A, f->kid[1], depth + 1);
        if (f->op == FIELD_SUB && is_const(f->kid[0], &c) && c == 1)
            return is_ind(A, f->kid[1], depth + 1);
        return 0;
    default: return 0;
    }
}

/* f as a x + b y + c z + d in the frame's coordinates (depth-limited). */
static int affine_of(const field *f, double r[4], int depth)
{
    if (depth > 64)
        return 0;
    double p[4], q[4], c;
    switch (f->kind) {
    case FK_CONST:
        if (!isfinite(f->k[0]))
            return 0;
        r[0] = r[1] = r[2] = 0;
        r[3] = f->k[0];
        return 1;
    case FK_COORD:
        r[0] = r[1] = r[2] = r[3] = 0;
        r[f->op] = 1;
        return 1;
    case FK_AFFINE:
        if (!affine_of(f->kid[0], p, depth + 1))
            return 0;
        for (int i = 0; i < 4; i++)
            r[i] = f->k[0] * p[i];
        r[3] += f->k[1];
        return 1;
    case FK_UNARY:
        if (f->op != FIELD_NEG || !affine_of(f->kid[0], p, depth + 1))
            return 0;
        for (int i = 0; i < 4; i++)
            r[i] = -p[i];
        return 1;
    case FK_BINARY:
        switch (f->op) {
        case FIELD_ADD:
        case FIELD_SUB:
            if (!affine_of(f->kid[0], p, depth + 1) || !affine_of(f->kid[1], q, depth + 1))
                return 0;
            for (int i = 0; i < 4; i++)
                r[i] = f->op == FIELD_ADD ? p[i] + q[i] : p[i] - q[i];
            return 1;
        case FIELD_MUL:
            if (is_const(f->kid[0], &c) && affine_of(f->kid[1], p, depth + 1)) {
            } else if (is_const(f->kid[1], &c) && affine_of(f->kid[0], p, depth + 1)) {
            } else {
                return 0;
            }
            for (int i = 0; i < 4; i++)
                r[i] = c * p[i];
            return 1;
        case FIELD_DIV:
            if (!is_const(f->kid[1], &c) || c == 0 || !affine_of(f->kid[0], p, depth + 1))
                return 0;
            for (int i = 0; i < 4; i++)
                r[i] = p[i] / c;
            return 1;
        default: return 0;
        }
    default: return 0;
    }
}

/* Eigenvalues of the symmetric 3x3 matrix a (closed form), largest and
 * smallest. */
static void sym_eig(const double a[3][3], double *emax, double *emin)
{
    double p1 = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    double q = (a[0][0] + a[1][1] + a[2][2]) / 3;
    if (p1 <= 1e-300) {
        double d[3] = {a[0][0], a[1][1], a[2][2]};
        *emax = fmax(d[0], fmax(d[1], d[2]));
        *emin = fmin(d[0], fmin(d[1], d[2]));
        return;
    }
    double p2 = (a[0][0] - q) * (a[0][0] - q) + (a[1][1] - q) * (a[1][1] - q) +
                (a[2][2] - q) * (a[2][2] - q) + 2 * p1;
    double p = sqrt(p2 / 6), b[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            b[i][j] = (a[i][j] - (i == j ? q : 0)) / p;
    double r = (b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1]) -
                b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0]) +
                b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])) /
               2;
    double phi = r <= -1 ? PI_ / 3 : r >= 1 ? 0 : acos(r) / 3;
    *emax = q + 2 * p * cos(phi);
    *emin = q + 2 * p * cos(phi + 2 * PI_ / 3);
}

/* A warp whose three coordinate fields are affine: sigma_max of the map and
 * whether it is a similarity. 0 if not affine or degenerate. */
static int warp_scale(const field *w, double *smax, int *similar)
{
    double m[3][4];
    for (int i = 0; i < 3; i++)
        if (!affine_of(w->kid[1 + i], m[i], 0))
            return 0;
    double a[3][3]; /* M^T M */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            a[i][j] = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
    double emax, emin;
    sym_eig(a, &emax, &emin);
    if (!(emax > 0) || !isfinite(emax) || !(emin > 1e-18 * emax))
        return 0;
    *smax = sqrt(emax);
    *similar = emax - emin <= 1e-9 * emax;
    return 1;
}

static field *neg(an *A, field *g)
{
    return g ? made(A, field_unary(FIELD_NEG, g)) : NULL;
}

/* op(a, b) of two results; either NULL gives NULL (releasing the other). */
static field *pair(an *A, field_binop op, field *a, field *b)
{
    if (!a || !b) {
        field_unref(a);
        field_unref(b);
        return NULL;
    }
    return made(A, field_binary(op, a, b));
}

/* g of an affine warp: child distance at the warped point, divided by
 * sigma_max. */
static field *warp_of(an *A, const field *w, field *g, int *exact)
{
    double smax;
    int similar;
    if (!g)
        return NULL;
    if (!warp_scale(w, &smax, &similar)) {
        field_unref(g);
        return NULL;
    }
    if (!similar)
        *exact = 0;
    field *h = made(A, field_warp(g, field_ref(w->kid[1]), field_ref(w->kid[2]),
                                  field_ref(w->kid[3])));
    if (h && smax != 1)
        h = made(A, field_affine(h, 1 / smax, 0));
    return h;
}

static double bias_exp(double b) { return log(b) / log(0.5); }

static field *lsdf(an *A, const field *f, double L, int *exact, int depth);

/* The complement {f < L}: -g. */
static field *lsdf_neg(an *A, const field *f, double L, int *exact, int depth)
{
    return neg(A, lsdf(A, f, L, exact, depth));
}

static field *lsdf_binary(an *A, const field *f, double L, int *exact, int depth)
{
    const field *a = f->kid[0], *b = f->kid[1];
    double c;
    int ca = is_const(a, &c) ? 1 : 0, cb = !ca && is_const(b, &c);
    switch (f->op) {
    case FIELD_GE:
    case FIELD_GT:
        if (!level_ok(L))
            return NULL;
        if (cb)
            return lsdf(A, a, c, exact, depth);
        if (ca) /* c >= b: b <= c */
            return lsdf_neg(A, b, c, exact, depth);
        return NULL;
    case FIELD_LE:
    case FIELD_LT:
        if (!level_ok(L))
            return NULL;
        if (cb)
            return lsdf_neg(A, a, c, exact, depth);
        if (ca)
            return lsdf(A, b, c, exact, depth);
        return NULL;
    case FIELD_MIN:
    case FIELD_MAX:
        *exact = 0;
        return pair(A, f->op == FIELD_MIN ? FIELD_MAX : FIELD_MIN, lsdf(A, a, L, exact, depth),
                    lsdf(A, b, L, exact, depth));
    case FIELD_MUL:
        if (ca || cb) {
            if (!(c > 0))
                return NULL;
            return lsdf(A, ca ? b : a, L / c, exact, depth);
        }
        goto indicators; /* a product of indicators is their intersection */
    case FIELD_AND:
    case FIELD_OR:
    indicators:
        if (!level_ok(L) || !is_ind(A, a, 0) || !is_ind(A, b, 0))
            return NULL;
        *exact = 0;
        return pair(A, f->op == FIELD_OR ? FIELD_MIN : FIELD_MAX, lsdf(A, a, 0.5, exact, depth),
                    lsdf(A, b, 0.5, exact, depth));
    case FIELD_DIV:
        if (!cb || !(c > 0))
            return NULL;
        return lsdf(A, a, L * c, exact, depth);
    case FIELD_ADD:
        if (!ca && !cb)
            return NULL;
        return lsdf(A, ca ? b : a, L - c, exact, depth);
    case FIELD_SUB:
        if (cb)
            return lsdf(A, a, L + c, exact, depth);
        if (ca) /* c - b >= L: b <= c - L */
            return lsdf_neg(A, b, c - L, exact, depth);
        return NULL;
    default: return NULL;
    }
}

/* g with {g <= 0} = {f >= L}, or NULL. */
static field *lsdf(an *A, const field *f, double L, int *exact, int depth)
{
    depth++;
    if (--A->budget < 0 || depth > 1000 || !isfinite(L) || A->oom)
        return NULL;
    switch (f->kind) {
    case FK_DENSITY:
        if (!level_ok(L))
            return NULL;
        if (!density_sdf_exact(&f->shape, L))
            *exact = 0;
        return made(A, field_shape_sdf(&f->shape, L));
    case FK_STEP:
        return level_ok(L) ? lsdf(A, f->kid[0], f->k[0], exact, depth) : NULL;
    case FK_WARP: return warp_of(A, f, lsdf(A, f->kid[0], L, exact, depth), exact);
    case FK_UNARY:
        if (f->op == FIELD_NEG)
            return lsdf_neg(A, f->kid[0], -L, exact, depth);
        if (f->op == FIELD_NOT && level_ok(L) && is_ind(A, f->kid[0], 0))
            return lsdf_neg(A, f->kid[0], 0.5, exact, depth);
        return NULL;
    case FK_BINARY: return lsdf_binary(A, f, L, exact, depth);
    case FK_AFFINE: {
        double a = f->k[0], b = f->k[1];
        if (a > 0)
            return lsdf(A, f->kid[0], (L - b) / a, exact, depth);
        if (a < 0)
            return lsdf_neg(A, f->kid[0], (L - b) / a, exact, depth);
        return NULL;
    }
    case FK_CLAMP: {
        double lo, hi;
        if (!is_const(f->kid[1], &lo) || !is_const(f->kid[2], &hi) || !(lo < L && L <= hi))
            return NULL;
        return lsdf(A, f->kid[0], L, exact, depth);
    }
    case FK_BIAS: /* clamp01(t)^k >= L with k > 0: t >= L^(1/k) */
        if (!level_ok(L) || !(f->k[0] > 0 && f->k[0] < 1))
            return NULL;
        return lsdf(A, f->kid[0], pow(L, 1 / bias_exp(f->k[0])), exact, depth);
    case FK_GAIN: {
        if (!level_ok(L) || !(f->k[0] > 0 && f->k[0] < 1))
            return NULL;
        double k = bias_exp(1 - f->k[0]);
        double t = L < 0.5 ? 0.5 * pow(2 * L, 1 / k) : 1 - 0.5 * pow(2 * (1 - L), 1 / k);
        return lsdf(A, f->kid[0], t, exact, depth);
    }
    case FK_SMOOTHSTEP: {
        double e0 = f->k[0], e1 = f->k[1];
        if (!level_ok(L))
            return NULL;
        if (e1 == e0) /* a step */
            return lsdf(A, f->kid[0], e0, exact, depth);
        if (!(e1 > e0))
            return NULL;
        /* u^2 (3 - 2u) = L on [0, 1] */
        double u = L >= 1 ? 1 : 0.5 - sin(asin(1 - 2 * L) / 3);
        return lsdf(A, f->kid[0], e0 + u * (e1 - e0), exact, depth);
    }
    default: return NULL;
    }
}

/* g with f = 0 (or NaN) wherever g > 0, or NULL. */
static field *support(an *A, const field *f, int depth)
{
    depth++;
    if (--A->budget < 0 || depth > 1000 || A->oom)
        return NULL;
    if (is_ind(A, f, 0)) {
        int exact = 1;
        return lsdf(A, f, 0.5, &exact, depth);
    }
    switch (f->kind) {
    case FK_WARP: {
        int exact = 1;
        return warp_of(A, f, support(A, f->kid[0], depth), &exact);
    }
    case FK_AFFINE:
        return f->k[1] == 0 ? support(A, f->kid[0], depth) : NULL;
    case FK_BIAS:
    case FK_GAIN: return support(A, f->kid[0], depth);
    case FK_BINARY:
        switch (f->op) {
        case FIELD_MUL: {
            field *a = support(A, f->kid[0], depth), *b = support(A, f->kid[1], depth);
            if (a && b)
                return made(A, field_binary(FIELD_MAX, a, b));
            return a ? a : b;
        }
        case FIELD_DIV: return support(A, f->kid[0], depth);
        case FIELD_MAX:
            return pair(A, FIELD_MIN, support(A, f->kid[0], depth), support(A, f->kid[1], depth));
        default: return NULL;
        }
    default: return NULL;
    }
}

rt_code field_level_sdf(const field *f, double level, field **g, int *exact, rt_error *e)
{
    an A = {FIELD_SDF_BUDGET, 0};
    int ex = 1;
    *g = f ? lsdf(&A, f, level, &ex, 0) : NULL;
    if (A.oom) {
        field_unref(*g);
        *g = NULL;
        return rt_fail(e, RT_ENOMEM, "out of memory deriving a distance field");
    }
    if (exact)
        *exact = *g ? ex : 0;
    return RT_OK;
}

rt_code field_hard_support(const field *f, field **g, rt_error *e)
{
    an A = {FIELD_SDF_BUDGET, 0};
    *g = f ? support(&A, f, 0) : NULL;
    if (A.oom) {
        field_unref(*g);
        *g = NULL;
        return rt_fail(e, RT_ENOMEM, "out of memory deriving a distance field");
    }
    return RT_OK;
}

static rt_code compile_opt(field *g, field_prog **out, rt_error *e)
{
    *out = NULL;
    if (!g)
        return RT_OK;
    *out = field_compile(g, e);
    field_unref(g); /* the program keeps its own reference */
    return *out ? RT_OK : e->code;
}

rt_code field_prog_level_sdf(const field_prog *p, double level, field_prog **out, int *exact,
                             rt_error *e)
{
    field *g;
    *out = NULL;
    rt_code c = field_level_sdf(p->root, level, &g, exact, e);
    return c ? c : compile_opt(g, out, e);
}

rt_code field_prog_hard_support(const field_prog *p, field_prog **out, rt_error *e)
{
    field *g;
    *out = NULL;
    rt_code c = field_hard_support(p->root, &g, e);
    return c ? c : compile_opt(g, out, e);
}
