/* fileio.c — whole-file reads, atomic writes, byte buffers. */
#define _POSIX_C_SOURCE 200809L
#include "fileio.h"
#include "rt_alloc.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- temp files a signal handler may have to remove ---------------------------------
 * A fixed table, because a signal handler can neither lock nor allocate. A
 * slot is FREE, BUSY (claimed by a writer that is filling in the name; the
 * handler leaves it alone) or ARMED (the file exists; the handler unlinks it).
 * Writers on any thread claim slots with compare-and-swap on lock-free atomic
 * ints, which are safe to read in a handler (C11 7.14.1.1). The writer blocks
 * SIGINT, SIGTERM and SIGHUP on its own thread between creating the file and
 * arming the slot, and between renaming it and freeing the slot, so on that
 * thread no signal sees a file that is not in the table. */
#if ATOMIC_INT_LOCK_FREE != 2
#error "fileio needs lock-free atomic int for its signal-safe temp table"
#endif

enum { SLOT_FREE, SLOT_BUSY, SLOT_ARMED };

static struct temp_slot {
    atomic_int state;
    char path[FILEIO_PATH_MAX + 64];
} temps[FILEIO_MAX_TEMPS];

static atomic_uint temp_counter;

void fileio_cleanup_temps(void)
{
    for (int i = 0; i < FILEIO_MAX_TEMPS; i++)
        if (atomic_load(&temps[i].state) == SLOT_ARMED)
            unlink(temps[i].path);
}

static void on_fatal_signal(int sig)
{
    int saved = errno;
    fileio_cleanup_temps();
    /* SA_RESETHAND restored the default action; the signal is blocked in its
     * own handler, so it is delivered (and kills us) when this returns. */
    raise(sig);
    errno = saved;
}

int fileio_install_signal_cleanup(void)
{
    static const int sigs[] = {SIGTERM, SIGHUP};
    int rc = 0;
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction old, sa;
        if (sigaction(sigs[i], NULL, &old) != 0) {
            rc = -1;
            continue;
        }
        if (!(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_IGN)
            continue; /* `nohup frac …`: an ignored signal stays ignored */
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_fatal_signal;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESETHAND;
        if (sigaction(sigs[i], &sa, NULL) != 0)
            rc = -1;
    }
    return rc;
}

static void block_signals(sigset_t *old)
{
    sigset_t s;
    sigemptyset(&s);
    sigaddset(&s, SIGINT);
    sigaddset(&s, SIGTERM);
    sigaddset(&s, SIGHUP);
    pthread_sigmask(SIG_BLOCK, &s, old);
}

static void restore_signals(const sigset_t *old) { pthread_sigmask(SIG_SETMASK, old, NULL); }

static struct temp_slot *claim_slot(void)
{
    for (int i = 0; i < FILEIO_MAX_TEMPS; i++) {
        int expect = SLOT_FREE;
        if (atomic_compare_exchange_strong(&temps[i].state, &expect, SLOT_BUSY))
            return &temps[i];
    }
    return NULL;
}

/* ---- folders ------------------------------------------------------------------------ */

static const char *node_kind(mode_t m)
{
    return S_ISREG(m)    ? "a file"
           : S_ISLNK(m)  ? "a symbolic link"
           : S_ISDIR(m)  ? "a folder"
           : S_ISCHR(m)  ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISFIFO(m) ? "a FIFO"
           : S_ISSOCK(m) ? "a socket"
                         : "not a regular file";
}

/* mkdir -p dir (a modifiable copy); for errors, name the folder and path. */
static rt_code make_folders(char *dir, const char *path, rt_error *e)
{
    size_t n = strlen(dir);
    for (size_t i = 1; i <= n; i++) {
        if (dir[i] != '/' && dir[i] != 0)
            continue;
        if (dir[i - 1] == '/') /* "a//b" */
            continue;
        char c = dir[i];
        dir[i] = 0;
        struct stat st;
        if (mkdir(dir, 0777) != 0) {
            int err = errno;
            if (stat(dir, &st) != 0) {
                rt_code rc = rt_fail(e, RT_EIO, "cannot create folder '%s' for '%s': %s", dir, path,
                                     strerror(err));
                dir[i] = c;
                return rc;
            }
            if (!S_ISDIR(st.st_mode)) {
                rt_code rc = rt_fail(e, RT_EIO, "cannot create folder '%s' for '%s': it exists and is %s", dir,
                                     path, node_kind(st.st_mode));
                dir[i] = c;
                return rc;
            }
        }
        dir[i] = c;
    }
    return RT_OK;
}

