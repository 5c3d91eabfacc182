/* wrinkly.c — wrinkly curves and surfaces, seed 002 §5.1 eq. (7)-(11), with
 * the adaptive sampling of §5.2 and a crack remedy of our own (wrinkly.h). */
#include "wrinkly.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ist.h"
#include "par.h"

void wrinkly_opts_default(wrinkly_opts *o)
{
    memset(o, 0, sizeof *o);
    o->tension = 2.0 / 3.0;
    o->shuffle = WRINKLY_HEIGHT | WRINKLY_COLOUR | WRINKLY_OPACITY;
    o->pixel = 1.0;
    o->k = 3;
    o->kmax = 8;
}

/* ---- one axis of the base construction ------------------------------------ */

/* Weights of the three control points p_{i-1}, p_i, p_{i+1} of the Bézier
 * segment containing u (wrinkly.h): P(u) = Σ w[q] p[idx[q]], P'(u) = Σ dw[q] p[idx[q]].
 * reflect: phantoms beyond open ends are reflections (positions), else
 * repeats (attributes). */
typedef struct axw {
    int idx[3];
    double w[3], dw[3];
} axw;

static void axis_weights(int n, int cyclic, double lam, int reflect, double u, axw *a)
{
    int i;
    double s;
    if (cyclic) {
        double uu = u - floor(u / n) * n;
        i = (int)floor(uu);
        if (i >= n)
            i = n - 1;
        if (i < 0)
            i = 0;
        s = uu - i;
    } else {
        i = (int)floor(u);
        if (i < 0)
            i = 0;
        if (i > n - 1)
            i = n - 1;
        s = u - i;
        if (s < 0)
            s = 0;
        if (s > 1)
            s = 1;
    }
    double t = 1 - s;
    double b0 = t * t * t, b1 = 3 * s * t * t, b2 = 3 * s * s * t, b3 = s * s * s;
    double d0 = -3 * t * t, d1 = 3 * t * t - 6 * s * t, d2 = 6 * s * t - 3 * s * s, d3 = 3 * s * s;
    double wm = 0.5 * b0 + 0.5 * (1 - lam) * b1;
    double w0 = 0.5 * b0 + 0.5 * (1 + lam) * (b1 + b2) + 0.5 * b3;
    double wp = 0.5 * (1 - lam) * b2 + 0.5 * b3;
    double dm = 0.5 * d0 + 0.5 * (1 - lam) * d1;
    double dd0 = 0.5 * d0 + 0.5 * (1 + lam) * (d1 + d2) + 0.5 * d3;
    double dp = 0.5 * (1 - lam) * d2 + 0.5 * d3;
    a->idx[0] = i - 1;
    a->idx[1] = i;
    a->idx[2] = i + 1;
    a->w[0] = wm, a->w[1] = w0, a->w[2] = wp;
    a->dw[0] = dm, a->dw[1] = dd0, a->dw[2] = dp;
    if (cyclic) {
        a->idx[0] = (i - 1 + n) % n;
        a->idx[2] = (i + 1) % n;
        return;
    }
    if (n == 1) {
        a->idx[0] = a->idx[2] = 0;
        return;
    }
    if (i == 0) { /* phantom p_{-1} */
        a->idx[0] = 0;
        if (reflect) { /* 2p_0 - p_1 */
            a->w[1] += 2 * a->w[0], a->w[2] -= a->w[0];
            a->dw[1] += 2 * a->dw[0], a->dw[2] -= a->dw[0];
            a->w[0] = a->dw[0] = 0;
        }
    }
    if (i == n - 1) { /* phantom p_n */
        a->idx[2] = n - 1;
        if (reflect) { /* 2p_{n-1} - p_{n-2} */
            a->w[1] += 2 * a->w[2], a->w[0] -= a->w[2];
            a->dw[1] += 2 * a->dw[2], a->dw[0] -= a->dw[2];
            a->w[2] = a->dw[2] = 0;
        }
    }
}

static double smooth01(double x)
{
    if (x <= 0)
        return 0;
    if (x >= 1)
        return 1;
    return x * x * (3 - 2 * x);
}

/* Weight of the shuffled value at u: 0 on a joint, 1 farther than band. */
static double crack_weight(int n, int cyclic, double band, double u)
{
    if (band <= 0)
        return 1;
    double j = floor(u + 0.5);
    if (!cyclic && (j <= 0 || j >= n))
        return 1; /* the ends of an open axis are not joints */
    return smooth01(fabs(u - j) / band);
}

static double lam_of(double t) { return t > 0 && t <= 1 ? t : 2.0 / 3.0; }

static double attr_of(const wrinkly_point *p, int which)
{
    return which == 0 ? p->h : which <= 3 ? p->rgb[which - 1] : p->opacity;
}

/* ---- curves ------------------------------------------------------------------ */

void wrinkly_curve_base(const wrinkly_curve *c, double tension, double u, double p[2], double dp[2])
{
    axw a;
    axis_weights(c->n, c->ax.cyclic, lam_of(tension), 1, u, &a);
    p[0] = p[1] = dp[0] = dp[1] = 0;
    for (int q = 0; q < 3; q++) {
        const wrinkly_point *pt = &c->pts[a.idx[q]];
        for (int d = 0; d < 2; d++) {
            p[d] += a.w[q] * pt->pos[d];
            dp[d] += a.dw[q] * pt->pos[d];
        }
    }
}

