/* cli_recipe.c — the recipe of a run for the writers, frac info, frac
 * rerun (also of an APNG that frac apng assembled), and frac apng (cli.h,
 * docs/provenance.md). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "apng.h"
#include "cli.h"
#include "fileio.h"
#include "lexer.h"
#include "recipe.h"
#include "rt_alloc.h"
#include "session.h"
#include "sha256.h"

/* Frame f of the range a..b:step: the names `frame` and `clock`, what %f
 * becomes, and the range for the recipe (cli_run_frames, and rerun of a frame). */
void cli_set_frame(interp *I, long f, long a, long b, long step)
{
    long big = labs(a) > labs(b) ? labs(a) : labs(b);
    int width = 1;
    for (; big >= 10; big /= 10)
        width++;
    I->frame = f;
    I->frames_given = 1;
    I->clock = b > a ? (double)(f - a) / (double)(b - a) : 0.0;
    I->frame_width = width;
    I->frame_count = (b - a) / step + 1;
    I->frame_first = a, I->frame_last = b, I->frame_step = step;
}

/* Does the script (NUL-terminated) use the name `clock`? Then its recipe
 * records the --frames range, which clock depends on, so a rerun of the
 * frame has the same clock; otherwise frame N's files stay identical to
 * those of --frames N..N. (A module of the script's own that reads clock is
 * not seen: docs/provenance.md.) Unsure (out of memory): yes. */
static int names_clock(const char *text)
{
    token_list tl = {0};
    if (lex_all(text, 0, 1, &tl))
        return 1;
    int found = 0;
    for (size_t i = 0; i < tl.n && !found; i++)
        found = tl.toks[i].type == T_IDENT && tl.toks[i].len == 5 && memcmp(tl.toks[i].start, "clock", 5) == 0;
    lex_free(&tl);
    return found;
}

/* The recipe of this run (recipe.h), handed to the writers. text NULL: no
 * script text (--no-recipe drops it too). */
int cli_install_recipe(interp *I, const opts *o, const char *path, const char *text, size_t len,
                          recipe_store *st)
{
    recipe r;
    memset(&r, 0, sizeof r);
    r.version = (char *)FRAC_VERSION;
    r.script_path = (char *)path;
    if (text)
        sha256_hex(text, len, r.sha256);
    r.seed = I->seed;
    r.frame_given = I->frames_given;
    r.frame = I->frame;
    r.frames_range = I->frames_given && text && names_clock(text);
    r.frames_a = I->frame_first, r.frames_b = I->frame_last, r.frames_step = I->frame_step;
    char **params = mem_alloc(I, (size_t)(o->nov ? o->nov : 1) * sizeof *params);
    if (!params)
        return -1;
    for (int k = 0; k < o->nov; k++)
        params[k] = (char *)o->ov[k].name; /* "NAME=VALUE" as typed */
    r.nparams = o->nov;
    r.params = params;
    r.nargs = o->nargs;
    r.args = (char **)o->args;
    r.has_script = text && !o->no_recipe;
    r.script = (char *)text;
    r.script_len = len;
    int rc = recipe_install(&r, st);
    mem_free(I, params);
    if (rc)
        mem_engine_error(I, "recipe", "out of memory building the recipe");
    return rc;
}

/* Read FILE's recipe into *r. Returns 0, or the exit code (the message printed). */
static int read_recipe(const char *path, recipe *r, char *oneline, size_t on)
{
    unsigned char *d;
    size_t n;
    rt_error e;
    rt_code c = fileio_read_all(path, (size_t)1 << 31, &d, &n, &e);
    if (c) {
        fprintf(stderr, "frac: error: %s\n", e.msg);
        return c == RT_ENOMEM ? EX_SOFTWARE : EX_IO;
    }
    char *text, err[256];
    size_t len;
    int found = recipe_find(d, n, &text, &len, oneline, on, err, sizeof err);
    rt_free(d);
    if (found < 0) {
        fprintf(stderr, "frac: error: '%s': %s\n", path, err);
        return EX_SCRIPT;
    }
    if (found > 0) {
        if (!oneline[0])
            fprintf(stderr, "frac: error: '%s' carries no frac recipe (frac writes one into the PNG, PPM/PGM, "
                            "NRRD, VTK, PLY, OBJ, STL, SVG and flame files it saves)\n", path);
        return oneline[0] ? -1 : EX_SCRIPT;
    }
    int bad = recipe_parse(text, len, r, err, sizeof err);
    rt_free(text);
    if (bad) {
        fprintf(stderr, "frac: error: '%s': %s\n", path, err);
        return EX_SCRIPT;
    }
    if (r->script) {
        char hex[65];
        sha256_hex(r->script, r->script_len, hex);
        if (strcmp(hex, r->sha256) != 0) {
            fprintf(stderr, "frac: error: '%s': the recipe's script text does not match its script-sha256 "
                            "(the file is damaged)\n", path);
            recipe_free(r);
            return EX_SCRIPT;
        }
    }
    return 0;
}

