/* bind_tiles.c — symmetric tiles and tilings in the language (seed 003 §4-1;
 * engine tiles.h).
 */
#include <string.h>

#include "builtin.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "tiles.h"

/* ---- tiles ----------------------------------------------------------------------------- */

static int wrap_image(interp *I, image *res, value *out)
{
    image *im = mem_alloc(I, sizeof *im);
    if (!im) {
        image_free(res);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    *im = *res;
    return lang_image_value(I, im, out);
}

/* tile(image, mirror, mode) */
static int b_tile(interp *I, value *a, int n, value *out)
{
    (void)n;
    const image *src = lang_as_image(a[0]);
    const char *m = AS_STR(a[1])->s, *md = AS_STR(a[2])->s;
    /* declared str{lr,tb,both} and str{max,mean,over} */
    int mirror = strcmp(m, "lr") == 0 ? TILES_LR : strcmp(m, "tb") == 0 ? TILES_TB : TILES_LR | TILES_TB;
    tiles_overlay rule = strcmp(md, "mean") == 0 ? TILES_MEAN : strcmp(md, "over") == 0 ? TILES_OVER : TILES_MAX;
    image res;
    rt_error e;
    rt_code c = tiles_symmetric(src, mirror, rule, &res, &e);
    if (c)
        return lang_rt_error(I, c, &e, "tile");
    return wrap_image(I, &res, out);
}

/* tiling(tile, size, mirrored) */
static int b_tiling(interp *I, value *a, int n, value *out)
{
    (void)n;
    const image *t = lang_as_image(a[0]);
    int w, h;
    if (lang_arg_size2(I, a[1], &w, &h, "tiling: size"))
        return -1;
    if ((double)w * h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT,
                      "image of %d×%d pixels exceeds the limit of %.0f pixels (raise it with --max-pixels)", w, h,
                      I->lim.max_pixels);
    image res;
    rt_error e;
    rt_code c = tiles_fill(t, w, h, val_truthy(a[2]), &res, &e);
    if (c)
        return lang_rt_error(I, c, &e, "tiling");
    return wrap_image(I, &res, out);
}

/* ---- registration ---------------------------------------------------------------------- */

static const bparam p_tile[] = {{"image", "image", NULL},
                                {"mirror", "str{lr,tb,both}", "\"both\""},
                                {"mode", "str{max,mean,over}", "\"max\""}};
static const bparam p_tiling[] = {{"tile", "image", NULL}, {"size", TY_SIZE, NULL}, {"mirrored", "bool", "false"}};

static const builtin tiles_builtins[] = {
    BUILTIN("tile", b_tile, p_tile,
            "A symmetric tile (seed 003 §4-1): the image overlaid with its left-right (\"lr\"), top-bottom (\"tb\") or both mirror images, combined by \"max\", \"mean\" or \"over\" (alpha compositing)."),
    BUILTIN("tiling", b_tiling, p_tiling,
            "A pattern: the tile repeated across an image of size pixels from the top-left corner; mirrored: true flips odd columns and rows so any tile joins seamlessly."),
};

int bind_tiles_init(interp *I)
{
    return BUILTIN_REGISTER(I, tiles_builtins);
}
