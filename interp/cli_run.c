/* cli_run.c — running a script from the command line: run, check, -e, the
 * REPL, every frame of --frames and every render of frac watch (cli.h). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "contract.h"
#include "eval.h"
#include "fileio.h"
#include "parser.h"
#include "recipe.h"
#include "repl.h"
#include "report.h"
#include "rt_alloc.h"
#include "session.h"
#include "shard.h"
#include "watch.h"

/* -o DIR: create the folder and its parents (mkdir -p) before anything runs,
 * so a missing folder does not lose a finished render. */
int cli_make_out_dir(const char *dir)
{
    char path[4096];
    size_t n = strlen(dir);
    if (n >= sizeof path) {
        fprintf(stderr, "frac: error: the output folder name is too long (%zu bytes)\n", n);
        return EX_IO;
    }
    memcpy(path, dir, n + 1);
    for (char *p = path + 1;; p++) {
        if (*p != '/' && *p != 0)
            continue;
        char c = *p;
        *p = 0;
        if (mkdir(path, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "frac: error: cannot create the output folder '%s': %s\n", dir, strerror(errno));
            return EX_IO;
        }
        *p = c;
        if (!c)
            break;
    }
    struct stat st;
    int gone = stat(dir, &st) != 0;
    if (gone || !S_ISDIR(st.st_mode)) {
        fprintf(stderr, "frac: error: cannot create the output folder '%s': %s\n", dir,
                gone ? strerror(errno) : "a file of that name is in the way");
        return EX_IO;
    }
    return 0;
}

static int read_script(interp *I, const char *path, unsigned char **text, size_t *len)
{
    rt_error e;
    if (strcmp(path, "-") == 0) {
        size_t cap = 1 << 16, n = 0;
        /* rt_malloc, like fileio_read_all below: the same hook as mem_alloc */
        unsigned char *buf = rt_malloc(cap + 1);
        if (!buf) {
            mem_engine_error(I, "reading the script from standard input", "out of memory");
            return session_report(I);
        }
        size_t r;
        while ((r = fread(buf + n, 1, cap - n, stdin)) > 0) {
            n += r;
            if (n == cap) {
                if (cap >= (64u << 20)) {
                    rt_free(buf);
                    fprintf(stderr, "frac: error: the script on standard input is larger than 64 MiB\n");
                    return EX_IO;
                }
                unsigned char *nb = rt_realloc(buf, cap * 2 + 1);
                if (!nb) {
                    rt_free(buf);
                    mem_engine_error(I, "reading the script from standard input", "out of memory");
                    return session_report(I);
                }
                buf = nb;
                cap *= 2;
            }
        }
        if (ferror(stdin)) { /* a read error is not the end of the script (issue 11) */
            int err = errno;
            rt_free(buf);
            fprintf(stderr, "frac: error: cannot read the script from standard input: %s\n", strerror(err));
            return EX_IO;
        }
        buf[n] = 0;
        *text = buf;
        *len = n;
        return 0;
    }
    rt_code c = fileio_read_all(path, 64u << 20, text, len, &e);
    if (c == RT_ENOMEM) { /* the buffer goes through the allocation hook: say why it refused */
        char what[80];
        snprintf(what, sizeof what, "reading '%.60s%s'", path, strlen(path) > 60 ? "…" : "");
        mem_engine_error(I, what, "out of memory");
        return session_report(I);
    }
    if (c) {
        fprintf(stderr, "frac: error: %s\n", e.msg);
        return EX_IO;
    }
    if (memchr(*text, 0, *len)) {
        fprintf(stderr, "frac: error: '%s' is not a text file (it contains NUL bytes)\n", path);
        rt_free(*text);
        return EX_SCRIPT;
    }
    return 0;
}

static int set_script_args(interp *I, const opts *o)
{
    value l = val_list(I, (size_t)o->nargs);
    if (l.k == V_NIL)
        return -1;
    for (int i = 0; i < o->nargs; i++)
        if (val_list_push(I, AS_LIST(l), val_cstr(I, o->args[i])))
            return -1;
    const char *name = interp_intern(I, "args", 4);
    if (!name)
        return -1;
    /* the first name of the global scope (the script's slots start after it) */
    return I->globals->n == 0 ? val_env_append(I, I->globals, name, l) : val_env_define(I, I->globals, name, l);
}

