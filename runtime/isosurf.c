/* isosurf.c — marching cubes with the asymptotic decider, shared edge
 * vertices, a generated case table.
 *
 * Seed 001 renders hypertextures "as solids thresholded at density >= 0.3 and
 * >= 0.5"; this engine turns such a solid into a closed mesh (see isosurf.h
 * for the method, the padding and the orientation rules).
 *
 * Lattice: node indices run from -1 to n on each axis; nodes -1 and n are the
 * virtual padding (outside). Cells run from -1 to n-1. A lattice edge is
 * (node, d) with d in {1, 2, 4} the axis (x = 1, y = 2, z = 4): the edge
 * goes from node to node + d. Surface vertices are keyed by (node, d).
 *
 * Parallel plan (deterministic, flying-edges style: edges first, then
 * cells, counts first, then fills into arrays allocated once). Pass 0
 * classifies every sample once into inside bits, 64 nodes of an x-row per
 * word (one chunk per node layer); rows with no inside node are flagged, and
 * a row's crossing x-, y- and z-edges are then XORs of neighbouring words,
 * the cells that need a case are those whose 8 corner bits differ, so only
 * crossing edges and mixed cells are ever visited (one count-trailing-zeros
 * per one), never a uniform node or cell. Chunk c owns cell layers and node
 * layers [z0, z1) with z0 = -1 + 4c. Pass 1 counts the crossing edges each
 * chunk owns (popcounts), the triangles and the centre vertices of its
 * cells; prefix sums give each chunk its first vertex id, first triangle and
 * first centre record. Pass 2 numbers the crossing edges of each node layer
 * in (y, x, d) order and writes the vertices it owns, then writes the
 * triangles of the cell layer below cell by cell at the chunk's place in the
 * mesh's triangle array. The top node layer z1 of a chunk belongs to the
 * next chunk, whose numbering of it starts at that chunk's first id, so
 * both agree without communicating. A last pass places the centre vertices
 * once every edge vertex is final. No hash and no growing list anywhere.
 */
#define _DEFAULT_SOURCE /* madvise's MADV_POPULATE_WRITE (Linux) */
#include "isosurf.h"
#include "rt_alloc.h"

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "par.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define SLAB 4
#if defined(__GNUC__)
#define INLINE static inline __attribute__((always_inline))
#else
#define INLINE static inline
#endif
#define S_EPS 1e-3

/* The case table, generated here from the cube's topology (no table is
 * copied from anywhere). Cube corners are bit sets (x = 1, y = 2, z = 4);
 * the 12 cube edges are numbered a * 4 + k for axis a and the k-th of the
 * four corners without bit a (in increasing order); face f = 2a + s is the
 * face where bit a equals s.
 *
 * For a mask of inside corners and one connect/separate decision per face,
 * each face's crossing edges are paired into segments: a face with two
 * crossings has one segment; an ambiguous face (inside corners on one
 * diagonal, outside on the other) has two, cutting off the outside corners
 * when the decision is "connected" and the inside corners otherwise.
 * Walking a face's corners counter-clockwise seen from outside the cube, a
 * crossing edge is an entry (outside -> inside) or an exit; each segment
 * runs from an entry to an exit. A crossing cube edge lies on two faces,
 * walked in opposite directions, so it is the entry of exactly one segment
 * and the exit of exactly one: the segments form disjoint directed cycles.
 * Each cycle is fanned into triangles from its lowest edge; the direction
 * makes the right-hand normal point from the inside corners to the outside.
 *
 * Neighbouring cells pair the crossings of a shared face the same way (the
 * decision depends only on the face's four samples, see face_connected), so
 * every segment is used by exactly one triangle on each side: the mesh is
 * closed and manifold. A cycle of k edges gives k - 2 triangles, as in
 * marching cubes. */
#define MC_MAXT 12
#define ISO_NCASES 656 /* sum over the 256 masks of 2^(ambiguous faces); checked */

typedef struct mc_case {
    unsigned char nt;
    unsigned char e[MC_MAXT][3]; /* cube edges of each triangle */
    unsigned char nc;            /* cycles fanned around a centre vertex */
    unsigned char ck[4];         /* their lengths */
    unsigned char ce[12];        /* their cube edges, in order, one cycle after another */
} mc_case;

typedef struct iso_table {
    unsigned char face[6][4];  /* corners of each face, counter-clockwise seen from outside */
    unsigned char elo[12];     /* lower corner of each edge */
    unsigned char eax[12];     /* axis of each edge */
    unsigned char amb[256];    /* bit set of the ambiguous faces of each mask */
    unsigned short base[256];  /* first entry of each mask in cases */
    unsigned char cen[256];    /* some entry of the mask has a centre vertex */
    size_t ncases;
    mc_case cases[ISO_NCASES]; /* per mask: one entry per combination of its ambiguous faces' decisions */
} iso_table;

static int popcount8(unsigned v)
{
    int n = 0;
    for (; v; v &= v - 1)
        n++;
    return n;
}

static int edge_index(const iso_table *tb, int c0, int c1)
{
    int lo = c0 & c1, ax = (c0 ^ c1) == 1 ? 0 : (c0 ^ c1) == 2 ? 1 : 2;
    for (int e = 4 * ax; e < 4 * ax + 4; e++)
        if (tb->elo[e] == lo)
            return e;
    return -1;
}

/* Do cube edges e and f lie on a common face? */
static int common_face(const iso_table *tb, int e, int f)
{
    for (int a = 0; a < 3; a++)
        if (tb->eax[e] != a && tb->eax[f] != a && (tb->elo[e] >> a & 1) == (tb->elo[f] >> a & 1))
            return 1;
    return 0;
}

