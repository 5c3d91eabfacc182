/* fuzz_shard.c — libFuzzer harness for the shard part reader: merge's check
 * of part files (interp/shard.c: header, records, CRC-32s, the same records
 * in every part, each shard once), reached through shard_check_parts.
 *
 * The input is one to four part files, split at each "FRACPART" magic. Each
 * is repaired before the check (as fuzz_loaders.c repairs PNG CRCs), so
 * mutations reach the record checks: the header CRC and every record's
 * CRC are recomputed where the structure allows. The script hash the parts
 * are checked against is the one in the first part's header (an input
 * whose length is 63 mod 64 flips its low bit, so "made from another
 * script" is reached too); the seed is 1, with no -D params. The parts are handed over as
 * memory files (memfd, /proc/self/fd/N), so nothing touches the disk.
 *
 * Oracles: no crash, no sanitizer report, no leak; an accepted set of parts
 * has count == the number of parts, and an error is always recorded when
 * the check fails. FRAC_FUZZ_VERBOSE=1 prints each input's outcome.
 * Seeds: `frac run --shard I/N` of the tiny tests/fuzz/shard_seed.frac
 * (the fuzz-seeds rule). */
#define _GNU_SOURCE
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "deflate.h"
#include "shard.h"
#include "state.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

#define MAXP 4
static int fds[MAXP];
static char paths[MAXP][64];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    for (int i = 0; i < MAXP; i++) {
        fds[i] = memfd_create("fuzz-part", 0);
        if (fds[i] < 0) {
            perror("memfd_create");
            exit(1);
        }
        snprintf(paths[i], sizeof paths[i], "/proc/self/fd/%d", fds[i]);
    }
    return 0;
}

static uint32_t le32(const unsigned char *p) { return p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static uint64_t le64(const unsigned char *p) { return le32(p) | (uint64_t)le32(p + 4) << 32; }
static void put_le32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16), p[3] = (unsigned char)(v >> 24);
}

/* Skip a string field (u32 length, bytes) at *pos; 0 if it fits. */
static int skip_str(const unsigned char *d, size_t n, size_t *pos)
{
    if (n - *pos < 4)
        return -1;
    uint32_t l = le32(d + *pos);
    if (l > n - *pos - 4)
        return -1;
    *pos += 4 + (size_t)l;
    return 0;
}

/* The layout of interp/shard.c, part format 4 (docs/scale.md): header
 * fields, then its CRC; records "REC " + 76 bytes of head + payload, then a
 * CRC of head and payload; the end ("END ", counts, the files read), then
 * its CRC. Repairs in place; hash gets the header's script hash. */
static void repair(unsigned char *d, size_t n, unsigned char hash[32])
{
    size_t pos = 12; /* "FRACPART", format */
    if (n < pos || skip_str(d, n, &pos) || skip_str(d, n, &pos) || n - pos < 32 + 8 + 4 + 32)
        return;
    memcpy(hash, d + pos, 32);
    pos += 32 + 8 + 4 + 32; /* hash, seed, frames flag, frame and range */
    if (skip_str(d, n, &pos) || n - pos < 12)
        return;
    pos += 8; /* index, count */
    put_le32(d + pos, deflate_crc32(0, d, pos));
    pos += 4;
    while (n - pos >= 80 && !memcmp(d + pos, "REC ", 4)) {
        uint64_t len = le64(d + pos + 72);
        if (len > n - pos - 80 || n - pos - 80 - len < 4)
            return;
        size_t end = pos + 80 + (size_t)len;
        put_le32(d + end, deflate_crc32(0, d + pos, end - pos));
        pos = end + 4;
    }
    if (n - pos < 16 || memcmp(d + pos, "END ", 4))
        return;
    size_t e = pos + 16;
    uint32_t files = le32(d + pos + 12);
    for (uint32_t f = 0; f < files; f++) {
        if (skip_str(d, n, &e) || n - e < 32)
            return;
        e += 32;
    }
    if (n - e >= 4)
        put_le32(d + e, deflate_crc32(0, d + pos, e - pos));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > (1u << 20))
        return 0;
    size_t at[MAXP + 1];
    int k = 0;
    for (const uint8_t *p = data; k < MAXP && (p = memmem(p, size - (size_t)(p - data), "FRACPART", 8)); p++)
        at[k++] = (size_t)(p - data);
    if (k == 0)
        at[k++] = 0; /* not a part at all: one file */
    at[0] = 0;
    at[k] = size;
    unsigned char *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    unsigned char hash[32] = {0};
    for (int i = 0; i < k; i++) {
        unsigned char h[32] = {0};
        repair(copy + at[i], at[i + 1] - at[i], h);
        if (i == 0) {
            memcpy(hash, h, 32);
            hash[0] ^= (unsigned char)(size % 64 == 63);
        }
        size_t len = at[i + 1] - at[i];
        if (ftruncate(fds[i], 0) || pwrite(fds[i], copy + at[i], len, 0) != (ssize_t)len) {
            perror("memfd");
            abort();
        }
    }
    free(copy);
    char *parts[MAXP];
    for (int i = 0; i < k; i++)
        parts[i] = paths[i];
    interp I;
    interp_init(&I);
    I.quiet = 1;
    shard s;
    shard_init_merge(&s, parts, k);
    int rc = shard_check_parts(&s, &I, hash);
    if (rc == 0 && s.count != k) {
        fprintf(stderr, "fuzz_shard: %d parts accepted as shards of %d\n", k, s.count);
        abort();
    }
    if (rc != 0 && !I.err.active) {
        fprintf(stderr, "fuzz_shard: the parts were refused without an error\n");
        abort();
    }
    if (getenv("FRAC_FUZZ_VERBOSE")) /* what a replayed input did */
        fprintf(stderr, "fuzz_shard: %d part(s): %s\n", k, rc ? I.err.msg : "accepted");
    shard_attempt_end(&s, 0, "");
    interp_free(&I);
    return 0;
}
