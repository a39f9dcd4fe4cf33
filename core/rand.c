/* rand.c — reproducible random numbers for tests and benchmarks
 * (pd_core.h): splitmix64, and doubles uniform in [-1, 1). */
#include <math.h>

#include "pd_core.h"

/* x += golden gamma, then two xor-shift-multiply rounds (Steele, Lea, Flood). */
uint64_t pd_rand_next(uint64_t *state)
{
    if (!state)
        return 0;
    uint64_t x = (*state += 0x9E3779B97F4A7C15ull);
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

/* 2 u - 1 with u the top 53 bits over 2^53. */
double pd_rand_pm1(uint64_t *state)
{
    if (!state)
        return NAN;
    return 2.0 * ((double)(pd_rand_next(state) >> 11) * 0x1.0p-53) - 1.0;
}