rt_code fileio_make_parents(const char *path, rt_error *e)
{
    const char *slash = strrchr(path, '/');
    if (!slash || slash == path)
        return RT_OK; /* the current folder, or "/" */
    size_t n = (size_t)(slash - path);
    if (n >= FILEIO_PATH_MAX)
        return rt_fail(e, RT_EIO, "path too long: '%.40s…' (%zu bytes; the limit is %d)", path, strlen(path),
                       FILEIO_PATH_MAX - 1);
    char dir[FILEIO_PATH_MAX];
    memcpy(dir, path, n);
    dir[n] = 0;
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return RT_OK;
        return rt_fail(e, RT_EIO, "cannot create folder '%s' for '%s': it exists and is %s", dir, path,
                       node_kind(st.st_mode));
    }
    if (errno != ENOENT && errno != ENOTDIR) /* ENOTDIR: make_folders names the file in the way */
        return rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(errno));
    return make_folders(dir, path, e);
}

/* ---- atomic writes ------------------------------------------------------------------ */

static int write_all(int fd, const unsigned char *p, size_t n)
{
    while (n > 0) {
        size_t chunk = n > ((size_t)1 << 30) ? (size_t)1 << 30 : n;
        ssize_t w = write(fd, p, chunk);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            return -1;
        }
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

/* Make the name of the k-th try at a temp file for path, into buf. Beside the
 * target ("x.png.tmp123-0"), or ".frac.tmp123-0" in the same folder when the
 * target's own name is too long to extend. */
static void temp_name(const char *path, unsigned k, char *buf, size_t size)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    long pid = (long)getpid();
    if (strlen(base) + 32 <= 255)
        snprintf(buf, size, "%s.tmp%ld-%u", path, pid, k);
    else
        snprintf(buf, size, "%.*s.frac.tmp%ld-%u", (int)(base - path), path, pid, k);
}

static void sync_folder(const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[FILEIO_PATH_MAX];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        fsync(fd); /* some file systems refuse (EINVAL); the file itself is synced */
        close(fd);
    }
}

static _Atomic(fileio_path_hook) path_hook;
static void *path_hook_ud;

void fileio_set_path_hook(fileio_path_hook fn, void *ud)
{
    path_hook_ud = ud;
    atomic_store(&path_hook, fn);
}

rt_code fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e)
{
    size_t plen = strlen(path);
    if (plen == 0)
        return rt_fail(e, RT_EIO, "cannot write a file with an empty name");
    if (plen >= FILEIO_PATH_MAX)
        return rt_fail(e, RT_EIO, "path too long: '%.40s…' (%zu bytes; the limit is %d)", path, plen,
                       FILEIO_PATH_MAX - 1);
    struct stat st;
    if (lstat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode))
            return rt_fail(e, RT_EIO, "cannot write '%s': it is %s, not a regular file (frac replaces only regular files)",
                           path, node_kind(st.st_mode));
    } else if (errno != ENOENT && errno != ENOTDIR) {
        return rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(errno));
    }
    rt_code rc = fileio_make_parents(path, e);
    if (rc)
        return rc;

    struct temp_slot *slot = claim_slot();
    char own[FILEIO_PATH_MAX + 64];
    char *tmp = slot ? slot->path : own; /* table full: still safe, just not removed on a signal */
    sigset_t old;
    int fd = -1, err = 0;
    block_signals(&old);
    for (int tries = 0; tries < 100; tries++) {
        temp_name(path, atomic_fetch_add(&temp_counter, 1u), tmp, sizeof own);
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST)
            break;
    }
    err = errno;
    if (fd >= 0 && slot)
        atomic_store(&slot->state, SLOT_ARMED);
    restore_signals(&old);
    if (fd < 0) {
        if (slot)
            atomic_store(&slot->state, SLOT_FREE);
        return rt_fail(e, RT_EIO, "cannot create a temporary file beside '%s': %s", path, strerror(err));
    }

    int bad = 0;
    if (write_all(fd, data, n) != 0 || fsync(fd) != 0) {
        bad = 1;
        err = errno;
    }
    if (close(fd) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    if (!bad && rename(tmp, path) != 0) {
        bad = 1;
        err = errno;
    }
    block_signals(&old);
    if (bad)
        unlink(tmp);
    if (slot)
        atomic_store(&slot->state, SLOT_FREE);
    restore_signals(&old);
    if (bad)
        return rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(err));
    sync_folder(path);
    fileio_path_hook hook = atomic_load(&path_hook);
    if (hook)
        hook(path_hook_ud, path, 1);
    return RT_OK;
}

