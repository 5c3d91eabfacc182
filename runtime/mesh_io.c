/* mesh_io.c — PLY, OBJ and binary STL writers and readers (see mesh_io.h). */
#include "mesh_io.h"
#include "rt_alloc.h"
#include "provenance.h"
#include "sample.h"
#include "textline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char to_u8(float c)
{
    double t = c > 0 ? (c < 1 ? c : 1) : 0;
    return (unsigned char)lround(t * 255.0);
}

static rt_code finish(bytebuf *out, rt_error *e)
{
    return out->failed ? rt_fail(e, RT_ENOMEM, "out of memory writing a mesh") : RT_OK;
}

rt_code mio_ply_to_mem(const mesh *m, int ascii, bytebuf *out, rt_error *e)
{
    if (m->failed)
        return rt_fail(e, RT_ENOMEM, "mesh is incomplete (an allocation failed)");
    bytebuf_printf(out, "ply\nformat %s 1.0\ncomment frac mesh\n", ascii ? "ascii" : "binary_little_endian");
    prov_put_lines(out, "comment ");
    bytebuf_printf(out, "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n", m->nv);
    if (m->nrm)
        bytebuf_printf(out, "property float nx\nproperty float ny\nproperty float nz\n");
    if (m->col)
        bytebuf_printf(out, "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n");
    if (m->nt)
        bytebuf_printf(out, "element face %zu\nproperty list uchar int vertex_indices\n", m->nt);
    bytebuf_printf(out, "end_header\n");
    for (size_t i = 0; i < m->nv && !out->failed; i++) {
        const float *p = m->pos + 3 * i;
        if (ascii) {
            bytebuf_printf(out, "%.9g %.9g %.9g", p[0], p[1], p[2]);
            if (m->nrm)
                bytebuf_printf(out, " %.9g %.9g %.9g", m->nrm[3 * i], m->nrm[3 * i + 1], m->nrm[3 * i + 2]);
            if (m->col)
                for (int k = 0; k < 4; k++)
                    bytebuf_printf(out, " %u", to_u8(m->col[4 * i + k]));
            bytebuf_printf(out, "\n");
        } else {
            for (int k = 0; k < 3; k++)
                bytebuf_f32le(out, p[k]);
            if (m->nrm)
                for (int k = 0; k < 3; k++)
                    bytebuf_f32le(out, m->nrm[3 * i + k]);
            if (m->col)
                for (int k = 0; k < 4; k++)
                    bytebuf_byte(out, to_u8(m->col[4 * i + k]));
        }
    }
    for (size_t t = 0; t < m->nt && !out->failed; t++) {
        const uint32_t *v = m->tri + 3 * t;
        if (ascii) {
            bytebuf_printf(out, "3 %u %u %u\n", (unsigned)v[0], (unsigned)v[1], (unsigned)v[2]);
        } else {
            bytebuf_byte(out, 3);
            for (int k = 0; k < 3; k++)
                bytebuf_u32le(out, v[k]);
        }
    }
    return finish(out, e);
}

