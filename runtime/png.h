/* png.h — PNG encoder and decoder (PNG specification, ISO/IEC 15948 / W3C
 * PNG 2nd edition), on top of our own deflate (deflate.h).
 *
 * Encoding. png_encode converts a float RGBA image to 8- or 16-bit samples
 * with round(clamp(v, 0, 1) * maxval) and writes a PNG with only IHDR, IDAT
 * and IEND (no time or gamma chunks), so identical pixels always give
 * identical bytes; when a recipe is set (provenance.h) a tEXt Software and
 * an iTXt frac:recipe chunk follow IHDR. channels selects the colour type:
 *   1  grey        (colour type 0)  grey = Rec. 709 luminance of R, G, B
 *   2  grey+alpha  (colour type 4)
 *   3  RGB         (colour type 2)  alpha is dropped (not composited)
 *   4  RGBA        (colour type 6)
 * Each row gets the filter (None, Sub, Up, Average, Paeth) whose output has
 * the smallest sum of absolute values as signed bytes (the heuristic of the
 * PNG specification §12.8, as libpng uses it); ties go to the lower type.
 * The filtered rows are deflated at PNG_DEFAULT_LEVEL = 2 (deflate.h: lazy
 * matching over chains of 16 positions that share 4 bytes). On the
 * benchmark images (bench/README_png.md) it runs at about the speed of
 * zlib's level 2 and gives files within a few per cent of zlib's level 6,
 * smaller on noisy and 16-bit images; png_encode_samples takes any level.
 *
 * png_encode_samples is the lower layer: rows of big-endian samples exactly
 * as PNG stores them (w * channels * bits / 8 bytes per row, top row first,
 * no filter byte) and a deflate level (0..9, see deflate.h; png_encode uses
 * PNG_DEFAULT_LEVEL). If filtered is not NULL the filtered stream (the exact
 * bytes given to deflate) is appended to it as well (for the benchmark).
 * png_save is png_encode plus fileio_write_atomic.
 *
 * Decoding. png_decode accepts every standard PNG: colour types 0, 2, 3, 4,
 * 6 with all their bit depths (1, 2, 4, 8, 16), tRNS transparency, Adam7
 * interlacing and all five filters. Ancillary chunks are skipped, but the
 * CRC of every chunk is checked. The result is a float RGBA image with
 * value / maxval per sample (palette entries / 255), grey replicated to
 * R, G, B, and alpha 1 where the file has none (0 for pixels matching the
 * tRNS colour). info (may be NULL) receives the header fields; png_read_info
 * reads only the signature and IHDR (e.g. to learn the bit depth).
 * Every malformed file gives RT_EFORMAT with a message naming the problem:
 * bad signature, CRC mismatch in a named chunk, missing or misplaced IHDR /
 * PLTE / IDAT / IEND, truncated chunk, invalid size, colour type or bit
 * depth, invalid filter type in a row, palette index out of range, image
 * data too short or too long, and the inflate errors of deflate.h.
 *
 * png_sample and png_luma are the conversions used above, shared with the
 * PNM writer so all integer formats quantise the same way.
 */
#ifndef PNG_H
#define PNG_H

#include <stddef.h>

#include "fileio.h"
#include "image.h"
#include "rt.h"

#define PNG_DEFAULT_LEVEL 2

typedef struct png_info {
    int w, h;
    int bit_depth;  /* 1, 2, 4, 8 or 16 */
    int color_type; /* 0 grey, 2 RGB, 3 palette, 4 grey+alpha, 6 RGBA */
    int interlace;  /* 0 none, 1 Adam7 */
    int channels;   /* samples per pixel in the file: 1, 3, 1, 2, 4 */
    int has_trns;   /* a tRNS chunk was present */
} png_info;

rt_code png_encode(const image *im, int bits, int channels, bytebuf *out, rt_error *e);
rt_code png_encode_samples(const unsigned char *rows, int w, int h, int channels, int bits,
                           int level, bytebuf *out, bytebuf *filtered, rt_error *e);
rt_code png_save(const image *im, const char *path, int bits, int channels, rt_error *e);

/* One chunk: length, type, data, CRC-32 of type and data (§5.3); for
 * writers of other chunk sequences on top of this encoder (apng.c). */
void png_write_chunk(bytebuf *out, const char *type, const unsigned char *data, size_t len);

rt_code png_read_info(const unsigned char *data, size_t n, png_info *info, rt_error *e);
rt_code png_decode(const unsigned char *data, size_t n, image *im, png_info *info, rt_error *e);
rt_code png_load(const char *path, image *im, png_info *info, rt_error *e);

/* Append the provenance chunks (tEXt Software, iTXt frac:recipe; see
 * provenance.h) when a recipe is set, nothing otherwise. png_encode_samples
 * puts them right after IHDR; other PNG writers (APNG) should do the same. */
rt_code png_put_recipe(bytebuf *out, rt_error *e);

/* The first tEXt, zTXt or iTXt chunk whose keyword is `keyword`: its text
 * (inflated when compressed, at most max_len bytes) is appended to out and
 * *found set to 1; *found = 0 when there is none. Every chunk's CRC up to
 * it is checked. Used by `frac info` for the recipe (provenance.h). */
rt_code png_text(const unsigned char *data, size_t n, const char *keyword, size_t max_len,
                 bytebuf *out, int *found, rt_error *e);

/* round(clamp(v, 0, 1) * maxval); NaN gives 0. */
unsigned png_sample(float v, unsigned maxval);
/* 0.2126 R + 0.7152 G + 0.0722 B of an RGBA pixel (linear values). */
float png_luma(const float *px);

#endif
