/* test_isosurf_mc.c — the marching-cubes extractor against facts computed
 * here, independently of runtime/isosurf.c:
 *   - every mesh is a closed, consistently oriented 2-manifold: each
 *     directed edge (a, b) occurs once and its reverse (b, a) once (so every
 *     edge is in exactly two triangles, wound oppositely), no triangle
 *     repeats a vertex, every vertex is used;
 *   - welded: no two vertices have the same position;
 *   - Euler characteristic V - E + F: sphere 2, torus 0, two touching spheres
 *     (one surface through the contact) 2; each of the 256 single-cube cases
 *     2 per connected component (inside one cube every piece is a ball);
 *   - signed volume of a sphere of radius r within 1% of 4/3 pi r^3 at 40^3;
 *   - triangle count <= 1.2x plain marching cubes, counted here per cell from
 *     the inside-corner mask: the side with at most 4 inside corners (the
 *     mask itself at 4) splits into edge-connected components; a component
 *     of k corners with i cube edges between them meets 3k - 2i cut edges,
 *     a polygon of 3k - 2i - 2 triangles. This reproduces the standard
 *     15-class counts (classes 1..14: 1 2 2 2 3 3 3 2 4 4 4 4 4 4), checked
 *     below on one mask per class;
 *   - random 3x3x3 and 4x3x3 grids (ambiguous faces shared by two cells,
 *     decided both ways) stay closed and oriented with positive volume;
 *   - the noisy blob is byte-identical on 1, 2 and 3 threads.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isosurf.h"
#include "noise.h"

static const double PI = 3.14159265358979323846;

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static int cmp_pos(const void *a, const void *b)
{
    const float *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x[k] != y[k])
            return x[k] < y[k] ? -1 : 1;
    return 0;
}

typedef struct topo {
    long euler;
    size_t components;
    int ok; /* closed, oriented, welded, no repeated or unused vertex */
} topo;

static size_t uf_find(size_t *p, size_t i)
{
    while (p[i] != i)
        i = p[i] = p[p[i]];
    return i;
}

/* Topology of m from its index lists alone (and positions for welding). */
static topo mesh_topo(const mesh *m, const char *what)
{
    topo t = {0, 0, 1};
    size_t nt = m->nt, nv = m->nv;
    uint64_t *de = malloc((3 * nt + 1) * sizeof *de);
    size_t *par = malloc((nv + 1) * sizeof *par);
    unsigned char *used = calloc(nv + 1, 1);
    if (!de || !par || !used) {
        CHECK(0, "%s: out of memory in the test", what);
        t.ok = 0;
        goto out;
    }
    for (size_t i = 0; i < nv; i++)
        par[i] = i;
    size_t bad_tri = 0;
    for (size_t k = 0; k < nt; k++) {
        const uint32_t *v = m->tri + 3 * k;
        bad_tri += v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || v[0] >= nv || v[1] >= nv || v[2] >= nv;
        for (int r = 0; r < 3; r++) {
            uint32_t a = v[r], b = v[(r + 1) % 3];
            de[3 * k + r] = (uint64_t)a << 32 | b;
            if (a < nv && b < nv) {
                used[a] = 1;
                size_t ra = uf_find(par, a), rb = uf_find(par, b);
                if (ra != rb)
                    par[ra] = rb;
            }
        }
    }
    CHECK(bad_tri == 0, "%s: %zu triangles repeat or misindex a vertex", what, bad_tri);
    qsort(de, 3 * nt, sizeof *de, cmp_u64);
    size_t dup = 0, unpaired = 0;
    for (size_t i = 0; i < 3 * nt; i++) {
        if (i + 1 < 3 * nt && de[i] == de[i + 1])
            dup++;
        uint64_t rev = (de[i] & 0xffffffffu) << 32 | de[i] >> 32;
        if (!bsearch(&rev, de, 3 * nt, sizeof *de, cmp_u64))
            unpaired++;
    }
    CHECK(dup == 0, "%s: %zu directed edges used twice (inconsistent orientation or non-manifold)", what, dup);
    CHECK(unpaired == 0, "%s: %zu directed edges without their reverse (holes)", what, unpaired);
    size_t unused = 0;
    for (size_t i = 0; i < nv; i++) {
        unused += !used[i];
        if (used[i] && uf_find(par, i) == i)
            t.components++;
    }
    CHECK(unused == 0, "%s: %zu unused vertices", what, unused);
    /* welded: positions are distinct (sorted, neighbours compared) */
    size_t same = 0;
    float(*ps)[3] = malloc((nv + 1) * sizeof *ps);
    if (ps) {
        memcpy(ps, m->pos, nv * sizeof *ps);
        qsort(ps, nv, sizeof *ps, cmp_pos);
        for (size_t i = 0; i + 1 < nv; i++)
            same += memcmp(ps[i], ps[i + 1], sizeof ps[i]) == 0;
        free(ps);
    }
    CHECK(same == 0, "%s: %zu duplicate vertex positions (not welded)", what, same);
    /* E = 3F/2 for a closed mesh */
    t.euler = (long)nv - (long)(3 * nt / 2) + (long)nt;
    t.ok = bad_tri == 0 && dup == 0 && unpaired == 0 && unused == 0 && same == 0;
out:
    free(de);
    free(par);
    free(used);
    return t;
}

