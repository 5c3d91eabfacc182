/* test_raster.c — Z-buffer rasteriser: coverage, shared edges, depth,
 * transparency, determinism. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "raster.h"
#include "wrinkly.h"

/* Camera at (0,0,1) looking at the origin with a 90° field of view on a
 * 100×100 image: world (x, y, 0) lands on pixel coordinates
 * (50(x+1), 50(1-y)), so screen positions can be chosen by hand. */
static void cam100(camera *c)
{
    memset(c, 0, sizeof *c);
    c->eye[2] = 1;
    c->up[1] = 1;
    c->fov = 90;
    camera_setup(c);
}

static void vert(mesh *m, double sx, double sy, double z, float r, float g, float b, float a)
{
    float p[3] = {(float)(sx / 50 - 1), (float)(1 - sy / 50), (float)z};
    /* on the plane z != 0 the perspective scale is 1/(1 - z) */
    p[0] *= (float)(1 - z), p[1] *= (float)(1 - z);
    float c[4] = {r, g, b, a};
    mesh_add_vertex(m, p, NULL, c);
}

static size_t count_alpha(const image *im, float a)
{
    size_t n = 0;
    for (int y = 0; y < im->h; y++)
        for (int x = 0; x < im->w; x++)
            n += image_at(im, x, y)[3] == a;
    return n;
}

static void test_coverage(void)
{
    camera cam;
    cam100(&cam);
    raster_opts o;
    raster_opts_default(&o);
    o.unlit = 1;
    o.background[3] = 0;
    image im;
    rt_error e;
    image_init(&im, 100, 100, &e);
    /* one triangle (10,10) (90,10) (10,90): pixel centres strictly inside,
     * with px >= 10, py >= 10, px + py <= 98 (the hypotenuse is a bottom-right
     * edge, so centres on it are excluded): Σ_{a+b<=78} 1 = 79·80/2 = 3160 */
    mesh m;
    mesh_init(&m, 0, 1);
    vert(&m, 10, 10, 0, 1, 1, 1, 1);
    vert(&m, 90, 10, 0, 1, 1, 1, 1);
    vert(&m, 10, 90, 0, 1, 1, 1, 1);
    mesh_add_tri(&m, 0, 1, 2);
    CHECK(raster_render(&m, &cam, &o, NULL, &im, &e) == RT_OK, "render: %s", e.msg);
    CHECK(count_alpha(&im, 1) == 3160, "single triangle covers %zu pixels, expected 3160", count_alpha(&im, 1));
    CHECK(image_at(&im, 10, 10)[3] == 1 && image_at(&im, 9, 10)[3] == 0 && image_at(&im, 10, 88)[3] == 1 &&
              image_at(&im, 10, 89)[3] == 0,
          "corner pixels");
    /* the second half of the square, half transparent: every pixel of the
     * 80×80 square drawn exactly once → alpha 0.5 everywhere, never 0.75 */
    mesh m2;
    mesh_init(&m2, 0, 1);
    vert(&m2, 10, 10, 0, 1, 1, 1, 0.5f);
    vert(&m2, 90, 10, 0, 1, 1, 1, 0.5f);
    vert(&m2, 10, 90, 0, 1, 1, 1, 0.5f);
    vert(&m2, 90, 90, 0, 1, 1, 1, 0.5f);
    mesh_add_tri(&m2, 0, 1, 2);
    mesh_add_tri(&m2, 1, 3, 2);
    CHECK(raster_render(&m2, &cam, &o, NULL, &im, &e) == RT_OK, "render 2");
    CHECK(count_alpha(&im, 0.5f) == 6400, "shared edge: %zu pixels at alpha 0.5, expected 6400",
          count_alpha(&im, 0.5f));
    CHECK(count_alpha(&im, 0.75f) == 0, "no pixel drawn twice");
    /* the other winding gives the same coverage */
    m2.tri[1] = 2, m2.tri[2] = 1, m2.tri[4] = 2, m2.tri[5] = 3;
    raster_render(&m2, &cam, &o, NULL, &im, &e);
    CHECK(count_alpha(&im, 0.5f) == 6400, "clockwise winding too");
    mesh_free(&m);
    mesh_free(&m2);
    image_free(&im);
}

