/* suite.c — a suite of ground motions: the records a suite file lists, the
 * statistics engineers quote over a suite, each record's scale to a target
 * (PGA or the elastic Sa(T1)), and a stochastic near-fault record for the
 * suite that ships with pound.
 *
 *   suite file  one record a line: PATH [SCALE]; '#' starts a comment; a
 *               relative PATH is read from the suite file's folder
 *   statistics  over the finite values x_1 <= ... <= x_n: mean, median,
 *               16th and 84th percentiles, min, max; a percentile p is
 *               x at the position p (n - 1) between order statistics,
 *               linear between them (NumPy's default)
 *   Sa(T)       w^2 max |u| of the elastic oscillator (period T, damping
 *               xi) under the record from rest: the exact reference with
 *               no wall (exact flights of the piecewise-linear record,
 *               peaks inside a step included)
 *   synthetic   a Mavroeidis-Papageorgiou velocity pulse's acceleration
 *               plus Clough-Penzien filtered white noise under the
 *               Jennings-Housner-Tsai envelope (docs/records.md, "Suites") */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_null.h"
#include "pd_problems.h"

#define SUITE_LINE_MAX 4096

/* ---- the suite ------------------------------------------------------------- */

pd_suite *pd_suite_new(void)
{
    return calloc(1, sizeof(pd_suite));
}

void pd_suite_free(pd_suite *s)
{
    if (!s)
        return;
    for (int k = 0; k < s->n; k++)
        free(s->path[k]);
    free(s->path);
    free(s->scale);
    free(s);
}

int pd_suite_add(pd_suite *s, const char *path, double scale, pd_err *err)
{
    if (!s)
        return PD_NULL_ARG(err, "s");
    if (!path)
        return PD_NULL_ARG(err, "path");
    if (!(scale > 0.0) || !isfinite(scale))
        return pd_err_set(err, PD_EINVAL, "record %s: the scale must be > 0 (got %g)", path, scale);
    if (!*path)
        return pd_err_set(err, PD_EINVAL, "a record's path is empty");
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 8;
        char **p = realloc(s->path, (size_t)cap * sizeof *p);
        if (p)
            s->path = p;
        double *f = p ? realloc(s->scale, (size_t)cap * sizeof *f) : NULL;
        if (!f)
            return pd_err_set(err, PD_ENOMEM, "out of memory for a suite of %d records", cap);
        s->scale = f;
        s->cap = cap;
    }
    if (!(s->path[s->n] = malloc(strlen(path) + 1)))
        return pd_err_set(err, PD_ENOMEM, "out of memory for a suite's record path");
    strcpy(s->path[s->n], path);
    s->scale[s->n++] = scale;
    return PD_OK;
}

/* PATH [SCALE] of one line (its comment cut) into s, a relative PATH
 * after the first ndir bytes of dir (the suite file's folder and its
 * slash; 0: the working folder). */
static int suite_line(pd_suite *s, char *line, const char *file, int lineno, const char *dir,
                      size_t ndir, pd_err *err)
{
    char *hash = strchr(line, '#'), *tok[2] = {0};
    int ntok = 0;
    if (hash)
        *hash = '\0';
    for (char *p = strtok(line, " \t\r\n"); p; p = strtok(NULL, " \t\r\n")) {
        if (ntok == 2)
            return pd_err_set(err, PD_EINVAL, "%s:%d: expected PATH [SCALE], got more", file,
                              lineno);
        tok[ntok++] = p;
    }
    if (ntok == 0)
        return PD_OK;
    double scale = 1.0;
    if (ntok == 2) {
        char *end;
        errno = 0;
        scale = strtod(tok[1], &end);
        if (*end || errno || !(scale > 0.0) || !isfinite(scale))
            return pd_err_set(err, PD_EINVAL, "%s:%d: the scale '%s' is not a number > 0", file,
                              lineno, tok[1]);
    }
    char path[SUITE_LINE_MAX + 1024];
    if (tok[0][0] == '/') /* absolute */
        ndir = 0;
    snprintf(path, sizeof path, "%.*s%s", (int)ndir, dir, tok[0]);
    return pd_suite_add(s, path, scale, err);
}