int cli_info(const char *path)
{
    recipe r;
    char oneline[256];
    int rc = read_recipe(path, &r, oneline, sizeof oneline);
    if (rc == -1) { /* VTK, STL: the one-line form only */
        printf("%s\n(a one-line recipe: this format has no room for more)\n", oneline);
        return EX_OK;
    }
    if (rc)
        return rc;
    bytebuf b;
    bytebuf_init(&b);
    recipe_text(&r, &b, NULL, NULL, 0);
    if (!b.failed)
        fwrite(b.data, 1, b.len, stdout);
    if (!r.script && r.has_script)
        printf("(the script text is not in this file: only PNG files carry it)\n");
    if (r.script && r.script_len && r.script[r.script_len - 1] != '\n')
        putchar('\n');
    bytebuf_free(&b);
    recipe_free(&r);
    return EX_OK;
}

/* Print how to run the recipe's script by hand (when the file lacks its text). */
static void print_run_line(const recipe *r)
{
    fprintf(stderr, "  run the script itself: frac %s --seed %llu", r->script_path, (unsigned long long)r->seed);
    for (int k = 0; k < r->nparams; k++)
        fprintf(stderr, " -D '%s'", r->params[k]);
    if (r->nargs)
        fprintf(stderr, " --");
    for (int k = 0; k < r->nargs; k++)
        fprintf(stderr, " '%s'", r->args[k]);
    fprintf(stderr, "\n");
}

/* frac rerun FILE: the recipe's script, params, args, seed and frame become
 * this run's (o and I), *text its script. Returns 0 or the exit code. */
int cli_rerun_prepare(interp *I, opts *o, recipe *r, char **text, size_t *len)
{
    char oneline[256];
    const char *file = o->script;
    int rc = read_recipe(file, r, oneline, sizeof oneline);
    if (rc == -1) {
        fprintf(stderr, "frac: error: '%s' carries only a one-line recipe (%s), not the script: "
                        "it cannot be rerun\n", file, oneline);
        return EX_SCRIPT;
    }
    if (rc)
        return rc;
    if (!r->script) {
        fprintf(stderr, "frac: error: '%s' cannot be rerun: %s\n", file,
                r->has_script ? "the file carries the recipe's header only, not the script text (only PNG files "
                                "carry it)"
                              : "its recipe was written with --no-recipe and has no script text");
        if (r->script_path[0] != '<') /* not <repl> */
            print_run_line(r);
        return EX_SCRIPT;
    }
    if (strcmp(r->version, FRAC_VERSION) != 0)
        fprintf(stderr, "frac: warning: '%s' was made by frac %s, this is frac %s: the files may differ\n", file,
                r->version, FRAC_VERSION);
    if (r->nparams > 0) {
        param_override *ov = mem_calloc(I, (size_t)r->nparams, sizeof *ov);
        if (!ov)
            return session_report(I);
        mem_free(I, o->ov);
        o->ov = ov;
    }
    for (int k = 0; k < r->nparams; k++) {
        o->ov[k].name = r->params[k];
        o->ov[k].text = strchr(r->params[k], '=') + 1;
    }
    o->nov = r->nparams;
    if (r->nargs > 0) {
        const char **args = mem_calloc(I, (size_t)r->nargs, sizeof *args);
        if (!args)
            return session_report(I);
        mem_free(I, o->args);
        o->args = args;
    }
    for (int k = 0; k < r->nargs; k++)
        o->args[k] = r->args[k];
    o->nargs = r->nargs;
    I->seed = r->seed;
    if (r->frame_given) /* a frame of --frames A..B:STEP: the same frame, clock and %f */
        cli_set_frame(I, r->frame, r->frames_range ? r->frames_a : r->frame, r->frames_range ? r->frames_b : r->frame,
                  r->frames_range ? r->frames_step : 1);
    session_set_frame(I);
    o->script = r->script_path;
    *text = r->script;
    *len = r->script_len;
    return 0;
}

