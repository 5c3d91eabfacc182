/* test_raster.c — Z-buffer rasteriser: coverage, shared edges, depth,
 * transparency, determinism. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "rt_alloc.h"
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
    wrinkly_point *p = rt_calloc((size_t)nu * nv, sizeof *p);
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
    /* the camera inside the closed tube, looking along it with a wide field
     * of view, so triangles pass beside and behind it: every ray hits the
     * surface, so no pixel is left background (dropping the triangles that
     * cross the near plane left 810 holes); still byte-identical for any
     * thread count and tile size */
    memset(&cam, 0, sizeof cam);
    cam.eye[0] = 1.6, cam.target[0] = 1.6, cam.target[2] = 1, cam.up[1] = 1, cam.fov = 100;
    camera_setup(&cam);
    o.background[3] = 0;
    raster_render(&m, &cam, &o, NULL, &ref, &e);
    size_t holes = 0;
    for (int y = 0; y < ref.h; y++)
        for (int x = 0; x < ref.w; x++)
            holes += image_at(&ref, x, y)[3] == 0;
    CHECK(holes == 0, "inside the tube: %zu holes", holes);
    for (int th = 1; th <= 4; th += 3) {
        rt_run run = {th, NULL, 0};
        image im;
        image_init(&im, 97, 71, &e);
        o.tile = 8;
        raster_render(&m, &cam, &o, &run, &im, &e);
        CHECK(!memcmp(im.px, ref.px, sizeof(float) * 4 * 97 * 71), "inside, tile 8, threads %d byte-identical", th);
        image_free(&im);
    }
    image_free(&ref);
    mesh_free(&m);
    rt_free(p);
}


/* Parallel binning: a mesh of several binning chunks, mostly opaque and
 * drawn twice (equal depths), on small tiles gives the same bytes for 1-4 threads and the same bytes as
 * one tile covering the image (where the list is the whole mesh in mesh
 * order), so each tile list keeps mesh order across chunks. */
static void test_binning(void)
{
    int nu = 6, nv = 5;
    wrinkly_point *p = rt_calloc((size_t)nu * nv, sizeof *p);
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
    /* none: the transparent patch too is drawn with the earlier copy in
     * front (it once sorted the later copy in front, which replaced the
     * original wherever the interpolated alpha rounded to 1: 6 pure-green
     * and some 5,800 all but green pixels) */
    CHECK(green == 0, "the earlier triangle wins the ties: %zu green pixels", green);
    size_t greenish = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *c = image_at(&ref, x, y);
            greenish += c[1] > 0 && c[0] < 0.02f && c[2] < 0.02f;
        }
    CHECK(greenish == 0, "transparent ties: %zu nearly green pixels", greenish);
    /* and with the copy first it is green: the test sees the list order */
    size_t half = 3 * (m.nt / 2);
    uint32_t *sw = rt_malloc(sizeof(uint32_t) * 2 * half);
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
    rt_free(sw);
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
    rt_free(p);
}

/* Near-plane clipping. Camera at (0, 1, 0) looking along -z, 90° on
 * 100×100: a pixel centre (px + 1/2, py + 1/2) has the ray direction
 * (nx, ny, -1) with nx = (px + 1/2)/50 - 1, ny = 1 - (py + 1/2)/50. The
 * floor y = 0, a square |x|, |z| <= L = 1000 around the camera (two
 * triangles, corners behind the camera), is hit by the rays with ny < 0 at
 * view depth d = -1/ny, world x = nx·d, z = -d: inside the square when
 * d <= L, i.e. ny <= -1/L, i.e. py + 1/2 >= 50.05, and |nx| < 1 always.
 * So exactly rows 50..99: 5,000 pixels, each drawn once (half transparent,
 * so a pixel drawn twice would show alpha 0.75). Every triangle crosses the
 * near plane and the cut corners land far outside the ±2^20 guard band; the
 * old set-up dropped both triangles and drew nothing. */
static void floor_mesh(mesh *m, double L, float a)
{
    mesh_init(m, 0, 1);
    const double cx[4] = {-1, 1, 1, -1}, cz[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; k++) {
        float p[3] = {(float)(cx[k] * L), 0, (float)(cz[k] * L)};
        /* colours linear on the plane: r along x, g along z */
        float c[4] = {(float)(0.5 + 0.4 * cx[k]), (float)(0.5 + 0.4 * cz[k]), 0.25f, a};
        mesh_add_vertex(m, p, NULL, c);
    }
    mesh_add_tri(m, 0, 1, 2);
    mesh_add_tri(m, 0, 2, 3);
}

