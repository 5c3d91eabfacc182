/* shard.c — part files, partial values, taint and re-run, merge (see shard.h). */
#include "shard.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deflate.h"
#include "builtin.h"
#include "lang_objects.h"
#include "session.h"
#include "sha256.h"

/* ---- small helpers ------------------------------------------------------------ */

/* CRC-32 of the PNG/zlib kind (reflected polynomial 0xEDB88320; equal to
 * deflate_crc32), eight bytes a step ("slicing-by-8": table k advances a
 * byte through k more zero bytes), so checking parts costs little next to
 * reading them. */
static uint32_t crc_tab[8][256];
static pthread_once_t crc_once = PTHREAD_ONCE_INIT;

static void crc_init(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++)
            c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_tab[0][n] = c;
    }
    for (uint32_t n = 0; n < 256; n++)
        for (int k = 1; k < 8; k++)
            crc_tab[k][n] = crc_tab[0][crc_tab[k - 1][n] & 0xFF] ^ (crc_tab[k - 1][n] >> 8);
}

static uint32_t part_crc(uint32_t crc, const void *data, size_t n)
{
    pthread_once(&crc_once, crc_init);
    const unsigned char *p = data;
    uint32_t c = crc ^ 0xFFFFFFFFu;
    for (; n >= 8; n -= 8, p += 8) {
        uint32_t lo = c ^ ((uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24);
        uint32_t hi = (uint32_t)p[4] | (uint32_t)p[5] << 8 | (uint32_t)p[6] << 16 | (uint32_t)p[7] << 24;
        c = crc_tab[7][lo & 0xFF] ^ crc_tab[6][(lo >> 8) & 0xFF] ^ crc_tab[5][(lo >> 16) & 0xFF] ^ crc_tab[4][lo >> 24] ^
            crc_tab[3][hi & 0xFF] ^ crc_tab[2][(hi >> 8) & 0xFF] ^ crc_tab[1][(hi >> 16) & 0xFF] ^ crc_tab[0][hi >> 24];
    }
    while (n--)
        c = crc_tab[0][(c ^ *p++) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
}

static void put_u32(bytebuf *b, uint32_t v) { bytebuf_u32le(b, v); }
static void put_u64(bytebuf *b, uint64_t v)
{
    bytebuf_u32le(b, (uint32_t)v);
    bytebuf_u32le(b, (uint32_t)(v >> 32));
}
static void put_str(bytebuf *b, const char *s)
{
    put_u32(b, (uint32_t)strlen(s));
    bytebuf_append(b, s, strlen(s));
}
static uint32_t get_u32(const unsigned char *p) { return p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t get_u64(const unsigned char *p) { return get_u32(p) | (uint64_t)get_u32(p + 4) << 32; }

static int parse_count(const char *s, long lo, long *out)
{
    if (!s || !*s)
        return -1;
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > SHARD_MAX_PARTS)
        return -1;
    *out = v;
    return 0;
}

static void chunk_range(size_t nchunks, int i, int n, size_t *lo, size_t *hi)
{
    /* contiguous: shard i of n computes chunks [nchunks*i/n, nchunks*(i+1)/n) */
    *lo = (size_t)((unsigned __int128)nchunks * (unsigned)i / (unsigned)n);
    *hi = (size_t)((unsigned __int128)nchunks * (unsigned)(i + 1) / (unsigned)n);
}

/* ---- the command line ------------------------------------------------------------ */

/* In this order. An MPI launcher's rank comes before SLURM_PROCID: a batch
 * job's script is task 0 of its job, so every rank that `mpirun` starts in
 * it inherits SLURM_PROCID=0 (seen on Slurm 22.05, tests/shard/slurm_real.sh);
 * only srun sets SLURM_PROCID a task. An array task's number (min and step
 * taken off: --array=A-B:S) comes first, as the one a user asked for. */
static const struct {
    const char *rank, *size, *min, *step;
} launchers[] = {
    {"SLURM_ARRAY_TASK_ID", "SLURM_ARRAY_TASK_COUNT", "SLURM_ARRAY_TASK_MIN", "SLURM_ARRAY_TASK_STEP"},
    {"OMPI_COMM_WORLD_RANK", "OMPI_COMM_WORLD_SIZE", NULL, NULL},
    {"PMI_RANK", "PMI_SIZE", NULL, NULL},
    {"SLURM_PROCID", "SLURM_NTASKS", NULL, NULL},
};

static void shard_zero(shard *s)
{
    memset(s, 0, sizeof *s);
    s->pending = -1;
    s->cur = -1;
    s->win_seq = -1;
    s->win_taken = -1;
}

int shard_init_run(shard *s, const char *spec)
{
    shard_zero(s);
    long i = -1, n = -1;
    if (strcmp(spec, "auto") == 0) {
        size_t k;
        for (k = 0; k < sizeof launchers / sizeof launchers[0]; k++) {
            const char *r = getenv(launchers[k].rank), *z = getenv(launchers[k].size);
            if (!r)
                continue;
            long mn = 0, st = 1;
            const char *m = launchers[k].min ? getenv(launchers[k].min) : NULL;
            const char *t = launchers[k].step ? getenv(launchers[k].step) : NULL;
            if (parse_count(r, 0, &i) || parse_count(z, 1, &n) || (m && parse_count(m, 0, &mn)) ||
                (t && parse_count(t, 1, &st))) {
                fprintf(stderr, "frac: --shard auto: %s=%s with %s=%s is not a shard number and count\n"
                                "(run `frac --help` for usage)\n",
                        launchers[k].rank, r, launchers[k].size, z ? z : "(unset)");
                return -1;
            }
            /* a list (--array=1,4,7) has no step: Slurm sets 1, and its gaps give
               a number out of range here */
            if (launchers[k].min && ((i - mn) % st != 0 || i < mn || (i - mn) / st >= n)) {
                fprintf(stderr,
                        "frac: --shard auto: %s=%s with %s=%ld, %s=%ld and %s=%ld is not a shard: "
                        "(ID - MIN) / STEP must be a whole number in 0..%ld (an --array range A-B or A-B:S "
                        "numbers the shards, a list does not)\n(run `frac --help` for usage)\n",
                        launchers[k].rank, r, launchers[k].min, mn, launchers[k].step, st, launchers[k].size, n,
                        n - 1);
                return -1;
            }
            if (!launchers[k].min && (i < 0 || i >= n)) {
                fprintf(stderr, "frac: --shard auto: %s=%s gives shard %ld, not in 0..%ld\n(run `frac --help` for usage)\n",
                        launchers[k].rank, r, i, n - 1);
                return -1;
            }
            i = (i - mn) / st;
            break;
        }
        if (k == sizeof launchers / sizeof launchers[0]) {
            fprintf(stderr, "frac: --shard auto: no launcher environment found (SLURM_ARRAY_TASK_ID, "
                            "OMPI_COMM_WORLD_RANK, PMI_RANK or SLURM_PROCID); give --shard I/N\n(run `frac --help` for usage)\n");
            return -1;
        }
    } else {
        const char *sl = strchr(spec, '/');
        char ib[32];
        if (sl && (size_t)(sl - spec) < sizeof ib) {
            memcpy(ib, spec, (size_t)(sl - spec));
            ib[sl - spec] = 0;
        }
        if (!sl || (size_t)(sl - spec) >= sizeof ib || parse_count(ib, 0, &i) || parse_count(sl + 1, 1, &n) || i >= n) {
            fprintf(stderr, "frac: --shard takes I/N with 0 <= I < N <= %d, or auto; got '%s'\n"
                            "(run `frac --help` for usage)\n",
                    SHARD_MAX_PARTS, spec);
            return -1;
        }
    }
    s->index = (int)i;
    s->count = (int)n;
    return 0;
}

void shard_init_merge(shard *s, char *const *parts, int nparts)
{
    shard_zero(s);
    s->merging = 1;
    s->all = parts;
    s->nall = nparts;
}

static int peek_frame(const char *path, long *f);

void shard_new_frame(shard *s)
{
    s->nfull = 0;
    s->again = 0;
}

/* merge --frames: this frame's parts among all given (by their headers); a
 * part of a frame outside the range is an error. */
static int select_frame(shard *s)
{
    interp *I = s->I;
    s->parts = s->all;
    s->nparts = s->nall;
    if (!I->frames_given)
        return 0;
    s->sel = mem_calloc(I, (size_t)s->nall + 1, sizeof *s->sel);
    if (!s->sel)
        return -1;
    int n = 0;
    for (int p = 0; p < s->nall; p++) {
        long f;
        if (peek_frame(s->all[p], &f)) {
            s->sel[n++] = s->all[p]; /* check_part says what is wrong with it */
            continue;
        }
        if (f < I->frame_first || f > I->frame_last || (f - I->frame_first) % I->frame_step != 0)
            return err_pos(I, -1, 0, 0, ERR_VALUE, "merge: '%s' is of frame %ld, not one of --frames %ld..%ld:%ld", s->all[p], f,
                           I->frame_first, I->frame_last, I->frame_step);
        if (f == I->frame)
            s->sel[n++] = s->all[p];
    }
    s->parts = s->sel;
    s->nparts = n;
    return 0;
}

/* ---- the header --------------------------------------------------------------- */

/* params as given with -D, sorted by name, one NAME=VALUE per line */
static void params_text(interp *I, bytebuf *b)
{
    int n = I->noverrides, done[256] = {0};
    for (int k = 0; k < n && k < 256; k++) {
        int best = -1;
        for (int j = 0; j < n && j < 256; j++)
            if (!done[j] && (best < 0 || strcmp(I->overrides[j].name, I->overrides[best].name) < 0))
                best = j;
        done[best] = 1;
        bytebuf_printf(b, "%s=%s\n", I->overrides[best].name, I->overrides[best].text);
    }
    bytebuf_byte(b, 0);
}

/* "for frame 3 of --frames 0..8:2", or "without --frames" */
static void frame_text(char *buf, size_t size, int given, long f, long a, long b, long step)
{
    if (!given)
        snprintf(buf, size, "without --frames");
    else
        snprintf(buf, size, "for frame %ld of --frames %ld..%ld:%ld", f, a, b, step);
}

static void header(shard *s, bytebuf *b, int index, int count)
{
    bytebuf pt;
    bytebuf_init(&pt);
    params_text(s->I, &pt);
    bytebuf_append(b, "FRACPART", 8);
    put_u32(b, SHARD_FORMAT);
    put_str(b, FRAC_VERSION);
    put_str(b, "sha256");
    bytebuf_append(b, s->hash, sizeof s->hash);
    put_u64(b, s->I->seed);
    interp *I = s->I; /* the frame: --frames given, the frame, the range */
    put_u32(b, (uint32_t)I->frames_given);
    put_u64(b, (uint64_t)(I->frames_given ? I->frame : 0));
    put_u64(b, (uint64_t)(I->frames_given ? I->frame_first : 0));
    put_u64(b, (uint64_t)(I->frames_given ? I->frame_last : 0));
    put_u64(b, (uint64_t)(I->frames_given ? I->frame_step : 0));
    put_str(b, pt.data ? (const char *)pt.data : "");
    put_u32(b, (uint32_t)index);
    put_u32(b, (uint32_t)count);
    bytebuf_free(&pt);
    put_u32(b, part_crc(0, b->data, b->len));
}

/* ---- records -------------------------------------------------------------------- */

#define REC_HEAD 80 /* "REC " seq sub op kind[16] nchunks lo hi total chunk_bytes payload */

struct shard_rec {
    uint32_t seq, sub, op;
    char kind[16];
    uint64_t nchunks, total, chunk_bytes;
    double win[6]; /* SHARD_OP_WINDOW: its payload, lo[dim] then hi[dim]; zero otherwise */
};

static void rec_head(bytebuf *b, const shard_rec *r, uint64_t lo, uint64_t hi, uint64_t payload)
{
    bytebuf_append(b, "REC ", 4);
    put_u32(b, r->seq);
    put_u32(b, r->sub);
    put_u32(b, r->op);
    bytebuf_append(b, r->kind, 16);
    put_u64(b, r->nchunks);
    put_u64(b, lo);
    put_u64(b, hi);
    put_u64(b, r->total);
    put_u64(b, r->chunk_bytes);
    put_u64(b, payload);
}

/* Room for n more bytes at b->data + b->len (0), or b->failed (-1). */
static int reserve(bytebuf *b, size_t n)
{
    if (b->failed)
        return -1;
    if (n <= b->cap - b->len)
        return 0;
    size_t ncap = b->cap ? b->cap : 256;
    while (ncap - b->len < n) {
        if (ncap > SIZE_MAX / 2) {
            b->failed = 1;
            return -1;
        }
        ncap *= 2;
    }
    unsigned char *nd = rt_realloc(b->data, ncap);
    if (!nd) {
        b->failed = 1;
        return -1;
    }
    b->data = nd;
    b->cap = ncap;
    return 0;
}

/* Sums are stored as unsigned LEB128 (7 bits a byte, low group first, the
 * high bit set on every byte but a value's last), and a 0 is always
 * followed by a second number, how many more zeros follow it (a run of L
 * zeros is 0, L - 1): most bins of a render's histogram are empty (85 % of
 * the 1024² fern's), and they lie in long runs beside and between the
 * attractor's arms. Returns the bytes added. a holds n uint64 (unit 8) or
 * uint32 (unit 4, par_part_sum32): the same values give the same bytes. */
static inline uint64_t sum_at(const void *a, size_t unit, size_t i)
{
    return unit == 4 ? ((const uint32_t *)a)[i] : ((const uint64_t *)a)[i];
}

static uint64_t put_sums(bytebuf *b, const void *a, size_t unit, size_t n)
{
    size_t start = b->len;
    for (size_t i = 0; i < n;) {
        size_t m = n - i < 4096 ? n - i : 4096; /* a block of at most ten bytes a value */
        if (reserve(b, 10 * m + 11)) /* + a run's count: a run takes 11 bytes at most */
            return 0;
        unsigned char *o = b->data + b->len;
        size_t end = i + m;
        while (i < end) {
            uint64_t v = sum_at(a, unit, i);
            if (!v) { /* a run, however long (past the block: its bytes fit) */
                size_t j = i + 1;
                if (unit == 4) {
                    const uint32_t *a4 = a;
                    while (n - j >= 8 && !(a4[j] | a4[j + 1] | a4[j + 2] | a4[j + 3] | a4[j + 4] | a4[j + 5] | a4[j + 6] | a4[j + 7]))
                        j += 8;
                } else {
                    const uint64_t *a8 = a;
                    while (n - j >= 8 && !(a8[j] | a8[j + 1] | a8[j + 2] | a8[j + 3] | a8[j + 4] | a8[j + 5] | a8[j + 6] | a8[j + 7]))
                        j += 8;
                }
                while (j < n && !sum_at(a, unit, j))
                    j++;
                *o++ = 0;
                v = j - i - 1;
                i = j;
            } else {
                i++;
            }
            while (v >= 0x80) {
                *o++ = (unsigned char)(v | 0x80);
                v >>= 7;
            }
            *o++ = (unsigned char)v;
        }
        b->len = (size_t)(o - b->data);
    }
    return b->len - start;
}

/* Decoding sums block by block (a value may straddle two blocks). */
typedef struct sum_dec {
    uint64_t v, n, want; /* value so far; values done; values expected */
    unsigned shift;
    int run; /* the number being read is a run's count (a 0 came before it) */
    int bad; /* more than 64 bits, more values than expected, a uint32 sum past 2^32 - 1 */
    size_t unit; /* acc holds uint64 (8) or uint32 (4) */
} sum_dec;

/* acc[n] += v for a uint64 or uint32 acc; 1 if a uint32 sum would wrap. */
static inline int sum_add(void *acc, size_t unit, uint64_t n, uint64_t v)
{
    if (unit != 4) {
        ((uint64_t *)acc)[n] += v;
        return 0;
    }
    uint32_t *a = acc;
    uint64_t t = a[n] + v;
    a[n] = (uint32_t)t;
    return t > UINT32_MAX;
}

/* acc: add each value into acc[n] (NULL: only check the structure); a run
 * of zeros adds nothing. Numbers of one or two bytes (nearly all: values
 * below 2^14, runs shorter than 129) are taken whole by the first loop;
 * the second reads any number byte by byte, across blocks too. */
#if defined(__GNUC__)
#define SUM_INLINE static inline __attribute__((always_inline))
#else
#define SUM_INLINE static inline
#endif
SUM_INLINE void sum_decode_as(sum_dec *d, const unsigned char *p, size_t len, void *acc, const size_t unit)
{
    /* locals: the stores into acc could alias d's fields */
    uint64_t v = d->v, n = d->n, want = d->want;
    unsigned shift = d->shift;
    int run = d->run, bad = d->bad;
    size_t i = 0;
    while (i < len && !bad) {
        while (shift == 0 && !run && len - i >= 2 && n < want) {
            unsigned c = p[i], c1 = p[i + 1];
            if (c - 1 < 0x7f) { /* 1 … 127 */
                if (acc && sum_add(acc, unit, n, c)) {
                    bad = 1;
                    break;
                }
                n++, i++;
            } else if (c == 0 && c1 < 0x80) { /* 0 and a one-byte count: c1 + 1 zeros */
                if (c1 >= want - n) {
                    bad = 1;
                    break;
                }
                n += c1 + 1u, i += 2;
            } else if (c >= 0x80 && c1 - 1 < 0x7f) { /* 128 … 16383 */
                if (acc && sum_add(acc, unit, n, (c & 0x7fu) | (uint64_t)c1 << 7)) {
                    bad = 1;
                    break;
                }
                n++, i += 2;
            } else {
                break;
            }
        }
        if (bad || i >= len)
            break;
        unsigned c = p[i++];
        if (shift > 63 || (shift == 63 && (c & 0x7e))) {
            bad = 1;
            break;
        }
        v |= (uint64_t)(c & 0x7f) << shift;
        if (c & 0x80) {
            shift += 7;
            continue;
        }
        shift = 0;
        if (run) { /* v more zeros */
            if (v > want - n) {
                bad = 1;
                break;
            }
            n += v;
            run = 0;
        } else {
            if (n >= want) {
                bad = 1;
                break;
            }
            if (!v)
                run = 1;
            else if (acc && sum_add(acc, unit, n, v)) {
                bad = 1;
                break;
            }
            n++;
        }
        v = 0;
    }
    d->v = v, d->n = n, d->shift = shift, d->run = run, d->bad = bad;
}

/* one copy of the decoder per width (the width a constant in the loop) */
static void sum_decode(sum_dec *d, const unsigned char *p, size_t len, void *acc)
{
    if (d->unit == 4)
        sum_decode_as(d, p, len, acc, 4);
    else
        sum_decode_as(d, p, len, acc, 8);
}

static int sum_done(const sum_dec *d) { return !d->bad && d->shift == 0 && !d->run && d->n == d->want; }

static void payload_range(const shard_rec *r, size_t lo, size_t hi, uint64_t *from, uint64_t *len)
{
    if (r->op != PAR_OP_ROWS) { /* SUM, COMBINE: the whole accumulator */
        *from = 0;
        *len = r->total;
        return;
    }
    uint64_t a = (uint64_t)lo * r->chunk_bytes, z = (uint64_t)hi * r->chunk_bytes;
    if (a > r->total)
        a = r->total;
    if (z > r->total)
        z = r->total;
    *from = a;
    *len = z - a;
}

/* ---- the runtime's callbacks ------------------------------------------------------ */

static int is_full(const shard *s, uint32_t seq)
{
    for (int k = 0; k < s->nfull; k++)
        if (s->full[k] == seq)
            return 1;
    return 0;
}

static void where(interp *I, const node *n, char *buf, size_t size)
{
    if (n && n->src < I->nsrc)
        snprintf(buf, size, "%s:%d:%d", I->srcs[n->src].name, n->line + I->srcs[n->src].first_line - 1, n->col);
    else
        buf[0] = 0;
}

/* Call `seq` (made at `at`) cannot be sharded: compute it fully from now on. */
static int taint(shard *s, uint32_t seq, const node *at, const char *why)
{
    interp *I = s->I;
    if (s->nfull >= SHARD_MAX_FULL)
        return err_at(I, NULL, ERR_LIMIT, "--shard: more than %d engine calls cannot be sharded", SHARD_MAX_FULL);
    s->full[s->nfull++] = seq;
    s->again = 1;
    if (!I->quiet) {
        char a[512], b[512];
        where(I, at, a, sizeof a);
        where(I, I->cur, b, sizeof b);
        fprintf(stderr, "frac: note: engine call %u (at %s) is computed fully in every shard: its result %s%s%s\n",
                seq, a, why, b[0] ? " at " : "", b);
    }
    return err_at(I, NULL, ERR_RUNTIME, "--shard: abandoned to re-run (call %u is computed fully)", seq);
}

/* merge: the parts hold a record this evaluation did not use (they were
 * made by an evaluation that went otherwise: another script or variant). */
static int unused_record(shard *s)
{
    const shard_rec *r = &s->recs[s->next_rec];
    return err_pos(s->I, -1, 0, 0, ERR_VALUE,
                   "merge: the parts' record %u (engine call %u, %.16s) is not used by this evaluation of the script: "
                   "the parts come from another script or variant",
                   s->next_rec, r->seq, r->kind);
}

/* merge: step over the window record of the call whose window was taken
 * (it follows that call's sections); one not taken stays, to be reported
 * as unused. */
static void skip_window(shard *s)
{
    while (s->next_rec < s->nrecs && s->recs[s->next_rec].op == SHARD_OP_WINDOW &&
           (long)s->recs[s->next_rec].seq == s->win_taken) {
        for (int i = 0; i < s->count; i++) /* the same size in every part: head, doubles, CRC */
            s->off[i] += REC_HEAD + (long)s->recs[s->next_rec].total + 4;
        s->next_rec++;
    }
}

static int cb_begin(rt_sharder *rs, const char *kind, size_t nchunks, size_t *lo, size_t *hi)
{
    shard *s = (shard *)rs;
    interp *I = s->I;
    if (s->merging)
        skip_window(s);
    if (s->pending >= 0) { /* a second call inside one builtin while the first one is partial */
        taint(s, (uint32_t)s->pending, s->pending_at, "feeds another engine call inside the same builtin");
        return -1;
    }
    uint32_t seq = s->seq++;
    s->cur = -1;
    if (s->merging) {
        if (s->next_rec < s->nrecs && s->recs[s->next_rec].seq < seq) { /* the call it was for went by */
            unused_record(s);
            return -1;
        }
        if (s->next_rec < s->nrecs && s->recs[s->next_rec].seq == seq) {
            const shard_rec *r = &s->recs[s->next_rec];
            if (strncmp(r->kind, kind, 16) != 0 || r->nchunks != nchunks) {
                err_at(I, NULL, ERR_VALUE, "merge: engine call %u is %s with %zu chunks here, but %.16s with %llu chunks in the parts",
                       seq, kind, nchunks, r->kind, (unsigned long long)r->nchunks);
                return -1;
            }
            s->cur = seq;
            s->sub = 0;
            s->cur_nchunks = nchunks;
            return PAR_MERGE;
        }
        return PAR_FULL;
    }
    if (is_full(s, seq))
        return PAR_FULL;
    s->cur = seq;
    s->sub = 0;
    s->cur_nchunks = nchunks;
    memset(s->cur_kind, 0, sizeof s->cur_kind);
    snprintf(s->cur_kind, sizeof s->cur_kind, "%s", kind);
    chunk_range(nchunks, s->index, s->count, lo, hi);
    s->pending = seq;
    s->pending_at = I->cur;
    return PAR_SHARD;
}

static rt_code merge_section(shard *s, const shard_rec *want, void *buf, size_t unit, par_combine_fn fn, void *ctx,
                            rt_error *e);

static rt_code cb_section(rt_sharder *rs, par_part_op op, void *buf, size_t total, size_t chunk_bytes,
                          par_combine_fn fn, void *ctx, rt_error *e)
{
    shard *s = (shard *)rs;
    if (s->cur < 0)
        return rt_fail(e, RT_EINVAL, "internal: a shard section outside a sharded call");
    shard_rec r;
    memset(&r, 0, sizeof r);
    r.seq = (uint32_t)s->cur;
    r.sub = s->sub++;
    r.op = op;
    r.nchunks = s->cur_nchunks;
    size_t unit = op == PAR_OP_SUM && chunk_bytes == 4 ? 4 : 8; /* SUM: its integers' width */
    r.total = op == PAR_OP_SUM ? total / unit * 8 : total; /* a record counts 8 bytes a sum */
    r.chunk_bytes = op == PAR_OP_SUM ? 0 : chunk_bytes;
    if (s->merging) {
        if (s->next_rec >= s->nrecs)
            return rt_fail(e, RT_EFORMAT, "merge: the parts have no record for section %u of engine call %u", r.sub, r.seq);
        const shard_rec *p = &s->recs[s->next_rec];
        memcpy(r.kind, p->kind, 16);
        if (p->seq != r.seq || p->sub != r.sub || p->op != r.op || p->total != r.total || p->chunk_bytes != r.chunk_bytes)
            return rt_fail(e, RT_EFORMAT, "merge: engine call %u section %u: the parts hold %llu bytes (op %u), this run needs %llu (op %u)",
                           r.seq, r.sub, (unsigned long long)p->total, p->op, (unsigned long long)r.total, r.op);
        rt_code c = merge_section(s, p, buf, unit, fn, ctx, e);
        s->next_rec++;
        return c;
    }
    memcpy(r.kind, s->cur_kind, 16);
    size_t lo, hi;
    chunk_range(r.nchunks, s->index, s->count, &lo, &hi);
    uint64_t from, len;
    payload_range(&r, lo, hi, &from, &len);
    size_t start = s->part.len;
    rec_head(&s->part, &r, lo, hi, len);
    if (op == PAR_OP_SUM) { /* LEB128, 7 bits a byte: most sums are small */
        len = put_sums(&s->part, buf, unit, total / unit);
        for (int q = 0; !s->part.failed && q < 8; q++) /* the length field, the head's last */
            s->part.data[start + REC_HEAD - 8 + q] = (unsigned char)(len >> 8 * q);
    } else {
        bytebuf_append(&s->part, (const unsigned char *)buf + from, (size_t)len); /* the host's bytes: little-endian */
    }
    if (s->part.failed)
        return rt_fail(e, RT_ENOMEM, "out of memory for the part file (%llu bytes)", (unsigned long long)len);
    put_u32(&s->part, part_crc(0, s->part.data + start, s->part.len - start));
    s->nrec++;
    return s->part.failed ? rt_fail(e, RT_ENOMEM, "out of memory for the part file") : RT_OK;
}

/* shard: the window record of split call seq, after its sections (its
 * chunk range like theirs, so every record of a part says whose it is). */
static void put_window(shard *s, uint32_t seq)
{
    shard_rec r;
    memset(&r, 0, sizeof r);
    r.seq = seq;
    r.sub = s->sub++;
    r.op = SHARD_OP_WINDOW;
    memcpy(r.kind, s->cur_kind, 16);
    r.nchunks = s->cur_nchunks;
    r.total = 16 * (uint64_t)s->win_dim;
    r.chunk_bytes = 8;
    size_t lo, hi;
    chunk_range(r.nchunks, s->index, s->count, &lo, &hi);
    size_t start = s->part.len;
    rec_head(&s->part, &r, lo, hi, r.total);
    for (int k = 0; k < 2 * s->win_dim; k++) { /* the doubles' IEEE 754 bits, little-endian */
        uint64_t bits;
        memcpy(&bits, &s->win[k], 8);
        put_u64(&s->part, bits);
    }
    if (!s->part.failed)
        put_u32(&s->part, part_crc(0, s->part.data + start, s->part.len - start));
    s->nrec++;
}

void shard_window_put(interp *I, int dim, const double *lo, const double *hi)
{
    shard *s = I->shard;
    if (!s || s->merging || dim < 1 || dim > 3)
        return;
    if (s->win_seq == (long)s->seq) { /* a second fit before one call: which one the call used is not known here */
        s->win_dim = 0;
        return;
    }
    s->win_seq = s->seq;
    s->win_dim = dim;
    memcpy(s->win, lo, (size_t)dim * sizeof *lo);
    memcpy(s->win + dim, hi, (size_t)dim * sizeof *hi);
}

int shard_window_take(interp *I, int dim, double *lo, double *hi)
{
    shard *s = I->shard;
    if (!s || !s->merging || s->win_taken == (long)s->seq)
        return 0; /* the second fit before one call: the shards recorded none */
    skip_window(s);
    for (uint32_t k = s->next_rec; k < s->nrecs && s->recs[k].seq <= s->seq; k++) {
        const shard_rec *r = &s->recs[k];
        if (r->seq == s->seq && r->op == SHARD_OP_WINDOW && r->total == 16 * (uint64_t)dim) {
            memcpy(lo, r->win, (size_t)dim * sizeof *lo);
            memcpy(hi, r->win + dim, (size_t)dim * sizeof *hi);
            s->win_taken = s->seq;
            return 1;
        }
    }
    return 0;
}

static int file_sha256(const char *path, unsigned char out[32], rt_error *e)
{
    unsigned char *data = NULL;
    size_t n = 0;
    if (fileio_read_all(path, (size_t)1 << 30, &data, &n, e))
        return -1;
    sha256_ctx h;
    sha256_init(&h);
    sha256_update(&h, data, n);
    sha256_final(&h, out);
    rt_free(data);
    return 0;
}

/* ---- merge: reading parts ------------------------------------------------------------ */

typedef struct reader {
    FILE *f;
    const char *path;
    uint32_t crc;
    long pos;
} reader;

static int rd(reader *r, void *p, size_t n)
{
    if (fread(p, 1, n, r->f) != n)
        return -1;
    r->crc = part_crc(r->crc, p, n);
    r->pos += (long)n;
    return 0;
}

/* Read one record head at r's position; 1 at the end marker, 0 a record, -1 error (message in msg). */
static int read_head(reader *r, shard_rec *h, uint64_t *lo, uint64_t *hi, uint64_t *len, char *msg, size_t ms)
{
    unsigned char b[REC_HEAD];
    memset(h, 0, sizeof *h); /* records are compared with memcmp: no stray padding bytes */
    r->crc = 0;
    if (rd(r, b, 4)) {
        snprintf(msg, ms, "it is truncated (no end marker)");
        return -1;
    }
    if (memcmp(b, "END ", 4) == 0)
        return 1;
    if (memcmp(b, "REC ", 4) != 0 || rd(r, b + 4, REC_HEAD - 4)) {
        snprintf(msg, ms, memcmp(b, "REC ", 4) ? "it is corrupt (bad record marker at byte %ld)" : "it is truncated (in a record header)", r->pos - 4);
        return -1;
    }
    h->seq = get_u32(b + 4);
    h->sub = get_u32(b + 8);
    h->op = get_u32(b + 12);
    memcpy(h->kind, b + 16, 16);
    h->nchunks = get_u64(b + 32);
    *lo = get_u64(b + 40);
    *hi = get_u64(b + 48);
    h->total = get_u64(b + 56);
    h->chunk_bytes = get_u64(b + 64);
    *len = get_u64(b + 72);
    return 0;
}


/* Read a string field of at most max bytes into buf (NUL-terminated). */
static int rd_str(reader *r, char *buf, size_t max)
{
    unsigned char b[4];
    if (rd(r, b, 4))
        return -1;
    uint32_t n = get_u32(b);
    if (n >= max || rd(r, buf, n))
        return -1;
    buf[n] = 0;
    return 0;
}

/* The header's frame block (fb, 36 bytes) is this run's frame. */
static int same_frame(const interp *I, const unsigned char *fb)
{
    if (!I->frames_given)
        return get_u32(fb) == 0;
    return get_u32(fb) == 1 && (long)get_u64(fb + 4) == I->frame && (long)get_u64(fb + 12) == I->frame_first &&
           (long)get_u64(fb + 20) == I->frame_last && (long)get_u64(fb + 28) == I->frame_step;
}

/* The frame of a part, from its header, without checking anything else:
 * 0 and *f, or -1 (not a part of a --frames run, or unreadable: check_part
 * says what is wrong). */
static int peek_frame(const char *path, long *f)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return -1;
    reader r = {fp, path, 0, 0};
    unsigned char b[40];
    char str[256];
    int rc = -1;
    if (!rd(&r, b, 12) && memcmp(b, "FRACPART", 8) == 0 && get_u32(b + 8) == SHARD_FORMAT && !rd_str(&r, str, sizeof str) &&
        !rd_str(&r, str, sizeof str) && !rd(&r, b, 40) && !rd(&r, b, 36) && get_u32(b) == 1) {
        *f = (long)get_u64(b + 4);
        rc = 0;
    }
    fclose(fp);
    return rc;
}

/* The header: each field against this run's. 0, or -1 with the reason in msg. */
static int read_header(shard *s, reader *r, int *index, int *count, char *msg, size_t ms)
{
    unsigned char b[16], hb[32], fb[36];
    char str[4096];
    bytebuf pt;
    bytebuf_init(&pt);
    params_text(s->I, &pt);
    int rc = -1;
    if (rd(r, b, 8) || memcmp(b, "FRACPART", 8) != 0)
        snprintf(msg, ms, "is not a frac part file");
    else if (rd(r, b, 4))
        snprintf(msg, ms, "is truncated (in its header)");
    else if (get_u32(b) != SHARD_FORMAT)
        snprintf(msg, ms, "has part format %u, from a%s frac; this frac reads format %d only: make the parts again with it",
                 get_u32(b), get_u32(b) < SHARD_FORMAT ? "n older" : "nother", SHARD_FORMAT);
    else if (rd_str(r, str, sizeof str))
        snprintf(msg, ms, "is truncated or corrupt (in its header)");
    else if (strcmp(str, FRAC_VERSION) != 0)
        snprintf(msg, ms, "was made by frac %.64s; this is frac %s", str, FRAC_VERSION);
    else if (rd_str(r, str, sizeof str) || strcmp(str, "sha256") != 0 || rd(r, hb, sizeof hb) || rd(r, b, 8))
        snprintf(msg, ms, "is truncated or corrupt (in its header)");
    else if (memcmp(hb, s->hash, sizeof hb) != 0)
        snprintf(msg, ms, "was made from another script (its hash differs)");
    else if (get_u64(b) != s->I->seed)
        snprintf(msg, ms, "was made with --seed %llu, not %llu", (unsigned long long)get_u64(b),
                 (unsigned long long)s->I->seed);
    else if (rd(r, fb, sizeof fb) || rd_str(r, str, sizeof str))
        snprintf(msg, ms, "is truncated or corrupt (in its header)");
    else if (!same_frame(s->I, fb)) {
        char a[96], c[96];
        frame_text(a, sizeof a, get_u32(fb) != 0, (long)get_u64(fb + 4), (long)get_u64(fb + 12), (long)get_u64(fb + 20),
                   (long)get_u64(fb + 28));
        frame_text(c, sizeof c, s->I->frames_given, s->I->frame, s->I->frame_first, s->I->frame_last, s->I->frame_step);
        snprintf(msg, ms, "was made %s; this merge is %s", a, c);
    } else if (strcmp(str, pt.data ? (const char *)pt.data : "") != 0)
        snprintf(msg, ms, "was made with other -D params");
    else if (rd(r, b, 8))
        snprintf(msg, ms, "is truncated (in its header)");
    else {
        *index = (int)get_u32(b);
        *count = (int)get_u32(b + 4);
        uint32_t crc = r->crc;
        if (fread(b + 8, 1, 4, r->f) != 4)
            snprintf(msg, ms, "is truncated (in its header)");
        else if (get_u32(b + 8) != crc)
            snprintf(msg, ms, "is corrupt (header checksum)");
        else if (*count < 1 || *count > SHARD_MAX_PARTS || *index >= *count)
            snprintf(msg, ms, "is corrupt (shard %d of %d)", *index, *count);
        else
            rc = 0;
        r->pos += 4;
    }
    bytebuf_free(&pt);
    return rc;
}

static int bad_part(interp *I, const char *path, const char *fmt, const char *detail)
{
    return err_pos(I, -1, 0, 0, ERR_VALUE, fmt, path, detail);
}

/* Check one part fully; fills its index and count; records compared with (or,
 * for the first part, stored into) s->recs. */
static int check_part(shard *s, const char *path, int first, int *index, int *count, long *first_rec)
{
    interp *I = s->I;
    reader r = {fopen(path, "rb"), path, 0, 0};
    if (!r.f)
        return err_pos(I, -1, 0, 0, ERR_IO, "merge: cannot open the part '%s': %s", path, strerror(errno));
    char msg[256] = "";
    int rc = -1;
    unsigned char b[64];
    unsigned char *blk = NULL;
    if (read_header(s, &r, index, count, msg, sizeof msg)) {
        bad_part(I, path, "merge: '%s' %s", msg);
        goto out;
    }
    *first_rec = r.pos;
    uint32_t k = 0;
    blk = mem_alloc(I, 1 << 16);
    if (!blk)
        goto out;
    for (;; k++) {
        shard_rec h;
        uint64_t lo, hi, len;
        long at = r.pos;
        int e = read_head(&r, &h, &lo, &hi, &len, msg, sizeof msg);
        if (e < 0)
            break;
        if (e == 1) {
            bytebuf tail; /* the files read: path, SHA-256 */
            bytebuf_init(&tail);
            int bad = rd(&r, b, 12) != 0;
            for (uint32_t f = 0; !bad && f < get_u32(b + 8); f++) {
                char fp[FILEIO_PATH_MAX];
                unsigned char fh[32];
                bad = rd_str(&r, fp, sizeof fp) || rd(&r, fh, sizeof fh);
                if (!bad) {
                    bytebuf_append(&tail, fp, strlen(fp) + 1);
                    bytebuf_append(&tail, fh, sizeof fh);
                }
            }
            uint32_t crc = r.crc;
            if (bad || fread(b + 12, 1, 4, r.f) != 4) {
                bytebuf_free(&tail);
                snprintf(msg, sizeof msg, "it is truncated or corrupt (in the end marker)");
                break;
            }
            if (get_u32(b) != k || get_u32(b + 12) != crc) {
                bytebuf_free(&tail);
                snprintf(msg, sizeof msg, "it is corrupt (end marker)");
                break;
            }
            int same = first || (tail.len == s->files.len && (!tail.len || memcmp(tail.data, s->files.data, tail.len) == 0));
            if (first) {
                bytebuf_free(&s->files);
                s->files = tail;
            } else {
                bytebuf_free(&tail);
            }
            if (!same || s->files.failed) {
                snprintf(msg, sizeof msg, "its shard read other files than the first part's");
                break;
            }
            if (!first && get_u32(b + 4) != s->ncalls) {
                snprintf(msg, sizeof msg, "it has %u engine calls, the first part given has %u", get_u32(b + 4), s->ncalls);
                break;
            }
            s->ncalls = get_u32(b + 4);
            if (!first && k != s->nrecs) {
                snprintf(msg, sizeof msg, "it has %u records, the first part given has %u", k, s->nrecs);
                break;
            }
            if (fgetc(r.f) != EOF) {
                snprintf(msg, sizeof msg, "it has bytes after its end marker");
                break;
            }
            s->nrecs = k;
            rc = 0;
            break;
        }
        size_t elo, ehi;
        chunk_range(h.nchunks, *index, *count, &elo, &ehi);
        uint64_t efrom, elen;
        payload_range(&h, elo, ehi, &efrom, &elen);
        int sums = h.op == PAR_OP_SUM; /* LEB128: ten bytes a value at most, and a run of zeros two at least */
        if (lo != elo || hi != ehi || (sums ? len / 10 > h.total / 8 || (h.total && len < 2) : len != elen) ||
            h.op < PAR_OP_SUM || h.op > SHARD_OP_WINDOW ||
            (h.op == SHARD_OP_WINDOW && (h.chunk_bytes != 8 || (h.total != 32 && h.total != 48))) ||
            (h.op == PAR_OP_SUM && h.total % 8) || (h.op == PAR_OP_COMBINE && (!h.chunk_bytes || h.total % h.chunk_bytes))) {
            snprintf(msg, sizeof msg, "it is corrupt (record at byte %ld)", at);
            break;
        }
        uint64_t left = len;
        sum_dec sd = {0, 0, h.total / 8, 0, 0, 0, 8};
        while (left) {
            size_t n = left < (1u << 16) ? (size_t)left : 1u << 16;
            if (rd(&r, blk, n))
                break;
            if (sums)
                sum_decode(&sd, blk, n, NULL);
            left -= n;
        }
        uint32_t crc = r.crc;
        if (left || fread(b, 1, 4, r.f) != 4) {
            snprintf(msg, sizeof msg, "it is truncated (in record %u)", k);
            break;
        }
        r.pos += 4;
        if (get_u32(b) != crc) {
            snprintf(msg, sizeof msg, "it is corrupt (checksum of record %u, engine call %u)", k, h.seq);
            break;
        }
        if (sums && !sum_done(&sd)) {
            snprintf(msg, sizeof msg, "it is corrupt (the sums of record %u, engine call %u)", k, h.seq);
            break;
        }
        if (h.op == SHARD_OP_WINDOW) { /* its doubles (one block: 48 bytes at most) */
            int dim = (int)(h.total / 16), ok = 1;
            for (int q = 0; q < 2 * dim; q++) {
                uint64_t bits = get_u64(blk + 8 * q);
                memcpy(&h.win[q], &bits, 8);
            }
            for (int q = 0; q < dim; q++)
                ok = ok && isfinite(h.win[q]) && isfinite(h.win[dim + q]) && h.win[dim + q] > h.win[q];
            if (!ok) {
                snprintf(msg, sizeof msg, "it is corrupt (the window of record %u, engine call %u)", k, h.seq);
                break;
            }
        }
        if (first) {
            if (k % 64 == 0) {
                shard_rec *nr = mem_realloc(I, s->recs, (k + 64) * sizeof *nr);
                if (!nr)
                    break;
                s->recs = nr;
            }
            s->recs[k] = h;
            s->nrecs = k + 1;
        } else if (k >= s->nrecs || memcmp(&s->recs[k], &h, sizeof h) != 0) {
            snprintf(msg, sizeof msg, "its record %u (engine call %u) differs from the first part's", k, h.seq);
            break;
        }
    }
    if (rc && msg[0])
        bad_part(I, path, "merge: '%s': %s", msg);
out:
    mem_free(I, blk);
    fclose(r.f);
    return rc;
}

static int merge_open(shard *s)
{
    interp *I = s->I;
    int n = s->nparts, count = -1;
    if (n < 1)
        return err_pos(I, -1, 0, 0, ERR_USAGE, "merge needs the script and its part files");
    int *idx = mem_alloc(I, (size_t)n * sizeof *idx);
    long *first = mem_alloc(I, (size_t)n * sizeof *first);
    if (!idx || !first) {
        mem_free(I, idx);
        mem_free(I, first);
        return -1;
    }
    int rc = 0;
    for (int p = 0; p < n && !rc; p++) {
        /* the first part read stores the records; the others must match.
         * c (the shard count a part declares) is known only once its header
         * has been read: a part that fails its check leaves count alone */
        int c = -1;
        if (check_part(s, s->parts[p], p == 0, &idx[p], &c, &first[p]))
            rc = -1;
        else if (p > 0 && c != count)
            rc = err_pos(I, -1, 0, 0, ERR_VALUE, "merge: '%s' is shard %d of %d, but '%s' is of %d", s->parts[p], idx[p], c,
                         s->parts[0], count);
        else
            count = c;
    }
    if (!rc) {
        s->count = count;
        s->order = mem_alloc(I, (size_t)count * sizeof *s->order);
        s->off = mem_alloc(I, (size_t)count * sizeof *s->off);
        if (!s->order || !s->off)
            rc = -1;
        for (int i = 0; !rc && i < count; i++)
            s->order[i] = -1;
        for (int p = 0; !rc && p < n; p++) {
            if (s->order[idx[p]] >= 0)
                rc = err_pos(I, -1, 0, 0, ERR_VALUE, "merge: shard %d of %d is given twice: '%s' and '%s'", idx[p], count,
                             s->parts[s->order[idx[p]]], s->parts[p]);
            else {
                s->order[idx[p]] = p;
                s->off[idx[p]] = first[p];
            }
        }
        for (int i = 0; !rc && i < count; i++)
            if (s->order[i] < 0)
                rc = err_pos(I, -1, 0, 0, ERR_VALUE, "merge: shard %d of %d is missing (%d part%s given)", i, count, n,
                             n == 1 ? "" : "s");
    }
    /* the files the shards read (imports, data) must be the ones this
     * evaluation will read: checked before anything is evaluated or written */
    for (size_t k = 0; !rc && k < s->files.len;) {
        const char *f = (const char *)s->files.data + k;
        size_t fl = strlen(f) + 1;
        unsigned char h[32];
        rt_error e;
        if (file_sha256(f, h, &e))
            rc = err_pos(I, -1, 0, 0, ERR_IO, "merge: cannot read '%s', which the shards read: %s", f, e.msg);
        else if (memcmp(h, s->files.data + k + fl, 32) != 0)
            rc = err_pos(I, -1, 0, 0, ERR_VALUE, "merge: '%s' is not the file the shards read (its SHA-256 differs)", f);
        k += fl + 32;
    }
    mem_free(I, idx);
    mem_free(I, first);
    return rc;
}

/* Fill buf from every part's record `want` (the next one in each part);
 * unit: a SUM's integer width in buf (8 or 4). */
static rt_code merge_section(shard *s, const shard_rec *want, void *buf, size_t unit, par_combine_fn fn, void *ctx,
                            rt_error *e)
{
    unsigned char blk[1 << 14];
    size_t step = sizeof blk;
    if (want->op == PAR_OP_COMBINE) {
        if (!fn || !want->chunk_bytes || want->chunk_bytes > sizeof blk)
            return rt_fail(e, RT_EINVAL, "internal: a combined section without a combine function");
        step = sizeof blk / want->chunk_bytes * want->chunk_bytes; /* whole elements */
    }
    for (int i = 0; i < s->count; i++) {
        const char *path = s->parts[s->order[i]];
        FILE *f = fopen(path, "rb");
        if (!f)
            return rt_fail(e, RT_EIO, "merge: cannot open '%s': %s", path, strerror(errno));
        reader r = {f, path, 0, s->off[i]};
        shard_rec h;
        uint64_t lo, hi, len;
        char msg[256];
        rt_code c = RT_OK;
        if (fseek(f, s->off[i], SEEK_SET) || read_head(&r, &h, &lo, &hi, &len, msg, sizeof msg) ||
            memcmp(&h, want, sizeof h) != 0) {
            c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging (record %u.%u of engine call %u not found at byte %ld)",
                        path, want->sub, want->seq, want->seq, s->off[i]);
        } else if (want->op == PAR_OP_COMBINE) {
            for (uint64_t k = 0; k < len && !c; k += step) {
                size_t n = len - k < step ? (size_t)(len - k) : step;
                if (rd(&r, blk, n))
                    c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging", path);
                else
                    fn(ctx, (unsigned char *)buf + k, blk, n / want->chunk_bytes);
            }
        } else if (want->op == PAR_OP_SUM) {
            sum_dec sd = {0, 0, want->total / 8, 0, 0, 0, unit};
            for (uint64_t k = 0; k < len && !c; k += sizeof blk) {
                size_t n = len - k < sizeof blk ? (size_t)(len - k) : sizeof blk;
                if (rd(&r, blk, n))
                    c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging", path);
                else
                    sum_decode(&sd, blk, n, buf);
            }
            if (!c && !sum_done(&sd))
                c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging (sums)", path);
        } else {
            uint64_t from, l2;
            payload_range(want, (size_t)lo, (size_t)hi, &from, &l2);
            if (rd(&r, (unsigned char *)buf + from, (size_t)len))
                c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging", path);
        }
        uint32_t crc = r.crc;
        if (!c && (fread(blk, 1, 4, f) != 4 || get_u32(blk) != crc))
            c = rt_fail(e, RT_EFORMAT, "merge: '%s' changed while merging (checksum)", path);
        s->off[i] = r.pos + 4;
        fclose(f);
        if (c)
            return c;
    }
    return RT_OK;
}

