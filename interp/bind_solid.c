/* bind_solid.c — seed 000 in the language: the 3-D random fractal D(P)
 * (midpoint displacement, Types I–IV) as a field, the marble and wood base
 * functions, the perturbation P' = F(P, D(P)), objects cut out of a solid
 * texture and planar slices. The reference for scripts is docs/solid.md;
 * the engines are runtime/mpd.h, runtime/solid.h and runtime/texobj.h.
 *
 * Everything a script builds here is a *field* (runtime/field.h): the
 * fractal and the base functions are external nodes, the perturbation is a
 * warp node, so solid textures combine with every other field (arithmetic,
 * noise, densities, sample, isosurface, raymarch, at) and user-defined base
 * functions and perturbations are plain field expressions. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "field.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "mpd.h"
#include "solid.h"
#include "texobj.h"
#include "report.h"

#define AUTO_BUDGET ((size_t)64 << 20) /* automatic strategy: largest array it builds */

/* ---- small helpers ------------------------------------------------------------------ */

/* A vec3 argument (declared: 3 finite numbers) copied out. */
static int get_vec3(interp *I, value v, double out[3], const char *what)
{
    return builtin_get_vec(I, v, out, 3, what);
}

/* An axis: "x", "y", "z" or a non-zero vector; normalised. */
static int get_axis(interp *I, value v, double a[3], const char *what)
{
    if (v.k == V_STR) { /* declared str{x,y,z}|vec3 */
        const char *s = AS_STR(v)->s;
        a[0] = a[1] = a[2] = 0;
        a[s[0] - 'x'] = 1;
        return 0;
    }
    if (get_vec3(I, v, a, what))
        return -1;
    double l = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(l > 0))
        return err_value(I, v, ERR_VALUE, "%s: the vector (0, 0, 0) has no direction", what);
    for (int i = 0; i < 3; i++)
        a[i] /= l;
    return 0;
}

/* Graph shorthands (constructors consume their arguments; NULL propagates). */
static field *fadd(field *a, field *b) { return field_binary(FIELD_ADD, a, b); }
static field *fsub(field *a, field *b) { return field_binary(FIELD_SUB, a, b); }
static field *fmul(field *a, field *b) { return field_binary(FIELD_MUL, a, b); }
static field *fref(field *f) { return f ? field_ref(f) : NULL; }

/* sum + term, the first term alone: a failed term (NULL) makes the whole sum
 * NULL — testing `sum ? … : term` would restart the sum after a failure and
 * silently drop its terms. */
static field *fsum(field *sum, field *term, int *terms)
{
    return (*terms)++ ? fadd(sum, term) : term;
}

/* s * f, without a multiplication when s is 1. */
static field *fscaled(double s, field *f)
{
    if (s == 1)
        return f;
    return fmul(field_const(s), f);
}

/* The coordinate along a unit axis, dot(P - o, a); the bare coordinate
 * node for a coordinate axis through the origin. */
static field *axis_coord(const double a[3], const double o[3])
{
    field *s = NULL;
    int terms = 0;
    for (int i = 0; i < 3; i++) {
        if (a[i] == 0)
            continue;
        field *c = field_coord(i);
        if (o[i] != 0)
            c = fsub(c, field_const(o[i]));
        c = fscaled(a[i], c);
        s = fsum(s, c, &terms);
    }
    return s;
}

/* warp(base, P + kD a): the linear perturbation along a unit axis (eq. (7)
 * for a = +z). Consumes base and kd. */
static field *warp_linear(field *base, field *kd, const double a[3])
{
    field *p[3];
    for (int i = 0; i < 3; i++) {
        p[i] = field_coord(i);
        if (a[i] != 0)
            p[i] = fadd(p[i], fscaled(a[i], fref(kd)));
    }
    field_unref(kd);
    return field_warp(base, p[0], p[1], p[2]);
}

