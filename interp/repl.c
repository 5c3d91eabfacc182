/* repl.c — the read-eval-print loop.
 *
 * On a terminal: prompts, line editing and history (runtime/lineedit), `..`
 * continuation prompts for incomplete input, Ctrl-C cancels a line or
 * interrupts a running evaluation. Piped: no prompts and no escape
 * sequences; values to stdout one per line, errors to stderr, and the exit
 * code is 65 if any input failed, so sessions can be tested by piping.
 *
 * Entries are parsed exactly as a script would parse the same lines. A
 * script's expression may go on after a line break when the next line starts
 * with 'elif', 'else' or '|>' (parse_if, parse_binary). Piped input is read
 * one line ahead to see that. A terminal cannot be read ahead, so there a
 * line starting with one of those tokens joins the entry before it: the
 * global bindings that entry changed are put back and the joined text runs
 * as one entry (docs/repl.md). Input that ends inside an open construct is
 * the parser's error (65); a read error on standard input or a failed write
 * to standard output is 74.
 */
#include "repl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "builtin.h"
#include "contract.h"
#include "eval.h"
#include "fileio.h"
#include "lexer.h"
#include "lineedit.h"
#include "parser.h"
#include "session.h"

typedef struct repl {
    interp *I;
    lineedit *le;
    int tty;      /* stdin and stdout are terminals: prompts, banner */
    int in_tty;   /* stdin is a terminal: no reading ahead */
    int line_no;  /* session line number of the next input line */
    int failed;   /* an entry failed: exit 65 when piped */
    int io_error; /* reading stdin or writing stdout failed: exit 74 */
    char **ahead; /* lines read ahead (piped), oldest first */
    size_t nahead, capahead;
    /* the previous entry (terminal), for a line that continues it */
    char *prev_text;
    int prev_first;
    value *snap; /* global values before it ran, one per binding then */
    size_t nsnap;
    /* the session as a script, for the recipe (repl.h) */
    bytebuf log;
    size_t prev_mark; /* log's length before the previous entry */
    repl_recipe_fn recipe;
    void *recipe_ud;
} repl;

/* Add an entry's text to the log and install the recipe with it. Returns
 * the log's length before, for log_end; -1 when the recipe could not be
 * built (reported; the entry must not run). */
static long log_begin(repl *r, const char *text, size_t len)
{
    size_t mark = r->log.len;
    if (!r->recipe)
        return (long)mark;
    bytebuf_append(&r->log, text, len);
    if (len && text[len - 1] != '\n')
        bytebuf_byte(&r->log, '\n');
    bytebuf_byte(&r->log, 0); /* NUL-terminated for the recipe's scan for clock */
    r->log.len--;
    if (r->log.failed || r->recipe(r->recipe_ud, (const char *)r->log.data, r->log.len)) {
        r->log.failed = 0;
        r->log.len = mark;
        if (r->log.data)
            r->log.data[mark] = 0;
        fprintf(stderr, "error: out of memory building the recipe of the session\n");
        r->failed = 1;
        return -1;
    }
    return (long)mark;
}

/* After the entry: it stays in the log if it ran without error; otherwise
 * the log (and the recipe) go back to what they were. */
static void log_end(repl *r, long mark, int ok)
{
    if (!r->recipe || ok || mark < 0)
        return;
    r->log.len = (size_t)mark;
    if (r->log.data)
        r->log.data[mark] = 0;
    if (r->recipe(r->recipe_ud, (const char *)r->log.data, r->log.len))
        fprintf(stderr, "error: out of memory building the recipe of the session\n");
}

/* The tokens that continue a script's expression from the line before. */
static int continues_previous(tok_type t) { return t == T_ELIF || t == T_ELSE || t == T_PIPE; }

/* The type of the first token of a line (T_EOF for blank or comment lines). */
static tok_type first_token(const char *line)
{
    token_list tl;
    if (lex_all(line, 0, 1, &tl))
        return T_EOF;
    tok_type t = (tok_type)tl.toks[0].type;
    lex_free(&tl);
    return t;
}

