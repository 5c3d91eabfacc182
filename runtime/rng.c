/* rng.c — stream seeding and the normal deviate. */
#include "rng.h"

#include <math.h>

void rng_init(rng *r, uint64_t seed, uint64_t stream)
{
    uint64_t h = rng_hash3(seed, stream, 0x6a09e667f3bcc909ull, 0xbb67ae8584caa73bull);
    for (int i = 0; i < 4; i++) {
        h = rng_mix64(h + (uint64_t)i);
        r->s[i] = h;
    }
    if ((r->s[0] | r->s[1] | r->s[2] | r->s[3]) == 0)
        r->s[0] = 1; /* the all-zero state is the one xoshiro cannot leave */
}

double rng_normal(rng *r)
{
    double u1 = 1.0 - rng_uniform(r); /* (0, 1]: log is finite */
    double u2 = rng_uniform(r);
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}
