/* raymarch.c — emission–absorption and thresholded-solid ray marching.
 *
 * Seed 001 (hypertexture with RIFS, after Perlin & Hoffert 1989) shows
 * D(x) = sphere(x) · noise(x) rendered with density as transparency and as
 * solids at D >= 0.3 / 0.5 (Figs. 5–8); it does not fix a discretisation.
 * Our reading: fixed steps with midpoint samples, opacity 1 - exp(-σρΔ)
 * (exact for piecewise-constant density), front-to-back compositing; solids
 * by first crossing + bisection, Lambert + ambient shading. See raymarch.h.
 */
#include "raymarch.h"

#include <math.h>
#include <string.h>

#include "par.h"

void rm_defaults(rm_opts *o)
{
    memset(o, 0, sizeof *o);
    o->mode = RM_EMISSION;
    for (int a = 0; a < 3; a++) {
        o->lo[a] = -1;
        o->hi[a] = 1;
    }
    o->step = 1.0 / 128;
    o->sigma = 8;
    for (int a = 0; a < 4; a++) {
        o->emission[a] = 1;
        o->surface[a] = 1;
        o->background[a] = 0;
    }
    o->background[3] = 1;
    o->light[0] = 0.4;
    o->light[1] = 0.8;
    o->light[2] = 0.45;
    o->ambient = 0.25;
    o->threshold = 0.5;
    o->refine = 10;
    o->min_transmittance = 1e-4;
}

void rm_volume_field(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    const volume *v = ctx;
    for (size_t i = 0; i < n; i++)
        out[i] = volume_sample(v, x[i], y[i], z[i]);
}

typedef struct rm_job {
    rt_field_fn f;
    const void *ctx;
    double thr;            /* solid mode: inside when f >= thr */
    rt_field_fn g;         /* emission: the hard support, or NULL */
    const void *gctx;
    const camera *cam;
    const rm_opts *o;
    image *im;
    double light[3];
    double h;
} rm_job;

/* Per-block scratch: rays and gathered sample points. */
typedef struct rays {
    double dir[RT_BLOCK][3];
    double t0[RT_BLOCK], dt[RT_BLOCK];
    long nstep[RT_BLOCK];
    double T[RT_BLOCK], L[RT_BLOCK][3];
    double ta[RT_BLOCK], tb[RT_BLOCK];
    int done[RT_BLOCK], hit[RT_BLOCK];
    size_t idx[RT_BLOCK], idx2[RT_BLOCK];
    double px[RT_BLOCK], py[RT_BLOCK], pz[RT_BLOCK], v[RT_BLOCK];
    double qx[RT_BLOCK], qy[RT_BLOCK], qz[RT_BLOCK];
    double g[3][RT_BLOCK], tmp[RT_BLOCK], tmp2[RT_BLOCK];
    double gprev[RT_BLOCK], seg[RT_BLOCK], tm[RT_BLOCK]; /* emission with a support */
} rays;

/* Slab intersection of eye + t·dir with the box; returns 0 on a miss. */
static int clip_box(const double eye[3], const double dir[3], const double lo[3], const double hi[3],
                    double *t0, double *t1)
{
    double a = 0, b = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (dir[k] == 0) {
            if (eye[k] < lo[k] || eye[k] > hi[k])
                return 0;
            continue;
        }
        double u = (lo[k] - eye[k]) / dir[k], w = (hi[k] - eye[k]) / dir[k];
        if (u > w) {
            double s = u;
            u = w;
            w = s;
        }
        if (u > a)
            a = u;
        if (w < b)
            b = w;
    }
    *t0 = a;
    *t1 = b;
    return b > a;
}

/* Gradient of the field at the m points (qx, qy, qz) into r->g. */
static void grad_block(const rm_job *j, rays *r, size_t m)
{
    double *q[3] = {r->qx, r->qy, r->qz};
    for (int a = 0; a < 3; a++) {
        for (size_t i = 0; i < m; i++)
            q[a][i] += j->h;
        j->f(j->ctx, m, r->qx, r->qy, r->qz, r->tmp);
        for (size_t i = 0; i < m; i++)
            q[a][i] -= 2 * j->h;
        j->f(j->ctx, m, r->qx, r->qy, r->qz, r->tmp2);
        for (size_t i = 0; i < m; i++) {
            q[a][i] += j->h;
            r->g[a][i] = (r->tmp[i] - r->tmp2[i]) / (2 * j->h);
        }
    }
}