/* Read one line (without the newline) into a malloc'd string; NULL at the
 * end of input or on a read error (r->io_error). Ctrl-C on a terminal
 * cancels the line: *cancelled is set and an empty line is returned. */
static char *read_line(repl *r, const char *prompt, int *cancelled)
{
    *cancelled = 0;
    if (r->nahead && prompt) {
        char *l = r->ahead[0];
        memmove(r->ahead, r->ahead + 1, --r->nahead * sizeof *r->ahead);
        return l;
    }
    char *line = NULL;
    for (;;) {
        lineedit_result res = lineedit_read(r->le, prompt ? prompt : "", &line);
        if (res == LINEEDIT_LINE)
            return line;
        if (res == LINEEDIT_INTERRUPT) {
            if (!r->tty)
                continue;
            *cancelled = 1;
            line = rt_malloc(1); /* like lineedit's lines: freed with rt_free */
            if (line)
                line[0] = 0;
            return line;
        }
        if (res == LINEEDIT_ERROR) {
            fprintf(stderr, "frac: %s\n", lineedit_errmsg(r->le));
            r->io_error = 1;
        }
        return NULL;
    }
}

/* Piped input: read ahead past blank and comment lines to the next line
 * with a token. If it continues the entry (see continues_previous), append
 * the comment lines and it to *text and return 1; otherwise keep the lines
 * for read_line and return 0. */
static int join_next(repl *r, char **text, size_t *len)
{
    for (;;) {
        size_t k = r->nahead;
        tok_type t = T_EOF;
        if (k && (t = first_token(r->ahead[k - 1])) != T_EOF)
            break;
        int cancelled;
        char *line = read_line(r, NULL, &cancelled); /* NULL: past the lines read ahead */
        if (!line)
            return 0;
        if (r->nahead == r->capahead) {
            size_t nc = r->capahead ? 2 * r->capahead : 8;
            char **na = rt_realloc(r->ahead, nc * sizeof *na);
            if (!na) {
                rt_free(line);
                return 0;
            }
            r->ahead = na;
            r->capahead = nc;
        }
        r->ahead[r->nahead++] = line;
    }
    if (!continues_previous(first_token(r->ahead[r->nahead - 1])))
        return 0;
    /* take every line read ahead; empty lines are not counted (as at the prompt) */
    for (size_t i = 0; i < r->nahead; i++) {
        char *l = r->ahead[i];
        size_t ml = strlen(l);
        if (ml) {
            char *nt = rt_realloc(*text, *len + ml + 2);
            if (!nt) {
                for (; i < r->nahead; i++)
                    rt_free(r->ahead[i]);
                r->nahead = 0;
                return 0;
            }
            *text = nt;
            nt[*len] = '\n';
            memcpy(nt + *len + 1, l, ml + 1);
            *len += ml + 1;
            r->line_no++;
        }
        rt_free(l);
    }
    r->nahead = 0;
    return 1;
}

/* Terminal: remember the global values before an entry runs, so that a
 * continuation line can put them back and run the joined entry. */
static void snap_drop(repl *r)
{
    for (size_t i = 0; i < r->nsnap; i++)
        val_unref(r->I, r->snap[i]);
    rt_free(r->snap);
    r->snap = NULL;
    r->nsnap = 0;
}

static void snap_take(repl *r)
{
    snap_drop(r);
    env *g = r->I->globals;
    if (!g->n || !(r->snap = rt_malloc(g->n * sizeof *r->snap)))
        return;
    for (size_t i = 0; i < g->n; i++) {
        r->snap[i] = g->vals[i];
        val_ref(g->vals[i]);
    }
    r->nsnap = g->n;
}

/* Bindings made by the entry after the snapshot stay (the joined entry
 * defines them again); those it changed get their old values back. */
static void snap_restore(repl *r)
{
    env *g = r->I->globals;
    for (size_t i = 0; i < r->nsnap && i < g->n; i++) {
        val_unref(r->I, g->vals[i]);
        g->vals[i] = r->snap[i];
    }
    for (size_t i = g->n; i < r->nsnap; i++)
        val_unref(r->I, r->snap[i]);
    rt_free(r->snap);
    r->snap = NULL;
    r->nsnap = 0;
}