/* Plain marching cubes' triangle count for one cell (see the top). */
static int plain_mc(int mask)
{
    int n = 0;
    for (int c = 0; c < 8; c++)
        n += mask >> c & 1;
    if (n > 4)
        mask = ~mask & 255;
    int seen = 0, tris = 0;
    for (int c0 = 0; c0 < 8; c0++) {
        if (!(mask >> c0 & 1) || (seen >> c0 & 1))
            continue;
        int comp = 1 << c0, grown = 1;
        while (grown) {
            grown = 0;
            for (int c = 0; c < 8; c++)
                if (comp >> c & 1)
                    for (int a = 1; a < 8; a <<= 1)
                        if ((mask >> (c ^ a) & 1) && !(comp >> (c ^ a) & 1))
                            comp |= 1 << (c ^ a), grown = 1;
        }
        seen |= comp;
        int k = 0, i = 0;
        for (int c = 0; c < 8; c++)
            if (comp >> c & 1) {
                k++;
                for (int a = 1; a < 8; a <<= 1)
                    i += (comp >> (c ^ a) & 1) && c < (c ^ a);
            }
        tris += 3 * k - 2 * i - 2;
    }
    return tris;
}

/* Plain marching cubes' count over the grid and its padding (cells -1 ..
 * n-1, padding samples outside), as the extractor sees the lattice. */
static size_t plain_mc_count(const volume *v, double level)
{
    size_t t = 0;
    for (int z = -1; z < v->nz; z++)
        for (int y = -1; y < v->ny; y++)
            for (int x = -1; x < v->nx; x++) {
                int mask = 0;
                for (int c = 0; c < 8; c++) {
                    int p = x + (c & 1), q = y + (c >> 1 & 1), r = z + (c >> 2 & 1);
                    if (p >= 0 && q >= 0 && r >= 0 && p < v->nx && q < v->ny && r < v->nz &&
                        *volume_at(v, p, q, r) >= level)
                        mask |= 1 << c;
                }
                t += (size_t)plain_mc(mask);
            }
    return t;
}

static void test_plain_counts(void)
{
    /* one mask per class 1..14 (corners x = 1, y = 2, z = 4) */
    static const int rep[14] = {0x01, 0x03, 0x09, 0x81, 0x07, 0x83, 0x16,
                                0x0f, 0x17, 0xc3, 0x47, 0x87, 0x69, 0x27};
    static const int want[14] = {1, 2, 2, 2, 3, 3, 3, 2, 4, 4, 4, 4, 4, 4};
    for (int k = 0; k < 14; k++) {
        CHECK(plain_mc(rep[k]) == want[k], "class %d: %d triangles, expected %d", k + 1, plain_mc(rep[k]),
              want[k]);
        CHECK(plain_mc(~rep[k] & 255) == want[k], "class %d complement", k + 1);
    }
    CHECK(plain_mc(0) == 0 && plain_mc(255) == 0, "empty and full cells");
}

static double signed_volume(const mesh *m)
{
    double v = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const float *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                    *c = m->pos + 3 * m->tri[3 * t + 2];
        v += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) -
              a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
              a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return v;
}

