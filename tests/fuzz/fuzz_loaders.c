/* fuzz_loaders.c — libFuzzer harnesses for the file decoders, calling the
 * runtime directly (no interpreter). One source, one binary per format:
 * built with -DFUZZ_LOADER=NAME, NAME one of
 *   png      png_decode (CRCs and the zlib Adler-32 are repaired first, so
 *            mutations reach the filters and the interlace code)
 *   inflate  inflate_zlib and inflate_raw on the raw bytes
 *   pnm      pnm_decode and pfm_decode (P5, P6, PF, Pf)
 *   ifs      fractint_parse (Fractint .ifs text)
 *   nrrd     vio_nrrd_from_mem (attached data only: dir NULL)
 *   vtk      vio_vtk_from_mem
 *   ply      mio_ply_from_mem (binary and ASCII)
 *   obj      mio_obj_from_mem
 *   stl      mio_stl_from_mem
 * Oracles beyond "no crash, no sanitizer report, no leak": a decoded image,
 * volume or mesh is checked for consistency (sizes, triangle indices in
 * range), images are re-encoded to 16-bit PNG and decoded back within
 * 1/65535, volumes to float NRRD and back bit-exactly, meshes to binary PLY
 * and back with the same counts.
 *
 * Known: a PNG may declare up to PNG_MAX_DIM² pixels and decode them from a
 * few KB (issue 11, memory work); the harness skips headers over 2^18
 * pixels so the campaign is not all out-of-memory reports. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rt_alloc.h"
#include "deflate.h"
#include "fractint.h"
#include "mesh.h"
#include "mesh_io.h"
#include "png.h"
#include "pnm.h"
#include "volume_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define STR2(x) #x
#define STR(x) STR2(x)
static const char *const loader = STR(FUZZ_LOADER);

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_loaders (%s): oracle failed: %s\n", loader, what);
    abort();
}

/* ---- oracles ---------------------------------------------------------- */

static void check_image(const image *im)
{
    if (im->w < 1 || im->h < 1 || !im->px)
        fail("decoded image has no pixels");
    if ((double)im->w * im->h > 4096)
        return;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    image back = {0, 0, NULL};
    if (png_encode(im, 16, 4, &b, &e) == RT_OK) {
        if (png_decode(b.data, b.len, &back, NULL, &e) != RT_OK)
            fail("16-bit PNG of a decoded image does not decode");
        if (back.w != im->w || back.h != im->h)
            fail("PNG round trip changed the size");
        for (size_t i = 0; i < (size_t)im->w * im->h * 4; i++) {
            float v = im->px[i];
            float c = isnan(v) ? 0.0f : v < 0 ? 0.0f : v > 1 ? 1.0f : v;
            if (fabsf(back.px[i] - c) > 1.0f / 65535)
                fail("PNG round trip changed a sample by more than 1/65535");
        }
        image_free(&back);
    }
    bytebuf_free(&b);
}

static void check_volume(const volume *v)
{
    if (v->nx < 1 || v->ny < 1 || v->nz < 1 || !v->v)
        fail("decoded volume has no samples");
    size_t n = (size_t)v->nx * v->ny * v->nz;
    if (n > 65536)
        return;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    volume back;
    memset(&back, 0, sizeof back);
    if (vio_nrrd_to_mem(v, VIO_FLOAT, NULL, &b, &e) == RT_OK) {
        if (vio_nrrd_from_mem(b.data, b.len, NULL, &back, &e) != RT_OK) {
            fprintf(stderr, "%s\n", e.msg);
            fail("float NRRD of a decoded volume does not decode");
        }
        if (back.nx != v->nx || back.ny != v->ny || back.nz != v->nz)
            fail("NRRD round trip changed the size");
        if (memcmp(back.v, v->v, n * sizeof *v->v) != 0) {
            for (size_t i = 0; i < n; i++)
                if (!(isnan(v->v[i]) && isnan(back.v[i])) && back.v[i] != v->v[i])
                    fail("NRRD round trip changed a sample");
        }
        volume_free(&back);
    }
    bytebuf_free(&b);
}

