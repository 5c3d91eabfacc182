/* volume_io.c — NRRD / raw+nhdr / legacy VTK volumes and axis slices.
 *
 * Formats as specified by teem ("NRRD format", teem.sourceforge.net/nrrd/
 * format.html) and VTK ("VTK file formats", legacy section). Layout and
 * quantisation conventions are in volume_io.h.
 */
#include "volume_io.h"
#include "rt_alloc.h"
#include "provenance.h"
#include "sample.h"
#include "textline.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Shortest of %.15g / %.17g that reads back as x. */
static void fmt_num(char *buf, size_t n, double x)
{
    snprintf(buf, n, "%.15g", x);
    if (strtod(buf, NULL) != x)
        snprintf(buf, n, "%.17g", x);
}

static size_t type_size(int type)
{
    return type == VIO_FLOAT ? 4 : type == VIO_USHORT ? 2 : 1;
}

static rt_code check_vol(const volume *v, int type, rt_error *e)
{
    if (type != VIO_FLOAT && type != VIO_USHORT && type != VIO_UCHAR)
        return rt_fail(e, RT_EINVAL, "volume sample type %d is not float, ushort or uchar", type);
    if (!v->v || v->nx < 1 || v->ny < 1 || v->nz < 1)
        return rt_fail(e, RT_EINVAL, "volume is empty");
    return RT_OK;
}

static double quant01(float f)
{
    double t = f > 0 ? (f < 1 ? f : 1) : 0; /* NaN -> 0 */
    return t;
}

rt_code vio_raw_to_mem(const volume *v, int type, bytebuf *out, rt_error *e)
{
    rt_code rc = check_vol(v, type, e);
    if (rc)
        return rc;
    size_t n = (size_t)v->nx * (size_t)v->ny * (size_t)v->nz;
    for (size_t i = 0; i < n && !out->failed; i++) {
        if (type == VIO_FLOAT)
            bytebuf_f32le(out, v->v[i]);
        else if (type == VIO_USHORT)
            bytebuf_u16le(out, (unsigned)lround(quant01(v->v[i]) * 65535.0));
        else
            bytebuf_byte(out, (unsigned char)lround(quant01(v->v[i]) * 255.0));
    }
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a volume");
    return RT_OK;
}

static void geometry(const volume *v, double s[3], double org[3])
{
    int n[3] = {v->nx, v->ny, v->nz};
    for (int a = 0; a < 3; a++) {
        s[a] = (v->hi[a] - v->lo[a]) / n[a];
        org[a] = v->lo[a] + 0.5 * s[a];
    }
}

rt_code vio_nrrd_to_mem(const volume *v, int type, const char *data_file, bytebuf *out, rt_error *e)
{
    rt_code rc = check_vol(v, type, e);
    if (rc)
        return rc;
    static const char *tname[3] = {"float", "ushort", "uchar"};
    double s[3], org[3];
    char a[3][32], b[3][32], lo[3][32], hi[3][32];
    geometry(v, s, org);
    for (int k = 0; k < 3; k++) {
        fmt_num(a[k], sizeof a[k], s[k]);
        fmt_num(b[k], sizeof b[k], org[k]);
        fmt_num(lo[k], sizeof lo[k], v->lo[k]);
        fmt_num(hi[k], sizeof hi[k], v->hi[k]);
    }
    bytebuf_printf(out, "NRRD0004\n");
    bytebuf_printf(out, "# frac volume: samples at cell centres, x fastest\n");
    prov_put_lines(out, "# ");
    bytebuf_printf(out, "type: %s\n", tname[type]);
    bytebuf_printf(out, "dimension: 3\n");
    bytebuf_printf(out, "space: 3D-right-handed\n");
    bytebuf_printf(out, "sizes: %d %d %d\n", v->nx, v->ny, v->nz);
    bytebuf_printf(out, "space directions: (%s,0,0) (0,%s,0) (0,0,%s)\n", a[0], a[1], a[2]);
    bytebuf_printf(out, "kinds: domain domain domain\n");
    bytebuf_printf(out, "centers: cell cell cell\n");
    if (type_size(type) > 1)
        bytebuf_printf(out, "endian: little\n");
    bytebuf_printf(out, "encoding: raw\n");
    bytebuf_printf(out, "space origin: (%s,%s,%s)\n", b[0], b[1], b[2]);
    bytebuf_printf(out, "frac_lo:=%s %s %s\n", lo[0], lo[1], lo[2]);
    bytebuf_printf(out, "frac_hi:=%s %s %s\n", hi[0], hi[1], hi[2]);
    if (data_file) {
        bytebuf_printf(out, "data file: %s\n", data_file);
    } else {
        bytebuf_printf(out, "\n");
        rc = vio_raw_to_mem(v, type, out, e);
        if (rc)
            return rc;
    }
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a volume");
    return RT_OK;
}

