/* cmd_converge.c — `pound converge`: errors against the event-driven
 * reference and cost as dt shrinks (Moreau–Jean, one curve per theta) or as
 * the contact stiffness grows (penalty); the observed order between rows;
 * the work-precision chart. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_output.h"
#include "pd_plot.h"

static const char converge_usage[] =
    "usage: pound converge [model flags | --scene F.json | --chain N] --dt MAX:MIN:N\n"
    "                      [--methods moreau,moreau-rtol,penalty,newmark,event-general]\n"
    "                      [--theta LIST] [--rtols LIST] [--kcs LIST] [--plot FILE.png]\n"
    "                      [-o FILE] [--json]\n"
    "  --dt MAX:MIN:N  N step sizes, log-spaced from MAX down to MIN (Moreau-Jean rows)\n"
    "  --theta LIST    one Moreau-Jean curve per theta (default 0.5)\n"
    "  --methods LIST  the rows: moreau (per dt and theta), moreau-rtol (Moreau-Jean to a\n"
    "                  tolerance, per --rtols), newmark (per dt), penalty (per stiffness),\n"
    "                  event-general (scenes: the GSL-based general reference, one row)\n"
    "  --rtols LIST    moreau-rtol rows: tolerances (default 1e-2,1e-3,1e-4,1e-5,1e-6);\n"
    "                  default methods: moreau,moreau-rtol\n"
    "  --kcs LIST      penalty rows: stiffness multiples of w0^2 (default 1e2,1e3,1e4,1e5,1e6),\n"
    "                  measured on the finest dt grid\n"
    "  --plot F.png    error vs dt in F.png, error vs CPU time (work-precision) in F-work.png\n"
    "  -o FILE         the table as CSV or HDF5\n"
    "  --error hist|umax  the error charted and ordered: err_hist_linf (the history,\n"
    "                  default) or err_umax_rel (the peak, what a spectrum reads)\n"
    "  order = log(err_prev / err) / log(dt_prev / dt) on that error\n"
    "  scenes: the errors of the worst structure (per structure in --json)\n";

enum { MAX_LIST = 32, MAX_ROWS = 1024 };

typedef struct row {
    pd_method method;
    double theta, dt, kc, err_umax, err_hist, cpu_s, order;
    double rtol, err_est; /* moreau-rtol rows (else NaN) */
    long impacts, steps;
    const double *serr_umax, *serr_hist; /* scenes: per structure */
} row;

typedef struct conv_args {
    pd_cli_case k;
    double dt_max, dt_min;
    int ndt, ntheta, nkc, nrtol, want_moreau, want_rtol, want_penalty, want_general, want_newmark,
        json, have_dt_range;
    int use_umax;      /* --error umax: chart and order err_umax_rel */
    int methods_given; /* --methods given (else the default rows) */
    double thetas[MAX_LIST], kcs[MAX_LIST], rtols[MAX_LIST];
    const char *plot, *out;
} conv_args;

/* The next element of a comma-separated list at *p (cut at its comma, *p
 * moved past it; NULL after the last).  Empty elements are kept: "a,,b"
 * gives "a", "", "b". */
static char *next_element(char **p)
{
    char *tok = *p, *comma = tok ? strchr(tok, ',') : NULL;
    if (comma)
        *comma = '\0';
    *p = comma ? comma + 1 : NULL;
    return tok;
}

/* An empty k-th element (from 1) of the list text given to flag: 2. */
static int empty_element(const char *flag, const char *text, int k)
{
    return pd_cli_usage_error("%s: element %d of '%s' is empty", flag, k, text);
}

/* "a,b,c" -> up to MAX_LIST finite numbers; 0 or 2. */
static int parse_list(const char *flag, const char *text, double *x, int *n)
{
    char buf[512], *p = buf;
    *n = 0;
    if (!text || strlen(text) >= sizeof buf)
        return pd_cli_usage_error("%s needs a comma-separated list of numbers", flag);
    if (!text[0])
        return pd_cli_usage_error("%s: empty list", flag);
    strcpy(buf, text);
    for (char *tok; (tok = next_element(&p));) {
        if (*n >= MAX_LIST)
            return pd_cli_usage_error("%s: at most %d values", flag, MAX_LIST);
        if (!tok[0])
            return empty_element(flag, text, *n + 1);
        if (pd_cli_double(flag, tok, &x[*n]))
            return 2;
        (*n)++;
    }
    return 0;
}

