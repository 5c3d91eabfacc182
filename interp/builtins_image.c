/* builtins_image.c — the image type in the language, and generic save/load. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "apng.h"
#include "builtin.h"
#include "eval.h"
#include "fileio.h"
#include "image.h"
#include "lexer.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "shard.h"

static void image_destroy(void *p)
{
    image *im = p;
    lang_image_discard(im);
}

static void image_summary(const void *p, bytebuf *out)
{
    const image *im = p;
    bytebuf_printf(out, "image %d×%d RGBA", im->w, im->h);
}

static int image_get(interp *I, const void *p, const char *name, value *out)
{
    const image *im = p;
    (void)I;
    if (strcmp(name, "width") == 0)
        *out = val_num(im->w);
    else if (strcmp(name, "height") == 0)
        *out = val_num(im->h);
    else
        return 1;
    return 0;
}

static int image_arith(interp *I, int op, value a, value b, value *out);
static int image_save_hook(interp *I, const void *p, const char *path, value opts);

const obj_class lang_image_class = {
    .name = "image",
    .destroy = image_destroy,
    .summary = image_summary,
    .arith = image_arith,
    .get = image_get,
    .save = image_save_hook,
};

int lang_image_new(interp *I, int w, int h, image **out)
{
    *out = NULL;
    if (w < 1 || h < 1)
        return err_at(I, NULL, ERR_VALUE, "image size %d×%d must be at least 1×1", w, h);
    if ((double)w * (double)h > I->lim.max_pixels)
        return err_at(I, NULL, ERR_LIMIT,
                      "image of %d×%d pixels exceeds the limit of %.0f pixels (raise it with --max-pixels)",
                      w, h, I->lim.max_pixels);
    char what[96];
    snprintf(what, sizeof what, "image of %d×%d pixels", w, h);
    if (mem_precheck(I, (double)w * h * 4 * sizeof(float), what))
        return -1;
    image *im = mem_alloc(I, sizeof *im);
    if (!im)
        return -1;
    rt_error e;
    if (image_init(im, w, h, &e)) {
        mem_free(I, im);
        return mem_engine_error(I, what, e.msg);
    }
    *out = im;
    return 0;
}

int lang_image_value(interp *I, image *im, value *out)
{
    *out = val_obj(I, &lang_image_class, im);
    return out->k == V_NIL ? -1 : 0;
}

void lang_image_discard(image *im)
{
    if (im) {
        image_free(im);
        rt_free(im);
    }
}

int lang_image_finish(interp *I, image *im, rt_code c, const rt_error *e, const char *what, value *out)
{
    if (c) {
        lang_image_discard(im);
        return lang_rt_error(I, c, e, what);
    }
    return lang_image_value(I, im, out);
}

image *lang_as_image(value v)
{
    if (v.k != V_OBJ || AS_OBJ(v)->cls != &lang_image_class)
        return NULL;
    /* every reader of an image's pixels comes here: pending pixels (a chaos
     * render's tone map, tonemap.h) are made now; save reaches the codecs
     * through the class's hook without this, so a PNG is encoded band by band */
    image *im = AS_OBJ(v)->payload;
    image_ready(im);
    return im;
}

int lang_get_colour(interp *I, value v, float rgba[4], const char *what)
{
    if (v.k == V_NUM) {
        if (!isfinite(v.u.n))
            return err_value(I, v, ERR_VALUE, "%s must be a finite number, got %s", what,
                          isnan(v.u.n) ? "nan" : v.u.n < 0 ? "-inf" : "inf");
        rgba[0] = rgba[1] = rgba[2] = (float)v.u.n;
        rgba[3] = 1;
        return 0;
    }
    if (v.k == V_LIST && (AS_LIST(v)->n == 3 || AS_LIST(v)->n == 4)) {
        double c[4] = {0, 0, 0, 1};
        if (builtin_get_vec(I, v, c, AS_LIST(v)->n, what))
            return -1;
        for (int i = 0; i < 4; i++)
            rgba[i] = (float)c[i];
        return 0;
    }
    if (v.k == V_STR && AS_STR(v)->s[0] == '#' && (AS_STR(v)->len == 7 || AS_STR(v)->len == 9)) {
        unsigned x[4] = {0, 0, 0, 255};
        int n = (int)(AS_STR(v)->len - 1) / 2;
        for (int i = 0; i < n; i++) {
            char hex[3] = {AS_STR(v)->s[1 + 2 * i], AS_STR(v)->s[2 + 2 * i], 0};
            char *end;
            x[i] = (unsigned)strtoul(hex, &end, 16);
            if (*end)
                return err_value(I, v, ERR_VALUE, "%s: \"%s\" is not a colour like \"#ff8800\"", what,
                              AS_STR(v)->s);
        }
        for (int i = 0; i < 4; i++)
            rgba[i] = (float)x[i] / 255.0f;
        return 0;
    }
    return err_value(I, v, ERR_TYPE,
                  "%s must be a colour: a grey level, [r, g, b], [r, g, b, a] or \"#rrggbb\", got %s", what,
                  val_type_name(v));
}

