/* lineedit.c — the REPL's line editor: raw-mode key handling, single-line
 * redraw with horizontal scrolling, history, terminal restoration.
 *
 * Not derived from a paper (this is terminal machinery, not an engine). The
 * escape sequences are the common VT100/xterm ones: CSI A-D arrows, CSI H/F,
 * CSI 1~/7~ and 4~/8~ Home/End, CSI 3~ Delete, SS3 (ESC O) variants, and for
 * output CR, CSI 0K (erase to end of line), CSI n C (cursor forward),
 * CSI H + CSI 2J (clear screen).
 */
#define _POSIX_C_SOURCE 200809L
#include "lineedit.h"
#include "rt_alloc.h"

#include <errno.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include "fileio.h"

enum { LE_RAW, LE_DUMB, LE_PIPE };

struct lineedit {
    int in_fd, out_fd;
    int mode;
    char *hist_path;
    int hist_max;
    char **hist; /* oldest first */
    int hist_len;
    int hist_dirty;
    /* bytes read from in_fd and not yet used (kept across reads) */
    unsigned char in[512];
    size_t in_pos, in_len;
    /* the line being edited */
    char *buf;
    size_t len, cap, pos; /* pos: byte offset of the cursor, on a code point start */
    const char *prompt;
    size_t prompt_w;
    char err[160];
};

/* ---- terminal state shared with signal handlers ---------------------------------
 * Signal handlers cannot be given a context pointer, so the terminal being
 * edited is recorded in this one static: the fd, its saved (cooked) termios
 * and the raw termios. `active` is set only after the others are written. */
static struct {
    volatile sig_atomic_t active;
    volatile sig_atomic_t refresh; /* resumed after a stop: redraw */
    int fd;
    struct termios saved, raw;
} g_term;

static const int g_sigs[] = {SIGTERM, SIGHUP, SIGQUIT, SIGSEGV, SIGBUS,
                             SIGFPE,  SIGILL, SIGABRT, SIGTSTP, SIGCONT};
#define NSIGS ((int)(sizeof g_sigs / sizeof g_sigs[0]))
static struct sigaction g_old[NSIGS];
static volatile sig_atomic_t g_installed[NSIGS];

static void on_fatal(int sig)
{
    int saved_errno = errno;
    if (g_term.active) {
        tcsetattr(g_term.fd, TCSANOW, &g_term.saved);
        g_term.active = 0;
    }
    for (int i = 0; i < NSIGS; i++)
        if (g_sigs[i] == sig && g_installed[i]) {
            sigaction(sig, &g_old[i], NULL);
            g_installed[i] = 0;
        }
    /* Pending until this handler returns (the signal is blocked in its own
     * handler); then the previous action runs (default: terminate). A
     * synchronous fault re-executes the instruction and faults again. */
    raise(sig);
    errno = saved_errno;
}

static void on_tstp(int sig)
{
    int saved_errno = errno;
    (void)sig;
    if (g_term.active)
        tcsetattr(g_term.fd, TCSANOW, &g_term.saved);
    struct sigaction dfl, ours;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(SIGTSTP, &dfl, &ours);
    raise(SIGTSTP);
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, SIGTSTP);
    sigprocmask(SIG_UNBLOCK, &s, NULL); /* stops here until SIGCONT */
    sigprocmask(SIG_BLOCK, &s, NULL);
    sigaction(SIGTSTP, &ours, NULL);
    if (g_term.active) {
        tcsetattr(g_term.fd, TCSANOW, &g_term.raw);
        g_term.refresh = 1;
    }
    errno = saved_errno;
}

static void on_cont(int sig)
{
    int saved_errno = errno;
    (void)sig;
    if (g_term.active) {
        tcsetattr(g_term.fd, TCSANOW, &g_term.raw);
        g_term.refresh = 1;
    }
    errno = saved_errno;
}

static void at_exit_restore(void)
{
    if (g_term.active) {
        tcsetattr(g_term.fd, TCSANOW, &g_term.saved);
        g_term.active = 0;
    }
}

