/* apng.h — animated PNG (APNG 1.0, the Mozilla specification; registered
 * with the PNG group as the acTL / fcTL / fdAT chunks of PNG 3rd edition),
 * on top of our PNG encoder (png.h) and deflate (deflate.h).
 *
 * An APNG is a PNG whose IDAT is the first frame, so a viewer without APNG
 * shows that frame. Layout written here:
 *
 *   signature, IHDR, acTL, [PLTE, tRNS], fcTL #0, IDAT…,
 *   fcTL #1, fdAT #2…, fcTL #k, fdAT #k+1…, …, IEND
 *
 * acTL holds the frame count and the number of plays (0: forever). Each
 * fcTL (26 bytes: sequence number, width, height, x and y offset, delay
 * numerator and denominator, dispose_op, blend_op) describes the frame whose
 * data follows: here always the whole canvas at (0, 0), delay delay_ms/1000
 * s, dispose_op 0 (APNG_DISPOSE_OP_NONE) and blend_op 0
 * (APNG_BLEND_OP_SOURCE: the frame replaces the canvas, transparent pixels
 * included). fdAT is a 4-byte sequence number followed by the same zlib
 * data an IDAT would hold. One sequence counter, starting at 0, numbers the
 * fcTL and fdAT chunks in file order. Identical frames give identical bytes.
 *
 * apng_assemble builds the file from n complete PNG files in memory (what
 * `frac apng` reads): their image data streams are copied unchanged, not
 * decoded and re-encoded, so each frame keeps its exact samples. Every
 * input is checked first (it must decode: png_decode) and all must have the
 * same IHDR (size, bit depth, colour type, interlacing) and, for palette
 * images, the same PLTE and tRNS; names[i] (may be NULL) names input i in
 * messages ("b.png is 16-bit RGBA 8×8, the first frame a.png is 8-bit RGB
 * 8×8: all frames must have the same size and format"). Other chunks of the
 * inputs (text, gamma…) are left out.
 *
 * apng_encode encodes n images with png_encode (bits 8 or 16, channels 1 to
 * 4 as there) and assembles them. apng_save is apng_encode plus
 * fileio_write_atomic: nothing is written unless the whole file is ready.
 */
#ifndef APNG_H
#define APNG_H

#include <stddef.h>

#include "fileio.h"
#include "image.h"
#include "rt.h"

#define APNG_DEFAULT_DELAY_MS 40 /* 25 frames per second */
#define APNG_MAX_DELAY_MS 65535  /* the delay numerator is 16 bits */
#define APNG_MAX_LOOP 2147483647 /* num_plays is a PNG four-byte integer, < 2^31 */

typedef struct apng_opts {
    int delay_ms; /* 0..APNG_MAX_DELAY_MS; each frame's delay */
    long loop;    /* plays: 0 forever, 1..APNG_MAX_LOOP */
} apng_opts;

rt_code apng_assemble(const unsigned char *const *pngs, const size_t *lens, int n, const char *const *names,
                      const apng_opts *o, bytebuf *out, rt_error *e);
rt_code apng_encode(const image *const *ims, int n, int bits, int channels, const apng_opts *o, bytebuf *out,
                    rt_error *e);
rt_code apng_save(const image *const *ims, int n, int bits, int channels, const apng_opts *o, const char *path,
                  rt_error *e);

#endif