/* The REPL's recipe: the session so far as a script (repl.h), so a file
 * saved in the REPL can be rerun. */

int cli_repl_set_recipe(void *ud, const char *text, size_t len)
{
    cli_repl_recipe *c = ud;
    if (c->installed)
        recipe_uninstall(&c->st);
    c->installed = 0;
    if (cli_install_recipe(c->I, c->o, "<repl>", text, len, &c->st))
        return -1;
    c->installed = 1;
    return 0;
}

/* frac rerun of an APNG that frac apng assembled: each frame the recipe
 * lists is rendered again as in cli_rerun_prepare (in a fresh interpreter, like
 * cli_run_frames), the file of each input found among what that render wrote
 * (by its name; or the one PNG the render wrote), and the frames assembled
 * with the same delay and loop into OUT (the recipe's apng-output, under -o
 * DIR), carrying the same recipe: the same bytes as the original. */
typedef struct apng_rerun {
    const recipe *r;
    int from;       /* the entries of this render: from.. with its frame */
    char **path;    /* each entry's file, once found (FILEIO_PATH_MAX) */
    int *hits;
    int npng;       /* PNG files this render wrote */
    char last_png[FILEIO_PATH_MAX];
} apng_rerun;

static const char *base_name(const char *p)
{
    const char *s = strrchr(p, '/');
    return s ? s + 1 : p;
}

static int assemble_apng(interp *I, const char **names, int n, const apng_opts *ao, const char *out, recipe *ar,
                         int make_recipe);

static int same_apng_frame(const recipe *r, int i, int j)
{
    return r->apng_framed[i] == r->apng_framed[j] && (!r->apng_framed[i] || r->apng_frame[i] == r->apng_frame[j]);
}

static void on_rerun_write(void *ud, const char *path, int wrote)
{
    apng_rerun *w = ud;
    size_t pl = strlen(path);
    if (!wrote || pl >= FILEIO_PATH_MAX)
        return;
    if (pl > 4 && strcmp(path + pl - 4, ".png") == 0) {
        w->npng++;
        memcpy(w->last_png, path, pl + 1);
    }
    for (int j = w->from; j < w->r->napng; j++)
        if (w->path[j] && same_apng_frame(w->r, w->from, j) &&
            strcmp(base_name(path), base_name(w->r->apng_name[j])) == 0 && w->hits[j]++ == 0)
            memcpy(w->path[j], path, pl + 1);
}

int cli_rerun_apng(interp *T, opts *o, recipe *r)
{
    int n = r->napng, rc = EX_OK;
    char **path = mem_calloc(T, (size_t)n, sizeof *path);
    int *hits = mem_calloc(T, (size_t)n, sizeof *hits);
    if (!path || !hits)
        rc = session_report(T);
    /* without a frames line the script does not read clock: the range only
     * sets the width of %f, which the listed frames' extremes give */
    long lo = 0, hi = 0;
    for (int i = 0, first = 1; i < n; i++)
        if (r->apng_framed[i]) {
            lo = first || r->apng_frame[i] < lo ? r->apng_frame[i] : lo;
            hi = first || r->apng_frame[i] > hi ? r->apng_frame[i] : hi;
            first = 0;
        }
    o->mode = "run";
    o->text = (unsigned char *)r->script;
    o->len = r->script_len;
    for (int i = 0; i < n && rc == EX_OK; i++) {
        if (path[i])
            continue; /* found by an earlier render of its frame */
        for (int j = i; j < n && rc == EX_OK; j++)
            if (!path[j] && same_apng_frame(r, i, j) && !(path[j] = mem_calloc(T, 1, FILEIO_PATH_MAX)))
                rc = session_report(T);
        if (rc)
            break;
        apng_rerun w = {r, i, path, hits, 0, ""};
        interp st, *I = &st;
        cli_fresh_interp(I, T);
        if (r->apng_framed[i])
            cli_set_frame(I, r->apng_frame[i], r->frames_range ? r->frames_a : lo, r->frames_range ? r->frames_b : hi,
                      r->frames_range ? r->frames_step : 1);
        fileio_set_path_hook(on_rerun_write, &w);
        rc = cli_run_frac(I, o);
        fileio_set_path_hook(NULL, NULL);
        interp_free(I);
        rt_alloc_set_hook(&T->hook);
        for (int j = i; j < n && rc == EX_OK; j++) {
            if (!same_apng_frame(r, i, j) || hits[j] == 1)
                continue;
            if (hits[j] == 0 && w.npng == 1) {
                memcpy(path[j], w.last_png, strlen(w.last_png) + 1);
                continue;
            }
            char fr[32] = "the run";
            if (r->apng_framed[j])
                snprintf(fr, sizeof fr, "frame %ld", r->apng_frame[j]);
            fprintf(stderr, "frac: error: %s of '%s' wrote %s file named '%s' (input %d of the APNG): cannot "
                            "assemble it again\n", fr, r->script_path, hits[j] ? "more than one" : "no",
                    base_name(r->apng_name[j]), j + 1);
            rc = EX_SCRIPT;
        }
    }
    o->text = NULL;
    char out[FILEIO_PATH_MAX];
    if (rc == EX_OK) {
        int k = T->out_dir ? snprintf(out, sizeof out, "%s/%s", T->out_dir, r->apng_output)
                           : snprintf(out, sizeof out, "%s", r->apng_output);
        if (k < 0 || (size_t)k >= sizeof out) {
            fprintf(stderr, "frac: error: the path of '%s' under '%s' is too long\n", r->apng_output, T->out_dir);
            rc = EX_IO;
        }
    }
    if (rc == EX_OK) {
        apng_opts ao = {(int)r->apng_delay, r->apng_loop};
        rc = assemble_apng(T, (const char **)path, n, &ao, out, r, 0);
    }
    for (int i = 0; path && i < n; i++)
        mem_free(T, path[i]);
    mem_free(T, path);
    mem_free(T, hits);
    return rc;
}

