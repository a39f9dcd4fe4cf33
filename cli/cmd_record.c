/* cmd_record.c — `pound record F... [--json] [--plot F.png] [--units U]
 * [--record-format F]`: the ground-motion measures and the fitted pulse of
 * each record (SPEC §5, docs/records.md), as a table or one JSON object,
 * and the paper's Fig. 2: acceleration, velocity and displacement with the
 * fitted pulse over them. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_cli.h"
#include "pd_plot.h"

static const char record_usage[] =
    "usage: pound record FILE... [--json] [--plot F.png] [--units g|m/s2|cm/s2]\n"
    "                    [--record-format auto|at2|v2|text]\n"
    "  the ground-motion measures of each record (PGA, PGV, PGD, Arias intensity,\n"
    "  significant durations T5-75 and T5-95) and its fitted Mavroeidis-Papageorgiou\n"
    "  velocity pulse (Tp, vp, ap, Le = ap / wp^2, fit quality r2, and the paper's\n"
    "  one-cycle sine or cosine acceleration pulse); docs/records.md\n"
    "  --json       one object {\"records\": [...]} with npts, dt, pga [m/s^2], pgv [m/s],\n"
    "               pgd [m], arias [m/s], t5_75, t5_95 [s], pulse {Tp, vp, ap, wp, Le, ...}\n"
    "  --plot F.png acceleration, velocity and displacement of every record with the fitted\n"
    "               pulse over them (the paper's Fig. 2)\n"
    "  --units      of two-column text records [g]\n"
    "  --records F  the records a suite file lists (PATH [SCALE] a line), after any FILE\n"
    "  --sa T       also Sa(T): the 5 %-damped pseudo-spectral acceleration at period T\n"
    "               [s], exact for the piecewise-linear record (JSON: sa_T, sa)\n"
    "  --synth-suite DIR  write the suite pound ships (seven stochastic near-fault\n"
    "               records, docs/records.md \"Suites\") into DIR: nf1.txt ... nf7.txt\n"
    "               (text, in g) and suite.txt\n";

enum { RECORD_MAX_FILES = 64 };

/* The command line. */
typedef struct record_args {
    const char *files[RECORD_MAX_FILES];
    int nfiles, json;
    const char *plot;
    pd_record_format format;
    pd_record_units units;
    int have_units;        /* --units given */
    double sa_T;           /* --sa T (0: none) */
    const char *synth_dir; /* --synth-suite DIR */
    pd_suite *suite;       /* --records F */
} record_args;

/* One record read, measured and fitted. */
typedef struct record_item {
    pd_cli_record *r;
    pd_record_measures m;
    double sa; /* Sa(sa_T) [m/s^2] */
} record_item;

static int parse_args(record_args *a, int argc, char **argv)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        const char *f = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(f, "--json"))
            a->json = 1;
        else if (!strcmp(f, "--sa")) {
            int rc = pd_cli_double(f, val, &a->sa_T);
            if (rc)
                return rc;
            if (!(a->sa_T >= 1e-3 && a->sa_T <= 1e3))
                return pd_cli_usage_error("--sa: the period must be in [0.001, 1000] s (got "
                                          "%.10g)",
                                          a->sa_T);
            i++;
        } else if (!strcmp(f, "--synth-suite") || !strcmp(f, "--records")) {
            pd_err err;
            if (!val)
                return pd_cli_usage_error("%s needs a %s", f,
                                          f[2] == 's' ? "folder" : "suite file");
            if (f[2] == 's')
                a->synth_dir = val;
            else if (a->suite)
                return pd_cli_usage_error("--records given twice");
            else if (pd_suite_read(val, &a->suite, &err))
                return pd_cli_usage_error("--records: %s", err.msg);
            for (int k = 0; a->suite && k < a->suite->n && f[2] == 'r'; k++) {
                if (a->nfiles >= RECORD_MAX_FILES)
                    return pd_cli_usage_error("record: at most %d files", RECORD_MAX_FILES);
                a->files[a->nfiles++] = a->suite->path[k];
            }
            i++;
        } else if (!strcmp(f, "--plot") || !strcmp(f, "--units") || !strcmp(f, "--record-format")) {
            if (!val)
                return pd_cli_usage_error("%s needs a value", f);
            if (!strcmp(f, "--plot"))
                a->plot = val;
            else if (!strcmp(f, "--units") && (a->have_units = 1) &&
                     pd_record_units_parse(val, &a->units))
                return pd_cli_usage_error("--units: '%s' is not one of g, m/s2, cm/s2", val);
            else if (!strcmp(f, "--record-format") && pd_record_format_parse(val, &a->format))
                return pd_cli_usage_error("--record-format: '%s' is not one of auto, at2, v2, "
                                          "text",
                                          val);
            i++;
        } else if (f[0] == '-' && f[1] != '\0')
            return pd_cli_usage_error("record: unknown flag '%s' (see pound record --help)", f);
        else if (!strcmp(f, "-"))
            return pd_cli_usage_error("record: '-' (standard input) is not read: give a file name");
        else if (a->nfiles >= RECORD_MAX_FILES)
            return pd_cli_usage_error("record: at most %d files", RECORD_MAX_FILES);
        else
            a->files[a->nfiles++] = f;
    }
    if (a->synth_dir && (a->nfiles || a->json || a->plot || a->sa_T > 0.0))
        return pd_cli_usage_error("--synth-suite: writes the shipped suite, and takes no other "
                                  "flag or file");
    if (!a->nfiles && !a->synth_dir)
        return pd_cli_usage_error("record: give one or more record files");
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    return 0;
}

