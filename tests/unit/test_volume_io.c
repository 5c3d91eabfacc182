/* test_volume_io.c — volume files against hand-written references.
 *
 * tests/data/formats/ holds files written by hand (header text typed, data
 * bytes as printf escapes computed by hand): a 3×2×2 volume with samples
 * 0, 0.25, ..., 2.75 (x fastest) over the box [0,3]×[0,1]×[0,2], as NRRD
 * float / ushort / uchar, as a detached .nhdr + .raw, and as legacy VTK
 * (big-endian), plus a foreign NRRD (big-endian shorts, `spacings`, no
 * origin). The writers must produce exactly those bytes and the readers must
 * read them back; files round-trip through disk; malformed headers give
 * precise errors; slices put the right samples in the right pixels. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "rt_alloc.h"
#include "volume_io.h"

#define DATA "tests/data/formats/"

static void ref_volume(volume *v)
{
    double lo[3] = {0, 0, 0}, hi[3] = {3, 1, 2};
    rt_error e;
    CHECK(volume_init(v, 3, 2, 2, lo, hi, &e) == RT_OK, "init");
    for (int i = 0; i < 12; i++)
        v->v[i] = 0.25f * (float)i;
}

static int same_as_file(const bytebuf *b, const char *path)
{
    unsigned char *d;
    size_t n;
    rt_error e;
    if (fileio_read_all(path, 1 << 20, &d, &n, &e) != RT_OK) {
        fprintf(stderr, "%s\n", e.msg);
        return 0;
    }
    int ok = n == b->len && memcmp(d, b->data, n) == 0;
    if (!ok)
        fprintf(stderr, "%s: %zu bytes, writer gave %zu\n", path, n, b->len);
    rt_free(d);
    return ok;
}

static void test_writers_match_references(void)
{
    volume v;
    ref_volume(&v);
    rt_error e;
    static const struct {
        int type;
        const char *file;
    } cases[] = {{VIO_FLOAT, DATA "vol_3x2x2_float.nrrd"},
                 {VIO_USHORT, DATA "vol_3x2x2_ushort.nrrd"},
                 {VIO_UCHAR, DATA "vol_3x2x2_uchar.nrrd"}};
    for (int i = 0; i < 3; i++) {
        bytebuf b;
        bytebuf_init(&b);
        CHECK(vio_nrrd_to_mem(&v, cases[i].type, NULL, &b, &e) == RT_OK, "%s", e.msg);
        CHECK(same_as_file(&b, cases[i].file), "writer differs from %s", cases[i].file);
        bytebuf_free(&b);
    }
    bytebuf b;
    bytebuf_init(&b);
    CHECK(vio_nrrd_to_mem(&v, VIO_FLOAT, "vol_3x2x2.raw", &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "vol_3x2x2.nhdr"), "detached header differs");
    bytebuf_free(&b);
    bytebuf_init(&b);
    CHECK(vio_raw_to_mem(&v, VIO_FLOAT, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "vol_3x2x2.raw"), "raw differs");
    bytebuf_free(&b);
    bytebuf_init(&b);
    CHECK(vio_vtk_to_mem(&v, &b, &e) == RT_OK, "%s", e.msg);
    CHECK(same_as_file(&b, DATA "vol_3x2x2.vtk"), "VTK differs");
    bytebuf_free(&b);
    volume_free(&v);
}

static void check_ref(const volume *v, const double *want, double tol, const char *what)
{
    CHECK(v->nx == 3 && v->ny == 2 && v->nz == 2, "%s: size %dx%dx%d", what, v->nx, v->ny, v->nz);
    double lo[3] = {0, 0, 0}, hi[3] = {3, 1, 2};
    for (int a = 0; a < 3; a++) {
        CHECK_NEAR(v->lo[a], lo[a], 1e-12, what);
        CHECK_NEAR(v->hi[a], hi[a], 1e-12, what);
    }
    if (v->nx * v->ny * v->nz == 12)
        for (int i = 0; i < 12; i++)
            CHECK(fabs(v->v[i] - want[i]) <= tol, "%s: sample %d is %.9g, expected %.9g", what, i,
                  v->v[i], want[i]);
}

static void test_readers_read_references(void)
{
    double f[12], u16[12], u8[12];
    /* quantised by hand: 0.25 -> 64 / 16384, 0.5 -> 128 / 32768,
     * 0.75 -> 191 / 49151, >= 1 -> 255 / 65535 */
    static const double q8[4] = {0, 64, 128, 191}, q16[4] = {0, 16384, 32768, 49151};
    for (int i = 0; i < 12; i++) {
        f[i] = 0.25 * i;
        u8[i] = i < 4 ? q8[i] / 255 : 1;
        u16[i] = i < 4 ? q16[i] / 65535 : 1;
    }
    volume v;
    rt_error e;
    CHECK(vio_load_nrrd(DATA "vol_3x2x2_float.nrrd", &v, &e) == RT_OK, "%s", e.msg);
    check_ref(&v, f, 0, "float nrrd");
    volume_free(&v);
    CHECK(vio_load_nrrd(DATA "vol_3x2x2_ushort.nrrd", &v, &e) == RT_OK, "%s", e.msg);
    check_ref(&v, u16, 1e-7, "ushort nrrd");
    volume_free(&v);
    CHECK(vio_load_nrrd(DATA "vol_3x2x2_uchar.nrrd", &v, &e) == RT_OK, "%s", e.msg);
    check_ref(&v, u8, 1e-7, "uchar nrrd");
    volume_free(&v);
    CHECK(vio_load_nrrd(DATA "vol_3x2x2.nhdr", &v, &e) == RT_OK, "%s", e.msg);
    check_ref(&v, f, 0, "nhdr + raw");
    volume_free(&v);
    CHECK(vio_load_vtk(DATA "vol_3x2x2.vtk", &v, &e) == RT_OK, "%s", e.msg);
    check_ref(&v, f, 0, "vtk");
    volume_free(&v);

    /* Big-endian shorts, spacings 2 1 0.5, no origin: lo = 0. */
    CHECK(vio_load_nrrd(DATA "vol_be_short.nrrd", &v, &e) == RT_OK, "%s", e.msg);
    CHECK(v.nx == 3 && v.ny == 2 && v.nz == 1, "be short size");
    static const float bs[6] = {-3, 300, 7, -32768, 32767, 0};
    if (v.nx * v.ny * v.nz == 6)
        for (int i = 0; i < 6; i++)
            CHECK(v.v[i] == bs[i], "be short sample %d: %g vs %g", i, v.v[i], bs[i]);
    CHECK(v.lo[0] == 0 && v.hi[0] == 6 && v.hi[1] == 2 && v.hi[2] == 0.5, "be short bounds %g %g %g",
          v.hi[0], v.hi[1], v.hi[2]);
    volume_free(&v);
}

