/* bind_superifs.c — V-variable super IFS in the language (seed 004 §5;
 * engine superifs.h).
 *
 * Class "superifs": the V buffers of a super IFS after some steps.
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
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "superifs.h"
#include "tonemap.h"
#include "report.h"
#include "shard.h"

/* ---- super IFS ------------------------------------------------------------------------- */

/* The points are computed when superifs_image first needs them (the
 * engine call, split across shards: superifs.h), so a script may print a
 * super IFS, its V, points, steps and ifs (all from the draws) in a shard
 * without making its points a result the shard must have whole. */
typedef struct lang_superifs {
    fset fs;           /* a copy of the sets (sets, maps, p in mem) */
    double *P;         /* N, or NULL */
    superifs_opts so;
    void *mem;
    int *ifs_of;       /* V: the IFS of each buffer at the last step */
    superifs_state st; /* st.pts NULL until computed */
    long part;         /* a shard: the split engine call whose share only st holds; -1 */
    const node *part_at; /* where that call was made */
    int nifs;
    uint64_t steps;
} lang_superifs;

static void superifs_destroy(void *pp)
{
    lang_superifs *s = pp;
    superifs_free(&s->st);
    rt_free(s->mem);
    rt_free(s->P);
    rt_free(s->ifs_of);
    rt_free(s);
}

/* Copy the sets into one block that s owns. */
static int copy_sets(lang_superifs *s, const fset *fs)
{
    size_t bytes = (size_t)fs->n * sizeof(fset_ifs);
    for (int k = 0; k < fs->n; k++)
        bytes += (size_t)fs->sets[k].n * (sizeof(affine) + sizeof(double));
    unsigned char *m = rt_malloc(bytes);
    if (!m)
        return -1;
    fset_ifs *sets = (fset_ifs *)m;
    unsigned char *p = m + (size_t)fs->n * sizeof(fset_ifs);
    for (int k = 0; k < fs->n; k++) {
        size_t n = (size_t)fs->sets[k].n;
        affine *maps = (affine *)p;
        memcpy(maps, fs->sets[k].maps, n * sizeof(affine));
        p += n * sizeof(affine);
        double *pr = NULL;
        if (fs->sets[k].p) {
            pr = (double *)p;
            memcpy(pr, fs->sets[k].p, n * sizeof(double));
        }
        p += n * sizeof(double);
        sets[k] = (fset_ifs){(int)n, maps, pr};
    }
    s->mem = m;
    s->fs = (fset){fs->n, sets};
    return 0;
}

static void superifs_summary(const void *pp, bytebuf *out)
{
    const lang_superifs *s = pp;
    bytebuf_printf(out, "superifs: V = %d buffers of %zu points, %d IFSs, %llu steps; last step used", s->so.V,
                   s->so.points, s->nifs, (unsigned long long)s->steps);
    for (int v = 0; v < s->so.V && v < 16; v++) {
        if (s->ifs_of[v] < 0)
            bytebuf_printf(out, " -");
        else
            bytebuf_printf(out, " F%d", s->ifs_of[v] + 1);
    }
    if (s->so.V > 16)
        bytebuf_printf(out, " …");
}

/* s.ifs[v]: the IFS (1-based) buffer v took at the last step, nil if none */
static int ifs_value(interp *I, const void *pp, size_t v, value *out)
{
    (void)I;
    const lang_superifs *s = pp;
    *out = s->ifs_of[v] < 0 ? val_nil() : val_num(s->ifs_of[v] + 1);
    return 0;
}