static void install_handlers(void)
{
    for (int i = 0; i < NSIGS; i++) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = g_sigs[i] == SIGTSTP ? on_tstp : g_sigs[i] == SIGCONT ? on_cont : on_fatal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = 0; /* no SA_RESTART: read() returns EINTR so we can redraw */
        if (sigaction(g_sigs[i], NULL, &g_old[i]) != 0)
            continue;
        if (g_old[i].sa_handler == SIG_IGN && !(g_old[i].sa_flags & SA_SIGINFO))
            continue; /* ignored signals stay ignored */
        if (sigaction(g_sigs[i], &sa, NULL) == 0)
            g_installed[i] = 1;
    }
}

static void remove_handlers(void)
{
    for (int i = 0; i < NSIGS; i++)
        if (g_installed[i]) {
            g_installed[i] = 0;
            sigaction(g_sigs[i], &g_old[i], NULL);
        }
}

/* Enter raw mode on le->in_fd; 0 or -1 (errno set). */
static int raw_on(lineedit *le)
{
    static int atexit_done;
    struct termios saved, raw;
    if (tcgetattr(le->in_fd, &saved) != 0)
        return -1;
    raw = saved;
    raw.c_iflag &= ~(tcflag_t)(BRKINT | ICRNL | INPCK | ISTRIP | IXON);
    raw.c_oflag &= ~(tcflag_t)OPOST;
    raw.c_cflag |= CS8;
    raw.c_lflag &= ~(tcflag_t)(ECHO | ICANON | IEXTEN | ISIG);
    raw.c_cc[VMIN] = 1;
    raw.c_cc[VTIME] = 0;
    if (!atexit_done) {
        atexit(at_exit_restore);
        atexit_done = 1;
    }
    g_term.active = 0;
    g_term.fd = le->in_fd;
    g_term.saved = saved;
    g_term.raw = raw;
    g_term.refresh = 0;
    install_handlers();
    g_term.active = 1;
    /* TCSADRAIN, not TCSAFLUSH: keys typed ahead must not be lost. */
    if (tcsetattr(le->in_fd, TCSADRAIN, &raw) != 0) {
        int err = errno;
        g_term.active = 0;
        remove_handlers();
        errno = err;
        return -1;
    }
    return 0;
}

static void raw_off(void)
{
    if (g_term.active) {
        while (tcsetattr(g_term.fd, TCSADRAIN, &g_term.saved) != 0 && errno == EINTR) {
        }
        g_term.active = 0;
    }
    remove_handlers();
}

/* ---- small helpers --------------------------------------------------------------- */

int lineedit_term_width(int fd)
{
    struct winsize ws;
    if (ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0)
        return ws.ws_col;
    const char *c = getenv("COLUMNS");
    if (c) {
        char *end;
        long v = strtol(c, &end, 10);
        if (end != c && *end == 0 && v > 0 && v < 100000)
            return (int)v;
    }
    return 80;
}

static int is_cont(unsigned char c) { return (c & 0xC0) == 0x80; }

/* Columns of s[0..n): every code point is one column (see lineedit.h). */
static size_t text_width(const char *s, size_t n)
{
    size_t w = 0;
    for (size_t i = 0; i < n; i++)
        w += !is_cont((unsigned char)s[i]);
    return w;
}

static void set_err(lineedit *le, const char *what, int err)
{
    snprintf(le->err, sizeof le->err, "%s: %s", what, strerror(err));
}

/* Write all of p[0..n) to out_fd; 0 or -1. */
static int out_write(lineedit *le, const void *p, size_t n)
{
    const char *c = p;
    while (n > 0) {
        ssize_t w = write(le->out_fd, c, n);
        if (w < 0) {
            if (errno == EINTR || errno == EAGAIN)
                continue;
            set_err(le, "cannot write to the terminal", errno);
            return -1;
        }
        c += w;
        n -= (size_t)w;
    }
    return 0;
}

static int out_str(lineedit *le, const char *s) { return out_write(le, s, strlen(s)); }

enum { IN_EOF = -1, IN_ERROR = -2, IN_TIMEOUT = -3, IN_EINTR = -4 };

