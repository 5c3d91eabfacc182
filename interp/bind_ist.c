/* bind_ist.c — the Iterated Shuffle Transformation (seed 002 §4) in the
 * language: ist objects, F and F^{-1}, the lists L_i^K and the adaptive
 * samples. The reference for scripts is docs/wrinkly.md; the engine is
 * runtime/ist.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "fileio.h"
#include "ist.h"
#include "lang_objects.h"
#include "lang_wrinkly.h"

/* ---- ist objects -------------------------------------------------------------------- */

typedef struct ist_obj {
    ist t;
} ist_obj;

static void ist_destroy(void *p)
{
    ist_obj *o = p;
    ist_free(&o->t);
    rt_free(o);
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
        return lang_num_list_value(I, t->bounds, (size_t)t->n + 1, out);
    else if (strcmp(name, "crossings") == 0) {
        double *m = mem_alloc(I, sizeof(double) * (size_t)t->n);
        if (!m)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        for (int i = 0; i < t->n; i++)
            m[i] = t->ms[i];
        int r = lang_num_list_value(I, m, (size_t)t->n, out);
        mem_free(I, m);
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
    long nint = 5, k;
    double *bounds = NULL;
    int *ms = NULL;
    if (a[4].k != V_NIL) {
        size_t nb = AS_LIST(a[4])->n;
        if (nb < 2 || nb > MAX_CONTROL + 1)
            return err_arg(I, 4, ERR_VALUE, "ist: bounds must be a list of 2 to %d numbers (N + 1 for N intervals), got %zu",
                           MAX_CONTROL + 1, nb);
        if (a[0].k != V_NIL && a[0].u.n + 1 != (double)nb)
            return err_arg(I, 4, ERR_VALUE, "ist: intervals is %g but bounds gives %zu intervals (N + 1 bounds for N intervals)",
                           a[0].u.n, nb - 1);
        nint = (long)nb - 1;
    } else if (a[0].k != V_NIL) {
        nint = (long)a[0].u.n;
    }
    k = (long)a[2].u.n;
    ist_spec s = {.n = (int)nint, .k = (int)k, .axis = a[3].u.b ? IST_CYCLIC : IST_TRANSLATION};
    const char *meth = AS_STR(a[5])->s;
    s.method = strcmp(meth, "lists") == 0 ? IST_LISTS : strcmp(meth, "closed") == 0 ? IST_CLOSED : IST_AUTO;
    int rc = -1;
    if (a[4].k != V_NIL) {
        bounds = mem_alloc(I, sizeof(double) * (size_t)(nint + 1));
        if (!bounds)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        for (long i = 0; i <= nint; i++)
            bounds[i] = AS_LIST(a[4])->items[i].u.n; /* declared vec: finite numbers */
        for (long i = 0; i < nint; i++)
            if (!(bounds[i + 1] > bounds[i])) {
                err_item(I, a[4], (size_t)i + 1, ERR_VALUE,
                         "ist: bounds must increase, but bound %ld = %g is not greater than bound %ld = %g", i + 1,
                         bounds[i + 1], i, bounds[i]);
                goto done;
            }
        s.bounds = bounds;
    }
    if (a[1].k == V_LIST) {
        if (AS_LIST(a[1])->n != (size_t)nint) {
            err_arg(I, 1, ERR_VALUE, "ist: crossings must be one whole number or a list of %ld (one per interval), got %zu",
                    nint, AS_LIST(a[1])->n);
            goto done;
        }
        ms = mem_alloc(I, sizeof(int) * (size_t)nint);
        if (!ms) {
            err_at(I, NULL, ERR_MEMORY, "out of memory");
            goto done;
        }
        for (long i = 0; i < nint; i++) {
            double x = AS_LIST(a[1])->items[i].u.n; /* declared vec[0,1000] */
            if (x != floor(x)) {
                err_item(I, a[1], (size_t)i, ERR_VALUE, "ist: argument 'crossings' item %ld must be a whole number, got %g",
                         i + 1, x);
                goto done;
            }
            ms[i] = (int)x;
        }
        s.m_each = ms;
    } else {
        s.m = (int)a[1].u.n;
    }
    ist_obj *o = mem_calloc(I, 1, sizeof *o);
    if (!o) {
        err_at(I, NULL, ERR_MEMORY, "out of memory");
        goto done;
    }
    /* The list evaluator is used unless the closed form applies: check its
     * memory first (an upper bound: N·(2M+1)^K entries; the hook counts the
     * lists themselves). */
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
            if (mem_precheck(I, est * IST_ENTRY_BYTES, "the IST list evaluator")) {
                mem_free(I, o);
                goto done;
            }
        }
    }
    rt_error e;
    rt_code c = ist_init(&o->t, &s, &e);
    if (c) {
        mem_free(I, o);
        lang_rt_error(I, c, &e, W);
        goto done;
    }
    *out = val_obj(I, &ist_class, o);
    rc = out->k == V_NIL ? -1 : 0;
