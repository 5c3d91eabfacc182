/* test_fileio.c — atomic writes: O_EXCL temp files, refusal of links and
 * special files, parent folders, long paths, temp files removed on signals. */
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700
#include <dirent.h>
#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "check.h"
#include "fileio.h"
#include "tempfiles.h"

static char root[256];

static void pathf(char *buf, size_t n, const char *name) { snprintf(buf, n, "%s/%s", root, name); }

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static int same_text(const char *path, const char *text)
{
    unsigned char *d;
    size_t n;
    if (fileio_read_all(path, 1 << 20, &d, &n, NULL))
        return 0;
    int ok = n == strlen(text) && memcmp(d, text, n) == 0;
    rt_free(d);
    return ok;
}

static void test_plain(void)
{
    char p[512];
    rt_error e;
    pathf(p, sizeof p, "plain.txt");
    CHECK(fileio_write_atomic(p, "one", 3, &e) == RT_OK, "%s", e.msg);
    CHECK(same_text(p, "one"), "first write");
    CHECK(fileio_write_atomic(p, "second", 6, &e) == RT_OK, "%s", e.msg);
    CHECK(same_text(p, "second"), "a regular file is replaced");
    CHECK(fileio_write_atomic(p, "", 0, &e) == RT_OK, "%s", e.msg);
    CHECK(same_text(p, ""), "empty file");
    CHECK(count_temps(root) == 0, "no temp file left");
}

/* A symlink planted where the temp file will be created must not be
 * followed: the temp file is opened with O_EXCL and another name is tried. */
static void test_excl(void)
{
    char p[512], victim[512], planted[600];
    rt_error e;
    pathf(p, sizeof p, "excl.txt");
    pathf(victim, sizeof victim, "victim.txt");
    put(victim, "precious");
    /* every name the writer could try first: this process's pid, counters 0..99
     * (and the old scheme's "NAME.tmpPID") */
    for (int k = -1; k < 100; k++) {
        if (k < 0)
            snprintf(planted, sizeof planted, "%s.tmp%ld", p, (long)getpid());
        else
            snprintf(planted, sizeof planted, "%s.tmp%ld-%d", p, (long)getpid(), k);
        CHECK(symlink(victim, planted) == 0, "symlink %s: %s", planted, strerror(errno));
    }
    rt_code c = fileio_write_atomic(p, "new", 3, &e);
    CHECK(same_text(victim, "precious"), "the planted link was followed");
    if (c == RT_OK) {
        CHECK(same_text(p, "new"), "written");
        struct stat st;
        CHECK(lstat(p, &st) == 0 && S_ISREG(st.st_mode), "target is a regular file");
    } else {
        CHECK(strstr(e.msg, "cannot create a temporary file beside") != NULL, "%s", e.msg);
    }
    for (int k = -1; k < 100; k++) {
        if (k < 0)
            snprintf(planted, sizeof planted, "%s.tmp%ld", p, (long)getpid());
        else
            snprintf(planted, sizeof planted, "%s.tmp%ld-%d", p, (long)getpid(), k);
        struct stat st;
        CHECK(lstat(planted, &st) == 0 && S_ISLNK(st.st_mode), "planted link %s kept", planted);
        unlink(planted);
    }
}

