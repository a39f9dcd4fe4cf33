/* plot_records.c — the paper's Fig. 2 for any records: the ground
 * acceleration, velocity and displacement of each record (a column each)
 * with its fitted Mavroeidis–Papageorgiou pulse over them, and the one-cycle
 * acceleration pulse the Pi terms use. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "pd_cli.h"
#include "pd_plot.h"

enum { PLOT_RECORDS_MAX = 6 };

typedef struct records_fig {
    const pd_cli_record *const *recs;
    int n;
} records_fig;

/* One block per record: t, a, v, d of the record, then of the fitted pulse,
 * then the one-cycle pulse's acceleration (m/s^2, m/s, m). */
static int records_data(FILE *f, const void *ctx)
{
    const records_fig *fig = ctx;
    for (int k = 0; k < fig->n; k++) {
        const pd_record *r = &fig->recs[k]->rec;
        const pd_record_pulse *p = &fig->recs[k]->pulse;
        double *v = malloc((size_t)r->npts * sizeof(double));
        double *d = malloc((size_t)r->npts * sizeof(double));
        pd_err err;
        if (!v || !d || pd_record_integrate(r, v, d, &err)) {
            free(v);
            free(d);
            return -1;
        }
        double dp = 0.0, vprev = 0.0;
        for (long i = 0; i < r->npts; i++) {
            double t = (double)i * r->dt, ap, vp;
            pd_record_pulse_eval(p, t, &ap, &vp);
            dp += i ? 0.5 * (vprev + vp) * r->dt : 0.0; /* the pulse's displacement */
            vprev = vp;
            fprintf(f, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", t, r->acc[i], v[i], d[i], ap,
                    vp, dp, pd_record_one_cycle(p, t));
        }
        fputs("\n\n", f);
        free(v);
        free(d);
    }
    return ferror(f) ? -1 : 0;
}

/* The title over record r's column: its name as it is (any bytes,
 * pd_plot_literal), then its pulse on a second line, its units in enhanced
 * text (m/s², m⁻¹). */
static void record_title(FILE *g, const pd_cli_record *r)
{
    fputs("set title ", g);
    pd_plot_literal(g, r->rec.name);
    fprintf(g, " . \"\\nT_p = %.3g s, a_p = %.3g m/s^2, 1/L_e = %.3g m^{-1}\"\n", r->pulse.Tp,
            r->pulse.ap, 1.0 / r->pulse.Le);
}

/* Three rows (acceleration, velocity, displacement), a column per record. */
static void records_script(FILE *g, const char *data, const char *png_tmp, const void *ctx)
{
    const records_fig *fig = ctx;
    static const char *const rows[3] = {"acceleration [m/s^2]", "velocity [m/s]",
                                        "displacement [m]"};
    fprintf(g, "set terminal pngcairo size %d,900 enhanced font 'sans,10'\n", 360 * fig->n + 120);
    pd_plot_style(g);
    fputs("set output ", g);
    pd_plot_text(g, png_tmp);
    fprintf(g, "\nset multiplot layout 3,%d\nset grid\nset key top right font ',8' box opaque\n",
            fig->n);
    for (int row = 0; row < 3; row++)
        for (int k = 0; k < fig->n; k++) {
            const pd_cli_record *r = fig->recs[k];
            if (row == 0)
                record_title(g, r);
            else
                fputs("unset title\n", g);
            fputs(k ? "unset key\n" : "set key\n", g); /* the same key in every column */
            fprintf(g, "set ylabel '%s'\nset xlabel '%s'\nplot ", k ? "" : rows[row],
                    row == 2 ? "t [s]" : "");
            pd_plot_text(g, data);
            fprintf(g,
                    " index %d using 1:%d with lines lc rgb 'gray40' title 'record', "
                    "'' index %d using 1:%d with lines lw 2 lc rgb 'red' title 'fitted pulse'",
                    k, 2 + row, k, 5 + row);
            if (row == 0)
                fprintf(g,
                        ", '' index %d using 1:8 with lines lw 1.5 dt 2 lc rgb 'blue' "
                        "title 'one-cycle %s pulse'",
                        k, pd_pulse_name(r->pulse.shape));
            fputc('\n', g);
        }
    fputs("unset multiplot\n", g);
}

int pd_plot_records(const char *png, const pd_cli_record *const *recs, int n, pd_err *err)
{
    if (n > PLOT_RECORDS_MAX)
        return pd_err_set(err, PD_EINVAL, "--plot: at most %d records in one figure (got %d)",
                          PLOT_RECORDS_MAX, n);
    records_fig fig = {.recs = recs, .n = n};
    return pd_plot_with(png, records_data, records_script, &fig, err);
}
