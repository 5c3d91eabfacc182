/* bind_field.c — fields in the language (seed 001 §6, DESIGN.md "fields are
 * graphs").
 *
 * A field value wraps an immutable node of runtime/field.h. Arithmetic and
 * math functions on fields build new nodes (the class's arith hook), so a
 * user function applied to a field — `(d => bias(d, 0.7))(sphere())` —
 * builds a graph once; evaluation happens later, natively, in blocks. The
 * compiled program is cached on the value. Volumes mix with fields: they
 * become trilinear-sampled external nodes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "density.h"
#include "eval.h"
#include "field.h"
#include "fileio.h"
#include "isosurf.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lexer.h"
#include "raymarch.h"
#include "report.h"

typedef struct field_val {
    field *f;
    field_prog *prog; /* compiled on first use */
} field_val;

static void fv_destroy(void *p)
{
    field_val *fv = p;
    field_prog_free(fv->prog);
    field_unref(fv->f);
    rt_free(fv);
}

static void fv_summary(const void *p, bytebuf *out)
{
    const field_val *fv = p;
    bytebuf_printf(out, "field ");
    field_print(fv->f, out, 120);
}

static int fv_arith(interp *I, int op, value a, value b, value *out);
static int fv_preview(interp *I, const void *p, image **out);

const obj_class lang_field_class = {
    .name = "field",
    .destroy = fv_destroy,
    .summary = fv_summary,
    .arith = fv_arith,
    .preview = fv_preview,
};

static field_val *as_fv(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_field_class ? AS_OBJ(v)->payload : NULL;
}

/* Wrap a new node (consumes it). */
int lang_field_value(interp *I, field *f, value *out)
{
    if (!f)
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    field_val *fv = mem_calloc(I, 1, sizeof *fv);
    if (!fv) {
        field_unref(f);
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a field");
    }
    fv->f = f;
    *out = val_obj(I, &lang_field_class, fv);
    return out->k == V_NIL ? -1 : 0;
}

/* A volume sampled trilinearly, as a field node; the node keeps the volume
 * value alive through a reference held in its context. */
typedef struct vol_ref {
    interp *I;
    heap *h;
    const volume *v;
} vol_ref;

static void vol_field_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    const vol_ref *r = ctx;
    for (size_t i = 0; i < n; i++)
        out[i] = volume_sample(r->v, x[i], y[i], z[i]);
}

static void vol_release(void *ctx)
{
    vol_ref *r = ctx;
    val_heap_unref(r->I, r->h);
    rt_free(r);
}

/* A new reference to the field node for a field, number or volume value;
 * NULL (with an error) otherwise. */
field *lang_to_field(interp *I, value v, const char *what)
{
    field_val *fv = as_fv(v);
    if (fv)
        return field_ref(fv->f);
    if (v.k == V_NUM || v.k == V_BOOL) {
        field *c = field_const(v.k == V_NUM ? v.u.n : v.u.b);
        if (!c)
            mem_engine_error(I, what, "out of memory");
        return c;
    }
    volume *vol = lang_as_volume(v);
    if (vol) {
        vol_ref *r = mem_alloc(I, sizeof *r);
        if (!r) {
            err_at(I, NULL, ERR_MEMORY, "out of memory");
            return NULL;
        }
        r->I = I;
        r->h = v.u.h;
        r->v = vol;
        v.u.h->rc++;
        field *f = field_external(vol_field_fn, r, vol_release, "volume");
        if (!f)
            err_at(I, NULL, ERR_MEMORY, "out of memory");
        return f;
    }
    err_value(I, v, ERR_TYPE, "%s must be a field, a number or a volume, got %s", what, val_type_name(v));
    return NULL;
}

static const field_prog *fv_prog(interp *I, field_val *fv)
{
    if (!fv->prog) {
        rt_error e;
        fv->prog = field_compile(fv->f, &e);
        if (!fv->prog)
            lang_rt_error(I, e.code, &e, "field");
    }
    return fv->prog;
}

