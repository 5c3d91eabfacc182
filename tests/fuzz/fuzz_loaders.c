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
 *   apng     apng_assemble: the input is split at each PNG signature into
 *            frames (each repaired as for png), assembled, and the result
 *            checked chunk by chunk (below)
 *   recipe   recipe_find on the input as a file frac wrote (PNG text chunks,
 *            comment lines, the one-line form), recipe_parse of what it
 *            finds and of the raw input; a parsed recipe is written back
 *            with recipe_text and must parse to the same fields
 * Oracles beyond "no crash, no sanitizer report, no leak": a decoded image,
 * volume or mesh is checked for consistency (sizes, triangle indices in
 * range), images are re-encoded to 16-bit PNG and decoded back within
 * 1/65535, volumes to float NRRD and back bit-exactly, meshes to binary PLY
 * and back with the same counts.
 *
 * FRAC_FUZZ_VERBOSE=1 prints what each apng and recipe input did.
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
#include "apng.h"
#include "deflate.h"
#include "fractint.h"
#include "mesh.h"
#include "mesh_io.h"
#include "png.h"
#include "pnm.h"
#include "recipe.h"
#include "volume_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define STR2(x) #x
#define STR(x) STR2(x)
static const char *const loader = STR(FUZZ_LOADER);

static int verbose; /* FRAC_FUZZ_VERBOSE=1: what each replayed input did (apng, recipe) */

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
    image back = {0, 0, NULL, NULL, NULL};
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

/* ---- APNG: the assembler and what it writes ----------------------------- */

static int same_image(const image *a, const image *b)
{
    if (a->w != b->w || a->h != b->h)
        return 0;
    size_t n = (size_t)a->w * a->h * 4;
    for (size_t i = 0; i < n; i++)
        if (a->px[i] != b->px[i] && !(isnan(a->px[i]) && isnan(b->px[i])))
            return 0;
    return 1;
}

/* Walk the assembled file: signature, every chunk's CRC, IHDR first and
 * equal to the first frame's, acTL (frames, plays) before the first IDAT,
 * fcTL/fdAT sequence numbers 0, 1, 2… in file order, one fcTL per frame
 * (whole canvas, delay as asked), IEND last. Each frame's data (IDAT, or
 * fdAT without its sequence number) is collected into frames[k]. */
static void check_apng(const unsigned char *d, size_t n, int nframes, const apng_opts *o,
                       const unsigned char *ihdr0, bytebuf *frames)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (n < 8 || memcmp(d, sig, 8) != 0)
        fail("APNG: no PNG signature");
    size_t pos = 8;
    uint32_t seq = 0;
    int fctl = 0, seen_actl = 0, seen_iend = 0, nchunk = 0;
    while (pos < n) {
        if (seen_iend)
            fail("APNG: bytes after IEND");
        if (n - pos < 12)
            fail("APNG: a truncated chunk");
        uint32_t l = be32(d + pos);
        if (l > n - pos - 12)
            fail("APNG: a chunk longer than the file");
        const unsigned char *type = d + pos + 4, *body = d + pos + 8;
        if (be32(body + l) != deflate_crc32(0, type, (size_t)l + 4))
            fail("APNG: a chunk CRC is wrong");
        if (nchunk++ == 0 && (memcmp(type, "IHDR", 4) != 0 || l != 13 || memcmp(body, ihdr0, 13) != 0))
            fail("APNG: the first chunk is not the first frame's IHDR");
        if (!memcmp(type, "acTL", 4)) {
            if (seen_actl || fctl || l != 8 || be32(body) != (uint32_t)nframes || be32(body + 4) != (uint32_t)o->loop)
                fail("APNG: acTL missing, repeated, late or wrong");
            seen_actl = 1;
        } else if (!memcmp(type, "fcTL", 4)) {
            if (!seen_actl || l != 26 || be32(body) != seq++ || fctl >= nframes ||
                memcmp(body + 4, ihdr0, 8) != 0 || be32(body + 12) != 0 || be32(body + 16) != 0 ||
                (body[20] << 8 | body[21]) != o->delay_ms || (body[22] << 8 | body[23]) != 1000 || body[24] ||
                body[25])
                fail("APNG: an fcTL is out of sequence or wrong");
            fctl++;
        } else if (!memcmp(type, "IDAT", 4)) {
            if (fctl != 1)
                fail("APNG: IDAT outside the first frame");
            bytebuf_append(&frames[0], body, l);
        } else if (!memcmp(type, "fdAT", 4)) {
            if (fctl < 2 || l < 4 || be32(body) != seq++)
                fail("APNG: an fdAT is out of sequence");
            bytebuf_append(&frames[fctl - 1], body + 4, l - 4);
        } else if (!memcmp(type, "IEND", 4)) {
            seen_iend = 1;
        }
        pos += 12 + (size_t)l;
    }
    if (!seen_iend || fctl != nframes)
        fail("APNG: no IEND, or not one fcTL per frame");
}

