/* image.h — the image type every engine renders into.
 *
 * Pixels are float RGBA, 4 floats per pixel, row-major, top row first
 * (y = 0 is the top of the picture). Colour values are nominally in [0, 1]
 * and linear in the sense that no transfer function is applied on save:
 * a value v is written to an 8-bit file as round(clamp(v) * 255). Values
 * outside [0, 1] are kept (PFM saves them) and clamped on integer output.
 */
#ifndef IMAGE_H
#define IMAGE_H

#include <stddef.h>

#include "rt.h"

typedef struct image_src image_src;

typedef struct image {
    int w, h;
    float *px; /* w * h * 4 floats; NULL: no pixels (mem is then ignored) */
    void *mem; /* the block px lies in: big images start on a 2 MiB boundary
                * (rt_calloc_huge), so filling one faults in huge pages only */
    image_src *src; /* NULL, or the pixels are pending (see below) */
} image;

/* Pending pixels. A renderer whose last stage is a pure function of data it
 * holds (tonemap.h: a histogram) may leave the pixels to be computed when
 * they are needed: px is allocated but not written (fresh zero pages, not
 * yet faulted in) and src computes any band of rows. image_rows reads a band
 * either way, so an encoder can run band by band without the full float
 * image ever being written (png_encode does); image_ready fills px from src
 * and drops src, after which the image is an ordinary one. Both give the
 * same floats. rows cannot fail: all checks and allocations happen when
 * the source is made. */
struct image_src {
    /* rows [y0, y1) into out (w * 4 floats per row) */
    void (*rows)(const image_src *s, int y0, int y1, float *out);
    void (*destroy)(image_src *s); /* frees s and what it holds */
};

/* Allocate a w×h image filled with transparent black. w, h >= 1. */
rt_code image_init(image *im, int w, int h, rt_error *e);
void image_free(image *im);
/* Fill the pixels of an image whose pixels are pending (nothing otherwise).
 * The pixel values do not change, so it takes a const image: every reader of
 * px calls it first (codecs, the interpreter's image values). */
void image_ready(const image *im);
/* Rows [y0, y1) into out (w * 4 floats per row), pending or not. */
void image_rows(const image *im, int y0, int y1, float *out);
/* Deep copy (the copy is ready). */
rt_code image_copy(image *dst, const image *src, rt_error *e);

static inline float *image_at(const image *im, int x, int y)
{
    return im->px + ((size_t)y * (size_t)im->w + (size_t)x) * 4;
}

/* Save by file extension: .png (8-bit RGBA unless opts say otherwise),
 * .ppm, .pgm, .pfm. Written to a temporary file beside path, then renamed. */
typedef struct image_save_opts {
    int bits;      /* 8 or 16 (PNG, PGM/PPM); 0 = 8 */
    int channels;  /* 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA (PNG); 0 = 4 for PNG, 3 for PPM */
} image_save_opts;

rt_code image_save(const image *im, const char *path, const image_save_opts *opts, rt_error *e);
/* Load .png, .ppm/.pgm (P5/P6, 8 or 16 bit) and .pfm by content. */
rt_code image_load(image *im, const char *path, rt_error *e);
/* What a loader starts with: im emptied (0 × 0, px NULL) and the file read
 * whole into *d (at most max bytes; rt_free it). */
rt_code image_read_file(const char *path, size_t max, image *im, unsigned char **d, size_t *n, rt_error *e);

#endif
