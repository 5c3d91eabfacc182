/* ptyrun.c — run an interactive program on a pseudo-terminal and play a script.
 *
 *   ptyrun [--cols N] [--rows N] [--timeout S] [--term T] [--check-termios]
 *          [--log FILE] SCRIPT -- CMD ARGS...
 *
 * CMD runs on a new pty (its own session, the pty as controlling terminal
 * and as stdin/stdout/stderr, window size COLS×ROWS, default 80×24, TERM=T,
 * default xterm-256color). SCRIPT (a file, or - for stdin) is played line
 * by line:
 *
 *   send TEXT      write TEXT to the terminal (what the user types)
 *   expect TEXT    wait until TEXT appears in the output after the end of the
 *                  previous match (so expects match in order); fails after
 *                  the timeout
 *   sleep MS       wait MS milliseconds (still capturing output)
 *   eof            type the terminal's EOF character (normally Ctrl-D)
 *   signal NAME    send INT, TERM, HUP, QUIT, TSTP, CONT or KILL to CMD's
 *                  process group
 *   wait           wait until CMD exits (fails after the timeout)
 *   # ...          comment; blank lines are ignored
 *
 * TEXT is everything after the single space following the command, with the
 * escapes \r \n \t \e (ESC) \\ \xHH; nothing else is interpreted, so
 * "expect \e[0K" matches an erase-line sequence. Output is captured as is
 * (nothing stripped).
 *
 * After the script ptyrun waits for CMD to exit (at most the timeout, then
 * kills it) and prints to stdout
 *   exit=N | exit=signal:N | exit=killed-after-timeout | exit=killed-after-failure
 *   termios=same | termios=changed (iflag/oflag/cflag/lflag/cc ...)   [--check-termios]
 * the second comparing the pty's settings after CMD exited with those
 * before it started (to check that raw mode was restored). --log FILE
 * writes everything CMD printed. Exit status: 0 if every expect (and wait)
 * succeeded, 1 if not (with the failed line and the tail of the output on
 * stderr), 2 on usage or system errors. The timeout (default 5 s) applies
 * to each expect and wait separately; an expect fails at once when the
 * program has exited without printing TEXT. After a failed line the program
 * is killed. Send keys to a line editor only after expecting its prompt:
 * keys typed while the terminal is still in cooked mode are processed by
 * the terminal (echo, ^C, ^D, ^U ...) before the editor sees them.
 *
 * Build (not part of the Makefile's unit tests):
 *   cc -std=c11 -O2 -Wall -Wextra -Werror -o build/ptyrun tests/ptyrun.c
 */
#define _XOPEN_SOURCE 700
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

static int g_master = -1;
static pid_t g_child = -1;
static int g_status, g_exited;
static char *g_out;          /* captured output */
static size_t g_len, g_cap;
static size_t g_mark;        /* where the next expect starts looking */

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static void die(const char *what)
{
    fprintf(stderr, "ptyrun: %s: %s\n", what, strerror(errno));
    if (g_child > 0 && !g_exited)
        kill(-g_child, SIGKILL);
    exit(2);
}

static void reap(void)
{
    if (!g_exited && g_child > 0 && waitpid(g_child, &g_status, WNOHANG) == g_child)
        g_exited = 1;
}

/* Capture output for at most ms milliseconds (returns sooner once some
 * output has arrived and no more is immediately available). */
static void pump(int ms)
{
    struct pollfd p = {.fd = g_master, .events = POLLIN};
    int r = poll(&p, 1, ms);
    if (r <= 0)
        return;
    for (;;) {
        if (g_cap - g_len < 4096) {
            size_t ncap = g_cap ? g_cap * 2 : 65536;
            char *nb = realloc(g_out, ncap + 1);
            if (!nb)
                die("out of memory");
            g_out = nb;
            g_cap = ncap;
        }
        ssize_t n = read(g_master, g_out + g_len, g_cap - g_len);
        if (n <= 0)
            break; /* EAGAIN: nothing more now; EIO: no slave left */
        g_len += (size_t)n;
        g_out[g_len] = 0;
    }
}

