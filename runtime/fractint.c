/* fractint.c — parser for Fractint .ifs files (format in fractint.h). */
#include "fractint.h"
#include "rt_alloc.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fileio.h"

typedef struct scan {
    const char *s;
    size_t len, pos;
    int line;
} scan;

/* skip spaces, newlines and ; comments */
static void skip_blank(scan *sc)
{
    while (sc->pos < sc->len) {
        char c = sc->s[sc->pos];
        if (c == ';') {
            while (sc->pos < sc->len && sc->s[sc->pos] != '\n')
                sc->pos++;
        } else if (c == '\n') {
            sc->line++;
            sc->pos++;
        } else if (isspace((unsigned char)c)) {
            sc->pos++;
        } else {
            break;
        }
    }
}

static int is_tok_end(char c)
{
    return isspace((unsigned char)c) || c == ';' || c == '}' || c == '{';
}

void fractint_free(fractint_list *l)
{
    for (int i = 0; i < l->n; i++) {
        rt_free(l->e[i].maps);
        rt_free(l->e[i].p);
    }
    rt_free(l->e);
    l->e = NULL;
    l->n = 0;
}

/* entry -> name ['(3D)'] '{' number* '}' */
static rt_code parse_entry(scan *sc, fractint_entry *en, rt_error *e)
{
    size_t start = sc->pos;
    en->line = sc->line;
    while (sc->pos < sc->len && sc->s[sc->pos] != '{' && sc->s[sc->pos] != '(' &&
           sc->s[sc->pos] != ';' && sc->s[sc->pos] != '\n')
        sc->pos++;
    size_t end = sc->pos;
    while (end > start && isspace((unsigned char)sc->s[end - 1]))
        end--;
    size_t nl = end - start < sizeof en->name - 1 ? end - start : sizeof en->name - 1;
    memcpy(en->name, sc->s + start, nl);
    en->name[nl] = 0;
    en->dim = 2;
    if (sc->pos < sc->len && sc->s[sc->pos] == '(') {
        size_t t0 = ++sc->pos;
        while (sc->pos < sc->len && sc->s[sc->pos] != ')' && sc->s[sc->pos] != '\n')
            sc->pos++;
        size_t tl = sc->pos - t0;
        if (sc->pos >= sc->len || sc->s[sc->pos] != ')' || tl != 2 ||
            strncasecmp(sc->s + t0, "3d", 2) != 0)
            return rt_fail(e, RT_EFORMAT, "line %d: expected '(3D)' after the entry name '%s'",
                           sc->line, en->name);
        sc->pos++;
        en->dim = 3;
    }
    skip_blank(sc);
    if (sc->pos >= sc->len || sc->s[sc->pos] != '{')
        return rt_fail(e, RT_EFORMAT, "line %d: expected '{' after the entry name '%s'", sc->line,
                       en->name);
    sc->pos++;
    int open_line = en->line;
    size_t cap = 0, nnum = 0;
    double *num = NULL;
    for (;;) {
        skip_blank(sc);
        if (sc->pos >= sc->len) {
            rt_free(num);
            return rt_fail(e, RT_EFORMAT, "line %d: entry '%s' opened at line %d is not closed with '}'",
                           sc->line, en->name, open_line);
        }
        if (sc->s[sc->pos] == '}') {
            sc->pos++;
            break;
        }
        size_t t0 = sc->pos;
        while (sc->pos < sc->len && !is_tok_end(sc->s[sc->pos]))
            sc->pos++;
        char tok[64];
        size_t tl = sc->pos - t0;
        if (tl == 0) /* a stray '{' */
            tl = 1, sc->pos++;
        size_t cl = tl < sizeof tok - 1 ? tl : sizeof tok - 1;
        memcpy(tok, sc->s + t0, cl);
        tok[cl] = 0;
        char *endp;
        double v = strtod(tok, &endp);
        if (tl >= sizeof tok || endp == tok || *endp || !isfinite(v)) {
            rt_free(num);
            return rt_fail(e, RT_EFORMAT, "line %d: expected a number or '}', found '%s'", sc->line,
                           tok);
        }
        if (nnum == cap) {
            cap = cap ? 2 * cap : 64;
            double *nn = rt_realloc(num, cap * sizeof *num);
            if (!nn) {
                rt_free(num);
                return rt_fail(e, RT_ENOMEM, "out of memory reading an .ifs file");
            }
            num = nn;
        }
        num[nnum++] = v;
    }
    size_t row = en->dim == 2 ? 7 : 13;
    if (nnum == 0) {
        rt_free(num);
        return rt_fail(e, RT_EFORMAT, "line %d: entry '%s' has no maps", sc->line, en->name);
    }
    if (nnum % row) {
        rt_free(num);
        return rt_fail(e, RT_EFORMAT, "line %d: entry '%s' has %zu numbers, not a whole number of %zu-number rows",
                       sc->line, en->name, nnum, row);
    }
    en->n = (int)(nnum / row);
    en->maps = rt_malloc(sizeof *en->maps * (size_t)en->n);
    en->p = rt_malloc(sizeof *en->p * (size_t)en->n);
    if (!en->maps || !en->p) {
        rt_free(num);
        return rt_fail(e, RT_ENOMEM, "out of memory reading an .ifs file");
    }
    for (int i = 0; i < en->n; i++) {
        const double *r = num + (size_t)i * row;
        if (en->dim == 2) {
            en->maps[i] = affine_from_2d(r[0], r[1], r[2], r[3], r[4], r[5]);
            en->p[i] = r[6];
        } else {
            en->maps[i] = affine_from_3d(r, r + 9);
            en->p[i] = r[12];
        }
    }
    rt_free(num);
    return RT_OK;
}

rt_code fractint_parse(const char *text, size_t len, fractint_list *out, rt_error *e)
{
    out->n = 0;
    out->e = NULL;
    scan sc = {text, len, 0, 1};
    int cap = 0;
    for (;;) {
        skip_blank(&sc);
        if (sc.pos >= sc.len)
            return RT_OK;
        if (out->n == cap) {
            cap = cap ? 2 * cap : 8;
            fractint_entry *ne = rt_realloc(out->e, sizeof *ne * (size_t)cap);
            if (!ne) {
                fractint_free(out);
                return rt_fail(e, RT_ENOMEM, "out of memory reading an .ifs file");
            }
            out->e = ne;
        }
        fractint_entry *en = &out->e[out->n];
        memset(en, 0, sizeof *en);
        rt_code rc = parse_entry(&sc, en, e);
        out->n++; /* so that fractint_free releases its arrays */
        if (rc) {
            fractint_free(out);
            return rc;
        }
    }
}

rt_code fractint_load(const char *path, fractint_list *out, rt_error *e)
{
    unsigned char *data;
    size_t n;
    out->n = 0;
    out->e = NULL;
    rt_code rc = fileio_read_all(path, (size_t)16 << 20, &data, &n, e);
    if (rc)
        return rc;
    rc = fractint_parse((const char *)data, n, out, e);
    rt_free(data);
    return rc;
}

const fractint_entry *fractint_find(const fractint_list *l, const char *name)
{
    for (int i = 0; i < l->n; i++)
        if (strcasecmp(l->e[i].name, name) == 0)
            return &l->e[i];
    return NULL;
}
