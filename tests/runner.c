/* runner.c — the one test runner: C unit tests, language tests, REPL
 * sessions and golden tests of the examples. Its last line is
 * "N passed, N failed".
 *
 *   runner --frac build/frac [--unit build/tests] [--ptyrun build/ptyrun] [--update-golden] [FILTER]
 *
 * Language tests (.frac files under tests/lang/ and tests/regression/) carry their
 * expectations as comments (tests/README.md has the full guide):
 *   # expect: TEXT                 next line of stdout, exactly
 *   # expect error: MESSAGE        stderr's first diagnostic (its first line that is
 *                                  neither indented nor a warning) is exactly
 *                                  "FILE:LINE:COL: error: MESSAGE", FILE this script,
 *                                  LINE this comment's line, any COL; the error is
 *                                  found before the script runs: `frac check` reports
 *                                  the same first diagnostic
 *   # expect runtime error: MESSAGE  the same, for an error raised while running:
 *                                  `frac check` passes
 *   …error@COL: MESSAGE            also pins the column (the caret), e.g.
 *                                  `# expect runtime error@9: MESSAGE`
 *   …error (no position): MESSAGE  the first diagnostic is "frac: error: MESSAGE"
 *                                  (command-line errors: nothing in a script to point at)
 *   …error at NAME:LINE[:COL]: MESSAGE  raised in another file (an import), NAME
 *                                  relative to this script's folder
 *   A MESSAGE ending in "..." is a prefix (for a part that varies, e.g. a depth).
 *   A script stops at its first error: one error expectation per file.
 *   # stderr: TEXT                 a whole line of stderr equals TEXT
 *   # stderr contains: TEXT        a line of stderr, not a source echo, contains TEXT
 *   # exit: N                      exit code (default 0; 65 with an error)
 *   # args: ARGS…                  extra command-line arguments before the script
 *   # stdin: TEXT                  a line of standard input
 * REPL tests (.repl files in tests/repl/): lines "in: TEXT" are piped to `frac repl`;
 * "out: TEXT" lines are the whole stdout, in order; "err: TEXT" must appear
 * in stderr in order; "exit: N" (default 0); "stdin-from: PATH" and
 * "stdout-to: PATH" replace the pipes with that file (read and write errors).
 * Doc tests: every fenced code block in README.md and docs/NAME.md (the
 * convention is in docs/internals.md, "Docs are tests").
 * Golden tests: every examples/NAME.frac runs with --threads 1 and with
 * --threads 3 into fresh directories; every file written and the stdout must
 * equal tests/golden/NAME/ byte for byte (both thread counts).
 * Every program runs with a timeout, in the repository root.
 */
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700
#include <dirent.h>
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct buf {
    char *d;
    size_t n, cap;
} buf;

static void buf_add(buf *b, const char *s, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        size_t nc = b->cap ? b->cap : 4096;
        while (nc < b->n + n + 1)
            nc *= 2;
        b->d = realloc(b->d, nc);
        if (!b->d) {
            perror("runner");
            exit(2);
        }
        b->cap = nc;
    }
    memcpy(b->d + b->n, s, n);
    b->n += n;
    b->d[b->n] = 0;
}

static void buf_fmt(buf *b, const char *fmt, ...)
{
    char tmp[8192];
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    buf_add(b, tmp, k < 0 ? 0 : (size_t)k >= sizeof tmp ? sizeof tmp - 1 : (size_t)k);
}

static int passed, failed;
static const char *filter;
static double timeout_s = 120;
/* When set, the next run() gives the child this file as stdin / stdout
 * instead of the pipe (REPL and CLI tests of read and write errors, e.g.
 * /dev/full), runs it in child_cwd, and puts child_path_dir first on its
 * PATH (so `#!/usr/bin/env frac` finds frac). */
static const char *child_stdin, *child_stdout, *child_cwd, *child_path_dir;

/* Run argv with stdin text (may be NULL), capture stdout/stderr; returns the
 * exit code, 128+signal, or -1 on timeout. */
