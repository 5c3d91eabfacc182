/* isosurf.c — marching tetrahedra on a Kuhn split with shared edge vertices.
 *
 * Seed 001 renders hypertextures "as solids thresholded at density >= 0.3 and
 * >= 0.5"; this engine turns such a solid into a closed mesh (see isosurf.h
 * for the method, the padding and the orientation rules).
 *
 * Lattice: node indices run from -1 to n on each axis; nodes -1 and n are the
 * virtual padding (outside). Cells run from -1 to n-1. A lattice edge is
 * (node, d) with d in 1..7 a bit set of axes (x = 1, y = 2, z = 4): the edge
 * goes from node to node + d. Every edge of every Kuhn tetrahedron is of
 * this form, so surface vertices are keyed by (node, d).
 *
 * Parallel plan (deterministic): chunk c owns cell layers and node layers
 * [z0, z1) with z0 = -1 + 4c. Pass 1 counts the crossing edges each chunk
 * owns; prefix sums give each chunk its first vertex id. Pass 2 numbers the
 * edges of each node layer in (y, x, d) order, writes the vertices it owns,
 * and emits triangles cell by cell into a per-chunk list; the lists are
 * concatenated in chunk order. The top node layer z1 of a chunk belongs to
 * the next chunk, whose numbering of it starts at that chunk's first id, so
 * both agree without communicating.
 */
#include "isosurf.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"

#define SLAB 4
#define S_EPS 1e-3

/* Triangle tables for the six Kuhn tetrahedra: for tetrahedron t and the
 * mask of its inside vertices, up to two triangles, each three edges, each
 * edge (lower corner, higher corner) as cube-corner bit sets. */
typedef struct iso_table {
    unsigned char ntri[6][16];
    unsigned char edge[6][16][2][3][2];
    /* the same, merged per cube: for each mask of the 8 inside corners, the
     * triangles of the six tetrahedra in order, each corner as an edge
     * (lower corner, direction = higher ^ lower) */
    unsigned char cell_ntri[256];
    unsigned char cell_edge[256][12][3][2];
} iso_table;

static void build_table(iso_table *tb)
{
    static const int perm[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
    memset(tb, 0, sizeof *tb);
    for (int t = 0; t < 6; t++) {
        int cv[4] = {0, perm[t][0], perm[t][0] | perm[t][1], 7};
        for (int m = 1; m < 15; m++) {
            int in[4], out[4], ni = 0, no = 0;
            for (int k = 0; k < 4; k++) {
                if (m >> k & 1)
                    in[ni++] = k;
                else
                    out[no++] = k;
            }
            int q[4][2], nq; /* edges (tet vertex pairs) in cyclic order */
            if (ni == 1 || no == 1) {
                int s = ni == 1 ? in[0] : out[0], r = 0;
                for (int k = 0; k < 4; k++)
                    if (k != s) {
                        q[r][0] = s;
                        q[r][1] = k;
                        r++;
                    }
                nq = 3;
            } else { /* a, b inside; c, d outside: cycle ac, ad, bd, bc */
                q[0][0] = in[0], q[0][1] = out[0];
                q[1][0] = in[0], q[1][1] = out[1];
                q[2][0] = in[1], q[2][1] = out[1];
                q[3][0] = in[1], q[3][1] = out[0];
                nq = 4;
            }
            /* Direction from inside to outside, on the unit cube. */
            double dir[3] = {0, 0, 0};
            for (int k = 0; k < 4; k++)
                for (int a = 0; a < 3; a++) {
                    double c = (cv[k] >> a) & 1;
                    dir[a] += (m >> k & 1) ? -c / ni : c / no;
                }
            int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
            int nt = nq == 3 ? 1 : 2;
            tb->ntri[t][m] = (unsigned char)nt;
            for (int ti = 0; ti < nt; ti++) {
                double p[3][3];
                for (int r = 0; r < 3; r++) {
                    int *ed = q[tris[ti][r]];
                    for (int a = 0; a < 3; a++)
                        p[r][a] = 0.5 * (((cv[ed[0]] >> a) & 1) + ((cv[ed[1]] >> a) & 1));
                }
                double u[3], w[3];
                for (int a = 0; a < 3; a++) {
                    u[a] = p[1][a] - p[0][a];
                    w[a] = p[2][a] - p[0][a];
                }
                double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                               u[0] * w[1] - u[1] * w[0]};
                int order[3] = {0, 1, 2};
                if (n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] < 0) {
                    order[1] = 2;
                    order[2] = 1;
                }
                for (int r = 0; r < 3; r++) {
                    int *ed = q[tris[ti][order[r]]];
                    int c0 = cv[ed[0]], c1 = cv[ed[1]];
                    /* corners along a Kuhn path are nested: the lower is a subset */
                    int lo = (c0 & c1) == c0 ? c0 : c1, hi = lo == c0 ? c1 : c0;
                    tb->edge[t][m][ti][r][0] = (unsigned char)lo;
                    tb->edge[t][m][ti][r][1] = (unsigned char)hi;
                }
            }
        }
    }
    for (int mask = 0; mask < 256; mask++) {
        int nt = 0;
        for (int t = 0; t < 6; t++) {
            int cv[4] = {0, perm[t][0], perm[t][0] | perm[t][1], 7};
            int tm = 0;
            for (int k = 0; k < 4; k++)
                tm |= (mask >> cv[k] & 1) << k;
            for (int ti = 0; ti < tb->ntri[t][tm]; ti++, nt++)
                for (int r = 0; r < 3; r++) {
                    int lo = tb->edge[t][tm][ti][r][0], hi = tb->edge[t][tm][ti][r][1];
                    tb->cell_edge[mask][nt][r][0] = (unsigned char)lo;
                    tb->cell_edge[mask][nt][r][1] = (unsigned char)(hi ^ lo);
                }
        }
        tb->cell_ntri[mask] = (unsigned char)nt;
    }
}