/* ---- attempts ----------------------------------------------------------------------- */

/* A shard notes every file its evaluation reads (imports, load_ifs, images
 * …; the path hook of fileio.h), once each, NUL-terminated in s->reads. */
static void on_path(void *ud, const char *path, int wrote)
{
    shard *s = ud;
    if (wrote)
        return;
    for (size_t k = 0; k < s->reads.len; k += strlen((const char *)s->reads.data + k) + 1)
        if (strcmp((const char *)s->reads.data + k, path) == 0)
            return;
    bytebuf_append(&s->reads, path, strlen(path) + 1);
}

int shard_attempt_begin(shard *s, interp *I, const char *script, const unsigned char *text, size_t len)
{
    (void)script;
    s->I = I;
    s->again = 0;
    s->seq = 0;
    s->pending = -1;
    s->cur = -1;
    s->live = 0;
    s->nrec = 0;
    s->next_rec = 0;
    s->win_seq = -1;
    s->win_dim = 0;
    s->win_taken = -1;
    sha256_ctx h;
    sha256_init(&h);
    sha256_update(&h, text, len);
    sha256_final(&h, s->hash);
    s->rt.begin = cb_begin;
    s->rt.section = cb_section;
    bytebuf_init(&s->part);
    I->shard = s;
    par_set_sharder(&s->rt);
    if (s->merging)
        return select_frame(s) || merge_open(s);
    header(s, &s->part, s->index, s->count);
    bytebuf_init(&s->reads);
    fileio_set_path_hook(on_path, s);
    s->devnull = fopen("/dev/null", "w");
    if (!s->devnull)
        return err_pos(I, -1, 0, 0, ERR_IO, "--shard: cannot open /dev/null: %s", strerror(errno));
    I->out = s->devnull; /* a shard prints nothing of the script's: the merge does */
    return 0;
}