/* Triangulate the cycle c[0..k-1] into k - 2 triangles (keeping its
 * direction) by the least total chord length between edge midpoints,
 * without a chord between two edges of one face: such a chord lies in the
 * face, and the neighbouring cell could draw the same one, giving an edge of
 * four triangles. (Two edges of one face are joined only by the face's own
 * segments.) Dynamic programming over the sub-polygons c[i..j]. */
static int triangulate(const iso_table *tb, const int *c, int k, unsigned char (*tri)[3])
{
    double mid[12][3], cost[12][12];
    signed char best[12][12];
    for (int i = 0; i < k; i++)
        for (int a = 0; a < 3; a++)
            mid[i][a] = tb->eax[c[i]] == a ? 0.5 : (tb->elo[c[i]] >> a & 1);
    for (int len = 1; len < k; len++)
        for (int i = 0; i + len < k; i++) {
            int j = i + len;
            cost[i][j] = len == 1 ? 0 : HUGE_VAL;
            best[i][j] = -1;
            if (len == 1)
                continue;
            int side = j - i < k - 1; /* (i, j) is a chord, not the closing edge (0, k-1) */
            if (side && common_face(tb, c[i], c[j]))
                continue;
            double l = 0;
            if (side)
                for (int a = 0; a < 3; a++)
                    l += (mid[i][a] - mid[j][a]) * (mid[i][a] - mid[j][a]);
            for (int m = i + 1; m < j; m++) {
                double t = cost[i][m] + cost[m][j] + sqrt(l);
                if (t < cost[i][j]) {
                    cost[i][j] = t;
                    best[i][j] = (signed char)m;
                }
            }
        }
    if (!(cost[0][k - 1] < HUGE_VAL))
        return -1;
    /* emit the triangles (i, m, j) of the chosen split, depth first */
    int stack[24][2], sp = 0, nt = 0;
    stack[sp][0] = 0, stack[sp][1] = k - 1, sp++;
    while (sp) {
        sp--;
        int i = stack[sp][0], j = stack[sp][1];
        if (j - i < 2)
            continue;
        int m = best[i][j];
        tri[nt][0] = (unsigned char)c[i];
        tri[nt][1] = (unsigned char)c[m];
        tri[nt][2] = (unsigned char)c[j];
        nt++;
        stack[sp][0] = i, stack[sp][1] = m, sp++;
        stack[sp][0] = m, stack[sp][1] = j, sp++;
    }
    return 0;
}

/* The triangles of mask with decisions dec (bit f: face f connects its
 * inside corners). Returns the triangle count, or -1 if the segments do
 * not form cycles (cannot happen; checked once per table). */
static int gen_case(const iso_table *tb, int mask, int dec, mc_case *out)
{
    int next[12];
    for (int e = 0; e < 12; e++)
        next[e] = -1;
    for (int f = 0; f < 6; f++) {
        int in[4], ed[4], n = 0;
        for (int k = 0; k < 4; k++)
            in[k] = mask >> tb->face[f][k] & 1;
        for (int k = 0; k < 4; k++) {
            ed[k] = edge_index(tb, tb->face[f][k], tb->face[f][(k + 1) & 3]);
            n += in[k] != in[(k + 1) & 3];
        }
        for (int k = 0; k < 4; k++) {
            if (in[k] || !in[(k + 1) & 3])
                continue; /* not an entry */
            int x;
            if (n == 2) {
                for (x = 0; x < 4; x++)
                    if (in[x] && !in[(x + 1) & 3])
                        break;
            } else {
                x = (dec >> f & 1) ? (k + 3) & 3 : (k + 1) & 3;
            }
            if (next[ed[k]] >= 0)
                return -1;
            next[ed[k]] = ed[x];
        }
    }
    int seen[12] = {0}, nt = 0;
    for (int e0 = 0; e0 < 12; e0++) {
        if (next[e0] < 0 || seen[e0])
            continue;
        int cyc[12], k = 0;
        for (int e = e0; !seen[e]; e = next[e]) {
            if (next[e] < 0)
                return -1;
            seen[e] = 1;
            cyc[k++] = e;
        }
        if (cyc[0] != e0 || next[cyc[k - 1]] != e0 || k < 3 || nt + k - 2 > MC_MAXT)
            return -1;
        if (triangulate(tb, cyc, k, out->e + nt) == 0) {
            nt += k - 2;
            continue;
        }
        /* no chord avoids the faces: a vertex at the cycle's centre */
        int at = 0;
        for (int c = 0; c < out->nc; c++)
            at += out->ck[c];
        out->ck[out->nc++] = (unsigned char)k;
        for (int i = 0; i < k; i++)
            out->ce[at + i] = (unsigned char)cyc[i];
    }
    out->nt = (unsigned char)nt;
    return nt;
}

/* 0 on success, 2 if some case does not close into cycles or the entries
 * are not ISO_NCASES (cannot happen: the unit tests build every case). */
