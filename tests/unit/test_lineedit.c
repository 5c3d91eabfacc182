/* test_lineedit.c — the line editor driven through a pseudo-terminal.
 *
 * A child process runs lineedit on the slave side of a pty made here
 * (posix_openpt); the parent plays the user on the master side and gets the
 * results back through a pipe, one line per lineedit_read:
 *   "L:<text>" LINE, "E" EOF, "I" INTERRUPT, "X" ERROR, each followed by
 *   " T=1" if the slave's termios after the read equals the one before.
 * Read k uses the prompt "pK> ", so the parent knows the editor is in raw
 * mode (the prompt is drawn only after that) before it sends keys.
 * Expected results are the edits worked out by hand from the key bindings.
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
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "rt_alloc.h"
#include "lineedit.h"

#define WAIT_MS 3000

typedef struct sess {
    int master, slave;
    int res;        /* read end of the result pipe */
    pid_t pid;
    char out[65536]; /* everything the child drew */
    size_t out_len;
    char rbuf[4096]; /* result lines not yet consumed */
    size_t rlen;
    int next_prompt;
    struct termios initial;
} sess;

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static void child_run(int slave, int res, const char *hist, int hist_max, const char *term)
{
    setpgid(0, 0);
    setenv("TERM", term, 1);
    lineedit *le = lineedit_new(slave, slave, hist, hist_max);
    for (int k = 0; le; k++) {
        char prompt[32], msg[1200];
        snprintf(prompt, sizeof prompt, "p%d> ", k);
        struct termios before, after;
        tcgetattr(slave, &before);
        char *line;
        lineedit_result r = lineedit_read(le, prompt, &line);
        tcgetattr(slave, &after);
        int same = before.c_lflag == after.c_lflag && before.c_iflag == after.c_iflag &&
                   before.c_oflag == after.c_oflag && before.c_cflag == after.c_cflag &&
                   memcmp(before.c_cc, after.c_cc, sizeof before.c_cc) == 0;
        if (r == LINEEDIT_LINE)
            snprintf(msg, sizeof msg, "L:%.1000s T=%d\n", line, same);
        else
            snprintf(msg, sizeof msg, "%c T=%d\n", r == LINEEDIT_EOF ? 'E' : r == LINEEDIT_INTERRUPT ? 'I' : 'X', same);
        if (write(res, msg, strlen(msg)) < 0)
            break;
        if (r == LINEEDIT_LINE) {
            lineedit_history_add(le, line);
            rt_free(line);
        }
        if (r == LINEEDIT_EOF || r == LINEEDIT_ERROR)
            break;
    }
    lineedit_free(le);
    _exit(0);
}

static int sess_start(sess *s, int cols, const char *hist, int hist_max, const char *term)
{
    memset(s, 0, sizeof *s);
    s->master = posix_openpt(O_RDWR | O_NOCTTY);
    if (s->master < 0 || grantpt(s->master) != 0 || unlockpt(s->master) != 0)
        return -1;
    s->slave = open(ptsname(s->master), O_RDWR | O_NOCTTY);
    if (s->slave < 0)
        return -1;
    struct winsize ws = {.ws_row = 24, .ws_col = (unsigned short)cols};
    ioctl(s->master, TIOCSWINSZ, &ws);
    tcgetattr(s->slave, &s->initial);
    int p[2];
    if (pipe(p) != 0)
        return -1;
    fflush(NULL);
    s->pid = fork();
    if (s->pid < 0)
        return -1;
    if (s->pid == 0) {
        close(s->master);
        close(p[0]);
        child_run(s->slave, p[1], hist, hist_max, term);
    }
    close(p[1]);
    s->res = p[0];
    fcntl(s->master, F_SETFL, O_NONBLOCK);
    return 0;
}

/* Read whatever the child drew (waiting up to ms for something). */
static void pump(sess *s, int ms)
{
    struct pollfd p = {.fd = s->master, .events = POLLIN};
    if (poll(&p, 1, ms) <= 0)
        return;
    for (;;) {
        ssize_t n = read(s->master, s->out + s->out_len, sizeof s->out - 1 - s->out_len);
        if (n <= 0)
            break;
        s->out_len += (size_t)n;
        s->out[s->out_len] = 0;
    }
}

static int out_has(const sess *s, const char *needle)
{
    size_t n = strlen(needle);
    for (size_t i = 0; i + n <= s->out_len; i++)
        if (memcmp(s->out + i, needle, n) == 0)
            return 1;
    return 0;
}

