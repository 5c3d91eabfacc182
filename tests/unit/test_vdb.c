/* test_vdb.c — OpenVDB writer and reader: round trips of asymmetric,
 * sparse and odd-sized volumes, both compression modes, vec3 grids, the
 * layout of the bytes against the format notes in vdb.h, and refusal of
 * corrupt, truncated and unsupported input. (tests/tools/vdb_check.py
 * checks the files with the OpenVDB library itself.) */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vdb.h"

static volume make(int nx, int ny, int nz, const double lo[3], const double hi[3])
{
    volume v;
    rt_error e;
    if (volume_init(&v, nx, ny, nz, lo, hi, &e)) {
        fprintf(stderr, "volume_init: %s\n", e.msg);
        exit(1);
    }
    return v;
}

/* v = x + 10 y + 100 z + 1 (the + 1 keeps voxel 0 non-zero): a flip or a
 * swap of axes changes values. */
static volume asym(int nx, int ny, int nz)
{
    const double lo[3] = {-1, -0.5, 2}, hi[3] = {1.6, 1.3, 3};
    volume v = make(nx, ny, nz, lo, hi);
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < ny; y++)
            for (int x = 0; x < nx; x++)
                *volume_at(&v, x, y, z) = (float)(x + 10 * y + 100 * z + 1);
    return v;
}

static int same(const volume *a, const volume *b)
{
    if (a->nx != b->nx || a->ny != b->ny || a->nz != b->nz || memcmp(a->lo, b->lo, sizeof a->lo) ||
        memcmp(a->hi, b->hi, sizeof a->hi))
        return 0;
    return memcmp(a->v, b->v, (size_t)a->nx * a->ny * a->nz * sizeof(float)) == 0;
}

static uint32_t u32_at(const bytebuf *b, size_t at)
{
    return (uint32_t)b->data[at] | (uint32_t)b->data[at + 1] << 8 | (uint32_t)b->data[at + 2] << 16 |
           (uint32_t)b->data[at + 3] << 24;
}

/* Write then read one float grid; returns 1 if the read volume equals v. */
static int round_trip(const volume *v, int flags, bytebuf *keep)
{
    vdb_grid g = {"density", 1, {v, NULL, NULL}};
    bytebuf b;
    rt_error e;
    if (vdb_to_mem(&g, 1, flags, &b, &e)) {
        fprintf(stderr, "vdb_to_mem: %s\n", e.msg);
        return 0;
    }
    volume r[3];
    int ch = 0;
    rt_code c = vdb_from_mem(b.data, b.len, NULL, 1e9, r, &ch, &e);
    int ok = c == RT_OK && ch == 1 && same(v, &r[0]);
    if (c)
        fprintf(stderr, "vdb_from_mem: %s\n", e.msg);
    else
        volume_free(&r[0]);
    if (keep)
        *keep = b;
    else
        bytebuf_free(&b);
    return ok;
}