/* ambient + (1 - ambient) · max(0, n · light) with n = -g/|g|; a vanishing
 * gradient faces the viewer (n = -dir). */
static double shade(const rm_job *j, const rays *r, size_t gi, const double dir[3])
{
    double n[3] = {-r->g[0][gi], -r->g[1][gi], -r->g[2][gi]};
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(l > 0) || !isfinite(l)) {
        n[0] = -dir[0], n[1] = -dir[1], n[2] = -dir[2];
        l = 1;
    }
    double d = (n[0] * j->light[0] + n[1] * j->light[1] + n[2] * j->light[2]) / l;
    if (!(d > 0))
        d = 0;
    return j->o->ambient + (1 - j->o->ambient) * d;
}

static void point_at(const rm_job *j, const rays *r, size_t i, double t, double *x, double *y, double *z)
{
    const double *eye = j->cam->eye;
    *x = eye[0] + t * r->dir[i][0];
    *y = eye[1] + t * r->dir[i][1];
    *z = eye[2] + t * r->dir[i][2];
}

/* g at one point of ray i; not a number counts as far outside. */
static double g_at(const rm_job *j, const rays *r, size_t i, double t)
{
    double x, y, z, v;
    point_at(j, r, i, t, &x, &y, &z);
    j->g(j->gctx, 1, &x, &y, &z, &v);
    return v <= 0 || v > 0 ? v : INFINITY;
}

/* The root of g on [a, b] (ga, gb of opposite signs): Illinois. */
static double g_root(const rm_job *j, const rays *r, size_t i, double a, double b, double ga,
                     double gb)
{
    double tol = 1e-12 * j->o->step;
    int side = 0;
    double t = 0.5 * (a + b);
    for (int it = 0; it < 60 && b - a > tol; it++) {
        t = (a * gb - b * ga) / (gb - ga);
        if (!(t > a && t < b))
            t = 0.5 * (a + b);
        double gt = g_at(j, r, i, t);
        if (fabs(gt) <= tol)
            break;
        if ((gt <= 0) == (ga <= 0)) {
            a = t, ga = gt;
            if (side == -1)
                gb *= 0.5;
            side = -1;
        } else {
            b = t, gb = gt;
            if (side == 1)
                ga *= 0.5;
            side = 1;
        }
    }
    return t;
}

static void add_piece(rays *r, size_t i, double a, double b, double *best)
{
    r->seg[i] += b - a;
    if (b - a > *best) {
        *best = b - a;
        r->tm[i] = 0.5 * (a + b);
    }
}

/* The inside length of [a, b] on ray i into r->seg[i] (see raymarch.h). */
static void seg_inside(const rm_job *j, rays *r, size_t i, double a, double b, double ga, double gb,
                       int depth, double *best)
{
    double L = b - a; /* rays have unit direction: t is length */
    if (ga > 0 && gb > 0 && ga + gb >= L)
        return;
    if (ga <= 0 && gb <= 0 && ga + gb <= -L) {
        add_piece(r, i, a, b, best);
        return;
    }
    if (depth >= 6) {
        if ((ga <= 0) == (gb <= 0)) {
            if (ga <= 0)
                add_piece(r, i, a, b, best);
            return;
        }
        double t = g_root(j, r, i, a, b, ga, gb);
        if (ga <= 0)
            add_piece(r, i, a, t, best);
        else
            add_piece(r, i, t, b, best);
        return;
    }
    double m = 0.5 * (a + b), gm = g_at(j, r, i, m);
    seg_inside(j, r, i, a, m, ga, gm, depth + 1, best);
    seg_inside(j, r, i, m, b, gm, gb, depth + 1, best);
}

/* With a support: g at the end of step k of each active ray (in a block),
 * then each ray's inside length and sample point for the step. */
