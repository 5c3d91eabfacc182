/* test_isosurf_bits.c — the extractor's inside bits (64 nodes of an x-row
 * per word, node x at bit x + 1, see isosurf.c) against facts computed here
 * by a direct scan of the samples, on grid widths around the word size
 * (1, 2, 61 .. 67, 126 .. 130), where a cell's two corners fall in two words:
 *   - the vertices on lattice lines are exactly the crossing lattice edges of
 *     the padded lattice (nodes -1 .. n on each axis, the padding outside,
 *     NaN outside), counted here sample by sample; every other vertex is a
 *     centre vertex of an ambiguous cell;
 *   - the mesh is closed and consistently oriented: each directed edge
 *     (a, b) occurs once and (b, a) once;
 *   - the mesh is byte-identical on 1, 2 and 3 threads;
 *   - known answer: f = x - 62.3 in grid units (nodes 62 and 63 are bits 63
 *     and 64, the last of word 0 and the first of word 1): every vertex on
 *     an x-edge of the plane lies at node 62 + 0.3 cells, and the solid
 *     x >= 63 clipped by the box has the box's volume from the plane on,
 *     less the chamfers along its 8 outer edges (legs of half a cell).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "isosurf.h"

static uint64_t lcg = 0x2545F4914F6CDD1Du;

static double rnd(void) /* uniform in [0, 1) */
{
    lcg = lcg * 6364136223846793005u + 1442695040888963407u;
    return (double)(lcg >> 11) / 9007199254740992.0;
}

static int inside(const volume *v, int x, int y, int z, double level)
{
    if (x < 0 || y < 0 || z < 0 || x >= v->nx || y >= v->ny || z >= v->nz)
        return 0;
    return *volume_at(v, x, y, z) >= level; /* NaN: outside */
}

static size_t crossing_edges(const volume *v, double level)
{
    size_t n = 0;
    for (int z = -1; z <= v->nz; z++)
        for (int y = -1; y <= v->ny; y++)
            for (int x = -1; x <= v->nx; x++) {
                int a = inside(v, x, y, z, level);
                n += (size_t)(a != inside(v, x + 1, y, z, level));
                n += (size_t)(a != inside(v, x, y + 1, z, level));
                n += (size_t)(a != inside(v, x, y, z + 1, level));
            }
    return n;
}

/* Vertices with at least two coordinates on lattice lines (node centres). */
static size_t lattice_vertices(const mesh *m, const volume *v)
{
    int n[3] = {v->nx, v->ny, v->nz};
    size_t k = 0;
    for (size_t i = 0; i < m->nv; i++) {
        int on = 0;
        for (int a = 0; a < 3; a++) {
            double g = (m->pos[3 * i + a] - v->lo[a]) / (v->hi[a] - v->lo[a]) * n[a] - 0.5;
            on += fabs(g - floor(g + 0.5)) < 1e-4;
        }
        k += on >= 2;
    }
    return k;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Each directed edge once, and its reverse present. */
static int closed_oriented(const mesh *m)
{
    size_t ne = 3 * m->nt;
    uint64_t *e = malloc((ne ? ne : 1) * sizeof *e);
    if (!e)
        return 0;
    for (size_t t = 0; t < m->nt; t++)
        for (int r = 0; r < 3; r++)
            e[3 * t + r] = (uint64_t)m->tri[3 * t + r] << 32 | m->tri[3 * t + (r + 1) % 3];
    qsort(e, ne, sizeof *e, cmp_u64);
    int ok = 1;
    for (size_t i = 0; i < ne && ok; i++) {
        if (i && e[i] == e[i - 1])
            ok = 0;
        uint64_t rev = e[i] >> 32 | e[i] << 32;
        ok = ok && bsearch(&rev, e, ne, sizeof *e, cmp_u64) != NULL;
    }
    free(e);
    return ok;
}

static int same_mesh(const mesh *a, const mesh *b)
{
    return a->nv == b->nv && a->nt == b->nt && memcmp(a->pos, b->pos, a->nv * 12) == 0 &&
           memcmp(a->nrm, b->nrm, a->nv * 12) == 0 && memcmp(a->tri, b->tri, a->nt * 12) == 0;
}

static void test_widths(void)
{
    static const int widths[] = {1, 2, 61, 62, 63, 64, 65, 66, 67, 126, 127, 128, 129, 130};
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    for (size_t wi = 0; wi < sizeof widths / sizeof widths[0]; wi++)
        for (int kind = 0; kind < 3; kind++) {
            int nx = widths[wi], ny = 3 + kind, nz = 4;
            volume v;
            rt_error e;
            CHECK(volume_init(&v, nx, ny, nz, lo, hi, &e) == RT_OK, "vol");
            for (size_t i = 0; i < (size_t)nx * ny * nz; i++) {
                double u = rnd();
                if (kind == 0) /* random signs: many ambiguous cells */
                    v.v[i] = (float)(u - 0.5);
                else if (kind == 1) /* NaN, exact level, runs of inside */
                    v.v[i] = u < 0.1 ? NAN : u < 0.2 ? 0.0f : (float)((i / 7) % 3 == 0 ? u : -u);
                else /* all inside: the box's caps */
                    v.v[i] = 1;
            }
            iso_opts o = {0};
            o.normals = 1;
            mesh m[3];
            for (int th = 1; th <= 3; th++) {
                rt_run run = {th, NULL, 0};
                CHECK(iso_from_volume(&v, &o, &run, &m[th - 1], &e) == RT_OK, "%s", e.msg);
            }
            size_t want = crossing_edges(&v, 0), got = lattice_vertices(&m[0], &v);
            CHECK(got == want, "width %d kind %d: %zu vertices on lattice edges, %zu crossing edges", nx, kind,
                  got, want);
            CHECK(m[0].nt > 0, "width %d kind %d: no triangles", nx, kind);
            CHECK(closed_oriented(&m[0]), "width %d kind %d: not closed and oriented", nx, kind);
            CHECK(same_mesh(&m[0], &m[1]) && same_mesh(&m[0], &m[2]), "width %d kind %d: differs on 2 or 3 threads",
                  nx, kind);
            for (int k = 0; k < 3; k++)
                mesh_free(&m[k]);
            volume_free(&v);
        }
}

static double signed_volume(const mesh *m)
{
    double s = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const float *a = m->pos + 3 * m->tri[3 * t], *b = m->pos + 3 * m->tri[3 * t + 1],
                    *c = m->pos + 3 * m->tri[3 * t + 2];
        s += a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) - a[1] * ((double)b[0] * c[2] - (double)b[2] * c[0]) +
             a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
    }
    return s / 6;
}