/* The measures and the pulse of one record as a JSON object. */
static void json_item(pd_json *js, const record_item *it, double sa_T)
{
    const pd_record *r = &it->r->rec;
    const pd_record_pulse *p = &it->r->pulse;
    pd_json_begin_object(js, NULL);
    pd_json_str(js, "name", r->name);
    pd_json_int(js, "npts", r->npts);
    pd_json_num(js, "dt", r->dt);
    pd_json_num(js, "duration", pd_record_duration(r));
    pd_json_num(js, "pga", it->m.pga);
    pd_json_num(js, "pgv", it->m.pgv);
    pd_json_num(js, "pgd", it->m.pgd);
    pd_json_num(js, "t_pga", it->m.t_pga);
    pd_json_num(js, "t_pgv", it->m.t_pgv);
    pd_json_num(js, "t_pgd", it->m.t_pgd);
    pd_json_num(js, "arias", it->m.arias);
    pd_json_num(js, "t5_75", it->m.t5_75);
    pd_json_num(js, "t5_95", it->m.t5_95);
    if (sa_T > 0.0) {
        pd_json_num(js, "sa_T", sa_T);
        pd_json_num(js, "sa", it->sa);
    }
    pd_json_begin_object(js, "pulse");
    pd_json_num(js, "Tp", p->Tp);
    pd_json_num(js, "vp", p->vp);
    pd_json_num(js, "ap", p->ap);
    pd_json_num(js, "wp", p->wp);
    pd_json_num(js, "Le", p->Le);
    pd_json_num(js, "fp", p->fp);
    pd_json_num(js, "nu", p->nu);
    pd_json_num(js, "gamma", p->gamma);
    pd_json_num(js, "t0", p->t0);
    pd_json_num(js, "r2", p->r2);
    pd_json_str(js, "shape", pd_pulse_name(p->shape));
    pd_json_num(js, "t_start", p->t_start);
    pd_json_end_object(js);
    pd_json_end_object(js);
}

/* The table, one row per record. */
static void print_table(const record_item *items, int n, double sa_T)
{
    printf("%-32s %6s %7s %8s %7s %7s %8s %6s %6s | %6s %6s %7s %8s %6s %6s\n", "record", "npts",
           "dt [s]", "PGA m/s2", "PGV m/s", "PGD m", "Ia m/s", "T5-75", "T5-95", "Tp [s]", "vp m/s",
           "ap m/s2", "Le [m]", "r2", "shape");
    for (int k = 0; k < n; k++) {
        const pd_record *r = &items[k].r->rec;
        const pd_record_measures *m = &items[k].m;
        const pd_record_pulse *p = &items[k].r->pulse;
        printf("%-32.32s %6ld %7.4g %8.4g %7.4g %7.4g %8.4g %6.3g %6.3g | %6.3g %6.3g %7.4g %8.4g "
               "%6.3f %6s\n",
               r->name, r->npts, r->dt, m->pga, m->pgv, m->pgd, m->arias, m->t5_75, m->t5_95, p->Tp,
               p->vp, p->ap, p->Le, p->r2, pd_pulse_name(p->shape));
    }
    for (int k = 0; k < n && sa_T > 0.0; k++)
        printf("%-32.32s Sa(%g s) = %.6g m/s^2 (5 %% damped, exact)\n", items[k].r->rec.name, sa_T,
               items[k].sa);
    printf("pulse: Mavroeidis-Papageorgiou velocity pulse fitted to the record's velocity; ap its "
           "largest acceleration, Le = ap Tp^2 / (4 pi^2); shape: the paper's one-cycle "
           "acceleration pulse (docs/records.md)\n");
}

