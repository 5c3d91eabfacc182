/* vdb.c — OpenVDB writer and reader; the format and its sources are in vdb.h. */
#include "vdb.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rt_alloc.h"

#define VDB_MAGIC 0x56444220u   /* version.h.in OPENVDB_MAGIC, "VDB " */
#define VDB_VERSION 224u        /* OPENVDB_FILE_VERSION of OpenVDB 10 */
#define VDB_VERSION_MIN 222u    /* OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION */
#define VDB_VERSION_MAX 225u    /* OPENVDB_FILE_VERSION_HALF_GRID (adds half grids only) */
#define COMPRESS_ZIP 0x1u       /* io/Compression.h */
#define COMPRESS_ACTIVE_MASK 0x2u
#define COMPRESS_BLOSC 0x4u
#define NO_MASK_OR_INACTIVE_VALS 0 /* io/Compression.h per-node metadata */
#define NO_MASK_AND_ALL_VALS 6

/* Node sizes of the 5-4-3 tree: log2 of the child count per axis, and of
 * the voxels a node spans per axis. */
#define LEAF_LOG2 3
#define LOWER_LOG2 4
#define UPPER_LOG2 5
#define LEAF_TOTAL 3  /* 8 voxels */
#define LOWER_TOTAL 7 /* 128 */
#define UPPER_TOTAL 12 /* 4096 */
#define LEAF_N 512
#define LOWER_N 4096
#define UPPER_N 32768

/* ---- writing --------------------------------------------------------------------------- */

typedef struct wleaf {
    int32_t o[3];          /* origin, multiples of 8 */
    uint64_t mask[LEAF_N / 64];
    int count;             /* active voxels */
} wleaf;

static int leaf_cmp(const void *pa, const void *pb)
{
    /* The order OpenVDB visits leaves: root children by origin (x, y, z),
     * then each internal node's children by offset, x major. */
    const wleaf *a = pa, *b = pb;
    static const int shift[3] = {UPPER_TOTAL, LOWER_TOTAL, LEAF_TOTAL};
    for (int s = 0; s < 3; s++)
        for (int i = 0; i < 3; i++) {
            int32_t x = a->o[i] >> shift[s], y = b->o[i] >> shift[s];
            if (x != y)
                return x < y ? -1 : 1;
        }
    return 0;
}

static void put_str(bytebuf *b, const char *s)
{
    size_t n = strlen(s);
    bytebuf_u32le(b, (uint32_t)n);
    bytebuf_append(b, s, n);
}

static void put_u64(bytebuf *b, uint64_t v)
{
    bytebuf_u32le(b, (uint32_t)v);
    bytebuf_u32le(b, (uint32_t)(v >> 32));
}

static void put_f64(bytebuf *b, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put_u64(b, u);
}

static void put_vec3d(bytebuf *b, const double v[3])
{
    for (int i = 0; i < 3; i++)
        put_f64(b, v[i]);
}

static void meta_head(bytebuf *b, const char *name, const char *type, uint32_t size)
{
    put_str(b, name);
    put_str(b, type);
    bytebuf_u32le(b, size);
}

static void meta_str(bytebuf *b, const char *name, const char *v)
{
    meta_head(b, name, "string", (uint32_t)strlen(v));
    bytebuf_append(b, v, strlen(v));
}

static void meta_vec3i(bytebuf *b, const char *name, const int32_t v[3])
{
    meta_head(b, name, "vec3i", 12);
    for (int i = 0; i < 3; i++)
        bytebuf_u32le(b, (uint32_t)v[i]);
}

static void meta_vec3d(bytebuf *b, const char *name, const double v[3])
{
    meta_head(b, name, "vec3d", 24);
    put_vec3d(b, v);
}

static void meta_i64(bytebuf *b, const char *name, int64_t v)
{
    meta_head(b, name, "int64", 8);
    put_u64(b, (uint64_t)v);
}

static void put_mask(bytebuf *b, const uint64_t *m, size_t words)
{
    for (size_t i = 0; i < words; i++)
        put_u64(b, m[i]);
}

/* An internal node's values (all inactive background 0): the metadata byte,
 * then with mask compression none at all, without it every value. */
static void put_internal_values(bytebuf *b, size_t n, int comps, int mask_compress)
{
    bytebuf_byte(b, mask_compress ? NO_MASK_OR_INACTIVE_VALS : NO_MASK_AND_ALL_VALS);
    if (!mask_compress)
        for (size_t i = 0; i < n * (size_t)comps; i++)
            bytebuf_f32le(b, 0.0f);
}

static float grid_value(const vdb_grid *g, int c, int x, int y, int z)
{
    const volume *v = g->vol[c];
    if (x >= v->nx || y >= v->ny || z >= v->nz)
        return 0.0f;
    return *volume_at(v, x, y, z);
}

static int grid_active(const vdb_grid *g, int x, int y, int z)
{
    for (int c = 0; c < g->channels; c++)
        if (grid_value(g, c, x, y, z) != 0.0f)
            return 1;
    return 0;
}