int shard_attempt_end(shard *s, int ok, const char *script)
{
    interp *I = s->I;
    int rc = 0;
    if (ok && s->merging)
        skip_window(s);
    if (ok && s->merging && (s->next_rec < s->nrecs || s->seq != s->ncalls)) {
        if (s->next_rec < s->nrecs)
            unused_record(s);
        else
            err_pos(I, -1, 0, 0, ERR_VALUE, "merge: this evaluation of the script made %u engine calls, the shards' made %u: "
                    "the parts come from another script or variant", s->seq, s->ncalls);
        rc = -1;
    }
    if (ok && !s->merging && !s->again) {
        fileio_set_path_hook(NULL, NULL);
        size_t end = s->part.len;
        bytebuf_append(&s->part, "END ", 4);
        put_u32(&s->part, s->nrec);
        put_u32(&s->part, s->seq); /* engine calls of the evaluation, split or not */
        uint32_t nf = 0;
        for (size_t k = 0; k < s->reads.len; k += strlen((const char *)s->reads.data + k) + 1)
            nf++;
        put_u32(&s->part, nf);
        for (size_t k = 0; k < s->reads.len && !rc; k += strlen((const char *)s->reads.data + k) + 1) {
            const char *f = (const char *)s->reads.data + k;
            unsigned char h[32];
            rt_error e;
            if (file_sha256(f, h, &e))
                rc = err_pos(I, -1, 0, 0, ERR_IO, "--shard: cannot read '%s' again to hash it: %s", f, e.msg);
            put_str(&s->part, f);
            bytebuf_append(&s->part, h, sizeof h);
        }
        if (!s->part.failed)
            put_u32(&s->part, part_crc(0, s->part.data + end, s->part.len - end));
        const char *base = strrchr(script, '/') ? strrchr(script, '/') + 1 : script;
        size_t bl = strlen(base);
        if (bl > 5 && strcmp(base + bl - 5, ".frac") == 0)
            bl -= 5;
        char name[1024], path[FILEIO_PATH_MAX];
        char fr[64] = "";
        int fw = I->frame_width > 0 && I->frame_width < 24 ? I->frame_width : 1;
        if (I->frames_given) /* NAME.fF.shard-I-of-N.part, F as %f in output paths */
            snprintf(fr, sizeof fr, ".f%s%0*lu", I->frame < 0 ? "-" : "", fw,
                     I->frame < 0 ? 0ul - (unsigned long)I->frame : (unsigned long)I->frame);
        snprintf(name, sizeof name, "%.*s%s.shard-%d-of-%d.part", (int)(bl < 900 ? bl : 900), base, fr, s->index, s->count);
        if (rc)
            ;
        else if (lang_join_path(I, NULL, I->out_dir, name, strlen(name), path, sizeof path, "--shard"))
            rc = -1;
        else if (s->part.failed)
            rc = mem_engine_error(I, "--shard", "out of memory for the part file");
        else {
            rt_error e;
            rt_code c = fileio_write_atomic(path, s->part.data, s->part.len, &e);
            if (c)
                rc = lang_rt_error(I, c, &e, "--shard");
            else if (!I->quiet)
                fprintf(stderr, "wrote %s\n", path);
        }
    }
    par_set_sharder(NULL);
    if (!s->merging) {
        fileio_set_path_hook(NULL, NULL);
        bytebuf_free(&s->reads);
    }
    bytebuf_free(&s->part);
    bytebuf_free(&s->files);
    mem_free(I, s->sel);
    s->sel = NULL;
    mem_free(I, s->recs);
    mem_free(I, s->order);
    mem_free(I, s->off);
    s->recs = NULL;
    s->order = NULL;
    s->off = NULL;
    s->nrecs = 0;
    if (s->devnull) {
        I->out = stdout;
        fclose(s->devnull);
        s->devnull = NULL;
    }
    return rc;
}

