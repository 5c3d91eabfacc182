/* fileio.c — whole-file reads, atomic writes, byte buffers. */
#define _POSIX_C_SOURCE 200809L
#include "fileio.h"
#include "rt_alloc.h"

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

rt_code fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e)
{
    size_t plen = strlen(path);
    char *tmp = rt_malloc(plen + 32);
    if (!tmp)
        return rt_fail(e, RT_ENOMEM, "out of memory");
    snprintf(tmp, plen + 32, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        rt_code c = rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(errno));
        rt_free(tmp);
        return c;
    }
    size_t w = n ? fwrite(data, 1, n, f) : 0;
    int bad = (w != n) | (fflush(f) != 0);
    int err = errno;
    bad |= fclose(f) != 0;
    if (bad) {
        remove(tmp);
        rt_free(tmp);
        return rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(err));
    }
    if (rename(tmp, path) != 0) {
        err = errno;
        remove(tmp);
        rt_free(tmp);
        return rt_fail(e, RT_EIO, "cannot write '%s': %s", path, strerror(err));
    }
    rt_free(tmp);
    return RT_OK;
}

rt_code fileio_read_all(const char *path, size_t max_bytes, unsigned char **data, size_t *n,
                        rt_error *e)
{
    *data = NULL;
    *n = 0;
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
