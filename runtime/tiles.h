/* tiles.h — symmetric tiles and wallpaper patterns (seed 003 §4-1, Fig. 6–8).
 *
 * seed 003 makes a *tile* by overlaying a generated image with its
 * left–right and/or top–bottom mirror images, then repeats the tile across a
 * bitmap. (Table 5 of the paper lists the function-set orders of its six
 * example tiles; those are orders for fset.h, the tiling itself is here.)
 *
 * tiles_symmetric: mirror is TILES_LR, TILES_TB or both (TILES_LR|TILES_TB:
 * four copies). The overlay rule combines the copies per channel:
 *   TILES_MAX   the maximum (bright fractal on dark ground; the default);
 *   TILES_MEAN  the average, summed in mirror pairs ((a+b)+(c+d))/4;
 *   TILES_OVER  each mirror copy composited over the original by straight
 *               alpha ("over"), in the order LR, TB, both.
 * MAX and MEAN are symmetric operations, so the tile is exactly symmetric:
 * pixel (x, y) equals (w−1−x, y) (LR) and (x, h−1−y) (TB), bit for bit.
 * OVER is not commutative and gives exact symmetry only where the copies are
 * opaque or transparent; use it for the look of layered prints.
 *
 * tiles_fill: a w×h canvas with the tile repeated from the top-left corner:
 * out(x, y) = tile(x mod tw, y mod th). With mirrored set, tiles in odd
 * columns are flipped left–right and in odd rows top–bottom, so any tile
 * joins seamlessly (period 2·tw × 2·th).
 */
#ifndef TILES_H
#define TILES_H

#include "image.h"
#include "rt.h"

enum { TILES_LR = 1, TILES_TB = 2 };

typedef enum tiles_overlay { TILES_MAX, TILES_MEAN, TILES_OVER } tiles_overlay;

/* out is allocated here (same size as src); free with image_free. */
rt_code tiles_symmetric(const image *src, int mirror, tiles_overlay rule, image *out, rt_error *e);
/* out is allocated here (w×h). */
rt_code tiles_fill(const image *tile, int w, int h, int mirrored, image *out, rt_error *e);

#endif