/* Decode the escapes of TEXT into out; returns the length or -1. */
static long unescape(const char *s, char *out)
{
    long n = 0;
    for (; *s; s++) {
        if (*s != '\\') {
            out[n++] = *s;
            continue;
        }
        s++;
        switch (*s) {
        case 'r': out[n++] = '\r'; break;
        case 'n': out[n++] = '\n'; break;
        case 't': out[n++] = '\t'; break;
        case 'e': out[n++] = 0x1b; break;
        case '\\': out[n++] = '\\'; break;
        case 'x': {
            int v = 0;
            for (int k = 0; k < 2; k++) {
                char c = s[1];
                int d = c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
                      : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
                if (d < 0)
                    return -1;
                v = v * 16 + d;
                s++;
            }
            out[n++] = (char)v;
            break;
        }
        default: return -1;
        }
    }
    return n;
}

static void send_bytes(const char *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(g_master, p, n);
        if (w < 0) {
            if (errno == EAGAIN || errno == EINTR) {
                pump(10); /* the child may be blocked writing: drain */
                continue;
            }
            die("write to the pty");
        }
        p += w;
        n -= (size_t)w;
    }
}

static const char *find(const char *needle, size_t n)
{
    if (n == 0)
        return g_out ? g_out + g_mark : "";
    for (size_t i = g_mark; i + n <= g_len; i++)
        if (memcmp(g_out + i, needle, n) == 0)
            return g_out + i;
    return NULL;
}

/* Print the last bytes of the output with control characters escaped. */
static void show_tail(FILE *f, size_t max)
{
    size_t a = g_len > max ? g_len - max : 0;
    fprintf(f, "--- captured output%s (%zu bytes in all, expect position %zu) ---\n",
            a ? " tail" : "", g_len, g_mark);
    for (size_t i = a; i < g_len; i++) {
        unsigned char c = (unsigned char)g_out[i];
        if (c == '\n')
            fputs("\\n\n", f);
        else if (c == '\r')
            fputs("\\r", f);
        else if (c == 0x1b)
            fputs("\\e", f);
        else if (c < 0x20 || c == 0x7f)
            fprintf(f, "\\x%02x", c);
        else
            fputc(c, f);
    }
    fputs("\n---\n", f);
}

static int sig_by_name(const char *s)
{
    static const struct { const char *n; int s; } t[] = {
        {"INT", SIGINT},   {"TERM", SIGTERM}, {"HUP", SIGHUP}, {"QUIT", SIGQUIT},
        {"TSTP", SIGTSTP}, {"CONT", SIGCONT}, {"KILL", SIGKILL},
    };
    if (strncmp(s, "SIG", 3) == 0)
        s += 3;
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        if (strcmp(s, t[i].n) == 0)
            return t[i].s;
    return 0;
}

static void usage(void)
{
    fprintf(stderr, "usage: ptyrun [--cols N] [--rows N] [--timeout S] [--term T] [--check-termios]\n"
                    "              [--log FILE] SCRIPT -- CMD ARGS...\n");
    exit(2);
}

static int termios_diff(const struct termios *a, const struct termios *b, char *why, size_t n)
{
    why[0] = 0;
    size_t k = 0;
#define FLAG(f)                                                                          \
    if (a->f != b->f)                                                                    \
        k += (size_t)snprintf(why + k, k < n ? n - k : 0, " " #f " %#lx->%#lx", (unsigned long)a->f, \
                              (unsigned long)b->f);
    FLAG(c_iflag)
    FLAG(c_oflag)
    FLAG(c_cflag)
    FLAG(c_lflag)
#undef FLAG
    for (int i = 0; i < NCCS; i++)
        if (a->c_cc[i] != b->c_cc[i] && k < n)
            k += (size_t)snprintf(why + k, n - k, " c_cc[%d] %d->%d", i, a->c_cc[i], b->c_cc[i]);
    return why[0] != 0;
}

