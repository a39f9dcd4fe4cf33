/* mj_batch_lanes.h — the batch's step of every lane, a text compiled once
 * per instruction set under the name MJB_LANES_STEP: mj_batch.c (the
 * baseline), mj_batch_x86v3.c (AVX2), mj_batch_x86v4.c (AVX-512), which
 * set their target for the whole file (a function's target attribute
 * would leave GCC expanding the wide vectors' comparisons lane by lane).
 * Every variant computes the same numbers: IEEE operations lane by lane,
 * no contraction into fused multiply-adds (the Makefile's FPFLAGS).
 *
 * The lanes' constants are stored in groups of MJ1_WIDTH (8) lanes
 * (mj1_coefv); the step works on the processor's own vector, LW lanes at a
 * time: 8 under AVX-512, 4 under AVX2, 2 on the baseline.  A vector wider
 * than the registers (8 lanes on AVX2) was split by GCC through the stack,
 * broadcasts included, and ran slower than the scalar kernel. */
#include <string.h>

#include "mj1.h"
#include "pd_lanes.h"

#define NVEC (PD_MJB_LANES / MJ1_WIDTH)

_Static_assert(PD_MJB_LANES % MJ1_WIDTH == 0, "whole vectors of lanes");
_Static_assert(MJ1_WIDTH % LW == 0, "whole native vectors in a group");
_Static_assert(sizeof(mj1_coefv) * NVEC <= sizeof(((pd_mjb *)0)->coef),
               "pd_mjb.coef holds the constants of every vector of lanes");

/* The constants of group j. */
static inline mj1_coefv *mjb_coef(pd_mjb *b, int j)
{
    return (mj1_coefv *)(void *)b->coef + j;
}

/* LW values from p (any alignment of a double). */
static inline lvec lload(const void *p)
{
    lvec x;
    memcpy(&x, p, sizeof x);
    return x;
}

/* mj1_step's operations, in its order, on lanes l .. l + LW - 1, whose
 * constants are at offset o of their group s; the forces F1 at the step's
 * end become the next step's F0. */
static inline void lanes_step(pd_mjb *b, const mj1_coefv *s, int l, int o)
{
    const lvec zero = {0.0};
    const double th = b->theta, *cs = (const double *)(const void *)s;
    const size_t W = MJ1_WIDTH; /* one constant's lanes in the group */
    lvec q0 = lload(&b->q[l]), v0 = lload(&b->v[l]), g = lload(&b->g[l]);
    lvec F0 = lload(&b->F0[l]), F1 = lload(&b->F1[l]), h = lload(&b->h[l]);
    lvec c = lload(cs + 0 * W + o), k = lload(cs + 1 * W + o), w = lload(cs + 2 * W + o);
    lvec e = lload(cs + 3 * W + o), g0 = lload(cs + 4 * W + o);
    lvec whatinv = lload(cs + 5 * W + o), winv = lload(cs + 6 * W + o);
    lvec delinv = lload(cs + 7 * W + o), hth = lload(cs + 8 * W + o);
    lvec hgamma = lload(cs + 9 * W + o);
    lmask wall;
    memcpy(&wall, cs + 10 * W + o, sizeof wall);
    lvec Fth = th * F1 + (1.0 - th) * F0;
    lvec rhs = h * (Fth - c * v0 - k * (q0 + hth * v0));
    lvec vfree = v0 + rhs * whatinv;
    lvec U0 = w * v0;
    lmask active = wall & (g + hgamma * U0 <= zero);
    lvec bb = w * vfree + e * U0;
    lvec imp = LSELECT(active & (bb < zero), -bb * delinv, zero);
    lvec vnew = LSELECT(active, vfree + winv * imp, vfree);
    lvec qnew = q0 + h * (th * vnew + (1.0 - th) * v0);
    lvec gnew = g0 + w * qnew;
    memcpy(&b->q[l], &qnew, sizeof qnew);
    memcpy(&b->v[l], &vnew, sizeof vnew);
    memcpy(&b->g[l], &gnew, sizeof gnew);
    memcpy(&b->P[l], &imp, sizeof imp);
    memcpy(&b->F0[l], &F1, sizeof F1);
}

/* Every lane one step. */
void MJB_LANES_STEP(pd_mjb *b)
{
    for (int j = 0; j < NVEC; j++)
        for (int o = 0; o < MJ1_WIDTH; o += LW)
            lanes_step(b, mjb_coef(b, j), j * MJ1_WIDTH + o, o);
}