static int build_table(iso_table *tb)
{
    memset(tb, 0, sizeof *tb);
    for (int e = 0; e < 12; e++) {
        int a = e >> 2, k = e & 3, low = (1 << a) - 1;
        tb->elo[e] = (unsigned char)((k & low) | (k & ~low) << 1);
        tb->eax[e] = (unsigned char)a;
    }
    for (int a = 0; a < 3; a++) {
        int B = 1 << (a + 1) % 3, C = 1 << (a + 2) % 3;
        for (int s = 0; s < 2; s++) {
            int b0 = s << a;
            unsigned char *F = tb->face[2 * a + s];
            F[0] = (unsigned char)b0;
            F[2] = (unsigned char)(b0 | B | C);
            /* (0,0) (1,0) (1,1) (0,1) in (b, c) turns about +e_a */
            F[1] = (unsigned char)(b0 | (s ? B : C));
            F[3] = (unsigned char)(b0 | (s ? C : B));
        }
    }
    size_t total = 0;
    for (int m = 0; m < 256; m++) {
        for (int f = 0; f < 6; f++) {
            const unsigned char *F = tb->face[f];
            int i0 = m >> F[0] & 1, i1 = m >> F[1] & 1, i2 = m >> F[2] & 1, i3 = m >> F[3] & 1;
            if (i0 == i2 && i1 == i3 && i0 != i1)
                tb->amb[m] |= (unsigned char)(1 << f);
        }
        tb->base[m] = (unsigned short)total;
        total += (size_t)1 << popcount8(tb->amb[m]);
    }
    tb->ncases = total;
    if (total != ISO_NCASES)
        return 2;
    for (int m = 0; m < 256; m++) {
        int na = popcount8(tb->amb[m]);
        for (int ci = 0; ci < 1 << na; ci++) {
            int dec = 0, bit = 0;
            for (int f = 0; f < 6; f++)
                if (tb->amb[m] >> f & 1)
                    dec |= (ci >> bit++ & 1) << f;
            if (gen_case(tb, m, dec, &tb->cases[tb->base[m] + ci]) < 0)
                return 2;
            tb->cen[m] |= tb->cases[tb->base[m] + ci].nc != 0;
        }
    }
    return 0;
}

/* The table depends on nothing but the cube, so it is built once per
 * process (as deflate.c's CRC tables) and only read afterwards: building it
 * took 2.7 M instructions, 4% of a 128^3 extraction. */
static iso_table the_table;
static int the_table_rc;
static pthread_once_t table_once = PTHREAD_ONCE_INIT;

static void table_init(void)
{
    the_table_rc = build_table(&the_table);
}

/* Population count of a word, inline (without -mpopcnt the builtin is a
 * call into libgcc). */
static int popcount64(uint64_t v)
{
    v -= v >> 1 & UINT64_C(0x5555555555555555);
    v = (v & UINT64_C(0x3333333333333333)) + (v >> 2 & UINT64_C(0x3333333333333333));
    v = (v + (v >> 4)) & UINT64_C(0x0F0F0F0F0F0F0F0F);
    return (int)((v * UINT64_C(0x0101010101010101)) >> 56);
}

/* Map the pages of a block that is about to be written through in one
 * call (Linux 5.14's MADV_POPULATE_WRITE) rather than one page fault per
 * 4 KiB as the writes first touch them. A fresh block of 128 KiB or more
 * comes straight from mmap on every call (glibc gives same-sized blocks to
 * mmap again after they are freed), so a 128^3 extraction met about 1,000
 * faults, a fifth of its time. Only the block's whole pages; contents are
 * unchanged (pages already mapped stay as they are); where the call is
 * unknown or refused, the writes fault the pages in as before. */
static void prefault(void *p, size_t bytes)
{
#if defined(MADV_POPULATE_WRITE)
    static const size_t least = 64 << 10; /* below this the faults cost less than the call */
    long pg = sysconf(_SC_PAGESIZE);
    if (!p || bytes < least || pg <= 0)
        return;
    uintptr_t a = ((uintptr_t)p + (uintptr_t)pg - 1) & ~((uintptr_t)pg - 1);
    uintptr_t b = ((uintptr_t)p + bytes) & ~((uintptr_t)pg - 1);
    if (b > a)
        (void)madvise((void *)a, b - a, MADV_POPULATE_WRITE);
#else
    (void)p;
    (void)bytes;
#endif
}

/* Centre vertices: records of CEN_REC words (vertex id, cycle length k, the
 * k vertices of the cycle), in one array; chunk c's start at cen_at[c]. */
#define CEN_REC 14

typedef struct iso_job {
    const volume *vol;
    double level;
    float flevel;   /* the least float >= level: f >= flevel exactly when (double)f >= level */
    int n[3];
    double cell[3];
    double den2[3]; /* 2 * cell: the central difference's denominator */
    ptrdiff_t stride[3];
    int want_normals;
    int NXp, NYp;   /* layer array width and height */
    size_t lsz;     /* NXp * NYp */
    size_t doff[8]; /* index offset of node + d within a layer */
    size_t eoff[12]; /* per cube edge: offset of its id from the cell's node, in a layer's ids */
    const iso_table *tb;
    /* Inside bits: node (x, y, z), each from -1, is bit x + 1 of the W words
     * of row (y, z); rows y = -1 .. n1 + 1 of layers z = -1 .. n2 + 1, the
     * padding rows and bits zero. rowany: the row has an inside node. */
    int W;
    uint64_t *bits;
    unsigned char *rowany;
    double *crd[3]; /* coord(a, i) at crd[a][i + 1], i = -1 .. n[a] */
    size_t nchunks;
    size_t *counts;  /* pass 1: owned vertices per chunk; then first ids */
    size_t *nedge;   /* per chunk: owned edge vertices (its centre vertices follow) */
    size_t *ncen;    /* per chunk: centre vertices */
    size_t *cen_at;  /* first centre record of each chunk */
    size_t *ntri;    /* pass 1: triangles per chunk */
    size_t *tri_at;  /* first triangle of each chunk */
    uint32_t *cen;   /* the centre records */
    float *pos, *nrm;
    unsigned char *cap; /* 1 = vertex on a box face (cap), 2 = centre vertex */
    uint32_t *tri;   /* the mesh's triangle array */
    int32_t *edges;  /* with an sdf: each vertex's lattice edge (x, y, z, d) */
    uint32_t **scratch; /* per worker: two layers of vertex ids (lsz * 3 each) */
    int nworkers;
} iso_job;

static int in_range(const iso_job *j, int i, int k, int l)
{
    return i >= 0 && i < j->n[0] && k >= 0 && k < j->n[1] && l >= 0 && l < j->n[2];
}

static float val(const iso_job *j, int i, int k, int l)
{
    return *volume_at(j->vol, i, k, l);
}

