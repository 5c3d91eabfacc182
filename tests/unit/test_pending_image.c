/* test_pending_image.c — an image whose pixels are pending (image.h's
 * image_src: a chaos render's tone map, tonemap_defer) gives every consumer
 * the same pixels as the same render made ready first (issue 15).
 *
 * For every registered builtin that can take an image — a parameter typed
 * `image` or `any`, variadic, or a list parameter of a builtin whose
 * documentation speaks of images — the table below must hold at least one
 * case (a new builtin fails the test until it has one). Each case runs
 * twice per producer (chaos, plain and with colour and supersampling;
 * chaos_fset; superifs_image), in one REPL-like
 * session: the producer's render is bound to IM, then
 *   - pending: the case runs on IM as it is;
 *   - ready:   the harness first fills IM's pixels itself from the source's
 *              rows (not through image_ready, so a broken image_ready shows)
 *              and drops the source;
 * and stdout, the error (if any) and every file the case wrote (PFM: the
 * floats exactly; 16-bit PNG: alpha too) must be identical. The renders are
 * checked to have both background and lit pixels, so zeros cannot pass.
 *
 * Linked with the interpreter's objects (Makefile: as the fuzz harness). */
#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "builtin.h"
#include "check.h"
#include "image.h"
#include "lang_image.h"
#include "session.h"
#include "state.h"
#include "test_session.h"

typedef struct pcase {
    const char *builtin; /* the builtin the case is for */
    const char *body;    /* IM: the image under test; J: a plain image; out(r): record r */
    int fails;           /* the call is an error (the same one either way) */
} pcase;

/* out(r) saves an image (PFM and 16-bit RGBA PNG), a list item by item, and
 * prints anything else. */
