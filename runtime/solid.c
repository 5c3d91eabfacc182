/* solid.c — base functions and perturbation of seed 000 §3. */
#include "solid.h"

#include <math.h>
#include <string.h>

/* seed 000 eq. (6) */
double solid_layer_value(const solid_layer *l, double z)
{
    double d = fabs(z - l->c) - l->w / 2.0;
    return d > 0 ? exp(-l->alpha * d) : 1.0;
}

double solid_marble_value(const solid_marble *m, double z)
{
    double s = 0;
    for (int i = 0; i < m->n; i++)
        s += solid_layer_value(&m->layer[i], z);
    return s;
}

void solid_marble_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    (void)x;
    (void)y;
    const solid_marble *m = ctx;
    for (size_t i = 0; i < n; i++)
        out[i] = solid_marble_value(m, z[i]);
}

rt_code solid_marble_check(const solid_marble *m, rt_error *e)
{
    if (m->n < 1 || m->n > SOLID_MAX_LAYERS)
        return rt_fail(e, RT_EINVAL, "marble: %d layers (expected 1 .. %d)", m->n, SOLID_MAX_LAYERS);
    for (int i = 0; i < m->n; i++) {
        const solid_layer *l = &m->layer[i];
        if (!isfinite(l->c))
            return rt_fail(e, RT_EINVAL, "marble layer %d: centre c = %g is not a finite number", i + 1, l->c);
        if (!(l->w >= 0) || !isfinite(l->w))
            return rt_fail(e, RT_EINVAL, "marble layer %d: width w = %g must be >= 0", i + 1, l->w);
        if (!(l->alpha > 0) || !isfinite(l->alpha))
            return rt_fail(e, RT_EINVAL, "marble layer %d: decay alpha = %g must be > 0", i + 1, l->alpha);
    }
    return RT_OK;
}

/* Distance of p from the axis and the radial unit vector (0 on the axis). */
static double wood_radial(const solid_wood *w, const double p[3], double u[3])
{
    double a[3], d[3];
    double al = sqrt(w->axis[0] * w->axis[0] + w->axis[1] * w->axis[1] + w->axis[2] * w->axis[2]);
    for (int i = 0; i < 3; i++) {
        a[i] = w->axis[i] / al;
        d[i] = p[i] - w->origin[i];
    }
    double t = d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
    for (int i = 0; i < 3; i++)
        d[i] -= t * a[i];
    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; i++)
        u[i] = r > 0 ? d[i] / r : 0.0;
    return r;
}

double solid_wood_radius(const solid_wood *w, const double p[3])
{
    double u[3];
    return wood_radial(w, p, u);
}

double solid_wood_profile(const solid_wood *w, double r)
{
    double q = r / w->spacing;
    double f = q - floor(q);
    double v = 0.5 - 0.5 * cos(6.283185307179586 * f);
    if (v < 0)
        v = 0;
    return w->sharpness == 1.0 ? v : pow(v, w->sharpness);
}

void solid_wood_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                   double *out)
{
    const solid_wood *w = ctx;
    for (size_t i = 0; i < n; i++) {
        double p[3] = {x[i], y[i], z[i]};
        out[i] = solid_wood_profile(w, solid_wood_radius(w, p));
    }
}

rt_code solid_wood_check(const solid_wood *w, rt_error *e)
{
    for (int i = 0; i < 3; i++)
        if (!isfinite(w->origin[i]) || !isfinite(w->axis[i]))
            return rt_fail(e, RT_EINVAL, "wood: origin and axis must be finite numbers");
    if (w->axis[0] == 0 && w->axis[1] == 0 && w->axis[2] == 0)
        return rt_fail(e, RT_EINVAL, "wood: axis (0, 0, 0) has no direction");
    if (!(w->spacing > 0) || !isfinite(w->spacing))
        return rt_fail(e, RT_EINVAL, "wood: ring spacing = %g must be > 0", w->spacing);
    if (!(w->sharpness > 0) || !isfinite(w->sharpness))
        return rt_fail(e, RT_EINVAL, "wood: sharpness = %g must be > 0", w->sharpness);
    return RT_OK;
}

void solid_texture_default(solid_texture *t)
{
    memset(t, 0, sizeof *t);
    t->base = SOLID_BASE_MARBLE;
    t->marble.n = 1;
    t->marble.layer[0].c = 0.5;
    t->marble.layer[0].w = 0.1;
    t->marble.layer[0].alpha = 10;
    t->wood.axis[2] = 1;
    t->wood.spacing = 0.1;
    t->wood.sharpness = 1;
    for (int i = 0; i < 3; i++)
        t->d_hi[i] = 1;
    t->warp = SOLID_WARP_NONE;
}

