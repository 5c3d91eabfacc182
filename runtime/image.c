/* image.c — allocation of the float RGBA image. Codecs live in png.c, pnm.c;
 * image_save/image_load dispatch by extension in image_io.c. */
#include "image.h"
#include "rt_alloc.h"

#include <stdlib.h>
#include <string.h>

rt_code image_init(image *im, int w, int h, rt_error *e)
{
    im->w = im->h = 0;
    im->px = NULL;
    im->mem = NULL;
    im->src = NULL;
    if (w < 1 || h < 1)
        return rt_fail(e, RT_EINVAL, "image size %d×%d is empty", w, h);
    size_t n = rt_mul_size(rt_mul_size((size_t)w, (size_t)h), 4 * sizeof(float));
    if (n == 0)
        return rt_fail(e, RT_ENOMEM, "image size %d×%d is too large", w, h);
    im->px = rt_calloc_huge(1, n, &im->mem);
    if (!im->px)
        return rt_fail(e, RT_ENOMEM, "out of memory for a %d×%d image", w, h);
    im->w = w;
    im->h = h;
    return RT_OK;
}

void image_free(image *im)
{
    /* px NULL: nothing is owned (a decoder that failed early, an image whose
     * pixels were moved to another struct), whatever mem holds */
    if (im->src)
        im->src->destroy(im->src);
    if (im->px)
        rt_free(im->mem);
    im->src = NULL;
    im->px = NULL;
    im->mem = NULL;
    im->w = im->h = 0;
}

void image_ready(const image *im)
{
    if (!im->src)
        return;
    /* a cache fill: the image is not const where it was made (image_init) */
    image *m = (image *)im;
    m->src->rows(m->src, 0, m->h, m->px);
    m->src->destroy(m->src);
    m->src = NULL;
}

void image_rows(const image *im, int y0, int y1, float *out)
{
    if (im->src)
        im->src->rows(im->src, y0, y1, out);
    else
        memcpy(out, image_at(im, 0, y0), (size_t)(y1 - y0) * (size_t)im->w * 4 * sizeof(float));
}

rt_code image_copy(image *dst, const image *src, rt_error *e)
{
    image_ready(src);
    rt_code c = image_init(dst, src->w, src->h, e);
    if (c)
        return c;
    memcpy(dst->px, src->px, (size_t)src->w * (size_t)src->h * 4 * sizeof(float));
    return RT_OK;
}