/* ---- arithmetic: element-wise on pixels (all four channels) --------------------- */

static float fop(int op, float x, float y)
{
    switch (op) {
    case T_PLUS: return x + y;
    case T_MINUS: return x - y;
    case T_STAR: return x * y;
    case T_SLASH: return x / y;
    case T_CARET: return powf(x, y);
    case OP_MAX: return x > y ? x : y;
    case OP_MIN: return x < y ? x : y;
    default: return x;
    }
}

static double u_round(double v) { return floor(v + 0.5); } /* as round() of a number */
static double u_sign(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }

/* The math function of one argument that op names (sqrt … sign), NULL for
 * any other op. */
static double (*unary_fn(int op))(double)
{
    switch (op) {
    case OP_SQRT: return sqrt;
    case OP_EXP: return exp;
    case OP_LOG: return log;
    case OP_SIN: return sin;
    case OP_COS: return cos;
    case OP_TAN: return tan;
    case OP_ASIN: return asin;
    case OP_ACOS: return acos;
    case OP_ATAN: return atan;
    case OP_ABS: return fabs;
    case OP_FLOOR: return floor;
    case OP_CEIL: return ceil;
    case OP_ROUND: return u_round;
    case OP_SIGN: return u_sign;
    default: return NULL;
    }
}

/* sqrt(im) … sign(im): the function of each colour channel, computed as for
 * a number (in double) and rounded to the pixel's float; alpha is kept, as
 * the operators keep the first image's. */
static int image_unary(interp *I, double (*f)(double), const image *x, value *out)
{
    image *r;
    if (lang_image_new(I, x->w, x->h, &r))
        return -1;
    size_t n = (size_t)x->w * (size_t)x->h * 4;
    for (size_t i = 0; i < n; i += 4) {
        for (int c = 0; c < 3; c++)
            r->px[i + c] = (float)f((double)x->px[i + c]);
        r->px[i + 3] = x->px[i + 3];
    }
    return lang_image_value(I, r, out) ? -1 : 1;
}

static int image_arith(interp *I, int op, value a, value b, value *out)
{
    image *x = lang_as_image(a), *y = lang_as_image(b);
    double (*f)(double) = unary_fn(op);
    if (f && x && b.k == V_NIL)
        return image_unary(I, f, x, out);
    int binary = op == T_PLUS || op == T_MINUS || op == T_STAR || op == T_SLASH || op == T_CARET ||
                 op == OP_MAX || op == OP_MIN;
    if (op == OP_NEG && x && b.k == V_NIL) {
        b = val_num(-1);
        op = T_STAR;
        binary = 1;
    }
    if (!binary)
        return 0;
    if ((x && !y && b.k != V_NUM) || (y && !x && a.k != V_NUM))
        return 0;
    if (x && y && (x->w != y->w || x->h != y->h))
        return err_at(I, NULL, ERR_VALUE, "images of different sizes (%d×%d and %d×%d)", x->w, x->h,
                      y->w, y->h);
    image *r;
    const image *shape = x ? x : y;
    if (lang_image_new(I, shape->w, shape->h, &r))
        return -1;
    /* Colour channels combine; alpha is the first image operand's. */
    size_t n = (size_t)shape->w * (size_t)shape->h * 4;
    const image *alpha = x ? x : y;
    for (size_t i = 0; i < n; i++) {
        if ((i & 3) == 3) {
            r->px[i] = alpha->px[i];
            continue;
        }
        float p = x ? x->px[i] : (float)a.u.n;
        float q = y ? y->px[i] : (float)b.u.n;
        r->px[i] = fop(op, p, q);
    }
    return lang_image_value(I, r, out) ? -1 : 1;
}

