/* density.c — soft shapes and DMFs of hypertexture (seed 001). See density.h. */
#include "density.h"

#include <math.h>

const char *density_name(density_kind k)
{
    switch (k) {
    case DENSITY_SPHERE: return "sphere";
    case DENSITY_BOX: return "box";
    case DENSITY_TORUS: return "torus";
    case DENSITY_CYLINDER: return "cylinder";
    }
    return "shape";
}

static rt_code check_pos(const char *shape, const char *what, double v, int allow_zero,
                         rt_error *e)
{
    if (!isfinite(v) || v < 0 || (!allow_zero && v == 0))
        return rt_fail(e, RT_EINVAL, "%s: %s = %g, expected a finite number %s 0", shape, what, v,
                       allow_zero ? ">=" : ">");
    return RT_OK;
}

rt_code density_check(const density_shape *d, rt_error *e)
{
    const char *nm = density_name(d->kind);
    static const char *cn[3] = {"centre x", "centre y", "centre z"};
    static const char *hn[3] = {"half size x", "half size y", "half size z"};
    for (int i = 0; i < 3; i++)
        if (!isfinite(d->c[i]))
            return rt_fail(e, RT_EINVAL, "%s: %s = %g, expected a finite number", nm, cn[i],
                           d->c[i]);
    rt_code c = check_pos(nm, "softness s", d->s, 1, e);
    if (c)
        return c;
    switch (d->kind) {
    case DENSITY_SPHERE: return check_pos(nm, "radius r", d->r, 0, e);
    case DENSITY_TORUS:
        if ((c = check_pos(nm, "major radius R", d->R, 0, e)))
            return c;
        return check_pos(nm, "tube radius r", d->r, 0, e);
    case DENSITY_BOX:
        for (int i = 0; i < 3; i++)
            if ((c = check_pos(nm, hn[i], d->h[i], 0, e)))
                return c;
        return RT_OK;
    case DENSITY_CYLINDER:
        if ((c = check_pos(nm, "radius r", d->r, 0, e)))
            return c;
        return check_pos(nm, "half height", d->h[2], 0, e);
    }
    return rt_fail(e, RT_EINVAL, "unknown density shape %d", (int)d->kind);
}

/* seed 001, soft sphere: D from d^2 between r1^2 and r0^2. */
static inline double soft_d2(double d2, double r1sq, double r0sq)
{
    if (d2 <= r1sq)
        return 1;
    if (d2 >= r0sq)
        return 0;
    return (r0sq - d2) / (r0sq - r1sq);
}

/* Shell of width s centred on the surface, linear in signed distance. */
static inline double soft_sd(double sd, double s)
{
    double hs = s * 0.5;
    if (sd <= -hs)
        return 1;
    if (sd >= hs)
        return 0;
    return (hs - sd) / s;
}

static inline double radii(double r, double s, double *r0sq)
{
    double r1 = r - s * 0.5, r0 = r + s * 0.5;
    if (r1 < 0)
        r1 = 0;
    *r0sq = r0 * r0;
    return r1 * r1;
}

/* Signed distance to an axis-aligned box / capped z cylinder (relative
 * coordinates): |max(q, 0)| + min(max_i q_i, 0). */
static inline double box_sd(const density_shape *d, double dx, double dy, double dz)
{
    double qx = fabs(dx) - d->h[0], qy = fabs(dy) - d->h[1], qz = fabs(dz) - d->h[2];
    double mx = qx > 0 ? qx : 0, my = qy > 0 ? qy : 0, mz = qz > 0 ? qz : 0;
    double in = qx > qy ? qx : qy;
    in = in > qz ? in : qz;
    return sqrt(mx * mx + my * my + mz * mz) + (in < 0 ? in : 0);
}

static inline double cyl_sd(const density_shape *d, double dx, double dy, double dz)
{
    double qr = sqrt(dx * dx + dy * dy) - d->r, qz = fabs(dz) - d->h[2];
    double mr = qr > 0 ? qr : 0, mz = qz > 0 ? qz : 0;
    double in = qr > qz ? qr : qz;
    return sqrt(mr * mr + mz * mz) + (in < 0 ? in : 0);
}

static inline double eval_one(const density_shape *d, double r1sq, double r0sq, double x, double y,
                              double z)
{
    double dx = x - d->c[0], dy = y - d->c[1], dz = z - d->c[2];
    switch (d->kind) {
    case DENSITY_SPHERE: return soft_d2(dx * dx + dy * dy + dz * dz, r1sq, r0sq);
    case DENSITY_TORUS: {
        double q = sqrt(dx * dx + dy * dy) - d->R;
        return soft_d2(q * q + dz * dz, r1sq, r0sq);
    }
    case DENSITY_BOX: return soft_sd(box_sd(d, dx, dy, dz), d->s);
    case DENSITY_CYLINDER: return soft_sd(cyl_sd(d, dx, dy, dz), d->s);
    }
    return 0;
}

double density_eval(const density_shape *d, double x, double y, double z)
{
    double r0sq, r1sq = radii(d->r, d->s, &r0sq);
    return eval_one(d, r1sq, r0sq, x, y, z);
}