/* "moreau,penalty,event-general" (any of them) into a; 0 or 2. */
static int parse_methods(conv_args *a, const char *text)
{
    char buf[128], *p = buf;
    if (!text || strlen(text) >= sizeof buf)
        return pd_cli_usage_error("--methods needs a list such as moreau,penalty");
    if (!text[0])
        return pd_cli_usage_error("--methods: give moreau, moreau-rtol, penalty, newmark, "
                                  "event-general (got '')");
    strcpy(buf, text);
    a->methods_given = 1;
    a->want_moreau = a->want_rtol = a->want_penalty = a->want_general = a->want_newmark = 0;
    for (int k = 1; p; k++) {
        char *tok = next_element(&p);
        if (!tok[0])
            return empty_element("--methods", text, k);
        if (!strcmp(tok, "moreau"))
            a->want_moreau = 1;
        else if (!strcmp(tok, "moreau-rtol"))
            a->want_rtol = 1;
        else if (!strcmp(tok, "penalty"))
            a->want_penalty = 1;
        else if (!strcmp(tok, "event-general"))
            a->want_general = 1;
        else if (!strcmp(tok, "newmark"))
            a->want_newmark = 1;
        else
            return pd_cli_usage_error("--methods: '%s' is not one of moreau, moreau-rtol, penalty, "
                                      "newmark, event-general",
                                      tok);
    }
    return 0;
}

/* "MAX:MIN:N" with MAX >= MIN > 0, N >= 2 (N = 1: MAX only). */
static int parse_range(conv_args *a, const char *text)
{
    char buf[256], *p1, *p2;
    if (!text || strlen(text) >= sizeof buf)
        return pd_cli_usage_error("--dt needs MAX:MIN:N");
    strcpy(buf, text);
    p1 = strchr(buf, ':');
    p2 = p1 ? strchr(p1 + 1, ':') : NULL;
    if (!p1 || !p2)
        return pd_cli_usage_error("--dt: '%s' is not MAX:MIN:N", text);
    *p1 = *p2 = '\0';
    if (pd_cli_double("--dt", buf, &a->dt_max) || pd_cli_double("--dt", p1 + 1, &a->dt_min) ||
        pd_cli_int("--dt", p2 + 1, &a->ndt))
        return 2;
    if (!(a->dt_min > 0.0) || a->dt_max < a->dt_min || a->ndt < 1 || a->ndt > 64)
        return pd_cli_usage_error("--dt: need MAX >= MIN > 0 and 1 <= N <= 64 (got %s)", text);
    if (a->ndt > 1 && !(a->dt_max > a->dt_min))
        return pd_cli_usage_error("--dt: MAX equals MIN: one step size is N = 1 (got %s)", text);
    a->have_dt_range = 1;
    return 0;
}

/* -o, --plot F.png and the F-work.png it implies name different files:
 * PD_OK or PD_EINVAL. */
static int check_outputs_distinct(const conv_args *a, pd_err *err)
{
    char work[4096] = "";
    size_t len = a->plot ? strlen(a->plot) : 0;
    if (a->plot && len < sizeof work - 16)
        snprintf(work, sizeof work, "%.*s-work.png", (int)(len - 4), a->plot);
    const char *flags[] = {"-o", "--plot", "--plot (work-precision chart)"};
    const char *paths[] = {a->out, a->plot, work[0] ? work : NULL};
    return pd_output_check_distinct(3, flags, paths, err);
}

