/* bind_fset.c — iterated function sets and orders in the language, and the
 * chaos game of a function set (seed 003; engines fset.h, hist.h,
 * tonemap.h).
 *
 * Classes: "fset" (a function set {W1 .. WN}, each W an IFS) and "order"
 * (which W each step uses). Set indices are 1-based in scripts (W1 is the
 * first set), 0-based in C. The readers shared with the shape, fractal-top
 * and super-IFS bindings are declared in lang_fset.h.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "fileio.h"
#include "fset.h"
#include "hist.h"
#include "lang_fset.h"
#include "par.h"
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lexer.h"
#include "tonemap.h"
#include "report.h"
#include "shard.h"

/* ---- function sets ---------------------------------------------------------------------- */

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

lang_fset *lang_as_fset(value v)
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
int lang_get_fset(interp *I, value v, int list_is_sets, value *out, const char *what)
{
    if (lang_as_fset(v)) {
        val_ref(v);
        *out = v;
        return 0;
    }
    int one = lang_as_ifs(v) != NULL || !list_is_sets;
    /* a table (rows of numbers) or a list of maps is one IFS, not a list of sets */
    if (!one && v.k == V_LIST && AS_LIST(v)->n > 0) {
        value f0 = AS_LIST(v)->items[0];
        if ((f0.k == V_LIST && AS_LIST(f0)->n > 0 && AS_LIST(f0)->items[0].k == V_NUM) ||
            (f0.k == V_OBJ && AS_OBJ(f0)->cls == &lang_map_class))
            one = 1;
    }
    if (!one && v.k != V_LIST)
        return err_value(I, v, ERR_TYPE, "%s must be a list of IFSs (ifs values or tables), got %s", what,
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
    return lang_get_fset(I, a[0], 1, out, "fset");
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
            if (val_list_push(I, AS_LIST(l), val_num(o->seq[i] + 1))) {
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
        if (builtin_get_vec(I, pr, o->p, np, "order: probabilities") || lang_arg_seed(I, a[3], &o->o.seed, "order")) {
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
                        val_fmt_number(x.u.n, got, sizeof got);
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
int lang_order_arg(interp *I, value v, int slot, int nsets, fset_order *o, int **tmp, const char *what)
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

/* ---- chaos game with a function set ------------------------------------------------------- */

/* points: declared int>=1; the limit is the session's. */
int lang_points_arg(interp *I, value v, uint64_t *out, const char *what)
{
    if (v.u.n > I->lim.max_points)
        return err_at(I, NULL, ERR_LIMIT, "%s: %.0f points exceed the limit of %.0f (raise it with --max-points)", what,
                      v.u.n, I->lim.max_points);
    *out = (uint64_t)v.u.n;
    return 0;
}

int lang_window_arg(interp *I, value v, double lo[2], double hi[2], const char *what)
{
    double win[4];
    if (builtin_get_vec(I, v, win, 4, what))
        return -1;
    lo[0] = win[0];
    hi[0] = win[1];
    lo[1] = win[2];
    hi[1] = win[3];
    if (!(hi[0] > lo[0]) || !(hi[1] > lo[1]))
        return err_item(I, v, SIZE_MAX, ERR_VALUE, "%s is [xmin, xmax, ymin, ymax] with min < max", what);
    return 0;
}

/* Tone-mapping arguments shared by chaos_fset and superifs_image. */
int lang_tone_args(interp *I, value palette, value curve, value gamma, value bright, value bg, tonemap_opts *t,
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

/* chaos_fset of a 3-D set: the nearest point per pixel through a camera
 * (default: framing(…) of the game's fitted box) */
static int chaos_fset_view(interp *I, const lang_fset *f, const fset_order *o, const fset_chaos_opts *co, value camv,
                           value sizev, value bgv, value *out)
{
    int w, h;
    float bg[4];
    camera cam;
    rt_error e;
    rt_code c;
    if (lang_arg_size2(I, sizev, &w, &h, "chaos_fset: size") || lang_get_colour(I, bgv, bg, "chaos_fset: background"))
        return -1;
    if (camv.k != V_NIL) {
        if (lang_get_camera(I, camv, &cam, "chaos_fset"))
            return -1;
    } else {
        double lo[3], hi[3];
        if (!shard_window_take(I, 3, lo, hi)) { /* merge: the box the shards fitted */
            if ((c = fset_chaos_box(&f->fs, o, co, lo, hi, &e)))
                return lang_rt_error(I, c, &e, "chaos_fset");
            shard_window_put(I, 3, lo, hi);
        }
        if (lang_frame_default(I, lo, hi, w, h, &cam, "chaos_fset: cannot frame the set (its box is not finite)"))
            return -1;
    }
    image *im;
    if (lang_depth_image(I, w, h, 8, "chaos_fset", &im))
        return -1;
    rt_run run = lang_run(I);
    c = fset_chaos_view(&f->fs, o, co, &cam, bg, im, &run, &e);
    return lang_image_finish(I, im, c, &e, "chaos_fset", out);
}

/* chaos_fset(system, order, points, size, window, mode, depth, burn, start,
 *            palette, curve, gamma, brightness, background, seed) */
static int b_chaos_fset(interp *I, value *a, int n, value *out)
{
    (void)n;
    value fv;
    if (lang_get_fset(I, a[0], 1, &fv, "chaos_fset: system"))
        return -1;
    const lang_fset *f = lang_as_fset(fv);
    int rc = -1, *tmp = NULL;
    fset_order o;
    fset_chaos_opts co;
    memset(&co, 0, sizeof co);
    int w, h;
    ramp r;
    tonemap_opts t;
    long depth;
    if (lang_order_arg(I, a[1], 1, f->n, &o, &tmp, "chaos_fset"))
        goto done;
    if (lang_points_arg(I, a[2], &co.points, "chaos_fset") || lang_arg_size2(I, a[3], &w, &h, "chaos_fset: size") ||
        lang_tone_args(I, a[9], a[10], a[11], a[12], a[13], &t, &r, "chaos_fset") || lang_arg_seed(I, a[14], &co.seed, "chaos_fset") ||
        builtin_get_vec(I, a[8], co.start, AS_LIST(a[8])->n, "chaos_fset: start"))
        goto done;
    if (f->dim == 2 && AS_LIST(a[8])->n != 2) {
        err_arg(I, 8, ERR_VALUE, "chaos_fset: start of a 2-D function set is [x, y]");
        goto done;
    }
    if (f->dim == 2 && a[15].k != V_NIL) {
        err_arg(I, 15, ERR_VALUE, "chaos_fset: camera applies to a 3-D function set (a 2-D one is drawn in a window)");
        goto done;
    }
    if (f->dim == 3 && a[4].k != V_NIL) {
        err_arg(I, 4, ERR_VALUE, "chaos_fset: window applies to a 2-D function set (a 3-D one is seen through camera:)");
        goto done;
    }
    if (f->dim == 3 && a[9].k != V_NIL) {
        err_arg(I, 9, ERR_VALUE, "chaos_fset: palette applies to a 2-D function set (a 3-D one is shaded by depth)");
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
    if (f->dim == 3) {
        rc = chaos_fset_view(I, f, &o, &co, a[15], a[3], a[13], out);
        goto done;
    }
    if (a[4].k != V_NIL) {
        if (lang_window_arg(I, a[4], lo, hi, "chaos_fset: window"))
            goto done;
    } else if (!shard_window_take(I, 2, lo, hi)) { /* in a merge, the window the shards fitted */
        if ((c = fset_order_validate(&o, f->n, &e)) || (c = fset_chaos_fit(&f->fs, &o, &co, w, h, lo, hi, &run, &e))) {
            lang_rt_error(I, c, &e, "chaos_fset");
            goto done;
        }
        shard_window_put(I, 2, lo, hi);
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
    c = hist2_init_for(&hs, w, h, lo, hi, 0, co.points, &e);
    if (!c) {
        double t0 = report_clock();
        c = fset_chaos(&f->fs, &o, &co, &hs, &run, &e);
        if (!c)
            report_work(I, "chaos game", "points", (double)co.points, t0);
        if (!c && !lang_image_new(I, w, h, &im))
            c = tonemap_defer(&hs, &t, im, &e); /* pixels pending until read (tonemap.h) */
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


/* ---- registration ---------------------------------------------------------------------- */

static const bparam p_fset[] = {{"sets", "list", NULL}};
static const bparam p_order[] = {{"sequence", "list|str", "nil"},
                                 {"repeat", "bool", "false"},
                                 {"probabilities", "vec[0,1]", "nil"},
                                 {"seed", "int>=0", "nil"}};
#define TY_CURVE "str{log,linear}"
static const bparam p_chaos_fset[] = {{"system", "fset|ifs|list", NULL},   {"order", "order", "nil"},
                                      {"points", "int>=1", "1e6"},          {"size", TY_SIZE, "[512, 512]"},
                                      {"window", "vec4", "nil"},            {"mode", "str{orbit,walk}", "\"orbit\""},
                                      {"depth", "int[1,1000000]", "nil"},   {"burn", "int[0,1000000]", "20"},
                                      {"start", "vec2|vec3", "[0, 0]"},     {"palette", "list", "nil"},
                                      {"curve", TY_CURVE, "\"log\""},       {"gamma", "num>0", "2.2"},
                                      {"brightness", "num>0", "1"},         {"background", TY_COLOUR, "[0, 0, 0, 1]"},
                                      {"seed", "int>=0", "nil"},            {"camera", TY_CAMERA, "nil"}};

static const builtin fset_builtins[] = {
    BUILTIN("fset", b_fset, p_fset,
            "A function set {W1, …, WN} (seed 003 def. 3.1): a list of IFSs, each an ifs value or a table of map rows. Sets are numbered from 1 (W1) as in the paper."),
    BUILTIN("order", b_order, p_order,
            "Which set each step uses: order([1, 2, 1, 2]) lists set numbers in application order (the first is applied first, to K0); order(\"W2 ∘ W1 ∘ W2 ∘ W1\") is the paper's composition notation (rightmost applied first); repeat: true cycles the sequence; order(probabilities: [p1, …], seed:) picks W_n with probability p_n at every step (seed 003 def. 3.2)."),
    BUILTIN("chaos_fset", b_chaos_fset, p_chaos_fset,
            "The chaos game of a function set with an order, tone-mapped like chaos(…). mode \"orbit\": one long orbit per chunk; with a sequence or periodic order a point is plotted after each full period (the attractor of the composition); with a random order after every step. mode \"walk\": every point is the end of a fresh walk of depth steps from start (a sample of K_depth). A 3-D set is seen through camera (default: framed as framing(…) does), nearest point per pixel shaded by depth, as view(…)."),
};

int bind_fset_init(interp *I)
{
    return BUILTIN_REGISTER(I, fset_builtins);
}