static int run(char *const argv[], const char *in, buf *out, buf *err, double timeout)
{
    int pin[2], pout[2], perr[2];
    if (pipe(pin) || pipe(pout) || pipe(perr)) {
        perror("pipe");
        exit(2);
    }
    pid_t pid = fork();
    if (pid < 0) {
        perror("fork");
        exit(2);
    }
    if (pid == 0) {
        setpgid(0, 0);
        dup2(pin[0], 0);
        dup2(pout[1], 1);
        dup2(perr[1], 2);
        close(pin[0]); close(pin[1]); close(pout[0]); close(pout[1]); close(perr[0]); close(perr[1]);
        if (child_cwd && chdir(child_cwd) != 0)
            _exit(127);
        if (child_stdin) {
            int fd = open(child_stdin, O_RDONLY);
            if (fd < 0 || dup2(fd, 0) < 0)
                _exit(127);
            close(fd);
        }
        if (child_stdout) {
            int fd = open(child_stdout, O_WRONLY);
            if (fd < 0 || dup2(fd, 1) < 0)
                _exit(127);
            close(fd);
        }
        if (child_path_dir) {
            char path[8192];
            snprintf(path, sizeof path, "%s:%s", child_path_dir, getenv("PATH") ? getenv("PATH") : "/usr/bin:/bin");
            setenv("PATH", path, 1);
        }
        execv(argv[0], argv);
        fprintf(stderr, "cannot run %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    setpgid(pid, pid);
    close(pin[0]);
    close(pout[1]);
    close(perr[1]);
    size_t in_len = in ? strlen(in) : 0, in_off = 0;
    if (!in_len)
        close(pin[1]);
    fcntl(pin[1], F_SETFL, O_NONBLOCK);
    struct timespec t0, t;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int open_out = 1, open_err = 1, open_in = in_len > 0, timed_out = 0;
    while (open_out || open_err) {
        struct pollfd fds[3];
        int nf = 0;
        if (open_out) fds[nf++] = (struct pollfd){pout[0], POLLIN, 0};
        if (open_err) fds[nf++] = (struct pollfd){perr[0], POLLIN, 0};
        if (open_in) fds[nf++] = (struct pollfd){pin[1], POLLOUT, 0};
        poll(fds, (nfds_t)nf, 100);
        for (int i = 0; i < nf; i++) {
            if (!fds[i].revents)
                continue;
            if (fds[i].fd == pin[1]) {
                ssize_t w = write(pin[1], in + in_off, in_len - in_off);
                if (w > 0)
                    in_off += (size_t)w;
                if (w < 0 || in_off == in_len) {
                    close(pin[1]);
                    open_in = 0;
                }
                continue;
            }
            char tmp[65536];
            ssize_t r = read(fds[i].fd, tmp, sizeof tmp);
            if (r <= 0) {
                if (fds[i].fd == pout[0]) open_out = 0; else open_err = 0;
            } else {
                buf_add(fds[i].fd == pout[0] ? out : err, tmp, (size_t)r);
            }
        }
        clock_gettime(CLOCK_MONOTONIC, &t);
        if ((double)(t.tv_sec - t0.tv_sec) + (double)(t.tv_nsec - t0.tv_nsec) * 1e-9 > timeout) {
            kill(-pid, SIGKILL);
            timed_out = 1;
            break;
        }
    }
    if (open_in)
        close(pin[1]);
    close(pout[0]);
    close(perr[0]);
    int status;
    waitpid(pid, &status, 0);
    if (!out->d) buf_add(out, "", 0);
    if (!err->d) buf_add(err, "", 0);
    if (timed_out)
        return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static void result(const char *name, int ok, buf *why)
{
    if (ok) {
        passed++;
    } else {
        failed++;
        printf("FAIL %s\n%s\n", name, why && why->d ? why->d : "");
    }
    fflush(stdout);
}

static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    buf b = {0};
    char tmp[65536];
    size_t r;
    while ((r = fread(tmp, 1, sizeof tmp, f)) > 0)
        buf_add(&b, tmp, r);
    fclose(f);
    if (!b.d)
        buf_add(&b, "", 0);
    if (len)
        *len = b.n;
    return b.d;
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Sorted list of entries of dir whose names end with ext (NULL: all files). */
static char **list_dir(const char *dir, const char *ext, int *n)
{
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    char **v = NULL;
    int cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        size_t l = strlen(e->d_name), el = ext ? strlen(ext) : 0;
        if (ext && (l < el || strcmp(e->d_name + l - el, ext) != 0))
            continue;
        if (*n == cap) {
            cap = cap ? cap * 2 : 32;
            v = realloc(v, (size_t)cap * sizeof *v);
        }
        v[(*n)++] = strdup(e->d_name);
    }
    closedir(d);
    if (*n)
        qsort(v, (size_t)*n, sizeof *v, cmp_str);
    return v;
}

static int matches_filter(const char *name) { return !filter || strstr(name, filter); }

/* ---- unit tests ---------------------------------------------------------------- */

static void run_unit(const char *dir)
{
    int n;
    char **names = list_dir(dir, NULL, &n);
    for (int i = 0; i < n; i++) {
        if (strncmp(names[i], "test_", 5) != 0 || strchr(names[i], '.') || !matches_filter(names[i]))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        char *argv[] = {path, NULL};
        buf out = {0}, err = {0}, why = {0};
        int rc = run(argv, NULL, &out, &err, timeout_s);
        char label[512];
        snprintf(label, sizeof label, "unit/%s", names[i]);
        if (rc != 0)
            buf_fmt(&why, "  exit %d%s\n  stdout: %s\n  stderr: %.4000s", rc, rc < 0 ? " (timeout)" : "", out.d, err.d);
        result(label, rc == 0, &why);
        free(out.d); free(err.d); free(why.d);
    }
}

/* ---- language tests ---------------------------------------------------------------- */

/* A line of stderr that echoes source: "%5d | TEXT" or the caret line "      | ^". */
static int is_echo_line(const char *s, size_t l)
{
    size_t i = 0, sp, dg;
    while (i < l && s[i] == ' ')
        i++;
    sp = i;
    while (i < l && s[i] >= '0' && s[i] <= '9')
        i++;
    dg = i - sp;
    if (dg)
        return i + 1 < l && s[i] == ' ' && s[i + 1] == '|';
    return sp > 0 && i < l && s[i] == '|';
}

/* `# stderr: TEXT`: some whole line of err equals want. */
static int has_line(const char *err, const char *want)
{
    size_t wl = strlen(want);
    for (const char *p = err; *p;) {
        const char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        if (l == wl && memcmp(p, want, l) == 0)
            return 1;
        p = e ? e + 1 : p + l;
    }
    return 0;
}

/* `# stderr contains: TEXT`: some line of err that is not a source echo
 * contains want. */
static int line_contains(const char *err, const char *want)
{
    size_t wl = strlen(want);
    for (const char *p = err; *p;) {
        const char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        if (!is_echo_line(p, l))
            for (size_t i = 0; i + wl <= l; i++)
                if (memcmp(p + i, want, wl) == 0)
                    return 1;
        p = e ? e + 1 : p + l;
    }
    return 0;
}

/* What a `# expect [runtime] error…` comment asks for. */
enum { AT_HERE, AT_NOPOS, AT_FILE };
typedef struct want_diag {
    int runtime;        /* 1: raised while running; 0: found before (so `frac check` finds it) */
    int where;          /* AT_HERE: this file, the comment's line; AT_NOPOS; AT_FILE: file:line */
    char file[4200];    /* AT_HERE / AT_FILE: the path frac must print (AT_FILE: normalised) */
    int line, col;      /* col 0: any column */
    char msg[4096];
    int prefix;         /* the message ended in "...": it is a prefix */
} want_diag;

/* The first diagnostic of a run: the first line of stderr that is neither
 * indented (source echo, caret, call trace) nor a warning. */
typedef struct got_diag {
    int found, is_error, has_pos;
    char file[4200];
    int line, col;
    char msg[4096];
    char text[4200];    /* the whole line, for messages */
} got_diag;

/* "a/./b/./c" -> "a/b/c", "./a" -> "a" */
static void norm_path(char *s)
{
    char *p;
    while ((p = strstr(s, "/./")))
        memmove(p, p + 2, strlen(p + 2) + 1);
    while (s[0] == '.' && s[1] == '/')
        memmove(s, s + 2, strlen(s + 2) + 1);
}

static void first_diag(const char *err, got_diag *g)
{
    memset(g, 0, sizeof *g);
    for (const char *p = err; *p;) {
        const char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        if (l && p[0] != ' ' && p[0] != '\t' && strncmp(p, "warning: ", 9) != 0) {
            g->found = 1;
            snprintf(g->text, sizeof g->text, "%.*s", (int)(l < 4100 ? l : 4100), p);
            break;
        }
        p = e ? e + 1 : p + l;
    }
    if (!g->found)
        return;
    if (strncmp(g->text, "frac: error: ", 13) == 0) {
        g->is_error = 1;
        snprintf(g->msg, sizeof g->msg, "%s", g->text + 13);
        return;
    }
    char *m = strstr(g->text, ": error: ");
    if (!m)
        return;
    /* FILE:LINE:COL before ": error: " (FILE may itself hold ':') */
    char head[4200];
    snprintf(head, sizeof head, "%.*s", (int)(m - g->text), g->text);
    char *c2 = strrchr(head, ':');
    if (!c2)
        return;
    *c2 = 0;
    char *c1 = strrchr(head, ':');
    if (!c1)
        return;
    *c1 = 0;
    char *end1, *end2;
    long ln = strtol(c1 + 1, &end1, 10), cl = strtol(c2 + 1, &end2, 10);
    if (*end1 || *end2 || end1 == c1 + 1 || end2 == c2 + 1)
        return;
    g->is_error = g->has_pos = 1;
    snprintf(g->file, sizeof g->file, "%s", head);
    g->line = (int)ln;
    g->col = (int)cl;
    snprintf(g->msg, sizeof g->msg, "%s", m + 9);
}

/* Parse the part after "error" of a `# expect [runtime] error…` comment on
 * line `line` of test `path`. Returns 0 if malformed. */
static int parse_want(const char *s, const char *path, int line, int runtime, want_diag *w)
{
    memset(w, 0, sizeof *w);
    w->runtime = runtime;
    const char *msg;
    if (strncmp(s, ": ", 2) == 0) {
        w->where = AT_HERE;
        msg = s + 2;
    } else if (s[0] == '@') {
        char *end;
        long c = strtol(s + 1, &end, 10);
        if (end == s + 1 || c < 1 || strncmp(end, ": ", 2) != 0)
            return 0;
        w->where = AT_HERE;
        w->col = (int)c;
        msg = end + 2;
    } else if (strncmp(s, " (no position): ", 16) == 0) {
        w->where = AT_NOPOS;
        msg = s + 16;
    } else if (strncmp(s, " at ", 4) == 0) {
        /* " at NAME:LINE[:COL]: MSG", NAME relative to the test's folder */
        const char *sep = strstr(s + 4, ": ");
        if (!sep)
            return 0;
        char spec[4096];
        snprintf(spec, sizeof spec, "%.*s", (int)(sep - s - 4), s + 4);
        char *c1 = strchr(spec, ':');
        if (!c1 || c1 == spec)
            return 0;
        *c1 = 0;
        char *end;
        long ln = strtol(c1 + 1, &end, 10), cl = 0;
        if (end == c1 + 1 || ln < 1)
            return 0;
        if (*end == ':') {
            char *e2;
            cl = strtol(end + 1, &e2, 10);
            if (e2 == end + 1 || cl < 1 || *e2)
                return 0;
        } else if (*end) {
            return 0;
        }
        const char *slash = strrchr(path, '/');
        snprintf(w->file, sizeof w->file, "%.*s%s", slash ? (int)(slash - path + 1) : 0, path, spec);
        norm_path(w->file);
        w->where = AT_FILE;
        w->line = (int)ln;
        w->col = (int)cl;
        msg = sep + 2;
    } else {
        return 0;
    }
    snprintf(w->msg, sizeof w->msg, "%s", msg);
    size_t ml = strlen(w->msg);
    if (ml >= 3 && strcmp(w->msg + ml - 3, "...") == 0) {
        w->msg[ml - 3] = 0;
        w->prefix = 1;
    }
    if (w->where == AT_HERE) {
        snprintf(w->file, sizeof w->file, "%s", path);
        w->line = line;
    }
    return 1;
}

static void want_text(buf *b, const want_diag *w)
{
    if (w->where == AT_NOPOS)
        buf_fmt(b, "frac: error: ");
    else if (w->col)
        buf_fmt(b, "%s:%d:%d: error: ", w->file, w->line, w->col);
    else
        buf_fmt(b, "%s:%d:(any column): error: ", w->file, w->line);
    buf_fmt(b, "%s%s", w->msg, w->prefix ? "..." : "");
}

/* Does the first diagnostic g satisfy w? */
static int diag_matches(const want_diag *w, const got_diag *g)
{
    if (!g->found || !g->is_error)
        return 0;
    if (w->where == AT_NOPOS) {
        if (g->has_pos)
            return 0;
    } else {
        if (!g->has_pos || g->line != w->line || (w->col && g->col != w->col))
            return 0;
        char f[4200];
        snprintf(f, sizeof f, "%s", g->file);
        if (w->where == AT_FILE)
            norm_path(f);
        if (strcmp(f, w->file) != 0)
            return 0;
    }
    return w->prefix ? strncmp(g->msg, w->msg, strlen(w->msg)) == 0 : strcmp(g->msg, w->msg) == 0;
}

static void run_lang_file(const char *frac, const char *path)
{
    size_t len;
    char *text = read_file(path, &len);
    if (!text)
        return;
    buf expect_out = {0}, in = {0}, why = {0};
    char *stderrs[64];
    int st_contains[64];
    int nst = 0, exit_code = -1, nwant = 0, ok = 1;
    want_diag want;
    char *args[64];
    int nargs = 0;
    int line = 1;
    for (char *p = text; *p;) {
        char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        char ln[4096];
        snprintf(ln, sizeof ln, "%.*s", (int)(l < sizeof ln - 1 ? l : sizeof ln - 1), p);
        char *c = strstr(ln, "# expect: ");
        char *ce = strstr(ln, "# expect error"), *cr = strstr(ln, "# expect runtime error");
        if (c) {
            buf_add(&expect_out, c + 10, strlen(c + 10));
            buf_add(&expect_out, "\n", 1);
        } else if (ce || cr) {
            if (nwant++) {
                ok = 0;
                buf_fmt(&why, "  line %d: a second error expectation (a script stops at its first error)\n", line);
            } else if (!parse_want(ce ? ce + 14 : cr + 22, path, line, cr != NULL, &want)) {
                ok = 0;
                buf_fmt(&why, "  line %d: malformed expectation (forms: `# expect [runtime] error: MSG`, "
                              "`…error@COL: MSG`, `…error (no position): MSG`, `…error at FILE:LINE[:COL]: MSG`):\n  %s\n",
                        line, ce ? ce : cr);
            }
        } else if ((c = strstr(ln, "# stderr: ")) && nst < 64) {
            st_contains[nst] = 0;
            stderrs[nst++] = strdup(c + 10);
        } else if ((c = strstr(ln, "# stderr contains: ")) && nst < 64) {
            st_contains[nst] = 1;
            stderrs[nst++] = strdup(c + 19);
        } else if ((c = strstr(ln, "# exit: "))) {
            exit_code = atoi(c + 8);
        } else if ((c = strstr(ln, "# stdin: "))) {
            buf_add(&in, c + 9, strlen(c + 9));
            buf_add(&in, "\n", 1);
        } else if ((c = strstr(ln, "# args: "))) {
            char *tok = strtok(c + 8, " ");
            while (tok && nargs < 60) {
                args[nargs++] = strdup(tok);
                tok = strtok(NULL, " ");
            }
        }
        line++;
        p = e ? e + 1 : p + l;
    }
    int have_want = nwant == 1 && ok;
    if (exit_code < 0)
        exit_code = nwant ? 65 : 0;
    char *argv[72];
    int k = 0;
    argv[k++] = (char *)frac;
    argv[k++] = "--quiet";
    for (int i = 0; i < nargs; i++)
        argv[k++] = args[i];
    argv[k++] = (char *)path;
    argv[k] = NULL;
    buf out = {0}, err = {0};
    int rc = run(argv, in.d, &out, &err, 60);
    if (rc != exit_code) {
        ok = 0;
        buf_fmt(&why, "  exit code %d, expected %d%s\n", rc, exit_code, rc < 0 ? " (timeout)" : "");
    }
    const char *eo = expect_out.d ? expect_out.d : "";
    if (strcmp(out.d, eo) != 0) {
        ok = 0;
        buf_fmt(&why, "  stdout:\n%s  expected:\n%s", out.d, eo);
    }
    if (have_want) {
        got_diag g;
        first_diag(err.d, &g);
        if (!diag_matches(&want, &g)) {
            ok = 0;
            buf_fmt(&why, "  first diagnostic: %s\n  expected:         ", g.found ? g.text : "(none: stderr is empty)");
            want_text(&why, &want);
            buf_fmt(&why, "\n");
        }
        /* The two kinds: an error found before the script runs is what
         * `frac check` reports too; a runtime error passes `frac check`. */
        char *cargv[72];
        int ck = 0;
        cargv[ck++] = (char *)frac;
        cargv[ck++] = "check";
        for (int i = 1; i < k; i++)
            cargv[ck++] = argv[i];
        cargv[ck] = NULL;
        buf cout = {0}, cerr = {0};
        int crc = run(cargv, NULL, &cout, &cerr, 60);
        got_diag cg;
        first_diag(cerr.d, &cg);
        if (want.runtime && crc != 0) {
            ok = 0;
            buf_fmt(&why, "  `frac check` fails (exit %d), so this is not a runtime error: write `# expect error…`\n"
                          "  frac check said: %s\n", crc, cg.found ? cg.text : "(nothing)");
        } else if (!want.runtime && (crc == 0 || !diag_matches(&want, &cg))) {
            ok = 0;
            if (crc == 0)
                buf_fmt(&why, "  `frac check` passes, so this error is raised at run time: write `# expect runtime error…`\n");
            else
                buf_fmt(&why, "  `frac check` (exit %d) reports another first diagnostic: %s\n", crc,
                        cg.found ? cg.text : "(none)");
        }
        free(cout.d);
        free(cerr.d);
    }
    for (int i = 0; i < nst; i++) {
        if (!(st_contains[i] ? line_contains(err.d, stderrs[i]) : has_line(err.d, stderrs[i]))) {
            ok = 0;
            buf_fmt(&why, st_contains[i] ? "  no stderr line (outside source echoes) contains: %s\n"
                                         : "  no whole stderr line equals: %s\n", stderrs[i]);
        }
        free(stderrs[i]);
    }
    if (!ok)
        buf_fmt(&why, "  stderr was:\n%.3000s", err.d);
    result(path, ok, &why);
    for (int i = 0; i < nargs; i++)
        free(args[i]);
    free(text); free(out.d); free(err.d); free(expect_out.d); free(in.d); free(why.d);
}

static void run_lang_dir(const char *frac, const char *dir)
{
    int n;
    char **names = list_dir(dir, NULL, &n);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        struct stat st;
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
            run_lang_dir(frac, path);
        } else {
            size_t l = strlen(names[i]);
            if (l > 5 && strcmp(names[i] + l - 5, ".frac") == 0 && matches_filter(path) &&
                strncmp(names[i], "_", 1) != 0) /* _NAME.frac: helpers imported by tests */
                run_lang_file(frac, path);
        }
        free(names[i]);
    }
    free(names);
}