static int parse_args(conv_args *a, int argc, char **argv)
{
    int rc;
    memset(a, 0, sizeof *a);
    pd_cli_case_init(&a->k);
    a->k.methods_listed = 1;
    a->want_moreau = a->want_rtol = 1;
    for (int i = 1; i < argc; i++) {
        const char *f = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(f, "--dt")) { /* a range here, not a single step */
            if ((rc = parse_range(a, val)))
                return rc;
            i++;
            continue;
        }
        if (!strcmp(f, "--theta")) {
            if ((rc = parse_list(f, val, a->thetas, &a->ntheta)))
                return rc;
            i++;
            continue;
        }
        if ((rc = pd_cli_case_flag(&a->k, argc, argv, &i)) == 2)
            return 2;
        if (rc == 1)
            continue;
        if (!strcmp(f, "--json"))
            a->json = 1;
        else if (!strcmp(f, "--error")) {
            if (!val || (strcmp(val, "hist") && strcmp(val, "umax")))
                return pd_cli_usage_error("--error: expected hist or umax");
            a->use_umax = !strcmp(val, "umax");
            i++;
        } else if (!strcmp(f, "--rtols")) {
            if ((rc = parse_list(f, val, a->rtols, &a->nrtol)))
                return rc;
            i++;
        } else if (!strcmp(f, "--kcs")) {
            if ((rc = parse_list(f, val, a->kcs, &a->nkc)))
                return rc;
            i++;
        } else if (!strcmp(f, "--methods")) {
            if ((rc = parse_methods(a, val)))
                return rc;
            i++;
        } else if (!strcmp(f, "--plot")) {
            if (!val)
                return pd_cli_usage_error("--plot needs a file name");
            a->plot = val;
            i++;
        } else if (!strcmp(f, "-o")) {
            if (!val)
                return pd_cli_usage_error("-o needs a file name");
            a->out = val;
            i++;
        } else
            return pd_cli_usage_error("converge: unknown flag '%s' (see pound converge --help)", f);
    }
    if (!a->have_dt_range)
        return pd_cli_usage_error("converge: --dt MAX:MIN:N is required");
    if (!a->ntheta) {
        a->thetas[0] = 0.5;
        a->ntheta = 1;
    }
    for (int t = 0; t < a->ntheta; t++)
        if (!(a->thetas[t] >= 0.5 && a->thetas[t] <= 1.0) && !a->k.opts.allow_unstable)
            return pd_cli_usage_error("--theta: %g is outside [1/2, 1] (add --allow-unstable)",
                                      a->thetas[t]);
    if (!a->nkc) {
        const double def[] = {1e2, 1e3, 1e4, 1e5, 1e6};
        memcpy(a->kcs, def, sizeof def);
        a->nkc = 5;
    }
    if (!a->nrtol) {
        const double def[] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
        memcpy(a->rtols, def, sizeof def);
        a->nrtol = 5;
    }
    for (int k = 0; k < a->nrtol; k++)
        if (!(a->rtols[k] >= PD_RTOL_MIN && a->rtols[k] < 1.0))
            return pd_cli_usage_error("--rtols: the tolerances must be in [%g, 1) (got %g)",
                                      PD_RTOL_MIN, a->rtols[k]);
    for (int k = 0; k < a->nkc; k++)
        if (!(a->kcs[k] > 0.0))
            return pd_cli_usage_error("--kcs: stiffness multiples must be > 0 (got %g)", a->kcs[k]);
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    pd_err err;
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (check_outputs_distinct(a, &err))
        return pd_cli_usage_error("%s", err.msg);
    a->k.have_dt = 1;
    a->k.opts.dt = a->dt_max;
    if ((rc = pd_cli_case_finish(&a->k)))
        return rc;
    if (a->k.have_rtol && !a->want_penalty)
        return pd_cli_usage_error("--rtol: in converge the penalty rows' integrator tolerance "
                                  "(--methods ...,penalty); Moreau-Jean to a tolerance: "
                                  "--methods moreau-rtol --rtols LIST");
    if (pd_osc_yields(&a->k.c)) { /* a yielding spring: fixed steps, Moreau-Jean's or Newmark's */
        if (a->methods_given && (a->want_rtol || a->want_penalty || a->want_general))
            return pd_cli_usage_error("--methods: a yielding oscillator converges by moreau and "
                                      "newmark (moreau-rtol, the adaptive penalty and "
                                      "event-general do not model yielding yet)");
        a->want_rtol = 0; /* the default rows: moreau */
    }
    if (a->want_general && !pd_cli_is_scene(&a->k))
        return pd_cli_usage_error("--methods: event-general is a reference for scenes (--scene, "
                                  "--chain); the oscillator's reference is exact");
    return 0;
}

/* The i-th of n log-spaced steps from dt_max down to dt_min. */
static double dt_at(const conv_args *a, int i)
{
    if (a->ndt == 1)
        return a->dt_max;
    return a->dt_max * pow(a->dt_min / a->dt_max, (double)i / (a->ndt - 1));
}

/* A reference and the runs measured against it: the oscillator's or a
 * scene's. */
typedef struct measurer {
    const pd_cli_case *k;
    pd_trace ref, work; /* oscillator */
    pd_osc_result rr;
    pd_scene *sc; /* scene */
    pd_scene_trace sref;
    pd_scene_result srr, sres;
    pd_scene_errors se;
    double *serr; /* rows x nstruct x 2: the per-structure errors of every row */
} measurer;

static void measurer_free(measurer *M)
{
    pd_trace_free(&M->ref);
    pd_trace_free(&M->work);
    pd_scene_trace_free(&M->sref);
    pd_scene_result_free(&M->srr);
    pd_scene_result_free(&M->sres);
    pd_scene_errors_free(&M->se);
    pd_scene_free(M->sc);
    free(M->serr);
}

/* Room for the grid of o (the finest, or the scenes' comparison grid). */
static int measurer_alloc(measurer *M, const pd_run_opts *o, int nrows, pd_err *err)
{
    int rc;
    if (!M->sc) {
        if (pd_trace_alloc(&M->ref, o) || pd_trace_alloc(&M->work, o))
            return pd_err_set(err, PD_ENOMEM, "out of memory for %ld grid points", M->ref.cap);
        return PD_OK;
    }
    if ((rc = pd_scene_trace_alloc(&M->sref, M->sc, o, err)) ||
        (rc = pd_scene_result_alloc(M->sc, &M->srr, err)) ||
        (rc = pd_scene_result_alloc(M->sc, &M->sres, err)) ||
        (rc = pd_scene_errors_alloc(M->sc, &M->se, err)))
        return rc;
    M->serr = malloc((size_t)nrows * (size_t)M->sc->nstruct * 2 * sizeof(double));
    return M->serr ? PD_OK : pd_err_set(err, PD_ENOMEM, "out of memory for the rows");
}

