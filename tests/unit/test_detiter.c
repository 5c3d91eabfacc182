/* test_detiter.c — deterministic iteration W^n(K_0) (seed 003 Fig. 1, 3). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "detiter.h"
#include "draw.h"

static const double R3 = 1.7320508075688772; /* √3 */

/* Seed 003 Table 1 (Koch) and Table 2 b (W1), Fractint order a b c d e f. */
static void koch_maps(affine m[2])
{
    m[0] = affine_from_2d(0.5, R3 / 6, R3 / 6, -0.5, 0, 0);
    m[1] = affine_from_2d(0.5, -R3 / 6, -R3 / 6, -0.5, 0.5, R3 / 6);
}

static void table2b_maps(affine m[2])
{
    m[0] = affine_from_2d(0.5, 0.5, 0.5, -0.5, 0, 0);
    m[1] = affine_from_2d(0.5, -0.5, -0.5, -0.5, 0.5, 0.5);
}

/* Apply by hand: x' = a x + b y + e, y' = c x + d y + f. */
static void hand(const affine *m, double *x, double *y)
{
    double a = m->m[0][0], b = m->m[0][1], c = m->m[1][0], d = m->m[1][1];
    double nx = a * *x + b * *y + m->t[0], ny = c * *x + d * *y + m->t[1];
    *x = nx;
    *y = ny;
}

/* Drawing: coverage facts computed by hand. */
/* Per-vertex colours (draw_polyline_rgba) by hand: a 4×2 image whose pixels
 * are world units (py = 2 - y); the line y = 1.5 runs through row 0's
 * centres from x = 0.5 (red) to 2.5 (blue) to 3.5 (green), width 2 (reach
 * r = 1.5). Segment 0 has (½, 0, ½, 1), segment 1 (0, ½, ½, 1). Row 0
 * (distance 0): coverage 1, pixel 3 lies 1 from segment 0 (½) and on
 * segment 1 (1), so it is segment 1's; pixel 2 is on both and stays with
 * the first. Row 1 (distance 1): coverage ½, pixel 3 goes to segment 1
 * (1 vs √2 away). On a transparent black image a pixel becomes colour·k
 * with alpha k. */
static void test_rgba_line(void)
{
    rt_error e;
    image im;
    draw_view v;
    CHECK(image_init(&im, 4, 2, &e) == RT_OK, "image");
    CHECK(draw_view_fit(&v, 4, 2, (double[]){0, 0}, (double[]){4, 2}, 0, &e) == RT_OK, "view");
    draw_clear(&im, (float[]){0, 0, 0, 0});
    const double xy[6] = {0.5, 1.5, 2.5, 1.5, 3.5, 1.5};
    const float rgba[12] = {1, 0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1};
    CHECK(draw_polyline_rgba(&im, &v, 3, xy, rgba, 0, 2, &e) == RT_OK, "draw: %s", e.msg);
    static const float want[8][4] = {
        {0.5f, 0, 0.5f, 1}, {0.5f, 0, 0.5f, 1}, {0.5f, 0, 0.5f, 1}, {0, 0.5f, 0.5f, 1},
        {0.25f, 0, 0.25f, 0.5f}, {0.25f, 0, 0.25f, 0.5f}, {0.25f, 0, 0.25f, 0.5f}, {0, 0.25f, 0.25f, 0.5f},
    };
    int same = 1;
    for (int i = 0; i < 8; i++)
        for (int c = 0; c < 4; c++)
            if (im.px[4 * i + c] != want[i][c]) {
                same = 0;
                fprintf(stderr, "pixel %d channel %d: %g, want %g\n", i, c, im.px[4 * i + c], want[i][c]);
            }
    CHECK(same, "per-vertex colour strokes");
    /* Over opaque white with alpha ½ at every vertex: k = ½ in row 0, so
     * pixel 0 is white·½ + (½, 0, ½)·½ = (¾, ½, ¾), alpha stays 1. */
    draw_clear(&im, (float[]){1, 1, 1, 1});
    float half[12];
    for (int i = 0; i < 12; i++)
        half[i] = i % 4 == 3 ? 0.5f : rgba[i];
    CHECK(draw_polyline_rgba(&im, &v, 3, xy, half, 0, 2, &e) == RT_OK, "draw ½");
    CHECK(im.px[0] == 0.75f && im.px[1] == 0.5f && im.px[2] == 0.75f && im.px[3] == 1, "alpha ½: %g %g %g %g",
          im.px[0], im.px[1], im.px[2], im.px[3]);
    draw_view small;
    CHECK(draw_view_fit(&small, 2, 2, (double[]){0, 0}, (double[]){4, 2}, 0, &e) == RT_OK, "small view");
    CHECK(draw_polyline_rgba(&im, &small, 3, xy, rgba, 0, 2, &e) == RT_EINVAL &&
              strcmp(e.msg, "view is 2×2 but the image is 4×2") == 0,
          "view and image differ: %s", e.msg);
    image_free(&im);
}