/* Next input byte (0..255) or IN_*. timeout_ms < 0 waits for ever. */
static int in_byte(lineedit *le, int timeout_ms)
{
    if (le->in_pos < le->in_len)
        return le->in[le->in_pos++];
    if (timeout_ms >= 0) {
        struct pollfd p = {.fd = le->in_fd, .events = POLLIN};
        int r = poll(&p, 1, timeout_ms);
        if (r == 0)
            return IN_TIMEOUT;
        if (r < 0)
            return errno == EINTR ? IN_EINTR : IN_ERROR;
    }
    ssize_t n = read(le->in_fd, le->in, sizeof le->in);
    if (n < 0) {
        if (errno == EINTR)
            return IN_EINTR;
        set_err(le, "cannot read the terminal", errno);
        return IN_ERROR;
    }
    if (n == 0)
        return IN_EOF;
    le->in_pos = 1;
    le->in_len = (size_t)n;
    return le->in[0];
}

/* ---- the line buffer ------------------------------------------------------------- */

static int buf_reserve(lineedit *le, size_t extra)
{
    if (le->len + extra + 1 <= le->cap)
        return 0;
    size_t cap = le->cap ? le->cap : 128;
    while (cap < le->len + extra + 1)
        cap *= 2;
    char *nb = rt_realloc(le->buf, cap);
    if (!nb) {
        snprintf(le->err, sizeof le->err, "out of memory");
        return -1;
    }
    le->buf = nb;
    le->cap = cap;
    return 0;
}

static int buf_set(lineedit *le, const char *s)
{
    size_t n = strlen(s);
    le->len = 0;
    if (buf_reserve(le, n) != 0)
        return -1;
    memcpy(le->buf, s, n);
    le->len = le->pos = n;
    le->buf[n] = 0;
    return 0;
}

static int buf_insert(lineedit *le, const char *s, size_t n)
{
    if (buf_reserve(le, n) != 0)
        return -1;
    memmove(le->buf + le->pos + n, le->buf + le->pos, le->len - le->pos);
    memcpy(le->buf + le->pos, s, n);
    le->len += n;
    le->pos += n;
    le->buf[le->len] = 0;
    return 0;
}

/* Delete bytes [a, b) and put the cursor at a. */
static void buf_delete(lineedit *le, size_t a, size_t b)
{
    memmove(le->buf + a, le->buf + b, le->len - b);
    le->len -= b - a;
    le->pos = a;
    le->buf[le->len] = 0;
}

static size_t prev_char(const lineedit *le, size_t i)
{
    if (i == 0)
        return 0;
    i--;
    while (i > 0 && is_cont((unsigned char)le->buf[i]))
        i--;
    return i;
}

static size_t next_char(const lineedit *le, size_t i)
{
    if (i >= le->len)
        return le->len;
    i++;
    while (i < le->len && is_cont((unsigned char)le->buf[i]))
        i++;
    return i;
}

/* ---- drawing --------------------------------------------------------------------- */

/* Redraw prompt and line on the current terminal row: the view starts at the
 * first code point and scrolls right only as far as needed to keep the
 * cursor on screen (the last column stays free so the cursor never wraps). */
static int refresh(lineedit *le)
{
    long cols = lineedit_term_width(le->out_fd);
    long avail = cols - (long)le->prompt_w - 1;
    if (avail < 1)
        avail = 1;
    size_t cur = text_width(le->buf, le->pos);
    size_t skip = cur > (size_t)avail ? cur - (size_t)avail : 0;
    size_t a = 0;
    for (size_t k = 0; k < skip; k++)
        a = next_char(le, a);
    size_t b = a;
    for (long k = 0; k < avail && b < le->len; k++)
        b = next_char(le, b);
    bytebuf o;
    bytebuf_init(&o);
    bytebuf_byte(&o, '\r');
    if (le->prompt)
        bytebuf_append(&o, le->prompt, strlen(le->prompt));
    bytebuf_append(&o, le->buf + a, b - a);
    bytebuf_append(&o, "\x1b[0K\r", 5);
    size_t col = le->prompt_w + cur - skip;
    if (col > 0)
        bytebuf_printf(&o, "\x1b[%zuC", col);
    int r;
    if (o.failed) {
        snprintf(le->err, sizeof le->err, "out of memory");
        r = -1;
    } else {
        r = out_write(le, o.data, o.len);
    }
    bytebuf_free(&o);
    return r;
}

/* ---- keys ------------------------------------------------------------------------ */

