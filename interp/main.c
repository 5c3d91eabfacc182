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
#include "apng.h"
#include "fit_cli.h"
#include "fileio.h"
#include "lexer.h"
#include "par.h"
#include "parser.h"
#include "recipe.h"
#include "report.h"
#include "repl.h"
#include "session.h"
#include "sha256.h"
#include "watch.h"
#include "shard.h"

enum { EX_OK = 0, EX_USAGE = 64, EX_SCRIPT = 65, EX_SOFTWARE = 70, EX_IO = 74 };

/* errno of a write to standard output that failed before finish_output's
 * flush (which then has nothing left to report) */
static int stdout_errno;

static const char usage_text[] =
    "usage: frac [run] [OPTIONS] SCRIPT.frac [OPTIONS] [ARGS…] [-- ARGS…]\n"
    "                                          run a script; files it names are written\n"
    "       frac check [--params] [OPTIONS] SCRIPT.frac\n"
    "                                          parse and check without running anything\n"
    "       frac info FILE                     print the recipe of a file frac wrote\n"
    "       frac rerun FILE [-o DIR]           render it again from its recipe (same\n"
    "                                          script, params, seed and frame)\n"
    "       frac run --shard I/N|auto [OPTIONS] SCRIPT.frac\n"
    "                                          compute shard I of N of every engine call:\n"
    "                                          writes SCRIPT.shard-I-of-N.part, no images\n"
    "       frac merge [OPTIONS] SCRIPT.frac PART...\n"
    "                                          the files of `frac run SCRIPT.frac` from its\n"
    "                                          parts, byte for byte (docs/scale.md)\n"
    "       frac repl                          interactive session (also: `frac` alone)\n"
    "       frac watch [--show] [OPTIONS] SCRIPT.frac\n"
    "                                          run the script, then again whenever it or a file\n"
    "                                          it imports or loads changes (a render in progress\n"
    "                                          is cancelled); --show previews the first image it\n"
    "                                          saved; Ctrl-C ends it (exit 0)\n"
    "       frac apng -o OUT.png [--delay MS] [--loop N] FRAME.png...\n"
    "                                          assemble PNG frames (same size and format) into\n"
    "                                          an animated PNG: MS per frame (default 40),\n"
    "                                          N plays (default 0: forever)\n"
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
    "  --stats               at the end of a run, print one line on stderr: the wall\n"
    "                        time and each engine's work and rate (on a terminal\n"
    "                        it is printed without --stats, unless --quiet)\n"
    "  --no-recipe           leave the script text out of the recipe that every\n"
    "                        output carries (its hash, params and seed stay)\n"
    "  --frames A..B[:STEP]  run the script once per frame A, A+STEP, … ≤ B, each\n"
    "                        in a fresh interpreter; the names `frame` (the number)\n"
    "                        and `clock` (0 at A, 1 at B) are 0 without it; `%f` in\n"
    "                        an output path is the frame number, zero-padded to the\n"
    "                        width of B; `%%` is a %. See docs/animation.md\n"
    "  --shard I/N | auto    with run: shard I (0 ≤ I < N) of N; auto takes them from\n"
    "                        SLURM_ARRAY_TASK_ID/_COUNT/_MIN, SLURM_PROCID/SLURM_NTASKS,\n"
    "                        OMPI_COMM_WORLD_RANK/_SIZE or PMI_RANK/PMI_SIZE; with\n"
    "                        --frames, one part a frame: SCRIPT.fF.shard-I-of-N.part\n"
    "                        (merge --frames A..B SCRIPT PART... merges every frame)\n"
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
    int no_recipe;      /* --no-recipe */
    int stats;          /* --stats */
    int seed_given;     /* --seed (rerun takes the recipe's) */
    int nargs;
    const char **args;  /* the script's arguments (pointers into argv) */
    param_override *ov; /* -D as typed: name is "NAME=VALUE", text the VALUE */
    int nov;
    const char *frames;           /* --frames A..B[:STEP] as typed; NULL: one plain run */
    long fa, fb, fstep;           /* its numbers */
    const unsigned char *text;    /* the script, read once for all frames (NULL: read it) */
    size_t len;
    const char *delay, *loop;     /* frac apng --delay MS --loop N, as typed */
    int show;                     /* frac watch --show */
    volatile sig_atomic_t *cancel; /* watch: the render's interrupt flag (NULL: the SIGINT flag) */
    const char *shard; /* --shard I/N or auto */
    shard *sh;         /* --shard or merge: kept across re-runs (shard.h) */
} opts;