/* Shape arithmetic by hand: A = the polyline (0,0)-(1,0)-(1,2), B = the
 * triangle (3,1),(4,1),(3,3) (closed). */
static void test_arith(void)
{
    rt_error e;
    detiter_shape a, b, j, m;
    CHECK(detiter_shape_make(&a, 2, 3, (double[]){0, 0, 1, 0, 1, 2}, DETITER_POLYLINE, &e) == RT_OK, "A");
    CHECK(detiter_shape_make(&b, 2, 3, (double[]){3, 1, 4, 1, 3, 3}, DETITER_POLYGON, &e) == RT_OK, "B");
    double lo[2], hi[2];
    detiter_bounds(&b, lo, hi);
    CHECK(lo[0] == 3 && hi[0] == 4 && lo[1] == 1 && hi[1] == 3, "bounds of B");
    /* A ∪ B: 6 vertices, polylines starting at 0 and 3, only the second closed. */
    CHECK(detiter_shape_join(&a, &b, &j, &e) == RT_OK, "join: %s", e.msg);
    CHECK(j.nverts == 6 && j.npoly == 2 && j.start[0] == 0 && j.start[1] == 3 && j.start[2] == 6 && !j.closed[0] &&
              j.closed[1] && j.v[6] == 3 && j.v[11] == 3,
          "join layout");
    CHECK_NEAR(detiter_length(&j), 3 + (1 + 2 + sqrt(5)), 1e-12, "join length = |A| + |B|");
    detiter_bounds(&j, lo, hi);
    CHECK(lo[0] == 0 && hi[0] == 4 && lo[1] == 0 && hi[1] == 3, "bounds of A ∪ B");
    /* A + (2, -1) = (2,-1)-(3,-1)-(3,1); A · 1.5 = (0,0)-(1.5,0)-(1.5,3). */
    CHECK(detiter_shape_shift(&a, (double[]){2, -1}, &m, &e) == RT_OK, "shift");
    CHECK(memcmp(m.v, (double[]){2, -1, 3, -1, 3, 1}, 6 * sizeof(double)) == 0 && m.npoly == 1 && !m.closed[0],
          "shift values");
    detiter_shape_free(&m);
    CHECK(detiter_shape_scale(&a, 1.5, &m, &e) == RT_OK, "scale");
    CHECK(memcmp(m.v, (double[]){0, 0, 1.5, 0, 1.5, 3}, 6 * sizeof(double)) == 0, "scale values");
    detiter_shape_free(&m);
    /* The rotation by 90° (x, y) -> (-y, x) plus (1, 0): B -> (0,3),(0,4),(-2,3). */
    affine r = affine_from_2d(0, -1, 1, 0, 1, 0);
    CHECK(detiter_shape_map(&b, &r, &m, &e) == RT_OK && m.closed[0], "map");
    CHECK(memcmp(m.v, (double[]){0, 3, 0, 4, -2, 3}, 6 * sizeof(double)) == 0, "map values");
    detiter_shape_free(&m);
    /* A 2-D map keeps a 3-D shape's z; a 3-D map does not apply to a 2-D shape. */
    detiter_shape c3;
    CHECK(detiter_shape_make(&c3, 3, 2, (double[]){1, 2, 7, 0, 1, -5}, DETITER_POINTS, &e) == RT_OK, "3-D points");
    CHECK(detiter_shape_map(&c3, &r, &m, &e) == RT_OK, "2-D map on 3-D");
    CHECK(memcmp(m.v, (double[]){-1, 1, 7, 0, 0, -5}, 6 * sizeof(double)) == 0, "z kept");
    detiter_shape_free(&m);
    affine r3 = affine_identity(3);
    CHECK(detiter_shape_map(&a, &r3, &m, &e) == RT_EINVAL &&
              strcmp(e.msg, "a 3-D map cannot apply to a 2-D shape") == 0,
          "3-D map on 2-D: %s", e.msg);
    CHECK(detiter_shape_join(&a, &c3, &m, &e) == RT_EINVAL &&
              strcmp(e.msg, "a 2-D and a 3-D shape cannot be joined") == 0,
          "join 2-D and 3-D: %s", e.msg);
    detiter_shape_free(&c3);
    detiter_shape_free(&j);
    detiter_shape_free(&a);
    detiter_shape_free(&b);
}