enum {
    K_NONE = 1000,
    K_UP,
    K_DOWN,
    K_LEFT,
    K_RIGHT,
    K_HOME,
    K_END,
    K_DELETE,
    K_EOF,   /* input ended */
    K_ERROR, /* read failed */
    K_EINTR, /* interrupted by a signal */
};

#define ESC_WAIT_MS 100 /* how long the rest of an escape sequence may take */

static int in_key_byte(lineedit *le)
{
    int c = in_byte(le, ESC_WAIT_MS);
    if (c == IN_ERROR)
        return K_ERROR;
    if (c == IN_EOF)
        return K_EOF;
    return c < 0 ? K_NONE : c;
}

/* The final byte of an arrow, Home or End key, the same after SS3 and CSI
 * (ESC O A, ESC [ A, ESC [ 1 ; 5 A); K_NONE for any other byte. */
static int cursor_key(int c)
{
    switch (c) {
    case 'A': return K_UP;
    case 'B': return K_DOWN;
    case 'C': return K_RIGHT;
    case 'D': return K_LEFT;
    case 'H': return K_HOME;
    case 'F': return K_END;
    default: return K_NONE;
    }
}

/* After ESC: decode CSI (ESC [ params final) and SS3 (ESC O final). Unknown
 * sequences and a lone ESC (nothing follows within ESC_WAIT_MS) give K_NONE;
 * Alt+key (ESC then a plain byte) is ignored. */
static int read_escape(lineedit *le)
{
    int c = in_key_byte(le);
    if (c >= 1000)
        return c;
    if (c == 'O') {
        c = in_key_byte(le);
        return c >= 1000 ? c : cursor_key(c);
    }
    if (c != '[')
        return K_NONE;
    long p1 = -1; /* first numeric parameter; modifiers after ';' are ignored */
    int nparams = 0;
    for (;;) {
        c = in_key_byte(le);
        if (c >= 1000)
            return c;
        if (c >= '0' && c <= '9') {
            if (nparams == 0)
                p1 = (p1 < 0 ? 0 : p1) * 10 + (c - '0');
            if (p1 > 100000)
                p1 = 100000;
        } else if (c == ';') {
            nparams++;
        } else if (c >= 0x20 && c <= 0x3F) {
            /* other parameter / intermediate bytes: carry on */
        } else {
            break;
        }
    }
    if (c == '~')
        switch (p1) {
        case 1: case 7: return K_HOME;
        case 4: case 8: return K_END;
        case 3: return K_DELETE;
        default: return K_NONE;
        }
    return cursor_key(c);
}

/* ---- history --------------------------------------------------------------------- */

static int is_blank(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (s[i] != ' ' && s[i] != '\t' && s[i] != '\r')
            return 0;
    return 1;
}

/* Add s[0..n) (no '\n' inside); 1 if added. */
static int hist_push(lineedit *le, const char *s, size_t n)
{
    if (le->hist_max <= 0 || is_blank(s, n))
        return 0;
    if (le->hist_len > 0) {
        const char *last = le->hist[le->hist_len - 1];
        if (strlen(last) == n && memcmp(last, s, n) == 0)
            return 0;
    }
    char *copy = rt_malloc(n + 1);
    if (!copy)
        return 0;
    memcpy(copy, s, n);
    copy[n] = 0;
    if (le->hist_len == le->hist_max) {
        rt_free(le->hist[0]);
        memmove(le->hist, le->hist + 1, (size_t)(le->hist_len - 1) * sizeof *le->hist);
        le->hist_len--;
    }
    le->hist[le->hist_len++] = copy;
    return 1;
}

/* Add every line of text (split at '\n', a trailing '\r' dropped). */
static int hist_add_text(lineedit *le, const char *text, size_t n)
{
    int added = 0;
    size_t a = 0;
    while (a < n) {
        const char *nl = memchr(text + a, '\n', n - a);
        size_t b = nl ? (size_t)(nl - text) : n;
        size_t e = b;
        if (e > a && text[e - 1] == '\r')
            e--;
        added |= hist_push(le, text + a, e - a);
        a = b + 1;
    }
    return added;
}

