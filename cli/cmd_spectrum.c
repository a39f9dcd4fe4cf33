/* cmd_spectrum.c — `pound spectrum`: pounding response spectra, Pi1 (and
 * gamma, chi) against Pi2 over lists of the other parameters, computed in
 * parallel (OpenMP threads; MPI ranks in the MPI build), journaled so that
 * an interrupted sweep resumes (--resume). */
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_alloc.h"
#include "pd_output.h"
#include "pd_spectrum.h"

static const char spectrum_usage[] =
    "usage: pound spectrum --Pi2 MIN:MAX:N [--linear] [model flags without --T0/--Pi2]\n"
    "                      [--Pi3 LIST | --gap LIST] [--eps LIST] [--xi LIST] [--pulse LIST]\n"
    "                      [--dir LIST] [--ap LIST] [--method M]\n"
    "                      [--dt H | --dt-per-Tp N] [-o FILE.h5|FILE.csv] [--plot FILE.png]\n"
    "                      [--json] [--resume] [--threads K]\n"
    "  --Pi2 MIN:MAX:N  N values of Pi2 = Tp/T0, log-spaced (--linear: equal steps)\n"
    "  LIST             comma-separated values; the sweep is every combination\n"
    "                   (one curve per pulse, dir, ap, xi, Pi3 or gap, eps)\n"
    "  --ap LIST        the dimensional view: umax [m] against T0 [s] per amplitude, at the\n"
    "                   same Pi3 (or the same gap in metres with --gap); --Tp T sets Tp\n"
    "  --dt-per-Tp N    dt = Tp/N for every point [default: dt = min(Tp, T0)/2000]\n"
    "  -o FILE          HDF5 (one group per curve) or CSV (one row per point); while it runs,\n"
    "                   FILE.partial journals the finished points\n"
    "  --resume         continue an interrupted sweep from FILE.partial (same flags)\n"
    "  --plot F.png     Pi1 vs Pi2 in F.png, gamma vs Pi2 in F-gamma.png (and with --ap,\n"
    "                   umax [cm] vs T0 in F-dim.png)\n"
    "  --threads K      OpenMP threads [OMP_NUM_THREADS or all cores]\n"
    "  --json           {\"points\": [...], \"cpu_s\": ..., \"wall_s\": ...} on stdout\n"
    "suites: --records F (a suite file; or --record given twice or more): each record's\n"
    "                   spectrum (JSON records) and the suite's statistics at every point\n"
    "                   (JSON stats: mean, median, p16, p84, min, max of Pi1, gamma, umax);\n"
    "                   -o writes the mean spectrum, FILE.recK.partial journals record K;\n"
    "                   --plot draws each record's curves and their mean (against Pi2 or T0)\n"
    "  --T0 MIN:MAX:N   a suite against the period instead of Pi2 (each record at Pi2 = its\n"
    "                   Tp / T0, log-spaced; with --gap the gap in metres)\n"
    "MPI: make MPI=1, then mpirun -np K build-mpi/pound spectrum ... (rank 0 writes)\n"
    "scenes: pound spectrum --scene F.json --Pi2 MIN:MAX:N [--ref NAME] [--Pi3 LIST]\n"
    "                       [--ref-contact K] [--eps LIST] [-o F] [--plot F.png] [--json]\n"
    "  Pi2 = Tp / T0 of the reference structure NAME [the first] (the pulse period is swept,\n"
    "  the other structures keep their period ratios); --Pi3 scales every gap so that\n"
    "  contact K [0] has Pi3 = gap wp^2 / ap (the others keep their ratios to it); --eps\n"
    "  sets every restitution; Pi1 and gamma per structure (its largest storey)\n";

/* Everything the command line sets. */
typedef struct spec_args {
    pd_spectrum s;
    pd_cli_case k; /* the model, scheme and method flags */
    const char *out, *plot;
    int json, resume, threads, have_pi2, have_pi3, have_gap, have_eps;
    const char *scene_list;            /* a list flag a scene sweep refuses */
    const char *pulse_flag;            /* --pulse or --dir when given (refused with --record) */
    const char *ref_name;              /* --ref NAME (scene sweeps) */
    int ref_contact, have_ref_contact; /* --ref-contact K */
    long stop_after;
    double t0_min, t0_max; /* --T0 MIN:MAX:N: a suite's axis of periods [s] */
    int t0_axis;
    pd_method method_in; /* the method before its resolution (a suite resolves per record) */
} spec_args;

/* The next comma-separated token of *p into tok: 0, or -1 when empty or
 * too long. */
static int next_token(const char **p, char *tok, size_t cap)
{
    size_t len = strcspn(*p, ",");
    if (len == 0 || len >= cap)
        return -1;
    memcpy(tok, *p, len);
    tok[len] = '\0';
    *p += len + ((*p)[len] == ',');
    return 0;
}

