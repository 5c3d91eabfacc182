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

static int level_for(double len, double target, int b, int kmax)
{
    int k = 0;
    double l = len;
    while (l > target && k < kmax) {
        l /= b;
        k++;
    }
    return k;
}

static rt_code check_axis(const char *what, int n, const wrinkly_axis *ax, rt_error *e)
{
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "wrinkly %s needs at least 1 control point, got %d", what, n);
    if (ax->m < 0 || ax->m > 50)
        return rt_fail(e, RT_EINVAL, "wrinkly %s crossing count M = %d; expected 0..50", what, ax->m);
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
    ist_spec sp = {.n = n, .m = ax->m, .k = k, .axis = ax->cyclic ? IST_CYCLIC : IST_TRANSLATION};
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
    int bb = 2 * ax->m + 1;
    uint64_t s = 1; /* keep the closed form exact */
    for (int q = 0; q < sp.k; q++) {
        if (s > ((uint64_t)1 << 50) / (uint64_t)bb) {
            sp.k = q;
            break;
        }
        s *= (uint64_t)bb;
    }
    rc = ist_init(map, &sp, e);
    if (rc) {
        rt_free(pos);
        return rc;
    }
    *out = pos;
    *count = tot;
    return RT_OK;
}

void wrinkly_curve_levels(const wrinkly_curve *c, const wrinkly_opts *o, int *ki)
{
    double lam = lam_of(o->tension);
    int b = 2 * c->ax.m + 1;
    int kmax = o->kmax > 0 ? o->kmax : 8;
    for (int i = 0; i < c->n; i++) {
        if (o->tol > 0 && b > 1) {
            double len = 0, p0[2], p1[2], d[2];
            wrinkly_curve_base(c, lam, i, p0, d);
            for (int q = 1; q <= 16; q++) {
                wrinkly_curve_base(c, lam, i + q / 16.0, p1, d);
                len += hypot(p1[0] - p0[0], p1[1] - p0[1]);
                p0[0] = p1[0], p0[1] = p1[1];
            }
            ki[i] = level_for(len, o->tol, b, kmax);
        } else {
            ki[i] = o->k < 0 ? 0 : o->k > kmax ? kmax : o->k;
        }
    }
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
    wrinkly_curve_levels(c, o, ki);
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

static double proj_len(const wrinkly_opts *o, const double a[3], const double b[3], int *ok)
{
    if (o->cam) {
        double ax, ay, az, bx, by, bz;
        if (camera_project(o->cam, o->width, o->height, a, &ax, &ay, &az) ||
            camera_project(o->cam, o->width, o->height, b, &bx, &by, &bz)) {
            *ok = 0;
            return 0;
        }
        return hypot(ax - bx, ay - by);
    }
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* K_i per base interval of both axes (§5.2, wrinkly.h). */
void wrinkly_surface_levels(const wrinkly_surface *s, const wrinkly_opts *o, int *ku, int *kv)
{
    double lam = lam_of(o->tension);
    int kmax = o->kmax > 0 ? o->kmax : 8;
    int bu = 2 * s->au.m + 1, bv = 2 * s->av.m + 1;
    int adaptive = o->cam || o->tol > 0;
    double target = o->cam ? (o->pixel > 0 ? o->pixel : 1.0) : o->tol;
    int kf = o->k < 0 ? 0 : o->k > kmax ? kmax : o->k;
    for (int i = 0; i < s->nu; i++)
        ku[i] = adaptive ? 0 : kf;
    for (int j = 0; j < s->nv; j++)
        kv[j] = adaptive ? 0 : kf;
    if (!adaptive)
        return;
    enum { G = 5 };
    for (int j = 0; j < s->nv; j++)
        for (int i = 0; i < s->nu; i++) {
            double g[G][G][3], nn[3];
            for (int b = 0; b < G; b++)
                for (int a = 0; a < G; a++)
                    wrinkly_surface_base(s, lam, i + a / (double)(G - 1), j + b / (double)(G - 1), g[b][a], nn);
            double lu = 0, lv = 0;
            for (int r = 0; r < G; r++) {
                double su = 0, sv = 0;
                for (int q = 0; q + 1 < G; q++) {
                    int ok = 1;
                    su += proj_len(o, g[r][q], g[r][q + 1], &ok);
                    sv += proj_len(o, g[q][r], g[q + 1][r], &ok);
                }
                lu = su > lu ? su : lu;
                lv = sv > lv ? sv : lv;
            }
            int a = bu > 1 ? level_for(lu, target, bu, kmax) : 0;
            int c = bv > 1 ? level_for(lv, target, bv, kmax) : 0;
            ku[i] = a > ku[i] ? a : ku[i];
            kv[j] = c > kv[j] ? c : kv[j];
        }
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
    wrinkly_surface_levels(s, o, ku, kv);
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
    r = rt_malloc(rt_mul_size(nvert, 3 * sizeof(double)));
    rt_free(out->nrm);
    rt_free(out->col);
    out->pos = rt_malloc(rt_mul_size(nvert, 3 * sizeof(float)));
    out->nrm = rt_malloc(rt_mul_size(nvert, 3 * sizeof(float)));
    out->col = rt_malloc(rt_mul_size(nvert, 4 * sizeof(float)));
    out->tri = rt_malloc(rt_mul_size(ntri ? ntri : 1, 3 * sizeof(uint32_t)));
    if (!r || !out->pos || !out->nrm || !out->col || !out->tri) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for a %zu-vertex wrinkly mesh", nvert);
        goto done;
    }
    out->nv = out->cap_v = nvert;
    out->nt = out->cap_t = ntri;
    surf_job J = {s, o, su, sv, nu, nv, s->au.cyclic, s->av.cyclic, r, out, side};
    rc = par_for(run, "wrinkly surface", nv, surf_row, &J);
    if (!rc)
        rc = par_for(run, "wrinkly normals", nv, surf_normals, &J);
    if (rc) {
        rt_fail(e, rc, "wrinkly surface interrupted");
        goto done;
    }
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
