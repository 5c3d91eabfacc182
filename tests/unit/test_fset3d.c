/* test_fset3d.c — 3-D function sets (seed 003 §3-4): iterating a mesh
 * (fset_iterate_mesh), orienting polyhedra (mesh_orient_outward), the 3-D
 * chaos game through a camera (fset_chaos_view, fset_chaos_box) and the one
 * default framing (camera_frame_box, camera_frame_sphere). Expected values are worked by hand. */
#include <string.h>

#include "camera.h"
#include "check.h"
#include "fset.h"
#include "mesh.h"

static const double PI = 3.14159265358979323846;

static affine half(double tx, double ty, double tz, double sx)
{
    double m[9] = {0.5 * sx, 0, 0, 0, 0.5, 0, 0, 0, 0.5}, t[3] = {tx, ty, tz};
    return affine_from_3d(m, t);
}

/* the unit cube, 12 triangles wound outward */
static void unit_cube(mesh *m)
{
    mesh_init(m, 0, 0);
    for (int i = 0; i < 8; i++) {
        float p[3] = {(float)(i & 1), (float)((i >> 1) & 1), (float)((i >> 2) & 1)};
        mesh_add_vertex(m, p, NULL, NULL);
    }
    static const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; f++) {
        mesh_add_tri(m, q[f][0], q[f][1], q[f][2]);
        mesh_add_tri(m, q[f][0], q[f][2], q[f][3]);
    }
}

