/* cli.h — what the command line's files share: the parsed options and the
 * commands, each in its own file.
 *
 *   main.c        usage, options, the command line, signals, exit codes
 *   cli_run.c     run, check, -e, repl, --frames, watch: reading the script
 *                 and running it in an interpreter (a fresh one per frame
 *                 and per watch render)
 *   cli_recipe.c  recipes (what every output carries), frac info, frac
 *                 rerun (also of an APNG), frac apng
 *
 * Nothing here exits: main.c turns the returned codes into the exit code. */
#ifndef CLI_H
#define CLI_H

#include <signal.h>
#include <stddef.h>

#include "apng.h"
#include "recipe.h"
#include "shard.h"
#include "state.h"

enum { EX_OK = 0, EX_USAGE = 64, EX_SCRIPT = 65, EX_SOFTWARE = 70, EX_IO = 74 };

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

/* SIGINT sets cli_interrupted (a second one exits 130 at once, leaving no
 * temp file); SIGTERM and SIGHUP remove temp files (fileio.h).
 * cli_catch_signals installs both. */
extern volatile sig_atomic_t cli_interrupted;
void cli_catch_signals(void);
/* Print "frac: MESSAGE" and the --help hint; returns 64. */
__attribute__((format(printf, 1, 2))) int cli_usage_error(const char *fmt, ...);
/* A whole number in [lo, hi] written in decimal; 0, or -1. */
int cli_parse_whole(const char *s, double lo, double hi, double *out);

/* cli_run.c */
/* run, check, -e, repl, info or rerun (o->mode) in I. */
int cli_run_frac(interp *I, opts *o);
/* Run (or check) the script text: the common tail of run, check, rerun,
 * each frame of --frames and each render of watch. */
int cli_run_script(interp *I, opts *o, int check, unsigned char *text, size_t len);
/* A new interpreter set up as T (limits, seed, threads, -o, output flags). */
void cli_fresh_interp(interp *I, const interp *T);
int cli_run_frames(interp *T, opts *o);
int cli_run_watch(interp *T, opts *o);
/* -o DIR: create the folder and its parents. 0, or the exit code. */
int cli_make_out_dir(const char *dir);

/* cli_recipe.c */
/* Frame f of the range a..b:step: `frame`, `clock`, the width of %f. */
void cli_set_frame(interp *I, long f, long a, long b, long step);
/* The recipe of this run handed to the writers (text NULL: no script text). */
int cli_install_recipe(interp *I, const opts *o, const char *path, const char *text, size_t len, recipe_store *st);
int cli_info(const char *path);
/* frac rerun FILE: the recipe's script, params, args, seed and frame become
 * this run's; *text its script. 0, or the exit code. */
int cli_rerun_prepare(interp *I, opts *o, recipe *r, char **text, size_t *len);
/* frac rerun of an APNG that frac apng assembled. */
int cli_rerun_apng(interp *T, opts *o, recipe *r);
int cli_run_apng(interp *I, opts *o);

/* The REPL's recipe: the session so far as a script (repl.h). */
typedef struct cli_repl_recipe {
    interp *I;
    const opts *o;
    recipe_store st;
    int installed;
} cli_repl_recipe;
int cli_repl_set_recipe(void *ud, const char *text, size_t len);

#endif