static int superifs_get(interp *I, const void *pp, const char *name, value *out)
{
    const lang_superifs *s = pp;
    if (strcmp(name, "V") == 0)
        *out = val_num(s->so.V);
    else if (strcmp(name, "points") == 0)
        *out = val_num((double)s->so.points);
    else if (strcmp(name, "steps") == 0)
        *out = val_num((double)s->steps);
    else if (strcmp(name, "ifs") == 0) {
        return val_list_build(I, (size_t)s->so.V, ifs_value, s, out);
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
    if (lang_get_fset(I, a[0], 1, &fv, "superifs: sets"))
        return -1;
    const lang_fset *f = lang_as_fset(fv);
    int rc = -1;
    double *P = NULL;
    superifs_opts so;
    memset(&so, 0, sizeof so);
    long V = (long)a[2].u.n, steps = (long)a[4].u.n; /* declared int[1,1024], int[0,100000] */
    uint64_t pts = 0;
    if (lang_points_arg(I, a[3], &pts, "superifs") || builtin_get_vec(I, a[5], so.start, 2, "superifs: start") ||
        lang_arg_seed(I, a[6], &so.seed, "superifs"))
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
        if (builtin_get_vec(I, a[1], P, np, "superifs: probabilities"))
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
    rt_error e;
    rt_code c = superifs_check(&f->fs, P, &so, &e); /* the errors of the run, here where they were made */
    if (c) {
        lang_rt_error(I, c, &e, "superifs");
        goto done;
    }
    lang_superifs *ls = mem_calloc(I, 1, sizeof *ls);
    if (!ls || copy_sets(ls, &f->fs) || !(ls->ifs_of = rt_malloc((size_t)V * sizeof *ls->ifs_of))) {
        if (ls)
            superifs_destroy(ls);
        err_at(I, NULL, ERR_MEMORY, "out of memory");
        goto done;
    }
    ls->P = P; /* ls owns it */
    P = NULL;
    ls->so = so;
    ls->part = -1;
    superifs_last_ifs(&ls->fs, ls->P, &ls->so, ls->ifs_of);
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
    lang_superifs *s = AS_OBJ(a[0])->payload;
    long buf = (long)a[1].u.n; /* declared int>=1 */
    int w, h;
    ramp r;
    tonemap_opts t;
    if (buf > s->so.V)
        return err_arg(I, 1, ERR_VALUE, "superifs_image: buffer must be between 1 and V = %d, got %ld", s->so.V, buf);
    if (lang_arg_size2(I, a[2], &w, &h, "superifs_image: size") ||
        lang_tone_args(I, a[4], a[5], a[6], a[7], a[8], &t, &r, "superifs_image"))
        return -1;
    double lo[2], hi[2];
    if (a[3].k != V_NIL && lang_window_arg(I, a[3], lo, hi, "superifs_image: window"))
        return -1;
    if ((double)w * h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT, "superifs_image: %d×%d pixels exceed the pixel limit (raise it with --max-pixels)", w, h);
    rt_error e;
    rt_code c;
    if (!s->st.pts) { /* the points: the engine call (split in a shard) */
        rt_run run = lang_run(I);
        double t0 = report_clock();
        if ((c = superifs_run(&s->fs, s->P, &s->so, &s->st, &run, &e)))
            return lang_rt_error(I, c, &e, "superifs_image");
        report_work(I, "super IFS", "points", (double)s->so.points * (double)s->so.V, t0);
        s->part = shard_pending_call(I, &s->part_at);
    } else if (s->part >= 0) {
        shard_pend_again(I, s->part, s->part_at); /* drawn from a shard's points: a partial result of that call */
    }
    if (s->part >= 0) { /* a shard: the result becomes a partial value (shard.h) */
        *out = val_nil();
        return 0;
    }
    if (a[3].k == V_NIL) {
        if (superifs_bounds(&s->st, lo, hi)) /* all buffers: every buffer is drawn at one scale */
            return err_at(I, NULL, ERR_VALUE, "superifs_image: the buffers hold no finite points; give window:");
        fset_fit_aspect(lo, hi, w, h, 0.03);
    }
    hist2 hs;
    image *im = NULL;
    c = hist2_init_for(&hs, w, h, lo, hi, 0, s->st.points, &e); /* one buffer's points */
    if (c)
        return lang_rt_error(I, c, &e, "superifs_image");
    c = superifs_render(&s->st, (int)buf - 1, &hs, &e);
    if (!c && !lang_image_new(I, w, h, &im))
        c = tonemap_defer(&hs, &t, im, &e); /* pixels pending until read (tonemap.h) */
    hist2_free(&hs);
    if (c || !im) {
        lang_image_discard(im);
        return I->err.active ? -1 : lang_rt_error(I, c, &e, "superifs_image");
    }
    return lang_image_value(I, im, out);
}

/* ---- registration ---------------------------------------------------------------------- */

#define TY_CURVE "str{log,linear}"
static const bparam p_superifs[] = {{"sets", "list|fset", NULL},   {"probabilities", "vec[0,1]", "nil"},
                                    {"V", "int[1,1024]", "3"},     {"points", "int>=1", "1e5"},
                                    {"steps", "int[0,100000]", "20"}, {"start", "vec2", "[0, 0]"},
                                    {"seed", "int>=0", "nil"}};
static const bparam p_superifs_image[] = {{"superifs", "superifs", NULL},   {"buffer", "int>=1", "1"},
                                          {"size", TY_SIZE, "[512, 512]"},  {"window", "vec4", "nil"},
                                          {"palette", "list", "nil"},       {"curve", TY_CURVE, "\"log\""},
                                          {"gamma", "num>0", "2.2"},        {"brightness", "num>0", "1"},
                                          {"background", TY_COLOUR, "[0, 0, 0, 1]"}};

static const builtin superifs_builtins[] = {
    BUILTIN("superifs", b_superifs, p_superifs,
            "A V-variable super IFS (seed 004 §5): V buffers of points, each step replacing every buffer by the union of the maps of a randomly chosen IFS applied to randomly chosen buffers. sets: a list of IFSs or an fset; probabilities: of choosing each IFS (default equal). V = 1 is Asai's random function set."),
    BUILTIN("superifs_image", b_superifs_image, p_superifs_image,
            "An image of one buffer (1 .. V) of a super IFS, tone-mapped like chaos(…); the default window covers all buffers so they share one scale."),
};

int bind_superifs_init(interp *I)
{
    return BUILTIN_REGISTER(I, superifs_builtins);
}
