/* draw.h — antialiased drawing of shapes (polylines, polygons, points) into
 * an image, and SVG export of the same shapes.
 *
 * A view maps the plane (y up) to pixels (y down, pixel (i, j) covering
 * [i, i+1) × [j, j+1), its centre at (i + ½, j + ½)):
 *     px = ox + sx·x,   py = oy − sy·y.
 * draw_view_fit builds one from world bounds lo..hi; with keep_aspect the
 * scale is the same on both axes (the smaller one) and the bounds are
 * centred, otherwise each axis is stretched to the image. Shapes in 3-D are
 * drawn by their x, y (an orthographic view down z).
 *
 * Drawing (draw_shape) is coverage based and deterministic: every segment of
 * width `width` pixels gives each pixel the coverage clamp(width/2 + ½ − d)
 * where d is the distance from the pixel centre to the segment; a point is a
 * disc of `radius` pixels the same way; a closed polygon with `fill` set is
 * filled by the even–odd rule with 4 sub-scanlines per pixel and exact
 * horizontal span coverage. The coverages of one call are combined with max
 * (so joints and overlaps are not darkened twice, and the result does not
 * depend on drawing order), then the colour is composited once over the
 * image: c ← c·(1 − α·cov) + colour·α·cov for the colour channels and
 * a ← a + (1 − a)·α·cov for alpha (straight alpha). One-vertex polylines
 * are points; longer ones are stroked (if width > 0).
 *
 * SVG export (draw_svg) writes the same shapes in pixel coordinates
 * (viewBox 0 0 w h), numbers printed with a fixed number of decimals (and
 * "-0" written as "0") so the output is byte-stable.
 */
#ifndef DRAW_H
#define DRAW_H

#include "detiter.h"
#include "fileio.h"
#include "image.h"
#include "rt.h"

typedef struct draw_view {
    int w, h;
    double sx, sy, ox, oy;
} draw_view;

rt_code draw_view_fit(draw_view *v, int w, int h, const double lo[2], const double hi[2],
                      int keep_aspect, rt_error *e);

static inline void draw_to_px(const draw_view *v, double x, double y, double *px, double *py)
{
    *px = v->ox + v->sx * x;
    *py = v->oy - v->sy * y;
}

/* Set every pixel to rgba. */
void draw_clear(image *im, const float rgba[4]);

typedef struct draw_style {
    float color[4]; /* RGBA, straight alpha */
    double width;   /* stroke width in pixels; 0: no stroke */
    double radius;  /* point radius in pixels */
    int fill;       /* fill closed polygons */
} draw_style;

/* The view's w, h must equal the image's. */
rt_code draw_shape(image *im, const draw_view *v, const detiter_shape *s, const draw_style *st,
                   rt_error *e);

/* Stroke one polyline of n vertices xy[2n] (closed: the last joins the
 * first) whose vertices carry colours rgba[4n]: segment i has the mean of
 * its two end colours, each pixel takes the colour of the segment that
 * covers it most (coverage as for draw_shape; of equal ones the first) and
 * that coverage, then one composite over the image as above with
 * α = clamp(alpha, 0, 1). */
rt_code draw_polyline_rgba(image *im, const draw_view *v, size_t n, const double *xy, const float *rgba, int closed,
                           double width, rt_error *e);

/* Append an SVG document to b: an optional background rectangle (bg may be
 * NULL), then the shape with the style (fill only if st->fill). precision:
 * decimals for coordinates, 0 .. 9. */
rt_code draw_svg(bytebuf *b, const draw_view *v, const detiter_shape *s, const draw_style *st,
                 const float *bg, int precision, rt_error *e);
/* The same with the fill in its own colour fill_rgba (NULL: st->color);
 * points are discs of st->color when there is a stroke, as draw() paints
 * them over the fill. */
rt_code draw_svg_fill(bytebuf *b, const draw_view *v, const detiter_shape *s, const draw_style *st,
                      const float *fill_rgba, const float *bg, int precision, rt_error *e);

#endif
