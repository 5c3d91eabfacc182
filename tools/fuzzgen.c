/* fuzzgen.c — writes seed corpora for the fuzz harnesses (tests/fuzz/).
 *
 *   fuzzgen DIR        writes DIR/script/gen_* and DIR/{png,apng,recipe,inflate,pnm,ifs,
 *                      nrrd,vtk,ply,obj,stl}/seed_*
 *   fuzzgen --over DIR also writes DIR/over/: inputs past the script
 *                      harness's nesting caps (the known deep-nesting
 *                      crashes of issue 11), for FRAC_FUZZ_ALL=1 runs
 *
 * Script seeds are deep and wide inputs: nested brackets, records, blocks,
 * prefix operators, conditionals and lambdas; long operator chains, long
 * tables, many arguments, long strings and lists, huge and tiny numbers and
 * NaN-producing expressions fed to builtins. Depths stay within the
 * harness's caps (64 levels, 400 operators) so the inputs run.
 *
 * Loader seeds are small valid files made with the runtime's own encoders
 * (asymmetric sizes, channels that differ), plus hand-built PNGs the encoder
 * does not write (palette with tRNS, Adam7, 1/2/4-bit grey) so the decoder's
 * other paths start covered. Built against libfracrt.a; not part of frac. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "apng.h"
#include "deflate.h"
#include "fileio.h"
#include "image.h"
#include "mesh.h"
#include "mesh_io.h"
#include "png.h"
#include "pnm.h"
#include "volume.h"
#include "volume_io.h"

static const char *root;

static void put(const char *sub, const char *name, const void *d, size_t n)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", root, sub);
    mkdir(path, 0777);
    snprintf(path, sizeof path, "%s/%s/%s", root, sub, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(d, 1, n, f) != n || fclose(f) != 0) {
        perror(path);
        exit(74);
    }
}

static void put_buf(const char *sub, const char *name, bytebuf *b)
{
    if (b->failed) {
        fprintf(stderr, "fuzzgen: out of memory\n");
        exit(70);
    }
    put(sub, name, b->data, b->len);
    bytebuf_free(b);
    bytebuf_init(b);
}

/* ---- script seeds ---------------------------------------------------------- */

static void rep(bytebuf *b, const char *s, int n)
{
    for (int i = 0; i < n; i++)
        bytebuf_append(b, s, strlen(s));
}

static void script(const char *sub, const char *name, bytebuf *b)
{
    put_buf(sub, name, b);
}

static void nest(const char *sub, const char *tag, const char *open, const char *mid,
                 const char *close, int depth)
{
    bytebuf b;
    bytebuf_init(&b);
    char name[64];
    bytebuf_printf(&b, "let x = ");
    rep(&b, open, depth);
    bytebuf_printf(&b, "%s", mid);
    rep(&b, close, depth);
    bytebuf_printf(&b, "\nprint(x)\nprint(str(x))\nprint(x == x)\n");
    snprintf(name, sizeof name, "gen_nest_%s_%d", tag, depth);
    script(sub, name, &b);
}

static void nests(const char *sub, const int *depths, int nd)
{
    for (int i = 0; i < nd; i++) {
        int d = depths[i];
        nest(sub, "paren", "(", "1", ")", d);
        nest(sub, "list", "[", "1", "]", d);
        nest(sub, "record", "{a: ", "1", "}", d);
        nest(sub, "do", "do ", "1", " end", d);
        nest(sub, "not", "not ", "true", "", d);
        nest(sub, "neg", "-", "1", "", d);
        nest(sub, "pow", "2^", "1", "", d);
        nest(sub, "if", "if true then ", "1", " else 0", d);
        nest(sub, "lambda", "y => ", "1", "", d);
        nest(sub, "pipe", "", "1", " |> abs", d);
        nest(sub, "call", "abs(", "-1", ")", d);
        nest(sub, "index", "[", "[1]", "][0]", d);
        nest(sub, "field", "{a: ", "1", "}.a", d);
        nest(sub, "compre", "[", "1", " for i in range(2)]", d);
    }
}

