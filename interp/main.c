/* main.c — the command line: run, check, repl, -e. The only place that exits. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "builtin.h"
#include "cstack.h"
#include "fileio.h"
#include "par.h"
#include "repl.h"
#include "session.h"

enum { EX_OK = 0, EX_USAGE = 64, EX_SCRIPT = 65, EX_SOFTWARE = 70, EX_IO = 74 };

static const char usage_text[] =
    "usage: frac SCRIPT.frac [ARGS…]       run a script (same as `frac run`)\n"
    "       frac run [OPTIONS] SCRIPT.frac  run; files named in the script are written\n"
    "       frac check [--params] SCRIPT    parse and check names without rendering\n"
    "       frac repl                       interactive session (also: `frac` alone)\n"
    "       frac -e 'EXPR'                  evaluate one expression and print it\n"
    "       frac --version | --help\n"
    "\n"
    "SCRIPT may be - to read the script from standard input.\n"
    "\n"
    "options:\n"
    "  -o, --out-dir DIR     where relative output paths go (default: current directory)\n"
    "  -D NAME=VALUE         override a top-level `param` of the script\n"
    "  --seed N              global random seed (default 1)\n"
    "  --threads N           worker threads (default: all cores)\n"
    "  --quiet               no progress bars or `wrote FILE` lines\n"
    "  --params              with check: list the script's params and defaults\n"
    "limits (a script that exceeds one stops with an error naming it):\n"
    "  --max-memory MIB      memory for values, images, volumes (default 4096)\n"
    "  --max-depth N         function call depth (default 1000, at most " CSTACK_STR(CSTACK_MAX_DEPTH) ")\n"
    "  --max-pixels N        pixels per image (default 64000000)\n"
    "  --max-points N        points per chaos game or sampling (default 1e10)\n"
    "  --max-voxels N        voxels per volume (default 134217728 = 512^3)\n"
    "  --max-list N          items per list (default 1e8)\n"
    "\n"
    "exit codes: 0 ok, 64 usage, 65 script error, 70 runtime failure, 74 I/O error,\n"
    "130 interrupted. Documentation: docs/language.md.\n";

static volatile sig_atomic_t interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    if (interrupted) /* a second Ctrl-C stops at once */
        _exit(130);
    interrupted = 1;
}

static int usage_error(const char *fmt, const char *arg)
{
    fprintf(stderr, "frac: ");
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n(run `frac --help` for usage)\n");
    return EX_USAGE;
}

