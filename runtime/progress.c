/* progress.c — terminal progress bar for long renders. */
#define _POSIX_C_SOURCE 200809L
#include "progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void draw(progress *p)
{
    enum { WIDTH = 30 };
    double f = p->total ? (double)p->done / (double)p->total : 1.0;
    int fill = (int)(f * WIDTH);
    char bar[WIDTH + 1];
    for (int i = 0; i < WIDTH; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[WIDTH] = 0;
    double t = now_seconds() - p->start;
    fprintf(stderr, "\r%s [%s] %3d%% %.1fs", p->label ? p->label : "", bar, (int)(f * 100.0), t);
    /* the rest at the rate so far (chunks are equal work in most engines) */
    if (f > 0 && f < 1)
        fprintf(stderr, " ETA %.1fs\033[K", t * (1 - f) / f);
    fflush(stderr);
}

void progress_begin(progress *p, const char *label, size_t total, int want)
{
    p->enabled = want && isatty(2);
    p->label = label;
    p->total = total;
    p->done = 0;
    p->start = now_seconds();
    p->last_draw = p->start;
    pthread_mutex_init(&p->lock, NULL);
}

void progress_step(progress *p, size_t n)
{
    if (!p->enabled)
        return;
    pthread_mutex_lock(&p->lock);
    p->done += n;
    double t = now_seconds();
    /* Only draw after half a second, so quick renders stay silent. */
    if (t - p->start > 0.5 && t - p->last_draw > 0.05) {
        p->last_draw = t;
        draw(p);
    }
    pthread_mutex_unlock(&p->lock);
}

void progress_end(progress *p)
{
    if (p->enabled && p->last_draw > p->start)
        fprintf(stderr, "\r\033[K");
    pthread_mutex_destroy(&p->lock);
}