static void test_depth(void)
{
    camera cam;
    cam100(&cam);
    raster_opts o;
    raster_opts_default(&o);
    o.unlit = 1;
    image im;
    rt_error e;
    image_init(&im, 100, 100, &e);
    for (int order = 0; order < 2; order++) {
        mesh m;
        mesh_init(&m, 0, 1);
        double zr = order ? 0.5 : 0, zg = order ? 0 : 0.5; /* green is nearer when order == 0 */
        vert(&m, 0, 0, zr, 1, 0, 0, 1), vert(&m, 100, 0, zr, 1, 0, 0, 1), vert(&m, 50, 100, zr, 1, 0, 0, 1);
        vert(&m, 0, 100, zg, 0, 1, 0, 1), vert(&m, 100, 100, zg, 0, 1, 0, 1), vert(&m, 50, 0, zg, 0, 1, 0, 1);
        mesh_add_tri(&m, 0, 1, 2);
        mesh_add_tri(&m, 3, 4, 5);
        raster_render(&m, &cam, &o, NULL, &im, &e);
        const float *c = image_at(&im, 50, 50);
        if (order == 0)
            CHECK(c[1] == 1 && c[0] == 0, "nearer green wins: %g %g", c[0], c[1]);
        else
            CHECK(c[0] == 1 && c[1] == 0, "nearer red wins: %g %g", c[0], c[1]);
        /* a transparent triangle behind an opaque one is hidden, in front it blends */
        mesh_free(&m);
    }
    mesh m;
    mesh_init(&m, 0, 1);
    vert(&m, 0, 0, 0, 1, 0, 0, 1), vert(&m, 100, 0, 0, 1, 0, 0, 1), vert(&m, 50, 100, 0, 1, 0, 0, 1);
    vert(&m, 0, 100, 0.5, 0, 0, 1, 0.25f), vert(&m, 100, 100, 0.5, 0, 0, 1, 0.25f), vert(&m, 50, 0, 0.5, 0, 0, 1, 0.25f);
    mesh_add_tri(&m, 3, 4, 5); /* transparent first in mesh order: still blended after the opaque one */
    mesh_add_tri(&m, 0, 1, 2);
    raster_render(&m, &cam, &o, NULL, &im, &e);
    const float *c = image_at(&im, 50, 50);
    CHECK_NEAR(c[0], 0.75, 1e-6, "blend red");
    CHECK_NEAR(c[2], 0.25, 1e-6, "blend blue");
    CHECK(c[3] == 1, "opaque result");
    mesh_free(&m);
    image_free(&im);
}

static void test_threads(void)
{
    int nu = 6, nv = 5;
    wrinkly_point *p = calloc((size_t)nu * nv, sizeof *p);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            wrinkly_point *q = &p[j * nu + i];
            double a = 6.283185307179586 * i / nu, b = 6.283185307179586 * j / nv;
            q->pos[0] = (2 + 0.7 * cos(b)) * cos(a), q->pos[1] = 0.7 * sin(b), q->pos[2] = (2 + 0.7 * cos(b)) * sin(a);
            q->h = 0.1 * ((i + 2 * j) % 4);
            q->rgb[0] = 0.2 + 0.1 * i, q->rgb[1] = 0.5, q->rgb[2] = 0.2 * j;
            q->opacity = (i + j) % 3 ? 1 : 0.6;
        }
    wrinkly_surface s = {p, nu, nv, {1, 1, 1}, {1, 1, 1}};
    wrinkly_opts wo;
    wrinkly_opts_default(&wo);
    wo.k = 2;
    mesh m;
    rt_error e;
    wrinkly_surface_mesh(&s, &wo, NULL, &m, NULL, &e);
    camera cam;
    camera_orbit(&cam, (double[3]){0, 0, 0}, 6, 30, 35, 45);
    raster_opts o;
    raster_opts_default(&o);
    o.tile = 16;
    image ref;
    image_init(&ref, 97, 71, &e);
    CHECK(raster_render(&m, &cam, &o, NULL, &ref, &e) == RT_OK, "render");
    size_t lit = 0;
    for (int y = 0; y < ref.h; y++)
        for (int x = 0; x < ref.w; x++)
            lit += image_at(&ref, x, y)[0] > 0;
    CHECK(lit > 1000, "the surface is visible: %zu pixels", lit);
    for (int th = 2; th <= 4; th += 2) {
        rt_run run = {th, NULL, 0};
        image im;
        image_init(&im, 97, 71, &e);
        raster_render(&m, &cam, &o, &run, &im, &e);
        CHECK(!memcmp(im.px, ref.px, sizeof(float) * 4 * 97 * 71), "threads %d byte-identical", th);
        image_free(&im);
    }
    image_free(&ref);
    mesh_free(&m);
    free(p);
}


/* Parallel binning: a mesh of several binning chunks, mostly opaque and
 * drawn twice (equal depths), on small tiles gives the same bytes for 1-4 threads and the same bytes as
 * one tile covering the image (where the list is the whole mesh in mesh
 * order), so each tile list keeps mesh order across chunks. */
