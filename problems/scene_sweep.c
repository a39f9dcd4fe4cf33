/* scene_sweep.c — Pi spectra of a scene (pd_problems.h, "scene sweeps"):
 * every task a modified copy of the scene, run independently, so that any
 * split of the tasks over threads gives the same numbers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_null.h"
#include "pd_problems.h"

#ifdef _OPENMP
#include <omp.h>
#endif

long pd_scene_sweep_twins(const pd_scene_sweep *w)
{
    return w ? w->npi2 : 0;
}

long pd_scene_sweep_points(const pd_scene_sweep *w)
{
    if (!w)
        return 0;
    return (long)w->npi2 * (w->npi3 > 0 ? w->npi3 : 1) * (w->neps > 0 ? w->neps : 1);
}

int pd_scene_sweep_check(const pd_scene_sweep *w, pd_err *err)
{
    if (!w)
        return PD_NULL_ARG(err, "w");
    const pd_scene *sc = w->sc;
    if (!sc || !sc->finished)
        return pd_err_set(err, PD_EINVAL, "scene: not finished");
    if (sc->exc.record)
        return pd_err_set(err, PD_EINVAL,
                          "scene: the sweep varies the pulse period, which a "
                          "record fixes (its fitted pulse's): sweep records with the oscillator");
    if (w->ref < 0 || w->ref >= sc->nstruct)
        return pd_err_set(err, PD_EINVAL, "ref: no structure %d", w->ref);
    if (!(w->pi2_min > 0.0) || w->npi2 < 1 || !(w->pi2_max >= w->pi2_min))
        return pd_err_set(err, PD_EINVAL, "Pi2: need 0 < MIN <= MAX and N >= 1");
    if (w->npi3 > 0 && pd_scene_springs(sc) > 0)
        return pd_err_set(err, PD_EINVAL,
                          "Pi3: a yielding scene's sweep keeps its gaps and yield drifts in "
                          "metres (the contact-free twin would change with each Pi3): sweep "
                          "Pi2 alone");
    if (w->npi3 > 0) {
        if (w->ref_contact < 0 || w->ref_contact >= sc->ncontact)
            return pd_err_set(err, PD_EINVAL, "ref-contact: no contact %d (the scene has %d)",
                              w->ref_contact, sc->ncontact);
        if (!(sc->ct[w->ref_contact].gap > 0.0))
            return pd_err_set(err, PD_EINVAL,
                              "ref-contact: contact %d has a zero gap: the gaps cannot be scaled "
                              "to a Pi3",
                              w->ref_contact);
    }
    if ((w->npi3 > 0 && !w->pi3) || (w->neps > 0 && !w->eps))
        return pd_err_set(err, PD_EINVAL, "%s: %d values but no list",
                          w->npi3 > 0 && !w->pi3 ? "Pi3" : "eps",
                          w->npi3 > 0 && !w->pi3 ? w->npi3 : w->neps);
    for (int i = 0; i < w->npi3; i++)
        if (!(w->pi3[i] >= 0.0) || !isfinite(w->pi3[i]))
            return pd_err_set(err, PD_EINVAL, "Pi3: must be >= 0 (got %g)", w->pi3[i]);
    for (int i = 0; i < w->neps; i++)
        if (!(w->eps[i] >= 0.0 && w->eps[i] <= 1.0))
            return pd_err_set(err, PD_EINVAL, "eps: restitution must be in [0, 1] (got %g)",
                              w->eps[i]);
    return PD_OK;
}

int pd_scene_sweep_scene(const pd_scene_sweep *w, long task, pd_scene **out, pd_scene_point *pt,
                         pd_err *err)
{
    int rc;
    if (!w || !out || !pt)
        return PD_NULL_ARG(err, !w ? "w" : !out ? "out" : "pt");
    *out = NULL;
    if ((rc = pd_scene_sweep_check(w, err)))
        return rc;
    if (task < 0 || task >= pd_scene_sweep_twins(w) + pd_scene_sweep_points(w))
        return pd_err_set(err, PD_EINVAL, "task: %ld is not one of the sweep's %ld", task,
                          pd_scene_sweep_twins(w) + pd_scene_sweep_points(w));
    const pd_scene *sc = w->sc;
    long ntw = pd_scene_sweep_twins(w), p = task - ntw;
    int twin = task < ntw, j = (int)(twin ? task : p % w->npi2);
    long rest = twin ? 0 : p / w->npi2;
    int i3 = w->npi3 > 0 ? (int)(rest % w->npi3) : 0;
    int ie = w->npi3 > 0 ? (int)(rest / w->npi3) : (int)rest;
    pd_scene *c = pd_scene_copy(sc);
    if (!c)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a copy of the scene");
    memset(pt, 0, sizeof *pt);
    pt->Pi2 = pd_grid_value(w->pi2_min, w->pi2_max, w->npi2, w->linear, j);
    c->exc.Tp = pt->Pi2 * sc->st[w->ref].T0; /* Pi2 = Tp / T0 of the reference */
    double wp = PD_TWO_PI / c->exc.Tp, Le = c->exc.ap / (wp * wp);
    if (!twin && w->npi3 > 0) { /* every gap scaled with the reference contact's */
        double f = w->pi3[i3] * Le / sc->ct[w->ref_contact].gap;
        for (int a = 0; a < c->ncontact; a++)
            c->ct[a].gap = sc->ct[a].gap * f;
    }
    if (!twin && w->neps > 0)
        for (int a = 0; a < c->ncontact; a++)
            c->ct[a].eps = w->eps[ie];
    if (w->opts.tend == 0.0)
        c->tend = 0.0; /* the file's tend was for its own pulse: derive it per point */
    if ((rc = pd_scene_finish(c, err))) {
        pd_scene_free(c);
        return rc;
    }
    pt->Tp = c->exc.Tp;
    pt->Le = Le;
    int refc = w->ref_contact >= 0 && w->ref_contact < c->ncontact ? w->ref_contact : 0;
    pt->Pi3 = c->ncontact > 0 ? c->ct[refc].gap / Le : NAN;
    pt->eps = c->ncontact > 0 ? c->ct[0].eps : NAN;
    *out = c;
    return PD_OK;
}

