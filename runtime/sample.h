/* sample.h — typed binary samples: the one decoder of fixed-size integers
 * and IEEE 754 floats in either byte order that the file readers share (PLY
 * and STL in mesh_io.c; NRRD and VTK in volume_io.c; PFM in pnm.c).
 *
 * A sample of type t takes sample_size(t) bytes at p: 1 for I8/U8, 2 for
 * I16/U16, 4 for I32/U32/F32, 8 for F64. Integers are two's complement
 * (signed types) or plain binary, floats IEEE 754 binary32/binary64; `big`
 * selects big-endian (most significant byte first) over little-endian.
 * sample_get gives the value as a double, which holds every one of these
 * types exactly. The caller checks that the bytes are there.
 */
#ifndef SAMPLE_H
#define SAMPLE_H

#include <stddef.h>
#include <stdint.h>

typedef enum sample_type {
    SAMPLE_NONE, /* no type (a name the reader does not know) */
    SAMPLE_I8,
    SAMPLE_U8,
    SAMPLE_I16,
    SAMPLE_U16,
    SAMPLE_I32,
    SAMPLE_U32,
    SAMPLE_F32,
    SAMPLE_F64
} sample_type;

/* Bytes of a sample (0 for SAMPLE_NONE). */
size_t sample_size(sample_type t);
/* The n (1..8) bytes at p as an unsigned integer. */
uint64_t sample_uint(const unsigned char *p, size_t n, int big);
/* The sample of type t at p. */
double sample_get(const unsigned char *p, sample_type t, int big);
/* The binary32 at p, bit for bit (NaN payloads included). */
void sample_f32(const unsigned char *p, int big, float *out);

#endif