double wrinkly_curve_attr(const wrinkly_curve *c, double tension, int which, double u)
{
    axw a;
    axis_weights(c->n, c->ax.cyclic, lam_of(tension), 0, u, &a);
    double v = 0;
    for (int q = 0; q < 3; q++)
        v += a.w[q] * attr_of(&c->pts[a.idx[q]], which);
    return v;
}

void wrinkly_polyline_free(wrinkly_polyline *p)
{
    rt_free(p->xy);
    rt_free(p->u);
    rt_free(p->rgba);
    memset(p, 0, sizeof *p);
}

static rt_code check_axis(const char *what, int n, const wrinkly_axis *ax, rt_error *e)
{
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "wrinkly %s needs at least 1 control point, got %d", what, n);
    if (ax->m < 0 || ax->m > 50)
        return rt_fail(e, RT_EINVAL, "wrinkly %s crossing count M = %d; expected 0..50", what, ax->m);
    if (ax->cyclic && ax->ist && 2 * ax->m + 1 > n)
        return rt_fail(e, RT_EINVAL,
                       "wrinkly %s is closed with M = %d, which needs at least 2M+1 = %d control points, got %d (lower crossings, or ist: false)",
                       what, ax->m, 2 * ax->m + 1, n);
    return RT_OK;
}

/* Sample positions of one axis: §5.2 samples plus the ends of an open axis;
 * *mapk receives the IST used for F^{-1} (K + extra rounds). */
static rt_code axis_samples(int n, const wrinkly_axis *ax, const int *ki, const wrinkly_opts *o,
                            uint64_t stream, double **out, size_t *count, ist *map, int *kout,
                            rt_error *e)
{
    int k = 0;
    for (int i = 0; i < n; i++)
        k = ki[i] > k ? ki[i] : k;
    *kout = k;
    ist samp;
    /* without ist the map is never used: the sample positions are the same
     * for both axis types, so a cyclic axis with 2M+1 > N is fine then */
    ist_spec sp = {.n = n, .m = ax->m, .k = k, .axis = ax->cyclic && ax->ist ? IST_CYCLIC : IST_TRANSLATION};
    rt_code rc = ist_init(&samp, &sp, e);
    if (rc)
        return rc;
    size_t ns = ist_sample_positions(&samp, ki, o->jitter, o->seed ^ (stream * 0x9e3779b97f4a7c15ull), NULL, 0);
    size_t tot = ns + (ax->cyclic ? 0 : 2);
    double *pos = rt_malloc(sizeof(double) * (tot ? tot : 1));
    if (!pos || ns == (size_t)-1) {
        rt_free(pos);
        ist_free(&samp);
        return rt_fail(e, RT_ENOMEM, "out of memory for wrinkly samples");
    }
    size_t off = ax->cyclic ? 0 : 1;
    ist_sample_positions(&samp, ki, o->jitter, o->seed ^ (stream * 0x9e3779b97f4a7c15ull), pos + off, ns);
    if (!ax->cyclic) {
        pos[0] = 0;
        pos[tot - 1] = n;
    }
    ist_free(&samp);
    sp.k = k + (o->extra > 0 ? o->extra : 0);
    int klim = ist_k_limit(&sp); /* extra rounds stop where double precision does (wrinkly.h) */
    if (sp.k > klim)
        sp.k = klim > k ? klim : k;
    rc = ist_init(map, &sp, e);
    if (rc) {
        rt_free(pos);
        return rc;
    }
    *out = pos;
    *count = tot;
    return RT_OK;
}

rt_code wrinkly_curve_sample(const wrinkly_curve *c, const wrinkly_opts *o, wrinkly_polyline *out,
                             rt_error *e)
{
    memset(out, 0, sizeof *out);
    rt_code rc = check_axis("curve", c->n, &c->ax, e);
    if (rc)
        return rc;
    double lam = lam_of(o->tension);
    int n = c->n;
    int *ki = rt_malloc(sizeof(int) * (size_t)n);
    if (!ki)
        return rt_fail(e, RT_ENOMEM, "out of memory for a wrinkly curve");
    rc = wrinkly_curve_levels(c, o, ki, e);
    if (rc) {
        rt_free(ki);
        return rc;
    }
    ist map;
    double *pos;
    size_t np;
    rc = axis_samples(n, &c->ax, ki, o, 0, &pos, &np, &map, &out->k, e);
    rt_free(ki);
    if (rc)
        return rc;
    out->xy = rt_malloc(sizeof(double) * 2 * np);
    out->rgba = rt_malloc(sizeof(float) * 4 * np);
    if (!out->xy || !out->rgba) {
        rt_free(pos);
        ist_free(&map);
        wrinkly_polyline_free(out);
        return rt_fail(e, RT_ENOMEM, "out of memory for %zu curve samples", np);
    }
    out->u = pos;
    out->n = np;
    out->closed = c->ax.cyclic;
    for (size_t q = 0; q < np; q++) {
        double u = pos[q], p[2], d[2];
        wrinkly_curve_base(c, lam, u, p, d);
        double su = c->ax.ist ? ist_inv(&map, u) : u;
        double cw = c->ax.ist ? crack_weight(n, c->ax.cyclic, o->crack_band, u) : 1;
        double av[5];
        for (int w = 0; w < 5; w++) {
            unsigned bit = w == 0 ? WRINKLY_HEIGHT : w <= 3 ? WRINKLY_COLOUR : WRINKLY_OPACITY;
            double plain = wrinkly_curve_attr(c, lam, w, u);
            av[w] = plain;
            if (o->shuffle & bit) {
                double sh = wrinkly_curve_attr(c, lam, w, su);
                av[w] = cw * sh + (1 - cw) * plain;
            }
        }
        double l = hypot(d[0], d[1]);
        double nx = l > 0 ? -d[1] / l : 0, ny = l > 0 ? d[0] / l : 0;
        out->xy[2 * q] = p[0] + av[0] * nx;
        out->xy[2 * q + 1] = p[1] + av[0] * ny;
        for (int w = 0; w < 4; w++)
            out->rgba[4 * q + w] = (float)av[1 + w];
    }
    ist_free(&map);
    return RT_OK;
}

