/* main.c — the command line: run, check, repl, -e. The only place that exits.
 *
 *   frac [COMMAND] [OPTIONS] [SCRIPT] [OPTIONS | ARGS]… [-- ARGS…]
 *
 * Options are recognised anywhere before `--`. The first word that is not an
 * option (nor, before it, a command word) is the script; every later word is
 * one of the script's `args`. Nothing on the command line is ignored: an
 * option that does not apply, a bad number or an unknown -D name is a usage
 * error (64) before anything runs, and a failed write to standard output or
 * standard error makes the exit code 74. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "builtin.h"
#include "contract.h"
#include "cstack.h"
#include "eval.h"
#include "fit_cli.h"
#include "fileio.h"
#include "par.h"
#include "parser.h"
#include "repl.h"
#include "session.h"

enum { EX_OK = 0, EX_USAGE = 64, EX_SCRIPT = 65, EX_SOFTWARE = 70, EX_IO = 74 };

static const char usage_text[] =
    "usage: frac [run] [OPTIONS] SCRIPT.frac [OPTIONS] [ARGS…] [-- ARGS…]\n"
    "                                          run a script; files it names are written\n"
    "       frac check [--params] [OPTIONS] SCRIPT.frac\n"
    "                                          parse and check without running anything\n"
    "       frac repl                          interactive session (also: `frac` alone)\n"
    "       frac -e 'EXPR'                     evaluate one expression and print it\n"
    "       frac fit TARGET.png --maps N|A..B [--seed S] [--iterations K] [--time SECONDS]\n"
    "                [--foreground auto|dark|light|alpha] [--threshold T] [-o FIT.frac]\n"
    "                                          fit an IFS to a picture; writes a script\n"
    "                                          (default fit.frac) that saves fit.png\n"
    "                                          (docs/fit.md)\n"
    "       frac --version | --help\n"
    "\n"
    "SCRIPT may be - to read the script from standard input. A script may start\n"
    "with `#!/usr/bin/env frac` and then runs as `./SCRIPT.frac -D NAME=VALUE …`.\n"
    "Options may come before or after SCRIPT, mixed with its arguments: each word\n"
    "after SCRIPT that is not an option goes, in order, into the list of strings\n"
    "`args` (`frac s.frac a -D x=1 b`: args is [\"a\", \"b\"] and x is 1). `--` ends\n"
    "the options: every word after it is an argument, even one that starts with -.\n"
    "Long options take their value as `--NAME VALUE` or `--NAME=VALUE`; giving an\n"
    "option twice is an error.\n"
    "\n"
    "options:\n"
    "  -o, --out-dir DIR     where relative output paths go (default: current\n"
    "                        directory); created, with its parents, before the\n"
    "                        script runs\n"
    "  -D NAME=VALUE         override the script's top-level `param NAME = …`; also\n"
    "                        -DNAME=VALUE. VALUE must suit the param's default: a\n"
    "                        number param takes a finite number (1e6, -2, pi/4), a\n"
    "                        boolean param true or false, a list param a list\n"
    "                        ([0, 2]), a string param the text as it is (or a\n"
    "                        quoted \"string\"). VALUE may use builtins, not the\n"
    "                        script's names. Checked before anything runs (for a\n"
    "                        default computed from the script's names, when the\n"
    "                        script reaches the param);\n"
    "                        an unknown NAME is an error\n"
    "  --seed N              global random seed, a whole number 0 ≤ N ≤ 2^53\n"
    "                        (default 1)\n"
    "  --threads N           worker threads, 1 to 256 (default: all cores)\n"
    "  -q, --quiet           no progress bars or `wrote FILE` lines\n"
    "  --params              with check: list the script's params and defaults\n"
    "limits (whole numbers ≥ 1; a script that exceeds one stops with an error\n"
    "naming it):\n"
    "  --max-memory MIB      all memory: values, images, volumes, engine buffers (default 4096)\n"
    "  --max-depth N         function call depth (default 1000, at most " CSTACK_STR(CSTACK_MAX_DEPTH) ")\n"
    "  --max-pixels N        pixels per image (default 64000000)\n"
    "  --max-points N        points per chaos game or sampling (default 1e10)\n"
    "  --max-voxels N        voxels per volume (default 134217728 = 512^3)\n"
    "  --max-list N          items per list (default 1e8)\n"
    "\n"
    "exit codes: 0 ok, 64 usage, 65 script error, 70 runtime failure, 74 I/O error\n"
    "(also when standard output cannot be written), 130 interrupted.\n"
    "Documentation: docs/language.md.\n";

static volatile sig_atomic_t interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    if (interrupted) { /* a second Ctrl-C stops at once, leaving no temp file */
        fileio_cleanup_temps();
        _exit(130);
    }
    interrupted = 1;
}