int main(void)
{
    rt_error e;
    mesh cube;
    unit_cube(&cube);
    mesh_stats st;
    CHECK(mesh_compute_stats(&cube, &st, &e) == RT_OK && fabs(st.volume - 1) < 1e-12, "cube volume %g", st.volume);

    /* orientation: reversed cube comes back outward; a clash is refused */
    mesh rev;
    unit_cube(&rev);
    for (size_t t = 0; t < rev.nt; t++) {
        uint32_t x = rev.tri[3 * t + 1];
        rev.tri[3 * t + 1] = rev.tri[3 * t + 2];
        rev.tri[3 * t + 2] = x;
    }
    int closed = 0;
    CHECK(mesh_orient_outward(&rev, &closed, &e) == RT_OK && closed, "reversed cube is closed");
    CHECK(mesh_compute_stats(&rev, &st, &e) == RT_OK && fabs(st.volume - 1) < 1e-12, "turned outward: %g", st.volume);
    rev.tri[0] = rev.tri[3], rev.tri[1] = rev.tri[4], rev.tri[2] = rev.tri[5]; /* a duplicated triangle */
    CHECK(mesh_orient_outward(&rev, &closed, &e) == RT_EINVAL && strstr(e.msg, "same direction"), "clash: %s", e.msg);
    mesh_free(&rev);

    /* three half maps, the third mirrored in x: 27 copies after 3 steps,
     * pieces disjoint, each outward: volume (3/8)^3, box worked by hand */
    affine w[3] = {half(0, 0, 0, 1), half(1, 0, 0, 1), half(0.5, 0, 1, -1)};
    fset_ifs set = {3, w, NULL};
    fset fs = {1, &set};
    int seq[1] = {0};
    fset_order o = {FSET_PERIODIC, 1, seq, NULL, 0};
    mesh k, k1;
    rt_run run3 = {3, NULL, 0}, run1 = {1, NULL, 0};
    CHECK(fset_iterate_mesh(&fs, &o, 3, 27, &cube, &k, &run3, &e) == RT_OK, "iterate: %s", e.msg);
    CHECK(k.nv == 8 * 27 && k.nt == 12 * 27, "counts %zu %zu", k.nv, k.nt);
    CHECK(mesh_compute_stats(&k, &st, &e) == RT_OK, "stats");
    CHECK(st.boundary_edges == 0 && st.nonmanifold_edges == 0 && st.euler == 54, "closed pieces, euler %ld", st.euler);
    CHECK_NEAR(st.volume, 27.0 / 512, 1e-9, "volume");
    CHECK(fset_iterate_mesh(&fs, &o, 3, 27, &cube, &k1, &run1, &e) == RT_OK, "iterate 1 thread");
    CHECK(memcmp(k.pos, k1.pos, k.nv * 3 * sizeof(float)) == 0 && memcmp(k.tri, k1.tri, k.nt * 3 * sizeof(uint32_t)) == 0,
          "same mesh on 1 and 3 threads");
    mesh_free(&k1);
    /* map-major layout (as detiter): K_3 lists K_2 under ω_1, then under ω_2,
     * …, so the first-applied map varies fastest. Copy 1 is ω_1 ∘ ω_1 ∘ ω_2
     * (x: 1 .. 1.5, then 0.5 .. 0.75, then 0.25 .. 0.375) and copy 9 is
     * ω_2 ∘ ω_1 ∘ ω_1 (x: 0 .. 0.25, then 1 .. 1.125). */
    CHECK(k.pos[3 * 8] == 0.25f && k.pos[3 * 15] == 0.375f, "copy 1 at x = 0.25 .. 0.375: %g %g", k.pos[3 * 8],
          k.pos[3 * 15]);
    CHECK(k.pos[3 * 72] == 1.0f && k.pos[3 * 79] == 1.125f, "copy 9 at x = 1 .. 1.125: %g %g", k.pos[3 * 72],
          k.pos[3 * 79]);
    CHECK(fset_iterate_mesh(&fs, &o, 3, 26, &cube, &k1, &run1, &e) == RT_EINVAL, "a wrong copy count is refused");
    mesh_free(&k);

    /* the 3-D chaos game: walks of depth 1 from s end at the three ω_i(s) */
    fset_chaos_opts co = {FSET_WALK, 3000, 4, 0, 0, 1, {0.2, 0.4, 0.6}};
    camera cam;
    double lo[3], hi[3];
    CHECK(fset_chaos_box(&fs, &o, &co, lo, hi, &e) == RT_OK, "box: %s", e.msg);
    /* the x ends are 0.1, 1.1 and 0.5 - 0.1 = 0.4: box 0.1 .. 1.1 widened by 5 % */
    CHECK_NEAR(lo[0], 0.05, 1e-12, "box lo x");
    CHECK_NEAR(hi[0], 1.15, 1e-12, "box hi x");
    CHECK(camera_frame_box(&cam, lo, hi, 40, 30, 30, 20, 40) == 0, "frame");
    image im;
    CHECK(image_init(&im, 40, 30, &e) == RT_OK, "image");
    float bg[4] = {0, 0, 0, 1};
    CHECK(fset_chaos_view(&fs, &o, &co, &cam, bg, &im, &run3, &e) == RT_OK, "view: %s", e.msg);
    int lit = 0;
    for (int i = 0; i < 40 * 30; i++)
        lit += im.px[4 * i] > 0;
    CHECK(lit == 3, "three lit pixels, got %d", lit);
    /* orbits: the same picture on 1 and 3 threads (per-worker depth buffers
     * merged by min) */
    fset_chaos_opts oo = {FSET_ORBIT, 300000, 9, 20, 1, 0, {0, 0, 0}};
    image im1;
    CHECK(image_init(&im1, 40, 30, &e) == RT_OK, "image");
    CHECK(fset_chaos_view(&fs, &o, &oo, &cam, bg, &im, &run3, &e) == RT_OK, "orbit view 3 threads");
    CHECK(fset_chaos_view(&fs, &o, &oo, &cam, bg, &im1, &run1, &e) == RT_OK, "orbit view 1 thread");
    CHECK(memcmp(im.px, im1.px, sizeof(float) * 4 * 40 * 30) == 0, "same picture on 1 and 3 threads");
    image_free(&im1);
    image_free(&im);

    /* camera_frame_box: all 8 corners of a box inside the image, within the
     * stated margin, for wide and tall images */
    double blo[3] = {-2, 0, 1}, bhi[3] = {3, 0.5, 1.2};
    int sizes[2][2] = {{200, 100}, {100, 200}};
    for (int s = 0; s < 2; s++) {
        int W = sizes[s][0], H = sizes[s][1];
        CHECK(camera_frame_box(&cam, blo, bhi, W, H, 30, 20, 40) == 0, "frame %dx%d", W, H);
        double worst = 0;
        for (int c = 0; c < 8; c++) {
            double p[3] = {c & 1 ? bhi[0] : blo[0], c & 2 ? bhi[1] : blo[1], c & 4 ? bhi[2] : blo[2]}, sx, sy, z;
            CHECK(camera_project(&cam, W, H, p, &sx, &sy, &z) == 0, "in front");
            worst = fmax(worst, fmax(fabs(2 * sx / W - 1), fabs(2 * sy / H - 1)));
        }
        double th = W < H ? atan(tan(20 * PI / 180) * W / H) : 20 * PI / 180;
        CHECK(worst <= tan(asin(sin(th) / 1.05)) / tan(th) + 1e-12, "corners within the margin: %g", worst);
    }
    double pt[3] = {5, 5, 5};
    CHECK(camera_frame_box(&cam, pt, pt, 10, 10, 0, 0, 40) == 0 && fabs(cam.eye[2] - 5 - 1.05 / sin(20 * PI / 180)) < 1e-9,
          "a point is framed as a unit sphere");
    double bad[3] = {0, NAN, 0};
    CHECK(camera_frame_box(&cam, bad, pt, 10, 10, 0, 0, 40) == -1, "non-finite box refused");

    /* camera_frame_sphere: the box's framing is that of its bounding sphere
     * (the same camera, bit for bit); a sphere's outline, where the ray from
     * the eye grazes it, reaches tan(asin(sin θ / 1.05)) / tan θ of the
     * half-height exactly (0.947 at θ = 20°) */
    camera cs;
    double ctr[3], rr = 0;
    for (int i = 0; i < 3; i++) {
        ctr[i] = 0.5 * (blo[i] + bhi[i]);
        rr += 0.25 * (bhi[i] - blo[i]) * (bhi[i] - blo[i]);
    }
    rr = sqrt(rr); /* 2.5144, half the diagonal */
    CHECK(camera_frame_box(&cam, blo, bhi, 64, 48, 30, 20, 40) == 0 &&
              camera_frame_sphere(&cs, ctr, rr, 64, 48, 30, 20, 40) == 0 && memcmp(&cam, &cs, sizeof cam) == 0,
          "frame_box = frame_sphere of its bounding sphere");
    double sc[3] = {0.3, -1, 2}, sr = 0.6;
    CHECK(camera_frame_sphere(&cs, sc, sr, 80, 60, 30, 20, 40) == 0, "frame a sphere");
    double d = 0;
    for (int i = 0; i < 3; i++)
        d += (cs.eye[i] - sc[i]) * (cs.eye[i] - sc[i]);
    d = sqrt(d);
    CHECK_NEAR(d, 1.05 * sr / sin(20 * PI / 180), 1e-12, "distance 1.05 r / sin 20°");
    /* the topmost grazing point: from the centre along upv by r·cos(a), back
     * toward the eye by r·sin(a), where sin(a) = r / d */
    double sa = sr / d, ca = sqrt(1 - sa * sa), top[3], sx, sy, z;
    for (int i = 0; i < 3; i++)
        top[i] = sc[i] + sr * ca * cs.upv[i] - sr * sa * cs.fwd[i];
    CHECK(camera_project(&cs, 80, 60, top, &sx, &sy, &z) == 0, "in front");
    CHECK_NEAR(1 - 2 * sy / 60, tan(asin(sin(20 * PI / 180) / 1.05)) / tan(20 * PI / 180), 1e-12, "outline at 0.947");
    CHECK(camera_frame_sphere(&cs, sc, INFINITY, 80, 60, 30, 20, 40) == -1 &&
              camera_frame_sphere(&cs, bad, 1, 80, 60, 30, 20, 40) == -1,
          "non-finite centre or radius refused");
    CHECK(camera_frame_sphere(&cs, pt, 0, 10, 10, 0, 0, 40) == 0 && fabs(cs.eye[2] - 5 - 1.05 / sin(20 * PI / 180)) < 1e-9,
          "radius 0 is framed as a unit sphere");
    mesh_free(&cube);
    return check_done("test_fset3d");
}