static void forget_prev(repl *r)
{
    rt_free(r->prev_text);
    r->prev_text = NULL;
    snap_drop(r);
}

static void print_value(repl *r, value v)
{
    if (v.k == V_NIL)
        return;
    bytebuf b;
    bytebuf_init(&b);
    val_print(r->I, v, &b, 1);
    bytebuf_byte(&b, '\n');
    fwrite(b.data, 1, b.len, stdout);
    fflush(stdout);
    bytebuf_free(&b);
}

static void report(repl *r)
{
    session_report(r->I);
    err_clear(r->I);
    r->I->depth = 0;
    r->failed = 1;
}

static const char help_text[] =
    "Commands:\n"
    "  :help [NAME]   this list, or the signature and description of a builtin\n"
    "  :load FILE     run a script in this session\n"
    "  :reset         forget every definition\n"
    "  :vars          list the names defined in this session\n"
    "  :time EXPR     evaluate and print how long it took\n"
    "  :show NAME     preview an image (or anything showable) in the terminal\n"
    "  :quit          leave (also Ctrl-D on an empty line)\n"
    "Type any statement or expression; bare expressions print their value.\n"
    "Unfinished input continues on a '..' line; a line starting with elif, else\n"
    "or |> continues the entry before it (which then runs again, joined).\n"
    "frame and clock are 0 here; `frac run --frames A..B` sets them (:help frame).\n"
    "Files you save carry the session so far as their recipe: `frac rerun FILE`\n"
    "makes them again (entries that failed are left out; docs/provenance.md).\n";

static const char frame_help[] =
    "frame, clock\n"
    "  Read-only numbers: with `frac run --frames A..B[:STEP]`, frame is the frame\n"
    "  number and clock (frame - A) / (B - A), 0 at A and 1 at B; 0 otherwise. In\n"
    "  output paths %f is the frame number, zero-padded. See docs/animation.md.\n";

static void cmd_help(repl *r, const char *arg)
{
    interp *I = r->I;
    if (!strcmp(arg, "frame") || !strcmp(arg, "clock")) {
        fputs(frame_help, stdout);
        return;
    }
    if (*arg) {
        const builtin *b = builtin_find(I, arg);
        if (!b) {
            fprintf(stderr, "no builtin named '%s'\n", arg);
            r->failed = 1;
            return;
        }
        bytebuf s;
        bytebuf_init(&s);
        builtin_signature(b, &s);
        printf("%.*s\n  %s\n", (int)s.len, (char *)s.data, b->doc);
        bytebuf_free(&s);
        return;
    }
    if (contract_compile_all(I)) { /* every declaration, so a bad one shows here */
        report(r);
        return;
    }
    fputs(help_text, stdout);
    printf("Builtins:");
    int col = 9;
    for (int i = 0; i < I->nbuiltins; i++) {
        int l = (int)strlen(I->builtins[i]->name) + 1;
        if (col + l > 78) {
            printf("\n ");
            col = 1;
        }
        printf(" %s", I->builtins[i]->name);
        col += l;
    }
    printf("\n");
}

static void cmd_vars(repl *r)
{
    env *g = r->I->globals;
    for (size_t i = 0; i < g->n; i++) {
        bytebuf b;
        bytebuf_init(&b);
        val_print(r->I, g->vals[i], &b, 1);
        if (b.len > 70) {
            b.len = 67;
            bytebuf_append(&b, "...", 3);
        }
        printf("%s = %.*s\n", g->names[i], (int)b.len, b.data ? (char *)b.data : "");
        bytebuf_free(&b);
    }
}