static void test_near_clip(void)
{
    camera cam;
    memset(&cam, 0, sizeof cam);
    cam.eye[1] = 1, cam.target[1] = 1, cam.target[2] = -1, cam.up[1] = 1, cam.fov = 90;
    camera_setup(&cam);
    raster_opts o;
    raster_opts_default(&o);
    o.unlit = 1;
    o.background[3] = 0;
    rt_error e;
    image im;
    image_init(&im, 100, 100, &e);
    const double L = 1000;
    mesh m;
    floor_mesh(&m, L, 0.5f);
    CHECK(raster_render(&m, &cam, &o, NULL, &im, &e) == RT_OK, "render: %s", e.msg);
    size_t cover = count_alpha(&im, 0.5f), wrong = 0;
    for (int y = 0; y < 100; y++)
        for (int x = 0; x < 100; x++)
            wrong += image_at(&im, x, y)[3] != (y >= 50 ? 0.5f : 0.0f);
    CHECK(cover == 5000, "floor through the near plane covers %zu pixels, expected 5000", cover);
    CHECK(wrong == 0, "%zu pixels off the rows below the horizon (or drawn twice)", wrong);
    /* colours as on the unclipped plane: r = 0.5 + 0.4 x/L, g = 0.5 - 0.4 d/L
     * (to the snapping of corners to 1/256 px: away from the horizon row,
     * where d changes by 200 per pixel, that is well under 1e-4) */
    const int probe[][2] = {{0, 52}, {99, 52}, {30, 51}, {71, 60}, {5, 99}, {50, 75}};
    for (size_t i = 0; i < sizeof probe / sizeof probe[0]; i++) {
        int px = probe[i][0], py = probe[i][1];
        double nx = (px + 0.5) / 50 - 1, ny = 1 - (py + 0.5) / 50, d = -1 / ny;
        const float *c = image_at(&im, px, py);
        CHECK_NEAR(c[0], 0.5 + 0.4 * nx * d / L, 1e-4, "clipped floor red");
        CHECK_NEAR(c[1], 0.5 - 0.4 * d / L, 1e-4, "clipped floor green");
    }
    /* opaque, the same coverage; small tiles and threads give the same bytes */
    mesh_free(&m);
    floor_mesh(&m, L, 1);
    CHECK(raster_render(&m, &cam, &o, NULL, &im, &e) == RT_OK, "render opaque");
    CHECK(count_alpha(&im, 1) == 5000, "opaque floor covers %zu pixels", count_alpha(&im, 1));
    for (int th = 1; th <= 4; th += 3) {
        rt_run run = {th, NULL, 0};
        image im2;
        image_init(&im2, 100, 100, &e);
        o.tile = 8;
        raster_render(&m, &cam, &o, &run, &im2, &e);
        CHECK(!memcmp(im2.px, im.px, sizeof(float) * 4 * 100 * 100), "clipped, tile 8, threads %d: same bytes", th);
        image_free(&im2);
    }
    o.tile = 32;
    /* looking the other way along the floor from below it: still rows 50..99 mirrored */
    cam.eye[1] = -1, cam.target[1] = -1;
    camera_setup(&cam);
    raster_render(&m, &cam, &o, NULL, &im, &e);
    size_t up = 0;
    for (int y = 0; y < 50; y++)
        for (int x = 0; x < 100; x++)
            up += image_at(&im, x, y)[3] == 1;
    CHECK(up == 5000 && count_alpha(&im, 1) == 5000, "floor from below covers rows 0..49: %zu", up);
    /* wholly behind the camera: nothing */
    cam.target[2] = 1, cam.eye[1] = 1, cam.target[1] = 1;
    cam.eye[2] = -1001, cam.target[2] = -1002;
    camera_setup(&cam);
    raster_render(&m, &cam, &o, NULL, &im, &e);
    CHECK(count_alpha(&im, 0) == 10000, "behind the camera: nothing drawn");
    mesh_free(&m);
    image_free(&im);
}

int main(void)
{
    test_coverage();
    test_depth();
    test_threads();
    test_binning();
    test_near_clip();
    return check_done("test_raster");
}