static void test_draw(void)
{
    rt_error e;
    image im;
    draw_view v;
    CHECK(image_init(&im, 10, 10, &e) == RT_OK, "image");
    CHECK(draw_view_fit(&v, 10, 10, (double[]){0, 0}, (double[]){10, 10}, 1, &e) == RT_OK, "view");
    /* World (x, y) is pixel (x, 10 − y). A width-1 line along pixel centres
     * y = 4.5 from x = 1 to 9 covers pixels 1..8 of row 5 fully, the end
     * pixels 0 and 9 (centres ½ beyond the ends) half, and nothing else. */
    double seg[4] = {1, 4.5, 9, 4.5};
    detiter_shape s;
    detiter_shape_make(&s, 2, 2, seg, DETITER_POLYLINE, &e);
    draw_style st = {{1, 0.5f, 0.25f, 1}, 1.0, 0, 0};
    CHECK(draw_shape(&im, &v, &s, &st, &e) == RT_OK, "draw line");
    int ok = 1;
    for (int y = 0; y < 10; y++)
        for (int x = 0; x < 10; x++) {
            float *p = image_at(&im, x, y);
            float want = y != 5 ? 0 : x >= 1 && x <= 8 ? 1 : 0.5f;
            ok &= p[3] == want && p[0] == want && p[1] == want * 0.5f;
        }
    CHECK(ok, "line covers row 5: pixels 1..8 fully, 0 and 9 half");
    detiter_shape_free(&s);
    /* Even–odd fill: the triangle (1,3) (9,3) (1,9) has area 24 pixels; the
     * total coverage equals it (widths are linear in y, so the 4 sub-scanline
     * midpoint rule is exact). */
    float clear[4] = {0, 0, 0, 0};
    draw_clear(&im, clear);
    double tri[6] = {1, 3, 9, 3, 1, 9};
    detiter_shape_make(&s, 2, 3, tri, DETITER_POLYGON, &e);
    draw_style fs = {{1, 1, 1, 1}, 0, 0, 1};
    CHECK(draw_shape(&im, &v, &s, &fs, &e) == RT_OK, "fill");
    double area = 0;
    for (int i = 0; i < 100; i++)
        area += im.px[4 * i + 3];
    CHECK_NEAR(area, 24, 1e-5, "filled triangle area");
    CHECK(image_at(&im, 2, 6)[3] == 1 && image_at(&im, 8, 2)[3] == 0, "inside full, outside empty");
    /* SVG: fixed decimals, y flipped, -0 printed as 0. */
    bytebuf b;
    bytebuf_init(&b);
    double pl[4] = {-0.0001, 10, 2.5, 7.25};
    detiter_shape_free(&s);
    detiter_shape_make(&s, 2, 2, pl, DETITER_POLYLINE, &e);
    draw_style ss = {{1, 0, 0, 1}, 1.5, 0, 0};
    CHECK(draw_svg(&b, &v, &s, &ss, NULL, 2, &e) == RT_OK, "svg");
    bytebuf_byte(&b, 0);
    const char *want = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                       "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\" "
                       "viewBox=\"0 0 10 10\">\n"
                       "<g fill=\"none\" stroke=\"#ff0000\" stroke-width=\"1.50\" "
                       "stroke-linejoin=\"round\" stroke-linecap=\"round\">\n"
                       "<polyline points=\"0.00,0.00 2.50,2.75\"/>\n</g>\n</svg>\n";
    CHECK(b.data && strcmp((const char *)b.data, want) == 0, "svg text:\n%s", b.data);
    bytebuf_free(&b);
    detiter_shape_free(&s);
    image_free(&im);
}