static void check_mesh(const mesh *m)
{
    for (size_t i = 0; i < m->nt * 3; i++)
        if (m->tri[i] >= m->nv)
            fail("decoded mesh has a triangle index out of range");
    mesh_stats st;
    rt_error e;
    mesh_compute_stats(m, &st, &e);
    if (m->nv > 4096)
        return;
    bytebuf b;
    bytebuf_init(&b);
    if (mio_ply_to_mem(m, 0, &b, &e) == RT_OK) {
        mesh back;
        if (mio_ply_from_mem(b.data, b.len, &back, &e) != RT_OK) {
            fprintf(stderr, "%s\n", e.msg);
            fail("binary PLY of a decoded mesh does not decode");
        }
        if (back.nv != m->nv || back.nt != m->nt)
            fail("PLY round trip changed the vertex or triangle count");
        mesh_free(&back);
    }
    bytebuf_free(&b);
}

/* ---- PNG: repair checksums so mutations get past them ------------------ */

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* Rebuild d as: signature, chunks with correct CRCs, all IDAT data merged
 * into one chunk at the place of the first IDAT, its zlib Adler-32 set to
 * the value of what the deflate data decode to (checksum errors themselves
 * are covered by tests/unit/test_png.c). Returns a malloc'd buffer (or NULL
 * to use the input as is). */
static unsigned char *png_repair(const unsigned char *d, size_t n, size_t *outn)
{
    if (n < 8)
        return NULL;
    bytebuf idat, o;
    bytebuf_init(&idat);
    bytebuf_init(&o);
    size_t pos = 8, idat_at = (size_t)-1;
    bytebuf_append(&o, d, 8);
    while (n - pos >= 12) {
        uint32_t l = be32(d + pos);
        if (l > n - pos - 12)
            break;
        if (memcmp(d + pos + 4, "IDAT", 4) == 0) {
            if (idat_at == (size_t)-1)
                idat_at = o.len;
            bytebuf_append(&idat, d + pos + 8, l);
        } else {
            size_t at = o.len;
            bytebuf_append(&o, d + pos, 8 + (size_t)l + 4);
            if (!o.failed)
                put_be32(o.data + at + 8 + l, deflate_crc32(0, o.data + at + 4, (size_t)l + 4));
        }
        pos += 12 + (size_t)l;
    }
    bytebuf_append(&o, d + pos, n - pos); /* any tail as it was */
    if (idat_at != (size_t)-1 && !idat.failed) {
        if (idat.len > 2) {
            bytebuf raw;
            bytebuf_init(&raw);
            size_t used = 0;
            rt_error e;
            if (inflate_raw(idat.data + 2, idat.len - 2, (size_t)1 << 24, &raw, &used, &e) == RT_OK &&
                idat.len - 2 - used >= 4)
                put_be32(idat.data + 2 + used, deflate_adler32(1, raw.data, raw.len));
            bytebuf_free(&raw);
        }
        bytebuf chunk;
        bytebuf_init(&chunk);
        bytebuf_u32be(&chunk, (uint32_t)idat.len);
        bytebuf_append(&chunk, "IDAT", 4);
        bytebuf_append(&chunk, idat.data, idat.len);
        bytebuf_u32be(&chunk, deflate_crc32(0, chunk.data ? chunk.data + 4 : NULL, idat.len + 4));
        /* splice the chunk in at idat_at */
        bytebuf all;
        bytebuf_init(&all);
        bytebuf_append(&all, o.data, idat_at);
        bytebuf_append(&all, chunk.data, chunk.len);
        bytebuf_append(&all, o.data + idat_at, o.len - idat_at);
        bytebuf_free(&chunk);
        bytebuf_free(&o);
        o = all;
    }
    bytebuf_free(&idat);
    if (o.failed) {
        bytebuf_free(&o);
        return NULL;
    }
    *outn = o.len;
    return o.data;
}

static void fuzz_png(const unsigned char *d, size_t n)
{
    size_t rn = 0;
    unsigned char *r = png_repair(d, n, &rn);
    if (r) {
        d = r;
        n = rn;
    }
    rt_error e;
    png_info info;
    if (png_read_info(d, n, &info, &e) == RT_OK && (double)info.w * info.h <= 262144) {
        image im;
        if (png_decode(d, n, &im, &info, &e) == RT_OK) {
            check_image(&im);
            image_free(&im);
        }
    }
    rt_free(r); /* a bytebuf's data: the runtime allocator */
}

