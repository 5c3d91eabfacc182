/* textline.c — header lines (textline.h). */
#include "textline.h"

#include <string.h>

long textline_next(const unsigned char *d, size_t n, size_t *pos, char *buf, size_t bn)
{
    if (*pos >= n)
        return -1;
    size_t end = *pos;
    while (end < n && d[end] != '\n')
        end++;
    size_t len = end - *pos, full;
    if (len && d[*pos + len - 1] == '\r')
        len--;
    full = len;
    if (len >= bn)
        len = bn - 1;
    memcpy(buf, d + *pos, len);
    buf[len] = 0;
    *pos = end < n ? end + 1 : end;
    return (long)full;
}
