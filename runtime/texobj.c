/* texobj.c — textured objects cut out of a solid texture (seed 000 §3, §7),
 * field volumes and slices. */
#include "texobj.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"

#define EPS_T 1e-9

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void unit3(const double a[3], double r[3])
{
    double l = sqrt(dot3(a, a));
    for (int i = 0; i < 3; i++)
        r[i] = l > 0 ? a[i] / l : 0.0;
}

void texobj_opts_default(texobj_opts *o)
{
    memset(o, 0, sizeof *o);
    o->light[0] = o->light[1] = o->light[2] = 1;
    o->ambient = 0.2;
    o->diffuse = 0.8;
    o->samples = 1;
}

rt_code texobj_shape_check(const texobj_shape *s, rt_error *e)
{
    static const char *names[4] = {"sphere", "cube", "cylinder", "plane"};
    if (s->kind < 0 || s->kind > 3)
        return rt_fail(e, RT_EINVAL, "shape kind %d is not sphere (0), cube (1), cylinder (2) or plane (3)", s->kind);
    for (int i = 0; i < 3; i++)
        if (!isfinite(s->center[i]))
            return rt_fail(e, RT_EINVAL, "%s: centre must be finite numbers", names[s->kind]);
    if (s->kind == TEXOBJ_PLANE) {
        double n2 = dot3(s->normal, s->normal);
        if (!(n2 > 0) || !isfinite(n2))
            return rt_fail(e, RT_EINVAL, "plane: normal (%g, %g, %g) has no direction", s->normal[0], s->normal[1],
                           s->normal[2]);
        return RT_OK;
    }
    if (!(s->radius > 0) || !isfinite(s->radius))
        return rt_fail(e, RT_EINVAL, "%s: %s = %g must be > 0", names[s->kind],
                       s->kind == TEXOBJ_CUBE ? "half side" : "radius", s->radius);
    if (s->kind == TEXOBJ_CYLINDER && (!(s->height > 0) || !isfinite(s->height)))
        return rt_fail(e, RT_EINVAL, "cylinder: height = %g must be > 0", s->height);
    return RT_OK;
}

static int hit_sphere(const texobj_shape *s, const double o[3], const double d[3], double *t, double n[3])
{
    double oc[3] = {o[0] - s->center[0], o[1] - s->center[1], o[2] - s->center[2]};
    double b = dot3(oc, d), c = dot3(oc, oc) - s->radius * s->radius;
    double disc = b * b - c;
    if (disc < 0)
        return 0;
    double sq = sqrt(disc), tt = -b - sq;
    if (tt <= EPS_T)
        tt = -b + sq;
    if (tt <= EPS_T)
        return 0;
    for (int i = 0; i < 3; i++)
        n[i] = (oc[i] + tt * d[i]) / s->radius;
    *t = tt;
    return 1;
}

static int hit_cube(const texobj_shape *s, const double o[3], const double d[3], double *t, double n[3])
{
    double tn = -INFINITY, tf = INFINITY;
    int an = -1, af = -1;
    for (int a = 0; a < 3; a++) {
        double lo = s->center[a] - s->radius, hi = s->center[a] + s->radius;
        if (d[a] == 0) {
            if (o[a] < lo || o[a] > hi)
                return 0;
            continue;
        }
        double t1 = (lo - o[a]) / d[a], t2 = (hi - o[a]) / d[a];
        if (t1 > t2) {
            double q = t1;
            t1 = t2;
            t2 = q;
        }
        if (t1 > tn)
            tn = t1, an = a;
        if (t2 < tf)
            tf = t2, af = a;
    }
    if (tn > tf || tf <= EPS_T)
        return 0;
    int axis;
    double sign;
    if (tn > EPS_T) {
        *t = tn;
        axis = an;
        sign = d[an] > 0 ? -1.0 : 1.0;
    } else {
        *t = tf;
        axis = af;
        sign = d[af] > 0 ? 1.0 : -1.0;
    }
    n[0] = n[1] = n[2] = 0;
    n[axis] = sign;
    return 1;
}

