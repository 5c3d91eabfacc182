/* tonemap.c — histogram to image (log density as in flam3's renderer; the
 * formulas are in tonemap.h). */
#include "tonemap.h"

#include <math.h>
#include <string.h>

#include "rt_alloc.h"

/* The count of image pixel (x, y): the sum of its k×k bins. */
static uint64_t pixel_count(const hist2 *hs, int k, int x, int y)
{
    if (k == 1)
        return hist2_get(hs, (size_t)y * hs->w + (size_t)x);
    uint64_t c = 0;
    for (int dy = 0; dy < k; dy++)
        for (int dx = 0; dx < k; dx++)
            c += hist2_get(hs, (size_t)(y * k + dy) * hs->w + (size_t)(x * k + dx));
    return c;
}

/* The colour sums of pixel (x, y), added bin by bin in row order. */
static void pixel_csum(const hist2 *hs, int k, int x, int y, double s[3])
{
    s[0] = s[1] = s[2] = 0;
    for (int dy = 0; dy < k; dy++)
        for (int dx = 0; dx < k; dx++) {
            size_t b = (size_t)(y * k + dy) * hs->w + (size_t)(x * k + dx);
            for (int ch = 0; ch < 3; ch++)
                s[ch] += hs->csum[3 * b + ch];
        }
}

/* The density value v of a pixel with count c > 0 (tonemap.h). */
static double density(tonemap_curve curve, uint64_t c, uint64_t mx, double lmx, double gamma,
                      double bright)
{
    double v = curve == TONEMAP_LOG ? log1p((double)c) / lmx : (double)c / (double)mx;
    if (gamma != 1)
        v = pow(v, 1 / gamma);
    v *= bright;
    return v > 1 ? 1 : v;
}

/* The largest of n counts. The OR of a block of counts is at least their
 * maximum, so a block whose OR is not above the maximum so far holds
 * nothing new: most blocks of a render (empty or sparse bins) cost only
 * the ORs, 2 counts per instruction with vector extensions (SSE2 on
 * x86-64, as png.c), instead of a compare and select per bin. */
#if defined(__GNUC__) || defined(__clang__)
typedef uint64_t tm_v2u64 __attribute__((vector_size(16)));
static uint64_t block_or(const uint64_t *c) /* 64 counts */
{
    tm_v2u64 o0, o1, o2, o3, v;
    memcpy(&o0, c, sizeof v), memcpy(&o1, c + 2, sizeof v);
    memcpy(&o2, c + 4, sizeof v), memcpy(&o3, c + 6, sizeof v);
    for (int i = 8; i < 64; i += 8) {
        memcpy(&v, c + i, sizeof v), o0 |= v;
        memcpy(&v, c + i + 2, sizeof v), o1 |= v;
        memcpy(&v, c + i + 4, sizeof v), o2 |= v;
        memcpy(&v, c + i + 6, sizeof v), o3 |= v;
    }
    v = (o0 | o1) | (o2 | o3);
    return v[0] | v[1];
}
#else
static uint64_t block_or(const uint64_t *c)
{
    uint64_t o = 0;
    for (int i = 0; i < 64; i++)
        o |= c[i];
    return o;
}
#endif

static uint64_t max_count(const uint64_t *c, size_t n)
{
    uint64_t mx = 0;
    size_t b = 0;
    for (; b + 64 <= n; b += 64)
        if (block_or(c + b) > mx)
            for (int i = 0; i < 64; i++)
                mx = c[b + i] > mx ? c[b + i] : mx;
    for (; b < n; b++)
        mx = c[b] > mx ? c[b] : mx;
    return mx;
}

/* The same for 32-bit counts (the compiler vectorises the plain OR loop). */
static uint32_t max_count32(const uint32_t *c, size_t n)
{
    uint32_t mx = 0;
    size_t b = 0;
    for (; b + 64 <= n; b += 64) {
        uint32_t o = 0;
        for (int i = 0; i < 64; i++)
            o |= c[b + i];
        if (o > mx)
            for (int i = 0; i < 64; i++)
                mx = c[b + i] > mx ? c[b + i] : mx;
    }
    for (; b < n; b++)
        mx = c[b] > mx ? c[b] : mx;
    return mx;
}