static void chains(const char *sub, const int *lens, int nl)
{
    static const char *ops[] = {"+", "-", "*", "/", "%", "==", "and", "or", "<"};
    bytebuf b;
    bytebuf_init(&b);
    char name[64];
    for (int i = 0; i < nl; i++) {
        for (size_t k = 0; k < sizeof ops / sizeof ops[0]; k++) {
            bytebuf_printf(&b, "let x = 1");
            for (int j = 0; j < lens[i]; j++)
                bytebuf_printf(&b, " %s %d", ops[k], j % 7 + 1);
            bytebuf_printf(&b, "\nprint(x)\n");
            snprintf(name, sizeof name, "gen_chain_%zu_%d", k, lens[i]);
            script(sub, name, &b);
        }
    }
}

static void wide(const char *sub)
{
    bytebuf b;
    bytebuf_init(&b);
    /* a long table: 300 rows of 7 numbers (an IFS with 300 maps) */
    bytebuf_printf(&b, "let t = {\n");
    for (int r = 0; r < 300; r++)
        bytebuf_printf(&b, "  %.3g %.3g %.3g %.3g %g %g %.4g\n", 0.5 - r * 0.001, 0.01 * (r % 5),
                       -0.01 * (r % 3), 0.5, r * 0.01, -r * 0.02, 1.0 / 300);
    bytebuf_printf(&b, "}\nprint(len(t))\nlet f = ifs(t)\nprint(f)\n"
                       "save(chaos(f, points: 1e4, size: [16, 12]), \"t.png\")\nload(\"t.png\")\n");
    script(sub, "gen_wide_table", &b);
    /* a long string and formatting */
    bytebuf_printf(&b, "let s = \"");
    rep(&b, "abc\\n\\t\\\"\\{", 800);
    bytebuf_printf(&b, "\"\nprint(len(s))\nprint(s + s)\nprint(format(\"{} {} {:.3f}\", s, 1, 2))\n");
    script(sub, "gen_wide_string", &b);
    /* many arguments, positional and named */
    bytebuf_printf(&b, "print(max(");
    for (int i = 0; i < 40; i++)
        bytebuf_printf(&b, "%s%d", i ? ", " : "", i);
    bytebuf_printf(&b, "))\nfn f(a, b = 2) = a + b\nprint(f(1, b: 3, b: 4))\nprint(f(");
    for (int i = 0; i < 40; i++)
        bytebuf_printf(&b, "%s%d", i ? ", " : "", i);
    bytebuf_printf(&b, "))\nprint(format(\"");
    rep(&b, "{}", 40);
    bytebuf_printf(&b, "\"");
    for (int i = 0; i < 40; i++)
        bytebuf_printf(&b, ", %d", i);
    bytebuf_printf(&b, "))\n");
    script(sub, "gen_wide_args", &b);
    /* long lists */
    bytebuf_printf(&b, "let l = range(9999)\nprint(len(l))\nlet m = concat(l, l)\nprint(len(m))\n"
                       "print(sum(l))\nprint(len([x * x for x in l if x %% 3 == 0]))\n"
                       "print(reverse(l)[0])\nprint(slice(l, 10, 20))\nprint(str(l)[0])\n"
                       "print(len(linspace(0, 1, 10000)))\nprint(len(repeat(1, 10001)))\n");
    script(sub, "gen_wide_list", &b);
    /* deep recursion under the depth limit and past it */
    bytebuf_printf(&b, "fn f(n) = if n == 0 then 0 else 1 + f(n - 1)\nprint(f(30))\nprint(f(1000))\n"
                       "fn g(n) do\n  let a = n + (n * (n - (n / (n + 1))))\n  if n <= 0 then a else g(n - 1)\nend\n"
                       "print(g(35))\nlet h = x => if x > 0 then h(x - 1) else 0\nprint(h(100))\n");
    script(sub, "gen_recursion", &b);
}

