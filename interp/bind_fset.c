/* bind_fset.c — iterated function sets, orders, deterministic iteration,
 * fractal tops, colour stealing, super IFS and tiles in the language
 * (seeds 003 and 004; engines fset.h, detiter.h, draw.h, tops.h,
 * superifs.h, tiles.h).
 *
 * Classes: "fset" (a function set {W1 .. WN}, each W an IFS), "order" (which
 * W each step uses), "shape" (polylines / polygons / points: K_0 and the
 * K_n of deterministic iteration) and "superifs" (the V buffers of a
 * V-variable super IFS after some steps). Set indices are 1-based in
 * scripts (W1 is the first set), 0-based in C.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "detiter.h"
#include "draw.h"
#include "fileio.h"
#include "fset.h"
#include "hist.h"
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lexer.h"
#include "superifs.h"
#include "tiles.h"
#include "tonemap.h"
#include "tops.h"

/* ---- function sets ---------------------------------------------------------------------- */

typedef struct lang_fset {
    int n;
    affine **maps;   /* n arrays */
    double **p;      /* n arrays (always set: given or |det| weights via ifs) */
    fset_ifs *sets;  /* n views */
    fset fs;
    int dim;
} lang_fset;

static void fset_destroy(void *pp)
{
    lang_fset *f = pp;
    for (int i = 0; i < f->n; i++) {
        rt_free(f->maps[i]);
        rt_free(f->p[i]);
    }
    rt_free(f->maps);
    rt_free(f->p);
    rt_free(f->sets);
    rt_free(f);
}

static void fset_summary(const void *pp, bytebuf *out)
{
    const lang_fset *f = pp;
    bytebuf_printf(out, "fset: %d set%s (", f->n, f->n == 1 ? "" : "s");
    for (int i = 0; i < f->n && i < 12; i++)
        bytebuf_printf(out, "%sW%d: %d map%s", i ? ", " : "", i + 1, f->sets[i].n, f->sets[i].n == 1 ? "" : "s");
    bytebuf_printf(out, "%s), %d-D", f->n > 12 ? ", …" : "", f->dim);
}

static int fset_get(interp *I, const void *pp, const char *name, value *out)
{
    (void)I;
    const lang_fset *f = pp;
    if (strcmp(name, "count") == 0)
        *out = val_num(f->n);
    else if (strcmp(name, "dim") == 0)
        *out = val_num(f->dim);
    else
        return 1;
    return 0;
}

static const obj_class fset_class = {
    .name = "fset",
    .destroy = fset_destroy,
    .summary = fset_summary,
    .get = fset_get,
};

static lang_fset *fset_alloc(interp *I, int n)
{
    lang_fset *f = mem_calloc(I, 1, sizeof *f);
    if (!f)
        return NULL;
    f->maps = mem_calloc(I, (size_t)n, sizeof *f->maps);
    f->p = mem_calloc(I, (size_t)n, sizeof *f->p);
    f->sets = mem_calloc(I, (size_t)n, sizeof *f->sets);
    if (!f->maps || !f->p || !f->sets) {
        mem_free(I, f->maps);
        mem_free(I, f->p);
        mem_free(I, f->sets);
        mem_free(I, f);
        return NULL;
    }
    f->n = n;
    return f;
}

static void fset_link(lang_fset *f)
{
    for (int i = 0; i < f->n; i++)
        f->sets[i] = (fset_ifs){f->sets[i].n, f->maps[i], f->p[i]};
    f->fs.n = f->n;
    f->fs.sets = f->sets;
    f->dim = f->n && f->sets[0].n ? f->maps[0][0].dim : 2;
}

/* One IFS (ifs value or table) as set i of f; probabilities default to
 * equal ones for a table without a probability column, the ifs's own for an
 * ifs value. */
static int fset_put(interp *I, lang_fset *f, int i, value v, const char *what)
{
    int cnt;
    int has = lang_get_maps(I, v, &f->maps[i], &f->p[i], &cnt, what);
    if (has < 0)
        return -1;
    if (!has) {
        mem_free(I, f->p[i]);
        f->p[i] = NULL;
    }
    f->sets[i].n = cnt;
    return 0;
}

static lang_fset *as_fset(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &fset_class ? AS_OBJ(v)->payload : NULL;
}

static int fset_finish(interp *I, lang_fset *f, const char *what, value *out)
{
    fset_link(f);
    rt_error e;
    rt_code c = fset_validate(&f->fs, &e);
    if (c) {
        fset_destroy(f);
        return lang_rt_error(I, c, &e, what);
    }
    *out = val_obj(I, &fset_class, f);
    return out->k == V_NIL ? -1 : 0;
}

/* fset, ifs, table or list of ifs/tables -> a function set value (new ref). */
static int get_fset(interp *I, value v, int list_is_sets, value *out, const char *what)
{
    if (as_fset(v)) {
        val_ref(v);
        *out = v;
        return 0;
    }
    int one = lang_as_ifs(v) != NULL || !list_is_sets;
    /* a table (rows of numbers) or a list of maps is one IFS, not a list of sets */
    if (!one && v.k == V_LIST && AS_LIST(v)->n > 0) {
        value f0 = AS_LIST(v)->items[0];
        if ((f0.k == V_LIST && AS_LIST(f0)->n > 0 && AS_LIST(f0)->items[0].k == V_NUM) ||
            (f0.k == V_OBJ && AS_OBJ(f0)->cls == &map_class))
            one = 1;
    }
    if (!one && v.k != V_LIST)
        return err_at(I, NULL, ERR_TYPE, "%s must be a list of IFSs (ifs values or tables), got %s", what,
                      val_type_name(v));
    int n = one ? 1 : (int)AS_LIST(v)->n;
    if (n < 1)
        return err_at(I, NULL, ERR_VALUE, "%s: the function set is empty (give at least one IFS)", what);
    if (n > 4096)
        return err_at(I, NULL, ERR_VALUE, "%s: %d IFSs, at most 4096", what, n);
    lang_fset *f = fset_alloc(I, n);
    if (!f)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    for (int i = 0; i < n; i++) {
        char w[96];
        snprintf(w, sizeof w, "%s: W%d", what, i + 1);
        if (fset_put(I, f, i, one ? v : AS_LIST(v)->items[i], w)) {
            fset_destroy(f);
            return -1;
        }
    }
    return fset_finish(I, f, what, out);
}

static int b_fset(interp *I, value *a, int n, value *out)
{
    (void)n;
    return get_fset(I, a[0], 1, out, "fset");
}

/* ---- orders ----------------------------------------------------------------------------- */

typedef struct lang_order {
    fset_order o;
    int *seq;
    double *p;
    int np;
} lang_order;

static void order_destroy(void *pp)
{
    lang_order *o = pp;
    rt_free(o->seq);
    rt_free(o->p);
    rt_free(o);
}

static void order_summary(const void *pp, bytebuf *out)
{
    const lang_order *o = pp;
    if (o->o.kind == FSET_RANDOM) {
        bytebuf_printf(out, "order: random over %d sets, probabilities [", o->np);
        for (int i = 0; i < o->np; i++)
            bytebuf_printf(out, "%s%g", i ? ", " : "", o->p[i]);
        bytebuf_printf(out, "], seed %llu", (unsigned long long)o->o.seed);
        return;
    }
    bytebuf_printf(out, "order: %s of %d step%s, ", o->o.kind == FSET_PERIODIC ? "periodic" : "sequence", o->o.len,
                   o->o.len == 1 ? "" : "s");
    /* the paper's notation: last applied on the left */
    int shown = 0;
    for (int i = o->o.len - 1; i >= 0; i--) {
        if (shown == 24) {
            bytebuf_printf(out, " ∘ …");
            break;
        }
        bytebuf_printf(out, "%sW%d", shown ? " ∘ " : "", o->seq[i] + 1);
        shown++;
    }
    bytebuf_printf(out, "(K0)%s", o->o.kind == FSET_PERIODIC ? ", repeated" : "");
}

static int order_get(interp *I, const void *pp, const char *name, value *out)
{
    const lang_order *o = pp;
    if (strcmp(name, "kind") == 0) {
        const char *k = o->o.kind == FSET_RANDOM ? "random" : o->o.kind == FSET_PERIODIC ? "periodic" : "sequence";
        *out = val_cstr(I, k);
        return out->k == V_NIL ? -1 : 0;
    }
    if (strcmp(name, "length") == 0) {
        *out = o->o.kind == FSET_RANDOM ? val_nil() : val_num(o->o.len);
        return 0;
    }
    if (strcmp(name, "sequence") == 0) {
        if (o->o.kind == FSET_RANDOM) {
            *out = val_nil();
            return 0;
        }
        value l = val_list(I, (size_t)o->o.len);
        if (l.k == V_NIL)
            return -1;
        for (int i = 0; i < o->o.len; i++)
            if (list_push(I, AS_LIST(l), val_num(o->seq[i] + 1))) {
                val_unref(I, l);
                return -1;
            }
        *out = l;
        return 0;
    }
    return 1;
}

static const obj_class order_class = {
    .name = "order",
    .destroy = order_destroy,
    .summary = order_summary,
    .get = order_get,
};

static const lang_order *as_order(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &order_class ? AS_OBJ(v)->payload : NULL;
}

