/* test_wrinkly.c — wrinkly curves and surfaces (seed 002 §5). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "ist.h"
#include "rt_alloc.h"
#include "mesh.h"
#include "rng.h"
#include "wrinkly.h"

static void make_curve_pts(wrinkly_point *p, int n, double rad)
{
    for (int i = 0; i < n; i++) {
        double a = 6.283185307179586 * i / n;
        memset(&p[i], 0, sizeof p[i]);
        p[i].pos[0] = rad * cos(a) * (1 + 0.2 * (i % 3));
        p[i].pos[1] = rad * sin(a);
        p[i].h = 0.1 * ((i * 7) % 5) - 0.2;
        p[i].rgb[0] = i / (double)n;
        p[i].rgb[1] = 0.5;
        p[i].rgb[2] = 1 - i / (double)n;
        p[i].opacity = 1;
    }
}

static void unit2(double v[2])
{
    double l = hypot(v[0], v[1]);
    v[0] /= l, v[1] /= l;
}

static void test_curve(void)
{
    enum { N = 7 };
    wrinkly_point p[N];
    make_curve_pts(p, N, 2.0);
    for (int cyc = 0; cyc < 2; cyc++) {
        wrinkly_curve c = {p, N, {cyc, 1, 1}};
        /* G1: at the joint u = i both segments are tangent to p_i - p_{i-1} */
        for (int i = 1; i < N; i++) {
            double q[2], dl[2], dr[2];
            wrinkly_curve_base(&c, 2.0 / 3, i - 1e-13, q, dl);
            wrinkly_curve_base(&c, 2.0 / 3, i, q, dr);
            double t[2] = {p[i].pos[0] - p[i - 1].pos[0], p[i].pos[1] - p[i - 1].pos[1]};
            unit2(dl), unit2(dr), unit2(t);
            CHECK(fabs(dl[0] * t[1] - dl[1] * t[0]) < 1e-9 && dl[0] * t[0] + dl[1] * t[1] > 0, "left tangent at %d", i);
            CHECK(fabs(dr[0] * t[1] - dr[1] * t[0]) < 1e-9 && dr[0] * t[0] + dr[1] * t[1] > 0, "right tangent at %d", i);
            CHECK_NEAR(q[0], 0.5 * (p[i].pos[0] + p[i - 1].pos[0]), 1e-12, "joint at the midpoint");
        }
        /* fixed points: R(i + 1/2) = (p_{i-1} + 6p_i + p_{i+1})/8 + H N with
         * H = (h_{i-1} + 6h_i + h_{i+1})/8 and N ⊥ (p_{i+1} - p_{i-1})
         * (uniform quadratic B-spline, λ = 2/3) */
        wrinkly_opts o;
        wrinkly_opts_default(&o);
        o.k = 3;
        wrinkly_polyline pl;
        rt_error e;
        CHECK(wrinkly_curve_sample(&c, &o, &pl, &e) == RT_OK, "sample: %s", e.msg);
        CHECK(pl.n == (size_t)N * 27 + (cyc ? 0 : 2), "Σ S_i samples (+2 ends): %zu", pl.n);
        CHECK(pl.closed == cyc, "closed flag");
        int found = 0;
        for (size_t q = 0; q < pl.n; q++) {
            double u = pl.u[q];
            int i = (int)floor(u);
            if (fabs(u - (i + 0.5)) > 1e-12 || i < 1 || i > N - 2)
                continue;
            found++;
            const wrinkly_point *a = &p[i - 1], *b = &p[i], *d = &p[i + 1];
            double P[2], T[2], H = (a->h + 6 * b->h + d->h) / 8;
            for (int k = 0; k < 2; k++) {
                P[k] = (a->pos[k] + 6 * b->pos[k] + d->pos[k]) / 8;
                T[k] = d->pos[k] - a->pos[k];
            }
            unit2(T);
            CHECK_NEAR(pl.xy[2 * q], P[0] - H * T[1], 1e-9, "fixed point x");
            CHECK_NEAR(pl.xy[2 * q + 1], P[1] + H * T[0], 1e-9, "fixed point y");
            CHECK_NEAR(pl.rgba[4 * q], (a->rgb[0] + 6 * b->rgb[0] + d->rgb[0]) / 8, 1e-6, "fixed colour");
        }
        CHECK(found == N - 2, "fixed points sampled: %d", found);
        /* crack remedy: the height step across a joint shrinks */
        double step[2];
        for (int band = 0; band < 2; band++) {
            o.k = 4;
            o.crack_band = band ? 0.2 : 0;
            wrinkly_polyline p2;
            wrinkly_curve_sample(&c, &o, &p2, &e);
            double worst = 0;
            for (size_t q = 1; q < p2.n; q++) {
                if (floor(p2.u[q]) == floor(p2.u[q - 1]) || floor(p2.u[q]) <= 0 || floor(p2.u[q]) >= N)
                    continue;
                double d = hypot(p2.xy[2 * q] - p2.xy[2 * q - 2], p2.xy[2 * q + 1] - p2.xy[2 * q - 1]);
                worst = d > worst ? d : worst;
            }
            step[band] = worst;
            wrinkly_polyline_free(&p2);
        }
        CHECK(step[1] < 0.5 * step[0], "crack band narrows the joint step: %g vs %g", step[1], step[0]);
        o.crack_band = 0;
        /* world tolerance: every sub-interval at most tol long → K_i from lengths */
        o.tol = 0.05;
        wrinkly_polyline p3;
        CHECK(wrinkly_curve_sample(&c, &o, &p3, &e) == RT_OK, "tol");
        CHECK(p3.k >= 2 && p3.k <= 4, "K from tolerance: %d", p3.k);
        wrinkly_polyline_free(&p3);
        wrinkly_polyline_free(&pl);
    }
}