void lineedit_history_add(lineedit *le, const char *line)
{
    if (le && line && hist_add_text(le, line, strlen(line)))
        le->hist_dirty = 1;
}

int lineedit_history_len(const lineedit *le) { return le ? le->hist_len : 0; }

const char *lineedit_history_get(const lineedit *le, int i)
{
    if (!le || i < 0 || i >= le->hist_len)
        return NULL;
    return le->hist[i];
}

rt_code lineedit_history_save(lineedit *le, rt_error *e)
{
    if (!le || !le->hist_path || le->hist_max <= 0)
        return RT_OK;
    bytebuf b;
    bytebuf_init(&b);
    for (int i = 0; i < le->hist_len; i++) {
        bytebuf_append(&b, le->hist[i], strlen(le->hist[i]));
        bytebuf_byte(&b, '\n');
    }
    if (b.failed) {
        bytebuf_free(&b);
        return rt_fail(e, RT_ENOMEM, "out of memory saving the history");
    }
    rt_code c = fileio_write_atomic(le->hist_path, b.data, b.len, e);
    bytebuf_free(&b);
    if (c == RT_OK)
        le->hist_dirty = 0;
    return c;
}

/* ---- creation -------------------------------------------------------------------- */

lineedit *lineedit_new(int in_fd, int out_fd, const char *history_path, int history_max)
{
    lineedit *le = rt_calloc(1, sizeof *le);
    if (!le)
        return NULL;
    le->in_fd = in_fd;
    le->out_fd = out_fd;
    le->hist_max = history_max > 0 ? history_max : 0;
    if (isatty(in_fd)) {
        const char *term = getenv("TERM");
        le->mode = term && strcmp(term, "dumb") == 0 ? LE_DUMB : LE_RAW;
    } else {
        le->mode = LE_PIPE;
    }
    if (le->hist_max > 0) {
        le->hist = rt_calloc((size_t)le->hist_max, sizeof *le->hist);
        if (!le->hist) {
            rt_free(le);
            return NULL;
        }
    }
    if (history_path) {
        le->hist_path = rt_strdup(history_path);
        if (!le->hist_path) {
            rt_free(le->hist);
            rt_free(le);
            return NULL;
        }
        unsigned char *data;
        size_t n;
        if (le->hist_max > 0 && fileio_read_all(history_path, (size_t)64 << 20, &data, &n, NULL) == RT_OK) {
            hist_add_text(le, (const char *)data, n);
            rt_free(data);
        }
    }
    return le;
}

void lineedit_free(lineedit *le)
{
    if (!le)
        return;
    if (g_term.active && g_term.fd == le->in_fd)
        raw_off();
    if (le->hist_dirty)
        lineedit_history_save(le, NULL);
    for (int i = 0; i < le->hist_len; i++)
        rt_free(le->hist[i]);
    rt_free(le->hist);
    rt_free(le->hist_path);
    rt_free(le->buf);
    rt_free(le);
}

int lineedit_is_raw(const lineedit *le) { return le && le->mode == LE_RAW; }

const char *lineedit_errmsg(const lineedit *le) { return le ? le->err : ""; }

/* ---- reading --------------------------------------------------------------------- */

/* Hand the buffer to the caller as a malloc'd string. */
static lineedit_result take_line(lineedit *le, char **line)
{
    char *s = rt_malloc(le->len + 1);
    if (!s) {
        snprintf(le->err, sizeof le->err, "out of memory");
        return LINEEDIT_ERROR;
    }
    memcpy(s, le->buf ? le->buf : "", le->len);
    s[le->len] = 0;
    *line = s;
    return LINEEDIT_LINE;
}

/* Dumb and piped modes: a plain line. */
static lineedit_result read_plain(lineedit *le, char **line)
{
    if (le->mode == LE_DUMB && le->prompt && out_str(le, le->prompt) != 0)
        return LINEEDIT_ERROR;
    for (;;) {
        int c = in_byte(le, -1);
        if (c == IN_EINTR)
            return LINEEDIT_INTERRUPT;
        if (c == IN_ERROR)
            return LINEEDIT_ERROR;
        if (c == IN_EOF)
            return le->len == 0 ? LINEEDIT_EOF : take_line(le, line);
        if (c == '\n') {
            if (le->len > 0 && le->buf[le->len - 1] == '\r')
                le->len--;
            return take_line(le, line);
        }
        char ch = (char)c;
        le->pos = le->len;
        if (buf_insert(le, &ch, 1) != 0)
            return LINEEDIT_ERROR;
    }
}