int pd_suite_read(const char *file, pd_suite **out, pd_err *err)
{
    if (!file)
        return PD_NULL_ARG(err, "file");
    if (!out)
        return PD_NULL_ARG(err, "out");
    *out = NULL;
    FILE *f = fopen(file, "r");
    if (!f)
        return pd_err_set(err, PD_EINVAL, "%s: cannot open the suite file (%s)", file,
                          strerror(errno));
    pd_suite *s = pd_suite_new();
    const char *slash = strrchr(file, '/');
    size_t ndir = slash ? (size_t)(slash - file) + 1 : 0; /* "dir/" */
    char line[SUITE_LINE_MAX];
    int rc = s ? PD_OK : pd_err_set(err, PD_ENOMEM, "out of memory for a suite");
    for (int lineno = 1; !rc && fgets(line, sizeof line, f); lineno++) {
        if (!strchr(line, '\n') && !feof(f))
            rc = pd_err_set(err, PD_EINVAL, "%s:%d: a line longer than %d bytes", file, lineno,
                            SUITE_LINE_MAX - 2);
        else
            rc = suite_line(s, line, file, lineno, file, ndir, err);
    }
    if (!rc && ferror(f))
        rc = pd_err_set(err, PD_EINVAL, "%s: read error", file);
    fclose(f);
    if (!rc && s->n == 0)
        rc =
            pd_err_set(err, PD_EINVAL, "%s: the suite lists no record (PATH [SCALE] a line)", file);
    if (rc) {
        pd_suite_free(s);
        return rc;
    }
    *out = s;
    return PD_OK;
}

/* ---- statistics -------------------------------------------------------------- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The p-quantile of sorted x (n >= 1): linear between order statistics. */
static double quantile(const double *x, int n, double p)
{
    double pos = p * (n - 1);
    int lo = (int)floor(pos);
    if (lo >= n - 1)
        return x[n - 1];
    return x[lo] + (pos - lo) * (x[lo + 1] - x[lo]);
}

int pd_stats_of(const double *x, int n, pd_stats *st, pd_err *err)
{
    if (!st)
        return PD_NULL_ARG(err, "st");
    *st = (pd_stats){
        .n = 0, .mean = NAN, .median = NAN, .p16 = NAN, .p84 = NAN, .min = NAN, .max = NAN};
    if (n <= 0)
        return PD_OK;
    if (!x)
        return PD_NULL_ARG(err, "x");
    double *y = pd_malloc(n, sizeof *y), sum = 0.0;
    if (!y)
        return pd_err_set(err, PD_ENOMEM, "out of memory for the statistics of %d values", n);
    int m = 0;
    for (int k = 0; k < n; k++) /* the finite values, summed in their order */
        if (isfinite(x[k])) {
            y[m++] = x[k];
            sum += x[k];
        }
    if (m > 0) {
        qsort(y, (size_t)m, sizeof *y, cmp_double);
        *st = (pd_stats){.n = m,
                         .mean = sum / m,
                         .median = quantile(y, m, 0.5),
                         .p16 = quantile(y, m, 0.16),
                         .p84 = quantile(y, m, 0.84),
                         .min = y[0],
                         .max = y[m - 1]};
    }
    free(y);
    return PD_OK;
}

/* ---- a scene over a suite ------------------------------------------------------ */

enum { PEAK_UMAX, PEAK_DRIFT, PEAK_ACC, PEAK_SHEAR, PEAK_GAMMA, PEAK_DUCT, PEAK_FREE, PEAK_FIGS };

/* Figure f of dof i in run r. */
static double dof_peak(const pd_scene_summary *r, int i, int f)
{
    const double v[PEAK_FIGS] = {r->r.umax[i],      r->r.drift_ratio[i], r->r.acc_max[i],
                                 r->r.shear_max[i], r->gamma[i],         r->r.ductility[i],
                                 r->free.umax[i]};
    return v[f];
}