rt_code mio_obj_to_mem(const mesh *m, bytebuf *out, rt_error *e)
{
    if (m->failed)
        return rt_fail(e, RT_ENOMEM, "mesh is incomplete (an allocation failed)");
    bytebuf_printf(out, "# frac mesh\n");
    prov_put_lines(out, "# ");
    for (size_t i = 0; i < m->nv && !out->failed; i++) {
        const float *p = m->pos + 3 * i;
        bytebuf_printf(out, "v %.9g %.9g %.9g", p[0], p[1], p[2]);
        if (m->col)
            bytebuf_printf(out, " %.9g %.9g %.9g", m->col[4 * i], m->col[4 * i + 1], m->col[4 * i + 2]);
        bytebuf_printf(out, "\n");
    }
    if (m->nrm)
        for (size_t i = 0; i < m->nv && !out->failed; i++)
            bytebuf_printf(out, "vn %.9g %.9g %.9g\n", m->nrm[3 * i], m->nrm[3 * i + 1], m->nrm[3 * i + 2]);
    for (size_t t = 0; t < m->nt && !out->failed; t++) {
        unsigned a = m->tri[3 * t] + 1u, b = m->tri[3 * t + 1] + 1u, c = m->tri[3 * t + 2] + 1u;
        if (m->nrm)
            bytebuf_printf(out, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
        else
            bytebuf_printf(out, "f %u %u %u\n", a, b, c);
    }
    return finish(out, e);
}

rt_code mio_stl_to_mem(const mesh *m, bytebuf *out, rt_error *e)
{
    if (m->failed)
        return rt_fail(e, RT_ENOMEM, "mesh is incomplete (an allocation failed)");
    if (m->nt > UINT32_MAX)
        return rt_fail(e, RT_EINVAL, "mesh has %zu triangles, more than STL can hold", m->nt);
    unsigned char hdr[80] = "frac mesh";
    const prov *pv = prov_get(); /* the one-line recipe, cut to the 80 bytes there are */
    if (pv && pv->oneline) {
        size_t l = strlen(pv->oneline);
        memset(hdr, ' ', sizeof hdr);
        memcpy(hdr, pv->oneline, l < sizeof hdr ? l : sizeof hdr);
    }
    bytebuf_append(out, hdr, 80);
    bytebuf_u32le(out, (uint32_t)m->nt);
    for (size_t t = 0; t < m->nt && !out->failed; t++) {
        const float *p[3];
        for (int k = 0; k < 3; k++)
            p[k] = m->pos + 3 * (size_t)m->tri[3 * t + k];
        double u[3], w[3];
        for (int k = 0; k < 3; k++) {
            u[k] = (double)p[1][k] - p[0][k];
            w[k] = (double)p[2][k] - p[0][k];
        }
        double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            bytebuf_f32le(out, l > 0 ? (float)(n[k] / l) : 0.0f);
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                bytebuf_f32le(out, p[v][k]);
        bytebuf_u16le(out, 0);
    }
    return finish(out, e);
}

static rt_code save_with(const char *path, const mesh *m, int kind, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code rc = kind == 0 ? mio_ply_to_mem(m, 0, &b, e)
                 : kind == 1 ? mio_ply_to_mem(m, 1, &b, e)
                 : kind == 2 ? mio_obj_to_mem(m, &b, e)
                             : mio_stl_to_mem(m, &b, e);
    if (!rc)
        rc = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return rc;
}

rt_code mio_save_ply(const char *path, const mesh *m, int ascii, rt_error *e)
{
    return save_with(path, m, ascii ? 1 : 0, e);
}

rt_code mio_save(const char *path, const mesh *m, rt_error *e)
{
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "ply") == 0)
        return save_with(path, m, 0, e);
    if (strcmp(ext, "obj") == 0)
        return save_with(path, m, 2, e);
    if (strcmp(ext, "stl") == 0)
        return save_with(path, m, 3, e);
    return rt_fail(e, RT_EINVAL, "mesh file '%s' does not end in .ply, .obj or .stl", path);
}

/* ---- readers ---- */

static rt_code reader_oom(mesh *m, rt_error *e)
{
    return m->failed ? rt_fail(e, RT_ENOMEM, "out of memory reading a mesh") : RT_OK;
}

static int ply_type(const char *s)
{
    static const struct {
        const char *n;
        int t;
    } tt[] = {{"char", SAMPLE_I8},    {"int8", SAMPLE_I8},     {"uchar", SAMPLE_U8},    {"uint8", SAMPLE_U8},
              {"short", SAMPLE_I16},  {"int16", SAMPLE_I16},   {"ushort", SAMPLE_U16},  {"uint16", SAMPLE_U16},
              {"int", SAMPLE_I32},    {"int32", SAMPLE_I32},   {"uint", SAMPLE_U32},    {"uint32", SAMPLE_U32},
              {"float", SAMPLE_F32},  {"float32", SAMPLE_F32}, {"double", SAMPLE_F64},  {"float64", SAMPLE_F64}};
    for (size_t i = 0; i < sizeof tt / sizeof tt[0]; i++)
        if (strcmp(s, tt[i].n) == 0)
            return tt[i].t;
    return SAMPLE_NONE;
}

#define PLY_MAXPROP 32
#define PLY_MAXELEM 16

typedef struct ply_prop {
    char name[64];
    int type, count_type; /* count_type != SAMPLE_NONE: a list */
} ply_prop;

typedef struct ply_elem {
    char name[64];
    size_t count;
    int nprop;
    ply_prop prop[PLY_MAXPROP];
} ply_elem;

typedef struct ply_in {
    const unsigned char *d;
    size_t n, pos;
    int fmt; /* 0 ascii, 1 LE, 2 BE */
    int bad;
} ply_in;