/* "a,b,c" -> up to PD_SPEC_MAX_LIST finite numbers: 0 or 2. */
static int parse_nums(const char *flag, const char *text, double *x, int *n)
{
    char tok[64];
    const char *p = text;
    *n = 0;
    if (!text || !*text)
        return pd_cli_usage_error("%s needs a comma-separated list of numbers", flag);
    while (*p) {
        if (next_token(&p, tok, sizeof tok))
            return pd_cli_usage_error("%s: '%s' is not a list of numbers", flag, text);
        if (*n >= PD_SPEC_MAX_LIST)
            return pd_cli_usage_error("%s: at most %d values", flag, PD_SPEC_MAX_LIST);
        if (pd_cli_double(flag, tok, &x[(*n)++]))
            return 2;
    }
    return text[strlen(text) - 1] == ','
               ? pd_cli_usage_error("%s: '%s' ends in a comma", flag, text)
               : 0;
}

/* "sine,cosine" -> pulses, or "normal,reverse" -> directivities: 0 or 2. */
static int parse_names(const char *flag, const char *text, int is_pulse, int *out, int *n, int cap)
{
    char tok[32];
    const char *p = text;
    *n = 0;
    if (!text || !*text || text[strlen(text) - 1] == ',')
        return pd_cli_usage_error("%s needs a comma-separated list of names", flag);
    while (*p) {
        pd_pulse pulse;
        int bad = next_token(&p, tok, sizeof tok) || *n >= cap;
        if (!bad && is_pulse && !(bad = pd_pulse_parse(tok, &pulse) != 0))
            out[*n] = (int)pulse;
        else if (!bad && !is_pulse)
            bad = pd_dir_parse(tok, &out[*n]) != 0;
        if (bad)
            return pd_cli_usage_error("%s: '%s' is not a list of %s", flag, text,
                                      is_pulse ? "sine, cosine, harmonic" : "normal, reverse");
        (*n)++;
    }
    return 0;
}

/* "MIN:MAX:N": 0 < MIN < MAX with N >= 2, or MIN = MAX with N = 1. */
static int parse_pi2(spec_args *a, const char *text)
{
    char buf[256], *p1, *p2;
    pd_spectrum *s = &a->s;
    if (!text || strlen(text) >= sizeof buf || !(p1 = strchr(strcpy(buf, text), ':')) ||
        !(p2 = strchr(p1 + 1, ':')))
        return pd_cli_usage_error("--Pi2: spectrum sweeps Pi2: give MIN:MAX:N (got '%s'; "
                                  "`pound simulate --Pi2 X` runs one value)",
                                  text ? text : "");
    *p1 = *p2 = '\0';
    if (pd_cli_double("--Pi2", buf, &s->pi2_min) || pd_cli_double("--Pi2", p1 + 1, &s->pi2_max) ||
        pd_cli_int("--Pi2", p2 + 1, &s->npi2))
        return 2;
    if (!(s->pi2_min > 0.0) || s->npi2 < 1 || s->npi2 > 1000000 ||
        (s->npi2 == 1 ? s->pi2_max != s->pi2_min : !(s->pi2_max > s->pi2_min)))
        return pd_cli_usage_error("--Pi2: need 0 < MIN < MAX and 2 <= N <= 1e6, or MIN = MAX "
                                  "with N = 1 (got %s)",
                                  text);
    a->have_pi2 = 1;
    return 0;
}

/* A list flag of the sweep: 1 consumed, 0 not one, 2 error. */
static int list_flag(spec_args *a, const char *f, const char *val)
{
    pd_spectrum *s = &a->s;
    int names[3], rc;
    if (!strcmp(f, "--Pi3") || !strcmp(f, "--gap")) {
        a->have_pi3 |= !strcmp(f, "--Pi3");
        a->have_gap |= !strcmp(f, "--gap");
        s->size_is_gap = !strcmp(f, "--gap");
        rc = parse_nums(f, val, s->size, &s->nsize);
    } else if (!strcmp(f, "--eps")) {
        a->have_eps = 1;
        rc = parse_nums(f, val, s->eps, &s->neps);
    } else if (!strcmp(f, "--xi"))
        rc = parse_nums(f, val, s->xi, &s->nxi);
    else if (!strcmp(f, "--ap")) {
        s->dimensional = 1;
        rc = parse_nums(f, val, s->ap, &s->nap);
    } else if (!strcmp(f, "--pulse")) {
        a->pulse_flag = f;
        if (!(rc = parse_names(f, val, 1, names, &s->npulse, 3)))
            for (int i = 0; i < s->npulse; i++)
                s->pulse[i] = (pd_pulse)names[i];
    } else if (!strcmp(f, "--dir"))
        rc = parse_names(f, val, 0, s->dir, &s->ndir, 2);
    else
        return 0;
    if (strcmp(f, "--Pi3") && strcmp(f, "--eps") && !a->scene_list)
        a->scene_list = f;
    return rc ? 2 : 1;
}

/* The command's own flags: 1 consumed (*i advanced past a value), 0 not
 * one, 2 error. */
