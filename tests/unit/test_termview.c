/* test_termview.c — exact bytes of the terminal preview for small images.
 *
 * Every expected string below is written out by hand from the rules in
 * termview.h: cells are "▀" (E2 96 80) with ESC[38;2;R;G;Bm for the upper
 * pixel and ESC[48;2;R;G;Bm for the lower one, a code only when it changes
 * along the line, ESC[0m + '\n' at each line end; greyscale uses the ramp
 * " .:-=+*#%@" at round(9 * mean Rec. 709 luminance).
 */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "termview.h"

#define UP "\xe2\x96\x80"

static void set(image *im, int x, int y, float r, float g, float b, float a)
{
    float *p = image_at(im, x, y);
    p[0] = r;
    p[1] = g;
    p[2] = b;
    p[3] = a;
}

/* Render and compare with want; prints both, escaped, on mismatch. */
static void expect_render(const image *im, const termview_opts *o, const char *want, const char *what)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_error e = {0};
    rt_code rc = termview_render(im, o, &b, &e);
    bytebuf_byte(&b, 0);
    int ok = rc == RT_OK && b.len - 1 == strlen(want) && memcmp(b.data, want, strlen(want)) == 0;
    CHECK(ok, "%s: rc=%d %s", what, (int)rc, e.msg);
    if (!ok && rc == RT_OK) {
        fprintf(stderr, "  got:  ");
        for (size_t i = 0; i + 1 < b.len; i++)
            fprintf(stderr, b.data[i] == 0x1b ? "\\e" : b.data[i] == '\n' ? "\\n" : "%c", b.data[i]);
        fprintf(stderr, "\n  want: ");
        for (size_t i = 0; want[i]; i++)
            fprintf(stderr, want[i] == 0x1b ? "\\e" : want[i] == '\n' ? "\\n" : "%c", want[i]);
        fprintf(stderr, "\n");
    }
    bytebuf_free(&b);
}

static void test_2x2(void)
{
    image im;
    image_init(&im, 2, 2, NULL);
    set(&im, 0, 0, 1, 0, 0, 1); /* red    | green */
    set(&im, 1, 0, 0, 1, 0, 1); /* blue   | white */
    set(&im, 0, 1, 0, 0, 1, 1);
    set(&im, 1, 1, 1, 1, 1, 1);
    termview_opts o = {.cols = 2, .color = 1};
    expect_render(&im, &o,
                  "\x1b[38;2;255;0;0m\x1b[48;2;0;0;255m" UP
                  "\x1b[38;2;0;255;0m\x1b[48;2;255;255;255m" UP "\x1b[0m\n",
                  "2x2 at 2 columns: one line, two cells");
    /* greyscale: Y(red) = .2126 -> 1.91 -> 2; Y(blue) = .0722; mean .1424 -> 1.28 -> '.';
     * Y(green) = .7152, Y(white) = 1; mean .8576 -> 7.72 -> 8 '%' */
    o.color = 0;
    expect_render(&im, &o, ".%\n", "2x2 greyscale");
    /* one column: P = round(2*1/2) = 1 pixel row, the mean of all four:
     * red+green+blue+white = (2,2,2)/4 = .5 -> 128; the lower half is background */
    o.color = 1;
    o.cols = 1;
    expect_render(&im, &o, "\x1b[38;2;128;128;128m\x1b[48;2;0;0;0m" UP "\x1b[0m\n",
                  "2x2 at 1 column: one pixel row, padded");
    image_free(&im);
}