/* Layer arrays of vertex ids are indexed by node (x, y) at (y + 1) * NXp +
 * (x + 1) with NXp = n0 + 3: the padding nodes -1 and n plus one more column
 * and row, so that node + d is always inside the array. */
static size_t lidx(const iso_job *j, int x, int y)
{
    return (size_t)(y + 1) * (size_t)j->NXp + (size_t)(x + 1);
}

static double coord(const iso_job *j, int a, int i)
{
    const volume *v = j->vol;
    return v->lo[a] + (v->hi[a] - v->lo[a]) * (i + 0.5) / j->n[a];
}

static size_t row_index(const iso_job *j, int y, int z)
{
    return (size_t)(z + 1) * (size_t)j->NYp + (size_t)(y + 1);
}

static const uint64_t *row_bits(const iso_job *j, int y, int z)
{
    return j->bits + row_index(j, y, z) * (size_t)j->W;
}

/* Word w of row r moved down one bit: bit i is node i + 1's. */
static uint64_t next_bits(const uint64_t *r, int w, int W)
{
    return r[w] >> 1 | (w + 1 < W ? r[w + 1] << 63 : 0);
}

/* Pass 0: the inside bits of node layer z (one chunk per layer). */
static void pass_classify(void *ctx, size_t c, int worker)
{
    (void)worker;
    iso_job *j = ctx;
    int z = (int)c, W = j->W, n0 = j->n[0];
    float lv = j->flevel;
    for (int y = 0; y < j->n[1]; y++) {
        const float *row = volume_at(j->vol, 0, y, z);
        uint64_t *b = j->bits + row_index(j, y, z) * (size_t)W, any = 0;
        /* first node x at bit x of word x / 64, then everything up one bit */
        for (int w = 0; 64 * w < n0; w++) {
            int x0 = 64 * w, xa = x0, xe = x0 + 64 < n0 ? x0 + 64 : n0;
            uint64_t v = 0;
#if defined(__SSE2__)
            if (xe - x0 == 64) {
                /* 16 comparisons at a time (x86-64's baseline SSE2: cmpps
                 * is false for NaN, as >= is), narrowed to 16 bytes and
                 * their signs gathered into 16 bits */
                __m128 l4 = _mm_set1_ps(lv);
                for (int k = 0; k < 4; k++) {
                    const float *r = row + x0 + 16 * k;
                    __m128i a = _mm_castps_si128(_mm_cmpge_ps(_mm_loadu_ps(r), l4));
                    __m128i b2 = _mm_castps_si128(_mm_cmpge_ps(_mm_loadu_ps(r + 4), l4));
                    __m128i c2 = _mm_castps_si128(_mm_cmpge_ps(_mm_loadu_ps(r + 8), l4));
                    __m128i d2 = _mm_castps_si128(_mm_cmpge_ps(_mm_loadu_ps(r + 12), l4));
                    __m128i m = _mm_packs_epi16(_mm_packs_epi32(a, b2), _mm_packs_epi32(c2, d2));
                    v |= (uint64_t)(unsigned)_mm_movemask_epi8(m) << (16 * k);
                }
                xa = xe;
            }
#elif defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
            if (xe - x0 == 64) {
                /* 64 comparisons into bytes (vectorised), each 8 bytes of 0/1
                 * gathered into 8 bits by one multiplication */
                unsigned char t[64];
                for (int k = 0; k < 64; k++)
                    t[k] = row[x0 + k] >= lv; /* NaN: outside */
                for (int k = 0; k < 8; k++) {
                    uint64_t g;
                    memcpy(&g, t + 8 * k, 8);
                    v |= (g * UINT64_C(0x0102040810204080)) >> 56 << (8 * k);
                }
                xa = xe;
            }
#endif
            for (int x = xa; x < xe; x++)
                v |= (uint64_t)(row[x] >= lv) << (x - x0); /* NaN: outside */
            b[w] = v;
            any |= v;
        }
        for (int w = W - 1; w >= 0; w--) {
            uint64_t hi = 64 * w < n0 ? b[w] << 1 : 0;
            b[w] = hi | (w > 0 ? b[w - 1] >> 63 : 0);
        }
        j->rowany[row_index(j, y, z)] = any != 0;
    }
}

/* The four node rows of cell row (y, z), in corner order (bits 1 and 2 of
 * the corner: +y, +z); 0 if they are all outside. */
static int cell_rows(const iso_job *j, int y, int z, const uint64_t *R[4])
{
    const unsigned char *a = j->rowany;
    size_t i0 = row_index(j, y, z), i1 = row_index(j, y, z + 1);
    if (!(a[i0] | a[i0 + 1] | a[i1] | a[i1 + 1]))
        return 0;
    R[0] = row_bits(j, y, z);
    R[1] = row_bits(j, y + 1, z);
    R[2] = row_bits(j, y, z + 1);
    R[3] = row_bits(j, y + 1, z + 1);
    return 1;
}

/* Word w of the cell row's corner bits: v[k] bit i is corner k (x = k & 1,
 * row k >> 1) of the cell based at node 64w + i - 1. Returns the cells whose
 * 8 corners are not all alike. */
static uint64_t cell_words(const uint64_t *R[4], int w, int W, uint64_t v[8])
{
    uint64_t any = 0, all = ~(uint64_t)0;
    for (int r = 0; r < 4; r++) {
        v[2 * r] = R[r][w];
        v[2 * r + 1] = next_bits(R[r], w, W);
        any |= v[2 * r] | v[2 * r + 1];
        all &= v[2 * r] & v[2 * r + 1];
    }
    return any & ~all;
}