static int own_flag(spec_args *a, int argc, char **argv, int *i)
{
    const char *f = argv[*i], *val = *i + 1 < argc ? argv[*i + 1] : NULL;
    int n, rc;
    if (!strcmp(f, "--json") || !strcmp(f, "--resume") || !strcmp(f, "--linear")) {
        a->json |= !strcmp(f, "--json");
        a->resume |= !strcmp(f, "--resume");
        a->s.linear |= !strcmp(f, "--linear");
        return 1;
    }
    if (!strcmp(f, "--T0") && val && strchr(val, ':')) { /* a suite's axis of periods */
        char buf[256], *p1, *p2;
        if (strlen(val) >= sizeof buf || !(p1 = strchr(strcpy(buf, val), ':')) ||
            !(p2 = strchr(p1 + 1, ':')))
            return pd_cli_usage_error("--T0: give MIN:MAX:N (got '%s')", val);
        *p1 = *p2 = '\0';
        if (pd_cli_double(f, buf, &a->t0_min) || pd_cli_double(f, p1 + 1, &a->t0_max) ||
            pd_cli_int(f, p2 + 1, &a->s.npi2))
            return 2;
        if (!(a->t0_min > 0.0 && a->t0_max > a->t0_min) || a->s.npi2 < 2 || a->s.npi2 > 1000000)
            return pd_cli_usage_error("--T0: need 0 < MIN < MAX and 2 <= N <= 1e6 (got %s)", val);
        a->t0_axis = a->have_pi2 = 1;
        (*i)++;
        return 1;
    }
    if (!strcmp(f, "--T0"))
        return pd_cli_usage_error("--T0: spectrum sweeps Pi2 = Tp/T0: give --Pi2 MIN:MAX:N (a "
                                  "suite of records also takes --T0 MIN:MAX:N)");
    if (!strcmp(f, "--no-wall"))
        return pd_cli_usage_error("--no-wall: spectrum runs the no-wall twin of every point "
                                  "itself (umax_free)");
    if (!strcmp(f, "--Pi2"))
        rc = parse_pi2(a, val);
    else if (!strcmp(f, "-o") || !strcmp(f, "--plot")) {
        if (!val)
            return pd_cli_usage_error("%s needs a file name", f);
        *(!strcmp(f, "-o") ? &a->out : &a->plot) = val;
        rc = 0;
    } else if (!strcmp(f, "--dt-per-Tp")) {
        pd_cli_case_implies(&a->k, f, PD_METHOD_MOREAU);
        if (!(rc = pd_cli_double(f, val, &a->s.dt_per_Tp)) && !(a->s.dt_per_Tp > 0.0))
            rc = pd_cli_usage_error("--dt-per-Tp: must be > 0 (got %g)", a->s.dt_per_Tp);
    } else if (!strcmp(f, "--ref")) {
        if (!val)
            return pd_cli_usage_error("--ref needs a structure name");
        a->ref_name = val;
        rc = 0;
    } else if (!strcmp(f, "--ref-contact")) {
        if (!(rc = pd_cli_int(f, val, &a->ref_contact)) && a->ref_contact < 0)
            rc = pd_cli_usage_error("--ref-contact: must be >= 0 (got %d)", a->ref_contact);
        a->have_ref_contact = 1;
    } else if (!strcmp(f, "--threads")) {
        if (!(rc = pd_cli_int(f, val, &a->threads)) && (a->threads < 1 || a->threads > 4096))
            rc = pd_cli_usage_error("--threads: must be in [1, 4096] (got %d)", a->threads);
    } else if (!strcmp(f, "--stop-after")) { /* test hook: die after K finished runs */
        if (!(rc = pd_cli_int(f, val, &n)) && n < 1)
            rc = pd_cli_usage_error("--stop-after: must be >= 1 (got %d)", n);
        a->stop_after = n;
    } else if ((rc = list_flag(a, f, val)) != 1)
        return rc;
    else
        rc = 0;
    (*i)++;
    return rc ? 2 : 1;
}

/* -o, --plot F.png and the charts it implies (F-gamma.png, F-dim.png) name
 * different files: PD_OK or PD_EINVAL. */
static int check_outputs_distinct(const spec_args *a, pd_err *err)
{
    char gamma[4096] = "", dim[4096] = "";
    size_t len = a->plot ? strlen(a->plot) : 0;
    if (a->plot && len >= 4 && len < sizeof gamma - 16) {
        snprintf(gamma, sizeof gamma, "%.*s-gamma.png", (int)(len - 4), a->plot);
        snprintf(dim, sizeof dim, "%.*s-dim.png", (int)(len - 4), a->plot);
    }
    const char *flags[] = {"-o", "--plot", "--plot (gamma chart)", "--plot (dimensional chart)"};
    const char *paths[] = {a->out, a->plot, gamma[0] ? gamma : NULL, dim[0] ? dim : NULL};
    return pd_output_check_distinct(4, flags, paths, err);
}

/* The rules of a scene sweep: 0 or 2. */
static int check_scene_args(spec_args *a)
{
    pd_err err;
    if (a->k.chain)
        return pd_cli_usage_error("--chain: spectrum sweeps a scene file (--scene F.json)");
    if (a->scene_list)
        return pd_cli_usage_error("%s: the scene file gives the structures and the excitation "
                                  "(a scene sweep takes --Pi2, --Pi3 and --eps lists)",
                                  a->scene_list);
    if (a->resume || a->stop_after || a->s.dt_per_Tp > 0.0)
        return pd_cli_usage_error("%s: not available for scene sweeps", a->resume ? "--resume"
                                                                        : a->stop_after
                                                                            ? "--stop-after"
                                                                            : "--dt-per-Tp");
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (check_outputs_distinct(a, &err))
        return pd_cli_usage_error("%s", err.msg);
    int rc = pd_cli_case_finish(&a->k);
    if (!rc && a->k.opts.rtol > 0.0)
        return pd_cli_usage_error("--rtol: a scene sweep's Moreau-Jean points take fixed steps; "
                                  "--rtol is the penalty integrator's tolerance here (--method "
                                  "penalty); exact points: --method event");
    return rc;
}