static void test_binning(void)
{
    int nu = 6, nv = 5;
    wrinkly_point *p = calloc((size_t)nu * nv, sizeof *p);
    for (int j = 0; j < nv; j++)
        for (int i = 0; i < nu; i++) {
            wrinkly_point *q = &p[j * nu + i];
            double a = 6.283185307179586 * i / nu, b = 6.283185307179586 * j / nv;
            q->pos[0] = (2 + 0.7 * cos(b)) * cos(a), q->pos[1] = 0.7 * sin(b), q->pos[2] = (2 + 0.7 * cos(b)) * sin(a);
            q->h = 0.1 * ((i + 2 * j) % 4);
            q->rgb[0] = 0.2 + 0.1 * i, q->rgb[1] = 0.5, q->rgb[2] = 0.2 * j;
            q->opacity = i == 2 && j == 1 ? 0.6 : 1; /* mostly opaque: ties decide */
        }
    wrinkly_surface s = {p, nu, nv, {1, 1, 1}, {1, 1, 1}};
    wrinkly_opts wo;
    wrinkly_opts_default(&wo);
    wo.k = 3;
    mesh m0;
    rt_error e;
    CHECK(wrinkly_surface_mesh(&s, &wo, NULL, &m0, NULL, &e) == RT_OK, "mesh: %s", e.msg);
    /* the surface twice, the copy green: at equal depth the earlier
     * triangle wins, so any change of list order shows */
    mesh m;
    mesh_init(&m, m0.nrm != NULL, 1);
    for (int copy = 0; copy < 2; copy++) {
        for (size_t v = 0; v < m0.nv; v++) {
            float c[4] = {0, 1, 0, m0.col ? m0.col[4 * v + 3] : 1};
            mesh_add_vertex(&m, m0.pos + 3 * v, m0.nrm ? m0.nrm + 3 * v : NULL,
                            copy ? c : m0.col ? m0.col + 4 * v : c);
        }
        for (size_t t = 0; t < m0.nt; t++)
            mesh_add_tri(&m, m0.tri[3 * t] + (uint32_t)(copy * m0.nv), m0.tri[3 * t + 1] + (uint32_t)(copy * m0.nv),
                         m0.tri[3 * t + 2] + (uint32_t)(copy * m0.nv));
    }
    mesh_free(&m0);
    CHECK(m.nt > 3 * 4096, "several binning chunks: %zu triangles", m.nt);
    camera cam;
    camera_orbit(&cam, (double[3]){0, 0, 0}, 5, 20, 35, 45);
    raster_opts o;
    raster_opts_default(&o);
    o.tile = 1024;
    int w = 203, h = 151;
    size_t bytes = sizeof(float) * 4 * (size_t)w * (size_t)h;
    image ref;
    image_init(&ref, w, h, &e);
    CHECK(raster_render(&m, &cam, &o, NULL, &ref, &e) == RT_OK, "render");
    size_t lit = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            lit += image_at(&ref, x, y)[0] > 0;
    CHECK(lit > 5000, "the surface is visible: %zu pixels", lit);
    size_t green = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *c = image_at(&ref, x, y);
            green += c[1] > 0 && c[0] == 0 && c[2] == 0 && c[3] == 1;
        }
    /* (a handful of pure-green pixels remain near the transparent patch) */
    CHECK(green < 100, "the earlier triangle wins the ties: %zu green pixels", green);
    /* and with the copy first it is green: the test sees the list order */
    size_t half = 3 * (m.nt / 2);
    uint32_t *sw = malloc(sizeof(uint32_t) * 2 * half);
    memcpy(sw, m.tri + half, sizeof(uint32_t) * half);
    memcpy(sw + half, m.tri, sizeof(uint32_t) * half);
    uint32_t *keep = m.tri;
    m.tri = sw;
    image gi;
    image_init(&gi, w, h, &e);
    raster_render(&m, &cam, &o, NULL, &gi, &e);
    green = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *c = image_at(&gi, x, y);
            green += c[1] > 0 && c[0] == 0 && c[2] == 0 && c[3] == 1;
        }
    CHECK(green > 1000, "copy first: %zu green pixels", green);
    image_free(&gi);
    m.tri = keep;
    free(sw);
    for (int tile = 8; tile <= 16; tile *= 2)
        for (int th = 1; th <= 4; th++) {
            rt_run run = {th, NULL, 0};
            image im;
            image_init(&im, w, h, &e);
            o.tile = tile;
            CHECK(raster_render(&m, &cam, &o, &run, &im, &e) == RT_OK, "render");
            CHECK(!memcmp(im.px, ref.px, bytes), "tile %d, threads %d: same bytes as one tile", tile, th);
            image_free(&im);
        }
    image_free(&ref);
    mesh_free(&m);
    free(p);
}

int main(void)
{
    test_coverage();
    test_depth();
    test_threads();
    test_binning();
    return check_done("test_raster");
}