static void test_refuse(void)
{
    char p[512], victim[512], msg[1200];
    rt_error e;
    struct stat st;
    pathf(victim, sizeof victim, "target_of_link.txt");
    put(victim, "keep");
    pathf(p, sizeof p, "link.png");
    CHECK(symlink(victim, p) == 0, "symlink");
    CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a symlink target is an I/O error");
    snprintf(msg, sizeof msg, "cannot write '%s': it is a symbolic link, not a regular file", p);
    CHECK(strstr(e.msg, msg) != NULL, "%s", e.msg);
    CHECK(lstat(p, &st) == 0 && S_ISLNK(st.st_mode), "the link is still a link");
    CHECK(same_text(victim, "keep"), "the link's target is untouched");

    pathf(p, sizeof p, "dangling.png");
    CHECK(symlink("/nonexistent/where", p) == 0, "symlink");
    CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a dangling symlink too");
    CHECK(strstr(e.msg, "it is a symbolic link") != NULL, "%s", e.msg);

    pathf(p, sizeof p, "fifo.png");
    CHECK(mkfifo(p, 0600) == 0, "mkfifo");
    CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a FIFO target");
    CHECK(strstr(e.msg, "it is a FIFO, not a regular file") != NULL, "%s", e.msg);
    CHECK(lstat(p, &st) == 0 && S_ISFIFO(st.st_mode), "the FIFO is still there");

    pathf(p, sizeof p, "adir.png");
    CHECK(mkdir(p, 0700) == 0, "mkdir");
    CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a folder target");
    CHECK(strstr(e.msg, "it is a folder, not a regular file") != NULL, "%s", e.msg);

    /* a character device like /dev/null (only root may make one) */
    pathf(p, sizeof p, "null.png");
    if (mknod(p, S_IFCHR | 0600, makedev(1, 3)) == 0) {
        CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a device target");
        CHECK(strstr(e.msg, "it is a character device, not a regular file") != NULL, "%s", e.msg);
        CHECK(lstat(p, &st) == 0 && S_ISCHR(st.st_mode), "the device node is still there");
    }
    CHECK(count_temps(root) == 0, "no temp file left");
}

static void test_parents(void)
{
    char p[512], msg[1200];
    rt_error e;
    pathf(p, sizeof p, "sub/dir//deep/x.txt");
    CHECK(fileio_write_atomic(p, "deep", 4, &e) == RT_OK, "%s", e.msg);
    CHECK(same_text(p, "deep"), "written into new folders");
    pathf(p, sizeof p, "sub/dir/y.txt");
    CHECK(fileio_write_atomic(p, "y", 1, &e) == RT_OK, "%s", e.msg);

    char file[512];
    pathf(file, sizeof file, "afile");
    put(file, "f");
    pathf(p, sizeof p, "afile/inner/z.txt");
    CHECK(fileio_write_atomic(p, "z", 1, &e) == RT_EIO, "a file where a folder must go");
    snprintf(msg, sizeof msg, "cannot create folder '%s' for '%s': it exists and is a file", file, p);
    CHECK(strstr(e.msg, msg) != NULL, "%s", e.msg);
    pathf(p, sizeof p, "afile/z.txt");
    CHECK(fileio_write_atomic(p, "z", 1, &e) == RT_EIO, "parent is a file");
    snprintf(msg, sizeof msg, "cannot create folder '%s' for '%s': it exists and is a file", file, p);
    CHECK(strstr(e.msg, msg) != NULL, "%s", e.msg);
    CHECK(same_text(file, "f"), "the file in the way is untouched");
}

static void test_long(void)
{
    rt_error e;
    size_t n = 5000;
    char *p = malloc(n + 1);
    memset(p, 'a', n);
    p[n] = 0;
    for (size_t i = 100; i < n; i += 100)
        p[i] = '/';
    CHECK(fileio_write_atomic(p, "x", 1, &e) == RT_EIO, "a path over PATH_MAX");
    CHECK(strncmp(e.msg, "path too long: ", 15) == 0 && strstr(e.msg, "(5000 bytes; the limit is 4095)"),
          "%s", e.msg);
    free(p);

    /* a 250-byte file name: the temp file cannot be NAME.tmpPID-N */
    char q[600];
    int k = snprintf(q, sizeof q, "%s/", root);
    memset(q + k, 'b', 250);
    q[k + 250] = 0;
    CHECK(fileio_write_atomic(q, "long name", 9, &e) == RT_OK, "%s", e.msg);
    CHECK(same_text(q, "long name"), "written");
    CHECK(count_temps(root) == 0, "no temp file left");
}

/* ---- concurrent writers ---------------------------------------------------------- */

