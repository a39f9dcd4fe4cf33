/* osc_batch_lanes.h — the batch's steps with their measurements fused in,
 * a text compiled once per instruction set under the name OSC_BATCH_RUN:
 * osc_batch.c (the baseline), osc_batch_x86v3.c (AVX2), osc_batch_x86v4.c
 * (AVX-512), after their target pragma.  A few vectors of lanes are loaded
 * once per block of steps and run its steps in registers: the engine's
 * arithmetic (engine/mj1_lanes.h, mj1_step's numbers lane for lane), then
 * pd_osc_track_common's numbers, pd_osc_track_events for the lanes that
 * need it (rare: a gap closing, an impact begun), pd_osc_track_shift's;
 * stored at the block's end.  The forces come from a table filled per
 * block (osc_batch.c), so a step has no call. */
#include "osc_batch.h"

#include "mj1_lanes.h" /* the processor's own vector (after the target pragma) */

#if defined(__SSE2__) && PD_LANES_X86
#include <immintrin.h>
#endif

_Static_assert(NL % LW == 0, "whole native vectors of lanes");

/* pd_max and the minimum's a < b ? a : b, lane by lane (the x86 max and min
 * instructions are exactly these: the second operand when the two are
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

/* Is any lane of the condition c set? */
#ifndef LANY
static inline int lany(lmask m)
{
#if defined(__AVX__) && PD_LANES_X86
    return !_mm256_testz_si256((__m256i)m, (__m256i)m);
#elif defined(__SSE2__) && PD_LANES_X86
    return _mm_movemask_pd((__m128d)m) != 0;
#else
    long long any = 0;
    for (int i = 0; i < LW; i++)
        any |= m[i];
    return any != 0;
#endif
}
#define LANY(c) lany(c)
#endif

/* The rare events of the lanes of l .. l + LW - 1 marked in due, from
 * their state before the step (q0, v0, P0, and v two steps back pv2) and
 * after it at step st, time t. */
static void lanes_events(osc_batch *ob, int l, lcond due, lvec st, lvec t, lvec x, lvec v,
                         lvec P, lvec q0, lvec v0, lvec P0, lvec pv2)
{
    for (int i = 0; i < LW; i++)
        if (LLANE(due, i) && ob->id[l + i] >= 0) {
            pd_osc_track *tr = &ob->rare[l + i];
            tr->prev_x = q0[i];
            tr->prev_v = v0[i];
            tr->prev2_v = pv2[i];
            tr->prev_P = P0[i];
            pd_osc_track_events(tr, (long)st[i], t[i], x[i], v[i], P[i]);
        }
}

/* Vectors of lanes stepped together, their chains interleaved (measured
 * on an AMD EPYC with AVX-512: 2 with AVX-512 and AVX2, 4 on the baseline's
 * 2-lane SSE2; 1 leaves the chain's latency bare; more spill registers). */
#ifndef OSC_G
#define OSC_G (LW == 2 ? 4 : 2)
#endif
_Static_assert(NL % (OSC_G * LW) == 0, "whole sets of vectors");

/* Lanes l0 .. l0 + OSC_G LW - 1 the k steps of the block with their state
 * and measurements in registers (the compiler's to spill where there are
 * too few), step after step: the step, then the measurements of
 * pd_osc_track_step (every lane has taken a step: step > 0; max |x| is the
 * larger of the two one-sided maxima, formed at the end: osc_batch.h's
 * rare_load). */
