/* test_texobj.c — textured objects, field volumes and slices. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "mpd.h"
#include "solid.h"
#include "texobj.h"

typedef struct counter {
    atomic_ullong points;
    double value;
} counter;

/* a constant field that counts how many points it is asked for */
static void counting(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    (void)x, (void)y, (void)z;
    counter *c = (counter *)ctx;
    atomic_fetch_add(&c->points, (unsigned long long)n);
    for (size_t i = 0; i < n; i++)
        out[i] = c->value;
}

static void lin_field(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    (void)ctx;
    for (size_t i = 0; i < n; i++)
        out[i] = x[i] + 2 * y[i] + 3 * z[i];
}

static void ramp_field(const void *ctx, size_t n, const double *x, const double *y, const double *z, double *out)
{
    (void)ctx, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = 0.5 + 0.25 * x[i] + 0.125 * y[i];
}

static camera front_camera(double dist)
{
    camera c;
    memset(&c, 0, sizeof c);
    c.eye[2] = dist;
    c.up[1] = 1;
    c.fov = 30;
    camera_setup(&c);
    return c;
}

/* Unit sphere at the origin seen from (0, 0, 5): a pixel's centre ray hits
 * iff its angle from the axis is below asin(1/5). Texture evaluations =
 * hit pixels; outside = background exactly; inside = lit by Lambert with
 * N.L computed from the exact ray–sphere geometry. */
static void test_sphere(void)
{
    const int W = 64, H = 48;
    camera cam = front_camera(5);
    image im;
    CHECK(image_init(&im, W, H, NULL) == RT_OK, "image");
    texobj_shape s = {TEXOBJ_SPHERE, {0, 0, 0}, 1.0, 0, {0, 0, 0}};
    counter cnt;
    atomic_init(&cnt.points, 0);
    cnt.value = 1.0; /* white through the grey ramp */
    texobj_source src = {counting, &cnt, NULL, NULL, NULL};
    texobj_opts o;
    texobj_opts_default(&o);
    o.background[0] = 0.1f, o.background[1] = 0.2f, o.background[2] = 0.3f, o.background[3] = 0.0f;
    o.light[0] = 0, o.light[1] = 0, o.light[2] = 1; /* from the camera */
    o.ambient = 0.1;
    o.diffuse = 0.9;
    texobj_stats st;
    rt_run run = {2, NULL, 0};
    rt_error e;
    CHECK(texobj_render(&s, &cam, &src, &o, &run, &im, &st, &e) == RT_OK, "%s", e.msg);
    double th = tan(15.0 * 3.14159265358979323846 / 180.0), aspect = (double)W / H;
    double sin_max = 1.0 / 5.0;
    int hits = 0, wrong = 0, lit_wrong = 0, nonbg = 0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double nx = (2.0 * (px + 0.5) / W - 1.0) * aspect * th, ny = (1.0 - 2.0 * (py + 0.5) / H) * th;
            double len = sqrt(nx * nx + ny * ny + 1.0);
            double sin_a = sqrt(nx * nx + ny * ny) / len; /* sine of the angle from the axis */
            const float *p = image_at(&im, px, py);
            int is_bg = p[0] == o.background[0] && p[1] == o.background[1] && p[2] == o.background[2] &&
                        p[3] == o.background[3];
            nonbg += !is_bg;
            if (fabs(sin_a - sin_max) < 2e-3)
                continue; /* too close to the silhouette to call */
            int inside = sin_a < sin_max;
            hits += inside;
            if (inside == is_bg)
                wrong++;
            if (inside) {
                /* ray from (0,0,5) along d = (nx, ny, -1)/len: nearest root of |e + t d| = 1 */
                double d[3] = {nx / len, ny / len, -1.0 / len};
                double b = 5.0 * d[2], t = -b - sqrt(b * b - 24.0);
                double nz = 5.0 + t * d[2]; /* N = hit point; N.L = its z */
                double expect = 0.1 + 0.9 * nz;
                if (fabs(p[0] - expect) > 1e-5 || p[3] != 1.0f)
                    lit_wrong++;
            }
        }
    CHECK(hits > 100, "sphere covers %d pixels", hits);
    CHECK(wrong == 0, "%d pixels on the wrong side of the silhouette", wrong);
    CHECK(lit_wrong == 0, "%d hit pixels not lit as ambient + diffuse N.L", lit_wrong);
    CHECK(st.rays == (uint64_t)W * H, "rays %llu", (unsigned long long)st.rays);
    CHECK(st.hits == (uint64_t)nonbg, "hits %llu vs lit pixels %d", (unsigned long long)st.hits, nonbg);
    CHECK(atomic_load(&cnt.points) == st.hits, "texture evaluated %llu times for %llu hit pixels",
          (unsigned long long)atomic_load(&cnt.points), (unsigned long long)st.hits);

    /* cost grows with visible pixels: a sphere of radius 0.5 has about a
     * quarter of the area (angular radius asin(0.1) vs asin(0.2)) */
    s.radius = 0.5;
    atomic_store(&cnt.points, 0);
    CHECK(texobj_render(&s, &cam, &src, &o, &run, &im, &st, &e) == RT_OK, "%s", e.msg);
    double ratio = (double)atomic_load(&cnt.points) / (double)nonbg;
    double expect = pow(tan(asin(0.1)) / tan(asin(0.2)), 2);
    CHECK(fabs(ratio - expect) < 0.06, "evaluations ratio %g, expected about %g", ratio, expect);
    CHECK(atomic_load(&cnt.points) == st.hits, "small sphere: evaluations = hits");

    /* supersampling: 3x3 rays per pixel, evaluations = hit rays */
    o.samples = 3;
    atomic_store(&cnt.points, 0);
    CHECK(texobj_render(&s, &cam, &src, &o, &run, &im, &st, &e) == RT_OK, "%s", e.msg);
    CHECK(st.rays == 9ull * W * H && atomic_load(&cnt.points) == st.hits, "supersampled counts");
    o.samples = 9;
    CHECK(texobj_render(&s, &cam, &src, &o, &run, &im, &st, &e) == RT_EINVAL &&
              strcmp(e.msg, "samples = 9 is out of range (expected 1 .. 8)") == 0,
          "%s", e.msg);
    s.radius = -1;
    o.samples = 1;
    CHECK(texobj_render(&s, &cam, &src, &o, &run, &im, &st, &e) == RT_EINVAL &&
              strcmp(e.msg, "sphere: radius = -1 must be > 0") == 0,
          "%s", e.msg);
    image_free(&im);
}