static double ply_read(ply_in *in, int t)
{
    if (in->bad)
        return 0;
    if (in->fmt == 0) {
        while (in->pos < in->n && (in->d[in->pos] == ' ' || in->d[in->pos] == '\t' ||
                                   in->d[in->pos] == '\n' || in->d[in->pos] == '\r'))
            in->pos++;
        char tmp[64];
        size_t k = 0;
        while (in->pos < in->n && k < sizeof tmp - 1 && in->d[in->pos] > ' ')
            tmp[k++] = (char)in->d[in->pos++];
        tmp[k] = 0;
        char *end;
        double v = strtod(tmp, &end);
        if (!k || *end)
            in->bad = 1;
        return v;
    }
    size_t sz = sample_size((sample_type)t);
    if (in->n - in->pos < sz) {
        in->bad = 1;
        return 0;
    }
    double v = sample_get(in->d + in->pos, (sample_type)t, in->fmt == 2);
    in->pos += sz;
    return v;
}

static int add_poly(mesh *m, const double *idx, size_t k, size_t nv)
{
    for (size_t i = 0; i < k; i++)
        if (!(idx[i] >= 0 && idx[i] < (double)nv))
            return -1;
    for (size_t i = 1; i + 1 < k; i++)
        mesh_add_tri(m, (uint32_t)idx[0], (uint32_t)idx[i], (uint32_t)idx[i + 1]);
    return 0;
}