static int wait_out(sess *s, const char *needle)
{
    double t0 = now_ms();
    while (!out_has(s, needle)) {
        if (now_ms() - t0 > WAIT_MS)
            return 0;
        pump(s, 20);
    }
    return 1;
}

static void send_keys(sess *s, const char *keys)
{
    size_t n = strlen(keys);
    while (n > 0) {
        ssize_t w = write(s->master, keys, n);
        if (w < 0 && (errno == EAGAIN || errno == EINTR))
            continue;
        if (w <= 0)
            return;
        keys += w;
        n -= (size_t)w;
    }
}

/* The next result line from the child, or "(timeout)". */
static const char *next_result(sess *s)
{
    static char line[1200];
    double t0 = now_ms();
    for (;;) {
        char *nl = memchr(s->rbuf, '\n', s->rlen);
        if (nl) {
            size_t n = (size_t)(nl - s->rbuf);
            memcpy(line, s->rbuf, n);
            line[n] = 0;
            memmove(s->rbuf, nl + 1, s->rlen - n - 1);
            s->rlen -= n + 1;
            return line;
        }
        if (now_ms() - t0 > WAIT_MS)
            return "(timeout)";
        pump(s, 0);
        struct pollfd p = {.fd = s->res, .events = POLLIN};
        if (poll(&p, 1, 20) > 0) {
            ssize_t n = read(s->res, s->rbuf + s->rlen, sizeof s->rbuf - s->rlen);
            if (n <= 0)
                return "(closed)";
            s->rlen += (size_t)n;
        }
    }
}

/* Wait for the next prompt, type keys, return the result of that read. */
static const char *type(sess *s, const char *keys)
{
    char prompt[32];
    snprintf(prompt, sizeof prompt, "p%d> ", s->next_prompt++);
    if (!wait_out(s, prompt))
        return "(no prompt)";
    send_keys(s, keys);
    return next_result(s);
}

/* Close everything, reap the child; returns its wait status. */
static int sess_end(sess *s)
{
    int st = -1;
    double t0 = now_ms();
    while (waitpid(s->pid, &st, WNOHANG) == 0) {
        if (now_ms() - t0 > WAIT_MS) {
            kill(s->pid, SIGKILL);
            waitpid(s->pid, &st, 0);
            break;
        }
        pump(s, 10);
    }
    close(s->res);
    close(s->master);
    close(s->slave);
    return st;
}

static int termios_same(const struct termios *a, const struct termios *b)
{
    return a->c_lflag == b->c_lflag && a->c_iflag == b->c_iflag && a->c_oflag == b->c_oflag &&
           a->c_cflag == b->c_cflag && memcmp(a->c_cc, b->c_cc, sizeof a->c_cc) == 0;
}