static void test_roundtrip(void)
{
    char dir[] = "/tmp/frac_volio_XXXXXX";
    CHECK(mkdtemp(dir) != NULL, "mkdtemp");
    char p1[128], p2[128], p3[128], p4[128];
    snprintf(p1, sizeof p1, "%s/a.nrrd", dir);
    snprintf(p2, sizeof p2, "%s/b.nhdr", dir);
    snprintf(p3, sizeof p3, "%s/b.raw", dir);
    snprintf(p4, sizeof p4, "%s/c.vtk", dir);
    double lo[3] = {-0.1, 0.3, 1e-3}, hi[3] = {0.7, 2.0 / 3.0, 5};
    volume v, w;
    rt_error e;
    CHECK(volume_init(&v, 5, 4, 3, lo, hi, &e) == RT_OK, "init");
    for (int i = 0; i < 60; i++)
        v.v[i] = (float)sin(i * 1.7) * 0.6f + 0.5f; /* some outside [0, 1] */
    v.v[7] = NAN;
    v.v[8] = -INFINITY;
    CHECK(vio_save_nrrd(p1, &v, VIO_FLOAT, &e) == RT_OK, "%s", e.msg);
    CHECK(vio_load_nrrd(p1, &w, &e) == RT_OK, "%s", e.msg);
    CHECK(w.nx == 5 && w.ny == 4 && w.nz == 3, "nrrd size");
    CHECK(memcmp(w.v, v.v, 60 * sizeof(float)) == 0, "float nrrd not bit-exact");
    CHECK(memcmp(w.lo, v.lo, sizeof v.lo) == 0 && memcmp(w.hi, v.hi, sizeof v.hi) == 0,
          "nrrd bounds not exact: %.17g %.17g", w.hi[1], v.hi[1]);
    volume_free(&w);
    int types[2] = {VIO_USHORT, VIO_UCHAR};
    double bound[2] = {0.5 / 65535 + 1e-7, 0.5 / 255 + 1e-7};
    for (int t = 0; t < 2; t++) {
        CHECK(vio_save_nrrd(p1, &v, types[t], &e) == RT_OK, "%s", e.msg);
        CHECK(vio_load_nrrd(p1, &w, &e) == RT_OK, "%s", e.msg);
        double worst = 0;
        for (int i = 0; i < 60; i++) {
            double x = v.v[i] > 0 ? (v.v[i] < 1 ? v.v[i] : 1) : 0;
            double d = fabs(w.v[i] - x);
            if (d > worst)
                worst = d;
        }
        CHECK(worst <= bound[t], "type %d: quantisation error %g > %g", types[t], worst, bound[t]);
        volume_free(&w);
    }
    CHECK(vio_save_nhdr(p2, p3, &v, VIO_FLOAT, &e) == RT_OK, "%s", e.msg);
    CHECK(vio_load_nrrd(p2, &w, &e) == RT_OK, "%s", e.msg);
    CHECK(w.nx == 5 && memcmp(w.v, v.v, 60 * sizeof(float)) == 0, "nhdr not bit-exact");
    volume_free(&w);
    CHECK(vio_save_vtk(p4, &v, &e) == RT_OK, "%s", e.msg);
    CHECK(vio_load_vtk(p4, &w, &e) == RT_OK, "%s", e.msg);
    CHECK(w.nz == 3 && memcmp(w.v, v.v, 60 * sizeof(float)) == 0, "vtk not bit-exact");
    for (int a = 0; a < 3; a++) {
        CHECK_NEAR(w.lo[a], v.lo[a], 1e-12, "vtk lo");
        CHECK_NEAR(w.hi[a], v.hi[a], 1e-12, "vtk hi");
    }
    volume_free(&w);
    volume_free(&v);
    remove(p1);
    remove(p2);
    remove(p3);
    remove(p4);
    rmdir(dir);
}

