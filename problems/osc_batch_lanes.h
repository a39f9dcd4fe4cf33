/* osc_batch_lanes.h — the batch's steps and their measurements, a text
 * compiled once per instruction set under the name OSC_BATCH_RUN:
 * osc_batch.c (the baseline), osc_batch_x86v3.c (AVX2), osc_batch_x86v4.c
 * (AVX-512), after their target pragma.  A set of vectors of lanes is
 * loaded once per block of steps and runs its steps in registers (the
 * engine's arithmetic, engine/pd_mj1_lanes.h: mj1_step's numbers lane for
 * lane), keeping each step's x, v and P in rings and, where the whole
 * block is measured, folding the block's extremes as it goes; a second
 * pass over the rings gives the other measurements and calls
 * pd_osc_track_events for the lanes that need it (rare: a gap closing, an
 * impact begun).  The steps' forces come from a table filled per block
 * (osc_batch.c), so a step has no call. */
#include "osc_batch.h"

#include "pd_mj1_lanes.h" /* the processor's own vector (after the target pragma) */

_Static_assert(NL % LW == 0, "whole native vectors of lanes");

/* The rare events of the lanes of l .. l + LW - 1 whose bits are set in
 * due, from their state before the step (q0, v0, P0, and v two steps back
 * pv2) and after it at step st, time t. */
static void lanes_events(osc_batch *ob, int l, unsigned due, lvec st, lvec t, lvec x, lvec v,
                         lvec P, lvec q0, lvec v0, lvec P0, lvec pv2)
{
    for (int i = 0; i < LW; i++)
        if ((due >> i & 1u) && ob->id[l + i] >= 0) {
            pd_osc_track *tr = &ob->rare[l + i];
            tr->prev_x = q0[i];
            tr->prev_v = v0[i];
            tr->prev2_v = pv2[i];
            tr->prev_P = P0[i];
            pd_osc_track_events(tr, (long)st[i], t[i], x[i], v[i], P[i]);
        }
}

/* Vectors of lanes stepped together, their chains interleaved: 4 on
 * every instruction set (measured on an AMD EPYC with AVX-512, the
 * paper-scale sweep, since the steps where no contact may close take the
 * short path: 8 vectors ran 4 % (SSE2) and 12 % (AVX2) slower, their q, v
 * and block extremes spilled from the 16 registers; 2 a third slower, the
 * step's chain of about 30 latencies too long for them). */
#ifndef OSC_G
#define OSC_G 4
#endif
_Static_assert(NL % (OSC_G * LW) == 0, "whole sets of vectors");
_Static_assert(OSC_G *LW <= 32, "a set's lanes are the bits of an unsigned");
_Static_assert(OSC_G <= 8, "mj1_lanes_step takes at most 8 vectors");

/* Contact steps counted in registers: AVX-512 adds one under the mask;
 * the others subtract the all-ones lanes of the condition (-1) from a
 * whole-number count, added to the lane's double at the block's end. */
#if defined(__AVX512F__) && PD_LANES_X86
typedef lvec lcount;
#define LCOUNT_ZERO ((lvec){0.0})
#define LCOUNT(n, c) ((lvec)_mm512_mask_add_pd((__m512d)(n), c, (__m512d)(n), _mm512_set1_pd(1.0)))
#define LCOUNT_ADD(x, n) ((x) + (n))
#else
typedef lmask lcount;
#define LCOUNT_ZERO ((lmask){0})
#define LCOUNT(n, c) ((n) - (c))
#define LCOUNT_ADD(x, n) ((x) + __builtin_convertvector(n, lvec))
#endif

/* The lanes due for pd_osc_track_events after a step, from x < Pi3 and
 * P > 0 before it (lt0, pos0) and after it (lt1, pos1), as bits: the gap
 * was open and closed (or an impulse stopped it closing), or an impact
 * began. */
#define EVENTS_DUE(lt0, lt1, pos0, pos1) (((lt0) & ~((lt1) & ~(pos1))) | ((pos1) & ~(pos0)))

/* Sixteen steps' lane bits (a byte a step). */
typedef unsigned char stepbytes __attribute__((vector_size(16)));
_Static_assert(LW <= 8, "a step's lanes are the bits of a byte");

/* Sixteen bytes from p (any alignment). */
static inline stepbytes sbload(const unsigned char *p)
{
    stepbytes x;
    memcpy(&x, p, sizeof x);
    return x;
}