static rt_code check_grid(const vdb_grid *g, const vdb_grid *all, int k, rt_error *e)
{
    if (!g->name || !g->name[0] || strlen(g->name) > 255)
        return rt_fail(e, RT_EINVAL, "a grid name must be 1 to 255 bytes");
    for (int j = 0; j < k; j++)
        if (strcmp(all[j].name, g->name) == 0)
            return rt_fail(e, RT_EINVAL, "two grids are named '%s'", g->name);
    if (g->channels != 1 && g->channels != 3)
        return rt_fail(e, RT_EINVAL, "grid '%s' has %d channels (1 or 3)", g->name, g->channels);
    const volume *v0 = g->vol[0];
    for (int c = 0; c < g->channels; c++) {
        const volume *v = g->vol[c];
        if (!v || !v->v || v->nx < 1 || v->ny < 1 || v->nz < 1)
            return rt_fail(e, RT_EINVAL, "grid '%s' has an empty volume", g->name);
        if (v->nx != v0->nx || v->ny != v0->ny || v->nz != v0->nz ||
            memcmp(v->lo, v0->lo, sizeof v->lo) || memcmp(v->hi, v0->hi, sizeof v->hi))
            return rt_fail(e, RT_EINVAL, "grid '%s': the 3 volumes of a vec3 grid must have the same size and box",
                           g->name);
        for (int i = 0; i < 3; i++)
            if (!(v->hi[i] > v->lo[i]) || !isfinite(v->hi[i] - v->lo[i]))
                return rt_fail(e, RT_EINVAL, "grid '%s': the volume's box must have lo < hi on every axis",
                               g->name);
    }
    return RT_OK;
}

/* One grid: descriptor, then the grid (compression word, metadata,
 * transform, topology, buffers), with the descriptor's three offsets
 * patched in at the end. */