static void expect_error(const char *text, size_t n, const char *msg)
{
    volume v;
    rt_error e;
    e.msg[0] = 0;
    rt_code rc = vio_nrrd_from_mem((const unsigned char *)text, n, NULL, &v, &e);
    CHECK(rc == RT_EFORMAT, "expected a format error for '%s'", msg);
    CHECK(strcmp(e.msg, msg) == 0, "message '%s', expected '%s'", e.msg, msg);
    if (!rc)
        volume_free(&v);
}

static void test_malformed(void)
{
#define H "NRRD0004\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
    expect_error("P6\n", 3, "not a NRRD file (no NRRD0001..NRRD0005 magic)");
    expect_error(H "\n", sizeof H, "NRRD header has no 'type' field");
    expect_error(H "type: quux\n\n", sizeof H "type: quux\n\n" - 1,
                 "NRRD header line 5: type 'quux' is not one of uchar, short, ushort, int, float, double");
    expect_error(H "type: float\n\n", sizeof H "type: float\n\n" - 1,
                 "NRRD header has no 'endian' field for 4-byte samples");
    expect_error(H "type: uchar\n\nabc", sizeof H "type: uchar\n\nabc" - 1,
                 "NRRD data is 3 bytes, expected 8 (2×2×2 samples of 1 byte(s))");
    expect_error(H "type: uchar\nspace directions: (1,0,0) (0,1,0.5) (0,0,1)\n\n",
                 sizeof H "type: uchar\nspace directions: (1,0,0) (0,1,0.5) (0,0,1)\n\n" - 1,
                 "NRRD header line 6: space direction 2 is not along axis 2 with a positive step");
    expect_error(H "type: uchar\nencoding: gzip\n\n", sizeof H "type: uchar\nencoding: gzip\n\n" - 1,
                 "NRRD header line 6: encoding 'gzip' is not supported (only raw)");
    expect_error("NRRD0004\ntype: uchar\ndimension: 2\n\n", sizeof "NRRD0004\ntype: uchar\ndimension: 2\n\n" - 1, "NRRD header line 3: dimension 2, expected 3");
    expect_error(H "type: uchar\nsizes 2 2 2\n\n", sizeof H "type: uchar\nsizes 2 2 2\n\n" - 1,
                 "NRRD header line 6: expected 'field: value', got 'sizes 2 2 2'");
#undef H
}

