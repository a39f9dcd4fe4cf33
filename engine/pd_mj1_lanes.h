/* pd_mj1_lanes.h — (the engine's inline interface, not installed) mj1_step's operations on the processor's
 * own vector of lanes, in registers: the one text of the batch's step
 * (mj_batch_lanes.h, over pd_mjb's arrays) and of the oscillator's batch,
 * which fuses its measurements into the same loop (problems/
 * osc_batch_lanes.h).  Include it after the file's `#pragma GCC target`
 * (pd_lanes.h: the width follows the target).  Every variant computes
 * mj1_step's numbers lane for lane: the same IEEE operations in the same
 * order, no fused multiply-adds (the Makefile's FPFLAGS), the choices as
 * selections (unit_w's one branch, a step where no lane's contact may
 * close, skips arithmetic whose result it knows). */
#ifndef PD_MJ1_LANES_H
#define PD_MJ1_LANES_H

#include <math.h>
#include <string.h>

#include "pd_mj1.h"
#include "pd_lanes.h"

_Static_assert(PD_MJB_LANES % MJ1_WIDTH == 0, "whole groups of lanes");
_Static_assert(MJ1_WIDTH % LW == 0, "whole native vectors in a group");
_Static_assert(sizeof(mj1_coefv) * (PD_MJB_LANES / MJ1_WIDTH) <= sizeof(((pd_mjb *)0)->coef),
               "pd_mjb.coef holds the constants of every group of lanes");

/* LW values from p (any alignment of a double). */
static inline lvec lload(const void *p)
{
    lvec x;
    memcpy(&x, p, sizeof x);
    return x;
}

/* LW values to p. */
static inline void lstore(void *p, lvec x)
{
    memcpy(p, &x, sizeof x);
}

/* The constants of lanes l .. l + LW - 1 (their group's, pd_mjb.coef). */
static inline const double *mj1_lanes_coef(const pd_mjb *b, int l)
{
    const mj1_coefv *s = (const mj1_coefv *)(const void *)b->coef + l / MJ1_WIDTH;
    return (const double *)(const void *)s + l % MJ1_WIDTH;
}

/* For each i < n (a constant once inlined: the statements' loops unroll,
 * so that the vectors' chains interleave and overlap). */
#define MJ1_EACH(n, stmt)                                                                          \
    _Pragma("GCC unroll 8") for (int i = 0; i < (n); i++)                                          \
    {                                                                                              \
        stmt;                                                                                      \
    }

/* pd_max and the minimum's a < b ? a : b, lane by lane (the x86 max and
 * min instructions are exactly these: the second operand when the two are
 * equal or unordered). */
#if defined(__AVX512F__) && PD_LANES_X86
#define LMAX(a, b) ((lvec)_mm512_max_pd((__m512d)(a), (__m512d)(b)))
#define LMIN(a, b) ((lvec)_mm512_min_pd((__m512d)(a), (__m512d)(b)))
#elif defined(__AVX__) && PD_LANES_X86
#define LMAX(a, b) ((lvec)_mm256_max_pd((__m256d)(a), (__m256d)(b)))
#define LMIN(a, b) ((lvec)_mm256_min_pd((__m256d)(a), (__m256d)(b)))
#elif defined(__SSE2__) && PD_LANES_X86
#define LMAX(a, b) ((lvec)_mm_max_pd((__m128d)(a), (__m128d)(b)))
#define LMIN(a, b) ((lvec)_mm_min_pd((__m128d)(a), (__m128d)(b)))
#else
#define LMAX(a, b) LSELECT((a) > (b), a, b)
#define LMIN(a, b) LSELECT((a) < (b), a, b)
#endif

/* mj1_fth on the lanes. */
static inline lvec mj1_lanes_fth(double th, lvec F0, lvec F1)
{
    return th * F1 + (1.0 - th) * F0;
}

/* mj1_step's operations, in its order, on n vectors of LW lanes (n <= 8),
 * vector i with steps h[i] and its constants at cs[i] (mj1_lanes_coef):
 * from (q, v) with the gap g and the step's force Fth (mj1_lanes_fth),
 * q, v and g move to the step's end and P gets the impulse.
 * The impulse is max(b (-1/D), +0) = mj1_step's (b < 0 ? -b/D : 0): the
 * product is -b/D to the bit, and not above +0 when b >= 0 or unordered.
 * unit_w (a constant once inlined): every lane has a contact with W = -1
 * (the oscillator's wall; a run without one has its wall at g0 = +inf,
 * mj1_lanes_far_wall), so that the products by W are negations, done as
 * such: U = -v, b = e U - v, g = g0 - q (x + (-y) is x - y to the bit),
 * the gap formed from q when the step needs it (g is neither read nor
 * written: the caller's is g0 - q), and the lanes need no selection: an
 * inactive lane's P is +0, and v + (W/What) P adds -0 to v (x + -0 is x,
 * -0 included; What > 0, as for the oscillator's M = 1, C, K >= 0), so
 * that a step where no lane's contact may close skips the impulses'
 * arithmetic.
 * Returns nonzero when a lane's contact may close (always without
 * unit_w). */