static void numbers(const char *sub)
{
    static const char *vals[] = {"0/0", "1/0", "-1/0", "1e300", "-1e300", "1e-320", "1e308 * 10",
                                 "sqrt(-1)", "log(0)", "inf - inf", "2^1024", "-0", "4294967297",
                                 "9007199254740993", "0.5", "-3"};
    bytebuf b;
    bytebuf_init(&b);
    char name[64];
    for (size_t i = 0; i < sizeof vals / sizeof vals[0]; i++) {
        const char *v = vals[i];
        bytebuf_printf(&b,
                       "let v = %s\nprint(v)\nprint(str(v))\nprint(floor(v), ceil(v), round(v))\n"
                       "print(range(v))\n"
                       "print([1, 2, 3][v])\n"
                       "print(\"abc\"[v])\n"
                       "print(repeat(1, v))\n"
                       "print(linspace(0, 1, v))\n"
                       "print(clamp(v, 0, 1), lerp(0, 1, v), smoothstep(0, 1, v))\n"
                       "print(image(size: [v, 4]))\n"
                       "print(chaos(ifs {0.5 0 0 0.5 0 0 1; 0.5 0 0 0.5 0.5 0 1}, points: v, size: [8, 8]))\n"
                       "print(measure(ifs {0.5 0 0 0.5 0 0 1}, grid: v, points: 100))\n"
                       "print(perlin(v, v, v), fbm(v, v, v))\n"
                       "print(sphere(r: v))\n"
                       "print(pow(v, v), atan2(v, v), v %% 3, 3 %% v)\n",
                       v);
        snprintf(name, sizeof name, "gen_number_%zu", i);
        script(sub, name, &b);
    }
}

/* The newer builtins with tiny work (fit: one map, one or two generations,
 * tiny targets; meshes of a few faces; framing), and their edges. */
static void newer(const char *sub)
{
    bytebuf b;
    bytebuf_init(&b);
    bytebuf_printf(&b, "let f = fit({\n1 1 0\n0 1 1\n}, maps: 1, iterations: 1)\nprint(f)\n"
                       "let g = fit([[1, 0, 1], [1, 1, 1]], maps: \"1..2\", iterations: 2, rifs: true, seed: 3)\n"
                       "print(g)\nprint(fit([[1, 1], [1, 0]], maps: 1, iterations: 1, start: f))\n"
                       "let im = image([3, 2], 1)\nprint(fit(im, maps: 1, iterations: 1, foreground: \"dark\"))\n"
                       "print(fit(im, maps: 1, iterations: 1, threshold: 1, time: 0.01))\n");
    script(sub, "gen_fit_tiny", &b);
    bytebuf_printf(&b, "let p = pyramid()\nlet c = cube([0, 0, 0], [1, 2, 3])\n"
                       "let t = polyhedron([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], "
                       "[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])\n"
                       "let q = polyhedron([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]], "
                       "[[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])\n"
                       "print(p, c, t, q)\nprint(c.lo, c.hi, t.vertices)\n"
                       "print(iterate(ifs([[0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5, 0, 0, 0], "
                       "[0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5, 0.5, 0, 0]]), start: p, steps: 1))\n"
                       "let cam = framing([0, 0, 0], [1, 1, 1], [8, 8])\nprint(cam)\n"
                       "print(framing(c.lo, c.hi, 4, azimuth: -720, elevation: -89.9))\n"
                       "print(rasterize(c, camera: cam, size: [8, 8]))\n");
    script(sub, "gen_meshes_framing", &b);
    bytebuf_free(&b);
}

static void scripts(const char *dir, int over)
{
    static const int depths[] = {8, 40, 60};
    static const int lens[] = {50, 390};
    static const int deep[] = {200, 3000, 30000};
    static const int longc[] = {2000, 6000};
    nests(dir, depths, 3);
    chains(dir, lens, 2);
    wide(dir);
    numbers(dir);
    newer(dir);
    if (over) {
        nests("over", deep, 3);
        chains("over", longc, 2);
    }
}

/* ---- loader seeds -------------------------------------------------------- */

static void test_image(image *im, int w, int h)
{
    rt_error e;
    if (image_init(im, w, h, &e)) {
        fprintf(stderr, "fuzzgen: %s\n", e.msg);
        exit(70);
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = image_at(im, x, y);
            p[0] = (float)x / (float)(w - 1 ? w - 1 : 1);
            p[1] = (float)y / (float)(h - 1 ? h - 1 : 1);
            p[2] = (x + y) % 3 == 0 ? 1.0f : 0.25f;
            p[3] = x < w / 2 ? 1.0f : 0.5f;
        }
}

