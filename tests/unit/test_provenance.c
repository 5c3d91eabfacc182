/* test_provenance.c — the recipe in the writers (provenance.h): where each
 * format puts it, that png_text reads it back, and that it changes nothing
 * else (the same pixels, vertices, and bytes once removed). */
#include <string.h>

#include "check.h"
#include "mesh_io.h"
#include "png.h"
#include "pnm.h"
#include "provenance.h"

static const char header[] = "frac-recipe 1\nversion: 9\nscript: 5\n";
static const char whole[] = "frac-recipe 1\nversion: 9\nscript: 5\n\nprint\xc3\x97"; /* UTF-8 × */

static void set(void)
{
    prov p = {"frac 9", whole, sizeof whole - 1, header, sizeof header - 1, "frac 9 seed=1 a=b"};
    prov_set(&p);
}

static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

int main(void)
{
    rt_error e;
    image im;
    image_init(&im, 6, 5, &e);
    for (int y = 0; y < 5; y++) /* asymmetric, channels differ */
        for (int x = 0; x < 6; x++) {
            float *p = image_at(&im, x, y);
            p[0] = (float)x / 5, p[1] = (float)y / 4, p[2] = x == 1 ? 1.0f : 0.2f, p[3] = 1;
        }

    /* PNG: IHDR, tEXt Software, iTXt frac:recipe, then IDAT; pixels unchanged */
    bytebuf plain, with;
    bytebuf_init(&plain);
    bytebuf_init(&with);
    prov_set(NULL);
    CHECK(png_encode(&im, 8, 4, &plain, &e) == RT_OK, "%s", e.msg);
    set();
    CHECK(png_encode(&im, 8, 4, &with, &e) == RT_OK, "%s", e.msg);
    const char *order[] = {"IHDR", "tEXt", "iTXt", "IDAT"};
    size_t pos = 8;
    for (int k = 0; k < 4 && pos + 8 <= with.len; k++) {
        CHECK(memcmp(with.data + pos + 4, order[k], 4) == 0, "chunk %d is %.4s, want %s", k,
              (const char *)with.data + pos + 4, order[k]);
        if (k == 1)
            CHECK(be32(with.data + pos) == 15 && memcmp(with.data + pos + 8, "Software\0frac 9", 15) == 0,
                  "tEXt Software");
        pos += 12 + be32(with.data + pos);
    }
    /* without the two chunks the file is the plain one, byte for byte */
    size_t t0 = 8 + 25; /* signature and IHDR */
    size_t after = 8 + 25;
    after += 12 + be32(with.data + after);
    after += 12 + be32(with.data + after);
    CHECK(with.len - (after - t0) == plain.len && memcmp(with.data, plain.data, t0) == 0 &&
              memcmp(with.data + after, plain.data + t0, plain.len - t0) == 0,
          "the PNG differs from the plain one by more than the recipe chunks");
    bytebuf txt;
    bytebuf_init(&txt);
    int found = 0;
    CHECK(png_text(with.data, with.len, "frac:recipe", 1 << 20, &txt, &found, &e) == RT_OK && found &&
              txt.len == sizeof whole - 1 && memcmp(txt.data, whole, txt.len) == 0,
          "png_text frac:recipe: %s", e.msg);
    bytebuf_free(&txt);
    bytebuf_init(&txt);
    CHECK(png_text(with.data, with.len, "Software", 100, &txt, &found, &e) == RT_OK && found && txt.len == 6 &&
              memcmp(txt.data, "frac 9", 6) == 0, "png_text Software");
    bytebuf_free(&txt);
    bytebuf_init(&txt);
    CHECK(png_text(plain.data, plain.len, "frac:recipe", 100, &txt, &found, &e) == RT_OK && !found,
          "a plain PNG has no recipe");
    CHECK(png_text(with.data, with.len, "frac:recipe", 10, &txt, &found, &e) != RT_OK, "max_len is enforced");
    bytebuf_free(&txt);
    image back;
    CHECK(png_decode(with.data, with.len, &back, NULL, &e) == RT_OK && back.w == 6 && back.h == 5, "%s", e.msg);
    int same = 1;
    for (size_t i = 0; i < 6 * 5 * 4; i++)
        same &= png_sample(back.px[i], 255) == png_sample(im.px[i], 255);
    CHECK(same, "pixels changed by the recipe");
    image_free(&back);
    bytebuf_free(&plain);
    bytebuf_free(&with);

    /* PPM: "# " lines right after the magic line; decodes the same */
    bytebuf_init(&with);
    CHECK(pnm_encode(&im, 8, 3, &with, &e) == RT_OK, "%s", e.msg);
    const char *want = "P6\n# frac-recipe 1\n# version: 9\n# script: 5\n6 5\n255\n";
    CHECK(with.len > strlen(want) && memcmp(with.data, want, strlen(want)) == 0, "PPM header");
    CHECK(pnm_decode(with.data, with.len, &back, NULL, &e) == RT_OK && back.w == 6 && back.h == 5, "%s", e.msg);
    image_free(&back);
    bytebuf_free(&with);

    /* PLY comments, OBJ comments, STL header */
    mesh m;
    mesh_init(&m, 0, 0);
    float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0};
    uint32_t ia = mesh_add_vertex(&m, a, NULL, NULL), ib = mesh_add_vertex(&m, b, NULL, NULL);
    uint32_t ic = mesh_add_vertex(&m, c, NULL, NULL);
    mesh_add_tri(&m, ia, ib, ic);
    bytebuf_init(&with);
    CHECK(mio_ply_to_mem(&m, 1, &with, &e) == RT_OK, "%s", e.msg);
    want = "ply\nformat ascii 1.0\ncomment frac mesh\ncomment frac-recipe 1\ncomment version: 9\ncomment script: 5\n"
           "element vertex 3\n";
    CHECK(with.len > strlen(want) && memcmp(with.data, want, strlen(want)) == 0, "PLY header");
    bytebuf_free(&with);
    bytebuf_init(&with);
    CHECK(mio_obj_to_mem(&m, &with, &e) == RT_OK, "%s", e.msg);
    want = "# frac mesh\n# frac-recipe 1\n# version: 9\n# script: 5\nv 0 0 0\n";
    CHECK(with.len > strlen(want) && memcmp(with.data, want, strlen(want)) == 0, "OBJ header %.*s", (int)with.len, (const char *)with.data);
    bytebuf_free(&with);
    bytebuf_init(&with);
    CHECK(mio_stl_to_mem(&m, &with, &e) == RT_OK && with.len == 84 + 50, "%s", e.msg);
    char stl[81];
    memcpy(stl, with.data, 80);
    stl[80] = 0;
    CHECK(strncmp(stl, "frac 9 seed=1 a=b ", 18) == 0 && stl[79] == ' ', "STL header '%s'", stl);
    mesh mb;
    CHECK(mio_stl_from_mem(with.data, with.len, &mb, &e) == RT_OK && mb.nt == 1, "%s", e.msg);
    mesh_free(&mb);
    bytebuf_free(&with);

    /* XML comment: "--" inside is written "-\x2d" */
    static const char dash[] = "frac-recipe 1\nparam a=--b\nscript: omitted\n";
    prov p = {"frac 9", dash, sizeof dash - 1, dash, sizeof dash - 1, "x"};
    prov_set(&p);
    bytebuf_init(&with);
    prov_put_xml_comment(&with);
    want = "<!-- frac recipe\nfrac-recipe 1\nparam a=-\\x2db\nscript: omitted\n-->\n";
    CHECK(with.len == strlen(want) && memcmp(with.data, want, with.len) == 0, "XML comment '%.*s'", (int)with.len,
          (const char *)with.data);
    bytebuf_free(&with);

    /* nothing set: the writers write what they wrote before */
    prov_set(NULL);
    bytebuf_init(&with);
    mio_obj_to_mem(&m, &with, &e);
    CHECK(with.len > 14 && memcmp(with.data, "# frac mesh\nv ", 14) == 0, "OBJ without a recipe");
    bytebuf_free(&with);
    mesh_free(&m);
    image_free(&im);
    return check_done("test_provenance");
}