/* The shipped suite into dir: each record as text "t a" in g (9 digits),
 * its parameters in its header, and suite.txt listing them: 0, or 1. */
static int synth_suite(const char *dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/suite.txt", dir);
    FILE *list = fopen(path, "w");
    if (!list) {
        fprintf(stderr, "pound: record: cannot write %s\n", path);
        return 1;
    }
    fprintf(list, "# pound's suite: seven stochastic near-fault records (pound record "
                  "--synth-suite DIR; docs/records.md, \"Suites\")\n");
    int rc = 0;
    for (int k = 0; k < pd_synth_shipped_count() && !rc; k++) {
        const pd_synth *p = pd_synth_shipped(k);
        char name[32];
        pd_record rec;
        pd_err err;
        snprintf(name, sizeof name, "nf%d.txt", k + 1);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        if (pd_record_synth(p, name, &rec, &err)) {
            fprintf(stderr, "pound: record: %s\n", err.msg);
            return 1;
        }
        FILE *f = fopen(path, "w");
        if (!f) {
            fprintf(stderr, "pound: record: cannot write %s\n", path);
            rc = 1;
        } else {
            fprintf(f,
                    "# %s: a stochastic near-fault record (pound record --synth-suite), in g\n"
                    "# pulse (Mavroeidis-Papageorgiou): vp %g m/s, Tp %g s, gamma %g, nu %g rad, "
                    "t0 %g s\n"
                    "# noise (Clough-Penzien): S0 %g m^2/s^3, wg %g rad/s, zg %g, wf %g rad/s, "
                    "zf %g; envelope (Jennings-Housner-Tsai): t1 %g s, t2 %g s, c %g 1/s; seed "
                    "%llu\n",
                    name, p->vp, p->Tp, p->gamma, p->nu, p->t0, p->S0, p->wg, p->zg, p->wf, p->zf,
                    p->t1, p->t2, p->c, p->seed);
            for (long i = 0; i < rec.npts; i++)
                fprintf(f, "%.2f %.9e\n", i * rec.dt, rec.acc[i] / PD_G_STANDARD);
            rc = fclose(f) ? 1 : 0;
            fprintf(list, "%s\n", name);
        }
        pd_record_free(&rec);
    }
    if (fclose(list))
        rc = 1;
    if (rc)
        fprintf(stderr, "pound: record: writing the suite into %s failed\n", dir);
    return rc;
}

int pd_cmd_record(int argc, char **argv)
{
    static record_args a;
    record_item items[RECORD_MAX_FILES];
    int n = 0, rc;
    if (pd_cli_help(argc, argv, record_usage, 0))
        return 0;
    if ((rc = parse_args(&a, argc, argv)))
        return rc;
    if (a.synth_dir) {
        rc = synth_suite(a.synth_dir);
        pd_suite_free(a.suite);
        return rc;
    }
    memset(items, 0, sizeof items);
    for (; n < a.nfiles; n++) {
        pd_err err;
        if ((rc = pd_cli_record_load(a.files[n], a.format, a.units, a.have_units, &items[n].r)))
            break;
        if (pd_record_measure(&items[n].r->rec, &items[n].m, &err) ||
            (a.sa_T > 0.0 && pd_record_sa(&items[n].r->rec, &items[n].r->pulse, a.sa_T, 0.05,
                                          &items[n].sa, &err))) {
            rc = pd_cli_usage_error("%s", err.msg);
            n++;
            break;
        }
    }
    if (!rc && a.plot) {
        pd_err err;
        const pd_cli_record *recs[RECORD_MAX_FILES];
        int nplot = n;
        for (int k = 0; k < n; k++)
            recs[k] = items[k].r;
        if (pd_plot_records(a.plot, recs, nplot, &err)) {
            fprintf(stderr, "pound: record: %s\n", err.msg);
            rc = 1;
        }
    }
    if (!rc && a.json) {
        pd_json js;
        pd_json_init(&js, stdout);
        pd_json_begin_object(&js, NULL);
        pd_json_begin_array(&js, "records");
        for (int k = 0; k < n; k++)
            json_item(&js, &items[k], a.sa_T);
        pd_json_end_array(&js);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else if (!rc)
        print_table(items, n, a.sa_T);
    for (int k = 0; k < n; k++)
        if (items[k].r) {
            pd_record_free(&items[k].r->rec);
            free(items[k].r);
        }
    pd_suite_free(a.suite);
    return rc;
}
