/* bind_wrinkly.c — seed 002 in the language: wrinkly curves (drawn into
 * images or SVG) and wrinkly surfaces (tessellated into meshes). The IST
 * binding is bind_ist.c, the rasteriser's bind_raster.c; what they share is
 * in lang_wrinkly.h. The reference for scripts is docs/wrinkly.md; the
 * engines are runtime/ist.h and runtime/wrinkly.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "detiter.h"
#include "draw.h"
#include "fileio.h"
#include "ist.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lang_wrinkly.h"
#include "wrinkly.h"
#include "report.h"

/* ---- small helpers ------------------------------------------------------------------ */

/* shuffle: nil (everything), "height", or a list of "height" / "colour" /
 * "opacity" (one string is a declared choice; the items of a list are
 * checked here, with the caret on the item). */
static int get_shuffle(interp *I, value v, unsigned *bits, const char *what)
{
    if (v.k == V_NIL) {
        *bits = WRINKLY_HEIGHT | WRINKLY_COLOUR | WRINKLY_OPACITY;
        return 0;
    }
    size_t n = v.k == V_LIST ? AS_LIST(v)->n : 1;
    *bits = 0;
    for (size_t i = 0; i < n; i++) {
        value s = v.k == V_LIST ? AS_LIST(v)->items[i] : v;
        const char *t = s.k == V_STR ? AS_STR(s)->s : NULL;
        if (t && strcmp(t, "height") == 0)
            *bits |= WRINKLY_HEIGHT;
        else if (t && (strcmp(t, "colour") == 0 || strcmp(t, "color") == 0))
            *bits |= WRINKLY_COLOUR;
        else if (t && strcmp(t, "opacity") == 0)
            *bits |= WRINKLY_OPACITY;
        else
            return err_item(I, v, i, ERR_VALUE,
                            "%s: argument 'shuffle' item %zu must be \"height\", \"colour\" or \"opacity\", got %s%s%s",
                            what, i + 1, t ? "\"" : "", t ? t : val_type_name(s), t ? "\"" : "");
    }
    return 0;
}

/* Style shared by curves and surfaces: how the attributes are interpolated
 * and sampled (not the level of detail, which the drawing call decides).
 * Ranges are declared (TY_STYLE_*). */
static int get_style(interp *I, value tension, value shuffle, value crack, value jitter, value extra, value seed,
                     wrinkly_opts *o, const char *what)
{
    wrinkly_opts_default(o);
    o->tension = tension.u.n;
    if (get_shuffle(I, shuffle, &o->shuffle, what))
        return -1;
    o->crack_band = crack.u.n;
    o->jitter = jitter.u.b;
    o->extra = (int)extra.u.n;
    return lang_arg_seed(I, seed, &o->seed, what);
}

static void style_summary(const wrinkly_opts *o, bytebuf *out)
{
    if (o->crack_band > 0)
        bytebuf_printf(out, ", crack band %g", o->crack_band);
    if (o->jitter)
        bytebuf_printf(out, ", jitter");
    if (o->extra)
        bytebuf_printf(out, ", +%d rounds", o->extra);
    if (o->normal != WRINKLY_NORMAL_AUTO)
        bytebuf_printf(out, ", normal %s",
                       o->normal == WRINKLY_NORMAL_OUTWARD ? "outward" : o->normal == WRINKLY_NORMAL_INWARD ? "inward" : "uv");
}

/* ---- control points ------------------------------------------------------------------ */

/* One scalar attribute (which: 0 height, 4 opacity) for n points laid out
 * as rows × cols (rows = 0: a flat list of cols). A number sets all. */
static int fill_scalar(interp *I, value v, int rows, int cols, wrinkly_point *p, int which, const char *what,
                       const char *name)
{
    size_t n = (size_t)(rows ? rows : 1) * (size_t)cols;
    for (size_t i = 0; i < n; i++) {
        double x;
        if (v.k == V_NUM) {
            x = v.u.n;
        } else if (v.k != V_LIST) {
            return err_value(I, v, ERR_TYPE, "%s: %s must be a number or a %s, got %s", what, name,
                          rows ? "grid (list of rows) of numbers" : "list of numbers, one per point", val_type_name(v));
        } else {
            vlist *l = AS_LIST(v);
            value it;
            if (rows) {
                size_t r = i / (size_t)cols, c = i % (size_t)cols;
                if (l->n != (size_t)rows || l->items[r].k != V_LIST || AS_LIST(l->items[r])->n != (size_t)cols)
                    return err_item(I, v, l->n != (size_t)rows ? SIZE_MAX : r, ERR_VALUE,
                                    "%s: %s must be a number or a grid of %d rows of %d numbers (like the control points)",
                                    what, name, rows, cols);
                it = AS_LIST(l->items[r])->items[c];
            } else {
                if (l->n != (size_t)cols)
                    return err_item(I, v, SIZE_MAX, ERR_VALUE,
                                    "%s: %s must be a number or a list of %d numbers (one per point), got %zu", what, name,
                                    cols, l->n);
                it = l->items[i];
            }
            if (it.k != V_NUM)
                return err_value(I, v, ERR_TYPE, "%s: %s must contain numbers, found %s", what, name, val_type_name(it));
            x = it.u.n; /* declared: finite */
        }
        if (which == 0)
            p[i].h = x;
        else
            p[i].opacity = x;
    }
    return 0;
}