typedef struct tri_list {
    uint32_t *t;
    size_t n, cap; /* in triangles */
    int failed;
} tri_list;

typedef struct iso_job {
    const volume *vol;
    double level;
    int n[3];
    double cell[3];
    int want_normals;
    int NXp, NYp;   /* layer array width and height */
    size_t lsz;     /* NXp * NYp */
    size_t doff[8]; /* index offset of node + d within a layer */
    iso_table tb;
    size_t nchunks;
    size_t *counts;  /* pass 1: owned vertices per chunk; then first ids */
    float *pos, *nrm;
    unsigned char *cap; /* 1 = vertex on a box face (cap) */
    tri_list *lists;
    uint32_t *tri_out; /* the mesh's triangle array */
    size_t *tri_at;    /* first triangle of each chunk in it */
    int *failed;     /* per chunk: allocation failure */
    int32_t *edges;  /* with an sdf: each vertex's lattice edge (x, y, z, d) */
} iso_job;

static int in_range(const iso_job *j, int i, int k, int l)
{
    return i >= 0 && i < j->n[0] && k >= 0 && k < j->n[1] && l >= 0 && l < j->n[2];
}

static float val(const iso_job *j, int i, int k, int l)
{
    return *volume_at(j->vol, i, k, l);
}

/* Layer arrays are indexed by node (x, y) at (y + 1) * NXp + (x + 1) with
 * NXp = n0 + 3: the padding nodes -1 and n plus one more column and row of
 * zeros, so that node + d is always inside the array. */
static size_t lidx(const iso_job *j, int x, int y)
{
    return (size_t)(y + 1) * (size_t)j->NXp + (size_t)(x + 1);
}

/* Inside flags of node layer z into buf (lsz bytes). */
static void inside_layer(const iso_job *j, int z, unsigned char *buf)
{
    memset(buf, 0, j->lsz);
    if (z < 0 || z >= j->n[2])
        return;
    for (int y = 0; y < j->n[1]; y++) {
        const float *row = volume_at(j->vol, 0, y, z);
        unsigned char *b = buf + lidx(j, 0, y);
        for (int x = 0; x < j->n[0]; x++)
            b[x] = (unsigned char)(row[x] >= j->level); /* NaN: outside */
    }
}

/* Does edge (node at idx, d) cross the surface? */
static int crosses(const iso_job *j, const unsigned char *in0, const unsigned char *in1, size_t idx, int d)
{
    const unsigned char *l2 = (d & 4) ? in1 : in0;
    return in0[idx] != l2[idx + j->doff[d]];
}

/* All 8 nodes of the cube based at idx agree: no edge from idx crosses. */
static int uniform(const iso_job *j, const unsigned char *in0, const unsigned char *in1, size_t idx)
{
    size_t w = (size_t)j->NXp;
    int s = in0[idx] + in0[idx + 1] + in0[idx + w] + in0[idx + w + 1] + in1[idx] + in1[idx + 1] +
            in1[idx + w] + in1[idx + w + 1];
    return s == 0 || s == 8;
}

static double coord(const iso_job *j, int a, int i)
{
    const volume *v = j->vol;
    return v->lo[a] + (v->hi[a] - v->lo[a]) * (i + 0.5) / j->n[a];
}