static rt_code put_grid(bytebuf *b, const vdb_grid *g, int flags, rt_error *e)
{
    const volume *v = g->vol[0];
    int comps = g->channels, mask_compress = !(flags & VDB_UNCOMPRESSED);
    int lx = (v->nx + 7) / 8, ly = (v->ny + 7) / 8, lz = (v->nz + 7) / 8;
    size_t cap = rt_mul_size(rt_mul_size((size_t)lx, (size_t)ly), (size_t)lz);
    wleaf *leaves = cap ? rt_malloc(rt_mul_size(cap, sizeof *leaves)) : NULL;
    if (!leaves)
        return rt_fail(e, RT_ENOMEM, "out of memory for the leaves of grid '%s'", g->name);
    size_t nl = 0;
    int64_t active = 0;
    int32_t bmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, bmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    for (int bz = 0; bz < lz; bz++)
        for (int by = 0; by < ly; by++)
            for (int bx = 0; bx < lx; bx++) {
                wleaf *L = &leaves[nl];
                memset(L, 0, sizeof *L);
                L->o[0] = bx * 8, L->o[1] = by * 8, L->o[2] = bz * 8;
                for (int i = 0; i < LEAF_N; i++) {
                    /* LeafNode::coordToOffset: x << 6 | y << 3 | z */
                    int x = L->o[0] + (i >> 6), y = L->o[1] + ((i >> 3) & 7), z = L->o[2] + (i & 7);
                    if (grid_active(g, x, y, z)) {
                        L->mask[i >> 6] |= (uint64_t)1 << (i & 63);
                        L->count++;
                        int32_t p[3] = {x, y, z};
                        for (int a = 0; a < 3; a++) {
                            if (p[a] < bmin[a]) bmin[a] = p[a];
                            if (p[a] > bmax[a]) bmax[a] = p[a];
                        }
                    }
                }
                if (L->count) {
                    active += L->count;
                    nl++;
                }
            }
    qsort(leaves, nl, sizeof *leaves, leaf_cmp);
    size_t nlower = 0, nupper = 0;
    for (size_t i = 0; i < nl; i++) {
        const int32_t *o = leaves[i].o, *q = i ? leaves[i - 1].o : NULL;
        if (!q || o[0] >> LOWER_TOTAL != q[0] >> LOWER_TOTAL || o[1] >> LOWER_TOTAL != q[1] >> LOWER_TOTAL ||
            o[2] >> LOWER_TOTAL != q[2] >> LOWER_TOTAL)
            nlower++;
        if (!q || o[0] >> UPPER_TOTAL != q[0] >> UPPER_TOTAL || o[1] >> UPPER_TOTAL != q[1] >> UPPER_TOTAL ||
            o[2] >> UPPER_TOTAL != q[2] >> UPPER_TOTAL)
            nupper++;
    }

    /* descriptor (GridDescriptor::writeHeader, writeStreamPos) */
    put_str(b, g->name);
    put_str(b, comps == 1 ? "Tree_float_5_4_3" : "Tree_vec3s_5_4_3");
    put_str(b, ""); /* no instance parent */
    size_t offsets_at = b->len;
    for (int i = 0; i < 3; i++)
        put_u64(b, 0);
    size_t grid_pos = b->len;
    bytebuf_u32le(b, mask_compress ? COMPRESS_ACTIVE_MASK : 0);

    /* metadata, in std::map (strcmp) order of the names */
    double s[3], t[3];
    for (int i = 0; i < 3; i++) {
        int n = i == 0 ? v->nx : i == 1 ? v->ny : v->nz;
        s[i] = (v->hi[i] - v->lo[i]) / n;
        t[i] = v->lo[i] + s[i] / 2;
    }
    int32_t size[3] = {v->nx, v->ny, v->nz};
    /* file_mem_bytes: what OpenVDB would hold in memory for these nodes
     * (values plus masks), informative only. */
    int64_t mem = (int64_t)nl * (LEAF_N * 4 * comps + LEAF_N / 8) +
                  (int64_t)nlower * (LOWER_N * 4 * comps + 2 * LOWER_N / 8) +
                  (int64_t)nupper * (UPPER_N * 4 * comps + 2 * UPPER_N / 8);
    bytebuf_u32le(b, active ? 11 : 9);
    meta_str(b, "class", comps == 1 ? "fog volume" : "unknown");
    meta_str(b, "creator", "frac");
    if (active) {
        meta_vec3i(b, "file_bbox_max", bmax);
        meta_vec3i(b, "file_bbox_min", bmin);
    }
    meta_str(b, "file_compression", mask_compress ? "active values" : "none");
    meta_i64(b, "file_mem_bytes", mem);
    meta_i64(b, "file_voxel_count", active);
    meta_vec3d(b, "frac_hi", v->hi);
    meta_vec3d(b, "frac_lo", v->lo);
    meta_vec3i(b, "frac_size", size);
    meta_str(b, "name", g->name);

    /* transform (Transform::write, ScaleTranslateMap::write) */
    put_str(b, s[0] == s[1] && s[1] == s[2] ? "UniformScaleTranslateMap" : "ScaleTranslateMap");
    double inv[3], inv2[3], half[3];
    for (int i = 0; i < 3; i++) {
        inv[i] = 1.0 / s[i];
        inv2[i] = inv[i] * inv[i];
        half[i] = inv[i] / 2;
    }
    put_vec3d(b, t);
    put_vec3d(b, s);
    put_vec3d(b, s); /* voxel size = |scale|, scale > 0 */
    put_vec3d(b, inv);
    put_vec3d(b, inv2);
    put_vec3d(b, half);

    /* topology: buffer count, root, internal nodes, leaf masks */
    bytebuf_u32le(b, 1);
    for (int c = 0; c < comps; c++)
        bytebuf_f32le(b, 0.0f); /* background */
    bytebuf_u32le(b, 0);        /* tiles */
    bytebuf_u32le(b, (uint32_t)nupper);
    uint64_t *cm = rt_calloc(UPPER_N / 64, sizeof *cm);
    if (!cm) {
        rt_free(leaves);
        return rt_fail(e, RT_ENOMEM, "out of memory writing grid '%s'", g->name);
    }
    static const uint64_t zeros[UPPER_N / 64];
    for (size_t i = 0; i < nl;) {
        /* one upper node: leaves [i, j) */
        size_t j = i;
        int32_t uo[3] = {leaves[i].o[0] >> UPPER_TOTAL << UPPER_TOTAL, leaves[i].o[1] >> UPPER_TOTAL << UPPER_TOTAL,
                         leaves[i].o[2] >> UPPER_TOTAL << UPPER_TOTAL};
        memset(cm, 0, UPPER_N / 8);
        while (j < nl && (leaves[j].o[0] >> UPPER_TOTAL << UPPER_TOTAL) == uo[0] &&
               (leaves[j].o[1] >> UPPER_TOTAL << UPPER_TOTAL) == uo[1] &&
               (leaves[j].o[2] >> UPPER_TOTAL << UPPER_TOTAL) == uo[2]) {
            /* InternalNode::coordToOffset for the 32³ node */
            int off = (((leaves[j].o[0] & 4095) >> LOWER_TOTAL) << 10) |
                      (((leaves[j].o[1] & 4095) >> LOWER_TOTAL) << 5) | ((leaves[j].o[2] & 4095) >> LOWER_TOTAL);
            cm[off >> 6] |= (uint64_t)1 << (off & 63);
            j++;
        }
        for (int a = 0; a < 3; a++)
            bytebuf_u32le(b, (uint32_t)uo[a]);
        put_mask(b, cm, UPPER_N / 64);
        put_mask(b, zeros, UPPER_N / 64);
        put_internal_values(b, UPPER_N, comps, mask_compress);
        for (size_t k = i; k < j;) {
            size_t m = k;
            int32_t lo_[3] = {leaves[k].o[0] >> LOWER_TOTAL, leaves[k].o[1] >> LOWER_TOTAL,
                              leaves[k].o[2] >> LOWER_TOTAL};
            uint64_t lm[LOWER_N / 64] = {0};
            while (m < j && (leaves[m].o[0] >> LOWER_TOTAL) == lo_[0] && (leaves[m].o[1] >> LOWER_TOTAL) == lo_[1] &&
                   (leaves[m].o[2] >> LOWER_TOTAL) == lo_[2]) {
                int off = (((leaves[m].o[0] & 127) >> LEAF_TOTAL) << 8) |
                          (((leaves[m].o[1] & 127) >> LEAF_TOTAL) << 4) | ((leaves[m].o[2] & 127) >> LEAF_TOTAL);
                lm[off >> 6] |= (uint64_t)1 << (off & 63);
                m++;
            }
            put_mask(b, lm, LOWER_N / 64);
            put_mask(b, zeros, LOWER_N / 64);
            put_internal_values(b, LOWER_N, comps, mask_compress);
            for (size_t q = k; q < m; q++)
                put_mask(b, leaves[q].mask, LEAF_N / 64);
            k = m;
        }
        i = j;
    }
    rt_free(cm);
    size_t block_pos = b->len;

    /* buffers: each leaf's mask again, the metadata byte, the values */
    for (size_t i = 0; i < nl; i++) {
        const wleaf *L = &leaves[i];
        put_mask(b, L->mask, LEAF_N / 64);
        bytebuf_byte(b, mask_compress ? NO_MASK_OR_INACTIVE_VALS : NO_MASK_AND_ALL_VALS);
        for (int k = 0; k < LEAF_N; k++) {
            if (mask_compress && !(L->mask[k >> 6] >> (k & 63) & 1))
                continue;
            int x = L->o[0] + (k >> 6), y = L->o[1] + ((k >> 3) & 7), z = L->o[2] + (k & 7);
            for (int c = 0; c < comps; c++)
                bytebuf_f32le(b, grid_value(g, c, x, y, z));
        }
    }
    rt_free(leaves);
    size_t end_pos = b->len;
    if (b->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing grid '%s'", g->name);
    uint64_t pos[3] = {grid_pos, block_pos, end_pos};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 8; k++)
            b->data[offsets_at + 8 * (size_t)i + (size_t)k] = (unsigned char)(pos[i] >> (8 * k));
    return RT_OK;
}