/* Everything the pixels depend on besides the bins, found once: the
 * checked options, k, M and the tables of small counts. tonemap_apply fills
 * every row from it at once; tonemap_defer keeps it (and the histogram) as
 * the image's pending source, filled band by band when read. */
enum { NV = 4096 };
typedef struct tm_plan {
    image_src src; /* first: the source is the plan */
    hist2 hs;      /* tonemap_defer: owned; tonemap_apply: the caller's, borrowed */
    tonemap_colour colour;
    tonemap_curve curve;
    float bg[4];
    ramp rp;
    int k, w;      /* k: bins per pixel on each axis; w: image width */
    uint64_t mx;
    double lmx, gamma, bright;
    size_t nv;
    double vt[NV];
    float ct[NV][4];
} tm_plan;

static rt_code plan_init(tm_plan *p, const hist2 *hs, const tonemap_opts *o, const image *im,
                         rt_error *e)
{
    if (im->w < 1 || im->h < 1 || hs->w % im->w || hs->h % im->h || hs->w / im->w != hs->h / im->h)
        return rt_fail(e, RT_EINVAL,
                       "histogram %d×%d is not a whole multiple k×k of the image %d×%d", hs->w,
                       hs->h, im->w, im->h);
    double gamma = o->gamma == 0 ? 1 : o->gamma;
    double bright = o->brightness == 0 ? 1 : o->brightness;
    if (!(gamma > 0))
        return rt_fail(e, RT_EINVAL, "gamma is %g (expected > 0)", gamma);
    if (!(bright > 0))
        return rt_fail(e, RT_EINVAL, "brightness is %g (expected > 0)", bright);
    int k = hs->w / im->w;
    /* No copy of the histogram: pass 1 finds M, the rows sum each pixel's
     * k×k bins again (integer sums, and the colour sums in the same order,
     * so the result is the same as summing once into a buffer). Without
     * supersampling (k = 1) both passes run straight along the bins. */
    size_t npx = (size_t)im->w * (size_t)im->h;
    uint64_t mx = 0;
    if (k == 1) {
        mx = hs->count32 ? max_count32(hs->count32, npx) : max_count(hs->count, npx);
    } else {
        for (int y = 0; y < im->h; y++)
            for (int x = 0; x < im->w; x++) {
                uint64_t c = pixel_count(hs, k, x, y);
                if (c > mx)
                    mx = c;
            }
    }
    p->hs = *hs;
    p->colour = o->colour;
    p->curve = o->curve;
    memcpy(p->bg, o->bg, sizeof p->bg);
    p->rp = o->ramp ? *o->ramp : ramp_grey();
    p->k = k;
    p->w = im->w;
    p->mx = mx;
    p->lmx = log1p((double)mx);
    p->gamma = gamma;
    p->bright = bright;
    /* v depends on the count only: small counts (most pixels) read it from
     * a table filled with the same expression, and so (ramp colours) does
     * the pixel. */
    p->nv = mx < NV ? (size_t)mx + 1 : NV;
    for (size_t c = 1; c < p->nv; c++) {
        p->vt[c] = density(p->curve, c, mx, p->lmx, gamma, bright);
        if (p->colour == TONEMAP_RAMP)
            ramp_eval(&p->rp, p->vt[c], p->ct[c]);
    }
    return RT_OK;
}

