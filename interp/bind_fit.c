/* bind_fit.c — fit(target, maps: …) and the `frac fit` command: an IFS fitted
 * to a picture (runtime/fit.h has the method). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "fileio.h"
#include "fit.h"
#include "fit_cli.h"
#include "lang_ifs.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "report.h"
#include "session.h"

/* "2..6" -> 2, 6; one number "3" -> 3, 3. Returns -1 if malformed. */
static int parse_range(const char *s, int *lo, int *hi)
{
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10), b = a;
    if (end == s || errno)
        return -1;
    if (end[0] == '.' && end[1] == '.') {
        const char *t = end + 2;
        b = strtol(t, &end, 10);
        if (end == t || errno)
            return -1;
    }
    if (*end || a < 1 || b > FIT_MAX_MAPS || a > b)
        return -1;
    *lo = (int)a;
    *hi = (int)b;
    return 0;
}

static ifs *build_ifs(const fit_result *r, ifs *f, rt_error *e)
{
    return ifs_build(f, r->maps, r->n, r->p, IFS_NORMALISE, e) ? NULL : f;
}

/* ---- fit(target, …) ---------------------------------------------------------------------- */

enum { A_TARGET, A_MAPS, A_ITER, A_SEED, A_TIME, A_START, A_RIFS, A_THRESH, A_FG };

static int mask_from_rows(interp *I, value rows, unsigned char **m, int *w, int *h)
{
    vlist *L = AS_LIST(rows);
    if (L->n < 1)
        return err_arg(I, A_TARGET, ERR_VALUE, "fit: a mask needs rows of numbers (a table), got an empty list");
    int cols = -1;
    for (size_t i = 0; i < L->n; i++) {
        value row = L->items[i];
        if (row.k != V_LIST || AS_LIST(row)->n < 1)
            return err_item(I, rows, i, ERR_VALUE, "fit: mask row %zu must be a list of numbers", i + 1);
        if (cols >= 0 && (int)AS_LIST(row)->n != cols)
            return err_item(I, rows, i, ERR_VALUE, "fit: mask row %zu has %zu numbers but row 1 has %d (rows need one length)",
                            i + 1, AS_LIST(row)->n, cols);
        cols = (int)AS_LIST(row)->n;
    }
    *w = cols;
    *h = (int)L->n;
    *m = mem_alloc(I, (size_t)*w * (size_t)*h);
    if (!*m)
        return -1;
    for (int y = 0; y < *h; y++) {
        vlist *row = AS_LIST(L->items[y]);
        for (int x = 0; x < *w; x++) {
            value v = row->items[x];
            if (v.k != V_NUM) {
                mem_free(I, *m);
                return err_item(I, rows, (size_t)y, ERR_TYPE, "fit: mask row %d has a non-number", y + 1);
            }
            (*m)[(size_t)y * *w + x] = v.u.n != 0;
        }
    }
    return 0;
}