static int is_one_colour(value v)
{
    if (v.k == V_NUM || v.k == V_STR)
        return 1;
    if (v.k == V_LIST && (AS_LIST(v)->n == 3 || AS_LIST(v)->n == 4)) {
        for (size_t i = 0; i < AS_LIST(v)->n; i++)
            if (AS_LIST(v)->items[i].k != V_NUM)
                return 0;
        return 1;
    }
    return 0;
}

static int fill_colours(interp *I, value v, int rows, int cols, wrinkly_point *p, const char *what)
{
    size_t n = (size_t)(rows ? rows : 1) * (size_t)cols;
    char w[96];
    snprintf(w, sizeof w, "%s: colours", what);
    float c[4] = {1, 1, 1, 1};
    if (v.k == V_NIL || is_one_colour(v)) {
        if (v.k != V_NIL && lang_get_colour(I, v, c, w))
            return -1;
        for (size_t i = 0; i < n; i++)
            for (int q = 0; q < 3; q++)
                p[i].rgb[q] = c[q];
        return 0;
    }
    if (v.k != V_LIST)
        return err_value(I, v, ERR_TYPE, "%s must be a colour or a %s of colours, got %s", w,
                      rows ? "grid" : "list", val_type_name(v));
    vlist *l = AS_LIST(v);
    for (size_t i = 0; i < n; i++) {
        value it;
        if (rows) {
            size_t r = i / (size_t)cols, cc = i % (size_t)cols;
            if (l->n != (size_t)rows || l->items[r].k != V_LIST || AS_LIST(l->items[r])->n != (size_t)cols)
                return err_item(I, v, l->n != (size_t)rows ? SIZE_MAX : r, ERR_VALUE,
                                "%s must be one colour or a grid of %d rows of %d colours", w, rows, cols);
            it = AS_LIST(l->items[r])->items[cc];
        } else {
            if (l->n != (size_t)cols)
                return err_item(I, v, SIZE_MAX, ERR_VALUE,
                                "%s must be one colour or a list of %d colours (one per point), got %zu", w, cols, l->n);
            it = l->items[i];
        }
        if (lang_get_colour(I, it, c, w))
            return -1;
        for (int q = 0; q < 3; q++)
            p[i].rgb[q] = c[q];
    }
    return 0;
}

/* ---- curves -------------------------------------------------------------------------- */

typedef struct curve_obj {
    wrinkly_point *pts;
    int n;
    wrinkly_axis ax;
    wrinkly_opts style;
} curve_obj;

static void curve_destroy(void *p)
{
    curve_obj *c = p;
    rt_free(c->pts);
    rt_free(c);
}

static void curve_summary(const void *p, bytebuf *out)
{
    const curve_obj *c = p;
    bytebuf_printf(out, "wrinkly curve: %d control points, %s, M = %d, %s", c->n, c->ax.cyclic ? "closed" : "open",
                   c->ax.m, c->ax.ist ? "IST" : "spline");
    style_summary(&c->style, out);
}

static int curve_get(interp *I, const void *p, const char *name, value *out)
{
    const curve_obj *c = p;
    (void)I;
    if (strcmp(name, "points") == 0)
        *out = val_num(c->n);
    else if (strcmp(name, "closed") == 0)
        *out = val_bool(c->ax.cyclic);
    else if (strcmp(name, "crossings") == 0)
        *out = val_num(c->ax.m);
    else
        return 1;
    return 0;
}

static int curve_save(interp *I, const void *p, const char *path, value opts);

static const obj_class curve_class = {
    .name = "wrinkly_curve",
    .destroy = curve_destroy,
    .summary = curve_summary,
    .get = curve_get,
    .save = curve_save,
};