static void eval_entry(repl *r, const char *text, int first_line, int timed, int logged)
{
    value v = val_nil();
    struct timespec t0, t1;
    long mark = logged ? log_begin(r, text, strlen(text)) : 0;
    if (mark < 0)
        return;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int bad = session_run_lines(r->I, "<repl>", text, strlen(text), first_line, 0, &v);
    if (logged)
        log_end(r, mark, !bad);
    if (bad) {
        val_unref(r->I, v);
        report(r);
        return;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    print_value(r, v);
    val_unref(r->I, v);
    if (timed)
        printf("time: %.3f s\n", (double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-9);
}

static int run_command(repl *r, char *line)
{
    char *cmd = line + 1;
    char *arg = cmd;
    while (*arg && *arg != ' ')
        arg++;
    if (*arg)
        *arg++ = 0;
    while (*arg == ' ')
        arg++;
    size_t al = strlen(arg);
    while (al && (arg[al - 1] == ' ' || arg[al - 1] == '\r'))
        arg[--al] = 0;
    interp *I = r->I;
    if (strcmp(cmd, "quit") == 0 || strcmp(cmd, "q") == 0)
        return 1;
    if (strcmp(cmd, "help") == 0 || strcmp(cmd, "h") == 0) {
        cmd_help(r, arg);
    } else if (strcmp(cmd, "vars") == 0) {
        cmd_vars(r);
    } else if (strcmp(cmd, "reset") == 0) {
        env *root = I->globals->parent;
        env *fresh = val_env_new(I, root);
        if (fresh) {
            val_heap_unref(I, &I->globals->h);
            I->globals = fresh;
            log_end(r, 0, 0); /* the session starts again: so does its script */
        }
    } else if (strcmp(cmd, "load") == 0) {
        unsigned char *text;
        size_t len;
        rt_error e;
        if (!*arg) {
            fprintf(stderr, "usage: :load FILE\n");
            r->failed = 1;
        } else if (fileio_read_all(arg, 64u << 20, &text, &len, &e)) {
            fprintf(stderr, "error: %s\n", e.msg);
            r->failed = 1;
        } else {
            long mark = log_begin(r, (const char *)text, len);
            int bad = mark < 0 || session_run(I, arg, (char *)text, len, 0, NULL);
            log_end(r, mark, !bad);
            if (bad && mark >= 0)
                report(r);
            mem_free(I, text);
        }
    } else if (strcmp(cmd, "time") == 0) {
        eval_entry(r, arg, r->line_no - 1, 1, 1);
    } else if (strcmp(cmd, "show") == 0) {
        char buf[512];
        snprintf(buf, sizeof buf, "show(%s)", arg);
        eval_entry(r, buf, r->line_no - 1, 0, 0);
    } else {
        fprintf(stderr, "unknown command ':%s' (try :help)\n", cmd);
        r->failed = 1;
    }
    return 0;
}

/* Add an entry as a source for the parser. It is parsed as the lines of a
 * script are, with the line break after its last line: so an operator or
 * keyword that a script does not continue past a line break is an error
 * here too, not a request for more input. A '\\' at the end is left last,
 * so that piped input ending there says so. */
static int add_entry_source(interp *I, const char *text, size_t len)
{
    if (len && text[len - 1] == '\\')
        return interp_add_source(I, "<repl>", text, len);
    char *t = rt_malloc(len + 2);
    if (!t)
        return -1;
    memcpy(t, text, len);
    t[len] = '\n';
    t[len + 1] = 0;
    int src = interp_add_source(I, "<repl>", t, len + 1);
    rt_free(t);
    return src;
}

/* A failed write to standard output ends the session with 74. */
static int stdout_failed(repl *r)
{
    if (r->io_error == 2)
        return 1;
    if (fflush(stdout) == 0 && !ferror(stdout))
        return 0;
    fprintf(stderr, "frac: cannot write to standard output\n");
    r->io_error = 2;
    return 1;
}

int repl_main(interp *I, volatile sig_atomic_t *interrupted, repl_recipe_fn recipe, void *ud)
{
    repl r = {0};
    r.I = I;
    r.recipe = recipe;
    r.recipe_ud = ud;
    bytebuf_init(&r.log);
    r.in_tty = isatty(0);
    r.tty = r.in_tty && isatty(1);
    r.line_no = 1;
    I->is_repl = 1;
    char hist[4096] = "";
    const char *home = getenv("HOME");
    if (r.tty && home && *home && strlen(home) + sizeof "/.frac_history" <= sizeof hist) /* else no history */
        snprintf(hist, sizeof hist, "%s/.frac_history", home);
    r.le = lineedit_new(0, 1, hist[0] ? hist : NULL, 1000);
    if (!r.le) {
        fprintf(stderr, "frac: out of memory\n");
        return 70;
    }
    if (r.tty)
        printf("frac %s — type :help for help, :quit or Ctrl-D to leave\n", FRAC_VERSION);
    while (!stdout_failed(&r)) {
        *interrupted = 0;
        int cancelled;
        char *line = read_line(&r, "frac> ", &cancelled);
        if (!line)
            break;
        if (cancelled || line[0] == 0) {
            mem_free(I, line);
            continue;
        }
        int first = r.line_no++;
        if (line[0] == ':') {
            forget_prev(&r);
            lineedit_history_add(r.le, line);
            int quit = run_command(&r, line);
            mem_free(I, line);
            if (quit)
                break;
            continue;
        }
        size_t len = strlen(line);
        char *text = line;
        int joined = 0;
        if (r.prev_text && continues_previous(first_token(line))) {
            /* terminal: this line goes on with the entry before it */
            size_t pl = strlen(r.prev_text);
            char *nt = rt_malloc(pl + len + 2);
            if (nt) {
                memcpy(nt, r.prev_text, pl);
                nt[pl] = '\n';
                memcpy(nt + pl + 1, line, len + 1);
                rt_free(line);
                text = nt;
                len += pl + 1;
                first = r.prev_first;
                joined = 1;
            }
        }
        /* accumulate continuation lines while the input is incomplete */
        int dropped = 0;
        for (;;) {
            int src = add_entry_source(I, text, len);
            node *prog;
            if (src < 0)
                break;
            I->srcs[src].first_line = first;
            if (parse_source(I, src, &prog) == 0) {
                if (!r.in_tty && join_next(&r, &text, &len))
                    continue;
                break;
            }
            if (!I->err.incomplete)
                break;
            char *more = read_line(&r, "..    ", &cancelled);
            if (!more || cancelled) {
                /* piped input that ends here is the parser's error; on a
                 * terminal Ctrl-C or Ctrl-D abandons the unfinished entry */
                rt_free(more);
                if (r.in_tty || r.io_error)
                    dropped = 1;
                break;
            }
            err_clear(I);
            r.line_no++;
            size_t ml = strlen(more);
            char *nt = mem_realloc(I, text, len + ml + 2);
            if (!nt) {
                mem_free(I, more);
                break;
            }
            text = nt;
            text[len] = '\n';
            memcpy(text + len + 1, more, ml + 1);
            len += ml + 1;
            mem_free(I, more);
        }
        lineedit_history_add(r.le, joined ? text + strlen(r.prev_text) + 1 : text);
        if (dropped || I->err.active) {
            if (dropped)
                err_clear(I);
            else
                report(&r);
            rt_free(text);
            forget_prev(&r);
            continue;
        }
        if (joined)
            snap_restore(&r);
        else if (r.in_tty)
            snap_take(&r);
        if (joined) /* the entry before ran again as part of this one */
            r.log.len = r.prev_mark;
        else
            r.prev_mark = r.log.len;
        eval_entry(&r, text, first, 0, 1);
        if (r.in_tty) {
            rt_free(r.prev_text);
            r.prev_text = text;
            r.prev_first = first;
        } else {
            rt_free(text);
        }
    }
    stdout_failed(&r);
    for (size_t i = 0; i < r.nahead; i++)
        rt_free(r.ahead[i]);
    rt_free(r.ahead);
    forget_prev(&r);
    lineedit_free(r.le);
    bytebuf_free(&r.log);
    if (r.io_error)
        return 74;
    return r.failed && !r.tty ? 65 : 0;
}
