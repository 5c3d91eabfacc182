/* watch.c — `frac watch`: re-render when a file read changes (watch.h). */
#include "watch.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "fileio.h"
#include "image.h"
#include "lineedit.h"
#include "termview.h"

#define WATCH_MAX_FILES 256
#define WATCH_POLL_MS 100

typedef struct fsig {
    int exists;
    long long mtime_ns, size;
    unsigned long long ino, dev;
} fsig;

typedef struct watched {
    char path[FILEIO_PATH_MAX];
    fsig sig;
    int used; /* read by the current render */
} watched;

typedef struct watcher {
    pthread_mutex_t lock;
    watched files[WATCH_MAX_FILES];
    int nfiles, dropped;
    char first_image[FILEIO_PATH_MAX]; /* --show: the first image the render wrote */
    char changed_path[FILEIO_PATH_MAX];
    volatile sig_atomic_t cancel;      /* the render's interrupt flag */
    atomic_int changed, stop;
    volatile sig_atomic_t *interrupted;
} watcher;

static fsig sig_of(const char *path)
{
    fsig s;
    memset(&s, 0, sizeof s);
    struct stat st;
    if (stat(path, &st) != 0)
        return s;
    s.exists = 1;
    s.mtime_ns = (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec;
    s.size = (long long)st.st_size;
    s.ino = (unsigned long long)st.st_ino;
    s.dev = (unsigned long long)st.st_dev;
    return s;
}

static int sig_same(const fsig *a, const fsig *b)
{
    return a->exists == b->exists && a->mtime_ns == b->mtime_ns && a->size == b->size && a->ino == b->ino &&
           a->dev == b->dev;
}

static int is_image_path(const char *path)
{
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    return !strcmp(ext, "png") || !strcmp(ext, "ppm") || !strcmp(ext, "pgm") || !strcmp(ext, "pfm");
}

/* fileio's path hook: record what the render reads, note what it writes */
static void on_path(void *ud, const char *path, int wrote)
{
    watcher *w = ud;
    if (strlen(path) >= FILEIO_PATH_MAX)
        return;
    pthread_mutex_lock(&w->lock);
    int i = 0;
    while (i < w->nfiles && strcmp(w->files[i].path, path) != 0)
        i++;
    if (wrote) {
        if (i < w->nfiles) /* written by the render itself: not a change */
            w->files[i].sig = sig_of(path);
        if (!w->first_image[0] && is_image_path(path))
            snprintf(w->first_image, sizeof w->first_image, "%s", path);
    } else if (i < w->nfiles) { /* read again: what it holds now is what the render sees */
        w->files[i].sig = sig_of(path);
        w->files[i].used = 1;
    } else if (w->nfiles < WATCH_MAX_FILES) {
        snprintf(w->files[i].path, sizeof w->files[i].path, "%s", path);
        w->files[i].sig = sig_of(path);
        w->files[i].used = 1;
        w->nfiles++;
    } else {
        w->dropped++;
    }
    pthread_mutex_unlock(&w->lock);
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

/* The poll thread: stat every file; a difference cancels the render. */
static void *poll_files(void *ud)
{
    watcher *w = ud;
    while (!atomic_load(&w->stop)) {
        if (*w->interrupted)
            w->cancel = 1;
        pthread_mutex_lock(&w->lock);
        for (int i = 0; i < w->nfiles; i++) {
            fsig now = sig_of(w->files[i].path);
            if (!sig_same(&now, &w->files[i].sig)) {
                w->files[i].sig = now;
                if (!atomic_load(&w->changed))
                    snprintf(w->changed_path, sizeof w->changed_path, "%s", w->files[i].path);
                atomic_store(&w->changed, 1);
                w->cancel = 1;
            }
        }
        pthread_mutex_unlock(&w->lock);
        sleep_ms(WATCH_POLL_MS);
    }
    return NULL;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void show_image(const char *path)
{
    if (!isatty(1)) {
        fprintf(stderr, "watch: --show: standard output is not a terminal; not drawing %s\n", path);
        return;
    }
    image im;
    rt_error e;
    rt_code c = image_load(&im, path, &e);
    if (c) {
        fprintf(stderr, "watch: --show: %s\n", e.msg);
        return;
    }
    termview_opts o;
    memset(&o, 0, sizeof o);
    int width = lineedit_term_width(1);
    o.cols = width > 2 ? width - 1 : 1;
    if (o.cols > im.w)
        o.cols = im.w;
    o.max_rows = 40;
    o.color = termview_env_color(getenv("NO_COLOR"), getenv("TERM"));
    fflush(stdout);
    if (termview_write(1, &im, &o, &e))
        fprintf(stderr, "watch: --show: %s\n", e.msg);
    image_free(&im);
}

int watch_main(interp *T, watch_render_fn render, void *ud, volatile sig_atomic_t *interrupted, int show,
               int quiet)
{
    watcher *w = mem_calloc(T, 1, sizeof *w);
    if (!w)
        return -1;
    pthread_mutex_init(&w->lock, NULL);
    w->interrupted = interrupted;
    pthread_t th;
    if (pthread_create(&th, NULL, poll_files, w) != 0) {
        pthread_mutex_destroy(&w->lock);
        mem_free(T, w);
        fprintf(stderr, "frac: error: watch: cannot start the thread that polls the files\n");
        return 70;
    }
    fileio_set_path_hook(on_path, w);
    while (!*interrupted) {
        pthread_mutex_lock(&w->lock);
        for (int i = 0; i < w->nfiles; i++)
            w->files[i].used = 0;
        w->dropped = 0;
        w->first_image[0] = 0;
        atomic_store(&w->changed, 0);
        w->cancel = 0;
        pthread_mutex_unlock(&w->lock);
        double t0 = now_s();
        int rc = render(ud, &w->cancel);
        fflush(stdout); /* print() output of this render, before the status line */
        if (*interrupted)
            break;
        pthread_mutex_lock(&w->lock);
        if (rc == 0 && !atomic_load(&w->changed)) { /* this render's files; after a failure or a cancel, the last ones too */
            int k = 0;
            for (int i = 0; i < w->nfiles; i++)
                if (w->files[i].used)
                    w->files[k++] = w->files[i];
            w->nfiles = k;
        }
        int n = w->nfiles, dropped = w->dropped;
        char first[FILEIO_PATH_MAX];
        snprintf(first, sizeof first, "%s", w->first_image);
        pthread_mutex_unlock(&w->lock);
        if (!atomic_load(&w->changed)) {
            if (rc == 0 && show && first[0])
                show_image(first);
            if (!quiet) {
                fprintf(stderr, "watch: %s in %.2f s; watching %d file%s for changes (Ctrl-C ends)\n",
                        rc == 0 ? "rendered" : "failed", now_s() - t0, n, n == 1 ? "" : "s");
                if (dropped)
                    fprintf(stderr, "watch: %d more files were read; only the first %d are watched\n", dropped,
                            WATCH_MAX_FILES);
            }
        }
        while (!atomic_load(&w->changed) && !*interrupted)
            sleep_ms(20);
        if (atomic_load(&w->changed) && !*interrupted && !quiet) {
            pthread_mutex_lock(&w->lock);
            fprintf(stderr, "watch: %s changed; rendering again\n", w->changed_path);
            pthread_mutex_unlock(&w->lock);
        }
    }
    fileio_set_path_hook(NULL, NULL);
    atomic_store(&w->stop, 1);
    pthread_join(th, NULL);
    pthread_mutex_destroy(&w->lock);
    mem_free(T, w);
    if (!quiet)
        fprintf(stderr, "watch: stopped\n");
    return 0;
}
