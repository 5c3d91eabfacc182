/* bind_ifs.c — affine maps, IFS and Recurrent IFS in the language, and the
 * chaos-game evaluations (seed 001 §5 measures, seed 003/004 IFS).
 *
 * Maps are values of class "map" (an affine map of the plane or of space):
 * affine(a, b, c, d, e, f) in Fractint order, or affine(scale:, rotate:,
 * shear:, translate:) built from transforms; m1 * m2 is the composition m1 ∘ m2
 * (m2 first) and m * [x, y] applies a map. An IFS is declared from a table
 * whose rows are maps in the literature's column orders (the row length
 * tells which), or from a list of maps.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "affine.h"
#include "builtin.h"
#include "chaos.h"
#include "fileio.h"
#include "flam3.h"
#include "fractint.h"
#include "hist.h"
#include "ifs.h"
#include "lang_image.h"
#include "lang_ifs.h"
#include "lang_objects.h"
#include "shard.h"
#include "lexer.h"
#include "tonemap.h"
#include "report.h"

/* ---- maps --------------------------------------------------------------------------- */

static void map_destroy(void *p) { rt_free(p); }

static void map_summary(const void *p, bytebuf *out)
{
    const affine *a = p;
    if (a->dim == 2)
        bytebuf_printf(out, "map 2-D [a b c d e f] = [%g %g %g %g %g %g], contraction %.4g", a->m[0][0],
                       a->m[0][1], a->m[1][0], a->m[1][1], a->t[0], a->t[1], affine_contraction(a));
    else
        bytebuf_printf(out, "map 3-D [%g %g %g; %g %g %g; %g %g %g] + [%g %g %g], contraction %.4g", a->m[0][0],
                       a->m[0][1], a->m[0][2], a->m[1][0], a->m[1][1], a->m[1][2], a->m[2][0], a->m[2][1],
                       a->m[2][2], a->t[0], a->t[1], a->t[2], affine_contraction(a));
}

static int map_row(interp *I, const affine *a, value *out)
{
    if (a->dim == 2) {
        double r[6] = {a->m[0][0], a->m[0][1], a->m[1][0], a->m[1][1], a->t[0], a->t[1]};
        return lang_num_list_value(I, r, (size_t)(6), out);
    }
    double r[12];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[3 * i + j] = a->m[i][j];
    for (int i = 0; i < 3; i++)
        r[9 + i] = a->t[i];
    return lang_num_list_value(I, r, (size_t)(12), out);
}

static int map_get(interp *I, const void *p, const char *name, value *out)
{
    const affine *a = p;
    if (strcmp(name, "contraction") == 0)
        *out = val_num(affine_contraction(a));
    else if (strcmp(name, "det") == 0)
        *out = val_num(affine_det(a));
    else if (strcmp(name, "dim") == 0)
        *out = val_num(a->dim);
    else if (strcmp(name, "row") == 0)
        return map_row(I, a, out);
    else
        return 1;
    return 0;
}

static int map_arith(interp *I, int op, value a, value b, value *out);

const obj_class lang_map_class = {
    .name = "map",
    .destroy = map_destroy,
    .summary = map_summary,
    .arith = map_arith,
    .get = map_get,
};

static const affine *as_map(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_map_class ? AS_OBJ(v)->payload : NULL;
}

static int map_value(interp *I, affine a, value *out)
{
    affine *p = mem_alloc(I, sizeof *p);
    if (!p)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    *p = a;
    *out = val_obj(I, &lang_map_class, p);
    return out->k == V_NIL ? -1 : 0;
}

static int map_arith(interp *I, int op, value a, value b, value *out)
{
    const affine *x = as_map(a), *y = as_map(b);
    if (op != T_STAR)
        return 0;
    if (x && y)
        return map_value(I, affine_compose(x, y), out) ? -1 : 1;
    if (x && b.k == V_LIST) {
        double p[3] = {0, 0, 0}, q[3];
        size_t n = AS_LIST(b)->n;
        if ((int)n != x->dim)
            return err_at(I, NULL, ERR_VALUE, "a %d-D map applies to points of %d numbers, got %zu", x->dim,
                          x->dim, n);
        if (builtin_get_vec(I, b, p, n, "point"))
            return -1;
        affine_apply(x, p, q);
        return lang_num_list_value(I, q, (size_t)(x->dim), out) ? -1 : 1;
    }
    return 0;
}

/* A map from a table row in one of the literature's column orders. */
static int row_to_map(interp *I, value table, value row, affine *m, double *p, int *has_p, int index,
                      const char *fn)
{
    double r[13];
    size_t n = row.k == V_LIST ? AS_LIST(row)->n : 0;
    char what[64];
    snprintf(what, sizeof what, "row %d", index + 1);
    if (n != 6 && n != 7 && n != 12 && n != 13)
        return err_item(I, table, (size_t)index, ERR_VALUE,
                      "%s: row %d has %zu numbers; a map row has 6 or 7 (2-D: a b c d e f [p]) or 12 or 13 (3-D: "
                      "a b c d e f g h i j k l [p])",
                      fn, index + 1, n);
    if (builtin_get_vec(I, row, r, n, what))
        return -1;
    if (n <= 7) {
        *m = affine_from_2d(r[0], r[1], r[2], r[3], r[4], r[5]);
        *has_p = n == 7;
        *p = n == 7 ? r[6] : 0;
    } else {
        *m = affine_from_3d(r, r + 9);
        *has_p = n == 13;
        *p = n == 13 ? r[12] : 0;
    }
    return 0;
}

