/* bind_wrinkly.c — seed 002 in the language: the Iterated Shuffle
 * Transformation (ist objects), wrinkly curves (drawn into images or SVG)
 * and wrinkly surfaces (tessellated into meshes, rasterised with a Z-buffer).
 * The reference for scripts is docs/wrinkly.md; the engines are
 * runtime/ist.h, runtime/wrinkly.h and runtime/raster.h. */
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
#include "raster.h"
#include "wrinkly.h"

#define MAX_CONTROL 100000 /* control points per axis */
#define MAX_M 50           /* crossing count of curves and surfaces (wrinkly.c) */
#define MAX_KMAX 20

/* ---- small helpers ------------------------------------------------------------------ */

static int list_of_nums(interp *I, const double *x, size_t n, value *out)
{
    value l = val_list(I, n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (list_push(I, AS_LIST(l), val_num(x[i]))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

static int get_seed(interp *I, value v, uint64_t *seed, const char *what)
{
    if (v.k == V_NIL) {
        *seed = I->seed;
        return 0;
    }
    if (v.u.n < 0 || v.u.n > 9007199254740992.0 || v.u.n != floor(v.u.n))
        return err_at(I, NULL, ERR_VALUE, "%s: seed must be a whole number >= 0, got %g", what, v.u.n);
    *seed = (uint64_t)v.u.n;
    return 0;
}

static int get_size2(interp *I, value v, int *w, int *h, const char *what)
{
    double s[2];
    if (v.k == V_NUM)
        s[0] = s[1] = v.u.n;
    else if (get_vec(I, v, s, 2, what))
        return -1;
    if (s[0] != floor(s[0]) || s[1] != floor(s[1]) || s[0] < 1 || s[1] < 1 || s[0] > 1e6 || s[1] > 1e6)
        return err_at(I, NULL, ERR_VALUE, "%s must be whole numbers of pixels between 1 and 1000000, got [%g, %g]",
                      what, s[0], s[1]);
    *w = (int)s[0];
    *h = (int)s[1];
    return 0;
}

/* shuffle: nil (everything), "height", or a list of "height" / "colour" / "opacity". */
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
            return err_at(I, NULL, ERR_VALUE,
                          "%s: shuffle must name attributes \"height\", \"colour\" or \"opacity\" (a string or a list of them), got %s%s%s",
                          what, t ? "\"" : "", t ? t : val_type_name(s), t ? "\"" : "");
    }
    return 0;
}

/* Style shared by curves and surfaces: how the attributes are interpolated
 * and sampled (not the level of detail, which the drawing call decides). */
static int get_style(interp *I, value tension, value shuffle, value crack, value jitter, value extra, value seed,
                     wrinkly_opts *o, const char *what)
{
    wrinkly_opts_default(o);
    if (!(tension.u.n > 0 && tension.u.n <= 1))
        return err_at(I, NULL, ERR_VALUE, "%s: tension must be in (0, 1], got %g", what, tension.u.n);
    o->tension = tension.u.n;
    if (get_shuffle(I, shuffle, &o->shuffle, what))
        return -1;
    if (!(crack.u.n >= 0 && crack.u.n <= 0.5))
        return err_at(I, NULL, ERR_VALUE,
                      "%s: crack_band must be between 0 (off) and 0.5 (parameter units), got %g", what, crack.u.n);
    o->crack_band = crack.u.n;
    o->jitter = jitter.u.b;
    char w[96];
    snprintf(w, sizeof w, "%s: extra", what);
    long ex;
    if (get_int(I, extra, 0, 8, &ex, w))
        return -1;
    o->extra = (int)ex;
    return get_seed(I, seed, &o->seed, what);
}

static void style_summary(const wrinkly_opts *o, bytebuf *out)
{
    if (o->crack_band > 0)
        bytebuf_printf(out, ", crack band %g", o->crack_band);
    if (o->jitter)
        bytebuf_printf(out, ", jitter");
    if (o->extra)
        bytebuf_printf(out, ", +%d rounds", o->extra);
}

/* ---- ist objects -------------------------------------------------------------------- */

typedef struct ist_obj {
    ist t;
    size_t bytes; /* reserved from the memory budget for the lists */
    interp *I;
} ist_obj;

static void ist_destroy(void *p)
{
    ist_obj *o = p;
    mem_release(o->I, o->bytes);
    ist_free(&o->t);
    free(o);
}

static void ist_summary(const void *p, bytebuf *out)
{
    const ist *t = &((const ist_obj *)p)->t;
    int lo = t->ms[0], hi = t->ms[0];
    for (int i = 1; i < t->n; i++) {
        lo = t->ms[i] < lo ? t->ms[i] : lo;
        hi = t->ms[i] > hi ? t->ms[i] : hi;
    }
    bytebuf_printf(out, "ist: %d interval%s", t->n, t->n == 1 ? "" : "s");
    if (t->bounds[0] != 0 || t->bounds[t->n] != t->n)
        bytebuf_printf(out, " on [%g, %g)", t->bounds[0], t->bounds[t->n]);
    if (lo == hi)
        bytebuf_printf(out, ", M = %d", lo);
    else
        bytebuf_printf(out, ", M = %d..%d", lo, hi);
    bytebuf_printf(out, ", K = %d, %s", t->k, t->axis == IST_CYCLIC ? "cyclic" : "translation");
}

static int ist_get(interp *I, const void *p, const char *name, value *out)
{
    const ist *t = &((const ist_obj *)p)->t;
    if (strcmp(name, "intervals") == 0)
        *out = val_num(t->n);
    else if (strcmp(name, "iterations") == 0)
        *out = val_num(t->k);
    else if (strcmp(name, "cyclic") == 0)
        *out = val_bool(t->axis == IST_CYCLIC);
    else if (strcmp(name, "closed_form") == 0)
        *out = val_bool(t->closed);
    else if (strcmp(name, "bounds") == 0)
        return list_of_nums(I, t->bounds, (size_t)t->n + 1, out);
    else if (strcmp(name, "crossings") == 0) {
        double *m = malloc(sizeof(double) * (size_t)t->n);
        if (!m)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        for (int i = 0; i < t->n; i++)
            m[i] = t->ms[i];
        int r = list_of_nums(I, m, (size_t)t->n, out);
        free(m);
        return r;
    } else
        return 1;
    return 0;
}

static const obj_class ist_class = {
    .name = "ist",
    .destroy = ist_destroy,
    .summary = ist_summary,
    .get = ist_get,
};

/* Bytes the list evaluator needs for Σ|L_i^K| entries (ist.h: seven arrays). */
#define IST_ENTRY_BYTES 48.0

static double ist_list_estimate(const ist *t)
{
    int bmax = 1;
    for (int i = 0; i < t->n; i++)
        bmax = 2 * t->ms[i] + 1 > bmax ? 2 * t->ms[i] + 1 : bmax;
    double e = t->n * pow(bmax, t->k);
    return e > (double)IST_MAX_ENTRIES ? (double)IST_MAX_ENTRIES : e;
}

/* ist(intervals, crossings, iterations, cyclic, bounds, method) */
static int b_ist(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "ist";
    long nint = 5, k, m = 0;
    double *bounds = NULL;
    int *ms = NULL;
    if (a[4].k != V_NIL) {
        size_t nb = AS_LIST(a[4])->n;
        if (nb < 2 || nb > MAX_CONTROL + 1)
            return err_at(I, NULL, ERR_VALUE, "ist: bounds must be a list of 2 to %d numbers (N + 1 for N intervals), got %zu",
                          MAX_CONTROL + 1, nb);
        if (a[0].k != V_NIL && (size_t)a[0].u.n + 1 != nb)
            return err_at(I, NULL, ERR_VALUE, "ist: intervals is %g but bounds gives %zu intervals (N + 1 bounds for N intervals)",
                          a[0].u.n, nb - 1);
        nint = (long)nb - 1;
    } else if (a[0].k != V_NIL && get_int(I, a[0], 1, MAX_CONTROL, &nint, "ist: intervals")) {
        return -1;
    }
    if (get_int(I, a[2], 0, IST_MAX_K, &k, "ist: iterations"))
        return -1;
    ist_spec s = {.n = (int)nint, .k = (int)k, .axis = a[3].u.b ? IST_CYCLIC : IST_TRANSLATION};
    const char *meth = AS_STR(a[5])->s;
    if (strcmp(meth, "auto") == 0)
        s.method = IST_AUTO;
    else if (strcmp(meth, "lists") == 0)
        s.method = IST_LISTS;
    else if (strcmp(meth, "closed") == 0)
        s.method = IST_CLOSED;
    else
        return err_at(I, NULL, ERR_VALUE, "ist: method must be \"auto\", \"lists\" or \"closed\", got \"%s\"", meth);
    int rc = -1;
    if (a[4].k != V_NIL) {
        bounds = malloc(sizeof(double) * (size_t)(nint + 1));
        if (!bounds)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        get_vec(I, a[4], bounds, (size_t)nint + 1, "ist: bounds");
        for (long i = 0; i <= nint; i++)
            if (!isfinite(bounds[i])) {
                err_at(I, NULL, ERR_VALUE, "ist: bound %ld is %g; bounds must be finite", i, bounds[i]);
                goto done;
            }
        for (long i = 0; i < nint; i++)
            if (!(bounds[i + 1] > bounds[i])) {
                err_at(I, NULL, ERR_VALUE, "ist: bounds must increase, but bound %ld = %g is not greater than bound %ld = %g",
                       i + 1, bounds[i + 1], i, bounds[i]);
                goto done;
            }
        s.bounds = bounds;
    }
    if (a[1].k == V_LIST) {
        if (AS_LIST(a[1])->n != (size_t)nint) {
            err_at(I, NULL, ERR_VALUE, "ist: crossings must be one whole number or a list of %ld (one per interval), got %zu",
                   nint, AS_LIST(a[1])->n);
            goto done;
        }
        ms = malloc(sizeof(int) * (size_t)nint);
        if (!ms) {
            err_at(I, NULL, ERR_MEMORY, "out of memory");
            goto done;
        }
        for (long i = 0; i < nint; i++) {
            char w[64];
            snprintf(w, sizeof w, "ist: crossings[%ld]", i);
            if (get_int(I, AS_LIST(a[1])->items[i], 0, 1000, &m, w))
                goto done;
            ms[i] = (int)m;
        }
        s.m_each = ms;
    } else {
        if (get_int(I, a[1], 0, 1000, &m, "ist: crossings"))
            goto done;
        s.m = (int)m;
    }
    ist_obj *o = calloc(1, sizeof *o);
    if (!o) {
        err_at(I, NULL, ERR_MEMORY, "out of memory");
        goto done;
    }
    o->I = I;
    /* The list evaluator is used unless the closed form applies: reserve its
     * memory first (an upper bound: N·(2M+1)^K entries). */
    {
        int mmax = s.m, uniform = 1, equal = 1;
        if (ms)
            for (long i = 0; i < nint; i++) {
                mmax = ms[i] > mmax ? ms[i] : mmax;
                uniform &= ms[i] == ms[0];
            }
        if (bounds)
            for (long i = 0; i <= nint; i++)
                equal &= bounds[i] == bounds[0] + (double)i * (bounds[1] - bounds[0]);
        double est = (double)nint * pow(2.0 * mmax + 1, (double)s.k);
        if (est > (double)IST_MAX_ENTRIES)
            est = (double)IST_MAX_ENTRIES;
        int closed = uniform && equal && s.method != IST_LISTS && pow(2.0 * mmax + 1, (double)s.k) <= 4503599627370496.0;
        if (!closed) {
            if (mem_reserve(I, est * IST_ENTRY_BYTES, "the IST lists")) {
                free(o);
                goto done;
            }
            o->bytes = (size_t)(est * IST_ENTRY_BYTES);
        }
    }
    rt_error e;
    rt_code c = ist_init(&o->t, &s, &e);
    if (c) {
        mem_release(I, o->bytes);
        free(o);
        lang_rt_error(I, c, &e, W);
        goto done;
    }
    *out = val_obj(I, &ist_class, o);
    rc = out->k == V_NIL ? -1 : 0;
done:
    free(bounds);
    free(ms);
    return rc;
}

static int ist_map(interp *I, value *a, int fwd, value *out)
{
    const ist *t = &((ist_obj *)AS_OBJ(a[0])->payload)->t;
    if (a[1].k == V_NUM) {
        *out = val_num(fwd ? ist_fwd(t, a[1].u.n) : ist_inv(t, a[1].u.n));
        return 0;
    }
    vlist *l = AS_LIST(a[1]);
    value r = val_list(I, l->n);
    if (r.k == V_NIL)
        return -1;
    for (size_t i = 0; i < l->n; i++) {
        double u = l->items[i].u.n;
        if (list_push(I, AS_LIST(r), val_num(fwd ? ist_fwd(t, u) : ist_inv(t, u)))) {
            val_unref(I, r);
            return -1;
        }
    }
    *out = r;
    return 0;
}

static int b_ist_inv(interp *I, value *a, int n, value *out)
{
    (void)n;
    return ist_map(I, a, 0, out);
}

static int b_ist_fwd(interp *I, value *a, int n, value *out)
{
    (void)n;
    return ist_map(I, a, 1, out);
}

static int b_ist_lists(interp *I, value *a, int n, value *out)
{
    (void)n;
    ist_obj *o = AS_OBJ(a[0])->payload;
    ist *t = &o->t;
    if (t->k > 9)
        return err_at(I, NULL, ERR_VALUE, "ist_lists: the Fig. 2 notation needs iterations <= 9, this ist has K = %d",
                      t->k);
    if (t->closed && !t->x) {
        double est = ist_list_estimate(t);
        if (mem_reserve(I, est * IST_ENTRY_BYTES, "the IST lists"))
            return -1;
        o->bytes += (size_t)(est * IST_ENTRY_BYTES);
    }
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    rt_code c = ist_print(t, &b, &e);
    if (c) {
        bytebuf_free(&b);
        return lang_rt_error(I, c, &e, "ist_lists");
    }
    /* drop the final newline: print() adds one */
    size_t len = b.len;
    if (len && b.data[len - 1] == '\n')
        len--;
    *out = val_str(I, (const char *)b.data, len);
    bytebuf_free(&b);
    return out->k == V_NIL ? -1 : 0;
}

static int b_ist_samples(interp *I, value *a, int n, value *out)
{
    (void)n;
    const ist *t = &((ist_obj *)AS_OBJ(a[0])->payload)->t;
    int *ki = malloc(sizeof(int) * (size_t)t->n);
    if (!ki)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    int rc = -1;
    double *pos = NULL;
    if (a[1].k == V_LIST && AS_LIST(a[1])->n != (size_t)t->n) {
        err_at(I, NULL, ERR_VALUE, "ist_samples: levels must be one whole number or a list of %d (one per interval), got %zu",
               t->n, AS_LIST(a[1])->n);
        goto done;
    }
    double count = 0;
    for (int i = 0; i < t->n; i++) {
        long l = t->k;
        value v = a[1].k == V_LIST ? AS_LIST(a[1])->items[i] : a[1];
        if (v.k != V_NIL && get_int(I, v, 0, t->k, &l, "ist_samples: levels (at most the ist's iterations)"))
            goto done;
        ki[i] = (int)l;
        count += pow(2.0 * t->ms[i] + 1, (double)l);
    }
    if (count > I->lim.max_list || count > I->lim.max_points) {
        err_at(I, NULL, ERR_LIMIT, "ist_samples: %.0f samples exceed the list limit (raise it with --max-list)", count);
        goto done;
    }
    uint64_t seed;
    if (get_seed(I, a[3], &seed, "ist_samples"))
        goto done;
    pos = malloc(sizeof(double) * ((size_t)count + 1));
    if (!pos) {
        err_at(I, NULL, ERR_MEMORY, "out of memory for %.0f samples", count);
        goto done;
    }
    size_t got = ist_sample_positions(t, ki, a[2].u.b, seed, pos, (size_t)count);
    if (got == (size_t)-1 || got > (size_t)count) {
        err_at(I, NULL, ERR_VALUE, "ist_samples: too many sub-intervals; lower the levels");
        goto done;
    }
    rc = list_of_nums(I, pos, got, out);
done:
    free(ki);
    free(pos);
    return rc;
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
            return err_at(I, NULL, ERR_TYPE, "%s: %s must be a number or a %s, got %s", what, name,
                          rows ? "grid (list of rows) of numbers" : "list of numbers, one per point", val_type_name(v));
        } else {
            vlist *l = AS_LIST(v);
            value it;
            if (rows) {
                size_t r = i / (size_t)cols, c = i % (size_t)cols;
                if (l->n != (size_t)rows || l->items[r].k != V_LIST || AS_LIST(l->items[r])->n != (size_t)cols)
                    return err_at(I, NULL, ERR_VALUE,
                                  "%s: %s must be a number or a grid of %d rows of %d numbers (like the control points)",
                                  what, name, rows, cols);
                it = AS_LIST(l->items[r])->items[c];
            } else {
                if (l->n != (size_t)cols)
                    return err_at(I, NULL, ERR_VALUE, "%s: %s must be a number or a list of %d numbers (one per point), got %zu",
                                  what, name, cols, l->n);
                it = l->items[i];
            }
            if (it.k != V_NUM)
                return err_at(I, NULL, ERR_TYPE, "%s: %s must contain numbers, found %s", what, name, val_type_name(it));
            x = it.u.n;
        }
        if (!isfinite(x))
            return err_at(I, NULL, ERR_VALUE, "%s: %s must be finite, got %g", what, name, x);
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
        return err_at(I, NULL, ERR_TYPE, "%s must be a colour or a %s of colours, got %s", w,
                      rows ? "grid" : "list", val_type_name(v));
    vlist *l = AS_LIST(v);
    for (size_t i = 0; i < n; i++) {
        value it;
        if (rows) {
            size_t r = i / (size_t)cols, cc = i % (size_t)cols;
            if (l->n != (size_t)rows || l->items[r].k != V_LIST || AS_LIST(l->items[r])->n != (size_t)cols)
                return err_at(I, NULL, ERR_VALUE, "%s must be one colour or a grid of %d rows of %d colours", w, rows,
                              cols);
            it = AS_LIST(l->items[r])->items[cc];
        } else {
            if (l->n != (size_t)cols)
                return err_at(I, NULL, ERR_VALUE, "%s must be one colour or a list of %d colours (one per point), got %zu",
                              w, cols, l->n);
            it = l->items[i];
        }
        if (lang_get_colour(I, it, c, w))
            return -1;
        for (int q = 0; q < 3; q++)
            p[i].rgb[q] = c[q];
    }
    return 0;
}