__attribute__((format(printf, 1, 2))) static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "frac: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(run `frac --help` for usage)\n");
    va_end(ap);
    return EX_USAGE;
}

/* ---- numeric options ---------------------------------------------------------- */

enum { F_SEED, F_THREADS, F_MEMORY, F_DEPTH, F_PIXELS, F_POINTS, F_VOXELS, F_LIST, F_FAIL, NNUM };

static const struct numflag {
    const char *name;
    double lo, hi;
    const char *range; /* for messages */
} numflags[NNUM] = {
    [F_SEED] = {"--seed", 0, 9007199254740992.0, "a whole number from 0 to 2^53 = 9007199254740992"},
    [F_THREADS] = {"--threads", 1, 256, "a whole number from 1 to 256"},
    [F_MEMORY] = {"--max-memory", 1, 1073741824.0, "a whole number of MiB from 1 to 2^30"},
    [F_DEPTH] = {"--max-depth", 1, CSTACK_MAX_DEPTH,
                 "a whole number from 1 to " CSTACK_STR(CSTACK_MAX_DEPTH) " (the most the interpreter's stack holds)"},
    [F_PIXELS] = {"--max-pixels", 1, 1e12, "a whole number from 1 to 1e12"},
    [F_POINTS] = {"--max-points", 1, 1e15, "a whole number from 1 to 1e15"},
    [F_VOXELS] = {"--max-voxels", 1, 1e12, "a whole number from 1 to 1e12"},
    [F_LIST] = {"--max-list", 1, 1e12, "a whole number from 1 to 1e12"},
    [F_FAIL] = {"--fail-alloc", 1, 1e12, "a whole number from 1 to 1e12"}, /* testing */
};

/* A whole number in [lo, hi], written in decimal (1e6 is fine; nan, inf,
 * hex, spaces and fractions are not). */
