/* sample.c — typed binary samples (sample.h). */
#include "sample.h"

#include <string.h>

size_t sample_size(sample_type t)
{
    static const size_t sz[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return (unsigned)t < sizeof sz / sizeof sz[0] ? sz[t] : 0;
}

uint64_t sample_uint(const unsigned char *p, size_t n, int big)
{
    uint64_t u = 0;
    for (size_t i = 0; i < n; i++)
        u |= (uint64_t)p[big ? i : n - 1 - i] << (8 * (n - 1 - i));
    return u;
}

void sample_f32(const unsigned char *p, int big, float *out)
{
    uint32_t w = (uint32_t)sample_uint(p, 4, big);
    memcpy(out, &w, 4);
}

double sample_get(const unsigned char *p, sample_type t, int big)
{
    uint64_t u = sample_uint(p, sample_size(t), big);
    switch (t) {
    case SAMPLE_I8:
        return (int8_t)(uint8_t)u;
    case SAMPLE_I16:
        return (int16_t)(uint16_t)u;
    case SAMPLE_I32:
        return (int32_t)(uint32_t)u;
    case SAMPLE_F32: {
        float f;
        sample_f32(p, big, &f);
        return f;
    }
    case SAMPLE_F64: {
        double d;
        memcpy(&d, &u, 8);
        return d;
    }
    default: /* the unsigned types */
        return (double)u;
    }
}