/* ---- builtins ---------------------------------------------------------------------- */

static int b_image(interp *I, value *a, int n, value *out)
{
    (void)n;
    int w, h;
    float c[4];
    image *im;
    if (lang_arg_size2(I, a[0], &w, &h, "image: size") || lang_get_colour(I, a[1], c, "image: colour") ||
        lang_image_new(I, w, h, &im))
        return -1;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        memcpy(im->px + 4 * i, c, sizeof c);
    return lang_image_value(I, im, out);
}

/* gradient(size, from, to, angle): linear blend along the direction `angle`
 * (degrees, 0 = left to right, 90 = bottom to top), from pixel centres. */
static int b_gradient(interp *I, value *a, int n, value *out)
{
    (void)n;
    int w, h;
    float c0[4], c1[4];
    image *im;
    if (lang_arg_size2(I, a[0], &w, &h, "gradient: size") || lang_get_colour(I, a[1], c0, "gradient: from") ||
        lang_get_colour(I, a[2], c1, "gradient: to"))
        return -1;
    double ang = a[3].u.n * 3.14159265358979323846 / 180.0;
    double dx = cos(ang), dy = sin(ang);
    /* project the corners to find the range of t */
    double tmin = 1e300, tmax = -1e300;
    for (int k = 0; k < 4; k++) {
        double x = (k & 1) ? w - 0.5 : 0.5, y = (k & 2) ? h - 0.5 : 0.5;
        double t = x * dx - y * dy;
        tmin = t < tmin ? t : tmin;
        tmax = t > tmax ? t : tmax;
    }
    if (lang_image_new(I, w, h, &im))
        return -1;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double t = tmax > tmin ? ((x + 0.5) * dx - (y + 0.5) * dy - tmin) / (tmax - tmin) : 0;
            float *p = image_at(im, x, y);
            for (int c = 0; c < 4; c++)
                p[c] = (float)(c0[c] + (c1[c] - c0[c]) * t);
        }
    return lang_image_value(I, im, out);
}

static int b_checker(interp *I, value *a, int n, value *out)
{
    (void)n;
    int w, h;
    long cell;
    float c0[4], c1[4];
    image *im;
    if (lang_arg_size2(I, a[0], &w, &h, "checker: size") || builtin_get_int(I, a[1], 1, 1000000, &cell, "checker: cell") ||
        lang_get_colour(I, a[2], c0, "checker: a") || lang_get_colour(I, a[3], c1, "checker: b") ||
        lang_image_new(I, w, h, &im))
        return -1;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            memcpy(image_at(im, x, y), ((x / cell + y / cell) & 1) ? c1 : c0, sizeof c0);
    return lang_image_value(I, im, out);
}