int lang_get_maps(interp *I, value v, affine **maps, double **p, int *n, const char *what)
{
    *maps = NULL;
    *p = NULL;
    *n = 0;
    const lang_ifs *li = lang_as_ifs(v);
    if (li) {
        *n = li->f.n;
        *maps = mem_alloc(I, sizeof(affine) * (size_t)*n);
        *p = mem_alloc(I, sizeof(double) * (size_t)*n);
        if (!*maps || !*p) {
            mem_free(I, *maps);
            mem_free(I, *p);
            *maps = NULL; /* the caller frees what it holds on error: nothing here */
            *p = NULL;
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        }
        memcpy(*maps, li->f.maps, sizeof(affine) * (size_t)*n);
        memcpy(*p, li->f.p, sizeof(double) * (size_t)*n);
        return 1;
    }
    if (v.k != V_LIST)
        return err_value(I, v, ERR_TYPE, "%s must be a table of map rows, a list of maps or an ifs, got %s", what,
                      val_type_name(v));
    vlist *l = AS_LIST(v);
    if (l->n == 0)
        return err_value(I, v, ERR_VALUE, "%s: IFS has no maps", what);
    if (l->n > IFS_MAX_MAPS)
        return err_value(I, v, ERR_VALUE, "%s: %zu maps, at most %d", what, l->n, IFS_MAX_MAPS);
    *maps = mem_alloc(I, sizeof(affine) * l->n);
    *p = mem_alloc(I, sizeof(double) * l->n);
    if (!*maps || !*p) {
        mem_free(I, *maps);
        mem_free(I, *p);
        *maps = NULL; /* the caller frees what it holds on error: nothing here */
        *p = NULL;
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    int all_p = 1;
    for (size_t i = 0; i < l->n; i++) {
        const affine *m = as_map(l->items[i]);
        int has = 0;
        if (m) {
            (*maps)[i] = *m;
            (*p)[i] = 0;
        } else if (row_to_map(I, v, l->items[i], &(*maps)[i], &(*p)[i], &has, (int)i, what)) {
            mem_free(I, *maps);
            mem_free(I, *p);
            *maps = NULL;
            *p = NULL;
            return -1;
        }
        if (i == 0)
            all_p = has;
        if (has != all_p) {
            /* the first row that differs from row 1 */
            mem_free(I, *maps);
            mem_free(I, *p);
            *maps = NULL;
            *p = NULL;
            return err_item(I, v, i, ERR_VALUE,
                            "%s: row %zu gives %s probability but row 1 %s (give one in every row or in none)",
                            what, i + 1, has ? "a" : "no", has ? "does not" : "does");
        }
        if ((*maps)[i].dim != (*maps)[0].dim) {
            int di = (*maps)[i].dim, d0 = (*maps)[0].dim;
            mem_free(I, *maps);
            mem_free(I, *p);
            *maps = NULL;
            *p = NULL;
            return err_item(I, v, i, ERR_VALUE, "%s: row %zu is a %d-D map but row 1 is %d-D", what, i + 1, di,
                            d0);
        }
    }
    *n = (int)l->n;
    return all_p;
}

/* ---- IFS and RIFS values --------------------------------------------------------------- */

static void ifs_destroy(void *p)
{
    lang_ifs *li = p;
    ifs_free(&li->f);
    rt_free(li);
}

static void ifs_summary(const void *p, bytebuf *out)
{
    const lang_ifs *li = p;
    double s = 0;
    for (int i = 0; i < li->f.n; i++)
        s += li->f.p[i];
    bytebuf_printf(out, "ifs: %d map%s, %d-D, contraction %.4g, probabilities sum %.15g", li->f.n,
                   li->f.n == 1 ? "" : "s", li->f.dim, li->f.max_contraction, s);
}

static int ifs_get(interp *I, const void *p, const char *name, value *out)
{
    const lang_ifs *li = p;
    if (strcmp(name, "maps") == 0) {
        value l = val_list(I, (size_t)li->f.n);
        if (l.k == V_NIL)
            return -1;
        for (int i = 0; i < li->f.n; i++) {
            value m;
            if (map_value(I, li->f.maps[i], &m) || val_list_push(I, AS_LIST(l), m)) {
                val_unref(I, l);
                return -1;
            }
        }
        *out = l;
        return 0;
    }
    if (strcmp(name, "probabilities") == 0)
        return lang_num_list_value(I, li->f.p, (size_t)(li->f.n), out);
    if (strcmp(name, "contraction") == 0)
        *out = val_num(li->f.max_contraction);
    else if (strcmp(name, "dim") == 0)
        *out = val_num(li->f.dim);
    else if (strcmp(name, "count") == 0)
        *out = val_num(li->f.n);
    else
        return 1;
    return 0;
}

static int sys_save(interp *I, chaos_sys *s, const char *path, value opts);
static int ifs_preview(interp *I, const void *p, image **out);

static int ifs_save_hook(interp *I, const void *p, const char *path, value opts)
{
    chaos_sys s = {&((const lang_ifs *)p)->f, NULL};
    return sys_save(I, &s, path, opts);
}

const obj_class lang_ifs_class = {
    .name = "ifs",
    .destroy = ifs_destroy,
    .summary = ifs_summary,
    .get = ifs_get,
    .save = ifs_save_hook,
    .preview = ifs_preview,
};

const lang_ifs *lang_as_ifs(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_ifs_class ? AS_OBJ(v)->payload : NULL;
}

static void rifs_destroy(void *p)
{
    lang_rifs *lr = p;
    rifs_free(&lr->r);
    rt_free(lr);
}

static void rifs_summary(const void *p, bytebuf *out)
{
    const rifs *r = &((const lang_rifs *)p)->r;
    bytebuf_printf(out, "rifs: %d maps, %d-D, Markov order %d, contraction %.4g", r->n, r->dim, r->order,
                   r->max_contraction);
}

static int rifs_get(interp *I, const void *p, const char *name, value *out)
{
    const rifs *r = &((const lang_rifs *)p)->r;
    if (strcmp(name, "stationary") == 0) {
        double *pi = mem_alloc(I, sizeof(double) * (size_t)r->n);
        if (!pi)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        rt_error e;
        if (rifs_stationary(r, pi, &e)) {
            mem_free(I, pi);
            return lang_rt_error(I, e.code, &e, "stationary");
        }
        int rc = lang_num_list_value(I, pi, (size_t)(r->n), out);
        mem_free(I, pi);
        return rc;
    }
    if (strcmp(name, "contraction") == 0)
        *out = val_num(r->max_contraction);
    else if (strcmp(name, "dim") == 0)
        *out = val_num(r->dim);
    else if (strcmp(name, "count") == 0)
        *out = val_num(r->n);
    else if (strcmp(name, "order") == 0)
        *out = val_num(r->order);
    else
        return 1;
    return 0;
}

static int rifs_save_hook(interp *I, const void *p, const char *path, value opts)
{
    chaos_sys s = {NULL, &((const lang_rifs *)p)->r};
    return sys_save(I, &s, path, opts);
}

static int rifs_preview(interp *I, const void *p, image **out);

const obj_class lang_rifs_class = {
    .name = "rifs",
    .destroy = rifs_destroy,
    .summary = rifs_summary,
    .get = rifs_get,
    .save = rifs_save_hook,
    .preview = rifs_preview,
};

static const rifs *as_rifs(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_rifs_class ? &((lang_rifs *)AS_OBJ(v)->payload)->r : NULL;
}

rt_code lang_chaos_fit(interp *I, const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                       rt_error *e)
{
    chaos_opts fo = *o;
    double cap = floor(I->lim.max_points); /* >= 1 (main.c) */
    fo.fit_points = cap < CHAOS_FIT_POINTS ? (uint64_t)(cap >= 1 ? cap : 1) : CHAOS_FIT_POINTS;
    return chaos_fit(s, &fo, w, h, lo, hi, e);
}

rt_code lang_chaos_fit_call(interp *I, const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                            rt_error *e)
{
    int dim = s->ifs ? s->ifs->dim : s->rifs->dim;
    if (shard_window_take(I, dim, lo, hi)) /* merge: the window the shards fitted */
        return RT_OK;
    rt_code c = lang_chaos_fit(I, s, o, w, h, lo, hi, e);
    if (!c)
        shard_window_put(I, dim, lo, hi);
    return c;
}

int lang_get_sys(interp *I, value v, chaos_sys *s, const char *what)
{
    const lang_ifs *li = lang_as_ifs(v);
    s->ifs = li ? &li->f : NULL;
    s->rifs = as_rifs(v);
    if (!s->ifs && !s->rifs)
        return err_value(I, v, ERR_TYPE, "%s must be an ifs or a rifs, got %s", what, val_type_name(v));
    return 0;
}

static int sys_dim(const chaos_sys *s) { return s->ifs ? s->ifs->dim : s->rifs->dim; }

/* ---- builtins: maps ---------------------------------------------------------------------- */

static int b_map(interp *I, value *a, int n, value *out)
{
    (void)n;
    /* map(a, b, c, d, e, f): Fractint order; or named transforms */
    int coef = 0, missing = -1;
    for (int i = 0; i < 6; i++) {
        coef += a[i].k == V_NUM;
        if (a[i].k != V_NUM && missing < 0)
            missing = i;
    }
    if (coef && coef != 6)
        return err_at(I, NULL, ERR_VALUE,
                      "affine: give all six coefficients a b c d e f (%c is missing), or use scale/rotate/shear/translate",
                      "abcdef"[missing]);
    if (coef == 6) {
        for (int i = 6; i < 10; i++)
            if (a[i].k != V_NIL)
                return err_arg(I, i, ERR_VALUE, "affine: coefficients and transforms cannot be mixed");
        return map_value(I, affine_from_2d(a[0].u.n, a[1].u.n, a[2].u.n, a[3].u.n, a[4].u.n, a[5].u.n), out);
    }
    /* scale, then shear, then rotate, then translate */
    double sx = 1, sy = 1;
    if (a[6].k == V_NUM) {
        sx = sy = a[6].u.n;
    } else if (a[6].k == V_LIST) {
        double s[2];
        if (builtin_get_vec(I, a[6], s, 2, "affine: scale"))
            return -1;
        sx = s[0];
        sy = s[1];
    }
    affine m = affine_from_2d(sx, 0, 0, sy, 0, 0);
    if (a[8].k == V_NUM) {
        affine sh = affine_from_2d(1, a[8].u.n, 0, 1, 0, 0);
        m = affine_compose(&sh, &m);
    }
    if (a[7].k == V_NUM) {
        double t = a[7].u.n * 3.14159265358979323846 / 180.0;
        affine r = affine_from_2d(cos(t), -sin(t), sin(t), cos(t), 0, 0);
        m = affine_compose(&r, &m);
    }
    if (a[9].k != V_NIL) {
        double t[2];
        if (builtin_get_vec(I, a[9], t, 2, "affine: translate"))
            return -1;
        m.t[0] += t[0];
        m.t[1] += t[1];
    }
    return map_value(I, m, out);
}

static int b_map3(interp *I, value *a, int n, value *out)
{
    (void)n;
    double m9[9], t[3] = {0, 0, 0};
    value rows = a[0];
    if (rows.k != V_LIST || AS_LIST(rows)->n != 3)
        return err_at(I, NULL, ERR_VALUE, "affine3: matrix must be 3 rows of 3 numbers");
    for (int i = 0; i < 3; i++)
        if (builtin_get_vec(I, AS_LIST(rows)->items[i], m9 + 3 * i, 3, "affine3: matrix row"))
            return -1;
    if (a[1].k != V_NIL && builtin_get_vec(I, a[1], t, 3, "affine3: translate"))
        return -1;
    return map_value(I, affine_from_3d(m9, t), out);
}

/* ---- builtins: ifs, rifs ----------------------------------------------------------------------- */

static int flags_of(value normalize, value allow)
{
    return (val_truthy(normalize) ? IFS_NORMALISE : 0) | (val_truthy(allow) ? IFS_ALLOW_EXPANDING : 0);
}

static int b_ifs(interp *I, value *a, int n, value *out)
{
    (void)n;
    affine *maps;
    double *p;
    int count;
    int has_p = lang_get_maps(I, a[0], &maps, &p, &count, "ifs");
    if (has_p < 0)
        return -1;
    if (a[1].k != V_NIL) {
        if (a[1].k != V_LIST || (int)AS_LIST(a[1])->n != count) {
            mem_free(I, maps);
            mem_free(I, p);
            return err_at(I, NULL, ERR_VALUE, "ifs: probabilities must be a list of %d numbers (one per map)", count);
        }
        if (builtin_get_vec(I, a[1], p, (size_t)count, "ifs: probabilities")) {
            mem_free(I, maps);
            mem_free(I, p);
            return -1;
        }
        has_p = 1;
    }
    lang_ifs *li = mem_calloc(I, 1, sizeof *li);
    if (!li) {
        mem_free(I, maps);
        mem_free(I, p);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    rt_error e;
    rt_code c = ifs_build(&li->f, maps, count, has_p ? p : NULL, flags_of(a[2], a[3]), &e);
    mem_free(I, maps);
    mem_free(I, p);
    if (c) {
        mem_free(I, li);
        return lang_rt_error(I, c, &e, "ifs");
    }
    if (li->f.warning[0] && !I->quiet)
        fprintf(stderr, "warning: ifs: %s\n", li->f.warning);
    *out = val_obj(I, &lang_ifs_class, li);
    return out->k == V_NIL ? -1 : 0;
}

static int b_rifs(interp *I, value *a, int n, value *out)
{
    (void)n;
    affine *maps;
    double *p;
    int count;
    if (lang_get_maps(I, a[0], &maps, &p, &count, "rifs") < 0)
        return -1;
    mem_free(I, p);
    long order;
    if (builtin_get_int(I, a[2], 1, 2, &order, "rifs: order")) {
        mem_free(I, maps);
        return -1;
    }
    int rows = order == 1 ? count : count * count;
    value M = a[1];
    if (M.k != V_LIST || (int)AS_LIST(M)->n != rows) {
        mem_free(I, maps);
        return err_at(I, NULL, ERR_VALUE, "rifs: the matrix must have %d rows of %d numbers (%s), got %zu rows", rows,
                      count, order == 1 ? "one per map" : "one per pair of maps", M.k == V_LIST ? AS_LIST(M)->n : 0);
    }
    double *P = mem_alloc(I, sizeof(double) * (size_t)rows * (size_t)count);
    if (!P) {
        mem_free(I, maps);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    for (int i = 0; i < rows; i++) {
        value row = AS_LIST(M)->items[i];
        char what[64];
        snprintf(what, sizeof what, "rifs: matrix row %d", i + 1);
        if (row.k != V_LIST || (int)AS_LIST(row)->n != count) {
            mem_free(I, maps);
            mem_free(I, P);
            return err_item(I, M, (size_t)i, ERR_VALUE, "%s must have %d numbers (one per map)", what, count);
        }
        if (builtin_get_vec(I, row, P + (size_t)i * count, (size_t)count, what)) {
            mem_free(I, maps);
            mem_free(I, P);
            return -1;
        }
    }
    lang_rifs *lr = mem_calloc(I, 1, sizeof *lr);
    if (!lr) {
        mem_free(I, maps);
        mem_free(I, P);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    rt_error e;
    rt_code c = rifs_build(&lr->r, maps, count, (int)order, P, flags_of(a[3], a[4]), &e);
    mem_free(I, maps);
    mem_free(I, P);
    if (c) {
        mem_free(I, lr);
        return lang_rt_error(I, c, &e, "rifs");
    }
    if (lr->r.warning[0] && !I->quiet)
        fprintf(stderr, "warning: rifs: %s\n", lr->r.warning);
    *out = val_obj(I, &lang_rifs_class, lr);
    return out->k == V_NIL ? -1 : 0;
}

/* ---- evaluations --------------------------------------------------------------------------------- */

static int points_arg(interp *I, value v, uint64_t *out, const char *what)
{
    if (v.k != V_NUM || !(v.u.n >= 1) || v.u.n != floor(v.u.n))
        return err_at(I, NULL, ERR_VALUE, "%s: points must be a whole number ≥ 1, got %g", what,
                      v.k == V_NUM ? v.u.n : NAN);
    if (v.u.n > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT, "%s: %.0f points exceed the limit of %.0f (raise it with --max-points)", what,
                      v.u.n, I->lim.max_points);
    *out = (uint64_t)v.u.n;
    return 0;
}

static int colour_mode(interp *I, value v, chaos_colour *c, const char *what)
{
    const char *s = v.k == V_STR ? AS_STR(v)->s : "";
    if (v.k == V_NIL || strcmp(s, "none") == 0 || strcmp(s, "density") == 0)
        *c = CHAOS_COLOUR_NONE;
    else if (strcmp(s, "map") == 0)
        *c = CHAOS_COLOUR_LAST;
    else /* declared str{none,density,map,blend} */
        *c = CHAOS_COLOUR_BLEND;
    (void)I, (void)what;
    return 0;
}

/* chaos(system, points, size, window, colour, palette, curve, gamma,
 *       brightness, background, supersample, seed) */
static int b_chaos(interp *I, value *a, int n, value *out)
{
    (void)n;
    chaos_sys s;
    chaos_opts o;
    memset(&o, 0, sizeof o);
    int w, h;
    long ss;
    ramp r;
    if (lang_get_sys(I, a[0], &s, "chaos: system") || points_arg(I, a[1], &o.points, "chaos") ||
        lang_arg_size2(I, a[2], &w, &h, "chaos: size") || colour_mode(I, a[4], &o.colour, "chaos") ||
        lang_get_ramp(I, a[5], &r, "chaos: palette") || builtin_get_int(I, a[10], 1, 8, &ss, "chaos: supersample") ||
        lang_arg_seed(I, a[11], &o.seed, NULL))
        return -1;
    if (sys_dim(&s) != 2)
        return err_at(I, NULL, ERR_VALUE,
                      "chaos: the system is 3-D; use view(…) for a picture, measure(…) for a volume or points(…) for a point cloud");
    o.ramp = &r;
    tonemap_opts t;
    memset(&t, 0, sizeof t);
    const char *curve = AS_STR(a[6])->s;
    t.curve = strcmp(curve, "log") == 0 ? TONEMAP_LOG : TONEMAP_LINEAR; /* declared str{log,linear} */
    t.gamma = a[7].u.n;
    t.brightness = a[8].u.n;
    t.colour = o.colour == CHAOS_COLOUR_NONE ? TONEMAP_RAMP : TONEMAP_MEAN;
    t.ramp = &r;
    if (lang_get_colour(I, a[9], t.bg, "chaos: background"))
        return -1;
    memcpy(o.bg, t.bg, sizeof o.bg);
    double lo[2], hi[2];
    rt_error e;
    rt_code c;
    if (a[3].k != V_NIL) {
        double win[4];
        if (builtin_get_vec(I, a[3], win, 4, "chaos: window"))
            return -1;
        lo[0] = win[0];
        hi[0] = win[1];
        lo[1] = win[2];
        hi[1] = win[3];
        if (!(hi[0] > lo[0]) || !(hi[1] > lo[1]))
            return err_at(I, NULL, ERR_VALUE, "chaos: window is [xmin, xmax, ymin, ymax] with min < max");
    } else if ((c = lang_chaos_fit_call(I, &s, &o, w, h, lo, hi, &e))) {
        return lang_rt_error(I, c, &e, "chaos");
    }
    if ((double)w * h * ss * ss > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT, "chaos: %d×%d pixels with supersample %ld exceed the pixel limit (raise it with --max-pixels)",
                      w, h, ss);
    double bytes = (double)w * h * ss * ss * (8 + (o.colour ? 12 : 0)) * (I->threads + 1);
    if (mem_precheck(I, bytes, "chaos: the histograms"))
        return -1;
    hist2 hs;
    c = hist2_init_for(&hs, w * (int)ss, h * (int)ss, lo, hi, o.colour != CHAOS_COLOUR_NONE, o.points, &e);
    if (c) {
        return lang_rt_error(I, c, &e, "chaos");
    }
    rt_run run = lang_run(I);
    chaos_stats st;
    double t0 = report_clock();
    c = chaos_hist2(&s, &o, &hs, &st, &run, &e);
    if (!c)
        report_work(I, "chaos game", "points", (double)o.points, t0);
    if (!c && shard_pending(I)) { /* a shard: the result becomes a partial value (shard.h) */
        hist2_free(&hs);
        *out = val_nil();
        return 0;
    }
    image *im = NULL; /* pixels pending until read: a PNG save tone-maps band by band */
    if (!c && !lang_image_new(I, w, h, &im))
        c = tonemap_defer(&hs, &t, im, &e);
    hist2_free(&hs);
    if (c || !im) {
        lang_image_discard(im);
        return I->err.active ? -1 : lang_rt_error(I, c, &e, "chaos");
    }
    return lang_image_value(I, im, out);
}

static int norm_arg(interp *I, value v, chaos_norm *nm, const char *what)
{
    const char *s = AS_STR(v)->s;
    if (strcmp(s, "total") == 0)
        *nm = CHAOS_NORM_TOTAL;
    else if (strcmp(s, "max") == 0)
        *nm = CHAOS_NORM_MAX;
    else /* declared str{total,max,count} */
        *nm = CHAOS_NORM_COUNT;
    (void)I, (void)what;
    return 0;
}

/* measure(system, grid, points, normalize, lo, hi, seed): the invariant
 * measure into a volume (3-D) or an image (2-D). */
static int b_measure(interp *I, value *a, int n, value *out)
{
    (void)n;
    chaos_sys s;
    chaos_opts o;
    memset(&o, 0, sizeof o);
    chaos_norm nm = CHAOS_NORM_TOTAL;
    if (lang_get_sys(I, a[0], &s, "measure: system") || points_arg(I, a[2], &o.points, "measure") ||
        norm_arg(I, a[3], &nm, "measure") || lang_arg_seed(I, a[6], &o.seed, NULL))
        return -1;
    int dim = sys_dim(&s);
    double g[3];
    if (a[1].k == V_NUM)
        g[0] = g[1] = g[2] = a[1].u.n;
    else if (builtin_get_vec(I, a[1], g, (size_t)dim, "measure: grid"))
        return -1;
    double lo[3], hi[3];
    rt_error e;
    rt_code c;
    if (a[4].k != V_NIL || a[5].k != V_NIL) {
        if (builtin_get_vec(I, a[4], lo, (size_t)dim, "measure: lo") || builtin_get_vec(I, a[5], hi, (size_t)dim, "measure: hi"))
            return -1;
        for (int i = 0; i < dim; i++)
            if (!(hi[i] > lo[i]))
                return err_at(I, NULL, ERR_VALUE, "measure: the box needs lo < hi on every axis");
    } else if ((c = lang_chaos_fit_call(I, &s, &o, (int)g[0], (int)g[1], lo, hi, &e))) {
        return lang_rt_error(I, c, &e, "measure");
    }
    rt_run run = lang_run(I);
    chaos_stats st;
    if (dim == 3) {
        volume *vol;
        if (lang_volume_new(I, (int)g[0], (int)g[1], (int)g[2], lo, hi, &vol))
            return -1;
        value res;
        if (lang_volume_value(I, vol, &res))
            return -1;
        double t0 = report_clock();
        c = chaos_volume(&s, &o, nm, vol, &st, &run, &e);
        if (!c)
            report_work(I, "chaos game", "points", (double)o.points, t0);
        if (c) {
            val_unref(I, res);
            return lang_rt_error(I, c, &e, "measure");
        }
        *out = res;
        return 0;
    }
    int w = (int)g[0], h = (int)g[1];
    image *im;
    if (lang_image_new(I, w, h, &im))
        return -1;
    hist2 hs;
    double bytes = (double)w * h * 8 * (I->threads + 1);
    if (mem_precheck(I, bytes, "measure: the histograms")) {
        lang_image_discard(im);
        return -1;
    }
    c = hist2_init_for(&hs, w, h, lo, hi, 0, o.points, &e);
    if (!c) {
        double t0 = report_clock();
        c = chaos_hist2(&s, &o, &hs, &st, &run, &e);
        if (!c)
            report_work(I, "chaos game", "points", (double)o.points, t0);
        if (!c)
            c = chaos_measure2(&hs, nm, st.plotted, im, &e);
        hist2_free(&hs);
    }
    return lang_image_finish(I, im, c, &e, "measure", out);
}

static int b_points(interp *I, value *a, int n, value *out)
{
    (void)n;
    chaos_sys s;
    chaos_opts o;
    memset(&o, 0, sizeof o);
    ramp r;
    if (lang_get_sys(I, a[0], &s, "points: system") || points_arg(I, a[1], &o.points, "points") ||
        colour_mode(I, a[2], &o.colour, "points") || lang_get_ramp(I, a[3], &r, "points: palette") ||
        lang_arg_seed(I, a[4], &o.seed, NULL))
        return -1;
    o.ramp = &r;
    if (mem_precheck(I, (double)o.points * 28, "points: the point cloud"))
        return -1;
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m) {
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    mesh_init(m, 0, o.colour != CHAOS_COLOUR_NONE);
    rt_run run = lang_run(I);
    rt_error e;
    double t0 = report_clock();
    rt_code c = chaos_points(&s, &o, m, &run, &e);
    if (!c)
        report_work(I, "chaos game", "points", (double)o.points, t0);
    return lang_mesh_finish(I, m, c, &e, "points", out);
}

static int b_view(interp *I, value *a, int n, value *out)
{
    (void)n;
    chaos_sys s;
    chaos_opts o;
    memset(&o, 0, sizeof o);
    camera cam;
    int w, h;
    ramp r;
    if (lang_get_sys(I, a[0], &s, "view: system") || (a[1].k != V_NIL && lang_get_camera(I, a[1], &cam, "view")) ||
        lang_arg_size2(I, a[2], &w, &h, "view: size") || points_arg(I, a[3], &o.points, "view") ||
        colour_mode(I, a[4], &o.colour, "view") || lang_get_ramp(I, a[5], &r, "view: palette") ||
        lang_get_colour(I, a[6], o.bg, "view: background") || lang_arg_seed(I, a[7], &o.seed, NULL))
        return -1;
    if (sys_dim(&s) != 3)
        return err_at(I, NULL, ERR_VALUE, "view: the system is 2-D; use chaos(…) to draw it");
    o.ramp = &r;
    rt_error e;
    rt_code c;
    if (a[1].k == V_NIL) { /* the default framing (camera.h) of the fitted box */
        double lo[3], hi[3];
        if ((c = lang_chaos_fit_call(I, &s, &o, w, h, lo, hi, &e)))
            return lang_rt_error(I, c, &e, "view");
        if (lang_frame_default(I, lo, hi, w, h, &cam, "view: cannot frame the attractor (its box is not finite)"))
            return -1;
    }
    image *im;
    if (lang_depth_image(I, w, h, 16, "view", &im))
        return -1;
    rt_run run = lang_run(I);
    chaos_stats st;
    double t0 = report_clock();
    c = chaos_project(&s, &o, &cam, im, &st, &run, &e);
    if (!c)
        report_work(I, "chaos game", "points", (double)o.points, t0);
    return lang_image_finish(I, im, c, &e, "view", out);
}

/* save(ifs, "x.flame"): flam3 XML for Fractorium, JWildfire, Apophysis. */
static int sys_save(interp *I, chaos_sys *s, const char *path, value opts)
{
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "flame") != 0 && strcmp(ext, "flam3") != 0 && strcmp(ext, "xml") != 0)
        return err_at(I, NULL, ERR_VALUE, "save: an IFS is saved as flam3 XML: use .flame, .flam3 or .xml, not .%s",
                      ext);
    if (sys_dim(s) != 2)
        return err_at(I, NULL, ERR_VALUE, "save: flam3 files hold 2-D systems only");
    flam3_opts fo;
    memset(&fo, 0, sizeof fo);
    fo.width = fo.height = 512;
    double v;
    if (contract_check_opts(I, opts, "rec{width: int[1,100000], height: int[1,100000]}", "save"))
        return -1;
    if (lang_opt_num(I, opts, "width", &v) == 1)
        fo.width = (int)v;
    if (lang_opt_num(I, opts, "height", &v) == 1)
        fo.height = (int)v;
    if (I->err.active)
        return -1;
    chaos_opts co;
    memset(&co, 0, sizeof co);
    co.seed = I->seed;
    rt_error e;
    rt_code c = lang_chaos_fit(I, s, &co, fo.width, fo.height, fo.lo, fo.hi, &e);
    if (!c)
        c = flam3_save(path, s, &fo, &e);
    if (c)
        return lang_rt_error(I, c, &e, "save");
    return 0;
}

static int sys_preview(interp *I, chaos_sys *s, image **out)
{
    chaos_opts o;
    memset(&o, 0, sizeof o);
    o.points = I->lim.max_points < 300000 ? (uint64_t)I->lim.max_points : 300000; /* --max-points (>= 1) */
    o.seed = I->seed;
    double t0 = report_clock();
    rt_run run = lang_run(I);
    rt_error e;
    rt_code c;
    image *im;
    if (lang_image_new(I, 256, 256, &im))
        return -1;
    if (sys_dim(s) == 3) {
        camera cam;
        double lo[3], hi[3];
        if ((c = lang_chaos_fit(I, s, &o, 256, 256, lo, hi, &e)))
            goto fail;
        camera_frame_box(&cam, lo, hi, 256, 256, 30, 20, 40);
        chaos_stats st;
        o.bg[3] = 1;
        if ((c = chaos_project(s, &o, &cam, im, &st, &run, &e)))
            goto fail;
    } else {
        hist2 hs;
        double lo[2], hi[2];
        if ((c = lang_chaos_fit(I, s, &o, 256, 256, lo, hi, &e)) || (c = hist2_init_for(&hs, 256, 256, lo, hi, 0, o.points, &e)))
            goto fail;
        chaos_stats st;
        c = chaos_hist2(s, &o, &hs, &st, &run, &e);
        tonemap_opts t;
        memset(&t, 0, sizeof t);
        t.bg[3] = 1;
        if (!c)
            c = tonemap_apply(&hs, &t, im, &e);
        hist2_free(&hs);
        if (c)
            goto fail;
    }
    report_work(I, "show", "points", (double)o.points, t0);
    *out = im;
    return 0;
fail:
    lang_image_discard(im);
    return lang_rt_error(I, c, &e, "show");
}

static int ifs_preview(interp *I, const void *p, image **out)
{
    chaos_sys s = {&((const lang_ifs *)p)->f, NULL};
    return sys_preview(I, &s, out);
}

static int rifs_preview(interp *I, const void *p, image **out)
{
    chaos_sys s = {NULL, &((const lang_rifs *)p)->r};
    return sys_preview(I, &s, out);
}

/* load_ifs(path): the entries of a Fractint .ifs file as a record name -> ifs */
static int b_load_ifs(interp *I, value *a, int n, value *out)
{
    (void)n;
    char path[4096];
    if (lang_script_path(I, a[0], path, sizeof path, "load_ifs"))
        return -1;
    fractint_list fl;
    rt_error e;
    rt_code c = fractint_load(path, &fl, &e);
    if (c == RT_EFORMAT) /* name the file: "load_ifs: x.ifs:4: expected …" */
        return err_at(I, NULL, ERR_VALUE, "load_ifs: %s:%s", path,
                      strncmp(e.msg, "line ", 5) == 0 ? e.msg + 5 : e.msg);
    if (c)
        return lang_rt_error(I, c, &e, "load_ifs");
    value r = val_rec(I);
    if (r.k == V_NIL) {
        fractint_free(&fl);
        return -1;
    }
    for (int i = 0; i < fl.n; i++) {
        const fractint_entry *en = &fl.e[i];
        lang_ifs *li = mem_calloc(I, 1, sizeof *li);
        if (!li) {
            fractint_free(&fl);
            val_unref(I, r);
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        }
        c = ifs_build(&li->f, en->maps, en->n, en->p, IFS_NORMALISE | IFS_ALLOW_EXPANDING, &e);
        if (c) {
            mem_free(I, li);
            if (c == RT_ENOMEM) /* the alias table: an allocation the hook refused */
                lang_rt_error(I, c, &e, "load_ifs");
            else
                err_at(I, NULL, ERR_VALUE, "load_ifs: %s:%d: entry '%s': %s", path, en->line, en->name, e.msg);
            fractint_free(&fl);
            val_unref(I, r);
            return -1;
        }
        value v = val_obj(I, &lang_ifs_class, li);
        const char *key = interp_intern(I, en->name, strlen(en->name));
        if (v.k == V_NIL || !key || val_rec_set(I, AS_REC(r), key, v)) {
            fractint_free(&fl);
            val_unref(I, r);
            return -1;
        }
    }
    fractint_free(&fl);
    *out = r;
    return 0;
}

static const bparam p_map[] = {{"a", "num", "nil"},      {"b", "num", "nil"},     {"c", "num", "nil"},
                               {"d", "num", "nil"},      {"e", "num", "nil"},     {"f", "num", "nil"},
                               {"scale", "num|vec2", "nil"}, {"rotate", "num", "nil"}, {"shear", "num", "nil"},
                               {"translate", "vec2", "nil"}};
static const bparam p_map3[] = {{"matrix", "list", NULL}, {"translate", "vec3", "nil"}};
static const bparam p_ifs[] = {{"maps", "list|ifs", NULL}, {"probabilities", "vec[0,1]", "nil"},
                               {"normalize", "bool", "false"}, {"allow_expanding", "bool", "false"}};
static const bparam p_rifs[] = {{"maps", "list|ifs", NULL}, {"matrix", "list", NULL}, {"order", "int{1,2}", "1"},
                                {"normalize", "bool", "false"}, {"allow_expanding", "bool", "false"}};
static const bparam p_chaos[] = {{"system", "ifs|rifs", NULL},   {"points", "int>=1", "1e6"},
                                 {"size", TY_SIZE, "[512, 512]"}, {"window", "vec4", "nil"},
                                 {"colour", "str{none,density,map,blend}", "nil"},          {"palette", "list", "nil"},
                                 {"curve", "str{log,linear}", "\"log\""},        {"gamma", "num>0", "2.2"},
                                 {"brightness", "num>0", "1"},      {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                 {"supersample", "int[1,8]", "1"},   {"seed", "int>=0", "nil"}};
static const bparam p_measure[] = {{"system", "ifs|rifs", NULL}, {"grid", "ivec[1,65536]|int[1,65536]", "64"},
                                   {"points", "int>=1", "1e6"},  {"normalize", "str{total,max,count}", "\"total\""},
                                   {"lo", "vec", "nil"},          {"hi", "vec", "nil"},
                                   {"seed", "int>=0", "nil"}};
static const bparam p_points[] = {{"system", "ifs|rifs", NULL}, {"points", "int>=1", "1e5"}, {"colour", "str{none,density,map,blend}", "nil"},
                                  {"palette", "list", "nil"},    {"seed", "int>=0", "nil"}};
static const bparam p_view[] = {{"system", "ifs|rifs", NULL}, {"camera", TY_CAMERA, "nil"},
                                {"size", TY_SIZE, "[512, 512]"}, {"points", "int>=1", "1e6"},
                                {"colour", "str{none,density,map,blend}", "nil"},          {"palette", "list", "nil"},
                                {"background", TY_COLOUR, "[0, 0, 0, 1]"}, {"seed", "int>=0", "nil"}};
static const bparam p_load_ifs[] = {{"path", "str", NULL}};

static const builtin ifs_builtins[] = {
    BUILTIN("affine", b_map, p_map,
            "A 2-D affine map: affine(a, b, c, d, e, f) with x' = a x + b y + e, y' = c x + d y + f (Fractint order), or affine(scale:, shear:, rotate:, translate:) applied in that order. m1 * m2 composes (m2 first); m * [x, y] applies."),
    BUILTIN("affine3", b_map3, p_map3, "A 3-D affine map x' = M x + t from a 3×3 matrix (rows) and a translation."),
    BUILTIN("ifs", b_ifs, p_ifs,
            "An IFS from a table of map rows (2-D: a b c d e f [p]; 3-D: a b c d e f g h i j k l [p], i.e. the 3×3 matrix by rows then the translation), a list of maps, or an ifs. Probabilities default to |det| weights; they must be ≥ 0 and sum to 1 unless normalize: true. Maps must contract unless allow_expanding: true."),
    BUILTIN("rifs", b_rifs, p_rifs,
            "A Recurrent IFS (seed 001): maps plus a matrix p_ij = probability of map j after map i (order 1), or after the pair of maps (i, k) for order 2 (n² rows). Rows must sum to 1 and the chain must be irreducible."),
    BUILTIN("chaos", b_chaos, p_chaos,
            "Render a 2-D IFS or RIFS by the chaos game: hit counts tone-mapped (log or linear density, gamma, brightness) through a palette, or coloured by map (colour: \"map\" or \"blend\"); window [xmin, xmax, ymin, ymax] or fitted; supersample k×k."),
    BUILTIN("measure", b_measure, p_measure,
            "The invariant measure (seed 001 §5): the fraction of chaos-game points per cell, into a volume (3-D systems; the fractal solid noise) or an image (2-D); normalize \"total\" (measures sum to 1), \"max\" (densest cell 1) or \"count\"."),
    BUILTIN("points", b_points, p_points, "Chaos-game points as a point cloud (a mesh without triangles; save as .ply)."),
    BUILTIN("view", b_view, p_view, "A 3-D IFS or RIFS seen through a camera (default: framing the whole attractor, as framing(…) does for its fitted box): nearest point per pixel, shaded by depth."),
    BUILTIN("load_ifs", b_load_ifs, p_load_ifs,
            "The entries of a Fractint .ifs file (2-D and (3D) entries, ; comments) as a record name -> ifs."),
};

int bind_ifs_init(interp *I)
{
    return BUILTIN_REGISTER(I, ifs_builtins);
}
