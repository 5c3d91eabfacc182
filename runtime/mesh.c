/* mesh.c — growable triangle mesh and its topology statistics. */
#include "mesh.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void mesh_init(mesh *m, int with_normals, int with_colours)
{
    memset(m, 0, sizeof *m);
    /* A non-NULL sentinel marks the attribute as present until the first
     * vertex allocates the real array. */
    m->nrm = with_normals ? rt_malloc(3 * sizeof(float)) : NULL;
    m->col = with_colours ? rt_malloc(4 * sizeof(float)) : NULL;
    if ((with_normals && !m->nrm) || (with_colours && !m->col))
        m->failed = 1;
}

void mesh_free(mesh *m)
{
    rt_free(m->pos);
    rt_free(m->nrm);
    rt_free(m->col);
    rt_free(m->tri);
    memset(m, 0, sizeof *m);
}

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t nc = *cap ? *cap : 64;
    while (nc < need)
        nc *= 2;
    void *np = rt_realloc(*p, rt_mul_size(nc, elem));
    if (!np)
        return -1;
    *p = np;
    *cap = nc;
    return 0;
}

uint32_t mesh_add_vertex(mesh *m, const float p[3], const float n[3], const float c[4])
{
    if (m->failed || m->nv >= UINT32_MAX - 1)
        goto fail;
    if (m->nv + 1 > m->cap_v) {
        size_t cap = m->cap_v, c2 = m->cap_v, c3 = m->cap_v;
        if (grow((void **)&m->pos, &cap, m->nv + 1, 3 * sizeof(float)))
            goto fail;
        if (m->nrm && grow((void **)&m->nrm, &c2, m->nv + 1, 3 * sizeof(float)))
            goto fail;
        if (m->col && grow((void **)&m->col, &c3, m->nv + 1, 4 * sizeof(float)))
            goto fail;
        m->cap_v = cap;
    }
    size_t i = m->nv++;
    memcpy(m->pos + 3 * i, p, 3 * sizeof(float));
    if (m->nrm) {
        if (n)
            memcpy(m->nrm + 3 * i, n, 3 * sizeof(float));
        else
            memset(m->nrm + 3 * i, 0, 3 * sizeof(float));
    }
    if (m->col) {
        static const float white[4] = {1, 1, 1, 1};
        memcpy(m->col + 4 * i, c ? c : white, 4 * sizeof(float));
    }
    return (uint32_t)i;
fail:
    m->failed = 1;
    return UINT32_MAX;
}

void mesh_add_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    if (m->failed)
        return;
    if (grow((void **)&m->tri, &m->cap_t, m->nt + 1, 3 * sizeof(uint32_t))) {
        m->failed = 1;
        return;
    }
    uint32_t *t = m->tri + 3 * m->nt++;
    t[0] = a;
    t[1] = b;
    t[2] = c;
}

/* Edges are keyed (min, max) in an open-addressing hash table. */
typedef struct edge_slot {
    uint64_t key; /* (lo << 32 | hi) + 1, 0 = empty */
    uint32_t count;
} edge_slot;

rt_code mesh_compute_stats(const mesh *m, mesh_stats *st, rt_error *e)
{
    memset(st, 0, sizeof *st);
    st->triangles = m->nt;
    size_t cap = 16;
    while (cap < m->nt * 6 + 16)
        cap *= 2;
    edge_slot *tab = rt_calloc(cap, sizeof *tab);
    unsigned char *used = rt_calloc(m->nv ? m->nv : 1, 1);
    if (!tab || !used) {
        rt_free(tab);
        rt_free(used);
        return rt_fail(e, RT_ENOMEM, "out of memory computing mesh statistics");
    }
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *v = m->tri + 3 * t;
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            st->degenerate++;
        } else {
            const float *a = m->pos + 3 * v[0], *b = m->pos + 3 * v[1], *c = m->pos + 3 * v[2];
            double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
            double ar = 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (ar == 0)
                st->degenerate++;
            st->area += ar;
            /* a·(b×c)/6: the signed volume of the tetrahedron (0, a, b, c) */
            double bc[3] = {(double)b[1] * c[2] - (double)b[2] * c[1], (double)b[2] * c[0] - (double)b[0] * c[2],
                            (double)b[0] * c[1] - (double)b[1] * c[0]};
            st->volume += (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6;
        }
        for (int k = 0; k < 3; k++) {
            uint32_t a = v[k], b = v[(k + 1) % 3];
            used[a] = used[b] = 1;
            uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            uint64_t key = ((lo << 32) | hi) + 1;
            size_t h = (size_t)((key * 0x9e3779b97f4a7c15ull) >> 20) & (cap - 1);
            while (tab[h].key && tab[h].key != key)
                h = (h + 1) & (cap - 1);
            tab[h].key = key;
            tab[h].count++;
        }
    }
    for (size_t i = 0; i < cap; i++) {
        if (!tab[i].key)
            continue;
        st->edges++;
        if (tab[i].count == 1)
            st->boundary_edges++;
        else if (tab[i].count > 2)
            st->nonmanifold_edges++;
    }
    for (size_t i = 0; i < m->nv; i++)
        st->vertices += used[i];
    st->euler = (long)st->vertices - (long)st->edges + (long)st->triangles;
    rt_free(tab);
    rt_free(used);
    return RT_OK;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