static void test_4x4_box(void)
{
    image im;
    image_init(&im, 4, 4, NULL);
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++) {
            set(&im, x, y, 0.2f, 0.4f, 0.6f, 1);                 /* TL block: constant */
            set(&im, x + 2, y, (x + y) % 2 ? 1.0f : 0.0f, 0,      /* TR: red/blue checker */
                (x + y) % 2 ? 0.0f : 1.0f, 1);
            set(&im, x, y + 2, 1, 1, 1, 0.5f);                    /* BL: half-transparent white */
        }
    set(&im, 2, 2, 0, 1, 0, 1); /* BR: two green, two fully transparent white */
    set(&im, 3, 2, 0, 1, 0, 1);
    set(&im, 2, 3, 1, 1, 1, 0);
    set(&im, 3, 3, 1, 1, 1, 0);
    termview_opts o = {.cols = 2, .color = 1};
    /* cols 2: P = round(4*2/4) = 2, one line; each pixel is the mean of a 2x2 block:
     * TL (.2,.4,.6) -> 51,102,153; TR (.5,0,.5) -> 128,0,128;
     * BL .5 over black -> 128,128,128; BR (0,.5,0) -> 0,128,0 */
    expect_render(&im, &o,
                  "\x1b[38;2;51;102;153m\x1b[48;2;128;128;128m" UP
                  "\x1b[38;2;128;0;128m\x1b[48;2;0;128;0m" UP "\x1b[0m\n",
                  "4x4 box-filtered to 2 columns");
    /* over a grey background .2 (51): BL = .5 + .5*.2 = .6 -> 153;
     * BR = (0,.5,0) + (.1,.1,.1) -> 26,153,26 (25.5 rounds up) */
    o.bg[0] = o.bg[1] = o.bg[2] = 0.2f;
    expect_render(&im, &o,
                  "\x1b[38;2;51;102;153m\x1b[48;2;153;153;153m" UP
                  "\x1b[38;2;128;0;128m\x1b[48;2;26;153;26m" UP "\x1b[0m\n",
                  "4x4 over a grey background");
    /* at full size: 4 columns, P = 4, two lines; first line upper row 0, lower row 1 */
    o.cols = 4;
    o.bg[0] = o.bg[1] = o.bg[2] = 0;
    expect_render(&im, &o,
                  "\x1b[38;2;51;102;153m\x1b[48;2;51;102;153m" UP UP
                  "\x1b[38;2;0;0;255m\x1b[48;2;255;0;0m" UP
                  "\x1b[38;2;255;0;0m\x1b[48;2;0;0;255m" UP "\x1b[0m\n"
                  "\x1b[38;2;128;128;128m\x1b[48;2;128;128;128m" UP UP
                  "\x1b[38;2;0;255;0m\x1b[48;2;0;0;0m" UP UP "\x1b[0m\n",
                  "4x4 at 4 columns, repeated codes elided");
    image_free(&im);
}

static void test_odd_and_fractional(void)
{
    image im;
    /* 2x3 at 2 columns: P = 3 pixel rows, two lines, the last lower half is background */
    image_init(&im, 2, 3, NULL);
    for (int x = 0; x < 2; x++) {
        set(&im, x, 0, 1, 0, 0, 1);
        set(&im, x, 1, 0, 1, 0, 1);
        set(&im, x, 2, 0, 0, 1, 1);
    }
    set(&im, 1, 2, 0.6f, 0.6f, 0.6f, 1);
    termview_opts o = {.cols = 2, .color = 1, .bg = {0.2f, 0.2f, 0.2f}};
    expect_render(&im, &o,
                  "\x1b[38;2;255;0;0m\x1b[48;2;0;255;0m" UP UP "\x1b[0m\n"
                  "\x1b[38;2;0;0;255m\x1b[48;2;51;51;51m" UP
                  "\x1b[38;2;153;153;153m" UP "\x1b[0m\n",
                  "odd height: padded with the background");
    /* greyscale of the same: line 1 mean(.2126,.7152) = .4639 -> 4.18 -> 4 '=';
     * line 2 col 0: mean(.0722, .2) = .1361 -> 1.22 -> '.'; col 1: mean(.6, .2) = .4 -> 3.6 -> 4 '=' */
    o.color = 0;
    expect_render(&im, &o, "==\n.=\n", "odd height greyscale");
    image_free(&im);

    /* 3x1 to 2 columns: column 0 = (2*v0 + v1)/3, column 1 = (v1 + 2*v2)/3;
     * P = round(1*2/3) = 1, so one line with a background lower half */
    image_init(&im, 3, 1, NULL);
    set(&im, 0, 0, 0.0f, 0.0f, 0.0f, 1);
    set(&im, 1, 0, 0.6f, 0.6f, 0.6f, 1);
    set(&im, 2, 0, 0.3f, 0.3f, 0.3f, 1);
    termview_opts o2 = {.cols = 2, .color = 1};
    expect_render(&im, &o2,
                  "\x1b[38;2;51;51;51m\x1b[48;2;0;0;0m" UP "\x1b[38;2;102;102;102m" UP "\x1b[0m\n",
                  "fractional box filter 3 -> 2");
    /* enlarging 3x1 to 6 columns: P = round(1*6/3) = 2; every pixel twice, one line */
    o2.cols = 6;
    expect_render(&im, &o2,
                  "\x1b[38;2;0;0;0m\x1b[48;2;0;0;0m" UP UP
                  "\x1b[38;2;153;153;153m\x1b[48;2;153;153;153m" UP UP
                  "\x1b[38;2;77;77;77m\x1b[48;2;77;77;77m" UP UP "\x1b[0m\n",
                  "enlarging repeats pixels");
    image_free(&im);
}

