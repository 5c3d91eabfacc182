/* tiles.c — mirror-symmetric tiles and tiled patterns (seed 003 §4-1). */
#include "tiles.h"

#include <string.h>

static void over(float *dst, const float *src)
{
    float a = src[3], b = dst[3] * (1 - a), oa = a + b;
    for (int c = 0; c < 3; c++)
        dst[c] = oa > 0 ? (src[c] * a + dst[c] * b) / oa : 0;
    dst[3] = oa;
}

rt_code tiles_symmetric(const image *src, int mirror, tiles_overlay rule, image *out, rt_error *e)
{
    if (mirror < 1 || mirror > 3)
        return rt_fail(e, RT_EINVAL, "tile mirror %d (expected left-right, top-bottom or both)",
                       mirror);
    if (rule != TILES_MAX && rule != TILES_MEAN && rule != TILES_OVER)
        return rt_fail(e, RT_EINVAL, "tile overlay rule %d is unknown", (int)rule);
    rt_code code = image_init(out, src->w, src->h, e);
    if (code)
        return code;
    int w = src->w, h = src->h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            /* copies: original, LR mirror, TB mirror, both */
            const float *p[4] = {image_at(src, x, y), image_at(src, w - 1 - x, y),
                                 image_at(src, x, h - 1 - y), image_at(src, w - 1 - x, h - 1 - y)};
            float *o = image_at(out, x, y);
            if (rule == TILES_OVER) {
                memcpy(o, p[0], 4 * sizeof *o);
                for (int k = 1; k < 4; k++)
                    if ((k & mirror) == k)
                        over(o, p[k]);
                continue;
            }
            for (int c = 0; c < 4; c++) {
                float v;
                if (mirror == 3) {
                    if (rule == TILES_MAX) {
                        float a = p[0][c] > p[1][c] ? p[0][c] : p[1][c];
                        float b = p[2][c] > p[3][c] ? p[2][c] : p[3][c];
                        v = a > b ? a : b;
                    } else {
                        v = ((p[0][c] + p[1][c]) + (p[2][c] + p[3][c])) * 0.25f;
                    }
                } else {
                    const float *q = p[mirror]; /* 1: LR, 2: TB */
                    v = rule == TILES_MAX ? (p[0][c] > q[c] ? p[0][c] : q[c])
                                          : (p[0][c] + q[c]) * 0.5f;
                }
                o[c] = v;
            }
        }
    return RT_OK;
}

rt_code tiles_fill(const image *tile, int w, int h, int mirrored, image *out, rt_error *e)
{
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "tiled canvas %d×%d is empty", w, h);
    rt_code code = image_init(out, w, h, e);
    if (code)
        return code;
    int tw = tile->w, th = tile->h;
    for (int y = 0; y < h; y++) {
        int ty = y % th;
        if (mirrored && (y / th) % 2)
            ty = th - 1 - ty;
        for (int x = 0; x < w; x++) {
            int tx = x % tw;
            if (mirrored && (x / tw) % 2)
                tx = tw - 1 - tx;
            memcpy(image_at(out, x, y), image_at(tile, tx, ty), 4 * sizeof(float));
        }
    }
    return RT_OK;
}
