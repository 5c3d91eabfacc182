/* rng.h — counter-based randomness.
 *
 * Every random number in frac comes from a stream identified by
 * (seed, stream id). A stream is seeded by hashing the pair with SplitMix64,
 * then advanced with xoshiro256++ (Blackman & Vigna), which is fast enough for
 * the chaos game's inner loop. Engines give each fixed chunk of work its own
 * stream id (e.g. the chunk index), so results never depend on the thread
 * count or on the order chunks run in.
 *
 * For values that must be a pure function of a position (solid-texture node
 * randoms, noise permutations) use rng_hash*: no state at all.
 */
#ifndef RNG_H
#define RNG_H

#include <stdint.h>

typedef struct rng {
    uint64_t s[4];
} rng;

/* SplitMix64 finaliser: a good 64-bit mixing function (bijective). */
static inline uint64_t rng_mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Hash of a seed and up to three 64-bit words. */
static inline uint64_t rng_hash3(uint64_t seed, uint64_t a, uint64_t b, uint64_t c)
{
    uint64_t h = rng_mix64(seed ^ 0x5851f42d4c957f2dull);
    h = rng_mix64(h ^ a);
    h = rng_mix64(h ^ (b + 0x2545f4914f6cdd1dull));
    h = rng_mix64(h ^ (c + 0x14057b7ef767814full));
    return h;
}

void rng_init(rng *r, uint64_t seed, uint64_t stream);

static inline uint64_t rng_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

/* xoshiro256++ */
static inline uint64_t rng_next(rng *r)
{
    uint64_t *s = r->s;
    uint64_t result = rng_rotl(s[0] + s[3], 23) + s[0];
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rng_rotl(s[3], 45);
    return result;
}

/* Uniform double in [0, 1) with 53 random bits. */
static inline double rng_uniform(rng *r) { return (double)(rng_next(r) >> 11) * 0x1.0p-53; }

/* Uniform double in [0, 1) from a hash value. */
static inline double rng_to_unit(uint64_t h) { return (double)(h >> 11) * 0x1.0p-53; }

/* Standard normal deviate (Box–Muller, one of the pair; deterministic). */
double rng_normal(rng *r);

#endif
