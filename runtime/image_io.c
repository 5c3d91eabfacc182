/* image_io.c — image_save / image_load (declared in image.h): choose the
 * codec by file extension when saving and by content (signature) when
 * loading. The codecs are png.c and pnm.c. */
#include <stdlib.h>
#include <string.h>

#include "image.h"
#include "rt_alloc.h"
#include "fileio.h"
#include "png.h"
#include "pnm.h"

#define IMAGE_MAX_FILE ((size_t)0xFFFFFFFFu) /* files of 4 GiB and more are refused */

rt_code image_save(const image *im, const char *path, const image_save_opts *opts, rt_error *e)
{
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    int bits = opts && opts->bits ? opts->bits : 8;
    int ch = opts ? opts->channels : 0;
    bytebuf b;
    bytebuf_init(&b);
    rt_code c;
    if (!strcmp(ext, "png")) {
        c = png_encode(im, bits, ch ? ch : 4, &b, e);
    } else if (!strcmp(ext, "ppm") || !strcmp(ext, "pgm")) {
        int want = ext[1] == 'p' ? 3 : 1;
        if (ch && ch != want)
            return rt_fail(e, RT_EINVAL, "a .%s file holds %d channel%s, not %d", ext, want,
                           want == 1 ? "" : "s", ch);
        c = pnm_encode(im, bits, want, &b, e);
    } else if (!strcmp(ext, "pfm")) {
        if (ch && ch != 1 && ch != 3)
            return rt_fail(e, RT_EINVAL, "a .pfm file holds 1 or 3 channels, not %d", ch);
        if (opts && opts->bits && opts->bits != 32)
            return rt_fail(e, RT_EINVAL, "a .pfm file holds 32-bit floats, not %d-bit samples",
                           opts->bits);
        c = pfm_encode(im, ch ? ch : 3, &b, e);
    } else {
        if (!ext[0])
            return rt_fail(e, RT_EINVAL,
                           "cannot tell the image format of '%s': no file extension (supported: "
                           ".png, .ppm, .pgm, .pfm)",
                           path);
        return rt_fail(e, RT_EINVAL,
                       "unsupported image extension '.%s' (supported: .png, .ppm, .pgm, .pfm)",
                       ext);
    }
    if (!c)
        c = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return c;
}

rt_code image_read_file(const char *path, size_t max, image *im, unsigned char **d, size_t *n, rt_error *e)
{
    im->w = im->h = 0;
    im->px = NULL;
    im->src = NULL;
    return fileio_read_all(path, max, d, n, e);
}

rt_code image_load(image *im, const char *path, rt_error *e)
{
    unsigned char *d;
    size_t n;
    rt_code c = image_read_file(path, IMAGE_MAX_FILE, im, &d, &n, e);
    if (c)
        return c;
    if (n >= 4 && d[0] == 0x89 && d[1] == 'P' && d[2] == 'N' && d[3] == 'G')
        c = png_decode(d, n, im, NULL, e);
    else if (n >= 2 && d[0] == 'P' && (d[1] == '5' || d[1] == '6'))
        c = pnm_decode(d, n, im, NULL, e);
    else if (n >= 2 && d[0] == 'P' && (d[1] == 'F' || d[1] == 'f'))
        c = pfm_decode(d, n, im, NULL, e);
    else
        c = rt_fail(e, RT_EFORMAT, "'%s' is not a PNG, PPM/PGM (P5/P6) or PFM image", path);
    if (c && c != RT_ENOMEM && e && !strstr(e->msg, path)) {
        char m[sizeof e->msg];
        memcpy(m, e->msg, sizeof m);
        rt_fail(e, c, "'%s': %s", path, m);
    }
    rt_free(d);
    return c;
}