/* Central difference of the grid at node (i, k, l) along axis a. */
static double grid_grad(const iso_job *j, int i, int k, int l, int a)
{
    int idx[3] = {i, k, l};
    int lo = idx[a] - 1, hi = idx[a] + 1;
    if (lo < 0)
        lo = 0;
    if (hi > j->n[a] - 1)
        hi = j->n[a] - 1;
    if (hi == lo)
        return 0;
    int p[3] = {i, k, l}, q[3] = {i, k, l};
    p[a] = lo;
    q[a] = hi;
    double d = (double)val(j, q[0], q[1], q[2]) - (double)val(j, p[0], p[1], p[2]);
    return d / ((hi - lo) * j->cell[a]);
}

static void make_vertex(iso_job *j, int x, int y, int z, int d, uint32_t id)
{
    int p[3] = {x, y, z}, q[3] = {x + (d & 1), y + (d >> 1 & 1), z + (d >> 2 & 1)};
    int pr = in_range(j, p[0], p[1], p[2]), qr = in_range(j, q[0], q[1], q[2]);
    double s = 0.5, nv[3] = {0, 0, 0};
    int pin = 0;
    if (pr && qr) {
        double fp = val(j, p[0], p[1], p[2]), fq = val(j, q[0], q[1], q[2]);
        pin = fp >= j->level;
        if (isfinite(fp) && isfinite(fq) && fq != fp) {
            s = (j->level - fp) / (fq - fp);
            if (!(s >= S_EPS))
                s = S_EPS;
            if (s > 1 - S_EPS)
                s = 1 - S_EPS;
        }
        if (j->want_normals) {
            for (int a = 0; a < 3; a++) {
                double g0 = grid_grad(j, p[0], p[1], p[2], a), g1 = grid_grad(j, q[0], q[1], q[2], a);
                nv[a] = -((1 - s) * g0 + s * g1);
            }
        }
        j->cap[id] = 0;
    } else {
        /* One end is padding: the vertex is on the box face; normal = the
         * outward normal of the face(s) the padding node lies beyond. */
        int *pad = pr ? q : p;
        for (int a = 0; a < 3; a++)
            nv[a] = pad[a] < 0 ? -1.0 : pad[a] >= j->n[a] ? 1.0 : 0.0;
        j->cap[id] = 1;
    }
    if (j->edges) {
        int32_t *E = j->edges + 4 * (size_t)id;
        E[0] = x, E[1] = y, E[2] = z, E[3] = d;
    }
    float *P = j->pos + 3 * (size_t)id;
    for (int a = 0; a < 3; a++) {
        double cp = coord(j, a, p[a]), cq = coord(j, a, q[a]);
        P[a] = (float)(cp + s * (cq - cp));
    }
    if (j->want_normals) {
        double l = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        if (!(l > 0) || !isfinite(l)) {
            /* flat or broken gradient: point from the inside end outward */
            double sg = pin ? 1.0 : -1.0;
            for (int a = 0; a < 3; a++)
                nv[a] = sg * (q[a] - p[a]) * j->cell[a];
            l = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        }
        float *N = j->nrm + 3 * (size_t)id;
        for (int a = 0; a < 3; a++)
            N[a] = (float)(nv[a] / l);
    }
}

/* Number the crossing edges of node layer z into ids (starting at
 * base + *counter); write the vertices when `write`. */
static void fill_layer(iso_job *j, int z, const unsigned char *in0, const unsigned char *in1,
                       uint32_t *ids, size_t base, size_t *counter, int write)
{
    /* ids of edges that do not cross are never read, so they are not set */
    for (int y = -1; y <= j->n[1]; y++)
        for (int x = -1; x <= j->n[0]; x++) {
            size_t idx = lidx(j, x, y);
            if (uniform(j, in0, in1, idx))
                continue;
            uint32_t *row = ids + idx * 7;
            for (int d = 1; d <= 7; d++) {
                if (!crosses(j, in0, in1, idx, d))
                    continue;
                uint32_t id = (uint32_t)(base + (*counter)++);
                row[d - 1] = id;
                if (write)
                    make_vertex(j, x, y, z, d, id);
            }
        }
}

static void chunk_range(const iso_job *j, size_t c, int *z0, int *z1)
{
    *z0 = -1 + (int)c * SLAB;
    *z1 = *z0 + SLAB < j->n[2] ? *z0 + SLAB : j->n[2];
}

static void pass_count(void *ctx, size_t c, int worker)
{
    (void)worker;
    iso_job *j = ctx;
    int z0, z1;
    chunk_range(j, c, &z0, &z1);
    unsigned char *in0 = rt_malloc(j->lsz), *in1 = rt_malloc(j->lsz);
    if (!in0 || !in1) {
        j->failed[c] = 1;
        rt_free(in0);
        rt_free(in1);
        return;
    }
    size_t cnt = 0;
    inside_layer(j, z0, in0);
    for (int z = z0; z < z1; z++) {
        inside_layer(j, z + 1, in1);
        for (int y = -1; y <= j->n[1]; y++)
            for (int x = -1; x <= j->n[0]; x++) {
                size_t idx = lidx(j, x, y);
                if (uniform(j, in0, in1, idx))
                    continue;
                for (int d = 1; d <= 7; d++)
                    cnt += (size_t)crosses(j, in0, in1, idx, d);
            }
        unsigned char *t = in0;
        in0 = in1;
        in1 = t;
    }
    j->counts[c] = cnt;
    rt_free(in0);
    rt_free(in1);
}