static int b_pixel(interp *I, value *a, int n, value *out)
{
    (void)n;
    image *im = lang_as_image(a[0]);
    long x, y;
    if (builtin_get_int(I, a[1], 0, im->w - 1, &x, "pixel: x") || builtin_get_int(I, a[2], 0, im->h - 1, &y, "pixel: y"))
        return -1;
    const float *p = image_at(im, (int)x, (int)y);
    value l = val_list(I, 4);
    if (l.k == V_NIL)
        return -1;
    for (int c = 0; c < 4; c++)
        if (val_list_push(I, AS_LIST(l), val_num(p[c]))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

static int b_load(interp *I, value *a, int n, value *out)
{
    (void)n;
    image *im = mem_alloc(I, sizeof *im);
    if (!im)
        return -1;
    char path[4096];
    if (lang_script_path(I, a[0], path, sizeof path, "load")) {
        mem_free(I, im);
        return -1;
    }
    rt_error e;
    /* the decoder checks the declared size against --max-pixels and the
     * memory left before it allocates (rt_check_pixels, rt_check_bytes) */
    rt_code c = image_load(im, path, &e);
    if (c) {
        mem_free(I, im);
        return lang_rt_error(I, c, &e, "load");
    }
    if ((double)im->w * im->h > I->lim.max_pixels) {
        image_destroy(im);
        return err_at(I, NULL, ERR_LIMIT, "load: image exceeds the pixel limit (raise it with --max-pixels)");
    }
    return lang_image_value(I, im, out);
}

/* `%f` in an output path becomes the frame number (--frames; 0 outside it),
 * zero-padded to I->frame_width digits (cfdg's convention; a negative frame
 * keeps its '-' before the padded digits: -03); `%%` is one '%'. Any other
 * '%' is an error, and so is a path without %f when several frames would
 * each overwrite it. */
static int expand_frame(interp *I, const char *p, size_t n, char *buf, size_t size, size_t *outn)
{
    size_t k = 0;
    int has_f = 0;
    for (size_t i = 0; i < n; i++) {
        char piece[32];
        size_t pl = 1;
        piece[0] = p[i];
        if (p[i] == '%') {
            char c = i + 1 < n ? p[i + 1] : 0;
            if (c == 'f') {
                long f = I->frame;
                int w = I->frame_width > 0 ? I->frame_width : 1;
                pl = (size_t)snprintf(piece, sizeof piece, "%s%0*lu", f < 0 ? "-" : "", w,
                                      f < 0 ? 0ul - (unsigned long)f : (unsigned long)f);
                has_f = 1;
            } else if (c != '%') {
                return err_at(I, NULL, ERR_VALUE,
                              "save: '%%%.*s' in the output path '%.*s' is neither %%f (the frame number) nor "
                              "%%%% (a percent sign)",
                              c ? 1 : 0, &p[i + 1], (int)n, p);
            }
            i++;
        }
        if (k + pl >= size)
            return err_at(I, NULL, ERR_IO, "save: path too long: '%.40s…'", p);
        memcpy(buf + k, piece, pl);
        k += pl;
    }
    if (I->frame_count >= 2 && !has_f)
        return err_at(I, NULL, ERR_VALUE, "save: output path '%.*s' has no %%f, every frame would overwrite it",
                      (int)n, p);
    buf[k] = 0;
    *outn = k;
    return 0;
}

int lang_output_path(interp *I, value path, char *buf, size_t size)
{
    if (AS_STR(path)->len == 0)
        return err_at(I, NULL, ERR_VALUE, "save: the file name is empty");
    if (!memchr(AS_STR(path)->s, '%', AS_STR(path)->len) && I->frame_count < 2)
        return lang_join_path(I, NULL, I->out_dir, AS_STR(path)->s, AS_STR(path)->len, buf, size, "save");
    char name[4096];
    size_t n = 0;
    if (expand_frame(I, AS_STR(path)->s, AS_STR(path)->len, name, sizeof name, &n))
        return -1;
    return lang_join_path(I, NULL, I->out_dir, name, n, buf, size, "save");
}

/* save(list_of_images, "x.png", {delay: MS, loop: N}): an animated PNG
 * (runtime/apng.h), the images its frames in order. */
static int save_animation(interp *I, value list, const char *path, value opts)
{
    if (contract_check_opts(I, opts,
                            "rec{delay: int[0,65535], loop: int[0,2147483647], bits: int{8,16}, channels: int[1,4]}",
                            "save"))
        return -1;
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "png") != 0)
        return err_arg(I, 1, ERR_VALUE, "save: a list of images is saved as an animated PNG (.png), not as .%s",
                       ext[0] ? ext : "(no extension)");
    const vlist *l = AS_LIST(list);
    if (l->n == 0)
        return err_arg(I, 0, ERR_VALUE, "save: the list of frames is empty (an animated PNG needs at least one)");
    for (size_t i = 0; i < l->n; i++) {
        const image *im = lang_as_image(l->items[i]), *first = lang_as_image(l->items[0]);
        if (!im)
            return err_item(I, list, i, ERR_TYPE, "save: frame %zu is %s, not an image", i + 1,
                            val_type_name(l->items[i]));
        if (im->w != first->w || im->h != first->h)
            return err_item(I, list, i, ERR_VALUE, "save: frame %zu is %d×%d, frame 1 is %d×%d: all frames must have "
                            "the same size", i + 1, im->w, im->h, first->w, first->h);
    }
    if (l->n > 1000000)
        return err_arg(I, 0, ERR_LIMIT, "save: %zu frames, more than an animated PNG of frac holds (1000000)", l->n);
    apng_opts ao = {APNG_DEFAULT_DELAY_MS, 0};
    int bits = 8, channels = 4;
    double x;
    if (lang_opt_num(I, opts, "delay", &x) == 1)
        ao.delay_ms = (int)x;
    if (lang_opt_num(I, opts, "loop", &x) == 1)
        ao.loop = (long)x;
    if (lang_opt_num(I, opts, "bits", &x) == 1)
        bits = (int)x;
    if (lang_opt_num(I, opts, "channels", &x) == 1)
        channels = (int)x;
    const image **ims = mem_calloc(I, l->n, sizeof *ims);
    if (!ims)
        return -1;
    for (size_t i = 0; i < l->n; i++)
        ims[i] = lang_as_image(l->items[i]);
    rt_error e;
    rt_code c = apng_save(ims, (int)l->n, bits, channels, &ao, path, &e);
    mem_free(I, ims);
    return c ? lang_rt_error(I, c, &e, "save") : 0;
}