/* The nonzero bytes of d as the bits of a whole number (byte i: bit i). */
static inline unsigned sbnonzero(stepbytes d)
{
#if PD_LANES_X86
    const stepbytes none = {0};
    return 0xffffu & ~(unsigned)_mm_movemask_epi8((__m128i)(d == none));
#else
    unsigned bits = 0;
    for (int i = 0; i < 16; i++)
        bits |= (d[i] != 0) << i;
    return bits;
#endif
}

/* Vector i of a set (lanes l .. l + LW - 1) over the k steps in the rings
 * (lanes_run_resident's): its contact steps, returned, and the events of
 * its lanes that need them (pd_osc_track_events_due's condition, from the
 * conditions of the step before), in step order. */
static inline __attribute__((always_inline)) lcount lanes_scan(osc_batch *ob, int l, int k, lvec h,
                                                               lvec st0, lvec Pi3,
                                                               lvec (*xr)[OSC_G], lvec (*vr)[OSC_G],
                                                               lvec (*Pr)[OSC_G], int i)
{
    const lvec zero = {0.0};
    lcount cnt = LCOUNT_ZERO;
    /* x < Pi3 and P > 0 after step s - 1 (s = 0: before the block), lane
     * l + j at bit j: formed for every step first (no chain through them);
     * zero past k (read by the last sixteen, which ignores them) */
    unsigned char ltb[OSC_BLOCK + 16] = {0}, posb[OSC_BLOCK + 16] = {0};
    ltb[0] = (unsigned char)lbits(LLT(xr[0][i], Pi3));
    posb[0] = (unsigned char)lbits(LGT(Pr[0][i], zero));
    for (int s = 1; s <= k; s++) {
        lcond posn = LGT(Pr[s][i], zero);
        ltb[s] = (unsigned char)lbits(LLT(xr[s][i], Pi3));
        posb[s] = (unsigned char)lbits(posn);
        cnt = LCOUNT(cnt, posn);
    }
    /* sixteen steps at a time, the steps with a lane due as bits */
    for (int s0 = 0; s0 < k; s0 += 16) {
        unsigned steps = sbnonzero(EVENTS_DUE(sbload(ltb + s0), sbload(ltb + s0 + 1),
                                              sbload(posb + s0), sbload(posb + s0 + 1)));
        if (k - s0 < 16)
            steps &= (1u << (k - s0)) - 1u;
        while (__builtin_expect(steps != 0, 0)) {
            int s = s0 + __builtin_ctz(steps);
            unsigned due = EVENTS_DUE(ltb[s], ltb[s + 1], posb[s], posb[s + 1]);
            lvec st = st0 + (double)(s + 1);
            lanes_events(ob, l, due, st, st * h, xr[s + 1][i], vr[s + 2][i], Pr[s + 1][i], xr[s][i],
                         vr[s + 1][i], Pr[s][i], vr[s][i]);
            steps &= steps - 1u;
        }
    }
    return cnt;
}

/* Lanes l0 .. l0 + OSC_G LW - 1 the k steps of the block, their state
 * (q, v, g) in registers step after step (the compiler's to spill where
 * there are too few), each step's x, v and P kept in rings; then a second
 * pass, free of the steps' chains, over the rings in step order:
 * pd_osc_track_common's numbers (the extremes folded by the steps instead
 * when `all`, below; every lane has taken a step: step > 0;
 * max |x| is the larger of the two one-sided maxima, formed at the end:
 * osc_batch.h's rare_load) and the test for pd_osc_track_events (rare:
 * the lanes that need them call them there, in their steps' order).
 * `all` (a constant once inlined): every step of the block lies in every
 * lane's window, so the extremes need no selection: the steps fold the
 * block's maxima of x and P and minimum of x (P only in a step with a
 * contact: the others' P is +0, which leaves a maximum from +0 as it is),
 * folded into the run's at the block's end, the largest -x is -(min x)
 * and the smallest gap Pi3 - max x (the x86 maximum and minimum keep the
 * last of equal values, so that the block's extreme is the very value the
 * step-by-step fold keeps, and -(min x) the very -x, signed zeros
 * included; fl(Pi3 - x) falls as x grows, and every x of the maximum was
 * a gap of the minimum before); and a vector whose lanes kept x < Pi3 and
 * P = 0 over the block has no event and no contact step, the
 * step-by-step scan (lanes_scan) left to the others.
 * The other rewritings are exact too: the largest impulse folds every P
 * (P >= +0, the maximum from +0); the gap is <= 0 exactly when x >= Pi3
 * and > 0 when x < Pi3 (a difference of doubles is 0 only for equal
 * ones), P == 0 when not P > 0 (P is +0 or positive); so the events'
 * condition is pd_osc_track_events_due's, from conditions carried over
 * from the previous step (a lane turned NaN may call the events once more:
 * they test their own conditions, and the lane is run again alone). */