/* order(sequence, repeat, probabilities, seed) */
static int b_order(interp *I, value *a, int n, value *out)
{
    (void)n;
    value sq = a[0], pr = a[2];
    if (sq.k != V_NIL && pr.k != V_NIL)
        return err_arg(I, 2, ERR_VALUE,
                      "order: give a sequence (a list of set numbers or \"W2 ∘ W1\") or probabilities, not both");
    if (sq.k == V_NIL && pr.k == V_NIL)
        return err_at(I, NULL, ERR_VALUE,
                      "order: give a sequence (a list of set numbers or \"W2 ∘ W1\") or probabilities: [p1, p2, …]");
    lang_order *o = mem_calloc(I, 1, sizeof *o);
    if (!o)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    if (pr.k != V_NIL) {
        size_t np = AS_LIST(pr)->n;
        if (val_truthy(a[1])) {
            mem_free(I, o);
            return err_arg(I, 1, ERR_VALUE, "order: repeat applies to a sequence, not to a random order");
        }
        if (np < 1 || np > 4096) {
            mem_free(I, o);
            return err_arg(I, 2, ERR_VALUE, "order: probabilities must be 1 to 4096 numbers (one per set), got %zu",
                           np);
        }
        o->p = mem_alloc(I, sizeof(double) * np);
        if (!o->p) {
            mem_free(I, o);
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        }
        if (get_vec(I, pr, o->p, np, "order: probabilities") || arg_seed(I, a[3], &o->o.seed, "order")) {
            order_destroy(o);
            return -1;
        }
        double s = 0; /* each in [0, 1] (declared) */
        for (size_t i = 0; i < np; i++)
            s += o->p[i];
        if (fabs(s - 1) > 1e-6) {
            err_arg(I, 2, ERR_VALUE, "order: probabilities sum to %.9g (expected 1)", s);
            order_destroy(o);
            return -1;
        }
        o->np = (int)np;
        o->o.kind = FSET_RANDOM;
        o->o.p = o->p;
    } else {
        if (a[3].k != V_NIL) {
            mem_free(I, o);
            return err_arg(I, 3, ERR_VALUE, "order: seed applies to a random order (probabilities:), not to a sequence");
        }
        if (sq.k == V_STR) {
            size_t off = 0;
            rt_error e;
            rt_code c = fset_order_parse(AS_STR(sq)->s, 0, &o->seq, &o->o.len, &off, &e);
            if (c) {
                mem_free(I, o);
                if (c == RT_EINVAL && strncmp(e.msg, "order: ", 7) == 0)
                    return err_arg(I, 0, ERR_VALUE, "%s", e.msg);
                return c == RT_EINVAL ? err_arg(I, 0, ERR_VALUE, "order: %s", e.msg) : lang_rt_error(I, c, &e, "order");
            }
        } else { /* a list (declared list|str) */
            size_t len = AS_LIST(sq)->n;
            if (len < 1 || len > 100000000) {
                mem_free(I, o);
                return err_arg(I, 0, ERR_VALUE, len < 1 ? "order: the sequence is empty (give set numbers like [1, 2, 1, 2])"
                                                        : "order: the sequence is too long (at most 100000000 steps)");
            }
            o->seq = mem_alloc(I, sizeof(int) * len);
            if (!o->seq) {
                mem_free(I, o);
                return err_at(I, NULL, ERR_MEMORY, "out of memory");
            }
            for (size_t i = 0; i < len; i++) {
                value x = AS_LIST(sq)->items[i];
                if (x.k != V_NUM || x.u.n != floor(x.u.n) || x.u.n < 1 || x.u.n > 4096) {
                    char got[40];
                    if (x.k == V_NUM)
                        fmt_number(x.u.n, got, sizeof got);
                    else
                        snprintf(got, sizeof got, "%s", val_type_name(x));
                    err_item(I, sq, i, ERR_VALUE, "order: item %zu must be a set number from 1 (W1) to 4096, got %s",
                             i + 1, got);
                    mem_free(I, o->seq);
                    mem_free(I, o);
                    return -1;
                }
                o->seq[i] = (int)x.u.n - 1;
            }
            o->o.len = (int)len;
        }
        o->o.kind = val_truthy(a[1]) ? FSET_PERIODIC : FSET_SEQUENCE;
        o->o.seq = o->seq;
    }
    *out = val_obj(I, &order_class, o);
    return out->k == V_NIL ? -1 : 0;
}

/* The order to use with a function set of nsets sets: given, or periodic
 * W1, W2, …, WN. *tmp holds a default's storage. */
static int order_arg(interp *I, value v, int slot, int nsets, fset_order *o, int **tmp, const char *what)
{
    *tmp = NULL;
    const lang_order *lo = as_order(v);
    if (lo) {
        *o = lo->o;
    } else if (v.k == V_NIL) {
        *tmp = mem_alloc(I, sizeof(int) * (size_t)nsets);
        if (!*tmp)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        for (int i = 0; i < nsets; i++)
            (*tmp)[i] = i;
        memset(o, 0, sizeof *o);
        o->kind = FSET_PERIODIC;
        o->len = nsets;
        o->seq = *tmp;
    }
    if (o->kind == FSET_RANDOM && lo->np != nsets) {
        mem_free(I, *tmp);
        return err_arg(I, slot, ERR_VALUE, "%s: the random order has %d probabilities but the function set has %d sets",
                       what, lo->np, nsets);
    }
    if (o->kind != FSET_RANDOM)
        for (int i = 0; i < o->len; i++)
            if (o->seq[i] >= nsets) {
                mem_free(I, *tmp);
                return err_arg(I, slot, ERR_VALUE, "%s: the order uses W%d but the function set has %d set%s", what,
                               o->seq[i] + 1, nsets, nsets == 1 ? "" : "s");
            }
    return 0;
}

/* ---- shapes ---------------------------------------------------------------------------- */

static void shape_destroy(void *pp)
{
    detiter_shape *s = pp;
    detiter_shape_free(s);
    rt_free(s);
}

static void shape_bounds(const detiter_shape *s, double lo[2], double hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    for (size_t i = 0; i < s->nverts; i++)
        for (int k = 0; k < 2; k++) {
            double x = s->v[i * (size_t)s->dim + (size_t)k];
            if (x < lo[k])
                lo[k] = x;
            if (x > hi[k])
                hi[k] = x;
        }
}

static void shape_summary(const void *pp, bytebuf *out)
{
    const detiter_shape *s = pp;
    size_t closed = 0;
    for (size_t i = 0; i < s->npoly; i++)
        closed += s->closed[i] != 0;
    bytebuf_printf(out, "shape: %zu vertices in %zu polyline%s (%zu closed), %d-D, length %.6g", s->nverts, s->npoly,
                   s->npoly == 1 ? "" : "s", closed, s->dim, detiter_length(s));
}

static int shape_get(interp *I, const void *pp, const char *name, value *out)
{
    const detiter_shape *s = pp;
    if (strcmp(name, "vertices") == 0)
        *out = val_num((double)s->nverts);
    else if (strcmp(name, "polylines") == 0)
        *out = val_num((double)s->npoly);
    else if (strcmp(name, "length") == 0)
        *out = val_num(detiter_length(s));
    else if (strcmp(name, "dim") == 0)
        *out = val_num(s->dim);
    else if (strcmp(name, "bounds") == 0) {
        double lo[2], hi[2], b[4];
        shape_bounds(s, lo, hi);
        b[0] = lo[0];
        b[1] = hi[0];
        b[2] = lo[1];
        b[3] = hi[1];
        return num_list_value(I, b, (size_t)(4), out);
    } else if (strcmp(name, "coords") == 0) {
        if ((double)s->nverts > I->lim.max_list)
            return err_at(I, NULL, ERR_LIMIT, "shape.coords: %zu vertices exceed the list limit of %.0f (raise it with --max-list)",
                          s->nverts, I->lim.max_list);
        value l = val_list(I, s->nverts);
        if (l.k == V_NIL)
            return -1;
        for (size_t i = 0; i < s->nverts; i++) {
            value p;
            if (num_list_value(I, s->v + i * (size_t)s->dim, (size_t)(s->dim), &p) || list_push(I, AS_LIST(l), p)) {
                val_unref(I, l);
                return -1;
            }
        }
        *out = l;
        return 0;
    } else
        return 1;
    return 0;
}

static int shape_arith(interp *I, int op, value a, value b, value *out);
static int shape_save(interp *I, const void *p, const char *path, value opts);
static int shape_preview(interp *I, const void *p, image **out);

static const obj_class shape_class = {
    .name = "shape",
    .destroy = shape_destroy,
    .summary = shape_summary,
    .get = shape_get,
    .arith = shape_arith,
    .save = shape_save,
    .preview = shape_preview,
};

static const detiter_shape *as_shape(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &shape_class ? AS_OBJ(v)->payload : NULL;
}