/* ---- command-line tests --------------------------------------------------------------
 * tests/cli/NAME.cli: "# args: A B C" (the whole command line after frac;
 * quoted 'single words' keep their spaces), "# stdin: TEXT" lines,
 * "# exit: N", "# stdout: TEXT" lines (the whole stdout, in order, exactly;
 * "# stdout:" alone is an empty line; none: stdout is empty), or instead
 * "# stdout contains: TEXT" (substrings, e.g. of the help text),
 * "# stderr: TEXT" (a whole line of stderr), "# stderr contains: TEXT" (a
 * substring of a line that is not a source echo),
 * "# stdout-to: PATH" (stdout goes to that file, e.g. /dev/full),
 * "# stdin-from: PATH" (stdin is read from that file, e.g. a folder),
 * "# exec: PATH" (run PATH, a shebang script, instead of frac, with frac's
 * folder first on PATH; the args follow it), "# file: NAME: TEXT" (the file
 * $TMP/NAME must contain TEXT). In all of them $TMP stands for a fresh empty
 * folder, removed after the test. */
static int rm_tree(const char *dir);

/* s[0..l) with every "$TMP" replaced by tmp, appended to out. */
static void add_subst(buf *out, const char *s, size_t l, const char *tmp)
{
    for (size_t i = 0; i < l;) {
        if (tmp && l - i >= 4 && memcmp(s + i, "$TMP", 4) == 0) {
            buf_add(out, tmp, strlen(tmp));
            i += 4;
        } else {
            buf_add(out, s + i, 1);
            i++;
        }
    }
    if (!out->d)
        buf_add(out, "", 0);
}
static int split_args(char *s, char **argv, int max)
{
    int n = 0;
    while (*s && n < max) {
        while (*s == ' ')
            s++;
        if (!*s)
            break;
        if (*s == '\'') {
            argv[n++] = ++s;
            while (*s && *s != '\'')
                s++;
        } else {
            argv[n++] = s;
            while (*s && *s != ' ')
                s++;
        }
        if (*s)
            *s++ = 0;
    }
    return n;
}

