/* recipe.c — building, parsing and finding recipes (recipe.h). */
#include "recipe.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "png.h"
#include "provenance.h"
#include "rt_alloc.h"

#define RECIPE_MAX ((size_t)64 << 20) /* the largest script frac reads is 64 MiB */

static void put_escaped(bytebuf *b, const char *s)
{
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '\\')
            bytebuf_append(b, "\\\\", 2);
        else if (c == '\n')
            bytebuf_append(b, "\\n", 2);
        else if (c == '\t')
            bytebuf_append(b, "\\t", 2);
        else if (c == '\r')
            bytebuf_append(b, "\\r", 2);
        else if (c < 0x20 || c == 0x7f)
            bytebuf_printf(b, "\\x%02x", c);
        else
            bytebuf_byte(b, c);
    }
}

void recipe_text(const recipe *r, bytebuf *out, size_t *header_len, char *oneline, size_t n)
{
    bytebuf_printf(out, "frac-recipe 1\nversion: ");
    put_escaped(out, r->version);
    bytebuf_printf(out, "\nscript-path: ");
    put_escaped(out, r->script_path);
    bytebuf_printf(out, "\n");
    if (r->sha256[0])
        bytebuf_printf(out, "script-sha256: %s\n", r->sha256);
    bytebuf_printf(out, "seed: %llu\n", (unsigned long long)r->seed);
    if (r->frame_given) {
        bytebuf_printf(out, "frame: %ld\n", r->frame);
        if (r->frames_range)
            bytebuf_printf(out, "frames: %ld..%ld:%ld\n", r->frames_a, r->frames_b, r->frames_step);
    } else
        bytebuf_printf(out, "frame: none\n");
    if (r->apng_output) {
        bytebuf_printf(out, "apng-output: ");
        put_escaped(out, r->apng_output);
        bytebuf_printf(out, "\napng-delay: %ld\napng-loop: %ld\n", r->apng_delay, r->apng_loop);
        for (int i = 0; i < r->napng; i++) {
            if (r->apng_framed[i])
                bytebuf_printf(out, "apng-frame: %ld ", r->apng_frame[i]);
            else
                bytebuf_printf(out, "apng-frame: none ");
            put_escaped(out, r->apng_name[i]);
            bytebuf_byte(out, '\n');
        }
    }
    for (int i = 0; i < r->nparams; i++) {
        bytebuf_printf(out, "param ");
        put_escaped(out, r->params[i]);
        bytebuf_byte(out, '\n');
    }
    for (int i = 0; i < r->nargs; i++) {
        bytebuf_printf(out, "arg ");
        put_escaped(out, r->args[i]);
        bytebuf_byte(out, '\n');
    }
    if (r->has_script)
        bytebuf_printf(out, "script: %zu\n", r->script_len);
    else
        bytebuf_printf(out, "script: omitted\n");
    if (header_len)
        *header_len = out->len;
    if (r->has_script && r->script) {
        bytebuf_byte(out, '\n');
        bytebuf_append(out, r->script, r->script_len);
    }
    if (oneline && n) {
        bytebuf l;
        bytebuf_init(&l);
        bytebuf_printf(&l, "frac ");
        put_escaped(&l, r->version);
        bytebuf_printf(&l, " seed=%llu", (unsigned long long)r->seed);
        if (r->sha256[0])
            bytebuf_printf(&l, " sha256=%s", r->sha256);
        if (r->frame_given)
            bytebuf_printf(&l, " frame=%ld", r->frame);
        for (int i = 0; i < r->nparams; i++) {
            bytebuf_byte(&l, ' ');
            put_escaped(&l, r->params[i]);
        }
        if (l.failed) { /* out of memory: the whole recipe fails (no file is written with a shorter one) */
            out->failed = 1;
            snprintf(oneline, n, "frac %s", r->version);
        } else {
            size_t k = l.len < n - 1 ? l.len : n - 1;
            if (k)
                memcpy(oneline, l.data, k);
            oneline[k] = 0;
        }
        bytebuf_free(&l);
    }
}

/* ---- parsing ---- */