static void print_params(interp *I)
{
    for (int i = 0; i < I->nparams; i++) {
        const node *d = I->params[i].decl;
        const node *v = d->kids[0];
        /* default: the source text from the value to the end of the line or comment */
        const char *p = I->srcs[v->src].text;
        for (int l = 1; l < v->line && *p; p++)
            if (*p == '\n')
                l++;
        p += v->col - 1;
        const char *e = p;
        while (*e && *e != '\n' && *e != '#')
            e++;
        while (e > p && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r'))
            e--;
        printf("%s = %.*s%s%s\n", I->params[i].name, (int)(e - p), p, d->doc ? "    # " : "",
               d->doc ? d->doc : "");
    }
}

/* -D before anything runs: each NAME must be a top-level param of the script,
 * and where the param's default is a constant expression, its value is checked now, by
 * evaluating that one `param` statement on its own — the same code, and so
 * the same messages, as when the script reaches it (apply_param_override in
 * eval.c). Params with computed defaults are checked there. */
static int check_overrides(interp *I, const char *name, const char *text, size_t len)
{
    int src = interp_add_source(I, name, text, len);
    node *prog;
    if (src < 0 || parse_source(I, src, &prog))
        return -1;
    for (int k = 0; k < I->noverrides; k++) {
        const node *decl = NULL;
        const char *cands[256];
        int nc = 0;
        for (int i = 0; i < prog->nkids; i++) {
            const node *s = prog->kids[i];
            if (s->kind != N_PARAM)
                continue;
            if (s->str == I->overrides[k].name && !decl)
                decl = s;
            if (nc < 256)
                cands[nc++] = s->str;
        }
        const char *ovname = I->overrides[k].name;
        if (!decl) {
            const char *s = interp_suggest_name(ovname, cands, (size_t)nc);
            return err_pos(I, -1, 0, 0, ERR_USAGE, "-D %s: the script has no param '%s'%s%s%s", ovname,
                           ovname, s ? " (did you mean '" : nc ? "" : " (it declares none)",
                           s ? s : "", s ? "'?)" : "");
        }
        if (!contract_is_constant(decl->kids[0])) /* its type is known without running */
            continue;
        node *blk = mem_arena_alloc(I, sizeof *blk);
        node **kids = mem_arena_alloc(I, sizeof *kids);
        if (!blk || !kids)
            return -1;
        memset(blk, 0, sizeof *blk);
        blk->kind = N_BLOCK;
        blk->src = decl->src;
        blk->line = decl->line;
        blk->col = decl->col;
        kids[0] = (node *)decl;
        blk->kids = kids;
        blk->nkids = 1;
        value v;
        if (eval_expr(I, I->globals, blk, &v))
            return -1;
        val_unref(I, v);
    }
    return 0;
}

/* -D NAME=VALUE (o->ov) as the interpreter's param overrides. */
static int set_overrides(interp *I, const opts *o)
{
    mem_free(I, I->overrides);
    I->noverrides = o->nov;
    I->overrides = mem_alloc(I, (size_t)(o->nov ? o->nov : 1) * sizeof *I->overrides);
    if (!I->overrides)
        return -1;
    for (int k = 0; k < o->nov; k++) {
        const char *eq = strchr(o->ov[k].name, '=');
        I->overrides[k].name = interp_intern(I, o->ov[k].name, (size_t)(eq - o->ov[k].name));
        I->overrides[k].text = o->ov[k].text;
        I->overrides[k].used = 0;
        if (!I->overrides[k].name)
            return -1;
    }
    return 0;
}

int cli_run_frac(interp *I, opts *o)
{
    int rc;
    if (session_setup(I)) {
        rc = session_report(I);
        return rc ? rc : EX_SOFTWARE;
    }
    if (set_overrides(I, o))
        return session_report(I);
    cli_catch_signals();
    I->interrupt = o->cancel ? o->cancel : &cli_interrupted;

    int check = strcmp(o->mode, "check") == 0;
    if (strcmp(o->mode, "info") == 0)
        return cli_info(o->script);
    if (strcmp(o->mode, "repl") == 0) {
        if (I->out_dir && (rc = cli_make_out_dir(I->out_dir)))
            return rc;
        cli_repl_recipe c;
        memset(&c, 0, sizeof c);
        c.I = I, c.o = o;
        if (cli_repl_set_recipe(&c, "", 0))
            return session_report(I);
        rc = repl_main(I, &cli_interrupted, cli_repl_set_recipe, &c);
        if (c.installed)
            recipe_uninstall(&c.st);
        return rc;
    }
    if (strcmp(o->mode, "eval") == 0) {
        if (I->out_dir && (rc = cli_make_out_dir(I->out_dir)))
            return rc;
        value v = val_nil();
        rc = EX_OK;
        recipe_store st;
        if (cli_install_recipe(I, o, "<-e>", o->expr, strlen(o->expr), &st))
            return session_report(I);
        if (session_run(I, "<-e>", o->expr, strlen(o->expr), 0, &v)) {
            rc = session_report(I);
        } else {
            bytebuf b;
            bytebuf_init(&b);
            val_print(I, v, &b, 1);
            if (b.failed) { /* the buffer's growth was refused by the allocation hook */
                mem_engine_error(I, "-e", "out of memory printing the value");
                rc = session_report(I);
            } else {
                fwrite(b.data, 1, b.len, stdout);
                fputc('\n', stdout);
            }
            bytebuf_free(&b);
        }
        val_unref(I, v);
        recipe_uninstall(&st);
        return rc;
    }
    unsigned char *text;
    size_t len;
    recipe rr;
    int rerun = strcmp(o->mode, "rerun") == 0;
    memset(&rr, 0, sizeof rr);
    if (o->text) { /* --frames: read once, freed by cli_run_frames */
        text = (unsigned char *)o->text;
        len = o->len;
    } else if (rerun) {
        char *t = NULL;
        if ((rc = cli_rerun_prepare(I, o, &rr, &t, &len))) {
            recipe_free(&rr);
            return rc;
        }
        if (rr.apng_output) { /* an APNG of frac apng: its frames, then the file */
            rc = cli_rerun_apng(I, o, &rr);
            recipe_free(&rr);
            return rc;
        }
        rr.script = NULL; /* the text is ours now (freed below) */
        text = (unsigned char *)t;
        if (set_overrides(I, o)) {
            rt_free(text);
            recipe_free(&rr);
            return session_report(I);
        }
    } else if ((rc = read_script(I, o->script, &text, &len))) {
        return rc;
    }
    rc = cli_run_script(I, o, check, text, len);
    if (!o->text)
        rt_free(text);
    recipe_free(&rr);
    return rc;
}

/* Run (or check) the script text: the common tail of run, check, rerun,
 * each frame of --frames and each render of watch. */
int cli_run_script(interp *I, opts *o, int check, unsigned char *text, size_t len)
{
    int rc;
    const char *name = strcmp(o->script, "-") == 0 ? "<stdin>" : o->script;
    if (set_script_args(I, o) || (o->nov && check_overrides(I, name, (const char *)text, len)))
        return session_report(I);
    if (!check && I->out_dir && (rc = cli_make_out_dir(I->out_dir)))
        return rc;
    recipe_store st;
    if (!check && cli_install_recipe(I, o, o->script, (const char *)text, len, &st))
        return session_report(I);
    if (o->sh) { /* --shard or merge: one attempt (shard.h) */
        int bad = shard_attempt_begin(o->sh, I, name, text, len) || session_run(I, name, (const char *)text, len, 0, NULL);
        bad = shard_attempt_end(o->sh, !bad, name) || bad;
        recipe_uninstall(&st);
        if (o->sh->again) /* abandoned by a taint: main runs it again */
            return EX_OK;
        return bad ? session_report(I) : EX_OK;
    }
    double t0 = report_clock();
    if (session_run(I, name, (const char *)text, len, check, NULL)) {
        /* watch: a render cancelled by a change is not reported */
        int cancelled = o->cancel && *o->cancel && I->err.kind == ERR_INTERRUPT;
        rc = cancelled ? 130 : session_report(I);
    } else {
        rc = EX_OK;
        if (check && o->list_params)
            print_params(I);
        /* the render report: asked for, or on a terminal when an engine ran */
        if (!check && (o->stats || (!I->quiet && I->nwork && isatty(2))))
            report_print(I, report_clock() - t0, stderr);
    }
    if (!check)
        recipe_uninstall(&st);
    return rc;
}

/* A new interpreter set up as T (limits, seed, threads, -o, output flags);
 * interp_init installs its allocation hook: restore T's after interp_free. */
void cli_fresh_interp(interp *I, const interp *T)
{
    interp_init(I);
    I->lim = T->lim;
    I->seed = T->seed;
    I->threads = T->threads;
    I->quiet = T->quiet;
    I->progress = T->progress;
    I->out_dir = T->out_dir;
    I->fail_alloc_at = T->fail_alloc_at;
}

/* frac watch: each render is a plain run of the script, read again, in a
 * fresh interpreter whose interrupt flag is the watcher's cancel flag. An
 * interruption there is a change of a file (or Ctrl-C), not an error. */
typedef struct watch_ctx {
    interp *T;
    opts *o;
} watch_ctx;

static int watch_render(void *ud, volatile sig_atomic_t *cancel)
{
    watch_ctx *c = ud;
    interp st, *I = &st;
    cli_fresh_interp(I, c->T);
    c->o->cancel = cancel;
    int rc = cli_run_frac(I, c->o);
    if (rc == 130 && *cancel)
        rc = 0; /* cancelled: watch_main starts again or stops */
    interp_free(I);
    rt_alloc_set_hook(&c->T->hook);
    return rc;
}

int cli_run_watch(interp *T, opts *o)
{
    cli_catch_signals();
    watch_ctx c = {T, o};
    int rc = watch_main(T, watch_render, &c, &cli_interrupted, o->show, T->quiet);
    return rc < 0 ? session_report(T) : rc;
}

/* --frames A..B:STEP: the script once per frame, each in a fresh interpreter
 * set up like a plain run (the same -D, --seed, -o, limits), so frame N is
 * byte for byte what `--frames N..N` gives for a script that reads `frame`
 * (`clock` is 0 for a single frame). Stops at the first frame that fails. */
int cli_run_frames(interp *T, opts *o)
{
    unsigned char *text;
    size_t len;
    int rc = read_script(T, o->script, &text, &len);
    if (rc)
        return rc;
    o->text = text;
    o->len = len;
    long count = (o->fb - o->fa) / o->fstep + 1;
    int tty = !T->quiet && isatty(2);
    rc = EX_OK;
    for (long k = 0; k < count && rc == EX_OK; k++) {
        long f = o->fa + k * o->fstep;
        if (cli_interrupted) {
            rc = 130;
            break;
        }
        if (tty)
            fprintf(stderr, "frame %ld (%ld of %ld)\n", f, k + 1, count);
        if (o->sh) /* --shard or merge: each frame its own calls and re-runs (shard.h) */
            shard_new_frame(o->sh);
        do {
            interp st, *I = &st;
            cli_fresh_interp(I, T);
            cli_set_frame(I, f, o->fa, o->fb, o->fstep);
            rc = cli_run_frac(I, o);
            interp_free(I);
            rt_alloc_set_hook(&T->hook); /* T's blocks (the script, the options) are counted by T */
        } while (rc == EX_OK && o->sh && o->sh->again);
        if (rc != EX_OK && count > 1)
            fprintf(stderr, "frac: stopped at frame %ld (%ld of %ld frames done)\n", f, k, count);
    }
    o->text = NULL;
    rt_free(text);
    return rc;
}
