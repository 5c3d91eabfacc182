/* test_raymarch.c — the ray marcher against closed forms: Beer–Lambert
 * transmission exp(-σ d / cos θ) through uniform slabs (the slab as the box,
 * and a slab inside a larger box sampled by steps), the emission of a
 * uniform slab C (1 - T), the silhouette of a solid sphere against its
 * projected radius tan(asin(r/D)), block-wise field calls, the volume
 * adapter, and identical images for 1, 2 and 4 threads. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "raymarch.h"

static _Atomic size_t max_block; /* largest n seen by a field call */

static void note(size_t n)
{
    /* several threads call this only in the determinism check, where the
     * value is not read */
    if (n > max_block)
        max_block = n;
}

static void const_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    (void)x, (void)y, (void)z;
    for (size_t i = 0; i < n; i++)
        out[i] = *(const double *)ctx;
}

/* density 1 for 0 <= z <= 0.5, else 0 */
static void slab_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                    double *out)
{
    (void)ctx, (void)x, (void)y;
    note(n);
    for (size_t i = 0; i < n; i++)
        out[i] = z[i] >= 0 && z[i] <= 0.5 ? 1 : 0;
}

/* 1 - |p| : solid unit sphere at threshold 0, soft ball in emission mode */
static void ball_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                    double *out)
{
    (void)ctx;
    note(n);
    for (size_t i = 0; i < n; i++)
        out[i] = 1 - sqrt(x[i] * x[i] + y[i] * y[i] + z[i] * z[i]);
}

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