static int shape_value(interp *I, detiter_shape *s, value *out)
{
    detiter_shape *p = mem_alloc(I, sizeof *p);
    if (!p) {
        detiter_shape_free(s);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    *p = *s;
    *out = val_obj(I, &shape_class, p);
    return out->k == V_NIL ? -1 : 0;
}

/* An empty shape with room for nv vertices and np polylines. */
static int shape_alloc(interp *I, detiter_shape *s, int dim, size_t nv, size_t np)
{
    memset(s, 0, sizeof *s);
    s->dim = dim;
    s->v = mem_alloc(I, sizeof(double) * (nv ? nv : 1) * (size_t)dim);
    s->start = mem_alloc(I, sizeof(size_t) * (np + 1));
    s->closed = mem_alloc(I, np ? np : 1);
    if (!s->v || !s->start || !s->closed) {
        detiter_shape_free(s);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    s->nverts = nv;
    s->npoly = np;
    return 0;
}

/* shape + [dx, dy], shape - [dx, dy], shape * k, map * shape, shape + shape (union) */
static int shape_arith(interp *I, int op, value a, value b, value *out)
{
    const detiter_shape *x = as_shape(a), *y = as_shape(b);
    if (x && y && op == T_PLUS) {
        if (x->dim != y->dim)
            return err_at(I, NULL, ERR_VALUE, "shape + shape: a %d-D and a %d-D shape cannot be joined", x->dim, y->dim);
        detiter_shape s;
        if (shape_alloc(I, &s, x->dim, x->nverts + y->nverts, x->npoly + y->npoly))
            return -1;
        memcpy(s.v, x->v, sizeof(double) * x->nverts * (size_t)x->dim);
        memcpy(s.v + x->nverts * (size_t)x->dim, y->v, sizeof(double) * y->nverts * (size_t)y->dim);
        for (size_t i = 0; i < x->npoly; i++) {
            s.start[i] = x->start[i];
            s.closed[i] = x->closed[i];
        }
        for (size_t i = 0; i < y->npoly; i++) {
            s.start[x->npoly + i] = x->nverts + y->start[i];
            s.closed[x->npoly + i] = y->closed[i];
        }
        s.start[s.npoly] = s.nverts;
        return shape_value(I, &s, out) ? -1 : 1;
    }
    const detiter_shape *src = x ? x : y;
    value other = x ? b : a;
    const affine *m = NULL;
    double t[3] = {0, 0, 0}, k = 1;
    int kind;
    if (other.k == V_OBJ && AS_OBJ(other)->cls == &map_class && y && op == T_STAR) {
        m = AS_OBJ(other)->payload;
        kind = 0;
    } else if (other.k == V_LIST && (op == T_PLUS || (op == T_MINUS && x))) {
        size_t nn = AS_LIST(other)->n;
        if ((int)nn != src->dim)
            return err_at(I, NULL, ERR_VALUE, "shape %s: a %d-D shape moves by a list of %d numbers, got %zu",
                          op == T_PLUS ? "+" : "-", src->dim, src->dim, nn);
        if (get_vec(I, other, t, nn, "shape offset"))
            return -1;
        if (op == T_MINUS)
            for (int i = 0; i < 3; i++)
                t[i] = -t[i];
        kind = 1;
    } else if (other.k == V_NUM && (op == T_STAR || (op == T_SLASH && x))) {
        k = op == T_STAR ? other.u.n : 1 / other.u.n;
        kind = 2;
    } else {
        return 0;
    }
    if (m && m->dim > src->dim)
        return err_at(I, NULL, ERR_VALUE, "map * shape: a %d-D map cannot apply to a %d-D shape", m->dim, src->dim);
    detiter_shape s;
    if (shape_alloc(I, &s, src->dim, src->nverts, src->npoly))
        return -1;
    memcpy(s.start, src->start, sizeof(size_t) * (src->npoly + 1));
    memcpy(s.closed, src->closed, src->npoly);
    for (size_t i = 0; i < src->nverts; i++) {
        const double *p = src->v + i * (size_t)src->dim;
        double *q = s.v + i * (size_t)src->dim;
        if (kind == 0) {
            double in[3] = {p[0], p[1], src->dim == 3 ? p[2] : 0}, o3[3];
            affine_apply(m, in, o3);
            for (int d = 0; d < m->dim; d++)
                q[d] = o3[d];
            if (m->dim < src->dim)
                q[2] = p[2];
        } else {
            for (int d = 0; d < src->dim; d++)
                q[d] = kind == 1 ? p[d] + t[d] : p[d] * k;
        }
    }
    return shape_value(I, &s, out) ? -1 : 1;
}

/* polygon / polyline / pointset: positional points, or one list of points */
static int make_shape(interp *I, value *a, int n, detiter_kind kind, const char *what, value *out)
{
    value *pts = a;
    int np = n;
    if (n == 0 && a[0].k == V_LIST) { /* points: [[x, y], …] (named) */
        pts = AS_LIST(a[0])->items;
        np = (int)AS_LIST(a[0])->n;
    } else if (n > 0 && a[n].k != V_NIL) {
        return err_at(I, NULL, ERR_VALUE, "%s: give the points either positionally or as points:, not both", what);
    } else if (n == 1 && a[0].k == V_LIST && AS_LIST(a[0])->n > 0 && AS_LIST(a[0])->items[0].k == V_LIST) {
        pts = AS_LIST(a[0])->items;
        np = (int)AS_LIST(a[0])->n;
    }
    int need = kind == DETITER_POLYGON ? 3 : kind == DETITER_POLYLINE ? 2 : 1;
    if (np < need)
        return err_at(I, NULL, ERR_VALUE, "%s: needs at least %d point%s [x, y], got %d", what, need, need == 1 ? "" : "s",
                      np);
    if ((double)np > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT, "%s: %d points exceed the limit of %.0f (raise it with --max-points)", what, np,
                      I->lim.max_points);
    int dim = pts[0].k == V_LIST ? (int)AS_LIST(pts[0])->n : 0;
    if (dim != 2 && dim != 3)
        return err_at(I, NULL, ERR_VALUE, "%s: point 1 must be [x, y] or [x, y, z], got %s", what,
                      pts[0].k == V_LIST ? "a list of another length" : val_type_name(pts[0]));
    double *v = mem_alloc(I, sizeof(double) * (size_t)np * (size_t)dim);
    if (!v)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    for (int i = 0; i < np; i++) {
        if (pts[i].k != V_LIST || (int)AS_LIST(pts[i])->n != dim) {
            mem_free(I, v);
            return err_at(I, NULL, ERR_VALUE, "%s: point %d must be a list of %d numbers like point 1", what, i + 1, dim);
        }
        char w[64];
        snprintf(w, sizeof w, "%s: point %d", what, i + 1);
        if (get_vec(I, pts[i], v + (size_t)i * (size_t)dim, (size_t)dim, w)) {
            mem_free(I, v);
            return -1;
        }
    }
    detiter_shape s;
    rt_error e;
    rt_code c = detiter_shape_make(&s, dim, (size_t)np, v, kind, &e);
    mem_free(I, v);
    if (c)
        return lang_rt_error(I, c, &e, what);
    return shape_value(I, &s, out);
}

static int b_polygon(interp *I, value *a, int n, value *out) { return make_shape(I, a, n, DETITER_POLYGON, "polygon", out); }
static int b_polyline(interp *I, value *a, int n, value *out) { return make_shape(I, a, n, DETITER_POLYLINE, "polyline", out); }
static int b_pointset(interp *I, value *a, int n, value *out) { return make_shape(I, a, n, DETITER_POINTS, "pointset", out); }

/* iterate(system, start, steps, order) */
static int b_iterate(interp *I, value *a, int n, value *out)
{
    (void)n;
    value fv;
    if (get_fset(I, a[0], 0, &fv, "iterate: system"))
        return -1;
    const lang_fset *f = as_fset(fv);
    fset_order o;
    int *tmp = NULL;
    if (order_arg(I, a[3], 3, f->n, &o, &tmp, "iterate")) {
        val_unref(I, fv);
        return -1;
    }
    long steps;
    int rc = -1;
    detiter_shape k0def, *k0 = NULL;
    int own_k0 = 0;
    if (a[2].k == V_NIL) {
        if (o.kind != FSET_SEQUENCE) {
            err_at(I, NULL, ERR_VALUE, "iterate: steps is needed (only a sequence order gives its own length)");
            goto done;
        }
        steps = o.len;
    } else {
        steps = (long)a[2].u.n; /* declared int[0,1000000] */
    }
    if (a[1].k == V_NIL) {
        /* seed 003 §2-2: the triangle (0,0), (1,0), (1/2, √3/6) */
        double tri[9] = {0, 0, 0, 1, 0, 0, 0.5, sqrt(3.0) / 6, 0};
        double tri2[6] = {0, 0, 1, 0, 0.5, sqrt(3.0) / 6};
        rt_error e;
        rt_code c = detiter_shape_make(&k0def, f->dim, 3, f->dim == 3 ? tri : tri2, DETITER_POLYGON, &e);
        if (c) {
            lang_rt_error(I, c, &e, "iterate");
            goto done;
        }
        k0 = &k0def;
        own_k0 = 1;
    } else {
        k0 = (detiter_shape *)as_shape(a[1]); /* declared shape */
    }
    if (o.kind == FSET_SEQUENCE && steps > o.len) {
        err_arg(I, 2, ERR_VALUE, "iterate: the order has %d step%s but steps is %ld (use order(…, repeat: true) to cycle)",
               o.len, o.len == 1 ? "" : "s", steps);
        goto done;
    }
    size_t need;
    rt_error e;
    rt_code c = detiter_count(&f->fs, &o, (size_t)steps, k0->nverts, &need, &e);
    if (c) {
        lang_rt_error(I, c, &e, "iterate");
        goto done;
    }
    if ((double)need > I->lim.max_points) {
        err_at(I, NULL, ERR_LIMIT,
               "iterate: K_%ld would have %zu vertices, more than the limit of %.0f points (raise it with --max-points, or lower steps)",
               steps, need, I->lim.max_points);
        goto done;
    }
    double bytes = (double)need * (k0->dim * 8 + 9) * 2;
    if (mem_precheck(I, bytes, "iterate: the shape"))
        goto done;
    rt_run run = lang_run(I);
    detiter_shape res;
    c = detiter_run(&f->fs, &o, (size_t)steps, k0, (size_t)need, &res, &run, &e);
    if (c) {
        lang_rt_error(I, c, &e, "iterate");
        goto done;
    }
    rc = shape_value(I, &res, out);
done:
    if (own_k0)
        detiter_shape_free(&k0def);
    mem_free(I, tmp);
    val_unref(I, fv);
    return rc;
}

/* ---- drawing --------------------------------------------------------------------------- */

static int window_arg(interp *I, value v, double lo[2], double hi[2], const char *what)
{
    double win[4];
    if (get_vec(I, v, win, 4, what))
        return -1;
    lo[0] = win[0];
    hi[0] = win[1];
    lo[1] = win[2];
    hi[1] = win[3];
    if (!(hi[0] > lo[0]) || !(hi[1] > lo[1]))
        return err_item(I, v, SIZE_MAX, ERR_VALUE, "%s is [xmin, xmax, ymin, ymax] with min < max", what);
    return 0;
}

/* Fitted view of a shape: its bounds plus a 5 % margin, same scale on both axes. */
static int shape_view(interp *I, const detiter_shape *s, value window, int w, int h, draw_view *v, const char *what)
{
    double lo[2], hi[2];
    char wn[64];
    snprintf(wn, sizeof wn, "%s: window", what);
    if (window.k != V_NIL) {
        if (window_arg(I, window, lo, hi, wn))
            return -1;
    } else {
        shape_bounds(s, lo, hi);
        for (int k = 0; k < 2; k++) {
            double ext = hi[k] - lo[k];
            if (!(ext > 0))
                ext = fmax(fabs(lo[k]), 1) * 0.1;
            double c = (lo[k] + hi[k]) / 2;
            lo[k] = c - ext * 0.55;
            hi[k] = c + ext * 0.55;
        }
    }
    rt_error e;
    rt_code c = draw_view_fit(v, w, h, lo, hi, 1, &e);
    return c ? lang_rt_error(I, c, &e, what) : 0;
}

static int fill_arg(interp *I, value v, int *fill, float rgba[4], const float stroke[4], const char *what)
{
    *fill = 0;
    if (v.k == V_NIL || (v.k == V_BOOL && !v.u.b))
        return 0;
    *fill = 1;
    if (v.k == V_BOOL) {
        memcpy(rgba, stroke, sizeof(float) * 4);
        return 0;
    }
    return lang_get_colour(I, v, rgba, what);
}

/* Fill (if asked) then stroke s onto im. */
static rt_code paint(image *im, const draw_view *view, const detiter_shape *s, const float colour[4], double width,
                     double radius, int fill, const float fillc[4], rt_error *e)
{
    draw_style st;
    memset(&st, 0, sizeof st);
    rt_code c = RT_OK;
    if (fill) {
        memcpy(st.color, fillc, sizeof st.color);
        st.fill = 1;
        st.width = 0;
        st.radius = radius;
        if ((c = draw_shape(im, view, s, &st, e)))
            return c;
    }
    if (width > 0 || !fill) {
        memcpy(st.color, colour, sizeof st.color);
        st.fill = 0;
        st.width = width;
        st.radius = radius;
        c = draw_shape(im, view, s, &st, e);
    }
    return c;
}

/* draw(shape, size, window, colour, width, radius, fill, background, onto) */
static int b_draw(interp *I, value *a, int n, value *out)
{
    (void)n;
    const detiter_shape *s = as_shape(a[0]);
    int w, h;
    const image *onto = a[8].k == V_NIL ? NULL : lang_as_image(a[8]);
    float col[4], fillc[4] = {0, 0, 0, 0}, bg[4];
    int fill;
    if (onto) {
        w = onto->w;
        h = onto->h;
    } else if (arg_size2(I, a[1], &w, &h, "draw: size"))
        return -1;
    if (lang_get_colour(I, a[3], col, "draw: colour") || fill_arg(I, a[6], &fill, fillc, col, "draw: fill") ||
        lang_get_colour(I, a[7], bg, "draw: background"))
        return -1;
    draw_view view;
    if (shape_view(I, s, a[2], w, h, &view, "draw"))
        return -1;
    image *im;
    if (lang_image_new(I, w, h, &im))
        return -1;
    if (onto)
        memcpy(im->px, onto->px, sizeof(float) * 4 * (size_t)w * (size_t)h);
    else
        draw_clear(im, bg);
    rt_error e;
    rt_code c = paint(im, &view, s, col, a[4].u.n, a[5].u.n, fill, fillc, &e);
    return lang_image_finish(I, im, c, &e, "draw", out);
}

static int opt_colour(interp *I, value opts, const char *key, float rgba[4], int *found)
{
    *found = 0;
    if (opts.k != V_REC)
        return 0;
    const char *k = intern(I, key, strlen(key));
    value *v = k ? rec_get(AS_REC(opts), k) : NULL;
    if (!v || v->k == V_NIL)
        return 0;
    if (v->k == V_BOOL) {
        *found = v->u.b ? 2 : 0;
        return 0;
    }
    *found = 1;
    char what[64];
    snprintf(what, sizeof what, "save: %s", key);
    return lang_get_colour(I, *v, rgba, what);
}

/* save(shape, "x.svg", {size, width, radius, colour, fill, background, precision}) */
static int shape_save(interp *I, const void *p, const char *path, value opts)
{
    const detiter_shape *s = p;
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "svg") != 0)
        return err_at(I, NULL, ERR_VALUE, "save: a shape is saved as .svg (draw it with draw(…) for a picture), got '.%s'",
                      ext);
    double size = 512, width = 1, radius = 1, prec = 3;
    if (opts_check(I, opts,
                   "rec{size: int[1,1000000], width: num[0,1000], radius: num[0,1000], precision: int[0,9], "
                   "colour: nil|bool|" TY_COLOUR ", fill: nil|bool|" TY_COLOUR ", background: nil|bool|" TY_COLOUR "}",
                   "save") ||
        opt_num(I, opts, "size", &size) < 0 || opt_num(I, opts, "width", &width) < 0 ||
        opt_num(I, opts, "radius", &radius) < 0 || opt_num(I, opts, "precision", &prec) < 0)
        return -1;
    draw_style st;
    memset(&st, 0, sizeof st);
    st.color[3] = 1;
    float bg[4];
    int has_col, has_bg, has_fill;
    float fillc[4];
    if (opt_colour(I, opts, "colour", st.color, &has_col) || opt_colour(I, opts, "background", bg, &has_bg) ||
        opt_colour(I, opts, "fill", fillc, &has_fill))
        return -1;
    st.width = width;
    st.radius = radius;
    st.fill = has_fill != 0;
    draw_view view;
    if (shape_view(I, s, val_nil(), (int)size, (int)size, &view, "save"))
        return -1;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    /* fill: true fills with the stroke colour */
    rt_code c = draw_svg_fill(&b, &view, s, &st, has_fill == 1 ? fillc : NULL, has_bg == 1 ? bg : NULL, (int)prec, &e);
    if (!c)
        c = b.failed ? rt_fail(&e, RT_ENOMEM, "out of memory writing SVG") : fileio_write_atomic(path, b.data, b.len, &e);
    bytebuf_free(&b);
    return c ? lang_rt_error(I, c, &e, "save") : 0;
}