static void *writer(void *arg)
{
    int id = (int)(size_t)arg;
    char p[512], text[64];
    for (int i = 0; i < 40; i++) {
        snprintf(p, sizeof p, "%s/threads/t%d/f%d.txt", root, id, i % 5);
        snprintf(text, sizeof text, "thread %d file %d", id, i);
        rt_error e;
        if (fileio_write_atomic(p, text, strlen(text), &e) != RT_OK)
            return (void *)1;
    }
    return NULL;
}

static void test_threads(void)
{
    pthread_t t[4];
    for (size_t i = 0; i < 4; i++)
        pthread_create(&t[i], NULL, writer, (void *)i);
    int bad = 0;
    for (int i = 0; i < 4; i++) {
        void *r;
        pthread_join(t[i], &r);
        bad += r != NULL;
    }
    CHECK(bad == 0, "%d writer threads failed", bad);
    for (int id = 0; id < 4; id++) {
        char p[512], text[64], dir[512];
        snprintf(p, sizeof p, "%s/threads/t%d/f4.txt", root, id);
        snprintf(text, sizeof text, "thread %d file 39", id);
        CHECK(same_text(p, text), "thread %d's last write", id);
        snprintf(dir, sizeof dir, "%s/threads/t%d", root, id);
        CHECK(count_temps(dir) == 0, "no temp file left by thread %d", id);
    }
}

/* ---- signals ----------------------------------------------------------------------- */

/* The child hits RLIMIT_FSIZE halfway through writing the temp file: the
 * kernel sends SIGXFSZ from inside write(), and this handler stands for a
 * signal arriving at that moment. */
static int xfsz_action;
static char xfsz_dir[512];

static void on_xfsz(int sig)
{
    (void)sig;
    if (xfsz_action == 0) {
        raise(SIGTERM);
    } else if (xfsz_action == 1) {
        raise(SIGHUP);
    } else {
        fileio_cleanup_temps();
        _exit(count_temps(xfsz_dir) == 0 ? 42 : 43);
    }
}

static int child_write_signalled(int action, const char *dir)
{
    pid_t pid = fork();
    if (pid == 0) {
        fileio_install_signal_cleanup();
        xfsz_action = action;
        snprintf(xfsz_dir, sizeof xfsz_dir, "%s", dir);
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_xfsz;
        sigemptyset(&sa.sa_mask);
        sigaction(SIGXFSZ, &sa, NULL);
        struct rlimit rl = {1 << 16, 1 << 16};
        setrlimit(RLIMIT_FSIZE, &rl);
        size_t n = 1 << 20;
        char *big = calloc(n, 1);
        char p[600];
        snprintf(p, sizeof p, "%s/big.raw", dir);
        rt_error e;
        fileio_write_atomic(p, big, n, &e);
        _exit(0); /* not reached when the signal works */
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return status;
}

static void test_signals(void)
{
    char dir[512];
    pathf(dir, sizeof dir, "sig_term");
    mkdir(dir, 0700);
    int st = child_write_signalled(0, dir);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "SIGTERM kills with the signal (status %#x)", st);
    CHECK(count_temps(dir) == 0, "SIGTERM during a write left a temp file");

    pathf(dir, sizeof dir, "sig_hup");
    mkdir(dir, 0700);
    st = child_write_signalled(1, dir);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGHUP, "SIGHUP kills with the signal (status %#x)", st);
    CHECK(count_temps(dir) == 0, "SIGHUP during a write left a temp file");

    pathf(dir, sizeof dir, "sig_direct");
    mkdir(dir, 0700);
    st = child_write_signalled(2, dir);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 42, "fileio_cleanup_temps removed the temp file (status %#x)",
          st);

    /* an ignored SIGHUP (nohup) stays ignored */
    pid_t pid = fork();
    if (pid == 0) {
        signal(SIGHUP, SIG_IGN);
        fileio_install_signal_cleanup();
        struct sigaction old;
        sigaction(SIGHUP, NULL, &old);
        _exit(old.sa_handler == SIG_IGN ? 0 : 1);
    }
    waitpid(pid, &st, 0);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "nohup's SIG_IGN kept");

    /* a real SIGTERM from outside while the child writes big files in a loop */
    pathf(dir, sizeof dir, "sig_kill");
    mkdir(dir, 0700);
    pid = fork();
    if (pid == 0) {
        fileio_install_signal_cleanup();
        size_t n = 8u << 20;
        char *big = calloc(n, 1);
        char p[600];
        snprintf(p, sizeof p, "%s/loop.raw", dir);
        for (;;) {
            rt_error e;
            fileio_write_atomic(p, big, n, &e);
        }
    }
    struct timespec ts = {0, 150 * 1000 * 1000};
    nanosleep(&ts, NULL);
    kill(pid, SIGTERM);
    waitpid(pid, &st, 0);
    CHECK(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "killed by SIGTERM (status %#x)", st);
    CHECK(count_temps(dir) == 0, "a temp file survived SIGTERM");
    char p[600];
    struct stat sb;
    snprintf(p, sizeof p, "%s/loop.raw", dir);
    if (stat(p, &sb) == 0)
        CHECK(sb.st_size == (off_t)(8u << 20), "the target is whole or absent, got %lld bytes",
              (long long)sb.st_size);
}