static void test_slice(void)
{
    volume v;
    ref_volume(&v);
    image im;
    rt_error e;
    /* z = 1, grey over [0, 4]: pixel (x, row) shows sample (x, 1 - row, 1) */
    CHECK(volume_slice_axis(&v, 2, 1, NULL, 0, 4, &im, &e) == RT_OK, "%s", e.msg);
    CHECK(im.w == 3 && im.h == 2, "z slice size %dx%d", im.w, im.h);
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 3; x++) {
            double want = 0.25 * (x + 3 * (1 - y) + 6 * 1) / 4;
            CHECK_NEAR(image_at(&im, x, y)[0], want, 1e-7, "z slice");
            CHECK(image_at(&im, x, y)[3] == 1, "alpha");
        }
    image_free(&im);
    /* x = 2: w = ny, h = nz; pixel (y, row) shows sample (2, y, 1 - row) */
    CHECK(volume_slice_axis(&v, 0, 2, NULL, 0, 4, &im, &e) == RT_OK, "%s", e.msg);
    CHECK(im.w == 2 && im.h == 2, "x slice size");
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++)
            CHECK_NEAR(image_at(&im, x, y)[0], 0.25 * (2 + 3 * x + 6 * (1 - y)) / 4, 1e-7, "x slice");
    image_free(&im);
    /* y = 0 with a red ramp: w = nx, h = nz */
    ramp r = ramp_grey();
    r.rgba[1][1] = r.rgba[1][2] = 0;
    CHECK(volume_slice_axis(&v, 1, 0, &r, 0, 2, &im, &e) == RT_OK, "%s", e.msg);
    CHECK(im.w == 3 && im.h == 2, "y slice size");
    CHECK_NEAR(image_at(&im, 1, 1)[0], 0.25 * 1 / 2, 1e-7, "y slice ramp red");
    CHECK_NEAR(image_at(&im, 1, 1)[1], 0, 1e-7, "y slice ramp green");
    CHECK_NEAR(image_at(&im, 2, 0)[0], 1, 1e-7, "y slice clamps at the last stop"); /* 2.0 / 2 */
    image_free(&im);
    CHECK(volume_slice_axis(&v, 1, 2, NULL, 0, 1, &im, &e) == RT_EINVAL, "index");
    CHECK(strcmp(e.msg, "slice index 2 along y is not in 0..1") == 0, "msg: %s", e.msg);
    volume_free(&v);
}

/* Declared sizes are checked against the voxel limit before the data are
 * looked for or the volume is allocated. */