rt_code vdb_to_mem(const vdb_grid *grids, int ngrids, int flags, bytebuf *out, rt_error *e)
{
    bytebuf_init(out);
    if (ngrids < 1)
        return rt_fail(e, RT_EINVAL, "a .vdb file needs at least one grid");
    for (int k = 0; k < ngrids; k++) {
        rt_code c = check_grid(&grids[k], grids, k, e);
        if (c)
            return c;
    }
    /* header (Archive::writeHeader) */
    put_u64(out, VDB_MAGIC);
    bytebuf_u32le(out, VDB_VERSION);
    bytebuf_u32le(out, 10); /* library major */
    bytebuf_u32le(out, 0);  /* library minor */
    bytebuf_byte(out, 1);   /* has grid offsets */
    size_t uuid_at = out->len;
    bytebuf_append(out, "00000000-0000-0000-0000-000000000000", 36);
    bytebuf_u32le(out, 0); /* no file metadata */
    bytebuf_u32le(out, (uint32_t)ngrids);
    for (int k = 0; k < ngrids; k++) {
        rt_code c = put_grid(out, &grids[k], flags, e);
        if (c) {
            bytebuf_free(out);
            return c;
        }
    }
    if (out->failed) {
        bytebuf_free(out);
        return rt_fail(e, RT_ENOMEM, "out of memory building a .vdb file");
    }
    /* The UUID: a hash of the contents (two FNV-1a passes), formatted as a
     * version-4 UUID, so the same volume gives the same file. */
    uint64_t h[2] = {0xcbf29ce484222325u, 0x84222325cbf29ce4u};
    for (size_t i = uuid_at + 36; i < out->len; i++)
        for (int k = 0; k < 2; k++)
            h[k] = (h[k] ^ out->data[i]) * 0x100000001b3u;
    unsigned char u[16];
    for (int i = 0; i < 16; i++)
        u[i] = (unsigned char)(h[i / 8] >> (8 * (i % 8)));
    u[6] = (unsigned char)((u[6] & 0x0f) | 0x40);
    u[8] = (unsigned char)((u[8] & 0x3f) | 0x80);
    static const char hex[] = "0123456789abcdef";
    for (int i = 0, p = 0; i < 16; i++) {
        if (i == 4 || i == 6 || i == 8 || i == 10)
            p++; /* the dash */
        out->data[uuid_at + (size_t)p++] = (unsigned char)hex[u[i] >> 4];
        out->data[uuid_at + (size_t)p++] = (unsigned char)hex[u[i] & 15];
    }
    return RT_OK;
}

rt_code vdb_save(const char *path, const vdb_grid *grids, int ngrids, int flags, rt_error *e)
{
    bytebuf b;
    rt_code c = vdb_to_mem(grids, ngrids, flags, &b, e);
    if (c)
        return c;
    c = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return c;
}

/* ---- reading --------------------------------------------------------------------------- */

typedef struct rd {
    const unsigned char *d;
    size_t n, pos;
    rt_error *e;
    int failed;
} rd;

static int rd_need(rd *r, size_t k)
{
    if (r->failed)
        return 0;
    if (r->pos > r->n || r->n - r->pos < k) {
        r->failed = 1;
        rt_fail(r->e, RT_EFORMAT, "truncated .vdb file (%zu bytes needed at offset %zu of %zu)", k, r->pos, r->n);
        return 0;
    }
    return 1;
}

static uint64_t rd_le(rd *r, int k)
{
    if (!rd_need(r, (size_t)k))
        return 0;
    uint64_t v = 0;
    for (int i = 0; i < k; i++)
        v |= (uint64_t)r->d[r->pos + (size_t)i] << (8 * i);
    r->pos += (size_t)k;
    return v;
}

static uint32_t rd_u32(rd *r) { return (uint32_t)rd_le(r, 4); }

