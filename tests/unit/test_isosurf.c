/* test_isosurf.c — the iso-surface extractor against geometric facts: closed
 * manifold meshes (every edge in two triangles), Euler characteristics of a
 * sphere (2), a torus (0) and two spheres (4), area and enclosed volume of a
 * sphere against 4πr² and 4/3πr³, a box-filling solid capped by the padding
 * (volume 8 for the cube [-1,1]³ less bounded chamfers), outward normals, and identical
 * output for 1, 2 and 4 threads. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isosurf.h"

static const double PI = 3.14159265358979323846;

typedef struct sph {
    double c[3], r;
} sph;

static void sphere_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                      double *out)
{
    const sph *s = ctx;
    for (size_t i = 0; i < n; i++) {
        double dx = x[i] - s->c[0], dy = y[i] - s->c[1], dz = z[i] - s->c[2];
        out[i] = s->r - sqrt(dx * dx + dy * dy + dz * dz);
    }
}

/* Torus around the y axis, major radius 0.6, minor 0.25. */
static void torus_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        double q = sqrt(x[i] * x[i] + z[i] * z[i]) - 0.6;
        out[i] = 0.25 - sqrt(q * q + y[i] * y[i]);
    }
}

static void two_spheres_fn(const void *ctx, size_t n, const double *x, const double *y,
                           const double *z, double *out)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        double a = 0.35 - sqrt((x[i] + 0.5) * (x[i] + 0.5) + y[i] * y[i] + z[i] * z[i]);
        double b = 0.35 - sqrt((x[i] - 0.5) * (x[i] - 0.5) + y[i] * y[i] + z[i] * z[i]);
        out[i] = a > b ? a : b;
    }
}

static void const_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    (void)x, (void)y, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = *(const double *)ctx;
}

static void xcoord_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                      double *out)
{
    (void)ctx, (void)y, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = x[i];
}

/* Signed volume enclosed by a closed mesh (divergence theorem); positive
 * when triangles are counter-clockwise seen from outside. */
