/* cmd_simulate.c — `pound simulate`: one run of the pounding oscillator or
 * of a scene (a row of structures), with its contact-free twin, printed and
 * optionally written and drawn. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_cli.h"
#include "pd_journal.h"
#include "pd_lcp_dump.h"
#include "pd_output.h"
#include "pd_scene_out.h"
#include "pd_spectrum.h"

static const char simulate_usage[] =
    "usage: pound simulate [model flags | --scene F.json | --chain N] [--method M]\n"
    "                      [--dt H] [--theta T] [--tend T] [-o FILE.h5|FILE.csv] [--every K]\n"
    "                      [--plot FILE.png] [--dump-lcp F.h5] [--json]\n"
    "  -o FILE     the histories (HDF5 or CSV by extension), every input and result as\n"
    "              attributes with units; --every K keeps every K-th step\n"
    "              oscillator: t, u, v, impulse, gap; scene: t, x and v per structure and\n"
    "              storey, gap and impulse per contact (docs/scenes.md)\n"
    "              The rows are streamed to FILE.tmpPID as the run goes (memory stays\n"
    "              bounded), renamed to FILE when complete (its mode kept; a symlink's\n"
    "              target replaced).  Before the run: FILE must be writable, an output\n"
    "              estimated above 100 MB is announced on stderr (\"pound: writing about\n"
    "              N MB to FILE\"), and one larger than the free space of FILE's file\n"
    "              system is refused (exit 2; fewer rows with --every K)\n"
    "  --plot F    the displacement histories, every wall drawn where it stands, each\n"
    "              impact marked once at the storey of its contact\n"
    "  --dump-lcp F.h5  every contact LCP Moreau-Jean solves (D, b, z, solver, pivots or\n"
    "              iterations), for `pound lcp F.h5 --all` (docs/lcp.md)\n"
    "  --json      one JSON object on stdout\n"
    "suites of records (docs/records.md, \"Suites\"):\n"
    "  --records F  every record a suite file lists (PATH [SCALE] a line, '#' comments;\n"
    "              paths from F's folder), or --record given twice or more: each record\n"
    "              replaces the oscillator's or the scene's excitation; per record what a\n"
    "              single run prints (JSON \"records\"), then the suite's mean, median,\n"
    "              16th/84th percentiles and max of every peak (\"stats\"); for scenes per\n"
    "              contact how often it closed and how often each code rule's gap would\n"
    "              have (the exact required gap beyond ABS, SRSS, DDC); -o FILE.EXT and\n"
    "              --plot F.png write each record's as FILE.recK.EXT (K from 1)\n"
    "  --threads K  records at once (OpenMP; one at a time with -o or --plot)\n"
    "              [OMP_NUM_THREADS or all cores]; the numbers do not depend on K; the MPI\n"
    "              build shares the records out over mpirun's ranks\n"
    "  --journal F  each finished record's results appended to F (removed when the suite\n"
    "              is printed, or when a record fails on its input or computation)\n"
    "  --resume    continue an interrupted suite from its --journal F (the same flags):\n"
    "              the records F holds are read back to the bit, the others run\n";

/* Everything the command line sets. */
typedef struct sim_args {
    pd_cli_case k;
    const char *out, *plot, *dump;
    long every;
    int json;
    int threads; /* --threads: a suite's records at once (0: OpenMP's default) */
    /* a suite's journal and ranks */
    const char *journal; /* --journal F: the finished records */
    int resume;          /* --resume: continue from F */
    long stop_after;     /* --stop-after K: the test hook (exit 130 after K records) */
    int rank, size;      /* MPI (1 rank in the plain build) */
    char *key;           /* the suite's journal key (suite_key) */
} sim_args;

/* Record k's file of a suite: PATH with ".recK" (K from 1) before its
 * extension ("out.h5" -> "out.rec1.h5"), or at its end: 0, or -1 when it
 * does not fit in cap. */
static int suite_path(const char *path, int k, char *buf, size_t cap)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    if (!dot || (slash && dot < slash) || dot == (slash ? slash + 1 : path))
        dot = path + strlen(path); /* no extension (or a hidden file's dot) */
    int n = snprintf(buf, cap, "%.*s.rec%d%s", (int)(dot - path), path, k + 1, dot);
    return n < 0 || (size_t)n >= cap ? -1 : 0;
}