static int b_fit(interp *I, value *a, int n, value *out)
{
    (void)n;
    fit_opts o = {.iterations = (long)a[A_ITER].u.n, .nmin = 3, .nmax = 3, .max_points = I->lim.max_points};
    if (a[A_MAPS].k == V_NIL) {
        if (a[A_START].k != V_NIL)
            o.nmin = o.nmax = lang_as_ifs(a[A_START])->f.n;
    } else if (a[A_MAPS].k == V_NUM) {
        o.nmin = o.nmax = (int)a[A_MAPS].u.n;
    } else if (parse_range(AS_STR(a[A_MAPS])->s, &o.nmin, &o.nmax)) {
        return err_arg(I, A_MAPS, ERR_VALUE, "fit: maps must be a count from 1 to %d or a range \"A..B\" (like \"2..6\"), got \"%s\"",
                       FIT_MAX_MAPS, AS_STR(a[A_MAPS])->s);
    }
    o.rifs = val_truthy(a[A_RIFS]);
    if (lang_arg_seed(I, a[A_SEED], &o.seed, "fit"))
        return -1;
    if (a[A_TIME].k == V_NUM)
        o.time_s = a[A_TIME].u.n;
    double cap = I->lim.max_fit_seconds; /* the fuzz harness's work cap covers fit's time budget */
    if (cap > 0 && (o.time_s <= 0 || o.time_s > cap))
        o.time_s = cap;
    affine *start = NULL;
    if (a[A_START].k != V_NIL) {
        const lang_ifs *s = lang_as_ifs(a[A_START]);
        if (s->f.dim != 2)
            return err_arg(I, A_START, ERR_VALUE, "fit: start must be a 2-D IFS, got a %d-D one", s->f.dim);
        if (s->f.n > FIT_MAX_MAPS)
            return err_arg(I, A_START, ERR_VALUE, "fit: start has %d maps (at most %d)", s->f.n, FIT_MAX_MAPS);
        if (o.nmin != s->f.n || o.nmax != s->f.n)
            return err_arg(I, A_START, ERR_VALUE, "fit: start has %d map%s but maps is %d", s->f.n,
                           s->f.n == 1 ? "" : "s", o.nmin);
        start = s->f.maps;
        o.start = start;
        o.nstart = s->f.n;
    }
    unsigned char *m = NULL;
    int w = 0, h = 0;
    const image *im = lang_as_image(a[A_TARGET]);
    if (im) {
        w = im->w;
        h = im->h;
        m = mem_alloc(I, (size_t)w * (size_t)h);
        if (!m)
            return -1;
        static const fit_fg modes[] = {FIT_FG_AUTO, FIT_FG_DARK, FIT_FG_LIGHT, FIT_FG_ALPHA};
        static const char *names[] = {"auto", "dark", "light", "alpha"};
        int mi = 0;
        while (strcmp(names[mi], AS_STR(a[A_FG])->s) != 0)
            mi++; /* declared as a choice */
        fit_mask_from_image(im, modes[mi], a[A_THRESH].u.n, m);
    } else if (mask_from_rows(I, a[A_TARGET], &m, &w, &h)) {
        return -1;
    }
    fit_result r;
    rt_error e;
    rt_run run = lang_run(I);
    double t0 = report_clock();
    rt_code c = fit_run(&(fit_mask){w, h, m}, &o, &run, &r, &e);
    mem_free(I, m);
    if (c)
        return lang_rt_error(I, c, &e, "fit");
    report_work(I, "fit", "points", r.points, t0);
    if (r.rifs) {
        lang_rifs *lr = mem_calloc(I, 1, sizeof *lr);
        if (!lr)
            return -1;
        c = rifs_build(&lr->r, r.maps, r.n, 1, r.P, RIFS_NORMALISE, &e);
        if (c) {
            mem_free(I, lr);
            return lang_rt_error(I, c, &e, "fit");
        }
        *out = val_obj(I, &lang_rifs_class, lr);
        return out->k == V_NIL ? -1 : 0;
    }
    lang_ifs *li = mem_calloc(I, 1, sizeof *li);
    if (!li)
        return -1;
    if (!build_ifs(&r, &li->f, &e)) {
        mem_free(I, li);
        return lang_rt_error(I, e.code, &e, "fit");
    }
    *out = val_obj(I, &lang_ifs_class, li);
    return out->k == V_NIL ? -1 : 0;
}

static const bparam p_fit[] = {
    {"target", "image|list", NULL},         {"maps", "int[1,16]|str", "nil"},
    {"iterations", "int[1,1000000]", "1000"}, {"seed", "int>=0", "nil"},
    {"time", "num>0", "nil"},               {"start", "ifs", "nil"},
    {"rifs", "bool", "false"},              {"threshold", "num[0,1]", "0.5"},
    {"foreground", "str{auto,dark,light,alpha}", "\"auto\""},
};
static const builtin fit_builtins[] = {
    BUILTIN("fit", b_fit, p_fit,
            "An IFS whose attractor draws the target: an image (foreground by threshold on luma or alpha) "
            "or a table of 0/1 rows. Coordinates: the target's pixels normalised to [0, 1]², y up; draw it "
            "with chaos(f, size: [w, h], window: [0, 1, 0, 1]). maps: a count or a range \"2..6\" (a "
            "penalty per map picks the count); iterations: generations of the optimiser (deterministic); "
            "time: a budget in seconds (not deterministic); start: an IFS to refine; rifs: true fits a "
            "Recurrent IFS (which transitions are forbidden) and returns a rifs. See docs/fit.md."),
};