/* A plain PNG of one frame: the IHDR (and PLTE / tRNS) of the assembled
 * file with that frame's data as one IDAT. */
static void frame_png(const unsigned char *d, size_t n, const bytebuf *data, bytebuf *out)
{
    bytebuf_append(out, d, 8);
    for (size_t pos = 8; n - pos >= 12;) {
        uint32_t l = be32(d + pos);
        const unsigned char *type = d + pos + 4;
        if (!memcmp(type, "IHDR", 4) || !memcmp(type, "PLTE", 4) || !memcmp(type, "tRNS", 4))
            bytebuf_append(out, d + pos, 12 + (size_t)l);
        pos += 12 + (size_t)l;
    }
    size_t at = out->len;
    bytebuf_u32be(out, (uint32_t)data->len);
    bytebuf_append(out, "IDAT", 4);
    bytebuf_append(out, data->data, data->len);
    if (!out->failed)
        bytebuf_u32be(out, deflate_crc32(0, out->data + at + 4, data->len + 4));
    bytebuf_u32be(out, 0);
    bytebuf_append(out, "IEND", 4);
    bytebuf_u32be(out, deflate_crc32(0, "IEND", 4));
}

#define APNG_FRAMES 4
static void fuzz_apng(const unsigned char *d, size_t n)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    /* frames start at each signature; bytes before the first are the options */
    size_t at[APNG_FRAMES + 1];
    int k = 0;
    for (size_t i = 0; i + 8 <= n && k < APNG_FRAMES; i++)
        if (d[i] == 0x89 && memcmp(d + i, sig, 8) == 0)
            at[k++] = i;
    if (k == 0)
        return;
    at[k] = n;
    apng_opts o = {at[0] >= 2 ? (d[0] << 8 | d[1]) % (APNG_MAX_DELAY_MS + 1) : APNG_DEFAULT_DELAY_MS,
                   at[0] >= 3 ? d[2] : 0};
    unsigned char *part[APNG_FRAMES] = {0};
    const unsigned char *pngs[APNG_FRAMES];
    size_t lens[APNG_FRAMES];
    image im[APNG_FRAMES];
    int ndec = 0, ok = 1;
    for (int i = 0; i < k; i++) {
        size_t rn = 0;
        part[i] = png_repair(d + at[i], at[i + 1] - at[i], &rn);
        pngs[i] = part[i] ? part[i] : d + at[i];
        lens[i] = part[i] ? rn : at[i + 1] - at[i];
        rt_error e;
        png_info info;
        /* the assembler decodes every frame: keep declared sizes small */
        if (png_read_info(pngs[i], lens[i], &info, &e) != RT_OK || (double)info.w * info.h > 65536)
            ok = 0;
        else if (ok && png_decode(pngs[i], lens[i], &im[i], NULL, &e) == RT_OK)
            ndec = i + 1;
        else
            ok = 0;
    }
    if (ok) {
        bytebuf out;
        bytebuf_init(&out);
        rt_error e;
        rt_code ac = apng_assemble(pngs, lens, k, NULL, &o, &out, &e);
        if (verbose)
            fprintf(stderr, "fuzz_apng: %d frame(s): %s\n", k, ac ? e.msg : "assembled and checked");
        if (ac == RT_OK) {
            /* a viewer without APNG shows the first frame */
            image first;
            if (png_decode(out.data, out.len, &first, NULL, &e) != RT_OK)
                fail("APNG: the assembled file does not decode as a PNG");
            if (!same_image(&first, &im[0]))
                fail("APNG: the default image is not the first frame");
            image_free(&first);
            bytebuf frames[APNG_FRAMES];
            for (int i = 0; i < k; i++)
                bytebuf_init(&frames[i]);
            const unsigned char *ihdr0 = NULL; /* the first frame's IHDR body */
            for (size_t pos = 8; !ihdr0 && lens[0] - pos >= 12 + 13; pos += 12 + (size_t)be32(pngs[0] + pos))
                if (!memcmp(pngs[0] + pos + 4, "IHDR", 4))
                    ihdr0 = pngs[0] + pos + 8;
            if (!ihdr0)
                fail("APNG: a frame that decodes has no IHDR");
            check_apng(out.data, out.len, k, &o, ihdr0, frames);
            /* each frame's data, as a PNG of its own, decodes to that frame */
            for (int i = 0; i < k; i++) {
                bytebuf one;
                bytebuf_init(&one);
                frame_png(out.data, out.len, &frames[i], &one);
                image back;
                if (one.failed || png_decode(one.data, one.len, &back, NULL, &e) != RT_OK)
                    fail("APNG: a frame's data does not decode");
                if (!same_image(&back, &im[i]))
                    fail("APNG: a frame's data decodes to another image");
                image_free(&back);
                bytebuf_free(&one);
                bytebuf_free(&frames[i]);
            }
        } else if (k == 1) {
            fail("APNG: one frame that decodes was refused");
        }
        bytebuf_free(&out);
    }
    for (int i = 0; i < ndec; i++)
        image_free(&im[i]);
    for (int i = 0; i < k; i++)
        rt_free(part[i]);
}

