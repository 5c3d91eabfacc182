/* test_mesh_io.c — mesh files against hand-written references.
 *
 * tests/data/formats/ holds a tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1)
 * with faces (0,2,1) (0,1,3) (0,3,2) (1,2,3) (counter-clockwise from
 * outside), written by hand: tet.ply (binary, RGBA colours red, green,
 * blue with alpha 128, white), tet_ascii.ply (normals and colours),
 * tet.obj (normals) and tet.stl (facet normals -z, -y, -x and (1,1,1)/√3 as
 * 0x3f13cd3a). Writers must produce exactly these bytes, readers must read
 * them; meshes round-trip through files (bit-exact positions); a point cloud
 * has no face element; malformed files give precise errors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "rt_alloc.h"
#include "mesh_io.h"

#define DATA "tests/data/formats/"

static const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
static const float N[4][3] = {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
static const float C[4][4] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 128.0f / 255}, {1, 1, 1, 1}};
static const uint32_t T[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

static void tet(mesh *m, int normals, int colours)
{
    mesh_init(m, normals, colours);
    for (int i = 0; i < 4; i++)
        mesh_add_vertex(m, P[i], normals ? N[i] : NULL, colours ? C[i] : NULL);
    for (int i = 0; i < 4; i++)
        mesh_add_tri(m, T[i][0], T[i][1], T[i][2]);
}

static int same_as_file(const bytebuf *b, const char *path)
{
    unsigned char *d;
    size_t n;
    rt_error e;
    if (fileio_read_all(path, 1 << 20, &d, &n, &e) != RT_OK)
        return 0;
    int ok = n == b->len && memcmp(d, b->data, n) == 0;
    if (!ok)
        fprintf(stderr, "%s: %zu bytes, writer gave %zu\n", path, n, b->len);
    rt_free(d);
    return ok;
}

static void test_writers(void)
{
    mesh m;
    rt_error e;
    bytebuf b;
    tet(&m, 0, 1);
    bytebuf_init(&b);
    CHECK(mio_ply_to_mem(&m, 0, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "tet.ply"), "binary PLY differs");
    bytebuf_free(&b);
    bytebuf_init(&b);
    CHECK(mio_stl_to_mem(&m, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "tet.stl"), "STL differs");
    bytebuf_free(&b);
    mesh_free(&m);
    tet(&m, 1, 1);
    bytebuf_init(&b);
    CHECK(mio_ply_to_mem(&m, 1, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "tet_ascii.ply"), "ASCII PLY differs");
    bytebuf_free(&b);
    mesh_free(&m);
    tet(&m, 1, 0);
    bytebuf_init(&b);
    CHECK(mio_obj_to_mem(&m, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "tet.obj"), "OBJ differs");
    bytebuf_free(&b);
    mesh_free(&m);
}

/* Same triangles corner by corner, by position (STL renumbers vertices in
 * order of first use). */
static int same_corners(const mesh *a, const mesh *b)
{
    if (a->nt != b->nt)
        return 0;
    for (size_t t = 0; t < 3 * a->nt; t++)
        if (memcmp(a->pos + 3 * (size_t)a->tri[t], b->pos + 3 * (size_t)b->tri[t], 12) != 0)
            return 0;
    return 1;
}

static void check_tet(const mesh *m, int normals, int colours, const char *what)
{
    CHECK(m->nv == 4 && m->nt == 4, "%s: %zu vertices %zu triangles", what, m->nv, m->nt);
    if (m->nv != 4 || m->nt != 4)
        return;
    mesh ref;
    tet(&ref, 0, 0);
    CHECK(same_corners(m, &ref), "%s: triangle corners differ", what);
    mesh_free(&ref);
    if (strstr(what, "stl") == NULL) {
        CHECK(memcmp(m->pos, P, sizeof P) == 0, "%s: positions", what);
        CHECK(memcmp(m->tri, T, sizeof T) == 0, "%s: triangles", what);
    }
    CHECK((m->nrm != NULL) == normals, "%s: normals present %d", what, m->nrm != NULL);
    if (normals && m->nrm)
        CHECK(memcmp(m->nrm, N, sizeof N) == 0, "%s: normals", what);
    CHECK((m->col != NULL) == colours, "%s: colours present", what);
    if (colours && m->col)
        for (int i = 0; i < 16; i++)
            CHECK_NEAR(m->col[i], C[i / 4][i % 4], 1e-7, what);
    mesh_stats st;
    rt_error e;
    mesh_compute_stats(m, &st, &e);
    CHECK(st.boundary_edges == 0 && st.euler == 2, "%s: not a closed tetrahedron", what);
}