static void run_cli_dir(const char *frac)
{
    int n;
    char **names = list_dir("tests/cli", ".cli", &n);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "tests/cli/%s", names[i]);
        free(names[i]);
        if (!matches_filter(path))
            continue;
        char *text = read_file(path, NULL);
        buf in = {0}, why = {0}, argb = {0}, want_out = {0};
        int err_contains[32];
        char *outs[32], *errs[32], *files[32], stdout_to[4096] = "", stdin_from[4096] = "", exec_path[4096] = "";
        int nout = 0, nerr = 0, nfile = 0, exit_code = 0;
        char tmpl[] = "/tmp/frac-cli-XXXXXX";
        char *tmp = text && (strstr(text, "$TMP") || strstr(text, "# file: ")) ? mkdtemp(tmpl) : NULL;
        for (char *p = text; p && *p;) {
            char *e = strchr(p, '\n');
            size_t l = e ? (size_t)(e - p) : strlen(p);
            if (strncmp(p, "# args: ", 8) == 0) {
                argb.n = 0;
                add_subst(&argb, p + 8, l - 8, tmp);
            } else if (strncmp(p, "# stdout-to: ", 13) == 0)
                snprintf(stdout_to, sizeof stdout_to, "%.*s", (int)(l - 13), p + 13);
            else if (strncmp(p, "# stdin-from: ", 14) == 0)
                snprintf(stdin_from, sizeof stdin_from, "%.*s", (int)(l - 14), p + 14);
            else if (strncmp(p, "# exec: ", 8) == 0)
                snprintf(exec_path, sizeof exec_path, "%.*s", (int)(l - 8), p + 8);
            else if (strncmp(p, "# stdin: ", 9) == 0) {
                add_subst(&in, p + 9, l - 9, tmp);
                buf_add(&in, "\n", 1);
            } else if (strncmp(p, "# exit: ", 8) == 0)
                exit_code = atoi(p + 8);
            else if ((strncmp(p, "# stdout:", 9) == 0 && (l == 9 || p[9] == ' ')) || strncmp(p, "# stdout contains: ", 19) == 0) {
                int contains = strncmp(p, "# stdout contains: ", 19) == 0;
                size_t skip = contains ? 19 : l == 9 ? 9 : 10;
                buf b = {0};
                add_subst(&b, p + skip, l - skip, tmp);
                if (contains) {
                    if (nout < 32)
                        outs[nout++] = b.d;
                    else
                        free(b.d);
                } else {
                    buf_add(&want_out, b.d, b.n);
                    buf_add(&want_out, "\n", 1);
                    free(b.d);
                }
            } else if ((strncmp(p, "# stderr: ", 10) == 0 || strncmp(p, "# stderr contains: ", 19) == 0) && nerr < 32) {
                int contains = strncmp(p, "# stderr contains: ", 19) == 0;
                size_t skip = contains ? 19 : 10;
                buf b = {0};
                add_subst(&b, p + skip, l - skip, tmp);
                err_contains[nerr] = contains;
                errs[nerr++] = b.d;
            } else if (strncmp(p, "# file: ", 8) == 0 && nfile < 32)
                files[nfile++] = strndup(p + 8, l - 8);
            p = e ? e + 1 : p + l;
        }
        char *argline = argb.d ? argb.d : "";
        char *argv[64];
        argv[0] = exec_path[0] ? exec_path : (char *)frac;
        int k = 1 + split_args(argline, argv + 1, 60);
        argv[k] = NULL;
        buf out = {0}, err = {0};
        char fracdir[4096];
        snprintf(fracdir, sizeof fracdir, "%s", frac);
        if (strrchr(fracdir, '/'))
            *strrchr(fracdir, '/') = 0;
        child_stdin = stdin_from[0] ? stdin_from : NULL;
        child_stdout = stdout_to[0] ? stdout_to : NULL;
        child_path_dir = exec_path[0] ? fracdir : NULL;
        int rc = run(argv, in.d ? in.d : "", &out, &err, 60);
        child_stdin = child_stdout = child_path_dir = NULL;
        int ok = rc == exit_code;
        if (!ok)
            buf_fmt(&why, "  exit code %d, expected %d\n", rc, exit_code);
        if (!nout && strcmp(out.d, want_out.d ? want_out.d : "") != 0) {
            ok = 0;
            buf_fmt(&why, "  stdout:\n%s  expected:\n%s", out.d, want_out.d ? want_out.d : "");
        }
        if (nout && want_out.d) {
            ok = 0;
            buf_fmt(&why, "  `# stdout:` and `# stdout contains:` in one test: use one form\n");
        }
        for (int j = 0; j < nout; j++) {
            if (!strstr(out.d, outs[j])) {
                ok = 0;
                buf_fmt(&why, "  stdout does not contain: %s\n", outs[j]);
            }
            free(outs[j]);
        }
        for (int j = 0; j < nerr; j++) {
            if (!(err_contains[j] ? line_contains(err.d, errs[j]) : has_line(err.d, errs[j]))) {
                ok = 0;
                buf_fmt(&why, err_contains[j] ? "  no stderr line (outside source echoes) contains: %s\n"
                                              : "  no whole stderr line equals: %s\n", errs[j]);
            }
            free(errs[j]);
        }
        for (int j = 0; j < nfile; j++) {
            char *colon = strstr(files[j], ": ");
            char fpath[8192];
            if (colon)
                *colon = 0;
            snprintf(fpath, sizeof fpath, "%s/%s", tmp, files[j]);
            char *ft = read_file(fpath, NULL);
            if (!colon || !ft || !strstr(ft, colon + 2)) {
                ok = 0;
                buf_fmt(&why, "  %s lacks: %s\n%.2000s\n", files[j], colon ? colon + 2 : "", ft ? ft : "(no file)");
            }
            free(ft);
            free(files[j]);
        }
        if (!ok)
            buf_fmt(&why, "  stdout was:\n%.2000s\n  stderr was:\n%.2000s", out.d, err.d);
        result(path, ok, &why);
        if (tmp)
            rm_tree(tmp);
        free(text); free(in.d); free(out.d); free(err.d); free(why.d); free(argb.d); free(want_out.d);
    }
    free(names);
}