static uint64_t lcg_state = 88172645463325252u;

static double rnd(void) /* uniform in [0, 1) */
{
    lcg_state = lcg_state * 6364136223846793005u + 1442695040888963407u;
    return (double)(lcg_state >> 11) / 9007199254740992.0;
}

/* Faces of the unit cube as corner quadruples in cyclic order (a diagonal
 * is (q[0], q[2]) and (q[1], q[3])). */
static const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};

static void test_single_cubes(void)
{
    double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    iso_opts o = {0};
    o.level = 0;
    size_t bad = 0, seen_conn = 0, seen_sep = 0;
    for (int mask = 0; mask < 256; mask++)
        for (int draw = 0; draw < 8; draw++) {
            volume v;
            rt_error e;
            mesh m;
            CHECK(volume_init(&v, 2, 2, 2, lo, hi, &e) == RT_OK, "vol");
            double val[8];
            for (int c = 0; c < 8; c++) {
                double mag = 0.05 + rnd();
                val[c] = (mask >> c & 1) ? mag : -mag;
                *volume_at(&v, c & 1, c >> 1 & 1, c >> 2 & 1) = (float)val[c];
                val[c] = (float)val[c];
            }
            /* predicted components: inside corners joined by cube edges and
             * by faces whose bilinear saddle is inside (asymptotic decider) */
            int comp[8];
            for (int c = 0; c < 8; c++)
                comp[c] = c;
            int changed = 1;
            while (changed) {
                changed = 0;
                for (int c = 0; c < 8; c++)
                    for (int d = 0; d < 8; d++) {
                        if (!(mask >> c & 1) || !(mask >> d & 1) || comp[c] == comp[d])
                            continue;
                        int x = c ^ d, join = x == 1 || x == 2 || x == 4;
                        for (int f = 0; f < 6 && !join; f++) {
                            const int *q = faces[f];
                            int ic = -1, id = -1;
                            for (int k = 0; k < 4; k++)
                                ic = q[k] == c ? k : ic, id = q[k] == d ? k : id;
                            if (ic < 0 || id < 0 || (ic ^ id) != 2)
                                continue;
                            int o1 = q[(ic + 1) & 3], o2 = q[(ic + 3) & 3];
                            if ((mask >> o1 & 1) || (mask >> o2 & 1))
                                continue; /* not ambiguous: joined by an edge anyway */
                            /* saddle of the bilinear interpolant: (v0 v2 - v1 v3) / (v0 + v2 - v1 - v3) */
                            double sd = (val[c] * val[d] - val[o1] * val[o2]) /
                                        (val[c] + val[d] - val[o1] - val[o2]);
                            join = sd >= 0;
                            if (join)
                                seen_conn++;
                            else
                                seen_sep++;
                        }
                        if (join) {
                            int from = comp[d], to = comp[c];
                            for (int k = 0; k < 8; k++)
                                if (comp[k] == from)
                                    comp[k] = to;
                            changed = 1;
                        }
                    }
            }
            size_t want_comp = 0;
            for (int c = 0; c < 8; c++)
                want_comp += (mask >> c & 1) && comp[c] == c;
            CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
            char what[64];
            snprintf(what, sizeof what, "case 0x%02x draw %d", mask, draw);
            topo t = mesh_topo(&m, what);
            double sv = signed_volume(&m);
            int fine = t.ok && t.components == want_comp && t.euler == 2 * (long)want_comp &&
                       (mask == 0 ? m.nt == 0 : sv > 0);
            if (!fine && bad < 10)
                CHECK(0, "%s: %zu components (want %zu), Euler %ld, volume %g", what, t.components, want_comp,
                      t.euler, sv);
            bad += !fine;
            mesh_free(&m);
            volume_free(&v);
        }
    CHECK(bad == 0, "%zu of 2048 single-cube meshes wrong", bad);
    CHECK(seen_conn > 100 && seen_sep > 100, "ambiguous faces decided connected %zu, separated %zu times",
          seen_conn, seen_sep);
}

/* Random signs and magnitudes on small grids: ambiguous faces shared by two
 * cells, decided both ways. */