int main(int argc, char **argv)
{
    int cols = 80, rows = 24, check_termios = 0;
    double timeout = 5;
    const char *term = "xterm-256color", *log_path = NULL, *script = NULL;
    int i = 1;
    for (; i < argc; i++) {
        if (strcmp(argv[i], "--") == 0) {
            i++;
            break;
        } else if (strcmp(argv[i], "--cols") == 0 && i + 1 < argc) {
            cols = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--rows") == 0 && i + 1 < argc) {
            rows = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--timeout") == 0 && i + 1 < argc) {
            timeout = atof(argv[++i]);
        } else if (strcmp(argv[i], "--term") == 0 && i + 1 < argc) {
            term = argv[++i];
        } else if (strcmp(argv[i], "--log") == 0 && i + 1 < argc) {
            log_path = argv[++i];
        } else if (strcmp(argv[i], "--check-termios") == 0) {
            check_termios = 1;
        } else if (argv[i][0] == '-' && argv[i][1] == '-') {
            usage();
        } else if (!script) {
            script = argv[i];
        } else {
            usage();
        }
    }
    if (!script || i >= argc || cols < 1 || rows < 1 || cols > 10000 || rows > 10000 || !(timeout > 0))
        usage();
    char **cmd = argv + i;
    FILE *sf = strcmp(script, "-") == 0 ? stdin : fopen(script, "r");
    if (!sf)
        die(script);

    g_master = posix_openpt(O_RDWR | O_NOCTTY);
    if (g_master < 0 || grantpt(g_master) != 0 || unlockpt(g_master) != 0)
        die("cannot create a pseudo-terminal");
    const char *sname = ptsname(g_master);
    if (!sname)
        die("ptsname");
    /* The parent keeps the slave open: its settings can be read after the
     * child exits, and reads of the master never fail with EIO meanwhile. */
    int slave = open(sname, O_RDWR | O_NOCTTY);
    if (slave < 0)
        die(sname);
    struct winsize ws = {.ws_row = (unsigned short)rows, .ws_col = (unsigned short)cols};
    if (ioctl(slave, TIOCSWINSZ, &ws) != 0)
        die("TIOCSWINSZ");
    struct termios before;
    if (tcgetattr(slave, &before) != 0)
        die("tcgetattr");
    signal(SIGPIPE, SIG_IGN);
    fflush(NULL);
    g_child = fork();
    if (g_child < 0)
        die("fork");
    if (g_child == 0) {
        setsid();
        if (ioctl(slave, TIOCSCTTY, 0) != 0) {
            perror("ptyrun: TIOCSCTTY");
            _exit(127);
        }
        dup2(slave, 0);
        dup2(slave, 1);
        dup2(slave, 2);
        if (slave > 2)
            close(slave);
        close(g_master);
        setenv("TERM", term, 1);
        char cs[16], rs[16];
        snprintf(cs, sizeof cs, "%d", cols);
        snprintf(rs, sizeof rs, "%d", rows);
        setenv("COLUMNS", cs, 1);
        setenv("LINES", rs, 1);
        signal(SIGPIPE, SIG_DFL);
        execvp(cmd[0], cmd);
        fprintf(stderr, "ptyrun: cannot run %s: %s\n", cmd[0], strerror(errno));
        _exit(127);
    }
    fcntl(g_master, F_SETFL, fcntl(g_master, F_GETFL) | O_NONBLOCK);

    int ok = 1, lineno = 0;
    char line[8192], text[8192];
    while (ok && fgets(line, sizeof line, sf)) {
        lineno++;
        size_t n = strlen(line);
        if (n > 0 && line[n - 1] == '\n')
            line[--n] = 0;
        if (n > 0 && line[n - 1] == '\r')
            line[--n] = 0;
        if (n == 0 || line[0] == '#')
            continue;
        char *arg = strchr(line, ' ');
        if (arg)
            *arg++ = 0;
        const char *op = line;
        long tn = 0;
        if ((strcmp(op, "send") == 0 || strcmp(op, "expect") == 0) &&
            (!arg || (tn = unescape(arg, text)) < 0)) {
            fprintf(stderr, "ptyrun: %s:%d: %s needs text with valid escapes (\\r \\n \\t \\e \\\\ \\xHH)\n",
                    script, lineno, op);
            ok = 0;
            break;
        }
        if (strcmp(op, "send") == 0) {
            pump(0);
            send_bytes(text, (size_t)tn);
        } else if (strcmp(op, "expect") == 0) {
            double t0 = now_s();
            const char *at;
            int last = 0;
            while (!(at = find(text, (size_t)tn))) {
                if (last || now_s() - t0 > timeout) {
                    if (last)
                        fprintf(stderr, "ptyrun: %s:%d: expect \"%s\" not seen before the program exited\n",
                                script, lineno, arg);
                    else
                        fprintf(stderr, "ptyrun: %s:%d: expect \"%s\" not seen within %g s\n", script,
                                lineno, arg, timeout);
                    show_tail(stderr, 2000);
                    ok = 0;
                    break;
                }
                reap();
                if (g_exited) { /* one last look at what it wrote, then give up */
                    pump(50);
                    last = 1;
                } else {
                    pump(20);
                }
            }
            if (at)
                g_mark = (size_t)(at - g_out) + (size_t)tn;
        } else if (strcmp(op, "sleep") == 0 && arg) {
            double t0 = now_s(), ms = atof(arg);
            while ((now_s() - t0) * 1000 < ms)
                pump(5);
        } else if (strcmp(op, "eof") == 0) {
            struct termios t;
            char c = tcgetattr(slave, &t) == 0 ? (char)t.c_cc[VEOF] : 4;
            pump(0);
            send_bytes(&c, 1);
        } else if (strcmp(op, "signal") == 0 && arg && sig_by_name(arg)) {
            pump(0);
            kill(-g_child, sig_by_name(arg));
        } else if (strcmp(op, "wait") == 0) {
            double t0 = now_s();
            for (reap(); !g_exited; reap()) {
                if (now_s() - t0 > timeout) {
                    fprintf(stderr, "ptyrun: %s:%d: the program did not exit within %g s\n", script,
                            lineno, timeout);
                    show_tail(stderr, 2000);
                    ok = 0;
                    break;
                }
                pump(10);
            }
        } else {
            fprintf(stderr, "ptyrun: %s:%d: unknown command '%s'\n", script, lineno, op);
            ok = 0;
        }
    }
    if (sf != stdin)
        fclose(sf);

    /* wait for the program to finish (it gets the timeout once more) */
    double t0 = now_s();
    int killed = 0; /* 1 after the timeout, 2 after a failed line */
    for (reap(); !g_exited; reap()) {
        if (!ok || now_s() - t0 > timeout) {
            killed = ok ? 1 : 2;
            if (ok) {
                fprintf(stderr, "ptyrun: the program did not exit within %g s after the script\n", timeout);
                show_tail(stderr, 2000);
                ok = 0;
            }
            kill(-g_child, SIGKILL);
            waitpid(g_child, &g_status, 0);
            g_exited = 1;
            break;
        }
        pump(10);
    }
    pump(50); /* what it wrote last */

    if (killed)
        printf("exit=%s\n", killed == 1 ? "killed-after-timeout" : "killed-after-failure");
    else if (WIFEXITED(g_status))
        printf("exit=%d\n", WEXITSTATUS(g_status));
    else if (WIFSIGNALED(g_status))
        printf("exit=signal:%d\n", WTERMSIG(g_status));
    if (check_termios) {
        struct termios after;
        char why[1024];
        if (tcgetattr(slave, &after) != 0)
            die("tcgetattr after");
        if (termios_diff(&before, &after, why, sizeof why))
            printf("termios=changed (%s )\n", why);
        else
            printf("termios=same\n");
    }
    if (log_path) {
        FILE *lf = fopen(log_path, "wb");
        if (!lf || (g_len && fwrite(g_out, 1, g_len, lf) != g_len) || fclose(lf) != 0)
            die(log_path);
    }
    fflush(stdout);
    free(g_out);
    close(slave);
    close(g_master);
    return ok ? 0 : 1;
}