/* ---- recipes -------------------------------------------------------------- */

static int same_str(const char *a, const char *b) { return (!a && !b) || (a && b && strcmp(a, b) == 0); }

static void recipe_round_trip(const char *text, size_t len)
{
    recipe r, b;
    char err[256];
    if (recipe_parse(text, len, &r, err, sizeof err)) {
        if (verbose)
            fprintf(stderr, "fuzz_recipe: %s\n", err);
        return;
    }
    if (verbose)
        fprintf(stderr, "fuzz_recipe: parsed (%d params, %d args, script %s)\n", r.nparams, r.nargs,
                r.script ? "text" : r.has_script ? "length only" : "omitted");
    bytebuf t;
    bytebuf_init(&t);
    size_t hl = 0;
    char one[256];
    recipe_text(&r, &t, &hl, one, sizeof one);
    if (t.failed)
        fail("recipe: out of memory writing it back");
    if (hl > t.len || strlen(one) >= sizeof one)
        fail("recipe: header length or one-line form out of range");
    if (recipe_parse((const char *)t.data, t.len, &b, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        fail("recipe: what recipe_text wrote does not parse");
    }
    int same = same_str(r.version, b.version) && same_str(r.script_path, b.script_path) &&
               !strcmp(r.sha256, b.sha256) && r.seed == b.seed && r.frame_given == b.frame_given &&
               r.frame == b.frame && r.frames_range == b.frames_range && r.frames_a == b.frames_a &&
               r.frames_b == b.frames_b && r.frames_step == b.frames_step && r.nparams == b.nparams &&
               r.nargs == b.nargs && r.has_script == b.has_script && r.script_len == b.script_len &&
               (r.script != NULL) == (b.script != NULL) &&
               (!r.script || memcmp(r.script, b.script, r.script_len) == 0);
    for (int i = 0; same && i < r.nparams; i++)
        same = !strcmp(r.params[i], b.params[i]);
    for (int i = 0; same && i < r.nargs; i++)
        same = !strcmp(r.args[i], b.args[i]);
    if (!same)
        fail("recipe: written back, it parses to other fields");
    /* the header alone (what the comment-line formats carry) parses too */
    recipe h;
    if (recipe_parse((const char *)t.data, hl, &h, err, sizeof err)) {
        fprintf(stderr, "%s\n", err);
        fail("recipe: the header alone does not parse");
    }
    recipe_free(&h);
    recipe_free(&b);
    recipe_free(&r);
    bytebuf_free(&t);
}

static void fuzz_recipe(const unsigned char *d, size_t n)
{
    size_t rn = 0;
    unsigned char *r = n >= 8 && !memcmp(d, "\x89PNG", 4) ? png_repair(d, n, &rn) : NULL;
    char *text = NULL, one[256], err[256];
    size_t len = 0;
    int found = recipe_find(r ? r : d, r ? rn : n, &text, &len, one, sizeof one, err, sizeof err);
    if (found == 0) {
        if (!text && len)
            fail("recipe_find: found, but no text");
        recipe_round_trip(text, len);
    } else if (found == 1 && strlen(one) >= sizeof one) {
        fail("recipe_find: the one-line form overflows");
    }
    rt_free(text);
    rt_free(r);
    recipe_round_trip((const char *)d, n);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > (1u << 20))
        return 0;
    /* a private heap copy of exactly size bytes: ASan sees any read past
     * the end, and no decoder can depend on a NUL after the data */
    verbose = getenv("FRAC_FUZZ_VERBOSE") != NULL;
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
    else if (!strcmp(loader, "apng"))
        fuzz_apng(d, size);
    else if (!strcmp(loader, "recipe"))
        fuzz_recipe(d, size);
    else
        fail("unknown FUZZ_LOADER");
    free(d);
    return 0;
}