/* The recipe an APNG made by `frac apng` carries: the frames' common recipe
 * (all inputs must be files of one run, recipe_same_run) plus the assembly —
 * the output's name, delay, loop, and each input's frame and name — so that
 * `frac rerun` can render the frames again and assemble the same file.
 * Returns 1 with *ar built, 0 when the frames have no common recipe (note
 * gets a line saying why, printed once the APNG is written), -1 out of
 * memory. */
static int apng_recipe(unsigned char *const *data, const size_t *lens, const char **names, int n,
                       const apng_opts *ao, const char *out, recipe *ar, char *note, size_t noten)
{
    char why[768] = "", err[256], one[256];
    int ok = 1;
    memset(ar, 0, sizeof *ar);
    for (int i = 0; i < n && ok; i++) {
        recipe cur, *r = i ? &cur : ar;
        char *text;
        size_t len;
        int f = recipe_find(data[i], lens[i], &text, &len, one, sizeof one, err, sizeof err);
        int bad = f == 0 ? recipe_parse(text, len, r, err, sizeof err) : -1;
        if (f == 0)
            rt_free(text);
        if (!bad && r->script) {
            char hex[65];
            sha256_hex(r->script, r->script_len, hex);
            bad = strcmp(hex, r->sha256) != 0;
            if (bad)
                recipe_free(r);
        }
        if (bad) {
            snprintf(why, sizeof why, "'%s' %s", names[i], f > 0 ? "carries none" : "has a damaged one");
            ok = 0;
            break;
        }
        if (i == 0) {
            ar->apng_frame = rt_calloc((size_t)n, sizeof *ar->apng_frame);
            ar->apng_framed = rt_calloc((size_t)n, 1);
            ar->apng_name = rt_calloc((size_t)n, sizeof *ar->apng_name);
            if (!ar->apng_frame || !ar->apng_framed || !ar->apng_name) {
                recipe_free(ar);
                return -1;
            }
        } else if (!recipe_same_run(ar, &cur, err, sizeof err)) {
            snprintf(why, sizeof why, "'%s' and '%s' differ in %s", names[0], names[i], err);
            ok = 0;
        }
        ar->apng_frame[i] = r->frame;
        ar->apng_framed[i] = (char)r->frame_given;
        if (i)
            recipe_free(&cur);
        if (ok) {
            size_t k = strlen(names[i]);
            if (!(ar->apng_name[i] = rt_malloc(k + 1))) {
                recipe_free(ar);
                return -1;
            }
            memcpy(ar->apng_name[i], names[i], k + 1);
            ar->napng = i + 1;
        }
    }
    const char *bn = base_name(out);
    if (ok && !*bn) {
        snprintf(why, sizeof why, "'%s' is not a file name", out);
        ok = 0;
    }
    if (ok && !(ar->apng_output = rt_malloc(strlen(bn) + 1)))
        ok = -1;
    if (ok <= 0) {
        if (!ok)
            snprintf(note, noten, "frac: note: %s carries no recipe: the frames are not all files of one run with a "
                                  "recipe (%s)\n", out, why);
        recipe_free(ar);
        return ok;
    }
    memcpy(ar->apng_output, bn, strlen(bn) + 1);
    ar->apng_delay = ao->delay_ms;
    ar->apng_loop = ao->loop;
    return 1;
}