static inline __attribute__((always_inline)) void lanes_run_resident(osc_batch *ob, int l0, int k,
                                                                     int all)
{
    enum { G = OSC_G };
    pd_mjb *b = &ob->mjb;
    const lvec zero = {0.0};
    const double *cs[G];
    lvec h[G], q[G], v[G]; /* (the gaps: g0 - q, unit_w's) */
    /* the rings: x after step s at xr[s + 1], v at vr[s + 2], P at
     * Pr[s + 1]; the state before the block at xr[0], vr[1] and Pr[0],
     * v two steps back at vr[0] */
    lvec xr[OSC_BLOCK + 1][G], vr[OSC_BLOCK + 2][G], Pr[OSC_BLOCK + 1][G];
    MJ1_EACH(G, cs[i] = mj1_lanes_coef(b, l0 + i * LW))
    MJ1_EACH(G, h[i] = lload(&b->h[l0 + i * LW]))
    MJ1_EACH(G, q[i] = lload(&b->q[l0 + i * LW]))
    MJ1_EACH(G, v[i] = lload(&b->v[l0 + i * LW]))
    MJ1_EACH(G, xr[0][i] = q[i])
    MJ1_EACH(G, vr[0][i] = lload(&ob->prev2_v[l0 + i * LW]))
    MJ1_EACH(G, vr[1][i] = v[i])
    MJ1_EACH(G, Pr[0][i] = lload(&b->P[l0 + i * LW]))
    lvec bx[G], bxmin[G], bP[G]; /* all's: the block's extremes, folded by the steps */
    MJ1_EACH(G, bx[i] = zero - HUGE_VAL)
    MJ1_EACH(G, bxmin[i] = zero + HUGE_VAL)
    MJ1_EACH(G, bP[i] = zero)
    for (int s = 0; s < k; s++) {
        lvec Fth[G], Pn[G];
        MJ1_EACH(G, Fth[i] = lload(&ob->Fth[s][l0 + i * LW]))
        unsigned closing = mj1_lanes_step(G, cs, b->theta, h, Fth, q, v, NULL, Pn, 1);
        MJ1_EACH(G, xr[s + 1][i] = q[i])
        MJ1_EACH(G, vr[s + 2][i] = v[i])
        MJ1_EACH(G, Pr[s + 1][i] = Pn[i])
        if (all) {
            MJ1_EACH(G, bx[i] = LMAX(bx[i], q[i]))
            MJ1_EACH(G, bxmin[i] = LMIN(bxmin[i], q[i]))
            if (closing)
                MJ1_EACH(G, bP[i] = LMAX(bP[i], Pn[i]))
        }
    }
    MJ1_EACH(G, lstore(&b->q[l0 + i * LW], q[i]))
    MJ1_EACH(G, lstore(&b->v[l0 + i * LW], v[i]))
    MJ1_EACH(G, lstore(&b->g[l0 + i * LW], lload(cs[i] + 4 * MJ1_WIDTH) - q[i]))
    MJ1_EACH(G, lstore(&b->P[l0 + i * LW], Pr[k][i]))
    MJ1_EACH(G, lstore(&ob->prev2_v[l0 + i * LW], vr[k][i]))
    /* the measurements and the events from the rings, in step order */
    lvec xto[G], xaw[G], mg[G], Pmax[G], st0[G], Pi3[G];
    lcount cnt[G];
    MJ1_EACH(G, xto[i] = lload(&ob->xtoward[l0 + i * LW]))
    MJ1_EACH(G, xaw[i] = lload(&ob->xaway[l0 + i * LW]))
    MJ1_EACH(G, mg[i] = lload(&ob->min_gap[l0 + i * LW]))
    MJ1_EACH(G, Pmax[i] = lload(&ob->Pmax[l0 + i * LW]))
    MJ1_EACH(G, st0[i] = lload(&b->steps[l0 + i * LW]))
    MJ1_EACH(G, Pi3[i] = lload(&ob->Pi3[l0 + i * LW]))
    MJ1_EACH(G, cnt[i] = LCOUNT_ZERO)
    if (all) {
        /* a vector whose gaps stayed open without an impulse has no event
         * and no contact step in the block; the others are scanned */
        for (int i = 0; i < G; i++)
            if (lbits(LGE(bx[i], Pi3[i]) | LGT(bP[i], zero)))
                cnt[i] = lanes_scan(ob, l0 + i * LW, k, h[i], st0[i], Pi3[i], xr, vr, Pr, i);
        MJ1_EACH(G, xto[i] = LMAX(xto[i], bx[i]))
        MJ1_EACH(G, xaw[i] = LMAX(xaw[i], -bxmin[i]))
        MJ1_EACH(G, Pmax[i] = LMAX(Pmax[i], bP[i]))
        MJ1_EACH(G, mg[i] = LMIN(mg[i], Pi3[i] - xto[i]))
    } else {
        lvec mf[G];
        MJ1_EACH(G, mf[i] = lload(&ob->meas_from[l0 + i * LW]))
        for (int s = 0; s < k; s++) {
            /* the step's end t = (st0 + s + 1) h (whole numbers: the sum of ones) */
            lcond meas[G];
            MJ1_EACH(G, meas[i] = LGE((st0[i] + (double)(s + 1)) * h[i], mf[i]))
            MJ1_EACH(G, xto[i] = LSEL(meas[i], LMAX(xto[i], xr[s + 1][i]), xto[i]))
            MJ1_EACH(G, xaw[i] = LSEL(meas[i], LMAX(xaw[i], -xr[s + 1][i]), xaw[i]))
            MJ1_EACH(G, mg[i] = LMIN(mg[i], Pi3[i] - xr[s + 1][i]))
            MJ1_EACH(G, Pmax[i] = LMAX(Pmax[i], Pr[s + 1][i]))
        }
        for (int i = 0; i < G; i++)
            cnt[i] = lanes_scan(ob, l0 + i * LW, k, h[i], st0[i], Pi3[i], xr, vr, Pr, i);
    }
    MJ1_EACH(G, lstore(&b->steps[l0 + i * LW], st0[i] + (double)k))
    MJ1_EACH(G, lstore(&ob->xtoward[l0 + i * LW], xto[i]))
    MJ1_EACH(G, lstore(&ob->xaway[l0 + i * LW], xaw[i]))
    MJ1_EACH(G, lstore(&ob->min_gap[l0 + i * LW], mg[i]))
    MJ1_EACH(G, lstore(&ob->Pmax[l0 + i * LW], Pmax[i]))
    MJ1_EACH(
        G, lstore(&ob->contact[l0 + i * LW], LCOUNT_ADD(lload(&ob->contact[l0 + i * LW]), cnt[i])))
}