#define EXPECT(s, keys, want)                                                       \
    do {                                                                            \
        const char *got_ = type(s, keys);                                           \
        CHECK(strcmp(got_, want) == 0, "keys %s: got '%s', want '%s'", #keys, got_, want); \
    } while (0)

static void test_editing(void)
{
    sess s;
    if (sess_start(&s, 80, NULL, 100, "xterm") != 0) {
        CHECK(0, "cannot start a pty session: %s", strerror(errno));
        return;
    }
    EXPECT(&s, "hello\r", "L:hello T=1");
    EXPECT(&s, "x = 1\n", "L:x = 1 T=1");                  /* LF also submits */
    EXPECT(&s, "helo\x1b[Dl\r", "L:hello T=1");           /* left arrow, insert */
    EXPECT(&s, "ac\x02" "b\x06" "d\r", "L:abcd T=1");      /* Ctrl-B, Ctrl-F */
    EXPECT(&s, "ac\x1b[D\x1b[D\x1b[Cb\r", "L:abc T=1");    /* right arrow */
    EXPECT(&s, "ac\x1bOD" "b\x1bOC" "d\r", "L:abcd T=1");  /* SS3 arrows */
    /* Home in every form, then End in every form */
    EXPECT(&s, "bc\x1b[Ha\r", "L:abc T=1");
    EXPECT(&s, "bc\x1b[1~a\r", "L:abc T=1");
    EXPECT(&s, "bc\x1b[7~a\r", "L:abc T=1");
    EXPECT(&s, "bc\x1bOHa\r", "L:abc T=1");
    EXPECT(&s, "bc\x01" "a\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x1b[F" "c\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x1b[4~" "c\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x1b[8~" "c\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x1bOF" "c\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x05" "c\r", "L:abc T=1");
    EXPECT(&s, "ab\x01\x1b[1;5F" "c\r", "L:abc T=1");      /* modifier parameter ignored */
    /* deleting */
    EXPECT(&s, "abx\x7f" "c\r", "L:abc T=1");              /* Backspace 0x7f */
    EXPECT(&s, "abx\x08" "c\r", "L:abc T=1");              /* Ctrl-H */
    EXPECT(&s, "\x7f\x7f" "a\r", "L:a T=1");               /* Backspace at start: nothing */
    EXPECT(&s, "xabc\x01\x1b[3~\r", "L:abc T=1");          /* Delete under cursor */
    EXPECT(&s, "abc\x1b[3~\r", "L:abc T=1");               /* Delete at end: nothing */
    EXPECT(&s, "abc def\x1b[D\x1b[D\x1b[D\x15\r", "L:def T=1");   /* Ctrl-U */
    EXPECT(&s, "abc def\x01\x1b[C\x0b\r", "L:a T=1");             /* Ctrl-K */
    EXPECT(&s, "let x = foo bar\x17\r", "L:let x = foo  T=1");    /* Ctrl-W */
    EXPECT(&s, "a bc  \x17\r", "L:a  T=1");                       /* blanks then a word */
    EXPECT(&s, "one two\x1b[D\x1b[D\x17\r", "L:one wo T=1");      /* mid-word: left part */
    /* Ctrl-D */
    EXPECT(&s, "xabc\x01\x04\r", "L:abc T=1");             /* deletes under the cursor */
    EXPECT(&s, "ab\x04\r", "L:ab T=1");                    /* at the end: nothing */
    /* Ctrl-C cancels the line; the next read starts empty */
    EXPECT(&s, "abc\x03", "I T=1");
    CHECK(wait_out(&s, "^C\r\n"), "Ctrl-C echoes ^C and a new line");
    EXPECT(&s, "x\r", "L:x T=1");
    /* unknown escapes and control bytes are ignored; a lone ESC too */
    EXPECT(&s, "a\x1b[99~\x1b[5~\x07" "b\r", "L:ab T=1");
    /* Ctrl-L clears the screen and redraws */
    EXPECT(&s, "ab\x0c" "c\r", "L:abc T=1");
    CHECK(wait_out(&s, "\x1b[H\x1b[2J"), "Ctrl-L writes clear-screen");
    /* UTF-8: é (C3 A9) and € (E2 82 AC) are one column and one cursor step */
    EXPECT(&s, "\xc3\xa9x\x1b[D\x1b[Da\r", "L:a\xc3\xa9x T=1");
    EXPECT(&s, "a\xe2\x82\xac\x7f" "b\r", "L:ab T=1");
    EXPECT(&s, "\xe2\x82\xac\xc3\xa9\x1b[D\x1b[D\x1b[3~\r", "L:\xc3\xa9 T=1");
    /* final redraw of "aéx" after Enter: the cursor goes to prompt width + 3 columns */
    char want[64];
    char pr[16];
    int pw = snprintf(pr, sizeof pr, "p%d> ", s.next_prompt);
    snprintf(want, sizeof want, "\r%sa\xc3\xa9x\x1b[0K\r\x1b[%dC\r\n", pr, pw + 3);
    EXPECT(&s, "a\xc3\xa9x\r", "L:a\xc3\xa9x T=1");
    CHECK(wait_out(&s, want), "redraw of a line with a two-byte character: cursor at column %d", pw + 3);
    /* Ctrl-D on an empty line ends the session */
    EXPECT(&s, "\x04", "E T=1");
    int st = sess_end(&s);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "child exit status %d", st);
    (void)termios_same;
}