rt_code mesh_orient_outward(mesh *m, int *closed, rt_error *e)
{
    *closed = 0;
    size_t ne = rt_mul_size(m->nt, 3);
    uint64_t *d = rt_mallocn(ne ? ne : 1, sizeof *d);
    if (!d)
        return rt_fail(e, RT_ENOMEM, "out of memory checking the orientation");
    for (size_t t = 0; t < m->nt; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->tri[3 * t + (size_t)k], b = m->tri[3 * t + (size_t)(k + 1) % 3];
            d[3 * t + (size_t)k] = a << 32 | b;
        }
    qsort(d, ne, sizeof *d, cmp_u64);
    int all_paired = ne > 0;
    for (size_t i = 0; i < ne; i++) {
        if (i + 1 < ne && d[i + 1] == d[i]) {
            unsigned a = (unsigned)(d[i] >> 32), b = (unsigned)(d[i] & 0xffffffffu);
            rt_free(d);
            return rt_fail(e, RT_EINVAL,
                           "the edge from vertex %u to vertex %u is used twice in the same direction (faces must all "
                           "wind the same way, and an edge may join at most two faces)",
                           a, b);
        }
        uint64_t rev = (d[i] & 0xffffffffu) << 32 | d[i] >> 32;
        if (all_paired && !bsearch(&rev, d, ne, sizeof *d, cmp_u64))
            all_paired = 0;
    }
    rt_free(d);
    if (!all_paired)
        return RT_OK;
    *closed = 1;
    double vol = 0;
    for (size_t t = 0; t < m->nt; t++) {
        const float *p = m->pos + 3 * (size_t)m->tri[3 * t], *q = m->pos + 3 * (size_t)m->tri[3 * t + 1],
                    *r = m->pos + 3 * (size_t)m->tri[3 * t + 2];
        vol += (double)p[0] * ((double)q[1] * r[2] - (double)q[2] * r[1]) -
               (double)p[1] * ((double)q[0] * r[2] - (double)q[2] * r[0]) +
               (double)p[2] * ((double)q[0] * r[1] - (double)q[1] * r[0]);
    }
    if (vol < 0)
        for (size_t t = 0; t < m->nt; t++) {
            uint32_t x = m->tri[3 * t + 1];
            m->tri[3 * t + 1] = m->tri[3 * t + 2];
            m->tri[3 * t + 2] = x;
        }
    return RT_OK;
}

void mesh_append(mesh *dst, const mesh *src, const float colour[4])
{
    uint32_t base = (uint32_t)dst->nv;
    static const float up[3] = {0, 1, 0};
    for (size_t i = 0; i < src->nv; i++)
        mesh_add_vertex(dst, src->pos + 3 * i, src->nrm ? src->nrm + 3 * i : up, src->col ? src->col + 4 * i : colour);
    for (size_t t = 0; t < src->nt; t++)
        mesh_add_tri(dst, base + src->tri[3 * t], base + src->tri[3 * t + 1], base + src->tri[3 * t + 2]);
}

void mesh_grow_box(const mesh *m, double lo[3], double hi[3])
{
    for (size_t i = 0; i < m->nv; i++)
        for (int d = 0; d < 3; d++) {
            lo[d] = fmin(lo[d], m->pos[3 * i + d]);
            hi[d] = fmax(hi[d], m->pos[3 * i + d]);
        }
}