/* The reference on the grid of o; its cost in *cpu. */
static int measure_reference(measurer *M, const pd_run_opts *o, double *cpu, pd_err *err)
{
    int rc = M->sc ? pd_scene_measure_reference(M->sc, o, &M->sref, &M->srr, err)
                   : pd_measure_reference(&M->k->c, o, &M->ref, &M->rr, err);
    *cpu = fmax(*cpu, M->sc ? M->srr.cpu_s : M->rr.cpu_s);
    return rc;
}

/* A scene's method run once for ten steps of o, untimed, before its first
 * row: the libraries a run loads on first use (CHOLMOD and its BLAS, some
 * ms: cli/lazy.c) are not the method's cost. */
static int warm_up(measurer *M, const pd_run_opts *o, pd_err *err)
{
    if (!M->sc)
        return PD_OK;
    pd_run_opts w = *o;
    w.tend = 10.0 * (o->dt > 0.0 ? o->dt : pd_scene_default_dt(M->sc));
    w.no_demands = w.no_law_band = 1;
    return pd_scene_run(M->sc, &w, NULL, NULL, &M->sres, err);
}

/* Row r: the method of o measured against the reference. */
static int measure_row(measurer *M, const pd_run_opts *o, int r, row *out, pd_err *err)
{
    int rc;
    int tol = o->rtol > 0.0;
    *out = (row){.method = o->method,
                 .theta = o->method == PD_METHOD_MOREAU && !tol ? o->theta : NAN,
                 .dt = tol ? NAN : o->dt,
                 .rtol = tol ? o->rtol : NAN,
                 .err_est = NAN,
                 .kc = o->method == PD_METHOD_PENALTY || o->method == PD_METHOD_NEWMARK
                           ? o->pen.kc_mult
                           : NAN,
                 .order = NAN};
    if (!M->sc) {
        pd_measured m;
        if ((rc = pd_measure_run(&M->k->c, o, &M->ref, M->rr.umax, &M->work, &m, err)))
            return rc;
        out->err_umax = m.err_umax_rel;
        out->err_hist = m.err_hist_linf;
        out->cpu_s = m.r.cpu_s;
        out->impacts = m.r.impacts;
        out->steps = m.r.steps;
        out->err_est = tol ? m.r.err_est : NAN;
        return PD_OK;
    }
    if ((rc = pd_scene_measure_run(M->sc, o, &M->sref, &M->srr, &M->sres, &M->se, err)))
        return rc;
    int ns = M->sc->nstruct;
    double *eu = M->serr + (size_t)r * ns * 2, *eh = eu + ns;
    memcpy(eu, M->se.err_umax, (size_t)ns * sizeof(double));
    memcpy(eh, M->se.err_hist, (size_t)ns * sizeof(double));
    out->err_umax = M->se.err_umax_max;
    out->err_hist = M->se.err_hist_max;
    out->cpu_s = M->se.cpu_s;
    out->impacts = M->se.impacts;
    out->steps = M->sres.steps;
    out->err_est = tol ? M->sres.err_est_max : NAN;
    out->serr_umax = eu;
    out->serr_hist = eh;
    return PD_OK;
}

/* The error a row is charted and ordered by. */
static double row_error(const conv_args *a, const row *r)
{
    return a->use_umax ? r->err_umax : r->err_hist;
}

/* A scene's rows are compared with its reference on one grid, the coarsest
 * step of the range (every row resolves it; a row on another grid is
 * interpolated between its own steps) but at most CONVERGE_GRID_DEFAULTS
 * default steps (min(Tp, T0) / 200) and at least the finest: the
 * reference's sampling, closed-form flights of every dof at every row, cost
 * 4-7x the runs on the finest grid. */
#define CONVERGE_GRID_DEFAULTS 10.0
static double converge_grid(const conv_args *a, const pd_scene *sc)
{
    double cap = CONVERGE_GRID_DEFAULTS * pd_scene_default_dt(sc);
    return fmax(a->dt_min, fmin(a->dt_max, cap));
}

/* Rows: the reference (a scene's once, on the comparison grid; the
 * oscillator's on each row's grid, exact and cheap), then Moreau–Jean per dt
 * and theta, Newmark per dt, to a tolerance per rtol, penalty per stiffness
 * on the finest grid. */
