/* cmd_simulate.c — `pound simulate`: one run of the pounding oscillator. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_oscillator.h"
#include "pd_output.h"

static const char simulate_usage[] =
    "usage: pound simulate [model flags] [--method moreau|event|penalty] [--dt H] [--theta T]\n"
    "                      [--tend T] [-o FILE.h5|FILE.csv] [--every K] [--json]\n"
    "  -o FILE  history t,u,v,impulse,gap (HDF5 or CSV by extension), --every K decimates\n"
    "  --json   one JSON object on stdout\n";

/* Everything the command line sets. */
typedef struct sim_args {
    pd_cli_case k;
    const char *out;
    long every;
    int json;
} sim_args;

/* Case flags, then the command's own; 0 or 2. */
static int parse_args(sim_args *a, int argc, char **argv)
{
    int rc, n;
    memset(a, 0, sizeof *a);
    pd_cli_case_init(&a->k);
    a->every = 1;
    for (int i = 1; i < argc; i++) {
        const char *f = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((rc = pd_cli_case_flag(&a->k, argc, argv, &i)) == 2)
            return 2;
        if (rc == 1)
            continue;
        if (!strcmp(f, "--json"))
            a->json = 1;
        else if (!strcmp(f, "-o")) {
            if (!val)
                return pd_cli_usage_error("-o needs a file name");
            a->out = val;
            i++;
        } else if (!strcmp(f, "--every")) {
            if ((rc = pd_cli_int(f, val, &n)))
                return rc;
            if (n < 1)
                return pd_cli_usage_error("--every: must be >= 1 (got %d)", n);
            a->every = n;
            i++;
        } else
            return pd_cli_usage_error("simulate: unknown flag '%s' (see pound simulate --help)", f);
    }
    pd_err err;
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    return pd_cli_case_finish(&a->k);
}

/* The recorded history, allocated once before the run. */
typedef struct history {
    long every, cap, rows;
    double *t, *u, *v, *impulse, *gap;
} history;

static int record(const pd_osc_sample *s, void *ctx)
{
    history *h = ctx;
    if (s->step % h->every || h->rows >= h->cap)
        return 0;
    h->t[h->rows] = s->t;
    h->u[h->rows] = s->u;
    h->v[h->rows] = s->v;
    h->impulse[h->rows] = s->impulse;
    h->gap[h->rows] = s->gap;
    h->rows++;
    return 0;
}

static void history_free(history *h)
{
    free(h->t);
    free(h->u);
    free(h->v);
    free(h->impulse);
    free(h->gap);
}

static int history_alloc(history *h, long nsteps, long every)
{
    memset(h, 0, sizeof *h);
    h->every = every;
    h->cap = nsteps / every + 1;
    h->t = malloc((size_t)h->cap * sizeof(double));
    h->u = malloc((size_t)h->cap * sizeof(double));
    h->v = malloc((size_t)h->cap * sizeof(double));
    h->impulse = malloc((size_t)h->cap * sizeof(double));
    h->gap = malloc((size_t)h->cap * sizeof(double));
    return h->t && h->u && h->v && h->impulse && h->gap ? 0 : -1;
}

/* Summary figures of a run and its no-wall twin. */
typedef struct summary {
    pd_osc_result r, free;
    double Pi1, gamma, chi, cpu_s;
} summary;

