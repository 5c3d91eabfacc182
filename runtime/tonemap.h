/* tonemap.h — from a hit-count histogram (hist.h) to an image (image.h).
 *
 * Supersampling: the histogram may be k times the image size on each axis
 * (hist w = k·image w and h = k·image h, k >= 1 an integer); each pixel
 * first sums the counts (and colour sums) of its k×k bins, then is mapped.
 * With counts C per pixel and M = the largest C over the image:
 *
 *   density     TONEMAP_LOG:    v = log(1 + C) / log(1 + M)      (flam3-style)
 *               TONEMAP_LINEAR: v = C / M
 *   gamma       v ← v^(1/gamma)            (gamma > 0; 1 = none)
 *   brightness  v ← min(1, brightness · v)  (brightness > 0)
 *   (M = 0, an empty histogram: every pixel is background.)
 *
 * Colour of a pixel with C > 0:
 *   TONEMAP_RAMP  pixel = ramp(v) (the ramp, or grey, as the density colour map)
 *   TONEMAP_MEAN  pixel = bg + (mean − bg)·v, mean = colour sum / C (the mean
 *                 colour of the hits, from csum; white if the histogram has none)
 *   alpha: RAMP takes the ramp's alpha; MEAN blends alpha as bg.a + (1 − bg.a)·v.
 * Pixels with C = 0 are the background colour bg (RGBA).
 */
#ifndef TONEMAP_H
#define TONEMAP_H

#include "hist.h"
#include "image.h"
#include "ramp.h"
#include "rt.h"

typedef enum tonemap_curve { TONEMAP_LOG, TONEMAP_LINEAR } tonemap_curve;
typedef enum tonemap_colour { TONEMAP_RAMP, TONEMAP_MEAN } tonemap_colour;

typedef struct tonemap_opts {
    tonemap_curve curve;
    tonemap_colour colour;
    double gamma;       /* 0 = 1 */
    double brightness;  /* 0 = 1 */
    float bg[4];
    const ramp *ramp;   /* TONEMAP_RAMP; NULL = grey */
} tonemap_opts;

/* Map hs into im (already initialised to the output size, overwritten).
 * Reads hs in place (two passes: the maximum, then the pixels); allocates
 * nothing. */
rt_code tonemap_apply(const hist2 *hs, const tonemap_opts *o, image *im, rt_error *e);
/* The same map with im's pixels left pending (image.h): the maximum pass
 * and the checks run now, the pixels when they are read (image_rows, e.g.
 * png_encode band by band) or made ready (image_ready), with the same
 * floats as tonemap_apply. On success im owns hs's arrays (hs is left
 * empty; hist2_free on it is harmless) and frees them when the pixels are
 * made or the image is freed; on failure hs and im are unchanged. The cost
 * of a render saved as PNG without ever being inspected: no 16 B/pixel
 * float image is written, the bins (8 B/pixel) are held instead. */
rt_code tonemap_defer(hist2 *hs, const tonemap_opts *o, image *im, rt_error *e);

#endif