/* ---- surfaces -------------------------------------------------------------- */

static void surf_eval(const wrinkly_surface *s, const axw *au, const axw *av, double p[3],
                      double pu[3], double pv[3])
{
    for (int d = 0; d < 3; d++)
        p[d] = pu[d] = pv[d] = 0;
    for (int b = 0; b < 3; b++)
        for (int a = 0; a < 3; a++) {
            const double *q = s->pts[(size_t)av->idx[b] * (size_t)s->nu + (size_t)au->idx[a]].pos;
            double w = au->w[a] * av->w[b], wu = au->dw[a] * av->w[b], wv = au->w[a] * av->dw[b];
            for (int d = 0; d < 3; d++) {
                p[d] += w * q[d];
                pu[d] += wu * q[d];
                pv[d] += wv * q[d];
            }
        }
}

static void cross_norm(const double a[3], const double b[3], double n[3])
{
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (l > 0)
        n[0] /= l, n[1] /= l, n[2] /= l;
}

static void cross3(const double a[3], const double b[3], double n[3])
{
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
}

void wrinkly_surface_flux(const wrinkly_surface *s, double tension, double *flux, double *reach)
{
    enum { G = 5 };
    double lam = lam_of(tension);
    /* midpoint rule on G×G cells per patch: first the area centroid, then Φ */
    double c[3] = {0, 0, 0}, area = 0;
    for (int pass = 0; pass < 2; pass++) {
        double f = 0, af = 0;
        for (int j = 0; j < s->nv; j++)
            for (int i = 0; i < s->nu; i++)
                for (int b = 0; b < G; b++)
                    for (int a = 0; a < G; a++) {
                        axw au, av;
                        axis_weights(s->nu, s->au.cyclic, lam, 1, i + (a + 0.5) / G, &au);
                        axis_weights(s->nv, s->av.cyclic, lam, 1, j + (b + 0.5) / G, &av);
                        double p[3], pu[3], pv[3], n[3];
                        surf_eval(s, &au, &av, p, pu, pv);
                        cross3(pu, pv, n);
                        double dA = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
                        if (pass == 0) {
                            for (int d = 0; d < 3; d++)
                                c[d] += p[d] * dA;
                            area += dA;
                        } else {
                            double r[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
                            f += r[0] * n[0] + r[1] * n[1] + r[2] * n[2];
                            af += sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) * dA;
                        }
                    }
        if (pass == 0 && area > 0)
            for (int d = 0; d < 3; d++)
                c[d] /= area;
        *flux = f / (G * G);
        *reach = af / (G * G);
    }
}

int wrinkly_surface_side(const wrinkly_surface *s, const wrinkly_opts *o, rt_error *e)
{
    if (o->normal == WRINKLY_NORMAL_UV)
        return 1;
    double f, af;
    wrinkly_surface_flux(s, o->tension, &f, &af);
    int body = af > 0 && fabs(f) >= 0.25 * af;
    if (o->normal == WRINKLY_NORMAL_AUTO)
        return body && f < 0 ? -1 : 1;
    if (!(af > 0 && fabs(f) > 1e-6 * af)) {
        rt_fail(e, RT_EINVAL, "the surface encloses no volume, so no side of it is %s (use normal \"uv\")",
                o->normal == WRINKLY_NORMAL_OUTWARD ? "outward" : "inward");
        return 0;
    }
    int out = f < 0 ? -1 : 1;
    return o->normal == WRINKLY_NORMAL_OUTWARD ? out : -out;
}

void wrinkly_surface_base(const wrinkly_surface *s, double tension, double u, double v, double p[3],
                          double n[3])
{
    axw au, av;
    double lam = lam_of(tension);
    axis_weights(s->nu, s->au.cyclic, lam, 1, u, &au);
    axis_weights(s->nv, s->av.cyclic, lam, 1, v, &av);
    double pu[3], pv[3];
    surf_eval(s, &au, &av, p, pu, pv);
    cross_norm(pu, pv, n);
}

/* Everything one sample of one axis needs, computed once per column/row. */
typedef struct axsamp {
    axw pos;   /* base weights at u (reflected phantoms) */
    axw plain; /* attribute weights at u */
    axw shuf;  /* attribute weights at F^{-1}(u) */
    double crack;
} axsamp;

typedef struct surf_job {
    const wrinkly_surface *s;
    const wrinkly_opts *o;
    const axsamp *su, *sv;
    size_t nu, nv;
    int cyc_u, cyc_v;
    double *r;   /* displaced positions, nu*nv*3 */
    mesh *m;
    double side; /* +1 or -1 on P_u × P_v (wrinkly_surface_side) */
} surf_job;

static double attr2(const wrinkly_surface *s, const axw *a, const axw *b, int which)
{
    double v = 0;
    for (int y = 0; y < 3; y++)
        for (int x = 0; x < 3; x++)
            v += a->w[x] * b->w[y] * attr_of(&s->pts[(size_t)b->idx[y] * (size_t)s->nu + (size_t)a->idx[x]], which);
    return v;
}