static rt_code save_buf(const char *path, bytebuf *b, rt_code rc, rt_error *e)
{
    if (!rc)
        rc = fileio_write_atomic(path, b->data, b->len, e);
    bytebuf_free(b);
    return rc;
}

rt_code vio_save_nrrd(const char *path, const volume *v, int type, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    return save_buf(path, &b, vio_nrrd_to_mem(v, type, NULL, &b, e), e);
}

static size_t dir_len(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? (size_t)(s - path) + 1 : 0;
}

rt_code vio_save_nhdr(const char *nhdr_path, const char *raw_path, const volume *v, int type,
                      rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code rc = save_buf(raw_path, &b, vio_raw_to_mem(v, type, &b, e), e);
    if (rc)
        return rc;
    size_t dl = dir_len(nhdr_path);
    const char *name = raw_path;
    if (dir_len(raw_path) == dl && strncmp(raw_path, nhdr_path, dl) == 0)
        name = raw_path + dl;
    bytebuf_init(&b);
    return save_buf(nhdr_path, &b, vio_nrrd_to_mem(v, type, name, &b, e), e);
}

rt_code vio_vtk_to_mem(const volume *v, bytebuf *out, rt_error *e)
{
    rt_code rc = check_vol(v, VIO_FLOAT, e);
    if (rc)
        return rc;
    double s[3], org[3];
    char a[3][32], b[3][32];
    geometry(v, s, org);
    for (int k = 0; k < 3; k++) {
        fmt_num(a[k], sizeof a[k], s[k]);
        fmt_num(b[k], sizeof b[k], org[k]);
    }
    size_t n = (size_t)v->nx * (size_t)v->ny * (size_t)v->nz;
    bytebuf_printf(out, "# vtk DataFile Version 3.0\n");
    /* the title line (at most 256 bytes): the one-line recipe when there is one */
    const prov *pv = prov_get();
    bytebuf_printf(out, "%.255s\n", pv && pv->oneline ? pv->oneline : "frac volume");
    bytebuf_printf(out, "BINARY\n");
    bytebuf_printf(out, "DATASET STRUCTURED_POINTS\n");
    bytebuf_printf(out, "DIMENSIONS %d %d %d\n", v->nx, v->ny, v->nz);
    bytebuf_printf(out, "ORIGIN %s %s %s\n", b[0], b[1], b[2]);
    bytebuf_printf(out, "SPACING %s %s %s\n", a[0], a[1], a[2]);
    bytebuf_printf(out, "POINT_DATA %zu\n", n);
    bytebuf_printf(out, "SCALARS density float 1\n");
    bytebuf_printf(out, "LOOKUP_TABLE default\n");
    for (size_t i = 0; i < n && !out->failed; i++)
        bytebuf_f32be(out, v->v[i]);
    bytebuf_printf(out, "\n");
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a volume");
    return RT_OK;
}

rt_code vio_save_vtk(const char *path, const volume *v, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    return save_buf(path, &b, vio_vtk_to_mem(v, &b, e), e);
}

/* ---- reading ---- */

