/* rt.c — shared runtime helpers. */
#include "rt.h"

#include <stdarg.h>
#include <stdio.h>

rt_code rt_fail(rt_error *e, rt_code code, const char *fmt, ...)
{
    if (e) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(e->msg, sizeof e->msg, fmt, ap);
        va_end(ap);
        e->code = code;
    }
    return code;
}

size_t rt_mul_size(size_t a, size_t b)
{
    if (a != 0 && b > SIZE_MAX / a)
        return 0;
    return a * b;
}
