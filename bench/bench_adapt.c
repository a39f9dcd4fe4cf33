/* bench_adapt.c — `pound bench --rtol`: Moreau–Jean to a tolerance against
 * fixed steps and the exact references (issue 28's cost figures).
 *
 *   one wall   180 cases (pulses, directions, Pi2 0.3 ... 6, Pi3 0.01 ... 0.5,
 *              eps 0 ... 0.9): at accuracy A = 1e-5 of umax the CPU time of fixed
 *              steps (dt halved from the default until |umax - umax_ref| <= A
 *              umax_ref; the run that got there) against the run to rtol A; the
 *              medians and the median of the per-case ratios; each run's CPU
 *              time the least of ADAPT_REPEAT repetitions (a machine shared with
 *              others, caches cold after the reference: the run's own cost)
 *   points     error of umax (largest over the structures) against CPU time for
 *              rtol 1e-2 ... 1e-6 on one wall, rows of 2, 10 and 100, a record
 *   cluster    the compressed three-structure row, rtol 1e-3
 *   row 1e4    ns per DOF-step of --chain 10000 to rtol 1e-3 and at fixed dt (each
 *              the least of ADAPT_REPEAT runs)
 * Times are the thread's CPU time (pd_cpu_seconds, as the runs report it). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "pd_bench.h"
#include "pd_problems.h"

#define ADAPT_ACC 1e-5 /* the one-wall comparison's accuracy */
#define ADAPT_NCASE 180
#define ADAPT_REPEAT 3 /* repetitions of a timed run: the least CPU time */

/* Run c with o (simulate: fixed steps, else pd_osc_run) ADAPT_REPEAT times
 * into r, its CPU time the least of theirs.  Returns the status. */
static int timed_run(const pd_osc *c, const pd_run_opts *o, int simulate, pd_osc_result *r,
                     pd_err *err)
{
    double best = HUGE_VAL;
    for (int k = 0; k < ADAPT_REPEAT; k++) {
        int rc = simulate ? pd_osc_simulate(c, o, NULL, NULL, r, err)
                          : pd_osc_run(c, o, NULL, NULL, r, err);
        if (rc)
            return rc;
        best = fmin(best, r->cpu_s);
    }
    r->cpu_s = best;
    return PD_OK;
}

/* The fixed-step run that reaches acc: dt halved from the default. */
static double fixed_cpu(const pd_osc *c, double umax_ref, double acc)
{
    pd_run_opts o = pd_run_default_opts();
    pd_osc_result r;
    pd_err err;
    o.method = PD_METHOD_MOREAU;
    o.no_demands = 1;
    for (o.dt = pd_osc_default_dt(c); o.dt > 1e-9; o.dt *= 0.5) {
        if (pd_osc_simulate(c, &o, NULL, NULL, &r, &err))
            return NAN;
        if (fabs(r.umax - umax_ref) <= acc * umax_ref)
            return timed_run(c, &o, 1, &r, &err) ? NAN : r.cpu_s;
    }
    return NAN;
}

typedef struct one_wall {
    double fixed_med, adapt_med, ratio_med;
    int within; /* adaptive runs within acc */
} one_wall;

static int bench_one_wall(one_wall *w)
{
    static double cf[ADAPT_NCASE], ca[ADAPT_NCASE], ratio[ADAPT_NCASE];
    const double pi2s[] = {0.3, 0.7, 1.5, 3.0, 6.0}, pi3s[] = {0.01, 0.1, 0.5},
                 epss[] = {0.0, 0.5, 0.9};
    int n = 0;
    w->within = 0;
    for (int p = 0; p < 2; p++)
        for (int d = 0; d < 2; d++)
            for (int a = 0; a < 5; a++)
                for (int b = 0; b < 3; b++)
                    for (int q = 0; q < 3; q++, n++) {
                        pd_osc c = pd_osc_default();
                        c.pulse = p ? PD_PULSE_COSINE : PD_PULSE_SINE;
                        c.dir = d ? -1 : 1;
                        c.Pi2 = pi2s[a];
                        c.Pi3 = pi3s[b];
                        c.eps = epss[q];
                        pd_run_opts o = pd_run_default_opts();
                        pd_osc_result ref, r;
                        pd_err err;
                        if (pd_osc_reference(&c, &o, NULL, NULL, &ref, &err))
                            return 1;
                        o.method = PD_METHOD_MOREAU;
                        o.rtol = ADAPT_ACC;
                        o.no_demands = 1;
                        if (timed_run(&c, &o, 0, &r, &err))
                            return 1;
                        w->within += fabs(r.umax - ref.umax) <= ADAPT_ACC * ref.umax;
                        cf[n] = fixed_cpu(&c, ref.umax, ADAPT_ACC);
                        ca[n] = r.cpu_s;
                        ratio[n] = cf[n] / ca[n];
                    }
    w->fixed_med = pd_bench_median(cf, n);
    w->adapt_med = pd_bench_median(ca, n);
    w->ratio_med = pd_bench_median(ratio, n);
    return 0;
}