/* warp(base, P + kD u), u the unit vector from the line o + s a to P (0 on
 * the line): the radial perturbation of wood. Consumes base and kd. */
static field *warp_radial(field *base, field *kd, const double a[3], const double o[3])
{
    field *d[3], *q[3] = {NULL, NULL, NULL}, *p[3];
    for (int i = 0; i < 3; i++) {
        d[i] = field_coord(i);
        if (o[i] != 0)
            d[i] = fsub(d[i], field_const(o[i]));
    }
    /* q = (P - o) - ((P - o) . a) a, the part of P - o across the axis;
     * along a coordinate axis it is just the other two components. */
    int j = -1;
    for (int i = 0; i < 3; i++)
        if (fabs(a[i]) == 1)
            j = i;
    if (j >= 0) {
        for (int i = 0; i < 3; i++)
            q[i] = i == j ? NULL : d[i];
        field_unref(d[j]);
    } else {
        field *t = NULL;
        int terms = 0;
        for (int i = 0; i < 3; i++)
            if (a[i] != 0) {
                field *c = fscaled(a[i], fref(d[i]));
                t = fsum(t, c, &terms);
            }
        for (int i = 0; i < 3; i++)
            q[i] = a[i] != 0 ? fsub(d[i], fscaled(a[i], fref(t))) : d[i];
        field_unref(t);
    }
    field *r2 = NULL;
    int terms2 = 0;
    for (int i = 0; i < 3; i++)
        if (i != j) {
            field *sq = fmul(fref(q[i]), fref(q[i]));
            r2 = fsum(r2, sq, &terms2);
        }
    field *r = field_unary(FIELD_SQRT, r2);
    /* s = r > 0 ? kD / r : 0 */
    /* in sequence: the division consumes r (and frees it if it fails), so r
     * must be referenced for the comparison first, not in whatever order the
     * compiler evaluates arguments */
    field *gt = field_binary(FIELD_GT, fref(r), field_const(0));
    field *div = field_binary(FIELD_DIV, kd, r);
    field *s = field_select(gt, div, field_const(0));
    for (int i = 0; i < 3; i++)
        p[i] = i == j ? field_coord(i) : fadd(field_coord(i), fmul(fref(s), q[i]));
    field_unref(s);
    return field_warp(base, p[0], p[1], p[2]);
}

/* k * D as a node (consumes nothing; NULL with an error on failure). */
static field *kd_node(interp *I, value fluct, double k, const char *what)
{
    field *d = lang_to_field(I, fluct, what);
    if (!d)
        return NULL;
    field *kd = fscaled(k, d);
    if (!kd)
        err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    return kd;
}

/* A compiled texture program for (texture - lo) / (hi - lo). */
static int texture_prog(interp *I, value v, double lo, double hi, field **tmp, field_prog **own,
                        const field_prog **prog, const char *who, const char *what)
{
    if (!(hi > lo) || !isfinite(lo) || !isfinite(hi))
        return err_at(I, NULL, ERR_VALUE, "%s: the palette range needs finite lo < hi, got %g and %g", who, lo, hi);
    if (lo == 0 && hi == 1)
        return lang_field_fn(I, v, tmp, own, prog, what);
    *tmp = NULL;
    *own = NULL;
    field *f = lang_to_field(I, v, what);
    if (!f)
        return -1;
    f = field_affine(f, 1.0 / (hi - lo), -lo / (hi - lo));
    if (!f)
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    rt_error e;
    *own = field_compile(f, &e);
    if (!*own) {
        field_unref(f);
        return lang_rt_error(I, e.code, &e, what);
    }
    *tmp = f;
    *prog = *own;
    return 0;
}

/* ---- fractal: D(P) as a field --------------------------------------------------------- */

typedef struct frac_ctx {
    mpd m;
    double lo[3], ext[3]; /* world box: P -> (P - lo) / ext */
    int unit;             /* the box is the unit cube: no mapping */
    interp *I;
} frac_ctx;