static void test_random_grids(void)
{
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    iso_opts o = {0};
    size_t bad = 0;
    for (int trial = 0; trial < 600; trial++) {
        int nx = 3 + trial % 2, ny = 3, nz = 3 + trial % 3 / 2;
        volume v;
        rt_error e;
        mesh m;
        CHECK(volume_init(&v, nx, ny, nz, lo, hi, &e) == RT_OK, "vol");
        for (size_t i = 0; i < (size_t)nx * ny * nz; i++)
            v.v[i] = (float)((rnd() < 0.5 ? -1 : 1) * (0.05 + rnd()));
        CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
        char what[48];
        snprintf(what, sizeof what, "random grid %d", trial);
        topo t = mesh_topo(&m, what);
        double sv = signed_volume(&m);
        int fine = t.ok && t.euler % 2 == 0 && t.euler <= 2 * (long)t.components && (m.nt == 0 || sv > 0);
        if (!fine && bad < 10)
            CHECK(0, "%s: Euler %ld, %zu components, volume %g", what, t.euler, t.components, sv);
        bad += !fine;
        mesh_free(&m);
        volume_free(&v);
    }
    CHECK(bad == 0, "%zu of 600 random grids wrong", bad);
}

typedef struct shape {
    int kind; /* 0 sphere, 1 torus, 2 two touching spheres, 3 noisy blob */
    double r;
    noise_perm np;
} shape;

static void shape_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out)
{
    const shape *s = ctx;
    if (s->kind == 3) {
        double nz[RT_BLOCK], sx[RT_BLOCK] = {0}, sy[RT_BLOCK] = {0}, sz[RT_BLOCK] = {0};
        for (size_t i = 0; i < n; i++)
            sx[i] = 4 * x[i], sy[i] = 4 * y[i], sz[i] = 4 * z[i];
        noise_fbm3_block(&s->np, 4, 2, 0.5, n, sx, sy, sz, nz);
        for (size_t i = 0; i < n; i++) { /* seed 001 soft sphere times noise */
            double d2 = x[i] * x[i] + y[i] * y[i] + z[i] * z[i], r1 = 0.45, r0 = 0.9;
            double sph = d2 < r1 * r1 ? 1 : d2 > r0 * r0 ? 0 : (r0 * r0 - d2) / (r0 * r0 - r1 * r1);
            out[i] = sph * (0.6 + 0.8 * nz[i]);
        }
        return;
    }
    for (size_t i = 0; i < n; i++) {
        double X = x[i] - 0.013, Y = y[i] + 0.021, Z = z[i] - 0.007;
        if (s->kind == 0) {
            out[i] = s->r - sqrt(X * X + Y * Y + Z * Z);
        } else if (s->kind == 1) {
            double q = sqrt(X * X + Z * Z) - 0.55;
            out[i] = 0.25 - sqrt(q * q + Y * Y);
        } else { /* radius 0.4 at x = -0.4 and x = 0.4: they touch at the origin */
            double a = 0.4 - sqrt((x[i] + 0.4) * (x[i] + 0.4) + y[i] * y[i] + z[i] * z[i]);
            double b = 0.4 - sqrt((x[i] - 0.4) * (x[i] - 0.4) + y[i] * y[i] + z[i] * z[i]);
            out[i] = a > b ? a : b;
        }
    }
}