static void test_history(void)
{
    sess s;
    if (sess_start(&s, 80, NULL, 100, "xterm") != 0) {
        CHECK(0, "cannot start a pty session");
        return;
    }
    EXPECT(&s, "one\r", "L:one T=1");
    EXPECT(&s, "two\r", "L:two T=1");
    EXPECT(&s, "\x1b[A\x1b[A!\r", "L:one! T=1");     /* recall the older entry and edit it */
    /* history: one two one!; type a draft, browse up and back down to it */
    EXPECT(&s, "draft\x1b[A\x1b[A\x1b[B\x1b[BX\r", "L:draftX T=1");
    EXPECT(&s, "\x1b[A\x1b[A\x1b[A\x1b[A\x1b[A\x1b[A\x1b[A\r", "L:one T=1"); /* stops at the oldest */
    /* history: one two one! draftX one; an edit to a recalled entry survives browsing */
    EXPECT(&s, "\x1b[AZ\x1b[A\x1b[B\r", "L:oneZ T=1");
    EXPECT(&s, "\x1b[A\x1b[A\r", "L:one T=1");           /* the stored entry itself is unchanged */
    EXPECT(&s, "\x10\x10\x0e\r", "L:one T=1");           /* Ctrl-P/Ctrl-N: up, up, down */
    EXPECT(&s, "\x1b[B\x1b[Bq\r", "L:q T=1");             /* Down at the live line: nothing */
    EXPECT(&s, "\x04", "E T=1");
    sess_end(&s);
}

static void test_scroll(void)
{
    sess s;
    if (sess_start(&s, 20, NULL, 0, "xterm") != 0) {
        CHECK(0, "cannot start a pty session");
        return;
    }
    /* 20 columns, prompt 4: 15 text columns and the cursor in column 19 */
    EXPECT(&s, "abcdefghijklmnopqrstuvwxyz0123\r", "L:abcdefghijklmnopqrstuvwxyz0123 T=1");
    CHECK(wait_out(&s, "\rp0> pqrstuvwxyz0123\x1b[0K\r\x1b[19C\r\n"),
          "scrolled view shows the last 15 characters with the cursor in column 19");
    /* cursor at the start: the view shows the first 15 characters, no cursor move
     * beyond the prompt */
    CHECK(wait_out(&s, "p1> "), "prompt");
    send_keys(&s, "abcdefghijklmnopqrstuvwxyz0123\x01");
    CHECK(wait_out(&s, "\rp1> abcdefghijklmno\x1b[0K\r\x1b[4C"), "view at the line start");
    send_keys(&s, "\x1b[C\x1b[C");
    CHECK(wait_out(&s, "\rp1> abcdefghijklmno\x1b[0K\r\x1b[6C"), "cursor moves inside the view");
    send_keys(&s, "\r");
    const char *r = next_result(&s);
    CHECK(strcmp(r, "L:abcdefghijklmnopqrstuvwxyz0123 T=1") == 0, "long line: %s", r);
    s.next_prompt++;
    CHECK(lineedit_term_width(s.slave) == 20, "TIOCGWINSZ width %d", lineedit_term_width(s.slave));
    EXPECT(&s, "\x04", "E T=1");
    sess_end(&s);
}

/* Raw mode is really on during a read, and a SIGTERM then restores it. */
static void test_signals(void)
{
    sess s;
    if (sess_start(&s, 80, NULL, 10, "xterm") != 0) {
        CHECK(0, "cannot start a pty session");
        return;
    }
    CHECK(wait_out(&s, "p0> "), "first prompt");
    struct termios t;
    tcgetattr(s.slave, &t);
    CHECK(!(t.c_lflag & (ECHO | ICANON | ISIG)), "raw mode while reading: lflag %#x", (unsigned)t.c_lflag);
    /* SIGTSTP: the terminal is restored while stopped, raw again after SIGCONT */
    kill(s.pid, SIGTSTP);
    int st = 0;
    pid_t w = waitpid(s.pid, &st, WUNTRACED);
    CHECK(w == s.pid && WIFSTOPPED(st), "SIGTSTP stops the editor (status %#x)", st);
    tcgetattr(s.slave, &t);
    CHECK(termios_same(&t, &s.initial), "termios restored while stopped");
    kill(s.pid, SIGCONT);
    double t0 = now_ms();
    do {
        pump(&s, 10);
        tcgetattr(s.slave, &t);
    } while ((t.c_lflag & ECHO) && now_ms() - t0 < WAIT_MS);
    CHECK(!(t.c_lflag & (ECHO | ICANON)), "raw mode again after SIGCONT");
    send_keys(&s, "ok\r");
    const char *r = next_result(&s);
    CHECK(strcmp(r, "L:ok T=1") == 0, "editing works after a stop: %s", r);
    CHECK(wait_out(&s, "p1> "), "second prompt");
    kill(s.pid, SIGTERM);
    st = sess_end(&s);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "killed by SIGTERM (status %#x)", st);
    /* sess_end closed the slave: reopen to look at the terminal state */
    (void)r;
}