static int hit_cylinder(const texobj_shape *s, const double o[3], const double d[3], double *t, double n[3])
{
    const double *c = s->center;
    double r = s->radius, hh = s->height / 2, best = INFINITY;
    double dx = o[0] - c[0], dz = o[2] - c[2];
    double a = d[0] * d[0] + d[2] * d[2], b = dx * d[0] + dz * d[2], cc = dx * dx + dz * dz - r * r;
    if (a > 0) {
        double disc = b * b - a * cc;
        if (disc >= 0) {
            double sq = sqrt(disc);
            double roots[2] = {(-b - sq) / a, (-b + sq) / a};
            for (int i = 0; i < 2; i++) {
                double tt = roots[i];
                if (tt > EPS_T && tt < best && fabs(o[1] + tt * d[1] - c[1]) <= hh) {
                    best = tt;
                    n[0] = (dx + tt * d[0]) / r;
                    n[1] = 0;
                    n[2] = (dz + tt * d[2]) / r;
                }
            }
        }
    }
    if (d[1] != 0)
        for (int k = -1; k <= 1; k += 2) {
            double tt = (c[1] + k * hh - o[1]) / d[1];
            double px = dx + tt * d[0], pz = dz + tt * d[2];
            if (tt > EPS_T && tt < best && px * px + pz * pz <= r * r) {
                best = tt;
                n[0] = 0;
                n[1] = k;
                n[2] = 0;
            }
        }
    if (best == INFINITY)
        return 0;
    *t = best;
    return 1;
}

static int hit_plane(const texobj_shape *s, const double o[3], const double d[3], double *t, double n[3])
{
    double un[3];
    unit3(s->normal, un);
    double den = dot3(d, un);
    if (fabs(den) < 1e-15)
        return 0;
    double w[3] = {s->center[0] - o[0], s->center[1] - o[1], s->center[2] - o[2]};
    double tt = dot3(w, un) / den;
    if (!(tt > EPS_T) || !isfinite(tt))
        return 0;
    *t = tt;
    for (int i = 0; i < 3; i++)
        n[i] = un[i];
    return 1;
}

int texobj_intersect(const texobj_shape *s, const double o[3], const double dir[3], double *t, double normal[3])
{
    switch (s->kind) {
    case TEXOBJ_SPHERE:
        return hit_sphere(s, o, dir, t, normal);
    case TEXOBJ_CUBE:
        return hit_cube(s, o, dir, t, normal);
    case TEXOBJ_CYLINDER:
        return hit_cylinder(s, o, dir, t, normal);
    case TEXOBJ_PLANE:
        return hit_plane(s, o, dir, t, normal);
    }
    return 0;
}

/* ---- rendering ------------------------------------------------------------ */

typedef struct rjob {
    const texobj_shape *s;
    const camera *cam;
    const texobj_source *src;
    const texobj_opts *o;
    image *im;
    ramp grey;
    double light[3];
    double *acc;      /* per worker: w * TEXOBJ_BAND * 4 */
    uint64_t *rays, *hits; /* per worker */
} rjob;

typedef struct hitbuf {
    size_t n;
    double x[RT_BLOCK], y[RT_BLOCK], z[RT_BLOCK];
    double nrm[RT_BLOCK][3];
    size_t pix[RT_BLOCK]; /* index into acc (pixel * 4) */
} hitbuf;

/* Evaluate the colour source once over the buffered hit points and shade. */
static void flush(const rjob *j, hitbuf *hb, double *acc)
{
    size_t n = hb->n;
    if (!n)
        return;
    float rgba[RT_BLOCK * 4];
    if (j->src->rgb)
        j->src->rgb(j->src->rgb_ctx, n, hb->x, hb->y, hb->z, rgba);
    else {
        double v[RT_BLOCK];
        j->src->field(j->src->field_ctx, n, hb->x, hb->y, hb->z, v);
        const ramp *r = j->src->ramp ? j->src->ramp : &j->grey;
        for (size_t i = 0; i < n; i++)
            ramp_eval(r, v[i], rgba + 4 * i);
    }
    for (size_t i = 0; i < n; i++) {
        double ndl = dot3(hb->nrm[i], j->light);
        double f = j->o->ambient + j->o->diffuse * (ndl > 0 ? ndl : 0.0);
        double *a = acc + hb->pix[i];
        for (int c = 0; c < 3; c++)
            a[c] += rgba[4 * i + c] * f;
        a[3] += rgba[4 * i + 3];
    }
    hb->n = 0;
}