static void test_declared_size(void)
{
    const char *nrrd = "NRRD0004\ntype: float\ndimension: 3\nsizes: 1000 1000 1000\nendian: little\n"
                       "encoding: raw\n\n";
    const char *vtk = "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\n"
                      "DIMENSIONS 1000 1000 1000\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 1000000000\n"
                      "SCALARS v float 1\nLOOKUP_TABLE default\n";
    volume v;
    rt_error e = {0};
    check_limits(-1, 1e6, -1);
    rt_code c = vio_nrrd_from_mem((const unsigned char *)nrrd, strlen(nrrd), NULL, &v, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "volume of 1000×1000×1000 voxels exceeds the limit of 1000000 voxels "
                                          "(raise it with --max-voxels)") == 0, "%d %s", c, e.msg);
    c = vio_vtk_from_mem((const unsigned char *)vtk, strlen(vtk), &v, &e);
    CHECK(c == RT_ELIMIT && strcmp(e.msg, "volume of 1000×1000×1000 voxels exceeds the limit of 1000000 voxels "
                                          "(raise it with --max-voxels)") == 0, "%d %s", c, e.msg);
    CHECK(check_hs.peak < 4096, "largest block before the refusals: %zu", check_hs.peak);
    check_limits_off();
}

/* Found by the fuzzer: a huge SPACING (or a nan ORIGIN) made volumes with
 * infinite bounds that no writer can store; both readers refuse them. */
static void test_bounds_not_finite(void)
{
    char vtk[512];
    int n = snprintf(vtk, sizeof vtk, "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\n"
                                      "DIMENSIONS 2 1 1\nORIGIN 0 0 0\nSPACING 1e308 1 1\nPOINT_DATA 2\n"
                                      "SCALARS d float 1\nLOOKUP_TABLE default\n");
    memset(vtk + n, 0, 8);
    volume v;
    rt_error e;
    rt_code c = vio_vtk_from_mem((const unsigned char *)vtk, (size_t)n + 8, &v, &e);
    CHECK(c == RT_EFORMAT && strcmp(e.msg, "VTK ORIGIN and SPACING give axis 0 the bounds -5e+307 .. inf "
                                           "(not finite and increasing)") == 0,
          "VTK huge spacing: code %d, '%s'", (int)c, e.msg);
    if (c == RT_OK)
        volume_free(&v);
    char nrrd[512];
    n = snprintf(nrrd, sizeof nrrd, "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n"
                                    "space origin: (nan,0,0)\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n\nA");
    c = vio_nrrd_from_mem((const unsigned char *)nrrd, (size_t)n, NULL, &v, &e);
    CHECK(c == RT_EFORMAT && strcmp(e.msg, "NRRD origin and spacing give axis 0 the bounds nan .. nan "
                                           "(not finite and increasing)") == 0,
          "NRRD nan origin: code %d, '%s'", (int)c, e.msg);
    if (c == RT_OK)
        volume_free(&v);
}

/* Found by the fuzzer: a huge `line skip` kept looping after the end of
 * the data (10^12 iterations here: the old reader ran for hours). */
static void test_huge_line_skip(void)
{
    const char nrrd[] = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n"
                        "line skip: 1000000000000\n\nA\n";
    volume v;
    rt_error e;
    rt_code c = vio_nrrd_from_mem((const unsigned char *)nrrd, sizeof nrrd - 1, NULL, &v, &e);
    CHECK(c == RT_EFORMAT && strcmp(e.msg, "NRRD data is 0 bytes, expected 1 (1×1×1 samples of 1 byte(s))") == 0,
          "NRRD huge line skip: code %d, '%s'", (int)c, e.msg);
    if (c == RT_OK)
        volume_free(&v);
}

int main(void)
{
    test_huge_line_skip();
    test_bounds_not_finite();
    test_writers_match_references();
    test_readers_read_references();
    test_roundtrip();
    test_malformed();
    test_slice();
    test_declared_size();
    return check_done("test_volume_io");
}