/* ---- REPL sessions ------------------------------------------------------------------ */

static void run_repl_dir(const char *frac, const char *dir)
{
    int n;
    char **names = list_dir(dir, ".repl", &n);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        if (!matches_filter(path))
            continue;
        char *text = read_file(path, NULL);
        buf in = {0}, want = {0}, why = {0};
        char *errs[64], stdin_from[1024] = "", stdout_to[1024] = "";
        int nerr = 0, exit_code = 0;
        for (char *p = text; p && *p;) {
            char *e = strchr(p, '\n');
            size_t l = e ? (size_t)(e - p) : strlen(p);
            if (strncmp(p, "in: ", 4) == 0) {
                buf_add(&in, p + 4, l - 4);
                buf_add(&in, "\n", 1);
            } else if (strncmp(p, "in:", 3) == 0 && l == 3) {
                buf_add(&in, "\n", 1);
            } else if (strncmp(p, "out: ", 5) == 0) {
                buf_add(&want, p + 5, l - 5);
                buf_add(&want, "\n", 1);
            } else if (strncmp(p, "err: ", 5) == 0 && nerr < 64) {
                errs[nerr++] = strndup(p + 5, l - 5);
            } else if (strncmp(p, "exit: ", 6) == 0) {
                exit_code = atoi(p + 6);
            } else if (strncmp(p, "stdin-from: ", 12) == 0) {
                snprintf(stdin_from, sizeof stdin_from, "%.*s", (int)(l - 12), p + 12);
            } else if (strncmp(p, "stdout-to: ", 11) == 0) {
                snprintf(stdout_to, sizeof stdout_to, "%.*s", (int)(l - 11), p + 11);
            }
            p = e ? e + 1 : p + l;
        }
        char *argv[] = {(char *)frac, "--quiet", "repl", NULL};
        buf out = {0}, err = {0};
        child_stdin = stdin_from[0] ? stdin_from : NULL;
        child_stdout = stdout_to[0] ? stdout_to : NULL;
        int rc = run(argv, in.d ? in.d : "", &out, &err, 60);
        child_stdin = child_stdout = NULL;
        int ok = rc == exit_code;
        if (!ok)
            buf_fmt(&why, "  exit code %d, expected %d\n", rc, exit_code);
        if (strcmp(out.d, want.d ? want.d : "") != 0) {
            ok = 0;
            buf_fmt(&why, "  stdout:\n%s  expected:\n%s", out.d, want.d ? want.d : "");
        }
        const char *from = err.d;
        for (int k = 0; k < nerr; k++) {
            const char *f = strstr(from, errs[k]);
            if (!f) {
                ok = 0;
                buf_fmt(&why, "  stderr lacks (in order): %s\n", errs[k]);
            } else {
                from = f + strlen(errs[k]);
            }
            free(errs[k]);
        }
        if (!ok)
            buf_fmt(&why, "  stderr was:\n%.3000s", err.d);
        result(path, ok, &why);
        free(text); free(in.d); free(want.d); free(out.d); free(err.d); free(why.d);
    }
}

/* ---- interactive sessions on a pseudo-terminal ---------------------------------------
 * tests/pty/NAME.pty are ptyrun scripts played against `frac repl` (or,
 * when the first line is "# args: A B", against `frac A B`) on a pty, in name order, with HOME pointing at one fresh folder (so history
 * carries from one script to the next). ptyrun must exit 0 and report
 * exit=0 and termios=same (raw mode restored). */
static void run_pty_dir(const char *frac, const char *ptyrun)
{
    int n;
    char **names = list_dir("tests/pty", ".pty", &n);
    char tmpl[] = "/tmp/frac-home-XXXXXX";
    char *home = mkdtemp(tmpl);
    const char *old_home = getenv("HOME");
    char *saved = old_home ? strdup(old_home) : NULL;
    if (home)
        setenv("HOME", home, 1);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "tests/pty/%s", names[i]);
        if (matches_filter(path)) {
            char *argv[16] = {(char *)ptyrun, "--check-termios", "--timeout", "20", path, "--",
                              (char *)frac, "repl", NULL};
            /* a first line "# args: A B" runs `frac A B` instead of `frac repl` */
            char *text = read_file(path, NULL);
            if (text && strncmp(text, "# args: ", 8) == 0) {
                char *nl = strchr(text, '\n');
                if (nl)
                    *nl = 0;
                argv[7 + split_args(text + 8, argv + 7, 8)] = NULL;
            }
            buf out = {0}, err = {0}, why = {0};
            int rc = run(argv, NULL, &out, &err, 120);
            int ok = rc == 0 && strstr(out.d, "exit=0") && strstr(out.d, "termios=same");
            if (!ok)
                buf_fmt(&why, "  ptyrun exit %d\n  stdout: %s\n  stderr: %.3000s", rc, out.d, err.d);
            result(path, ok, &why);
            free(out.d); free(err.d); free(why.d); free(text);
        }
        free(names[i]);
    }
    free(names);
    if (saved) {
        setenv("HOME", saved, 1);
        free(saved);
    }
    if (home)
        rm_tree(home);
}

/* Does frac's first diagnostic (stderr's first line) carry a position,
 * "FILE:LINE:COL: error: …"? */
static int err_has_position(const char *err)
{
    if (!err)
        return 0;
    const char *p = err, *nl = strchr(p, '\n');
    size_t len = nl ? (size_t)(nl - p) : strlen(p);
    for (size_t i = 0; i + 2 < len; i++) {
        if (p[i] != ':' || !isdigit((unsigned char)p[i + 1]))
            continue;
        size_t j = i + 1;
        while (j < len && isdigit((unsigned char)p[j]))
            j++;
        if (j < len && p[j] == ':' && j + 1 < len && isdigit((unsigned char)p[j + 1])) {
            size_t c = j + 1;
            while (c < len && isdigit((unsigned char)p[c]))
                c++;
            if (len - c >= 8 && memcmp(p + c, ": error:", 8) == 0)
                return 1;
        }
    }
    return 0;
}

/* ---- allocation failure ----------------------------------------------------------
 * Run a script failing the N-th allocation, for N = 1, 2, … until the script
 * no longer runs out: each run must end with exit 70 and an "out of memory"
 * message (or succeed once N is past the last allocation) — never a crash, a
 * sanitizer report (leaks included, under ASan) or another exit code. Every
 * allocation counts: the interpreter's, and the engines' and codecs' through
 * the runtime's allocation hook (runtime/rt_alloc.h);
 * tests/failalloc/engines_io.frac renders, saves and loads an image, a
 * volume and a mesh to reach them.
 *
 * A big script is affordable with a stride k: the loop tries every N up to
 * FA_HEAD (start-up: the stdlib, the parser), then every k-th, plus the
 * allocations in `extra` (where a bug once was). FA_STRIDE=K in the
 * environment overrides every loop's stride (FA_STRIDE=1: the whole loop),
 * FA_HEAD=H the head (a scan of many small scripts under ASan need not
 * repeat the start-up allocations they share in every one);
 * `runner --frac F --fail-alloc SCRIPT…` runs only these loops, over any
 * scripts (tests/README.md, "Allocation failure"). */
enum { FA_HEAD = 64 };

/* A script's "# args: A B" and "# stdin: TEXT" lines, as run_lang_file reads them. */
static int script_setup(const char *path, char **args, int max, buf *in)
{
    char *text = read_file(path, NULL);
    int n = 0;
    for (char *p = text; p && *p;) {
        char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        char ln[4096], *c;
        snprintf(ln, sizeof ln, "%.*s", (int)(l < sizeof ln - 1 ? l : sizeof ln - 1), p);
        if ((c = strstr(ln, "# stdin: "))) {
            buf_add(in, c + 9, strlen(c + 9));
            buf_add(in, "\n", 1);
        } else if ((c = strstr(ln, "# args: "))) {
            for (char *tok = strtok(c + 8, " "); tok && n < max; tok = strtok(NULL, " "))
                args[n++] = strdup(tok);
        }
        p = e ? e + 1 : p + l;
    }
    free(text);
    return n;
}