rt_code mio_ply_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e)
{
    mesh_init(m, 0, 0);
    if (n < 4 || memcmp(d, "ply", 3) != 0 || (d[3] != '\n' && d[3] != '\r'))
        return rt_fail(e, RT_EFORMAT, "not a PLY file (no 'ply' magic line)");
    ply_elem el[PLY_MAXELEM];
    int nel = 0, fmt = -1, lineno = 0;
    size_t pos = 0;
    char line[512];
    for (;;) {
        if (textline_next(d, n, &pos, line, sizeof line) < 0)
            return rt_fail(e, RT_EFORMAT, "PLY header has no end_header");
        lineno++;
        char a[64], b[64], c[64], dd[64];
        int nw = sscanf(line, "%63s %63s %63s %63s", a, b, c, dd);
        if (nw <= 0 || strcmp(a, "comment") == 0 || strcmp(a, "obj_info") == 0 || strcmp(a, "ply") == 0)
            continue;
        if (strcmp(a, "end_header") == 0)
            break;
        if (strcmp(a, "format") == 0 && nw >= 2) {
            fmt = strcmp(b, "ascii") == 0 ? 0 : strcmp(b, "binary_little_endian") == 0 ? 1
                  : strcmp(b, "binary_big_endian") == 0 ? 2 : -2;
            if (fmt == -2)
                return rt_fail(e, RT_EFORMAT, "PLY header line %d: unknown format '%s'", lineno, b);
        } else if (strcmp(a, "element") == 0 && nw >= 3) {
            if (nel == PLY_MAXELEM)
                return rt_fail(e, RT_EFORMAT, "PLY header line %d: more than %d elements", lineno, PLY_MAXELEM);
            char *endp;
            double cnt = strtod(c, &endp);
            if (*endp || !(cnt >= 0 && cnt < 4e9) || cnt != floor(cnt))
                return rt_fail(e, RT_EFORMAT, "PLY header line %d: element count '%s'", lineno, c);
            memset(&el[nel], 0, sizeof el[nel]);
            snprintf(el[nel].name, sizeof el[nel].name, "%s", b);
            el[nel].count = (size_t)cnt;
            nel++;
        } else if (strcmp(a, "property") == 0 && nw >= 3) {
            if (!nel)
                return rt_fail(e, RT_EFORMAT, "PLY header line %d: property before any element", lineno);
            ply_elem *E = &el[nel - 1];
            if (E->nprop == PLY_MAXPROP)
                return rt_fail(e, RT_EFORMAT, "PLY header line %d: too many properties", lineno);
            ply_prop *P = &E->prop[E->nprop++];
            if (strcmp(b, "list") == 0) {
                char f5[64] = "";
                if (nw < 4 || sscanf(line, "%*s %*s %*s %*s %63s", f5) != 1)
                    return rt_fail(e, RT_EFORMAT, "PLY header line %d: list property needs two types and a name", lineno);
                P->count_type = ply_type(c);
                P->type = ply_type(dd);
                snprintf(P->name, sizeof P->name, "%s", f5);
                if (!P->count_type || !P->type)
                    return rt_fail(e, RT_EFORMAT, "PLY header line %d: unknown type in '%s'", lineno, line);
            } else {
                P->type = ply_type(b);
                P->count_type = SAMPLE_NONE;
                snprintf(P->name, sizeof P->name, "%s", c);
                if (!P->type)
                    return rt_fail(e, RT_EFORMAT, "PLY header line %d: unknown type '%s'", lineno, b);
            }
        } else {
            return rt_fail(e, RT_EFORMAT, "PLY header line %d: unexpected '%.60s'", lineno, line);
        }
    }
    if (fmt < 0)
        return rt_fail(e, RT_EFORMAT, "PLY header has no format line");
    /* Which attributes does the vertex element carry? */
    int have_n = 0, have_c = 0;
    size_t nverts = 0;
    for (int i = 0; i < nel; i++)
        if (strcmp(el[i].name, "vertex") == 0) {
            nverts = el[i].count;
            for (int k = 0; k < el[i].nprop; k++) {
                have_n |= strcmp(el[i].prop[k].name, "nx") == 0;
                have_c |= strcmp(el[i].prop[k].name, "red") == 0;
            }
        }
    /* the declared vertices and faces (one triangle each at least), before
     * any is read */
    double nfaces = 0;
    for (int i = 0; i < nel; i++)
        if (strcmp(el[i].name, "face") == 0)
            nfaces = (double)el[i].count;
    rt_code lc = rt_check_bytes((double)nverts * (12 + (have_n ? 12 : 0) + (have_c ? 16 : 0)) + nfaces * 12,
                                "reading the PLY vertices and faces", e);
    if (lc)
        return lc;
    /* Every property of every row takes at least one byte of data (binary:
     * its size; ASCII: a digit and a separator), so the declared rows must
     * fit in what is left of the file. Without this a vertex element with
     * no properties and a count of 10^9 reads nothing a billion times. */
    double need = 0;
    for (int i = 0; i < nel; i++) {
        if (el[i].count > 0 && el[i].nprop == 0)
            return rt_fail(e, RT_EFORMAT, "PLY element '%s' has %zu rows but no properties", el[i].name,
                           el[i].count);
        need += (double)el[i].count * el[i].nprop;
    }
    if (need > (double)(n - pos))
        return rt_fail(e, RT_EFORMAT, "PLY header declares at least %.0f bytes of data, the file holds %zu", need,
                       n - pos);
    mesh_free(m);
    mesh_init(m, have_n, have_c);
    ply_in in = {d, n, pos, fmt, 0};
    double idx[256];
    for (int i = 0; i < nel; i++) {
        ply_elem *E = &el[i];
        int is_v = strcmp(E->name, "vertex") == 0, is_f = strcmp(E->name, "face") == 0;
        for (size_t r = 0; r < E->count && !in.bad; r++) {
            float p[3] = {0, 0, 0}, nn[3] = {0, 0, 0}, cc[4] = {1, 1, 1, 1};
            for (int k = 0; k < E->nprop; k++) {
                ply_prop *P = &E->prop[k];
                if (P->count_type) {
                    double cnt = ply_read(&in, P->count_type);
                    if (!(cnt >= 0 && cnt <= 255)) {
                        in.bad = 1;
                        break;
                    }
                    size_t kk = (size_t)cnt;
                    int use = is_f && (strcmp(P->name, "vertex_indices") == 0 || strcmp(P->name, "vertex_index") == 0);
                    for (size_t q = 0; q < kk; q++)
                        idx[q] = ply_read(&in, P->type);
                    if (use && !in.bad && add_poly(m, idx, kk, nverts))
                        return rt_fail(e, RT_EFORMAT, "PLY face %zu has a vertex index out of 0..%zu", r,
                                       nverts ? nverts - 1 : 0);
                    continue;
                }
                double v = ply_read(&in, P->type);
                if (!is_v)
                    continue;
                static const char *names[10] = {"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue", "alpha"};
                for (int q = 0; q < 10; q++)
                    if (strcmp(P->name, names[q]) == 0) {
                        if (q < 3)
                            p[q] = (float)v;
                        else if (q < 6)
                            nn[q - 3] = (float)v;
                        else
                            cc[q - 6] = (float)(P->type == SAMPLE_F32 || P->type == SAMPLE_F64 ? v : v / 255.0);
                    }
            }
            if (is_v && !in.bad)
                mesh_add_vertex(m, p, nn, cc);
        }
        if (in.bad)
            return rt_fail(e, RT_EFORMAT, "PLY data for element '%s' is truncated or malformed", E->name);
    }
    return reader_oom(m, e);
}