static int parse_whole(const char *s, double lo, double hi, double *out)
{
    if (!*s || strspn(s, "0123456789.eE+-") != strlen(s))
        return -1;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || v != floor(v) || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

static void set_numflag(interp *I, int f, double d)
{
    switch (f) {
    case F_SEED: I->seed = (uint64_t)d; break;
    case F_THREADS: I->threads = (int)d; break;
    case F_MEMORY: I->lim.max_memory = (size_t)(d * 1048576.0); break;
    case F_DEPTH: I->lim.max_depth = (int)d; break;
    case F_PIXELS: I->lim.max_pixels = d; break;
    case F_POINTS: I->lim.max_points = d; break;
    case F_VOXELS: I->lim.max_voxels = d; break;
    case F_LIST: I->lim.max_list = d; break;
    case F_FAIL: /* count from here: parsing the command line allocated */
        I->fail_alloc_at = (long)d;
        I->alloc_count = 0;
        break;
    }
}

/* ---- the command line --------------------------------------------------------- */

typedef struct opts {
    const char *mode; /* "run", "check", "repl", "eval"; NULL until known */
    const char *script;
    const char *expr;
    int list_params;
    int nargs;
    const char **args;  /* the script's arguments (pointers into argv) */
    param_override *ov; /* -D as typed: name is "NAME=VALUE", text the VALUE */
    int nov;
} opts;

static int is_command(const char *w)
{
    return strcmp(w, "run") == 0 || strcmp(w, "check") == 0 || strcmp(w, "repl") == 0;
}

/* Fill *o from argv. Returns -1 to go on, or the exit code to stop with
 * (0 after --help/--version, 64 on a usage error). */
static int parse_command_line(interp *I, int argc, char **argv, opts *o)
{
    int seen[NNUM] = {0}, seen_o = 0, end_of_options = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (end_of_options || a[0] != '-' || a[1] == 0) {
            if (!end_of_options && !o->mode && !o->script && is_command(a))
                o->mode = a; /* the command word may follow options */
            else if (!o->script)
                o->script = a;
            else
                o->args[o->nargs++] = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            end_of_options = 1;
            continue;
        }
        /* --NAME=VALUE: split; short options take their value from the next word */
        char name[32];
        const char *inline_val = NULL, *eq = strchr(a, '=');
        if (a[1] == '-' && eq && (size_t)(eq - a) < sizeof name) {
            memcpy(name, a, (size_t)(eq - a));
            name[eq - a] = 0;
            inline_val = eq + 1;
        } else {
            snprintf(name, sizeof name, "%s", strlen(a) < sizeof name ? a : "-?");
        }
        const char *val = inline_val ? inline_val : i + 1 < argc ? argv[i + 1] : NULL;
        int f = 0;
        while (f < NNUM && strcmp(name, numflags[f].name) != 0)
            f++;

        if (!strcmp(name, "--help") || !strcmp(name, "-h") || !strcmp(name, "--version") ||
            !strcmp(name, "--quiet") || !strcmp(name, "-q") || !strcmp(name, "--params")) {
            if (inline_val)
                return usage_error("%s takes no value (got '%s')", name, a);
            if (!strcmp(name, "--help") || !strcmp(name, "-h")) {
                fputs(usage_text, stdout);
                return EX_OK;
            } else if (!strcmp(name, "--version")) {
                printf("frac %s\n", FRAC_VERSION);
                return EX_OK;
            } else if (!strcmp(name, "--params")) {
                o->list_params = 1;
            } else {
                I->quiet = 1;
                I->progress = 0;
            }
            continue;
        }
        if (strncmp(a, "-D", 2) == 0) {
            const char *def = a[2] ? a + 2 : val;
            if (!a[2])
                i++;
            const char *deq = def ? strchr(def, '=') : NULL;
            if (!deq || deq == def)
                return usage_error("-D needs NAME=VALUE, got '%s'", def ? def : "");
            for (int k = 0; k < o->nov; k++) {
                const char *prev = o->ov[k].name;
                size_t l = (size_t)(deq - def);
                if (strncmp(prev, def, l) == 0 && prev[l] == '=')
                    return usage_error("-D %.*s is given twice (%s and %s)", (int)l, def, prev, def);
            }
            o->ov[o->nov].name = def; /* interned once the interpreter is set up */
            o->ov[o->nov].text = deq + 1;
            o->nov++;
            continue;
        }
        int is_e = !strcmp(name, "-e"), is_o = !strcmp(name, "-o") || !strcmp(name, "--out-dir");
        if (is_e || is_o || f < NNUM) {
            const char *what = is_e ? "an expression" : is_o ? "a folder" : numflags[f].range;
            if (!val)
                return usage_error("%s needs a value: %s", name, what);
            if (!inline_val)
                i++;
            if ((is_e && o->expr) || (is_o && seen_o) || (f < NNUM && seen[f]))
                return usage_error("%s is given twice", name);
            if (is_e) {
                o->expr = val;
            } else if (is_o) {
                if (!*val)
                    return usage_error("%s needs a value: %s", name, what);
                I->out_dir = val;
                seen_o = 1;
            } else {
                double d;
                if (parse_whole(val, numflags[f].lo, numflags[f].hi, &d))
                    return usage_error("%s takes %s, got '%s'", name, what, val);
                set_numflag(I, f, d);
                seen[f] = 1;
            }
            continue;
        }
        if (o->script)
            return usage_error("unknown option '%s' after the script (to give it to the script in `args`, "
                               "put it after `--`: frac %s -- %s)",
                               a, o->script, a);
        return usage_error("unknown option '%s'", a);
    }

    if (o->expr) {
        if (o->mode)
            return usage_error("-e does not go with `%s`", o->mode);
        if (o->script)
            return usage_error("-e takes no script or arguments (got '%s')", o->script);
        o->mode = "eval";
    }
    if (!o->mode)
        o->mode = o->script ? "run" : "repl";
    if (strcmp(o->mode, "repl") == 0 && o->script)
        return usage_error("repl takes no script (got '%s'; run it with `frac %s`, or :load it in the REPL)",
                           o->script, o->script);
    if ((strcmp(o->mode, "run") == 0 || strcmp(o->mode, "check") == 0) && !o->script)
        return usage_error("%s needs a script file (or - for standard input)", o->mode);
    if (o->list_params && strcmp(o->mode, "check") != 0)
        return usage_error("%s", "--params goes with `frac check`");
    if (o->nov && (strcmp(o->mode, "eval") == 0 || strcmp(o->mode, "repl") == 0))
        return usage_error("-D sets a param of a script (frac SCRIPT -D NAME=VALUE); %s has none",
                           strcmp(o->mode, "eval") == 0 ? "-e" : "the REPL");
    return -1;
}

/* -o DIR: create the folder and its parents (mkdir -p) before anything runs,
 * so a missing folder does not lose a finished render. */
static int make_out_dir(const char *dir)
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