/* Cube of half side 1 seen face-on from distance 5: the front face (z = 1,
 * distance 4) covers |ndc| < 1/4 exactly. Plane y = -1 seen level: only
 * rays pointing down (ndc_y < 0) hit. Cylinder: centre pixel's normal faces
 * the camera. */
static void test_shapes(void)
{
    const int W = 40, H = 40;
    camera cam = front_camera(5);
    double th = tan(15.0 * 3.14159265358979323846 / 180.0);
    double d[3], t, n[3];
    int wrong = 0;
    texobj_shape cube = {TEXOBJ_CUBE, {0, 0, 0}, 1.0, 0, {0, 0, 0}};
    texobj_shape plane = {TEXOBJ_PLANE, {0, -1, 0}, 0, 0, {0, 2, 0}};
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            double nx = (2.0 * (px + 0.5) / W - 1.0) * th, ny = (1.0 - 2.0 * (py + 0.5) / H) * th;
            camera_ray(&cam, W, H, px + 0.5, py + 0.5, d);
            int in = fabs(nx) < 0.25 && fabs(ny) < 0.25;
            int hit = texobj_intersect(&cube, cam.eye, d, &t, n);
            wrong += hit != in;
            if (hit && in)
                wrong += n[2] != 1.0 || fabs(cam.eye[2] + t * d[2] - 1.0) > 1e-12;
            wrong += texobj_intersect(&plane, cam.eye, d, &t, n) != (ny < 0);
        }
    CHECK(wrong == 0, "%d cube/plane pixels wrong", wrong);
    texobj_shape cyl = {TEXOBJ_CYLINDER, {0, 0, 0}, 1.0, 2.0, {0, 0, 0}};
    double o[3] = {0, 0, 5}, down[3] = {0, -1, 0}, fwd[3] = {0, 0, -1}, top[3] = {0.3, 5, 0.2};
    CHECK(texobj_intersect(&cyl, o, fwd, &t, n) && fabs(t - 4) < 1e-12 && n[2] == 1, "cylinder side t=%g", t);
    CHECK(texobj_intersect(&cyl, top, down, &t, n) && fabs(t - 4) < 1e-12 && n[1] == 1, "cylinder cap t=%g", t);
    CHECK(!texobj_intersect(&cyl, o, down, &t, n), "cylinder miss");
    /* from inside the sphere the far wall is hit */
    texobj_shape sph = {TEXOBJ_SPHERE, {0, 0, 0}, 2.0, 0, {0, 0, 0}};
    double c0[3] = {0, 0, 0};
    CHECK(texobj_intersect(&sph, c0, fwd, &t, n) && fabs(t - 2) < 1e-12, "inside sphere");
}