static void frac_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    const frac_ctx *c = ctx;
    if (c->unit) {
        mpd_eval(&c->m, n, x, y, z, out);
        return;
    }
    double u[RT_BLOCK], v[RT_BLOCK], w[RT_BLOCK];
    for (size_t s = 0; s < n; s += RT_BLOCK) {
        size_t k = n - s < RT_BLOCK ? n - s : RT_BLOCK;
        for (size_t i = 0; i < k; i++) {
            u[i] = (x[s + i] - c->lo[0]) / c->ext[0];
            v[i] = (y[s + i] - c->lo[1]) / c->ext[1];
            w[i] = (z[s + i] - c->lo[2]) / c->ext[2];
        }
        mpd_eval(&c->m, k, u, v, w, out + s);
    }
}

static void frac_release(void *ctx)
{
    frac_ctx *c = ctx;
    mpd_free(&c->m);
    rt_free(c);
}

static const char *roman[5] = {"auto", "I", "II", "III", "IV"};

/* The automatic strategy's byte budget: 64 MiB, or --max-memory if less. */
static size_t auto_budget(const interp *I)
{
    return AUTO_BUDGET < I->lim.max_memory ? AUTO_BUDGET : I->lim.max_memory;
}

/* Lattice nodes of a Type I array at level R: (2^R + 1)^3. */
static double lattice_nodes(int R)
{
    double n = ldexp(1.0, R) + 1;
    return n * n * n;
}

/* R is declared TY_R: a whole number 1 .. MPD_MAX_R. */
#define TY_R "int[1,20]"
_Static_assert(MPD_MAX_R == 20, "TY_R writes MPD_MAX_R out");