static void test_slab(void)
{
    /* (1) The box is the slab z in [0, 0.5] (wide in x, y); density 1. */
    camera c = look_down_z(3, 50);
    image im;
    rt_error e;
    CHECK(image_init(&im, 24, 20, &e) == RT_OK, "image");
    rm_opts o;
    rm_defaults(&o);
    o.lo[0] = o.lo[1] = -50;
    o.hi[0] = o.hi[1] = 50;
    o.lo[2] = 0;
    o.hi[2] = 0.5;
    o.sigma = 2;
    o.step = 0.05;
    o.emission[0] = o.emission[1] = o.emission[2] = 0;
    o.background[0] = 1, o.background[1] = 0.5, o.background[2] = 0.25, o.background[3] = 1;
    double one = 1;
    CHECK(rm_render(const_fn, &one, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    double worst = 0;
    for (int y = 0; y < im.h; y++)
        for (int x = 0; x < im.w; x++) {
            double d[3];
            camera_ray(&c, im.w, im.h, x + 0.5, y + 0.5, d);
            double T = exp(-2 * 0.5 / fabs(d[2])); /* path length d / cos θ */
            const float *p = image_at(&im, x, y);
            double err = fabs(p[0] - T) / T;
            if (err > worst)
                worst = err;
            CHECK(fabs(p[1] - 0.5 * T) <= 0.005 * T && fabs(p[2] - 0.25 * T) <= 0.005 * T,
                  "pixel %d,%d: green/blue not background·T", x, y);
            CHECK_NEAR(p[3], 1.0, 1e-6, "alpha over opaque background");
        }
    CHECK(worst < 0.005, "slab box: worst relative error %g", worst);

    /* (2) The slab inside a box [-1, 1]³ of zero density around it: the
     * step sampling must find the slab's faces (midpoint rule, Δ = 0.002:
     * error in optical depth <= σΔ = 0.004). */
    for (int a = 0; a < 3; a++) {
        o.lo[a] = -1;
        o.hi[a] = 1;
    }
    o.step = 0.002;
    max_block = 0;
    CHECK(rm_render(slab_fn, NULL, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    CHECK(max_block > 1 && max_block <= RT_BLOCK, "field called per block: max n %zu", (size_t)max_block);
    worst = 0;
    int tested = 0;
    for (int y = 0; y < im.h; y++)
        for (int x = 0; x < im.w; x++) {
            double d[3];
            camera_ray(&c, im.w, im.h, x + 0.5, y + 0.5, d);
            /* does the ray cross the whole slab inside the box? z = 0.5 .. 0 */
            double t1 = (0 - 3) / d[2]; /* the far face; the near one is inside it */
            int ok = fabs(t1 * d[0]) <= 1 && fabs(t1 * d[1]) <= 1;
            if (!ok)
                continue;
            tested++;
            double T = exp(-2 * 0.5 / fabs(d[2]));
            double err = fabs(image_at(&im, x, y)[0] - T) / T;
            if (err > worst)
                worst = err;
        }
    CHECK(tested > 100, "only %d pixels cross the slab", tested);
    CHECK(worst < 0.005, "slab in box: worst relative error %g", worst);

    /* (3) Emission of a uniform slab over a black background: C (1 - T). */
    o.emission[0] = 0.8f, o.emission[1] = 0.4f, o.emission[2] = 0.2f;
    o.background[0] = o.background[1] = o.background[2] = 0;
    o.background[3] = 0;
    CHECK(rm_render(slab_fn, NULL, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    double d[3];
    camera_ray(&c, im.w, im.h, 12.5, 10.5, d);
    double T = exp(-2 * 0.5 / fabs(d[2]));
    const float *p = image_at(&im, 12, 10);
    CHECK(fabs(p[0] - 0.8 * (1 - T)) < 0.005 * 0.8 * (1 - T), "emission red %g vs %g", p[0], 0.8 * (1 - T));
    CHECK(fabs(p[2] - 0.2 * (1 - T)) < 0.005 * 0.2 * (1 - T), "emission blue %g", p[2]);
    CHECK(fabs(p[3] - (1 - T)) < 0.005 * (1 - T), "alpha over transparent background %g", p[3]);
    image_free(&im);
}

static void test_sphere_silhouette(void)
{
    double D = 4;
    camera c = look_down_z(D, 40);
    image im;
    rt_error e;
    int W = 81, H = 61;
    CHECK(image_init(&im, W, H, &e) == RT_OK, "image");
    rm_opts o;
    rm_defaults(&o);
    o.mode = RM_SOLID;
    o.threshold = 0;
    o.step = 0.01;
    o.light[0] = 0, o.light[1] = 0, o.light[2] = 1; /* light from the camera */
    o.ambient = 0;
    o.lo[0] = o.lo[1] = o.lo[2] = -1.2;
    o.hi[0] = o.hi[1] = o.hi[2] = 1.2;
    CHECK(rm_render(ball_fn, NULL, &c, &o, NULL, &im, &e) == RT_OK, "%s", e.msg);
    /* Projected radius in pixels: the sphere subtends asin(r/D). */
    double rpx = tan(asin(1 / D)) / tan(20 * 3.14159265358979323846 / 180) * H / 2.0;
    int cx = W / 2, cy = H / 2; /* pixel (40, 30) is centred on the axis */
    int left = cx, right = cx, top = cy, bottom = cy;
    while (left > 0 && image_at(&im, left - 1, cy)[3] > 0.5 && image_at(&im, left - 1, cy)[0] > 0)
        left--;
    while (right < W - 1 && image_at(&im, right + 1, cy)[0] > 0)
        right++;
    while (top > 0 && image_at(&im, cx, top - 1)[0] > 0)
        top--;
    while (bottom < H - 1 && image_at(&im, cx, bottom + 1)[0] > 0)
        bottom++;
    double wr = (right - left + 1) / 2.0, hr = (bottom - top + 1) / 2.0;
    CHECK(fabs(wr - rpx) <= 1, "silhouette half-width %g px vs projected radius %g", wr, rpx);
    CHECK(fabs(hr - rpx) <= 1, "silhouette half-height %g px vs projected radius %g", hr, rpx);
    /* Every pixel whose ray passes clearly inside / outside is hit / missed,
     * and with the light at the eye the shade is n · l = cos of the
     * incidence angle: 1 at the centre. */
    size_t wrong = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d[3];
            camera_ray(&c, W, H, x + 0.5, y + 0.5, d);
            double b = D * sqrt(1 - d[2] * d[2]); /* ray's distance from the centre */
            int hit = image_at(&im, x, y)[0] > 0;
            if (b < 0.97 && !hit)
                wrong++;
            if (b > 1.03 && hit)
                wrong++;
        }
    CHECK(wrong == 0, "%zu pixels on the wrong side of the silhouette", wrong);
    const float *ctr = image_at(&im, cx, cy);
    CHECK_NEAR(ctr[0], 1.0, 2e-3, "centre shade (normal toward the light)");
    /* off-centre pixel: the hit point p on the unit sphere has normal p, so
     * the shade is p · (0, 0, 1) = p_z */
    {
        double d[3];
        camera_ray(&c, W, H, cx + 10.5, cy + 0.5, d);
        double bb = -(D * d[2]), cc = D * D - 1, t = bb - sqrt(bb * bb - cc);
        double pz = D + t * d[2];
        CHECK_NEAR(image_at(&im, cx + 10, cy)[0], pz, 5e-3, "Lambert shade at an off-centre pixel");
    }
    image_free(&im);
}

static void test_threads_and_volume(void)
{
    camera c;
    double tgt[3] = {0, 0, 0};
    camera_orbit(&c, tgt, 3.5, 30, 20, 45);
    rm_opts o;
    rm_defaults(&o);
    o.lighting = 1;
    o.step = 0.02;
    ramp rp = ramp_grey();
    o.emission_ramp = &rp;
    image im[3];
    rt_error e;
    int th[3] = {1, 2, 4};
    for (int mode = 0; mode < 2; mode++) {
        o.mode = mode;
        o.threshold = 0.3;
        for (int k = 0; k < 3; k++) {
            rt_run run = {th[k], NULL, 0};
            CHECK(image_init(&im[k], 37, 29, &e) == RT_OK, "image");
            CHECK(rm_render(ball_fn, NULL, &c, &o, &run, &im[k], &e) == RT_OK, "%s", e.msg);
        }
        for (int k = 1; k < 3; k++)
            CHECK(memcmp(im[k].px, im[0].px, 37 * 29 * 16) == 0, "mode %d: %d threads differ", mode, th[k]);
        for (int k = 0; k < 3; k++)
            image_free(&im[k]);
    }
    /* Volume adapter: a constant volume renders like the constant field. */
    volume v;
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    CHECK(volume_init(&v, 3, 4, 5, lo, hi, &e) == RT_OK, "vol");
    for (int i = 0; i < 60; i++)
        v.v[i] = 0.25f;
    double q = 0.25;
    o.mode = RM_EMISSION;
    o.lighting = 0;
    CHECK(image_init(&im[0], 16, 16, &e) == RT_OK && image_init(&im[1], 16, 16, &e) == RT_OK, "img");
    CHECK(rm_render(rm_volume_field, &v, &c, &o, NULL, &im[0], &e) == RT_OK, "%s", e.msg);
    CHECK(rm_render(const_fn, &q, &c, &o, NULL, &im[1], &e) == RT_OK, "%s", e.msg);
    CHECK(memcmp(im[0].px, im[1].px, 16 * 16 * 16) == 0, "volume adapter differs from constant field");
    image_free(&im[0]);
    image_free(&im[1]);
    volume_free(&v);

    /* Validation messages. */
    CHECK(image_init(&im[0], 4, 4, &e) == RT_OK, "img");
    o.step = 0;
    CHECK(rm_render(const_fn, &q, &c, &o, NULL, &im[0], &e) == RT_EINVAL, "step 0");
    CHECK(strcmp(e.msg, "raymarch step 0 is not a positive number") == 0, "msg: %s", e.msg);
    o.step = 0.1;
    o.hi[2] = -3;
    CHECK(rm_render(const_fn, &q, &c, &o, NULL, &im[0], &e) == RT_EINVAL, "box");
    CHECK(strcmp(e.msg, "raymarch box along z: lo -1 is not below hi -3") == 0, "msg: %s", e.msg);
    image_free(&im[0]);
}

int main(void)
{
    test_slab();
    test_sphere_silhouette();
    test_threads_and_volume();
    return check_done("test_raymarch");
}