static void support_step(const rm_job *j, rays *r, size_t n, long k)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (r->done[i] || k >= r->nstep[i])
            continue;
        point_at(j, r, i, r->t0[i] + (k + 1) * r->dt[i], &r->px[m], &r->py[m], &r->pz[m]);
        r->idx[m++] = i;
    }
    if (!m)
        return;
    j->g(j->gctx, m, r->px, r->py, r->pz, r->v);
    for (size_t s = 0; s < m; s++) {
        size_t i = r->idx[s];
        double gb = r->v[s] <= 0 || r->v[s] > 0 ? r->v[s] : INFINITY, best = 0;
        double a = r->t0[i] + k * r->dt[i], b = r->t0[i] + (k + 1) * r->dt[i];
        r->seg[i] = 0;
        seg_inside(j, r, i, a, b, r->gprev[i], gb, 0, &best);
        r->gprev[i] = gb;
    }
}

static void march_emission(const rm_job *j, rays *r, size_t n)
{
    const rm_opts *o = j->o;
    if (j->g) { /* g at each ray's entry */
        size_t m = 0;
        for (size_t i = 0; i < n; i++) {
            if (r->done[i])
                continue;
            point_at(j, r, i, r->t0[i], &r->px[m], &r->py[m], &r->pz[m]);
            r->idx[m++] = i;
        }
        if (m)
            j->g(j->gctx, m, r->px, r->py, r->pz, r->v);
        for (size_t s = 0; s < m; s++)
            r->gprev[r->idx[s]] = r->v[s] <= 0 || r->v[s] > 0 ? r->v[s] : INFINITY;
    }
    for (long k = 0;; k++) {
        size_t na = 0, live = 0;
        if (j->g)
            support_step(j, r, n, k);
        for (size_t i = 0; i < n; i++) {
            if (r->done[i] || k >= r->nstep[i])
                continue;
            live++;
            double t = r->t0[i] + (k + 0.5) * r->dt[i];
            if (j->g) {
                if (!(r->seg[i] > 0))
                    continue; /* wholly outside the support: no density */
                t = r->tm[i];
            } else {
                r->seg[i] = r->dt[i];
            }
            point_at(j, r, i, t, &r->px[na], &r->py[na], &r->pz[na]);
            r->idx[na++] = i;
        }
        if (!live)
            break;
        if (!na)
            continue;
        j->f(j->ctx, na, r->px, r->py, r->pz, r->v);
        size_t nl = 0; /* samples needing a normal */
        if (o->lighting) {
            for (size_t s = 0; s < na; s++)
                if (r->v[s] > 0) {
                    r->qx[nl] = r->px[s];
                    r->qy[nl] = r->py[s];
                    r->qz[nl] = r->pz[s];
                    r->idx2[nl++] = s;
                }
            if (nl)
                grad_block(j, r, nl);
        }
        size_t li = 0;
        for (size_t s = 0; s < na; s++) {
            size_t i = r->idx[s];
            double rho = r->v[s] > 0 ? r->v[s] : 0; /* NaN -> 0 */
            if (rho == 0)
                continue;
            double alpha = 1 - exp(-o->sigma * rho * r->seg[i]);
            float c[4];
            if (o->emission_ramp)
                ramp_eval(o->emission_ramp, rho, c);
            else
                memcpy(c, o->emission, sizeof c);
            double sh = 1;
            if (o->lighting) {
                while (li < nl && r->idx2[li] < s)
                    li++;
                sh = shade(j, r, li, r->dir[i]);
            }
            for (int a = 0; a < 3; a++)
                r->L[i][a] += r->T[i] * alpha * c[a] * sh;
            r->T[i] *= 1 - alpha;
            if (r->T[i] < o->min_transmittance)
                r->done[i] = 1;
        }
    }
}