static int parse_number(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

typedef struct opts {
    const char *mode; /* "run", "check", "repl", "eval" */
    const char *script;
    const char *expr;
    int list_params;
    int nargs;
    char **args;
} opts;

static int read_script(const char *path, unsigned char **text, size_t *len)
{
    rt_error e;
    if (strcmp(path, "-") == 0) {
        size_t cap = 1 << 16, n = 0;
        unsigned char *buf = malloc(cap + 1);
        if (!buf)
            return EX_SOFTWARE;
        size_t r;
        while ((r = fread(buf + n, 1, cap - n, stdin)) > 0) {
            n += r;
            if (n == cap) {
                if (cap >= (64u << 20)) {
                    free(buf);
                    fprintf(stderr, "frac: error: the script on standard input is larger than 64 MiB\n");
                    return EX_IO;
                }
                unsigned char *nb = realloc(buf, cap * 2 + 1);
                if (!nb) {
                    free(buf);
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
    if (fileio_read_all(path, 64u << 20, text, len, &e)) {
        fprintf(stderr, "frac: error: %s\n", e.msg);
        return EX_IO;
    }
    if (memchr(*text, 0, *len)) {
        fprintf(stderr, "frac: error: '%s' is not a text file (it contains NUL bytes)\n", path);
        free(*text);
        return EX_SCRIPT;
    }
    return 0;
}

static int set_script_args(interp *I, opts *o)
{
    value l = val_list(I, (size_t)o->nargs);
    if (l.k == V_NIL)
        return -1;
    for (int i = 0; i < o->nargs; i++)
        if (list_push(I, AS_LIST(l), val_cstr(I, o->args[i])))
            return -1;
    const char *name = intern(I, "args", 4);
    return name ? env_define(I, I->globals, name, l) : -1;
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

static int frac_main(int argc, char **argv)
{
    interp st, *I = &st;
    interp_init(I);
    I->threads = par_cores();
    I->progress = 1;
    opts o = {0};
    int i = 1;
    if (i < argc && (strcmp(argv[i], "run") == 0 || strcmp(argv[i], "check") == 0 || strcmp(argv[i], "repl") == 0)) {
        o.mode = argv[i];
        i++;
    }
    param_override *ov = calloc((size_t)argc, sizeof *ov);
    if (!ov)
        return EX_SOFTWARE;
    int nov = 0, rc;
    for (; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        double d;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage_text, stdout);
            free(ov);
            return EX_OK;
        } else if (strcmp(a, "--version") == 0) {
            printf("frac %s\n", FRAC_VERSION);
            free(ov);
            return EX_OK;
        } else if (strcmp(a, "-e") == 0) {
            if (!val) {
                free(ov);
                return usage_error("%s needs an expression", a);
            }
            o.mode = "eval";
            o.expr = val;
            i++;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--out-dir") == 0) {
            if (!val) {
                free(ov);
                return usage_error("%s needs a directory", a);
            }
            I->out_dir = val;
            i++;
        } else if (strncmp(a, "-D", 2) == 0) {
            const char *def = a[2] ? a + 2 : val;
            if (!a[2])
                i++;
            const char *eq = def ? strchr(def, '=') : NULL;
            if (!eq || eq == def) {
                free(ov);
                return usage_error("-D needs NAME=VALUE, got '%s'", def ? def : "");
            }
            ov[nov].name = (const char *)def; /* interned below */
            ov[nov].text = eq + 1;
            nov++;
        } else if (strcmp(a, "--seed") == 0 && val && parse_number(val, 0, 9007199254740991.0, &d) == 0) {
            I->seed = (uint64_t)d;
            i++;
        } else if (strcmp(a, "--threads") == 0 && val && parse_number(val, 1, 256, &d) == 0 && d == (int)d) {
            I->threads = (int)d;
            i++;
        } else if (strcmp(a, "--max-memory") == 0 && val && parse_number(val, 1, 1 << 30, &d) == 0) {
            I->lim.max_memory = (size_t)(d * 1048576.0);
            i++;
        } else if (strcmp(a, "--max-depth") == 0 && val && parse_number(val, 1, 1e300, &d) == 0 &&
                   d > CSTACK_MAX_DEPTH) {
            free(ov);
            return usage_error("--max-depth %s is more than the interpreter's stack holds (at most "
                               CSTACK_STR(CSTACK_MAX_DEPTH) ")", val);
        } else if (strcmp(a, "--max-depth") == 0 && val && parse_number(val, 1, CSTACK_MAX_DEPTH, &d) == 0) {
            I->lim.max_depth = (int)d;
            i++;
        } else if (strcmp(a, "--max-pixels") == 0 && val && parse_number(val, 1, 1e12, &d) == 0) {
            I->lim.max_pixels = d;
            i++;
        } else if (strcmp(a, "--max-points") == 0 && val && parse_number(val, 1, 1e15, &d) == 0) {
            I->lim.max_points = d;
            i++;
        } else if (strcmp(a, "--max-voxels") == 0 && val && parse_number(val, 1, 1e12, &d) == 0) {
            I->lim.max_voxels = d;
            i++;
        } else if (strcmp(a, "--max-list") == 0 && val && parse_number(val, 1, 1e12, &d) == 0) {
            I->lim.max_list = d;
            i++;
        } else if (strcmp(a, "--fail-alloc") == 0 && val && parse_number(val, 1, 1e12, &d) == 0) {
            I->fail_alloc_at = (long)d;
            i++;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            I->quiet = 1;
            I->progress = 0;
        } else if (strcmp(a, "--params") == 0) {
            o.list_params = 1;
        } else if (a[0] == '-' && a[1] != 0) {
            free(ov);
            if (strncmp(a, "--", 2) == 0 && !val)
                return usage_error("option %s is unknown or needs a value", a);
            return usage_error("unknown option or bad value: %s (see --help)", a);
        } else if (!o.mode && (strcmp(a, "run") == 0 || strcmp(a, "check") == 0 || strcmp(a, "repl") == 0)) {
            o.mode = a; /* the command word may follow options */
        } else {
            o.script = a;
            o.args = argv + i + 1;
            o.nargs = argc - i - 1;
            break;
        }
    }
    if (!o.mode)
        o.mode = o.expr ? "eval" : o.script ? "run" : "repl";
    if ((strcmp(o.mode, "run") == 0 || strcmp(o.mode, "check") == 0) && !o.script) {
        free(ov);
        return usage_error("%s needs a script file (or - for standard input)", o.mode);
    }
    if (o.list_params && strcmp(o.mode, "check") != 0) {
        free(ov);
        return usage_error("%s", "--params goes with `frac check`");
    }

    if (session_setup(I)) {
        rc = session_report(I);
        interp_free(I);
        free(ov);
        return rc ? rc : EX_SOFTWARE;
    }
    I->noverrides = nov;
    I->overrides = mem_alloc(I, (size_t)(nov ? nov : 1) * sizeof *I->overrides);
    for (int k = 0; k < nov && I->overrides; k++) {
        const char *eq = strchr(ov[k].name, '=');
        I->overrides[k].name = intern(I, ov[k].name, (size_t)(eq - ov[k].name));
        I->overrides[k].text = ov[k].text;
        I->overrides[k].used = 0;
    }
    free(ov);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    I->interrupt = &interrupted;

    if (strcmp(o.mode, "repl") == 0) {
        rc = repl_main(I, &interrupted);
        interp_free(I);
        return rc;
    }
    if (strcmp(o.mode, "eval") == 0) {
        value v = val_nil();
        rc = EX_OK;
        if (session_run(I, "<-e>", o.expr, strlen(o.expr), 0, &v)) {
            rc = session_report(I);
        } else {
            bytebuf b;
            bytebuf_init(&b);
            val_print(I, v, &b, 1);
            fwrite(b.data, 1, b.len, stdout);
            fputc('\n', stdout);
            bytebuf_free(&b);
        }
        val_unref(I, v);
        interp_free(I);
        return rc;
    }
    unsigned char *text;
    size_t len;
    rc = read_script(o.script, &text, &len);
    if (rc) {
        interp_free(I);
        return rc;
    }
    if (set_script_args(I, &o)) {
        free(text);
        rc = session_report(I);
        interp_free(I);
        return rc;
    }
    const char *name = strcmp(o.script, "-") == 0 ? "<stdin>" : o.script;
    int check = strcmp(o.mode, "check") == 0;
    if (session_run(I, name, (const char *)text, len, check, NULL)) {
        rc = session_report(I);
    } else {
        rc = EX_OK;
        if (check && o.list_params)
            print_params(I);
    }
    free(text);
    fflush(stdout);
    if (ferror(stdout) && rc == EX_OK)
        rc = EX_IO;
    interp_free(I);
    return rc;
}

/* The interpreter runs on a thread with a stack size frac chooses (cstack.h). */
int main(int argc, char **argv) { return cstack_main(frac_main, argc, argv); }