static int shape_preview(interp *I, const void *p, image **out)
{
    const detiter_shape *s = p;
    draw_view view;
    if (shape_view(I, s, val_nil(), 256, 256, &view, "show"))
        return -1;
    image *im;
    if (lang_image_new(I, 256, 256, &im))
        return -1;
    float bg[4] = {0, 0, 0, 1}, col[4] = {1, 1, 1, 1};
    draw_clear(im, bg);
    rt_error e;
    rt_code c = paint(im, &view, s, col, 1, 1, 0, col, &e);
    if (c) {
        lang_image_discard(im);
        return lang_rt_error(I, c, &e, "show");
    }
    *out = im;
    return 0;
}

/* ---- chaos game with a function set ------------------------------------------------------- */

/* points: declared int>=1; the limit is the session's. */
static int points_arg(interp *I, value v, uint64_t *out, const char *what)
{
    if (v.u.n > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT, "%s: %.0f points exceed the limit of %.0f (raise it with --max-points)", what,
                      v.u.n, I->lim.max_points);
    *out = (uint64_t)v.u.n;
    return 0;
}

/* Tone-mapping arguments shared by chaos_fset and superifs_image. */
static int tone_args(interp *I, value palette, value curve, value gamma, value bright, value bg, tonemap_opts *t,
                     ramp *r, const char *what)
{
    memset(t, 0, sizeof *t);
    char w[64];
    snprintf(w, sizeof w, "%s: palette", what);
    if (lang_get_ramp(I, palette, r, w))
        return -1;
    /* declared: curve str{log,linear}, gamma and brightness num>0 */
    t->curve = strcmp(AS_STR(curve)->s, "linear") == 0 ? TONEMAP_LINEAR : TONEMAP_LOG;
    t->gamma = gamma.u.n;
    t->brightness = bright.u.n;
    t->colour = TONEMAP_RAMP;
    t->ramp = r;
    snprintf(w, sizeof w, "%s: background", what);
    return lang_get_colour(I, bg, t->bg, w);
}