static int b_fractal(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "fractal";
    mpd_params p;
    mpd_params_default(&p);
    p.R = (int)a[0].u.n;
    p.beta = a[1].u.n; /* declared: finite, >= 0 */
    if (lang_arg_seed(I, a[2], &p.seed, W))
        return -1;
    if (a[3].k == V_NUM) {
        for (int i = 0; i < 8; i++)
            p.corner[i] = a[3].u.n;
    } else if (a[3].k != V_NIL && builtin_get_vec(I, a[3], p.corner, 8, "fractal: corners")) {
        return -1;
    }
    /* declared str|int[1,4]: "auto" or Types I-IV (the message for a
     * wrong string names both forms) */
    if (a[4].k == V_STR && strcmp(AS_STR(a[4])->s, "auto") != 0)
        return err_arg(I, 4, ERR_VALUE, "fractal: strategy must be \"auto\" or 1, 2, 3, 4 (Types I-IV), got \"%s\"",
                       AS_STR(a[4])->s);
    int type = a[4].k == V_STR ? MPD_AUTO : (int)a[4].u.n;
    int R2 = -1;
    if (a[5].k != V_NIL) {
        if (type != MPD_AUTO && type != MPD_TYPE4)
            return err_at(I, NULL, ERR_VALUE, "fractal: R2 is only used by Type IV (strategy: 4), not Type %s",
                          roman[type]);
        if (a[5].u.n != floor(a[5].u.n) || a[5].u.n < 0 || a[5].u.n > p.R)
            return err_at(I, NULL, ERR_VALUE, "fractal: R2 = %g is out of range (expected a whole number 0 .. R = %d)",
                          a[5].u.n, p.R);
        R2 = (int)a[5].u.n;
        type = MPD_TYPE4;
    }
    double lo[3], hi[3];
    if (lang_get_box(I, a[6], a[7], lo, hi, W))
        return -1;

    /* The automatic strategy: Type I when its array fits the budget and
     * --max-voxels, else Type IV with the largest array that does (Type III
     * if none). */
    size_t maxmem = I->lim.max_memory;
    size_t budget = auto_budget(I);
    double maxnodes = I->lim.max_voxels;
    if (type == MPD_AUTO) {
        if (mpd_type1_bytes(p.R) <= budget && lattice_nodes(p.R) <= maxnodes) {
            type = MPD_TYPE1;
        } else {
            R2 = mpd_largest_r2(p.R, budget, maxnodes);
            type = R2 >= 0 ? MPD_TYPE4 : MPD_TYPE3;
        }
    }
    if (type == MPD_TYPE4 && R2 < 0)
        R2 = mpd_largest_r2(p.R, budget, maxnodes) < 0 ? 0 : mpd_largest_r2(p.R, budget, maxnodes);
    p.type = type;
    p.R2 = R2;
    p.mem_limit = maxmem;
    p.budget = budget;
    p.max_nodes = maxnodes;
    size_t bytes = type == MPD_TYPE1 ? mpd_type1_bytes(p.R) : type == MPD_TYPE4 ? mpd_type1_bytes(R2) : 0;
    double nodes = type == MPD_TYPE1 ? lattice_nodes(p.R) : type == MPD_TYPE4 ? lattice_nodes(R2) : 0;
    /* Arrays beyond --max-memory or --max-voxels are refused by mpd_init
     * with a message that names the strategy that fits; within them, check
     * the budget first for a clear message (the allocation hook counts the
     * array itself). */
    if (bytes && bytes <= maxmem && nodes <= maxnodes) {
        char what[64];
        snprintf(what, sizeof what, "fractal: the Type %s array", roman[type]);
        if (mem_precheck(I, (double)bytes, what))
            return -1;
    }
    frac_ctx *c = mem_calloc(I, 1, sizeof *c);
    if (!c) {
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    rt_run run = lang_run(I);
    rt_error e;
    double t0 = report_clock();
    rt_code rc = mpd_init(&c->m, &p, &run, &e);
    if (!rc && bytes)
        report_work(I, "midpoint displacement", "lattice points",
                    pow(ldexp(1.0, type == MPD_TYPE1 ? p.R : R2) + 1, 3), t0);
    if (rc) {
        mem_free(I, c);
        if (rc == RT_EINVAL && bytes > maxmem) /* the array is over --max-memory */
            return err_at(I, NULL, ERR_LIMIT, "fractal: %s (the limit is --max-memory)", e.msg);
        if (rc == RT_EINVAL && nodes > maxnodes) /* the array is over --max-voxels */
            return err_at(I, NULL, ERR_LIMIT, "fractal: %s (the limit is --max-voxels)", e.msg);
        return lang_rt_error(I, rc, &e, W);
    }
    c->I = I;
    c->unit = 1;
    for (int i = 0; i < 3; i++) {
        c->lo[i] = lo[i];
        c->ext[i] = hi[i] - lo[i];
        if (lo[i] != 0 || hi[i] != 1)
            c->unit = 0;
    }
    char name[32];
    if (c->m.type == MPD_TYPE4)
        snprintf(name, sizeof name, "fractal(R %d, IV, R2 %d)", c->m.R, c->m.R2);
    else
        snprintf(name, sizeof name, "fractal(R %d, %s)", c->m.R, roman[c->m.type]);
    return lang_field_value(I, field_external(frac_fn, c, frac_release, name), out);
}

static int rec_num(interp *I, value r, const char *key, double v)
{
    return val_rec_set(I, AS_REC(r), interp_intern(I, key, strlen(key)), val_num(v));
}

/* fractal_memory(R, R2): the bytes each strategy needs, as this
 * implementation uses them. */
static int b_fractal_memory(interp *I, value *a, int n, value *out)
{
    (void)n;
    int R = (int)a[0].u.n;
    int R2;
    if (a[1].k == V_NIL) {
        R2 = mpd_largest_r2(R, auto_budget(I), I->lim.max_voxels);
        if (R2 < 0)
            R2 = 0;
    } else {
        if (a[1].u.n != floor(a[1].u.n) || a[1].u.n < 0 || a[1].u.n > R)
            return err_at(I, NULL, ERR_VALUE,
                          "fractal_memory: R2 = %g is out of range (expected a whole number 0 .. R = %d)", a[1].u.n, R);
        R2 = (int)a[1].u.n;
    }
    value r = val_rec(I);
    if (r.k == V_NIL)
        return -1;
    double n1 = ldexp(1.0, R) + 1;
    if (rec_num(I, r, "type1", 4.0 * n1 * n1 * n1) || rec_num(I, r, "type3", (double)mpd_path_bytes(R)) ||
        rec_num(I, r, "type4", (double)mpd_type4_bytes(R, R2)) || rec_num(I, r, "R2", R2) ||
        rec_num(I, r, "nodes", n1 * n1 * n1)) {
        val_unref(I, r);
        return -1;
    }
    *out = r;
    return 0;
}

/* ---- base functions and perturbation ------------------------------------------------- */

static int b_marble(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *t = AS_LIST(a[0]);
    if (t->n < 1 || t->n > SOLID_MAX_LAYERS)
        return err_at(I, NULL, ERR_VALUE, "marble: layers must be a table of 1 to %d rows `c w alpha`, got %zu rows",
                      SOLID_MAX_LAYERS, t->n);
    solid_marble *m = mem_calloc(I, 1, sizeof *m);
    if (!m)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    m->n = (int)t->n;
    for (size_t i = 0; i < t->n; i++) {
        value row = t->items[i];
        double v[3];
        if (row.k != V_LIST || AS_LIST(row)->n != 3) {
            mem_free(I, m);
            return err_at(I, NULL, ERR_VALUE, "marble: layer %zu must be a row `c w alpha` of 3 numbers, got %s", i + 1,
                          row.k == V_LIST ? "a row of another length" : val_type_name(row));
        }
        char w[48];
        snprintf(w, sizeof w, "marble: layer %zu", i + 1);
        if (builtin_get_vec(I, row, v, 3, w)) {
            mem_free(I, m);
            return -1;
        }
        m->layer[i].c = v[0];
        m->layer[i].w = v[1];
        m->layer[i].alpha = v[2];
    }
    rt_error e;
    double ax[3];
    if (solid_marble_check(m, &e)) {
        mem_free(I, m);
        return err_at(I, NULL, ERR_VALUE, "%s", e.msg);
    }
    if (get_axis(I, a[3], ax, "marble: axis")) {
        mem_free(I, m);
        return -1;
    }
    field *g = field_external(solid_marble_fn, m, rt_free, "marble");
    if (!g)
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    /* G is a function of z; the layers lie across `axis`: evaluate it at
     * z := P . a (+ k D(P): eq. (7) along the axis). */
    static const double zero[3] = {0, 0, 0};
    field *s = axis_coord(ax, zero);
    if (a[1].k != V_NIL) {
        field *kd = kd_node(I, a[1], a[2].u.n, "marble: fluct");
        if (!kd) {
            field_unref(g);
            field_unref(s);
            return -1;
        }
        s = fadd(s, kd);
    } else if (ax[2] == 1) {
        field_unref(s);
        return lang_field_value(I, g, out);
    }
    return lang_field_value(I, field_warp(g, field_coord(0), field_coord(1), s), out);
}

static int b_wood(interp *I, value *a, int n, value *out)
{
    (void)n;
    solid_wood *w = mem_calloc(I, 1, sizeof *w);
    if (!w)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    w->spacing = a[0].u.n;
    w->sharpness = a[1].u.n;
    rt_error e;
    if (get_axis(I, a[2], w->axis, "wood: axis") || get_vec3(I, a[3], w->origin, "wood: origin")) {
        mem_free(I, w);
        return -1;
    }
    if (solid_wood_check(w, &e)) {
        mem_free(I, w);
        return err_at(I, NULL, ERR_VALUE, "%s", e.msg);
    }
    double ax[3], o[3];
    memcpy(ax, w->axis, sizeof ax);
    memcpy(o, w->origin, sizeof o);
    field *g = field_external(solid_wood_fn, w, rt_free, "wood");
    if (!g)
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    if (a[4].k == V_NIL)
        return lang_field_value(I, g, out);
    field *kd = kd_node(I, a[4], a[5].u.n, "wood: fluct");
    if (!kd) {
        field_unref(g);
        return -1;
    }
    return lang_field_value(I, warp_radial(g, kd, ax, o), out);
}

static int b_perturb(interp *I, value *a, int n, value *out)
{
    (void)n;
    double ax[3], o[3];
    const char *mode = AS_STR(a[3])->s;
    int radial = strcmp(mode, "radial") == 0; /* declared str{linear,radial} */
    if (get_axis(I, a[4], ax, "perturb: axis") ||
        get_vec3(I, a[5], o, "perturb: origin"))
        return -1;
    field *base = lang_to_field(I, a[0], "perturb: base");
    if (!base)
        return -1;
    field *kd = kd_node(I, a[1], a[2].u.n, "perturb: fluct");
    if (!kd) {
        field_unref(base);
        return -1;
    }
    return lang_field_value(I, radial ? warp_radial(base, kd, ax, o) : warp_linear(base, kd, ax), out);
}

/* ---- textured objects and slices ------------------------------------------------------ */

static int b_textured(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "textured";
    texobj_shape s;
    memset(&s, 0, sizeof s);
    const char *obj = AS_STR(a[1])->s;
    static const char *kinds[4] = {"sphere", "cube", "cylinder", "plane"};
    s.kind = 0; /* declared str{sphere,cube,cylinder,plane} */
    for (int i = 0; i < 4; i++)
        if (strcmp(obj, kinds[i]) == 0)
            s.kind = i;
    camera cam;
    int w, h;
    ramp r;
    if ((a[2].k != V_NIL && lang_get_camera(I, a[2], &cam, W)) || lang_arg_size2(I, a[3], &w, &h, "textured: size") ||
        lang_get_ramp(I, a[4], &r, "textured: palette") || get_vec3(I, a[7], s.center, "textured: center") ||
        get_vec3(I, a[10], s.normal, "textured: normal"))
        return -1;
    s.radius = a[8].u.n;
    s.height = a[9].u.n;
    rt_error e;
    if (texobj_shape_check(&s, &e))
        return err_at(I, NULL, ERR_VALUE, "textured: %s", e.msg);
    if (a[2].k == V_NIL) {
        /* the one default framing, of the object's bounding sphere (a plane: the disc of `radius`) */
        double br = s.kind == TEXOBJ_CUBE ? s.radius * sqrt(3.0)
                   : s.kind == TEXOBJ_CYLINDER ? sqrt(s.radius * s.radius + 0.25 * s.height * s.height)
                                               : s.radius;
        if (camera_frame_sphere(&cam, s.center, br, w, h, 30, 20, 40))
            return err_at(I, NULL, ERR_VALUE, "textured: cannot frame the object");
    }
    texobj_opts o;
    texobj_opts_default(&o);
    if (get_vec3(I, a[11], o.light, "textured: light"))
        return -1;
    if (o.light[0] == 0 && o.light[1] == 0 && o.light[2] == 0)
        return err_at(I, NULL, ERR_VALUE, "textured: light (0, 0, 0) has no direction");
    o.ambient = a[12].u.n; /* declared num[0,1] */
    o.diffuse = a[13].u.n;
    if (lang_get_colour(I, a[14], o.background, "textured: background"))
        return -1;
    o.samples = (int)a[15].u.n; /* declared int[1,8] */
    field *tmp;
    field_prog *own;
    const field_prog *prog;
    if (texture_prog(I, a[0], a[5].u.n, a[6].u.n, &tmp, &own, &prog, W, "textured: texture"))
        return -1;
    image *im;
    value res;
    if (lang_image_new(I, w, h, &im) || lang_image_value(I, im, &res)) {
        lang_field_fn_done(tmp, own);
        return -1;
    }
    texobj_source src = {.field = field_prog_fn, .field_ctx = prog, .ramp = &r};
    rt_run run = lang_run(I);
    double t0 = report_clock();
    rt_code rc = texobj_render(&s, &cam, &src, &o, &run, im, NULL, &e);
    if (!rc)
        report_work(I, "textured", "pixels", (double)im->w * im->h, t0);
    lang_field_fn_done(tmp, own);
    if (rc) {
        val_unref(I, res);
        return lang_rt_error(I, rc, &e, W);
    }
    *out = res;
    return 0;
}

static int b_slice_plane(interp *I, value *a, int n, value *out)
{
    (void)n;
    double o[3], u[3], v[3];
    int w, h;
    ramp r;
    if (get_vec3(I, a[1], o, "slice_plane: origin") || get_vec3(I, a[2], u, "slice_plane: u") ||
        get_vec3(I, a[3], v, "slice_plane: v") || lang_arg_size2(I, a[4], &w, &h, "slice_plane: size") ||
        lang_get_ramp(I, a[5], &r, "slice_plane: palette"))
        return -1;
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    if (c[0] == 0 && c[1] == 0 && c[2] == 0)
        return err_at(I, NULL, ERR_VALUE,
                      "slice_plane: u and v must span a plane, got [%g, %g, %g] and [%g, %g, %g] (zero or parallel)",
                      u[0], u[1], u[2], v[0], v[1], v[2]);
    field *tmp;
    field_prog *own;
    const field_prog *prog;
    if (texture_prog(I, a[0], a[6].u.n, a[7].u.n, &tmp, &own, &prog, "slice_plane", "slice_plane: field"))
        return -1;
    image *im;
    value res;
    if (lang_image_new(I, w, h, &im) || lang_image_value(I, im, &res)) {
        lang_field_fn_done(tmp, own);
        return -1;
    }
    rt_run run = lang_run(I);
    rt_error e;
    rt_code rc = texobj_slice(field_prog_fn, prog, &r, o, u, v, &run, im, &e);
    lang_field_fn_done(tmp, own);
    if (rc) {
        val_unref(I, res);
        return lang_rt_error(I, rc, &e, "slice_plane");
    }
    *out = res;
    return 0;
}

/* ---- registration --------------------------------------------------------------------- */

/* an axis: "x", "y", "z" or a direction vector */
#define TY_AXIS3 "str{x,y,z}|vec3"
static const bparam p_fractal[] = {{"R", TY_R, "8"},
                                   {"beta", "num>=0", "0.5"},
                                   {"seed", "int[0,9007199254740992]", "nil"},
                                   {"corners", "num|vec8", "nil"},
                                   {"strategy", "str|int[1,4]", "\"auto\""},
                                   {"R2", "int>=0", "nil"},
                                   {"lo", "vec3", "[-1, -1, -1]"},
                                   {"hi", "vec3", "[1, 1, 1]"}};
static const bparam p_fmem[] = {{"R", TY_R, NULL}, {"R2", "int>=0", "nil"}};
static const bparam p_marble[] = {{"layers", "list", NULL},
                                  {"fluct", "num|field|volume", "nil"},
                                  {"k", "num", "0.1"},
                                  {"axis", TY_AXIS3, "\"z\""}};
static const bparam p_wood[] = {{"spacing", "num", "0.1"},       {"sharpness", "num", "1"},
                                {"axis", TY_AXIS3, "\"z\""},    {"origin", "vec3", "[0, 0, 0]"},
                                {"fluct", "num|field|volume", "nil"}, {"k", "num", "0.02"}};
static const bparam p_perturb[] = {{"base", "num|field|volume", NULL}, {"fluct", "num|field|volume", NULL},
                                   {"k", "num", "0.1"},                {"mode", "str{linear,radial}", "\"linear\""},
                                   {"axis", TY_AXIS3, "\"z\""},        {"origin", "vec3", "[0, 0, 0]"}};
static const bparam p_textured[] = {
    {"texture", "num|field|volume", NULL}, {"object", "str{sphere,cube,cylinder,plane}", "\"sphere\""},
    {"camera", TY_CAMERA "|nil", "nil"}, {"size", TY_SIZE, "[256, 256]"},  {"palette", "list", "nil"},
    {"lo", "num", "0"},                    {"hi", "num", "1"},               {"center", "vec3", "[0, 0, 0]"},
    {"radius", "num", "1"},                {"height", "num", "2"},           {"normal", "vec3", "[0, 0, 1]"},
    {"light", "vec3", "[1, 1, 1]"},        {"ambient", "num[0,1]", "0.2"},   {"diffuse", "num[0,1]", "0.8"},
    {"background", TY_COLOUR, "0"},        {"supersample", "int[1,8]", "1"}};
static const bparam p_slice_plane[] = {{"field", "num|field|volume", NULL}, {"origin", "vec3", "[0, 0, 0]"},
                                       {"u", "vec3", "[1, 0, 0]"},          {"v", "vec3", "[0, 1, 0]"},
                                       {"size", TY_SIZE, "[256, 256]"},     {"palette", "list", "nil"},
                                       {"lo", "num", "0"},                  {"hi", "num", "1"}};

static const builtin solid_builtins[] = {
    BUILTIN("fractal", b_fractal, p_fractal,
            "The 3-D random fractal D(P) of seed 000 (midpoint displacement to level R, L(n) = exp(-(n-1) beta)) "
            "as a field over the box lo..hi, trilinear between lattice nodes. strategy: \"auto\", 1 (Type I: whole "
            "array), 2 (Type II: memoised parents), 3 (Type III: octree descent), 4 (Type IV: array to level R2, "
            "descent below); all give identical values. Arrays count against --max-memory and --max-voxels (a lattice "
            "node is a voxel); \"auto\" picks within both. corners: 8 numbers (index x + 2y + 4z) or one."),
    BUILTIN("fractal_memory", b_fractal_memory, p_fmem,
            "Bytes each strategy needs at level R: {type1, type3, type4, R2, nodes} (Type IV with array level R2; "
            "default: the automatic choice)."),
    BUILTIN("marble", b_marble, p_marble,
            "Marble layers of seed 000 eq. (6): G = sum of exp(-alpha d) (1 inside a layer), d = |z - c| - w/2, "
            "one table row `c w alpha` per layer, across `axis`; with fluct, evaluated at z + k D(P) (eq. (7))."),
    BUILTIN("wood", b_wood, p_wood,
            "Wood rings around the line through origin along axis: ((1 - cos(2 pi r / spacing)) / 2)^sharpness; "
            "with fluct, the radius is displaced by k D(P)."),
    BUILTIN("perturb", b_perturb, p_perturb,
            "The perturbation P' = F(P, D(P)) of any base field: mode \"linear\" moves P by k D along axis "
            "(eq. (7) for \"z\"), \"radial\" away from the line through origin along axis."),
    BUILTIN("textured", b_textured, p_textured,
            "An image of a sphere, cube, cylinder or plane cut out of a solid texture, seen by a camera (default: "
            "the object's bounding sphere framed as by framing(); a plane: the disc of radius): the "
            "texture is evaluated only at the visible surface points, mapped from lo..hi through the palette, "
            "and shaded by one directional light."),
    BUILTIN("slice_plane", b_slice_plane, p_slice_plane,
            "An image of the plane through origin spanned by u (right) and v (up), half sides; the field mapped "
            "from lo..hi through the palette."),
};

int bind_solid_init(interp *I)
{
    return BUILTIN_REGISTER(I, solid_builtins);
}