/* The slice z = 0 over [-1, 1]^2 (y up), grey from the slice's min to max. */
static int fv_preview(interp *I, const void *p, image **out)
{
    field_val *fv = (field_val *)p;
    const field_prog *prog = fv_prog(I, fv);
    if (!prog)
        return -1;
    image *im;
    rt_error e;
    if (lang_image_new(I, 128, 128, &im))
        return -1;
    rt_code c = field_preview(prog, im, &e);
    if (c) {
        lang_image_discard(im);
        return lang_rt_error(I, c, &e, "show");
    }
    *out = im;
    return 0;
}

static int fv_arith(interp *I, int op, value a, value b, value *out)
{
    int binop = -1, unop = -1;
    switch (op) {
    case T_PLUS: binop = FIELD_ADD; break;
    case T_MINUS: binop = FIELD_SUB; break;
    case T_STAR: binop = FIELD_MUL; break;
    case T_SLASH: binop = FIELD_DIV; break;
    case T_PERCENT: binop = FIELD_MOD; break;
    case T_CARET: binop = FIELD_POW; break;
    case T_LT: binop = FIELD_LT; break;
    case T_LE: binop = FIELD_LE; break;
    case T_GT: binop = FIELD_GT; break;
    case T_GE: binop = FIELD_GE; break;
    case T_EQ: binop = FIELD_EQ; break;
    case T_NE: binop = FIELD_NE; break;
    case OP_MAX: binop = FIELD_MAX; break;
    case OP_MIN: binop = FIELD_MIN; break;
    case OP_ATAN2: binop = FIELD_ATAN2; break;
    case OP_NEG: unop = FIELD_NEG; break;
    case OP_SQRT: unop = FIELD_SQRT; break;
    case OP_EXP: unop = FIELD_EXP; break;
    case OP_LOG: unop = FIELD_LOG; break;
    case OP_SIN: unop = FIELD_SIN; break;
    case OP_COS: unop = FIELD_COS; break;
    case OP_TAN: unop = FIELD_TAN; break;
    case OP_ABS: unop = FIELD_ABS; break;
    case OP_FLOOR: unop = FIELD_FLOOR; break;
    case OP_CEIL: unop = FIELD_CEIL; break;
    case OP_ROUND: unop = FIELD_ROUND; break;
    case OP_SIGN: unop = FIELD_SIGN; break;
    case OP_ASIN: unop = FIELD_ASIN; break;
    case OP_ACOS: unop = FIELD_ACOS; break;
    case OP_ATAN: unop = FIELD_ATAN; break;
    default: return 0;
    }
    if (unop >= 0) {
        field *fa = lang_to_field(I, a, "operand");
        if (!fa)
            return -1;
        return lang_field_value(I, field_unary((field_unop)unop, fa), out) ? -1 : 1;
    }
    /* only fields, numbers and volumes combine with fields */
    if (!(as_fv(a) || a.k == V_NUM || lang_as_volume(a)) || !(as_fv(b) || b.k == V_NUM || lang_as_volume(b)))
        return 0;
    field *fa = lang_to_field(I, a, "left operand");
    if (!fa)
        return -1;
    field *fb = lang_to_field(I, b, "right operand");
    if (!fb) {
        field_unref(fa);
        return -1;
    }
    return lang_field_value(I, field_binary((field_binop)binop, fa, fb), out) ? -1 : 1;
}

/* ---- helpers for builtins ------------------------------------------------------- */

/* A DMF works on numbers (computed now) or fields (a node). */
typedef double (*dmf_num)(double p, double t);

static int get_grid(interp *I, value v, int n[3], const char *what)
{
    double g[3];
    if (v.k == V_NUM) {
        g[0] = g[1] = g[2] = v.u.n;
    } else if (builtin_get_vec(I, v, g, 3, what)) {
        return -1;
    }
    for (int i = 0; i < 3; i++) /* declared TY_GRID3: whole numbers 2 to 65536 */
        n[i] = (int)g[i];
    if ((double)n[0] * n[1] * n[2] > I->lim.max_voxels)
        return err_at(I, NULL, ERR_LIMIT, "%s of %d×%d×%d exceeds the limit of %.0f voxels (raise it with --max-voxels)",
                      what, n[0], n[1], n[2], I->lim.max_voxels);
    return 0;
}

/* ---- builtins ------------------------------------------------------------------------ */