/* Widen lo..hi by a margin and to the aspect w:h about its centre. */
static void fit_aspect(double lo[2], double hi[2], int w, int h, double margin)
{
    double ext[2];
    for (int k = 0; k < 2; k++) {
        ext[k] = hi[k] - lo[k];
        if (!(ext[k] > 1e-12))
            ext[k] = fmax(1e-3, fmax(fabs(lo[k]), fabs(hi[k])) * 0.1);
        ext[k] *= 1 + 2 * margin;
    }
    double aspect = (double)w / h;
    if (ext[0] / ext[1] < aspect)
        ext[0] = ext[1] * aspect;
    else
        ext[1] = ext[0] / aspect;
    for (int k = 0; k < 2; k++) {
        double c = (lo[k] + hi[k]) / 2;
        lo[k] = c - ext[k] / 2;
        hi[k] = c + ext[k] / 2;
    }
}

/* The window of a function-set chaos game: a bound from the maps'
 * contractions, narrowed by three coarse histogram passes. */
static rt_code fset_fit(const fset *fs, const fset_order *o, const fset_chaos_opts *opts, int w, int h, double lo[2],
                        double hi[2], const rt_run *run, rt_error *e)
{
    double R = 0;
    int contractive = 1;
    for (int s = 0; s < fs->n; s++)
        for (int m = 0; m < fs->sets[s].n; m++) {
            const affine *a = &fs->sets[s].maps[m];
            double c = affine_contraction(a);
            if (!(c < 0.999))
                contractive = 0;
            else
                R = fmax(R, hypot(a->t[0], a->t[1]) / (1 - c));
        }
    R = contractive ? R + hypot(opts->start[0], opts->start[1]) + 1e-9 : 1e6;
    lo[0] = lo[1] = -R;
    hi[0] = hi[1] = R;
    fset_chaos_opts fo = *opts;
    fo.points = opts->points < 50000 ? opts->points : 50000;
    for (int pass = 0; pass < 4; pass++) {
        hist2 hs;
        const int G = 256;
        rt_code c = hist2_init(&hs, G, G, lo, hi, 0, e);
        if (c)
            return c;
        if ((c = fset_chaos(fs, o, &fo, &hs, run, e))) {
            hist2_free(&hs);
            return c;
        }
        int x0 = G, x1 = -1, y0 = G, y1 = -1;
        for (int j = 0; j < G; j++)
            for (int i = 0; i < G; i++)
                if (hs.count[(size_t)j * G + i]) {
                    if (i < x0)
                        x0 = i;
                    if (i > x1)
                        x1 = i;
                    if (j < y0)
                        y0 = j;
                    if (j > y1)
                        y1 = j;
                }
        hist2_free(&hs);
        if (x1 < 0)
            return rt_fail(e, RT_EINVAL, "no point of the chaos game fell near the origin; give window: [xmin, xmax, ymin, ymax]");
        double bx = (hi[0] - lo[0]) / G, by = (hi[1] - lo[1]) / G;
        double nlo0 = lo[0] + (x0 - 1) * bx, nhi0 = lo[0] + (x1 + 2) * bx;
        double nhi1 = hi[1] - (y0 - 1) * by, nlo1 = hi[1] - (y1 + 2) * by;
        lo[0] = nlo0;
        hi[0] = nhi0;
        lo[1] = nlo1;
        hi[1] = nhi1;
    }
    fit_aspect(lo, hi, w, h, 0.03);
    return RT_OK;
}

/* chaos_fset(system, order, points, size, window, mode, depth, burn, start,
 *            palette, curve, gamma, brightness, background, seed) */
static int b_chaos_fset(interp *I, value *a, int n, value *out)
{
    (void)n;
    value fv;
    if (get_fset(I, a[0], 1, &fv, "chaos_fset: system"))
        return -1;
    const lang_fset *f = as_fset(fv);
    int rc = -1, *tmp = NULL;
    fset_order o;
    fset_chaos_opts co;
    memset(&co, 0, sizeof co);
    int w, h;
    ramp r;
    tonemap_opts t;
    long depth;
    if (order_arg(I, a[1], 1, f->n, &o, &tmp, "chaos_fset"))
        goto done;
    if (points_arg(I, a[2], &co.points, "chaos_fset") || arg_size2(I, a[3], &w, &h, "chaos_fset: size") ||
        tone_args(I, a[9], a[10], a[11], a[12], a[13], &t, &r, "chaos_fset") || arg_seed(I, a[14], &co.seed, "chaos_fset") ||
        get_vec(I, a[8], co.start, 2, "chaos_fset: start"))
        goto done;
    if (f->dim != 2) {
        err_arg(I, 0, ERR_VALUE, "chaos_fset: the function set is 3-D; the chaos game draws 2-D sets (use iterate for 3-D shapes)");
        goto done;
    }
    if (strcmp(AS_STR(a[5])->s, "orbit") == 0) { /* declared str{orbit,walk} */
        co.mode = FSET_ORBIT;
        co.plot_period = o.kind != FSET_RANDOM;
        co.burn = (uint64_t)a[7].u.n;
        if (a[6].k != V_NIL) {
            err_arg(I, 6, ERR_VALUE, "chaos_fset: depth applies to mode \"walk\", not \"orbit\"");
            goto done;
        }
    } else {
        co.mode = FSET_WALK;
        if (a[6].k == V_NIL) {
            if (o.kind == FSET_RANDOM) {
                err_arg(I, 1, ERR_VALUE, "chaos_fset: mode \"walk\" with a random order needs depth: (steps per walk)");
                goto done;
            }
            depth = o.len;
        } else {
            depth = (long)a[6].u.n;
        }
        co.depth = (uint64_t)depth;
    }
    double lo[2], hi[2];
    rt_error e;
    rt_code c;
    rt_run run = lang_run(I);
    if (a[4].k != V_NIL) {
        if (window_arg(I, a[4], lo, hi, "chaos_fset: window"))
            goto done;
    } else if ((c = fset_order_validate(&o, f->n, &e)) || (c = fset_fit(&f->fs, &o, &co, w, h, lo, hi, &run, &e))) {
        lang_rt_error(I, c, &e, "chaos_fset");
        goto done;
    }
    double bytes = (double)w * h * 8 * (I->threads + 1);
    if ((double)w * h > I->lim.max_pixels) {
        err_at(I, NULL, ERR_LIMIT, "chaos_fset: %d×%d pixels exceed the pixel limit (raise it with --max-pixels)", w, h);
        goto done;
    }
    if (mem_precheck(I, bytes, "chaos_fset: the histograms"))
        goto done;
    hist2 hs;
    image *im = NULL;
    c = hist2_init(&hs, w, h, lo, hi, 0, &e);
    if (!c) {
        c = fset_chaos(&f->fs, &o, &co, &hs, &run, &e);
        if (!c && !lang_image_new(I, w, h, &im))
            c = tonemap_apply(&hs, &t, im, &e);
        hist2_free(&hs);
    }
    if (c || !im) {
        lang_image_discard(im);
        if (!I->err.active)
            lang_rt_error(I, c, &e, "chaos_fset");
        goto done;
    }
    rc = lang_image_value(I, im, out);
done:
    mem_free(I, tmp);
    val_unref(I, fv);
    return rc;
}

/* ---- fractal tops and colour stealing ---------------------------------------------------- */

static fset_ifs ifs_view(const lang_ifs *li) { return (fset_ifs){li->f.n, li->f.maps, li->f.p}; }

/* The view of an IFS's attractor (fitted by chaos_fit) or of a window. */
static int ifs_window(interp *I, const lang_ifs *li, value window, int w, int h, uint64_t seed, double lo[2],
                      double hi[2], const char *what)
{
    if (window.k != V_NIL) {
        char wn[64];
        snprintf(wn, sizeof wn, "%s", what);
        return window_arg(I, window, lo, hi, wn);
    }
    if (li->f.dim != 2)
        return err_at(I, NULL, ERR_VALUE, "%s: the IFS is 3-D; fractal tops and colour stealing need 2-D maps", what);
    chaos_sys s = {&li->f, NULL};
    chaos_opts o;
    memset(&o, 0, sizeof o);
    o.seed = seed;
    o.points = 100000;
    rt_error e;
    rt_code c = chaos_fit(&s, &o, w, h, lo, hi, &e);
    return c ? lang_rt_error(I, c, &e, what) : 0;
}

