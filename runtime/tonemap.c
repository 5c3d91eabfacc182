/* tonemap.c — histogram to image (log density as in flam3's renderer; the
 * formulas are in tonemap.h). */
#include "tonemap.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>

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
    size_t np = (size_t)im->w * (size_t)im->h;
    uint64_t *cnt = rt_malloc(sizeof *cnt * np);
    double *cs = hs->csum ? rt_malloc(sizeof *cs * 3 * np) : NULL;
    if (!cnt || (hs->csum && !cs)) {
        rt_free(cnt);
        rt_free(cs);
        return rt_fail(e, RT_ENOMEM, "out of memory for tone mapping");
    }
    uint64_t mx = 0;
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++) {
            size_t p = (size_t)y * im->w + x;
            uint64_t c = 0;
            double s[3] = {0, 0, 0};
            for (int dy = 0; dy < k; dy++)
                for (int dx = 0; dx < k; dx++) {
                    size_t b = (size_t)(y * k + dy) * hs->w + (size_t)(x * k + dx);
                    c += hs->count[b];
                    if (cs)
                        for (int ch = 0; ch < 3; ch++)
                            s[ch] += hs->csum[3 * b + ch];
                }
            cnt[p] = c;
            if (cs)
                for (int ch = 0; ch < 3; ch++)
                    cs[3 * p + ch] = s[ch];
            if (c > mx)
                mx = c;
        }
    ramp grey = ramp_grey();
    const ramp *rp = o->ramp ? o->ramp : &grey;
    double lmx = log1p((double)mx);
    for (size_t p = 0; p < np; p++) {
        float *px = im->px + 4 * p;
        uint64_t c = cnt[p];
        if (c == 0 || mx == 0) {
            for (int ch = 0; ch < 4; ch++)
                px[ch] = o->bg[ch];
            continue;
        }
        double v = o->curve == TONEMAP_LOG ? log1p((double)c) / lmx : (double)c / (double)mx;
        if (gamma != 1)
            v = pow(v, 1 / gamma);
        v *= bright;
        if (v > 1)
            v = 1;
        if (o->colour == TONEMAP_RAMP) {
            ramp_eval(rp, v, px);
        } else {
            for (int ch = 0; ch < 3; ch++) {
                double mean = cs ? cs[3 * p + ch] / (double)c : 1.0;
                px[ch] = (float)(o->bg[ch] + (mean - o->bg[ch]) * v);
            }
            px[3] = (float)(o->bg[3] + (1 - o->bg[3]) * v);
        }
    }
    rt_free(cnt);
    rt_free(cs);
    return RT_OK;
}