static void test_sigterm_restores(void)
{
    sess s;
    if (sess_start(&s, 80, NULL, 10, "xterm") != 0) {
        CHECK(0, "cannot start a pty session");
        return;
    }
    CHECK(wait_out(&s, "p0> "), "prompt");
    send_keys(&s, "half a line");
    CHECK(wait_out(&s, "half a line"), "echoed by the editor");
    kill(s.pid, SIGTERM);
    int st;
    waitpid(s.pid, &st, 0);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "re-raised SIGTERM kills (status %#x)", st);
    struct termios t;
    tcgetattr(s.slave, &t);
    CHECK(termios_same(&t, &s.initial), "termios restored after SIGTERM in raw mode");
    close(s.res);
    close(s.master);
    close(s.slave);
}

static void test_dumb(void)
{
    sess s;
    if (sess_start(&s, 80, NULL, 10, "dumb") != 0) {
        CHECK(0, "cannot start a pty session");
        return;
    }
    EXPECT(&s, "plain\n", "L:plain T=1");
    EXPECT(&s, "\x04", "E T=1");                 /* the terminal's own EOF */
    sess_end(&s);
    CHECK(!memchr(s.out, 0x1b, s.out_len), "TERM=dumb: no escape sequences");
    CHECK(out_has(&s, "p0> plain"), "prompt written, input echoed by the terminal");
}

/* Non-terminal input: plain lines, no prompt, no output at all. */
static void test_pipe(void)
{
    int in[2], out[2];
    if (pipe(in) != 0 || pipe(out) != 0) {
        CHECK(0, "pipe");
        return;
    }
    const char *text = "abc\r\ndef\n\n\x1b[Dlast";
    CHECK(write(in[1], text, strlen(text)) == (ssize_t)strlen(text), "write");
    close(in[1]);
    lineedit *le = lineedit_new(in[0], out[1], NULL, 10);
    CHECK(le && !lineedit_is_raw(le), "piped editor is not raw");
    const char *want[] = {"abc", "def", "", "\x1b[Dlast"};
    for (int i = 0; i < 4; i++) {
        char *line = NULL;
        lineedit_result r = lineedit_read(le, "> ", &line);
        CHECK(r == LINEEDIT_LINE && line && strcmp(line, want[i]) == 0, "pipe line %d: r=%d '%s'", i,
              (int)r, line ? line : "(null)");
        rt_free(line);
    }
    char *line = (char *)1;
    CHECK(lineedit_read(le, "> ", &line) == LINEEDIT_EOF && line == NULL, "pipe EOF");
    CHECK(lineedit_read(le, "> ", &line) == LINEEDIT_EOF, "EOF again");
    lineedit_free(le);
    close(out[1]);
    char buf[16];
    CHECK(read(out[0], buf, sizeof buf) == 0, "nothing written in piped mode");
    close(out[0]);
    close(in[0]);
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    static char buf[4096];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return buf;
}

