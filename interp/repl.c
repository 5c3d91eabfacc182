/* repl.c — the read-eval-print loop.
 *
 * On a terminal: prompts, line editing and history (runtime/lineedit), `..`
 * continuation prompts for incomplete input, Ctrl-C cancels a line or
 * interrupts a running evaluation. Piped: no prompts and no escape
 * sequences; values to stdout one per line, errors to stderr, and the exit
 * code is 65 if any input failed, so sessions can be tested by piping.
 */
#include "repl.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "builtin.h"
#include "eval.h"
#include "fileio.h"
#include "lineedit.h"
#include "parser.h"
#include "session.h"

typedef struct repl {
    interp *I;
    lineedit *le;
    int tty;
    int line_no; /* session line number of the next input line */
    int failed;
} repl;

/* Read one line (without the newline) into a malloc'd string; NULL at the
 * end of input. Ctrl-C on a terminal cancels the line: *cancelled is set and
 * an empty line is returned. */
static char *read_line(repl *r, const char *prompt, int *cancelled)
{
    *cancelled = 0;
    char *line = NULL;
    for (;;) {
        lineedit_result res = lineedit_read(r->le, prompt, &line);
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
        if (res == LINEEDIT_ERROR)
            fprintf(stderr, "frac: %s\n", lineedit_errmsg(r->le));
        return NULL;
    }
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
    "Type any statement or expression; bare expressions print their value.\n";

static void cmd_help(repl *r, const char *arg)
{
    interp *I = r->I;
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

static void eval_entry(repl *r, const char *text, int first_line, int timed)
{
    value v = val_nil();
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (session_run_lines(r->I, "<repl>", text, strlen(text), first_line, 0, &v)) {
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
        env *fresh = env_new(I, root);
        if (fresh) {
            heap_unref(I, &I->globals->h);
            I->globals = fresh;
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
            if (session_run(I, arg, (char *)text, len, 0, NULL))
                report(r);
            mem_free(I, text);
        }
    } else if (strcmp(cmd, "time") == 0) {
        eval_entry(r, arg, r->line_no - 1, 1);
    } else if (strcmp(cmd, "show") == 0) {
        char buf[512];
        snprintf(buf, sizeof buf, "show(%s)", arg);
        eval_entry(r, buf, r->line_no - 1, 0);
    } else {
        fprintf(stderr, "unknown command ':%s' (try :help)\n", cmd);
        r->failed = 1;
    }
    return 0;
}

int repl_main(interp *I, volatile sig_atomic_t *interrupted)
{
    repl r = {0};
    r.I = I;
    r.tty = isatty(0) && isatty(1);
    r.line_no = 1;
    I->is_repl = 1;
    char hist[4096] = "";
    const char *home = getenv("HOME");
    if (r.tty && home && *home)
        snprintf(hist, sizeof hist, "%s/.frac_history", home);
    r.le = lineedit_new(0, 1, hist[0] ? hist : NULL, 1000);
    if (!r.le) {
        fprintf(stderr, "frac: out of memory\n");
        return 70;
    }
    if (r.tty)
        printf("frac %s — type :help for help, :quit or Ctrl-D to leave\n", FRAC_VERSION);
    for (;;) {
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
            lineedit_history_add(r.le, line);
            int quit = run_command(&r, line);
            mem_free(I, line);
            if (quit)
                break;
            continue;
        }
        /* accumulate continuation lines while the input is incomplete */
        size_t len = strlen(line);
        char *text = line;
        int dropped = 0;
        for (;;) {
            int src = interp_add_source(I, "<repl>", text, len);
            node *prog;
            if (src < 0)
                break;
            I->srcs[src].first_line = first;
            if (parse_source(I, src, &prog) == 0 || !I->err.incomplete)
                break;
            err_clear(I);
            char *more = read_line(&r, "..    ", &cancelled);
            if (!more || cancelled) {
                /* Ctrl-C or end of input abandons the unfinished entry */
                mem_free(I, more);
                dropped = 1;
                break;
            }
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
        lineedit_history_add(r.le, text);
        if (dropped) {
            err_clear(I);
        } else if (I->err.active) {
            report(&r);
        } else {
            eval_entry(&r, text, first, 0);
        }
        mem_free(I, text);
    }
    lineedit_free(r.le);
    return r.failed && !r.tty ? 65 : 0;
}
