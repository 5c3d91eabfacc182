/* deflate.c — DEFLATE compressor (RFC 1951), zlib wrapper (RFC 1950),
 * Adler-32 and CRC-32. Not one of the seed papers: this is infrastructure for
 * PNG output (see DESIGN.md, "PNG": fixed Huffman alone costs ~45% in size).
 *
 * Pipeline: LZ77 with hash chains over the whole input (the input is in
 * memory, so positions are absolute and the 32 KiB window is enforced by a
 * distance check instead of sliding a buffer) -> symbols buffered per block
 * -> for each block the smallest of dynamic Huffman, fixed Huffman and stored
 * (RFC 1951 §3.2.4–3.2.7). The lazy-matching rule and the parameters of
 * levels 6..9 (good/lazy/nice/chain, 3-byte hash) are zlib's, so level 6
 * behaves like zlib's level 6; levels 1..5 hash 4 bytes (see level_cfgs).
 * The code itself is ours.
 */
#include "deflate.h"
#include "rt_alloc.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- checksums */

/* Reflected CRC-32, polynomial 0xEDB88320 (PNG spec annex D, ISO 3309).
 * crc_table[0] is the byte-at-a-time table; crc_table[k][b] is the CRC of
 * byte b followed by k zero bytes, so eight table look-ups advance the CRC
 * over eight input bytes at once ("slicing by 8": the CRC is linear, the
 * eight bytes' contributions are independent and combine by XOR). */
static uint32_t crc_table[8][256];
static pthread_once_t crc_once = PTHREAD_ONCE_INIT;

static void crc_init(void)
{
    for (uint32_t i = 0; i < 256; i++) {
        uint32_t c = i;
        for (int k = 0; k < 8; k++)
            c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[0][i] = c;
    }
    for (int k = 1; k < 8; k++)
        for (int i = 0; i < 256; i++) {
            uint32_t c = crc_table[k - 1][i];
            crc_table[k][i] = crc_table[0][c & 0xFF] ^ (c >> 8);
        }
}