static int parse_type(const char *s)
{
    static const struct {
        const char *name;
        int t;
    } names[] = {
        {"uchar", SAMPLE_U8},          {"unsigned char", SAMPLE_U8},      {"uint8", SAMPLE_U8},
        {"uint8_t", SAMPLE_U8},        {"short", SAMPLE_I16},             {"short int", SAMPLE_I16},
        {"signed short", SAMPLE_I16},  {"signed short int", SAMPLE_I16},  {"int16", SAMPLE_I16},
        {"int16_t", SAMPLE_I16},       {"ushort", SAMPLE_U16},            {"unsigned short", SAMPLE_U16},
        {"unsigned short int", SAMPLE_U16}, {"uint16", SAMPLE_U16},       {"uint16_t", SAMPLE_U16},
        {"int", SAMPLE_I32},           {"signed int", SAMPLE_I32},        {"int32", SAMPLE_I32},
        {"int32_t", SAMPLE_I32},       {"float", SAMPLE_F32},             {"double", SAMPLE_F64},
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(s, names[i].name) == 0)
            return names[i].t;
    return SAMPLE_NONE;
}

/* A sample as a voxel value: 8- and 16-bit unsigned samples scaled to
 * [0, 1], the others as they are. */
static float decode(const unsigned char *p, int t, int big)
{
    switch (t) {
    case SAMPLE_U8:
        return (float)(sample_get(p, SAMPLE_U8, big) / 255.0);
    case SAMPLE_U16:
        return (float)(sample_get(p, SAMPLE_U16, big) / 65535.0);
    case SAMPLE_F32: {
        float f;
        sample_f32(p, big, &f);
        return f;
    }
    default:
        return (float)sample_get(p, (sample_type)t, big);
    }
}

/* Parse "(a,b,c)" at *s; advances *s. */
static int parse_vec(const char **s, double v[3])
{
    const char *p = *s;
    while (*p == ' ' || *p == '\t')
        p++;
    if (*p != '(')
        return -1;
    p++;
    for (int k = 0; k < 3; k++) {
        char *end;
        v[k] = strtod(p, &end);
        if (end == p)
            return -1;
        p = end;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p != (k < 2 ? ',' : ')'))
            return -1;
        p++;
    }
    *s = p;
    return 0;
}

static int parse_nums(const char *s, double *v, int n)
{
    for (int k = 0; k < n; k++) {
        char *end;
        v[k] = strtod(s, &end);
        if (end == s)
            return -1;
        s = end;
    }
    while (*s == ' ' || *s == '\t')
        s++;
    return *s ? -1 : 0;
}

/* The volume of dims[0] × dims[1] × dims[2] samples of a type (big-endian
 * if big) at data over lo..hi. A huge spacing or origin (or nan/inf, which
 * strtod reads) gives bounds no writer can store (found by the fuzzer):
 * refused, naming the header fields `from`. */
static rt_code volume_of_samples(volume *v, const int dims[3], const double lo[3], const double hi[3],
                                 const unsigned char *data, int type, int big, const char *from, rt_error *e)
{
    for (int k = 0; k < 3; k++)
        if (!(isfinite(lo[k]) && isfinite(hi[k]) && lo[k] < hi[k]))
            return rt_fail(e, RT_EFORMAT, "%s give axis %d the bounds %g .. %g (not finite and increasing)", from, k,
                           lo[k], hi[k]);
    rt_code rc = volume_init(v, dims[0], dims[1], dims[2], lo, hi, e);
    if (rc)
        return rc;
    size_t count = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2], ts = sample_size((sample_type)type);
    for (size_t i = 0; i < count; i++)
        v->v[i] = decode(data + i * ts, type, big);
    return RT_OK;
}

/* A file read whole for a loader (v->v NULL until it is filled). */
static rt_code read_volume_file(const char *path, volume *v, unsigned char **d, size_t *n, rt_error *e)
{
    v->v = NULL;
    return fileio_read_all(path, (size_t)1 << 40, d, n, e);
}