static void push_tri(tri_list *L, uint32_t a, uint32_t b, uint32_t c)
{
    if (L->failed)
        return;
    if (L->n == L->cap) {
        size_t nc = L->cap ? L->cap * 2 : 1024;
        uint32_t *nt = rt_realloc(L->t, nc * 3 * sizeof(uint32_t));
        if (!nt) {
            L->failed = 1;
            return;
        }
        L->t = nt;
        L->cap = nc;
    }
    uint32_t *t = L->t + 3 * L->n++;
    t[0] = a;
    t[1] = b;
    t[2] = c;
}

static void pass_build(void *ctx, size_t c, int worker)
{
    (void)worker;
    iso_job *j = ctx;
    int z0, z1;
    chunk_range(j, c, &z0, &z1);
    size_t lsz = j->lsz, w = (size_t)j->NXp;
    unsigned char *ins[3];
    uint32_t *ids[2];
    ins[0] = rt_malloc(lsz);
    ins[1] = rt_malloc(lsz);
    ins[2] = rt_malloc(lsz);
    ids[0] = rt_malloc(lsz * 7 * sizeof(uint32_t));
    ids[1] = rt_malloc(lsz * 7 * sizeof(uint32_t));
    tri_list *L = &j->lists[c];
    if (!ins[0] || !ins[1] || !ins[2] || !ids[0] || !ids[1]) {
        j->failed[c] = 1;
        goto done;
    }
    size_t counter = 0, base = j->counts[c];
    inside_layer(j, z0, ins[0]);
    inside_layer(j, z0 + 1, ins[1]);
    fill_layer(j, z0, ins[0], ins[1], ids[0], base, &counter, 1);
    for (int z = z0; z < z1; z++) {
        /* ins[0] = layer z, ins[1] = layer z+1; number layer z+1 */
        inside_layer(j, z + 2, ins[2]);
        if (z + 1 < z1) {
            fill_layer(j, z + 1, ins[1], ins[2], ids[1], base, &counter, 1);
        } else {
            size_t c2 = 0, nb = c + 1 < j->nchunks ? j->counts[c + 1] : 0;
            fill_layer(j, z + 1, ins[1], ins[2], ids[1], nb, &c2, 0);
        }
        for (int y = -1; y < j->n[1]; y++)
            for (int x = -1; x < j->n[0]; x++) {
                size_t idx = lidx(j, x, y);
                const unsigned char *a = ins[0] + idx, *b = ins[1] + idx;
                int mask = a[0] | a[1] << 1 | a[w] << 2 | a[w + 1] << 3 | b[0] << 4 | b[1] << 5 |
                           b[w] << 6 | b[w + 1] << 7;
                int nt = j->tb.cell_ntri[mask];
                for (int ti = 0; ti < nt; ti++) {
                    uint32_t v[3];
                    for (int r = 0; r < 3; r++) {
                        int lo = j->tb.cell_edge[mask][ti][r][0], d = j->tb.cell_edge[mask][ti][r][1];
                        const uint32_t *I = ids[lo >> 2 & 1];
                        v[r] = I[(idx + j->doff[lo & 3]) * 7 + (size_t)(d - 1)];
                    }
                    push_tri(L, v[0], v[1], v[2]);
                }
            }
        unsigned char *tmp = ins[0];
        ins[0] = ins[1];
        ins[1] = ins[2];
        ins[2] = tmp;
        uint32_t *ti2 = ids[0];
        ids[0] = ids[1];
        ids[1] = ti2;
    }
done:
    rt_free(ins[0]);
    rt_free(ins[1]);
    rt_free(ins[2]);
    rt_free(ids[0]);
    rt_free(ids[1]);
}

/* Concatenate the chunks' triangle lists (in chunk order, at fixed offsets). */
static void pass_concat(void *ctx, size_t c, int worker)
{
    (void)worker;
    iso_job *j = ctx;
    if (j->lists[c].n)
        memcpy(j->tri_out + 3 * j->tri_at[c], j->lists[c].t, j->lists[c].n * 3 * sizeof(uint32_t));
    rt_free(j->lists[c].t);
    j->lists[c].t = NULL;
}