/* One task into its slots. */
static int run_task(const pd_scene_sweep *w, long t, pd_scene_point *pt, double *umax, pd_err *err)
{
    pd_scene *c;
    pd_scene_result r;
    pd_run_opts o = w->opts;
    int rc;
    if ((rc = pd_scene_sweep_scene(w, t, &c, pt, err)))
        return pt->status = rc; /* the run's own status: pd_scene_sweep_run returns it */
    o.no_wall = t < pd_scene_sweep_twins(w);
    o.no_demands = 1;  /* a sweep keeps umax */
    o.no_law_band = 1; /* nor the other impact law's run */
    if (!(rc = pd_scene_result_alloc(c, &r, err))) {
        rc = pd_scene_run(c, &o, NULL, NULL, &r, err);
        for (int s = 0; s < c->nstruct; s++) {
            double m = 0.0;
            for (int k = 0; k < c->st[s].storeys; k++)
                m = fmax(m, r.umax[c->st[s].dof + k]);
            umax[s] = m;
        }
        for (int a = 0; a < c->ncontact; a++)
            pt->impacts += r.impacts[a];
        pt->steps = r.steps;
        pt->cpu_s = r.cpu_s;
        pd_scene_result_free(&r);
    }
    pd_scene_free(c);
    pt->status = rc;
    return rc;
}

int pd_scene_sweep_run(const pd_scene_sweep *w, int threads, pd_scene_point *pts, double *umax,
                       pd_err *err)
{
    if (!w || !pts || !umax)
        return PD_NULL_ARG(err, !w ? "w" : !pts ? "pts" : "umax");
    long n = pd_scene_sweep_twins(w) + pd_scene_sweep_points(w), first_bad = -1;
    int rc;
    if ((rc = pd_scene_sweep_check(w, err)))
        return rc;
    int ns = w->sc->nstruct;
#ifdef _OPENMP
    int nt = threads > 0 ? threads : omp_get_max_threads();
#else
    int nt = 1; /* the pragma below is ignored without OpenMP */
    (void)threads;
    (void)nt;
#endif
    /* one task at a time to each thread; each writes only its own slots */
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
    for (long t = 0; t < n; t++) {
        pd_err e;
        if (run_task(w, t, &pts[t], umax + (size_t)t * ns, &e)) {
#pragma omp critical(pd_scene_sweep)
            if (first_bad < 0 || t < first_bad) {
                first_bad = t;
                if (err)
                    *err = e;
            }
        }
    }
    return first_bad < 0 ? PD_OK : pts[first_bad].status;
}