/* Figure f of structure S in run r: its largest storey's (NaN passed
 * over; none finite: 0, ductility NaN), the base shear storey 1's. */
static double structure_peak(const pd_structure *S, const pd_scene_summary *r, int f)
{
    double v = f == PEAK_DUCT ? NAN : 0.0;
    int top = f == PEAK_SHEAR ? S->dof + 1 : S->dof + S->storeys;
    for (int i = S->dof; i < top; i++) {
        double x = dof_peak(r, i, f);
        v = x > v || (isnan(v) && isfinite(x)) ? x : v;
    }
    return v;
}

/* The statistics of one set of peaks (a structure's, S, or dof's); col
 * holds run k's figure f in turn; umax (NULL: not kept): each run's umax. */
static int peaks_of(pd_suite_peaks *p, double *col, int n, const pd_structure *S, int dof,
                    const pd_scene_summary *runs, double *umax, pd_err *err)
{
    pd_stats *st[PEAK_FIGS] = {&p->umax,  &p->drift_ratio, &p->acc_max,  &p->shear_max,
                               &p->gamma, &p->ductility,   &p->umax_free};
    for (int f = 0; f < PEAK_FIGS; f++) {
        for (int k = 0; k < n; k++)
            col[k] = S ? structure_peak(S, &runs[k], f) : dof_peak(&runs[k], dof, f);
        if (f == PEAK_UMAX && umax)
            memcpy(umax, col, (size_t)n * sizeof *col);
        int rc = pd_stats_of(col, n, st[f], err);
        if (rc)
            return rc;
    }
    return PD_OK;
}

/* The share of runs whose required gap at contact c exceeds rule's. */
static double rule_share(const pd_scene_summary *runs, int n, int c, int q)
{
    int k, closed = 0;
    for (k = 0; k < n; k++) {
        const double *rule = q == 0   ? runs[k].rule_abs
                             : q == 1 ? runs[k].rule_srss
                                      : runs[k].rule_ddc;
        closed += runs[k].required_gap[c] > rule[c] * (1.0 + PD_SUITE_RULE_TOL);
    }
    return (double)closed / n;
}

/* Contact c's statistics over the runs. */
static int contact_of(pd_suite_contact *p, double *col, int n, int c, const pd_scene_summary *runs,
                      pd_err *err)
{
    pd_stats *st[9] = {&p->required_gap, &p->impacts,     &p->max_impulse,
                       &p->contact_time, &p->force_equiv, &p->force_max,
                       &p->rule_abs,     &p->rule_srss,   &p->rule_ddc};
    int hit = 0;
    for (int k = 0; k < n; k++)
        hit += runs[k].r.impacts[c] > 0;
    p->closed = (double)hit / n;
    for (int f = 0; f < 9; f++) {
        for (int k = 0; k < n; k++) {
            const pd_scene_result *r = &runs[k].r;
            const double v[9] = {
                runs[k].required_gap[c], (double)r->impacts[c], r->max_impulse[c],
                r->contact_time[c],      r->force_equiv[c],     r->force_max[c],
                runs[k].rule_abs[c],     runs[k].rule_srss[c],  runs[k].rule_ddc[c]};
            col[k] = v[f];
        }
        int rc = pd_stats_of(col, n, st[f], err);
        if (rc)
            return rc;
    }
    p->abs_closed = rule_share(runs, n, c, 0);
    p->srss_closed = rule_share(runs, n, c, 1);
    p->ddc_closed = rule_share(runs, n, c, 2);
    return PD_OK;
}

void pd_scene_suite_free(pd_scene_suite *s)
{
    if (!s)
        return;
    free(s->structure);
    free(s->storey);
    free(s->contact);
    free(s->structure_umax);
    *s = (pd_scene_suite){.n = 0};
}

