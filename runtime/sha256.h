/* sha256.h — SHA-256 (FIPS 180-4, the same algorithm as FIPS 180-2).
 *
 * Incremental: sha256_init, sha256_update any number of times, then
 * sha256_final writes the 32-byte digest. sha256_hex is the one-shot form
 * giving 64 lower-case hex digits and a NUL (what `sha256sum` prints).
 * Used for the script hash in every output's recipe (interp/recipe.h). */
#ifndef SHA256_H
#define SHA256_H

#include <stddef.h>
#include <stdint.h>

typedef struct sha256_ctx {
    uint32_t h[8];
    uint64_t len;            /* bytes hashed so far */
    unsigned char buf[64];
    size_t nbuf;
} sha256_ctx;

void sha256_init(sha256_ctx *c);
void sha256_update(sha256_ctx *c, const void *data, size_t n);
void sha256_final(sha256_ctx *c, unsigned char digest[32]);
void sha256_hex(const void *data, size_t n, char hex[65]);

#endif
