/* osc_batch_lanes.h — the batch's measurements after each step, a text
 * compiled once per instruction set under the name OSC_BATCH_OBSERVE:
 * osc_batch.c (the baseline), osc_batch_x86v3.c (AVX2), osc_batch_x86v4.c
 * (AVX-512).  Every variant computes pd_osc_track_common's numbers, lane
 * for lane. */
#include "osc_batch.h"

#include "pd_lanes.h" /* the processor's own vector (after the target pragma) */

_Static_assert(NL % LW == 0, "whole native vectors of lanes");

/* One vector of lanes after a step: pd_osc_track_common's numbers lane for
 * lane (max |x| is the larger of the two one-sided maxima, formed at the
 * end: osc_batch.h's rare_load); pd_osc_track_events for
 * the lanes that need it (rare: a gap closing, an impact begun); then
 * pd_osc_track_shift's. */
static inline void track_vector(osc_batch *ob, int l)
{
    const lvec zero = {0.0}, one = zero + 1.0;
    lvec x, v, P, Pi3, xto, xaw, mg, Pmax, cont, px, pP, pv;
#define LOAD(var, arr) memcpy(&var, &(arr)[l], sizeof var)
#define STORE(arr, var) memcpy(&(arr)[l], &var, sizeof var)
    LOAD(x, ob->mjb.q);
    LOAD(v, ob->mjb.v);
    LOAD(P, ob->mjb.P);
    LOAD(Pi3, ob->Pi3);
    LOAD(xto, ob->xtoward);
    LOAD(xaw, ob->xaway);
    LOAD(mg, ob->min_gap);
    LOAD(Pmax, ob->Pmax);
    LOAD(cont, ob->contact);
    LOAD(px, ob->prev_x);
    LOAD(pP, ob->prev_P);
    LOAD(pv, ob->prev_v);
    lvec gap = Pi3 - x, nx = -x;
    lvec t, mf;
    LOAD(t, ob->mjb.t);
    LOAD(mf, ob->meas_from);
    lmask pos = P > zero, meas = t >= mf;
    xto = LSELECT(meas, LSELECT(xto > x, xto, x), xto);
    xaw = LSELECT(meas, LSELECT(xaw > nx, xaw, nx), xaw);
    cont = cont + (lvec)(pos & (lmask)one);
    Pmax = LSELECT(pos, LSELECT(Pmax > P, Pmax, P), Pmax);
    mg = LSELECT(mg < gap, mg, gap);
    lvec gprev = Pi3 - px;
    /* every lane has taken a step: step > 0 */
    lmask due = ((gprev > zero) & ((gap <= zero) | pos)) | (pos & (pP == zero));
    STORE(ob->xtoward, xto);
    STORE(ob->xaway, xaw);
    STORE(ob->min_gap, mg);
    STORE(ob->Pmax, Pmax);
    STORE(ob->contact, cont);
    long long hit = 0;
    for (int i = 0; i < LW; i++)
        hit |= due[i];
    if (hit)
        for (int i = 0; i < LW; i++)
            if (due[i] && ob->id[l + i] >= 0) {
                rare_load(ob, l + i);
                pd_osc_track_events(&ob->rare[l + i], (long)ob->mjb.steps[l + i],
                                    ob->mjb.t[l + i], x[i], v[i], P[i]);
            }
    STORE(ob->prev2_v, pv);
    STORE(ob->prev_x, x);
    STORE(ob->prev_v, v);
    STORE(ob->prev_P, P);
#undef LOAD
#undef STORE
}

/* After every step, every vector of lanes. */
int OSC_BATCH_OBSERVE(const pd_mjb *b, void *ctx)
{
    osc_batch *ob = ctx;
    (void)b;
    for (int l = 0; l < NL; l += LW)
        track_vector(ob, l);
    return 0;
}

