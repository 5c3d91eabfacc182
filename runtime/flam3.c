/* flam3.c — flame XML export (conventions in flam3.h). */
#include "flam3.h"
#include "provenance.h"

#include <stdlib.h>

static void put_escaped(bytebuf *b, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': bytebuf_printf(b, "&amp;"); break;
        case '<': bytebuf_printf(b, "&lt;"); break;
        case '>': bytebuf_printf(b, "&gt;"); break;
        case '"': bytebuf_printf(b, "&quot;"); break;
        default: bytebuf_byte(b, (unsigned char)*s);
        }
    }
}

static int to_byte(float v)
{
    double x = v < 0 ? 0 : v > 1 ? 1 : v;
    return (int)(x * 255 + 0.5);
}

rt_code flam3_write(const chaos_sys *s, const flam3_opts *o, bytebuf *out, rt_error *e)
{
    const affine *maps;
    const double *P = NULL, *p = NULL;
    int n, dim;
    if ((s->ifs != NULL) == (s->rifs != NULL))
        return rt_fail(e, RT_EINVAL, "flam3 export needs exactly one IFS or RIFS");
    if (s->ifs) {
        maps = s->ifs->maps, n = s->ifs->n, dim = s->ifs->dim, p = s->ifs->p;
    } else {
        if (s->rifs->order != 1)
            return rt_fail(e, RT_EINVAL,
                           "flam3 cannot express a Markov order %d RIFS (its xaos is order 1)",
                           s->rifs->order);
        maps = s->rifs->maps, n = s->rifs->n, dim = s->rifs->dim, P = s->rifs->P;
    }
    if (dim != 2)
        return rt_fail(e, RT_EINVAL, "flam3 export needs 2-D maps (these are %d-D)", dim);
    if (o->width < 1 || o->height < 1)
        return rt_fail(e, RT_EINVAL, "flame size %d×%d is empty", o->width, o->height);
    if (!(o->hi[0] > o->lo[0]) || !(o->hi[1] > o->lo[1]))
        return rt_fail(e, RT_EINVAL, "flame window is empty");
    if (o->map_c)
        for (int k = 0; k < n; k++)
            if (!(o->map_c[k] >= 0 && o->map_c[k] <= 1))
                return rt_fail(e, RT_EINVAL, "colour %d is %.6g (expected 0 .. 1)", k + 1, o->map_c[k]);
    double sy = o->keep_y ? 1 : -1;
    double cx = 0.5 * (o->lo[0] + o->hi[0]), cy = 0.5 * (o->lo[1] + o->hi[1]) * sy;
    /* scale: pixels per unit, fitting the window's width (the height follows
     * from the aspect of size) */
    double scale = o->width / (o->hi[0] - o->lo[0]);
    prov_put_xml_comment(out);
    bytebuf_printf(out, "<flame name=\"");
    put_escaped(out, o->name ? o->name : "frac");
    bytebuf_printf(out,
                   "\" version=\"frac\" size=\"%d %d\" center=\"%.17g %.17g\" scale=\"%.17g\" "
                   "rotate=\"0\" supersample=\"2\" filter=\"0.5\" quality=\"100\" "
                   "background=\"0 0 0\" brightness=\"4\" gamma=\"4\" vibrancy=\"1\">\n",
                   o->width, o->height, cx, cy, scale);
    for (int i = 0; i < n; i++) {
        const affine *a = &maps[i];
        double c = o->map_c ? o->map_c[i] : n > 1 ? (double)i / (n - 1) : 0;
        /* conjugation by S = diag(1, sy): m01, m10, t1 scale by sy */
        double A = a->m[0][0], B = a->m[1][0] * sy, C = a->m[0][1] * sy, D = a->m[1][1];
        double E = a->t[0], F = a->t[1] * sy;
        bytebuf_printf(out,
                       "  <xform weight=\"%.17g\" color=\"%.17g\" linear=\"1\" "
                       "coefs=\"%.17g %.17g %.17g %.17g %.17g %.17g\"",
                       p ? p[i] : 1.0, c, A, B, C, D, E, F);
        if (P) {
            bytebuf_printf(out, " chaos=\"");
            for (int j = 0; j < n; j++)
                bytebuf_printf(out, j ? " %.17g" : "%.17g", P[(size_t)i * n + j]);
            bytebuf_printf(out, "\"");
        }
        bytebuf_printf(out, "/>\n");
    }
    ramp grey = ramp_grey();
    const ramp *rp = o->ramp ? o->ramp : &grey;
    for (int i = 0; i < 256; i++) {
        float col[4];
        ramp_eval(rp, i / 255.0, col);
        bytebuf_printf(out, "  <color index=\"%d\" rgb=\"%d %d %d\"/>\n", i, to_byte(col[0]),
                       to_byte(col[1]), to_byte(col[2]));
    }
    bytebuf_printf(out, "</flame>\n");
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory writing a flame");
    return RT_OK;
}

rt_code flam3_save(const char *path, const chaos_sys *s, const flam3_opts *o, rt_error *e)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_code rc = flam3_write(s, o, &b, e);
    if (!rc)
        rc = fileio_write_atomic(path, b.data, b.len, e);
    bytebuf_free(&b);
    return rc;
}