static void test_asymmetric(void)
{
    volume v = asym(13, 9, 5);
    bytebuf b;
    CHECK(round_trip(&v, 0, &b), "13×9×5 asymmetric volume, mask compressed");
    /* header: magic "VDB " as int64, format 224, library 10.0, offsets flag,
     * a 36-character UUID with dashes at 8, 13, 18, 23 */
    CHECK(memcmp(b.data, "\x20\x42\x44\x56\0\0\0\0", 8) == 0, "magic");
    CHECK(u32_at(&b, 8) == 224 && u32_at(&b, 12) == 10 && u32_at(&b, 16) == 0, "versions");
    CHECK(b.data[20] == 1, "has grid offsets");
    CHECK(b.data[29] == '-' && b.data[34] == '-' && b.data[39] == '-' && b.data[44] == '-', "uuid dashes");
    CHECK(u32_at(&b, 57) == 0 && u32_at(&b, 61) == 1, "no file metadata, one grid");
    CHECK(u32_at(&b, 65) == 7 && memcmp(b.data + 69, "density", 7) == 0, "grid name");
    CHECK(u32_at(&b, 76) == 16 && memcmp(b.data + 80, "Tree_float_5_4_3", 16) == 0, "grid type");
    /* the same volume gives the same bytes (the UUID is a hash) */
    bytebuf b2;
    vdb_grid g = {"density", 1, {&v, NULL, NULL}};
    rt_error e;
    CHECK(vdb_to_mem(&g, 1, 0, &b2, &e) == RT_OK && b2.len == b.len && memcmp(b.data, b2.data, b.len) == 0,
          "deterministic");
    bytebuf_free(&b2);
    /* uncompressed: every value of every node stored; far larger, same volume */
    bytebuf bu;
    CHECK(round_trip(&v, VDB_UNCOMPRESSED, &bu), "uncompressed round trip");
    CHECK(bu.len > b.len + 4 * (32768 + 4096), "uncompressed stores the internal nodes' values (%zu vs %zu)",
          bu.len, b.len);
    bytebuf_free(&bu);

    *volume_at(&v, 12, 8, 4) = -7.25f;
    CHECK(round_trip(&v, 0, NULL), "negative value at the far corner");
    bytebuf_free(&b);
    volume_free(&v);
}

static void test_sizes(void)
{
    /* sizes not multiples of 8, one voxel, and a volume crossing the
     * 128-voxel lower-node boundary and two upper-node children (x > 4096) */
    int sizes[][3] = {{1, 1, 1}, {8, 8, 8}, {9, 17, 3}, {130, 2, 3}, {4100, 1, 2}};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        volume v = asym(sizes[i][0], sizes[i][1], sizes[i][2]);
        CHECK(round_trip(&v, 0, NULL), "size %d×%d×%d", sizes[i][0], sizes[i][1], sizes[i][2]);
        volume_free(&v);
    }
}

static void test_sparse(void)
{
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 2, 3};
    volume v = make(64, 64, 64, lo, hi);
    *volume_at(&v, 0, 0, 0) = 1;
    *volume_at(&v, 63, 5, 40) = 2;
    *volume_at(&v, 20, 63, 63) = 0.5f;
    bytebuf b;
    CHECK(round_trip(&v, 0, &b), "sparse 64³ with 3 voxels");
    /* the upper node's two 4 KiB masks, 3 lower nodes' 1 KiB of masks, 3
     * leaves: far below the 1 MiB of the dense volume */
    CHECK(b.len < 12000, "sparse file is small (%zu bytes)", b.len);
    bytebuf_free(&b);
    /* all zero: no leaves at all, the box kept by frac's metadata */
    memset(v.v, 0, 64 * 64 * 64 * sizeof(float));
    CHECK(round_trip(&v, 0, NULL), "empty volume");
    volume_free(&v);
}