static int compute_rows(conv_args *a, measurer *M, row *rows, int *nrows, double *ref_cpu,
                        pd_err *err)
{
    pd_run_opts o = a->k.opts;
    int rc, n = 0;
    /* scenes: the reference once, on the comparison grid (converge_grid) */
    int once = M->sc != NULL;
    o.dt = once ? converge_grid(a, M->sc) : a->dt_min;
    *ref_cpu = 0.0;
    if ((rc = measurer_alloc(M, &o, a->ndt * (a->ntheta + 1) + a->nrtol + a->nkc + 1, err)))
        goto done;
    if (once && (rc = measure_reference(M, &o, ref_cpu, err)))
        goto done;
    for (int i = 0; i < a->ndt && a->want_moreau; i++) {
        o.dt = dt_at(a, i);
        if (!once && (rc = measure_reference(M, &o, ref_cpu, err)))
            goto done;
        for (int t = 0; t < a->ntheta; t++, n++) {
            o.theta = a->thetas[t];
            o.method = PD_METHOD_MOREAU;
            if ((n == 0 && (rc = warm_up(M, &o, err))) ||
                (rc = measure_row(M, &o, n, &rows[n], err)))
                goto done;
        }
    }
    for (int i = 0; i < a->ndt && a->want_newmark; i++, n++) {
        /* the penalty elements (kc: --kc, else the method's default) on
         * Newmark's fixed steps dt */
        o.dt = dt_at(a, i);
        if (!once && (rc = measure_reference(M, &o, ref_cpu, err)))
            goto done;
        o.method = PD_METHOD_NEWMARK;
        if ((i == 0 && (rc = warm_up(M, &o, err))) || (rc = measure_row(M, &o, n, &rows[n], err)))
            goto done;
    }
    for (int k = 0; k < a->nrtol && a->want_rtol; k++, n++) {
        /* to a tolerance: measured on the finest grid */
        o.dt = a->dt_min;
        o.method = PD_METHOD_MOREAU;
        if (!once && k == 0 && (rc = measure_reference(M, &o, ref_cpu, err)))
            goto done;
        o.dt = 0.0;
        o.rtol = a->rtols[k];
        rc = k == 0 ? warm_up(M, &o, err) : PD_OK;
        if (!rc)
            rc = measure_row(M, &o, n, &rows[n], err);
        o.rtol = 0.0;
        if (rc)
            goto done;
    }
    if (a->want_penalty) {
        o.dt = a->dt_min;
        if (!once && (rc = measure_reference(M, &o, ref_cpu, err)))
            goto done;
        for (int k = 0; k < a->nkc; k++, n++) {
            o.method = PD_METHOD_PENALTY;
            o.pen.kc_mult = a->kcs[k];
            o.pen.kc_abs = 0.0;
            if ((k == 0 && (rc = warm_up(M, &o, err))) ||
                (rc = measure_row(M, &o, n, &rows[n], err)))
                goto done;
        }
    }
    if (a->want_general) { /* one more point: the GSL-based reference on the finest grid */
        o.dt = a->dt_min;
        o.method = PD_METHOD_EVENT_GENERAL;
        if (!once && (rc = measure_reference(M, &o, ref_cpu, err)))
            goto done;
        if ((rc = measure_row(M, &o, n, &rows[n], err)))
            goto done;
        n++;
    }
    /* observed order between successive Moreau–Jean rows of one theta, and
     * between successive Newmark rows */
    for (int r = 0; r < n; r++)
        for (int q = r - 1; q >= 0; q--)
            if ((rows[q].method == PD_METHOD_MOREAU && rows[r].method == PD_METHOD_MOREAU &&
                 isnan(rows[q].rtol) && isnan(rows[r].rtol) && rows[q].theta == rows[r].theta) ||
                (rows[q].method == PD_METHOD_NEWMARK && rows[r].method == PD_METHOD_NEWMARK)) {
                rows[r].order = log(row_error(a, &rows[q]) / row_error(a, &rows[r])) /
                                log(rows[q].dt / rows[r].dt);
                break;
            }
done:
    *nrows = n;
    return rc;
}

/* The case in words, for titles: the text's, or (chart) the chart's in
 * UTF-8 (Π₂, Π₃, ε; a record named as such, a chain as a chain). */
static void case_title(const conv_args *a, const measurer *M, int chart, char *buf, size_t cap)
{
    const pd_osc *c = &a->k.c;
    if (M->sc && (!chart || a->k.scene_path))
        snprintf(buf, cap, "scene %s (%d structures)", a->k.scene_path ? a->k.scene_path : "chain",
                 M->sc->nstruct);
    else if (M->sc && pd_osc_yields(c))
        snprintf(buf, cap,
                 "a row of %d yielding SDOFs between two walls (--chain, Piy = %.3g, "
                 "\u03b1 = %g)",
                 M->sc->nstruct, c->Piy, c->alpha);
    else if (M->sc)
        snprintf(buf, cap, "a row of %d SDOFs between two walls (--chain)", M->sc->nstruct);
    else if (!chart)
        snprintf(buf, cap, "%s %s pulse, Pi2 = %.3g, Pi3 = %.3g, eps = %g", pd_dir_name(c->dir),
                 pd_osc_excitation_name(c), c->Pi2, c->Pi3, c->eps);
    else
        snprintf(buf, cap, "%s %s%s, \u03a0\u2082 = %.3g, \u03a0\u2083 = %.3g, \u03b5 = %g",
                 c->record ? "record" : pd_dir_name(c->dir), pd_osc_excitation_name(c),
                 c->record ? "" : " pulse", c->Pi2, c->Pi3, c->eps);
}

