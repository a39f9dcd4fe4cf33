/* mj_batch_lanes.h — the batch's step of every lane, a text compiled once
 * per instruction set under the name MJB_LANES_STEP: mj_batch.c (the
 * baseline), mj_batch_x86v3.c (AVX2), mj_batch_x86v4.c (AVX-512), which
 * set their target for the whole file (a function's target attribute
 * would leave GCC expanding the wide vectors' comparisons lane by lane).
 * The arithmetic is pd_mj1_lanes.h's, on the processor's own vector: 8 lanes
 * under AVX-512, 4 under AVX2, 2 on the baseline.  A vector wider than the
 * registers (8 lanes on AVX2) was split by GCC through the stack,
 * broadcasts included, and ran slower than the scalar kernel. */
#include "pd_mj1_lanes.h"

/* Lanes l .. l + LW - 1 one step; the forces F1 at the step's end become
 * the next step's F0. */
static inline void lanes_step(pd_mjb *b, int l)
{
    const double *cs = mj1_lanes_coef(b, l);
    lvec q = lload(&b->q[l]), v = lload(&b->v[l]), g = lload(&b->g[l]), P;
    lvec h = lload(&b->h[l]), F1 = lload(&b->F1[l]);
    lvec Fth = mj1_lanes_fth(b->theta, lload(&b->F0[l]), F1);      /* theta F1 + (1 - theta) F0 */
    mj1_lanes_step(1, &cs, b->theta, &h, &Fth, &q, &v, &g, &P, 0); /* a wall per lane */
    lstore(&b->q[l], q);
    lstore(&b->v[l], v);
    lstore(&b->g[l], g);
    lstore(&b->P[l], P);
    lstore(&b->F0[l], F1); /* unless a breakpoint replaces it */
}

/* Every lane one step. */
void MJB_LANES_STEP(pd_mjb *b)
{
    for (int l = 0; l < PD_MJB_LANES; l += LW)
        lanes_step(b, l);
}