static void test_vec3_and_names(void)
{
    volume r = asym(10, 3, 2), g = asym(10, 3, 2), bl = asym(10, 3, 2), d = asym(5, 6, 7);
    for (int i = 0; i < 60; i++) {
        g.v[i] = -g.v[i];
        bl.v[i] = (float)(i % 3 == 0);
    }
    vdb_grid grids[3] = {{"temperature", 1, {&d, NULL, NULL}},
                         {"color", 3, {&r, &g, &bl}},
                         {"density", 1, {&r, NULL, NULL}}};
    bytebuf b;
    rt_error e;
    CHECK(vdb_to_mem(grids, 3, 0, &b, &e) == RT_OK, "three grids: %s", e.msg);
    volume o[3];
    int ch;
    CHECK(vdb_from_mem(b.data, b.len, NULL, 1e9, o, &ch, &e) == RT_OK && ch == 1 && same(&o[0], &r),
          "default grid is density");
    if (ch)
        volume_free(&o[0]);
    CHECK(vdb_from_mem(b.data, b.len, "temperature", 1e9, o, &ch, &e) == RT_OK && ch == 1 && same(&o[0], &d),
          "named grid");
    if (ch)
        volume_free(&o[0]);
    CHECK(vdb_from_mem(b.data, b.len, "color", 1e9, o, &ch, &e) == RT_OK && ch == 3 && same(&o[0], &r) &&
              same(&o[1], &g) && same(&o[2], &bl),
          "vec3 grid");
    for (int c = 0; c < ch; c++)
        volume_free(&o[c]);
    CHECK(vdb_from_mem(b.data, b.len, "smoke", 1e9, o, &ch, &e) == RT_EFORMAT &&
              strcmp(e.msg, "the .vdb file has no grid 'smoke' (it has 'temperature', 'color', 'density')") == 0,
          "missing grid: %s", e.msg);
    bytebuf_free(&b);
    vdb_grid dup[2] = {{"density", 1, {&d, NULL, NULL}}, {"density", 1, {&r, NULL, NULL}}};
    CHECK(vdb_to_mem(dup, 2, 0, &b, &e) == RT_EINVAL && strcmp(e.msg, "two grids are named 'density'") == 0,
          "duplicate names: %s", e.msg);
    vdb_grid odd = {"color", 3, {&r, &g, &d}};
    CHECK(vdb_to_mem(&odd, 1, 0, &b, &e) == RT_EINVAL, "vec3 of unequal volumes");
    volume_free(&r);
    volume_free(&g);
    volume_free(&bl);
    volume_free(&d);
}

static uint64_t u64_at(const bytebuf *b, size_t at) { return u32_at(b, at) | (uint64_t)u32_at(b, at + 4) << 32; }

static void put32(bytebuf *b, size_t at, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b->data[at + (size_t)i] = (unsigned char)(v >> (8 * i));
}

/* Expect reading d to fail with code and exactly msg (NULL: any message). */
static void refuse(const unsigned char *d, size_t n, rt_code code, const char *msg, const char *what)
{
    volume o[3];
    int ch = 0;
    rt_error e = {RT_OK, ""};
    rt_code c = vdb_from_mem(d, n, NULL, 1e9, o, &ch, &e);
    CHECK(c == code && (!msg || strcmp(e.msg, msg) == 0), "%s: code %d, message '%s'", what, (int)c, e.msg);
    for (int k = 0; k < ch; k++)
        volume_free(&o[k]);
}