/* ---- partial values -------------------------------------------------------------------- */

typedef struct partial {
    shard *s;
    uint32_t seq;
    const node *at;
} partial;

static void partial_destroy(void *p)
{
    partial *q = p;
    q->s->live--;
    rt_free(q);
}

static void partial_summary(const void *p, bytebuf *out)
{
    bytebuf_printf(out, "<partial result of engine call %u>", ((const partial *)p)->seq);
}

static int partial_arith(interp *I, int op, value a, value b, value *out);
static int partial_get(interp *I, const void *p, const char *name, value *out);
static int partial_save(interp *I, const void *p, const char *path, value opts)
{
    (void)I, (void)p, (void)path, (void)opts;
    return 0; /* the record is in the part already */
}

static const obj_class partial_class = {
    .name = "partial",
    .destroy = partial_destroy,
    .summary = partial_summary,
    .arith = partial_arith,
    .get = partial_get,
    .save = partial_save,
};

static int partial_arith(interp *I, int op, value a, value b, value *out)
{
    (void)I, (void)op, (void)out;
    const partial *p = a.k == V_OBJ && AS_OBJ(a)->cls == &partial_class ? AS_OBJ(a)->payload : AS_OBJ(b)->payload;
    return taint(p->s, p->seq, p->at, "is operated on");
}

