/* test_raymarch_sdf.c — ray marching hard shapes with their distances: a
 * hard slab (a box) in a larger box transmits exp(-σ d / cos θ) to 1e-3
 * relative at the default step (without its support the midpoint rule is
 * off by more), a hard sphere in solid mode is shaded by ambient + (1 -
 * ambient) max(0, n·l) with n the radial direction at the ray's analytic
 * hit point (without the distance the 0/1 differences shade it in patches),
 * and a hard sphere's emission through its chord length 2 sqrt(r^2 - b^2). */
#include <math.h>
#include <string.h>

#include "check.h"
#include "field.h"
#include "raymarch.h"

static camera look_down_z(double dist, double fov)
{
    camera c;
    memset(&c, 0, sizeof c);
    c.eye[2] = dist;
    c.up[1] = 1;
    c.fov = fov;
    camera_setup(&c);
    return c;
}

typedef struct progs {
    field *f;
    field_prog *pf, *pg;
} progs;

static void progs_of(const density_shape *d, int solid, progs *p)
{
    rt_error e;
    p->f = field_density(d);
    p->pf = field_compile(p->f, &e);
    p->pg = NULL;
    CHECK(p->pf != NULL, "compile");
    if (solid)
        CHECK(field_prog_level_sdf(p->pf, 0.5, &p->pg, NULL, &e) == RT_OK && p->pg, "sdf");
    else
        CHECK(field_prog_hard_support(p->pf, &p->pg, &e) == RT_OK && p->pg, "support");
}

static void progs_free(progs *p)
{
    field_prog_free(p->pf);
    field_prog_free(p->pg);
    field_unref(p->f);
}

/* Worst relative transmission error over the pixels whose ray crosses the
 * whole slab |z| <= d/2 (half 2 in x, y) inside the box [-1, 1]^3. */