rt_code fileio_read_all(const char *path, size_t max_bytes, unsigned char **data, size_t *n,
                        rt_error *e)
{
    *data = NULL;
    *n = 0;
    fileio_path_hook hook = atomic_load(&path_hook);
    if (hook)
        hook(path_hook_ud, path, 0);
    FILE *f = fopen(path, "rb");
    if (!f)
        return rt_fail(e, RT_EIO, "cannot open '%s': %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    unsigned char *buf = rt_malloc(cap + 1);
    if (!buf) {
        fclose(f);
        return rt_fail(e, RT_ENOMEM, "out of memory");
    }
    for (;;) {
        if (len == cap) {
            if (cap >= max_bytes) {
                rt_free(buf);
                fclose(f);
                return rt_fail(e, RT_EIO, "'%s' is larger than %zu bytes", path, max_bytes);
            }
            size_t ncap = cap * 2 > max_bytes ? max_bytes : cap * 2;
            unsigned char *nb = rt_realloc(buf, ncap + 1);
            if (!nb) {
                rt_free(buf);
                fclose(f);
                return rt_fail(e, RT_ENOMEM, "out of memory reading '%s'", path);
            }
            buf = nb;
            cap = ncap;
        }
        size_t r = fread(buf + len, 1, cap - len, f);
        len += r;
        if (r == 0) {
            if (ferror(f)) {
                int err = errno;
                rt_free(buf);
                fclose(f);
                return rt_fail(e, RT_EIO, "cannot read '%s': %s", path, strerror(err));
            }
            break;
        }
    }
    fclose(f);
    buf[len] = 0;
    *data = buf;
    *n = len;
    return RT_OK;
}

void bytebuf_init(bytebuf *b)
{
    b->data = NULL;
    b->len = b->cap = 0;
    b->failed = 0;
}

void bytebuf_free(bytebuf *b)
{
    rt_free(b->data);
    bytebuf_init(b);
}

void bytebuf_append(bytebuf *b, const void *p, size_t n)
{
    if (b->failed || n == 0)
        return;
    if (b->len + n > b->cap) {
        size_t ncap = b->cap ? b->cap : 256;
        while (ncap < b->len + n) {
            if (ncap > SIZE_MAX / 2) {
                b->failed = 1;
                return;
            }
            ncap *= 2;
        }
        unsigned char *nd = rt_realloc(b->data, ncap);
        if (!nd) {
            b->failed = 1;
            return;
        }
        b->data = nd;
        b->cap = ncap;
    }
    memcpy(b->data + b->len, p, n);
    b->len += n;
}

void bytebuf_printf(bytebuf *b, const char *fmt, ...)
{
    char small[512];
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (k < 0) {
        b->failed = 1;
        return;
    }
    if ((size_t)k < sizeof small) {
        bytebuf_append(b, small, (size_t)k);
        return;
    }
    char *big = rt_malloc((size_t)k + 1);
    if (!big) {
        b->failed = 1;
        return;
    }
    va_start(ap, fmt);
    vsnprintf(big, (size_t)k + 1, fmt, ap);
    va_end(ap);
    bytebuf_append(b, big, (size_t)k);
    rt_free(big);
}

void bytebuf_u16be(bytebuf *b, unsigned v)
{
    unsigned char c[2] = {(unsigned char)(v >> 8), (unsigned char)v};
    bytebuf_append(b, c, 2);
}

void bytebuf_u32be(bytebuf *b, uint32_t v)
{
    unsigned char c[4] = {(unsigned char)(v >> 24), (unsigned char)(v >> 16), (unsigned char)(v >> 8),
                          (unsigned char)v};
    bytebuf_append(b, c, 4);
}

void bytebuf_u16le(bytebuf *b, unsigned v)
{
    unsigned char c[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    bytebuf_append(b, c, 2);
}

void bytebuf_u32le(bytebuf *b, uint32_t v)
{
    unsigned char c[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    bytebuf_append(b, c, 4);
}

void bytebuf_f32le(bytebuf *b, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    bytebuf_u32le(b, u);
}

void bytebuf_f32be(bytebuf *b, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    bytebuf_u32be(b, u);
}

const char *fileio_ext(const char *path, char *buf, size_t bufsize)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t i = 0;
    if (dot && bufsize > 0) {
        for (dot++; *dot && i + 1 < bufsize; dot++)
            buf[i++] = (char)tolower((unsigned char)*dot);
    }
    if (bufsize > 0)
        buf[i] = 0;
    return buf;
}