static void print_json(const sim_args *a, const summary *s)
{
    pd_json js;
    const pd_osc *c = &a->k.c;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    pd_json_str(&js, "method", pd_method_name(a->k.method));
    pd_json_num(&js, "umax", s->r.umax);
    pd_json_num(&js, "Pi1", s->Pi1);
    pd_json_num(&js, "u_toward", s->r.u_toward);
    pd_json_num(&js, "u_away", s->r.u_away);
    pd_json_int(&js, "impacts", s->r.impacts);
    pd_json_int(&js, "accumulations", s->r.accumulations);
    pd_json_num(&js, "first_impact", s->r.first_impact); /* NaN -> null */
    pd_json_num(&js, "first_impact_velocity", s->r.first_impact_velocity);
    pd_json_num(&js, "max_impact_velocity", s->r.max_impact_velocity);
    pd_json_num(&js, "contact_time", s->r.contact_time);
    pd_json_num(&js, "min_gap", s->r.min_gap);
    pd_json_num(&js, "umax_free", s->free.umax);
    pd_json_num(&js, "gamma", s->gamma);
    pd_json_num(&js, "chi", s->chi);
    pd_json_int(&js, "steps", s->r.steps);
    pd_json_num(&js, "cpu_s", s->cpu_s);
    pd_json_num(&js, "Pi2", c->Pi2);
    pd_json_num(&js, "Pi3", c->Pi3);
    pd_json_num(&js, "eps", c->eps);
    pd_json_num(&js, "xi", c->xi);
    pd_json_num(&js, "ap", c->ap);
    pd_json_num(&js, "Tp", c->Tp);
    pd_json_num(&js, "T0", pd_osc_T0(c));
    pd_json_num(&js, "gap", pd_osc_gap(c));
    pd_json_str(&js, "pulse", pd_pulse_name(c->pulse));
    pd_json_str(&js, "dir", pd_dir_name(c->dir));
    pd_json_num(&js, "dt", s->r.dt);
    pd_json_num(&js, "theta", s->r.theta);
    pd_json_num(&js, "gamma_active", s->r.gamma);
    pd_json_num(&js, "tend", s->r.tend);
    pd_json_str(&js, "kernel", s->r.kernel);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

static void print_text(const sim_args *a, const summary *s)
{
    const pd_osc *c = &a->k.c;
    printf("pounding oscillator, %s %s pulse: ap = %g m/s^2, Tp = %g s, T0 = %g s, "
           "gap = %g m, eps = %g, xi = %g\n",
           pd_dir_name(c->dir), pd_pulse_name(c->pulse), c->ap, c->Tp, pd_osc_T0(c),
           pd_osc_gap(c), c->eps, c->xi);
    if (a->k.method == PD_METHOD_MOREAU)
        printf("  Pi2 = %.6g  Pi3 = %.6g   Moreau-Jean theta = %g, dt = %.6g s, %ld steps to %g s\n",
               c->Pi2, c->Pi3, s->r.theta, s->r.dt, s->r.steps, s->r.tend);
    else
        printf("  Pi2 = %.6g  Pi3 = %.6g   %s (%s), %ld %s to %g s\n", c->Pi2, c->Pi3,
               a->k.method == PD_METHOD_EVENT ? "event-driven reference" : "penalty",
               s->r.kernel, s->r.steps, a->k.method == PD_METHOD_EVENT ? "events" : "steps",
               s->r.tend);
    printf("  umax      = %.6g m   (Pi1 = %.6g)\n", s->r.umax, s->Pi1);
    printf("  toward    = %.6g m,  away = %.6g m\n", s->r.u_toward, s->r.u_away);
    printf("  umax_free = %.6g m   gamma = umax/umax_free = %.4g,  chi = gap/umax_free = %.4g\n",
           s->free.umax, s->gamma, s->chi);
    if (s->r.impacts)
        printf("  impacts   = %ld, first at t = %.6g s (velocity %.4g m/s), contact time %.4g s\n",
               s->r.impacts, s->r.first_impact, s->r.first_impact_velocity, s->r.contact_time);
    else
        printf("  impacts   = 0 (the oscillator never reaches the wall)\n");
    printf("  cpu       = %.3g s\n", s->cpu_s);
}

/* Write the history and every input and summary figure. */
static int write_output(const sim_args *a, const summary *s, const history *h, pd_err *err)
{
    const pd_osc *c = &a->k.c;
    pd_column cols[] = {{"t", "s", h->t},
                        {"u", "m", h->u},
                        {"v", "m/s", h->v},
                        {"impulse", "m/s", h->impulse},
                        {"gap", "m", h->gap}};
    pd_attr attrs[] = {
        {"method", NULL, 1, 0, pd_method_name(a->k.method)},
        {"pulse", NULL, 1, 0, pd_pulse_name(c->pulse)},
        {"dir", NULL, 1, 0, pd_dir_name(c->dir)},
        {"ap", "m/s^2", 0, c->ap, NULL},
        {"Tp", "s", 0, c->Tp, NULL},
        {"T0", "s", 0, pd_osc_T0(c), NULL},
        {"gap", "m", 0, pd_osc_gap(c), NULL},
        {"eps", "1", 0, c->eps, NULL},
        {"xi", "1", 0, c->xi, NULL},
        {"Pi2", "1", 0, c->Pi2, NULL},
        {"Pi3", "1", 0, c->Pi3, NULL},
        {"dt", "s", 0, s->r.dt, NULL},
        {"theta", "1", 0, s->r.theta, NULL},
        {"tend", "s", 0, s->r.tend, NULL},
        {"every", "steps", 0, (double)a->every, NULL},
        {"umax", "m", 0, s->r.umax, NULL},
        {"Pi1", "1", 0, s->Pi1, NULL},
        {"u_toward", "m", 0, s->r.u_toward, NULL},
        {"u_away", "m", 0, s->r.u_away, NULL},
        {"impacts", "1", 0, (double)s->r.impacts, NULL},
        {"first_impact", "s", 0, s->r.first_impact, NULL},
        {"contact_time", "s", 0, s->r.contact_time, NULL},
        {"umax_free", "m", 0, s->free.umax, NULL},
        {"gamma", "1", 0, s->gamma, NULL},
        {"steps", "1", 0, (double)s->r.steps, NULL},
        {"cpu_s", "s", 0, s->cpu_s, NULL}};
    pd_table t = {h->rows, 5, cols, (int)(sizeof attrs / sizeof attrs[0]), attrs};
    return pd_output_write(a->out, &t, err);
}

int pd_cmd_simulate(int argc, char **argv)
{
    sim_args a;
    summary s;
    history hist;
    pd_err err;
    int rc, status = 0;
    if (pd_cli_help(argc, argv, simulate_usage, 1))
        return 0;
    if ((rc = parse_args(&a, argc, argv)))
        return rc;
    memset(&hist, 0, sizeof hist);
    if (a.out && history_alloc(&hist, pd_steps_for(a.k.opts.tend, a.k.opts.dt), a.every)) {
        history_free(&hist);
        fprintf(stderr, "pound: simulate: out of memory for the history (use --every)\n");
        return 1;
    }
    memset(&s, 0, sizeof s);
    double cpu0 = pd_cpu_seconds();
    pd_osc_opts free_opts = a.k.opts;
    free_opts.no_wall = 1;
    if ((rc = pd_cli_run(&a.k, a.k.method, &a.k.opts, a.out ? record : NULL, &hist, &s.r, &err)) ||
        (rc = pd_cli_run(&a.k, a.k.method, &free_opts, NULL, NULL, &s.free, &err))) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    s.cpu_s = pd_cpu_seconds() - cpu0;
    s.Pi1 = s.r.umax / pd_osc_Le(&a.k.c);
    s.gamma = s.free.umax > 0.0 ? s.r.umax / s.free.umax : NAN;
    s.chi = s.free.umax > 0.0 ? pd_osc_gap(&a.k.c) / s.free.umax : NAN;
    if (a.out && write_output(&a, &s, &hist, &err)) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = 1;
        goto done;
    }
    if (a.json)
        print_json(&a, &s);
    else
        print_text(&a, &s);
done:
    history_free(&hist);
    return status;
}