static inline __attribute__((always_inline)) void lanes_run_resident(osc_batch *ob, int l0,
                                                                    int k)
{
    enum { G = OSC_G };
    pd_mjb *b = &ob->mjb;
    const lvec zero = {0.0}, one = zero + 1.0;
    const double *cs[G];
    lvec h[G], st0[G], q[G], v[G], g[G], P[G], pv2[G], xto[G], xaw[G], mg[G], Pmax[G];
    lvec cont[G], Pi3[G], mf[G];
    MJ1_EACH(G, cs[i] = mj1_lanes_coef(b, l0 + i * LW))
    MJ1_EACH(G, h[i] = lload(&b->h[l0 + i * LW]))
    MJ1_EACH(G, st0[i] = lload(&b->steps[l0 + i * LW]))
    MJ1_EACH(G, q[i] = lload(&b->q[l0 + i * LW]))
    MJ1_EACH(G, v[i] = lload(&b->v[l0 + i * LW]))
    MJ1_EACH(G, g[i] = lload(&b->g[l0 + i * LW]))
    MJ1_EACH(G, P[i] = lload(&b->P[l0 + i * LW]))
    MJ1_EACH(G, pv2[i] = lload(&ob->prev2_v[l0 + i * LW]))
    MJ1_EACH(G, xto[i] = lload(&ob->xtoward[l0 + i * LW]))
    MJ1_EACH(G, xaw[i] = lload(&ob->xaway[l0 + i * LW]))
    MJ1_EACH(G, mg[i] = lload(&ob->min_gap[l0 + i * LW]))
    MJ1_EACH(G, Pmax[i] = lload(&ob->Pmax[l0 + i * LW]))
    MJ1_EACH(G, cont[i] = lload(&ob->contact[l0 + i * LW]))
    MJ1_EACH(G, Pi3[i] = lload(&ob->Pi3[l0 + i * LW]))
    MJ1_EACH(G, mf[i] = lload(&ob->meas_from[l0 + i * LW]))
    for (int s = 0; s < k; s++) {
        /* the step count: st0 + s + 1 (whole numbers: the sum of ones) */
        const double ds = (double)(s + 1);
        lvec st[G], t[G], x[G], vn[G], Pn[G], F0[G], F1[G], gap[G];
        lcond pos[G], meas[G], due[G];
        MJ1_EACH(G, st[i] = st0[i] + ds)
        MJ1_EACH(G, t[i] = st[i] * h[i])
        MJ1_EACH(G, F0[i] = lload(&ob->F[s][l0 + i * LW]))
        MJ1_EACH(G, F1[i] = lload(&ob->F[s + 1][l0 + i * LW]))
        MJ1_EACH(G, x[i] = q[i])
        MJ1_EACH(G, vn[i] = v[i])
        mj1_lanes_step(G, cs, b->theta, h, F0, F1, x, vn, g, Pn);
        MJ1_EACH(G, gap[i] = Pi3[i] - x[i])
        MJ1_EACH(G, pos[i] = LGT(Pn[i], zero))
        MJ1_EACH(G, meas[i] = LGE(t[i], mf[i]))
        MJ1_EACH(G, xto[i] = LSEL(meas[i], LMAX(xto[i], x[i]), xto[i]))
        MJ1_EACH(G, xaw[i] = LSEL(meas[i], LMAX(xaw[i], -x[i]), xaw[i]))
        MJ1_EACH(G, cont[i] = cont[i] + LKEEP(pos[i], one))
        MJ1_EACH(G, Pmax[i] = LSEL(pos[i], LMAX(Pmax[i], Pn[i]), Pmax[i]))
        MJ1_EACH(G, mg[i] = LMIN(mg[i], gap[i]))
        MJ1_EACH(G, due[i] = (LGT(Pi3[i] - q[i], zero) & (LLE(gap[i], zero) | pos[i])) |
                             (pos[i] & LEQ(P[i], zero)))
        for (int i = 0; i < G; i++)
            if (__builtin_expect(LANY(due[i]), 0))
                lanes_events(ob, l0 + i * LW, due[i], st[i], t[i], x[i], vn[i], Pn[i], q[i],
                             v[i], P[i], pv2[i]);
        MJ1_EACH(G, pv2[i] = v[i])
        MJ1_EACH(G, q[i] = x[i])
        MJ1_EACH(G, v[i] = vn[i])
        MJ1_EACH(G, P[i] = Pn[i])
    }
    MJ1_EACH(G, lstore(&b->steps[l0 + i * LW], st0[i] + (double)k))
    MJ1_EACH(G, lstore(&b->q[l0 + i * LW], q[i]))
    MJ1_EACH(G, lstore(&b->v[l0 + i * LW], v[i]))
    MJ1_EACH(G, lstore(&b->g[l0 + i * LW], g[i]))
    MJ1_EACH(G, lstore(&b->P[l0 + i * LW], P[i]))
    MJ1_EACH(G, lstore(&ob->prev2_v[l0 + i * LW], pv2[i]))
    MJ1_EACH(G, lstore(&ob->xtoward[l0 + i * LW], xto[i]))
    MJ1_EACH(G, lstore(&ob->xaway[l0 + i * LW], xaw[i]))
    MJ1_EACH(G, lstore(&ob->min_gap[l0 + i * LW], mg[i]))
    MJ1_EACH(G, lstore(&ob->Pmax[l0 + i * LW], Pmax[i]))
    MJ1_EACH(G, lstore(&ob->contact[l0 + i * LW], cont[i]))
}

/* k steps of every lane, OSC_G vectors at a time; then the lanes' clocks,
 * the forces F[k] as the next step's F0, the batch's step count. */
void OSC_BATCH_RUN(osc_batch *ob_, int k)
{
    osc_batch *ob = __builtin_assume_aligned(ob_, 64); /* batch_open's aligned_alloc */
    pd_mjb *b = &ob->mjb;
    for (int j = 0; j < NL / (OSC_G * LW); j++)
        lanes_run_resident(ob, j * OSC_G * LW, k);
    for (int l = 0; l < NL; l += LW) {
        lstore(&b->t[l], lload(&b->steps[l]) * lload(&b->h[l]));
        lstore(&b->F0[l], lload(&ob->F[k][l]));
    }
    b->iter += k;
}