static void test_grey_ramp(void)
{
    image im;
    image_init(&im, 5, 2, NULL);
    /* per column, upper and lower the same colour: Y = .7152 (green) -> 6.44 -> '*',
     * .2126 (red) -> ':', .0722 (blue) -> '.', 1 (white) -> '@', transparent -> ' ' */
    float c[5][4] = {{0, 1, 0, 1}, {1, 0, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}, {1, 1, 1, 0}};
    for (int x = 0; x < 5; x++)
        for (int y = 0; y < 2; y++)
            set(&im, x, y, c[x][0], c[x][1], c[x][2], c[x][3]);
    termview_opts o = {.cols = 5, .color = 0};
    expect_render(&im, &o, "*:.@ \n", "greyscale ramp levels");
    /* out-of-range and NaN values are clamped: 7 -> 1, -3 -> 0, NaN -> 0 */
    set(&im, 0, 0, 7, 7, 7, 1);
    set(&im, 0, 1, 7, 7, 7, 1);
    set(&im, 1, 0, -3, -3, -3, 1);
    set(&im, 1, 1, NAN, NAN, NAN, 1);
    o.color = 1;
    o.cols = 2;
    /* now x0 white (7 clamped), x1 black (-3 and NaN), x2 blue, x3 white, x4 transparent.
     * cols 2 of 5: P = round(2*2/5) = 1 pixel row, the mean of both source rows.
     * Column 0 covers x in [0, 2.5): weights 2, 2, 1 (of 5) for x0, x1, x2:
     *   R = G = 2/5 = .4 -> 102, B = (2 + 1)/5 = .6 -> 153.
     * Column 1 covers [2.5, 5): weights 1, 2, 2 for x2, x3, x4:
     *   R = G = 2/5 -> 102, B = (1 + 2)/5 -> 153: the same, so no codes repeated */
    expect_render(&im, &o,
                  "\x1b[38;2;102;102;153m\x1b[48;2;0;0;0m" UP UP "\x1b[0m\n",
                  "clamping and non-integer box widths");
    image_free(&im);
}