/* Torus-like control mesh: major radius 3, minor 1. */
static wrinkly_point *torus(int nu, int nv, uint64_t seed)
{
    wrinkly_point *p = rt_calloc((size_t)nu * nv, sizeof *p);
    rng r;
    rng_init(&r, seed, 0);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            double a = 6.283185307179586 * i / nu, b = 6.283185307179586 * j / nv;
            wrinkly_point *q = &p[j * nu + i];
            q->pos[0] = (3 + cos(b)) * cos(a);
            q->pos[1] = sin(b);
            q->pos[2] = (3 + cos(b)) * sin(a);
            q->h = 0.3 * rng_uniform(&r);
            q->rgb[0] = rng_uniform(&r), q->rgb[1] = 0.6, q->rgb[2] = 0.3;
            q->opacity = 1;
        }
    return p;
}

static void test_surface(void)
{
    int nu = 8, nv = 6;
    wrinkly_point *p = torus(nu, nv, 5);
    for (int kind = 0; kind < 3; kind++) {
        /* 0 torus (closed both ways), 1 tube (v open), 2 sheet (both open) */
        wrinkly_surface s = {p, nu, nv, {kind < 2, 1, 1}, {kind == 0, kind != 1, 1}};
        wrinkly_opts o;
        wrinkly_opts_default(&o);
        o.k = 2;
        o.normal = WRINKLY_NORMAL_UV; /* the winding test below follows P_u × P_v */
        mesh m;
        wrinkly_info info;
        rt_error e;
        CHECK(wrinkly_surface_mesh(&s, &o, NULL, &m, &info, &e) == RT_OK, "mesh: %s", e.msg);
        size_t su = (size_t)nu * 9 + (kind < 2 ? 0 : 2), sv = (size_t)nv * 9 + (kind == 0 ? 0 : 2);
        CHECK(info.samples[0] == su && info.samples[1] == sv, "samples %zu × %zu", info.samples[0],
              info.samples[1]);
        CHECK(m.nv == su * sv, "vertex count");
        mesh_stats st;
        mesh_compute_stats(&m, &st, &e);
        CHECK(st.degenerate == 0, "kind %d: %zu degenerate triangles", kind, st.degenerate);
        CHECK(st.nonmanifold_edges == 0, "kind %d: non-manifold", kind);
        if (kind == 0) {
            CHECK(st.boundary_edges == 0, "torus is watertight: %zu boundary edges", st.boundary_edges);
            CHECK(st.euler == 0, "torus Euler characteristic %ld", st.euler);
        } else if (kind == 1) {
            CHECK(st.boundary_edges == 2 * su, "tube has two boundary loops: %zu", st.boundary_edges);
            CHECK(st.euler == 0, "tube Euler characteristic %ld", st.euler);
        } else {
            CHECK(st.boundary_edges == 2 * (su - 1) + 2 * (sv - 1), "sheet boundary: %zu", st.boundary_edges);
            CHECK(st.euler == 1, "sheet Euler characteristic %ld", st.euler);
        }
        if (kind == 0) {
            /* outward winding: the face normal of a triangle points away from the torus axis ring */
            const uint32_t *t = m.tri;
            const float *a = m.pos + 3 * t[0], *b = m.pos + 3 * t[1], *c = m.pos + 3 * t[2];
            double u1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, u2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double n[3] = {u1[1] * u2[2] - u1[2] * u2[1], u1[2] * u2[0] - u1[0] * u2[2], u1[0] * u2[1] - u1[1] * u2[0]};
            double ring = hypot(a[0], a[2]);
            double out[3] = {a[0] - 3 * a[0] / ring, a[1], a[2] - 3 * a[2] / ring};
            double dot = n[0] * out[0] + n[1] * out[1] + n[2] * out[2];
            /* this torus has P_u = (-sin a, 0, cos a), P_v = (0, 1, 0) at b = 0, so
             * P_u × P_v = (-cos a, 0, -sin a) points inward: triangles follow it */
            CHECK(dot < 0, "triangles wind counter-clockwise about P_u × P_v: %g", dot);
            /* byte-identical for threads 1, 2, 4 */
            for (int th = 2; th <= 4; th += 2) {
                rt_run run = {th, NULL, 0};
                mesh m2;
                wrinkly_opts o2 = o;
                o2.jitter = 1;
                o2.extra = 1;
                o2.seed = 9;
                mesh m1;
                wrinkly_surface_mesh(&s, &o2, NULL, &m1, NULL, &e);
                CHECK(wrinkly_surface_mesh(&s, &o2, &run, &m2, NULL, &e) == RT_OK, "threads");
                CHECK(m1.nv == m2.nv && m1.nt == m2.nt && !memcmp(m1.pos, m2.pos, m1.nv * 12) &&
                          !memcmp(m1.col, m2.col, m1.nv * 16) && !memcmp(m1.nrm, m2.nrm, m1.nv * 12) &&
                          !memcmp(m1.tri, m2.tri, m1.nt * 12),
                      "threads %d identical", th);
                mesh_free(&m1);
                mesh_free(&m2);
            }
        }
        mesh_free(&m);
    }
    /* LOD: a camera farther away needs fewer triangles; counts follow the
     * pixel area, not (2M+1)^K */
    wrinkly_surface s = {p, nu, nv, {1, 1, 1}, {1, 1, 1}};
    size_t prev = (size_t)-1;
    for (int q = 0; q < 4; q++) {
        double dist = 8.0 * pow(3.0, q);
        camera cam;
        camera_orbit(&cam, (double[3]){0, 0, 0}, dist, 20, 30, 40);
        wrinkly_opts o;
        wrinkly_opts_default(&o);
        o.cam = &cam;
        o.width = o.height = 200;
        o.kmax = 6;
        mesh m;
        wrinkly_info info;
        rt_error e;
        CHECK(wrinkly_surface_mesh(&s, &o, NULL, &m, &info, &e) == RT_OK, "lod: %s", e.msg);
        CHECK(m.nt < prev, "distance %g: %zu triangles, fewer than %zu", dist, m.nt, prev);
        /* sub-intervals end between 1/(2M+1) and 1 pixel on each axis, and the
         * far side of the torus is tessellated too: tens of triangles per
         * pixel at the closest view (47× here since K_i bounds every
         * sub-interval with its heights, 24× with the old mean-length rule) */
        CHECK(m.nt <= 60 * 200 * 200, "distance %g: %zu triangles within 60× the pixel count", dist, m.nt);
        if (getenv("WRINKLY_VERBOSE"))
            printf("distance %g: K %d,%d, %zu triangles\n", dist, info.k[0], info.k[1], m.nt);
        prev = m.nt;
        mesh_free(&m);
    }
    /* validation */
    wrinkly_surface bad = {p, 0, nv, {1, 1, 1}, {1, 1, 1}};
    wrinkly_opts o;
    wrinkly_opts_default(&o);
    mesh m;
    rt_error e;
    CHECK(wrinkly_surface_mesh(&bad, &o, NULL, &m, NULL, &e) == RT_EINVAL, "nu = 0 refused");
    CHECK(strcmp(e.msg, "wrinkly surface (u axis) needs at least 1 control point, got 0") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    rt_free(p);
}


/* Signed volume of a triangle mesh, Σ a·(b × c)/6 (positive: outward winding). */
static double signed_volume(const mesh *m)
{
    double v = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const float *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                    *c = m->pos + 3 * m->tri[3 * t + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6;
    }
    return v;
}

/* Orientation (wrinkly.h): the torus in both grid orders (u around the
 * axis or around the tube) is outward by default and with "outward",
 * inward with "inward", and follows P_u × P_v with "uv"; heights then push
 * the surface out of the body; a flat sheet has no outward side. */
static void test_orientation(void)
{
    int nu = 8, nv = 6;
    wrinkly_point *p = torus(nu, nv, 5);
    wrinkly_point *q = rt_calloc((size_t)nu * nv, sizeof *q); /* transposed: u runs around the tube */
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++)
            q[i * nv + j] = p[j * nu + i];
    double vol_tube = 2 * 3.14159265358979 * 3 * 3.14159265358979; /* 2π R · π r², R = 3, r = 1 */
    for (int order = 0; order < 2; order++) {
        wrinkly_surface s = order ? (wrinkly_surface){q, nv, nu, {1, 1, 1}, {1, 1, 1}}
                                  : (wrinkly_surface){p, nu, nv, {1, 1, 1}, {1, 1, 1}};
        double sign_uv = 0;
        int sides[4] = {0, 0, 0, 0};
        for (int mode = 0; mode < 4; mode++) {
            wrinkly_opts o;
            wrinkly_opts_default(&o);
            o.k = 1;
            o.normal = mode;
            mesh m;
            rt_error e;
            wrinkly_info info;
            CHECK(wrinkly_surface_mesh(&s, &o, NULL, &m, &info, &e) == RT_OK, "mesh: %s", e.msg);
            double v = signed_volume(&m);
            /* heights 0..0.3 outward grow the tube; the spline base alone is a
             * little inside the control torus */
            if (mode == WRINKLY_NORMAL_AUTO || mode == WRINKLY_NORMAL_OUTWARD)
                CHECK(v > 0.8 * vol_tube, "order %d mode %d: volume %.3f, expected > %.3f", order, mode, v,
                      0.8 * vol_tube);
            else if (mode == WRINKLY_NORMAL_INWARD)
                CHECK(v < 0 && -v < 0.8 * vol_tube, "order %d inward: volume %.3f (heights push in)", order, v);
            else
                sign_uv = v > 0 ? 1 : -1;
            /* every vertex normal agrees with the winding: dot with the face normal > 0 */
            int agree = 0;
            for (size_t t = 0; t < m.nt; t++) {
                const uint32_t *tr = m.tri + 3 * t;
                const float *a = m.pos + 3 * tr[0], *b = m.pos + 3 * tr[1], *c = m.pos + 3 * tr[2];
                double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
                double fn[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
                const float *vn = m.nrm + 3 * tr[0];
                agree += fn[0] * vn[0] + fn[1] * vn[1] + fn[2] * vn[2] > 0;
            }
            CHECK(agree > 0.95 * (double)m.nt, "order %d mode %d: vertex normals follow the winding (%d of %zu)",
                  order, mode, agree, m.nt);
            sides[mode] = info.side;
            mesh_free(&m);
        }
        CHECK(sides[WRINKLY_NORMAL_UV] == 1 && sides[WRINKLY_NORMAL_AUTO] == sides[WRINKLY_NORMAL_OUTWARD] &&
                  sides[WRINKLY_NORMAL_INWARD] == -sides[WRINKLY_NORMAL_OUTWARD],
              "order %d: sides reported %d %d %d %d", order, sides[0], sides[1], sides[2], sides[3]);
        /* this torus: P_u × P_v points inward in one grid order and outward in the other */
        CHECK(sign_uv == (order ? 1 : -1), "order %d: uv orientation %g", order, sign_uv);
    }
    /* a flat sheet: auto keeps P_u × P_v, outward is refused */
    wrinkly_point flat[16];
    memset(flat, 0, sizeof flat);
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            flat[j * 4 + i].pos[0] = i, flat[j * 4 + i].pos[2] = -j, flat[j * 4 + i].opacity = 1;
    wrinkly_surface sh = {flat, 4, 4, {0, 1, 1}, {0, 1, 1}};
    wrinkly_opts o;
    wrinkly_opts_default(&o);
    rt_error e;
    CHECK(wrinkly_surface_side(&sh, &o, &e) == 1, "flat sheet: auto is uv");
    o.normal = WRINKLY_NORMAL_OUTWARD;
    CHECK(wrinkly_surface_side(&sh, &o, &e) == 0 &&
              strcmp(e.msg, "the surface encloses no volume, so no side of it is outward (use normal \"uv\")") == 0,
          "flat sheet: outward refused: %s", e.msg);
    rt_free(p);
    rt_free(q);
}

/* ---- §5.2 LOD, measured independently -------------------------------------
 * The rule (wrinkly.h): K_i is the smallest level at which every level-K_i
 * sub-interval of A_i, heights included, projects to at most the target.
 * With K_i rounds F^{-1} is a rigid shift on each level-K_i sub-interval, so
 * the picture of R over one is a smooth arc: evaluate it densely with an
 * IST of K_i rounds, project, sum the segments, take the longest. */

/* World point → picture: pixels with a camera, the point itself without. */
static void lod_proj(const camera *cam, int w, int h, const double x[3], double out[2], int *ok)
{
    if (!cam) {
        out[0] = x[0], out[1] = x[1];
        return;
    }
    double z;
    if (camera_project(cam, w, h, x, &out[0], &out[1], &z))
        *ok = 0;
}

static double lod_dist3(const camera *cam, int w, int h, const double a[3], const double b[3])
{
    if (!cam)
        return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    double pa[2], pb[2];
    int ok = 1;
    lod_proj(cam, w, h, a, pa, &ok);
    lod_proj(cam, w, h, b, pb, &ok);
    return ok ? hypot(pa[0] - pb[0], pa[1] - pb[1]) : 0;
}

enum { LOD_DENSE = 24 };

/* Longest projected level-k sub-interval of interval i of a curve. */
static double curve_longest(const wrinkly_curve *c, const camera *cam, int w, int h, int i, int k)
{
    ist t;
    ist_spec sp = {.n = c->n, .m = c->ax.m, .k = k, .axis = c->ax.cyclic ? IST_CYCLIC : IST_TRANSLATION};
    rt_error e;
    if (ist_init(&t, &sp, &e))
        return INFINITY;
    double S = pow(2 * c->ax.m + 1, k), best = 0;
    for (long s = 0; s < (long)S; s++) {
        double len = 0, prev[3];
        for (int q = 0; q <= LOD_DENSE; q++) {
            double f = 1e-7 + (1 - 2e-7) * q / LOD_DENSE, u = i + (s + f) / S, p[2], d[2];
            wrinkly_curve_base(c, 2.0 / 3, u, p, d);
            double l = hypot(d[0], d[1]), H = wrinkly_curve_attr(c, 2.0 / 3, 0, ist_inv(&t, u));
            double x[3] = {p[0] - H * d[1] / l, p[1] + H * d[0] / l, 0};
            if (q)
                len += lod_dist3(cam, w, h, prev, x);
            memcpy(prev, x, sizeof prev);
        }
        best = len > best ? len : best;
    }
    ist_free(&t);
    return best;
}

/* Longest projected level-k sub-interval along axis ax (0 u, 1 v) of base
 * interval i of a surface, over 8 rows per base interval of the other axis
 * (whose F^{-1} has ko rounds). */
static double surf_longest(const wrinkly_surface *s, const camera *cam, int w, int h, int ax, int i, int k, int ko)
{
    const wrinkly_axis *A = ax ? &s->av : &s->au, *O = ax ? &s->au : &s->av;
    int na = ax ? s->nv : s->nu, no = ax ? s->nu : s->nv;
    ist t, to;
    ist_spec sp = {.n = na, .m = A->m, .k = k, .axis = A->cyclic ? IST_CYCLIC : IST_TRANSLATION};
    ist_spec so = {.n = no, .m = O->m, .k = ko, .axis = O->cyclic ? IST_CYCLIC : IST_TRANSLATION};
    rt_error e;
    if (ist_init(&t, &sp, &e))
        return INFINITY;
    if (ist_init(&to, &so, &e)) {
        ist_free(&t);
        return INFINITY;
    }
    double S = pow(2 * A->m + 1, k), best = 0;
    for (int r = 0; r < 8 * no; r++) {
        double ov = (r + 0.37) / 8, osrc = ist_inv(&to, ov);
        for (long sub = 0; sub < (long)S; sub++) {
            double len = 0, prev[3];
            for (int q = 0; q <= LOD_DENSE; q++) {
                double f = 1e-7 + (1 - 2e-7) * q / LOD_DENSE, a = i + (sub + f) / S, src = ist_inv(&t, a);
                double u = ax ? ov : a, v = ax ? a : ov, p[3], n[3];
                wrinkly_surface_base(s, 2.0 / 3, u, v, p, n);
                double H = wrinkly_surface_attr(s, 2.0 / 3, 0, ax ? osrc : src, ax ? src : osrc);
                double x[3] = {p[0] + H * n[0], p[1] + H * n[1], p[2] + H * n[2]};
                if (q)
                    len += lod_dist3(cam, w, h, prev, x);
                memcpy(prev, x, sizeof prev);
            }
            best = len > best ? len : best;
        }
    }
    ist_free(&t);
    ist_free(&to);
    return best;
}

static void test_lod(void)
{
    /* a curve: world tolerance, then a camera looking at its plane */
    enum { N = 7 };
    wrinkly_point p[N];
    make_curve_pts(p, N, 2.0);
    for (int i = 0; i < N; i++)
        p[i].h *= 2; /* heights up to 0.4: they dominate some intervals */
    camera cc;
    camera_orbit(&cc, (double[3]){0, 0, 0}, 9, 0, 0, 40);
    for (int cyc = 0; cyc < 2; cyc++)
        for (int mode = 0; mode < 2; mode++) {
            wrinkly_curve c = {p, N, {cyc, 1, 1}};
            wrinkly_opts o;
            wrinkly_opts_default(&o);
            o.kmax = 8;
            if (mode == 0)
                o.tol = 0.02;
            else
                o.cam = &cc, o.width = o.height = 300, o.pixel = 1;
            double target = mode == 0 ? o.tol : o.pixel;
            int ki[N], wasteful = 0, kmaxed = 0;
            rt_error le;
            CHECK(wrinkly_curve_levels(&c, &o, ki, &le) == RT_OK, "curve levels: %s", le.msg);
            for (int i = 0; i < N; i++) {
                double l = curve_longest(&c, o.cam, o.width, o.height, i, ki[i]);
                CHECK(l <= target, "curve cyc %d mode %d interval %d: K_i %d, longest %g > %g", cyc, mode, i, ki[i], l, target);
                kmaxed += ki[i] == o.kmax;
                if (ki[i] > 0 && curve_longest(&c, o.cam, o.width, o.height, i, ki[i] - 1) > target)
                    wasteful++;
                if (getenv("WRINKLY_VERBOSE"))
                    printf("curve cyc %d mode %d i %d: K %d longest %g, at K-1 %g\n", cyc, mode, i, ki[i], l,
                           ki[i] ? curve_longest(&c, o.cam, o.width, o.height, i, ki[i] - 1) : 0);
            }
            CHECK(kmaxed == 0, "curve cyc %d mode %d: no interval hits kmax", cyc, mode);
            CHECK(wasteful > 0, "curve cyc %d mode %d: K_i - 1 fails somewhere (minimal)", cyc, mode);
        }
    /* a torus with heights: world tolerance, then a camera */
    int nu = 8, nv = 6;
    wrinkly_point *tp = torus(nu, nv, 5);
    wrinkly_surface s = {tp, nu, nv, {1, 1, 1}, {1, 1, 1}};
    camera cam;
    camera_orbit(&cam, (double[3]){0, 0, 0}, 24, 20, 30, 40);
    for (int mode = 0; mode < 2; mode++) {
        wrinkly_opts o;
        wrinkly_opts_default(&o);
        o.kmax = 6;
        if (mode == 0)
            o.tol = 0.1;
        else
            o.cam = &cam, o.width = o.height = 200;
        double target = mode == 0 ? o.tol : o.pixel;
        int ku[8], kv[6], kx[2] = {0, 0};
        rt_error le;
        CHECK(wrinkly_surface_levels(&s, &o, ku, kv, &le) == RT_OK, "surface levels: %s", le.msg);
        for (int i = 0; i < nu; i++)
            kx[0] = ku[i] > kx[0] ? ku[i] : kx[0];
        for (int j = 0; j < nv; j++)
            kx[1] = kv[j] > kx[1] ? kv[j] : kx[1];
        for (int ax = 0; ax < 2; ax++) {
            int wasteful = 0, na = ax ? nv : nu;
            for (int i = 0; i < na; i++) {
                int k = ax ? kv[i] : ku[i];
                double l = surf_longest(&s, o.cam, o.width, o.height, ax, i, k, kx[!ax]);
                CHECK(l <= target, "surface mode %d axis %d interval %d: K_i %d, longest %g > %g", mode, ax, i, k, l,
                      target);
                CHECK(k < o.kmax, "surface mode %d axis %d interval %d below kmax", mode, ax, i);
                double l1 = k > 0 ? surf_longest(&s, o.cam, o.width, o.height, ax, i, k - 1, kx[!ax]) : 0;
                wasteful += l1 > target;
                if (getenv("WRINKLY_VERBOSE"))
                    printf("surface mode %d axis %d i %d: K %d longest %g, at K-1 %g\n", mode, ax, i, k, l, l1);
            }
            CHECK(wasteful > 0, "surface mode %d axis %d: K_i - 1 fails somewhere (minimal)", mode, ax);
        }
    }
    rt_free(tp);
}

int main(void)
{
    test_curve();
    test_surface();
    test_orientation();
    test_lod();
    return check_done("test_wrinkly");
}