/* Parse a 1-based (or negative, relative) OBJ index; 0 on error. */
static long obj_index(const char *s, char **end, size_t count)
{
    long v = strtol(s, end, 10);
    if (*end == s)
        return 0;
    if (v < 0)
        v = (long)count + v + 1;
    if (v < 1 || (size_t)v > count)
        return 0;
    return v;
}

rt_code mio_obj_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e)
{
    /* First pass: which attributes exist; collect normals. */
    size_t nvn = 0, cap_vn = 0, nv = 0;
    float *vn = NULL;
    int have_c = 0, lineno = 0;
    char line[4096];
    /* initialised before the first pass too: its errors return at once and
     * the caller mesh_frees *m (found by the fuzzer) */
    mesh_init(m, 0, 0);
    for (int pass = 0; pass < 2; pass++) {
        size_t pos = 0;
        lineno = 0;
        if (pass == 1) {
            mesh_free(m);
            mesh_init(m, nvn > 0, have_c);
            nv = 0;
        }
        while (pos < n) {
            textline_next(d, n, &pos, line, sizeof line);
            lineno++;
            char *s = line;
            while (*s == ' ' || *s == '\t')
                s++;
            if (s[0] == 'v' && (s[1] == ' ' || s[1] == '\t')) {
                double c[6];
                int k = 0;
                char *p = s + 2, *q;
                while (k < 6) {
                    c[k] = strtod(p, &q);
                    if (q == p)
                        break;
                    p = q;
                    k++;
                }
                if (k < 3) {
                    rt_free(vn);
                    if (pass == 1)
                        mesh_free(m);
                    return rt_fail(e, RT_EFORMAT, "OBJ line %d: vertex needs 3 coordinates", lineno);
                }
                if (pass == 0) {
                    have_c |= k == 6;
                    nv++;
                } else {
                    float p3[3] = {(float)c[0], (float)c[1], (float)c[2]};
                    float c4[4] = {k == 6 ? (float)c[3] : 1, k == 6 ? (float)c[4] : 1, k == 6 ? (float)c[5] : 1, 1};
                    mesh_add_vertex(m, p3, NULL, c4);
                    nv++;
                }
            } else if (s[0] == 'v' && s[1] == 'n' && (s[2] == ' ' || s[2] == '\t')) {
                if (pass == 1)
                    continue;
                double c[3];
                char *p = s + 3, *q;
                for (int k = 0; k < 3; k++) {
                    c[k] = strtod(p, &q);
                    if (q == p) {
                        rt_free(vn);
                        return rt_fail(e, RT_EFORMAT, "OBJ line %d: normal needs 3 components", lineno);
                    }
                    p = q;
                }
                if (nvn == cap_vn) {
                    cap_vn = cap_vn ? 2 * cap_vn : 64;
                    float *nb = rt_realloc(vn, cap_vn * 3 * sizeof(float));
                    if (!nb) {
                        rt_free(vn);
                        return rt_fail(e, RT_ENOMEM, "out of memory reading a mesh");
                    }
                    vn = nb;
                }
                for (int k = 0; k < 3; k++)
                    vn[3 * nvn + (size_t)k] = (float)c[k];
                nvn++;
            } else if (s[0] == 'f' && (s[1] == ' ' || s[1] == '\t') && pass == 1) {
                double idx[256];
                size_t k = 0;
                char *p = s + 2;
                for (;;) {
                    while (*p == ' ' || *p == '\t' || *p == '\r')
                        p++;
                    if (!*p)
                        break;
                    char *q;
                    long vi = obj_index(p, &q, nv), ni = 0;
                    if (!vi || k == 256) {
                        rt_free(vn);
                        mesh_free(m);
                        return rt_fail(e, RT_EFORMAT, "OBJ line %d: face index out of 1..%zu", lineno, nv);
                    }
                    p = q;
                    if (*p == '/') {
                        p++;
                        if (*p != '/')
                            strtol(p, &p, 10); /* texture index, unused */
                        if (*p == '/') {
                            p++;
                            ni = obj_index(p, &q, nvn);
                            if (!ni) {
                                rt_free(vn);
                                mesh_free(m);
                                return rt_fail(e, RT_EFORMAT, "OBJ line %d: normal index out of 1..%zu", lineno, nvn);
                            }
                            p = q;
                        }
                    }
                    if (ni && m->nrm && !m->failed)
                        memcpy(m->nrm + 3 * (size_t)(vi - 1), vn + 3 * (size_t)(ni - 1), 3 * sizeof(float));
                    idx[k++] = (double)(vi - 1);
                }
                if (k < 3) {
                    rt_free(vn);
                    mesh_free(m);
                    return rt_fail(e, RT_EFORMAT, "OBJ line %d: face has fewer than 3 vertices", lineno);
                }
                add_poly(m, idx, k, nv);
            }
        }
    }
    rt_free(vn);
    return reader_oom(m, e);
}

