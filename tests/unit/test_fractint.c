/* test_fractint.c — the Fractint .ifs parser on tests/data/ifs/. Expected
 * values are the numbers written in the files. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "flam3.h"
#include "fractint.h"
#include "ifs.h"

static void test_sample(void)
{
    rt_error e;
    fractint_list l;
    rt_code rc = fractint_load("tests/data/ifs/sample.ifs", &l, &e);
    CHECK(rc == RT_OK, "load: %s", e.msg);
    if (rc)
        return;
    CHECK(l.n == 4, "%d entries", l.n);
    const fractint_entry *f = fractint_find(&l, "FERN");
    CHECK(f && f->dim == 2 && f->n == 4 && f->line == 4, "fern entry");
    if (f) {
        /* row 2: .85 .04 -.04 .85 0 1.6 .85 → x' = .85x + .04y, y' = -.04x + .85y + 1.6 */
        CHECK(f->maps[1].m[0][0] == 0.85 && f->maps[1].m[0][1] == 0.04 &&
                  f->maps[1].m[1][0] == -0.04 && f->maps[1].m[1][1] == 0.85 &&
                  f->maps[1].t[0] == 0 && f->maps[1].t[1] == 1.6,
              "fern map 2");
        CHECK(f->p[0] == 0.01 && f->p[3] == 0.07, "fern probabilities");
        ifs fi;
        CHECK(ifs_build(&fi, f->maps, f->n, f->p, 0, &e) == RT_OK, "fern builds: %s", e.msg);
        ifs_free(&fi);
    }
    const fractint_entry *s = fractint_find(&l, "sierpinski");
    CHECK(s && s->n == 3 && s->line == 11, "sierpinski entry (name on its own line)");
    if (s)
        CHECK(s->p[1] == 0.333333 && s->maps[2].t[0] == 0.25 && s->maps[2].t[1] == 0.5,
              "wrapped row");
    const fractint_entry *t = fractint_find(&l, "3dtetra");
    CHECK(t && t->dim == 3 && t->n == 4, "3-D entry");
    if (t)
        CHECK(t->maps[2].t[1] == 0.5 && t->maps[2].m[2][2] == 0.5 && t->p[3] == 0.25, "3-D map 3");
    const fractint_entry *r = fractint_find(&l, "rotated");
    CHECK(r && r->dim == 3 && r->n == 1, "compact one-line 3-D entry");
    if (r) {
        /* a b c d e f g h i j k l: x' = -0.5 y + 1, y' = 0.5 x + 2, z' = 0.5 z + 3 */
        double in[3] = {2, 4, 6}, out[3];
        affine_apply(&r->maps[0], in, out);
        CHECK(out[0] == -1 && out[1] == 3 && out[2] == 6, "3-D column order: %g %g %g", out[0],
              out[1], out[2]);
    }
    CHECK(fractint_find(&l, "nothing") == NULL, "unknown name");
    fractint_free(&l);
}

static void expect(const char *path, const char *want)
{
    rt_error e;
    fractint_list l;
    rt_code rc = fractint_load(path, &l, &e);
    CHECK(rc == RT_EFORMAT, "%s: code %d", path, (int)rc);
    CHECK(strcmp(e.msg, want) == 0, "%s: got \"%s\", want \"%s\"", path, e.msg, want);
    CHECK(l.n == 0 && l.e == NULL, "%s: list empty after an error", path);
}

static void test_errors(void)
{
    expect("tests/data/ifs/bad_token.ifs", "line 4: expected a number or '}', found 'x1'");
    expect("tests/data/ifs/bad_count.ifs",
           "line 4: entry 'y' has 13 numbers, not a whole number of 7-number rows");
    expect("tests/data/ifs/unclosed.ifs",
           "line 5: entry 'z' opened at line 3 is not closed with '}'");
    rt_error e;
    fractint_list l;
    const char *t1 = "a\n{ }";
    CHECK(fractint_parse(t1, strlen(t1), &l, &e) == RT_EFORMAT &&
              strcmp(e.msg, "line 2: entry 'a' has no maps") == 0,
          "empty entry: %s", e.msg);
    const char *t2 = "fern\n; no brace\n.5 0 0 .5 0 0 1";
    CHECK(fractint_parse(t2, strlen(t2), &l, &e) == RT_EFORMAT &&
              strcmp(e.msg, "line 3: expected '{' after the entry name 'fern'") == 0,
          "no brace: %s", e.msg);
    const char *t3 = "w (2D) { }";
    CHECK(fractint_parse(t3, strlen(t3), &l, &e) == RT_EFORMAT &&
              strcmp(e.msg, "line 1: expected '(3D)' after the entry name 'w'") == 0,
          "bad tag: %s", e.msg);
    CHECK(fractint_parse("", 0, &l, &e) == RT_OK && l.n == 0, "empty file");
}

/* Parse the numbers of attribute `name` in the n-th <xform .../> (0-based). */
static int xform_attr(const char *xml, int nth, const char *name, double *v, int max)
{
    const char *x = xml;
    for (int i = 0; i <= nth; i++) {
        x = strstr(x, "<xform ");
        if (!x)
            return 0;
        x++;
    }
    char key[32];
    snprintf(key, sizeof key, " %s=\"", name);
    const char *a = strstr(x, key), *end = strstr(x, "/>");
    if (!a || a > end)
        return 0;
    a += strlen(key);
    int k = 0;
    char *ep;
    while (k < max && *a != '"') {
        v[k++] = strtod(a, &ep);
        a = ep;
    }
    return k;
}