static void test_history_file(void)
{
    char dir[] = "/tmp/test_lineedit_XXXXXX";
    if (!mkdtemp(dir)) {
        CHECK(0, "mkdtemp");
        return;
    }
    char path[128];
    snprintf(path, sizeof path, "%s/hist", dir);
    int fd = open("/dev/null", O_RDONLY);

    lineedit *le = lineedit_new(fd, fd, path, 3); /* missing file: fine */
    CHECK(le && lineedit_history_len(le) == 0, "missing history file gives an empty history");
    lineedit_history_add(le, "a");
    lineedit_history_add(le, "b");
    lineedit_history_add(le, "b");      /* consecutive duplicate */
    lineedit_history_add(le, "");       /* empty */
    lineedit_history_add(le, "   ");    /* blank */
    lineedit_history_add(le, "c");
    lineedit_history_add(le, "d\ne");   /* two lines */
    CHECK(lineedit_history_len(le) == 3, "bounded to 3: %d", lineedit_history_len(le));
    CHECK(lineedit_history_get(le, 0) && strcmp(lineedit_history_get(le, 0), "c") == 0, "oldest kept is c");
    CHECK(lineedit_history_get(le, 2) && strcmp(lineedit_history_get(le, 2), "e") == 0, "newest is e");
    CHECK(lineedit_history_get(le, 3) == NULL && lineedit_history_get(le, -1) == NULL, "out of range");
    lineedit_free(le);
    const char *f = slurp(path);
    CHECK(f && strcmp(f, "c\nd\ne\n") == 0, "history file: '%s'", f ? f : "(missing)");

    /* reload, bounded to 2 at load; a duplicate of the last loaded line is skipped */
    le = lineedit_new(fd, fd, path, 2);
    CHECK(lineedit_history_len(le) == 2 && strcmp(lineedit_history_get(le, 0), "d") == 0,
          "reload keeps the newest 2");
    lineedit_history_add(le, "e");
    lineedit_free(le); /* unchanged: not rewritten */
    f = slurp(path);
    CHECK(f && strcmp(f, "c\nd\ne\n") == 0, "unchanged history is not rewritten: '%s'", f ? f : "");

    /* persisted history is recalled with Up in a terminal session */
    sess s;
    if (sess_start(&s, 80, path, 10, "xterm") == 0) {
        EXPECT(&s, "\x1b[A\x1b[A\r", "L:d T=1");
        EXPECT(&s, "\x04", "E T=1");
        sess_end(&s);
        f = slurp(path);
        CHECK(f && strcmp(f, "c\nd\ne\nd\n") == 0, "session appended its line: '%s'", f ? f : "");
    }
    /* a history file that is a directory cannot be read or written */
    char bad[160];
    snprintf(bad, sizeof bad, "%s/sub", dir);
    mkdir(bad, 0700);
    le = lineedit_new(fd, fd, bad, 5);
    CHECK(le && lineedit_history_len(le) == 0, "unreadable history is empty");
    lineedit_history_add(le, "x");
    rt_error e = {0};
    CHECK(lineedit_history_save(le, &e) == RT_EIO && strstr(e.msg, "sub"), "save error names the file: %s", e.msg);
    lineedit_free(le);
    /* history disabled */
    le = lineedit_new(fd, fd, NULL, 0);
    lineedit_history_add(le, "x");
    CHECK(lineedit_history_len(le) == 0, "history_max 0 keeps nothing");
    lineedit_free(le);

    close(fd);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "ls -A %s | wc -l", dir);
    FILE *p = popen(cmd, "r");
    int count = -1;
    if (p) {
        if (fscanf(p, "%d", &count) != 1)
            count = -1;
        pclose(p);
    }
    CHECK(count == 2, "no temporary files left beside the history (entries: %d)", count);
    rmdir(bad);
    remove(path);
    rmdir(dir);
}

static void test_width_env(void)
{
    int p[2];
    if (pipe(p) != 0)
        return;
    setenv("COLUMNS", "123", 1);
    CHECK(lineedit_term_width(p[0]) == 123, "COLUMNS fallback");
    setenv("COLUMNS", "12x", 1);
    CHECK(lineedit_term_width(p[0]) == 80, "bad COLUMNS ignored");
    unsetenv("COLUMNS");
    CHECK(lineedit_term_width(p[0]) == 80, "default 80");
    close(p[0]);
    close(p[1]);
}

static void test_sigint(void)
{
    static volatile sig_atomic_t flag;
    struct sigaction before, mid, after;
    sigaction(SIGINT, NULL, &before);
    CHECK(lineedit_install_sigint(&flag) == 0, "install");
    sigaction(SIGINT, NULL, &mid);
    CHECK(mid.sa_handler != before.sa_handler, "a handler is installed");
    raise(SIGINT);
    CHECK(flag == 1, "SIGINT sets the flag");
    lineedit_remove_sigint();
    sigaction(SIGINT, NULL, &after);
    CHECK(after.sa_handler == before.sa_handler, "previous action restored");
    /* a second SIGINT while the flag is set kills (checked in a child) */
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        static volatile sig_atomic_t f2;
        lineedit_install_sigint(&f2);
        raise(SIGINT);
        raise(SIGINT);
        _exit(0);
    }
    int st;
    waitpid(pid, &st, 0);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGINT, "second SIGINT terminates (status %#x)", st);
}

int main(void)
{
    signal(SIGPIPE, SIG_IGN);
    test_pipe();
    test_width_env();
    test_sigint();
    test_history_file();
    test_editing();
    test_history();
    test_scroll();
    test_sigterm_restores();
    test_signals();
    test_dumb();
    return check_done("test_lineedit");
}