/* ---- the others --------------------------------------------------------- */

static void fuzz_inflate(const unsigned char *d, size_t n)
{
    rt_error e;
    bytebuf out;
    bytebuf_init(&out);
    if (inflate_zlib(d, n, (size_t)1 << 22, &out, &e) == RT_OK) {
        /* what decodes must re-encode and decode to the same bytes */
        bytebuf z, back;
        bytebuf_init(&z);
        bytebuf_init(&back);
        if (deflate_zlib(out.data, out.len, 6, &z, &e) == RT_OK) {
            if (inflate_zlib(z.data, z.len, out.len, &back, &e) != RT_OK || back.len != out.len ||
                (out.len && memcmp(back.data, out.data, out.len) != 0))
                fail("deflate/inflate round trip differs");
        }
        bytebuf_free(&z);
        bytebuf_free(&back);
    }
    bytebuf_free(&out);
    bytebuf_init(&out);
    size_t used;
    if (inflate_raw(d, n, (size_t)1 << 22, &out, &used, &e) == RT_OK && used > n)
        fail("inflate_raw used more bytes than it was given");
    bytebuf_free(&out);
}

static void fuzz_pnm(const unsigned char *d, size_t n)
{
    rt_error e;
    image im;
    pnm_info info;
    if (pnm_decode(d, n, &im, &info, &e) == RT_OK) {
        check_image(&im);
        image_free(&im);
    }
    if (pfm_decode(d, n, &im, &info, &e) == RT_OK) {
        if (im.w < 1 || im.h < 1 || !im.px)
            fail("decoded PFM has no pixels");
        image_free(&im);
    }
}

static void fuzz_ifs(const unsigned char *d, size_t n)
{
    rt_error e;
    fractint_list l;
    if (fractint_parse((const char *)d, n, &l, &e) == RT_OK) {
        for (int i = 0; i < l.n; i++) {
            if (l.e[i].n < 1 || (l.e[i].dim != 2 && l.e[i].dim != 3))
                fail("fractint entry with no maps or a bad dimension");
            if (fractint_find(&l, l.e[i].name) == NULL)
                fail("fractint_find does not find a parsed entry");
        }
        fractint_free(&l);
    }
}

static void fuzz_volume(const unsigned char *d, size_t n, int vtk)
{
    rt_error e;
    volume v;
    memset(&v, 0, sizeof v);
    rt_code c = vtk ? vio_vtk_from_mem(d, n, &v, &e) : vio_nrrd_from_mem(d, n, NULL, &v, &e);
    if (c == RT_OK) {
        check_volume(&v);
        volume_free(&v);
    }
}

static void fuzz_mesh(const unsigned char *d, size_t n, int fmt)
{
    rt_error e;
    mesh m;
    rt_code c = fmt == 0 ? mio_ply_from_mem(d, n, &m, &e)
              : fmt == 1 ? mio_obj_from_mem(d, n, &m, &e)
                         : mio_stl_from_mem(d, n, &m, &e);
    if (c == RT_OK)
        check_mesh(&m);
    mesh_free(&m);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > (1u << 20))
        return 0;
    /* a private heap copy of exactly size bytes: ASan sees any read past
     * the end, and no decoder can depend on a NUL after the data */
    unsigned char *d = malloc(size ? size : 1);
    if (!d)
        return 0;
    memcpy(d, data, size);
    if (!strcmp(loader, "png"))
        fuzz_png(d, size);
    else if (!strcmp(loader, "inflate"))
        fuzz_inflate(d, size);
    else if (!strcmp(loader, "pnm"))
        fuzz_pnm(d, size);
    else if (!strcmp(loader, "ifs"))
        fuzz_ifs(d, size);
    else if (!strcmp(loader, "nrrd"))
        fuzz_volume(d, size, 0);
    else if (!strcmp(loader, "vtk"))
        fuzz_volume(d, size, 1);
    else if (!strcmp(loader, "ply"))
        fuzz_mesh(d, size, 0);
    else if (!strcmp(loader, "obj"))
        fuzz_mesh(d, size, 1);
    else if (!strcmp(loader, "stl"))
        fuzz_mesh(d, size, 2);
    else
        fail("unknown FUZZ_LOADER");
    free(d);
    return 0;
}