static void surf_row(void *ctx, size_t j, int worker)
{
    (void)worker;
    surf_job *J = ctx;
    const wrinkly_surface *s = J->s;
    const axsamp *sv = &J->sv[j];
    for (size_t i = 0; i < J->nu; i++) {
        const axsamp *su = &J->su[i];
        double p[3], pu[3], pv[3], n[3];
        surf_eval(s, &su->pos, &sv->pos, p, pu, pv);
        cross_norm(pu, pv, n);
        for (int d = 0; d < 3; d++)
            n[d] *= J->side;
        double cw = su->crack * sv->crack;
        double av[5];
        for (int w = 0; w < 5; w++) {
            unsigned bit = w == 0 ? WRINKLY_HEIGHT : w <= 3 ? WRINKLY_COLOUR : WRINKLY_OPACITY;
            double plain = attr2(s, &su->plain, &sv->plain, w);
            av[w] = plain;
            if (J->o->shuffle & bit) /* eq. (11) */
                av[w] = cw * attr2(s, &su->shuf, &sv->shuf, w) + (1 - cw) * plain;
        }
        size_t id = j * J->nu + i;
        for (int d = 0; d < 3; d++) {
            J->r[3 * id + d] = p[d] + av[0] * n[d];
            J->m->pos[3 * id + d] = (float)J->r[3 * id + d];
            J->m->nrm[3 * id + d] = (float)n[d]; /* replaced by surf_normals */
        }
        for (int w = 0; w < 4; w++)
            J->m->col[4 * id + w] = (float)av[1 + w];
    }
}