static int rm_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return -1;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        struct dirent *e;
        while (d && (e = readdir(d))) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            char sub[4200];
            snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
            rm_tree(sub);
        }
        if (d)
            closedir(d);
        return rmdir(path);
    }
    return unlink(path);
}

/* fileio_set_path_hook (frac watch): every read is seen before the file is
 * opened (a missing one too), every completed write after it; a failed
 * write is not reported; NULL removes the hook. */
static char seen[8][512];
static int seen_wrote[8], nseen;
static void on_path(void *ud, const char *path, int wrote)
{
    CHECK(ud == (void *)seen, "the hook gets its user data");
    if (nseen < 8) {
        snprintf(seen[nseen], sizeof seen[nseen], "%s", path);
        seen_wrote[nseen++] = wrote;
    }
}

static void test_path_hook(void)
{
    char a[4096], missing[4096], dir[4096];
    pathf(a, sizeof a, "hooked.txt");
    pathf(missing, sizeof missing, "no_such_file.txt");
    pathf(dir, sizeof dir, "hook_dir");
    mkdir(dir, 0777);
    rt_error e;
    unsigned char *d;
    size_t n;
    fileio_set_path_hook(on_path, seen);
    CHECK(fileio_write_atomic(a, "abc", 3, &e) == RT_OK, "write: %s", e.msg);
    CHECK(fileio_read_all(a, 100, &d, &n, &e) == RT_OK && n == 3, "read back");
    rt_free(d);
    CHECK(fileio_read_all(missing, 100, &d, &n, &e) == RT_EIO, "missing file");
    CHECK(fileio_write_atomic(dir, "x", 1, &e) == RT_EIO, "a folder is refused");
    fileio_set_path_hook(NULL, NULL);
    CHECK(fileio_read_all(a, 100, &d, &n, &e) == RT_OK, "read without the hook");
    rt_free(d);
    CHECK(nseen == 3, "3 paths seen, got %d", nseen);
    CHECK(nseen >= 3 && !strcmp(seen[0], a) && seen_wrote[0] == 1, "the write: %s %d", seen[0], seen_wrote[0]);
    CHECK(nseen >= 3 && !strcmp(seen[1], a) && seen_wrote[1] == 0, "the read: %s %d", seen[1], seen_wrote[1]);
    CHECK(nseen >= 3 && !strcmp(seen[2], missing) && seen_wrote[2] == 0, "the missing read: %s", seen[2]);
}

int main(void)
{
    const char *t = getenv("TMPDIR");
    snprintf(root, sizeof root, "%s/frac_fileio_XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(root)) {
        perror("mkdtemp");
        return 1;
    }
    test_plain();
    test_excl();
    test_refuse();
    test_parents();
    test_long();
    test_threads();
    test_signals();
    test_path_hook();
    rm_tree(root);
    return check_done("test_fileio");
}
