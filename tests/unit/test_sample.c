/* test_sample.c — the shared typed-sample decoder (sample.h) on byte
 * patterns worked out by hand from the two's-complement and IEEE 754
 * definitions. */
#include <string.h>

#include "check.h"
#include "sample.h"

int main(void)
{
    const unsigned char b[8] = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08};
    CHECK(sample_uint(b, 2, 0) == 0x0201 && sample_uint(b, 2, 1) == 0x0102, "16-bit byte orders");
    CHECK(sample_uint(b, 4, 0) == 0x04030201u && sample_uint(b, 4, 1) == 0x01020304u, "32-bit byte orders");
    CHECK(sample_uint(b, 8, 0) == 0x0807060504030201ull && sample_uint(b, 8, 1) == 0x0102030405060708ull,
          "64-bit byte orders");
    CHECK(sample_size(SAMPLE_I8) == 1 && sample_size(SAMPLE_U16) == 2 && sample_size(SAMPLE_U32) == 4 &&
              sample_size(SAMPLE_F32) == 4 && sample_size(SAMPLE_F64) == 8 && sample_size(SAMPLE_NONE) == 0,
          "sizes");
    /* 0xff is -1 signed, 255 unsigned; 0xfffe (big-endian ff fe) is -2 / 65534;
     * 0x80000000 is INT32_MIN / 2^31. */
    const unsigned char ff[4] = {0xff, 0xfe, 0x00, 0x80};
    CHECK(sample_get(ff, SAMPLE_I8, 0) == -1 && sample_get(ff, SAMPLE_U8, 0) == 255, "8-bit");
    CHECK(sample_get(ff, SAMPLE_I16, 1) == -2 && sample_get(ff, SAMPLE_U16, 1) == 65534, "16-bit big-endian");
    CHECK(sample_get(ff, SAMPLE_I16, 0) == -257, "16-bit little-endian fe ff = 0xfeff = -257");
    const unsigned char m[4] = {0x00, 0x00, 0x00, 0x80};
    CHECK(sample_get(m, SAMPLE_I32, 0) == -2147483648.0 && sample_get(m, SAMPLE_U32, 0) == 2147483648.0, "32-bit");
    /* 1.5f = 0x3fc00000, -2.0 (double) = 0xc000000000000000. */
    const unsigned char f_be[4] = {0x3f, 0xc0, 0x00, 0x00}, f_le[4] = {0x00, 0x00, 0xc0, 0x3f};
    CHECK(sample_get(f_be, SAMPLE_F32, 1) == 1.5 && sample_get(f_le, SAMPLE_F32, 0) == 1.5, "float 1.5");
    const unsigned char d_le[8] = {0, 0, 0, 0, 0, 0, 0, 0xc0};
    CHECK(sample_get(d_le, SAMPLE_F64, 0) == -2.0 && sample_get(d_le, SAMPLE_F64, 1) == 0xc0 * 0x1p-1074,
          "double -2 (and its reverse, the subnormal 192 · 2^-1074)");
    /* A signalling NaN 0x7f800001 keeps its bits through sample_f32. */
    const unsigned char snan[4] = {0x01, 0x00, 0x80, 0x7f};
    float f;
    uint32_t bits;
    sample_f32(snan, 0, &f);
    memcpy(&bits, &f, 4);
    CHECK(bits == 0x7f800001u, "NaN payload kept: %08x", (unsigned)bits);
    return check_done("test_sample");
}