static int partial_get(interp *I, const void *pp, const char *name, value *out)
{
    (void)I, (void)out;
    const partial *p = pp;
    char why[96];
    snprintf(why, sizeof why, "is inspected (.%s)", name);
    return taint(p->s, p->seq, p->at, why);
}

static int scan(shard *s, const char *bname, value v, int depth)
{
    if (v.k == V_OBJ && AS_OBJ(v)->cls == &partial_class) {
        const partial *p = AS_OBJ(v)->payload;
        char why[96];
        snprintf(why, sizeof why, "is passed to %s", bname);
        return taint(s, p->seq, p->at, why);
    }
    if (depth > 64)
        return 0;
    if (v.k == V_LIST)
        for (size_t i = 0; i < AS_LIST(v)->n; i++)
            if (scan(s, bname, AS_LIST(v)->items[i], depth + 1))
                return -1;
    if (v.k == V_REC)
        for (size_t i = 0; i < AS_REC(v)->n; i++)
            if (scan(s, bname, AS_REC(v)->vals[i], depth + 1))
                return -1;
    return 0;
}

int shard_scan_args(interp *I, const char *bname, const node *call, const value *pos, int npos,
                    const value *named, int nnamed)
{
    shard *s = I->shard;
    if (!s || s->live <= 0)
        return 0;
    const node *saved = I->cur;
    I->cur = call;
    int from = strcmp(bname, "save") == 0, rc = 0; /* save(partial, …) is what a shard is for */
    for (int i = from; i < npos && !rc; i++)
        rc = scan(s, bname, pos[i], 0);
    for (int i = 0; i < nnamed && !rc; i++)
        rc = scan(s, bname, named[i], 0);
    I->cur = saved;
    return rc;
}

