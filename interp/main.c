/* main.c — the command line: usage, options, the commands' dispatch (the
 * commands themselves are in cli_run.c and cli_recipe.c: cli.h). The only
 * place that exits.
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

#include "cli.h"
#include "cstack.h"
#include "fileio.h"
#include "fit_cli.h"
#include "par.h"
#include "session.h"
#include "shard.h"

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
    "                [--rifs] [--foreground auto|dark|light|alpha] [--threshold T]\n"
    "                [--threads N] [-q] [-o FIT.frac]\n"
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
    "                        SLURM_ARRAY_TASK_ID/_COUNT/_MIN/_STEP, OMPI_COMM_WORLD_RANK/\n"
    "                        _SIZE, PMI_RANK/PMI_SIZE or SLURM_PROCID/SLURM_NTASKS; with\n"
    "                        --frames, one part a frame: SCRIPT.fF.shard-I-of-N.part\n"
    "                        (merge --frames A..B SCRIPT PART... merges every frame)\n"
    "limits (whole numbers ≥ 1; a script that exceeds one stops with an error\n"
    "naming it):\n"
    "  --max-memory MIB      all memory: values, images, volumes, engine buffers (default 4096)\n"
    "  --max-depth N         function call depth (default 1000, at most " CSTACK_STR(CSTACK_MAX_DEPTH) ")\n"
    "  --max-pixels N        pixels per image (default 64000000)\n"
    "  --max-points N        points per chaos game or sampling (default 1e10)\n"
    "                        (also each loss evaluation of fit() and show()'s IFS preview)\n"
    "  --max-voxels N        voxels per volume, lattice nodes per fractal() array\n"
    "                        (default 134217728 = 512^3)\n"
    "  --max-list N          items per list (default 1e8)\n"
    "\n"
    "exit codes: 0 ok, 64 usage, 65 script error, 70 runtime failure, 74 I/O error\n"
    "(also when standard output cannot be written), 130 interrupted.\n"
    "Documentation: docs/language.md.\n";

volatile sig_atomic_t cli_interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    if (cli_interrupted) { /* a second Ctrl-C stops at once, leaving no temp file */
        fileio_cleanup_temps();
        _exit(130);
    }
    cli_interrupted = 1;
}

void cli_catch_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    fileio_install_signal_cleanup();
}