/* One number of --frames, the n characters at s: an optional '-' and
 * decimal digits, at most FRAME_MAX in size. */
#define FRAME_MAX 999999999L
#define FRAME_COUNT_MAX 100000L
static int frame_number(const char *spec, const char *s, size_t n, long *out)
{
    size_t i = n && *s == '-';
    long v = 0;
    int ok = i < n;
    for (; ok && i < n; i++) {
        ok = s[i] >= '0' && s[i] <= '9' && (v = v * 10 + (s[i] - '0')) <= FRAME_MAX;
    }
    if (!ok) {
        usage_error("--frames %s: '%.*s' is not a whole number from -%ld to %ld", spec, (int)n, s, FRAME_MAX,
                    FRAME_MAX);
        return -1;
    }
    *out = *s == '-' ? -v : v;
    return 0;
}

/* --frames A..B[:STEP]: whole numbers, A <= B, STEP >= 1, at most
 * FRAME_COUNT_MAX frames. Prints the usage error and returns -1 if not. */
static int parse_frames(opts *o)
{
    const char *s = o->frames, *dots = strstr(s, ".."), *colon = dots ? strchr(dots + 2, ':') : NULL;
    long a, b, step = 1;
    if (!dots) {
        usage_error("--frames takes A..B or A..B:STEP (e.g. 0..47 or 0..94:2), got '%s'", s);
        return -1;
    }
    const char *bend = colon ? colon : dots + 2 + strlen(dots + 2);
    if (frame_number(s, s, (size_t)(dots - s), &a) || frame_number(s, dots + 2, (size_t)(bend - dots - 2), &b) ||
        (colon && frame_number(s, colon + 1, strlen(colon + 1), &step)))
        return -1;
    if (b < a) {
        usage_error("--frames %s: the last frame %ld comes before the first %ld", s, b, a);
        return -1;
    }
    if (step < 1) {
        usage_error("--frames %s: the step must be at least 1, got %ld", s, step);
        return -1;
    }
    long count = (b - a) / step + 1;
    if (count > FRAME_COUNT_MAX) {
        usage_error("--frames %s: %ld frames, more than the limit of %ld", s, count, FRAME_COUNT_MAX);
        return -1;
    }
    o->fa = a;
    o->fb = b;
    o->fstep = step;
    return 0;
}

