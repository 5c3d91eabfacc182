/* test_mesh.c — mesh statistics on hand-built meshes.
 *
 * A unit cube of 12 triangles wound counter-clockwise from outside: area 6,
 * closed (no boundary edge), Euler characteristic 2 and signed volume 1; the
 * same cube with every triangle flipped has volume -1, and moving the cube
 * away from the origin does not change its volume (the sum a·(b×c)/6 is
 * independent of the origin for a closed mesh). */
#include <math.h>
#include <string.h>

#include "check.h"
#include "mesh.h"

/* corners: bit 0 x, bit 1 y, bit 2 z */
static const uint32_t FACES[6][4] = {
    {0, 2, 3, 1}, /* z = 0, seen from -z */
    {4, 5, 7, 6}, /* z = 1 */
    {0, 1, 5, 4}, /* y = 0 */
    {2, 6, 7, 3}, /* y = 1 */
    {0, 4, 6, 2}, /* x = 0 */
    {1, 3, 7, 5}, /* x = 1 */
};

static void cube(mesh *m, const double off[3], int flip)
{
    mesh_init(m, 0, 0);
    for (int i = 0; i < 8; i++) {
        float p[3] = {(float)((i & 1) + off[0]), (float)(((i >> 1) & 1) + off[1]), (float)(((i >> 2) & 1) + off[2])};
        mesh_add_vertex(m, p, NULL, NULL);
    }
    for (int f = 0; f < 6; f++) {
        const uint32_t *q = FACES[f];
        if (flip) {
            mesh_add_tri(m, q[0], q[2], q[1]);
            mesh_add_tri(m, q[0], q[3], q[2]);
        } else {
            mesh_add_tri(m, q[0], q[1], q[2]);
            mesh_add_tri(m, q[0], q[2], q[3]);
        }
    }
}

static void check_cube(const double off[3], int flip, double want, const char *what)
{
    mesh m;
    mesh_stats st;
    rt_error e;
    cube(&m, off, flip);
    CHECK(mesh_compute_stats(&m, &st, &e) == RT_OK, "%s: %s", what, e.msg);
    CHECK(st.triangles == 12 && st.boundary_edges == 0 && st.nonmanifold_edges == 0 && st.euler == 2,
          "%s: not a closed cube", what);
    CHECK_NEAR(st.area, 6, 1e-12, what);
    CHECK_NEAR(st.volume, want, 1e-9, what);
    mesh_free(&m);
}

int main(void)
{
    const double zero[3] = {0, 0, 0}, away[3] = {3, -2, 5};
    check_cube(zero, 0, 1, "unit cube");
    check_cube(zero, 1, -1, "flipped unit cube");
    check_cube(away, 0, 1, "moved cube");
    check_cube(away, 1, -1, "moved flipped cube");
    /* an open mesh (one triangle) has a volume too: the cone to the origin */
    mesh m;
    mesh_stats st;
    rt_error e;
    mesh_init(&m, 0, 0);
    const float a[3] = {1, 0, 0}, b[3] = {0, 1, 0}, c[3] = {0, 0, 1};
    mesh_add_vertex(&m, a, NULL, NULL);
    mesh_add_vertex(&m, b, NULL, NULL);
    mesh_add_vertex(&m, c, NULL, NULL);
    mesh_add_tri(&m, 0, 1, 2);
    CHECK(mesh_compute_stats(&m, &st, &e) == RT_OK, "%s", e.msg);
    CHECK_NEAR(st.volume, 1.0 / 6, 1e-12, "one triangle");
    mesh_free(&m);
    /* mesh_append: two cubes side by side are one closed mesh of 16
     * vertices, 24 triangles, Euler characteristic 4 (two spheres) and volume
     * 2; the second cube's triangles index vertices 8..15. The cubes have no
     * normals or colours, so the merged mesh (which has both) gets (0, 1, 0)
     * and the fallback colour, while a coloured source keeps its own. */
    mesh one, two, all;
    cube(&one, zero, 0);
    cube(&two, (double[]){1.5, 0, 0}, 0);
    mesh_init(&all, 1, 1);
    const float grey[4] = {0.5f, 0.5f, 0.5f, 1};
    mesh_append(&all, &one, grey);
    mesh_append(&all, &two, grey);
    CHECK(!all.failed && all.nv == 16 && all.nt == 24, "appended: %zu vertices, %zu triangles", all.nv, all.nt);
    CHECK(all.tri[3 * 12] == 8 + FACES[0][0] && all.tri[3 * 12 + 1] == 8 + FACES[0][1] &&
              all.tri[3 * 12 + 2] == 8 + FACES[0][2],
          "second cube re-indexed");
    CHECK(all.pos[3 * 9] == 2.5f && all.nrm[3 * 9 + 1] == 1 && all.nrm[3 * 9] == 0 && all.col[4 * 9] == 0.5f,
          "vertex 9 = (2.5, 0, 0), normal up, fallback colour");
    CHECK(mesh_compute_stats(&all, &st, &e) == RT_OK && st.euler == 4 && st.boundary_edges == 0, "two closed cubes");
    CHECK_NEAR(st.volume, 2, 1e-9, "two cubes' volume");
    /* The box of the two cubes is [0, 2.5] × [0, 1] × [0, 1]; a box that
     * already holds more (down to z = -3) keeps it. */
    double blo[3] = {INFINITY, INFINITY, INFINITY}, bhi[3] = {-INFINITY, -INFINITY, -INFINITY};
    mesh_grow_box(&all, blo, bhi);
    CHECK(blo[0] == 0 && blo[1] == 0 && blo[2] == 0 && bhi[0] == 2.5 && bhi[1] == 1 && bhi[2] == 1,
          "box [%g, %g] × [%g, %g] × [%g, %g]", blo[0], bhi[0], blo[1], bhi[1], blo[2], bhi[2]);
    blo[2] = -3;
    mesh_grow_box(&one, blo, bhi);
    CHECK(blo[2] == -3 && bhi[0] == 2.5, "a box only grows");
    mesh tri;
    mesh_init(&tri, 0, 1);
    const float red[4] = {1, 0, 0, 1};
    mesh_add_vertex(&tri, a, NULL, red);
    mesh_append(&all, &tri, grey);
    CHECK(all.nv == 17 && all.col[4 * 16] == 1 && all.col[4 * 16 + 1] == 0, "own colour kept");
    mesh_free(&tri);
    mesh_free(&one);
    mesh_free(&two);
    mesh_free(&all);
    return check_done("test_mesh");
}