static void test_readers(void)
{
    mesh m;
    rt_error e;
    CHECK(mio_load(DATA "tet.ply", &m, &e) == RT_OK, "%s", e.msg);
    check_tet(&m, 0, 1, "tet.ply");
    mesh_free(&m);
    CHECK(mio_load(DATA "tet_ascii.ply", &m, &e) == RT_OK, "%s", e.msg);
    check_tet(&m, 1, 1, "tet_ascii.ply");
    mesh_free(&m);
    CHECK(mio_load(DATA "tet.obj", &m, &e) == RT_OK, "%s", e.msg);
    check_tet(&m, 1, 0, "tet.obj");
    mesh_free(&m);
    CHECK(mio_load(DATA "tet.stl", &m, &e) == RT_OK, "%s", e.msg);
    check_tet(&m, 0, 0, "tet.stl"); /* welding recovers the 4 shared vertices */
    mesh_free(&m);
}

/* A closed octahedron with awkward coordinates. */
static void octa(mesh *m, int normals, int colours)
{
    mesh_init(m, normals, colours);
    static const int ax[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int i = 0; i < 6; i++) {
        float p[3], c[4] = {0.1f * i, 0.3f, 1.0f / 3.0f, 0.5f};
        for (int a = 0; a < 3; a++)
            p[a] = (float)(ax[i][a] * (0.7 + 0.01 * i) + 1e-3 * a / 3.0);
        float n[3] = {(float)ax[i][0], (float)ax[i][1], (float)ax[i][2]};
        mesh_add_vertex(m, p, n, c);
    }
    static const uint32_t f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                     {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    for (int t = 0; t < 8; t++)
        mesh_add_tri(m, f[t][0], f[t][1], f[t][2]);
}

static void test_roundtrip(void)
{
    char dir[] = "/tmp/frac_meshio_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    static const char *names[4] = {"a.ply", "b.ply", "c.obj", "d.stl"};
    mesh m, r;
    rt_error e;
    octa(&m, 1, 1);
    for (int k = 0; k < 4; k++) {
        char path[128];
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        rt_code rc = k == 1 ? mio_save_ply(path, &m, 1, &e) : mio_save(path, &m, &e);
        CHECK(rc == RT_OK, "%s: %s", names[k], e.msg);
        CHECK(mio_load(path, &r, &e) == RT_OK, "%s: %s", names[k], e.msg);
        CHECK(r.nv == 6 && r.nt == 8, "%s: %zu / %zu", names[k], r.nv, r.nt);
        if (r.nv == 6 && r.nt == 8) {
            CHECK(same_corners(&r, &m), "%s: triangle corners not exact", names[k]);
            if (k < 3) {
                CHECK(memcmp(r.pos, m.pos, 6 * 12) == 0, "%s: positions not exact", names[k]);
                CHECK(memcmp(r.tri, m.tri, 8 * 12) == 0, "%s: triangles differ", names[k]);
            }
            if (k < 3)
                CHECK(r.nrm && memcmp(r.nrm, m.nrm, 6 * 12) == 0, "%s: normals differ", names[k]);
            if (k < 2 && r.col)
                for (int i = 0; i < 24; i++)
                    CHECK(fabs(r.col[i] - m.col[i]) <= 0.5 / 255 + 1e-7, "%s: colour %d", names[k], i);
            if (k == 2 && r.col) /* OBJ carries rgb exactly (9 digits), alpha 1 */
                CHECK(r.col[4] == m.col[4] && r.col[6] == m.col[6] && r.col[7] == 1, "obj colours");
        }
        mesh_free(&r);
        remove(path);
    }
    mesh_free(&m);

    /* Point cloud: no face element at all. */
    char path[128];
    snprintf(path, sizeof path, "%s/cloud.ply", dir);
    mesh_init(&m, 0, 0);
    float p[3] = {0.25f, -1.5f, 3};
    mesh_add_vertex(&m, p, NULL, NULL);
    mesh_add_vertex(&m, P[1], NULL, NULL);
    bytebuf b;
    bytebuf_init(&b);
    CHECK(mio_ply_to_mem(&m, 0, &b, &e) == RT_OK, "%s", e.msg);
    bytebuf_byte(&b, 0);
    CHECK(strstr((const char *)b.data, "element face") == NULL, "point cloud has a face element");
    bytebuf_free(&b);
    CHECK(mio_save(path, &m, &e) == RT_OK, "%s", e.msg);
    CHECK(mio_load(path, &r, &e) == RT_OK, "%s", e.msg);
    CHECK(r.nv == 2 && r.nt == 0 && r.pos[1] == -1.5f, "point cloud read back");
    mesh_free(&r);
    mesh_free(&m);
    remove(path);
    rmdir(dir);
}

static void test_errors(void)
{
    mesh m;
    rt_error e;
    const char *bad1 = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0\n3 0 1 2\n";
    CHECK(mio_ply_from_mem((const unsigned char *)bad1, strlen(bad1), &m, &e) == RT_EFORMAT, "index");
    CHECK(strcmp(e.msg, "PLY face 0 has a vertex index out of 0..0") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    const char *bad2 = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n0\n";
    CHECK(mio_ply_from_mem((const unsigned char *)bad2, strlen(bad2), &m, &e) == RT_EFORMAT, "trunc");
    CHECK(strcmp(e.msg, "PLY data for element 'vertex' is truncated or malformed") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    const char *bad3 = "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n";
    CHECK(mio_ply_from_mem((const unsigned char *)bad3, strlen(bad3), &m, &e) == RT_EFORMAT, "type");
    CHECK(strcmp(e.msg, "PLY header line 4: unknown type 'quad'") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    /* fuzz finding F9 (ply timeout): a vertex element whose property lines
     * were lost declared 1,844,674,407 rows; each read nothing */
    const char *bad6 = "ply\nformat ascii 1.0\nelement vertex 1844674407\nend_header\n0 0 0\n";
    CHECK(mio_ply_from_mem((const unsigned char *)bad6, strlen(bad6), &m, &e) == RT_EFORMAT, "no props");
    CHECK(strcmp(e.msg, "PLY element 'vertex' has 1844674407 rows but no properties") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    /* 1000 rows of 3 properties need at least 3000 bytes; 6 are there */
    const char *bad7 = "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
                       "property float z\nend_header\n0 0 0\n";
    CHECK(mio_ply_from_mem((const unsigned char *)bad7, strlen(bad7), &m, &e) == RT_EFORMAT, "rows");
    CHECK(strcmp(e.msg, "PLY header declares at least 3000 bytes of data, the file holds 6") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    const char *bad4 = "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
    CHECK(mio_obj_from_mem((const unsigned char *)bad4, strlen(bad4), &m, &e) == RT_EFORMAT, "obj");
    CHECK(strcmp(e.msg, "OBJ line 3: face index out of 1..2") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    const char *bad5 = "solid x\nfacet normal 0 0 1\n";
    CHECK(mio_stl_from_mem((const unsigned char *)bad5, strlen(bad5), &m, &e) == RT_EFORMAT, "stl");
    CHECK(strcmp(e.msg, "ASCII STL is not read (only binary STL)") == 0, "msg: %s", e.msg);
    mesh_free(&m);
    CHECK(mio_save("/tmp/x.off", &m, &e) == RT_EINVAL, "ext");
    CHECK(strcmp(e.msg, "mesh file '/tmp/x.off' does not end in .ply, .obj or .stl") == 0, "msg: %s", e.msg);
}

/* Declared element counts are checked against the memory left before any
 * is read. */
static void test_declared_size(void)
{
    mesh m;
    rt_error e = {0};
    const char *ply = "ply\nformat ascii 1.0\nelement vertex 100000000\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
    size_t nt = 100000, n = 84 + 50 * nt;
    unsigned char *stl = rt_calloc(n, 1);
    check_limits(-1, -1, 1 << 20);
    rt_code c = mio_ply_from_mem((const unsigned char *)ply, strlen(ply), &m, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "reading the PLY vertices and faces needs 1144 MiB, more than the 1 MiB "
                                          "left under the memory limit (raise it with --max-memory MiB)") == 0,
          "%d %s", c, e.msg);
    mesh_free(&m);
    stl[80] = (unsigned char)(nt & 255), stl[81] = (unsigned char)(nt >> 8 & 255), stl[82] = (unsigned char)(nt >> 16);
    c = mio_stl_from_mem(stl, n, &m, &e);
    CHECK(c == RT_ELIMIT && strstr(e.msg, "reading the STL triangles needs ") &&
          strstr(e.msg, "more than the 1 MiB left under the memory limit"), "%d %s", c, e.msg);
    CHECK(check_hs.peak < 4096, "largest block before the refusals: %zu", check_hs.peak);
    mesh_free(&m);
    check_limits_off();
    rt_free(stl);
}

/* Found by the fuzzer: an OBJ error in the first pass (a vertex or normal
 * with too few numbers) returned before *m was initialised, so the
 * documented mesh_free afterwards freed garbage pointers. */
static void test_obj_early_error_initialises(void)
{
    static const char *bad[] = {"v 0 0\n", "vn 0 1\nv 0 0 0\n"};
    static const char *msg[] = {"OBJ line 1: vertex needs 3 coordinates",
                                "OBJ line 1: normal needs 3 components"};
    for (int i = 0; i < 2; i++) {
        mesh m;
        memset(&m, 0x5a, sizeof m); /* what an uninitialised local may hold */
        rt_error e;
        rt_code c = mio_obj_from_mem((const unsigned char *)bad[i], strlen(bad[i]), &m, &e);
        CHECK(c == RT_EFORMAT && strcmp(e.msg, msg[i]) == 0, "OBJ '%s': code %d, '%s'", bad[i], (int)c, e.msg);
        CHECK(m.pos == NULL && m.tri == NULL && m.nv == 0, "OBJ '%s': mesh not initialised", bad[i]);
        mesh_free(&m);
    }
}

/* unit cubes wound outward at the given corners (lower corners) */
static void cubes(mesh *m, const float (*at)[3], int n)
{
    static const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    mesh_init(m, 0, 0);
    for (int c = 0; c < n; c++) {
        uint32_t base = (uint32_t)m->nv;
        for (int i = 0; i < 8; i++) {
            float p[3] = {at[c][0] + (float)(i & 1), at[c][1] + (float)((i >> 1) & 1), at[c][2] + (float)((i >> 2) & 1)};
            mesh_add_vertex(m, p, NULL, NULL);
        }
        for (int f = 0; f < 6; f++) {
            mesh_add_tri(m, base + q[f][0], base + q[f][1], base + q[f][2]);
            mesh_add_tri(m, base + q[f][0], base + q[f][2], base + q[f][3]);
        }
    }
}

/* STL keeps no shared vertices; the reader welds equal positions and then
 * gives each edge-connected piece its own vertices again, so closed pieces
 * that touch (along an edge, a whole face, a corner) or even coincide come
 * back as the closed pieces they were: 8 vertices and Euler characteristic 2
 * each, no non-manifold edge, the same triangles in the same order. */
static void test_stl_pieces(void)
{
    static const float edge[2][3] = {{0, 0, 0}, {1, 1, 0}}, face[2][3] = {{0, 0, 0}, {1, 0, 0}},
                       corner[2][3] = {{0, 0, 0}, {1, 1, 1}}, twice[2][3] = {{0, 0, 0}, {0, 0, 0}},
                       four[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    const struct {
        const float (*at)[3];
        int n;
        const char *what;
        size_t welded; /* distinct positions */
    } cases[] = {{edge, 2, "along an edge", 14}, {face, 2, "face to face", 12}, {corner, 2, "at a corner", 15},
                 {twice, 2, "one cube given twice", 8}, {four, 4, "four in a square (a shared edge of 8 triangles)", 18}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        mesh m, r;
        rt_error e;
        bytebuf b;
        bytebuf_init(&b);
        cubes(&m, cases[k].at, cases[k].n);
        CHECK(mio_stl_to_mem(&m, &b, &e) == RT_OK, "%s: write", cases[k].what);
        CHECK(mio_stl_from_mem(b.data, b.len, &r, &e) == RT_OK, "%s: read: %s", cases[k].what, e.msg);
        mesh_stats st;
        CHECK(mesh_compute_stats(&r, &st, &e) == RT_OK, "stats");
        CHECK(r.nv == 8 * (size_t)cases[k].n && r.nt == m.nt, "%s: %zu vertices, %zu triangles", cases[k].what, r.nv,
              r.nt);
        CHECK(st.boundary_edges == 0 && st.nonmanifold_edges == 0 && st.euler == 2 * cases[k].n,
              "%s: %zu boundary, %zu non-manifold edges, Euler %ld", cases[k].what, st.boundary_edges,
              st.nonmanifold_edges, st.euler);
        CHECK_NEAR(st.volume, cases[k].n, 1e-9, cases[k].what);
        int same = 1;
        for (size_t t = 0; t < m.nt && t < r.nt; t++)
            for (int c = 0; c < 3; c++)
                same &= memcmp(m.pos + 3 * m.tri[3 * t + c], r.pos + 3 * r.tri[3 * t + c], 12) == 0;
        CHECK(same, "%s: the same triangles in the same order", cases[k].what);
        /* the distinct positions: what a reader that only welds would give */
        size_t distinct = 0;
        for (size_t i = 0; i < r.nv; i++) {
            size_t j = 0;
            while (j < i && memcmp(r.pos + 3 * j, r.pos + 3 * i, 12) != 0)
                j++;
            distinct += j == i;
        }
        CHECK(distinct == cases[k].welded, "%s: %zu distinct positions", cases[k].what, distinct);
        /* each piece a block of 12 triangles on its own 8 vertices */
        int apart = 1;
        for (size_t t = 0; t < r.nt; t++)
            for (int c = 0; c < 3; c++)
                apart &= r.tri[3 * t + c] / 8 == t / 12;
        CHECK(apart, "%s: each cube on its own vertices", cases[k].what);
        mesh_free(&m);
        mesh_free(&r);
        bytebuf_free(&b);
    }
    /* one piece: the welded mesh unchanged (vertices in order of first use) */
    mesh m, r;
    rt_error e;
    bytebuf b;
    bytebuf_init(&b);
    tet(&m, 0, 0);
    CHECK(mio_stl_to_mem(&m, &b, &e) == RT_OK && mio_stl_from_mem(b.data, b.len, &r, &e) == RT_OK, "tet");
    CHECK(r.nv == 4 && r.nt == 4, "tet: %zu %zu", r.nv, r.nt);
    static const uint32_t want[12] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 2, 1, 3};
    CHECK(memcmp(r.tri, want, sizeof want) == 0, "tet: indices in order of first use");
    mesh_free(&m);
    mesh_free(&r);
    bytebuf_free(&b);
}

int main(void)
{
    test_obj_early_error_initialises();
    test_writers();
    test_readers();
    test_roundtrip();
    test_errors();
    test_declared_size();
    test_stl_pieces();
    return check_done("test_mesh_io");
}