static int read_script(const char *path, unsigned char **text, size_t *len)
{
    rt_error e;
    if (strcmp(path, "-") == 0) {
        size_t cap = 1 << 16, n = 0;
        /* rt_malloc, like fileio_read_all below: the same hook as mem_alloc */
        unsigned char *buf = rt_malloc(cap + 1);
        if (!buf)
            return EX_SOFTWARE;
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
                    return EX_SOFTWARE;
                }
                buf = nb;
                cap *= 2;
            }
        }
        buf[n] = 0;
        *text = buf;
        *len = n;
        return 0;
    }
    rt_code c = fileio_read_all(path, 64u << 20, text, len, &e);
    if (c) {
        fprintf(stderr, "frac: error: %s\n", e.msg);
        return c == RT_ENOMEM ? EX_SOFTWARE : EX_IO; /* the buffer goes through the allocation hook */
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
    return name ? val_env_define(I, I->globals, name, l) : -1;
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

/* Standard output and standard error are checked once at the end (print
 * checks its own writes): a full disk or a closed pipe is an I/O error, not
 * a success. */
static int finish_output(int rc)
{
    errno = 0;
    int bad = fflush(stdout) != 0;
    int e = errno;
    bad |= ferror(stdout);
    if (bad && rc == EX_OK) {
        fprintf(stderr, "frac: error: cannot write to standard output%s%s\n", e ? ": " : "",
                e ? strerror(e) : "");
        rc = EX_IO;
    }
    if ((fflush(stderr) != 0 || ferror(stderr)) && rc == EX_OK)
        rc = EX_IO; /* nowhere left to say so */
    return rc;
}

static int run_frac(interp *I, opts *o)
{
    int rc;
    if (session_setup(I)) {
        rc = session_report(I);
        return rc ? rc : EX_SOFTWARE;
    }
    I->noverrides = o->nov;
    I->overrides = mem_alloc(I, (size_t)(o->nov ? o->nov : 1) * sizeof *I->overrides);
    if (!I->overrides)
        return session_report(I);
    for (int k = 0; k < o->nov; k++) {
        const char *eq = strchr(o->ov[k].name, '=');
        I->overrides[k].name = interp_intern(I, o->ov[k].name, (size_t)(eq - o->ov[k].name));
        I->overrides[k].text = o->ov[k].text;
        I->overrides[k].used = 0;
        if (!I->overrides[k].name)
            return session_report(I);
    }
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    fileio_install_signal_cleanup();
    I->interrupt = &interrupted;

    int check = strcmp(o->mode, "check") == 0;
    if (strcmp(o->mode, "repl") == 0) {
        if (I->out_dir && (rc = make_out_dir(I->out_dir)))
            return rc;
        return repl_main(I, &interrupted);
    }
    if (strcmp(o->mode, "eval") == 0) {
        if (I->out_dir && (rc = make_out_dir(I->out_dir)))
            return rc;
        value v = val_nil();
        rc = EX_OK;
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
        return rc;
    }
    unsigned char *text;
    size_t len;
    rc = read_script(o->script, &text, &len);
    if (rc)
        return rc;
    const char *name = strcmp(o->script, "-") == 0 ? "<stdin>" : o->script;
    if (set_script_args(I, o) || (o->nov && check_overrides(I, name, (const char *)text, len))) {
        rt_free(text);
        return session_report(I);
    }
    if (!check && I->out_dir && (rc = make_out_dir(I->out_dir))) {
        rt_free(text);
        return rc;
    }
    if (session_run(I, name, (const char *)text, len, check, NULL)) {
        rc = session_report(I);
    } else {
        rc = EX_OK;
        if (check && o->list_params)
            print_params(I);
    }
    rt_free(text);
    return rc;
}

static int frac_main(int argc, char **argv)
{
    interp st, *I = &st;
    interp_init(I);
    I->threads = par_cores();
    I->progress = 1;
    opts o = {0};
    o.args = mem_calloc(I, (size_t)argc, sizeof *o.args);
    o.ov = mem_calloc(I, (size_t)argc, sizeof *o.ov);
    int rc = EX_SOFTWARE;
    if (o.args && o.ov && argc > 1 && strcmp(argv[1], "fit") == 0) {
        rc = fit_command(I, argc - 1, argv + 1, &interrupted); /* its own options (interp/bind_fit.c) */
    } else if (o.args && o.ov) {
        rc = parse_command_line(I, argc, argv, &o);
        if (rc < 0)
            rc = run_frac(I, &o);
    }
    mem_free(I, o.args);
    mem_free(I, o.ov);
    interp_free(I);
    return finish_output(rc);
}

/* The interpreter runs on a thread with a stack size frac chooses (cstack.h). */
int main(int argc, char **argv) { return cstack_main(frac_main, argc, argv); }