int pd_scene_suite_stats(const pd_scene *sc, const pd_scene_summary *runs, int n,
                         pd_scene_suite *out, pd_err *err)
{
    if (!out)
        return PD_NULL_ARG(err, "out");
    *out = (pd_scene_suite){.n = 0};
    if (!sc)
        return PD_NULL_ARG(err, "sc");
    if (!runs)
        return PD_NULL_ARG(err, "runs");
    if (n < 1)
        return pd_err_set(err, PD_EINVAL, "a suite needs at least one run (got %d)", n);
    for (int k = 0; k < n; k++) {
        const pd_scene_summary *r = &runs[k];
        if (!pd_scene_result_fits(sc, &r->r) || !pd_scene_result_fits(sc, &r->free) || !r->gamma ||
            !r->required_gap || !r->rule_abs || !r->rule_srss || !r->rule_ddc)
            return pd_err_set(err, PD_EINVAL, "run %d is not a summary of this scene", k);
    }
    int rc = PD_OK;
    double *col = pd_malloc(n, sizeof *col);
    *out = (pd_scene_suite){.n = n,
                            .nstruct = sc->nstruct,
                            .ndof = sc->n,
                            .ncontact = sc->ncontact,
                            .structure = pd_calloc(sc->nstruct, sizeof *out->structure),
                            .storey = pd_calloc(sc->n, sizeof *out->storey),
                            .contact = pd_calloc(sc->ncontact, sizeof *out->contact),
                            .structure_umax = pd_calloc((long)sc->nstruct * n, sizeof(double))};
    if (!col || !out->structure || !out->storey || (sc->ncontact && !out->contact) ||
        !out->structure_umax) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for a suite of %d runs", n);
        goto done;
    }
    for (int s = 0; s < sc->nstruct && !rc; s++) /* each structure: its largest storey's */
        rc = peaks_of(&out->structure[s], col, n, &sc->st[s], 0, runs,
                      out->structure_umax + (size_t)s * n, err);
    for (int i = 0; i < sc->n && !rc; i++) /* each storey */
        rc = peaks_of(&out->storey[i], col, n, NULL, i, runs, NULL, err);
    for (int c = 0; c < sc->ncontact && !rc; c++)
        rc = contact_of(&out->contact[c], col, n, c, runs, err);
done:
    free(col);
    if (rc)
        pd_scene_suite_free(out);
    return rc;
}

/* ---- scaling ------------------------------------------------------------------ */

int pd_record_sa(const pd_record *rec, const pd_record_pulse *pulse, double T, double xi,
                 double *Sa, pd_err *err)
{
    if (!rec)
        return PD_NULL_ARG(err, "rec");
    if (!pulse)
        return PD_NULL_ARG(err, "pulse");
    if (!Sa)
        return PD_NULL_ARG(err, "Sa");
    *Sa = NAN;
    if (!(T > 0.0) || !isfinite(T))
        return pd_err_set(err, PD_EINVAL, "Sa(T): the period must be > 0 (got %g)", T);
    if (!(xi >= 0.0 && xi < 1.0))
        return pd_err_set(err, PD_EINVAL, "Sa(T): the damping ratio must be in [0, 1) (got %g)",
                          xi);
    /* the elastic oscillator under the record, exact: the reference, no wall */
    pd_osc c = pd_osc_default();
    pd_osc_set_record(&c, rec, pulse, 1.0);
    c.Pi2 = c.Tp / T;
    c.xi = xi;
    pd_run_opts o = pd_run_default_opts();
    o.no_wall = 1;
    o.no_demands = 1; /* umax alone (faster; the same umax) */
    pd_osc_result r;
    int rc = pd_osc_resolve_opts(&c, &o, &o, err);
    if (!rc)
        rc = pd_osc_reference(&c, &o, NULL, NULL, &r, err);
    if (rc)
        return rc;
    double w = PD_TWO_PI / T;
    *Sa = w * w * r.umax;
    return PD_OK;
}