int cli_usage_error(const char *fmt, ...)
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
int cli_parse_whole(const char *s, double lo, double hi, double *out)
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
        cli_usage_error("--frames %s: '%.*s' is not a whole number from -%ld to %ld", spec, (int)n, s, FRAME_MAX,
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
        cli_usage_error("--frames takes A..B or A..B:STEP (e.g. 0..47 or 0..94:2), got '%s'", s);
        return -1;
    }
    const char *bend = colon ? colon : dots + 2 + strlen(dots + 2);
    if (frame_number(s, s, (size_t)(dots - s), &a) || frame_number(s, dots + 2, (size_t)(bend - dots - 2), &b) ||
        (colon && frame_number(s, colon + 1, strlen(colon + 1), &step)))
        return -1;
    if (b < a) {
        cli_usage_error("--frames %s: the last frame %ld comes before the first %ld", s, b, a);
        return -1;
    }
    if (step < 1) {
        cli_usage_error("--frames %s: the step must be at least 1, got %ld", s, step);
        return -1;
    }
    long count = (b - a) / step + 1;
    if (count > FRAME_COUNT_MAX) {
        cli_usage_error("--frames %s: %ld frames, more than the limit of %ld", s, count, FRAME_COUNT_MAX);
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
                return cli_usage_error("%s takes no value (got '%s')", name, a);
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
                    return cli_usage_error("%s is given twice", name);
                o->stats = 1;
            } else if (!strcmp(name, "--no-recipe")) {
                if (o->no_recipe)
                    return cli_usage_error("%s is given twice", name);
                o->no_recipe = 1;
            } else if (!strcmp(name, "--show")) {
                if (o->show)
                    return cli_usage_error("%s is given twice", name);
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
                return cli_usage_error("-D needs NAME=VALUE, got '%s'", def ? def : "");
            for (int k = 0; k < o->nov; k++) {
                const char *prev = o->ov[k].name;
                size_t l = (size_t)(deq - def);
                if (strncmp(prev, def, l) == 0 && prev[l] == '=')
                    return cli_usage_error("-D %.*s is given twice (%s and %s)", (int)l, def, prev, def);
            }
            o->ov[o->nov].name = def; /* interned once the interpreter is set up */
            o->ov[o->nov].text = deq + 1;
            o->nov++;
            continue;
        }
        if (!strcmp(name, "--shard")) {
            if (!val || !*val)
                return cli_usage_error("--shard needs a value: I/N or auto");
            if (o->shard)
                return cli_usage_error("--shard is given twice");
            if (!inline_val)
                i++;
            o->shard = val;
            continue;
        }
        int is_e = !strcmp(name, "-e"), is_o = !strcmp(name, "-o") || !strcmp(name, "--out-dir");
        if (!strcmp(name, "--delay") || !strcmp(name, "--loop")) {
            const char **slot = !strcmp(name, "--delay") ? &o->delay : &o->loop;
            if (!val)
                return cli_usage_error("%s needs a value: %s", name,
                                   slot == &o->delay ? "milliseconds per frame" : "a number of plays (0: forever)");
            if (!inline_val)
                i++;
            if (*slot)
                return cli_usage_error("%s is given twice", name);
            *slot = val;
            continue;
        }
        if (!strcmp(name, "--frames")) {
            if (!val)
                return cli_usage_error("--frames needs a value: A..B or A..B:STEP (e.g. 0..47)");
            if (!inline_val)
                i++;
            if (o->frames)
                return cli_usage_error("--frames is given twice");
            o->frames = val;
            if (parse_frames(o))
                return EX_USAGE;
            continue;
        }
        if (is_e || is_o || f < NNUM) {
            const char *what = is_e ? "an expression" : is_o ? "a folder" : numflags[f].range;
            if (!val)
                return cli_usage_error("%s needs a value: %s", name, what);
            if (!inline_val)
                i++;
            if ((is_e && o->expr) || (is_o && seen_o) || (f < NNUM && seen[f]))
                return cli_usage_error("%s is given twice", name);
            if (is_e) {
                o->expr = val;
            } else if (is_o) {
                if (!*val)
                    return cli_usage_error("%s needs a value: %s", name, what);
                I->out_dir = val;
                seen_o = 1;
            } else {
                double d;
                if (cli_parse_whole(val, numflags[f].lo, numflags[f].hi, &d))
                    return cli_usage_error("%s takes %s, got '%s'", name, what, val);
                set_numflag(I, f, d);
                seen[f] = 1;
                o->seed_given |= f == F_SEED;
            }
            continue;
        }
        if (o->script)
            return cli_usage_error("unknown option '%s' after the script (to give it to the script in `args`, "
                               "put it after `--`: frac %s -- %s)",
                               a, o->script, a);
        return cli_usage_error("unknown option '%s'", a);
    }

    if (o->expr) {
        if (o->mode)
            return cli_usage_error("-e does not go with `%s`", o->mode);
        if (o->script)
            return cli_usage_error("-e takes no script or arguments (got '%s')", o->script);
        o->mode = "eval";
    }
    if (!o->mode)
        o->mode = o->script ? "run" : "repl";
    if (strcmp(o->mode, "repl") == 0 && o->script)
        return cli_usage_error("repl takes no script (got '%s'; run it with `frac %s`, or :load it in the REPL)",
                           o->script, o->script);
    if ((strcmp(o->mode, "run") == 0 || strcmp(o->mode, "check") == 0) && !o->script)
        return cli_usage_error("%s needs a script file (or - for standard input)", o->mode);
    int info = strcmp(o->mode, "info") == 0, rerun = strcmp(o->mode, "rerun") == 0;
    if ((info || rerun) && !o->script)
        return cli_usage_error("%s needs a file that frac wrote (frac %s FILE)", o->mode, o->mode);
    if ((info || rerun) && o->nargs)
        return cli_usage_error("%s takes one file (got '%s' too)", o->mode, o->args[0]);
    if ((info || rerun) && (o->nov || o->seed_given))
        return cli_usage_error("%s takes the params and the seed from the file's recipe (%s given)", o->mode,
                           o->nov ? "-D" : "--seed");
    if (o->stats && strcmp(o->mode, "run") != 0 && !rerun)
        return cli_usage_error("--stats goes with running a script (frac SCRIPT or frac rerun FILE), not %s",
                           strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (o->no_recipe && strcmp(o->mode, "check") == 0)
        return cli_usage_error("%s", "--no-recipe is for runs that write files; check writes none");
    if (info && (I->out_dir || o->no_recipe))
        return cli_usage_error("info only reads the file (%s does not go with it)", I->out_dir ? "-o" : "--no-recipe");
    if (strcmp(o->mode, "apng") == 0) {
        if (!o->script)
            return cli_usage_error("%s", "apng needs frames: frac apng -o OUT.png FRAME.png...");
        if (!I->out_dir)
            return cli_usage_error("%s", "apng needs -o OUT.png, the file to write");
        if (o->nov || o->frames || o->list_params)
            return cli_usage_error("%s does not go with `frac apng`", o->nov ? "-D" : o->frames ? "--frames" : "--params");
    } else if (o->delay || o->loop) {
        return cli_usage_error("%s goes with `frac apng`", o->delay ? "--delay" : "--loop");
    }
    if (o->show && strcmp(o->mode, "watch") != 0)
        return cli_usage_error("%s", "--show goes with `frac watch` (in a script or the REPL, use show(image))");
    if (strcmp(o->mode, "watch") == 0 && (!o->script || strcmp(o->script, "-") == 0))
        return cli_usage_error("%s", "watch needs a script file to watch: frac watch SCRIPT.frac [-o DIR] [-D NAME=VALUE]");
    if (o->frames && strcmp(o->mode, "run") != 0 && strcmp(o->mode, "merge") != 0)
        return cli_usage_error("--frames goes with `frac run` (frac run --frames A..B SCRIPT), not with %s",
                           strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (strcmp(o->mode, "merge") == 0 && (!o->script || !o->nargs))
        return cli_usage_error("merge needs the script and its part files: frac merge [-o DIR] SCRIPT.frac PART...");
    if (o->shard && strcmp(o->mode, "run") != 0)
        return cli_usage_error("--shard goes with `frac run`, not `%s`", strcmp(o->mode, "eval") == 0 ? "-e" : o->mode);
    if (o->shard && !strcmp(o->script, "-"))
        return cli_usage_error("--shard needs a script file, not standard input");
    if (o->shard && o->nargs)
        return cli_usage_error("--shard runs a script without arguments (got '%s'): merge could not give them to it",
                           o->args[0]);
    if (o->list_params && strcmp(o->mode, "check") != 0)
        return cli_usage_error("%s", "--params goes with `frac check`");
    if (o->nov && (strcmp(o->mode, "eval") == 0 || strcmp(o->mode, "repl") == 0))
        return cli_usage_error("-D sets a param of a script (frac SCRIPT -D NAME=VALUE); %s has none",
                           strcmp(o->mode, "eval") == 0 ? "-e" : "the REPL");
    return -1;
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

static int frac_main(int argc, char **argv)
{
    int fit_at = bind_fit_command_index(argc, argv);
    if (fit_at) { /* its own options, before or after the word fit (interp/bind_fit.c) */
        interp st, *I = &st;
        interp_init(I);
        I->threads = par_cores();
        I->progress = 1;
        int frc = bind_fit_command(I, argc, argv, fit_at, &cli_interrupted);
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
                rc = o.frames                       ? cli_run_frames(I, &o)
                     : strcmp(o.mode, "apng") == 0  ? cli_run_apng(I, &o)
                     : strcmp(o.mode, "watch") == 0 ? cli_run_watch(I, &o)
                                                    : cli_run_frac(I, &o);
                again = o.sh && sh.again;
            }
        }
        mem_free(I, o.args);
        mem_free(I, o.ov);
        long made = I->alloc_count;
        if (I->fail_alloc_at && made < I->fail_alloc_at) /* tells the fail-alloc loop (tests/runner.c) it is past the end */
            fprintf(stderr, "frac: note: --fail-alloc %ld was not reached: the run made %ld allocations\n",
                    I->fail_alloc_at, made);
        interp_free(I);
    } while (again);
    return finish_output(rc);
}

/* The interpreter runs on a thread with a stack size frac chooses (cstack.h). */
int main(int argc, char **argv) { return cstack_main(frac_main, argc, argv); }