static int get_crossings(interp *I, value v, int *m, const char *what)
{
    long x;
    char w[96];
    snprintf(w, sizeof w, "%s: crossings", what);
    if (get_int(I, v, 0, MAX_M, &x, w))
        return -1;
    *m = (int)x;
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
    free(c->pts);
    free(c);
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
        return err_at(I, NULL, ERR_VALUE, "wrinkly_curve: points must be a list of 1 to %d points [x, y], got %zu",
                      MAX_CONTROL, pl->n);
    curve_obj *c = calloc(1, sizeof *c);
    if (c)
        c->pts = calloc(pl->n, sizeof *c->pts);
    if (!c || !c->pts) {
        if (c)
            free(c);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    c->n = (int)pl->n;
    for (size_t i = 0; i < pl->n; i++) {
        char w[64];
        snprintf(w, sizeof w, "wrinkly_curve: point %zu", i);
        if (get_vec(I, pl->items[i], c->pts[i].pos, 2, w))
            goto fail;
        if (!isfinite(c->pts[i].pos[0]) || !isfinite(c->pts[i].pos[1])) {
            err_at(I, NULL, ERR_VALUE, "wrinkly_curve: point %zu is not finite", i);
            goto fail;
        }
    }
    if (fill_scalar(I, a[1], 0, c->n, c->pts, 0, W, "heights") || fill_colours(I, a[2], 0, c->n, c->pts, W) ||
        fill_scalar(I, a[3], 0, c->n, c->pts, 4, W, "opacity") || get_crossings(I, a[4], &c->ax.m, W))
        goto fail;
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

/* Level of detail: iterations (fixed K) or tolerance (world length of a
 * sub-interval); kmax caps K. */
typedef struct lod {
    int k, kmax;
    double tol;
    int fixed; /* iterations given */
} lod;

static int get_lod(interp *I, value iterations, value tolerance, value kmax, lod *l, const char *what)
{
    char w[96];
    long x;
    l->k = 3;
    l->tol = 0;
    l->fixed = iterations.k != V_NIL;
    snprintf(w, sizeof w, "%s: kmax", what);
    if (get_int(I, kmax, 0, MAX_KMAX, &x, w))
        return -1;
    l->kmax = (int)x;
    if (iterations.k != V_NIL) {
        snprintf(w, sizeof w, "%s: iterations", what);
        if (get_int(I, iterations, 0, MAX_KMAX, &x, w))
            return -1;
        l->k = (int)x;
        if (l->k > l->kmax)
            l->kmax = l->k;
    }
    if (tolerance.k != V_NIL) {
        if (iterations.k != V_NIL)
            return err_at(I, NULL, ERR_VALUE, "%s: give either iterations or tolerance, not both", what);
        if (!(tolerance.u.n > 0) || !isfinite(tolerance.u.n))
            return err_at(I, NULL, ERR_VALUE, "%s: tolerance must be a positive length, got %g", what, tolerance.u.n);
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
    int *ki = malloc(sizeof(int) * (size_t)c->n);
    if (!ki)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    wrinkly_curve_levels(&wc, &o, ki);
    double count = c->ax.cyclic ? 0 : 2;
    for (int i = 0; i < c->n; i++)
        count += pow(2.0 * c->ax.m + 1, ki[i]);
    free(ki);
    if (count > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT,
                      "%s: the curve would have %.0f samples, more than the limit of %.0f points (raise it with --max-points, or lower iterations/kmax)",
                      what, count, I->lim.max_points);
    if (mem_reserve(I, count * 40, "the curve samples"))
        return -1;
    rt_error e;
    rt_code rc = wrinkly_curve_sample(&wc, &o, pl, &e);
    mem_release(I, (size_t)(count * 40));
    if (rc)
        return lang_rt_error(I, rc, &e, what);
    return 0;
}

static int b_wrinkly_points(interp *I, value *a, int n, value *out)
{
    (void)n;
    const curve_obj *c = AS_OBJ(a[0])->payload;
    lod l;
    if (get_lod(I, a[1], a[2], a[3], &l, "wrinkly_points"))
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
        if (list_of_nums(I, pl.xy + 2 * i, 2, &pt) || list_push(I, AS_LIST(r), pt)) {
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
    double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    double pad = hm + 0.05 * (ext > 0 ? ext : 1) + (ext > 0 ? 0 : 0.5);
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
            return err_at(I, NULL, ERR_VALUE, "%s: bounds must be [[xmin, ymin], [xmax, ymax]]", what);
        if (get_vec(I, l->items[0], lo, 2, m) || get_vec(I, l->items[1], hi, 2, m))
            return -1;
        if (!(hi[0] > lo[0] && hi[1] > lo[1]) || !isfinite(lo[0] + lo[1] + hi[0] + hi[1]))
            return err_at(I, NULL, ERR_VALUE, "%s: bounds must have xmin < xmax and ymin < ymax", what);
    }
    rt_error e;
    if (draw_view_fit(v, w, h, lo, hi, 1, &e))
        return err_at(I, NULL, ERR_VALUE, "%s: %s", what, e.msg);
    return 0;
}

/* Stroke a polyline whose segments have their own colours: per pixel the
 * segment with the largest coverage wins (coverage as in draw.h), then one
 * composite over the image. */
static int stroke_coloured(interp *I, image *im, const draw_view *v, const wrinkly_polyline *pl, double width)
{
    size_t np = (size_t)im->w * (size_t)im->h;
    float *cov = calloc(np, sizeof *cov);
    float *col = calloc(np * 4, sizeof *col);
    if (!cov || !col) {
        free(cov);
        free(col);
        return err_at(I, NULL, ERR_MEMORY, "out of memory drawing a curve");
    }
    size_t nseg = pl->n < 2 ? 0 : pl->closed ? pl->n : pl->n - 1;
    double r = width / 2 + 0.5;
    for (size_t s = 0; s < nseg; s++) {
        size_t i = s, j = (s + 1) % pl->n;
        double ax, ay, bx, by;
        draw_to_px(v, pl->xy[2 * i], pl->xy[2 * i + 1], &ax, &ay);
        draw_to_px(v, pl->xy[2 * j], pl->xy[2 * j + 1], &bx, &by);
        float c[4];
        for (int q = 0; q < 4; q++)
            c[q] = 0.5f * (pl->rgba[4 * i + q] + pl->rgba[4 * j + q]);
        int x0 = (int)floor(fmin(ax, bx) - r), x1 = (int)ceil(fmax(ax, bx) + r);
        int y0 = (int)floor(fmin(ay, by) - r), y1 = (int)ceil(fmax(ay, by) + r);
        x0 = x0 < 0 ? 0 : x0;
        y0 = y0 < 0 ? 0 : y0;
        x1 = x1 > im->w - 1 ? im->w - 1 : x1;
        y1 = y1 > im->h - 1 ? im->h - 1 : y1;
        double dx = bx - ax, dy = by - ay, ll = dx * dx + dy * dy;
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++) {
                double px = x + 0.5 - ax, py = y + 0.5 - ay;
                double t = ll > 0 ? (px * dx + py * dy) / ll : 0;
                t = t < 0 ? 0 : t > 1 ? 1 : t;
                double ex = px - t * dx, ey = py - t * dy;
                double k = r - sqrt(ex * ex + ey * ey);
                k = k < 0 ? 0 : k > 1 ? 1 : k;
                size_t id = (size_t)y * (size_t)im->w + (size_t)x;
                if (k > cov[id]) {
                    cov[id] = (float)k;
                    memcpy(col + 4 * id, c, sizeof c);
                }
            }
    }
    for (size_t id = 0; id < np; id++) {
        if (cov[id] <= 0)
            continue;
        float *p = im->px + 4 * id, *c = col + 4 * id;
        float al = c[3] < 0 ? 0 : c[3] > 1 ? 1 : c[3];
        float k = al * cov[id];
        for (int q = 0; q < 3; q++)
            p[q] = p[q] * (1 - k) + c[q] * k;
        p[3] = p[3] + (1 - p[3]) * k;
    }
    free(cov);
    free(col);
    return 0;
}

static int polyline_shape(interp *I, const wrinkly_polyline *pl, int closed, detiter_shape *s)
{
    rt_error e;
    if (detiter_shape_make(s, 2, pl->n, pl->xy, closed ? DETITER_POLYGON : DETITER_POLYLINE, &e))
        return err_at(I, NULL, ERR_MEMORY, "%s", e.msg);
    return 0;
}

