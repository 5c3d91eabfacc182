/* fileio.h — whole-file reads and safe writes.
 *
 * fileio_write_atomic never leaves a partial or misplaced file:
 *  - a target that exists and is not a regular file (a symbolic link, a
 *    folder, a device, a FIFO, a socket) is refused with RT_EIO: the write
 *    never goes through a link or replaces a node such as /dev/null;
 *  - missing parent folders of the target are created (mkdir -p; an error
 *    names the folder that could not be made);
 *  - the data goes to a new temporary file beside the target, created with
 *    O_EXCL (a fresh name per try, retried on EEXIST), written fully, fsync'd
 *    and renamed into place; then the folder is fsync'd (where the file system
 *    allows it). On any error the temporary file is removed;
 *  - paths of FILEIO_PATH_MAX bytes or more are refused ("path too long"),
 *    never truncated.
 * Writes may run on any thread at once. Up to FILEIO_MAX_TEMPS temporary files
 * being written are kept in a fixed table that fileio_cleanup_temps() (safe to
 * call from a signal handler) unlinks; a write beyond that many concurrent ones
 * still works but is not covered. fileio_install_signal_cleanup() installs
 * SIGTERM and SIGHUP handlers that unlink the temporary files and then re-raise
 * the signal with its default action, so the exit status still says "killed by
 * signal N" (an ignored signal, as under nohup, stays ignored). A SIGINT
 * handler that ends the process should call fileio_cleanup_temps() first.
 */
#ifndef FILEIO_H
#define FILEIO_H

#include <stddef.h>

#include "rt.h"

#define FILEIO_PATH_MAX 4096 /* bytes in a path, with its NUL (Linux PATH_MAX) */
#define FILEIO_MAX_TEMPS 64

rt_code fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e);
/* Create the missing parent folders of path (mkdir -p of its dirname). */
rt_code fileio_make_parents(const char *path, rt_error *e);
/* Unlink every temporary file being written. Async-signal-safe. */
void fileio_cleanup_temps(void);
/* SIGTERM/SIGHUP: clean up, then die of the signal. Returns 0, or -1 if a
 * sigaction failed. */
int fileio_install_signal_cleanup(void);
rt_code fileio_read_all(const char *path, size_t max_bytes, unsigned char **data, size_t *n,
                        rt_error *e);
/* Watching (frac watch): with a hook set, fn(ud, path, wrote) sees every
 * path fileio_read_all opens (wrote 0; called before reading, so a file that
 * is missing is seen too) and every file fileio_write_atomic has written
 * (wrote 1). One process-wide hook, like the allocation hook (rt_alloc.h),
 * called on the thread that reads or writes; NULL removes it. */
typedef void (*fileio_path_hook)(void *ud, const char *path, int wrote);
void fileio_set_path_hook(fileio_path_hook fn, void *ud);

/* A growable byte buffer for building files in memory. */
typedef struct bytebuf {
    unsigned char *data;
    size_t len, cap;
    int failed; /* an allocation failed; further appends are ignored */
} bytebuf;

void bytebuf_init(bytebuf *b);
void bytebuf_free(bytebuf *b);
void bytebuf_append(bytebuf *b, const void *p, size_t n);
void bytebuf_printf(bytebuf *b, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static inline void bytebuf_byte(bytebuf *b, unsigned char c) { bytebuf_append(b, &c, 1); }
void bytebuf_u16be(bytebuf *b, unsigned v);
void bytebuf_u32be(bytebuf *b, uint32_t v);
void bytebuf_u16le(bytebuf *b, unsigned v);
void bytebuf_u32le(bytebuf *b, uint32_t v);
void bytebuf_f32le(bytebuf *b, float v);
void bytebuf_f32be(bytebuf *b, float v);

/* Lower-case extension of path without the dot ("" if none), into buf. */
const char *fileio_ext(const char *path, char *buf, size_t bufsize);

#endif