/* ---- STL: pieces apart again ----
 * Welding equal positions also joins separate closed pieces that touch (the
 * K_n of a function set): an edge where two pieces meet gets four
 * triangles. So after welding, the triangles are grouped into pieces by
 * their edges, and each piece gets its own copies of the vertices it shares
 * with another. An edge of two triangles joins them. At an edge (a, b) of
 * more triangles the pairs are found by turning about it: each triangle
 * wound a→b closes, with the first triangle wound b→a met when turning from
 * it into its inside (the side its normal points away from), the wedge of
 * one piece's solid; each b→a triangle closes one wedge. (Two pieces sharing
 * a face give two coincident triangles of opposite winding; each stays with
 * its own piece. A piece given twice ties: the nearer triangle in the file
 * wins.) A mesh
 * whose vertices all lie on one edge-connected piece comes back unchanged. */

typedef struct edge_use {
    uint32_t lo, hi; /* the undirected edge, lo < hi */
    uint32_t use;    /* 3 t + k: corner k of triangle t starts it */
} edge_use;

static int edge_use_cmp(const void *pa, const void *pb)
{
    const edge_use *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return a->use < b->use ? -1 : a->use > b->use;
}

static uint32_t uf_find(uint32_t *parent, uint32_t t)
{
    while (parent[t] != t) {
        parent[t] = parent[parent[t]];
        t = parent[t];
    }
    return t;
}

static void uf_join(uint32_t *parent, uint32_t a, uint32_t b)
{
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a != b)
        parent[a > b ? a : b] = a < b ? a : b; /* the smaller index is the root: deterministic */
}

/* the pairs at one edge of n >= 3 uses (see above) */
static void join_around_edge(const mesh *m, const edge_use *u, size_t n, unsigned char *taken, uint32_t *parent)
{
    const float *pa = m->pos + 3 * (size_t)u[0].lo, *pb = m->pos + 3 * (size_t)u[0].hi;
    double ax[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]};
    double len = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    if (!(len > 0))
        return;
    for (int i = 0; i < 3; i++)
        ax[i] /= len;
    /* e1 ⊥ ax, e2 = ax × e1: angles about ax increase from e1 toward e2 */
    int k0 = fabs(ax[0]) < fabs(ax[1]) ? (fabs(ax[0]) < fabs(ax[2]) ? 0 : 2) : (fabs(ax[1]) < fabs(ax[2]) ? 1 : 2);
    double e1[3] = {0, 0, 0}, e2[3];
    e1[k0] = 1;
    double d = e1[0] * ax[0] + e1[1] * ax[1] + e1[2] * ax[2];
    for (int i = 0; i < 3; i++)
        e1[i] -= d * ax[i];
    double l1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int i = 0; i < 3; i++)
        e1[i] /= l1;
    e2[0] = ax[1] * e1[2] - ax[2] * e1[1];
    e2[1] = ax[2] * e1[0] - ax[0] * e1[2];
    e2[2] = ax[0] * e1[1] - ax[1] * e1[0];
    for (size_t i = 0; i < n; i++) {
        uint32_t t = u[i].use / 3, k = u[i].use % 3;
        if (m->tri[3 * t + k] != u[i].lo) /* wound b→a: found from its partner */
            continue;
        /* a→b: its normal ax × w turns toward increasing angle, its inside
         * toward decreasing: take the b→a use with the smallest turn in (0, 2π] */
        double best = INFINITY;
        size_t pick = n;
        const float *pc = m->pos + 3 * (size_t)m->tri[3 * t + (k + 2) % 3];
        double w[3] = {pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]};
        double th = atan2(w[0] * e2[0] + w[1] * e2[1] + w[2] * e2[2], w[0] * e1[0] + w[1] * e1[1] + w[2] * e1[2]);
        for (size_t j = 0; j < n; j++) {
            uint32_t tj = u[j].use / 3, kj = u[j].use % 3;
            if (m->tri[3 * tj + kj] == u[j].lo || taken[j])
                continue;
            const float *qc = m->pos + 3 * (size_t)m->tri[3 * tj + (kj + 2) % 3];
            double v[3] = {qc[0] - pa[0], qc[1] - pa[1], qc[2] - pa[2]};
            double tj_th = atan2(v[0] * e2[0] + v[1] * e2[1] + v[2] * e2[2], v[0] * e1[0] + v[1] * e1[1] + v[2] * e1[2]);
            double turn = th - tj_th;
            while (turn <= 0)
                turn += 2 * 3.14159265358979323846;
            while (turn > 2 * 3.14159265358979323846)
                turn -= 2 * 3.14159265358979323846;
            /* a tie: the same third vertex, a piece given twice; keep
             * neighbours in the file together */
            if (turn < best || (turn == best && pick < n && llabs((long long)tj - t) < llabs((long long)(u[pick].use / 3) - t))) {
                best = turn;
                pick = j;
            }
        }
        if (pick < n) {
            taken[pick] = 1;
            uf_join(parent, t, u[pick].use / 3);
        }
    }
}