static void render_band(void *ctx, size_t chunk, int worker)
{
    const rjob *j = ctx;
    const image *im = j->im;
    int w = im->w, y0 = (int)chunk * TEXOBJ_BAND, y1 = y0 + TEXOBJ_BAND;
    if (y1 > im->h)
        y1 = im->h;
    int s = j->o->samples;
    double *acc = j->acc + (size_t)worker * (size_t)w * TEXOBJ_BAND * 4;
    memset(acc, 0, (size_t)w * TEXOBJ_BAND * 4 * sizeof *acc);
    hitbuf hb;
    hb.n = 0;
    uint64_t rays = 0, hits = 0;
    for (int py = y0; py < y1; py++)
        for (int px = 0; px < w; px++) {
            size_t pix = ((size_t)(py - y0) * (size_t)w + (size_t)px) * 4;
            for (int sy = 0; sy < s; sy++)
                for (int sx = 0; sx < s; sx++) {
                    double dir[3], t, nrm[3];
                    camera_ray(j->cam, im->w, im->h, px + (sx + 0.5) / s, py + (sy + 0.5) / s, dir);
                    rays++;
                    if (!texobj_intersect(j->s, j->cam->eye, dir, &t, nrm)) {
                        for (int c = 0; c < 4; c++)
                            acc[pix + c] += j->o->background[c];
                        continue;
                    }
                    hits++;
                    if (dot3(nrm, dir) > 0) /* face the camera */
                        for (int c = 0; c < 3; c++)
                            nrm[c] = -nrm[c];
                    size_t k = hb.n++;
                    hb.x[k] = j->cam->eye[0] + t * dir[0];
                    hb.y[k] = j->cam->eye[1] + t * dir[1];
                    hb.z[k] = j->cam->eye[2] + t * dir[2];
                    for (int c = 0; c < 3; c++)
                        hb.nrm[k][c] = nrm[c];
                    hb.pix[k] = pix;
                    if (hb.n == RT_BLOCK)
                        flush(j, &hb, acc);
                }
        }
    flush(j, &hb, acc);
    double inv = 1.0 / (s * s);
    for (int py = y0; py < y1; py++)
        for (int px = 0; px < w; px++) {
            const double *a = acc + ((size_t)(py - y0) * (size_t)w + (size_t)px) * 4;
            float *out = image_at(im, px, py);
            for (int c = 0; c < 4; c++)
                out[c] = (float)(a[c] * inv);
        }
    j->rays[worker] += rays;
    j->hits[worker] += hits;
}

rt_code texobj_render(const texobj_shape *s, const camera *cam, const texobj_source *src, const texobj_opts *o,
                      const rt_run *run, image *im, texobj_stats *st, rt_error *e)
{
    rt_code rc = texobj_shape_check(s, e);
    if (rc)
        return rc;
    if (!src->rgb && !src->field)
        return rt_fail(e, RT_EINVAL, "textured object: no colour source (a field or an RGB function)");
    if (o->samples < 1 || o->samples > 8)
        return rt_fail(e, RT_EINVAL, "samples = %d is out of range (expected 1 .. 8)", o->samples);
    if (!(o->ambient >= 0) || !(o->diffuse >= 0) || !isfinite(o->ambient) || !isfinite(o->diffuse))
        return rt_fail(e, RT_EINVAL, "ambient = %g and diffuse = %g must be >= 0", o->ambient, o->diffuse);
    if (!im->px || im->w < 1 || im->h < 1)
        return rt_fail(e, RT_EINVAL, "textured object: the image is not initialised");
    rjob j = {.s = s, .cam = cam, .src = src, .o = o, .im = im, .grey = ramp_grey()};
    unit3(o->light, j.light);
    size_t nbands = ((size_t)im->h + TEXOBJ_BAND - 1) / TEXOBJ_BAND;
    int nw = par_workers(run, nbands);
    j.acc = rt_malloc((size_t)nw * (size_t)im->w * TEXOBJ_BAND * 4 * sizeof *j.acc);
    j.rays = rt_calloc((size_t)nw, sizeof *j.rays);
    j.hits = rt_calloc((size_t)nw, sizeof *j.hits);
    if (!j.acc || !j.rays || !j.hits) {
        rt_free(j.acc);
        rt_free(j.rays);
        rt_free(j.hits);
        return rt_fail(e, RT_ENOMEM, "out of memory rendering a %d x %d textured object", im->w, im->h);
    }
    /* a chunk is a band of TEXOBJ_BAND rows: a shard fills its bands and
     * counts its rays and hits, merge places the bands and adds the counts (par.h) */
    par_part pp;
    rc = par_part_begin(&pp, run, "textured object", nbands, e);
    if (!rc)
        rc = par_part_for(&pp, "textured object", render_band, &j);
    uint64_t cnt[2] = {0, 0};
    for (int w = 0; w < nw; w++) {
        cnt[0] += j.rays[w];
        cnt[1] += j.hits[w];
    }
    if (!rc && pp.mode != PAR_FULL) {
        size_t band = (size_t)im->w * TEXOBJ_BAND * 4 * sizeof *im->px;
        rc = par_part_rows(&pp, im->px, (size_t)im->w * (size_t)im->h * 4 * sizeof *im->px, band, e);
        if (!rc)
            rc = par_part_sum(&pp, cnt, 2, e);
        if (rc) {
            rt_free(j.acc);
            rt_free(j.rays);
            rt_free(j.hits);
            return rc;
        }
    }
    if (st) {
        st->rays = cnt[0];
        st->hits = cnt[1];
    }
    rt_free(j.acc);
    rt_free(j.rays);
    rt_free(j.hits);
    if (rc)
        return rt_fail(e, rc, "interrupted");
    return RT_OK;
}