static int b_wrinkly_curve(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "wrinkly_curve";
    vlist *pl = AS_LIST(a[0]);
    if (pl->n < 1 || pl->n > MAX_CONTROL)
        return err_arg(I, 0, ERR_VALUE, "wrinkly_curve: points must be a list of 1 to %d points [x, y], got %zu",
                       MAX_CONTROL, pl->n);
    curve_obj *c = mem_calloc(I, 1, sizeof *c);
    if (c)
        c->pts = mem_calloc(I, pl->n, sizeof *c->pts);
    if (!c || !c->pts) {
        if (c)
            mem_free(I, c);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    c->n = (int)pl->n;
    for (size_t i = 0; i < pl->n; i++) {
        char w[64];
        snprintf(w, sizeof w, "wrinkly_curve: point %zu", i);
        value pt = pl->items[i];
        if (pt.k != V_LIST || AS_LIST(pt)->n != 2) {
            char got[48];
            if (pt.k == V_LIST)
                snprintf(got, sizeof got, "%zu item%s", AS_LIST(pt)->n, AS_LIST(pt)->n == 1 ? "" : "s");
            else
                snprintf(got, sizeof got, "%s", val_type_name(pt));
            err_item(I, a[0], i, ERR_VALUE, "%s must be a list of 2 numbers, got %s", w, got);
            goto fail;
        }
        if (builtin_get_vec(I, pt, c->pts[i].pos, 2, w)) /* numbers: finite (declared list) */
            goto fail;
    }
    if (fill_scalar(I, a[1], 0, c->n, c->pts, 0, W, "heights") || fill_colours(I, a[2], 0, c->n, c->pts, W) ||
        fill_scalar(I, a[3], 0, c->n, c->pts, 4, W, "opacity"))
        goto fail;
    c->ax.m = (int)a[4].u.n;
    c->ax.cyclic = a[5].u.b;
    c->ax.ist = a[6].u.b;
    if (get_style(I, a[8], a[7], a[9], a[10], a[11], a[12], &c->style, W))
        goto fail;
    *out = val_obj(I, &curve_class, c);
    return out->k == V_NIL ? -1 : 0;
fail:
    curve_destroy(c);
    return -1;
}

/* iterations, tolerance and kmax as declared (int[0,20], num>0, int[0,20]);
 * tol_slot: the argument to blame when both iterations and tolerance are
 * given (-1: the call). */
int lang_get_lod(interp *I, value iterations, value tolerance, value kmax, int tol_slot, lod *l, const char *what)
{
    l->k = 3;
    l->tol = 0;
    l->fixed = iterations.k != V_NIL;
    l->kmax = (int)kmax.u.n;
    if (iterations.k != V_NIL) {
        l->k = (int)iterations.u.n;
        if (l->k > l->kmax)
            l->kmax = l->k;
    }
    if (tolerance.k != V_NIL) {
        if (iterations.k != V_NIL)
            return err_arg(I, tol_slot, ERR_VALUE, "%s: give either iterations or tolerance, not both", what);
        l->tol = tolerance.u.n;
    }
    return 0;
}

/* Sample a curve after checking the sample count against --max-points. */
static int curve_sample(interp *I, const curve_obj *c, const lod *l, wrinkly_polyline *pl, const char *what)
{
    wrinkly_curve wc = {c->pts, c->n, c->ax};
    wrinkly_opts o = c->style;
    o.k = l->k;
    o.kmax = l->kmax;
    o.tol = l->tol;
    int *ki = mem_alloc(I, sizeof(int) * (size_t)c->n);
    if (!ki)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    rt_error e;
    rt_code rc = wrinkly_curve_levels(&wc, &o, ki, &e);
    if (rc) {
        mem_free(I, ki);
        return lang_rt_error(I, rc, &e, what);
    }
    double count = c->ax.cyclic ? 0 : 2;
    for (int i = 0; i < c->n; i++)
        count += pow(2.0 * c->ax.m + 1, ki[i]);
    mem_free(I, ki);
    if (count > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT,
                      "%s: the curve would have %.0f samples, more than the limit of %.0f points (raise it with --max-points, or lower iterations/kmax)",
                      what, count, I->lim.max_points);
    if (mem_precheck(I, count * 40, "the curve samples"))
        return -1;
    double t0 = report_clock();
    rc = wrinkly_curve_sample(&wc, &o, pl, &e);
    if (rc)
        return lang_rt_error(I, rc, &e, what);
    report_work(I, "wrinkly curve", "points", (double)pl->n, t0);
    return 0;
}

static int b_wrinkly_points(interp *I, value *a, int n, value *out)
{
    (void)n;
    const curve_obj *c = AS_OBJ(a[0])->payload;
    lod l;
    if (lang_get_lod(I, a[1], a[2], a[3], 2, &l, "wrinkly_points"))
        return -1;
    wrinkly_polyline pl;
    if (curve_sample(I, c, &l, &pl, "wrinkly_points"))
        return -1;
    if ((double)pl.n > I->lim.max_list) {
        wrinkly_polyline_free(&pl);
        return err_at(I, NULL, ERR_LIMIT, "wrinkly_points: %zu points exceed the list limit (raise it with --max-list)",
                      pl.n);
    }
    value r = val_list(I, pl.n);
    if (r.k == V_NIL)
        goto oom;
    for (size_t i = 0; i < pl.n; i++) {
        value pt;
        if (lang_num_list_value(I, pl.xy + 2 * i, 2, &pt) || val_list_push(I, AS_LIST(r), pt)) {
            val_unref(I, r);
            goto oom;
        }
    }
    wrinkly_polyline_free(&pl);
    *out = r;
    return 0;
oom:
    wrinkly_polyline_free(&pl);
    return -1;
}

/* World bounds of a curve's drawing: the control points widened by the
 * largest |height|, plus a 5 % margin. */
static void curve_bounds(const curve_obj *c, double lo[2], double hi[2])
{
    double hm = 0;
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    for (int i = 0; i < c->n; i++) {
        for (int d = 0; d < 2; d++) {
            lo[d] = c->pts[i].pos[d] < lo[d] ? c->pts[i].pos[d] : lo[d];
            hi[d] = c->pts[i].pos[d] > hi[d] ? c->pts[i].pos[d] : hi[d];
        }
        hm = fabs(c->pts[i].h) > hm ? fabs(c->pts[i].h) : hm;
    }
    double seg = 0; /* an open curve runs on beyond its end points */
    for (int i = 0; i + 1 < c->n; i++)
        seg = fmax(seg, hypot(c->pts[i + 1].pos[0] - c->pts[i].pos[0], c->pts[i + 1].pos[1] - c->pts[i].pos[1]));
    double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    double pad = hm + (c->ax.cyclic ? 0 : 0.5 * seg) + 0.05 * (ext > 0 ? ext : 1) + (ext > 0 ? 0 : 0.5);
    for (int d = 0; d < 2; d++) {
        lo[d] -= pad;
        hi[d] += pad;
    }
}

static int get_view(interp *I, const curve_obj *c, value bounds, int w, int h, draw_view *v, const char *what)
{
    double lo[2], hi[2];
    if (bounds.k == V_NIL) {
        curve_bounds(c, lo, hi);
    } else {
        vlist *l = AS_LIST(bounds);
        char m[96];
        snprintf(m, sizeof m, "%s: bounds", what);
        if (l->n != 2 || l->items[0].k != V_LIST || l->items[1].k != V_LIST)
            return err_item(I, bounds, SIZE_MAX, ERR_VALUE, "%s: bounds must be [[xmin, ymin], [xmax, ymax]]", what);
        if (builtin_get_vec(I, l->items[0], lo, 2, m) || builtin_get_vec(I, l->items[1], hi, 2, m))
            return -1;
        if (!(hi[0] > lo[0] && hi[1] > lo[1]))
            return err_item(I, bounds, SIZE_MAX, ERR_VALUE, "%s: bounds must have xmin < xmax and ymin < ymax", what);
    }
    rt_error e;
    if (draw_view_fit(v, w, h, lo, hi, 1, &e))
        return err_at(I, NULL, ERR_VALUE, "%s: %s", what, e.msg);
    return 0;
}

static int polyline_shape(interp *I, const wrinkly_polyline *pl, int closed, detiter_shape *s)
{
    rt_error e;
    if (detiter_shape_make(s, 2, pl->n, pl->xy, closed ? DETITER_POLYGON : DETITER_POLYLINE, &e))
        return err_at(I, NULL, ERR_MEMORY, "%s", e.msg);
    return 0;
}

/* wrinkly_draw(curve, size, bounds, width, colour, fill, background, onto, pixel, iterations, kmax) */
static int b_wrinkly_draw(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "wrinkly_draw";
    const curve_obj *c = AS_OBJ(a[0])->payload;
    int w, h;
    image *onto = a[7].k == V_NIL ? NULL : lang_as_image(a[7]);
    if (onto) {
        w = onto->w;
        h = onto->h;
    } else if (lang_arg_size2(I, a[1], &w, &h, "wrinkly_draw: size")) {
        return -1;
    }
    draw_view v;
    if (get_view(I, c, a[2], w, h, &v, W))
        return -1;
    float stroke[4] = {1, 1, 1, 1}, fill[4] = {1, 1, 1, 1}, bg[4];
    if ((a[4].k != V_NIL && lang_get_colour(I, a[4], stroke, "wrinkly_draw: colour")) ||
        (a[5].k != V_NIL && lang_get_colour(I, a[5], fill, "wrinkly_draw: fill")) ||
        lang_get_colour(I, a[6], bg, "wrinkly_draw: background"))
        return -1;
    if (a[5].k != V_NIL && !c->ax.cyclic)
        return err_arg(I, 5, ERR_VALUE, "wrinkly_draw: fill needs a closed curve (wrinkly_curve(…, closed: true))");
    lod l;
    value tol = a[9].k == V_NIL ? val_num(a[8].u.n / v.sx) : val_nil();
    if (lang_get_lod(I, a[9], tol, a[10], -1, &l, W))
        return -1;
    image *im;
    if (lang_image_new(I, w, h, &im))
        return -1;
    rt_error e;
    if (onto) {
        memcpy(im->px, onto->px, sizeof(float) * 4 * (size_t)w * (size_t)h);
    } else {
        draw_clear(im, bg);
    }
    wrinkly_polyline pl;
    if (curve_sample(I, c, &l, &pl, W)) {
        lang_image_discard(im);
        return -1;
    }
    detiter_shape s;
    memset(&s, 0, sizeof s);
    int rc = polyline_shape(I, &pl, pl.closed, &s);
    if (!rc && a[5].k != V_NIL) {
        draw_style st = {{fill[0], fill[1], fill[2], fill[3]}, 0, 0, 1};
        if (draw_shape(im, &v, &s, &st, &e))
            rc = lang_rt_error(I, e.code, &e, W);
    }
    if (!rc && a[3].u.n > 0) {
        if (a[4].k == V_NIL) {
            if (draw_polyline_rgba(im, &v, pl.n, pl.xy, pl.rgba, pl.closed, a[3].u.n, &e))
                rc = lang_rt_error(I, e.code, &e, W);
        } else {
            draw_style st = {{stroke[0], stroke[1], stroke[2], stroke[3]}, a[3].u.n, a[3].u.n / 2, 0};
            if (draw_shape(im, &v, &s, &st, &e))
                rc = lang_rt_error(I, e.code, &e, W);
        }
    }
    if (s.v)
        detiter_shape_free(&s);
    wrinkly_polyline_free(&pl);
    if (rc) {
        lang_image_discard(im);
        return -1;
    }
    return lang_image_value(I, im, out);
}

/* save(curve, "x.svg", {size: 512, width: 1.5, iterations: K}) */
static int curve_save(interp *I, const void *p, const char *path, value opts)
{
    const curve_obj *c = p;
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "svg") != 0)
        return err_at(I, NULL, ERR_VALUE,
                      "save: a wrinkly curve is saved as .svg (draw it with wrinkly_draw for a picture), got '.%s'", ext);
    double size = 512, width = 1.5, iters = -1;
    if (contract_check_opts(I, opts, "rec{size: int[1,1000000], width: num(0,1000], iterations: int[0,20]}", "save") ||
        lang_opt_num(I, opts, "size", &size) < 0 || lang_opt_num(I, opts, "width", &width) < 0 ||
        lang_opt_num(I, opts, "iterations", &iters) < 0)
        return -1;
    draw_view v;
    if (get_view(I, c, val_nil(), (int)size, (int)size, &v, "save"))
        return -1;
    lod l;
    if (lang_get_lod(I, iters >= 0 ? val_num(iters) : val_nil(), iters >= 0 ? val_nil() : val_num(1 / v.sx), val_num(8), -1,
                &l, "save"))
        return -1;
    wrinkly_polyline pl;
    if (curve_sample(I, c, &l, &pl, "save"))
        return -1;
    detiter_shape s;
    if (polyline_shape(I, &pl, pl.closed, &s)) {
        wrinkly_polyline_free(&pl);
        return -1;
    }
    wrinkly_polyline_free(&pl);
    draw_style st = {{0, 0, 0, 1}, width, width / 2, 0};
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    rt_code rc = draw_svg(&b, &v, &s, &st, NULL, 3, &e);
    detiter_shape_free(&s);
    if (!rc)
        rc = b.failed ? rt_fail(&e, RT_ENOMEM, "out of memory writing SVG") : fileio_write_atomic(path, b.data, b.len, &e);
    bytebuf_free(&b);
    if (rc)
        return lang_rt_error(I, rc, &e, "save");
    return 0;
}