static char *dup_n(const char *s, size_t n)
{
    char *d = rt_malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

static int hexval(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

/* Undo put_escaped; NULL on a bad escape or out of memory. */
static char *unescape(const char *s, size_t n, int *bad)
{
    char *d = rt_malloc(n + 1);
    if (!d)
        return NULL;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] != '\\') {
            d[k++] = s[i];
            continue;
        }
        char c = ++i < n ? s[i] : 0;
        if (c == '\\' || c == 'n' || c == 't' || c == 'r') {
            d[k++] = c == 'n' ? '\n' : c == 't' ? '\t' : c == 'r' ? '\r' : '\\';
        } else if (c == 'x' && i + 2 < n && hexval(s[i + 1]) >= 0 && hexval(s[i + 2]) >= 0) {
            d[k++] = (char)(hexval(s[i + 1]) * 16 + hexval(s[i + 2]));
            i += 2;
        } else {
            rt_free(d);
            *bad = 1;
            return NULL;
        }
    }
    d[k] = 0;
    if (memchr(d, 0, k)) {
        rt_free(d);
        *bad = 1;
        return NULL;
    }
    return d;
}

static int push(char ***list, int *n, char *s)
{
    char **nl = rt_realloc(*list, (size_t)(*n + 1) * sizeof **list);
    if (!nl)
        return -1;
    nl[(*n)++] = s;
    *list = nl;
    return 0;
}

void recipe_free(recipe *r)
{
    rt_free(r->version);
    rt_free(r->script_path);
    for (int i = 0; i < r->nparams; i++)
        rt_free(r->params[i]);
    rt_free(r->params);
    for (int i = 0; i < r->nargs; i++)
        rt_free(r->args[i]);
    rt_free(r->args);
    rt_free(r->script);
    rt_free(r->apng_output);
    for (int i = 0; i < r->napng; i++)
        rt_free(r->apng_name[i]);
    rt_free(r->apng_name);
    rt_free(r->apng_frame);
    rt_free(r->apng_framed);
    memset(r, 0, sizeof *r);
}

static int same_list(char **a, int na, char **b, int nb)
{
    if (na != nb)
        return 0;
    for (int i = 0; i < na; i++)
        if (strcmp(a[i], b[i]) != 0)
            return 0;
    return 1;
}

int recipe_same_run(const recipe *a, const recipe *b, char *why, size_t whyn)
{
    const char *d = strcmp(a->version, b->version) ? "the frac version"
                    : strcmp(a->script_path, b->script_path) ? "the script path"
                    : strcmp(a->sha256, b->sha256) ? "the script (its SHA-256)"
                    : a->seed != b->seed ? "the seed"
                    : a->frames_range != b->frames_range ||
                            (a->frames_range && (a->frames_a != b->frames_a || a->frames_b != b->frames_b ||
                                                 a->frames_step != b->frames_step))
                        ? "the --frames range"
                    : !same_list(a->params, a->nparams, b->params, b->nparams) ? "the params (-D)"
                    : !same_list(a->args, a->nargs, b->args, b->nargs) ? "the script's arguments"
                    : a->has_script != b->has_script || a->script_len != b->script_len ||
                            (a->script && b->script && memcmp(a->script, b->script, a->script_len) != 0) ||
                            !a->script != !b->script
                        ? "the script text carried"
                    : a->apng_output || b->apng_output ? "being an APNG already"
                                                       : NULL;
    if (d)
        snprintf(why, whyn, "%s", d);
    return d == NULL;
}

__attribute__((format(printf, 4, 5))) static int fail(recipe *r, char *err, size_t errn, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errn, fmt, ap);
    va_end(ap);
    recipe_free(r);
    return -1;
}

static int parse_u64(const char *s, size_t n, unsigned long long max, unsigned long long *out)
{
    if (n == 0 || n > 20)
        return -1;
    unsigned long long v = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9' || v > (max - (unsigned)(s[i] - '0')) / 10)
            return -1;
        v = v * 10 + (unsigned)(s[i] - '0');
    }
    *out = v;
    return 0;
}

/* A whole number with an optional '-', |v| <= max. */
static int parse_long(const char *s, size_t n, unsigned long long max, long *out)
{
    int neg = n > 0 && s[0] == '-';
    unsigned long long v;
    if (parse_u64(s + neg, n - (size_t)neg, max, &v))
        return -1;
    *out = neg ? -(long)v : (long)v;
    return 0;
}