int bind_fit_init(interp *I) { return BUILTIN_REGISTER(I, fit_builtins); }

/* ---- frac fit ---------------------------------------------------------------------------- */

#define FIT_USAGE                                                                                          \
    "usage: frac fit TARGET.png --maps N|A..B [--seed S] [--iterations K] [--time SECONDS] [--rifs]\n"   \
    "        [--foreground auto|dark|light|alpha] [--threshold T] [--threads N] [-q] [-o FIT.frac]"

static int fit_usage(const char *fmt, const char *a)
{
    fprintf(stderr, "frac: fit: ");
    fprintf(stderr, fmt, a);
    fprintf(stderr, "\n(" FIT_USAGE ")\n");
    return 64;
}

static int whole(const char *s, double lo, double hi, double *out)
{
    char *end;
    if (!*s || strspn(s, "0123456789.eE+-") != strlen(s))
        return -1;
    double v = strtod(s, &end);
    if (*end || !isfinite(v) || v != floor(v) || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

/* fit's options that take a value (the next word, or --NAME=VALUE) */
static const char *const fit_valued[] = {"--maps", "--seed", "--iterations", "--time",
                                         "-o", "--threads", "--foreground", "--threshold"};
#define FIT_NVALUED (sizeof fit_valued / sizeof *fit_valued)
/* the other commands' options that take a value: skipped when looking for the word fit,
 * refused by fit */
static const char *const main_valued[] = {"--out-dir", "-e", "-D", "--frames", "--shard", "--delay", "--loop",
                                          "--max-memory", "--max-depth", "--max-pixels", "--max-points",
                                          "--max-voxels", "--max-list", "--fail-alloc"};
#define MAIN_NVALUED (sizeof main_valued / sizeof *main_valued)
/* and the ones that take none */
static const char *const main_flags[] = {"--params", "--no-recipe", "--stats", "--show", "--version"};
#define MAIN_NFLAGS (sizeof main_flags / sizeof *main_flags)

static int in_list(const char *a, const char *const *list, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!strcmp(a, list[i]))
            return 1;
    return 0;
}

int bind_fit_command_index(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--"))
            return 0;
        if (a[0] != '-' || !a[1])
            return strcmp(a, "fit") == 0 ? i : 0;
        if (!strchr(a, '=') && (in_list(a, fit_valued, FIT_NVALUED) || in_list(a, main_valued, MAIN_NVALUED)))
            i++; /* its value */
    }
    return 0;
}
/* The script: the maps as a table in Fractint order (f: the IFS built from them; NULL for a
 * RIFS: the maps and the transition matrix as tables), and a render of the attractor in the
 * target's frame at the target's size, white on black. */