static double slab_error(const rm_opts *o0, const progs *p, double d, int use_support)
{
    camera c = look_down_z(3, 40);
    rm_opts o = *o0;
    o.support = use_support ? field_prog_fn : NULL;
    o.support_ctx = p->pg;
    image im;
    rt_error e;
    CHECK(image_init(&im, 21, 17, &e) == RT_OK, "image");
    CHECK(rm_render(field_prog_fn, p->pf, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    double worst = 0;
    for (int y = 0; y < im.h; y++)
        for (int x = 0; x < im.w; x++) {
            double dir[3];
            camera_ray(&c, im.w, im.h, x + 0.5, y + 0.5, dir);
            double t1 = (-d / 2 - 3) / dir[2];
            if (fabs(t1 * dir[0]) > 1 || fabs(t1 * dir[1]) > 1)
                continue;
            double T = exp(-o.sigma * d / fabs(dir[2]));
            worst = fmax(worst, fabs(image_at(&im, x, y)[0] - T) / T);
        }
    image_free(&im);
    return worst;
}

static void test_slab(void)
{
    rm_opts o;
    rm_defaults(&o); /* step 1/128, box [-1, 1]^3 */
    o.sigma = 3;
    o.lighting = 0;
    o.emission[0] = o.emission[1] = o.emission[2] = 0;
    o.background[0] = o.background[1] = o.background[2] = 1;
    double ds[3] = {0.5, 0.3, 0.123};
    for (int k = 0; k < 3; k++) {
        density_shape s;
        memset(&s, 0, sizeof s);
        s.kind = DENSITY_BOX;
        s.h[0] = s.h[1] = 2;
        s.h[2] = ds[k] / 2;
        progs p;
        progs_of(&s, 0, &p);
        double with = slab_error(&o, &p, ds[k], 1), without = slab_error(&o, &p, ds[k], 0);
        CHECK(with < 1e-3, "slab d %g: relative error %g with the support", ds[k], with);
        /* the midpoint rule counts whole steps: the error this fixes */
        CHECK(without > 1e-3, "slab d %g: without the support the error was expected > 1e-3: %g",
              ds[k], without);
        progs_free(&p);
    }
    /* A hard sphere of density 1 * 0.6: the chord through the centre. */
    density_shape s;
    memset(&s, 0, sizeof s);
    s.kind = DENSITY_SPHERE;
    s.r = 0.55;
    rt_error e;
    field *f = field_binary(FIELD_MUL, field_density(&s), field_const(0.6));
    field_prog *pf = field_compile(f, &e), *pg = NULL;
    CHECK(field_prog_hard_support(pf, &pg, &e) == RT_OK && pg, "support of 0.6 sphere");
    camera c = look_down_z(3, 40);
    o.support = field_prog_fn;
    o.support_ctx = pg;
    image im;
    CHECK(image_init(&im, 15, 15, &e) == RT_OK, "image");
    CHECK(rm_render(field_prog_fn, pf, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    double worst = 0;
    for (int y = 0; y < im.h; y++)
        for (int x = 0; x < im.w; x++) {
            double dir[3];
            camera_ray(&c, im.w, im.h, x + 0.5, y + 0.5, dir);
            /* distance b of the line from the centre: eye (0, 0, 3) */
            double tc = -3 * dir[2], b2 = 9 - tc * tc;
            double len = b2 < s.r * s.r ? 2 * sqrt(s.r * s.r - b2) : 0;
            double T = exp(-o.sigma * 0.6 * len);
            worst = fmax(worst, fabs(image_at(&im, x, y)[0] - T) / T);
        }
    CHECK(worst < 1e-4, "sphere chords: worst relative error %g", worst);
    image_free(&im);
    field_prog_free(pg);
    field_prog_free(pf);
    field_unref(f);
}

/* Solid shading error vs the analytic sphere, over pixels that hit it. */
static double shade_error(const progs *p, const density_shape *s, int use_sdf, int *hits)
{
    camera c = look_down_z(3, 40);
    rm_opts o;
    rm_defaults(&o);
    o.mode = RM_SOLID;
    o.sdf = use_sdf ? field_prog_fn : NULL;
    o.sdf_ctx = p->pg;
    o.light[0] = 0.3, o.light[1] = -0.5, o.light[2] = 0.8;
    o.ambient = 0.2;
    image im;
    rt_error e;
    CHECK(image_init(&im, 31, 31, &e) == RT_OK, "image");
    CHECK(rm_render(field_prog_fn, p->pf, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    double ll = sqrt(0.09 + 0.25 + 0.64), l[3] = {0.3 / ll, -0.5 / ll, 0.8 / ll};
    double worst = 0;
    *hits = 0;
    for (int y = 0; y < im.h; y++)
        for (int x = 0; x < im.w; x++) {
            double dir[3], eye[3] = {0, 0, 3};
            camera_ray(&c, im.w, im.h, x + 0.5, y + 0.5, dir);
            double tc = -3 * dir[2], b2 = 9 - tc * tc, r2 = s->r * s->r;
            if (b2 > 0.97 * r2) /* misses, and the rim where a step can skip */
                continue;
            double t = tc - sqrt(r2 - b2), n[3];
            for (int a = 0; a < 3; a++)
                n[a] = (eye[a] + t * dir[a]) / s->r;
            double d = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
            double want = 0.2 + 0.8 * (d > 0 ? d : 0);
            worst = fmax(worst, fabs(image_at(&im, x, y)[0] - want));
            ++*hits;
        }
    image_free(&im);
    return worst;
}

static void test_solid_normals(void)
{
    density_shape s;
    memset(&s, 0, sizeof s);
    s.kind = DENSITY_SPHERE;
    s.r = 0.7;
    progs p;
    progs_of(&s, 1, &p);
    int hits;
    double with = shade_error(&p, &s, 1, &hits);
    CHECK(hits > 300, "only %d pixels hit", hits);
    /* 0.005 in shade is about 0.4 degrees of normal at the steepest */
    CHECK(with < 0.005, "hard sphere shading off by %g with the distance", with);
    double without = shade_error(&p, &s, 0, &hits);
    CHECK(without > 0.1, "the 0/1 differences were expected to shade in patches: %g", without);
    progs_free(&p);
}

int main(void)
{
    test_slab();
    test_solid_normals();
    return check_done("test_raymarch_sdf");
}