static void test_shapes(void)
{
    static const char *name[4] = {"sphere", "torus", "two touching spheres", "noisy blob"};
    static const long euler[4] = {2, 0, 2, 0};
    static const int grid[4] = {40, 48, 41, 64};
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    for (int k = 0; k < 4; k++) {
        shape s;
        memset(&s, 0, sizeof s);
        s.kind = k;
        s.r = 0.7;
        noise_perm_init(&s.np, 7);
        iso_opts o = {0};
        o.level = k == 3 ? 0.3 : 0;
        o.normals = 1;
        volume v;
        rt_error e;
        mesh m;
        CHECK(volume_init(&v, grid[k], grid[k], grid[k], lo, hi, &e) == RT_OK, "vol");
        CHECK(iso_sample_field(shape_fn, &s, &v, NULL, &e) == RT_OK, "sample");
        CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
        topo t = mesh_topo(&m, name[k]);
        CHECK(t.ok, "%s: not a closed welded 2-manifold", name[k]);
        if (k < 3) {
            CHECK(t.euler == euler[k], "%s: Euler %ld, expected %ld", name[k], t.euler, euler[k]);
            CHECK(t.components == 1, "%s: %zu components", name[k], t.components);
        } else {
            CHECK(t.euler % 2 == 0 && t.components > 0, "%s: Euler %ld", name[k], t.euler);
        }
        size_t plain = plain_mc_count(&v, o.level);
        CHECK(m.nt <= 1.2 * plain && m.nt > 0, "%s: %zu triangles, plain marching cubes %zu", name[k], m.nt,
              plain);
        printf("%s: %zu triangles = %.4f x plain marching cubes (%zu), Euler %ld, %zu components\n", name[k],
               m.nt, (double)m.nt / plain, plain, t.euler, t.components);
        double sv = signed_volume(&m);
        if (k == 0) {
            double want = 4.0 / 3.0 * PI * 0.343;
            CHECK(fabs(sv / want - 1) < 0.01, "sphere volume %g vs 4/3 pi r^3 = %g", sv, want);
        }
        CHECK(sv > 0, "%s: signed volume %g (inward)", name[k], sv);
        if (k == 3) { /* the blob has ambiguous cells, centre vertices among them: same bytes on 2 and 3 threads */
            size_t centres = 0; /* vertices with fewer than two coordinates on lattice lines */
            for (size_t i = 0; i < m.nv; i++) {
                int on = 0;
                for (int a = 0; a < 3; a++) {
                    double g = (m.pos[3 * i + a] + 1) * grid[k] / 2 - 0.5;
                    on += fabs(g - floor(g + 0.5)) < 1e-4;
                }
                centres += on < 2;
            }
            printf("noisy blob: %zu centre vertices\n", centres);
            CHECK(centres > 0, "the noisy blob was expected to need centre vertices");
            /* a centre vertex is the mean of its cycle, and its fan's
             * triangles are its only ones: each cycle vertex is in two of
             * them, so the mean of the other corners over the fan is that mean */
            double *nb = calloc(4 * m.nv, sizeof *nb);
            CHECK(nb != NULL, "memory");
            for (size_t ti = 0; nb && ti < m.nt; ti++)
                for (int c = 0; c < 3; c++) {
                    size_t v0 = m.tri[3 * ti + c];
                    for (int o2 = 1; o2 < 3; o2++) {
                        size_t w = m.tri[3 * ti + (c + o2) % 3];
                        for (int a = 0; a < 3; a++)
                            nb[4 * v0 + a] += m.pos[3 * w + a];
                        nb[4 * v0 + 3] += 1;
                    }
                }
            size_t off = 0;
            for (size_t i = 0; nb && i < m.nv; i++) {
                int on = 0;
                for (int a = 0; a < 3; a++) {
                    double g = (m.pos[3 * i + a] + 1) * grid[k] / 2 - 0.5;
                    on += fabs(g - floor(g + 0.5)) < 1e-4;
                }
                if (on >= 2)
                    continue;
                for (int a = 0; a < 3; a++)
                    off += !(fabs(nb[4 * i + a] / nb[4 * i + 3] - m.pos[3 * i + a]) < 1e-5);
            }
            CHECK(off == 0, "noisy blob: %zu centre vertex coordinates are not the mean of their cycle", off);
            free(nb);
            for (int th = 2; th <= 3; th++) {
                rt_run run = {th, NULL, 0};
                mesh m2;
                CHECK(iso_from_volume(&v, &o, &run, &m2, &e) == RT_OK, "%s", e.msg);
                int same = m2.nv == m.nv && m2.nt == m.nt && memcmp(m2.pos, m.pos, m.nv * 12) == 0 &&
                           memcmp(m2.nrm, m.nrm, m.nv * 12) == 0 && memcmp(m2.tri, m.tri, m.nt * 12) == 0;
                CHECK(same, "noisy blob on %d threads differs", th);
                mesh_free(&m2);
            }
        }
        mesh_free(&m);
        volume_free(&v);
    }
}

int main(void)
{
    test_plain_counts();
    test_single_cubes();
    test_random_grids();
    test_shapes();
    return check_done("test_isosurf_mc");
}
