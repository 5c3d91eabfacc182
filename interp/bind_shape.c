/* bind_shape.c — shapes in the language: polylines, polygons and point sets
 * (the K_0 and K_n of deterministic iteration, seed 003 §2-2, §3-2),
 * iterate, draw and SVG output (engines detiter.h, draw.h).
 *
 * Class "shape"; arithmetic moves, scales, maps and unites shapes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "detiter.h"
#include "draw.h"
#include "fileio.h"
#include "fset.h"
#include "lang_fset.h"
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lexer.h"
#include "report.h"

/* ---- shapes ---------------------------------------------------------------------------- */

static void shape_destroy(void *pp)
{
    detiter_shape *s = pp;
    detiter_shape_free(s);
    rt_free(s);
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

/* shape.coords[i]: vertex i as [x, y] (or [x, y, z]) */
static int vertex_value(interp *I, const void *pp, size_t i, value *out)
{
    const detiter_shape *s = pp;
    return lang_num_list_value(I, s->v + i * (size_t)s->dim, (size_t)s->dim, out);
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
        detiter_bounds(s, lo, hi);
        b[0] = lo[0];
        b[1] = hi[0];
        b[2] = lo[1];
        b[3] = hi[1];
        return lang_num_list_value(I, b, (size_t)(4), out);
    } else if (strcmp(name, "coords") == 0) {
        if ((double)s->nverts > I->lim.max_list)
            return err_at(I, NULL, ERR_LIMIT, "shape.coords: %zu vertices exceed the list limit of %.0f (raise it with --max-list)",
                          s->nverts, I->lim.max_list);
        return val_list_build(I, s->nverts, vertex_value, s, out);
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

/* shape + [dx, dy], shape - [dx, dy], shape * k, map * shape, shape + shape (union) */
static int shape_arith(interp *I, int op, value a, value b, value *out)
{
    const detiter_shape *x = as_shape(a), *y = as_shape(b);
    detiter_shape s;
    rt_error e;
    rt_code c;
    const char *what;
    if (x && y && op == T_PLUS) {
        if (x->dim != y->dim)
            return err_at(I, NULL, ERR_VALUE, "shape + shape: a %d-D and a %d-D shape cannot be joined", x->dim, y->dim);
        what = "shape + shape";
        c = detiter_shape_join(x, y, &s, &e);
    } else {
        const detiter_shape *src = x ? x : y;
        value other = x ? b : a;
        if (other.k == V_OBJ && AS_OBJ(other)->cls == &lang_map_class && y && op == T_STAR) {
            const affine *m = AS_OBJ(other)->payload;
            if (m->dim > src->dim)
                return err_at(I, NULL, ERR_VALUE, "map * shape: a %d-D map cannot apply to a %d-D shape", m->dim,
                              src->dim);
            what = "map * shape";
            c = detiter_shape_map(src, m, &s, &e);
        } else if (other.k == V_LIST && (op == T_PLUS || (op == T_MINUS && x))) {
            size_t nn = AS_LIST(other)->n;
            double t[3] = {0, 0, 0};
            if ((int)nn != src->dim)
                return err_at(I, NULL, ERR_VALUE, "shape %s: a %d-D shape moves by a list of %d numbers, got %zu",
                              op == T_PLUS ? "+" : "-", src->dim, src->dim, nn);
            if (builtin_get_vec(I, other, t, nn, "shape offset"))
                return -1;
            if (op == T_MINUS)
                for (int i = 0; i < 3; i++)
                    t[i] = -t[i];
            what = op == T_PLUS ? "shape +" : "shape -";
            c = detiter_shape_shift(src, t, &s, &e);
        } else if (other.k == V_NUM && (op == T_STAR || (op == T_SLASH && x))) {
            what = op == T_STAR ? "shape *" : "shape /";
            c = detiter_shape_scale(src, op == T_STAR ? other.u.n : 1 / other.u.n, &s, &e);
        } else {
            return 0;
        }
    }
    if (c)
        return lang_rt_error(I, c, &e, what);
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
        if (builtin_get_vec(I, pts[i], v + (size_t)i * (size_t)dim, (size_t)dim, w)) {
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

/* ---- polyhedra: 3-D initial sets K0 (seed 003 §3-4) ------------------------------------ */

/* A mesh from nv vertices (3 doubles each) and nf polygon faces, face f
 * being idx[off[f] .. off[f+1]-1] (0-based vertex numbers, already checked),
 * fan-triangulated, then oriented outward (mesh_orient_outward). */
static int poly_mesh(interp *I, const double *v, size_t nv, const size_t *off, const uint32_t *idx, size_t nf,
                     const char *what, value *out)
{
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m)
        return -1;
    mesh_init(m, 0, 0);
    for (size_t i = 0; i < nv; i++) {
        float p[3] = {(float)v[3 * i], (float)v[3 * i + 1], (float)v[3 * i + 2]};
        mesh_add_vertex(m, p, NULL, NULL);
    }
    for (size_t f = 0; f < nf; f++)
        for (size_t k = off[f] + 1; k + 1 < off[f + 1]; k++)
            mesh_add_tri(m, idx[off[f]], idx[k], idx[k + 1]);
    int closed;
    rt_error e;
    rt_code c = m->failed ? RT_ENOMEM : mesh_orient_outward(m, &closed, &e);
    if (c) {
        mesh_free(m);
        mem_free(I, m);
        return c == RT_ENOMEM ? err_at(I, NULL, ERR_MEMORY, "out of memory") : err_arg(I, 1, ERR_VALUE, "%s: %s", what, e.msg);
    }
    return lang_mesh_value(I, m, out);
}

/* pyramid(): seed 003 Fig. 5's K0, the four-sided pyramid on the five points
 * the paper lists. Its scan prints them as (0,0,0) (1,0,0) (1/2, ρ, 3/6)
 * (1/2, ρ, -3/6) (1/2, 3/6, ρ); our reading (ρ a garbled 0, 3/6 a √3/6 that
 * lost its root, as in the Koch triangle (1/2, √3/6) of the same paper) is a
 * rhombus base in the plane y = 0 and the apex (1/2, √3/6, 0). It contains
 * the gasket's four fixed points (Table 4b: twice its translations). */
static int b_pyramid(interp *I, value *a, int n, value *out)
{
    (void)a;
    (void)n;
    const double r = sqrt(3.0) / 6;
    const double v[15] = {0, 0, 0, 1, 0, 0, 0.5, 0, r, 0.5, 0, -r, 0.5, r, 0};
    /* base 0 3 1 2 (seen from below), sides to the apex 4 */
    static const uint32_t idx[16] = {0, 3, 1, 2, 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4};
    static const size_t off[6] = {0, 4, 7, 10, 13, 16};
    return poly_mesh(I, v, 5, off, idx, 5, "pyramid", out);
}

/* cube(lo, hi): the box [lo, hi], 8 corners, 6 faces as 12 triangles */
static int b_cube(interp *I, value *a, int n, value *out)
{
    (void)n;
    double lo[3], hi[3];
    if (builtin_get_vec(I, a[0], lo, 3, "cube: lo") || builtin_get_vec(I, a[1], hi, 3, "cube: hi"))
        return -1;
    for (int d = 0; d < 3; d++)
        if (!(lo[d] < hi[d]))
            return err_arg(I, 1, ERR_VALUE, "cube: hi must be above lo on every axis, but on axis %c %g <= %g",
                           "xyz"[d], hi[d], lo[d]);
    double v[24];
    for (int i = 0; i < 8; i++) /* corner i: bit 0 x, bit 1 y, bit 2 z */
        for (int d = 0; d < 3; d++)
            v[3 * i + d] = (i >> d) & 1 ? hi[d] : lo[d];
    static const uint32_t idx[24] = {0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5};
    static const size_t off[7] = {0, 4, 8, 12, 16, 20, 24};
    return poly_mesh(I, v, 8, off, idx, 6, "cube", out);
}

/* polyhedron(vertices, faces): faces are lists of 0-based vertex numbers */
static int b_polyhedron(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "polyhedron";
    vlist *vl = AS_LIST(a[0]), *fl = AS_LIST(a[1]);
    if (vl->n < 4)
        return err_arg(I, 0, ERR_VALUE, "%s: needs at least 4 vertices [x, y, z], got %zu", W, vl->n);
    if (fl->n < 1)
        return err_arg(I, 1, ERR_VALUE, "%s: needs at least 1 face", W);
    if ((double)vl->n > I->lim.max_points)
        return err_arg(I, 0, ERR_LIMIT, "%s: %zu vertices exceed the limit of %.0f (raise it with --max-points)", W,
                       vl->n, I->lim.max_points);
    size_t total = 0;
    for (size_t f = 0; f < fl->n; f++) {
        value fv = fl->items[f];
        if (fv.k != V_LIST || AS_LIST(fv)->n < 3)
            return err_item(I, a[1], f, ERR_VALUE, "%s: face %zu must be a list of at least 3 vertex numbers", W, f);
        total += AS_LIST(fv)->n;
    }
    if ((double)total > I->lim.max_points)
        return err_arg(I, 1, ERR_LIMIT, "%s: %zu face corners exceed the limit of %.0f (raise it with --max-points)",
                       W, total, I->lim.max_points);
    double *v = mem_alloc(I, sizeof(double) * 3 * vl->n);
    size_t *off = mem_alloc(I, sizeof(size_t) * (fl->n + 1));
    uint32_t *idx = mem_alloc(I, sizeof(uint32_t) * total);
    int rc = -1;
    if (!v || !off || !idx)
        goto done;
    for (size_t i = 0; i < vl->n; i++) {
        value p = vl->items[i];
        if (p.k != V_LIST || AS_LIST(p)->n != 3) {
            err_item(I, a[0], i, ERR_VALUE, "%s: vertex %zu must be [x, y, z]", W, i);
            goto done;
        }
        char w[64];
        snprintf(w, sizeof w, "%s: vertex %zu", W, i);
        if (builtin_get_vec(I, p, v + 3 * i, 3, w))
            goto done;
    }
    off[0] = 0;
    for (size_t f = 0; f < fl->n; f++) {
        vlist *face = AS_LIST(fl->items[f]);
        off[f + 1] = off[f] + face->n;
        for (size_t k = 0; k < face->n; k++) {
            value x = face->items[k];
            if (x.k != V_NUM || !(x.u.n >= 0 && x.u.n < (double)vl->n) || x.u.n != floor(x.u.n)) {
                err_item(I, a[1], f, ERR_VALUE, "%s: face %zu: corner %zu must be a vertex number 0 .. %zu, got %s", W,
                         f, k, vl->n - 1, x.k == V_NUM ? "another number" : val_type_name(x));
                goto done;
            }
            idx[off[f] + k] = (uint32_t)x.u.n;
            for (size_t j = 0; j < k; j++)
                if (idx[off[f] + j] == idx[off[f] + k]) {
                    err_item(I, a[1], f, ERR_VALUE, "%s: face %zu uses vertex %u twice", W, f, idx[off[f] + k]);
                    goto done;
                }
        }
    }
    rc = poly_mesh(I, v, vl->n, off, idx, fl->n, W, out);
done:
    if (rc && !I->err.active)
        err_at(I, NULL, ERR_MEMORY, "out of memory");
    mem_free(I, v);
    mem_free(I, off);
    mem_free(I, idx);
    return rc;
}

/* iterate of a mesh K0: the mesh K_n (fset_iterate_mesh) */
static int iterate_mesh(interp *I, const lang_fset *f, const fset_order *o, long steps, const mesh *k0, value *out)
{
    size_t copies;
    rt_error e;
    rt_code c = detiter_count(&f->fs, o, (size_t)steps, 1, &copies, &e);
    if (c)
        return lang_rt_error(I, c, &e, "iterate");
    double nv = (double)copies * (double)k0->nv, nt = (double)copies * (double)k0->nt;
    if (nv > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT,
                      "iterate: K_%ld would have %.0f vertices, more than the limit of %.0f points (raise it with --max-points, or lower steps)",
                      steps, nv, I->lim.max_points);
    if (mem_precheck(I, nv * (12 + (k0->col ? 16 : 0)) + nt * 12 + (double)copies * 2 * sizeof(affine),
                     "iterate: the mesh"))
        return -1;
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m)
        return -1;
    rt_run run = lang_run(I);
    double t0 = report_clock();
    c = fset_iterate_mesh(&f->fs, o, (size_t)steps, copies, k0, m, &run, &e);
    if (!c)
        report_work(I, "iterate", "triangles", (double)m->nt, t0);
    return lang_mesh_finish(I, m, c, &e, "iterate", out);
}

/* iterate(system, start, steps, order) */
static int b_iterate(interp *I, value *a, int n, value *out)
{
    (void)n;
    value fv;
    if (lang_get_fset(I, a[0], 0, &fv, "iterate: system"))
        return -1;
    const lang_fset *f = lang_as_fset(fv);
    fset_order o;
    int *tmp = NULL;
    if (lang_order_arg(I, a[3], 3, f->n, &o, &tmp, "iterate")) {
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
    } else if (lang_as_mesh(a[1])) {
        if (o.kind == FSET_SEQUENCE && steps > o.len) {
            err_arg(I, 2, ERR_VALUE, "iterate: the order has %d step%s but steps is %ld (use order(…, repeat: true) to cycle)",
                    o.len, o.len == 1 ? "" : "s", steps);
            goto done;
        }
        rc = iterate_mesh(I, f, &o, steps, lang_as_mesh(a[1]), out);
        goto done;
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
    double t0 = report_clock();
    c = detiter_run(&f->fs, &o, (size_t)steps, k0, (size_t)need, &res, &run, &e);
    if (c) {
        lang_rt_error(I, c, &e, "iterate");
        goto done;
    }
    report_work(I, "iterate", "vertices", (double)need, t0);
    rc = shape_value(I, &res, out);
done:
    if (own_k0)
        detiter_shape_free(&k0def);
    mem_free(I, tmp);
    val_unref(I, fv);
    return rc;
}

/* ---- drawing --------------------------------------------------------------------------- */

/* Fitted view of a shape: its bounds plus a 5 % margin, same scale on both axes. */
static int shape_view(interp *I, const detiter_shape *s, value window, int w, int h, draw_view *v, const char *what)
{
    double lo[2], hi[2];
    char wn[64];
    snprintf(wn, sizeof wn, "%s: window", what);
    if (window.k != V_NIL) {
        if (lang_window_arg(I, window, lo, hi, wn))
            return -1;
    } else {
        detiter_bounds(s, lo, hi);
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
    } else if (lang_arg_size2(I, a[1], &w, &h, "draw: size"))
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
    const char *k = interp_intern(I, key, strlen(key));
    value *v = k ? val_rec_get(AS_REC(opts), k) : NULL;
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
    if (contract_check_opts(I, opts,
                   "rec{size: int[1,1000000], width: num[0,1000], radius: num[0,1000], precision: int[0,9], "
                   "colour: nil|bool|" TY_COLOUR ", fill: nil|bool|" TY_COLOUR ", background: nil|bool|" TY_COLOUR "}",
                   "save") ||
        lang_opt_num(I, opts, "size", &size) < 0 || lang_opt_num(I, opts, "width", &width) < 0 ||
        lang_opt_num(I, opts, "radius", &radius) < 0 || lang_opt_num(I, opts, "precision", &prec) < 0)
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

/* ---- registration ---------------------------------------------------------------------- */

static const bparam p_shape[] = {{"points", "list", "nil"}};
static const bparam p_iterate[] = {{"system", "ifs|fset|list", NULL},
                                   {"start", "shape|mesh", "nil"},
                                   {"steps", "int[0,1000000]", "nil"},
                                   {"order", "order", "nil"}};
static const bparam p_pyramid[] = {{"_unused", "nil", "nil"}};
static const bparam p_cube[] = {{"lo", "vec3", "[0, 0, 0]"}, {"hi", "vec3", "[1, 1, 1]"}};
static const bparam p_polyhedron[] = {{"vertices", "list", NULL}, {"faces", "list", NULL}};
#define TY_FILL "bool|" TY_COLOUR
static const bparam p_draw[] = {{"shape", "shape", NULL},            {"size", TY_SIZE, "[512, 512]"},
                                {"window", "vec4", "nil"},           {"colour", TY_COLOUR, "1"},
                                {"width", "num[0,1000]", "1"},       {"radius", "num[0,1000]", "1"},
                                {"fill", TY_FILL, "nil"},            {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                {"onto", "image", "nil"}};

static const builtin shape_builtins[] = {
    BUILTIN_VAR("polygon", b_polygon, p_shape,
                "A closed polygon (an initial set K0): polygon([x, y], [x, y], [x, y], …) or polygon(list of points); 2-D or 3-D points."),
    BUILTIN_VAR("polyline", b_polyline, p_shape, "An open polyline (an initial set K0) through the given points."),
    BUILTIN_VAR("pointset", b_pointset, p_shape, "A set of separate points (an initial set K0)."),
    BUILTIN("pyramid", b_pyramid, p_pyramid,
            "Seed 003 Fig. 5's initial set K0: the four-sided pyramid on (0,0,0), (1,0,0), (1/2,0,√3/6), (1/2,0,-√3/6) and the apex (1/2,√3/6,0), a closed mesh of 6 triangles wound outward."),
    BUILTIN("cube", b_cube, p_cube, "The box [lo, hi] as a closed mesh (8 vertices, 12 triangles, wound outward): a 3-D initial set K0."),
    BUILTIN("polyhedron", b_polyhedron, p_polyhedron,
            "A polyhedron (a 3-D initial set K0) from vertices [[x, y, z], …] and faces [[i, j, k, …], …] (0-based vertex numbers, at least 3 per face, fan-triangulated); faces must wind one way, and a closed one wound inside out is reversed so it winds outward."),
    BUILTIN("iterate", b_iterate, p_iterate,
            "Deterministic iteration K_n = W_σ(n) ∘ … ∘ W_σ(1)(K0) (seed 003 §2-2, §3-2): each step replaces the shape by the union of its images under every map of the set the order names. system: an ifs, a table or an fset; start: a shape (default: the triangle (0,0), (1,0), (1/2, √3/6)) or a mesh (a 3-D K0 such as pyramid(): the result is the mesh K_n, each copy wound outward); steps: default the length of a sequence order; order: default W1, W2, …, WN repeated. The vertex count is checked against --max-points first."),
    BUILTIN("draw", b_draw, p_draw,
            "An antialiased image of a shape: strokes of width pixels in colour, points as discs of radius, closed polygons filled if fill is true or a colour; window [xmin, xmax, ymin, ymax] or fitted to the shape; onto: draw over a copy of an image instead of a background."),
};

int bind_shape_init(interp *I)
{
    return BUILTIN_REGISTER(I, shape_builtins);
}