/* top(system, size, points, window, palette, symbols, depth, background, seed) */
static int b_top(interp *I, value *a, int n, value *out)
{
    (void)n;
    const lang_ifs *li = lang_as_ifs(a[0]);
    int w, h;
    tops_opts to;
    memset(&to, 0, sizeof to);
    ramp r;
    float bg[4];
    long nsym = (long)a[5].u.n; /* declared int[1,64] */
    to.depth = (int)a[6].u.n;   /* declared int[0,64] */
    if (arg_size2(I, a[1], &w, &h, "top: size") || points_arg(I, a[2], &to.points, "top") ||
        lang_get_ramp(I, a[4], &r, "top: palette") || lang_get_colour(I, a[7], bg, "top: background") ||
        arg_seed(I, a[8], &to.seed, "top"))
        return -1;
    if (li->f.dim != 2)
        return err_arg(I, 0, ERR_VALUE, "top: the IFS is 3-D; fractal tops need 2-D maps");
    double lo[2], hi[2];
    if (ifs_window(I, li, a[3], w, h, to.seed, lo, hi, "top: window"))
        return -1;
    if ((double)w * h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT, "top: %d×%d pixels exceed the pixel limit (raise it with --max-pixels)", w, h);
    double bytes = (double)w * h * sizeof(tops_cell) * (I->threads + 1);
    if (mem_precheck(I, bytes, "top: the address buffers"))
        return -1;
    draw_view view;
    tops_buf tb;
    rt_error e;
    rt_run run = lang_run(I);
    fset_ifs f = ifs_view(li);
    image *im = NULL;
    rt_code c = draw_view_fit(&view, w, h, lo, hi, 1, &e);
    if (!c)
        c = tops_run(&f, &view, &to, &tb, &run, &e);
    if (c)
        return lang_rt_error(I, c, &e, "top");
    if (nsym > tb.depth) {
        tops_free(&tb);
        return err_arg(I, 5, ERR_VALUE, "top: symbols must be between 1 and the address depth %d, got %ld", tb.depth, nsym);
    }
    if (lang_image_new(I, w, h, &im)) {
        tops_free(&tb);
        return -1;
    }
    c = tops_colour(&tb, (int)nsym, &r, bg, im, &e);
    tops_free(&tb);
    return lang_image_finish(I, im, c, &e, "top", out);
}

/* Shared set-up of steal / fractal_filter: a[0] screen, a[1] source, then
 * size, points, window, source_window, background, depth, seed at the
 * given indices. */
typedef struct steal_setup {
    fset_ifs f, g;
    int w, h;
    tops_opts to;
    float bg[4];
    double lo[2], hi[2], slo[2], shi[2];
} steal_setup;

static int steal_args(interp *I, value *a, int k, steal_setup *s, int src_w, int src_h, const char *what)
{
    const lang_ifs *fi = lang_as_ifs(a[0]), *gi = lang_as_ifs(a[1]);
    memset(s, 0, sizeof *s);
    char wn[64];
    snprintf(wn, sizeof wn, "%s: size", what);
    if (arg_size2(I, a[k], &s->w, &s->h, wn) || points_arg(I, a[k + 1], &s->to.points, what))
        return -1;
    snprintf(wn, sizeof wn, "%s: background", what);
    if (lang_get_colour(I, a[k + 4], s->bg, wn))
        return -1;
    s->to.depth = (int)a[k + 5].u.n; /* declared int[0,64] */
    if (arg_seed(I, a[k + 6], &s->to.seed, what))
        return -1;
    if (fi->f.n != gi->f.n)
        return err_arg(I, 1, ERR_VALUE,
                      "%s: the screen IFS has %d maps but the source IFS has %d; colour stealing pairs map i of one with map i of the other",
                      what, fi->f.n, gi->f.n);
    if (fi->f.dim != 2 || gi->f.dim != 2)
        return err_arg(I, fi->f.dim != 2 ? 0 : 1, ERR_VALUE, "%s: colour stealing needs 2-D IFSs", what);
    snprintf(wn, sizeof wn, "%s: window", what);
    if (ifs_window(I, fi, a[k + 2], s->w, s->h, s->to.seed, s->lo, s->hi, wn))
        return -1;
    snprintf(wn, sizeof wn, "%s: source_window", what);
    if (ifs_window(I, gi, a[k + 3], src_w, src_h, s->to.seed, s->slo, s->shi, wn))
        return -1;
    if ((double)s->w * s->h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT, "%s: %d×%d pixels exceed the pixel limit (raise it with --max-pixels)", what,
                      s->w, s->h);
    s->f = ifs_view(fi);
    s->g = ifs_view(gi);
    return 0;
}

/* steal(screen, source, picture, size, points, window, source_window, background, depth, seed) */
static int b_steal(interp *I, value *a, int n, value *out)
{
    (void)n;
    const image *pic = lang_as_image(a[2]);
    steal_setup s;
    if (steal_args(I, a, 3, &s, pic->w, pic->h, "steal"))
        return -1;
    double bytes = (double)s.w * s.h * sizeof(tops_cell) * (I->threads + 1);
    if (mem_precheck(I, bytes, "steal: the address buffers"))
        return -1;
    draw_view sv, srcv;
    tops_buf tb;
    rt_error e;
    rt_run run = lang_run(I);
    rt_code c = draw_view_fit(&sv, s.w, s.h, s.lo, s.hi, 1, &e);
    if (!c)
        c = draw_view_fit(&srcv, pic->w, pic->h, s.slo, s.shi, 0, &e);
    if (!c)
        c = tops_steal(&s.f, &sv, &s.g, &srcv, &s.to, &tb, &run, &e);
    if (c)
        return lang_rt_error(I, c, &e, "steal");
    image *im;
    if (lang_image_new(I, s.w, s.h, &im)) {
        tops_free(&tb);
        return -1;
    }
    c = tops_steal_apply(&tb, pic, s.bg, im, &e);
    tops_free(&tb);
    return lang_image_finish(I, im, c, &e, "steal", out);
}

/* fractal_filter(screen, source, frames, size, points, window, source_window, background, depth, seed) */
static int b_fractal_filter(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *fl = AS_LIST(a[2]);
    if (fl->n < 1)
        return err_arg(I, 2, ERR_VALUE, "fractal_filter: frames is empty (give a list of images of one size)");
    if (fl->n > 100000)
        return err_arg(I, 2, ERR_VALUE, "fractal_filter: %zu frames, at most 100000", fl->n);
    image *frames = mem_alloc(I, sizeof(image) * fl->n);
    if (!frames)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    for (size_t i = 0; i < fl->n; i++) {
        const image *im = lang_as_image(fl->items[i]);
        if (!im) {
            mem_free(I, frames);
            return err_item(I, a[2], i, ERR_TYPE, "fractal_filter: frame %zu must be an image, got %s", i + 1,
                            val_type_name(fl->items[i]));
        }
        frames[i] = *im;
        if (im->w != frames[0].w || im->h != frames[0].h) {
            int w0 = frames[0].w, h0 = frames[0].h;
            mem_free(I, frames);
            return err_item(I, a[2], i, ERR_VALUE, "fractal_filter: frame %zu is %d×%d but frame 1 is %d×%d", i + 1, im->w,
                            im->h, w0, h0);
        }
    }
    steal_setup s;
    if (steal_args(I, a, 3, &s, frames[0].w, frames[0].h, "fractal_filter")) {
        mem_free(I, frames);
        return -1;
    }
    if ((double)s.w * s.h * (double)fl->n > I->lim.max_pixels * 64) {
        mem_free(I, frames);
        return err_at(I, NULL, ERR_LIMIT, "fractal_filter: %zu frames of %d×%d pixels are too many (raise --max-pixels)",
                      fl->n, s.w, s.h);
    }
    double bytes = (double)s.w * s.h * sizeof(tops_cell) * (I->threads + 1);
    if (mem_precheck(I, bytes, "fractal_filter: the address buffers")) {
        mem_free(I, frames);
        return -1;
    }
    image *res = mem_calloc(I, fl->n, sizeof(image));
    value l = val_list(I, fl->n);
    draw_view sv;
    rt_error e;
    rt_run run = lang_run(I);
    rt_code c = !res ? rt_fail(&e, RT_ENOMEM, "out of memory") : draw_view_fit(&sv, s.w, s.h, s.lo, s.hi, 1, &e);
    if (!c && l.k != V_NIL)
        c = tops_filter(&s.f, &sv, &s.g, s.slo, s.shi, frames, (int)fl->n, &s.to, s.bg, res, &run, &e);
    mem_free(I, frames);
    if (c || l.k == V_NIL) {
        if (res)
            for (size_t i = 0; i < fl->n; i++)
                image_free(&res[i]);
        mem_free(I, res);
        if (l.k != V_NIL)
            val_unref(I, l);
        return I->err.active ? -1 : lang_rt_error(I, c, &e, "fractal_filter");
    }
    size_t i = 0;
    for (; i < fl->n; i++) {
        image *im = mem_alloc(I, sizeof *im);
        value v;
        if (!im) {
            err_at(I, NULL, ERR_MEMORY, "out of memory");
            break;
        }
        *im = res[i];
        res[i].px = NULL;
        if (lang_image_value(I, im, &v) || list_push(I, AS_LIST(l), v)) {
            i++;
            break;
        }
    }
    if (i < fl->n || I->err.active) {
        for (; i < fl->n; i++)
            image_free(&res[i]);
        mem_free(I, res);
        val_unref(I, l);
        return -1;
    }
    mem_free(I, res);
    *out = l;
    return 0;
}