uint32_t deflate_crc32(uint32_t crc, const void *p, size_t n)
{
    pthread_once(&crc_once, crc_init);
    const unsigned char *s = p;
    uint32_t c = crc ^ 0xFFFFFFFFu;
    for (; n >= 8; n -= 8, s += 8) {
        uint32_t lo = c ^ ((uint32_t)s[0] | (uint32_t)s[1] << 8 | (uint32_t)s[2] << 16 |
                           (uint32_t)s[3] << 24);
        c = crc_table[7][lo & 0xFF] ^ crc_table[6][(lo >> 8) & 0xFF] ^
            crc_table[5][(lo >> 16) & 0xFF] ^ crc_table[4][lo >> 24] ^ crc_table[3][s[4]] ^
            crc_table[2][s[5]] ^ crc_table[1][s[6]] ^ crc_table[0][s[7]];
    }
    while (n--)
        c = crc_table[0][(c ^ *s++) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

uint32_t deflate_adler32(uint32_t adler, const void *p, size_t n)
{
    /* RFC 1950 §8.2; 5552 is the largest block for which the sums cannot
     * overflow 32 bits before the reduction modulo 65521. */
    const unsigned char *s = p;
    uint32_t a = adler & 0xFFFF, b = adler >> 16;
    while (n > 0) {
        size_t k = n < 5552 ? n : 5552;
        n -= k;
        for (; k >= 8; k -= 8, s += 8) {
            a += s[0], b += a;
            a += s[1], b += a;
            a += s[2], b += a;
            a += s[3], b += a;
            a += s[4], b += a;
            a += s[5], b += a;
            a += s[6], b += a;
            a += s[7], b += a;
        }
        while (k--) {
            a += *s++;
            b += a;
        }
        a %= 65521;
        b %= 65521;
    }
    return (b << 16) | a;
}

/* ------------------------------------------------------------- bit writer */

typedef struct bitw {
    unsigned char *buf;
    size_t len, cap;
    uint64_t bits;
    int nbits;
    int failed;
} bitw;

static int bw_reserve(bitw *w, size_t extra)
{
    if (w->failed)
        return 0;
    if (w->len + extra <= w->cap)
        return 1;
    size_t ncap = w->cap ? w->cap : 4096;
    while (ncap < w->len + extra) {
        if (ncap > SIZE_MAX / 2) {
            w->failed = 1;
            return 0;
        }
        ncap *= 2;
    }
    unsigned char *nb = rt_realloc(w->buf, ncap);
    if (!nb) {
        w->failed = 1;
        return 0;
    }
    w->buf = nb;
    w->cap = ncap;
    return 1;
}

/* Append the n (<= 32) low bits of v, least significant first (§3.1.1). */
static inline void bw_put(bitw *w, uint32_t v, int n)
{
    w->bits |= (uint64_t)v << w->nbits;
    w->nbits += n;
    if (w->nbits >= 32) {
        if (w->len + 4 > w->cap && !bw_reserve(w, 4)) {
            w->bits = 0; /* failed: keep the shift counts in range */
            w->nbits = 0;
            return;
        }
        unsigned char *o = w->buf + w->len;
        o[0] = (unsigned char)w->bits;
        o[1] = (unsigned char)(w->bits >> 8);
        o[2] = (unsigned char)(w->bits >> 16);
        o[3] = (unsigned char)(w->bits >> 24);
        w->len += 4;
        w->bits >>= 32;
        w->nbits -= 32;
    }
}

/* Pad with zero bits to a byte boundary and flush the bit buffer. */
static void bw_align(bitw *w)
{
    if (!bw_reserve(w, 8))
        return;
    while (w->nbits > 0) {
        w->buf[w->len++] = (unsigned char)w->bits;
        w->bits >>= 8;
        w->nbits -= 8;
    }
    w->nbits = 0;
    w->bits = 0;
}

static void bw_bytes(bitw *w, const unsigned char *p, size_t n)
{
    if (n == 0 || !bw_reserve(w, n))
        return;
    memcpy(w->buf + w->len, p, n);
    w->len += n;
}

/* --------------------------------------------------------------- Huffman */

#define NLIT 288  /* literal/length alphabet incl. the two unused codes */
#define NDIST 32
#define NCL 19

static int ilog2u(uint32_t v) /* floor(log2 v), v >= 1 */
{
#if defined(__GNUC__)
    return 31 - __builtin_clz(v);
#else
    int r = 0;
    while (v >>= 1)
        r++;
    return r;
#endif
}

typedef struct symfreq {
    uint32_t freq;
    int sym;
} symfreq;

static int cmp_symfreq(const void *a, const void *b)
{
    const symfreq *x = a, *y = b;
    if (x->freq != y->freq)
        return x->freq < y->freq ? -1 : 1;
    return (x->sym > y->sym) - (x->sym < y->sym);
}

/* Code lengths for a length-limited Huffman code over freq[0..n-1] (n <= 288).
 * Unused symbols get length 0. A code is always complete: if only one symbol
 * is used a second one gets a 1-bit code too (some decoders reject an
 * incomplete code). No symbol used: all lengths 0. */
static void huff_lengths(const uint32_t *freq, int n, int maxlen, uint8_t *len)
{
    symfreq sf[NLIT];
    uint32_t A[NLIT];
    int m = 0;
    memset(len, 0, (size_t)n);
    for (int i = 0; i < n; i++)
        if (freq[i]) {
            sf[m].freq = freq[i];
            sf[m].sym = i;
            m++;
        }
    if (m == 0)
        return;
    if (m == 1) {
        len[sf[0].sym] = 1;
        len[sf[0].sym == 0 ? 1 : 0] = 1;
        return;
    }
    qsort(sf, (size_t)m, sizeof sf[0], cmp_symfreq);
    for (int i = 0; i < m; i++)
        A[i] = sf[i].freq;

    /* In-place minimum-redundancy code lengths for sorted weights: Moffat &
     * Katajainen, "In-place calculation of minimum-redundancy codes" (1995).
     * Pass 1 builds the tree (parent pointers), pass 2 computes internal
     * node depths, pass 3 leaf depths; A[i] ends as the length of the i-th
     * lightest symbol. */
    int root = 0, leaf = 2, next;
    A[0] += A[1];
    for (next = 1; next < m - 1; next++) {
        if (leaf >= m || A[root] < A[leaf]) {
            A[next] = A[root];
            A[root++] = (uint32_t)next;
        } else
            A[next] = A[leaf++];
        if (leaf >= m || (root < next && A[root] < A[leaf])) {
            A[next] += A[root];
            A[root++] = (uint32_t)next;
        } else
            A[next] += A[leaf++];
    }
    A[m - 2] = 0;
    for (next = m - 3; next >= 0; next--)
        A[next] = A[A[next]] + 1;
    {
        int avbl = 1, used = 0, dpth = 0;
        root = m - 2;
        next = m - 1;
        while (avbl > 0) {
            while (root >= 0 && (int)A[root] == dpth) {
                used++;
                root--;
            }
            while (avbl > used) {
                A[next--] = (uint32_t)dpth;
                avbl--;
            }
            avbl = 2 * used;
            dpth++;
            used = 0;
        }
    }

    /* Limit to maxlen: clamp, then repair the Kraft sum by moving codes one
     * level down (each step keeps the code count and lowers the sum by one
     * unit of 2^-maxlen). */
    int count[64] = {0};
    for (int i = 0; i < m; i++)
        count[A[i] > (uint32_t)maxlen ? maxlen : (int)A[i]]++;
    uint32_t total = 0;
    for (int l = 1; l <= maxlen; l++)
        total += (uint32_t)count[l] << (maxlen - l);
    while (total > (1u << maxlen)) {
        count[maxlen]--;
        for (int l = maxlen - 1; l > 0; l--)
            if (count[l]) {
                count[l]--;
                count[l + 1] += 2;
                break;
            }
        total--;
    }
    /* the lightest symbols get the longest codes */
    int i = 0;
    for (int l = maxlen; l >= 1; l--)
        for (int k = 0; k < count[l]; k++)
            len[sf[i++].sym] = (uint8_t)l;
}

/* Canonical codes (§3.2.2), bit-reversed for the LSB-first writer. */
static void huff_codes(const uint8_t *len, int n, uint16_t *code)
{
    int count[16] = {0};
    uint32_t next[16];
    for (int i = 0; i < n; i++)
        count[len[i]]++;
    count[0] = 0;
    uint32_t c = 0;
    for (int l = 1; l < 16; l++) {
        c = (c + (uint32_t)count[l - 1]) << 1;
        next[l] = c;
    }
    for (int i = 0; i < n; i++) {
        int l = len[i];
        if (!l) {
            code[i] = 0;
            continue;
        }
        uint32_t v = next[l]++, r = 0;
        for (int k = 0; k < l; k++) {
            r = (r << 1) | (v & 1);
            v >>= 1;
        }
        code[i] = (uint16_t)r;
    }
}

/* Length 3..258 -> symbol 257..285, extra bits and their value (§3.2.5). */
static inline void len_sym(int length, int *sym, int *nextra, int *extra)
{
    int l = length - 3;
    if (l < 8) {
        *sym = 257 + l;
        *nextra = 0;
        *extra = 0;
    } else if (l == 255) {
        *sym = 285;
        *nextra = 0;
        *extra = 0;
    } else {
        int nb = ilog2u((uint32_t)l);
        *sym = 257 + 4 * (nb - 1) + ((l >> (nb - 2)) & 3);
        *nextra = nb - 2;
        *extra = l & ((1 << (nb - 2)) - 1);
    }
}

/* Distance 1..32768 -> symbol 0..29, extra bits and their value. */
static inline void dist_sym(int dist, int *sym, int *nextra, int *extra)
{
    int d = dist - 1;
    if (d < 4) {
        *sym = d;
        *nextra = 0;
        *extra = 0;
    } else {
        int nb = ilog2u((uint32_t)d);
        *sym = 2 * nb + ((d >> (nb - 1)) & 1);
        *nextra = nb - 1;
        *extra = d & ((1 << (nb - 1)) - 1);
    }
}

/* The same mappings as tables, built once from len_sym and dist_sym: for
 * length l, len_tab[l - 3] = symbol - 257; for distance d, the symbol is
 * dist_tab[d - 1] if d <= 256, else dist_tab[256 + ((d - 1) >> 7)] (above
 * 256 every symbol covers a multiple of 128 distances). sym_nx/sym_base:
 * extra-bit count and first value of each length (0..28) and distance
 * (32 + 0..29) symbol. */
static uint8_t len_tab[256], dist_tab[512], sym_nx[64];
static uint16_t sym_base[64];
static pthread_once_t tab_once = PTHREAD_ONCE_INIT;

static void tab_init(void)
{
    for (int l = 3; l <= 258; l++) {
        int sym, nx, x;
        len_sym(l, &sym, &nx, &x);
        len_tab[l - 3] = (uint8_t)(sym - 257);
        sym_nx[sym - 257] = (uint8_t)nx;
        if (x == 0)
            sym_base[sym - 257] = (uint16_t)l;
    }
    for (int d = 1; d <= 32768; d++) {
        int sym, nx, x;
        dist_sym(d, &sym, &nx, &x);
        if (d <= 256)
            dist_tab[d - 1] = (uint8_t)sym;
        else
            dist_tab[256 + ((d - 1) >> 7)] = (uint8_t)sym;
        sym_nx[32 + sym] = (uint8_t)nx;
        if (x == 0)
            sym_base[32 + sym] = (uint16_t)d;
    }
}

static inline int dist_code(int d)
{
    return d <= 256 ? dist_tab[d - 1] : dist_tab[256 + ((d - 1) >> 7)];
}

/* ---------------------------------------------------------------- LZ77 */

#define WSIZE 32768
#define WMASK (WSIZE - 1)
#define MAX_DIST 32768
#define HBITS_MAX 16
#define MIN_MATCH 3
#define MAX_MATCH 258
#define TOO_FAR 4096
#define BLOCK_SYMS 16384

typedef struct level_cfg {
    int good, lazy, nice, chain, lazy_mode, hlen, hbits;
    int insert_max; /* lazy levels: a longer match inserts only its last 2 positions (0: all) */
} level_cfg;

/* Levels 6..9 are zlib's configuration table (deflate.c,
 * configuration_table) with its 3-byte hash of 15 bits, so level 6 behaves
 * like zlib's level 6. Levels 1..5 are ours: they hash 4 bytes into 16 bits,
 * so a chain holds only positions that share 4 bytes (a 3-byte hash chains
 * every position that shares 3 bytes, or just the hash, and most of the
 * walk is spent rejecting them); 3-byte matches are then found only by
 * chance, which costs little on image data, where a 3-byte match is seldom
 * cheaper than its literals. Levels 2..5 match lazily; level 2 inserts
 * only the last 2 positions of a match longer than 16 into the chains
 * (long matches are runs and repeats, whose inner positions seldom start a
 * better match; inserting them was a third of the time on images with empty
 * areas). On filtered PNG rows
 * (bench/README_png.md) level 2 runs at about the speed of zlib's level 2
 * and gives files the size of zlib's level 6 or smaller. For the greedy
 * level 1 "lazy" is the longest match whose positions are all inserted into
 * the hash chains. */
static const level_cfg level_cfgs[10] = {
    {0, 0, 0, 0, 0, 3, 15, 0},        {4, 4, 8, 4, 0, 4, 16, 0},        {4, 8, 64, 16, 1, 4, 16, 16},
    {4, 8, 64, 32, 1, 4, 16, 0},      {8, 16, 64, 64, 1, 4, 16, 0},     {8, 16, 128, 64, 1, 4, 16, 0},
    {8, 16, 128, 128, 1, 3, 15, 0},   {8, 32, 128, 256, 1, 3, 15, 0},   {32, 128, 258, 1024, 1, 3, 15, 0},
    {32, 258, 258, 4096, 1, 3, 15, 0},
};

typedef struct deflater {
    const unsigned char *in;
    size_t n;
    level_cfg cfg;
    int32_t *head, *prev;
    uint16_t *sym_ll, *sym_d; /* literal or length; distance (0 = literal) */
    int nsyms;
    uint32_t lfreq[NLIT], dfreq[NDIST];
    size_t block_start, covered; /* input range of the pending block */
    bitw w;
} deflater;

/* Hash of the cfg.hlen (3 or 4) bytes at p into cfg.hbits bits; the bytes
 * are combined in a fixed order, so the output is the same on any byte
 * order. */
static inline uint32_t hash_at(const deflater *d, const unsigned char *p)
{
    uint32_t v = d->cfg.hlen == 4 ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                                        (uint32_t)p[3] << 24
                                  : ((uint32_t)p[0] << 16) | ((uint32_t)p[1] << 8) | p[2];
    return (v * 2654435761u) >> (32 - d->cfg.hbits);
}

/* Can position pos be hashed (cfg.hlen bytes from pos inside the input)? */
static inline int hashable(const deflater *d, size_t pos)
{
    return pos + (size_t)d->cfg.hlen <= d->n;
}

/* Insert position pos (hashable) and return the previous chain head. */
static inline int32_t insert_pos(deflater *d, size_t pos)
{
    uint32_t h = hash_at(d, d->in + pos);
    int32_t old = d->head[h];
    d->prev[pos & WMASK] = old;
    d->head[h] = (int32_t)pos;
    return old;
}

/* Longest match for pos among the chain starting at cur that is longer than
 * prev_len (and >= MIN_MATCH); returns its length or 0. */
static inline int longest_match(const deflater *d, size_t pos, int32_t cur, int prev_len, int *mdist)
{
    const unsigned char *s = d->in + pos;
    size_t avail = d->n - pos;
    int maxlen = avail < MAX_MATCH ? (int)avail : MAX_MATCH;
    int best = prev_len < MIN_MATCH - 1 ? MIN_MATCH - 1 : prev_len;
    int found = 0;
    if (best >= maxlen)
        return 0;
    int chain = d->cfg.chain;
    if (prev_len >= d->cfg.good)
        chain >>= 2;
    int nice = d->cfg.nice < maxlen ? d->cfg.nice : maxlen;
    uint16_t end2, start2;
    memcpy(&end2, s + best - 1, 2);
    memcpy(&start2, s, 2);
    while (cur >= 0 && pos - (size_t)cur <= MAX_DIST && chain-- > 0) {
        const unsigned char *m = d->in + cur;
        uint16_t me, ms;
        memcpy(&me, m + best - 1, 2);
        memcpy(&ms, m, 2);
        /* a longer match must agree at best-1, best and at the start */
        if (me == end2 && ms == start2) {
            int len = 2;
            while (len + 8 <= maxlen) {
                uint64_t a, b;
                memcpy(&a, m + len, 8);
                memcpy(&b, s + len, 8);
                if (a != b) {
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
                    len += __builtin_ctzll(a ^ b) >> 3; /* first differing byte */
                    goto counted;
#else
                    break;
#endif
                }
                len += 8;
            }
            while (len < maxlen && m[len] == s[len])
                len++;
#if defined(__GNUC__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
        counted:
#endif
            if (len > best) {
                best = len;
                found = 1;
                if (len < maxlen)
                    memcpy(&end2, s + best - 1, 2);
                *mdist = (int)(pos - (size_t)cur);
                if (len >= nice)
                    break;
            }
        }
        int32_t nx = d->prev[cur & WMASK];
        if (nx >= cur) /* slot reused by a newer position: chain ends */
            break;
        cur = nx;
    }
    return found ? best : 0;
}

/* ----------------------------------------------------------- block output */

static const uint8_t cl_order[NCL] = {16, 17, 18, 0, 8, 7, 9, 6, 10, 5, 11, 4, 12, 3, 13, 2, 14, 1, 15};

static void fixed_lengths(uint8_t *ll, uint8_t *dl)
{
    for (int i = 0; i < NLIT; i++)
        ll[i] = i < 144 ? 8 : i < 256 ? 9 : i < 280 ? 7 : 8;
    for (int i = 0; i < NDIST; i++)
        dl[i] = 5;
}

/* Write the block's symbols and its end code. Space for the worst case
 * (48 bits per symbol: 15 + 5 + 15 + 13) is reserved first, so the loop
 * keeps the bit buffer in registers and stores 4 bytes whenever 32 bits are
 * pending, with no capacity checks. */
static void write_symbols(deflater *d, const uint8_t *ll, const uint16_t *lc, const uint8_t *dl,
                          const uint16_t *dc)
{
    bitw *w = &d->w;
    if (!bw_reserve(w, (size_t)d->nsyms * 6 + 16))
        return;
    uint64_t bits = w->bits;
    int nbits = w->nbits;
    unsigned char *o = w->buf + w->len;
#define PUTBITS(v, n)                                                                              \
    do {                                                                                           \
        bits |= (uint64_t)(v) << nbits;                                                            \
        nbits += (n);                                                                              \
        if (nbits >= 32) {                                                                         \
            o[0] = (unsigned char)bits, o[1] = (unsigned char)(bits >> 8);                        \
            o[2] = (unsigned char)(bits >> 16), o[3] = (unsigned char)(bits >> 24);               \
            o += 4;                                                                                \
            bits >>= 32;                                                                           \
            nbits -= 32;                                                                           \
        }                                                                                          \
    } while (0)
    for (int i = 0; i < d->nsyms; i++) {
        int v = d->sym_ll[i], dist = d->sym_d[i];
        if (dist == 0) {
            PUTBITS(lc[v], ll[v]);
        } else {
            int ls = len_tab[v - 3], ds = dist_code(dist);
            /* code and extra bits together: at most 15 + 5 and 15 + 13 bits */
            PUTBITS(lc[257 + ls] | (uint32_t)(v - sym_base[ls]) << ll[257 + ls],
                    ll[257 + ls] + sym_nx[ls]);
            PUTBITS(dc[ds] | (uint32_t)(dist - sym_base[32 + ds]) << dl[ds],
                    dl[ds] + sym_nx[32 + ds]);
        }
    }
    PUTBITS(lc[256], ll[256]);
#undef PUTBITS
    w->len = (size_t)(o - w->buf);
    w->bits = bits;
    w->nbits = nbits;
}

/* Emit the pending symbols as one block (or several stored blocks). */
static void flush_block(deflater *d, int final, int force_stored)
{
    bitw *w = &d->w;
    d->lfreq[256] = 1;

    /* bits spent on extra bits, the same for fixed and dynamic */
    uint64_t extra_bits = 0;
    for (int s = 265; s < 285; s++)
        extra_bits += (uint64_t)d->lfreq[s] * (uint64_t)((s - 261) / 4);
    for (int s = 4; s < 30; s++)
        extra_bits += (uint64_t)d->dfreq[s] * (uint64_t)((s - 2) / 2);

    /* dynamic code */
    uint8_t ll[NLIT], dl[NDIST];
    huff_lengths(d->lfreq, 286, 15, ll);
    ll[286] = ll[287] = 0;
    huff_lengths(d->dfreq, 30, 15, dl);
    dl[30] = dl[31] = 0;
    if (dl[0] == 0 && dl[1] == 0) {
        int any = 0;
        for (int i = 0; i < 30; i++)
            any |= dl[i];
        if (!any) /* no distances: two 1-bit codes keep the code complete */
            dl[0] = dl[1] = 1;
    }
    int hlit = 286, hdist = 30;
    while (hlit > 257 && ll[hlit - 1] == 0)
        hlit--;
    while (hdist > 1 && dl[hdist - 1] == 0)
        hdist--;

    /* run-length code the concatenated lengths (§3.2.7) */
    uint8_t all[286 + 30];
    memcpy(all, ll, (size_t)hlit);
    memcpy(all + hlit, dl, (size_t)hdist);
    int nall = hlit + hdist;
    uint8_t rl_sym[286 + 30], rl_x[286 + 30];
    int nrl = 0;
    uint32_t clfreq[NCL] = {0};
    for (int i = 0; i < nall;) {
        int l = all[i], run = 1;
        while (i + run < nall && all[i + run] == l)
            run++;
        i += run;
        if (l == 0) {
            while (run >= 11) {
                int r = run < 138 ? run : 138;
                rl_sym[nrl] = 18, rl_x[nrl++] = (uint8_t)(r - 11);
                run -= r;
            }
            if (run >= 3) {
                rl_sym[nrl] = 17, rl_x[nrl++] = (uint8_t)(run - 3);
                run = 0;
            }
        } else {
            rl_sym[nrl] = (uint8_t)l, rl_x[nrl++] = 0;
            run--;
            while (run >= 3) {
                int r = run < 6 ? run : 6;
                rl_sym[nrl] = 16, rl_x[nrl++] = (uint8_t)(r - 3);
                run -= r;
            }
        }
        while (run-- > 0)
            rl_sym[nrl] = (uint8_t)l, rl_x[nrl++] = 0;
    }
    for (int i = 0; i < nrl; i++)
        clfreq[rl_sym[i]]++;
    uint8_t cll[NCL];
    uint16_t clc[NCL];
    huff_lengths(clfreq, NCL, 7, cll);
    int hclen = NCL;
    while (hclen > 4 && cll[cl_order[hclen - 1]] == 0)
        hclen--;

    uint64_t dyn = 3 + 14 + 3 * (uint64_t)hclen + extra_bits;
    for (int i = 0; i < NCL; i++)
        dyn += (uint64_t)clfreq[i] * cll[i];
    dyn += 2 * (uint64_t)clfreq[16] + 3 * (uint64_t)clfreq[17] + 7 * (uint64_t)clfreq[18];
    for (int i = 0; i < 286; i++)
        dyn += (uint64_t)d->lfreq[i] * ll[i];
    for (int i = 0; i < 30; i++)
        dyn += (uint64_t)d->dfreq[i] * dl[i];

    uint8_t fll[NLIT], fdl[NDIST];
    fixed_lengths(fll, fdl);
    uint64_t fix = 3 + extra_bits;
    for (int i = 0; i < 286; i++)
        fix += (uint64_t)d->lfreq[i] * fll[i];
    for (int i = 0; i < 30; i++)
        fix += (uint64_t)d->dfreq[i] * 5;

    size_t raw = d->covered - d->block_start;
    uint64_t sto = 0;
    {
        int pos = w->nbits & 7;
        size_t left = raw;
        do {
            size_t k = left < 65535 ? left : 65535;
            sto += 3 + (uint64_t)((8 - (pos + 3) % 8) % 8) + 32 + 8 * (uint64_t)k;
            pos = 0;
            left -= k;
        } while (left > 0);
    }

    if (force_stored || (sto < dyn && sto < fix)) {
        const unsigned char *p = d->in + d->block_start;
        size_t left = raw;
        do {
            size_t k = left < 65535 ? left : 65535;
            left -= k;
            bw_put(w, (uint32_t)(final && left == 0), 1);
            bw_put(w, 0, 2);
            bw_align(w);
            unsigned char hdr[4] = {(unsigned char)k, (unsigned char)(k >> 8), (unsigned char)~k,
                                    (unsigned char)(~k >> 8)};
            bw_bytes(w, hdr, 4);
            bw_bytes(w, p, k);
            p += k;
        } while (left > 0);
    } else if (fix <= dyn) {
        uint16_t lc[NLIT], dc[NDIST];
        huff_codes(fll, NLIT, lc);
        huff_codes(fdl, NDIST, dc);
        bw_put(w, (uint32_t)final, 1);
        bw_put(w, 1, 2);
        write_symbols(d, fll, lc, fdl, dc);
    } else {
        uint16_t lc[NLIT], dc[NDIST];
        huff_codes(ll, NLIT, lc);
        huff_codes(dl, NDIST, dc);
        huff_codes(cll, NCL, clc);
        bw_put(w, (uint32_t)final, 1);
        bw_put(w, 2, 2);
        bw_put(w, (uint32_t)(hlit - 257), 5);
        bw_put(w, (uint32_t)(hdist - 1), 5);
        bw_put(w, (uint32_t)(hclen - 4), 4);
        for (int i = 0; i < hclen; i++)
            bw_put(w, cll[cl_order[i]], 3);
        for (int i = 0; i < nrl; i++) {
            int s = rl_sym[i];
            bw_put(w, clc[s], cll[s]);
            if (s == 16)
                bw_put(w, rl_x[i], 2);
            else if (s == 17)
                bw_put(w, rl_x[i], 3);
            else if (s == 18)
                bw_put(w, rl_x[i], 7);
        }
        write_symbols(d, ll, lc, dl, dc);
    }
    d->nsyms = 0;
    memset(d->lfreq, 0, sizeof d->lfreq);
    memset(d->dfreq, 0, sizeof d->dfreq);
    d->block_start = d->covered;
}

static inline void emit_lit(deflater *d, int c)
{
    d->sym_ll[d->nsyms] = (uint16_t)c;
    d->sym_d[d->nsyms++] = 0;
    d->lfreq[c]++;
    d->covered++;
    if (d->nsyms == BLOCK_SYMS)
        flush_block(d, 0, 0);
}

static inline void emit_match(deflater *d, int len, int dist)
{
    d->sym_ll[d->nsyms] = (uint16_t)len;
    d->sym_d[d->nsyms++] = (uint16_t)dist; /* 32768 fits in 16 bits */
    d->lfreq[257 + len_tab[len - 3]]++;
    d->dfreq[dist_code(dist)]++;
    d->covered += (size_t)len;
    if (d->nsyms == BLOCK_SYMS)
        flush_block(d, 0, 0);
}

static void lz_greedy(deflater *d)
{
    size_t n = d->n, pos = 0;
    while (pos < n) {
        int32_t hh = hashable(d, pos) ? insert_pos(d, pos) : -1;
        int ml = 0, md = 0;
        if (hh >= 0 && pos - (size_t)hh <= MAX_DIST)
            ml = longest_match(d, pos, hh, 0, &md);
        if (ml >= MIN_MATCH) {
            emit_match(d, ml, md);
            if (ml <= d->cfg.lazy)
                for (size_t p = pos + 1; p < pos + (size_t)ml && hashable(d, p); p++)
                    insert_pos(d, p);
            pos += (size_t)ml;
        } else {
            emit_lit(d, d->in[pos]);
            pos++;
        }
    }
}

/* zlib's lazy evaluation: a match found at pos-1 is emitted only if pos
 * does not start a longer one; otherwise pos-1 becomes a literal. */
static void lz_lazy(deflater *d)
{
    size_t n = d->n, pos = 0;
    int match_len = 0, match_dist = 0, avail = 0;
    while (pos < n) {
        int32_t hh = hashable(d, pos) ? insert_pos(d, pos) : -1;
        int prev_len = match_len, prev_dist = match_dist;
        match_len = 0;
        if (hh >= 0 && pos - (size_t)hh <= MAX_DIST && prev_len < d->cfg.lazy) {
            match_len = longest_match(d, pos, hh, prev_len, &match_dist);
            if (match_len == MIN_MATCH && match_dist > TOO_FAR)
                match_len = 0;
        }
        if (prev_len >= MIN_MATCH && match_len <= prev_len) {
            emit_match(d, prev_len, prev_dist);
            size_t end = pos - 1 + (size_t)prev_len, p = pos + 1;
            if (d->cfg.insert_max && prev_len > d->cfg.insert_max)
                p = end - 2;
            for (; p < end && hashable(d, p); p++)
                insert_pos(d, p);
            pos = end;
            avail = 0;
            match_len = 0;
        } else if (avail) {
            emit_lit(d, d->in[pos - 1]);
            pos++;
        } else {
            avail = 1;
            pos++;
        }
    }
    if (avail)
        emit_lit(d, d->in[n - 1]);
}

static rt_code deflate_to(const unsigned char *in, size_t n, int level, bitw *w, rt_error *e)
{
    if (level < 0 || level > 9)
        return rt_fail(e, RT_EINVAL, "deflate level %d is out of range (expected 0..9)", level);
    deflater *d = rt_calloc(1, sizeof *d);
    if (!d)
        return rt_fail(e, RT_ENOMEM, "out of memory for the deflate state");
    /* empty input may come as (NULL, 0); d->in + offset must stay defined */
    static const unsigned char no_input[1];
    d->in = in ? in : no_input;
    d->n = n;
    d->cfg = level_cfgs[level];
    pthread_once(&tab_once, tab_init);
    d->w = *w;
    if (level > 0) {
        d->head = rt_malloc(((size_t)1 << HBITS_MAX) * sizeof *d->head);
        d->prev = rt_malloc(WSIZE * sizeof *d->prev);
        d->sym_ll = rt_malloc(BLOCK_SYMS * sizeof *d->sym_ll);
        d->sym_d = rt_malloc(BLOCK_SYMS * sizeof *d->sym_d);
        if (!d->head || !d->prev || !d->sym_ll || !d->sym_d) {
            rt_free(d->head), rt_free(d->prev), rt_free(d->sym_ll), rt_free(d->sym_d);
            *w = d->w;
            rt_free(d);
            return rt_fail(e, RT_ENOMEM, "out of memory for the deflate state");
        }
        for (int i = 0; i < (1 << d->cfg.hbits); i++)
            d->head[i] = -1;
        for (int i = 0; i < WSIZE; i++)
            d->prev[i] = -1;
        if (d->cfg.lazy_mode)
            lz_lazy(d);
        else
            lz_greedy(d);
        flush_block(d, 1, 0);
    } else {
        d->covered = n; /* level 0: everything as stored blocks */
        flush_block(d, 1, 1);
    }
    bw_align(&d->w);
    *w = d->w;
    rt_free(d->head), rt_free(d->prev), rt_free(d->sym_ll), rt_free(d->sym_d);
    rt_free(d);
    if (w->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory for deflate output");
    return RT_OK;
}

static rt_code append_out(bitw *w, bytebuf *out, rt_error *e)
{
    bytebuf_append(out, w->buf, w->len);
    rt_free(w->buf);
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory for deflate output");
    return RT_OK;
}

rt_code deflate_raw(const unsigned char *in, size_t n, int level, bytebuf *out, rt_error *e)
{
    bitw w = {0};
    rt_code c = deflate_to(in, n, level, &w, e);
    if (c) {
        rt_free(w.buf);
        return c;
    }
    return append_out(&w, out, e);
}

rt_code deflate_zlib(const unsigned char *in, size_t n, int level, bytebuf *out, rt_error *e)
{
    bitw w = {0};
    /* CMF: method 8, 32 KiB window; FLG: level hint, no dictionary, and the
     * check bits making CMF*256+FLG a multiple of 31 (RFC 1950 §2.2). */
    unsigned cmf = 0x78, flevel = level <= 1 ? 0 : level <= 5 ? 1 : level == 6 ? 2 : 3;
    unsigned flg = flevel << 6;
    flg += (31 - (cmf * 256 + flg) % 31) % 31;
    unsigned char hdr[2] = {(unsigned char)cmf, (unsigned char)flg};
    bw_bytes(&w, hdr, 2);
    rt_code c = deflate_to(in, n, level, &w, e);
    if (c) {
        rt_free(w.buf);
        return c;
    }
    uint32_t a = deflate_adler32(1, in, n);
    unsigned char tr[4] = {(unsigned char)(a >> 24), (unsigned char)(a >> 16), (unsigned char)(a >> 8),
                           (unsigned char)a};
    bw_bytes(&w, tr, 4);
    if (w.failed) {
        rt_free(w.buf);
        return rt_fail(e, RT_ENOMEM, "out of memory for deflate output");
    }
    return append_out(&w, out, e);
}