static size_t write_script(char *buf, size_t cap, const char *target, int w, int h, const fit_opts *o,
                           const fit_result *r, const ifs *f, const char *fg)
{
    size_t n = 0;
#define OUT(...) (n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, __VA_ARGS__))
    char name[256];
    size_t k = 0;
    for (const char *p = target; *p && k + 1 < sizeof name; p++)
        name[k++] = (unsigned char)*p < 32 ? '?' : *p;
    name[k] = 0;
    OUT("# An IFS fitted by `frac fit` to %s (%d×%d pixels, foreground %s).\n", name, w, h, fg);
    OUT("# maps %d, seed %llu, iterations %ld; final loss %.4g cells (docs/fit.md).\n", r->n,
        (unsigned long long)o->seed, o->iterations, r->loss);
    if (f) {
        OUT("# Coordinates: the target's pixels normalised to [0, 1]², y up. Rows: a b c d e f p.\n");
        OUT("let fitted = ifs({\n");
        for (int i = 0; i < f->n; i++) {
            const affine *a = &f->maps[i];
            OUT("  %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", a->m[0][0], a->m[0][1], a->m[1][0], a->m[1][1], a->t[0],
                a->t[1], f->p[i]);
        }
        OUT("}, normalize: true)\n");
    } else {
        OUT("# A Recurrent IFS: map rows a b c d e f, then the transition matrix (row i: the\n");
        OUT("# probabilities of the next map after map i; 0 = forbidden). Coordinates: the\n");
        OUT("# target's pixels normalised to [0, 1]², y up.\n");
        OUT("let fitted = rifs({\n");
        for (int i = 0; i < r->n; i++) {
            const affine *a = &r->maps[i];
            OUT("  %.9g %.9g %.9g %.9g %.9g %.9g\n", a->m[0][0], a->m[0][1], a->m[1][0], a->m[1][1], a->t[0], a->t[1]);
        }
        OUT("}, {\n");
        for (int i = 0; i < r->n; i++) {
            OUT(" ");
            for (int j = 0; j < r->n; j++)
                OUT(" %.9g", r->P[i * r->n + j]);
            OUT("\n");
        }
        OUT("}, normalize: true)\n");
    }
    double pts = 40.0 * w * h;
    pts = pts < 1e5 ? 1e5 : pts > 5e7 ? 5e7 : pts;
    OUT("save(chaos(fitted, points: %.0f, size: [%d, %d], window: [0, 1, 0, 1], curve: \"linear\",\n", pts, w, h);
    OUT("           brightness: 1e9), \"fit.png\")\n");
#undef OUT
    return n;
}