static void chunk(bytebuf *b, const char *type, const unsigned char *d, size_t n)
{
    bytebuf_u32be(b, (uint32_t)n);
    size_t at = b->len;
    bytebuf_append(b, type, 4);
    bytebuf_append(b, d, n);
    bytebuf_u32be(b, b->failed ? 0 : deflate_crc32(0, b->data + at, n + 4));
}

/* A PNG from raw filtered scanlines (filter bytes included), for the colour
 * types and interlacing png_encode does not write. */
static void png_raw(const char *name, int w, int h, int depth, int ct, int interlace,
                    const unsigned char *plte, size_t nplte, const unsigned char *trns, size_t ntrns,
                    const unsigned char *raw, size_t nraw)
{
    bytebuf b, z;
    bytebuf_init(&b);
    bytebuf_init(&z);
    rt_error e;
    bytebuf_append(&b, "\x89PNG\r\n\x1a\n", 8);
    unsigned char ih[13] = {0, 0, 0, (unsigned char)w, 0, 0, 0, (unsigned char)h,
                            (unsigned char)depth, (unsigned char)ct, 0, 0, (unsigned char)interlace};
    chunk(&b, "IHDR", ih, 13);
    if (plte)
        chunk(&b, "PLTE", plte, nplte);
    if (trns)
        chunk(&b, "tRNS", trns, ntrns);
    chunk(&b, "tEXt", (const unsigned char *)"Comment\0fuzz seed", 17);
    if (deflate_zlib(raw, nraw, 6, &z, &e)) {
        fprintf(stderr, "fuzzgen: %s\n", e.msg);
        exit(70);
    }
    /* split the data over two IDAT chunks */
    size_t half = z.len / 2;
    chunk(&b, "IDAT", z.data, half);
    chunk(&b, "IDAT", z.data + half, z.len - half);
    chunk(&b, "IEND", NULL, 0);
    bytebuf_free(&z);
    put_buf("png", name, &b);
}

static void pngs(void)
{
    image im;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    test_image(&im, 6, 5);
    static const int bits[] = {8, 16};
    char name[64];
    for (int bi = 0; bi < 2; bi++)
        for (int ch = 1; ch <= 4; ch++) {
            png_encode(&im, bits[bi], ch, &b, &e);
            snprintf(name, sizeof name, "seed_%d_%d.png", bits[bi], ch);
            put_buf("png", name, &b);
        }
    /* the same deflate streams for the inflate harness */
    png_encode(&im, 8, 4, &b, &e);
    bytebuf_free(&b);
    image_free(&im);

    /* palette 2-bit with tRNS, 3×3: rows of 1 byte (filter 0, then 4 px) */
    const unsigned char plte[] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    const unsigned char trns[] = {0, 128};
    const unsigned char pal2[] = {0, 0x1b, 1, 0x6c, 2, 0x93}; /* filters 0, 1, 2 */
    png_raw("seed_palette_trns.png", 3, 3, 2, 3, 0, plte, sizeof plte, trns, sizeof trns, pal2,
            sizeof pal2);
    /* grey 1-bit and 4-bit with a grey tRNS */
    const unsigned char g1[] = {0, 0xa0, 3, 0x50, 4, 0xf0};
    png_raw("seed_grey1.png", 3, 3, 1, 0, 0, NULL, 0, NULL, 0, g1, sizeof g1);
    const unsigned char gt[] = {0, 7};
    const unsigned char g4[] = {0, 0x07, 0xf0, 1, 0x12, 0x30, 4, 0x70, 0x10};
    png_raw("seed_grey4_trns.png", 3, 3, 4, 0, 0, NULL, 0, gt, sizeof gt, g4, sizeof g4);
    /* RGB 8-bit with an RGB tRNS */
    const unsigned char rt[] = {0, 1, 0, 2, 0, 3};
    const unsigned char rgb[] = {0, 1, 2, 3, 9, 9, 9, 2, 0, 0, 0, 0, 0, 0};
    png_raw("seed_rgb_trns.png", 2, 2, 8, 2, 0, NULL, 0, rt, sizeof rt, rgb, sizeof rgb);
    /* Adam7, grey 8-bit, 3×3. The passes are p1 1×1, p2 and p3 empty,
     * p4 1×1, p5 2×1, p6 1×2, p7 3×1; each row is a filter byte and its pixels. */
    const unsigned char a7[] = {0, 10,          /* p1 */
                                0, 20,          /* p4 */
                                0, 30, 31,      /* p5: y 2, x 0 and 2 */
                                0, 40, 0, 41,   /* p6: x 1, y 0 and 2 */
                                0, 50, 51, 52}; /* p7: y 1 */
    png_raw("seed_adam7.png", 3, 3, 8, 0, 1, NULL, 0, NULL, 0, a7, sizeof a7);
}

