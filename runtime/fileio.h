/* fileio.h — whole-file reads and safe writes.
 *
 * fileio_write_atomic writes data to a temporary file in the same directory
 * as path and renames it into place only when every byte is written and
 * flushed, so an error or a crash never leaves a half-written file over a
 * good one.
 */
#ifndef FILEIO_H
#define FILEIO_H

#include <stddef.h>

#include "rt.h"

rt_code fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e);
/* Read a whole file into a malloc'd buffer (NUL-terminated for convenience;
 * *n excludes the NUL). Files larger than max_bytes are refused. */
rt_code fileio_read_all(const char *path, size_t max_bytes, unsigned char **data, size_t *n,
                        rt_error *e);

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