rt_code solid_texture_check(const solid_texture *t, rt_error *e)
{
    static const char ax[3] = {'x', 'y', 'z'};
    rt_code rc;
    if (t->base == SOLID_BASE_MARBLE && (rc = solid_marble_check(&t->marble, e)))
        return rc;
    if ((t->base == SOLID_BASE_WOOD || t->warp == SOLID_WARP_RADIAL) && (rc = solid_wood_check(&t->wood, e)))
        return rc;
    if (t->base == SOLID_BASE_FIELD && !t->base_fn)
        return rt_fail(e, RT_EINVAL, "solid texture: base field missing");
    if (t->base < 0 || t->base > 2)
        return rt_fail(e, RT_EINVAL, "solid texture: base = %d is not marble (0), wood (1) or field (2)", t->base);
    if (t->warp < 0 || t->warp > 3)
        return rt_fail(e, RT_EINVAL, "solid texture: perturbation = %d is not none (0), z (1), radial (2) or user (3)",
                       t->warp);
    if (t->warp == SOLID_WARP_USER && !t->warp_fn)
        return rt_fail(e, RT_EINVAL, "solid texture: user perturbation function missing");
    if (!isfinite(t->k))
        return rt_fail(e, RT_EINVAL, "solid texture: k = %g is not a finite number", t->k);
    for (int i = 0; i < 3; i++)
        if (!(t->d_hi[i] > t->d_lo[i]) || !isfinite(t->d_lo[i]) || !isfinite(t->d_hi[i]))
            return rt_fail(e, RT_EINVAL, "solid texture: D box hi.%c = %g must be greater than lo.%c = %g", ax[i],
                           t->d_hi[i], ax[i], t->d_lo[i]);
    return RT_OK;
}

/* One block of at most RT_BLOCK points. */
static void eval_block(const solid_texture *t, size_t n, const double *x, const double *y, const double *z,
                       double *out)
{
    double d[RT_BLOCK], px[RT_BLOCK], py[RT_BLOCK], pz[RT_BLOCK];
    double dx[RT_BLOCK], dy[RT_BLOCK], dz[RT_BLOCK];
    if (t->d_fn && t->warp != SOLID_WARP_NONE) {
        for (size_t i = 0; i < n; i++) {
            dx[i] = (x[i] - t->d_lo[0]) / (t->d_hi[0] - t->d_lo[0]);
            dy[i] = (y[i] - t->d_lo[1]) / (t->d_hi[1] - t->d_lo[1]);
            dz[i] = (z[i] - t->d_lo[2]) / (t->d_hi[2] - t->d_lo[2]);
        }
        t->d_fn(t->d_ctx, n, dx, dy, dz, d);
    } else
        for (size_t i = 0; i < n; i++)
            d[i] = 0;
    switch (t->warp) {
    case SOLID_WARP_Z: /* seed 000 eq. (7) */
        for (size_t i = 0; i < n; i++) {
            px[i] = x[i];
            py[i] = y[i];
            pz[i] = z[i] + t->k * d[i];
        }
        break;
    case SOLID_WARP_RADIAL:
        for (size_t i = 0; i < n; i++) {
            double p[3] = {x[i], y[i], z[i]}, u[3];
            wood_radial(&t->wood, p, u);
            px[i] = x[i] + t->k * d[i] * u[0];
            py[i] = y[i] + t->k * d[i] * u[1];
            pz[i] = z[i] + t->k * d[i] * u[2];
        }
        break;
    case SOLID_WARP_USER:
        t->warp_fn(t->warp_ctx, n, x, y, z, d, px, py, pz);
        break;
    default:
        for (size_t i = 0; i < n; i++) {
            px[i] = x[i];
            py[i] = y[i];
            pz[i] = z[i];
        }
    }
    switch (t->base) {
    case SOLID_BASE_WOOD:
        solid_wood_fn(&t->wood, n, px, py, pz, out);
        break;
    case SOLID_BASE_FIELD:
        t->base_fn(t->base_ctx, n, px, py, pz, out);
        break;
    default:
        solid_marble_fn(&t->marble, n, px, py, pz, out);
    }
}

void solid_eval(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    const solid_texture *t = ctx;
    for (size_t b = 0; b < n; b += RT_BLOCK) {
        size_t len = n - b < RT_BLOCK ? n - b : RT_BLOCK;
        eval_block(t, len, x + b, y + b, z + b, out + b);
    }
}

void solid_color(const solid_texture *t, const ramp *r, size_t n, const double *x, const double *y,
                 const double *z, float *rgba)
{
    double v[RT_BLOCK];
    for (size_t b = 0; b < n; b += RT_BLOCK) {
        size_t len = n - b < RT_BLOCK ? n - b : RT_BLOCK;
        eval_block(t, len, x + b, y + b, z + b, v);
        for (size_t i = 0; i < len; i++)
            ramp_eval(r, v[i], rgba + 4 * (b + i));
    }
}

static ramp make_ramp(int n, const double *pos, const float (*c)[3])
{
    ramp r;
    memset(&r, 0, sizeof r);
    r.n = n;
    for (int i = 0; i < n; i++) {
        r.pos[i] = pos[i];
        for (int k = 0; k < 3; k++)
            r.rgba[i][k] = c[i][k];
        r.rgba[i][3] = 1;
    }
    return r;
}

ramp solid_ramp_marble(void)
{
    static const double pos[5] = {0.0, 0.3, 0.6, 0.85, 1.0};
    static const float c[5][3] = {{0.93f, 0.92f, 0.88f}, {0.86f, 0.85f, 0.82f}, {0.55f, 0.60f, 0.56f},
                                  {0.25f, 0.32f, 0.30f}, {0.12f, 0.16f, 0.15f}};
    return make_ramp(5, pos, c);
}

ramp solid_ramp_wood(void)
{
    static const double pos[4] = {0.0, 0.45, 0.8, 1.0};
    static const float c[4][3] = {
        {0.85f, 0.66f, 0.42f}, {0.78f, 0.57f, 0.34f}, {0.55f, 0.35f, 0.18f}, {0.40f, 0.24f, 0.11f}};
    return make_ramp(4, pos, c);
}