/* APNG harness inputs: 3 option bytes (delay, plays), then the frames as
 * whole PNG files one after the other (tests/fuzz/fuzz_loaders.c). */
static void apngs(void)
{
    bytebuf b, f;
    bytebuf_init(&b);
    bytebuf_init(&f);
    rt_error e;
    image a, c;
    test_image(&a, 5, 4);
    test_image(&c, 5, 4);
    for (size_t i = 0; i < (size_t)5 * 4 * 4; i += 3)
        c.px[i] = 1.0f - c.px[i]; /* a second frame that differs */
    static const int bits[] = {8, 16};
    char name[64];
    for (int bi = 0; bi < 2; bi++)
        for (int ch = 1; ch <= 4; ch += 3) {
            for (int nf = 1; nf <= 3; nf++) {
                bytebuf_append(&b, "\x00\x28\x02", 3);
                for (int k = 0; k < nf; k++) {
                    png_encode(k % 2 ? &c : &a, bits[bi], ch, &f, &e);
                    bytebuf_append(&b, f.data, f.len);
                    bytebuf_free(&f);
                    bytebuf_init(&f);
                }
                snprintf(name, sizeof name, "seed_%d_%d_x%d", bits[bi], ch, nf);
                put_buf("apng", name, &b);
            }
        }
    /* frames of two sizes (refused), and an APNG as a frame */
    image sm;
    test_image(&sm, 3, 3);
    bytebuf_append(&b, "\x01\x00\x00", 3);
    png_encode(&a, 8, 3, &f, &e);
    bytebuf_append(&b, f.data, f.len);
    bytebuf_free(&f);
    bytebuf_init(&f);
    png_encode(&sm, 8, 3, &f, &e);
    bytebuf_append(&b, f.data, f.len);
    bytebuf_free(&f);
    bytebuf_init(&f);
    put_buf("apng", "seed_two_sizes", &b);
    const image *ims[2] = {&a, &c};
    apng_opts o = {APNG_DEFAULT_DELAY_MS, 0};
    bytebuf_append(&b, "\x00\x10\x00", 3);
    if (apng_encode(ims, 2, 8, 4, &o, &f, &e) == RT_OK)
        bytebuf_append(&b, f.data, f.len);
    bytebuf_free(&f);
    put_buf("apng", "seed_apng_in", &b);
    image_free(&a);
    image_free(&c);
    image_free(&sm);
}

/* Recipe texts (interp/recipe.h) for the recipe harness; files frac wrote
 * are added by the fuzz-seeds rule. */
static void recipes(void)
{
    static const char *const texts[] = {
        "frac-recipe 1\nversion: 0.1.0\nscript-path: a.frac\nscript-sha256: "
        "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef\nseed: 1\nframe: none\n"
        "param n=3\nparam s=\"a\\tb\\\\c\\x01\"\narg x\narg \\n\nscript: 8\n\nprint(1)",
        "frac-recipe 1\nversion: 0.1.0\nscript-path: b.frac\nseed: 9007199254740992\nframe: -2\n"
        "frames: -2..10:4\nscript: omitted\n",
        "frac-recipe 1\nversion: 0.1.0\nscript-path: c\\x7f.frac\nseed: 0\nframe: 7\nscript: 0\n",
        "# frac-recipe 1\n# version: 0.1.0\n# script-path: d.frac\n# seed: 2\n# frame: none\n# script: 3\nP5\n",
        "comment frac-recipe 1\ncomment version: 0.1.0\ncomment script-path: e.frac\ncomment seed: 3\n"
        "comment frame: none\ncomment script: omitted\n",
        "frac-recipe 2\nversion: 9\n",
    };
    char name[32];
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        snprintf(name, sizeof name, "seed_text_%zu", i);
        put("recipe", name, texts[i], strlen(texts[i]));
    }
}