/* Vertex normals of the displaced grid by central differences. */
static void surf_normals(void *ctx, size_t j, int worker)
{
    (void)worker;
    surf_job *J = ctx;
    size_t nu = J->nu, nv = J->nv;
    size_t j0 = j > 0 ? j - 1 : J->cyc_v ? nv - 1 : j, j1 = j + 1 < nv ? j + 1 : J->cyc_v ? 0 : j;
    for (size_t i = 0; i < nu; i++) {
        size_t i0 = i > 0 ? i - 1 : J->cyc_u ? nu - 1 : i, i1 = i + 1 < nu ? i + 1 : J->cyc_u ? 0 : i;
        const double *a = J->r + 3 * (j * nu + i1), *b = J->r + 3 * (j * nu + i0);
        const double *c = J->r + 3 * (j1 * nu + i), *d = J->r + 3 * (j0 * nu + i);
        double du[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        double dv[3] = {c[0] - d[0], c[1] - d[1], c[2] - d[2]};
        double n[3];
        cross_norm(du, dv, n);
        size_t id = j * nu + i;
        if (n[0] != 0 || n[1] != 0 || n[2] != 0)
            for (int q = 0; q < 3; q++)
                J->m->nrm[3 * id + q] = (float)(n[q] * J->side);
    }
}

/* ---- level of detail (§5.2, wrinkly.h "Adaptive sampling") ------------------ */

/* |J(x)·v|: how fast the picture of x moves when x moves with velocity v —
 * pixels with a camera (the exact Jacobian of camera_project; 0 behind the
 * camera, where nothing is drawn), world units without one. */
static double lod_rate(const wrinkly_opts *o, const double x[3], const double v[3])
{
    if (!o->cam)
        return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const camera *c = o->cam;
    double d[3] = {x[0] - c->eye[0], x[1] - c->eye[1], x[2] - c->eye[2]};
    double z = d[0] * c->fwd[0] + d[1] * c->fwd[1] + d[2] * c->fwd[2];
    if (z <= 1e-9)
        return 0;
    double xr = d[0] * c->right[0] + d[1] * c->right[1] + d[2] * c->right[2];
    double yu = d[0] * c->upv[0] + d[1] * c->upv[1] + d[2] * c->upv[2];
    double vz = v[0] * c->fwd[0] + v[1] * c->fwd[1] + v[2] * c->fwd[2];
    double vr = v[0] * c->right[0] + v[1] * c->right[1] + v[2] * c->right[2];
    double vu = v[0] * c->upv[0] + v[1] * c->upv[1] + v[2] * c->upv[2];
    /* sx = xr/z · h/(2 tan) + w/2, sy = -yu/z · h/(2 tan) + h/2 */
    double f = (double)o->height / (2 * c->tan_half * z * z);
    return f * hypot(vr * z - xr * vz, vu * z - yu * vz);
}

/* Bounds of an attribute on one Bézier segment (interval) of one axis from
 * its four Bézier control values c (convex hull and hodograph): the values
 * lie in [lo, hi], |d/du| <= d. */
typedef struct hbound {
    double d, lo, hi;
} hbound;

/* The Bézier control values of the segment of interval i as weights of the
 * three points p_{i-1}, p_i, p_{i+1} (axis_weights, wrinkly.h). */
static void bez_rows(double lam, double E[4][3])
{
    double r[4][3] = {{0.5, 0.5, 0}, {0.5 * (1 - lam), 0.5 * (1 + lam), 0},
                      {0, 0.5 * (1 + lam), 0.5 * (1 - lam)}, {0, 0.5, 0.5}};
    memcpy(E, r, sizeof r);
}

/* Intervals whose attributes can appear in interval i after k IST rounds
 * (|j - i| <= kM, wrapped or clipped): *lo..*hi, indices taken mod n on a
 * cyclic axis. */
static void src_range(int n, const wrinkly_axis *ax, int shuffled, int i, int k, int *lo, int *hi)
{
    long r = shuffled && ax->ist ? (long)k * ax->m : 0;
    if (ax->cyclic && 2 * r + 1 >= n) {
        *lo = 0, *hi = n - 1;
        return;
    }
    long a = i - r, b = i + r;
    if (!ax->cyclic) {
        a = a < 0 ? 0 : a;
        b = b > n - 1 ? n - 1 : b;
    }
    *lo = (int)a, *hi = (int)b;
}

static void hb_join(hbound *a, const hbound *b)
{
    a->d = b->d > a->d ? b->d : a->d;
    a->lo = b->lo < a->lo ? b->lo : a->lo;
    a->hi = b->hi > a->hi ? b->hi : a->hi;
}

static const hbound hb_empty = {0, INFINITY, -INFINITY};

/* One sample of the base for the bound: where it is, and the rates of P',
 * N and N' there (at the base point and at the base point displaced by
 * ±hg·N, hg = max |h|: the picture of R lies between them). */
enum { LOD_X = 3 };
typedef struct lodpt {
    double dp[LOD_X], n[LOD_X], dn[LOD_X];
} lodpt;

static void lod_point(const wrinkly_opts *o, const double p[3], const double dp[3], const double n[3],
                      const double dn[3], double hg, lodpt *q)
{
    for (int x = 0; x < LOD_X; x++) {
        double h = (x - 1) * hg, at[3];
        for (int d = 0; d < 3; d++)
            at[d] = p[d] + h * n[d];
        q->dp[x] = lod_rate(o, at, dp);
        q->n[x] = lod_rate(o, at, n);
        q->dn[x] = lod_rate(o, at, dn);
    }
}

/* The bound on the projected length of R over a sub-interval of width 1
 * (divide by B^k): max over the samples of |J P'| + |H'|max |J N| + |H|max |J N'|. */
static double lod_density(const lodpt *q, size_t nq, double hd, double habs)
{
    double g = 0;
    for (size_t s = 0; s < nq; s++)
        for (int x = 0; x < LOD_X; x++) {
            double v = q[s].dp[x] + hd * q[s].n[x] + habs * q[s].dn[x];
            g = v > g ? v : g;
        }
    return g;
}

/* |d/du| of the height that R uses, from the bound of the attribute: the
 * crack blend adds |s'| |H_shuffled - H_plain| <= (1.5/w)(hi - lo). */
static double lod_hd(const wrinkly_opts *o, const wrinkly_axis *ax, const hbound *b)
{
    double d = b->d;
    if (ax->ist && (o->shuffle & WRINKLY_HEIGHT) && o->crack_band > 0 && b->hi > b->lo)
        d += 1.5 / o->crack_band * (b->hi - b->lo);
    return d;
}

static double lod_target(const wrinkly_opts *o) { return o->cam ? (o->pixel > 0 ? o->pixel : 1.0) : o->tol; }

/* Samples per base interval along the axis being measured. */
enum { LOD_G = 17, LOD_GS = 7 };
#define LOD_EDGE 1e-4 /* samples stay this far inside the segment (P'' jumps at joints) */
#define LOD_FD 1e-5   /* central difference step for N' */

static double lod_u(int i, int q, int g) { return i + LOD_EDGE + (1 - 2 * LOD_EDGE) * q / (double)(g - 1); }

static void curve_frame(const wrinkly_curve *c, double lam, double u, double p[3], double dp[3], double n[3])
{
    double pp[2], d[2];
    wrinkly_curve_base(c, lam, u, pp, d);
    double l = hypot(d[0], d[1]);
    p[0] = pp[0], p[1] = pp[1], p[2] = 0;
    dp[0] = d[0], dp[1] = d[1], dp[2] = 0;
    n[0] = l > 0 ? -d[1] / l : 0, n[1] = l > 0 ? d[0] / l : 0, n[2] = 0;
}

rt_code wrinkly_curve_levels(const wrinkly_curve *c, const wrinkly_opts *o, int *ki, rt_error *e)
{
    double lam = lam_of(o->tension);
    int n = c->n, b = 2 * c->ax.m + 1;
    int kmax = o->kmax > 0 ? o->kmax : 8;
    int kf = o->k < 0 ? 0 : o->k > kmax ? kmax : o->k;
    int adaptive = (o->cam || o->tol > 0) && b > 1;
    for (int i = 0; i < n; i++)
        ki[i] = o->cam || o->tol > 0 ? 0 : kf;
    if (!adaptive)
        return RT_OK;
    double E[4][3], hg = 0;
    bez_rows(lam, E);
    for (int i = 0; i < n; i++)
        hg = fabs(c->pts[i].h) > hg ? fabs(c->pts[i].h) : hg;
    /* per interval: the height's Bézier bounds */
    /* no memory for the bound is out of memory, not "the finest level":
     * (2M+1)^kmax samples per interval would turn it into a bogus size */
    hbound *hb = rt_malloc(sizeof *hb * (size_t)n);
    if (!hb)
        return rt_fail(e, RT_ENOMEM, "out of memory for the level-of-detail bounds of a wrinkly curve");
    for (int i = 0; i < n; i++) {
        axw a;
        axis_weights(n, c->ax.cyclic, lam, 0, i + 0.5, &a);
        double cv[4];
        for (int r = 0; r < 4; r++) {
            cv[r] = 0;
            for (int q = 0; q < 3; q++)
                cv[r] += E[r][q] * c->pts[a.idx[q]].h;
        }
        hb[i] = hb_empty;
        for (int r = 0; r < 4; r++) {
            hb[i].lo = cv[r] < hb[i].lo ? cv[r] : hb[i].lo;
            hb[i].hi = cv[r] > hb[i].hi ? cv[r] : hb[i].hi;
            if (r < 3 && 3 * fabs(cv[r + 1] - cv[r]) > hb[i].d)
                hb[i].d = 3 * fabs(cv[r + 1] - cv[r]);
        }
    }
    double target = lod_target(o);
    int shuf = (o->shuffle & WRINKLY_HEIGHT) != 0;
    for (int i = 0; i < n; i++) {
        lodpt q[LOD_G];
        for (int s = 0; s < LOD_G; s++) {
            double u = lod_u(i, s, LOD_G), p[3], dp[3], nn[3], p1[3], d1[3], n1[3], p0[3], d0[3], n0[3], dn[3];
            curve_frame(c, lam, u, p, dp, nn);
            curve_frame(c, lam, u + LOD_FD, p1, d1, n1);
            curve_frame(c, lam, u - LOD_FD, p0, d0, n0);
            for (int d = 0; d < 3; d++)
                dn[d] = (n1[d] - n0[d]) / (2 * LOD_FD);
            lod_point(o, p, dp, nn, dn, hg, &q[s]);
        }
        int k = 0;
        for (;; k++) {
            int lo, hi;
            src_range(n, &c->ax, shuf, i, k, &lo, &hi);
            hbound h = hb_empty;
            for (int j = lo; j <= hi; j++)
                hb_join(&h, &hb[((j % n) + n) % n]);
            double habs = fmax(fabs(h.lo), fabs(h.hi));
            double g = lod_density(q, LOD_G, lod_hd(o, &c->ax, &h), habs);
            if (k >= kmax || g / pow(b, k) <= target)
                break;
        }
        ki[i] = k;
    }
    rt_free(hb);
    return RT_OK;
}

double wrinkly_surface_attr(const wrinkly_surface *s, double tension, int which, double u, double v)
{
    axw au, av;
    double lam = lam_of(tension);
    axis_weights(s->nu, s->au.cyclic, lam, 0, u, &au);
    axis_weights(s->nv, s->av.cyclic, lam, 0, v, &av);
    return attr2(s, &au, &av, which);
}

/* Height bounds of one patch: d = |H_u| (axis 0) or |H_v| (axis 1). */
typedef struct patchb {
    hbound u, v;
} patchb;

static void patch_bounds(const wrinkly_surface *s, double lam, int i, int j, patchb *pb)
{
    double E[4][3], C[4][4];
    bez_rows(lam, E);
    axw au, av;
    axis_weights(s->nu, s->au.cyclic, lam, 0, i + 0.5, &au);
    axis_weights(s->nv, s->av.cyclic, lam, 0, j + 0.5, &av);
    double lo = INFINITY, hi = -INFINITY;
    for (int b = 0; b < 4; b++)
        for (int a = 0; a < 4; a++) {
            double x = 0;
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    x += E[a][q] * E[b][r] * s->pts[(size_t)av.idx[r] * (size_t)s->nu + (size_t)au.idx[q]].h;
            C[b][a] = x;
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
    double du = 0, dv = 0;
    for (int b = 0; b < 4; b++)
        for (int a = 0; a < 3; a++) {
            du = fmax(du, 3 * fabs(C[b][a + 1] - C[b][a]));
            dv = fmax(dv, 3 * fabs(C[a + 1][b] - C[a][b]));
        }
    pb->u = (hbound){du, lo, hi};
    pb->v = (hbound){dv, lo, hi};
}

/* Samples of patch (i, j) for the bound along axis `ax` (0 u, 1 v). */
static void patch_samples(const wrinkly_surface *s, const wrinkly_opts *o, double lam, double hg, int i, int j,
                          int ax, lodpt *q)
{
    for (int b = 0; b < LOD_GS; b++)
        for (int a = 0; a < LOD_GS; a++) {
            double u = lod_u(i, a, LOD_GS), v = lod_u(j, b, LOD_GS);
            axw wu, wv;
            axis_weights(s->nu, s->au.cyclic, lam, 1, u, &wu);
            axis_weights(s->nv, s->av.cyclic, lam, 1, v, &wv);
            double p[3], pu[3], pv[3], nn[3], n0[3], n1[3], dn[3], x[3];
            surf_eval(s, &wu, &wv, p, pu, pv);
            cross_norm(pu, pv, nn);
            for (int sgn = -1; sgn <= 1; sgn += 2) {
                double uu = u + (ax == 0 ? sgn * LOD_FD : 0), vv = v + (ax == 1 ? sgn * LOD_FD : 0);
                double *nd = sgn < 0 ? n0 : n1;
                wrinkly_surface_base(s, lam, uu, vv, x, nd);
            }
            for (int d = 0; d < 3; d++)
                dn[d] = (n1[d] - n0[d]) / (2 * LOD_FD);
            lod_point(o, p, ax == 0 ? pu : pv, nn, dn, hg, &q[b * LOD_GS + a]);
        }
}

/* K_i per base interval of both axes (§5.2, wrinkly.h). */
rt_code wrinkly_surface_levels(const wrinkly_surface *s, const wrinkly_opts *o, int *ku, int *kv, rt_error *e)
{
    double lam = lam_of(o->tension);
    int kmax = o->kmax > 0 ? o->kmax : 8;
    int nu = s->nu, nv = s->nv;
    int adaptive = o->cam || o->tol > 0;
    int kf = o->k < 0 ? 0 : o->k > kmax ? kmax : o->k;
    for (int i = 0; i < nu; i++)
        ku[i] = adaptive ? 0 : kf;
    for (int j = 0; j < nv; j++)
        kv[j] = adaptive ? 0 : kf;
    if (!adaptive)
        return RT_OK;
    size_t np = (size_t)nu * (size_t)nv, nmax = (size_t)(nu > nv ? nu : nv);
    patchb *pb = rt_malloc(sizeof *pb * np);
    patchb *win = rt_malloc(sizeof *win * np);
    lodpt *q = rt_malloc(sizeof *q * nmax * LOD_GS * LOD_GS);
    rt_code rc = RT_OK;
    /* no memory for the bound is out of memory, not "the finest level":
     * (2M+1)^kmax vertices per interval would turn it into a bogus size */
    if (!pb || !win || !q) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the level-of-detail bounds of a wrinkly surface");
        goto done;
    }
    double hg = 0;
    for (size_t t = 0; t < np; t++)
        hg = fabs(s->pts[t].h) > hg ? fabs(s->pts[t].h) : hg;
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++)
            patch_bounds(s, lam, i, j, &pb[(size_t)j * nu + i]);
    double target = lod_target(o);
    int shuf = (o->shuffle & WRINKLY_HEIGHT) != 0;
    for (int ax = 0; ax < 2; ax++) {
        const wrinkly_axis *A = ax == 0 ? &s->au : &s->av, *O = ax == 0 ? &s->av : &s->au;
        int na = ax == 0 ? nu : nv, no = ax == 0 ? nv : nu, b = 2 * A->m + 1;
        int *kk = ax == 0 ? ku : kv;
        if (b == 1)
            continue; /* subdividing a base-1 axis changes nothing: level 0 */
        /* win[(a, c)] joins the patches (a, c') over the sources c' of c on
         * the other axis (any level up to kmax) */
        for (int c = 0; c < no; c++) {
            int lo, hi;
            src_range(no, O, shuf, c, kmax, &lo, &hi);
            for (int a = 0; a < na; a++) {
                hbound h = hb_empty;
                for (int cc = lo; cc <= hi; cc++) {
                    int w = ((cc % no) + no) % no;
                    const patchb *p = ax == 0 ? &pb[(size_t)w * nu + a] : &pb[(size_t)a * nu + w];
                    hb_join(&h, ax == 0 ? &p->u : &p->v);
                }
                win[(size_t)c * na + a] = (patchb){h, h};
            }
        }
        for (int a = 0; a < na; a++) {
            for (int c = 0; c < no; c++)
                patch_samples(s, o, lam, hg, ax == 0 ? a : c, ax == 0 ? c : a, ax,
                              q + (size_t)c * LOD_GS * LOD_GS);
            int k = 0;
            for (;; k++) {
                int lo, hi, ok = 1;
                src_range(na, A, shuf, a, k, &lo, &hi);
                for (int c = 0; c < no && ok; c++) {
                    hbound h = hb_empty;
                    for (int aa = lo; aa <= hi; aa++)
                        hb_join(&h, &win[(size_t)c * na + ((aa % na) + na) % na].u);
                    double g = lod_density(q + (size_t)c * LOD_GS * LOD_GS, LOD_GS * LOD_GS, lod_hd(o, A, &h),
                                           fmax(fabs(h.lo), fabs(h.hi)));
                    ok = g / pow(b, k) <= target;
                }
                if (ok || k >= kmax)
                    break;
            }
            kk[a] = k;
        }
    }
done:
    rt_free(pb);
    rt_free(win);
    rt_free(q);
    return rc;
}