static const double TRI[6] = {0, 0, 1, 0, 0.5, 0.28867513459481287};

int main(void)
{
    rt_error e;
    affine koch[2], w2[2];
    koch_maps(koch);
    table2b_maps(w2);
    detiter_shape k0;
    CHECK(detiter_shape_make(&k0, 2, 3, TRI, DETITER_POLYGON, &e) == RT_OK, "make K0");

    /* Koch: K_n has 3·2^n vertices in 2^n triangles; each map is a
     * similarity of ratio 1/√3 so the length grows by 2/√3 per step. */
    fset_ifs kifs = {2, koch, NULL};
    fset kfs = {1, &kifs};
    int zero = 0;
    fset_order per = {FSET_PERIODIC, 1, &zero, NULL, 0};
    double len0 = detiter_length(&k0);
    CHECK_NEAR(len0, 1 + 2 * sqrt(0.25 + 1.0 / 12), 1e-12, "K0 perimeter");
    for (int n = 1; n <= 8; n++) {
        detiter_shape kn;
        rt_code c = detiter_run(&kfs, &per, (size_t)n, &k0, 100000, &kn, NULL, &e);
        CHECK(c == RT_OK, "koch step %d: %s", n, e.msg);
        if (c)
            continue;
        CHECK(kn.nverts == (size_t)3 << n, "K_%d has %zu vertices", n, kn.nverts);
        CHECK(kn.npoly == (size_t)1 << n, "K_%d has %zu polygons", n, kn.npoly);
        CHECK_NEAR(detiter_length(&kn) / len0, pow(2 / R3, n), 1e-9, "Koch length ratio");
        if (n == 8) {
            /* The Koch curve from (0,0) to (1,0) peaks at (1/2, √3/6): its
             * bounding box is [0,1]×[0,√3/6], and K_8 touches all four sides. */
            double mnx = 1e9, mxx = -1e9, mny = 1e9, mxy = -1e9;
            int inside = 1;
            for (size_t i = 0; i < kn.nverts; i++) {
                double x = kn.v[2 * i], y = kn.v[2 * i + 1];
                inside &= x >= -1e-12 && x <= 1 + 1e-12 && y >= -1e-12 && y <= R3 / 6 + 1e-12;
                mnx = fmin(mnx, x), mxx = fmax(mxx, x), mny = fmin(mny, y), mxy = fmax(mxy, y);
            }
            CHECK(inside, "all K_8 vertices in the Koch bounding box");
            CHECK_NEAR(mnx, 0, 1e-12, "K_8 min x");
            CHECK_NEAR(mxx, 1, 1e-12, "K_8 max x");
            CHECK_NEAR(mny, 0, 1e-12, "K_8 min y");
            CHECK_NEAR(mxy, R3 / 6, 1e-12, "K_8 max y");
        }
        detiter_shape_free(&kn);
    }

    /* K_4 = W_2(W_1(W_2(W_1(K_0)))) with W_1 = Koch and W_2 = Table 2 b:
     * every word m4 m3 m2 m1 applied by hand must appear as a triangle. */
    fset_ifs sets[2] = {{2, koch, NULL}, {2, w2, NULL}};
    fset fs = {2, sets};
    int ord[4] = {0, 1, 0, 1};
    fset_order seq = {FSET_SEQUENCE, 4, ord, NULL, 0};
    detiter_shape k4;
    CHECK(detiter_run(&fs, &seq, 4, &k0, 1000, &k4, NULL, &e) == RT_OK, "K_4: %s", e.msg);
    CHECK(k4.nverts == 48 && k4.npoly == 16, "K_4 has 16 triangles");
    int found_all = 1;
    for (int word = 0; word < 16; word++) {
        double t[6];
        memcpy(t, TRI, sizeof t);
        const affine *step[4] = {&koch[word & 1], &w2[(word >> 1) & 1], &koch[(word >> 2) & 1],
                                 &w2[(word >> 3) & 1]};
        for (int v = 0; v < 3; v++)
            for (int s = 0; s < 4; s++)
                hand(step[s], &t[2 * v], &t[2 * v + 1]);
        int found = 0;
        for (size_t p = 0; p < k4.npoly && !found; p++) {
            const double *q = k4.v + 2 * k4.start[p];
            int same = k4.closed[p];
            for (int i = 0; i < 6; i++)
                same &= fabs(q[i] - t[i]) < 1e-12;
            found = same;
        }
        found_all &= found;
    }
    CHECK(found_all, "K_4 equals the composition applied by hand");
    detiter_shape_free(&k4);

    /* A finite order shorter than the steps asked for is an error. */
    detiter_shape bad;
    CHECK(detiter_run(&fs, &seq, 5, &k0, 1000, &bad, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg, "order has 4 steps but deterministic iteration asks for 5") == 0,
          "short order: %s", e.msg);
    /* Vertex budget: 3·2^10 = 3072 > 3000. */
    CHECK(detiter_run(&kfs, &per, 10, &k0, 3000, &bad, NULL, &e) == RT_EINVAL &&
              strcmp(e.msg,
                     "deterministic iteration of 10 steps would need 3072 vertices (limit 3000)") ==
                  0,
          "budget: %s", e.msg);

    /* Points and 3-D: the 3-D Sierpinski maps (scale 1/2 toward the four
     * corners of a tetrahedron) keep a point set inside the unit simplex,
     * and 5 steps from the 4 corners give 4·4^5 points. */
    affine t3[4];
    double corner[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 4; i++) {
        double m9[9] = {0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5};
        double tt[3] = {corner[i][0] / 2, corner[i][1] / 2, corner[i][2] / 2};
        t3[i] = affine_from_3d(m9, tt);
    }
    fset_ifs s3 = {4, t3, NULL};
    fset fs3 = {1, &s3};
    detiter_shape p0, p5;
    CHECK(detiter_shape_make(&p0, 3, 4, &corner[0][0], DETITER_POINTS, &e) == RT_OK, "points");
    CHECK(detiter_run(&fs3, &per, 5, &p0, 1 << 20, &p5, NULL, &e) == RT_OK, "3-D: %s", e.msg);
    CHECK(p5.nverts == 4096 && p5.npoly == 4096, "3-D point count %zu", p5.nverts);
    int in = 1;
    for (size_t i = 0; i < p5.nverts; i++) {
        const double *q = p5.v + 3 * i;
        in &= q[0] >= 0 && q[1] >= 0 && q[2] >= 0 && q[0] + q[1] + q[2] <= 1 + 1e-12;
    }
    CHECK(in, "3-D points stay in the simplex");

    /* Byte-identical for 1, 2, 4 threads (big enough for several chunks). */
    detiter_shape ref;
    rt_run r1 = {1, NULL, 0};
    CHECK(detiter_run(&fs3, &per, 8, &p0, 1 << 20, &ref, &r1, &e) == RT_OK, "8 steps");
    for (int t = 2; t <= 4; t += 2) {
        rt_run rt = {t, NULL, 0};
        detiter_shape o;
        CHECK(detiter_run(&fs3, &per, 8, &p0, 1 << 20, &o, &rt, &e) == RT_OK, "threads");
        CHECK(o.nverts == ref.nverts && memcmp(o.v, ref.v, ref.nverts * 3 * sizeof(double)) == 0,
              "identical with %d threads", t);
        detiter_shape_free(&o);
    }
    detiter_shape_free(&ref);
    detiter_shape_free(&p0);
    detiter_shape_free(&p5);
    detiter_shape_free(&k0);
    test_draw();
    test_arith();
    test_rgba_line();
    return check_done("test_detiter");
}
