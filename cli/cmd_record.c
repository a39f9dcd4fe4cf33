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
    "  --units      of two-column text records [g]\n";

enum { RECORD_MAX_FILES = 64 };

/* The command line. */
typedef struct record_args {
    const char *files[RECORD_MAX_FILES];
    int nfiles, json;
    const char *plot;
    pd_record_format format;
    pd_record_units units;
    int have_units; /* --units given */
} record_args;

/* One record read, measured and fitted. */
typedef struct record_item {
    pd_cli_record *r;
    pd_record_measures m;
} record_item;

static int parse_args(record_args *a, int argc, char **argv)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        const char *f = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(f, "--json"))
            a->json = 1;
        else if (!strcmp(f, "--plot") || !strcmp(f, "--units") || !strcmp(f, "--record-format")) {
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
    if (!a->nfiles)
        return pd_cli_usage_error("record: give one or more record files");
    if (a->plot && (strlen(a->plot) < 5 || strcmp(a->plot + strlen(a->plot) - 4, ".png")))
        return pd_cli_usage_error("--plot: '%s' must end in .png", a->plot);
    return 0;
}

/* The measures and the pulse of one record as a JSON object. */
static void json_item(pd_json *js, const record_item *it)
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
static void print_table(const record_item *items, int n)
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
    printf("pulse: Mavroeidis-Papageorgiou velocity pulse fitted to the record's velocity; ap its "
           "largest acceleration, Le = ap Tp^2 / (4 pi^2); shape: the paper's one-cycle "
           "acceleration pulse (docs/records.md)\n");
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
    memset(items, 0, sizeof items);
    for (; n < a.nfiles; n++) {
        pd_err err;
        if ((rc = pd_cli_record_load(a.files[n], a.format, a.units, a.have_units, &items[n].r)))
            break;
        if (pd_record_measure(&items[n].r->rec, &items[n].m, &err)) {
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
            json_item(&js, &items[k]);
        pd_json_end_array(&js);
        pd_json_end_object(&js);
        pd_json_finish(&js);
    } else if (!rc)
        print_table(items, n);
    for (int k = 0; k < n; k++)
        if (items[k].r) {
            pd_record_free(&items[k].r->rec);
            free(items[k].r);
        }
    return rc;
}