void density_eval_block(const density_shape *d, size_t n, const double *x, const double *y,
                        const double *z, double *out)
{
    double r0sq, r1sq = radii(d->r, d->s, &r0sq);
    if (d->kind == DENSITY_SPHERE) { /* the common case, without the switch */
        double cx = d->c[0], cy = d->c[1], cz = d->c[2];
        for (size_t i = 0; i < n; i++) {
            double dx = x[i] - cx, dy = y[i] - cy, dz = z[i] - cz;
            out[i] = soft_d2(dx * dx + dy * dy + dz * dz, r1sq, r0sq);
        }
        return;
    }
    for (size_t i = 0; i < n; i++)
        out[i] = eval_one(d, r1sq, r0sq, x[i], y[i], z[i]);
}

/* The radius (sphere, torus) or offset (box, cylinder) of the level surface:
 * {D >= level} is {d^2 <= rho^2} or {sd <= offset}. */
static double level_param(const density_shape *d, double level)
{
    if (d->kind == DENSITY_BOX || d->kind == DENSITY_CYLINDER)
        return d->s * (0.5 - level);
    if (d->s == 0)
        return d->r; /* the hard shape: the same surface for every level */
    double r0sq, r1sq = radii(d->r, d->s, &r0sq);
    double rho2 = r0sq - level * (r0sq - r1sq);
    return rho2 > 0 ? sqrt(rho2) : 0;
}

static inline double sdf_one(const density_shape *d, double p, double x, double y, double z)
{
    double dx = x - d->c[0], dy = y - d->c[1], dz = z - d->c[2];
    switch (d->kind) {
    case DENSITY_SPHERE: return sqrt(dx * dx + dy * dy + dz * dz) - p;
    case DENSITY_TORUS: {
        double q = sqrt(dx * dx + dy * dy) - d->R;
        return sqrt(q * q + dz * dz) - p;
    }
    case DENSITY_BOX: return box_sd(d, dx, dy, dz) - p;
    case DENSITY_CYLINDER: return cyl_sd(d, dx, dy, dz) - p;
    }
    return NAN;
}

double density_sdf(const density_shape *d, double level, double x, double y, double z)
{
    return sdf_one(d, level_param(d, level), x, y, z);
}

void density_sdf_block(const density_shape *d, double level, size_t n, const double *x,
                       const double *y, const double *z, double *out)
{
    double p = level_param(d, level);
    for (size_t i = 0; i < n; i++)
        out[i] = sdf_one(d, p, x[i], y[i], z[i]);
}

int density_sdf_exact(const density_shape *d, double level)
{
    if (d->s == 0 || d->kind == DENSITY_SPHERE || d->kind == DENSITY_TORUS)
        return 1;
    return level <= 0.5; /* an outward offset of a convex shape's distance is exact */
}

double density_smooth_union(double a, double b, double k)
{
    double m = a > b ? a : b;
    if (!(k > 0))
        return m;
    double h = k - fabs(a - b);
    if (h > 0) {
        h /= k;
        m += h * h * k * 0.25;
    }
    return m > 1 ? 1 : m;
}

/* ---- DMFs */

rt_code dmf_check_bias(double b, rt_error *e)
{
    if (!(b > 0 && b < 1))
        return rt_fail(e, RT_EINVAL, "bias: b = %g, expected 0 < b < 1", b);
    return RT_OK;
}

rt_code dmf_check_gain(double g, rt_error *e)
{
    if (!(g > 0 && g < 1))
        return rt_fail(e, RT_EINVAL, "gain: g = %g, expected 0 < g < 1", g);
    return RT_OK;
}

static inline double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }

static inline double bias_exp(double b) { return log(b) / log(0.5); }

/* Perlin 1985: bias(b, t) = t^(ln b / ln 0.5), with the exponent k given. */
static inline double bias_k(double k, double t) { return pow(clamp01(t), k); }

static inline double gain_k(double k, double t)
{
    t = clamp01(t);
    if (t < 0.5)
        return pow(2 * t, k) * 0.5;
    return 1 - pow(2 - 2 * t, k) * 0.5;
}

double dmf_bias(double b, double t) { return bias_k(bias_exp(b), t); }
double dmf_gain(double g, double t) { return gain_k(bias_exp(1 - g), t); }

double dmf_step(double edge, double t) { return t >= edge ? 1 : 0; }

static inline double smooth(double e0, double inv, double t)
{
    double u = (t - e0) * inv;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    return u * u * (3 - 2 * u);
}

double dmf_smoothstep(double e0, double e1, double t)
{
    if (e1 == e0)
        return dmf_step(e0, t);
    return smooth(e0, 1 / (e1 - e0), t);
}

void dmf_bias_block(double b, size_t n, const double *t, double *out)
{
    double k = bias_exp(b);
    for (size_t i = 0; i < n; i++)
        out[i] = bias_k(k, t[i]);
}

void dmf_gain_block(double g, size_t n, const double *t, double *out)
{
    double k = bias_exp(1 - g);
    for (size_t i = 0; i < n; i++)
        out[i] = gain_k(k, t[i]);
}

void dmf_smoothstep_block(double e0, double e1, size_t n, const double *t, double *out)
{
    if (e1 == e0) {
        for (size_t i = 0; i < n; i++)
            out[i] = dmf_step(e0, t[i]);
        return;
    }
    double inv = 1 / (e1 - e0);
    for (size_t i = 0; i < n; i++)
        out[i] = smooth(e0, inv, t[i]);
}