/* The mask of inside corners of the cell at bit b of cell_words' v. */
static int cell_mask(const uint64_t v[8], int b)
{
    if (b < 63) /* both corners of each row in one word */
        return (int)(v[0] >> b & 3) | (int)(v[2] >> b & 3) << 2 | (int)(v[4] >> b & 3) << 4 |
               (int)(v[6] >> b & 3) << 6;
    return (int)(v[0] >> 63) | (int)(v[1] >> 63) << 1 | (int)(v[2] >> 63) << 2 | (int)(v[3] >> 63) << 3 |
           (int)(v[4] >> 63) << 4 | (int)(v[5] >> 63) << 5 | (int)(v[6] >> 63) << 6 | (int)(v[7] >> 63) << 7;
}

/* The crossing edges of node row (y, z) in word w, per axis; 0 if none. */
static uint64_t row_crossings(const iso_job *j, int y, int z, int w, uint64_t c[3])
{
    const uint64_t *A = row_bits(j, y, z), *B = row_bits(j, y + 1, z), *C = row_bits(j, y, z + 1);
    uint64_t a = A[w];
    c[0] = a ^ next_bits(A, w, j->W);
    c[1] = a ^ B[w];
    c[2] = a ^ C[w];
    return c[0] | c[1] | c[2];
}

static int row_has_crossings(const iso_job *j, int y, int z)
{
    const unsigned char *a = j->rowany;
    return a[row_index(j, y, z)] | a[row_index(j, y + 1, z)] | a[row_index(j, y, z + 1)];
}

/* Central difference of the grid at node i (pointer p) along axis a
 * (one-sided at the border, 0 on a one-sample axis). */
static double grid_grad(const iso_job *j, const float *p, int i, int a)
{
    ptrdiff_t st = j->stride[a];
    int n = j->n[a];
    if (i > 0 && i < n - 1)
        return ((double)p[st] - (double)p[-st]) / j->den2[a];
    int lo = i - 1 < 0 ? 0 : i - 1, hi = i + 1 > n - 1 ? n - 1 : i + 1;
    if (hi == lo)
        return 0;
    double d = (double)p[(hi - i) * st] - (double)p[(lo - i) * st];
    return d / ((hi - lo) * j->cell[a]);
}