static const pcase cases[] = {
    {"sqrt", "out(sqrt(IM))", 0},
    {"exp", "out(exp(IM))", 0},
    {"log", "out(log(IM + 1))", 0},
    {"sin", "out(sin(IM))", 0},
    {"cos", "out(cos(IM))", 0},
    {"tan", "out(tan(IM))", 0},
    {"asin", "out(asin(IM * 0.5))", 0},
    {"acos", "out(acos(IM * 0.5))", 0},
    {"atan", "out(atan(IM))", 0},
    {"abs", "out(abs(IM - 0.5))", 0},
    {"floor", "out(floor(IM * 3))", 0},
    {"ceil", "out(ceil(IM * 3))", 0},
    {"round", "out(round(IM * 3))", 0},
    {"sign", "out(sign(IM - 0.5))", 0},
    {"pow", "out(pow(IM, 2))", 0},
    {"pow", "out(pow(2, IM))", 0},
    {"min", "out(min(IM, 0.5))", 0},
    {"max", "out(max(J, IM))", 0},
    {"clamp", "out(clamp(IM, 0.2, 0.8))", 0},
    {"lerp", "out(lerp(IM, J, 0.25))", 0},
    {"lerp", "out(lerp(J, 1, IM))", 0},
    {"len", "out(len([IM, IM]))", 0},
    {"repeat", "out(repeat(IM, 2))", 0},
    {"str", "out(str(IM))", 0},
    {"format", "out(format(\"{} {}\", IM, pixel(IM, 8, 8)))", 0},
    {"print", "print(IM, IM.width, IM.height)", 0},
    {"type", "out(type(IM))", 0},
    {"assert", "assert(IM, \"an image is true\")\nout(IM)", 0},
    {"fold", "out(fold([0.5, 2], IM, (acc, k) => acc * k))", 0},
    {"sum", "out(sum([IM, J, IM]))", 0},
    {"concat", "out(concat([IM], [J]))", 0},
    {"select", "out(select(1, 2, IM))", 1},
    {"show", "show(IM)\nout(IM)", 0},
    {"hstack", "out(hstack(IM, J, gap: 2, background: 0.5))", 0},
    {"vstack", "out(vstack([J, IM], gap: 1))", 0},
    {"pixel", "out([pixel(IM, i % 24, (i * 7) % 24) for i in range(0, 576, 5)])", 0},
    {"save", "save(IM, DIR + \"/s.png\")", 0},
    {"save", "save(IM, DIR + \"/s16.png\", {bits: 16})", 0},
    {"save", "save(IM, DIR + \"/g.png\", {channels: 1})", 0},
    {"save", "save(IM, DIR + \"/ga16.png\", {channels: 2, bits: 16})", 0},
    {"save", "save(IM, DIR + \"/rgb.png\", {channels: 3})", 0},
    {"save", "save(IM, DIR + \"/s.ppm\")", 0},
    {"save", "save(IM, DIR + \"/s16.pgm\", {bits: 16})", 0},
    {"save", "save(IM, DIR + \"/s.pfm\")", 0},
    {"save", "save(IM, DIR + \"/g.pfm\", {channels: 1})", 0},
    {"save", "save([IM, J, IM], DIR + \"/anim.png\", {delay: 50})", 0},
    {"save", "save([J, IM], DIR + \"/anim16.png\", {bits: 16, channels: 2})", 0},
    {"wrinkly_draw", "out(wrinkly_draw(wrinkly_curve([[0, 0], [1, 0.5], [0, 1]], crossings: 2), onto: IM))", 0},
    {"draw", "out(draw(polygon([0.1, 0.1], [0.9, 0.2], [0.3, 0.8]), window: [0, 1, 0, 1], fill: true, onto: IM))", 0},
    {"steal", "out(steal(sierpinski, sierpinski, IM, size: 24, points: 3000, seed: 2))", 0},
    {"fractal_filter", "out(fractal_filter(sierpinski, sierpinski, [IM, J], size: 24, points: 3000, seed: 2))", 0},
    {"tile", "out(tile(IM, \"lr\", \"max\"))", 0},
    {"tile", "out(tile(IM, \"both\", \"mean\"))", 0},
    {"tiling", "out(tiling(IM, [40, 30], mirrored: true))", 0},
    {"fit", "out(fit(IM, maps: 3, iterations: 4, seed: 1))", 0},
    {"arithmetic", "out([IM + J, IM - 0.1, 2 * IM, IM / 2, J ^ IM, -IM])", 0},
    {"arithmetic", "out(IM * IM)", 0},
};

/* Builtins the enumeration below finds that take no image at all: variadic
 * ones whose arguments are points, and ones with a list parameter whose
 * documentation says "image" but whose lists hold palettes, colours, maps,
 * sets or scenes (the image is what they make). */
static const char *const no_image[] = {
    "polygon", "polyline", "pointset",                         /* variadic: points */
    "slice", "raymarch", "textured", "slice_plane",            /* palette / colour lists */
    "rasterize", "chaos_fset", "iterate", "superifs_image", /* scenes, systems, palettes */
};

static const char *const producers[] = {
    "let IM = chaos(sierpinski, points: 4e4, size: 24, window: [0, 1, 0, 1], background: [0, 0, 1, 1], seed: 3)",
    "let IM = chaos(sierpinski, points: 4e4, size: 24, window: [0, 1, 0, 1], colour: \"blend\", supersample: 2, seed: 4)",
    "let IM = chaos_fset(sierpinski, points: 4e4, size: 24, window: [-0.1, 1.1, -0.1, 1.1], gamma: 0.7, seed: 3)",
    "let F2 = ifs {\n  1/3 0 0 1/3 0 0\n  1/3 0 0 1/3 2/3 0\n  1/3 0 0 1/3 1/3 2/3\n}\n"
    "let IM = superifs_image(superifs([sierpinski, F2], V: 2, points: 2000, steps: 12, seed: 3), size: 24, "
    "window: [0, 1, 0, 1], background: 0.2)",
};

/* A parameter typed image or any, a variadic builtin, or a list parameter
 * of a builtin whose documentation speaks of images (a list of frames). */