static inline __attribute__((always_inline)) unsigned
mj1_lanes_step(int n, const double *const *cs, double th, const lvec *h, const lvec *Fth, lvec *q,
               lvec *v, lvec *g, lvec *P, int unit_w)
{
    const lvec zero = {0.0};
    const size_t W = MJ1_WIDTH; /* one constant's lanes in the group */
    /* cs[i] + k W: constant k of mj1_coefv (c k w e g0 whatinv winv ndelinv hth hgamma wall) */
    lvec rhs[8], vfree[8], U0[8], bb[8];
    lcond active[8], wall[8];
    lmask wm[8];
    unsigned closing = ~0u; /* nonzero when a lane's contact may close */
    MJ1_EACH(n, rhs[i] = h[i] * (Fth[i] - lload(cs[i] + 0 * W) * v[i] -
                                 lload(cs[i] + 1 * W) * (q[i] + lload(cs[i] + 8 * W) * v[i])))
    MJ1_EACH(n, vfree[i] = v[i] + rhs[i] * lload(cs[i] + 5 * W))
    if (unit_w) {
        /* g + h gamma U0 <= 0 with U0 = -v: (g0 - q) - (h gamma) v <= 0
         * to the bit; the impulses only when a lane's contact may close
         * (rare: in a step of none, P is +0 and v + (W/What) P is v) */
        MJ1_EACH(n,
                 active[i] = LLE((lload(cs[i] + 4 * W) - q[i]) - lload(cs[i] + 9 * W) * v[i], zero))
        closing = 0;
        MJ1_EACH(n, closing |= lbits(active[i]))
        if (__builtin_expect(closing != 0, 0)) {
            MJ1_EACH(n, U0[i] = -v[i])
            MJ1_EACH(n, bb[i] = lload(cs[i] + 3 * W) * U0[i] - vfree[i])
            MJ1_EACH(n, P[i] = LKEEP(active[i], LMAX(bb[i] * lload(cs[i] + 7 * W), zero)))
            MJ1_EACH(n, vfree[i] = vfree[i] + lload(cs[i] + 6 * W) * P[i])
        } else {
            MJ1_EACH(n, P[i] = zero)
        }
    } else {
        MJ1_EACH(n, U0[i] = lload(cs[i] + 2 * W) * v[i])
        MJ1_EACH(n, memcpy(&wm[i], cs[i] + 10 * W, sizeof wm[i]))
        MJ1_EACH(n, wall[i] = LCOND_OF(wm[i]))
        MJ1_EACH(n, active[i] = wall[i] & LLE(g[i] + lload(cs[i] + 9 * W) * U0[i], zero))
        MJ1_EACH(n, bb[i] = lload(cs[i] + 2 * W) * vfree[i] + lload(cs[i] + 3 * W) * U0[i])
        MJ1_EACH(n, P[i] = LKEEP(active[i], LMAX(bb[i] * lload(cs[i] + 7 * W), zero)))
        MJ1_EACH(n, vfree[i] = LSEL(active[i], vfree[i] + lload(cs[i] + 6 * W) * P[i], vfree[i]))
    }
    /* q+ = q + h (theta v+ + (1 - theta) v), then v+ and g+ = g0 + W q+ */
    MJ1_EACH(n, q[i] = q[i] + h[i] * (th * vfree[i] + (1.0 - th) * v[i]))
    MJ1_EACH(n, v[i] = vfree[i])
    if (!unit_w)
        MJ1_EACH(n, g[i] = lload(cs[i] + 4 * W) + lload(cs[i] + 2 * W) * q[i])
    return closing;
}

/* Lane l's contact (W = -1) moved to g0 = +inf, where it never closes:
 * the oscillator's run without a wall, or an idle lane, on a lane of
 * unit_w's (its q, v and P are the no-contact step's to the bit: an
 * inactive lane's P is +0). */
static inline void mj1_lanes_far_wall(pd_mjb *b, int l)
{
    mj1_coefv *s = (mj1_coefv *)(void *)b->coef + l / MJ1_WIDTH;
    s->g0[l % MJ1_WIDTH] = INFINITY; /* g0 - q = +inf > 0: never active */
    b->g[l] = INFINITY;
}

/* Lanes meeting their breakpoint at this batch step (b->iter ==
 * b->next_event): mj_batch.c's, for a caller running the steps itself. */
void pd_mjb_breakpoints(pd_mjb *b);

#endif
