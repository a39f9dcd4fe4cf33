/* chain.c — the benchmark chains' right-hand sides (pd_lcp.h). */
#include "pd_lcp.h"

#define CHAIN_SEED 20240611u /* the streams of the benchmark chains */

/* q_j uniform in [-1, 1) from the stream of (N, seed). */
void pd_lcp_chain_q(int N, int seed, double *q)
{
    if (!q)
        return;
    /* a stream per (N, seed) */
    uint64_t state = CHAIN_SEED + (uint64_t)N + 1000003u * (uint64_t)seed;
    for (int j = 0; j < N; j++)
        q[j] = pd_rand_pm1(&state);
}
