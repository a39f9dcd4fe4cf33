/* scene_priv.h — what the scene's modules share (problems-private): the
 * penalty's default contact stiffness and the stiffest storey it scales,
 * and the methods' work budget checked when a run is resolved. */
#ifndef PD_SCENE_PRIV_H
#define PD_SCENE_PRIV_H

#include "pd_problems.h"

#define SCENE_PEN_KC 1e4 /* the default contact stiffness: this * the stiffest storey's */

/* The largest storey stiffness of the scene [N/m]. */
double pd_scene_stiffest(const pd_scene *sc);

/* The penalty's contact stiffness of o on sc [N/m] (Kelvin-Voigt: kc_abs,
 * or kc_mult, default SCENE_PEN_KC, times the stiffest storey). */
double pd_scene_penalty_kc(const pd_scene *sc, const pd_run_opts *o);

/* The shortest period of the penalty elements [s] (Kelvin-Voigt's kc on the
 * contact's reduced mass; for Hertz-damp with kc_abs [N/m^1.5], the tangent
 * 1.5 kc sqrt(d) at a penetration of 1 % of Le): HUGE_VAL without contacts. */
double pd_scene_contact_period_min(const pd_scene *sc, const pd_run_opts *o);

/* The energy balance of a yielding scene's Moreau-Jean run (scene_energy.c):
 * the step's identity summed, from rest, in the model's units. */
typedef struct pd_scene_energy pd_scene_energy;
pd_scene_energy *pd_scene_energy_alloc(const pd_model *md, double h, double theta);
void pd_scene_energy_free(pd_scene_energy *e);
/* After each step (and at the start: st->step 0). */
void pd_scene_energy_note(pd_scene_energy *e, const pd_state *st);
/* The same after each Newmark step (theta 1/2, the step's length from the
 * times): st->P the elements' forces at its end, lam0 at its start. */
void pd_scene_energy_note_forces(pd_scene_energy *e, const pd_state *st, const double *lam0);
/* The balance in joules (energy unit E = Le^2 wp^2 kg). */
void pd_scene_energy_finish(const pd_scene_energy *e, double E, pd_energy *out);
/* The exact row reference's balance (its opts.energy terms) in joules. */
void pd_scene_energy_of_edr(const pd_edr_result *er, double E, pd_energy *out);

/* Each contact's separation from the summary's twin (separation.c):
 * required_gap and the rules, into the summary's arrays. */
void pd_scene_separation(const pd_scene *sc, pd_scene_summary *s);

#endif