typedef struct split_slot {
    uint64_t key; /* piece << 32 | vertex */
    uint32_t idx; /* UINT32_MAX = empty */
} split_slot;

/* *m welded; replaced by the same triangles with one set of vertices per piece */
static rt_code split_pieces(mesh *m, rt_error *e)
{
    size_t nt = m->nt, nu = 3 * nt;
    if (nt == 0 || nt > UINT32_MAX / 3) /* uses are numbered in 32 bits */
        return RT_OK;
    size_t cap = 16;
    while (cap < nu * 2)
        cap *= 2;
    rt_code lc = rt_check_bytes((double)nu * (sizeof(edge_use) + 1) + (double)nt * 4 + (double)cap * sizeof(split_slot) +
                                    (double)nu * 12 + (double)nt * 12,
                                "separating the STL's pieces", e);
    if (lc)
        return lc;
    edge_use *u = rt_malloc(nu * sizeof *u);
    uint32_t *parent = rt_malloc(nt * sizeof *parent);
    unsigned char *taken = rt_calloc(nu, 1);
    split_slot *tab = rt_malloc(cap * sizeof *tab);
    mesh out;
    mesh_init(&out, 0, 0);
    rt_code rc = RT_OK;
    if (!u || !parent || !taken || !tab) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory reading a mesh");
        goto done;
    }
    for (size_t i = 0; i < nu; i++) {
        uint32_t a = m->tri[i], b = m->tri[i % 3 == 2 ? i - 2 : i + 1];
        u[i].lo = a < b ? a : b;
        u[i].hi = a < b ? b : a;
        u[i].use = (uint32_t)i;
    }
    qsort(u, nu, sizeof *u, edge_use_cmp);
    for (size_t t = 0; t < nt; t++)
        parent[t] = (uint32_t)t;
    for (size_t i = 0; i < nu;) {
        size_t j = i + 1;
        while (j < nu && u[j].lo == u[i].lo && u[j].hi == u[i].hi)
            j++;
        if (j - i == 2)
            uf_join(parent, u[i].use / 3, u[i + 1].use / 3);
        else if (j - i > 2 && u[i].lo != u[i].hi)
            join_around_edge(m, u + i, j - i, taken + i, parent);
        i = j;
    }
    for (size_t i = 0; i < cap; i++)
        tab[i].idx = UINT32_MAX;
    for (size_t t = 0; t < nt && !out.failed; t++) {
        uint32_t piece = uf_find(parent, (uint32_t)t), v[3];
        for (int k = 0; k < 3; k++) {
            uint64_t key = (uint64_t)piece << 32 | m->tri[3 * t + k];
            size_t s = (size_t)((key * 0x9e3779b97f4a7c15ull) >> 20) & (cap - 1);
            while (tab[s].idx != UINT32_MAX && tab[s].key != key)
                s = (s + 1) & (cap - 1);
            if (tab[s].idx == UINT32_MAX) {
                tab[s].key = key;
                tab[s].idx = mesh_add_vertex(&out, m->pos + 3 * (size_t)m->tri[3 * t + k], NULL, NULL);
            }
            v[k] = tab[s].idx;
        }
        mesh_add_tri(&out, v[0], v[1], v[2]);
    }
    rc = reader_oom(&out, e);