static void run_fail_alloc(const char *frac, const char *script, int stride, const int *extra)
{
    char label[4200];
    snprintf(label, sizeof label, "fail-alloc/%s", script);
    if (!matches_filter(label))
        return;
    const char *env = getenv("FA_STRIDE");
    if (env && atoi(env) > 0)
        stride = atoi(env);
    if (stride < 1)
        stride = 1;
    int head = FA_HEAD;
    if ((env = getenv("FA_HEAD")) && atoi(env) >= 0)
        head = atoi(env);
    if (access(script, R_OK) != 0) { /* or every run fails alike and the loop passes */
        buf why = {0};
        buf_fmt(&why, "  cannot read %s: %s\n", script, strerror(errno));
        result(label, 0, &why);
        free(why.d);
        return;
    }
    char tmpl[] = "/tmp/frac-failalloc-XXXXXX";
    char *dir = mkdtemp(tmpl);
    if (!dir) {
        buf why = {0};
        buf_fmt(&why, "  mkdtemp: %s\n", strerror(errno));
        result(label, 0, &why);
        free(why.d);
        return;
    }
    buf why = {0}, ref = {0}, referr = {0}, in = {0};
    char *sargs[32], num[32];
    int nargs = script_setup(script, sargs, 32, &in);
    /* frac --quiet [--fail-alloc N] -o DIR ARGS… SCRIPT */
    char *argv[48];
    int k = 0;
    argv[k++] = (char *)frac;
    argv[k++] = "--quiet";
    int at_n = k;
    argv[k++] = "--fail-alloc";
    argv[k++] = num;
    argv[k++] = "-o";
    argv[k++] = dir;
    for (int i = 0; i < nargs; i++)
        argv[k++] = sargs[i];
    argv[k++] = (char *)script;
    argv[k] = NULL;
    int ok = 1, n, runs = 0, positioned = 0;
    long made = -1;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    /* the output of a run that fails nothing: a run that ends without running
     * out of memory must print the same and exit the same (0, or the script's
     * own error), or an allocation failure was swallowed or turned into
     * another error */
    char *refargv[48];
    int rk = 0;
    for (int i = 0; i < k; i++)
        if (i != at_n && i != at_n + 1) /* without --fail-alloc N */
            refargv[rk++] = argv[i];
    refargv[rk] = NULL;
    int refrc = run(refargv, in.d, &ref, &referr, timeout_s);
    for (n = 1; n < 100000000;) {
        snprintf(num, sizeof num, "%d", n);
        buf out = {0}, err = {0};
        int rc = run(argv, in.d, &out, &err, timeout_s);
        int oom = strstr(err.d, "out of memory") != NULL;
        runs++;
        if (!(rc == 70 && oom)) {
            /* a failure frac may tolerate (a cache, a check-time evaluation
             * it can skip), or the run is past the last allocation — either
             * way it must do what a normal run does */
            const char *past = strstr(err.d, "was not reached");
            if (past)
                sscanf(past, "was not reached: the run made %ld", &made);
            if (rc != refrc) {
                ok = 0;
                buf_fmt(&why, "  --fail-alloc %d: exit %d (a normal run: %d)\n  stderr: %.2000s\n", n, rc, refrc, err.d);
            } else if (strcmp(out.d ? out.d : "", ref.d ? ref.d : "") != 0) {
                ok = 0;
                buf_fmt(&why, "  --fail-alloc %d: exit %d but stdout differs from a normal run (a failure "
                              "swallowed?)\n  stdout: %.500s\n", n, rc, out.d ? out.d : "");
            }
            free(out.d); free(err.d);
            if (past || !ok)
                break; /* past the last allocation (frac says so), or a failure found */
        } else {
            /* out of memory: once a failure has been reported at a place in
             * a script (the script has begun), every later one must be too */
            int pos = err_has_position(err.d);
            if (pos)
                positioned = n;
            else if (positioned) {
                ok = 0;
                buf_fmt(&why, "  --fail-alloc %d: out of memory without a position (--fail-alloc %d had one)\n"
                              "  stderr: %.2000s\n", n, positioned, err.d);
            }
            free(out.d); free(err.d);
            if (!ok)
                break;
        }
        /* the next N: n + 1 in the head, else n + stride or an extra one before it */
        int next = n < head ? n + 1 : n + stride;
        for (const int *x = extra; x && *x; x++)
            if (*x > n && *x < next)
                next = *x;
        n = next;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (getenv("FA_DEBUG"))
        fprintf(stderr, "%s: stopped at %d (%ld allocations, head %d, stride %d, %d runs, %.1f s)\n", label, n,
                made, head, stride, runs, (t1.tv_sec - t0.tv_sec) + (t1.tv_nsec - t0.tv_nsec) * 1e-9);
    rm_tree(dir);
    result(label, ok, &why);
    for (int i = 0; i < nargs; i++)
        free(sargs[i]);
    free(why.d);
    free(ref.d);
    free(referr.d);
    free(in.d);
}

/* ---- checks with outside tools --------------------------------------------------------
 * tests/tools/NAME.py scripts, run as `/usr/bin/python3 tests/tools/NAME.py FRAC`.
 * tests/tools/vdb_check.py opens frac's .vdb files with the OpenVDB library
 * (Debian python3-openvdb, for /usr/bin/python3); tests/tools/mesh_check.py
 * reads the meshes of 3-D function sets with its own PLY/OBJ/STL readers;
 * admesh_check.py, vtk_check.py and blender_check.py open frac's meshes (and
 * a .vtk and a .vdb volume) with ADMesh, VTK and Blender (tests/tools/_meshes.py
 * makes the meshes and works out what each must show). An
 * exit 77 (a module or python missing) prints its "skipped: …" line and
 * counts neither way. */
static void run_py_check(const char *frac, const char *name)
{
    char label[256], script[300];
    snprintf(label, sizeof label, "tools/%s", name);
    snprintf(script, sizeof script, "tests/tools/%s", name);
    if (!matches_filter(label))
        return;
    if (access("/usr/bin/python3", X_OK) != 0) {
        printf("%s skipped: /usr/bin/python3 not installed\n", label);
        return;
    }
    char *argv[] = {"/usr/bin/python3", script, (char *)frac, NULL};
    buf out = {0}, err = {0}, why = {0};
    int rc = run(argv, NULL, &out, &err, 120);
    if (rc == 77) {
        printf("%s %s", label, out.d);
    } else {
        if (rc != 0)
            buf_fmt(&why, "  exit %d\n  stdout: %.3000s\n  stderr: %.3000s", rc, out.d, err.d);
        result(label, rc == 0, &why);
    }
    free(out.d); free(err.d); free(why.d);
}

/* ---- golden tests ---------------------------------------------------------------------- */

static int rm_tree(const char *dir)
{
    int n;
    char **names = list_dir(dir, NULL, &n);
    for (int i = 0; i < n; i++) {
        char p[4096];
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        struct stat st;
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode))
            rm_tree(p);
        else
            unlink(p);
        free(names[i]);
    }
    free(names);
    return rmdir(dir);
}

static int write_file(const char *path, const char *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    int ok = fwrite(data, 1, n, f) == n;
    return (fclose(f) == 0 && ok) ? 0 : -1;
}