done:
    mem_free(I, bounds);
    mem_free(I, ms);
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
        if (val_list_push(I, AS_LIST(r), val_num(fwd ? ist_fwd(t, u) : ist_inv(t, u)))) {
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
        if (mem_precheck(I, est * IST_ENTRY_BYTES, "the IST list evaluator"))
            return -1;
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
    int *ki = mem_alloc(I, sizeof(int) * (size_t)t->n);
    if (!ki)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    int rc = -1;
    double *pos = NULL;
    if (a[1].k == V_LIST && AS_LIST(a[1])->n != (size_t)t->n) {
        err_arg(I, 1, ERR_VALUE, "ist_samples: levels must be one whole number or a list of %d (one per interval), got %zu",
                t->n, AS_LIST(a[1])->n);
        goto done;
    }
    double count = 0;
    for (int i = 0; i < t->n; i++) {
        double l = t->k;
        value v = a[1].k == V_LIST ? AS_LIST(a[1])->items[i] : a[1];
        if (v.k != V_NIL)
            l = v.u.n; /* declared: >= 0 */
        if (l != floor(l) || l > t->k) {
            char lw[48] = "";
            if (a[1].k == V_LIST)
                snprintf(lw, sizeof lw, " item %d", i + 1);
            if (a[1].k == V_LIST)
                err_item(I, a[1], (size_t)i, ERR_VALUE,
                         "ist_samples: argument 'levels'%s must be a whole number from 0 to the ist's iterations %d, got %g",
                         lw, t->k, l);
            else
                err_arg(I, 1, ERR_VALUE,
                        "ist_samples: argument 'levels' must be a whole number from 0 to the ist's iterations %d, got %g",
                        t->k, l);
            goto done;
        }
        ki[i] = (int)l;
        count += pow(2.0 * t->ms[i] + 1, (double)l);
    }
    if (count > I->lim.max_list || count > I->lim.max_points) {
        err_at(I, NULL, ERR_LIMIT, "ist_samples: %.0f samples exceed the list limit (raise it with --max-list)", count);
        goto done;
    }
    uint64_t seed;
    if (lang_arg_seed(I, a[3], &seed, "ist_samples"))
        goto done;
    pos = mem_alloc(I, sizeof(double) * ((size_t)count + 1));
    if (!pos) {
        err_at(I, NULL, ERR_MEMORY, "out of memory for %.0f samples", count);
        goto done;
    }
    size_t got = ist_sample_positions(t, ki, a[2].u.b, seed, pos, (size_t)count);
    if (got == (size_t)-1 || got > (size_t)count) {
        err_at(I, NULL, ERR_VALUE, "ist_samples: too many sub-intervals; lower the levels");
        goto done;
    }
    rc = lang_num_list_value(I, pos, got, out);
done:
    mem_free(I, ki);
    mem_free(I, pos);
    return rc;
}

/* ---- registration ---------------------------------------------------------------------- */

/* MAX_CONTROL written out (type texts are literal); IST_MAX_K is a plain
 * number in ist.h, so its text comes from the macro. */
#define TY_STR_(x) #x
#define TY_STR(x) TY_STR_(x)
static const bparam p_ist[] = {{"intervals", "int[1,100000]", "nil"}, {"crossings", "int[0,1000]|vec[0,1000]", "1"},
                               {"iterations", "int[0," TY_STR(IST_MAX_K) "]", "2"},      {"cyclic", "bool", "false"},
                               {"bounds", "vec", "nil"},              {"method", "str{auto,lists,closed}", "\"auto\""}};
static const bparam p_ist_map[] = {{"ist", "ist", NULL}, {"u", "num|vec", NULL}};
static const bparam p_ist_one[] = {{"ist", "ist", NULL}};
static const bparam p_ist_samples[] = {{"ist", "ist", NULL}, {"levels", "int>=0|vec[0,60]", "nil"},
                                       {"jitter", "bool", "false"}, {"seed", "int>=0", "nil"}};

static const builtin ist_builtins[] = {
    BUILTIN("ist", b_ist, p_ist,
            "An Iterated Shuffle Transformation (seed 002 §4.1): N base intervals (default 5, or the N + 1 `bounds`), crossing count M (`crossings`, one number or one per interval), K = `iterations`, on a translation or `cyclic` axis. method: \"auto\", \"lists\" or \"closed\"."),
    BUILTIN("ist_inv", b_ist_inv, p_ist_map,
            "F^{-1}(u) of an ist: the source coordinate whose attributes appear at u (eq. 9); u a number or a list of numbers."),
    BUILTIN("ist_fwd", b_ist_fwd, p_ist_map, "F(u) of an ist: where the source coordinate u is moved to (eq. 6)."),
    BUILTIN("ist_lists", b_ist_lists, p_ist_one,
            "The lists L_i^K of an ist in the notation of the paper's Fig. 2, one line per base interval (\"L5: 322 412 502 | …\"); K <= 9."),
    BUILTIN("ist_samples", b_ist_samples, p_ist_samples,
            "The adaptive sample positions of §5.2: in each base interval the (2M+1)^levels chosen sub-intervals' centres (or a seeded random point with jitter); levels one number or one per interval, default K."),
};

int bind_ist_init(interp *I)
{
    return BUILTIN_REGISTER(I, ist_builtins);
}