done:
    rt_free(u);
    rt_free(parent);
    rt_free(taken);
    rt_free(tab);
    if (rc) {
        mesh_free(&out);
        return rc;
    }
    mesh_free(m);
    *m = out;
    return RT_OK;
}

/* Weld table: bit patterns of positions -> vertex index. */
typedef struct weld_slot {
    uint32_t key[3];
    uint32_t idx; /* UINT32_MAX = empty */
} weld_slot;

rt_code mio_stl_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e)
{
    mesh_init(m, 0, 0);
    if (n >= 5 && memcmp(d, "solid", 5) == 0 && (n < 84 || 84 + 50 * (size_t)sample_uint(d + 80, 4, 0) != n))
        return rt_fail(e, RT_EFORMAT, "ASCII STL is not read (only binary STL)");
    if (n < 84)
        return rt_fail(e, RT_EFORMAT, "STL file is %zu bytes, shorter than its 84-byte header", n);
    uint32_t nt = (uint32_t)sample_uint(d + 80, 4, 0);
    if ((n - 84) / 50 < nt)
        return rt_fail(e, RT_EFORMAT, "STL file holds %zu triangles, its header says %u", (n - 84) / 50, (unsigned)nt);
    size_t cap = 16;
    while (cap < (size_t)nt * 6 + 16)
        cap *= 2;
    /* the weld table and up to 3 vertices and one triangle per facet */
    rt_code lc = rt_check_bytes((double)cap * sizeof(weld_slot) + (double)nt * (3 * 12 + 12),
                                "reading the STL triangles", e);
    if (lc)
        return lc;
    weld_slot *tab = rt_malloc(cap * sizeof *tab);
    if (!tab)
        return rt_fail(e, RT_ENOMEM, "out of memory reading a mesh");
    for (size_t i = 0; i < cap; i++)
        tab[i].idx = UINT32_MAX;
    for (uint32_t t = 0; t < nt && !m->failed; t++) {
        const unsigned char *f = d + 84 + 50 * (size_t)t + 12;
        uint32_t v[3];
        for (int k = 0; k < 3; k++) {
            uint32_t key[3];
            float p[3];
            for (int a = 0; a < 3; a++) {
                const unsigned char *b = f + 12 * k + 4 * a;
                key[a] = (uint32_t)sample_uint(b, 4, 0);
                memcpy(&p[a], &key[a], 4);
            }
            uint64_t h = ((uint64_t)key[0] * 0x9e3779b97f4a7c15ull) ^ ((uint64_t)key[1] * 0xc2b2ae3d27d4eb4full) ^
                         ((uint64_t)key[2] * 0x165667b19e3779f9ull);
            size_t s = (size_t)(h >> 17) & (cap - 1);
            while (tab[s].idx != UINT32_MAX && memcmp(tab[s].key, key, sizeof key) != 0)
                s = (s + 1) & (cap - 1);
            if (tab[s].idx == UINT32_MAX) {
                memcpy(tab[s].key, key, sizeof key);
                tab[s].idx = mesh_add_vertex(m, p, NULL, NULL);
            }
            v[k] = tab[s].idx;
        }
        mesh_add_tri(m, v[0], v[1], v[2]);
    }
    rt_free(tab);
    rt_code rc = reader_oom(m, e);
    return rc ? rc : split_pieces(m, e);
}

rt_code mio_load(const char *path, mesh *m, rt_error *e)
{
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    mesh_init(m, 0, 0);
    int kind = strcmp(ext, "ply") == 0 ? 0 : strcmp(ext, "obj") == 0 ? 1 : strcmp(ext, "stl") == 0 ? 2 : -1;
    if (kind < 0)
        return rt_fail(e, RT_EINVAL, "mesh file '%s' does not end in .ply, .obj or .stl", path);
    unsigned char *d;
    size_t n;
    rt_code rc = fileio_read_all(path, (size_t)1 << 40, &d, &n, e);
    if (rc)
        return rc;
    mesh_free(m);
    rc = kind == 0 ? mio_ply_from_mem(d, n, m, e) : kind == 1 ? mio_obj_from_mem(d, n, m, e)
                                                           : mio_stl_from_mem(d, n, m, e);
    rt_free(d);
    return rc;
}