/* Pass 3: callback gradients (for field input) and vertex colours. */
#define VCHUNK 4096

typedef struct attr_job {
    rt_field_fn f;
    const void *ctx;
    double h[3];
    const iso_opts *o;
    mesh *m;
    const unsigned char *cap;
    int do_grad;
} attr_job;

static void pass_attr(void *ctx, size_t c, int worker)
{
    (void)worker;
    attr_job *a = ctx;
    mesh *m = a->m;
    size_t v0 = c * VCHUNK, v1 = v0 + VCHUNK < m->nv ? v0 + VCHUNK : m->nv;
    double x[RT_BLOCK], y[RT_BLOCK], z[RT_BLOCK], px[RT_BLOCK], py[RT_BLOCK], pz[RT_BLOCK];
    double out[3][RT_BLOCK], out2[RT_BLOCK];
    for (size_t b = v0; b < v1; b += RT_BLOCK) {
        size_t n = v1 - b < RT_BLOCK ? v1 - b : RT_BLOCK;
        for (size_t i = 0; i < n; i++) {
            const float *P = m->pos + 3 * (b + i);
            px[i] = P[0];
            py[i] = P[1];
            pz[i] = P[2];
        }
        if (a->do_grad) {
            double g[3][RT_BLOCK];
            for (int ax = 0; ax < 3; ax++) {
                for (int sgn = 0; sgn < 2; sgn++) {
                    double off = sgn ? -a->h[ax] : a->h[ax];
                    for (size_t i = 0; i < n; i++) {
                        x[i] = px[i] + (ax == 0 ? off : 0);
                        y[i] = py[i] + (ax == 1 ? off : 0);
                        z[i] = pz[i] + (ax == 2 ? off : 0);
                    }
                    a->f(a->ctx, n, x, y, z, sgn ? out2 : out[0]);
                }
                for (size_t i = 0; i < n; i++)
                    g[ax][i] = (out[0][i] - out2[i]) / (2 * a->h[ax]);
            }
            for (size_t i = 0; i < n; i++) {
                if (a->cap[b + i])
                    continue;
                double l = sqrt(g[0][i] * g[0][i] + g[1][i] * g[1][i] + g[2][i] * g[2][i]);
                if (!(l > 0) || !isfinite(l))
                    continue; /* keep the grid normal */
                float *N = m->nrm + 3 * (b + i);
                for (int ax = 0; ax < 3; ax++)
                    N[ax] = (float)(-g[ax][i] / l);
            }
        }
        if (a->o && a->o->colour_mode != ISO_COLOUR_NONE) {
            int nf = a->o->colour_mode == ISO_COLOUR_RGB ? 3 : 1;
            for (int k = 0; k < nf; k++)
                a->o->colour_fn[k](a->o->colour_ctx[k], n, px, py, pz, out[k]);
            for (size_t i = 0; i < n; i++) {
                float *C = m->col + 4 * (b + i);
                if (nf == 1) {
                    if (a->o->colour_ramp) {
                        ramp_eval(a->o->colour_ramp, out[0][i], C);
                    } else {
                        double t = out[0][i];
                        t = t > 0 ? (t < 1 ? t : 1) : 0; /* NaN -> 0 */
                        C[0] = C[1] = C[2] = (float)t;
                        C[3] = 1;
                    }
                } else {
                    for (int k = 0; k < 3; k++) {
                        double t = out[k][i];
                        C[k] = (float)(t > 0 ? (t < 1 ? t : 1) : 0);
                    }
                    C[3] = 1;
                }
            }
        }
    }
}

/* Pass 2b (with an sdf): move each vertex to the root of g on its edge. */
typedef struct root_job {
    rt_field_fn g;
    const void *ctx;
    const iso_job *j;
    mesh *m;
} root_job;

#define ROOT_ITERS 40