int recipe_parse(const char *text, size_t len, recipe *r, char *err, size_t errn)
{
    memset(r, 0, sizeof *r);
    if (!text || len == 0) /* an empty frac:recipe chunk: no text at all */
        return fail(r, err, errn, "the recipe is empty (no 'frac-recipe 1' line)");
    const char *p = text, *end = text + len;
    int lineno = 0, seen_script = 0, seen_seed = 0, seen_frame = 0;
    while (p < end && !seen_script) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        size_t n = nl ? (size_t)(nl - p) : (size_t)(end - p);
        const char *line = p;
        p += n + (nl ? 1 : 0);
        lineno++;
        if (lineno == 1) {
            if (n == 13 && memcmp(line, "frac-recipe 1", 13) == 0)
                continue;
            if (n > 12 && memcmp(line, "frac-recipe ", 12) == 0)
                return fail(r, err, errn, "the recipe is in format '%.*s', newer than this frac reads (1)",
                            (int)(n - 12 > 20 ? 20 : n - 12), line + 12);
            return fail(r, err, errn, "not a frac recipe (no 'frac-recipe 1' line)");
        }
        const char *sp = memchr(line, ' ', n);
        size_t kl = sp ? (size_t)(sp - line) : n;
        const char *val = sp ? sp + 1 : line + n;
        size_t vl = (size_t)(line + n - val);
        int bad = 0;
        char **slot = NULL;
#define KEY(k) (kl == sizeof k - 1 && memcmp(line, k, kl) == 0)
        if (KEY("version:"))
            slot = &r->version;
        else if (KEY("script-path:"))
            slot = &r->script_path;
        if (slot) {
            if (*slot)
                return fail(r, err, errn, "recipe line %d: '%.*s' is given twice", lineno, (int)kl, line);
            if (!(*slot = unescape(val, vl, &bad)))
                return fail(r, err, errn, bad ? "recipe line %d: a bad escape" : "recipe line %d: out of memory",
                            lineno);
        } else if (KEY("script-sha256:")) {
            int ok = vl == 64;
            for (size_t i = 0; ok && i < 64; i++)
                ok = (val[i] >= '0' && val[i] <= '9') || (val[i] >= 'a' && val[i] <= 'f');
            if (!ok)
                return fail(r, err, errn, "recipe line %d: script-sha256 is not 64 hex digits", lineno);
            memcpy(r->sha256, val, 64);
            r->sha256[64] = 0;
        } else if (KEY("seed:")) {
            unsigned long long v;
            if (parse_u64(val, vl, 9007199254740992ULL, &v))
                return fail(r, err, errn, "recipe line %d: seed is not a whole number from 0 to 2^53", lineno);
            r->seed = v;
            seen_seed = 1;
        } else if (KEY("frame:")) {
            unsigned long long v;
            seen_frame = 1;
            if (vl == 4 && memcmp(val, "none", 4) == 0) {
                r->frame_given = 0;
            } else if (!parse_long(val, vl, 1000000000000ULL, &r->frame)) {
                r->frame_given = 1;
            } else {
                return fail(r, err, errn, "recipe line %d: frame is not 'none' or a whole number", lineno);
            }
            (void)v;
        } else if (KEY("frames:")) {
            const char *dots = memchr(val, '.', vl), *colon = memchr(val, ':', vl);
            if (!r->frame_given || !dots || !colon || colon < dots || dots + 1 >= val + vl || dots[1] != '.' ||
                parse_long(val, (size_t)(dots - val), 1000000000000ULL, &r->frames_a) ||
                parse_long(dots + 2, (size_t)(colon - dots - 2), 1000000000000ULL, &r->frames_b) ||
                parse_long(colon + 1, (size_t)(val + vl - colon - 1), 1000000000000ULL, &r->frames_step) ||
                r->frames_step < 1 || r->frames_b < r->frames_a)
                return fail(r, err, errn, "recipe line %d: frames is not A..B:STEP after a frame", lineno);
            r->frames_range = 1;
        } else if (KEY("apng-output:")) {
            if (r->apng_output)
                return fail(r, err, errn, "recipe line %d: 'apng-output:' is given twice", lineno);
            if (!(r->apng_output = unescape(val, vl, &bad)) || !r->apng_output[0] || strchr(r->apng_output, '/'))
                return fail(r, err, errn,
                            !r->apng_output && !bad ? "recipe line %d: out of memory"
                                                    : "recipe line %d: apng-output is not a file name",
                            lineno);
        } else if (KEY("apng-delay:") || KEY("apng-loop:")) {
            long v;
            long max = KEY("apng-delay:") ? 65535 : 2147483647L;
            if (parse_long(val, vl, (unsigned long long)max, &v) || v < 0)
                return fail(r, err, errn, "recipe line %d: %.*s is not a whole number from 0 to %ld", lineno,
                            (int)kl - 1, line, max);
            *(KEY("apng-delay:") ? &r->apng_delay : &r->apng_loop) = v;
        } else if (KEY("apng-frame:")) {
            const char *sp2 = memchr(val, ' ', vl);
            long f = 0;
            int framed = !(sp2 && sp2 - val == 4 && memcmp(val, "none", 4) == 0);
            if (!sp2 || (framed && parse_long(val, (size_t)(sp2 - val), 1000000000000ULL, &f)))
                return fail(r, err, errn, "recipe line %d: apng-frame is not 'F NAME' (F a frame or none)", lineno);
            if (r->napng >= 100000)
                return fail(r, err, errn, "recipe line %d: more than 100000 APNG frames", lineno);
            char *nm = unescape(sp2 + 1, (size_t)(val + vl - sp2 - 1), &bad);
            if (!nm)
                return fail(r, err, errn, bad ? "recipe line %d: a bad escape" : "recipe line %d: out of memory",
                            lineno);
            long *nf = rt_realloc(r->apng_frame, (size_t)(r->napng + 1) * sizeof *nf);
            if (nf)
                r->apng_frame = nf;
            char *nd = nf ? rt_realloc(r->apng_framed, (size_t)(r->napng + 1)) : NULL;
            if (nd)
                r->apng_framed = nd;
            if (!nd || push(&r->apng_name, &r->napng, nm)) {
                rt_free(nm);
                return fail(r, err, errn, "recipe line %d: out of memory", lineno);
            }
            r->apng_frame[r->napng - 1] = f;
            r->apng_framed[r->napng - 1] = (char)framed;
        } else if (KEY("param") || KEY("arg")) {
            char *s = unescape(val, vl, &bad);
            if (!s)
                return fail(r, err, errn, bad ? "recipe line %d: a bad escape" : "recipe line %d: out of memory",
                            lineno);
            if (KEY("param") && (!strchr(s, '=') || s[0] == '=')) {
                rt_free(s);
                return fail(r, err, errn, "recipe line %d: a param is not NAME=TEXT", lineno);
            }
            if (KEY("param") ? push(&r->params, &r->nparams, s) : push(&r->args, &r->nargs, s)) {
                rt_free(s);
                return fail(r, err, errn, "recipe line %d: out of memory", lineno);
            }
        } else if (KEY("script:")) {
            unsigned long long v;
            seen_script = 1;
            if (vl == 7 && memcmp(val, "omitted", 7) == 0)
                r->has_script = 0;
            else if (!parse_u64(val, vl, RECIPE_MAX, &v))
                r->has_script = 1, r->script_len = (size_t)v;
            else
                return fail(r, err, errn, "recipe line %d: script is not 'omitted' or a length in bytes", lineno);
        } else {
            return fail(r, err, errn, "recipe line %d: unknown field '%.*s'", lineno, (int)(kl > 40 ? 40 : kl),
                        line);
        }
#undef KEY
    }
    if (!r->version || !r->script_path || !seen_seed || !seen_frame || !seen_script)
        return fail(r, err, errn, "the recipe is incomplete (it lacks the '%s' line)",
                    !r->version       ? "version:"
                    : !r->script_path ? "script-path:"
                    : !seen_seed      ? "seed:"
                    : !seen_frame     ? "frame:"
                                      : "script:");
    if (!r->apng_output != !r->napng)
        return fail(r, err, errn, "the recipe's APNG lines are incomplete (%s)",
                    r->apng_output ? "no apng-frame line" : "apng-frame without apng-output");
    if (r->has_script && p < end) {
        if (*p != '\n' || (size_t)(end - p - 1) != r->script_len)
            return fail(r, err, errn, "the recipe's script text is not the %zu bytes its header says", r->script_len);
        if (!(r->script = dup_n(p + 1, r->script_len)))
            return fail(r, err, errn, "out of memory reading the recipe");
    } else if (p < end) {
        return fail(r, err, errn, "the recipe has text after its header but says the script is omitted");
    }
    return 0;
}

