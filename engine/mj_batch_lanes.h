/* mj_batch_lanes.h — the batch's step of every lane, a text compiled once
 * per instruction set under the name MJB_LANES_STEP: mj_batch.c (the
 * baseline), mj_batch_x86v3.c (AVX2), mj_batch_x86v4.c (AVX-512), which
 * set their target for the whole file (a function's target attribute
 * would leave GCC expanding the wide vectors' comparisons lane by lane).
 * Every variant computes the same numbers: IEEE operations lane by lane,
 * no contraction into fused multiply-adds (the Makefile's FPFLAGS). */
#include <string.h>

#include "mj1.h"

#define NVEC (PD_MJB_LANES / MJ1_WIDTH)

_Static_assert(PD_MJB_LANES % MJ1_WIDTH == 0, "whole vectors of lanes");
_Static_assert(sizeof(mj1_coefv) * NVEC <= sizeof(((pd_mjb *)0)->coef),
               "pd_mjb.coef holds the constants of every vector of lanes");

/* The constants of vector j. */
static inline mj1_coefv *mjb_coef(pd_mjb *b, int j)
{
    return (mj1_coefv *)(void *)b->coef + j;
}

/* Every vector of lanes one step (mj1_stepv) with the forces F1 at the
 * step's end, which become the next step's F0. */
void MJB_LANES_STEP(pd_mjb *b)
{
    for (int j = 0; j < NVEC; j++) {
        int l = j * MJ1_WIDTH;
        mj1_vec q, v, g, P, F0, F1, h;
        memcpy(&q, &b->q[l], sizeof q);
        memcpy(&v, &b->v[l], sizeof v);
        memcpy(&g, &b->g[l], sizeof g);
        memcpy(&F0, &b->F0[l], sizeof F0);
        memcpy(&F1, &b->F1[l], sizeof F1);
        memcpy(&h, &b->h[l], sizeof h);
        mj1_stepv(b->theta, &h, mjb_coef(b, j), &F0, &F1, &q, &v, &g, &P);
        memcpy(&b->q[l], &q, sizeof q);
        memcpy(&b->v[l], &v, sizeof v);
        memcpy(&b->g[l], &g, sizeof g);
        memcpy(&b->P[l], &P, sizeof P);
        memcpy(&b->F0[l], &F1, sizeof F1);
    }
}