rt_code vio_nrrd_from_mem(const unsigned char *d, size_t n, const char *dir, volume *v, rt_error *e)
{
    v->v = NULL;
    if (n < 8 || memcmp(d, "NRRD000", 7) != 0 || d[7] < '1' || d[7] > '5')
        return rt_fail(e, RT_EFORMAT, "not a NRRD file (no NRRD0001..NRRD0005 magic)");
    int type = SAMPLE_NONE, dim = 0, endian = -1, have_sizes = 0, have_dirs = 0, have_sp = 0;
    int have_org = 0, have_lo = 0, have_hi = 0, have_enc = 0;
    long sizes[3] = {0, 0, 0};
    double sp[3] = {1, 1, 1}, org[3] = {0, 0, 0}, flo[3], fhi[3];
    long byte_skip = 0, line_skip = 0;
    char datafile[1024] = "";
    size_t pos = 0, data_at = n;
    int lineno = 0, ended = 0;
    char line[2048];
    while (pos < n) {
        long len = textline_next(d, n, &pos, line, sizeof line);
        lineno++;
        if (len >= (long)sizeof line)
            return rt_fail(e, RT_EFORMAT, "NRRD header line %d is too long", lineno);
        if (lineno == 1)
            continue;
        if (len == 0) {
            ended = 1;
            data_at = pos;
            break;
        }
        if (line[0] == '#')
            continue;
        char *kv = strstr(line, ":=");
        char *colon = strstr(line, ": ");
        if (kv && (!colon || kv < colon)) {
            *kv = 0;
            const char *val = kv + 2;
            if (strcmp(line, "frac_lo") == 0) {
                if (parse_nums(val, flo, 3))
                    return rt_fail(e, RT_EFORMAT, "NRRD header line %d: frac_lo needs 3 numbers", lineno);
                have_lo = 1;
            } else if (strcmp(line, "frac_hi") == 0) {
                if (parse_nums(val, fhi, 3))
                    return rt_fail(e, RT_EFORMAT, "NRRD header line %d: frac_hi needs 3 numbers", lineno);
                have_hi = 1;
            }
            continue;
        }
        if (!colon)
            return rt_fail(e, RT_EFORMAT, "NRRD header line %d: expected 'field: value', got '%.60s'",
                           lineno, line);
        *colon = 0;
        const char *key = line, *val = colon + 2;
        while (*val == ' ')
            val++;
        if (strcmp(key, "type") == 0) {
            type = parse_type(val);
            if (type == SAMPLE_NONE)
                return rt_fail(e, RT_EFORMAT,
                               "NRRD header line %d: type '%.40s' is not one of uchar, short, ushort, int, float, double",
                               lineno, val);
        } else if (strcmp(key, "dimension") == 0) {
            dim = atoi(val);
            if (dim != 3)
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: dimension %.20s, expected 3", lineno, val);
        } else if (strcmp(key, "sizes") == 0) {
            double s3[3];
            if (parse_nums(val, s3, 3))
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: sizes needs 3 numbers", lineno);
            for (int k = 0; k < 3; k++) {
                if (!(s3[k] >= 1 && s3[k] <= 1e9) || s3[k] != floor(s3[k]))
                    return rt_fail(e, RT_EFORMAT, "NRRD header line %d: size %g is not a positive integer",
                                   lineno, s3[k]);
                sizes[k] = (long)s3[k];
            }
            have_sizes = 1;
        } else if (strcmp(key, "encoding") == 0) {
            if (strcmp(val, "raw") != 0)
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: encoding '%.40s' is not supported (only raw)",
                               lineno, val);
            have_enc = 1;
        } else if (strcmp(key, "endian") == 0) {
            if (strcmp(val, "little") == 0)
                endian = 0;
            else if (strcmp(val, "big") == 0)
                endian = 1;
            else
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: endian '%.40s' is not little or big",
                               lineno, val);
        } else if (strcmp(key, "space directions") == 0) {
            const char *p = val;
            for (int k = 0; k < 3; k++) {
                double vec[3];
                if (parse_vec(&p, vec))
                    return rt_fail(e, RT_EFORMAT, "NRRD header line %d: space directions needs 3 vectors (x,y,z)",
                                   lineno);
                for (int a = 0; a < 3; a++)
                    if ((a == k && !(vec[a] > 0)) || (a != k && vec[a] != 0))
                        return rt_fail(e, RT_EFORMAT,
                                       "NRRD header line %d: space direction %d is not along axis %d with a positive step",
                                       lineno, k + 1, k + 1);
                sp[k] = vec[k];
            }
            have_dirs = 1;
        } else if (strcmp(key, "spacings") == 0) {
            if (parse_nums(val, sp, 3) || !(sp[0] > 0 && sp[1] > 0 && sp[2] > 0))
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: spacings needs 3 positive numbers", lineno);
            have_sp = 1;
        } else if (strcmp(key, "space origin") == 0) {
            const char *p = val;
            if (parse_vec(&p, org))
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: space origin is not (x,y,z)", lineno);
            have_org = 1;
        } else if (strcmp(key, "data file") == 0 || strcmp(key, "datafile") == 0) {
            if (strlen(val) >= sizeof datafile || strncmp(val, "LIST", 4) == 0 || strchr(val, '%'))
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: data file '%.60s' is not supported",
                               lineno, val);
            strcpy(datafile, val);
        } else if (strcmp(key, "byte skip") == 0 || strcmp(key, "byteskip") == 0) {
            byte_skip = atol(val);
            if (byte_skip < -1)
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: byte skip %ld", lineno, byte_skip);
        } else if (strcmp(key, "line skip") == 0 || strcmp(key, "lineskip") == 0) {
            line_skip = atol(val);
            if (line_skip < 0)
                return rt_fail(e, RT_EFORMAT, "NRRD header line %d: line skip %ld", lineno, line_skip);
        }
        /* other fields (space, kinds, centers, content, ...) do not change
         * the samples */
    }
    if (type == SAMPLE_NONE)
        return rt_fail(e, RT_EFORMAT, "NRRD header has no 'type' field");
    if (!dim)
        return rt_fail(e, RT_EFORMAT, "NRRD header has no 'dimension' field");
    if (!have_sizes)
        return rt_fail(e, RT_EFORMAT, "NRRD header has no 'sizes' field");
    if (!have_enc)
        return rt_fail(e, RT_EFORMAT, "NRRD header has no 'encoding' field");
    if (sample_size((sample_type)type) > 1 && endian < 0)
        return rt_fail(e, RT_EFORMAT, "NRRD header has no 'endian' field for %zu-byte samples", sample_size((sample_type)type));
    if (have_dirs && have_sp)
        return rt_fail(e, RT_EFORMAT, "NRRD header has both 'space directions' and 'spacings'");
    size_t count = rt_mul_size(rt_mul_size((size_t)sizes[0], (size_t)sizes[1]), (size_t)sizes[2]);
    size_t need = rt_mul_size(count, sample_size((sample_type)type));
    if (!need)
        return rt_fail(e, RT_EFORMAT, "NRRD sizes are too large");
    rt_code lc = rt_check_voxels((double)sizes[0], (double)sizes[1], (double)sizes[2], e);
    if (lc) /* before reading a detached data file or allocating the volume */
        return lc;

    const unsigned char *data = d;
    size_t dn = n;
    unsigned char *file = NULL;
    if (datafile[0]) {
        if (!dir)
            return rt_fail(e, RT_EFORMAT, "NRRD detached data file '%s' cannot be located", datafile);
        size_t pl = strlen(dir) + strlen(datafile) + 2;
        char *path = rt_malloc(pl);
        if (!path)
            return rt_fail(e, RT_ENOMEM, "out of memory");
        if (datafile[0] == '/' || !dir[0])
            snprintf(path, pl, "%s", datafile);
        else
            snprintf(path, pl, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", datafile);
        rt_code rc = fileio_read_all(path, need + (byte_skip > 0 ? (size_t)byte_skip : 0) + (1u << 20) + need,
                                     &file, &dn, e);
        rt_free(path);
        if (rc)
            return rc;
        data = file;
        data_at = 0;
    } else if (!ended) {
        return rt_fail(e, RT_EFORMAT, "NRRD header has no blank line before the data and no data file");
    }
    size_t at = data_at;
    /* stop at the end of the data: a huge line skip must not loop on
     * (found by the fuzzer: "line skip: 66666666674" ran for minutes) */
    for (long l = 0; l < line_skip && at < dn; l++) {
        while (at < dn && data[at] != '\n')
            at++;
        if (at < dn)
            at++;
    }
    if (byte_skip == -1)
        at = dn >= need ? dn - need : 0;
    else
        at += (size_t)byte_skip;
    if (at > dn || dn - at < need) {
        rt_free(file);
        return rt_fail(e, RT_EFORMAT, "NRRD data is %zu bytes, expected %zu (%ld×%ld×%ld samples of %zu byte(s))",
                       at > dn ? 0 : dn - at, need, sizes[0], sizes[1], sizes[2], sample_size((sample_type)type));
    }
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        if (have_org) {
            lo[k] = org[k] - 0.5 * sp[k];
        } else {
            lo[k] = 0;
        }
        hi[k] = lo[k] + sp[k] * (double)sizes[k];
        if (have_lo && have_hi) {
            lo[k] = flo[k];
            hi[k] = fhi[k];
        }
    }
    const int dims[3] = {(int)sizes[0], (int)sizes[1], (int)sizes[2]};
    rt_code rc = volume_of_samples(v, dims, lo, hi, data + at, type, endian == 1, "NRRD origin and spacing", e);
    rt_free(file);
    return rc;
}