/* A case of the points: the oscillator (sc NULL) or a scene. */
typedef struct adapt_case {
    const char *name;
    pd_scene *sc;
    pd_osc c;
} adapt_case;

#define ADAPT_NPOINT 5
static const double point_rtols[ADAPT_NPOINT] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6};

typedef struct point {
    double rtol, err, est, cpu;
    int met;
} point;

/* The error of umax against the exact reference and the CPU time of each
 * tolerance (the largest structure's error for a scene); nr: how many of
 * point_rtols to run (the row of 100 stops at 1e-3). */
static int bench_points(const adapt_case *k, int nr, point *pt, double *ref_cpu)
{
    pd_run_opts o = pd_run_default_opts();
    pd_err err;
    if (!k->sc) {
        pd_osc_result ref, r;
        if (pd_osc_reference(&k->c, &o, NULL, NULL, &ref, &err))
            return 1;
        *ref_cpu = ref.cpu_s;
        for (int j = 0; j < nr; j++) {
            o.method = PD_METHOD_MOREAU;
            o.rtol = point_rtols[j];
            if (pd_osc_run(&k->c, &o, NULL, NULL, &r, &err))
                return 1;
            pt[j] = (point){.rtol = o.rtol,
                            .err = fabs(r.umax - ref.umax) / ref.umax,
                            .est = r.err_est,
                            .cpu = r.cpu_s,
                            .met = r.rtol_met};
        }
        return 0;
    }
    pd_scene_result ref = {0}, r = {0};
    int rc = pd_scene_result_alloc(k->sc, &ref, &err) || pd_scene_result_alloc(k->sc, &r, &err);
    o.method = PD_METHOD_EVENT;
    rc = rc || pd_scene_run(k->sc, &o, NULL, NULL, &ref, &err);
    *ref_cpu = ref.cpu_s;
    for (int j = 0; j < nr && !rc; j++) {
        o.method = PD_METHOD_MOREAU;
        o.rtol = point_rtols[j];
        rc = pd_scene_run(k->sc, &o, NULL, NULL, &r, &err);
        double e = 0.0;
        for (int i = 0; i < k->sc->n && !rc; i++)
            e = fmax(e, fabs(r.umax[i] - ref.umax[i]) / ref.umax[i]);
        pt[j] = (point){
            .rtol = o.rtol, .err = e, .est = r.err_est_max, .cpu = r.cpu_s, .met = r.rtol_met};
    }
    if (rc)
        fprintf(stderr, "pound: bench --rtol: %s: %s\n", k->name, err.msg);
    pd_scene_result_free(&ref);
    pd_scene_result_free(&r);
    return rc;
}