static void test_size_and_errors(void)
{
    int c, p;
    termview_opts o = {.cols = 80};
    termview_size(1600, 900, &o, &c, &p);
    CHECK(c == 80 && p == 45, "1600x900 at 80: %d x %d (P = 80*900/1600 = 45)", c, p);
    o.max_rows = 10;
    termview_size(1600, 900, &o, &c, &p);
    CHECK(c == 35 && p == 20, "max 10 lines: cols floor(20*1600/900) = 35, P = round(19.69) = 20: %d x %d", c, p);
    o.max_rows = 2;
    o.cols = 10;
    termview_size(1, 100, &o, &c, &p);
    CHECK(c == 1 && p == 4, "1x100 under 2 lines: one column cut to 4 pixel rows: %d x %d", c, p);

    image im;
    image_init(&im, 2, 8, NULL);
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 2; x++)
            set(&im, x, y, y < 4 ? 1.0f : 0.0f, 0, 0, 1);
    /* 2x8 at 2 columns would be 8 pixel rows = 4 lines; max 2 lines -> 1 column,
     * P = round(8/2) = 4: upper two pixels red, lower two black */
    termview_opts t = {.cols = 2, .max_rows = 2, .color = 1};
    expect_render(&im, &t,
                  "\x1b[38;2;255;0;0m\x1b[48;2;255;0;0m" UP "\x1b[0m\n"
                  "\x1b[38;2;0;0;0m\x1b[48;2;0;0;0m" UP "\x1b[0m\n",
                  "max_rows shrinks the width");

    bytebuf b;
    bytebuf_init(&b);
    rt_error e = {0};
    t.cols = 0;
    CHECK(termview_render(&im, &t, &b, &e) == RT_EINVAL &&
              strcmp(e.msg, "preview: width must be at least 1 column (got 0)") == 0,
          "cols 0: %s", e.msg);
    t.cols = 3;
    t.max_rows = -1;
    CHECK(termview_render(&im, &t, &b, &e) == RT_EINVAL && strstr(e.msg, "got -1"), "max_rows -1: %s", e.msg);
    image empty = {0, 0, NULL, NULL, NULL};
    t.max_rows = 0;
    CHECK(termview_render(&empty, &t, &b, &e) == RT_EINVAL && strstr(e.msg, "empty"), "empty image: %s", e.msg);
    CHECK(b.len == 0, "nothing written on error");
    bytebuf_free(&b);
    image_free(&im);

    CHECK(termview_env_color(NULL, "xterm-256color") == 1, "colour by default");
    CHECK(termview_env_color("", "xterm") == 1, "empty NO_COLOR is ignored");
    CHECK(termview_env_color("1", "xterm") == 0, "NO_COLOR");
    CHECK(termview_env_color(NULL, "dumb") == 0, "TERM=dumb");
    CHECK(termview_env_color(NULL, NULL) == 0, "no TERM");
}

/* The greyscale output never contains an escape and has exactly cols
 * characters per line; a larger image checks the counts. */
static void test_large_shape(void)
{
    image im;
    image_init(&im, 64, 48, NULL);
    for (int y = 0; y < 48; y++)
        for (int x = 0; x < 64; x++)
            set(&im, x, y, (float)x / 63.0f, (float)y / 47.0f, 0.5f, 1);
    termview_opts o = {.cols = 20, .color = 0};
    bytebuf b;
    bytebuf_init(&b);
    CHECK(termview_render(&im, &o, &b, NULL) == RT_OK, "render");
    /* P = round(48*20/64) = 15 -> 8 lines of 20 characters */
    CHECK(b.len == 8 * 21, "greyscale size %zu", b.len);
    CHECK(!memchr(b.data, 0x1b, b.len), "no escapes in greyscale");
    bytebuf_free(&b);
    bytebuf_init(&b);
    o.color = 1;
    CHECK(termview_render(&im, &o, &b, NULL) == RT_OK, "render colour");
    size_t blocks = 0, lines = 0;
    for (size_t i = 0; i + 2 < b.len; i++)
        blocks += memcmp(b.data + i, UP, 3) == 0;
    for (size_t i = 0; i < b.len; i++)
        lines += b.data[i] == '\n';
    CHECK(blocks == 160 && lines == 8, "colour: %zu blocks, %zu lines", blocks, lines);
    bytebuf_free(&b);
    image_free(&im);
}

int main(void)
{
    test_2x2();
    test_4x4_box();
    test_odd_and_fractional();
    test_grey_ramp();
    test_size_and_errors();
    test_large_shape();
    return check_done("test_termview");
}