static double enclosed_volume(const mesh *m)
{
    double v = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const float *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                    *c = m->pos + 3 * m->tri[3 * t + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
              a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return v;
}

static void check_closed(const mesh *m, long euler, const char *what, mesh_stats *st)
{
    rt_error e;
    CHECK(mesh_compute_stats(m, st, &e) == RT_OK, "%s: stats", what);
    CHECK(st->triangles > 0, "%s: empty mesh", what);
    CHECK(st->boundary_edges == 0, "%s: %zu boundary edges", what, st->boundary_edges);
    CHECK(st->nonmanifold_edges == 0, "%s: %zu non-manifold edges", what, st->nonmanifold_edges);
    CHECK(st->degenerate == 0, "%s: %zu degenerate triangles", what, st->degenerate);
    CHECK(st->euler == euler, "%s: Euler characteristic %ld, expected %ld", what, st->euler, euler);
    CHECK(st->vertices == m->nv, "%s: %zu unused vertices", what, m->nv - st->vertices);
}

static void test_sphere(void)
{
    sph s = {{0.05, -0.03, 0.02}, 0.8};
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    int res[3] = {72, 72, 72};
    iso_opts o = {0};
    o.level = 0;
    o.normals = 1;
    mesh m;
    rt_error e;
    CHECK(iso_from_field(sphere_fn, &s, lo, hi, res, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    mesh_stats st;
    check_closed(&m, 2, "sphere", &st);
    double area = 4 * PI * s.r * s.r;
    CHECK(fabs(st.area - area) < 0.01 * area, "sphere area %g vs 4πr² = %g", st.area, area);
    double vol = enclosed_volume(&m), want = 4.0 / 3.0 * PI * s.r * s.r * s.r;
    CHECK(fabs(vol - want) < 0.01 * want, "sphere volume %g vs 4/3πr³ = %g", vol, want);
    /* vertices on the sphere, normals radial and outward */
    size_t bad_n = 0, bad_p = 0;
    for (size_t i = 0; i < m.nv; i++) {
        double d[3], l = 0, dot = 0;
        for (int a = 0; a < 3; a++) {
            d[a] = m.pos[3 * i + a] - s.c[a];
            l += d[a] * d[a];
        }
        l = sqrt(l);
        for (int a = 0; a < 3; a++)
            dot += d[a] / l * m.nrm[3 * i + a];
        bad_n += !(dot > 0.999);
        bad_p += !(fabs(l - s.r) < 1e-3);
    }
    CHECK(bad_n == 0, "%zu of %zu normals not radial outward", bad_n, m.nv);
    CHECK(bad_p == 0, "%zu of %zu vertices off the sphere", bad_p, m.nv);
    /* every triangle's right-hand normal points away from the centre */
    size_t inward = 0;
    for (size_t t = 0; t < m.nt; t++) {
        const float *a = m.pos + 3 * m.tri[3 * t], *b = m.pos + 3 * m.tri[3 * t + 1],
                    *c = m.pos + 3 * m.tri[3 * t + 2];
        double u[3], w[3], n[3], cen[3];
        for (int k = 0; k < 3; k++) {
            u[k] = b[k] - a[k];
            w[k] = c[k] - a[k];
            cen[k] = (a[k] + b[k] + c[k]) / 3.0 - s.c[k];
        }
        n[0] = u[1] * w[2] - u[2] * w[1];
        n[1] = u[2] * w[0] - u[0] * w[2];
        n[2] = u[0] * w[1] - u[1] * w[0];
        inward += n[0] * cen[0] + n[1] * cen[1] + n[2] * cen[2] <= 0;
    }
    CHECK(inward == 0, "%zu triangles wind inward", inward);

    /* Volume input gives the same mesh (the field case samples the same
     * cell centres); normals differ (grid vs callback gradient) but are
     * still outward. */
    volume v;
    CHECK(volume_init(&v, res[0], res[1], res[2], lo, hi, &e) == RT_OK, "vol");
    CHECK(iso_sample_field(sphere_fn, &s, &v, NULL, &e) == RT_OK, "sample");
    mesh m2;
    CHECK(iso_from_volume(&v, &o, NULL, &m2, &e) == RT_OK, "%s", e.msg);
    CHECK(m2.nv == m.nv && m2.nt == m.nt, "volume mesh size %zu/%zu vs %zu/%zu", m2.nv, m2.nt, m.nv, m.nt);
    if (m2.nv == m.nv && m2.nt == m.nt) {
        CHECK(memcmp(m2.pos, m.pos, m.nv * 12) == 0, "volume positions differ");
        CHECK(memcmp(m2.tri, m.tri, m.nt * 12) == 0, "volume triangles differ");
        size_t bad = 0;
        for (size_t i = 0; i < m2.nv; i++) {
            double dot = 0, l = 0;
            for (int a = 0; a < 3; a++) {
                double d = m2.pos[3 * i + a] - s.c[a];
                dot += d * m2.nrm[3 * i + a];
                l += d * d;
            }
            bad += !(dot / sqrt(l) > 0.99);
        }
        CHECK(bad == 0, "%zu grid normals off radial", bad);
    }
    mesh_free(&m2);
    volume_free(&v);
    mesh_free(&m);
}

/* Grid normals from a quadratic density R² - |p - c|²: its central
 * differences are exact, -2(node - c), and blending the two nodes' values
 * (1 - s, s) at the crossing gives -2(vertex - c), so every normal is the
 * radial direction at its own vertex (up to the float samples), not at a
 * point elsewhere on the edge. */
typedef struct quad {
    double c[3], r2;
} quad;

static void quad_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    const quad *q = ctx;
    for (size_t i = 0; i < n; i++) {
        double dx = x[i] - q->c[0], dy = y[i] - q->c[1], dz = z[i] - q->c[2];
        out[i] = q->r2 - (dx * dx + dy * dy + dz * dz);
    }
}

static void test_grid_normals(void)
{
    quad q = {{0.03, -0.05, 0.02}, 0.5};
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    volume v;
    rt_error e;
    CHECK(volume_init(&v, 24, 24, 24, lo, hi, &e) == RT_OK, "vol");
    CHECK(iso_sample_field(quad_fn, &q, &v, NULL, &e) == RT_OK, "sample");
    iso_opts o = {0};
    o.normals = 1;
    mesh m;
    CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    double worst = 0;
    for (size_t i = 0; i < m.nv; i++) {
        double d[3], l = 0, err = 0;
        for (int a = 0; a < 3; a++) {
            d[a] = m.pos[3 * i + a] - q.c[a];
            l += d[a] * d[a];
        }
        l = sqrt(l);
        for (int a = 0; a < 3; a++)
            err += fabs(m.nrm[3 * i + a] - d[a] / l);
        worst = err > worst ? err : worst;
    }
    CHECK(m.nv > 100 && worst < 1e-4, "%zu vertices: a grid normal is %g off the radial direction at its vertex",
          m.nv, worst);
    mesh_free(&m);
    volume_free(&v);
}

static void test_topologies(void)
{
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    int res[3] = {40, 36, 44};
    iso_opts o = {0};
    mesh m;
    rt_error e;
    mesh_stats st;
    CHECK(iso_from_field(torus_fn, NULL, lo, hi, res, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    check_closed(&m, 0, "torus", &st);
    /* torus area 4π²Rr = 4π²·0.6·0.25 (coarse grid: 3%) */
    double ta = 4 * PI * PI * 0.6 * 0.25;
    CHECK(fabs(st.area - ta) < 0.03 * ta, "torus area %g vs %g", st.area, ta);
    CHECK(m.nrm == NULL, "no normals asked, got some");
    mesh_free(&m);
    CHECK(iso_from_field(two_spheres_fn, NULL, lo, hi, res, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    check_closed(&m, 4, "two spheres", &st);
    mesh_free(&m);

    /* Everything inside: the padding caps the box. Cap vertices lie exactly
     * on the faces of [lo, hi]; the volume is the cube's 8 less the chamfers
     * along box edges (each a prism of cross-section h²/8, h <= 2/16). */
    double one = 1;
    int r2[3] = {20, 16, 24};
    o.normals = 1;
    CHECK(iso_from_field(const_fn, &one, lo, hi, r2, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    check_closed(&m, 2, "full box", &st);
    double vb = enclosed_volume(&m), chamfer = 12 * 2 * (0.125 * 0.125) / 8;
    CHECK(vb <= 8 + 1e-6 && vb >= 8 - chamfer, "full box volume %g not in [8 - %g, 8]", vb, chamfer);
    CHECK(st.area <= 24 + 1e-5 && st.area >= 24 - 12 * 2 * 0.125, "full box area %g", st.area);
    size_t bad = 0;
    for (size_t i = 0; i < m.nv; i++) {
        const float *p = m.pos + 3 * i, *n = m.nrm + 3 * i;
        double dot = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
        bad += !(dot > 0) || !(fabs(p[0]) == 1 || fabs(p[1]) == 1 || fabs(p[2]) == 1);
    }
    CHECK(bad == 0, "%zu box vertices off the faces or with inward normals", bad);
    mesh_free(&m);

    /* Half space x >= 0.3 inside the box: the linear field is interpolated
     * exactly, so the cut is the plane x = 0.3 and the volume is 0.7·4 less
     * chamfers along the box edges the slab touches. */
    o.level = 0.3;
    CHECK(iso_from_field(xcoord_fn, NULL, lo, hi, r2, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    check_closed(&m, 2, "half box", &st);
    vb = enclosed_volume(&m);
    CHECK(vb <= 2.8 + 1e-6 && vb >= 2.8 - chamfer, "half box volume %g not in [2.8 - %g, 2.8]", vb, chamfer);
    bad = 0;
    for (size_t i = 0; i < m.nv; i++) {
        const float *p = m.pos + 3 * i;
        bad += !(fabs(p[0] - 0.3) < 1e-6 || fabs(p[0]) == 1 || fabs(p[1]) == 1 || fabs(p[2]) == 1);
        bad += p[0] < 0.3 - 1e-6;
    }
    CHECK(bad == 0, "%zu half-box vertices off the cut plane and the box faces", bad);
    mesh_free(&m);

    /* Nothing inside: an empty mesh, not an error. */
    double zero = -1;
    o.level = 0;
    CHECK(iso_from_field(const_fn, &zero, lo, hi, r2, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    CHECK(m.nv == 0 && m.nt == 0, "empty: %zu %zu", m.nv, m.nt);
    mesh_free(&m);

    /* Samples exactly at the level (inside, f >= t): clamped interpolation
     * keeps all triangles non-degenerate. A 1-voxel plateau of value 0. */
    volume v;
    CHECK(volume_init(&v, 4, 4, 4, lo, hi, &e) == RT_OK, "vol");
    for (int i = 0; i < 64; i++)
        v.v[i] = -1;
    *volume_at(&v, 1, 1, 1) = 0;
    *volume_at(&v, 2, 1, 1) = 0;
    CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    check_closed(&m, 2, "plateau", &st);
    mesh_free(&m);
    volume_free(&v);
}

static void test_threads_and_colour(void)
{
    sph s = {{0.1, 0, -0.1}, 0.7};
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    int res[3] = {33, 30, 37};
    ramp rp = ramp_grey();
    iso_opts o = {0};
    o.level = 0.05;
    o.normals = 1;
    o.colour_mode = ISO_COLOUR_RAMP;
    o.colour_fn[0] = xcoord_fn;
    o.colour_ramp = &rp;
    mesh m[3];
    rt_error e;
    int th[3] = {1, 2, 4};
    for (int k = 0; k < 3; k++) {
        rt_run run = {th[k], NULL, 0};
        CHECK(iso_from_field(sphere_fn, &s, lo, hi, res, &o, &run, &m[k], &e) == RT_OK, "%s", e.msg);
    }
    for (int k = 1; k < 3; k++) {
        CHECK(m[k].nv == m[0].nv && m[k].nt == m[0].nt, "threads %d: size differs", th[k]);
        if (m[k].nv != m[0].nv || m[k].nt != m[0].nt)
            continue;
        CHECK(memcmp(m[k].pos, m[0].pos, m[0].nv * 12) == 0, "threads %d: positions differ", th[k]);
        CHECK(memcmp(m[k].nrm, m[0].nrm, m[0].nv * 12) == 0, "threads %d: normals differ", th[k]);
        CHECK(memcmp(m[k].col, m[0].col, m[0].nv * 16) == 0, "threads %d: colours differ", th[k]);
        CHECK(memcmp(m[k].tri, m[0].tri, m[0].nt * 12) == 0, "threads %d: triangles differ", th[k]);
    }
    /* colour = grey ramp of x, clamped to [0, 1] */
    size_t bad = 0;
    for (size_t i = 0; i < m[0].nv; i++) {
        double x = m[0].pos[3 * i];
        double g = x < 0 ? 0 : x > 1 ? 1 : x;
        bad += fabs(m[0].col[4 * i] - g) > 1e-6 || m[0].col[4 * i + 3] != 1;
    }
    CHECK(bad == 0, "%zu colours are not ramp(x)", bad);
    for (int k = 0; k < 3; k++)
        mesh_free(&m[k]);

    /* RGB from three fields: (x, 0.3, x) with x clamped to [0, 1] */
    double c3 = 0.3;
    o.colour_mode = ISO_COLOUR_RGB;
    o.colour_fn[1] = const_fn;
    o.colour_ctx[1] = &c3;
    o.colour_fn[2] = xcoord_fn;
    CHECK(iso_from_field(sphere_fn, &s, lo, hi, res, &o, NULL, &m[0], &e) == RT_OK, "%s", e.msg);
    bad = 0;
    for (size_t i = 0; i < m[0].nv; i++) {
        double x = m[0].pos[3 * i], g = x < 0 ? 0 : x > 1 ? 1 : x;
        const float *c = m[0].col + 4 * i;
        bad += c[0] != (float)g || c[1] != 0.3f || c[2] != (float)g || c[3] != 1;
    }
    CHECK(m[0].nv > 0 && bad == 0, "%zu RGB colours wrong", bad);
    mesh_free(&m[0]);
}

static void test_errors(void)
{
    double lo[3] = {-1, -1, -1}, hi[3] = {1, -2, 1};
    int res[3] = {4, 4, 4};
    iso_opts o = {0};
    mesh m;
    rt_error e;
    CHECK(iso_from_field(torus_fn, NULL, lo, hi, res, &o, NULL, &m, &e) == RT_EINVAL, "bad bounds");
    CHECK(strcmp(e.msg, "isosurface bounds along y: lo -1 is not below hi -2") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    hi[1] = 1;
    res[2] = 0;
    CHECK(iso_from_field(torus_fn, NULL, lo, hi, res, &o, NULL, &m, &e) == RT_EINVAL, "bad res");
    CHECK(strcmp(e.msg, "isosurface resolution 0 along z is not >= 1") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    res[2] = 4;
    o.level = NAN;
    CHECK(iso_from_field(torus_fn, NULL, lo, hi, res, &o, NULL, &m, &e) == RT_EINVAL, "nan level");
    CHECK(strcmp(e.msg, "isosurface level nan is not a finite number") == 0, "msg: %s", e.msg);
    mesh_free(&m);
}

int main(void)
{
    test_sphere();
    test_grid_normals();
    test_topologies();
    test_threads_and_colour();
    test_errors();
    return check_done("test_isosurf");
}