static void pass_root(void *ctx, size_t c, int worker)
{
    (void)worker;
    root_job *R = ctx;
    const iso_job *j = R->j;
    mesh *m = R->m;
    size_t v0 = c * VCHUNK, v1 = v0 + VCHUNK < m->nv ? v0 + VCHUNK : m->nv;
    double p[3][RT_BLOCK], q[3][RT_BLOCK], x[3][RT_BLOCK], gv[RT_BLOCK];
    double sa[RT_BLOCK], sb[RT_BLOCK], ga[RT_BLOCK], gb[RT_BLOCK], s[RT_BLOCK];
    int side[RT_BLOCK], live[RT_BLOCK];
    size_t id[RT_BLOCK];
    double tol = 1e-12 * fmin(j->cell[0], fmin(j->cell[1], j->cell[2]));
    for (size_t b = v0; b < v1;) {
        size_t n = 0;
        for (; b < v1 && n < RT_BLOCK; b++) {
            if (j->cap[b])
                continue;
            const int32_t *E = j->edges + 4 * b;
            int d = E[3], qi[3] = {E[0] + (d & 1), E[1] + (d >> 1 & 1), E[2] + (d >> 2 & 1)};
            for (int a = 0; a < 3; a++) {
                p[a][n] = coord(j, a, E[a]);
                q[a][n] = coord(j, a, qi[a]);
            }
            id[n++] = b;
        }
        if (!n)
            continue;
        R->g(R->ctx, n, p[0], p[1], p[2], ga);
        R->g(R->ctx, n, q[0], q[1], q[2], gb);
        size_t nl = 0;
        for (size_t i = 0; i < n; i++) {
            sa[i] = 0, sb[i] = 1, side[i] = 0;
            /* a bracket in double precision, or keep the grid's vertex */
            live[i] = isfinite(ga[i]) && isfinite(gb[i]) && (ga[i] <= 0) != (gb[i] <= 0);
            s[i] = -1;
            nl += (size_t)live[i];
        }
        for (int it = 0; it < ROOT_ITERS && nl; it++) {
            for (size_t i = 0; i < n; i++) {
                if (live[i]) {
                    double t = (sa[i] * gb[i] - sb[i] * ga[i]) / (gb[i] - ga[i]);
                    if (!(t > sa[i] && t < sb[i]))
                        t = 0.5 * (sa[i] + sb[i]);
                    s[i] = t;
                }
                double t = s[i] < 0 ? 0.5 : s[i]; /* finished rays are re-evaluated harmlessly */
                for (int a = 0; a < 3; a++)
                    x[a][i] = p[a][i] + t * (q[a][i] - p[a][i]);
            }
            R->g(R->ctx, n, x[0], x[1], x[2], gv);
            for (size_t i = 0; i < n; i++) {
                if (!live[i])
                    continue;
                double g = gv[i];
                if (!isfinite(g) || fabs(g) <= tol || sb[i] - sa[i] <= 1e-15) {
                    live[i] = 0, nl--;
                    continue;
                }
                /* Illinois: halve the value kept twice on one side */
                if ((g <= 0) == (ga[i] <= 0)) {
                    sa[i] = s[i], ga[i] = g;
                    if (side[i] == -1)
                        gb[i] *= 0.5;
                    side[i] = -1;
                } else {
                    sb[i] = s[i], gb[i] = g;
                    if (side[i] == 1)
                        ga[i] *= 0.5;
                    side[i] = 1;
                }
            }
        }
        for (size_t i = 0; i < n; i++) {
            if (s[i] < 0)
                continue;
            double t = s[i] < S_EPS ? S_EPS : s[i] > 1 - S_EPS ? 1 - S_EPS : s[i];
            float *P = m->pos + 3 * id[i];
            for (int a = 0; a < 3; a++)
                P[a] = (float)(p[a][i] + t * (q[a][i] - p[a][i]));
        }
    }
}

typedef struct neg_ctx {
    rt_field_fn f;
    const void *ctx;
} neg_ctx;

static void neg_fn(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                   double *out)
{
    const neg_ctx *c = ctx;
    c->f(c->ctx, n, x, y, z, out);
    for (size_t i = 0; i < n; i++)
        out[i] = -out[i];
}

static rt_code check_opts(const iso_opts *o, rt_error *e)
{
    if (!isfinite(o->level))
        return rt_fail(e, RT_EINVAL, "isosurface level %g is not a finite number", o->level);
    if (o->colour_mode == ISO_COLOUR_RAMP && !o->colour_fn[0])
        return rt_fail(e, RT_EINVAL, "isosurface colour by ramp needs a colour field");
    if (o->colour_mode == ISO_COLOUR_RGB && (!o->colour_fn[0] || !o->colour_fn[1] || !o->colour_fn[2]))
        return rt_fail(e, RT_EINVAL, "isosurface RGB colour needs three colour fields");
    if (o->colour_mode < 0 || o->colour_mode > 2)
        return rt_fail(e, RT_EINVAL, "isosurface colour mode %d is not 0, 1 or 2", o->colour_mode);
    return RT_OK;
}