static void test_flam3(void)
{
    rt_error e;
    /* x' = .5x + .1y + .25, y' = .2x + .4y + .75 (Fractint a b c d e f = .5 .1 .2 .4 .25 .75) */
    affine m[2] = {affine_from_2d(0.5, 0.1, 0.2, 0.4, 0.25, 0.75), affine_from_2d(0.5, 0, 0, 0.5, 0.5, 0)};
    double p[2] = {0.3, 0.7};
    ifs f;
    CHECK(ifs_build(&f, m, 2, p, 0, &e) == RT_OK, "ifs");
    chaos_sys s = {&f, NULL};
    flam3_opts o = {0};
    o.name = "a<b";
    o.width = 200, o.height = 100;
    o.lo[0] = 0, o.hi[0] = 2, o.lo[1] = 1, o.hi[1] = 2;
    o.keep_y = 1;
    bytebuf b;
    bytebuf_init(&b);
    CHECK(flam3_write(&s, &o, &b, &e) == RT_OK, "write: %s", e.msg);
    bytebuf_byte(&b, 0);
    const char *xml = (const char *)b.data;
    CHECK(strncmp(xml, "<flame name=\"a&lt;b\"", 20) == 0, "flame element, escaped name");
    CHECK(strstr(xml, "size=\"200 100\"") && strstr(xml, "center=\"1 1.5\"") &&
              strstr(xml, "scale=\"100\""),
          "size/center/scale");
    CHECK(strstr(xml, "<color index=\"255\" rgb=\"255 255 255\"/>") != NULL, "palette end");
    /* flam3 applies x' = A x + C y + E, y' = B x + D y + F with coefs A B C D E F:
     * evaluate that at (3, 5) and compare with the map */
    double c[6];
    CHECK(xform_attr(xml, 0, "coefs", c, 6) == 6, "coefs");
    double X = c[0] * 3 + c[2] * 5 + c[4], Y = c[1] * 3 + c[3] * 5 + c[5];
    CHECK_NEAR(X, 0.5 * 3 + 0.1 * 5 + 0.25, 1e-15, "flam3 x'");
    CHECK_NEAR(Y, 0.2 * 3 + 0.4 * 5 + 0.75, 1e-15, "flam3 y'");
    double w[1];
    CHECK(xform_attr(xml, 1, "weight", w, 1) == 1 && w[0] == 0.7, "weight = probability");
    CHECK(strstr(xml, "</flame>") != NULL, "closed");
    bytebuf_free(&b);
    /* upright (default): the map conjugated by y -> -y: at (3, -5) flam3 gives (x', -y') */
    o.keep_y = 0;
    bytebuf_init(&b);
    CHECK(flam3_write(&s, &o, &b, &e) == RT_OK, "write upright");
    bytebuf_byte(&b, 0);
    xml = (const char *)b.data;
    CHECK(xform_attr(xml, 0, "coefs", c, 6) == 6, "coefs");
    X = c[0] * 3 + c[2] * -5 + c[4], Y = c[1] * 3 + c[3] * -5 + c[5];
    CHECK_NEAR(X, 0.5 * 3 + 0.1 * 5 + 0.25, 1e-15, "upright x'");
    CHECK_NEAR(-Y, 0.2 * 3 + 0.4 * 5 + 0.75, 1e-15, "upright y'");
    CHECK(strstr(xml, "center=\"1 -1.5\"") != NULL, "upright centre");
    bytebuf_free(&b);
    ifs_free(&f);
    /* RIFS: unit weights, chaos row = matrix row */
    rifs r;
    double P[4] = {0.25, 0.75, 1, 0};
    CHECK(rifs_build(&r, m, 2, 1, P, 0, &e) == RT_OK, "rifs");
    chaos_sys s2 = {NULL, &r};
    bytebuf_init(&b);
    CHECK(flam3_write(&s2, &o, &b, &e) == RT_OK, "write rifs");
    bytebuf_byte(&b, 0);
    double ch[4];
    CHECK(xform_attr((const char *)b.data, 0, "chaos", ch, 4) == 2 && ch[0] == 0.25 && ch[1] == 0.75,
          "chaos row 1");
    CHECK(xform_attr((const char *)b.data, 1, "chaos", ch, 4) == 2 && ch[0] == 1 && ch[1] == 0,
          "chaos row 2");
    CHECK(xform_attr((const char *)b.data, 1, "weight", w, 1) == 1 && w[0] == 1, "unit weight");
    bytebuf_free(&b);
    rifs_free(&r);
    double P2[8] = {0, 1, 0.5, 0.5, 0.5, 0.5, 1, 0};
    CHECK(rifs_build(&r, m, 2, 2, P2, 0, &e) == RT_OK, "rifs 2");
    bytebuf_init(&b);
    CHECK(flam3_write(&s2, &o, &b, &e) == RT_EINVAL &&
              strcmp(e.msg, "flam3 cannot express a Markov order 2 RIFS (its xaos is order 1)") == 0,
          "order 2: %s", e.msg);
    bytebuf_free(&b);
    rifs_free(&r);
}

int main(void)
{
    test_flam3();
    test_sample();
    test_errors();
    return check_done("test_fractint");
}