/* Read n PNG files, assemble them (apng_assemble) and write OUT; with ar the
 * APNG carries that recipe. Every frame is checked before anything is
 * written. */
static int assemble_apng(interp *I, const char **names, int n, const apng_opts *ao, const char *out, recipe *ar,
                         int make_recipe)
{
    unsigned char **data = mem_calloc(I, (size_t)n, sizeof *data);
    size_t *lens = mem_calloc(I, (size_t)n, sizeof *lens);
    int rc = data && lens ? EX_OK : session_report(I);
    rt_error e;
    for (int i = 0; i < n && rc == EX_OK; i++) {
        rt_code c = fileio_read_all(names[i], (size_t)1 << 30, &data[i], &lens[i], &e);
        if (c) {
            fprintf(stderr, "frac: error: %s\n", e.msg);
            rc = c == RT_ENOMEM ? EX_SOFTWARE : EX_IO;
        }
    }
    recipe built;
    int have = 0;
    char note[1536] = "";
    if (rc == EX_OK && make_recipe) {
        have = apng_recipe(data, lens, names, n, ao, out, &built, note, sizeof note);
        if (have < 0) {
            mem_engine_error(I, "apng", "out of memory building the recipe");
            rc = session_report(I);
        }
        ar = have > 0 ? &built : NULL;
    }
    recipe_store st;
    int installed = 0;
    if (rc == EX_OK && ar) {
        if (recipe_install(ar, &st)) {
            mem_engine_error(I, "apng", "out of memory building the recipe");
            rc = session_report(I);
        } else {
            installed = 1;
        }
    }
    if (rc == EX_OK) {
        bytebuf b;
        bytebuf_init(&b);
        rt_code c = apng_assemble((const unsigned char *const *)data, lens, n, names, ao, &b, &e);
        if (!c)
            c = fileio_write_atomic(out, b.data, b.len, &e);
        bytebuf_free(&b);
        if (c) {
            fprintf(stderr, "frac: error: %s\n", e.msg);
            rc = c == RT_ENOMEM ? EX_SOFTWARE : c == RT_EIO ? EX_IO : EX_SCRIPT;
        } else if (!I->quiet) {
            fprintf(stderr, "%swrote %s (%d frames)\n", note, out, n);
        }
    }
    if (installed)
        recipe_uninstall(&st);
    if (have > 0)
        recipe_free(&built);
    for (int i = 0; data && i < n; i++)
        rt_free(data[i]);
    mem_free(I, data);
    mem_free(I, lens);
    return rc;
}

/* frac apng -o OUT.png [--delay MS] [--loop N] FRAME.png...: the frames'
 * image data copied into one animated PNG (runtime/apng.h); every frame is
 * checked before anything is written. When the frames are files of one run
 * (one script, params and seed; `--frames` frames differ only in the
 * frame), the APNG carries their recipe and the assembly, for frac rerun. */
int cli_run_apng(interp *I, opts *o)
{
    apng_opts ao = {APNG_DEFAULT_DELAY_MS, 0};
    double d;
    if (o->delay && cli_parse_whole(o->delay, 0, APNG_MAX_DELAY_MS, &d))
        return cli_usage_error("--delay takes a whole number of milliseconds from 0 to %d, got '%s'", APNG_MAX_DELAY_MS,
                           o->delay);
    if (o->delay)
        ao.delay_ms = (int)d;
    if (o->loop && cli_parse_whole(o->loop, 0, APNG_MAX_LOOP, &d))
        return cli_usage_error("--loop takes a whole number of plays from 0 (forever) to %d, got '%s'", APNG_MAX_LOOP,
                           o->loop);
    if (o->loop)
        ao.loop = (long)d;
    int n = 1 + o->nargs;
    const char **names = mem_calloc(I, (size_t)n, sizeof *names);
    if (!names)
        return session_report(I);
    for (int i = 0; i < n; i++)
        names[i] = i ? o->args[i - 1] : o->script;
    int rc = assemble_apng(I, names, n, &ao, I->out_dir, NULL, 1);
    mem_free(I, names);
    return rc;
}