int pd_record_scale_to(const pd_record *rec, const pd_record_pulse *pulse, pd_scale_target kind,
                       double value, double T1, double xi, double *scale, pd_err *err)
{
    if (!rec)
        return PD_NULL_ARG(err, "rec");
    if (!pulse)
        return PD_NULL_ARG(err, "pulse");
    if (!scale)
        return PD_NULL_ARG(err, "scale");
    *scale = 1.0;
    if (kind == PD_SCALE_NONE)
        return PD_OK;
    if (!(value > 0.0) || !isfinite(value))
        return pd_err_set(err, PD_EINVAL, "the scaling target must be > 0 m/s^2 (got %g)", value);
    double now = NAN; /* the record's PGA or Sa(T1) at scale 1 */
    int rc;
    if (kind == PD_SCALE_PGA) {
        pd_record_measures m;
        if ((rc = pd_record_measure(rec, &m, err)))
            return rc;
        now = m.pga;
    } else if (kind == PD_SCALE_SA) {
        if ((rc = pd_record_sa(rec, pulse, T1, xi, &now, err)))
            return rc;
    } else {
        return pd_err_set(err, PD_EINVAL, "unknown scaling target %d", (int)kind);
    }
    if (!(now > 0.0))
        return pd_err_set(err, PD_EINVAL, "%s: its %s is 0: it cannot be scaled to a target",
                          rec->name, kind == PD_SCALE_PGA ? "PGA" : "Sa(T1)");
    /* the response is linear in the record: scale = target / now */
    *scale = value / now;
    return PD_OK;
}

/* ---- a stochastic near-fault record ------------------------------------------ */

/* A standard normal deviate (Box-Muller on the stream *s). */
static double normal(uint64_t *s)
{
    double u1 = 0.5 * (pd_rand_pm1(s) + 1.0), u2 = 0.5 * (pd_rand_pm1(s) + 1.0);
    u1 = u1 > 0.0 ? u1 : 0x1p-53;
    return sqrt(-2.0 * log(u1)) * cos(PD_TWO_PI * u2);
}

/* The Clough-Penzien filters' state derivative for the white noise w:
 *   x'' + 2 zg wg x' + wg^2 x = -w,  a1 = -(2 zg wg x' + wg^2 x)
 *   y'' + 2 zf wf y' + wf^2 y = a1,   the motion y'' */
static void cp_rate(const pd_synth *p, const double s[4], double w, double d[4])
{
    double a1 = -(2.0 * p->zg * p->wg * s[1] + p->wg * p->wg * s[0]);
    d[0] = s[1];
    d[1] = a1 - w;
    d[2] = s[3];
    d[3] = a1 - 2.0 * p->zf * p->wf * s[3] - p->wf * p->wf * s[2];
}

/* Jennings-Housner-Tsai: (t / t1)^2 rising, 1 to t2, exp(-c (t - t2)) after. */
static double envelope(const pd_synth *p, double t)
{
    return t < p->t1 ? (t / p->t1) * (t / p->t1) : t <= p->t2 ? 1.0 : exp(-p->c * (t - p->t2));
}