/* The sweep's corners (smallest and largest Pi2, every size and amplitude)
 * through the checks of one case, so that a value whose derived quantities
 * overflow is refused naming its flag: 0 or 2. */
static int check_corners(const spec_args *a)
{
    const pd_spectrum *s = &a->s;
    double pi2[2] = {s->pi2_min, s->pi2_max};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < s->nsize; j++)
            for (int k = 0; k < s->nap; k++) {
                pd_cli_case p = a->k; /* a copy: owns nothing that is freed here */
                p.c = s->base;
                p.c.Pi2 = pi2[i];
                p.have_Pi2 = 1;
                if (s->dimensional)
                    p.c.ap = s->ap[k];
                p.have_gap = s->size_is_gap;
                p.have_Pi3 = !s->size_is_gap;
                if (s->size_is_gap)
                    pd_osc_set_gap(&p.c, s->size[j]);
                else
                    p.c.Pi3 = s->size[j];
                if (s->dt_per_Tp > 0.0) {
                    p.opts.dt = p.c.Tp / s->dt_per_Tp;
                    p.have_dt = 1;
                    p.dt_flag = "--dt-per-Tp";
                }
                int rc = pd_cli_case_check_derived(&p);
                if (rc)
                    return rc;
            }
    return 0;
}

/* Cross-flag rules once every flag is read: 0 or 2. */
static int check_args(spec_args *a)
{
    pd_spectrum *s = &a->s;
    pd_err err;
    if (!a->have_pi2)
        return pd_cli_usage_error("spectrum: --Pi2 MIN:MAX:N is required");
    if (pd_cli_case_is_suite(&a->k) && (a->k.scene_path || a->k.chain))
        return pd_cli_usage_error("--records: a suite's spectrum is the oscillator's (a scene's "
                                  "suite: pound simulate --scene F --records R)");
    if (a->t0_axis && !pd_cli_case_is_suite(&a->k))
        return pd_cli_usage_error("--T0 MIN:MAX:N: the axis of a suite's spectrum (--records); "
                                  "one record or a pulse: --Pi2 MIN:MAX:N");
    if (a->t0_axis && a->s.linear)
        return pd_cli_usage_error("--linear: a suite's --T0 axis is log-spaced");
    if (pd_cli_case_is_suite(&a->k) && (a->resume || a->stop_after) && !a->out)
        return pd_cli_usage_error("%s needs -o FILE", a->resume ? "--resume" : "--stop-after");
    if (a->k.scene_path || a->k.chain)
        return check_scene_args(a);
    if (a->ref_name || a->have_ref_contact)
        return pd_cli_usage_error("%s: goes with --scene", a->ref_name ? "--ref" : "--ref-contact");
    if (a->have_pi3 && a->have_gap)
        return pd_cli_usage_error("--gap and --Pi3 are alternatives: give one");
    if (s->dt_per_Tp > 0.0 && a->k.have_dt)
        return pd_cli_usage_error("--dt and --dt-per-Tp are alternatives: give one");
    if (a->resume && !a->out)
        return pd_cli_usage_error("--resume needs -o FILE (the sweep's journal is FILE.partial)");
    if (a->stop_after && !a->out)
        return pd_cli_usage_error("--stop-after needs -o FILE");
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    if (a->out && pd_output_check_path(a->out, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (check_outputs_distinct(a, &err))
        return pd_cli_usage_error("%s", err.msg);
    if (pd_spec_tasks(s) > PD_SPEC_MAX_TASKS)
        return pd_cli_usage_error("--Pi2: %ld runs in this sweep, at most %ld", pd_spec_tasks(s),
                                  PD_SPEC_MAX_TASKS);
    for (int i = 0; i < s->neps; i++)
        if (!(s->eps[i] >= 0.0 && s->eps[i] <= 1.0))
            return pd_cli_usage_error("--eps: restitution must be in [0, 1] (got %g)", s->eps[i]);
    for (int i = 0; i < s->nxi; i++)
        if (!(s->xi[i] >= 0.0 && s->xi[i] < 1.0))
            return pd_cli_usage_error("--xi: damping ratio must be in [0, 1) (got %g)", s->xi[i]);
    for (int i = 0; i < s->nap; i++)
        if (!(s->ap[i] > 0.0))
            return pd_cli_usage_error("--ap: pulse amplitude must be > 0 (got %g)", s->ap[i]);
    for (int i = 0; i < s->nsize; i++)
        if (!(s->size[i] >= 0.0))
            return pd_cli_usage_error("%s: must be >= 0 (got %g)",
                                      s->size_is_gap ? "--gap" : "--Pi3", s->size[i]);
    if (a->k.record_path && a->pulse_flag)
        return pd_cli_usage_error("%s: the record replaces the pulse (its fitted pulse gives Tp; "
                                  "--scale scales it)",
                                  a->pulse_flag);
    pd_cli_case checked = a->k; /* the flags' ranges, errors naming them */
    int rc = pd_cli_case_finish(&checked);
    if (rc)
        return rc;
    if (checked.opts.rtol > 0.0)
        return pd_cli_usage_error("--rtol: a spectrum's Moreau-Jean points take fixed steps (its "
                                  "batched kernels); --rtol is the penalty integrator's "
                                  "tolerance here (--method penalty); exact points: --method "
                                  "event");
    a->k.record = checked.record; /* a record and its pulse: the sweep's */
    a->k.recs = checked.recs;     /* a suite's records (owned by a->k from here) */
    a->k.rec_scale = checked.rec_scale;
    a->k.suite = checked.suite;
    if (a->t0_axis) { /* the first record's Pi2 range, for the checks below */
        a->s.pi2_min = checked.c.Tp / a->t0_max;
        a->s.pi2_max = checked.c.Tp / a->t0_min;
    }
    s->base = a->k.c;
    s->base.Piy = checked.c.Piy; /* --uy in metres made Piy: the sweep keeps Piy */
    if (a->k.record) {           /* its pulse's amplitude (times --scale) unless --ap lists them */
        pd_osc_set_record(&s->base, &a->k.record->rec, &a->k.record->pulse, a->k.scale);
        if (!s->dimensional)
            s->ap[0] = s->base.ap;
    }
    s->opts = a->k.opts;                      /* dt and tend stay 0 (per point) unless given */
    s->opts.pen.rtol = checked.opts.pen.rtol; /* --rtol routed (penalty) */
    /* the method given or implied by the flags (as the checked case took
     * it), else one for the whole sweep */
    a->k.method_by = checked.method_by;
    s->opts.method = checked.method_by ? checked.opts.method : PD_METHOD_AUTO;
    a->method_in = s->opts.method;
    pd_spec_resolve_method(s);
    if ((rc = check_corners(a)))
        return rc;
    if (pd_spec_validate(s, &err))
        return pd_cli_usage_error("%s", err.msg);
    return 0;
}

/* Every flag, then the cross-flag rules and every point checked: 0 or 2. */
static int parse_args(spec_args *a, int argc, char **argv)
{
    int rc;
    memset(a, 0, sizeof *a);
    pd_spec_init(&a->s);
    pd_cli_case_init(&a->k);
    a->k.suites_by = "spectrum";
    for (int i = 1; i < argc; i++) {
        if ((rc = own_flag(a, argc, argv, &i)) == 1)
            continue;
        if (rc == 2 || (rc = pd_cli_case_flag(&a->k, argc, argv, &i)) == 2)
            return 2;
        if (rc == 0)
            return pd_cli_usage_error("spectrum: unknown flag '%s' (see pound spectrum --help)",
                                      argv[i]);
    }
    return check_args(a);
}

/* Parse on every rank; only rank 0 prints the error (same argv, same
 * verdict everywhere). */
static int parse_on_rank(spec_args *a, int argc, char **argv, int rank)
{
    int saved = -1, rc;
    if (rank > 0) {
        fflush(stderr);
        saved = dup(2);
        int nul = open("/dev/null", O_WRONLY);
        if (nul >= 0) {
            dup2(nul, 2);
            close(nul);
        }
    }
    rc = parse_args(a, argc, argv);
    if (saved >= 0) {
        fflush(stderr);
        dup2(saved, 2);
        close(saved);
    }
    return rc;
}

/* Rank 0: the journal (read back with --resume): 0, 1 or 2. */
static int open_journal(const spec_args *a, const pd_spectrum *s, const char *out,
                        pd_spec_journal *j, pd_spec_result *res, long *loaded)
{
    pd_err err;
    char *key = pd_spec_key(s);
    int rc = key ? pd_spec_journal_open(j, out, key, pd_spec_tasks(s), a->resume, res, loaded, &err)
                 : pd_err_set(&err, PD_ENOMEM, "out of memory");
    free(key);
    if (rc)
        fprintf(stderr, "pound: %s\n", err.msg);
    return rc == 0 ? 0 : rc == PD_EINVAL ? 2 : 1;
}

/* Rank 0: rows, the file (then the journal goes), charts, the summary. */
static int write_results(const spec_args *a, const pd_spec_result *res, pd_spec_journal *j,
                         const pd_spec_totals *t)
{
    pd_err err;
    int rc = 0;
    pd_spec_row *rows = malloc((size_t)pd_spec_points(&a->s) * sizeof *rows);
    if (!rows) {
        fprintf(stderr, "pound: spectrum: out of memory for the rows\n");
        return 1;
    }
    pd_spec_rows(&a->s, res, rows);
    if (a->out && (rc = pd_spec_write(a->out, &a->s, rows, &err)) == 0)
        pd_spec_journal_close(j, 1); /* the file is in place: the journal has served */
    if (!rc && a->plot)
        rc = pd_spec_plot(a->plot, &a->s, rows, &err);
    if (rc)
        fprintf(stderr, "pound: spectrum: %s\n", err.msg);
    else if (a->json)
        pd_spec_print_json(&a->s, rows, t);
    else
        pd_spec_print_text(&a->s, rows, t);
    rc = rc ? 1 : 0;
    free(rows);
    return rc;
}

/* Compute and (rank 0) write; the exit status, the same on every rank. */
static int sweep(spec_args *a, int rank, int size, double wall0)
{
    pd_spec_journal j = {.fd = -1};
    pd_spec_exec ex = {.threads = a->threads,
                       .progress = rank == 0 && isatty(2),
                       .stop_after = a->stop_after,
                       .rank = rank,
                       .size = size};
    pd_spec_totals t = {.method_by = pd_cli_method_by(&a->k),
                        .runs = pd_spec_tasks(&a->s),
                        .threads = pd_spec_threads(a->threads),
                        .ranks = size};
    pd_spec_result *res = calloc((size_t)t.runs, sizeof *res);
    pd_err err;
    int status = res ? 0 : 1;
    if (rank == 0 && !status && a->out)
        status = open_journal(a, &a->s, a->out, &j, res, &t.resumed);
    pd_spec_mpi_agree(&status);
    if (!status && pd_spec_mpi_bcast_done(res, t.runs))
        status = 1;
    if (!status) {
        ex.journal = a->out ? &j : NULL;
        int rc = pd_spec_compute(&a->s, &ex, res, &err);
        if (rc && rank == 0)
            fprintf(stderr, "pound: spectrum: %s\n", err.msg);
        status = rc == 0 ? 0 : rc == PD_EINVAL ? 2 : 1;
    }
    pd_spec_mpi_agree(&status);
    for (long k = 0; k < t.runs && res; k++) {
        t.cpu_s += res[k].cpu_s;
        t.steps += (double)res[k].steps;
    }
    t.wall_s = pd_wall_seconds() - wall0;
    if (rank == 0 && !status)
        status = write_results(a, res, &j, &t);
    pd_spec_journal_close(&j, 0);
    pd_spec_mpi_agree(&status);
    free(res);
    return status;
}

/* ==== a suite of records ===================================================== */

/* Record k's sweep: the suite's sweep on its record (its scale, its
 * method resolved; with --T0 its Pi2 range Tp / T0). */
static int suite_spectrum(const spec_args *a, int k, pd_spectrum *s, pd_err *err)
{
    *s = a->s;
    pd_osc_set_record(&s->base, &a->k.recs[k]->rec, &a->k.recs[k]->pulse, a->k.rec_scale[k]);
    if (!s->dimensional)
        s->ap[0] = s->base.ap;
    if (a->t0_axis) { /* log-spaced in T0 = log-spaced in Pi2, the same N */
        s->pi2_min = s->base.Tp / a->t0_max;
        s->pi2_max = s->base.Tp / a->t0_min;
    }
    s->opts.method = a->method_in;
    pd_spec_resolve_method(s);
    return pd_spec_validate(s, err);
}

/* The statistics of figure f (0 Pi1, 1 gamma, 2 umax) at point p over the
 * records' rows (nrec x points). */
static void point_stats(const pd_spec_row *rows, int nrec, long points, long p, int f, double *x,
                        pd_stats *st)
{
    pd_err err;
    for (int k = 0; k < nrec; k++) {
        const pd_spec_row *r = &rows[(size_t)k * points + p];
        x[k] = f == 0 ? r->Pi1 : f == 1 ? r->gamma : r->umax;
    }
    pd_stats_of(x, nrec, st, &err); /* out of memory: st stays NaN, n 0 */
}

/* The suite's output: JSON (every record's points, the statistics at each
 * point), or text (per curve, the mean spectrum at up to SUITE_TEXT_ROWS
 * points); -o and --plot: the mean spectrum. */
#define SUITE_TEXT_ROWS 12
static int suite_output(const spec_args *a, const pd_spectrum *specs, pd_spec_row *rows,
                        const pd_spec_totals *t)
{
    int nrec = a->k.suite->n, rc = 0;
    long points = pd_spec_points(&specs[0]);
    static const char *const fig[3] = {"Pi1", "gamma", "umax"};
    double *x = malloc((size_t)nrec * sizeof *x);
    pd_spec_row *mean = malloc((size_t)points * sizeof *mean);
    pd_err err;
    if (!x || !mean) {
        free(x);
        free(mean);
        fprintf(stderr, "pound: spectrum: out of memory for the suite's statistics\n");
        return 1;
    }
    /* the mean spectrum: the first record's rows with the means of the figures */
    for (long p = 0; p < points; p++) {
        pd_stats st[3];
        for (int f = 0; f < 3; f++)
            point_stats(rows, nrec, points, p, f, x, &st[f]);
        mean[p] = rows[p];
        mean[p].Pi1 = st[0].mean;
        mean[p].gamma = st[1].mean;
        mean[p].umax = st[2].mean;
        if (a->t0_axis)
            mean[p].c.Pi2 = NAN; /* each record's Tp / T0 */
    }
    if (a->out && (rc = pd_spec_write(a->out, &specs[0], mean, &err)) == 0)
        for (int k = 0; k < nrec; k++) { /* the file is in place: the journals have served */
            char path[4096];
            snprintf(path, sizeof path, "%s.rec%d.partial", a->out, k + 1);
            remove(path);
        }
    if (!rc && a->plot)
        rc = pd_spec_plot_suite(a->plot, &specs[0], nrec, rows, mean, a->t0_axis, &err);
    if (rc) {
        fprintf(stderr, "pound: spectrum: %s\n", err.msg);
        free(x);
        free(mean);
        return 1;
    }
    if (a->json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_str(&js, "suite", a->k.records_path ? a->k.records_path : "--record");
        pd_json_int(&js, "n", nrec);
        pd_json_str(&js, "axis", a->t0_axis ? "T0" : "Pi2");
        pd_json_begin_array(&js, "records");
        for (int k = 0; k < nrec; k++) {
            pd_json_begin_object(&js, NULL);
            pd_json_str(&js, "record", a->k.recs[k]->rec.name);
            pd_json_num(&js, "scale", a->k.rec_scale[k]);
            pd_json_num(&js, "Tp", specs[k].base.Tp);
            pd_json_num(&js, "ap", specs[k].base.ap);
            pd_json_str(&js, "method", pd_method_name(specs[k].opts.method));
            pd_json_begin_array(&js, "points");
            for (long p = 0; p < points; p++)
                pd_spec_json_point(&js, &specs[k], &rows[(size_t)k * points + p]);
            pd_json_end_array(&js);
            pd_json_end_object(&js);
        }
        pd_json_end_array(&js);
        pd_json_begin_array(&js, "stats");
        for (long p = 0; p < points; p++) {
            pd_json_begin_object(&js, NULL);
            pd_json_int(&js, "curve", rows[p].curve);
            if (a->t0_axis)
                pd_json_num(&js, "T0", rows[p].T0);
            else
                pd_json_num(&js, "Pi2", rows[p].c.Pi2);
            pd_json_num(&js, a->k.c.Pi3 >= 0.0 && !specs[0].size_is_gap ? "Pi3" : "gap",
                        specs[0].size_is_gap ? rows[p].gap : rows[p].c.Pi3);
            pd_json_num(&js, "eps", rows[p].c.eps);
            for (int f = 0; f < 3; f++) {
                pd_stats st;
                point_stats(rows, nrec, points, p, f, x, &st);
                pd_json_stats(&js, fig[f], &st);
            }
            pd_json_end_object(&js);
        }
        pd_json_end_array(&js);
        pd_json_num(&js, "cpu_s", t->cpu_s);
        pd_json_num(&js, "wall_s", t->wall_s);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else {
        printf("pounding spectra over a suite of %d records (%s): %ld curves x %d %s, %s\n", nrec,
               a->k.records_path ? a->k.records_path : "--record", pd_spec_curves(&specs[0]),
               specs[0].npi2, a->t0_axis ? "T0" : "Pi2", pd_method_name(specs[0].opts.method));
        for (long c = 0; c < pd_spec_curves(&specs[0]); c++) {
            char label[128];
            pd_spec_curve_label(&specs[0], c, label, sizeof label);
            printf("  curve %s\n  %12s %12s %12s %12s %12s %12s\n", label,
                   a->t0_axis ? "T0 [s]" : "Pi2", "mean Pi1", "p16 Pi1", "p84 Pi1", "mean gamma",
                   "mean umax");
            int stride = specs[0].npi2 > SUITE_TEXT_ROWS
                             ? (specs[0].npi2 + SUITE_TEXT_ROWS - 1) / SUITE_TEXT_ROWS
                             : 1;
            for (int j = 0; j < specs[0].npi2; j += stride) {
                long p = c * specs[0].npi2 + j;
                pd_stats st[3];
                for (int f = 0; f < 3; f++)
                    point_stats(rows, nrec, points, p, f, x, &st[f]);
                printf("  %12.5g %12.5g %12.5g %12.5g %12.5g %12.5g\n",
                       a->t0_axis ? rows[p].T0 : rows[p].c.Pi2, st[0].mean, st[0].p16, st[0].p84,
                       st[1].mean, st[2].mean);
            }
        }
        printf("  (every %s point and each record's spectrum: --json; -o writes the mean "
               "spectrum)\n  cpu %.3g s, wall %.3g s\n",
               a->t0_axis ? "T0" : "Pi2", t->cpu_s, t->wall_s);
    }
    free(x);
    free(mean);
    return 0;
}

/* Every record's sweep in turn (each on every thread, each journaled to
 * FILE.recK.partial with -o), then the suite's statistics at every point. */
static int suite_sweep(spec_args *a, int rank, int size, double wall0)
{
    int nrec = a->k.suite->n, status = 0;
    pd_spectrum *specs = calloc((size_t)nrec, sizeof *specs);
    long points = pd_spec_points(&a->s), runs = pd_spec_tasks(&a->s);
    pd_spec_row *rows = malloc((size_t)nrec * (size_t)points * sizeof *rows);
    pd_spec_result *res = malloc((size_t)runs * sizeof *res);
    pd_spec_totals t = {.method_by = pd_cli_method_by(&a->k),
                        .threads = pd_spec_threads(a->threads),
                        .ranks = size};
    pd_err err;
    if (!specs || !rows || !res) {
        fprintf(stderr, "pound: spectrum: out of memory for a suite of %d records\n", nrec);
        status = 1;
    }
    pd_spec_mpi_agree(&status);
    /* each record's sweep in turn, over every rank and thread (as sweep) */
    for (int k = 0; k < nrec && !status; k++) {
        pd_spec_journal j = {.fd = -1};
        pd_spec_exec ex = {.threads = a->threads,
                           .progress = rank == 0 && isatty(2),
                           .stop_after = a->stop_after,
                           .rank = rank,
                           .size = size};
        char out[4096];
        if (suite_spectrum(a, k, &specs[k], &err)) { /* the same on every rank */
            status = rank == 0 ? pd_cli_usage_error("%s: %s", a->k.suite->path[k], err.msg) : 2;
            break;
        }
        memset(res, 0, (size_t)runs * sizeof *res);
        snprintf(out, sizeof out, "%s.rec%d", a->out ? a->out : "", k + 1);
        if (rank == 0 && a->out)
            status = open_journal(a, &specs[k], out, &j, res, &t.resumed);
        pd_spec_mpi_agree(&status);
        if (!status && pd_spec_mpi_bcast_done(res, runs))
            status = 1;
        ex.journal = a->out ? &j : NULL;
        int rc = status ? 0 : pd_spec_compute(&specs[k], &ex, res, &err);
        if (rc && rank == 0)
            fprintf(stderr, "pound: spectrum: %s: %s\n", a->k.suite->path[k], err.msg);
        if (rc)
            status = rc == PD_EINVAL ? 2 : 1;
        pd_spec_mpi_agree(&status);
        for (long r = 0; r < runs && !status; r++) {
            t.cpu_s += res[r].cpu_s;
            t.steps += (double)res[r].steps;
        }
        t.runs += runs;
        if (!status && rank == 0)
            pd_spec_rows(&specs[k], res, rows + (size_t)k * points);
        pd_spec_journal_close(&j, 0);
    }
    t.wall_s = pd_wall_seconds() - wall0;
    /* bad input (the same flags fail the same way): the records' journals
     * hold nothing to resume, and would make the next run refuse to start */
    for (int k = 0; status == 2 && rank == 0 && a->out && k < nrec; k++) {
        char path[4096];
        snprintf(path, sizeof path, "%s.rec%d.partial", a->out, k + 1);
        remove(path);
    }
    if (!status && rank == 0)
        status = suite_output(a, specs, rows, &t);
    pd_spec_mpi_agree(&status);
    free(specs);
    free(rows);
    free(res);
    return status;
}

/* The files' provenance (docs/formats.md): a spectrum file is reproducible
 * (no `created`), and its command is the sweep without the flags that only
 * choose where the results go and how they are computed (-o, --plot,
 * --json, --threads, --resume, --stop-after), so that equal sweeps give
 * byte-identical files.  0, or 1 when out of memory. */
static int set_provenance(int argc, char **argv)
{
    static const char *const with_value[] = {"-o", "--plot", "--threads", "--stop-after"};
    char **kept = pd_malloc(argc, sizeof *kept);
    int n = 0;
    if (!kept) {
        fprintf(stderr, "pound: spectrum: out of memory\n");
        return 1;
    }
    for (int i = 0; i < argc; i++) {
        int skip = i > 0 && (!strcmp(argv[i], "--json") || !strcmp(argv[i], "--resume"));
        for (size_t k = 0; i > 0 && k < sizeof with_value / sizeof *with_value && !skip; k++)
            if (!strcmp(argv[i], with_value[k])) {
                skip = 1;
                i++; /* and its value */
            }
        if (!skip)
            kept[n++] = argv[i];
    }
    pd_provenance_set(n, kept, PD_FORMAT_SPECTRUM_SCENE, 1);
    free(kept);
    return 0;
}

int pd_cmd_spectrum(int argc, char **argv)
{
    spec_args *a;
    int rank = 0, size = 1, threaded = 1, rc;
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            fputs(spectrum_usage, stdout);
            fputs(pd_cli_case_help, stdout);
            return 0;
        }
    if ((rc = pd_spec_mpi_init("spectrum", &rank, &size, &threaded)))
        return rc;
    double wall0 = pd_wall_seconds();
    if (!(a = malloc(sizeof *a)))
        rc = 1;
    else if (!(rc = parse_on_rank(a, argc, argv, rank)) && !(rc = set_provenance(argc, argv))) {
        if (!threaded)
            a->threads = 1; /* MPI without thread support: one thread per rank */
        if (a->k.scene_path) {
            pd_scene_sweep_args sa = {.k = &a->k,
                                      .ref_name = a->ref_name,
                                      .ref_contact = a->ref_contact,
                                      .pi2_min = a->s.pi2_min,
                                      .pi2_max = a->s.pi2_max,
                                      .npi2 = a->s.npi2,
                                      .linear = a->s.linear,
                                      .npi3 = a->have_pi3 ? a->s.nsize : 0,
                                      .pi3 = a->s.size,
                                      .neps = a->have_eps ? a->s.neps : 0,
                                      .eps = a->s.eps,
                                      .out = a->out,
                                      .plot = a->plot,
                                      .json = a->json,
                                      .threads = a->threads};
            rc = size > 1 ? pd_cli_usage_error("spectrum --scene runs in one process (OpenMP "
                                               "threads), not under mpirun")
                          : pd_cmd_spectrum_scene(&sa, wall0);
        } else if (pd_cli_case_is_suite(&a->k))
            rc = suite_sweep(a, rank, size, wall0);
        else
            rc = sweep(a, rank, size, wall0);
    }
    pd_cli_case_free(&a->k);
    free(a);
    pd_spec_mpi_finalize();
    return rc;
}
