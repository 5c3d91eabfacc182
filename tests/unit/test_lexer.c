/* test_lexer.c — the scanner's number literals and keywords (interp/lexer.c,
 * compiled into this test: it needs only the runtime's allocator).
 *
 * Number literals are read by a fast path (Clinger's) when it is exact and by
 * strtod otherwise; every literal must give the very double strtod gives for
 * its text without the underscores (bit for bit), which is how the lexer read
 * every literal before. Tens of thousands of literals of every shape are
 * checked against strtod, and a few against values the C compiler converts
 * itself (its own correctly rounded reading, independent of libc). */
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "lexer.c"

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static unsigned rnd(unsigned n) /* 0 … n-1, xorshift64* */
{
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (unsigned)((rng * 2685821657736338717ull) >> 33) % n;
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* strtod of the whole literal, underscores dropped (every digit counts: the
 * lexer once cut literals to 127 characters) */
static double reference(const char *lit)
{
    char buf[512];
    size_t n = 0;
    for (const char *q = lit; *q && n + 1 < sizeof buf; q++)
        if (*q != '_')
            buf[n++] = *q;
    buf[n] = 0;
    return strtod(buf, NULL);
}

static double lex_one(const char *lit, int *ok)
{
    token_list tl;
    *ok = 0;
    if (lex_all(lit, 0, 1, &tl))
        return 0;
    double v = tl.toks[0].num;
    *ok = tl.n == 2 && tl.toks[0].type == T_NUMBER && tl.toks[0].len == (int)strlen(lit) &&
          tl.toks[1].type == T_EOF;
    lex_free(&tl);
    return v;
}

static void literal(const char *lit)
{
    int ok;
    double got = lex_one(lit, &ok), want = reference(lit);
    CHECK(ok && same_bits(got, want), "'%s': lexed %.17g (%s token), strtod %.17g", lit, got,
          ok ? "one" : "not one", want);
}

static void known(const char *lit, double want)
{
    int ok;
    double got = lex_one(lit, &ok);
    CHECK(ok && same_bits(got, want), "'%s': lexed %.17g, want %.17g", lit, got, want);
}

static void digits(char **p, int n, int underscores)
{
    for (int i = 0; i < n; i++) {
        /* mostly small digits and runs of 0 and 9, which round hardest */
        unsigned r = rnd(10);
        *(*p)++ = (char)('0' + (r < 3 ? 0 : r < 6 ? 9 : rnd(10)));
        if (underscores && i + 1 < n && rnd(6) == 0)
            *(*p)++ = '_';
    }
}

static void random_literal(char *buf)
{
    char *p = buf;
    int shape = (int)rnd(6), us = rnd(3) == 0;
    int ni = (int)rnd(24) + 1, nf = (int)rnd(24) + 1;
    switch (shape) {
    case 0: /* integer */
        digits(&p, ni, us);
        break;
    case 1: /* decimal */
        digits(&p, ni, us);
        *p++ = '.';
        digits(&p, nf, us);
        break;
    case 2: /* leading point */
        *p++ = '.';
        digits(&p, nf, us);
        break;
    case 3: /* trailing point */
        digits(&p, ni, us);
        *p++ = '.';
        break;
    default: { /* exponent, small or anywhere in range */
        digits(&p, ni, us);
        if (rnd(2)) {
            *p++ = '.';
            digits(&p, nf, us);
        }
        *p++ = rnd(2) ? 'e' : 'E';
        unsigned s = rnd(3);
        if (s)
            *p++ = s == 1 ? '+' : '-';
        int e = shape == 4 ? (int)rnd(30) : (int)rnd(400);
        p += sprintf(p, e < 10 && rnd(4) == 0 ? "0%d" : "%d", e);
        break;
    }
    }
    *p = 0;
}

static void keywords_and_names(void)
{
    static const struct {
        const char *text;
        tok_type t;
    } cases[] = {
        {"let", T_LET},     {"param", T_PARAM}, {"fn", T_FN},     {"import", T_IMPORT}, {"as", T_AS},
        {"if", T_IF},       {"then", T_THEN},   {"else", T_ELSE}, {"elif", T_ELIF},     {"do", T_DO},
        {"end", T_END},     {"for", T_FOR},     {"in", T_IN},     {"and", T_AND},       {"or", T_OR},
        {"not", T_NOT},     {"true", T_TRUE},   {"false", T_FALSE}, {"nil", T_NIL},
        /* near misses are names */
        {"lets", T_IDENT},  {"i", T_IDENT},     {"ifx", T_IDENT}, {"_if", T_IDENT},     {"If", T_IDENT},
        {"elsif", T_IDENT}, {"imports", T_IDENT}, {"nol", T_IDENT}, {"tru", T_IDENT},   {"fals", T_IDENT},
        {"paramx", T_IDENT}, {"ab", T_IDENT},   {"an", T_IDENT},  {"en", T_IDENT},      {"x1_y", T_IDENT},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        token_list tl;
        if (lex_all(cases[i].text, 0, 1, &tl)) {
            CHECK(0, "lex_all('%s') failed", cases[i].text);
            continue;
        }
        CHECK(tl.toks[0].type == cases[i].t && tl.toks[0].len == (int)strlen(cases[i].text),
              "'%s': token %s, want %s", cases[i].text, lex_name(tl.toks[0].type), lex_name(cases[i].t));
        lex_free(&tl);
    }
}

int main(void)
{
    /* values the compiler reads itself */
    known("0.1", 0.1);
    known("1e22", 1e22);
    known("1e23", 1e23); /* 10^23 is not a double: strtod's side */
    known("9007199254740993", 9007199254740992.0); /* 2^53 + 1 rounds to even */
    known("9007199254740995", 9007199254740996.0);
    known("123456789012345678", 123456789012345678.0);
    known("1_000_000", 1e6);
    known("2.5E6", 2.5e6);
    known(".5", 0.5);
    known("1.", 1.0);
    known("3.14159265358979323846", 3.14159265358979323846);
    known("0.000001", 1e-6);
    known("4.9e-324", 4.9e-324);
    known("2.2250738585072014e-308", 2.2250738585072014e-308);
    known("1.7976931348623157e308", 1.7976931348623157e308);
    known("1e400", HUGE_VAL);
    known("0e400", 0.0);
    known("00000000000000000000000000000000042", 42.0);

    /* edges of the fast path, and every shape at random */
    static const char *edges[] = {
        "0", "00", "0.0", "9007199254740992", "9007199254740991.0", "900719925474099.3", "1e-22",
        "1e-23", "123e-22", "9007199254740992e22", "9007199254740993e-22", "1234567890123456789",
        "12345678901234567890", "0.1234567890123456789", "1.5e+22", "1.5e-0", "7e0022",
        "0.000000000000000000000000000001", "1_2.3_4e5", "5_", "1e99999999999", "1e-99999999999",
        /* 128 characters or more: the lexer copies them to the heap for strtod */
        "0.0000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "000000000000000000000000000000000000000000000001",
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
        "0000000000000000000000000000000000000000000000000007",
    };
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; i++)
        literal(edges[i]);
    char buf[256];
    for (int i = 0; i < 100000; i++) {
        random_literal(buf);
        literal(buf);
    }
    keywords_and_names();
    return check_done("test_lexer");
}