/* ---- surfaces ------------------------------------------------------------------------ */

static void surf_destroy(void *p)
{
    surf_obj *s = p;
    rt_free(s->pts);
    rt_free(s);
}

static void axis_summary(const wrinkly_axis *a, bytebuf *out)
{
    bytebuf_printf(out, "%s, M = %d, %s", a->cyclic ? "cyclic" : "open", a->m, a->ist ? "IST" : "spline");
}

static void surf_summary(const void *p, bytebuf *out)
{
    const surf_obj *s = p;
    bytebuf_printf(out, "wrinkly surface: %d×%d control points; u: ", s->nu, s->nv);
    axis_summary(&s->au, out);
    bytebuf_printf(out, "; v: ");
    axis_summary(&s->av, out);
    style_summary(&s->style, out);
}

static int surf_get(interp *I, const void *p, const char *name, value *out)
{
    const surf_obj *s = p;
    (void)I;
    if (strcmp(name, "nu") == 0)
        *out = val_num(s->nu);
    else if (strcmp(name, "nv") == 0)
        *out = val_num(s->nv);
    else
        return 1;
    return 0;
}

static const obj_class surf_class = {
    .name = "wrinkly_surface",
    .destroy = surf_destroy,
    .summary = surf_summary,
    .get = surf_get,
};