int pd_record_synth(const pd_synth *p, const char *name, pd_record *rec, pd_err *err)
{
    if (!p)
        return PD_NULL_ARG(err, "p");
    if (!rec)
        return PD_NULL_ARG(err, "rec");
    memset(rec, 0, sizeof *rec);
    if (!(p->dt > 0.0 && p->duration > p->dt && p->duration / p->dt < 1e7) || !(p->Tp > 0.0) ||
        !(p->gamma > 1.0) || !(p->wg > 0.0 && p->wf > 0.0 && p->zg > 0.0 && p->zf > 0.0) ||
        !(p->S0 >= 0.0) || !(p->t1 > 0.0 && p->t2 >= p->t1 && p->c > 0.0))
        return pd_err_set(err, PD_EINVAL, "synthetic record: a parameter is out of range");
    long n = (long)floor(p->duration / p->dt + 0.5) + 1;
    double *acc = pd_malloc(n, sizeof *acc);
    if (!acc)
        return pd_err_set(err, PD_ENOMEM, "out of memory for a synthetic record of %ld samples", n);
    pd_record_pulse mp = {
        .vp = p->vp, .fp = 1.0 / p->Tp, .nu = p->nu, .gamma = p->gamma, .t0 = p->t0};
    uint64_t seed = (uint64_t)p->seed;
    double s[4] = {0.0, 0.0, 0.0, 0.0}, h = p->dt / 4.0, sd = sqrt(PD_TWO_PI * p->S0 / p->dt);
    for (long k = 0; k < n; k++) {
        double t = k * p->dt, d[4];
        /* the motion at t, the pulse's acceleration on it */
        cp_rate(p, s, 0.0, d);
        double a_pulse, v_pulse;
        pd_record_pulse_eval(&mp, t, &a_pulse, &v_pulse);
        acc[k] = envelope(p, t) * d[3] + a_pulse;
        /* the noise held over the sample step, four RK4 steps of dt / 4 */
        double w = sd * normal(&seed);
        for (int j = 0; j < 4; j++) {
            double k1[4], k2[4], k3[4], k4[4], y[4];
            cp_rate(p, s, w, k1);
            for (int i = 0; i < 4; i++)
                y[i] = s[i] + 0.5 * h * k1[i];
            cp_rate(p, y, w, k2);
            for (int i = 0; i < 4; i++)
                y[i] = s[i] + 0.5 * h * k2[i];
            cp_rate(p, y, w, k3);
            for (int i = 0; i < 4; i++)
                y[i] = s[i] + h * k3[i];
            cp_rate(p, y, w, k4);
            for (int i = 0; i < 4; i++)
                s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    int rc =
        pd_record_from_array(rec, name ? name : "synthetic", acc, n, p->dt, PD_UNITS_M_S2, err);
    free(acc);
    return rc;
}

/* The suite pound ships (examples/records/suite/): seven near-fault
 * motions, pulses of 0.6 to 3 s on firm-soil noise (Clough-Penzien: wg
 * 15 rad/s, zg 0.6, wf 1.5 rad/s, zf 0.6), 20 s at 0.01 s. */
/* clang-format off */
static const pd_synth shipped[] = { /* one record to two lines */
    {.duration = 20, .dt = 0.01, .vp = 0.90, .Tp = 0.6, .gamma = 2.0, .nu = 0.0, .t0 = 4.0,
     .S0 = 0.005, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 8, .c = 0.3, .seed = 101},
    {.duration = 20, .dt = 0.01, .vp = 0.80, .Tp = 0.9, .gamma = 1.8, .nu = 1.5708, .t0 = 5.0,
     .S0 = 0.012, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 8, .c = 0.3, .seed = 102},
    {.duration = 20, .dt = 0.01, .vp = 1.00, .Tp = 1.2, .gamma = 2.2, .nu = 3.1416, .t0 = 5.5,
     .S0 = 0.015, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 9, .c = 0.3, .seed = 103},
    {.duration = 20, .dt = 0.01, .vp = 0.70, .Tp = 1.5, .gamma = 2.5, .nu = -1.5708, .t0 = 6.0,
     .S0 = 0.010, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 9, .c = 0.3, .seed = 104},
    {.duration = 20, .dt = 0.01, .vp = 1.20, .Tp = 2.0, .gamma = 1.6, .nu = 0.5, .t0 = 6.5,
     .S0 = 0.020, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 10, .c = 0.25, .seed = 105},
    {.duration = 20, .dt = 0.01, .vp = 0.90, .Tp = 2.5, .gamma = 2.0, .nu = 2.0, .t0 = 7.0,
     .S0 = 0.012, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 10, .c = 0.25, .seed = 106},
    {.duration = 20, .dt = 0.01, .vp = 1.10, .Tp = 3.0, .gamma = 1.7, .nu = -0.8, .t0 = 8.0,
     .S0 = 0.015, .wg = 15, .zg = 0.6, .wf = 1.5, .zf = 0.6, .t1 = 2, .t2 = 10, .c = 0.25, .seed = 107},
};
/* clang-format on */

int pd_synth_shipped_count(void)
{
    return (int)(sizeof shipped / sizeof shipped[0]);
}

const pd_synth *pd_synth_shipped(int k)
{
    return k >= 0 && k < pd_synth_shipped_count() ? &shipped[k] : NULL;
}
