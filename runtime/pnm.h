/* pnm.h — Netpbm binary grey/colour images (P5 PGM, P6 PPM) and the Portable
 * Float Map (PFM: "PF" RGB, "Pf" grey).
 *
 * PGM/PPM (netpbm pgm(5), ppm(5)): header "P5" or "P6", width, height and
 * maxval as decimal numbers separated by whitespace, '#' comments (to the end
 * of the line) allowed wherever whitespace is, then exactly one whitespace
 * byte and the samples, row by row from the top: one byte each if maxval <
 * 256, else two bytes big-endian. maxval is 1..65535; a sample above maxval
 * is an error. Decoding gives value / maxval, grey replicated to R, G, B and
 * alpha 1. pnm_encode writes maxval 255 (bits 8) or 65535 (bits 16) with
 * round(clamp(v) * maxval); channels 1 writes P5 with the Rec. 709 luminance
 * (png_luma), channels 3 writes P6; alpha is dropped.
 *
 * PFM (as defined by Paul Debevec's HDRShop and used by most renderers):
 * "PF" (3 channels) or "Pf" (1 channel), width and height, then a scale
 * whose sign gives the byte order (negative: little-endian, positive:
 * big-endian; its magnitude is ignored), one whitespace byte, then 32-bit
 * IEEE floats with rows stored bottom-to-top. Values are kept as they are
 * (outside [0, 1], negative, infinite). pfm_encode writes little-endian
 * ("-1.0"), channels 3 (PF) or 1 (Pf, luminance).
 *
 * Malformed input gives RT_EFORMAT naming the problem ("PPM maxval 70000 is
 * out of range (expected 1..65535)", "PGM data are truncated (10 of 12
 * bytes)", ...). Trailing bytes after the pixel data are ignored.
 */
#ifndef PNM_H
#define PNM_H

#include <stddef.h>

#include "fileio.h"
#include "image.h"
#include "rt.h"

typedef struct pnm_info {
    int w, h;
    int channels;    /* 1 (P5, Pf) or 3 (P6, PF) */
    unsigned maxval; /* PGM/PPM; 0 for PFM */
    int little_endian; /* PFM byte order */
} pnm_info;

rt_code pnm_encode(const image *im, int bits, int channels, bytebuf *out, rt_error *e);
rt_code pnm_decode(const unsigned char *d, size_t n, image *im, pnm_info *info, rt_error *e);

rt_code pfm_encode(const image *im, int channels, bytebuf *out, rt_error *e);
rt_code pfm_decode(const unsigned char *d, size_t n, image *im, pnm_info *info, rt_error *e);

#endif