static void test_refusals(void)
{
    volume v = asym(13, 9, 5);
    vdb_grid g = {"density", 1, {&v, NULL, NULL}};
    bytebuf b;
    rt_error e;
    CHECK(vdb_to_mem(&g, 1, 0, &b, &e) == RT_OK, "write");
    /* every truncation fails cleanly */
    int bad = 0;
    for (size_t n = 0; n < b.len; n++) {
        volume o[3];
        int ch = 0;
        if (vdb_from_mem(b.data, n, NULL, 1e9, o, &ch, &e) != RT_EFORMAT) {
            bad++;
            for (int k = 0; k < ch; k++)
                volume_free(&o[k]);
        }
    }
    CHECK(bad == 0, "%d truncations of %zu were not refused", bad, b.len);
    refuse(b.data, b.len - 1, RT_EFORMAT, NULL, "one byte short");
    /* flipped bytes anywhere: an error or a volume, never a crash (ASan) */
    unsigned char *c = malloc(b.len);
    uint32_t s = 12345;
    for (int t = 0; t < 3000; t++) {
        memcpy(c, b.data, b.len);
        for (int k = 0; k < 3; k++) {
            s = s * 1103515245u + 12345u;
            c[(s >> 8) % b.len] ^= (unsigned char)(1u << (s >> 28 & 7));
        }
        volume o[3];
        int ch = 0;
        /* a small voxel limit: a flipped origin must not make a huge allocation */
        if (vdb_from_mem(c, b.len, NULL, 1e6, o, &ch, &e) == RT_OK)
            for (int k = 0; k < ch; k++)
                volume_free(&o[k]);
    }
    free(c);

    bytebuf m;
    bytebuf_init(&m);
    bytebuf_append(&m, b.data, b.len);
    m.data[0] = 'X';
    refuse(m.data, m.len, RT_EFORMAT, "not an OpenVDB file (no 'VDB ' magic number)", "magic");
    memcpy(m.data, b.data, b.len);
    put32(&m, 8, 221);
    refuse(m.data, m.len, RT_EFORMAT, "OpenVDB file format version 221 is not supported (frac reads 222 to 225)",
           "old version");
    put32(&m, 8, 226);
    refuse(m.data, m.len, RT_EFORMAT, "OpenVDB file format version 226 is not supported (frac reads 222 to 225)",
           "new version");
    memcpy(m.data, b.data, b.len);
    m.data[20] = 0;
    refuse(m.data, m.len, RT_EFORMAT,
           "the .vdb file was written as a stream without grid offsets (not supported)", "stream");
    memcpy(m.data, b.data, b.len);
    memcpy(m.data + 85, "int32", 5); /* Tree_float_5_4_3 -> Tree_int32_5_4_3 */
    refuse(m.data, m.len, RT_EFORMAT,
           "grid 'density' has type Tree_int32_5_4_3; frac reads Tree_float_5_4_3 and Tree_vec3s_5_4_3 grids",
           "grid type");
    size_t grid_pos = (size_t)u64_at(&b, 100);
    CHECK(u32_at(&b, grid_pos) == 2, "compression word: active mask only");
    memcpy(m.data, b.data, b.len);
    put32(&m, grid_pos, 3);
    refuse(m.data, m.len, RT_EFORMAT,
           "grid 'density' is compressed with zip; frac reads .vdb files saved without zip or blosc",
           "zip");
    put32(&m, grid_pos, 6);
    refuse(m.data, m.len, RT_EFORMAT,
           "grid 'density' is compressed with blosc; frac reads .vdb files saved without zip or blosc",
           "blosc");
    memcpy(m.data, b.data, b.len);
    put32(&m, 100, (uint32_t)b.len + 1); /* grid offset past the end */
    refuse(m.data, m.len, RT_EFORMAT, "grid 'density' has offsets outside the file (corrupt file?)", "offsets");
    /* the voxel limit is checked before allocating */
    volume o[3];
    int ch;
    CHECK(vdb_from_mem(b.data, b.len, NULL, 100, o, &ch, &e) == RT_EINVAL &&
              strcmp(e.msg, "grid 'density' spans 13×9×5 voxels, more than the limit of 100") == 0,
          "limit: %s", e.msg);
    bytebuf_free(&m);

    /* half floats: the type name gains "_HalfFloat" (10 bytes), so every
     * offset after it moves by 10 */
    bytebuf h;
    bytebuf_init(&h);
    bytebuf_append(&h, b.data, 76);
    bytebuf_u32le(&h, 26);
    bytebuf_append(&h, "Tree_float_5_4_3_HalfFloat", 26);
    bytebuf_append(&h, b.data + 96, b.len - 96);
    for (int k = 0; k < 3; k++) {
        uint64_t p = u64_at(&h, 110 + 8 * (size_t)k) + 10;
        put32(&h, 110 + 8 * (size_t)k, (uint32_t)p);
    }
    refuse(h.data, h.len, RT_EFORMAT, "grid 'density' is stored as half floats (not supported)", "half");
    bytebuf_free(&h);
    bytebuf_free(&b);

    /* writer refusals */
    vdb_grid none = {"", 1, {&v, NULL, NULL}};
    CHECK(vdb_to_mem(&none, 1, 0, &b, &e) == RT_EINVAL && strcmp(e.msg, "a grid name must be 1 to 255 bytes") == 0,
          "empty name: %s", e.msg);
    CHECK(vdb_to_mem(&g, 0, 0, &b, &e) == RT_EINVAL, "no grids");
    volume_free(&v);
}

int main(void)
{
    test_refusals();
    test_asymmetric();
    test_sizes();
    test_sparse();
    test_vec3_and_names();
    return check_done("test_vdb");
}