static rt_code run_iso(const volume *vol, const iso_opts *o, rt_field_fn gf, const void *gctx,
                       const neg_ctx *sdf, const rt_run *run, mesh *out, rt_error *e)
{
    int colours = o->colour_mode != ISO_COLOUR_NONE;
    mesh_init(out, o->normals, colours);
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory for the isosurface mesh");
    rt_code rc = check_opts(o, e);
    if (rc)
        return rc;
    static const char *axn = "xyz";
    int nn[3] = {vol->nx, vol->ny, vol->nz};
    for (int a = 0; a < 3; a++) {
        if (nn[a] < 1)
            return rt_fail(e, RT_EINVAL, "isosurface grid size %d along %c is not >= 1", nn[a], axn[a]);
        if (!(vol->lo[a] < vol->hi[a]) || !isfinite(vol->hi[a] - vol->lo[a]))
            return rt_fail(e, RT_EINVAL, "isosurface bounds along %c: lo %g is not below hi %g",
                           axn[a], vol->lo[a], vol->hi[a]);
    }
    iso_job *j = rt_calloc(1, sizeof *j);
    if (!j)
        return rt_fail(e, RT_ENOMEM, "out of memory for the isosurface");
    j->vol = vol;
    j->level = sdf ? 0 : o->level; /* with an sdf, vol holds -g: inside is -g >= 0 */
    j->want_normals = o->normals != 0;
    for (int a = 0; a < 3; a++) {
        j->n[a] = nn[a];
        j->cell[a] = (vol->hi[a] - vol->lo[a]) / nn[a];
    }
    j->NXp = nn[0] + 3;
    j->NYp = nn[1] + 3;
    j->lsz = (size_t)j->NXp * (size_t)j->NYp;
    for (int d = 0; d < 8; d++)
        j->doff[d] = (size_t)(d & 1) + (size_t)(d >> 1 & 1) * (size_t)j->NXp;
    build_table(&j->tb);
    j->nchunks = (size_t)(vol->nz + 1 + SLAB - 1) / SLAB;
    j->counts = rt_calloc(j->nchunks + 1, sizeof(size_t));
    j->lists = rt_calloc(j->nchunks, sizeof(tri_list));
    j->failed = rt_calloc(j->nchunks, sizeof(int));
    size_t nv = 0, nt = 0;
    if (!j->counts || !j->lists || !j->failed) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the isosurface");
        goto done;
    }
    rc = par_for(run, "isosurface", j->nchunks, pass_count, j);
    if (rc)
        goto fail_par;
    for (size_t c = 0; c < j->nchunks; c++) {
        if (j->failed[c]) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory for the isosurface");
            goto done;
        }
        size_t k = j->counts[c];
        j->counts[c] = nv;
        nv += k;
    }
    if (nv >= UINT32_MAX) {
        rc = rt_fail(e, RT_EINVAL, "isosurface has %zu vertices, more than a mesh can index", nv);
        goto done;
    }
    j->pos = rt_malloc((nv ? nv : 1) * 3 * sizeof(float));
    j->cap = rt_malloc(nv ? nv : 1);
    if (j->want_normals)
        j->nrm = rt_malloc((nv ? nv : 1) * 3 * sizeof(float));
    if (sdf)
        j->edges = rt_malloc((nv ? nv : 1) * 4 * sizeof(int32_t));
    if (!j->pos || !j->cap || (j->want_normals && !j->nrm) || (sdf && !j->edges)) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu isosurface vertices", nv);
        goto done;
    }
    rc = par_for(run, "isosurface", j->nchunks, pass_build, j);
    if (rc)
        goto fail_par;
    for (size_t c = 0; c < j->nchunks; c++) {
        if (j->failed[c] || j->lists[c].failed) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory for the isosurface triangles");
            goto done;
        }
        nt += j->lists[c].n;
    }
    /* Hand the arrays to the mesh. */
    rt_free(out->pos);
    rt_free(out->nrm);
    out->pos = j->pos;
    j->pos = NULL;
    if (j->want_normals) {
        out->nrm = j->nrm;
        j->nrm = NULL;
    } else {
        out->nrm = NULL;
    }
    out->nv = out->cap_v = nv;
    if (colours) {
        rt_free(out->col);
        out->col = rt_malloc((nv ? nv : 1) * 4 * sizeof(float));
        if (!out->col) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory for isosurface colours");
            goto done;
        }
    }
    out->tri = rt_malloc((nt ? nt : 1) * 3 * sizeof(uint32_t));
    if (!out->tri) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu isosurface triangles", nt);
        goto done;
    }
    out->nt = out->cap_t = nt;
    j->tri_out = out->tri;
    j->tri_at = rt_calloc(j->nchunks, sizeof(size_t));
    if (!j->tri_at) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the isosurface");
        goto done;
    }
    for (size_t c = 1; c < j->nchunks; c++)
        j->tri_at[c] = j->tri_at[c - 1] + j->lists[c - 1].n;
    rc = par_for(run, "isosurface", j->nchunks, pass_concat, j);
    if (rc)
        goto fail_par;
    if (sdf) {
        root_job R = {sdf->f, sdf->ctx, j, out};
        rc = par_for(run, "isosurface", (nv + VCHUNK - 1) / VCHUNK, pass_root, &R);
        if (rc)
            goto fail_par;
    }
    if ((gf && j->want_normals) || colours) {
        attr_job aj;
        memset(&aj, 0, sizeof aj);
        aj.f = gf;
        aj.ctx = gctx;
        aj.o = o;
        aj.m = out;
        aj.cap = j->cap;
        aj.do_grad = gf && j->want_normals;
        for (int a = 0; a < 3; a++)
            aj.h[a] = 0.25 * j->cell[a];
        rc = par_for(run, "isosurface", (nv + VCHUNK - 1) / VCHUNK, pass_attr, &aj);
        if (rc)
            goto fail_par;
    }
    rc = RT_OK;
    goto done;