static void write_normal(iso_job *j, uint32_t id, double nv[3], const int p[3], const int q[3], int pin)
{
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

/* Where the level crosses an edge whose ends hold fp and fq, as a fraction
 * of the edge from the fp end, kept S_EPS off both ends (0.5 when the ends
 * are equal or not finite). */
static inline double edge_fraction(double level, double fp, double fq)
{
    double s = 0.5;
    if (isfinite(fp) && isfinite(fq) && fq != fp) {
        s = (level - fp) / (fq - fp);
        if (!(s >= S_EPS))
            s = S_EPS;
        if (s > 1 - S_EPS)
            s = 1 - S_EPS;
    }
    return s;
}

/* Vertex id: its edge (p, axis d) when edges are kept, and its position
 * the fraction s of the way from node p to node q. */
static inline void put_vertex(iso_job *j, uint32_t id, int d, const int p[3], const int q[3], double s)
{
    if (j->edges) {
        int32_t *E = j->edges + 4 * (size_t)id;
        E[0] = p[0], E[1] = p[1], E[2] = p[2], E[3] = d;
    }
    float *O = j->pos + 3 * (size_t)id;
    for (int a = 0; a < 3; a++) {
        double cp = j->crd[a][p[a] + 1], cq = j->crd[a][q[a] + 1];
        O[a] = (float)(cp + s * (cq - cp));
    }
}

/* make_vertex for an edge whose two ends are at least one node from the
 * grid's border on every axis (most edges): the same arithmetic without
 * the border cases, so the compiler can overlap the divisions. */
static void make_vertex_inner(iso_job *j, int x, int y, int z, int d, uint32_t id)
{
    int p[3] = {x, y, z}, q[3] = {x + (d & 1), y + (d >> 1 & 1), z + (d >> 2 & 1)};
    const float *P = volume_at(j->vol, x, y, z), *Q = P + j->stride[d >> 1];
    double fp = *P, fq = *Q, s = edge_fraction(j->level, fp, fq);
    int pin = fp >= j->level;
    j->cap[id] = 0;
    put_vertex(j, id, d, p, q, s);
    if (j->want_normals) {
        double g0[3], g1[3], nv[3];
        for (int a = 0; a < 3; a++) {
            ptrdiff_t st = j->stride[a];
            g0[a] = ((double)P[st] - (double)P[-st]) / j->den2[a];
            g1[a] = ((double)Q[st] - (double)Q[-st]) / j->den2[a];
        }
        for (int a = 0; a < 3; a++)
            nv[a] = -((1 - s) * g0[a] + s * g1[a]);
        write_normal(j, id, nv, p, q, pin);
    }
}

static void make_vertex(iso_job *j, int x, int y, int z, int d, uint32_t id)
{
    int hi = (d & 1) + 1, hj = (d >> 1 & 1) + 1, hk = (d >> 2 & 1) + 1;
    if (x >= 1 && y >= 1 && z >= 1 && x + hi < j->n[0] && y + hj < j->n[1] && z + hk < j->n[2]) {
        make_vertex_inner(j, x, y, z, d, id);
        return;
    }
    int p[3] = {x, y, z}, q[3] = {x + (d & 1), y + (d >> 1 & 1), z + (d >> 2 & 1)};
    int pr = in_range(j, p[0], p[1], p[2]), qr = in_range(j, q[0], q[1], q[2]);
    double s = 0.5, nv[3] = {0, 0, 0};
    int pin = 0;
    if (pr && qr) {
        const float *fpp = volume_at(j->vol, p[0], p[1], p[2]), *fqp = volume_at(j->vol, q[0], q[1], q[2]);
        double fp = *fpp, fq = *fqp;
        pin = fp >= j->level;
        s = edge_fraction(j->level, fp, fq);
        j->cap[id] = 0;
        if (j->want_normals) {
            for (int a = 0; a < 3; a++) {
                double g0 = grid_grad(j, fpp, p[a], a), g1 = grid_grad(j, fqp, q[a], a);
                nv[a] = -((1 - s) * g0 + s * g1);
            }
        }
    } else {
        /* One end is padding: the vertex is on the box face; normal = the
         * outward normal of the face(s) the padding node lies beyond. */
        int *pad = pr ? q : p;
        for (int a = 0; a < 3; a++)
            nv[a] = pad[a] < 0 ? -1.0 : pad[a] >= j->n[a] ? 1.0 : 0.0;
        j->cap[id] = 1;
    }
    put_vertex(j, id, d, p, q, s);
    if (j->want_normals)
        write_normal(j, id, nv, p, q, pin);
}

/* Number the crossing edges of node layer z in (y, x, axis) order into ids
 * (starting at base + *counter); write the vertices when `write`. */
static void number_layer(iso_job *j, int z, uint32_t *ids, size_t base, size_t *counter, int write)
{
    /* ids of edges that do not cross are never read, so they are not set */
    for (int y = -1; y <= j->n[1]; y++) {
        if (!row_has_crossings(j, y, z))
            continue;
        for (int w = 0; w < j->W; w++) {
            uint64_t c[3], u = row_crossings(j, y, z, w, c);
            while (u) {
                int b = __builtin_ctzll(u), x = 64 * w + b - 1;
                u &= u - 1;
                uint32_t *row = ids + lidx(j, x, y) * 3;
                for (int a = 0; a < 3; a++) {
                    if (!(c[a] >> b & 1))
                        continue;
                    uint32_t id = (uint32_t)(base + (*counter)++);
                    row[a] = id;
                    if (write)
                        make_vertex(j, x, y, z, 1 << a, id);
                }
            }
        }
    }
}

static int decisions(const iso_job *j, int x, int y, int z, int mask);

static void chunk_range(const iso_job *j, size_t c, int *z0, int *z1)
{
    *z0 = -1 + (int)c * SLAB;
    *z1 = *z0 + SLAB < j->n[2] ? *z0 + SLAB : j->n[2];
}

static const mc_case *cell_case(const iso_job *j, int x, int y, int z, int mask)
{
    int ci = j->tb->base[mask];
    if (j->tb->amb[mask])
        ci += decisions(j, x, y, z, mask);
    return &j->tb->cases[ci];
}

/* What the two passes carry while they walk the cells: pass 1 counts the
 * triangles and centre vertices; pass 2 writes them, the next triangle at
 * T and the next centre record at CR, centre ids from cen0 on, edge ids
 * from ids[0] (cell layer z's bottom node layer) and ids[1] (its top). */
typedef struct cell_acc {
    size_t ntri, ncen;
    uint32_t *T, *CR, **ids;
    const uint32_t *eb[12]; /* per cube edge: its id for the cell at layer index 0 (idx * 3 on) */
    size_t cen0;
} cell_acc;

INLINE void count_cell(cell_acc *a, const mc_case *K)
{
    a->ntri += K->nt;
    for (int k = 0; k < K->nc; k++)
        a->ntri += K->ck[k];
    a->ncen += K->nc;
}

/* the triangles of the cell at layer index idx, and its centre vertices
 * (each with a fan of triangles around it) */
INLINE void build_cell(iso_job *j, cell_acc *a, size_t idx, const mc_case *K)
{
    uint32_t *T = a->T;
    for (int ti = 0; ti < K->nt; ti++, T += 3)
        for (int r = 0; r < 3; r++) {
            int e = K->e[ti][r];
            T[r] = a->eb[e][idx * 3];
        }
    for (int k = 0, at = 0; k < K->nc; at += K->ck[k++]) {
        uint32_t *rec = a->CR;
        int n = K->ck[k];
        a->CR += CEN_REC;
        rec[0] = (uint32_t)(a->cen0 + a->ncen++);
        rec[1] = (uint32_t)n;
        for (int r = 0; r < n; r++) {
            int e = K->ce[at + r];
            rec[2 + r] = a->eb[e][idx * 3];
        }
        for (int r = 0; r < n; r++, T += 3) {
            T[0] = rec[2 + r];
            T[1] = rec[2 + (r + 1) % n];
            T[2] = rec[0];
        }
        j->cap[rec[0]] = 2;
    }
    a->T = T;
}

/* The cells of cell layer z that the surface crosses (corners not all
 * alike), in (y, x) order: counted (build 0, pass 1) or written (1). */
INLINE void walk_cells(iso_job *j, int z, cell_acc *a, const int build)
{
    int W = j->W;
    if (build)
        for (int e = 0; e < 12; e++)
            a->eb[e] = a->ids[j->tb->elo[e] >> 2] + j->eoff[e];
    for (int y = -1; y < j->n[1]; y++) {
        const uint64_t *R[4];
        if (!cell_rows(j, y, z, R))
            continue;
        for (int w = 0; w < W; w++) {
            uint64_t v[8], act = cell_words(R, w, W, v);
            while (act) {
                int b = __builtin_ctzll(act), x = 64 * w + b - 1;
                act &= act - 1;
                const mc_case *K = cell_case(j, x, y, z, cell_mask(v, b));
                if (build)
                    build_cell(j, a, lidx(j, x, y), K);
                else
                    count_cell(a, K);
            }
        }
    }
}

/* Pass 1: the chunk's crossing edges (node layers z0 .. z1-1), and the
 * triangles and centre vertices of its cell layers. */
static void pass_count(void *ctx, size_t c, int worker)
{
    (void)worker;
    iso_job *j = ctx;
    int z0, z1, W = j->W;
    chunk_range(j, c, &z0, &z1);
    size_t cnt = 0;
    cell_acc a = {0};
    for (int z = z0; z < z1; z++) {
        for (int y = -1; y <= j->n[1]; y++) {
            if (!row_has_crossings(j, y, z))
                continue;
            for (int w = 0; w < W; w++) {
                uint64_t e[3];
                row_crossings(j, y, z, w, e);
                cnt += (size_t)(popcount64(e[0]) + popcount64(e[1]) + popcount64(e[2]));
            }
        }
        walk_cells(j, z, &a, 0);
    }
    j->nedge[c] = cnt;
    j->ncen[c] = a.ncen;
    j->ntri[c] = a.ntri;
    j->counts[c] = cnt + a.ncen;
}

/* The asymptotic decider on face f of the cell at (x, y, z): the bilinear
 * interpolant of the face's four samples v (relative to the level) has its
 * saddle value (v0 v2 - v1 v3) / (v0 + v2 - v1 - v3); the inside corners
 * are connected across the face when that value is inside (>= 0). With the
 * inside pair's product P_in >= 0 and the outside pair's P_out > 0, that is
 * P_in >= P_out, a symmetric expression of the four samples, so the two
 * cells sharing the face decide alike. A face with a padding node or a
 * non-finite sample keeps its inside corners separate. */
static int face_connected(const iso_job *j, int x, int y, int z, int f)
{
    double v[4];
    for (int k = 0; k < 4; k++) {
        int c = j->tb->face[f][k], p = x + (c & 1), q = y + (c >> 1 & 1), r = z + (c >> 2 & 1);
        if (!in_range(j, p, q, r))
            return 0;
        v[k] = (double)val(j, p, q, r) - j->level;
        if (!isfinite(v[k]))
            return 0;
    }
    double a = v[0] * v[2], b = v[1] * v[3];
    return v[0] >= 0 ? a >= b : b >= a;
}

/* Index of the cell's decisions among its mask's table entries. */
static int decisions(const iso_job *j, int x, int y, int z, int mask)
{
    int ci = 0, bit = 0, amb = j->tb->amb[mask];
    for (int f = 0; f < 6; f++)
        if (amb >> f & 1)
            ci |= face_connected(j, x, y, z, f) << bit++;
    return ci;
}

/* Centre vertices: the mean of their cycle's vertices (after any root
 * finding), normal the normalised mean of theirs. */
typedef struct cen_job {
    iso_job *j;
    mesh *m;
} cen_job;

static void pass_centres(void *ctx, size_t c, int worker)
{
    (void)worker;
    cen_job *C = ctx;
    const iso_job *j = C->j;
    mesh *m = C->m;
    for (size_t i = 0; i < j->ncen[c]; i++) {
        const uint32_t *rec = j->cen + CEN_REC * (j->cen_at[c] + i);
        int n = (int)rec[1];
        double p[3] = {0, 0, 0}, q[3] = {0, 0, 0};
        for (int r = 0; r < n; r++)
            for (int a = 0; a < 3; a++) {
                p[a] += m->pos[3 * (size_t)rec[2 + r] + a];
                if (m->nrm)
                    q[a] += m->nrm[3 * (size_t)rec[2 + r] + a];
            }
        double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int a = 0; a < 3; a++) {
            m->pos[3 * (size_t)rec[0] + a] = (float)(p[a] / n);
            if (m->nrm)
                m->nrm[3 * (size_t)rec[0] + a] = (float)(l > 0 ? q[a] / l : 0);
        }
    }
}

