/* test_isosurf_sdf.c — iso-surfaces of hard shapes through their signed
 * distance: area and volume of a hard sphere (4 pi r^2, 4/3 pi r^3), box
 * (8 (ab + bc + ca), 8abc) and capped cylinder (2 pi r^2 + 4 pi r h,
 * 2 pi r^2 h) within 1% at grid 96, vertices on the surface, normals
 * radial, the mesh closed and outward; and the 0/1 density alone (no
 * distance) for comparison, whose staircase is far off. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "field.h"
#include "isosurf.h"

static const double PI = 3.14159265358979323846;

/* Mesh of a hard shape at grid res over [-1, 1]^3, with (use_sdf) or
 * without its distance. */
static void mesh_of(const density_shape *d, int res, int use_sdf, mesh *m, mesh_stats *st)
{
    rt_error e;
    field *f = field_density(d);
    field_prog *pf = field_compile(f, &e), *pg = NULL;
    CHECK(pf != NULL, "compile");
    if (use_sdf) {
        int exact = 0;
        CHECK(field_prog_level_sdf(pf, 0.5, &pg, &exact, &e) == RT_OK && pg && exact, "sdf of %s",
              density_name(d->kind));
    }
    iso_opts o;
    memset(&o, 0, sizeof o);
    o.level = 0.5;
    o.normals = 1;
    o.sdf = pg ? field_prog_fn : NULL;
    o.sdf_ctx = pg;
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    int r3[3] = {res, res, res};
    CHECK(iso_from_field(field_prog_fn, pf, lo, hi, r3, &o, NULL, m, &e) == RT_OK, "%s", e.msg);
    CHECK(mesh_compute_stats(m, st, &e) == RT_OK, "stats");
    CHECK(st->boundary_edges == 0 && st->nonmanifold_edges == 0 && st->euler == 2 && st->degenerate == 0,
          "%s closed: %zu boundary, %zu non-manifold, euler %ld, %zu degenerate", density_name(d->kind),
          st->boundary_edges, st->nonmanifold_edges, st->euler, st->degenerate);
    field_prog_free(pg);
    field_prog_free(pf);
    field_unref(f);
}

static void test_sphere(void)
{
    density_shape d;
    memset(&d, 0, sizeof d);
    d.kind = DENSITY_SPHERE;
    d.r = 0.7;
    mesh m;
    mesh_stats st;
    mesh_of(&d, 96, 1, &m, &st);
    double A = 4 * PI * 0.49, V = 4.0 / 3 * PI * 0.343;
    CHECK(fabs(st.area / A - 1) < 0.01, "sphere area %g vs %g", st.area, A);
    CHECK(fabs(st.volume / V - 1) < 0.01, "sphere volume %g vs %g (positive: outward)", st.volume, V);
    double worst_r = 0, worst_n = 0;
    for (size_t i = 0; i < m.nv; i++) {
        const float *p = m.pos + 3 * i, *n = m.nrm + 3 * i;
        double r = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
        worst_r = fmax(worst_r, fabs(r - 0.7));
        double c = (p[0] * n[0] + p[1] * n[1] + p[2] * n[2]) / r;
        worst_n = fmax(worst_n, acos(fmin(1, c)));
    }
    CHECK(worst_r < 1e-6, "vertices off the sphere by %g", worst_r);
    CHECK(worst_n < 1e-3, "normals off the radius by %g rad", worst_n);
    mesh_free(&m);
    /* The 0/1 samples alone: a staircase, area far too large. */
    mesh_of(&d, 96, 0, &m, &st);
    CHECK(st.area / A - 1 > 0.05, "the staircase was expected to be > 5%% too large: %g", st.area / A - 1);
    mesh_free(&m);
}

static void test_box_cylinder(void)
{
    density_shape b;
    memset(&b, 0, sizeof b);
    b.kind = DENSITY_BOX;
    b.c[0] = 0.05;
    b.h[0] = 0.5, b.h[1] = 0.6, b.h[2] = 0.7;
    mesh m;
    mesh_stats st;
    mesh_of(&b, 96, 1, &m, &st);
    double A = 8 * (0.5 * 0.6 + 0.6 * 0.7 + 0.7 * 0.5), V = 8 * 0.5 * 0.6 * 0.7;
    CHECK(fabs(st.area / A - 1) < 0.01, "box area %g vs %g", st.area, A);
    CHECK(fabs(st.volume / V - 1) < 0.01, "box volume %g vs %g", st.volume, V);
    mesh_free(&m);
    density_shape c;
    memset(&c, 0, sizeof c);
    c.kind = DENSITY_CYLINDER;
    c.r = 0.6;
    c.h[2] = 0.7;
    mesh_of(&c, 96, 1, &m, &st);
    A = 2 * PI * 0.36 + 4 * PI * 0.6 * 0.7;
    V = 2 * PI * 0.36 * 0.7;
    CHECK(fabs(st.area / A - 1) < 0.01, "cylinder area %g vs %g", st.area, A);
    CHECK(fabs(st.volume / V - 1) < 0.01, "cylinder volume %g vs %g", st.volume, V);
    mesh_free(&m);
}

int main(void)
{
    test_sphere();
    test_box_cylinder();
    return check_done("test_isosurf_sdf");
}