/* Same image for 1, 2 and 4 threads with a marble texture on a Type IV D. */
static void test_threads(void)
{
    mpd_params p;
    mpd_params_default(&p);
    p.R = 7;
    p.type = MPD_TYPE4;
    p.R2 = 4;
    mpd m;
    rt_error e;
    CHECK(mpd_init(&m, &p, NULL, &e) == RT_OK, "%s", e.msg);
    solid_texture tex;
    solid_texture_default(&tex);
    tex.d_fn = mpd_eval;
    tex.d_ctx = &m;
    tex.k = 0.1;
    tex.warp = SOLID_WARP_Z;
    for (int i = 0; i < 3; i++)
        tex.d_lo[i] = -1, tex.d_hi[i] = 1;
    ramp r = solid_ramp_marble();
    texobj_source src = {solid_eval, &tex, &r, NULL, NULL};
    texobj_opts o;
    texobj_opts_default(&o);
    o.samples = 2;
    camera cam;
    double target[3] = {0, 0, 0};
    camera_orbit(&cam, target, 4, 30, 20, 40);
    image im[3];
    for (int q = 0; q < 3; q++) {
        rt_run run = {1 << q, NULL, 0};
        image_init(&im[q], 48, 37, NULL);
        texobj_shape s = {TEXOBJ_CUBE, {0, 0, 0}, 0.8, 0, {0, 0, 0}};
        CHECK(texobj_render(&s, &cam, &src, &o, &run, &im[q], NULL, &e) == RT_OK, "%s", e.msg);
    }
    for (int q = 1; q < 3; q++)
        CHECK(memcmp(im[0].px, im[q].px, 48 * 37 * 4 * sizeof(float)) == 0, "threads 1 vs %d", 1 << q);
    /* the texture varies over the visible faces */
    float mn = 1, mx = 0;
    for (int i = 0; i < 48 * 37; i++)
        if (im[0].px[4 * i + 3] > 0.99f) {
            mn = fminf(mn, im[0].px[4 * i]);
            mx = fmaxf(mx, im[0].px[4 * i]);
        }
    CHECK(mx - mn > 0.1f, "textured cube shows variation (%g .. %g)", mn, mx);
    for (int q = 0; q < 3; q++)
        image_free(&im[q]);
    mpd_free(&m);
}

static void test_volume_and_slice(void)
{
    volume v;
    double lo[3] = {-1, 0, 2}, hi[3] = {1, 3, 4};
    CHECK(volume_init(&v, 4, 3, 5, lo, hi, NULL) == RT_OK, "volume");
    rt_run run = {2, NULL, 0};
    CHECK(texobj_sample_volume(lin_field, NULL, &v, &run, NULL) == RT_OK, "sample");
    int bad = 0;
    for (int k = 0; k < 5; k++)
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < 4; i++) {
                /* centres: x = -1 + 0.5 (i + 0.5), y = j + 0.5, z = 2 + 0.4 (k + 0.5) */
                double x = -1 + 0.5 * (i + 0.5), y = j + 0.5, z = 2 + 0.4 * (k + 0.5);
                bad += fabs(*volume_at(&v, i, j, k) - (x + 2 * y + 3 * z)) > 1e-5;
            }
    CHECK(bad == 0, "%d volume samples wrong", bad);
    volume_free(&v);

    image im;
    image_init(&im, 8, 4, NULL);
    double org[3] = {0, 0, 7}, u[3] = {1, 0, 0}, w[3] = {0, 1, 0};
    CHECK(texobj_slice(ramp_field, NULL, NULL, org, u, w, &run, &im, NULL) == RT_OK, "slice");
    bad = 0;
    for (int py = 0; py < 4; py++)
        for (int px = 0; px < 8; px++) {
            double a = 2.0 * (px + 0.5) / 8 - 1, b = 1 - 2.0 * (py + 0.5) / 4;
            bad += fabs(image_at(&im, px, py)[0] - (0.5 + 0.25 * a + 0.125 * b)) > 1e-6;
        }
    CHECK(bad == 0, "%d slice pixels wrong", bad);
    image_free(&im);
}

int main(void)
{
    test_sphere();
    test_shapes();
    test_threads();
    test_volume_and_slice();
    return check_done("test_texobj");
}