/* ---- super IFS ------------------------------------------------------------------------- */

typedef struct lang_superifs {
    superifs_state st;
    int nifs;
    uint64_t steps;
} lang_superifs;

static void superifs_destroy(void *pp)
{
    lang_superifs *s = pp;
    superifs_free(&s->st);
    rt_free(s);
}

static void superifs_summary(const void *pp, bytebuf *out)
{
    const lang_superifs *s = pp;
    bytebuf_printf(out, "superifs: V = %d buffers of %zu points, %d IFSs, %llu steps; last step used", s->st.V,
                   s->st.points, s->nifs, (unsigned long long)s->steps);
    for (int v = 0; v < s->st.V && v < 16; v++) {
        if (s->st.ifs_of[v] < 0)
            bytebuf_printf(out, " -");
        else
            bytebuf_printf(out, " F%d", s->st.ifs_of[v] + 1);
    }
    if (s->st.V > 16)
        bytebuf_printf(out, " …");
}

static int superifs_get(interp *I, const void *pp, const char *name, value *out)
{
    const lang_superifs *s = pp;
    if (strcmp(name, "V") == 0)
        *out = val_num(s->st.V);
    else if (strcmp(name, "points") == 0)
        *out = val_num((double)s->st.points);
    else if (strcmp(name, "steps") == 0)
        *out = val_num((double)s->steps);
    else if (strcmp(name, "ifs") == 0) {
        value l = val_list(I, (size_t)s->st.V);
        if (l.k == V_NIL)
            return -1;
        for (int v = 0; v < s->st.V; v++)
            if (list_push(I, AS_LIST(l), s->st.ifs_of[v] < 0 ? val_nil() : val_num(s->st.ifs_of[v] + 1))) {
                val_unref(I, l);
                return -1;
            }
        *out = l;
        return 0;
    } else
        return 1;
    return 0;
}

static const obj_class superifs_class = {
    .name = "superifs",
    .destroy = superifs_destroy,
    .summary = superifs_summary,
    .get = superifs_get,
};

/* superifs(sets, probabilities, V, points, steps, start, seed) */
static int b_superifs(interp *I, value *a, int n, value *out)
{
    (void)n;
    value fv;
    if (get_fset(I, a[0], 1, &fv, "superifs: sets"))
        return -1;
    const lang_fset *f = as_fset(fv);
    int rc = -1;
    double *P = NULL;
    superifs_opts so;
    memset(&so, 0, sizeof so);
    long V = (long)a[2].u.n, steps = (long)a[4].u.n; /* declared int[1,1024], int[0,100000] */
    uint64_t pts = 0;
    if (points_arg(I, a[3], &pts, "superifs") || get_vec(I, a[5], so.start, 2, "superifs: start") ||
        arg_seed(I, a[6], &so.seed, "superifs"))
        goto done;
    if (f->dim != 2) {
        err_arg(I, 0, ERR_VALUE, "superifs: the IFSs are 3-D; a super IFS needs 2-D maps");
        goto done;
    }
    if (a[1].k != V_NIL) {
        size_t np = AS_LIST(a[1])->n;
        if ((int)np != f->n) {
            err_arg(I, 1, ERR_VALUE, "superifs: probabilities must be a list of %d numbers (one per IFS), got %zu", f->n, np);
            goto done;
        }
        P = mem_alloc(I, sizeof(double) * np);
        if (!P) {
            err_at(I, NULL, ERR_MEMORY, "out of memory");
            goto done;
        }
        if (get_vec(I, a[1], P, np, "superifs: probabilities"))
            goto done;
        double sum = 0; /* each in [0, 1] (declared) */
        for (size_t i = 0; i < np; i++)
            sum += P[i];
        if (fabs(sum - 1) > 1e-6) {
            err_arg(I, 1, ERR_VALUE, "superifs: probabilities sum to %.9g (expected 1)", sum);
            goto done;
        }
    }
    if ((double)V * (double)pts > I->lim.max_points) {
        err_at(I, NULL, ERR_LIMIT, "superifs: %ld buffers of %.0f points exceed the limit of %.0f points (raise it with --max-points)",
               V, (double)pts, I->lim.max_points);
        goto done;
    }
    so.V = (int)V;
    so.points = (size_t)pts;
    so.steps = (uint64_t)steps;
    double bytes = (double)V * (double)pts * 16 * 2;
    if (mem_precheck(I, bytes, "superifs: the buffers"))
        goto done;
    lang_superifs *ls = mem_calloc(I, 1, sizeof *ls);
    if (!ls) {
        err_at(I, NULL, ERR_MEMORY, "out of memory");
        goto done;
    }
    rt_error e;
    rt_run run = lang_run(I);
    rt_code c = superifs_run(&f->fs, P, &so, &ls->st, &run, &e);
    if (c) {
        mem_free(I, ls);
        lang_rt_error(I, c, &e, "superifs");
        goto done;
    }
    ls->nifs = f->n;
    ls->steps = so.steps;
    *out = val_obj(I, &superifs_class, ls);
    rc = out->k == V_NIL ? -1 : 0;
done:
    mem_free(I, P);
    val_unref(I, fv);
    return rc;
}

/* superifs_image(s, buffer, size, window, palette, curve, gamma, brightness, background) */
static int b_superifs_image(interp *I, value *a, int n, value *out)
{
    (void)n;
    const lang_superifs *s = AS_OBJ(a[0])->payload;
    long buf = (long)a[1].u.n; /* declared int>=1 */
    int w, h;
    ramp r;
    tonemap_opts t;
    if (buf > s->st.V)
        return err_arg(I, 1, ERR_VALUE, "superifs_image: buffer must be between 1 and V = %d, got %ld", s->st.V, buf);
    if (arg_size2(I, a[2], &w, &h, "superifs_image: size") ||
        tone_args(I, a[4], a[5], a[6], a[7], a[8], &t, &r, "superifs_image"))
        return -1;
    double lo[2], hi[2];
    if (a[3].k != V_NIL) {
        if (window_arg(I, a[3], lo, hi, "superifs_image: window"))
            return -1;
    } else {
        /* the bounds of all buffers, so every buffer is drawn at one scale */
        lo[0] = lo[1] = INFINITY;
        hi[0] = hi[1] = -INFINITY;
        size_t np = (size_t)s->st.V * s->st.points;
        for (size_t i = 0; i < np; i++)
            for (int k = 0; k < 2; k++) {
                double x = s->st.pts[2 * i + (size_t)k];
                if (!isfinite(x))
                    continue;
                if (x < lo[k])
                    lo[k] = x;
                if (x > hi[k])
                    hi[k] = x;
            }
        if (!(hi[0] >= lo[0]) || !(hi[1] >= lo[1]))
            return err_at(I, NULL, ERR_VALUE, "superifs_image: the buffers hold no finite points; give window:");
        fit_aspect(lo, hi, w, h, 0.03);
    }
    if ((double)w * h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT, "superifs_image: %d×%d pixels exceed the pixel limit (raise it with --max-pixels)", w, h);
    hist2 hs;
    rt_error e;
    image *im = NULL;
    rt_code c = hist2_init(&hs, w, h, lo, hi, 0, &e);
    if (c)
        return lang_rt_error(I, c, &e, "superifs_image");
    c = superifs_render(&s->st, (int)buf - 1, &hs, &e);
    if (!c && !lang_image_new(I, w, h, &im))
        c = tonemap_apply(&hs, &t, im, &e);
    hist2_free(&hs);
    if (c || !im) {
        lang_image_discard(im);
        return I->err.active ? -1 : lang_rt_error(I, c, &e, "superifs_image");
    }
    return lang_image_value(I, im, out);
}

/* ---- tiles ----------------------------------------------------------------------------- */