static int takes_image(const builtin *b)
{
    if (b->variadic)
        return 1;
    int list = 0;
    for (int i = 0; i < b->nparams; i++) {
        const char *t = b->params[i].type;
        if (strstr(t, "image") || strstr(t, "any"))
            return 1;
        list |= strstr(t, "list") != NULL;
    }
    return list && b->doc && strstr(b->doc, "image");
}

static void test_table_complete(void)
{
    interp st;
    interp_init(&st);
    CHECK(session_setup(&st) == 0, "session_setup");
    int n = 0;
    for (int i = 0; i < st.nbuiltins; i++) {
        const builtin *b = st.builtins[i];
        if (!takes_image(b))
            continue;
        n++;
        int found = 0;
        for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++)
            found |= strcmp(cases[k].builtin, b->name) == 0;
        for (size_t k = 0; k < sizeof no_image / sizeof no_image[0]; k++)
            found |= strcmp(no_image[k], b->name) == 0;
        CHECK(found, "builtin '%s' takes an image (or any value) but has no case (or no_image entry) in test_pending_image.c", b->name);
    }
    /* 14 math functions, pow … select, sum, show, hstack, vstack, pixel,
     * save, the two `onto` drawers, steal, fractal_filter, tile, tiling, fit,
     * and the no_image ones */
    CHECK(n >= 50, "only %d builtins take an image", n);
    interp_free(&st);
}

typedef struct result {
    int rc;
    char err[1100];
    char *out;   /* stdout */
    size_t nout;
    char *files; /* name NUL bytes, for every file in the folder, sorted by name */
    size_t nfiles;
    int nfile;
} result;

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static void slurp_dir(const char *dir, result *r)
{
    char *names[64];
    int k = 0;
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)) && k < 64)
        if (e->d_name[0] != '.')
            names[k++] = strdup(e->d_name);
    if (d)
        closedir(d);
    qsort(names, (size_t)k, sizeof names[0], cmp_names);
    r->files = NULL;
    r->nfiles = 0;
    r->nfile = k;
    for (int i = 0; i < k; i++) {
        char path[600];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        FILE *f = fopen(path, "rb");
        size_t len = strlen(names[i]) + 1;
        r->files = realloc(r->files, r->nfiles + len);
        memcpy(r->files + r->nfiles, names[i], len);
        r->nfiles += len;
        if (f) {
            char buf[65536];
            size_t got;
            while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
                r->files = realloc(r->files, r->nfiles + got);
                memcpy(r->files + r->nfiles, buf, got);
                r->nfiles += got;
            }
            fclose(f);
        }
        unlink(path);
        free(names[i]);
    }
}

static char *slurp_file(FILE *f, size_t *n)
{
    fflush(f);
    rewind(f);
    char *s = NULL;
    *n = 0;
    char buf[4096];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        s = realloc(s, *n + got + 1);
        memcpy(s + *n, buf, got);
        *n += got;
        s[*n] = 0;
    }
    return s;
}

static int run_text(interp *st, const char *text, result *r)
{
    int rc = session_run_lines(st, "<test>", text, strlen(text), 1, 0, NULL);
    if (rc && st->err.active && !r->err[0])
        snprintf(r->err, sizeof r->err, "%s", st->err.msg);
    return rc;
}

/* The image bound to IM (pending or not). */
static image *bound_image(interp *st)
{
    const char *name = interp_intern(st, "IM", 2);
    const value *v = name ? val_env_lookup(st->globals, name) : NULL;
    if (!v || v->k != V_OBJ || AS_OBJ(*v)->cls != &lang_image_class)
        return NULL;
    return AS_OBJ(*v)->payload; /* not lang_as_image: that makes the pixels */
}

/* Run producer p then the case body in one session; ready: fill IM's pixels
 * from its source's rows first (the harness's own route, not image_ready). */