static int is_command(const char *w)
{
    return strcmp(w, "run") == 0 || strcmp(w, "check") == 0 || strcmp(w, "repl") == 0 || strcmp(w, "info") == 0 ||
           strcmp(w, "rerun") == 0 || strcmp(w, "apng") == 0 || strcmp(w, "watch") == 0 || strcmp(w, "merge") == 0;
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
            !strcmp(name, "--quiet") || !strcmp(name, "-q") || !strcmp(name, "--params") ||
            !strcmp(name, "--no-recipe") || !strcmp(name, "--stats") || !strcmp(name, "--show")) {
            if (inline_val)
                return usage_error("%s takes no value (got '%s')", name, a);
            if (!strcmp(name, "--help") || !strcmp(name, "-h")) {
                if (fputs(usage_text, stdout) == EOF) /* longer than stdout's buffer: it fails here */
                    stdout_errno = errno;
                return EX_OK;
            } else if (!strcmp(name, "--version")) {
                printf("frac %s\n", FRAC_VERSION);
                return EX_OK;
            } else if (!strcmp(name, "--params")) {
                o->list_params = 1;
            } else if (!strcmp(name, "--stats")) {
                if (o->stats)
                    return usage_error("%s is given twice", name);
                o->stats = 1;
            } else if (!strcmp(name, "--no-recipe")) {
                if (o->no_recipe)
                    return usage_error("%s is given twice", name);
                o->no_recipe = 1;
            } else if (!strcmp(name, "--show")) {
                if (o->show)
                    return usage_error("%s is given twice", name);
                o->show = 1;
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
        if (!strcmp(name, "--shard")) {
            if (!val || !*val)
                return usage_error("--shard needs a value: I/N or auto");
            if (o->shard)
                return usage_error("--shard is given twice");
            if (!inline_val)
                i++;
            o->shard = val;
            continue;
        }
        int is_e = !strcmp(name, "-e"), is_o = !strcmp(name, "-o") || !strcmp(name, "--out-dir");
        if (!strcmp(name, "--delay") || !strcmp(name, "--loop")) {
            const char **slot = !strcmp(name, "--delay") ? &o->delay : &o->loop;
            if (!val)
                return usage_error("%s needs a value: %s", name,
                                   slot == &o->delay ? "milliseconds per frame" : "a number of plays (0: forever)");
            if (!inline_val)
                i++;
            if (*slot)
                return usage_error("%s is given twice", name);
            *slot = val;
            continue;
        }
        if (!strcmp(name, "--frames")) {
            if (!val)
                return usage_error("--frames needs a value: A..B or A..B:STEP (e.g. 0..47)");
            if (!inline_val)
                i++;
            if (o->frames)
                return usage_error("--frames is given twice");
            o->frames = val;
            if (parse_frames(o))
                return EX_USAGE;
            continue;
        }
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
                o->seed_given |= f == F_SEED;
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
    int info = strcmp(o->mode, "info") == 0, rerun = strcmp(o->mode, "rerun") == 0;
    if ((info || rerun) && !o->script)
        return usage_error("%s needs a file that frac wrote (frac %s FILE)", o->mode, o->mode);
    if ((info || rerun) && o->nargs)
        return usage_error("%s takes one file (got '%s' too)", o->mode, o->args[0]);
    if ((info || rerun) && (o->nov || o->seed_given))
        return usage_error("%s takes the params and the seed from the file's recipe (%s given)", o->mode,
                           o->nov ? "-D" : "--seed");
    if (o->stats && strcmp(o->mode, "run") != 0 && !rerun)
        return usage_error("--stats goes with running a script (frac SCRIPT or frac rerun FILE), not %s",
                           strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (o->no_recipe && strcmp(o->mode, "check") == 0)
        return usage_error("%s", "--no-recipe is for runs that write files; check writes none");
    if (info && (I->out_dir || o->no_recipe))
        return usage_error("info only reads the file (%s does not go with it)", I->out_dir ? "-o" : "--no-recipe");
    if (strcmp(o->mode, "apng") == 0) {
        if (!o->script)
            return usage_error("%s", "apng needs frames: frac apng -o OUT.png FRAME.png...");
        if (!I->out_dir)
            return usage_error("%s", "apng needs -o OUT.png, the file to write");
        if (o->nov || o->frames || o->list_params)
            return usage_error("%s does not go with `frac apng`", o->nov ? "-D" : o->frames ? "--frames" : "--params");
    } else if (o->delay || o->loop) {
        return usage_error("%s goes with `frac apng`", o->delay ? "--delay" : "--loop");
    }
    if (o->show && strcmp(o->mode, "watch") != 0)
        return usage_error("%s", "--show goes with `frac watch` (in a script or the REPL, use show(image))");
    if (strcmp(o->mode, "watch") == 0 && (!o->script || strcmp(o->script, "-") == 0))
        return usage_error("%s", "watch needs a script file to watch: frac watch SCRIPT.frac [-o DIR] [-D NAME=VALUE]");
    if (o->frames && strcmp(o->mode, "run") != 0 && strcmp(o->mode, "merge") != 0)
        return usage_error("--frames goes with `frac run` (frac run --frames A..B SCRIPT), not with %s",
                           strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (strcmp(o->mode, "merge") == 0 && (!o->script || !o->nargs))
        return usage_error("merge needs the script and its part files: frac merge [-o DIR] SCRIPT.frac PART...");
    if (o->shard && strcmp(o->mode, "run") != 0)
        return usage_error("--shard goes with `frac run`, not `%s`", strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (o->shard && !strcmp(o->script, "-"))
        return usage_error("--shard needs a script file, not standard input");
    if (o->shard && o->nargs)
        return usage_error("--shard runs a script without arguments (got '%s'): merge could not give them to it",
                           o->args[0]);
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
    int e = errno ? errno : stdout_errno;
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

/* ---- recipes: what every output carries, frac info, frac rerun ------------------------- */

/* The recipe of this run (recipe.h), handed to the writers. text NULL: no
 * script (the REPL). */
/* Frame f of the range a..b:step: the names `frame` and `clock`, what %f
 * becomes, and the range for the recipe (run_frames, and rerun of a frame). */
static void set_frame(interp *I, long f, long a, long b, long step)
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

static int install_recipe(interp *I, const opts *o, const char *path, const char *text, size_t len,
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

static int info_main(const char *path)
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
static int rerun_prepare(interp *I, opts *o, recipe *r, char **text, size_t *len)
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
                              : "its recipe was written with --no-recipe (or from the REPL) and has no script text");
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
        set_frame(I, r->frame, r->frames_range ? r->frames_a : r->frame, r->frames_range ? r->frames_b : r->frame,
                  r->frames_range ? r->frames_step : 1);
    session_set_frame(I);
    o->script = r->script_path;
    *text = r->script;
    *len = r->script_len;
    return 0;
}

static int run_script(interp *I, opts *o, int check, unsigned char *text, size_t len);

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

static int run_frac(interp *I, opts *o)
{
    int rc;
    if (session_setup(I)) {
        rc = session_report(I);
        return rc ? rc : EX_SOFTWARE;
    }
    if (set_overrides(I, o))
        return session_report(I);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    fileio_install_signal_cleanup();
    I->interrupt = o->cancel ? o->cancel : &interrupted;

    int check = strcmp(o->mode, "check") == 0;
    if (strcmp(o->mode, "info") == 0)
        return info_main(o->script);
    if (strcmp(o->mode, "repl") == 0) {
        if (I->out_dir && (rc = make_out_dir(I->out_dir)))
            return rc;
        recipe_store st;
        if (install_recipe(I, o, "<repl>", NULL, 0, &st))
            return session_report(I);
        rc = repl_main(I, &interrupted);
        recipe_uninstall(&st);
        return rc;
    }
    if (strcmp(o->mode, "eval") == 0) {
        if (I->out_dir && (rc = make_out_dir(I->out_dir)))
            return rc;
        value v = val_nil();
        rc = EX_OK;
        recipe_store st;
        if (install_recipe(I, o, "<-e>", o->expr, strlen(o->expr), &st))
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
    if (o->text) { /* --frames: read once, freed by run_frames */
        text = (unsigned char *)o->text;
        len = o->len;
    } else if (rerun) {
        char *t = NULL;
        if ((rc = rerun_prepare(I, o, &rr, &t, &len))) {
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
    rc = run_script(I, o, check, text, len);
    if (!o->text)
        rt_free(text);
    recipe_free(&rr);
    return rc;
}

/* Run (or check) the script text: the common tail of run, check, rerun,
 * each frame of --frames and each render of watch. */
static int run_script(interp *I, opts *o, int check, unsigned char *text, size_t len)
{
    int rc;
    const char *name = strcmp(o->script, "-") == 0 ? "<stdin>" : o->script;
    if (set_script_args(I, o) || (o->nov && check_overrides(I, name, (const char *)text, len)))
        return session_report(I);
    if (!check && I->out_dir && (rc = make_out_dir(I->out_dir)))
        return rc;
    recipe_store st;
    if (!check && install_recipe(I, o, o->script, (const char *)text, len, &st))
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
static void fresh_interp(interp *I, const interp *T)
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
    fresh_interp(I, c->T);
    c->o->cancel = cancel;
    int rc = run_frac(I, c->o);
    if (rc == 130 && *cancel)
        rc = 0; /* cancelled: watch_main starts again or stops */
    interp_free(I);
    rt_alloc_set_hook(&c->T->hook);
    return rc;
}

static int run_watch(interp *T, opts *o)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    fileio_install_signal_cleanup();
    watch_ctx c = {T, o};
    int rc = watch_main(T, watch_render, &c, &interrupted, o->show, T->quiet);
    return rc < 0 ? session_report(T) : rc;
}

/* frac apng -o OUT.png [--delay MS] [--loop N] FRAME.png...: the frames'
 * image data copied into one animated PNG (runtime/apng.h); every frame is
 * checked before anything is written. */
static int run_apng(interp *I, opts *o)
{
    apng_opts ao = {APNG_DEFAULT_DELAY_MS, 0};
    double d;
    if (o->delay && parse_whole(o->delay, 0, APNG_MAX_DELAY_MS, &d))
        return usage_error("--delay takes a whole number of milliseconds from 0 to %d, got '%s'", APNG_MAX_DELAY_MS,
                           o->delay);
    if (o->delay)
        ao.delay_ms = (int)d;
    if (o->loop && parse_whole(o->loop, 0, APNG_MAX_LOOP, &d))
        return usage_error("--loop takes a whole number of plays from 0 (forever) to %d, got '%s'", APNG_MAX_LOOP,
                           o->loop);
    if (o->loop)
        ao.loop = (long)d;
    int n = 1 + o->nargs;
    const char **names = mem_calloc(I, (size_t)n, sizeof *names);
    unsigned char **data = mem_calloc(I, (size_t)n, sizeof *data);
    size_t *lens = mem_calloc(I, (size_t)n, sizeof *lens);
    int rc = names && data && lens ? EX_OK : session_report(I);
    rt_error e;
    for (int i = 0; i < n && rc == EX_OK; i++) {
        names[i] = i ? o->args[i - 1] : o->script;
        rt_code c = fileio_read_all(names[i], (size_t)1 << 30, &data[i], &lens[i], &e);
        if (c) {
            fprintf(stderr, "frac: error: %s\n", e.msg);
            rc = c == RT_ENOMEM ? EX_SOFTWARE : EX_IO;
        }
    }
    if (rc == EX_OK) {
        bytebuf b;
        bytebuf_init(&b);
        rt_code c = apng_assemble((const unsigned char *const *)data, lens, n, names, &ao, &b, &e);
        if (!c)
            c = fileio_write_atomic(I->out_dir, b.data, b.len, &e);
        bytebuf_free(&b);
        if (c) {
            fprintf(stderr, "frac: error: %s\n", e.msg);
            rc = c == RT_ENOMEM ? EX_SOFTWARE : c == RT_EIO ? EX_IO : EX_SCRIPT;
        } else if (!I->quiet) {
            fprintf(stderr, "wrote %s (%d frames)\n", I->out_dir, n);
        }
    }
    for (int i = 0; data && i < n; i++)
        rt_free(data[i]);
    mem_free(I, names);
    mem_free(I, data);
    mem_free(I, lens);
    return rc;
}

/* --frames A..B:STEP: the script once per frame, each in a fresh interpreter
 * set up like a plain run (the same -D, --seed, -o, limits), so frame N is
 * byte for byte what `--frames N..N` gives for a script that reads `frame`
 * (`clock` is 0 for a single frame). Stops at the first frame that fails. */
static int run_frames(interp *T, opts *o)
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
        if (interrupted) {
            rc = 130;
            break;
        }
        if (tty)
            fprintf(stderr, "frame %ld (%ld of %ld)\n", f, k + 1, count);
        if (o->sh) /* --shard or merge: each frame its own calls and re-runs (shard.h) */
            shard_new_frame(o->sh);
        do {
            interp st, *I = &st;
            fresh_interp(I, T);
            set_frame(I, f, o->fa, o->fb, o->fstep);
            rc = run_frac(I, o);
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

static int frac_main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "fit") == 0) { /* its own options (interp/bind_fit.c) */
        interp st, *I = &st;
        interp_init(I);
        I->threads = par_cores();
        I->progress = 1;
        int frc = fit_command(I, argc - 1, argv + 1, &interrupted);
        interp_free(I);
        return finish_output(frc);
    }
    shard sh; /* --shard / merge: lives across the re-runs, each in a fresh interpreter */
    int rc, again = 0;
    do {
        interp st, *I = &st;
        interp_init(I);
        I->threads = par_cores();
        I->progress = 1;
        opts o = {0};
        o.args = mem_calloc(I, (size_t)argc, sizeof *o.args);
        o.ov = mem_calloc(I, (size_t)argc, sizeof *o.ov);
        rc = EX_SOFTWARE;
        if (o.args && o.ov) {
            rc = parse_command_line(I, argc, argv, &o);
            if (rc < 0 && !again) {
                if (o.shard && shard_init_run(&sh, o.shard))
                    rc = EX_USAGE;
                else if (!strcmp(o.mode, "merge"))
                    shard_init_merge(&sh, (char *const *)o.args, o.nargs);
            }
            if (rc < 0 && !strcmp(o.mode, "merge"))
                o.nargs = 0; /* the words after the script are its parts, not its `args` */
            if (rc < 0) {
                o.sh = o.shard || !strcmp(o.mode, "merge") ? &sh : NULL;
                rc = o.frames                       ? run_frames(I, &o)
                     : strcmp(o.mode, "apng") == 0  ? run_apng(I, &o)
                     : strcmp(o.mode, "watch") == 0 ? run_watch(I, &o)
                                                    : run_frac(I, &o);
                again = o.sh && sh.again;
            }
        }
        mem_free(I, o.args);
        mem_free(I, o.ov);
        interp_free(I);
    } while (again);
    return finish_output(rc);
}

/* The interpreter runs on a thread with a stack size frac chooses (cstack.h). */
int main(int argc, char **argv) { return cstack_main(frac_main, argc, argv); }