rt_code vio_load_nrrd(const char *path, volume *v, rt_error *e)
{
    unsigned char *d;
    size_t n;
    rt_code rc = read_volume_file(path, v, &d, &n, e);
    if (rc)
        return rc;
    size_t dl = dir_len(path);
    char *dir = rt_malloc(dl + 1);
    if (!dir) {
        rt_free(d);
        return rt_fail(e, RT_ENOMEM, "out of memory");
    }
    memcpy(dir, path, dl);
    dir[dl] = 0;
    rc = vio_nrrd_from_mem(d, n, dir, v, e);
    rt_free(dir);
    rt_free(d);
    return rc;
}

rt_code vio_vtk_from_mem(const unsigned char *d, size_t n, volume *v, rt_error *e)
{
    v->v = NULL;
    size_t pos = 0;
    char line[512];
    if (textline_next(d, n, &pos, line, sizeof line) < 0 || strncmp(line, "# vtk DataFile Version", 22) != 0)
        return rt_fail(e, RT_EFORMAT, "not a legacy VTK file (no '# vtk DataFile Version' line)");
    if (textline_next(d, n, &pos, line, sizeof line) < 0)
        return rt_fail(e, RT_EFORMAT, "VTK file ends after its first line");
    if (textline_next(d, n, &pos, line, sizeof line) < 0 || strcmp(line, "BINARY") != 0)
        return rt_fail(e, RT_EFORMAT, "VTK line 3: '%.40s', only BINARY is read", line);
    if (textline_next(d, n, &pos, line, sizeof line) < 0 || strcmp(line, "DATASET STRUCTURED_POINTS") != 0)
        return rt_fail(e, RT_EFORMAT, "VTK line 4: '%.40s', only DATASET STRUCTURED_POINTS is read", line);
    double dims[3] = {0, 0, 0}, org[3] = {0, 0, 0}, sp[3] = {1, 1, 1};
    int have_dims = 0, lineno = 4;
    for (;;) {
        lineno++;
        if (textline_next(d, n, &pos, line, sizeof line) < 0)
            return rt_fail(e, RT_EFORMAT, "VTK file ends in its header");
        if (!line[0])
            continue;
        if (strncmp(line, "DIMENSIONS ", 11) == 0) {
            if (parse_nums(line + 11, dims, 3))
                return rt_fail(e, RT_EFORMAT, "VTK line %d: DIMENSIONS needs 3 numbers", lineno);
            for (int k = 0; k < 3; k++)
                if (!(dims[k] >= 1 && dims[k] <= 1e9) || dims[k] != floor(dims[k]))
                    return rt_fail(e, RT_EFORMAT, "VTK line %d: dimension %g is not a positive integer",
                                   lineno, dims[k]);
            have_dims = 1;
        } else if (strncmp(line, "ORIGIN ", 7) == 0) {
            if (parse_nums(line + 7, org, 3))
                return rt_fail(e, RT_EFORMAT, "VTK line %d: ORIGIN needs 3 numbers", lineno);
        } else if (strncmp(line, "SPACING ", 8) == 0 || strncmp(line, "ASPECT_RATIO ", 13) == 0) {
            if (parse_nums(strchr(line, ' ') + 1, sp, 3) || !(sp[0] > 0 && sp[1] > 0 && sp[2] > 0))
                return rt_fail(e, RT_EFORMAT, "VTK line %d: SPACING needs 3 positive numbers", lineno);
        } else if (strncmp(line, "POINT_DATA ", 11) == 0) {
            continue;
        } else if (strncmp(line, "SCALARS ", 8) == 0) {
            char name[256], ty[64];
            if (sscanf(line + 8, "%255s %63s", name, ty) != 2 || strcmp(ty, "float") != 0)
                return rt_fail(e, RT_EFORMAT, "VTK line %d: only 'SCALARS name float' is read", lineno);
        } else if (strncmp(line, "LOOKUP_TABLE ", 13) == 0) {
            break;
        } else {
            return rt_fail(e, RT_EFORMAT, "VTK line %d: unexpected '%.40s'", lineno, line);
        }
    }
    if (!have_dims)
        return rt_fail(e, RT_EFORMAT, "VTK header has no DIMENSIONS");
    size_t count = rt_mul_size(rt_mul_size((size_t)dims[0], (size_t)dims[1]), (size_t)dims[2]);
    if (!count || !rt_mul_size(count, 4))
        return rt_fail(e, RT_EFORMAT, "VTK dimensions are too large");
    rt_code lc = rt_check_voxels((double)dims[0], (double)dims[1], (double)dims[2], e);
    if (lc)
        return lc;
    if (n - pos < count * 4)
        return rt_fail(e, RT_EFORMAT, "VTK data is %zu bytes, expected %zu", n - pos, count * 4);
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = org[k] - 0.5 * sp[k];
        hi[k] = lo[k] + sp[k] * dims[k];
    }
    const int nd[3] = {(int)dims[0], (int)dims[1], (int)dims[2]};
    return volume_of_samples(v, nd, lo, hi, d + pos, SAMPLE_F32, 1, "VTK ORIGIN and SPACING", e);
}