static int b_save(interp *I, value *a, int n, value *out)
{
    (void)n;
    value v = a[0];
    if (v.k == V_LIST) {
        char path[4096];
        if (lang_output_path(I, a[1], path, sizeof path) || save_animation(I, v, path, a[2]))
            return -1;
        if (!I->quiet && !I->is_repl)
            fprintf(stderr, "wrote %s (%zu frames)\n", path, AS_LIST(v)->n);
        *out = a[0];
        val_ref(*out);
        return 0;
    }
    if (v.k != V_OBJ || !AS_OBJ(v)->cls->save)
        return err_at(I, NULL, ERR_TYPE, "save: cannot save %s (images, volumes, meshes… can be saved)",
                      val_type_name(v));
    char path[4096];
    if (lang_output_path(I, a[1], path, sizeof path))
        return -1;
    if (shard_skip_save(I)) { /* a shard writes only its part file (shard.h) */
        *out = a[0];
        val_ref(*out);
        return 0;
    }
    if (AS_OBJ(v)->cls->save(I, AS_OBJ(v)->payload, path, a[2]))
        return -1;
    if (!I->quiet && !I->is_repl)
        fprintf(stderr, "wrote %s\n", path);
    *out = a[0];
    val_ref(*out);
    return 0;
}

static int image_save_hook(interp *I, const void *p, const char *path, value opts)
{
    image_save_opts o = {0, 0};
    if (contract_check_opts(I, opts, "rec{bits: int{8,16}, channels: int[1,4]}", "save"))
        return -1;
    double x;
    if (lang_opt_num(I, opts, "bits", &x) == 1)
        o.bits = (int)x;
    if (lang_opt_num(I, opts, "channels", &x) == 1)
        o.channels = (int)x;
    rt_error e;
    rt_code c = image_save(p, path, &o, &e);
    if (c) /* lang_rt_error: an encoder buffer refused by the allocation hook is a memory error */
        return lang_rt_error(I, c, &e, "save");
    return 0;
}

/* hstack(a, b, …) / vstack(…): images side by side (top-aligned) or one
 * above the other (left-aligned), with `gap` pixels of `background`. */