static void march_solid(const rm_job *j, rays *r, size_t n)
{
    const rm_opts *o = j->o;
    double thr = j->thr;
    for (long k = 0;; k++) {
        size_t na = 0;
        for (size_t i = 0; i < n; i++) {
            if (r->done[i] || k > r->nstep[i])
                continue;
            point_at(j, r, i, r->t0[i] + k * r->dt[i], &r->px[na], &r->py[na], &r->pz[na]);
            r->idx[na++] = i;
        }
        if (!na)
            break;
        j->f(j->ctx, na, r->px, r->py, r->pz, r->v);
        for (size_t s = 0; s < na; s++) {
            size_t i = r->idx[s];
            if (r->v[s] >= thr) {
                r->done[i] = r->hit[i] = 1;
                r->tb[i] = r->t0[i] + k * r->dt[i];
                r->ta[i] = k ? r->t0[i] + (k - 1) * r->dt[i] : r->tb[i];
            }
        }
    }
    /* Bisection in lock-step over all hits: ta outside, tb inside. */
    size_t nh = 0;
    for (size_t i = 0; i < n; i++)
        if (r->hit[i])
            r->idx2[nh++] = i;
    for (int it = 0; it < o->refine && nh; it++) {
        for (size_t s = 0; s < nh; s++) {
            size_t i = r->idx2[s];
            point_at(j, r, i, 0.5 * (r->ta[i] + r->tb[i]), &r->px[s], &r->py[s], &r->pz[s]);
        }
        j->f(j->ctx, nh, r->px, r->py, r->pz, r->v);
        for (size_t s = 0; s < nh; s++) {
            size_t i = r->idx2[s];
            double mid = 0.5 * (r->ta[i] + r->tb[i]);
            if (r->v[s] >= thr)
                r->tb[i] = mid;
            else
                r->ta[i] = mid;
        }
    }
    if (!nh)
        return;
    for (size_t s = 0; s < nh; s++) {
        size_t i = r->idx2[s];
        point_at(j, r, i, r->tb[i], &r->qx[s], &r->qy[s], &r->qz[s]);
    }
    grad_block(j, r, nh);
    for (size_t s = 0; s < nh; s++) {
        size_t i = r->idx2[s];
        double sh = shade(j, r, s, r->dir[i]);
        for (int a = 0; a < 3; a++)
            r->L[i][a] = o->surface[a] * sh;
        r->T[i] = 0;
    }
}

static void row_fn(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    const rm_job *j = ctx;
    const rm_opts *o = j->o;
    image *im = j->im;
    int y = (int)chunk;
    rays r; /* ~60 KB on the stack */
    for (int x0 = 0; x0 < im->w; x0 += RT_BLOCK) {
        size_t n = (size_t)(im->w - x0) < RT_BLOCK ? (size_t)(im->w - x0) : RT_BLOCK;
        for (size_t i = 0; i < n; i++) {
            camera_ray(j->cam, im->w, im->h, x0 + (double)i + 0.5, y + 0.5, r.dir[i]);
            double t0, t1;
            r.T[i] = 1;
            r.L[i][0] = r.L[i][1] = r.L[i][2] = 0;
            r.done[i] = r.hit[i] = 0;
            if (clip_box(j->cam->eye, r.dir[i], o->lo, o->hi, &t0, &t1)) {
                double ns = ceil((t1 - t0) / o->step);
                r.nstep[i] = ns < 1 ? 1 : (long)ns;
                r.t0[i] = t0;
                r.dt[i] = (t1 - t0) / (double)r.nstep[i];
            } else {
                r.nstep[i] = 0;
                r.done[i] = 1;
            }
        }
        if (o->mode == RM_SOLID)
            march_solid(j, &r, n);
        else
            march_emission(j, &r, n);
        for (size_t i = 0; i < n; i++) {
            float *p = image_at(im, x0 + (int)i, y);
            double T = r.T[i];
            for (int a = 0; a < 3; a++)
                p[a] = (float)(r.L[i][a] + T * o->background[a]);
            p[3] = (float)(1 - T + T * o->background[3]);
        }
    }
}

typedef struct rm_neg {
    rt_field_fn f;
    const void *ctx;
} rm_neg;

static void neg_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                   double *out)
{
    const rm_neg *c = ctx;
    c->f(c->ctx, n, x, y, z, out);
    for (size_t i = 0; i < n; i++)
        out[i] = -out[i];
}