/* Pass 2: number and write the chunk's vertices, and write its triangles
 * and centre records at the places pass 1 counted for them. */
static void pass_build(void *ctx, size_t c, int worker)
{
    iso_job *j = ctx;
    int z0, z1;
    chunk_range(j, c, &z0, &z1);
    uint32_t *ids[2] = {j->scratch[worker], j->scratch[worker] + j->lsz * 3};
    size_t counter = 0, base = j->counts[c];
    cell_acc a = {0};
    a.T = j->tri + 3 * j->tri_at[c];
    a.CR = j->cen + CEN_REC * j->cen_at[c];
    a.ids = ids;
    a.cen0 = base + j->nedge[c];
    number_layer(j, z0, ids[0], base, &counter, 1);
    for (int z = z0; z < z1; z++) {
        /* ids[0] = layer z; number layer z+1 (the next chunk's first layer
         * is numbered from that chunk's first id and not written here) */
        if (z + 1 < z1) {
            number_layer(j, z + 1, ids[1], base, &counter, 1);
        } else {
            size_t c2 = 0, nb = c + 1 < j->nchunks ? j->counts[c + 1] : 0;
            number_layer(j, z + 1, ids[1], nb, &c2, 0);
        }
        walk_cells(j, z, &a, 1);
        uint32_t *t = ids[0];
        ids[0] = ids[1];
        ids[1] = t;
    }
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
                if (a->cap[b + i] == 1)
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
    j->flevel = (float)j->level;
    if ((double)j->flevel < j->level)
        j->flevel = nextafterf(j->flevel, INFINITY);
    j->want_normals = o->normals != 0;
    for (int a = 0; a < 3; a++) {
        j->n[a] = nn[a];
        j->cell[a] = (vol->hi[a] - vol->lo[a]) / nn[a];
        j->den2[a] = 2 * j->cell[a];
    }
    j->stride[0] = 1;
    j->stride[1] = (ptrdiff_t)nn[0];
    j->stride[2] = (ptrdiff_t)nn[0] * (ptrdiff_t)nn[1];
    j->NXp = nn[0] + 3;
    j->NYp = nn[1] + 3;
    j->lsz = (size_t)j->NXp * (size_t)j->NYp;
    j->W = (nn[0] + 2 + 63) / 64;
    for (int d = 0; d < 8; d++)
        j->doff[d] = (size_t)(d & 1) + (size_t)(d >> 1 & 1) * (size_t)j->NXp;
    pthread_once(&table_once, table_init);
    j->tb = &the_table;
    if (the_table_rc) {
        rc = rt_fail(e, RT_EINVAL, "isosurface case table is inconsistent (internal error)");
        goto done;
    }
    for (int k = 0; k < 12; k++) {
        int lo = j->tb->elo[k];
        j->eoff[k] = j->doff[lo & 3] * 3 + j->tb->eax[k];
    }
    size_t nrows = (size_t)j->NYp * (size_t)(nn[2] + 3);
    j->bits = rt_calloc(nrows * (size_t)j->W, sizeof(uint64_t));
    j->rowany = rt_calloc(nrows, 1);
    for (int a = 0; a < 3; a++) {
        j->crd[a] = rt_malloc(((size_t)nn[a] + 2) * sizeof(double));
        if (j->crd[a])
            for (int i = -1; i <= nn[a]; i++)
                j->crd[a][i + 1] = coord(j, a, i);
    }
    j->nchunks = (size_t)(vol->nz + 1 + SLAB - 1) / SLAB;
    j->counts = rt_calloc(j->nchunks + 1, sizeof(size_t));
    j->nedge = rt_calloc(j->nchunks, sizeof(size_t));
    j->ncen = rt_calloc(j->nchunks, sizeof(size_t));
    j->cen_at = rt_calloc(j->nchunks, sizeof(size_t));
    j->ntri = rt_calloc(j->nchunks, sizeof(size_t));
    j->tri_at = rt_calloc(j->nchunks, sizeof(size_t));
    j->nworkers = par_workers(run, j->nchunks);
    j->scratch = rt_calloc((size_t)j->nworkers, sizeof(uint32_t *));
    for (int w = 0; j->scratch && w < j->nworkers; w++)
        j->scratch[w] = rt_malloc(j->lsz * 6 * sizeof(uint32_t));
    int scratch_ok = j->scratch != NULL;
    for (int w = 0; scratch_ok && w < j->nworkers; w++)
        scratch_ok = j->scratch[w] != NULL;
    size_t nv = 0, nt = 0, nc = 0;
    if (!j->bits || !j->rowany || !j->crd[0] || !j->crd[1] || !j->crd[2] || !j->counts || !j->nedge ||
        !j->ncen || !j->cen_at || !j->ntri || !j->tri_at || !scratch_ok) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for the isosurface");
        goto done;
    }
    prefault(j->bits, nrows * (size_t)j->W * sizeof(uint64_t));
    for (int w = 0; w < j->nworkers; w++)
        prefault(j->scratch[w], j->lsz * 6 * sizeof(uint32_t));
    rc = par_for(run, "isosurface", (size_t)nn[2], pass_classify, j);
    if (rc)
        goto fail_par;
    rc = par_for(run, "isosurface", j->nchunks, pass_count, j);
    if (rc)
        goto fail_par;
    for (size_t c = 0; c < j->nchunks; c++) {
        size_t k = j->counts[c];
        j->counts[c] = nv;
        nv += k;
        j->tri_at[c] = nt;
        nt += j->ntri[c];
        j->cen_at[c] = nc;
        nc += j->ncen[c];
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
    j->cen = rt_malloc((nc ? nc : 1) * CEN_REC * sizeof(uint32_t));
    if (!j->pos || !j->cap || (j->want_normals && !j->nrm) || (sdf && !j->edges) || !j->cen) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu isosurface vertices", nv);
        goto done;
    }
    out->tri = rt_malloc((nt ? nt : 1) * 3 * sizeof(uint32_t));
    if (!out->tri) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu isosurface triangles", nt);
        goto done;
    }
    out->nt = out->cap_t = nt;
    j->tri = out->tri;
    prefault(j->pos, nv * 3 * sizeof(float));
    prefault(j->nrm, nv * 3 * sizeof(float));
    prefault(j->cap, nv);
    prefault(j->tri, nt * 3 * sizeof(uint32_t));
    rc = par_for(run, "isosurface", j->nchunks, pass_build, j);
    if (rc)
        goto fail_par;
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
    if (sdf) {
        root_job R = {sdf->f, sdf->ctx, j, out};
        rc = par_for(run, "isosurface", (nv + VCHUNK - 1) / VCHUNK, pass_root, &R);
        if (rc)
            goto fail_par;
    }
    if (nc) {
        cen_job C = {j, out};
        rc = par_for(run, "isosurface", j->nchunks, pass_centres, &C);
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
    rt_free(j->bits);
    rt_free(j->rowany);
    for (int a = 0; a < 3; a++)
        rt_free(j->crd[a]);
    rt_free(j->counts);
    rt_free(j->nedge);
    rt_free(j->ncen);
    rt_free(j->cen_at);
    rt_free(j->ntri);
    rt_free(j->tri_at);
    rt_free(j->cen);
    if (j->scratch)
        for (int w = 0; w < j->nworkers; w++)
            rt_free(j->scratch[w]);
    rt_free(j->scratch);
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
    /* The sampling is the call's split loop (par.h, docs/scale.md): one z
     * slice a chunk. A shard samples its slices only and extracts nothing
     * (its mesh becomes a partial value that nothing uses); merge places the
     * shards' slices and extracts as a single run does. */
    par_part pp;
    rc = par_part_begin(&pp, run, "isosurface", (size_t)vol.nz, e);
    if (!rc) {
        sample_job s = {f, ctx, &vol};
        if (par_part_for(&pp, "sampling field", pass_sample, &s))
            rc = rt_fail(e, RT_ECANCEL, "field sampling interrupted");
    }
    size_t slice = (size_t)vol.nx * (size_t)vol.ny * sizeof *vol.v;
    if (!rc)
        rc = par_part_rows(&pp, vol.v, slice * (size_t)vol.nz, slice, e);
    if (!rc && pp.mode != PAR_SHARD) {
        mesh_free(out);
        rc = run_iso(&vol, opts, f, ctx, opts->sdf ? &sd : NULL, run, out, e);
    }
    volume_free(&vol);
    return rc;
}