rt_code vio_load_vtk(const char *path, volume *v, rt_error *e)
{
    unsigned char *d;
    size_t n;
    rt_code rc = read_volume_file(path, v, &d, &n, e);
    if (rc)
        return rc;
    rc = vio_vtk_from_mem(d, n, v, e);
    rt_free(d);
    return rc;
}

rt_code volume_slice_axis(const volume *v, int axis, int index, const ramp *r, double vmin,
                          double vmax, image *out, rt_error *e)
{
    static const char *axn = "xyz";
    int n[3] = {v->nx, v->ny, v->nz};
    out->px = NULL;
    out->src = NULL;
    if (axis < 0 || axis > 2)
        return rt_fail(e, RT_EINVAL, "slice axis %d is not 0 (x), 1 (y) or 2 (z)", axis);
    if (index < 0 || index >= n[axis])
        return rt_fail(e, RT_EINVAL, "slice index %d along %c is not in 0..%d", index, axn[axis],
                       n[axis] - 1);
    if (!(vmin < vmax) || !isfinite(vmax - vmin))
        return rt_fail(e, RT_EINVAL, "slice range [%g, %g] is empty", vmin, vmax);
    int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2; /* image x and y axes */
    rt_code rc = image_init(out, n[ua], n[va], e);
    if (rc)
        return rc;
    for (int py = 0; py < n[va]; py++)
        for (int px = 0; px < n[ua]; px++) {
            int idx[3];
            idx[axis] = index;
            idx[ua] = px;
            idx[va] = n[va] - 1 - py; /* top row = highest index */
            double t = (*volume_at(v, idx[0], idx[1], idx[2]) - vmin) / (vmax - vmin);
            float *p = image_at(out, px, py);
            if (r) {
                ramp_eval(r, t, p);
            } else {
                float g = (float)(t > 0 ? (t < 1 ? t : 1) : 0);
                p[0] = p[1] = p[2] = g;
                p[3] = 1;
            }
        }
    return RT_OK;
}
