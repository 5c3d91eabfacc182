/* termview.h — preview an image in a text terminal.
 *
 * termview_render appends to a bytebuf the text that draws `im` in a
 * terminal, `cols` character cells wide:
 *
 *   - Size. The image is resampled to cols × P pixels with
 *     P = round(h * cols / w) (at least 1; halves round up), which keeps the
 *     aspect ratio because a character cell is about twice as tall as wide
 *     and holds two pixels stacked vertically. The output has ceil(P / 2)
 *     lines; when P is odd the pixel grid is made even by a last pixel row
 *     of background colour. With max_rows > 0 and more lines than that, the
 *     width is reduced to floor(2 * max_rows * w / h) columns (at least 1)
 *     so the whole picture fits; only when even one column is too tall is P
 *     cut to 2 * max_rows (and the aspect lost). Pass cols = min(terminal
 *     width, image width) to avoid enlarging small images (enlarging works:
 *     it repeats pixels).
 *   - Resampling is a box filter: each output pixel is the area-weighted
 *     mean of the source pixels its rectangle covers (exact fractional
 *     coverage at the edges, integer weights, so the result is exact and
 *     deterministic).
 *   - Alpha. Colours and alpha are clamped to [0, 1] (NaN counts as 0) and
 *     each source pixel is composited over the background (bg, black when
 *     the options are zero-initialised) before averaging, with straight
 *     (non-premultiplied) alpha as in PNG: c = a * rgb + (1 - a) * bg.
 *   - Colour mode (color != 0): every cell is U+2580 UPPER HALF BLOCK "▀"
 *     with foreground = upper pixel (ESC[38;2;R;G;Bm) and background = lower
 *     pixel (ESC[48;2;R;G;Bm), 8-bit values round(v * 255). A colour code is
 *     written only when it differs from the previous cell's on the same
 *     line (each line starts with both codes). Every line ends with ESC[0m
 *     and '\n'.
 *   - Greyscale mode (color == 0): no escape sequences at all. One character
 *     per cell from the ramp " .:-=+*#%@" (dark to light, suited to a dark
 *     terminal background) for the mean luminance of the cell's two pixels,
 *     Y = 0.2126 R + 0.7152 G + 0.0722 B (Rec. 709 weights, on the values as
 *     stored), index round(Y * 9). Every line ends with '\n'.
 *
 * The output depends only on the inputs. termview_env_color decides the
 * mode the usual way: colour unless NO_COLOR is set to a non-empty value
 * (no-color.org) or TERM is unset, empty or "dumb".
 */
#ifndef TERMVIEW_H
#define TERMVIEW_H

#include "fileio.h"
#include "image.h"
#include "rt.h"

typedef struct termview_opts {
    int cols;     /* width in character cells, >= 1 */
    int max_rows; /* at most this many lines (0: no limit) */
    int color;    /* 1: 24-bit colour half blocks, 0: greyscale characters */
    float bg[3];  /* background under transparent pixels (linear RGB in [0, 1]) */
} termview_opts;

/* The output size for a w×h image: *cols cells wide, *pixel_rows resampled
 * pixel rows (before padding to even), so ceil(*pixel_rows / 2) lines. */
void termview_size(int w, int h, const termview_opts *o, int *cols, int *pixel_rows);

/* Append the preview to out. RT_EINVAL for an empty image or cols < 1 or
 * max_rows < 0; RT_ENOMEM if memory runs out. */
rt_code termview_render(const image *im, const termview_opts *o, bytebuf *out, rt_error *e);

/* Render and write to fd (all of it, retrying short writes). */
rt_code termview_write(int fd, const image *im, const termview_opts *o, rt_error *e);

/* 1 if colour should be used given getenv("NO_COLOR") and getenv("TERM"). */
int termview_env_color(const char *no_color, const char *term);

#endif