/* The compressed cluster (docs/methods.md, "Moreau–Jean to a tolerance"). */
static pd_scene *cluster_scene(void)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_COSINE, .dir = 1, .ap = 4.18, .Tp = 0.89};
    pd_scene *sc = pd_scene_new(&x);
    if (!sc || pd_scene_add_sdof(sc, "S1", 0.234, 0.05, 3e5, NULL) ||
        pd_scene_add_sdof(sc, "S2", 1.36, 0.05, 3.3e5, NULL) ||
        pd_scene_add_sdof(sc, "S3", 0.81, 0.05, 2.1e5, NULL) ||
        pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, 0.0071, 0.08, 0, NULL) ||
        pd_scene_add_contact(sc, 0, 1, 1, 1, 0.005, 0.08, 1, NULL) ||
        pd_scene_add_contact(sc, 1, 1, 2, 1, 0.0246, 0.71, 2, NULL) || pd_scene_finish(sc, NULL)) {
        pd_scene_free(sc);
        return NULL;
    }
    sc->tend = 4.5;
    return sc;
}

/* The docs' rows (--chain N --pulse sine --Tp 1 --Pi3 0.05 --eps 0.6):
 * the oscillator's defaults otherwise, periods T0 and 1.5 T0. */
static pd_scene *docs_row(int N)
{
    pd_scene *sc = NULL;
    pd_osc c = pd_osc_default();
    c.pulse = PD_PULSE_SINE;
    c.Tp = 1.0;
    c.Pi3 = 0.05;
    c.eps = 0.6;
    pd_scene_excitation x = {.pulse = c.pulse, .dir = c.dir, .ap = c.ap, .Tp = c.Tp};
    if (pd_scene_chain(N, &x, pd_osc_T0(&c), 1.5, c.xi, pd_osc_gap(&c), c.eps, &sc, NULL))
        return NULL;
    return sc;
}

/* ns per DOF-step of --chain N to tend, at rtol (> 0) or at fixed dt: the
 * least of ADAPT_REPEAT runs. */
static double per_dof_step(int N, double tend, double rtol, double dt)
{
    pd_scene *sc = docs_row(N);
    pd_scene_result r = {0};
    pd_run_opts o = pd_run_default_opts();
    double ns = NAN;
    o.method = PD_METHOD_MOREAU;
    o.rtol = rtol;
    o.dt = dt;
    o.tend = tend;
    int ok = sc && !pd_scene_result_alloc(sc, &r, NULL);
    for (int k = 0; ok && k < ADAPT_REPEAT && !pd_scene_run(sc, &o, NULL, NULL, &r, NULL); k++)
        ns = fmin(k ? ns : HUGE_VAL, 1e9 * r.cpu_s / ((double)r.steps * sc->n));
    pd_scene_result_free(&r);
    pd_scene_free(sc);
    return ns;
}