static float rd_f32(rd *r)
{
    uint32_t u = rd_u32(r);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static double rd_f64(rd *r)
{
    uint64_t u = rd_le(r, 8);
    double f;
    memcpy(&f, &u, 8);
    return f;
}

static int rd_fail(rd *r, const char *fmt, ...)
{
    if (!r->failed) {
        va_list ap;
        va_start(ap, fmt);
        r->e->code = RT_EFORMAT;
        vsnprintf(r->e->msg, sizeof r->e->msg, fmt, ap);
        va_end(ap);
    }
    r->failed = 1;
    return -1;
}

/* A string into buf (at most cap-1 bytes; longer ones are refused). */
static int rd_str(rd *r, char *buf, size_t cap)
{
    uint32_t n = rd_u32(r);
    if (r->failed)
        return -1;
    if (n >= cap)
        return rd_fail(r, "a string in the .vdb file is too long (corrupt file?)");
    if (!rd_need(r, n))
        return -1;
    memcpy(buf, r->d + r->pos, n);
    buf[n] = 0;
    r->pos += n;
    return 0;
}

static void rd_mask(rd *r, uint64_t *m, size_t words)
{
    for (size_t i = 0; i < words; i++)
        m[i] = rd_le(r, 8);
}

static int bit(const uint64_t *m, int i) { return (int)(m[i >> 6] >> (i & 63) & 1); }

static int popcount(const uint64_t *m, size_t words)
{
    int c = 0;
    for (size_t i = 0; i < words; i++)
        for (uint64_t w = m[i]; w; w &= w - 1)
            c++;
    return c;
}

/* io::readCompressedValues for n values of comps floats each: the metadata
 * byte, optional inactive values and selection mask, then the values
 * (only the active ones when the grid is mask-compressed). sel is scratch
 * of n/64 words. */
static int rd_values(rd *r, int n, int comps, const uint64_t *mask, int mask_compress, const float *bg,
                     uint64_t *sel, float *out)
{
    int meta = (int)rd_le(r, 1);
    if (r->failed)
        return -1;
    if (meta > NO_MASK_AND_ALL_VALS)
        return rd_fail(r, "unknown node compression mode %d in the .vdb file (corrupt file?)", meta);
    float in0[3], in1[3];
    for (int c = 0; c < comps; c++) {
        in1[c] = bg[c];
        in0[c] = meta == NO_MASK_OR_INACTIVE_VALS ? bg[c] : -bg[c];
    }
    if (meta == 2 || meta == 4 || meta == 5)
        for (int c = 0; c < comps; c++)
            in0[c] = rd_f32(r);
    if (meta == 5)
        for (int c = 0; c < comps; c++)
            in1[c] = rd_f32(r);
    size_t words = (size_t)n / 64;
    memset(sel, 0, words * 8);
    if (meta >= 3 && meta <= 5)
        rd_mask(r, sel, words);
    int count = mask_compress && meta != NO_MASK_AND_ALL_VALS ? popcount(mask, words) : n;
    if (!rd_need(r, (size_t)count * (size_t)comps * 4))
        return -1;
    if (count == n) {
        for (int i = 0; i < n * comps; i++)
            out[i] = rd_f32(r);
        return 0;
    }
    for (int i = 0; i < n; i++)
        for (int c = 0; c < comps; c++)
            out[i * comps + c] = bit(mask, i) ? rd_f32(r) : bit(sel, i) ? in1[c] : in0[c];
    return r->failed ? -1 : 0;
}

typedef struct rleaf {
    int32_t o[3];
    uint64_t mask[LEAF_N / 64];
} rleaf;

typedef struct rgrid {
    rd *r;
    int comps, mask_compress;
    float bg[3];
    rleaf *leaves;
    size_t nl, cap;
    float *scratch;     /* UPPER_N * comps values */
    uint64_t sel[UPPER_N / 64];
} rgrid;

/* An internal node's topology; log2 = 5 or 4. Records leaves. */
static int rd_internal(rgrid *g, int log2, const int32_t o[3])
{
    rd *r = g->r;
    int n = 1 << (3 * log2), child_total = log2 == UPPER_LOG2 ? LOWER_TOTAL : LEAF_TOTAL;
    size_t words = (size_t)n / 64;
    uint64_t *cm = rt_malloc(2 * words * sizeof *cm);
    if (!cm) {
        r->failed = 1;
        rt_fail(r->e, RT_ENOMEM, "out of memory reading a .vdb file");
        return -1;
    }
    uint64_t *vm = cm + words;
    rd_mask(r, cm, words);
    rd_mask(r, vm, words);
    if (r->failed || rd_values(r, n, g->comps, vm, g->mask_compress, g->bg, g->sel, g->scratch)) {
        rt_free(cm);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        if (bit(cm, i))
            continue;
        if (bit(vm, i)) {
            rt_free(cm);
            return rd_fail(r, "the .vdb grid has active tiles (constant regions); frac reads voxels in leaves only");
        }
        for (int c = 0; c < g->comps; c++)
            if (g->scratch[i * g->comps + c] != g->bg[c] && !(isnan(g->scratch[i * g->comps + c]) && isnan(g->bg[c]))) {
                rt_free(cm);
                return rd_fail(r, "the .vdb grid has tiles whose value is not the background; frac reads "
                                  "voxels in leaves only");
            }
    }
    for (int i = 0; i < n && !r->failed; i++) {
        if (!bit(cm, i))
            continue;
        int32_t co[3] = {o[0] + ((i >> (2 * log2)) << child_total), o[1] + (((i >> log2) & ((1 << log2) - 1)) << child_total),
                         o[2] + ((i & ((1 << log2) - 1)) << child_total)};
        if (log2 == UPPER_LOG2) {
            if (rd_internal(g, LOWER_LOG2, co))
                break;
            continue;
        }
        if (g->nl == g->cap) {
            size_t nc = g->cap ? 2 * g->cap : 64;
            rleaf *nv = rt_realloc(g->leaves, nc * sizeof *nv);
            if (!nv) {
                r->failed = 1;
                rt_fail(r->e, RT_ENOMEM, "out of memory reading a .vdb file");
                break;
            }
            g->leaves = nv;
            g->cap = nc;
        }
        rleaf *L = &g->leaves[g->nl++];
        memcpy(L->o, co, sizeof co);
        rd_mask(r, L->mask, LEAF_N / 64);
    }
    rt_free(cm);
    return r->failed ? -1 : 0;
}

typedef struct rmeta {
    int has_size, has_lo, has_hi;
    int32_t size[3];
    double lo[3], hi[3];
    char cls[64];
} rmeta;

static int rd_meta(rd *r, rmeta *m)
{
    uint32_t count = rd_u32(r);
    for (uint32_t i = 0; i < count && !r->failed; i++) {
        char name[256], type[256];
        if (rd_str(r, name, sizeof name) || rd_str(r, type, sizeof type))
            return -1;
        uint32_t size = rd_u32(r);
        if (!rd_need(r, size))
            return -1;
        size_t next = r->pos + size;
        if (strcmp(name, "frac_size") == 0 && strcmp(type, "vec3i") == 0 && size == 12) {
            for (int k = 0; k < 3; k++)
                m->size[k] = (int32_t)rd_u32(r);
            m->has_size = 1;
        } else if ((strcmp(name, "frac_lo") == 0 || strcmp(name, "frac_hi") == 0) && strcmp(type, "vec3d") == 0 &&
                   size == 24) {
            int hi = name[5] == 'h';
            for (int k = 0; k < 3; k++)
                (hi ? m->hi : m->lo)[k] = rd_f64(r);
            *(hi ? &m->has_hi : &m->has_lo) = 1;
        } else if (strcmp(name, "class") == 0 && strcmp(type, "string") == 0 && size < sizeof m->cls) {
            memcpy(m->cls, r->d + r->pos, size);
            m->cls[size] = 0;
        }
        r->pos = next;
    }
    return r->failed ? -1 : 0;
}

/* The transform as world = t + s ⊙ index. */
static int rd_transform(rd *r, double s[3], double t[3])
{
    char type[64];
    if (rd_str(r, type, sizeof type))
        return -1;
    double v[6][3];
    for (int i = 0; i < 3; i++)
        s[i] = 1, t[i] = 0;
    if (strcmp(type, "ScaleTranslateMap") == 0 || strcmp(type, "UniformScaleTranslateMap") == 0 ||
        strcmp(type, "ScaleMap") == 0 || strcmp(type, "UniformScaleMap") == 0) {
        int translate = strstr(type, "Translate") != NULL, nv = translate ? 6 : 5;
        for (int k = 0; k < nv; k++)
            for (int i = 0; i < 3; i++)
                v[k][i] = rd_f64(r);
        for (int i = 0; i < 3; i++) {
            t[i] = translate ? v[0][i] : 0;
            s[i] = v[translate][i];
        }
    } else if (strcmp(type, "TranslationMap") == 0) {
        for (int i = 0; i < 3; i++)
            t[i] = rd_f64(r);
    } else if (strcmp(type, "AffineMap") == 0) {
        double m[4][4]; /* row-vector convention: translation in row 3 */
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++)
                m[i][j] = rd_f64(r);
        for (int i = 0; i < 4 && !r->failed; i++)
            for (int j = 0; j < 4; j++)
                if (i != j && !(i == 3 && j < 3) && m[i][j] != 0)
                    return rd_fail(r, "the .vdb grid's AffineMap rotates or shears; frac reads axis-aligned "
                                      "transforms only");
        for (int i = 0; i < 3; i++) {
            s[i] = m[i][i];
            t[i] = m[3][i];
        }
    } else {
        return rd_fail(r, "the .vdb grid's transform is a %s; frac reads scale and translation maps only", type);
    }
    if (r->failed)
        return -1;
    for (int i = 0; i < 3; i++)
        if (!(s[i] > 0) || !isfinite(s[i]) || !isfinite(t[i]))
            return rd_fail(r, "the .vdb grid's transform has a voxel size that is not positive and finite");
    return 0;
}

