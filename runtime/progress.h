/* progress.h — a progress bar on stderr, drawn only when stderr is a terminal.
 *
 * Thread-safe: progress_step may be called from any worker. The bar redraws
 * at most ~20 times a second and is erased by progress_end. It shows the
 * label, the bar, the percentage, the time so far and, once some chunks are
 * done, an ETA: the time so far × (remaining / done).
 */
#ifndef PROGRESS_H
#define PROGRESS_H

#include <pthread.h>
#include <stddef.h>

typedef struct progress {
    int enabled;
    const char *label;
    size_t total, done;
    double last_draw, start;
    pthread_mutex_t lock;
} progress;

void progress_begin(progress *p, const char *label, size_t total, int want);
void progress_step(progress *p, size_t n);
void progress_end(progress *p);

#endif