/* History browsing state for one read: edits[0] is the line being typed,
 * edits[k] the edited copy of the k-th newest entry (NULL: unchanged). */
typedef struct browse {
    char **edits;
    int n, at;
} browse;

static int browse_move(lineedit *le, browse *h, int to)
{
    if (to < 0 || to > le->hist_len || to == h->at)
        return 0;
    char *keep = rt_strdup(le->buf ? le->buf : "");
    if (!keep) {
        snprintf(le->err, sizeof le->err, "out of memory");
        return -1;
    }
    rt_free(h->edits[h->at]);
    h->edits[h->at] = keep;
    h->at = to;
    const char *src = h->edits[to] ? h->edits[to] : to == 0 ? "" : le->hist[le->hist_len - to];
    return buf_set(le, src);
}

static int is_word_space(char c) { return c == ' ' || c == '\t'; }

static lineedit_result read_raw(lineedit *le, char **line)
{
    browse h = {NULL, le->hist_len + 1, 0};
    h.edits = rt_calloc((size_t)h.n, sizeof *h.edits);
    if (!h.edits) {
        snprintf(le->err, sizeof le->err, "out of memory");
        return LINEEDIT_ERROR;
    }
    if (raw_on(le) != 0) {
        set_err(le, "cannot set the terminal to raw mode", errno);
        rt_free(h.edits);
        return LINEEDIT_ERROR;
    }
    lineedit_result res = LINEEDIT_ERROR;
    int dirty = 1;
    for (;;) {
        if (g_term.refresh) {
            g_term.refresh = 0;
            dirty = 1;
        }
        if (dirty && le->in_pos == le->in_len) { /* redraw once the typed-ahead keys are used */
            if (refresh(le) != 0)
                goto done;
            dirty = 0;
        }
        int c = in_byte(le, -1);
        if (c == IN_EINTR) {
            if (!g_term.active) { /* a handled signal restored the terminal: back to raw */
                if (raw_on(le) != 0) {
                    set_err(le, "cannot set the terminal to raw mode", errno);
                    goto done;
                }
            }
            dirty = 1;
            continue;
        }
        if (c == IN_ERROR)
            goto done;
        if (c == IN_EOF) {
            res = LINEEDIT_EOF;
            goto done;
        }
        if (c == 0x1b)
            c = read_escape(le);
        dirty = 1;
        switch (c) {
        case K_ERROR:
            goto done;
        case K_EOF:
            res = LINEEDIT_EOF;
            goto done;
        case '\r':
        case '\n':
            le->pos = le->len;
            if (refresh(le) != 0 || out_str(le, "\r\n") != 0)
                goto done;
            res = take_line(le, line);
            goto done;
        case 0x03: /* Ctrl-C */
            le->pos = le->len;
            if (refresh(le) != 0 || out_str(le, "^C\r\n") != 0)
                goto done;
            res = LINEEDIT_INTERRUPT;
            goto done;
        case 0x04: /* Ctrl-D */
            if (le->len == 0) {
                if (out_str(le, "\r\n") != 0)
                    goto done;
                res = LINEEDIT_EOF;
                goto done;
            }
            if (le->pos < le->len)
                buf_delete(le, le->pos, next_char(le, le->pos));
            break;
        case K_DELETE:
            if (le->pos < le->len)
                buf_delete(le, le->pos, next_char(le, le->pos));
            break;
        case 0x7f: /* Backspace */
        case 0x08: /* Ctrl-H */
            if (le->pos > 0)
                buf_delete(le, prev_char(le, le->pos), le->pos);
            break;
        case 0x02: /* Ctrl-B */
        case K_LEFT:
            le->pos = prev_char(le, le->pos);
            break;
        case 0x06: /* Ctrl-F */
        case K_RIGHT:
            le->pos = next_char(le, le->pos);
            break;
        case 0x01: /* Ctrl-A */
        case K_HOME:
            le->pos = 0;
            break;
        case 0x05: /* Ctrl-E */
        case K_END:
            le->pos = le->len;
            break;
        case 0x15: /* Ctrl-U */
            buf_delete(le, 0, le->pos);
            break;
        case 0x0b: /* Ctrl-K */
            buf_delete(le, le->pos, le->len);
            le->pos = le->len;
            break;
        case 0x17: { /* Ctrl-W: blanks, then the non-blank word before the cursor */
            size_t a = le->pos;
            while (a > 0 && is_word_space(le->buf[a - 1]))
                a--;
            while (a > 0 && !is_word_space(le->buf[a - 1]))
                a--;
            buf_delete(le, a, le->pos);
            break;
        }
        case 0x0c: /* Ctrl-L */
            if (out_str(le, "\x1b[H\x1b[2J") != 0)
                goto done;
            break;
        case 0x10: /* Ctrl-P */
        case K_UP:
            if (browse_move(le, &h, h.at + 1) != 0)
                goto done;
            break;
        case 0x0e: /* Ctrl-N */
        case K_DOWN:
            if (browse_move(le, &h, h.at - 1) != 0)
                goto done;
            break;
        case 0x1a: /* Ctrl-Z: suspend like a cooked terminal would */
            raise(SIGTSTP);
            break;
        case '\t': /* Tab: no completion; insert one space so pasted code keeps its shape */
            if (buf_insert(le, " ", 1) != 0)
                goto done;
            break;
        default:
            if (c >= 0x20 && c < 0x7f) {
                char ch = (char)c;
                if (buf_insert(le, &ch, 1) != 0)
                    goto done;
            } else if (c >= 0xC2 && c <= 0xF4) { /* UTF-8 lead byte */
                char u[4];
                int need = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : 2, got = 1;
                u[0] = (char)c;
                while (got < need) {
                    int d = in_key_byte(le);
                    if (d >= 1000 || !is_cont((unsigned char)d)) {
                        if (d < 1000) /* not a continuation: give it back */
                            le->in_pos--;
                        break;
                    }
                    u[got++] = (char)d;
                }
                if (got == need && buf_insert(le, u, (size_t)need) != 0)
                    goto done;
            }
            /* other control bytes and stray UTF-8 bytes are ignored */
            break;
        }
    }
done:
    raw_off();
    for (int i = 0; i < h.n; i++)
        rt_free(h.edits[i]);
    rt_free(h.edits);
    return res;
}

