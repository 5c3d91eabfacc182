/* tonemap.c — histogram to image (log density as in flam3's renderer; the
 * formulas are in tonemap.h). */
#include "tonemap.h"

#include <math.h>
#include <string.h>

/* The count of image pixel (x, y): the sum of its k×k bins. */
static uint64_t pixel_count(const hist2 *hs, int k, int x, int y)
{
    if (k == 1)
        return hs->count[(size_t)y * hs->w + (size_t)x];
    uint64_t c = 0;
    for (int dy = 0; dy < k; dy++)
        for (int dx = 0; dx < k; dx++)
            c += hs->count[(size_t)(y * k + dy) * hs->w + (size_t)(x * k + dx)];
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

rt_code tonemap_apply(const hist2 *hs, const tonemap_opts *o, image *im, rt_error *e)
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
    /* No copy of the histogram: pass 1 finds M, pass 2 sums each pixel's
     * k×k bins again (integer sums, and the colour sums in the same order,
     * so the result is the same as summing once into a buffer). Without
     * supersampling (k = 1) both passes run straight along the bins. */
    size_t npx = (size_t)im->w * (size_t)im->h;
    uint64_t mx = 0;
    if (k == 1) {
        const uint64_t *cnt = hs->count;
        for (size_t b = 0; b < npx; b++)
            mx = cnt[b] > mx ? cnt[b] : mx;
    } else {
        for (int y = 0; y < im->h; y++)
            for (int x = 0; x < im->w; x++) {
                uint64_t c = pixel_count(hs, k, x, y);
                if (c > mx)
                    mx = c;
            }
    }
    ramp grey = ramp_grey();
    const ramp *rp = o->ramp ? o->ramp : &grey;
    double lmx = log1p((double)mx);
    /* v depends on the count only: small counts (most pixels) read it from
     * a table filled with the same expression, and so (ramp colours) does
     * the pixel. */
    enum { NV = 4096 };
    double vt[NV];
    float ct[NV][4];
    size_t nv = mx < NV ? (size_t)mx + 1 : NV;
    for (size_t c = 1; c < nv; c++) {
        vt[c] = density(o->curve, c, mx, lmx, gamma, bright);
        if (o->colour == TONEMAP_RAMP)
            ramp_eval(rp, vt[c], ct[c]);
    }
    if (k == 1 && o->colour == TONEMAP_RAMP) { /* the common case, straight along the bins */
        const uint64_t *cnt = hs->count;
        float bg[4], *px = im->px;
        memcpy(bg, o->bg, sizeof bg);
        for (size_t b = 0; b < npx; b++, px += 4) {
            uint64_t c = cnt[b];
            if (c < nv) /* c = 0 (then also when M = 0): the background */
                memcpy(px, c ? ct[c] : bg, sizeof bg);
            else
                ramp_eval(rp, density(o->curve, c, mx, lmx, gamma, bright), px);
        }
        return RT_OK;
    }
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++) {
            float *px = image_at(im, x, y);
            uint64_t c = pixel_count(hs, k, x, y);
            if (c == 0 || mx == 0) {
                for (int ch = 0; ch < 4; ch++)
                    px[ch] = o->bg[ch];
                continue;
            }
            if (o->colour == TONEMAP_RAMP && c < nv) {
                for (int ch = 0; ch < 4; ch++)
                    px[ch] = ct[c][ch];
                continue;
            }
            double v = c < nv ? vt[c] : density(o->curve, c, mx, lmx, gamma, bright);
            if (o->colour == TONEMAP_RAMP) {
                ramp_eval(rp, v, px);
            } else {
                double cs[3] = {1, 1, 1};
                if (hs->csum)
                    pixel_csum(hs, k, x, y, cs);
                for (int ch = 0; ch < 3; ch++) {
                    double mean = hs->csum ? cs[ch] / (double)c : 1.0;
                    px[ch] = (float)(o->bg[ch] + (mean - o->bg[ch]) * v);
                }
                px[3] = (float)(o->bg[3] + (1 - o->bg[3]) * v);
            }
        }
    return RT_OK;
}