/* ---- volumes and slices ------------------------------------------------------ */

typedef struct vjob {
    rt_field_fn f;
    const void *ctx;
    volume *vol;
} vjob;

static void volume_slice(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    const vjob *j = ctx;
    volume *v = j->vol;
    size_t per = (size_t)v->nx * (size_t)v->ny;
    double x[RT_BLOCK], y[RT_BLOCK], z[RT_BLOCK], out[RT_BLOCK];
    double zc = v->lo[2] + (v->hi[2] - v->lo[2]) * ((double)chunk + 0.5) / v->nz;
    for (size_t b = 0; b < per; b += RT_BLOCK) {
        size_t len = per - b < RT_BLOCK ? per - b : RT_BLOCK;
        for (size_t i = 0; i < len; i++) {
            size_t q = b + i, ix = q % (size_t)v->nx, iy = q / (size_t)v->nx;
            x[i] = v->lo[0] + (v->hi[0] - v->lo[0]) * ((double)ix + 0.5) / v->nx;
            y[i] = v->lo[1] + (v->hi[1] - v->lo[1]) * ((double)iy + 0.5) / v->ny;
            z[i] = zc;
        }
        j->f(j->ctx, len, x, y, z, out);
        float *dst = v->v + chunk * per + b;
        for (size_t i = 0; i < len; i++)
            dst[i] = (float)out[i];
    }
}

rt_code texobj_sample_volume(rt_field_fn f, const void *ctx, volume *vol, const rt_run *run, rt_error *e)
{
    if (!f || !vol->v || vol->nx < 1 || vol->ny < 1 || vol->nz < 1)
        return rt_fail(e, RT_EINVAL, "volume sampling: no field or the volume is not initialised");
    vjob j = {f, ctx, vol};
    par_part pp; /* one chunk per z slice (par.h) */
    size_t slice = (size_t)vol->nx * (size_t)vol->ny * sizeof *vol->v;
    rt_code rc = par_part_begin(&pp, run, "sample volume", (size_t)vol->nz, e);
    if (rc)
        return rc;
    rc = par_part_for(&pp, "sample volume", volume_slice, &j);
    return rc ? rt_fail(e, rc, "interrupted") : par_part_rows(&pp, vol->v, slice * (size_t)vol->nz, slice, e);
}

typedef struct sjob {
    rt_field_fn f;
    const void *ctx;
    const ramp *r;
    double o[3], u[3], v[3];
    image *im;
} sjob;

static void slice_row(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    const sjob *j = ctx;
    image *im = j->im;
    int py = (int)chunk;
    double b = 1.0 - 2.0 * (py + 0.5) / im->h;
    double x[RT_BLOCK], y[RT_BLOCK], z[RT_BLOCK], out[RT_BLOCK];
    for (int p0 = 0; p0 < im->w; p0 += RT_BLOCK) {
        int len = im->w - p0 < RT_BLOCK ? im->w - p0 : RT_BLOCK;
        for (int i = 0; i < len; i++) {
            double a = 2.0 * (p0 + i + 0.5) / im->w - 1.0;
            x[i] = j->o[0] + a * j->u[0] + b * j->v[0];
            y[i] = j->o[1] + a * j->u[1] + b * j->v[1];
            z[i] = j->o[2] + a * j->u[2] + b * j->v[2];
        }
        j->f(j->ctx, (size_t)len, x, y, z, out);
        for (int i = 0; i < len; i++)
            ramp_eval(j->r, out[i], image_at(im, p0 + i, py));
    }
}

rt_code texobj_slice(rt_field_fn f, const void *ctx, const ramp *r, const double origin[3], const double u[3],
                     const double v[3], const rt_run *run, image *im, rt_error *e)
{
    if (!f || !im->px || im->w < 1 || im->h < 1)
        return rt_fail(e, RT_EINVAL, "slice: no field or the image is not initialised");
    ramp grey = ramp_grey();
    sjob j;
    j.f = f;
    j.ctx = ctx;
    j.r = r ? r : &grey;
    for (int i = 0; i < 3; i++) {
        j.o[i] = origin[i];
        j.u[i] = u[i];
        j.v[i] = v[i];
    }
    j.im = im;
    par_part pp; /* one chunk per row (par.h) */
    size_t row = (size_t)im->w * 4 * sizeof *im->px;
    rt_code rc = par_part_begin(&pp, run, "slice", (size_t)im->h, e);
    if (rc)
        return rc;
    rc = par_part_for(&pp, "slice", slice_row, &j);
    return rc ? rt_fail(e, rc, "interrupted") : par_part_rows(&pp, im->px, row * (size_t)im->h, row, e);
}