/* Image rows [y0, y1) into out (image_src.rows). */
static void plan_rows(const image_src *s, int y0, int y1, float *out)
{
    const tm_plan *p = (const tm_plan *)s;
    const hist2 *hs = &p->hs;
    int k = p->k, w = p->w;
    uint64_t mx = p->mx;
    size_t nv = p->nv;
    if (k == 1 && p->colour == TONEMAP_RAMP) { /* the common case, straight along the bins */
        /* one loop per count width; every value the loop reads in a local
         * (the build's -fno-strict-aliasing: a store into out would
         * otherwise reload p's fields) */
        size_t b0 = (size_t)y0 * (size_t)w, n = (size_t)(y1 - y0) * (size_t)w;
        float *px = out;
        if (hs->count32) {
            const uint32_t *cnt = hs->count32 + b0;
            for (size_t b = 0; b < n; b++, px += 4) {
                uint32_t c = cnt[b];
                if (c < nv) /* c = 0 (then also when M = 0): the background */
                    memcpy(px, c ? p->ct[c] : p->bg, sizeof p->bg);
                else
                    ramp_eval(&p->rp, density(p->curve, c, mx, p->lmx, p->gamma, p->bright), px);
            }
        } else {
            const uint64_t *cnt = hs->count + b0;
            for (size_t b = 0; b < n; b++, px += 4) {
                uint64_t c = cnt[b];
                if (c < nv)
                    memcpy(px, c ? p->ct[c] : p->bg, sizeof p->bg);
                else
                    ramp_eval(&p->rp, density(p->curve, c, mx, p->lmx, p->gamma, p->bright), px);
            }
        }
        return;
    }
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < w; x++) {
            float *px = out + ((size_t)(y - y0) * (size_t)w + (size_t)x) * 4;
            uint64_t c = pixel_count(hs, k, x, y);
            if (c == 0 || mx == 0) {
                for (int ch = 0; ch < 4; ch++)
                    px[ch] = p->bg[ch];
                continue;
            }
            if (p->colour == TONEMAP_RAMP && c < nv) {
                for (int ch = 0; ch < 4; ch++)
                    px[ch] = p->ct[c][ch];
                continue;
            }
            double v = c < nv ? p->vt[c] : density(p->curve, c, mx, p->lmx, p->gamma, p->bright);
            if (p->colour == TONEMAP_RAMP) {
                ramp_eval(&p->rp, v, px);
            } else {
                double cs[3] = {1, 1, 1};
                if (hs->csum)
                    pixel_csum(hs, k, x, y, cs);
                for (int ch = 0; ch < 3; ch++) {
                    double mean = hs->csum ? cs[ch] / (double)c : 1.0;
                    px[ch] = (float)(p->bg[ch] + (mean - p->bg[ch]) * v);
                }
                px[3] = (float)(p->bg[3] + (1 - p->bg[3]) * v);
            }
        }
}

static void plan_destroy(image_src *s)
{
    tm_plan *p = (tm_plan *)s;
    hist2_free(&p->hs);
    rt_free(p);
}

rt_code tonemap_apply(const hist2 *hs, const tonemap_opts *o, image *im, rt_error *e)
{
    tm_plan p;
    rt_code c = plan_init(&p, hs, o, im, e);
    if (c)
        return c;
    if (im->src) { /* im is overwritten: pixels it had pending are dropped */
        im->src->destroy(im->src);
        im->src = NULL;
    }
    plan_rows(&p.src, 0, im->h, im->px);
    return RT_OK;
}

rt_code tonemap_defer(hist2 *hs, const tonemap_opts *o, image *im, rt_error *e)
{
    tm_plan *p = rt_malloc(sizeof *p);
    if (!p)
        return rt_fail(e, RT_ENOMEM, "out of memory for a tone map");
    rt_code c = plan_init(p, hs, o, im, e);
    if (c) {
        rt_free(p);
        return c;
    }
    if (im->src)
        im->src->destroy(im->src);
    p->src.rows = plan_rows;
    p->src.destroy = plan_destroy;
    im->src = &p->src;
    hs->count = NULL; /* the plan owns the arrays now */
    hs->count32 = NULL;
    hs->csum = NULL;
    hs->mem_count = hs->mem_csum = NULL;
    hs->w = hs->h = 0;
    return RT_OK;
}