static void print_rows(const conv_args *a, const measurer *M, const row *rows, int n,
                       double ref_cpu)
{
    char title[256];
    case_title(a, M, 0, title, sizeof title);
    if (a->json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_begin_array(&js, "rows");
        for (int r = 0; r < n; r++) {
            pd_json_begin_object(&js, NULL);
            pd_json_str(&js, "method", pd_method_name(rows[r].method)); /* rtol: its own */
            pd_json_num(&js, "theta", rows[r].theta);
            pd_json_num(&js, "dt", rows[r].dt);
            pd_json_num(&js, "rtol", rows[r].rtol);
            pd_json_num(&js, "err_est", rows[r].err_est);
            pd_json_num(&js, "kc", rows[r].kc);
            pd_json_num(&js, "err_umax_rel", rows[r].err_umax);
            pd_json_num(&js, "err_hist_linf", rows[r].err_hist);
            pd_json_num(&js, "cpu_s", rows[r].cpu_s);
            pd_json_num(&js, "order", rows[r].order);
            pd_json_int(&js, "impacts", rows[r].impacts);
            pd_json_int(&js, "steps", rows[r].steps);
            if (M->sc) {
                pd_json_begin_array(&js, "structures");
                for (int k = 0; k < M->sc->nstruct; k++) {
                    pd_json_begin_object(&js, NULL);
                    pd_json_str(&js, "name", M->sc->st[k].name);
                    pd_json_num(&js, "err_umax_rel", rows[r].serr_umax[k]);
                    pd_json_num(&js, "err_hist_linf", rows[r].serr_hist[k]);
                    pd_json_end_object(&js);
                }
                pd_json_end_array(&js);
            }
            pd_json_end_object(&js);
        }
        pd_json_end_array(&js);
        pd_json_num(&js, "cpu_s_ref", ref_cpu);
        if (M->sc) {
            long impacts = 0;
            for (int c = 0; c < M->sc->ncontact; c++)
                impacts += M->srr.impacts[c];
            pd_json_int(&js, "impacts_ref", impacts);
            pd_cli_ref_decisions_json(&js, &M->srr);
        }
        pd_json_end_object(&js);
        pd_json_finish(&js);
        return;
    }
    printf("%s; reference cost %.3g s\n", title, ref_cpu);
    if (M->sc)
        pd_cli_ref_decisions_text(stdout, &M->srr);
    printf("  %-13s %6s %11s %8s %8s %11s %11s %9s %10s %7s %8s\n", "method", "theta", "dt [s]",
           "rtol", "kc", "err_umax", "err_hist", "err_est", "cpu [s]", "order", "impacts");
    for (int r = 0; r < n; r++)
        printf("  %-13s %6.3g %11.4g %8.2g %8.3g %11.3g %11.3g %9.2g %10.3g %7.3f %8ld\n",
               isnan(rows[r].rtol) ? pd_method_name(rows[r].method) : "moreau-rtol", rows[r].theta,
               rows[r].dt, rows[r].rtol, rows[r].kc, rows[r].err_umax, rows[r].err_hist,
               rows[r].err_est, rows[r].cpu_s, rows[r].order, rows[r].impacts);
}