static void inflates(void)
{
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    const char *text = "abcabcabcabc the quick brown fox jumps over the lazy dog abcabcabc";
    for (int level = 0; level <= 9; level += 3) {
        deflate_zlib((const unsigned char *)text, strlen(text), level, &b, &e);
        char name[32];
        snprintf(name, sizeof name, "seed_level%d", level);
        put_buf("inflate", name, &b);
    }
    unsigned char zeros[3000];
    memset(zeros, 0, sizeof zeros);
    for (size_t i = 0; i < sizeof zeros; i += 7)
        zeros[i] = (unsigned char)(i * 31);
    deflate_zlib(zeros, sizeof zeros, 6, &b, &e);
    put_buf("inflate", "seed_long", &b);
    deflate_zlib((const unsigned char *)"", 0, 6, &b, &e);
    put_buf("inflate", "seed_empty", &b);
}

static void pnms(void)
{
    image im;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    test_image(&im, 6, 5);
    pnm_encode(&im, 8, 1, &b, &e);
    put_buf("pnm", "seed_8.pgm", &b);
    pnm_encode(&im, 16, 1, &b, &e);
    put_buf("pnm", "seed_16.pgm", &b);
    pnm_encode(&im, 8, 3, &b, &e);
    put_buf("pnm", "seed_8.ppm", &b);
    pnm_encode(&im, 16, 3, &b, &e);
    put_buf("pnm", "seed_16.ppm", &b);
    pfm_encode(&im, 3, &b, &e);
    put_buf("pnm", "seed_rgb.pfm", &b);
    pfm_encode(&im, 1, &b, &e);
    put_buf("pnm", "seed_grey.pfm", &b);
    image_free(&im);
    const char hand[] = "P6\n# a comment\n2 1 # another\n300\n\x00\x01\x00\x02\x00\x03\x01\x00\x00\x00\x00\x05";
    put("pnm", "seed_comments.ppm", hand, sizeof hand - 1);
    unsigned char pfmbe[] = "PF\n1 1\n1.0\n\x3f\x80\x00\x00\x40\x00\x00\x00\xff\x80\x00\x00";
    put("pnm", "seed_be.pfm", pfmbe, sizeof pfmbe - 1);
}

static void ifss(void)
{
    const char fern[] = "; the fern\nfern {\n  0 0 0 .16 0 0 .01\n  .85 .04 -.04 .85 0 1.6 .85\n"
                        "  .2 -.26 .23 .22 0 1.6 .07 ; comment\n  -.15 .28 .26 .24 0 .44 .07\n}\n"
                        "3dfern (3D) {\n  .00 .00 0 .0 .18 .0 0 0.0 0.00 .00 0.0 .0 .01\n"
                        "  .85 .00 0 .0 .85 .1 0 -0.1 0.85 .00 1.6 .0 .85\n"
                        "  .20 -.20 0 .2 .20 0 0 0 0.3 0 0.8 0 .07\n"
                        "  -.2 .2 0 .2 .2 0 0 0 .3 0 .8 0\n  .07\n}\nwrapped { .5 0 0\n .5 0 0 .5 }\n";
    put("ifs", "seed_fern.ifs", fern, sizeof fern - 1);
    const char one[] = "x{1 0 0 1 0 0 1}";
    put("ifs", "seed_one.ifs", one, sizeof one - 1);
}