int shard_after_builtin(interp *I, int rc, value *out)
{
    shard *s = I->shard;
    if (!s)
        return rc;
    long win = s->win_dim ? s->win_seq : -1; /* a window fitted for the call this builtin made */
    s->win_seq = -1;
    if (s->pending < 0)
        return rc;
    if (rc != 0) { /* the builtin used its partial result itself (a pre-pass, a check) */
        if (!s->again && !(I->err.active && I->err.kind == ERR_INTERRUPT)) {
            err_clear(I);
            taint(s, (uint32_t)s->pending, s->pending_at, "is used inside its builtin");
        }
        s->pending = -1;
        return -1;
    }
    if (win == s->pending && s->cur == s->pending)
        put_window(s, (uint32_t)s->pending);
    partial *p = mem_alloc(I, sizeof *p);
    if (!p)
        return -1;
    p->s = s;
    p->seq = (uint32_t)s->pending;
    p->at = s->pending_at;
    s->pending = -1;
    val_unref(I, *out);
    s->live++; /* val_obj destroys p on failure */
    *out = val_obj(I, &partial_class, p);
    return out->k == V_NIL ? -1 : 0;
}

int shard_pending(const interp *I)
{
    return I->shard && !I->shard->merging && I->shard->pending >= 0;
}

long shard_pending_call(const interp *I, const node **at)
{
    if (!shard_pending(I))
        return -1;
    *at = I->shard->pending_at;
    return I->shard->pending;
}

void shard_pend_again(interp *I, long seq, const node *at)
{
    shard *s = I->shard;
    if (!s || s->merging || s->pending >= 0)
        return;
    s->pending = seq;
    s->pending_at = at;
}

int shard_skip_save(interp *I)
{
    return I->shard && !I->shard->merging;
}

/* ---- for the fuzz harness ------------------------------------------------------------ */

int shard_check_parts(shard *s, interp *I, const unsigned char script_hash[32])
{
    s->I = I;
    memcpy(s->hash, script_hash, 32);
    return merge_open(s);
}