fail_par:
    rc = rt_fail(e, RT_ECANCEL, "isosurface interrupted");
done:
    if (j->lists)
        for (size_t c = 0; c < j->nchunks; c++)
            rt_free(j->lists[c].t);
    rt_free(j->lists);
    rt_free(j->tri_at);
    rt_free(j->counts);
    rt_free(j->failed);
    rt_free(j->pos);
    rt_free(j->nrm);
    rt_free(j->cap);
    rt_free(j->edges);
    rt_free(j);
    return rc;
}

rt_code iso_from_volume(const volume *vol, const iso_opts *opts, const rt_run *run, mesh *out,
                        rt_error *e)
{
    return run_iso(vol, opts, NULL, NULL, NULL, run, out, e);
}

typedef struct sample_job {
    rt_field_fn f;
    const void *ctx;
    volume *vol;
} sample_job;

static void pass_sample(void *ctx, size_t c, int worker)
{
    (void)worker;
    sample_job *s = ctx;
    volume *v = s->vol;
    int z = (int)c;
    double x[RT_BLOCK], y[RT_BLOCK], zz[RT_BLOCK], out[RT_BLOCK];
    double cz = v->lo[2] + (v->hi[2] - v->lo[2]) * (z + 0.5) / v->nz;
    size_t nslice = (size_t)v->nx * (size_t)v->ny;
    float *dst = v->v + nslice * (size_t)z;
    for (size_t b = 0; b < nslice; b += RT_BLOCK) {
        size_t n = nslice - b < RT_BLOCK ? nslice - b : RT_BLOCK;
        for (size_t i = 0; i < n; i++) {
            size_t k = b + i;
            int ix = (int)(k % (size_t)v->nx), iy = (int)(k / (size_t)v->nx);
            x[i] = v->lo[0] + (v->hi[0] - v->lo[0]) * (ix + 0.5) / v->nx;
            y[i] = v->lo[1] + (v->hi[1] - v->lo[1]) * (iy + 0.5) / v->ny;
            zz[i] = cz;
        }
        s->f(s->ctx, n, x, y, zz, out);
        for (size_t i = 0; i < n; i++)
            dst[b + i] = (float)out[i];
    }
}

rt_code iso_sample_field(rt_field_fn f, const void *ctx, volume *vol, const rt_run *run,
                         rt_error *e)
{
    sample_job s = {f, ctx, vol};
    if (par_for(run, "sampling field", (size_t)vol->nz, pass_sample, &s))
        return rt_fail(e, RT_ECANCEL, "field sampling interrupted");
    return RT_OK;
}

rt_code iso_from_field(rt_field_fn f, const void *ctx, const double lo[3], const double hi[3],
                       const int res[3], const iso_opts *opts, const rt_run *run, mesh *out,
                       rt_error *e)
{
    mesh_init(out, 0, 0);
    static const char *axn = "xyz";
    for (int a = 0; a < 3; a++) {
        if (res[a] < 1)
            return rt_fail(e, RT_EINVAL, "isosurface resolution %d along %c is not >= 1", res[a], axn[a]);
        if (!(lo[a] < hi[a]) || !isfinite(hi[a] - lo[a]))
            return rt_fail(e, RT_EINVAL, "isosurface bounds along %c: lo %g is not below hi %g",
                           axn[a], lo[a], hi[a]);
    }
    volume vol;
    rt_code rc = volume_init(&vol, res[0], res[1], res[2], lo, hi, e);
    if (rc)
        return rc;
    neg_ctx sd = {opts->sdf, opts->sdf_ctx};
    if (opts->sdf) { /* sample -g: the solid is -g >= 0, normals -grad(-g) */
        f = neg_fn;
        ctx = &sd;
    }
    rc = iso_sample_field(f, ctx, &vol, run, e);
    if (!rc) {
        mesh_free(out);
        rc = run_iso(&vol, opts, f, ctx, opts->sdf ? &sd : NULL, run, out, e);
    }
    volume_free(&vol);
    return rc;
}