int bind_fit_command(interp *I, int argc, char **argv, int at, volatile sig_atomic_t *cancel)
{
    const char *target = NULL, *outp = "fit.frac", *maps = NULL, *fgname = "auto";
    fit_opts o = {.iterations = 1000, .seed = I->seed};
    double thresh = 0.5;
    int quiet = 0, given[FIT_NVALUED] = {0};
    for (int i = 1; i < argc; i++) {
        if (i == at)
            continue;
        const char *a = argv[i];
        if (a[0] != '-' || !a[1]) {
            if (target)
                return fit_usage("takes one target picture (got '%s' too)", a);
            target = a;
            continue;
        }
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(FIT_USAGE "\n(docs/fit.md)\n", stdout);
            return 0;
        }
        if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
            continue;
        }
        if (!strcmp(a, "--rifs")) {
            if (o.rifs)
                return fit_usage("%s is given twice", a);
            o.rifs = 1;
            continue;
        }
        /* --NAME=VALUE or --NAME VALUE */
        char name[32];
        const char *eq = a[1] == '-' ? strchr(a, '=') : NULL, *v = NULL;
        snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - a) : (int)strlen(a), a);
        size_t f = 0;
        while (f < FIT_NVALUED && strcmp(name, fit_valued[f]) != 0)
            f++;
        if (f == FIT_NVALUED) {
            if (in_list(name, main_valued, MAIN_NVALUED) || in_list(name, main_flags, MAIN_NFLAGS) ||
                !strncmp(name, "-D", 2))
                return fit_usage("%s does not go with `frac fit`", !strncmp(name, "-D", 2) ? "-D" : name);
            return fit_usage("unknown option '%s'", a);
        }
        if (eq) {
            v = eq + 1;
        } else {
            if (i + 1 >= argc || i + 1 == at)
                return fit_usage("%s needs a value", a);
            v = argv[++i];
        }
        if (given[f]++)
            return fit_usage("%s is given twice", name);
        double d;
        switch (f) {
        case 0: maps = v; break;
        case 1:
            if (whole(v, 0, 9007199254740992.0, &d))
                return fit_usage("--seed takes a whole number from 0 to 2^53, got '%s'", v);
            o.seed = (uint64_t)d;
            break;
        case 2:
            if (whole(v, 1, 1e6, &d))
                return fit_usage("--iterations takes a whole number from 1 to 1000000, got '%s'", v);
            o.iterations = (long)d;
            break;
        case 3: {
            char *end;
            d = strtod(v, &end);
            if (end == v || *end || !isfinite(d) || d <= 0)
                return fit_usage("--time takes a number of seconds > 0, got '%s'", v);
            o.time_s = d;
            break;
        }
        case 4:
            if (!*v)
                return fit_usage("%s", "-o needs a file name (the script to write)");
            outp = v;
            break;
        case 5:
            if (whole(v, 1, 256, &d))
                return fit_usage("--threads takes a whole number from 1 to 256, got '%s'", v);
            I->threads = (int)d;
            break;
        case 6:
            if (strcmp(v, "auto") && strcmp(v, "dark") && strcmp(v, "light") && strcmp(v, "alpha"))
                return fit_usage("--foreground takes auto, dark, light or alpha, got '%s'", v);
            fgname = v;
            break;
        case 7: {
            char *end;
            d = strtod(v, &end);
            if (end == v || *end || !(d >= 0 && d <= 1))
                return fit_usage("--threshold takes a number from 0 to 1, got '%s'", v);
            thresh = d;
            break;
        }
        }
    }
    if (!target)
        return fit_usage("%s", "needs a target picture (frac fit TARGET.png --maps N)");
    if (!maps)
        return fit_usage("%s", "needs --maps N (a count from 1 to 16, or a range like 2..6)");
    if (parse_range(maps, &o.nmin, &o.nmax))
        return fit_usage("--maps takes a count from 1 to 16 or a range A..B like 2..6, got '%s'", maps);
    image im = {0};
    rt_error e;
    rt_code c = image_load(&im, target, &e);
    if (c) {
        err_pos(I, -1, 0, 0, lang_rt_kind(c), "fit: %s", e.msg);
        return session_report(I);
    }
    unsigned char *m = rt_malloc((size_t)im.w * (size_t)im.h);
    if (!m) {
        image_free(&im);
        err_pos(I, -1, 0, 0, ERR_MEMORY, "fit: out of memory");
        return session_report(I);
    }
    fit_fg mode = !strcmp(fgname, "dark") ? FIT_FG_DARK : !strcmp(fgname, "light") ? FIT_FG_LIGHT
                  : !strcmp(fgname, "alpha") ? FIT_FG_ALPHA : FIT_FG_AUTO;
    mode = fit_mask_from_image(&im, mode, thresh, m);
    static const char *fgnames[] = {"auto", "dark", "light", "alpha"};
    rt_run run = {.threads = I->threads > 0 ? I->threads : 1, .cancel = cancel, .progress = !quiet};
    fit_result r;
    int w = im.w, h = im.h;
    image_free(&im);
    c = fit_run(&(fit_mask){w, h, m}, &o, &run, &r, &e);
    rt_free(m);
    ifs f = {0};
    if (!c && !r.rifs && !build_ifs(&r, &f, &e))
        c = e.code;
    if (c) {
        err_pos(I, -1, 0, 0, lang_rt_kind(c), "fit: %s: %s", target, e.msg);
        return session_report(I);
    }
    char buf[8192];
    size_t len = write_script(buf, sizeof buf, target, w, h, &o, &r, r.rifs ? NULL : &f, fgnames[mode]);
    if (!r.rifs)
        ifs_free(&f);
    c = len < sizeof buf ? fileio_write_atomic(outp, buf, len, &e) : rt_fail(&e, RT_ENOMEM, "script too long");
    if (c) {
        err_pos(I, -1, 0, 0, lang_rt_kind(c), "fit: %s", e.msg);
        return session_report(I);
    }
    if (!quiet)
        fprintf(stderr, "wrote %s (%d maps%s, loss %.4g)\n", outp, r.n, r.rifs ? ", recurrent" : "", r.loss);
    return 0;
}