static void test_plane_at_word_boundary(void)
{
    int nx = 130, ny = 5, nz = 4;
    /* one cell = 1 unit: nodes at x + 0.5 */
    double lo[3] = {0, 0, 0}, hi[3] = {nx, ny, nz};
    volume v;
    rt_error e;
    CHECK(volume_init(&v, nx, ny, nz, lo, hi, &e) == RT_OK, "vol");
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < ny; y++)
            for (int x = 0; x < nx; x++)
                *volume_at(&v, x, y, z) = (float)(x - 62.3);
    iso_opts o = {0};
    mesh m;
    CHECK(iso_from_volume(&v, &o, NULL, &m, &e) == RT_OK, "%s", e.msg);
    /* the plane's vertices: the x-edges from node 62 (at x = 62.5) at
     * s = 0.3; every other vertex is a cap vertex at a node's x or on the
     * face x = 130 */
    size_t on_plane = 0, elsewhere = 0;
    for (size_t i = 0; i < m.nv; i++) {
        double x = m.pos[3 * i], fr = x - floor(x);
        if (fabs(x - 62.8) < 1e-4)
            on_plane++;
        else
            elsewhere += !(x > 63 && (fabs(fr - 0.5) < 1e-4 || x == 130));
    }
    CHECK(elsewhere == 0, "%zu vertices neither on the plane x = 62.8 nor on the caps", elsewhere);
    CHECK(on_plane == (size_t)ny * nz, "%zu vertices on the plane, expected %d", on_plane, ny * nz);
    CHECK(closed_oriented(&m), "plane solid not closed");
    /* solid: x from 62.8 to 130 less chamfers of legs 1/2 on the outer box's
     * 8 edges of the solid (4 along x, 4 along y or z at x = 130); the plane
     * side has the padding too: its 4 edges lose a leg-1/2 chamfer and the
     * plane's ends at the box faces are cut like the box edges (the
     * chamfer's other leg is 0.5 on the cap side, 0.3 + ... on the plane
     * side): the volume is checked against the exact box less at most
     * 12 * length / 8 (isosurf.h's bound). */
    double L = 130 - 62.8, box = L * ny * nz, sv = signed_volume(&m);
    double bound = (4 * L + 4 * ny + 4 * nz) / 8.0 + (2 * ny + 2 * nz) / 8.0;
    CHECK(sv <= box + 1e-3 && sv >= box - bound, "plane solid volume %g, box %g, chamfers at most %g", sv, box,
          bound);
    mesh_free(&m);
    volume_free(&v);
}

int main(void)
{
    test_widths();
    test_plane_at_word_boundary();
    return check_done("test_isosurf_bits");
}
