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
    if (im->px)
        rt_free(im->mem);
    im->px = NULL;
    im->mem = NULL;
    im->w = im->h = 0;
}

rt_code image_copy(image *dst, const image *src, rt_error *e)
{
    rt_code c = image_init(dst, src->w, src->h, e);
    if (c)
        return c;
    memcpy(dst->px, src->px, (size_t)src->w * (size_t)src->h * 4 * sizeof(float));
    return RT_OK;
}