rt_code rm_render(rt_field_fn f, const void *ctx, const camera *cam, const rm_opts *o,
                  const rt_run *run, image *im, rt_error *e)
{
    static const char *axn = "xyz";
    if (!im || !im->px || im->w < 1 || im->h < 1)
        return rt_fail(e, RT_EINVAL, "raymarch needs an allocated image");
    if (o->mode != RM_EMISSION && o->mode != RM_SOLID)
        return rt_fail(e, RT_EINVAL, "raymarch mode %d is not 0 (emission) or 1 (solid)", o->mode);
    double diag = 0;
    for (int a = 0; a < 3; a++) {
        if (!(o->lo[a] < o->hi[a]) || !isfinite(o->hi[a] - o->lo[a]))
            return rt_fail(e, RT_EINVAL, "raymarch box along %c: lo %g is not below hi %g", axn[a],
                           o->lo[a], o->hi[a]);
        diag += (o->hi[a] - o->lo[a]) * (o->hi[a] - o->lo[a]);
    }
    if (!(o->step > 0) || !isfinite(o->step))
        return rt_fail(e, RT_EINVAL, "raymarch step %g is not a positive number", o->step);
    if (sqrt(diag) / o->step > 1e8)
        return rt_fail(e, RT_EINVAL, "raymarch step %g is too small for the box (over 1e8 steps per ray)",
                       o->step);
    if (!(o->sigma >= 0) || !isfinite(o->sigma))
        return rt_fail(e, RT_EINVAL, "raymarch sigma %g is not a non-negative number", o->sigma);
    if (!(o->ambient >= 0 && o->ambient <= 1))
        return rt_fail(e, RT_EINVAL, "raymarch ambient %g is not in [0, 1]", o->ambient);
    if (o->refine < 0 || o->refine > 60)
        return rt_fail(e, RT_EINVAL, "raymarch refine %d is not in 0..60", o->refine);
    if (!(o->min_transmittance >= 0 && o->min_transmittance < 1))
        return rt_fail(e, RT_EINVAL, "raymarch min_transmittance %g is not in [0, 1)",
                       o->min_transmittance);
    if (!isfinite(o->threshold))
        return rt_fail(e, RT_EINVAL, "raymarch threshold %g is not a finite number", o->threshold);
    if (!(cam->tan_half > 0))
        return rt_fail(e, RT_EINVAL, "raymarch camera is not set up (camera_setup)");
    if (!(o->grad_h >= 0) || !isfinite(o->grad_h))
        return rt_fail(e, RT_EINVAL, "raymarch grad_h %g is not a non-negative number", o->grad_h);
    rm_job j;
    j.f = f;
    j.ctx = ctx;
    j.thr = o->threshold;
    j.g = o->mode == RM_EMISSION ? o->support : NULL;
    j.gctx = o->support_ctx;
    rm_neg neg = {o->sdf, o->sdf_ctx};
    if (o->mode == RM_SOLID && o->sdf) { /* march -g against 0: inside is g <= 0 */
        j.f = neg_fn;
        j.ctx = &neg;
        j.thr = 0;
    }
    j.cam = cam;
    j.o = o;
    j.im = im;
    j.h = o->grad_h > 0 ? o->grad_h : 0.5 * o->step;
    double l = sqrt(o->light[0] * o->light[0] + o->light[1] * o->light[1] + o->light[2] * o->light[2]);
    for (int a = 0; a < 3; a++)
        j.light[a] = l > 0 ? o->light[a] / l : 0;
    /* one chunk per row: a shard fills its rows, merge places them (par.h) */
    par_part pp;
    size_t row = (size_t)im->w * 4 * sizeof *im->px;
    rt_code rc = par_part_begin(&pp, run, "raymarch", (size_t)im->h, e);
    if (rc)
        return rc;
    if (par_part_for(&pp, "raymarch", row_fn, &j))
        return rt_fail(e, RT_ECANCEL, "raymarch interrupted");
    return par_part_rows(&pp, im->px, row * (size_t)im->h, row, e);
}