static rt_code make_axis(int n, const wrinkly_axis *ax, const int *ki, const wrinkly_opts *o,
                         double lam, uint64_t stream, axsamp **out, size_t *count, int *k, rt_error *e)
{
    ist map;
    double *pos;
    size_t np;
    rt_code rc = axis_samples(n, ax, ki, o, stream, &pos, &np, &map, k, e);
    if (rc)
        return rc;
    axsamp *a = rt_malloc(sizeof *a * np);
    if (!a) {
        rt_free(pos);
        ist_free(&map);
        return rt_fail(e, RT_ENOMEM, "out of memory for %zu wrinkly samples", np);
    }
    for (size_t q = 0; q < np; q++) {
        double u = pos[q];
        axis_weights(n, ax->cyclic, lam, 1, u, &a[q].pos);
        axis_weights(n, ax->cyclic, lam, 0, u, &a[q].plain);
        axis_weights(n, ax->cyclic, lam, 0, ax->ist ? ist_inv(&map, u) : u, &a[q].shuf);
        a[q].crack = ax->ist ? crack_weight(n, ax->cyclic, o->crack_band, u) : 1;
    }
    rt_free(pos);
    ist_free(&map);
    *out = a;
    *count = np;
    return RT_OK;
}

rt_code wrinkly_surface_mesh(const wrinkly_surface *s, const wrinkly_opts *o, const rt_run *run,
                             mesh *out, wrinkly_info *info, rt_error *e)
{
    mesh_init(out, 1, 1);
    if (info)
        memset(info, 0, sizeof *info);
    rt_code rc = check_axis("surface (u axis)", s->nu, &s->au, e);
    if (!rc)
        rc = check_axis("surface (v axis)", s->nv, &s->av, e);
    if (rc)
        return rc;
    double lam = lam_of(o->tension);
    int *ku = rt_malloc(sizeof(int) * (size_t)s->nu), *kv = rt_malloc(sizeof(int) * (size_t)s->nv);
    axsamp *su = NULL, *sv = NULL;
    double *r = NULL;
    size_t nu = 0, nv = 0;
    int k[2] = {0, 0};
    if (!ku || !kv) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for a wrinkly surface");
        goto done;
    }
    int side = wrinkly_surface_side(s, o, e);
    if (!side) {
        rc = RT_EINVAL;
        goto done;
    }
    rc = wrinkly_surface_levels(s, o, ku, kv, e);
    if (!rc)
        rc = make_axis(s->nu, &s->au, ku, o, lam, 1, &su, &nu, &k[0], e);
    if (!rc)
        rc = make_axis(s->nv, &s->av, kv, o, lam, 2, &sv, &nv, &k[1], e);
    if (rc)
        goto done;
    size_t nvert = rt_mul_size(nu, nv);
    size_t qu = s->au.cyclic ? nu : nu - 1, qv = s->av.cyclic ? nv : nv - 1;
    size_t ntri = rt_mul_size(rt_mul_size(qu, qv), 2);
    if (!nvert || nvert >= UINT32_MAX || (qu && qv && !ntri)) {
        rc = rt_fail(e, RT_EINVAL, "wrinkly surface would have %zu × %zu vertices; lower kmax", nu, nv);
        goto done;
    }
    /* The rows of v are the call's chunks (par.h): with o->split a shard
     * computes its rows only (and the displaced rows next to them, which
     * their normals need); merge computes none and places the shards'. */
    par_part pp = {run, NULL, PAR_FULL, nv, 0, nv};
    if (o->split && (rc = par_part_begin(&pp, run, "wrinkly surface", nv, e)))
        goto done;
    if (pp.mode != PAR_MERGE)
        r = rt_malloc(rt_mul_size(nvert, 3 * sizeof(double)));
    rt_free(out->nrm);
    rt_free(out->col);
    out->pos = rt_malloc(rt_mul_size(nvert, 3 * sizeof(float)));
    out->nrm = rt_malloc(rt_mul_size(nvert, 3 * sizeof(float)));
    out->col = rt_malloc(rt_mul_size(nvert, 4 * sizeof(float)));
    out->tri = rt_malloc(rt_mul_size(ntri ? ntri : 1, 3 * sizeof(uint32_t)));
    if ((!r && pp.mode != PAR_MERGE) || !out->pos || !out->nrm || !out->col || !out->tri) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for a %zu-vertex wrinkly mesh", nvert);
        goto done;
    }
    out->nv = out->cap_v = nvert;
    out->nt = out->cap_t = ntri;
    surf_job J = {s, o, su, sv, nu, nv, s->au.cyclic, s->av.cyclic, r, out, side};
    if (pp.mode == PAR_SHARD) {
        /* the other shards' rows: never used, but not left undefined */
        memset(out->pos, 0, nvert * 3 * sizeof(float));
        memset(out->nrm, 0, nvert * 3 * sizeof(float));
        memset(out->col, 0, nvert * 4 * sizeof(float));
    }
    rc = par_part_for(&pp, "wrinkly surface", surf_row, &J);
    if (!rc && pp.mode == PAR_SHARD && pp.hi > pp.lo) {
        /* the neighbour rows of the range, for the central differences */
        size_t below = pp.lo > 0 ? pp.lo - 1 : J.cyc_v ? nv - 1 : nv;
        size_t above = pp.hi < nv ? pp.hi : J.cyc_v ? 0 : nv;
        if (below < nv && (below < pp.lo || below >= pp.hi))
            surf_row(&J, below, 0);
        if (above < nv && above != below && (above < pp.lo || above >= pp.hi))
            surf_row(&J, above, 0);
    }
    if (!rc)
        rc = par_part_for(&pp, "wrinkly normals", surf_normals, &J);
    if (rc) {
        rt_fail(e, rc, "wrinkly surface interrupted");
        goto done;
    }
    if ((rc = par_part_rows(&pp, out->pos, nvert * 3 * sizeof(float), nu * 3 * sizeof(float), e)) ||
        (rc = par_part_rows(&pp, out->nrm, nvert * 3 * sizeof(float), nu * 3 * sizeof(float), e)) ||
        (rc = par_part_rows(&pp, out->col, nvert * 4 * sizeof(float), nu * 4 * sizeof(float), e)))
        goto done;
    size_t t = 0;
    for (size_t j = 0; j < qv; j++)
        for (size_t i = 0; i < qu; i++) {
            uint32_t a = (uint32_t)(j * nu + i), b = (uint32_t)(j * nu + (i + 1) % nu);
            uint32_t c = (uint32_t)(((j + 1) % nv) * nu + (i + 1) % nu), d = (uint32_t)(((j + 1) % nv) * nu + i);
            uint32_t *tr = out->tri + 3 * t;
            if (side < 0) /* counter-clockwise seen from the side N points to */
                b ^= d, d ^= b, b ^= d;
            tr[0] = a, tr[1] = b, tr[2] = c;
            tr[3] = a, tr[4] = c, tr[5] = d;
            t += 2;
        }
    if (info) {
        info->side = side;
        info->k[0] = k[0];
        info->k[1] = k[1];
        info->samples[0] = nu;
        info->samples[1] = nv;
        info->vertices = nvert;
        info->triangles = ntri;
    }
done:
    rt_free(ku);
    rt_free(kv);
    rt_free(su);
    rt_free(sv);
    rt_free(r);
    if (rc) {
        mesh_free(out);
        mesh_init(out, 1, 1);
    }
    return rc;
}