/* ---- finding a recipe in a file ---- */

static const char *find_sub(const char *h, size_t hn, const char *needle)
{
    size_t nn = strlen(needle);
    for (size_t i = 0; i + nn <= hn; i++)
        if (h[i] == needle[0] && memcmp(h + i, needle, nn) == 0)
            return h + i;
    return NULL;
}

int recipe_find(const unsigned char *d, size_t n, char **text, size_t *len, char *oneline, size_t on,
                char *err, size_t errn)
{
    *text = NULL;
    *len = 0;
    if (on)
        oneline[0] = 0;
    if (n >= 8 && memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0) {
        bytebuf b;
        bytebuf_init(&b);
        int found;
        rt_error e;
        if (png_text(d, n, "frac:recipe", RECIPE_MAX + 4096, &b, &found, &e)) {
            snprintf(err, errn, "%s", e.msg);
            bytebuf_free(&b);
            return -1;
        }
        if (!found) {
            bytebuf_free(&b);
            return 1;
        }
        *text = (char *)b.data; /* the bytebuf's block is an rt_malloc block */
        *len = b.len;
        return 0;
    }
    /* the header in comment lines, near the start of the file */
    const char *s = (const char *)d;
    size_t lim = n < ((size_t)1 << 20) ? n : (size_t)1 << 20;
    const char *hit = find_sub(s, lim, "frac-recipe 1\n");
    while (hit) {
        const char *ls = hit;
        while (ls > s && ls[-1] != '\n')
            ls--;
        size_t pl = (size_t)(hit - ls); /* the prefix: "# ", "comment ", "" */
        bytebuf b;
        bytebuf_init(&b);
        const char *q = ls, *end = s + n;
        int done = 0;
        while (q < end && !done) {
            const char *nl = memchr(q, '\n', (size_t)(end - q));
            if (!nl || (size_t)(nl - q) < pl || memcmp(q, ls, pl) != 0)
                break;
            bytebuf_append(&b, q + pl, (size_t)(nl - q) - pl + 1);
            done = (size_t)(nl - q) >= pl + 7 && memcmp(q + pl, "script:", 7) == 0;
            q = nl + 1;
        }
        if (done && !b.failed) {
            *text = (char *)b.data;
            *len = b.len;
            return 0;
        }
        bytebuf_free(&b);
        size_t off = (size_t)(hit - s) + 1;
        hit = off < lim ? find_sub(hit + 1, lim - off, "frac-recipe 1\n") : NULL;
    }
    /* the one-line form: a VTK title (line 2) or an STL header (80 bytes) */
    if (on) {
        const char *t = NULL;
        size_t tl = 0;
        if (n >= 84 && memcmp(d, "frac ", 5) == 0) {
            t = s, tl = 80;
        } else if (n > 23 && memcmp(d, "# vtk DataFile Version ", 23) == 0) {
            const char *nl = memchr(s, '\n', n);
            if (nl && (size_t)(s + n - nl) > 6 && memcmp(nl + 1, "frac ", 5) == 0) {
                t = nl + 1;
                const char *nl2 = memchr(t, '\n', (size_t)(s + n - t));
                tl = nl2 ? (size_t)(nl2 - t) : 0;
            }
        }
        if (t && find_sub(t, tl, " seed=")) {
            while (tl && (t[tl - 1] == ' ' || t[tl - 1] == 0))
                tl--;
            if (tl >= on)
                tl = on - 1;
            memcpy(oneline, t, tl);
            oneline[tl] = 0;
        }
    }
    return 1;
}

/* ---- handing it to the writers ---- */

int recipe_install(const recipe *r, recipe_store *st)
{
    bytebuf_init(&st->text);
    size_t hl = 0;
    recipe_text(r, &st->text, &hl, st->oneline, sizeof st->oneline);
    if (st->text.failed) {
        bytebuf_free(&st->text);
        return -1;
    }
    snprintf(st->software, sizeof st->software, "frac %s", r->version);
    prov p = {st->software, (const char *)st->text.data, st->text.len, (const char *)st->text.data, hl,
              st->oneline};
    prov_set(&p);
    return 0;
}

void recipe_uninstall(recipe_store *st)
{
    prov_set(NULL);
    bytebuf_free(&st->text);
}