static void run_case(const char *dir, const char *producer, const pcase *c, int ready, result *r, int *was_pending,
                     double *lit)
{
    memset(r, 0, sizeof *r);
    interp st;
    FILE *f;
    r->rc = test_session(&st, 1, &f);
    if (!f)
        return;
    char pre[2048];
    snprintf(pre, sizeof pre,
             "import \"ifs\"\nlet DIR = \"%s\"\n%s\nlet J = gradient(24, [1, 0, 0, 1], [0, 1, 0, 0.5], 30)\n"
             "fn out(r) = if type(r) == \"image\" then [save(r, DIR + \"/r.pfm\"), save(r, DIR + \"/r.png\", {bits: 16})] "
             "elif type(r) == \"list\" and len(r) > 0 and type(r[0]) == \"image\" then "
             "[save(r[i], format(\"{}/r{}.pfm\", DIR, i)) for i in range(len(r))] else print(r)\n",
             dir, producer);
    if (!r->rc)
        r->rc = run_text(&st, pre, r);
    image *im = r->rc ? NULL : bound_image(&st);
    CHECK(r->rc || im, "IM is not an image after '%s'", producer);
    *was_pending = im && im->src;
    if (im && ready && im->src) {
        im->src->rows(im->src, 0, im->h, im->px);
        im->src->destroy(im->src);
        im->src = NULL;
    }
    if (im && !im->src) { /* lit: the fraction of pixels unlike the top-left one (the background) */
        size_t n = (size_t)im->w * (size_t)im->h, d = 0;
        for (size_t i = 0; i < n; i++)
            d += memcmp(im->px + 4 * i, im->px, 4 * sizeof(float)) != 0;
        *lit = (double)d / (double)n;
    }
    if (!r->rc)
        r->rc = run_text(&st, c->body, r);
    r->out = slurp_file(f, &r->nout);
    fclose(f);
    interp_free(&st);
    slurp_dir(dir, r);
}

static void result_free(result *r)
{
    free(r->out);
    free(r->files);
}

static void test_cases(void)
{
    char dir[] = "/tmp/frac_pending_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    for (size_t p = 0; p < sizeof producers / sizeof producers[0]; p++) {
        for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
            result a, b;
            int pa = 0, pb = 0;
            double lit = -1, lit_a = -1;
            run_case(dir, producers[p], &cases[k], 0, &a, &pa, &lit_a);
            run_case(dir, producers[p], &cases[k], 1, &b, &pb, &lit);
            const char *what = cases[k].body;
            if (cases[k].fails)
                CHECK(a.rc && b.rc && a.err[0], "producer %zu, %s: did not fail", p, what);
            else
                CHECK(a.rc == 0 && b.rc == 0, "producer %zu, %s: failed (%s | %s)", p, what, a.err, b.err);
            CHECK(pa && pb, "producer %zu: its render is not pending", p);
            CHECK(lit > 0.05 && lit < 0.95, "producer %zu: %.3f of its pixels lit", p, lit);
            CHECK(cases[k].fails || a.nout + a.nfile > 0, "producer %zu, %s: wrote nothing", p, what);
            CHECK(a.nout == b.nout && (!a.nout || memcmp(a.out, b.out, a.nout) == 0),
                  "producer %zu, %s: stdout differs:\n  pending: %s\n  ready:   %s", p, what, a.out ? a.out : "",
                  b.out ? b.out : "");
            CHECK(strcmp(a.err, b.err) == 0, "producer %zu, %s: errors differ", p, what);
            CHECK(a.nfile == b.nfile && a.nfiles == b.nfiles && (!a.nfiles || memcmp(a.files, b.files, a.nfiles) == 0),
                  "producer %zu, %s: the files differ (%d vs %d files, %zu vs %zu bytes)", p, what, a.nfile, b.nfile,
                  a.nfiles, b.nfiles);
            result_free(&a);
            result_free(&b);
        }
    }
    rmdir(dir);
}

int main(void)
{
    test_table_complete();
    test_cases();
    return check_done("test_pending_image");
}