static int stack(interp *I, value *a, int n, value *out, int horizontal)
{
    const char *name = horizontal ? "hstack" : "vstack";
    value *items = a;
    size_t count = (size_t)n;
    if (n == 1 && a[0].k == V_LIST) {
        items = AS_LIST(a[0])->items;
        count = AS_LIST(a[0])->n;
    }
    value gapv = a[n], bgv = a[n + 1];
    long gap;
    float bg[4];
    if (builtin_get_int(I, gapv, 0, 100000, &gap, horizontal ? "hstack: gap" : "vstack: gap") ||
        lang_get_colour(I, bgv, bg, horizontal ? "hstack: background" : "vstack: background"))
        return -1;
    if (count == 0)
        return err_at(I, NULL, ERR_VALUE, "%s: give at least one image", name);
    double W = 0, H = 0;
    for (size_t i = 0; i < count; i++) {
        image *im = lang_as_image(items[i]);
        if (!im)
            return err_at(I, NULL, ERR_TYPE, "%s: item %zu is %s, not an image", name, i + 1,
                          val_type_name(items[i]));
        if (horizontal) {
            W += im->w + (i ? gap : 0);
            H = im->h > H ? im->h : H;
        } else {
            H += im->h + (i ? gap : 0);
            W = im->w > W ? im->w : W;
        }
    }
    if (W > 1e6 || H > 1e6)
        return err_at(I, NULL, ERR_LIMIT, "%s: the result would be %.0f×%.0f pixels", name, W, H);
    image *r;
    if (lang_image_new(I, (int)W, (int)H, &r))
        return -1;
    for (size_t p = 0; p < (size_t)W * (size_t)H; p++)
        memcpy(r->px + 4 * p, bg, sizeof bg);
    int x0 = 0, y0 = 0;
    for (size_t i = 0; i < count; i++) {
        image *im = lang_as_image(items[i]);
        for (int y = 0; y < im->h; y++)
            memcpy(image_at(r, x0, y0 + y), image_at(im, 0, y), (size_t)im->w * 4 * sizeof(float));
        if (horizontal)
            x0 += im->w + (int)gap;
        else
            y0 += im->h + (int)gap;
    }
    return lang_image_value(I, r, out);
}

static int b_hstack(interp *I, value *a, int n, value *out) { return stack(I, a, n, out, 1); }
static int b_vstack(interp *I, value *a, int n, value *out) { return stack(I, a, n, out, 0); }

static const bparam p_stack[] = {{"gap", "int[0,100000]", "0"}, {"background", TY_COLOUR, "0"}};
static const bparam p_image[] = {{"size", TY_SIZE, NULL}, {"colour", TY_COLOUR, "0"}};
static const bparam p_gradient[] = {{"size", TY_SIZE, NULL}, {"from", TY_COLOUR, "0"}, {"to", TY_COLOUR, "1"},
                                    {"angle", "num", "0"}};
static const bparam p_checker[] = {{"size", TY_SIZE, NULL}, {"cell", "int>=1", "8"}, {"a", TY_COLOUR, "0"},
                                   {"b", TY_COLOUR, "1"}};
static const bparam p_pixel[] = {{"image", "image", NULL}, {"x", "int", NULL}, {"y", "int", NULL}};
static const bparam p_load[] = {{"path", "str", NULL}};
static const bparam p_save[] = {{"value", "any", NULL}, {"path", "str", NULL}, {"options", "rec", "nil"}};

static const builtin image_builtins[] = {
    BUILTIN("image", b_image, p_image, "A new image of size [w, h] (or n for n×n) filled with a colour."),
    BUILTIN("gradient", b_gradient, p_gradient,
            "A linear colour gradient across an image; angle in degrees (0: left to right, 90: bottom to top)."),
    BUILTIN("checker", b_checker, p_checker, "A checkerboard of two colours with square cells of `cell` pixels."),
    BUILTIN_VAR("hstack", b_hstack, p_stack,
                "Images side by side, top-aligned (several images or one list), `gap` pixels of `background` between them."),
    BUILTIN_VAR("vstack", b_vstack, p_stack, "Images one above the other, left-aligned, like hstack."),
    BUILTIN("pixel", b_pixel, p_pixel, "The [r, g, b, a] of pixel (x, y); (0, 0) is the top-left."),
    BUILTIN("load", b_load, p_load, "Load an image (PNG, PPM/PGM, PFM), relative to the script's folder."),
    BUILTIN("save", b_save, p_save,
            "Save an image (.png .ppm .pgm .pfm), volume or mesh; the extension picks the format. Relative paths go under --out-dir. Options: {bits: 16, channels: 3}."),
};

int builtin_image_init(interp *I)
{
    return BUILTIN_REGISTER(I, image_builtins);
}