static void test_volume(volume *v, int nx, int ny, int nz)
{
    double lo[3] = {-1, -0.5, 0}, hi[3] = {1, 0.5, 2};
    rt_error e;
    if (volume_init(v, nx, ny, nz, lo, hi, &e)) {
        fprintf(stderr, "fuzzgen: %s\n", e.msg);
        exit(70);
    }
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++)
                *volume_at(v, i, j, k) = (float)(i + 10 * j + 100 * k) / 400.0f;
}

static void volumes(void)
{
    volume v;
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    test_volume(&v, 3, 2, 4);
    static const struct { int type; const char *name; } nrrd[] = {
        {VIO_FLOAT, "seed_float.nrrd"}, {VIO_USHORT, "seed_ushort.nrrd"}, {VIO_UCHAR, "seed_uchar.nrrd"}};
    for (size_t i = 0; i < sizeof nrrd / sizeof nrrd[0]; i++) {
        vio_nrrd_to_mem(&v, nrrd[i].type, NULL, &b, &e);
        put_buf("nrrd", nrrd[i].name, &b);
    }
    vio_vtk_to_mem(&v, &b, &e);
    put_buf("vtk", "seed.vtk", &b);
    volume_free(&v);
    const char hand[] = "NRRD0001\n# comment\ntype: short\ndimension: 3\nsizes: 2 1 1\n"
                        "endian: big\nencoding: raw\nspacings: 0.5 1 2\nbyte skip: 1\n\n\x07\x00\x01\xff\xfe";
    put("nrrd", "seed_short_big.nrrd", hand, sizeof hand - 1);
    const char hand2[] = "NRRD0005\ntype: double\ndimension: 3\nsizes: 1 1 1\nendian: little\n"
                         "encoding: raw\nspace origin: (1,2,3)\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
                         "\n\x00\x00\x00\x00\x00\x00\xf0\x3f";
    put("nrrd", "seed_double.nrrd", hand2, sizeof hand2 - 1);
}

static void meshes(void)
{
    mesh m;
    mesh_init(&m, 1, 1);
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float n[3] = {0, 0, 1}, c[4] = {1, 0.5f, 0, 1};
    for (int i = 0; i < 4; i++)
        mesh_add_vertex(&m, p[i], n, c);
    mesh_add_tri(&m, 0, 2, 1);
    mesh_add_tri(&m, 0, 1, 3);
    mesh_add_tri(&m, 0, 3, 2);
    mesh_add_tri(&m, 1, 2, 3);
    bytebuf b;
    bytebuf_init(&b);
    rt_error e;
    for (int ascii = 0; ascii <= 1; ascii++) {
        mio_ply_to_mem(&m, ascii, &b, &e);
        put_buf("ply", ascii ? "seed_ascii.ply" : "seed_bin.ply", &b);
    }
    mio_obj_to_mem(&m, &b, &e);
    put_buf("obj", "seed.obj", &b);
    mio_stl_to_mem(&m, &b, &e);
    put_buf("stl", "seed.stl", &b);
    mesh_free(&m);
    const char obj[] = "# hand\no thing\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0 1\nvn 0 0 1\nvt 0 0\n"
                       "f 1/1/1 2/1/1 3/1/1\nf -1 -2 -3 \nf 1//1 2//1 4//1 3//1\ng x\ns off\nusemtl m\n";
    put("obj", "seed_hand.obj", obj, sizeof obj - 1);
    const char ply[] = "ply\nformat ascii 1.0\ncomment hand\nelement vertex 3\nproperty float x\n"
                       "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
                       "property uchar blue\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n0 1 0 0 0 255\n3 0 1 2\n";
    put("ply", "seed_hand.ply", ply, sizeof ply - 1);
}

int main(int argc, char **argv)
{
    int over = 0;
    if (argc == 3 && strcmp(argv[1], "--over") == 0) {
        over = 1;
        root = argv[2];
    } else if (argc == 2) {
        root = argv[1];
    } else {
        fprintf(stderr, "usage: fuzzgen [--over] DIR\n");
        return 64;
    }
    mkdir(root, 0777);
    scripts("script", over);
    pngs();
    apngs();
    recipes();
    inflates();
    pnms();
    ifss();
    volumes();
    meshes();
    return 0;
}