static void run_golden(const char *frac, int update)
{
    int n;
    char **names = list_dir("examples", ".frac", &n);
    char tmpl[] = "/tmp/frac-golden-XXXXXX";
    char *tmp = mkdtemp(tmpl);
    if (!tmp) {
        perror("mkdtemp");
        exit(2);
    }
    for (int i = 0; i < n; i++) {
        char script[4096], base[1024], label[1200];
        snprintf(script, sizeof script, "examples/%s", names[i]);
        snprintf(base, sizeof base, "%.*s", (int)(strlen(names[i]) - 5), names[i]);
        snprintf(label, sizeof label, "golden/%s", base);
        if (!matches_filter(label))
            continue;
        const char *threads[] = {"1", "3"};
        buf why = {0};
        int ok = 1;
        for (int t = 0; t < (update ? 1 : 2); t++) {
            char outdir[4200];
            snprintf(outdir, sizeof outdir, "%s/%s-%s", tmp, base, threads[t]);
            mkdir(outdir, 0755);
            char *argv[] = {(char *)frac, "--quiet", "--threads", (char *)threads[t], "-o", outdir, script, NULL};
            buf out = {0}, err = {0};
            int rc = run(argv, NULL, &out, &err, timeout_s);
            if (rc != 0) {
                ok = 0;
                buf_fmt(&why, "  --threads %s: exit %d%s\n  stderr: %.3000s\n", threads[t], rc,
                        rc < 0 ? " (timeout)" : "", err.d);
                free(out.d); free(err.d);
                break;
            }
            char gdir[4200];
            snprintf(gdir, sizeof gdir, "tests/golden/%s", base);
            if (update) {
                mkdir("tests/golden", 0755);
                rm_tree(gdir);
                mkdir(gdir, 0755);
                char p[4400];
                snprintf(p, sizeof p, "%s/stdout.txt", gdir);
                write_file(p, out.d, out.n);
            }
            int nf;
            char **files = list_dir(outdir, NULL, &nf);
            for (int f = 0; f < nf; f++) {
                char op[4400], gp[4400];
                snprintf(op, sizeof op, "%s/%s", outdir, files[f]);
                snprintf(gp, sizeof gp, "%s/%s", gdir, files[f]);
                size_t ol, gl;
                char *od = read_file(op, &ol);
                if (update) {
                    write_file(gp, od, ol);
                } else {
                    char *gd = read_file(gp, &gl);
                    if (!gd) {
                        ok = 0;
                        buf_fmt(&why, "  %s: no golden %s (run `make golden` and review the diff)\n",
                                files[f], gp);
                    } else if (gl != ol || memcmp(gd, od, ol) != 0) {
                        ok = 0;
                        buf_fmt(&why, "  --threads %s: %s differs from %s (%zu vs %zu bytes)\n", threads[t],
                                files[f], gp, ol, gl);
                    }
                    free(gd);
                }
                free(od);
                free(files[f]);
            }
            free(files);
            if (!update) {
                /* every golden file must be produced, and stdout must match */
                int ng;
                char **gfiles = list_dir(gdir, NULL, &ng);
                if (!gfiles) {
                    ok = 0;
                    buf_fmt(&why, "  no goldens in %s (run `make golden`)\n", gdir);
                }
                for (int g = 0; g < ng; g++) {
                    char op[4400];
                    snprintf(op, sizeof op, "%s/%s", outdir, gfiles[g]);
                    if (strcmp(gfiles[g], "stdout.txt") == 0) {
                        char gp[4400];
                        snprintf(gp, sizeof gp, "%s/stdout.txt", gdir);
                        char *gd = read_file(gp, NULL);
                        if (!gd || strcmp(gd, out.d) != 0) {
                            ok = 0;
                            buf_fmt(&why, "  stdout differs from %s:\n%.2000s", gp, out.d);
                        }
                        free(gd);
                    } else if (access(op, F_OK) != 0) {
                        ok = 0;
                        buf_fmt(&why, "  %s was not written (golden has it)\n", gfiles[g]);
                    }
                    free(gfiles[g]);
                }
                free(gfiles);
            }
            free(out.d);
            free(err.d);
        }
        if (update)
            printf("updated %s\n", label);
        else
            result(label, ok, &why);
        free(why.d);
    }
    rm_tree(tmp);
}

/* ---- docs are tests ------------------------------------------------------------------
 * A block opens with ``` and a tag (its indent is removed from its lines):
 *   frac    run by piping it to `frac --quiet repl` in a fresh folder (outputs
 *           written there): exit 0, and stdout must equal the ```output block
 *           that directly follows it, or be empty if none does;
 *   output  that expected output;
 *   text, c shown, never run (transcripts, messages, formulas, C excerpts);
 *   anything else (sh, …) and any block after a line "<!-- not run: REASON -->"
 *           is not run, and must carry that line with a reason.
 * A block without a tag is an error, so no block is left unchecked by accident. */
typedef struct doc_block {
    char tag[32];
    int line;      /* of the opening fence */
    int not_run;   /* 1: marked with a reason; -1: marked without one */
    buf text;
} doc_block;

static int read_doc_blocks(const char *path, doc_block **out)
{
    char *text = read_file(path, NULL);
    int n = 0, cap = 0, line = 0, in = 0;
    size_t indent = 0;
    int marked = 0;
    doc_block *v = NULL;
    for (char *p = text; p && *p;) {
        char *e = strchr(p, '\n');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        line++;
        size_t sp = 0;
        while (sp < l && p[sp] == ' ')
            sp++;
        int fence = l - sp >= 3 && strncmp(p + sp, "```", 3) == 0;
        if (in) {
            if (fence && l - sp == 3) {
                in = 0;
            } else {
                size_t cut = sp < indent ? sp : indent;
                buf_add(&v[n - 1].text, p + cut, l - cut);
                buf_add(&v[n - 1].text, "\n", 1);
            }
        } else if (fence) {
            if (n == cap) {
                cap = cap ? 2 * cap : 16;
                v = realloc(v, (size_t)cap * sizeof *v);
                if (!v)
                    exit(2);
            }
            doc_block *b = &v[n++];
            memset(b, 0, sizeof *b);
            snprintf(b->tag, sizeof b->tag, "%.*s", (int)(l - sp - 3), p + sp + 3);
            b->line = line;
            b->not_run = marked;
            buf_add(&b->text, "", 0);
            in = 1;
            indent = sp;
            marked = 0;
        } else if (l > sp) {
            const char *m = "<!-- not run:";
            if (strncmp(p + sp, m, strlen(m)) == 0) {
                const char *r = p + sp + strlen(m);
                while (*r == ' ')
                    r++;
                marked = strncmp(r, "-->", 3) == 0 ? -1 : 1;
            } else {
                marked = 0;
            }
        }
        p = e ? e + 1 : p + l;
    }
    free(text);
    *out = v;
    return n;
}

static void run_doc_file(const char *frac, const char *path)
{
    doc_block *b;
    int n = read_doc_blocks(path, &b);
    for (int i = 0; i < n; i++) {
        char label[4200];
        snprintf(label, sizeof label, "docs %s:%d", path, b[i].line);
        if (!matches_filter(label) || strcmp(b[i].tag, "output") == 0)
            continue;
        buf why = {0};
        int ok = 1;
        const char *tag = b[i].tag;
        int next_output = i + 1 < n && strcmp(b[i + 1].tag, "output") == 0;
        if (b[i].not_run < 0) {
            ok = 0;
            buf_fmt(&why, "  <!-- not run: --> needs a reason\n");
        } else if (!*tag) {
            ok = 0;
            buf_fmt(&why, "  a code block needs a tag: frac (run), output, text or another with <!-- not run: REASON -->\n");
        } else if (b[i].not_run || strcmp(tag, "text") == 0 || strcmp(tag, "c") == 0) {
            if (next_output && !b[i].not_run) {
                ok = 0;
                buf_fmt(&why, "  an output block follows a block that is not run\n");
            }
        } else if (strcmp(tag, "frac") != 0) {
            ok = 0;
            buf_fmt(&why, "  a ```%s block is not run: mark it <!-- not run: REASON -->\n", tag);
        } else {
            char tmpl[] = "/tmp/frac-doc-XXXXXX";
            char *dir = mkdtemp(tmpl);
            if (!dir) {
                perror("mkdtemp");
                exit(2);
            }
            char *argv[] = {(char *)frac, "--quiet", "--threads", "2", "repl", NULL};
            buf out = {0}, err = {0};
            child_cwd = dir;
            int rc = run(argv, b[i].text.d, &out, &err, timeout_s);
            child_cwd = NULL;
            const char *want = next_output ? b[i + 1].text.d : "";
            if (rc != 0) {
                ok = 0;
                buf_fmt(&why, "  exit code %d, expected 0\n", rc);
            }
            if (strcmp(out.d, want) != 0) {
                ok = 0;
                buf_fmt(&why, "  stdout:\n%s  expected:\n%s", out.d, want);
            }
            if (!ok)
                buf_fmt(&why, "  stderr was:\n%.3000s", err.d);
            rm_tree(dir);
            free(out.d);
            free(err.d);
        }
        result(label, ok, &why);
        free(why.d);
    }
    for (int i = 0; i < n; i++)
        free(b[i].text.d);
    free(b);
}