/* err_hist against dt (Moreau–Jean curves) and against CPU time (all). */
static int plot_rows(const conv_args *a, const measurer *M, const row *rows, int n, double ref_cpu,
                     pd_err *err)
{
    static double xs[2][MAX_LIST + 3][MAX_ROWS], ys[2][MAX_LIST + 3][MAX_ROWS];
    pd_curve by_dt[MAX_LIST + 1], by_cpu[MAX_LIST + 3];
    char labels[MAX_LIST + 3][64], work_png[4096];
    int ncurve = 0;
    for (int t = 0; t < a->ntheta && a->want_moreau; t++, ncurve++) {
        int m = 0;
        for (int r = 0; r < n; r++)
            if (rows[r].method == PD_METHOD_MOREAU && isnan(rows[r].rtol) &&
                rows[r].theta == a->thetas[t]) {
                xs[0][ncurve][m] = rows[r].dt;
                ys[0][ncurve][m] = row_error(a, &rows[r]);
                xs[1][ncurve][m] = rows[r].cpu_s;
                ys[1][ncurve][m] = row_error(a, &rows[r]);
                m++;
            }
        snprintf(labels[ncurve], sizeof labels[0], "Moreau\u2013Jean \u03b8 = %g", a->thetas[t]);
        by_dt[ncurve] =
            (pd_curve){.label = labels[ncurve], .n = m, .x = xs[0][ncurve], .y = ys[0][ncurve]};
        by_cpu[ncurve] =
            (pd_curve){.label = labels[ncurve], .n = m, .x = xs[1][ncurve], .y = ys[1][ncurve]};
    }
    if (a->want_newmark) {
        int m = 0;
        for (int r = 0; r < n; r++)
            if (rows[r].method == PD_METHOD_NEWMARK) {
                xs[0][ncurve][m] = rows[r].dt;
                ys[0][ncurve][m] = row_error(a, &rows[r]);
                xs[1][ncurve][m] = rows[r].cpu_s;
                ys[1][ncurve][m] = row_error(a, &rows[r]);
                m++;
            }
        snprintf(labels[ncurve], sizeof labels[0], "Newmark penalty");
        by_dt[ncurve] =
            (pd_curve){.label = labels[ncurve], .n = m, .x = xs[0][ncurve], .y = ys[0][ncurve]};
        by_cpu[ncurve] =
            (pd_curve){.label = labels[ncurve], .n = m, .x = xs[1][ncurve], .y = ys[1][ncurve]};
        ncurve++;
    }
    int nrt = 0; /* to a tolerance: a work-precision curve */
    if (a->want_rtol) {
        for (int r = 0; r < n; r++)
            if (!isnan(rows[r].rtol)) {
                xs[1][ncurve][nrt] = rows[r].cpu_s;
                ys[1][ncurve][nrt] = row_error(a, &rows[r]);
                nrt++;
            }
        snprintf(labels[ncurve], sizeof labels[0], "Moreau\u2013Jean to rtol %g \u2026 %g",
                 a->rtols[0], a->rtols[a->nrtol - 1]);
        by_cpu[ncurve] =
            (pd_curve){.label = labels[ncurve], .n = nrt, .x = xs[1][ncurve], .y = ys[1][ncurve]};
    }
    int npen = 0, cpen = ncurve + (nrt > 0);
    if (a->want_penalty) {
        for (int r = 0; r < n; r++)
            if (rows[r].method == PD_METHOD_PENALTY) {
                xs[1][cpen][npen] = rows[r].cpu_s;
                ys[1][cpen][npen] = row_error(a, &rows[r]);
                npen++;
            }
        snprintf(labels[cpen], sizeof labels[0], "penalty (kc = %g \u2026 %g \u03c9\u2080\u00b2)",
                 a->kcs[0], a->kcs[a->nkc - 1]);
        by_cpu[cpen] =
            (pd_curve){.label = labels[cpen], .n = npen, .x = xs[1][cpen], .y = ys[1][cpen]};
    }
    int ngen = 0;
    for (int r = 0; r < n && a->want_general; r++)
        if (rows[r].method == PD_METHOD_EVENT_GENERAL) {
            int c = cpen + (npen > 0);
            xs[1][c][0] = rows[r].cpu_s;
            ys[1][c][0] = row_error(a, &rows[r]);
            snprintf(labels[c], sizeof labels[0], "general reference (event-general, GSL)");
            by_cpu[c] = (pd_curve){
                .label = labels[c], .n = 1, .x = xs[1][c], .y = ys[1][c], .style = PD_CURVE_MARKER};
            ngen = 1;
        }
    char title[256];
    const char *ylabel =
        a->use_umax ? "|u_{max} - u_{max,ref}| / u_{max,ref}" : "max |u - u_{ref}| / u_{max,ref}";
    case_title(a, M, 1, title, sizeof title);
    pd_chart c1 = {.title = title,
                   .xlabel = "dt [s]",
                   .ylabel = ylabel,
                   .logx = 1,
                   .logy = 1,
                   .ncurves = ncurve,
                   .curves = by_dt,
                   .vline = NAN,
                   .slope_ref = 1.0};
    pd_chart c2 = {.title = title,
                   .xlabel = "CPU time per run [s]",
                   .ylabel = ylabel,
                   .logx = 1,
                   .logy = 1,
                   .ncurves = ncurve + (nrt > 0) + (npen > 0) + ngen,
                   .curves = by_cpu,
                   .vline = ref_cpu,
                   .vline_label = "event-driven reference"};
    size_t len = strlen(a->plot);
    snprintf(work_png, sizeof work_png, "%.*s-work.png", (int)(len - 4), a->plot);
    int rc = ncurve ? pd_plot(a->plot, &c1, err) : PD_OK; /* the dt chart: fixed steps */
    return rc ? rc : pd_plot(work_png, &c2, err);
}

/* The table as CSV or HDF5 columns (docs/formats.md, PD_FORMAT_CONVERGE);
 * the method is a coded column: its name in the CSV ("moreau", "penalty"),
 * its pd_method code in the HDF5 file with a "codes" attribute naming them.
 * The case as attributes: the oscillator's, or the scene's excitation. */