static int64_t pos_of(rd *r)
{
    uint64_t v = rd_le(r, 8);
    return v > (uint64_t)INT64_MAX ? -1 : (int64_t)v;
}

static rt_code rd_grid(rd *r, size_t grid_pos, int comps, const char *gname, double max_voxels, volume out[3])
{
    r->pos = grid_pos;
    uint32_t comp = rd_u32(r);
    if (r->failed)
        return r->e->code;
    if (comp & (COMPRESS_ZIP | COMPRESS_BLOSC))
        return rt_fail(r->e, RT_EFORMAT,
                       "grid '%s' is compressed with %s; frac reads .vdb files saved without zip or blosc",
                       gname, comp & COMPRESS_BLOSC ? "blosc" : "zip");
    if (comp & ~7u)
        return rt_fail(r->e, RT_EFORMAT, "grid '%s' has unknown compression flags 0x%x", gname, comp);
    rmeta m;
    memset(&m, 0, sizeof m);
    double s[3], t[3];
    if (rd_meta(r, &m) || rd_transform(r, s, t))
        return r->e->code;
    if (rd_u32(r) != 1 && !r->failed)
        return rt_fail(r->e, RT_EFORMAT, "grid '%s' has several buffers per node (not supported)", gname);
    rgrid g;
    memset(&g, 0, sizeof g);
    g.r = r;
    g.comps = comps;
    g.mask_compress = (comp & COMPRESS_ACTIVE_MASK) != 0;
    for (int c = 0; c < comps; c++)
        g.bg[c] = rd_f32(r);
    uint32_t ntiles = rd_u32(r), nchildren = rd_u32(r);
    if (r->failed)
        return r->e->code;
    /* root tiles: only inactive background tiles are accepted */
    for (uint32_t i = 0; i < ntiles && !r->failed; i++) {
        r->pos += 12;
        int bad = 0;
        for (int c = 0; c < comps; c++)
            bad |= rd_f32(r) != g.bg[c];
        bad |= rd_le(r, 1) != 0;
        if (bad && !r->failed)
            return rt_fail(r->e, RT_EFORMAT, "grid '%s' has tiles (constant regions); frac reads voxels in leaves only",
                           gname);
    }
    g.scratch = rt_malloc((size_t)UPPER_N * (size_t)comps * sizeof *g.scratch);
    if (!g.scratch)
        return rt_fail(r->e, RT_ENOMEM, "out of memory reading grid '%s'", gname);
    int32_t prev[3] = {0, 0, 0};
    for (uint32_t i = 0; i < nchildren && !r->failed; i++) {
        int32_t o[3];
        for (int k = 0; k < 3; k++)
            o[k] = (int32_t)rd_u32(r);
        if (r->failed)
            break;
        if ((o[0] | o[1] | o[2]) & 4095) {
            rd_fail(r, "grid '%s' has a root child whose origin is not a multiple of 4096 (corrupt file?)", gname);
            break;
        }
        if (i > 0 && !(o[0] > prev[0] || (o[0] == prev[0] && (o[1] > prev[1] || (o[1] == prev[1] && o[2] > prev[2]))))) {
            rd_fail(r, "grid '%s': the root's children are not in coordinate order (corrupt file?)", gname);
            break;
        }
        memcpy(prev, o, sizeof o);
        if (rd_internal(&g, UPPER_LOG2, o))
            break;
    }
    rt_code code = RT_OK;
    if (r->failed) {
        code = r->e->code;
        goto done;
    }
    /* the box: frac's metadata when it agrees with the transform, else the
     * active voxels' bounding box */
    int64_t imin[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, imax[3] = {INT64_MIN, INT64_MIN, INT64_MIN};
    for (size_t i = 0; i < g.nl; i++)
        for (int k = 0; k < LEAF_N; k++)
            if (bit(g.leaves[i].mask, k)) {
                int64_t p[3] = {g.leaves[i].o[0] + (k >> 6), g.leaves[i].o[1] + ((k >> 3) & 7), g.leaves[i].o[2] + (k & 7)};
                for (int a = 0; a < 3; a++) {
                    if (p[a] < imin[a]) imin[a] = p[a];
                    if (p[a] > imax[a]) imax[a] = p[a];
                }
            }
    int64_t dims[3], base[3];
    double lo[3], hi[3];
    int frac_box = m.has_size && m.has_lo && m.has_hi;
    for (int a = 0; a < 3 && frac_box; a++) {
        double sa = (m.hi[a] - m.lo[a]) / m.size[a];
        double tol = 1e-9 * fabs(sa);
        if (m.size[a] < 1 || !(m.hi[a] > m.lo[a]) || !(fabs(sa - s[a]) <= tol) ||
            !(fabs(m.lo[a] + sa / 2 - t[a]) <= tol + 1e-12 * fabs(t[a])))
            frac_box = 0;
    }
    for (int a = 0; a < 3; a++) {
        if (frac_box) {
            base[a] = 0;
            dims[a] = m.size[a];
            lo[a] = m.lo[a];
            hi[a] = m.hi[a];
        } else {
            if (imin[a] > imax[a]) {
                code = rt_fail(r->e, RT_EFORMAT, "grid '%s' has no active voxels, so its extent is unknown", gname);
                goto done;
            }
            base[a] = imin[a];
            dims[a] = imax[a] - imin[a] + 1;
            lo[a] = t[a] + s[a] * ((double)imin[a] - 0.5);
            hi[a] = lo[a] + s[a] * (double)dims[a];
        }
    }
    double voxels = (double)dims[0] * (double)dims[1] * (double)dims[2];
    if (dims[0] > INT32_MAX || dims[1] > INT32_MAX || dims[2] > INT32_MAX || voxels > max_voxels) {
        code = rt_fail(r->e, RT_EINVAL, "grid '%s' spans %lld×%lld×%lld voxels, more than the limit of %.0f",
                       gname, (long long)dims[0], (long long)dims[1], (long long)dims[2], max_voxels);
        goto done;
    }
    for (int c = 0; c < comps; c++) {
        code = volume_init(&out[c], (int)dims[0], (int)dims[1], (int)dims[2], lo, hi, r->e);
        if (code) {
            for (int k = 0; k < c; k++)
                volume_free(&out[k]);
            goto done;
        }
        if (g.bg[c] != 0)
            for (size_t k = 0; k < (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2]; k++)
                out[c].v[k] = g.bg[c];
    }
    /* buffers, in the topology's order */
    for (size_t i = 0; i < g.nl && !r->failed; i++) {
        const rleaf *L = &g.leaves[i];
        uint64_t skip[LEAF_N / 64];
        rd_mask(r, skip, LEAF_N / 64); /* the same mask again; OpenVDB uses the topology's */
        if (rd_values(r, LEAF_N, comps, L->mask, g.mask_compress, g.bg, g.sel, g.scratch))
            break;
        for (int k = 0; k < LEAF_N; k++) {
            int64_t p[3] = {L->o[0] + (k >> 6) - base[0], L->o[1] + ((k >> 3) & 7) - base[1],
                            L->o[2] + (k & 7) - base[2]};
            int inside = p[0] >= 0 && p[0] < dims[0] && p[1] >= 0 && p[1] < dims[1] && p[2] >= 0 && p[2] < dims[2];
            if (!inside) {
                if (bit(L->mask, k)) {
                    rd_fail(r, "grid '%s' has active voxels outside its frac_size box (corrupt file?)", gname);
                    break;
                }
                continue;
            }
            for (int c = 0; c < comps; c++)
                *volume_at(&out[c], (int)p[0], (int)p[1], (int)p[2]) = g.scratch[k * comps + c];
        }
    }
    if (r->failed) {
        code = r->e->code;
        for (int c = 0; c < comps; c++)
            volume_free(&out[c]);
    }
done:
    rt_free(g.scratch);
    rt_free(g.leaves);
    return code;
}

rt_code vdb_from_mem(const unsigned char *d, size_t n, const char *name, double max_voxels, volume out[3],
                     int *channels, rt_error *e)
{
    rt_error scratch;
    if (!e)
        e = &scratch;
    rd r = {d, n, 0, e, 0};
    *channels = 0;
    if (n < 8 || rd_le(&r, 8) != VDB_MAGIC)
        return rt_fail(e, RT_EFORMAT, "not an OpenVDB file (no 'VDB ' magic number)");
    uint32_t version = rd_u32(&r);
    if (r.failed)
        return e->code;
    if (version < VDB_VERSION_MIN || version > VDB_VERSION_MAX)
        return rt_fail(e, RT_EFORMAT, "OpenVDB file format version %u is not supported (frac reads %u to %u)",
                       version, VDB_VERSION_MIN, VDB_VERSION_MAX);
    r.pos += 8; /* library version */
    int offsets = (int)rd_le(&r, 1);
    r.pos += 36; /* UUID */
    if (r.failed)
        return e->code;
    if (!offsets)
        return rt_fail(e, RT_EFORMAT, "the .vdb file was written as a stream without grid offsets (not supported)");
    rmeta fm;
    memset(&fm, 0, sizeof fm);
    if (rd_meta(&r, &fm))
        return e->code;
    uint32_t ngrids = rd_u32(&r);
    if (r.failed)
        return e->code;
    char names[512] = "";
    int nfound = 0;
    size_t only_pos = 0;
    int only_comps = 0;
    char only_name[256] = "";
    for (uint32_t i = 0; i < ngrids; i++) {
        char gname[256], type[256], parent[256];
        if (rd_str(&r, gname, sizeof gname) || rd_str(&r, type, sizeof type))
            return e->code;
        if (rd_str(&r, parent, sizeof parent)) /* instance parent (format >= 216) */
            return e->code;
        int64_t gpos = pos_of(&r), bpos = pos_of(&r), epos = pos_of(&r);
        if (r.failed)
            return e->code;
        if (gpos < 0 || epos < gpos || bpos < gpos || (uint64_t)epos > n || (uint64_t)gpos < r.pos)
            return rt_fail(e, RT_EFORMAT, "grid '%s' has offsets outside the file (corrupt file?)", gname);
        /* a '\x1e' suffix makes duplicate names unique (GridDescriptor::addSuffix) */
        char *sfx = strchr(gname, 0x1e);
        if (sfx)
            *sfx = 0;
        if (strlen(names) + strlen(gname) + 4 < sizeof names)
            snprintf(names + strlen(names), sizeof names - strlen(names), "%s'%s'", i ? ", " : "", gname);
        int want = name ? strcmp(gname, name) == 0 : strcmp(gname, "density") == 0;
        if (want || (!name && ngrids == 1)) {
            size_t tl = strlen(type);
            if (tl > 10 && strcmp(type + tl - 10, "_HalfFloat") == 0)
                return rt_fail(e, RT_EFORMAT, "grid '%s' is stored as half floats (not supported)", gname);
            int comps = strcmp(type, "Tree_float_5_4_3") == 0 ? 1 : strcmp(type, "Tree_vec3s_5_4_3") == 0 ? 3 : 0;
            if (!comps)
                return rt_fail(e, RT_EFORMAT,
                               "grid '%s' has type %s; frac reads Tree_float_5_4_3 and Tree_vec3s_5_4_3 grids",
                               gname, type);
            if (parent[0])
                return rt_fail(e, RT_EFORMAT, "grid '%s' is an instance of grid '%s' (not supported)", gname,
                               parent);
            if (want || !nfound) {
                only_pos = (size_t)gpos;
                only_comps = comps;
                snprintf(only_name, sizeof only_name, "%s", gname);
                nfound = 1;
                if (want)
                    break;
            }
        }
        r.pos = (size_t)epos;
    }
    if (!nfound) {
        if (name)
            return rt_fail(e, RT_EFORMAT, "the .vdb file has no grid '%s' (it has %s)", name,
                           ngrids ? names : "no grids");
        return rt_fail(e, RT_EFORMAT, "the .vdb file has no grid 'density' (it has %s): name the grid to read",
                       ngrids ? names : "no grids");
    }
    rt_code c = rd_grid(&r, only_pos, only_comps, only_name, max_voxels, out);
    if (c == RT_OK)
        *channels = only_comps;
    return c;
}

rt_code vdb_load(const char *path, const char *name, double max_voxels, volume out[3], int *channels,
                 rt_error *e)
{
    unsigned char *d;
    size_t n;
    rt_code c = fileio_read_all(path, (size_t)1 << 40, &d, &n, e);
    if (c)
        return c;
    c = vdb_from_mem(d, n, name, max_voxels, out, channels, e);
    rt_free(d);
    return c;
}