static void run_docs(const char *frac)
{
    run_doc_file(frac, "README.md");
    int n;
    char **names = list_dir("docs", ".md", &n);
    for (int i = 0; i < n; i++) {
        char path[4096];
        snprintf(path, sizeof path, "docs/%s", names[i]);
        run_doc_file(frac, path);
        free(names[i]);
    }
    free(names);
}

int main(int argc, char **argv)
{
    const char *frac = NULL, *unit = NULL, *ptyrun = NULL;
    int update = 0, nscan = 0;
    const char **scan = calloc((size_t)argc, sizeof *scan);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--frac") == 0 && i + 1 < argc)
            frac = argv[++i];
        else if (strcmp(argv[i], "--unit") == 0 && i + 1 < argc)
            unit = argv[++i];
        else if (strcmp(argv[i], "--ptyrun") == 0 && i + 1 < argc)
            ptyrun = argv[++i];
        else if (strcmp(argv[i], "--fail-alloc") == 0 && i + 1 < argc)
            scan[nscan++] = argv[++i];
        else if (strcmp(argv[i], "--update-golden") == 0)
            update = 1;
        else if (strcmp(argv[i], "--timeout") == 0 && i + 1 < argc)
            timeout_s = atof(argv[++i]);
        else
            filter = argv[i];
    }
    if (!frac) {
        fprintf(stderr, "usage: runner --frac FRAC [--unit DIR] [--update-golden] [--fail-alloc SCRIPT]... [FILTER]\n");
        return 64;
    }
    static char fracabs[4096];
    if (!realpath(frac, fracabs)) {
        perror(frac);
        return 2;
    }
    if (update) {
        run_golden(fracabs, 1);
        return 0;
    }
    if (nscan) { /* only the allocation-failure loop, over the scripts given */
        for (int i = 0; i < nscan; i++)
            run_fail_alloc(fracabs, scan[i], 1, NULL);
        printf("%d passed, %d failed\n", passed, failed);
        free(scan);
        return failed ? 1 : 0;
    }
    free(scan);
    if (unit)
        run_unit(unit);
    run_lang_dir(fracabs, "tests/lang");
    run_lang_dir(fracabs, "tests/regression");
    run_cli_dir(fracabs);
    run_repl_dir(fracabs, "tests/repl");
    run_docs(fracabs);
    if (ptyrun) {
        static char ptyabs[4096];
        if (realpath(ptyrun, ptyabs))
            run_pty_dir(fracabs, ptyabs);
    }
    run_py_check(fracabs, "vdb_check.py");
    run_py_check(fracabs, "mesh_check.py");   /* 3-D function sets' meshes: own PLY/OBJ/STL readers */
    run_py_check(fracabs, "admesh_check.py"); /* STL meshes opened by ADMesh */
    run_py_check(fracabs, "vtk_check.py");    /* PLY/OBJ/STL meshes and a .vtk volume read by VTK */
    run_py_check(fracabs, "blender_check.py"); /* meshes and a .vdb imported by Blender (optional) */
    run_py_check(fracabs, "frames_check.py"); /* --frames from outside: frame identity, tty progress */
    run_py_check(fracabs, "apng_check.py");   /* APNG: own decoder, pngcheck, PIL, apngdis */
    run_py_check(fracabs, "watch_check.py");  /* frac watch in the background: edits, cancel, Ctrl-C */
    run_golden(fracabs, 0);
    run_fail_alloc(fracabs, "examples/tour.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/lang/core/functions.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/failalloc/engines_io.frac", 1, NULL);
    /* each of these crashed or printed a wrong value at some allocation before
     * the loop went on past tolerated failures (session 5): superifs sets,
     * the wood and marble warps, field compilation under the solid renderer */
    run_fail_alloc(fracabs, "tests/lang/fset/image_facts.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/lang/solid/wood.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/lang/solid/marble.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/lang/solid/render.frac", 1, NULL);
    /* session 7: a failed level-of-detail bound became "the finest level", a
     * 28908 MiB mesh and exit 65 (allocations 475, 557, 772, 821 of 1,663) */
    static const int wrinkly_lod[] = {475, 476, 477, 557, 558, 559, 772, 773, 774, 821, 822, 823, 0};
    run_fail_alloc(fracabs, "tests/lang/wrinkly/surface_facts.frac", 5, wrinkly_lod);
    /* session 7: out of memory while the check evaluated a constant argument
     * skipped the check (the script ran, printed, then failed at the call);
     * slice reported its image's out of memory as a bad value (exit 65) */
    run_fail_alloc(fracabs, "tests/lang/contract/camera_required.frac", 1, NULL);
    run_fail_alloc(fracabs, "tests/lang/contract/volume_choices_runtime.frac", 1, NULL);
    /* session 7, under ASan: a failed lex of a stdlib module (looking up
     * which module defines an unknown name) leaked its tokens and lost the
     * out-of-memory */
    run_fail_alloc(fracabs, "tests/lang/names/scope.frac", 1, NULL);
    /* one script per engine family the loops above do not reach, with a
     * stride (session 7: each scanned whole, or with a stride under 25,
     * outside make test; tests/README.md "Allocation failure") */
    run_fail_alloc(fracabs, "tests/lang/ifs/contraction.frac", 10, NULL);      /* IFS, RIFS, chaos game */
    run_fail_alloc(fracabs, "tests/lang/fset/order_facts.frac", 50, NULL);     /* function sets by order */
    run_fail_alloc(fracabs, "tests/lang/fset/chaos_3d_facts.frac", 100, NULL); /* 3-D chaos, views */
    run_fail_alloc(fracabs, "tests/lang/fset/polyhedron_facts.frac", 20, NULL); /* fset meshes */
    run_fail_alloc(fracabs, "tests/lang/solid/levels.frac", 25, NULL);         /* isosurface levels */
    run_fail_alloc(fracabs, "examples/asai_fig1.frac", 10, NULL);              /* tiles, strokes, PNG */
    run_fail_alloc(fracabs, "tests/lang/fit/budget.frac", 8, NULL);            /* fit */
    run_fail_alloc(fracabs, "tests/lang/fields/sdf.frac", 12, NULL);           /* fields, raymarch */
    run_fail_alloc(fracabs, "examples/super_steal.frac", 4, NULL);             /* steal */
    run_fail_alloc(fracabs, "examples/super_top.frac", 2, NULL);               /* fractal tops */
    run_fail_alloc(fracabs, "examples/ifs_flam3.frac", 10, NULL);              /* flam3 writer */
    run_fail_alloc(fracabs, "examples/ifs_fractint.frac", 4, NULL);            /* .ifs reader */
    run_fail_alloc(fracabs, "examples/rifs_forbidden.frac", 8, NULL);          /* forbidden-word RIFS */
    run_fail_alloc(fracabs, "examples/anim_morph.frac", 2, NULL);              /* APNG writer */
    run_fail_alloc(fracabs, "examples/wrinkly_fig2.frac", 2, NULL);            /* wrinkly curves */
    run_fail_alloc(fracabs, "examples/hypertexture_vdb.frac", 2, NULL);        /* hypertexture, VDB writer */
    run_fail_alloc(fracabs, "examples/patterns.frac", 2, NULL);                /* PNG 8/16-bit, PPM, PGM, PFM writers */
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