lineedit_result lineedit_read(lineedit *le, const char *prompt, char **line)
{
    *line = NULL;
    le->err[0] = 0;
    le->len = le->pos = 0;
    if (buf_reserve(le, 0) != 0)
        return LINEEDIT_ERROR;
    le->buf[0] = 0;
    le->prompt = prompt;
    le->prompt_w = prompt ? text_width(prompt, strlen(prompt)) : 0;
    lineedit_result r = le->mode == LE_RAW ? read_raw(le, line) : read_plain(le, line);
    le->prompt = NULL;
    return r;
}

/* ---- SIGINT while evaluating ----------------------------------------------------- */

static volatile sig_atomic_t *g_sigint_flag;
static struct sigaction g_sigint_old;
static int g_sigint_installed;

static void on_sigint(int sig)
{
    if (g_sigint_flag && *g_sigint_flag) { /* second Ctrl-C: stop at once */
        struct sigaction dfl;
        memset(&dfl, 0, sizeof dfl);
        dfl.sa_handler = SIG_DFL;
        sigemptyset(&dfl.sa_mask);
        sigaction(sig, &dfl, NULL);
        raise(sig);
        return;
    }
    if (g_sigint_flag)
        *g_sigint_flag = 1;
}

int lineedit_install_sigint(volatile sig_atomic_t *flag)
{
    g_sigint_flag = flag;
    if (g_sigint_installed)
        return 0;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    if (sigaction(SIGINT, &sa, &g_sigint_old) != 0)
        return -1;
    g_sigint_installed = 1;
    return 0;
}

void lineedit_remove_sigint(void)
{
    if (g_sigint_installed) {
        sigaction(SIGINT, &g_sigint_old, NULL);
        g_sigint_installed = 0;
    }
    g_sigint_flag = NULL;
}