/* An axis record {cyclic: false, crossings: 1, ist: true} (keys and types
 * declared by TY_AXIS). */
static void get_axis(interp *I, value v, wrinkly_axis *ax)
{
    ax->cyclic = 0;
    ax->m = 1;
    ax->ist = 1;
    if (v.k == V_NIL)
        return;
    double x;
    if (lang_opt_num(I, v, "cyclic", &x) == 1)
        ax->cyclic = x != 0;
    if (lang_opt_num(I, v, "ist", &x) == 1)
        ax->ist = x != 0;
    if (lang_opt_num(I, v, "crossings", &x) == 1)
        ax->m = (int)x;
}

/* wrinkly_surface(control, heights, colours, opacity, u, v, shuffle, tension, crack_band, jitter, extra, seed, normal) */
static int b_wrinkly_surface(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "wrinkly_surface";
    vlist *rows = AS_LIST(a[0]);
    if (rows->n < 1 || rows->n > MAX_CONTROL || rows->items[0].k != V_LIST || AS_LIST(rows->items[0])->n < 1)
        return err_arg(I, 0, ERR_VALUE,
                       "wrinkly_surface: control must be a grid: a list of rows, each a list of points [x, y, z]");
    size_t nu = AS_LIST(rows->items[0])->n, nv = rows->n;
    if (nu > MAX_CONTROL || (double)nu * (double)nv > 1e7)
        return err_at(I, NULL, ERR_LIMIT, "wrinkly_surface: %zu×%zu control points are too many (at most 10000000)", nu,
                      nv);
    surf_obj *s = mem_calloc(I, 1, sizeof *s);
    if (s)
        s->pts = mem_calloc(I, nu * nv, sizeof *s->pts);
    if (!s || !s->pts) {
        mem_free(I, s);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    s->nu = (int)nu;
    s->nv = (int)nv;
    for (size_t j = 0; j < nv; j++) {
        value row = rows->items[j];
        if (row.k != V_LIST || AS_LIST(row)->n != nu) {
            err_item(I, a[0], j, ERR_VALUE,
                     "wrinkly_surface: control row %zu has %zu points, but row 0 has %zu (every row needs the same number)", j,
                     row.k == V_LIST ? AS_LIST(row)->n : 0, nu);
            goto fail;
        }
        for (size_t i = 0; i < nu; i++) {
            char w[96];
            snprintf(w, sizeof w, "wrinkly_surface: control point [%zu][%zu]", j, i);
            double *p = s->pts[j * nu + i].pos;
            if (builtin_get_vec(I, AS_LIST(row)->items[i], p, 3, w)) /* numbers: finite (declared list) */
                goto fail;
        }
    }
    if (fill_scalar(I, a[1], s->nv, s->nu, s->pts, 0, W, "heights") ||
        fill_colours(I, a[2], s->nv, s->nu, s->pts, W) || fill_scalar(I, a[3], s->nv, s->nu, s->pts, 4, W, "opacity") ||
        get_style(I, a[7], a[6], a[8], a[9], a[10], a[11], &s->style, W))
        goto fail;
    get_axis(I, a[4], &s->au);
    get_axis(I, a[5], &s->av);
    if (a[12].k != V_NIL) {
        const char *nm = AS_STR(a[12])->s;
        s->style.normal = strcmp(nm, "outward") == 0  ? WRINKLY_NORMAL_OUTWARD
                          : strcmp(nm, "inward") == 0 ? WRINKLY_NORMAL_INWARD
                                                      : WRINKLY_NORMAL_UV;
        /* a sheet has no outward side: say so here, at the argument */
        wrinkly_surface ws = {s->pts, s->nu, s->nv, s->au, s->av};
        rt_error e;
        if (!wrinkly_surface_side(&ws, &s->style, &e)) {
            err_arg(I, 12, ERR_VALUE, "wrinkly_surface: normal \"%s\": %s", nm, e.msg);
            goto fail;
        }
    }
    *out = val_obj(I, &surf_class, s);
    return out->k == V_NIL ? -1 : 0;
fail:
    surf_destroy(s);
    return -1;
}

surf_obj *lang_as_surf(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &surf_class ? AS_OBJ(v)->payload : NULL;
}

/* Tessellate after checking the vertex count (--max-points) and the memory
 * the engine needs (--max-memory). cam may be NULL. */
/* split: the mesh is the builtin's result (tessellate), so a shard may
 * compute its rows only (docs/scale.md); not where it feeds an engine inside
 * the same builtin (rasterize). */
static int surf_mesh(interp *I, const surf_obj *so, const camera *cam, int w, int h, double pixel, const lod *l,
                     int split, mesh **out, const char *what)
{
    wrinkly_surface ws = {so->pts, so->nu, so->nv, so->au, so->av};
    wrinkly_opts o = so->style;
    o.split = split;
    o.cam = cam;
    o.width = w;
    o.height = h;
    o.pixel = pixel;
    o.tol = l->tol;
    o.k = l->k;
    o.kmax = l->kmax;
    int *ku = mem_alloc(I, sizeof(int) * (size_t)so->nu), *kv = mem_alloc(I, sizeof(int) * (size_t)so->nv);
    if (!ku || !kv) {
        mem_free(I, ku);
        mem_free(I, kv);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    rt_error e;
    rt_code rc = wrinkly_surface_levels(&ws, &o, ku, kv, &e);
    if (rc) {
        mem_free(I, ku);
        mem_free(I, kv);
        return lang_rt_error(I, rc, &e, what);
    }
    double cu = so->au.cyclic ? 0 : 2, cv = so->av.cyclic ? 0 : 2;
    for (int i = 0; i < so->nu; i++)
        cu += pow(2.0 * so->au.m + 1, ku[i]);
    for (int j = 0; j < so->nv; j++)
        cv += pow(2.0 * so->av.m + 1, kv[j]);
    mem_free(I, ku);
    mem_free(I, kv);
    double nvert = cu * cv;
    if (nvert > I->lim.max_points || nvert >= 4294967295.0)
        return err_at(I, NULL, ERR_LIMIT,
                      "%s: the surface would have %.0f × %.0f = %.0f vertices, more than the limit of %.0f points (raise it with --max-points, or lower iterations/kmax)",
                      what, cu, cv, nvert, fmin(I->lim.max_points, 4294967294.0));
    /* positions, normals, colours (floats), the displaced grid (doubles),
     * two triangles per vertex */
    double bytes = nvert * (12 + 12 + 16 + 24 + 24);
    if (mem_precheck(I, bytes, "the wrinkly mesh"))
        return -1;
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m) {
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    rt_run run = lang_run(I);
    double t0 = report_clock();
    rc = wrinkly_surface_mesh(&ws, &o, &run, m, NULL, &e);
    if (rc) {
        mesh_free(m);
        mem_free(I, m);
        return lang_rt_error(I, rc, &e, what);
    }
    report_work(I, "wrinkly surface", "triangles", (double)m->nt, t0);
    *out = m;
    return 0;
}

int lang_surf_mesh(interp *I, const surf_obj *so, const camera *cam, int w, int h, double pixel, const lod *l,
                   mesh **out, const char *what)
{
    return surf_mesh(I, so, cam, w, h, pixel, l, 0, out, what);
}

static int get_camera_lod(interp *I, value cam, value tol, value iters, camera *c, int *use_cam, const char *what)
{
    *use_cam = cam.k != V_NIL;
    if (!*use_cam)
        return 0;
    if (tol.k != V_NIL || iters.k != V_NIL)
        return err_arg(I, tol.k != V_NIL ? 4 : 5, ERR_VALUE,
                       "%s: with a camera the level of detail follows the pixels; drop tolerance and iterations (or the camera)",
                       what);
    return lang_get_camera(I, cam, c, what);
}

/* tessellate(surface, camera, size, pixel, tolerance, iterations, kmax) */
static int b_tessellate(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "tessellate";
    const surf_obj *so = AS_OBJ(a[0])->payload;
    camera cam;
    int use_cam, w = 256, h = 256;
    lod l;
    if (get_camera_lod(I, a[1], a[4], a[5], &cam, &use_cam, W) || lang_arg_size2(I, a[2], &w, &h, "tessellate: size") ||
        lang_get_lod(I, a[5], a[4], a[6], 4, &l, W))
        return -1;
    mesh *m;
    if (surf_mesh(I, so, use_cam ? &cam : NULL, w, h, a[3].u.n, &l, 1, &m, W))
        return -1;
    return lang_mesh_value(I, m, out);
}

/* ---- registration ---------------------------------------------------------------------- */

/* MAX_CONTROL, MAX_M and MAX_KMAX written out (type texts are literal). */
#define TY_AXIS "rec{cyclic: bool, crossings: int[0,50], ist: bool}"
#define TY_SHUFFLE "str{height,colour,color,opacity}|list"
static const bparam p_curve[] = {{"points", "list", NULL},          {"heights", "num|vec", "0"},
                                 {"colours", "num|str|list", "nil"}, {"opacity", "num|vec", "1"},
                                 {"crossings", "int[0,50]", "1"},   {"closed", "bool", "false"},
                                 {"ist", "bool", "true"},           {"shuffle", TY_SHUFFLE, "nil"},
                                 {"tension", "num(0,1]", "2/3"},    {"crack_band", "num[0,0.5]", "0"},
                                 {"jitter", "bool", "false"},       {"extra", "int[0,8]", "0"},
                                 {"seed", "int>=0", "nil"}};
static const bparam p_points[] = {{"curve", "wrinkly_curve", NULL}, {"iterations", TY_LOD_K, "nil"},
                                  {"tolerance", "num>0", "nil"}, {"kmax", TY_LOD_K, "8"}};
static const bparam p_draw[] = {{"curve", "wrinkly_curve", NULL}, {"size", TY_SIZE, "[256, 256]"},
                                {"bounds", "list", "nil"},        {"width", "num[0,1000]", "1.5"},
                                {"colour", TY_COLOUR, "nil"},     {"fill", TY_COLOUR, "nil"},
                                {"background", TY_COLOUR, "0"},   {"onto", "image", "nil"},
                                {"pixel", "num>0", "1"},          {"iterations", TY_LOD_K, "nil"},
                                {"kmax", TY_LOD_K, "8"}};
static const bparam p_surface[] = {{"control", "list", NULL},            {"heights", "num|list", "0"},
                                   {"colours", "num|str|list", "nil"},    {"opacity", "num|list", "1"},
                                   {"u", TY_AXIS, "nil"},                {"v", TY_AXIS, "nil"},
                                   {"shuffle", TY_SHUFFLE, "nil"},       {"tension", "num(0,1]", "2/3"},
                                   {"crack_band", "num[0,0.5]", "0"},    {"jitter", "bool", "false"},
                                   {"extra", "int[0,8]", "0"},           {"seed", "int>=0", "nil"},
                                   {"normal", "str{outward,inward,uv}", "nil"}};
static const bparam p_tess[] = {{"surface", "wrinkly_surface", NULL}, {"camera", TY_CAMERA, "nil"},
                                {"size", TY_SIZE, "[256, 256]"},      {"pixel", "num>0", "1"},
                                {"tolerance", "num>0", "nil"},        {"iterations", TY_LOD_K, "nil"},
                                {"kmax", TY_LOD_K, "8"}};

static const builtin wrinkly_builtins[] = {
    BUILTIN("wrinkly_curve", b_wrinkly_curve, p_curve,
            "A wrinkly curve (eq. 10) through 2-D control points with heights, colours and opacity; crossings M, closed (cyclic), ist: false for the plain spline; shuffle names the attributes the IST moves; crack_band, jitter, extra, seed control the sampling."),
    BUILTIN("wrinkly_points", b_wrinkly_points, p_points,
            "Sample a wrinkly curve into a list of [x, y] points: fixed `iterations` (default 3) or adaptive to `tolerance` (world length of a sub-interval), K capped by kmax."),
    BUILTIN("wrinkly_draw", b_wrinkly_draw, p_draw,
            "Draw a wrinkly curve antialiased into an image (or over `onto`): sub-intervals adapt to `pixel` pixels unless `iterations` is given; colour nil uses the curve's own colours; fill a closed curve."),
    BUILTIN("wrinkly_surface", b_wrinkly_surface, p_surface,
            "A wrinkly surface (eq. 11) over a grid of control points [x, y, z] (a list of rows): heights, colours, opacity per point (or one value); u and v are records {cyclic, crossings, ist}; normal: \"outward\", \"inward\" or \"uv\" orients N (default: outward for a body-like surface, else P_u × P_v)."),
    BUILTIN("tessellate", b_tessellate, p_tess,
            "Sample a wrinkly surface into a coloured mesh (§5.2): with a camera, sub-intervals project to at most `pixel` pixels of an image of `size`; else `tolerance` (world length) or fixed `iterations` (default 3)."),
};

int bind_wrinkly_init(interp *I)
{
    return BUILTIN_REGISTER(I, wrinkly_builtins);
}