static int b_field(interp *I, value *a, int n, value *out)
{
    (void)n;
    field *f = lang_to_field(I, a[0], "field: value");
    return f ? lang_field_value(I, f, out) : -1;
}

static int shape(interp *I, density_shape *s, value *out)
{
    rt_error e;
    if (density_check(s, &e))
        return err_at(I, NULL, ERR_VALUE, "%s", e.msg);
    return lang_field_value(I, field_density(s), out);
}

/* Density shapes: the centre first, then the kind's own parameters (their
 * ranges declared in the table). */
#define SHAPE_BUILTIN(name, KIND, set)                                              \
    static int b_##name(interp *I, value *a, int n, value *out)                    \
    {                                                                               \
        (void)n;                                                                    \
        density_shape s = {0};                                                      \
        s.kind = KIND;                                                              \
        if (builtin_get_vec(I, a[0], s.c, 3, #name ": center"))                     \
            return -1;                                                              \
        set;                                                                        \
        return shape(I, &s, out);                                                   \
    }
SHAPE_BUILTIN(sphere, DENSITY_SPHERE, (s.r = a[1].u.n, s.s = a[2].u.n))
SHAPE_BUILTIN(box, DENSITY_BOX, if (builtin_get_vec(I, a[1], s.h, 3, "box: half")) return -1; s.s = a[2].u.n)
SHAPE_BUILTIN(torus, DENSITY_TORUS, (s.R = a[1].u.n, s.r = a[2].u.n, s.s = a[3].u.n))
SHAPE_BUILTIN(cylinder, DENSITY_CYLINDER, (s.r = a[1].u.n, s.h[2] = a[2].u.n, s.s = a[3].u.n))

static int noise_common(interp *I, field *f, double freq, value *out)
{
    /* freq: declared num>0 */
    if (freq != 1)
        f = field_scale(f, 1.0 / freq); /* child evaluated at P * freq */
    return lang_field_value(I, f, out);
}

static int b_perlin(interp *I, value *a, int n, value *out)
{
    (void)n;
    uint64_t seed;
    if (lang_arg_seed(I, a[1], &seed, "perlin"))
        return -1;
    return noise_common(I, field_perlin(seed), a[0].u.n, out);
}

static int octaves_arg(interp *I, value v, int *oct, const char *what)
{
    long o;
    if (builtin_get_int(I, v, 1, 30, &o, what))
        return -1;
    *oct = (int)o;
    return 0;
}

static int b_fbm(interp *I, value *a, int n, value *out)
{
    (void)n;
    uint64_t seed;
    int oct;
    if (octaves_arg(I, a[0], &oct, "fbm: octaves") || lang_arg_seed(I, a[4], &seed, "fbm"))
        return -1;
    return noise_common(I, field_fbm(seed, oct, a[2].u.n, a[3].u.n), a[1].u.n, out);
}

static int b_turbulence(interp *I, value *a, int n, value *out)
{
    (void)n;
    uint64_t seed;
    int oct;
    if (octaves_arg(I, a[0], &oct, "turbulence: octaves") || lang_arg_seed(I, a[2], &seed, "turbulence"))
        return -1;
    return noise_common(I, field_turbulence(seed, oct), a[1].u.n, out);
}

/* DMFs: on numbers they compute, on fields they build nodes; one line each.
 * Their parameter ranges are declared (bias b and gain g in (0, 1)). */
#define DMF_BUILTIN(name, who, on_number, on_field)                                 \
    static int b_##name(interp *I, value *a, int n, value *out)                    \
    {                                                                               \
        (void)n;                                                                    \
        if (a[0].k == V_NUM) {                                                      \
            *out = val_num(on_number);                                              \
            return 0;                                                               \
        }                                                                           \
        field *t = lang_to_field(I, a[0], who ": t");                               \
        return t ? lang_field_value(I, on_field, out) : -1;                         \
    }
DMF_BUILTIN(bias, "bias", dmf_bias(a[1].u.n, a[0].u.n), field_bias(t, a[1].u.n))
DMF_BUILTIN(gain, "gain", dmf_gain(a[1].u.n, a[0].u.n), field_gain(t, a[1].u.n))
DMF_BUILTIN(step, "step", dmf_step(a[1].u.n, a[0].u.n), field_step(t, a[1].u.n))
DMF_BUILTIN(smoothstep_ordered, "smoothstep", dmf_smoothstep(a[1].u.n, a[2].u.n, a[0].u.n), field_smoothstep(t, a[1].u.n, a[2].u.n))

static int b_smoothstep(interp *I, value *a, int n, value *out)
{
    if (!(a[2].u.n > a[1].u.n))
        return err_arg(I, 2, ERR_VALUE, "smoothstep: needs e0 < e1, got %g and %g", a[1].u.n, a[2].u.n);
    return b_smoothstep_ordered(I, a, n, out);
}

static int b_select(interp *I, value *a, int n, value *out)
{
    (void)n;
    if (a[0].k != V_OBJ && a[1].k != V_OBJ && a[2].k != V_OBJ) {
        *out = val_truthy(a[0]) && !(a[0].k == V_NUM && a[0].u.n == 0) ? a[1] : a[2];
        val_ref(*out);
        return 0;
    }
    field *c = lang_to_field(I, a[0], "select: cond");
    field *x = c ? lang_to_field(I, a[1], "select: a") : NULL;
    field *y = x ? lang_to_field(I, a[2], "select: b") : NULL;
    if (!y) {
        field_unref(c);
        field_unref(x);
        return -1;
    }
    return lang_field_value(I, field_select(c, x, y), out);
}

static int b_smooth_union(interp *I, value *a, int n, value *out)
{
    (void)n;
    field *x = lang_to_field(I, a[0], "smooth_union: a"); /* k: declared num>0 */
    field *y = x ? lang_to_field(I, a[1], "smooth_union: b") : NULL;
    if (!y) {
        field_unref(x);
        return -1;
    }
    return lang_field_value(I, field_smooth_union(x, y, a[2].u.n), out);
}

static int b_translate(interp *I, value *a, int n, value *out)
{
    (void)n;
    double d[3];
    if (builtin_get_vec(I, a[1], d, 3, "translate: by"))
        return -1;
    field *f = lang_to_field(I, a[0], "translate: field");
    return f ? lang_field_value(I, field_translate(f, d[0], d[1], d[2]), out) : -1;
}

static int b_scale(interp *I, value *a, int n, value *out)
{
    (void)n;
    if (a[1].u.n == 0)
        return err_arg(I, 1, ERR_VALUE, "scale: the factor must be a non-zero number, got 0");
    field *f = lang_to_field(I, a[0], "scale: field");
    return f ? lang_field_value(I, field_scale(f, a[1].u.n), out) : -1;
}

/* rotate(f, axis, degrees): the field turned about an axis through the
 * origin (right-handed); evaluated at the inverse rotation of P. */
static int b_rotate(interp *I, value *a, int n, value *out)
{
    (void)n;
    double ax[3];
    if (builtin_get_vec(I, a[1], ax, 3, "rotate: axis"))
        return -1;
    double l = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    if (!(l > 0))
        return err_arg(I, 1, ERR_VALUE, "rotate: the axis must not be zero");
    for (int i = 0; i < 3; i++)
        ax[i] /= l;
    double t = -a[2].u.n * 3.14159265358979323846 / 180.0; /* inverse */
    double c = cos(t), s = sin(t), C = 1 - c;
    double x = ax[0], y = ax[1], z = ax[2];
    double m[12] = {c + x * x * C,     x * y * C - z * s, x * z * C + y * s, 0,
                    y * x * C + z * s, c + y * y * C,     y * z * C - x * s, 0,
                    z * x * C - y * s, z * y * C + x * s, c + z * z * C,     0};
    field *f = lang_to_field(I, a[0], "rotate: field");
    return f ? lang_field_value(I, field_transform(f, m), out) : -1;
}

static int b_warp(interp *I, value *a, int n, value *out)
{
    (void)n;
    field *f = lang_to_field(I, a[0], "warp: field");
    field *fx = f ? lang_to_field(I, a[1], "warp: x") : NULL;
    field *fy = fx ? lang_to_field(I, a[2], "warp: y") : NULL;
    field *fz = fy ? lang_to_field(I, a[3], "warp: z") : NULL;
    if (!fz) {
        field_unref(f);
        field_unref(fx);
        field_unref(fy);
        return -1;
    }
    return lang_field_value(I, field_warp(f, fx, fy, fz), out);
}

static int b_at(interp *I, value *a, int n, value *out)
{
    (void)n;
    double p[3];
    if (builtin_get_vec(I, a[1], p, 3, "at: point"))
        return -1;
    if (a[0].k == V_NUM) {
        *out = a[0];
        return 0;
    }
    volume *vol = lang_as_volume(a[0]);
    if (vol) {
        *out = val_num(volume_sample(vol, p[0], p[1], p[2]));
        return 0;
    }
    field_val *fv = as_fv(a[0]);
    if (!fv)
        return err_at(I, NULL, ERR_TYPE, "at: expects a field or a volume, got %s", val_type_name(a[0]));
    const field_prog *pr = fv_prog(I, fv);
    if (!pr)
        return -1;
    *out = val_num(field_prog_eval1(pr, p[0], p[1], p[2]));
    return 0;
}

/* The field's compiled program as an rt_field_fn (for numbers: a constant). */
int lang_field_fn(interp *I, value v, field **tmp, field_prog **own, const field_prog **prog,
                  const char *what)
{
    *tmp = NULL;
    *own = NULL;
    field_val *fv = as_fv(v);
    if (fv) {
        *prog = fv_prog(I, fv);
        return *prog ? 0 : -1;
    }
    *tmp = lang_to_field(I, v, what);
    if (!*tmp)
        return -1;
    rt_error e;
    *own = field_compile(*tmp, &e);
    if (!*own) {
        field_unref(*tmp);
        return lang_rt_error(I, e.code, &e, what);
    }
    *prog = *own;
    return 0;
}

void lang_field_fn_done(field *tmp, field_prog *own)
{
    field_prog_free(own);
    field_unref(tmp);
}

static int b_sample(interp *I, value *a, int n, value *out)
{
    (void)n;
    int g[3];
    double lo[3], hi[3];
    if (get_grid(I, a[1], g, "sample: grid") || lang_get_box(I, a[2], a[3], lo, hi, "sample"))
        return -1;
    field *tmp;
    field_prog *own;
    const field_prog *prog;
    if (lang_field_fn(I, a[0], &tmp, &own, &prog, "sample"))
        return -1;
    volume *vol;
    if (lang_volume_new(I, g[0], g[1], g[2], lo, hi, &vol)) {
        lang_field_fn_done(tmp, own);
        return -1;
    }
    value res;
    if (lang_volume_value(I, vol, &res)) {
        lang_field_fn_done(tmp, own);
        return -1;
    }
    rt_run run = lang_run(I);
    rt_error e;
    double t0 = report_clock();
    rt_code c = field_sample_volume(field_prog_fn, prog, vol, &run, &e);
    if (!c)
        report_work(I, "sample", "voxels", (double)g[0] * g[1] * g[2], t0);
    lang_field_fn_done(tmp, own);
    if (c) {
        val_unref(I, res);
        return lang_rt_error(I, c, &e, "sample");
    }
    *out = res;
    return 0;
}

static int b_isosurface(interp *I, value *a, int n, value *out)
{
    (void)n;
    iso_opts o;
    memset(&o, 0, sizeof o);
    o.level = a[1].u.n;
    o.normals = 1;
    ramp r;
    field *ctmp = NULL;
    field_prog *cown = NULL;
    const field_prog *cprog = NULL;
    if (a[5].k != V_NIL) {
        if (lang_get_ramp(I, a[6], &r, "isosurface: palette") ||
            lang_field_fn(I, a[5], &ctmp, &cown, &cprog, "isosurface: colour"))
            return -1;
        o.colour_mode = ISO_COLOUR_RAMP;
        o.colour_fn[0] = field_prog_fn;
        o.colour_ctx[0] = cprog;
        o.colour_ramp = &r;
    }
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m) {
        lang_field_fn_done(ctmp, cown);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    mesh_init(m, 0, 0); /* empty (no allocation): freed safely if the surface's set-up fails first */
    rt_run run = lang_run(I);
    rt_error e;
    rt_code c;
    double t0 = report_clock();
    volume *vol = lang_as_volume(a[0]);
    if (vol) {
        c = iso_from_volume(vol, &o, &run, m, &e);
    } else {
        int g[3];
        double lo[3], hi[3];
        field *tmp;
        field_prog *own;
        const field_prog *prog;
        if (get_grid(I, a[2], g, "isosurface: grid") || lang_get_box(I, a[3], a[4], lo, hi, "isosurface") ||
            lang_field_fn(I, a[0], &tmp, &own, &prog, "isosurface")) {
            mem_free(I, m);
            lang_field_fn_done(ctmp, cown);
            return -1;
        }
        field_prog *sdf = NULL; /* the exact surface of hard shapes, if the field has one */
        c = field_prog_level_sdf(prog, o.level, &sdf, NULL, &e);
        o.sdf = sdf ? field_prog_fn : NULL;
        o.sdf_ctx = sdf;
        if (!c)
            c = iso_from_field(field_prog_fn, prog, lo, hi, g, &o, &run, m, &e);
        field_prog_free(sdf);
        lang_field_fn_done(tmp, own);
    }
    lang_field_fn_done(ctmp, cown);
    if (!c)
        report_work(I, "isosurface", "triangles", (double)m->nt, t0);
    return lang_mesh_finish(I, m, c, &e, "isosurface", out);
}

static int b_raymarch(interp *I, value *a, int n, value *out)
{
    (void)n;
    rm_opts o;
    rm_defaults(&o);
    camera cam;
    int w, h;
    double sz[2];
    if (a[2].k == V_NUM) /* declared TY_SIZE */
        sz[0] = sz[1] = a[2].u.n;
    else if (builtin_get_vec(I, a[2], sz, 2, "raymarch: size"))
        return -1;
    w = (int)sz[0];
    h = (int)sz[1];
    if ((a[1].k != V_NIL && lang_get_camera(I, a[1], &cam, "raymarch")) ||
        lang_get_box(I, a[3], a[4], o.lo, o.hi, "raymarch"))
        return -1;
    if (a[1].k == V_NIL && lang_frame_default(I, o.lo, o.hi, w, h, &cam, "raymarch: cannot frame the box"))
        return -1;
    /* declared: mode str{emission,solid}, sigma num>0, step num>0 */
    o.mode = strcmp(AS_STR(a[5])->s, "solid") == 0 ? RM_SOLID : RM_EMISSION;
    o.threshold = a[6].u.n;
    o.sigma = a[7].u.n;
    if (a[8].k != V_NIL)
        o.step = a[8].u.n;
    ramp r;
    if (a[9].k == V_LIST && AS_LIST(a[9])->n > 0 && AS_LIST(a[9])->items[0].k == V_LIST) {
        if (lang_get_ramp(I, a[9], &r, "raymarch: colour"))
            return -1;
        o.emission_ramp = &r;
    } else if (lang_get_colour(I, a[9], o.emission, "raymarch: colour")) {
        return -1;
    }
    memcpy(o.surface, o.emission, sizeof o.surface);
    if (lang_get_colour(I, a[10], o.background, "raymarch: background"))
        return -1;
    o.lighting = val_truthy(a[11]);
    if (a[12].k != V_NIL && builtin_get_vec(I, a[12], o.light, 3, "raymarch: light"))
        return -1;
    image *im;
    if (lang_image_new(I, w, h, &im))
        return -1;
    value res;
    if (lang_image_value(I, im, &res))
        return -1;
    field *tmp;
    field_prog *own;
    const field_prog *prog;
    rt_code c;
    rt_error e;
    rt_run run = lang_run(I);
    double t0 = report_clock();
    volume *vol = lang_as_volume(a[0]);
    if (vol) {
        c = rm_render(rm_volume_field, vol, &cam, &o, &run, im, &e);
    } else {
        if (lang_field_fn(I, a[0], &tmp, &own, &prog, "raymarch")) {
            val_unref(I, res);
            return -1;
        }
        field_prog *sdf = NULL; /* exact boundaries of hard shapes, if the field has them */
        c = o.mode == RM_SOLID ? field_prog_level_sdf(prog, o.threshold, &sdf, NULL, &e)
                               : field_prog_hard_support(prog, &sdf, &e);
        o.sdf = o.support = sdf ? field_prog_fn : NULL;
        o.sdf_ctx = o.support_ctx = sdf;
        if (!c)
            c = rm_render(field_prog_fn, prog, &cam, &o, &run, im, &e);
        field_prog_free(sdf);
        lang_field_fn_done(tmp, own);
    }
    if (c) {
        val_unref(I, res);
        return lang_rt_error(I, c, &e, "raymarch");
    }
    report_work(I, "raymarch", "rays", (double)im->w * im->h, t0);
    *out = res;
    return 0;
}

/* a grid of cells: one whole number for every axis, or one per axis */
#define TY_GRID3 "ivec3[2,65536]|int[2,65536]"

static const bparam p_value[] = {{"value", "num|field|volume", NULL}};
static const bparam p_sphere[] = {{"center", "vec3", "[0, 0, 0]"}, {"r", "num>0", "1"}, {"soft", "num>=0", "0"}};
static const bparam p_box[] = {{"center", "vec3", "[0, 0, 0]"}, {"half", "vec3>0", "[1, 1, 1]"}, {"soft", "num>=0", "0"}};
static const bparam p_torus[] = {{"center", "vec3", "[0, 0, 0]"}, {"R", "num>0", "1"}, {"r", "num>0", "0.25"},
                                 {"soft", "num>=0", "0"}};
static const bparam p_cylinder[] = {{"center", "vec3", "[0, 0, 0]"}, {"r", "num>0", "1"}, {"half_height", "num>0", "1"},
                                    {"soft", "num>=0", "0"}};
static const bparam p_perlin[] = {{"frequency", "num>0", "1"}, {"seed", "int", "nil"}};
static const bparam p_fbm[] = {{"octaves", "int[1,30]", "6"}, {"frequency", "num>0", "1"}, {"lacunarity", "num>0", "2"},
                               {"gain", "num", "0.5"}, {"seed", "int", "nil"}};
static const bparam p_turb[] = {{"octaves", "int[1,30]", "6"}, {"frequency", "num>0", "1"}, {"seed", "int", "nil"}};
static const bparam p_bias[] = {{"t", "num|field|volume", NULL}, {"b", "num(0,1)", NULL}};
static const bparam p_gain[] = {{"t", "num|field|volume", NULL}, {"g", "num(0,1)", NULL}};
static const bparam p_smoothstep[] = {{"t", "num|field|volume", NULL}, {"e0", "num", "0"}, {"e1", "num", "1"}};
static const bparam p_step[] = {{"t", "num|field|volume", NULL}, {"edge", "num", "0.5"}};
static const bparam p_select[] = {{"cond", "any", NULL}, {"a", "any", NULL}, {"b", "any", NULL}};
static const bparam p_sunion[] = {{"a", "num|field|volume", NULL}, {"b", "num|field|volume", NULL}, {"k", "num>0", "0.1"}};
static const bparam p_translate[] = {{"field", "num|field|volume", NULL}, {"by", "vec3", NULL}};
static const bparam p_scale[] = {{"field", "num|field|volume", NULL}, {"by", "num", NULL}};
static const bparam p_rotate[] = {{"field", "num|field|volume", NULL}, {"axis", "vec3", NULL}, {"degrees", "num", NULL}};
static const bparam p_warp[] = {{"field", "num|field|volume", NULL}, {"x", "num|field|volume", NULL},
                                {"y", "num|field|volume", NULL}, {"z", "num|field|volume", NULL}};
static const bparam p_at[] = {{"field", "num|field|volume", NULL}, {"point", "vec3", NULL}};
static const bparam p_sample[] = {{"field", "num|field", NULL}, {"grid", TY_GRID3, "64"},
                                  {"lo", "vec3", "[-1, -1, -1]"}, {"hi", "vec3", "[1, 1, 1]"}};
static const bparam p_iso[] = {{"field", "num|field|volume", NULL}, {"level", "num", "0.5"}, {"grid", TY_GRID3, "64"},
                               {"lo", "vec3", "[-1, -1, -1]"},       {"hi", "vec3", "[1, 1, 1]"},
                               {"colour", "num|field|volume", "nil"}, {"palette", "list", "nil"}};
static const bparam p_rm[] = {{"field", "num|field|volume", NULL}, {"camera", TY_CAMERA "|nil", "nil"},
                              {"size", TY_SIZE, "[256, 256]"},   {"lo", "vec3", "[-1, -1, -1]"},
                              {"hi", "vec3", "[1, 1, 1]"},         {"mode", "str{emission,solid}", "\"emission\""},
                              {"threshold", "num", "0.5"},         {"sigma", "num>0", "8"},
                              {"step", "num>0", "nil"},            {"colour", TY_COLOUR "|list", "1"},
                              {"background", TY_COLOUR, "0"},          {"lighting", "bool", "true"},
                              {"light", "vec3", "nil"}};

static const builtin field_builtins[] = {
    BUILTIN("field", b_field, p_value, "A field from a number (constant) or a volume (trilinear samples)."),
    BUILTIN("sphere", b_sphere, p_sphere,
            "Soft sphere density (seed 001): 1 inside r - soft/2, 0 outside r + soft/2, linear in the squared distance between."),
    BUILTIN("box", b_box, p_box, "Soft box density: half extents `half`, a shell of width `soft` around the surface."),
    BUILTIN("torus", b_torus, p_torus, "Soft torus density around the z axis: major radius R, tube radius r."),
    BUILTIN("cylinder", b_cylinder, p_cylinder, "Soft capped cylinder density along z."),
    BUILTIN("perlin", b_perlin, p_perlin, "Perlin's improved gradient noise (2002) at P * frequency, in about [-1, 1]; zero on the integer lattice."),
    BUILTIN("fbm", b_fbm, p_fbm, "Fractional Brownian motion: sum of gain^i * noise(lacunarity^i * P)."),
    BUILTIN("turbulence", b_turbulence, p_turb, "Perlin's turbulence: sum over octaves of |noise(2^i P)| / 2^i."),
    BUILTIN("bias", b_bias, p_bias, "Perlin's bias: t^(log b / log 0.5); bias(0.5, b) = b. On numbers or fields."),
    BUILTIN("gain", b_gain, p_gain, "Perlin's gain: an S-curve (g < 0.5) or its inverse (g > 0.5); gain(0.5, g) = 0.5."),
    BUILTIN("smoothstep", b_smoothstep, p_smoothstep, "0 below e0, 1 above e1, 3u^2 - 2u^3 between."),
    BUILTIN("step", b_step, p_step, "Threshold: 0 below edge, 1 from edge on."),
    BUILTIN("select", b_select, p_select, "cond != 0 ? a : b, point by point on fields (both sides are evaluated)."),
    BUILTIN("smooth_union", b_smooth_union, p_sunion, "A smooth maximum of two densities; k is the blend width."),
    BUILTIN("translate", b_translate, p_translate, "The field moved by a vector."),
    BUILTIN("scale", b_scale, p_scale, "The field enlarged by a factor about the origin."),
    BUILTIN("rotate", b_rotate, p_rotate, "The field turned by `degrees` about an axis through the origin."),
    BUILTIN("warp", b_warp, p_warp, "The field evaluated at the point (x(P), y(P), z(P)): any deformation of space."),
    BUILTIN("at", b_at, p_at, "The value of a field or volume at a point [x, y, z]."),
    BUILTIN("sample", b_sample, p_sample, "Sample a field into a volume of `grid` cells over the box lo..hi (values at cell centres)."),
    BUILTIN("isosurface", b_isosurface, p_iso,
            "A closed triangle mesh of {field = level} (marching cubes, asymptotic decider), from a field over a grid or from a volume; optional vertex colours from another field through a palette."),
    BUILTIN("raymarch", b_raymarch, p_rm,
            "Render a field or volume with a camera (default: the box lo..hi framed as by framing()): mode \"emission\" (density as opacity, extinction sigma) or \"solid\" (surfaces where density >= threshold)."),
};

int bind_field_init(interp *I)
{
    env *root = I->globals;
    while (root->parent)
        root = root->parent;
    const char *names[3] = {"X", "Y", "Z"};
    for (int i = 0; i < 3; i++) {
        value v;
        if (lang_field_value(I, field_coord(i), &v) || val_env_define(I, root, interp_intern(I, names[i], 1), v))
            return -1;
    }
    return BUILTIN_REGISTER(I, field_builtins);
}