/* Is every step of the block (its first step's end: the lanes' clocks
 * grow) inside the measuring window of the busy lanes among l0 .. l0 +
 * OSC_G LW - 1 (an idle lane's figures are set anew when it starts)? */
static inline int lanes_all_measured(const osc_batch *ob, int l0)
{
    const pd_mjb *b = &ob->mjb;
    for (int l = l0; l < l0 + OSC_G * LW; l++)
        if (ob->id[l] >= 0 && !((b->steps[l] + 1.0) * b->h[l] >= ob->meas_from[l]))
            return 0;
    return 1;
}

/* k steps of every lane, OSC_G vectors at a time; then the lanes' clocks,
 * the force at the block's end as the next step's F0, the batch's step
 * count. */
void OSC_BATCH_RUN(osc_batch *ob_, int k)
{
    osc_batch *ob = __builtin_assume_aligned(ob_, 64); /* batch_open's aligned_alloc */
    pd_mjb *b = &ob->mjb;
    for (int l0 = 0; l0 < NL; l0 += OSC_G * LW) {
        if (lanes_all_measured(ob, l0))
            lanes_run_resident(ob, l0, k, 1);
        else
            lanes_run_resident(ob, l0, k, 0);
    }
    for (int l = 0; l < NL; l += LW) {
        lstore(&b->t[l], lload(&b->steps[l]) * lload(&b->h[l]));
        lstore(&b->F0[l], lload(&ob->Fend[l]));
    }
    b->iter += k;
}