int pd_bench_adapt(pd_json *js)
{
    one_wall w = {.fixed_med = NAN, .adapt_med = NAN, .ratio_med = NAN};
    enum { NCASE = 6 };
    adapt_case cases[NCASE] = {{.name = "one wall (sine, Pi2 1.5, Pi3 0.1, eps 0.5)"},
                               {.name = "row of 2 (examples/scenes/two-sdof.json)"},
                               {.name = "row of 10 (--chain 10)"},
                               {.name = "row of 100 (--chain 100)"},
                               {.name = "compressed cluster (3 SDOFs)"},
                               {.name = "record (Rinaldi, T0 0.8 s, gap 1 cm, eps 0.6)"}};
    point pts[NCASE][ADAPT_NPOINT];
    int npts[NCASE] = {5, 5, 5, 2, 4, 4}, rc = 0;
    double ref_cpu[NCASE] = {0};
    pd_record rec = {0};
    pd_record_pulse rp;
    cases[0].c = pd_osc_default();
    cases[0].c.Pi2 = 1.5;
    cases[0].c.Pi3 = 0.1;
    cases[0].c.eps = 0.5;
    pd_scene_load("examples/scenes/two-sdof.json", &cases[1].sc, NULL);
    cases[2].sc = docs_row(10);
    cases[3].sc = docs_row(100);
    cases[4].sc = cluster_scene();
    const char *rec_path = "examples/records/NGA_no_1063_RRS228.AT2";
    int have_rec = !access(rec_path, R_OK) &&
                   !pd_record_read(rec_path, PD_RECORD_AUTO, PD_UNITS_G, &rec, NULL) &&
                   !pd_record_fit_pulse(&rec, &rp, NULL);
    if (have_rec) {
        cases[5].c = pd_osc_default();
        pd_osc_set_record(&cases[5].c, &rec, &rp, 1.0);
        pd_osc_set_T0(&cases[5].c, 0.8);
        pd_osc_set_gap(&cases[5].c, 0.01);
        cases[5].c.eps = 0.6;
    }
    rc |= bench_one_wall(&w);
    for (int k = 0; k < NCASE; k++) {
        int absent = (k >= 1 && k <= 4 && !cases[k].sc) || (k == 5 && !have_rec);
        if (absent || bench_points(&cases[k], npts[k], pts[k], &ref_cpu[k]))
            npts[k] = 0;
    }
    double ns_adapt = per_dof_step(10000, 0.2, 1e-3, 0.0),
           ns_fixed = per_dof_step(10000, 0.2, 0.0, 0.0);
    if (js) {
        pd_json_begin_object(js, "rtol");
        pd_json_num(js, "one_wall_accuracy", ADAPT_ACC);
        pd_json_num(js, "one_wall_fixed_cpu_median", w.fixed_med);
        pd_json_num(js, "one_wall_adaptive_cpu_median", w.adapt_med);
        pd_json_num(js, "one_wall_ratio_of_medians", w.fixed_med / w.adapt_med);
        pd_json_num(js, "one_wall_median_ratio", w.ratio_med);
        pd_json_int(js, "one_wall_within", w.within);
        pd_json_begin_array(js, "points");
        for (int k = 0; k < NCASE; k++)
            for (int j = 0; j < npts[k]; j++) {
                pd_json_begin_object(js, NULL);
                pd_json_str(js, "case", cases[k].name);
                pd_json_num(js, "rtol", pts[k][j].rtol);
                pd_json_num(js, "err_umax", pts[k][j].err);
                pd_json_num(js, "err_est", pts[k][j].est);
                pd_json_bool(js, "rtol_met", pts[k][j].met);
                pd_json_num(js, "cpu_s", pts[k][j].cpu);
                pd_json_num(js, "cpu_s_ref", ref_cpu[k]);
                pd_json_end_object(js);
            }
        pd_json_end_array(js);
        pd_json_num(js, "chain_10000_ns_per_dof_step_rtol", ns_adapt);
        pd_json_num(js, "chain_10000_ns_per_dof_step_fixed", ns_fixed);
        pd_json_end_object(js);
    } else {
        printf("Moreau-Jean to a tolerance (one core, CPU time)\n");
        printf("  one wall, %d cases, umax to %g: fixed steps (dt halved from the default until "
               "there) median %.3g s, to rtol %g median %.3g s: ratio of medians %.2f, median "
               "ratio %.2f (goal >= 10); %d of %d adaptive runs within %g\n",
               ADAPT_NCASE, ADAPT_ACC, w.fixed_med, ADAPT_ACC, w.adapt_med,
               w.fixed_med / w.adapt_med, w.ratio_med, w.within, ADAPT_NCASE, ADAPT_ACC);
        printf("  %-48s %8s %10s %10s %5s %10s %10s\n", "case", "rtol", "err_umax", "err_est",
               "met", "cpu [s]", "ref [s]");
        for (int k = 0; k < NCASE; k++)
            for (int j = 0; j < npts[k]; j++)
                printf("  %-48s %8.0e %10.3g %10.3g %5s %10.4g %10.4g\n", j ? "" : cases[k].name,
                       pts[k][j].rtol, pts[k][j].err, pts[k][j].est, pts[k][j].met ? "yes" : "no",
                       pts[k][j].cpu, ref_cpu[k]);
        printf("  (goals: the compressed cluster within 1e-3 in < 2 s, the row of 100 within 1e-3 "
               "in < 20 s)\n");
        printf("  --chain 10000 to 0.2 s: %.1f ns per DOF-step to rtol 1e-3, %.1f at the default "
               "dt: %.2fx (goal <= 2x)\n",
               ns_adapt, ns_fixed, ns_adapt / ns_fixed);
    }
    for (int k = 0; k < NCASE; k++)
        pd_scene_free(cases[k].sc);
    if (have_rec)
        pd_record_free(&rec);
    return rc;
}
