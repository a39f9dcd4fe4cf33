/* osc_priv.h — (problems-private) what oscillator.c and osc_penalty.c share. */
#ifndef PD_OSC_PRIV_H
#define PD_OSC_PRIV_H

#include "pd_problems.h"

/* Steps of the Newmark penalty method per period of its stiffest contact
 * element, at least: its step is the output step dt, or dt / k for the
 * smallest whole k that gives this many (coarser steps pump energy into the
 * elements: docs/methods.md, "Penalty baseline": a chain of 3 at kc 1e8
 * blows up at 0.7 steps per period and agrees with the adaptive penalty at
 * 3.5). */
#define PD_NEWMARK_STEPS_PER_CONTACT 10.0

/* dt / k, the Newmark step for the output step dt and the element period Tc. */
double pd_newmark_step(double dt, double Tc);

/* The contact element's stiffness in Pi units (osc_penalty.c's file comment). */
double pd_osc_penalty_kc(const pd_osc *c, const pd_penalty_setup *po);

#endif