/* Case flags, then the command's own; 0 or 2. */
static int parse_args(sim_args *a, int argc, char **argv)
{
    int rc, n;
    pd_err err;
    memset(a, 0, sizeof *a);
    pd_cli_case_init(&a->k);
    a->k.suites_by = "simulate";
    a->every = 1;
    for (int i = 1; i < argc; i++) {
        const char *f = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((rc = pd_cli_case_flag(&a->k, argc, argv, &i)) == 2)
            return 2;
        if (rc == 1)
            continue;
        if (!strcmp(f, "--json"))
            a->json = 1;
        else if (!strcmp(f, "-o") || !strcmp(f, "--plot") || !strcmp(f, "--dump-lcp")) {
            if (!val)
                return pd_cli_usage_error("%s needs a file name", f);
            *(!strcmp(f, "-o") ? &a->out : !strcmp(f, "--plot") ? &a->plot : &a->dump) = val;
            if (!strcmp(f, "--dump-lcp"))
                pd_cli_case_implies(&a->k, f, PD_METHOD_MOREAU);
            i++;
        } else if (!strcmp(f, "--threads")) {
            if ((rc = pd_cli_int(f, val, &n)))
                return rc;
            if (n < 1 || n > 4096)
                return pd_cli_usage_error("--threads: must be in [1, 4096] (got %d)", n);
            a->threads = n;
            i++;
        } else if (!strcmp(f, "--journal")) {
            if (!val)
                return pd_cli_usage_error("--journal needs a file name");
            a->journal = val;
            i++;
        } else if (!strcmp(f, "--resume"))
            a->resume = 1;
        else if (!strcmp(f, "--stop-after")) { /* test hook: die after K finished records */
            if ((rc = pd_cli_int(f, val, &n)))
                return rc;
            if (n < 1)
                return pd_cli_usage_error("--stop-after: must be >= 1 (got %d)", n);
            a->stop_after = n;
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
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    if (a->plot && pd_output_check_writable("--plot", a->plot, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (a->dump && (strlen(a->dump) < 4 || strcmp(a->dump + strlen(a->dump) - 3, ".h5")))
        return pd_cli_usage_error("--dump-lcp: '%s' must end in .h5", a->dump);
    if (a->dump && pd_output_check_writable("--dump-lcp", a->dump, &err))
        return pd_cli_usage_error("%s", err.msg);
    const char *flags[] = {"-o", "--plot", "--dump-lcp", "--journal"},
               *paths[] = {a->out, a->plot, a->dump, a->journal};
    if (pd_output_check_distinct(4, flags, paths, &err))
        return pd_cli_usage_error("%s", err.msg);
    if ((a->resume || a->stop_after) && !a->journal)
        return pd_cli_usage_error("%s needs --journal F (the suite's finished records)",
                                  a->resume ? "--resume" : "--stop-after");
    if (a->journal && pd_output_check_writable("--journal", a->journal, &err))
        return pd_cli_usage_error("%s", err.msg);
    if ((rc = pd_cli_case_finish(&a->k)))
        return rc;
    if (a->journal && !pd_cli_case_is_suite(&a->k)) {
        pd_cli_case_free(&a->k);
        return pd_cli_usage_error("--journal: the journal of a suite (--records F, or --record "
                                  "given twice or more)");
    }
    if (pd_cli_case_is_suite(&a->k) && a->dump) {
        pd_cli_case_free(&a->k);
        return pd_cli_usage_error("--dump-lcp: the LCPs of one run (--record F), not of a suite");
    }
    for (int k = 0; pd_cli_case_is_suite(&a->k) && k < a->k.suite->n; k++) {
        char out[PD_PATH_MAX], plot[PD_PATH_MAX];
        const char *flag = NULL;
        if (a->out && suite_path(a->out, k, out, sizeof out))
            flag = "-o";
        else if (a->plot && suite_path(a->plot, k, plot, sizeof plot))
            flag = "--plot";
        else if ((a->out && pd_output_check_writable("-o", out, &err)) ||
                 (a->plot && pd_output_check_writable("--plot", plot, &err))) {
            pd_cli_case_free(&a->k);
            return pd_cli_usage_error("%s", err.msg);
        }
        const char *rflags[] = {"-o (a record's file)", "--plot (a record's chart)", "--journal"},
                   *rpaths[] = {a->out ? out : NULL, a->plot ? plot : NULL, a->journal};
        if (!flag && pd_output_check_distinct(3, rflags, rpaths, &err)) {
            pd_cli_case_free(&a->k);
            return pd_cli_usage_error("%s", err.msg);
        }
        if (flag) {
            pd_cli_case_free(&a->k);
            return pd_cli_usage_error("%s: the path is too long for a suite's record files", flag);
        }
    }
    if (a->dump && a->k.opts.method != PD_METHOD_MOREAU) {
        pd_cli_case_free(&a->k);
        return pd_cli_usage_error(
            "--dump-lcp: the LCPs dumped are Moreau-Jean's (--method moreau)");
    }
    return 0;
}

/* About how many bytes -o writes for rows of width values (CSV: %.17g
 * text, some 23 bytes a value). */
static double output_bytes(const char *path, long rows, int width)
{
    size_t n = strlen(path);
    int csv = n > 4 && !strcmp(path + n - 4, ".csv");
    return 8192.0 + (double)rows * width * (csv ? 23.0 : 8.0);
}

/* Before the run: refuse an output larger than the space free for it,
 * announce a large one; 0 or 2. */
static int check_output_size(const char *path, double bytes)
{
    pd_err err;
    if (pd_output_check_room("-o", path, bytes, &err))
        return pd_cli_usage_error("%s (--every K keeps every K-th step)", err.msg);
    if (bytes >= PD_OUTPUT_NOTICE_MB * 1e6)
        fprintf(stderr, "pound: writing about %.0f MB to %s\n", bytes / 1e6, path);
    return 0;
}

/* --dump-lcp: open the dump and hook it on the run's options; 0 or 1. */
static int dump_open(const sim_args *a, pd_lcp_dump **d, pd_run_opts *run)
{
    pd_err err;
    *d = NULL;
    if (!a->dump)
        return 0;
    if (pd_lcp_dump_open(d, a->dump, &err)) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        return 1;
    }
    run->on_lcp = pd_lcp_dump_add;
    run->on_lcp_ctx = *d;
    return 0;
}

/* --dump-lcp: the dump into place; 0 or 1. */
static int dump_finish(pd_lcp_dump *d)
{
    pd_err err;
    if (d && pd_lcp_dump_finish(d, &err)) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        return 1;
    }
    return 0;
}

/* ==== the oscillator ======================================================== */

/* Where the oscillator's samples go: the file (every every-th step, at most
 * rows_max rows) and the chart. */
typedef struct osc_out {
    const pd_osc *c; /* the oscillator (its spring's force in the rows) */
    long every, rows, rows_max;
    pd_table_writer *file;
    pd_scene_plot *plot; /* --plot: the same samples as a one-structure scene */
} osc_out;

/* The oscillator's columns. */
static const pd_column osc_cols[] = {{.name = "t", .units = "s"},
                                     {.name = "u", .units = "m"},
                                     {.name = "v", .units = "m/s"},
                                     {.name = "impulse", .units = "m/s"},
                                     {.name = "gap", .units = "m"},
                                     /* a yielding oscillator's (osc_ncols) */
                                     {.name = "up", .units = "m"},
                                     {.name = "spring_force", .units = "N/kg"}};
enum { OSC_COLS = sizeof osc_cols / sizeof osc_cols[0], OSC_YIELD_COLS = 2 };

/* The oscillator's columns: the yielding ones for a yielding oscillator only. */
static int osc_ncols(const pd_osc *c)
{
    return pd_osc_yields(c) ? OSC_COLS : OSC_COLS - OSC_YIELD_COLS;
}

/* A pd_osc_sampler: a row to the file, a point to the chart; a failed write
 * stops the run. */
static int record(const pd_osc_sample *s, void *ctx)
{
    osc_out *o = ctx;
    if (o->plot) {
        pd_scene_sample ss = {.step = s->step,
                              .t = s->t,
                              .x = &s->u,
                              .v = &s->v,
                              .gap = &s->gap,
                              .impulse = &s->impulse,
                              .impacts = &s->impacts};
        pd_scene_plot_sample(&ss, o->plot);
    }
    if (!o->file || s->step % o->every || o->rows >= o->rows_max)
        return 0;
    double w0 = PD_TWO_PI / pd_osc_T0(o->c); /* the spring's force w0^2 (u - (1 - alpha) up) */
    double row[OSC_COLS] = {s->t,
                            s->u,
                            s->v,
                            s->impulse,
                            s->gap,
                            s->up,
                            w0 * w0 * (s->u - (1.0 - o->c->alpha) * s->up)};
    o->rows++;
    return pd_table_row(o->file, row) ? 1 : 0;
}

/* Which method ran, and why. */
static void method_line(const pd_cli_case *k)
{
    const char *m = pd_method_name(k->opts.method);
    if (k->method_by)
        printf("  method    = %s (%s)\n", m, k->method_by);
    else if (pd_osc_yields(&k->c) && !pd_osc_yield_exact(&k->c))
        printf("  method    = %s (the exact reference does not model this yielding spring: its "
               "sliding phase is overdamped, 0 < alpha <= xi^2)\n",
               m);
    else if (pd_cli_is_scene(k))
        printf("  method    = %s (the default for scenes; --method event|penalty|newmark for "
               "the others)\n",
               m);
    else
        printf("  method    = %s (the default for one oscillator: %s; --method moreau|event|"
               "penalty|newmark chooses)\n",
               m,
               k->opts.method == PD_METHOD_EVENT ? "exact and fastest"
                                                 : "the exact reference's scan is over budget");
}

/* A yielding run's energy balance as JSON keys energy_* (NaN -> null), the
 * hysteretic term among them when asked (the oscillator reports it as
 * hysteretic_energy). */
static void energy_json(pd_json *js, const pd_energy *en, int hysteretic)
{
    pd_json_num(js, "energy_input", en->input);
    pd_json_num(js, "energy_kinetic", en->kinetic);
    pd_json_num(js, "energy_strain", en->strain);
    pd_json_num(js, "energy_damping", en->damping);
    if (hysteretic)
        pd_json_num(js, "energy_hysteretic", en->hysteretic);
    pd_json_num(js, "energy_impact", en->impact);
    pd_json_num(js, "energy_residual", en->residual);
}

/* The run of oscillator c by method into js as one object. */
static void osc_json(pd_json *js, const sim_args *a, const pd_osc *c, pd_method method,
                     const pd_osc_summary *s)
{
    pd_json_begin_object(js, NULL);
    pd_json_str(js, "method", pd_method_name(method));
    pd_json_str(js, "method_by", pd_cli_method_by(&a->k));
    pd_json_num(js, "umax", s->r.umax);
    pd_json_num(js, "Pi1", s->Pi1);
    pd_json_num(js, "u_toward", s->r.u_toward);
    pd_json_num(js, "u_away", s->r.u_away);
    pd_json_int(js, "impacts", s->r.impacts);
    pd_json_int(js, "accumulations", s->r.accumulations);
    pd_json_num(js, "first_impact", s->r.first_impact); /* NaN -> null */
    pd_json_num(js, "first_impact_velocity", s->r.first_impact_velocity);
    pd_json_num(js, "max_impact_velocity", s->r.max_impact_velocity);
    pd_json_num(js, "max_impulse", s->r.max_impulse);
    pd_json_num(js, "contact_time", s->r.contact_time);
    pd_json_num(js, "min_gap", s->r.min_gap);
    /* demands, per unit mass (docs/scenes.md, "Demands") */
    pd_json_num(js, "height", a->k.height);
    pd_json_num(js, "drift_ratio", s->r.umax / a->k.height);
    pd_json_num(js, "acc_max", s->r.acc_max);
    pd_json_num(js, "shear_max", s->r.shear_max); /* per unit mass: |k u + c u'| / m */
    pd_json_num(js, "force_equiv", s->r.force_equiv);
    pd_json_num(js, "force_max", s->r.force_max); /* NaN -> null: not compliant */
    pd_json_num(js, "contact_duration", s->r.contact_duration);
    pd_json_num(js, "umax_free", s->free.umax);
    pd_json_num(js, "gamma", s->gamma);
    pd_json_num(js, "chi", s->chi);
    pd_json_int(js, "steps", s->r.steps);
    pd_json_num(js, "cpu_s", s->cpu_s);
    pd_json_num(js, "rtol", s->r.rtol);
    pd_json_num(js, "err_est", s->err_est); /* NaN -> null: fixed steps */
    pd_json_bool(js, "rtol_met", s->rtol_met);
    pd_json_int(js, "steps_rejected", s->r.steps_rejected);
    pd_json_num(js, "dt_min", s->r.dt_min);
    pd_json_num(js, "dt_max", s->r.dt_max);
    pd_json_num(js, "Pi2", c->Pi2);
    pd_json_num(js, "Pi3", c->Pi3);
    pd_json_num(js, "eps", c->eps);
    pd_json_num(js, "xi", c->xi);
    pd_json_num(js, "ap", c->ap);
    pd_json_num(js, "Tp", c->Tp);
    pd_json_num(js, "T0", pd_osc_T0(c));
    pd_json_num(js, "gap", pd_osc_gap(c));
    pd_json_str(js, "pulse", pd_osc_excitation_name(c));
    pd_json_str(js, "dir", pd_dir_name(c->dir));
    if (c->record) {
        pd_json_str(js, "record", c->record->name);
        pd_json_num(js, "scale", c->scale);
    }
    pd_json_num(js, "dt", s->r.dt);
    pd_json_num(js, "theta", s->r.theta);
    pd_json_num(js, "gamma_active", s->r.gamma);
    pd_json_num(js, "tend", s->r.tend);
    pd_json_str(js, "kernel", s->r.kernel);
    if (pd_osc_yields(c)) { /* the yielding spring (SPEC §7) */
        pd_json_num(js, "uy", pd_osc_uy(c));
        pd_json_num(js, "Piy", c->Piy);
        pd_json_num(js, "alpha", c->alpha);
        pd_json_num(js, "ductility", s->r.ductility);
        pd_json_num(js, "residual", s->r.residual);
        pd_json_int(js, "n_yield", s->r.n_yield);
        pd_json_num(js, "plastic_excursion", s->r.plastic_excursion);
        pd_json_num(js, "hysteretic_energy", s->r.hysteretic_energy);
        pd_json_num(js, "ductility_free", s->free.ductility);
        /* the balance per unit mass [J/kg]; its hysteretic term is hysteretic_energy */
        energy_json(js, &s->r.energy, 0);
        /* Newton's failures, honestly (newmark; 0: no Newton iterations) */
        pd_json_int(js, "newton_failures", s->r.newton_failures);
    }
    pd_json_end_object(js);
}

static void print_json(const sim_args *a, const pd_osc_summary *s)
{
    pd_json js;
    pd_json_init(&js, stdout);
    osc_json(&js, a, &a->k.c, a->k.opts.method, s);
    pd_json_finish(&js);
}

/* To a tolerance that was not met: one line on stderr (the figures stand,
 * with their estimate). */
static void warn_rtol(double rtol, double err_est, int met)
{
    if (rtol > 0.0 && !met)
        fprintf(stderr,
                "pound: simulate: warning: rtol %g not met: err_est %.2g (the steps "
                "reached their floor, the budget, or the estimate stayed above rtol after the "
                "tighter runs; docs/scheme.md, \"Moreau-Jean to a tolerance\")\n",
                rtol, err_est);
}

/* A yielding run's energy balance on one line, when it has one (a finite
 * input), in unit (J/kg for the oscillator, J for a scene). */
static void energy_line(const pd_energy *en, const char *unit)
{
    if (isfinite(en->input))
        printf("  energy    = input %.6g %s = kinetic %.4g + strain %.4g + damping %.4g + "
               "hysteretic %.4g + impacts %.4g, residual %.2g of the input\n",
               en->input, unit, en->kinetic, en->strain, en->damping, en->hysteretic, en->impact,
               en->residual);
}

static void print_text(const sim_args *a, const pd_osc_summary *s)
{
    const pd_osc *c = &a->k.c;
    if (c->record)
        printf("pounding oscillator, record %s (%s, scale %g; its fitted pulse: ap = %g m/s^2, "
               "Tp = %g s), T0 = %g s, gap = %g m, eps = %g, xi = %g\n",
               c->record->name, pd_dir_name(c->dir), c->scale, c->ap, c->Tp, pd_osc_T0(c),
               pd_osc_gap(c), c->eps, c->xi);
    else
        printf("pounding oscillator, %s %s pulse: ap = %g m/s^2, Tp = %g s, T0 = %g s, "
               "gap = %g m, eps = %g, xi = %g\n",
               pd_dir_name(c->dir), pd_pulse_name(c->pulse), c->ap, c->Tp, pd_osc_T0(c),
               pd_osc_gap(c), c->eps, c->xi);
    if (a->k.opts.method == PD_METHOD_MOREAU && s->r.rtol > 0.0)
        printf("  Pi2 = %.6g  Pi3 = %.6g   Moreau-Jean to rtol = %g: %ld steps (%ld tries "
               "halved), dt %.3g to %.3g s, to %g s\n",
               c->Pi2, c->Pi3, s->r.rtol, s->r.steps, s->r.steps_rejected, s->r.dt_min, s->r.dt_max,
               s->r.tend);
    else if (a->k.opts.method == PD_METHOD_MOREAU)
        printf(
            "  Pi2 = %.6g  Pi3 = %.6g   Moreau-Jean theta = %g, dt = %.6g s, %ld steps to %g s\n",
            c->Pi2, c->Pi3, s->r.theta, s->r.dt, s->r.steps, s->r.tend);
    else
        printf("  Pi2 = %.6g  Pi3 = %.6g   %s (%s), %ld %s to %g s\n", c->Pi2, c->Pi3,
               a->k.opts.method == PD_METHOD_EVENT ? "event-driven reference" : "penalty",
               s->r.kernel, s->r.steps,
               a->k.opts.method != PD_METHOD_EVENT ? "steps"
               : c->record ? "events (impacts, ends of contact, the record's samples)"
                           : "events (impacts, ends of contact, the pulse's end)",
               s->r.tend);
    method_line(&a->k);
    printf("  umax      = %.6g m   (Pi1 = %.6g)\n", s->r.umax, s->Pi1);
    printf("  toward    = %.6g m,  away = %.6g m\n", s->r.u_toward, s->r.u_away);
    printf("  umax_free = %.6g m   gamma = umax/umax_free = %.4g,  chi = gap/umax_free = %.4g\n",
           s->free.umax, s->gamma, s->chi);
    if (s->r.impacts)
        printf("  impacts   = %ld, first at t = %.6g s (velocity %.4g m/s), contact time %.4g s\n",
               s->r.impacts, s->r.first_impact, s->r.first_impact_velocity, s->r.contact_time);
    else
        printf("  impacts   = 0 (the oscillator never reaches the wall)\n");
    if (pd_osc_yields(c))
        printf("  yielding  = uy %.6g m (Piy = %.6g), alpha %g: ductility %.5g (no wall %.5g), "
               "residual %.5g m, %ld yield onsets, plastic excursion %.5g m, hysteretic "
               "energy %.5g J/kg\n",
               pd_osc_uy(c), c->Piy, c->alpha, s->r.ductility, s->free.ductility, s->r.residual,
               s->r.n_yield, s->r.plastic_excursion, s->r.hysteretic_energy);
    if (pd_osc_yields(c) && !strcmp(s->r.kernel, "newmark"))
        printf("  newton    = %ld of %ld steps failed Newton's iterations (each redone at the "
               "spring's initial stiffness)\n",
               s->r.newton_failures, s->r.steps);
    if (pd_osc_yields(c))
        energy_line(&s->r.energy, "J/kg");
    printf("  demands   = drift ratio %.5g (height %g m), a_abs %.6g m/s^2, base shear per "
           "unit mass %.6g N/kg\n",
           s->r.umax / a->k.height, a->k.height, s->r.acc_max, s->r.shear_max);
    if (s->r.impacts && isnan(s->r.force_max)) /* an impulsive method */
        printf("  contact   = equivalent force %.6g N/kg (pi I / (2 td), td = %g s, "
               "--contact-duration)\n",
               s->r.force_equiv, s->r.contact_duration);
    else if (s->r.impacts)
        printf("  contact   = equivalent force %.6g N/kg (pi I / (2 td), td = %g s, "
               "--contact-duration), peak force %.6g N/kg\n",
               s->r.force_equiv, s->r.contact_duration, s->r.force_max);
    if (s->r.rtol > 0.0)
        printf("  err_est   = %.2g (the peaks' estimated relative error, the run's and its "
               "no-wall twin's; %s)\n",
               s->err_est, s->rtol_met ? "rtol met" : "rtol NOT met");
    printf("  cpu       = %.3g s\n", s->cpu_s);
}

/* Every input and summary figure after the histories; the file into place. */
static int finish_output(const sim_args *a, const pd_osc *c, const pd_run_opts *opts,
                         const pd_osc_summary *s, pd_table_writer *w, pd_err *err)
{
#define NUM(n, u, x) {.name = n, .units = u, .num = (x)}
#define TXT(n, x)                                                                                  \
    {                                                                                              \
        .name = n, .is_text = 1, .text = (x)                                                       \
    }
    pd_attr attrs[64] = {TXT("method", pd_method_name(opts->method)),
                         TXT("pulse", pd_osc_excitation_name(c)),
                         TXT("dir", pd_dir_name(c->dir)),
                         NUM("scale", "1", c->record ? c->scale : 1.0),
                         NUM("ap", "m/s^2", c->ap),
                         NUM("Tp", "s", c->Tp),
                         NUM("T0", "s", pd_osc_T0(c)),
                         NUM("gap", "m", pd_osc_gap(c)),
                         NUM("eps", "1", c->eps),
                         NUM("xi", "1", c->xi),
                         NUM("Pi2", "1", c->Pi2),
                         NUM("Pi3", "1", c->Pi3),
                         NUM("dt", "s", s->r.dt),
                         NUM("theta", "1", s->r.theta),
                         NUM("tend", "s", s->r.tend),
                         NUM("every", "1", (double)a->every),
                         NUM("umax", "m", s->r.umax),
                         NUM("Pi1", "1", s->Pi1),
                         NUM("u_toward", "m", s->r.u_toward),
                         NUM("u_away", "m", s->r.u_away),
                         NUM("impacts", "1", (double)s->r.impacts),
                         NUM("first_impact", "s", s->r.first_impact),
                         NUM("max_impulse", "m/s", s->r.max_impulse),
                         NUM("contact_time", "s", s->r.contact_time),
                         NUM("height", "m", a->k.height),
                         NUM("drift_ratio", "1", s->r.umax / a->k.height),
                         NUM("acc_max", "m/s^2", s->r.acc_max),
                         NUM("shear_max", "N/kg", s->r.shear_max),
                         NUM("force_equiv", "N/kg", s->r.force_equiv),
                         NUM("force_max", "N/kg", s->r.force_max),
                         NUM("contact_duration", "s", s->r.contact_duration),
                         NUM("umax_free", "m", s->free.umax),
                         NUM("gamma", "1", s->gamma),
                         NUM("steps", "1", (double)s->r.steps),
                         NUM("cpu_s", "s", s->cpu_s),
                         NUM("rtol", "1", s->r.rtol),
                         NUM("err_est", "1", s->err_est),
                         NUM("rtol_met", "1", s->rtol_met),
                         NUM("steps_rejected", "1", (double)s->r.steps_rejected),
                         NUM("dt_min", "s", s->r.dt_min),
                         NUM("dt_max", "s", s->r.dt_max)};
    int n = 0;
    while (attrs[n].name)
        n++;
    if (pd_osc_yields(c)) { /* the yielding spring's inputs and figures */
        pd_attr ya[] = {NUM("uy", "m", pd_osc_uy(c)),
                        NUM("Piy", "1", c->Piy),
                        NUM("alpha", "1", c->alpha),
                        NUM("ductility", "1", s->r.ductility),
                        NUM("residual", "m", s->r.residual),
                        NUM("n_yield", "1", (double)s->r.n_yield),
                        NUM("plastic_excursion", "m", s->r.plastic_excursion),
                        NUM("hysteretic_energy", "J/kg", s->r.hysteretic_energy),
                        NUM("energy_input", "J/kg", s->r.energy.input),
                        NUM("energy_kinetic", "J/kg", s->r.energy.kinetic),
                        NUM("energy_strain", "J/kg", s->r.energy.strain),
                        NUM("energy_damping", "J/kg", s->r.energy.damping),
                        NUM("energy_impact", "J/kg", s->r.energy.impact),
                        NUM("energy_residual", "1", s->r.energy.residual)};
        for (size_t i = 0; i < sizeof ya / sizeof ya[0]; i++)
            attrs[n++] = ya[i];
        attrs[n++] = (pd_attr){/* newmark's; 0: no Newton iterations */
                               .name = "newton_failures",
                               .units = "1",
                               .num = (double)s->r.newton_failures};
    }
#undef NUM
#undef TXT
    return pd_table_finish(w, n, attrs, err);
}

/* The oscillator as a one-structure scene, for the chart. */
static pd_scene *oscillator_scene(const pd_osc *c)
{
    pd_scene_excitation x = {.pulse = c->pulse, .dir = c->dir, .ap = c->ap, .Tp = c->Tp};
    pd_scene *sc = pd_scene_new(&x);
    if (!sc || pd_scene_add_sdof(sc, "oscillator", pd_osc_T0(c), c->xi, 1.0, NULL) ||
        pd_scene_add_contact(sc, 0, 1, PD_WALL, 0, pd_osc_gap(c), c->eps, 0, NULL) ||
        pd_scene_finish(sc, NULL)) {
        pd_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* The oscillator's run of case c under opts, its file (out) and chart
 * (plot) written, nothing printed: PD_OK or a status, its message in err. */
static int osc_run_files(const sim_args *a, const pd_osc *c, const pd_run_opts *opts,
                         const char *out, const char *plot, pd_osc_summary *s, pd_err *err)
{
    pd_scene *psc = NULL;
    int rc = PD_OK;
    /* to a tolerance the steps are the run's: the fixed scheme's count at the
     * default dt stands for them in the chart's size, no cap on the rows */
    int tol = opts->rtol > 0.0;
    long nsteps = pd_steps_for(opts->tend, tol ? pd_osc_default_dt(c) : opts->dt);
    osc_out o = {.c = c, .every = a->every, .rows_max = tol ? LONG_MAX : nsteps / a->every + 1};
    if (out && (rc = pd_table_open(&o.file, out, osc_ncols(c), osc_cols, "t", o.rows_max, err)))
        goto done;
    if (plot && (!(psc = oscillator_scene(c)) || pd_scene_plot_open(&o.plot, psc, nsteps, err))) {
        rc = pd_err_set(err, PD_ENOMEM, "out of memory for the chart");
        goto done;
    }
    if ((rc = pd_osc_summarize(c, opts, out || plot ? record : NULL, &o, s, err)))
        goto done;
    if (isfinite(s->r.umax) && !isfinite(s->r.umax / a->k.height)) {
        rc = pd_err_set(err, PD_EINVAL,
                        "--height: the drift ratio umax / H overflows (umax %g m, H %g m): give "
                        "a larger height",
                        s->r.umax, a->k.height);
        goto done;
    }
    /* an impulse whose equivalent force overflows at any duration: the
     * excitation's scale (the duration's own case is the library's) */
    if (isfinite(s->r.max_impulse) && !isfinite(s->r.force_equiv)) {
        rc = pd_err_set(err, PD_EINVAL,
                        "%s: the impacts' equivalent force pi I / (2 td) overflows (impulse I = "
                        "%g): a weaker excitation",
                        c->record ? "--scale" : "--ap", s->r.max_impulse);
        goto done;
    }
    char title[PD_NAME_MAX + 160];
    snprintf(title, sizeof title,
             "pounding oscillator: %s %s%s, T0 = %.3g s, gap = %.3g m, "
             "eps = %.3g (%s)",
             pd_osc_excitation_name(c), pd_dir_name(c->dir), c->record ? "" : " pulse",
             pd_osc_T0(c), pd_osc_gap(c), c->eps, pd_method_name(opts->method));
    if (o.file && (rc = finish_output(a, c, opts, s, o.file, err)))
        goto done;
    if (plot)
        rc = pd_scene_plot_draw(o.plot, plot, title, err);
done:
    pd_table_free(o.file);
    pd_scene_plot_free(o.plot);
    pd_scene_free(psc);
    return rc;
}

/* The oscillator's run, its file, chart, dump and summary: the exit status. */
static int simulate_oscillator(sim_args *a)
{
    pd_osc_summary s;
    pd_lcp_dump *dump = NULL;
    pd_err err;
    int rc, status = 0;
    int tol = a->k.opts.rtol > 0.0;
    long nsteps = pd_steps_for(a->k.opts.tend, tol ? pd_osc_default_dt(&a->k.c) : a->k.opts.dt);
    if (a->out && (status = check_output_size(
                       a->out, output_bytes(a->out, nsteps / a->every + 1, osc_ncols(&a->k.c)))))
        goto done;
    if ((status = dump_open(a, &dump, &a->k.opts)))
        goto done;
    if ((rc = osc_run_files(a, &a->k.c, &a->k.opts, a->out, a->plot, &s, &err))) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    if ((status = dump_finish(dump)))
        goto done;
    warn_rtol(s.r.rtol, s.err_est, s.rtol_met);
    if (a->json)
        print_json(a, &s);
    else
        print_text(a, &s);
done:
    pd_lcp_dump_free(dump);
    return status;
}

/* ==== a progress line ======================================================== */

/* A run longer than PROGRESS_AFTER seconds says how far it has come on
 * stderr, on one line rewritten in place, when stderr is a terminal. */
#define PROGRESS_AFTER 2.0

typedef struct progress {
    double t0;  /* wall clock at the start */
    int shown;  /* a line is on the terminal */
    int active; /* stderr is a terminal */
} progress;

static void progress_start(progress *p)
{
    *p = (progress){.t0 = pd_wall_seconds(), .shown = 0, .active = isatty(STDERR_FILENO)};
}

static void on_progress(double fraction, void *ctx)
{
    progress *p = ctx;
    double elapsed = pd_wall_seconds() - p->t0;
    if (!p->active || elapsed < PROGRESS_AFTER)
        return;
    fprintf(stderr,
            "\rpound: simulate: %3.0f %% of a run (the scene's, then its contact-free "
            "twin's), %.0f s ",
            100.0 * fraction, elapsed);
    p->shown = 1;
}

/* A suite's records done so far. */
static void suite_progress(progress *p, int done, int n)
{
    double elapsed = pd_wall_seconds() - p->t0;
    if (!p->active || elapsed < PROGRESS_AFTER)
        return;
    fprintf(stderr, "\rpound: simulate: %d of %d records, %.0f s ", done, n, elapsed);
    p->shown = 1;
}

/* The line cleared before the results. */
static void progress_end(progress *p)
{
    if (p->shown)
        fprintf(stderr, "\r%78s\r", "");
    p->shown = 0;
}

/* ==== suites of records ====================================================== */

/* One figure of every record's run: its statistics into js under key. */
static void stats_json(pd_json *js, const char *key, const double *x, int n)
{
    pd_stats st;
    pd_err err;
    pd_stats_of(x, n, &st, &err); /* out of memory: st stays NaN, n 0 */
    pd_json_stats(js, key, &st);
}

/* The suite's header: its file or records, the scaling. */
static void suite_header(const sim_args *a, FILE *f)
{
    fprintf(f, "suite: %d records (%s)", a->k.suite->n,
            a->k.records_path ? a->k.records_path : "--record");
    if (a->k.target == PD_SCALE_PGA)
        fprintf(f, ", each scaled to PGA = %g m/s^2", a->k.target_value);
    else if (a->k.target == PD_SCALE_SA)
        fprintf(f, ", each scaled to Sa(T1) = %g m/s^2 (5 %% damped)", a->k.target_value);
    fprintf(f, "\n");
}

/* The statistics rows of a suite's text table: each statistic's name,
 * lead blank columns, then the statistic of each of the ncol columns. */
static void stats_rows(int lead, int ncol, const double *const *cols, int n)
{
    static const char *const names[] = {"mean", "median", "p16", "p84", "max"};
    pd_stats st[16];
    pd_err err;
    ncol = ncol < 16 ? ncol : 16;
    for (int j = 0; j < ncol; j++)
        pd_stats_of(cols[j], n, &st[j], &err); /* out of memory: NaN */
    for (int r = 0; r < 5; r++) {
        printf("  %-24s", names[r]);
        for (int j = 0; j < lead; j++)
            printf(" %12s", "");
        for (int j = 0; j < ncol; j++) {
            const double v[5] = {st[j].mean, st[j].median, st[j].p16, st[j].p84, st[j].max};
            printf(" %12.5g", v[r]);
        }
        printf("\n");
    }
}

/* The oscillator's peaks over a suite (ductility last: yielding runs). */
enum { OSC_FIGS = 16, SUITE_TEXT_STRUCTS = 6 };
static const char *const osc_fig_names[OSC_FIGS] = {
    "umax",         "Pi1",         "gamma",     "impacts",  "max_impulse", "acc_max",
    "shear_max",    "drift_ratio", "u_toward",  "u_away",   "umax_free",   "max_impact_velocity",
    "contact_time", "force_equiv", "force_max", "ductility"};

/* The oscillator's figures of a run, in osc_fig_names' order. */
static void osc_figs(const sim_args *a, const pd_osc_summary *s, double *f)
{
    double v[OSC_FIGS] = {
        s->r.umax,         s->Pi1,           s->gamma,       (double)s->r.impacts,
        s->r.max_impulse,  s->r.acc_max,     s->r.shear_max, s->r.umax / a->k.height,
        s->r.u_toward,     s->r.u_away,      s->free.umax,   s->r.max_impact_velocity,
        s->r.contact_time, s->r.force_equiv, s->r.force_max, s->r.ductility};
    memcpy(f, v, sizeof v);
}

/* A suite's JSON opening keys: its file (none for --record files), the
 * number of records, the target. */
static void suite_json_head(pd_json *js, const sim_args *a)
{
    if (a->k.records_path)
        pd_json_str(js, "suite", a->k.records_path);
    pd_json_int(js, "n", a->k.suite->n);
    if (a->k.target != PD_SCALE_NONE) {
        pd_json_str(js, "target", a->k.target == PD_SCALE_PGA ? "pga" : "sa");
        pd_json_num(js, "target_value", a->k.target_value);
    }
}

/* A suite's runs: record k's run, its summary as a journal line's body and
 * back (suite_journal.c), over the records this rank has not read back. */
typedef struct suite_runner {
    const sim_args *a;
    int (*run)(void *ctx, int k, pd_err *err);                     /* PD_OK or a status */
    char *(*body)(const void *ctx, int k, size_t *len);            /* NULL: out of memory */
    int (*parse)(void *ctx, const char *body, size_t len, int *k); /* 0 or -1 */
    void *ctx;
    unsigned char *done; /* n: finished (run here, read back, or sent by a rank) */
    pd_suite_names names;
    pd_journal journal; /* --journal (rank 0) */
    int rank, size;
    int failed, rc_failed; /* the lowest failed record (-1: none) and its status */
    char msg[sizeof(((pd_err *)0)->msg)];
    long finished_here; /* for --stop-after */
} suite_runner;

/* A journal line read back, or a rank's: record k finished (a body read
 * twice replaces the first). */
static int runner_read(const char *body, size_t len, void *ctx)
{
    suite_runner *s = ctx;
    int k;
    if (s->parse(s->ctx, body, len, &k))
        return -1;
    s->done[k] = 1;
    return 0;
}

/* Record k failed with rc: the lowest failure's message kept. */
static void runner_fail(suite_runner *s, int k, int rc, const char *msg)
{
    if (s->failed >= 0 && s->failed < k)
        return;
    s->failed = k;
    s->rc_failed = rc;
    snprintf(s->msg, sizeof s->msg, "%s", msg);
}

/* Rank 0: a finished record into the journal (a failed append said once). */
static void runner_journal(suite_runner *s, const char *body, size_t len)
{
    if (!s->a->journal || !pd_journal_append(&s->journal, body, len) || s->journal.failed != 1)
        return;
    fprintf(stderr, "pound: simulate: cannot append to %s; the suite goes on\n", s->journal.path);
    s->journal.failed = 2; /* said once */
}

/* Rank 0: a rank's message ("R ..." a finished record, "E k rc msg" a
 * failed one), journaled like rank 0's own. */
static void runner_message(suite_runner *s, const char *text, size_t len)
{
    int k, rc, at = 0;
    if (len > 2 && text[0] == 'E' && sscanf(text, "E %d %d %n", &k, &rc, &at) == 2 && at > 0)
        runner_fail(s, k, rc, text + at);
    else if (runner_read(text, len, s))
        runner_fail(s, s->a->k.suite->n, PD_EIO, "a rank's record could not be read back");
    else
        runner_journal(s, text, len);
}

/* Record k finished here with rc: journaled (rank 0) or sent to rank 0. */
static void runner_finished(suite_runner *s, int k, int rc, const pd_err *err)
{
    size_t len = 0;
    char *body = rc ? NULL : s->body(s->ctx, k, &len);
    if (!rc && !body) {
        rc = PD_ENOMEM;
        err = &(pd_err){.status = PD_ENOMEM, .msg = "out of memory for the record's summary"};
    }
    if (s->rank == 0) {
        if (rc)
            runner_fail(s, k, rc, err->msg);
        else {
            s->done[k] = 1;
            runner_journal(s, body, len);
        }
    } else {
        char line[sizeof err->msg + 32];
        int n = rc ? snprintf(line, sizeof line, "E %d %d %s", k, rc, err->msg) : 0;
        if (rc ? pd_mpi_send_text(line, (size_t)n) : pd_mpi_send_text(body, len))
            pd_spec_mpi_abort(1); /* rank 0 would wait for it */
    }
    free(body);
    if (!rc && s->a->stop_after > 0 && ++s->finished_here >= s->a->stop_after)
        _exit(130); /* the test hook: die like an interrupted suite */
}

/* The records finished so far (run here, read back, or sent by a rank). */
static int done_count(const suite_runner *s)
{
    int m = 0;
    for (int k = 0; k < s->a->k.suite->n; k++)
        m += s->done[k];
    return m;
}

/* A suite's runner over ctx's records (done: n flags, zero), this rank's. */
static suite_runner runner_make(const sim_args *a, int (*run)(void *, int, pd_err *),
                                char *(*body)(const void *, int, size_t *),
                                int (*parse)(void *, const char *, size_t, int *), void *ctx,
                                unsigned char *done)
{
    return (suite_runner){.a = a,
                          .run = run,
                          .body = body,
                          .parse = parse,
                          .ctx = ctx,
                          .done = done,
                          .journal = {.fd = -1},
                          .rank = a->rank,
                          .size = a->size};
}

/* The messages rank 0 awaits: one for each record the other ranks run. */
static int awaited(const suite_runner *s)
{
    int m = 0;
    for (int k = 0; s->rank == 0 && k < s->a->k.suite->n; k++)
        m += k % s->size != 0 && !s->done[k];
    return m;
}

/* Rank 0: a rank's message, waiting for one when block; 1 when one came. */
static int runner_receive(suite_runner *s, int block)
{
    size_t len;
    char *text = s->rank == 0 ? pd_mpi_recv_text(block, &len) : NULL;
    if (!text)
        return 0;
    runner_message(s, text, len);
    free(text);
    return 1;
}

/* Open --journal (rank 0; with --resume its records read back) and tell
 * every rank which records are done: 0, 1 or 2. */
static int runner_open(suite_runner *s, const char *key)
{
    pd_err err;
    int rc = 0, n = s->a->k.suite->n;
    if (s->rank == 0 && s->a->journal)
        rc = pd_suite_journal_open(&s->journal, s->a->journal, key, s->a->resume, runner_read, s,
                                   &err);
    int status = rc == PD_EINVAL ? 2 : rc ? 1 : 0;
    pd_spec_mpi_agree(&status);
    if (status) {
        if (rc)
            fprintf(stderr, "pound: simulate: %s\n", err.msg);
        return status;
    }
    pd_mpi_bcast_bytes(s->done, n);
    return 0;
}

/* Every record's run (OpenMP over this rank's records: k = rank mod size;
 * the numbers the same whatever the threads and ranks), a progress line
 * counting them, the journal; the first failing record's message: 0, 1 or
 * 2 on every rank. */
static int run_records(suite_runner *s, const char *key, pd_err *errs)
{
    const sim_args *a = s->a;
    int n = a->k.suite->n, status;
    /* records in turn when each writes files (HDF5 is not thread-safe) */
    int nt = a->out || a->plot ? 1 : pd_spec_threads(a->threads);
    s->failed = -1;
    if ((status = runner_open(s, key)))
        return status;
    int expect = awaited(s);
    progress pr;
    progress_start(&pr);
#pragma omp parallel for schedule(dynamic) num_threads(nt)
    for (int k = 0; k < n; k++) {
        if (k % s->size != s->rank || s->done[k])
            continue;
        int rc = s->run(s->ctx, k, &errs[k]);
#pragma omp critical
        {
            runner_finished(s, k, rc, &errs[k]);
            while (expect > 0 && runner_receive(s, 0)) /* the ranks' so far */
                expect--;
            suite_progress(&pr, done_count(s), n);
        }
    }
    for (; expect > 0; expect--) { /* every rank's, a failure or not: they wait to send */
        runner_receive(s, 1);
        suite_progress(&pr, done_count(s), n);
    }
    progress_end(&pr);
    status = s->failed < 0 ? 0 : s->rc_failed == PD_EINVAL ? 2 : 1;
    /* a failure of the machine (a write, memory) may not come again: the
     * journal and the finished records' files stay for --resume */
    int keep =
        s->failed >= 0 && a->journal && (s->rc_failed == PD_EIO || s->rc_failed == PD_ENOMEM);
    pd_spec_mpi_agree(&status);
    pd_spec_mpi_agree(&keep);
    if (!status)
        return 0;
    if (s->rank == 0 && s->failed >= 0)
        fprintf(stderr, "pound: simulate: %s: %s%s%s%s\n",
                a->k.suite->path[s->failed < n ? s->failed : 0], s->msg,
                keep ? " (the finished records stay in " : "", keep ? a->journal : "",
                keep ? ": --resume continues the suite)" : "");
    if (keep)
        return status;
    /* else the suite cannot finish with these flags (the runs are
     * deterministic): no partial output, and no journal to resume */
    for (int k = 0; k < n && (a->out || a->plot); k++) {
        char path[PD_PATH_MAX];
        if (a->out && !suite_path(a->out, k, path, sizeof path))
            unlink(path);
        if (a->plot && !suite_path(a->plot, k, path, sizeof path))
            unlink(path);
    }
    if (s->rank == 0)
        pd_journal_close(&s->journal, 1);
    return status;
}

/* After the suite's output (status 0: printed): the journal has served;
 * the names go. */
static void runner_end(suite_runner *s, int status)
{
    /* removed once the results are out (stdout written: not a full disk) */
    int out = !status && fflush(stdout) == 0 && !ferror(stdout);
    if (s->a && s->rank == 0 && s->a->journal && s->journal.fd >= 0)
        pd_journal_close(&s->journal, out);
    pd_suite_names_free(&s->names);
}

/* The oscillator's runs of a suite: record k's case, options, summary. */
typedef struct osc_runs {
    const sim_args *a;
    const pd_osc *cs;
    const pd_run_opts *os;
    pd_osc_summary *ss;
    pd_suite_names *names; /* the kernels' names read back */
} osc_runs;

static char *osc_record_body(const void *ctx, int k, size_t *len)
{
    const osc_runs *r = ctx;
    return pd_suite_osc_body(k, &r->ss[k], len);
}

static int osc_record_parse(void *ctx, const char *body, size_t len, int *k)
{
    osc_runs *r = ctx;
    pd_osc_summary v;
    if (pd_suite_osc_parse(body, len, r->a->k.suite->n, k, &v, r->names))
        return -1;
    r->ss[*k] = v;
    return 0;
}

/* Record k's run, its files (-o, --plot: PATH.recK.EXT) written. */
static int osc_record_run(void *ctx, int k, pd_err *err)
{
    osc_runs *r = ctx;
    char out[PD_PATH_MAX], plot[PD_PATH_MAX];
    if (!r->a->out && !r->a->plot)
        return pd_osc_summarize(&r->cs[k], &r->os[k], NULL, NULL, &r->ss[k], err);
    if (r->a->out)
        suite_path(r->a->out, k, out, sizeof out); /* fits: parse_args checked */
    if (r->a->plot)
        suite_path(r->a->plot, k, plot, sizeof plot);
    return osc_run_files(r->a, &r->cs[k], &r->os[k], r->a->out ? out : NULL,
                         r->a->plot ? plot : NULL, &r->ss[k], err);
}

/* Every record of the suite through the oscillator: per-record results as
 * single runs give them (the same function makes each), then the suite's
 * statistics. */
static int suite_oscillator(sim_args *a)
{
    int n = a->k.suite->n, status = 0;
    pd_osc *cs = calloc((size_t)n, sizeof *cs);
    pd_run_opts *os = calloc((size_t)n, sizeof *os);
    pd_osc_summary *ss = calloc((size_t)n, sizeof *ss);
    double *figs = calloc((size_t)n * OSC_FIGS, sizeof *figs),
           *col = calloc((size_t)n, sizeof *col);
    pd_err *errs = calloc((size_t)n, sizeof *errs);
    unsigned char *done = calloc((size_t)n, 1);
    suite_runner sr = {.journal = {.fd = -1}};
    if (!cs || !os || !ss || !figs || !col || !errs || !done) {
        fprintf(stderr, "pound: simulate: out of memory for a suite of %d records\n", n);
        status = 1;
    }
    double bytes = 0.0;                      /* the records' files together */
    for (int k = 0; k < n && !status; k++) { /* each record's case, checked before any run */
        status = pd_cli_case_record(&a->k, k, &cs[k], &os[k]);
        long steps =
            pd_steps_for(os[k].tend, os[k].rtol > 0.0 ? pd_osc_default_dt(&cs[k]) : os[k].dt);
        bytes += a->out ? output_bytes(a->out, steps / a->every + 1, osc_ncols(&cs[k])) : 0.0;
    }
    if (!status && a->out)
        status = check_output_size(a->out, bytes);
    pd_spec_mpi_agree(&status); /* every rank goes on, or none */
    if (status)
        goto done;
    osc_runs runs = {.a = a, .cs = cs, .os = os, .ss = ss, .names = &sr.names};
    sr = runner_make(a, osc_record_run, osc_record_body, osc_record_parse, &runs, done);
    if ((status = run_records(&sr, a->key, errs)) || a->rank)
        goto done;
    for (int k = 0; k < n; k++) {
        osc_figs(a, &ss[k], figs + (size_t)k * OSC_FIGS);
        warn_rtol(ss[k].r.rtol, ss[k].err_est, ss[k].rtol_met);
    }
    int yields = pd_osc_yields(&cs[0]), nf = yields ? OSC_FIGS : OSC_FIGS - 1;
    if (a->json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        suite_json_head(&js, a);
        pd_json_begin_array(&js, "records");
        for (int k = 0; k < n; k++)
            osc_json(&js, a, &cs[k], os[k].method, &ss[k]);
        pd_json_end_array(&js);
        pd_json_begin_object(&js, "stats");
        for (int j = 0; j < nf; j++) {
            for (int k = 0; k < n; k++)
                col[k] = figs[(size_t)k * OSC_FIGS + j];
            stats_json(&js, osc_fig_names[j], col, n);
        }
        pd_json_end_object(&js);
        pd_json_end_object(&js);
        pd_json_finish(&js);
        goto done;
    }
    suite_header(a, stdout);
    printf("  oscillator: T0 %s, gap %s, eps = %g, xi = %g; method %s\n",
           a->k.have_T0 ? "given" : "from Pi2 and each record's Tp",
           a->k.have_gap ? "given" : "from Pi3 and each record's Le", cs[0].eps, cs[0].xi,
           pd_method_name(os[0].method));
    printf("  %-24s %12s %12s %12s %12s %12s %12s %12s\n", "record", "scale", "T0 [s]", "umax [m]",
           "Pi1", "impacts", "gamma", "a_abs [m/s2]");
    for (int k = 0; k < n; k++)
        printf("  %-24.24s %12.5g %12.5g %12.5g %12.5g %12ld %12.5g %12.5g\n", cs[k].record->name,
               cs[k].scale, pd_osc_T0(&cs[k]), ss[k].r.umax, ss[k].Pi1, ss[k].r.impacts,
               ss[k].gamma, ss[k].r.acc_max);
    /* the columns umax, Pi1, impacts, gamma, a_abs over the records */
    static const int pick[5] = {0, 1, 3, 2, 5};
    double *buf = calloc((size_t)5 * n, sizeof *buf);
    const double *cols[5];
    if (!buf) {
        fprintf(stderr, "pound: simulate: out of memory for the suite's statistics\n");
        status = 1;
        goto done;
    }
    for (int j = 0; j < 5; j++) {
        for (int k = 0; k < n; k++)
            buf[(size_t)j * n + k] = figs[(size_t)k * OSC_FIGS + pick[j]];
        cols[j] = buf + (size_t)j * n;
    }
    stats_rows(2, 5, cols, n);
    free(buf);
done:
    runner_end(&sr, status);
    free(cs);
    free(os);
    free(ss);
    free(figs);
    free(col);
    free(errs);
    free(done);
    return status;
}

/* ==== scenes ================================================================ */

/* The writer and the chart both take the samples. */
typedef struct fanout {
    pd_scene_writer *w;
    pd_scene_plot *p;
} fanout;

static int fan_sample(const pd_scene_sample *s, void *ctx)
{
    fanout *f = ctx;
    if (f->p)
        pd_scene_plot_sample(s, f->p);
    return f->w ? pd_scene_writer_sample(s, f->w) : 0;
}

/* Name of a contact's side. */
static const char *side_name(const pd_scene *sc, int s)
{
    return s == PD_WALL ? "wall" : sc->st[s].name;
}

/* The run of scene sc into js as one object. */
static void scene_json_obj(pd_json *js, const sim_args *a, const pd_scene *sc,
                           const pd_scene_summary *s)
{
    const pd_scene_result *r = &s->r;
    pd_json_begin_object(js, NULL);
    pd_json_str(js, "method", r->method);
    pd_json_str(js, "method_by", pd_cli_method_by(&a->k));
    pd_json_int(js, "steps", r->steps);
    pd_json_num(js, "cpu_s", s->cpu_s);
    pd_json_num(js, "cpu_s_run", r->cpu_s);
    pd_json_str(js, "kernel", r->kernel);
    pd_json_str(js, "factor", r->factor);
    pd_json_str(js, "lcp_solver", r->lcp_solver);
    pd_json_int(js, "lcp_solves", r->lcp_solves);
    /* the event-driven reference's model decisions (0 for the other methods) */
    long impacts = 0;
    for (int c = 0; c < sc->ncontact; c++)
        impacts += r->impacts[c];
    pd_json_int(js, "impacts", impacts);
    pd_json_int(js, "simultaneous", r->simultaneous);
    pd_json_int(js, "tol_closed", r->tol_closed);
    pd_json_int(js, "accumulations", r->accumulations);
    pd_json_num(js, "close_tol", r->close_tol);
    /* the row reference: its impact law ("none": another method), the peaks under the other */
    pd_json_str(js, "impact_law", r->impact_law ? r->impact_law : "none");
    pd_json_num(js, "law_band", r->law_band_max); /* NaN -> null: no simultaneous impact */
    if (pd_scene_springs(sc) > 0) /* a yielding scene's energy balance [J] (NaN -> null) */
        energy_json(js, &r->energy, 1);
    pd_json_num(js, "contact_duration", r->contact_duration);
    pd_json_num(js, "dt", r->dt);
    pd_json_num(js, "theta", r->theta);
    pd_json_num(js, "tend", r->tend);
    pd_json_num(js, "rtol", r->rtol);
    pd_json_num(js, "err_est", s->err_est); /* NaN -> null: fixed steps */
    pd_json_bool(js, "rtol_met", s->rtol_met);
    pd_json_int(js, "steps_rejected", r->steps_rejected);
    pd_json_num(js, "dt_min", r->dt_min);
    pd_json_num(js, "dt_max", r->dt_max);
    pd_json_int(js, "dofs", sc->n);
    pd_json_str(js, "pulse", sc->exc.record ? sc->exc.record->name : pd_pulse_name(sc->exc.pulse));
    pd_json_str(js, "dir", sc->exc.dir > 0 ? "+x" : "-x");
    if (sc->exc.record) {
        pd_json_str(js, "record", sc->exc.record->name);
        pd_json_num(js, "scale", sc->exc.scale);
    }
    pd_json_num(js, "ap", sc->exc.ap);
    pd_json_num(js, "Tp", sc->exc.Tp);
    pd_json_num(js, "Le", pd_scene_Le(sc));
    pd_json_begin_array(js, "structures");
    for (int k = 0; k < sc->nstruct; k++) {
        const pd_structure *st = &sc->st[k];
        int o = st->dof, n = st->storeys;
        pd_json_begin_object(js, NULL);
        pd_json_str(js, "name", st->name);
        pd_json_int(js, "storeys", n);
        pd_json_num(js, "T0", st->T0);
        pd_json_num(js, "Pi2", s->Pi2[k]);
        pd_json_nums(js, "umax", n, r->umax + o);
        pd_json_nums(js, "u_pos", n, r->u_pos + o);
        pd_json_nums(js, "u_neg", n, r->u_neg + o);
        pd_json_nums(js, "drift", n, r->drift + o);
        pd_json_nums(js, "storey_heights", n, st->height);
        pd_json_nums(js, "drift_ratio", n, r->drift_ratio + o);
        pd_json_nums(js, "acc_max", n, r->acc_max + o);
        pd_json_nums(js, "shear_max", n, r->shear_max + o);
        pd_json_num(js, "base_shear_max", r->shear_max[o]);
        pd_json_nums(js, "Pi1", n, s->Pi1 + o);
        pd_json_nums(js, "umax_free", n, s->free.umax + o);
        pd_json_nums(js, "gamma", n, s->gamma + o);
        pd_json_num(js, "err_est", s->err_est_structure[k]); /* NaN -> null: fixed steps */
        pd_json_num(js, "law_band", r->law_band[k]);
        if (st->uy) { /* yielding storeys (SPEC §7): NaN -> null for an elastic one */
            pd_json_nums(js, "uy", n, st->uy);
            pd_json_nums(js, "yield_alpha", n, st->yield_alpha);
            pd_json_nums(js, "ductility", n, r->ductility + o);
            pd_json_nums(js, "residual", n, r->residual + o);
            pd_json_nums(js, "plastic_excursion", n, r->plastic_excursion + o);
            pd_json_begin_array(js, "n_yield");
            for (int i = 0; i < n; i++)
                pd_json_int(js, NULL, r->n_yield[o + i]);
            pd_json_end_array(js);
        }
        pd_json_end_object(js);
    }
    pd_json_end_array(js);
    pd_json_begin_array(js, "contacts");
    for (int c = 0; c < sc->ncontact; c++) {
        const pd_contact *ct = &sc->ct[c];
        pd_json_begin_object(js, NULL);
        pd_json_str(js, "a", side_name(sc, ct->a));
        pd_json_str(js, "b", side_name(sc, ct->b));
        pd_json_int(js, "level", ct->a == PD_WALL ? ct->level_b : ct->level_a);
        pd_json_int(js, "level_b", ct->level_b);
        pd_json_num(js, "gap", ct->gap);
        pd_json_num(js, "eps", ct->eps);
        pd_json_num(js, "Pi3", s->Pi3[c]);
        pd_json_int(js, "impacts", r->impacts[c]);
        pd_json_num(js, "first_impact", r->first_impact[c]);
        pd_json_num(js, "max_impulse", r->max_impulse[c]);
        pd_json_num(js, "contact_time", r->contact_time[c]);
        pd_json_num(js, "approach", r->approach[c]);
        pd_json_num(js, "force_equiv", r->force_equiv[c]);
        pd_json_num(js, "force_max", r->force_max[c]); /* NaN -> null: not compliant */
        pd_json_num(js, "chi", s->chi[c]);
        pd_json_num(js, "required_gap", s->required_gap[c]);
        pd_json_begin_object(js, "rules");
        pd_json_num(js, "abs", s->rule_abs[c]);
        pd_json_num(js, "srss", s->rule_srss[c]);
        pd_json_num(js, "ddc", s->rule_ddc[c]);
        pd_json_end_object(js);
        pd_json_end_object(js);
    }
    pd_json_end_array(js);
    pd_json_end_object(js);
}

static void scene_json(const sim_args *a, const pd_scene *sc, const pd_scene_summary *s)
{
    pd_json js;
    pd_json_init(&js, stdout);
    scene_json_obj(&js, a, sc, s);
    pd_json_finish(&js);
}

enum { TEXT_MAX_STRUCTURES = 40, TEXT_MAX_CONTACTS = 60 };

/* Contact c's sides as "a-b" into pair, and its level (a wall's side's). */
static int contact_label(const pd_scene *sc, int c, char *pair, size_t cap)
{
    const pd_contact *ct = &sc->ct[c];
    snprintf(pair, cap, "%s-%s", side_name(sc, ct->a), side_name(sc, ct->b));
    return ct->a == PD_WALL ? ct->level_b : ct->level_a;
}

static void scene_text(const sim_args *a, const pd_scene *sc, const pd_scene_summary *s)
{
    const pd_scene_result *r = &s->r;
    printf("scene %s: %d structure%s, %d dof%s, %d contact%s; %s %s along %s, ap = %g m/s^2, "
           "Tp = %g s%s\n",
           a->k.scene_path ? a->k.scene_path : "(chain)", sc->nstruct, sc->nstruct > 1 ? "s" : "",
           sc->n, sc->n > 1 ? "s" : "", sc->ncontact, sc->ncontact == 1 ? "" : "s",
           sc->exc.record ? "record" : pd_pulse_name(sc->exc.pulse),
           sc->exc.record ? sc->exc.record->name : "pulse", sc->exc.dir > 0 ? "+x" : "-x",
           sc->exc.ap, sc->exc.Tp, sc->exc.record ? " (its fitted pulse)" : "");
    if (a->k.opts.method == PD_METHOD_MOREAU && r->rtol > 0.0)
        printf("  Moreau-Jean to rtol = %g: %ld steps (%ld tries halved), dt %.3g to %.3g s, to "
               "%g s (kernel %s, LCP %s, %ld LCPs)\n",
               r->rtol, r->steps, r->steps_rejected, r->dt_min, r->dt_max, r->tend, r->kernel,
               r->lcp_solver, r->lcp_solves);
    else if (a->k.opts.method == PD_METHOD_MOREAU)
        printf("  Moreau-Jean theta = %g, dt = %.6g s, %ld steps to %g s (kernel %s, factor %s, "
               "LCP %s, %ld LCPs)\n",
               r->theta, r->dt, r->steps, r->tend, r->kernel, r->factor, r->lcp_solver,
               r->lcp_solves);
    else {
        int pen = a->k.opts.method == PD_METHOD_PENALTY || a->k.opts.method == PD_METHOD_NEWMARK;
        printf("  %s (%s), %ld %s to %g s\n", pen ? "penalty" : "event-driven reference", r->kernel,
               r->steps, pen ? "steps" : "events", r->tend);
    }
    method_line(&a->k);
    if (a->k.opts.method == PD_METHOD_EVENT) {
        long impacts = 0;
        for (int c = 0; c < sc->ncontact; c++)
            impacts += r->impacts[c];
        if (isnan(r->close_tol)) /* the one-wall fast path */
            printf("  decisions = %ld impacts, %ld accumulations jumped (one contact)\n", impacts,
                   r->accumulations);
        else
            printf("  decisions = %ld impacts: %ld LCPs of several contacts (simultaneous), %ld "
                   "contacts closed within --close-tol %g Le, %ld accumulations jumped\n",
                   impacts, r->simultaneous, r->tol_closed, r->close_tol, r->accumulations);
        if (r->impact_law && isinf(r->law_band_max))
            printf("  impact law = %s: law_band = inf (the run under --impact-law %s did not "
                   "finish)\n",
                   r->impact_law, strcmp(r->impact_law, "single") ? "single" : "staged");
        else if (r->impact_law && !isnan(r->law_band_max))
            printf("  impact law = %s: law_band = %.2g (umax under --impact-law %s moves by "
                   "this, relative; per structure below)\n",
                   r->impact_law, r->law_band_max,
                   strcmp(r->impact_law, "single") ? "single" : "staged");
        else if (r->impact_law)
            printf("  impact law = %s (no simultaneous impact: the laws agree)\n", r->impact_law);
    }
    int tol = r->rtol > 0.0;            /* to a tolerance: each structure's estimate */
    int band = !isnan(r->law_band_max); /* simultaneous impacts: each structure's law_band */
    printf("  %-12s %7s %9s %12s %12s %10s %8s%s%s\n", "structure", "storey", "T0 [s]", "umax [m]",
           "drift [m]", "Pi1", "gamma", tol ? "    err_est" : "", band ? "   law_band" : "");
    for (int k = 0; k < sc->nstruct && k < TEXT_MAX_STRUCTURES; k++) {
        const pd_structure *st = &sc->st[k];
        for (int i = 0; i < st->storeys; i++) {
            int d = st->dof + i;
            char T0[16] = "", est[24] = "", lb[24] = "";
            if (i == 0)
                snprintf(T0, sizeof T0, "%.4g", st->T0);
            if (i == 0 && tol)
                snprintf(est, sizeof est, " %10.2g", s->err_est_structure[k]);
            if (i == 0 && band)
                snprintf(lb, sizeof lb, " %10.2g", r->law_band[k]);
            printf("  %-12s %7d %9s %12.6g %12.6g %10.5g %8.4g%s%s\n", i ? "" : st->name, i + 1, T0,
                   r->umax[d], r->drift[d], s->Pi1[d], s->gamma[d], est, lb);
        }
    }
    if (sc->nstruct > TEXT_MAX_STRUCTURES)
        printf("  ... %d more structures (--json or -o for all)\n",
               sc->nstruct - TEXT_MAX_STRUCTURES);
    printf("  demands (peaks; storey shear with damping, storey 1 = base shear):\n");
    printf("  %-12s %7s %12s %12s %14s %14s\n", "structure", "storey", "height [m]", "drift ratio",
           "a_abs [m/s^2]", "shear [N]");
    for (int k = 0; k < sc->nstruct && k < TEXT_MAX_STRUCTURES; k++) {
        const pd_structure *st = &sc->st[k];
        for (int i = 0; i < st->storeys; i++) {
            int d = st->dof + i;
            printf("  %-12s %7d %12.4g %12.5g %14.6g %14.6g\n", i ? "" : st->name, i + 1,
                   st->height[i], r->drift_ratio[d], r->acc_max[d], r->shear_max[d]);
        }
    }
    if (pd_scene_springs(sc) > 0) { /* the yielding storeys */
        printf("  yielding (storeys with a finite uy):\n");
        printf("  %-12s %7s %10s %7s %10s %12s %8s %12s\n", "structure", "storey", "uy [m]",
               "alpha", "ductility", "residual [m]", "onsets", "excursion [m]");
        for (int k = 0; k < sc->nstruct && k < TEXT_MAX_STRUCTURES; k++) {
            const pd_structure *st = &sc->st[k];
            for (int i = 0; st->uy && i < st->storeys; i++) {
                int d = st->dof + i;
                printf("  %-12s %7d %10.4g %7.3g %10.5g %12.5g %8ld %12.5g\n", i ? "" : st->name,
                       i + 1, st->uy[i], st->yield_alpha[i], r->ductility[d], r->residual[d],
                       r->n_yield[d], r->plastic_excursion[d]);
            }
        }
        energy_line(&r->energy, "J");
    }
    if (sc->ncontact)
        printf("  %-22s %6s %10s %8s %12s %14s %10s\n", "contact", "level", "gap [m]", "impacts",
               "first [s]", "max imp. [N s]", "chi");
    for (int c = 0; c < sc->ncontact && c < TEXT_MAX_CONTACTS; c++) {
        char pair[2 * PD_NAME_MAX + 8];
        int level = contact_label(sc, c, pair, sizeof pair);
        printf("  %-22s %6d %10.4g %8ld %12.6g %14.6g %10.4g\n", pair, level, sc->ct[c].gap,
               r->impacts[c], r->first_impact[c], r->max_impulse[c], s->chi[c]);
    }
    if (sc->ncontact > TEXT_MAX_CONTACTS)
        printf("  ... %d more contacts (--json or -o for all)\n", sc->ncontact - TEXT_MAX_CONTACTS);
    if (sc->ncontact) /* the gap each contact needs: exact, and the codes' rules */
        printf("  %-22s %6s %10s %12s %10s %10s %10s\n", "separation [m]", "level", "gap",
               "required", "ABS", "SRSS", "DDC");
    for (int c = 0; c < sc->ncontact && c < TEXT_MAX_CONTACTS; c++) {
        char pair[2 * PD_NAME_MAX + 8];
        int level = contact_label(sc, c, pair, sizeof pair);
        printf("  %-22s %6d %10.4g %12.6g %10.4g %10.4g %10.4g\n", pair, level, sc->ct[c].gap,
               s->required_gap[c], s->rule_abs[c], s->rule_srss[c], s->rule_ddc[c]);
    }
    if (sc->ncontact)
        printf("  (required: the largest closing of the free motions, the contact-free twin's%s)\n",
               r->method && !strcmp(r->method, "event") ? ", exact" : "; exact by --method event");
    if (sc->ncontact)
        printf("  %-22s %18s %18s\n", "contact forces", "equivalent [N]", "peak (penalty) [N]");
    for (int c = 0; c < sc->ncontact && c < TEXT_MAX_CONTACTS; c++) {
        char pair[2 * PD_NAME_MAX + 8];
        contact_label(sc, c, pair, sizeof pair);
        char peak[32] = "-"; /* an impulsive method: no force history */
        if (!isnan(r->force_max[c]))
            snprintf(peak, sizeof peak, "%.6g", r->force_max[c]);
        printf("  %-22s %18.6g %18s\n", pair, r->force_equiv[c], peak);
    }
    if (sc->ncontact)
        printf(
            "  (equivalent: pi I / (2 td), a half-sine pulse of td = %g s, --contact-duration)\n",
            r->contact_duration);
    if (tol)
        printf("  err_est   = %.2g (the peaks' estimated relative error: umax, drift and the "
               "demands of every structure, the run's and its contact-free twin's; %s)\n",
               s->err_est, s->rtol_met ? "rtol met" : "rtol NOT met");
    printf("  cpu       = %.3g s (the run and its contact-free twin)\n", s->cpu_s);
}

/* The method a scene's run took. */
static const char *r_method(const pd_scene_summary *s)
{
    return s->r.method ? s->r.method : "?";
}

/* The run of scene sc under the resolved options o, its file (out) and
 * chart (plot) written, nothing printed: PD_OK or a status, its message in
 * err. */
static int scene_run_files(const sim_args *a, const pd_scene *sc, const pd_run_opts *o,
                           const char *out, const char *plot, pd_scene_summary *s, pd_err *err)
{
    fanout fo = {0};
    char name[64], title[512];
    long expected = pd_steps_for(o->tend, o->dt); /* samples: every step or every dt */
    int rc = PD_OK;
    if ((out && (rc = pd_scene_writer_open(
                     &fo.w, out, sc, a->every,
                     o->method == PD_METHOD_PENALTY || o->method == PD_METHOD_NEWMARK, err))) ||
        (plot && (rc = pd_scene_plot_open(&fo.p, sc, expected, err))))
        goto done;
    if ((rc = pd_scene_summarize(sc, o, fo.w || fo.p ? fan_sample : NULL, &fo, s, err)))
        goto done;
    snprintf(name, sizeof name, "chain of %d", a->k.chain);
    pd_scene_run_info ri = {.sum = s, .scene_name = a->k.scene_path ? a->k.scene_path : name};
    /* the chart's title: the scene file's name (not its folders), method, excitation */
    const char *base = strrchr(ri.scene_name, '/');
    snprintf(title, sizeof title, "%s: %s, %s%s", base ? base + 1 : ri.scene_name, r_method(s),
             sc->exc.record ? "record " : "",
             sc->exc.record ? sc->exc.record->name : pd_pulse_name(sc->exc.pulse));
    if (fo.w && (rc = pd_scene_writer_finish(fo.w, &ri, err)))
        goto done;
    if (fo.p)
        rc = pd_scene_plot_draw(fo.p, plot, title, err);
done:
    pd_scene_writer_free(fo.w);
    pd_scene_plot_free(fo.p);
    return rc;
}

/* The width of a scene's file: t, x and v of every dof, gap and impulse of
 * every contact. */
static int scene_width(const pd_scene *sc)
{
    return 1 + 2 * sc->n + 2 * sc->ncontact;
}

static int simulate_scene(sim_args *a)
{
    pd_scene *sc = NULL;
    pd_scene_summary s;
    pd_run_opts o;
    pd_lcp_dump *dump = NULL;
    pd_err err;
    int rc, status;
    memset(&s, 0, sizeof s);
    if ((status = pd_cli_scene(&a->k, &sc)))
        return status;
    pd_scene_resolve_opts(sc, &a->k.opts, &o, &err);
    long expected = pd_steps_for(o.tend, o.dt);
    if (a->out && (status = check_output_size(
                       a->out, output_bytes(a->out, expected / a->every + 1, scene_width(sc)))))
        goto done;
    if ((status = dump_open(a, &dump, &o)))
        goto done;
    progress pr;
    progress_start(&pr);
    o.progress = on_progress;
    o.progress_ctx = &pr;
    rc = scene_run_files(a, sc, &o, a->out, a->plot, &s, &err);
    progress_end(&pr);
    if (rc) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    if ((status = dump_finish(dump)))
        goto done;
    warn_rtol(s.r.rtol, s.err_est, s.rtol_met);
    if (a->json)
        scene_json(a, sc, &s);
    else
        scene_text(a, sc, &s);
done:
    pd_lcp_dump_free(dump);
    pd_scene_summary_free(&s);
    pd_scene_free(sc);
    return status;
}

/* The scene's runs of a suite: record k's scene copy, the options, summary. */
typedef struct scene_runs {
    const sim_args *a;
    pd_scene **scs;
    const pd_run_opts *opts;
    pd_scene_summary *ss;
    pd_suite_names *names; /* the runs' names read back */
} scene_runs;

static char *scene_record_body(const void *ctx, int k, size_t *len)
{
    const scene_runs *r = ctx;
    return pd_suite_scene_body(k, &r->ss[k], len);
}

static int scene_record_parse(void *ctx, const char *body, size_t len, int *k)
{
    scene_runs *r = ctx;
    pd_scene_summary v;
    if (pd_suite_scene_parse(body, len, r->scs[0], r->a->k.suite->n, k, &v, r->names))
        return -1;
    pd_scene_summary_free(&r->ss[*k]); /* a record read twice: the later line */
    r->ss[*k] = v;
    return 0;
}

/* Record k's run, its files (-o, --plot: PATH.recK.EXT) written. */
static int scene_record_run(void *ctx, int k, pd_err *err)
{
    scene_runs *r = ctx;
    char out[PD_PATH_MAX], plot[PD_PATH_MAX];
    pd_run_opts o;
    int rc = pd_scene_resolve_opts(r->scs[k], r->opts, &o, err);
    if (rc || (!r->a->out && !r->a->plot))
        return rc ? rc : pd_scene_summarize(r->scs[k], &o, NULL, NULL, &r->ss[k], err);
    if (r->a->out)
        suite_path(r->a->out, k, out, sizeof out); /* fits: parse_args checked */
    if (r->a->plot)
        suite_path(r->a->plot, k, plot, sizeof plot);
    return scene_run_files(r->a, r->scs[k], &o, r->a->out ? out : NULL, r->a->plot ? plot : NULL,
                           &r->ss[k], err);
}

/* The suite's runs on the scene: ss[k] of record k on its copy scs[k]: 0,
 * 1 or 2. */
static int suite_scene_run(sim_args *a, pd_scene **scs, pd_scene_summary *ss, pd_err *errs,
                           suite_runner *sr, unsigned char *done)
{
    int n = a->k.suite->n, status;
    double bytes = 0.0;           /* the records' files together */
    for (int k = 0; k < n; k++) { /* each record on its copy, checked before any run */
        pd_err err;
        pd_run_opts o;
        if (pd_cli_scene_record(&a->k, k, scs[k], &err) ||
            pd_scene_resolve_opts(scs[k], &a->k.opts, &o, &err))
            return pd_cli_usage_error("%s: %s", a->k.suite->path[k], err.msg);
        long rows = pd_steps_for(o.tend, o.dt) / a->every + 1;
        bytes += a->out ? output_bytes(a->out, rows, scene_width(scs[k])) : 0.0;
    }
    if (a->out && (status = check_output_size(a->out, bytes)))
        return status;
    scene_runs runs = {.a = a, .scs = scs, .opts = &a->k.opts, .ss = ss, .names = &sr->names};
    *sr = runner_make(a, scene_record_run, scene_record_body, scene_record_parse, &runs, done);
    if ((status = run_records(sr, a->key, errs)) || a->rank)
        return status;
    for (int k = 0; k < n; k++)
        warn_rtol(ss[k].r.rtol, ss[k].err_est, ss[k].rtol_met);
    return 0;
}

/* One set of peaks' statistics into js (ductility only when yielding). */
static void peaks_json(pd_json *js, const pd_suite_peaks *p, int yields)
{
    pd_json_stats(js, "umax", &p->umax);
    pd_json_stats(js, "drift_ratio", &p->drift_ratio);
    pd_json_stats(js, "acc_max", &p->acc_max);
    pd_json_stats(js, "shear_max", &p->shear_max);
    pd_json_stats(js, "gamma", &p->gamma);
    pd_json_stats(js, "umax_free", &p->umax_free);
    if (yields)
        pd_json_stats(js, "ductility", &p->ductility);
}

/* The scene suite's JSON: each record's run, then per structure (and its
 * storeys) and contact the statistics (docs/records.md, "Suites"). */
static void suite_scene_json(const sim_args *a, const pd_scene *sc, pd_scene **scs,
                             const pd_scene_summary *ss, const pd_scene_suite *st)
{
    int n = a->k.suite->n, yields = pd_scene_springs(sc) > 0;
    pd_json js;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    suite_json_head(&js, a);
    pd_json_begin_array(&js, "records");
    for (int k = 0; k < n; k++)
        scene_json_obj(&js, a, scs[k], &ss[k]);
    pd_json_end_array(&js);
    pd_json_begin_object(&js, "stats");
    pd_json_begin_array(&js, "structures");
    for (int s = 0; s < sc->nstruct; s++) {
        const pd_structure *S = &sc->st[s];
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "name", S->name);
        peaks_json(&js, &st->structure[s], yields);
        pd_json_begin_array(&js, "storeys"); /* each storey's own */
        for (int i = S->dof; i < S->dof + S->storeys; i++) {
            pd_json_begin_object(&js, NULL);
            pd_json_int(&js, "storey", i - S->dof + 1);
            peaks_json(&js, &st->storey[i], yields);
            pd_json_end_object(&js);
        }
        pd_json_end_array(&js);
        pd_json_end_object(&js);
    }
    pd_json_end_array(&js);
    pd_json_begin_array(&js, "contacts");
    for (int c = 0; c < sc->ncontact; c++) {
        const pd_suite_contact *ct = &st->contact[c];
        char pair[2 * PD_NAME_MAX + 4];
        int level = contact_label(sc, c, pair, sizeof pair);
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "sides", pair);
        pd_json_int(&js, "level", level);
        pd_json_num(&js, "closed", ct->closed); /* the share of records with an impact */
        pd_json_stats(&js, "required_gap", &ct->required_gap);
        pd_json_stats(&js, "impacts", &ct->impacts);
        pd_json_stats(&js, "max_impulse", &ct->max_impulse);
        pd_json_stats(&js, "contact_time", &ct->contact_time);
        pd_json_stats(&js, "force_equiv", &ct->force_equiv);
        pd_json_stats(&js, "force_max", &ct->force_max);
        pd_json_begin_object(&js, "rules");
        pd_json_stats(&js, "abs", &ct->rule_abs);
        pd_json_stats(&js, "srss", &ct->rule_srss);
        pd_json_stats(&js, "ddc", &ct->rule_ddc);
        pd_json_end_object(&js);
        /* the share of records whose required gap exceeds the rule's */
        pd_json_begin_object(&js, "rule_closed");
        pd_json_num(&js, "abs", ct->abs_closed);
        pd_json_num(&js, "srss", ct->srss_closed);
        pd_json_num(&js, "ddc", ct->ddc_closed);
        pd_json_end_object(&js);
        pd_json_end_object(&js);
    }
    pd_json_end_array(&js);
    pd_json_end_object(&js);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

/* The scene suite's text: a row per record (each structure's largest
 * storey's umax), the statistics rows, then per contact how often it and
 * each rule closed. */
static int suite_scene_text(const sim_args *a, const pd_scene *sc, pd_scene **scs,
                            const pd_scene_summary *ss, const pd_scene_suite *st)
{
    static const char *const names[] = {"mean", "median", "p16", "p84", "max"};
    int n = a->k.suite->n;
    int ncol = sc->nstruct < SUITE_TEXT_STRUCTS ? sc->nstruct : SUITE_TEXT_STRUCTS;
    suite_header(a, stdout);
    printf("  scene %s: %d structures, %d contacts; method %s; umax [m] of each structure's "
           "largest storey%s\n",
           a->k.scene_path ? a->k.scene_path : "(chain)", sc->nstruct, sc->ncontact, ss[0].r.method,
           ncol < sc->nstruct ? " (the first ones; --json: all)" : "");
    printf("  %-24s %12s", "record", "scale");
    for (int s = 0; s < ncol; s++)
        printf(" %12.12s", sc->st[s].name);
    printf("\n");
    for (int k = 0; k < n; k++) {
        printf("  %-24.24s %12.5g", scs[k]->exc.record->name, scs[k]->exc.scale);
        for (int s = 0; s < ncol; s++)
            printf(" %12.5g", st->structure_umax[(size_t)s * n + k]);
        printf("\n");
    }
    for (int r = 0; r < 5; r++) {
        printf("  %-24s %12s", names[r], "");
        for (int s = 0; s < ncol; s++) {
            const pd_stats *u = &st->structure[s].umax;
            const double v[5] = {u->mean, u->median, u->p16, u->p84, u->max};
            printf(" %12.5g", v[r]);
        }
        printf("\n");
    }
    if (!sc->ncontact)
        return 0;
    printf("  %-24s %12s %12s %12s %12s %12s\n", "contact (level)", "closed", "required",
           "ABS closed", "SRSS closed", "DDC closed");
    for (int c = 0; c < sc->ncontact; c++) {
        const pd_suite_contact *ct = &st->contact[c];
        char pair[2 * PD_NAME_MAX + 4];
        int level = contact_label(sc, c, pair, sizeof pair);
        printf("  %-18.18s (%3d) %12.3g %12.5g %12.3g %12.3g %12.3g\n", pair, level, ct->closed,
               ct->required_gap.mean, ct->abs_closed, ct->srss_closed, ct->ddc_closed);
    }
    printf("  (closed: the share of records with an impact; required: the mean required gap "
           "[m]; RULE closed: the share whose required gap exceeds the rule's)\n");
    return 0;
}

/* Every record of the suite on the scene (each replacing its excitation):
 * per-record results as single runs give them, then per structure and
 * contact the suite's statistics, how often each contact closed and how
 * often each code rule's gap would have been closed (the required gap
 * above the rule's). */
static int suite_scene(sim_args *a)
{
    pd_scene *base = NULL, **scs = NULL;
    pd_scene_summary *ss = NULL;
    pd_scene_suite st = {.n = 0};
    pd_err *errs = NULL, err;
    suite_runner sr = {.journal = {.fd = -1}};
    unsigned char *done = NULL;
    int n = a->k.suite->n, status;
    if ((status = pd_cli_scene(&a->k, &base)))
        return status;
    scs = calloc((size_t)n, sizeof *scs);
    ss = calloc((size_t)n, sizeof *ss);
    errs = calloc((size_t)n, sizeof *errs);
    done = calloc((size_t)n, 1);
    for (int k = 0; scs && k < n; k++)
        scs[k] = pd_scene_copy(base);
    for (int k = 0; scs && k < n && !status; k++)
        status = !scs[k];
    if (!scs || !ss || !errs || !done || status) {
        fprintf(stderr, "pound: simulate: out of memory for a suite of %d records\n", n);
        status = 1;
    }
    pd_spec_mpi_agree(&status); /* every rank goes on, or none */
    if (!status)
        status = suite_scene_run(a, scs, ss, errs, &sr, done);
    if (!status && a->rank) /* rank 0 prints */
        goto done;
    if (!status && pd_scene_suite_stats(base, ss, n, &st, &err)) {
        fprintf(stderr, "pound: simulate: %s\n", err.msg);
        status = 1;
    }
    if (!status && a->json)
        suite_scene_json(a, base, scs, ss, &st);
    else if (!status)
        status = suite_scene_text(a, base, scs, ss, &st);
done:
    runner_end(&sr, status);
    free(done);
    pd_scene_suite_free(&st);
    for (int k = 0; ss && k < n; k++)
        pd_scene_summary_free(&ss[k]);
    for (int k = 0; scs && k < n; k++)
        pd_scene_free(scs[k]);
    free(scs);
    free(ss);
    free(errs);
    pd_scene_free(base);
    return status;
}

/* FNV-1a (64 bits) of a file's bytes (0 when it cannot be read): a
 * journal's key holds it, so that a changed scene or record file is not
 * mixed with the runs made before the change. */
static unsigned long long file_hash(const char *path)
{
    unsigned long long h = 14695981039346656037ull;
    unsigned char buf[8192];
    size_t n;
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        for (size_t i = 0; i < n; i++)
            h = (h ^ buf[i]) * 1099511628211ull;
    fclose(f);
    return h;
}

/* A suite's journal key: pound's version and the summaries' layouts, the
 * flags that decide its numbers and files (all but --json, --threads,
 * --journal, --resume, --stop-after) as flag=value, the scene file's hash,
 * and every record with its scale and its file's hash; NULL when out of
 * memory. */
static char *suite_key(const sim_args *a, int argc, char **argv)
{
    static const char *const skipped[] = {"--json", "--threads", "--journal", "--resume",
                                          "--stop-after"};
    char *key = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&key, &len);
    if (!f)
        return NULL;
    fprintf(f, "version=%s layout=%zu,%zu,%zu", PD_VERSION, sizeof(pd_osc_summary),
            sizeof(pd_scene_summary), sizeof(pd_scene_result));
    for (int i = 1; i < argc; i++) {
        const char *t = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL, *eq = strchr(t, '=');
        size_t nl = eq ? (size_t)(eq - t) : strlen(t);
        int skip = 0, value = t[0] == '-' && !eq && v &&
                              (v[0] != '-' || (v[1] >= '0' && v[1] <= '9') || v[1] == '.');
        for (size_t q = 0; q < sizeof skipped / sizeof *skipped; q++)
            skip |= strlen(skipped[q]) == nl && !strncmp(t, skipped[q], nl);
        if (!skip && t[0] == '-')
            fprintf(f, " %.*s=%s", (int)nl, t, eq ? eq + 1 : value ? v : "1");
        else if (!skip)
            fprintf(f, " arg=%s", t);
        i += value && strcmp(t, "--json") && strcmp(t, "--resume"); /* its value */
    }
    if (a->k.scene_path)
        fprintf(f, " <the-scene-file>=%016llx", file_hash(a->k.scene_path));
    for (int k = 0; k < a->k.suite->n; k++)
        fprintf(f, " <record-%d>=%s@%a#%016llx", k + 1, a->k.suite->path[k], a->k.rec_scale[k],
                file_hash(a->k.suite->path[k]));
    int bad = ferror(f);
    if (fclose(f) || bad) {
        free(key);
        return NULL;
    }
    return key;
}

int pd_cmd_simulate(int argc, char **argv)
{
    sim_args a;
    int rc;
    if (pd_cli_help(argc, argv, simulate_usage, 1))
        return 0;
    if ((rc = parse_args(&a, argc, argv)))
        return rc;
    pd_provenance_set(argc, argv, pd_cli_is_scene(&a.k) ? PD_FORMAT_SCENE : PD_FORMAT_OSCILLATOR,
                      0);
    /* a suite's records over the ranks (MPI) and threads, journaled; one run
     * is one process's */
    int threaded = 1, suite = pd_cli_case_is_suite(&a.k);
    a.size = 1;
    if ((rc = pd_spec_mpi_init("simulate", &a.rank, &a.size, &threaded)))
        ;
    else if (!suite && a.size > 1)
        rc = pd_cli_usage_error("simulate: one run is one process's; mpirun shares out the "
                                "records of a suite (--records F)");
    else if (!suite)
        rc = pd_cli_is_scene(&a.k) ? simulate_scene(&a) : simulate_oscillator(&a);
    else if (!(a.key = suite_key(&a, argc, argv))) {
        fprintf(stderr, "pound: simulate: out of memory\n");
        rc = 1;
    } else {
        if (!threaded)
            a.threads = 1; /* MPI without thread support: one thread per rank */
        rc = pd_cli_is_scene(&a.k) ? suite_scene(&a) : suite_oscillator(&a);
    }
    free(a.key);
    pd_cli_case_free(&a.k);
    pd_spec_mpi_finalize();
    return rc;
}