static int write_rows(const conv_args *a, const measurer *M, const row *rows, int n, double ref_cpu,
                      pd_err *err)
{
    enum { NC = 12 };
    static double col[NC][MAX_ROWS];
    const char *methods[] = {pd_method_name(PD_METHOD_MOREAU),
                             pd_method_name(PD_METHOD_EVENT),
                             pd_method_name(PD_METHOD_PENALTY),
                             pd_method_name(PD_METHOD_AUTO),
                             pd_method_name(PD_METHOD_EVENT_GENERAL),
                             pd_method_name(PD_METHOD_NEWMARK)}; /* by code, as in --json */
    char chain[64];
    for (int r = 0; r < n; r++) {
        double v[NC] = {
            (double)rows[r].method,  rows[r].theta,         rows[r].dt,    rows[r].kc,
            rows[r].err_umax,        rows[r].err_hist,      rows[r].cpu_s, rows[r].order,
            (double)rows[r].impacts, (double)rows[r].steps, rows[r].rtol,  rows[r].err_est};
        for (int c = 0; c < NC; c++)
            col[c][r] = v[c];
    }
    pd_column cols[NC] = {
        {.name = "method", .units = "1", .values = col[0], .labels = methods, .nlabels = 6},
        {.name = "theta", .units = "1", .values = col[1]},
        {.name = "dt", .units = "s", .values = col[2]},
        {.name = "kc", .units = "1", .values = col[3]}, /* a multiple of w0^2 */
        {.name = "err_umax_rel", .units = "1", .values = col[4]},
        {.name = "err_hist_linf", .units = "1", .values = col[5]},
        {.name = "cpu_s", .units = "s", .values = col[6]},
        {.name = "order", .units = "1", .values = col[7]},
        {.name = "impacts", .units = "1", .values = col[8]},
        {.name = "steps", .units = "1", .values = col[9]},
        {.name = "rtol", .units = "1", .values = col[10]}, /* moreau-rtol rows, else NaN */
        {.name = "err_est", .units = "1", .values = col[11]}};
#define NUM(nm, u, x)                                                                              \
    {                                                                                              \
        .name = nm, .units = u, .num = (x)                                                         \
    }
#define TXT(nm, x)                                                                                 \
    {                                                                                              \
        .name = nm, .is_text = 1, .text = (x)                                                      \
    }
    const pd_osc *c = &a->k.c;
    pd_attr osc[] = {TXT("error", a->use_umax ? "umax" : "hist"),
                     NUM("cpu_s_ref", "s", ref_cpu),
                     TXT("pulse", pd_osc_excitation_name(c)),
                     TXT("dir", pd_dir_name(c->dir)),
                     NUM("Pi2", "1", c->Pi2),
                     NUM("Pi3", "1", c->Pi3),
                     NUM("eps", "1", c->eps),
                     NUM("xi", "1", c->xi),
                     NUM("ap", "m/s^2", c->ap),
                     NUM("Tp", "s", c->Tp)};
    const pd_scene_excitation *x = M->sc ? &M->sc->exc : NULL;
    snprintf(chain, sizeof chain, "chain of %d", a->k.chain);
    pd_attr scene[] = {TXT("error", a->use_umax ? "umax" : "hist"),
                       NUM("cpu_s_ref", "s", ref_cpu),
                       TXT("scene", a->k.scene_path ? a->k.scene_path : chain),
                       NUM("structures", "1", M->sc ? M->sc->nstruct : 0),
                       TXT("pulse", !x          ? ""
                                    : x->record ? x->record->name
                                                : pd_pulse_name(x->pulse)),
                       TXT("dir", x && x->dir < 0 ? "-x" : "+x"),
                       NUM("ap", "m/s^2", x ? x->ap : 0.0),
                       NUM("Tp", "s", x ? x->Tp : 0.0)};
#undef NUM
#undef TXT
    pd_table t = {.rows = n,
                  .ncols = NC,
                  .cols = cols,
                  .nattrs = M->sc ? (int)(sizeof scene / sizeof scene[0])
                                  : (int)(sizeof osc / sizeof osc[0]),
                  .attrs = M->sc ? scene : osc,
                  .dim = "row"};
    return pd_output_write(a->out, &t, err);
}

int pd_cmd_converge(int argc, char **argv)
{
    static conv_args a;
    static row rows[MAX_ROWS];
    measurer M;
    int n = 0, rc, status = 0;
    double ref_cpu = 0.0;
    pd_err err;
    if (pd_cli_help(argc, argv, converge_usage, 1))
        return 0;
    if ((rc = parse_args(&a, argc, argv)))
        return rc;
    pd_provenance_set(argc, argv, PD_FORMAT_CONVERGE, 0);
    if (a.ndt * (a.ntheta + 1) + a.nrtol + a.nkc + 1 > MAX_ROWS) {
        pd_cli_case_free(&a.k);
        return pd_cli_usage_error("converge: too many rows (at most %d)", MAX_ROWS);
    }
    memset(&M, 0, sizeof M);
    M.k = &a.k;
    if (pd_cli_is_scene(&a.k) && (status = pd_cli_scene(&a.k, &M.sc)))
        return status;
    if ((rc = compute_rows(&a, &M, rows, &n, &ref_cpu, &err))) {
        fprintf(stderr, "pound: converge: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
    } else if ((a.plot && plot_rows(&a, &M, rows, n, ref_cpu, &err)) ||
               (a.out && write_rows(&a, &M, rows, n, ref_cpu, &err))) {
        fprintf(stderr, "pound: converge: %s\n", err.msg);
        status = 1;
    } else
        print_rows(&a, &M, rows, n, ref_cpu);
    measurer_free(&M);
    pd_cli_case_free(&a.k);
    return status;
}