static int wrap_image(interp *I, image *res, value *out)
{
    image *im = mem_alloc(I, sizeof *im);
    if (!im) {
        image_free(res);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    *im = *res;
    return lang_image_value(I, im, out);
}

/* tile(image, mirror, mode) */
static int b_tile(interp *I, value *a, int n, value *out)
{
    (void)n;
    const image *src = lang_as_image(a[0]);
    const char *m = AS_STR(a[1])->s, *md = AS_STR(a[2])->s;
    /* declared str{lr,tb,both} and str{max,mean,over} */
    int mirror = strcmp(m, "lr") == 0 ? TILES_LR : strcmp(m, "tb") == 0 ? TILES_TB : TILES_LR | TILES_TB;
    tiles_overlay rule = strcmp(md, "mean") == 0 ? TILES_MEAN : strcmp(md, "over") == 0 ? TILES_OVER : TILES_MAX;
    image res;
    rt_error e;
    rt_code c = tiles_symmetric(src, mirror, rule, &res, &e);
    if (c)
        return lang_rt_error(I, c, &e, "tile");
    return wrap_image(I, &res, out);
}

/* tiling(tile, size, mirrored) */
static int b_tiling(interp *I, value *a, int n, value *out)
{
    (void)n;
    const image *t = lang_as_image(a[0]);
    int w, h;
    if (arg_size2(I, a[1], &w, &h, "tiling: size"))
        return -1;
    if ((double)w * h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT,
                      "image of %d×%d pixels exceeds the limit of %.0f pixels (raise it with --max-pixels)", w, h,
                      I->lim.max_pixels);
    image res;
    rt_error e;
    rt_code c = tiles_fill(t, w, h, val_truthy(a[2]), &res, &e);
    if (c)
        return lang_rt_error(I, c, &e, "tiling");
    return wrap_image(I, &res, out);
}

/* ---- registration ---------------------------------------------------------------------- */

static const bparam p_fset[] = {{"sets", "list", NULL}};
static const bparam p_order[] = {{"sequence", "list|str", "nil"},
                                 {"repeat", "bool", "false"},
                                 {"probabilities", "vec[0,1]", "nil"},
                                 {"seed", "int>=0", "nil"}};
static const bparam p_shape[] = {{"points", "list", "nil"}};
static const bparam p_iterate[] = {{"system", "ifs|fset|list", NULL},
                                   {"start", "shape", "nil"},
                                   {"steps", "int[0,1000000]", "nil"},
                                   {"order", "order", "nil"}};
#define TY_FILL "bool|" TY_COLOUR
#define TY_CURVE "str{log,linear}"
static const bparam p_draw[] = {{"shape", "shape", NULL},            {"size", TY_SIZE, "[512, 512]"},
                                {"window", "vec4", "nil"},           {"colour", TY_COLOUR, "1"},
                                {"width", "num[0,1000]", "1"},       {"radius", "num[0,1000]", "1"},
                                {"fill", TY_FILL, "nil"},            {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                {"onto", "image", "nil"}};
static const bparam p_chaos_fset[] = {{"system", "fset|ifs|list", NULL},   {"order", "order", "nil"},
                                      {"points", "int>=1", "1e6"},          {"size", TY_SIZE, "[512, 512]"},
                                      {"window", "vec4", "nil"},            {"mode", "str{orbit,walk}", "\"orbit\""},
                                      {"depth", "int[1,1000000]", "nil"},   {"burn", "int[0,1000000]", "20"},
                                      {"start", "vec2", "[0, 0]"},          {"palette", "list", "nil"},
                                      {"curve", TY_CURVE, "\"log\""},       {"gamma", "num>0", "2.2"},
                                      {"brightness", "num>0", "1"},         {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                      {"seed", "int>=0", "nil"}};
static const bparam p_top[] = {{"system", "ifs", NULL},           {"size", TY_SIZE, "[512, 512]"},
                               {"points", "int>=1", "1e6"},      {"window", "vec4", "nil"},
                               {"palette", "list", "nil"},       {"symbols", "int[1,64]", "1"},
                               {"depth", "int[0,64]", "0"},      {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                               {"seed", "int>=0", "nil"}};
static const bparam p_steal[] = {{"screen", "ifs", NULL},          {"source", "ifs", NULL},
                                 {"picture", "image", NULL},       {"size", TY_SIZE, "[512, 512]"},
                                 {"points", "int>=1", "1e6"},      {"window", "vec4", "nil"},
                                 {"source_window", "vec4", "nil"}, {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                 {"depth", "int[0,64]", "0"},      {"seed", "int>=0", "nil"}};
static const bparam p_filter[] = {{"screen", "ifs", NULL},          {"source", "ifs", NULL},
                                  {"frames", "list", NULL},         {"size", TY_SIZE, "[512, 512]"},
                                  {"points", "int>=1", "1e6"},      {"window", "vec4", "nil"},
                                  {"source_window", "vec4", "nil"}, {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                  {"depth", "int[0,64]", "0"},      {"seed", "int>=0", "nil"}};
static const bparam p_superifs[] = {{"sets", "list|fset", NULL},   {"probabilities", "vec[0,1]", "nil"},
                                    {"V", "int[1,1024]", "3"},     {"points", "int>=1", "1e5"},
                                    {"steps", "int[0,100000]", "20"}, {"start", "vec2", "[0, 0]"},
                                    {"seed", "int>=0", "nil"}};
static const bparam p_superifs_image[] = {{"superifs", "superifs", NULL},   {"buffer", "int>=1", "1"},
                                          {"size", TY_SIZE, "[512, 512]"},  {"window", "vec4", "nil"},
                                          {"palette", "list", "nil"},       {"curve", TY_CURVE, "\"log\""},
                                          {"gamma", "num>0", "2.2"},        {"brightness", "num>0", "1"},
                                          {"background", TY_COLOUR, "[0, 0, 0, 1]"}};
static const bparam p_tile[] = {{"image", "image", NULL},
                                {"mirror", "str{lr,tb,both}", "\"both\""},
                                {"mode", "str{max,mean,over}", "\"max\""}};
static const bparam p_tiling[] = {{"tile", "image", NULL}, {"size", TY_SIZE, NULL}, {"mirrored", "bool", "false"}};

static const builtin fset_builtins[] = {
    BUILTIN("fset", b_fset, p_fset,
            "A function set {W1, …, WN} (seed 003 def. 3.1): a list of IFSs, each an ifs value or a table of map rows. Sets are numbered from 1 (W1) as in the paper."),
    BUILTIN("order", b_order, p_order,
            "Which set each step uses: order([1, 2, 1, 2]) lists set numbers in application order (the first is applied first, to K0); order(\"W2 ∘ W1 ∘ W2 ∘ W1\") is the paper's composition notation (rightmost applied first); repeat: true cycles the sequence; order(probabilities: [p1, …], seed:) picks W_n with probability p_n at every step (seed 003 def. 3.2)."),
    BUILTIN_VAR("polygon", b_polygon, p_shape,
                "A closed polygon (an initial set K0): polygon([x, y], [x, y], [x, y], …) or polygon(list of points); 2-D or 3-D points."),
    BUILTIN_VAR("polyline", b_polyline, p_shape, "An open polyline (an initial set K0) through the given points."),
    BUILTIN_VAR("pointset", b_pointset, p_shape, "A set of separate points (an initial set K0)."),
    BUILTIN("iterate", b_iterate, p_iterate,
            "Deterministic iteration K_n = W_σ(n) ∘ … ∘ W_σ(1)(K0) (seed 003 §2-2, §3-2): each step replaces the shape by the union of its images under every map of the set the order names. system: an ifs, a table or an fset; start: a shape (default: the triangle (0,0), (1,0), (1/2, √3/6)); steps: default the length of a sequence order; order: default W1, W2, …, WN repeated. The vertex count is checked against --max-points first."),
    BUILTIN("draw", b_draw, p_draw,
            "An antialiased image of a shape: strokes of width pixels in colour, points as discs of radius, closed polygons filled if fill is true or a colour; window [xmin, xmax, ymin, ymax] or fitted to the shape; onto: draw over a copy of an image instead of a background."),
    BUILTIN("chaos_fset", b_chaos_fset, p_chaos_fset,
            "The chaos game of a function set with an order, tone-mapped like chaos(…). mode \"orbit\": one long orbit per chunk; with a sequence or periodic order a point is plotted after each full period (the attractor of the composition); with a random order after every step. mode \"walk\": every point is the end of a fresh walk of depth steps from start (a sample of K_depth)."),
    BUILTIN("top", b_top, p_top,
            "The fractal top of a 2-D IFS (seed 004 §3): every pixel coloured by the first symbols of the greatest address among the points that fall in it, through the palette."),
    BUILTIN("steal", b_steal, p_steal,
            "Colour stealing (seed 004 §4): the screen IFS draws its fractal top while the source IFS, with the same number of maps and the same random indices, walks over the picture; each pixel takes the colour of the source pixel its top point stole. source_window: the part of the source IFS's plane the picture covers (default: its fitted attractor)."),
    BUILTIN("fractal_filter", b_fractal_filter, p_filter,
            "The fractal filter (seed 004 §6): colour stealing with one top applied to every frame of a list of images of one size; a list of images."),
    BUILTIN("superifs", b_superifs, p_superifs,
            "A V-variable super IFS (seed 004 §5): V buffers of points, each step replacing every buffer by the union of the maps of a randomly chosen IFS applied to randomly chosen buffers. sets: a list of IFSs or an fset; probabilities: of choosing each IFS (default equal). V = 1 is Asai's random function set."),
    BUILTIN("superifs_image", b_superifs_image, p_superifs_image,
            "An image of one buffer (1 .. V) of a super IFS, tone-mapped like chaos(…); the default window covers all buffers so they share one scale."),
    BUILTIN("tile", b_tile, p_tile,
            "A symmetric tile (seed 003 §4-1): the image overlaid with its left-right (\"lr\"), top-bottom (\"tb\") or both mirror images, combined by \"max\", \"mean\" or \"over\" (alpha compositing)."),
    BUILTIN("tiling", b_tiling, p_tiling,
            "A pattern: the tile repeated across an image of size pixels from the top-left corner; mirrored: true flips odd columns and rows so any tile joins seamlessly."),
};

int bind_fset_init(interp *I)
{
    return builtins_register(I, fset_builtins, (int)(sizeof fset_builtins / sizeof fset_builtins[0]));
}
