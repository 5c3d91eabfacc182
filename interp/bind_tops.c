/* bind_tops.c — fractal tops, colour stealing and the fractal filter in the
 * language (seed 004 §3, §4, §6; engine tops.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "fileio.h"
#include "fset.h"
#include "lang_fset.h"
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "tops.h"
#include "report.h"

/* ---- fractal tops and colour stealing ---------------------------------------------------- */

static fset_ifs ifs_view(const lang_ifs *li) { return (fset_ifs){li->f.n, li->f.maps, li->f.p}; }

/* The view of an IFS's attractor (fitted by chaos_fit) or of a window. */
static int ifs_window(interp *I, const lang_ifs *li, value window, int w, int h, uint64_t seed, double lo[2],
                      double hi[2], const char *what)
{
    if (window.k != V_NIL) {
        char wn[64];
        snprintf(wn, sizeof wn, "%s", what);
        return lang_window_arg(I, window, lo, hi, wn);
    }
    if (li->f.dim != 2)
        return err_at(I, NULL, ERR_VALUE, "%s: the IFS is 3-D; fractal tops and colour stealing need 2-D maps", what);
    chaos_sys s = {&li->f, NULL};
    chaos_opts o;
    memset(&o, 0, sizeof o);
    o.seed = seed;
    o.points = 100000;
    rt_error e;
    rt_code c = lang_chaos_fit_call(I, &s, &o, w, h, lo, hi, &e);
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
    if (lang_arg_size2(I, a[1], &w, &h, "top: size") || lang_points_arg(I, a[2], &to.points, "top") ||
        lang_get_ramp(I, a[4], &r, "top: palette") || lang_get_colour(I, a[7], bg, "top: background") ||
        lang_arg_seed(I, a[8], &to.seed, "top"))
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
    double t0 = report_clock();
    rt_code c = draw_view_fit(&view, w, h, lo, hi, 1, &e);
    if (!c)
        c = tops_run(&f, &view, &to, &tb, &run, &e);
    if (c)
        return lang_rt_error(I, c, &e, "top");
    report_work(I, "fractal top", "points", (double)to.points, t0);
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
    if (lang_arg_size2(I, a[k], &s->w, &s->h, wn) || lang_points_arg(I, a[k + 1], &s->to.points, what))
        return -1;
    snprintf(wn, sizeof wn, "%s: background", what);
    if (lang_get_colour(I, a[k + 4], s->bg, wn))
        return -1;
    s->to.depth = (int)a[k + 5].u.n; /* declared int[0,64] */
    if (lang_arg_seed(I, a[k + 6], &s->to.seed, what))
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
    double t0 = report_clock();
    rt_code c = draw_view_fit(&sv, s.w, s.h, s.lo, s.hi, 1, &e);
    if (!c)
        c = draw_view_fit(&srcv, pic->w, pic->h, s.slo, s.shi, 0, &e);
    if (!c)
        c = tops_steal(&s.f, &sv, &s.g, &srcv, &s.to, &tb, &run, &e);
    if (c)
        return lang_rt_error(I, c, &e, "steal");
    report_work(I, "colour stealing", "points", (double)s.to.points, t0);
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
    double t0 = report_clock();
    rt_code c = !res ? rt_fail(&e, RT_ENOMEM, "out of memory") : draw_view_fit(&sv, s.w, s.h, s.lo, s.hi, 1, &e);
    if (!c && l.k != V_NIL)
        c = tops_filter(&s.f, &sv, &s.g, s.slo, s.shi, frames, (int)fl->n, &s.to, s.bg, res, &run, &e);
    if (!c && l.k != V_NIL)
        report_work(I, "fractal filter", "points", (double)s.to.points, t0);
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
        if (lang_image_value(I, im, &v) || val_list_push(I, AS_LIST(l), v)) {
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

/* ---- registration ---------------------------------------------------------------------- */

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

static const builtin tops_builtins[] = {
    BUILTIN("top", b_top, p_top,
            "The fractal top of a 2-D IFS (seed 004 §3): every pixel coloured by the first symbols of the greatest address among the points that fall in it, through the palette."),
    BUILTIN("steal", b_steal, p_steal,
            "Colour stealing (seed 004 §4): the screen IFS draws its fractal top while the source IFS, with the same number of maps and the same random indices, walks over the picture; each pixel takes the colour of the source pixel its top point stole. source_window: the part of the source IFS's plane the picture covers (default: its fitted attractor)."),
    BUILTIN("fractal_filter", b_fractal_filter, p_filter,
            "The fractal filter (seed 004 §6): colour stealing with one top applied to every frame of a list of images of one size; a list of images."),
};

int bind_tops_init(interp *I)
{
    return BUILTIN_REGISTER(I, tops_builtins);
}
